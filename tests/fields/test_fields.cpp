// Vertex fields from the original mesh: point location against a brute-force search, a linear
// field kept exact by any coarsening, the field errors, and the CLI's --preserve-field.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <random>

#include "geometry.h"
#include "test_support.hpp"
#include "tetcollapse/collapse.hpp"
#include "tetcollapse/device.hpp"
#include "tetcollapse/device_fields.hpp"
#include "tetcollapse/fields.hpp"
#include "tetcollapse/io.hpp"

namespace tc {
namespace {

using namespace test;
using geo::tc_d3;

Mesh jiggled(int n, unsigned seed) {
  Mesh m = cube_tets(n);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-0.3 / n, 0.3 / n);
  for (double& x : m.points)
    if (x > 0 && x < 1) x += u(rng);
  return m;
}

double linear(const double* p) { return 1 + p[0] + 2 * p[1] - 3 * p[2]; }

void add_linear_field(Mesh& m) {
  m.vertex_fields.push_back({"f", 1, {}});
  for (int64_t v = 0; v < m.num_vertices(); ++v) m.vertex_fields.back().values.push_back(linear(&m.points[3 * size_t(v)]));
}

// The smallest barycentric coordinate of p in tet t, and p's distance to the tet (brute force:
// the distance to its nearest sample among a fine grid of its points would be slow; outside
// points are compared through the located tet's own coordinates instead).
double min_bary(const Mesh& m, int64_t t, tc_d3 p) {
  tc_d3 c[4];
  for (int k = 0; k < 4; ++k) c[k] = geo::tc_point(m.points.data(), m.tets[size_t(4 * t + k)]);
  const double v = geo::tc_orient3d(c[0], c[1], c[2], c[3]);
  const double b[4] = {geo::tc_orient3d(p, c[1], c[2], c[3]) / v, geo::tc_orient3d(c[0], p, c[2], c[3]) / v,
                       geo::tc_orient3d(c[0], c[1], p, c[3]) / v, geo::tc_orient3d(c[0], c[1], c[2], p) / v};
  return std::min({b[0], b[1], b[2], b[3]});
}

TEST(TetLocator, FindsTheTetABruteForceSearchFinds) {
  const Mesh m = jiggled(6, 3);
  const TetLocator loc(m);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.001, 0.999);
  for (int i = 0; i < 2000; ++i) {
    const double p[3] = {u(rng), u(rng), u(rng)};
    double bary[4];
    const int64_t t = loc.locate(p, bary);
    ASSERT_GE(t, 0);
    int64_t holding = 0;
    for (int64_t s = 0; s < m.num_tets(); ++s) holding += min_bary(m, s, {p[0], p[1], p[2]}) >= -1e-12;
    ASSERT_GE(holding, 1) << "the cube holds every point";
    EXPECT_GE(min_bary(m, t, {p[0], p[1], p[2]}), -1e-12) << "the located tet holds p";
    // the coordinates reproduce p
    tc_d3 q{0, 0, 0};
    for (int k = 0; k < 4; ++k) q = q + geo::tc_point(m.points.data(), m.tets[size_t(4 * t + k)]) * bary[k];
    EXPECT_NEAR(q.x, p[0], 1e-12);
    EXPECT_NEAR(q.y, p[1], 1e-12);
    EXPECT_NEAR(q.z, p[2], 1e-12);
  }
  // outside: the nearest point of the nearest tet, on the cube's face
  const double out[3] = {1.5, 0.5, 0.25};
  double bary[4];
  const int64_t t = loc.locate(out, bary);
  ASSERT_GE(t, 0);
  tc_d3 q{0, 0, 0};
  for (int k = 0; k < 4; ++k) q = q + geo::tc_point(m.points.data(), m.tets[size_t(4 * t + k)]) * bary[k];
  EXPECT_NEAR(q.x, 1.0, 1e-12);
  EXPECT_NEAR(q.y, 0.5, 1e-9);
  EXPECT_NEAR(q.z, 0.25, 1e-9);
}

// `in` coarsened by the sequential method to 2.5 x its median edge length.
Mesh coarsened(const Mesh& in, CollapseOptions::Boundary boundary) {
  Mesh m = in;
  CollapseOptions o;
  o.method = CollapseOptions::Sequential;
  o.target_factor = 2.5;
  o.boundary = boundary;
  collapse_sequential(m, o);
  return m;
}

