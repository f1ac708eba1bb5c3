// The greedy selection (CollapseOptions::Greedy, cl/collapse_admissible.cl greedy_*): against a
// host run of its definition (take the admissible edges one after another in priority order,
// skipping each that touches a tet of an edge taken before), for every loop threshold and in
// the exact cost order; its priority against the documented formula; whole runs against the
// two-pass detection; the options and the CLI.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <string>
#include <vector>

#include "collapse/stages.hpp"
#include "stage_inputs.hpp"
#include "tetcollapse/check.hpp"
#include "tetcollapse/collapse.hpp"
#include "tetcollapse/io.hpp"
#include "test_support.hpp"

using namespace tc;
using namespace tc::collapse_detail;

namespace {

using Input = test::StageInput;

// The stage inputs (stage_inputs.hpp: cubes with equal, signed and +-0 costs, the bracket, a
// shared mesh), and cubes with tets taken away (odd links: refusals by the link condition) and
// the bracket in strict mode.
std::vector<Input> inputs() {
  std::vector<Input> in = test::conflict_stage_inputs({"polyfem_screw.msh"});
  const StageParams p = params_from(CollapseOptions{});
  for (uint32_t seed = 1; seed <= 3; ++seed) {
    uint32_t r = seed * 2654435761u;
    const Mesh holes = test::sub_mesh(test::cube_tets(3), [&](int64_t) {
      r = r * 1664525u + 1013904223u;
      return (r >> 24) >= 77;
    });
    for (int mode : {1, 2}) {
      StageParams q = p;
      q.mode = mode;
      in.push_back({"cube with holes " + std::to_string(seed) + " mode " + std::to_string(mode), holes, q,
                    2 * median_edge_length(holes)});
    }
  }
  const Mesh bracket = read_mesh(test::project_mesh("bracket.msh"));
  StageParams strict = p;
  strict.mode = 0;
  in.push_back({"bracket, strict", bracket, strict, 2 * median_edge_length(bracket)});
  return in;
}

// One iteration's greedy selection on the device, and what the host needs to check it: the
// edges, every edge's full test (admissible(): adm), the priority and the selection (fin).
struct GreedyStage {
  DeviceMesh dm;
  Connectivity c;
  EdgeState s;
  uint32_t ne = 0, taken = 0, tested = 0;
  std::vector<int32_t> edges;
  std::vector<uint32_t> adm, fin;
  std::vector<uint8_t> reason;        // of admissible(): every marked edge's full test
  std::vector<uint8_t> greedy_reason; // of the last selection
  std::vector<double> cost, prio;
  std::vector<uint32_t> marked;

  GreedyStage(Context& ctx, const Mesh& m, StageParams p, double target) {
    test::run_to_admissible(ctx, m, p, target, dm, c, s);
    ne = c.ne;
    edges = c.edges.download_range(0, 2 * size_t(ne));
    adm = s.result.edges_are_admissible.download_range(0, ne);
    reason = s.result.edges2reason.download_range(0, ne);
    cost = s.cost.edges2cost.download_range(0, ne);
    marked = s.cost.edges_are_marked.download_range(0, ne);
    select(ctx, p);
  }
  void select(Context& ctx, const StageParams& p, bool keep_verdicts = false) {
    uint32_t passed_q = 0;
    s.carry.verdict_ready = keep_verdicts;  // else every verdict unknown: tested again
    s.cost.counters.fill(0u);               // as before each selection of a run
    taken = greedy_selection(ctx, dm, c, s, p, passed_q, tested);
    fin = s.result.edges_are_final.download_range(0, ne);
    greedy_reason = s.result.edges2reason.download_range(0, ne);
    prio = p.priority_levels > 0 ? s.lazy.edges2priority.download_range(0, ne) : cost;
  }
};

// The definition, one edge after another: the admissible edges in (prio, index) order, each
// taken unless an end point is within reach (N[]) of an edge taken before.
std::vector<uint32_t> host_greedy(const GreedyStage& st, uint32_t nv) {
  std::vector<std::vector<int32_t>> nbr(nv);
  for (uint32_t e = 0; e < st.ne; ++e) {
    nbr[st.edges[2 * e]].push_back(st.edges[2 * e + 1]);
    nbr[st.edges[2 * e + 1]].push_back(st.edges[2 * e]);
  }
  std::vector<uint32_t> order;
  for (uint32_t e = 0; e < st.ne; ++e)
    if (st.adm[e]) order.push_back(e);
  std::sort(order.begin(), order.end(), [&](uint32_t x, uint32_t y) {
    return st.prio[x] < st.prio[y] || (st.prio[x] == st.prio[y] && x < y);
  });
  std::vector<uint8_t> blocked(nv, 0);
  std::vector<uint32_t> fin(st.ne, 0);
  for (uint32_t e : order) {
    const int32_t a = st.edges[2 * e], b = st.edges[2 * e + 1];
    if (blocked[a] || blocked[b]) continue;
    fin[e] = 1;
    for (int32_t x : {a, b}) {
      blocked[x] = 1;
      for (int32_t y : nbr[x]) blocked[y] = 1;
    }
  }
  return fin;
}

}  // namespace

