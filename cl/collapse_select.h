/* The link and volume tests of an edge collapse on the device and the helpers of the selections'
 * rounds, shared by the selections of cl/collapse_admissible.cl (the lazy filter, the greedy
 * selection) and cl/collapse_matching.cl (the matching selection). The tests themselves are
 * cl/collapse_checks.h, shared with the sequential CPU method; here is what only the device has:
 * its star (the CSR arrays of the iteration, and the matching selection's live mesh) and its
 * ways of gathering the common neighbours of an edge. The checks are described at the top of
 * cl/collapse_admissible.cl. */
#ifndef TETCOLLAPSE_COLLAPSE_SELECT_H
#define TETCOLLAPSE_COLLAPSE_SELECT_H

#include "collapse_common.h"

/* The mesh a test reads. Every selection but the matching one tests edges on the mesh of the
 * iteration's start (the connectivity as built). The matching selection (collapse_matching.cl)
 * applies its collapses as it takes them: tets are renamed in place, the tets a collapse removes
 * are flagged in tets_are_dead[] and tet_nbr is glued across them, and a survivor moves in pts[]. A
 * test of an edge whose star such a collapse changed runs "live" (live = 1): ring(a) and
 * ring(b), which gained no tet (a and b are no end point of a collapse taken), are read without
 * their removed tets, and what the connectivity gives of the star (N(a), N(b), the S-edges,
 * the S flags and classes of a and b, the tets' qualities) is computed from the rings, tet_nbr
 * and the labels as they are now. With live = 0 (a constant at every call site, so the compiler
 * drops the live code) tets_are_dead is not read. */
#define TCC_DEAD(t) (live && tets_are_dead[t])
#define TCC_NO_DEAD ((__global const uchar*)0) /* tets_are_dead of the tests that are never live */

/* The star the shared tests read (cl/collapse_checks.h): the connectivity of the iteration (ring,
 * tet_nbr), its S flags (vflags, eflags) and points, and, live, the removed tets. */
#define TCS_LINK_PARAMS                                                                                       \
  __global const int *tets, __global const uint *vt_off, __global const int *vt, __global const int *tet_nbr, \
      __global const int *labels, int use_labels, __global const uchar *vflags, __global const uchar *eflags, \
      int live, __global const uchar *tets_are_dead
#define TCS_LINK_ARGS tets, vt_off, vt, tet_nbr, labels, use_labels, vflags, eflags, live, tets_are_dead
#define TCS_VOL_PARAMS                                                                                       \
  __global const int *tets, __global const uint *vt_off, __global const int *vt, __global const double *pts, \
      __global const double *tets2quality, int live, __global const uchar *tets_are_dead,                     \
      __global const double *vfield, uint vfield_stride, double field_eps
#define TCS_VOL_ARGS tets, vt_off, vt, pts, tets2quality, live, tets_are_dead, vfield, vfield_stride, field_eps
#define TCS_RING_BEGIN(x) vt_off[x]
#define TCS_RING_END(x) vt_off[(x) + 1]
#define TCS_RING_TET(i) vt[i]
#define TCS_DEAD(t) TCC_DEAD(t)
#define TCS_TET(t) (tets + 4 * (t))
#define TCS_TETS tets
#define TCS_ACROSS(t, f) tet_nbr[4 * (t) + (f)]
#define TCS_USE_LABELS use_labels
#define TCS_LABEL(t) labels[t]
/* live, the S-edges from the rings (eflags and vflags are those of the iteration's start);
 * else from eflags, passing over a c off S */
#define TCS_SEDGE_SKIP(c) (!live && !(vflags[c] & (TCC_BOUNDARY | TCC_INTERFACE)))
#define TCS_SEDGE(x, c, e) (live ? tcc_ring_sedge(TCS_LINK_ARGS, (x), (c)) : (uint)eflags[e])
#define TCS_POINT(v) tc_point(pts, (v))
/* tets2quality holds the qualities of the iteration's start */
#define TCS_OLD_QUALITY(t, p0, p1, p2, p3) (live ? tc_tet_quality(p0, p1, p2, p3) : tets2quality[t])
#define TCS_FIELD_EPS field_eps
#define TCS_FIELD(v) vfield[(size_t)(v) * vfield_stride]

