/* The boundary error bound's test on the device (CollapseOptions::max_boundary_error; the
 * kernels of collapse_bound.cl and, compiled with -DTCC_BOUND, the selection's test in
 * collapse_select.h): the sequential method's SeqMesh::surface_change
 * (host/collapse/sequential_error.cpp) on the device's arrays. */
#ifndef TETCOLLAPSE_COLLAPSE_BOUND_H
#define TETCOLLAPSE_COLLAPSE_BOUND_H

#include "collapse_common.h"
#include "collapse_surface_error.h"

/* The bound the S triangles at the survivor get from the collapse of x onto y (y at p): the
 * largest bound of the old fan's vertices in *base, plus the returned fan distance (0 when S does
 * not change, INFINITY when it cannot be bounded, or when *base + it would pass `limit`). The old
 * fan: the owned S faces through x (and those of the tets the collapse removes), and through y
 * when it moves; the new one: the faces after the collapse, on the owner's side. */
inline double tcc_bound_change(int x, int y, int moves_y, double3 p, __global const int* tets,
                               __global const uint* vt_off, __global const int* vt, __global const int* tet_nbr,
                               __global const int* labels, int use_labels, __global const double* pts,
                               __global const double* vfield, uint vfield_stride, uint eps_col, double limit,
                               double* base) {
  tc_d3 olds[3 * TCC_MAX_FAN], news[3 * TCC_MAX_FAN];
  int oid[3 * TCC_MAX_FAN], nid[3 * TCC_MAX_FAN];
  int no = 0, nn = 0;
  const int pid = moves_y ? -1 : y; /* the survivor's name in the new fan */
  *base = 0.0;
  for (int side = 0; side < (moves_y ? 2 : 1); ++side) {
    int z = side == 0 ? x : y;
    for (uint i = vt_off[z]; i < vt_off[z + 1]; ++i) {
      int t = vt[i];
      __global const int* q = tets + 4 * t;
      if (side == 1 && tcc_has(tets, t, x)) continue;
      int removed = side == 0 && tcc_has(tets, t, y);
      for (int f = 0; f < 4; ++f) {
        uint on_s;
        if ((q[f] == z && !removed) || !tcc_owned_sface(tet_nbr, labels, use_labels, t, f, &on_s)) continue;
        if (no == TCC_MAX_FAN) return INFINITY;
        for (int k = 0; k < 3; ++k) {
          int v = q[TC_TET_FACES[f][k]];
          olds[3 * no + k] = tc_point(pts, v);
          oid[3 * no + k] = v;
          *base = fmax(*base, vfield[(size_t)v * vfield_stride + eps_col]);
        }
        ++no;
      }
    }
  }
  /* the new S faces (as tcc_sg_new_tri finds them), on the owner's side */
  for (int side = 0; side < 2; ++side) {
    int z = side == 0 ? x : y, w = side == 0 ? y : x;
    for (uint i = vt_off[z]; i < vt_off[z + 1]; ++i) {
      int t = vt[i];
      if (tcc_has(tets, t, w)) continue; /* removed, or seen from ring(x) */
      __global const int* q = tets + 4 * t;
      for (int f = 0; f < 4; ++f) {
        if (q[f] == z) continue; /* the face opposite z does not contain it */
        int o = tet_nbr[4 * t + f], other;
        if (o >= 0 && tcc_has(tets, o, x) && tcc_has(tets, o, y)) {
          other = tet_nbr[4 * o + tcc_local(tets, o, z)]; /* glued through the removed tet o */
        } else if (side == 0 || moves_y) {
          other = o;
        } else {
          continue; /* through y, which stays: unchanged */
        }
        if (!(other < 0 || (use_labels && labels[t] < labels[other]))) continue;
        if (nn == TCC_MAX_FAN) return INFINITY;
        for (int k = 0; k < 3; ++k) {
          int v = q[TC_TET_FACES[f][k]];
          news[3 * nn + k] = v == x || v == y ? p : tc_point(pts, v);
          nid[3 * nn + k] = v == x || v == y ? pid : v;
        }
        ++nn;
      }
    }
  }
  if (no == 0 && nn == 0) return 0.0;
  return tcc_fan_distance_within(olds, oid, no, news, nid, nn, tcc_fan_budget(limit, *base));
}

/* The bound the survivor of the collapse of e = (a, b) in direction dir would take (the bound
 * per vertex in component eps_col of the vertex fields): -1 when S is not touched, INFINITY when
 * the change cannot be bounded or the bound would pass `limit`; the collapse keeps the bound when
 * this is at most the bound. */
inline double tcc_bound_after(int a, int b, int dir, __global const int* tets, __global const uint* vt_off,
                              __global const int* vt, __global const int* tet_nbr, __global const int* labels,
                              int use_labels, __global const double* pts, __global const double* vfield,
                              uint vfield_stride, __global const uchar* vflags, uint eps_col, double limit) {
  int x = (dir & TCC_DIR_REMOVE_V1) ? b : a, y = x == a ? b : a;
  double3 p = tcc_placement(pts, vfield, vfield_stride, a, b, (uint)dir), py = tc_point(pts, y);
  int moves_y = !(py.x == p.x && py.y == p.y && py.z == p.z);
  if (!vflags[x] && !(moves_y && vflags[y])) return -1.0; /* S is not touched */
  double base;
  double change = tcc_bound_change(x, y, moves_y, p, tets, vt_off, vt, tet_nbr, labels, use_labels, pts, vfield,
                                   vfield_stride, eps_col, limit, &base);
  return change == 0.0 ? -1.0 : base + change; /* (NaN: refused by the caller's <=) */
}

#endif /* TETCOLLAPSE_COLLAPSE_BOUND_H */
