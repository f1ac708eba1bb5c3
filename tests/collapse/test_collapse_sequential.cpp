// The sequential CPU method (tc::collapse_sequential, host/collapse/sequential*.{hpp,cpp}):
// its checks give the device's verdicts edge for edge (first iteration, and on the incremental
// state of later ones), its vertex classes stay those of a fresh classification, its results
// are valid, deterministic and carry the attributes; refusals; the CLI's --method sequential.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <random>
#include <set>
#include <stdexcept>
#include <tuple>

#include "collapse/sequential_mesh.hpp"
#include "collapse/sequential_run.hpp"
#include "collapse/stages.hpp"
#include "tetcollapse/check.hpp"
#include "tetcollapse/collapse.hpp"
#include "tetcollapse/error.hpp"
#include "tetcollapse/io.hpp"
#include "tetcollapse/topology.hpp"
#include "test_support.hpp"

using namespace tc;
using namespace tc::collapse_detail;
using namespace tc::sequential_detail;

namespace {

// What the device's stages say about every edge of a mesh in its first iteration.
struct DeviceVerdicts {
  std::vector<int32_t> edges;
  std::vector<uint32_t> marked;
  std::vector<uint8_t> reason, dir, vflags, vclass, eflags;
};

DeviceVerdicts device_verdicts(Context& ctx, const Mesh& m, const CollapseOptions& o, double target) {
  StageParams p = params_from(o);
  p.target = target;
  DeviceMesh dm;
  Connectivity c;
  EdgeState s;
  upload_mesh(ctx, m, o, dm);
  build_connectivity(ctx, dm, c, p);
  cost_and_mark(ctx, dm, c, s, p);
  admissible(ctx, dm, c, s, p);
  DeviceVerdicts d;
  d.edges = c.edges.download_range(0, 2 * size_t(c.ne));
  d.marked = s.cost.edges_are_marked.download_range(0, c.ne);
  d.reason = s.result.edges2reason.download_range(0, c.ne);
  d.dir = s.result.edges2dir.download_range(0, c.ne);
  d.vflags = c.vflags.download_range(0, dm.nv);
  d.vclass = c.vclass.download_range(0, dm.nv);
  d.eflags = c.eflags.download_range(0, c.ne);
  return d;
}

// Compares the sequential checks on `sm` (whose mesh arrays are `m`) with the device's on a
// fresh upload of m: flags, classes, edges, and the verdict (reason and direction) of every
// marked edge. Returns the number of marked edges compared.
int64_t expect_same_verdicts(Context& ctx, SeqMesh& sm, const Mesh& m, const CollapseOptions& o, double target,
                             const std::string& what) {
  const DeviceVerdicts d = device_verdicts(ctx, m, o, target);
  EXPECT_EQ(int64_t(sm.alive_vertices()), m.num_vertices()) << what;
  int64_t bad_flags = 0, bad_class = 0;
  for (int32_t v = 0; v < sm.num_vertices(); ++v) {
    bad_flags += sm.vflags(v) != d.vflags[v];
    bad_class += sm.vclass(v) != d.vclass[v];
  }
  EXPECT_EQ(bad_flags, 0) << what;
  EXPECT_EQ(bad_class, 0) << what;
  // the same edges
  std::vector<int32_t> nb;
  int64_t ne = 0;
  for (int32_t v = 0; v < sm.num_vertices(); ++v) {
    sm.neighbours(v, nb, true);
    ne += int64_t(nb.size());
  }
  EXPECT_EQ(ne, int64_t(d.marked.size())) << what;
  int64_t compared = 0, bad_eflags = 0, bad_reason = 0, bad_dir = 0;
  std::map<int, int64_t> reasons;
  for (size_t e = 0; e < d.marked.size(); ++e) {
    const int32_t a = d.edges[2 * e], b = d.edges[2 * e + 1];
    EXPECT_TRUE(sm.is_edge(a, b)) << what << ": edge " << a << " " << b;
    bad_eflags += sm.edge_flags(a, b) != d.eflags[e];
    if (!d.marked[e]) {
      EXPECT_EQ(d.reason[e], kNotMarked);
      continue;
    }
    const Verdict v = sm.check(a, b);
    uint8_t fe = 0;
    const int dir = sm.predicate(a, b, fe);
    if (dir >= 0) {  // the reordered test of the queue gives the same answer
      EXPECT_EQ(sm.admissible(a, b, fe, dir), v.reason == kOk) << what;
    }
    ++compared;
    ++reasons[v.reason];
    if (v.reason != d.reason[e]) {
      if (bad_reason < 5)
        ADD_FAILURE() << what << ": edge (" << a << ", " << b << ") sequential reason " << int(v.reason)
                      << ", device " << int(d.reason[e]);
      ++bad_reason;
    } else if (v.reason == kOk && v.dir != d.dir[e]) {
      ++bad_dir;
    }
  }
  EXPECT_EQ(bad_eflags, 0) << what;
  EXPECT_EQ(bad_reason, 0) << what;
  EXPECT_EQ(bad_dir, 0) << what;
  return compared;
}

int64_t expect_same_verdicts_fresh(Context& ctx, const Mesh& in, const CollapseOptions& o, double factor,
                                   const std::string& what) {
  Mesh m = in;
  SeqMesh sm(m, seq_params_from(o));
  return expect_same_verdicts(ctx, sm, m, o, factor * median_edge_length(in), what);
}

// cube_tets(n) with two materials (x < 0.5 and x > 0.5): an interface inside.
Mesh two_material_cube(int n) {
  Mesh m = test::cube_tets(n);
  Labels l{"material", {}};
  for (int64_t t = 0; t < m.num_tets(); ++t) {
    double x = 0;
    for (int k = 0; k < 4; ++k) x += m.points[3 * m.tets[4 * t + k]];
    l.values.push_back(x / 4 < 0.5 ? 1 : 2);
  }
  m.tet_labels.push_back(l);
  return m;
}

CheckReport check(const Mesh& m, const Mesh& ref, bool hausdorff = false) {
  CheckOptions o;
  o.quality = false;
  o.hausdorff = hausdorff;
  return check_mesh(m, o, &ref);
}

std::set<std::tuple<double, double, double>> boundary_points(const Mesh& m) {
  Topology t = build_topology(m);
  std::set<std::tuple<double, double, double>> s;
  for (int32_t v = 0; v < t.num_vertices; ++v)
    if (t.vertex_boundary[v]) s.insert({m.points[3 * v], m.points[3 * v + 1], m.points[3 * v + 2]});
  return s;
}

// Runs the sequential method and checks the result against the input as the CLI's --check does.
CollapseReport expect_valid_run(const Mesh& in, Mesh& m, const CollapseOptions& o, const std::string& what) {
  m = in;
  CollapseReport r = collapse_sequential(m, o);
  EXPECT_EQ(r.tets_out, m.num_tets()) << what;
  EXPECT_LT(r.tets_out, r.tets_in) << what << ": nothing collapsed";
  const bool strict = o.boundary == CollapseOptions::Strict;
  CheckReport c = check(m, in, strict);
  EXPECT_TRUE(c.valid) << what << "\n" << check_report_text(c);
  EXPECT_FALSE(c.reference.topology_changed) << what;
  if (strict) {
    EXPECT_TRUE(c.reference.hausdorff_computed) << what;
    EXPECT_EQ(c.reference.hausdorff, 0.0) << what;
  }
  // the report adds up
  int64_t collapsed = 0;
  for (const IterationStats& s : r.iterations) {
    EXPECT_LE(s.candidates, s.marked);
    EXPECT_LE(s.tested, s.candidates);
    EXPECT_LE(s.selected, s.tested);
    EXPECT_LE(s.collapsed, s.selected);
    EXPECT_EQ(s.vertices - s.vertices_after, s.collapsed);
    collapsed += s.collapsed;
  }
  EXPECT_EQ(r.vertices_in - r.vertices_out, collapsed) << what;
  EXPECT_EQ(r.device, "cpu-sequential");
  if (!r.iterations.empty() && int(r.iterations.size()) < o.max_iterations) {
    EXPECT_LT(r.iterations.back().collapsed, std::max<int64_t>(o.eps_c, 1)) << what;
  }
  return r;
}

Mesh read_shared(const std::string& name) {
  const std::string path = test::shared_mesh(name);
  return path.empty() ? Mesh{} : read_mesh(path);
}

// Skips the test (with the names) unless every one of the shared meshes is present.
#define SKIP_UNLESS_SHARED(...)                                                                        \
  do {                                                                                               \
    TC_SKIP_IF_NO_SHARED();                                                                          \
    for (const char* n : {__VA_ARGS__})                                                              \
      if (test::shared_mesh(n).empty()) GTEST_SKIP() << "shared mesh " << n << " is absent; skipped"; \
  } while (0)

}  // namespace

