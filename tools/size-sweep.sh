#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# size-sweep.sh [BUILD_DIR [OUT_DIR [HEIGHTS...]]]: `zomefab run` on every mesh of data/ at each
# height (default 200 400 700 mm) with its up axis, one after the other; prints a Markdown table row
# per run (exit code, seconds, peak memory, pieces, or the first error line). zomefab run checks its
# outputs with the project's verifier before it names them (exit 3 and OUT.failed otherwise).
# The table in docs/benchmarks.md ("Size sweep") comes from this script.
set -u
cd "$(dirname "$0")/.."
build=${1:-build}; out=${2:-/tmp/zomefab-sweep}; shift 2 2>/dev/null || shift $#
heights=("$@"); [ ${#heights[@]} -eq 0 ] && heights=(200 400 700)
mkdir -p "$out"
# mesh:up (data/README.md: the CGAL dino and cheese are z up, the rest y up)
meshes=(bunny_cgal_75k:y bunny_npm_3674:y armadillo_cgal_52k:y elephant_cgal_89k:y dino_cgal_8k:z
        cheese_cgal_18k:z bunny_stanford_open_69k:y)
echo "| mesh | height | exit | s | peak MB | result |"
echo "|---|---|---|---|---|---|"
for h in "${heights[@]}"; do
  for m in "${meshes[@]}"; do
    name=${m%%:*}; up=${m##*:}; dir=$out/$name-$h
    rm -rf "$dir" "$dir.failed"
    start=$(date +%s.%N)
    "$build/tools/zomefab" run "data/$name.stl" --up "$up" --height-mm "$h" -o "$dir" -q \
      --report "$out/$name-$h.json" 2> "$out/$name-$h.err"
    rc=$?
    seconds=$(echo "$(date +%s.%N) - $start" | bc)
    peak=$(grep -o '"peak_rss_bytes": *[0-9]*' "$out/$name-$h.json" 2>/dev/null | grep -o '[0-9]*$')
    if [ $rc -eq 0 ]; then
      result="$(ls "$dir"/pieces/piece-*.stl | wc -l) pieces on $(ls "$dir"/plates/plate-*.3mf | wc -l) plates, verified"
    else
      result=$(head -1 "$out/$name-$h.err" | sed 's/^zomefab: error: //; s/|/\\|/g' | cut -c1-160)
    fi
    printf "| %s | %s | %s | %.0f | %s | %s |\n" "$name" "$h" "$rc" "$seconds" \
      "$([ -n "$peak" ] && echo $((peak / 1000000)) || echo -)" "$result"
  done
done
