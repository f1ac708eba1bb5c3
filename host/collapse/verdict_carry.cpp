// Verdict carrying across iterations (cl/collapse_verdicts.cl).
#include "collapse/verdict_carry.hpp"

#include <algorithm>

namespace tc::collapse_detail {

void remember_for_carry(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s) {
  s.update_next = true;
  ensure(s.prev_verts_are_dirty, ctx, dm.nv);
  run(ctx, "collapse_verdicts.cl", "verdict_dirty", dm.nv, arg("nv", dm.nv), arg("vaff", s.verts2collapse), arg("nb_off", c.nb_off), arg("nb", c.nb), arg("vdirty", s.prev_verts_are_dirty));
  s.prev_nv = dm.nv;
  s.prev_nt = dm.nt;
}

void note_compaction(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s) {
  // collapse_and_compact left keep flags in c.count and new indices in c.cursor (old numbering)
  ensure(s.verts2prev, ctx, dm.nv);
  ensure(s.verts_are_dirty, ctx, dm.nv);
  ensure(s.verts_are_dirty_words, ctx, dm.nv);
  run(ctx, "collapse_verdicts.cl", "verdict_vertex_old", s.prev_nv, arg("nv_prev", s.prev_nv), arg("keep", c.count), arg("newidx", c.cursor), arg("vdirty", s.prev_verts_are_dirty), arg("vold", s.verts2prev), arg("ndirty", s.verts_are_dirty), arg("dirty_flags", s.verts_are_dirty_words));
  ensure(s.tets2prev, ctx, dm.nt);
  run(ctx, "collapse_verdicts.cl", "verdict_tet_old", s.prev_nt, arg("nt_prev", s.prev_nt), arg("keep", s.prev_tets_are_kept), arg("newidx", s.prev_tets2new), arg("told", s.tets2prev));
  std::swap(s.prev_nb_off, c.nb_off);
  std::swap(s.prev_edge_off, c.edge_off);
  std::swap(s.prev_nb, c.nb);
  std::swap(s.prev_nb_edge, c.nb_edge);
  std::swap(s.prev_tet_nbr, c.tet_nbr);
  std::swap(s.prev_vclass, c.vclass);
  std::swap(s.prev_eflags, c.eflags);
  std::swap(s.prev_edges2verdict, s.edges2verdict);
  s.has_prev = true;
}

void carry_verdicts(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s) {
  ensure(s.edges2verdict, ctx, c.ne);
  s.verdict_ready = s.has_prev;
  if (!s.has_prev) return;
  run(ctx, "collapse_verdicts.cl", "verdict_carry", dm.nv, arg("nv", dm.nv), arg("nb_off", c.nb_off), arg("nb", c.nb), arg("edge_off", c.edge_off), arg("vold", s.verts2prev), arg("vdirty", s.prev_verts_are_dirty), arg("prev_nb_off", s.prev_nb_off), arg("prev_nb_edge", s.prev_nb_edge), arg("prev_verdict", s.prev_edges2verdict), arg("verdict", s.edges2verdict));
  s.has_prev = false;
}

std::vector<uint8_t> tail_touched(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s) {
  DeviceBuffer<uint8_t> touched(ctx, std::max<size_t>(dm.nv, 1));
  run(ctx, "collapse_verdicts.cl", "tail_touched", dm.nv, arg("nv", dm.nv), arg("ndirty", s.verts_are_dirty), arg("nb_off", c.nb_off), arg("nb_edge", c.nb_edge), arg("verdict", s.edges2verdict), arg("touched", touched));
  return touched.download_range(0, dm.nv);
}

}  // namespace tc::collapse_detail
