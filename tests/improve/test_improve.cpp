// The improvement: each operation alone on a configuration built for it, then the whole phase
// on coarsened meshes (validity by the checker, the boundary kept, determinism).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <set>

#include "geometry.h"
#include "improve/improve_mesh.hpp"
#include "improve/star_mesh.hpp"
#include "test_support.hpp"
#include "tetcollapse/check.hpp"
#include "tetcollapse/collapse.hpp"
#include "tetcollapse/device.hpp"
#include "tetcollapse/improve.hpp"
#include "tetcollapse/io.hpp"

namespace tc {
namespace {

using improve_detail::ImpMesh;
using namespace test;
constexpr double kPi = 3.14159265358979323846;

double volume_of(const Mesh& m) {
  double v = 0;
  for (int64_t t = 0; t < m.num_tets(); ++t) {
    geo::tc_d3 p[4];
    for (int k = 0; k < 4; ++k) p[k] = geo::tc_point(m.points.data(), m.tets[size_t(4 * t + k)]);
    v += geo::tc_tet_volume(p[0], p[1], p[2], p[3]);
  }
  return v;
}

double worst(const Mesh& m) {
  double q = 2;
  for (int64_t t = 0; t < m.num_tets(); ++t) {
    geo::tc_d3 p[4];
    for (int k = 0; k < 4; ++k) p[k] = geo::tc_point(m.points.data(), m.tets[size_t(4 * t + k)]);
    q = std::min(q, geo::tc_tet_min_sine(p[0], p[1], p[2], p[3]));
  }
  return q;
}

// n ring vertices on the unit circle (z = 0), a = (0, 0, h) and b = (0, 0, -h); the n tets
// around the edge (a, b), positively oriented. Vertices: 0 = a, 1 = b, 2.. = ring.
Mesh edge_ring(int n, double h) {
  Mesh m;
  m.points = {0, 0, h, 0, 0, -h};
  for (int i = 0; i < n; ++i) {
    m.points.push_back(std::cos(2 * kPi * i / n));
    m.points.push_back(std::sin(2 * kPi * i / n));
    m.points.push_back(0);
  }
  // A ring counterclockwise seen from a gives (a, b, r_i+1, r_i) positive.
  for (int i = 0; i < n; ++i) m.tets.insert(m.tets.end(), {0, 1, 2 + (i + 1) % n, 2 + i});
  return m;
}

// The same bipyramid as two tets sharing the triangle of a 3-ring.
Mesh two_tets(double h) {
  Mesh m = edge_ring(3, h);
  m.tets = {2, 3, 4, 0, 4, 3, 2, 1};
  return m;
}

// cube_tets(n) with every coordinate strictly inside (0, 1) moved by up to `amplitude`.
Mesh jiggled_cube(int n, double amplitude, unsigned seed) {
  Mesh m = cube_tets(n);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-amplitude, amplitude);
  for (double& x : m.points)
    if (x > 0 && x < 1) x += u(rng);
  return m;
}

TEST(ImproveMeasure, MinSineMatchesTheDihedralAngles) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 200; ++i) {
    geo::tc_d3 p[4];
    for (auto& x : p) x = {u(rng), u(rng), u(rng)};
    if (geo::tc_tet_volume(p[0], p[1], p[2], p[3]) < 0) std::swap(p[0], p[1]);
    const double lo = geo::tc_min_dihedral(p[0], p[1], p[2], p[3]), hi = geo::tc_max_dihedral(p[0], p[1], p[2], p[3]);
    EXPECT_NEAR(geo::tc_tet_min_sine(p[0], p[1], p[2], p[3]), std::min(std::sin(lo), std::sin(hi)), 1e-9);
    EXPECT_LT(geo::tc_tet_min_sine(p[1], p[0], p[2], p[3]), 0) << "inverted: negative";
    EXPECT_NEAR(std::acos(geo::tc_tet_max_dihedral_cos(p[0], p[1], p[2], p[3])), lo, 1e-7);
  }
  const geo::tc_d3 r[4] = {{1, 1, 1}, {-1, 1, -1}, {1, -1, -1}, {-1, -1, 1}};
  EXPECT_NEAR(geo::tc_tet_min_sine(r[0], r[1], r[2], r[3]), std::sqrt(8.0) / 3, 1e-12) << "regular tet";
}

// The edge (0, 1) of edge_ring(n, h) is removed: `tets` tets, the same volume, a better worst.
void expect_edge_removed(int n, double h, int64_t tets) {
  Mesh m = edge_ring(n, h);
  const double v0 = volume_of(m), q0 = worst(m);
  ImpMesh im(m, {});
  EXPECT_TRUE(improve_detail::try_edge_removal(im, 0, 1));
  im.write_back();
  ASSERT_EQ(m.num_tets(), tets);
  EXPECT_NEAR(volume_of(m), v0, 1e-12);
  EXPECT_GT(worst(m), q0);
  EXPECT_FALSE(ImpMesh(m, {}).has_edge(0, 1));
}

TEST(ImproveOps, ThreeTwoFlipRemovesALongEdge) { expect_edge_removed(3, 1.0, 2); }

