// Ray tracing pipeline stack sizes.
//
// Per shader: spirv::RayStageInfo::stackSize of its compiled code (src/spirv/compiler.hpp says how the figure is
// derived), reached through each group's ShaderDesc and reported by vkGetRayTracingShaderGroupStackSizeKHR.
// Per pipeline: the default stack size of the spec's "Ray Tracing Pipeline Stack" section:
//   rayGenStackMax
//   + min(1, maxPipelineRayRecursionDepth) * max(closestHitStackMax, missStackMax,
//                                                intersectionStackMax + anyHitStackMax)
//   + max(0, maxPipelineRayRecursionDepth - 1) * max(closestHitStackMax, missStackMax)
//   + 2 * callableStackMax
// where each *StackMax is the largest stack size of the pipeline's shaders of that stage (libraries included).
#pragma once

#include <cstdint>
#include <vector>

#include "rt/group_handles.hpp"

namespace vkrt::rt {

struct StageStackMax {
  uint64_t rayGen = 0, closestHit = 0, miss = 0, intersection = 0, anyHit = 0, callable = 0;
  void add(const ShaderDesc& s);
};

uint64_t defaultPipelineStackSize(const StageStackMax& m, uint32_t maxPipelineRayRecursionDepth);

// The default stack size of a pipeline made of `groups`.
uint64_t defaultPipelineStackSize(const std::vector<const GroupRecord*>& groups, uint32_t maxPipelineRayRecursionDepth);

}  // namespace vkrt::rt
