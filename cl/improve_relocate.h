/* Vertex relocation: a vertex moves to raise the worst quality of its star. Written once for
 * the device (cl/improve_relocate.cl, a conflict-free set of vertices at a time) and the host
 * (host/improve/smooth.cpp, one vertex at a time), compiled as OpenCL C and as C++ (names in
 * namespace tc::geo there, as cl/geometry.h).
 *
 * The objective, the smallest min-sine of the star (tc_tet_min_sine), is not smooth, so each
 * step follows the gradient of the worst tet, or the mean of the gradients of the nearly worst
 * ones, with a halving line search that accepts only a rise of the worst (after Freitag and
 * Ollivier-Gooch's non-smooth smoothing, in its simplest form). The gradients are taken
 * numerically: the measure is cheap and a star has a few dozen tets.
 *
 * A vertex moves freely (TCI_FREE), within a plane (TCI_IN_PLANE, `dir` its normal) or along a
 * line (TCI_ALONG_LINE, `dir` the line), and never further than max_offset from `start`. A
 * step is accepted only when the star's worst min-sine rises and its smallest dihedral angle
 * does not fall below min(its value before, the threshold); on the host a curved surface's
 * vertex must also keep the surface free of self-intersections (the `surface_clear` hook). */
#ifndef TETCOLLAPSE_IMPROVE_RELOCATE_H
#define TETCOLLAPSE_IMPROVE_RELOCATE_H

#include "geometry.h"

