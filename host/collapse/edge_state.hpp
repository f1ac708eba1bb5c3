// Per-edge and per-vertex state of the stages after the connectivity.
#pragma once

#include <cstdint>

#include "collapse/launch.hpp"

namespace tc::collapse_detail {

// Per-edge, per-vertex and per-tet state of the stages after the connectivity, named for what
// each buffer maps (edges2x: a value per edge; edges_are_x: a 0/1 flag per edge; verts2x, tets2x
// likewise). Grouped by the stage that writes it; later stages read the selection's result.
struct EdgeState {
  // Cost and marking (cost.cpp); counters: marked, admissible, pass 1, pass 2, tested, passed Q.
  DeviceBuffer<double> edges2cost;
  DeviceBuffer<uint32_t> edges_are_marked;
  DeviceBuffer<uint32_t> counters;

  // The selection's result, read by the surface guard and the compaction: the edges to
  // collapse, the direction of each (which end point survives, where it goes), per vertex the
  // collapse that moves or removes it (-1: none), and why a tested edge was refused (Reason).
  DeviceBuffer<uint32_t> edges_are_final;
  DeviceBuffer<uint8_t> edges2dir, edges2reason;
  DeviceBuffer<int32_t> verts2collapse;
  DeviceBuffer<uint8_t> edges2state;  // conflict passes: 0 undecided, 1 in, 2 out
  // admissible() over every marked edge (the atomic-min conflicts), and conflict pass 1's winners
  DeviceBuffer<uint32_t> edges_are_admissible, edges_pass1;

  // The quality guard: tc_tet_quality per tet (collapse_admissible.cl), complete for the
  // connectivity of quality_generation, or carried through the compaction (-1: to compute).
  DeviceBuffer<double> tets2quality, tets2quality_next;
  uint64_t quality_generation = 0;
  bool quality_carried = false;

  // The lazy filter and the selections' rounds (select_lazy.cpp, select_two_pass.cpp): the
  // candidates (marked and passing Q) as flags and as a list, the turn lists of the rounds and
  // their lengths, each vertex's claim (its slot: the first undecided candidate at it), pass 2's
  // rivals per slot, the round an edge was last queued, the vertices listed in a round, where a
  // one-work-group loop stopped.
  DeviceBuffer<uint32_t> edges_are_candidates, candidate_list, turn_lists[2], list_counts;
  DeviceBuffer<uint32_t> slots2rivals, slots2rival_count;
  DeviceBuffer<int32_t> verts2slot[2];
  DeviceBuffer<uint32_t> edges2queued, vertex_list, loop_resume;
  // The greedy and matching selections: the priority (CollapseTuning::priority_levels), per edge
  // the edge it waits for, per vertex the round it was last listed, the edges taken in a round,
  // the waiting lists (per vertex its first waiting edge, per edge the next).
  DeviceBuffer<double> edges2priority;
  DeviceBuffer<int32_t> edges2blocker, verts2waiting, edges2next_waiting;
  DeviceBuffer<uint32_t> verts2listed, round_taken;
  // The matching selection (select_matching.cpp): each slot's priority, per edge whether its
  // early test ran and the round it was taken in, per tet whether a collapse removed it and
  // which; the positions and fields of the iteration's start (matching_backup), for undoing what
  // the surface guard refuses (matching_undo: per edge refused / to undo, per vertex the first
  // round reaching it). in_place: the collapses are applied (collapse_and_compact only compacts).
  DeviceBuffer<double> verts2slot_priority;
  DeviceBuffer<uint8_t> edges_early_tested, tets_are_dead, edges_are_refused, edges_to_undo;
  DeviceBuffer<uint32_t> edges2round, verts2first_round;
  DeviceBuffer<int32_t> tets2killer;
  DeviceBuffer<double> points_before, vfields_before;
  bool in_place = false;

  // Verdicts of the link and volume tests kept across iterations (verdict_carry.cpp):
  // edges2verdict[e] is the reason of a test of e (TCC_OK or a refusal), kVolumeOk (the greedy
  // selection's volume test passed, the link condition not yet run) or TCC_VERDICT_UNKNOWN;
  // carried to the next iteration for the edges whose end points' rings did not change.
  DeviceBuffer<uint8_t> edges2verdict;
  bool verdict_ready = false;
  // Later selection rounds (next_selection_round): the earlier rounds' results, and the flag that
  // restricts the candidates to edges with clean end points (prev_verts_are_dirty).
  DeviceBuffer<uint32_t> rounds_final;
  DeviceBuffer<uint8_t> rounds_dir;
  DeviceBuffer<int32_t> rounds_verts2collapse;
  bool restrict_clean = false;
  // What carry_verdicts needs of the previous iteration: its connectivity and verdicts, which of
  // its vertices a collapse touched (dirty: an end point of a collapse or a neighbour of one), and
  // the maps between its vertices and tets and the current ones.
  bool has_prev = false;
  uint32_t prev_nv = 0, prev_nt = 0;
  DeviceBuffer<uint8_t> prev_edges2verdict, prev_verts_are_dirty;
  DeviceBuffer<uint8_t> verts_are_dirty;          // per current vertex: its previous self's
  DeviceBuffer<uint32_t> verts_are_dirty_words;   // the same as 0/1 words (for compact_indices)
  DeviceBuffer<int32_t> verts2prev, tets2prev;    // current -> previous
  DeviceBuffer<int32_t> prev_verts2new;           // previous vertex -> current (collapse_and_compact)
  DeviceBuffer<uint32_t> prev_tets_are_kept, prev_tets2new;  // (collapse_and_compact)
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
