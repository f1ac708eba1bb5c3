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
                         int mode, int paper_rule, double eps_v, double q_min, double field_eps,
                         __global const double* tets2quality,
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
                                use_labels, pts, vfield, vfield_stride, vflags, eflags, eps_v, q_min, field_eps, tets2quality);
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
