// The selection and surface guard loop every conflict detection shares (selection.hpp).
#include "collapse/selection.hpp"

#include "stopwatch.hpp"

namespace tc::collapse_detail {

uint32_t Selection::select(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                           IterationStats& stats) {
  Stopwatch clock;
  begin(ctx, dm, s);
  // marked and passed_q are counted before the first selection, tested and the seconds add up
  // over the selections (a selection tests only edges no earlier one tested), the other counts
  // are the last's
  for (bool first = true;; first = false) {
    const Chosen chosen = choose(ctx, dm, c, s, p, stats);
    if (first) stats.passed_q = chosen.passed_q;
    stats.tested += chosen.tested;
    stats.seconds_admissible += clock.lap();
    uint32_t left = chosen.after_pass2;
    const uint32_t refused = guard(ctx, dm, c, s, p, left);
    count(chosen, left, stats);
    stats.seconds_pass2 += clock.lap();
    if (refused == 0 || guard_leaves_final()) return left;
    s.verdict_ready = true;  // this iteration's verdicts still hold for the next selection
  }
}

uint32_t Selection::guard(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                          uint32_t& chosen) {
  return guard_.run(ctx, dm, c, s, p, chosen);
}

void Selection::count(const Chosen& c, uint32_t, IterationStats& stats) const {
  stats.admissible = c.admissible;
  stats.after_pass1 = c.after_pass1;
  stats.after_pass2 = c.after_pass2;
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
