#include "runtime/descriptor_update_template.hpp"

#include <cstdio>

#include "runtime/alloc.hpp"
#include "runtime/descriptor_set.hpp"
#include "runtime/device.hpp"
#include "runtime/report.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {

DescriptorUpdateTemplate::DescriptorUpdateTemplate(Device* dev, const VkDescriptorUpdateTemplateCreateInfo& info,
                                                   DescriptorSetLayout* layout)
    : Object(kType, dev->instance, dev),
      layout(layout),
      entries(info.pDescriptorUpdateEntries, info.pDescriptorUpdateEntries + info.descriptorUpdateEntryCount) {
  layout->retain();
}

DescriptorUpdateTemplate::~DescriptorUpdateTemplate() { DescriptorSetLayout::release(layout); }

}  // namespace vkrt

using namespace vkrt;

extern "C" {

VKAPI_ATTR VkResult VKAPI_CALL vkrt_CreateDescriptorUpdateTemplate(
    VkDevice device, const VkDescriptorUpdateTemplateCreateInfo* pCreateInfo, const VkAllocationCallbacks* pAllocator,
    VkDescriptorUpdateTemplate* pDescriptorUpdateTemplate) {
  Device* dev = fromHandleUnchecked<Device>(device);
  // VUID-VkDescriptorUpdateTemplateCreateInfo-templateType-parameter (push descriptors are not exposed)
  if (pCreateInfo->templateType != VK_DESCRIPTOR_UPDATE_TEMPLATE_TYPE_DESCRIPTOR_SET) {
    report(dev, Severity::Error, "VUID-VkDescriptorUpdateTemplateCreateInfo-templateType-parameter",
           "vkCreateDescriptorUpdateTemplate: templateType %d is not supported (VK_KHR_push_descriptor is not enabled)",
           pCreateInfo->templateType);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  DescriptorSetLayout* layout = liveSetLayout(pCreateInfo->descriptorSetLayout);
  // VUID-VkDescriptorUpdateTemplateCreateInfo-templateType-00350
  if (!layout) {
    report(dev, Severity::Error, "VUID-VkDescriptorUpdateTemplateCreateInfo-templateType-00350",
           "vkCreateDescriptorUpdateTemplate: descriptorSetLayout 0x%llx is not a live VkDescriptorSetLayout",
           (unsigned long long)rawHandle(pCreateInfo->descriptorSetLayout));
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  for (uint32_t i = 0; i < pCreateInfo->descriptorUpdateEntryCount; ++i) {
    const VkDescriptorUpdateTemplateEntry& e = pCreateInfo->pDescriptorUpdateEntries[i];
    const DescriptorBinding* b = layout->bindingAt(e.dstBinding);
    // VUID-VkDescriptorUpdateTemplateEntry-dstBinding-00354
    if (!b || b->type != e.descriptorType) {
      report(dev, Severity::Error, "VUID-VkDescriptorUpdateTemplateEntry-dstBinding-00354",
             "vkCreateDescriptorUpdateTemplate: pDescriptorUpdateEntries[%u] names binding %u (%s), which the layout "
             "does not have with that type",
             i, e.dstBinding, descriptorTypeName(e.descriptorType));
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
    if (isInlineBlock(e.descriptorType)) {
      // VUID-VkDescriptorUpdateTemplateEntry-descriptor-02226, VUID-VkDescriptorUpdateTemplateEntry-descriptor-02227
      if (e.dstArrayElement % 4 || e.descriptorCount % 4) {
        report(dev, Severity::Error,
               e.dstArrayElement % 4 ? "VUID-VkDescriptorUpdateTemplateEntry-descriptor-02226"
                                     : "VUID-VkDescriptorUpdateTemplateEntry-descriptor-02227",
               "vkCreateDescriptorUpdateTemplate: pDescriptorUpdateEntries[%u] updates an inline uniform block from "
               "byte %u for %u bytes; both must be multiples of 4",
               i, e.dstArrayElement, e.descriptorCount);
        return VK_ERROR_VALIDATION_FAILED_EXT;
      }
    }
    // VUID-VkDescriptorUpdateTemplateEntry-dstArrayElement-00355 (checked against the largest set; a set with a
    // smaller variable count is checked again at update time). An inline uniform block counts bytes, in the set's
    // inline storage.
    const uint64_t end = isInlineBlock(e.descriptorType)
                             ? uint64_t(b->inlineOffset) + e.dstArrayElement + e.descriptorCount
                             : uint64_t(b->offset) + e.dstArrayElement + e.descriptorCount;
    if (end > (isInlineBlock(e.descriptorType) ? layout->inlineBytes : layout->recordCount)) {
      report(
          dev, Severity::Error, "VUID-VkDescriptorUpdateTemplateEntry-dstArrayElement-00355",
          "vkCreateDescriptorUpdateTemplate: pDescriptorUpdateEntries[%u]: %u descriptors from element %u of binding "
          "%u run past the end of the set",
          i, e.descriptorCount, e.dstArrayElement, e.dstBinding);
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
  }
  auto* t =
      createObject<DescriptorUpdateTemplate>(pAllocator, VK_SYSTEM_ALLOCATION_SCOPE_OBJECT, dev, *pCreateInfo, layout);
  if (!t) return VK_ERROR_OUT_OF_HOST_MEMORY;
  *pDescriptorUpdateTemplate = toHandle(t);
  return VK_SUCCESS;
}

VKAPI_ATTR void VKAPI_CALL vkrt_DestroyDescriptorUpdateTemplate(VkDevice device,
                                                                VkDescriptorUpdateTemplate descriptorUpdateTemplate,
                                                                const VkAllocationCallbacks* pAllocator) {
  if (!descriptorUpdateTemplate) return;
  auto* t = fromHandle<DescriptorUpdateTemplate>(descriptorUpdateTemplate);
  // VUID-vkDestroyDescriptorUpdateTemplate-descriptorUpdateTemplate-parameter
  if (!t) {
    report(fromHandle<Device>(device), Severity::Error,
           "VUID-vkDestroyDescriptorUpdateTemplate-descriptorUpdateTemplate-parameter",
           "vkDestroyDescriptorUpdateTemplate: 0x%llx is not a live VkDescriptorUpdateTemplate",
           (unsigned long long)rawHandle(descriptorUpdateTemplate));
    return;
  }
  destroyObject(t, pAllocator);
}

VKAPI_ATTR void VKAPI_CALL vkrt_UpdateDescriptorSetWithTemplate(VkDevice device, VkDescriptorSet descriptorSet,
                                                                VkDescriptorUpdateTemplate descriptorUpdateTemplate,
                                                                const void* pData) {
  Device* dev = fromHandleUnchecked<Device>(device);
  DescriptorSet* set = fromHandle<DescriptorSet>(descriptorSet);
  auto* t = fromHandle<DescriptorUpdateTemplate>(descriptorUpdateTemplate);
  // VUID-vkUpdateDescriptorSetWithTemplate-descriptorSet-parameter, -descriptorUpdateTemplate-parameter
  if (!set || !t) {
    report(dev, Severity::Error,
           !set ? "VUID-vkUpdateDescriptorSetWithTemplate-descriptorSet-parameter"
                : "VUID-vkUpdateDescriptorSetWithTemplate-descriptorUpdateTemplate-parameter",
           "vkUpdateDescriptorSetWithTemplate: %s is not live", !set ? "descriptorSet" : "descriptorUpdateTemplate");
    return;
  }
  // Bindings and types are checked against the set's own layout by writeDescriptors.
  auto* data = static_cast<const uint8_t*>(pData);
  for (bool apply : {false, true}) {
    for (size_t i = 0; i < t->entries.size(); ++i) {
      const VkDescriptorUpdateTemplateEntry& e = t->entries[i];
      char what[96];
      std::snprintf(what, sizeof what, "vkUpdateDescriptorSetWithTemplate: pDescriptorUpdateEntries[%zu]", i);
      // An inline uniform block entry's data is its bytes, from pData + offset (stride is ignored).
      const bool ok = isInlineBlock(e.descriptorType)
                          ? writeInlineBlock(set, e.dstBinding, e.dstArrayElement, e.descriptorCount, data + e.offset,
                                             apply, what, "VUID-VkDescriptorUpdateTemplateEntry-descriptor-02226",
                                             "VUID-VkDescriptorUpdateTemplateEntry-descriptor-02227")
                          : writeDescriptors(set, e.dstBinding, e.dstArrayElement, e.descriptorCount, e.descriptorType,
                                             data + e.offset, e.stride, apply, what);
      if (!ok) return;
    }
  }
}

}  // extern "C"
