// The greedy selection (cl/collapse_admissible.cl, greedy_*).
#pragma once

#include <cstdint>

#include "collapse/connectivity.hpp"
#include "collapse/params.hpp"
#include "collapse/upload.hpp"

namespace tc::collapse_detail {

struct EdgeState;  // edge_state.hpp

// The greedy selection (cl/collapse_admissible.cl, greedy_*), in place of
// lazy_admissible_pass1 and conflict_pass2: the edges that taking the candidates one after
// another in priority order would take, skipping those that fail the tests or touch a tet of
// an edge taken before. Each edge is tested when its turn comes. Outputs as conflict_pass2
// (edges_are_final, edges_pass1 = edges_are_final, verts2collapse, edges2dir); returns the number taken; passed_q and tested as
// lazy_admissible_pass1 (tested: the edges whose volume test ran).
uint32_t greedy_selection(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                          uint32_t& passed_q, uint32_t& tested);

}  // namespace tc::collapse_detail
