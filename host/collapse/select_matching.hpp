// The matching selection (cl/collapse_matching.cl).
#pragma once

#include <cstdint>
#include <vector>

#include "collapse/connectivity.hpp"
#include "collapse/params.hpp"
#include "collapse/upload.hpp"

namespace tc::collapse_detail {

struct EdgeState;     // edge_state.hpp
struct SurfaceGuard;  // guard_surface.hpp

// What only this selection uses (its Selection keeps it): each slot's priority, per edge whether
// its early test ran and the round it was taken in, per tet which collapse removed it; the
// positions and fields of the iteration's start (matching_backup), for undoing what the surface
// guard refuses (matching_undo: per edge refused / to undo, per vertex the first round reaching
// it).
struct MatchingState {
  DeviceBuffer<double> verts2slot_priority;
  DeviceBuffer<uint8_t> edges_early_tested, edges_are_refused, edges_to_undo;
  DeviceBuffer<uint32_t> edges2round, verts2first_round;
  DeviceBuffer<int32_t> tets2killer;
  DeviceBuffer<double> points_before, vfields_before;
};

// The matching selection (cl/collapse_matching.cl), in place of greedy_selection: the edges that
// taking the candidates one after another in priority order would take, each tested on the mesh
// with the earlier ones collapsed, skipping only those that share an end point with an edge
// taken before. The collapses are applied to dm (tets, points, fields) and c.tet_nbr as they are
// taken (s.result.tets_are_dead: the removed tets; s.result.in_place), so matching_backup must
// come before and collapse_and_compact after (it then only compacts). Outputs and counts as
// greedy_selection; m keeps what the undo needs (matching_undo).
uint32_t matching_selection(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, MatchingState& m,
                            const StageParams& p, uint32_t& passed_q, uint32_t& tested);
// Keeps the positions and vertex fields as they are, for matching_undo.
void matching_backup(Context& ctx, DeviceMesh& dm, MatchingState& m);
// After SurfaceGuard::run_applied refused collapses of the matching selection: undoes them and
// every collapse taken after one of them within reach (cl/collapse_matching.cl, match_undo*);
// returns how many were undone (edges_are_final, verts2collapse, edges2state and the mesh updated), and has the guard's next
// run test only what the undo may concern (SurfaceGuard::restrict_to_undone). The second form
// undoes the edges of `refused` (taken ones) and their closure instead (listed in *undone).
uint32_t matching_undo(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, MatchingState& m,
                       SurfaceGuard& guard);
uint32_t matching_undo(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, MatchingState& m,
                       const std::vector<uint32_t>& refused, std::vector<uint32_t>* undone = nullptr);

}  // namespace tc::collapse_detail
