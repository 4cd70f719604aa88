#!/usr/bin/env bash
# Runs vulkaninfo through vkrt and fails unless it succeeds, lists the vkrt device, and vkrt reported nothing.
set -u
out=$("$@" 2>&1)
rc=$?
echo "$out"
[ $rc -eq 0 ] || { echo "vulkaninfo exited with $rc"; exit 1; }
echo "$out" | grep -q "deviceName *= vkrt" || { echo "vkrt's device is not listed"; exit 1; }
if echo "$out" | grep -q "^vkrt: "; then echo "vkrt reported an error"; exit 1; fi
exit 0
