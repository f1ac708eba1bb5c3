// Point location and vertex fields on the device (tetcollapse/device_fields.hpp; cl/bvh.cl).
//
// Why our own BVH: the OpenCL libraries packaged for Debian (Boost.Compute, clFFT, clBLAS)
// have none, and the linear BVH is a few kernels over the project's own radix sort.
#include "tetcollapse/device_fields.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>

#include "collapse/programs.hpp"
#include "device/primitives.hpp"
#include "fields_detail.hpp"
#include "tetcollapse/fields.hpp"

namespace tc {

namespace {

constexpr const char* kFile = "bvh.cl";

template <class... A>
void launch(Context& ctx, const char* name, size_t n, const A&... a) {
  if (n == 0) return;
  cl::Kernel k = ctx.kernel(kFile, name);
  dev::set_args(k, name, a...);
  ctx.launch(k, n, name);
}

cl_uint u32(int64_t v) { return static_cast<cl_uint>(v); }

}  // namespace

void fields_detail::prefetch_programs(Context& ctx) {
  ctx.prefetch(kFile);
  dev::prefetch_sort(ctx);
  dev::prefetch_scan(ctx);
}

DeviceTetLocator::DeviceTetLocator(const Mesh& mesh, Context& ctx)
    : mesh_(mesh), ctx_(ctx), n_(mesh.num_tets()) {
  if (n_ == 0) return;
  if (n_ > std::numeric_limits<int32_t>::max() / 2)
    throw std::invalid_argument("DeviceTetLocator: more than 2^30 tets");
  tets_ = DeviceBuffer<int32_t>(ctx, mesh.tets);
  points_ = DeviceBuffer<double>(ctx, mesh.points);
  double lo[3], hi[3];
  for (int c = 0; c < 3; ++c) lo[c] = hi[c] = mesh.points[size_t(c)];
  for (size_t i = 0; i + 2 < mesh.points.size(); i += 3)
    for (int c = 0; c < 3; ++c) {
      lo[c] = std::min(lo[c], mesh.points[i + size_t(c)]);
      hi[c] = std::max(hi[c], mesh.points[i + size_t(c)]);
    }
  const double extent = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], 1e-300});
  keys_ = DeviceBuffer<uint64_t>(ctx, size_t(n_));
  launch(ctx, "bvh_keys", size_t(n_), u32(n_), tets_.buffer(), points_.buffer(), lo[0], lo[1], lo[2],
         1023.0 / extent, keys_.buffer());
  dev::radix_sort(ctx, keys_, size_t(n_), 62);  // 30 bits of Morton code above 32 of index
  const int64_t nodes = 2 * n_ - 1;
  child_ = DeviceBuffer<int32_t>(ctx, size_t(std::max<int64_t>(2 * (n_ - 1), 1)));
  DeviceBuffer<int32_t> parent(ctx, std::vector<int32_t>(size_t(nodes), -1));
  launch(ctx, "bvh_nodes", size_t(n_ - 1), u32(n_), keys_.buffer(), child_.buffer(), parent.buffer());
  boxes_ = DeviceBuffer<float>(ctx, size_t(6 * nodes));  // (floats rounded outwards: cl/bvh.cl)
  DeviceBuffer<uint32_t> arrived(ctx, std::vector<uint32_t>(size_t(std::max<int64_t>(n_ - 1, 1)), 0));
  // the boxes a little wider than the tets, so that a point the barycentric test accepts
  // (coordinates >= -1e-12) is never outside its tet's box
  launch(ctx, "bvh_boxes", size_t(n_), u32(n_), keys_.buffer(), tets_.buffer(), points_.buffer(), 1e-9 * extent,
         child_.buffer(), parent.buffer(), boxes_.buffer(), arrived.buffer());
  ctx.finish();
}

void DeviceTetLocator::locate(const std::vector<double>& points, std::vector<int32_t>& tets,
                              std::vector<double>& bary) const {
  const size_t nq = points.size() / 3;
  if (nq > (size_t{1} << 28)) throw std::invalid_argument("DeviceTetLocator::locate: more than 2^28 points");
  tets.assign(nq, -1);
  bary.assign(4 * nq, 0.0);
  if (nq == 0 || n_ == 0) return;
  DeviceBuffer<double> q(ctx_, points), b(ctx_, 4 * nq);
  DeviceBuffer<int32_t> t(ctx_, nq);
  launch(ctx_, "bvh_locate", nq, u32(int64_t(nq)), q.buffer(), u32(n_), keys_.buffer(), child_.buffer(),
         boxes_.buffer(), tets_.buffer(), points_.buffer(), t.buffer(), b.buffer());
  t.download(tets.data(), nq);
  b.download(bary.data(), 4 * nq);
}

void DeviceTetLocator::interpolate(const std::vector<int32_t>& tets, const std::vector<double>& bary,
                                   const std::vector<double>& values, int components, std::vector<double>& out) const {
  const size_t nq = tets.size(), nc = size_t(components);
  if (values.size() != size_t(mesh_.num_vertices()) * nc)
    throw std::invalid_argument("DeviceTetLocator::interpolate: " + std::to_string(values.size()) +
                                " values for " + std::to_string(mesh_.num_vertices()) + " vertices of " +
                                std::to_string(components) + " components");
  out.resize(nq * nc);
  if (nq == 0 || n_ == 0) return;
  DeviceBuffer<int32_t> t(ctx_, tets);
  DeviceBuffer<double> b(ctx_, bary), v(ctx_, values), o(ctx_, out);
  launch(ctx_, "bvh_interpolate", nq, u32(int64_t(nq)), t.buffer(), b.buffer(), tets_.buffer(), v.buffer(),
         u32(components), o.buffer());
  o.download(out.data(), out.size());
}

int64_t resample_vertex_fields(const Mesh& original, Mesh& mesh, Context& ctx) {
  const std::vector<fields_detail::FieldPair> pairs = fields_detail::shared_fields(original, mesh);
  if (pairs.empty() || original.num_tets() == 0) return 0;
  const DeviceTetLocator locator(original, ctx);
  std::vector<int32_t> tets;
  std::vector<double> bary;
  locator.locate(mesh.points, tets, bary);
  for (const auto& p : pairs) locator.interpolate(tets, bary, p.from->values, p.from->components, p.to->values);
  // the points in no tet: the nearest tet's nearest point, on the host
  int64_t outside = 0;
  std::unique_ptr<TetLocator> host;
  for (int64_t v = 0; v < mesh.num_vertices(); ++v) {
    if (tets[size_t(v)] >= 0) continue;
    if (!host) host = std::make_unique<TetLocator>(original);
    double b[4];
    bool out = false;
    const int64_t t = host->locate(&mesh.points[3 * size_t(v)], b, &out);
    outside += out;
    for (const auto& p : pairs) fields_detail::interpolate_at(original, p, t, b, v);
  }
  return outside;
}

}  // namespace tc
