#!/bin/bash
# SPDX-License-Identifier: GPL-3.0-or-later
# The docs' GNU parallel recipe (tools/batch/parallel-run.sh, docs/batch.md) over a 3-entry manifest,
# two entries at a time; then a re-run of one index replaces that entry only.
#   parallel_test.sh ZOMEFAB SOURCE_DIR WORK_DIR
set -euo pipefail
ZF=$1 SRC=$2 work=$3
. "$SRC/tests/batch/batch_test_lib.sh"
command -v parallel > /dev/null || { echo "SKIP: GNU parallel is not installed (Debian package parallel)"; exit 77; }
rm -rf "$work" && mkdir -p "$work"
write_manifest "$work/manifest.json"
[ "$(ZOMEFAB=$ZF "$ZF" batch "$work/manifest.json" --count)" = 3 ] || fail "--count is not 3"
set +e
ZOMEFAB=$ZF "$SRC/tools/batch/parallel-run.sh" "$work/manifest.json" "$work/results" 2 > "$work/log" 2>&1
code=$?
set -e
cat "$work/log"
[ $code = 3 ] || fail "parallel-run.sh exited $code (expected 3: one entry failed)"
check_results "$work/results"

# Re-running index 0 replaces bunny240 and nothing else.
before=$(stat -c %i.%.9Y "$work/results/bunny260.summary.json" "$work/results/bunny260/report.json")
old=$(stat -c %i.%.9Y "$work/results/bunny240/report.json")
sleep 1.1
"$ZF" batch "$work/manifest.json" -o "$work/results" --index 0 -q || fail "re-run of index 0 failed"
[ "$old" != "$(stat -c %i.%.9Y "$work/results/bunny240/report.json")" ] || fail "the re-run did not replace bunny240"
[ "$before" = "$(stat -c %i.%.9Y "$work/results/bunny260.summary.json" "$work/results/bunny260/report.json")" ] ||
    fail "re-running index 0 touched bunny260"
"$ZF" batch "$work/manifest.json" -o "$work/results" --merge -q && fail "merge exited 0 with a failed entry"
check_results "$work/results"
echo "parallel batch: 2 ok, 1 failed (exit 2); re-run of one index replaced only its entry"
