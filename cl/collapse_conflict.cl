/* Stages 4 and 5 of a collapse iteration: conflict detection (paper Sec. 3.3).
 *
 * Pass 1 over edges: an admissible edge survives when no other admissible edge at either end
 * point comes first in (cost, index) order; survivors write their id to vaff (vertAffectedByEdge)
 * at both end points. Survivors share no vertex, so those writes never race.
 * Pass 2 over tets: a tet touched by several surviving edges keeps the first in (cost, index)
 * order and flags the others in kill[]; then a pass over edges finalises: fin = p1 && !kill,
 * and the vertices of killed edges are released (vaff = -1). Pass 2 decides from the complete
 * pass-1 result, never from a partially updated one, so the outcome does not depend on the
 * order in which work items run. */
#include "collapse_common.h"

__kernel void conflict_pass1(uint ne, __global const int* edges, __global const uint* adm,
                             __global const double* cost, __global const uint* nb_off,
                             __global const int* nb_edge, __global uint* p1, __global int* vaff,
                             __global uint* counters) {
  uint e = get_global_id(0);
  if (e >= ne) return;
  p1[e] = 0u;
  if (!adm[e]) return;
  int ends[2] = {edges[2 * e], edges[2 * e + 1]};
  for (int s = 0; s < 2; ++s)
    for (uint i = nb_off[ends[s]]; i < nb_off[ends[s] + 1]; ++i) {
      int f = nb_edge[i];
      if (f != (int)e && adm[f] && tcc_before(cost, f, (int)e)) return;
    }
  p1[e] = 1u;
  vaff[ends[0]] = (int)e;
  vaff[ends[1]] = (int)e;
  atomic_inc(&counters[2]);
}

__kernel void conflict_pass2(uint nt, __global const int* tets, __global const int* vaff,
                             __global const double* cost, __global uint* kill) {
  uint t = get_global_id(0);
  if (t >= nt) return;
  int best = -1, n = 0;
  int seen[4];
  for (int k = 0; k < 4; ++k) {
    int e = vaff[tets[4 * t + k]];
    if (e < 0) continue;
    int dup = 0;
    for (int j = 0; j < n; ++j) dup |= seen[j] == e;
    if (dup) continue;
    seen[n++] = e;
    if (best < 0 || tcc_before(cost, e, best)) best = e;
  }
  if (n < 2) return;
  for (int j = 0; j < n; ++j)
    if (seen[j] != best) kill[seen[j]] = 1u; /* every writer writes the same value */
}

__kernel void conflict_finalize(uint ne, __global const int* edges, __global const uint* p1,
                                __global const uint* kill, __global uint* fin, __global int* vaff,
                                __global uint* counters) {
  uint e = get_global_id(0);
  if (e >= ne) return;
  uint f = p1[e] && !kill[e];
  fin[e] = f;
  if (p1[e] && kill[e]) {
    vaff[edges[2 * e]] = -1;
    vaff[edges[2 * e + 1]] = -1;
  }
  if (f) atomic_inc(&counters[3]);
}
