// Point location and vertex fields from the original mesh (tetcollapse/fields.hpp).
#include "tetcollapse/fields.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>

#include "fields_detail.hpp"
#include "geometry.h"

namespace tc {

using geo::tc_d3;

namespace {

tc_d3 corner(const Mesh& m, int64_t t, int k) { return geo::tc_point(m.points.data(), m.tets[size_t(4 * t + k)]); }

void corners(const Mesh& m, int64_t t, tc_d3 c[4]) {
  for (int k = 0; k < 4; ++k) c[k] = corner(m, t, k);
}

// The distance from p to the bounding box of the corners: at most p's distance to the tet.
double box_distance(const tc_d3 c[4], tc_d3 p) {
  auto axis = [&](double x, double a, double b, double e, double f) {
    const double lo = std::min({a, b, e, f}), hi = std::max({a, b, e, f});
    return x < lo ? lo - x : x > hi ? x - hi : 0.0;
  };
  const double dx = axis(p.x, c[0].x, c[1].x, c[2].x, c[3].x), dy = axis(p.y, c[0].y, c[1].y, c[2].y, c[3].y),
               dz = axis(p.z, c[0].z, c[1].z, c[2].z, c[3].z);
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

}  // namespace

namespace fields_detail {

void barycentric(const tc_d3 c[4], tc_d3 p, double b[4]) { geo::tc_barycentric(c[0], c[1], c[2], c[3], p, b); }

namespace {

// The point of triangle (a, b, c) nearest to p, with its barycentric coordinates (Ericson,
// Real-Time Collision Detection, 5.1.5).
tc_d3 closest_on_triangle(tc_d3 p, tc_d3 a, tc_d3 b, tc_d3 c, double w[3]) {
  const tc_d3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = geo::dot(ab, ap), d2 = geo::dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return w[0] = 1, w[1] = w[2] = 0, a;
  const tc_d3 bp = p - b;
  const double d3 = geo::dot(ab, bp), d4 = geo::dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return w[1] = 1, w[0] = w[2] = 0, b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double s = d1 / (d1 - d3);
    return w[0] = 1 - s, w[1] = s, w[2] = 0, a + ab * s;
  }
  const tc_d3 cp = p - c;
  const double d5 = geo::dot(ab, cp), d6 = geo::dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return w[2] = 1, w[0] = w[1] = 0, c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double s = d2 / (d2 - d6);
    return w[0] = 1 - s, w[2] = s, w[1] = 0, a + ac * s;
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double s = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return w[1] = 1 - s, w[2] = s, w[0] = 0, b + (c - b) * s;
  }
  const double den = 1 / (va + vb + vc), v = vb * den, u = vc * den;
  return w[0] = 1 - v - u, w[1] = v, w[2] = u, a + ab * v + ac * u;
}

}  // namespace

double distance_to_tet(const tc_d3 c[4], tc_d3 p, double b[4]) {
  barycentric(c, p, b);
  if (b[0] >= 0 && b[1] >= 0 && b[2] >= 0 && b[3] >= 0) return 0;
  double best = std::numeric_limits<double>::infinity();
  for (const auto& F : geo::TC_TET_FACES) {
    double w[3];
    const tc_d3 q = closest_on_triangle(p, c[F[0]], c[F[1]], c[F[2]], w);
    const double d = geo::length(q - p);
    if (d < best) {
      best = d;
      b[0] = b[1] = b[2] = b[3] = 0;
      for (int k = 0; k < 3; ++k) b[F[k]] = w[k];
    }
  }
  return best;
}

}  // namespace fields_detail

using fields_detail::barycentric;
using fields_detail::distance_to_tet;