/* The link condition and the volume test themselves: shared with the sequential CPU method. */
#include "collapse_checks.h"

/* Predicate Q (tcc_predicate_q): shared with the sequential CPU method. */
#include "collapse_predicate.h"
#ifdef TCC_BOUND
#include "collapse_bound.h"
#endif

/* The volume test (and the quality guard) of the edge (a, b), a < b, which passed Q with the
 * direction bits dir: TCC_OK, TCC_REFUSED_VOLUME or TCC_REFUSED_QUALITY. Live (see the top):
 * without the removed tets, and the qualities before computed here (tets2quality holds those of
 * the iteration's start). */
inline uchar tcc_volume_test(int a, int b, int dir, __global const int* tets, __global const uint* vt_off,
                             __global const int* vt, __global const double* pts, __global const double* vfield,
                             uint vfield_stride, double eps_v, double q_min, double field_eps,
                             __global const double* tets2quality, int live, __global const uchar* tets_are_dead) {
  double3 p = tcc_placement(pts, vfield, vfield_stride, a, b, (uint)dir);
#ifdef TCC_USER_PLACEMENT
  /* a user placement may be no point at all (inf, nan: e.g. a division by a zero field
   * difference) */
  if (!isfinite(p.x) || !isfinite(p.y) || !isfinite(p.z)) return TCC_REFUSED_VOLUME;
#endif
  return (uchar)tcc_volume_verdict(TCS_VOL_ARGS, a, b, p, eps_v, q_min);
}

/* Live: N(a) n N(b) from the tets of the rings into cn (at most TCC_MAX_LINK); returns its size,
 * or -1 when a list does not fit. */
inline int tcc_live_common(int a, int b, __global const int* tets, __global const uint* vt_off, __global const int* vt,
                           __global const uchar* tets_are_dead, int* cn) {
  int na[TCC_MAX_LINK], nna = 0, ncn = 0;
  for (uint i = vt_off[a]; i < vt_off[a + 1]; ++i) {
    int t = vt[i];
    if (tets_are_dead[t]) continue;
    __global const int* q = tets + 4 * t;
    for (int k = 0; k < 4; ++k) {
      int v = q[k];
      if (v == a || tcc_in(na, nna, v)) continue;
      if (nna == TCC_MAX_LINK) return -1;
      na[nna++] = v;
    }
  }
  for (uint i = vt_off[b]; i < vt_off[b + 1]; ++i) {
    int t = vt[i];
    if (tets_are_dead[t]) continue;
    __global const int* q = tets + 4 * t;
    for (int k = 0; k < 4; ++k) {
      int v = q[k]; /* a is not in na */
      if (v == b || !tcc_in(na, nna, v) || tcc_in(cn, ncn, v)) continue;
      if (ncn == TCC_MAX_LINK) return -1;
      cn[ncn++] = v;
    }
  }
  return ncn;
}

/* Live, for a ring(a) of at most TCC_LIVE_LINK_RING tets: N(a) n N(b) when it is lk(ab)'s
 * vertices (pc, pd: the np edges of lk(ab)), into cn; -1 when it is not (a common neighbour off
 * lk(ab): the link test's (i) refuses), or does not fit. The same verdicts as tcc_live_common
 * followed by (i), without its lists: N(a) n N(b) always holds lk(ab)'s vertices, so (i) only asks
 * whether a vertex of a tet of ring(b) without a, off lk(ab), is in N(a). Such a vertex is looked
 * up in a 256-bit filter of the vertices of ring(a) (their ids mod 256), and only a hit is checked
 * against the tets of ring(a). The caller takes it for a ring(a) of at most TCC_MAX_LINK / 3 tets
 * too: then |N(a)| <= TCC_MAX_LINK, and tcc_live_common's refusal of a longer list of N(a) cannot
 * happen. */
