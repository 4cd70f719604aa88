#!/usr/bin/env bash
# Whether every test that failed in a ctest run (its Testing/Temporary/LastTest.log, the one argument) failed only
# because ThreadSanitizer could not map shadow memory (GCC 12's runtime prints "ThreadSanitizer failed to allocate ...
# (errno: 12)" and exits: at start-up, or, on the VM of 2026-12-07, while the test runs, after it has started threads;
# docs/testing.md): exit 0 then, 1 when any failure is of another kind or none failed. tools/test.sh runs such tests
# again with the environment padded (the failure depends on its size).
set -euo pipefail
log=${1:?usage: tools/tsan_startup_only.sh LastTest.log}
[ -r "$log" ] || exit 1
awk '
  /^[0-9]+\/[0-9]+ Test: / { startup = 0 }
  /ThreadSanitizer failed to allocate/ { startup = 1 }
  /^Test Failed\./ { failed++; if (startup) ofStartup++ }
  /^Test Passed\./ { startup = 0 }
  END { exit !(failed > 0 && failed == ofStartup) }' "$log"
