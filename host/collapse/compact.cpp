// The collapses applied and the mesh compacted (cl/collapse_compact.cl, cl/collapse_update.cl).
#include "collapse/compact.hpp"

#include "collapse/edge_state.hpp"
#include "device/primitives.hpp"

namespace tc::collapse_detail {

void collapse_and_compact(Context& ctx, const StageParams& p, DeviceMesh& dm, DeviceMesh& next, Connectivity& c,
                          EdgeState& s, DeviceBuffer<int32_t>& origin, uint32_t n_origin) {
  const std::string F = "collapse_compact.cl";
  const uint32_t nv = dm.nv, nt = dm.nt;
  // vertices
  DeviceBuffer<uint32_t>& vkeep = c.count;  // scratch reuse: nv entries
  DeviceBuffer<uint32_t>& vnew = c.cursor;
  run(ctx, F, "vertex_keep", nv, arg("nv", nv), arg("verts2collapse", s.result.verts2collapse), arg("edges", c.edges), arg("edges2dir", s.result.edges2dir), arg("keep", vkeep));
  const uint32_t nv2 = dev::exclusive_scan(ctx, vkeep, vnew, nv);
  DeviceBuffer<int32_t>& vmap = s.compact.prev_verts2new;  // kept for build_connectivity's carry
  ensure(vmap, ctx, nv);
  run(ctx, F, "vertex_map", nv, arg("nv", nv), arg("verts2collapse", s.result.verts2collapse), arg("edges", c.edges), arg("edges2dir", s.result.edges2dir), arg("newidx", vnew), arg("keep", vkeep), arg("vmap", vmap));
  next.nv = nv2;
  ensure(next.points, ctx, size_t(nv2) * 3);
  ensure(next.vfields, ctx, size_t(nv2) * dm.vfield_comps);
  ensure(next.vmask, ctx, dm.has_mask ? nv2 : 0);
  next.vfield_comps = dm.vfield_comps;
  next.tfield_comps = dm.tfield_comps;
  next.has_mask = dm.has_mask;
  next.has_labels = dm.has_labels;
  const cl_int in_place = s.result.in_place ? 1 : 0;
  run_stage(ctx, p, F, "vertex_write", nv, arg("nv", nv), arg("verts2collapse", s.result.verts2collapse), arg("edges", c.edges), arg("edges2dir", s.result.edges2dir), arg("keep", vkeep), arg("newidx", vnew), arg("pts", dm.points), arg("out_pts", next.points), arg("ncomp", dm.vfield_comps), arg("vfields", dm.vfields), arg("out_vfields", next.vfields), arg("has_mask", dm.has_mask ? 1 : 0), arg("vmask", dm.vmask), arg("out_vmask", next.vmask), arg("in_place", in_place));
  // tets
  DeviceBuffer<uint32_t>& tkeep = s.compact.prev_tets_are_kept;  // kept for note_compaction
  DeviceBuffer<uint32_t>& tnew = s.compact.prev_tets2new;
  ensure(tkeep, ctx, nt);
  ensure(tnew, ctx, nt);
  run(ctx, F, "tet_keep", nt, arg("nt", nt), arg("tets", dm.tets), arg("verts2collapse", s.result.verts2collapse), arg("edges", c.edges), arg("keep", tkeep), arg("in_place", in_place), arg("tets_are_dead", s.result.in_place ? s.result.tets_are_dead.buffer() : vkeep.buffer()));
  const uint32_t nt2 = dev::exclusive_scan(ctx, tkeep, tnew, nt);
  next.nt = nt2;
  ensure(next.tets, ctx, size_t(nt2) * 4);
  run(ctx, F, "tet_write", nt, arg("nt", nt), arg("tets", dm.tets), arg("keep", tkeep), arg("newidx", tnew), arg("vmap", vmap), arg("out_tets", next.tets));
  // the quality guard's qualities of the tets no collapse touched (tet_qualities); like the
  // connectivity, only when carrying was asked for (remember_for_carry), so that
  // reuse_across_iterations = false computes every quality afresh and the tests compare both
  s.quality.quality_carried = s.compact.update_next && s.quality.quality_generation == c.generation &&
                              s.quality.tets2quality.size() == nt && nt2 > 0;
  if (s.quality.quality_carried) {
    ensure(s.quality.tets2quality_next, ctx, nt2);
    run(ctx, "collapse_admissible.cl", "tet_quality_carry", nt, arg("nt", nt), arg("tets", dm.tets), arg("keep", tkeep), arg("newidx", tnew), arg("verts2collapse", s.result.verts2collapse), arg("tets2quality", s.quality.tets2quality), arg("tets2quality_next", s.quality.tets2quality_next));
    std::swap(s.quality.tets2quality, s.quality.tets2quality_next);
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
  if (s.compact.update_next) {
    // the next iteration's rings and tet_nbr from this one's (collapse_update.cl)
    const std::string U8 = "collapse_update.cl";
    ensure(s.compact.upd_count, ctx, nv2);
    run(ctx, U8, "ring_update_count", nv, arg("nv_prev", nv), arg("vkeep", vkeep), arg("vnew", vnew), arg("verts2collapse", s.result.verts2collapse), arg("edges", c.edges), arg("vt_off", c.vt_off), arg("vt", c.vt), arg("tkeep", tkeep), arg("count", s.compact.upd_count));
    const uint32_t nring = scan_offsets(ctx, s.compact.upd_count, s.compact.upd_vt_off, nv2);
    ensure(s.compact.upd_vt, ctx, nring);
    run(ctx, U8, "ring_update_write", nv, arg("nv_prev", nv), arg("vkeep", vkeep), arg("vnew", vnew), arg("verts2collapse", s.result.verts2collapse), arg("edges", c.edges), arg("vt_off", c.vt_off), arg("vt", c.vt), arg("tkeep", tkeep), arg("tnew", tnew), arg("new_vt_off", s.compact.upd_vt_off), arg("new_vt", s.compact.upd_vt));
    ensure(s.compact.upd_tet_nbr, ctx, size_t(nt2) * 4);
    run(ctx, U8, "tet_nbr_update", nt, arg("nt_prev", nt), arg("tets", dm.tets), arg("tkeep", tkeep), arg("tnew", tnew), arg("verts2collapse", s.result.verts2collapse), arg("edges", c.edges), arg("tet_nbr", c.tet_nbr), arg("new_tet_nbr", s.compact.upd_tet_nbr), arg("in_place", in_place));
    s.compact.update_next = false;
    s.compact.has_update = true;
  }
  std::swap(dm, next);
  // The mesh before the compaction is not read again: released rather than kept for the next
  // compaction, whose mesh is smaller.
  next = DeviceMesh{};
}

}  // namespace tc::collapse_detail
