// The host tail (CollapseTuning::host_tail): once an iteration of the parallel method collapses
// few edges, the rest runs on the host with the sequential method's checks, greedily.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "collapse/sequential_mesh.hpp"
#include "collapse/sequential_run.hpp"
#include "collapse/stages.hpp"
#include "tetcollapse/check.hpp"
#include "tetcollapse/collapse.hpp"
#include "tetcollapse/io.hpp"
#include "collapse_test_util.hpp"
#include "test_support.hpp"

using namespace tc;
using tc::test::count_on_host;

namespace {

// The smallest and largest x of the mesh's points.
std::pair<double, double> x_range(const Mesh& m) {
  double lo = m.points[0], hi = m.points[0];
  for (size_t v = 0; v < m.points.size(); v += 3) {
    lo = std::min(lo, m.points[v]);
    hi = std::max(hi, m.points[v]);
  }
  return {lo, hi};
}

// The bracket (curved faces, ridges, corners, Gmsh's boundary triangles) with two materials
// (split at the centre of its box) and a vertex field (x).
Mesh bracket_with_attributes() {
  Mesh m = read_mesh(test::project_mesh("bracket.msh"));
  const auto [lo, hi] = x_range(m);
  Labels l;
  l.name = "material";
  for (int64_t t = 0; t < m.num_tets(); ++t) {
    double cx = 0;
    for (int k = 0; k < 4; ++k) cx += m.points[3 * size_t(m.tets[4 * t + k])] / 4;
    l.values.push_back(cx < 0.5 * (lo + hi) ? 1 : 2);
  }
  m.tet_labels.insert(m.tet_labels.begin(), l);
  Field f;
  f.name = "x";
  f.components = 1;
  for (size_t v = 0; v < m.points.size(); v += 3) f.values.push_back(m.points[v]);
  m.vertex_fields.push_back(f);
  return m;
}

CollapseOptions tail_early() {
  CollapseOptions o;
  o.target_factor = 2;
  o.tuning.host_tail = 0.05;  // from the first iteration collapsing fewer than 5% of its tets
  o.tuning.host_tail_min_iterations = 0;  // however fast the counts shrink
  return o;
}

}  // namespace

TEST(CollapseHostTail, FinishesOnTheHostWithNothingLeft) {
  Context ctx;
  const Mesh in = bracket_with_attributes();
  Mesh m = in;
  const CollapseReport r = collapse(m, tail_early(), ctx);
  ASSERT_GE(count_on_host(r), 1) << "the tail did not run";
  // greedy: one iteration (another only after a refusal by the surface guard); the sequential
  // method's own iterations would need many more (a cascade each)
  EXPECT_LE(count_on_host(r), 2);
  // device iterations first, then the host's, numbered on; each starts where the last ended
  int64_t collapsed = 0;
  for (size_t i = 0; i < r.iterations.size(); ++i) {
    const IterationStats& s = r.iterations[i];
    EXPECT_EQ(s.iteration, int(i));
    if (i > 0) {
      EXPECT_FALSE(r.iterations[i - 1].on_host && !s.on_host) << "a device iteration after the host tail";
      EXPECT_EQ(s.tets, r.iterations[i - 1].tets_after);
      EXPECT_EQ(s.vertices, r.iterations[i - 1].vertices_after);
    }
    collapsed += s.collapsed;
  }
  EXPECT_GT(r.iterations[r.iterations.size() - count_on_host(r)].collapsed, 0);
  EXPECT_EQ(r.vertices_in - r.vertices_out, collapsed);
  EXPECT_EQ(r.tets_out, m.num_tets());

  CheckOptions co;
  co.quality = false;
  co.hausdorff = false;
  const CheckReport c = check_mesh(m, co, &in);
  EXPECT_TRUE(c.valid) << check_report_text(c);
  EXPECT_FALSE(c.reference.topology_changed);
  ASSERT_EQ(m.tet_labels.size(), in.tet_labels.size());
  EXPECT_EQ(m.tet_labels[0].values.size(), size_t(m.num_tets()));
  ASSERT_EQ(m.vertex_fields.size(), 1u);
  ASSERT_EQ(m.vertex_fields[0].values.size(), size_t(m.num_vertices()));
  // the field stays with the survivors (midpoint placement averages it): within the input's range
  const auto [flo, fhi] = std::minmax_element(in.vertex_fields[0].values.begin(), in.vertex_fields[0].values.end());
  for (double x : m.vertex_fields[0].values) {
    EXPECT_GE(x, *flo);
    EXPECT_LE(x, *fhi);
  }

  // Nothing is left to collapse: a fresh device iteration with the same target finds nothing.
  Mesh again = m;
  CollapseOptions o2 = tail_early();
  o2.target_length = r.target_length;
  o2.tuning.host_tail = 0;
  o2.max_iterations = 1;
  const CollapseReport r2 = collapse(again, o2, ctx);
  ASSERT_EQ(r2.iterations.size(), 1u);
  EXPECT_GT(r2.iterations[0].marked, 0);
  EXPECT_EQ(r2.iterations[0].collapsed, 0);
}

