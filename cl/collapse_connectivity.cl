/* Stage 1 of a collapse iteration: connectivity of the current mesh, without global sorts.
 *
 *   vertex -> tets   count (atomic_inc per corner) + exclusive scan + scatter (atomic cursor)
 *                    + a per-vertex sort of each short list, so the lists are deterministic.
 *   vertex -> verts  N(v): gather the other corners of ring(v), sort and unique per vertex in
 *                    a scratch area of 3 |ring(v)| slots, count, scan, copy.
 *   edges            (v, u) for u in N(v), u > v, in that order: sorted lexicographically, the
 *                    same numbering as tc::build_topology; nb_edge gives each N(v) entry's edge.
 *   boundary         derived locally from the rings (see collapse_common.h): S-faces, edge and
 *                    vertex flags, ridge edges and vertex classes with tc::build_topology's rules.
 */
#include "collapse_common.h"
#include "collapse_classify.h"

__kernel void conn_count(__global const int* tets, uint nt, __global uint* count) {
  uint t = get_global_id(0);
  if (t >= nt) return;
  for (int k = 0; k < 4; ++k) atomic_inc(&count[tets[4 * t + k]]);
}

__kernel void conn_scatter(__global const int* tets, uint nt, __global const uint* vt_off, __global uint* cursor,
                           __global int* vt) {
  uint t = get_global_id(0);
  if (t >= nt) return;
  for (int k = 0; k < 4; ++k) {
    int v = tets[4 * t + k];
    uint slot = atomic_inc(&cursor[v]);
    vt[vt_off[v] + slot] = (int)t;
  }
}

/* Insertion sort of a short global segment (lists are a few dozen entries). */
inline void tcc_sort_segment(__global int* a, uint n) {
  for (uint i = 1; i < n; ++i) {
    int x = a[i];
    uint j = i;
    while (j > 0 && a[j - 1] > x) {
      a[j] = a[j - 1];
      --j;
    }
    a[j] = x;
  }
}

#ifndef TCC_MAX_NB
#define TCC_MAX_NB 64
#endif
#ifndef TCC_GATHER_BITS
#define TCC_GATHER_BITS 1024
#endif

/* Inserts u into the ascending list s[0..*m) unless it is there. */
inline void tcc_insert_sorted(__global int* s, uint* m, int u) {
  uint j = *m;
  while (j > 0 && s[j - 1] > u) --j;
  if (j > 0 && s[j - 1] == u) return;
  for (uint k = *m; k > j; --k) s[k] = s[k - 1];
  s[j] = u;
  ++*m;
}

/* |N(v)| and the number of its entries above v (the edges v owns). */
inline void tcc_count_neighbours(__global const int* s, uint m, uint v, __global uint* nb_count,
                                 __global uint* up_count) {
  uint up = 0;
  for (uint i = 0; i < m; ++i) up += s[i] > (int)v ? 1u : 0u;
  nb_count[v] = m;
  up_count[v] = up;
}

/* Sorts ring(v) (unless sort == 0: carried rings are sorted); then gathers N(v) into scratch[3 vt_off[v] ..], sorted and unique, and counts
 * it (nb_count) and its part above v (up_count). */
