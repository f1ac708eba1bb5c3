/* The two-pass selection's pass 1 by rounds (tc::CollapseOptions::TwoPass, select_two_pass.cpp):
 * the lazy filter's decisions over the turn list, per round or in one work-group. The rest of
 * pass 1 (lazy_init, lazy_p1_recompute, lazy_p1_turns) is shared with the greedy and matching
 * selections in collapse_admissible.cl; a file of its own so that a run of another selection
 * does not compile these. */
#include "collapse_common.h"
#include "collapse_select.h"

/* Pass 1's decision of a turn-list edge (the rounds are described in collapse_admissible.cl). */
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