TetLocator::TetLocator(const Mesh& mesh) : mesh_(mesh) {
  const int64_t nt = mesh.num_tets();
  if (nt == 0) return;
  double hi[3];
  for (int c = 0; c < 3; ++c) lo_[c] = hi[c] = mesh.points[size_t(c)];
  for (size_t i = 0; i + 2 < mesh.points.size(); i += 3)
    for (int c = 0; c < 3; ++c) {
      lo_[c] = std::min(lo_[c], mesh.points[i + size_t(c)]);
      hi[c] = std::max(hi[c], mesh.points[i + size_t(c)]);
    }
  // cells of about the mean tet's extent, at most ~ 2 per tet
  double extent = 0;
  for (int c = 0; c < 3; ++c) extent = std::max(extent, hi[c] - lo_[c]);
  double volume = 1;
  for (int c = 0; c < 3; ++c) volume *= std::max(hi[c] - lo_[c], extent * 1e-6);
  cell_ = std::max(std::cbrt(volume / double(nt)) * 1.5, extent * 1e-6);
  if (!(cell_ > 0) || !std::isfinite(cell_)) cell_ = 1;
  for (int c = 0; c < 3; ++c) dim_[c] = std::max<int64_t>(1, int64_t((hi[c] - lo_[c]) / cell_) + 1);
  const double margin = 1e-9 * extent;
  std::vector<int64_t> counts(size_t(dim_[0] * dim_[1] * dim_[2]) + 1, 0);
  auto each_cell = [&](int64_t t, auto&& fn) {
    int64_t a[3], b[3];
    for (int c = 0; c < 3; ++c) {
      double l = mesh.points[3 * size_t(mesh.tets[size_t(4 * t)]) + size_t(c)], h = l;
      for (int k = 1; k < 4; ++k) {
        const double x = mesh.points[3 * size_t(mesh.tets[size_t(4 * t + k)]) + size_t(c)];
        l = std::min(l, x);
        h = std::max(h, x);
      }
      // the box a little wider, as the device's BVH has it (DeviceTetLocator): a point the
      // coordinates' tolerance accepts just outside the tet is then in one of its cells
      a[c] = std::clamp<int64_t>(int64_t((l - margin - lo_[c]) / cell_), 0, dim_[c] - 1);
      b[c] = std::clamp<int64_t>(int64_t((h + margin - lo_[c]) / cell_), 0, dim_[c] - 1);
    }
    for (int64_t k = a[2]; k <= b[2]; ++k)
      for (int64_t j = a[1]; j <= b[1]; ++j)
        for (int64_t i = a[0]; i <= b[0]; ++i) fn(cell_index(i, j, k));
  };
  for (int64_t t = 0; t < nt; ++t) each_cell(t, [&](int64_t c) { ++counts[size_t(c) + 1]; });
  for (size_t i = 1; i < counts.size(); ++i) counts[i] += counts[i - 1];
  offsets_ = counts;
  tets_.resize(size_t(counts.back()));
  for (int64_t t = 0; t < nt; ++t) each_cell(t, [&](int64_t c) { tets_[size_t(counts[size_t(c)]++)] = t; });
}

