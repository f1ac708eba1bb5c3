/* Stage 2 of a collapse iteration: cost per edge and marking.
 *
 * The default cost is the edge length. A user cost (tc::CollapseOptions::cost_cl_source) is
 * compiled in with -DTCC_USER_COST and must define
 *     double tc_user_cost(double3 p0, double3 p1, double f0, double f1);
 * p0, p1: the edge's end points; f0, f1: the first component of the first vertex field at
 * them (0 when the mesh has no vertex field). An edge is marked when its cost is below the
 * target and the vertex mask allows it (both end points, or either with mask_either). */
#include "collapse_common.h"

__kernel void cost_and_mark(uint ne, __global const int* edges, __global const double* pts,
                            __global const double* vfield, uint vfield_stride, int has_vfield,
                            __global const uchar* vmask, int mask_mode, double target, __global double* edges2cost,
                            __global uint* edges_are_marked, __global uint* counters) {
  __local uint group_marked;
  uint e = get_global_id(0);
  uint m = 0u;
  if (e < ne) {
    int a = edges[2 * e], b = edges[2 * e + 1];
    double3 pa = tc_point(pts, a), pb = tc_point(pts, b);
#ifdef TCC_USER_COST
    double fa = has_vfield ? vfield[(size_t)a * vfield_stride] : 0.0;
    double fb = has_vfield ? vfield[(size_t)b * vfield_stride] : 0.0;
    double c = tc_user_cost(pa, pb, fa, fb);
#else
    double3 d = pb - pa;
    double c = sqrt(tcc_dot(d, d));
#endif
    edges2cost[e] = c;
    /* mask_mode 0: no mask; 1: both end points in the mask; 2: either */
    int allowed = mask_mode == 0 ? 1 : mask_mode == 1 ? (vmask[a] && vmask[b]) : (vmask[a] || vmask[b]);
    m = (allowed && c < target) ? 1u : 0u;
    edges_are_marked[e] = m;
  }
  tcc_group_count(m, &group_marked, &counters[0]);
}
