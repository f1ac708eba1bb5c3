// The boundary error bound measured against the reference surface
// (collapse/surface_distance.hpp, CollapseOptions::boundary_reference): the distance pieces on
// shapes built for them, then whole runs, measured by the checker's two-sided distance.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <memory>
#include <random>
#include <string>

#include "collapse/surface_distance.hpp"
#include "test_support.hpp"
#include "tetcollapse/check.hpp"
#include "tetcollapse/coarsen.hpp"
#include "tetcollapse/io.hpp"
#include "tetcollapse/collapse.hpp"
#include "tetcollapse/topology.hpp"

namespace tc {
namespace {

using geo::tc_d3;
using surface_distance::Tri;

TEST(SurfaceDistance, PointTriangleDistanceIsTheSmallestOverTheTriangle) {
  std::mt19937 g(7);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int it = 0; it < 300; ++it) {
    const Tri t{tc_d3{u(g), u(g), u(g)}, tc_d3{u(g), u(g), u(g)}, tc_d3{u(g), u(g), u(g)}};
    const tc_d3 p{2 * u(g), 2 * u(g), 2 * u(g)};
    const double d = surface_distance::point_triangle_dist2(p, t);
    double sampled = INFINITY;
    const int n = 200;
    for (int i = 0; i <= n; ++i)
      for (int j = 0; i + j <= n; ++j) {
        const tc_d3 q = t[0] + (t[1] - t[0]) * (double(i) / n) + (t[2] - t[0]) * (double(j) / n);
        sampled = std::min(sampled, geo::dot(p - q, p - q));
      }
    EXPECT_LE(d, sampled + 1e-12) << it;
    EXPECT_GE(std::sqrt(d), std::sqrt(sampled) - 0.02) << it << ": no smaller than a point of it";
  }
}

// A triangle of no area (a repeated corner, or three points on a line) is its edges.
TEST(SurfaceDistance, ATriangleOfNoAreaIsItsEdges) {
  const tc_d3 p{0.5, 1, 0};
  for (const Tri& t : {Tri{tc_d3{0, 0, 0}, tc_d3{0, 0, 0}, tc_d3{1, 0, 0}},
                       Tri{tc_d3{0, 0, 0}, tc_d3{0.5, 0, 0}, tc_d3{1, 0, 0}}, Tri{tc_d3{1, 0, 0}, tc_d3{1, 0, 0}, tc_d3{1, 0, 0}}}) {
    const double d = surface_distance::point_triangle_dist2(p, t);
    const double expected = t[0].x == 1 ? 0.25 + 1 : 1;
    EXPECT_DOUBLE_EQ(d, expected);
  }
}

// The unit square in z = 0 as two triangles, and a triangle over its diagonal at height h.
std::vector<double> square() { return {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 0, 0, 1, 1, 0, 0, 1, 0}; }

TEST(SurfaceDistance, ATriangleIsWithinWhatItsHeightSays) {
  const surface_distance::ReferenceSurface ref(square());
  std::vector<const Tri*> feats;
  for (size_t i = 0; i < ref.size(); ++i) feats.push_back(&ref.tri(int32_t(i)));
  const double e = 0.01;
  for (double h : {0.0, 0.5 * e, 0.9 * e, 1.01 * e, 2 * e}) {
    // across the square's diagonal: no single triangle of the square holds it, so it is split
    // (near the diagonal into pieces small against e - h)
    const Tri t{tc_d3{0.1, 0.2, h}, tc_d3{0.9, 0.3, h}, tc_d3{0.4, 0.8, h}};
    EXPECT_EQ(surface_distance::within(t, feats, e * e, 8), h <= 0.9 * e) << h;
  }
  // beyond the square's edge by more than e: farther than e, whatever the height
  const Tri out{tc_d3{0.5, 0.5, 0}, tc_d3{1.02, 0.5, 0}, tc_d3{0.5, 0.9, 0}};
  EXPECT_FALSE(surface_distance::within(out, feats, e * e, 8));
}

// Across the edge two features share, the plane that bisects their angle cuts a piece into two
// parts, each within e of its own feature: certified whole, without a split (depth 0).
TEST(SurfaceDistance, APieceAcrossACommonEdgeIsHeldByBothFeatures) {
  const surface_distance::ReferenceSurface ref(square());
  std::vector<const Tri*> feats;
  for (size_t i = 0; i < ref.size(); ++i) feats.push_back(&ref.tri(int32_t(i)));
  const double e = 0.01;
  const Tri across{tc_d3{0.4, 0.5, 0.5 * e}, tc_d3{0.6, 0.45, 0.5 * e}, tc_d3{0.52, 0.6, 0.5 * e}};
  EXPECT_TRUE(surface_distance::within(across, feats, e * e, 0));
  const Tri high{tc_d3{0.4, 0.5, 1.1 * e}, tc_d3{0.6, 0.45, 1.1 * e}, tc_d3{0.52, 0.6, 1.1 * e}};
  EXPECT_FALSE(surface_distance::within(high, feats, e * e, 0));
  // one feature alone holds no piece across the edge: without the other, refused
  const std::vector<const Tri*> one = {feats[0]};
  EXPECT_FALSE(surface_distance::within(across, one, e * e, 0));
}

// Sound on folded pairs: whatever within() certifies (any depth), every point of the piece,
// densely sampled, lies within e of the two triangles.
TEST(SurfaceDistance, WhatTheCutCertifiesIsWithinTheBound) {
  std::mt19937 g(11);
  std::uniform_real_distribution<double> u(-1, 1);
  int certified = 0;
  for (int it = 0; it < 400; ++it) {
    // two triangles on the edge (0,0,0)-(1,0,0), folded by a random angle
    const double fold = 0.2 + 1.4 * (u(g) + 1), e = 0.02 + 0.05 * (u(g) + 1);
    const Tri t1{tc_d3{0, 0, 0}, tc_d3{1, 0, 0}, tc_d3{0.5 + 0.3 * u(g), 1, 0}};
    const Tri t2{tc_d3{1, 0, 0}, tc_d3{0, 0, 0}, tc_d3{0.5 + 0.3 * u(g), -std::cos(fold), std::sin(fold)}};
    const std::vector<const Tri*> feats = {&t1, &t2};
    const tc_d3 c{0.5 + 0.2 * u(g), 0.1 * u(g), 0.1 * u(g)};
    const double r = 0.05 + 0.1 * (u(g) + 1);
    const Tri piece{c + tc_d3{r * u(g), r * u(g), r * u(g)}, c + tc_d3{r * u(g), r * u(g), r * u(g)},
                    c + tc_d3{r * u(g), r * u(g), r * u(g)}};
    if (!surface_distance::within(piece, feats, e * e, it % 3)) continue;
    ++certified;
    double worst = 0;
    const int n = 60;
    for (int i = 0; i <= n; ++i)
      for (int j = 0; i + j <= n; ++j) {
        const tc_d3 q = piece[0] + (piece[1] - piece[0]) * (double(i) / n) + (piece[2] - piece[0]) * (double(j) / n);
        worst = std::max(worst, std::min(surface_distance::point_triangle_dist2(q, t1),
                                         surface_distance::point_triangle_dist2(q, t2)));
      }
    EXPECT_LE(std::sqrt(worst), e * (1 + 1e-12)) << it;
  }
  EXPECT_GT(certified, 40) << "the random pieces test something";
}

// k triangles around the origin, their outer corners at radius 1 and the given heights.
std::vector<double> fan(const std::vector<double>& heights, double twist = 0) {
  std::vector<double> t;
  const size_t k = heights.size();
  const auto corner = [&](size_t i) {
    const double a = 2 * M_PI * (double(i % k) + (i % 2 ? twist : 0)) / double(k);
    return tc_d3{std::cos(a), std::sin(a), heights[i % k]};
  };
  for (size_t i = 0; i < k; ++i)
    for (const tc_d3& v : {tc_d3{0, 0, 0}, corner(i), corner(i + 1)}) t.insert(t.end(), {v.x, v.y, v.z});
  return t;
}

std::vector<const Tri*> all_of(const surface_distance::ReferenceSurface& ref) {
  std::vector<const Tri*> f;
  for (size_t i = 0; i < ref.size(); ++i) f.push_back(&ref.tri(int32_t(i)));
  return f;
}

// The largest distance to the features over points of the piece on a grid of n steps a side.
double sampled_distance(const Tri& piece, const std::vector<const Tri*>& feats, int n) {
  double worst = 0;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; i + j <= n; ++j) {
      const tc_d3 q = piece[0] + (piece[1] - piece[0]) * (double(i) / n) + (piece[2] - piece[0]) * (double(j) / n);
      double d2 = INFINITY;
      for (const Tri* t : feats) d2 = std::min(d2, surface_distance::point_triangle_dist2(q, *t));
      worst = std::max(worst, d2);
    }
  return std::sqrt(worst);
}

