// vkDestroyPipeline: one destroy for every pipeline kind, deleting through Pipeline's virtual destructor.
#include "runtime/pipeline.hpp"

#include "runtime/alloc.hpp"
#include "runtime/device.hpp"
#include "runtime/lookup.hpp"
#include "runtime/report.hpp"
#include "vkrt_entrypoints.h"

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