// --- the checks: the same verdicts as the device ---

TEST(SequentialVerdicts, SameAsDeviceOnCubesInEveryMode) {
  Context ctx;
  for (const Mesh& in : {test::cube_tets(4), two_material_cube(4)}) {
    for (auto mode : {CollapseOptions::Features, CollapseOptions::Strict, CollapseOptions::Free})
      for (bool paper : {false, true})
        for (double qmin : {0.0, 0.1}) {
          CollapseOptions o;
          o.boundary = mode;
          o.paper_boundary_rule = paper;
          o.min_quality = qmin;
          const std::string what = "cube labels " + std::to_string(in.tet_labels.size()) + " mode " +
                                   std::to_string(int(mode)) + " paper " + std::to_string(paper) + " qmin " +
                                   std::to_string(qmin);
          EXPECT_GT(expect_same_verdicts_fresh(ctx, in, o, 2.0, what), 100) << what;
        }
  }
}

TEST(SequentialVerdicts, SameAsDeviceOnBracketAndSharedMeshes) {
  Context ctx;
  CollapseOptions o;  // features, quality guard 0.1
  Mesh bracket = read_mesh(test::project_mesh("bracket.msh"));
  EXPECT_GT(expect_same_verdicts_fresh(ctx, bracket, o, 2.0, "bracket"), 1000);
  CollapseOptions paper0 = o;
  paper0.min_quality = 0;
  paper0.paper_boundary_rule = true;
  expect_same_verdicts_fresh(ctx, bracket, paper0, 1.0, "bracket paper rule, no guard");
  SKIP_UNLESS_SHARED("polyfem_bimetal.msh", "sfepy_multi_material_cylinder_plate.vtk", "gen_gmsh_Angled_43k.msh",
                     "polyfem_mat100x100t40.msh");
  // interfaces (2 and 4 materials), ridges and corners of a CAD part, a sheet one tet thick
  for (const char* name : {"polyfem_bimetal.msh", "sfepy_multi_material_cylinder_plate.vtk", "gen_gmsh_Angled_43k.msh",
                           "polyfem_mat100x100t40.msh"}) {
    Mesh m = read_shared(name);
    ASSERT_GT(m.num_tets(), 0) << name << " is missing from the shared meshes";
    EXPECT_GT(expect_same_verdicts_fresh(ctx, m, o, 2.0, name), 1000) << name;
    CollapseOptions free = o;
    free.boundary = CollapseOptions::Free;
    free.min_quality = 0;
    expect_same_verdicts_fresh(ctx, m, free, 1.0, std::string(name) + " free");
  }
}

// With the volume test out of the way (eps_v = -infinity: no tet is too small), every marked
// edge that passes Q reaches the link condition, whose refusals the volume test otherwise hides
// (it runs first): the device's link test and the host's (SeqMesh::link_ok), one test
// (cl/collapse_checks.h) over two stars, each with its own gathering of the common neighbours,
// must refuse the same edges, and refuse many.
TEST(SequentialVerdicts, LinkConditionAloneAgreesWithTheDevice) {
  Context ctx;
  std::vector<std::pair<std::string, Mesh>> meshes;
  meshes.push_back({"cube", test::cube_tets(4)});
  meshes.push_back({"two-material cube", two_material_cube(4)});
  meshes.push_back({"bracket", read_mesh(test::project_mesh("bracket.msh"))});
  // closed by cones: the checks with the virtual vertex become checks with a real one
  meshes.push_back({"coned cube", test::cone_boundary(test::cube_tets(3), 0.5, 0.5, 2.0)});
  meshes.push_back({"coned slab", test::cone_boundary(test::slab(5), 0.5, 0.5, 2.0)});
  meshes.push_back({"coned bracket", test::cone_boundary(meshes[2].second, 0.0, 0.0, 0.0)});
  for (auto& [name, in] : meshes) {
    int64_t link = 0, ok = 0;
    for (auto mode : {CollapseOptions::Features, CollapseOptions::Free}) {
      CollapseOptions o;
      o.boundary = mode;  // features: boundary edges too, with S; free: every edge
      o.min_quality = 0;
      o.eps_v = -INFINITY;
      const std::string what = name + " mode " + std::to_string(int(mode)) + " without the volume test";
      const DeviceVerdicts d = device_verdicts(ctx, in, o, 2.0 * median_edge_length(in));
      link += std::count(d.reason.begin(), d.reason.end(), uint8_t(kRefusedLink));
      ok += std::count(d.reason.begin(), d.reason.end(), uint8_t(kOk));
      EXPECT_EQ(std::count(d.reason.begin(), d.reason.end(), uint8_t(kRefusedVolume)), 0) << what;
      EXPECT_GT(expect_same_verdicts_fresh(ctx, in, o, 2.0, what), 100) << what;
    }
    EXPECT_GT(link, 10) << name;  // the link condition is what refuses here
    EXPECT_GT(ok, 10) << name;
  }
}

