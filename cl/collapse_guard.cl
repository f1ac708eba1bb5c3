/* Surface guard: after the conflict passes, refuse the chosen collapses that would make the
 * feature surface S (boundary and material interfaces) intersect itself.
 *
 * Why a global test: the admissible filter only looks at the stars of a and b. A collapse that
 * moves S within the paper's tolerances (a face vertex removed from a slightly curved face,
 * a ridge vertex cut off a curved ridge) moves the surface by up to the sagitta of the patch,
 * and a part of S that is not in the star (the other side of a narrow gap: another body, the
 * far wall of a thin slot, a boss standing in a hole) may lie within that distance. Nothing
 * local sees it; the tets stay positive. (Found on corpus mesh cad_052: a ridge vertex on the
 * rim of a hole (radius 0.09), collapsed onto its neighbour, made the rim its chord, and the
 * chord cut through the wall of a boss standing in the hole, a thin crescent of void away.)
 *
 * Per iteration, over the collapses chosen by the conflict passes (fin):
 *   sguard_queries    a collapse that changes S (removed vertex x on S, or a survivor y on S
 *                     that moves to the midpoint) is a query: the bounding box of its new
 *                     S triangles (below); the host grids the boxes;
 *   sguard_tris       the new S triangles of each query with their boxes (the filter read
 *                     before a triangle pair is tested), and the vertices whose faces the
 *                     query replaces (x, and y when it moves);
 *   sguard_vertex_cells  the grid cell of every vertex (a face's cells lie between its
 *                     vertices' cells);
 *   sguard_surface    every S face of the current mesh that is not replaced by the query is
 *                     tested against the query's new triangles (over the tets owning S faces,
 *                     their faces from smask, through the grid; a face in cells without a
 *                     query is passed over before its points are read);
 *   sguard_pairs      the new triangles of two queries are tested against each other (two
 *                     collapses of one iteration never share a tet, but their new triangles
 *                     may still cross), and those of one query among themselves (a fold of
 *                     S around the survivor that positive tets do not exclude);
 *   sguard_drop       a query with a hit is unmarked; the host then selects again.
 * The new S triangles of the collapse of x onto y (y at the placement p): the faces containing
 * x of the tets of ring(x) that survive, and, when y moves, the faces containing y of ring(y),
 * with x renamed y; a face is taken when it is on S now, or when the tet across it is removed
 * by the collapse and the face it is glued to through that tet is on the boundary or the two
 * tets' labels differ. The current S faces are tested in their current places, also those that
 * another chosen collapse moves (whose new triangles are tested too): that only refuses more.
 * The triangle test: cl/collapse_guard_geometry.h (floating point with a tolerance: rounding
 * never hides a contact).
 */
#include "collapse_common.h"
#include "collapse_guard_geometry.h"

/* The collapse of edge e as chosen: x removed, y survives at *p; returns whether y moves. */
inline int tcc_sg_collapse(int e, __global const int* edges, __global const uchar* dir, __global const double* pts,
                           __global const double* vfield, uint vfield_stride, int* x, int* y, double3* p) {
  int v0 = edges[2 * e], v1 = edges[2 * e + 1];
  uint d = dir[e];
  *x = (d & TCC_DIR_REMOVE_V1) ? v1 : v0;
  *y = (d & TCC_DIR_REMOVE_V1) ? v0 : v1;
  *p = tcc_placement(pts, vfield, vfield_stride, v0, v1, d);
  double3 py = tc_point(pts, *y);
  return !(py.x == p->x && py.y == p->y && py.z == p->z);
}

/* Is face f of tet t (found in ring(x) when side == 0, ring(y) when side == 1) a new S
 * triangle of the collapse of x onto y (see the top)? Fills its vertex ids (x renamed y) and
 * positions (y at p). A face glued to another one through a removed tet o is S after the
 * collapse when the face of o it is glued to is on the boundary or the two tets' labels
 * differ. */
