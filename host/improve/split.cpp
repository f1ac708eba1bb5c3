// Edge split: a bad tet whose four vertices lie on the surface (across a thin part, say) cannot be
// reached by relocation, which moves them within their faces at most, and flips often find no
// better triangulation of so few vertices. A new free vertex on its longest interior edge, placed
// by the relocation's own ascent (tci_relocate) in the ring of that edge, splits each tet of the
// ring in two. Klingner and Shewchuk (2007) found vertex insertion the operation that lifts the
// worst angles furthest after smoothing and flips; this is its simplest form, and the only
// operation of the improvement that adds a vertex.
#include <algorithm>
#include <cmath>
#include <limits>

#include "improve/improve_mesh.hpp"
#include "improve_relocate.h"

namespace tc::improve_detail {

namespace {

// The tets around the edge (a, b), when they close around it inside one label with no face at
// it that the input tags (an interior edge), else empty.
std::vector<int32_t> interior_ring(const ImpMesh& m, int32_t a, int32_t b) {
  EdgeRing ring;
  if (m.tagged_edge(a, b) || !edge_ring(m, a, b, ring) || !ring.closed || ring.tets.size() < 3) return {};
  for (int i = 0; i < ring.mm; ++i)
    if (m.tagged_face(a, b, ring.r[i]) || !m.selected(ring.r[i])) return {};
  return ring.tets;
}

}  // namespace

bool try_split(ImpMesh& m, int32_t t, int64_t max_tets) {
  const Tet q = m.tet(t);
  for (int32_t v : q)
    if (m.motion(v) == kFree || !m.selected(v)) return false;
  // the longest interior edge
  int32_t a = -1, b = -1;
  std::vector<int32_t> ring;
  double longest = 0;
  for (const auto& e : geo::TC_TET_EDGES) {
    const int32_t x = q[size_t(e[0])], y = q[size_t(e[1])];
    const double l = geo::length(m.point(y) - m.point(x));
    if (!(l > longest)) continue;
    std::vector<int32_t> r = interior_ring(m, x, y);
    if (r.empty()) continue;
    longest = l;
    a = x;
    b = y;
    ring = std::move(r);
  }
  if (a < 0 || (max_tets > 0 && m.live_tets() + int64_t(ring.size()) > max_tets)) return false;
  // (the tets below 13 degrees: a split must not leave more of them, though its worst rises)
  double old_sine = std::numeric_limits<double>::infinity(), old_cos = -1;
  int old_bad = 0;
  for (int32_t r : ring) {
    old_sine = std::min(old_sine, m.quality(r));
    old_cos = std::max(old_cos, m.max_cos(r));
    old_bad += m.max_cos(r) > kCos13;
  }
  // The ring alone, renumbered: its vertices, then the new one (last) at the edge's midpoint;
  // each tet in two, the new vertex in place of b, then of a (both as positive as the tet).
  std::vector<int32_t> verts;
  for (int32_t r : ring) verts.insert(verts.end(), m.tet(r).begin(), m.tet(r).end());
  std::sort(verts.begin(), verts.end());
  verts.erase(std::unique(verts.begin(), verts.end()), verts.end());
  const auto local = [&](int32_t v) { return int32_t(std::lower_bound(verts.begin(), verts.end(), v) - verts.begin()); };
  const int32_t nv = int32_t(verts.size());
  std::vector<double> pts;
  for (int32_t v : verts) {
    const tc_d3 p = m.point(v);
    pts.insert(pts.end(), {p.x, p.y, p.z});
  }
  const tc_d3 mid = (m.point(a) + m.point(b)) * 0.5;
  pts.insert(pts.end(), {mid.x, mid.y, mid.z});
  std::vector<Tet> added;
  std::vector<int32_t> tets;
  for (int32_t r : ring)
    for (int32_t replaced : {b, a}) {
      Tet h = m.tet(r);
      for (int32_t& v : h) v = v == replaced ? nv : local(v);
      tets.insert(tets.end(), h.begin(), h.end());
      Tet g = m.tet(r);
      for (int32_t& v : g) v = v == replaced ? -1 : v;  // (the new vertex's index once added)
      added.push_back(g);
    }
  const int n = int(added.size());
  std::vector<int32_t> star(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) star[size_t(i)] = i;
  const auto quality = [&](int i, tc_d3 p) { return geo::tci_quality_with(pts.data(), tets.data(), i, nv, p); };
  std::vector<int32_t> sorted = star;
  std::sort(sorted.begin(), sorted.end(), [&](int32_t x, int32_t y) { return quality(x, mid) < quality(y, mid); });
  tc_d3 p = mid;
  if (!geo::tci_relocate(pts.data(), tets.data(), star.data(), sorted.data(), n, nv, kFree, tc_d3{0, 0, 0}, mid,
                         std::numeric_limits<double>::infinity(), m.cos_threshold(), {}, &p))
    p = mid;
  double new_sine = std::numeric_limits<double>::infinity(), new_cos = -1;
  int new_bad = 0;
  for (int i = 0; i < n; ++i) {
    tc_d3 c[4];
    for (int k = 0; k < 4; ++k) {
      const int32_t v = tets[size_t(4 * i + k)];
      c[k] = v == nv ? p : geo::tc_point(pts.data(), v);
    }
    if (!(geo::tc_orient3d(c[0], c[1], c[2], c[3]) > 0)) return false;
    new_sine = std::min(new_sine, geo::tc_tet_min_sine(c[0], c[1], c[2], c[3]));
    const double cos_i = geo::tc_tet_max_dihedral_cos(c[0], c[1], c[2], c[3]);
    new_cos = std::max(new_cos, cos_i);
    new_bad += cos_i > kCos13;
  }
  if (!m.improves(old_sine, old_cos, new_sine, new_cos) || new_bad > old_bad) return false;
  const int32_t v = m.add_vertex(p, ring);
  for (Tet& g : added)
    for (int32_t& x : g) x = x < 0 ? v : x;
  for (size_t i = 0; i < ring.size(); ++i) m.replace({ring[i]}, {added[2 * i], added[2 * i + 1]}, ring[i]);
  return true;
}

void split_pass(ImpMesh& m, const std::vector<int32_t>& bad, int64_t max_tets, ImprovePassStats& stats) {
  // A split adds a vertex: only for the tets with an angle below 13 degrees or above 167 (the
  // paper's bad tets, those of the collapse step, by the passes' measure, the min-sine); at the
  // passes' 20 degrees it added several times as many tets (docs/algorithm.md).
  for (int32_t t : bad)  // (a slot a split reused holds a new tet: tried while it is bad)
    if (m.alive(t) && m.quality(t) < kSin13 && try_split(m, t, max_tets)) ++stats.splits;
}

}  // namespace tc::improve_detail
