#!/usr/bin/env bash
# expect_exit.sh CODE REGEX [--no-file PATH]... [--not REGEX]... -- COMMAND...
# Runs COMMAND; fails unless it exits with CODE, its stderr matches the extended REGEX (on one line)
# and none of the --not ones, and none of the --no-file paths exists afterwards, nor a temporary
# of one (no partial outputs).
set -u
code=$1; regex=$2; shift 2
nofiles=()
nots=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do
  [ "$1" = "--no-file" ] && { nofiles+=("$2"); shift 2; continue; }
  [ "$1" = "--not" ] && { nots+=("$2"); shift 2; continue; }
  echo "expect_exit.sh: unknown argument $1" >&2; exit 2
done
shift
for f in "${nofiles[@]+"${nofiles[@]}"}"; do rm -rf "$f"; done
err=$(mktemp)
"$@" > /dev/null 2> "$err"
actual=$?
status=0
if [ "$actual" -ne "$code" ]; then echo "FAIL: exit code $actual, expected $code: $*" >&2; status=1; fi
if ! grep -Eq -- "$regex" "$err"; then echo "FAIL: stderr does not match /$regex/" >&2; status=1; fi
for n in "${nots[@]+"${nots[@]}"}"; do
  if grep -Eq -- "$n" "$err"; then echo "FAIL: stderr matches /$n/" >&2; status=1; fi
done
for f in "${nofiles[@]+"${nofiles[@]}"}"; do
  if [ -e "$f" ]; then echo "FAIL: $f was written" >&2; status=1; fi
done
# A temporary file is ".NAME.tmpPID" beside its target. Only the named outputs' own are looked for:
# ctest runs other tests in the same directory at the same time, and their temporaries are theirs.
for f in "${nofiles[@]+"${nofiles[@]}"}"; do
  if ls -a "$(dirname "$f")" 2>/dev/null | grep -qF ".$(basename "$f").tmp"; then
    echo "FAIL: a temporary file of $f was left behind" >&2; status=1
  fi
done
echo "--- stderr:" >&2; cat "$err" >&2; rm -f "$err"
exit $status
