/* The matching selection (tc::CollapseOptions::Matching): stages 3-5 of an iteration in one, the
 * admissible filter, the conflict detection and the collapses.
 *
 * The edges that taking the candidates one after another in priority order would take, where
 * each candidate is tested on the mesh with the collapses taken before it applied and only the
 * edges sharing an end point with a taken one are skipped: the taken edges are a matching, and
 * their collapses may share tets. The greedy selection (collapse_admissible.cl) skips every
 * edge within reach of a taken one instead (no two of its collapses touch a common tet), which
 * leaves most of what this one takes to later iterations (bench/bench_conflict_rule, measured in
 * bench/README.md), each of them a pass over the mesh.
 *
 * Rounds as in the greedy selection (verts2slot[x]: the first undecided candidate at x; an edge
 * first at both end points is in the turn list, and it decides once no undecided candidate before
 * it is within reach, an end point in N[a] or N[b]). Such an edge's test reads only ring(a) U
 * ring(b) and the positions of their vertices, N[a] U N[b], which only the collapses of edges
 * within reach change; those before it are decided, those after it wait for it. So the test
 * sees exactly the collapses taken before it (priority order), and the edges deciding in one
 * round touch disjoint stars. A round:
 *   match_decide  each turn-list edge e = (a, b): while a candidate before it is within reach
 *                 (edges2blocker[e], as in the greedy selection) it waits, after one volume test on
 *                 the mesh as it is (edges_early_tested[e]: a refusal is OUT at once, which frees
 *                 the way for the edges after it), on the waiting list of the vertex whose slot
 *                 holds the blocker (tcc_wait_on: back in a turn list when that edge decides); else
 *                 its tests (Q, volume, link) on the mesh as it is, IN or OUT. Read-only on the
 *                 mesh;
 *   match_apply   each edge taken this round is collapsed in place: the tets holding both end
 *                 points flagged in tets_are_dead and tet_nbr glued across them
 *                 (collapse_update.cl), the removed vertex renamed to the survivor in the tets of
 *                 its ring, the survivor placed (pts) with its fields (tcc_survivor_fields);
 *                 verts2collapse of both end points; the other candidates at a and b OUT, the
 *                 vertices whose slot they held listed;
 *   lazy_p1_recompute and lazy_p1_turns (collapse_admissible.cl) over the listed vertices.
 * A test is live (collapse_select.h) when an end point of a taken edge is in N[a] U N[b]
 * (verts2collapse): its star changed. Else the mesh around it is the iteration's start and the
 * verdict kept from the previous iteration (collapse_verdicts.cl) holds, as in the greedy
 * selection; a live verdict is not kept (the end points are dirty for the carry: their rings
 * change).
 * Decisions do not depend on the order of the work items: the turn lists are the same as a
 * set whatever the order, and each decision reads only what the rounds before it wrote.
 * What stays for the host (collapse_and_compact with in_place): compaction and renumbering. The
 * surface guard runs on the result (guard_surface.hpp: SurfaceGuard::run_applied); when it
 * refuses collapses the host restores the mesh and selects again.
 *
 * cnt[]: as in the greedy selection ([0], [1] the turn lists, [2] the vertex list, [4] the edges
 * taken this round). counters[1] taken, counters[4] tests run (volume tests; link tests are
 * not counted apart). */
#include "collapse_common.h"
#include "collapse_classify.h"
#include "collapse_select.h"

/* The test's arguments in the match kernels: those of the lazy filter's test (TCC_TEST_PARAMS,
 * in the same order; the mesh writable here, for match_apply), then the ridge and face
 * thresholds of the live classification and the removed tets. */
