/* Flips on the device (host/improve/flips_device.cpp): for each bad tet, the first interior
 * flip that improves it, then a conflict-free set of those flips.
 *
 *   flip_find    per bad tet, in the host's order: the removal of one of its edges whose ring
 *                is closed (n tets -> 2n - 4, n <= 7, the best triangulation of the ring:
 *                cl/improve_flip.h), else a 2-3 flip of one of its faces; each accepted only
 *                when the worst min-sine of the changed tets rises and the smallest dihedral
 *                angle stays above min(its value before, the threshold). Boundary flips
 *                (open rings) are left to the host.
 *   flip_claim   each flip still competing claims the vertices of its old tets (smallest flip
 *                index wins: the bad tets come worst first); a flip touching a vertex taken by
 *                a winner drops out until the host's next round
 *   flip_won     a flip that holds all its claims wins and takes its vertices
 * Winners share no vertex, so each one's tests (which read only the stars of its vertices)
 * hold whatever the others do, and the host may apply them all. The choice depends on the flip
 * indices alone, never on the work-group size. */
#include "geometry.h"
#include "improve_flip.h"

#define TCI_MAX_NEW (2 * TCI_MAX_RING - 4)
#define TCI_NONE 0
#define TCI_EDGE_REMOVAL 1
#define TCI_FLIP23 2
/* flip states */
#define TCI_COMPETING 0
#define TCI_WON 1
#define TCI_DROPPED 2

typedef struct {
  __global const int* tets;
  __global const int* labels;
  __global const double* quality;
  __global const double* max_cos;
  __global const uint* off;
  __global const int* vt;
  __global const uchar* selected;
  __global const ulong* tagged_edges;
  uint n_tagged_edges;
  __global const int* tagged_faces; /* 4 ints per face: sorted vertices, 0 */
  uint n_tagged_faces;
  __global const double* pts;
} FlipMesh;

inline int contains4(int4 q, int x) { return q.x == x || q.y == x || q.z == x || q.w == x; }

/* A tet other than `skip` with vertices a, b and (c >= 0) c, or -1. */
inline int tet_with(const FlipMesh* m, int skip, int a, int b, int c) {
  for (uint i = m->off[a]; i < m->off[a + 1]; ++i) {
    int t = m->vt[i];
    int4 q = vload4(t, m->tets);
    if (t != skip && contains4(q, b) && (c < 0 || contains4(q, c))) return t;
  }
  return -1;
}

inline int has_edge(const FlipMesh* m, int a, int b) {
  if (m->off[a + 1] - m->off[a] > m->off[b + 1] - m->off[b]) return tet_with(m, -1, b, a, -1) >= 0;
  return tet_with(m, -1, a, b, -1) >= 0;
}

inline int tagged_edge(const FlipMesh* m, int a, int b) {
  ulong key = a < b ? ((ulong)a << 32) | (ulong)(uint)b : ((ulong)b << 32) | (ulong)(uint)a;
  uint lo = 0, hi = m->n_tagged_edges;
  while (lo < hi) {
    uint mid = (lo + hi) / 2;
    if (m->tagged_edges[mid] < key) lo = mid + 1;
    else hi = mid;
  }
  return lo < m->n_tagged_edges && m->tagged_edges[lo] == key;
}

inline int tagged_face(const FlipMesh* m, int a, int b, int c) {
  if (m->n_tagged_faces == 0) return 0;
  int x = min(a, min(b, c)), z = max(a, max(b, c)), y = a + b + c - x - z;
  uint lo = 0, hi = m->n_tagged_faces;
  while (lo < hi) {
    uint mid = (lo + hi) / 2;
    __global const int* f = m->tagged_faces + 4 * mid;
    int less = f[0] < x || (f[0] == x && (f[1] < y || (f[1] == y && f[2] < z)));
    if (less) lo = mid + 1;
    else hi = mid;
  }
  if (lo >= m->n_tagged_faces) return 0;
  __global const int* f = m->tagged_faces + 4 * lo;
  return f[0] == x && f[1] == y && f[2] == z;
}

inline double quality_of(const FlipMesh* m, int a, int b, int c, int d) {
  return tc_tet_min_sine(tc_point(m->pts, a), tc_point(m->pts, b), tc_point(m->pts, c), tc_point(m->pts, d));
}
inline double max_cos_of(const FlipMesh* m, int a, int b, int c, int d) {
  return tc_tet_max_dihedral_cos(tc_point(m->pts, a), tc_point(m->pts, b), tc_point(m->pts, c), tc_point(m->pts, d));
}

/* The removal of the edge (a, b) when its ring is closed; the old and new tets into the out
 * arrays. Returns the number of new tets, 0 if not possible or no better. */
