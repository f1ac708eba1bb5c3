// Surface guard (cl/collapse_guard.cl): after the conflict passes, refuses the chosen collapses
// whose new boundary / interface triangles would intersect the feature surface S (another part
// of S across a narrow gap, or another chosen collapse's new triangles). Refused edges are
// unmarked; the caller then selects again (same connectivity) and guards again, until nothing
// is refused. Only collapses that change S are tested, against the S faces near them.
#pragma once

#include <cstdint>

#include <vector>

#include "collapse/connectivity.hpp"
#include "collapse/params.hpp"
#include "collapse/upload.hpp"

namespace tc::collapse_detail {

struct EdgeState;  // edge_state.hpp

struct SurfaceGuard {
  DeviceBuffer<int32_t> qedge, tid;          // per query: its edge; per new triangle: ids
  DeviceBuffer<int32_t> qrep;                // per query: x, and y when it moves (else -1)
  // run_applied: per vertex, the query whose survivor it is (-1: none); per triangle, the lowest
  // survivor among its vertices (each pair of S faces tested once: cl/collapse_guard.cl)
  DeviceBuffer<int32_t> verts2query, tmin;
  DeviceBuffer<double> qbox, tpos, tbox, tplane;  // per query: box; per new triangle: positions, box, plane
  DeviceBuffer<uint32_t> qntri, qoff, qcount, qbad, cell_off;
  DeviceBuffer<int32_t> cell_q;  // per grid entry, by cell (cell_off): query, qrep's x, its low cell packed, 0
  DeviceBuffer<uint32_t> vcell;              // per vertex: its cell, packed (sguard_vertex_cells)
  uint32_t last_queries = 0;  // collapses tested by the last run (that change S)
  DeviceBuffer<uint32_t> stets;  // the tets owning an S face (n_stets), listed for the connectivity
  uint64_t stets_generation = 0;  // of this Connectivity::generation
  uint32_t n_stets = 0;

  DeviceBuffer<uint32_t> applied_owns_s, applied_stets;  // run_applied: the S faces of the result
  DeviceBuffer<uint8_t> applied_smask;
  DeviceBuffer<uint8_t> requery;  // per edge: queried again by the next run_applied (restrict_to_undone)
  DeviceBuffer<uint32_t> undone_list;
  DeviceBuffer<double> undone_boxes;
  bool only_requery = false;
  // run_applied tests each pair of S faces once, for the query of its lowest survivor, and a hit
  // refuses every query of the pair (cl/collapse_guard.cl); false: once per query of the pair,
  // as run does (the same refusals; for the tests). last_run_each_pair_once: whether the last run
  // tested pairs, each once (false when it had no query, and for run).
  bool each_pair_once = true;
  bool last_run_each_pair_once = false;

  // Tests the `chosen` collapses of s.result (edges_are_final, edges2dir); returns how many were
  // refused (their edges are unmarked in s.cost.edges_are_marked).
  uint32_t run(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p, uint32_t chosen);
  // The same for the matching selection, whose collapses are applied to dm and c.tet_nbr
  // (SelectionResult::in_place): on the result (cl/collapse_guard_applied.cl).
  uint32_t run_applied(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                       uint32_t chosen);
  // After the matching selection undid the collapses of `undone` (after a run_applied that
  // refused some): the next run_applied tests only the queries that the undo may concern
  // (cl/collapse_guard_applied.cl, sguard_undone_boxes).
  // Frees the buffers (Selection::release); the next run allocates them again.
  void release();
  void restrict_to_undone(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s,
                          const std::vector<uint32_t>& undone);
  // After a run that refused collapses: their edges flagged in flag (1) and listed in list (from
  // count[0] on, which is advanced).
  void refused_edges(Context& ctx, DeviceBuffer<uint8_t>& flag, DeviceBuffer<uint32_t>& list,
                     DeviceBuffer<uint32_t>& count);

 private:
  // qoff from the nq queries' triangle counts (qntri); returns the triangles in all.
  uint32_t query_offsets(Context& ctx, uint32_t nq);
  void reserve_triangles(Context& ctx, uint32_t nq, uint32_t ntri);
  // The queries' triangles (tid, ...) against the S faces the n_sweep tets of sweep_tets own
  // (smask) and against each other, through a grid; the queries with a hit are refused. each_once:
  // each pair once (run_applied, with verts2query and tmin filled).
  uint32_t test_queries(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                        uint32_t chosen, uint32_t nq, DeviceBuffer<uint8_t>& smask, DeviceBuffer<uint32_t>& sweep_tets,
                        uint32_t n_sweep, bool each_once);
};

}  // namespace tc::collapse_detail
