// The whole collapse loop: validity, feature preservation, strict mode, determinism, shared meshes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <set>
#include <tuple>

#include "tetcollapse/check.hpp"
#include "tetcollapse/collapse.hpp"
#include "tetcollapse/io.hpp"
#include "tetcollapse/topology.hpp"
#include "collapse_test_util.hpp"
#include "test_support.hpp"

using namespace tc;

namespace {

CheckReport check(const Mesh& m, const Mesh* ref = nullptr) {
  CheckOptions o;
  o.quality = false;
  o.hausdorff = false;
  return check_mesh(m, o, ref);
}

// cube_tets(n) with a label array (1 where a tet's first vertex has x < 0.5, else 2: a material
// interface at x = 0.5), a tet field (the tet's index) and a vertex field (10 x the position)
Mesh cube_with_labels_and_fields(int n) {
  Mesh in = test::cube_tets(n);
  Labels l{"material", {}};
  Field tf{"tq", 1, {}}, vf{"vx", 3, {}};
  for (int64_t t = 0; t < in.num_tets(); ++t) {
    l.values.push_back(in.points[3 * in.tets[4 * t]] < 0.5 ? 1 : 2);
    tf.values.push_back(double(t));
  }
  for (int64_t v = 0; v < in.num_vertices(); ++v)
    for (int c = 0; c < 3; ++c) vf.values.push_back(in.points[3 * v + c] * 10);
  in.tet_labels.push_back(l);
  in.tet_fields.push_back(tf);
  in.vertex_fields.push_back(vf);
  return in;
}

std::set<std::tuple<double, double, double>> boundary_points(const Mesh& m) {
  Topology t = build_topology(m);
  std::set<std::tuple<double, double, double>> s;
  for (int32_t v = 0; v < t.num_vertices; ++v)
    if (t.vertex_boundary[v]) s.insert({m.points[3 * v], m.points[3 * v + 1], m.points[3 * v + 2]});
  return s;
}

}  // namespace

TEST(CollapsePipeline, CubeCoarsenedToTwiceMedianStaysValid) {
  Context ctx;
  Mesh in = test::cube_tets(6), m = in;
  CollapseOptions o;
  o.target_factor = 2;
  CollapseReport r = collapse(m, o, ctx);
  EXPECT_GT(r.iterations.size(), 1u);
  EXPECT_LT(r.tets_out, r.tets_in / 3) << "reduction too small";
  EXPECT_EQ(r.tets_out, m.num_tets());
  CheckReport c = check(m, &in);
  EXPECT_TRUE(c.valid) << check_report_text(c);
  EXPECT_FALSE(c.reference.topology_changed);
  // the 8 corners are still there, at their exact positions
  auto b = boundary_points(m);
  for (int i = 0; i < 8; ++i)
    EXPECT_TRUE(b.count({double(i & 1), double((i >> 1) & 1), double((i >> 2) & 1)})) << "corner " << i;
  // every boundary vertex is still on the cube's surface
  for (auto [x, y, z] : b) {
    bool on = x == 0 || x == 1 || y == 0 || y == 1 || z == 0 || z == 1;
    EXPECT_TRUE(on) << x << " " << y << " " << z;
  }
  // volume preserved exactly up to rounding (the boundary only slides within its faces)
  EXPECT_NEAR(c.volume, 1.0, 1e-12);
  // statistics are consistent
  int64_t collapsed = 0;
  for (const auto& s : r.iterations) {
    EXPECT_LE(s.candidates, s.marked);
    EXPECT_LE(s.tested, 2 * s.candidates);  // the matching selection: an early test and the full one
    EXPECT_LE(s.collapsed, s.candidates);
    EXPECT_LE(s.selected, s.candidates);
    EXPECT_LE(s.collapsed, s.selected);  // the matching selection undoes what the guard refuses
    if (s.refused_by_guard == 0) {
      EXPECT_EQ(s.collapsed, s.selected);
    }
    EXPECT_EQ(s.vertices - s.vertices_after, s.collapsed);
    collapsed += s.collapsed;
  }
  EXPECT_EQ(r.vertices_in - r.vertices_out, collapsed);
}

