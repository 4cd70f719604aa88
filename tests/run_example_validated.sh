#!/usr/bin/env bash
# Runs an example program under the Khronos validation layer (VK_INSTANCE_LAYERS) on vkrt and fails unless it
# succeeds, the loader inserted the layer, and neither the layer (its default log) nor vkrt reported anything.
# Usage: run_example_validated.sh <program> [args...]
set -u
out=$(VK_INSTANCE_LAYERS=VK_LAYER_KHRONOS_validation VK_LOADER_DEBUG=layer "$@" 2>&1)
rc=$?
echo "$out" | grep -v "| LAYER:"
[ $rc -eq 0 ] || { echo "FAIL: exited with $rc"; exit 1; }
echo "$out" | grep -q 'Insert instance layer "VK_LAYER_KHRONOS_validation"' ||
  { echo "FAIL: the validation layer was not loaded"; exit 1; }
if echo "$out" | grep -E "Validation (Error|Warning)|^vkrt: "; then echo "FAIL: reports above"; exit 1; fi
echo "PASS"
