// Vertex and index buffer binding and the draw commands: vkCmdBindVertexBuffers(2), vkCmdBindIndexBuffer, vkCmdDraw,
// vkCmdDrawIndexed, vkCmdDrawIndirect, vkCmdDrawIndexedIndirect, vkCmdDrawIndirectCount and
// vkCmdDrawIndexedIndirectCount. The rules on their own arguments are checked when they are recorded; the rules that
// need the bound pipeline when they execute (gfx/draw_executor.cpp).
#include <cstring>
#include <vector>

#include "gfx/draw_executor.hpp"
#include "gfx/graphics_state.hpp"
#include "runtime/buffer.hpp"
#include "runtime/device.hpp"
#include "runtime/physical_device.hpp"
#include "runtime/report.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt::gfx {
namespace {

using ull = unsigned long long;

struct Vuid {
  char text[96];
  Vuid(const char* command, const char* suffix) { std::snprintf(text, sizeof text, "VUID-%s-%s", command, suffix); }
};

const VkPhysicalDeviceLimits& limits(const CommandBuffer* cb) {
  return cb->device->physicalDevice->properties10.limits;
}

// VUID-vkCmdDraw*-renderpass: inside a render pass instance (or a secondary that continues one).
bool checkInsideRenderPass(CommandBuffer* cb, const char* command) {
  if (cb->insideRenderPass || recordState(cb).pass.active) return true;
  if (cb->level == VK_COMMAND_BUFFER_LEVEL_SECONDARY && (cb->usage & VK_COMMAND_BUFFER_USAGE_RENDER_PASS_CONTINUE_BIT))
    return true;
  Vuid v(command, "renderpass");
  report(cb, Severity::Error, v.text, "%s: recorded outside of a render pass instance", command);
  return false;
}

// The indirect buffer rules shared by the four indirect commands (VUID-<command>-buffer-02708, -buffer-02709,
// -offset-02710).
bool checkIndirectBuffer(CommandBuffer* cb, const Buffer* buf, VkBuffer handle, VkDeviceSize offset,
                         const char* command) {
  if (!buf) {
    Vuid v(command, "buffer-parameter");
    report(cb, Severity::Error, v.text, "%s: buffer 0x%llx is not a live VkBuffer", command, (ull)rawHandle(handle));
    return false;
  }
  const char* suffix = !(buf->usage & VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT) ? "buffer-02709"
                       : !buf->memory                                      ? "buffer-02708"
                       : offset % 4                                        ? "offset-02710"
                                                                           : nullptr;
  if (suffix) {
    Vuid v(command, suffix);
    report(buf, Severity::Error, v.text,
           "%s: buffer usage 0x%x (needs VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT), %s, offset %llu (a multiple of 4)",
           command, buf->usage, buf->memory ? "bound to memory" : "not bound to memory", (ull)offset);
    return false;
  }
  return true;
}

// The extent of `count` records of `size` bytes every `stride` bytes from `offset` fits in the buffer.
bool fits(const Buffer* buf, VkDeviceSize offset, uint32_t count, uint32_t stride, uint32_t size) {
  if (count == 0) return true;
  const unsigned __int128 end = (unsigned __int128)stride * (count - 1) + offset + size;
  return end <= buf->size;
}

// VkDrawIndirectCommand / VkDrawIndexedIndirectCommand rules checked as the draw executes (firstInstance without
// drawIndirectFirstInstance). Returns false after reporting.
bool checkFirstInstance(const CommandBuffer* cb, uint32_t firstInstance, bool indexed, const char* command) {
  if (firstInstance == 0 || cb->device->enabled(Feature::drawIndirectFirstInstance)) return true;
  // VUID-VkDrawIndirectCommand-firstInstance-00501, VUID-VkDrawIndexedIndirectCommand-firstInstance-00554
  report(cb, Severity::Error,
         indexed ? "VUID-VkDrawIndexedIndirectCommand-firstInstance-00554"
                 : "VUID-VkDrawIndirectCommand-firstInstance-00501",
         "%s: an indirect command has firstInstance %u but the drawIndirectFirstInstance feature is not enabled; the "
         "draw is skipped",
         command, firstInstance);
  return false;
}

// Runs the draws of an indirect command at execution.
void executeIndirect(const CommandBuffer* cb, ExecState& st, const Buffer* buf, VkDeviceSize offset, uint32_t drawCount,
                     uint32_t stride, bool indexed, const char* command) {
  for (uint32_t k = 0; k < drawCount; ++k) {
    const uint8_t* at = buf->data() + offset + uint64_t(k) * stride;
    DrawParams p;
    p.indexed = indexed;
    p.drawIndex = k;
    if (indexed) {
      VkDrawIndexedIndirectCommand c;
      std::memcpy(&c, at, sizeof c);
      if (!checkFirstInstance(cb, c.firstInstance, true, command)) return;
      p.count = c.indexCount;
      p.instanceCount = c.instanceCount;
      p.firstIndex = c.firstIndex;
      p.vertexOffset = c.vertexOffset;
      p.firstInstance = c.firstInstance;
    } else {
      VkDrawIndirectCommand c;
      std::memcpy(&c, at, sizeof c);
      if (!checkFirstInstance(cb, c.firstInstance, false, command)) return;
      p.count = c.vertexCount;
      p.instanceCount = c.instanceCount;
      p.firstVertex = c.firstVertex;
      p.firstInstance = c.firstInstance;
    }
    executeDraw(cb, st, p, command);
  }
}

void recordIndirect(VkCommandBuffer commandBuffer, VkBuffer buffer, VkDeviceSize offset, uint32_t drawCount,
                    uint32_t stride, bool indexed, const char* command) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, command);
  if (!cb || !checkInsideRenderPass(cb, command)) return;
  const Buffer* buf = fromHandle<Buffer>(buffer);
  if (!checkIndirectBuffer(cb, buf, buffer, offset, command)) return;
  const uint32_t size = indexed ? sizeof(VkDrawIndexedIndirectCommand) : sizeof(VkDrawIndirectCommand);
  const char* suffix = nullptr;
  // VUID-vkCmdDrawIndirect-drawCount-02718 / VUID-vkCmdDrawIndexedIndirect-drawCount-02718
  if (drawCount > 1 && !cb->device->enabled(Feature::multiDrawIndirect)) suffix = "drawCount-02718";
  // VUID-vkCmdDrawIndirect-drawCount-02719 / VUID-vkCmdDrawIndexedIndirect-drawCount-02719
  else if (drawCount > limits(cb).maxDrawIndirectCount)
    suffix = "drawCount-02719";
  // VUID-vkCmdDrawIndirect-drawCount-00476 / VUID-vkCmdDrawIndexedIndirect-drawCount-00528
  else if (drawCount > 1 && (stride % 4 || stride < size))
    suffix = indexed ? "drawCount-00528" : "drawCount-00476";
  // VUID-vkCmdDrawIndirect-drawCount-00487, -00488 / VUID-vkCmdDrawIndexedIndirect-drawCount-00539, -00540
  else if (!fits(buf, offset, drawCount, stride, size))
    suffix = drawCount == 1 ? (indexed ? "drawCount-00539" : "drawCount-00487")
                            : (indexed ? "drawCount-00540" : "drawCount-00488");
  if (suffix) {
    Vuid v(command, suffix);
    report(cb, Severity::Error, v.text,
           "%s: drawCount %u (multiDrawIndirect %s, maxDrawIndirectCount %u), stride %u, offset %llu, %u-byte "
           "commands, buffer size %llu",
           command, drawCount, cb->device->enabled(Feature::multiDrawIndirect) ? "on" : "off",
           limits(cb).maxDrawIndirectCount, stride, (ull)offset, size, (ull)buf->size);
    return;
  }
  if (indexed && !recordState(cb).draw.indexBound) {
    // VUID-vkCmdDrawIndexedIndirect-None-07312
    Vuid v(command, "None-07312");
    report(cb, Severity::Error, v.text, "%s: no index buffer is bound", command);
    return;
  }
  cb->record([cb, buf, offset, drawCount, stride, indexed, command](ExecState& st) {
    executeIndirect(cb, st, buf, offset, drawCount, stride, indexed, command);
  });
}