#define TCC_MATCH_PARAMS                                                                                               \
  __global int *tets, __global const uint *vt_off, __global const int *vt, __global int *tet_nbr,                      \
      __global const uint *nb_off, __global const int *nb, __global const int *nb_edge, __global const int *labels,    \
      int use_labels, __global double *pts, __global double *vfield, uint vfield_stride, __global const uchar *vflags, \
      __global const uchar *vclass, __global const uchar *eflags, int mode, int paper_rule, double eps_v,              \
      double q_min, double field_eps, __global const double *tets2quality, __global uchar *edges2dir,                  \
      __global uchar *edges2reason, __global uint *counters, __global uchar *edges2verdict, double bound,             \
      uint eps_col, __global double *edges2eps, double eps_r, double eps_f, __global uchar *tets_are_dead
#define TCC_MATCH_ARGS TCC_TEST_ARGS, eps_r, eps_f, tets_are_dead

/* Live: the S-faces through v owned by the tets of ring(v) that are left (tcc_owned_sface with
 * tet_nbr as it is now), as conn_surface_flags gathers them: the vertices after and before v
 * along each, its kind and unit normal. Returns their number, -1 when more than
 * TCC_MAX_VERTEX_SFACES. */
inline int tcc_live_sfaces(int v, __global const int* tets, __global const uint* vt_off, __global const int* vt,
                           __global const int* tet_nbr, __global const int* labels, int use_labels,
                           __global const double* pts, __global const uchar* tets_are_dead, int* after, int* before,
                           uchar* kind, double3* normal) {
  int fn = 0;
  for (uint i = vt_off[v]; i < vt_off[v + 1]; ++i) {
    int t = vt[i];
    if (tets_are_dead[t]) continue;
    __global const int* q = tets + 4 * t;
    int lv = tcc_local(tets, t, v);
    for (int f = 0; f < 4; ++f) {
      uint on_s;
      if (f == lv || !tcc_owned_sface(tet_nbr, labels, use_labels, t, f, &on_s)) continue;
      if (fn == TCC_MAX_VERTEX_SFACES) return -1;
      int w[3] = {q[TC_TET_FACES[f][0]], q[TC_TET_FACES[f][1]], q[TC_TET_FACES[f][2]]};
      int p = w[0] == v ? 0 : w[1] == v ? 1 : 2;
      after[fn] = w[(p + 1) % 3];
      before[fn] = w[(p + 2) % 3];
      kind[fn] = (uchar)on_s;
      normal[fn] = tcc_face_normal(pts, tets, t, f);
      ++fn;
    }
  }
  return fn;
}

/* Live: Q's direction bits of (a, b) (as tcc_lazy_dir) from the S flags, the classes and the
 * edge's flags computed now (collapse_classify.h, the rules of conn_surface_flags); -1 refuses.
 * *fa, *fb, *fe receive the flags for the link test. A vertex off S at the iteration's start
 * (vflags) is off S now: collapses keep S's topology, and one that is no end point of a
 * collapse gains no S-face (collapse_verdicts.cl). */
inline int tcc_live_dir(int a, int b, __global const int* tets, __global const uint* vt_off, __global const int* vt,
                        __global const int* tet_nbr, __global const int* labels, int use_labels,
                        __global const double* pts, __global const uchar* tets_are_dead, __global const uchar* vflags,
                        int mode, int paper_rule, double eps_r, double eps_f, uint* fa, uint* fb, uint* fe) {
  /* b first, then a in the same arrays (the edge's flags come from a's S-faces) */
  int after[TCC_MAX_VERTEX_SFACES], before[TCC_MAX_VERTEX_SFACES];
  uchar kind[TCC_MAX_VERTEX_SFACES];
  double3 normal[TCC_MAX_VERTEX_SFACES];
  int cls[2];
  uint fv[2], f = 0;
  for (int s = 1; s >= 0; --s) {
    const int v = s == 0 ? a : b;
    const int fn = vflags[v] ? tcc_live_sfaces(v, tets, vt_off, vt, tet_nbr, labels, use_labels, pts, tets_are_dead,
                                               after, before, kind, normal)
                             : 0;
    if (fn < 0) return -1;
    fv[s] = 0;
    for (int j = 0; j < fn; ++j) fv[s] |= kind[j];
    cls[s] = fn == 0 ? TCC_INTERIOR : tc_sf_class(after, before, normal, fn, eps_r, eps_f);
    if (s == 0 && fv[0] && fv[1]) {
      int ridge = 0;
      f = tc_sf_edge(b, after, before, kind, normal, fn, eps_r, &ridge) | (ridge ? TCC_RIDGE : 0u);
    }
  }
  *fa = fv[0];
  *fb = fv[1];
  *fe = f;
  return tcc_user_dir(tcc_predicate_q(a, b, fv[0], fv[1], f, cls[0], cls[1], mode, paper_rule), fv[0], fv[1], mode);
}

