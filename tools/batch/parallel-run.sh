#!/bin/bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Runs a zomefab batch with GNU parallel, JOBS entries at a time (docs/batch.md), then merges:
#   tools/batch/parallel-run.sh MANIFEST.json RESULTS_DIR [JOBS [parallel options, e.g. -S host1,host2]]
# Across hosts RESULTS_DIR and the manifest must be on a shared file system at the same path.
# Exit 0 when every entry succeeded, 3 when any failed (the merge's exit code).
set -euo pipefail
if [ $# -lt 2 ]; then
    echo "usage: parallel-run.sh MANIFEST.json RESULTS_DIR [JOBS [parallel options...]]" >&2
    exit 1
fi
manifest=$1 results=$2 jobs=${3:-2}
shift $(($# < 3 ? 2 : 3))
zomefab=${ZOMEFAB:-zomefab}
n=$("$zomefab" batch "$manifest" --count)
# One thread per entry: JOBS entries share the machine's cores. An entry's failure is in its summary;
# parallel's own exit code (the number of failed entries) is not the batch's, so it is not fatal here.
seq 0 $((n - 1)) | parallel --will-cite -j "$jobs" "$@" \
    "$zomefab" batch "$manifest" -o "$results" --index {} --threads 1 -q || true
exec "$zomefab" batch "$manifest" -o "$results" --merge
