// Atomic-min conflict detection (Gautron and Kenzel 2023; CollapseOptions::AtomicMin,
// cl/collapse_atomic_min.cl): the stage against a host recomputation of the descriptors and of
// the per-tet minima, the conflict-freedom the compaction relies on, the local-minimum property,
// whole runs (valid meshes, boundary topology, determinism) and the CLI.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>

#include "collapse/stages.hpp"
#include "stage_inputs.hpp"
#include "tetcollapse/check.hpp"
#include "tetcollapse/collapse.hpp"
#include "tetcollapse/io.hpp"
#include "test_support.hpp"

using namespace tc;
using namespace tc::collapse_detail;

namespace {

// The descriptor as documented in cl/collapse_atomic_min.cl, written again here: an
// order-preserving key of the cost (-0.0 as +0.0), its low k bits replaced by the edge index,
// k the fewest bits (>= 1) holding every index.
uint64_t cost_key(double c) {
  if (c == 0.0) c = 0.0;
  uint64_t bits;
  std::memcpy(&bits, &c, sizeof bits);
  return (bits >> 63) ? ~bits : bits | (uint64_t(1) << 63);
}
int index_bits(uint32_t ne) {
  int k = 1;
  while ((uint64_t(1) << k) < ne) ++k;
  return k;
}
uint64_t descriptor(double c, uint32_t e, uint32_t ne) {
  const uint64_t low = (uint64_t(1) << index_bits(ne)) - 1;
  return (cost_key(c) & ~low) | e;
}

// One iteration up to the atomic-min stage on the device; its inputs and outputs on the host.
struct AtomicStage {
  DeviceMesh dm;
  Connectivity c;
  EdgeState s;
  uint32_t ne = 0, n = 0;
  std::vector<int32_t> edges, vaff, tets;
  std::vector<uint32_t> adm, fin;
  std::vector<double> cost;
  std::vector<uint8_t> dir;
  std::vector<std::vector<int32_t>> ring;  // tets of each vertex, from the mesh

  AtomicStage(Context& ctx, const Mesh& m, StageParams p, double target) {
    test::run_to_admissible(ctx, m, p, target, dm, c, s);
    n = conflicts_atomic_min(ctx, dm, c, s);
    ne = c.ne;
    edges = c.edges.download_range(0, 2 * size_t(ne));
    adm = s.result.edges_are_admissible.download_range(0, ne);
    fin = s.result.edges_are_final.download_range(0, ne);
    cost = s.cost.edges2cost.download_range(0, ne);
    dir = s.result.edges2dir.download_range(0, ne);
    vaff = s.result.verts2collapse.download_range(0, dm.nv);
    tets = m.tets;
    ring.assign(m.num_vertices(), {});
    for (size_t t = 0; t < tets.size() / 4; ++t)
      for (int k = 0; k < 4; ++k) ring[tets[4 * t + k]].push_back(int32_t(t));
  }
  uint64_t desc(uint32_t e) const { return descriptor(cost[e], e, ne); }
  // The tets of ring(a) and ring(b) for e = (a, b).
  std::vector<int32_t> star(uint32_t e) const {
    std::vector<int32_t> r = ring[edges[2 * e]];
    r.insert(r.end(), ring[edges[2 * e + 1]].begin(), ring[edges[2 * e + 1]].end());
    std::sort(r.begin(), r.end());
    r.erase(std::unique(r.begin(), r.end()), r.end());
    return r;
  }
  // The admissible edges other than e with an end point in a tet of e's star: those that
  // propagate to a tet e propagates to.
  std::set<uint32_t> rivals(uint32_t e, const std::vector<std::vector<uint32_t>>& vertex_edges) const {
    std::set<uint32_t> r;
    for (int32_t t : star(e))
      for (int k = 0; k < 4; ++k)
        for (uint32_t f : vertex_edges[tets[4 * t + k]])
          if (f != e && adm[f]) r.insert(f);
    return r;
  }
  std::vector<std::vector<uint32_t>> vertex_edges() const {
    std::vector<std::vector<uint32_t>> ve(ring.size());
    for (uint32_t e = 0; e < ne; ++e) {
      ve[edges[2 * e]].push_back(e);
      ve[edges[2 * e + 1]].push_back(e);
    }
    return ve;
  }
};

// make_cube_mesh(n) with every interior vertex moved by up to 3% of the spacing per axis
// (a fixed pseudo-random sequence): distinct costs, tets still positive.
Mesh jittered_cube(int n) {
  Mesh m = make_cube_mesh(n);
  uint32_t state = 12345;
  auto next = [&state] {
    state = state * 1664525u + 1013904223u;
    return double(state >> 8) / double(1u << 24) - 0.5;  // [-0.5, 0.5)
  };
  for (size_t v = 0; v < m.points.size() / 3; ++v) {
    bool interior = true;
    for (int c = 0; c < 3; ++c) interior = interior && m.points[3 * v + c] > 0 && m.points[3 * v + c] < 1;
    if (interior)
      for (int c = 0; c < 3; ++c) m.points[3 * v + c] += 0.06 / n * next();
  }
  return m;
}

using Input = test::StageInput;

// The stage inputs (stage_inputs.hpp) and a jittered cube (distinct costs); two shared meshes.
std::vector<Input> stage_inputs() {
  std::vector<Input> in = test::conflict_stage_inputs({"polyfem_screw.msh", "libigl_octopus-low.mesh"});
  const Mesh jittered = jittered_cube(6);
  in.push_back({"jittered cube", jittered, params_from(CollapseOptions{}), 2 * median_edge_length(jittered)});
  return in;
}

}  // namespace

