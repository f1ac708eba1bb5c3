/* The boundary error bound on the device (CollapseOptions::max_boundary_error), after the
 * selection: each chosen collapse that changes S gets the bound of cl/collapse_surface_error.h
 * between the S faces it replaces and those it makes (the sequential method's
 * SeqMesh::surface_change, host/collapse/sequential_error.cpp, on the device's arrays). One over
 * the bound is dropped as the surface guard drops its refusals (unmarked, its verdict kept, the
 * selection runs again); the others' survivors take their new bound (bound_apply).
 *
 * The selection's test (tcc_lazy_decide, compiled with -DTCC_BOUND) refuses what exceeds the
 * bound as it tests an edge; bound_test then only finds each chosen collapse's new bound (and
 * refuses, as a safeguard, what the selection let through).
 *
 * The bound per vertex is the last component of the vertex fields (eps_col), which the
 * compaction carries: bound_apply writes the new bound on both end points, so that a midpoint's
 * average and a survivor's own value are that bound. */
#include "collapse_bound.h"
#include "collapse_guard.h"

/* Per chosen collapse that changes S: refused (unmarked, verdict TCC_REFUSED_SURFACE, counted)
 * past the bound, else edges2eps[e] = the survivor's new bound (-1: S unchanged). */
__kernel void bound_test(uint ne, __global const int* edges, __global const uint* edges_are_final,
                         __global const uchar* edges2dir, __global const double* pts, __global const double* vfield,
                         uint vfield_stride, uint eps_col, __global const int* tets, __global const uint* vt_off,
                         __global const int* vt, __global const int* tet_nbr, __global const int* labels,
                         int use_labels, __global const uchar* vflags, double bound, __global uint* edges_are_marked,
                         int has_verdict, __global uchar* edges2verdict, __global double* edges2eps,
                         __global uint* count) {
  uint e = get_global_id(0);
  if (e >= ne || !edges_are_final[e]) return;
  edges2eps[e] = -1.0;
  int x, y;
  double3 p;
  int moves_y = tcc_sg_collapse((int)e, edges, edges2dir, pts, vfield, vfield_stride, &x, &y, &p);
  if (!vflags[x] && !(moves_y && vflags[y])) return; /* S is not touched */
  double base;
  double change = tcc_bound_change(x, y, moves_y, p, tets, vt_off, vt, tet_nbr, labels, use_labels, pts, vfield,
                                   vfield_stride, eps_col, &base);
  if (base + change <= bound) {
    if (change > 0.0) edges2eps[e] = base + change;
    return;
  }
  edges_are_marked[e] = 0u;
  if (has_verdict) edges2verdict[e] = TCC_REFUSED_SURFACE;
  atomic_inc(count);
}

/* The final collapses' survivors take their new bound (on both end points: see the top). */
__kernel void bound_apply(uint ne, __global const int* edges, __global const uint* edges_are_final,
                          __global const uchar* edges2dir, __global const double* edges2eps, __global double* vfield,
                          uint vfield_stride, uint eps_col) {
  uint e = get_global_id(0);
  if (e >= ne || !edges_are_final[e] || !(edges2eps[e] > 0.0)) return;
  int v0 = edges[2 * e], v1 = edges[2 * e + 1];
  int y = (edges2dir[e] & TCC_DIR_REMOVE_V1) ? v0 : v1, x = y == v0 ? v1 : v0;
  double b = fmax(vfield[(size_t)y * vfield_stride + eps_col], edges2eps[e]);
  vfield[(size_t)x * vfield_stride + eps_col] = b;
  vfield[(size_t)y * vfield_stride + eps_col] = b;
}