TEST(CollapseHostTail, DeterministicAndBoundedByMaxIterations) {
  Context ctx;
  const Mesh in = bracket_with_attributes();
  Mesh a = in, b = in;
  const CollapseReport ra = collapse(a, tail_early(), ctx);
  collapse(b, tail_early(), ctx);
  EXPECT_EQ(a.points, b.points);
  EXPECT_EQ(a.tets, b.tets);
  EXPECT_EQ(a.tet_labels[0].values, b.tet_labels[0].values);
  EXPECT_EQ(a.vertex_fields[0].values, b.vertex_fields[0].values);
  // the sequential method's option to skip invalidated edges does not reach the greedy tail
  // (it would skip every edge queued after a collapse and stop with admissible edges left)
  CollapseOptions skip = tail_early();
  skip.sequential_skip_invalidated = true;
  Mesh d = in;
  collapse(d, skip, ctx);
  EXPECT_EQ(d.tets, a.tets);
  // max_iterations counts the host's iterations too: room for one, or none
  const int device_its = int(ra.iterations.size()) - count_on_host(ra);
  CollapseOptions o = tail_early();
  o.max_iterations = device_its + 1;
  Mesh c = in;
  const CollapseReport rc = collapse(c, o, ctx);
  EXPECT_EQ(int(rc.iterations.size()), device_its + 1);
  EXPECT_EQ(count_on_host(rc), 1);
  EXPECT_TRUE(rc.iterations.back().on_host);
  o.max_iterations = device_its;
  Mesh e = in;
  const CollapseReport re = collapse(e, o, ctx);
  EXPECT_EQ(int(re.iterations.size()), device_its);
  EXPECT_EQ(count_on_host(re), 0);
}

TEST(CollapseHostTail, OnlyWhenRunningUntilNothingCollapses) {
  Context ctx;
  const Mesh in = bracket_with_attributes();
  CollapseOptions off = tail_early();
  off.tuning.host_tail = 0;
  CollapseOptions eps = tail_early();
  eps.eps_c = 50;  // stops by itself: no tail
  CollapseOptions user = tail_early();
  user.target_length = 2 * median_edge_length(in);
  user.cost_cl_source = "double tc_user_cost(double3 p0, double3 p1, double f0, double f1) { return length(p1 - p0); }";
  for (const CollapseOptions* o : {&off, &eps, &user}) {
    Mesh m = in;
    const CollapseReport r = collapse(m, *o, ctx);
    EXPECT_GT(r.vertices_in, r.vertices_out);
    EXPECT_EQ(count_on_host(r), 0);
  }
  // a tail that would die out within host_tail_min_iterations stays on the device
  CollapseOptions slow = tail_early();
  slow.tuning.host_tail_min_iterations = 1e9;
  {
    Mesh m = in;
    EXPECT_EQ(count_on_host(collapse(m, slow, ctx)), 0);
  }
  // the default: with Context::cpu_tuning (a CPU device unless TETCOLLAPSE_TUNING says
  // otherwise) from 0.2% on, else never (the context decides, not the run)
  CollapseOptions d;
  d.target_factor = 2;
  EXPECT_LT(d.tuning.host_tail, 0);
  d.tuning.host_tail_min_iterations = 0;  // the bracket's tail dies out fast
  Mesh m = in;
  const CollapseReport r = collapse(m, d, ctx);
  if (ctx.cpu_tuning()) {
    ASSERT_GE(count_on_host(r), 1);
    const IterationStats& last_device = r.iterations[r.iterations.size() - count_on_host(r) - 1];
    EXPECT_LT(double(last_device.collapsed), CollapseTuning::kHostTailCpuMatching * double(last_device.tets));
  } else {
    EXPECT_EQ(count_on_host(r), 0);
  }
}

