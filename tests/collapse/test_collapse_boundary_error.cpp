// The boundary error bound (CollapseOptions::max_boundary_error): the fan bound of
// cl/collapse_surface_error.h on fans built for it, then whole runs on curved shapes, measured
// by the checker's two-sided Hausdorff distance.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <stdexcept>

#include "check/check_cgal.hpp"  // check_detail::hausdorff, for the interface
#include "collapse/sequential_run.hpp"
#include "collapse_predicate.h"
#include "collapse_surface_error.h"
#include "geometry.h"
#include "test_support.hpp"
#include "tetcollapse/check.hpp"
#include "tetcollapse/coarsen.hpp"
#include "tetcollapse/collapse.hpp"
#include "tetcollapse/topology.hpp"

namespace tc {
namespace {

using geo::tc_d3;
using namespace test;
constexpr double kPi = 3.14159265358979323846;

// The fan of n triangles around `centre` over the regular n-gon of radius 1 in z = 0.
std::vector<tc_d3> fan(tc_d3 centre, int n) {
  std::vector<tc_d3> t;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * kPi * i / n, b = 2 * kPi * (i + 1) / n;
    t.insert(t.end(), {centre, {std::cos(a), std::sin(a), 0}, {std::cos(b), std::sin(b), 0}});
  }
  return t;
}

// The polygon's fan from its vertex 0 (a half-edge collapse of the centre onto it).
std::vector<tc_d3> fan_from_corner(int n) {
  std::vector<tc_d3> t;
  for (int i = 1; i + 1 < n; ++i) {
    const double a = 2 * kPi * i / n, b = 2 * kPi * (i + 1) / n;
    t.insert(t.end(), {{1, 0, 0}, {std::cos(a), std::sin(a), 0}, {std::cos(b), std::sin(b), 0}});
  }
  return t;
}

// tcc_fan_distance of two fans given as points, each point named by its coordinates (one point,
// one vertex).
double fan_distance(const std::vector<tc_d3>& olds, const std::vector<tc_d3>& news, double budget = INFINITY) {
  std::map<std::array<double, 3>, int> names;
  const auto ids = [&](const std::vector<tc_d3>& t) {
    std::vector<int> id;
    for (const tc_d3& p : t) id.push_back(names.emplace(std::array<double, 3>{p.x, p.y, p.z}, int(names.size())).first->second);
    return id;
  };
  const std::vector<int> oid = ids(olds), nid = ids(news);
  return geo::tcc_fan_distance_within(olds.data(), oid.data(), int(olds.size() / 3), news.data(), nid.data(),
                                      int(news.size() / 3), budget);
}

TEST(BoundaryErrorFan, FlatPatchRetriangulatedMovesNothing) {
  const auto olds = fan({0.1, -0.2, 0}, 6), news = fan_from_corner(6);
  EXPECT_LT(fan_distance(olds, news), 1e-9);
}

TEST(BoundaryErrorFan, ATentFlattenedMovesByItsHeight) {
  for (double h : {0.01, 0.2}) {
    const auto olds = fan({0.1, 0.05, h}, 8), news = fan_from_corner(8);
    const double d = fan_distance(olds, news);
    // the apex is h above the plane of the new fan, straight over a point of it
    EXPECT_NEAR(d, h, 1e-9 + 0.05 * h) << h;
    EXPECT_GE(d, h * std::cos(std::atan(h / 0.9))) << "no less than the apex's distance to the plane";
  }
}

// A budget cuts the measure short only where the distance is above it: below, the same value.
TEST(BoundaryErrorFan, ABudgetChangesNoVerdict) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U(-0.3, 0.3);
  int cut = 0;
  for (int it = 0; it < 200; ++it) {
    const auto olds = fan({U(rng), U(rng), U(rng)}, 5 + it % 6), news = fan_from_corner(5 + it % 6);
    const double d = fan_distance(olds, news);
    if (!std::isfinite(d)) continue;
    const double budget = U(rng) + 0.3;  // [0, 0.6)
    const double within = fan_distance(olds, news, budget);
    if (d <= budget) {
      EXPECT_EQ(within, d) << it;
    } else {
      EXPECT_TRUE(std::isinf(within)) << it;  // (above the budget either way)
      ++cut;
    }
    // the budget callers give: base + distance against a limit, the verdict as without it
    const double base = 0.1, limit = 0.1 + budget;
    EXPECT_EQ(base + fan_distance(olds, news, geo::tcc_fan_budget(limit, base)) <= limit, base + d <= limit) << it;
  }
  EXPECT_GT(cut, 20);
}

