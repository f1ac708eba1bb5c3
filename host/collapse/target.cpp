// The target length and the volume threshold a run uses.
#include "collapse/target.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "collapse/cost.hpp"
#include "collapse/edge_state.hpp"
#include "geometry.h"
#include "topology/faces_at_vertices.hpp"

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
  // Each edge once, at its smaller end point, from a vertex -> tets list: 4 bytes per tet corner
  // and 8 per edge, where sorting the tets' edge keys took 32 bytes per tet edge (and rank 0 of
  // the MPI tool measures the whole input before anything else: bench/README.md).
  const int64_t nv = mesh.num_vertices();
  const auto valid = [nv](int32_t v) { return v >= 0 && v < nv; };
  const topology_detail::VertexTets vt(mesh);
  std::vector<int32_t> seen(size_t(nv), -1);  // seen[w] == v: the edge (v, w) is counted
  std::vector<double> len;
  for (int32_t v = 0; v < int32_t(nv); ++v)
    for (int64_t i = vt.offset[size_t(v)]; i < vt.offset[size_t(v) + 1]; ++i) {
      const int32_t* q = &mesh.tets[4 * size_t(vt.around[size_t(i)])];
      int self = 0;  // (a tet that repeats v has the edge (v, v), of length 0)
      for (int k = 0; k < 4; ++k) {
        const int32_t w = q[k];
        self += w == v;
        if (valid(w) && (w > v || (w == v && self == 2)) && seen[size_t(w)] != v) {
          seen[size_t(w)] = v;
          len.push_back(geo::length(geo::tc_point(mesh.points.data(), w) - geo::tc_point(mesh.points.data(), v)));
        }
      }
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
