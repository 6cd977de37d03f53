#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# print_parts_test.sh ZOMEFAB DATA_DIR OUTDIR: with --cut-for-support a piece that needs much support
# however it lies and that no plane cuts into two held halves is printed in two parts glued together
# before mounting (docs/pieces.md, "Printed in parts"). The bunny at 400 mm with a 2.4 mm wall: its
# back and the top of its head are domes; printed in parts, every step is still held by two pegs or
# more, verified (exit 0), each part is in a glued group, and the pieces need less support (the cost
# report's estimate) than the same run without the option.
set -u
zf=$1 data=$2 out=$3
rm -rf "$out" "$out.failed" "$out.plain" "$out.plain.failed"
run() {
  "$zf" run "$data/bunny_cgal_75k.stl" --up y --height-mm 400 --shell-mm 2.4 "$@" -q 2>"${*: -1}.err" ||
    { echo "zomefab run $* failed: $(cat "${*: -1}.err")"; exit 1; }
}
run -o "$out.plain"
run --cut-for-support -o "$out"
python3 -c "
import json, sys
def load(d):
    r = json.load(open(d + '/report.json'))
    p = json.load(open(d + '/pieces/pieces.json'))
    return r, p, sum(x['hollow']['support_mm3'] for x in r['cost']['per_piece'])
r, p, support = load('$out')
_, _, plain = load('$out.plain')
v = r['verify']
splits = p['summary']['print_splits']
glued = {q for pair in p['installation']['glued'] for q in pair}
print(f\"verified: {v['passed']}, {len(v['per_piece'])} pieces in {v['bodies']} steps, \"
      f\"{v['bodies_with_two_pegs']} held by two pegs; {splits} printed in parts, {len(glued)} pieces glued; \"
      f\"support {support / 1000:.0f} cm³ against {plain / 1000:.0f} cm³ without the option\")
ok = v['passed'] and v['bodies_with_two_pegs'] == v['bodies'] and splits >= 1
ok = ok and len(glued) >= splits + 1 and support < 0.9 * plain
sys.exit(0 if ok else 1)"
