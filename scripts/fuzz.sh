#!/usr/bin/env bash
# Builds the libFuzzer harnesses of the mesh readers with clang (ASan + UBSan) in
# build-fuzz/ and runs one or all of them.
#   scripts/fuzz.sh [SECONDS] [HARNESS...]      HARNESS: gmsh medit vtk vtu tetgen (default: all)
#   scripts/fuzz.sh --coverage [HARNESS...]     line coverage of each reader reached by the
#                                               corpus of earlier runs (build-fuzzcov/, llvm-cov)
#   SECONDS defaults to 60; each harness runs that long, one after the other
#   (JOBS=N runs N at a time). Environment: BUILD_DIR, MAX_LEN (default 16384), NICE (default 19),
#   MALLOC_LIMIT_MB (default 256: a larger single allocation is a finding),
#   EXTRA_SEEDS=DIR (extra read-only seeds in DIR/<harness>/, e.g. heads of local meshes),
#   TC_FUZZ_ROUNDTRIP=1 (also write every accepted mesh and read it back; see fuzz_harness.hpp).
# Needs clang and libFuzzer: Debian packages clang and libclang-rt-14-dev (clang 14, bookworm).
# The working corpus grows in BUILD_DIR/corpus/<harness> (seeded from tests/fuzz/seeds/);
# crashers land in BUILD_DIR/crashes/<harness>/, logs in BUILD_DIR/logs/. To keep a crasher
# as a regression test, copy it to tests/data/fuzz/<harness>/ (tests/io/test_fuzz_regressions).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${BUILD_DIR:-$root/build-fuzz}

# Source files of each reader, for the coverage report.
reader_files() {
  case $1 in
    gmsh) echo host/io/gmsh.cpp ;;
    medit) echo host/io/medit.cpp ;;
    vtk) echo host/io/vtk.cpp host/io/vtk_common.cpp ;;
    vtu) echo host/io/vtu.cpp host/io/vtk_common.cpp ;;
    tetgen) echo host/io/tetgen.cpp ;;
  esac
}

if [[ "${1:-}" == "--coverage" ]]; then
  shift
  harnesses=("$@")
  ((${#harnesses[@]})) || harnesses=(gmsh medit vtk vtu tetgen)
  cov=${COV_BUILD_DIR:-$root/build-fuzzcov}
  v=$(clang++ --version | sed -n 's/.*clang version \([0-9]*\).*/\1/p')
  cmake -S "$root" -B "$cov" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ \
        -DTETCOLLAPSE_FUZZ=ON -DTETCOLLAPSE_FUZZ_COVERAGE=ON -DTETCOLLAPSE_BUILD_BENCH=OFF >/dev/null
  targets=()
  for h in "${harnesses[@]}"; do targets+=("fuzz_$h"); done
  nice -n "${NICE:-19}" cmake --build "$cov" --target "${targets[@]}" -j "${BUILD_JOBS:-2}" >/dev/null
  for h in "${harnesses[@]}"; do
    corpus=$build/corpus/$h
    [[ -d "$corpus" ]] || corpus=$root/tests/fuzz/seeds/$h
    rm -f "$cov/$h".profraw "$cov/$h".profdata
    # -runs=0: execute every corpus input once, no fuzzing.
    LLVM_PROFILE_FILE="$cov/$h.profraw" nice -n "${NICE:-19}" "$cov/tests/fuzz/fuzz_$h" "$corpus" -runs=0 >/dev/null 2>&1
    "llvm-profdata-$v" merge -sparse "$cov/$h.profraw" -o "$cov/$h.profdata"
    echo "coverage of $h by $(find "$corpus" -type f | wc -l) inputs in $corpus:"
    # shellcheck disable=SC2046
    "llvm-cov-$v" report "$cov/tests/fuzz/fuzz_$h" -instr-profile="$cov/$h.profdata" \
        $(for f in $(reader_files "$h"); do echo "$root/$f"; done) | sed 's/^/  /'
    # The same files without their writing functions (the harnesses only read).
    # shellcheck disable=SC2046
    "llvm-cov-$v" export -format=lcov "$cov/tests/fuzz/fuzz_$h" -instr-profile="$cov/$h.profdata" \
        $(for f in $(reader_files "$h"); do echo "$root/$f"; done) | python3 "$root/scripts/fuzz_reader_coverage.py"
  done
  exit 0
fi
seconds=${1:-60}
[[ $# -gt 0 ]] && shift
harnesses=("$@")
((${#harnesses[@]})) || harnesses=(gmsh medit vtk vtu tetgen)
jobs=${JOBS:-1}
max_len=${MAX_LEN:-16384}
nice_level=${NICE:-19}
# A single allocation above this from an input of at most MAX_LEN bytes can only come from
# a count taken on trust; libFuzzer reports it as an out-of-memory finding.
malloc_limit=${MALLOC_LIMIT_MB:-256}

command -v clang++ >/dev/null || { echo "fuzz: clang++ not found (apt-get install clang libclang-rt-14-dev)" >&2; exit 1; }
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ \
      -DTETCOLLAPSE_FUZZ=ON -DTETCOLLAPSE_BUILD_BENCH=OFF >/dev/null
targets=()
for h in "${harnesses[@]}"; do targets+=("fuzz_$h"); done
nice -n "$nice_level" cmake --build "$build" --target "${targets[@]}" -j "${BUILD_JOBS:-2}"

run() {
  local h=$1 corpus=$build/corpus/$1 crashes=$build/crashes/$1/ log=$build/logs/$1.log
  mkdir -p "$corpus" "$crashes" "$build/logs"
  # Start from the committed seeds (and keep what earlier runs found).
  cp -n "$root/tests/fuzz/seeds/$h/"* "$corpus/" 2>/dev/null || true
  local extra=()
  [[ -n "${EXTRA_SEEDS:-}" && -d "$EXTRA_SEEDS/$h" ]] && extra=("$EXTRA_SEEDS/$h")
  echo "fuzz: $h for ${seconds}s -> $log"
  # Fork mode with ignore_*: a crash, timeout or OOM is saved to $crashes and the run goes
  # on for its whole time instead of stopping at the first finding.
  local rc=0
  nice -n "$nice_level" "$build/tests/fuzz/fuzz_$h" "$corpus" "${extra[@]}" \
      -fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1 -print_funcs=0 \
      -dict="$root/tests/fuzz/dicts/$h.dict" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=4096 \
      -malloc_limit_mb="$malloc_limit" \
      -max_len="$max_len" -artifact_prefix="$crashes" >"$log" 2>&1 || rc=$?
  # Summary: the last status line (executions, coverage, exec/s, oom/timeout/crash counts).
  echo "fuzz: $h: $(grep -E '^#[0-9]+' "$log" | tail -1)"
  local found
  found=$(find "$crashes" -type f | wc -l)
  if ((rc != 0 || found > 0)); then
    echo "fuzz: $h FOUND A PROBLEM (exit $rc, $found files in $crashes); see $log" >&2
    return 1
  fi
}

status=0
if ((jobs <= 1)); then
  for h in "${harnesses[@]}"; do run "$h" || status=1; done
else
  for h in "${harnesses[@]}"; do
    run "$h" &
    while (($(jobs -rp | wc -l) >= jobs)); do wait -n || status=1; done
  done
  while (($(jobs -rp | wc -l) > 0)); do wait -n || status=1; done
fi
exit $status