// cube_tets(3) without about 30% of its tets, chosen by a fixed generator from seed: notches,
// tunnels, tets joined at an edge or a vertex only (a non-manifold boundary); every kind of
// link configuration, many of which no mesher would produce.
Mesh cube_with_holes(uint32_t seed) {
  uint32_t r = seed * 2654435761u;
  return test::sub_mesh(test::cube_tets(3), [&](int64_t) {
    r = r * 1664525u + 1013904223u;
    return (r >> 24) >= 77;
  });
}

// The device's link test and the host's agree edge by edge on odd configurations too: cubes with
// tets taken away, as they are and closed by a cone (test::cone_boundary: the checks with the
// virtual vertex become checks with a real one), without the volume test. Each part of the
// device's test that could be dropped (check (i), the pairs of a tet of ring(a) with exactly two
// common neighbours) changes some verdict here.
TEST(SequentialVerdicts, LinkConditionAgreesOnCubesWithTetsTakenAway) {
  Context ctx;
  int64_t link = 0, ok = 0;
  for (uint32_t seed = 1; seed <= 6; ++seed)
    for (int coned = 0; coned < 2; ++coned) {
      const Mesh holes = cube_with_holes(seed);
      const Mesh in = coned ? test::cone_boundary(holes, 0.5, 0.5, 3.0) : holes;
      for (auto mode : {CollapseOptions::Features, CollapseOptions::Free}) {
        CollapseOptions o;
        o.boundary = mode;
        o.min_quality = 0;
        o.eps_v = -INFINITY;
        const std::string what =
            "seed " + std::to_string(seed) + (coned ? " coned" : "") + " mode " + std::to_string(int(mode));
        const DeviceVerdicts d = device_verdicts(ctx, in, o, 2.0 * median_edge_length(in));
        link += std::count(d.reason.begin(), d.reason.end(), uint8_t(kRefusedLink));
        ok += std::count(d.reason.begin(), d.reason.end(), uint8_t(kOk));
        EXPECT_GT(expect_same_verdicts_fresh(ctx, in, o, 2.0, what), 20) << what;
      }
    }
  EXPECT_GT(link, 100);
  EXPECT_GT(ok, 100);
}

// The link test's lists have a cap (TCC_MAX_LINK, 96 by default): an edge with more common
// neighbours or more tets around it is refused, conservatively. Built with a cap of 6, which many
// of the bracket's edges reach exactly, the device must agree with the host on every edge within
// the cap (the lists are filled up to it, then stop) and may only refuse the others.
TEST(SequentialVerdicts, LinkListCapOnlyRefusesLargerLists) {
  constexpr size_t kCap = 6;
  test::EnvVar cap("TETCOLLAPSE_CL_OPTIONS", "-DTCC_MAX_LINK=" + std::to_string(kCap));
  Context ctx;  // builds its programs with the cap
  const Mesh bracket = read_mesh(test::project_mesh("bracket.msh"));
  CollapseOptions o;
  o.boundary = CollapseOptions::Free;  // every edge goes through the link test
  o.min_quality = 0;
  o.eps_v = -INFINITY;
  const DeviceVerdicts d = device_verdicts(ctx, bracket, o, 2.0 * median_edge_length(bracket));
  std::map<std::pair<int32_t, int32_t>, size_t> tets_of_edge;
  for (size_t t = 0; t < bracket.tets.size(); t += 4)
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) {
        int32_t x = bracket.tets[t + i], y = bracket.tets[t + j];
        ++tets_of_edge[{std::min(x, y), std::max(x, y)}];
      }
  Mesh m = bracket;
  SeqMesh sm(m, seq_params_from(o));
  int64_t within = 0, at_cap = 0, beyond = 0, bad = 0;
  std::vector<int32_t> na, nb, common;
  for (size_t e = 0; e < d.marked.size(); ++e) {
    if (!d.marked[e]) continue;
    const int32_t a = d.edges[2 * e], b = d.edges[2 * e + 1];
    sm.neighbours(a, na);
    sm.neighbours(b, nb);
    std::sort(na.begin(), na.end());
    std::sort(nb.begin(), nb.end());
    common.clear();
    std::set_intersection(na.begin(), na.end(), nb.begin(), nb.end(), std::back_inserter(common));
    const size_t ncn = common.size(), np = tets_of_edge[{std::min(a, b), std::max(a, b)}];
    const uint8_t host = sm.check(a, b).reason;
    if (ncn <= kCap && np <= kCap) {
      ++within;
      at_cap += ncn == kCap || np == kCap;
      if (d.reason[e] != host && bad++ < 5)
        ADD_FAILURE() << "edge (" << a << ", " << b << "), " << ncn << " common neighbours, " << np
                      << " tets: host reason " << int(host) << ", device " << int(d.reason[e]);
    } else {
      ++beyond;
      EXPECT_EQ(d.reason[e], uint8_t(kRefusedLink)) << "edge beyond the cap not refused: " << a << " " << b;
    }
  }
  EXPECT_EQ(bad, 0);
  EXPECT_GT(at_cap, 100) << "the cap is not reached often enough to test it";
  EXPECT_GT(within, 1000);
  EXPECT_GT(beyond, 100);
}

TEST(SequentialVerdicts, IncrementalStateAgreesWithTheDeviceInLaterIterations) {
  // After each sequential iteration the classes and rings of the dynamic mesh were updated
  // collapse by collapse; the device builds them from scratch on the same mesh.
  Context ctx;
  std::vector<std::pair<std::string, Mesh>> meshes;
  meshes.push_back({"two-material cube", two_material_cube(6)});
  meshes.push_back({"bracket", read_mesh(test::project_mesh("bracket.msh"))});
  for (const char* name : {"polyfem_bimetal.msh", "gen_gmsh_Angled_43k.msh"})  // when present
    if (!test::shared_mesh(name).empty()) meshes.push_back({name, read_shared(name)});
  for (auto& [name, in] : meshes) {
    ASSERT_GT(in.num_tets(), 0) << name;
    Mesh m = in;
    CollapseOptions o;
    o.target_factor = 2;
    SequentialRun run(m, o);
    for (int it = 0; it < 3 && run.step(); ++it) {
      const std::string what = name + " after iteration " + std::to_string(it + 1);
      EXPECT_EQ(run.seq().verify_classes(), 0) << what;
      EXPECT_EQ(run.seq().verify_nbr(), 0) << what;
      EXPECT_EQ(run.seq().verify_guard(), 0) << what;
      expect_same_verdicts(ctx, run.seq(), m, o, run.target(), what);
    }
  }
}

