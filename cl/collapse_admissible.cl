/* Stage 3 of a collapse iteration: the admissible filter over marked edges (paper Sec. 3.2).
 *
 * Checks, cheapest first; the first that fails is recorded in edges2reason[e]:
 *   Q       boundary protection by mode (strict / features / free), which also decides the
 *           survivor and the placement (edges2dir, see collapse_common.h);
 *   volume  every tet of ring(a) U ring(b) that survives, with the moved vertex at the placement,
 *           has a volume of at least eps_v (and, with the quality guard, the quality rule);
 *           before the link condition: it costs less, and it refuses most of the edges that
 *           are refused;
 *   link    the link condition of Dey et al. for 3-manifolds with boundary, the boundary closed
 *           by a virtual vertex w joined to every S-face (boundary and material interfaces):
 *           (i)   every common neighbour of a and b is a vertex of lk(ab), and if a and b are
 *                 both on S, ab is an S-edge (w is in lk(a) and lk(b));
 *           (ii)  for triangles (a,c,d) and (b,c,d) the tet (a,b,c,d) exists; for S-edges
 *                 (a,c) and (b,c) the triangle (a,b,c) is an S-face;
 *           (iii) no tets (a,c,d,e) and (b,c,d,e); no S-faces (a,c,d) and (b,c,d).
 * Lists larger than TCC_MAX_LINK refuse the edge (conservative; never reached on real meshes). */
#include "collapse_common.h"
#include "collapse_select.h"

/* tets2quality[t] = tc_tet_quality of tet t (the quality guard's "before", once per iteration
 * instead of once per test that looks at t). With only_missing, the entries carried through
 * the compaction (tet_quality_carry) are kept and only those marked -1 are computed. */
__kernel void tet_quality(uint nt, __global const int* tets, __global const double* pts, __global double* tets2quality,
                          int only_missing) {
  uint t = get_global_id(0);
  if (t >= nt || (only_missing && tets2quality[t] >= 0.0)) return;
  __global const int* q = tets + 4 * t;
  tets2quality[t] = tc_tet_quality(tc_point(pts, q[0]), tc_point(pts, q[1]), tc_point(pts, q[2]), tc_point(pts, q[3]));
}

/* Through the compaction: a kept tet none of whose vertices is an end point of a collapse
 * (verts2collapse) has the same vertices at the same places, so the same quality; the others get -1
 * (computed again by tet_quality). Indices are the previous mesh's. */
__kernel void tet_quality_carry(uint nt, __global const int* tets, __global const uint* keep,
                                __global const uint* newidx, __global const int* verts2collapse,
                                __global const double* tets2quality, __global double* tets2quality_next) {
  uint t = get_global_id(0);
  if (t >= nt || !keep[t]) return;
  __global const int* q = tets + 4 * t;
  int changed =
      verts2collapse[q[0]] >= 0 || verts2collapse[q[1]] >= 0 || verts2collapse[q[2]] >= 0 || verts2collapse[q[3]] >= 0;
  tets2quality_next[newidx[t]] = changed ? -1.0 : tets2quality[t];
}

