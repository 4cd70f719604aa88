#!/usr/bin/env bash
# Whether every test that failed in a ctest run (its Testing/Temporary/LastTest.log, the one argument) failed only
# because ThreadSanitizer could not map its shadow memory at start-up (GCC 12's runtime prints "ThreadSanitizer failed
# to allocate ... (errno: 12)" and exits before the test runs): exit 0 then, 1 when any failure is of another kind or
# none failed. tools/test.sh runs such tests again.
set -euo pipefail
log=${1:?usage: tools/tsan_startup_only.sh LastTest.log}
[ -r "$log" ] || exit 1
awk '
  /^[0-9]+\/[0-9]+ Test: / { startup = 0 }
  /ThreadSanitizer failed to allocate/ { startup = 1 }
  /^Test Failed\./ { failed++; if (startup) ofStartup++ }
  /^Test Passed\./ { startup = 0 }
  END { exit !(failed > 0 && failed == ofStartup) }' "$log"
