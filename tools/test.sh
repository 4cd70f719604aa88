#!/usr/bin/env bash
# Builds vkrt with AddressSanitizer and UndefinedBehaviorSanitizer and runs every test (unit, end-to-end
# through the Vulkan loader with the validation layer, vulkaninfo, ...), then builds the Debian package and checks it
# installed (tools/package.sh in build-pkg/, tests/check_package.sh), then runs each libFuzzer target for a short
# fixed time (tools/fuzz.sh: clang-14, build-fuzz/), then builds vkrt with ThreadSanitizer and runs the unit and
# end-to-end tests again. Usage: tools/test.sh [ctest args...] (given to both ctest runs)
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
