// The state of an iteration's stages after the connectivity, composed of each stage's own.
#pragma once

#include "collapse/admissible.hpp"
#include "collapse/compact.hpp"
#include "collapse/cost.hpp"
#include "collapse/select_lazy.hpp"
#include "collapse/selection_result.hpp"
#include "collapse/verdict_carry.hpp"

namespace tc::collapse_detail {

// Each stage declares its state beside its functions; the stages take this aggregate because
// later stages read earlier ones' (the selection reads the cost, the compaction the selection's
// result). The buffers are named for what each maps (edges2x: a value per edge; edges_are_x: a
// 0/1 flag per edge; verts2x, tets2x likewise). What only the two-pass or the matching selection
// uses, its Selection keeps (TwoPassState, MatchingState).
struct EdgeState {
  CostState cost;          // cost.hpp
  SelectionResult result;  // selection_result.hpp
  QualityCache quality;    // admissible.hpp
  LazyState lazy;          // select_lazy.hpp
  CarryState carry;        // verdict_carry.hpp
  CompactState compact;    // compact.hpp
};

// Before the selection runs again (after refusals of the surface guard or the boundary error
// bound): its counters start from zero, but counters[0], marked, stays.
inline void restart_selection_counters(EdgeState& s) {
  uint32_t marked = 0;
  s.cost.counters.download(&marked, 1, 0);
  s.cost.counters.fill(0u);
  s.cost.counters.upload(&marked, 1, 0);
}

}  // namespace tc::collapse_detail