TEST(ResampleFields, AnyCoarseningKeepsALinearFieldExact) {
  Mesh in = jiggled(8, 7);
  add_linear_field(in);
  for (auto boundary : {CollapseOptions::Features, CollapseOptions::Free}) {
    Mesh m = coarsened(in, boundary);
    ASSERT_LT(m.num_vertices(), in.num_vertices() / 2);
    const int64_t outside = resample_vertex_fields(in, m);
    double err = 0;
    for (int64_t v = 0; v < m.num_vertices(); ++v)
      err = std::max(err, std::fabs(m.vertex_fields[0].values[size_t(v)] - linear(&m.points[3 * size_t(v)])));
    EXPECT_LT(err, 1e-12) << "exact at every vertex";
    if (boundary == CollapseOptions::Features) {
      EXPECT_EQ(outside, 0);
      // the same volume: the two linear fields agree everywhere
      const std::vector<FieldError> e = field_errors(in, m, 20000);
      ASSERT_EQ(e.size(), 1u);
      EXPECT_EQ(e[0].name, "f");
      EXPECT_LT(e[0].max_rel, 1e-12);
    }
  }
}

// The device's BVH (cl/bvh.cl) answers as a brute-force search over every tet does: the
// lowest-numbered tet holding the point (coordinates >= -1e-12), -1 outside; the meshes from one
// tet (the root a leaf) to a few thousand, points inside, on faces and vertices, and outside.
TEST(DeviceTetLocator, FindsWhatABruteForceSearchFinds) {
  Context ctx;
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-0.2, 1.2);
  for (int n : {0, 1, 2, 7}) {
    Mesh m = n == 0 ? cube_tets(1) : jiggled(n, unsigned(n));
    if (n == 0) m.tets.resize(4);  // one tet
    std::vector<double> q;
    for (int i = 0; i < 3000; ++i) q.insert(q.end(), {u(rng), u(rng), u(rng)});
    for (size_t i = 0; i < std::min<size_t>(m.points.size(), 600); ++i) q.push_back(m.points[i]);  // vertices
    const DeviceTetLocator loc(m, ctx);
    EXPECT_EQ(loc.nodes(), 2 * m.num_tets() - 1);
    std::vector<int32_t> tets;
    std::vector<double> bary;
    loc.locate(q, tets, bary);
    ASSERT_EQ(tets.size(), q.size() / 3);
    int64_t inside = 0;
    for (size_t i = 0; i < tets.size(); ++i) {
      const tc_d3 p{q[3 * i], q[3 * i + 1], q[3 * i + 2]};
      int64_t first = -1;
      for (int64_t t = 0; t < m.num_tets() && first < 0; ++t)
        if (min_bary(m, t, p) >= -1e-12) first = t;
      ASSERT_EQ(tets[i], first) << "point " << i << " of the mesh of " << m.num_tets() << " tets";
      inside += first >= 0;
      if (first < 0) continue;
      double b[4];
      tc_d3 c[4];
      for (int k = 0; k < 4; ++k) c[k] = geo::tc_point(m.points.data(), m.tets[size_t(4 * first + k)]);
      geo::tc_barycentric(c[0], c[1], c[2], c[3], p, b);
      for (int k = 0; k < 4; ++k) EXPECT_EQ(bary[4 * i + size_t(k)], b[k]);
    }
    EXPECT_GT(inside, n == 0 ? 100 : 1000) << "many points are inside";
  }
}

// Resampling on the device gives the host's values bit for bit (the same operations, no
// contraction), the points outside the original handed to the host's nearest-tet search.
TEST(ResampleFields, TheDeviceGivesTheHostsValues) {
  Context ctx;
  Mesh in = jiggled(8, 7);
  add_linear_field(in);
  in.vertex_fields.push_back({"g", 2, {}});
  for (int64_t v = 0; v < in.num_vertices(); ++v)
    in.vertex_fields.back().values.insert(in.vertex_fields.back().values.end(),
                                          {std::sin(9 * in.points[3 * size_t(v)]), double(v % 7)});
  for (auto boundary : {CollapseOptions::Features, CollapseOptions::Free}) {
    Mesh m = coarsened(in, boundary);
    m.points[0] = 1.3;  // a vertex outside the original: the host's nearest-tet search
    Mesh d = m;
    const int64_t out_host = resample_vertex_fields(in, m), out_device = resample_vertex_fields(in, d, ctx);
    EXPECT_EQ(out_device, out_host);
    EXPECT_GE(out_host, 1);
    for (size_t f = 0; f < m.vertex_fields.size(); ++f)
      for (size_t i = 0; i < m.vertex_fields[f].values.size(); ++i)
        ASSERT_EQ(d.vertex_fields[f].values[i], m.vertex_fields[f].values[i]) << "field " << f << " value " << i;
  }
}

