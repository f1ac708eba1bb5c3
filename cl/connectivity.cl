/* Mesh connectivity on the device (paper, Section 3.1): edges, tet -> edges, CSR adjacency,
 * boundary and material-interface faces with outward unit normals, boundary flags.
 *
 * The host side (host/device/connectivity.cpp) chains these kernels with the runtime's
 * primitives (stable radix sort, segment heads, scan). Every kernel is one work item per
 * element with no local memory and no atomics on results, so the arrays do not depend on the
 * work-group size; the orders are the ones defined in include/tetcollapse/topology.hpp, and
 * the arithmetic is written out term by term (no builtin cross/dot/normalize, no contraction
 * into fma) so the normals are bit-identical to the C++ reference. OpenCL C 1.2. */
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
#pragma OPENCL FP_CONTRACT OFF

/* Local edges of face f (the face opposite corner f) as indices into TC_TET_EDGES
 * {01, 02, 03, 12, 13, 23}. */
__constant int TC_FACE_EDGES[4][3] = {{3, 4, 5}, {1, 2, 5}, {0, 2, 4}, {0, 1, 3}};
__constant int TC_TET_EDGE_CORNERS[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
__constant int TC_OUT_FACES[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

/* Index in TC_TET_EDGES of the edge joining local corners i != j. */
inline int tc_local_edge(int i, int j) {
  int a = min(i, j), b = max(i, j);
  return a == 0 ? b - 1 : (a == 1 ? b + 1 : 5);
}

/* Checks the tets: every index in [0, nv) and four distinct corners. bad[0] receives the
 * smallest offending tet index (atomic_min keeps the report independent of scheduling). */
__kernel void tc_check_tets(__global const int* tets, uint nt, int nv, __global uint* bad) {
  uint t = get_global_id(0);
  if (t >= nt) return;
  int v0 = tets[4 * t], v1 = tets[4 * t + 1], v2 = tets[4 * t + 2], v3 = tets[4 * t + 3];
  bool ok = v0 >= 0 && v1 >= 0 && v2 >= 0 && v3 >= 0 && v0 < nv && v1 < nv && v2 < nv && v3 < nv &&
            v0 != v1 && v0 != v2 && v0 != v3 && v1 != v2 && v1 != v3 && v2 != v3;
  if (!ok) atomic_min(bad, t);
}

/* Keys (v0 << 32 | v1), v0 < v1, of the 6 edges of every tet; payload tet * 6 + local edge. */
__kernel void tc_edge_keys(__global const int* tets, uint n, __global ulong* keys, __global uint* vals) {
  uint i = get_global_id(0);
  if (i >= n) return;
  uint t = i / 6, e = i % 6;
  uint a = (uint)tets[4 * t + TC_TET_EDGE_CORNERS[e][0]];
  uint b = (uint)tets[4 * t + TC_TET_EDGE_CORNERS[e][1]];
  keys[i] = ((ulong)min(a, b) << 32) | (ulong)max(a, b);
  vals[i] = i;
}

/* One work item per distinct edge s (segment [starts[s], starts[s+1]) of the sorted keys):
 * the edge's vertices, the tet -> edge entries, and edge -> tets in sorted (ascending) order. */
__kernel void tc_edge_segments(__global const ulong* keys, __global const uint* vals, __global const uint* starts,
                               uint ne, __global uint* edges, __global uint* tet_edges, __global uint* edge_tets) {
  uint s = get_global_id(0);
  if (s >= ne) return;
  uint b = starts[s], e = starts[s + 1];
  ulong k = keys[b];
  edges[2 * s] = (uint)(k >> 32);
  edges[2 * s + 1] = (uint)(k & 0xffffffffUL);
  for (uint i = b; i < e; ++i) {
    uint p = vals[i];
    tet_edges[p] = s;
    edge_tets[i] = p / 6;
  }
}

/* Keys for a CSR list: entry i belongs to list src[i]; payload i / per (its entity). */
__kernel void tc_list_keys(__global const uint* src, uint n, uint per, __global ulong* keys, __global uint* vals) {
  uint i = get_global_id(0);
  if (i >= n) return;
  keys[i] = (ulong)src[i];
  vals[i] = i / per;
}

/* offsets[v] = first position of a key >= v in the sorted keys (v = 0 .. lists, so
 * offsets[lists] = n): lists without entries get empty ranges. */
__kernel void tc_csr_offsets(__global const ulong* keys, uint n, uint lists, __global uint* offsets) {
  uint v = get_global_id(0);
  if (v > lists) return;
  uint lo = 0, hi = n;
  while (lo < hi) {
    uint mid = lo + (hi - lo) / 2;
    if (keys[mid] < (ulong)v) lo = mid + 1;
    else hi = mid;
  }
  offsets[v] = lo;
}

/* Face keys: the triangle a < b < c of face f of tet t is keyed (edge_id(a, b) << 32 | c);
 * payload t * 4 + f. */
__kernel void tc_face_keys(__global const int* tets, __global const uint* tet_edges, uint n, __global ulong* keys,
                           __global uint* vals) {
  uint i = get_global_id(0);
  if (i >= n) return;
  uint t = i / 4, f = i % 4;
  int l0 = TC_OUT_FACES[f][0], l1 = TC_OUT_FACES[f][1], l2 = TC_OUT_FACES[f][2], tmp;
  /* the same three-element sorting network as the C++ reference */
  if (tets[4 * t + l0] > tets[4 * t + l1]) { tmp = l0; l0 = l1; l1 = tmp; }
  if (tets[4 * t + l1] > tets[4 * t + l2]) { tmp = l1; l1 = l2; l2 = tmp; }
  if (tets[4 * t + l0] > tets[4 * t + l1]) { tmp = l0; l0 = l1; l1 = tmp; }
  uint ab = tet_edges[6 * t + tc_local_edge(l0, l1)];
  keys[i] = ((ulong)ab << 32) | (ulong)(uint)tets[4 * t + l2];
  vals[i] = i;
}

/* How many S-faces each distinct face contributes: 1 for a boundary face (one tet), 1 for an
 * interface (two tets, different labels), 0 for an interior face, one per tet when more than
 * two tets share it (invalid input, each side kept as boundary). */
__kernel void tc_face_count(__global const uint* vals, __global const uint* starts, uint nf,
                            __global const int* labels, uint has_labels, __global uint* count) {
  uint s = get_global_id(0);
  if (s >= nf) return;
  uint b = starts[s], m = starts[s + 1] - b;
  uint c = m;
  if (m == 2) c = (has_labels && labels[vals[b] / 4] != labels[vals[b + 1] / 4]) ? 1u : 0u;
  count[s] = c;
}

/* Writes the S-faces of distinct face s at position offset[s] (exclusive scan of the counts):
 * the owner's face in outward order (TC_TET_FACES), owner, local index, interface flag and
 * the unit normal. An interface face is owned by the tet of the smaller label. */
__kernel void tc_face_emit(__global const uint* vals, __global const uint* starts, uint nf,
                           __global const int* labels, uint has_labels, __global const uint* offset,
                           __global const int* tets, __global const double* points, __global uint* sfaces,
                           __global uint* sface_tet, __global char* sface_local, __global uchar* sface_interface,
                           __global double* normals) {
  uint s = get_global_id(0);
  if (s >= nf) return;
  uint b = starts[s], m = starts[s + 1] - b;
  uint first = b, last = b + m, out = offset[s];
  uchar iface = 0;
  if (m == 2) {
    if (!has_labels) return;
    int la = labels[vals[b] / 4], lb = labels[vals[b + 1] / 4];
    if (la == lb) return;
    first = la < lb ? b : b + 1;
    last = first + 1;
    iface = 1;
  }
  for (uint i = first; i < last; ++i, ++out) {
    uint p = vals[i], t = p / 4, f = p % 4;
    uint v[3];
    double x[3], y[3], z[3];
    for (int k = 0; k < 3; ++k) {
      v[k] = (uint)tets[4 * t + TC_OUT_FACES[f][k]];
      sfaces[3 * out + k] = v[k];
      x[k] = points[3 * v[k]];
      y[k] = points[3 * v[k] + 1];
      z[k] = points[3 * v[k] + 2];
    }
    sface_tet[out] = t;
    sface_local[out] = (char)f;
    sface_interface[out] = iface;
    /* n = (p1 - p0) x (p2 - p0), then n / |n| (zero stays zero), as tc::geo does */
    double ux = x[1] - x[0], uy = y[1] - y[0], uz = z[1] - z[0];
    double wx = x[2] - x[0], wy = y[2] - y[0], wz = z[2] - z[0];
    double nx = uy * wz - uz * wy, ny = uz * wx - ux * wz, nz = ux * wy - uy * wx;
    double l = sqrt(nx * nx + ny * ny + nz * nz);
    if (l > 0.0) {
      nx = nx / l;
      ny = ny / l;
      nz = nz / l;
    }
    normals[3 * out] = nx;
    normals[3 * out + 1] = ny;
    normals[3 * out + 2] = nz;
  }
}

/* Keys for edge -> S-faces: the 3 edges of every S-face, found through its owner's tet edges. */
__kernel void tc_sface_edge_keys(__global const uint* sface_tet, __global const char* sface_local,
                                 __global const uint* tet_edges, uint n, __global ulong* keys, __global uint* vals) {
  uint i = get_global_id(0);
  if (i >= n) return;
  uint s = i / 3, k = i % 3;
  keys[i] = (ulong)tet_edges[6 * sface_tet[s] + TC_FACE_EDGES[(int)sface_local[s]][k]];
  vals[i] = s;
}

/* flags[x] = OR over the S-faces of x of (interface ? 2 : 1). */
__kernel void tc_boundary_flags(__global const uint* offsets, __global const uint* list, uint n,
                                __global const uchar* sface_interface, __global uchar* flags) {
  uint x = get_global_id(0);
  if (x >= n) return;
  uchar f = 0;
  for (uint i = offsets[x]; i < offsets[x + 1]; ++i) f |= sface_interface[list[i]] ? (uchar)2 : (uchar)1;
  flags[x] = f;
}