TEST(ImproveOps, ThreeTwoFlipRefusedWhenItWouldWorsen) {
  Mesh m = edge_ring(3, 0.3);  // the three tets are better than the two
  ImpMesh im(m, {});
  EXPECT_FALSE(improve_detail::try_edge_removal(im, 0, 1));
  im.write_back();
  EXPECT_EQ(m.num_tets(), 3);
}

TEST(ImproveOps, TwoThreeFlipSplitsAFlatPair) {
  Mesh m = two_tets(0.2);
  const double v0 = volume_of(m), q0 = worst(m);
  ImpMesh im(m, {});
  int flipped = 0;
  for (int f = 0; f < 4; ++f) flipped += improve_detail::try_flip23(im, 0, f);
  EXPECT_EQ(flipped, 1);
  im.write_back();
  ASSERT_EQ(m.num_tets(), 3);
  EXPECT_NEAR(volume_of(m), v0, 1e-12);
  EXPECT_GT(worst(m), q0);
  EXPECT_GT(worst(m), 0);
}

TEST(ImproveOps, EdgeOfFiveTetsBecomesSix) { expect_edge_removed(5, 3.0, 6); }

// A needle bipyramid: every vertex on the boundary (relocation moves none off its surface), the
// long edge (0, 1) inside. Its split at a new vertex halves the needles: 8 tets, the same
// volume, a better worst; the new vertex inside, a linear vertex field exact there.
TEST(ImproveOps, ASplitHalvesTheNeedlesOfALongInteriorEdge) {
  Mesh m = edge_ring(4, 10.0);
  m.vertex_fields.push_back({"f", 1, {}});
  for (int64_t v = 0; v < m.num_vertices(); ++v) {
    const double* p = &m.points[3 * size_t(v)];
    m.vertex_fields[0].values.push_back(1 + p[0] - 2 * p[1] + 3 * p[2]);
  }
  const double v0 = volume_of(m), q0 = worst(m);
  ASSERT_LT(std::asin(q0) * 180 / kPi, 13) << "a bad tet";
  ImpMesh im(m, {});
  for (int32_t v = 0; v < 6; ++v) ASSERT_NE(im.motion(v), improve_detail::kFree) << v;
  EXPECT_TRUE(improve_detail::try_split(im, 0));
  im.write_back();
  ASSERT_EQ(m.num_tets(), 8);
  ASSERT_EQ(m.num_vertices(), 7);
  EXPECT_NEAR(volume_of(m), v0, 1e-9);
  EXPECT_GT(worst(m), 2 * q0);
  const double* p = &m.points[18];
  EXPECT_NEAR(p[0], 0, 1e-9);
  EXPECT_NEAR(p[1], 0, 1e-9);
  EXPECT_LT(std::fabs(p[2]), 10.0);
  EXPECT_NEAR(m.vertex_fields[0].values[6], 1 + p[0] - 2 * p[1] + 3 * p[2], 1e-9);
  const CheckReport r = check_mesh(m);
  EXPECT_TRUE(r.valid) << check_report_text(r);
}

TEST(ImproveOps, ASplitThatWouldNotImproveIsRefused) {
  Mesh m = edge_ring(4, 1.0);  // an octahedron of right angles: its halves are no better
  ImpMesh im(m, {});
  EXPECT_FALSE(improve_detail::try_split(im, 0));
  im.write_back();
  EXPECT_EQ(m.num_tets(), 4);
  EXPECT_EQ(m.num_vertices(), 6);
}

TEST(ImproveOps, BoundaryEdgeIsNotRemoved) {
  Mesh m = edge_ring(5, 3.0);
  m.tets.resize(4 * 4);  // drop one tet: the ring opens, the edge lies on the boundary
  ImpMesh im(m, {});
  EXPECT_FALSE(improve_detail::try_edge_removal(im, 0, 1));
}

TEST(ImproveOps, FlipsKeepLabelsApart) {
  Mesh m = edge_ring(3, 1.0);
  m.tet_labels.push_back({"material", {1, 1, 2}});
  ImpMesh im(m, {});
  EXPECT_FALSE(improve_detail::try_edge_removal(im, 0, 1)) << "the faces around the edge include an interface";
}

// Half of a 4-ring around a long edge (a, b): its two boundary faces lie in the plane y = 0, a
// flat quad (a, r0, b, r2) whose long diagonal (a, b) flips to (r0, r2).
TEST(ImproveOps, FlatBoundaryPairFlipsItsDiagonal) {
  Mesh m = edge_ring(4, 3.0);
  m.tets.resize(2 * 4);  // (a, b, r1, r0), (a, b, r2, r1)
  const double v0 = volume_of(m), q0 = worst(m);
  const Mesh before = m;
  {
    ImpMesh im(m, {});
    EXPECT_TRUE(improve_detail::try_edge_removal(im, 0, 1));
    im.write_back();
  }
  ASSERT_EQ(m.num_tets(), 2);
  EXPECT_NEAR(volume_of(m), v0, 1e-12);
  EXPECT_GT(worst(m), q0);
  EXPECT_EQ(sface_keys(m).count({0, 2, 4}), 1u) << "the new diagonal (r0, r2) on the boundary";
  EXPECT_EQ(sface_keys(m).count({1, 2, 4}), 1u);
  const CheckReport cr = check_mesh(m, {}, &before);
  EXPECT_TRUE(cr.valid) << check_report_text(cr);

  ImproveOptions strict;
  strict.boundary = CollapseOptions::Strict;
  Mesh s = before;
  EXPECT_FALSE(improve_detail::try_edge_removal(*std::make_unique<ImpMesh>(s, strict), 0, 1)) << "strict";
  ImproveOptions fixed;
  fixed.max_boundary_move = 0;
  Mesh f = before;
  EXPECT_FALSE(improve_detail::try_edge_removal(*std::make_unique<ImpMesh>(f, fixed), 0, 1))
      << "max_boundary_move 0: no boundary face changes";
}

