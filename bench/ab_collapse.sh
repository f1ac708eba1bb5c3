#!/usr/bin/env bash
# Interleaved A/B timing of two bench_collapse binaries (bench/bench_collapse.cpp): runs A, then
# B, N times, each `--runs 1` with the given options, and prints each side's sorted times, the
# ratio of the medians and the median of the N paired ratios (run i of A over run i of B, taken
# a few seconds apart: less moved by the machine's drift than either median). Both sides see
# the same load of the machine, which on a shared host moves single medians by up to 20%
# within minutes; use this to compare two commits.
#   bench/ab_collapse.sh A_BINARY B_BINARY [N] [bench_collapse options...]
# e.g. build the old commit in a worktree:
#   git worktree add /tmp/old <commit> && cmake -S /tmp/old -B /tmp/old/build -DCMAKE_BUILD_TYPE=Release
#   cmake --build /tmp/old/build --target bench_collapse
#   bench/ab_collapse.sh /tmp/old/build/bench/bench_collapse build/bench/bench_collapse 4 --eps-c 0 --min-quality 0
set -euo pipefail
if [ $# -lt 2 ]; then
  sed -n '2,13p' "$0" | sed 's/^# \{0,1\}//'
  exit 2
fi
a=$1 b=$2
shift 2
n=3
if [ $# -gt 0 ] && [[ $1 =~ ^[0-9]+$ ]]; then n=$1; shift; fi
[ $# -gt 0 ] || set -- --eps-c 0 --min-quality 0
one() {  # the wall time of collapse() of one run
  "$1" --runs 1 "${@:2}" 2>&1 | sed -n 's/.*wall time of collapse(): median \([0-9.]*\) s.*/\1/p' | head -1
}
ta=() tb=()
for ((i = 0; i < n; ++i)); do
  ta+=("$(one "$a" "$@")")
  tb+=("$(one "$b" "$@")")
done
median() { printf '%s\n' "$@" | sort -g | awk '{v[NR]=$1} END{print (NR % 2) ? v[(NR+1)/2] : (v[NR/2]+v[NR/2+1])/2}'; }
echo "A $a: $(printf '%s\n' "${ta[@]}" | sort -g | tr '\n' ' ')s"
echo "B $b: $(printf '%s\n' "${tb[@]}" | sort -g | tr '\n' ' ')s"
ma=$(median "${ta[@]}") mb=$(median "${tb[@]}")
awk -v a="$ma" -v b="$mb" 'BEGIN{printf "medians %.3f s -> %.3f s: B is %.2fx the speed of A\n", a, b, a / b}'
ratios=()
faster=0
for ((i = 0; i < n; ++i)); do
  ratios+=("$(awk -v a="${ta[$i]}" -v b="${tb[$i]}" 'BEGIN{printf "%.4f", a / b}')")
  if awk -v a="${ta[$i]}" -v b="${tb[$i]}" 'BEGIN{exit !(b < a)}'; then faster=$((faster + 1)); fi
done
awk -v r="$(median "${ratios[@]}")" -v f="$faster" -v n="$n" \
  'BEGIN{printf "paired: median of A/B %.2fx; B faster in %d of %d pairs\n", r, f, n}'