void recordIndirectCount(VkCommandBuffer commandBuffer, VkBuffer buffer, VkDeviceSize offset, VkBuffer countBuffer,
                         VkDeviceSize countBufferOffset, uint32_t maxDrawCount, uint32_t stride, bool indexed,
                         const char* command) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, command);
  if (!cb) return;
  // VUID-vkCmdDrawIndirectCount-None-04445 / VUID-vkCmdDrawIndexedIndirectCount-None-04445
  if (!cb->device->enabled(Feature::drawIndirectCount)) {
    Vuid v(command, "None-04445");
    report(cb, Severity::Error, v.text, "%s: the drawIndirectCount feature is not enabled", command);
    return;
  }
  if (!checkInsideRenderPass(cb, command)) return;
  const Buffer* buf = fromHandle<Buffer>(buffer);
  if (!checkIndirectBuffer(cb, buf, buffer, offset, command)) return;
  const Buffer* count = fromHandle<Buffer>(countBuffer);
  if (!count) {
    Vuid v(command, "countBuffer-parameter");
    report(cb, Severity::Error, v.text, "%s: countBuffer 0x%llx is not a live VkBuffer", command,
           (ull)rawHandle(countBuffer));
    return;
  }
  const uint32_t size = indexed ? sizeof(VkDrawIndexedIndirectCommand) : sizeof(VkDrawIndirectCommand);
  const char* suffix = nullptr;
  // VUID-<command>-countBuffer-02715, -countBuffer-02714, -countBufferOffset-02716, -countBufferOffset-04129,
  // -stride-03110 / -stride-03142, -maxDrawCount-03111 / -maxDrawCount-03143
  if (!(count->usage & VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT))
    suffix = "countBuffer-02715";
  else if (!count->memory)
    suffix = "countBuffer-02714";
  else if (countBufferOffset % 4)
    suffix = "countBufferOffset-02716";
  else if (countBufferOffset > count->size || count->size - countBufferOffset < 4)
    suffix = "countBufferOffset-04129";
  else if (stride % 4 || stride < size)
    suffix = indexed ? "stride-03142" : "stride-03110";
  else if (!fits(buf, offset, maxDrawCount, stride, size))
    suffix = indexed ? "maxDrawCount-03143" : "maxDrawCount-03111";
  if (suffix) {
    Vuid v(command, suffix);
    report(
        cb, Severity::Error, v.text,
        "%s: countBuffer usage 0x%x (%s), countBufferOffset %llu, count buffer size %llu; stride %u (a multiple of 4, "
        "at least %u), maxDrawCount %u, offset %llu, buffer size %llu",
        command, count->usage, count->memory ? "bound" : "not bound to memory", (ull)countBufferOffset,
        (ull)count->size, stride, size, maxDrawCount, (ull)offset, (ull)buf->size);
    return;
  }
  if (indexed && !recordState(cb).draw.indexBound) {
    // VUID-vkCmdDrawIndexedIndirectCount-None-07312
    Vuid v(command, "None-07312");
    report(cb, Severity::Error, v.text, "%s: no index buffer is bound", command);
    return;
  }
  cb->record([cb, buf, offset, count, countBufferOffset, maxDrawCount, stride, indexed, command](ExecState& st) {
    uint32_t n;
    std::memcpy(&n, count->data() + countBufferOffset, 4);
    // The draw count is the smaller of the buffer's value and maxDrawCount ("Drawing Commands").
    executeIndirect(cb, st, buf, offset, n < maxDrawCount ? n : maxDrawCount, stride, indexed, command);
  });
}