TEST(CollapsePipeline, StrictKeepsBoundaryVerticesBitIdentical) {
  Context ctx;
  Mesh in = test::cube_tets(5), m = in;
  CollapseOptions o;
  o.target_factor = 2;
  o.boundary = CollapseOptions::Strict;
  CollapseReport r = collapse(m, o, ctx);
  EXPECT_LT(r.tets_out, r.tets_in);
  EXPECT_TRUE(check(m, &in).valid);
  EXPECT_EQ(boundary_points(m), boundary_points(in));
}

TEST(CollapsePipeline, PaperBoundaryRuleAdmitsFewerEdges) {
  // On the same mesh, the paper's rule refuses every interior edge touching the boundary: a
  // subset of the default's admissible edges, strictly smaller on a cube.
  Context ctx;
  Mesh in = test::cube_tets(5);
  CollapseOptions o;
  o.target_factor = 2;
  o.max_iterations = 1;
  Mesh a = in, b = in;
  CollapseReport ra = collapse(a, o, ctx);
  o.paper_boundary_rule = true;
  CollapseReport rb = collapse(b, o, ctx);
  EXPECT_EQ(ra.iterations[0].marked, rb.iterations[0].marked);
  // Q runs on every marked edge (the link and volume tests only where needed, see collapse.hpp)
  EXPECT_LT(rb.iterations[0].candidates, ra.iterations[0].candidates);
  o.max_iterations = 1000;
  Mesh c = in;
  collapse(c, o, ctx);
  EXPECT_TRUE(check(c, &in).valid);
}

TEST(CollapsePipeline, DeterministicAcrossWorkGroupSizes) {
  Context ctx;
  const Mesh in = cube_with_labels_and_fields(5);  // a label array and fields travel along
  CollapseOptions o;
  o.target_factor = 2.5;
  Mesh first;
  for (size_t wg : {0, 1, 4, 32, 256}) {
    ctx.set_work_group_size(wg);
    Mesh m = in;
    collapse(m, o, ctx);
    if (wg == 0) {
      first = m;
      CheckReport c = check(m, &in);
      EXPECT_TRUE(c.valid) << check_report_text(c);
      EXPECT_EQ(m.tet_labels[0].values.size(), size_t(m.num_tets()));
      EXPECT_EQ(m.tet_fields[0].values.size(), size_t(m.num_tets()));
      EXPECT_EQ(m.vertex_fields[0].values.size(), size_t(3 * m.num_vertices()));
      // the vertex field follows the vertices: 10 x position, also after midpoint averaging
      for (int64_t v = 0; v < m.num_vertices(); ++v)
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(m.vertex_fields[0].values[3 * v + c], 10 * m.points[3 * v + c], 1e-12);
      // the material interface x = 0.5 is kept: labels on each side of it
      for (int64_t t = 0; t < m.num_tets(); ++t) {
        double x = 0;
        for (int k = 0; k < 4; ++k) x += m.points[3 * m.tets[4 * t + k]] / 4;
        EXPECT_EQ(m.tet_labels[0].values[t], x < 0.5 ? 1 : 2);
      }
      continue;
    }
    test::expect_same_mesh(m, first, "work-group size " + std::to_string(wg));
  }
}

// Adaptive marking by a vertex mask (one byte per input vertex): the mask travels through the
// spatial order's renumbering and with the survivors.
TEST(CollapsePipeline, MaskKeepsUnselectedVertices) {
  Context ctx;
  const Mesh in = test::cube_tets(6);
  CollapseOptions o;
  o.target_factor = 2;
  std::set<test::Point3> outside;
  o.vertex_mask = test::mask_x_below(in, 0.5, &outside);
  for (bool order : {true, false}) {
    SCOPED_TRACE(order);
    o.tuning.spatial_order = order;
    Mesh m = in;
    CollapseReport r = collapse(m, o, ctx);
    EXPECT_LT(r.tets_out, r.tets_in);
    CheckReport c = check(m, &in);
    EXPECT_TRUE(c.valid) << check_report_text(c);
    const std::set<test::Point3> out = test::vertex_positions(m);
    for (const auto& p : outside) EXPECT_TRUE(out.count(p)) << "an unselected vertex moved or went away";
  }
}

