#include "runtime/descriptor_set_layout.hpp"

#include <algorithm>
#include <cstring>

#include "runtime/alloc.hpp"
#include "runtime/device.hpp"
#include "runtime/physical_device.hpp"
#include "runtime/report.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {

const char* descriptorTypeName(VkDescriptorType type) {
  switch (type) {
    case VK_DESCRIPTOR_TYPE_SAMPLER: return "VK_DESCRIPTOR_TYPE_SAMPLER";
    case VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER: return "VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER";
    case VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE: return "VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE";
    case VK_DESCRIPTOR_TYPE_STORAGE_IMAGE: return "VK_DESCRIPTOR_TYPE_STORAGE_IMAGE";
    case VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER: return "VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER";
    case VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER: return "VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER";
    case VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER: return "VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER";
    case VK_DESCRIPTOR_TYPE_STORAGE_BUFFER: return "VK_DESCRIPTOR_TYPE_STORAGE_BUFFER";
    case VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC: return "VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC";
    case VK_DESCRIPTOR_TYPE_STORAGE_BUFFER_DYNAMIC: return "VK_DESCRIPTOR_TYPE_STORAGE_BUFFER_DYNAMIC";
    case VK_DESCRIPTOR_TYPE_INPUT_ATTACHMENT: return "VK_DESCRIPTOR_TYPE_INPUT_ATTACHMENT";
    case VK_DESCRIPTOR_TYPE_INLINE_UNIFORM_BLOCK: return "VK_DESCRIPTOR_TYPE_INLINE_UNIFORM_BLOCK";
    case VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR: return "VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR";
    case VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_NV: return "VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_NV";
    default: return "an unknown descriptor type";
  }
}

bool isDynamicBufferType(VkDescriptorType type) {
  return type == VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC || type == VK_DESCRIPTOR_TYPE_STORAGE_BUFFER_DYNAMIC;
}

bool descriptorTypeSupported(const Device* dev, VkDescriptorType type) {
  switch (type) {
    case VK_DESCRIPTOR_TYPE_SAMPLER:
    case VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER:
    case VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE:
    case VK_DESCRIPTOR_TYPE_STORAGE_IMAGE:
    case VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER:
    case VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER:
    case VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER:
    case VK_DESCRIPTOR_TYPE_STORAGE_BUFFER:
    case VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC:
    case VK_DESCRIPTOR_TYPE_STORAGE_BUFFER_DYNAMIC:
    case VK_DESCRIPTOR_TYPE_INPUT_ATTACHMENT: return true;      // image view records (spirv Codegen::subpassRead)
    case VK_DESCRIPTOR_TYPE_INLINE_UNIFORM_BLOCK: return true;  // core 1.3 (layouts check the feature: 04604)
    case VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR:
      return dev->extensionEnabled(VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME);
    case VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_NV:  // the same descriptor: a structure's address (abi.hpp)
      return dev->extensionEnabled(VK_NV_RAY_TRACING_EXTENSION_NAME);
    default: return false;
  }
}

