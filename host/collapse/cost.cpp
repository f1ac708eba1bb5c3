// Stage 2: cost and marking (cl/collapse_cost.cl).
#include "collapse/cost.hpp"

#include "collapse/edge_state.hpp"

namespace tc::collapse_detail {

uint32_t cost_and_mark(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p) {
  ensure(s.cost.counters, ctx, kCounters);
  s.cost.counters.fill(0);
  ensure(s.cost.edges2cost, ctx, c.ne);
  ensure(s.cost.edges_are_marked, ctx, c.ne);
  // with a user cost, its function comes before the kernel (see collapse_cost.cl)
  Kernel k = p.cost_source.empty()
                     ? kernel(ctx, "collapse_cost.cl", "cost_and_mark")
                     : user_kernel(ctx, "user cost", "collapse_cost.cl", "cost_and_mark",
                                   "#line 1 \"cost_cl_source\"\n" + p.cost_source, "-DTCC_USER_COST");
  const cl_int mask_mode = dm.has_mask ? p.mask_mode : 0;
  k.set(arg("ne", c.ne), arg("edges", c.edges), arg("pts", dm.points), arg("vfield", dm.vfields), arg("vfield_stride", dm.vfield_comps), arg("has_vfield", dm.vfield_comps > 0 ? 1 : 0), arg("vmask", dm.vmask), arg("mask_mode", mask_mode), arg("target", p.target), arg("edges2cost", s.cost.edges2cost), arg("edges_are_marked", s.cost.edges_are_marked), arg("counters", s.cost.counters));
  k.launch(ctx, c.ne);
  return read_counter(s.cost, 0);
}

}  // namespace tc::collapse_detail