// A short interior edge (u, v): the tets around it are slivers that no flip can mend (the
// two vertices stay nearly one whatever the triangulation) and that, with smoothing off, only
// the collapse step removes.
TEST(ImproveOps, ASliverOnlyACollapseRemoves) {
  Mesh m = cube_tets(4);
  int32_t u = -1, v = -1;  // (0.5, 0.5, 0.5) and (0.75, 0.5, 0.5), neighbours in the Kuhn split
  for (int64_t i = 0; i < m.num_vertices(); ++i) {
    const double* p = &m.points[3 * size_t(i)];
    if (p[1] == 0.5 && p[2] == 0.5 && p[0] == 0.5) u = int32_t(i);
    if (p[1] == 0.5 && p[2] == 0.5 && p[0] == 0.75) v = int32_t(i);
  }
  ASSERT_GE(u, 0);
  ASSERT_GE(v, 0);
  m.points[3 * size_t(v)] = 0.5075;  // along the edge, so every tet stays positive
  ImproveOptions o;
  o.smoothing = false;
  Mesh without = m;
  o.collapse = false;
  const ImproveReport r0 = improve(without, o);
  EXPECT_LT(r0.before.min_dihedral_deg, 5);
  EXPECT_LT(r0.after.min_dihedral_deg, 5) << "flips alone leave the slivers";
  o.collapse = true;
  const ImproveReport r = improve(m, o);
  int64_t collapsed = 0;
  for (const auto& p : r.passes) collapsed += p.collapsed;
  EXPECT_GE(collapsed, 1);
  EXPECT_GT(r.after.min_dihedral_deg, 25) << "the collapse took the short edge and its slivers";
  EXPECT_EQ(r.after.below_13_deg, 0);
  EXPECT_TRUE(check_mesh(m, {}, nullptr).valid);
  // under a vertex mask the step collapses between selected vertices only (the mask follows
  // its renumbering into the passes after it)
  Mesh all = without;
  o.vertex_mask.assign(size_t(all.num_vertices()), 7);  // (non-zero: selected)
  const ImproveReport ra = improve(all, o);
  EXPECT_EQ(all.tets, m.tets) << "a mask of every vertex is none";
  EXPECT_EQ(ra.after.below_13_deg, 0);
  Mesh pinned = without;
  o.vertex_mask[size_t(u)] = o.vertex_mask[size_t(v)] = 0;
  const ImproveReport rp = improve(pinned, o);
  EXPECT_LT(rp.after.min_dihedral_deg, 5) << "the short edge's ends are not selected";
  for (int32_t w : {u, v}) {
    bool kept = false;
    for (int64_t i = 0; i < pinned.num_vertices(); ++i)
      kept = kept || std::equal(&pinned.points[3 * size_t(i)], &pinned.points[3 * size_t(i)] + 3, &without.points[3 * size_t(w)]);
    EXPECT_TRUE(kept) << "an unselected vertex stays where it was";
  }
  o.vertex_mask.clear();
  // no rounds: no collapse step
  Mesh no_rounds = without;
  o.collapse_rounds = 0;
  int64_t none = 0;
  for (const auto& p : improve(no_rounds, o).passes) none += p.collapsed;
  EXPECT_EQ(none, 0);
}

// A thin tet (a, b, x1, x2) on top of two others (c below), which four more tets (e1..e4)
// wrap so that they keep one face each on the boundary: its faces through (a, b) are on the
// boundary.
Mesh roof(double eps) {
  Mesh m;
  m.points = {0, 0, eps, 1, 1, eps, 1, 0, 0, 0, 1, 0, 0.5, 0.5, -1,  // a b x1 x2 c
              2, 0.5, -0.3, 0.5, 2, -0.3, 0.5, -1, -0.3, -1, 0.5, -0.3};  // e1 e2 e3 e4
  for (std::array<int32_t, 4> q : {std::array<int32_t, 4>{0, 1, 2, 3}, {1, 2, 3, 4}, {0, 2, 3, 4}, {1, 2, 4, 5},
                                   {1, 3, 4, 6}, {0, 2, 4, 7}, {0, 3, 4, 8}}) {
    geo::tc_d3 p[4];
    for (int k = 0; k < 4; ++k) p[k] = geo::tc_point(m.points.data(), q[size_t(k)]);
    if (geo::tc_tet_volume(p[0], p[1], p[2], p[3]) < 0) std::swap(q[2], q[3]);
    m.tets.insert(m.tets.end(), q.begin(), q.end());
  }
  m.tris = {0, 1, 2, 0, 1, 3};  // the two top faces, tagged alike
  m.tri_tags = {7, 7};
  return m;
}

