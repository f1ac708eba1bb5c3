// Stage 2: the cost of every edge and the marking (cl/collapse_cost.cl).
#pragma once

#include <cstdint>

#include "collapse/connectivity.hpp"
#include "collapse/edge_state.hpp"
#include "collapse/params.hpp"
#include "collapse/upload.hpp"

namespace tc::collapse_detail {

// Returns the number of marked edges.
uint32_t cost_and_mark(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p);

}  // namespace tc::collapse_detail