DescriptorSetLayout::DescriptorSetLayout(Device* dev, const VkDescriptorSetLayoutCreateInfo& info,
                                         const VkAllocationCallbacks* alloc)
    : Object(kType, dev->instance, dev), flags(info.flags) {
  if (alloc) {
    alloc_ = *alloc;
    hasAlloc_ = true;
  }
  auto* bf = findInChain<VkDescriptorSetLayoutBindingFlagsCreateInfo>(
      info.pNext, VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_BINDING_FLAGS_CREATE_INFO);
  for (uint32_t i = 0; i < info.bindingCount; ++i) {
    const VkDescriptorSetLayoutBinding& b = info.pBindings[i];
    DescriptorBinding d;
    d.binding = b.binding;
    d.type = b.descriptorType;
    d.count = b.descriptorCount;
    d.stages = b.stageFlags;
    d.flags = (bf && bf->bindingCount) ? bf->pBindingFlags[i] : 0;
    if (b.pImmutableSamplers && b.descriptorCount &&
        (b.descriptorType == VK_DESCRIPTOR_TYPE_SAMPLER ||
         b.descriptorType == VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER)) {
      for (uint32_t k = 0; k < b.descriptorCount; ++k)
        d.immutableSamplers.push_back(findObject(rawHandle(b.pImmutableSamplers[k]), VK_OBJECT_TYPE_SAMPLER));
    }
    bindings.push_back(std::move(d));
  }
  std::sort(bindings.begin(), bindings.end(),
            [](const DescriptorBinding& a, const DescriptorBinding& b) { return a.binding < b.binding; });
  for (DescriptorBinding& d : bindings) {
    d.offset = recordCount;
    if (isInlineBlock(d.type)) {  // one record pointing at `count` bytes of the set's inline storage
      d.inlineOffset = inlineBytes;
      inlineBytes += d.count;
      recordCount += d.count ? 1 : 0;
    } else {
      recordCount += d.count;
    }
    if (isDynamicBufferType(d.type)) {
      d.dynamicIndex = dynamicCount;
      dynamicCount += d.count;
    }
    if (d.flags & VK_DESCRIPTOR_BINDING_VARIABLE_DESCRIPTOR_COUNT_BIT) hasVariableCount = true;
  }
}

bool DescriptorSetLayout::sameDefinition(const DescriptorSetLayout& other) const {
  if (this == &other) return true;
  if (flags != other.flags || bindings.size() != other.bindings.size()) return false;
  for (size_t i = 0; i < bindings.size(); ++i) {
    const DescriptorBinding& x = bindings[i];
    const DescriptorBinding& y = other.bindings[i];
    if (x.binding != y.binding || x.type != y.type || x.count != y.count || x.stages != y.stages ||
        x.flags != y.flags || x.immutableSamplers != y.immutableSamplers)
      return false;
  }
  return true;
}

const DescriptorBinding* DescriptorSetLayout::bindingAt(uint32_t binding) const {
  auto it = std::lower_bound(bindings.begin(), bindings.end(), binding,
                             [](const DescriptorBinding& d, uint32_t b) { return d.binding < b; });
  return it != bindings.end() && it->binding == binding ? &*it : nullptr;
}

uint32_t DescriptorSetLayout::recordCountFor(uint32_t variableCount) const {
  if (!hasVariableCount || isInlineBlock(bindings.back().type)) return recordCount;  // an inline block keeps its record
  return recordCount - bindings.back().count + std::min(variableCount, bindings.back().count);
}

uint32_t DescriptorSetLayout::inlineBytesFor(uint32_t variableCount) const {
  if (!hasVariableCount || !isInlineBlock(bindings.back().type)) return inlineBytes;
  return inlineBytes - bindings.back().count + std::min(variableCount, bindings.back().count);
}

void DescriptorSetLayout::release(DescriptorSetLayout* layout) {
  if (!layout) return;
  if (layout->refs_.fetch_sub(1, std::memory_order_acq_rel) == 1) {
    VkAllocationCallbacks a = layout->alloc_;
    destroyObject(layout, layout->hasAlloc_ ? &a : nullptr);
  }
}

DescriptorSetLayout* liveSetLayout(VkDescriptorSetLayout h) {
  DescriptorSetLayout* l = fromHandle<DescriptorSetLayout>(h);
  return l && !l->destroyedByApp.load() ? l : nullptr;
}

}  // namespace vkrt

using namespace vkrt;

