#!/usr/bin/env bash
# `make demo`: the longest pipeline that exists today, on the bundled Stanford bunny at 400 mm.
set -euo pipefail
build=${1:-build}
out=${2:-out/demo}
mesh=data/bunny_cgal_75k.stl
mkdir -p "$out"
"$build/tools/zf-info" "$mesh" --up y --height-mm 400 --report "$out/info.json" > /dev/null
echo "demo: wrote $out/info.json (mesh checks of $mesh scaled to 400 mm)" >&2
