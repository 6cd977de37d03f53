#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# glued_chain_test.sh ZOMEFAB DATA_DIR OUTDIR: a glued group that holds its step may take a peg from
# another step; that step's own glue is then tried on top (docs/mounting.md, "Glued to a neighbour
# to be held"). The armadillo at 500 mm: its left leg reaches one ball only (piece 8, one peg); glued
# to the hip (piece 4) the pair is held by two, but the piece beside them (10) lost a peg to the
# pair's tenon, so the trial was undone and 11 of 12 steps were held by two pegs. Now 10 is glued to
# its neighbour in the same trial: every step held by two pegs or more, verified (exit 0).
set -u
zf=$1 data=$2 out=$3
rm -rf "$out" "$out.failed"
"$zf" run "$data/armadillo_cgal_52k.stl" --up y --height-mm 500 -o "$out" -q 2>"$out.err" ||
  { echo "zomefab run failed: $(cat "$out.err")"; exit 1; }
python3 -c "
import json, sys
v = json.load(open('$out/report.json'))['verify']
print(f\"verified: {v['passed']}, {len(v['per_piece'])} pieces in {v['bodies']} steps, {v['bodies_with_two_pegs']} held by two pegs\")
sys.exit(0 if v['passed'] and v['bodies_with_two_pegs'] == v['bodies'] else 1)"