// The device takes exactly the host's edges, with 64 steps and in the exact order; and the same
// edges with the same counts (tested, taken) and refusals whether its rounds run as separate
// launches or in one work-group (the loop thresholds at both extremes), for every work-group
// size, and with or without the waiting lists.
TEST(CollapseGreedy, TakesWhatTakingTheEdgesInOrderWouldTake) {
  Context ctx;
  int64_t link_refusals = 0, volume_refusals = 0;
  for (const Input& in : inputs()) {
    for (double levels : {64.0, 0.0}) {
      StageParams p = in.params;
      p.priority_levels = levels;
      SCOPED_TRACE(in.name + ", priority levels " + std::to_string(levels));
      GreedyStage st(ctx, in.mesh, p, in.target);
      const std::vector<uint32_t> expect = host_greedy(st, st.dm.nv);
      const uint32_t n_expect = std::accumulate(expect.begin(), expect.end(), 0u);
      EXPECT_GT(n_expect, 0u);
      EXPECT_EQ(st.taken, n_expect);
      EXPECT_EQ(st.fin, expect);
      // every taken edge was tested; far fewer than the candidates were
      const int64_t candidates = std::count_if(st.reason.begin(), st.reason.end(),
                                               [](uint8_t r) { return r != kNotMarked && r != kRefusedQ; });
      EXPECT_GE(st.tested, st.taken);
      EXPECT_LT(st.tested, candidates);
      // the selection's own refusals (each also a refusal of the full test)
      for (uint32_t e = 0; e < st.ne; ++e) {
        const uint8_t r = st.greedy_reason[e];
        if (r == kRefusedLink || r == kRefusedVolume) {
          EXPECT_EQ(r, st.reason[e]) << "edge " << e;
        }
        link_refusals += r == kRefusedLink;
        volume_refusals += r == kRefusedVolume;
      }
      const uint32_t taken = st.taken, tested = st.tested;
      const std::vector<uint8_t> reasons = st.greedy_reason;
      for (size_t wg : {0, 1, 16})
        for (auto [size, exit] : {std::pair<uint32_t, uint32_t>{0, 0}, {UINT32_MAX, UINT32_MAX}, {4, 8}})
          for (bool waiting : {true, false}) {
            if (!waiting && wg != 0) continue;  // without the waiting lists: at the default size only
            ctx.set_work_group_size(wg);
            StageParams q = p;
            q.greedy_loop_size = size;
            q.greedy_loop_exit = exit;
            q.waiting_lists = waiting;
            q.target = in.target;
            st.select(ctx, q);
            const std::string what = "work-group size " + std::to_string(wg) + ", loop size " + std::to_string(size) +
                                     ", exit " + std::to_string(exit) + (waiting ? "" : ", no waiting lists");
            EXPECT_EQ(st.fin, expect) << what;
            EXPECT_EQ(st.taken, taken) << what;
            EXPECT_EQ(st.tested, tested) << what;
            EXPECT_EQ(st.greedy_reason, reasons) << what;
          }
      ctx.set_work_group_size(0);
    }
  }
  // both kinds of refusal happen in the selection itself: the link condition runs apart from
  // (after) the volume test
  EXPECT_GT(link_refusals, 10);
  EXPECT_GT(volume_refusals, 50);
}