// Over a vertex of the reference, the wedges around its fan cut a piece into parts, each
// within e of its own triangle: certified whole (depth 0), which no two triangles do.
TEST(SurfaceDistance, APieceOverAVertexIsHeldByItsFan) {
  const surface_distance::ReferenceSurface ref(fan(std::vector<double>(6, 0.0)));
  const std::vector<const Tri*> feats = all_of(ref);
  const double e = 0.01;
  const auto over = [](double h) {
    return Tri{tc_d3{-0.3, -0.2, h}, tc_d3{0.35, -0.25, h}, tc_d3{0.05, 0.4, h}};
  };
  EXPECT_TRUE(surface_distance::within(over(0.5 * e), feats, e * e, 0, nullptr, &ref));
  EXPECT_FALSE(surface_distance::within(over(0.5 * e), feats, e * e, 0)) << "not without the fans";
  EXPECT_FALSE(surface_distance::within(over(1.1 * e), feats, e * e, 0, nullptr, &ref));
  EXPECT_FALSE(surface_distance::within(over(1.1 * e), feats, e * e, 8, nullptr, &ref));
  // a piece reaching past the fan's outer edges: not held by it
  const Tri past{tc_d3{-1.2, -0.2, 0}, tc_d3{0.35, -0.25, 0}, tc_d3{0.05, 0.4, 0}};
  EXPECT_FALSE(surface_distance::within(past, feats, e * e, 0, nullptr, &ref));
}

