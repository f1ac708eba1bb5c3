// The atomic-min conflict detection (cl/collapse_atomic_min.cl).
#pragma once

#include <cstdint>

#include "collapse/connectivity.hpp"
#include "collapse/params.hpp"
#include "collapse/upload.hpp"

namespace tc::collapse_detail {

struct EdgeState;  // edge_state.hpp

// Atomic-min conflict detection (select_atomic_min.cpp) over the admissible edges
// of admissible(): replaces both conflict passes, with the same outputs as conflict_pass2.
// Returns the number of edges to collapse.
uint32_t conflicts_atomic_min(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s);

}  // namespace tc::collapse_detail
