#!/usr/bin/env bash
# On the device machine, after tools/cts/device.sh has unpacked /tmp/rt and /tmp/vkrt (libvkrt.so and
# vkrt_rasterbench): vkrt_rasterbench at 1920x1080 on vkrt
# (VKRT_THREADS) and lavapipe 24.3 (LP_NUM_THREADS) at 1, 2 and 16 threads, three runs each, alternating drivers.
# Usage: rasterbench_lavapipe.sh <dev> (the carried folder: lvp.tar.xz, BoxTextured.glb)
dev=$(realpath "$1")
export LD_LIBRARY_PATH=/tmp/rt/usr/lib/x86_64-linux-gnu:/tmp/rt/lib/x86_64-linux-gnu:/tmp/rt/usr/lib/llvm-15/lib
mkdir -p /tmp/lvp && tar -xJf "$dev/lvp.tar.xz" -C /tmp/lvp
printf '{"file_format_version": "1.0.0", "ICD": {"library_path": "/tmp/lvp/libvulkan_lvp.so", "api_version": "1.3.289"}}\n' > /tmp/lvp/lvp_icd.json
# Threads per core: with 2 (SMT), 16 threads on 16 logical CPUs share 8 cores, which alone raises the CPU time per
# frame over the 1-thread run's.
lscpu | grep -E 'Model name|^CPU\(s\)|Thread\(s\) per core|Core\(s\) per socket|Flags' | cut -c1-200
for t in 1 2 16; do
  for run in 1 2 3; do
    echo "== vkrt threads $t run $run"
    VKRT_THREADS=$t VK_DRIVER_FILES=/tmp/vkrt/vkrt_icd.json timeout 120 /tmp/vkrt/vkrt_rasterbench --model "$dev/BoxTextured.glb" --frames 3 --warmup 1 2>&1 | tail -3
    echo "== lavapipe threads $t run $run"
    LP_NUM_THREADS=$t VK_DRIVER_FILES=/tmp/lvp/lvp_icd.json timeout 120 /tmp/vkrt/vkrt_rasterbench --model "$dev/BoxTextured.glb" --frames 3 --warmup 1 2>&1 | tail -3
  done
done
