// Host side of the boundary error bound on the device (bound.hpp).
#include "collapse/bound.hpp"

#include "collapse/edge_state.hpp"
#include "collapse/launch.hpp"

namespace tc::collapse_detail {

namespace {
constexpr const char* kFile = "collapse_bound.cl";
}

uint32_t BoundStage::test(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p) {
  ensure(edges2eps, ctx, std::max<size_t>(c.ne, 1));
  ensure(count, ctx, 1);
  count.fill(0u);
  const cl_int use_labels = dm.has_labels && p.use_labels ? 1 : 0;
  const bool has_verdict = s.carry.edges2verdict.size() >= c.ne && s.carry.edges2verdict.buffer()();
  run_stage(ctx, p, kFile, "bound_test", c.ne, arg("ne", c.ne), arg("edges", c.edges),
            arg("edges_are_final", s.result.edges_are_final), arg("edges2dir", s.result.edges2dir), arg("pts", dm.points),
            arg("vfield", dm.vfields), arg("vfield_stride", dm.vfield_comps), arg("eps_col", p.eps_col),
            arg("tets", dm.tets), arg("vt_off", c.vt_off), arg("vt", c.vt), arg("tet_nbr", c.tet_nbr),
            arg("labels", dm.labels[0]), arg("use_labels", use_labels), arg("vflags", c.vflags),
            arg("bound", p.bound), arg("edges_are_marked", s.cost.edges_are_marked),
            arg("has_verdict", cl_int(has_verdict ? 1 : 0)),
            arg("edges2verdict", has_verdict ? s.carry.edges2verdict.buffer() : count.buffer()),
            arg("edges2eps", edges2eps), arg("count", count));
  uint32_t refused = 0;
  count.download(&refused, 1);
  if (refused > 0) restart_selection_counters(s);
  return refused;
}

void BoundStage::apply(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p) {
  run_stage(ctx, p, kFile, "bound_apply", c.ne, arg("ne", c.ne), arg("edges", c.edges),
            arg("edges_are_final", s.result.edges_are_final), arg("edges2dir", s.result.edges2dir),
            arg("edges2eps", edges2eps), arg("vfield", dm.vfields), arg("vfield_stride", dm.vfield_comps),
            arg("eps_col", p.eps_col));
}

}  // namespace tc::collapse_detail
