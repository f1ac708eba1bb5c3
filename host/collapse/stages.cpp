// Host side of the collapse stages: buffer management and kernel launches (cl/collapse_*.cl).
#include "collapse/stages.hpp"
#include "collapse/spatial_order.hpp"
#include "collapse/guard_surface.hpp"
#include "collapse/launch.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <functional>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <system_error>
#include <thread>

#include "device/primitives.hpp"
#include "tetcollapse/error.hpp"

namespace tc::collapse_detail {

namespace {

const cl::Buffer& primary_labels(DeviceMesh& dm) { return dm.labels[0].buffer(); }

}  // namespace

StageParams params_from(const CollapseOptions& o) {
  StageParams p;
  p.mode = o.boundary == CollapseOptions::Strict ? 0 : o.boundary == CollapseOptions::Features ? 1 : 2;
  p.paper_rule = o.paper_boundary_rule;
  p.use_labels = o.use_labels;
  p.eps_f = o.eps_f;
  p.eps_r = o.eps_r;
  p.eps_v = o.eps_v;
  p.min_quality = o.min_quality;
  p.priority_levels = o.priority_levels;
  p.mask_mode = o.vertex_mask.empty() ? 0 : o.mask_either ? 2 : 1;
  p.cost_source = o.cost_cl_source;
  // (#line: the compiler's messages give the line in the user's source, under its option's name)
  if (!o.placement_cl_source.empty()) {
    p.user_source += "#line 1 \"placement_cl_source\"\n" + o.placement_cl_source + "\n";
    p.user_defines += " -DTCC_USER_PLACEMENT";
  }
  if (!o.predicate_cl_source.empty()) {
    p.user_source += "#line 1 \"predicate_cl_source\"\n" + o.predicate_cl_source + "\n";
    p.user_defines += " -DTCC_USER_PREDICATE";
  }
  return p;
}

void check_collapse_input(const Mesh& mesh) {
  if (mesh.points.size() % 3 != 0 || mesh.tets.size() % 4 != 0)
    throw InputError("<mesh>", "point or tet array length is not a multiple of 3 or 4");
  const int64_t nv = mesh.num_vertices(), nt = mesh.num_tets();
  // Edges and N(v) entries must fit 31-bit indices: 12 nt scratch slots bound both.
  if (nv >= std::numeric_limits<int32_t>::max() || nt >= std::numeric_limits<int32_t>::max() / 12)
    throw InputError("<mesh>", "mesh too large for the collapse's 32-bit indices: " + std::to_string(nv) +
                                   " vertices, " + std::to_string(nt) + " tets");
  for (int64_t t = 0; t < nt; ++t) {
    const int32_t* q = &mesh.tets[4 * t];
    for (int i = 0; i < 4; ++i) {
      if (q[i] < 0 || q[i] >= nv)
        throw InputError("<mesh>", "tet " + std::to_string(t) + " has vertex index " + std::to_string(q[i]) +
                                       " outside [0, " + std::to_string(nv) + ")");
      for (int j = 0; j < i; ++j)
        if (q[i] == q[j]) throw InputError("<mesh>", "tet " + std::to_string(t) + " repeats vertex " + std::to_string(q[i]));
    }
  }
  for (const Labels& l : mesh.tet_labels)
    if (l.values.size() != size_t(nt))
      throw InputError("<mesh>", "label array '" + l.name + "' has " + std::to_string(l.values.size()) +
                                     " values for " + std::to_string(nt) + " tets");
}

namespace {

// ring(v) for every vertex: counted, then filled in tet order, so each ring is ascending. Why
// on the host for a CPU device (Context::cpu_tuning): one sequential pass over the tets (W1: a
// few ms on one core) against the device's atomic count and scatter and a sort of every ring
// (conn_count, conn_scatter, conn_ring_sort_and_gather's sort), ~0.025 s on both cores; the
// tets are in spatial order, so the writes are near each other. A GPU does its own.
void host_rings(const std::vector<int32_t>& tets, uint32_t nv, std::vector<uint32_t>& off, std::vector<int32_t>& vt) {
  off.assign(size_t(nv) + 1, 0);
  for (int32_t v : tets) ++off[size_t(v) + 1];
  for (size_t v = 0; v < nv; ++v) off[v + 1] += off[v];
  vt.resize(tets.size());
  std::vector<uint32_t> cursor(off.begin(), off.end() - 1);
  for (size_t i = 0; i < tets.size(); ++i) vt[cursor[size_t(tets[i])]++] = int32_t(i / 4);
}

}  // namespace

void upload_mesh(Context& ctx, const Mesh& mesh, const CollapseOptions& o, DeviceMesh& dm,
                 std::vector<int32_t>* vertex_new) {
  check_collapse_input(mesh);
  const int64_t nv = mesh.num_vertices(), nt = mesh.num_tets();
  SpatialOrder spatial;
  const SpatialOrder* order = nullptr;
  if (vertex_new) {  // the indices are checked: the order may use them
    spatial = spatial_order(mesh);
    order = &spatial;
  }
  // entity i of the device mesh is entity old(i) of `mesh` (the identity without an order)
  auto vold = [&](int64_t i) { return order ? int64_t(order->vertex_old[size_t(i)]) : i; };
  auto told = [&](int64_t i) { return order ? int64_t(order->tet_old[size_t(i)]) : i; };
  auto gather = [&](const auto& values, int64_t count, size_t per, auto old) {
    std::remove_cvref_t<decltype(values)> out(values.size());
    for (int64_t i = 0; i < count; ++i)
      for (size_t c = 0; c < per; ++c) out[size_t(i) * per + c] = values[size_t(old(i)) * per + c];
    return out;
  };
  dm.nv = uint32_t(nv);
  dm.nt = uint32_t(nt);
  const std::vector<int32_t>& tets = order ? spatial.tets : mesh.tets;
  // The rings (Context::cpu_tuning: a CPU device) on a second thread while this one gathers and
  // uploads the rest: the device's threads are idle during the upload (W1: the rings ~0.02 s,
  // the rest ~0.015 s).
  dm.has_rings = ctx.cpu_tuning();
  std::vector<uint32_t> ring_off;
  std::vector<int32_t> ring_vt;
  std::exception_ptr ring_error;
  std::jthread rings;  // after what it reads and writes: joined first when this function throws
  bool rings_here = false;
  if (dm.has_rings) {
    try {
      rings = std::jthread([&tets, nv = dm.nv, &ring_off, &ring_vt, &ring_error] {
        try {
          host_rings(tets, nv, ring_off, ring_vt);
        } catch (...) {
          ring_error = std::current_exception();
        }
      });
    } catch (const std::system_error&) {  // no thread to be had: on this one, below
      rings_here = true;
    }
  }
  dm.points = order ? DeviceBuffer<double>(ctx, gather(mesh.points, nv, 3, vold)) : DeviceBuffer<double>(ctx, mesh.points);
  dm.tets = DeviceBuffer<int32_t>(ctx, tets);
  dm.labels.clear();
  for (const Labels& l : mesh.tet_labels) {  // lengths checked by check_collapse_input
    dm.labels.emplace_back(ctx, order ? gather(l.values, nt, 1, told) : l.values);
  }
  dm.has_labels = !dm.labels.empty() && o.use_labels;
  if (dm.labels.empty()) dm.labels.emplace_back(ctx, 0);  // placeholder argument
  auto pack = [&](const std::vector<Field>& fields, int64_t count, const char* kind, uint32_t& comps,
                  DeviceBuffer<double>& out, auto old) {
    comps = 0;
    for (const Field& f : fields) {
      if (f.components <= 0 || f.values.size() != size_t(count) * size_t(f.components))
        throw InputError("<mesh>", std::string(kind) + " field '" + f.name + "' has " + std::to_string(f.values.size()) +
                                       " values, expected " + std::to_string(count) + " x " + std::to_string(f.components));
      comps += uint32_t(f.components);
    }
    std::vector<double> packed(size_t(count) * comps);
    uint32_t c0 = 0;
    for (const Field& f : fields) {
      for (int64_t i = 0; i < count; ++i)
        for (int c = 0; c < f.components; ++c)
          packed[size_t(i) * comps + c0 + c] = f.values[size_t(old(i)) * f.components + c];
      c0 += uint32_t(f.components);
    }
    out = DeviceBuffer<double>(ctx, packed);
  };
  pack(mesh.vertex_fields, nv, "vertex", dm.vfield_comps, dm.vfields, vold);
  pack(mesh.tet_fields, nt, "tet", dm.tfield_comps, dm.tfields, told);
  dm.has_mask = !o.vertex_mask.empty();
  if (dm.has_mask && o.vertex_mask.size() != size_t(nv))
    throw std::invalid_argument("vertex_mask has " + std::to_string(o.vertex_mask.size()) + " entries for " +
                                std::to_string(nv) + " vertices");
  dm.vmask = DeviceBuffer<uint8_t>(ctx, order && dm.has_mask ? gather(o.vertex_mask, nv, 1, vold) : o.vertex_mask);
  if (dm.has_rings) {
    if (rings_here) host_rings(tets, dm.nv, ring_off, ring_vt);
    else rings.join();
    if (ring_error) std::rethrow_exception(ring_error);
    dm.vt_off = DeviceBuffer<uint32_t>(ctx, ring_off);
    dm.vt = DeviceBuffer<int32_t>(ctx, ring_vt);
  }
  if (vertex_new) *vertex_new = std::move(spatial.vertex_new);
}

uint32_t next_selection_round(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                              uint32_t& tested) {
  remember_for_carry(ctx, dm, c, s);  // s.vdirty: the stars of the collapses chosen so far
  std::swap(s.fin, s.fin1);
  std::swap(s.dir, s.dir1);
  std::swap(s.vaff, s.vaff1);
  s.restrict_clean = true;
  s.verdict_ready = true;  // this iteration's verdicts still hold (same connectivity)
  uint32_t passed_q = 0;
  lazy_admissible_pass1(ctx, dm, c, s, p, passed_q, tested);
  const uint32_t total = conflict_pass2(ctx, dm, c, s);  // counters[3] counts both rounds
  run(ctx, "collapse_verdicts.cl", "merge_rounds_edges", c.ne, arg("ne", c.ne), arg("fin1", s.fin1), arg("dir1", s.dir1), arg("fin", s.fin), arg("dir", s.dir));
  run(ctx, "collapse_verdicts.cl", "merge_rounds_vertices", dm.nv, arg("nv", dm.nv), arg("vaff1", s.vaff1), arg("vaff", s.vaff));
  return total;
}

void remember_for_carry(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s) {
  s.update_next = true;
  ensure(s.vdirty, ctx, dm.nv);
  run(ctx, "collapse_verdicts.cl", "verdict_dirty", dm.nv, arg("nv", dm.nv), arg("vaff", s.vaff), arg("nb_off", c.nb_off), arg("nb", c.nb), arg("vdirty", s.vdirty));
  s.prev_nv = dm.nv;
  s.prev_nt = dm.nt;
}

void note_compaction(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s) {
  // collapse_and_compact left keep flags in c.count and new indices in c.cursor (old numbering)
  ensure(s.vold, ctx, dm.nv);
  ensure(s.ndirty, ctx, dm.nv);
  ensure(s.dirty_flags, ctx, dm.nv);
  run(ctx, "collapse_verdicts.cl", "verdict_vertex_old", s.prev_nv, arg("nv_prev", s.prev_nv), arg("keep", c.count), arg("newidx", c.cursor), arg("vdirty", s.vdirty), arg("vold", s.vold), arg("ndirty", s.ndirty), arg("dirty_flags", s.dirty_flags));
  ensure(s.told, ctx, dm.nt);
  run(ctx, "collapse_verdicts.cl", "verdict_tet_old", s.prev_nt, arg("nt_prev", s.prev_nt), arg("keep", s.tkeep), arg("newidx", s.tnew), arg("told", s.told));
  std::swap(s.prev_nb_off, c.nb_off);
  std::swap(s.prev_edge_off, c.edge_off);
  std::swap(s.prev_nb, c.nb);
  std::swap(s.prev_nb_edge, c.nb_edge);
  std::swap(s.prev_tet_nbr, c.tet_nbr);
  std::swap(s.prev_vclass, c.vclass);
  std::swap(s.prev_eflags, c.eflags);
  std::swap(s.prev_verdict, s.verdict);
  s.has_prev = true;
}

void carry_verdicts(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s) {
  ensure(s.verdict, ctx, c.ne);
  s.verdict_ready = s.has_prev;
  if (!s.has_prev) return;
  run(ctx, "collapse_verdicts.cl", "verdict_carry", dm.nv, arg("nv", dm.nv), arg("nb_off", c.nb_off), arg("nb", c.nb), arg("edge_off", c.edge_off), arg("vold", s.vold), arg("vdirty", s.vdirty), arg("prev_nb_off", s.prev_nb_off), arg("prev_nb_edge", s.prev_nb_edge), arg("prev_verdict", s.prev_verdict), arg("verdict", s.verdict));
  s.has_prev = false;
}

std::vector<uint8_t> tail_touched(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s) {
  DeviceBuffer<uint8_t> touched(ctx, std::max<size_t>(dm.nv, 1));
  run(ctx, "collapse_verdicts.cl", "tail_touched", dm.nv, arg("nv", dm.nv), arg("ndirty", s.ndirty), arg("nb_off", c.nb_off), arg("nb_edge", c.nb_edge), arg("verdict", s.verdict), arg("touched", touched));
  return touched.download_range(0, dm.nv);
}

void download_mesh(const DeviceMesh& dm, Mesh& mesh) {
  mesh.points = dm.points.download_range(0, size_t(dm.nv) * 3);
  mesh.tets = dm.tets.download_range(0, size_t(dm.nt) * 4);
  for (size_t l = 0; l < mesh.tet_labels.size(); ++l) mesh.tet_labels[l].values = dm.labels[l].download_range(0, dm.nt);
  auto unpack = [](std::vector<Field>& fields, const DeviceBuffer<double>& buf, uint32_t comps, uint32_t count) {
    std::vector<double> packed = buf.download_range(0, size_t(count) * comps);
    uint32_t c0 = 0;
    for (Field& f : fields) {
      f.values.assign(size_t(count) * f.components, 0.0);
      for (uint32_t i = 0; i < count; ++i)
        for (int c = 0; c < f.components; ++c) f.values[size_t(i) * f.components + c] = packed[size_t(i) * comps + c0 + c];
      c0 += uint32_t(f.components);
    }
  };
  unpack(mesh.vertex_fields, dm.vfields, dm.vfield_comps, dm.nv);
  unpack(mesh.tet_fields, dm.tfields, dm.tfield_comps, dm.nt);
}

void build_connectivity(Context& ctx, DeviceMesh& dm, Connectivity& c, const StageParams& p, EdgeState* carry) {
  const std::string F = "collapse_connectivity.cl";
  const uint32_t nv = dm.nv, nt = dm.nt;
  ensure(c.count, ctx, nv);
  ensure(c.cursor, ctx, nv);
  // rings and tet_nbr carried through the compaction (collapse_update.cl)
  const bool updated = carry && carry->has_prev && carry->has_update;
  // the rings are sorted: carried (updated) or the host's (the first build with cpu_tuning)
  const bool sorted = updated || dm.has_rings;
  if (updated) {
    std::swap(c.vt_off, carry->upd_vt_off);
    std::swap(c.vt, carry->upd_vt);
    std::swap(c.tet_nbr, carry->upd_tet_nbr);
    carry->has_update = false;
  } else if (dm.has_rings) {
    std::swap(c.vt_off, dm.vt_off);
    std::swap(c.vt, dm.vt);
    dm.has_rings = false;
  } else {
    c.count.fill(0);
    c.cursor.fill(0);
    ensure(c.vt, ctx, size_t(nt) * 4);
    run(ctx, F, "conn_count", nt, arg("tets", dm.tets), arg("nt", nt), arg("count", c.count));
    scan_offsets(ctx, c.count, c.vt_off, nv);
    run(ctx, F, "conn_scatter", nt, arg("tets", dm.tets), arg("nt", nt), arg("vt_off", c.vt_off), arg("cursor", c.cursor), arg("vt", c.vt));
  }
  ensure(c.scratch, ctx, size_t(nt) * 12);
  ensure(c.up_count, ctx, nv);
  // c.count is reused for |N(v)|
  const bool cy = carry && carry->has_prev;
  const cl_int ci = cy ? 1 : 0;
  // carried data when cy (collapse_verdicts.cl), placeholders otherwise
  const cl::Buffer& nd = cy ? carry->ndirty.buffer() : c.count.buffer();
  const cl::Buffer& vo = cy ? carry->vold.buffer() : c.count.buffer();
  const cl::Buffer& vm = cy ? carry->vmap.buffer() : c.count.buffer();
  const cl::Buffer& pno = cy ? carry->prev_nb_off.buffer() : c.count.buffer();
  const cl::Buffer& pnb = cy ? carry->prev_nb.buffer() : c.count.buffer();
  run(ctx, F, "conn_ring_sort_and_gather", nv, arg("tets", dm.tets), arg("nv", nv), arg("vt_off", c.vt_off), arg("vt", c.vt), arg("scratch", c.scratch), arg("nb_count", c.count), arg("up_count", c.up_count), arg("sort", cl_int(sorted ? 0 : 1)), arg("carry", ci), arg("ndirty", nd), arg("vold", vo), arg("vmap", vm), arg("prev_nb_off", pno), arg("prev_nb", pnb), arg("rename", cl_int(updated ? 1 : 0)), arg("prev_vaff", updated ? carry->vaff.buffer() : c.count.buffer()));
  uint32_t nnb = scan_offsets(ctx, c.count, c.nb_off, nv);
  c.ne = scan_offsets(ctx, c.up_count, c.edge_off, nv);
  ensure(c.nb, ctx, nnb);
  ensure(c.nb_edge, ctx, nnb);
  ensure(c.edges, ctx, size_t(c.ne) * 2);
  run(ctx, F, "conn_write_neighbours", nv, arg("nv", nv), arg("vt_off", c.vt_off), arg("scratch", c.scratch), arg("nb_off", c.nb_off), arg("edge_off", c.edge_off), arg("nb", c.nb), arg("nb_edge", c.nb_edge), arg("edges", c.edges));
  run(ctx, F, "conn_lower_edges", nv, arg("nv", nv), arg("nb_off", c.nb_off), arg("nb", c.nb), arg("edge_off", c.edge_off), arg("nb_edge", c.nb_edge), arg("carry", ci), arg("ndirty", nd), arg("vold", vo), arg("prev_nb_off", pno), arg("prev_edge_off", cy ? carry->prev_edge_off.buffer() : c.count.buffer()), arg("prev_nb_edge", cy ? carry->prev_nb_edge.buffer() : c.count.buffer()));
  ensure(c.eflags, ctx, c.ne);
  ensure(c.vflags, ctx, nv);
  ensure(c.vclass, ctx, nv);
  const cl_int use_labels = dm.has_labels && p.use_labels ? 1 : 0;
  ensure(c.tet_nbr, ctx, size_t(nt) * 4);
  // carried boundary data
  const cl::Buffer& to = cy ? carry->told.buffer() : c.vt.buffer();
  const cl::Buffer& tn = cy ? carry->tnew.buffer() : c.vt_off.buffer();
  const cl::Buffer& pt = cy ? carry->prev_tet_nbr.buffer() : c.vt.buffer();
  const cl::Buffer& pvc = cy ? carry->prev_vclass.buffer() : c.vflags.buffer();
  const cl::Buffer& pef = cy ? carry->prev_eflags.buffer() : c.vflags.buffer();
  const cl::Buffer& pne = cy ? carry->prev_nb_edge.buffer() : c.nb_edge.buffer();
  if (updated) {
    // c.tet_nbr taken over above
  } else if (cy) {
    run(ctx, F, "conn_tet_neighbours_carry", nt, arg("nt", nt), arg("tets", dm.tets), arg("tet_nbr", c.tet_nbr), arg("ndirty", nd), arg("told", to), arg("tnew", tn), arg("prev_tet_nbr", pt));
    // the full matching only for the dirty vertices
    ensure(c.dirty_list, ctx, nv);
    const uint32_t nd_count = dev::compact_indices(ctx, carry->dirty_flags, c.dirty_list, nv);
    run(ctx, F, "conn_tet_neighbours", nd_count, arg("n", nd_count), arg("tets", dm.tets), arg("vt_off", c.vt_off), arg("vt", c.vt), arg("tet_nbr", c.tet_nbr), arg("use_list", cl_int(1)), arg("list", c.dirty_list));
  } else {
    run(ctx, F, "conn_tet_neighbours", nv, arg("n", nv), arg("tets", dm.tets), arg("vt_off", c.vt_off), arg("vt", c.vt), arg("tet_nbr", c.tet_nbr), arg("use_list", cl_int(0)), arg("list", c.vt_off));
  }
  c.up_count.fill(0);  // scratch reuse (its scan is done): S bits per vertex
  ensure(c.owns_s, ctx, nt);
  ensure(c.smask, ctx, nt);
  static std::atomic<uint64_t> generations{0};  // unique across Connectivity objects
  c.generation = ++generations;
  run(ctx, F, "conn_vertex_flags_faces", nt, arg("nt", nt), arg("tets", dm.tets), arg("tet_nbr", c.tet_nbr), arg("labels", primary_labels(dm)), arg("use_labels", use_labels), arg("bits", c.up_count), arg("owns_s", c.owns_s), arg("smask", c.smask));
  run(ctx, F, "conn_vertex_flags", nv, arg("nv", nv), arg("bits", c.up_count), arg("vflags", c.vflags));
  run(ctx, F, "conn_surface_flags", nv, arg("nv", nv), arg("tets", dm.tets), arg("vt_off", c.vt_off), arg("vt", c.vt), arg("tet_nbr", c.tet_nbr), arg("labels", primary_labels(dm)), arg("use_labels", use_labels), arg("pts", dm.points), arg("eps_r", p.eps_r), arg("eps_f", p.eps_f), arg("nb_off", c.nb_off), arg("nb", c.nb), arg("edge_off", c.edge_off), arg("vflags", c.vflags), arg("smask", c.smask), arg("eflags", c.eflags), arg("vclass", c.vclass), arg("carry", ci), arg("ndirty", nd), arg("vold", vo), arg("prev_nb_off", pno), arg("prev_nb", pnb), arg("prev_nb_edge", pne), arg("prev_eflags", pef), arg("prev_vclass", pvc));
}

namespace {
uint32_t counter(EdgeState& s, int i) {
  uint32_t v = 0;
  s.counters.download(&v, 1, size_t(i));
  return v;
}
}  // namespace

uint32_t cost_and_mark(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p) {
  ensure(s.counters, ctx, 6);
  s.counters.fill(0);
  ensure(s.cost, ctx, c.ne);
  ensure(s.marked, ctx, c.ne);
  // with a user cost, its function comes before the kernel (see collapse_cost.cl)
  Kernel k = p.cost_source.empty()
                     ? kernel(ctx, "collapse_cost.cl", "cost_and_mark")
                     : user_kernel(ctx, "user cost", "collapse_cost.cl", "cost_and_mark",
                                   "#line 1 \"cost_cl_source\"\n" + p.cost_source, "-DTCC_USER_COST");
  const cl_int mask_mode = dm.has_mask ? p.mask_mode : 0;
  k.set(arg("ne", c.ne), arg("edges", c.edges), arg("pts", dm.points), arg("vfield", dm.vfields), arg("vfield_stride", dm.vfield_comps), arg("has_vfield", dm.vfield_comps > 0 ? 1 : 0), arg("vmask", dm.vmask), arg("mask_mode", mask_mode), arg("target", p.target), arg("cost", s.cost), arg("marked", s.marked), arg("counters", s.counters));
  k.launch(ctx, c.ne);
  return counter(s, 0);
}

namespace {
// The quality guard's per-tet qualities of the current mesh (a placeholder when it is off):
// once per connectivity; after a compaction only the tets that changed (tet_quality_carry).
const cl::Buffer& tet_qualities(Context& ctx, DeviceMesh& dm, const Connectivity& c, EdgeState& s,
                                const StageParams& p) {
  if (!(p.min_quality > 0)) {
    ensure(s.tet_quality, ctx, 1);
    s.quality_carried = false;
    s.quality_generation = 0;
    return s.tet_quality.buffer();
  }
  if (s.quality_generation == c.generation && s.tet_quality.size() == dm.nt) return s.tet_quality.buffer();
  const cl_int only_missing = s.quality_carried && s.tet_quality.size() == dm.nt ? 1 : 0;
  ensure(s.tet_quality, ctx, dm.nt);
  run(ctx, "collapse_admissible.cl", "tet_quality", dm.nt, arg("nt", dm.nt), arg("tets", dm.tets), arg("pts", dm.points), arg("quality", s.tet_quality), arg("only_missing", only_missing));
  s.quality_carried = false;
  s.quality_generation = c.generation;
  return s.tet_quality.buffer();
}
}  // namespace

uint32_t admissible(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p) {
  s.in_place = false;
  ensure(s.adm, ctx, c.ne);
  ensure(s.dir, ctx, c.ne);
  ensure(s.reason, ctx, c.ne);
  const cl_int use_labels = dm.has_labels && p.use_labels ? 1 : 0;
  run_stage(ctx, p, "collapse_admissible.cl", "admissible", c.ne, arg("ne", c.ne), arg("edges", c.edges), arg("marked", s.marked), arg("tets", dm.tets), arg("vt_off", c.vt_off), arg("vt", c.vt), arg("tet_nbr", c.tet_nbr), arg("nb_off", c.nb_off), arg("nb", c.nb), arg("nb_edge", c.nb_edge), arg("labels", primary_labels(dm)), arg("use_labels", use_labels), arg("pts", dm.points), arg("vfield", dm.vfields), arg("vfield_stride", dm.vfield_comps), arg("vflags", c.vflags), arg("vclass", c.vclass), arg("eflags", c.eflags), arg("mode", p.mode), arg("paper_rule", p.paper_rule ? 1 : 0), arg("eps_v", p.eps_v), arg("q_min", p.min_quality), arg("tet_quality", tet_qualities(ctx, dm, c, s, p)), arg("adm", s.adm), arg("edge_dir", s.dir), arg("reason", s.reason), arg("counters", s.counters));
  return counter(s, 1);
}

namespace {
// Compacts the candidate edges (flags[e] != 0) into s.cand_edges and prepares the per-slot
// rival storage; returns their number.
uint32_t prepare_candidates(Context& ctx, EdgeState& s, const DeviceBuffer<uint32_t>& flags, uint32_t ne) {
  ensure(s.cand_edges, ctx, ne);
  const uint32_t n = dev::compact_indices(ctx, flags, s.cand_edges, ne);
  ensure(s.rcount, ctx, n);
  ensure(s.rivals, ctx, size_t(n) * 16);  // TCC_RIVALS
  s.rcount.fill(0xffffffffu);             // TCC_UNSCANNED
  return n;
}

// The worklist loop of the conflict rounds: round(n, first, cur) enqueues one round over the n
// entries of s.work[cur] (all candidates when first), which appends those still undecided to
// s.work[1 - cur] via s.work_n; repeats until none is left. Every round decides at least the
// undecided candidate of smallest (cost, index), so this terminates. When `tail` is given,
// the rounds left once at most tail_size entries remain go to tail(n, first, cur), which runs
// them all in one launch.
template <class Round, class Tail = void (*)(uint32_t, cl_int, int)>
void rounds(Context& ctx, EdgeState& s, uint32_t n, const char* what, const Round& round, const Tail* tail = nullptr,
            uint32_t tail_size = 0) {
  ensure(s.work_n, ctx, 1);
  ensure(s.work[0], ctx, n);
  ensure(s.work[1], ctx, n);
  int cur = 0;
  for (cl_int first = 1; n > 0; first = 0) {
    s.work_n.fill(0);
    auto t0 = std::chrono::steady_clock::now();
    if (tail && n <= tail_size) {
      (*tail)(n, first, cur);
      if (kProfile) {
        ctx.finish();
        std::fprintf(stderr, "  %-28s n=%-9u %8.4f s (all remaining rounds)\n", what, n,
                     std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      }
      return;
    }
    round(n, first, cur);
    uint32_t next = 0;
    s.work_n.download(&next, 1);
    if (kProfile)
      std::fprintf(stderr, "  %-28s n=%-9u %8.4f s\n", what, n,
                   std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    n = next;
    cur = 1 - cur;
  }
}

// Pass-1 rounds (collapse_conflict.cl: pass1_claim, then `decide`, whose arguments other than
// the round's are already set) over the n candidates of s.cand_edges until none is left
// undecided. s.vaff must be -1 everywhere; it ends with the IN edge at each vertex.
void pass1_rounds(Context& ctx, Kernel& decide, EdgeState& s, const Connectivity& c, uint32_t nv, uint32_t n,
                  const char* what) {
  ensure(s.slot[0], ctx, nv);
  ensure(s.slot[1], ctx, nv);
  s.slot[0].fill(-1);
  s.slot[1].fill(-1);
  Kernel claim = kernel(ctx, "collapse_conflict.cl", "pass1_claim");
  auto round = [&](uint32_t m, cl_int first, int cur) {
    claim.set(arg("n", m), arg("first", first), arg("list", s.work[cur]), arg("cand", s.cand_edges), arg("edges", c.edges), arg("cost", s.cost), arg("vaff", s.vaff), arg("slot", s.slot[cur]), arg("state", s.state));
    claim.launch(ctx, m);
    decide.set(arg("n", m), arg("first", first), arg("list", s.work[cur]), arg("next", s.work[1 - cur]), arg("next_n", s.work_n), arg("cand", s.cand_edges), arg("edges", c.edges), arg("slot", s.slot[cur]), arg("slot_next", s.slot[1 - cur]), arg("state", s.state), arg("vaff", s.vaff));
    decide.launch(ctx, m);
  };
  rounds(ctx, s, n, what, round);
}
}  // namespace

namespace {
// The vertex part of a per-round step of the lazy filter and of the greedy selection, after its
// decisions (cl/collapse_admissible.cl): the slots of the cnt[2] listed vertices (s.dlist) anew
// in the order `order`, then the edges now first at both end points to turn list 1 - cur
// (counted in s.work_n[1 - cur]; s.work_n[3]: those without a verdict). `recompute` and `turns`
// are the kernels lazy_p1_recompute and lazy_p1_turns, made once by the caller. With slotp (the
// matching selection) the slots' priorities are kept there too.
void vertex_part(Context& ctx, EdgeState& s, const Connectivity& c, Kernel& recompute, Kernel& turns,
                 const DeviceBuffer<double>& order, int cur, cl_uint round, DeviceBuffer<double>* slotp = nullptr,
                 bool waiting = false) {
  uint32_t nd = 0;
  s.work_n.download(&nd, 1, 2);
  recompute.set(arg("n", nd), arg("dlist", s.dlist), arg("nb_off", c.nb_off), arg("nb_edge", c.nb_edge), arg("state", s.state), arg("cost", order), arg("slot", s.slot[0]), arg("slotp", slotp ? slotp->buffer() : order.buffer()), arg("with_slotp", cl_int(slotp ? 1 : 0)));
  recompute.launch(ctx, nd);
  turns.set(arg("n", nd), arg("dlist", s.dlist), arg("edges", c.edges), arg("slot", s.slot[0]), arg("tlist", s.work[1 - cur]), arg("cnt", s.work_n), arg("which", cl_uint(1 - cur)), arg("queued", s.queued), arg("round", round + 1), arg("verdict", s.verdict), arg("waiting", cl_int(waiting ? 1 : 0)), arg("whead", waiting ? s.whead.buffer() : s.slot[0].buffer()), arg("wnext", waiting ? s.wnext.buffer() : s.slot[0].buffer()));
  turns.launch(ctx, nd);
}

// Pass 1 of the lazy filter over the candidates (s.cand[e] != 0 for e < ne; lazy_init made them
// and their first claims in s.slot[0]; cl/collapse_admissible.cl, lazy_p1_*): rounds over the
// turn list until it is empty. `decide` and `loop` have the test's arguments set. s.vaff must
// be -1 everywhere. The rounds run in one work-group (lazy_p1_loop) while the turn list holds
// at most p.loop_tests edges to test (the others take the verdict carried from the previous
// iteration, cheap) and at most p.loop_turns in all; the loop hands back to the per-round
// kernels when a list has more than p.loop_exit_tests to test.
void lazy_p1_rounds(Context& ctx, EdgeState& s, const Connectivity& c, Kernel& decide, Kernel& loop,
                    const StageParams& p) {
  const std::string A = "collapse_admissible.cl";
  const uint32_t n = c.ne;  // bounds the candidates
  ensure(s.queued, ctx, c.ne);
  ensure(s.work[0], ctx, n);
  ensure(s.work[1], ctx, n);
  ensure(s.dlist, ctx, 2 * size_t(n) + 1);  // an edge is listed at most twice per pass
  ensure(s.work_n, ctx, 4);
  ensure(s.resume, ctx, 3);
  s.queued.fill(0xffffffffu);
  s.work_n.fill(0);
  if (n == 0) return;
  run(ctx, A, "lazy_p1_first_turns", n, arg("ne", n), arg("cand", s.cand), arg("edges", c.edges), arg("slot", s.slot[0]), arg("tlist", s.work[0]), arg("cnt", s.work_n), arg("verdict", s.verdict));
  uint32_t cnt[4];
  s.work_n.download(cnt, 4);
  uint32_t nt = cnt[0], nu = cnt[3];
  Kernel recompute = kernel(ctx, A, "lazy_p1_recompute"), turns = kernel(ctx, A, "lazy_p1_turns");
  int cur = 0;  // the list of this round
  cl_uint round = 0;
  while (nt > 0) {
    auto t0 = std::chrono::steady_clock::now();
    s.work_n.fill(0);
    const bool one_group = nu <= p.loop_tests && nt <= p.loop_turns;
    if (one_group) {
      s.resume.fill(0);
      loop.set(arg("n", nt), arg("cur", cl_int(cur)), arg("round", round), arg("t0", s.work[0]), arg("t1", s.work[1]), arg("cnt", s.work_n), arg("dlist", s.dlist), arg("queued", s.queued), arg("edges", c.edges), arg("cost", s.cost), arg("slot", s.slot[0]), arg("state", s.state), arg("vaff", s.vaff), arg("max_tests", cl_uint(p.loop_exit_tests)), arg("resume", s.resume));
      loop.launch_one_group(ctx);
      uint32_t r[3];
      s.resume.download(r, 3);
      nt = r[0];  // 0: every round done; else the loop stopped before a list with many to test
      nu = UINT32_MAX;
      cur = int(r[1]);
      round = r[2];
    } else {
      decide.set(arg("n", nt), arg("tlist", s.work[cur]), arg("edges", c.edges), arg("state", s.state), arg("vaff", s.vaff), arg("slot", s.slot[0]), arg("dlist", s.dlist), arg("cnt", s.work_n));
      decide.launch(ctx, nt);
      vertex_part(ctx, s, c, recompute, turns, s.cost, cur, round);
      s.work_n.download(cnt, 4);
      nt = cnt[1 - cur];
      nu = cnt[3];
      cur = 1 - cur;
      ++round;
    }
    if (kProfile) {
      ctx.finish();
      std::fprintf(stderr, "  %-28s n=%-9u %8.4f s%s\n", "lazy_p1_round", nt,
                   std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
                   one_group ? " (one work-group)" : "");
    }
  }
}
}  // namespace

uint32_t conflict_pass1(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s) {
  const std::string F = "collapse_conflict.cl";
  ensure(s.p1, ctx, c.ne);
  ensure(s.state, ctx, c.ne);
  ensure(s.vaff, ctx, dm.nv);
  s.vaff.fill(-1);
  run(ctx, F, "conflict_init", c.ne, arg("ne", c.ne), arg("adm", s.adm), arg("state", s.state));
  ensure(s.cand_edges, ctx, c.ne);
  const uint32_t n = dev::compact_indices(ctx, s.adm, s.cand_edges, c.ne);
  Kernel decide = kernel(ctx, F, "conflict_pass1_decide");
  pass1_rounds(ctx, decide, s, c, dm.nv, n, "conflict_pass1_decide");
  run(ctx, F, "conflict_pass1_finish", c.ne, arg("ne", c.ne), arg("edges", c.edges), arg("state", s.state), arg("p1", s.p1), arg("vaff", s.vaff), arg("counters", s.counters));
  return counter(s, 2);
}

namespace {
// The start shared by the lazy filter and the greedy selection: buffers, the verdicts, lazy_init
// (candidates, Q, carried refusals, the first claims in s.slot[0] in the order of `order`), and
// the test's arguments of each kernel of `tests` (from the given argument index on).
void lazy_start(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                const DeviceBuffer<double>& order, std::initializer_list<Kernel*> tests,
                bool keep_refused = false) {
  const std::string A = "collapse_admissible.cl";
  s.in_place = false;
  ensure(s.dir, ctx, c.ne);
  ensure(s.reason, ctx, c.ne);
  ensure(s.cand, ctx, c.ne);
  ensure(s.p1, ctx, c.ne);
  ensure(s.state, ctx, c.ne);
  ensure(s.vaff, ctx, dm.nv);
  s.vaff.fill(-1);
  const cl_int use_labels = dm.has_labels && p.use_labels ? 1 : 0;
  const cl_int mode = p.mode, paper_rule = p.paper_rule ? 1 : 0;
  ensure(s.verdict, ctx, c.ne);
  if (!s.verdict_ready) s.verdict.fill(0xff);  // TCC_VERDICT_UNKNOWN
  s.verdict_ready = false;
  const bool restrict_clean = s.restrict_clean;
  s.restrict_clean = false;
  ensure(s.slot[0], ctx, dm.nv);
  s.slot[0].fill(-1);
  run_stage(ctx, p, A, "lazy_init", c.ne, arg("ne", c.ne), arg("edges", c.edges), arg("marked", s.marked), arg("vflags", c.vflags), arg("vclass", c.vclass), arg("eflags", c.eflags), arg("mode", mode), arg("paper_rule", paper_rule), arg("pts", dm.points), arg("vfield", dm.vfields), arg("vfield_stride", dm.vfield_comps), arg("state", s.state), arg("edge_dir", s.dir), arg("reason", s.reason), arg("cand", s.cand), arg("counters", s.counters), arg("restrict_clean", cl_int(restrict_clean ? 1 : 0)), arg("vdirty", restrict_clean ? s.vdirty.buffer() : c.vflags.buffer()), arg("verdict", s.verdict), arg("cost", order), arg("slot", s.slot[0]), arg("keep_refused", cl_int(keep_refused ? 1 : 0)));
  const cl::Buffer& quality = tet_qualities(ctx, dm, c, s, p);
  for (Kernel* k : tests)
    k->set(arg("tets", dm.tets), arg("vt_off", c.vt_off), arg("vt", c.vt), arg("tet_nbr", c.tet_nbr),
           arg("nb_off", c.nb_off), arg("nb", c.nb), arg("nb_edge", c.nb_edge), arg("labels", primary_labels(dm)),
           arg("use_labels", use_labels), arg("pts", dm.points), arg("vfield", dm.vfields),
           arg("vfield_stride", dm.vfield_comps), arg("vflags", c.vflags), arg("vclass", c.vclass),
           arg("eflags", c.eflags), arg("mode", mode), arg("paper_rule", paper_rule), arg("eps_v", p.eps_v),
           arg("q_min", p.min_quality), arg("tet_quality", quality), arg("edge_dir", s.dir), arg("reason", s.reason),
           arg("counters", s.counters), arg("verdict", s.verdict));
}
}  // namespace

uint32_t lazy_admissible_pass1(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                               uint32_t& passed_q, uint32_t& tested) {
  const std::string A = "collapse_admissible.cl";
  // the test's arguments, the same for the per-round kernel and the one-work-group loop
  Kernel decide = stage_kernel(ctx, p, A, "lazy_p1_decide"), loop = stage_kernel(ctx, p, A, "lazy_p1_loop");
  lazy_start(ctx, dm, c, s, p, s.cost, {&decide, &loop});
  lazy_p1_rounds(ctx, s, c, decide, loop, p);
  run(ctx, "collapse_conflict.cl", "conflict_pass1_finish", c.ne, arg("ne", c.ne), arg("edges", c.edges), arg("state", s.state), arg("p1", s.p1), arg("vaff", s.vaff), arg("counters", s.counters));
  uint32_t cnt[6];
  s.counters.download(cnt, 6);
  passed_q = cnt[5];
  tested = cnt[4];
  return cnt[2];
}

namespace {
// The priority of the greedy and matching selections: greedy_priority with levels > 0, else the
// cost.
const DeviceBuffer<double>& selection_priority(Context& ctx, Connectivity& c, EdgeState& s, const StageParams& p) {
  if (!(p.priority_levels > 0)) return s.cost;
  ensure(s.prio, ctx, c.ne);
  run(ctx, "collapse_admissible.cl", "greedy_priority", c.ne, arg("ne", c.ne), arg("cost", s.cost), arg("marked", s.marked), arg("target", p.target), arg("levels", p.priority_levels), arg("prio", s.prio));
  return s.prio;
}

// The buffers of the greedy and matching selections' rounds, set for the first round.
void selection_buffers(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s) {
  ensure(s.fin, ctx, c.ne);
  ensure(s.blocker, ctx, c.ne);
  ensure(s.queued, ctx, c.ne);
  ensure(s.vstamp, ctx, dm.nv);
  ensure(s.inlist, ctx, c.ne);
  ensure(s.dlist, ctx, std::max<size_t>(dm.nv, 1));  // a vertex is listed at most once per round
  ensure(s.work[0], ctx, c.ne);
  ensure(s.work[1], ctx, c.ne);
  ensure(s.work_n, ctx, 5);
  ensure(s.resume, ctx, 3);
  ensure(s.whead, ctx, std::max<size_t>(dm.nv, 1));  // the waiting lists (tcc_wait_on, collapse_select.h)
  ensure(s.wnext, ctx, c.ne);
  s.whead.fill(-1);
  s.blocker.fill(-1);
  s.queued.fill(0xffffffffu);
  s.vstamp.fill(0xffffffffu);
  s.work_n.fill(0);
}

// The rounds of the greedy and matching selections (after lazy_start, selection_buffers and the
// first claims): the first turn list, then round after round until none is left, each either
// the per-round kernels (`round(nt, cur, round)`, which leave the next turn list's length in
// s.work_n[1 - cur]) or, once a turn list holds at most p.greedy_loop_size edges, the loop in
// one work-group (`loop(nt, cur, round)`, which stops before a turn list longer than
// p.greedy_loop_exit and leaves where in s.resume); then greedy_finish and the counts (passed_q
// and tested as lazy_admissible_pass1; returns the number taken).
template <class Round, class Loop>
uint32_t selection_rounds(Context& ctx, Connectivity& c, EdgeState& s, const StageParams& p, const char* name,
                          const Round& one_round, const Loop& loop, uint32_t& passed_q, uint32_t& tested) {
  const std::string A = "collapse_admissible.cl";
  run(ctx, A, "lazy_p1_first_turns", c.ne, arg("ne", c.ne), arg("cand", s.cand), arg("edges", c.edges), arg("slot", s.slot[0]), arg("tlist", s.work[0]), arg("cnt", s.work_n), arg("verdict", s.verdict));
  uint32_t nt = 0;
  s.work_n.download(&nt, 1);
  int cur = 0;  // the turn list of this round
  for (cl_uint round = 0; nt > 0; ++round) {
    auto t0 = std::chrono::steady_clock::now();
    s.work_n.fill(0);
    const bool one_group = nt <= p.greedy_loop_size;
    if (one_group) {
      s.resume.fill(0);
      loop(nt, cur, round);
      uint32_t r[3];
      s.resume.download(r, 3);
      nt = r[0];  // 0: every round done; else the loop stopped before a long turn list
      cur = int(r[1]);
      round = r[2] - 1;
    } else {
      one_round(nt, cur, round);
      s.work_n.download(&nt, 1, size_t(1 - cur));
      cur = 1 - cur;
    }
    if (kProfile) {
      ctx.finish();
      std::fprintf(stderr, "  %-28s n=%-9u %8.4f s%s\n", name, nt,
                   std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
                   one_group ? " (one work-group)" : "");
    }
  }
  run(ctx, A, "greedy_finish", c.ne, arg("ne", c.ne), arg("state", s.state), arg("p1", s.p1), arg("fin", s.fin), arg("counters", s.counters));
  uint32_t cnt[6];
  s.counters.download(cnt, 6);
  passed_q = cnt[5];
  tested = cnt[4];
  return cnt[3];
}
}  // namespace

uint32_t greedy_selection(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                          uint32_t& passed_q, uint32_t& tested) {
  const std::string A = "collapse_admissible.cl";
  Kernel decide = stage_kernel(ctx, p, A, "greedy_decide"), loop = stage_kernel(ctx, p, A, "greedy_loop");
  // the priority first: lazy_init claims the first slots in its order
  const DeviceBuffer<double>& prio = selection_priority(ctx, c, s, p);
  lazy_start(ctx, dm, c, s, p, prio, {&decide, &loop});
  selection_buffers(ctx, dm, c, s);
  const cl_int W = p.waiting_lists ? 1 : 0;
  Kernel block = kernel(ctx, A, "greedy_block"), recompute = kernel(ctx, A, "lazy_p1_recompute"),
             turns = kernel(ctx, A, "lazy_p1_turns");
  auto one_round = [&](uint32_t nt, int cur, cl_uint round) {
    decide.set(arg("n", nt), arg("cur", cl_uint(cur)), arg("tlist", s.work[cur]), arg("tnext", s.work[1 - cur]), arg("cnt", s.work_n), arg("edges", c.edges), arg("prio", prio), arg("slot", s.slot[0]), arg("blocker", s.blocker), arg("queued", s.queued), arg("round", round), arg("inlist", s.inlist), arg("vstamp", s.vstamp), arg("dlist", s.dlist), arg("state", s.state), arg("vaff", s.vaff), arg("waiting", W), arg("whead", s.whead), arg("wnext", s.wnext));
    decide.launch(ctx, nt);
    block.set(arg("inlist", s.inlist), arg("cnt", s.work_n), arg("edges", c.edges), arg("nb_off", c.nb_off), arg("nb", c.nb), arg("nb_edge", c.nb_edge), arg("slot", s.slot[0]), arg("vstamp", s.vstamp), arg("round", round), arg("dlist", s.dlist), arg("state", s.state));
    block.launch(ctx, nt);  // over the round's taken edges (cnt[4] <= nt)
    vertex_part(ctx, s, c, recompute, turns, prio, cur, round, nullptr, p.waiting_lists);
  };
  auto in_one_group = [&](uint32_t nt, int cur, cl_uint round) {
    loop.set(arg("n", nt), arg("cur", cl_int(cur)), arg("round", round), arg("t0", s.work[0]), arg("t1", s.work[1]), arg("cnt", s.work_n), arg("edges", c.edges), arg("prio", prio), arg("slot", s.slot[0]), arg("blocker", s.blocker), arg("queued", s.queued), arg("inlist", s.inlist), arg("vstamp", s.vstamp), arg("dlist", s.dlist), arg("state", s.state), arg("vaff", s.vaff), arg("max_n", p.greedy_loop_exit), arg("resume", s.resume), arg("waiting", W), arg("whead", s.whead), arg("wnext", s.wnext));
    loop.launch_one_group(ctx);
  };
  return selection_rounds(ctx, c, s, p, "greedy_round", one_round, in_one_group, passed_q, tested);
}

uint32_t matching_selection(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                            uint32_t& passed_q, uint32_t& tested) {
  const std::string A = "collapse_admissible.cl", M = "collapse_matching.cl";
  Kernel decide = stage_kernel(ctx, p, M, "match_decide"), apply = stage_kernel(ctx, p, M, "match_apply"),
             loop = stage_kernel(ctx, p, M, "match_loop");
  // the priority first: lazy_init claims the first slots in its order
  const DeviceBuffer<double>& prio = selection_priority(ctx, c, s, p);
  // the test's arguments (TCC_MATCH_PARAMS): the lazy filter's, then the live test's
  lazy_start(ctx, dm, c, s, p, prio, {&decide, &apply, &loop}, true);
  s.in_place = true;
  ensure(s.tdead, ctx, std::max<size_t>(dm.nt, 1));
  ensure(s.tkill, ctx, std::max<size_t>(dm.nt, 1));
  ensure(s.dround, ctx, c.ne);
  s.tdead.fill(0);
  for (Kernel* k : {&decide, &apply, &loop})
    k->set(arg("eps_r", p.eps_r), arg("eps_f", p.eps_f), arg("tdead", s.tdead));
  selection_buffers(ctx, dm, c, s);
  ensure(s.spec, ctx, c.ne);
  s.spec.fill(p.match_early_tests ? 0 : 1);  // 1: the early test counts as done
  ensure(s.slotp, ctx, dm.nv);
  run(ctx, A, "slot_priority", dm.nv, arg("nv", dm.nv), arg("slot", s.slot[0]), arg("prio", prio), arg("slotp", s.slotp));
  const cl_int W = p.waiting_lists ? 1 : 0;
  Kernel recompute = kernel(ctx, A, "lazy_p1_recompute"), turns = kernel(ctx, A, "lazy_p1_turns");
  auto one_round = [&](uint32_t nt, int cur, cl_uint round) {
    decide.set(arg("n", nt), arg("cur", cl_uint(cur)), arg("tlist", s.work[cur]), arg("tnext", s.work[1 - cur]), arg("cnt", s.work_n), arg("edges", c.edges), arg("prio", prio), arg("slot", s.slot[0]), arg("slotp", s.slotp), arg("blocker", s.blocker), arg("spec", s.spec), arg("dround", s.dround), arg("queued", s.queued), arg("round", round), arg("inlist", s.inlist), arg("vstamp", s.vstamp), arg("dlist", s.dlist), arg("state", s.state), arg("vaff", s.vaff), arg("waiting", W), arg("whead", s.whead), arg("wnext", s.wnext));
    decide.launch(ctx, nt);
    apply.set(arg("inlist", s.inlist), arg("cnt", s.work_n), arg("edges", c.edges), arg("slot", s.slot[0]), arg("vstamp", s.vstamp), arg("round", round), arg("dlist", s.dlist), arg("state", s.state), arg("vaff", s.vaff), arg("tkill", s.tkill));
    apply.launch(ctx, nt);  // over the round's taken edges (cnt[4] <= nt)
    vertex_part(ctx, s, c, recompute, turns, prio, cur, round, &s.slotp, p.waiting_lists);
  };
  auto in_one_group = [&](uint32_t nt, int cur, cl_uint round) {
    loop.set(arg("n", nt), arg("cur", cl_int(cur)), arg("round", round), arg("t0", s.work[0]), arg("t1", s.work[1]), arg("cnt", s.work_n), arg("edges", c.edges), arg("prio", prio), arg("slot", s.slot[0]), arg("slotp", s.slotp), arg("blocker", s.blocker), arg("spec", s.spec), arg("dround", s.dround), arg("queued", s.queued), arg("inlist", s.inlist), arg("vstamp", s.vstamp), arg("dlist", s.dlist), arg("state", s.state), arg("vaff", s.vaff), arg("tkill", s.tkill), arg("max_n", p.greedy_loop_exit), arg("resume", s.resume), arg("waiting", W), arg("whead", s.whead), arg("wnext", s.wnext));
    loop.launch_one_group(ctx);
  };
  return selection_rounds(ctx, c, s, p, "match_round", one_round, in_one_group, passed_q, tested);
}

void matching_backup(Context& ctx, DeviceMesh& dm, EdgeState& s) {
  if (!s.points0.buffer()()) {
    s.points0 = DeviceBuffer<double>(ctx, 1);
    s.vfields0 = DeviceBuffer<double>(ctx, 1);
  }
  s.points0.copy_from(dm.points, size_t(dm.nv) * 3);
  s.vfields0.copy_from(dm.vfields, size_t(dm.nv) * dm.vfield_comps);
}

uint32_t matching_undo(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, SurfaceGuard& guard) {
  ensure(s.refused, ctx, c.ne);
  ensure(s.work_n, ctx, 5);
  s.refused.fill(0);
  s.work_n.fill(0);
  guard.refused_edges(ctx, s.refused, s.work[0], s.work_n);
  uint32_t n = 0;
  s.work_n.download(&n, 1);
  std::vector<uint32_t> undone;
  const uint32_t count = matching_undo(ctx, dm, c, s, s.work[0].download_range(0, n), &undone);
  guard.restrict_to_undone(ctx, dm, c, s, undone);  // the next guard run: only where the undo changed S
  return count;
}

uint32_t matching_undo(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s,
                       const std::vector<uint32_t>& refused, std::vector<uint32_t>* undone) {
  const std::string M = "collapse_matching.cl";
  ensure(s.refused, ctx, c.ne);
  ensure(s.undo, ctx, c.ne);
  ensure(s.reachmin, ctx, dm.nv);
  ensure(s.work_n, ctx, 5);
  s.reachmin.fill(0xffffffffu);
  // the refused flagged, and listed in s.work[0] (the undone: the refused first, then each growth)
  std::vector<uint8_t> flags(c.ne, 0);
  for (uint32_t e : refused) flags[e] = 1;
  s.refused.upload(flags);
  s.undo.upload(flags);
  uint32_t n = uint32_t(refused.size());
  s.work[0].upload(refused.data(), n);
  s.work_n.upload(&n, 1);
  // the taken edges
  ensure(s.cand_edges, ctx, c.ne);
  const uint32_t taken = dev::compact_indices(ctx, s.fin, s.cand_edges, c.ne);
  uint32_t done = 0;  // entries of work[0] whose reach is marked
  while (done < n) {
    // (the list's new part starts at done: marked through an offset sub-range of work[0])
    std::vector<uint32_t> fresh = s.work[0].download_range(done, n - done);
    s.work[1].upload(fresh.data(), fresh.size());
    run(ctx, M, "match_undo_reach", fresh.size(), arg("n", fresh.size()), arg("list", s.work[1]), arg("edges", c.edges), arg("nb_off", c.nb_off), arg("nb", c.nb), arg("dround", s.dround), arg("reachmin", s.reachmin));
    done = n;
    run(ctx, M, "match_undo_grow", taken, arg("n", taken), arg("taken", s.cand_edges), arg("edges", c.edges), arg("dround", s.dround), arg("reachmin", s.reachmin), arg("undo", s.undo), arg("list", s.work[0]), arg("count", s.work_n));
    s.work_n.download(&n, 1);
  }
  // undone in the reverse order of their rounds (then of their index: any order within a round)
  std::vector<uint32_t> order = s.work[0].download_range(0, n), rounds(n);
  if (n > 0) {  // one read of the span of dround they cover (a read each cost ~35 us on PoCL)
    const auto [lo, hi] = std::minmax_element(order.begin(), order.end());
    const std::vector<uint32_t> span = s.dround.download_range(*lo, size_t(*hi - *lo) + 1);
    for (uint32_t i = 0; i < n; ++i) rounds[i] = span[order[i] - *lo];
  }
  std::vector<uint32_t> idx(n);
  std::iota(idx.begin(), idx.end(), 0u);
  std::sort(idx.begin(), idx.end(), [&](uint32_t a, uint32_t b) {
    return rounds[a] != rounds[b] ? rounds[a] > rounds[b] : order[a] > order[b];
  });
  std::vector<uint32_t> sorted(n);
  for (uint32_t i = 0; i < n; ++i) sorted[i] = order[idx[i]];
  s.work[1].upload(sorted.data(), n);
  if (undone) *undone = sorted;
  run(ctx, M, "match_undo", 1, arg("n", n), arg("order", s.work[1]), arg("refused", s.refused), arg("edges", c.edges), arg("edge_dir", s.dir), arg("tets", dm.tets), arg("vt_off", c.vt_off), arg("vt", c.vt), arg("tet_nbr", c.tet_nbr), arg("tdead", s.tdead), arg("tkill", s.tkill), arg("pts", dm.points), arg("vfield", dm.vfields), arg("vfield_stride", dm.vfield_comps), arg("pts0", s.points0), arg("vfield0", s.vfields0), arg("vaff", s.vaff), arg("state", s.state), arg("fin", s.fin), arg("reason", s.reason));
  return n;
}

uint32_t conflict_pass2(Context& ctx, DeviceMesh&, Connectivity& c, EdgeState& s, uint32_t loop_size) {
  const std::string F = "collapse_conflict.cl";
  ensure(s.fin, ctx, c.ne);
  run(ctx, F, "conflict_pass2_init", c.ne, arg("ne", c.ne), arg("p1", s.p1), arg("state", s.state));
  const uint32_t n = prepare_candidates(ctx, s, s.p1, c.ne);
  Kernel round = kernel(ctx, F, "conflict_pass2_round"), loop = kernel(ctx, F, "conflict_pass2_loop");
  round.set(arg("edges", c.edges), arg("cost", s.cost), arg("nb_off", c.nb_off), arg("nb", c.nb), arg("vaff", s.vaff), arg("state", s.state));
  loop.set(arg("edges", c.edges), arg("cost", s.cost), arg("nb_off", c.nb_off), arg("nb", c.nb), arg("vaff", s.vaff), arg("state", s.state));
  // the last rounds (at most loop_size candidates left) in one work-group
  auto tail = [&](uint32_t m, cl_int first, int cur) {
    loop.set(arg("n", m), arg("first", first), arg("cur", cl_int(cur)), arg("l0", s.work[0]), arg("l1", s.work[1]), arg("next_n", s.work_n), arg("cand", s.cand_edges), arg("rivals", s.rivals), arg("rcount", s.rcount));
    loop.launch_one_group(ctx);
  };
  rounds(
      ctx, s, n, "conflict_pass2_round",
      [&](uint32_t m, cl_int first, int cur) {
        round.set(arg("n", m), arg("first", first), arg("list", s.work[cur]), arg("next", s.work[1 - cur]), arg("next_n", s.work_n), arg("cand", s.cand_edges), arg("rivals", s.rivals), arg("rcount", s.rcount));
        round.launch(ctx, m);
      },
      &tail, loop_size);
  run(ctx, F, "conflict_finalize", c.ne, arg("ne", c.ne), arg("edges", c.edges), arg("p1", s.p1), arg("state", s.state), arg("fin", s.fin), arg("vaff", s.vaff), arg("counters", s.counters));
  return counter(s, 3);
}

void collapse_and_compact(Context& ctx, const StageParams& p, DeviceMesh& dm, DeviceMesh& next, Connectivity& c,
                          EdgeState& s, DeviceBuffer<int32_t>& origin, uint32_t n_origin) {
  const std::string F = "collapse_compact.cl";
  const uint32_t nv = dm.nv, nt = dm.nt;
  // vertices
  DeviceBuffer<uint32_t>& vkeep = c.count;  // scratch reuse: nv entries
  DeviceBuffer<uint32_t>& vnew = c.cursor;
  run(ctx, F, "vertex_keep", nv, arg("nv", nv), arg("vaff", s.vaff), arg("edges", c.edges), arg("edge_dir", s.dir), arg("keep", vkeep));
  const uint32_t nv2 = dev::exclusive_scan(ctx, vkeep, vnew, nv);
  DeviceBuffer<int32_t>& vmap = s.vmap;  // kept for build_connectivity's carry
  ensure(vmap, ctx, nv);
  run(ctx, F, "vertex_map", nv, arg("nv", nv), arg("vaff", s.vaff), arg("edges", c.edges), arg("edge_dir", s.dir), arg("newidx", vnew), arg("keep", vkeep), arg("vmap", vmap));
  next.nv = nv2;
  ensure(next.points, ctx, size_t(nv2) * 3);
  ensure(next.vfields, ctx, size_t(nv2) * dm.vfield_comps);
  ensure(next.vmask, ctx, dm.has_mask ? nv2 : 0);
  next.vfield_comps = dm.vfield_comps;
  next.tfield_comps = dm.tfield_comps;
  next.has_mask = dm.has_mask;
  next.has_labels = dm.has_labels;
  const cl_int in_place = s.in_place ? 1 : 0;
  run_stage(ctx, p, F, "vertex_write", nv, arg("nv", nv), arg("vaff", s.vaff), arg("edges", c.edges), arg("edge_dir", s.dir), arg("keep", vkeep), arg("newidx", vnew), arg("pts", dm.points), arg("out_pts", next.points), arg("ncomp", dm.vfield_comps), arg("vfields", dm.vfields), arg("out_vfields", next.vfields), arg("has_mask", dm.has_mask ? 1 : 0), arg("vmask", dm.vmask), arg("out_vmask", next.vmask), arg("in_place", in_place));
  // tets
  DeviceBuffer<uint32_t>& tkeep = s.tkeep;  // kept for note_compaction
  DeviceBuffer<uint32_t>& tnew = s.tnew;
  ensure(tkeep, ctx, nt);
  ensure(tnew, ctx, nt);
  run(ctx, F, "tet_keep", nt, arg("nt", nt), arg("tets", dm.tets), arg("vaff", s.vaff), arg("edges", c.edges), arg("keep", tkeep), arg("in_place", in_place), arg("tdead", s.in_place ? s.tdead.buffer() : vkeep.buffer()));
  const uint32_t nt2 = dev::exclusive_scan(ctx, tkeep, tnew, nt);
  next.nt = nt2;
  ensure(next.tets, ctx, size_t(nt2) * 4);
  run(ctx, F, "tet_write", nt, arg("nt", nt), arg("tets", dm.tets), arg("keep", tkeep), arg("newidx", tnew), arg("vmap", vmap), arg("out_tets", next.tets));
  // the quality guard's qualities of the tets no collapse touched (tet_qualities); like the
  // connectivity, only when carrying was asked for (remember_for_carry), so that
  // reuse_across_iterations = false computes every quality afresh and the tests compare both
  s.quality_carried = s.update_next && s.quality_generation == c.generation && s.tet_quality.size() == nt && nt2 > 0;
  if (s.quality_carried) {
    ensure(s.tet_quality_next, ctx, nt2);
    run(ctx, "collapse_admissible.cl", "tet_quality_carry", nt, arg("nt", nt), arg("tets", dm.tets), arg("keep", tkeep), arg("newidx", tnew), arg("vaff", s.vaff), arg("quality", s.tet_quality), arg("out", s.tet_quality_next));
    std::swap(s.tet_quality, s.tet_quality_next);
  }
  next.labels.resize(dm.labels.size());
  for (size_t l = 0; l < dm.labels.size(); ++l) {
    ensure(next.labels[l], ctx, dm.labels[l].size() == 0 ? 0 : nt2);
    if (dm.labels[l].size() != 0)
      run(ctx, F, "compact_ints", nt, arg("n", nt), arg("keep", tkeep), arg("newidx", tnew), arg("ncomp", 1), arg("in", dm.labels[l]), arg("out", next.labels[l]));
  }
  ensure(next.tfields, ctx, size_t(nt2) * dm.tfield_comps);
  if (dm.tfield_comps > 0)
    run(ctx, F, "compact_doubles", nt, arg("n", nt), arg("keep", tkeep), arg("newidx", tnew), arg("ncomp", dm.tfield_comps), arg("in", dm.tfields), arg("out", next.tfields));
  if (n_origin > 0) run(ctx, F, "origin_update", n_origin, arg("n", n_origin), arg("vmap", vmap), arg("origin", origin));
  if (s.update_next) {
    // the next iteration's rings and tet_nbr from this one's (collapse_update.cl)
    const std::string U8 = "collapse_update.cl";
    ensure(s.upd_count, ctx, nv2);
    run(ctx, U8, "ring_update_count", nv, arg("nv_prev", nv), arg("vkeep", vkeep), arg("vnew", vnew), arg("vaff", s.vaff), arg("edges", c.edges), arg("vt_off", c.vt_off), arg("vt", c.vt), arg("tkeep", tkeep), arg("count", s.upd_count));
    const uint32_t nring = scan_offsets(ctx, s.upd_count, s.upd_vt_off, nv2);
    ensure(s.upd_vt, ctx, nring);
    run(ctx, U8, "ring_update_write", nv, arg("nv_prev", nv), arg("vkeep", vkeep), arg("vnew", vnew), arg("vaff", s.vaff), arg("edges", c.edges), arg("vt_off", c.vt_off), arg("vt", c.vt), arg("tkeep", tkeep), arg("tnew", tnew), arg("new_vt_off", s.upd_vt_off), arg("new_vt", s.upd_vt));
    ensure(s.upd_tet_nbr, ctx, size_t(nt2) * 4);
    run(ctx, U8, "tet_nbr_update", nt, arg("nt_prev", nt), arg("tets", dm.tets), arg("tkeep", tkeep), arg("tnew", tnew), arg("vaff", s.vaff), arg("edges", c.edges), arg("tet_nbr", c.tet_nbr), arg("new_tet_nbr", s.upd_tet_nbr), arg("in_place", in_place));
    s.update_next = false;
    s.has_update = true;
  }
  std::swap(dm, next);
}

}  // namespace tc::collapse_detail