/* The tests of e = (a, b) on the mesh as it is: the volume test alone (full = 0: the early
 * test of a waiting edge, at the placement Q gave at the iteration's start) or Q, the volume
 * test and the link condition (full = 1); TCC_OK or
 * the refusal, with Q's direction bits in *dir. Not live: the lazy filter's test, with the
 * verdicts kept. */
inline uchar tcc_match_test(int e, int a, int b, int live, int full, int* dir, TCC_TEST_PARAMS, double eps_r,
                            double eps_f, __global const uchar* tets_are_dead) {
  if (!live) {
    *dir = tcc_lazy_dir(e, a, b, TCC_TEST_ARGS);
    /* a kept refusal by the link condition: the volume test, which runs before it, passed */
    if (!full)
      return edges2verdict[e] == TCC_REFUSED_LINK || tcc_lazy_volume(e, a, b, *dir, TCC_TEST_ARGS) ? TCC_OK
                                                                                                   : edges2verdict[e];
    return tcc_lazy_verdict(e, a, b, *dir, TCC_TEST_ARGS);
  }
  uint fa = 0, fb = 0, fe = 0;
  /* the early test at the placement of Q at the iteration's start (the classes of a changed S
   * are computed for the full test only: the early test only has to refuse most of what the
   * full one would, cheaply) */
  *dir = full ? tcc_live_dir(a, b, tets, vt_off, vt, tet_nbr, labels, use_labels, pts, tets_are_dead, vflags, mode,
                             paper_rule, eps_r, eps_f, &fa, &fb, &fe)
              : tcc_lazy_dir(e, a, b, TCC_TEST_ARGS);
  if (*dir < 0 || !tcc_user_allows(pts, vfield, vfield_stride, a, b)) return TCC_REFUSED_Q;
  atomic_inc(&counters[4]);
  uchar r = tcc_volume_test(a, b, *dir, tets, vt_off, vt, pts, vfield, vfield_stride, eps_v, q_min, field_eps, tets2quality, 1,
                            tets_are_dead);
  if (r != TCC_OK || !full) return r;
  return tcc_link_test(a, b, fa, fb, fe, tets, vt_off, vt, tet_nbr, nb_off, nb, nb_edge, labels, use_labels, vflags,
                       eflags, 1, tets_are_dead);
}

#ifdef TCC_PREFETCH_OK
/* The loads of the next items of match_decide besides their tests' (CPU devices, as
 * tcc_prefetch_test): two items ahead the edge's own entries, each in an array of its own (its
 * state, blocker, early test, priority, kept verdict and flags, whose loads it would wait for;
 * its writes, edges2reason, edges2dir, edges2queued and edges2next_waiting, gain nothing: measured
 * in bench/README.md); for the blocker scan four items ahead the entries of nb_off, three ahead the
 * lists N(a), N(b), one ahead the slot, its priority and verts2collapse of each vertex in them. */