#ifndef TCC_LIVE_LINK_RING
#define TCC_LIVE_LINK_RING 32
#endif
inline int tcc_live_link_common(TCS_LINK_PARAMS, int a, int b, const int* pc, const int* pd, int np, const int* p8,
                                const int* d8, int* cn) {
  uint bits[8] = {0u, 0u, 0u, 0u, 0u, 0u, 0u, 0u};
  for (uint i = vt_off[a]; i < vt_off[a + 1]; ++i) {
    const int t = vt[i];
    if (tets_are_dead[t]) continue;
    const int4 q = vload4(t, tets);
    bits[(q.x >> 5) & 7] |= 1u << (q.x & 31);
    bits[(q.y >> 5) & 7] |= 1u << (q.y & 31);
    bits[(q.z >> 5) & 7] |= 1u << (q.z & 31);
    bits[(q.w >> 5) & 7] |= 1u << (q.w & 31);
  }
  for (uint i = vt_off[b]; i < vt_off[b + 1]; ++i) {
    const int t = vt[i];
    if (tets_are_dead[t]) continue;
    const int4 q4 = vload4(t, tets);
    if ((q4.x == a) | (q4.y == a) | (q4.z == a) | (q4.w == a)) continue; /* a tet of the edge: lk(ab) */
    const int q[4] = {q4.x, q4.y, q4.z, q4.w};
    for (int k = 0; k < 4; ++k) {
      const int v = q[k];
      if (v == b || !(bits[(v >> 5) & 7] & (1u << (v & 31)))) continue;
      if (tcc_in_lk(v, pc, pd, np, p8, d8)) continue;
      if (tcc_ring_has(TCS_LINK_ARGS, a, v, v, -1)) return -1; /* in N(a), off lk(ab) */
    }
  }
  int ncn = 0;
  for (int k = 0; k < 2 * np; ++k) {
    const int v = k < np ? pc[k] : pd[k - np];
    if (tcc_in(cn, ncn, v)) continue;
    if (ncn == TCC_MAX_LINK) return -1;
    cn[ncn++] = v;
  }
  return ncn;
}

/* The link condition of the edge (a, b), a < b: TCC_OK or TCC_REFUSED_LINK. The common
 * neighbours are gathered here, the decision is tcc_link_holds (cl/collapse_checks.h). Not live,
 * by a merge of the sorted N(a) and N(b), which also gives the edges (a, c) and (b, c) whose
 * eflags (ii) reads; live (see the top), from the rings, and an edge that no tet holds any more
 * is refused. */
inline uchar tcc_link_test(int a, int b, uint fa, uint fb, uint fe, __global const int* tets,
                           __global const uint* vt_off, __global const int* vt, __global const int* tet_nbr,
                           __global const uint* nb_off, __global const int* nb, __global const int* nb_edge,
                           __global const int* labels, int use_labels, __global const uchar* vflags,
                           __global const uchar* eflags, int live, __global const uchar* tets_are_dead) {
  /* cn: the common neighbours of a and b, with the edges (a, cn[k]) and (b, cn[k]) (one more
   * slot: the merge writes at ncn before it knows whether it keeps the entry); (pc, pd): the
   * edges of lk(ab), one per tet of the edge */
  int cn[TCC_MAX_LINK + 1], cea[TCC_MAX_LINK + 1], ceb[TCC_MAX_LINK + 1], pc[TCC_MAX_LINK], pd[TCC_MAX_LINK];
  int ncn = 0;
  if (!live) {
    /* a merge of the sorted N(a) and N(b) without branches on their values */
    uint i = nb_off[a], ie = nb_off[a + 1], j = nb_off[b], je = nb_off[b + 1];
    while (i < ie && j < je) {
      const int x = nb[i], y = nb[j];
      if (x == y && ncn == TCC_MAX_LINK) return TCC_REFUSED_LINK;
      cn[ncn] = x; /* ncn <= TCC_MAX_LINK here */
      cea[ncn] = nb_edge[i]; /* the edges (a, x) and (b, x) when x == y */
      ceb[ncn] = nb_edge[j];
      ncn += x == y;
      i += x <= y;
      j += y <= x;
    }
  }
  const int np = tcc_link_edges(TCS_LINK_ARGS, a, b, pc, pd);
  if (np < 0) return TCC_REFUSED_LINK;
  if (live && np == 0) return TCC_REFUSED_LINK; /* earlier collapses removed every tet of the edge */
  int p8[8], d8[8];
  tcc_pad8(pc, np, p8);
  tcc_pad8(pd, np, d8);
  if (live) {
    const uint ring = vt_off[a + 1] - vt_off[a];
    ncn = ring <= TCC_LIVE_LINK_RING && 3 * ring <= TCC_MAX_LINK
              ? tcc_live_link_common(TCS_LINK_ARGS, a, b, pc, pd, np, p8, d8, cn)
              : tcc_live_common(a, b, tets, vt_off, vt, tets_are_dead, cn);
    if (ncn < 0) return TCC_REFUSED_LINK;
  }
  return tcc_link_holds(TCS_LINK_ARGS, a, b, fa, fb, fe, cn, cea, ceb, ncn, pc, pd, np, p8, d8) ? TCC_OK
                                                                                              : TCC_REFUSED_LINK;
}