TEST(SequentialVerdicts, ClassesStayThoseOfAFreshClassification) {
  // build_topology (the CPU reference of the classification) on the mesh after every iteration
  std::vector<std::pair<std::string, Mesh>> meshes;
  meshes.push_back({"two-material cube", two_material_cube(5)});
  meshes.push_back({"bracket", read_mesh(test::project_mesh("bracket.msh"))});
  if (!test::shared_mesh("sfepy_multi_material_cylinder_plate.vtk").empty())  // when present
    meshes.push_back({"cylinder plate", read_shared("sfepy_multi_material_cylinder_plate.vtk")});
  for (auto& [name, in] : meshes) {
    ASSERT_GT(in.num_tets(), 0) << name;
    Mesh m = in;
    CollapseOptions o;
    o.target_factor = 2;
    o.min_quality = 0;
    SequentialRun run(m, o);
    int steps = 0;
    while (run.step()) {
      ++steps;
      Topology t = build_topology(m);
      int64_t bad = 0;
      for (int32_t v = 0; v < t.num_vertices; ++v)
        bad += run.seq().vclass(v) != t.vertex_class[v] || run.seq().vflags(v) != t.vertex_boundary[v];
      EXPECT_EQ(bad, 0) << name << " after iteration " << steps;
      EXPECT_EQ(run.seq().verify_classes(), 0) << name << " after iteration " << steps;
      EXPECT_EQ(run.seq().verify_nbr(), 0) << name << " after iteration " << steps;
      EXPECT_EQ(run.seq().verify_guard(), 0) << name << " after iteration " << steps;
    }
    EXPECT_GT(steps, 1) << name;
  }
}

// The tet neighbours SeqMesh keeps through its collapses (the faces glued across each removed
// tet) equal a ring scan's after every single collapse, not only after a compaction; and the
// classes stay right too. Two materials (interface faces) and the bracket (boundary).
TEST(SequentialVerdicts, NeighboursStayThoseOfARingScanAfterEveryCollapse) {
  std::vector<std::pair<std::string, Mesh>> meshes;
  meshes.push_back({"two-material cube", two_material_cube(4)});
  meshes.push_back({"bracket", read_mesh(test::project_mesh("bracket.msh"))});
  for (auto& [name, in] : meshes) {
    Mesh m = in;
    CollapseOptions o;
    o.min_quality = 0;
    SeqMesh sm(m, seq_params_from(o));
    ASSERT_EQ(sm.verify_nbr(), 0) << name;
    std::vector<int32_t> nb;
    int collapses = 0;
    for (int32_t a = 0; a < sm.num_vertices() && collapses < 60; ++a) {
      if (!sm.alive(a)) continue;
      sm.neighbours(a, nb, true);
      for (int32_t b : nb) {
        if (!sm.alive(a) || !sm.alive(b)) break;
        const Verdict v = sm.check(a, b);
        if (v.reason != kOk) continue;
        sm.collapse(a, b, v.dir);
        ++collapses;
        ASSERT_EQ(sm.verify_nbr(), 0) << name << " after collapse " << collapses;
        ASSERT_EQ(sm.verify_classes(), 0) << name << " after collapse " << collapses;
        break;
      }
    }
    EXPECT_GE(collapses, 30) << name;
  }
}

// --- results ---

TEST(SequentialCollapse, CubesStayValidInEveryMode) {
  for (auto mode : {CollapseOptions::Features, CollapseOptions::Strict, CollapseOptions::Free}) {
    Mesh in = two_material_cube(6), m;
    CollapseOptions o;
    o.target_factor = 2;
    o.boundary = mode;
    expect_valid_run(in, m, o, "cube mode " + std::to_string(int(mode)));
    if (mode == CollapseOptions::Free) continue;
    // the 8 corners never move, and every boundary vertex stays on the cube's surface
    auto b = boundary_points(m);
    for (int i = 0; i < 8; ++i)
      EXPECT_TRUE(b.count({double(i & 1), double((i >> 1) & 1), double((i >> 2) & 1)})) << "corner " << i;
    for (auto [x, y, z] : b) EXPECT_TRUE(x == 0 || x == 1 || y == 0 || y == 1 || z == 0 || z == 1 || x == 0.5);
    if (mode == CollapseOptions::Strict) {
      EXPECT_EQ(b, boundary_points(in));
    }
  }
}

// The paper's reading of its baseline (--sequential-skip-invalidated): an edge an earlier
// collapse of the iteration changed waits for the next iteration instead of being re-checked.
// Still valid; fewer collapses in the first iteration, so at least as many iterations.
TEST(SequentialCollapse, SkippingInvalidatedEdgesStaysValidAndNeedsMoreIterations) {
  const Mesh in = read_mesh(test::project_mesh("bracket.msh"));
  Mesh m1, m2;
  CollapseOptions o;
  o.min_quality = 0;
  const CollapseReport recheck = expect_valid_run(in, m1, o, "bracket re-check");
  o.sequential_skip_invalidated = true;
  const CollapseReport skip = expect_valid_run(in, m2, o, "bracket skip");
  ASSERT_FALSE(recheck.iterations.empty());
  ASSERT_FALSE(skip.iterations.empty());
  EXPECT_LT(skip.iterations[0].collapsed, recheck.iterations[0].collapsed);
  EXPECT_GT(skip.iterations.size(), recheck.iterations.size());
}

TEST(SequentialCollapse, BracketAndSharedMeshesStayValid) {
  Mesh m;
  CollapseOptions o;
  o.target_factor = 2;
  expect_valid_run(read_mesh(test::project_mesh("bracket.msh")), m, o, "bracket features");
  CollapseOptions strict = o;
  strict.boundary = CollapseOptions::Strict;
  expect_valid_run(read_mesh(test::project_mesh("bracket.msh")), m, strict, "bracket strict");
  SKIP_UNLESS_SHARED("polyfem_bimetal.msh", "ipc_hammer.msh", "gen_gmsh_Angled_43k.msh", "polyfem_cubes_v41.msh");
  for (const char* name : {"polyfem_bimetal.msh", "ipc_hammer.msh", "gen_gmsh_Angled_43k.msh"}) {
    Mesh in = read_shared(name);
    ASSERT_GT(in.num_tets(), 0) << name;
    expect_valid_run(in, m, o, name);
  }
  // the paper's setting: no quality guard, paper boundary rule
  Mesh in = read_shared("polyfem_cubes_v41.msh");
  ASSERT_GT(in.num_tets(), 0);
  CollapseOptions paper = o;
  paper.min_quality = 0;
  paper.paper_boundary_rule = true;
  expect_valid_run(in, m, paper, "cubes_v41 paper rule");
}

