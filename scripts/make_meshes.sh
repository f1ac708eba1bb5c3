#!/usr/bin/env bash
# Regenerates the project's own meshes in meshes/ (the committed files are its output).
# Needs gmsh from Debian (scripts/setup.sh installs it).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
out="$here/../meshes"
command -v gmsh >/dev/null || { echo "make_meshes.sh: gmsh is not installed (apt-get install gmsh)" >&2; exit 2; }
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
# Single thread: the result is deterministic.
(cd "$tmp" && gmsh "$here/bracket.geo" -3 -nt 1 -format msh41 -bin -o "$tmp/bracket.msh" >/dev/null)
mv "$tmp/bracket.msh" "$out/bracket.msh"
echo "wrote $out/bracket.msh"