TEST(BoundaryErrorFan, FoldedFanGetsNoBound) {
  const auto olds = fan({0, 0, 0}, 6);
  const auto folded = fan({1.5, 0, 0}, 6);  // the centre outside the polygon: triangles flip
  EXPECT_TRUE(std::isinf(fan_distance(olds, folded)));
  const auto half = fan_from_corner(4);  // covers another area
  EXPECT_TRUE(std::isinf(fan_distance(olds, half)));
}

// The height of the fan `t` (n triangles, counter-clockwise seen from +z) over (x, y), or NaN
// when no triangle holds the point.
double fan_height_at(const std::vector<tc_d3>& t, double x, double y) {
  for (size_t i = 0; i + 2 < t.size(); i += 3) {
    const tc_d3 a = t[i], b = t[i + 1], c = t[i + 2];
    const double det = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
    const double l1 = ((x - a.x) * (c.y - a.y) - (c.x - a.x) * (y - a.y)) / det;
    const double l2 = ((b.x - a.x) * (y - a.y) - (x - a.x) * (b.y - a.y)) / det;
    if (l1 >= -1e-12 && l2 >= -1e-12 && l1 + l2 <= 1 + 1e-12) return (1 - l1 - l2) * a.z + l1 * b.z + l2 * c.z;
  }
  return std::nan("");
}

// Random fans over one polygon in z = 0 (the mean plane is then z = 0 exactly): the old one
// around a lifted centre, the new one around another or from a corner. The bound is the largest
// vertical gap between the two: at least every gap sampled, and at most the largest sampled plus
// what the samples' spacing can miss.
TEST(BoundaryErrorFan, TheBoundIsTheLargestGapOfRandomFans) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-1, 1);
  int bounded = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const int n = 5 + trial % 6;
    std::vector<tc_d3> rim;
    for (int i = 0; i < n; ++i) {
      const double a = 2 * kPi * (i + 0.3 * U(rng)) / n, r = 1 + 0.2 * U(rng);
      rim.push_back({r * std::cos(a), r * std::sin(a), 0});
    }
    const auto around = [&](tc_d3 c) {
      std::vector<tc_d3> t;
      for (int i = 0; i < n; ++i) t.insert(t.end(), {c, rim[size_t(i)], rim[size_t((i + 1) % n)]});
      return t;
    };
    const std::vector<tc_d3> olds = around({0.2 * U(rng), 0.2 * U(rng), 0.3 * U(rng)});
    std::vector<tc_d3> news;
    if (trial % 3 == 0) {
      for (int i = 1; i + 1 < n; ++i) news.insert(news.end(), {rim[0], rim[size_t(i)], rim[size_t(i + 1)]});
    } else {
      news = around({0.2 * U(rng), 0.2 * U(rng), 0.3 * U(rng)});
    }
    const double d = fan_distance(olds, news);
    if (std::isinf(d)) continue;
    ++bounded;
    double sampled = 0;
    const int k = 200;
    for (int i = 0; i <= k; ++i)
      for (int j = 0; j <= k; ++j) {
        const double x = -1.2 + 2.4 * i / k, y = -1.2 + 2.4 * j / k;
        const double ho = fan_height_at(olds, x, y), hn = fan_height_at(news, x, y);
        if (!std::isnan(ho) && !std::isnan(hn)) sampled = std::max(sampled, std::fabs(ho - hn));
      }
    EXPECT_GE(d, sampled - 1e-12) << "trial " << trial;
    // the gap is 2-Lipschitz-ish in (x, y) at these slopes (below 1): a sample lies within 0.012
    EXPECT_LE(d, sampled + 0.03) << "trial " << trial;
  }
  EXPECT_GE(bounded, 150);
}

double hausdorff_rel(const Mesh& out, const Mesh& in) {
  CheckOptions co;
  co.hausdorff = true;
  const CheckReport r = check_mesh(out, co, &in);
  EXPECT_TRUE(r.valid) << check_report_text(r);
  return r.reference.hausdorff_rel;
}

