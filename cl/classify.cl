/* Feature classification of the boundary (paper, Section 3.1): ridge edges, then face /
 * ridge / corner vertices, with the rules written out in include/tetcollapse/topology.hpp and
 * implemented identically by host/topology/topology.cpp. One work item per edge / vertex,
 * arithmetic term by term without contraction so the decisions match the C++ reference. */
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
#pragma OPENCL FP_CONTRACT OFF

/* Is (p, q) a directed edge of triangle f? */
inline bool tc_traverses(__global const uint* f, uint p, uint q) {
  return (f[0] == p && f[1] == q) || (f[1] == p && f[2] == q) || (f[2] == p && f[0] == q);
}

inline double tc_ndot(__global const double* normals, uint a, uint b) {
  return normals[3 * a] * normals[3 * b] + normals[3 * a + 1] * normals[3 * b + 1] +
         normals[3 * a + 2] * normals[3 * b + 2];
}

/* Ridge edge: S-degree other than 0 or 2; or two S-faces not traversing it in opposite
 * directions; or two with 1 - dot(n0, n1) > eps_r. */
__kernel void tc_classify_edges(__global const uint* edges, __global const uint* offsets, __global const uint* list,
                                uint ne, __global const uint* sfaces, __global const double* normals, double eps_r,
                                __global uchar* ridge) {
  uint e = get_global_id(0);
  if (e >= ne) return;
  uint b = offsets[e], m = offsets[e + 1] - b;
  uchar r;
  if (m == 0) r = 0;
  else if (m != 2) r = 1;
  else {
    uint f0 = list[b], f1 = list[b + 1], v0 = edges[2 * e], v1 = edges[2 * e + 1];
    bool d0 = tc_traverses(sfaces + 3 * f0, v0, v1), d1 = tc_traverses(sfaces + 3 * f1, v0, v1);
    if (d0 == d1) r = 1;
    else r = (1.0 - tc_ndot(normals, f0, f1) > eps_r) ? 1 : 0;
  }
  ridge[e] = r;
}

/* Vertex of S-face f after v (k = 1) or before v (k = 2) in its orientation. */
inline uint tc_other(__global const uint* sfaces, uint f, uint v, int k) {
  __global const uint* t = sfaces + 3 * f;
  int p = t[0] == v ? 0 : (t[1] == v ? 1 : 2);
  return t[(p + k) % 3];
}

/* 0 interior, 1 face, 2 ridge, 3 corner (tc::VertexClass). */
__kernel void tc_classify_vertices(__global const uint* ve_offsets, __global const uint* ve_list,
                                   __global const uchar* ridge, __global const uint* vs_offsets,
                                   __global const uint* vs_list, uint nv, __global const uint* sfaces,
                                   __global const double* normals, double eps_f, __global uchar* cls) {
  uint v = get_global_id(0);
  if (v >= nv) return;
  uint fb = vs_offsets[v], fn = vs_offsets[v + 1] - fb;
  if (fn == 0) { cls[v] = 0; return; }
  uint ridges = 0;
  for (uint i = ve_offsets[v]; i < ve_offsets[v + 1]; ++i) ridges += ridge[ve_list[i]];
  if (ridges == 2) { cls[v] = 2; return; }
  if (ridges != 0) { cls[v] = 3; return; }
  for (uint i = 0; i < fn; ++i)
    for (uint j = i + 1; j < fn; ++j)
      if (1.0 - tc_ndot(normals, vs_list[fb + i], vs_list[fb + j]) > eps_f) { cls[v] = 3; return; }
  /* one closed fan: follow "before v" -> the unique triangle whose "after v" matches */
  uint cur = 0;
  for (uint step = 1; step <= fn; ++step) {
    uint want = tc_other(sfaces, vs_list[fb + cur], v, 2);
    uint next = 0, found = 0;
    for (uint j = 0; j < fn; ++j)
      if (tc_other(sfaces, vs_list[fb + j], v, 1) == want) { next = j; ++found; }
    if (found != 1) { cls[v] = 3; return; }
    cur = next;
    if (cur == 0 && step != fn) { cls[v] = 3; return; }
  }
  cls[v] = cur == 0 ? 1 : 3;
}
