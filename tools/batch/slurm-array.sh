#!/bin/bash
# SPDX-License-Identifier: GPL-3.0-or-later
# One task of a zomefab batch under a Slurm job array: task I runs manifest entry I (docs/batch.md).
#   sbatch --array=0-$((n - 1)) tools/batch/slurm-array.sh MANIFEST.json RESULTS_DIR
# (tools/batch/slurm-submit.sh sets the range from the manifest and queues the merge after it.)
# Every task writes only RESULTS_DIR/<name>/ and RESULTS_DIR/<name>.summary.json of its own entry,
# so tasks can share RESULTS_DIR on a shared file system. The task fails (exit 3) when its entry failed.
#SBATCH --job-name=zomefab
#SBATCH --cpus-per-task=2
#SBATCH --mem=4G
#SBATCH --time=00:30:00
set -euo pipefail
if [ $# -ne 2 ] || [ -z "${SLURM_ARRAY_TASK_ID:-}" ]; then
    echo "usage: sbatch --array=0-N slurm-array.sh MANIFEST.json RESULTS_DIR" >&2
    exit 1
fi
exec "${ZOMEFAB:-zomefab}" batch "$1" -o "$2" --index "$SLURM_ARRAY_TASK_ID" \
    --threads "${SLURM_CPUS_PER_TASK:-1}"
