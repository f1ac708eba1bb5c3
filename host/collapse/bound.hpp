// The boundary error bound on the device (cl/collapse_bound.cl): the selection's test refuses
// what exceeds it (programs built with kBoundDefines for the run); after it, the
// chosen collapses that change S get their new bounds (and, as a safeguard, any over the bound
// is refused), written on the survivors once the selection is final. The bound per vertex is the last vertex field component
// (StageParams::eps_col), which collapse() adds for the run.
#pragma once

#include <cstdint>

#include "collapse/connectivity.hpp"
#include "collapse/params.hpp"
#include "collapse/upload.hpp"

namespace tc::collapse_detail {

struct EdgeState;  // edge_state.hpp

struct BoundStage {
  DeviceBuffer<double> edges2eps;
  DeviceBuffer<uint32_t> count;
  // Tests the chosen collapses (s.result.edges_are_final); returns how many were refused (their
  // edges unmarked in s.cost.edges_are_marked, the selection to run again).
  uint32_t test(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p);
  // After the last test: the final collapses' survivors take their bounds.
  void apply(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p);
  void release() { *this = BoundStage{}; }
};

}  // namespace tc::collapse_detail
