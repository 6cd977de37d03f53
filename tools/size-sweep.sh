#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# size-sweep.sh [BUILD_DIR [OUT_DIR [HEIGHTS...]]]: `zomefab run` on every mesh of data/ at each
# height (default 200 400 700 mm) with its up axis, one after the other; prints a Markdown table row
# per run (exit code, seconds, peak memory, pieces with their tenons and mounting steps, or the first
# error line). zomefab run checks its outputs with the project's verifier before it names them (exit 3
# and nothing written otherwise). The open bunny runs with --repair, as its error advises.
# The table in docs/benchmarks.md ("Size sweep") comes from this script. Exits 1 when a run neither
# completed nor was refused because the object is too thin for a frame or for one B0 cube (the only
# refusals issue 18 allows; the error must say so first); `ctest -L sweep` (make sweep) runs it so.
set -u
cd "$(dirname "$0")/.."
build=${1:-build}; out=${2:-/tmp/zomefab-sweep}
# mesh:up (data/README.md: the CGAL dino and cheese are z up, the rest y up)
# SWEEP_MESHES="name:up[:option] ..." runs those instead.
meshes=(bunny_cgal_75k:y bunny_npm_3674:y armadillo_cgal_52k:y elephant_cgal_89k:y dino_cgal_8k:z
        cheese_cgal_18k:z bunny_stanford_open_69k:y:--repair)
# size-sweep.sh --meshes: the list above, one name:up[:option] per line (tests/pipeline makes a test of each).
[ "${1:-}" = --meshes ] && { printf '%s\n' "${meshes[@]}"; exit 0; }
[ -n "${SWEEP_MESHES:-}" ] && read -r -a meshes <<< "$SWEEP_MESHES"
shift 2 2>/dev/null || shift $#
heights=("$@"); [ ${#heights[@]} -eq 0 ] && heights=(200 400 700)
mkdir -p "$out"
failed=0
echo "| mesh | height | exit | s | peak MB | result |"
echo "|---|---|---|---|---|---|"
for h in "${heights[@]}"; do
  for m in "${meshes[@]}"; do
    IFS=: read -r name up extra <<< "$m"; dir=$out/$name-$h
    rm -rf "$dir" "$dir.failed"
    start=$(date +%s%N)
    "$build/tools/zomefab" run "data/$name.stl" --up "$up" --height-mm "$h" -o "$dir" -q $extra \
      --report "$out/$name-$h.json" 2> "$out/$name-$h.err"
    rc=$?
    seconds=$(( ($(date +%s%N) - start + 500000000) / 1000000000 ))
    peak=$(grep -o '"peak_rss_bytes": *[0-9]*' "$out/$name-$h.json" 2>/dev/null | grep -o '[0-9]*$')
    if [ $rc -eq 0 ]; then
      result="$(python3 - "$dir/pieces/pieces.json" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
pieces = j["pieces"]; inst = j["installation"]; steps = inst["steps"]
two = sum(1 for p in pieces if len(p["tenons"]) >= 2)
held = sum(1 for s in steps if sum(len(pieces[p]["tenons"]) for p in s["pieces"]) >= 2)
grouped = sum(len(s["pieces"]) for s in steps if len(s["pieces"]) > 1)
glued = len(inst.get("glued_on", []))
print(f"{len(pieces)} pieces, {two} with ≥ 2 tenons; {len(steps)} steps, {held} held by ≥ 2 pegs; "
      f"{grouped} pieces in glued groups, {glued} glued on; {j['summary']['tenons']} tenons; verified")
PY
)"
    else
      result=$(grep -m1 'error:' "$out/$name-$h.err" | sed 's/^zomefab: error: //; s/|/\\|/g')
      [ ${#result} -gt 240 ] && result="${result:0:120} … ${result: -110}"
      # The refusal must lead with the thinness: a plan's problems named first would hide it.
      if ! { [ $rc -eq 3 ] && grep -m1 'error:' "$out/$name-$h.err" |
               grep -q -E 'error: ([^ ]+: )?(object too thin for a Zome frame|the object is thinner than one B0 cube)'; }; then
        failed=$((failed + 1))
      fi
    fi
    printf "| %s | %s | %s | %s | %s | %s |\n" "$name" "$h" "$rc" "$seconds" \
      "$([ -n "$peak" ] && echo $((peak / 1000000)) || echo -)" "$result"
  done
done
[ $failed -eq 0 ] || { echo "$failed run(s) neither completed nor were refused as too thin" >&2; exit 1; }
