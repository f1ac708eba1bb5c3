// Stage 1: connectivity (cl/collapse_connectivity.cl), carried through the compaction for the
// vertices whose rings did not change.
#include "collapse/connectivity.hpp"

#include <atomic>

#include "collapse/edge_state.hpp"
#include "device/primitives.hpp"

namespace tc::collapse_detail {

void build_connectivity(Context& ctx, DeviceMesh& dm, Connectivity& c, const StageParams& p, EdgeState* s) {
  const std::string F = "collapse_connectivity.cl";
  const uint32_t nv = dm.nv, nt = dm.nt;
  ensure(c.count, ctx, nv);
  ensure(c.cursor, ctx, nv);
  // rings and tet_nbr carried through the compaction (collapse_update.cl)
  const bool updated = s && s->carry.has_prev && s->compact.has_update;
  // the rings are sorted: carried (updated) or the host's (the first build with cpu_tuning)
  const bool sorted = updated || dm.has_rings;
  if (updated) {
    std::swap(c.vt_off, s->compact.upd_vt_off);
    std::swap(c.vt, s->compact.upd_vt);
    std::swap(c.tet_nbr, s->compact.upd_tet_nbr);
    s->compact.has_update = false;
    // what was swapped out is the previous mesh's: released (the compaction allocates anew)
    s->compact.upd_vt_off = s->compact.upd_count = DeviceBuffer<uint32_t>();
    s->compact.upd_vt = s->compact.upd_tet_nbr = DeviceBuffer<int32_t>();
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
  const bool cy = s && s->carry.has_prev;
  const cl_int ci = cy ? 1 : 0;
  // carried data when cy (collapse_verdicts.cl), placeholders otherwise
  const cl::Buffer& nd = cy ? s->carry.verts_are_dirty.buffer() : c.count.buffer();
  const cl::Buffer& vo = cy ? s->carry.verts2prev.buffer() : c.count.buffer();
  const cl::Buffer& vm = cy ? s->compact.prev_verts2new.buffer() : c.count.buffer();
  const cl::Buffer& pno = cy ? s->carry.prev_nb_off.buffer() : c.count.buffer();
  const cl::Buffer& pnb = cy ? s->carry.prev_nb.buffer() : c.count.buffer();
  run(ctx, F, "conn_ring_sort_and_gather", nv, arg("tets", dm.tets), arg("nv", nv), arg("vt_off", c.vt_off), arg("vt", c.vt), arg("scratch", c.scratch), arg("nb_count", c.count), arg("up_count", c.up_count), arg("sort", cl_int(sorted ? 0 : 1)), arg("carry", ci), arg("verts_are_dirty", nd), arg("verts2prev", vo), arg("prev_verts2new", vm), arg("prev_nb_off", pno), arg("prev_nb", pnb), arg("rename", cl_int(updated ? 1 : 0)), arg("prev_verts2collapse", updated ? s->result.verts2collapse.buffer() : c.count.buffer()));
  uint32_t nnb = scan_offsets(ctx, c.count, c.nb_off, nv);
  c.ne = scan_offsets(ctx, c.up_count, c.edge_off, nv);
  ensure(c.nb, ctx, nnb);
  ensure(c.nb_edge, ctx, nnb);
  ensure(c.edges, ctx, size_t(c.ne) * 2);
  run(ctx, F, "conn_write_neighbours", nv, arg("nv", nv), arg("vt_off", c.vt_off), arg("scratch", c.scratch), arg("nb_off", c.nb_off), arg("edge_off", c.edge_off), arg("nb", c.nb), arg("nb_edge", c.nb_edge), arg("edges", c.edges));
  // The candidates' 12 slots per tet are read only above: released (the queue holds the buffer
  // until the kernel is done) so that the selection's and the compaction's buffers do not come on
  // top of them; the next build allocates them again, at its smaller mesh's size.
  c.scratch = DeviceBuffer<int32_t>();
  run(ctx, F, "conn_lower_edges", nv, arg("nv", nv), arg("nb_off", c.nb_off), arg("nb", c.nb), arg("edge_off", c.edge_off), arg("nb_edge", c.nb_edge), arg("carry", ci), arg("verts_are_dirty", nd), arg("verts2prev", vo), arg("prev_nb_off", pno), arg("prev_edge_off", cy ? s->carry.prev_edge_off.buffer() : c.count.buffer()), arg("prev_nb_edge", cy ? s->carry.prev_nb_edge.buffer() : c.count.buffer()));
  ensure(c.eflags, ctx, c.ne);
  ensure(c.vflags, ctx, nv);
  ensure(c.vclass, ctx, nv);
  const cl_int use_labels = dm.has_labels && p.use_labels ? 1 : 0;
  ensure(c.tet_nbr, ctx, size_t(nt) * 4);
  // carried boundary data
  const cl::Buffer& to = cy ? s->carry.tets2prev.buffer() : c.vt.buffer();
  const cl::Buffer& tn = cy ? s->compact.prev_tets2new.buffer() : c.vt_off.buffer();
  const cl::Buffer& pt = cy ? s->carry.prev_tet_nbr.buffer() : c.vt.buffer();
  const cl::Buffer& pvc = cy ? s->carry.prev_vclass.buffer() : c.vflags.buffer();
  const cl::Buffer& pef = cy ? s->carry.prev_eflags.buffer() : c.vflags.buffer();
  const cl::Buffer& pne = cy ? s->carry.prev_nb_edge.buffer() : c.nb_edge.buffer();
  if (updated) {
    // c.tet_nbr taken over above
  } else if (cy) {
    run(ctx, F, "conn_tet_neighbours_carry", nt, arg("nt", nt), arg("tets", dm.tets), arg("tet_nbr", c.tet_nbr), arg("verts_are_dirty", nd), arg("tets2prev", to), arg("prev_tets2new", tn), arg("prev_tet_nbr", pt));
    // the full matching only for the dirty vertices
    ensure(c.dirty_list, ctx, nv);
    const uint32_t nd_count = dev::compact_indices(ctx, s->carry.verts_are_dirty_words, c.dirty_list, nv);
    run(ctx, F, "conn_tet_neighbours", nd_count, arg("n", nd_count), arg("tets", dm.tets), arg("vt_off", c.vt_off), arg("vt", c.vt), arg("tet_nbr", c.tet_nbr), arg("use_list", cl_int(1)), arg("list", c.dirty_list));
  } else {
    run(ctx, F, "conn_tet_neighbours", nv, arg("n", nv), arg("tets", dm.tets), arg("vt_off", c.vt_off), arg("vt", c.vt), arg("tet_nbr", c.tet_nbr), arg("use_list", cl_int(0)), arg("list", c.vt_off));
  }
  c.up_count.fill(0);  // scratch reuse (its scan is done): S bits per vertex
  ensure(c.owns_s, ctx, nt);
  ensure(c.smask, ctx, nt);
  static std::atomic<uint64_t> generations{0};  // unique across Connectivity objects
  c.generation = ++generations;
  run(ctx, F, "conn_vertex_flags_faces", nt, arg("nt", nt), arg("tets", dm.tets), arg("tet_nbr", c.tet_nbr), arg("labels", dm.primary_labels()), arg("use_labels", use_labels), arg("bits", c.up_count), arg("owns_s", c.owns_s), arg("smask", c.smask));
  run(ctx, F, "conn_vertex_flags", nv, arg("nv", nv), arg("bits", c.up_count), arg("vflags", c.vflags));
  run(ctx, F, "conn_surface_flags", nv, arg("nv", nv), arg("tets", dm.tets), arg("vt_off", c.vt_off), arg("vt", c.vt), arg("tet_nbr", c.tet_nbr), arg("labels", dm.primary_labels()), arg("use_labels", use_labels), arg("pts", dm.points), arg("eps_r", p.eps_r), arg("eps_f", p.eps_f), arg("nb_off", c.nb_off), arg("nb", c.nb), arg("edge_off", c.edge_off), arg("vflags", c.vflags), arg("smask", c.smask), arg("eflags", c.eflags), arg("vclass", c.vclass), arg("carry", ci), arg("verts_are_dirty", nd), arg("verts2prev", vo), arg("prev_nb_off", pno), arg("prev_nb", pnb), arg("prev_nb_edge", pne), arg("prev_eflags", pef), arg("prev_vclass", pvc));
}

}  // namespace tc::collapse_detail
