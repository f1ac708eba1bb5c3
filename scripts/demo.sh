#!/usr/bin/env bash
# Quick start, command 1: install what is needed, build, and run the main job on the
# bundled default mesh: coarsen meshes/bracket.msh to twice its median edge length,
# check the result and print the summary.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/setup.sh"
"$root/scripts/build.sh"
cli="${BUILD_DIR:-$root/build}/tetcollapse"
mesh="$root/meshes/bracket.msh"
out="${OUT:-$root/build/bracket_coarse.msh}"
"$cli" devices
"$cli" info "$mesh"
"$cli" "$mesh" "$out" --target-factor 2 --check --stats "${out%.*}.json"
"$cli" info "$out"