/* The volume test, then the link condition (tcc_volume_test, tcc_link_test); returns TCC_OK or
 * the first refusal. */
inline uchar tcc_link_and_volume(int a, int b, uint fa, uint fb, uint fe, int dir, __global const int* tets,
                                 __global const uint* vt_off, __global const int* vt, __global const int* tet_nbr,
                                 __global const uint* nb_off, __global const int* nb, __global const int* nb_edge,
                                 __global const int* labels, int use_labels, __global const double* pts,
                                 __global const double* vfield, uint vfield_stride, __global const uchar* vflags,
                                 __global const uchar* eflags, double eps_v, double q_min, double field_eps,
                                 __global const double* tets2quality) {
  uchar r = tcc_volume_test(a, b, dir, tets, vt_off, vt, pts, vfield, vfield_stride, eps_v, q_min, field_eps, tets2quality, 0,
                            TCC_NO_DEAD);
  if (r != TCC_OK) return r;
  return tcc_link_test(a, b, fa, fb, fe, tets, vt_off, vt, tet_nbr, nb_off, nb, nb_edge, labels, use_labels, vflags,
                       eflags, 0, TCC_NO_DEAD);
}

/* The arguments of the lazy filter's test (tcc_lazy_decide), passed down unchanged by the
 * kernels that decide turns: mesh, connectivity, flags, mode, thresholds, and the outputs. */
#define TCC_TEST_PARAMS                                                                                             \
  __global const int *tets, __global const uint *vt_off, __global const int *vt, __global const int *tet_nbr,       \
      __global const uint *nb_off, __global const int *nb, __global const int *nb_edge, __global const int *labels, \
      int use_labels, __global const double *pts, __global const double *vfield, uint vfield_stride,                \
      __global const uchar *vflags, __global const uchar *vclass, __global const uchar *eflags, int mode,           \
      int paper_rule, double eps_v, double q_min, double field_eps, __global const double *tets2quality,            \
      __global uchar *edges2dir, __global uchar *edges2reason, __global uint *counters, __global uchar *edges2verdict, \
      double bound, uint eps_col, __global double *edges2eps
#define TCC_TEST_ARGS                                                                                             \
  tets, vt_off, vt, tet_nbr, nb_off, nb, nb_edge, labels, use_labels, pts, vfield, vfield_stride, vflags, vclass, \
      eflags, mode, paper_rule, eps_v, q_min, field_eps, tets2quality, edges2dir, edges2reason, counters,         \
      edges2verdict, bound, eps_col, edges2eps

/* Q's direction bits of the candidate e = (a, b), with the user's placement (tcc_user_dir). */
inline int tcc_lazy_dir(int e, int a, int b, TCC_TEST_PARAMS) {
  uint fa = vflags[a], fb = vflags[b];
  return tcc_user_dir(tcc_predicate_q(a, b, fa, fb, eflags[e], vclass[a], vclass[b], mode, paper_rule), fa, fb, mode);
}

/* The volume test alone (the cheaper part, and the one that refuses most edges) of e = (a, b)
 * in direction dir, unless a verdict is kept (carried from an earlier iteration: the rings of
 * a and b are unchanged since): a new test is counted in counters[4] and kept in edges2verdict[],
 * as TCC_VOLUME_OK when it passes (the link condition is then still to run). Returns whether
 * the edge is not refused. */
