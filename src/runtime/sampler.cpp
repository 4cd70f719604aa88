#include "runtime/sampler.hpp"

#include "runtime/alloc.hpp"
#include "runtime/device.hpp"
#include "runtime/lookup.hpp"
#include "runtime/physical_device.hpp"
#include "runtime/report.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {

Sampler::Sampler(Device* dev, const VkSamplerCreateInfo& ci) : Object(kType, dev->instance, dev), info(ci) {
  info.pNext = nullptr;
}

}  // namespace vkrt

using namespace vkrt;

extern "C" {

VKAPI_ATTR VkResult VKAPI_CALL vkrt_CreateSampler(VkDevice device, const VkSamplerCreateInfo* pCreateInfo,
                                                  const VkAllocationCallbacks* pAllocator, VkSampler* pSampler) {
  Device* dev = fromHandleUnchecked<Device>(device);
  if (pCreateInfo->anisotropyEnable) {
    // VUID-VkSamplerCreateInfo-anisotropyEnable-01070: the samplerAnisotropy feature must be enabled
    if (!dev->enabled(Feature::samplerAnisotropy)) {
      report(dev, Severity::Error, "VUID-VkSamplerCreateInfo-anisotropyEnable-01070",
             "vkCreateSampler: anisotropyEnable is VK_TRUE, but the device was created without samplerAnisotropy");
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
    // VUID-VkSamplerCreateInfo-anisotropyEnable-01071: maxAnisotropy in [1, maxSamplerAnisotropy]
    const float limit = dev->physicalDevice->properties10.limits.maxSamplerAnisotropy;
    if (!(pCreateInfo->maxAnisotropy >= 1.0f && pCreateInfo->maxAnisotropy <= limit)) {
      report(dev, Severity::Error, "VUID-VkSamplerCreateInfo-anisotropyEnable-01071",
             "vkCreateSampler: maxAnisotropy %g is outside [1, %g] (maxSamplerAnisotropy)",
             double(pCreateInfo->maxAnisotropy), double(limit));
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
    // VUID-VkSamplerCreateInfo-unnormalizedCoordinates-01076: no anisotropy with unnormalized coordinates
    if (pCreateInfo->unnormalizedCoordinates) {
      report(dev, Severity::Error, "VUID-VkSamplerCreateInfo-unnormalizedCoordinates-01076",
             "vkCreateSampler: anisotropyEnable and unnormalizedCoordinates are both VK_TRUE");
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
  }
  // VUID-VkSamplerCreateInfo-addressModeU-01079: MIRROR_CLAMP_TO_EDGE needs samplerMirrorClampToEdge or
  // VK_KHR_sampler_mirror_clamp_to_edge (the image functions implement it: runtime/image_functions.cpp, wrap)
  for (VkSamplerAddressMode m : {pCreateInfo->addressModeU, pCreateInfo->addressModeV, pCreateInfo->addressModeW}) {
    if (m == VK_SAMPLER_ADDRESS_MODE_MIRROR_CLAMP_TO_EDGE && !dev->enabled(Feature::samplerMirrorClampToEdge) &&
        !dev->extensionEnabled(VK_KHR_SAMPLER_MIRROR_CLAMP_TO_EDGE_EXTENSION_NAME)) {
      report(dev, Severity::Error, "VUID-VkSamplerCreateInfo-addressModeU-01079",
             "vkCreateSampler: address mode VK_SAMPLER_ADDRESS_MODE_MIRROR_CLAMP_TO_EDGE (U %d, V %d, W %d) needs the "
             "samplerMirrorClampToEdge feature or the VK_KHR_sampler_mirror_clamp_to_edge extension, and neither is "
             "enabled",
             (int)pCreateInfo->addressModeU, (int)pCreateInfo->addressModeV, (int)pCreateInfo->addressModeW);
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
  }
  // VUID-VkSamplerCreateInfo-unnormalizedCoordinates-01072..01076
  if (pCreateInfo->unnormalizedCoordinates &&
      (pCreateInfo->minFilter != pCreateInfo->magFilter || pCreateInfo->mipmapMode != VK_SAMPLER_MIPMAP_MODE_NEAREST ||
       pCreateInfo->minLod != 0.0f || pCreateInfo->maxLod != 0.0f ||
       (pCreateInfo->addressModeU != VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE &&
        pCreateInfo->addressModeU != VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER) ||
       (pCreateInfo->addressModeV != VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE &&
        pCreateInfo->addressModeV != VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER) ||
       pCreateInfo->compareEnable)) {
    report(dev, Severity::Error, "VUID-VkSamplerCreateInfo-unnormalizedCoordinates-01072",
           "vkCreateSampler: unnormalizedCoordinates requires equal min/mag filters, nearest mipmaps, lod 0, clamped "
           "U/V addressing and no compare");
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  auto* s = createObject<Sampler>(pAllocator, VK_SYSTEM_ALLOCATION_SCOPE_OBJECT, dev, *pCreateInfo);
  if (!s) return VK_ERROR_OUT_OF_HOST_MEMORY;
  *pSampler = toHandle(s);
  return VK_SUCCESS;
}

VKAPI_ATTR void VKAPI_CALL vkrt_DestroySampler(VkDevice device, VkSampler sampler,
                                               const VkAllocationCallbacks* pAllocator) {
  destroyDeviceChildWhenIdle<Sampler>(device, sampler, pAllocator, "vkDestroySampler",
                                      "VUID-vkDestroySampler-sampler-parameter", "VUID-vkDestroySampler-sampler-01082");
}

}  // extern "C"
