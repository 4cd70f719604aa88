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
  quad = describeQuadSampler(info);
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
  if (pCreateInfo->unnormalizedCoordinates) {
    // The limits of unnormalized coordinates (01076, anisotropy, is checked above).
    const VkSamplerCreateInfo& ci = *pCreateInfo;
    auto clamped = [](VkSamplerAddressMode m) {
      return m == VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE || m == VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER;
    };
    const struct {
      bool violated;
      const char* vuid;
      const char* what;
    } rules[] = {
        // VUID-VkSamplerCreateInfo-unnormalizedCoordinates-01072: minFilter == magFilter
        {ci.minFilter != ci.magFilter, "VUID-VkSamplerCreateInfo-unnormalizedCoordinates-01072",
         "minFilter and magFilter differ"},
        // VUID-VkSamplerCreateInfo-unnormalizedCoordinates-01073: mipmapMode NEAREST
        {ci.mipmapMode != VK_SAMPLER_MIPMAP_MODE_NEAREST, "VUID-VkSamplerCreateInfo-unnormalizedCoordinates-01073",
         "mipmapMode is not VK_SAMPLER_MIPMAP_MODE_NEAREST"},
        // VUID-VkSamplerCreateInfo-unnormalizedCoordinates-01074: minLod and maxLod zero
        {ci.minLod != 0.0f || ci.maxLod != 0.0f, "VUID-VkSamplerCreateInfo-unnormalizedCoordinates-01074",
         "minLod or maxLod is not zero"},
        // VUID-VkSamplerCreateInfo-unnormalizedCoordinates-01075: U and V clamp to edge or border
        {!clamped(ci.addressModeU) || !clamped(ci.addressModeV),
         "VUID-VkSamplerCreateInfo-unnormalizedCoordinates-01075",
         "addressModeU or addressModeV is neither CLAMP_TO_EDGE nor CLAMP_TO_BORDER"},
        // VUID-VkSamplerCreateInfo-unnormalizedCoordinates-01077: no depth comparison
        {ci.compareEnable != VK_FALSE, "VUID-VkSamplerCreateInfo-unnormalizedCoordinates-01077",
         "compareEnable is VK_TRUE"},
    };
    for (const auto& r : rules) {
      if (!r.violated) continue;
      report(dev, Severity::Error, r.vuid,
             "vkCreateSampler: unnormalizedCoordinates is VK_TRUE, but %s (minFilter %d, magFilter %d, mipmapMode %d, "
             "minLod %g, maxLod %g, addressModeU %d, addressModeV %d, compareEnable %u)",
             r.what, (int)ci.minFilter, (int)ci.magFilter, (int)ci.mipmapMode, double(ci.minLod), double(ci.maxLod),
             (int)ci.addressModeU, (int)ci.addressModeV, ci.compareEnable);
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
  }
  // VUID-VkSamplerCreateInfo-compareEnable-01080: with compareEnable, compareOp is a VkCompareOp (the image functions
  // apply it to each texel of OpImage*Dref* instructions; "Depth Compare Operation")
  if (pCreateInfo->compareEnable &&
      !(pCreateInfo->compareOp >= VK_COMPARE_OP_NEVER && pCreateInfo->compareOp <= VK_COMPARE_OP_ALWAYS)) {
    report(dev, Severity::Error, "VUID-VkSamplerCreateInfo-compareEnable-01080",
           "vkCreateSampler: compareEnable is VK_TRUE, but compareOp %d is not a valid VkCompareOp",
           (int)pCreateInfo->compareOp);
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

// Sampler Y'CbCr conversion (core 1.1) needs the samplerYcbcrConversion feature, which vkrt does not support (none of
// the multi-planar formats has a format feature), so no conversion can be created: every call is reported.
VKAPI_ATTR VkResult VKAPI_CALL vkrt_CreateSamplerYcbcrConversion(VkDevice device,
                                                                 const VkSamplerYcbcrConversionCreateInfo* pCreateInfo,
                                                                 const VkAllocationCallbacks* pAllocator,
                                                                 VkSamplerYcbcrConversion* pYcbcrConversion) {
  Device* dev = fromHandleUnchecked<Device>(device);
  // VUID-vkCreateSamplerYcbcrConversion-None-01648: the samplerYcbcrConversion feature must be enabled
  report(dev, Severity::Error, "VUID-vkCreateSamplerYcbcrConversion-None-01648",
         "vkCreateSamplerYcbcrConversion: the samplerYcbcrConversion feature is not enabled (vkrt does not support "
         "it); format %d",
         (int)pCreateInfo->format);
  return VK_ERROR_VALIDATION_FAILED_EXT;
}

VKAPI_ATTR void VKAPI_CALL vkrt_DestroySamplerYcbcrConversion(VkDevice device, VkSamplerYcbcrConversion ycbcrConversion,
                                                              const VkAllocationCallbacks* pAllocator) {
  if (!ycbcrConversion) return;  // VK_NULL_HANDLE: nothing to do
  // No conversion can be created on vkrt, so any other handle is not a live one.
  report(fromHandle<Device>(device), Severity::Error, "VUID-vkDestroySamplerYcbcrConversion-ycbcrConversion-parameter",
         "vkDestroySamplerYcbcrConversion: 0x%llx is not a live VkSamplerYcbcrConversion",
         (unsigned long long)rawHandle(ycbcrConversion));
}

}  // extern "C"
