// Per-edge and per-vertex state of the stages after the connectivity.
#pragma once

#include <cstdint>

#include "collapse/launch.hpp"

namespace tc::collapse_detail {

// Per-edge and per-vertex state of the later stages.
struct EdgeState {
  DeviceBuffer<double> cost;
  DeviceBuffer<uint32_t> marked, adm, p1, fin;
  DeviceBuffer<uint8_t> state;      // conflict passes: 0 undecided, 1 in, 2 out
  DeviceBuffer<double> tet_quality; // quality guard: tc_tet_quality per tet (collapse_admissible.cl)
  DeviceBuffer<double> tet_quality_next;
  uint64_t quality_generation = 0;  // tet_quality is complete for the connectivity of this generation
  bool quality_carried = false;     // tet_quality holds the carried values (-1: to compute) of the mesh
  DeviceBuffer<uint32_t> cand;      // lazy filter: marked and passing Q
  // Conflict rounds (collapse_conflict.cl): candidate edges, worklists of their slots, the
  // length of the next worklist, stored rivals per slot (pass 2) and their count.
  DeviceBuffer<uint32_t> cand_edges, work[2], work_n, rivals, rcount;
  DeviceBuffer<int32_t> slot[2];    // pass 1: per-vertex claims (collapse_conflict.cl)
  DeviceBuffer<uint32_t> queued, dlist, resume;  // lazy pass 1: turn-list stamps, vertex list, loop exit
  DeviceBuffer<uint8_t> dir, reason;
  DeviceBuffer<int32_t> vaff;       // per vertex
  // greedy selection (greedy_selection): the priority (levels > 0), per edge the edge it waits
  // for, per vertex the round it was last listed, the edges taken in a round
  DeviceBuffer<double> prio, slotp;  // slotp: the priority of each vertex's slot (matching)
  DeviceBuffer<int32_t> blocker;
  DeviceBuffer<int32_t> whead, wnext;  // the selections' waiting lists: per vertex, per edge
  DeviceBuffer<uint32_t> vstamp, inlist;
  // matching selection (matching_selection): per edge whether its early test ran and the round
  // it was taken in, per tet whether a collapse removed it and which; the positions and fields
  // of the iteration's start (matching_backup), for undoing collapses the surface guard refuses
  // (matching_undo: per edge refused / undone, per vertex the first round reaching it); in_place:
  // the collapses are applied (collapse_and_compact only compacts)
  DeviceBuffer<uint8_t> spec, tdead, refused, undo;
  DeviceBuffer<uint32_t> dround, reachmin;
  DeviceBuffer<int32_t> tkill;
  DeviceBuffer<double> points0, vfields0;
  bool in_place = false;
  // marked, admissible, pass1, pass2, tested (lazy), passed Q (lazy)
  DeviceBuffer<uint32_t> counters;
  // Verdicts of the link and volume tests kept across iterations (collapse_verdicts.cl):
  // verdict[e] is the reason of a test of e (TCC_OK or a refusal), kVolumeOk (the greedy
  // selection's volume test passed, the link condition not yet run) or TCC_VERDICT_UNKNOWN.
  // Carried to the next iteration for the edges whose end points' rings did not change.
  DeviceBuffer<uint8_t> verdict;
  bool verdict_ready = false;
  // later selection rounds (next_selection_round): the previous rounds' results, and the flag
  // that restricts lazy_admissible_pass1's candidates to edges with clean end points (vdirty)
  DeviceBuffer<uint32_t> fin1;
  DeviceBuffer<uint8_t> dir1;
  DeviceBuffer<int32_t> vaff1;
  bool restrict_clean = false;  // verdict holds carried values (else lazy_admissible_pass1 clears it)
  // what carry_verdicts needs from the previous iteration
  bool has_prev = false;
  uint32_t prev_nv = 0, prev_nt = 0;
  DeviceBuffer<uint8_t> prev_verdict, vdirty;  // vdirty per previous vertex
  DeviceBuffer<uint8_t> ndirty;                // per current vertex: vdirty of its previous self
  DeviceBuffer<uint32_t> dirty_flags;          // the same as 0/1 words (for compact_indices)
  DeviceBuffer<int32_t> vold;                  // current vertex -> previous vertex
  DeviceBuffer<int32_t> vmap;                  // previous vertex -> current (collapse_and_compact)
  DeviceBuffer<int32_t> told;                  // current tet -> previous tet
  DeviceBuffer<uint32_t> tkeep, tnew;          // previous tet: kept, new index (collapse_and_compact)
  DeviceBuffer<uint32_t> prev_nb_off, prev_edge_off;
  DeviceBuffer<int32_t> prev_nb, prev_nb_edge, prev_tet_nbr;
  DeviceBuffer<uint8_t> prev_vclass, prev_eflags;
  // Connectivity carried through the compaction (collapse_update.cl): requested by
  // remember_for_carry, computed by collapse_and_compact, taken over by build_connectivity.
  bool update_next = false, has_update = false;
  DeviceBuffer<uint32_t> upd_count, upd_vt_off;
  DeviceBuffer<int32_t> upd_vt, upd_tet_nbr;
};

// Counter i of s.counters (marked, admissible, pass1, pass2, tested, passed Q).
inline uint32_t read_counter(EdgeState& s, int i) {
  uint32_t v = 0;
  s.counters.download(&v, 1, size_t(i));
  return v;
}

}  // namespace tc::collapse_detail
