/* Helpers shared by the collapse kernels (cl/collapse_*.cl).
 *
 * Connectivity of one iteration, all built by cl/collapse_connectivity.cl:
 *   vt_off[v] .. vt_off[v+1]     ring(v): the tets containing v, ascending, in vt[]
 *   nb_off[v] .. nb_off[v+1]     N(v): the neighbour vertices of v, ascending, in nb[], and
 *                                nb_edge[] the id of the edge (v, nb[k])
 *   edges[2e], edges[2e+1]       edge e = (v0 < v1); edges are sorted lexicographically
 * A parameter that receives one of the host's per-edge, per-vertex or per-tet buffers has that
 * buffer's name (edges2cost, verts2collapse, edges_are_final: the State structs of the stages in
 * host/collapse), since the host sets every argument by its parameter's name (launch.hpp there).
 * The floating-point contraction is switched off so that face normals and their dot products
 * are bit-identical to the host's tc::build_topology (which the tests compare against).
 */
#ifndef TETCOLLAPSE_COLLAPSE_COMMON_H
#define TETCOLLAPSE_COLLAPSE_COMMON_H

#pragma OPENCL FP_CONTRACT OFF
#include "geometry.h"

/* Flags (TCC_BOUNDARY, TCC_INTERFACE, TCC_RIDGE), vertex classes (TCC_INTERIOR .. TCC_CORNER),
 * boundary modes (TCC_STRICT, TCC_FEATURES, TCC_FREE), edge_dir bits (TCC_DIR_*) and the
 * predicate Q: cl/collapse_predicate.h, shared with the sequential method. */
#include "collapse_predicate.h"

/* Software prefetch for the next work items of a kernel, where the host asks for it (CPU
 * devices, which run a work-group's items one after another: TCC_PREFETCH) and the compiler
 * has the builtin (clang, as in PoCL). */
#if defined(TCC_PREFETCH) && defined(__has_builtin)
#if __has_builtin(__builtin_prefetch)
#define TCC_PREFETCH_OK 1
#endif
#endif

/* Adds flag (0 or 1) of every work item of the group to *counter, with one global atomic per
 * work-group instead of one per item: on a CPU device a global counter incremented by every
 * item bounces its cache line between the cores.
 * Every work item of the group must call it (barriers); lc is a __local uint of the kernel. */
inline void tcc_group_count(uint flag, volatile __local uint* lc, __global uint* counter) {
  if (get_local_id(0) == 0) *lc = 0u;
  barrier(CLK_LOCAL_MEM_FENCE);
  if (flag) atomic_inc(lc);
  barrier(CLK_LOCAL_MEM_FENCE);
  if (get_local_id(0) == 0 && *lc) atomic_add(counter, *lc);
}

/* Refusal reasons written by the admissible filter (tc::collapse::Reason). */
#define TCC_OK 0
#define TCC_NOT_MARKED 1
#define TCC_REFUSED_Q 2
#define TCC_REFUSED_LINK 3
#define TCC_REFUSED_VOLUME 4
#define TCC_REFUSED_QUALITY 6 /* 5 is the host's "untested" */
#define TCC_UNTESTED 5 /* lazy filter: marked, passed Q, never tested (a cheaper rival won) */
#define TCC_VERDICT_UNKNOWN 0xff /* collapse_verdicts.cl: no test result kept for the edge */
#define TCC_REFUSED_SURFACE 7 /* by the surface guard (collapse_guard.cl) */
#define TCC_VOLUME_OK 8 /* verdict only: the volume test passed, the link condition is untested */

/* The iteration's counters (host/collapse/cost.hpp, CostState::counters): 0-5 the stages' counts,
 * then the refusals of the boundary error bound's test (collapse_select.h). */
#define TCC_COUNTER_BOUND_REFUSED 6
#define TCC_COUNTERS 7

/* Per-edge states of the conflict passes and of the lazy admissible filter. */
#define TCC_UNDECIDED 0
#define TCC_IN 1
#define TCC_OUT 2

/* Does tet t contain vertex x? */
inline int tcc_has(__global const int* tets, int t, int x) {
  __global const int* q = tets + 4 * t;
  return q[0] == x || q[1] == x || q[2] == x || q[3] == x;
}

/* Local index (0..3) of x in tet t, or -1. */
inline int tcc_local(__global const int* tets, int t, int x) {
  __global const int* q = tets + 4 * t;
  return q[0] == x ? 0 : q[1] == x ? 1 : q[2] == x ? 2 : q[3] == x ? 3 : -1;
}

