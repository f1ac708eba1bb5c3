#!/usr/bin/env bash
# Installs the built project into a temporary prefix, builds examples/ against the installed
# CMake package with find_package(tetcollapse), and runs it on a small mesh.
set -euo pipefail
build=$1 src=$2
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
cmake --install "$build" --prefix "$tmp/prefix" >/dev/null
test -f "$tmp/prefix/include/tetcollapse/collapse.hpp"
test -x "$tmp/prefix/bin/tetcollapse"
cmake -S "$src/examples" -B "$tmp/build" -DCMAKE_PREFIX_PATH="$tmp/prefix" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$tmp/build" -j 2 >/dev/null
out=$("$tmp/build/coarsen" "$src/meshes/bracket.msh" "$tmp/out.mesh")
echo "$out"
case "$out" in *"23925 -> "*valid*) ;; *) echo "unexpected output" >&2; exit 1 ;; esac
test -s "$tmp/out.mesh"