inline int tcc_lazy_volume(int e, int a, int b, int dir, TCC_TEST_PARAMS) {
  uchar r = edges2verdict[e];
  if (r == TCC_VERDICT_UNKNOWN) {
    r = tcc_volume_test(a, b, dir, tets, vt_off, vt, pts, vfield, vfield_stride, eps_v, q_min, field_eps, tets2quality, 0,
                        TCC_NO_DEAD);
    if (r == TCC_OK) r = TCC_VOLUME_OK;
    edges2verdict[e] = r;
    atomic_inc(&counters[4]);
  }
  return r == TCC_OK || r == TCC_VOLUME_OK;
}

/* The verdict of the link and volume tests of e = (a, b) in direction dir: the volume test
 * (tcc_lazy_volume), then the link condition where it passed, the result kept in
 * edges2verdict[]. */
inline uchar tcc_lazy_verdict(int e, int a, int b, int dir, TCC_TEST_PARAMS) {
  if (tcc_lazy_volume(e, a, b, dir, TCC_TEST_ARGS) && edges2verdict[e] == TCC_VOLUME_OK)
    edges2verdict[e] = tcc_link_test(a, b, vflags[a], vflags[b], eflags[e], tets, vt_off, vt, tet_nbr, nb_off, nb,
                                     nb_edge, labels, use_labels, vflags, eflags, 0, TCC_NO_DEAD);
  return edges2verdict[e];
}

/* The turn of edge e in the lazy filter: its link and volume tests (or the verdict kept),
 * then IN (verts2collapse of both end points; returns 1) or OUT (0). */
inline int tcc_lazy_decide(int e, __global const int* edges, __global uchar* edges2state, __global int* verts2collapse,
                           TCC_TEST_PARAMS) {
  int a = edges[2 * e], b = edges[2 * e + 1];
  int dir = tcc_lazy_dir(e, a, b, TCC_TEST_ARGS);
  uchar r = tcc_lazy_verdict(e, a, b, dir, TCC_TEST_ARGS);
#ifdef TCC_BOUND
  /* the boundary error bound (collapse_bound.h), after the tests: not carried as a pass, since
   * the bounds of the fan's vertices may grow while the rings stay (a refusal stays one); the
   * survivor's new bound of a collapse taken, for bound_apply (collapse_bound.cl) */
  if (r == TCC_OK) {
    /* (measured only as far as the verdict needs: past the bound, or past the best so far) */
    double after = tcc_bound_after(a, b, dir, tets, vt_off, vt, tet_nbr, labels, use_labels, pts, vfield,
                                   vfield_stride, vflags, eps_col, bound);
    /* beyond the paper: a collapse of S to the midpoint may keep either end point instead, where
     * that changes S least and the tets keep their shape (TCC_END_POINT_MIN_QUALITY) */
    if ((dir & TCC_DIR_MIDPOINT) && !(dir & TCC_DIR_USER) && after > 0.0)
      for (int d = (int)TCC_DIR_REMOVE_V1; d >= 0; --d) {
        if (tcc_volume_test(a, b, d, tets, vt_off, vt, pts, vfield, vfield_stride, eps_v,
                            fmax(q_min, TCC_END_POINT_MIN_QUALITY), field_eps, tets2quality, 0, TCC_NO_DEAD) != TCC_OK)
          continue;
        const double other = tcc_bound_after(a, b, d, tets, vt_off, vt, tet_nbr, labels, use_labels, pts, vfield,
                                             vfield_stride, vflags, eps_col, fmin(after, bound));
        if (other < after) {
          after = other;
          dir = d;
        }
      }
    if (bound > 0.0) edges2eps[e] = after; /* (sized for the edges only under a bound: lazy_start) */
    if (!(after <= bound)) {
      r = TCC_REFUSED_SURFACE;
      edges2verdict[e] = r;
      atomic_inc(&counters[TCC_COUNTER_BOUND_REFUSED]);
    }
  }
#endif
  edges2reason[e] = r;
  if (r == TCC_OK) {
    edges2dir[e] = (uchar)dir;
    atomic_inc(&counters[1]);
    edges2state[e] = TCC_IN;
    verts2collapse[a] = e;
    verts2collapse[b] = e;
    return 1;
  }
  edges2state[e] = TCC_OUT;
  return 0;
}

