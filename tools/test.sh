#!/usr/bin/env bash
# Builds vkrt with AddressSanitizer and UndefinedBehaviorSanitizer and runs every test (unit, end-to-end
# through the Vulkan loader with the validation layer, vulkaninfo, ...), then the tests the CPU's instruction set
# can change once per set below this CPU's best (Embree's kernels, the compiler's target: tools/isa_matrix.sh),
# then builds the Debian package and checks it installed (tools/package.sh in build-pkg/, tests/check_package.sh),
# then runs each libFuzzer target for a short fixed time (tools/fuzz.sh: clang-14, build-fuzz/), then builds vkrt
# with ThreadSanitizer and runs the unit and end-to-end tests again. Usage: tools/test.sh [ctest args...] (given
# to both ctest runs)
# VKRT_FUZZ_SECONDS: seconds per fuzz target (tools/fuzz.sh; 0 skips the fuzz step).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/tools/install-deps.sh"
source "$root/tools/compiler_cache.sh"
status=0
# AddressSanitizer + UndefinedBehaviorSanitizer: build-test/, every test.
build="$root/build-test"
start=$SECONDS
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Debug -DVKRT_SANITIZE=ON "${launcher[@]}" \
  > "$root/.configure.log" 2>&1 ||
  { cat "$root/.configure.log"; exit 1; }
cmake --build "$build" -j "$(nproc)"
echo "AddressSanitizer build (build-test/): $((SECONDS - start)) s"
start=$SECONDS
(cd "$build" && ctest -j "$(nproc)" --output-on-failure --timeout 600 "$@") || status=1
echo "AddressSanitizer tests: $((SECONDS - start)) s"
# The instruction-set matrix (docs/testing.md): nothing vkrt does may depend on the CPU's instruction set beyond
# what the specification allows, so the tests that the instruction set can change run again, in the same build,
# once per set below this CPU's best (tools/isa_matrix.sh lists them): the acceleration structure, ray query and
# tracing tests with each set of Embree kernels (VKRT_EMBREE_ISA), the compiler's tests with code compiled for each
# x86-64 baseline (VKRT_JIT_CPU). Each run is one test process per binary (a test process per test, as ctest
# starts them, would double the suite's time), the unit and end-to-end binaries side by side.
matrixStart=$SECONDS
embreeUnit='Accel*:LargeBuilds*:EmbreeLimits*:SpirvRayQuery*:SpirvRayTracing*'
embreeE2e='Trace*:NvTrace*:RayQuery*'
matrix() {  # matrix NAME=VALUE unit-filter [e2e-filter]
  local log="$build/matrix-${1//[^A-Za-z0-9.=_-]/_}"
  echo "== $1"
  env "$1" "$build/tests/vkrt_unit_tests" --gtest_brief=1 --gtest_filter="$2" > "$log-unit.log" 2>&1 &
  local unit=$!
  local ok=0
  if [ -n "${3:-}" ]; then
    env "$1" VK_DRIVER_FILES="$build/vkrt_icd.json" "$build/tests/vkrt_e2e_tests" --gtest_brief=1 \
      --gtest_filter="$3" > "$log-e2e.log" 2>&1 || ok=1
    tail -n 3 "$log-e2e.log"
    [ $ok = 0 ] || cat "$log-e2e.log"
  fi
  wait $unit || ok=2
  tail -n 3 "$log-unit.log"
  [ $ok != 2 ] || cat "$log-unit.log"
  return $ok
}
for isa in $("$root/tools/isa_matrix.sh" embree); do
  matrix "VKRT_EMBREE_ISA=$isa" "$embreeUnit" "$embreeE2e" || status=1
done
for cpu in $("$root/tools/isa_matrix.sh" jit); do
  matrix "VKRT_JIT_CPU=$cpu" 'Spirv*:Spmd*' || status=1
done
# The scalar compute path (VKRT_SPMD=0), the reference the SPMD code is compared with: SPMD is the default, so
# without this run the scalar form of barrier-free shaders the SPMD compiler supports would go untested; likewise
# the fragment quads' fibers (the draw tests).
scalarE2e='Compute*:ShaderDebug*:Draw*:RenderPass*:Multiview*:InputAttachment*:DepthCompare*:Blit*:Resolve*'
scalarE2e="$scalarE2e:ShaderWatchdogTest.*Barriers*:ShaderFaultTest.*Barriers*"  # one fiber per invocation
matrix VKRT_SPMD=0 'Spirv*:Spmd*:OutOfBounds*:DebugPrintf*' "$scalarE2e" || status=1
echo "instruction-set matrix: $((SECONDS - matrixStart)) s"
# The Debian package: a Release build of the driver in build-pkg/ (tools/package.sh), its contents and fields, and
# the loader finding it installed, without VK_DRIVER_FILES (tests/check_package.sh, with build-test/'s path tracer).
packageStart=$SECONDS
if deb=$("$root/tools/package.sh" "$root/build-pkg"); then
  "$root/tests/check_package.sh" "$deb" "$build/examples/pathtracer" || status=1
else
  echo "package step: tools/package.sh failed"
  status=1
fi
echo "package step (build-pkg/ build, package and checks): $((SECONDS - packageStart)) s"
# libFuzzer targets: build-fuzz/ (clang-14), each on its seed corpus for VKRT_FUZZ_SECONDS (default 8) seconds.
if [ "${VKRT_FUZZ_SECONDS:-8}" != 0 ]; then
  fuzzStart=$SECONDS
  "$root/tools/fuzz.sh" || status=1
  echo "fuzz step (build-fuzz/ build and runs): $((SECONDS - fuzzStart)) s"
fi
# ThreadSanitizer: build-tsan/, the unit and end-to-end tests (tests/CMakeLists.txt registers only those there).
tsan="$root/build-tsan"
start=$SECONDS
cmake -S "$root" -B "$tsan" -G Ninja -DCMAKE_BUILD_TYPE=Debug -DVKRT_SANITIZE=thread "${launcher[@]}" \
  > "$root/.configure-tsan.log" 2>&1 ||
  { cat "$root/.configure-tsan.log"; exit 1; }
cmake --build "$tsan" -j "$(nproc)" --target vkrt_unit_tests vkrt_e2e_tests
echo "ThreadSanitizer build (build-tsan/): $((SECONDS - start)) s"
# (Its time is ctest's "Total Test time"; ctest's summary stays the last lines the command prints.)
# Address-space randomization off where the machine allows it: GCC 12's ThreadSanitizer maps its shadow at fixed
# addresses and, when a randomly placed mapping is in the way, fails to start the test. (Its "failed to allocate ...
# (errno: 12)" in the middle of a test was another thing: tests/sanitizer_options.cpp, intercept_tls_get_addr.)
norandom=()
if setarch "$(uname -m)" -R true 2> /dev/null; then norandom=(setarch "$(uname -m)" -R); fi
(cd "$tsan" && "${norandom[@]}" ctest -j "$(nproc)" --output-on-failure --timeout 600 "$@") || status=1
exit $status