inline int tcc_sg_new_tri(int t, int f, int side, int x, int y, int moves_y, double3 p, __global const int* tets,
                          __global const int* tet_nbr, __global const int* labels, int use_labels,
                          __global const double* pts, int* id, double3* pos, double3* old, int* is_glued) {
  __global const int* q = tets + 4 * t;
  int z = side == 0 ? x : y;
  if (q[f] == z) return 0; /* the face opposite z does not contain it */
  int other = tet_nbr[4 * t + f];
  int glued = other >= 0 && tcc_has(tets, other, x) && tcc_has(tets, other, y);
  if (glued) { /* through the removed tet o = other */
    int across = tet_nbr[4 * other + tcc_local(tets, other, z)];
    if (!(across < 0 || (use_labels && labels[t] != labels[across]))) return 0; /* interior after */
  } else {
    if (side == 1 && !moves_y) return 0; /* unchanged */
    if (!(other < 0 || (use_labels && labels[t] != labels[other]))) return 0; /* interior */
  }
  for (int k = 0; k < 3; ++k) {
    int v = q[TC_TET_FACES[f][k]];
    old[k] = tc_point(pts, v);
    if (v == x) v = y;
    id[k] = v;
    pos[k] = v == y ? p : old[k];
  }
  *is_glued = glued;
  return 1;
}

/* Loop over the new S triangles of a collapse: BODY sees id[3], pos[3], the positions before
 * old_[3] and glued_. */
#define TCC_SG_FOR_NEW_TRIS(x, y, moves_y, p, id, pos, BODY)                                               \
  for (int side_ = 0, glued_ = 0; side_ < 2; ++side_) {                                                   \
    int z_ = side_ == 0 ? (x) : (y);                                                                        \
    double3 old_[3];                                                                                        \
    for (uint i_ = vt_off[z_]; i_ < vt_off[z_ + 1]; ++i_) {                                                 \
      int t_ = vt[i_];                                                                                      \
      if (tcc_has(tets, t_, side_ == 0 ? (y) : (x))) continue; /* removed, or seen from ring(x) */         \
      for (int f_ = 0; f_ < 4; ++f_) {                                                                      \
        if (!tcc_sg_new_tri(t_, f_, side_, (x), (y), (moves_y), (p), tets, tet_nbr, labels, use_labels, pts, \
                            id, pos, old_, &glued_))                                                        \
          continue;                                                                                         \
        BODY                                                                                                \
      }                                                                                                     \
    }                                                                                                       \
  }

/* Queries: the chosen collapses that change S, with the box and the number of their new S
 * triangles. */
__kernel void sguard_queries(uint ne, __global const int* edges, __global const uint* fin, __global const uchar* dir,
                             __global const double* pts, __global const double* vfield, uint vfield_stride,
                             __global const int* tets, __global const uint* vt_off,
                             __global const int* vt, __global const int* tet_nbr, __global const int* labels,
                             int use_labels, __global const uchar* vflags, __global int* qedge,
                             __global double* qbox, __global uint* qntri, __global uint* qcount) {
  uint e = get_global_id(0);
  if (e >= ne || !fin[e]) return;
  int x, y;
  double3 p;
  int moves_y = tcc_sg_collapse((int)e, edges, dir, pts, vfield, vfield_stride, &x, &y, &p);
  if (!vflags[x] && !(moves_y && vflags[y])) return; /* S is not touched */
  double3 lo = (double3)(INFINITY, INFINITY, INFINITY), hi = -lo;
  int id[3];
  uint n = 0;
  double3 pos[3];
  /* flat: every triangle before and after in one plane (that of the first, up to 1e-13 of its
   * size), none glued */
  int flat = 1;
  double3 pn = (double3)(0.0, 0.0, 0.0), po = pn;
  double ptol = 0.0;
  TCC_SG_FOR_NEW_TRIS(x, y, moves_y, p, id, pos, {
    if (n == 0) {
      pn = tcc_cross(old_[1] - old_[0], old_[2] - old_[0]);
      po = old_[0];
      double3 e = old_[1] - old_[0];
      ptol = 1e-13 * sqrt(tcc_dot(e, e)) * sqrt(tcc_dot(pn, pn));
    }
    ++n;
    flat &= !glued_ && ptol > 0.0;
    for (int k = 0; k < 3; ++k) {
      flat &= fabs(tcc_dot(pn, old_[k] - po)) <= ptol && fabs(tcc_dot(pn, pos[k] - po)) <= ptol;
      lo = fmin(lo, pos[k]);
      hi = fmax(hi, pos[k]);
    }
  })
  /* A flat collapse re-triangulates a planar disk of S with its boundary polygon fixed (the
   * triangles keep their orientation, being faces of positive tets): S does not change as a
   * point set, and nothing can cross it. The usual case on the flat faces of CAD models. */
  if (n == 0 || flat) return;
  uint slot = atomic_inc(qcount);
  qedge[slot] = (int)e;
  qntri[slot] = n;
  __global double* b = qbox + 6 * slot;
  b[0] = lo.x, b[1] = lo.y, b[2] = lo.z, b[3] = hi.x, b[4] = hi.y, b[5] = hi.z;
}

