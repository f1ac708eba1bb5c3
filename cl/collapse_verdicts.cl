/* Verdicts of the link and volume tests kept across iterations.
 *
 * The verdict of edge (a, b) depends only on ring(a) U ring(b): the tets, their vertices'
 * positions, labels and flags, and vflags of the common neighbours of a and b (a surviving
 * vertex keeps its S membership: collapses preserve the boundary's topology); with a user
 * placement also on the vertex fields at a and b, which change only at the survivors of
 * collapses, end points of the collapses themselves. A collapse of
 * (u, s) changes exactly the rings of the vertices of ring(u) U ring(s) = {u, s} U N(u) U N(s),
 * so an edge neither of whose end points is such a vertex keeps its verdict. Such an edge exists
 * in the previous mesh as (verts2prev[a], verts2prev[b]) (compaction keeps the order of the kept
 * vertices).
 */
#include "collapse_common.h"

/* prev_verts_are_dirty[v]: v is an end point of a final edge (verts2collapse[v] >= 0 after
 * conflict_finalize) or a neighbour of one; or of a collapse the matching selection undid
 * (verts2collapse -2: its edge was admissible, which a verdict kept for an edge at a clean vertex
 * must not hide from the host tail, tail_touched). */
__kernel void verdict_dirty(uint nv, __global const int* verts2collapse, __global const uint* nb_off,
                            __global const int* nb, __global uchar* prev_verts_are_dirty) {
  uint v = get_global_id(0);
  if (v >= nv) return;
  uchar d = verts2collapse[v] != -1;
  for (uint i = nb_off[v]; i < nb_off[v + 1] && !d; ++i) d = verts2collapse[nb[i]] != -1;
  prev_verts_are_dirty[v] = d;
}

/* verts2prev[new index] = previous index and verts_are_dirty[new index] = prev_verts_are_dirty, for
 * the kept vertices (all vertices of the new mesh are kept vertices). */
__kernel void verdict_vertex_old(uint nv_prev, __global const uint* keep, __global const uint* newidx,
                                 __global const uchar* prev_verts_are_dirty, __global int* verts2prev,
                                 __global uchar* verts_are_dirty, __global uint* verts_are_dirty_words) {
  uint v = get_global_id(0);
  if (v >= nv_prev || !keep[v]) return;
  verts2prev[newidx[v]] = (int)v;
  verts_are_dirty[newidx[v]] = prev_verts_are_dirty[v];
  verts_are_dirty_words[newidx[v]] = prev_verts_are_dirty[v];
}

/* tets2prev[new index] = previous index, for the kept tets. */
__kernel void verdict_tet_old(uint nt_prev, __global const uint* prev_tets_are_kept, __global const uint* prev_tets2new,
                              __global int* tets2prev) {
  uint t = get_global_id(0);
  if (t >= nt_prev || !prev_tets_are_kept[t]) return;
  tets2prev[prev_tets2new[t]] = (int)t;
}

/* edges2verdict[] of the edges v owns (v < u), per vertex v: the previous verdict of (v, u) when
 * both are clean (prev_verts_are_dirty of their previous selves 0), else TCC_VERDICT_UNKNOWN. A
 * clean v's N(v) is the previous one renumbered in order (conn_ring_sort_and_gather), so its part
 * above v is the previous part above verts2prev[v], entry for entry, with the previous edge ids in
 * prev_nb_edge. */
__kernel void verdict_carry(uint nv, __global const uint* nb_off, __global const int* nb, __global const uint* edge_off,
                            __global const int* verts2prev, __global const uchar* prev_verts_are_dirty,
                            __global const uint* prev_nb_off, __global const int* prev_nb_edge,
                            __global const uchar* prev_edges2verdict, __global uchar* edges2verdict) {
  uint v = get_global_id(0);
  if (v >= nv) return;
  const uint e0 = edge_off[v], up = edge_off[v + 1] - e0;
  const int ov = verts2prev[v];
  if (prev_verts_are_dirty[ov]) {
    for (uint i = 0; i < up; ++i) edges2verdict[e0 + i] = TCC_VERDICT_UNKNOWN;
    return;
  }
  __global const int* upper = nb + (nb_off[v + 1] - up);
  __global const int* prev_upper_edge = prev_nb_edge + (prev_nb_off[ov + 1] - up);
  for (uint i = 0; i < up; ++i)
    edges2verdict[e0 + i] =
        prev_verts_are_dirty[verts2prev[upper[i]]] ? TCC_VERDICT_UNKNOWN : prev_edges2verdict[prev_upper_edge[i]];
}

/* Merges an earlier selection round (rounds_final, rounds_dir, rounds_verts2collapse) into the
 * current one: the edges of the two rounds touch disjoint stars (the later round only takes edges
 * with clean end points). */
__kernel void merge_rounds_edges(uint ne, __global const uint* rounds_final, __global const uchar* rounds_dir,
                                 __global uint* edges_are_final, __global uchar* edges2dir) {
  uint e = get_global_id(0);
  if (e >= ne || !rounds_final[e]) return;
  edges_are_final[e] = 1u;
  edges2dir[e] = rounds_dir[e];
}
__kernel void merge_rounds_vertices(uint nv, __global const int* rounds_verts2collapse, __global int* verts2collapse) {
  uint v = get_global_id(0);
  if (v >= nv || rounds_verts2collapse[v] < 0) return;
  verts2collapse[v] = rounds_verts2collapse[v];
}

/* The host tail's touched flags (collapse/sequential_run.hpp, TailSeed), per vertex of the
 * current mesh after carry_verdicts: its ring changed in the last iteration (verts_are_dirty), or
 * an edge at it keeps the surface guard's refusal (the guard looks beyond the star, so such an edge
 * is tested again). */
__kernel void tail_touched(uint nv, __global const uchar* verts_are_dirty, __global const uint* nb_off,
                           __global const int* nb_edge, __global const uchar* edges2verdict, __global uchar* touched) {
  uint v = get_global_id(0);
  if (v >= nv) return;
  uchar t = verts_are_dirty[v];
  for (uint j = nb_off[v]; j < nb_off[v + 1] && !t; ++j) t = edges2verdict[nb_edge[j]] == TCC_REFUSED_SURFACE;
  touched[v] = t;
}
