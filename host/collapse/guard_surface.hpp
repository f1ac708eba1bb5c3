// Surface guard (cl/collapse_guard.cl): after the conflict passes, refuses the chosen collapses
// whose new boundary / interface triangles would intersect the feature surface S (another part
// of S across a narrow gap, or another chosen collapse's new triangles). Refused edges are
// unmarked; the caller then selects again (same connectivity) and guards again, until nothing
// is refused. Only collapses that change S are tested, against the S faces near them.
#pragma once

#include <cstdint>

#include "collapse/stages.hpp"

namespace tc::collapse_detail {

struct SurfaceGuard {
  DeviceBuffer<int32_t> qedge, tid;          // per query: its edge; per new triangle: ids
  DeviceBuffer<int32_t> qrep;                // per query: x, and y when it moves (else -1)
  DeviceBuffer<double> qbox, tpos, tbox, tplane;  // per query: box; per new triangle: positions, box, plane
  DeviceBuffer<uint32_t> qntri, qoff, qcount, qbad, cell_off, cell_items;
  DeviceBuffer<int32_t> qcell;               // per query: the cells of its box's low and high corners (6 ints)
  DeviceBuffer<uint32_t> vcell;              // per vertex: its cell, packed (sguard_vertex_cells)
  uint32_t last_queries = 0;  // collapses tested by the last run (that change S)
  DeviceBuffer<uint32_t> stets;  // the tets owning an S face (n_stets), listed for the connectivity
  uint64_t stets_generation = 0;  // of this Connectivity::generation
  uint32_t n_stets = 0;

  // Tests the `chosen` collapses of s.fin / s.dir; returns how many were refused (their edges
  // are unmarked in s.marked).
  uint32_t run(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p, uint32_t chosen);
};

}  // namespace tc::collapse_detail