/* --- The guard of the matching selection (collapse_matching.cl), whose collapses are applied to
 * the mesh (tets renamed, tdead, tet_nbr glued, survivors placed) and may share tets: it tests
 * the result. Every S face of the result that a collapse changed holds the survivor x of that
 * collapse (renamed from the removed vertex y, moved with x, or glued across a removed tet), so
 * a query is a collapse whose survivor is on S, with as new triangles all S faces through x
 * now; the sweep (sguard_surface) is over the S faces of the result (sguard_applied_smask) and
 * skips those through x, which are the query's own (sguard_pairs tests them among themselves).
 * Every pair of faces of the result that was not a pair before has a face of a query, so
 * nothing that crosses is missed. --- */

/* The faces each tet of the result owns on S (tcc_owned_sface over tet_nbr as glued): smask and
 * owns_s as conn_vertex_flags_faces writes them for a connectivity; 0 for the removed tets. */
__kernel void sguard_applied_smask(uint nt, __global const int* tet_nbr, __global const int* labels, int use_labels,
                                   __global const uchar* tdead, __global uint* owns_s, __global uchar* smask) {
  uint t = get_global_id(0);
  if (t >= nt) return;
  uint mask = 0;
  for (int f = 0; f < 4 && !tdead[t]; ++f) {
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
#define TCC_SG_FOR_APPLIED_FACES(x, y, ...)                                                             \
  for (int side_ = 0; side_ < 2; ++side_) {                                                              \
    int z_ = side_ == 0 ? (x) : (y);                                                                     \
    for (uint i_ = vt_off[z_]; i_ < vt_off[z_ + 1]; ++i_) {                                              \
      int t_ = vt[i_];                                                                                   \
      uint m_ = smask[t_];                                                                               \
      if (tdead[t_] || !m_) continue;                                                                    \
      int l_ = tcc_local(tets, t_, (x));                                                                 \
      for (int f_ = 0; f_ < 4; ++f_) {                                                                   \
        if (f_ == l_ || !(m_ & (1u << f_))) continue;                                                    \
        __VA_ARGS__                                                                                      \
      }                                                                                                  \
    }                                                                                                    \
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
inline void tcc_sg_applied(int e, __global const int* edges, __global const uchar* dir, int* x, int* y) {
  uint d = dir[e];
  *x = (d & TCC_DIR_REMOVE_V1) ? edges[2 * e] : edges[2 * e + 1];
  *y = (d & TCC_DIR_REMOVE_V1) ? edges[2 * e + 1] : edges[2 * e];
}

/* Queries of the matching selection: the taken collapses whose survivor is on S, with the number
 * of the S faces through it now (sguard_applied_tris writes them and the box). */
__kernel void sguard_applied_queries(uint ne, __global const int* edges, __global const uint* fin,
                                     __global const uchar* dir, __global const int* tets,
                                     __global const uint* vt_off, __global const int* vt, __global const uchar* tdead,
                                     __global const uchar* smask, __global const uchar* vflags, __global int* qedge,
                                     __global uint* qntri, __global uint* qcount, int only_flagged,
                                     __global const uchar* requery, __global int* qof) {
  uint e = get_global_id(0);
  if (e >= ne || !fin[e] || (only_flagged && !requery[e])) return;
  int x, y;
  tcc_sg_applied((int)e, edges, dir, &x, &y);
  if (!vflags[x] && !vflags[y]) return; /* S is not touched */
  uint n = 0; /* without their points */
  TCC_SG_FOR_APPLIED_FACES(x, y, { ++n; })
  if (n == 0) return;
  uint slot = atomic_inc(qcount);
  qedge[slot] = (int)e;
  qntri[slot] = n;
  qof[x] = (int)slot; /* a vertex survives one collapse at most */
}

/* The plane data (tc_sg_plane) of new triangle n in tplane (5 doubles each). */
inline void tcc_sg_store_plane(__global double* tplane, uint n, tc_sg_plane q) {
  __global double* d = tplane + 5 * n;
  d[0] = q.n.x, d[1] = q.n.y, d[2] = q.n.z, d[3] = q.ln, d[4] = q.e2;
}
inline tc_sg_plane tcc_sg_load_plane(__global const double* tplane, uint n) {
  __global const double* d = tplane + 5 * n;
  tc_sg_plane q;
  q.n = (double3)(d[0], d[1], d[2]);
  q.ln = d[3];
  q.e2 = d[4];
  return q;
}

/* Triangle n of a query: ids, positions, box and plane (sguard_tris, sguard_applied_tris). */
inline void tcc_sg_store_tri(uint n, const int* id, const double3* pos, __global int* tid, __global double* tpos,
                             __global double* tbox, __global double* tplane) {
  for (int k = 0; k < 3; ++k) {
    tid[3 * n + k] = id[k];
    tpos[9 * n + 3 * k] = pos[k].x;
    tpos[9 * n + 3 * k + 1] = pos[k].y;
    tpos[9 * n + 3 * k + 2] = pos[k].z;
  }
  vstore3(fmin(fmin(pos[0], pos[1]), pos[2]), 2 * n, tbox);
  vstore3(fmax(fmax(pos[0], pos[1]), pos[2]), 2 * n + 1, tbox);
  tcc_sg_store_plane(tplane, n, tc_sg_plane_of(pos));
}

/* The new S triangles of each query, at qoff[q] .. qoff[q + 1] (ids, positions, boxes and
 * planes). */
__kernel void sguard_tris(uint nq, __global const int* qedge, __global const uint* qoff, __global const int* edges,
                          __global const uchar* dir, __global const double* pts, __global const double* vfield,
                          uint vfield_stride, __global const int* tets, __global const uint* vt_off,
                          __global const int* vt, __global const int* tet_nbr, __global const int* labels,
                          int use_labels, __global int* tid, __global double* tpos,
                          __global double* tbox, __global double* tplane, __global int* qrep) {
  uint qi = get_global_id(0);
  if (qi >= nq) return;
  int x, y;
  double3 p;
  int moves_y = tcc_sg_collapse(qedge[qi], edges, dir, pts, vfield, vfield_stride, &x, &y, &p);
  qrep[2 * qi] = x;
  qrep[2 * qi + 1] = moves_y ? y : -1;
  uint n = qoff[qi];
  int id[3];
  double3 pos[3];
  TCC_SG_FOR_NEW_TRIS(x, y, moves_y, p, id, pos, {
    tcc_sg_store_tri(n, id, pos, tid, tpos, tbox, tplane);
    ++n;
  })
}

/* Each pair of S faces of the result is tested once (sguard_surface and sguard_pairs with
 * `dedup`, the matching selection's runs). Without it, a pair (A, B) is tested for every query
 * q whose survivor x_q is a vertex of A or B: by the sweep of A against q when x_q is in B
 * alone (and of B when in A alone), by sguard_pairs of q when in both; each refuses q on a
 * hit. With it, only for the query whose survivor has the lowest id of those (qof: the query of
 * each survivor of the run, -1 for other vertices; tmin: per triangle, the lowest survivor among
 * its vertices), and a hit refuses all of them (tcc_sg_refuse_all): the same refusals, fewer
 * pairs (most S faces of the result hold a survivor, so most pairs would be tested twice). */
inline int tcc_sg_first_survivor(const int* id, __global const int* qof) {
  int m = INT_MAX;
  for (int k = 0; k < 3; ++k)
    if (qof[id[k]] >= 0) m = min(m, id[k]);
  return m;
}
inline void tcc_sg_refuse_all(const int* ia, const int* ib, __global const int* qof, uint code,
                              volatile __global uint* qbad) {
  for (int k = 0; k < 6; ++k) {
    const int q = qof[k < 3 ? ia[k] : ib[k - 3]];
    if (q >= 0) atomic_max(qbad + q, code); /* the largest code whatever the order */
  }
}

/* The S faces through the survivor of each query of sguard_applied_queries, at qoff[q] ..
 * qoff[q + 1], and the query's box; qrep: the survivor (the faces through it are the query's
 * own). */
__kernel void sguard_applied_tris(uint nq, __global const int* qedge, __global const uint* qoff,
                                  __global const int* edges, __global const uchar* dir, __global const double* pts,
                                  __global const int* tets, __global const uint* vt_off, __global const int* vt,
                                  __global const uchar* tdead, __global const uchar* smask, __global int* tid,
                                  __global double* tpos, __global double* tbox, __global double* tplane,
                                  __global int* qrep, __global const int* qof, __global int* tmin,
                                  __global double* qbox) {
  uint qi = get_global_id(0);
  if (qi >= nq) return;
  int x, y;
  tcc_sg_applied(qedge[qi], edges, dir, &x, &y);
  qrep[2 * qi] = x;
  qrep[2 * qi + 1] = -1;
  uint n = qoff[qi];
  int id[3];
  double3 pos[3];
  double3 lo = (double3)(INFINITY, INFINITY, INFINITY), hi = -lo;
  TCC_SG_FOR_APPLIED_TRIS(x, y, id, pos, {
    tcc_sg_store_tri(n, id, pos, tid, tpos, tbox, tplane);
    tmin[n] = tcc_sg_first_survivor(id, qof);
    ++n;
    for (int k = 0; k < 3; ++k) {
      lo = fmin(lo, pos[k]);
      hi = fmax(hi, pos[k]);
    }
  })
  __global double* b = qbox + 6 * qi;
  b[0] = lo.x, b[1] = lo.y, b[2] = lo.z, b[3] = hi.x, b[4] = hi.y, b[5] = hi.z;
}

inline void tcc_sg_load_tri(__global const int* tid, __global const double* tpos, uint n, int* id, double3* pos) {
  for (int k = 0; k < 3; ++k) {
    id[k] = tid[3 * n + k];
    pos[k] = (double3)(tpos[9 * n + 3 * k], tpos[9 * n + 3 * k + 1], tpos[9 * n + 3 * k + 2]);
  }
}

/* The box of new triangle n, as sguard_tris stored it. */
inline void tcc_sg_load_box(__global const double* tbox, uint n, double3* lo, double3* hi) {
  *lo = vload3(2 * n, tbox);
  *hi = vload3(2 * n + 1, tbox);
}

/* Are the box [lo, hi] and the box b (6 doubles: its low corner, then its high corner) apart? */
inline int tcc_sg_box_apart(double3 lo, double3 hi, __global const double* b) {
  return lo.x > b[3] || lo.y > b[4] || lo.z > b[5] || b[0] > hi.x || b[1] > hi.y || b[2] > hi.z;
}

/* Are the box [lo, hi] and the box of new triangle n (tbox, written by sguard_tris) apart? The
 * filter before a triangle pair's test, read before the triangle itself. */
inline int tcc_sg_tri_box_apart(double3 lo, double3 hi, __global const double* tbox, uint n) {
  return tcc_sg_box_apart(lo, hi, tbox + 6 * n);
}

/* The uniform grid of the query boxes (built by the host): cell (i, j, k) of size 1 / ih from
 * org, dims gd; the entries of cell c are cell_q[cell_off[c] .. cell_off[c + 1]), 4 ints each:
 * the query, its x = qrep[2 q] (the survivor in run_applied), the cell of its box's low corner
 * packed as vcell's (i | j << 10 | k << 20), 0; each cell's by increasing x when the run tests
 * each pair once (sguard_surface's scan stops early), else by query. A product
 * by the inverse instead of a division (the host's cell_of does the same arithmetic, which
 * keeps every pair's owner cell among the cells both were entered in). */
inline int tcc_sg_cell(double v, double org, double ih, int n) {
  double c = floor((v - org) * ih);
  return c < 0.0 ? 0 : c >= (double)n ? n - 1 : (int)c;
}

/* Is (i, j, k) the cell holding the low corner of the overlap of boxes A and B (so each pair
 * is tested once)? Also tests the overlap. The cell of the overlap's low corner is, per axis,
 * the larger of the two boxes' low cells (the cell of a coordinate does not decrease with it):
 * A's are (i0, j0, k0), B's packed in bc (a grid entry's, the host's same arithmetic), so most
 * pairs met in another of their common cells are passed over before B's box is read. */
inline int tcc_sg_owner_cell(double3 alo, double3 ahi, int i0, int j0, int k0, uint bc, __global const double* b,
                             int i, int j, int k) {
  if (max(i0, (int)(bc & 0x3ffu)) != i || max(j0, (int)((bc >> 10) & 0x3ffu)) != j || max(k0, (int)(bc >> 20)) != k)
    return 0;
  return !tcc_sg_box_apart(alo, ahi, b);
}

/* Loop over the grid entries (cell_q) of the cells that the box [LO, HI] overlaps: the body (the
 * variadic rest, so that it may hold commas) sees the box's low cell (i0_, j0_, k0_), the cell
 * (ci, cj, ck) and the entry ITEM (`continue` goes to the next entry, `break` to the next
 * cell). Needs ox, oy, oz, ih, gx, gy, gz, cell_off and cell_q in scope. */
#define TCC_SG_FOR_CELL_ENTRIES(LO, HI, ITEM, ...)                                                            \
  {                                                                                                          \
    const int i0_ = tcc_sg_cell((LO).x, ox, ih, gx), i1_ = tcc_sg_cell((HI).x, ox, ih, gx);                  \
    const int j0_ = tcc_sg_cell((LO).y, oy, ih, gy), j1_ = tcc_sg_cell((HI).y, oy, ih, gy);                  \
    const int k0_ = tcc_sg_cell((LO).z, oz, ih, gz), k1_ = tcc_sg_cell((HI).z, oz, ih, gz);                  \
    for (int ck = k0_; ck <= k1_; ++ck)                                                                      \
      for (int cj = j0_; cj <= j1_; ++cj)                                                                    \
        for (int ci = i0_; ci <= i1_; ++ci) {                                                                \
          const uint c_ = ((uint)ck * (uint)gy + (uint)cj) * (uint)gx + (uint)ci;                            \
          for (uint m_ = cell_off[c_]; m_ < cell_off[c_ + 1]; ++m_) {                                        \
            const int4 ITEM = vload4(m_, cell_q);                                                            \
            __VA_ARGS__                                                                                      \
          }                                                                                                  \
        }                                                                                                    \
  }

/* The grid cell of every vertex, packed (i | j << 10 | k << 20; at most 1024 cells per axis): a
 * face's cells per axis run from the smallest to the largest of its vertices' (tcc_sg_cell does
 * not decrease with the coordinate), so sguard_surface finds the faces near no query from these
 * alone, without their points. */
__kernel void sguard_vertex_cells(uint nv, __global const double* pts, double ox, double oy, double oz, double ih,
                                  int gx, int gy, int gz, __global uint* vcell) {
  uint v = get_global_id(0);
  if (v >= nv) return;
  double3 p = tc_point(pts, v);
  vcell[v] = (uint)tcc_sg_cell(p.x, ox, ih, gx) | (uint)tcc_sg_cell(p.y, oy, ih, gy) << 10 |
             (uint)tcc_sg_cell(p.z, oz, ih, gz) << 20;
}

/* Is a query entered in a cell of the box of cells spanned by the packed cells a, b, c? */
inline int tcc_sg_cells_used(uint a, uint b, uint c, int gx, int gy, __global const uint* cell_off) {
  const uint m = 0x3ffu;
  const int i0 = min(min(a & m, b & m), c & m), i1 = max(max(a & m, b & m), c & m);
  const int j0 = min(min((a >> 10) & m, (b >> 10) & m), (c >> 10) & m), j1 = max(max((a >> 10) & m, (b >> 10) & m), (c >> 10) & m);
  const int k0 = min(min(a >> 20, b >> 20), c >> 20), k1 = max(max(a >> 20, b >> 20), c >> 20);
  for (int ck = k0; ck <= k1; ++ck)
    for (int cj = j0; cj <= j1; ++cj) {
      const uint row = ((uint)ck * (uint)gy + (uint)cj) * (uint)gx;
      if (cell_off[row + (uint)i0] != cell_off[row + (uint)i1 + 1]) return 1;
    }
  return 0;
}

/* The S face fid (fpos, box lo..hi; its plane fplane once *has_plane; code names it) against the
 * triangles of query qi (rx = qrep[2 qi], the survivor in run_applied, the removed vertex in run;
 * ry = qrep[2 qi + 1]: -1, or the survivor when it moves): unless the face has one of them (the
 * collapse moves or removes it), each triangle whose box meets the face's is tested; a hit
 * refuses qi (returns at once), or with dedup every query of the pair (tcc_sg_refuse_all), and
 * only the pairs whose lowest survivor is rx are tested. */
inline void tcc_sg_face_query(uint qi, int rx, const int* fid, const double3* fpos, double3 lo, double3 hi,
                              int* has_plane, tc_sg_plane* fplane, uint code, int dedup, __global const int* qrep,
                              __global const uint* qoff, __global const int* tid, __global const double* tpos,
                              __global const double* tbox, __global const double* tplane,
                              __global const int* qof, __global const int* tmin, __global uint* qbad) {
  const int ry = qrep[2 * qi + 1];
  if (fid[0] == rx || fid[1] == rx || fid[2] == rx || fid[0] == ry || fid[1] == ry || fid[2] == ry) return;
  for (uint r = qoff[qi]; r < qoff[qi + 1]; ++r) {
    if ((dedup && tmin[r] < rx) || tcc_sg_tri_box_apart(lo, hi, tbox, r)) continue;
    int id[3];
    double3 pos[3];
    tcc_sg_load_tri(tid, tpos, r, id, pos);
    if (!*has_plane) {
      *fplane = tc_sg_plane_of(fpos);
      *has_plane = 1;
    }
    if (!tc_sg_tri_tri_planes(id, pos, tcc_sg_load_plane(tplane, r), fid, fpos, *fplane)) continue;
    if (!dedup) {
      qbad[qi] = code;
      return;
    }
    tcc_sg_refuse_all(id, fid, qof, code, qbad); /* and on: the face's pairs with other triangles */
  }
}

/* Every current S face (smask: the faces a tet owns on S) against the queries whose box it
 * overlaps; a face in cells without queries (vcell) is passed over before its points are read.
 * With dedup a cell's scan stops at the first x at or above the face's lowest survivor (the face
 * has x, or the pairs are another query's). */
__kernel void sguard_surface(uint n, __global const uint* stets, __global const uchar* smask,
                             __global const uint* vcell, __global const double* pts,
                             __global const int* tets, __global const int* qrep, __global const double* qbox,
                             __global const uint* qoff, __global const int* tid, __global const double* tpos,
                             __global const double* tbox, __global const double* tplane, double ox, double oy, double oz,
                             double ih, int gx, int gy, int gz, __global const uint* cell_off,
                             __global const int* cell_q, __global uint* qbad, int dedup, __global const int* qof,
                             __global const int* tmin) {
  const uint g = get_global_id(0);
  if (g >= n) return;
  const uint t = stets[g];
  __global const int* tq = tets + 4 * t;
  const uint mask = smask[t];
  for (int f = 0; f < 4; ++f) {
    if (!(mask & (1u << f))) continue;
    int fid[3];
    for (int k = 0; k < 3; ++k) fid[k] = tq[TC_TET_FACES[f][k]];
    if (!tcc_sg_cells_used(vcell[fid[0]], vcell[fid[1]], vcell[fid[2]], gx, gy, cell_off)) continue;
    double3 fpos[3];
    for (int k = 0; k < 3; ++k) fpos[k] = tc_point(pts, fid[k]);
    double3 lo = fmin(fmin(fpos[0], fpos[1]), fpos[2]), hi = fmax(fmax(fpos[0], fpos[1]), fpos[2]);
    int has_plane = 0; /* the face's plane, computed at its first triangle test */
    tc_sg_plane fplane;
    const int flow = dedup ? tcc_sg_first_survivor(fid, qof) : INT_MAX; /* its lowest survivor */
    uint code = 4u * t + (uint)f; /* names the face for debugging; never 0 */
    code = code < 0x7ffffffeu ? code + 2u : 1u;
    TCC_SG_FOR_CELL_ENTRIES(lo, hi, item, {
      const uint qi = (uint)item.x;
      if (dedup) {
        if (flow <= item.y) break;
      } else if (qbad[qi] != 0u) {
        continue;
      }
      if (!tcc_sg_owner_cell(lo, hi, i0_, j0_, k0_, (uint)item.z, qbox + 6 * qi, ci, cj, ck)) continue;
      tcc_sg_face_query(qi, item.y, fid, fpos, lo, hi, &has_plane, &fplane, code, dedup, qrep, qoff, tid, tpos, tbox,
                        tplane, qof, tmin, qbad);
    })
  }
}

/* The new triangles of a query among themselves, and with cross (not for the matching
 * selection's queries: the sweep meets the other queries' triangles among the S faces of the
 * result) those of two queries against each other. */
__kernel void sguard_pairs(uint nq, __global const double* qbox, __global const uint* qoff, __global const int* tid,
                           __global const double* tpos, __global const double* tbox, __global const double* tplane,
                           double ox, double oy, double oz, double ih, int gx, int gy, int gz,
                           __global const uint* cell_off, __global const int* cell_q, __global uint* qbad, int cross, int dedup, __global const int* qrep, __global const int* qof,
                           __global const int* tmin) {
  uint qa = get_global_id(0);
  if (qa >= nq) return;
  __global const double* ba = qbox + 6 * qa;
  double3 lo = (double3)(ba[0], ba[1], ba[2]), hi = (double3)(ba[3], ba[4], ba[5]);
  /* the new triangles of the collapse among themselves (S folded over itself around y); dedup:
   * a pair with a lower survivor is that one's */
  const int x = dedup ? qrep[2 * qa] : 0;
  for (uint na = qoff[qa]; na < qoff[qa + 1]; ++na) {
    if (dedup && tmin[na] < x) continue;
    int ida[3];
    double3 posa[3];
    tcc_sg_load_tri(tid, tpos, na, ida, posa);
    const tc_sg_plane pla = tcc_sg_load_plane(tplane, na);
    double3 alo, ahi;
    tcc_sg_load_box(tbox, na, &alo, &ahi);
    for (uint nb = na + 1; nb < qoff[qa + 1]; ++nb) {
      if ((dedup && tmin[nb] < x) || tcc_sg_tri_box_apart(alo, ahi, tbox, nb)) continue;
      int idb[3];
      double3 posb[3];
      tcc_sg_load_tri(tid, tpos, nb, idb, posb);
      if (!tc_sg_tri_tri_planes(ida, posa, pla, idb, posb, tcc_sg_load_plane(tplane, nb))) continue;
      if (dedup) {
        tcc_sg_refuse_all(ida, idb, qof, 0x80000000u | qa, qbad);
        continue;
      }
      qbad[qa] = 0x80000000u | qa;
      return;
    }
  }
  if (!cross) return;
  TCC_SG_FOR_CELL_ENTRIES(lo, hi, item, {
    const uint qb = (uint)item.x;
    if (qb == qa || !tcc_sg_owner_cell(lo, hi, i0_, j0_, k0_, (uint)item.z, qbox + 6 * qb, ci, cj, ck)) continue;
    for (uint na = qoff[qa]; na < qoff[qa + 1]; ++na) {
      double3 alo, ahi;
      tcc_sg_load_box(tbox, na, &alo, &ahi);
      int ida[3];
      double3 posa[3];
      tc_sg_plane pla;
      int loaded = 0;
      for (uint nb = qoff[qb]; nb < qoff[qb + 1]; ++nb) {
        if (tcc_sg_tri_box_apart(alo, ahi, tbox, nb)) continue;
        if (!loaded) {
          tcc_sg_load_tri(tid, tpos, na, ida, posa);
          pla = tcc_sg_load_plane(tplane, na);
          loaded = 1;
        }
        int idb[3];
        double3 posb[3];
        tcc_sg_load_tri(tid, tpos, nb, idb, posb);
        if (!tc_sg_tri_tri_planes(ida, posa, pla, idb, posb, tcc_sg_load_plane(tplane, nb))) continue;
        qbad[qa] = 0x80000000u | qb; /* names the other query for debugging */
        return;
      }
    }
  })
}

/* The guard's refusal is kept as the edge's verdict (TCC_REFUSED_SURFACE, collapse_verdicts.cl)
 * so that the edge is not chosen again while its rings do not change. */
/* A query with a hit is unmarked (selected again without it) and its verdict set (when the
 * verdict buffer is there); counts them. */
__kernel void sguard_drop(uint nq, __global const int* qedge, __global const uint* qbad, __global uint* marked,
                          int has_verdict, __global uchar* verdict, __global uint* count) {
  uint q = get_global_id(0);
  if (q >= nq || !qbad[q]) return;
  marked[qedge[q]] = 0u;
  if (has_verdict) verdict[qedge[q]] = TCC_REFUSED_SURFACE;
  atomic_inc(count);
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
                                  __global const uchar* dir, __global const uint* nb_off, __global const int* nb,
                                  __global const int* vaff, __global const double* pts, __global double* boxes) {
  uint i = get_global_id(0);
  if (i >= n) return;
  const int g = (int)undone[i];
  double3 lo = (double3)(INFINITY, INFINITY, INFINITY), hi = -lo;
  for (int s = 0; s < 2; ++s) {
    const int x = edges[2 * g + s];
    for (uint j = nb_off[x]; j <= nb_off[x + 1]; ++j) { /* N(x), then x */
      int z = j == nb_off[x + 1] ? x : nb[j];
      const int h = vaff[z];
      if (h >= 0) { /* an end point of a collapse still taken: where its survivor is */
        const uint d = dir[h];
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
