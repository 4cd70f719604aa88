#!/usr/bin/env bash
# tools/tsan_startup_only.sh on made-up ctest logs: true only when tests failed and every failure is ThreadSanitizer's
# start-up failure (then tools/test.sh runs them again); a real failure beside it, a run without failures, a failure
# that merely mentions ThreadSanitizer elsewhere, and a missing log all keep their verdict.
set -euo pipefail
script=${1:?usage: check_tsan_startup_only.sh tools/tsan_startup_only.sh}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT

# One test's block as ctest writes it to LastTest.log: name, output, verdict ("Passed" or "Failed").
block() {
  printf '1/9 Testing: %s\n1/9 Test: %s\nCommand: "x"\nOutput:\n----------\n%s\n<end of output>\n' "$1" "$1" "$2"
  printf 'Test time =   0.01 sec\n----------\nTest %s.\n"%s" end time: now\n----------\n' "$3" "$1"
}
startup='==7==ERROR: ThreadSanitizer failed to allocate 0x1000 (4096) bytes at address 7f0000 (errno: 12)'
expect() {  # expect 0|1 name: the script's exit status on $dir/name.log
  local got=0
  "$script" "$dir/$2.log" || got=$?
  if [ "$got" != "$1" ]; then
    echo "FAIL: $2: exit $got, expected $1"
    exit 1
  fi
  echo "ok: $2 -> $got"
}

{ block A.one "fine" Passed; block A.two "$startup" Failed; } > "$dir/startup.log"
expect 0 startup
{ block B.one "$startup" Failed; block B.two "$startup" Failed; block B.three "fine" Passed; } > "$dir/two.log"
expect 0 two
{ block C.one "$startup" Failed; block C.two "Expected: 3, actual: 4" Failed; } > "$dir/real.log"
expect 1 real
{ block D.one "Expected: 3, actual: 4" Failed; block D.two "$startup" Failed; } > "$dir/real-first.log"
expect 1 real-first
# The signature in a passing test's output does not carry over to the next test's failure.
{ block E.one "$startup" Passed; block E.two "WARNING: ThreadSanitizer: data race" Failed; } > "$dir/carry.log"
expect 1 carry
{ block F.one "fine" Passed; } > "$dir/none.log"
expect 1 none
expect 1 missing
echo "check_tsan_startup_only: OK"
