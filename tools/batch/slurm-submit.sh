#!/bin/bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Queues a whole zomefab batch on Slurm (docs/batch.md): a job array with one task per manifest entry,
# then a merge job that runs after every task has ended, whatever their exit codes.
#   tools/batch/slurm-submit.sh MANIFEST.json RESULTS_DIR [sbatch options for the array tasks...]
# Prints the merge job's id on stdout. `zomefab` is taken from PATH unless ZOMEFAB names it.
set -euo pipefail
if [ $# -lt 2 ]; then
    echo "usage: slurm-submit.sh MANIFEST.json RESULTS_DIR [sbatch options...]" >&2
    exit 1
fi
manifest=$1 results=$2
shift 2
zomefab=${ZOMEFAB:-zomefab}
n=$("$zomefab" batch "$manifest" --count)
here=$(cd "$(dirname "$0")" && pwd)
array=$(sbatch --parsable --array=0-$((n - 1)) "$@" "$here/slurm-array.sh" "$manifest" "$results")
array=${array%%;*}
merge=$(sbatch --parsable --job-name=zomefab-merge --dependency=afterany:"$array" --cpus-per-task=1 \
    --mem=1G --time=00:10:00 --wrap "$(printf '%q ' "$zomefab" batch "$manifest" -o "$results" --merge)")
echo "${merge%%;*}"
