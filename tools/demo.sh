#!/usr/bin/env bash
# Builds vkrt (release) and runs the demo through the standard Vulkan loader: scene_demo traces a box with triangle
# meshes, spheres (an intersection shader), an alpha-tested panel (an any-hit shader), a mirror and shadows (a second
# trace) through a ray tracing pipeline on vkrt, and writes the image to build/scene.png.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/tools/install-deps.sh"
build="$root/build"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DVKRT_BUILD_TESTS=OFF > "$root/.configure.log" 2>&1 ||
  { cat "$root/.configure.log"; exit 1; }
cmake --build "$build" -j "$(nproc)"
export VK_DRIVER_FILES="$build/vkrt_icd.json"
"$build/examples/scene_demo" --width 800 --height 600 --out "$build/scene.png"
