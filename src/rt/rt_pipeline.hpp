// Ray tracing pipelines (VK_KHR_ray_tracing_pipeline) and pipeline libraries (VK_KHR_pipeline_library); the pipelines
// of VK_NV_ray_tracing are the same objects (vkCreateRayTracingPipelinesNV translates its create infos).
//
// A RayTracingPipeline is its list of shader groups, each a pointer to a device-wide GroupRecord
// (src/rt/group_handles.hpp): its own pGroups first, then each library's groups in pLibraries order,
// recursively (a library's list already has its own libraries' groups after its own). Linking copies those
// pointers: it never looks at SPIR-V again, so its cost is proportional to the number of groups.
#pragma once

#include <cstdint>
#include <mutex>
#include <vector>

#include "rt/group_handles.hpp"
#include "runtime/pipeline.hpp"

namespace vkrt::rt {

// What pipeline layout compatibility looks at ("identically defined" set layouts and push-constant ranges),
// copied out of a VkPipelineLayout at creation: a library's layout may be destroyed before it is linked.
struct LayoutShape {
  struct Binding {
    uint32_t binding = 0, type = 0, count = 0, stages = 0, flags = 0;
    std::vector<const void*> immutableSamplers;
    bool operator==(const Binding&) const = default;
  };
  struct Set {
    uint32_t flags = 0;
    std::vector<Binding> bindings;  // by binding number
    bool operator==(const Set&) const = default;
  };
  std::vector<Set> sets;
  std::vector<VkPushConstantRange> pushConstants;  // sorted by (offset, size, stageFlags)
};
LayoutShape shapeOf(const PipelineLayout& layout);

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
  LayoutShape layoutShape;        // of `layout` at creation (compared when the pipeline is linked as a library)
  // VK_PIPELINE_CREATE_DEFER_COMPILE_BIT_NV: per stage, 1 until vkCompileDeferredNV was called for it (empty
  // otherwise). The code itself is compiled at creation, as for every pipeline; this is the state the rules of
  // vkCompileDeferredNV are checked against.
  std::vector<uint8_t> deferredStages;
  std::mutex deferredMutex;

  bool isLibrary() const { return (createFlags & VK_PIPELINE_CREATE_LIBRARY_BIT_KHR) != 0; }
  uint32_t groupCount() const { return static_cast<uint32_t>(groups.size()); }
};

// The ray tracing pipeline behind a live pipeline, or nullptr when it is another kind.
inline RayTracingPipeline* asRayTracing(Pipeline* p) {
  return p && p->bindPoint == VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR ? static_cast<RayTracingPipeline*>(p) : nullptr;
}

}  // namespace vkrt::rt
