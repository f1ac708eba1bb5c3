/* The reference surface of the boundary error bound (CollapseOptions::boundary_reference): the
 * input's S faces as triangles, 9 coordinates each, written once after the first connectivity
 * build (host/collapse/reference.cpp). stets: the tets owning an S face (Connectivity::owns_s,
 * compacted); smask: which of their faces (bit f: the face opposite local vertex f). */
#include "collapse_common.h"

/* counts[i]: the S faces tet stets[i] owns */
__kernel void reference_counts(uint n, __global const uint* stets, __global const uchar* smask,
                               __global uint* counts) {
  uint i = get_global_id(0);
  if (i >= n) return;
  uint m = smask[stets[i]];
  counts[i] = (m & 1u) + ((m >> 1) & 1u) + ((m >> 2) & 1u) + ((m >> 3) & 1u);
}

/* the triangles of tet stets[i] from off[i], in the order of its faces */
__kernel void reference_write(uint n, __global const uint* stets, __global const uchar* smask,
                              __global const uint* off, __global const int* tets, __global const double* pts,
                              __global double* out) {
  uint i = get_global_id(0);
  if (i >= n) return;
  int t = (int)stets[i];
  uint m = smask[t], k = off[i];
  for (int f = 0; f < 4; ++f) {
    if (!((m >> f) & 1u)) continue;
    for (int c = 0; c < 3; ++c) {
      int v = tets[4 * t + TC_TET_FACES[f][c]];
      for (int d = 0; d < 3; ++d) out[(size_t)9 * k + 3 * c + d] = pts[(size_t)3 * v + d];
    }
    ++k;
  }
}
