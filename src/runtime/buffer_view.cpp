#include "runtime/buffer_view.hpp"

#include <algorithm>

#include "runtime/alloc.hpp"
#include "runtime/buffer.hpp"
#include "runtime/device.hpp"
#include "runtime/format.hpp"
#include "runtime/lookup.hpp"
#include "runtime/physical_device.hpp"
#include "runtime/report.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {

BufferView::BufferView(Device* dev, const VkBufferViewCreateInfo& info, Buffer* buf, VkDeviceSize r)
    : Object(kType, dev->instance, dev),
      buffer(buf),
      format(info.format),
      offset(info.offset),
      range(r),
      formatInfo(vkrt::formatInfo(info.format)) {}

}  // namespace vkrt

using namespace vkrt;

extern "C" {

VKAPI_ATTR VkResult VKAPI_CALL vkrt_CreateBufferView(VkDevice device, const VkBufferViewCreateInfo* pCreateInfo,
                                                     const VkAllocationCallbacks* pAllocator, VkBufferView* pView) {
  Device* dev = fromHandleUnchecked<Device>(device);
  Buffer* buf = fromHandle<Buffer>(pCreateInfo->buffer);
  if (!buf) {
    report(dev, Severity::Error, "VUID-VkBufferViewCreateInfo-buffer-parameter",
           "vkCreateBufferView: buffer 0x%llx is not a live VkBuffer",
           (unsigned long long)rawHandle(pCreateInfo->buffer));
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  const FormatInfo* f = formatInfo(pCreateInfo->format);
  VkFormatFeatureFlags features = bufferFormatFeatures(pCreateInfo->format);
  // VUID-VkBufferViewCreateInfo-buffer-00933 / 00934: the format supports the buffer's texel usages
  bool uniform = buf->usage & VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT;
  bool storage = buf->usage & VK_BUFFER_USAGE_STORAGE_TEXEL_BUFFER_BIT;
  if (!uniform && !storage) {
    report(buf, Severity::Error, "VUID-VkBufferViewCreateInfo-buffer-00932",
           "vkCreateBufferView: the buffer has no texel buffer usage (usage 0x%x)", buf->usage);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  if (!f || (uniform && !(features & VK_FORMAT_FEATURE_UNIFORM_TEXEL_BUFFER_BIT)) ||
      (storage && !(features & VK_FORMAT_FEATURE_STORAGE_TEXEL_BUFFER_BIT))) {
    report(buf, Severity::Error,
           uniform ? "VUID-VkBufferViewCreateInfo-buffer-00933" : "VUID-VkBufferViewCreateInfo-buffer-00934",
           "vkCreateBufferView: format %d does not support the buffer's texel usage 0x%x", (int)pCreateInfo->format,
           buf->usage);
    return VK_ERROR_FORMAT_NOT_SUPPORTED;
  }
  const VkPhysicalDeviceLimits& l = dev->physicalDevice->properties10.limits;
  // The offset's alignment: minTexelBufferOffsetAlignment (VUID-VkBufferViewCreateInfo-offset-02749), or with the
  // texelBufferAlignment feature (VK_EXT_texel_buffer_alignment) the lesser of the usage's alignment in bytes and,
  // where single-texel alignment holds, a texel (a component for three-component formats): VUID-...-buffer-02750
  // for storage texel buffers, -02751 for uniform ones. The texel buffer functions read texels at any byte.
  VkDeviceSize alignment = l.minTexelBufferOffsetAlignment;
  const char* alignmentVuid = "VUID-VkBufferViewCreateInfo-offset-02749";
  if (dev->enabled(Feature::texelBufferAlignment)) {
    const VkPhysicalDeviceVulkan13Properties& p13 = dev->physicalDevice->properties13;
    const VkDeviceSize texel = f->texelSize % 3 == 0 ? f->texelSize / f->components : f->texelSize;
    auto lesser = [&](VkDeviceSize bytes, VkBool32 singleTexel) {
      return singleTexel ? std::min(bytes, texel) : bytes;
    };
    alignment = 1;
    if (storage) {
      alignment = lesser(p13.storageTexelBufferOffsetAlignmentBytes, p13.storageTexelBufferOffsetSingleTexelAlignment);
      alignmentVuid = "VUID-VkBufferViewCreateInfo-buffer-02750";
    }
    if (uniform) {
      VkDeviceSize u =
          lesser(p13.uniformTexelBufferOffsetAlignmentBytes, p13.uniformTexelBufferOffsetSingleTexelAlignment);
      if (pCreateInfo->offset % u) alignmentVuid = "VUID-VkBufferViewCreateInfo-buffer-02751";
      alignment = std::max(alignment, u);  // both are powers of two: a multiple of the larger is of both
    }
  }
  // VUID-VkBufferViewCreateInfo-offset-00925: below the size; and aligned (above)
  if (pCreateInfo->offset >= buf->size || pCreateInfo->offset % alignment) {
    report(buf, Severity::Error,
           pCreateInfo->offset >= buf->size ? "VUID-VkBufferViewCreateInfo-offset-00925" : alignmentVuid,
           "vkCreateBufferView: offset %llu must be below the buffer size %llu and a multiple of %llu",
           (unsigned long long)pCreateInfo->offset, (unsigned long long)buf->size, (unsigned long long)alignment);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  const bool whole = pCreateInfo->range == VK_WHOLE_SIZE;
  const VkDeviceSize range =
      whole ? (buf->size - pCreateInfo->offset) / f->texelSize * f->texelSize : pCreateInfo->range;
  // VUID-VkBufferViewCreateInfo-range-00928 (non-zero), range-00929 (texel multiple), offset-00931 (inside the
  // buffer), range-00930 / range-04059 (at most maxTexelBufferElements)
  const char* vuid = nullptr;
  if (!whole && range == 0)
    vuid = "VUID-VkBufferViewCreateInfo-range-00928";
  else if (!whole && range % f->texelSize)
    vuid = "VUID-VkBufferViewCreateInfo-range-00929";
  else if (!whole && range > buf->size - pCreateInfo->offset)
    vuid = "VUID-VkBufferViewCreateInfo-offset-00931";
  else if (range / f->texelSize > l.maxTexelBufferElements)
    vuid = whole ? "VUID-VkBufferViewCreateInfo-range-04059" : "VUID-VkBufferViewCreateInfo-range-00930";
  else if (range == 0)
    vuid = "VUID-VkBufferViewCreateInfo-range-04059";  // VK_WHOLE_SIZE leaves no texel
  if (vuid) {
    report(buf, Severity::Error, vuid,
           "vkCreateBufferView: range %llu at offset %llu is not a non-zero multiple of the %u-byte texel within the "
           "%llu-byte buffer and %u elements",
           (unsigned long long)pCreateInfo->range, (unsigned long long)pCreateInfo->offset, f->texelSize,
           (unsigned long long)buf->size, l.maxTexelBufferElements);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  auto* view = createObject<BufferView>(pAllocator, VK_SYSTEM_ALLOCATION_SCOPE_OBJECT, dev, *pCreateInfo, buf, range);
  if (!view) return VK_ERROR_OUT_OF_HOST_MEMORY;
  *pView = toHandle(view);
  return VK_SUCCESS;
}

VKAPI_ATTR void VKAPI_CALL vkrt_DestroyBufferView(VkDevice device, VkBufferView view,
                                                  const VkAllocationCallbacks* pAllocator) {
  destroyDeviceChildWhenIdle<BufferView>(device, view, pAllocator, "vkDestroyBufferView",
                                         "VUID-vkDestroyBufferView-bufferView-parameter",
                                         "VUID-vkDestroyBufferView-bufferView-00936");
}

}  // extern "C"