TEST(CollapsePipeline, TrianglesAndEdgesAreRemapped) {
  Context ctx;
  Mesh m = test::cube_tets(4);
  // tag the boundary triangles of the z = 0 face and the edges of its border
  Topology t = build_topology(m);
  for (int32_t f = 0; f < t.num_sfaces(); ++f) {
    bool bottom = true;
    for (int k = 0; k < 3; ++k) bottom = bottom && m.points[3 * t.sfaces[3 * f + k] + 2] == 0;
    if (bottom) {
      m.tris.insert(m.tris.end(), &t.sfaces[3 * f], &t.sfaces[3 * f] + 3);
      m.tri_tags.push_back(7);
    }
  }
  const size_t tris_in = m.tri_tags.size();
  CollapseOptions o;
  o.target_factor = 2;
  collapse(m, o, ctx);
  ASSERT_EQ(m.tris.size(), 3 * m.tri_tags.size());
  EXPECT_LT(m.tri_tags.size(), tris_in);
  EXPECT_GT(m.tri_tags.size(), 0u);
  // every remaining triangle is a boundary face of the result on z = 0
  EXPECT_TRUE(test::triangles_off_surface(m).empty());
  for (size_t i = 0; i < m.tri_tags.size(); ++i)
    for (int c = 0; c < 3; ++c) EXPECT_EQ(m.points[3 * size_t(m.tris[3 * i + c]) + 2], 0.0) << "triangle " << i;
}

TEST(CollapsePipeline, SharedMeshesCoarsenedToMedianStayValid) {
  TC_SKIP_IF_NO_SHARED();
  Context ctx;
  for (const char* name : {"libigl_octopus-low.mesh", "polyfem_screw.msh", "polyfem_bimetal.msh", "mmg_tinyBoxt.mesh"}) {
    std::string path = test::shared_mesh(name);
    if (path.empty()) {
      std::printf("skipping %s: absent\n", name);
      continue;
    }
    Mesh in;
    try {
      in = read_mesh(path);
    } catch (const std::exception& e) {
      std::printf("skipping %s: cannot read it: %s\n", name, e.what());
      continue;
    }
    SCOPED_TRACE(name);
    Mesh m = in;
    CollapseOptions o;
    CollapseReport r = collapse(m, o, ctx);
    std::printf("%s: tets %lld -> %lld, %zu iterations\n", name, (long long)r.tets_in, (long long)r.tets_out,
                r.iterations.size());
    EXPECT_LT(r.tets_out, r.tets_in);
    CheckReport c = check(m, &in);
    EXPECT_TRUE(c.valid) << check_report_text(c);
    EXPECT_FALSE(c.reference.topology_changed);
  }
}

