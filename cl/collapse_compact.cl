/* Stage 6 of a collapse iteration: collapse the final edges and compact (paper Sec. 3.4).
 *
 *   vertex_keep    keep[v] = 0 for the removed end point of a final edge (verts2collapse[v] >= 0)
 *   (host)         exclusive scan of keep -> new index of every kept vertex
 *   vertex_map     vmap[v] = new index of v, or of the survivor for a removed vertex
 *   vertex_write   positions (survivor at the placement), vertex fields (averaged for midpoint
 *                  placement, interpolated for a user placement), vertex mask
 *   tet_keep       a tet holding both end points of a final edge disappears
 * With in_place (the matching selection, collapse_matching.cl, applied its collapses to the mesh
 * as it took them: tets renamed, removed tets flagged in tets_are_dead, survivors placed with their
 * fields), vertex_write copies and tet_keep reads tets_are_dead.
 *   (host)         exclusive scan of the tet flags
 *   tet_write      tets remapped through vmap, labels and tet fields carried
 *   origin_update  origin[i] (input vertex -> current vertex) composed with vmap */
#include "collapse_common.h"

inline int tcc_removed_vertex(__global const int* edges, __global const uchar* edges2dir, int e) {
  return (edges2dir[e] & TCC_DIR_REMOVE_V1) ? edges[2 * e + 1] : edges[2 * e];
}
inline int tcc_survivor(__global const int* edges, __global const uchar* edges2dir, int e) {
  return (edges2dir[e] & TCC_DIR_REMOVE_V1) ? edges[2 * e] : edges[2 * e + 1];
}

__kernel void vertex_keep(uint nv, __global const int* verts2collapse, __global const int* edges,
                          __global const uchar* edges2dir, __global uint* keep) {
  uint v = get_global_id(0);
  if (v >= nv) return;
  int e = verts2collapse[v];
  keep[v] = (e >= 0 && tcc_removed_vertex(edges, edges2dir, e) == (int)v) ? 0u : 1u;
}

__kernel void vertex_map(uint nv, __global const int* verts2collapse, __global const int* edges,
                         __global const uchar* edges2dir, __global const uint* newidx, __global const uint* keep,
                         __global int* vmap) {
  uint v = get_global_id(0);
  if (v >= nv) return;
  vmap[v] = keep[v] ? (int)newidx[v] : (int)newidx[tcc_survivor(edges, edges2dir, verts2collapse[v])];
}

__kernel void vertex_write(uint nv, __global const int* verts2collapse, __global const int* edges,
                           __global const uchar* edges2dir, __global const uint* keep, __global const uint* newidx,
                           __global const double* pts, __global double* out_pts, uint ncomp,
                           __global const double* vfields, __global double* out_vfields, int has_mask,
                           __global const uchar* vmask, __global uchar* out_vmask, int in_place) {
  uint v = get_global_id(0);
  if (v >= nv || !keep[v]) return;
  uint o = newidx[v];
  int e = in_place ? -1 : verts2collapse[v];
  double3 p = tc_point(pts, (int)v);
  if (e >= 0) { /* v survives the collapse of e: its position and fields as placed */
    const uint d = edges2dir[e];
    const int v0 = edges[2 * e], v1 = edges[2 * e + 1];
    p = tcc_placement(pts, vfields, ncomp, v0, v1, d);
    tcc_survivor_fields((int)v, v0, v1, d, p, pts, ncomp, vfields, out_vfields, o);
  } else {
    for (uint c = 0; c < ncomp; ++c) out_vfields[(size_t)o * ncomp + c] = vfields[(size_t)v * ncomp + c];
  }
  out_pts[3 * o] = p.x;
  out_pts[3 * o + 1] = p.y;
  out_pts[3 * o + 2] = p.z;
  if (has_mask) out_vmask[o] = vmask[v];
}

__kernel void tet_keep(uint nt, __global const int* tets, __global const int* verts2collapse, __global const int* edges,
                       __global uint* keep, int in_place, __global const uchar* tets_are_dead) {
  uint t = get_global_id(0);
  if (t >= nt) return;
  if (in_place) {
    keep[t] = !tets_are_dead[t];
    return;
  }
  __global const int* q = tets + 4 * t;
  uint k = 1u;
  for (int i = 0; i < 4; ++i) {
    int e = verts2collapse[q[i]];
    if (e < 0) continue;
    int other = edges[2 * e] == q[i] ? edges[2 * e + 1] : edges[2 * e];
    if (tcc_has(tets, (int)t, other)) k = 0u;
  }
  keep[t] = k;
}

__kernel void tet_write(uint nt, __global const int* tets, __global const uint* keep, __global const uint* newidx,
                        __global const int* vmap, __global int* out_tets) {
  uint t = get_global_id(0);
  if (t >= nt || !keep[t]) return;
  uint o = newidx[t];
  for (int i = 0; i < 4; ++i) out_tets[4 * o + i] = vmap[tets[4 * t + i]];
}

/* Carries ncomp values per kept entity (labels, tet fields). */
__kernel void compact_ints(uint n, __global const uint* keep, __global const uint* newidx, uint ncomp,
                           __global const int* in, __global int* out) {
  uint t = get_global_id(0);
  if (t >= n || !keep[t]) return;
  for (uint c = 0; c < ncomp; ++c) out[(size_t)newidx[t] * ncomp + c] = in[(size_t)t * ncomp + c];
}
__kernel void compact_doubles(uint n, __global const uint* keep, __global const uint* newidx, uint ncomp,
                              __global const double* in, __global double* out) {
  uint t = get_global_id(0);
  if (t >= n || !keep[t]) return;
  for (uint c = 0; c < ncomp; ++c) out[(size_t)newidx[t] * ncomp + c] = in[(size_t)t * ncomp + c];
}

__kernel void origin_update(uint n, __global const int* vmap, __global int* origin) {
  uint i = get_global_id(0);
  if (i >= n) return;
  origin[i] = vmap[origin[i]];
}
