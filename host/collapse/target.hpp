// The target length a run uses (tc::median_edge_length and tc::volume_threshold are public).
#pragma once

#include "collapse/connectivity.hpp"
#include "collapse/params.hpp"
#include "collapse/upload.hpp"
#include "tetcollapse/collapse.hpp"

namespace tc::collapse_detail {

struct EdgeState;  // edge_state.hpp

// o.target_length, or o.target_factor x the median edge length of the mesh of `c` (the
// device's edge list; also in report.median_edge_length).
double target_length(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                     const CollapseOptions& o, CollapseReport& report);

}  // namespace tc::collapse_detail