inline void tcc_prefetch_decide(uint i, uint n, __global const uint* tlist, __global const int* edges,
                                __global const uint* nb_off, __global const int* nb,
                                __global const double* verts2slot_priority, __global const int* verts2slot,
                                __global const int* verts2collapse, __global const uchar* edges2state,
                                __global const int* edges2blocker, __global const uchar* edges_early_tested,
                                __global const double* edges2priority, __global const uchar* edges2verdict,
                                __global const uchar* eflags) {
  if (i + 2 < n) { /* the edge's own entries, each in an array of its own */
    const int e2 = (int)tlist[i + 2];
    __builtin_prefetch(edges2state + e2);
    __builtin_prefetch(edges2blocker + e2);
    __builtin_prefetch(edges_early_tested + e2);
    __builtin_prefetch(edges2priority + e2);
    __builtin_prefetch(edges2verdict + e2);
    __builtin_prefetch(eflags + e2);
  }
  if (i + 4 < n) {
    int e4 = (int)tlist[i + 4];
    for (int s = 0; s < 2; ++s) __builtin_prefetch(nb_off + edges[2 * e4 + s]);
  }
  if (i + 3 < n) {
    int e3 = (int)tlist[i + 3];
    for (int s = 0; s < 2; ++s) __builtin_prefetch(nb + nb_off[edges[2 * e3 + s]]);
  }
  if (i + 1 < n) {
    int e1 = (int)tlist[i + 1];
    for (int s = 0; s < 2; ++s) {
      int x = edges[2 * e1 + s];
      for (uint j = nb_off[x]; j < nb_off[x + 1]; ++j) {
        int z = nb[j];
        __builtin_prefetch(verts2slot_priority + z);
        __builtin_prefetch(verts2slot + z);
        __builtin_prefetch(verts2collapse + z);
      }
    }
  }
}
#endif

inline void tcc_match_decide(int e, __global const int* edges, __global const double* edges2priority,
                             __global const int* verts2slot, __global const double* verts2slot_priority,
                             __global int* edges2blocker, __global uchar* edges_early_tested,
                             __global uint* edges2round, __global uint* tnext, __global uint* tn,
                             volatile __global uint* edges2queued, uint round, __global uint* inlist,
                             __global uint* in_n, volatile __global uint* verts2listed, __global uint* dlist,
                             __global uint* dn, __global uchar* edges2state, __global const int* verts2collapse,
                             __global int* verts2waiting, __global int* edges2next_waiting, TCC_TEST_PARAMS,
                             double eps_r, double eps_f, __global const uchar* tets_are_dead) {
  if (edges2state[e] != TCC_UNDECIDED) return; /* OUT by match_apply: an end point was taken */
  int a = edges[2 * e], b = edges[2 * e + 1];
  int f = edges2blocker[e], fz = -1; /* fz: the vertex whose slot holds a blocker found now */
  int wait = f >= 0 && edges2state[f] == TCC_UNDECIDED;
  if (!wait) {
    /* the blocker: the last, in priority order, of the slots over N(a) and N(b) holding an edge
     * before e (when it decides, more of the others have: fewer scans than with the first);
     * and whether a taken edge changed the star (verts2collapse of a vertex of N(a) U N(b): its
     * star changed) */
    f = -1;
    int touched = 0;
    const double pe = edges2priority[e];
    double pf = 0.0;
    for (int s = 0; s < 2; ++s) {
      int x = s == 0 ? a : b;
      for (uint j = nb_off[x]; j < nb_off[x + 1]; ++j) {
        const int z = nb[j];
        touched |= verts2collapse[z] >= 0;
        const double pz = verts2slot_priority[z]; /* the slot's priority (slot_priority, tcc_p1_recompute) */
        if (pz > pe) continue;     /* after e, or no slot (INFINITY) */
        const int g = verts2slot[z];
        if (g == e || (pz == pe && g > e)) continue;
        if (f < 0 || pf < pz || (pf == pz && f < g)) {
          f = g;
          pf = pz;
          fz = z;
        }
      }
    }
    edges2blocker[e] = f;
    wait = f >= 0;
    /* the tests when e's turn has come; a waiting edge's early volume test, once (refused on the
     * mesh as it is now: OUT) */
    const int full = !wait;
    if (full || !edges_early_tested[e]) {
      edges_early_tested[e] = 1;
      int dir;
      const uchar r = tcc_match_test(e, a, b, touched, full, &dir, TCC_TEST_ARGS, eps_r, eps_f, tets_are_dead);
      if (r == TCC_OK && full) {
        edges2reason[e] = TCC_OK;
        edges2dir[e] = (uchar)dir;
        edges2state[e] = TCC_IN;
        edges2round[e] = round;
        atomic_inc(&counters[1]);
        inlist[atomic_inc(in_n)] = (uint)e;
        return;
      }
      if (r != TCC_OK) { /* refused: a and b need their next edge */
        edges2reason[e] = r;
        edges2state[e] = TCC_OUT;
        tcc_refused_ends(a, b, verts2listed, round, dlist, dn);
        return;
      }
    }
  }
  tcc_wait(e, fz, verts2waiting, edges2next_waiting, edges2queued, round, tnext, tn);
}

