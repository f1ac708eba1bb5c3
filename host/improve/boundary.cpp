// Removal of a thin tet on the boundary: a sliver with two faces on the outer boundary (after a
// coarsening, typically four surface vertices nearly in a plane). No flip or move of interior
// vertices removes it, and its vertices may not move; taking it away exposes its two other
// faces, so the boundary quad (a, x2, b, x1) changes its diagonal from (a, b) to (x1, x2). The
// boundary moves by the tet's thickness, which must stay within max_boundary_move (under a
// boundary error bound: the bound of the quad's corners plus that move).
#include <cmath>

#include "collapse_surface_error.h"
#include "improve/improve_mesh.hpp"

namespace tc::improve_detail {

namespace {

double distance_to_plane(tc_d3 p, tc_d3 a, tc_d3 b, tc_d3 c) {
  const double n = geo::length(geo::cross(b - a, c - a));
  return n > 0 ? std::fabs(geo::tc_orient3d(a, b, c, p)) / n : INFINITY;
}

}  // namespace

// The height of a quad, relative to its diagonal, below which it counts as flat.
constexpr double kFlat = 1e-12;

// How far the boundary moves when the quad (a, x1, b, x2) changes its diagonal from (a, b) to
// (x1, x2): the larger distance of a and b from the other diagonal's triangles' planes.
double boundary_quad_height(const ImpMesh& m, int32_t a, int32_t b, int32_t x1, int32_t x2) {
  const tc_d3 pa = m.point(a), pb = m.point(b), p1 = m.point(x1), p2 = m.point(x2);
  return std::max(distance_to_plane(pa, pb, p1, p2), distance_to_plane(pb, pa, p1, p2));
}

bool flat_quad(const ImpMesh& m, int32_t a, int32_t b, int32_t x1, int32_t x2) {
  return boundary_quad_height(m, a, b, x1, x2) <= kFlat * geo::length(m.point(b) - m.point(a));
}

// Under a boundary error bound: a bound on the two-sided distance between the tet's boundary
// faces (those opposite x1 and x2) and the faces its removal exposes (opposite a and b), which
// span the same quad (cl/collapse_surface_error.h); INFINITY when it cannot be bounded.
double sliver_surface_change(const ImpMesh& m, int32_t t, int32_t x1, int32_t x2) {
  const Tet& q = m.tet(t);
  tc_d3 olds[6], news[6];
  int oid[6], nid[6];
  int no = 0, nn = 0;
  for (int f = 0; f < 4; ++f) {
    const auto& F = geo::TC_TET_FACES[f];  // oriented away from q[f]: out of t
    const bool gone = q[size_t(f)] == x1 || q[size_t(f)] == x2;
    for (int k = 0; k < 3; ++k) {
      // the exposed faces reversed: out of the mesh that is left, the side the gone ones face
      const int32_t v = q[size_t(F[gone ? k : 2 - k])];
      (gone ? olds[3 * no + k] : news[3 * nn + k]) = m.point(v);
      (gone ? oid[3 * no + k] : nid[3 * nn + k]) = v;
    }
    ++(gone ? no : nn);
  }
  return geo::tcc_fan_distance(olds, oid, no, news, nid, nn);
}

bool try_remove_boundary_sliver(ImpMesh& m, int32_t t) {
  if (!m.may_change_boundary()) return false;
  const Tet q = m.tet(t);
  int boundary[4], nb = 0;
  for (int f = 0; f < 4; ++f) {
    const auto& F = geo::TC_TET_FACES[f];
    if (m.across(t, q[F[0]], q[F[1]], q[F[2]]) < 0) boundary[nb++] = f;
  }
  if (nb != 2) return false;
  // x1, x2: opposite the boundary faces; (a, b): the edge the two boundary faces share.
  const int32_t x1 = q[boundary[0]], x2 = q[boundary[1]];
  int32_t ab[2], n = 0;
  for (int k = 0; k < 4; ++k)
    if (k != boundary[0] && k != boundary[1]) ab[n++] = q[k];
  const int32_t a = ab[0], b = ab[1];
  for (int32_t v : q)
    if (!m.selected(v) || m.tets_of(v).size() < 2) return false;  // a vertex would be left alone
  if (m.tagged_edge(a, b)) return false;  // an edge of a feature line the input names
  // The edge (a, b) must go with t (no other tet has it), and (x1, x2) must not be on the
  // boundary already: otherwise the surface would stop being a manifold there.
  for (int32_t s : m.tets_of(a))
    if (s != t && contains(m.tet(s), b)) return false;
  for (int32_t s : m.tets_of(x1)) {
    const Tet& r = m.tet(s);
    if (s == t || !contains(r, x2)) continue;
    for (int32_t y : r)
      if (y != x1 && y != x2 && m.across(s, x1, x2, y) < 0) return false;
  }
  const bool flat = flat_quad(m, a, b, x1, x2);
  double change = 0;
  if (m.bounded()) {  // (replace_on_boundary adds it to the quad's bounds)
    change = flat ? 0 : sliver_surface_change(m, t, x1, x2);
    if (!(change <= m.max_boundary_move())) return false;
  } else if (boundary_quad_height(m, a, b, x1, x2) > m.max_boundary_move()) {
    return false;
  }
  return m.replace_on_boundary({t}, {}, {{{a, b, x2}, {a, b, x1}}}, {{{b, x1, x2}, {a, x1, x2}}}, flat, change);
}

}  // namespace tc::improve_detail
