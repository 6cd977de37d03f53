#!/usr/bin/env bash
# signal_test.sh SIGNAL ZOMEFAB MESH OUTDIR: starts `zomefab run` on MESH, sends SIGNAL once it is
# working, and checks what docs/cli.md promises: exit 5, a message, no output directory and no
# staging directory left beside it.
set -u
sig=$1 zf=$2 mesh=$3 out=$4
rm -rf "$out" "$out".failed
parent=$(dirname "$out"); name=$(basename "$out")
err=$(mktemp)
"$zf" run "$mesh" --up y --height-mm 300 -o "$out" 2>"$err" &
pid=$!
# Wait until the run has started its first stage (its progress line), at most 20 s.
for _ in $(seq 200); do grep -q "\[" "$err" && break; sleep 0.1; done
kill -s "$sig" $pid
wait $pid
rc=$?
status=0
[ $rc -eq 5 ] || { echo "expected exit 5 after SIG$sig, got $rc"; status=1; }
grep -qi "interrupt\|cancel" "$err" || { echo "no message about the interruption:"; cat "$err"; status=1; }
[ ! -e "$out" ] || { echo "$out exists"; status=1; }
ls -A "$parent" | grep -q "^\.$name\.tmp" && { echo "a staging directory is left:"; ls -A "$parent"; status=1; }
rm -f "$err"
exit $status