void bindVertexBuffers(VkCommandBuffer commandBuffer, uint32_t firstBinding, uint32_t bindingCount,
                       const VkBuffer* pBuffers, const VkDeviceSize* pOffsets, const VkDeviceSize* pSizes,
                       const VkDeviceSize* pStrides, const char* command) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, command);
  if (!cb) return;
  const uint32_t max = limits(cb).maxVertexInputBindings;
  // VUID-vkCmdBindVertexBuffers-firstBinding-00624, -00625 / VUID-vkCmdBindVertexBuffers2-firstBinding-03355,
  // -03356
  if (firstBinding >= max || uint64_t(firstBinding) + bindingCount > max) {
    const bool two = std::strcmp(command, "vkCmdBindVertexBuffers2") == 0;
    Vuid v(command, firstBinding >= max ? (two ? "firstBinding-03355" : "firstBinding-00624")
                                        : (two ? "firstBinding-03356" : "firstBinding-00625"));
    report(cb, Severity::Error, v.text, "%s: firstBinding %u, bindingCount %u exceed maxVertexInputBindings (%u)",
           command, firstBinding, bindingCount, max);
    return;
  }
  std::vector<VertexBufferBinding> bindings(bindingCount);
  const bool two = pSizes || pStrides || std::strcmp(command, "vkCmdBindVertexBuffers2") == 0;
  for (uint32_t k = 0; k < bindingCount; ++k) {
    const Buffer* buf = fromHandle<Buffer>(pBuffers[k]);
    const char* suffix = nullptr;
    // VUID-vkCmdBindVertexBuffers-pBuffers-04001 / VUID-vkCmdBindVertexBuffers2-pBuffers-04111 (nullDescriptor is not
    // supported), -pBuffers-00627 / -03359, -pBuffers-00628 / -03360, -pOffsets-00626 / -03357,
    // VUID-vkCmdBindVertexBuffers2-pSizes-03358, -pStrides-03362
    if (!buf)
      suffix = two ? "pBuffers-04111" : "pBuffers-04001";
    else if (!(buf->usage & VK_BUFFER_USAGE_VERTEX_BUFFER_BIT))
      suffix = two ? "pBuffers-03359" : "pBuffers-00627";
    else if (!buf->memory)
      suffix = two ? "pBuffers-03360" : "pBuffers-00628";
    else if (pOffsets[k] >= buf->size)
      suffix = two ? "pOffsets-03357" : "pOffsets-00626";
    else if (pSizes && pSizes[k] != VK_WHOLE_SIZE && pSizes[k] > buf->size - pOffsets[k])
      suffix = "pSizes-03358";
    else if (pStrides && pStrides[k] > limits(cb).maxVertexInputBindingStride)
      suffix = "pStrides-03362";
    if (suffix) {
      Vuid v(command, suffix);
      report(cb, Severity::Error, v.text,
             "%s: pBuffers[%u] 0x%llx (usage 0x%x, size %llu, %s), pOffsets[%u] %llu, size %llu, stride %llu (max %u)",
             command, k, (ull)rawHandle(pBuffers[k]), buf ? buf->usage : 0u, buf ? (ull)buf->size : 0ull,
             buf && buf->memory ? "bound" : "not bound", k, (ull)pOffsets[k],
             pSizes ? (ull)pSizes[k] : (ull)VK_WHOLE_SIZE, pStrides ? (ull)pStrides[k] : 0ull,
             limits(cb).maxVertexInputBindingStride);
      return;
    }
    VertexBufferBinding& b = bindings[k];
    b.buffer = buf;
    b.offset = pOffsets[k];
    b.size = pSizes && pSizes[k] != VK_WHOLE_SIZE ? pSizes[k] : buf->size - pOffsets[k];
    b.stride = pStrides ? uint32_t(pStrides[k]) : 0;
  }
  const bool strides = pStrides != nullptr;
  cb->record([firstBinding, strides, bindings = std::move(bindings)](ExecState& st) {
    DrawExecState& d = execState(st).draw;
    for (size_t k = 0; k < bindings.size(); ++k) {
      const uint32_t b = firstBinding + uint32_t(k);
      d.vertex[b] = bindings[k];
      d.vertexBound |= 1u << b;
      if (strides)
        d.strideSet |= 1u << b;
      else
        d.strideSet &= ~(1u << b);
    }
  });
}

}  // namespace
}  // namespace vkrt::gfx

