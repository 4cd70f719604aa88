#!/usr/bin/env bash
# The GFXReconstruct round trip on vkrt: scene_demo presents N frames through a headless swapchain under the
# capture layer (VK_LAYER_LUNARG_gfxreconstruct), then gfxrecon-replay replays the capture file in another process;
# both write their presented frames with VKRT_PRESENT_DIR, and the replayed frames must be byte for byte the live
# ones. Neither run may print an error (vkrt's reports, the tools' ERROR lines), except the one misuse of
# GFXReconstruct 0.9.18 that vkrt reports at capture (listed below).
# Usage: run_gfxr_roundtrip.sh <scene_demo> <work folder> [frames]
set -u
demo=$1
work=$2
frames=${3:-3}
rm -rf "$work"
mkdir -p "$work/live" "$work/replay"

# Capture. GFXReconstruct 0.9.18 asks for a buffer's opaque capture address right after vkCreateBuffer, before the
# buffer is bound (VUID-VkBufferDeviceAddressInfo-buffer-02600): vkrt reports it and returns 0, which the replay
# passes on as "no particular address"; the buffer's address comes from its memory, which is replayed at its
# captured address. Those reports are the only ones accepted.
VKRT_PRESENT_DIR="$work/live" VK_INSTANCE_LAYERS=VK_LAYER_LUNARG_gfxreconstruct \
  GFXRECON_CAPTURE_FILE="$work/capture.gfxr" GFXRECON_CAPTURE_FILE_TIMESTAMP=false \
  "$demo" --width 96 --height 64 --present "$frames" --out "$work/live.png" > "$work/capture.log" 2>&1
rc=$?
cat "$work/capture.log"
[ $rc -eq 0 ] || { echo "FAIL: the capture run exited with $rc"; exit 1; }
[ -s "$work/capture.gfxr" ] || { echo "FAIL: no capture file"; exit 1; }
if grep -v "VUID-VkBufferDeviceAddressInfo-buffer-02600" "$work/capture.log" | grep -E "^vkrt: |ERROR"; then
  echo "FAIL: errors during capture"
  exit 1
fi

# Replay in another process, on the headless surface, with the swapchain image indices of the capture (the default
# virtual swapchain copies each frame with vkCmdBlitImage, a graphics-queue command; see docs/gfxreconstruct.md).
VKRT_PRESENT_DIR="$work/replay" gfxrecon-replay --wsi headless --use-captured-swapchain-indices \
  "$work/capture.gfxr" > "$work/replay.log" 2>&1
rc=$?
cat "$work/replay.log"
[ $rc -eq 0 ] || { echo "FAIL: gfxrecon-replay exited with $rc"; exit 1; }
if grep -E "^vkrt: |ERROR|FATAL" "$work/replay.log"; then
  echo "FAIL: errors during replay"
  exit 1
fi
grep -q "$frames frames" "$work/replay.log" || { echo "FAIL: the replay did not report $frames frames"; exit 1; }

live=$(cd "$work/live" && ls)
replayed=$(cd "$work/replay" && ls)
[ "$(echo "$live" | wc -w)" -eq "$frames" ] || { echo "FAIL: $frames live frames expected, got: $live"; exit 1; }
[ "$live" = "$replayed" ] || { echo "FAIL: live frames [$live], replayed frames [$replayed]"; exit 1; }
for f in $live; do
  cmp "$work/live/$f" "$work/replay/$f" || { echo "FAIL: replayed $f differs from the live one"; exit 1; }
done
# The frames differ from one another (the demo changes a sphere's colour each frame), so their order is checked too.
[ "$frames" -lt 2 ] || ! cmp -s "$work/live/$(echo "$live" | head -1)" "$work/live/$(echo "$live" | tail -1)" ||
  { echo "FAIL: the first and last frames are identical"; exit 1; }
echo "PASS: $frames replayed frames are byte for byte the live ones"