namespace {

// Checks a VkDescriptorSetLayoutCreateInfo. Reports the first problem (unless `quiet`) and returns false.
bool validateLayout(Device* dev, const VkDescriptorSetLayoutCreateInfo& info, bool quiet, const char* cmd) {
#define FAIL(vuid, ...)                                          \
  do {                                                           \
    if (!quiet) report(dev, Severity::Error, vuid, __VA_ARGS__); \
    return false;                                                \
  } while (0)
  auto on = [dev](Feature f) { return dev->enabled(f); };
  auto* bf = findInChain<VkDescriptorSetLayoutBindingFlagsCreateInfo>(
      info.pNext, VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_BINDING_FLAGS_CREATE_INFO);
  // VUID-VkDescriptorSetLayoutBindingFlagsCreateInfo-bindingCount-03002
  if (bf && bf->bindingCount && bf->bindingCount != info.bindingCount)
    FAIL("VUID-VkDescriptorSetLayoutBindingFlagsCreateInfo-bindingCount-03002",
         "%s: VkDescriptorSetLayoutBindingFlagsCreateInfo::bindingCount is %u but the layout has %u bindings", cmd,
         bf->bindingCount, info.bindingCount);
  // Push descriptors with VK_KHR_push_descriptor; descriptor buffers are not exposed.
  const VkDescriptorSetLayoutCreateFlags kKnownFlags = VK_DESCRIPTOR_SET_LAYOUT_CREATE_UPDATE_AFTER_BIND_POOL_BIT |
                                                       (dev->extensionEnabled(VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME)
                                                            ? VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR
                                                            : 0);
  // VUID-VkDescriptorSetLayoutCreateInfo-flags-parameter
  if (info.flags & ~kKnownFlags)
    FAIL("VUID-VkDescriptorSetLayoutCreateInfo-flags-parameter",
         "%s: flags 0x%x include bits of extensions this device does not enable (supported: 0x%x)", cmd, info.flags,
         kKnownFlags);
  if (info.flags & VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR) {
    uint64_t total = 0;
    for (uint32_t i = 0; i < info.bindingCount; ++i) {
      const VkDescriptorSetLayoutBinding& b = info.pBindings[i];
      total += b.descriptorCount;
      // VUID-VkDescriptorSetLayoutCreateInfo-flags-00280
      if (isDynamicBufferType(b.descriptorType))
        FAIL("VUID-VkDescriptorSetLayoutCreateInfo-flags-00280",
             "%s: a push descriptor layout (VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR) may hold no "
             "dynamic buffer, but pBindings[%u] (binding %u) is %s",
             cmd, i, b.binding, descriptorTypeName(b.descriptorType));
      // VUID-VkDescriptorSetLayoutCreateInfo-flags-02208
      if (isInlineBlock(b.descriptorType))
        FAIL("VUID-VkDescriptorSetLayoutCreateInfo-flags-02208",
             "%s: a push descriptor layout may hold no inline uniform block, but pBindings[%u] (binding %u) is one",
             cmd, i, b.binding);
      // VUID-VkDescriptorSetLayoutBindingFlagsCreateInfo-flags-03003
      constexpr VkDescriptorBindingFlags kNotPushed = VK_DESCRIPTOR_BINDING_UPDATE_AFTER_BIND_BIT |
                                                      VK_DESCRIPTOR_BINDING_UPDATE_UNUSED_WHILE_PENDING_BIT |
                                                      VK_DESCRIPTOR_BINDING_VARIABLE_DESCRIPTOR_COUNT_BIT;
      const VkDescriptorBindingFlags fl = (bf && bf->bindingCount == info.bindingCount) ? bf->pBindingFlags[i] : 0;
      if (fl & kNotPushed)
        FAIL("VUID-VkDescriptorSetLayoutBindingFlagsCreateInfo-flags-03003",
             "%s: a push descriptor layout's bindings may not be UPDATE_AFTER_BIND, UPDATE_UNUSED_WHILE_PENDING or "
             "VARIABLE_DESCRIPTOR_COUNT, but pBindingFlags[%u] (binding %u) is 0x%x",
             cmd, i, b.binding, fl);
    }
    // VUID-VkDescriptorSetLayoutCreateInfo-flags-00281
    if (total > kMaxPushDescriptors)
      FAIL("VUID-VkDescriptorSetLayoutCreateInfo-flags-00281",
           "%s: a push descriptor layout holds %llu descriptors, more than maxPushDescriptors %u", cmd,
           (unsigned long long)total, kMaxPushDescriptors);
  }
  bool anyUpdateAfterBind = false, anyDynamic = false;
  for (uint32_t i = 0; i < info.bindingCount; ++i) {
    const VkDescriptorSetLayoutBinding& b = info.pBindings[i];
    // VUID-VkDescriptorSetLayoutCreateInfo-binding-00279
    for (uint32_t j = 0; j < i; ++j)
      if (info.pBindings[j].binding == b.binding)
        FAIL("VUID-VkDescriptorSetLayoutCreateInfo-binding-00279",
             "%s: pBindings[%u] and pBindings[%u] both use binding number %u", cmd, j, i, b.binding);
    // VUID-VkDescriptorSetLayoutBinding-descriptorType-parameter
    if (!descriptorTypeSupported(dev, b.descriptorType))
      FAIL("VUID-VkDescriptorSetLayoutBinding-descriptorType-parameter",
           "%s: pBindings[%u] (binding %u) has descriptor type %s (%d), which this device does not support or whose "
           "extension is not enabled",
           cmd, i, b.binding, descriptorTypeName(b.descriptorType), b.descriptorType);
    // VUID-VkDescriptorSetLayoutBinding-descriptorType-00282
    if ((b.descriptorType == VK_DESCRIPTOR_TYPE_SAMPLER ||
         b.descriptorType == VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER) &&
        b.descriptorCount && b.pImmutableSamplers)
      for (uint32_t k = 0; k < b.descriptorCount; ++k)
        if (!findObject(rawHandle(b.pImmutableSamplers[k]), VK_OBJECT_TYPE_SAMPLER))
          FAIL("VUID-VkDescriptorSetLayoutBinding-descriptorType-00282",
               "%s: pBindings[%u].pImmutableSamplers[%u] (0x%llx) is not a live VkSampler", cmd, i, k,
               (unsigned long long)rawHandle(b.pImmutableSamplers[k]));
    // VUID-VkDescriptorSetLayoutBinding-descriptorType-01510: input attachments only in fragment shaders
    if (b.descriptorType == VK_DESCRIPTOR_TYPE_INPUT_ATTACHMENT && b.descriptorCount && b.stageFlags != 0 &&
        b.stageFlags != VK_SHADER_STAGE_FRAGMENT_BIT)
      FAIL("VUID-VkDescriptorSetLayoutBinding-descriptorType-01510",
           "%s: pBindings[%u] (binding %u) is an input attachment with stageFlags 0x%x (0 or FRAGMENT only)", cmd, i,
           b.binding, b.stageFlags);
    if (isInlineBlock(b.descriptorType)) {
      // VUID-VkDescriptorSetLayoutBinding-descriptorType-04604
      if (!on(Feature::inlineUniformBlock))
        FAIL("VUID-VkDescriptorSetLayoutBinding-descriptorType-04604",
             "%s: pBindings[%u] (binding %u) is VK_DESCRIPTOR_TYPE_INLINE_UNIFORM_BLOCK but the inlineUniformBlock "
             "feature is not enabled",
             cmd, i, b.binding);
      // VUID-VkDescriptorSetLayoutBinding-descriptorType-02209
      if (b.descriptorCount % 4)
        FAIL("VUID-VkDescriptorSetLayoutBinding-descriptorType-02209",
             "%s: pBindings[%u] (binding %u) is an inline uniform block of %u bytes, not a multiple of 4", cmd, i,
             b.binding, b.descriptorCount);
      // VUID-VkDescriptorSetLayoutBinding-descriptorType-08004
      const uint32_t maxSize = dev->physicalDevice->properties13.maxInlineUniformBlockSize;
      if (b.descriptorCount > maxSize)
        FAIL("VUID-VkDescriptorSetLayoutBinding-descriptorType-08004",
             "%s: pBindings[%u] (binding %u) is an inline uniform block of %u bytes, more than "
             "maxInlineUniformBlockSize %u",
             cmd, i, b.binding, b.descriptorCount, maxSize);
    }
    anyDynamic = anyDynamic || isDynamicBufferType(b.descriptorType);
    VkDescriptorBindingFlags fl = (bf && bf->bindingCount) ? bf->pBindingFlags[i] : 0;
    if (!fl) continue;
    if (fl & VK_DESCRIPTOR_BINDING_UPDATE_AFTER_BIND_BIT) {
      anyUpdateAfterBind = true;
      struct Req {
        VkDescriptorType type;
        VkBool32 enabled;
        const char* vuid;
      };
      const Req reqs[] = {
          {VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, on(Feature::descriptorBindingUniformBufferUpdateAfterBind),
           "VUID-VkDescriptorSetLayoutBindingFlagsCreateInfo-descriptorBindingUniformBufferUpdateAfterBind-03005"},
          {VK_DESCRIPTOR_TYPE_SAMPLER, on(Feature::descriptorBindingSampledImageUpdateAfterBind),
           "VUID-VkDescriptorSetLayoutBindingFlagsCreateInfo-descriptorBindingSampledImageUpdateAfterBind-03006"},
          {VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, on(Feature::descriptorBindingSampledImageUpdateAfterBind),
           "VUID-VkDescriptorSetLayoutBindingFlagsCreateInfo-descriptorBindingSampledImageUpdateAfterBind-03006"},
          {VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, on(Feature::descriptorBindingSampledImageUpdateAfterBind),
           "VUID-VkDescriptorSetLayoutBindingFlagsCreateInfo-descriptorBindingSampledImageUpdateAfterBind-03006"},
          {VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, on(Feature::descriptorBindingStorageImageUpdateAfterBind),
           "VUID-VkDescriptorSetLayoutBindingFlagsCreateInfo-descriptorBindingStorageImageUpdateAfterBind-03007"},
          {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, on(Feature::descriptorBindingStorageBufferUpdateAfterBind),
           "VUID-VkDescriptorSetLayoutBindingFlagsCreateInfo-descriptorBindingStorageBufferUpdateAfterBind-03008"},
          {VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, on(Feature::descriptorBindingUniformTexelBufferUpdateAfterBind),
           "VUID-VkDescriptorSetLayoutBindingFlagsCreateInfo-descriptorBindingUniformTexelBufferUpdateAfterBind-03009"},
          {VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER, on(Feature::descriptorBindingStorageTexelBufferUpdateAfterBind),
           "VUID-VkDescriptorSetLayoutBindingFlagsCreateInfo-descriptorBindingStorageTexelBufferUpdateAfterBind-03010"},
          {VK_DESCRIPTOR_TYPE_INLINE_UNIFORM_BLOCK, on(Feature::descriptorBindingInlineUniformBlockUpdateAfterBind),
           "VUID-VkDescriptorSetLayoutBindingFlagsCreateInfo-descriptorBindingInlineUniformBlockUpdateAfterBind-02211"},
          {VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, VK_FALSE,
           "VUID-VkDescriptorSetLayoutBindingFlagsCreateInfo-descriptorBindingAccelerationStructureUpdateAfterBind-"
           "03570"},
      };
      for (const Req& r : reqs)
        if (r.type == b.descriptorType && !r.enabled)
          FAIL(r.vuid,
               "%s: pBindings[%u] (%s) has VK_DESCRIPTOR_BINDING_UPDATE_AFTER_BIND_BIT but the feature is "
               "not enabled",
               cmd, i, descriptorTypeName(b.descriptorType));
      // VUID-VkDescriptorSetLayoutBindingFlagsCreateInfo-None-03011
      if (isDynamicBufferType(b.descriptorType) || b.descriptorType == VK_DESCRIPTOR_TYPE_INPUT_ATTACHMENT)
        FAIL("VUID-VkDescriptorSetLayoutBindingFlagsCreateInfo-None-03011",
             "%s: pBindings[%u] is %s and must not use VK_DESCRIPTOR_BINDING_UPDATE_AFTER_BIND_BIT", cmd, i,
             descriptorTypeName(b.descriptorType));
    }
    // VUID-VkDescriptorSetLayoutBindingFlagsCreateInfo-descriptorBindingUpdateUnusedWhilePending-03012
    if ((fl & VK_DESCRIPTOR_BINDING_UPDATE_UNUSED_WHILE_PENDING_BIT) &&
        !on(Feature::descriptorBindingUpdateUnusedWhilePending))
      FAIL("VUID-VkDescriptorSetLayoutBindingFlagsCreateInfo-descriptorBindingUpdateUnusedWhilePending-03012",
           "%s: pBindingFlags[%u] has UPDATE_UNUSED_WHILE_PENDING but descriptorBindingUpdateUnusedWhilePending is "
           "not enabled",
           cmd, i);
    // VUID-VkDescriptorSetLayoutBindingFlagsCreateInfo-descriptorBindingPartiallyBound-03013
    if ((fl & VK_DESCRIPTOR_BINDING_PARTIALLY_BOUND_BIT) && !on(Feature::descriptorBindingPartiallyBound))
      FAIL("VUID-VkDescriptorSetLayoutBindingFlagsCreateInfo-descriptorBindingPartiallyBound-03013",
           "%s: pBindingFlags[%u] has PARTIALLY_BOUND but descriptorBindingPartiallyBound is not enabled", cmd, i);
    if (fl & VK_DESCRIPTOR_BINDING_VARIABLE_DESCRIPTOR_COUNT_BIT) {
      // VUID-VkDescriptorSetLayoutBindingFlagsCreateInfo-descriptorBindingVariableDescriptorCount-03014
      if (!on(Feature::descriptorBindingVariableDescriptorCount))
        FAIL("VUID-VkDescriptorSetLayoutBindingFlagsCreateInfo-descriptorBindingVariableDescriptorCount-03014",
             "%s: pBindingFlags[%u] has VARIABLE_DESCRIPTOR_COUNT but descriptorBindingVariableDescriptorCount is "
             "not enabled",
             cmd, i);
      // VUID-VkDescriptorSetLayoutBindingFlagsCreateInfo-pBindingFlags-03015
      if (isDynamicBufferType(b.descriptorType) || b.descriptorType == VK_DESCRIPTOR_TYPE_INPUT_ATTACHMENT)
        FAIL("VUID-VkDescriptorSetLayoutBindingFlagsCreateInfo-pBindingFlags-03015",
             "%s: pBindings[%u] is %s and cannot have a variable descriptor count", cmd, i,
             descriptorTypeName(b.descriptorType));
      // VUID-VkDescriptorSetLayoutBindingFlagsCreateInfo-pBindingFlags-03004
      for (uint32_t j = 0; j < info.bindingCount; ++j)
        if (info.pBindings[j].binding > b.binding)
          FAIL("VUID-VkDescriptorSetLayoutBindingFlagsCreateInfo-pBindingFlags-03004",
               "%s: binding %u has VARIABLE_DESCRIPTOR_COUNT but is not the highest binding (pBindings[%u] is "
               "binding %u)",
               cmd, b.binding, j, info.pBindings[j].binding);
    }
  }
  // VUID-VkDescriptorSetLayoutCreateInfo-flags-03000
  if (anyUpdateAfterBind && !(info.flags & VK_DESCRIPTOR_SET_LAYOUT_CREATE_UPDATE_AFTER_BIND_POOL_BIT))
    FAIL("VUID-VkDescriptorSetLayoutCreateInfo-flags-03000",
         "%s: a binding has VK_DESCRIPTOR_BINDING_UPDATE_AFTER_BIND_BIT but flags lack "
         "VK_DESCRIPTOR_SET_LAYOUT_CREATE_UPDATE_AFTER_BIND_POOL_BIT",
         cmd);
  // VUID-VkDescriptorSetLayoutCreateInfo-descriptorType-03001
  if (anyUpdateAfterBind && anyDynamic)
    FAIL("VUID-VkDescriptorSetLayoutCreateInfo-descriptorType-03001",
         "%s: a binding has UPDATE_AFTER_BIND, so no binding may be a dynamic buffer", cmd);
  return true;
#undef FAIL
}

}  // namespace

