#!/usr/bin/env bash
# Runs vulkaninfo through vkrt and fails unless it succeeds, lists the vkrt device, and neither vkrt nor the loader
# reported an error.
set -u
out=$("$@" 2>&1)
rc=$?
echo "$out"
[ $rc -eq 0 ] || { echo "vulkaninfo exited with $rc"; exit 1; }
echo "$out" | grep -q "deviceName *= vkrt" || { echo "vkrt's device is not listed"; exit 1; }
if echo "$out" | grep -q "^vkrt: "; then echo "vkrt reported an error"; exit 1; fi
# The loader's errors too (vulkaninfo creates a device with VK_KHR_swapchain and VK_KHR_device_group to print the
# device group's present capabilities; an extension vkrt lacked was a loader ERROR line).
if echo "$out" | grep -q "ERROR"; then echo "an ERROR line in the output"; exit 1; fi
exit 0