TEST(ImproveOps, AThinBoundaryTetIsRemovedWithinTheBound) {
  Mesh m = roof(5e-4);
  const Mesh before = m;
  {
    ImpMesh im(m, {});
    EXPECT_TRUE(improve_detail::try_remove_boundary_sliver(im, 0)) << "it moves the boundary by 1e-3 < 0.001 x diagonal";
    im.write_back();
  }
  ASSERT_EQ(m.num_tets(), 6);
  EXPECT_EQ(sface_keys(m).count({1, 2, 3}), 1u);
  EXPECT_EQ(sface_keys(m).count({0, 2, 3}), 1u);
  EXPECT_EQ(triangles_off_surface(m).size(), 0u) << "the tagged triangles follow the boundary";
  const CheckReport cr = check_mesh(m, {}, &before);
  EXPECT_TRUE(cr.valid) << check_report_text(cr);

  Mesh thick = roof(1e-2);
  EXPECT_FALSE(improve_detail::try_remove_boundary_sliver(*std::make_unique<ImpMesh>(thick, ImproveOptions{}), 0))
      << "1e-2 is over the bound";
  ImproveOptions strict;
  strict.boundary = CollapseOptions::Strict;
  Mesh s = roof(5e-4);
  EXPECT_FALSE(improve_detail::try_remove_boundary_sliver(*std::make_unique<ImpMesh>(s, strict), 0))
      << "strict: the boundary stays";
  Mesh tagged = roof(5e-4);
  tagged.tri_tags = {7, 8};
  EXPECT_FALSE(improve_detail::try_remove_boundary_sliver(*std::make_unique<ImpMesh>(tagged, ImproveOptions{}), 0))
      << "two surfaces the input tags apart";
}

// Under a boundary error bound the removal moves the surface by the tet's thickness (5e-4 here):
// done while the quad's corners' bounds plus that stay within the bound, which they then take.
TEST(ImproveOps, AThinBoundaryTetIsRemovedUnderTheErrorBoundWhenItFits) {
  const auto attempt = [](double bound, double spent, std::vector<double>* reached) {
    Mesh m = roof(5e-4);
    ImproveOptions o;
    o.max_boundary_error_abs = bound;
    o.vertex_boundary_error.assign(size_t(m.num_vertices()), 0.0);
    o.vertex_boundary_error[0] = spent;  // a
    ImpMesh im(m, o);
    const bool removed = improve_detail::try_remove_boundary_sliver(im, 0);
    if (reached) *reached = im.boundary_errors();
    return removed;
  };
  std::vector<double> e;
  ASSERT_TRUE(attempt(1e-3, 0, &e));
  for (int v = 0; v < 4; ++v) {  // a, b, x1, x2: the new surface is 5e-4 below the old one's ridge
    EXPECT_GE(e[size_t(v)], 5e-4) << "vertex " << v;
    EXPECT_LE(e[size_t(v)], 5.1e-4) << "vertex " << v;
  }
  EXPECT_EQ(e[4], 0.0) << "c is no corner of the quad";
  EXPECT_FALSE(attempt(4e-4, 0, nullptr)) << "thicker than the bound";
  EXPECT_FALSE(attempt(1e-3, 6e-4, nullptr)) << "a corner already spent 6e-4 of 1e-3";
  EXPECT_TRUE(attempt(1e-3, 4e-4, &e));
  EXPECT_GE(e[1], 9e-4) << "b takes what a spent plus the move";
}

TEST(ImproveOps, TheSurfaceGuardSeesAMoveThroughTheSurface) {
  Mesh m = cube_tets(3);
  int32_t v = -1;  // a vertex inside the face z = 0
  for (int64_t i = 0; i < m.num_vertices(); ++i)
    if (m.points[3 * i] > 0 && m.points[3 * i] < 1 && m.points[3 * i + 1] > 0 && m.points[3 * i + 1] < 1 &&
        m.points[3 * i + 2] == 0)
      v = int32_t(i);
  ASSERT_GE(v, 0);
  ImpMesh im(m, {});
  const geo::tc_d3 p = im.point(v);
  EXPECT_TRUE(im.surface_stays_clear(v, {p.x + 0.01, p.y, p.z})) << "a small move within the face";
  EXPECT_FALSE(im.surface_stays_clear(v, {p.x, p.y, 1.5})) << "its triangles would cross the top face";
}

