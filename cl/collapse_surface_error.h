/* The boundary error bound's geometry (tc::CollapseOptions::max_boundary_error), written once
 * for the host (host/collapse/sequential_error.cpp) and the kernels, compiled as OpenCL C and
 * as C++ (names in namespace tc::geo there).
 *
 * A collapse that changes S replaces a patch of S, the old fan (the S faces through the
 * removed vertex, and through the survivor when it moves), by the new fan over the same
 * boundary loop. tcc_fan_distance bounds the two-sided Hausdorff distance between the two: both
 * are projected onto the old fan's mean plane; when each covers its projection once (every
 * triangle positively oriented, the two covering the same area), every point of one lies
 * straight above or below a point of the other, and the gap between the two piecewise linear
 * height functions is largest at a vertex of their overlay: a vertex of either fan or a
 * crossing of their edges. So the bound is the largest gap there (plus rounding). A fan that
 * does not project once (folded, or two sheets meeting at a ridge) gets no bound (infinity):
 * the collapse is refused. */
#ifndef TETCOLLAPSE_COLLAPSE_SURFACE_ERROR_H
#define TETCOLLAPSE_COLLAPSE_SURFACE_ERROR_H

#include "geometry.h"

#ifndef __OPENCL_C_VERSION__
namespace tc::geo {
#endif

/* the most triangles a fan may have for the bound (a larger one gets none) */
#define TCC_MAX_FAN 48

/* The height at (u, v) of the fan whose projected corners are pu, pv and heights ph (3 per
 * triangle), n triangles: from the triangle holding the point (barycentric coordinates all >=
 * -tol), else the nearest by its smallest coordinate. */
TC_FN double tcc_fan_height(const double* pu, const double* pv, const double* ph, int n, double u, double v,
                            double tol) {
  double best_min = -INFINITY, best_h = 0;
  for (int i = 0; i < n; ++i) {
    double ax = pu[3 * i], ay = pv[3 * i], bx = pu[3 * i + 1], by = pv[3 * i + 1], cx = pu[3 * i + 2],
           cy = pv[3 * i + 2];
    double det = (bx - ax) * (cy - ay) - (cx - ax) * (by - ay);
    double l1 = ((u - ax) * (cy - ay) - (cx - ax) * (v - ay)) / det;
    double l2 = ((bx - ax) * (v - ay) - (u - ax) * (by - ay)) / det;
    double l0 = 1.0 - l1 - l2;
    double m = l0 < l1 ? l0 : l1;
    m = l2 < m ? l2 : m;
    if (m > best_min) {
      best_min = m;
      best_h = l0 * ph[3 * i] + l1 * ph[3 * i + 1] + l2 * ph[3 * i + 2];
    }
    if (m >= -tol) return best_h;
  }
  return best_h;
}

/* A bound on the two-sided Hausdorff distance between the old fan (no triangles, 3 corners
 * each in order, consistently oriented) and the new fan (nn) over the same boundary loop, or
 * INFINITY when it cannot be bounded this way (see the top). oid and nid name each corner: one
 * name, one point (the mesh's vertex ids, and for a point that moved a name no corner of the
 * other fan has, e.g. -1). INFINITY too as soon as a gap above `budget` is found: a caller that
 * only asks whether the bound is at most that need not measure the rest. */
TC_FN double tcc_fan_distance_within(const tc_d3* olds, const int* oid, int no, const tc_d3* news, const int* nid,
                                     int nn, double budget) {
  if (no < 1 || nn < 1 || no > TCC_MAX_FAN || nn > TCC_MAX_FAN) return INFINITY;
  /* the mean plane: the sum of the old triangles' area vectors */
  tc_d3 nsum = TC_D3(0, 0, 0), o = olds[0];
  double scale = 0;
  for (int i = 0; i < no; ++i) {
    nsum = nsum + cross(olds[3 * i + 1] - olds[3 * i], olds[3 * i + 2] - olds[3 * i]);
    for (int k = 0; k < 3; ++k) {
      tc_d3 d = olds[3 * i + k] - o;
      double l = sqrt(dot(d, d));
      scale = l > scale ? l : scale;
    }
  }
  double nl = sqrt(dot(nsum, nsum));
  if (!(nl > 0) || !(scale > 0)) return INFINITY;
  tc_d3 nz = nsum / nl;
  /* a frame (e1, e2, nz) */
  tc_d3 t = fabs(nz.x) < 0.6 ? TC_D3(1, 0, 0) : TC_D3(0, 1, 0);
  tc_d3 e1 = cross(nz, t);
  e1 = e1 / sqrt(dot(e1, e1));
  tc_d3 e2 = cross(nz, e1);
  double ou[3 * TCC_MAX_FAN], ov[3 * TCC_MAX_FAN], oh[3 * TCC_MAX_FAN];
  double nu[3 * TCC_MAX_FAN], nv[3 * TCC_MAX_FAN], nh[3 * TCC_MAX_FAN];
  double area_old = 0, area_new = 0;
  for (int side = 0; side < 2; ++side) {
    const tc_d3* tri = side == 0 ? olds : news;
    int n = side == 0 ? no : nn;
    double* pu = side == 0 ? ou : nu;
    double* pv = side == 0 ? ov : nv;
    double* ph = side == 0 ? oh : nh;
    for (int i = 0; i < n; ++i) {
      for (int k = 0; k < 3; ++k) {
        tc_d3 d = tri[3 * i + k] - o;
        pu[3 * i + k] = dot(d, e1);
        pv[3 * i + k] = dot(d, e2);
        ph[3 * i + k] = dot(d, nz);
      }
      double a = (pu[3 * i + 1] - pu[3 * i]) * (pv[3 * i + 2] - pv[3 * i]) -
                 (pu[3 * i + 2] - pu[3 * i]) * (pv[3 * i + 1] - pv[3 * i]);
      /* every triangle positively oriented in the projection (a fold, or a sliver seen edge on,
       * gets no bound) */
      if (!(a > 1e-12 * scale * scale)) return INFINITY;
      if (side == 0) area_old += a;
      else area_new += a;
    }
  }
  /* the same boundary loop, each covered once: the same projected area */
  if (!(fabs(area_old - area_new) <= 1e-9 * (area_old + area_new))) return INFINITY;
  /* Both fans hold the boundary loop and whatever the change left: at a vertex they share the
   * gap is zero, and so it is at every point of an edge they share, crossings included. So the
   * gap is measured at the vertices one fan has alone and at the crossings of the edges neither
   * shares, each edge once (an inner edge borders two triangles of its fan). */
  unsigned char v_own[2][3 * TCC_MAX_FAN], e_own[2][3 * TCC_MAX_FAN];
  for (int side = 0; side < 2; ++side) {
    const int n = side == 0 ? no : nn, m = side == 0 ? nn : no;
    const int* pid = side == 0 ? oid : nid;
    const int* qid = side == 0 ? nid : oid;
    for (int j = 0; j < 3 * n; ++j) {
      const int j2 = j % 3 == 2 ? j - 2 : j + 1, a = pid[j], b = pid[j2];
      int own_v = 1, own_e = 1;
      /* by triangles (two distinct corners of one are an edge of it, one way or the other) */
      for (int t = 0; t < m && (own_v || own_e); ++t) {
        const int c0 = qid[3 * t], c1 = qid[3 * t + 1], c2 = qid[3 * t + 2];
        const int has_a = c0 == a || c1 == a || c2 == a, has_b = c0 == b || c1 == b || c2 == b;
        own_v &= !has_a;
        if (a == b) /* (an edge of no length: the same one only) */
          own_e &= !((c0 == a && c1 == a) || (c1 == a && c2 == a) || (c2 == a && c0 == a));
        else
          own_e &= !(has_a && has_b);
      }
      /* the same edge, the other way, earlier in this fan */
      for (int t = 0; 3 * t < j && own_e; ++t) {
        const int p0 = pid[3 * t], p1 = pid[3 * t + 1], p2 = pid[3 * t + 2];
        own_e = !((p0 == b && p1 == a) || (p1 == b && p2 == a && 3 * t + 1 < j) ||
                  (p2 == b && p0 == a && 3 * t + 2 < j));
      }
      v_own[side][j] = (unsigned char)own_v;
      e_own[side][j] = (unsigned char)own_e;
    }
  }
  double tol = 1e-9, gap = 0;
  /* the vertices */
  for (int side = 0; side < 2; ++side) {
    int n = side == 0 ? no : nn;
    const double* pu = side == 0 ? ou : nu;
    const double* pv = side == 0 ? ov : nv;
    const double* ph = side == 0 ? oh : nh;
    for (int j = 0; j < 3 * n; ++j) {
      if (!v_own[side][j]) continue;
      double h = side == 0 ? tcc_fan_height(nu, nv, nh, nn, pu[j], pv[j], tol)
                           : tcc_fan_height(ou, ov, oh, no, pu[j], pv[j], tol);
      double g = fabs(h - ph[j]);
      gap = g > gap ? g : gap;
      if (gap + 1e-12 * scale > budget) return INFINITY;
    }
  }
  /* the crossings of the edges */
  for (int i = 0; i < 3 * no; ++i) {
    if (!e_own[0][i]) continue;
    int i2 = i % 3 == 2 ? i - 2 : i + 1;
    double ax = ou[i], ay = ov[i], bx = ou[i2], by = ov[i2];
    for (int j = 0; j < 3 * nn; ++j) {
      if (!e_own[1][j]) continue;
      int j2 = j % 3 == 2 ? j - 2 : j + 1;
      double cx = nu[j], cy = nv[j], dx = nu[j2], dy = nv[j2];
      double den = (bx - ax) * (dy - cy) - (by - ay) * (dx - cx);
      if (den == 0) continue; /* parallel: their overlay vertices are the end points */
      double s = ((cx - ax) * (dy - cy) - (cy - ay) * (dx - cx)) / den;
      double r = ((cx - ax) * (by - ay) - (cy - ay) * (bx - ax)) / den;
      if (s <= 0 || s >= 1 || r <= 0 || r >= 1) continue;
      double g = fabs((oh[i] + s * (oh[i2] - oh[i])) - (nh[j] + r * (nh[j2] - nh[j])));
      gap = g > gap ? g : gap;
    }
    if (gap + 1e-12 * scale > budget) return INFINITY;
  }
  /* rounding: the heights are differences of coordinates of size `scale` */
  return gap + 1e-12 * scale;
}

TC_FN double tcc_fan_distance(const tc_d3* olds, const int* oid, int no, const tc_d3* news, const int* nid, int nn) {
  return tcc_fan_distance_within(olds, oid, no, news, nid, nn, INFINITY);
}

/* The budget of tcc_fan_distance_within for a caller that keeps a change when base + the
 * distance is at most `limit`: a little above limit - base, so that a distance cut short is
 * beyond the limit after rounding as well (the cut then changes no verdict). */
TC_FN double tcc_fan_budget(double limit, double base) { return limit - base + 1e-9 * fabs(limit); }

#ifndef __OPENCL_C_VERSION__
}  // namespace tc::geo
#endif

#endif /* TETCOLLAPSE_COLLAPSE_SURFACE_ERROR_H */