TEST(SequentialCollapse, DeterministicAndTheSameWithoutReuse) {
  Mesh in = read_mesh(test::project_mesh("bracket.msh"));
  CollapseOptions o;
  o.target_factor = 2;
  Mesh a = in, b = in, c = in;
  CollapseReport ra = collapse_sequential(a, o);
  CollapseReport rb = collapse_sequential(b, o);
  o.tuning.reuse_across_iterations = false;  // every marked edge tested, every popped edge checked again
  CollapseReport rc = collapse_sequential(c, o);
  EXPECT_EQ(a.points, b.points);
  EXPECT_EQ(a.tets, b.tets);
  EXPECT_EQ(a.points, c.points);
  EXPECT_EQ(a.tets, c.tets);
  ASSERT_EQ(ra.iterations.size(), rc.iterations.size());
  for (size_t i = 0; i < ra.iterations.size(); ++i) {
    EXPECT_EQ(ra.iterations[i].collapsed, rc.iterations[i].collapsed);
    EXPECT_EQ(ra.iterations[i].selected, rc.iterations[i].selected);
    EXPECT_LE(ra.iterations[i].tested, rc.iterations[i].tested);
  }
  // tc::collapse dispatches to the same method
  Context ctx;
  Mesh d = in;
  o.tuning.reuse_across_iterations = true;
  o.method = CollapseOptions::Sequential;
  CollapseReport rd = collapse(d, o, ctx);
  EXPECT_EQ(rd.device, "cpu-sequential");
  EXPECT_EQ(a.tets, d.tets);
}

TEST(SequentialCollapse, AttributesTravel) {
  Mesh in = two_material_cube(5);
  Field tf{"tq", 1, {}}, vf{"lin", 1, {}};
  for (int64_t t = 0; t < in.num_tets(); ++t) tf.values.push_back(double(in.tet_labels[0].values[t]) * 10);
  for (int64_t v = 0; v < in.num_vertices(); ++v)
    vf.values.push_back(in.points[3 * v] + 2 * in.points[3 * v + 1] + 4 * in.points[3 * v + 2]);
  in.tet_fields.push_back(tf);
  in.vertex_fields.push_back(vf);
  // the boundary triangles of the input, tagged by their index
  Topology topo = build_topology(in);
  for (int32_t f = 0; f < topo.num_sfaces(); ++f) {
    if (topo.sface_interface[f]) continue;
    in.tris.insert(in.tris.end(), &topo.sfaces[3 * f], &topo.sfaces[3 * f] + 3);
    in.tri_tags.push_back(f);
  }
  CollapseOptions o;
  o.target_factor = 2;
  for (auto mode : {CollapseOptions::Features, CollapseOptions::Free}) {
    o.boundary = mode;
    Mesh m;
    expect_valid_run(in, m, o, "attributes");
    ASSERT_EQ(m.tet_labels[0].values.size(), size_t(m.num_tets()));
    ASSERT_EQ(m.tet_fields[0].values.size(), size_t(m.num_tets()));
    ASSERT_EQ(m.vertex_fields[0].values.size(), size_t(m.num_vertices()));
    for (int64_t t = 0; t < m.num_tets(); ++t)  // a tet keeps its label and field together
      EXPECT_EQ(m.tet_fields[0].values[t], 10.0 * m.tet_labels[0].values[t]);
    // a linear field averaged at midpoints and kept at kept positions stays the same linear field
    for (int64_t v = 0; v < m.num_vertices(); ++v)
      EXPECT_NEAR(m.vertex_fields[0].values[v], m.points[3 * v] + 2 * m.points[3 * v + 1] + 4 * m.points[3 * v + 2],
                  1e-12);
    // triangles remapped: valid indices, no degenerate ones, tags alongside
    EXPECT_EQ(m.tris.size(), 3 * m.tri_tags.size());
    EXPECT_LT(m.tris.size(), in.tris.size());
    for (size_t i = 0; i < m.tris.size(); i += 3) {
      for (int k = 0; k < 3; ++k) ASSERT_LT(m.tris[i + k], m.num_vertices());
      EXPECT_TRUE(m.tris[i] != m.tris[i + 1] && m.tris[i] != m.tris[i + 2] && m.tris[i + 1] != m.tris[i + 2]);
    }
    if (mode == CollapseOptions::Features) {
      // S is kept: every remapped boundary triangle is a boundary face of the result
      Topology t = build_topology(m);
      std::set<std::array<int32_t, 3>> faces;
      for (int32_t f = 0; f < t.num_sfaces(); ++f) {
        std::array<int32_t, 3> k{t.sfaces[3 * f], t.sfaces[3 * f + 1], t.sfaces[3 * f + 2]};
        std::sort(k.begin(), k.end());
        faces.insert(k);
      }
      for (size_t i = 0; i < m.tris.size(); i += 3) {
        std::array<int32_t, 3> k{m.tris[i], m.tris[i + 1], m.tris[i + 2]};
        std::sort(k.begin(), k.end());
        EXPECT_TRUE(faces.count(k)) << "triangle " << i / 3;
      }
    }
  }
}

TEST(SequentialCollapse, MaskKeepsUnselectedVertices) {
  Mesh in = test::cube_tets(6);
  CollapseOptions o;
  o.target_factor = 2;
  std::set<test::Point3> outside;
  o.vertex_mask = test::mask_x_below(in, 0.5, &outside);
  Mesh m;
  expect_valid_run(in, m, o, "mask");
  const std::set<test::Point3> out = test::vertex_positions(m);
  for (const auto& p : outside) EXPECT_TRUE(out.count(p)) << "an unselected vertex moved or went away";
}

TEST(SequentialCollapse, StopRuleAndIterationLimit) {
  Mesh in = read_mesh(test::project_mesh("bracket.msh"));
  CollapseOptions o;
  o.target_factor = 2;
  o.eps_c = 100;
  Mesh m;
  CollapseReport r = expect_valid_run(in, m, o, "eps_c 100");
  ASSERT_FALSE(r.iterations.empty());
  for (size_t i = 0; i + 1 < r.iterations.size(); ++i) EXPECT_GE(r.iterations[i].collapsed, 100);
  EXPECT_LT(r.iterations.back().collapsed, 100);
  o.eps_c = 0;
  o.max_iterations = 1;
  m = in;
  EXPECT_EQ(collapse_sequential(m, o).iterations.size(), 1u);
  o.max_iterations = 0;
  m = in;
  CollapseReport r0 = collapse_sequential(m, o);
  EXPECT_TRUE(r0.iterations.empty());
  EXPECT_EQ(m.tets, in.tets);
}

