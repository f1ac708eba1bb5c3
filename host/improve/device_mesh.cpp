// ImpDeviceMesh: the upload both device passes share.
#include "improve/device_mesh.hpp"

namespace tc::improve_detail {

ImpDeviceMesh::ImpDeviceMesh(Context& ctx, const ImpMesh& m)
    : tets(ctx, 4 * size_t(m.num_tet_slots())),
      pts(ctx, 3 * size_t(m.num_vertices())),
      quality(ctx, size_t(m.num_tet_slots())),
      verts2tets_offsets(ctx, size_t(m.num_vertices()) + 1) {
  const int32_t nv = m.num_vertices(), nt = m.num_tet_slots();
  tets.upload(m.tet_data(), 4 * size_t(nt));
  pts.upload(m.point_data(), 3 * size_t(nv));
  std::vector<double> q(static_cast<size_t>(nt));
  for (int32_t t = 0; t < nt; ++t) q[size_t(t)] = m.quality(t);
  quality.upload(q);
  std::vector<uint32_t> offsets(size_t(nv) + 1, 0);
  std::vector<int32_t> vt;
  for (int32_t v = 0; v < nv; ++v) {
    vt.insert(vt.end(), m.tets_of(v).begin(), m.tets_of(v).end());
    offsets[size_t(v) + 1] = uint32_t(vt.size());
  }
  verts2tets_offsets.upload(offsets);
  verts2tets = DeviceBuffer<int32_t>(ctx, vt);
}

}  // namespace tc::improve_detail
