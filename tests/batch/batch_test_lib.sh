# SPDX-License-Identifier: GPL-3.0-or-later
# Shared by the batch tests: the 3-entry manifest (two small runs, one open mesh) and the checks of
# the merged summary. Sourced; expects ZF (the zomefab binary) and SRC (the source tree).

fail() { echo "FAIL: $*" >&2; exit 1; }

# write_manifest FILE: bunny at 240 and 260 mm (about 3 s each) and an open tetrahedron (exit 2).
write_manifest() {
    cat > "$1" <<JSON
{
  "format": "zomefab.batch",
  "version": 1,
  "defaults": {"up": "y", "iterations": 20000, "voxel-mm": 1.5},
  "entries": [
    {"name": "bunny240", "mesh": "$SRC/data/bunny_npm_3674.stl", "options": {"height-mm": 240}},
    {"name": "open", "mesh": "$SRC/tests/cli/fixtures/open_tetra.obj"},
    {"name": "bunny260", "mesh": "$SRC/data/bunny_npm_3674.stl", "options": {"height-mm": 260}}
  ]
}
JSON
}

# check_results DIR: the merged summary has 2 ok and 1 failed entry, the failed one with exit code 2
# and the open mesh named; both good entries have their outputs.
check_results() {
    local dir=$1
    [ -f "$dir/summary.json" ] || fail "no $dir/summary.json"
    [ -f "$dir/summary.md" ] || fail "no $dir/summary.md"
    local ok failed
    ok=$(grep -c '"status": "ok"' "$dir/summary.json" || true)
    failed=$(grep -c '"status": "failed"' "$dir/summary.json" || true)
    [ "$ok" = 2 ] && [ "$failed" = 1 ] || fail "summary has $ok ok and $failed failed (expected 2 and 1)"
    grep -q '"exit_code": 2' "$dir/open.summary.json" || fail "open.summary.json has no exit code 2"
    grep -q '| open | failed |' "$dir/summary.md" || fail "summary.md does not list the failure"
    for name in bunny240 bunny260; do
        grep -q '"exit_code": 0' "$dir/$name.summary.json" || fail "$name did not succeed"
        [ -f "$dir/$name/report.json" ] && [ -f "$dir/$name/frame.json" ] || fail "$name has no outputs"
    done
    ! ls -a "$dir" | grep -q '\.tmp' || fail "staging files left in $dir: $(ls -a "$dir")"
}
