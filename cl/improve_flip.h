/* Edge removal's combinatorics, written once for the device (cl/improve_flip.cl) and the host
 * (host/improve/flips.cpp), compiled as OpenCL C and as C++ (names in namespace tc::geo
 * there): the ring of an edge from its tets, and the best triangulation of the ring's polygon
 * (Klincsek's dynamic programme, as Shewchuk's "Two discrete optimization algorithms for the
 * topological improvement of tetrahedral meshes" uses it). Only private arrays: the callers
 * gather what the mesh says. */
#ifndef TETCOLLAPSE_IMPROVE_FLIP_H
#define TETCOLLAPSE_IMPROVE_FLIP_H

#ifndef __OPENCL_C_VERSION__
namespace tc::geo {
#endif

/* Shewchuk: larger rings rarely give a better triangulation */
#define TCI_MAX_RING 7

/* The two vertices of tet q other than a and b, ordered so that (a, b, *c, *d) is an even
 * permutation of q, i.e. has q's (positive) orientation. */
TC_FN void tci_others(const int* q, int a, int b, int* c, int* d) {
  int pos[4], n = 0, ia = -1, ib = -1;
  for (int k = 0; k < 4; ++k) {
    if (q[k] == a) ia = k;
    else if (q[k] == b) ib = k;
    else pos[n++] = k;
  }
  int perm[4] = {ia, ib, pos[0], pos[1]};
  int inversions = 0;
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) inversions += perm[i] > perm[j];
  *c = q[pos[0]];
  *d = q[pos[1]];
  if (inversions & 1) {
    int t = *c;
    *c = *d;
    *d = t;
  }
}

/* The ring r[0..*len) of an edge whose n tets go from[i] -> to[i] around it: a closed ring
 * (*closed, *len = n) or a chain (*len = n + 1, from the vertex no arc enters). *start: the
 * tet the chain starts with. Returns 0 when the arcs are not one simple ring or chain. */
TC_FN int tci_chain(int n, const int* from, const int* to, int* r, int* len, int* closed, int* start) {
  int s = 0;
  for (int i = 0; i < n; ++i) {
    int entered = 0;
    for (int k = 0; k < n; ++k) entered = entered || to[k] == from[i];
    if (!entered) s = i;
  }
  *start = s;
  r[0] = from[s];
  int l = 1;
  for (int step = 0; step < n; ++step) {
    int j = 0;
    while (j < n && from[j] != r[l - 1]) ++j;
    if (j == n) return 0; /* not one chain */
    r[l++] = to[j];
  }
  *closed = r[l - 1] == r[0];
  if (*closed) --l;
  for (int i = 0; i < l; ++i)
    for (int k = 0; k < i; ++k)
      if (r[k] == r[i]) return 0; /* not a simple ring or chain */
  *len = l;
  return 1;
}

/* The triangle (i, j, k), i < j < k, of a polygon of mm vertices, as an index into the
 * caller's table of triangle qualities. */
TC_FN int tci_tri_index(int i, int j, int k) { return (i * TCI_MAX_RING + j) * (TCI_MAX_RING + 1) + k; }
#define TCI_TRI_TABLE (TCI_MAX_RING * (TCI_MAX_RING + 1) * (TCI_MAX_RING + 1))

/* Klincsek's programme over the polygon r_0..r_mm-1: best[i][j] (flattened i * TCI_MAX_RING + j)
 * is the best worst quality of a triangulation of the sub-polygon r_i..r_j, split[...] its
 * apex. chord_ok[i * TCI_MAX_RING + j]: the chord (i, j) may be used; tri_q[tci_tri_index(i,
 * k, j)]: the quality the triangle gives (-infinity: not allowed), read only for i < k < j with
 * chord (i, j) allowed and j - i >= 2. Returns best[0][mm - 1]. */
TC_FN double tci_klincsek(int mm, const int* chord_ok, const double* tri_q, double* best, int* split) {
  for (int l = 1; l < mm; ++l)
    for (int i = 0; i + l < mm; ++i) {
      int j = i + l, ij = i * TCI_MAX_RING + j;
      split[ij] = -1;
      if (l == 1) {
        best[ij] = INFINITY;
        continue;
      }
      best[ij] = -INFINITY;
      if (!chord_ok[ij]) continue;
      for (int k = i + 1; k < j; ++k) {
        double q = best[i * TCI_MAX_RING + k], x = best[k * TCI_MAX_RING + j], t = tri_q[tci_tri_index(i, k, j)];
        q = x < q ? x : q;
        q = t < q ? t : q;
        if (q > best[ij]) {
          best[ij] = q;
          split[ij] = k;
        }
      }
    }
  return best[mm - 1];
}

/* The tets of the triangulation split[] describes: each triangle (r_i, r_k, r_j) with b and,
 * reversed, with a, both positive. out: 4 ints per tet; returns their count (2 mm - 4). */
TC_FN int tci_emit(int mm, const int* r, const int* split, int a, int b, int* out) {
  int stack[2 * TCI_MAX_RING][2], top = 0, n = 0;
  stack[top][0] = 0;
  stack[top++][1] = mm - 1;
  while (top > 0) {
    --top;
    int i = stack[top][0], j = stack[top][1];
    if (j - i < 2) continue;
    int k = split[i * TCI_MAX_RING + j];
    out[4 * n] = r[i];
    out[4 * n + 1] = r[k];
    out[4 * n + 2] = r[j];
    out[4 * n + 3] = b;
    ++n;
    out[4 * n] = r[j];
    out[4 * n + 1] = r[k];
    out[4 * n + 2] = r[i];
    out[4 * n + 3] = a;
    ++n;
    stack[top][0] = i;
    stack[top++][1] = k;
    stack[top][0] = k;
    stack[top++][1] = j;
  }
  return n;
}

#ifndef __OPENCL_C_VERSION__
}  // namespace tc::geo
#endif

#endif /* TETCOLLAPSE_IMPROVE_FLIP_H */