// An octahedron around an interior vertex pushed towards one corner.
TEST(ImproveOps, SmoothingCentresAnInteriorVertex) {
  Mesh m;
  m.points = {0.7, 0.1, 0.05, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1};
  const int32_t x[2] = {1, 2}, y[2] = {3, 4}, z[2] = {5, 6};
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      for (int k = 0; k < 2; ++k) {
        int32_t q[4] = {0, x[i], y[j], z[k]};
        geo::tc_d3 p[4];
        for (int c = 0; c < 4; ++c) p[c] = geo::tc_point(m.points.data(), q[c]);
        if (geo::tc_tet_volume(p[0], p[1], p[2], p[3]) < 0) std::swap(q[2], q[3]);
        m.tets.insert(m.tets.end(), q, q + 4);
      }
  // a linear field: the interpolation at the new place reproduces it
  m.vertex_fields.push_back({"f", 1, {}});
  for (int64_t v = 0; v < m.num_vertices(); ++v)
    m.vertex_fields[0].values.push_back(m.points[3 * v] + 2 * m.points[3 * v + 1] + 3 * m.points[3 * v + 2]);
  const double q0 = worst(m);
  ImpMesh im(m, {});
  EXPECT_EQ(im.motion(0), improve_detail::kFree);
  EXPECT_EQ(im.motion(1), improve_detail::kFixed) << "a corner of the octahedron";
  EXPECT_TRUE(improve_detail::try_smooth(im, 0));
  EXPECT_GT(worst(m), q0 + 0.2);
  EXPECT_LT(std::hypot(m.points[0], m.points[1], m.points[2]), 0.2) << "near the centre";
  EXPECT_NEAR(m.vertex_fields[0].values[0], m.points[0] + 2 * m.points[1] + 3 * m.points[2], 1e-12);
}

// The relocation on the device: cl/improve_relocate.h compiled as OpenCL C gives the places the
// host computes when the vertices to move share no tet (then the order does not matter).
TEST(ImproveDevice, RelocationMatchesTheHostForVerticesApart) {
  Mesh m = cube_tets(8);
  ImproveOptions o;
  o.threshold_deg = 40;
  o.vertex_mask.assign(size_t(m.num_vertices()), 0);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-0.04, 0.04);
  int selected = 0;
  for (int64_t v = 0; v < m.num_vertices(); ++v) {
    const double* p = &m.points[3 * size_t(v)];
    const int i = int(std::lround(p[0] * 8)), j = int(std::lround(p[1] * 8)), k = int(std::lround(p[2] * 8));
    // interior grid points two apart in every direction: no two share a tet
    if (i % 2 || j % 2 || k % 2 || i == 0 || j == 0 || k == 0 || i == 8 || j == 8 || k == 8) continue;
    o.vertex_mask[size_t(v)] = 1;
    for (int c = 0; c < 3; ++c) m.points[3 * size_t(v) + size_t(c)] += u(rng);
    ++selected;
  }
  ASSERT_EQ(selected, 27);
  Mesh on_host = m, on_device = m;
  ImpMesh host_mesh(on_host, o), device_mesh(on_device, o);
  std::vector<int32_t> all(size_t(host_mesh.num_tet_slots()));
  for (size_t t = 0; t < all.size(); ++t) all[t] = int32_t(t);
  tc::ImprovePassStats hs, ds;
  improve_detail::smooth_pass(host_mesh, all, hs);
  Context ctx;
  improve_detail::smooth_pass(device_mesh, ctx, all, ds);
  EXPECT_EQ(hs.relocated, 27);
  EXPECT_EQ(ds.relocated, hs.relocated);
  // (OpenCL rounds a few operations differently; the numeric gradients carry that to ~1e-11)
  for (size_t i = 0; i < m.points.size(); ++i)
    ASSERT_NEAR(on_device.points[i], on_host.points[i], 1e-9) << i / 3;
}

// The device finds the flips the host finds: an edge of n tets alone, on its closed ring.
TEST(ImproveDevice, FlipsMatchTheHostOnARing) {
  for (const auto& [n, h] : std::vector<std::pair<int, double>>{{3, 1.0}, {4, 2.0}, {5, 3.0}}) {
    Mesh on_host = edge_ring(n, h), on_device = on_host;
    ImpMesh host_mesh(on_host, {}), device_mesh(on_device, {});
    std::vector<int32_t> all(static_cast<size_t>(n));
    for (int t = 0; t < n; ++t) all[size_t(t)] = t;
    tc::ImprovePassStats hs, ds;
    improve_detail::flip_pass(host_mesh, all, hs);
    Context ctx;
    improve_detail::flip_pass(device_mesh, ctx, all, ds);
    EXPECT_EQ(hs.edge_removals, 1) << n;
    EXPECT_EQ(ds.edge_removals, 1) << n;
    host_mesh.write_back();
    device_mesh.write_back();
    expect_same_mesh(on_device, on_host, "ring of " + std::to_string(n));
  }
}

