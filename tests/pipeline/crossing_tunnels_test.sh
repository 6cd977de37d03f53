#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# crossing_tunnels_test.sh ZOMEFAB OUTDIR: an object whose tunnels cross (docs/mounting.md, "What is
# not done"). A 300 mm cube with two square tunnels 90 mm across, along x and along y, crossing in
# its middle: the pieces lining them can reach their places only along the tunnels, past the
# crossing, which the planner's straight paths and rings do not do. zomefab run exits 3 after one
# partition (before: three, each as stuck), saying that the pieces placed nowhere line tunnels
# that cross; nothing is written.
set -u
zf=$1 out=$2
rm -rf "$out" "$out.failed" "$out.stl"
. "$(dirname "$0")/made_mesh.sh"
make_stl "$out.stl" <<'PY'
C, n = 30.0, 10  # the cube as 10 × 10 × 10 cells of 30 mm; the tunnels take cells 3 to 5 across
def solid(i, j, k):
    if min(i, j, k) < 0 or max(i, j, k) >= n: return False
    mid = lambda a: 3 <= a <= 5
    return not ((mid(j) and mid(k)) or (mid(i) and mid(k)))
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
"$zf" run "$out.stl" --up z --height-mm 300 -o "$out" -v 2>"$out.err"
rc=$?
grep -E "partitioning again for|line tunnels" "$out.err" | cut -c1-400
[ $rc -eq 3 ] || { echo "zomefab run exited $rc, expected 3"; tail -3 "$out.err"; exit 1; }
grep -q "error: the pieces cannot be put on the frame: [0-9]* of the [0-9]* pieces placed nowhere line tunnels through the object that cross each other (2 straight tunnels" "$out.err" ||
    { echo "the error does not name the crossing tunnels"; tail -1 "$out.err"; exit 1; }
! grep -q "partitioning again for smaller" "$out.err" || { echo "it partitioned again"; exit 1; }
[ ! -e "$out" ] || { echo "$out was written"; exit 1; }
echo "exit 3 after one partition, naming the crossing tunnels"
