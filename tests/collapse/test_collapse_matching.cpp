// The matching selection (CollapseOptions::Matching, cl/collapse_matching.cl): against a host run
// of its definition (SeqMesh: the candidates one after another in priority order, each tested on
// the mesh with the earlier ones collapsed, those sharing an end point with a taken one skipped),
// including the mesh its in-place collapses leave; the same decisions and mesh at every
// work-group size and loop threshold; the undo of collapses the surface guard refuses; the link
// condition's rule per kind of S it brought to light; whole runs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>
#include <vector>

#include "collapse/guard_surface.hpp"
#include "collapse/sequential_mesh.hpp"
#include "collapse/sequential_run.hpp"
#include "collapse/stages.hpp"
#include "collapse_predicate.h"
#include "stage_inputs.hpp"
#include "tetcollapse/check.hpp"
#include "tetcollapse/collapse.hpp"
#include "tetcollapse/io.hpp"
#include "test_support.hpp"

using namespace tc;
using namespace tc::collapse_detail;
using tc::test::expect_same_mesh;

namespace {

struct Input {
  std::string name;
  Mesh mesh;
  CollapseOptions options;
  double target;
};

// The bracket (features, strict, free; with and without the quality guard), cubes with tets
// taken away (odd links), two materials, and a shared mesh when present. No spatial order: the
// host works in the input's numbering.
std::vector<Input> inputs() {
  std::vector<Input> in;
  CollapseOptions o;
  o.tuning.spatial_order = false;
  const Mesh bracket = read_mesh(test::project_mesh("bracket.msh"));
  for (auto mode : {CollapseOptions::Features, CollapseOptions::Strict, CollapseOptions::Free})
    for (double q : {0.0, 0.1}) {
      CollapseOptions b = o;
      b.boundary = mode;
      b.min_quality = q;
      in.push_back({"bracket, mode " + std::to_string(int(mode)) + ", min_quality " + std::to_string(q), bracket, b,
                    2 * median_edge_length(bracket)});
    }
  for (uint32_t seed = 1; seed <= 2; ++seed) {
    uint32_t r = seed * 2654435761u;
    const Mesh holes = test::sub_mesh(test::cube_tets(4), [&](int64_t) {
      r = r * 1664525u + 1013904223u;
      return (r >> 24) >= 77;
    });
    for (auto mode : {CollapseOptions::Features, CollapseOptions::Free}) {
      CollapseOptions b = o;
      b.boundary = mode;
      in.push_back({"cube with holes " + std::to_string(seed) + ", mode " + std::to_string(int(mode)), holes, b,
                    2 * median_edge_length(holes)});
    }
  }
  const Mesh two = test::two_materials(5);
  for (auto mode : {CollapseOptions::Features, CollapseOptions::Free}) {
    CollapseOptions b = o;
    b.boundary = mode;
    in.push_back({"two materials, mode " + std::to_string(int(mode)), two, b, 3 * median_edge_length(two)});
  }
  const std::string screw = test::shared_mesh("polyfem_screw.msh");
  if (!screw.empty()) {
    const Mesh m = read_mesh(screw);
    in.push_back({"polyfem_screw", m, o, 2 * median_edge_length(m)});
  } else {
    std::printf("skipping polyfem_screw.msh: absent\n");
  }
  return in;
}

// One iteration's matching selection on the device, and what the host needs to check it.
struct MatchStage {
  DeviceMesh dm;
  Connectivity c;
  EdgeState s;
  MatchingState matching;
  StageParams p;
  uint32_t ne = 0, taken = 0, tested = 0;
  std::vector<int32_t> edges;
  std::vector<uint32_t> marked, fin, dround;
  std::vector<uint8_t> dir, reason;
  std::vector<double> prio;

