// The admissible filter over every marked edge at once (cl/collapse_admissible.cl, admissible),
// which the atomic-min conflict detection takes, and the quality guard's per-tet qualities.
#pragma once

#include <cstdint>

#include "collapse/connectivity.hpp"
#include "collapse/params.hpp"
#include "collapse/upload.hpp"

namespace tc::collapse_detail {

// The quality guard: tc_tet_quality per tet (collapse_admissible.cl), complete for the
// connectivity of quality_generation, or carried through the compaction (-1: to compute), which
// collapse_and_compact writes.
struct QualityCache {
  DeviceBuffer<double> tets2quality, tets2quality_next;
  uint64_t quality_generation = 0;
  bool quality_carried = false;
};

struct EdgeState;  // edge_state.hpp

// Tests every marked edge (edges_are_admissible, edges2dir, edges2reason); returns the number of admissible edges.
uint32_t admissible(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p);
// The quality guard's per-tet qualities of the current mesh (a placeholder when it is off):
// once per connectivity; after a compaction only the tets that changed (tet_quality_carry).
const cl::Buffer& tet_qualities(Context& ctx, DeviceMesh& dm, const Connectivity& c, QualityCache& q,
                                const StageParams& p);

}  // namespace tc::collapse_detail
