/* Stage 3 of a collapse iteration: the admissible filter over marked edges (paper Sec. 3.2).
 *
 * Checks, cheapest first; the first that fails is recorded in reason[e]:
 *   Q       boundary protection by mode (strict / features / free), which also decides the
 *           survivor and the placement (edge_dir, see collapse_common.h);
 *   link    the link condition of Dey et al. for 3-manifolds with boundary, the boundary closed
 *           by a virtual vertex w joined to every S-face (boundary and material interfaces):
 *           (i)   every common neighbour of a and b is a vertex of lk(ab), and if a and b are
 *                 both on S, ab is an S-edge (w is in lk(a) and lk(b));
 *           (ii)  for triangles (a,c,d) and (b,c,d) the tet (a,b,c,d) exists; for S-edges
 *                 (a,c) and (b,c) the triangle (a,b,c) is an S-face;
 *           (iii) no tets (a,c,d,e) and (b,c,d,e); no S-faces (a,c,d) and (b,c,d);
 *   volume  every tet of ring(a) U ring(b) that survives, with the moved vertex at the placement,
 *           has a volume of at least eps_v.
 * Lists larger than TCC_MAX_LINK refuse the edge (conservative; never reached on real meshes). */
#include "collapse_common.h"

#ifndef TCC_MAX_LINK
#define TCC_MAX_LINK 96
#endif

inline int tcc_in(const int* list, int n, int x) {
  for (int i = 0; i < n; ++i)
    if (list[i] == x) return 1;
  return 0;
}

/* Does some tet of ring(x) contain y and z (and w when w >= 0)? */
inline int tcc_ring_has(__global const int* tets, __global const uint* vt_off, __global const int* vt, int x, int y,
                        int z, int w) {
  for (uint i = vt_off[x]; i < vt_off[x + 1]; ++i) {
    int t = vt[i];
    if (tcc_has(tets, t, y) && tcc_has(tets, t, z) && (w < 0 || tcc_has(tets, t, w))) return 1;
  }
  return 0;
}

/* Predicate Q; returns the edge_dir bits, or -1 to refuse. a < b. */
inline int tcc_predicate_q(int a, int b, uint fa, uint fb, uint fe, int ca, int cb, int mode, int paper_rule) {
  const int keep_a = TCC_DIR_REMOVE_V1, keep_b = 0;
  const int sa = fa != 0u, sb = fb != 0u, se = (fe & (TCC_BOUNDARY | TCC_INTERFACE)) != 0u;
  if (mode == TCC_FREE) return TCC_DIR_MIDPOINT | keep_a;
  if (mode == TCC_STRICT) {
    if (sa && sb) return -1;
    if (sa || sb) return paper_rule ? -1 : (sa ? keep_a : keep_b);
    return TCC_DIR_MIDPOINT | keep_a;
  }
  /* features */
  if (sa && sb && !se) return -1;               /* would pinch two sheets of S together */
  if (paper_rule && (sa || sb) && !se) return -1; /* the paper: no interior edge touching S */
  if (ca == cb) {
    if (ca == TCC_CORNER) return -1;
    if (ca == TCC_RIDGEV && !(fe & TCC_RIDGE)) return -1;
    return TCC_DIR_MIDPOINT | keep_a; /* equal ranks: midpoint, survivor = lower index */
  }
  int removed_class = ca < cb ? ca : cb;
  if (removed_class == TCC_FACE && !se) return -1;
  if (removed_class == TCC_RIDGEV && !(fe & TCC_RIDGE)) return -1;
  return ca > cb ? keep_a : keep_b;
}