// A selection again in the same connectivity after some taken edges were dropped, as after a
// refusal of the surface guard (sguard_drop: unmarked, verdict TCC_REFUSED_SURFACE): the
// verdicts of the first selection are kept, among them edges whose volume test passed but
// whose link condition was never needed (TCC_VOLUME_OK, blocked by a taken edge); now they may
// be taken. The result is the host's greedy without the dropped edges.
TEST(CollapseGreedy, SelectingAgainKeepsTheVerdicts) {
  Context ctx;
  int64_t dropped_all = 0, tested_first = 0, tested_again = 0, taken_volume_ok = 0;
  for (const Input& in : inputs()) {
    SCOPED_TRACE(in.name);
    StageParams p = in.params;
    p.target = in.target;
    GreedyStage st(ctx, in.mesh, p, in.target);
    std::vector<uint32_t> marked = st.marked;
    std::vector<uint8_t> verdict = st.s.carry.edges2verdict.download_range(0, st.ne);
    const int64_t volume_ok = std::count(verdict.begin(), verdict.end(), uint8_t(kVolumeOk));
    int64_t dropped = 0, k = 0;
    for (uint32_t e = 0; e < st.ne; ++e)
      if (st.fin[e] && k++ % 3 == 0) {
        marked[e] = 0;
        verdict[e] = uint8_t(kRefusedSurface);
        st.adm[e] = 0;
        ++dropped;
      }
    st.s.cost.edges_are_marked.upload(marked);
    st.s.carry.edges2verdict.upload(verdict);
    const uint32_t tested_before = st.tested;
    st.select(ctx, p, true);
    const std::vector<uint32_t> expect = host_greedy(st, st.dm.nv);
    EXPECT_EQ(st.fin, expect);
    for (uint32_t e = 0; e < st.ne; ++e) taken_volume_ok += st.fin[e] && verdict[e] == kVolumeOk;
    EXPECT_EQ(st.taken, std::accumulate(expect.begin(), expect.end(), 0u));
    EXPECT_LE(st.tested, tested_before);  // kept verdicts are not tested again
    tested_first += tested_before;
    tested_again += st.tested;
    if (volume_ok > 0) dropped_all += dropped;
  }
  EXPECT_GT(dropped_all, 20);
  EXPECT_LT(tested_again, tested_first / 2);
  EXPECT_GT(taken_volume_ok, 10);  // kept TCC_VOLUME_OK verdicts, now taken
}

// The priority is the documented formula: the cost in steps of target / levels, then the hash of
// the index (2654435761 e mod 2^32, over 2^32); unmarked edges keep their cost.
TEST(CollapseGreedy, PriorityIsCostStepThenHash) {
  Context ctx;
  for (const Input& in : inputs()) {
    SCOPED_TRACE(in.name);
    GreedyStage st(ctx, in.mesh, in.params, in.target);
    int marked = 0;
    for (uint32_t e = 0; e < st.ne; ++e) {
      const double expect = st.marked[e] ? std::floor(st.cost[e] / in.target * 64.0) +
                                               double(uint32_t(e * 2654435761u)) * (1.0 / 4294967296.0)
                                         : st.cost[e];
      ASSERT_EQ(st.prio[e], expect) << "edge " << e;
      marked += st.marked[e] != 0;
    }
    EXPECT_GT(marked, 0);
  }
}