TEST(BoundaryErrorRun, ABallStaysWithinTheBoundAndCoarsens) {
  const Mesh in = ball(10);
  for (int64_t t = 0; t < in.num_tets(); ++t) {
    geo::tc_d3 p[4];
    for (int k = 0; k < 4; ++k) p[k] = geo::tc_point(in.points.data(), in.tets[size_t(4 * t + k)]);
    ASSERT_GT(geo::tc_tet_volume(p[0], p[1], p[2], p[3]), 0) << "the ball's tets are positive";
  }
  CollapseOptions o;
  o.method = CollapseOptions::Sequential;
  o.target_factor = 2;
  Mesh unbounded = in;
  collapse_sequential(unbounded, o);
  for (double e : {0.002, 0.01}) {
    Mesh m = in;
    o.max_boundary_error = e;
    const CollapseReport r = collapse_sequential(m, o);
    EXPECT_NEAR(r.boundary_error_bound, e * std::sqrt(12.0), 1e-9);
    EXPECT_LE(r.boundary_error, r.boundary_error_bound);
    EXPECT_GT(r.boundary_error, 0) << "the sphere's vertices moved";
    const double measured = hausdorff_rel(m, in);
    EXPECT_LE(measured, e) << "the checker's two-sided distance within the bound";
    EXPECT_LT(m.num_tets(), unbounded.num_tets()) << e << ": the curved boundary coarsens too";
    int64_t refused = 0;
    for (const auto& it : r.iterations) refused += it.refused_by_bound;
    EXPECT_GT(refused, 0) << e << ": the bound refused some collapses";
  }
}

// Under the bound a collapse of a curved face to the midpoint (on the chord) may keep an end
// point (on the surface) instead, where that changes S less and the tets keep their shape:
// every edge of the sphere's surface gets the smallest bound of the three, and some an end point.
TEST(BoundaryErrorRun, ACollapseOfACurvedFaceTakesTheCloserPlacement) {
  Mesh m = ball(10);
  CollapseOptions o;
  o.max_boundary_error = 0.01;
  sequential_detail::SeqParams p = sequential_detail::seq_params_from(o);
  p.eps_f = 2;  // as under the bound: the sphere's vertices are face vertices
  sequential_detail::SeqMesh sm(m, p);
  const std::vector<double> eps(size_t(m.num_vertices()), 0.0);
  std::set<std::pair<int32_t, int32_t>> edges;
  for (int64_t t = 0; t < m.num_tets(); ++t)
    for (const auto& E : geo::TC_TET_EDGES) {
      const int32_t a = m.tets[size_t(4 * t + E[0])], b = m.tets[size_t(4 * t + E[1])];
      edges.insert({std::min(a, b), std::max(a, b)});
    }
  int surface = 0, end_points = 0;
  for (const auto& [a, b] : edges) {
    uint8_t fe = 0;
    const int dir = sm.predicate(a, b, fe);
    if (dir < 0 || !(dir & TCC_DIR_MIDPOINT)) continue;
    double base = 0, base_chosen = 0;
    const double mid = sm.surface_change(a, b, uint8_t(dir), eps, &base);
    if (!(mid > 0)) continue;  // S unchanged
    ++surface;
    double change = 0;
    const uint8_t chosen = sm.closest_placement(a, b, uint8_t(dir), eps, &base_chosen, &change);
    double base_again = 0;
    EXPECT_EQ(sm.surface_change(a, b, chosen, eps, &base_again), change) << "the chosen direction's own";
    EXPECT_EQ(base_again, base_chosen);
    EXPECT_LE(base_chosen + change, base + mid) << a << " " << b;
    if (chosen == dir) continue;
    ++end_points;
    EXPECT_FALSE(chosen & TCC_DIR_MIDPOINT);
    EXPECT_TRUE(sm.keeps_shape(a, b, chosen, TCC_END_POINT_MIN_QUALITY));
  }
  EXPECT_GT(surface, 100);
  EXPECT_GT(end_points, 0) << "of " << surface;
}

// The faces between tets of labels 1 and 2, as a triangle soup oriented out of label 1.
check_detail::Soup interface_soup(const Mesh& m) {
  std::map<std::array<int32_t, 3>, std::pair<int64_t, std::array<int32_t, 3>>> seen;
  check_detail::Soup s;
  s.points = m.points;
  const auto& label = m.tet_labels[0].values;
  for (int64_t t = 0; t < m.num_tets(); ++t)
    for (const auto& F : geo::TC_TET_FACES) {
      std::array<int32_t, 3> f, k;
      for (int c = 0; c < 3; ++c) f[size_t(c)] = m.tets[size_t(4 * t + F[c])];
      k = f;
      std::sort(k.begin(), k.end());
      const auto [it, fresh] = seen.emplace(k, std::make_pair(t, f));
      if (fresh || label[size_t(it->second.first)] == label[size_t(t)]) continue;
      const auto& out = label[size_t(t)] == 1 ? f : it->second.second;
      s.tris.insert(s.tris.end(), out.begin(), out.end());
    }
  return s;
}

