#!/usr/bin/env bash
# Builds vkrt with AddressSanitizer and UndefinedBehaviorSanitizer and runs every test (unit, end-to-end
# through the Vulkan loader with the validation layer, vulkaninfo, ...), then the tests the CPU's instruction set
# can change once per set below this CPU's best (Embree's kernels, the compiler's target: tools/isa_matrix.sh),
# then runs each libFuzzer target for a short fixed time (tools/fuzz.sh: clang-14, build-fuzz/), then builds vkrt
# with ThreadSanitizer and runs the unit and end-to-end tests again. Usage: tools/test.sh [ctest args...] (given
# to every ctest run)
# VKRT_FUZZ_SECONDS: seconds per fuzz target (tools/fuzz.sh; 0 skips the fuzz step).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/tools/install-deps.sh"
status=0
# AddressSanitizer + UndefinedBehaviorSanitizer: build-test/, every test.
build="$root/build-test"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Debug -DVKRT_SANITIZE=ON > "$root/.configure.log" 2>&1 ||
  { cat "$root/.configure.log"; exit 1; }
cmake --build "$build" -j "$(nproc)"
(cd "$build" && ctest -j "$(nproc)" --output-on-failure --timeout 600 "$@") || status=1
# The instruction-set matrix (docs/testing.md): nothing vkrt does may depend on the CPU's instruction set beyond
# what the specification allows, so the tests that the instruction set can change run again, in the same build,
# once per set below this CPU's best: the acceleration structure, ray query and tracing tests with each set of
# Embree kernels (VKRT_EMBREE_ISA), the compiler's tests with code compiled for each x86-64 baseline
# (VKRT_JIT_CPU). tools/isa_matrix.sh lists the sets.
matrixStart=$SECONDS
embreeTests='^(Accel|LargeBuilds|EmbreeLimits|SpirvRayQuery|SpirvRayTracing|Trace|NvTrace|RayQuery)'
jitTests='^Spirv'
for isa in $("$root/tools/isa_matrix.sh" embree); do
  echo "== VKRT_EMBREE_ISA=$isa"
  (cd "$build" && VKRT_EMBREE_ISA=$isa ctest -j "$(nproc)" --output-on-failure --timeout 600 -R "$embreeTests" "$@") ||
    status=1
done
for cpu in $("$root/tools/isa_matrix.sh" jit); do
  echo "== VKRT_JIT_CPU=$cpu"
  (cd "$build" && VKRT_JIT_CPU=$cpu ctest -j "$(nproc)" --output-on-failure --timeout 600 -R "$jitTests" "$@") ||
    status=1
done
echo "instruction-set matrix: $((SECONDS - matrixStart)) s"
# libFuzzer targets: build-fuzz/ (clang-14), each on its seed corpus for VKRT_FUZZ_SECONDS (default 15) seconds.
if [ "${VKRT_FUZZ_SECONDS:-15}" != 0 ]; then
  fuzzStart=$SECONDS
  "$root/tools/fuzz.sh" || status=1
  echo "fuzz step (build-fuzz/ build and runs): $((SECONDS - fuzzStart)) s"
fi
# ThreadSanitizer: build-tsan/, the unit and end-to-end tests (tests/CMakeLists.txt registers only those there).
tsan="$root/build-tsan"
cmake -S "$root" -B "$tsan" -G Ninja -DCMAKE_BUILD_TYPE=Debug -DVKRT_SANITIZE=thread > "$root/.configure-tsan.log" 2>&1 ||
  { cat "$root/.configure-tsan.log"; exit 1; }
cmake --build "$tsan" -j "$(nproc)" --target vkrt_unit_tests vkrt_e2e_tests
(cd "$tsan" && ctest -j "$(nproc)" --output-on-failure --timeout 600 "$@") || status=1
exit $status