__kernel void admissible(uint ne, __global const int* edges, __global const uint* edges_are_marked,
                         __global const int* tets, __global const uint* vt_off, __global const int* vt,
                         __global const int* tet_nbr, __global const uint* nb_off, __global const int* nb,
                         __global const int* nb_edge, __global const int* labels, int use_labels,
                         __global const double* pts, __global const double* vfield, uint vfield_stride,
                         __global const uchar* vflags, __global const uchar* vclass, __global const uchar* eflags,
                         int mode, int paper_rule, double eps_v, double q_min, __global const double* tets2quality,
                         __global uint* edges_are_admissible, __global uchar* edges2dir, __global uchar* edges2reason,
                         __global uint* counters) {
  uint e = get_global_id(0);
  if (e >= ne) return;
  edges_are_admissible[e] = 0u;
  edges2dir[e] = 0;
  if (!edges_are_marked[e]) {
    edges2reason[e] = TCC_NOT_MARKED;
    return;
  }
  int a = edges[2 * e], b = edges[2 * e + 1];
  uint fa = vflags[a], fb = vflags[b], fe = eflags[e];
  int dir = tcc_user_dir(tcc_predicate_q(a, b, fa, fb, fe, vclass[a], vclass[b], mode, paper_rule), fa, fb, mode);
  if (dir < 0 || !tcc_user_allows(pts, vfield, vfield_stride, a, b)) {
    edges2reason[e] = TCC_REFUSED_Q;
    return;
  }
  atomic_inc(&counters[5]);  /* passed Q: IterationStats::candidates */
  uchar r = tcc_link_and_volume(a, b, fa, fb, fe, dir, tets, vt_off, vt, tet_nbr, nb_off, nb, nb_edge, labels,
                                use_labels, pts, vfield, vfield_stride, vflags, eflags, eps_v, q_min, tets2quality);
  edges2reason[e] = r;
  if (r != TCC_OK) return;
  edges_are_admissible[e] = 1u;
  edges2dir[e] = (uchar)dir;
  atomic_inc(&counters[1]);
}

/* --- Lazy admissible filter fused with conflict pass 1 ---
 *
 * Pass 1 keeps an admissible edge when every admissible edge before it in (cost, index) order
 * that shares a vertex with it is dropped. Whether a cheaper rival is admissible matters only
 * while that rival is undecided, so the expensive link and volume tests run only on edges all
 * of whose cheaper candidate rivals are already decided: such an edge is IN when it passes the
 * tests, OUT (refused) otherwise; an edge with a cheaper IN rival is OUT without a test. The
 * fixpoint is the same as testing every marked edge and then running conflict pass 1 (the
 * test result of an edge is never looked at before its own turn), at the cost of testing only
 * the edges whose turn comes: the winners and the refused edges that would have won.
 * States as in collapse_conflict.cl; counters[1] admissible (tested and passed), counters[4]
 * tested, counters[5] passed Q. */

/* Q for every edge: candidates (marked, passing Q) are UNDECIDED with edges_are_candidates[e] = 1,
 * except those whose refusal is carried from an earlier iteration (edges2verdict): OUT at once.
 * Same fixpoint: a refused edge ends OUT whatever its rivals do, and the others only wait for it to
 * be decided. In the late iterations nearly every candidate is such an edge, and the rounds then
 * see only the few that can still collapse. With keep_refused (the matching selection, whose early
 * tests make its result depend on when each edge's turn comes) those edges stay candidates, their
 * tests given by the verdicts: the rounds are then the same as when every verdict is computed
 * anew (CollapseOptions::reuse_across_iterations off), and so is the result. */
/* lazy_init for edge e; returns whether it passes Q (counted in counters[5]). */
inline uint tcc_lazy_init_edge(uint e, __global const int* edges, __global const uint* edges_are_marked,
                               __global const uchar* vflags, __global const uchar* vclass, __global const uchar* eflags,
                               int mode, int paper_rule, __global const double* pts, __global const double* vfield,
                               uint vfield_stride, __global uchar* edges2state, __global uchar* edges2dir,
                               __global uchar* edges2reason, __global uint* edges_are_candidates, int restrict_clean,
                               __global const uchar* prev_verts_are_dirty, __global const uchar* edges2verdict,
                               __global const double* edges2order, volatile __global int* verts2slot,
                               int keep_refused) {
  edges2dir[e] = 0;
  edges_are_candidates[e] = 0u;
  edges2state[e] = TCC_OUT;
  if (!edges_are_marked[e]) {
    edges2reason[e] = TCC_NOT_MARKED;
    return 0u;
  }
  int a = edges[2 * e], b = edges[2 * e + 1];
  /* a later selection round: only edges away from the collapses chosen so far */
  if (restrict_clean && (prev_verts_are_dirty[a] || prev_verts_are_dirty[b])) return 0u;
  if (tcc_predicate_q(a, b, vflags[a], vflags[b], eflags[e], vclass[a], vclass[b], mode, paper_rule) < 0 ||
      !tcc_user_allows(pts, vfield, vfield_stride, a, b)) {
    edges2reason[e] = TCC_REFUSED_Q;
    return 0u;
  }
  uchar r = edges2verdict[e];
  if (r != TCC_VERDICT_UNKNOWN && r != TCC_OK && r != TCC_VOLUME_OK && !keep_refused) {
    edges2reason[e] = r;
    return 1u;
  }
  edges2reason[e] = TCC_UNTESTED;
  edges2state[e] = TCC_UNDECIDED;
  edges_are_candidates[e] = 1u;
  /* pass 1's first claims (lazy_p1_first_turns reads them): verts2slot[] is -1 on entry */
  tcc_claim(verts2slot + a, (int)e, edges2order);
  tcc_claim(verts2slot + b, (int)e, edges2order);
  return 1u;
}

