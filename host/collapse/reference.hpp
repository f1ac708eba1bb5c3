// The reference surface of the boundary error bound (CollapseOptions::boundary_reference) from
// the device's mesh after its first connectivity build (cl/collapse_reference.cl).
#pragma once

#include <memory>
#include <vector>

#include "collapse/connectivity.hpp"
#include "collapse/upload.hpp"

namespace tc::collapse_detail {

// The S faces of `dm` (those Connectivity::smask marks) as triangles, 9 coordinates each.
std::shared_ptr<const std::vector<double>> reference_surface(Context& ctx, const DeviceMesh& dm,
                                                             const Connectivity& c);

}  // namespace tc::collapse_detail