  MatchStage(Context& ctx, const Mesh& m, const CollapseOptions& o, double target, bool early,
             uint32_t loop_size = StageParams{}.greedy_loop_size, uint32_t loop_exit = StageParams{}.greedy_loop_exit,
             bool waiting_lists = true) {
    p = params_from(o);
    p.target = target;
    p.match_early_tests = early;
    p.waiting_lists = waiting_lists;
    p.greedy_loop_size = loop_size;
    p.greedy_loop_exit = loop_exit;
    upload_mesh(ctx, m, o, dm);
    build_connectivity(ctx, dm, c, p);
    cost_and_mark(ctx, dm, c, s, p);
    ne = c.ne;
    edges = c.edges.download_range(0, 2 * size_t(ne));
    marked = s.cost.edges_are_marked.download_range(0, ne);
    matching_backup(ctx, dm, matching);
    uint32_t passed_q = 0;
    s.carry.verdict_ready = false;
    taken = matching_selection(ctx, dm, c, s, matching, p, passed_q, tested);
    fin = s.result.edges_are_final.download_range(0, ne);
    dround = matching.edges2round.download_range(0, ne);
    dir = s.result.edges2dir.download_range(0, ne);
    reason = s.result.edges2reason.download_range(0, ne);
    prio = s.lazy.edges2priority.download_range(0, ne);
  }
  // The mesh as the collapses left it, compacted.
  Mesh result(Context& ctx, const Mesh& input) {
    DeviceMesh next;
    DeviceBuffer<int32_t> origin(ctx, 1);
    collapse_and_compact(ctx, p, dm, next, c, s, origin, 0);
    Mesh out = input;
    download_mesh(dm, out);
    return out;
  }
};

// The definition on the host: the marked edges passing Q on the start mesh, in (priority, index)
// order, each tested (SeqMesh::check) on the mesh with the earlier ones collapsed unless an end
// point is one of a taken edge. Returns per edge the direction taken + 1 (0: not taken); `work`
// ends as the result.
std::vector<int> host_matching(const MatchStage& st, Mesh& work, const CollapseOptions& o) {
  sequential_detail::SeqMesh sm(work, sequential_detail::seq_params_from(o));
  std::vector<uint32_t> order;
  for (uint32_t e = 0; e < st.ne; ++e) {
    if (!st.marked[e]) continue;
    uint8_t fe = 0;
    if (sm.predicate(st.edges[2 * e], st.edges[2 * e + 1], fe) >= 0) order.push_back(e);
  }
  std::sort(order.begin(), order.end(), [&](uint32_t x, uint32_t y) {
    return st.prio[x] < st.prio[y] || (st.prio[x] == st.prio[y] && x < y);
  });
  std::vector<uint8_t> used(size_t(work.num_vertices()), 0);
  std::vector<int> taken(st.ne, 0);
  for (uint32_t e : order) {
    const int32_t a = st.edges[2 * e], b = st.edges[2 * e + 1];
    if (used[a] || used[b] || !sm.is_edge(a, b)) continue;
    const sequential_detail::Verdict v = sm.check(a, b);
    if (v.reason != kOk) continue;
    sm.collapse(a, b, v.dir);
    used[a] = used[b] = 1;
    taken[e] = 1 + v.dir;
  }
  std::vector<int32_t> vmap, kept;
  sm.compact(vmap, kept);
  return taken;
}

// Without the early tests the device takes exactly the host's edges in the same directions, and
// its in-place collapses leave exactly the host's mesh (positions, tets and their vertex order,
// labels), for every input.
void expect_takes_what_the_host_takes() {
  Context ctx;
  for (const Input& in : inputs()) {
    SCOPED_TRACE(in.name);
    MatchStage st(ctx, in.mesh, in.options, in.target, false);
    Mesh host = in.mesh;
    const std::vector<int> expect = host_matching(st, host, in.options);
    std::vector<int> got(st.ne, 0);
    for (uint32_t e = 0; e < st.ne; ++e) got[e] = st.fin[e] ? 1 + st.dir[e] : 0;
    const int n_expect = int(std::count_if(expect.begin(), expect.end(), [](int x) { return x > 0; }));
    EXPECT_GT(n_expect, 0);
    EXPECT_EQ(int(st.taken), n_expect);
    EXPECT_EQ(got, expect);
    expect_same_mesh(st.result(ctx, in.mesh), host, "the result");
  }
}

}  // namespace

TEST(CollapseMatching, TakesWhatTakingTheEdgesInOrderWouldTake) { expect_takes_what_the_host_takes(); }

