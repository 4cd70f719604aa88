// Pipeline libraries: checking VkPipelineLibraryCreateInfoKHR against the pipeline being created, and
// appending the libraries' groups (in pLibraries order, each library's list already flattened).
#pragma once

#include <string>
#include <vector>

#include "rt/rt_pipeline.hpp"

namespace vkrt::rt {

// Checks every library rule of VkRayTracingPipelineCreateInfoKHR / VkPipelineLibraryCreateInfoKHR for
// pCreateInfos[index] and reports the first violation against `dev`. Fills `libraries` with the live
// libraries. Returns false after a report.
// `shape` is the shape of info.layout (libraries must have been created with a compatible layout).
bool checkLibraries(Device* dev, const VkRayTracingPipelineCreateInfoKHR& info, uint32_t index,
                    const LayoutShape& shape, std::vector<RayTracingPipeline*>& libraries);

// Empty when two layouts are compatible (same number of sets, identically defined set layouts and push-constant
// ranges); otherwise what differs first, with its values.
std::string layoutDifference(const LayoutShape& mine, const LayoutShape& library);

// Appends the libraries' groups to `groups` (O(number of groups)).
void linkLibraries(const std::vector<RayTracingPipeline*>& libraries, std::vector<const GroupRecord*>& groups);

}  // namespace vkrt::rt