// Sound on bent and twisted fans: whatever within() certifies with the fans (any depth), every
// point of the piece, densely sampled, lies within e of the reference.
TEST(SurfaceDistance, WhatTheFanCertifiesIsWithinTheBound) {
  std::mt19937 g(5);
  std::uniform_real_distribution<double> u(-1, 1);
  int certified = 0, whole = 0;
  for (int it = 0; it < 600; ++it) {
    const size_t k = 3 + size_t(it % 6);
    std::vector<double> heights(k);
    const double bend = it % 4 == 0 ? 1.5 : 0.3;  // (some fans folded past what wedges allow)
    for (double& h : heights) h = bend * u(g);
    const surface_distance::ReferenceSurface ref(fan(heights, 0.3 * u(g)));
    const std::vector<const Tri*> feats = all_of(ref);
    const double e = 0.01 + 0.02 * (u(g) + 1);
    // corners on three of the fan's triangles (within 0.5 of its vertex), off it by up to e
    const auto near_fan = [&](size_t i) {
      const Tri& t = *feats[i % k];
      const double b1 = 0.25 * (u(g) + 1), b2 = 0.25 * (u(g) + 1);
      return t[0] + (t[1] - t[0]) * b1 + (t[2] - t[0]) * b2 + tc_d3{0, 0, e * u(g)};
    };
    const size_t first = size_t(it);
    const Tri piece{near_fan(first), near_fan(first + 1 + size_t(it / 7) % (k - 1)), near_fan(first + k / 2)};
    const int depth = it % 3;
    if (!surface_distance::within(piece, feats, e * e, depth, nullptr, &ref)) continue;
    ++certified;
    whole += !surface_distance::within(piece, feats, e * e, depth);
    EXPECT_LE(sampled_distance(piece, feats, 60), e * (1 + 1e-12)) << it;
  }
  EXPECT_GT(certified, 50) << "the random pieces test something";
  EXPECT_GT(whole, 25) << "and the fans certify what the splits alone do not";
}

// A piece in the plane of a wedge's side (the fan flat, its axis z: the plane through the vertex,
// an edge's end and z) has every corner on that side up to rounding, which may alternate: the
// clipping then makes more points than a convex cut would, within its buffers, and what it
// certifies is within the bound.
TEST(SurfaceDistance, PiecesInAWedgesPlaneAreCutSafely) {
  std::mt19937 g(3);
  std::uniform_real_distribution<double> u(-1, 1);
  int certified = 0;
  for (int it = 0; it < 2000; ++it) {
    const size_t k = 4 + size_t(it % 5);
    const surface_distance::ReferenceSurface ref(fan(std::vector<double>(k, 0.0), 0.2 * u(g)));
    const std::vector<const Tri*> feats = all_of(ref);
    const tc_d3 w = (*feats[size_t(it) % k])[1];  // an outer corner: a wedge side through it
    const auto in_plane = [&] { return w * (0.5 * u(g)) + tc_d3{0, 0, 1e-3 * u(g)}; };  // (across the vertex)
    const Tri piece{in_plane(), in_plane(), in_plane()};
    const double e = 2e-3;
    if (!surface_distance::within(piece, feats, e * e, it % 3, nullptr, &ref)) continue;
    ++certified;
    EXPECT_LE(sampled_distance(piece, feats, 20), e * (1 + 1e-12)) << it;
  }
  EXPECT_GT(certified, 1000) << "the pieces test something";
}