/* verts2slot[v] anew; with verts2slot_priority (the matching selection), verts2slot_priority[v] =
 * the slot's priority (INFINITY for none), which its scans compare without loading the edge's. */
inline void tcc_p1_recompute(int v, __global const uint* nb_off, __global const int* nb_edge,
                             __global const uchar* edges2state, __global const double* cost, __global int* verts2slot,
                             __global double* verts2slot_priority) {
  int m = verts2slot[v];
  if (m >= 0 && edges2state[m] == TCC_UNDECIDED) return; /* decisions only remove edges: still first */
  m = -1;
  for (uint j = nb_off[v]; j < nb_off[v + 1]; ++j) {
    int g = nb_edge[j];
    if (edges2state[g] == TCC_UNDECIDED && (m < 0 || tcc_before(cost, g, m))) m = g;
  }
  verts2slot[v] = m;
  if (verts2slot_priority) verts2slot_priority[v] = m >= 0 ? cost[m] : INFINITY;
}

/* Appends e to a turn list (tlist, its length *tn) unless it is there already: edges2queued[e]
 * holds the stamp of the last list e went to. Returns whether it appended. */
inline int tcc_queue_once(int e, volatile __global uint* edges2queued, uint stamp, __global uint* tlist,
                          __global uint* tn) {
  if (atomic_xchg(edges2queued + e, stamp) == stamp) return 0;
  tlist[atomic_inc(tn)] = (uint)e;
  return 1;
}

/* Waiting lists of the greedy and matching selections (StageParams::waiting_lists): an edge e
 * whose blocker, an edge before it, is verts2slot[z] for a z within reach waits on z's list
 * (verts2waiting[z], then edges2next_waiting) instead of going to every next turn list until the
 * blocker decides. verts2slot[z] changes only when its edge decides, and then z is listed
 * (tcc_refused_ends, match_apply, greedy_block), so tcc_p1_turn wakes the list in the vertex part
 * of the round in which the blocker decided: e is in the next turn list, the first in which it
 * would have found its blocker decided. The same rounds and decisions, fewer visits (without the
 * lists most turn-list entries of the matching selection only find their blocker undecided). The
 * lists are written in the decisions and read in the vertex part, after them; a woken edge is on
 * no list and is visited before it waits again, so it is on one list at most. */
inline void tcc_wait_on(int e, int z, __global int* verts2waiting, __global int* edges2next_waiting) {
  edges2next_waiting[e] = atomic_xchg(verts2waiting + z, e);
}

/* The edges waiting for the slot of v, if any (verts2waiting: 0 for the selections without
 * waiting lists), to the next turn list, each once. */
inline void tcc_wake(int v, __global int* verts2waiting, __global const int* edges2next_waiting, __global uint* tlist,
                     __global uint* tn, volatile __global uint* edges2queued, uint round) {
  if (!verts2waiting) return;
  int w = verts2waiting[v];
  verts2waiting[v] = -1;
  for (; w >= 0; w = edges2next_waiting[w]) tcc_queue_once(w, edges2queued, round, tlist, tn);
}

inline void tcc_p1_turn(int v, __global const int* edges, __global const int* verts2slot, __global uint* tlist,
                        __global uint* tn, volatile __global uint* edges2queued, uint round,
                        __global const uchar* edges2verdict, __global uint* untested, __global int* verts2waiting,
                        __global const int* edges2next_waiting) {
  tcc_wake(v, verts2waiting, edges2next_waiting, tlist, tn, edges2queued, round);
  int m = verts2slot[v];
  if (m < 0 || verts2slot[edges[2 * m]] != m || verts2slot[edges[2 * m + 1]] != m) return;
  /* not when listed from its other end point */
  if (tcc_queue_once(m, edges2queued, round, tlist, tn) && edges2verdict[m] == TCC_VERDICT_UNKNOWN)
    atomic_inc(untested);
}

