#!/usr/bin/env bash
# Builds vkrt with AddressSanitizer and UndefinedBehaviorSanitizer and runs every test (unit, end-to-end
# through the Vulkan loader with the validation layer, vulkaninfo). Usage: tools/test.sh [ctest args...]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/tools/install-deps.sh"
build="$root/build-test"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Debug -DVKRT_SANITIZE=ON > "$root/.configure.log" 2>&1 ||
  { cat "$root/.configure.log"; exit 1; }
cmake --build "$build" -j "$(nproc)"
cd "$build"
ctest -j "$(nproc)" --output-on-failure --timeout 600 "$@"