// The unit square as a grid of n x n cells, two triangles each (counterclockwise seen from +z),
// its vertices at the heights z(i, j); without the triangles `skip` lists.
std::vector<double> grid(int n, const std::function<double(int, int)>& z, const std::vector<int>& skip = {}) {
  std::vector<double> t;
  const auto at = [&](int i, int j) { return tc_d3{double(i) / n, double(j) / n, z(i, j)}; };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const tc_d3 tris[2][3] = {{at(i, j), at(i + 1, j), at(i + 1, j + 1)}, {at(i, j), at(i + 1, j + 1), at(i, j + 1)}};
      for (int k = 0; k < 2; ++k) {
        if (std::find(skip.begin(), skip.end(), 2 * (i * n + j) + k) != skip.end()) continue;
        for (const tc_d3& v : tris[k]) t.insert(t.end(), {v.x, v.y, v.z});
      }
    }
  return t;
}

// A piece over many triangles of the reference, each far smaller than it, is cut by their
// outlines into parts each within e of its own triangle: certified whole (depth 0), which
// neither two triangles nor one fan do; not where a triangle under it is missing (its middle
// farther than e from the rest) or a vertex under it stands too high.
TEST(SurfaceDistance, APieceOverManyTrianglesIsCutByTheirOutlines) {
  const double e = 0.01;
  const auto flat = [](int, int) { return 0.0; };
  const Tri piece{tc_d3{0.1, 0.12, 0.5 * e}, tc_d3{0.9, 0.2, 0.3 * e}, tc_d3{0.4, 0.85, 0.6 * e}};
  const surface_distance::ReferenceSurface ref(grid(10, flat));
  const std::vector<const Tri*> feats = all_of(ref);
  EXPECT_TRUE(surface_distance::within(piece, feats, e * e, 0, nullptr, &ref));
  EXPECT_FALSE(surface_distance::within(piece, feats, e * e, 0)) << "not without the reference's vertices";
  // turned over: the same cut, the triangles' orientation seen from the piece reversed
  const Tri turned{piece[0], piece[2], piece[1]};
  EXPECT_TRUE(surface_distance::within(turned, feats, e * e, 0, nullptr, &ref));
  // cell (4, 4)'s first triangle missing: its middle is 0.03 from the others
  const surface_distance::ReferenceSurface holed(grid(10, flat, {2 * 44}));
  EXPECT_FALSE(surface_distance::within(piece, all_of(holed), e * e, 0, nullptr, &holed));
  EXPECT_FALSE(surface_distance::within(piece, all_of(holed), e * e, 8, nullptr, &holed));
  // a vertex under the piece 2e high
  const surface_distance::ReferenceSurface peak(grid(10, [](int i, int j) { return i == 5 && j == 4 ? 0.02 : 0.0; }));
  EXPECT_FALSE(surface_distance::within(piece, all_of(peak), e * e, 0, nullptr, &peak));
  // two sheets under the piece (the grid twice, 0.5 e apart): each point is over two triangles,
  // which the cut does not count as a cover (the splits may certify it)
  std::vector<double> two = grid(10, flat), upper = grid(10, [&](int, int) { return 0.5 * e; });
  two.insert(two.end(), upper.begin(), upper.end());
  const surface_distance::ReferenceSurface sheets(two);
  EXPECT_FALSE(surface_distance::within(piece, all_of(sheets), e * e, 0, nullptr, &sheets));
  // a patch whose rim is the piece's (the triangles of a grid inside x + y <= 1, under the
  // piece over the same triangle): its free edges lie on the piece's sides, which they do not cross
  std::vector<double> half;
  const int n = 8;
  const auto at = [&](int i, int j) { return tc_d3{double(i) / n, double(j) / n, 0.0}; };
  for (int i = 0; i < n; ++i)
    for (int j = 0; i + j < n; ++j) {
      std::vector<std::array<tc_d3, 3>> tris = {{at(i, j), at(i + 1, j), at(i, j + 1)}};
      if (i + j + 2 <= n) tris.push_back({at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)});
      for (const auto& t : tris)
        for (const tc_d3& v : t) half.insert(half.end(), {v.x, v.y, v.z});
    }
  const surface_distance::ReferenceSurface patch(half);
  const Tri over{tc_d3{0, 0, 0.5 * e}, tc_d3{1, 0, 0.5 * e}, tc_d3{0, 1, 0.5 * e}};
  EXPECT_TRUE(surface_distance::within(over, all_of(patch), e * e, 0, nullptr, &patch));
  // and one reaching past it by 2e: not held
  const Tri past{tc_d3{0, 0, 0}, tc_d3{1 + 2 * e, 0, 0}, tc_d3{0, 1, 0}};
  EXPECT_FALSE(surface_distance::within(past, all_of(patch), e * e, 0, nullptr, &patch));
}

