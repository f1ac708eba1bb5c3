// The boundary error bound of the sequential method's dynamic mesh (SeqMesh::surface_change):
// the S faces a collapse replaces and those it makes, as the surface guard finds them, one
// side of each interface (its owner's, so that a sheet is oriented one way), and the bound of
// cl/collapse_surface_error.h between the two.
#include <algorithm>
#include <cmath>

#include "collapse/sequential_mesh.hpp"
#include "collapse_predicate.h"
#include "collapse_surface_error.h"

namespace tc::sequential_detail {

using geo::tc_d3;

SeqMesh::CollapseEnds SeqMesh::collapse_ends(int32_t a, int32_t b, uint8_t dir) const {
  if (a > b) std::swap(a, b);
  const bool remove_b = (dir & TCC_DIR_REMOVE_V1) != 0;
  const int32_t x = remove_b ? b : a, y = remove_b ? a : b;
  const tc_d3 p = placement(a, b, dir), py = point(y);
  return {x, y, p, !(py.x == p.x && py.y == p.y && py.z == p.z)};
}

double SeqMesh::surface_change(int32_t a, int32_t b, uint8_t dir, const std::vector<double>& eps, double* base,
                               double limit) {
  *base = 0;
  const auto [x, y, p, moves_y] = collapse_ends(a, b, dir);
  if (!vflags_[x] && !(moves_y && vflags_[y])) return 0;  // S is not touched
  tc_d3 olds[3 * TCC_MAX_FAN], news[3 * TCC_MAX_FAN];
  int oid[3 * TCC_MAX_FAN], nid[3 * TCC_MAX_FAN];
  int no = 0, nn = 0;
  const int32_t pid = moves_y ? -1 : y;  // the survivor's name in the new fan
  bool fits = true;
  each_old_sface(x, y, moves_y, [&](int32_t, const int32_t* q, int f) {
    if (no == TCC_MAX_FAN) {
      fits = false;
      return;
    }
    for (int k = 0; k < 3; ++k) {
      const int32_t v = q[geo::TC_TET_FACES[f][k]];
      olds[3 * no + k] = point(v);
      oid[3 * no + k] = v;
      *base = std::max(*base, eps[size_t(v)]);
    }
    ++no;
  });
  if (!fits) return INFINITY;
  // the new S faces (as guard_ok finds them), on the owner's side
  each_new_sface(x, y, moves_y, [&](int32_t t, const int32_t* q, int f, int32_t other) {
    if (!(other < 0 || (labels_ && label(t) < label(other)))) return;
    if (nn == TCC_MAX_FAN) {
      fits = false;
      return;
    }
    for (int k = 0; k < 3; ++k) {
      const int32_t v = q[geo::TC_TET_FACES[f][k]];
      news[3 * nn + k] = v == x || v == y ? p : point(v);
      nid[3 * nn + k] = v == x || v == y ? pid : v;
    }
    ++nn;
  });
  if (!fits) return INFINITY;
  return geo::tcc_fan_distance_within(olds, oid, no, news, nid, nn, geo::tcc_fan_budget(limit, *base));
}

// On a curved face the midpoint lies on the chord and an end point on the surface: keeping the
// one that changes S least lets the bound last for more collapses. As the device's selection
// (tcc_lazy_decide, collapse_select.h).
uint8_t SeqMesh::closest_placement(int32_t a, int32_t b, uint8_t dir, const std::vector<double>& eps, double* base,
                                   double* change) {
  *change = surface_change(a, b, dir, eps, base);
  // (S unchanged, or NaN: refused by the caller)
  if (!(dir & TCC_DIR_MIDPOINT) || (dir & TCC_DIR_USER) || !(*change > 0)) return dir;
  for (const uint8_t d : {uint8_t(TCC_DIR_REMOVE_V1), uint8_t(0)}) {
    if (!keeps_shape(a, b, d, TCC_END_POINT_MIN_QUALITY)) continue;
    double b2 = 0;
    const double c = surface_change(a, b, d, eps, &b2, *base + *change);  // (measured only while it may win)
    if (b2 + c < *base + *change) {
      *base = b2;
      *change = c;
      dir = d;
    }
  }
  return dir;
}

}  // namespace tc::sequential_detail
