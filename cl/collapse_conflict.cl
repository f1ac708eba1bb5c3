/* Stages 4 and 5 of a collapse iteration: conflict detection (paper Sec. 3.3).
 *
 * Pass 1 over edges (edges sharing a vertex conflict) and pass 2 (edges touching a common tet
 * conflict) each select, among their candidates, the greedy independent set in (cost, index)
 * order: an edge is IN when every conflicting candidate before it is OUT, and OUT as soon as one
 * conflicting candidate before it is IN. The paper's single sweep is the first round of this
 * (keep an edge when nothing cheaper conflicts); repeating the sweep until every candidate is
 * decided keeps the edges whose cheaper rivals have themselves been dropped, which the paper's
 * version loses. The fixpoint is unique (induction over the (cost, index) order) and every
 * decision is final when taken, so the result does not depend on the order in which work items
 * run or on the work-group size, although states are updated in place.
 * States: 0 undecided, 1 IN, 2 OUT (edges2state[] per edge, uchar). */
#include "collapse_common.h"


/* Initial states: admissible edges undecided, others out. */
__kernel void conflict_init(uint ne, __global const uint* edges_are_admissible, __global uchar* edges2state) {
  uint e = get_global_id(0);
  if (e >= ne) return;
  edges2state[e] = edges_are_admissible[e] ? TCC_UNDECIDED : TCC_OUT;
}

/* The rounds run over worklists of slots of cand[] (the candidate edges): list[0..n) holds
 * the undecided ones (the first round, first != 0, takes slot i for work item i); those
 * still waiting for a cheaper rival are appended to next (via the counter next_n). The order
 * of a worklist does not matter, since a decision depends only on final decisions of cheaper
 * edges.
 *
 * Pass 1 (edges sharing a vertex conflict) runs two kernels per round, with per-vertex slots
 * instead of scans of the neighbour edges:
 *   pass1_claim   an undecided edge with an end point taken by an IN edge is OUT (that edge
 *                 was the first undecided edge there when it won, so it comes before); the
 *                 others claim both end points (tcc_claim: the slot keeps the first claimant);
 *   *_decide      an edge holding both of its slots is first among the undecided edges at both
 *                 end points, i.e. every rival before it is OUT: it is decided (IN; in the lazy
 *                 filter IN when it passes the link and volume tests, else OUT); the others
 *                 wait for the next round, whose slots they clear (two slot arrays alternate,
 *                 so clearing never races with reading).
 * verts2collapse[x] is the IN edge at x (-1 when none). */
__kernel void pass1_claim(uint n, int first, __global const uint* list, __global const uint* cand,
                          __global const int* edges, __global const double* edges2cost,
                          __global const int* verts2collapse, volatile __global int* verts2slot,
                          __global uchar* edges2state) {
  uint i = get_global_id(0);
  if (i >= n) return;
  int e = (int)cand[first ? i : list[i]];
  int a = edges[2 * e], b = edges[2 * e + 1];
  if (verts2collapse[a] >= 0 || verts2collapse[b] >= 0) {
    edges2state[e] = TCC_OUT;
    return;
  }
  tcc_claim(verts2slot + a, e, edges2cost);
  tcc_claim(verts2slot + b, e, edges2cost);
}

/* Pass 1 over admissible edges (every edge tested beforehand): a turn means IN. */
__kernel void conflict_pass1_decide(uint n, int first, __global const uint* list, __global uint* next,
                                    __global uint* next_n, __global const uint* cand, __global const int* edges,
                                    __global const int* verts2slot, __global int* verts2slot_next,
                                    __global uchar* edges2state, __global int* verts2collapse) {
  uint i = get_global_id(0);
  if (i >= n) return;
  int e;
  if (tcc_pass1_turn(i, first, list, next, next_n, cand, edges, verts2slot, verts2slot_next, edges2state, &e) <= 0)
    return;
  edges2state[e] = TCC_IN;
  verts2collapse[edges[2 * e]] = e;
  verts2collapse[edges[2 * e + 1]] = e;
}

/* After pass 1: edges_pass1 flags, verts2collapse (vertAffectedByEdge) of both end points of IN
 * edges, counters[2]. */
__kernel void conflict_pass1_finish(uint ne, __global const int* edges, __global const uchar* edges2state,
                                    __global uint* edges_pass1, __global int* verts2collapse, __global uint* counters) {
  __local uint group_in;
  uint e = get_global_id(0);
  uint in = e < ne && edges2state[e] == TCC_IN;
  if (e < ne) edges_pass1[e] = in;
  if (in) {
    verts2collapse[edges[2 * e]] = (int)e;
    verts2collapse[edges[2 * e + 1]] = (int)e;
  }
  tcc_group_count(in, &group_in, &counters[2]);
}