__kernel void conn_ring_sort_and_gather(__global const int* tets, uint nv, __global const uint* vt_off,
                                        __global int* vt, __global int* scratch, __global uint* nb_count,
                                        __global uint* up_count, int sort, int carry,
                                        __global const uchar* verts_are_dirty, __global const int* verts2prev,
                                        __global const int* prev_verts2new, __global const uint* prev_nb_off,
                                        __global const int* prev_nb, int rename,
                                        __global const int* prev_verts2collapse) {
  uint v = get_global_id(0);
  if (v >= nv) return;
  uint b = vt_off[v], n = vt_off[v + 1] - b;
  if (sort) { /* else already sorted (collapse_update.cl) */
    if (n <= TCC_MAX_NB) {
      /* each entry goes to its rank among the (distinct) tets: compares without branches,
       * where an insertion sort mispredicts the end of every inner loop */
      int r[TCC_MAX_NB];
      for (uint i = 0; i < n; ++i) r[i] = vt[b + i];
      for (uint i = 0; i < n; ++i) {
        uint rank = 0;
        for (uint j = 0; j < n; ++j) rank += r[j] < r[i] ? 1u : 0u;
        vt[b + rank] = r[i];
      }
    } else {
      tcc_sort_segment(vt + b, n);
    }
  }
  __global int* s = scratch + 3 * b;
  if (carry && !verts_are_dirty[v]) {
    /* ring(v) unchanged (collapse_verdicts.cl): N(v) is the previous one renumbered; none of
     * its vertices was removed and compaction keeps their order, so it stays sorted */
    int o = verts2prev[v];
    uint pb = prev_nb_off[o], m = prev_nb_off[o + 1] - pb, up = 0;
    for (uint i = 0; i < m; ++i) {
      int u = prev_verts2new[prev_nb[pb + i]];
      s[i] = u;
      up += u > (int)v ? 1u : 0u;
    }
    nb_count[v] = m;
    up_count[v] = up;
    return;
  }
  if (carry && rename && prev_verts2collapse[verts2prev[v]] < 0) {
    /* v is a neighbour of collapses, not an end point (rename: the rings were carried through
     * the compaction, collapse_update.cl). A collapse of x onto y renames x to y in the tets
     * of ring(v) and removes tets holding both; the link condition leaves every edge (v, w)
     * in some surviving tet, so N(v) is the previous one with each removed x renamed to its
     * survivor. The end points of the collapses (renamed, or kept but possibly equal to a
     * renamed one) are merged into the renumbered others, which stay in order. */
    int o = verts2prev[v];
    uint pb = prev_nb_off[o], pm = prev_nb_off[o + 1] - pb, m = 0;
    int ren[16];
    int nr = 0;
    for (uint i = 0; i < pm && nr <= 16; ++i) {
      int w = prev_nb[pb + i];
      if (prev_verts2collapse[w] >= 0) {
        if (nr < 16) ren[nr] = prev_verts2new[w];
        ++nr;
      } else {
        s[m++] = prev_verts2new[w];
      }
    }
    if (nr <= 16) {
      for (int r = 0; r < nr; ++r) tcc_insert_sorted(s, &m, ren[r]);
      tcc_count_neighbours(s, m, v, nb_count, up_count);
      return;
    }
  }
  if (carry && rename && prev_verts2collapse[verts2prev[v]] >= 0) {
    /* v survives the collapse of u onto it: N(v) = N(u) U N(v) without u and v (the same link
     * condition argument), renumbered. No other vertex of the two lists is an end point of a
     * collapse (no tet holds end points of two final edges), so both renumber in order (the
     * compaction keeps the order of the kept vertices) and a merge of the two keeps N(v)
     * sorted. Otherwise (not expected) the general gather below. */
    const int o = verts2prev[v];
    const uint ab = prev_nb_off[o], ae = prev_nb_off[o + 1];
    int u = -1, other = 0;
    for (uint i = ab; i < ae; ++i) {
      int w = prev_nb[i];
      if (prev_verts2collapse[w] < 0) continue;
      if (prev_verts2new[w] == (int)v && u < 0)
        u = w;
      else other = 1;
    }
    if (u >= 0 && !other) {
      const uint bb = prev_nb_off[u], be = prev_nb_off[u + 1];
      for (uint j = bb; j < be && !other; ++j) other = prev_nb[j] != o && prev_verts2collapse[prev_nb[j]] >= 0;
      if (!other) {
        /* u in N(v) and v in N(u) renumber to v, out of order: skipped before comparing. At
         * most 3 |ring(v)| entries fit in v's scratch (each tet gives 3 neighbours); more
         * would contradict the argument above: then the general gather. */
        const uint cap = 3 * n;
        uint i = ab, j = bb, m = 0;
        for (;;) {
          if (i < ae && prev_nb[i] == u) ++i;
          if (j < be && prev_nb[j] == o) ++j;
          if (i >= ae && j >= be) break;
          if (m == cap) break;
          int x = i < ae ? prev_verts2new[prev_nb[i]] : INT_MAX, y = j < be ? prev_verts2new[prev_nb[j]] : INT_MAX;
          int z = x < y ? x : y;
          if (x == z) ++i;
          if (y == z) ++j;
          s[m++] = z;
        }
        if (i >= ae && j >= be) {
          tcc_count_neighbours(s, m, v, nb_count, up_count);
          return;
        }
      }
    }
  }
  /* When the other corners of ring(v) span fewer than TCC_GATHER_BITS ids (the usual case: the
   * vertices are in spatial order), N(v) is a bitmap over that span, read out in order: sorted
   * and unique by construction: one bit per corner instead of an insertion into a sorted list
   * (measured in bench/README.md). */
  int lo = INT_MAX, hi = INT_MIN;
  for (uint i = 0; i < n; ++i) {
    const int4 q = vload4(vt[b + i], tets);
    lo = min(lo, min(min(q.x == (int)v ? INT_MAX : q.x, q.y == (int)v ? INT_MAX : q.y),
                     min(q.z == (int)v ? INT_MAX : q.z, q.w == (int)v ? INT_MAX : q.w)));
    hi = max(hi, max(max(q.x, q.y), max(q.z, q.w)));
  }
  if (n > 0 && hi - lo < TCC_GATHER_BITS) {
    uint bits[TCC_GATHER_BITS / 32];
    for (int w = 0; w < TCC_GATHER_BITS / 32; ++w) bits[w] = 0u;
    for (uint i = 0; i < n; ++i) {
      const int4 q = vload4(vt[b + i], tets);
      const int c[4] = {q.x, q.y, q.z, q.w};
      for (int k = 0; k < 4; ++k) {
        const uint r = (uint)(c[k] - lo);
        if (c[k] != (int)v) bits[r >> 5] |= 1u << (r & 31u);
      }
    }
    uint m = 0, up = 0;
    for (int w = 0; w < TCC_GATHER_BITS / 32; ++w)
      for (uint x = bits[w]; x != 0u; x &= x - 1u) {
        const int u = lo + 32 * w + 31 - (int)clz(x & (0u - x)); /* the lowest bit (ctz is OpenCL 2.0) */
        s[m++] = u;
        up += u > (int)v ? 1u : 0u;
      }
    nb_count[v] = m;
    up_count[v] = up;
    return;
  }
  /* Else N(v) is built by insertion into a sorted private list (short: the valence), spilling to
   * the global scratch area only when it outgrows TCC_MAX_NB */
  int loc[TCC_MAX_NB];
  uint m = 0;
  int big = 0;
  for (uint i = 0; i < n; ++i) {
    __global const int* q = tets + 4 * vt[b + i];
    for (int k = 0; k < 4; ++k) {
      int u = q[k];
      if (u == (int)v) continue;
      if (!big) {
        /* u's place and whether it is there, without branches (see the ring sort above) */
        uint j = 0;
        int dup = 0;
        for (uint i = 0; i < m; ++i) {
          j += loc[i] < u ? 1u : 0u;
          dup |= loc[i] == u;
        }
        if (dup) continue;
        if (m < TCC_MAX_NB) {
          for (uint k2 = m; k2 > j; --k2) loc[k2] = loc[k2 - 1];
          loc[j] = u;
          ++m;
          continue;
        }
        for (uint k2 = 0; k2 < m; ++k2) s[k2] = loc[k2];
        big = 1;
      }
      tcc_insert_sorted(s, &m, u);
    }
  }
  if (!big)
    for (uint k2 = 0; k2 < m; ++k2) s[k2] = loc[k2];
  tcc_count_neighbours(s, m, v, nb_count, up_count);
}

