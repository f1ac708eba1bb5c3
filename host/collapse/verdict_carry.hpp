// Verdicts of the link and volume tests carried across iterations (cl/collapse_verdicts.cl).
#pragma once

#include <cstdint>
#include <vector>

#include "collapse/connectivity.hpp"
#include "collapse/params.hpp"
#include "collapse/upload.hpp"

namespace tc::collapse_detail {

// The verdicts of the link and volume tests kept across iterations.
struct CarryState {
  // edges2verdict[e] is the reason of a test of e (TCC_OK or a refusal), kVolumeOk (the greedy
  // selection's volume test passed, the link condition not yet run) or TCC_VERDICT_UNKNOWN;
  // carried to the next iteration for the edges whose end points' rings did not change. The
  // selections' tests and the surface guard write it; verdict_ready: it holds for the next
  // selection (else lazy_start sets every verdict unknown).
  DeviceBuffer<uint8_t> edges2verdict;
  bool verdict_ready = false;
  // What carry_verdicts needs of the previous iteration: its connectivity and verdicts, which of
  // its vertices a collapse touched (dirty: an end point of a collapse or a neighbour of one; a
  // later selection round of the same connectivity reads prev_verts_are_dirty too), and the maps
  // from the current vertices and tets to the previous ones.
  bool has_prev = false;
  uint32_t prev_nv = 0, prev_nt = 0;
  DeviceBuffer<uint8_t> prev_edges2verdict, prev_verts_are_dirty;
  DeviceBuffer<uint8_t> verts_are_dirty;          // per current vertex: its previous self's
  DeviceBuffer<uint32_t> verts_are_dirty_words;   // the same as 0/1 words (for compact_indices)
  DeviceBuffer<int32_t> verts2prev, tets2prev;    // current -> previous
  DeviceBuffer<uint32_t> prev_nb_off, prev_edge_off;
  DeviceBuffer<int32_t> prev_nb, prev_nb_edge, prev_tet_nbr;
  DeviceBuffer<uint8_t> prev_vclass, prev_eflags;
};

struct EdgeState;  // edge_state.hpp

// Verdict carrying around collapse_and_compact: remember_for_carry() before it (dirty vertices:
// the end points of the final edges and their neighbours), note_compaction() right after it
// (previous connectivity and verdicts kept, current -> previous vertex map), carry_verdicts()
// after the next build_connectivity (fills s.carry.edges2verdict for the next lazy_admissible_pass1).
void remember_for_carry(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s);
void note_compaction(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s);
void carry_verdicts(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s);
// After carry_verdicts: per vertex, whether its ring changed in the last iteration or an edge at
// it keeps the surface guard's refusal (cl/collapse_verdicts.cl tail_touched; the host tail's
// TailSeed::touched).
std::vector<uint8_t> tail_touched(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s);

}  // namespace tc::collapse_detail
