#!/usr/bin/env bash
# The CTS on the device machine (16 cores, Ubuntu 24.04, no network), from a folder <dev> carried there:
#   <dev>/debs/*.deb          vkrt's run-time libraries Ubuntu lacks (libllvm15, libembree3-3, libtbb12, libtbbmalloc2,
#                             libz3-4) and the loader (libvulkan1), from `apt-get download` on Debian 12; unpacked
#                             with dpkg -x into /tmp/rt (never over /), put on LD_LIBRARY_PATH
#   <dev>/vkrt.tar.xz         libvkrt.so (and bench/vkrt_rasterbench) of a Release build
#   <dev>/deqp.tar.xz.*       deqp-vk and its data folder (split in 15 MiB parts), or else
#   <dev>/cts-graphics-src.tar.xz  the sources from tools/cts/build-graphics.sh --tarball, built here (about 4.5 min)
# (neither is needed on a warm machine that built or unpacked deqp-vk in an earlier call: that one is run).
# (LAVAPIPE=1: lavapipe's <dev>/lvp.tar.xz instead of vkrt.) Then runs api.smoke.* in one process (the sanity check) and tools/cts/run_parallel.sh (16 processes, VKRT_THREADS=1) over the patterns, <budget_s> seconds, into $OUT.
# SHARDS=n: n processes instead of 16; PIN=k: each pinned to k cores of its own with VKRT_THREADS=k (run_parallel.sh).
# Usage: device.sh <dev> <budget_s> <pattern>...     (STRIDE / EXCLUDE pass through to run_parallel.sh)
set -u
dev=$(realpath "$1"); budget=$2; shift 2
here=$(cd "$(dirname "$0")" && pwd)
out=${OUT:-/tmp/out}; mkdir -p "$out"
mkdir -p /tmp/rt && for f in "$dev"/debs/*.deb; do dpkg -x "$f" /tmp/rt; done
export LD_LIBRARY_PATH=/tmp/rt/usr/lib/x86_64-linux-gnu:/tmp/rt/lib/x86_64-linux-gnu:/tmp/rt/usr/lib/llvm-15/lib
mkdir -p /tmp/vkrt && tar -xJf "$dev/vkrt.tar.xz" -C /tmp/vkrt
printf '{"file_format_version": "1.0.0", "ICD": {"library_path": "/tmp/vkrt/libvkrt.so", "api_version": "1.3.239"}}\n' \
  > /tmp/vkrt/vkrt_icd.json
# LAVAPIPE=1: the same run on <dev>/lvp.tar.xz (libvulkan_lvp.so of ../shared/lavapipe/build.sh) instead of vkrt
icd=/tmp/vkrt/vkrt_icd.json
if [ -n "${LAVAPIPE:-}" ]; then
  mkdir -p /tmp/lvp && tar -xJf "$dev/lvp.tar.xz" -C /tmp/lvp
  printf '{"file_format_version": "1.0.0", "ICD": {"library_path": "/tmp/lvp/libvulkan_lvp.so", "api_version": "1.3.289"}}\n' \
    > /tmp/lvp/lvp_icd.json
  icd=/tmp/lvp/lvp_icd.json
fi
cts=/tmp/cts/build/external/vulkancts/modules/vulkan
mkdir -p "$cts"
if [ -x "$cts/deqp-vk" ]; then
  echo "deqp-vk: the one a warm machine kept"
elif ls "$dev"/deqp.tar.xz.* > /dev/null 2>&1; then
  cat "$dev"/deqp.tar.xz.* | tar -xJ -C "$cts"
else
  tar -xJf "$dev/cts-graphics-src.tar.xz" -C /tmp/cts
  cmake -S /tmp/cts/src -B /tmp/cts/build -G Ninja -DCMAKE_BUILD_TYPE=Release -DDEQP_TARGET=vulkan_headless > /tmp/cts/cmake.log
  SECONDS=0; ninja -C /tmp/cts/build -j "$(nproc)" deqp-vk > /tmp/cts/ninja.log 2>&1 || { tail -40 /tmp/cts/ninja.log; exit 1; }
  echo "deqp-vk built in $SECONDS s"
  strip "$cts/deqp-vk"
  (cd "$cts" && tar -cf - deqp-vk vulkan | xz -T0 -6 | split -b 15M - "$out/deqp.tar.xz.")
fi
export VKRT_THREADS=1 LP_NUM_THREADS=1
# the sanity check first: api.smoke.* in one process
(cd "$cts" && VK_DRIVER_FILES=$icd timeout 120 ./deqp-vk --deqp-case='dEQP-VK.api.smoke.*' \
   --deqp-log-filename=/tmp/smoke.qpa --deqp-log-images=disable --deqp-log-shader-sources=disable | tail -12)
# DEADLINE (seconds since the epoch) caps the budget so that the results are packed before the command's time is up
[ -n "${DEADLINE:-}" ] && budget=$(( DEADLINE - $(date +%s) < budget ? DEADLINE - $(date +%s) : budget ))
"$here/run_parallel.sh" "$cts/deqp-vk" "$icd" "${SHARDS:-16}" "$budget" /tmp/r "$@"
xz -T0 -c /tmp/r/results.txt > "$out/results.txt.xz"
xz -T0 -c /tmp/r/messages.txt > "$out/messages.txt.xz"
xz -T0 -c /tmp/r/reports.txt > "$out/reports.txt.xz"