// Sound on bumpy and folded grids and tilted pieces: whatever within() certifies with the
// reference's vertices, every point of the piece, densely sampled, lies within e of it.
TEST(SurfaceDistance, WhatTheOutlinesCertifyIsWithinTheBound) {
  std::mt19937 g(11);
  std::uniform_real_distribution<double> u(-1, 1);
  int certified = 0, whole = 0;
  for (int it = 0; it < 400; ++it) {
    const double e = 0.005 + 0.01 * (u(g) + 1);
    // heights up to 0.3 e on most grids; some up to 10 e (folded as the tilted piece sees them)
    const double amp = (it % 4 == 0 ? 10 : 0.3) * e;
    std::vector<double> h(13 * 13);
    for (double& x : h) x = amp * u(g);
    const std::vector<int> skip = it % 5 == 0 ? std::vector<int>{int(g() % 288)} : std::vector<int>{};
    const surface_distance::ReferenceSurface ref(grid(12, [&](int i, int j) { return h[size_t(13 * i + j)]; }, skip));
    const std::vector<const Tri*> feats = all_of(ref);
    const auto corner = [&] {
      return tc_d3{0.5 + 0.45 * u(g), 0.5 + 0.45 * u(g), (it % 3 == 0 ? 0.1 : 1.2 * e) * u(g)};
    };
    const Tri piece{corner(), corner(), corner()};
    const int depth = it % 2;
    if (!surface_distance::within(piece, feats, e * e, depth, nullptr, &ref)) continue;
    ++certified;
    whole += !surface_distance::within(piece, feats, e * e, depth);
    EXPECT_LE(sampled_distance(piece, feats, 50), e * (1 + 1e-12)) << it;
  }
  EXPECT_GT(certified, 40) << "the random pieces test something";
  EXPECT_GT(whole, 20) << "and the outlines certify what the splits alone do not";
}

// A tent of height h over the unit square's centre (four triangles) as the reference and as S;
// the collapse of the apex onto a corner flattens it (two triangles).
struct Tent {
  std::vector<double> reference;
  std::vector<Tri> olds, news;
};
Tent tent(double h) {
  const tc_d3 c{0.5, 0.5, h}, p[4] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  Tent t;
  for (int i = 0; i < 4; ++i) {
    const Tri f{p[i], p[(i + 1) % 4], c};
    t.olds.push_back(f);
    for (const tc_d3& v : f) t.reference.insert(t.reference.end(), {v.x, v.y, v.z});
  }
  t.news = {Tri{p[0], p[1], p[2]}, Tri{p[0], p[2], p[3]}};
  return t;
}

TEST(SurfaceDistance, FlatteningATentIsMadeOnlyWithinTheBound) {
  const double e = 0.01;
  for (double h : {0.5 * e, 0.9 * e, 1.2 * e, 3 * e}) {
    const Tent t = tent(h);
    const surface_distance::ReferenceSurface ref(t.reference);
    EXPECT_EQ(ref.change_ok(t.olds, t.news, {}, e, e), h <= 0.9 * e) << h;
  }
}

