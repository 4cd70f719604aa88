#include "runtime/pipeline_layout.hpp"

#include "runtime/alloc.hpp"
#include "runtime/descriptor_set_layout.hpp"
#include "runtime/device.hpp"
#include "runtime/physical_device.hpp"
#include "runtime/report.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {

PipelineLayout::PipelineLayout(Device* dev, const VkPipelineLayoutCreateInfo& info,
                               const std::vector<DescriptorSetLayout*>& layouts)
    : Object(kType, dev->instance, dev),
      setLayouts(layouts),
      pushConstantRanges(info.pPushConstantRanges, info.pPushConstantRanges + info.pushConstantRangeCount),
      flags(info.flags) {
  uint32_t dyn = 0;
  for (DescriptorSetLayout* l : setLayouts) {
    l->retain();
    dynamicOffsetStart.push_back(dyn);
    dyn += l->dynamicCount;
  }
  dynamicOffsetStart.push_back(dyn);
}

PipelineLayout::~PipelineLayout() {
  for (DescriptorSetLayout* l : setLayouts) DescriptorSetLayout::release(l);
}

VkShaderStageFlags PipelineLayout::pushConstantStages(uint32_t offset, uint32_t size) const {
  VkShaderStageFlags stages = 0;
  for (const VkPushConstantRange& r : pushConstantRanges)
    if (offset >= r.offset && uint64_t(offset) + size <= uint64_t(r.offset) + r.size) stages |= r.stageFlags;
  return stages;
}

}  // namespace vkrt

using namespace vkrt;

