/* A linear bounding volume hierarchy over the tets of a mesh, built on the device, and point
 * location in it (the paper's Section 4.5: a vertex of the coarse mesh takes the value of the
 * original field at its place, found through a BVH of the original tets).
 *
 * Construction after Karras 2012 ("Maximizing parallelism in the construction of BVHs, octrees,
 * and k-d trees"): each tet's key is the Morton code of its box centre (10 bits per axis) above
 * its index, so keys are unique; the host sorts them (the project's radix sort); then every
 * internal node finds its range of leaves and its split independently (bvh_nodes), and the boxes
 * are merged from the leaves up, the second child to arrive at a node merging (bvh_boxes).
 * Nodes: internal 0 .. n-2 (0 is the root), leaf j (the j-th key) is node n-1+j.
 *
 * Location (bvh_locate): the lowest-numbered tet whose barycentric coordinates at p are all at
 * least -1e-12, the rule of the host's TetLocator, so both give the same tet; -1 when there is
 * none (the host then finds the nearest tet). */
#pragma OPENCL FP_CONTRACT OFF
#include "geometry.h"

#define TCB_STACK 96 /* > the deepest node: every level splits at a different bit of 62 */

inline ulong tcb_spread(ulong x) { /* the 10 low bits of x, two zero bits after each */
  x &= 0x3ffu;
  x = (x | (x << 16)) & 0x30000ffu;
  x = (x | (x << 8)) & 0x300f00fu;
  x = (x | (x << 4)) & 0x30c30c3u;
  x = (x | (x << 2)) & 0x9249249u;
  return x;
}

inline ulong tcb_cell(double x, double lo, double scale) {
  double c = (x - lo) * scale;
  return (ulong)(c < 0.0 ? 0.0 : c > 1023.0 ? 1023.0 : c);
}

__kernel void bvh_keys(uint nt, __global const int* tets, __global const double* pts, double lox, double loy,
                       double loz, double scale, __global ulong* keys) {
  uint t = get_global_id(0);
  if (t >= nt) return;
  double3 lo = tc_point(pts, tets[4 * (ulong)t]), hi = lo;
  for (int k = 1; k < 4; ++k) {
    double3 p = tc_point(pts, tets[4 * (ulong)t + k]);
    lo = fmin(lo, p);
    hi = fmax(hi, p);
  }
  double3 c = 0.5 * (lo + hi);
  ulong code = (tcb_spread(tcb_cell(c.x, lox, scale)) << 2) | (tcb_spread(tcb_cell(c.y, loy, scale)) << 1) |
               tcb_spread(tcb_cell(c.z, loz, scale));
  keys[t] = (code << 32) | (ulong)t;
}

/* The length of the common prefix of keys i and j; -1 outside the leaves. */
inline int tcb_delta(__global const ulong* keys, int n, int i, int j) {
  if (j < 0 || j >= n) return -1;
  return (int)clz(keys[i] ^ keys[j]);
}

/* Internal node i: its two children (child[2i], child[2i+1]) and their parent entries. */
__kernel void bvh_nodes(uint n_leaves, __global const ulong* keys, __global int* child, __global int* parent) {
  int i = (int)get_global_id(0), n = (int)n_leaves;
  if (i >= n - 1) return;
  int d = tcb_delta(keys, n, i, i + 1) > tcb_delta(keys, n, i, i - 1) ? 1 : -1;
  int dmin = tcb_delta(keys, n, i, i - d);
  int lmax = 2;
  while (tcb_delta(keys, n, i, i + lmax * d) > dmin) lmax *= 2;
  int l = 0;
  for (int t = lmax / 2; t >= 1; t /= 2)
    if (tcb_delta(keys, n, i, i + (l + t) * d) > dmin) l += t;
  int j = i + l * d;
  int dnode = tcb_delta(keys, n, i, j);
  int s = 0, div = 2, t;
  do {
    t = (l + div - 1) / div;
    if (tcb_delta(keys, n, i, i + (s + t) * d) > dnode) s += t;
    div *= 2;
  } while (t > 1);
  int gamma = i + s * d + min(d, 0);
  int left = min(i, j) == gamma ? n - 1 + gamma : gamma;
  int right = max(i, j) == gamma + 1 ? n - 1 + gamma + 1 : gamma + 1;
  child[2 * i] = left;
  child[2 * i + 1] = right;
  parent[left] = i;
  parent[right] = i;
}

/* Leaf j's box (its tet's, widened by `margin` so that a point the barycentric test accepts is
 * never outside it), then up: the second child to reach a node writes the node's box. arrived[]
 * is 0 on entry. The boxes are floats rounded outwards (a box only has to hold its tets): at 12
 * doubles per tet (2 nodes of 6) they were the run's largest buffer, above a quarter of what the
 * collapse needs in all, and so past CL_DEVICE_MAX_MEM_ALLOC_SIZE first (Context::
 * largest_allocation). */
