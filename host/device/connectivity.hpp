// Connectivity and boundary classification on the device (paper, Section 3.1).
//
// Builds, from device buffers of points and tets, the same arrays as tc::build_topology (see
// include/tetcollapse/topology.hpp for their definitions and orders), kept on the device for
// the later stages. download() returns them as a tc::Topology, equal array by array to the
// single-threaded construction. Kernels: cl/connectivity.cl, cl/classify.cl.
#pragma once

#include <cstdint>

#include "tetcollapse/device.hpp"
#include "tetcollapse/mesh.hpp"
#include "tetcollapse/topology.hpp"

namespace tc::dev {

struct DeviceTopology {
  uint32_t num_vertices = 0, num_tets = 0, num_edges = 0, num_sfaces = 0;

  DeviceBuffer<uint32_t> edges;      // 2 per edge
  DeviceBuffer<uint32_t> tet_edges;  // 6 per tet
  DeviceBuffer<uint32_t> vertex_tets_offsets, vertex_tets;
  DeviceBuffer<uint32_t> vertex_edges_offsets, vertex_edges;
  DeviceBuffer<uint32_t> edge_tets_offsets, edge_tets;

  DeviceBuffer<uint32_t> sfaces;  // 3 per S-face (boundary and interface faces)
  DeviceBuffer<uint32_t> sface_tet;
  DeviceBuffer<int8_t> sface_local;
  DeviceBuffer<uint8_t> sface_interface;
  DeviceBuffer<double> sface_normals;  // 3 per S-face
  DeviceBuffer<uint32_t> vertex_sfaces_offsets, vertex_sfaces;
  DeviceBuffer<uint32_t> edge_sfaces_offsets, edge_sfaces;

  DeviceBuffer<uint8_t> vertex_boundary, edge_boundary;  // kOnBoundary | kOnInterface
  DeviceBuffer<uint8_t> vertex_class;                    // tc::VertexClass
  DeviceBuffer<uint8_t> edge_ridge;

  // Bytes held by the arrays above.
  size_t bytes() const;
  // Copies everything to the host.
  Topology download() const;
};

// points: 3 doubles per vertex (num_vertices of them); tets: 4 indices per tet; labels: one
// per tet or nullptr (ignored unless options.use_labels). Throws tc::InputError ("<mesh>")
// for an index out of range or a repeated vertex in a tet, DeviceError on OpenCL failures.
DeviceTopology build_device_topology(Context& ctx, const DeviceBuffer<double>& points,
                                     const DeviceBuffer<int32_t>& tets, uint32_t num_vertices,
                                     const DeviceBuffer<int32_t>* labels, const TopologyOptions& options = {},
                                     TopologyTimings* timings = nullptr);

// Convenience: uploads the mesh (first label array as labels) and builds.
DeviceTopology build_device_topology(Context& ctx, const Mesh& mesh, const TopologyOptions& options = {},
                                     TopologyTimings* timings = nullptr);

}  // namespace tc::dev
