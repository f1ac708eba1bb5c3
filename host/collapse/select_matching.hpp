// The matching selection (cl/collapse_matching.cl).
#pragma once

#include <cstdint>
#include <vector>

#include "collapse/connectivity.hpp"
#include "collapse/edge_state.hpp"
#include "collapse/params.hpp"
#include "collapse/upload.hpp"

namespace tc::collapse_detail {

struct SurfaceGuard;  // guard_surface.hpp

// The matching selection (cl/collapse_matching.cl), in place of greedy_selection: the edges that
// taking the candidates one after another in priority order would take, each tested on the mesh
// with the earlier ones collapsed, skipping only those that share an end point with an edge
// taken before. The collapses are applied to dm (tets, points, fields) and c.tet_nbr as they are
// taken (s.tets_are_dead: the removed tets; s.in_place), so matching_backup must come before and
// collapse_and_compact after (it then only compacts). Outputs and counts as greedy_selection.
uint32_t matching_selection(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                            uint32_t& passed_q, uint32_t& tested);
// Keeps the positions and vertex fields as they are, for matching_undo.
void matching_backup(Context& ctx, DeviceMesh& dm, EdgeState& s);
// After SurfaceGuard::run_applied refused collapses of the matching selection: undoes them and
// every collapse taken after one of them within reach (cl/collapse_matching.cl, match_undo*);
// returns how many were undone (edges_are_final, verts2collapse, edges2state and the mesh updated), and has the guard's next
// run test only what the undo may concern (SurfaceGuard::restrict_to_undone). The second form
// undoes the edges of `refused` (taken ones) and their closure instead (listed in *undone).
uint32_t matching_undo(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, SurfaceGuard& guard);
uint32_t matching_undo(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s,
                       const std::vector<uint32_t>& refused, std::vector<uint32_t>* undone = nullptr);

}  // namespace tc::collapse_detail
