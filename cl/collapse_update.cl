/* Connectivity carried through a compaction instead of rebuilt (every iteration after the
 * first; the paper names the rebuild as its bottleneck). A collapse of the final edge (u, s),
 * u removed, s surviving, changes the mesh only inside ring(u) U ring(s):
 *   rings     ring'(s) = ring(u) U ring(s) without the tets holding both u and s (exactly the
 *             tets the two rings share); every other kept vertex keeps its ring minus the dropped
 *             tets. Compaction keeps the order of the kept tets, so merging the previous sorted
 *             rings, renumbered, gives the new rings sorted, with no scatter and no sort.
 *   tet_nbr   a dropped tet (u, s, c, d) glued the tet X across its face (u, c, d) to the tet Y
 *             across (s, c, d); after the collapse both faces are (s, c, d), so X and Y are
 *             neighbours. Every other face keeps its neighbour (the link condition rules out
 *             any other coincidence of faces). X and Y lie in the collapse's star, which no other
 *             final edge touches, so Y is kept.
 * The matching selection (collapse_matching.cl) glues tet_nbr as it applies its collapses, so
 * with in_place tet_nbr_update only renumbers.
 * Inputs are those of collapse_compact.cl before the swap: previous tets, rings (vt_off, vt,
 * ascending), tet_nbr, verts2collapse and edges2dir of the final edges, keep flags and new
 * indices. */
#include "collapse_common.h"

/* The vertex removed onto kept vertex v, or -1. */
inline int tcc_removed_onto(__global const int* verts2collapse, __global const int* edges, int v) {
  int e = verts2collapse[v];
  if (e < 0) return -1;
  return edges[2 * e] == v ? edges[2 * e + 1] : edges[2 * e];
}

__kernel void ring_update_count(uint nv_prev, __global const uint* vkeep, __global const uint* vnew,
                                __global const int* verts2collapse, __global const int* edges,
                                __global const uint* vt_off, __global const int* vt, __global const uint* tkeep,
                                __global uint* count) {
  uint v = get_global_id(0);
  if (v >= nv_prev || !vkeep[v]) return;
  uint n = 0;
  for (uint i = vt_off[v]; i < vt_off[v + 1]; ++i) n += tkeep[vt[i]];
  int u = tcc_removed_onto(verts2collapse, edges, (int)v);
  if (u >= 0)
    for (uint i = vt_off[u]; i < vt_off[u + 1]; ++i) n += tkeep[vt[i]];
  count[vnew[v]] = n;
}

__kernel void ring_update_write(uint nv_prev, __global const uint* vkeep, __global const uint* vnew,
                                __global const int* verts2collapse, __global const int* edges,
                                __global const uint* vt_off, __global const int* vt, __global const uint* tkeep,
                                __global const uint* tnew, __global const uint* new_vt_off, __global int* new_vt) {
  uint v = get_global_id(0);
  if (v >= nv_prev || !vkeep[v]) return;
  __global int* out = new_vt + new_vt_off[vnew[v]];
  int u = tcc_removed_onto(verts2collapse, edges, (int)v);
  uint i = vt_off[v], ie = vt_off[v + 1];
  uint j = u >= 0 ? vt_off[u] : 0u, je = u >= 0 ? vt_off[u + 1] : 0u;
  uint m = 0;
  while (i < ie || j < je) {
    int t;
    if (j >= je || (i < ie && vt[i] < vt[j])) t = vt[i++];
    else t = vt[j++];
    if (tkeep[t]) out[m++] = (int)tnew[t];
  }
}

__kernel void tet_nbr_update(uint nt_prev, __global const int* tets, __global const uint* tkeep,
                             __global const uint* tnew, __global const int* verts2collapse, __global const int* edges,
                             __global const int* tet_nbr, __global int* new_tet_nbr, int in_place) {
  uint t = get_global_id(0);
  if (t >= nt_prev || !tkeep[t]) return;
  for (int f = 0; f < 4; ++f) {
    int x = tet_nbr[4 * t + f], out = x;
    if (in_place) { /* glued already (collapse_matching.cl): every neighbour is kept */
      out = x >= 0 ? (int)tnew[x] : x;
    } else if (x >= 0 && tkeep[x]) {
      out = (int)tnew[x];
    } else if (x >= 0) {
      /* x = (u, s, c, d) was dropped by the final edge of its vertices; t holds one of u, s */
      __global const int* q = tets + 4 * x;
      int e = -1;
      for (int k = 0; k < 4 && e < 0; ++k) e = verts2collapse[q[k]];
      int a = edges[2 * e], b = edges[2 * e + 1];
      int mine = tcc_has(tets, (int)t, a) ? a : b;
      int y = tet_nbr[4 * x + tcc_local(tets, x, mine)];
      out = y < 0 ? y : tkeep[y] ? (int)tnew[y] : -2; /* Y dropped: impossible, see above */
    }
    new_tet_nbr[4 * tnew[t] + f] = out;
  }
}