/* Copies N(v) to nb[] and writes the edges owned by v (u > v) and their ids. */
__kernel void conn_write_neighbours(uint nv, __global const uint* vt_off, __global const int* scratch,
                                    __global const uint* nb_off, __global const uint* edge_off, __global int* nb,
                                    __global int* nb_edge, __global int* edges) {
  uint v = get_global_id(0);
  if (v >= nv) return;
  __global const int* s = scratch + 3 * vt_off[v];
  uint b = nb_off[v], m = nb_off[v + 1] - b;
  uint lower = m - (edge_off[v + 1] - edge_off[v]);
  for (uint i = 0; i < m; ++i) {
    int u = s[i];
    nb[b + i] = u;
    if (i >= lower) {
      uint e = edge_off[v] + (i - lower);
      nb_edge[b + i] = (int)e;
      edges[2 * e] = (int)v;
      edges[2 * e + 1] = u;
    }
  }
}

/* Edge ids of the entries u < v of N(v): edge (u, v) is owned by u, and is the edge of v's rank
 * among the entries of N(u) above u. With carry, when v and u are clean (rings unchanged since
 * the previous iteration, collapse_verdicts.cl), N(v) and N(u) are the previous ones renumbered
 * in order: u is at the same place in N(v), v has the same rank in N(u), which the previous edge
 * id gives without a scan. */