// The live link test (tcc_link_test) finds N(a) n N(b) through a filter of ring(a)'s vertices
// when ring(a) has at most TCC_LIVE_LINK_RING tets (32) and TCC_MAX_LINK / 3, else through
// tcc_live_common's lists; by default both ways run on these inputs. Each way alone decides every
// live test here, and the host still agrees on every edge: with the cap at 0 the lists, with the
// caps at 100 tets the filter (no ring of these inputs is larger).
TEST(CollapseMatching, LiveLinkTestAgreesWithTheHostOnEachPathAlone) {
  for (const Input& in : inputs()) {  // the rings a test reads are those of the input
    std::vector<int> ring(size_t(in.mesh.num_vertices()), 0);
    for (int32_t v : in.mesh.tets) ++ring[size_t(v)];
    ASSERT_LE(*std::max_element(ring.begin(), ring.end()), 100) << in.name;
  }
  {
    test::EnvVar cap("TETCOLLAPSE_CL_OPTIONS", "-DTCC_LIVE_LINK_RING=0");
    SCOPED_TRACE("tcc_live_common only");
    expect_takes_what_the_host_takes();
  }
  {
    test::EnvVar cap("TETCOLLAPSE_CL_OPTIONS", "-DTCC_LIVE_LINK_RING=100 -DTCC_MAX_LINK=300");
    SCOPED_TRACE("tcc_live_link_common only");
    expect_takes_what_the_host_takes();
  }
}

// With the early tests (the default), the decisions, their rounds, counts, refusals and the mesh
// the collapses leave are the same whether the rounds run as separate launches or in one
// work-group, for every work-group size, and with or without the waiting lists (a waiting edge
// woken when its blocker decides, or sent to every turn list until then); the taken edges form
// a matching, and each of them, tested in the order of its round on the host, passes.
TEST(CollapseMatching, SameAtEveryWorkGroupSizeAndLoopThreshold) {
  Context ctx;
  for (const Input& in : inputs()) {
    SCOPED_TRACE(in.name);
    MatchStage ref(ctx, in.mesh, in.options, in.target, true);
    const Mesh ref_mesh = ref.result(ctx, in.mesh);
    // a matching, valid in round order
    std::vector<uint8_t> used(size_t(in.mesh.num_vertices()), 0);
    std::vector<uint32_t> order;
    for (uint32_t e = 0; e < ref.ne; ++e)
      if (ref.fin[e]) {
        for (int k = 0; k < 2; ++k) {
          EXPECT_EQ(used[ref.edges[2 * e + k]], 0) << "edge " << e;
          used[ref.edges[2 * e + k]] = 1;
        }
        order.push_back(e);
      }
    std::stable_sort(order.begin(), order.end(), [&](uint32_t x, uint32_t y) { return ref.dround[x] < ref.dround[y]; });
    Mesh work = in.mesh;
    sequential_detail::SeqMesh sm(work, sequential_detail::seq_params_from(in.options));
    for (uint32_t e : order) {
      const sequential_detail::Verdict v = sm.check(ref.edges[2 * e], ref.edges[2 * e + 1]);
      EXPECT_EQ(v.reason, kOk) << "edge " << e << " of round " << ref.dround[e];
      EXPECT_EQ(v.dir, ref.dir[e]) << "edge " << e;
      sm.collapse(ref.edges[2 * e], ref.edges[2 * e + 1], ref.dir[e]);
    }
    for (size_t wg : {1, 16, 0})
      for (auto [size, exit] : {std::pair<uint32_t, uint32_t>{0, 0}, {UINT32_MAX, UINT32_MAX}, {4, 8}})
        for (bool waiting : {true, false}) {
          if (!waiting && wg != 0) continue;  // without the waiting lists: at the default size only
          ctx.set_work_group_size(wg);
          MatchStage st(ctx, in.mesh, in.options, in.target, true, size, exit, waiting);
          const std::string what = "work-group size " + std::to_string(wg) + ", loop size " + std::to_string(size) +
                                   ", exit " + std::to_string(exit) + (waiting ? "" : ", no waiting lists");
          EXPECT_EQ(st.fin, ref.fin) << what;
          EXPECT_EQ(st.dir, ref.dir) << what;
          EXPECT_EQ(st.reason, ref.reason) << what;
          for (uint32_t e = 0; e < st.ne; ++e)
            if (ref.fin[e]) {
              EXPECT_EQ(st.dround[e], ref.dround[e]) << what << ", round of edge " << e;
            }
          EXPECT_EQ(st.taken, ref.taken) << what;
          EXPECT_EQ(st.tested, ref.tested) << what;
          expect_same_mesh(st.result(ctx, in.mesh), ref_mesh, what);
        }
    ctx.set_work_group_size(0);
  }
}