TEST(ResampleFields, TheValueAtANewPlaceIsTheOriginalsNotAnAverage) {
  Mesh in = jiggled(8, 11);
  in.vertex_fields.push_back({"g", 1, {}});
  for (int64_t v = 0; v < in.num_vertices(); ++v) {
    const double* p = &in.points[3 * size_t(v)];
    in.vertex_fields[0].values.push_back(std::sin(6 * p[0]) * std::cos(5 * p[1]) + p[2] * p[2]);
  }
  Mesh m = in;
  CollapseOptions o;
  o.method = CollapseOptions::Sequential;
  o.target_factor = 2;
  o.boundary = CollapseOptions::Free;
  collapse_sequential(m, o);
  const double before = field_errors(in, m, 50000)[0].rms_rel;
  resample_vertex_fields(in, m);
  const double after = field_errors(in, m, 50000)[0].rms_rel;
  EXPECT_LT(after, before) << "the original field at each vertex is closer than the average of two ends";
  EXPECT_GT(before, 0);
  // at an output vertex, the value is the input's field there (located in the input)
  const TetLocator loc(in);
  for (int64_t v = 0; v < m.num_vertices(); v += 7) {
    double b[4];
    const int64_t t = loc.locate(&m.points[3 * size_t(v)], b);
    double x = 0;
    for (int k = 0; k < 4; ++k) x += b[k] * in.vertex_fields[0].values[size_t(in.tets[size_t(4 * t + k)])];
    EXPECT_NEAR(m.vertex_fields[0].values[size_t(v)], x, 1e-12);
  }
}

TEST(FieldErrors, NoneAgainstItselfAndOneWhereTheFieldDiffers) {
  Mesh a = jiggled(4, 1);
  add_linear_field(a);
  EXPECT_LT(field_errors(a, a, 5000)[0].max_abs, 1e-14);
  Mesh b = a;
  b.vertex_fields[0].values[size_t(40)] += 0.5;
  const FieldError e = field_errors(a, b, 5000)[0];
  EXPECT_NEAR(e.max_abs, 0.5, 1e-12) << "at the vertex itself";
  EXPECT_GT(e.rms_abs, 0);
  EXPECT_EQ(e.samples, 5000 + a.num_vertices());
}

TEST(FieldsCli, PreserveFieldCoarsensAndChecksTheField) {
  Mesh in = jiggled(8, 13);
  in.vertex_fields.push_back({"rho", 1, {}});
  for (int64_t v = 0; v < in.num_vertices(); ++v)
    in.vertex_fields[0].values.push_back(std::exp(-8 * std::pow(in.points[3 * size_t(v)] - 0.5, 2)));
  TempDir dir;
  const std::string src = dir.file("in.vtu"), out = dir.file("out.vtu");
  write_mesh(src, in);
  std::string log;
  ASSERT_EQ(run_command(std::string("'") + TC_CLI + "' '" + src + "' '" + out +
                            "' --preserve-field rho --field-tolerance 0.05 --no-improve",
                        &log),
            0)
      << log;
  const Mesh m = read_mesh(out);
  EXPECT_LT(m.num_vertices(), in.num_vertices());
  ASSERT_EQ(run_command(std::string("'") + TC_CLI + "' check '" + out + "' --reference '" + src + "'", &log), 0) << log;
  EXPECT_NE(log.find("field 'rho'"), std::string::npos) << log;
  EXPECT_EQ(run_command(std::string("'") + TC_CLI + "' '" + src + "' '" + out + "' --preserve-field nope", &log), 2);
  EXPECT_NE(log.find("nope"), std::string::npos) << log;
  EXPECT_EQ(run_command(std::string("'") + TC_CLI + "' '" + src + "' '" + out +
                            "' --preserve-field rho --max-field-error 0.01 --field-check 0.5",
                        &log),
            2);
  EXPECT_NE(log.find("--field-check"), std::string::npos) << log;
}

