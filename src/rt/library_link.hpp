// Pipeline libraries: checking VkPipelineLibraryCreateInfoKHR against the pipeline being created, and
// appending the libraries' groups (in pLibraries order, each library's list already flattened).
#pragma once

#include <vector>

#include "rt/rt_pipeline.hpp"

namespace vkrt::rt {

// Checks every library rule of VkRayTracingPipelineCreateInfoKHR / VkPipelineLibraryCreateInfoKHR for
// pCreateInfos[index] and reports the first violation against `dev`. Fills `libraries` with the live
// libraries. Returns false after a report.
bool checkLibraries(Device* dev, const VkRayTracingPipelineCreateInfoKHR& info, uint32_t index,
                    std::vector<RayTracingPipeline*>& libraries);

// Appends the libraries' groups to `groups` (O(number of groups)).
void linkLibraries(const std::vector<RayTracingPipeline*>& libraries, std::vector<const GroupRecord*>& groups);

}  // namespace vkrt::rt