TEST(BoundaryErrorRun, TheInterfaceOfTwoMaterialsKeepsItsShapeAndLabels) {
  Mesh in = ball(8);
  in.tet_labels.push_back({"material", {}});
  for (int64_t t = 0; t < in.num_tets(); ++t) {  // an inner ball of radius 0.5
    double c[3] = {0, 0, 0};
    for (int k = 0; k < 4; ++k)
      for (int d = 0; d < 3; ++d) c[d] += in.points[3 * size_t(in.tets[size_t(4 * t + k)]) + size_t(d)] / 4;
    in.tet_labels[0].values.push_back(std::hypot(c[0], c[1], c[2]) < 0.5 ? 1 : 2);
  }
  CollapseOptions o;
  o.method = CollapseOptions::Sequential;
  o.target_factor = 2;
  o.max_boundary_error = 0.005;
  Mesh m = in;
  const CollapseReport r = collapse_sequential(m, o);
  EXPECT_LE(r.boundary_error, r.boundary_error_bound);
  EXPECT_LE(hausdorff_rel(m, in), 0.005);
  const check_detail::Hausdorff h = check_detail::hausdorff(interface_soup(m), interface_soup(in), 1e-5);
  ASSERT_TRUE(h.ran) << h.why_not;
  EXPECT_LE(std::max(h.a_to_b, h.b_to_a), r.boundary_error_bound) << "the interface within the bound";
  EXPECT_GT(std::max(h.a_to_b, h.b_to_a), 0) << "and it moved";
  EXPECT_LT(m.num_tets(), in.num_tets() / 2);
}

// The parallel method tests the bound on the device (cl/collapse_bound.h): the ball within it,
// refusals counted, the bound per vertex reported, about the sequential method's tet count; the
// host tail (when it runs) goes on from the device's bounds; with a mask only the selected half
// coarsens; a user cost keeps the bound too.
TEST(BoundaryErrorRun, TheParallelMethodKeepsTheBoundToo) {
  const Mesh in = ball(10);
  CollapseOptions o;
  o.target_factor = 2;
  o.max_boundary_error = 0.002;
  Context ctx;
  for (double tail : {-1.0, 0.0}) {  // the host tail as the device chooses, or none
    o.tuning.host_tail = tail;
    Mesh m = in;
    const CollapseReport r = collapse(m, o, ctx);
    const std::string what = tail == 0 ? "device alone" : "with the host tail";
    EXPECT_LE(r.boundary_error, r.boundary_error_bound) << what;
    EXPECT_GT(r.boundary_error, 0) << what;
    EXPECT_LE(hausdorff_rel(m, in), 0.002) << what;
    ASSERT_EQ(r.vertex_boundary_error.size(), size_t(m.num_vertices())) << what;
    EXPECT_EQ(m.vertex_fields.size(), in.vertex_fields.size()) << what << ": the bound's field is gone";
    int64_t refused = 0, on_device = 0;
    for (const auto& it : r.iterations) {
      refused += it.refused_by_bound;
      on_device += !it.on_host;
    }
    EXPECT_GT(refused, 0) << what << ": the bound refused some collapses";
    EXPECT_GT(on_device, 1) << what;
    for (size_t i = 0; i < r.iterations.size(); ++i) EXPECT_EQ(r.iterations[i].iteration, int(i)) << "numbered on";
    Mesh seq = in;
    CollapseOptions so = o;
    so.method = CollapseOptions::Sequential;
    so.tuning.remeasure_boundary_error = tail != 0;  // (the device alone: the carried bound alone)
    collapse_sequential(seq, so);
    EXPECT_EQ(r.boundary_reference != nullptr, tail != 0) << what;
    EXPECT_LT(m.num_tets(), in.num_tets() / 3) << what;
    EXPECT_NEAR(double(m.num_tets()), double(seq.num_tets()), 0.15 * double(seq.num_tets())) << what;
  }
  o.tuning.host_tail = -1;
  // with a mask: only the selected half (x < 0) coarsens, within the bound
  Mesh masked = in;
  o.vertex_mask.assign(size_t(in.num_vertices()), 0);
  int64_t right = 0, left_on_sphere = 0;
  const auto on_sphere = [](const double* p) { return std::fabs(std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) - 1) < 1e-9; };
  for (int64_t v = 0; v < in.num_vertices(); ++v) {
    o.vertex_mask[size_t(v)] = in.points[3 * size_t(v)] < 0.0;
    right += !o.vertex_mask[size_t(v)];
    left_on_sphere += o.vertex_mask[size_t(v)] && on_sphere(&in.points[3 * size_t(v)]);
  }
  const CollapseReport rm = collapse(masked, o, ctx);
  EXPECT_LE(hausdorff_rel(masked, in), 0.002);
  EXPECT_LE(rm.boundary_error, rm.boundary_error_bound);
  int64_t right_after = 0, left_on_sphere_after = 0;
  for (int64_t v = 0; v < masked.num_vertices(); ++v) {
    right_after += masked.points[3 * size_t(v)] >= 0.0;
    left_on_sphere_after += masked.points[3 * size_t(v)] < 0.0 && on_sphere(&masked.points[3 * size_t(v)]);
  }
  EXPECT_GE(right_after, right) << "no unselected vertex went (survivors of the left may cross)";
  EXPECT_LT(left_on_sphere_after, left_on_sphere) << "the selected part's surface coarsened";
  // a user cost: the device's test is the same
  o.vertex_mask.clear();
  o.cost_cl_source = "double tc_user_cost(double3 p0, double3 p1, double f0, double f1) { return length(p1 - p0); }";
  o.target_length = 0.4;
  Mesh user = in;
  const CollapseReport ru = collapse(user, o, ctx);
  EXPECT_LE(ru.boundary_error, ru.boundary_error_bound);
  EXPECT_LE(hausdorff_rel(user, in), 0.002);
  EXPECT_LT(user.num_tets(), in.num_tets() / 2);
  // the user's f0 and f1 stay 0 on a mesh without fields (the bound's field is not the first)
  o.cost_cl_source.clear();
  o.target_length = 0;
  o.predicate_cl_source = "int tc_user_predicate(double3 p0, double3 p1, double f0, double f1) { return 1; }";
  Mesh any = in;
  collapse(any, o, ctx);
  o.predicate_cl_source =
      "int tc_user_predicate(double3 p0, double3 p1, double f0, double f1) { return f0 == 0.0 && f1 == 0.0; }";
  Mesh zero = in;
  collapse(zero, o, ctx);
  EXPECT_EQ(zero.tets, any.tets) << "f0 and f1 are 0 without fields";
  EXPECT_TRUE(zero.vertex_fields.empty());
  o.predicate_cl_source.clear();
  o.max_boundary_error = std::numeric_limits<double>::infinity();
  Mesh inf = in;
  EXPECT_THROW(collapse(inf, o, ctx), std::invalid_argument) << "an infinite bound";
}