inline int edge_removal(const FlipMesh* m, int a, int b, double cos_threshold, int* old, int* n_old, int* added) {
  if (tagged_edge(m, a, b) || !m->selected[a] || !m->selected[b]) return 0;
  int n = 0;
  for (uint i = m->off[a]; i < m->off[a + 1]; ++i) {
    int t = m->vt[i];
    if (contains4(vload4(t, m->tets), b)) {
      if (n == TCI_MAX_RING) return 0;
      old[n++] = t;
    }
  }
  if (n < 3) return 0; /* a closed ring has three tets at least */
  int from[TCI_MAX_RING], to[TCI_MAX_RING];
  double old_min = INFINITY, old_cos = -1;
  for (int i = 0; i < n; ++i) {
    if (m->labels[old[i]] != m->labels[old[0]]) return 0;
    int q[4];
    for (int k = 0; k < 4; ++k) q[k] = m->tets[4 * old[i] + k];
    tci_others(q, a, b, &from[i], &to[i]);
    old_min = fmin(old_min, m->quality[old[i]]);
    old_cos = fmax(old_cos, m->max_cos[old[i]]);
  }
  int r[TCI_MAX_RING + 1], mm = 0, closed = 0, start = 0;
  if (!tci_chain(n, from, to, r, &mm, &closed, &start) || !closed) return 0;
  for (int i = 0; i < mm; ++i)
    if (tagged_face(m, a, b, r[i]) || !m->selected[r[i]]) return 0;
  int chord_ok[TCI_MAX_RING * TCI_MAX_RING];
  double tri_q[TCI_TRI_TABLE], best[TCI_MAX_RING * TCI_MAX_RING];
  int split[TCI_MAX_RING * TCI_MAX_RING];
  for (int i = 0; i < mm; ++i)
    for (int j = i + 2; j < mm; ++j) {
      chord_ok[i * TCI_MAX_RING + j] = (i == 0 && j == mm - 1) || !has_edge(m, r[i], r[j]);
      if (!chord_ok[i * TCI_MAX_RING + j]) continue;
      for (int k = i + 1; k < j; ++k)
        tri_q[tci_tri_index(i, k, j)] =
            tagged_face(m, r[i], r[k], r[j]) || tet_with(m, -1, r[i], r[k], r[j]) >= 0
                ? -INFINITY
                : fmin(quality_of(m, r[i], r[k], r[j], b), quality_of(m, r[j], r[k], r[i], a));
    }
  double new_min = tci_klincsek(mm, chord_ok, tri_q, best, split);
  if (!(new_min > old_min) || split[mm - 1] < 0) return 0;
  int n_new = tci_emit(mm, r, split, a, b, added);
  double new_cos = -1;
  for (int i = 0; i < n_new; ++i)
    new_cos = fmax(new_cos, max_cos_of(m, added[4 * i], added[4 * i + 1], added[4 * i + 2], added[4 * i + 3]));
  if (!(new_cos <= fmax(old_cos, cos_threshold))) return 0;
  *n_old = n;
  return n_new;
}

/* The 2-3 flip of face f of tet t with its neighbour across it. */
inline int flip23(const FlipMesh* m, int t, int f, double cos_threshold, int* old, int* n_old, int* added) {
  int4 qt = vload4(t, m->tets);
  int q[4] = {qt.x, qt.y, qt.z, qt.w};
  int p = q[f], u = q[TC_TET_FACES[f][0]], v = q[TC_TET_FACES[f][1]], w = q[TC_TET_FACES[f][2]];
  if (tagged_face(m, u, v, w)) return 0;
  int o = tet_with(m, t, u, v, w);
  if (o < 0) return 0;
  int4 qo = vload4(o, m->tets);
  int apex = qo.x != u && qo.x != v && qo.x != w ? qo.x
             : qo.y != u && qo.y != v && qo.y != w ? qo.y
             : qo.z != u && qo.z != v && qo.z != w ? qo.z
                                                     : qo.w;
  if (m->labels[o] != m->labels[t] || has_edge(m, p, apex)) return 0;
  if (!m->selected[p] || !m->selected[apex] || !m->selected[u] || !m->selected[v] || !m->selected[w]) return 0;
  int tri[3][2] = {{u, v}, {v, w}, {w, u}};
  double new_min = INFINITY, new_cos = -1;
  for (int i = 0; i < 3; ++i) {
    added[4 * i] = p;
    added[4 * i + 1] = apex;
    added[4 * i + 2] = tri[i][0];
    added[4 * i + 3] = tri[i][1];
    new_min = fmin(new_min, quality_of(m, p, apex, tri[i][0], tri[i][1]));
    new_cos = fmax(new_cos, max_cos_of(m, p, apex, tri[i][0], tri[i][1]));
  }
  double old_min = fmin(m->quality[t], m->quality[o]), old_cos = fmax(m->max_cos[t], m->max_cos[o]);
  if (!(new_min > old_min && new_cos <= fmax(old_cos, cos_threshold))) return 0;
  old[0] = t;
  old[1] = o;
  *n_old = 2;
  return 3;
}

