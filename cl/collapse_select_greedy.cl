/* The greedy selection (tc::CollapseOptions::Greedy, select_greedy.cpp): a file of its own so
 * that a run of another selection does not compile it.
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
 *   lazy_p1_recompute and lazy_p1_turns (collapse_admissible.cl) over the listed vertices:
 *                  their slots anew, and
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

#include "collapse_common.h"
#include "collapse_select.h"


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