extern "C" {

VKAPI_ATTR VkResult VKAPI_CALL vkrt_CreateDescriptorSetLayout(VkDevice device,
                                                              const VkDescriptorSetLayoutCreateInfo* pCreateInfo,
                                                              const VkAllocationCallbacks* pAllocator,
                                                              VkDescriptorSetLayout* pSetLayout) {
  Device* dev = fromHandleUnchecked<Device>(device);
  if (!validateLayout(dev, *pCreateInfo, false, "vkCreateDescriptorSetLayout")) return VK_ERROR_VALIDATION_FAILED_EXT;
  auto* l =
      createObject<DescriptorSetLayout>(pAllocator, VK_SYSTEM_ALLOCATION_SCOPE_OBJECT, dev, *pCreateInfo, pAllocator);
  if (!l) return VK_ERROR_OUT_OF_HOST_MEMORY;
  *pSetLayout = toHandle(l);
  return VK_SUCCESS;
}

VKAPI_ATTR void VKAPI_CALL vkrt_DestroyDescriptorSetLayout(VkDevice device, VkDescriptorSetLayout descriptorSetLayout,
                                                           const VkAllocationCallbacks* pAllocator) {
  if (!descriptorSetLayout) return;
  DescriptorSetLayout* l = fromHandle<DescriptorSetLayout>(descriptorSetLayout);
  // VUID-vkDestroyDescriptorSetLayout-descriptorSetLayout-parameter
  if (!l || l->destroyedByApp.exchange(true)) {
    report(fromHandle<Device>(device), Severity::Error,
           "VUID-vkDestroyDescriptorSetLayout-descriptorSetLayout-parameter",
           "vkDestroyDescriptorSetLayout: 0x%llx is not a live VkDescriptorSetLayout",
           (unsigned long long)rawHandle(descriptorSetLayout));
    return;
  }
  DescriptorSetLayout::release(l);
}

VKAPI_ATTR void VKAPI_CALL vkrt_GetDescriptorSetLayoutSupport(VkDevice device,
                                                              const VkDescriptorSetLayoutCreateInfo* pCreateInfo,
                                                              VkDescriptorSetLayoutSupport* pSupport) {
  Device* dev = fromHandleUnchecked<Device>(device);
  const uint32_t maxPerSet = dev->physicalDevice->properties11.maxPerSetDescriptors;
  uint64_t total = 0;
  uint32_t variableBinding = UINT32_MAX;
  auto* bf = findInChain<VkDescriptorSetLayoutBindingFlagsCreateInfo>(
      pCreateInfo->pNext, VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_BINDING_FLAGS_CREATE_INFO);
  for (uint32_t i = 0; i < pCreateInfo->bindingCount; ++i) {
    const VkDescriptorSetLayoutBinding& b = pCreateInfo->pBindings[i];
    // An inline uniform block is one descriptor of descriptorCount bytes (its size is checked by validateLayout).
    total += isInlineBlock(b.descriptorType) ? (b.descriptorCount ? 1 : 0) : b.descriptorCount;
    if (bf && bf->bindingCount == pCreateInfo->bindingCount &&
        (bf->pBindingFlags[i] & VK_DESCRIPTOR_BINDING_VARIABLE_DESCRIPTOR_COUNT_BIT))
      variableBinding = i;
  }
  bool ok = validateLayout(dev, *pCreateInfo, true, "vkGetDescriptorSetLayoutSupport") && total <= maxPerSet;
  pSupport->supported = ok ? VK_TRUE : VK_FALSE;
  for (auto* s = static_cast<VkBaseOutStructure*>(pSupport->pNext); s; s = s->pNext) {
    if (s->sType == VK_STRUCTURE_TYPE_DESCRIPTOR_SET_VARIABLE_DESCRIPTOR_COUNT_LAYOUT_SUPPORT) {
      auto* v = reinterpret_cast<VkDescriptorSetVariableDescriptorCountLayoutSupport*>(s);
      // The variable binding may grow to whatever the per-set limit leaves once the other bindings are counted;
      // an inline uniform block's bound is a size: maxInlineUniformBlockSize ("Descriptor Set Layout" support).
      if (!ok || variableBinding == UINT32_MAX) {
        v->maxVariableDescriptorCount = 0;
      } else if (isInlineBlock(pCreateInfo->pBindings[variableBinding].descriptorType)) {
        v->maxVariableDescriptorCount = dev->physicalDevice->properties13.maxInlineUniformBlockSize;
      } else {
        v->maxVariableDescriptorCount =
            maxPerSet - static_cast<uint32_t>(total - pCreateInfo->pBindings[variableBinding].descriptorCount);
      }
    }
  }
}

}  // extern "C"
