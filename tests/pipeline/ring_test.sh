#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# ring_test.sh ZOMEFAB OUTDIR: an object with a hole through it (docs/mounting.md, "Keystones").
# A torus 440 mm across, its tube 140 mm thick (so a B0 cube fits inside): the pieces lining the
# hole form a ring whose cut faces meet toward the hole, and before keystones no order existed
# ("pieces 0 + 4 + 7 + 14 (glued), pieces 13 + 16 + 17 + 18 (glued) and piece 19 cannot be put on
# in any order", exit 3 after three partitions). Now a keystone is cut out of the ring and the run
# passes its verifier (exit 0), about a minute.
set -u
zf=$1 out=$2
rm -rf "$out" "$out.failed" "$out.stl"
. "$(dirname "$0")/made_mesh.sh"
make_stl "$out.stl" <<'PY'
R, r, N, M = 150.0, 70.0, 96, 48  # centre circle and tube radius (mm), segments around each
def point(i, j):
    u, v = 2 * math.pi * (i % N) / N, 2 * math.pi * (j % M) / M
    return ((R + r * math.cos(v)) * math.cos(u), (R + r * math.cos(v)) * math.sin(u), r * math.sin(v))
for i in range(N):
    for j in range(M):
        a, b, c, d = point(i, j), point(i + 1, j), point(i + 1, j + 1), point(i, j + 1)
        tris += [(a, b, c), (a, c, d)]
PY
run_made "$zf" "$out.stl" 140 "$out" "keystone|cannot be put on" || exit 1
grep -q "a keystone cut out of it" "$out.err" || { echo "no keystone was cut"; exit 1; }
python3 -c "
import json, sys
v = json.load(open('$out/report.json'))['verify']
print(f\"verified: {v['passed']}, {len(v['per_piece'])} pieces in {v['bodies']} steps, {v['bodies_with_two_pegs']} held by two pegs\")
sys.exit(0 if v['passed'] and v['bodies_with_two_pegs'] == v['bodies'] else 1)"