/* The face of tet t opposite local vertex f is shared with how many other tets? The first one
 * found goes to *other. The face's vertices are all in ring(x) for x = any face vertex. */
inline int tcc_face_others(__global const int* tets, __global const uint* vt_off, __global const int* vt, int t, int f,
                           int* other) {
  __global const int* q = tets + 4 * t;
  int p0 = q[TC_TET_FACES[f][0]], p1 = q[TC_TET_FACES[f][1]], p2 = q[TC_TET_FACES[f][2]];
  int n = 0;
  *other = -1;
  for (uint i = vt_off[p0]; i < vt_off[p0 + 1]; ++i) {
    int u = vt[i];
    if (u != t && tcc_has(tets, u, p1) && tcc_has(tets, u, p2)) {
      if (n == 0) *other = u;
      ++n;
    }
  }
  return n;
}

/* tet_nbr[4 t + f]: the tet across the face of t opposite local vertex f; -1 when the face is in
 * no other tet (boundary), -2 when in several (invalid input: each side counts as boundary). */

/* At most this many S-faces through a vertex are gathered (conn_surface_flags, the matching
 * selection's live tests); more (rare: a fan of thin boundary faces) classify it as a corner there and
 * refuse the edge here. */
#ifndef TCC_MAX_VERTEX_SFACES
#define TCC_MAX_VERTEX_SFACES 64
#endif

/* Is the face of tet t opposite local vertex f an S-face owned by t (as in tc::build_topology:
 * a boundary face is owned by its only tet; an interface face by the tet of the smaller label;
 * a face in more than two tets, invalid input, counts as boundary for each)? Returns 0 when
 * not, else TCC_BOUNDARY or TCC_INTERFACE. *on_s receives the kind even when t does not own it. */
inline uint tcc_owned_sface(__global const int* tet_nbr, __global const int* labels, int use_labels, int t, int f,
                            uint* on_s) {
  int other = tet_nbr[4 * t + f];
  if (other < 0) {
    *on_s = TCC_BOUNDARY;
    return TCC_BOUNDARY;
  }
  if (use_labels && labels[t] != labels[other]) {
    *on_s = TCC_INTERFACE;
    return labels[t] < labels[other] ? TCC_INTERFACE : 0u;
  }
  *on_s = 0u;
  return 0u;
}

/* Bit-exact twins of tc::geo::cross / dot / normalize on the host (no built-ins, whose rounding
 * is implementation-defined). */