// TETCOLLAPSE_RECORD_CHECKS records the first reference surface and its checks, which replay
// (bench/bench_measured_check) to the same verdicts; nothing is written without it.
TEST(SurfaceDistance, RecordedChecksReplayToTheSameVerdicts) {
  const test::TempDir dir;
  const std::string path = dir.file("checks.bin");
  const Tent t = tent(0.01);  // flattened: within e exactly when e is at least its height
  const std::vector<double> bounds = {0.005, 0.009, 0.012, 0.03};
  std::vector<bool> verdicts;
  {
    auto record = std::make_unique<const test::EnvVar>("TETCOLLAPSE_RECORD_CHECKS", path);
    const surface_distance::ReferenceSurface ref(t.reference);
    record.reset();
    const surface_distance::ReferenceSurface other(tent(0.02).reference);  // (not recorded)
    for (double e : bounds) {
      verdicts.push_back(ref.change_ok(t.olds, t.news, {}, e, e));
      other.change_ok(t.olds, t.news, {}, e, e);
    }
  }
  EXPECT_EQ(verdicts, (std::vector<bool>{false, false, true, true}));
  std::vector<double> reference;
  std::vector<surface_distance::RecordedCheck> checks;
  ASSERT_TRUE(surface_distance::read_recorded_checks(path.c_str(), reference, checks));
  EXPECT_EQ(reference, t.reference);
  ASSERT_EQ(checks.size(), verdicts.size());
  const surface_distance::ReferenceSurface replay(reference);
  for (size_t i = 0; i < checks.size(); ++i) {
    const auto& c = checks[i];
    EXPECT_EQ(c.e, bounds[i]);
    EXPECT_EQ(c.news.size(), t.news.size());
    EXPECT_EQ(replay.change_ok(c.olds, c.news, c.around, c.e, c.reach), verdicts[i]) << i;
  }
  std::vector<double> none;
  EXPECT_FALSE(surface_distance::read_recorded_checks(dir.file("missing.bin").c_str(), none, checks));
}

// A reference triangle over a vertex inside the new patch, far larger than the bound, is
// certified by the patch's fan around that vertex (each wedge's part within e of its triangle),
// where splitting it would need pieces smaller than the bound around the vertex, deeper than
// the branch and bound goes.
TEST(SurfaceDistance, AReferenceTriangleOverANewVertexIsHeldByItsFan) {
  const double e = 1e-4;
  const tc_d3 a{0, 0, 0}, b{1, 0, 0}, c{0.3, 1, 0}, v{0.4, 0.35, 0};
  const std::vector<double> reference = {a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z};
  const surface_distance::ReferenceSurface ref(reference);
  const std::vector<Tri> olds = {Tri{a, b, c}}, news = {Tri{a, b, v}, Tri{b, c, v}, Tri{c, a, v}};
  EXPECT_TRUE(ref.change_ok(olds, news, {}, e, e)) << "a vertex inserted in the plane moves nothing";
  // the same vertex lifted beyond the bound: refused
  const tc_d3 up{v.x, v.y, 3 * e};
  EXPECT_FALSE(ref.change_ok(olds, {Tri{a, b, up}, Tri{b, c, up}, Tri{c, a, up}}, {}, e, e));
}

// A reference triangle held whole by an S triangle in one check is tried against that triangle
// first in the next (ReferenceSurface::holder_): the verdicts of a surface that has measured
// before are those of a fresh one, whether the triangle that held it is still there or gone
// (its place left bare: the new triangles lie on the reference, so only the reference's side
// can refuse).
TEST(SurfaceDistance, ATriangleThatHeldTheReferenceBeforeDecidesNothingOnceItIsGone) {
  const double e = 0.01;
  std::vector<double> reference;  // [0, 2] x [0, 1] at z = 0 in small triangles, diagonals (x0, y0)-(x1, y1)
  const int n = 16;
  for (int i = 0; i < 2 * n; ++i)
    for (int j = 0; j < n; ++j) {
      const double x0 = double(i) / n, x1 = double(i + 1) / n, y0 = double(j) / n, y1 = double(j + 1) / n;
      reference.insert(reference.end(), {x0, y0, 0, x1, y0, 0, x1, y1, 0, x0, y0, 0, x1, y1, 0, x0, y1, 0});
    }
  // S: two unit squares, two triangles each along the reference's diagonals (each small
  // triangle lies in one of them whole)
  const tc_d3 a{0, 0, 0}, b{1, 0, 0}, c{1, 1, 0}, d{0, 1, 0}, f{2, 0, 0}, g{2, 1, 0};
  const std::vector<Tri> left = {Tri{a, b, c}, Tri{a, c, d}}, right = {Tri{b, f, g}, Tri{b, g, c}};
  const std::vector<Tri> right_half = {Tri{b, f, g}};  // (b, g, c) gone, nothing in its place
  struct Step {
    const std::vector<Tri>&olds, &news, &around;
    bool verdict;
  };
  const Step steps[] = {
      {right, right, left, true},        // every small triangle of the right square held by one of it
      {right, right_half, left, false},  // those (b, g, c) held are left bare: no hint may hold them
      {right_half, right, left, true},   // (b, g, c) back: held again
  };
  const surface_distance::ReferenceSurface used(reference);
  for (size_t i = 0; i < std::size(steps); ++i) {
    const Step& st = steps[i];
    const surface_distance::ReferenceSurface fresh(reference);
    EXPECT_EQ(fresh.change_ok(st.olds, st.news, st.around, e, e), st.verdict) << i;
    EXPECT_EQ(used.change_ok(st.olds, st.news, st.around, e, e), st.verdict) << i;
  }
}