__kernel void match_decide(uint n, uint cur, __global const uint* tlist, __global uint* tnext, __global uint* cnt,
                           __global const int* edges, __global const double* edges2priority,
                           __global const int* verts2slot, __global const double* verts2slot_priority,
                           __global int* edges2blocker, __global uchar* edges_early_tested, __global uint* edges2round,
                           volatile __global uint* edges2queued, uint round, __global uint* inlist,
                           volatile __global uint* verts2listed, __global uint* dlist, __global uchar* edges2state,
                           __global int* verts2collapse, int waiting, __global int* verts2waiting,
                           __global int* edges2next_waiting, TCC_MATCH_PARAMS) {
  uint i = get_global_id(0);
  if (i >= n) return;
#ifdef TCC_PREFETCH_OK
  tcc_prefetch_test(i, n, tlist, edges, vt_off, vt, tets, pts, tets_are_dead, tet_nbr, vflags, q_min, tets2quality);
  tcc_prefetch_decide(i, n, tlist, edges, nb_off, nb, verts2slot_priority, verts2slot, verts2collapse, edges2state,
                      edges2blocker, edges_early_tested, edges2priority, edges2verdict, eflags);
#endif
  tcc_match_decide((int)tlist[i], edges, edges2priority, verts2slot, verts2slot_priority, edges2blocker,
                   edges_early_tested, edges2round, tnext, cnt + (1 - cur), edges2queued, round, inlist, cnt + 4,
                   verts2listed, dlist, cnt + 2, edges2state, verts2collapse, waiting ? verts2waiting : 0,
                   edges2next_waiting, TCC_MATCH_ARGS);
}

/* Removed tet d = (x, y, c, d') of the collapse of y onto x: the tet X across its face opposite y
 * (holding x) and the tet Y across its face opposite x (holding y) become neighbours, as
 * tet_nbr_update glues them through a compaction (collapse_update.cl); a boundary on one side
 * (-1, or -2: several tets, invalid input) becomes the other's. */
inline void tcc_glue_across(int d, int x, int y, __global const int* tets, __global int* tet_nbr) {
  int X = tet_nbr[4 * d + tcc_local(tets, d, y)], Y = tet_nbr[4 * d + tcc_local(tets, d, x)];
  for (int k = 0; X >= 0 && k < 4; ++k)
    if (tet_nbr[4 * X + k] == d) {
      tet_nbr[4 * X + k] = Y;
      break;
    }
  for (int k = 0; Y >= 0 && k < 4; ++k)
    if (tet_nbr[4 * Y + k] == d) {
      tet_nbr[4 * Y + k] = X;
      break;
    }
}

/* The collapse of the taken edge e, in place (see the top), then the other candidates at its
 * end points OUT. Its star is disjoint from those of the other edges taken in the round. */
