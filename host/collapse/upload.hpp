// The current mesh on the device, and how it gets there and back.
#pragma once

#include <cstdint>
#include <vector>

#include "collapse/launch.hpp"
#include "tetcollapse/collapse.hpp"
#include "tetcollapse/mesh.hpp"

namespace tc::collapse_detail {

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
  const cl::Buffer& primary_labels() const { return labels[0].buffer(); }
};

// The refusals both methods share (tc::InputError): array lengths, sizes beyond 32-bit indices
// (12 nt scratch slots must fit), tet vertex indices out of range or repeated, label arrays of
// the wrong length.
void check_collapse_input(const Mesh& mesh);

// An estimate of the device memory the parallel method's busiest stage (the first iteration's
// selection, or its connectivity build) holds for `mesh`, from the counts (the edges taken as
// vertices + tets, as in a mesh with few boundary faces) and the buffers each stage allocates,
// plus a tenth for what depends on the surface and the collapses (the surface guard's queries).
uint64_t device_bytes_estimate(const Mesh& mesh, const CollapseOptions& o);
// Refuses (DeviceError, with the sizes) a mesh whose estimate exceeds the device's global memory
// (CL_DEVICE_GLOBAL_MEM_SIZE), before any work on the device.
void check_device_memory(const Context& ctx, const Mesh& mesh, const CollapseOptions& o);

// With vertex_new, the device mesh is renumbered in spatial order (spatial_order.hpp) and
// *vertex_new receives the map input vertex -> device vertex; else it keeps the input's order.
void upload_mesh(Context& ctx, const Mesh& mesh, const CollapseOptions& o, DeviceMesh& dm,
                 std::vector<int32_t>* vertex_new = nullptr);

void download_mesh(const DeviceMesh& dm, Mesh& mesh);
// upload_mesh, in spatial order with CollapseTuning::spatial_order; returns the map input
// vertex -> device vertex, which collapse_and_compact keeps current.
DeviceBuffer<int32_t> upload_with_origin(Context& ctx, const Mesh& mesh, const CollapseOptions& o, DeviceMesh& dm);
// Triangles or edges (`arity` vertices each) through the vertex map `origin`, in place;
// degenerate ones and those with an index outside the map dropped, tags kept with their element.
// (The device's result, the sequential method's and the improvement's star mesh spliced back.)
void remap_elements(std::vector<int32_t>& elems, std::vector<int32_t>& tags, int arity,
                    const std::vector<int32_t>& origin);
// download_mesh, and the input's triangles and edges remapped through origin (degenerate ones
// dropped).
void download_result(const DeviceMesh& dm, const DeviceBuffer<int32_t>& origin, Mesh& mesh);

}  // namespace tc::collapse_detail