// Direction from the reference: a new S far from the old one fails through the reference
// points the old S stood for, even when the new triangles lie on the reference (a tent's base
// collapsed away from its apex: the base lies on nothing of a raised reference).
TEST(SurfaceDistance, TheReferenceTheOldTrianglesStoodForMustStayNear) {
  const double e = 0.01;
  const Tent t = tent(0.5);  // a steep tent: the flat base is far from the apex
  const surface_distance::ReferenceSurface ref(t.reference);
  // the new triangles: the tent's own two faces through the apex, which cover only half of it
  const std::vector<Tri> half = {t.olds[0], t.olds[1]};
  EXPECT_FALSE(ref.change_ok(t.olds, half, {}, e, e)) << "the other half of the tent is left far";
  EXPECT_TRUE(ref.change_ok(t.olds, half, {t.olds[2], t.olds[3]}, e, e)) << "unless it stays around";
  EXPECT_TRUE(ref.change_ok(t.olds, t.olds, {}, e, e)) << "nothing changed";
  // and from the new triangles: one reaching beyond the reference fails although every
  // reference point keeps a new triangle over it
  std::vector<Tri> wider = t.olds;
  wider.push_back(Tri{tc_d3{1, 0, 0}, tc_d3{1.5, 0, 0}, tc_d3{1, 1, 0}});
  EXPECT_FALSE(ref.change_ok(t.olds, wider, {}, e, e)) << "a new triangle off the reference";
}

// The reference surface of a mesh (tc::feature_surface_triangles) is its S as the topology
// lists it: the boundary, and the interface between labels unless they are ignored.
TEST(SurfaceDistance, TheFeatureSurfaceIsTheTopologysS) {
  for (const auto& [name, m] : {std::pair<std::string, Mesh>{"ball", test::ball(4)}, {"two materials", test::two_materials(4)}})
    for (bool labels : {true, false}) {
      TopologyOptions to;
      to.use_labels = labels;
      const Topology topo = build_topology(m, to);
      std::vector<std::array<double, 9>> expected, got;
      const auto key = [](const double* p) {  // a triangle by its sorted corners
        std::array<std::array<double, 3>, 3> c{{{p[0], p[1], p[2]}, {p[3], p[4], p[5]}, {p[6], p[7], p[8]}}};
        std::sort(c.begin(), c.end());
        return std::array<double, 9>{c[0][0], c[0][1], c[0][2], c[1][0], c[1][1], c[1][2], c[2][0], c[2][1], c[2][2]};
      };
      for (size_t f = 0; f < topo.sfaces.size(); f += 3) {
        double p[9];
        for (int k = 0; k < 3; ++k)
          for (int d = 0; d < 3; ++d) p[3 * k + d] = m.points[3 * size_t(topo.sfaces[f + size_t(k)]) + size_t(d)];
        expected.push_back(key(p));
      }
      const std::vector<double> tris = feature_surface_triangles(m, labels);
      ASSERT_EQ(tris.size() % 9, 0u);
      for (size_t i = 0; i < tris.size(); i += 9) got.push_back(key(&tris[i]));
      std::sort(expected.begin(), expected.end());
      std::sort(got.begin(), got.end());
      EXPECT_EQ(got, expected) << name << (labels ? "" : ", labels ignored");
      EXPECT_FALSE(got.empty()) << name;
    }
}

// A check of many triangles measures on two threads; its verdict is the same whichever thread
// measures which piece: repeated runs give the same mesh.
TEST(SurfaceDistanceRun, MeasuredRunsAreDeterministic) {
  const Mesh in = test::torus(6, 24);
  CollapseOptions o;
  o.target_factor = 2;
  o.max_boundary_error = 0.004;
  o.method = CollapseOptions::Sequential;
  Mesh first = in;
  collapse_sequential(first, o);
  for (int run = 0; run < 4; ++run) {
    Mesh m = in;
    collapse_sequential(m, o);
    EXPECT_EQ(m.points, first.points) << run;
    EXPECT_EQ(m.tets, first.tets) << run;
  }
}

double hausdorff_rel(const Mesh& out, const Mesh& in) {
  CheckOptions co;
  co.hausdorff = true;
  const CheckReport r = check_mesh(out, co, &in);
  EXPECT_TRUE(r.valid) << check_report_text(r);
  EXPECT_FALSE(r.reference.topology_changed);
  return r.reference.hausdorff_rel;
}