// --- the surface guard (as tests/collapse/test_collapse_regressions.cpp for the device) ---

namespace {

void add_tet(Mesh& m, int a, int b, int c, int d) {
  auto p = [&](int i) { return geo::tc_point(m.points.data(), i); };
  if (geo::tc_orient3d(p(a), p(b), p(c), p(d)) < 0) std::swap(b, c);
  m.tets.insert(m.tets.end(), {a, b, c, d});
}

// Four tets under a square whose top is a shallow dimple (v4, a face vertex: its only collapses
// flatten the top to z = 0), and optionally a tet standing on its tip in the dimple's void,
// below z = 0: flattening would push the top through it.
Mesh dimple_and_tip(bool with_b, double lift = 0) {
  Mesh m;
  m.points = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0, 0, 0, -0.05, 0, 0, -1};
  for (int i = 0; i < 4; ++i) add_tet(m, 4, i, (i + 1) % 4, 5);
  if (with_b) {
    m.points.insert(m.points.end(), {0.2, 0.1, -0.02 + lift, 0.7, 0.1, 0.5 + lift, -0.1, 0.6, 0.5 + lift, -0.1, -0.4,
                                     0.5 + lift});
    add_tet(m, 6, 7, 8, 9);
  }
  return m;
}

// cube_tets(n) moved to x in [5, 6], then dimple_and_tip(true) with its vertices from *first on:
// collapses in the cube renumber the dimple's vertices and tets.
Mesh cube_then_dimple(int n, int32_t* first) {
  Mesh m = test::cube_tets(n);
  for (size_t i = 0; i < m.points.size(); i += 3) m.points[i] += 5.0;
  const Mesh d = dimple_and_tip(true);
  *first = int32_t(m.num_vertices());
  m.points.insert(m.points.end(), d.points.begin(), d.points.end());
  for (int32_t v : d.tets) m.tets.push_back(*first + v);
  return m;
}

}  // namespace

TEST(SequentialGuard, FlatteningDoesNotPushTheSurfaceIntoAnotherBody) {
  CollapseOptions o;
  o.target_length = 10;  // every edge is marked
  for (double q : {0.1, 0.0}) {
    o.min_quality = q;
    // alone, the dimple is flattened; with the tip in its void it is not; with the tip lifted
    // clear of z = 0 it is again
    for (int c = 0; c < 3; ++c) {
      const Mesh in = c == 0 ? dimple_and_tip(false) : dimple_and_tip(true, c == 2 ? 0.03 : 0.0);
      ASSERT_TRUE(check(in, in).valid);
      Mesh out = in;
      collapse_sequential(out, o);
      EXPECT_EQ(out.num_vertices(), in.num_vertices() - (c == 1 ? 0 : 1)) << "case " << c << " qmin " << q;
      CheckReport r = check(out, in);
      EXPECT_TRUE(r.valid) << "case " << c << "\n" << check_report_text(r);
    }
  }
  // the guard is what refuses it: the local checks admit the collapse
  Mesh in = dimple_and_tip(true);
  SeqMesh sm(in, seq_params_from(o));
  std::vector<std::pair<int32_t, uint8_t>> admitted;
  for (int32_t c = 0; c < 4; ++c) {
    const Verdict v = sm.check(c, 4);
    if (v.reason != kOk) continue;
    admitted.push_back({c, v.dir});
    EXPECT_TRUE(sm.guard_ok(c, 4, v.dir)) << "no guard yet";
  }
  EXPECT_FALSE(admitted.empty());
  sm.build_guard(0.1);
  for (auto [c, dir] : admitted) EXPECT_FALSE(sm.guard_ok(c, 4, dir)) << "corner " << c;
}

// The guard's grid has at most max(2^16, 8 x the S faces) cells: with a small tet far away
// (cells of the faces' mean extent would number ~10^9), its cells grow, and it still refuses.
TEST(SequentialGuard, RefusesWithTheGridCoarsened) {
  CollapseOptions o;
  o.target_length = 10;
  o.min_quality = 0;
  for (bool far : {false, true}) {
    Mesh in = dimple_and_tip(true);
    if (far) {
      const int32_t base = int32_t(in.num_vertices());
      in.points.insert(in.points.end(), {1000, 1000, 1000, 1001, 1000, 1000, 1000, 1001, 1000, 1000, 1000, 1001});
      add_tet(in, base, base + 1, base + 2, base + 3);
    }
    SeqMesh sm(in, seq_params_from(o));
    sm.build_guard(0.1);
    int refused = 0;
    for (int32_t c = 0; c < 4; ++c) {
      const Verdict v = sm.check(c, 4);
      if (v.reason == kOk) refused += !sm.guard_ok(c, 4, v.dir);
    }
    EXPECT_GE(refused, 1) << (far ? "with" : "without") << " the far tet";
    Mesh out = in;
    collapse_sequential(out, o);
    EXPECT_TRUE(check(out, in).valid) << (far ? "with" : "without") << " the far tet";
  }
}

// compact() renumbers the guard's grid instead of building it again (when few collapses came
// since it was built): after one collapse elsewhere, the dimple's collapses are still refused.
TEST(SequentialGuard, RefusesAfterACompaction) {
  CollapseOptions o;
  o.target_length = 10;
  o.min_quality = 0;
  int32_t first = 0;
  Mesh m = cube_then_dimple(4, &first);
  const int64_t nt = m.num_tets();
  SeqMesh sm(m, seq_params_from(o));
  sm.build_guard(0.1);
  std::vector<int32_t> nb, vmap, kept;
  bool collapsed = false;
  for (int32_t a = 0; a < first && !collapsed; ++a) {  // one collapse in the cube
    sm.neighbours(a, nb, true);
    for (int32_t b : nb) {
      const Verdict v = sm.check(a, b);
      if (v.reason != kOk || !sm.guard_ok(a, b, v.dir)) continue;
      sm.collapse(a, b, v.dir);
      collapsed = true;
      break;
    }
  }
  ASSERT_TRUE(collapsed) << "no collapse in the cube";
  EXPECT_EQ(sm.verify_guard(), 0) << "after the collapse";
  sm.compact(vmap, kept);
  EXPECT_EQ(sm.verify_guard(), 0) << "after the compaction";
  // the dimple's vertices and tets (the last five) moved down
  ASSERT_EQ(vmap[size_t(first)], first - 1);
  ASSERT_LT(m.num_tets(), nt);
  const int32_t centre = vmap[size_t(first) + 4];
  int admitted = 0;
  for (int32_t c = 0; c < 4; ++c) {
    const int32_t corner = vmap[size_t(first + c)];
    const Verdict v = sm.check(corner, centre);
    if (v.reason != kOk) continue;
    ++admitted;
    EXPECT_FALSE(sm.guard_ok(corner, centre, v.dir)) << "corner " << c;
  }
  EXPECT_GE(admitted, 1);
}

