/* Edge flags and vertex classes from the S-faces around a vertex (the rules of
 * tc::build_topology, include/tetcollapse/topology.hpp), shared by the connectivity stage
 * (cl/collapse_connectivity.cl, conn_surface_flags) and the sequential CPU method
 * (host/collapse/sequential_mesh.cpp, SeqMesh::classify): written once, compiled as OpenCL C
 * and as C++ (names in namespace tc::geo there, as cl/geometry.h).
 *
 * Both callers gather the S-faces of a vertex v that v's tets own (tcc_owned_sface): per face,
 * the vertices after and before v along the face's orientation, its unit normal and its kind
 * (TCC_BOUNDARY or TCC_INTERFACE). The S-faces through an edge (v, u) are those with u after or
 * before v. */
#ifndef TETCOLLAPSE_COLLAPSE_CLASSIFY_H
#define TETCOLLAPSE_COLLAPSE_CLASSIFY_H

#include "collapse_predicate.h"
#include "geometry.h"

#ifndef __OPENCL_C_VERSION__
namespace tc::geo {
#endif

/* a.b, written out (the same operations on both sides) */
TC_FN double tc_sf_dot(tc_d3 a, tc_d3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

/* The ridge rule for an S-edge (a, b) with ns owned S-faces through it, the first two oriented
 * a -> b or not (fwd0, fwd1), with unit normals n0, n1: a ridge when ns != 2, when the two faces
 * traverse the edge in the same direction, or when 1 - n0.n1 > eps_r. Symmetric in a and b
 * (swapping them flips both directions). */
TC_FN int tc_sf_ridge_rule(int ns, int fwd0, int fwd1, tc_d3 n0, tc_d3 n1, double eps_r) {
  if (ns != 2) return 1;
  if (fwd0 == fwd1) return 1;
  return 1.0 - tc_sf_dot(n0, n1) > eps_r;
}

/* The edge (v, u) among v's fn S-faces (kind may be 0: no flags wanted): returns the OR of the
 * kinds of the faces through it (0: none, not an S-edge) and sets *ridge by the ridge rule. */
TC_FN unsigned tc_sf_edge(int u, const int* after, const int* before, const unsigned char* kind,
                          const tc_d3* normal, int fn, double eps_r, int* ridge) {
  unsigned flags = 0;
  int ns = 0, k0 = 0, k1 = 0;
  for (int j = 0; j < fn; ++j)
    if (after[j] == u || before[j] == u) {
      if (kind) flags |= kind[j];
      if (ns == 0) k0 = j;
      else if (ns == 1) k1 = j;
      ++ns;
    }
  *ridge = ns > 0 && tc_sf_ridge_rule(ns, after[k0] == u, after[k1] == u, normal[k0], normal[k1], eps_r);
  return flags;
}

/* The class of a vertex on S from all of its fn >= 1 S-faces: ridge when exactly two of its
 * edges are ridges; face when none is, all normals are within eps_f (1 - ni.nj <= eps_f) and
 * the faces form one closed fan; corner otherwise. */
TC_FN int tc_sf_class(const int* after, const int* before, const tc_d3* normal, int fn, double eps_r, double eps_f) {
  /* the ridge edges at v: each vertex of v's S-faces once */
  int ridges = 0;
  for (int j = 0; j < fn; ++j)
    for (int side = 0; side < 2; ++side) {
      const int u = side == 0 ? after[j] : before[j];
      int seen = side == 1 && after[j] == u;
      for (int k = 0; k < j && !seen; ++k) seen = after[k] == u || before[k] == u;
      if (seen) continue;
      int ridge = 0;
      tc_sf_edge(u, after, before, 0, normal, fn, eps_r, &ridge);
      ridges += ridge;
    }
  if (ridges == 2) return TCC_RIDGEV;
  if (ridges != 0) return TCC_CORNER;
  for (int i = 0; i < fn; ++i)
    for (int j = i + 1; j < fn; ++j)
      if (1.0 - tc_sf_dot(normal[i], normal[j]) > eps_f) return TCC_CORNER;
  /* one closed fan: following before -> the unique face whose `after` equals it runs through
   * all fn faces and closes (the walk's result does not depend on the start) */
  int cur = 0;
  for (int step = 1; step <= fn; ++step) {
    int want = before[cur], next = -1, found = 0;
    for (int j = 0; j < fn; ++j)
      if (after[j] == want) {
        next = j;
        ++found;
      }
    if (found != 1) return TCC_CORNER;
    cur = next;
    if (cur == 0 && step != fn) return TCC_CORNER;
  }
  return cur == 0 ? TCC_FACE : TCC_CORNER;
}

#ifndef __OPENCL_C_VERSION__
}  // namespace tc::geo
#endif

#endif
