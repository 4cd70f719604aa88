// Binding-state commands: vkCmdBindPipeline, vkCmdBindDescriptorSets and vkCmdPushConstants. They record
// closures that update the executing command buffer's ExecState (runtime/command_buffer.hpp), which the
// dispatch and trace commands read. Push descriptors: runtime/push_descriptor_commands.cpp.
#include <algorithm>
#include <cstring>
#include <vector>

#include "runtime/buffer.hpp"
#include "runtime/command_buffer.hpp"
#include "runtime/command_pool.hpp"
#include "runtime/descriptor_set.hpp"
#include "runtime/device.hpp"
#include "runtime/physical_device.hpp"
#include "runtime/pipeline.hpp"
#include "runtime/pipeline_layout.hpp"
#include "runtime/report.hpp"
#include "vkrt_entrypoints.h"

using namespace vkrt;

namespace {

using ull = unsigned long long;

constexpr uint32_t kMaxSets = 8;  // BindState::sets

BindState& bindState(ExecState& st, VkPipelineBindPoint bp) { return st.bound(bindPointIndex(bp)); }

// The bind points vkrt's queue family (graphics + compute + transfer) supports.
bool supportedBindPoint(VkPipelineBindPoint bp) { return bindPointIndex(bp) >= 0; }

}  // namespace

