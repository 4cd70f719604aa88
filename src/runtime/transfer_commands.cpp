// Transfer commands on buffers: vkCmdCopyBuffer(2), vkCmdFillBuffer, vkCmdUpdateBuffer.
#include <cstring>
#include <string>
#include <vector>

#include "runtime/buffer.hpp"
#include "runtime/command_buffer.hpp"
#include "runtime/report.hpp"
#include "vkrt_entrypoints.h"

using namespace vkrt;

namespace {

using ull = unsigned long long;

Buffer* liveBuffer(const CommandBuffer* cb, VkBuffer h, const char* fn, const char* what, const char* vuid) {
  Buffer* b = fromHandle<Buffer>(h);
  if (!b) report(cb, Severity::Error, vuid, "%s: %s 0x%llx is not a live VkBuffer", fn, what, (ull)rawHandle(h));
  return b;
}

// VUID names of vkCmdCopyBuffer and VkCopyBufferInfo2 differ only in their prefix.
struct CopyVuids {
  const char* prefix;  // "VUID-vkCmdCopyBuffer-" or "VUID-VkCopyBufferInfo2-"
  std::string operator()(const char* rest) const { return std::string(prefix) + rest; }
};

template <class Region>
void recordCopy(CommandBuffer* cb, VkBuffer srcH, VkBuffer dstH, uint32_t regionCount, const Region* regions,
                const char* fn, const CopyVuids& v) {
  Buffer* src = liveBuffer(cb, srcH, fn, "srcBuffer", v("srcBuffer-parameter").c_str());
  if (!src) return;
  Buffer* dst = liveBuffer(cb, dstH, fn, "dstBuffer", v("dstBuffer-parameter").c_str());
  if (!dst) return;
  // VUID-vkCmdCopyBuffer-regionCount-arraylength, VUID-VkCopyBufferInfo2-regionCount-arraylength
  if (regionCount == 0) {
    report(cb, Severity::Error, v("regionCount-arraylength").c_str(), "%s: regionCount must be greater than 0", fn);
    return;
  }
  // VUID-vkCmdCopyBuffer-srcBuffer-00118
  if (!(src->usage & VK_BUFFER_USAGE_TRANSFER_SRC_BIT)) {
    report(src, Severity::Error, v("srcBuffer-00118").c_str(),
           "%s: srcBuffer was created without VK_BUFFER_USAGE_TRANSFER_SRC_BIT (usage 0x%x)", fn, src->usage);
    return;
  }
  // VUID-vkCmdCopyBuffer-dstBuffer-00120
  if (!(dst->usage & VK_BUFFER_USAGE_TRANSFER_DST_BIT)) {
    report(dst, Severity::Error, v("dstBuffer-00120").c_str(),
           "%s: dstBuffer was created without VK_BUFFER_USAGE_TRANSFER_DST_BIT (usage 0x%x)", fn, dst->usage);
    return;
  }
  // VUID-vkCmdCopyBuffer-srcBuffer-00119
  if (!src->memory) {
    report(src, Severity::Error, v("srcBuffer-00119").c_str(), "%s: srcBuffer is not bound to memory", fn);
    return;
  }
  // VUID-vkCmdCopyBuffer-dstBuffer-00121
  if (!dst->memory) {
    report(dst, Severity::Error, v("dstBuffer-00121").c_str(), "%s: dstBuffer is not bound to memory", fn);
    return;
  }
  std::vector<VkBufferCopy> copies(regionCount);
  for (uint32_t i = 0; i < regionCount; ++i) {
    const Region& r = regions[i];
    copies[i] = {r.srcOffset, r.dstOffset, r.size};
    // VUID-VkBufferCopy-size-01988, VUID-VkBufferCopy2-size-01988
    if (r.size == 0) {
      report(cb, Severity::Error, v.prefix[5] == 'v' ? "VUID-VkBufferCopy-size-01988" : "VUID-VkBufferCopy2-size-01988",
             "%s: pRegions[%u].size must be greater than 0", fn, i);
      return;
    }
    // VUID-vkCmdCopyBuffer-srcOffset-00113
    if (r.srcOffset >= src->size) {
      report(src, Severity::Error, v("srcOffset-00113").c_str(),
             "%s: pRegions[%u].srcOffset %llu is not less than the srcBuffer size %llu", fn, i, (ull)r.srcOffset,
             (ull)src->size);
      return;
    }
    // VUID-vkCmdCopyBuffer-dstOffset-00114
    if (r.dstOffset >= dst->size) {
      report(dst, Severity::Error, v("dstOffset-00114").c_str(),
             "%s: pRegions[%u].dstOffset %llu is not less than the dstBuffer size %llu", fn, i, (ull)r.dstOffset,
             (ull)dst->size);
      return;
    }
    // VUID-vkCmdCopyBuffer-size-00115
    if (r.size > src->size - r.srcOffset) {
      report(src, Severity::Error, v("size-00115").c_str(),
             "%s: pRegions[%u] reads [%llu, +%llu) past the end of the %llu-byte srcBuffer", fn, i, (ull)r.srcOffset,
             (ull)r.size, (ull)src->size);
      return;
    }
    // VUID-vkCmdCopyBuffer-size-00116
    if (r.size > dst->size - r.dstOffset) {
      report(dst, Severity::Error, v("size-00116").c_str(),
             "%s: pRegions[%u] writes [%llu, +%llu) past the end of the %llu-byte dstBuffer", fn, i, (ull)r.dstOffset,
             (ull)r.size, (ull)dst->size);
      return;
    }
  }
  // VUID-vkCmdCopyBuffer-pRegions-00117: source and destination regions must not overlap in memory
  const uint8_t* srcBase = src->data();
  const uint8_t* dstBase = dst->data();
  for (uint32_t i = 0; i < regionCount; ++i) {
    for (uint32_t k = 0; k < regionCount; ++k) {
      const uint8_t* s = srcBase + copies[i].srcOffset;
      const uint8_t* d = dstBase + copies[k].dstOffset;
      if (s < d + copies[k].size && d < s + copies[i].size) {
        report(dst, Severity::Error, v("pRegions-00117").c_str(),
               "%s: source region %u [%llu, +%llu) overlaps destination region %u [%llu, +%llu) in memory", fn, i,
               (ull)copies[i].srcOffset, (ull)copies[i].size, k, (ull)copies[k].dstOffset, (ull)copies[k].size);
        return;
      }
    }
  }
  cb->record([src, dst, copies = std::move(copies)](ExecState&) {
    for (const VkBufferCopy& c : copies) std::memcpy(dst->data() + c.dstOffset, src->data() + c.srcOffset, c.size);
  });
}

}  // namespace