#ifdef __OPENCL_C_VERSION__
#define TCI_GLOBAL __global
#define TCI_HOOK_PARAM int no_hook
#define TCI_SURFACE_CLEAR(v, p) 1
#define TCI_INFINITY INFINITY
#else
#include <functional>
#include <limits>
namespace tc::geo {
#define TCI_GLOBAL
/* host only: whether moving v to p keeps the feature surface clear (empty: no check) */
#define TCI_HOOK_PARAM const std::function<bool(int, tc_d3)>& surface_clear
#define TCI_SURFACE_CLEAR(v, p) (!surface_clear || surface_clear((v), (p)))
#define TCI_INFINITY std::numeric_limits<double>::infinity()
#endif

#define TCI_FIXED 0
#define TCI_FREE 1
#define TCI_IN_PLANE 2
#define TCI_ALONG_LINE 3

#define TCI_STEPS 4           /* ascent steps per vertex and pass */
#define TCI_HALVINGS 8        /* line search */
#define TCI_NEARLY_WORST 1e-3
/* A relocation that raises the star's worst min-sine by less is not made: such gains do not
 * change what a user measures, and a vertex making them would be retried every pass. */
#define TCI_MIN_GAIN 1e-3

/* Written out rather than the OpenCL built-ins, so that both sides round alike. */
TC_FN double tci_length(tc_d3 a) { return sqrt(a.x * a.x + a.y * a.y + a.z * a.z); }
TC_FN tc_d3 tci_normalize(tc_d3 a) {
  double l = tci_length(a);
  return l > 0 ? a / l : a;
}

/* The corners of tet t (packed 4 ints per tet) with vertex v taken at p. */
TC_FN void tci_corners(TCI_GLOBAL const double* pts, TCI_GLOBAL const int* tets, int t, int v, tc_d3 p,
                       tc_d3* c) {
  for (int k = 0; k < 4; ++k) {
    int x = tets[4 * t + k];
    c[k] = x == v ? p : tc_point(pts, x);
  }
}

TC_FN double tci_quality_with(TCI_GLOBAL const double* pts, TCI_GLOBAL const int* tets, int t, int v, tc_d3 p) {
  tc_d3 c[4];
  tci_corners(pts, tets, t, v, p, c);
  return tc_tet_min_sine(c[0], c[1], c[2], c[3]);
}

TC_FN double tci_max_cos_with(TCI_GLOBAL const double* pts, TCI_GLOBAL const int* tets, int t, int v, tc_d3 p) {
  tc_d3 c[4];
  tci_corners(pts, tets, t, v, p, c);
  return tc_tet_max_dihedral_cos(c[0], c[1], c[2], c[3]);
}

/* The star's worst min-sine with v at p, or any value <= bound once one tet is that bad: most
 * trial positions fail, and `sorted` lists the star's tets worst first. */
TC_FN double tci_star_min(TCI_GLOBAL const double* pts, TCI_GLOBAL const int* tets, const int* sorted, int n, int v,
                          tc_d3 p, double bound) {
  double q = TCI_INFINITY;
  for (int i = 0; i < n; ++i) {
    double x = tci_quality_with(pts, tets, sorted[i], v, p);
    q = x < q ? x : q;
    if (q <= bound) break;
  }
  return q;
}

TC_FN double tci_star_max_cos(TCI_GLOBAL const double* pts, TCI_GLOBAL const int* tets, TCI_GLOBAL const int* star,
                              int n, int v, tc_d3 p) {
  double c = -1;
  for (int i = 0; i < n; ++i) {
    double x = tci_max_cos_with(pts, tets, star[i], v, p);
    c = x > c ? x : c;
  }
  return c;
}

TC_FN tc_d3 tci_gradient(TCI_GLOBAL const double* pts, TCI_GLOBAL const int* tets, int t, int v, tc_d3 p, double h) {
  tc_d3 ex = TC_D3(h, 0, 0), ey = TC_D3(0, h, 0), ez = TC_D3(0, 0, h);
  return TC_D3(tci_quality_with(pts, tets, t, v, p + ex) - tci_quality_with(pts, tets, t, v, p - ex),
               tci_quality_with(pts, tets, t, v, p + ey) - tci_quality_with(pts, tets, t, v, p - ey),
               tci_quality_with(pts, tets, t, v, p + ez) - tci_quality_with(pts, tets, t, v, p - ez)) /
         (2 * h);
}

/* d restricted to the motion allowed */
TC_FN tc_d3 tci_allowed(int motion, tc_d3 dir, tc_d3 d) {
  return motion == TCI_IN_PLANE ? d - dir * dot(d, dir) : motion == TCI_ALONG_LINE ? dir * dot(d, dir) : d;
}

/* Relocates v (star: its n tets; sorted: the same, worst first). Returns 1 and the new place in
 * *out when the star's worst min-sine rises by at least TCI_MIN_GAIN, else 0. */
TC_FN int tci_relocate(TCI_GLOBAL const double* pts, TCI_GLOBAL const int* tets, TCI_GLOBAL const int* star,
                       const int* sorted, int n, int v, int motion, tc_d3 dir, tc_d3 start, double max_offset,
                       double cos_threshold, TCI_HOOK_PARAM, tc_d3* out) {
  if (motion == TCI_FIXED || n == 0) return 0;
  tc_d3 p = tc_point(pts, v);
  /* the scale of the star: its mean edge length at v */
  double scale = 0;
  int count = 0;
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < 4; ++k) {
      int x = tets[4 * star[i] + k];
      if (x != v) {
        scale += tci_length(tc_point(pts, x) - p);
        ++count;
      }
    }
  scale /= count;
  double h = 1e-7 * scale;
  double current = tci_star_min(pts, tets, sorted, n, v, p, -TCI_INFINITY);
  double current_cos = tci_star_max_cos(pts, tets, star, n, v, p);
  double start_q = current;
  int moved = 0;
  for (int step = 0; step < TCI_STEPS; ++step) {
    double worst = TCI_INFINITY;
    int worst_tet = -1;
    for (int i = 0; i < n; ++i) {
      double q = tci_quality_with(pts, tets, star[i], v, p);
      if (q < worst) {
        worst = q;
        worst_tet = star[i];
      }
    }
    tc_d3 directions[2];
    directions[0] = tci_allowed(motion, dir, tci_gradient(pts, tets, worst_tet, v, p, h));
    directions[1] = TC_D3(0, 0, 0);
    for (int i = 0; i < n; ++i)
      if (tci_quality_with(pts, tets, star[i], v, p) <= worst + TCI_NEARLY_WORST)
        directions[1] = directions[1] + tci_normalize(tci_allowed(motion, dir, tci_gradient(pts, tets, star[i], v, p, h)));
    /* The mean of opposed unit gradients cancels to rounding noise, whose direction is
     * arbitrary (off the allowed plane or line): skip it. Every direction is projected again
     * after normalising, so rounding does not take a vertex off its plane or line. */
    if (tci_length(directions[1]) < 1e-6) directions[1] = TC_D3(0, 0, 0);
    int improved = 0;
    for (int j = 0; j < 2 && !improved; ++j) {
      tc_d3 d = tci_allowed(motion, dir, tci_normalize(directions[j]));
      double len = tci_length(d);
      if (!(len > 0.5)) continue;
      d = d / len;
      double s = 0.25 * scale;
      for (int k = 0; k < TCI_HALVINGS && !improved; ++k, s *= 0.5) {
        tc_d3 candidate = p + d * s;
        if (!(tci_length(candidate - start) <= max_offset)) continue;
        double q = tci_star_min(pts, tets, sorted, n, v, candidate, current);
        if (!(q > current)) continue;
        double c = tci_star_max_cos(pts, tets, star, n, v, candidate);
        /* the worst min-sine rises; the smallest angle stays above min(before, threshold) */
        if (c <= (current_cos > cos_threshold ? current_cos : cos_threshold) && TCI_SURFACE_CLEAR(v, candidate)) {
          p = candidate;
          current = q;
          current_cos = c;
          improved = 1;
        }
      }
    }
    if (!improved) break;
    moved = 1;
  }
  if (!moved || current < start_q + TCI_MIN_GAIN) return 0;
  *out = p;
  return 1;
}

#ifndef __OPENCL_C_VERSION__
}  // namespace tc::geo
#endif

#endif /* TETCOLLAPSE_IMPROVE_RELOCATE_H */
