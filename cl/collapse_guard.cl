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
 * Per iteration, over the collapses chosen by the conflict passes (edges_are_final):
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
 * The matching selection, whose collapses are applied as it takes them, tests the result
 * instead (collapse_guard_applied.cl) and undoes what is refused.
 * The new S triangles of the collapse of x onto y (y at the placement p): the faces containing
 * x of the tets of ring(x) that survive, and, when y moves, the faces containing y of ring(y),
 * with x renamed y; a face is taken when it is on S now, or when the tet across it is removed
 * by the collapse and the face it is glued to through that tet is on the boundary or the two
 * tets' labels differ. The current S faces are tested in their current places, also those that
 * another chosen collapse moves (whose new triangles are tested too): that only refuses more.
 * The triangle test: cl/collapse_guard_geometry.h (floating point with a tolerance: rounding
 * never hides a contact).
 */

#include "collapse_guard.h"

/* Queries: the chosen collapses that change S, with the box and the number of their new S
 * triangles. */
__kernel void sguard_queries(uint ne, __global const int* edges, __global const uint* edges_are_final,
                             __global const uchar* edges2dir, __global const double* pts, __global const double* vfield,
                             uint vfield_stride, __global const int* tets, __global const uint* vt_off,
                             __global const int* vt, __global const int* tet_nbr, __global const int* labels,
                             int use_labels, __global const uchar* vflags, __global int* qedge, __global double* qbox,
                             __global uint* qntri, __global uint* qcount) {
  uint e = get_global_id(0);
  if (e >= ne || !edges_are_final[e]) return;
  int x, y;
  double3 p;
  int moves_y = tcc_sg_collapse((int)e, edges, edges2dir, pts, vfield, vfield_stride, &x, &y, &p);
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
 * the mesh (tets renamed, tets_are_dead, tet_nbr glued, survivors placed) and may share tets: it
 * tests the result. Every S face of the result that a collapse changed holds the survivor x of that
 * collapse (renamed from the removed vertex y, moved with x, or glued across a removed tet), so
 * a query is a collapse whose survivor is on S, with as new triangles all S faces through x
 * now; the sweep (sguard_surface) is over the S faces of the result (sguard_applied_smask) and
 * skips those through x, which are the query's own (sguard_pairs tests them among themselves).
 * Every pair of faces of the result that was not a pair before has a face of a query, so
 * nothing that crosses is missed. --- */

/* The new S triangles of each query, at qoff[q] .. qoff[q + 1] (ids, positions, boxes and
 * planes). */
__kernel void sguard_tris(uint nq, __global const int* qedge, __global const uint* qoff, __global const int* edges,
                          __global const uchar* edges2dir, __global const double* pts, __global const double* vfield,
                          uint vfield_stride, __global const int* tets, __global const uint* vt_off,
                          __global const int* vt, __global const int* tet_nbr, __global const int* labels,
                          int use_labels, __global int* tid, __global double* tpos, __global double* tbox,
                          __global double* tplane, __global int* qrep) {
  uint qi = get_global_id(0);
  if (qi >= nq) return;
  int x, y;
  double3 p;
  int moves_y = tcc_sg_collapse(qedge[qi], edges, edges2dir, pts, vfield, vfield_stride, &x, &y, &p);
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


/* Every current S face (smask: the faces a tet owns on S) against the queries whose box it
 * overlaps; a face in cells without queries (vcell) is passed over before its points are read.
 * With dedup a cell's scan stops at the first x at or above the face's lowest survivor (the face
 * has x, or the pairs are another query's). */
__kernel void sguard_surface(uint n, __global const uint* stets, __global const uchar* smask,
                             __global const uint* vcell, __global const double* pts, __global const int* tets,
                             __global const int* qrep, __global const double* qbox, __global const uint* qoff,
                             __global const int* tid, __global const double* tpos, __global const double* tbox,
                             __global const double* tplane, double ox, double oy, double oz, double ih, int gx, int gy,
                             int gz, __global const uint* cell_off, __global const int* cell_q, __global uint* qbad,
                             int dedup, __global const int* verts2query, __global const int* tmin) {
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
    const int flow = dedup ? tcc_sg_first_survivor(fid, verts2query) : INT_MAX; /* its lowest survivor */
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
                        tplane, verts2query, tmin, qbad);
    })
  }
}

/* The new triangles of a query among themselves, and with cross (not for the matching
 * selection's queries: the sweep meets the other queries' triangles among the S faces of the
 * result) those of two queries against each other. */
__kernel void sguard_pairs(uint nq, __global const double* qbox, __global const uint* qoff, __global const int* tid,
                           __global const double* tpos, __global const double* tbox, __global const double* tplane,
                           double ox, double oy, double oz, double ih, int gx, int gy, int gz,
                           __global const uint* cell_off, __global const int* cell_q, __global uint* qbad, int cross,
                           int dedup, __global const int* qrep, __global const int* verts2query,
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
        tcc_sg_refuse_all(ida, idb, verts2query, 0x80000000u | qa, qbad);
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
__kernel void sguard_drop(uint nq, __global const int* qedge, __global const uint* qbad,
                          __global uint* edges_are_marked, int has_verdict, __global uchar* edges2verdict,
                          __global uint* count) {
  uint q = get_global_id(0);
  if (q >= nq || !qbad[q]) return;
  edges_are_marked[qedge[q]] = 0u;
  if (has_verdict) edges2verdict[qedge[q]] = TCC_REFUSED_SURFACE;
  atomic_inc(count);
}