inline void tcc_match_apply(int e, __global const int* edges, __global const int* verts2slot,
                            volatile __global uint* verts2listed, uint round, __global uint* dlist, __global uint* dn,
                            __global uchar* edges2state, __global int* verts2collapse, __global int* tets2killer,
                            TCC_MATCH_PARAMS) {
  const int v0 = edges[2 * e], v1 = edges[2 * e + 1];
  const uint d = edges2dir[e];
  const int y = (d & TCC_DIR_REMOVE_V1) ? v1 : v0, x = (d & TCC_DIR_REMOVE_V1) ? v0 : v1;
  const double3 p = tcc_placement(pts, vfield, vfield_stride, v0, v1, d);
  tcc_survivor_fields(x, v0, v1, d, p, pts, vfield_stride, vfield, vfield, (uint)x);
  vstore3(p, x, pts);
  verts2collapse[v0] = e;
  verts2collapse[v1] = e;
  for (uint i = vt_off[x]; i < vt_off[x + 1]; ++i) { /* the tets of the edge go */
    int t = vt[i];
    if (tets_are_dead[t] || !tcc_has(tets, t, y)) continue;
    tets_are_dead[t] = 1;
    tets2killer[t] = e;
    tcc_glue_across(t, x, y, tets, tet_nbr);
  }
  for (uint i = vt_off[y]; i < vt_off[y + 1]; ++i) { /* y's other tets are x's */
    int t = vt[i];
    if (tets_are_dead[t]) continue;
    for (int k = 0; k < 4; ++k)
      if (tets[4 * t + k] == y) tets[4 * t + k] = x;
  }
  for (int s = 0; s < 2; ++s) {
    int z = s == 0 ? v0 : v1;
    tcc_greedy_list_vertex(z, verts2listed, round, dlist, dn); /* its slot was e */
    for (uint j = nb_off[z]; j < nb_off[z + 1]; ++j) {
      int g = nb_edge[j];
      if (g == e || edges2state[g] != TCC_UNDECIDED) continue;
      edges2state[g] = TCC_OUT; /* two taken edges may both do this: the same write */
      int u = nb[j];
      if (verts2slot[u] == g) tcc_greedy_list_vertex(u, verts2listed, round, dlist, dn);
    }
  }
}

#ifdef TCC_PREFETCH_OK
/* The loads of the next items of a work item of match_apply (CPU devices, as tcc_prefetch_test;
 * the next item is `step` entries on, tcc_spread_index): two items ahead the rings' lists and the
 * edge lists N(a), N(b); one ahead the rings' tets, their tets_are_dead and rows of tet_nbr (the
 * removed tets' are glued across), and the edges' states (each read otherwise waits for memory). */
inline void tcc_prefetch_apply(uint i, uint n, uint step, __global const uint* inlist, __global const int* edges,
                               __global const uint* vt_off, __global const int* vt, __global const int* tets,
                               __global const uchar* tets_are_dead, __global const int* tet_nbr,
                               __global const uint* nb_off, __global const int* nb_edge,
                               __global const uchar* edges2state) {
  if (i + 2 * step < n) {
    int e2 = (int)inlist[i + 2 * step];
    for (int s = 0; s < 2; ++s) {
      int x = edges[2 * e2 + s];
      __builtin_prefetch(vt + vt_off[x]);
      __builtin_prefetch(nb_edge + nb_off[x]);
    }
  }
  if (i + step < n) {
    int e1 = (int)inlist[i + step];
    for (int s = 0; s < 2; ++s) {
      int x = edges[2 * e1 + s];
      for (uint k = vt_off[x]; k < vt_off[x + 1]; ++k) {
        int t = vt[k];
        __builtin_prefetch(tets + 4 * t);
        __builtin_prefetch(tets_are_dead + t);
        __builtin_prefetch(tet_nbr + 4 * t);
      }
      for (uint j = nb_off[x]; j < nb_off[x + 1]; ++j) __builtin_prefetch(edges2state + nb_edge[j]);
    }
  }
}
#endif