// A collapse of m by the sequential or the parallel method.
CollapseReport collapse_by(bool sequential, Mesh& m, CollapseOptions o, Context& ctx) {
  if (!sequential) return collapse(m, o, ctx);
  o.method = CollapseOptions::Sequential;
  return collapse_sequential(m, o);
}

// A detail of the boundary smaller than the bound goes: a cube with a notch of an eighth of its
// side at a corner (three concave ridges, corners), under a bound larger than the notch, loses
// more tets with the merge of features than without, and stays within the bound; under a bound
// smaller than every boundary edge nothing merges.
TEST(SurfaceDistanceRun, DetailsSmallerThanTheBoundMerge) {
  const Mesh notched = test::notched_cube(8);
  Context ctx;
  for (bool parallel : {false, true})
    for (double e : {0.08, 1e-4}) {
      int64_t tets[2];
      std::vector<double> points[2];
      for (bool merge : {false, true}) {
        CollapseOptions o;
        o.target_factor = 2;
        o.max_boundary_error = e;
        o.tuning.merge_features_within_bound = merge;
        Mesh m = notched;
        collapse_by(!parallel, m, o, ctx);
        if (merge && e > 0.01) {
          EXPECT_LE(hausdorff_rel(m, notched), e) << (parallel ? "parallel" : "sequential");
        }
        tets[merge] = m.num_tets();
        points[merge] = m.points;
      }
      if (e > 0.01) {
        EXPECT_LT(tets[1], tets[0]) << (parallel ? "parallel" : "sequential") << ": the notch merges";
      } else {
        EXPECT_EQ(points[1], points[0]) << (parallel ? "parallel" : "sequential") << ": no edge is that short";
      }
    }
}

// A run whose host tail starts early on the shared wrench nut (--host-tail 0.03) met a piece
// whose cut by a wedge made more points than the cut's buffer held, and crashed: it now ends
// valid and within the bound.
TEST(SurfaceDistanceRun, AnEarlyHostTailOnTheWrenchNutStaysWithinTheBound) {
  TC_SKIP_IF_NO_SHARED();
  const std::string path = test::shared_mesh("gen_gmsh_wrenchnut_27k.msh");
  if (path.empty()) GTEST_SKIP() << "gen_gmsh_wrenchnut_27k.msh is absent from the shared meshes; skipped";
  const Mesh in = read_mesh(path);
  Mesh m = in;
  Context ctx;
  CollapseOptions o;
  o.target_factor = 2;
  o.max_boundary_error = 0.001;  // (the CLI's default)
  o.tuning.host_tail = 0.03;
  collapse(m, o, ctx);
  EXPECT_LT(m.num_tets(), in.num_tets() / 2);
  EXPECT_LE(hausdorff_rel(m, in), o.max_boundary_error * (1 + 1e-9));
}

// Whole runs on curved shapes: measured where the carried bound refuses, the curved faces
// coarsen further, and the checker's distance stays within the bound; both methods, and the
// coarsening with its improvement phase and later cycles, which go on from the reference.
TEST(SurfaceDistanceRun, MeasuredChangesCoarsenFurtherWithinTheBound) {
  Context ctx;
  const double e = 0.004;
  for (const auto& [name, in] : {std::pair<std::string, Mesh>{"torus", test::torus(6, 24)},
                                 {"filleted cylinder", test::filleted_cylinder(10, 0.3)}}) {
    for (int how = 0; how < 3; ++how) {
      const std::string what = name + (how == 0 ? ", sequential" : how == 1 ? ", parallel" : ", coarsen");
      int64_t tets[2];
      for (bool measure : {false, true}) {
        CollapseOptions o;
        o.target_factor = 2;
        o.max_boundary_error = e;
        o.tuning.remeasure_boundary_error = measure;
        Mesh m = in;
        if (how < 2) {
          const CollapseReport r = collapse_by(how == 0, m, o, ctx);
          EXPECT_EQ(r.boundary_reference != nullptr, measure) << what;
        } else {
          CoarsenOptions co;
          co.collapse = o;
          const CoarsenReport r = coarsen(m, co, &ctx);
          EXPECT_TRUE(r.improved) << what;
          EXPECT_FALSE(r.later_cycles.empty()) << what;
        }
        EXPECT_LE(hausdorff_rel(m, in), e) << what << (measure ? ", measured" : ", carried");
        tets[measure] = m.num_tets();
      }
      EXPECT_LT(tets[1], tets[0]) << what << ": the measured bound lets more of S coarsen";
    }
  }
}

}  // namespace
}  // namespace tc
