#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# fuzz-all.sh [SECONDS [TARGET...]]: runs each libFuzzer target of build-fuzz/ (make fuzz) for
# SECONDS (default 300) from its seed corpus fuzz/corpus/<name>/, with its dictionary when there is
# one. New corpus entries go to build-fuzz/corpus/<name>/ (the repository's seeds stay as they are);
# a crash, leak, timeout or out-of-memory input is copied to fuzz/regressions/<name>/, which
# tests/project/fuzz_regressions_test.cpp replays in every `make test`. Prints one line per target:
# executions, corpus size, findings. Exit 1 when any target found something.
set -u
cd "$(dirname "$0")/.."
seconds=${1:-300}; shift || true
targets=("$@")
[ ${#targets[@]} -eq 0 ] && targets=(stl obj ply gltf frame partition pieces manifest vdb)
status=0
for t in "${targets[@]}"; do
  bin=build-fuzz/fuzz/fuzz_$t
  [ -x "$bin" ] || { echo "fuzz-all.sh: $bin missing: run make fuzz first" >&2; exit 2; }
  work=build-fuzz/corpus/$t; artifacts=build-fuzz/artifacts/$t
  mkdir -p "$work" "$artifacts"
  dict=(); [ -f fuzz/dicts/$t.dict ] && dict=(-dict=fuzz/dicts/$t.dict)
  log=build-fuzz/fuzz_$t.log
  # -rss_limit_mb: a reader may not need more than 2 GB for inputs of -max_len (the .vdb seeds are
  # ~84 KB); -timeout: 10 s for one input.
  "$bin" -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=10 -max_len=131072 -print_final_stats=1 \
    -artifact_prefix="$artifacts/" "${dict[@]}" "$work" "fuzz/corpus/$t" > "$log" 2>&1
  rc=$?
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$')
  findings=$(ls "$artifacts" | wc -l)
  if [ "$findings" -gt 0 ] || [ $rc -ne 0 ]; then
    mkdir -p fuzz/regressions/$t
    cp "$artifacts"/* fuzz/regressions/$t/ 2>/dev/null
    status=1
  fi
  echo "fuzz_$t: ${runs:-0} executions in ${seconds} s, corpus $(ls "$work" | wc -l), findings $findings (exit $rc, log $log)"
done
exit $status