// Whole runs: valid, the boundary's topology kept, the same mesh and per-iteration counts at
// another work-group size, and against the paper's two passes on the same input: fewer
// iterations on the bracket (each takes more).
TEST(CollapseGreedy, WholeRunsValidAndNeedFewerIterationsThanTwoPass) {
  Context ctx;
  const Mesh in = read_mesh(test::project_mesh("bracket.msh"));
  CollapseOptions o;
  o.target_factor = 2;
  o.tuning.host_tail = 0;  // every iteration on the device: the counts compare the detections
  o.conflicts = CollapseOptions::Greedy;
  Mesh g = in, again = in, t = in;
  const CollapseReport rg = collapse(g, o, ctx);
  ctx.set_work_group_size(16);
  const CollapseReport ra = collapse(again, o, ctx);
  ctx.set_work_group_size(0);
  EXPECT_EQ(g.points, again.points);
  EXPECT_EQ(g.tets, again.tets);
  ASSERT_EQ(rg.iterations.size(), ra.iterations.size());
  for (size_t i = 0; i < rg.iterations.size(); ++i) {
    EXPECT_EQ(rg.iterations[i].tested, ra.iterations[i].tested) << "iteration " << i;
    EXPECT_EQ(rg.iterations[i].collapsed, ra.iterations[i].collapsed) << "iteration " << i;
  }
  CheckOptions co;
  co.hausdorff = false;
  const CheckReport cg = check_mesh(g, co, &in);
  EXPECT_TRUE(cg.valid) << check_report_text(cg);
  EXPECT_FALSE(cg.reference.topology_changed);
  o.conflicts = CollapseOptions::TwoPass;
  const CollapseReport rt = collapse(t, o, ctx);
  std::printf("bracket: greedy %zu iterations, %lld tets; two-pass %zu iterations, %lld tets\n", rg.iterations.size(),
              (long long)rg.tets_out, rt.iterations.size(), (long long)rt.tets_out);
  EXPECT_LT(rg.iterations.size(), rt.iterations.size());
  EXPECT_GT(rg.iterations[0].collapsed, rt.iterations[0].collapsed);
  for (const IterationStats& s : rg.iterations) {
    if (s.refused_by_guard == 0) {
      EXPECT_EQ(s.selected, s.collapsed);
    }
  }
  o.conflicts = CollapseOptions::Greedy;
  o.tuning.priority_levels = -1;
  Mesh bad = in;
  EXPECT_THROW(collapse(bad, o, ctx), std::invalid_argument);
  o.tuning.priority_levels = NAN;
  EXPECT_THROW(collapse(bad, o, ctx), std::invalid_argument);
}

// The CLI: the matching selection by default (named in the stats), --conflicts picks the others,
// the exact order with --priority-levels 0, and a negative level count refused.
TEST(CollapseGreedy, CommandLine) {
  test::TempDir dir;
  const std::string in = dir.file("cube.mesh"), out = dir.file("out.msh"), stats = dir.file("stats.json");
  write_mesh(in, make_cube_mesh(4));
  const std::string base = std::string(TC_CLI) + " " + in + " " + out + " --target-factor 2 --check --stats " + stats;
  std::string log;
  for (const std::string opts : {"", " --conflicts greedy --priority-levels 0", " --conflicts two-pass"}) {
    SCOPED_TRACE(opts);
    ASSERT_EQ(test::run_command(base + opts, &log), 0) << log;
    EXPECT_NE(log.find("valid"), std::string::npos) << log;
    EXPECT_GT(read_mesh(out).num_tets(), 0);
    const std::string json = test::read_text(stats);
    const std::string name = opts.find("two-pass") != std::string::npos ? "two-pass"
                             : opts.find("greedy") != std::string::npos  ? "greedy"
                                                                         : "matching";
    EXPECT_NE(json.find("\"conflicts\":\"" + name + "\""), std::string::npos) << json.substr(0, 400);
  }
  for (const std::string bad : {" --priority-levels -1", " --priority-levels 8 --conflicts two-pass",
                                 " --priority-levels 8 --method sequential"}) {
    EXPECT_NE(test::run_command(base + bad, &log), 0) << bad;
    EXPECT_NE(log.find("priority-levels"), std::string::npos) << log;
  }
  test::run_command(TC_CLI + std::string(" --help"), &log);
  EXPECT_NE(log.find("--priority-levels"), std::string::npos);
  EXPECT_NE(log.find("greedy"), std::string::npos);
}
