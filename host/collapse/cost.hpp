// Stage 2: the cost of every edge and the marking (cl/collapse_cost.cl).
#pragma once

#include <cstdint>

#include "collapse/connectivity.hpp"
#include "collapse/params.hpp"
#include "collapse/upload.hpp"

namespace tc::collapse_detail {

// The cost and the marking. The surface guard unmarks the collapses it refuses, and every stage
// after adds its counts to counters (zeroed here, once per iteration).
struct CostState {
  DeviceBuffer<double> edges2cost;
  DeviceBuffer<uint32_t> edges_are_marked;
  // marked, admissible, pass 1, pass 2, tested, passed Q; the boundary error bound's refusals
  DeviceBuffer<uint32_t> counters;
};
// The counters' count and the bound's refusals' index (TCC_COUNTERS, TCC_COUNTER_BOUND_REFUSED in
// cl/collapse_common.h).
constexpr size_t kCounters = 7, kCounterBoundRefused = 6;

// Counter i of counters (marked, admissible, pass1, pass2, tested, passed Q).
inline uint32_t read_counter(CostState& s, int i) {
  uint32_t v = 0;
  s.counters.download(&v, 1, size_t(i));
  return v;
}

struct EdgeState;  // edge_state.hpp

// Returns the number of marked edges.
uint32_t cost_and_mark(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p);

}  // namespace tc::collapse_detail
