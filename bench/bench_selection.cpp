// The selection stage alone: the greedy selection (greedy_selection) and the matching
// selection (matching_selection) of one iteration, repeated on the same connectivity, so that a
// change to either can be timed without the rest of the pipeline and the machine's noise over a
// whole run. Iteration K's input is made by running K whole iterations of the pipeline's
// stages first (matching selection, guard not run). Before each repetition the mesh the matching
// selection collapses in place is copied back and the kept verdicts are dropped (every
// repetition tests from scratch, as the first iteration does). Prints the median and minimum of
// N repetitions and the counts (taken, tests), which a change that keeps the decisions keeps.
//
//   bench_selection [MESH] [--runs N] [--iteration K] [--target-factor F] [--min-quality Q]
//                   [--priority-levels L] [--no-early-tests] [--loop SIZE EXIT] [--waiting-ab]
// Defaults (bench_stage_setup.hpp): W1's mesh (robot 514k) and target (2 x median edge length),
// 7 runs, iteration 0, min_quality 0; --loop: the rounds run in one work-group once a turn list
// holds at most SIZE edges, back to per-round kernels above EXIT (StageParams::greedy_loop_size,
// greedy_loop_exit); --waiting-ab: each selection also without its waiting lists
// (StageParams::waiting_lists) in the same repetitions, the order switched each time.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "bench_stage_setup.hpp"

using namespace tc;
using namespace tc::collapse_detail;

namespace {

double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

struct Timing {
  std::vector<double> t;
  uint32_t taken = 0, tested = 0;
  double median() {
    std::sort(t.begin(), t.end());
    return t[t.size() / 2];
  }
};

}  // namespace

int main(int argc, char** argv) {
  bench::StageBenchArgs a;
  int iteration = 0;
  bool early = true, waiting_ab = false;
  uint32_t loop_size = StageParams{}.greedy_loop_size, loop_exit = StageParams{}.greedy_loop_exit;
  auto own = [&](int& i) {
    if (!std::strcmp(argv[i], "--no-early-tests")) {
      early = false;
      return true;
    }
    if (!std::strcmp(argv[i], "--waiting-ab")) {
      waiting_ab = true;
      return true;
    }
    if (!std::strcmp(argv[i], "--iteration") && i + 1 < argc) {
      iteration = std::max(0, std::atoi(argv[++i]));
      return true;
    }
    if (std::strcmp(argv[i], "--loop") || i + 2 >= argc) return false;
    loop_size = uint32_t(std::atoi(argv[++i]));
    loop_exit = uint32_t(std::atoi(argv[++i]));
    return true;
  };
  if (int rc = bench::parse_stage_args("bench_selection", argc, argv, a, own); rc >= 0) return rc;
  bench::StageBench b;
  if (!bench::load_stage_bench("bench_selection", a, b)) return 1;
  auto& [mesh, ctx, p, dm, vertex_new, c] = b;
  const std::string& path = a.path;
  const int runs = a.runs;
  p.match_early_tests = early;
  p.greedy_loop_size = loop_size;
  p.greedy_loop_exit = loop_exit;
  DeviceMesh next;
  EdgeState s;
  MatchingState m;
  DeviceBuffer<int32_t> origin(ctx, 1);
  uint32_t passed_q = 0, tested = 0;
  for (int it = 0; it < iteration; ++it) {  // the earlier iterations, matching
    cost_and_mark(ctx, dm, c, s, p);
    s.carry.verdict_ready = false;
    matching_backup(ctx, dm, m);
    matching_selection(ctx, dm, c, s, m, p, passed_q, tested);
    collapse_and_compact(ctx, p, dm, next, c, s, origin, 0);
    build_connectivity(ctx, dm, c, p);
  }
  const uint32_t marked = cost_and_mark(ctx, dm, c, s, p);
  std::printf("mesh %s\ndevice %s\niteration %d: %u vertices, %u tets, %u edges, %u marked; target %g, min_quality %g, "
              "priority levels %g, early tests %s\n",
              path.c_str(), ctx.info().name.c_str(), iteration, dm.nv, dm.nt, c.ne, marked, p.target, p.min_quality,
              p.priority_levels, early ? "on" : "off");
  // the mesh as it is, for the matching selection's repetitions
  DeviceBuffer<int32_t> tets0(ctx, 1), nbr0(ctx, 1);
  DeviceBuffer<double> pts0(ctx, 1), vf0(ctx, 1);
  tets0.copy_from(dm.tets, size_t(dm.nt) * 4);
  nbr0.copy_from(c.tet_nbr, size_t(dm.nt) * 4);
  pts0.copy_from(dm.points, size_t(dm.nv) * 3);
  vf0.copy_from(dm.vfields, size_t(dm.nv) * dm.vfield_comps);
  // with --waiting-ab each selection also without its waiting lists, the order switched in every
  // repetition
  Timing greedy, matching, greedy_nw, matching_nw;
  auto time_one = [&](Timing& t, bool match, bool waiting) {
    p.waiting_lists = waiting;
    s.cost.counters.fill(0u);
    s.cost.counters.upload(&marked, 1, 0);
    s.carry.verdict_ready = false;
    const double t0 = now();
    t.taken = match ? matching_selection(ctx, dm, c, s, m, p, passed_q, t.tested)
                    : greedy_selection(ctx, dm, c, s, p, passed_q, t.tested);
    ctx.finish();
    t.t.push_back(now() - t0);
    if (!match) return;
    dm.tets.copy_from(tets0, size_t(dm.nt) * 4);
    c.tet_nbr.copy_from(nbr0, size_t(dm.nt) * 4);
    dm.points.copy_from(pts0, size_t(dm.nv) * 3);
    dm.vfields.copy_from(vf0, size_t(dm.nv) * dm.vfield_comps);
  };
  for (int r = 0; r < runs; ++r) {  // alternately, so that all see the same load
    const bool flip = waiting_ab && r % 2;
    for (bool waiting : {!flip, flip}) {
      if (!waiting_ab && !waiting) continue;
      time_one(waiting ? greedy : greedy_nw, false, waiting);
      time_one(waiting ? matching : matching_nw, true, waiting);
    }
  }
  std::vector<std::pair<const char*, Timing*>> rows = {{"greedy", &greedy}, {"matching", &matching}};
  if (waiting_ab)
    rows.insert(rows.end(), {{"greedy, no waiting lists,", &greedy_nw}, {"matching, no waiting lists,", &matching_nw}});
  for (auto [name, t] : rows) {
    const double med = t->median();
    std::printf("%-8s selection: median %.4f s, min %.4f s over %d runs; %u taken, %u tests; %.1f us per collapse\n", name,
                med, t->t.front(), runs, t->taken, t->tested, 1e6 * med / std::max(1u, t->taken));
  }
  return 0;
}