__kernel void lazy_init(uint ne, __global const int* edges, __global const uint* edges_are_marked,
                        __global const uchar* vflags, __global const uchar* vclass, __global const uchar* eflags,
                        int mode, int paper_rule, __global const double* pts, __global const double* vfield,
                        uint vfield_stride, __global uchar* edges2state, __global uchar* edges2dir,
                        __global uchar* edges2reason, __global uint* edges_are_candidates, __global uint* counters,
                        int restrict_clean, __global const uchar* prev_verts_are_dirty,
                        __global const uchar* edges2verdict, __global const double* edges2order,
                        volatile __global int* verts2slot, int keep_refused) {
  __local uint group_passed_q;
  uint e = get_global_id(0);
  uint q = e < ne ? tcc_lazy_init_edge(e, edges, edges_are_marked, vflags, vclass, eflags, mode, paper_rule, pts,
                                       vfield, vfield_stride, edges2state, edges2dir, edges2reason,
                                       edges_are_candidates, restrict_clean, prev_verts_are_dirty, edges2verdict,
                                       edges2order, verts2slot, keep_refused)
                  : 0u;
  tcc_group_count(q, &group_passed_q, &counters[5]);
}

/* The turn of edge e in the lazy filter: its link and volume tests (or the verdict kept),
 * then IN (verts2collapse of both end points; returns 1) or OUT (0). */