extern "C" {

VKAPI_ATTR void VKAPI_CALL vkrt_CmdCopyBuffer(VkCommandBuffer commandBuffer, VkBuffer srcBuffer, VkBuffer dstBuffer,
                                              uint32_t regionCount, const VkBufferCopy* pRegions) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdCopyBuffer");
  if (!cb) return;
  // VUID-vkCmdCopyBuffer-renderpass: outside a render pass instance
  if (!cb->outsideRenderPass("vkCmdCopyBuffer", "VUID-vkCmdCopyBuffer-renderpass")) return;
  recordCopy(cb, srcBuffer, dstBuffer, regionCount, pRegions, "vkCmdCopyBuffer", CopyVuids{"VUID-vkCmdCopyBuffer-"});
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdCopyBuffer2(VkCommandBuffer commandBuffer,
                                               const VkCopyBufferInfo2* pCopyBufferInfo) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdCopyBuffer2");
  if (!cb) return;
  // VUID-vkCmdCopyBuffer2-renderpass: outside a render pass instance
  if (!cb->outsideRenderPass("vkCmdCopyBuffer2", "VUID-vkCmdCopyBuffer2-renderpass")) return;
  recordCopy(cb, pCopyBufferInfo->srcBuffer, pCopyBufferInfo->dstBuffer, pCopyBufferInfo->regionCount,
             pCopyBufferInfo->pRegions, "vkCmdCopyBuffer2", CopyVuids{"VUID-VkCopyBufferInfo2-"});
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdFillBuffer(VkCommandBuffer commandBuffer, VkBuffer dstBuffer, VkDeviceSize dstOffset,
                                              VkDeviceSize size, uint32_t data) {
  const char* fn = "vkCmdFillBuffer";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  // VUID-vkCmdFillBuffer-renderpass: outside a render pass instance
  if (!cb->outsideRenderPass(fn, "VUID-vkCmdFillBuffer-renderpass")) return;
  Buffer* dst = liveBuffer(cb, dstBuffer, fn, "dstBuffer", "VUID-vkCmdFillBuffer-dstBuffer-parameter");
  if (!dst) return;
  // VUID-vkCmdFillBuffer-dstBuffer-00029
  if (!(dst->usage & VK_BUFFER_USAGE_TRANSFER_DST_BIT)) {
    report(dst, Severity::Error, "VUID-vkCmdFillBuffer-dstBuffer-00029",
           "%s: dstBuffer was created without VK_BUFFER_USAGE_TRANSFER_DST_BIT (usage 0x%x)", fn, dst->usage);
    return;
  }
  // VUID-vkCmdFillBuffer-dstBuffer-00031
  if (!dst->memory) {
    report(dst, Severity::Error, "VUID-vkCmdFillBuffer-dstBuffer-00031", "%s: dstBuffer is not bound to memory", fn);
    return;
  }
  // VUID-vkCmdFillBuffer-dstOffset-00024
  if (dstOffset >= dst->size) {
    report(dst, Severity::Error, "VUID-vkCmdFillBuffer-dstOffset-00024",
           "%s: dstOffset %llu is not less than the buffer size %llu", fn, (ull)dstOffset, (ull)dst->size);
    return;
  }
  // VUID-vkCmdFillBuffer-dstOffset-00025
  if (dstOffset % 4) {
    report(dst, Severity::Error, "VUID-vkCmdFillBuffer-dstOffset-00025", "%s: dstOffset %llu is not a multiple of 4",
           fn, (ull)dstOffset);
    return;
  }
  if (size != VK_WHOLE_SIZE) {
    // VUID-vkCmdFillBuffer-size-00026
    if (size == 0) {
      report(dst, Severity::Error, "VUID-vkCmdFillBuffer-size-00026", "%s: size must be greater than 0", fn);
      return;
    }
    // VUID-vkCmdFillBuffer-size-00027
    if (size > dst->size - dstOffset) {
      report(dst, Severity::Error, "VUID-vkCmdFillBuffer-size-00027",
             "%s: [%llu, +%llu) runs past the end of the %llu-byte buffer", fn, (ull)dstOffset, (ull)size,
             (ull)dst->size);
      return;
    }
    // VUID-vkCmdFillBuffer-size-00028
    if (size % 4) {
      report(dst, Severity::Error, "VUID-vkCmdFillBuffer-size-00028", "%s: size %llu is not a multiple of 4", fn,
             (ull)size);
      return;
    }
  } else {
    size = (dst->size - dstOffset) & ~VkDeviceSize(3);  // the whole rest, rounded down to a multiple of 4
  }
  cb->record([dst, dstOffset, size, data](ExecState&) {
    uint8_t* p = dst->data() + dstOffset;
    for (VkDeviceSize i = 0; i < size; i += 4) std::memcpy(p + i, &data, 4);
  });
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdUpdateBuffer(VkCommandBuffer commandBuffer, VkBuffer dstBuffer,
                                                VkDeviceSize dstOffset, VkDeviceSize dataSize, const void* pData) {
  const char* fn = "vkCmdUpdateBuffer";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  // VUID-vkCmdUpdateBuffer-renderpass: outside a render pass instance
  if (!cb->outsideRenderPass(fn, "VUID-vkCmdUpdateBuffer-renderpass")) return;
  Buffer* dst = liveBuffer(cb, dstBuffer, fn, "dstBuffer", "VUID-vkCmdUpdateBuffer-dstBuffer-parameter");
  if (!dst) return;
  // VUID-vkCmdUpdateBuffer-dstBuffer-00034
  if (!(dst->usage & VK_BUFFER_USAGE_TRANSFER_DST_BIT)) {
    report(dst, Severity::Error, "VUID-vkCmdUpdateBuffer-dstBuffer-00034",
           "%s: dstBuffer was created without VK_BUFFER_USAGE_TRANSFER_DST_BIT (usage 0x%x)", fn, dst->usage);
    return;
  }
  // VUID-vkCmdUpdateBuffer-dstBuffer-00035
  if (!dst->memory) {
    report(dst, Severity::Error, "VUID-vkCmdUpdateBuffer-dstBuffer-00035", "%s: dstBuffer is not bound to memory", fn);
    return;
  }
  // VUID-vkCmdUpdateBuffer-dataSize-arraylength
  if (dataSize == 0) {
    report(dst, Severity::Error, "VUID-vkCmdUpdateBuffer-dataSize-arraylength", "%s: dataSize must be greater than 0",
           fn);
    return;
  }
  // VUID-vkCmdUpdateBuffer-dataSize-00037
  if (dataSize > 65536) {
    report(dst, Severity::Error, "VUID-vkCmdUpdateBuffer-dataSize-00037", "%s: dataSize %llu is greater than 65536", fn,
           (ull)dataSize);
    return;
  }
  // VUID-vkCmdUpdateBuffer-dataSize-00038
  if (dataSize % 4) {
    report(dst, Severity::Error, "VUID-vkCmdUpdateBuffer-dataSize-00038", "%s: dataSize %llu is not a multiple of 4",
           fn, (ull)dataSize);
    return;
  }
  // VUID-vkCmdUpdateBuffer-dstOffset-00032
  if (dstOffset >= dst->size) {
    report(dst, Severity::Error, "VUID-vkCmdUpdateBuffer-dstOffset-00032",
           "%s: dstOffset %llu is not less than the buffer size %llu", fn, (ull)dstOffset, (ull)dst->size);
    return;
  }
  // VUID-vkCmdUpdateBuffer-dstOffset-00036
  if (dstOffset % 4) {
    report(dst, Severity::Error, "VUID-vkCmdUpdateBuffer-dstOffset-00036", "%s: dstOffset %llu is not a multiple of 4",
           fn, (ull)dstOffset);
    return;
  }
  // VUID-vkCmdUpdateBuffer-dataSize-00033
  if (dataSize > dst->size - dstOffset) {
    report(dst, Severity::Error, "VUID-vkCmdUpdateBuffer-dataSize-00033",
           "%s: [%llu, +%llu) runs past the end of the %llu-byte buffer", fn, (ull)dstOffset, (ull)dataSize,
           (ull)dst->size);
    return;
  }
  const uint8_t* bytes = static_cast<const uint8_t*>(pData);
  cb->record([dst, dstOffset, data = std::vector<uint8_t>(bytes, bytes + dataSize)](ExecState&) {
    std::memcpy(dst->data() + dstOffset, data.data(), data.size());
  });
}

}  // extern "C"