__kernel void match_apply(__global const uint* inlist, __global uint* cnt, __global const int* edges,
                          __global const int* verts2slot, volatile __global uint* verts2listed, uint round,
                          __global uint* dlist, __global uchar* edges2state, __global int* verts2collapse,
                          __global int* tets2killer, TCC_MATCH_PARAMS) {
  uint i = tcc_spread_index();
  const uint n = cnt[4];
  if (i >= n) return;
#ifdef TCC_PREFETCH_OK
  tcc_prefetch_apply(i, n, get_num_groups(0), inlist, edges, vt_off, vt, tets, tets_are_dead, tet_nbr, nb_off, nb_edge,
                     edges2state);
#endif
  tcc_match_apply((int)inlist[i], edges, verts2slot, verts2listed, round, dlist, cnt + 2, edges2state, verts2collapse,
                  tets2killer, TCC_MATCH_ARGS);
}

/* The remaining rounds in one work-group, once the turn list is short (as greedy_loop). */
__kernel void match_loop(uint n, int cur, uint round, __global uint* t0, __global uint* t1, __global uint* cnt,
                         __global const int* edges, __global const double* edges2priority, __global int* verts2slot,
                         __global double* verts2slot_priority, __global int* edges2blocker,
                         __global uchar* edges_early_tested, __global uint* edges2round,
                         volatile __global uint* edges2queued, __global uint* inlist,
                         volatile __global uint* verts2listed, __global uint* dlist, __global uchar* edges2state,
                         __global int* verts2collapse, __global int* tets2killer, uint max_n, __global uint* resume,
                         int waiting, __global int* verts2waiting, __global int* edges2next_waiting, TCC_MATCH_PARAMS) {
  const uint lid = get_local_id(0), ls = get_local_size(0);
  if (!waiting) verts2waiting = 0;
  while (n > 0) {
    __global uint* tl = cur ? t1 : t0;
    __global uint* tnext = cur ? t0 : t1;
    __global uint* cnext = cnt + (1 - cur);
    for (uint i = lid; i < n; i += ls)
      tcc_match_decide((int)tl[i], edges, edges2priority, verts2slot, verts2slot_priority, edges2blocker,
                       edges_early_tested, edges2round, tnext, cnext, edges2queued, round, inlist, cnt + 4,
                       verts2listed, dlist, cnt + 2, edges2state, verts2collapse, verts2waiting, edges2next_waiting,
                       TCC_MATCH_ARGS);
    barrier(CLK_GLOBAL_MEM_FENCE);
    const uint nin = cnt[4];
    for (uint i = lid; i < nin; i += ls)
      tcc_match_apply((int)inlist[i], edges, verts2slot, verts2listed, round, dlist, cnt + 2, edges2state,
                      verts2collapse, tets2killer, TCC_MATCH_ARGS);
    barrier(CLK_GLOBAL_MEM_FENCE);
    tcc_p1_vertex_part(cnt[2], dlist, nb_off, nb_edge, edges2state, edges2priority, verts2slot, edges, tnext, cnext,
                       edges2queued, round, edges2verdict, cnt + 3, verts2slot_priority, verts2waiting,
                       edges2next_waiting);
    if (tcc_loop_next(&n, &cur, &round, max_n, cnt, resume)) return;
  }
}

/* --- Collapses the surface guard refuses (SurfaceGuard::run_applied) are undone, with every
 * taken collapse whose tests saw one of them: the taken ones of a later round within reach of
 * one undone, and so on (match_undo_reach, match_undo_grow). The others keep their collapses:
 * each saw only collapses that stay. Undone in the reverse order of their rounds (the host
 * sorts them), each the inverse of match_apply; the guard then tests the result again. --- */

/* verts2first_round[v]: the first round of the listed collapses with v in N[a] U N[b]. */
__kernel void match_undo_reach(uint n, __global const uint* list, __global const int* edges,
                               __global const uint* nb_off, __global const int* nb, __global const uint* edges2round,
                               volatile __global uint* verts2first_round) {
  uint i = get_global_id(0);
  if (i >= n) return;
  int d = (int)list[i];
  uint r = edges2round[d];
  for (int s = 0; s < 2; ++s) {
    int x = edges[2 * d + s];
    atomic_min(verts2first_round + x, r);
    for (uint j = nb_off[x]; j < nb_off[x + 1]; ++j) atomic_min(verts2first_round + nb[j], r);
  }
}

