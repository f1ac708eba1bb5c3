// Verdict carrying across iterations (cl/collapse_verdicts.cl).
#include "collapse/verdict_carry.hpp"

#include <algorithm>

#include "collapse/edge_state.hpp"

namespace tc::collapse_detail {

void remember_for_carry(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s) {
  s.compact.update_next = true;
  ensure(s.carry.prev_verts_are_dirty, ctx, dm.nv);
  run(ctx, "collapse_verdicts.cl", "verdict_dirty", dm.nv, arg("nv", dm.nv), arg("verts2collapse", s.result.verts2collapse), arg("nb_off", c.nb_off), arg("nb", c.nb), arg("prev_verts_are_dirty", s.carry.prev_verts_are_dirty));
  s.carry.prev_nv = dm.nv;
  s.carry.prev_nt = dm.nt;
}

void note_compaction(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s) {
  // collapse_and_compact left keep flags in c.count and new indices in c.cursor (old numbering)
  ensure(s.carry.verts2prev, ctx, dm.nv);
  ensure(s.carry.verts_are_dirty, ctx, dm.nv);
  ensure(s.carry.verts_are_dirty_words, ctx, dm.nv);
  run(ctx, "collapse_verdicts.cl", "verdict_vertex_old", s.carry.prev_nv, arg("nv_prev", s.carry.prev_nv), arg("keep", c.count), arg("newidx", c.cursor), arg("prev_verts_are_dirty", s.carry.prev_verts_are_dirty), arg("verts2prev", s.carry.verts2prev), arg("verts_are_dirty", s.carry.verts_are_dirty), arg("verts_are_dirty_words", s.carry.verts_are_dirty_words));
  ensure(s.carry.tets2prev, ctx, dm.nt);
  run(ctx, "collapse_verdicts.cl", "verdict_tet_old", s.carry.prev_nt, arg("nt_prev", s.carry.prev_nt), arg("prev_tets_are_kept", s.compact.prev_tets_are_kept), arg("prev_tets2new", s.compact.prev_tets2new), arg("tets2prev", s.carry.tets2prev));
  std::swap(s.carry.prev_nb_off, c.nb_off);
  std::swap(s.carry.prev_edge_off, c.edge_off);
  std::swap(s.carry.prev_nb, c.nb);
  std::swap(s.carry.prev_nb_edge, c.nb_edge);
  std::swap(s.carry.prev_tet_nbr, c.tet_nbr);
  std::swap(s.carry.prev_vclass, c.vclass);
  std::swap(s.carry.prev_eflags, c.eflags);
  std::swap(s.carry.prev_edges2verdict, s.carry.edges2verdict);
  s.carry.has_prev = true;
}

void carry_verdicts(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s) {
  ensure(s.carry.edges2verdict, ctx, c.ne);
  s.carry.verdict_ready = s.carry.has_prev;
  if (!s.carry.has_prev) return;
  run(ctx, "collapse_verdicts.cl", "verdict_carry", dm.nv, arg("nv", dm.nv), arg("nb_off", c.nb_off), arg("nb", c.nb), arg("edge_off", c.edge_off), arg("verts2prev", s.carry.verts2prev), arg("prev_verts_are_dirty", s.carry.prev_verts_are_dirty), arg("prev_nb_off", s.carry.prev_nb_off), arg("prev_nb_edge", s.carry.prev_nb_edge), arg("prev_edges2verdict", s.carry.prev_edges2verdict), arg("edges2verdict", s.carry.edges2verdict));
  s.carry.has_prev = false;
  // The previous iteration's connectivity and maps are read only by the carried
  // build_connectivity and the kernel above: released, so that this iteration's stages do not
  // hold two meshes' connectivity (note_compaction hands the next ones over).
  CarryState& k = s.carry;
  k.prev_nb_off = k.prev_edge_off = DeviceBuffer<uint32_t>();
  k.prev_nb = k.prev_nb_edge = k.prev_tet_nbr = DeviceBuffer<int32_t>();
  k.prev_vclass = k.prev_eflags = k.prev_edges2verdict = DeviceBuffer<uint8_t>();
  k.tets2prev = k.verts2prev = DeviceBuffer<int32_t>();
  s.compact.prev_verts2new = DeviceBuffer<int32_t>();
  s.compact.prev_tets_are_kept = s.compact.prev_tets2new = DeviceBuffer<uint32_t>();
}

std::vector<uint8_t> tail_touched(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s) {
  DeviceBuffer<uint8_t> touched(ctx, std::max<size_t>(dm.nv, 1));
  run(ctx, "collapse_verdicts.cl", "tail_touched", dm.nv, arg("nv", dm.nv), arg("verts_are_dirty", s.carry.verts_are_dirty), arg("nb_off", c.nb_off), arg("nb_edge", c.nb_edge), arg("edges2verdict", s.carry.edges2verdict), arg("touched", touched));
  return touched.download_range(0, dm.nv);
}

}  // namespace tc::collapse_detail
