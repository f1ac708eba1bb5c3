/* Conflict detection of Gautron and Kenzel 2023 ([GK23]; paper Sec. 4, "Gautron et al.'s
 * method"), the baseline replacing both passes of collapse_conflict.cl
 * (CollapseOptions::AtomicMin, host/collapse/conflict_atomic.cpp).
 *
 *   atomic_min_reset      desc[t] = ULONG_MAX for every tet
 *   atomic_min_propagate  every admissible edge e = (a, b): atom_min(desc[t], D(e)) for every
 *                         tet t of ring(a) and ring(b)
 *   atomic_min_select     e collapses when desc[t] == D(e) for every t of ring(a) and ring(b);
 *                         writes edges_are_final, edges_pass1, verts2collapse and counters[2],
 *                         counters[3] as conflict_pass1_finish + conflict_finalize do
 *
 * Descriptor D(e) (64 bits): the low k bits hold the edge index, k = the fewest bits holding
 * every index (ne - 1 < 2^k, k >= 1); the high 64 - k bits are the high bits of an
 * order-preserving 64-bit key of the double cost (sign bit flipped for non-negative costs, all
 * bits flipped for negative ones; -0.0 is read as +0.0, so equal costs get equal keys). The key
 * is truncated toward zero, which keeps the order monotone. Hence D orders edges by (cost,
 * index), exactly as the two-pass detection's tcc_before does, except for two costs that differ
 * only in the dropped low k bits of their keys (relative difference below about 2^(k - 52)):
 * those compare by index. D is unique per edge (its index), so every tet's minimum is
 * held by exactly one edge.
 *
 * Why the selection is conflict-free in the sense of conflict_pass2 (which collapse_compact.cl
 * relies on): if a tet contains an end point of selected edges e and f, it is in a ring of
 * both, so it received D(e) and D(f) and holds only one of them: one of e, f was not selected.
 * So no tet holds end points of two selected edges, and (every vertex lies in a tet) no vertex
 * belongs to two selected edges: verts2collapse is written once per vertex. An edge is selected
 * exactly when its descriptor is smaller than that of every other admissible edge with an end point
 * in a tet of ring(a) or ring(b) - the local minima of the conflict graph of pass 2, i.e. the
 * first round of conflict_pass2's greedy fixpoint; with the same order the result is therefore
 * a subset of what the two passes select. The result depends on nothing but the descriptors
 * (min is commutative): deterministic for any work-group size or schedule.
 *
 * Needs cl_khr_int64_extended_atomics (atom_min on ulong); the host refuses devices without it. */
#pragma OPENCL EXTENSION cl_khr_int64_base_atomics : enable
#pragma OPENCL EXTENSION cl_khr_int64_extended_atomics : enable
#include "collapse_common.h"

/* Order-preserving key of a double: x < y (as doubles, no NaN) <=> key(x) < key(y). */
inline ulong tcc_cost_key(double c) {
  if (c == 0.0) c = 0.0; /* -0.0 == +0.0 as doubles: one key for both */
  ulong bits = as_ulong(c);
  return (bits >> 63) ? ~bits : (bits | 0x8000000000000000UL);
}

inline ulong tcc_descriptor(double c, uint e, uint idx_bits) {
  ulong low = (1UL << idx_bits) - 1UL;
  return (tcc_cost_key(c) & ~low) | (ulong)e;
}

__kernel void atomic_min_reset(uint nt, __global ulong* desc) {
  uint t = get_global_id(0);
  if (t >= nt) return;
  desc[t] = ULONG_MAX;
}

__kernel void atomic_min_propagate(uint ne, __global const int* edges, __global const uint* edges_are_admissible,
                                   __global const double* edges2cost, __global const uint* vt_off,
                                   __global const int* vt, uint idx_bits, __global ulong* desc) {
  uint e = get_global_id(0);
  if (e >= ne || !edges_are_admissible[e]) return;
  ulong d = tcc_descriptor(edges2cost[e], e, idx_bits);
  for (int s = 0; s < 2; ++s) {
    int x = edges[2 * e + s];
    for (uint j = vt_off[x]; j < vt_off[x + 1]; ++j) atom_min(&desc[vt[j]], d);
  }
}

__kernel void atomic_min_select(uint ne, __global const int* edges, __global const uint* edges_are_admissible,
                                __global const double* edges2cost, __global const uint* vt_off, __global const int* vt,
                                uint idx_bits, __global const ulong* desc, __global uint* edges_are_final,
                                __global uint* edges_pass1, __global int* verts2collapse, __global uint* counters) {
  uint e = get_global_id(0);
  if (e >= ne) return;
  uint f = 0u;
  if (edges_are_admissible[e]) {
    ulong d = tcc_descriptor(edges2cost[e], e, idx_bits);
    f = 1u;
    for (int s = 0; s < 2 && f; ++s) {
      int x = edges[2 * e + s];
      for (uint j = vt_off[x]; j < vt_off[x + 1]; ++j)
        if (desc[vt[j]] != d) {
          f = 0u;
          break;
        }
    }
  }
  edges_are_final[e] = f;
  edges_pass1[e] = f;
  if (f) {
    verts2collapse[edges[2 * e]] = (int)e;
    verts2collapse[edges[2 * e + 1]] = (int)e;
    atomic_inc(&counters[2]);
    atomic_inc(&counters[3]);
  }
}
