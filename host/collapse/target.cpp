// The target length and the volume threshold a run uses.
#include "collapse/target.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "collapse/cost.hpp"
#include "collapse/edge_state.hpp"
#include "geometry.h"
#include "topology/topology_detail.hpp"

namespace tc {

namespace {

// nth_element: the lower median for an even count, as in tc::summarize.
double median_of(std::vector<double> v) {
  if (v.empty()) return 0;
  size_t m = (v.size() - 1) / 2;
  std::nth_element(v.begin(), v.begin() + m, v.end());
  return v[m];
}

}  // namespace

double median_edge_length(const Mesh& mesh) {
  // each edge once: its keys sorted by the topology's radix sort (a few times std::sort's speed
  // on a mesh's millions of keys; the improvement asks this once per round)
  std::vector<topology_detail::KeyPayload> keys;
  keys.reserve(mesh.tets.size() / 4 * 6);
  for (size_t t = 0; t + 3 < mesh.tets.size(); t += 4)
    for (int e = 0; e < 6; ++e) {
      uint32_t a = uint32_t(mesh.tets[t + geo::TC_TET_EDGES[e][0]]), b = uint32_t(mesh.tets[t + geo::TC_TET_EDGES[e][1]]);
      if (a > b) std::swap(a, b);
      keys.push_back({uint64_t(a) << 32 | b, 0});
    }
  topology_detail::radix_sort(keys);
  std::vector<double> len;
  len.reserve(keys.size());
  const int64_t nv = mesh.num_vertices();
  for (size_t i = 0; i < keys.size(); ++i) {
    if (i > 0 && keys[i].key == keys[i - 1].key) continue;
    const uint64_t k = keys[i].key;
    int64_t a = int64_t(k >> 32), b = int64_t(k & 0xffffffffu);
    if (a >= nv || b >= nv) continue;
    double d = 0;
    for (int c = 0; c < 3; ++c) d += (mesh.points[3 * b + c] - mesh.points[3 * a + c]) * (mesh.points[3 * b + c] - mesh.points[3 * a + c]);
    len.push_back(std::sqrt(d));
  }
  return median_of(std::move(len));
}

namespace {
double bbox_diagonal_squared(const Mesh& mesh) {
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (size_t i = 0; i + 2 < mesh.points.size(); i += 3)
    for (int c = 0; c < 3; ++c) {
      lo[c] = std::min(lo[c], mesh.points[i + c]);
      hi[c] = std::max(hi[c], mesh.points[i + c]);
    }
  double d2 = 0;
  for (int c = 0; c < 3; ++c) d2 += hi[c] > lo[c] ? (hi[c] - lo[c]) * (hi[c] - lo[c]) : 0;
  return d2;
}
}  // namespace

double volume_threshold(const Mesh& mesh, const CollapseOptions& options) {
  switch (options.eps_v_scale) {
    case CollapseOptions::Absolute:
      return options.eps_v;
    case CollapseOptions::DiagonalCubed: {
      const double d2 = bbox_diagonal_squared(mesh);
      return options.eps_v * d2 * std::sqrt(d2);
    }
    case CollapseOptions::MeanTetVolume:
      break;
  }
  // (unsigned: a mesh of negative tets refused later is measured as well)
  return mesh.num_tets() > 0 ? options.eps_v * mean_tet_volume(mesh) : options.eps_v;
}

double boundary_error_bound(const Mesh& mesh, const CollapseOptions& options) {
  if (options.max_boundary_error_abs > 0) return options.max_boundary_error_abs;
  return options.max_boundary_error * std::sqrt(bbox_diagonal_squared(mesh));
}

namespace collapse_detail {

double target_length(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                     const CollapseOptions& o, CollapseReport& report) {
  if (o.target_length > 0) return o.target_length;
  // the edge lengths are the cost without a user cost and without a target
  StageParams q = p;
  q.cost_source.clear();
  q.target = 0;
  cost_and_mark(ctx, dm, c, s, q);
  report.median_edge_length = median_of(s.cost.edges2cost.download_range(0, c.ne));
  return o.target_factor * report.median_edge_length;
}

}  // namespace collapse_detail

}  // namespace tc
