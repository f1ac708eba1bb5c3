// The harmonic index of the paper's collapse for mesh improvement (Section 4.6, after Alexa 2019,
// "Harmonic triangulations"): eta(t) = (sum of the squared face areas of t) / volume(t), which a
// regular tet minimises for its size; CollapseOptions::harmonic_cost.
#include <algorithm>
#include <cmath>

#include "collapse/sequential_mesh.hpp"

namespace tc::sequential_detail {

using geo::tc_d3;

namespace {

double harmonic_index(const tc_d3 (&c)[4]) {
  const double v = geo::tc_orient3d(c[0], c[1], c[2], c[3]) / 6;
  if (!(v > 0)) return INFINITY;
  double areas = 0;
  for (const auto& F : geo::TC_TET_FACES) {
    const tc_d3 n = geo::cross(c[F[1]] - c[F[0]], c[F[2]] - c[F[0]]);
    areas += 0.25 * geo::dot(n, n);
  }
  return areas / v;
}

}  // namespace

double SeqMesh::harmonic_sum(int32_t a, int32_t b, const tc_d3* place) {
  double sum = 0;
  each_edge_star_shape(a, b, place, [&](const tc_d3(&c)[4]) { sum += harmonic_index(c); });
  return sum;
}

double SeqMesh::worst_sine(int32_t a, int32_t b, const tc_d3* place) {
  double worst = INFINITY;
  each_edge_star_shape(a, b, place,
                       [&](const tc_d3(&c)[4]) { worst = std::min(worst, geo::tc_tet_min_sine(c[0], c[1], c[2], c[3])); });
  return worst;
}

void SeqMesh::harmonic_terms(int32_t a, int32_t b, std::vector<HarmonicTerm>& terms) {
  terms.clear();
  const tc_d3 p0 = point(a), d = point(b) - p0;
  each_edge_star_tet(a, b, [&](int32_t, const int32_t* q, bool removed) {
    if (removed) return;
    const int32_t z = has(q, a) ? a : b;
    const int m = local(q, z);
    tc_d3 c0[4], c1[4];
    for (int k = 0; k < 4; ++k) c0[k] = c1[k] = point(q[k]);
    c0[m] = p0;
    c1[m] = p0 + d;
    HarmonicTerm h{0, 0, 0, 0, 0};
    // the volume is linear in the moving corner: its values at t = 0 and t = 1
    h.v0 = geo::tc_orient3d(c0[0], c0[1], c0[2], c0[3]) / 6;
    h.v1 = geo::tc_orient3d(c1[0], c1[1], c1[2], c1[3]) / 6 - h.v0;
    for (const auto& F : geo::TC_TET_FACES) {
      int at = -1;
      for (int k = 0; k < 3; ++k)
        if (F[k] == m) at = k;
      if (at < 0) {  // the face opposite the moving corner: fixed
        const tc_d3 n = geo::cross(c0[F[1]] - c0[F[0]], c0[F[2]] - c0[F[0]]);
        h.q0 += 0.25 * geo::dot(n, n);
        continue;
      }
      // the face (p, u, w) in its order: cross(u - p, w - p) = A + t B with p = p0 + t d
      const tc_d3 u = c0[F[(at + 1) % 3]] - p0, v = c0[F[(at + 2) % 3]] - p0;
      const tc_d3 A = geo::cross(u, v), B = geo::cross(v - u, d);
      h.q0 += 0.25 * geo::dot(A, A);
      h.q1 += 0.5 * geo::dot(A, B);
      h.q2 += 0.25 * geo::dot(B, B);
    }
    terms.push_back(h);
  });
}

double SeqMesh::harmonic_at(const std::vector<HarmonicTerm>& terms, double t) {
  double sum = 0;
  for (const HarmonicTerm& h : terms) {
    const double v = h.v0 + h.v1 * t;
    if (!(v > 0)) return INFINITY;
    sum += (h.q0 + t * (h.q1 + t * h.q2)) / v;
  }
  return sum;
}

}  // namespace tc::sequential_detail
