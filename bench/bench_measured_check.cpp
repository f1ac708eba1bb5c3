// The boundary error bound's measured check (collapse/surface_distance.hpp, change_ok) timed
// alone: the checks of a real run, recorded, replayed against the same reference surface.
//
//     TETCOLLAPSE_RECORD_CHECKS=checks.bin build/tetcollapse IN OUT [options]   # record
//     build/bench/bench_measured_check checks.bin [--runs N]                    # replay
//
// Prints the number of checks and of those that passed (the same for two builds whose verdicts
// agree), and the minimum and median over N runs of the time all of them take. A run of the
// whole tool mixes the check with the rest of the run and varies by 20% on a shared machine;
// the replay of the same checks, alternated between two builds, tells a 5% change.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "collapse/surface_distance.hpp"

using namespace tc::surface_distance;

int main(int argc, char** argv) {
  if (argc < 2 || !std::strcmp(argv[1], "--help")) {
    std::fprintf(stderr, "usage: bench_measured_check CHECKS.bin [--runs N]  (record with TETCOLLAPSE_RECORD_CHECKS)\n");
    return 2;
  }
  int runs = 5;
  for (int i = 2; i + 1 < argc; ++i)
    if (!std::strcmp(argv[i], "--runs")) runs = std::max(1, std::atoi(argv[i + 1]));
  std::vector<double> reference;
  std::vector<RecordedCheck> checks;
  if (!read_recorded_checks(argv[1], reference, checks)) {
    std::fprintf(stderr, "bench_measured_check: %s: not a file of recorded checks\n", argv[1]);
    return 2;
  }
  const ReferenceSurface surface(reference);
  std::vector<double> seconds;
  size_t passed = 0;
  for (int r = 0; r < runs; ++r) {
    passed = 0;
    const auto t0 = std::chrono::steady_clock::now();
    for (const RecordedCheck& c : checks) passed += surface.change_ok(c.olds, c.news, c.around, c.e, c.reach);
    seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(seconds.begin(), seconds.end());
  std::printf("%zu reference triangles, %zu checks, %zu passed; %d runs: min %.3f s, median %.3f s\n", surface.size(),
              checks.size(), passed, runs, seconds.front(), seconds[seconds.size() / 2]);
  return 0;
}