/* The vertex part of a round run in one work-group (lazy_p1_loop, greedy_loop): the slots of
 * the nd listed vertices anew, then the edges now first at both end points to the next turn
 * list; a barrier after each. */
inline void tcc_p1_vertex_part(uint nd, __global const uint* dlist, __global const uint* nb_off,
                               __global const int* nb_edge, __global const uchar* edges2state,
                               __global const double* order, __global int* verts2slot, __global const int* edges,
                               __global uint* tnext, __global uint* cnext, volatile __global uint* edges2queued,
                               uint round, __global const uchar* edges2verdict, __global uint* untested,
                               __global double* verts2slot_priority, __global int* verts2waiting,
                               __global const int* edges2next_waiting) {
  const uint lid = get_local_id(0), ls = get_local_size(0);
  for (uint i = lid; i < nd; i += ls)
    tcc_p1_recompute((int)dlist[i], nb_off, nb_edge, edges2state, order, verts2slot, verts2slot_priority);
  barrier(CLK_GLOBAL_MEM_FENCE);
  for (uint i = lid; i < nd; i += ls)
    tcc_p1_turn((int)dlist[i], edges, verts2slot, tnext, cnext, edges2queued, round + 1, edges2verdict, untested,
                verts2waiting, edges2next_waiting);
  barrier(CLK_GLOBAL_MEM_FENCE);
}

/* After a round of greedy_loop or match_loop (its vertex part done): the next round's turn list
 * becomes the current one; returns 1 when the loop stops because that list holds more than
 * max_n edges (resume[] = its length, its list, its round, for the host's per-round kernels),
 * else 0 with the counters cleared. The same values in every work item: a uniform exit. */
inline int tcc_loop_next(uint* n, int* cur, uint* round, uint max_n, __global uint* cnt, __global uint* resume) {
  *n = cnt[1 - *cur];
  barrier(CLK_GLOBAL_MEM_FENCE);
  *cur = 1 - *cur;
  ++*round;
  if (*n > max_n) {
    if (get_local_id(0) == 0) {
      resume[0] = *n;
      resume[1] = (uint)*cur;
      resume[2] = *round;
    }
    return 1;
  }
  if (get_local_id(0) == 0) cnt[0] = cnt[1] = cnt[2] = cnt[3] = cnt[4] = 0;
  barrier(CLK_GLOBAL_MEM_FENCE);
  return 0;
}

#ifdef TCC_PREFETCH_OK
/* CPU devices (the host sets TCC_PREFETCH) run a work-group's items one after another: start the
 * memory traffic of the next items' tests, whose loops otherwise wait for each of their tets in
 * turn: a load per step, each step one item nearer, so that each reads what the step before
 * fetched: five items ahead the edge's end points, four ahead their entries of vt_off, three ahead
 * the rings' lists (two lines each), two ahead the rings' tets, one ahead their points (the lists
 * and the offsets get steps of their own: loaded in the step of what they index, they stalled this
 * function). In match_decide (tets_are_dead non-null) also, two items ahead, tets_are_dead of each
 * tet and, at an end point on S (vflags), its row of tet_nbr, which a live test reads (whether it
 * is live is known only after the blocker scan, so for every item). With the quality guard
 * (q_min > 0), two items ahead each tet's quality at the iteration's start. Each of these loads
 * pays on a CPU device (measured in bench/README.md). Prefetches change no result: they write
 * nothing, and every load here reads what the items' own work may read, in a launch that does
 * not write it. */
