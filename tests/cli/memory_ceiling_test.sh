#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# memory_ceiling_test.sh ZOMEFAB ZF_SDF MESH OUTDIR: what docs/cli.md promises when memory runs out.
# 1. A running tool's address space is capped at 90 % of the machine's memory and swap
#    (/proc/PID/limits), so a runaway allocation fails inside the tool instead of waking the OOM killer.
# 2. An allocation beyond the cap (here a lower `ulimit -v`, and --max-memory-gb set past the stage's
#    own guard) is exit 3 with one "out of memory" line and no output, not an abort: OpenVDB's
#    destructors allocate while a std::bad_alloc unwinds, which ends in std::terminate.
set -u
zf=$1 sdf=$2 mesh=$3 out=$4
rm -rf "$out"; mkdir -p "$out"
status=0
err=$out/run.err
"$zf" run "$mesh" --up y --height-mm 300 -o "$out/run" 2>"$err" &
pid=$!
for _ in $(seq 200); do grep -q "\[" "$err" && break; sleep 0.1; done
limit=$(awk '/^Max address space/ {print $4}' /proc/$pid/limits)
kill -INT $pid; wait $pid
total=$(awk '/^MemTotal:|^SwapTotal:/ {sum += $2} END {print sum * 1024}' /proc/meminfo)
expected=$(awk -v t="$total" 'BEGIN {printf "%.0f", 0.9 * t}')
# A lower limit set before (a container's, a user's ulimit -v) stays.
inherited=$(ulimit -v)
[ "$inherited" != unlimited ] && [ $((inherited * 1024)) -lt "$expected" ] && expected=$((inherited * 1024))
echo "address space limit $limit bytes, 90 % of memory and swap $expected bytes"
# unistd's mem_unit and /proc/meminfo's kB round differently: within 0.1 %.
awk -v l="$limit" -v e="$expected" 'BEGIN {exit !(l != "unlimited" && l / e > 0.999 && l / e < 1.001)}' ||
  { echo "expected the address space capped at about $expected bytes, got $limit"; status=1; }

(ulimit -v 600000; exec "$sdf" "$mesh" --up y --height-mm 2000 --max-memory-gb 1000 -o "$out/big.vdb") \
  2>"$out/big.err"
rc=$?
cat "$out/big.err"
[ $rc -eq 3 ] || { echo "expected exit 3 when memory runs out, got $rc"; status=1; }
[ "$(wc -l < "$out/big.err")" -eq 1 ] && grep -q "^zf-sdf: error: out of memory" "$out/big.err" ||
  { echo "expected one 'out of memory' line"; status=1; }
[ ! -e "$out/big.vdb" ] || { echo "big.vdb was written"; status=1; }
exit $status
