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
 * States: 0 undecided, 1 IN, 2 OUT (state[] per edge, uchar). */
#include "collapse_common.h"


/* Initial states: admissible edges undecided, others out. */
__kernel void conflict_init(uint ne, __global const uint* adm, __global uchar* state) {
  uint e = get_global_id(0);
  if (e >= ne) return;
  state[e] = adm[e] ? TCC_UNDECIDED : TCC_OUT;
}

/* The rounds run over worklists of slots of cand[] (the candidate edges): list[0..n) holds
 * the undecided ones (the first round, first != 0, takes slot i for work item i); those
 * still waiting for a cheaper rival are appended to next (via the counter next_n). The order
 * of a worklist does not matter, since a decision depends only on final decisions of cheaper
 * edges. rivals / rcount: see collapse_common.h.
 *
 * One round of pass 1. */
__kernel void conflict_pass1_round(uint n, int first, __global const uint* list, __global uint* next,
                                   __global uint* next_n, __global const uint* cand, __global uint* rivals,
                                   __global uint* rcount, __global const int* edges, __global const double* cost,
                                   __global const uint* nb_off, __global const int* nb_edge,
                                   __global uchar* state) {
  uint i = get_global_id(0);
  if (i >= n) return;
  uint c = first ? i : list[i];
  int e = (int)cand[c];
  int w = tcc_pass1_wait(e, edges[2 * e], edges[2 * e + 1], nb_off, nb_edge, cost, state, rivals + c * TCC_RIVALS,
                         rcount + c);
  if (w < 0) state[e] = TCC_OUT;
  else if (w > 0) next[atomic_inc(next_n)] = c;
  else state[e] = TCC_IN;
}

/* After pass 1: p1 flags, vaff (vertAffectedByEdge) of both end points of IN edges, counters[2]. */
__kernel void conflict_pass1_finish(uint ne, __global const int* edges, __global const uchar* state,
                                    __global uint* p1, __global int* vaff, __global uint* counters) {
  uint e = get_global_id(0);
  if (e >= ne) return;
  uint in = state[e] == TCC_IN;
  p1[e] = in;
  if (in) {
    vaff[edges[2 * e]] = (int)e;
    vaff[edges[2 * e + 1]] = (int)e;
    atomic_inc(&counters[2]);
  }
}

/* Pass 2 initial states: pass-1 edges undecided, others out. */
__kernel void conflict_pass2_init(uint ne, __global const uint* p1, __global uchar* state) {
  uint e = get_global_id(0);
  if (e >= ne) return;
  state[e] = p1[e] ? TCC_UNDECIDED : TCC_OUT;
}

/* One round of pass 2 over the pass-1 edges: the rivals of e = (a, b) are the pass-1 edges
 * recorded (vaff) at the vertices of the tets of ring(a) and ring(b). */
__kernel void conflict_pass2_round(uint n, int first, __global const uint* list, __global uint* next,
                                   __global uint* next_n, __global const uint* cand, __global uint* rivals,
                                   __global uint* rcount, __global const int* edges, __global const double* cost,
                                   __global const int* tets, __global const uint* vt_off, __global const int* vt,
                                   __global const int* vaff, __global uchar* state) {
  uint i = get_global_id(0);
  if (i >= n) return;
  uint c = first ? i : list[i];
  int e = (int)cand[c];
  int w = tcc_pass2_wait(e, edges[2 * e], edges[2 * e + 1], tets, vt_off, vt, vaff, cost, state,
                         rivals + c * TCC_RIVALS, rcount + c);
  if (w < 0) state[e] = TCC_OUT;
  else if (w > 0) next[atomic_inc(next_n)] = c;
  else state[e] = TCC_IN;
}

/* fin = IN after pass 2; the vertices of dropped pass-1 edges are released. */
__kernel void conflict_finalize(uint ne, __global const int* edges, __global const uint* p1,
                                __global const uchar* state, __global uint* fin, __global int* vaff,
                                __global uint* counters) {
  uint e = get_global_id(0);
  if (e >= ne) return;
  uint f = p1[e] && state[e] == TCC_IN;
  fin[e] = f;
  if (p1[e] && !f) {
    vaff[edges[2 * e]] = -1;
    vaff[edges[2 * e + 1]] = -1;
  }
  if (f) atomic_inc(&counters[3]);
}
