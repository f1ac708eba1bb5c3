// tc::coarsen: the command line's sequence as one call (tetcollapse/coarsen.hpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "test_support.hpp"
#include "tetcollapse/coarsen.hpp"
#include "tetcollapse/device.hpp"
#include "tetcollapse/fields.hpp"
#include "tetcollapse/check.hpp"
#include "tetcollapse/collapse.hpp"
#include "tetcollapse/improve.hpp"
#include "tetcollapse/io.hpp"
#include "collapse/upload.hpp"

namespace tc {
namespace {

Mesh bumpy_cube(unsigned seed) {
  Mesh m = test::cube_tets(7);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-0.25 / 7, 0.25 / 7);  // (more inverts Kuhn tets)
  for (double& x : m.points)
    if (x > 0 && x < 1) x += u(rng);
  m.vertex_fields.push_back({"rho", 1, {}});
  for (int64_t v = 0; v < m.num_vertices(); ++v) {
    const double* p = &m.points[3 * size_t(v)];
    m.vertex_fields[0].values.push_back(std::exp(-8 * (std::pow(p[0] - 0.5, 2) + std::pow(p[1] - 0.4, 2))) + p[2]);
  }
  return m;
}

// Coarsening to twice the median edge length within 0.002 of the diagonal, one cycle.
CoarsenOptions bounded_to_twice_the_median() {
  CoarsenOptions co;
  co.cycles = 1;
  co.collapse.target_factor = 2;
  co.collapse.max_boundary_error = 0.002;
  return co;
}

// The same mesh as the collapse, the improvement and the resampling called one after the other.
TEST(Coarsen, IsTheCollapseThenTheImprovementThenTheFields) {
  Context ctx;
  const Mesh in = bumpy_cube(1);
  CoarsenOptions co;
  co.collapse.target_factor = 2;
  co.cycles = 1;
  Mesh a = in;
  const CoarsenReport r = coarsen(a, co, &ctx);
  EXPECT_TRUE(r.improved);
  Mesh b = in;
  collapse(b, co.collapse, ctx);
  ImproveOptions io;
  improve(b, io, ctx);
  resample_vertex_fields(in, b);
  EXPECT_EQ(a.tets, b.tets);
  EXPECT_EQ(a.points, b.points);
  EXPECT_EQ(a.vertex_fields[0].values, b.vertex_fields[0].values);
  EXPECT_EQ(r.collapse.tets_out, a.num_tets());
}

// With its flips, relocation and collapse step all off the improvement would change nothing: no
// improvement phase, and the collapse has all of the boundary error bound (as without the phase).
TEST(Coarsen, NoImprovementPhaseWithEveryOperationOff) {
  Context ctx;
  const Mesh in = test::ball(8);
  CoarsenOptions co = bounded_to_twice_the_median();
  co.improvement.flips = co.improvement.smoothing = co.improvement.collapse = false;
  Mesh off = in, none = in;
  const CoarsenReport r = coarsen(off, co, &ctx);
  EXPECT_FALSE(r.improved);
  co.improve = false;
  coarsen(none, co, &ctx);
  EXPECT_EQ(off.tets, none.tets);
  EXPECT_EQ(off.points, none.points);
  co.improve = true;
  co.improvement.collapse = true;
  EXPECT_TRUE(improvement_follows(co));
}

// Later cycles (CoarsenOptions::cycles) collapse the edges the improvement made collapsible:
// fewer tets, the first cycle the one-cycle run's, each cycle starting where the one before
// ended, the result valid and, since each cycle goes on from the bound each vertex spent,
// within the boundary error bound by the checker's two-sided distance.
TEST(Coarsen, LaterCyclesCollapseWhatTheImprovementFreed) {
  Context ctx;
  const Mesh in = test::torus(8, 24);
  CoarsenOptions co = bounded_to_twice_the_median();
  Mesh one = in, three = in;
  co.cycles = 1;
  const CoarsenReport r1 = coarsen(one, co, &ctx);
  EXPECT_TRUE(r1.later_cycles.empty());
  co.cycles = 3;
  const CoarsenReport r3 = coarsen(three, co, &ctx);
  ASSERT_FALSE(r3.later_cycles.empty());
  EXPECT_LT(three.num_tets(), one.num_tets() * 19 / 20) << "a later cycle coarsens further";
  EXPECT_EQ(r3.later_cycles[0].tets_before, one.num_tets()) << "the first cycle is the one-cycle run";
  for (size_t k = 0; k < r3.later_cycles.size(); ++k) {
    const CycleReport& c = r3.later_cycles[k];
    if (k > 0) {
      EXPECT_EQ(c.tets_before, r3.later_cycles[k - 1].tets_after);
    }
    EXPECT_LE(c.tets_collapsed, c.tets_before);
    EXPECT_EQ(c.collapse.target_length, r3.collapse.target_length) << "the same target";
    EXPECT_EQ(c.improved, c.tets_collapsed < c.tets_before) << "every collapse that removed a tet is improved";
    if (double(c.tets_before - c.tets_collapsed) < kCycleMinShare * double(c.tets_before)) {
      EXPECT_EQ(k + 1, r3.later_cycles.size()) << "a cycle that removed too few is the last";
    }
  }
  EXPECT_EQ(r3.later_cycles.back().tets_after, three.num_tets());
  EXPECT_EQ(last_improvement(r3).after.tets, three.num_tets()) << "the last improvement's quality is the result's";
  EXPECT_EQ(r3.collapse.tets_out, three.num_tets());
  CheckOptions check;
  check.hausdorff = true;
  const CheckReport cr = check_mesh(three, check, &in);
  EXPECT_TRUE(cr.valid) << check_report_text(cr);
  EXPECT_LE(cr.reference.hausdorff_rel, 0.002) << "the checker's two-sided distance within the bound";
  EXPECT_LE(r3.collapse.boundary_error, boundary_error_bound(in, co.collapse) * (1 + 1e-12));

  co.cycles = 0;
  Mesh m = in;
  EXPECT_THROW(coarsen(m, co, &ctx), std::invalid_argument);
  co.cycles = 2;
  co.collapse.vertex_mask.assign(size_t(in.num_vertices()), 1);
  EXPECT_THROW(coarsen(m, co, &ctx), std::invalid_argument) << "the input's mask does not fit the coarse mesh";
  co.improve_mask = [](const Mesh& coarse) { return std::vector<uint8_t>(size_t(coarse.num_vertices()), 1); };
  EXPECT_NO_THROW(coarsen(m, co, &ctx));
}

// No buffer is split over CL_DEVICE_MAX_MEM_ALLOC_SIZE (Context::largest_allocation): OpenCL
// grants a quarter of the global memory per allocation at least, so a run whose largest buffer
// stays below a quarter of what the memory check estimates it needs never needs one. Held here
// for the whole command (both cycles, the fields' resampling), with and without the boundary
// error bound, on the CPU's and the GPU's code paths.
// A needle bipyramid (four tets around a long interior edge, every vertex on the boundary), the
// flips off: the improvement alone splits the edge, 8 tets; in the coarsening, which collapses
// nothing here, the splits do not take the mesh past the tets it was given.
TEST(Coarsen, ItsSplitsNeverTakeTheMeshPastItsInput) {
  Mesh m;
  m.points = {0, 0, 10, 0, 0, -10, 1, 0, 0, 0, 1, 0, -1, 0, 0, 0, -1, 0};
  for (int i = 0; i < 4; ++i) m.tets.insert(m.tets.end(), {0, 1, 2 + (i + 1) % 4, 2 + i});
  ImproveOptions no_flips;
  no_flips.flips = false;
  Mesh improved = m;
  improve(improved, no_flips);
  EXPECT_EQ(improved.num_tets(), 8) << "a split";
  Context ctx;
  CoarsenOptions co;
  co.improvement = no_flips;
  co.collapse.target_length = 1e-3;  // (nothing to collapse)
  Mesh coarse = m;
  const CoarsenReport r = coarsen(coarse, co, &ctx);
  EXPECT_TRUE(r.improved);
  EXPECT_LE(coarse.num_tets(), m.num_tets());
}

// No threshold in mesh units: the bracket in units 2^30 times smaller or larger (exact in
// binary) gives the same coarse mesh, scaled, with the defaults (the collapse under the boundary
// error bound, the improvement, two cycles). With the paper's absolute volume threshold
// (2e-12) the smaller one, whose tets are all below it, did not coarsen at all.
TEST(Coarsen, TheSameMeshInAnyUnitGivesTheSameResult) {
  Context ctx;
  const Mesh bracket = read_mesh(test::project_mesh("bracket.msh"));
  CoarsenOptions co;
  co.collapse.target_factor = 2;
  Mesh ref = bracket;
  coarsen(ref, co, &ctx);
  ASSERT_LT(ref.num_tets(), bracket.num_tets() / 4);
  for (double scale : {std::ldexp(1.0, -30), std::ldexp(1.0, 30)}) {
    Mesh m = bracket;
    for (double& x : m.points) x *= scale;
    coarsen(m, co, &ctx);
    EXPECT_EQ(m.tets, ref.tets) << "scale " << scale;
    ASSERT_EQ(m.points.size(), ref.points.size());
    size_t differ = 0;
    for (size_t i = 0; i < m.points.size(); ++i) differ += m.points[i] != ref.points[i] * scale;
    EXPECT_EQ(differ, 0u) << "scale " << scale;
  }
  // the same threshold the paper's way, in mesh units, refuses every collapse of the smaller one
  Mesh tiny = bracket;
  for (double& x : tiny.points) x *= std::ldexp(1.0, -30);
  co.collapse.eps_v = 2e-12;
  co.collapse.eps_v_scale = CollapseOptions::Absolute;
  co.improve = false;
  coarsen(tiny, co, &ctx);
  EXPECT_EQ(tiny.num_tets(), bracket.num_tets());
}

TEST(Coarsen, TheLargestBufferIsUnderAQuarterOfTheEstimate) {
  Mesh bracket = read_mesh(test::project_mesh("bracket.msh"));
  bracket.vertex_fields.push_back({"z", 1, {}});
  for (int64_t v = 0; v < bracket.num_vertices(); ++v) bracket.vertex_fields[0].values.push_back(bracket.points[3 * size_t(v) + 2]);
  for (const Mesh& in : {bracket, test::ball(14)}) {
    for (double bound : {0.0, 0.001}) {
      for (bool cpu : {true, false}) {
        Context ctx;
        ctx.set_cpu_tuning(cpu);
        CoarsenOptions co;
        co.collapse.target_factor = 2;
        co.collapse.max_boundary_error = bound;
        Mesh m = in;
        coarsen(m, co, &ctx);
        const uint64_t estimate = collapse_detail::device_bytes_estimate(in, co.collapse);
        EXPECT_LE(4 * ctx.largest_allocation(), estimate)
            << in.num_tets() << " tets, bound " << bound << ", cpu tuning " << cpu << ": largest buffer "
            << ctx.largest_allocation() << " bytes";
        EXPECT_GT(ctx.largest_allocation(), estimate / 100) << "it counts the mesh's buffers";
      }
    }
  }
}

// A boundary error bound: the collapse uses its share, the improvement the rest, and the result
// stays within the whole.
TEST(Coarsen, SharesABoundaryErrorBoundWithTheImprovement) {
  Context ctx;
  Mesh m = bumpy_cube(2);
  CoarsenOptions co = bounded_to_twice_the_median();
  const double bound = boundary_error_bound(m, co.collapse);
  const CoarsenReport r = coarsen(m, co, &ctx);
  EXPECT_TRUE(r.improved);
  EXPECT_EQ(r.collapse.boundary_error_bound, bound);
  EXPECT_LE(r.collapse.boundary_error, kCollapseShareOfBound * bound * (1 + 1e-12));
}

// The improvement goes on from what the collapse spent at each vertex: on a ball it moves
// vertices of the curved surface, and the checker's two-sided distance of the result stays
// within the bound. With every vertex seeded as spent, no vertex of the curved surface moves.
TEST(Coarsen, TheImprovementKeepsTheBoundVertexByVertex) {
  Context ctx;
  const Mesh in = test::ball(8);
  CoarsenOptions co = bounded_to_twice_the_median();
  Mesh m = in;
  const CoarsenReport r = coarsen(m, co, &ctx);
  ASSERT_TRUE(r.improved);
  ASSERT_EQ(last_improvement(r).vertex_boundary_error.size(), size_t(m.num_vertices())) << "per output vertex";
  CheckOptions check;
  check.hausdorff = true;
  const CheckReport cr = check_mesh(m, check, &in);
  EXPECT_TRUE(cr.valid) << check_report_text(cr);
  EXPECT_LE(cr.reference.hausdorff_rel, 0.002) << "the checker's two-sided distance within the bound";

  // the collapse alone, then the improvement with and without the collapse's spending
  Mesh collapsed = in;
  CollapseOptions cc = co.collapse;
  cc.max_boundary_error = 0;
  cc.max_boundary_error_abs = kCollapseShareOfBound * boundary_error_bound(in, co.collapse);
  const CollapseReport c = collapse(collapsed, cc, ctx);
  const auto surface_moves = [&](const std::vector<double>& spent) {
    Mesh x = collapsed;
    ImproveOptions io;
    io.max_boundary_error_abs = boundary_error_bound(in, co.collapse);
    io.vertex_boundary_error = spent;
    io.collapse = false;  // (the collapse step renumbers the vertices)
    improve(x, io, ctx);
    int64_t moved = 0;
    for (int64_t v = 0; v < collapsed.num_vertices(); ++v) {  // (a split appends its vertex)
      const double* p = &collapsed.points[3 * size_t(v)];
      const double* q = &x.points[3 * size_t(v)];
      const bool on_sphere = std::fabs(std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) - 1) < 1e-9;
      moved += on_sphere && (p[0] != q[0] || p[1] != q[1] || p[2] != q[2]);
    }
    return moved;
  };
  EXPECT_GT(surface_moves(c.vertex_boundary_error), 0) << "the improvement moves vertices of the sphere";
  EXPECT_EQ(surface_moves(std::vector<double>(size_t(collapsed.num_vertices()), boundary_error_bound(in, co.collapse))), 0)
      << "nothing is left to spend";
  // the bounds reached come back per vertex: each at least where it began, within the bound,
  // some higher (the sphere's vertices moved); with the collapse step, per output vertex
  for (bool step : {false, true}) {
    Mesh x = collapsed;
    ImproveOptions io;
    io.max_boundary_error_abs = boundary_error_bound(in, co.collapse);
    io.vertex_boundary_error = c.vertex_boundary_error;
    io.collapse = step;
    const ImproveReport ir = improve(x, io, ctx);
    ASSERT_EQ(ir.vertex_boundary_error.size(), size_t(x.num_vertices())) << step;
    EXPECT_LE(*std::max_element(ir.vertex_boundary_error.begin(), ir.vertex_boundary_error.end()),
              io.max_boundary_error_abs) << step;
    if (step) continue;
    int64_t higher = 0;
    for (size_t v = 0; v < c.vertex_boundary_error.size(); ++v) {
      EXPECT_GE(ir.vertex_boundary_error[v], c.vertex_boundary_error[v]) << v;
      higher += ir.vertex_boundary_error[v] > c.vertex_boundary_error[v];
    }
    EXPECT_GT(higher, 0);
  }
  ImproveOptions free_mode;
  free_mode.boundary = CollapseOptions::Free;
  free_mode.max_boundary_error_abs = 0.01;
  Mesh x = collapsed;
  EXPECT_THROW(improve(x, free_mode, ctx), std::invalid_argument) << "the bound is the features mode's";
}