// Undoing collapses (as after refusals of the surface guard): every third taken edge refused;
// the undone are the refused and every taken edge of a later round within reach of an undone
// one (N[a] U N[b] on the start mesh holds an end point), and the mesh is the one collapsing
// the others alone, in the order of their rounds, leaves (the host's; positions, tets, labels).
TEST(CollapseMatching, UndoLeavesTheOtherCollapses) {
  Context ctx;
  int64_t undone_beyond = 0;
  for (const Input& in : inputs()) {
    SCOPED_TRACE(in.name);
    MatchStage st(ctx, in.mesh, in.options, in.target, true);
    std::vector<uint32_t> taken, refused;
    for (uint32_t e = 0; e < st.ne; ++e)
      if (st.fin[e]) taken.push_back(e);
    for (size_t i = 0; i < taken.size(); i += 3) refused.push_back(taken[i]);
    const uint32_t undone = matching_undo(ctx, st.dm, st.c, st.s, st.matching, refused);
    const std::vector<uint32_t> fin = st.s.result.edges_are_final.download_range(0, st.ne);
    const std::vector<uint8_t> reason = st.s.result.edges2reason.download_range(0, st.ne);
    // the closure on the host
    std::vector<std::vector<int32_t>> nbr(size_t(in.mesh.num_vertices()));
    for (uint32_t e = 0; e < st.ne; ++e) {
      nbr[st.edges[2 * e]].push_back(st.edges[2 * e + 1]);
      nbr[st.edges[2 * e + 1]].push_back(st.edges[2 * e]);
    }
    std::vector<uint32_t> reach(size_t(in.mesh.num_vertices()), UINT32_MAX);  // first undone round reaching v
    std::vector<uint8_t> out(st.ne, 0);
    for (uint32_t e : refused) out[e] = 1;
    for (bool grew = true; grew;) {
      grew = false;
      std::fill(reach.begin(), reach.end(), UINT32_MAX);
      for (uint32_t d : taken)
        if (out[d])
          for (int k = 0; k < 2; ++k) {
            const int32_t x = st.edges[2 * d + k];
            reach[x] = std::min(reach[x], st.dround[d]);
            for (int32_t z : nbr[x]) reach[z] = std::min(reach[z], st.dround[d]);
          }
      for (uint32_t h : taken)
        if (!out[h] && (reach[st.edges[2 * h]] < st.dround[h] || reach[st.edges[2 * h + 1]] < st.dround[h])) {
          out[h] = 1;
          grew = true;
        }
    }
    const uint32_t n_out = uint32_t(std::count(out.begin(), out.end(), 1));
    EXPECT_EQ(undone, n_out);
    undone_beyond += n_out - refused.size();
    std::vector<uint32_t> keep;
    for (uint32_t e : taken) {
      EXPECT_EQ(fin[e], out[e] ? 0u : 1u) << "edge " << e;
      if (out[e]) {
        EXPECT_EQ(reason[e], refused.end() != std::find(refused.begin(), refused.end(), e) ? kRefusedSurface : kUntested);
      } else {
        keep.push_back(e);
      }
    }
    std::stable_sort(keep.begin(), keep.end(), [&](uint32_t x, uint32_t y) { return st.dround[x] < st.dround[y]; });
    Mesh host = in.mesh;
    {
      sequential_detail::SeqMesh sm(host, sequential_detail::seq_params_from(in.options));
      for (uint32_t e : keep) sm.collapse(st.edges[2 * e], st.edges[2 * e + 1], st.dir[e]);
      std::vector<int32_t> vmap, kept;
      sm.compact(vmap, kept);
    }
    expect_same_mesh(st.result(ctx, in.mesh), host, "after the undo");
  }
  EXPECT_GT(undone_beyond, 0);  // collapses undone for having seen a refused one
}