/* The taken collapses (taken[0 .. n)) not undone yet with an end point reached in an earlier
 * round: undone too (listed). */
__kernel void match_undo_grow(uint n, __global const uint* taken, __global const int* edges,
                              __global const uint* edges2round, __global const uint* verts2first_round,
                              __global uchar* edges_to_undo, __global uint* list, __global uint* count) {
  uint i = get_global_id(0);
  if (i >= n) return;
  int h = (int)taken[i];
  if (edges_to_undo[h]) return;
  uint r = edges2round[h];
  if (verts2first_round[edges[2 * h]] < r || verts2first_round[edges[2 * h + 1]] < r) {
    edges_to_undo[h] = 1;
    list[atomic_inc(count)] = (uint)h;
  }
}

/* Removed tet d back: its neighbours across its faces point to it again (each at its face
 * shared with d: the one opposite its vertex that d does not hold). */
inline void tcc_unglue(int d, __global const int* tets, __global int* tet_nbr) {
  for (int f = 0; f < 4; ++f) {
    int m = tet_nbr[4 * d + f];
    if (m < 0) continue;
    for (int k = 0; k < 4; ++k)
      if (!tcc_has(tets, d, tets[4 * m + k])) {
        tet_nbr[4 * m + k] = d;
        break;
      }
  }
}

/* The n collapses of order[] undone one after another (one work item: they are few, and in the
 * order given, the reverse of their rounds). edges_are_refused[g]: by the guard (its reason
 * TCC_REFUSED_SURFACE) or undone with one (TCC_UNTESTED). */
__kernel void match_undo(uint n, __global const uint* order, __global const uchar* edges_are_refused,
                         __global const int* edges, __global const uchar* edges2dir, __global int* tets,
                         __global const uint* vt_off, __global const int* vt, __global int* tet_nbr,
                         __global uchar* tets_are_dead, __global int* tets2killer, __global double* pts,
                         __global double* vfield, uint vfield_stride, __global const double* pts0,
                         __global const double* vfield0, __global int* verts2collapse, __global uchar* edges2state,
                         __global uint* edges_are_final, __global uchar* edges2reason) {
  if (get_global_id(0) != 0) return;
  for (uint i = 0; i < n; ++i) {
    const int g = (int)order[i];
    const int v0 = edges[2 * g], v1 = edges[2 * g + 1];
    const uint d = edges2dir[g];
    const int y = (d & TCC_DIR_REMOVE_V1) ? v1 : v0, x = (d & TCC_DIR_REMOVE_V1) ? v0 : v1;
    for (uint k = vt_off[y]; k < vt_off[y + 1]; ++k) { /* y's tets that are left: y again */
      int t = vt[k];
      if (tets_are_dead[t]) continue;
      for (int j = 0; j < 4; ++j)
        if (tets[4 * t + j] == x) tets[4 * t + j] = y;
    }
    for (uint k = vt_off[x]; k < vt_off[x + 1]; ++k) { /* the tets g removed */
      int t = vt[k];
      if (!tets_are_dead[t] || tets2killer[t] != g) continue;
      tets_are_dead[t] = 0;
      tets2killer[t] = -1;
      tcc_unglue(t, tets, tet_nbr);
    }
    for (int c = 0; c < 3; ++c) pts[3 * x + c] = pts0[3 * x + c];
    for (uint c = 0; c < vfield_stride; ++c) vfield[(size_t)x * vfield_stride + c] = vfield0[(size_t)x * vfield_stride + c];
    verts2collapse[v0] = -2; /* no collapse, but dirty for the carry (verdict_dirty): g's tests must run again */
    verts2collapse[v1] = -2;
    edges2state[g] = TCC_OUT;
    edges_are_final[g] = 0u;
    edges2reason[g] = edges_are_refused[g] ? TCC_REFUSED_SURFACE : TCC_UNTESTED;
  }
}
