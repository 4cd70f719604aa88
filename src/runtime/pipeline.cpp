// vkDestroyPipeline: one destroy for every pipeline kind, deleting through Pipeline's virtual destructor; the
// handle checks and the undo of createPipelineBatch.
#include "runtime/pipeline.hpp"

#include "runtime/alloc.hpp"
#include "runtime/device.hpp"
#include "runtime/lookup.hpp"
#include "runtime/pipeline_cache.hpp"
#include "runtime/report.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {

bool checkPipelineBatchHandles(const PipelineBatchCommand& cmd, VkDevice device, VkPipelineCache pipelineCache,
                               Device** dev, PipelineCache** cache) {
  *dev = fromHandle<Device>(device);
  // VUID-vkCreateComputePipelines-device-parameter, VUID-vkCreateGraphicsPipelines-device-parameter
  if (!*dev) {
    report(nullptr, Severity::Error, cmd.deviceVuid, "%s: device 0x%llx is not a live VkDevice", cmd.name,
           (unsigned long long)rawHandle(device));
    return false;
  }
  *cache = fromHandle<PipelineCache>(pipelineCache);
  // VUID-vkCreateComputePipelines-pipelineCache-parameter, VUID-vkCreateGraphicsPipelines-pipelineCache-parameter
  if (pipelineCache && !*cache) {
    report(*dev, Severity::Error, cmd.cacheVuid, "%s: pipelineCache 0x%llx is not a live VkPipelineCache", cmd.name,
           (unsigned long long)rawHandle(pipelineCache));
    return false;
  }
  return true;
}

void undoPipelineBatch(VkPipeline* out, uint32_t count, const VkAllocationCallbacks* allocator) {
  for (uint32_t k = 0; k < count; ++k) {
    destroyObject(fromHandleUnchecked<Pipeline>(out[k]), allocator);
    out[k] = VK_NULL_HANDLE;
  }
}

}  // namespace vkrt

using namespace vkrt;

extern "C" {

VKAPI_ATTR void VKAPI_CALL vkrt_DestroyPipeline(VkDevice device, VkPipeline pipeline,
                                                const VkAllocationCallbacks* pAllocator) {
  if (!pipeline) return;
  Pipeline* p = fromHandle<Pipeline>(pipeline);
  // VUID-vkDestroyPipeline-pipeline-parameter
  if (!p) {
    report(fromHandle<Device>(device), Severity::Error, "VUID-vkDestroyPipeline-pipeline-parameter",
           "vkDestroyPipeline: 0x%llx is not a live VkPipeline", (unsigned long long)rawHandle(pipeline));
    return;
  }
  destroyWhenIdle(p, pAllocator, "vkDestroyPipeline", "VUID-vkDestroyPipeline-pipeline-00765");
}

}  // extern "C"