inline double3 tcc_cross(double3 a, double3 b) {
  return (double3)(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
inline double tcc_dot(double3 a, double3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline double3 tcc_normalize(double3 a) {
  double l = sqrt(tcc_dot(a, a));
  return l > 0.0 ? (double3)(a.x / l, a.y / l, a.z / l) : a;
}

/* Unit normal of the face of tet t opposite local vertex f, oriented out of t, computed as
 * tc::build_topology does from the face's vertices in TC_TET_FACES order. */
inline double3 tcc_face_normal(__global const double* pts, __global const int* tets, int t, int f) {
  __global const int* q = tets + 4 * t;
  double3 p0 = tc_point(pts, q[TC_TET_FACES[f][0]]);
  double3 p1 = tc_point(pts, q[TC_TET_FACES[f][1]]);
  double3 p2 = tc_point(pts, q[TC_TET_FACES[f][2]]);
  return tcc_normalize(tcc_cross(p1 - p0, p2 - p0));
}

/* --- The user's placement and predicate (tc::CollapseOptions::placement_cl_source and
 * predicate_cl_source), compiled in with -DTCC_USER_PLACEMENT / -DTCC_USER_PREDICATE after
 * this header (the host builds "this header, the user's source, the stage's file"):
 *     double3 tc_user_placement(double3 p0, double3 p1, double f0, double f1);
 *     int tc_user_predicate(double3 p0, double3 p1, double f0, double f1);
 * p0, p1: the edge's end points (v0 < v1); f0, f1: the first component of the first vertex
 * field at them (0 without vertex fields), as for the user cost (collapse_cost.cl). --- */
#ifdef TCC_USER_PLACEMENT
double3 tc_user_placement(double3 p0, double3 p1, double f0, double f1);
#endif
#ifdef TCC_USER_PREDICATE
int tc_user_predicate(double3 p0, double3 p1, double f0, double f1);
#endif

/* The first component of the first vertex field at v (vf packs every component of every field,
 * vstride per vertex; 0 without fields). */
inline double tcc_field0(__global const double* vf, uint vstride, int v) {
  return vstride > 0u ? vf[(size_t)v * vstride] : 0.0;
}

/* Q's direction bits (tcc_predicate_q, dir >= 0) with the user's placement where it applies:
 * in place of the midpoint, when both end points are off S, or on every edge in free mode (so
 * that the boundary modes keep their promises: S vertices move along S only by the built-in
 * rules). */
inline int tcc_user_dir(int dir, uint fa, uint fb, int mode) {
#ifdef TCC_USER_PLACEMENT
  if (dir >= 0 && (dir & (int)TCC_DIR_MIDPOINT) && (mode == TCC_FREE || (fa == 0u && fb == 0u)))
    dir |= (int)TCC_DIR_USER;
#else
  (void)fa;
  (void)fb;
  (void)mode;
#endif
  return dir;
}

/* Does the user's predicate allow collapsing (v0, v1)? (Always without one.) */
inline int tcc_user_allows(__global const double* pts, __global const double* vf, uint vstride, int v0, int v1) {
#ifdef TCC_USER_PREDICATE
  return tc_user_predicate(tc_point(pts, v0), tc_point(pts, v1), tcc_field0(vf, vstride, v0),
                           tcc_field0(vf, vstride, v1)) != 0;
#else
  (void)pts;
  (void)vf;
  (void)vstride;
  (void)v0;
  (void)v1;
  return 1;
#endif
}

/* Where the survivor of the collapse of (v0, v1) with the direction bits dir goes. */
inline double3 tcc_placement(__global const double* pts, __global const double* vf, uint vstride, int v0, int v1,
                             uint dir) {
  double3 p0 = tc_point(pts, v0), p1 = tc_point(pts, v1);
#ifdef TCC_USER_PLACEMENT
  if (dir & TCC_DIR_USER) return tc_user_placement(p0, p1, tcc_field0(vf, vstride, v0), tcc_field0(vf, vstride, v1));
#else
  (void)vf;
  (void)vstride;
#endif
  if (dir & TCC_DIR_MIDPOINT) return (p0 + p1) * 0.5;
  return (dir & TCC_DIR_REMOVE_V1) ? p0 : p1;
}

/* The survivor's vertex fields after the collapse of (v0, v1) with the direction bits d, the
 * survivor v placed at p (the placement of tcc_placement): at a midpoint the average of v's and
 * the removed vertex's, at a user placement their interpolation at p's parameter along the edge
 * (clamped to the edge), else v's own. Reads the ncomp values of v and of the removed vertex from
 * in, writes them at out[o ncomp ..] (out may be in, with o = v). */
inline void tcc_survivor_fields(int v, int v0, int v1, uint d, double3 p, __global const double* pts, uint ncomp,
                                __global const double* in, __global double* out, uint o) {
  const int partner = (d & TCC_DIR_MIDPOINT) ? (v == v0 ? v1 : v0) : -1;
  double s = 0.5; /* the partner's parameter, seen from v */
  if (d & TCC_DIR_USER) {
    const double3 p0 = tc_point(pts, v0), d01 = tc_point(pts, v1) - p0;
    const double len2 = tcc_dot(d01, d01);
    const double s01 = len2 > 0.0 ? tcc_dot(p - p0, d01) / len2 : 0.5; /* the parameter of v1 */
    s = v == v0 ? s01 : 1.0 - s01;
  }
  for (uint c = 0; c < ncomp; ++c) {
    double x = in[(size_t)v * ncomp + c];
    if (partner >= 0) {
      const double y = in[(size_t)partner * ncomp + c];
      x = s == 0.5 ? 0.5 * (x + y) : !(s > 0.0) ? x : s >= 1.0 ? y : x + s * (y - x);
    }
    out[(size_t)o * ncomp + c] = x;
  }
}

/* Worklists of the conflict rounds (collapse_conflict.cl, collapse_admissible.cl): slot c of
 * the candidate list cand[] keeps, after its first visit, the cheaper rivals that were still
 * undecided (at most TCC_RIVALS, in slots2rivals[c TCC_RIVALS ..]; their count in
 * slots2rival_count[c]), so a later visit looks only at those and drops the ones decided OUT
 * meanwhile. slots2rival_count[c] is TCC_UNSCANNED before the first visit and TCC_RIVALS + 1 when
 * they did not fit (every visit then scans all rivals). */
#define TCC_RIVALS 16
#define TCC_UNSCANNED 0xffffffffu

/* Waiting test over the stored rivals: -1 when one is IN, 1 while some are undecided, 0 when
 * all are OUT. Keeps only the undecided ones. */
inline int tcc_stored_rivals(__global uint* rv, __global uint* rcount, __global const uchar* edges2state) {
  uint n = *rcount, m = 0;
  for (uint j = 0; j < n; ++j) {
    uint f = rv[j];
    uchar sf = edges2state[f];
    if (sf == TCC_IN) return -1;
    if (sf == TCC_UNDECIDED) rv[m++] = f;
  }
  *rcount = m;
  return m > 0 ? 1 : 0;
}

/* Records rival f (undecided, before e) at the first visit; m counts the distinct ones. */
inline void tcc_store_rival(__global uint* rv, uint* m, uint f) {
  uint n = *m < TCC_RIVALS ? *m : TCC_RIVALS;
  for (uint j = 0; j < n; ++j)
    if (rv[j] == f) return;
  if (*m < TCC_RIVALS) rv[*m] = f;
  ++*m;
}

/* (cost, index) order used by both conflict passes. */
inline int tcc_before(__global const double* cost, int f, int e) {
  double cf = cost[f], ce = cost[e];
  return cf < ce || (cf == ce && f < e);
}

/* Pass 1 claims: verts2slot[x] ends as the first, in (cost, index) order, of the edges that claim
 * end point x in a round (-1 when none); a compare-and-swap loop, so the result does not depend
 * on the order of the claims. */
inline void tcc_claim(volatile __global int* slot, int e, __global const double* cost) {
  int cur = *slot;
  while (cur < 0 || tcc_before(cost, e, cur)) {
    int prev = atomic_cmpxchg(slot, cur, e);
    if (prev == cur) return;
    cur = prev;
  }
}

/* Whether the candidate of list entry i decides this round: -1 when it was dropped by
 * pass1_claim, 0 when it waits (appended to next, its next-round slots cleared), 1 when it is
 * first at both end points. *edge receives the edge. */
inline int tcc_pass1_turn(uint i, int first, __global const uint* list, __global uint* next, __global uint* next_n,
                          __global const uint* cand, __global const int* edges, __global const int* verts2slot,
                          __global int* verts2slot_next, __global const uchar* edges2state, int* edge) {
  uint c = first ? i : list[i];
  int e = (int)cand[c];
  *edge = e;
  if (edges2state[e] != TCC_UNDECIDED) return -1;
  int a = edges[2 * e], b = edges[2 * e + 1];
  if (verts2slot[a] == e && verts2slot[b] == e) return 1;
  verts2slot_next[a] = -1;
  verts2slot_next[b] = -1;
  next[atomic_inc(next_n)] = c;
  return 0;
}

/* Pass-2 rivals of e = (a, b): the pass-1 edges recorded (verts2collapse) at a vertex of a tet of
 * ring(a) or ring(b), before e. The vertices of the tets of ring(x) are x and N(x) (every edge
 * lies in a tet), so N(a) and N(b) are scanned: each vertex once instead of the 4 corners of
 * every tet of the rings, which repeat them. Returns as tcc_stored_rivals. */
inline int tcc_pass2_wait(int e, int a, int b, __global const uint* nb_off, __global const int* nb,
                          __global const int* verts2collapse, __global const double* cost,
                          __global const uchar* edges2state, __global uint* rv, __global uint* rcount) {
  if (*rcount <= TCC_RIVALS) return tcc_stored_rivals(rv, rcount, edges2state);
  uint m = 0;
  for (int s = 0; s < 2; ++s) {
    int x = s == 0 ? a : b;
    for (uint j = nb_off[x]; j < nb_off[x + 1]; ++j) {
      int f = verts2collapse[nb[j]];
      if (f < 0 || f == e) continue;
      uchar sf = edges2state[f];
      if (sf == TCC_OUT || !tcc_before(cost, f, e)) continue;
      if (sf == TCC_IN) return -1;
      tcc_store_rival(rv, &m, (uint)f); /* both ends of f, or a common neighbour, give f twice */
    }
  }
  *rcount = m <= TCC_RIVALS ? m : TCC_RIVALS + 1;
  return m > 0 ? 1 : 0;
}

#endif
