/* Vertex relocation on the device (host/improve/relocate_device.cpp): rounds of a conflict-free
 * set of vertices, each relocated by tci_relocate (cl/improve_relocate.h).
 *
 * A round, over the pass's candidates:
 *   relocate_keys     each candidate still to try: key = (its star's worst min-sine, its index)
 *   relocate_chosen   a candidate whose key is the smallest in every tet of its star is chosen
 *                     and relocated; its star's tets get their min-sine again
 * Two chosen vertices never share a tet, so none reads a point or a tet's quality that another
 * writes in the round, and the candidate of smallest key is always chosen: every round makes
 * progress. The choice depends on the keys only, never on the work-group size or the order work
 * items run in. Vertices not to try keep the largest key (the host fills verts2key with it). */
#include "improve_relocate.h"

/* stars wider than this are left to the host */
#define TCI_MAX_STAR 128
#define TCI_NO_KEY 0xFFFFFFFFFFFFFFFFUL

__kernel void relocate_keys(uint nc, __global const int* cands, __global const uint* verts2tets_offsets,
                            __global const int* verts2tets, __global const double* tets2quality,
                            __global const uchar* verts_are_cands, __global ulong* verts2key) {
  uint i = get_global_id(0);
  if (i >= nc) return;
  int v = cands[i];
  ulong key = TCI_NO_KEY;
  if (verts_are_cands[v]) {
    double q = INFINITY;
    for (uint j = verts2tets_offsets[v]; j < verts2tets_offsets[v + 1]; ++j) q = fmin(q, tets2quality[verts2tets[j]]);
    /* non-negative floats order as their bits */
    float f = (float)fmax(q, 0.0);
    key = ((ulong)as_uint(f) << 32) | (ulong)v;
  }
  verts2key[v] = key;
}

/* verts2round: the round a vertex was chosen in (from 1), negated when it did not move, 0 if
 * it was not chosen; counters[0]: candidates left for the next round. */
__kernel void relocate_chosen(uint nc, uint round, __global const int* cands, __global const uint* verts2tets_offsets,
                              __global const int* verts2tets, __global const int* tets,
                              __global const ulong* verts2key, __global const uchar* verts2motion,
                              __global const double* verts2direction, double cos_threshold, __global double* pts,
                              __global double* tets2quality, __global uchar* verts_are_cands,
                              __global int* verts2round, __global uint* counters) {
  uint i = get_global_id(0);
  if (i >= nc) return;
  int v = cands[i];
  if (!verts_are_cands[v]) return;
  uint b = verts2tets_offsets[v], e = verts2tets_offsets[v + 1];
  ulong key = verts2key[v];
  for (uint j = b; j < e; ++j) {
    int4 q = vload4(verts2tets[j], tets);
    if (verts2key[q.x] < key || verts2key[q.y] < key || verts2key[q.z] < key || verts2key[q.w] < key) {
      atomic_inc(&counters[0]);
      return;
    }
  }
  verts_are_cands[v] = 0;
  /* the star worst first (insertion sort: a few dozen tets) */
  int sorted[TCI_MAX_STAR];
  int n = (int)(e - b);
  for (int k = 0; k < n; ++k) {
    int t = verts2tets[b + k], j = k;
    double q = tets2quality[t];
    while (j > 0 && tets2quality[sorted[j - 1]] > q) {
      sorted[j] = sorted[j - 1];
      --j;
    }
    sorted[j] = t;
  }
  tc_d3 p;
  if (!tci_relocate(pts, tets, verts2tets + b, sorted, n, v, verts2motion[v], tc_point(verts2direction, v),
                    tc_point(pts, v), INFINITY, cos_threshold, 0, &p)) {
    verts2round[v] = -(int)round;
    return;
  }
  pts[3 * v] = p.x;
  pts[3 * v + 1] = p.y;
  pts[3 * v + 2] = p.z;
  verts2round[v] = (int)round;
  /* the star's tets are this vertex's alone in the round */
  for (uint j = b; j < e; ++j) {
    int4 q = vload4(verts2tets[j], tets);
    tets2quality[verts2tets[j]] =
        tc_tet_min_sine(tc_point(pts, q.x), tc_point(pts, q.y), tc_point(pts, q.z), tc_point(pts, q.w));
  }
}