int64_t TetLocator::locate(const double p[3], double bary[4], bool* outside) const {
  if (outside) *outside = true;
  if (offsets_.empty()) return -1;
  const tc_d3 q{p[0], p[1], p[2]};
  int64_t at[3];
  for (int c = 0; c < 3; ++c) {
    const double x = std::floor((p[c] - lo_[c]) / cell_);
    at[c] = !(x > 0) ? 0 : x >= double(dim_[c]) ? dim_[c] - 1 : int64_t(x);
  }
  // A tet that holds p has p in its box, so it is listed in p's cell: look there first.
  double b[4];
  tc_d3 c[4];
  const int64_t home = cell_index(at[0], at[1], at[2]);
  for (int64_t e = offsets_[size_t(home)]; e < offsets_[size_t(home) + 1]; ++e) {
    const int64_t t = tets_[size_t(e)];
    corners(mesh_, t, c);
    barycentric(c, q, b);
    if (b[0] >= -1e-12 && b[1] >= -1e-12 && b[2] >= -1e-12 && b[3] >= -1e-12) {  // (a NaN fails)
      std::copy(b, b + 4, bary);
      if (outside) *outside = false;
      return t;
    }
  }
  // Outside every tet: shells of cells around p's, until no cell further out can hold a tet
  // nearer than the nearest found.
  int64_t best = -1;
  double best_d = std::numeric_limits<double>::infinity();
  const int64_t max_r = std::max({dim_[0], dim_[1], dim_[2]});
  for (int64_t r = 0; r <= max_r; ++r) {
    for (int64_t k = at[2] - r; k <= at[2] + r; ++k)
      for (int64_t j = at[1] - r; j <= at[1] + r; ++j)
        for (int64_t i = at[0] - r; i <= at[0] + r; ++i) {
          if (std::max({std::abs(i - at[0]), std::abs(j - at[1]), std::abs(k - at[2])}) != r) continue;
          if (i < 0 || j < 0 || k < 0 || i >= dim_[0] || j >= dim_[1] || k >= dim_[2]) continue;
          const int64_t cell = cell_index(i, j, k);
          for (int64_t e = offsets_[size_t(cell)]; e < offsets_[size_t(cell) + 1]; ++e) {
            const int64_t t = tets_[size_t(e)];
            corners(mesh_, t, c);
            if (box_distance(c, q) >= best_d) continue;  // cheaper than the distance, and a bound of it
            const double d = distance_to_tet(c, q, b);
            if (d < best_d) {
              best_d = d;
              best = t;
              std::copy(b, b + 4, bary);
            }
          }
        }
    // a tet in shell r + 1 or beyond is at least r cells away from p
    if (best >= 0 && double(r) * cell_ >= best_d) break;
  }
  return best;
}

namespace fields_detail {

std::vector<FieldPair> shared_fields(const Mesh& original, Mesh& mesh) {
  std::vector<FieldPair> pairs;
  for (Field& f : mesh.vertex_fields)
    if (const Field* g = original.find_vertex_field(f.name); g && g->components == f.components)
      pairs.push_back({g, &f});
  return pairs;
}

void interpolate_at(const Mesh& original, const FieldPair& p, int64_t t, const double b[4], int64_t v) {
  const size_t nc = size_t(p.to->components);
  for (size_t c = 0; c < nc; ++c) {
    double x = 0;
    for (int k = 0; k < 4; ++k) x += b[k] * p.from->values[size_t(original.tets[size_t(4 * t + k)]) * nc + c];
    p.to->values[size_t(v) * nc + c] = x;
  }
}

}  // namespace fields_detail

int64_t resample_vertex_fields(const Mesh& original, Mesh& mesh) {
  const std::vector<fields_detail::FieldPair> pairs = fields_detail::shared_fields(original, mesh);
  if (pairs.empty() || original.num_tets() == 0) return 0;
  const TetLocator locator(original);
  int64_t outside = 0;
  for (int64_t v = 0; v < mesh.num_vertices(); ++v) {
    double bary[4];
    bool out = false;
    const int64_t t = locator.locate(&mesh.points[3 * size_t(v)], bary, &out);
    outside += out;
    for (const auto& p : pairs) fields_detail::interpolate_at(original, p, t, bary, v);
  }
  return outside;
}