/* Pass 2 initial states: pass-1 edges undecided, others out. */
__kernel void conflict_pass2_init(uint ne, __global const uint* edges_pass1, __global uchar* edges2state) {
  uint e = get_global_id(0);
  if (e >= ne) return;
  edges2state[e] = edges_pass1[e] ? TCC_UNDECIDED : TCC_OUT;
}

/* One round of pass 2 over the pass-1 edges: the rivals of e = (a, b) are the pass-1 edges
 * recorded (verts2collapse) at the vertices of the tets of ring(a) and ring(b), i.e. at N(a) and
 * N(b). */
inline void tcc_pass2_item(uint i, int first, __global const uint* list, __global uint* next, __global uint* next_n,
                           __global const uint* cand, __global uint* slots2rivals, __global uint* slots2rival_count,
                           __global const int* edges, __global const double* edges2cost, __global const uint* nb_off,
                           __global const int* nb, __global const int* verts2collapse, __global uchar* edges2state) {
  uint c = first ? i : list[i];
  int e = (int)cand[c];
  int w = tcc_pass2_wait(e, edges[2 * e], edges[2 * e + 1], nb_off, nb, verts2collapse, edges2cost, edges2state,
                         slots2rivals + c * TCC_RIVALS, slots2rival_count + c);
  if (w < 0)
    edges2state[e] = TCC_OUT;
  else if (w > 0) next[atomic_inc(next_n)] = c;
  else
    edges2state[e] = TCC_IN;
}

__kernel void conflict_pass2_round(uint n, int first, __global const uint* list, __global uint* next,
                                   __global uint* next_n, __global const uint* cand, __global uint* slots2rivals,
                                   __global uint* slots2rival_count, __global const int* edges,
                                   __global const double* edges2cost, __global const uint* nb_off,
                                   __global const int* nb, __global const int* verts2collapse,
                                   __global uchar* edges2state) {
  uint i = get_global_id(0);
  if (i >= n) return;
  tcc_pass2_item(i, first, list, next, next_n, cand, slots2rivals, slots2rival_count, edges, edges2cost, nb_off, nb,
                 verts2collapse, edges2state);
}

/* The remaining pass-2 rounds in one work-group, once few candidates are left (a round then
 * costs barriers instead of a launch and a read-back, as lazy_p1_loop). Entry: n entries of
 * worklist `cur` (l0 or l1; all candidates when first), *next_n = 0. */
__kernel void conflict_pass2_loop(uint n, int first, int cur, __global uint* l0, __global uint* l1,
                                  __global uint* next_n, __global const uint* cand, __global uint* slots2rivals,
                                  __global uint* slots2rival_count, __global const int* edges,
                                  __global const double* edges2cost, __global const uint* nb_off,
                                  __global const int* nb, __global const int* verts2collapse,
                                  __global uchar* edges2state) {
  const uint lid = get_local_id(0), ls = get_local_size(0);
  while (n > 0) {
    __global uint* list = cur ? l1 : l0;
    __global uint* next = cur ? l0 : l1;
    for (uint i = lid; i < n; i += ls)
      tcc_pass2_item(i, first, list, next, next_n, cand, slots2rivals, slots2rival_count, edges, edges2cost, nb_off, nb,
                     verts2collapse, edges2state);
    barrier(CLK_GLOBAL_MEM_FENCE);
    n = *next_n;
    barrier(CLK_GLOBAL_MEM_FENCE);
    if (lid == 0) *next_n = 0;
    barrier(CLK_GLOBAL_MEM_FENCE);
    first = 0;
    cur = 1 - cur;
  }
}

/* edges_are_final = IN after pass 2; the vertices of dropped pass-1 edges are released. */
__kernel void conflict_finalize(uint ne, __global const int* edges, __global const uint* edges_pass1,
                                __global const uchar* edges2state, __global uint* edges_are_final,
                                __global int* verts2collapse, __global uint* counters) {
  __local uint group_fin;
  uint e = get_global_id(0);
  uint f = 0u;
  if (e < ne) {
    f = edges_pass1[e] && edges2state[e] == TCC_IN;
    edges_are_final[e] = f;
    if (edges_pass1[e] && !f) {
      verts2collapse[edges[2 * e]] = -1;
      verts2collapse[edges[2 * e + 1]] = -1;
    }
  }
  tcc_group_count(f, &group_fin, &counters[3]);
}
