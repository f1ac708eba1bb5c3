/* The surface guard's helpers (collapse_guard.cl, collapse_guard_applied.cl): the new S
 * triangles of a collapse, the storage of the queries' triangles and planes, the grid of the
 * query boxes, and the test of an S face against the queries in its cells. */
#ifndef TETCOLLAPSE_COLLAPSE_GUARD_H
#define TETCOLLAPSE_COLLAPSE_GUARD_H

#include "collapse_common.h"
#include "collapse_guard_geometry.h"

/* The collapse of edge e as chosen: x removed, y survives at *p; returns whether y moves. */
inline int tcc_sg_collapse(int e, __global const int* edges, __global const uchar* edges2dir,
                           __global const double* pts, __global const double* vfield, uint vfield_stride, int* x,
                           int* y, double3* p) {
  int v0 = edges[2 * e], v1 = edges[2 * e + 1];
  uint d = edges2dir[e];
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

/* Each pair of S faces of the result is tested once (sguard_surface and sguard_pairs with
 * `dedup`, the matching selection's runs). Without it, a pair (A, B) is tested for every query
 * q whose survivor x_q is a vertex of A or B: by the sweep of A against q when x_q is in B
 * alone (and of B when in A alone), by sguard_pairs of q when in both; each refuses q on a
 * hit. With it, only for the query whose survivor has the lowest id of those (verts2query: the
 * query of each survivor of the run, -1 for other vertices; tmin: per triangle, the lowest survivor
 * among its vertices), and a hit refuses all of them (tcc_sg_refuse_all): the same refusals, fewer
 * pairs (most S faces of the result hold a survivor, so most pairs would be tested twice). */
inline int tcc_sg_first_survivor(const int* id, __global const int* verts2query) {
  int m = INT_MAX;
  for (int k = 0; k < 3; ++k)
    if (verts2query[id[k]] >= 0) m = min(m, id[k]);
  return m;
}
inline void tcc_sg_refuse_all(const int* ia, const int* ib, __global const int* verts2query, uint code,
                              volatile __global uint* qbad) {
  for (int k = 0; k < 6; ++k) {
    const int q = verts2query[k < 3 ? ia[k] : ib[k - 3]];
    if (q >= 0) atomic_max(qbad + q, code); /* the largest code whatever the order */
  }
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
                              __global const int* verts2query, __global const int* tmin, __global uint* qbad) {
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
    tcc_sg_refuse_all(id, fid, verts2query, code, qbad); /* and on: the face's pairs with other triangles */
  }
}

#endif