// Curved shapes made for the bound: a cylinder whose rims are rounded by fillets (no ridge: caps,
// side and fillets meet smoothly, though the coarse fillets' edges pass eps_r) and a torus. On
// both methods and with the improvement phase after the collapse: the checker's two-sided
// distance within the bound, the boundary's topology kept, the curved surfaces coarsened (a
// quarter of the boundary vertices gone at least, fewer tets than the paper's method leaves,
// which keeps the torus's boundary as it is).
TEST(BoundaryErrorRun, CurvedShapesCoarsenWithinTheBound) {
  Context ctx;
  const auto boundary_vertices = [](const Mesh& m) {
    TopologyOptions no_labels;
    no_labels.use_labels = false;
    const Topology topo = build_topology(m, no_labels);
    std::vector<uint8_t> on(size_t(m.num_vertices()), 0);
    for (int32_t v : topo.sfaces) on[size_t(v)] = 1;
    return std::count(on.begin(), on.end(), 1);
  };
  const double e = 0.01;
  for (const auto& [name, in] : {std::pair<std::string, Mesh>{"filleted cylinder", test::filleted_cylinder(10, 0.3)},
                                 {"torus", test::torus(6, 24)}}) {
    CheckOptions check;
    check.hausdorff = true;
    ASSERT_TRUE(check_mesh(in, check, nullptr).valid) << name;
    CollapseOptions o;
    o.target_factor = 2;
    Mesh paper = in;
    collapse(paper, o, ctx);
    o.max_boundary_error = e;
    for (int how = 0; how < 3; ++how) {
      const std::string what = name + (how == 0 ? ", sequential" : how == 1 ? ", parallel" : ", with the improvement");
      Mesh m = in;
      if (how == 0) {
        CollapseOptions so = o;
        so.method = CollapseOptions::Sequential;
        collapse_sequential(m, so);
      } else if (how == 1) {
        collapse(m, o, ctx);
      } else {
        CoarsenOptions co;
        co.collapse = o;
        EXPECT_TRUE(coarsen(m, co, &ctx).improved) << what;
      }
      const CheckReport r = check_mesh(m, check, &in);
      EXPECT_TRUE(r.valid) << what << "\n" << check_report_text(r);
      EXPECT_FALSE(r.reference.topology_changed) << what;
      EXPECT_LE(r.reference.hausdorff_rel, e) << what;
      EXPECT_GT(r.reference.hausdorff_rel, 0) << what << ": the boundary moved";
      EXPECT_LT(4 * boundary_vertices(m), 3 * boundary_vertices(in)) << what;
      EXPECT_LT(m.num_tets(), paper.num_tets()) << what << ": fewer than the paper's method leaves";
    }
  }
}