extern "C" {

VKAPI_ATTR void VKAPI_CALL vkrt_CmdBindPipeline(VkCommandBuffer commandBuffer, VkPipelineBindPoint pipelineBindPoint,
                                                VkPipeline pipeline) {
  const char* fn = "vkCmdBindPipeline";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  Pipeline* p = fromHandle<Pipeline>(pipeline);
  if (!p) {
    report(cb, Severity::Error, "VUID-vkCmdBindPipeline-pipeline-parameter", "%s: 0x%llx is not a live VkPipeline", fn,
           (ull)rawHandle(pipeline));
    return;
  }
  // VUID-vkCmdBindPipeline-pipelineBindPoint-parameter (the queue family supports the three bind points)
  if (!supportedBindPoint(pipelineBindPoint)) {
    report(cb, Severity::Error, "VUID-vkCmdBindPipeline-pipelineBindPoint-parameter",
           "%s: pipelineBindPoint %d is not a bind point vkrt supports (graphics, compute, ray tracing)", fn,
           (int)pipelineBindPoint);
    return;
  }
  // VUID-vkCmdBindPipeline-pipelineBindPoint-00778
  if (pipelineBindPoint == VK_PIPELINE_BIND_POINT_GRAPHICS && !cb->supportsGraphics()) {
    report(cb, Severity::Error, "VUID-vkCmdBindPipeline-pipelineBindPoint-00778",
           "%s: VK_PIPELINE_BIND_POINT_GRAPHICS in a command buffer of queue family %u, which has no graphics", fn,
           cb->pool->queueFamilyIndex);
    return;
  }
  // VUID-vkCmdBindPipeline-pipelineBindPoint-00779, VUID-vkCmdBindPipeline-pipelineBindPoint-00780,
  // VUID-vkCmdBindPipeline-pipelineBindPoint-02392
  if (p->bindPoint != pipelineBindPoint) {
    const bool compute = pipelineBindPoint == VK_PIPELINE_BIND_POINT_COMPUTE;
    const bool graphics = pipelineBindPoint == VK_PIPELINE_BIND_POINT_GRAPHICS;
    report(p, Severity::Error,
           compute    ? "VUID-vkCmdBindPipeline-pipelineBindPoint-00779"
           : graphics ? "VUID-vkCmdBindPipeline-pipelineBindPoint-00780"
                      : "VUID-vkCmdBindPipeline-pipelineBindPoint-02392",
           "%s: pipelineBindPoint is %s but the pipeline is not a %s pipeline", fn,
           compute    ? "VK_PIPELINE_BIND_POINT_COMPUTE"
           : graphics ? "VK_PIPELINE_BIND_POINT_GRAPHICS"
                      : "VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR",
           compute    ? "compute"
           : graphics ? "graphics"
                      : "ray tracing");
    return;
  }
  // VUID-vkCmdBindPipeline-pipeline-03382
  if (p->createFlags & VK_PIPELINE_CREATE_LIBRARY_BIT_KHR) {
    report(p, Severity::Error, "VUID-vkCmdBindPipeline-pipeline-03382",
           "%s: the pipeline was created with VK_PIPELINE_CREATE_LIBRARY_BIT_KHR and cannot be bound", fn);
    return;
  }
  cb->record([pipelineBindPoint, p](ExecState& st) { bindState(st, pipelineBindPoint).pipeline = p; });
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdBindDescriptorSets(VkCommandBuffer commandBuffer,
                                                      VkPipelineBindPoint pipelineBindPoint, VkPipelineLayout layout,
                                                      uint32_t firstSet, uint32_t descriptorSetCount,
                                                      const VkDescriptorSet* pDescriptorSets,
                                                      uint32_t dynamicOffsetCount, const uint32_t* pDynamicOffsets) {
  const char* fn = "vkCmdBindDescriptorSets";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  PipelineLayout* pl = fromHandle<PipelineLayout>(layout);
  if (!pl) {
    report(cb, Severity::Error, "VUID-vkCmdBindDescriptorSets-layout-parameter",
           "%s: 0x%llx is not a live VkPipelineLayout", fn, (ull)rawHandle(layout));
    return;
  }
  // VUID-vkCmdBindDescriptorSets-pipelineBindPoint-parameter (the queue family supports the three bind points)
  if (!supportedBindPoint(pipelineBindPoint)) {
    report(cb, Severity::Error, "VUID-vkCmdBindDescriptorSets-pipelineBindPoint-parameter",
           "%s: pipelineBindPoint %d is not a bind point vkrt supports (graphics, compute, ray tracing)", fn,
           (int)pipelineBindPoint);
    return;
  }
  // VUID-vkCmdBindDescriptorSets-pipelineBindPoint-00361: a bind point the pool's queue family supports
  if (pipelineBindPoint == VK_PIPELINE_BIND_POINT_GRAPHICS && !cb->supportsGraphics()) {
    report(cb, Severity::Error, "VUID-vkCmdBindDescriptorSets-pipelineBindPoint-00361",
           "%s: VK_PIPELINE_BIND_POINT_GRAPHICS in a command buffer of queue family %u, which has no graphics", fn,
           cb->pool->queueFamilyIndex);
    return;
  }
  // VUID-vkCmdBindDescriptorSets-descriptorSetCount-arraylength
  if (descriptorSetCount == 0) {
    report(cb, Severity::Error, "VUID-vkCmdBindDescriptorSets-descriptorSetCount-arraylength",
           "%s: descriptorSetCount must be greater than 0", fn);
    return;
  }
  // VUID-vkCmdBindDescriptorSets-firstSet-00360
  if (firstSet > pl->setLayouts.size() || descriptorSetCount > pl->setLayouts.size() - firstSet ||
      firstSet + descriptorSetCount > kMaxSets) {
    report(pl, Severity::Error, "VUID-vkCmdBindDescriptorSets-firstSet-00360",
           "%s: sets [%u, %u) exceed the layout's %zu set layouts", fn, firstSet, firstSet + descriptorSetCount,
           pl->setLayouts.size());
    return;
  }
  std::vector<DescriptorSet*> sets(descriptorSetCount);
  uint32_t dynamicTotal = 0;
  for (uint32_t i = 0; i < descriptorSetCount; ++i) {
    DescriptorSet* s = fromHandle<DescriptorSet>(pDescriptorSets[i]);
    // VUID-vkCmdBindDescriptorSets-pDescriptorSets-06563
    if (!s) {
      report(cb, Severity::Error, "VUID-vkCmdBindDescriptorSets-pDescriptorSets-06563",
             "%s: pDescriptorSets[%u] 0x%llx is not a live VkDescriptorSet", fn, i, (ull)rawHandle(pDescriptorSets[i]));
      return;
    }
    // VUID-vkCmdBindDescriptorSets-pDescriptorSets-00358
    if (!s->layout->sameDefinition(*pl->setLayouts[firstSet + i])) {
      report(s, Severity::Error, "VUID-vkCmdBindDescriptorSets-pDescriptorSets-00358",
             "%s: pDescriptorSets[%u] was allocated with a set layout that does not match set %u of the pipeline "
             "layout",
             fn, i, firstSet + i);
      return;
    }
    sets[i] = s;
    dynamicTotal += s->layout->dynamicCount;
  }
  // VUID-vkCmdBindDescriptorSets-dynamicOffsetCount-00359
  if (dynamicOffsetCount != dynamicTotal) {
    report(cb, Severity::Error, "VUID-vkCmdBindDescriptorSets-dynamicOffsetCount-00359",
           "%s: dynamicOffsetCount is %u but the sets have %u dynamic descriptors", fn, dynamicOffsetCount,
           dynamicTotal);
    return;
  }
  const VkPhysicalDeviceLimits& limits = cb->device->physicalDevice->properties10.limits;
  std::vector<std::vector<uint32_t>> offsets(descriptorSetCount);
  uint32_t next = 0;
  for (uint32_t i = 0; i < descriptorSetCount; ++i) {
    DescriptorSet* s = sets[i];
    offsets[i].assign(pDynamicOffsets + next, pDynamicOffsets + next + s->layout->dynamicCount);
    for (const DescriptorBinding& b : s->layout->bindings) {
      if (!isDynamicBufferType(b.type)) continue;
      const bool uniform = b.type == VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC;
      const VkDeviceSize align =
          uniform ? limits.minUniformBufferOffsetAlignment : limits.minStorageBufferOffsetAlignment;
      for (uint32_t e = 0; e < s->elementCount(b); ++e) {
        const uint32_t index = next + b.dynamicIndex + e;
        const uint32_t off = pDynamicOffsets[index];
        // VUID-vkCmdBindDescriptorSets-pDynamicOffsets-01971, VUID-vkCmdBindDescriptorSets-pDynamicOffsets-01972
        if (align && off % align) {
          report(s, Severity::Error,
                 uniform ? "VUID-vkCmdBindDescriptorSets-pDynamicOffsets-01971"
                         : "VUID-vkCmdBindDescriptorSets-pDynamicOffsets-01972",
                 "%s: pDynamicOffsets[%u] = %u is not a multiple of %s (%llu)", fn, index, off,
                 uniform ? "minUniformBufferOffsetAlignment" : "minStorageBufferOffsetAlignment", (ull)align);
          return;
        }
        const DescriptorRecord& r = s->records()[b.offset + e];
        if (!r.object) continue;  // not written (partially bound)
        const Buffer* buf = recordObject<Buffer>(r.object);
        const uint64_t start = r.address - reinterpret_cast<uint64_t>(buf->data());
        // VUID-vkCmdBindDescriptorSets-pDescriptorSets-01979
        if (start + off + r.range > buf->size) {
          report(s, Severity::Error, "VUID-vkCmdBindDescriptorSets-pDescriptorSets-01979",
                 "%s: binding %u element %u: offset %llu + dynamic offset %u + range %llu exceeds the buffer size "
                 "%llu",
                 fn, b.binding, e, (ull)start, off, (ull)r.range, (ull)buf->size);
          return;
        }
      }
    }
    next += s->layout->dynamicCount;
  }
  // A push descriptor set of these numbers is disturbed: a later push starts from none (its descriptors are
  // undefined until pushed again: vkCmdPushDescriptorSetKHR).
  const int bpIndex = bindPointIndex(pipelineBindPoint);  // a supported one (checked above)
  for (uint32_t i = 0; i < descriptorSetCount; ++i) cb->pushedSets[bpIndex][firstSet + i].reset();
  cb->record([pipelineBindPoint, pl, firstSet, sets = std::move(sets), offsets = std::move(offsets)](ExecState& st) {
    BindState& bs = bindState(st, pipelineBindPoint);
    bs.layout = pl;
    for (size_t i = 0; i < sets.size(); ++i) {
      bs.sets[firstSet + i] = sets[i];
      bs.dynamicOffsets[firstSet + i] = offsets[i];
    }
  });
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdPushConstants(VkCommandBuffer commandBuffer, VkPipelineLayout layout,
                                                 VkShaderStageFlags stageFlags, uint32_t offset, uint32_t size,
                                                 const void* pValues) {
  const char* fn = "vkCmdPushConstants";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  PipelineLayout* pl = fromHandle<PipelineLayout>(layout);
  if (!pl) {
    report(cb, Severity::Error, "VUID-vkCmdPushConstants-layout-parameter", "%s: 0x%llx is not a live VkPipelineLayout",
           fn, (ull)rawHandle(layout));
    return;
  }
  // VUID-vkCmdPushConstants-stageFlags-requiredbitmask
  if (stageFlags == 0) {
    report(cb, Severity::Error, "VUID-vkCmdPushConstants-stageFlags-requiredbitmask", "%s: stageFlags is 0", fn);
    return;
  }
  // VUID-vkCmdPushConstants-size-arraylength
  if (size == 0) {
    report(cb, Severity::Error, "VUID-vkCmdPushConstants-size-arraylength", "%s: size must be greater than 0", fn);
    return;
  }
  // VUID-vkCmdPushConstants-offset-00368
  if (offset % 4) {
    report(cb, Severity::Error, "VUID-vkCmdPushConstants-offset-00368", "%s: offset %u is not a multiple of 4", fn,
           offset);
    return;
  }
  // VUID-vkCmdPushConstants-size-00369
  if (size % 4) {
    report(cb, Severity::Error, "VUID-vkCmdPushConstants-size-00369", "%s: size %u is not a multiple of 4", fn, size);
    return;
  }
  const uint32_t maxSize = std::min<uint32_t>(cb->device->physicalDevice->properties10.limits.maxPushConstantsSize,
                                              sizeof(ExecState::pushConstants));
  // VUID-vkCmdPushConstants-offset-00370
  if (offset >= maxSize) {
    report(cb, Severity::Error, "VUID-vkCmdPushConstants-offset-00370",
           "%s: offset %u is not less than maxPushConstantsSize %u", fn, offset, maxSize);
    return;
  }
  // VUID-vkCmdPushConstants-size-00371
  if (size > maxSize - offset) {
    report(cb, Severity::Error, "VUID-vkCmdPushConstants-size-00371", "%s: [%u, +%u) exceeds maxPushConstantsSize %u",
           fn, offset, size, maxSize);
    return;
  }
  for (uint32_t byte = offset; byte < offset + size; byte += 4) {
    VkShaderStageFlags covering = 0;
    for (const VkPushConstantRange& r : pl->pushConstantRanges) {
      if (byte < r.offset || byte - r.offset >= r.size) continue;
      covering |= r.stageFlags;
      // VUID-vkCmdPushConstants-offset-01796
      if ((r.stageFlags & stageFlags) != r.stageFlags) {
        report(
            pl, Severity::Error, "VUID-vkCmdPushConstants-offset-01796",
            "%s: byte %u lies in a push constant range of stages 0x%x, but stageFlags 0x%x does not include them all",
            fn, byte, r.stageFlags, stageFlags);
        return;
      }
    }
    // VUID-vkCmdPushConstants-offset-01795
    if ((covering & stageFlags) != stageFlags) {
      report(pl, Severity::Error, "VUID-vkCmdPushConstants-offset-01795",
             "%s: byte %u is not in a push constant range for every stage of stageFlags 0x%x (covered: 0x%x)", fn, byte,
             stageFlags, covering);
      return;
    }
  }
  std::vector<uint8_t> bytes(static_cast<const uint8_t*>(pValues), static_cast<const uint8_t*>(pValues) + size);
  cb->record([offset, bytes = std::move(bytes)](ExecState& st) {
    std::memcpy(st.pushConstants + offset, bytes.data(), bytes.size());
  });
}

}  // extern "C"
