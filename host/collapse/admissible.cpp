// The admissible filter over every marked edge (cl/collapse_admissible.cl).
#include "collapse/admissible.hpp"

#include "collapse/edge_state.hpp"

namespace tc::collapse_detail {

// The quality guard's per-tet qualities of the current mesh (a placeholder when it is off):
// once per connectivity; after a compaction only the tets that changed (tet_quality_carry).
const cl::Buffer& tet_qualities(Context& ctx, DeviceMesh& dm, const Connectivity& c, QualityCache& q,
                                const StageParams& p) {
  if (!(p.min_quality > 0)) {
    ensure(q.tets2quality, ctx, 1);
    q.quality_carried = false;
    q.quality_generation = 0;
    return q.tets2quality.buffer();
  }
  if (q.quality_generation == c.generation && q.tets2quality.size() == dm.nt) return q.tets2quality.buffer();
  const cl_int only_missing = q.quality_carried && q.tets2quality.size() == dm.nt ? 1 : 0;
  ensure(q.tets2quality, ctx, dm.nt);
  run(ctx, "collapse_admissible.cl", "tet_quality", dm.nt, arg("nt", dm.nt), arg("tets", dm.tets), arg("pts", dm.points), arg("tets2quality", q.tets2quality), arg("only_missing", only_missing));
  q.quality_carried = false;
  q.quality_generation = c.generation;
  return q.tets2quality.buffer();
}

uint32_t admissible(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p) {
  s.result.in_place = false;
  ensure(s.result.edges_are_admissible, ctx, c.ne);
  ensure(s.result.edges2dir, ctx, c.ne);
  ensure(s.result.edges2reason, ctx, c.ne);
  const cl_int use_labels = dm.has_labels && p.use_labels ? 1 : 0;
  run_stage(ctx, p, "collapse_admissible.cl", "admissible", c.ne, arg("ne", c.ne), arg("edges", c.edges), arg("edges_are_marked", s.cost.edges_are_marked), arg("tets", dm.tets), arg("vt_off", c.vt_off), arg("vt", c.vt), arg("tet_nbr", c.tet_nbr), arg("nb_off", c.nb_off), arg("nb", c.nb), arg("nb_edge", c.nb_edge), arg("labels", dm.primary_labels()), arg("use_labels", use_labels), arg("pts", dm.points), arg("vfield", dm.vfields), arg("vfield_stride", dm.vfield_comps), arg("vflags", c.vflags), arg("vclass", c.vclass), arg("eflags", c.eflags), arg("mode", p.mode), arg("paper_rule", p.paper_rule ? 1 : 0), arg("eps_v", p.eps_v), arg("q_min", p.min_quality), arg("field_eps", p.field_eps), arg("tets2quality", tet_qualities(ctx, dm, c, s.quality, p)), arg("edges_are_admissible", s.result.edges_are_admissible), arg("edges2dir", s.result.edges2dir), arg("edges2reason", s.result.edges2reason), arg("counters", s.cost.counters));
  return read_counter(s.cost, 1);
}

}  // namespace tc::collapse_detail