/* flips2kind: TCI_NONE, TCI_EDGE_REMOVAL or TCI_FLIP23; flips2old: TCI_MAX_RING tets per flip
 * (the first: whose label and fields the new tets take), flips2n_old; flips2new: TCI_MAX_NEW
 * tets of 4 ints, flips2n_new. */
__kernel void flip_find(uint nf, __global const int* flips2tet, __global const int* tets,
                        __global const int* tets2label, __global const double* tets2quality,
                        __global const double* tets2max_cos, __global const uint* verts2tets_offsets,
                        __global const int* verts2tets, __global const uchar* verts_are_selected,
                        __global const ulong* tagged_edges, uint n_tagged_edges, __global const int* tagged_faces,
                        uint n_tagged_faces, __global const double* pts, double cos_threshold,
                        __global int* flips2kind, __global int* flips2old, __global int* flips2n_old,
                        __global int* flips2new, __global int* flips2n_new, __global int* flips2state) {
  uint i = get_global_id(0);
  if (i >= nf) return;
  FlipMesh m = {tets, tets2label, tets2quality, tets2max_cos, verts2tets_offsets, verts2tets, verts_are_selected,
                tagged_edges, n_tagged_edges, tagged_faces, n_tagged_faces, pts};
  int t = flips2tet[i];
  int4 qt = vload4(t, tets);
  int q[4] = {qt.x, qt.y, qt.z, qt.w};
  int old[TCI_MAX_RING], added[4 * TCI_MAX_NEW], n_old = 0, n_new = 0, kind = TCI_NONE;
  /* the edges first: removing an edge takes the sliver with it whichever way it is bad */
  for (int e = 0; e < 6 && n_new == 0; ++e)
    n_new = edge_removal(&m, q[TC_TET_EDGES[e][0]], q[TC_TET_EDGES[e][1]], cos_threshold, old, &n_old, added);
  if (n_new > 0) kind = TCI_EDGE_REMOVAL;
  for (int f = 0; f < 4 && n_new == 0; ++f) {
    n_new = flip23(&m, t, f, cos_threshold, old, &n_old, added);
    if (n_new > 0) kind = TCI_FLIP23;
  }
  flips2kind[i] = kind;
  flips2state[i] = kind == TCI_NONE ? TCI_DROPPED : TCI_COMPETING;
  flips2n_old[i] = n_old;
  flips2n_new[i] = n_new;
  for (int k = 0; k < n_old; ++k) flips2old[TCI_MAX_RING * i + k] = old[k];
  for (int k = 0; k < 4 * n_new; ++k) flips2new[4 * TCI_MAX_NEW * i + k] = added[k];
}

/* counters[0]: flips still competing */
__kernel void flip_claim(uint nf, __global const int* tets, __global const int* flips2old,
                         __global const int* flips2n_old, __global const uchar* verts_are_taken,
                         __global int* flips2state, __global uint* verts2claim, __global uint* counters) {
  uint i = get_global_id(0);
  if (i >= nf || flips2state[i] != TCI_COMPETING) return;
  int n = flips2n_old[i];
  for (int k = 0; k < n; ++k) {
    int4 q = vload4(flips2old[TCI_MAX_RING * i + k], tets);
    if (verts_are_taken[q.x] || verts_are_taken[q.y] || verts_are_taken[q.z] || verts_are_taken[q.w]) {
      flips2state[i] = TCI_DROPPED;
      return;
    }
  }
  atomic_inc(&counters[0]);
  for (int k = 0; k < n; ++k) {
    int4 q = vload4(flips2old[TCI_MAX_RING * i + k], tets);
    atomic_min(&verts2claim[q.x], i);
    atomic_min(&verts2claim[q.y], i);
    atomic_min(&verts2claim[q.z], i);
    atomic_min(&verts2claim[q.w], i);
  }
}

__kernel void flip_won(uint nf, __global const int* tets, __global const int* flips2old,
                       __global const int* flips2n_old, __global const uint* verts2claim, __global int* flips2state,
                       __global uchar* verts_are_taken) {
  uint i = get_global_id(0);
  if (i >= nf || flips2state[i] != TCI_COMPETING) return;
  int n = flips2n_old[i];
  for (int k = 0; k < n; ++k) {
    int4 q = vload4(flips2old[TCI_MAX_RING * i + k], tets);
    if (verts2claim[q.x] != i || verts2claim[q.y] != i || verts2claim[q.z] != i || verts2claim[q.w] != i) return;
  }
  flips2state[i] = TCI_WON;
  for (int k = 0; k < n; ++k) {
    int4 q = vload4(flips2old[TCI_MAX_RING * i + k], tets);
    verts_are_taken[q.x] = 1;
    verts_are_taken[q.y] = 1;
    verts_are_taken[q.z] = 1;
    verts_are_taken[q.w] = 1;
  }
}
