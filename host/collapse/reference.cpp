// The reference surface from the device (reference.hpp).
#include "collapse/reference.hpp"

#include "collapse/launch.hpp"
#include "device/primitives.hpp"

namespace tc::collapse_detail {

std::shared_ptr<const std::vector<double>> reference_surface(Context& ctx, const DeviceMesh& dm,
                                                             const Connectivity& c) {
  auto out = std::make_shared<std::vector<double>>();
  if (dm.nt == 0) return out;
  const std::string F = "collapse_reference.cl";
  DeviceBuffer<uint32_t> stets(ctx, dm.nt);
  const uint32_t n = dev::compact_indices(ctx, c.owns_s, stets, dm.nt);
  if (n == 0) return out;
  DeviceBuffer<uint32_t> counts(ctx, n), off;
  run(ctx, F, "reference_counts", n, arg("n", n), arg("stets", stets), arg("smask", c.smask), arg("counts", counts));
  const uint32_t total = scan_offsets(ctx, counts, off, n);
  DeviceBuffer<double> tris(ctx, 9 * size_t(total));
  run(ctx, F, "reference_write", n, arg("n", n), arg("stets", stets), arg("smask", c.smask), arg("off", off),
      arg("tets", dm.tets), arg("pts", dm.points), arg("out", tris));
  *out = tris.download();
  return out;
}

}  // namespace tc::collapse_detail
