#include "field_points.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "tetcollapse/fields.hpp"

namespace tc::mpi {

namespace {

const Field& named_field(const Mesh& m, const std::string& name) {
  const Field* f = m.find_vertex_field(name);
  if (!f) throw std::invalid_argument("no vertex field named '" + name + "'");
  return *f;
}

// The vertices some tet uses: an unused one is not part of the field (the library's rule).
std::vector<uint8_t> used_vertices(const Mesh& m) {
  std::vector<uint8_t> used(size_t(m.num_vertices()), 0);
  for (int32_t v : m.tets) used[size_t(v)] = 1;
  return used;
}

}  // namespace

std::vector<double> field_range(const Mesh& input, const std::string& name) {
  const Field& f = named_field(input, name);
  const size_t nc = size_t(f.components);
  std::vector<double> lo(nc, INFINITY), hi(nc, -INFINITY), range(nc, 0.0);
  for (size_t i = 0; i < f.values.size(); ++i) {
    lo[i % nc] = std::min(lo[i % nc], f.values[i]);
    hi[i % nc] = std::max(hi[i % nc], f.values[i]);
  }
  for (size_t c = 0; c < nc; ++c) range[c] = hi[c] >= lo[c] ? hi[c] - lo[c] : 0.0;
  return range;
}

FieldPointCut::FieldPointCut(const Mesh& input, const std::string& name, const Mesh& whole,
                             const std::vector<int32_t>& tet_part, int nparts)
    : input_(input), field_(named_field(input, name)) {
  // each tet's index within its part, in the global order (Splitter::extract's)
  std::vector<int32_t> local(tet_part.size()), count(size_t(nparts), 0);
  for (size_t t = 0; t < tet_part.size(); ++t) local[t] = count[size_t(tet_part[t])]++;
  const std::vector<uint8_t> used = used_vertices(input);
  const TetLocator loc(whole);
  const int64_t nv = input.num_vertices();
  part_of_.assign(size_t(nv), -1);
  local_tet_.assign(size_t(nv), -1);
  for (int64_t v = 0; v < nv; ++v) {
    if (!used[size_t(v)]) continue;
    double b[4];
    const int64_t t = loc.locate(&input.points[3 * size_t(v)], b);
    if (t < 0) continue;
    part_of_[size_t(v)] = tet_part[size_t(t)];
    local_tet_[size_t(v)] = local[size_t(t)];
  }
}

void FieldPointCut::fill(int p, Part& part) const {
  const Field& f = field_;
  const size_t nc = size_t(f.components);
  part.field_points.clear();
  part.field_values.clear();
  part.field_tets.clear();
  for (size_t v = 0; v < part_of_.size(); ++v) {
    if (part_of_[v] != p) continue;
    part.field_points.insert(part.field_points.end(), &input_.points[3 * v], &input_.points[3 * v + 3]);
    part.field_values.insert(part.field_values.end(), &f.values[nc * v], &f.values[nc * v + nc]);
    part.field_tets.push_back(local_tet_[v]);
  }
}

double measured_field_error(const Mesh& input, const std::string& name, const Mesh& mesh,
                            const std::vector<double>& range) {
  const Field& f = named_field(input, name);
  const Field& g = named_field(mesh, name);
  const size_t nc = size_t(f.components);
  if (size_t(g.components) != nc) throw std::logic_error("the bounded field lost components");
  const std::vector<uint8_t> used = used_vertices(input);
  const TetLocator loc(mesh);
  double worst = 0;
  for (int64_t v = 0; v < input.num_vertices(); ++v) {
    double b[4];
    const int64_t t = used[size_t(v)] ? loc.locate(&input.points[3 * size_t(v)], b) : -1;
    if (t < 0) continue;
    for (size_t c = 0; c < nc; ++c) {
      if (!(range[c] > 0)) continue;
      double x = 0;
      for (int k = 0; k < 4; ++k) x += b[k] * g.values[nc * size_t(mesh.tets[4 * size_t(t) + size_t(k)]) + c];
      worst = std::max(worst, std::abs(x - f.values[nc * size_t(v) + c]) / range[c]);
    }
  }
  return worst;
}

}  // namespace tc::mpi
