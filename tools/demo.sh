#!/usr/bin/env bash
# Builds vkrt (release) and runs the demo through the standard Vulkan loader: scene_demo traces a box with triangle
# meshes, spheres (an intersection shader), an alpha-tested panel (an any-hit shader), a mirror and shadows (a second
# trace) through a ray tracing pipeline on vkrt, and writes the image to build/scene.png.
#
#   tools/demo.sh               one frame, build/scene.png
#   tools/demo.sh --present N   N frames presented through a headless swapchain, each written by vkrt to
#                               build/frames/frame-NNNNNN.png (VKRT_PRESENT_DIR); the last one also to build/scene.png
set -euo pipefail
frames=0
if [ $# -gt 0 ]; then
  if [ $# -ne 2 ] || [ "$1" != "--present" ] || ! [ "$2" -ge 1 ] 2>/dev/null; then
    echo "usage: tools/demo.sh [--present N]" >&2
    exit 2
  fi
  frames=$2
fi
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/tools/install-deps.sh"
build="$root/build"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DVKRT_BUILD_TESTS=OFF > "$root/.configure.log" 2>&1 ||
  { cat "$root/.configure.log"; exit 1; }
cmake --build "$build" -j "$(nproc)"
export VK_DRIVER_FILES="$build/vkrt_icd.json"
if [ "$frames" -gt 0 ]; then
  rm -rf "$build/frames"
  mkdir -p "$build/frames"
  VKRT_PRESENT_DIR="$build/frames" "$build/examples/scene_demo" --width 800 --height 600 --out "$build/scene.png" \
    --present "$frames"
  echo "demo: $frames frames in $build/frames"
else
  "$build/examples/scene_demo" --width 800 --height 600 --out "$build/scene.png"
fi