__kernel void conn_lower_edges(uint nv, __global const uint* nb_off, __global const int* nb,
                               __global const uint* edge_off, __global int* nb_edge, int carry,
                               __global const uchar* verts_are_dirty, __global const int* verts2prev,
                               __global const uint* prev_nb_off, __global const uint* prev_edge_off,
                               __global const int* prev_nb_edge) {
  uint v = get_global_id(0);
  if (v >= nv) return;
  uint b = nb_off[v], m = nb_off[v + 1] - b;
  uint lower = m - (edge_off[v + 1] - edge_off[v]);
  const int clean = carry && !verts_are_dirty[v];
  const uint pb = clean ? prev_nb_off[verts2prev[v]] : 0u;
  for (uint i = 0; i < lower; ++i) {
    int u = nb[b + i];
    if (clean && !verts_are_dirty[u]) {
      nb_edge[b + i] = (int)(edge_off[u] + ((uint)prev_nb_edge[pb + i] - prev_edge_off[verts2prev[u]]));
      continue;
    }
    /* position of v among the upper part of N(u) */
    uint ub = nb_off[u + 1] - (edge_off[u + 1] - edge_off[u]);
    uint lo = ub;
    while (nb[lo] < (int)v) ++lo; /* v is in the upper part of N(u): a short scan */
    nb_edge[b + i] = (int)(edge_off[u] + (lo - ub));
  }
}

#ifndef TCC_MAX_MIN_FACES
#define TCC_MAX_MIN_FACES 128
#endif

/* tet_nbr (see collapse_common.h). Each face is matched by its smallest vertex v: the faces of
 * ring(v) whose other two vertices are both above v are paired in private memory (they are few
 * per vertex) by sorting their keys, instead of a ring scan per face. A vertex with more such faces
 * than TCC_MAX_MIN_FACES falls back to the ring scan for its faces. */
/* Carried tet_nbr for the faces owned by (whose smallest vertex is) a clean vertex v
 * (verts_are_dirty[v] == 0): ring(v) is unchanged since the previous iteration
 * (collapse_verdicts.cl), so the tet across the face is a kept tet of ring(v), at its new index
 * prev_tets2new[previous index]; compaction keeps the order of the vertices of every tet, so the
 * local face numbers are the same. One work item per tet; conn_tet_neighbours then matches the
 * dirty vertices' faces. */
__kernel void conn_tet_neighbours_carry(uint nt, __global const int* tets, __global int* tet_nbr,
                                        __global const uchar* verts_are_dirty, __global const int* tets2prev,
                                        __global const uint* prev_tets2new, __global const int* prev_tet_nbr) {
  uint t = get_global_id(0);
  if (t >= nt) return;
  __global const int* q = tets + 4 * t;
  for (int f = 0; f < 4; ++f) {
    int owner = -1;
    for (int j = 0; j < 4; ++j)
      if (j != f && (owner < 0 || q[j] < owner)) owner = q[j];
    if (verts_are_dirty[owner]) continue;
    int o = prev_tet_nbr[4 * tets2prev[t] + f];
    tet_nbr[4 * t + f] = o < 0 ? o : (int)prev_tets2new[o];
  }
}

/* The two local indices of a tet other than lv and f (lv != f), ascending: face f (opposite
 * local vertex f) of a tet holding v at local index lv has v and the vertices at
 * TCC_OTHER2[lv][f]. */
