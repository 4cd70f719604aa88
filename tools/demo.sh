#!/usr/bin/env bash
# Builds vkrt (release) and runs the demo through the standard Vulkan loader: vulkaninfo --summary lists the
# vkrt device, then buffer_demo fills, copies and updates buffers on vkrt's queue and prints the bytes.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/tools/install-deps.sh"
build="$root/build"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DVKRT_BUILD_TESTS=OFF > "$root/.configure.log" 2>&1 ||
  { cat "$root/.configure.log"; exit 1; }
cmake --build "$build" -j "$(nproc)"
export VK_DRIVER_FILES="$build/vkrt_icd.json"
vulkaninfo --summary 2>/dev/null | sed -n '/^Devices:/,$p'
"$build/examples/buffer_demo"
