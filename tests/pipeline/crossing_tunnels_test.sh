#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# crossing_tunnels_test.sh ZOMEFAB OUTDIR: objects whose tunnels cross (docs/mounting.md, "Tunnels
# that cross" and "Three tunnels through one point"). A 300 mm cube with two square tunnels 90 mm
# across, along x and along y, crossing in its middle: the partition's pieces there line both
# tunnels and meet the frame along every direction; the linings are carved along the tunnels' prisms
# and cut into rings, and the run completes and verifies (before: exit 3). The same cube with a third
# tunnel along z through the same point: no lining crosses the crossing's middle there, so the
# linings are cut into staves that slide in along their tunnels and are pushed onto pegs across
# them (steps of two legs); the run completes and verifies (before: exit 3 after one partition).
set -u
zf=$1 out=$2
rm -rf "$out" "$out.failed" "$out".*.stl "$out.three" "$out.three.failed"
. "$(dirname "$0")/made_mesh.sh"
# cube.stl AXES: the cube as 10 × 10 × 10 cells of 30 mm; a tunnel along each axis of AXES takes the
# cells 3 to 5 across it.
cube() {
    make_stl "$1" <<PY
C, n, axes = 30.0, 10, [$2]
def solid(i, j, k):
    if min(i, j, k) < 0 or max(i, j, k) >= n: return False
    mid = lambda a: 3 <= a <= 5
    c = (i, j, k)
    return not any(mid(c[(a + 1) % 3]) and mid(c[(a + 2) % 3]) for a in axes)
for i in range(n):
    for j in range(n):
        for k in range(n):
            if not solid(i, j, k): continue
            for a in range(3):
                for s in (-1, 1):
                    o = [i, j, k]; o[a] += s
                    if solid(*o): continue
                    b, c = (a + 1) % 3, (a + 2) % 3  # the face of the cell on side s of axis a
                    base = [i, j, k]; base[a] += 1 if s > 0 else 0
                    def P(db, dc):
                        q = list(base); q[b] += db; q[c] += dc
                        return tuple(C * (x - n / 2) for x in q)
                    p00, p10, p11, p01 = P(0, 0), P(1, 0), P(1, 1), P(0, 1)
                    tris.extend([(p00, p10, p11), (p00, p11, p01)] if s > 0 else [(p00, p11, p10), (p00, p01, p11)])
PY
}
cube "$out.two.stl" "0, 1"
cube "$out.three.stl" "0, 1, 2"

# 1.5 mm voxels: the same outcome in 3 minutes instead of 5.5 (most of it the rounds of gluing to be held).
run_made "$zf" "$out.two.stl" 300 "$out" "tunnels cross|partitioning again for" --voxel-mm 1.5 ||
    { echo "two tunnels: expected exit 0"; exit 1; }
grep -q "mounting: 2 tunnels cross; their linings carved into [0-9]* pieces along them" "$out.err" ||
    { echo "two tunnels: the linings were not carved"; exit 1; }
python3 - "$out" <<'PY' || exit 1
import json, sys
out = sys.argv[1]
report = json.load(open(f"{out}/report.json"))
assert report["verify"]["passed"], "the verifier failed"
inst = json.load(open(f"{out}/pieces/pieces.json"))["installation"]
steps = inst["steps"]
print(f"two tunnels: {report['verify']['bodies']} mounting steps, {len(inst['glued_on'])} pieces glued on, verified")
PY

run_made "$zf" "$out.three.stl" 300 "$out.three" "three at a time|partitioning again for" --voxel-mm 2 ||
    { echo "three tunnels: expected exit 0"; exit 1; }
grep -q "mounting: 3 tunnels cross three at a time; their linings carved into [0-9]* pieces along them and cut into [0-9]* staves" "$out.three.err" ||
    { echo "three tunnels: the linings were not cut into staves"; exit 1; }
python3 - "$out.three" <<'PY' || exit 1
import json, sys
out = sys.argv[1]
report = json.load(open(f"{out}/report.json"))
assert report["verify"]["passed"], "the verifier failed"
inst = json.load(open(f"{out}/pieces/pieces.json"))["installation"]
steps = inst["steps"]
staves = [s for s in steps if "slide" in s]
assert len(staves) >= 12, f"{len(staves)} steps of two legs, expected a stave per wall of every tunnel's half"
# Staves go on first, x tunnels' first, then y's, then z's; each slides along a grid axis, out of a mouth.
assert steps[:len(staves)] == staves, "a stave goes on after another piece"
axes = [max(range(3), key=lambda k: abs(s["slide"]["grid"][k])) for s in staves]
assert axes == sorted(axes), f"staves not in the order of their axes: {axes}"
for s in staves:
    assert 8.0 <= s["slide"]["lift_mm"] <= 90.0, s
guide = open(f"{out}/assembly.md").read()
assert "Slide it into the tunnel from its mouth" in guide, "the guide does not say how a stave goes on"
print(f"three tunnels: {report['verify']['bodies']} mounting steps, {len(staves)} staves on two legs, verified")
PY
