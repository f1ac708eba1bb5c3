// The greedy selection (cl/collapse_admissible.cl, greedy_*).
#include "collapse/select_greedy.hpp"

#include <memory>

#include "collapse/edge_state.hpp"
#include "collapse/select_lazy.hpp"
#include "collapse/selection.hpp"

namespace tc::collapse_detail {

uint32_t greedy_selection(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                          uint32_t& passed_q, uint32_t& tested) {
  const std::string A = "collapse_admissible.cl", G = "collapse_select_greedy.cl";
  Kernel decide = stage_kernel(ctx, p, G, "greedy_decide"), loop = stage_kernel(ctx, p, G, "greedy_loop");
  // the priority first: lazy_init claims the first slots in its order
  const DeviceBuffer<double>& prio = selection_priority(ctx, c, s, p);
  lazy_start(ctx, dm, c, s, p, prio, {&decide, &loop});
  selection_buffers(ctx, dm, c, s);
  const cl_int W = p.waiting_lists ? 1 : 0;
  Kernel block = kernel(ctx, G, "greedy_block"), recompute = kernel(ctx, A, "lazy_p1_recompute"),
             turns = kernel(ctx, A, "lazy_p1_turns");
  auto one_round = [&](uint32_t nt, int cur, cl_uint round) {
    decide.set(arg("n", nt), arg("cur", cl_uint(cur)), arg("tlist", s.lazy.turn_lists[cur]), arg("tnext", s.lazy.turn_lists[1 - cur]), arg("cnt", s.lazy.list_counts), arg("edges", c.edges), arg("edges2priority", prio), arg("verts2slot", s.lazy.verts2slot[0]), arg("edges2blocker", s.lazy.edges2blocker), arg("edges2queued", s.lazy.edges2queued), arg("round", round), arg("inlist", s.lazy.round_taken), arg("verts2listed", s.lazy.verts2listed), arg("dlist", s.lazy.vertex_list), arg("edges2state", s.result.edges2state), arg("verts2collapse", s.result.verts2collapse), arg("waiting", W), arg("verts2waiting", s.lazy.verts2waiting), arg("edges2next_waiting", s.lazy.edges2next_waiting));
    decide.launch(ctx, nt);
    block.set(arg("inlist", s.lazy.round_taken), arg("cnt", s.lazy.list_counts), arg("edges", c.edges), arg("nb_off", c.nb_off), arg("nb", c.nb), arg("nb_edge", c.nb_edge), arg("verts2slot", s.lazy.verts2slot[0]), arg("verts2listed", s.lazy.verts2listed), arg("round", round), arg("dlist", s.lazy.vertex_list), arg("edges2state", s.result.edges2state));
    block.launch(ctx, nt);  // over the round's taken edges (cnt[4] <= nt)
    vertex_part(ctx, s, c, recompute, turns, prio, cur, round, nullptr, p.waiting_lists);
  };
  auto in_one_group = [&](uint32_t nt, int cur, cl_uint round) {
    loop.set(arg("n", nt), arg("cur", cl_int(cur)), arg("round", round), arg("t0", s.lazy.turn_lists[0]), arg("t1", s.lazy.turn_lists[1]), arg("cnt", s.lazy.list_counts), arg("edges", c.edges), arg("edges2priority", prio), arg("verts2slot", s.lazy.verts2slot[0]), arg("edges2blocker", s.lazy.edges2blocker), arg("edges2queued", s.lazy.edges2queued), arg("inlist", s.lazy.round_taken), arg("verts2listed", s.lazy.verts2listed), arg("dlist", s.lazy.vertex_list), arg("edges2state", s.result.edges2state), arg("verts2collapse", s.result.verts2collapse), arg("max_n", p.greedy_loop_exit), arg("resume", s.lazy.loop_resume), arg("waiting", W), arg("verts2waiting", s.lazy.verts2waiting), arg("edges2next_waiting", s.lazy.edges2next_waiting));
    loop.launch_one_group(ctx);
  };
  return selection_rounds(ctx, c, s, p, "greedy_round", one_round, in_one_group, passed_q, tested);
}


namespace {

class GreedySelection final : public Selection {
  Chosen choose(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                const IterationStats&) override {
    Chosen r;
    r.selected = greedy_selection(ctx, dm, c, s, p, r.candidates, r.tested);
    return r;
  }
};

}  // namespace

std::unique_ptr<Selection> make_greedy_selection() { return std::make_unique<GreedySelection>(); }

}  // namespace tc::collapse_detail
