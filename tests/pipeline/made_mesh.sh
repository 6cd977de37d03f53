# SPDX-License-Identifier: GPL-3.0-or-later
# Sourced by the pipeline tests that make their own mesh (ring_test.sh, tunnel_test.sh).

# make_stl OUT.stl < PYTHON: runs PYTHON, which fills the list `tris` with triangles (three
# points each, mm; math is imported), and writes them to OUT.stl as binary STL.
make_stl() {
    {
        echo "import math, struct, sys"
        echo "tris = []"
        cat
        cat <<'PY'
with open(sys.argv[1], "wb") as f:
    f.write(b"zomefab test mesh".ljust(80, b" ") + struct.pack("<I", len(tris)))
    for t in tris:
        f.write(struct.pack("<12fH", 0, 0, 0, *t[0], *t[1], *t[2], 0))
PY
    } | python3 - "$1"
}

# run_made ZOMEFAB MESH HEIGHT_MM OUTDIR PATTERN [OPTION...]: `zomefab run MESH --up z [OPTION...]`
# into OUTDIR, prints its stderr lines matching PATTERN and the verifier's; fails (1) unless zomefab
# exits 0.
run_made() {
    "$1" run "$2" --up z --height-mm "$3" -o "$4" -v "${@:6}" 2>"$4.err"
    local rc=$?
    grep -E "$5|verify:" "$4.err" | cut -c1-300
    [ $rc -eq 0 ] || { echo "zomefab run exited $rc"; tail -3 "$4.err"; return 1; }
}