Mesh with_bump(int n, unsigned seed) {
  Mesh m = jiggled(n, seed);
  m.vertex_fields.push_back({"rho", 1, {}});
  for (int64_t v = 0; v < m.num_vertices(); ++v) {
    const double* p = &m.points[3 * size_t(v)];
    m.vertex_fields[0].values.push_back(std::exp(-10 * (std::pow(p[0] - 0.4, 2) + std::pow(p[1] - 0.6, 2))) + p[2]);
  }
  return m;
}

// The field error bound holds at every input vertex, by the locator's own measurement of the
// output (not the run's), in both boundary modes, and the run does coarsen.
TEST(FieldBound, EveryInputVertexKeepsItsValueWithinTheBound) {
  const Mesh in = with_bump(10, 3);
  for (auto boundary : {CollapseOptions::Features, CollapseOptions::Free}) {
    for (double bound : {0.01, 0.05}) {
      Mesh m = in;
      CollapseOptions o;
      o.method = CollapseOptions::Sequential;
      o.boundary = boundary;
      o.max_field_error = bound;
      o.bounded_field = "rho";
      const CollapseReport r = collapse_sequential(m, o);
      EXPECT_LT(m.num_vertices(), in.num_vertices() * 3 / 4) << "the bound alone decides: it coarsens";
      EXPECT_EQ(r.field_error_bound, bound);
      EXPECT_LE(r.field_error, bound);
      EXPECT_GT(r.field_error, bound / 4) << "it coarsens up to the bound";
      const FieldError e = field_errors(in, m, 0)[0];
      EXPECT_LE(e.max_vertex_rel, bound * (1 + 1e-9));
      EXPECT_NEAR(e.max_vertex_rel, r.field_error, 1e-9) << "the run measures what the locator measures";
      // every input vertex stays inside the output
      const TetLocator loc(m);
      int64_t outside = 0;
      for (int64_t v = 0; v < in.num_vertices(); ++v) {
        double b[4];
        bool out = false;
        loc.locate(&in.points[3 * size_t(v)], b, &out);
        outside += out;
      }
      EXPECT_EQ(outside, 0);
      // the survivors carry the input's field at their places
      resample_vertex_fields(in, m);
      EXPECT_LE(field_errors(in, m, 0)[0].max_vertex_rel, bound * (1 + 1e-9));
    }
  }
}

// The points where the bound is measured, given (CollapseOptions::field_points, for a run that
// goes on from an earlier one): the input's vertices located in the mesh given, their input
// values and the input's range.
void give_field_points(const Mesh& input, const Mesh& mesh, CollapseOptions& o) {
  const TetLocator loc(mesh);
  o.field_points = input.points;
  o.field_point_values = input.vertex_fields[0].values;
  o.field_point_tets.clear();
  for (int64_t v = 0; v < input.num_vertices(); ++v) {
    double b[4];
    o.field_point_tets.push_back(int32_t(loc.locate(&input.points[3 * size_t(v)], b)));
  }
  const auto [lo, hi] = std::minmax_element(input.vertex_fields[0].values.begin(), input.vertex_fields[0].values.end());
  o.field_range = {*hi - *lo};
}

