/* Triangle-triangle test of the surface guard (cl/collapse_guard.cl), written once and compiled
 * as OpenCL C and as C++ (namespace tc::geo, as geometry.h), so that the host (the sequential
 * method, the tests) can run the very test the device runs.
 *
 * Floating point with a tolerance: every side / inside decision is made on a distance compared
 * with 1e-9 times the triangles' size, and a contact within it counts, so rounding never hides
 * a pair that intersects exactly (and flat faces of CAD models, whose points are coplanar and
 * collinear only up to rounding, get consistent answers); the price is that triangles closer
 * than that are reported too. Pairs sharing an edge are not tested (they can only overlap when
 * coplanar, which the tets between them exclude in a valid mesh).
 */
#ifndef TETCOLLAPSE_COLLAPSE_GUARD_GEOMETRY_H
#define TETCOLLAPSE_COLLAPSE_GUARD_GEOMETRY_H

#include "geometry.h"

#ifndef __OPENCL_C_VERSION__
namespace tc::geo {
#endif

/* A point of a coordinate plane. */
typedef struct {
  double x, y;
} tc_sg_d2;

/* p in the plane of the two axes kept when axis `drop` is dropped. */
TC_FN tc_sg_d2 tc_sg_proj(tc_d3 p, int drop) {
  tc_sg_d2 r;
  r.x = drop == 0 ? p.y : drop == 1 ? p.z : p.x;
  r.y = drop == 0 ? p.z : drop == 1 ? p.x : p.y;
  return r;
}

/* Side of 2D point c of the line through a and b: 0 within distance tol, else -1 / 1. */
TC_FN int tc_sg_side2(tc_sg_d2 a, tc_sg_d2 b, tc_sg_d2 c, double tol) {
  double ex = b.x - a.x, ey = b.y - a.y, len = sqrt(ex * ex + ey * ey);
  double det = ex * (c.y - a.y) - ey * (c.x - a.x); /* len x signed distance */
  return det > tol * len ? 1 : det < -tol * len ? -1 : 0;
}

/* Do the 2D segments (p, q) and (u, w) come within tol of crossing or overlapping? (Signs from
 * distances, not from exact orientations: the points of a straight CAD edge, rounded, are
 * collinear only up to rounding, and exact signs then disagree with each other.) */
TC_FN int tc_sg_seg_seg2(tc_sg_d2 p, tc_sg_d2 q, tc_sg_d2 u, tc_sg_d2 w, double tol) {
  int s1 = tc_sg_side2(p, q, u, tol), s2 = tc_sg_side2(p, q, w, tol);
  int s3 = tc_sg_side2(u, w, p, tol), s4 = tc_sg_side2(u, w, q, tol);
  if (s1 * s2 > 0 || s3 * s4 > 0) return 0;
  if ((s1 == 0 && s2 == 0) || (s3 == 0 && s4 == 0)) { /* collinear: do the intervals overlap? */
    double dx = q.x - p.x, dy = q.y - p.y, len = sqrt(dx * dx + dy * dy);
    if (!(len > 0.0)) return 1;
    double tu = (dx * (u.x - p.x) + dy * (u.y - p.y)) / len, tw = (dx * (w.x - p.x) + dy * (w.y - p.y)) / len;
    double lo = tu < tw ? tu : tw, hi = tu < tw ? tw : tu;
    return lo <= len + tol && hi >= -tol;
  }
  return 1;
}

/* Is 2D point p in triangle (a, b, c) grown by tol? */
TC_FN int tc_sg_in_tri2(tc_sg_d2 p, tc_sg_d2 a, tc_sg_d2 b, tc_sg_d2 c, double tol) {
  double area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
  double sgn = area >= 0.0 ? 1.0 : -1.0;
  for (int k = 0; k < 3; ++k) {
    tc_sg_d2 u = k == 0 ? a : k == 1 ? b : c, w = k == 0 ? b : k == 1 ? c : a;
    double ex = w.x - u.x, ey = w.y - u.y, len = sqrt(ex * ex + ey * ey);
    if (sgn * (ex * (p.y - u.y) - ey * (p.x - u.x)) < -tol * len) return 0;
  }
  return 1;
}

/* What tc_sg_one_side and tc_sg_seg_tri need of a triangle p: its normal cross(p1 - p0,
 * p2 - p0), the normal's length and the longest squared edge. Computed once per triangle by
 * the kernels that test one triangle against many (the same arithmetic as computing it per
 * pair: the same decisions). */
typedef struct {
  tc_d3 n;
  double ln, e2;
} tc_sg_plane;

TC_FN tc_sg_plane tc_sg_plane_of(const tc_d3* p) {
  tc_sg_plane r;
  r.n = cross(p[1] - p[0], p[2] - p[0]);
  r.ln = sqrt(dot(r.n, r.n));
  r.e2 = 0.0;
  for (int k = 0; k < 3; ++k) {
    tc_d3 e = p[(k + 1) % 3] - p[k];
    double l = dot(e, e);
    r.e2 = r.e2 > l ? r.e2 : l;
  }
  return r;
}

/* Does the closed segment (p, q) meet the closed triangle (a, b, c), up to 1e-9 times their
 * size? A segment within that distance of the triangle's plane is tested in the plane (in 2D,
 * the dominant axis of the normal dropped); otherwise the point where it crosses the plane.
 * pl is the triangle's plane (tc_sg_plane_of). */
TC_FN int tc_sg_seg_tri(tc_d3 p, tc_d3 q, tc_d3 a, tc_d3 b, tc_d3 c, tc_sg_plane pl) {
  tc_d3 pq = q - p, n = pl.n;
  if (!(pl.ln > 0.0)) return 1; /* a degenerate triangle: cannot tell */
  double s2 = dot(pq, pq);
  s2 = pl.e2 > s2 ? pl.e2 : s2;
  double tol = 1e-9 * sqrt(s2);
  double dp = dot(n, p - a) / pl.ln, dq = dot(n, q - a) / pl.ln; /* signed distances to the plane */
  if ((dp > tol && dq > tol) || (dp < -tol && dq < -tol)) return 0;
  double nx = fabs(n.x), ny = fabs(n.y), nz = fabs(n.z);
  int drop = nx >= ny && nx >= nz ? 0 : ny >= nz ? 1 : 2;
  tc_sg_d2 a2 = tc_sg_proj(a, drop), b2 = tc_sg_proj(b, drop), c2 = tc_sg_proj(c, drop);
  if (fabs(dp) <= tol && fabs(dq) <= tol) { /* in the plane */
    tc_sg_d2 p2 = tc_sg_proj(p, drop), q2 = tc_sg_proj(q, drop);
    return tc_sg_in_tri2(p2, a2, b2, c2, tol) || tc_sg_in_tri2(q2, a2, b2, c2, tol) ||
           tc_sg_seg_seg2(p2, q2, a2, b2, tol) || tc_sg_seg_seg2(p2, q2, b2, c2, tol) ||
           tc_sg_seg_seg2(p2, q2, c2, a2, tol);
  }
  double t = dp / (dp - dq); /* dp != dq: they are not both within tol, nor on one side */
  t = t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t;
  return tc_sg_in_tri2(tc_sg_proj(p + pq * t, drop), a2, b2, c2, tol);
}

/* Are the vertices of B not shared with A all farther than 1e-9 times the two triangles' size
 * from A's plane, on one side? (Then B meets A at most in what they share; the tolerance is at
 * least that of tc_sg_seg_tri, so this never drops a pair that test would report.) */
TC_FN int tc_sg_one_side(const int* ia, const tc_d3* pa, tc_sg_plane qa, const int* ib, const tc_d3* pb,
                         tc_sg_plane qb) {
  if (!(qa.ln > 0.0)) return 0;
  double tol = 1e-9 * sqrt(qa.e2 > qb.e2 ? qa.e2 : qb.e2);
  int above = 0, below = 0, free = 0;
  for (int k = 0; k < 3; ++k) {
    if (ib[k] == ia[0] || ib[k] == ia[1] || ib[k] == ia[2]) continue;
    double d = dot(qa.n, pb[k] - pa[0]) / qa.ln;
    ++free;
    above += d > tol;
    below += d < -tol;
  }
  return free > 0 && (above == free || below == free);
}

/* Do triangles A and B (vertex ids ia, ib; positions pa, pb; planes qa, qb of tc_sg_plane_of)
 * intersect other than in what they share? Sharing an edge (or all three vertices): not
 * tested. Sharing one vertex s: they meet elsewhere iff the edge opposite s of one meets the
 * other. Sharing none: iff an edge of one meets the other. */
TC_FN int tc_sg_tri_tri_planes(const int* ia, const tc_d3* pa, tc_sg_plane qa, const int* ib, const tc_d3* pb,
                               tc_sg_plane qb) {
  int sa = -1, sb = -1, shared = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (ia[i] == ib[j]) {
        ++shared;
        sa = i;
        sb = j;
      }
  if (shared >= 2) return 0;
  /* cheap and most frequent: one triangle on one side of the other's plane */
  if (tc_sg_one_side(ia, pa, qa, ib, pb, qb) || tc_sg_one_side(ib, pb, qb, ia, pa, qa)) return 0;
  if (shared == 1)
    return tc_sg_seg_tri(pa[(sa + 1) % 3], pa[(sa + 2) % 3], pb[0], pb[1], pb[2], qb) ||
           tc_sg_seg_tri(pb[(sb + 1) % 3], pb[(sb + 2) % 3], pa[0], pa[1], pa[2], qa);
  for (int i = 0; i < 3; ++i) {
    if (tc_sg_seg_tri(pa[i], pa[(i + 1) % 3], pb[0], pb[1], pb[2], qb)) return 1;
    if (tc_sg_seg_tri(pb[i], pb[(i + 1) % 3], pa[0], pa[1], pa[2], qa)) return 1;
  }
  return 0;
}

/* The same, computing the planes. */
TC_FN int tc_sg_tri_tri(const int* ia, const tc_d3* pa, const int* ib, const tc_d3* pb) {
  return tc_sg_tri_tri_planes(ia, pa, tc_sg_plane_of(pa), ib, pb, tc_sg_plane_of(pb));
}

#ifndef __OPENCL_C_VERSION__
}  // namespace tc::geo
#endif

#endif