// The host descriptor is the documented order: (cost, index) for costs far apart, -0.0 = +0.0,
// negative below positive.
TEST(CollapseAtomicMin, DescriptorOrder) {
  const uint32_t ne = 1000;  // 10 index bits
  EXPECT_EQ(index_bits(1), 1);
  EXPECT_EQ(index_bits(2), 1);
  EXPECT_EQ(index_bits(3), 2);
  EXPECT_EQ(index_bits(1024), 10);
  EXPECT_EQ(index_bits(1025), 11);
  const double costs[] = {-1e300, -2.5, -1.0, -1e-300, 0.0, 1e-300, 0.5, 1.0, 1.0 + 1e-9, 3.0, 1e300};
  for (size_t i = 0; i + 1 < std::size(costs); ++i) {
    EXPECT_LT(descriptor(costs[i], 999, ne), descriptor(costs[i + 1], 0, ne)) << costs[i];
    EXPECT_LT(descriptor(costs[i], 3, ne), descriptor(costs[i], 4, ne)) << costs[i];
  }
  EXPECT_EQ(descriptor(-0.0, 7, ne), descriptor(0.0, 7, ne));
  // costs closer than the dropped bits compare by index
  EXPECT_LT(descriptor(1.0 + 1e-15, 1, ne), descriptor(1.0, 2, ne));
}

// Stage test: the selected edges are exactly the admissible edges holding the minimum
// descriptor in every tet of both rings (recomputed on the host), they are conflict-free as
// conflict_pass2's output is (no vertex in two of them, no tet with end points of two), and
// fin, vaff and the counter say the same.
TEST(CollapseAtomicMin, SelectsTheEdgesHoldingEveryMinimum) {
  Context ctx;
  ASSERT_TRUE(ctx.info().int64_atomics_extended) << "this device cannot run the atomic-min detection";
  for (const Input& in : stage_inputs()) {
    SCOPED_TRACE(in.name);
    AtomicStage st(ctx, in.mesh, in.params, in.target);
    const uint32_t nt = uint32_t(st.tets.size() / 4);
    std::vector<uint64_t> tmin(nt, UINT64_MAX);
    uint32_t n_adm = 0;
    for (uint32_t e = 0; e < st.ne; ++e) {
      if (!st.adm[e]) continue;
      ++n_adm;
      for (int32_t t : st.star(e)) tmin[t] = std::min(tmin[t], st.desc(e));
    }
    uint32_t selected = 0;
    for (uint32_t e = 0; e < st.ne; ++e) {
      bool holds = st.adm[e] != 0;
      for (int32_t t : holds ? st.star(e) : std::vector<int32_t>{}) holds = holds && tmin[t] == st.desc(e);
      ASSERT_EQ(st.fin[e] != 0, holds) << "edge " << e;
      selected += holds;
    }
    std::printf("%s: %u admissible, %u selected\n", in.name.c_str(), n_adm, selected);
    EXPECT_GT(n_adm, 0u);
    EXPECT_GT(selected, 0u);
    EXPECT_EQ(st.n, selected);
    uint32_t counters[6];
    st.s.cost.counters.download(counters, 6);
    EXPECT_EQ(counters[3], selected);
    EXPECT_EQ(counters[2], selected);
    // vaff: exactly the end points of the selected edges, each in one edge
    std::vector<int32_t> owner(st.ring.size(), -1);
    for (uint32_t e = 0; e < st.ne; ++e) {
      if (!st.fin[e]) continue;
      for (int k = 0; k < 2; ++k) {
        int32_t v = st.edges[2 * e + k];
        EXPECT_EQ(owner[v], -1) << "vertex " << v << " in two selected edges";
        owner[v] = int32_t(e);
      }
    }
    EXPECT_EQ(st.vaff, owner);
    // no tet holds end points of two selected edges
    for (uint32_t t = 0; t < nt; ++t) {
      std::set<int32_t> es;
      for (int k = 0; k < 4; ++k)
        if (owner[st.tets[4 * t + k]] >= 0) es.insert(owner[st.tets[4 * t + k]]);
      EXPECT_LE(es.size(), 1u) << "tet " << t;
    }
  }
}

