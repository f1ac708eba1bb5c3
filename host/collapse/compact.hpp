// The last stage of an iteration: the collapses applied, the mesh compacted
// (cl/collapse_compact.cl, cl/collapse_update.cl).
#pragma once

#include <cstdint>

#include "collapse/connectivity.hpp"
#include "collapse/edge_state.hpp"
#include "collapse/params.hpp"
#include "collapse/upload.hpp"

namespace tc::collapse_detail {

// Applies the final collapses (the survivors at p's placement): dm becomes the new mesh (via
// `next`, swapped in); origin (input vertex -> current vertex) is updated when non-empty.
void collapse_and_compact(Context& ctx, const StageParams& p, DeviceMesh& dm, DeviceMesh& next, Connectivity& c,
                          EdgeState& s, DeviceBuffer<int32_t>& origin, uint32_t n_origin);

}  // namespace tc::collapse_detail
