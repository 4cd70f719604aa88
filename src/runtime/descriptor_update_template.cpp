#include "runtime/descriptor_update_template.hpp"

#include <cstdio>

#include "runtime/alloc.hpp"
#include "runtime/descriptor_set.hpp"
#include "runtime/device.hpp"
#include "runtime/pipeline_layout.hpp"
#include "runtime/report.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {

DescriptorUpdateTemplate::DescriptorUpdateTemplate(Device* dev, const VkDescriptorUpdateTemplateCreateInfo& info,
                                                   DescriptorSetLayout* layout)
    : Object(kType, dev->instance, dev),
      layout(layout),
      type(info.templateType),
      bindPoint(info.pipelineBindPoint),
      entries(info.pDescriptorUpdateEntries, info.pDescriptorUpdateEntries + info.descriptorUpdateEntryCount) {
  layout->retain();
}

DescriptorUpdateTemplate::~DescriptorUpdateTemplate() { DescriptorSetLayout::release(layout); }

bool DescriptorUpdateTemplate::write(DescriptorSet* set, const void* pData, const char* fn) const {
  // Bindings and types are checked against the set's own layout by writeDescriptors.
  auto* data = static_cast<const uint8_t*>(pData);
  for (bool apply : {false, true}) {
    for (size_t i = 0; i < entries.size(); ++i) {
      const VkDescriptorUpdateTemplateEntry& e = entries[i];
      char what[112];
      std::snprintf(what, sizeof what, "%s: pDescriptorUpdateEntries[%zu]", fn, i);
      // An inline uniform block entry's data is its bytes, from pData + offset (stride is ignored).
      const bool ok = isInlineBlock(e.descriptorType)
                          ? writeInlineBlock(set, e.dstBinding, e.dstArrayElement, e.descriptorCount, data + e.offset,
                                             apply, what, "VUID-VkDescriptorUpdateTemplateEntry-descriptor-02226",
                                             "VUID-VkDescriptorUpdateTemplateEntry-descriptor-02227")
                          : writeDescriptors(set, e.dstBinding, e.dstArrayElement, e.descriptorCount, e.descriptorType,
                                             data + e.offset, e.stride, apply, what);
      if (!ok) return false;
    }
  }
  return true;
}

}  // namespace vkrt

using namespace vkrt;

extern "C" {

VKAPI_ATTR VkResult VKAPI_CALL vkrt_CreateDescriptorUpdateTemplate(
    VkDevice device, const VkDescriptorUpdateTemplateCreateInfo* pCreateInfo, const VkAllocationCallbacks* pAllocator,
    VkDescriptorUpdateTemplate* pDescriptorUpdateTemplate) {
  Device* dev = fromHandleUnchecked<Device>(device);
  const bool push = pCreateInfo->templateType == VK_DESCRIPTOR_UPDATE_TEMPLATE_TYPE_PUSH_DESCRIPTORS_KHR;
  // VUID-VkDescriptorUpdateTemplateCreateInfo-templateType-parameter (push descriptors with VK_KHR_push_descriptor)
  if (pCreateInfo->templateType != VK_DESCRIPTOR_UPDATE_TEMPLATE_TYPE_DESCRIPTOR_SET &&
      !(push && dev->extensionEnabled(VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME))) {
    report(dev, Severity::Error, "VUID-VkDescriptorUpdateTemplateCreateInfo-templateType-parameter",
           "vkCreateDescriptorUpdateTemplate: templateType %d is not supported%s", pCreateInfo->templateType,
           push ? " (VK_KHR_push_descriptor is not enabled)" : "");
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  DescriptorSetLayout* layout = nullptr;
  if (push) {
    const VkPipelineBindPoint bp = pCreateInfo->pipelineBindPoint;
    // VUID-VkDescriptorUpdateTemplateCreateInfo-templateType-00351
    if (bp != VK_PIPELINE_BIND_POINT_COMPUTE && bp != VK_PIPELINE_BIND_POINT_GRAPHICS &&
        bp != VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR) {
      report(dev, Severity::Error, "VUID-VkDescriptorUpdateTemplateCreateInfo-templateType-00351",
             "vkCreateDescriptorUpdateTemplate: a push descriptor template has pipelineBindPoint %d, not a bind point "
             "vkrt supports (graphics, compute, ray tracing)",
             (int)bp);
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
    PipelineLayout* pl = fromHandle<PipelineLayout>(pCreateInfo->pipelineLayout);
    // VUID-VkDescriptorUpdateTemplateCreateInfo-templateType-00352
    if (!pl) {
      report(dev, Severity::Error, "VUID-VkDescriptorUpdateTemplateCreateInfo-templateType-00352",
             "vkCreateDescriptorUpdateTemplate: a push descriptor template's pipelineLayout 0x%llx is not a live "
             "VkPipelineLayout",
             (unsigned long long)rawHandle(pCreateInfo->pipelineLayout));
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
    // VUID-VkDescriptorUpdateTemplateCreateInfo-templateType-00353
    if (pCreateInfo->set >= pl->setLayouts.size() || !pl->setLayouts[pCreateInfo->set]->isPush()) {
      report(pl, Severity::Error, "VUID-VkDescriptorUpdateTemplateCreateInfo-templateType-00353",
             "vkCreateDescriptorUpdateTemplate: set %u is not the push descriptor set of pipelineLayout (%zu set "
             "layouts%s)",
             pCreateInfo->set, pl->setLayouts.size(),
             pCreateInfo->set < pl->setLayouts.size() ? "; that one was created without "
                                                        "VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR"
                                                      : "");
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
    layout = pl->setLayouts[pCreateInfo->set];
  } else {
    layout = liveSetLayout(pCreateInfo->descriptorSetLayout);
    // VUID-VkDescriptorUpdateTemplateCreateInfo-templateType-00350
    if (!layout) {
      report(dev, Severity::Error, "VUID-VkDescriptorUpdateTemplateCreateInfo-templateType-00350",
             "vkCreateDescriptorUpdateTemplate: descriptorSetLayout 0x%llx is not a live VkDescriptorSetLayout",
             (unsigned long long)rawHandle(pCreateInfo->descriptorSetLayout));
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
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
  t->write(set, pData, "vkUpdateDescriptorSetWithTemplate");
}

}  // extern "C"
