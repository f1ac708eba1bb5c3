/* Verdicts of the link and volume tests kept across iterations.
 *
 * The verdict of edge (a, b) depends only on ring(a) U ring(b): the tets, their vertices'
 * positions, labels and flags, and vflags of the common neighbours of a and b (a surviving
 * vertex keeps its S membership: collapses preserve the boundary's topology); with a user
 * placement also on the vertex fields at a and b, which change only at the survivors of
 * collapses, end points of the collapses themselves. A collapse of
 * (u, s) changes exactly the rings of the vertices of ring(u) U ring(s) = {u, s} U N(u) U N(s),
 * so an edge neither of whose end points is such a vertex keeps its verdict. Such an edge exists
 * in the previous mesh as (vold[a], vold[b]) (compaction keeps the order of the kept vertices).
 */
#include "collapse_common.h"

/* vdirty[v]: v is an end point of a final edge (vaff[v] >= 0 after conflict_finalize) or a
 * neighbour of one; or of a collapse the matching selection undid (vaff -2: its edge was
 * admissible, which a verdict kept for an edge at a clean vertex must not hide from the host
 * tail, tail_touched). */
__kernel void verdict_dirty(uint nv, __global const int* vaff, __global const uint* nb_off, __global const int* nb,
                            __global uchar* vdirty) {
  uint v = get_global_id(0);
  if (v >= nv) return;
  uchar d = vaff[v] != -1;
  for (uint i = nb_off[v]; i < nb_off[v + 1] && !d; ++i) d = vaff[nb[i]] != -1;
  vdirty[v] = d;
}

/* vold[new index] = previous index and ndirty[new index] = vdirty, for the kept vertices (all
 * vertices of the new mesh are kept vertices). */
__kernel void verdict_vertex_old(uint nv_prev, __global const uint* keep, __global const uint* newidx,
                                 __global const uchar* vdirty, __global int* vold, __global uchar* ndirty,
                                 __global uint* dirty_flags) {
  uint v = get_global_id(0);
  if (v >= nv_prev || !keep[v]) return;
  vold[newidx[v]] = (int)v;
  ndirty[newidx[v]] = vdirty[v];
  dirty_flags[newidx[v]] = vdirty[v];
}

/* told[new index] = previous index, for the kept tets. */
__kernel void verdict_tet_old(uint nt_prev, __global const uint* keep, __global const uint* newidx,
                              __global int* told) {
  uint t = get_global_id(0);
  if (t >= nt_prev || !keep[t]) return;
  told[newidx[t]] = (int)t;
}

/* verdict[] of the edges v owns (v < u), per vertex v: the previous verdict of (v, u) when both
 * are clean (vdirty of their previous selves 0), else TCC_VERDICT_UNKNOWN. A clean v's N(v) is
 * the previous one renumbered in order (conn_ring_sort_and_gather), so its part above v is the
 * previous part above vold[v], entry for entry, with the previous edge ids in prev_nb_edge. */
__kernel void verdict_carry(uint nv, __global const uint* nb_off, __global const int* nb,
                            __global const uint* edge_off, __global const int* vold,
                            __global const uchar* vdirty, __global const uint* prev_nb_off,
                            __global const int* prev_nb_edge, __global const uchar* prev_verdict,
                            __global uchar* verdict) {
  uint v = get_global_id(0);
  if (v >= nv) return;
  const uint e0 = edge_off[v], up = edge_off[v + 1] - e0;
  const int ov = vold[v];
  if (vdirty[ov]) {
    for (uint i = 0; i < up; ++i) verdict[e0 + i] = TCC_VERDICT_UNKNOWN;
    return;
  }
  __global const int* upper = nb + (nb_off[v + 1] - up);
  __global const int* prev_upper_edge = prev_nb_edge + (prev_nb_off[ov + 1] - up);
  for (uint i = 0; i < up; ++i)
    verdict[e0 + i] = vdirty[vold[upper[i]]] ? TCC_VERDICT_UNKNOWN : prev_verdict[prev_upper_edge[i]];
}

/* Merges an earlier selection round (fin1, dir1, vaff1) into the current one: the edges of the
 * two rounds touch disjoint stars (the later round only takes edges with clean end points). */
__kernel void merge_rounds_edges(uint ne, __global const uint* fin1, __global const uchar* dir1, __global uint* fin,
                                 __global uchar* dir) {
  uint e = get_global_id(0);
  if (e >= ne || !fin1[e]) return;
  fin[e] = 1u;
  dir[e] = dir1[e];
}
__kernel void merge_rounds_vertices(uint nv, __global const int* vaff1, __global int* vaff) {
  uint v = get_global_id(0);
  if (v >= nv || vaff1[v] < 0) return;
  vaff[v] = vaff1[v];
}

/* The host tail's touched flags (collapse/sequential_run.hpp, TailSeed), per vertex of the
 * current mesh after carry_verdicts: its ring changed in the last iteration (ndirty), or an edge
 * at it keeps the surface guard's refusal (the guard looks beyond the star, so such an edge is
 * tested again). */
__kernel void tail_touched(uint nv, __global const uchar* ndirty, __global const uint* nb_off,
                           __global const int* nb_edge, __global const uchar* verdict, __global uchar* touched) {
  uint v = get_global_id(0);
  if (v >= nv) return;
  uchar t = ndirty[v];
  for (uint j = nb_off[v]; j < nb_off[v + 1] && !t; ++j) t = verdict[nb_edge[j]] == TCC_REFUSED_SURFACE;
  touched[v] = t;
}
