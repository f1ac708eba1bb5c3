// Vertex relocation: a vertex moves to raise the worst quality of its star. The objective (the
// smallest min-sine of the star) is not smooth, so each step follows the gradient of the worst
// tet, or the mean of the gradients of the nearly worst ones, with a halving line search that
// accepts only a rise of the worst (after Freitag and Ollivier-Gooch's non-smooth smoothing, in
// its simplest form). The gradients are taken numerically: the measure is cheap and a star has
// a few dozen tets.
#include <algorithm>
#include <cmath>
#include <limits>

#include "improve/improve_mesh.hpp"

namespace tc::improve_detail {

namespace {

constexpr int kSteps = 4;         // ascent steps per vertex and pass
constexpr int kHalvings = 8;      // line search
constexpr double kNearlyWorst = 1e-3;
// A relocation that raises the star's worst min-sine by less is not made: such gains do not
// change what a user measures, and a vertex making them would be retried every pass.
constexpr double kMinGain = 1e-3;

// The worst quality of the star with v at p, or any value <= bound once one tet is that bad:
// most trial positions fail, and the worst tets come first in `star`.
double star_min(const ImpMesh& m, const std::vector<int32_t>& star, int32_t v, tc_d3 p, double bound) {
  double q = std::numeric_limits<double>::infinity();
  for (int32_t t : star) {
    q = std::min(q, m.quality_with(t, v, p));
    if (q <= bound) break;
  }
  return q;
}

double star_max_cos(const ImpMesh& m, int32_t v, tc_d3 p) {
  double c = -1;
  for (int32_t t : m.tets_of(v)) c = std::max(c, m.max_cos_with(t, v, p));
  return c;
}

tc_d3 gradient(const ImpMesh& m, int32_t t, int32_t v, tc_d3 p, double h) {
  const tc_d3 ex{h, 0, 0}, ey{0, h, 0}, ez{0, 0, h};
  return tc_d3{m.quality_with(t, v, p + ex) - m.quality_with(t, v, p - ex),
               m.quality_with(t, v, p + ey) - m.quality_with(t, v, p - ey),
               m.quality_with(t, v, p + ez) - m.quality_with(t, v, p - ez)} /
         (2 * h);
}

}  // namespace

bool try_smooth(ImpMesh& m, int32_t v) {
  const Motion motion = m.motion(v);
  if (motion == kFixed || m.tets_of(v).empty()) return false;
  const tc_d3 n = m.motion_direction(v);
  auto allowed = [&](tc_d3 d) {
    return motion == kInPlane ? d - n * geo::dot(d, n) : motion == kAlongLine ? n * geo::dot(d, n) : d;
  };
  tc_d3 p = m.point(v);
  // The scale of the star: its mean edge length at v.
  double scale = 0;
  int count = 0;
  for (int32_t t : m.tets_of(v))
    for (int32_t x : m.tet(t))
      if (x != v) {
        scale += geo::length(m.point(x) - p);
        ++count;
      }
  scale /= count;
  const double h = 1e-7 * scale;
  std::vector<int32_t> star = m.tets_of(v);
  std::sort(star.begin(), star.end(), [&](int32_t a, int32_t b) { return m.quality(a) < m.quality(b); });
  const double inf = std::numeric_limits<double>::infinity();
  double current = star_min(m, star, v, p, -inf), current_cos = star_max_cos(m, v, p);
  const double start = current;
  std::vector<double> qualities;  // of the star's tets (tets_of(v) order) at p
  bool moved = false;
  for (int step = 0; step < kSteps; ++step) {
    double worst = std::numeric_limits<double>::infinity();
    int32_t worst_tet = -1;
    qualities.clear();
    for (int32_t t : m.tets_of(v)) {
      qualities.push_back(m.quality_with(t, v, p));
      if (qualities.back() < worst) {
        worst = qualities.back();
        worst_tet = t;
      }
    }
    tc_d3 directions[2] = {allowed(gradient(m, worst_tet, v, p, h)), {0, 0, 0}};
    for (size_t i = 0; i < qualities.size(); ++i)
      if (qualities[i] <= worst + kNearlyWorst)
        directions[1] = directions[1] + geo::normalize(allowed(gradient(m, m.tets_of(v)[i], v, p, h)));
    // The mean of opposed unit gradients cancels to rounding noise, whose direction is
    // arbitrary (off the allowed plane or line): skip it. Every direction is projected again
    // after normalising, so rounding does not take a vertex off its plane or line.
    if (geo::length(directions[1]) < 1e-6) directions[1] = {0, 0, 0};
    bool improved = false;
    for (tc_d3 d : directions) {
      d = allowed(geo::normalize(d));
      const double len = geo::length(d);
      if (!(len > 0.5)) continue;
      d = d / len;
      for (double s = 0.25 * scale, k = 0; k < kHalvings && !improved; ++k, s *= 0.5) {
        const tc_d3 candidate = p + d * s;
        if (!m.within_reach(v, candidate)) continue;
        const double q = star_min(m, star, v, candidate, current);
        if (!(q > current)) continue;
        const double c = star_max_cos(m, v, candidate);
        if (m.improves(current, current_cos, q, c) && (!m.bends_surface(v) || m.surface_stays_clear(v, candidate))) {
          p = candidate;
          current = q;
          current_cos = c;
          improved = true;
        }
      }
      if (improved) break;
    }
    if (!improved) break;
    moved = true;
  }
  if (!moved || current < start + kMinGain) return false;
  m.move(v, p);
  if (motion != kFree) m.surface_moved(v);  // its surface triangles moved: re-list them
  return true;
}

void smooth_pass(ImpMesh& m, const std::vector<int32_t>& bad, ImprovePassStats& stats) {
  std::vector<int32_t> verts;
  for (int32_t t : bad)
    if (m.alive(t))
      for (int32_t v : m.tet(t)) verts.push_back(v);
  std::sort(verts.begin(), verts.end());
  verts.erase(std::unique(verts.begin(), verts.end()), verts.end());
  for (int32_t v : verts) {
    if (m.settled(m.smooth_failed_at, v)) continue;  // it found nothing and nothing changed since
    if (try_smooth(m, v)) ++stats.relocated;
    else m.failed(m.smooth_failed_at, v);
  }
}

}  // namespace tc::improve_detail
