/* Stage 6 of a collapse iteration: collapse the final edges and compact (paper Sec. 3.4).
 *
 *   vertex_keep    keep[v] = 0 for the removed end point of a final edge (vaff[v] >= 0)
 *   (host)         exclusive scan of keep -> new index of every kept vertex
 *   vertex_map     vmap[v] = new index of v, or of the survivor for a removed vertex
 *   vertex_write   positions (survivor at the placement), vertex fields (averaged for midpoint
 *                  placement, interpolated for a user placement), vertex mask
 *   tet_keep       a tet holding both end points of a final edge disappears
 *   (host)         exclusive scan of the tet flags
 *   tet_write      tets remapped through vmap, labels and tet fields carried
 *   origin_update  origin[i] (input vertex -> current vertex) composed with vmap */
#include "collapse_common.h"

inline int tcc_removed_vertex(__global const int* edges, __global const uchar* edge_dir, int e) {
  return (edge_dir[e] & TCC_DIR_REMOVE_V1) ? edges[2 * e + 1] : edges[2 * e];
}
inline int tcc_survivor(__global const int* edges, __global const uchar* edge_dir, int e) {
  return (edge_dir[e] & TCC_DIR_REMOVE_V1) ? edges[2 * e] : edges[2 * e + 1];
}

__kernel void vertex_keep(uint nv, __global const int* vaff, __global const int* edges,
                          __global const uchar* edge_dir, __global uint* keep) {
  uint v = get_global_id(0);
  if (v >= nv) return;
  int e = vaff[v];
  keep[v] = (e >= 0 && tcc_removed_vertex(edges, edge_dir, e) == (int)v) ? 0u : 1u;
}

__kernel void vertex_map(uint nv, __global const int* vaff, __global const int* edges,
                         __global const uchar* edge_dir, __global const uint* newidx, __global const uint* keep,
                         __global int* vmap) {
  uint v = get_global_id(0);
  if (v >= nv) return;
  vmap[v] = keep[v] ? (int)newidx[v] : (int)newidx[tcc_survivor(edges, edge_dir, vaff[v])];
}

__kernel void vertex_write(uint nv, __global const int* vaff, __global const int* edges,
                           __global const uchar* edge_dir, __global const uint* keep, __global const uint* newidx,
                           __global const double* pts, __global double* out_pts, uint ncomp,
                           __global const double* vfields, __global double* out_vfields, int has_mask,
                           __global const uchar* vmask, __global uchar* out_vmask) {
  uint v = get_global_id(0);
  if (v >= nv || !keep[v]) return;
  uint o = newidx[v];
  int e = vaff[v];
  double3 p = tc_point(pts, (int)v);
  int partner = -1;
  /* the fields of v and of the removed vertex: averaged at the midpoint; at a user placement p,
   * interpolated at p's parameter s along the edge (v0 + s (v1 - v0), clamped to [0, 1]) */
  double s = 0.5;
  if (e >= 0) { /* v survives the collapse of e */
    const uint d = edge_dir[e];
    const int v0 = edges[2 * e], v1 = edges[2 * e + 1];
    p = tcc_placement(pts, vfields, ncomp, v0, v1, d);
    if (d & TCC_DIR_MIDPOINT) partner = tcc_removed_vertex(edges, edge_dir, e);
    if (d & TCC_DIR_USER) {
      const double3 p0 = tc_point(pts, v0), d01 = tc_point(pts, v1) - p0;
      const double len2 = tcc_dot(d01, d01);
      const double s01 = len2 > 0.0 ? tcc_dot(p - p0, d01) / len2 : 0.5; /* the parameter of v1 */
      s = (int)v == v0 ? s01 : 1.0 - s01; /* of the partner, seen from v (clamped below) */
    }
  }
  out_pts[3 * o] = p.x;
  out_pts[3 * o + 1] = p.y;
  out_pts[3 * o + 2] = p.z;
  for (uint c = 0; c < ncomp; ++c) {
    double x = vfields[(size_t)v * ncomp + c];
    if (partner >= 0) {
      const double y = vfields[(size_t)partner * ncomp + c];
      x = s == 0.5 ? 0.5 * (x + y) : !(s > 0.0) ? x : s >= 1.0 ? y : x + s * (y - x);
    }
    out_vfields[(size_t)o * ncomp + c] = x;
  }
  if (has_mask) out_vmask[o] = vmask[v];
}

__kernel void tet_keep(uint nt, __global const int* tets, __global const int* vaff, __global const int* edges,
                       __global uint* keep) {
  uint t = get_global_id(0);
  if (t >= nt) return;
  __global const int* q = tets + 4 * t;
  uint k = 1u;
  for (int i = 0; i < 4; ++i) {
    int e = vaff[q[i]];
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
