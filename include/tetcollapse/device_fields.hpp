// Point location and vertex fields on the OpenCL device (the paper's Section 4.5: a vertex of
// the coarse mesh takes the value of the original piecewise linear field at its place, found
// through a BVH of the original tets built on the device).
//
//   tc::Mesh original = mesh;
//   tc::collapse(mesh, options, ctx);
//   tc::resample_vertex_fields(original, mesh, ctx);   // as tetcollapse/fields.hpp's, on ctx
#pragma once

#include <cstdint>
#include <vector>

#include "tetcollapse/device.hpp"
#include "tetcollapse/mesh.hpp"

namespace tc {

// A linear BVH over a mesh's tets (Karras 2012), built and queried on the device (cl/bvh.cl).
// It answers as TetLocator does for a point inside the mesh: the lowest-numbered tet in which
// every barycentric coordinate of the point is at least -1e-12, with those coordinates, by the
// same operations (geometry.h's tc_barycentric); -1 for a point in no tet, for which TetLocator
// finds the nearest tet on the host. The mesh must outlive the locator.
class DeviceTetLocator {
 public:
  DeviceTetLocator(const Mesh& mesh, Context& ctx);
  // points: xyz per point; tets and bary (4 per point) are resized.
  void locate(const std::vector<double>& points, std::vector<int32_t>& tets, std::vector<double>& bary) const;
  // The located points' field (`components` values per vertex of the mesh) at each point, where
  // tets[i] >= 0 (the others are left as they were in out).
  void interpolate(const std::vector<int32_t>& tets, const std::vector<double>& bary, const std::vector<double>& values,
                   int components, std::vector<double>& out) const;
  int64_t nodes() const { return 2 * n_ - 1; }

 private:
  const Mesh& mesh_;
  Context& ctx_;
  int64_t n_ = 0;  // leaves: the mesh's tets
  DeviceBuffer<int32_t> tets_;
  DeviceBuffer<double> points_;
  DeviceBuffer<float> boxes_;  // (floats rounded outwards: cl/bvh.cl)
  DeviceBuffer<uint64_t> keys_;
  DeviceBuffer<int32_t> child_;
};

// resample_vertex_fields (tetcollapse/fields.hpp) with the points inside the original located
// and interpolated on the device; the same values. Returns how many vertices lay outside.
int64_t resample_vertex_fields(const Mesh& original, Mesh& mesh, Context& ctx);

}  // namespace tc
