#!/usr/bin/env bash
# Builds vkrt (release) and runs the demos through the standard Vulkan loader.
#
#   tools/demo.sh               the path tracer (examples/pathtracer) on the glTF model 2CylinderEngine.glb (Debian's
#                               assimp-testmodels), 640x480, 32 samples per pixel: build/pathtracer.png
#   tools/demo.sh --present N   scene_demo (a box with triangle meshes, spheres from an intersection shader, an
#                               alpha-tested panel, a mirror and shadows) traces N frames presented through a
#                               headless swapchain, each written by vkrt to build/frames/frame-NNNNNN.png
#                               (VKRT_PRESENT_DIR); the last one also to build/scene.png
#   tools/demo.sh --hybrid      hybrid (a rasterized scene whose fragment shader finds shadows with ray queries, grid
#                               lines from derivatives, a blended overlay), 800x600, checked against its CPU
#                               reference: build/hybrid.png
set -euo pipefail
frames=0
hybrid=0
if [ $# -eq 1 ] && [ "$1" = "--hybrid" ]; then
  hybrid=1
elif [ $# -gt 0 ]; then
  if [ $# -ne 2 ] || [ "$1" != "--present" ] || ! [ "$2" -ge 1 ] 2>/dev/null; then
    echo "usage: tools/demo.sh [--present N | --hybrid]" >&2
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
if [ "$hybrid" = 1 ]; then
  "$build/examples/hybrid" --width 800 --height 600 --check --out "$build/hybrid.png"
elif [ "$frames" -gt 0 ]; then
  rm -rf "$build/frames"
  mkdir -p "$build/frames"
  VKRT_PRESENT_DIR="$build/frames" "$build/examples/scene_demo" --width 800 --height 600 --out "$build/scene.png" \
    --present "$frames"
  echo "demo: $frames frames in $build/frames"
else
  model=$(dpkg -L assimp-testmodels | grep '/2CylinderEngine-glTF-Binary/2CylinderEngine.glb$' | head -n 1)
  [ -n "$model" ] || { echo "demo: assimp-testmodels has no 2CylinderEngine.glb" >&2; exit 1; }
  "$build/examples/pathtracer" --scene "$model" --width 640 --height 480 --spp 32 --bounces 6 --seed 1 \
    --out "$build/pathtracer.png"
fi