// The virtual vertex per kind of S (tcc_w_join_ok): an interface edge joining two points of the
// outer boundary (the diagonal cutting the corner of the interface plane z = 0.5 between the
// faces y = 0 and x = 1) would pinch the boundary: refused by the link condition on the device
// and on the host, in free mode where Q lets it through. Its rule, case by case.
TEST(CollapseMatching, LinkConditionPerKindOfSurface) {
  using tc::rules::tcc_w_join_ok;
  const unsigned B = TCC_BOUNDARY, I = TCC_INTERFACE;
  EXPECT_TRUE(tcc_w_join_ok(0, 0, 0));
  EXPECT_TRUE(tcc_w_join_ok(B, 0, 0));
  EXPECT_FALSE(tcc_w_join_ok(B, B, 0));
  EXPECT_TRUE(tcc_w_join_ok(B, B, B));
  EXPECT_FALSE(tcc_w_join_ok(B, I, 0));
  EXPECT_TRUE(tcc_w_join_ok(B, I, I));
  EXPECT_FALSE(tcc_w_join_ok(B | I, B | I, I));  // the pinch
  EXPECT_FALSE(tcc_w_join_ok(B | I, B | I, B));
  EXPECT_TRUE(tcc_w_join_ok(B | I, B | I, B | I));
  EXPECT_TRUE(tcc_w_join_ok(B | I, I, I));
  EXPECT_TRUE(tcc_w_join_ok(B | I, B, B | TCC_RIDGE));

  Context ctx;
  const Mesh m = test::two_materials(4);
  auto vertex = [&](double x, double y, double z) {
    for (int32_t v = 0; v < int32_t(m.num_vertices()); ++v)
      if (m.points[3 * v] == x && m.points[3 * v + 1] == y && m.points[3 * v + 2] == z) return v;
    return int32_t(-1);
  };
  const int32_t a = vertex(0.75, 0.0, 0.5), b = vertex(1.0, 0.25, 0.5);
  ASSERT_GE(a, 0);
  ASSERT_GE(b, 0);
  CollapseOptions o;
  o.boundary = CollapseOptions::Free;
  o.min_quality = 0;
  o.tuning.spatial_order = false;
  StageParams p = params_from(o);
  DeviceMesh dm;
  Connectivity c;
  EdgeState s;
  test::run_to_admissible(ctx, m, p, 10, dm, c, s);
  const std::vector<int32_t> edges = c.edges.download_range(0, 2 * size_t(c.ne));
  const std::vector<uint8_t> reason = s.result.edges2reason.download_range(0, c.ne), eflags = c.eflags.download_range(0, c.ne);
  int32_t e = -1;
  for (uint32_t i = 0; i < c.ne; ++i)
    if (edges[2 * i] == std::min(a, b) && edges[2 * i + 1] == std::max(a, b)) e = int32_t(i);
  ASSERT_GE(e, 0) << "the diagonal is an edge of the mesh";
  EXPECT_EQ(eflags[e] & (TCC_BOUNDARY | TCC_INTERFACE), TCC_INTERFACE);
  EXPECT_EQ(reason[e], kRefusedLink);
  Mesh work = m;
  sequential_detail::SeqMesh sm(work, sequential_detail::seq_params_from(o));
  EXPECT_EQ(sm.check(std::min(a, b), std::max(a, b)).reason, kRefusedLink);
}

// Whole runs with the matching selection (the default): valid, the boundary's topology kept, the
// same mesh at another work-group size and without the work kept across iterations (the carried
// connectivity and verdicts give what building them anew gives), and more collapses per
// iteration than the greedy selection (fewer iterations). The shared polyfem_bimetal (two
// materials) in free mode is the run that showed the pinch of the link condition's rule per kind.
TEST(CollapseMatching, WholeRunsValidDeterministicAndInFewerIterations) {
  Context ctx;
  std::vector<Input> runs;
  const Mesh bracket = read_mesh(test::project_mesh("bracket.msh"));
  for (auto mode : {CollapseOptions::Features, CollapseOptions::Strict, CollapseOptions::Free}) {
    CollapseOptions o;
    o.boundary = mode;
    o.target_factor = 2;
    runs.push_back({"bracket, mode " + std::to_string(int(mode)), bracket, o, 0});
  }
  CollapseOptions two;
  two.boundary = CollapseOptions::Free;
  two.target_factor = 3;
  runs.push_back({"two materials, free", test::two_materials(6), two, 0});
  const std::string bimetal = test::shared_mesh("polyfem_bimetal.msh");
  if (!bimetal.empty()) {
    CollapseOptions o;
    o.boundary = CollapseOptions::Free;
    o.min_quality = 0;
    o.target_factor = 2;
    runs.push_back({"polyfem_bimetal, free", read_mesh(bimetal), o, 0});
  } else {
    std::printf("skipping polyfem_bimetal.msh: absent\n");
  }
  for (const Input& in : runs) {
    SCOPED_TRACE(in.name);
    ASSERT_EQ(in.options.conflicts, CollapseOptions::Matching);
    Mesh out = in.mesh;
    const CollapseReport r = collapse(out, in.options, ctx);
    CheckOptions co;
    co.quality = false;
    co.hausdorff = false;
    const CheckReport check = check_mesh(out, co, &in.mesh);
    EXPECT_TRUE(check.valid) << check_report_text(check);
    EXPECT_FALSE(check.reference.topology_changed);
    EXPECT_LT(out.num_tets(), in.mesh.num_tets());
    for (int variant = 0; variant < 2; ++variant) {
      CollapseOptions o = in.options;
      if (variant == 0) ctx.set_work_group_size(8);
      else o.tuning.reuse_across_iterations = false;
      Mesh again = in.mesh;
      const CollapseReport r2 = collapse(again, o, ctx);
      ctx.set_work_group_size(0);
      expect_same_mesh(again, out, variant == 0 ? "work-group size 8" : "reuse_across_iterations false");
      ASSERT_EQ(r2.iterations.size(), r.iterations.size());
      for (size_t i = 0; i < r.iterations.size(); ++i)
        EXPECT_EQ(r2.iterations[i].collapsed, r.iterations[i].collapsed)
            << (variant == 0 ? "work-group size 8" : "reuse_across_iterations false") << ", iteration " << i;
    }
    CollapseOptions g = in.options;
    g.conflicts = CollapseOptions::Greedy;
    Mesh greedy = in.mesh;
    const CollapseReport rg = collapse(greedy, g, ctx);
    EXPECT_LT(r.iterations.size(), rg.iterations.size());
    EXPECT_GT(r.iterations[0].collapsed, rg.iterations[0].collapsed);
  }
}

