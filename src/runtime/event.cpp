#include "runtime/event.hpp"

#include <cstdio>
#include <vector>

#include "runtime/alloc.hpp"
#include "runtime/buffer.hpp"
#include "runtime/command_buffer.hpp"
#include "runtime/device.hpp"
#include "runtime/fence.hpp"
#include "runtime/image.hpp"
#include "runtime/queue.hpp"
#include "runtime/report.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {

Event::Event(Device* dev, VkEventCreateFlags f) : Object(kType, dev->instance, dev), flags(f) {}

}  // namespace vkrt

using namespace vkrt;

namespace {

// The layout transitions of swapchain images among `barriers` (the only images whose layout vkrt tracks: a present
// checks it), applied when the barrier executes.
template <class Barrier>
void addPresentableTransitions(uint32_t count, const Barrier* barriers,
                               std::vector<std::pair<Image*, VkImageLayout>>& out) {
  for (uint32_t i = 0; barriers && i < count; ++i) {
    Image* img = fromHandle<Image>(barriers[i].image);
    if (img && img->presentable && barriers[i].oldLayout != barriers[i].newLayout)
      out.emplace_back(img, barriers[i].newLayout);
  }
}

void applyTransitions(const std::vector<std::pair<Image*, VkImageLayout>>& transitions) {
  for (auto& [img, layout] : transitions) img->trackedLayout.store(layout);
}

Event* liveEvent(const Object* about, VkEvent h, const char* fn, const char* vuid) {
  Event* e = fromHandle<Event>(h);
  if (!e)
    report(about, Severity::Error, vuid, "%s: 0x%llx is not a live VkEvent", fn, (unsigned long long)rawHandle(h));
  return e;
}

void setEvent(Event* e, bool value) {
  {
    std::lock_guard lock(sync::mutex());
    e->set = value;
  }
  sync::notifyAll();
}

// Blocks the executing queue until every event is set (or the queue is being torn down).
void waitEvents(const std::vector<Event*>& events, const ExecState& st) {
  std::unique_lock lock(sync::mutex());
  sync::changed().wait(lock, [&] {
    if (st.queue && st.queue->abandoning()) return true;
    for (Event* e : events)
      if (!e->set) return false;
    return true;
  });
}

// Checks the ranges of buffer memory barriers (VkBufferMemoryBarrier, or VkBufferMemoryBarrier2 when `v2`: they
// share the buffer/offset/size members and the VUID numbers).
template <class Barrier>
bool checkBufferBarriers(CommandBuffer* cb, uint32_t count, const Barrier* barriers, const char* fn, bool v2) {
  for (uint32_t i = 0; i < count; ++i) {
    const Barrier& b = barriers[i];
    Buffer* buf = fromHandle<Buffer>(b.buffer);
    if (!buf) {
      report(cb, Severity::Error,
             v2 ? "VUID-VkBufferMemoryBarrier2-buffer-parameter" : "VUID-VkBufferMemoryBarrier-buffer-parameter",
             "%s: pBufferMemoryBarriers[%u].buffer 0x%llx is not a live VkBuffer", fn, i,
             (unsigned long long)rawHandle(b.buffer));
      return false;
    }
    // VUID-VkBufferMemoryBarrier-offset-01187, VUID-VkBufferMemoryBarrier2-offset-01187
    if (b.offset >= buf->size) {
      report(buf, Severity::Error,
             v2 ? "VUID-VkBufferMemoryBarrier2-offset-01187" : "VUID-VkBufferMemoryBarrier-offset-01187",
             "%s: pBufferMemoryBarriers[%u].offset %llu is not less than the buffer size %llu", fn, i,
             (unsigned long long)b.offset, (unsigned long long)buf->size);
      return false;
    }
    // VUID-VkBufferMemoryBarrier-size-01188, VUID-VkBufferMemoryBarrier2-size-01188
    if (b.size == 0) {
      report(buf, Severity::Error,
             v2 ? "VUID-VkBufferMemoryBarrier2-size-01188" : "VUID-VkBufferMemoryBarrier-size-01188",
             "%s: pBufferMemoryBarriers[%u].size is 0", fn, i);
      return false;
    }
    // VUID-VkBufferMemoryBarrier-size-01189, VUID-VkBufferMemoryBarrier2-size-01189
    if (b.size != VK_WHOLE_SIZE && b.size > buf->size - b.offset) {
      report(buf, Severity::Error,
             v2 ? "VUID-VkBufferMemoryBarrier2-size-01189" : "VUID-VkBufferMemoryBarrier-size-01189",
             "%s: pBufferMemoryBarriers[%u] [%llu, +%llu) exceeds the buffer size %llu", fn, i,
             (unsigned long long)b.offset, (unsigned long long)b.size, (unsigned long long)buf->size);
      return false;
    }
  }
  return true;
}

// The stage masks of each barrier of `dep` (named `name` in reports) against the command buffer's queue family
// (srcVuid / dstVuid), then the buffer barriers' ranges.
bool checkDependencyInfo(CommandBuffer* cb, const VkDependencyInfo* dep, const char* fn, const char* name,
                         const char* srcVuid, const char* dstVuid) {
  auto stages = [&](const char* member, uint32_t i, VkPipelineStageFlags2 src, VkPipelineStageFlags2 dst) {
    char what[128];
    std::snprintf(what, sizeof what, "%s->%s[%u].srcStageMask", name, member, i);
    if (!cb->familySupportsStages(src, fn, srcVuid, what)) return false;
    std::snprintf(what, sizeof what, "%s->%s[%u].dstStageMask", name, member, i);
    return cb->familySupportsStages(dst, fn, dstVuid, what);
  };
  for (uint32_t i = 0; i < dep->memoryBarrierCount; ++i)
    if (!stages("pMemoryBarriers", i, dep->pMemoryBarriers[i].srcStageMask, dep->pMemoryBarriers[i].dstStageMask))
      return false;
  for (uint32_t i = 0; i < dep->bufferMemoryBarrierCount; ++i)
    if (!stages("pBufferMemoryBarriers", i, dep->pBufferMemoryBarriers[i].srcStageMask,
                dep->pBufferMemoryBarriers[i].dstStageMask))
      return false;
  for (uint32_t i = 0; i < dep->imageMemoryBarrierCount; ++i)
    if (!stages("pImageMemoryBarriers", i, dep->pImageMemoryBarriers[i].srcStageMask,
                dep->pImageMemoryBarriers[i].dstStageMask))
      return false;
  return checkBufferBarriers(cb, dep->bufferMemoryBarrierCount, dep->pBufferMemoryBarriers, fn, true);
}

// The synchronization2 feature gate of the *2 commands.
bool checkSync2(CommandBuffer* cb, const char* fn, const char* vuid) {
  if (cb->device->enabled(Feature::synchronization2)) return true;
  report(cb, Severity::Error, vuid, "%s: the synchronization2 feature is not enabled", fn);
  return false;
}

void recordSetEvent(CommandBuffer* cb, Event* e, bool value) {
  cb->record([e, value](ExecState&) { setEvent(e, value); });
}

}  // namespace