// The mask and the boundary triangles travel into the host tail: unselected vertices stay, the
// triangles are remapped onto faces of the result.
TEST(CollapseHostTail, MaskAndTrianglesCarried) {
  Context ctx;
  const Mesh in = bracket_with_attributes();
  ASSERT_GT(in.tris.size(), 0u);
  const auto [lo, hi] = x_range(in);
  CollapseOptions o = tail_early();
  std::set<test::Point3> outside;
  o.vertex_mask = test::mask_x_below(in, lo + 0.6 * (hi - lo), &outside);
  Mesh m = in;
  const CollapseReport r = collapse(m, o, ctx);
  ASSERT_GE(count_on_host(r), 1);
  EXPECT_LT(r.tets_out, r.tets_in);
  const std::set<test::Point3> out = test::vertex_positions(m);
  for (const auto& p : outside) EXPECT_TRUE(out.count(p)) << "an unselected vertex moved or went away";
  ASSERT_EQ(m.tris.size(), 3 * m.tri_tags.size());
  EXPECT_GT(m.tri_tags.size(), 0u);
  EXPECT_TRUE(test::triangles_off_surface(m).empty()) << "triangles that are not boundary faces of the result";
}

// The host tail starts from the device's edges, flags and classes and skips the tests of edges
// whose end points the last device iteration left untouched (TailSeed, collapse/sequential_run.hpp):
// the same result as starting from the mesh alone (TETCOLLAPSE_HOST_TAIL_SEED=0), with fewer
// tests in the first host iteration after a greedy selection, and as many after the two passes
// (no touched flags: their pass 2 may drop the winner that blocked an admissible edge).
TEST(CollapseHostTail, SeedFromTheDeviceChangesNothing) {
  Context ctx;
  std::vector<std::pair<std::string, Mesh>> inputs{{"bracket", bracket_with_attributes()}};
  const std::string shared = test::shared_mesh("gen_gmsh_Angled_43k.msh");
  if (!shared.empty()) inputs.emplace_back("Angled 43k", read_mesh(shared));
  else std::printf("Angled 43k absent: the bracket alone\n");
  // its matching selection's last device iteration has collapses the surface guard undid
  const std::string fusee = test::shared_mesh("gen_gmsh_917_fusee_88k.msh");
  if (!fusee.empty()) inputs.emplace_back("fusee 88k", read_mesh(fusee));
  else std::printf("fusee 88k absent\n");
  for (const auto& [name, in] : inputs)
    for (CollapseOptions::Conflicts conflicts :
         {CollapseOptions::Greedy, CollapseOptions::TwoPass, CollapseOptions::Matching}) {
      SCOPED_TRACE(name + (conflicts == CollapseOptions::Greedy     ? ", greedy"
                           : conflicts == CollapseOptions::TwoPass ? ", two-pass"
                                                                   : ", matching"));
      CollapseOptions o = tail_early();
      o.conflicts = conflicts;
      o.min_quality = 0;
      Mesh seeded = in, alone = in;
      const CollapseReport rs = collapse(seeded, o, ctx);
      CollapseReport ra;
      {
        test::EnvVar off("TETCOLLAPSE_HOST_TAIL_SEED", "0");
        ra = collapse(alone, o, ctx);
      }
      ASSERT_GE(count_on_host(rs), 1) << "the tail did not run";
      EXPECT_EQ(seeded.points, alone.points);
      EXPECT_EQ(seeded.tets, alone.tets);
      EXPECT_EQ(seeded.tet_labels.size() > 0 ? seeded.tet_labels[0].values : std::vector<int32_t>{},
                alone.tet_labels.size() > 0 ? alone.tet_labels[0].values : std::vector<int32_t>{});
      ASSERT_EQ(rs.iterations.size(), ra.iterations.size());
      const size_t first_host = rs.iterations.size() - size_t(count_on_host(rs));
      for (size_t i = 0; i < rs.iterations.size(); ++i) EXPECT_EQ(rs.iterations[i].collapsed, ra.iterations[i].collapsed);
      EXPECT_EQ(rs.iterations[first_host].edges, ra.iterations[first_host].edges);  // the device's list, gathered
      EXPECT_EQ(rs.iterations[first_host].marked, ra.iterations[first_host].marked);
      EXPECT_EQ(rs.iterations[first_host].candidates, ra.iterations[first_host].candidates);
      if (conflicts != CollapseOptions::TwoPass)
        EXPECT_LT(rs.iterations[first_host].tested, ra.iterations[first_host].tested);
      else
        EXPECT_EQ(rs.iterations[first_host].tested, ra.iterations[first_host].tested);
    }
}

