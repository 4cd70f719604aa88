// VkPipeline: the base of compute pipelines (runtime/compute_pipeline.hpp), graphics pipelines
// (src/gfx/graphics_pipeline.hpp) and ray tracing pipelines (src/rt/rt_pipeline.hpp). vkDestroyPipeline
// (pipeline.cpp) deletes through the virtual destructor. createPipelineBatch is the batch rule of
// vkCreateComputePipelines and vkCreateGraphicsPipelines.
#pragma once

#include "runtime/device.hpp"
#include "runtime/object.hpp"

namespace vkrt {

class PipelineCache;
class PipelineLayout;

class Pipeline : public Object {
 public:
  using Handle = VkPipeline;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_PIPELINE;

  Pipeline(Device* dev, VkPipelineBindPoint bindPoint, VkPipelineCreateFlags flags, PipelineLayout* layout)
      : Object(kType, dev->instance, dev), bindPoint(bindPoint), createFlags(flags), layout(layout) {}
  virtual ~Pipeline() = default;

  const VkPipelineBindPoint bindPoint;
  const VkPipelineCreateFlags createFlags;
  PipelineLayout* const layout;
};

// One vkCreateXxxPipelines command as createPipelineBatch reports it: its name and the VUIDs of its device and
// pipelineCache parameter rules.
struct PipelineBatchCommand {
  const char* name;
  const char* deviceVuid;  // VUID-<name>-device-parameter
  const char* cacheVuid;   // VUID-<name>-pipelineCache-parameter
};

// The handle rules of a batch: `device` must be a live VkDevice and `pipelineCache` VK_NULL_HANDLE or a live
// VkPipelineCache. Returns false after reporting a broken rule; otherwise sets *dev and *cache (null for none).
bool checkPipelineBatchHandles(const PipelineBatchCommand& cmd, VkDevice device, VkPipelineCache pipelineCache,
                               Device** dev, PipelineCache** cache);

// Destroys the pipelines out[0, count) created by a batch that is being undone, and nulls their handles.
void undoPipelineBatch(VkPipeline* out, uint32_t count, const VkAllocationCallbacks* allocator);

// The body of vkCreateComputePipelines and vkCreateGraphicsPipelines (spec "Multiple Pipeline Creation"):
// after the handle checks, every out[i] is VK_NULL_HANDLE, then createOne(dev, cache, i, &out[i]) makes pipeline i
// in order, setting out[i] only on success. A misuse (VK_ERROR_VALIDATION_FAILED_EXT) or VK_ERROR_OUT_OF_HOST_MEMORY
// in any of them undoes the whole call: the pipelines made so far are destroyed and that result is returned. Any
// other failure (VK_PIPELINE_COMPILE_REQUIRED) leaves that pipeline VK_NULL_HANDLE and the batch goes on, unless
// its create info has VK_PIPELINE_CREATE_EARLY_RETURN_ON_FAILURE_BIT, which ends the batch there (the later handles
// stay VK_NULL_HANDLE); the first such result is returned. The ray tracing commands, which validate every create
// info before building any and may defer, keep their own loop (src/rt/rt_pipeline.cpp).
template <class CreateInfo, class CreateOne>
VkResult createPipelineBatch(const PipelineBatchCommand& cmd, VkDevice device, VkPipelineCache pipelineCache,
                             uint32_t count, const CreateInfo* infos, const VkAllocationCallbacks* allocator,
                             VkPipeline* out, CreateOne&& createOne) {
  Device* dev = nullptr;
  PipelineCache* cache = nullptr;
  if (!checkPipelineBatchHandles(cmd, device, pipelineCache, &dev, &cache)) return VK_ERROR_VALIDATION_FAILED_EXT;
  for (uint32_t i = 0; i < count; ++i) out[i] = VK_NULL_HANDLE;
  VkResult result = VK_SUCCESS;
  for (uint32_t i = 0; i < count; ++i) {
    const VkResult r = createOne(dev, cache, i, &out[i]);
    if (r == VK_SUCCESS) continue;
    if (r == VK_ERROR_VALIDATION_FAILED_EXT || r == VK_ERROR_OUT_OF_HOST_MEMORY) {
      undoPipelineBatch(out, i, allocator);
      return r;
    }
    if (result == VK_SUCCESS) result = r;
    if (infos[i].flags & VK_PIPELINE_CREATE_EARLY_RETURN_ON_FAILURE_BIT) break;
  }
  return result;
}

}  // namespace vkrt
