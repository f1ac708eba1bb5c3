// Host side of the boundary error bound on the device (bound.hpp).
#include "collapse/bound.hpp"

#include "collapse/edge_state.hpp"
#include "collapse/launch.hpp"

namespace tc::collapse_detail {

void bound_apply(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p) {
  run_stage(ctx, p, "collapse_bound.cl", "bound_apply", c.ne, arg("ne", c.ne), arg("edges", c.edges),
            arg("edges_are_final", s.result.edges_are_final), arg("edges2dir", s.result.edges2dir),
            arg("edges2eps", s.result.edges2eps), arg("vfield", dm.vfields), arg("vfield_stride", dm.vfield_comps),
            arg("eps_col", p.eps_col));
}

}  // namespace tc::collapse_detail