extern "C" {

VKAPI_ATTR VkResult VKAPI_CALL vkrt_CreatePipelineLayout(VkDevice device, const VkPipelineLayoutCreateInfo* pCreateInfo,
                                                         const VkAllocationCallbacks* pAllocator,
                                                         VkPipelineLayout* pPipelineLayout) {
  Device* dev = fromHandleUnchecked<Device>(device);
  const VkPhysicalDeviceLimits& lim = dev->physicalDevice->properties10.limits;
  const char* cmd = "vkCreatePipelineLayout";
  // VUID-VkPipelineLayoutCreateInfo-setLayoutCount-00286
  if (pCreateInfo->setLayoutCount > lim.maxBoundDescriptorSets) {
    report(dev, Severity::Error, "VUID-VkPipelineLayoutCreateInfo-setLayoutCount-00286",
           "%s: setLayoutCount %u exceeds maxBoundDescriptorSets %u", cmd, pCreateInfo->setLayoutCount,
           lim.maxBoundDescriptorSets);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  std::vector<DescriptorSetLayout*> layouts;
  uint32_t uniformDynamic = 0, storageDynamic = 0;
  for (uint32_t i = 0; i < pCreateInfo->setLayoutCount; ++i) {
    DescriptorSetLayout* l = liveSetLayout(pCreateInfo->pSetLayouts[i]);
    // VUID-VkPipelineLayoutCreateInfo-graphicsPipelineLibrary-06753
    if (!l) {
      report(dev, Severity::Error, "VUID-VkPipelineLayoutCreateInfo-graphicsPipelineLibrary-06753",
             "%s: pSetLayouts[%u] (0x%llx) is not a live VkDescriptorSetLayout", cmd, i,
             (unsigned long long)rawHandle(pCreateInfo->pSetLayouts[i]));
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
    // VUID-VkPipelineLayoutCreateInfo-pSetLayouts-00293
    if (l->isPush())
      for (uint32_t j = 0; j < i; ++j)
        if (layouts[j]->isPush()) {
          report(dev, Severity::Error, "VUID-VkPipelineLayoutCreateInfo-pSetLayouts-00293",
                 "%s: pSetLayouts[%u] and pSetLayouts[%u] were both created with "
                 "VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR; a pipeline layout has at most one push "
                 "descriptor set",
                 cmd, j, i);
          return VK_ERROR_VALIDATION_FAILED_EXT;
        }
    for (const DescriptorBinding& b : l->bindings) {
      if (b.type == VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC) uniformDynamic += b.count;
      if (b.type == VK_DESCRIPTOR_TYPE_STORAGE_BUFFER_DYNAMIC) storageDynamic += b.count;
    }
    layouts.push_back(l);
  }
  // VUID-VkPipelineLayoutCreateInfo-descriptorType-03016 (dynamic uniform buffers)
  if (uniformDynamic > lim.maxDescriptorSetUniformBuffersDynamic) {
    report(dev, Severity::Error, "VUID-VkPipelineLayoutCreateInfo-descriptorType-03016",
           "%s: %u dynamic uniform buffers exceed maxDescriptorSetUniformBuffersDynamic %u", cmd, uniformDynamic,
           lim.maxDescriptorSetUniformBuffersDynamic);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // VUID-VkPipelineLayoutCreateInfo-descriptorType-03017 (dynamic storage buffers)
  if (storageDynamic > lim.maxDescriptorSetStorageBuffersDynamic) {
    report(dev, Severity::Error, "VUID-VkPipelineLayoutCreateInfo-descriptorType-03017",
           "%s: %u dynamic storage buffers exceed maxDescriptorSetStorageBuffersDynamic %u", cmd, storageDynamic,
           lim.maxDescriptorSetStorageBuffersDynamic);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  const uint32_t maxPush = lim.maxPushConstantsSize;
  for (uint32_t i = 0; i < pCreateInfo->pushConstantRangeCount; ++i) {
    const VkPushConstantRange& r = pCreateInfo->pPushConstantRanges[i];
    const char* vuid = nullptr;
    // VUID-VkPushConstantRange-stageFlags-requiredbitmask
    if (r.stageFlags == 0) vuid = "VUID-VkPushConstantRange-stageFlags-requiredbitmask";
    // VUID-VkPushConstantRange-offset-00294
    else if (r.offset >= maxPush)
      vuid = "VUID-VkPushConstantRange-offset-00294";
    // VUID-VkPushConstantRange-offset-00295
    else if (r.offset % 4)
      vuid = "VUID-VkPushConstantRange-offset-00295";
    // VUID-VkPushConstantRange-size-00296
    else if (r.size == 0)
      vuid = "VUID-VkPushConstantRange-size-00296";
    // VUID-VkPushConstantRange-size-00297
    else if (r.size % 4)
      vuid = "VUID-VkPushConstantRange-size-00297";
    // VUID-VkPushConstantRange-size-00298
    else if (r.size > maxPush - r.offset)
      vuid = "VUID-VkPushConstantRange-size-00298";
    if (vuid) {
      report(dev, Severity::Error, vuid,
             "%s: pPushConstantRanges[%u] (offset %u, size %u, stageFlags 0x%x) is invalid: offset and size must be "
             "multiples of 4, size > 0, stageFlags != 0 and the range within maxPushConstantsSize %u",
             cmd, i, r.offset, r.size, r.stageFlags, maxPush);
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
    // VUID-VkPipelineLayoutCreateInfo-pPushConstantRanges-00292
    for (uint32_t j = 0; j < i; ++j) {
      if (pCreateInfo->pPushConstantRanges[j].stageFlags & r.stageFlags) {
        report(dev, Severity::Error, "VUID-VkPipelineLayoutCreateInfo-pPushConstantRanges-00292",
               "%s: pPushConstantRanges[%u] and [%u] share stages 0x%x; each stage may have one range", cmd, j, i,
               pCreateInfo->pPushConstantRanges[j].stageFlags & r.stageFlags);
        return VK_ERROR_VALIDATION_FAILED_EXT;
      }
    }
  }
  auto* pl = createObject<PipelineLayout>(pAllocator, VK_SYSTEM_ALLOCATION_SCOPE_OBJECT, dev, *pCreateInfo, layouts);
  if (!pl) return VK_ERROR_OUT_OF_HOST_MEMORY;
  *pPipelineLayout = toHandle(pl);
  return VK_SUCCESS;
}

VKAPI_ATTR void VKAPI_CALL vkrt_DestroyPipelineLayout(VkDevice device, VkPipelineLayout pipelineLayout,
                                                      const VkAllocationCallbacks* pAllocator) {
  if (!pipelineLayout) return;
  PipelineLayout* pl = fromHandle<PipelineLayout>(pipelineLayout);
  // VUID-vkDestroyPipelineLayout-pipelineLayout-parameter
  if (!pl) {
    report(fromHandle<Device>(device), Severity::Error, "VUID-vkDestroyPipelineLayout-pipelineLayout-parameter",
           "vkDestroyPipelineLayout: 0x%llx is not a live VkPipelineLayout",
           (unsigned long long)rawHandle(pipelineLayout));
    return;
  }
  destroyObject(pl, pAllocator);
}

}  // extern "C"
