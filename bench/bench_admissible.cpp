// The link and volume test of the admissible filter alone (cl/collapse_admissible.cl,
// tcc_link_and_volume), on every marked edge of a mesh's first iteration: the stage
// `admissible()`, which tests each candidate once, in edge order. The lazy filter of the
// pipeline runs the same test on far fewer edges (counts in bench/README.md); this
// program measures the test's cost per edge without the rounds around it, so that a change to
// the test can be timed on its own. Prints the median of N launches and the verdict counts
// (which a change that keeps the decisions must keep).
//
//   bench_admissible [MESH] [--runs N] [--target-factor F] [--min-quality Q] [--priority-levels L]
// Defaults (bench_stage_setup.hpp): W1's mesh (robot 514k) and target (2 x median edge length),
// 7 runs, min_quality 0.
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

int main(int argc, char** argv) {
  bench::StageBenchArgs a;
  if (int rc = bench::parse_stage_args("bench_admissible", argc, argv, a); rc >= 0) return rc;
  bench::StageBench b;
  if (!bench::load_stage_bench("bench_admissible", a, b)) return 1;
  auto& [mesh, ctx, p, dm, vertex_new, c] = b;
  const std::string& path = a.path;
  const int runs = a.runs;
  EdgeState s;
  const uint32_t marked = cost_and_mark(ctx, dm, c, s, p);
  std::printf("mesh %s\ndevice %s\n%u edges, %u marked; target %g, min_quality %g\n", path.c_str(),
              ctx.info().name.c_str(), c.ne, marked, p.target, p.min_quality);
  // Two sets: every marked edge (most refusals are by volume, found before the link test), then
  // only the admissible ones (each test runs to its end), as the lazy filter's tests mostly do.
  for (int set = 0; set < 2; ++set) {
    uint32_t adm = admissible(ctx, dm, c, s, p);  // warm-up (the first: kernel build)
    std::vector<double> t;
    for (int r = 0; r < runs; ++r) {
      s.cost.counters.fill(0u);
      auto t0 = std::chrono::steady_clock::now();
      adm = admissible(ctx, dm, c, s, p);  // reads back its counter: the launch is finished
      t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }
    std::vector<uint8_t> reason = s.result.edges2reason.download_range(0, c.ne);
    size_t by[9] = {0};  // by reason; [8]: a code this program does not know
    for (uint8_t r : reason) ++by[r < 8 ? r : 8];
    if (by[8] || by[kUntested] || by[kRefusedSurface])
      std::fprintf(stderr, "bench_admissible: unexpected reasons (%zu unknown, %zu untested, %zu surface)\n", by[8],
                   by[kUntested], by[kRefusedSurface]);
    const size_t tested = by[kOk] + by[kRefusedLink] + by[kRefusedVolume] + by[kRefusedQuality];
    std::sort(t.begin(), t.end());
    const double med = t[t.size() / 2];
    // the launch's time (every edge, the unmarked and Q-refused ones too) over its tests
    std::printf("%s: median %.4f s (min %.4f, max %.4f) over %d runs, %zu tests = %.3f us per test\n",
                set == 0 ? "every marked edge" : "admissible edges only", med, t.front(), t.back(), runs, tested,
                1e6 * med / double(std::max<size_t>(1, tested)));
    std::printf("  verdicts: ok %zu (admissible %u), refused Q %zu, link %zu, volume %zu, quality %zu\n", by[kOk], adm,
                by[kRefusedQ], by[kRefusedLink], by[kRefusedVolume], by[kRefusedQuality]);
    if (set == 0) {  // mark only the admissible edges
      std::vector<uint32_t> m(c.ne);
      for (uint32_t e = 0; e < c.ne; ++e) m[e] = reason[e] == kOk ? 1u : 0u;
      s.cost.edges_are_marked.upload(m);
    }
  }
  return 0;
}