__kernel void bvh_boxes(uint n_leaves, __global const ulong* keys, __global const int* tets,
                        __global const double* pts, double margin, __global const int* child,
                        __global const int* parent, volatile __global float* boxes,
                        volatile __global uint* arrived) {
  int j = (int)get_global_id(0), n = (int)n_leaves;
  if (j >= n) return;
  int t = (int)(keys[j] & 0xffffffffu);
  double3 lo = tc_point(pts, tets[4 * (ulong)t]), hi = lo;
  for (int k = 1; k < 4; ++k) {
    double3 p = tc_point(pts, tets[4 * (ulong)t + k]);
    lo = fmin(lo, p);
    hi = fmax(hi, p);
  }
  int node = n - 1 + j;
  lo -= margin;
  hi += margin;
  boxes[6 * (ulong)node] = convert_float_rtn(lo.x), boxes[6 * (ulong)node + 1] = convert_float_rtn(lo.y);
  boxes[6 * (ulong)node + 2] = convert_float_rtn(lo.z);
  boxes[6 * (ulong)node + 3] = convert_float_rtp(hi.x), boxes[6 * (ulong)node + 4] = convert_float_rtp(hi.y);
  boxes[6 * (ulong)node + 5] = convert_float_rtp(hi.z);
  node = parent[node];
  while (node >= 0) {
    mem_fence(CLK_GLOBAL_MEM_FENCE);
    if (atomic_inc(&arrived[node]) == 0) return; /* the other child is not done: it comes up */
    mem_fence(CLK_GLOBAL_MEM_FENCE);             /* its box before ours is read */
    int a = child[2 * node], b = child[2 * node + 1];
    for (int c = 0; c < 3; ++c) {
      boxes[6 * (ulong)node + c] = fmin(boxes[6 * (ulong)a + c], boxes[6 * (ulong)b + c]);
      boxes[6 * (ulong)node + 3 + c] = fmax(boxes[6 * (ulong)a + 3 + c], boxes[6 * (ulong)b + 3 + c]);
    }
    node = parent[node];
  }
}

inline int tcb_in_box(__global const float* b, double3 p) {
  return p.x >= (double)b[0] && p.y >= (double)b[1] && p.z >= (double)b[2] && p.x <= (double)b[3] &&
         p.y <= (double)b[4] && p.z <= (double)b[5];
}

/* Query q: out_tet[q] and out_bary[4q..4q+3] (see the file's comment); n_leaves >= 1. */
__kernel void bvh_locate(uint nq, __global const double* queries, uint n_leaves, __global const ulong* keys,
                         __global const int* child, __global const float* boxes, __global const int* tets,
                         __global const double* pts, __global int* out_tet, __global double* out_bary) {
  uint q = get_global_id(0);
  if (q >= nq) return;
  const int n = (int)n_leaves;
  const double3 p = tc_point(queries, (int)q);
  int stack[TCB_STACK];
  int sp = 0, best = -1;
  double bb[4] = {0.0, 0.0, 0.0, 0.0};
  stack[sp++] = 0;
  while (sp > 0) {
    int node = stack[--sp];
    if (!tcb_in_box(boxes + 6 * (ulong)node, p)) continue;
    if (node >= n - 1) {
      int t = (int)(keys[node - (n - 1)] & 0xffffffffu);
      if (best >= 0 && t >= best) continue;
      double3 c0 = tc_point(pts, tets[4 * (ulong)t]), c1 = tc_point(pts, tets[4 * (ulong)t + 1]), c2 = tc_point(pts, tets[4 * (ulong)t + 2]),
              c3 = tc_point(pts, tets[4 * (ulong)t + 3]);
      double b[4];
      tc_barycentric(c0, c1, c2, c3, p, b);
      if (b[0] >= -1e-12 && b[1] >= -1e-12 && b[2] >= -1e-12 && b[3] >= -1e-12) { /* NaN: no */
        best = t;
        for (int k = 0; k < 4; ++k) bb[k] = b[k];
      }
    } else if (sp + 2 <= TCB_STACK) {
      stack[sp++] = child[2 * node + 1];
      stack[sp++] = child[2 * node];
    }
  }
  out_tet[q] = best;
  for (int k = 0; k < 4; ++k) out_bary[4 * (ulong)q + k] = bb[k];
}

/* out[q * nc + c] = the field (nc components per vertex) at query q in its tet; queries in no
 * tet (-1) are left to the host. */
__kernel void bvh_interpolate(uint nq, __global const int* qtet, __global const double* qbary,
                              __global const int* tets, __global const double* values, uint nc,
                              __global double* out) {
  uint q = get_global_id(0);
  if (q >= nq || qtet[q] < 0) return;
  int t = qtet[q];
  for (uint c = 0; c < nc; ++c) {
    double x = 0.0;
    for (int k = 0; k < 4; ++k) x += qbary[4 * (ulong)q + k] * values[(ulong)tets[4 * (ulong)t + k] * nc + c];
    out[(ulong)q * nc + c] = x;
  }
}
