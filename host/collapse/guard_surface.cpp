// Host side of the surface guard (cl/collapse_guard.cl): the queries are found on the device,
// their boxes gridded here (a dense uniform grid; the boxes are few and of similar size, the
// collapses of one iteration), then every S face and every pair of queries is tested on the
// device through the grid. TETCOLLAPSE_PROFILE=1 prints the launches and a count per run;
// TETCOLLAPSE_GUARD_DEBUG=1 also names each refused edge and what its new triangles hit.
#include "collapse/guard_surface.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "collapse/edge_state.hpp"
#include "device/primitives.hpp"
#include "tetcollapse/error.hpp"

namespace tc::collapse_detail {

namespace {

// ensure (launch.hpp) with at least one element: no zero-sized OpenCL buffers.
template <class T>
void ensure_nonempty(DeviceBuffer<T>& b, Context& ctx, size_t n) {
  ensure(b, ctx, std::max<size_t>(n, 1));
}

// The kernels of the matching selection's guard live in collapse_guard_applied.cl.
bool applied_kernel(const std::string& name) {
  return name.rfind("sguard_applied_", 0) == 0 || name == "sguard_undone_boxes" || name == "sguard_requery" ||
         name == "sguard_refused_list";
}

template <class... T>
void launch(Context& ctx, const StageParams& p, const char* name, size_t n, const Arg<T>&... args) {
  // the placement may be the user's
  run_stage(ctx, p, applied_kernel(name) ? "collapse_guard_applied.cl" : "collapse_guard.cl", name, n, args...);
}

// The cell of coordinate v on one axis (ih = 1 / the cell size); the same arithmetic as
// tcc_sg_cell in the kernels.
int cell_of(double v, double org, double ih, int n) {
  double c = std::floor((v - org) * ih);
  return c < 0.0 ? 0 : c >= double(n) ? n - 1 : int(c);
}

// At most this many cells per axis: the grid is over the union of the query boxes, which
// may be spread over the whole mesh.
constexpr int kMaxCellsPerAxis = 48;
static_assert(kMaxCellsPerAxis + 1 < 1024, "sguard_vertex_cells packs a cell in 10 bits per axis");

}  // namespace

void SurfaceGuard::release() {
  const bool pairs_once = each_pair_once;
  *this = SurfaceGuard{};
  each_pair_once = pairs_once;
}

uint32_t SurfaceGuard::run(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                           uint32_t chosen) {
  last_queries = 0;
  last_run_each_pair_once = false;
  if (chosen == 0) return 0;
  ensure_nonempty(qedge, ctx, chosen);
  ensure_nonempty(qbox, ctx, size_t(chosen) * 6);
  ensure_nonempty(qntri, ctx, chosen);
  ensure_nonempty(qcount, ctx, 1);
  qcount.fill(0u);
  const cl_int use_labels = dm.has_labels && p.use_labels ? 1 : 0;
  const cl::Buffer& labels = dm.labels[0].buffer();
  launch(ctx, p, "sguard_queries", c.ne, arg("ne", c.ne), arg("edges", c.edges), arg("edges_are_final", s.result.edges_are_final), arg("edges2dir", s.result.edges2dir), arg("pts", dm.points), arg("vfield", dm.vfields), arg("vfield_stride", dm.vfield_comps), arg("tets", dm.tets), arg("vt_off", c.vt_off), arg("vt", c.vt), arg("tet_nbr", c.tet_nbr), arg("labels", labels), arg("use_labels", use_labels), arg("vflags", c.vflags), arg("qedge", qedge), arg("qbox", qbox), arg("qntri", qntri), arg("qcount", qcount));
  uint32_t nq = 0;
  qcount.download(&nq, 1);
  last_queries = nq;
  if (nq == 0) return 0;

  // the new triangles of each query, stored once (offsets by a scan of their counts)
  reserve_triangles(ctx, nq, query_offsets(ctx, nq));
  launch(ctx, p, "sguard_tris", nq, arg("nq", nq), arg("qedge", qedge), arg("qoff", qoff), arg("edges", c.edges), arg("edges2dir", s.result.edges2dir), arg("pts", dm.points), arg("vfield", dm.vfields), arg("vfield_stride", dm.vfield_comps), arg("tets", dm.tets), arg("vt_off", c.vt_off), arg("vt", c.vt), arg("tet_nbr", c.tet_nbr), arg("labels", labels), arg("use_labels", use_labels), arg("tid", tid), arg("tpos", tpos), arg("tbox", tbox), arg("tplane", tplane), arg("qrep", qrep));
  // the tets owning an S face (conn_vertex_flags_faces), listed once per connectivity
  if (stets_generation != c.generation) {
    ensure_nonempty(stets, ctx, dm.nt);
    n_stets = dev::compact_indices(ctx, c.owns_s, stets, dm.nt);
    stets_generation = c.generation;
  }
  ensure_nonempty(verts2query, ctx, 1);  // passed, not read (each pair once is for run_applied)
  ensure_nonempty(tmin, ctx, 1);
  return test_queries(ctx, dm, c, s, p, chosen, nq, c.smask, stets, n_stets, false);
}

uint32_t SurfaceGuard::run_applied(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                                   uint32_t chosen) {
  last_queries = 0;
  last_run_each_pair_once = false;
  if (chosen == 0) return 0;
  // the S faces of the result
  ensure_nonempty(applied_owns_s, ctx, dm.nt);
  ensure_nonempty(applied_smask, ctx, dm.nt);
  const cl_int use_labels = dm.has_labels && p.use_labels ? 1 : 0;
  launch(ctx, p, "sguard_applied_smask", dm.nt, arg("nt", dm.nt), arg("tet_nbr", c.tet_nbr), arg("labels", dm.labels[0]), arg("use_labels", use_labels), arg("tets_are_dead", s.result.tets_are_dead), arg("owns_s", applied_owns_s), arg("smask", applied_smask));
  ensure_nonempty(qedge, ctx, chosen);
  ensure_nonempty(qbox, ctx, size_t(chosen) * 6);
  ensure_nonempty(qntri, ctx, chosen);
  ensure_nonempty(qcount, ctx, 1);
  qcount.fill(0u);
  const bool only = only_requery;
  only_requery = false;
  if (only) ensure_nonempty(requery, ctx, c.ne);  // (filled by restrict_to_undone)
  ensure_nonempty(verts2query, ctx, dm.nv);
  verts2query.fill(-1);
  launch(ctx, p, "sguard_applied_queries", c.ne, arg("ne", c.ne), arg("edges", c.edges), arg("edges_are_final", s.result.edges_are_final), arg("edges2dir", s.result.edges2dir), arg("tets", dm.tets), arg("vt_off", c.vt_off), arg("vt", c.vt), arg("tets_are_dead", s.result.tets_are_dead), arg("smask", applied_smask), arg("vflags", c.vflags), arg("qedge", qedge), arg("qntri", qntri), arg("qcount", qcount), arg("only_flagged", cl_int(only ? 1 : 0)), arg("requery", only ? requery.buffer() : applied_smask.buffer()), arg("verts2query", verts2query));
  uint32_t nq = 0;
  qcount.download(&nq, 1);
  last_queries = nq;
  if (nq == 0) return 0;
  const uint32_t ntri = query_offsets(ctx, nq);
  reserve_triangles(ctx, nq, ntri);
  ensure_nonempty(tmin, ctx, ntri);
  launch(ctx, p, "sguard_applied_tris", nq, arg("nq", nq), arg("qedge", qedge), arg("qoff", qoff), arg("edges", c.edges), arg("edges2dir", s.result.edges2dir), arg("pts", dm.points), arg("tets", dm.tets), arg("vt_off", c.vt_off), arg("vt", c.vt), arg("tets_are_dead", s.result.tets_are_dead), arg("smask", applied_smask), arg("tid", tid), arg("tpos", tpos), arg("tbox", tbox), arg("tplane", tplane), arg("qrep", qrep), arg("verts2query", verts2query), arg("tmin", tmin), arg("qbox", qbox));
  ensure_nonempty(applied_stets, ctx, dm.nt);
  const uint32_t n_applied = dev::compact_indices(ctx, applied_owns_s, applied_stets, dm.nt);
  return test_queries(ctx, dm, c, s, p, chosen, nq, applied_smask, applied_stets, n_applied, each_pair_once);
}

void SurfaceGuard::restrict_to_undone(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s,
                                      const std::vector<uint32_t>& undone) {
  if (undone.empty() || last_queries == 0) return;
  StageParams p;  // the kernels have no user code
  const uint32_t nu = uint32_t(undone.size());
  ensure_nonempty(undone_list, ctx, nu);
  undone_list.upload(undone.data(), nu);
  ensure_nonempty(undone_boxes, ctx, size_t(nu) * 6);
  launch(ctx, p, "sguard_undone_boxes", nu, arg("n", nu), arg("undone", undone_list), arg("edges", c.edges), arg("edges2dir", s.result.edges2dir), arg("nb_off", c.nb_off), arg("nb", c.nb), arg("verts2collapse", s.result.verts2collapse), arg("pts", dm.points), arg("boxes", undone_boxes));
  ensure_nonempty(requery, ctx, c.ne);
  requery.fill(0);
  launch(ctx, p, "sguard_requery", last_queries, arg("nq", last_queries), arg("qedge", qedge), arg("qbox", qbox), arg("nu", nu), arg("boxes", undone_boxes), arg("requery", requery));
  only_requery = true;
}

void SurfaceGuard::refused_edges(Context& ctx, DeviceBuffer<uint8_t>& flag, DeviceBuffer<uint32_t>& list,
                                 DeviceBuffer<uint32_t>& count) {
  if (last_queries == 0) return;
  StageParams p;  // the kernel has no user code
  launch(ctx, p, "sguard_refused_list", last_queries, arg("nq", last_queries), arg("qedge", qedge), arg("qbad", qbad), arg("flag", flag), arg("list", list), arg("count", count));
}

uint32_t SurfaceGuard::query_offsets(Context& ctx, uint32_t nq) {
  const std::vector<uint32_t> counts = qntri.download_range(0, nq);
  std::vector<uint32_t> off_tri(nq + 1, 0);
  for (uint32_t q = 0; q < nq; ++q) off_tri[q + 1] = off_tri[q] + counts[q];
  ensure_nonempty(qoff, ctx, nq + 1);
  qoff.upload(off_tri);
  return off_tri[nq];
}

void SurfaceGuard::reserve_triangles(Context& ctx, uint32_t nq, uint32_t ntri) {
  ensure_nonempty(tid, ctx, size_t(ntri) * 3);
  ensure_nonempty(tpos, ctx, size_t(ntri) * 9);
  ensure_nonempty(tbox, ctx, size_t(ntri) * 6);
  ensure_nonempty(tplane, ctx, size_t(ntri) * 5);
  ensure_nonempty(qrep, ctx, size_t(nq) * 2);
}

uint32_t SurfaceGuard::test_queries(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                                    uint32_t chosen, uint32_t nq, DeviceBuffer<uint8_t>& smask,
                                    DeviceBuffer<uint32_t>& sweep_tets, uint32_t n_sweep, bool each_once) {
  // The grid: cells twice the median query box (most boxes span <= 2 cells per axis, the large
  // ones are entered in every cell they span), at most kMaxCellsPerAxis per axis.
  const std::vector<double> box = qbox.download_range(0, size_t(nq) * 6);
  double lo[3], hi[3];
  for (int a = 0; a < 3; ++a) {
    lo[a] = std::numeric_limits<double>::infinity();
    hi[a] = -lo[a];
  }
  std::vector<double> extent(nq);
  for (uint32_t q = 0; q < nq; ++q) {
    extent[q] = 0;
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], box[6 * q + a]);
      hi[a] = std::max(hi[a], box[6 * q + 3 + a]);
      extent[q] = std::max(extent[q], box[6 * q + 3 + a] - box[6 * q + a]);
    }
  }
  std::nth_element(extent.begin(), extent.begin() + nq / 2, extent.end());
  double ext = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  double h = std::max(2 * extent[nq / 2], ext / kMaxCellsPerAxis);
  if (!(h > 0) || !std::isfinite(h)) h = 1;  // all boxes one point
  const double ih = 1.0 / h;
  int g[3];
  for (int a = 0; a < 3; ++a) g[a] = std::min(kMaxCellsPerAxis + 1, int(std::floor((hi[a] - lo[a]) / h)) + 1);
  const size_t ncells = size_t(g[0]) * g[1] * g[2];
  // each query's cells: low (the first 3, also tcc_sg_owner_cell's) and high corner, per axis
  std::vector<int32_t> range(size_t(nq) * 6);
  for (uint32_t q = 0; q < nq; ++q)
    for (int a = 0; a < 6; ++a) range[6 * size_t(q) + a] = cell_of(box[6 * q + a], lo[a % 3], ih, g[a % 3]);
  // counting sort of the (cell, query) pairs by cell
  std::vector<uint32_t> off(ncells + 1, 0);
  auto for_cells = [&](uint32_t q, auto&& fn) {
    const int32_t* r = &range[6 * size_t(q)];
    for (int k = r[2]; k <= r[5]; ++k)
      for (int j = r[1]; j <= r[4]; ++j)
        for (int i = r[0]; i <= r[3]; ++i) fn((size_t(k) * g[1] + j) * g[0] + i);
  };
  for (uint32_t q = 0; q < nq; ++q) for_cells(q, [&](size_t cell) { ++off[cell + 1]; });
  for (size_t i = 0; i < ncells; ++i) off[i + 1] += off[i];
  // each pair once: placed by increasing x = qrep[2 q] (the survivor), which the sweep's scan of
  // a cell relies on (a counting sort of the queries by x); else in query order
  const std::vector<int32_t> rep = qrep.download_range(0, size_t(nq) * 2);
  std::vector<uint32_t> order(nq);
  if (each_once) {
    std::vector<uint32_t> by_x(size_t(dm.nv) + 1, 0);
    for (uint32_t q = 0; q < nq; ++q) ++by_x[size_t(rep[2 * q]) + 1];
    for (size_t i = 0; i < size_t(dm.nv); ++i) by_x[i + 1] += by_x[i];
    for (uint32_t q = 0; q < nq; ++q) order[by_x[size_t(rep[2 * q])]++] = q;
  } else {
    for (uint32_t q = 0; q < nq; ++q) order[q] = q;
  }
  // the entries (cl/collapse_guard.cl, tcc_sg_cell): query, x, low cell packed, 0
  std::vector<uint32_t> cursor(off.begin(), off.end() - 1);
  std::vector<int32_t> entries(size_t(std::max<uint32_t>(off[ncells], 1)) * 4, 0);
  for (uint32_t q : order)
    for_cells(q, [&](size_t cell) {
      const size_t m = cursor[cell]++;
      const int32_t* r = &range[6 * size_t(q)];
      entries[4 * m] = int32_t(q);
      entries[4 * m + 1] = rep[2 * q];
      entries[4 * m + 2] = r[0] | r[1] << 10 | r[2] << 20;  // as sguard_vertex_cells packs
    });
  if (kProfile)
    std::fprintf(stderr, "  surface guard grid: h %g, %d x %d x %d cells, %u entries for %u queries\n", h, g[0], g[1],
                 g[2], off[ncells], nq);
  ensure_nonempty(cell_off, ctx, off.size());
  cell_off.upload(off);
  ensure_nonempty(cell_q, ctx, entries.size());
  cell_q.upload(entries);

  ensure_nonempty(qbad, ctx, nq);
  qbad.fill(0u);
  const cl_int dedup = each_once ? 1 : 0;
  last_run_each_pair_once = each_once;
  ensure_nonempty(vcell, ctx, dm.nv);
  launch(ctx, p, "sguard_vertex_cells", dm.nv, arg("nv", dm.nv), arg("pts", dm.points), arg("ox", cl_double(lo[0])), arg("oy", cl_double(lo[1])), arg("oz", cl_double(lo[2])), arg("ih", cl_double(ih)), arg("gx", cl_int(g[0])), arg("gy", cl_int(g[1])), arg("gz", cl_int(g[2])), arg("vcell", vcell));
  launch(ctx, p, "sguard_surface", n_sweep, arg("n", n_sweep), arg("stets", sweep_tets), arg("smask", smask), arg("vcell", vcell), arg("pts", dm.points), arg("tets", dm.tets), arg("qrep", qrep), arg("qbox", qbox), arg("qoff", qoff), arg("tid", tid), arg("tpos", tpos), arg("tbox", tbox), arg("tplane", tplane), arg("ox", cl_double(lo[0])), arg("oy", cl_double(lo[1])), arg("oz", cl_double(lo[2])), arg("ih", cl_double(ih)), arg("gx", cl_int(g[0])), arg("gy", cl_int(g[1])), arg("gz", cl_int(g[2])), arg("cell_off", cell_off), arg("cell_q", cell_q), arg("qbad", qbad), arg("dedup", dedup), arg("verts2query", verts2query), arg("tmin", tmin));
  launch(ctx, p, "sguard_pairs", nq, arg("nq", nq), arg("qbox", qbox), arg("qoff", qoff), arg("tid", tid), arg("tpos", tpos), arg("tbox", tbox), arg("tplane", tplane), arg("ox", cl_double(lo[0])), arg("oy", cl_double(lo[1])), arg("oz", cl_double(lo[2])), arg("ih", cl_double(ih)), arg("gx", cl_int(g[0])), arg("gy", cl_int(g[1])), arg("gz", cl_int(g[2])), arg("cell_off", cell_off), arg("cell_q", cell_q), arg("qbad", qbad), arg("cross", cl_int(s.result.in_place ? 0 : 1)), arg("dedup", dedup), arg("qrep", qrep), arg("verts2query", verts2query), arg("tmin", tmin));
  qcount.fill(0u);
  const bool has_verdict = !s.result.in_place && s.carry.edges2verdict.size() >= c.ne && s.carry.edges2verdict.buffer()();
  launch(ctx, p, "sguard_drop", nq, arg("nq", nq), arg("qedge", qedge), arg("qbad", qbad), arg("edges_are_marked", s.cost.edges_are_marked), arg("has_verdict", cl_int(has_verdict ? 1 : 0)), arg("edges2verdict", has_verdict ? s.carry.edges2verdict.buffer() : qbad.buffer()), arg("count", qcount));
  uint32_t refused = 0;
  qcount.download(&refused, 1);
  if (kProfile) std::fprintf(stderr, "  surface guard: %u collapses chosen, %u change S, %u refused\n", chosen, nq, refused);
  if (std::getenv("TETCOLLAPSE_GUARD_DEBUG") && refused > 0) {
    std::vector<uint32_t> bad = qbad.download_range(0, nq);
    std::vector<int32_t> qe = qedge.download_range(0, nq);
    std::vector<int32_t> ed = c.edges.download_range(0, size_t(c.ne) * 2);
    std::vector<uint8_t> dr = s.result.edges2dir.download_range(0, c.ne);
    std::vector<int32_t> tt = dm.tets.download_range(0, size_t(dm.nt) * 4);
    for (uint32_t q = 0; q < nq; ++q)
      if (bad[q]) {
        int e = qe[q];
        std::fprintf(stderr, "  refused edge %d (%d, %d) dir %d:", e, ed[2 * e], ed[2 * e + 1], dr[e]);
        if (bad[q] & 0x80000000u) {
          int other = qe[bad[q] & 0x7fffffffu];
          std::fprintf(stderr, " new triangles of edge %d (%d, %d) dir %d", other, ed[2 * other], ed[2 * other + 1],
                       dr[other]);
        } else if (bad[q] >= 2) {
          uint32_t t = (bad[q] - 2) / 4, f = (bad[q] - 2) % 4;
          std::fprintf(stderr, " face %u/%u = tet (%d %d %d %d)", t, f, tt[4 * t], tt[4 * t + 1], tt[4 * t + 2], tt[4 * t + 3]);
        }
        std::fprintf(stderr, "\n");
      }
  }
  if (refused > 0) restart_selection_counters(s);
  return refused;
}

}  // namespace tc::collapse_detail
