#!/usr/bin/env bash
# deqp-vk of vulkan-cts-1.3.7.3 with the graphics groups of issue 22 beside ../shared/cts's ray tracing, ray query,
# compute and SPIR-V assembly groups: api (api.smoke, api.copy_and_blit: blits and resolves), renderpass,
# renderpass2, dynamic_rendering, draw, image, rasterization, fragment_operations, and texture (texture.patch: the
# texture module and the shader executor it uses).
#
# The sources are the shared recipe's (../shared/cts/build.sh: the same tag, the same three pinned dependencies, its
# rt-only, fixes and compute patches), then tools/cts/sbt-sizes.patch and tools/cts/graphics.patch. Amber is not
# built (the shared recipe's stub): amber-based cases of these groups report NotSupported.
#
#   CTS_GIT=... SPVT_GIT=... GLSLANG_GIT=... SPVH_GIT=... tools/cts/build-graphics.sh <out>            # build here
#   CTS_GIT=... SPVT_GIT=... GLSLANG_GIT=... SPVH_GIT=... tools/cts/build-graphics.sh --tarball <out>  # sources only
#
# --tarball writes <out>/cts-graphics-src.tar.xz (about 8 MiB) instead of building: the sources without what these
# groups do not compile (other test modules, the OpenGL CTS, amber and video data, the dependencies' tests), small
# enough to carry to a machine with more cores, where
#   tar -xJf cts-graphics-src.tar.xz && cmake -S src -B build -G Ninja -DCMAKE_BUILD_TYPE=Release \
#     -DDEQP_TARGET=vulkan_headless && ninja -C build deqp-vk
# builds it (729 steps). The binary is <out>/build/external/vulkancts/modules/vulkan/deqp-vk; run it from its folder.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
shared=${SHARED_CTS:-$(realpath -m "$here/../../../shared/cts")}
tarball=0
[ "${1:-}" = --tarball ] && { tarball=1; shift; }
out=$(realpath -m "${1:?usage: build-graphics.sh [--tarball] <output folder>}")
: "${CTS_GIT:?git directory of KhronosGroup/VK-GL-CTS}" "${SPVT_GIT:?git directory of KhronosGroup/SPIRV-Tools}"
: "${GLSLANG_GIT:?git directory of KhronosGroup/glslang}" "${SPVH_GIT:?git directory of KhronosGroup/SPIRV-Headers}"
src=$out/src; build=$out/build
rm -rf "$src" "$build"; mkdir -p "$src" "$build"
# As ../shared/cts/build.sh: the stored copy lacks blobs of 4 MiB or more (mustpass lists, not needed). `git archive`
# with those paths excluded still stops at the first missing blob, so the files are checked out from an index of
# their own, without android/ and the mustpass lists.
index=$(mktemp)
GIT_INDEX_FILE=$index git --git-dir="$CTS_GIT" read-tree vulkan-cts-1.3.7.3
GIT_INDEX_FILE=$index git --git-dir="$CTS_GIT" ls-files | grep -v -e '^android/' -e '^external/vulkancts/mustpass/' |
  GIT_INDEX_FILE=$index git --git-dir="$CTS_GIT" --work-tree="$src" checkout-index --stdin
rm -f "$index"
extract() { mkdir -p "$src/external/$1/src"; git --git-dir="$2" archive "$3" | tar -x -C "$src/external/$1/src"; }
extract spirv-tools "$SPVT_GIT" bfc94f63a7adbcf8ae166f5f108ac9f69079efc0
extract glslang "$GLSLANG_GIT" c5117b328afc86e16edff6ed6afe0fe7872a7cf3
extract spirv-headers "$SPVH_GIT" b8b9eb8640c8c0107ba580fbcb10f969022ca32c
for p in "$shared/rt-only.patch" "$shared/fixes.patch" "$shared/compute.patch" "$here/sbt-sizes.patch" "$here/graphics.patch" "$here/texture.patch" \
  "$here/draw-rendering-info.patch"; do
  patch -s -d "$src" -p1 < "$p"
done
if [ $tarball = 1 ]; then
  mods="$src/external/vulkancts/modules/vulkan"
  keep=" util amber compute spirv_assembly ray_tracing ray_query api draw renderpass rasterization fragment_ops image texture shaderexecutor pipeline wsi ycbcr "
  for d in "$mods"/*/; do case "$keep" in *" $(basename "$d") "*) ;; *) rm -rf "$d" ;; esac; done
  rm -rf "$src/external/openglcts" "$src/modules" "$src/android" "$src/doc" "$src/external/vulkancts/vkscserver" \
    "$src/external/vulkancts/vkscpc" "$src/external/vulkancts/data/vulkan/amber" "$src/external/vulkancts/data/vulkan/video" \
    "$src/external/glslang/src/Test"
  # SPIRV-Tools adds its test folders whatever SPIRV_SKIP_TESTS says: keep their CMake files only.
  find "$src/external/spirv-tools/src/test" -type f ! -name CMakeLists.txt ! -name '*.cmake' -delete
  tar -C "$out" -cf - src | xz -T0 -6 > "$out/cts-graphics-src.tar.xz"
  rm -rf "$src" "$build"
  echo "sources: $out/cts-graphics-src.tar.xz"
  exit 0
fi
cmake -S "$src" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DDEQP_TARGET=vulkan_headless > "$out/cmake.log"
ninja -C "$build" -j "$(nproc)" deqp-vk
echo "deqp-vk: $build/external/vulkancts/modules/vulkan/deqp-vk"
