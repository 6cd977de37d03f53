#!/usr/bin/env bash
# `make demo`: the whole pipeline on the bundled Stanford bunny at 400 mm (README.md).
set -euo pipefail
build=${1:-build}
out=${2:-out/demo}
mesh=data/bunny_cgal_75k.stl
mkdir -p "$(dirname "$out")"
"$build/tools/zomefab" run "$mesh" --up y --height-mm 400 -o "$out"
echo "demo: outputs of $mesh at 400 mm are in $out/: open $out/viewer.html to look at it, $out/assembly.html to build it, print $out/plates/ (README.md lists every file)" >&2
