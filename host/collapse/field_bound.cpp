// The field error bound of the sequential method: see collapse/field_bound.hpp.
#include "collapse/field_bound.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "collapse_predicate.h"
#include "fields_detail.hpp"

namespace tc::sequential_detail {

using geo::tc_d3;

void SeqMesh::collapse_region(int32_t a, int32_t b, uint8_t dir, std::vector<int32_t>& tets,
                              std::vector<int32_t>& after, int32_t* survivor, tc_d3* place) {
  if (a > b) std::swap(a, b);
  const bool remove_b = (dir & TCC_DIR_REMOVE_V1) != 0;
  const int32_t x = remove_b ? b : a, y = remove_b ? a : b;
  *survivor = y;
  *place = placement(a, b, dir);
  tets.clear();
  after.clear();
  each_edge_star_tet(x, y, [&](int32_t t, const int32_t* q, bool removed) {
    tets.push_back(t);
    for (int k = 0; k < 4; ++k) after.push_back(removed ? -1 : q[k] == x ? y : q[k]);
  });
}

namespace {

// How far below 0 a barycentric coordinate may be for a point still to count as inside: the
// rounding of a point on a face.
constexpr double kInside = 1e-10;

const Field& bounded(const Mesh& mesh, const std::string& name, size_t* index) {
  for (size_t i = 0; i < mesh.vertex_fields.size(); ++i)
    if (name.empty() || mesh.vertex_fields[i].name == name) {
      *index = i;
      return mesh.vertex_fields[i];
    }
  throw std::invalid_argument(name.empty() ? std::string("max_field_error needs a vertex field")
                                           : "max_field_error: no vertex field '" + name + "'");
}

Mesh input_copy(const Mesh& mesh) {
  Mesh m;
  m.points = mesh.points;
  m.tets = mesh.tets;
  m.vertex_fields = mesh.vertex_fields;
  return m;
}

}  // namespace

FieldBound::FieldBound(const Mesh& mesh, const CollapseOptions& o, const SeqMesh& sm)
    : input_(input_copy(mesh)), locator_(input_), share_(o.max_field_error) {
  if (!(share_ > 0) || !std::isfinite(share_)) throw std::invalid_argument("max_field_error must be finite and > 0");
  const Field& f = bounded(input_, o.bounded_field, &in_field_);
  bounded(mesh, o.bounded_field, &mesh_field_);
  nc_ = f.components;
  const size_t nc = size_t(nc_);
  const bool given = !o.field_points.empty() || !o.field_point_tets.empty() || !o.field_point_values.empty();
  size_t np = size_t(input_.num_vertices());
  if (given) {
    np = o.field_point_tets.size();
    if (o.field_points.size() != 3 * np || o.field_point_values.size() != nc * np)
      throw std::invalid_argument("field_points: 3 coordinates, field_point_values: " + std::to_string(nc) +
                                  " values and field_point_tets: a tet per point (" + std::to_string(np) + " tets)");
    for (int32_t t : o.field_point_tets)
      if (t < 0 || t >= sm.num_tets()) throw std::invalid_argument("field_point_tets: a tet the mesh does not have");
    for (double x : o.field_points)
      if (!std::isfinite(x)) throw std::invalid_argument("field_points: a coordinate that is not finite");
    owned_points_ = o.field_points;
    owned_values_ = o.field_point_values;
    points_at_ = owned_points_.data();
    values_at_ = owned_values_.data();
  } else {
    points_at_ = input_.points.data();
    values_at_ = f.values.data();
  }
  if (!o.field_range.empty() && o.field_range.size() != nc)
    throw std::invalid_argument("field_range: one range per component of the bounded field");
  range_.assign(nc, 0.0);
  tol_.assign(nc, 0.0);
  for (size_t c = 0; c < nc; ++c) {
    double lo = INFINITY, hi = -INFINITY, big = 0;
    for (size_t v = 0; v < np; ++v) {
      const double x = values_at_[v * nc + c];
      lo = std::min(lo, x);
      hi = std::max(hi, x);
      big = std::max(big, std::abs(x));
    }
    const double range = o.field_range.empty() ? hi - lo : o.field_range[c];
    if ((np == 0 && o.field_range.empty()) || !std::isfinite(range) || !(range >= 0) || !std::isfinite(big))
      throw std::invalid_argument("max_field_error: field '" + f.name + "' has no finite range");
    range_[c] = range;
    // the bound, and room for the rounding of an interpolation that should be exact
    tol_[c] = share_ * range + 64 * std::numeric_limits<double>::epsilon() * big;
  }
  head_.assign(size_t(sm.num_tets()), -1);
  next_.assign(np, -1);
  for (int32_t v = 0; v < int32_t(np); ++v) {  // a vertex is in each tet of its ring: the first
    const int32_t t = given ? o.field_point_tets[size_t(v)] : sm.some_tet(v);
    if (t < 0) continue;  // an unused vertex: not part of the field
    next_[size_t(v)] = head_[size_t(t)];
    head_[size_t(t)] = v;
  }
}

double FieldBound::at_survivor(const Field& f, size_t c) const {
  const size_t nc = size_t(f.components);
  double x = 0;
  for (int k = 0; k < 4; ++k)
    x += survivor_bary_[k] * f.values[size_t(input_.tets[4 * size_t(survivor_tet_) + size_t(k)]) * nc + c];
  return x;
}

double FieldBound::value_error(double value, int32_t v, int c) const {
  return std::abs(value - values_at_[size_t(v) * size_t(nc_) + size_t(c)]);
}

bool FieldBound::admits(SeqMesh& sm, const Mesh& mesh, int32_t a, int32_t b, uint8_t dir) {
  tc_d3 p;
  sm.collapse_region(a, b, dir, region_, after_, &survivor_, &p);
  const double pp[3] = {p.x, p.y, p.z};
  survivor_tet_ = locator_.locate(pp, survivor_bary_);
  const Field& in = input_.vertex_fields[in_field_];
  survivor_values_.resize(size_t(nc_));
  for (int c = 0; c < nc_; ++c) survivor_values_[size_t(c)] = at_survivor(in, size_t(c));
  points_.clear();
  for (int32_t t : region_)
    for (int32_t v = head_[size_t(t)]; v >= 0; v = next_[size_t(v)]) points_.push_back(v);
  assign_.resize(points_.size());
  const std::vector<double>& cur = mesh.vertex_fields[mesh_field_].values;
  auto value = [&](int32_t u, int c) {
    return u == survivor_ ? survivor_values_[size_t(c)] : cur[size_t(u) * size_t(nc_) + size_t(c)];
  };
  auto corners = [&](size_t i, tc_d3 c[4]) {
    for (int k = 0; k < 4; ++k) {
      const int32_t u = after_[4 * i + size_t(k)];
      c[k] = u == survivor_ ? p : geo::tc_point(mesh.points.data(), u);
    }
  };
  for (size_t j = 0; j < points_.size(); ++j) {
    const tc_d3 q = geo::tc_point(points_at_, points_[j]);
    // the tet that holds q best (largest smallest coordinate); outside all of them, the nearest
    size_t best = SIZE_MAX;
    double best_min = -INFINITY, bary[4], b[4];
    tc_d3 c[4];
    for (size_t i = 0; i < region_.size(); ++i) {
      if (after_[4 * i] < 0) continue;
      corners(i, c);
      fields_detail::barycentric(c, q, b);
      const double m = std::min({b[0], b[1], b[2], b[3]});
      if (m > best_min) {
        best_min = m;
        best = i;
        std::copy(b, b + 4, bary);
        if (m >= 0) break;  // inside: no other tet holds it better (one on a shared face agrees)
      }
    }
    // Every input vertex stays inside the result, so that its value there is the one of the tet
    // that holds it, whatever happens elsewhere (the value at the nearest point of the nearest tet
    // would depend on which tet is nearest, which later collapses elsewhere may change).
    if (best == SIZE_MAX || !(best_min >= -kInside)) return false;
    for (int comp = 0; comp < nc_; ++comp) {
      double x = 0;
      for (int k = 0; k < 4; ++k) x += bary[k] * value(after_[4 * best + size_t(k)], comp);
      if (!(value_error(x, points_[j], comp) <= tol_[size_t(comp)])) return false;
    }
    assign_[j] = region_[best];
  }
  return true;
}

void FieldBound::apply(Mesh& mesh, int32_t survivor) {
  if (survivor != survivor_) throw std::logic_error("FieldBound::apply: not the collapse admits() checked");
  for (Field& f : mesh.vertex_fields) {
    const Field* g = input_.find_vertex_field(f.name);
    if (!g || g->components != f.components) continue;
    const size_t nc = size_t(f.components);
    for (size_t c = 0; c < nc; ++c) f.values[size_t(survivor) * nc + c] = at_survivor(*g, c);
  }
  for (int32_t t : region_) head_[size_t(t)] = -1;
  for (size_t j = 0; j < points_.size(); ++j) {
    const int32_t t = assign_[j];
    next_[size_t(points_[j])] = head_[size_t(t)];
    head_[size_t(t)] = points_[j];
  }
}

void FieldBound::compact(const std::vector<int32_t>& tmap) {
  for (size_t t = 0; t < tmap.size(); ++t)
    if (tmap[t] >= 0) head_[size_t(tmap[t])] = head_[t];  // tmap[t] <= t: in place
  int32_t m = 0;
  for (int32_t x : tmap) m = std::max(m, x + 1);
  head_.resize(size_t(m));
}

double FieldBound::max_error(const SeqMesh& sm, const Mesh& mesh) const {
  const std::vector<double>& cur = mesh.vertex_fields[mesh_field_].values;
  double worst = 0;
  for (int32_t t = 0; t < sm.num_tets(); ++t) {
    if (!sm.tet_alive(t) || head_[size_t(t)] < 0) continue;
    const int32_t* q = sm.tet_vertices(t);
    tc_d3 c[4];
    for (int k = 0; k < 4; ++k) c[k] = geo::tc_point(mesh.points.data(), q[k]);
    for (int32_t v = head_[size_t(t)]; v >= 0; v = next_[size_t(v)]) {
      double b[4];
      fields_detail::distance_to_tet(c, geo::tc_point(points_at_, v), b);
      for (int comp = 0; comp < nc_; ++comp) {
        if (!(range_[size_t(comp)] > 0)) continue;
        double x = 0;
        for (int k = 0; k < 4; ++k) x += b[k] * cur[size_t(q[k]) * size_t(nc_) + size_t(comp)];
        worst = std::max(worst, value_error(x, v, comp) / range_[size_t(comp)]);
      }
    }
  }
  return worst;
}

}  // namespace tc::sequential_detail