// A second run on the output of a first, as the MPI tool's rounds go on: given the input's
// vertices as the points, the bound still holds at them; measured at its own vertices instead,
// the second run adds its error to the first's and goes past the bound (the check can fail).
// Given the mesh's own vertices, a run is the one without points, bit for bit.
TEST(FieldBound, ARunGoesOnFromTheInputsPointsWhereOneBeforeEnded) {
  const Mesh in = with_bump(10, 3);
  const double bound = 0.02;
  CollapseOptions o;
  o.method = CollapseOptions::Sequential;
  o.max_field_error = bound;
  o.target_length = 0.15;  // the first run leaves longer edges for the second
  Mesh first = in;
  collapse_sequential(first, o);
  ASSERT_LE(field_errors(in, first, 0)[0].max_vertex_rel, bound * (1 + 1e-9));
  o.target_length = 0;  // (the bound alone)

  Mesh own = first;
  collapse_sequential(own, o);
  EXPECT_GT(field_errors(in, own, 0)[0].max_vertex_rel, bound * 1.1) << "the errors of two runs add up";

  Mesh goes_on = first;
  CollapseOptions g = o;
  give_field_points(in, first, g);
  const CollapseReport r = collapse_sequential(goes_on, g);
  const double e = field_errors(in, goes_on, 0)[0].max_vertex_rel;
  EXPECT_LE(e, bound * (1 + 1e-9));
  EXPECT_NEAR(r.field_error, e, 1e-9) << "the run measures at the points given";
  EXPECT_LT(goes_on.num_vertices(), first.num_vertices()) << "and still coarsens";

  Mesh a = first, b = first;
  CollapseOptions self = o;
  give_field_points(first, first, self);
  collapse_sequential(a, o);
  collapse_sequential(b, self);
  EXPECT_EQ(a.points, b.points);
  EXPECT_EQ(a.tets, b.tets);
}

TEST(FieldBound, GivenPointsNeedTheBoundAndMatchingSizes) {
  const Mesh in = with_bump(4, 1);
  CollapseOptions o;
  o.method = CollapseOptions::Sequential;
  o.max_field_error = 0.01;
  give_field_points(in, in, o);
  {
    Mesh m = in;
    EXPECT_NO_THROW(collapse_sequential(m, o));
  }
  auto throws = [&](CollapseOptions bad) {
    Mesh m = in;
    EXPECT_THROW(collapse_sequential(m, bad), std::invalid_argument);
  };
  CollapseOptions bad = o;
  bad.field_point_values.pop_back();
  throws(bad);
  bad = o;
  bad.field_point_tets[0] = int32_t(in.num_tets());
  throws(bad);
  bad = o;
  bad.field_range = {1, 2};
  throws(bad);
  bad = o;
  bad.field_points[4] = NAN;
  throws(bad);
  bad = o;
  bad.max_field_error = 0;
  throws(bad);
  Context ctx;
  Mesh m = in;
  EXPECT_THROW(collapse(m, bad, ctx), std::invalid_argument) << "nor on the device";
}

// A linear field is exact in any coarsening, so the bound refuses nothing on its account; a
// bumpy one under a small bound keeps more vertices. (A check that admitted everything would
// coarsen both alike.)
TEST(FieldBound, ALinearFieldCoarsensFurtherThanABumpyOne) {
  Mesh lin = jiggled(10, 5);
  add_linear_field(lin);
  Mesh bumpy = with_bump(10, 5);
  CollapseOptions o;
  o.method = CollapseOptions::Sequential;
  o.max_field_error = 0.002;
  const CollapseReport rl = collapse_sequential(lin, o);
  const CollapseReport rb = collapse_sequential(bumpy, o);
  EXPECT_LT(rl.field_error, 1e-9);
  int64_t refused = 0;
  for (const IterationStats& it : rb.iterations) refused += it.refused_by_bound;
  EXPECT_GT(refused, 0);
  EXPECT_LT(lin.num_vertices() * 3, bumpy.num_vertices() * 2) << lin.num_vertices() << " vs " << bumpy.num_vertices();
}

TEST(FieldBound, ANamedFieldMustExistAndTheBoundBeFinite) {
  Mesh m = with_bump(4, 1);
  CollapseOptions o;
  o.method = CollapseOptions::Sequential;
  o.max_field_error = 0.01;
  o.bounded_field = "nope";
  EXPECT_THROW(collapse_sequential(m, o), std::invalid_argument);
  o.bounded_field.clear();
  o.max_field_error = INFINITY;
  EXPECT_THROW(collapse_sequential(m, o), std::invalid_argument);
  Mesh bare = jiggled(4, 1);
  o.max_field_error = 0.01;
  EXPECT_THROW(collapse_sequential(bare, o), std::invalid_argument) << "no vertex field";
}