// A run goes on from the bounds a run before it spent (CollapseOptions::vertex_boundary_error):
// zeros are no seed at all; every vertex at the full bound leaves the sphere's vertices where
// they are; the seed's bounds come back in the report, at least as large; on both methods.
TEST(BoundaryErrorRun, ARunGoesOnFromTheBoundsGiven) {
  const Mesh in = ball(10);
  const auto on_sphere = [](const double* p) { return std::fabs(std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) - 1) < 1e-9; };
  const auto sphere_points = [&](const Mesh& m) {
    std::vector<std::array<double, 3>> out;
    for (int64_t v = 0; v < m.num_vertices(); ++v)
      if (on_sphere(&m.points[3 * size_t(v)])) out.push_back({m.points[3 * size_t(v)], m.points[3 * size_t(v) + 1], m.points[3 * size_t(v) + 2]});
    std::sort(out.begin(), out.end());
    return out;
  };
  Context ctx;
  for (auto method : {CollapseOptions::Sequential, CollapseOptions::Parallel}) {
    const std::string what = method == CollapseOptions::Sequential ? "sequential" : "parallel";
    CollapseOptions o;
    o.method = method;
    o.target_factor = 2;
    o.max_boundary_error = 0.002;
    const double bound = boundary_error_bound(in, o);
    const auto run = [&](Mesh& m, const CollapseOptions& opt) {
      return method == CollapseOptions::Sequential ? collapse_sequential(m, opt) : collapse(m, opt, ctx);
    };
    Mesh plain = in, zeros = in, spent = in;
    const CollapseReport rp = run(plain, o);
    o.vertex_boundary_error.assign(size_t(in.num_vertices()), 0.0);
    run(zeros, o);
    EXPECT_EQ(zeros.tets, plain.tets) << what;
    EXPECT_EQ(zeros.points, plain.points) << what;
    o.vertex_boundary_error.assign(size_t(in.num_vertices()), bound);
    const CollapseReport rs = run(spent, o);
    EXPECT_LT(spent.num_tets(), in.num_tets()) << what << ": the interior still coarsens";
    EXPECT_EQ(sphere_points(spent), sphere_points(in)) << what << ": no sphere vertex moved or went";
    ASSERT_EQ(rs.vertex_boundary_error.size(), size_t(spent.num_vertices())) << what;
    EXPECT_EQ(*std::min_element(rs.vertex_boundary_error.begin(), rs.vertex_boundary_error.end()), bound) << what;
    EXPECT_GT(rp.boundary_error, 0) << what << ": without the seed the sphere moves";
    o.vertex_boundary_error.pop_back();
    Mesh wrong = in;
    EXPECT_THROW(run(wrong, o), std::invalid_argument) << what << ": one value short";
    o.vertex_boundary_error.assign(size_t(in.num_vertices()), 0.0);
    o.max_boundary_error = 0;
    EXPECT_THROW(run(wrong, o), std::invalid_argument) << what << ": a seed without a bound";
  }
}

TEST(BoundaryErrorRun, RefusedWhereItCannotHold) {
  Mesh m = ball(4);
  CollapseOptions o;
  o.max_boundary_error = 0.001;
  o.method = CollapseOptions::Sequential;
  o.boundary = CollapseOptions::Free;
  EXPECT_THROW(collapse_sequential(m, o), std::invalid_argument) << "free mode does not bound the boundary";
  o.boundary = CollapseOptions::Features;
  o.max_boundary_error = -1;
  EXPECT_THROW(collapse_sequential(m, o), std::invalid_argument);
}

}  // namespace
}  // namespace tc