// No improvement phase under the field error bound (its moves are not checked against it) or a
// user predicate (rules it cannot know); the field options are checked.
TEST(Coarsen, SkipsTheImprovementWhereItWouldBreakARule) {
  Context ctx;
  {
    Mesh m = bumpy_cube(3);
    CoarsenOptions co;
    co.preserve_field = "rho";
    co.collapse.max_field_error = 0.02;
    const CoarsenReport r = coarsen(m, co, &ctx);
    EXPECT_FALSE(r.improved);
    EXPECT_LE(r.collapse.field_error, 0.02);
    EXPECT_LT(m.num_vertices(), bumpy_cube(3).num_vertices());
  }
  {
    Mesh m = bumpy_cube(4);
    CoarsenOptions co;
    co.collapse.target_factor = 2;
    co.collapse.predicate_cl_source = "int tc_user_predicate(double3 p0, double3 p1, double f0, double f1) { return 1; }";
    EXPECT_FALSE(coarsen(m, co, &ctx).improved);
  }
  Mesh m = bumpy_cube(5);
  CoarsenOptions co;
  co.preserve_field = "nope";
  EXPECT_THROW(coarsen(m, co, &ctx), std::invalid_argument);
  co.preserve_field.clear();
  co.collapse.max_field_error = 0.01;
  EXPECT_THROW(coarsen(m, co, &ctx), std::invalid_argument) << "which field?";
  CoarsenOptions parallel;
  EXPECT_THROW(coarsen(m, parallel, nullptr), std::invalid_argument) << "the parallel method needs a device";
}

}  // namespace
}  // namespace tc
