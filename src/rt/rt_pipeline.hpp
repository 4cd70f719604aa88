// Ray tracing pipelines (VK_KHR_ray_tracing_pipeline) and pipeline libraries (VK_KHR_pipeline_library).
//
// A RayTracingPipeline is its list of shader groups, each a pointer to a device-wide GroupRecord
// (src/rt/group_handles.hpp): its own pGroups first, then each library's groups in pLibraries order,
// recursively (a library's list already has its own libraries' groups after its own). Linking copies those
// pointers: it never looks at SPIR-V again, so its cost is proportional to the number of groups.
#pragma once

#include <cstdint>
#include <vector>

#include "rt/group_handles.hpp"
#include "runtime/pipeline.hpp"

namespace vkrt::rt {

class RayTracingPipeline : public Pipeline {
 public:
  RayTracingPipeline(Device* dev, VkPipelineCreateFlags flags, PipelineLayout* layout);

  std::vector<const GroupRecord*> groups;
  uint32_t ownGroupCount = 0;
  uint32_t maxRecursionDepth = 0;
  bool hasInterface = false;
  uint32_t maxPayloadSize = 0;
  uint32_t maxHitAttributeSize = 0;
  bool dynamicStackSize = false;  // VK_DYNAMIC_STATE_RAY_TRACING_PIPELINE_STACK_SIZE_KHR
  uint64_t defaultStackSize = 0;  // the spec's formula (src/rt/stack_size.hpp)

  bool isLibrary() const { return (createFlags & VK_PIPELINE_CREATE_LIBRARY_BIT_KHR) != 0; }
  uint32_t groupCount() const { return static_cast<uint32_t>(groups.size()); }
};

// The ray tracing pipeline behind a live pipeline, or nullptr when it is another kind.
inline RayTracingPipeline* asRayTracing(Pipeline* p) {
  return p && p->bindPoint == VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR ? static_cast<RayTracingPipeline*>(p) : nullptr;
}

}  // namespace vkrt::rt
