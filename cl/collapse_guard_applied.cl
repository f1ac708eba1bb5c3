/* The surface guard of the matching selection (SurfaceGuard::run_applied): its collapses are
 * applied as it takes them, so the guard tests the result. A query is a taken collapse whose
 * survivor is on S; its triangles are the S faces through the survivor (sguard_applied_*); the
 * S faces of the result and the pairs are tested by the kernels of collapse_guard.cl
 * (sguard_surface, sguard_pairs, each pair once); the refused queries' edges are listed
 * (sguard_refused_list) for the undo, and the next run tests only the queries near what the
 * undo changed (sguard_undone_boxes, sguard_requery). */

#include "collapse_guard.h"

/* The faces each tet of the result owns on S (tcc_owned_sface over tet_nbr as glued): smask and
 * owns_s as conn_vertex_flags_faces writes them for a connectivity; 0 for the removed tets. */
__kernel void sguard_applied_smask(uint nt, __global const int* tet_nbr, __global const int* labels, int use_labels,
                                   __global const uchar* tets_are_dead, __global uint* owns_s, __global uchar* smask) {
  uint t = get_global_id(0);
  if (t >= nt) return;
  uint mask = 0;
  for (int f = 0; f < 4 && !tets_are_dead[t]; ++f) {
    uint on_s;
    if (tcc_owned_sface(tet_nbr, labels, use_labels, (int)t, f, &on_s)) mask |= 1u << f;
  }
  smask[t] = (uchar)mask;
  owns_s[t] = mask != 0u;
}

/* Loop over the S faces of the result through the survivor x of the collapse of y onto x: the
 * faces through x of the tets of ring(x) U ring(y) that are left (the two rings share only the
 * removed tets). The body (the variadic rest) sees the tet t_ and the face f_
 * (sguard_applied_queries counts them, sguard_applied_tris writes them: one selection for both). */
#define TCC_SG_FOR_APPLIED_FACES(x, y, ...)                 \
  for (int side_ = 0; side_ < 2; ++side_) {                 \
    int z_ = side_ == 0 ? (x) : (y);                        \
    for (uint i_ = vt_off[z_]; i_ < vt_off[z_ + 1]; ++i_) { \
      int t_ = vt[i_];                                      \
      uint m_ = smask[t_];                                  \
      if (tets_are_dead[t_] || !m_) continue;               \
      int l_ = tcc_local(tets, t_, (x));                    \
      for (int f_ = 0; f_ < 4; ++f_) {                      \
        if (f_ == l_ || !(m_ & (1u << f_))) continue;       \
        __VA_ARGS__                                         \
      }                                                     \
    }                                                       \
  }
/* The same with each face's vertices: the body sees id[3] and pos[3]. */
#define TCC_SG_FOR_APPLIED_TRIS(x, y, id, pos, ...)                                                     \
  TCC_SG_FOR_APPLIED_FACES(x, y, {                                                                       \
    for (int k_ = 0; k_ < 3; ++k_) {                                                                     \
      id[k_] = tets[4 * t_ + TC_TET_FACES[f_][k_]];                                                      \
      pos[k_] = tc_point(pts, id[k_]);                                                                   \
    }                                                                                                    \
    __VA_ARGS__                                                                                          \
  })

/* The applied collapse of edge e: x survives, y was removed. */
inline void tcc_sg_applied(int e, __global const int* edges, __global const uchar* edges2dir, int* x, int* y) {
  uint d = edges2dir[e];
  *x = (d & TCC_DIR_REMOVE_V1) ? edges[2 * e] : edges[2 * e + 1];
  *y = (d & TCC_DIR_REMOVE_V1) ? edges[2 * e + 1] : edges[2 * e];
}

/* Queries of the matching selection: the taken collapses whose survivor is on S, with the number
 * of the S faces through it now (sguard_applied_tris writes them and the box). */
__kernel void sguard_applied_queries(uint ne, __global const int* edges, __global const uint* edges_are_final,
                                     __global const uchar* edges2dir, __global const int* tets,
                                     __global const uint* vt_off, __global const int* vt,
                                     __global const uchar* tets_are_dead, __global const uchar* smask,
                                     __global const uchar* vflags, __global int* qedge, __global uint* qntri,
                                     __global uint* qcount, int only_flagged, __global const uchar* requery,
                                     __global int* verts2query) {
  uint e = get_global_id(0);
  if (e >= ne || !edges_are_final[e] || (only_flagged && !requery[e])) return;
  int x, y;
  tcc_sg_applied((int)e, edges, edges2dir, &x, &y);
  if (!vflags[x] && !vflags[y]) return; /* S is not touched */
  uint n = 0; /* without their points */
  TCC_SG_FOR_APPLIED_FACES(x, y, { ++n; })
  if (n == 0) return;
  uint slot = atomic_inc(qcount);
  qedge[slot] = (int)e;
  qntri[slot] = n;
  verts2query[x] = (int)slot; /* a vertex survives one collapse at most */
}