// The paper's field cost, built in: both methods (and so the parallel method's host tail)
// collapse where the field is flat and keep every vertex where it is steep.
TEST(FieldCost, CollapsesWhereTheFieldIsFlatOnBothMethods) {
  Mesh in = jiggled(8, 21);
  in.vertex_fields.push_back({"phi", 1, {}});
  for (int64_t v = 0; v < in.num_vertices(); ++v) {
    const double x = in.points[3 * size_t(v)];
    in.vertex_fields[0].values.push_back(x < 0.5 ? 0.0 : 10 * (x - 0.5));
  }
  auto count = [](const Mesh& m, double lo, double hi) {
    int64_t n = 0;
    for (int64_t v = 0; v < m.num_vertices(); ++v) n += m.points[3 * size_t(v)] > lo && m.points[3 * size_t(v)] < hi;
    return n;
  };
  Context ctx;
  for (auto method : {CollapseOptions::Sequential, CollapseOptions::Parallel}) {
    Mesh m = in;
    CollapseOptions o;
    o.method = method;
    o.field_difference_cost = true;
    o.target_length = 1e-6;  // only the flat half (and the face x = 1) has ends this close
    collapse(m, o, ctx);
    EXPECT_LT(count(m, 0, 0.45), count(in, 0, 0.45) / 2) << "the flat half coarsens";
    // (the face x = 1 is a level set of the field: it coarsens)
    EXPECT_EQ(count(m, 0.62, 0.97), count(in, 0.62, 0.97)) << "no vertex inside the steep half goes";
  }
  CollapseOptions bad;
  bad.field_difference_cost = true;
  Mesh m = in;
  EXPECT_THROW(collapse(m, bad, ctx), std::invalid_argument) << "no target";
  bad.target_length = 0.01;
  bad.cost_cl_source = "double tc_user_cost(double3 p0, double3 p1, double f0, double f1) { return 0.0; }";
  EXPECT_THROW(collapse(m, bad, ctx), std::invalid_argument) << "two costs";
}

// The field check (CollapseOptions::field_check), the shared volume test's (cl/collapse_checks.h):
// a linear field is interpolated exactly, so even a check of 1e-9 refuses nothing and both
// methods give what they give without it, bit for bit.
TEST(FieldCheck, RefusesNothingOnALinearField) {
  Mesh in = jiggled(8, 23);
  add_linear_field(in);
  Context ctx;
  for (auto method : {CollapseOptions::Sequential, CollapseOptions::Parallel})
    for (auto boundary : {CollapseOptions::Features, CollapseOptions::Free}) {
      CollapseOptions o;
      o.method = method;
      o.boundary = boundary;
      o.field_difference_cost = true;
      o.target_length = 0.5;
      Mesh plain = in, checked = in;
      collapse(plain, o, ctx);
      o.field_check = 1e-9;
      collapse(checked, o, ctx);
      ASSERT_LT(plain.num_vertices(), in.num_vertices() / 2) << "it coarsens";
      EXPECT_EQ(checked.tets, plain.tets);
      EXPECT_EQ(checked.points, plain.points);
    }
}

// A peak the edges' end differences do not see: every edge is marked (|1 - 0| below the
// target), so the paper's cost alone removes the peak's vertex; the check keeps it where it was,
// with its value, on both methods.
TEST(FieldCheck, KeepsAPeakTheEdgeDifferenceMisses) {
  Mesh in = jiggled(6, 29);
  in.vertex_fields.push_back({"phi", 1, std::vector<double>(size_t(in.num_vertices()), 0.0)});
  int64_t peak = -1;
  double nearest = INFINITY;
  for (int64_t v = 0; v < in.num_vertices(); ++v) {
    const double* p = &in.points[3 * size_t(v)];
    const double d = std::pow(p[0] - 0.5, 2) + std::pow(p[1] - 0.5, 2) + std::pow(p[2] - 0.5, 2);
    if (d < nearest) nearest = d, peak = v;
  }
  in.vertex_fields[0].values[size_t(peak)] = 1.0;
  const double* at = &in.points[3 * size_t(peak)];
  auto kept = [&](const Mesh& m) {
    for (int64_t v = 0; v < m.num_vertices(); ++v)
      if (m.points[3 * size_t(v)] == at[0] && m.points[3 * size_t(v) + 1] == at[1] &&
          m.points[3 * size_t(v) + 2] == at[2] && std::fabs(m.vertex_fields[0].values[size_t(v)] - 1.0) < 1e-12)
        return true;
    return false;
  };
  Context ctx;
  for (auto method : {CollapseOptions::Sequential, CollapseOptions::Parallel}) {
    CollapseOptions o;
    o.method = method;
    o.field_difference_cost = true;
    o.target_length = 2;
    Mesh plain = in, checked = in;
    collapse(plain, o, ctx);
    EXPECT_FALSE(kept(plain)) << "the paper's cost alone flattens the peak";
    o.field_check = 0.25;  // 0.5 in field units: any collapse at the peak moves it by more
    collapse(checked, o, ctx);
    EXPECT_TRUE(kept(checked));
    EXPECT_LT(checked.num_vertices(), in.num_vertices() / 2) << "the rest coarsens";
  }
}