using namespace vkrt;
using namespace vkrt::gfx;

extern "C" {

VKAPI_ATTR void VKAPI_CALL vkrt_CmdBindVertexBuffers(VkCommandBuffer commandBuffer, uint32_t firstBinding,
                                                     uint32_t bindingCount, const VkBuffer* pBuffers,
                                                     const VkDeviceSize* pOffsets) {
  bindVertexBuffers(commandBuffer, firstBinding, bindingCount, pBuffers, pOffsets, nullptr, nullptr,
                    "vkCmdBindVertexBuffers");
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdBindVertexBuffers2(VkCommandBuffer commandBuffer, uint32_t firstBinding,
                                                      uint32_t bindingCount, const VkBuffer* pBuffers,
                                                      const VkDeviceSize* pOffsets, const VkDeviceSize* pSizes,
                                                      const VkDeviceSize* pStrides) {
  bindVertexBuffers(commandBuffer, firstBinding, bindingCount, pBuffers, pOffsets, pSizes, pStrides,
                    "vkCmdBindVertexBuffers2");
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdBindIndexBuffer(VkCommandBuffer commandBuffer, VkBuffer buffer, VkDeviceSize offset,
                                                   VkIndexType indexType) {
  const char* fn = "vkCmdBindIndexBuffer";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  const Buffer* buf = fromHandle<Buffer>(buffer);
  if (!buf) {
    report(cb, Severity::Error, "VUID-vkCmdBindIndexBuffer-buffer-parameter",
           "%s: buffer 0x%llx is not a live VkBuffer", fn, (ull)rawHandle(buffer));
    return;
  }
  // VUID-vkCmdBindIndexBuffer-indexType-02507 (NONE), VUID-vkCmdBindIndexBuffer-indexType-02765 (UINT8:
  // indexTypeUint8 is not supported)
  if (indexType != VK_INDEX_TYPE_UINT16 && indexType != VK_INDEX_TYPE_UINT32) {
    report(cb, Severity::Error,
           indexType == VK_INDEX_TYPE_UINT8_EXT ? "VUID-vkCmdBindIndexBuffer-indexType-02765"
                                                : "VUID-vkCmdBindIndexBuffer-indexType-02507",
           "%s: indexType %d is not VK_INDEX_TYPE_UINT16 or VK_INDEX_TYPE_UINT32", fn, int(indexType));
    return;
  }
  const uint32_t size = indexType == VK_INDEX_TYPE_UINT16 ? 2 : 4;
  // VUID-vkCmdBindIndexBuffer-buffer-00433, -buffer-00434, -offset-00431, -offset-00432 (memory offsets are 64-byte
  // aligned: the buffer's own offset decides)
  const char* vuid = !(buf->usage & VK_BUFFER_USAGE_INDEX_BUFFER_BIT) ? "VUID-vkCmdBindIndexBuffer-buffer-00433"
                     : !buf->memory                                   ? "VUID-vkCmdBindIndexBuffer-buffer-00434"
                     : offset >= buf->size                            ? "VUID-vkCmdBindIndexBuffer-offset-00431"
                     : (buf->memoryOffset + offset) % size            ? "VUID-vkCmdBindIndexBuffer-offset-00432"
                                                                      : nullptr;
  if (vuid) {
    report(buf, Severity::Error, vuid,
           "%s: buffer usage 0x%x (needs VK_BUFFER_USAGE_INDEX_BUFFER_BIT), %s, size %llu; offset %llu (a multiple of "
           "%u, less than the size)",
           fn, buf->usage, buf->memory ? "bound" : "not bound to memory", (ull)buf->size, (ull)offset, size);
    return;
  }
  recordState(cb).draw.indexBound = true;
  const raster::IndexType type =
      indexType == VK_INDEX_TYPE_UINT16 ? raster::IndexType::UInt16 : raster::IndexType::UInt32;
  cb->record([buf, offset, type](ExecState& st) {
    DrawExecState& d = execState(st).draw;
    d.indexBuffer = buf;
    d.indexOffset = offset;
    d.indexType = type;
  });
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdDraw(VkCommandBuffer commandBuffer, uint32_t vertexCount, uint32_t instanceCount,
                                        uint32_t firstVertex, uint32_t firstInstance) {
  const char* fn = "vkCmdDraw";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb || !checkInsideRenderPass(cb, fn)) return;
  DrawParams p;
  p.count = vertexCount;
  p.instanceCount = instanceCount;
  p.firstVertex = firstVertex;
  p.firstInstance = firstInstance;
  cb->record([cb, p](ExecState& st) { executeDraw(cb, st, p, "vkCmdDraw"); });
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdDrawIndexed(VkCommandBuffer commandBuffer, uint32_t indexCount,
                                               uint32_t instanceCount, uint32_t firstIndex, int32_t vertexOffset,
                                               uint32_t firstInstance) {
  const char* fn = "vkCmdDrawIndexed";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb || !checkInsideRenderPass(cb, fn)) return;
  // VUID-vkCmdDrawIndexed-None-07312
  if (!recordState(cb).draw.indexBound) {
    report(cb, Severity::Error, "VUID-vkCmdDrawIndexed-None-07312", "%s: no index buffer is bound", fn);
    return;
  }
  DrawParams p;
  p.indexed = true;
  p.count = indexCount;
  p.instanceCount = instanceCount;
  p.firstIndex = firstIndex;
  p.vertexOffset = vertexOffset;
  p.firstInstance = firstInstance;
  cb->record([cb, p](ExecState& st) { executeDraw(cb, st, p, "vkCmdDrawIndexed"); });
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdDrawIndirect(VkCommandBuffer commandBuffer, VkBuffer buffer, VkDeviceSize offset,
                                                uint32_t drawCount, uint32_t stride) {
  recordIndirect(commandBuffer, buffer, offset, drawCount, stride, false, "vkCmdDrawIndirect");
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdDrawIndexedIndirect(VkCommandBuffer commandBuffer, VkBuffer buffer,
                                                       VkDeviceSize offset, uint32_t drawCount, uint32_t stride) {
  recordIndirect(commandBuffer, buffer, offset, drawCount, stride, true, "vkCmdDrawIndexedIndirect");
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdDrawIndirectCount(VkCommandBuffer commandBuffer, VkBuffer buffer,
                                                     VkDeviceSize offset, VkBuffer countBuffer,
                                                     VkDeviceSize countBufferOffset, uint32_t maxDrawCount,
                                                     uint32_t stride) {
  recordIndirectCount(commandBuffer, buffer, offset, countBuffer, countBufferOffset, maxDrawCount, stride, false,
                      "vkCmdDrawIndirectCount");
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdDrawIndexedIndirectCount(VkCommandBuffer commandBuffer, VkBuffer buffer,
                                                            VkDeviceSize offset, VkBuffer countBuffer,
                                                            VkDeviceSize countBufferOffset, uint32_t maxDrawCount,
                                                            uint32_t stride) {
  recordIndirectCount(commandBuffer, buffer, offset, countBuffer, countBufferOffset, maxDrawCount, stride, true,
                      "vkCmdDrawIndexedIndirectCount");
}

}  // extern "C"
