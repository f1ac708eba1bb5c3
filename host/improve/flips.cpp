// Topological improvement: edge removal (n tets around an interior edge -> 2n - 4; n = 3 is the
// 3-2 flip) and the 2-3 flip (Shewchuk, "Two discrete optimization algorithms for the
// topological improvement of tetrahedral meshes"; Klingner and Shewchuk 2007). Only faces
// inside one label are removed, so the boundary and the interfaces stay as they are.
#include <algorithm>
#include <limits>

#include "improve/improve_mesh.hpp"
#include "improve_flip.h"

namespace tc::improve_detail {

namespace {

constexpr int kMaxRing = TCI_MAX_RING;

}  // namespace

bool edge_ring(const ImpMesh& m, int32_t a, int32_t b, EdgeRing& ring) {
  ring.tets.clear();
  for (int32_t t : m.tets_of(a))
    if (contains(m.tet(t), b)) ring.tets.push_back(t);
  const int n = int(ring.tets.size());
  if (n < 2 || n > kMaxRing) return false;
  for (int i = 0; i < n; ++i) {
    if (m.label(ring.tets[size_t(i)]) != m.label(ring.tets[0])) return false;
    geo::tci_others(m.tet(ring.tets[size_t(i)]).data(), a, b, &ring.from[i], &ring.to[i]);
  }
  return geo::tci_chain(n, ring.from, ring.to, ring.r, &ring.mm, &ring.closed, &ring.start);
}

// The ring of the edge (a, b): r[0..m) with (a, b, r[i], r[i+1]) the tets around it, of one
// label. A closed ring (m tets) means no boundary or interface face contains the edge, and the
// faces the operation keeps (a r_i r_i+1, b r_i r_i+1) are exactly the ring's outside. An open
// ring (m - 1 tets, from the face (a, b, r_0) to (a, b, r_m-1)) is an edge of the boundary.
// The new tets pair each triangle (r_i, r_j, r_k), i < j < k, of a triangulation of the
// polygon r_0..r_m-1 with a and with b: (r_i, r_j, r_k, b) and (r_k, r_j, r_i, a) are then
// positive. On the boundary, the polygon's closing edge (r_0, r_m-1) becomes the diagonal of the
// boundary quad (a, r_0, b, r_m-1) in place of (a, b): the boundary 2-2 flip for two tets, and
// its generalisation for more.
bool try_edge_removal(ImpMesh& m, int32_t a, int32_t b, bool open_rings_only) {
  if (m.tagged_edge(a, b) || !m.selected(a) || !m.selected(b)) return false;
  EdgeRing ring;
  if (!edge_ring(m, a, b, ring)) return false;
  const std::vector<int32_t>& ring_tets = ring.tets;
  const int n = int(ring_tets.size());  // tets
  const int32_t *to = ring.to, *r = ring.r;
  const int mm = ring.mm, closed = ring.closed, start = ring.start;  // mm: polygon vertices, n closed, n + 1 open
  double old_min = std::numeric_limits<double>::infinity(), old_cos = -1;
  for (int32_t t : ring_tets) {
    old_min = std::min(old_min, m.quality(t));
    old_cos = std::max(old_cos, m.max_cos(t));
  }
  if (closed ? n < 3 : !m.may_change_boundary() || mm > kMaxRing) return false;
  if (open_rings_only && closed) return false;
  for (int i = 0; i < mm; ++i) {  // a face of the old tets that the input tags must stay
    const bool outer = !closed && (i == 0 || i == mm - 1);  // these two: replace_on_boundary
    if ((!outer && m.tagged_face(a, b, r[i])) || !m.selected(r[i])) return false;
  }
  if (!closed) {
    // both faces at the edge on the outer boundary, the new diagonal not an edge yet
    if (m.across(ring_tets[size_t(start)], a, b, r[0]) >= 0) return false;
    int last = 0;
    while (last < n && to[last] != r[mm - 1]) ++last;
    if (m.across(ring_tets[size_t(last)], a, b, r[mm - 1]) >= 0 || m.has_edge(r[0], r[mm - 1])) return false;
    // Only flat quads: flipping a bent one would pin its vertices (their planes or lines no
    // longer hold), which costs more relocations than the flip gains.
    if (!flat_quad(m, a, b, r[0], r[mm - 1])) return false;
  }

  // The best triangulation of the polygon; a chord that is already an edge of the mesh is not
  // allowed, nor a triangle that is a face of the mesh or of the input's tags.
  int chord_ok[kMaxRing * kMaxRing];
  double tri_q[TCI_TRI_TABLE], best[kMaxRing * kMaxRing];
  int split[kMaxRing * kMaxRing];
  for (int i = 0; i < mm; ++i)
    for (int j = i + 2; j < mm; ++j) {
      chord_ok[i * kMaxRing + j] = (i == 0 && j == mm - 1) || !m.has_edge(r[i], r[j]);
      if (!chord_ok[i * kMaxRing + j]) continue;
      for (int k = i + 1; k < j; ++k)
        tri_q[geo::tci_tri_index(i, k, j)] =
            m.tagged_face(r[i], r[k], r[j]) || m.has_face(r[i], r[k], r[j])
                ? -std::numeric_limits<double>::infinity()
                : std::min(m.quality_of({r[i], r[k], r[j], b}), m.quality_of({r[j], r[k], r[i], a}));
    }
  const double new_min = geo::tci_klincsek(mm, chord_ok, tri_q, best, split);
  if (!(new_min > old_min) || split[mm - 1] < 0) return false;
  std::vector<Tet> added(size_t(2 * mm - 4));
  geo::tci_emit(mm, r, split, a, b, added[0].data());
  double new_cos = -1;
  for (const Tet& q : added) new_cos = std::max(new_cos, m.max_cos_of(q));
  if (!m.improves(old_min, old_cos, new_min, new_cos)) return false;
  if (closed) {
    m.replace(ring_tets, added, ring_tets[0]);
    return true;
  }
  const int32_t r0 = r[0], rl = r[mm - 1];
  return m.replace_on_boundary(ring_tets, added, {{{a, b, r0}, {a, b, rl}}}, {{{a, r0, rl}, {b, r0, rl}}},
                               flat_quad(m, a, b, r0, rl));
}

// The 2-3 flip: tets t = (face u v w, apex p) and its neighbour o across that face (apex q)
// become three tets around the new edge (p, q).
bool try_flip23(ImpMesh& m, int32_t t, int face) {
  const Tet& qt = m.tet(t);
  const int32_t p = qt[face];
  // TC_TET_FACES is oriented away from the opposite vertex: q lies on its positive side.
  const int32_t u = qt[geo::TC_TET_FACES[face][0]], v = qt[geo::TC_TET_FACES[face][1]],
                w = qt[geo::TC_TET_FACES[face][2]];
  if (m.tagged_face(u, v, w)) return false;
  const int32_t o = m.across(t, u, v, w);
  if (o < 0) return false;
  int32_t q = -1;  // o's apex
  for (int32_t x : m.tet(o))
    if (x != u && x != v && x != w) q = x;
  if (m.label(o) != m.label(t) || m.has_edge(p, q)) return false;
  if (!m.selected(p) || !m.selected(q) || !m.selected(u) || !m.selected(v) || !m.selected(w)) return false;
  const std::vector<Tet> added = {{p, q, u, v}, {p, q, v, w}, {p, q, w, u}};
  double new_min = std::numeric_limits<double>::infinity(), new_cos = -1;
  for (const Tet& a : added) {
    new_min = std::min(new_min, m.quality_of(a));
    new_cos = std::max(new_cos, m.max_cos_of(a));
  }
  if (!m.improves(std::min(m.quality(t), m.quality(o)), std::max(m.max_cos(t), m.max_cos(o)), new_min, new_cos))
    return false;
  m.replace({t, o}, added, t);
  return true;
}

bool try_boundary_flips(ImpMesh& m, int32_t t, ImprovePassStats& stats) {
  const Tet q = m.tet(t);
  for (int e = 0; e < 6; ++e)
    if (try_edge_removal(m, q[geo::TC_TET_EDGES[e][0]], q[geo::TC_TET_EDGES[e][1]], true)) {
      ++stats.edge_removals;
      return true;
    }
  if (try_remove_boundary_sliver(m, t)) {
    ++stats.boundary_removals;
    return true;
  }
  return false;
}

void flip_pass(ImpMesh& m, const std::vector<int32_t>& bad, ImprovePassStats& stats) {
  for (int32_t t : bad) {
    if (!m.alive(t)) continue;
    const Tet q = m.tet(t);
    // Where every operation failed before and nothing changed since, they fail again.
    if (m.settled(m.flip_failed_at, q[0]) && m.settled(m.flip_failed_at, q[1]) &&
        m.settled(m.flip_failed_at, q[2]) && m.settled(m.flip_failed_at, q[3]))
      continue;
    bool done = false;
    // The edges first: removing an edge takes the sliver with it whichever way it is bad.
    for (int e = 0; e < 6 && !done; ++e)
      if (try_edge_removal(m, q[geo::TC_TET_EDGES[e][0]], q[geo::TC_TET_EDGES[e][1]])) {
        ++stats.edge_removals;
        done = true;
      }
    for (int f = 0; f < 4 && !done; ++f)
      if (try_flip23(m, t, f)) {
        ++stats.flips23;
        done = true;
      }
    if (!done && try_remove_boundary_sliver(m, t)) {
      ++stats.boundary_removals;
      done = true;
    }
    if (!done)
      for (int32_t v : q) m.failed(m.flip_failed_at, v);
  }
}

}  // namespace tc::improve_detail