// Neighbouring vertices move in rounds chosen by their keys alone: the same mesh whatever the
// work-group size, on the CPU and the GPU tuning paths; valid, and the worst tet no worse.
TEST(ImproveDevice, SameMeshWhateverTheWorkGroupSize) {
  const Mesh m = jiggled_cube(6, 0.05, 9);
  ImproveOptions o;
  o.threshold_deg = 30;
  o.collapse = false;
  Context ctx;
  Mesh first[2];  // per tuning: on a GPU the flips are found on the device too
  for (const auto& [wg, cpu] :
       std::vector<std::pair<size_t, bool>>{{0, true}, {1, true}, {0, false}, {1, false}, {4, false}, {64, false}}) {
    ctx.set_work_group_size(wg);
    ctx.set_cpu_tuning(cpu);
    Mesh d = m;
    const ImproveReport r = improve(d, o, ctx);
    int64_t relocated = 0, flipped = 0;
    for (const auto& p : r.passes) {
      relocated += p.relocated;
      flipped += p.edge_removals + p.flips23;
    }
    EXPECT_GT(relocated, 20);
    EXPECT_GT(flipped, 5);
    EXPECT_GE(worst(d), worst(m));
    if (first[cpu].points.empty()) {
      EXPECT_TRUE(check_mesh(d, {}, nullptr).valid);
      first[cpu] = d;
    } else {
      expect_same_mesh(d, first[cpu], "work-group size " + std::to_string(wg));
    }
  }
}

// The passes stop at the first that leaves the smallest angle (within 0.05 degrees) and the
// counts below 10 and 13 degrees (within 5%) as they were, counts of zero included: a mesh
// with nothing below 13 degrees but tets below the threshold (40 degrees here), whose
// relocations go on moving a few vertices, is not polished pass after pass up to
// max_iterations.
TEST(ImprovePhase, StopsAtThePassThatGainsNothingEvenWithNoBadCounts) {
  const Mesh m = jiggled_cube(6, 0.03, 9);
  ImproveOptions o;
  o.threshold_deg = 40;
  o.collapse = false;
  Mesh d = m;
  const ImproveReport r = improve(d, o);
  ASSERT_GE(r.passes.size(), 2u);
  EXPECT_EQ(r.before.below_13_deg, 0) << "nothing below 13 degrees to begin with";
  EXPECT_LT(r.passes.size(), size_t(o.max_iterations)) << "stopped by the stall rule";
  for (size_t i = 1; i + 1 < r.passes.size(); ++i) {
    const ImprovePassStats &prev = r.passes[i - 1], &p = r.passes[i];
    const bool gained = p.min_dihedral_deg >= prev.min_dihedral_deg + 0.05 ||
                        double(p.below_10_deg) < 0.95 * double(prev.below_10_deg) ||
                        double(p.below_13_deg) < 0.95 * double(prev.below_13_deg);
    EXPECT_TRUE(gained) << "pass " << i << " gained nothing, yet pass " << i + 1 << " ran";
  }
}

TEST(ImprovePhase, OnlyTheMaskedVerticesMove) {
  Mesh m = jiggled_cube(5, 0.03, 11);
  ImproveOptions o;
  o.threshold_deg = 40;
  o.vertex_mask.resize(size_t(m.num_vertices()));
  for (int64_t v = 0; v < m.num_vertices(); ++v) o.vertex_mask[size_t(v)] = m.points[3 * v] < 0.5;
  o.collapse = false;  // (its collapse step renumbers the vertices)
  const Mesh before = m;
  improve(m, o);
  int64_t moved = 0;
  for (int64_t v = 0; v < m.num_vertices(); ++v) {
    const bool same = m.points[3 * v] == before.points[3 * v] && m.points[3 * v + 1] == before.points[3 * v + 1] &&
                      m.points[3 * v + 2] == before.points[3 * v + 2];
    if (!o.vertex_mask[size_t(v)]) {
      EXPECT_TRUE(same) << "vertex " << v << " is not selected";
    }
    moved += !same;
  }
  EXPECT_GT(moved, 0);
}

// Coarsened meshes (the sequential method: no device needed), improved.
Mesh coarsened(const std::string& path, double factor, CollapseOptions::Boundary boundary) {
  Mesh m = read_mesh(path);
  CollapseOptions o;
  o.method = CollapseOptions::Sequential;
  o.target_factor = factor;
  o.boundary = boundary;
  collapse_sequential(m, o);
  return m;
}