__kernel void admissible(uint ne, __global const int* edges, __global const uint* marked, __global const int* tets,
                         __global const uint* vt_off, __global const int* vt, __global const uint* nb_off,
                         __global const int* nb, __global const int* nb_edge, __global const int* labels,
                         int use_labels, __global const double* pts, __global const uchar* vflags,
                         __global const uchar* vclass, __global const uchar* eflags, int mode, int paper_rule,
                         double eps_v, __global uint* adm, __global uchar* edge_dir, __global uchar* reason,
                         __global uint* counters) {
  uint e = get_global_id(0);
  if (e >= ne) return;
  adm[e] = 0u;
  edge_dir[e] = 0;
  if (!marked[e]) {
    reason[e] = TCC_NOT_MARKED;
    return;
  }
  int a = edges[2 * e], b = edges[2 * e + 1];
  uint fa = vflags[a], fb = vflags[b], fe = eflags[e];

  /* --- Q --- */
  int dir = tcc_predicate_q(a, b, fa, fb, fe, vclass[a], vclass[b], mode, paper_rule);
  if (dir < 0) {
    reason[e] = TCC_REFUSED_Q;
    return;
  }

  /* --- link condition --- */
  int cn[TCC_MAX_LINK], pc[TCC_MAX_LINK], pd[TCC_MAX_LINK];
  int ncn = 0, np = 0;
  {
    uint i = nb_off[a], ie = nb_off[a + 1], j = nb_off[b], je = nb_off[b + 1];
    while (i < ie && j < je) {
      int x = nb[i], y = nb[j];
      if (x < y) ++i;
      else if (y < x) ++j;
      else {
        if (ncn == TCC_MAX_LINK) {
          reason[e] = TCC_REFUSED_LINK;
          return;
        }
        cn[ncn++] = x;
        ++i;
        ++j;
      }
    }
  }
  for (uint i = vt_off[a]; i < vt_off[a + 1]; ++i) {
    int t = vt[i];
    if (!tcc_has(tets, t, b)) continue;
    if (np == TCC_MAX_LINK) {
      reason[e] = TCC_REFUSED_LINK;
      return;
    }
    __global const int* q = tets + 4 * t;
    int o[2], no = 0;
    for (int k = 0; k < 4; ++k)
      if (q[k] != a && q[k] != b) o[no++] = q[k];
    pc[np] = o[0];
    pd[np] = o[1];
    ++np;
  }
  int ok = 1;
  /* (i) vertices, and w */
  for (int k = 0; k < ncn && ok; ++k)
    if (!tcc_in(pc, np, cn[k]) && !tcc_in(pd, np, cn[k])) ok = 0;
  const uint smask = TCC_BOUNDARY | TCC_INTERFACE;
  if (ok && (fa & smask) && (fb & smask) && !(fe & smask)) ok = 0;
  /* (ii) with w: S-edges (a,c) and (b,c) need the S-face (a,b,c) */
  for (int k = 0; k < ncn && ok; ++k) {
    int c = cn[k];
    if (!(vflags[c] & smask)) continue;
    int eac = tcc_edge_id(nb_off, nb, nb_edge, a, c), ebc = tcc_edge_id(nb_off, nb, nb_edge, b, c);
    if (eac < 0 || ebc < 0) continue;
    if ((eflags[eac] & smask) && (eflags[ebc] & smask) &&
        !tcc_triangle_kind(tets, vt_off, vt, labels, use_labels, a, b, c))
      ok = 0;
  }
  /* (ii) triangles and (iii) tets and S-faces, from the tets of ring(a) without b */
  for (uint i = vt_off[a]; i < vt_off[a + 1] && ok; ++i) {
    int t = vt[i];
    if (tcc_has(tets, t, b)) continue;
    __global const int* q = tets + 4 * t;
    int o[3], no = 0;
    for (int k = 0; k < 4; ++k)
      if (q[k] != a) o[no++] = q[k];
    int in0 = tcc_in(cn, ncn, o[0]), in1 = tcc_in(cn, ncn, o[1]), in2 = tcc_in(cn, ncn, o[2]);
    if (in0 && in1 && in2 && tcc_ring_has(tets, vt_off, vt, b, o[0], o[1], o[2])) {
      ok = 0; /* tets (a,c,d,e) and (b,c,d,e) */
      break;
    }
    const int pairs[3][2] = {{0, 1}, {0, 2}, {1, 2}};
    const int inside[3] = {in0, in1, in2};
    for (int k = 0; k < 3 && ok; ++k) {
      if (!inside[pairs[k][0]] || !inside[pairs[k][1]]) continue;
      int c = o[pairs[k][0]], d = o[pairs[k][1]];
      if (!tcc_ring_has(tets, vt_off, vt, b, c, d, -1)) continue; /* (b,c,d) is no triangle */
      int in_lk = 0;
      for (int m = 0; m < np; ++m)
        if ((pc[m] == c && pd[m] == d) || (pc[m] == d && pd[m] == c)) in_lk = 1;
      if (!in_lk) {
        ok = 0;
        break;
      }
      if (tcc_triangle_kind(tets, vt_off, vt, labels, use_labels, a, c, d) &&
          tcc_triangle_kind(tets, vt_off, vt, labels, use_labels, b, c, d))
        ok = 0;
    }
  }
  if (!ok) {
    reason[e] = TCC_REFUSED_LINK;
    return;
  }

  /* --- volumes after the tentative collapse --- */
  double3 p = tcc_placement(pts, a, b, (uint)dir);
  double3 pa = tc_point(pts, a), pb = tc_point(pts, b);
  for (int side = 0; side < 2; ++side) {
    int x = side == 0 ? a : b, y = side == 0 ? b : a;
    double3 px = side == 0 ? pa : pb;
    if (px.x == p.x && px.y == p.y && px.z == p.z) continue; /* x does not move: its tets keep their shape */
    for (uint i = vt_off[x]; i < vt_off[x + 1]; ++i) {
      int t = vt[i];
      if (tcc_has(tets, t, y)) continue; /* removed by the collapse */
      __global const int* q = tets + 4 * t;
      double3 c[4];
      for (int k = 0; k < 4; ++k) c[k] = q[k] == x ? p : tc_point(pts, q[k]);
      if (!(tc_tet_volume(c[0], c[1], c[2], c[3]) >= eps_v)) {
        reason[e] = TCC_REFUSED_VOLUME;
        return;
      }
    }
  }
  adm[e] = 1u;
  edge_dir[e] = (uchar)dir;
  reason[e] = TCC_OK;
  atomic_inc(&counters[1]);
}