// A selected edge's descriptor is below that of every admissible edge sharing a tet with it
// (local minimum of the conflict graph), and that agrees with the (cost, index) order of the
// two-pass detection but for costs closer than the descriptor's resolution. With the same
// order, the selection is the first round of the two-pass greedy fixpoint: a subset of it.
TEST(CollapseAtomicMin, SelectedEdgesAreLocalMinimaAndASubsetOfTwoPass) {
  Context ctx;
  for (const Input& in : stage_inputs()) {
    SCOPED_TRACE(in.name);
    AtomicStage st(ctx, in.mesh, in.params, in.target);
    const auto ve = st.vertex_edges();
    int checked = 0, resolution_ties = 0;
    for (uint32_t e = 0; e < st.ne; ++e) {
      if (!st.fin[e]) continue;
      for (uint32_t f : st.rivals(e, ve)) {
        ASSERT_LT(st.desc(e), st.desc(f)) << "selected edge " << e << " vs admissible edge " << f;
        const bool before = st.cost[e] < st.cost[f] || (st.cost[e] == st.cost[f] && e < f);
        if (!before) {  // only when the costs are within the dropped bits
          EXPECT_EQ(cost_key(st.cost[e]) >> index_bits(st.ne), cost_key(st.cost[f]) >> index_bits(st.ne));
          ++resolution_ties;
        }
        ++checked;
      }
    }
    EXPECT_GT(checked, 0);
    // the two passes on the same admissible edges (they overwrite fin and vaff)
    const std::vector<uint32_t> atomic_fin = st.fin;
    conflict_pass1(ctx, st.dm, st.c, st.s);
    TwoPassState two_pass;
    const uint32_t n2 = conflict_pass2(ctx, st.dm, st.c, st.s, two_pass);
    const std::vector<uint32_t> two = st.s.result.edges_are_final.download_range(0, st.ne);
    uint32_t outside = 0;
    for (uint32_t e = 0; e < st.ne; ++e) outside += atomic_fin[e] && !two[e];
    std::printf("%s: atomic-min %u, two-pass %u, atomic edges not in two-pass %u, resolution ties %d\n",
                in.name.c_str(), st.n, n2, outside, resolution_ties);
    if (resolution_ties == 0) {
      EXPECT_EQ(outside, 0u);
      EXPECT_LE(st.n, n2);
    }
  }
}

namespace {

CheckReport check(const Mesh& m, const Mesh& ref) {
  CheckOptions o;
  o.quality = false;
  o.hausdorff = false;
  return check_mesh(m, o, &ref);
}

CollapseOptions atomic_options(double factor) {
  CollapseOptions o;
  o.conflicts = CollapseOptions::AtomicMin;
  o.target_factor = factor;
  return o;
}

}  // namespace

