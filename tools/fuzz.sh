#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/) with clang-14, AddressSanitizer and UBSan in build-fuzz/ and runs each on
# its seed corpus (fuzz/corpus/) for a fixed time. A crash, a sanitizer report, a leak, a timeout or running out of
# memory fails the run; the input that did it is left in build-fuzz/findings/. New inputs the fuzzer finds go to
# build-fuzz/corpus/<target>/ (the seeds in the repository are only read).
# Usage: tools/fuzz.sh [target...]   (default: all; a target is its name without vkrt_fuzz_, e.g. spirv_module)
# VKRT_FUZZ_SECONDS: seconds per target (default 8; the JIT target gets twice as long). tools/test.sh runs this.
# VKRT_FUZZ_ARGS: more libFuzzer options for every target (e.g. -jobs=2 -workers=2).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build="$root/build-fuzz"
seconds=${VKRT_FUZZ_SECONDS:-8}
source "$root/tools/compiler_cache.sh"
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(spirv_module spirv_pipeline group_handles sbt_trace accel_build accel_deserialize)

cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_COMPILER=clang-14 \
  -DCMAKE_CXX_COMPILER=clang++-14 -DVKRT_FUZZ=ON -DVKRT_BUILD_TESTS=OFF -DVKRT_BUILD_BENCH=OFF "${launcher[@]}" \
  > "$root/.configure-fuzz.log" 2>&1 || { cat "$root/.configure-fuzz.log"; exit 1; }
cmake --build "$build" -j "$(nproc)" --target "${targets[@]/#/vkrt_fuzz_}"

# Per target: its seed folder, the largest input it gets (bytes) and the time one input may take (seconds).
declare -A corpus=([spirv_module]=spirv [spirv_pipeline]=spirv [group_handles]=group_handles
                   [sbt_trace]=sbt_trace [accel_build]=accel_build [accel_deserialize]=accel_deserialize)
declare -A maxLen=([spirv_module]=8192 [spirv_pipeline]=8192 [group_handles]=1300 [sbt_trace]=4200 [accel_build]=4096
                   [accel_deserialize]=4096)
declare -A timeout=([spirv_pipeline]=60)
mkdir -p "$build/findings"
status=0
for t in "${targets[@]}"; do
  work="$build/corpus/$t"
  mkdir -p "$work"
  secs=$seconds
  [ "$t" = spirv_pipeline ] && secs=$((seconds * 2))
  log="$build/fuzz-$t.log"
  # ASAN_OPTIONS: the symbolized report; LeakSanitizer stays on (a leak is a finding).
  if ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    "$build/fuzz/vkrt_fuzz_$t" -max_total_time="$secs" -max_len="${maxLen[$t]}" -timeout="${timeout[$t]:-20}" \
    -rss_limit_mb=4096 -print_final_stats=1 -artifact_prefix="$build/findings/$t-" ${VKRT_FUZZ_ARGS:-} \
    "$work" "$root/fuzz/corpus/${corpus[$t]}" > "$log" 2>&1; then
    echo "fuzz $t: $(grep -m1 -o 'stat::number_of_executed_units: [0-9]*' "$log" | grep -o '[0-9]*$') executions" \
         "in ${secs} s, no finding $(grep -m1 -o '[0-9]* shader compilations' "$log" || true)"
  else
    echo "fuzz $t: FINDING (log: $log; inputs in $build/findings/)"
    tail -n 60 "$log"
    status=1
  fi
done
exit $status