// A seed's edge list that is no list of edges of the mesh (odd length, a >= b, a vertex out of
// range) is refused before it is used.
TEST(CollapseHostTail, SeedEdgesAreChecked) {
  const Mesh in = test::cube_tets(2);
  CollapseOptions o;
  o.method = CollapseOptions::Sequential;
  o.target_length = 1;
  const size_t nv = size_t(in.num_vertices());
  auto seed_with = [nv](std::vector<int32_t> edges) {
    sequential_detail::TailSeed seed;
    seed.vflags.assign(nv, 0);
    seed.vclass.assign(nv, 0);
    seed.touched.assign(nv, 1);
    seed.edges = std::move(edges);
    return seed;
  };
  for (const std::vector<int32_t>& bad : std::vector<std::vector<int32_t>>{
           {0, 1, 2}, {1, 0}, {0, int32_t(nv)}, {-1, 1}, {3, 3}}) {
    const sequential_detail::TailSeed seed = seed_with(bad);
    Mesh m = in;
    EXPECT_THROW(sequential_detail::SequentialRun(m, o, &seed), std::invalid_argument) << bad.size() << " entries";
  }
  const sequential_detail::TailSeed good = seed_with({0, 1});  // a good one is taken
  Mesh m = in;
  EXPECT_NO_THROW(sequential_detail::SequentialRun(m, o, &good));
}

// tail_touched (cl/collapse_verdicts.cl): a vertex counts as touched when its ring changed
// (ndirty) or when an edge at it keeps the surface guard's refusal, which looks beyond the star.
TEST(CollapseHostTail, TouchedFlagsFromDirtyVerticesAndGuardRefusals) {
  using namespace collapse_detail;
  Context ctx;
  const Mesh m = test::cube_tets(3);
  CollapseOptions o;
  DeviceMesh dm;
  upload_mesh(ctx, m, o, dm);
  Connectivity c;
  build_connectivity(ctx, dm, c, params_from(o));
  ASSERT_GT(c.ne, 10u);
  EdgeState s;
  std::vector<uint8_t> ndirty(dm.nv, 0), verdict(c.ne, 0xff);
  ndirty[1] = 1;
  const uint32_t refused = c.ne / 2;
  verdict[refused] = kRefusedSurface;
  verdict[refused / 2] = kRefusedVolume;  // a refusal of the star: not touched for it
  s.carry.verts_are_dirty = DeviceBuffer<uint8_t>(ctx, ndirty);
  s.carry.edges2verdict = DeviceBuffer<uint8_t>(ctx, verdict);
  const std::vector<uint8_t> touched = tail_touched(ctx, dm, c, s);
  const std::vector<int32_t> edges = c.edges.download_range(0, 2 * size_t(c.ne));
  ASSERT_EQ(touched.size(), size_t(dm.nv));
  for (int32_t v = 0; v < int32_t(dm.nv); ++v) {
    const bool expected = v == 1 || v == edges[2 * refused] || v == edges[2 * refused + 1];
    EXPECT_EQ(touched[v] != 0, expected) << "vertex " << v;
  }
}

// SeqMesh takes the device's flags, classes and tet neighbours as they are (the host tail's
// seed): they must be what it computes itself (verify_classes and verify_nbr recompute them from
// the mesh). Sizes are checked.
TEST(CollapseHostTail, SeededClassesAreTheHostsOwn) {
  using namespace collapse_detail;
  Context ctx;
  Mesh m = bracket_with_attributes();
  CollapseOptions o;
  DeviceMesh dm;
  upload_mesh(ctx, m, o, dm, nullptr);  // the input's numbering
  Connectivity c;
  build_connectivity(ctx, dm, c, params_from(o));
  const std::vector<uint8_t> vf = c.vflags.download_range(0, dm.nv), vc = c.vclass.download_range(0, dm.nv);
  const std::vector<int32_t> nbr = c.tet_nbr.download_range(0, 4 * size_t(dm.nt));
  sequential_detail::SeqMesh seeded(m, sequential_detail::seq_params_from(o), &vf, &vc, &nbr);
  EXPECT_EQ(seeded.verify_classes(), 0);
  EXPECT_EQ(seeded.verify_nbr(), 0);
  int ridges_or_corners = 0;
  for (int32_t v = 0; v < seeded.num_vertices(); ++v) ridges_or_corners += seeded.vclass(v) >= 2 ? 1 : 0;
  EXPECT_GT(ridges_or_corners, 0);
  const std::vector<uint8_t> short_list(vf.begin(), vf.end() - 1);
  EXPECT_THROW(sequential_detail::SeqMesh(m, sequential_detail::seq_params_from(o), &short_list, &vc),
               std::invalid_argument);
  const std::vector<int32_t> short_nbr(nbr.begin(), nbr.end() - 1);
  EXPECT_THROW(sequential_detail::SeqMesh(m, sequential_detail::seq_params_from(o), &vf, &vc, &short_nbr),
               std::invalid_argument);
}