extern "C" {

VKAPI_ATTR VkResult VKAPI_CALL vkrt_CreateEvent(VkDevice device, const VkEventCreateInfo* pCreateInfo,
                                                const VkAllocationCallbacks* pAllocator, VkEvent* pEvent) {
  Device* dev = fromHandleUnchecked<Device>(device);
  Event* e = createObject<Event>(pAllocator, VK_SYSTEM_ALLOCATION_SCOPE_OBJECT, dev, pCreateInfo->flags);
  if (!e) return VK_ERROR_OUT_OF_HOST_MEMORY;
  *pEvent = toHandle(e);
  return VK_SUCCESS;
}

VKAPI_ATTR void VKAPI_CALL vkrt_DestroyEvent(VkDevice device, VkEvent event, const VkAllocationCallbacks* pAllocator) {
  if (!event) return;
  Event* e = liveEvent(fromHandle<Device>(device), event, "vkDestroyEvent", "VUID-vkDestroyEvent-event-parameter");
  if (e) destroyObject(e, pAllocator);
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_GetEventStatus(VkDevice device, VkEvent event) {
  Event* e = liveEvent(fromHandle<Device>(device), event, "vkGetEventStatus", "VUID-vkGetEventStatus-event-parameter");
  if (!e) return VK_ERROR_VALIDATION_FAILED_EXT;
  // VUID-vkGetEventStatus-event-03940
  if (e->flags & VK_EVENT_CREATE_DEVICE_ONLY_BIT) {
    report(e, Severity::Error, "VUID-vkGetEventStatus-event-03940",
           "vkGetEventStatus: the event was created with VK_EVENT_CREATE_DEVICE_ONLY_BIT");
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  std::lock_guard lock(sync::mutex());
  return e->set ? VK_EVENT_SET : VK_EVENT_RESET;
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_SetEvent(VkDevice device, VkEvent event) {
  Event* e = liveEvent(fromHandle<Device>(device), event, "vkSetEvent", "VUID-vkSetEvent-event-parameter");
  if (!e) return VK_ERROR_VALIDATION_FAILED_EXT;
  // VUID-vkSetEvent-event-03941
  if (e->flags & VK_EVENT_CREATE_DEVICE_ONLY_BIT) {
    report(e, Severity::Error, "VUID-vkSetEvent-event-03941",
           "vkSetEvent: the event was created with VK_EVENT_CREATE_DEVICE_ONLY_BIT");
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  setEvent(e, true);
  return VK_SUCCESS;
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_ResetEvent(VkDevice device, VkEvent event) {
  Event* e = liveEvent(fromHandle<Device>(device), event, "vkResetEvent", "VUID-vkResetEvent-event-parameter");
  if (!e) return VK_ERROR_VALIDATION_FAILED_EXT;
  // VUID-vkResetEvent-event-03823
  if (e->flags & VK_EVENT_CREATE_DEVICE_ONLY_BIT) {
    report(e, Severity::Error, "VUID-vkResetEvent-event-03823",
           "vkResetEvent: the event was created with VK_EVENT_CREATE_DEVICE_ONLY_BIT");
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  setEvent(e, false);
  return VK_SUCCESS;
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdSetEvent(VkCommandBuffer commandBuffer, VkEvent event,
                                            VkPipelineStageFlags stageMask) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdSetEvent");
  if (!cb) return;
  // VUID-vkCmdSetEvent-renderpass: outside a render pass instance
  if (!cb->outsideRenderPass("vkCmdSetEvent", "VUID-vkCmdSetEvent-renderpass")) return;
  Event* e = liveEvent(cb, event, "vkCmdSetEvent", "VUID-vkCmdSetEvent-event-parameter");
  if (!e) return;
  // VUID-vkCmdSetEvent-stageMask-01149
  if (stageMask & VK_PIPELINE_STAGE_HOST_BIT) {
    report(cb, Severity::Error, "VUID-vkCmdSetEvent-stageMask-01149",
           "vkCmdSetEvent: stageMask 0x%x includes VK_PIPELINE_STAGE_HOST_BIT", stageMask);
    return;
  }
  if (!cb->familySupportsStages(stageMask, "vkCmdSetEvent", "VUID-vkCmdSetEvent-stageMask-06457", "stageMask")) return;
  recordSetEvent(cb, e, true);
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdResetEvent(VkCommandBuffer commandBuffer, VkEvent event,
                                              VkPipelineStageFlags stageMask) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdResetEvent");
  if (!cb) return;
  // VUID-vkCmdResetEvent-renderpass: outside a render pass instance
  if (!cb->outsideRenderPass("vkCmdResetEvent", "VUID-vkCmdResetEvent-renderpass")) return;
  Event* e = liveEvent(cb, event, "vkCmdResetEvent", "VUID-vkCmdResetEvent-event-parameter");
  if (!e) return;
  // VUID-vkCmdResetEvent-stageMask-01153
  if (stageMask & VK_PIPELINE_STAGE_HOST_BIT) {
    report(cb, Severity::Error, "VUID-vkCmdResetEvent-stageMask-01153",
           "vkCmdResetEvent: stageMask 0x%x includes VK_PIPELINE_STAGE_HOST_BIT", stageMask);
    return;
  }
  if (!cb->familySupportsStages(stageMask, "vkCmdResetEvent", "VUID-vkCmdResetEvent-stageMask-06458", "stageMask"))
    return;
  recordSetEvent(cb, e, false);
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdSetEvent2(VkCommandBuffer commandBuffer, VkEvent event,
                                             const VkDependencyInfo* pDependencyInfo) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdSetEvent2");
  // VUID-vkCmdSetEvent2-renderpass: outside a render pass instance
  if (cb && !cb->outsideRenderPass("vkCmdSetEvent2", "VUID-vkCmdSetEvent2-renderpass")) return;
  if (!cb || !checkSync2(cb, "vkCmdSetEvent2", "VUID-vkCmdSetEvent2-synchronization2-03824")) return;
  Event* e = liveEvent(cb, event, "vkCmdSetEvent2", "VUID-vkCmdSetEvent2-event-parameter");
  if (!e || !checkDependencyInfo(cb, pDependencyInfo, "vkCmdSetEvent2", "pDependencyInfo",
                                 "VUID-vkCmdSetEvent2-srcStageMask-03827", "VUID-vkCmdSetEvent2-dstStageMask-03828"))
    return;
  recordSetEvent(cb, e, true);
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdResetEvent2(VkCommandBuffer commandBuffer, VkEvent event,
                                               VkPipelineStageFlags2 stageMask) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdResetEvent2");
  // VUID-vkCmdResetEvent2-renderpass: outside a render pass instance
  if (cb && !cb->outsideRenderPass("vkCmdResetEvent2", "VUID-vkCmdResetEvent2-renderpass")) return;
  if (!cb || !checkSync2(cb, "vkCmdResetEvent2", "VUID-vkCmdResetEvent2-synchronization2-03829")) return;
  Event* e = liveEvent(cb, event, "vkCmdResetEvent2", "VUID-vkCmdResetEvent2-event-parameter");
  if (!e) return;
  // VUID-vkCmdResetEvent2-stageMask-03830
  if (stageMask & VK_PIPELINE_STAGE_2_HOST_BIT) {
    report(cb, Severity::Error, "VUID-vkCmdResetEvent2-stageMask-03830",
           "vkCmdResetEvent2: stageMask 0x%llx includes VK_PIPELINE_STAGE_2_HOST_BIT", (unsigned long long)stageMask);
    return;
  }
  recordSetEvent(cb, e, false);
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdWaitEvents(VkCommandBuffer commandBuffer, uint32_t eventCount,
                                              const VkEvent* pEvents, VkPipelineStageFlags srcStageMask,
                                              VkPipelineStageFlags dstStageMask, uint32_t, const VkMemoryBarrier*,
                                              uint32_t bufferMemoryBarrierCount,
                                              const VkBufferMemoryBarrier* pBufferMemoryBarriers,
                                              uint32_t imageMemoryBarrierCount,
                                              const VkImageMemoryBarrier* pImageMemoryBarriers) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdWaitEvents");
  if (!cb) return;
  // VUID-vkCmdWaitEvents-eventCount-arraylength
  if (eventCount == 0) {
    report(cb, Severity::Error, "VUID-vkCmdWaitEvents-eventCount-arraylength",
           "vkCmdWaitEvents: eventCount must be greater than 0");
    return;
  }
  std::vector<Event*> events(eventCount);
  for (uint32_t i = 0; i < eventCount; ++i)
    if (!(events[i] = liveEvent(cb, pEvents[i], "vkCmdWaitEvents", "VUID-vkCmdWaitEvents-pEvents-parameter"))) return;
  if (!cb->familySupportsStages(srcStageMask, "vkCmdWaitEvents", "VUID-vkCmdWaitEvents-srcStageMask-06459",
                                "srcStageMask") ||
      !cb->familySupportsStages(dstStageMask, "vkCmdWaitEvents", "VUID-vkCmdWaitEvents-dstStageMask-06460",
                                "dstStageMask"))
    return;
  if (!checkBufferBarriers(cb, bufferMemoryBarrierCount, pBufferMemoryBarriers, "vkCmdWaitEvents", false)) return;
  std::vector<std::pair<Image*, VkImageLayout>> transitions;
  addPresentableTransitions(imageMemoryBarrierCount, pImageMemoryBarriers, transitions);
  cb->record([events, transitions](ExecState& st) {
    waitEvents(events, st);
    applyTransitions(transitions);
  });
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdWaitEvents2(VkCommandBuffer commandBuffer, uint32_t eventCount,
                                               const VkEvent* pEvents, const VkDependencyInfo* pDependencyInfos) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdWaitEvents2");
  if (!cb || !checkSync2(cb, "vkCmdWaitEvents2", "VUID-vkCmdWaitEvents2-synchronization2-03836")) return;
  // VUID-vkCmdWaitEvents2-eventCount-arraylength
  if (eventCount == 0) {
    report(cb, Severity::Error, "VUID-vkCmdWaitEvents2-eventCount-arraylength",
           "vkCmdWaitEvents2: eventCount must be greater than 0");
    return;
  }
  std::vector<Event*> events(eventCount);
  for (uint32_t i = 0; i < eventCount; ++i) {
    if (!(events[i] = liveEvent(cb, pEvents[i], "vkCmdWaitEvents2", "VUID-vkCmdWaitEvents2-pEvents-parameter"))) return;
    char name[40];
    std::snprintf(name, sizeof name, "pDependencyInfos[%u]", i);
    // VUID-vkCmdWaitEvents2-srcStageMask-03842 allows HOST alone besides the family's stages: HOST is every family's.
    if (!checkDependencyInfo(cb, &pDependencyInfos[i], "vkCmdWaitEvents2", name,
                             "VUID-vkCmdWaitEvents2-srcStageMask-03842", "VUID-vkCmdWaitEvents2-dstStageMask-03843"))
      return;
  }
  std::vector<std::pair<Image*, VkImageLayout>> transitions;
  for (uint32_t i = 0; i < eventCount; ++i)
    addPresentableTransitions(pDependencyInfos[i].imageMemoryBarrierCount, pDependencyInfos[i].pImageMemoryBarriers,
                              transitions);
  cb->record([events, transitions](ExecState& st) {
    waitEvents(events, st);
    applyTransitions(transitions);
  });
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdPipelineBarrier(VkCommandBuffer commandBuffer, VkPipelineStageFlags srcStageMask,
                                                   VkPipelineStageFlags dstStageMask, VkDependencyFlags, uint32_t,
                                                   const VkMemoryBarrier*, uint32_t bufferMemoryBarrierCount,
                                                   const VkBufferMemoryBarrier* pBufferMemoryBarriers,
                                                   uint32_t imageMemoryBarrierCount,
                                                   const VkImageMemoryBarrier* pImageMemoryBarriers) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdPipelineBarrier");
  if (!cb) return;
  if (!cb->familySupportsStages(srcStageMask, "vkCmdPipelineBarrier", "VUID-vkCmdPipelineBarrier-srcStageMask-06461",
                                "srcStageMask") ||
      !cb->familySupportsStages(dstStageMask, "vkCmdPipelineBarrier", "VUID-vkCmdPipelineBarrier-dstStageMask-06462",
                                "dstStageMask"))
    return;
  if (!checkBufferBarriers(cb, bufferMemoryBarrierCount, pBufferMemoryBarriers, "vkCmdPipelineBarrier", false)) return;
  // Commands execute in order on one worker: the barrier keeps its place and has nothing else to do but note the
  // layouts of swapchain images.
  std::vector<std::pair<Image*, VkImageLayout>> transitions;
  addPresentableTransitions(imageMemoryBarrierCount, pImageMemoryBarriers, transitions);
  cb->record([transitions](ExecState&) { applyTransitions(transitions); });
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdPipelineBarrier2(VkCommandBuffer commandBuffer,
                                                    const VkDependencyInfo* pDependencyInfo) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdPipelineBarrier2");
  if (!cb || !checkSync2(cb, "vkCmdPipelineBarrier2", "VUID-vkCmdPipelineBarrier2-synchronization2-03848")) return;
  if (!checkDependencyInfo(cb, pDependencyInfo, "vkCmdPipelineBarrier2", "pDependencyInfo",
                           "VUID-vkCmdPipelineBarrier2-srcStageMask-03849",
                           "VUID-vkCmdPipelineBarrier2-dstStageMask-03850"))
    return;
  std::vector<std::pair<Image*, VkImageLayout>> transitions;
  addPresentableTransitions(pDependencyInfo->imageMemoryBarrierCount, pDependencyInfo->pImageMemoryBarriers,
                            transitions);
  cb->record([transitions](ExecState&) { applyTransitions(transitions); });
}

}  // extern "C"
