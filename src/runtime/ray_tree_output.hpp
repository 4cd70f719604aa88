// Where the ray trees of a launch or dispatch go (VKRT_RAY_TREE, docs/ray-tree.md): appended to the file
// VKRT_RAY_TREE_OUT names (one JSON object per line when its name ends in ".json" or ".jsonl", else the indented
// text), or, without one, each as an INFO message (message id name "vkrt-ray-tree", the text) through
// VK_EXT_debug_utils, about the command buffer.
#pragma once

#include "exec/ray_tree.hpp"
#include "runtime/device.hpp"

namespace vkrt {

// A recorder for a launch (`compute` false) or dispatch of `dev`, or null when the setting names no invocation of
// that kind: decided once per launch.
std::unique_ptr<exec::RayTreeRecorder> rayTreeRecorder(const Device* dev, bool compute);

// Delivers the trees of the named invocations that ran (for a dispatch, `skipEmpty`: those that made a ray query).
void deliverRayTrees(const Object* about, Device* dev, exec::RayTreeRecorder& recorder, exec::RayTreeContext ctx,
                     bool skipEmpty);

}  // namespace vkrt