TEST(ImprovePhase, BracketGetsValidAndBetter) {
  for (auto mode : {CollapseOptions::Features, CollapseOptions::Strict}) {
    Mesh m = coarsened(project_mesh("bracket.msh"), 2, mode);
    const Mesh before = m;
    ImproveOptions o;
    o.boundary = mode;
    Mesh on_device = m;
    const ImproveReport r = improve(m, o);
    EXPECT_LT(r.before.min_dihedral_deg, 8) << "the coarsened bracket has slivers to remove";
    Context ctx;
    for (bool cpu : {true, false}) {  // (the GPU tuning: flips found on the device too)
      Mesh d = on_device;
      ctx.set_cpu_tuning(cpu);
      const ImproveReport rd = improve(d, o, ctx);
      EXPECT_GT(rd.after.min_dihedral_deg, rd.before.min_dihedral_deg + 2.5) << "on the device " << cpu;
      EXPECT_LT(rd.after.below_10_deg, rd.before.below_10_deg / 4 + 1) << "on the device " << cpu;
      EXPECT_GE(worst(d), worst(before)) << "on the device " << cpu;
      EXPECT_TRUE(check_mesh(d, {}, &before).valid) << "on the device " << cpu;
    }
    EXPECT_GT(r.after.min_dihedral_deg, r.before.min_dihedral_deg + 2.5);
    EXPECT_LT(r.after.below_10_deg, r.before.below_10_deg / 4 + 1);
    EXPECT_GE(worst(m), worst(before)) << "the worst tet is never made worse";
    CheckOptions co;
    co.hausdorff = true;
    const CheckReport cr = check_mesh(m, co, &before);
    EXPECT_TRUE(cr.valid) << check_report_text(cr);
    EXPECT_NEAR(cr.reference.volume_change_rel, 0, mode == CollapseOptions::Strict ? 1e-12 : 1e-3);
    // the boundary moves within max_boundary_move (0.001 of the diagonal; the collapse step's
    // moves along flat faces do not change the shape)
    EXPECT_LE(cr.reference.hausdorff_rel, mode == CollapseOptions::Strict ? 0.0 : 1.1e-3);
    if (mode == CollapseOptions::Strict) {
      EXPECT_EQ(cr.reference.hausdorff, 0) << "strict: the boundary stays bit for bit";
      const auto keys = sface_keys(before);
      for (const auto& f : keys)
        for (int32_t v : f)
          for (int k = 0; k < 3; ++k) ASSERT_EQ(m.points[3 * size_t(v) + k], before.points[3 * size_t(v) + k]);
    }
    Mesh again = before;
    improve(again, o);
    expect_same_mesh(m, again, "deterministic");
  }
}

TEST(ImprovePhase, FlatFacesStayInTheirPlanes) {
  Mesh m = cube_tets(6);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.02, 0.02);
  for (int64_t v = 0; v < m.num_vertices(); ++v)  // jiggle within the faces: off them no coordinate changes
    for (int k = 0; k < 3; ++k) {
      double& x = m.points[3 * size_t(v) + k];
      if (x > 0 && x < 1) x += u(rng);
    }
  const Mesh before = m;
  ImproveOptions o;
  o.threshold_deg = 40;
  const ImproveReport r = improve(m, o);
  EXPECT_GT(r.after.min_dihedral_deg, r.before.min_dihedral_deg);
  int64_t moved_on_faces = 0;
  for (int64_t v = 0; v < m.num_vertices(); ++v)
    for (int k = 0; k < 3; ++k) {
      const double x = before.points[3 * size_t(v) + k];
      if (x == 0 || x == 1) {
        EXPECT_EQ(m.points[3 * size_t(v) + k], x) << "vertex " << v << " left its face plane";
        moved_on_faces += m.points[3 * size_t(v) + (k + 1) % 3] != before.points[3 * size_t(v) + (k + 1) % 3];
      }
    }
  EXPECT_GT(moved_on_faces, 0) << "face vertices move within their planes";
  EXPECT_NE(sface_keys(m), sface_keys(before)) << "boundary 2-2 flips change diagonals on the flat faces";
  const CheckReport cr = check_mesh(m, {}, &before);
  EXPECT_TRUE(cr.valid) << check_report_text(cr);
}

TEST(ImprovePhase, MaterialInterfacesStay) {
  Mesh m = two_materials(4);  // the interface at z = 0.5, a grid plane
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-0.025, 0.025);
  for (int64_t v = 0; v < m.num_vertices(); ++v)
    for (int k = 0; k < 3; ++k) {
      double& x = m.points[3 * size_t(v) + k];
      if (x > 0 && x < 1 && !(k == 2 && x == 0.5)) x += u(rng);
    }
  const Mesh before = m;
  ImproveOptions o;
  o.threshold_deg = 40;
  const ImproveReport r = improve(m, o);
  ASSERT_FALSE(r.passes.empty());
  EXPECT_GT(r.passes[0].relocated + r.passes[0].edge_removals, 0) << "something to do";
  // the interface (z = 0.5, not jiggled along z) keeps its triangles; the outer boundary may
  // flip diagonals of its flat faces
  auto interface = [](const Mesh& mesh) {
    std::set<std::array<int32_t, 3>> faces;
    for (const auto& f : sface_keys(mesh))
      if (mesh.points[3 * size_t(f[0]) + 2] == 0.5 && mesh.points[3 * size_t(f[1]) + 2] == 0.5 &&
          mesh.points[3 * size_t(f[2]) + 2] == 0.5)
        faces.insert(f);
    return faces;
  };
  EXPECT_FALSE(interface(before).empty());
  EXPECT_EQ(interface(m), interface(before));
  const CheckReport cr = check_mesh(m, {}, &before);
  EXPECT_TRUE(cr.valid) << check_report_text(cr);
}

