// The paper's selection: the lazy admissible filter with conflict pass 1 over edges, then
// conflict pass 2 over tets (cl/collapse_conflict.cl).
#pragma once

#include <cstdint>

#include "collapse/connectivity.hpp"
#include "collapse/params.hpp"
#include "collapse/upload.hpp"

namespace tc::collapse_detail {

// What only this selection uses (its Selection keeps it): pass 2's rivals per slot, and the
// earlier selection rounds' results (next_selection_round).
struct TwoPassState {
  DeviceBuffer<uint32_t> slots2rivals, slots2rival_count;
  DeviceBuffer<uint32_t> rounds_final;
  DeviceBuffer<uint8_t> rounds_dir;
  DeviceBuffer<int32_t> rounds_verts2collapse;
};

struct EdgeState;  // edge_state.hpp

// Conflict pass 1 over the admissible edges (s.result.edges_are_admissible); returns the number kept.
uint32_t conflict_pass1(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s);
// admissible() followed by conflict_pass1() with the same result (edges_pass1, verts2collapse, edges2dir of the kept
// edges), testing only the edges whose turn comes (cl/collapse_admissible.cl). Returns the
// number kept; passed_q and tested receive the number of marked edges passing Q and tested.
// restrict_clean: lazy_start's.
uint32_t lazy_admissible_pass1(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                               uint32_t& passed_q, uint32_t& tested, bool restrict_clean = false);
uint32_t conflict_pass2(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, TwoPassState& t,
                        uint32_t loop_size = 2048);
// A further selection round in the same connectivity after conflict_pass2: edges whose end
// points are neither end points of the collapses chosen so far nor their neighbours (their
// stars are disjoint from those collapses, which change nothing the edges' tests look at) go
// through the lazy filter and both conflict passes again; the result is merged
// (edges_are_final, edges2dir, verts2collapse). Returns the total number of collapses chosen; tested receives the round's tests.
uint32_t next_selection_round(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, TwoPassState& t,
                              const StageParams& p, uint32_t& tested);

}  // namespace tc::collapse_detail
