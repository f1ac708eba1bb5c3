/* The boundary error bound on the device (CollapseOptions::max_boundary_error), after the
 * selection. The selection's test (tcc_lazy_decide, compiled with -DTCC_BOUND, collapse_select.h)
 * refuses a collapse that changes S past the bound (the bound of cl/collapse_surface_error.h
 * between the S faces it replaces and those it makes: the sequential method's
 * SeqMesh::surface_change, host/collapse/sequential_error.cpp, on the device's arrays) and keeps
 * the survivor's new bound of each it takes in edges2eps; bound_apply writes them once the
 * selection is final.
 *
 * The bound per vertex is the last component of the vertex fields (eps_col), which the
 * compaction carries: bound_apply writes the new bound on both end points, so that a midpoint's
 * average and a survivor's own value are that bound. */
#include "collapse_common.h"

/* The final collapses' survivors take their new bound (edges2eps; -1: S unchanged). */
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