// Whole runs: valid output, the boundary's topology kept, the same mesh bit for bit on a second
// run, for every work-group size (cube), and with or without the work carried across iterations.
// (The bracket runs in NeedsAtLeastAsManyIterationsAsTwoPass.)
TEST(CollapseAtomicMin, FullRunsStayValidAndDeterministic) {
  Context ctx;
  std::vector<std::pair<std::string, Mesh>> inputs;
  {
    Mesh cube = jittered_cube(5);
    Labels l{"material", {}};
    for (int64_t t = 0; t < cube.num_tets(); ++t) l.values.push_back(cube.points[3 * cube.tets[4 * t]] < 0.5 ? 1 : 2);
    cube.tet_labels.push_back(l);
    inputs.emplace_back("cube", cube);
  }
  for (const char* name : {"polyfem_screw.msh", "libigl_octopus-low.mesh"}) {
    std::string path = test::shared_mesh(name);
    if (path.empty()) {
      std::printf("skipping %s: absent\n", name);
      continue;
    }
    inputs.emplace_back(name, read_mesh(path));
  }
  for (const auto& [name, in] : inputs) {
    SCOPED_TRACE(name);
    CollapseOptions o = atomic_options(2);
    Mesh a = in;
    CollapseReport r = collapse(a, o, ctx);
    std::printf("%s: tets %lld -> %lld, %zu iterations\n", name.c_str(), (long long)r.tets_in, (long long)r.tets_out,
                r.iterations.size());
    EXPECT_LT(r.tets_out, r.tets_in);
    if (name != "libigl_octopus-low.mesh") {  // mostly boundary: few tets go (as with two-pass)
      EXPECT_LT(r.tets_out, r.tets_in / 2);
    }
    EXPECT_GT(r.iterations.size(), 1u);
    CheckReport c = check(a, in);
    EXPECT_TRUE(c.valid) << check_report_text(c);
    EXPECT_FALSE(c.reference.topology_changed);
    int64_t collapsed = 0;
    for (const IterationStats& s : r.iterations) {
      EXPECT_LE(s.collapsed, s.selected);
      EXPECT_LE(s.selected, s.tested);
      EXPECT_EQ(s.tested, s.candidates);  // every candidate tested
      EXPECT_LE(s.candidates, s.marked);
      EXPECT_EQ(s.vertices - s.vertices_after, s.collapsed);
      collapsed += s.collapsed;
    }
    EXPECT_EQ(r.vertices_in - r.vertices_out, collapsed);
    if (name == "libigl_octopus-low.mesh") continue;
    // the same again, and without carried work
    Mesh b = in;
    collapse(b, o, ctx);
    EXPECT_EQ(a.points, b.points);
    EXPECT_EQ(a.tets, b.tets);
    o.tuning.reuse_across_iterations = false;
    Mesh d = in;
    collapse(d, o, ctx);
    EXPECT_EQ(a.points, d.points);
    EXPECT_EQ(a.tets, d.tets);
    if (name != "cube") continue;
    for (size_t wg : {1, 4, 32, 256}) {
      ctx.set_work_group_size(wg);
      Mesh w = in;
      collapse(w, atomic_options(2), ctx);
      EXPECT_EQ(w.points, a.points) << "work-group size " << wg;
      EXPECT_EQ(w.tets, a.tets) << "work-group size " << wg;
      EXPECT_EQ(w.tet_labels[0].values, a.tet_labels[0].values) << "work-group size " << wg;
    }
    ctx.set_work_group_size(0);
  }
}

// Paper Fig. 7: the atomic-min detection selects fewer edges per iteration, so it needs at least
// as many iterations as the two passes to converge (eps_c 0, median edge length).
TEST(CollapseAtomicMin, NeedsAtLeastAsManyIterationsAsTwoPass) {
  Context ctx;
  Mesh in = read_mesh(test::project_mesh("bracket.msh"));
  CollapseOptions o = atomic_options(1);
  o.eps_c = 0;
  Mesh a = in, b = in;
  CollapseReport ra = collapse(a, o, ctx);
  o.conflicts = CollapseOptions::TwoPass;
  CollapseReport rb = collapse(b, o, ctx);
  std::printf("bracket, 1 x median, eps_c 0: atomic-min %zu iterations (%lld tets), two-pass %zu (%lld tets)\n",
              ra.iterations.size(), (long long)ra.tets_out, rb.iterations.size(), (long long)rb.tets_out);
  ASSERT_FALSE(ra.iterations.empty());
  EXPECT_LE(ra.iterations[0].collapsed, rb.iterations[0].collapsed);
  EXPECT_GE(ra.iterations.size(), rb.iterations.size());
  // and the atomic-min result is a valid coarsening with the boundary's topology
  EXPECT_LT(ra.tets_out, ra.tets_in);
  CheckReport c = check(a, in);
  EXPECT_TRUE(c.valid) << check_report_text(c);
  EXPECT_FALSE(c.reference.topology_changed);
}

TEST(CollapseAtomicMin, CommandLine) {
  test::TempDir dir;
  const std::string in = dir.file("cube.mesh"), out = dir.file("out.msh"), stats = dir.file("stats.json");
  write_mesh(in, jittered_cube(4));
  std::string log;
  const int rc = test::run_command(std::string(TC_CLI) + " " + in + " " + out +
                                       " --conflicts atomic-min --target-factor 2 --check --stats " + stats,
                                   &log);
  ASSERT_EQ(rc, 0) << log;
  EXPECT_NE(log.find("valid"), std::string::npos) << log;
  Mesh m = read_mesh(out);
  EXPECT_GT(m.num_tets(), 0);
  const std::string json = test::read_text(stats);
  EXPECT_NE(json.find("atomic-min"), std::string::npos) << json.substr(0, 400);
}
