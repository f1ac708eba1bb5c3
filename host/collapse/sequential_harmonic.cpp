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

}  // namespace tc::sequential_detail