// Work kept across iterations (carried verdicts, and what else reuse_across_iterations covers)
// changes nothing: same mesh bit for bit and the same decisions per iteration as recomputing
// everything, in every boundary mode, with and without the quality guard, with the greedy and
// the two-pass conflict detection. Fewer tests in all; with two-pass also in each run (its
// tests are the edges whose pass-1 turn comes, a set the carry only shrinks; the greedy tests
// an edge when it is first at both end points, which a carried refusal can make happen before
// a neighbour's collapse would have ruled the edge out).
TEST(CollapsePipeline, ReuseAcrossIterationsGivesTheSameResult) {
  Context ctx;
  std::vector<std::pair<std::string, Mesh>> inputs;
  {
    Mesh cube = test::cube_tets(6);
    Labels l{"material", {}};
    for (int64_t t = 0; t < cube.num_tets(); ++t) l.values.push_back(cube.points[3 * cube.tets[4 * t] + 1] < 0.4 ? 1 : 2);
    cube.tet_labels.push_back(l);
    inputs.emplace_back("cube", cube);
  }
  for (const char* name : {"polyfem_screw.msh", "polyfem_bimetal.msh"}) {
    std::string path = test::shared_mesh(name);
    if (path.empty()) continue;  // the cube alone still compares both ways
    try {
      inputs.emplace_back(name, read_mesh(path));
    } catch (const std::exception&) {
    }
  }
  int compared = 0;
  int64_t all_tested_a = 0, all_tested_b = 0;
  for (auto conflicts : {CollapseOptions::Greedy, CollapseOptions::TwoPass})
  for (const auto& [name, in] : inputs)
    for (auto mode : {CollapseOptions::Strict, CollapseOptions::Features, CollapseOptions::Free})
      for (double q : {0.0, 0.1}) {
        if (name != "cube" && mode != CollapseOptions::Features) continue;  // keeps the test short
        SCOPED_TRACE(name + " mode " + std::to_string(int(mode)) + " min_quality " + std::to_string(q) +
                     " conflicts " + std::to_string(int(conflicts)));
        CollapseOptions o;
        o.conflicts = conflicts;
        o.target_factor = 2;
        o.boundary = mode;
        o.min_quality = q;
        Mesh a = in, b = in;
        o.tuning.reuse_across_iterations = true;
        CollapseReport ra = collapse(a, o, ctx);
        o.tuning.reuse_across_iterations = false;
        CollapseReport rb = collapse(b, o, ctx);
        EXPECT_EQ(a.points, b.points);
        EXPECT_EQ(a.tets, b.tets);
        ASSERT_EQ(ra.iterations.size(), rb.iterations.size());
        int64_t tested_a = 0, tested_b = 0;
        for (size_t i = 0; i < ra.iterations.size(); ++i) {
          EXPECT_EQ(ra.iterations[i].selected, rb.iterations[i].selected) << "iteration " << i;
          EXPECT_EQ(ra.iterations[i].collapsed, rb.iterations[i].collapsed) << "iteration " << i;
          tested_a += ra.iterations[i].tested;
          tested_b += rb.iterations[i].tested;
        }
        if (conflicts == CollapseOptions::TwoPass) {
          EXPECT_LE(tested_a, tested_b);  // not tested again
        }
        all_tested_a += tested_a;
        all_tested_b += tested_b;
        EXPECT_GT(ra.iterations.size(), 2u);
        ++compared;
      }
  EXPECT_GE(compared, 12);  // the cube alone: 3 modes x 2 guards x 2 conflict detections
  EXPECT_LT(all_tested_a, all_tested_b);
}

// A second selection round per iteration (edges away from the first round's collapses): valid
// output, deterministic, and iteration 0 collapses at least as much as with one round.
TEST(CollapsePipeline, SecondSelectionRoundStaysValid) {
  Context ctx;
  Mesh in = test::cube_tets(6);
  CollapseOptions o;
  o.conflicts = CollapseOptions::TwoPass;  // rounds after the two passes
  o.target_factor = 2;
  Mesh one = in, two = in, again = in;
  CollapseReport r1 = collapse(one, o, ctx);
  o.selection_rounds = 2;
  CollapseReport r2 = collapse(two, o, ctx);
  collapse(again, o, ctx);
  ASSERT_FALSE(r1.iterations.empty());
  ASSERT_FALSE(r2.iterations.empty());
  EXPECT_GE(r2.iterations[0].collapsed, r1.iterations[0].collapsed);
  EXPECT_LT(r2.tets_out, r2.tets_in);
  CheckReport c = check(two, &in);
  EXPECT_TRUE(c.valid) << check_report_text(c);
  EXPECT_FALSE(c.reference.topology_changed);
  EXPECT_EQ(two.points, again.points);
  EXPECT_EQ(two.tets, again.tets);
  o.selection_rounds = 0;
  Mesh bad = in;
  EXPECT_THROW(collapse(bad, o, ctx), std::invalid_argument);
  o.selection_rounds = 2;
  o.conflicts = CollapseOptions::Greedy;
  EXPECT_THROW(collapse(bad, o, ctx), std::invalid_argument);
}