__constant uchar TCC_OTHER2[4][4][2] = {{{0, 0}, {2, 3}, {1, 3}, {1, 2}},
                                        {{2, 3}, {0, 0}, {0, 3}, {0, 2}},
                                        {{1, 3}, {0, 3}, {0, 0}, {0, 1}},
                                        {{1, 2}, {0, 2}, {0, 1}, {0, 0}}};

/* Over vertices 0..n-1, or over list[0..n-1] when use_list. */
__kernel void conn_tet_neighbours(uint n, __global const int* tets, __global const uint* vt_off,
                                  __global const int* vt, __global int* tet_nbr, int use_list,
                                  __global const uint* list) {
  uint gid = get_global_id(0);
  if (gid >= n) return;
  uint v = use_list ? list[gid] : gid;
  int tf[TCC_MAX_MIN_FACES]; /* 4 t + f (t < 2^29: check_collapse_input) */
  ulong key[TCC_MAX_MIN_FACES];
  int k = 0, overflow = 0;
  for (uint i = vt_off[v]; i < vt_off[v + 1]; ++i) {
    int t = vt[i];
    __global const int* q = tets + 4 * t;
    int lv = tcc_local(tets, t, (int)v);
    for (int f = 0; f < 4; ++f) {
      if (f == lv) continue;
      int u = q[TCC_OTHER2[lv][f][0]], w = q[TCC_OTHER2[lv][f][1]];
      if (u < (int)v || w < (int)v) continue; /* v is not the smallest vertex of this face */
      if (k == TCC_MAX_MIN_FACES) {
        overflow = 1;
        int other;
        int m = tcc_face_others(tets, vt_off, vt, t, f, &other);
        tet_nbr[4 * t + f] = m == 0 ? -1 : m == 1 ? other : -2;
        continue;
      }
      tf[k] = 4 * t + f;
      key[k] = u < w ? ((ulong)(uint)u << 32 | (uint)w) : ((ulong)(uint)w << 32 | (uint)u);
      ++k;
    }
  }
  if (overflow) { /* faces beyond the capacity may match these too: the ring scan for each */
    for (int i = 0; i < k; ++i) {
      int other;
      int m = tcc_face_others(tets, vt_off, vt, tf[i] >> 2, tf[i] & 3, &other);
      tet_nbr[tf[i]] = m == 0 ? -1 : m == 1 ? other : -2;
    }
    return;
  }
  /* Sorted by key (insertion sort: few entries), each run of equal keys is one face: one entry
   * is a boundary face, two are the two tets of an inner face, more an invalid input. */
  for (int i = 1; i < k; ++i) {
    ulong kk = key[i];
    int x = tf[i];
    int j = i;
    for (; j > 0 && key[j - 1] > kk; --j) {
      key[j] = key[j - 1];
      tf[j] = tf[j - 1];
    }
    key[j] = kk;
    tf[j] = x;
  }
  for (int i = 0; i < k;) {
    int j = i + 1;
    while (j < k && key[j] == key[i]) ++j;
    for (int m = i; m < j; ++m)
      tet_nbr[tf[m]] = j - i == 1 ? -1 : j - i == 2 ? (tf[m == i ? i + 1 : i] >> 2) : -2;
    i = j;
  }
}

/* vflags: S membership of every vertex, from the faces around it, in two steps: every tet ORs
 * the S kind of each of its faces into the face's vertices (few faces are on S, so the atomics
 * are rare; OR is order-independent), then the bits become vflags. Per tet rather than per
 * vertex ring: each face is looked at from 2 tets instead of from 3 vertices x 2 tets.
 * owns_s[t]: whether t owns an S face (tcc_owned_sface), and smask[t] which (bit f: the face
 * opposite local vertex f), for the surface guard. */