namespace {
// The shared meshes on which the matching selection's surface guard refuses collapses (the
// wrenchnut 27k at 3x and the fusee 88k at 1x the median edge length), those present.
std::vector<std::pair<std::string, double>> guard_refusal_runs() {
  std::vector<std::pair<std::string, double>> runs;
  for (auto [name, factor] : {std::pair<const char*, double>{"gen_gmsh_wrenchnut_27k.msh", 3.0},
                              {"gen_gmsh_917_fusee_88k.msh", 1.0}}) {
    const std::string path = test::shared_mesh(name);
    if (!path.empty()) runs.push_back({path, factor});
  }
  return runs;
}

// The matching selection's iterations on `in` (target factor x its median edge length, in the
// spatial order, as collapse() without the host tail); after each selection
// guard(iteration, dm, c, s, matching, p, chosen) runs the surface guard and its undos and returns
// the collapses left. Returns the result.
template <class Guard>
Mesh run_guarded_matching(Context& ctx, const Mesh& in, double factor, const Guard& guard) {
  CollapseOptions o;
  StageParams p = params_from(o);
  p.target = factor * median_edge_length(in);
  DeviceMesh dm, next;
  std::vector<int32_t> vertex_new;  // the spatial order, as collapse() (the refusals depend on the order)
  upload_mesh(ctx, in, o, dm, &vertex_new);
  Connectivity c;
  EdgeState s;
  MatchingState matching;
  DeviceBuffer<int32_t> origin(ctx, 1);
  for (int it = 0; it < 40; ++it) {
    build_connectivity(ctx, dm, c, p, &s);
    carry_verdicts(ctx, dm, c, s);
    cost_and_mark(ctx, dm, c, s, p);
    matching_backup(ctx, dm, matching);
    uint32_t passed_q = 0, tested = 0;
    const uint32_t chosen =
        guard(it, dm, c, s, matching, p, matching_selection(ctx, dm, c, s, matching, p, passed_q, tested));
    if (chosen == 0) break;
    remember_for_carry(ctx, dm, c, s);
    collapse_and_compact(ctx, p, dm, next, c, s, origin, 0);
    note_compaction(ctx, dm, c, s);
  }
  Mesh out = in;
  download_mesh(dm, out);
  return out;
}
}  // namespace