// The guard's grid drops stale entries as it meets them and passes over entries by their boxes
// (SeqMesh::any_live_guard_face): its verdicts must be those of a scan of every face of every
// live tet, after collapses and after compactions that renumber the grid. Greedy passes over the
// vertices, each verdict compared (up to a count), the grid checked every 50 collapses and after
// each pass; the dimple's collapses are refused, so both verdicts are compared.
TEST(SequentialGuard, GridVerdictsAreThoseOfAScanOfEveryFace) {
  int32_t first = 0;
  std::vector<std::tuple<std::string, Mesh, double>> inputs;
  inputs.emplace_back("dimple and tip beside a cube", cube_then_dimple(4, &first), 10.0);
  inputs.emplace_back("bracket", read_mesh(test::project_mesh("bracket.msh")), 0.0);
  const std::string wrench = test::shared_mesh("gen_gmsh_wrenchnut_27k.msh");
  if (!wrench.empty()) inputs.emplace_back("wrenchnut 27k", read_mesh(wrench), 0.0);
  else std::printf("wrenchnut 27k absent: the dimple and the bracket alone\n");
  int64_t refused = 0;
  for (auto& [name, in, target] : inputs) {
    SCOPED_TRACE(name);
    Mesh m = in;
    CollapseOptions o;
    o.min_quality = 0;
    SeqMesh sm(m, seq_params_from(o));
    const double limit = target > 0 ? target : 3 * median_edge_length(in);
    sm.build_guard(limit);
    std::vector<int32_t> nb, vmap, kept;
    int64_t compared = 0, collapses = 0;
    const int64_t most = m.num_tets() > 2000 ? 100 : 1500;  // each scan is long
    for (int pass = 0; pass < 3 && compared < most; ++pass) {
      for (int32_t a = 0; a < sm.num_vertices() && compared < most; ++a) {
        if (!sm.alive(a)) continue;
        sm.neighbours(a, nb, true);
        for (int32_t b : nb) {
          if (!sm.alive(a) || !sm.alive(b)) break;
          if (!(sm.length(a, b) < limit)) continue;
          const Verdict v = sm.check(a, b);
          if (v.reason != kOk) continue;
          const bool ok = sm.guard_ok(a, b, v.dir);
          ASSERT_EQ(ok, sm.guard_ok_scanning(a, b, v.dir)) << "edge " << a << "-" << b << ", pass " << pass;
          ++compared;
          if (!ok) {
            ++refused;
            continue;
          }
          sm.collapse(a, b, v.dir);
          if (++collapses % 50 == 0) {
            ASSERT_EQ(sm.verify_guard(), 0) << "after collapse " << collapses;
          }
          break;
        }
      }
      ASSERT_EQ(sm.verify_guard(), 0) << "after pass " << pass;
      sm.compact(vmap, kept);
      ASSERT_EQ(sm.verify_guard(), 0) << "after the compaction of pass " << pass;
    }
    EXPECT_GE(collapses, 50);
  }
  EXPECT_GE(refused, 1) << "no refusal: only passing verdicts were compared";
}

// Greedy (the host tail's mode): after an iteration in which the surface guard refused edges,
// the next iteration lists only those. Sound when no other edge is admissible and passes the
// guard then: checked over every edge of the mesh after each such iteration.
TEST(SequentialGuard, GreedyLaterIterationsNeedOnlyTheRefusedEdges) {
  // the dimple with the tip in its void (refused) after a cube that collapses in the same
  // iteration, so that another iteration follows with the refused edges renumbered
  int32_t first = 0;  // the dimple's first vertex
  std::vector<std::pair<std::string, Mesh>> inputs{{"dimple and tip beside a cube", cube_then_dimple(3, &first)}};
  ASSERT_EQ(int32_t(inputs[0].second.num_vertices()), first + 10);
  const std::string fusee = test::shared_mesh("gen_gmsh_917_fusee_88k.msh");
  if (!fusee.empty()) inputs.emplace_back("fusee 88k", read_mesh(fusee));
  else std::printf("fusee 88k absent: the dimple and the cube alone\n");
  int64_t refusing_iterations = 0, checked_iterations = 0;
  for (const auto& [name, in] : inputs) {
    SCOPED_TRACE(name);
    Mesh m = in;
    CollapseOptions o;
    o.min_quality = 0;
    if (name == "dimple and tip beside a cube") o.target_length = 10;
    else o.target_factor = 2;
    SequentialRun run(m, o);
    run.set_greedy(true);
    for (bool more = run.step();; ) {
      const std::vector<int32_t>& refused = run.guard_refused();
      refusing_iterations += !refused.empty();
      if (!more) break;  // more: the guard refused edges and the iteration collapsed some
      std::set<std::pair<int32_t, int32_t>> listed;
      for (size_t i = 0; i + 1 < refused.size(); i += 2)
        listed.insert({std::min(refused[i], refused[i + 1]), std::max(refused[i], refused[i + 1])});
      SeqMesh& sm = run.seq();
      EXPECT_EQ(sm.verify_guard(), 0);  // renumbered by the compaction, not built again
      if (name == "dimple and tip beside a cube") {
        // renumbered: edges to the dimple's centre, vertex 4 of the last 10 (the cube lost some)
        EXPECT_LT(sm.num_vertices(), int32_t(in.num_vertices()));
        const int32_t centre = sm.num_vertices() - 10 + 4;
        for (const auto& [a, b] : listed) EXPECT_TRUE(sm.is_edge(a, b) && b == centre) << a << "-" << b;
      }
      std::vector<int32_t> nb;
      int64_t admissible = 0;
      for (int32_t a = 0; a < sm.num_vertices(); ++a) {
        sm.neighbours(a, nb, true);
        for (int32_t b : nb) {
          if (!(sm.length(a, b) < run.target())) continue;
          const Verdict v = sm.check(a, b);
          if (v.reason != kOk || !sm.guard_ok(a, b, v.dir)) continue;
          ++admissible;
          EXPECT_TRUE(listed.count({a, b})) << "edge " << a << "-" << b << " is admissible and not listed";
        }
      }
      ++checked_iterations;
      more = run.step();
      const IterationStats& s = run.report().iterations.back();
      EXPECT_LE(s.edges, int64_t(listed.size()));  // the listed edges that are still edges
      EXPECT_EQ(s.collapsed >= 1, admissible >= 1) << admissible << " admissible edges";
    }
    run.finish();
    // valid: the later iterations (their grid renumbered by the compactions) refused again
    // what the first refused
    EXPECT_TRUE(check(m, in).valid) << check_report_text(check(m, in));
    std::printf("%s: %lld iterations with refusals, %lld checked (all inputs so far)\n", name.c_str(),
                (long long)refusing_iterations, (long long)checked_iterations);
  }
  EXPECT_GE(refusing_iterations, 1) << "the guard refused nothing";
  EXPECT_GE(checked_iterations, 1) << "no iteration with refusals and collapses: the test saw no later iteration";
}

