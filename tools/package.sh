#!/usr/bin/env bash
# Builds vkrt's Debian package, vkrt_<version>_<arch>.deb: configures <build-dir> (default build-pkg/) as a Release
# build of the driver alone (no tests, benchmarks or examples: only src/ compiles; through ccache when it is
# installed), installed under /usr, builds it and runs CPack's DEB generator (cmake/VkrtInstall.cmake says what the
# package holds). It prints the .deb's path on standard output, and nothing else there (the rest goes to stderr).
# Usage: tools/package.sh [build-dir]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=$(realpath -m "${1:-$root/build-pkg}")
"$root/tools/install-deps.sh" >&2
source "$root/tools/compiler_cache.sh"
mkdir -p "$build"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_INSTALL_PREFIX=/usr \
  -DVKRT_BUILD_TESTS=OFF -DVKRT_BUILD_BENCH=OFF -DVKRT_BUILD_EXAMPLES=OFF -DVKRT_SANITIZE=OFF -DVKRT_FUZZ=OFF \
  "${launcher[@]}" > "$build/configure.log" 2>&1 || { cat "$build/configure.log" >&2; exit 1; }
echo "package: building the driver in $build (log: $build/build.log)" >&2
cmake --build "$build" -j "$(nproc)" > "$build/build.log" 2>&1 || { tail -n 100 "$build/build.log" >&2; exit 1; }
rm -rf "$build/package"
(cd "$build" && cpack --config CPackConfig.cmake -B "$build/package") > "$build/cpack.log" 2>&1 ||
  { cat "$build/cpack.log" >&2; exit 1; }
debs=("$build"/package/*.deb)
[ ${#debs[@]} -eq 1 ] && [ -f "${debs[0]}" ] || { cat "$build/cpack.log" >&2; echo "package: no single .deb" >&2; exit 1; }
echo "${debs[0]}"