// The GPU code paths (Context::cpu_tuning false: kernels without prefetching, the volume test's
// short chunks, the rings built on the device, the primitives' local-memory scans and 4-bit
// sorts, launches without the CPU minimum of work-groups) give the CPU paths' result bit for
// bit, with every conflict detection and boundary mode, with and without a host tail. These are
// the paths a deployment on a GPU takes; PoCL runs them here.
TEST(CollapsePipeline, GpuTuningGivesTheCpuTuningsResult) {
  Context cpu, gpu;
  cpu.set_cpu_tuning(true);
  gpu.set_cpu_tuning(false);
  std::vector<std::pair<std::string, Mesh>> inputs;
  inputs.emplace_back("cube", cube_with_labels_and_fields(5));
  for (const char* name : {"polyfem_screw.msh", "gen_gmsh_wrenchnut_27k.msh"}) {
    const std::string path = test::shared_mesh(name);
    if (path.empty()) {
      std::printf("[ note ] %s absent: compared on the cube only\n", name);
      continue;
    }
    inputs.emplace_back(name, read_mesh(path));
  }
  int compared = 0, tails = 0;
  for (const auto& [name, in] : inputs)
    for (auto conflicts :
         {CollapseOptions::Matching, CollapseOptions::Greedy, CollapseOptions::TwoPass, CollapseOptions::AtomicMin})
      for (auto mode : {CollapseOptions::Features, CollapseOptions::Strict, CollapseOptions::Free})
        for (double tail : {-1.0, 0.0, 0.05}) {
          if (conflicts == CollapseOptions::AtomicMin && !cpu.info().int64_atomics_extended) continue;
          if (conflicts == CollapseOptions::AtomicMin && tail > 0) continue;  // no host tail with it
          // keeps it short: the shared meshes with the default selection
          if (name != "cube" && (mode != CollapseOptions::Features || tail < 0 || conflicts != CollapseOptions::Matching))
            continue;
          SCOPED_TRACE(name + " conflicts " + std::to_string(int(conflicts)) + " mode " + std::to_string(int(mode)) +
                       " host_tail " + std::to_string(tail));
          CollapseOptions o;
          o.conflicts = conflicts;
          o.boundary = mode;
          o.target_factor = 2;
          o.tuning.host_tail = tail;
          Mesh a = in, b = in;
          const CollapseReport ra = collapse(a, o, cpu), rb = collapse(b, o, gpu);
          if (tail < 0) {
            // automatic: a host tail on the CPU only (when the run has one), so only validity is compared
            EXPECT_EQ(test::count_on_host(rb), 0);
            EXPECT_TRUE(check(b, &in).valid);
            continue;
          }
          EXPECT_EQ(test::count_on_host(ra), test::count_on_host(rb));
          tails += test::count_on_host(ra) > 0 ? 1 : 0;
          test::expect_same_mesh(a, b);
          ASSERT_EQ(ra.iterations.size(), rb.iterations.size());
          for (size_t i = 0; i < ra.iterations.size(); ++i) {
            EXPECT_EQ(ra.iterations[i].tested, rb.iterations[i].tested) << "iteration " << i;
            EXPECT_EQ(ra.iterations[i].collapsed, rb.iterations[i].collapsed) << "iteration " << i;
          }
          EXPECT_LT(a.num_tets(), in.num_tets());
          ++compared;
        }
  // the cube: 3 modes x (3 conflict detections x 2 tails + atomic-min's one when the device has
  // the atomics); each shared mesh: 2 tails
  const int atomic = cpu.info().int64_atomics_extended ? 1 : 0;
  EXPECT_EQ(compared, 3 * (3 * 2 + atomic) + 2 * int(inputs.size() - 1));
  EXPECT_GT(tails, 0);      // the host tail ran on both
  // and at the work-group sizes of GPUs (a warp, a wavefront, a large group): the same again
  for (size_t wg : {32, 64, 256})
    for (auto conflicts : {CollapseOptions::Matching, CollapseOptions::TwoPass}) {
      SCOPED_TRACE("work-group size " + std::to_string(wg) + " conflicts " + std::to_string(int(conflicts)));
      CollapseOptions o;
      o.conflicts = conflicts;
      o.target_factor = 2;
      o.tuning.host_tail = 0;
      Mesh a = inputs[0].second, b = inputs[0].second;
      collapse(a, o, cpu);
      gpu.set_work_group_size(wg);
      collapse(b, o, gpu);
      gpu.set_work_group_size(0);
      test::expect_same_mesh(a, b);
    }
}
