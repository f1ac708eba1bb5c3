// Vertex relocation on the host, one vertex after the other: the ascent of
// cl/improve_relocate.h, with the surface guard for vertices of curved surfaces.
#include <algorithm>
#include <functional>

#include "improve/improve_mesh.hpp"
#include "improve_relocate.h"

namespace tc::improve_detail {

static_assert(kFixed == TCI_FIXED && kFree == TCI_FREE && kInPlane == TCI_IN_PLANE && kAlongLine == TCI_ALONG_LINE,
              "the host's motion classes are those of cl/improve_relocate.h");

bool try_smooth(ImpMesh& m, int32_t v) {
  const Motion motion = m.motion(v);
  const std::vector<int32_t>& star = m.tets_of(v);
  if (motion == kFixed || star.empty()) return false;
  std::vector<int32_t> sorted = star;
  std::sort(sorted.begin(), sorted.end(), [&](int32_t a, int32_t b) { return m.quality(a) < m.quality(b); });
  const auto relocate = [&](const std::function<bool(int, tc_d3)>& surface_clear, tc_d3* p) {
    return geo::tci_relocate(m.point_data(), m.tet_data(), star.data(), sorted.data(), int(star.size()), v, motion,
                             m.motion_direction(v), m.start(v), m.max_offset(v), m.cos_threshold(), surface_clear, p);
  };
  tc_d3 p;
  if (!relocate({}, &p)) return false;
  // Under a boundary error bound, a move of the surface must keep it (ImpMesh::boundary_error_at).
  const bool bounded = m.bounded() && motion != kFree;
  const auto within = [&m](int u, tc_d3 x) { return m.boundary_error_at(u, x) <= m.max_boundary_move(); };
  double error = bounded ? m.boundary_error_at(v, p) : 0;
  // On a curved surface the guard is the costly part: it is asked of the ascent's end only,
  // and of every step only when that end would cross the surface (or leave the bound).
  if (m.bends_surface(v) && !((!bounded || error <= m.max_boundary_move()) && m.surface_stays_clear(v, p))) {
    if (!relocate([&](int u, tc_d3 x) { return (!bounded || within(u, x)) && m.surface_stays_clear(u, x); }, &p))
      return false;
    if (bounded) error = m.boundary_error_at(v, p);
  }
  if (bounded) m.set_boundary_error(v, error);
  m.move(v, p);
  if (motion != kFree) m.surface_moved(v);  // its surface triangles moved: re-list them
  return true;
}

std::vector<int32_t> smoothing_candidates(const ImpMesh& m, const std::vector<int32_t>& bad) {
  std::vector<int32_t> verts;
  for (int32_t t : bad)
    if (m.alive(t))
      for (int32_t v : m.tet(t)) verts.push_back(v);
  std::sort(verts.begin(), verts.end());
  verts.erase(std::unique(verts.begin(), verts.end()), verts.end());
  std::erase_if(verts, [&](int32_t v) { return m.motion(v) == kFixed; });
  return verts;
}

void smooth_pass(ImpMesh& m, const std::vector<int32_t>& bad, ImprovePassStats& stats) {
  for (int32_t v : smoothing_candidates(m, bad)) {
    if (m.settled(m.smooth_failed_at, v)) continue;  // it found nothing and nothing changed since
    if (try_smooth(m, v)) ++stats.relocated;
    else m.failed(m.smooth_failed_at, v);
  }
}

}  // namespace tc::improve_detail
