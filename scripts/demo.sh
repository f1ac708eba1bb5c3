#!/usr/bin/env bash
# Quick start, command 1: install what is needed, build, and run the main job on the
# bundled default mesh (meshes/bracket.msh).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/setup.sh"
"$root/scripts/build.sh"
cli="${BUILD_DIR:-$root/build}/tetcollapse"
mesh="$root/meshes/bracket.msh"
"$cli" devices
"$cli" info "$mesh"
