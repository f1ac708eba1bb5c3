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

double SeqMesh::harmonic_sum(int32_t a, int32_t b, const tc_d3* place, double* worst_sine) {
  double sum = 0;
  if (worst_sine) *worst_sine = INFINITY;
  for (int side = 0; side < 2; ++side) {
    const int32_t z = side == 0 ? a : b, w = side == 0 ? b : a;
    const int32_t* rz = ring(z);
    for (uint32_t i = 0; i < rlen_[z]; ++i) {
      const int32_t* q = tet(rz[i]);
      const bool both = has(q, w);
      if (both && (side == 1 || place)) continue;  // seen from ring(a), or removed
      tc_d3 c[4];
      for (int k = 0; k < 4; ++k) c[k] = place && (q[k] == a || q[k] == b) ? *place : point(q[k]);
      sum += harmonic_index(c);
      if (worst_sine) *worst_sine = std::min(*worst_sine, geo::tc_tet_min_sine(c[0], c[1], c[2], c[3]));
    }
  }
  return sum;
}

void SeqMesh::harmonic_terms(int32_t a, int32_t b, std::vector<HarmonicTerm>& terms) {
  terms.clear();
  const tc_d3 p0 = point(a), d = point(b) - p0;
  for (int side = 0; side < 2; ++side) {
    const int32_t z = side == 0 ? a : b, w = side == 0 ? b : a;
    const int32_t* rz = ring(z);
    for (uint32_t i = 0; i < rlen_[z]; ++i) {
      const int32_t* q = tet(rz[i]);
      if (has(q, w)) continue;  // removed
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
    }
  }
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