std::vector<FieldError> field_errors(const Mesh& reference, const Mesh& mesh, int64_t random_points) {
  std::vector<FieldError> out;
  std::vector<std::pair<const Field*, const Field*>> pairs;
  for (const Field& f : reference.vertex_fields)
    if (const Field* g = mesh.find_vertex_field(f.name); g && g->components == f.components && !f.values.empty())
      pairs.push_back({&f, g});
  if (pairs.empty() || reference.num_tets() == 0 || mesh.num_tets() == 0) return out;
  // the sample points, each with its reference tet and coordinates there
  struct Sample {
    tc_d3 p;
    int64_t tet;
    double bary[4];
  };
  std::vector<Sample> samples;
  std::vector<int64_t> vertex_tet(size_t(reference.num_vertices()), -1);
  std::vector<int> vertex_corner(size_t(reference.num_vertices()), 0);
  for (int64_t t = 0; t < reference.num_tets(); ++t)
    for (int k = 0; k < 4; ++k) {
      const size_t v = size_t(reference.tets[size_t(4 * t + k)]);
      if (vertex_tet[v] < 0) vertex_tet[v] = t, vertex_corner[v] = k;
    }
  for (int64_t v = 0; v < reference.num_vertices(); ++v) {
    if (vertex_tet[size_t(v)] < 0) continue;
    Sample s{geo::tc_point(reference.points.data(), int32_t(v)), vertex_tet[size_t(v)], {0, 0, 0, 0}};
    s.bary[vertex_corner[size_t(v)]] = 1;
    samples.push_back(s);
  }
  const size_t at_vertices = samples.size();  // the first samples: the reference's vertices
  std::vector<double> cumulative(size_t(reference.num_tets()));
  double total = 0;
  for (int64_t t = 0; t < reference.num_tets(); ++t)
    cumulative[size_t(t)] = total += std::fabs(geo::tc_tet_volume(corner(reference, t, 0), corner(reference, t, 1),
                                                                   corner(reference, t, 2), corner(reference, t, 3)));
  std::mt19937_64 rng(20261127);
  std::uniform_real_distribution<double> u(0, 1);
  for (int64_t i = 0; i < random_points && total > 0; ++i) {
    const int64_t t = std::min<int64_t>(
        reference.num_tets() - 1, std::lower_bound(cumulative.begin(), cumulative.end(), u(rng) * total) - cumulative.begin());
    double e[4] = {-std::log(1 - u(rng)), -std::log(1 - u(rng)), -std::log(1 - u(rng)), -std::log(1 - u(rng))};
    const double sum = e[0] + e[1] + e[2] + e[3];  // normalised exponentials: uniform in the tet
    Sample s{{0, 0, 0}, t, {e[0] / sum, e[1] / sum, e[2] / sum, e[3] / sum}};
    for (int k = 0; k < 4; ++k) s.p = s.p + corner(reference, t, k) * s.bary[k];
    samples.push_back(s);
  }
  const TetLocator locator(mesh);
  std::vector<std::pair<int64_t, std::array<double, 4>>> located(samples.size());
  for (size_t i = 0; i < samples.size(); ++i) {
    const double p[3] = {samples[i].p.x, samples[i].p.y, samples[i].p.z};
    located[i].first = locator.locate(p, located[i].second.data());
  }
  for (const auto& [ref, got] : pairs) {
    const size_t nc = size_t(ref->components);
    FieldError fe;
    fe.name = ref->name;
    double lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < ref->values.size(); i += nc) {
      lo = std::min(lo, ref->values[i]);
      hi = std::max(hi, ref->values[i]);
    }
    fe.range = hi - lo;
    double sq = 0;
    for (size_t i = 0; i < samples.size(); ++i) {
      double a = 0, b = 0;
      for (int k = 0; k < 4; ++k) {
        a += samples[i].bary[k] * ref->values[size_t(reference.tets[size_t(4 * samples[i].tet + k)]) * nc];
        b += located[i].second[size_t(k)] * got->values[size_t(mesh.tets[size_t(4 * located[i].first + k)]) * nc];
      }
      const double d = std::fabs(a - b);
      fe.max_abs = std::max(fe.max_abs, d);
      if (i < at_vertices) fe.max_vertex_abs = std::max(fe.max_vertex_abs, d);
      sq += d * d;
    }
    fe.samples = int64_t(samples.size());
    fe.rms_abs = std::sqrt(sq / double(samples.size()));
    fe.max_rel = fe.range > 0 ? fe.max_abs / fe.range : 0;
    fe.rms_rel = fe.range > 0 ? fe.rms_abs / fe.range : 0;
    fe.max_vertex_rel = fe.range > 0 ? fe.max_vertex_abs / fe.range : 0;
    out.push_back(fe);
  }
  return out;
}

}  // namespace tc