inline int tcc_lazy_decide(int e, __global const int* edges, __global uchar* edges2state, __global int* verts2collapse,
                           TCC_TEST_PARAMS) {
  int a = edges[2 * e], b = edges[2 * e + 1];
  int dir = tcc_lazy_dir(e, a, b, TCC_TEST_ARGS);
  uchar r = tcc_lazy_verdict(e, a, b, dir, TCC_TEST_ARGS);
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

/* Pass 1 of the lazy filter, driven by the vertices whose first undecided edge changed.
 *
 * verts2slot[v] is the first undecided candidate at v in (cost, index) order (-1 when none), and
 * an edge whose turn comes (verts2slot[a] == verts2slot[b] == e: every edge before it at a and b
 * is OUT) is in the turn list of the round. A round (lazy_p1_decide, lazy_p1_recompute,
 * lazy_p1_turns):
 *   decide     each edge of the turn list is tested (tcc_lazy_decide): IN makes every undecided
 *              edge at a and b OUT and lists their other end points where such an edge was
 *              first; OUT lists a and b;
 *   recompute  verts2slot[v] anew for the listed vertices (duplicates compute the same value);
 *   turns      the edges now first at both end points, each once (edges2queued[e] = round); in the
 *              greedy and matching selections also the edges waiting on the listed vertices
 *              (tcc_wake, collapse_select.h).
 * Only the vertices where something was decided are looked at, so a pass costs about the
 * number of candidates times the vertex degree, where rescanning every undecided candidate in
 * every round (pass1_claim + conflict_pass1_decide) costs that times the number of rounds (many on
 * large meshes). Same decisions as those rounds: a decision depends only on final decisions of
 * edges before it (see collapse_conflict.cl). Turn-list edges share no vertex, so their
 * decisions do not race. The first turn list: the claims of lazy_init, then lazy_p1_first_turns.
 *
 * cnt[0]: the length of the first turn list; cnt[3]: how many of its edges have no verdict
 * carried from an earlier iteration (those are tested; the host runs the rounds in one
 * work-group once few are). Over every edge (edges_are_candidates[e]: a candidate), which costs
 * less than compacting the candidates first. */
__kernel void lazy_p1_first_turns(uint ne, __global const uint* edges_are_candidates, __global const int* edges,
                                  __global const int* verts2slot, __global uint* tlist, __global uint* cnt,
                                  __global const uchar* edges2verdict) {
  uint e = get_global_id(0);
  if (e >= ne || !edges_are_candidates[e]) return;
  if (verts2slot[edges[2 * e]] != (int)e || verts2slot[edges[2 * e + 1]] != (int)e) return;
  tlist[atomic_inc(cnt)] = e;
  if (edges2verdict[e] == TCC_VERDICT_UNKNOWN) atomic_inc(cnt + 3);
}

inline void tcc_p1_decide(int e, __global const int* edges, __global uchar* edges2state, __global int* verts2collapse,
                          __global const int* verts2slot, __global uint* dlist, __global uint* dn, TCC_TEST_PARAMS) {
  int a = edges[2 * e], b = edges[2 * e + 1];
  if (tcc_lazy_decide(e, edges, edges2state, verts2collapse, TCC_TEST_ARGS)) {
    for (int s = 0; s < 2; ++s) {
      int x = s == 0 ? a : b;
      for (uint j = nb_off[x]; j < nb_off[x + 1]; ++j) {
        int g = nb_edge[j];
        if (g == e || edges2state[g] != TCC_UNDECIDED) continue;
        edges2state[g] = TCC_OUT; /* two IN edges may both do this: the same write */
        /* the other end point y of g needs a new first edge only when g was it (slots change
         * in lazy_p1_recompute only, so this read does not race) */
        int y = nb[j];
        if (verts2slot[y] == g) dlist[atomic_inc(dn)] = (uint)y;
      }
    }
  } else {
    uint base = atomic_add(dn, 2u);
    dlist[base] = (uint)a;
    dlist[base + 1] = (uint)b;
  }
}

/* Per-round kernels: cnt[0], cnt[1] count the two turn lists, cnt[2] the vertex list, cnt[3]
 * the edges of the new turn list that will be tested (no carried verdict). */
__kernel void lazy_p1_decide(uint n, __global const uint* tlist, __global const int* edges, __global uchar* edges2state,
                             __global int* verts2collapse, __global const int* verts2slot, __global uint* dlist,
                             __global uint* cnt, TCC_TEST_PARAMS) {
  uint i = get_global_id(0);
  if (i >= n) return;
#ifdef TCC_PREFETCH_OK
  tcc_prefetch_test(i, n, tlist, edges, vt_off, vt, tets, pts, TCC_NO_DEAD, tet_nbr, vflags, q_min, tets2quality);
#endif
  tcc_p1_decide((int)tlist[i], edges, edges2state, verts2collapse, verts2slot, dlist, cnt + 2, TCC_TEST_ARGS);
}

__kernel void lazy_p1_recompute(uint n, __global const uint* dlist, __global const uint* nb_off,
                                __global const int* nb_edge, __global const uchar* edges2state,
                                __global const double* edges2order, __global int* verts2slot,
                                __global double* verts2slot_priority, int with_slotp) {
  /* spread (tcc_spread_index): the list is the vertices listed by the decisions, then by
   * match_apply or greedy_block, in the order their atomics gave; spread over the work-groups
   * the cores share it better than indexed by the global id (measured in bench/README.md) */
  const uint i = tcc_spread_index(), st = (uint)get_num_groups(0);
  if (i >= n) return;
#ifdef TCC_PREFETCH_OK
  /* as in lazy_p1_decide: the next items' edge lists, then their costs */
  if (i + 2 * st < n) __builtin_prefetch(nb_edge + nb_off[dlist[i + 2 * st]]);
  if (i + st < n) {
    int v1 = (int)dlist[i + st];
    for (uint j = nb_off[v1]; j < nb_off[v1 + 1]; ++j) __builtin_prefetch(edges2order + nb_edge[j]);
  }
#endif
  tcc_p1_recompute((int)dlist[i], nb_off, nb_edge, edges2state, edges2order, verts2slot,
                   with_slotp ? verts2slot_priority : 0);
}

__kernel void lazy_p1_turns(uint n, __global const uint* dlist, __global const int* edges,
                            __global const int* verts2slot, __global uint* tlist, __global uint* cnt, uint which,
                            __global uint* edges2queued, uint round, __global const uchar* edges2verdict, int waiting,
                            __global int* verts2waiting, __global const int* edges2next_waiting) {
  uint i = get_global_id(0);
  if (i >= n) return;
  tcc_p1_turn((int)dlist[i], edges, verts2slot, tlist, cnt + which, edges2queued, round, edges2verdict, cnt + 3,
              waiting ? verts2waiting : 0, edges2next_waiting);
}

/* The remaining rounds in one work-group, once the turn list is short: a round then costs
 * barriers instead of launches and read-backs, which cost far more. Entry: the n edges
 * of turn list `cur` (t0 or t1) are round `round`'s; cnt[0..3] (turn-list lengths,
 * vertex-list length, untested turns) are 0. Once a new turn list has more than max_tests
 * edges to test (a single work-group would test them one after another), the loop stops and
 * leaves resume[0..2] = (its length, its list, its round) for the host's per-round kernels;
 * resume[0] stays 0 when every round is done. */
__kernel void lazy_p1_loop(uint n, int cur, uint round, __global uint* t0, __global uint* t1, __global uint* cnt,
                           __global uint* dlist, __global uint* edges2queued, __global const int* edges,
                           __global const double* edges2cost, __global int* verts2slot, __global uchar* edges2state,
                           __global int* verts2collapse, uint max_tests, __global uint* resume, TCC_TEST_PARAMS) {
  const uint lid = get_local_id(0), ls = get_local_size(0);
  while (n > 0) {
    __global uint* tl = cur ? t1 : t0;
    __global uint* tnext = cur ? t0 : t1;
    __global uint* cnext = cnt + (1 - cur);
    for (uint i = lid; i < n; i += ls)
      tcc_p1_decide((int)tl[i], edges, edges2state, verts2collapse, verts2slot, dlist, cnt + 2, TCC_TEST_ARGS);
    barrier(CLK_GLOBAL_MEM_FENCE);
    tcc_p1_vertex_part(cnt[2], dlist, nb_off, nb_edge, edges2state, edges2cost, verts2slot, edges, tnext, cnext,
                       edges2queued, round, edges2verdict, cnt + 3, 0, 0, 0);
    n = *cnext;
    const uint untested = cnt[3];
    barrier(CLK_GLOBAL_MEM_FENCE);
    cur = 1 - cur;
    ++round;
    if (n > 0 && untested > max_tests) { /* the same value in every work item: a uniform exit */
      if (lid == 0) {
        resume[0] = n;
        resume[1] = (uint)cur;
        resume[2] = round;
      }
      return;
    }
    if (lid == 0) {
      cnt[2] = 0;
      cnt[3] = 0;
      *cnext = 0;
    }
    barrier(CLK_GLOBAL_MEM_FENCE);
  }
}

/* ---- The greedy selection (tc::CollapseOptions::Greedy) ----
 *
 * One selection in place of the lazy pass 1 and conflict pass 2: the greedy independent set, in
 * priority order (edges2priority, then index), of the candidates of lazy_init under the conflicts
 * of both passes at once. Two edges conflict when they touch a common tet, i.e. when an end point
 * of one is an end point or a neighbour of an end point of the other (pass 1's conflicts, a shared
 * end point, are a part of these). Edge e = (a, b) is taken when it passes the tests and comes
 * before every undecided candidate within reach (an end point in N[a] or N[b], N[x] = x and its
 * neighbours); taking it makes every undecided edge within reach OUT. As in the conflict passes
 * (collapse_conflict.cl), a decision depends only on final decisions of edges before it, so the
 * result is the one of taking the edges one after another in priority order, whatever the
 * order of the work items.
 *
 * The two-pass detection keeps a set of the same kind, but chooses it among pass 1's winners
 * only (an edge that lost pass 1 to an edge that then lost pass 2 is not taken), and tests every
 * pass-1 winner although most of them lose pass 2. So the greedy selection runs fewer tests (the
 * volume part only for most) and takes more collapses (measured in bench/README.md).
 *
 * Driven, as lazy pass 1, by the vertices where something was decided: verts2slot[x] is the first
 * undecided candidate at x (lazy_init's claims, then tcc_p1_recompute), and an edge first at
 * both end points is in the turn list. A round:
 *   greedy_decide  each turn-list edge: the volume test (tcc_lazy_volume; a refusal is OUT at
 *                  once, which frees the way for the edges after it without waiting for its
 *                  turn); then the slots over N(a) and N(b): one holding an edge before e
 *                  (edges2blocker[e]) makes e wait; else e is first within reach: the link
 *                  condition (tcc_lazy_decide), IN (listed for greedy_block) or OUT. A waiting
 *                  edge waits on the vertex whose slot holds its blocker (tcc_wait_on,
 *                  collapse_select.h), and lazy_p1_turns puts it in the turn list of the round
 *                  after its blocker decided (without the waiting lists, StageParams::
 *                  waiting_lists: in every next turn list, where it only checks the blocker's
 *                  state until then, no scan). Edges deciding in one round are pairwise
 *                  free of conflicts (each comes first within reach of the other), so their
 *                  writes do not race;
 *   greedy_block   every undecided edge within reach of an edge taken this round is OUT, and
 *                  the vertices whose slot it held are listed (verts2listed: once per round);
 *   lazy_p1_recompute and lazy_p1_turns (above) over the listed vertices: their slots anew, and
 *                  the edges now first at both end points, or waiting on them, go to the next
 *                  turn list.
 * Slots change only in lazy_p1_recompute, so every kernel reads the round's slots. States
 * change in greedy_decide (of its own edges) and greedy_block; the two reads of another edge's
 * state in the same kernel are benign: greedy_decide's of its blocker (decided or not, the
 * unchanged slots make e wait in this round either way) and greedy_block's (two taken edges
 * write the same OUT). Decisions and counts do not depend on the order of the work items.
 * Once the turn list is short the rounds run in one work-group (greedy_loop).
 *
 * cnt[]: [0], [1] the two turn lists, [2] the vertex list, [3] (lazy_p1_turns: turn-list edges
 * without a verdict, unused here), [4] the edges taken this round. */

/* The priority with levels > 0: the cost in `levels` steps per target length and, within a
 * step, an order that is a bijective hash of the index. In the exact (cost, index) order the
 * turns follow chains of slowly growing cost and an iteration takes many rounds; in steps far
 * fewer, for nearly as many edges (a simulation of the greedy without the tests, measured in
 * bench/README.md). Unmarked edges keep their cost. */
__kernel void greedy_priority(uint ne, __global const double* edges2cost, __global const uint* edges_are_marked,
                              double target, double levels, __global double* edges2priority) {
  uint e = get_global_id(0);
  if (e >= ne) return;
  double c = edges2cost[e];
  edges2priority[e] =
      edges_are_marked[e] ? floor(c / target * levels) + (double)(e * 2654435761u) * (1.0 / 4294967296.0) : c;
}

inline void tcc_greedy_decide(int e, __global const int* edges, __global const double* edges2priority,
                              __global const int* verts2slot, __global int* edges2blocker, __global uint* tnext,
                              __global uint* tn, volatile __global uint* edges2queued, uint round,
                              __global uint* inlist, __global uint* in_n, volatile __global uint* verts2listed,
                              __global uint* dlist, __global uint* dn, __global uchar* edges2state,
                              __global int* verts2collapse, __global int* verts2waiting,
                              __global int* edges2next_waiting, TCC_TEST_PARAMS) {
  if (edges2state[e] != TCC_UNDECIDED) return; /* OUT by greedy_block */
  int a = edges[2 * e], b = edges[2 * e + 1];
  int f = edges2blocker[e], fz = -1; /* fz: the vertex whose slot holds a blocker found now */
  int wait = f >= 0 && edges2state[f] == TCC_UNDECIDED;
  if (!wait) {
    if (tcc_lazy_volume(e, a, b, tcc_lazy_dir(e, a, b, TCC_TEST_ARGS), TCC_TEST_ARGS)) {
      f = -1; /* the first slot over N(a) and N(b) holding an edge before e, if any */
      for (int s = 0; s < 2 && f < 0; ++s) {
        int x = s == 0 ? a : b;
        for (uint j = nb_off[x]; j < nb_off[x + 1]; ++j) {
          int g = verts2slot[nb[j]];
          if (g >= 0 && g != e && tcc_before(edges2priority, g, e)) {
            f = g;
            fz = nb[j];
            break;
          }
        }
      }
      edges2blocker[e] = f;
      wait = f >= 0;
    }
    if (!wait) {
      if (tcc_lazy_decide(e, edges, edges2state, verts2collapse, TCC_TEST_ARGS)) {
        inlist[atomic_inc(in_n)] = (uint)e;
      } else { /* refused: a and b need their next edge */
        tcc_refused_ends(a, b, verts2listed, round, dlist, dn);
      }
      return;
    }
  }
  tcc_wait(e, fz, verts2waiting, edges2next_waiting, edges2queued, round, tnext, tn);
}

__kernel void greedy_decide(uint n, uint cur, __global const uint* tlist, __global uint* tnext, __global uint* cnt,
                            __global const int* edges, __global const double* edges2priority,
                            __global const int* verts2slot, __global int* edges2blocker,
                            volatile __global uint* edges2queued, uint round, __global uint* inlist,
                            volatile __global uint* verts2listed, __global uint* dlist, __global uchar* edges2state,
                            __global int* verts2collapse, int waiting, __global int* verts2waiting,
                            __global int* edges2next_waiting, TCC_TEST_PARAMS) {
  uint i = get_global_id(0);
  if (i >= n) return;
#ifdef TCC_PREFETCH_OK
  tcc_prefetch_test(i, n, tlist, edges, vt_off, vt, tets, pts, TCC_NO_DEAD, tet_nbr, vflags, q_min, tets2quality);
#endif
  tcc_greedy_decide((int)tlist[i], edges, edges2priority, verts2slot, edges2blocker, tnext, cnt + (1 - cur),
                    edges2queued, round, inlist, cnt + 4, verts2listed, dlist, cnt + 2, edges2state, verts2collapse,
                    waiting ? verts2waiting : 0, edges2next_waiting, TCC_TEST_ARGS);
}

/* The edge e taken: every undecided edge with an end point in N[a] or N[b] is OUT; the vertices
 * whose slot held an edge made OUT are listed. */
inline void tcc_greedy_block(int e, __global const int* edges, __global const uint* nb_off, __global const int* nb,
                             __global const int* nb_edge, __global const int* verts2slot,
                             volatile __global uint* verts2listed, uint round, __global uint* dlist, __global uint* dn,
                             __global uchar* edges2state) {
  int a = edges[2 * e], b = edges[2 * e + 1];
  for (int s = 0; s < 2; ++s) {
    int x = s == 0 ? a : b;
    for (uint k = nb_off[x]; k <= nb_off[x + 1]; ++k) { /* N(x), then x */
      int z = k == nb_off[x + 1] ? x : nb[k];
      if (verts2slot[z] >= 0) tcc_greedy_list_vertex(z, verts2listed, round, dlist, dn);
      for (uint j = nb_off[z]; j < nb_off[z + 1]; ++j) {
        int g = nb_edge[j];
        if (edges2state[g] != TCC_UNDECIDED) continue;
        edges2state[g] = TCC_OUT; /* two taken edges may both do this: the same write */
        int u = nb[j];
        if (verts2slot[u] == g) tcc_greedy_list_vertex(u, verts2listed, round, dlist, dn);
      }
    }
  }
}

__kernel void greedy_block(__global const uint* inlist, __global uint* cnt, __global const int* edges,
                           __global const uint* nb_off, __global const int* nb, __global const int* nb_edge,
                           __global const int* verts2slot, volatile __global uint* verts2listed, uint round,
                           __global uint* dlist, __global uchar* edges2state) {
  uint i = tcc_spread_index();
  if (i >= cnt[4]) return;
  tcc_greedy_block((int)inlist[i], edges, nb_off, nb, nb_edge, verts2slot, verts2listed, round, dlist, cnt + 2,
                   edges2state);
}

/* The remaining rounds in one work-group, once the turn list is short (a round then costs
 * barriers instead of four launches and two read-backs). Entry: the n edges of turn list `cur`
 * (t0 or t1) are round `round`'s; cnt[] is 0. When a new turn list is longer than max_n, the
 * loop stops and leaves resume[0..2] = (its length, its list, its round) for the host's
 * per-round kernels; resume[0] stays 0 when every round is done. */
__kernel void greedy_loop(uint n, int cur, uint round, __global uint* t0, __global uint* t1, __global uint* cnt,
                          __global const int* edges, __global const double* edges2priority, __global int* verts2slot,
                          __global int* edges2blocker, volatile __global uint* edges2queued, __global uint* inlist,
                          volatile __global uint* verts2listed, __global uint* dlist, __global uchar* edges2state,
                          __global int* verts2collapse, uint max_n, __global uint* resume, int waiting,
                          __global int* verts2waiting, __global int* edges2next_waiting, TCC_TEST_PARAMS) {
  const uint lid = get_local_id(0), ls = get_local_size(0);
  if (!waiting) verts2waiting = 0;
  while (n > 0) {
    __global uint* tl = cur ? t1 : t0;
    __global uint* tnext = cur ? t0 : t1;
    __global uint* cnext = cnt + (1 - cur);
    for (uint i = lid; i < n; i += ls)
      tcc_greedy_decide((int)tl[i], edges, edges2priority, verts2slot, edges2blocker, tnext, cnext, edges2queued, round,
                        inlist, cnt + 4, verts2listed, dlist, cnt + 2, edges2state, verts2collapse, verts2waiting,
                        edges2next_waiting, TCC_TEST_ARGS);
    barrier(CLK_GLOBAL_MEM_FENCE);
    const uint nin = cnt[4];
    for (uint i = lid; i < nin; i += ls)
      tcc_greedy_block((int)inlist[i], edges, nb_off, nb, nb_edge, verts2slot, verts2listed, round, dlist, cnt + 2,
                       edges2state);
    barrier(CLK_GLOBAL_MEM_FENCE);
    tcc_p1_vertex_part(cnt[2], dlist, nb_off, nb_edge, edges2state, edges2priority, verts2slot, edges, tnext, cnext,
                       edges2queued, round, edges2verdict, cnt + 3, 0, verts2waiting, edges2next_waiting);
    if (tcc_loop_next(&n, &cur, &round, max_n, cnt, resume)) return;
  }
}

/* verts2slot_priority[v] = the priority of verts2slot[v] (INFINITY for none), after lazy_init's
 * claims (the matching selection's scans, tcc_p1_recompute). */
__kernel void slot_priority(uint nv, __global const int* verts2slot, __global const double* edges2priority,
                            __global double* verts2slot_priority) {
  uint v = get_global_id(0);
  if (v >= nv) return;
  int m = verts2slot[v];
  verts2slot_priority[v] = m >= 0 ? edges2priority[m] : INFINITY;
}

/* After the greedy selection: edges_pass1 = edges_are_final = IN, counted in counters[2] and
 * counters[3]. */
__kernel void greedy_finish(uint ne, __global const uchar* edges2state, __global uint* edges_pass1,
                            __global uint* edges_are_final, __global uint* counters) {
  __local uint group_in;
  uint e = get_global_id(0);
  uint in = e < ne && edges2state[e] == TCC_IN;
  if (e < ne) {
    edges_pass1[e] = in;
    edges_are_final[e] = in;
  }
  tcc_group_count(in, &group_in, &counters[2]);
  if (get_local_id(0) == 0 && group_in) atomic_add(&counters[3], group_in);
}
