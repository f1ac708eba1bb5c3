// The fans of a collapse as triangles, for the boundary error bound measured against the
// reference surface (SeqMesh::s_triangles, collapse_fans; collapse/surface_distance.hpp).
#include <algorithm>

#include "collapse/sequential_mesh.hpp"
#include "collapse_predicate.h"

namespace tc::sequential_detail {

using geo::tc_d3;
using Tri = std::array<tc_d3, 3>;

void SeqMesh::s_triangles(std::vector<double>& out) const {
  for (int32_t t = 0; t < nt_; ++t) {
    if (!talive_[t]) continue;
    const int32_t* q = tet(t);
    for (int f = 0; f < 4; ++f) {
      if (!owned_sface(t, f)) continue;
      for (int k = 0; k < 3; ++k) {
        const tc_d3 p = point(q[geo::TC_TET_FACES[f][k]]);
        out.insert(out.end(), {p.x, p.y, p.z});
      }
    }
  }
}

void SeqMesh::collapse_fans(int32_t a, int32_t b, uint8_t dir, std::vector<Tri>& olds, std::vector<Tri>& news,
                            std::vector<Tri>& around, std::vector<int32_t>& corners) const {
  olds.clear();
  news.clear();
  around.clear();
  corners.clear();
  const auto [x, y, p, moves_y] = collapse_ends(a, b, dir);
  const auto tri = [&](const int32_t* q, int f) {
    return Tri{point(q[geo::TC_TET_FACES[f][0]]), point(q[geo::TC_TET_FACES[f][1]]), point(q[geo::TC_TET_FACES[f][2]])};
  };
  each_old_sface(x, y, moves_y, [&](int32_t, const int32_t* q, int f) { olds.push_back(tri(q, f)); });
  each_new_sface(x, y, moves_y, [&](int32_t t, const int32_t* q, int f, int32_t other) {
    if (!(other < 0 || (labels_ && label(t) < label(other)))) return;  // (on the owner's side)
    Tri n;
    for (int k = 0; k < 3; ++k) {
      const int32_t v = q[geo::TC_TET_FACES[f][k]];
      n[size_t(k)] = v == x || v == y ? p : point(v);
      if (v != x && v != y) corners.push_back(v);
    }
    news.push_back(n);
  });
  std::sort(corners.begin(), corners.end());
  corners.erase(std::unique(corners.begin(), corners.end()), corners.end());
  // the S faces that stay at those corners (and at y when it stays): neither through x nor
  // through a moving y, nor of a tet the collapse removes; each once
  std::vector<int32_t> at = corners;
  if (!moves_y) at.push_back(y);
  std::vector<std::array<int32_t, 3>> seen;
  for (int32_t w : at) {
    each_face_through(w, [&](int32_t t, const int32_t* q, int f, int) {
      if (has(q, x) && has(q, y)) return;
      std::array<int32_t, 3> k{q[geo::TC_TET_FACES[f][0]], q[geo::TC_TET_FACES[f][1]], q[geo::TC_TET_FACES[f][2]]};
      const auto in = [&](int32_t v) { return k[0] == v || k[1] == v || k[2] == v; };
      if (in(x) || (moves_y && in(y)) || !owned_sface(t, f)) return;
      std::sort(k.begin(), k.end());
      if (std::find(seen.begin(), seen.end(), k) != seen.end()) return;
      seen.push_back(k);
      around.push_back(tri(q, f));
    });
  }
  for (const auto& k : seen) corners.insert(corners.end(), k.begin(), k.end());
  std::sort(corners.begin(), corners.end());
  corners.erase(std::unique(corners.begin(), corners.end()), corners.end());
  corners.erase(std::remove_if(corners.begin(), corners.end(), [&](int32_t v) { return v == x || v == y; }),
                corners.end());
}

}  // namespace tc::sequential_detail
