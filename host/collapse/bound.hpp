// The boundary error bound on the device (cl/collapse_bound.cl): the selection's test refuses
// what exceeds it (programs built with kBoundDefines for the run) and keeps each taken
// collapse's new bound (SelectionResult::edges2eps), which the survivors take once the
// selection is final. The bound per vertex is the last vertex field component
// (StageParams::eps_col), which collapse() adds for the run.
#pragma once

#include "collapse/connectivity.hpp"
#include "collapse/params.hpp"
#include "collapse/upload.hpp"

namespace tc::collapse_detail {

struct EdgeState;  // edge_state.hpp

// After the last selection of an iteration: the final collapses' survivors take their bounds.
void bound_apply(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p);

}  // namespace tc::collapse_detail