__kernel void conn_vertex_flags_faces(uint nt, __global const int* tets, __global const int* tet_nbr,
                                      __global const int* labels, int use_labels, __global uint* bits,
                                      __global uint* owns_s, __global uchar* smask) {
  uint t = get_global_id(0);
  if (t >= nt) return;
  __global const int* q = tets + 4 * t;
  uint owns = 0;
  for (int f = 0; f < 4; ++f) {
    uint on_s;
    if (tcc_owned_sface(tet_nbr, labels, use_labels, (int)t, f, &on_s)) owns |= 1u << f;
    if (!on_s) continue;
    for (int j = 0; j < 4; ++j)
      if (j != f) atomic_or(&bits[q[j]], on_s);
  }
  owns_s[t] = owns != 0; /* the tets the surface guard looks at */
  smask[t] = (uchar)owns;
}

__kernel void conn_vertex_flags(uint nv, __global const uint* bits, __global uchar* vflags) {
  uint v = get_global_id(0);
  if (v >= nv) return;
  vflags[v] = (uchar)bits[v];
}

/* Edge flags of (a, b) from ring(a): S membership (boundary / interface: the kinds of the
 * owned S-faces through the edge) and TCC_RIDGE by the ridge rule (collapse_classify.h). */
inline uchar tcc_edge_flags_of(int a, int b, __global const int* tets, __global const uint* vt_off,
                               __global const int* vt, __global const int* tet_nbr, __global const int* labels,
                               int use_labels, __global const double* pts, double eps_r) {
  uint flags = 0;
  int ns = 0;
  int ft[2], ff[2];
  for (uint i = vt_off[a]; i < vt_off[a + 1]; ++i) {
    int t = vt[i];
    int lb = tcc_local(tets, t, b);
    if (lb < 0) continue;
    int la = tcc_local(tets, t, a);
    for (int f = 0; f < 4; ++f) {
      if (f == la || f == lb) continue; /* faces containing a and b are opposite the others */
      uint on_s;
      uint own = tcc_owned_sface(tet_nbr, labels, use_labels, t, f, &on_s);
      flags |= on_s;
      if (own) {
        if (ns < 2) {
          ft[ns] = t;
          ff[ns] = f;
        }
        ++ns;
      }
    }
  }
  if (ns > 0) {
    int dir[2] = {0, 0};
    double3 n[2] = {(double3)(0.0), (double3)(0.0)};
    for (int k = 0; k < 2 && k < ns; ++k) {
      __global const int* q = tets + 4 * ft[k];
      int f0 = q[TC_TET_FACES[ff[k]][0]], f1 = q[TC_TET_FACES[ff[k]][1]], f2 = q[TC_TET_FACES[ff[k]][2]];
      dir[k] = (f0 == a && f1 == b) || (f1 == a && f2 == b) || (f2 == a && f0 == b);
      n[k] = tcc_face_normal(pts, tets, ft[k], ff[k]);
    }
    if (tc_sf_ridge_rule(ns, dir[0], dir[1], n[0], n[1], eps_r)) flags |= TCC_RIDGE;
  }
  return (uchar)flags;
}

/* Edge flags and vertex classes, per vertex v: the flags of the edges v owns (v < u) and the class
 * of v, from the owned S-faces through v, gathered once (rather than a ring scan per edge), by
 * the rules of collapse_classify.h (tc_sf_edge, tc_sf_class; the sequential method's too). An
 * S-edge joins two S vertices (most edges are not: 0 at once). The ridge edges at v are those
 * to the vertices of its S-faces (the rule is symmetric: v's work item decides the edges it
 * does not own the same way as their owners do).
 * More than TCC_MAX_VERTEX_SFACES S-faces at a vertex (rare: a fan of thin boundary faces) classify it as
 * corner, which only protects it more, and its edges' flags come from ring scans
 * (tcc_edge_flags_of). With carry, a vertex whose ring is unchanged (verts_are_dirty == 0) keeps
 * its class and its edges' flags (found in the previous N(v)). */
