// The stages of one collapse iteration over device buffers (used by collapse(), and by the
// tests one stage at a time). Kernels: cl/collapse_*.cl; shared helpers: cl/collapse_common.h.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "collapse/launch.hpp"
#include "tetcollapse/collapse.hpp"
#include "tetcollapse/device.hpp"
#include "tetcollapse/mesh.hpp"

namespace tc::collapse_detail {

struct SurfaceGuard;  // guard_surface.hpp

// The current mesh on the device.
struct DeviceMesh {
  uint32_t nv = 0, nt = 0;
  DeviceBuffer<double> points;        // 3 per vertex
  DeviceBuffer<int32_t> tets;         // 4 per tet
  bool has_labels = false;            // primary labels drive material interfaces
  std::vector<DeviceBuffer<int32_t>> labels;  // every label array of the mesh, 1 per tet
  uint32_t vfield_comps = 0, tfield_comps = 0;  // all fields packed per entity
  DeviceBuffer<double> vfields, tfields;
  bool has_mask = false;
  DeviceBuffer<uint8_t> vmask;
  // ring(v) of every vertex (ascending), filled on the host by upload_mesh with
  // Context::cpu_tuning (a CPU device);
  // the first build_connectivity takes them (has_rings then false)
  bool has_rings = false;
  DeviceBuffer<uint32_t> vt_off;  // nv + 1
  DeviceBuffer<int32_t> vt;       // 4 nt
};

// Stage 1 output.
struct Connectivity {
  uint32_t ne = 0;
  DeviceBuffer<uint32_t> vt_off;   // nv + 1
  DeviceBuffer<int32_t> vt;        // 4 nt: ring(v), ascending
  DeviceBuffer<uint32_t> nb_off;   // nv + 1
  DeviceBuffer<int32_t> nb;        // N(v), ascending
  DeviceBuffer<int32_t> nb_edge;   // edge id of each N(v) entry
  DeviceBuffer<uint32_t> edge_off; // nv + 1: edges owned by v (v is the smaller end)
  DeviceBuffer<int32_t> edges;     // 2 per edge, sorted lexicographically
  DeviceBuffer<int32_t> tet_nbr;   // 4 per tet: tet across each face (collapse_common.h)
  DeviceBuffer<uint8_t> vflags, vclass, eflags;  // see collapse_common.h
  DeviceBuffer<uint32_t> owns_s;   // per tet: 1 when it owns an S face (the surface guard's tets)
  DeviceBuffer<uint8_t> smask;     // per tet: which faces it owns on S (bit f: the face opposite local vertex f)
  uint64_t generation = 0;         // new (process-wide unique) at every build_connectivity
  // scratch
  DeviceBuffer<uint32_t> count, cursor, up_count;
  DeviceBuffer<int32_t> scratch;
  DeviceBuffer<uint32_t> dirty_list;  // vertices recomputed when carrying (build_connectivity)
};

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

// The refusals both methods share (tc::InputError): array lengths, sizes beyond 32-bit indices
// (12 nt scratch slots must fit), tet vertex indices out of range or repeated, label arrays of
// the wrong length.
void check_collapse_input(const Mesh& mesh);

enum Reason : uint8_t {
  kOk = 0, kNotMarked = 1, kRefusedQ = 2, kRefusedLink = 3, kRefusedVolume = 4, kRefusedQuality = 6,
  kUntested = 5,  // lazy filter: passed Q, never tested because a cheaper rival won (an edge
                  // with a refusal carried from the previous iteration keeps that reason)
  kRefusedSurface = 7,  // the surface guard (guard_surface.hpp)
  kVolumeOk = 8         // in verdict[] only (TCC_VOLUME_OK): the volume test passed, the link not yet run
};

struct StageParams {
  int mode = 1;  // 0 strict, 1 features, 2 free
  bool paper_rule = false;
  bool use_labels = true;
  double eps_f = 0.01, eps_r = 0.1, eps_v = 2e-12;
  double min_quality = 0;  // quality guard, 0 = off
  double target = 0;
  int mask_mode = 0;  // 0 none, 1 both, 2 either
  std::string cost_source;  // user cost, "" for the edge length
  // The user's placement and predicate (OpenCL C, "" for none) and the -D options that switch
  // them on (collapse_common.h): compiled into the kernels that place a survivor or evaluate Q
  // (stage_kernel).
  std::string user_source, user_defines;
  // One work-group for the conflict rounds (no launch and read-back per round): lazy pass 1
  // once at most loop_tests edges of a turn list are to be tested and loop_turns in all, back
  // to per-round launches when a list has more than loop_exit_tests to test; pass 2
  // (conflict_pass2's loop_size) once at most 2048 candidates wait. Results do not depend on
  // them (tests set them to 0 and to the maximum).
  uint32_t loop_tests = 128, loop_turns = 4096, loop_exit_tests = 512;
  // Greedy selection: the priority in steps of target / priority_levels (0: the exact cost),
  // CollapseOptions::priority_levels; its rounds run in one work-group (greedy_loop) once the
  // turn list holds at most greedy_loop_size edges, back to per-round kernels when one holds
  // more than greedy_loop_exit. Results do not depend on the last two. With the waiting lists a
  // turn list holds only edges to decide (~3 us of a core each on W1), so one core is slower
  // than two plus a round's launches (~0.25 ms) above ~170 of them (bench_selection, matching,
  // 6-8 alternations, medians: iteration 3 0.077 s against 0.086 s at 512/2048, iteration 6
  // 0.043 s against 0.048 s, iteration 0 the same).
  double priority_levels = 64;
  uint32_t greedy_loop_size = 128, greedy_loop_exit = 512;
  // Greedy and matching selections: an edge waiting for its blocker waits on the blocker's
  // vertex and is woken when the blocker decides (tcc_wait_on, cl/collapse_select.h), instead of
  // going to every turn list until then. Results do not depend on it.
  bool waiting_lists = true;
  // Matching selection: a waiting edge's early volume test (cl/collapse_matching.cl, spec).
  bool match_early_tests = true;
};
StageParams params_from(const CollapseOptions& o);

// With vertex_new, the device mesh is renumbered in spatial order (spatial_order.hpp) and
// *vertex_new receives the map input vertex -> device vertex; else it keeps the input's order.
void upload_mesh(Context& ctx, const Mesh& mesh, const CollapseOptions& o, DeviceMesh& dm,
                 std::vector<int32_t>* vertex_new = nullptr);

// With carry (an EdgeState after note_compaction), the data (N(v), tet_nbr, vclass,
// eflags) of the vertices whose rings did not change is copied from the previous iteration
// instead of recomputed, and the rings and tet_nbr computed by collapse_and_compact are taken
// over (carry->upd_*, swapped into c).
void build_connectivity(Context& ctx, DeviceMesh& dm, Connectivity& c, const StageParams& p,
                        EdgeState* carry = nullptr);
// Returns the number of marked edges.
uint32_t cost_and_mark(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p);
// Tests every marked edge (adm, dir, reason); returns the number of admissible edges.
uint32_t admissible(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p);
// Conflict pass 1 over the admissible edges (s.adm); returns the number kept.
uint32_t conflict_pass1(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s);
// admissible() followed by conflict_pass1() with the same result (p1, vaff, dir of the kept
// edges), testing only the edges whose turn comes (cl/collapse_admissible.cl). Returns the
// number kept; passed_q and tested receive the number of marked edges passing Q and tested.
uint32_t lazy_admissible_pass1(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                               uint32_t& passed_q, uint32_t& tested);
uint32_t conflict_pass2(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, uint32_t loop_size = 2048);
// The greedy selection (cl/collapse_admissible.cl, greedy_*), in place of
// lazy_admissible_pass1 and conflict_pass2: the edges that taking the candidates one after
// another in priority order would take, skipping those that fail the tests or touch a tet of
// an edge taken before. Each edge is tested when its turn comes. Outputs as conflict_pass2
// (fin, p1 = fin, vaff, dir); returns the number taken; passed_q and tested as
// lazy_admissible_pass1 (tested: the edges whose volume test ran).
uint32_t greedy_selection(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                          uint32_t& passed_q, uint32_t& tested);
// The matching selection (cl/collapse_matching.cl), in place of greedy_selection: the edges that
// taking the candidates one after another in priority order would take, each tested on the mesh
// with the earlier ones collapsed, skipping only those that share an end point with an edge
// taken before. The collapses are applied to dm (tets, points, fields) and c.tet_nbr as they are
// taken (s.tdead: the removed tets; s.in_place), so matching_backup must come before and
// collapse_and_compact after (it then only compacts). Outputs and counts as greedy_selection.
uint32_t matching_selection(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                            uint32_t& passed_q, uint32_t& tested);
// Keeps the positions and vertex fields as they are, for matching_undo.
void matching_backup(Context& ctx, DeviceMesh& dm, EdgeState& s);
// After SurfaceGuard::run_applied refused collapses of the matching selection: undoes them and
// every collapse taken after one of them within reach (cl/collapse_matching.cl, match_undo*);
// returns how many were undone (fin, vaff, state and the mesh updated), and has the guard's next
// run test only what the undo may concern (SurfaceGuard::restrict_to_undone). The second form
// undoes the edges of `refused` (taken ones) and their closure instead (listed in *undone).
uint32_t matching_undo(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, SurfaceGuard& guard);
uint32_t matching_undo(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s,
                       const std::vector<uint32_t>& refused, std::vector<uint32_t>* undone = nullptr);
// Atomic-min conflict detection (host/collapse/conflict_atomic.cpp) over the admissible edges
// of admissible(): replaces both conflict passes, with the same outputs as conflict_pass2.
// Returns the number of edges to collapse.
uint32_t conflicts_atomic_min(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s);
// Applies the final collapses (the survivors at p's placement): dm becomes the new mesh (via
// `next`, swapped in); origin (input vertex -> current vertex) is updated when non-empty.
void collapse_and_compact(Context& ctx, const StageParams& p, DeviceMesh& dm, DeviceMesh& next, Connectivity& c,
                          EdgeState& s, DeviceBuffer<int32_t>& origin, uint32_t n_origin);

// A further selection round in the same connectivity after conflict_pass2: edges whose end
// points are neither end points of the collapses chosen so far nor their neighbours (their
// stars are disjoint from those collapses, which change nothing the edges' tests look at) go
// through the lazy filter and both conflict passes again; the result is merged (fin, dir,
// vaff). Returns the total number of collapses chosen; tested receives the round's tests.
uint32_t next_selection_round(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                              uint32_t& tested);

// Verdict carrying around collapse_and_compact: remember_for_carry() before it (dirty vertices:
// the end points of the final edges and their neighbours), note_compaction() right after it
// (previous connectivity and verdicts kept, current -> previous vertex map), carry_verdicts()
// after the next build_connectivity (fills s.verdict for the next lazy_admissible_pass1).
void remember_for_carry(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s);
void note_compaction(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s);
void carry_verdicts(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s);
// After carry_verdicts: per vertex, whether its ring changed in the last iteration or an edge at
// it keeps the surface guard's refusal (cl/collapse_verdicts.cl tail_touched; the host tail's
// TailSeed::touched).
std::vector<uint8_t> tail_touched(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s);

void download_mesh(const DeviceMesh& dm, Mesh& mesh);

}  // namespace tc::collapse_detail