// --- refusals ---

TEST(SequentialCollapse, CornersAreNeverRemoved) {
  Mesh m = test::cube_tets(1);  // 8 corners and nothing else
  CollapseOptions o;
  o.target_length = 10;
  o.min_quality = 0;
  CollapseReport r = collapse_sequential(m, o);
  EXPECT_EQ(r.tets_out, 6);
  EXPECT_EQ(m.num_vertices(), 8);
  ASSERT_EQ(r.iterations.size(), 1u);
  EXPECT_EQ(r.iterations[0].marked, 19);
  EXPECT_EQ(r.iterations[0].candidates, 0);
}

TEST(SequentialCollapse, RefusesWhatItCannotDo) {
  Mesh m = test::cube_tets(2);
  CollapseOptions o;
  o.cost_cl_source = "double tc_user_cost(double3 p0, double3 p1, double f0, double f1) { return 0.0; }";
  o.target_length = 1;
  EXPECT_THROW(collapse_sequential(m, o), std::invalid_argument);
  CollapseOptions mask;
  mask.vertex_mask.assign(3, 1);
  EXPECT_THROW(collapse_sequential(m, mask), std::invalid_argument);
  CollapseOptions neg;
  neg.max_iterations = -1;
  EXPECT_THROW(collapse_sequential(m, neg), std::invalid_argument);
  Mesh bad = m;
  bad.tets[5] = int32_t(bad.num_vertices());
  EXPECT_THROW(collapse_sequential(bad, CollapseOptions{}), InputError);
  bad = m;
  bad.tets[5] = bad.tets[4];
  EXPECT_THROW(collapse_sequential(bad, CollapseOptions{}), InputError);
  bad = m;
  bad.tet_labels.push_back({"l", {1, 2}});
  EXPECT_THROW(collapse_sequential(bad, CollapseOptions{}), InputError);
  EXPECT_EQ(m.tets, test::cube_tets(2).tets);  // refused before touching the mesh
}

// --- the command line ---

TEST(SequentialCli, MethodSequentialWithCheck) {
  test::TempDir dir;
  const std::string cli = std::string("'") + TC_CLI + "'";
  const std::string in = test::project_mesh("bracket.msh"), out = dir.file("out.msh"), stats = dir.file("s.json");
  std::string text;
  EXPECT_EQ(test::run_command(cli + " " + in + " " + out + " --method sequential --check --stats " + stats, &text), 0)
      << text;
  EXPECT_NE(text.find("valid"), std::string::npos) << text;
  Mesh m = read_mesh(out);
  EXPECT_GT(m.num_tets(), 0);
  EXPECT_LT(m.num_tets(), read_mesh(in).num_tets());
  EXPECT_NE(test::read_text(stats).find("cpu-sequential"), std::string::npos);
  // --device makes no sense without a device: a usage error
  EXPECT_EQ(test::run_command(cli + " " + in + " " + out + " --method sequential --device 0", &text), 2) << text;
  // a user cost is OpenCL C: refused with a message naming the method
  const std::string cost = dir.file("cost.cl");
  test::write_text(cost, "double tc_user_cost(double3 p0, double3 p1, double f0, double f1) { return 0.0; }\n");
  EXPECT_EQ(test::run_command(cli + " " + in + " " + out + " --method sequential --cost-cl " + cost +
                                  " --target-length 1",
                              &text),
            2);  // a usage error
  EXPECT_NE(text.find("sequential"), std::string::npos) << text;
}

namespace tc {
namespace {

// The harmonic index of a tet (sum of squared face areas / volume) and its smallest dihedral
// angle's sine, over a whole mesh: the sum and the worst.
std::pair<double, double> harmonic_and_worst(const Mesh& m) {
  double sum = 0, worst = 1;
  for (int64_t t = 0; t < m.num_tets(); ++t) {
    geo::tc_d3 c[4];
    for (int k = 0; k < 4; ++k) c[k] = geo::tc_point(m.points.data(), m.tets[size_t(4 * t + k)]);
    double areas = 0;
    for (const auto& F : geo::TC_TET_FACES) {
      const geo::tc_d3 n = geo::cross(c[F[1]] - c[F[0]], c[F[2]] - c[F[0]]);
      areas += 0.25 * geo::dot(n, n);
    }
    sum += areas / (geo::tc_orient3d(c[0], c[1], c[2], c[3]) / 6);
    worst = std::min(worst, geo::tc_tet_min_sine(c[0], c[1], c[2], c[3]));
  }
  return {sum, worst};
}

// The paper's collapse for mesh improvement: each collapse lowers the harmonic sum of what it
// reshapes (so the mesh's), never lowers the worst tet, and some do happen on a jiggled grid.
TEST(HarmonicCollapse, LowersTheHarmonicSumAndNeverTheWorstTet) {
  Mesh in = test::cube_tets(6);
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-0.45 / 6, 0.45 / 6);
  for (double& x : in.points)
    if (x > 0 && x < 1) x += u(rng);
  const auto [sum0, worst0] = harmonic_and_worst(in);
  for (auto boundary : {CollapseOptions::Features, CollapseOptions::Free}) {
    Mesh m = in;
    CollapseOptions o;
    o.method = CollapseOptions::Sequential;
    o.boundary = boundary;
    o.harmonic_cost = true;
    o.min_quality = 0;  // (the worst-tet rule alone, without the mean-ratio guard)
    const CollapseReport r = collapse_sequential(m, o);
    EXPECT_LT(m.num_tets(), in.num_tets());
    const auto [sum1, worst1] = harmonic_and_worst(m);
    EXPECT_LT(sum1, sum0);
    EXPECT_GE(worst1, worst0);
    // a second run finds nothing more to gain
    Mesh again = m;
    const CollapseReport r2 = collapse_sequential(again, o);
    EXPECT_EQ(again.num_tets(), m.num_tets());
    (void)r;
    (void)r2;
  }
}

}  // namespace
}  // namespace tc
