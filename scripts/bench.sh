#!/usr/bin/env bash
# The benchmark suite: builds tetcollapse (Release) and runs bench/run_suite.py, then
# bench/plot_suite.py (PNGs in bench/plots/, markdown tables in bench/results/<name>.md).
#   scripts/bench.sh [run_suite.py options]        e.g. scripts/bench.sh --quick
# BUILD_DIR (default build/) and JOBS (default nproc) as for scripts/build.sh; NO_PEER_BUILD=1 does not build bench_peer_cgal. Needs Debian's
# python3-matplotlib for the plots (/usr/bin/python3).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${BUILD_DIR:-$root/build}
jobs=${JOBS:-$(nproc)}
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" --target tetcollapse -j "$jobs"
# the CGAL peer of bench/peers.py (found next to tetcollapse), when the project has it; NO_PEER_BUILD=1 skips it
if [ -z "${NO_PEER_BUILD:-}" ]; then
  cmake --build "$build" --target bench_peer_cgal -j "$jobs" >/dev/null 2>&1 || echo "bench.sh: bench_peer_cgal not built (the CGAL peer will be skipped)"
fi

out=$root/bench/results/suite.json
for a in "$@"; do [ "$a" = --quick ] && out=$root/bench/results/smoke.json; done
outarg=(--out "$out")
prev=
for a in "$@"; do [ "$prev" = --out ] && { out=$a; outarg=(); }; prev=$a; done
/usr/bin/python3 "$root/bench/run_suite.py" --cli "$build/tetcollapse" "${outarg[@]}" "$@"
/usr/bin/python3 "$root/bench/plot_suite.py" "$out" --markdown "${out%.json}.md"