// After the undo of refused collapses, the surface guard tests only the queries near the
// undone ones (SurfaceGuard::restrict_to_undone): on every iteration of runs where the guard
// refuses (guard_refusal_runs), it refuses what a guard testing every query of the result
// refuses (each pair once per query of the pair, as without dedup), and the results
// are valid.
TEST(CollapseMatching, GuardAfterUndoTestsWhatTheUndoChanged) {
  const auto runs = guard_refusal_runs();
  if (runs.empty()) GTEST_SKIP() << "gen_gmsh_wrenchnut_27k.msh and gen_gmsh_917_fusee_88k.msh absent from the shared meshes";
  Context ctx;
  int undos = 0, restricted_queries = 0, full_queries = 0;
  for (const auto& [path, factor] : runs) {
    SCOPED_TRACE(path);
    const Mesh in = read_mesh(path);
    SurfaceGuard guard;
    const Mesh out = run_guarded_matching(ctx, in, factor, [&](int it, DeviceMesh& dm, Connectivity& c, EdgeState& s,
                                                               MatchingState& matching, const StageParams& p,
                                                               uint32_t chosen) {
      while (guard.run_applied(ctx, dm, c, s, p, chosen) > 0) {
        chosen -= matching_undo(ctx, dm, c, s, matching, guard);
        ++undos;
        // a guard testing every query of the result, beside the restricted one the loop runs next
        SurfaceGuard full;
        full.each_pair_once = false;
        const uint32_t full_refused = full.run_applied(ctx, dm, c, s, p, chosen);
        full_queries += int(full.last_queries);
        const std::vector<uint32_t> marked = s.cost.edges_are_marked.download_range(0, c.ne);
        const uint32_t refused = guard.run_applied(ctx, dm, c, s, p, chosen);
        restricted_queries += int(guard.last_queries);
        EXPECT_EQ(refused, full_refused) << "iteration " << it;
        EXPECT_EQ(s.cost.edges_are_marked.download_range(0, c.ne), marked) << "iteration " << it;  // the same ones unmarked
        if (refused == 0) break;
        chosen -= matching_undo(ctx, dm, c, s, matching, guard);
      }
      return chosen;
    });
    CheckOptions co;
    co.quality = false;
    co.hausdorff = false;
    const CheckReport check = check_mesh(out, co, &in);
    EXPECT_TRUE(check.valid) << check_report_text(check);
  }
  EXPECT_GT(undos, 0);
  EXPECT_LT(restricted_queries, full_queries);
}

// The surface guard of the matching selection tests each pair of S faces of the result once, for
// the query of its lowest survivor, and a hit refuses every query of the pair
// (SurfaceGuard::each_pair_once): on every guard run of guard_refusal_runs, it refuses the same
// edges as testing each pair once per query of the pair.
TEST(CollapseMatching, GuardTestsEachPairOnceWithTheSameRefusals) {
  const auto runs = guard_refusal_runs();
  if (runs.empty()) GTEST_SKIP() << "gen_gmsh_wrenchnut_27k.msh and gen_gmsh_917_fusee_88k.msh absent from the shared meshes";
  Context ctx;
  int guard_runs = 0;
  uint32_t refusals = 0;
  for (const auto& [path, factor] : runs) {
    SCOPED_TRACE(path);
    run_guarded_matching(ctx, read_mesh(path), factor, [&](int it, DeviceMesh& dm, Connectivity& c, EdgeState& s,
                                                          MatchingState& matching, const StageParams& p,
                                                          uint32_t chosen) {
      // the refused edges of a guard's last run, flagged (SurfaceGuard::refused_edges)
      auto refused_flags = [&](SurfaceGuard& g) {
        DeviceBuffer<uint8_t> flag(ctx, std::max<size_t>(c.ne, 1));
        DeviceBuffer<uint32_t> list(ctx, std::max<size_t>(c.ne, 1)), count(ctx, 1);
        flag.fill(0);
        count.fill(0u);
        g.refused_edges(ctx, flag, list, count);
        return flag.download_range(0, c.ne);
      };
      for (;;) {
        SurfaceGuard every, once;
        every.each_pair_once = false;
        const uint32_t refused_every = every.run_applied(ctx, dm, c, s, p, chosen);
        EXPECT_FALSE(every.last_run_each_pair_once);
        const std::vector<uint8_t> flags_every = refused_flags(every);
        const uint32_t refused = once.run_applied(ctx, dm, c, s, p, chosen);
        EXPECT_EQ(once.last_run_each_pair_once, once.last_queries > 0);
        guard_runs += once.last_run_each_pair_once ? 1 : 0;
        EXPECT_EQ(refused, refused_every) << "iteration " << it;
        EXPECT_EQ(refused_flags(once), flags_every) << "iteration " << it;  // the same edges refused
        refusals += refused;
        if (refused == 0) return chosen;
        chosen -= matching_undo(ctx, dm, c, s, matching, once);
      }
    });
  }
  EXPECT_GT(guard_runs, 4);
  EXPECT_GT(refusals, 0u);
}
