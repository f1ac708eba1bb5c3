#include "improve_collapse.hpp"

#include <cmath>
#include <numbers>

#include "geometry.h"
#include "tetcollapse/collapse.hpp"

namespace tc::mpi {

int64_t collapse_bad_tets(Mesh& mesh, const std::vector<uint8_t>& selected, const ImproveOptions& options,
                          double length) {
  const double cos13 = std::cos(13 * std::numbers::pi / 180);
  std::vector<uint8_t> mask(size_t(mesh.num_vertices()), 0);
  bool any = false;
  for (int64_t t = 0; t < mesh.num_tets(); ++t) {
    geo::tc_d3 p[4];
    for (int k = 0; k < 4; ++k) p[k] = geo::tc_point(mesh.points.data(), mesh.tets[size_t(4 * t + k)]);
    if (geo::tc_tet_max_dihedral_cos(p[0], p[1], p[2], p[3]) <= cos13) continue;
    for (int k = 0; k < 4; ++k) {
      const size_t v = size_t(mesh.tets[size_t(4 * t + k)]);
      mask[v] = selected[v];
      any = any || selected[v];
    }
  }
  if (!any) return 0;
  CollapseOptions o;
  o.method = CollapseOptions::Sequential;
  o.boundary = options.boundary;
  o.eps_f = options.eps_f;
  o.eps_r = options.eps_r;
  o.use_labels = options.use_labels;
  if (options.boundary == CollapseOptions::Features) o.max_boundary_error_abs = options.max_boundary_error_abs;
  o.min_quality = 0.3;
  o.target_length = length;
  o.vertex_mask = std::move(mask);
  const QualitySummary before = quality_summary(mesh);
  Mesh kept = mesh;
  int64_t collapsed = 0;
  for (const IterationStats& it : collapse_sequential(mesh, o).iterations) collapsed += it.collapsed;
  const QualitySummary after = quality_summary(mesh);
  if (after.min_dihedral_deg < before.min_dihedral_deg || after.below_10_deg > before.below_10_deg ||
      after.below_13_deg > before.below_13_deg) {
    mesh = std::move(kept);
    return 0;
  }
  return collapsed;
}

}  // namespace tc::mpi