TEST(ImprovePhase, SharedMeshesCoarsenedAndImprovedAreValid) {
  const std::vector<std::string> meshes = shared_volume_meshes();
  if (meshes.empty()) GTEST_SKIP() << "no shared meshes at " << shared_meshes_dir();
  int tried = 0;
  for (const std::string& path : meshes) {
    Mesh m = read_mesh(path);
    if (m.num_tets() > 30000) continue;  // a unit test: the small ones
    ++tried;
    CollapseOptions o;
    o.method = CollapseOptions::Sequential;
    o.target_factor = 2;
    collapse_sequential(m, o);
    const Mesh coarse = m;
    if (!check_mesh(coarse, {}, nullptr).valid) continue;  // an input the checker refuses already
    const ImproveReport r = improve(m, {});
    EXPECT_GE(r.after.min_dihedral_deg, r.before.min_dihedral_deg) << path << ": the worst angle never falls";
    EXPECT_LE(r.after.below_13_deg, r.before.below_13_deg) << path;
    const CheckReport cr = check_mesh(m, {}, &coarse);
    EXPECT_TRUE(cr.valid) << path << "\n" << check_report_text(cr);
  }
  EXPECT_GT(tried, 2);
}

// The collapse step on the stars of its vertices (improve/star_mesh.hpp) leaves the whole mesh
// as the sequential method run on the whole mesh with the same vertex mask does, bit for bit:
// points, tets in order, labels, vertex and tet fields, tagged triangles; a two-material mesh
// with the bracket's curved boundary, the harmonic and the shortest-edge costs, with and
// without a boundary error bound; the vertices of the worst tets masked, as the step does.
TEST(StarMesh, TheStepOnTheStarsIsTheStepOnTheWholeMesh) {
  Mesh whole = two_material_bracket();
  whole.vertex_fields.push_back({"x", 1, {}});
  for (int64_t v = 0; v < whole.num_vertices(); ++v) whole.vertex_fields[0].values.push_back(whole.points[size_t(3 * v)]);
  whole.tet_fields.push_back({"t", 1, {}});
  for (int64_t t = 0; t < whole.num_tets(); ++t) whole.tet_fields[0].values.push_back(double(t));
  // tagged triangles: a face of each of the first thousand tets
  for (int64_t t = 0; t < std::min<int64_t>(whole.num_tets(), 1000); ++t)
    whole.tris.insert(whole.tris.end(), &whole.tets[size_t(4 * t)], &whole.tets[size_t(4 * t + 3)]),
        whole.tri_tags.push_back(int32_t(t % 3));
  std::vector<std::pair<double, int64_t>> worst;
  for (int64_t t = 0; t < whole.num_tets(); ++t) {
    geo::tc_d3 p[4];
    for (int k = 0; k < 4; ++k) p[k] = geo::tc_point(whole.points.data(), whole.tets[size_t(4 * t + k)]);
    worst.push_back({-geo::tc_tet_max_dihedral_cos(p[0], p[1], p[2], p[3]), t});
  }
  std::sort(worst.begin(), worst.end());
  std::vector<uint8_t> mask(size_t(whole.num_vertices()), 0);
  for (size_t i = 0; i < worst.size() / 10; ++i)
    for (int k = 0; k < 4; ++k) mask[size_t(whole.tets[size_t(4 * worst[i].second + k)])] = 1;
  for (bool harmonic : {true, false})
    for (double bound : {0.0, 0.01}) {
      CollapseOptions o;
      o.method = CollapseOptions::Sequential;
      o.min_quality = 0.3;
      o.target_length = 1.5 * median_edge_length(whole);
      o.harmonic_cost = harmonic;
      o.max_boundary_error_abs = bound;
      // (the step's runs go on from the bounds spent, with no reference surface: a star mesh's
      // own S is cut where the stars end)
      o.tuning.remeasure_boundary_error = false;
      Mesh ref = whole;
      o.vertex_mask = mask;
      const CollapseReport r = collapse_sequential(ref, o);
      int64_t collapsed = 0;
      for (const IterationStats& it : r.iterations) collapsed += it.collapsed;
      ASSERT_GT(collapsed, 20) << "the step collapses";
      improve_detail::StarMesh star = improve_detail::star_mesh(whole, mask);
      ASSERT_LT(star.mesh.num_tets(), whole.num_tets());
      o.vertex_mask.assign(star.verts.size(), 0);
      for (size_t i = 0; i < star.verts.size(); ++i) o.vertex_mask[i] = mask[size_t(star.verts[i])];
      sequential_detail::SequentialRun run(star.mesh, o);
      run.keep_origin();
      while (run.step()) {
      }
      run.finish();
      Mesh out = whole;
      improve_detail::splice(out, star, run);
      const std::string what = std::string(harmonic ? "harmonic" : "shortest") + (bound > 0 ? ", bounded" : "");
      EXPECT_EQ(out.points, ref.points) << what;
      EXPECT_EQ(out.tets, ref.tets) << what;
      ASSERT_EQ(out.tet_labels.size(), 1u);
      EXPECT_EQ(out.tet_labels[0].values, ref.tet_labels[0].values) << what;
      EXPECT_EQ(out.vertex_fields[0].values, ref.vertex_fields[0].values) << what;
      EXPECT_EQ(out.tet_fields[0].values, ref.tet_fields[0].values) << what;
      EXPECT_EQ(out.tris, ref.tris) << what;
      EXPECT_EQ(out.tri_tags, ref.tri_tags) << what;
    }
}

}  // namespace
}  // namespace tc
