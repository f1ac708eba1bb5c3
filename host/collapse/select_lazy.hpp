// What the lazy filter, the greedy and the matching selections share (select_lazy.cpp).
#pragma once

#include <cstdint>
#include <functional>
#include <initializer_list>

#include "collapse/connectivity.hpp"
#include "collapse/params.hpp"
#include "collapse/upload.hpp"

namespace tc::collapse_detail {

// The lazy filter's and the selections' rounds (select_two_pass.cpp, select_greedy.cpp and
// select_matching.cpp use them too): the candidates (marked and passing Q) as flags and as a
// list, the turn lists of the rounds and their lengths, each vertex's claim (its slot: the first
// undecided candidate at it), the round an edge was last queued, the vertices listed in a round,
// where a one-work-group loop stopped.
struct LazyState {
  DeviceBuffer<uint32_t> edges_are_candidates, candidate_list, turn_lists[2], list_counts;
  DeviceBuffer<int32_t> verts2slot[2];
  DeviceBuffer<uint32_t> edges2queued, vertex_list, loop_resume;
  // The greedy and matching selections: the priority (CollapseTuning::priority_levels), per edge
  // the edge it waits for, per vertex the round it was last listed, the edges taken in a round,
  // the waiting lists (per vertex its first waiting edge, per edge the next).
  DeviceBuffer<double> edges2priority;
  DeviceBuffer<int32_t> edges2blocker, verts2waiting, edges2next_waiting;
  DeviceBuffer<uint32_t> verts2listed, round_taken;
};

struct EdgeState;  // edge_state.hpp

void vertex_part(Context& ctx, EdgeState& s, const Connectivity& c, Kernel& recompute, Kernel& turns,
                 const DeviceBuffer<double>& order, int cur, cl_uint round, DeviceBuffer<double>* slotp = nullptr,
                 bool waiting = false);
void lazy_start(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                const DeviceBuffer<double>& order, std::initializer_list<Kernel*> tests, bool keep_refused = false,
                bool restrict_clean = false);
const DeviceBuffer<double>& selection_priority(Context& ctx, Connectivity& c, EdgeState& s, const StageParams& p);
void selection_buffers(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s);

// The rounds of the greedy and matching selections (after lazy_start, selection_buffers and the
// first claims): the first turn list, then round after round until none is left, each either
// the per-round kernels (`one_round(nt, cur, round)`, which leave the next turn list's length in
// s.lazy.list_counts[1 - cur]) or, once a turn list holds at most p.greedy_loop_size edges, the
// loop in one work-group (`loop(nt, cur, round)`, which stops before a turn list longer than
// p.greedy_loop_exit and leaves where in s.lazy.loop_resume); then greedy_finish and the counts
// (passed_q and tested as lazy_admissible_pass1; returns the number taken).
using RoundFn = std::function<void(uint32_t nt, int cur, cl_uint round)>;
uint32_t selection_rounds(Context& ctx, Connectivity& c, EdgeState& s, const StageParams& p, const char* name,
                          const RoundFn& one_round, const RoundFn& loop, uint32_t& passed_q, uint32_t& tested);

}  // namespace tc::collapse_detail
