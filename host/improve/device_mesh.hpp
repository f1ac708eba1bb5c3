// The improvement's mesh as its kernels read it (cl/improve_relocate.cl, cl/improve_flip.cl):
// the tet slots, the points, each tet's min-sine and each vertex's tets in the host's order (the
// relocation's ascent sums gradients in that order); a dead slot is in no vertex's list.
#pragma once

#include "improve/improve_mesh.hpp"
#include "tetcollapse/device.hpp"

namespace tc::improve_detail {

struct ImpDeviceMesh {
  ImpDeviceMesh(Context& ctx, const ImpMesh& m);
  DeviceBuffer<int32_t> tets;  // 4 per slot
  DeviceBuffer<double> pts, quality;
  DeviceBuffer<uint32_t> verts2tets_offsets;
  DeviceBuffer<int32_t> verts2tets;
};

}  // namespace tc::improve_detail