TEST(FieldsCli, MaxFieldErrorBoundsTheNamedFieldAtTheInputVertices) {
  const Mesh in = with_bump(8, 17);
  TempDir dir;
  const std::string src = dir.file("in.vtu"), out = dir.file("out.vtu"), stats = dir.file("s.json");
  write_mesh(src, in);
  std::string log;
  const std::string cmd = std::string("'") + TC_CLI + "' '" + src + "' '" + out + "'";
  ASSERT_EQ(run_command(cmd + " --preserve-field rho --max-field-error 0.02 --stats '" + stats + "'", &log), 0) << log;
  EXPECT_NE(log.find("field error at the input's vertices"), std::string::npos) << log;
  EXPECT_EQ(log.find("quality after improve"), std::string::npos) << "no improvement phase under the bound";
  const Mesh m = read_mesh(out);
  EXPECT_LT(m.num_vertices(), in.num_vertices());
  EXPECT_LE(field_errors(in, m, 0)[0].max_vertex_rel, 0.02 * (1 + 1e-9));
  EXPECT_NE(read_text(stats).find("\"field_error_bound\":0.02"), std::string::npos);
  EXPECT_EQ(run_command(cmd + " --max-field-error 0.02", &log), 2) << "which field?";
  EXPECT_NE(log.find("--preserve-field"), std::string::npos) << log;
  EXPECT_EQ(run_command(cmd + " --preserve-field rho --max-field-error 0.02 --field-tolerance 0.1", &log), 2);
  EXPECT_EQ(run_command(cmd + " --preserve-field rho --max-field-error 0.02 --method sequential", &log), 0) << log;
}

// scripts/render_dvr.py renders a small mesh and its coarsened copy (when VTK and Xvfb are
// installed: scripts/setup.sh --with-tools).
TEST(FieldsCli, TheRenderingScriptComparesTwoMeshes) {
  std::string probe;
  if (run_command("/usr/bin/python3 -c 'import vtk, numpy' && command -v xvfb-run", &probe) != 0)
    GTEST_SKIP() << "no VTK Python module or xvfb-run (scripts/setup.sh --with-tools installs them)";
  Mesh in = jiggled(6, 17);
  in.vertex_fields.push_back({"rho", 1, {}});
  for (int64_t v = 0; v < in.num_vertices(); ++v) in.vertex_fields[0].values.push_back(in.points[3 * size_t(v)]);
  TempDir dir;
  const std::string a = dir.file("a.vtu"), b = dir.file("b.vtu"), png = dir.file("pair.png");
  write_mesh(a, in);
  std::string log;
  const std::string script = std::string("/usr/bin/python3 '") + TC_SOURCE_DIR + "/scripts/render_dvr.py' ";
  ASSERT_EQ(run_command(script + "'" + a + "' '" + a + "' --field rho --size 96 --json", &log), 0) << log;
  EXPECT_NE(log.find("\"psnr\": Infinity"), std::string::npos) << "an image against itself: " << log;
  Mesh shifted = in;
  for (double& x : shifted.vertex_fields[0].values) x = 1 - x;
  write_mesh(b, shifted);
  ASSERT_EQ(run_command(script + "'" + a + "' '" + b + "' --field rho --size 96 --json --png '" + png + "'", &log), 0)
      << log;
  EXPECT_EQ(log.find("Infinity"), std::string::npos) << "a reversed field renders otherwise: " << log;
  EXPECT_TRUE(std::filesystem::exists(png));
}

}  // namespace
}  // namespace tc