/* The S faces through the survivor of each query of sguard_applied_queries, at qoff[q] ..
 * qoff[q + 1], and the query's box; qrep: the survivor (the faces through it are the query's
 * own). */
__kernel void sguard_applied_tris(uint nq, __global const int* qedge, __global const uint* qoff,
                                  __global const int* edges, __global const uchar* edges2dir,
                                  __global const double* pts, __global const int* tets, __global const uint* vt_off,
                                  __global const int* vt, __global const uchar* tets_are_dead,
                                  __global const uchar* smask, __global int* tid, __global double* tpos,
                                  __global double* tbox, __global double* tplane, __global int* qrep,
                                  __global const int* verts2query, __global int* tmin, __global double* qbox) {
  uint qi = get_global_id(0);
  if (qi >= nq) return;
  int x, y;
  tcc_sg_applied(qedge[qi], edges, edges2dir, &x, &y);
  qrep[2 * qi] = x;
  qrep[2 * qi + 1] = -1;
  uint n = qoff[qi];
  int id[3];
  double3 pos[3];
  double3 lo = (double3)(INFINITY, INFINITY, INFINITY), hi = -lo;
  TCC_SG_FOR_APPLIED_TRIS(x, y, id, pos, {
    tcc_sg_store_tri(n, id, pos, tid, tpos, tbox, tplane);
    tmin[n] = tcc_sg_first_survivor(id, verts2query);
    ++n;
    for (int k = 0; k < 3; ++k) {
      lo = fmin(lo, pos[k]);
      hi = fmax(hi, pos[k]);
    }
  })
  __global double* b = qbox + 6 * qi;
  b[0] = lo.x, b[1] = lo.y, b[2] = lo.z, b[3] = hi.x, b[4] = hi.y, b[5] = hi.z;
}

/* The refused queries' edges (qbad), flagged and listed, for the matching selection's undo. */
__kernel void sguard_refused_list(uint nq, __global const int* qedge, __global const uint* qbad,
                                  __global uchar* flag, __global uint* list, __global uint* count) {
  uint q = get_global_id(0);
  if (q >= nq || !qbad[q]) return;
  flag[qedge[q]] = 1;
  list[atomic_inc(count)] = (uint)qedge[q];
}

/* After the matching selection undid collapses (match_undo), the faces whose shape or
 * neighbours changed since the last run are those through the end points of an undone
 * collapse: they lie in the box of N[a] U N[b] (positions now; a removed vertex at its
 * survivor's). Every pair of S faces that no run tested holds such a face and, unless both
 * are faces of the iteration's start, the survivor of a collapse still taken whose query box
 * (its new triangles') then meets that box: the next run needs only those queries
 * (sguard_requery flags them, sguard_applied_queries with only_flagged). */
__kernel void sguard_undone_boxes(uint n, __global const uint* undone, __global const int* edges,
                                  __global const uchar* edges2dir, __global const uint* nb_off, __global const int* nb,
                                  __global const int* verts2collapse, __global const double* pts,
                                  __global double* boxes) {
  uint i = get_global_id(0);
  if (i >= n) return;
  const int g = (int)undone[i];
  double3 lo = (double3)(INFINITY, INFINITY, INFINITY), hi = -lo;
  for (int s = 0; s < 2; ++s) {
    const int x = edges[2 * g + s];
    for (uint j = nb_off[x]; j <= nb_off[x + 1]; ++j) { /* N(x), then x */
      int z = j == nb_off[x + 1] ? x : nb[j];
      const int h = verts2collapse[z];
      if (h >= 0) { /* an end point of a collapse still taken: where its survivor is */
        const uint d = edges2dir[h];
        z = (d & TCC_DIR_REMOVE_V1) ? edges[2 * h] : edges[2 * h + 1];
      }
      const double3 p = tc_point(pts, z);
      lo = fmin(lo, p);
      hi = fmax(hi, p);
    }
  }
  vstore3(lo, 2 * i, boxes);
  vstore3(hi, 2 * i + 1, boxes);
}

/* The last run's queries whose box meets one of the nu boxes of sguard_undone_boxes: their
 * edges flagged in requery (a loop over the boxes: they are few). */
__kernel void sguard_requery(uint nq, __global const int* qedge, __global const double* qbox, uint nu,
                             __global const double* boxes, __global uchar* requery) {
  uint q = get_global_id(0);
  if (q >= nq) return;
  __global const double* b = qbox + 6 * q;
  const double3 lo = (double3)(b[0], b[1], b[2]), hi = (double3)(b[3], b[4], b[5]);
  for (uint i = 0; i < nu; ++i)
    if (!tcc_sg_box_apart(lo, hi, boxes + 6 * i)) { /* vstore3(lo, 2 i), vstore3(hi, 2 i + 1) */
      requery[qedge[q]] = 1;
      return;
    }
}
