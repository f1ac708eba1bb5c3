#include "collapse/spatial_order.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace tc::collapse_detail {

namespace {
// The 21 low bits of x spread to every third bit of a 63-bit word.
uint64_t spread3(uint64_t x) {
  x &= 0x1fffff;
  x = (x | x << 32) & 0x1f00000000ffffULL;
  x = (x | x << 16) & 0x1f0000ff0000ffULL;
  x = (x | x << 8) & 0x100f00f00f00f00fULL;
  x = (x | x << 4) & 0x10c30c30c30c30c3ULL;
  x = (x | x << 2) & 0x1249249249249249ULL;
  return x;
}
}  // namespace

SpatialOrder spatial_order(const Mesh& mesh) {
  const size_t nv = size_t(mesh.num_vertices()), nt = size_t(mesh.num_tets());
  SpatialOrder o;
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (size_t v = 0; v < nv; ++v)
    for (int c = 0; c < 3; ++c) {
      const double x = mesh.points[3 * v + c];
      if (!std::isfinite(x)) continue;
      lo[c] = std::min(lo[c], x);
      hi[c] = std::max(hi[c], x);
    }
  double extent = 0;
  for (int c = 0; c < 3; ++c) extent = std::max(extent, hi[c] > lo[c] ? hi[c] - lo[c] : 0.0);
  // 0 when every point is the same, or when the extent overflows (coordinates near +-1e308)
  const double scale = extent > 0 && std::isfinite(extent) ? double((1u << 21) - 1) / extent : 0;
  // (code, input index) sorted as pairs, not indices through a comparator that looks the codes
  // up: the same order, without a cache miss per comparison
  std::vector<std::pair<uint64_t, int32_t>> code(nv);
  for (size_t v = 0; v < nv; ++v) {
    uint64_t k = 0;
    for (int c = 0; c < 3; ++c) {
      const double x = mesh.points[3 * v + c];
      const double q = std::isfinite(x) && scale > 0 ? (x - lo[c]) * scale : 0.0;  // non-finite: refused later
      k |= spread3(q > 0 ? uint64_t(std::min(q, double((1u << 21) - 1))) : 0) << c;
    }
    code[v] = {k, int32_t(v)};
  }
  std::sort(code.begin(), code.end());
  o.vertex_old.resize(nv);
  o.vertex_new.resize(nv);
  for (size_t i = 0; i < nv; ++i) {
    o.vertex_old[i] = code[i].second;
    o.vertex_new[size_t(code[i].second)] = int32_t(i);
  }
  // tets: a stable counting sort by their smallest new vertex index, each placed renumbered
  std::vector<uint32_t> start(nv + 1, 0), key(nt);
  for (size_t t = 0; t < nt; ++t) {
    int32_t m = o.vertex_new[size_t(mesh.tets[4 * t])];
    for (int k = 1; k < 4; ++k) m = std::min(m, o.vertex_new[size_t(mesh.tets[4 * t + k])]);
    key[t] = uint32_t(m);
    ++start[size_t(m) + 1];
  }
  for (size_t v = 0; v < nv; ++v) start[v + 1] += start[v];
  o.tet_old.resize(nt);
  o.tets.resize(4 * nt);
  for (size_t t = 0; t < nt; ++t) {
    const uint32_t at = start[key[t]]++;
    o.tet_old[at] = int32_t(t);
    for (int k = 0; k < 4; ++k) o.tets[4 * size_t(at) + k] = o.vertex_new[size_t(mesh.tets[4 * t + k])];
  }
  return o;
}

}  // namespace tc::collapse_detail