__kernel void conn_surface_flags(uint nv, __global const int* tets, __global const uint* vt_off, __global const int* vt,
                                 __global const int* tet_nbr, __global const int* labels, int use_labels,
                                 __global const double* pts, double eps_r, double eps_f, __global const uint* nb_off,
                                 __global const int* nb, __global const uint* edge_off, __global const uchar* vflags,
                                 __global const uchar* smask, __global uchar* eflags, __global uchar* vclass, int carry,
                                 __global const uchar* verts_are_dirty, __global const int* verts2prev,
                                 __global const uint* prev_nb_off, __global const int* prev_nb,
                                 __global const int* prev_nb_edge, __global const uchar* prev_eflags,
                                 __global const uchar* prev_vclass) {
  uint v = get_global_id(0);
  if (v >= nv) return;
  const uint e0 = edge_off[v], up = edge_off[v + 1] - e0;
  __global const int* upper = nb + (nb_off[v + 1] - up); /* N(v) above v, in edge order */
  const int on_s = vflags[v] != 0;
  if (carry && !verts_are_dirty[v]) { /* ring(v), which decides the class and the owned edges' flags, is unchanged */
    /* and N(v) is the previous one renumbered in order (conn_ring_sort_and_gather): its part above
     * v is the previous part above verts2prev[v], entry for entry (as verdict_carry reads it) */
    const int o = verts2prev[v];
    vclass[v] = prev_vclass[o];
    __global const int* prev_upper_edge = prev_nb_edge + (prev_nb_off[o + 1] - up);
    for (uint i = 0; i < up; ++i) eflags[e0 + i] = on_s && vflags[upper[i]] ? prev_eflags[prev_upper_edge[i]] : (uchar)0;
    return;
  }
  if (!on_s) {
    for (uint i = 0; i < up; ++i) eflags[e0 + i] = 0;
    vclass[v] = TCC_INTERIOR;
    return;
  }
  /* the owned S-faces through v: kind, the vertices after and before v along the face's
   * orientation, unit normal */
  double3 normal[TCC_MAX_VERTEX_SFACES];
  int after[TCC_MAX_VERTEX_SFACES], before[TCC_MAX_VERTEX_SFACES];
  uchar kind[TCC_MAX_VERTEX_SFACES];
  int fn = 0, overflow = 0;
  for (uint i = vt_off[v]; i < vt_off[v + 1]; ++i) {
    int t = vt[i];
    const uint mask = smask[t]; /* the faces t owns on S (conn_vertex_flags_faces) */
    if (!mask) continue;
    int lv = tcc_local(tets, t, (int)v);
    for (int f = 0; f < 4; ++f) {
      if (f == lv || !(mask & (1u << f))) continue;
      /* owned: on the boundary, or the lower-labelled side of an interface (tcc_owned_sface) */
      const uint own = tet_nbr[4 * t + f] < 0 ? TCC_BOUNDARY : TCC_INTERFACE;
      if (fn == TCC_MAX_VERTEX_SFACES) {
        overflow = 1;
        continue;
      }
      __global const int* q = tets + 4 * t;
      int w[3] = {q[TC_TET_FACES[f][0]], q[TC_TET_FACES[f][1]], q[TC_TET_FACES[f][2]]};
      int p = w[0] == (int)v ? 0 : w[1] == (int)v ? 1 : 2;
      after[fn] = w[(p + 1) % 3];
      before[fn] = w[(p + 2) % 3];
      kind[fn] = (uchar)own;
      normal[fn] = tcc_face_normal(pts, tets, t, f);
      ++fn;
    }
  }
  if (overflow) {
    for (uint i = 0; i < up; ++i) {
      const int u = upper[i];
      eflags[e0 + i] = vflags[u] ? tcc_edge_flags_of((int)v, u, tets, vt_off, vt, tet_nbr, labels, use_labels, pts, eps_r) : 0;
    }
    vclass[v] = TCC_CORNER;
    return;
  }
  /* the edges v owns, then v's class (collapse_classify.h) */
  for (uint i = 0; i < up; ++i) {
    const int u = upper[i];
    uint fl = 0;
    int ridge = 0;
    if (vflags[u]) fl = tc_sf_edge(u, after, before, kind, normal, fn, eps_r, &ridge);
    eflags[e0 + i] = (uchar)(fl | (ridge ? TCC_RIDGE : 0u));
  }
  vclass[v] = fn == 0 ? TCC_INTERIOR : (uchar)tc_sf_class(after, before, normal, fn, eps_r, eps_f);
}