inline void tcc_prefetch_test(uint i, uint n, __global const uint* tlist, __global const int* edges,
                              __global const uint* vt_off, __global const int* vt, __global const int* tets,
                              __global const double* pts, __global const uchar* tets_are_dead,
                              __global const int* tet_nbr, __global const uchar* vflags, double q_min,
                              __global const double* tets2quality) {
  if (i + 5 < n) __builtin_prefetch(edges + 2 * tlist[i + 5]);
  if (i + 4 < n) {
    int e4 = (int)tlist[i + 4];
    for (int s = 0; s < 2; ++s) __builtin_prefetch(vt_off + edges[2 * e4 + s]);
  }
  if (i + 3 < n) {
    int e3 = (int)tlist[i + 3];
    for (int s = 0; s < 2; ++s) {
      __global const int* l = vt + vt_off[edges[2 * e3 + s]];
      __builtin_prefetch(l);
      __builtin_prefetch(l + 16);
    }
  }
  if (i + 2 < n) {
    int e2 = (int)tlist[i + 2];
    for (int s = 0; s < 2; ++s) {
      int x = edges[2 * e2 + s];
      const int on_s = tets_are_dead && vflags[x];
      for (uint k = vt_off[x]; k < vt_off[x + 1]; ++k) {
        const int t = vt[k];
        __builtin_prefetch(tets + 4 * t);
        if (tets_are_dead) __builtin_prefetch(tets_are_dead + t);
        if (on_s) __builtin_prefetch(tet_nbr + 4 * t);
        if (q_min > 0.0) __builtin_prefetch(tets2quality + t);
      }
    }
  }
  if (i + 1 < n) {
    int e1 = (int)tlist[i + 1];
    for (int s = 0; s < 2; ++s) {
      int x = edges[2 * e1 + s];
      for (uint k = vt_off[x]; k < vt_off[x + 1]; ++k) {
        int4 q = vload4(vt[k], tets);
        __builtin_prefetch(pts + 3 * q.x);
        __builtin_prefetch(pts + 3 * q.y);
        __builtin_prefetch(pts + 3 * q.z);
        __builtin_prefetch(pts + 3 * q.w);
      }
    }
  }
}
#endif

/* The entry of a list of unknown length m <= the launch's size that work item takes: the local
 * id times the number of work-groups plus the group's id (a bijection on the launch), so the
 * first m entries are spread over every work-group. Indexed by the global id, they would all
 * fall in the first few groups, which the CPU drivers run on one thread: PoCL hands each thread
 * a range of consecutive work-groups (match_apply, launched over the turn list for the few
 * entries of it taken, ran no faster on two cores than on one). */
inline uint tcc_spread_index(void) { return (uint)(get_local_id(0) * get_num_groups(0) + get_group_id(0)); }

inline void tcc_greedy_list_vertex(int v, volatile __global uint* verts2listed, uint round, __global uint* dlist,
                                   __global uint* dn) {
  if (atomic_xchg(verts2listed + v, round) != round) dlist[atomic_inc(dn)] = (uint)v;
}

/* The tails of the greedy and matching decisions: a refused edge (a, b) lists both end points,
 * whose slots need their next edge; a waiting edge e goes to the next turn list once. */
inline void tcc_refused_ends(int a, int b, volatile __global uint* verts2listed, uint round, __global uint* dlist,
                             __global uint* dn) {
  tcc_greedy_list_vertex(a, verts2listed, round, dlist, dn);
  tcc_greedy_list_vertex(b, verts2listed, round, dlist, dn);
}
inline void tcc_requeue(int e, volatile __global uint* edges2queued, uint round, __global uint* tnext,
                        __global uint* tn) {
  tcc_queue_once(e, edges2queued, round + 1, tnext, tn);
}

/* The waiting edge e of the greedy and matching selections (tcc_greedy_decide, tcc_match_decide),
 * whose blocker is verts2slot[fz] (fz -1: the blocker found at an earlier visit, still undecided):
 * on fz's waiting list, woken when verts2slot[fz] decides (tcc_wake), or without waiting lists
 * (verts2waiting 0) in the next turn list. With the lists fz is not expected to be -1 (an edge is
 * on a list until its blocker decides); the turn list is then the correct fallback. */
inline void tcc_wait(int e, int fz, __global int* verts2waiting, __global int* edges2next_waiting,
                     volatile __global uint* edges2queued, uint round, __global uint* tnext, __global uint* tn) {
  if (verts2waiting && fz >= 0)
    tcc_wait_on(e, fz, verts2waiting, edges2next_waiting);
  else
    tcc_requeue(e, edges2queued, round, tnext, tn);
}

#endif
