// The selection and surface guard loop every conflict detection shares (selection.hpp).
#include "collapse/selection.hpp"

#include "collapse/bound.hpp"
#include "collapse/edge_state.hpp"
#include "stopwatch.hpp"

namespace tc::collapse_detail {

uint32_t Selection::select(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                           IterationStats& stats) {
  Stopwatch clock;
  begin(ctx, dm, s);
  // candidates and selected are the first selection's; tested, the refusals and the seconds add
  // up over the selections (a selection tests only edges no earlier one tested)
  for (bool first = true;; first = false) {
    const Chosen chosen = choose(ctx, dm, c, s, p, stats);
    if (first) {
      stats.candidates = chosen.candidates;
      stats.selected = chosen.selected;
    }
    stats.tested += chosen.tested;
    if (p.bound > 0) {  // the selection's test refused these (TCC_BOUND, cl/collapse_select.h)
      uint32_t out = 0;
      s.cost.counters.download(&out, 1, kCounterBoundRefused);
      stats.refused_by_bound += out;
    }
    stats.seconds_select += clock.lap();
    uint32_t left = chosen.selected;
    const uint32_t refused = guard(ctx, dm, c, s, p, left);
    stats.refused_by_guard += refused;
    stats.seconds_guard += clock.lap();
    if (refused == 0 || guard_leaves_final()) {
      if (p.bound > 0 && left > 0) bound_apply(ctx, dm, c, s, p);
      return left;
    }
    s.carry.verdict_ready = true;  // this iteration's verdicts still hold for the next selection
  }
}

uint32_t Selection::guard(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                          uint32_t& chosen) {
  return guard_.run(ctx, dm, c, s, p, chosen);
}

void Selection::release(EdgeState& s) {
  s.lazy = LazyState{};
  s.cost.edges2cost = DeviceBuffer<double>();
  s.cost.edges_are_marked = DeviceBuffer<uint32_t>();
  s.result.edges_are_final = s.result.edges_are_admissible = s.result.edges_pass1 = DeviceBuffer<uint32_t>();
  s.result.edges2state = s.result.edges2reason = DeviceBuffer<uint8_t>();
  s.result.edges2eps = DeviceBuffer<double>();
  guard_.release();
}

std::unique_ptr<Selection> make_selection(const CollapseOptions& o) {
  switch (o.conflicts) {
    case CollapseOptions::TwoPass: return make_two_pass_selection(o.selection_rounds);
    case CollapseOptions::Greedy: return make_greedy_selection();
    case CollapseOptions::AtomicMin: return make_atomic_min_selection();
    case CollapseOptions::Matching: break;
  }
  return make_matching_selection();
}

}  // namespace tc::collapse_detail
