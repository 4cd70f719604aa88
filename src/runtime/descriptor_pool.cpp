#include "runtime/descriptor_pool.hpp"

#include <vector>

#include "runtime/alloc.hpp"
#include "runtime/descriptor_set.hpp"
#include "runtime/device.hpp"
#include "runtime/lookup.hpp"
#include "runtime/report.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {

void descriptorDemand(const DescriptorSetLayout& layout, uint32_t variableCount,
                      std::map<VkDescriptorType, uint64_t>& out) {
  for (const DescriptorBinding& b : layout.bindings) {
    uint32_t n = (b.flags & VK_DESCRIPTOR_BINDING_VARIABLE_DESCRIPTOR_COUNT_BIT) ? variableCount : b.count;
    if (n) out[b.type] += n;
    if (n && isInlineBlock(b.type)) out[kInlineBindings] += 1;
  }
}

DescriptorPool::DescriptorPool(Device* dev, const VkDescriptorPoolCreateInfo& info)
    : Object(kType, dev->instance, dev), flags(info.flags), maxSets(info.maxSets) {
  for (uint32_t i = 0; i < info.poolSizeCount; ++i)
    capacity_[info.pPoolSizes[i].type] += info.pPoolSizes[i].descriptorCount;
  auto* ib = findInChain<VkDescriptorPoolInlineUniformBlockCreateInfo>(
      info.pNext, VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_INLINE_UNIFORM_BLOCK_CREATE_INFO);
  if (ib) capacity_[kInlineBindings] = ib->maxInlineUniformBlockBindings;
}

DescriptorPool::~DescriptorPool() {
  reset("vkDestroyDescriptorPool", "VUID-vkDestroyDescriptorPool-descriptorPool-00303");
}

bool DescriptorPool::fits(const DescriptorSetLayout& layout, uint32_t variableCount,
                          std::map<VkDescriptorType, uint64_t>& pending, uint32_t pendingSets) const {
  if (sets_.size() + pendingSets + 1 > maxSets) return false;
  std::map<VkDescriptorType, uint64_t> need;
  descriptorDemand(layout, variableCount, need);
  for (auto& [type, n] : need) {
    auto cap = capacity_.find(type);
    auto used = used_.find(type);
    uint64_t have = cap == capacity_.end() ? 0 : cap->second;
    uint64_t taken = (used == used_.end() ? 0 : used->second) + pending[type];
    if (taken + n > have) return false;
  }
  for (auto& [type, n] : need) pending[type] += n;
  return true;
}

void DescriptorPool::add(DescriptorSet* set) {
  std::map<VkDescriptorType, uint64_t> need;
  descriptorDemand(*set->layout, set->variableCount, need);
  for (auto& [type, n] : need) used_[type] += n;
  sets_.insert(set);
}

void DescriptorPool::free(DescriptorSet* set, const char* fn, const char* pendingVuid) {
  std::map<VkDescriptorType, uint64_t> need;
  descriptorDemand(*set->layout, set->variableCount, need);
  for (auto& [type, n] : need) used_[type] -= n;
  sets_.erase(set);
  destroyWhenIdle(set, nullptr, fn, pendingVuid);
}

void DescriptorPool::reset(const char* fn, const char* pendingVuid) {
  for (DescriptorSet* s : sets_) destroyWhenIdle(s, nullptr, fn, pendingVuid);
  sets_.clear();
  used_.clear();
}

}  // namespace vkrt

using namespace vkrt;

extern "C" {

VKAPI_ATTR VkResult VKAPI_CALL vkrt_CreateDescriptorPool(VkDevice device, const VkDescriptorPoolCreateInfo* pCreateInfo,
                                                         const VkAllocationCallbacks* pAllocator,
                                                         VkDescriptorPool* pDescriptorPool) {
  Device* dev = fromHandleUnchecked<Device>(device);
  // VUID-VkDescriptorPoolCreateInfo-maxSets-00301
  if (pCreateInfo->maxSets == 0) {
    report(dev, Severity::Error, "VUID-VkDescriptorPoolCreateInfo-maxSets-00301",
           "vkCreateDescriptorPool: maxSets must be greater than 0");
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  auto* inlineInfo = findInChain<VkDescriptorPoolInlineUniformBlockCreateInfo>(
      pCreateInfo->pNext, VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_INLINE_UNIFORM_BLOCK_CREATE_INFO);
  for (uint32_t i = 0; i < pCreateInfo->poolSizeCount; ++i) {
    const VkDescriptorPoolSize& s = pCreateInfo->pPoolSizes[i];
    if (isInlineBlock(s.type)) {
      // VUID-VkDescriptorPoolSize-type-02218
      if (s.descriptorCount % 4) {
        report(dev, Severity::Error, "VUID-VkDescriptorPoolSize-type-02218",
               "vkCreateDescriptorPool: pPoolSizes[%u] has %u bytes of inline uniform blocks, not a multiple of 4", i,
               s.descriptorCount);
        return VK_ERROR_VALIDATION_FAILED_EXT;
      }
      // VUID-VkDescriptorPoolCreateInfo-pPoolSizes-09424
      if (!inlineInfo || inlineInfo->maxInlineUniformBlockBindings == 0) {
        report(dev, Severity::Error, "VUID-VkDescriptorPoolCreateInfo-pPoolSizes-09424",
               "vkCreateDescriptorPool: pPoolSizes[%u] is VK_DESCRIPTOR_TYPE_INLINE_UNIFORM_BLOCK but the pNext chain "
               "has no VkDescriptorPoolInlineUniformBlockCreateInfo with maxInlineUniformBlockBindings > 0 (%s)",
               i, inlineInfo ? "it is 0" : "none");
        return VK_ERROR_VALIDATION_FAILED_EXT;
      }
    }
    // VUID-VkDescriptorPoolSize-descriptorCount-00302
    if (s.descriptorCount == 0) {
      report(dev, Severity::Error, "VUID-VkDescriptorPoolSize-descriptorCount-00302",
             "vkCreateDescriptorPool: pPoolSizes[%u].descriptorCount (%s) must be greater than 0", i,
             descriptorTypeName(s.type));
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
    // VUID-VkDescriptorPoolSize-type-parameter
    if (!descriptorTypeSupported(dev, s.type)) {
      report(dev, Severity::Error, "VUID-VkDescriptorPoolSize-type-parameter",
             "vkCreateDescriptorPool: pPoolSizes[%u].type is %s (%d), which this device does not support or whose "
             "extension is not enabled",
             i, descriptorTypeName(s.type), s.type);
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
  }
  auto* pool = createObject<DescriptorPool>(pAllocator, VK_SYSTEM_ALLOCATION_SCOPE_OBJECT, dev, *pCreateInfo);
  if (!pool) return VK_ERROR_OUT_OF_HOST_MEMORY;
  *pDescriptorPool = toHandle(pool);
  return VK_SUCCESS;
}

VKAPI_ATTR void VKAPI_CALL vkrt_DestroyDescriptorPool(VkDevice device, VkDescriptorPool descriptorPool,
                                                      const VkAllocationCallbacks* pAllocator) {
  if (!descriptorPool) return;
  DescriptorPool* pool = fromHandle<DescriptorPool>(descriptorPool);
  // VUID-vkDestroyDescriptorPool-descriptorPool-parameter
  if (!pool) {
    report(fromHandle<Device>(device), Severity::Error, "VUID-vkDestroyDescriptorPool-descriptorPool-parameter",
           "vkDestroyDescriptorPool: 0x%llx is not a live VkDescriptorPool",
           (unsigned long long)rawHandle(descriptorPool));
    return;
  }
  destroyObject(pool, pAllocator);
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_ResetDescriptorPool(VkDevice device, VkDescriptorPool descriptorPool,
                                                        VkDescriptorPoolResetFlags flags) {
  DescriptorPool* pool = fromHandle<DescriptorPool>(descriptorPool);
  // VUID-vkResetDescriptorPool-descriptorPool-parameter
  if (!pool) {
    report(fromHandle<Device>(device), Severity::Error, "VUID-vkResetDescriptorPool-descriptorPool-parameter",
           "vkResetDescriptorPool: 0x%llx is not a live VkDescriptorPool",
           (unsigned long long)rawHandle(descriptorPool));
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  pool->reset();
  return VK_SUCCESS;
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_AllocateDescriptorSets(VkDevice device,
                                                           const VkDescriptorSetAllocateInfo* pAllocateInfo,
                                                           VkDescriptorSet* pDescriptorSets) {
  Device* dev = fromHandleUnchecked<Device>(device);
  const uint32_t n = pAllocateInfo->descriptorSetCount;
  for (uint32_t i = 0; i < n; ++i) pDescriptorSets[i] = VK_NULL_HANDLE;
  DescriptorPool* pool = fromHandle<DescriptorPool>(pAllocateInfo->descriptorPool);
  // VUID-VkDescriptorSetAllocateInfo-descriptorPool-parameter
  if (!pool) {
    report(dev, Severity::Error, "VUID-VkDescriptorSetAllocateInfo-descriptorPool-parameter",
           "vkAllocateDescriptorSets: descriptorPool 0x%llx is not a live VkDescriptorPool",
           (unsigned long long)rawHandle(pAllocateInfo->descriptorPool));
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  auto* var = findInChain<VkDescriptorSetVariableDescriptorCountAllocateInfo>(
      pAllocateInfo->pNext, VK_STRUCTURE_TYPE_DESCRIPTOR_SET_VARIABLE_DESCRIPTOR_COUNT_ALLOCATE_INFO);
  // VUID-VkDescriptorSetVariableDescriptorCountAllocateInfo-descriptorSetCount-03045
  if (var && var->descriptorSetCount && var->descriptorSetCount != n) {
    report(pool, Severity::Error, "VUID-VkDescriptorSetVariableDescriptorCountAllocateInfo-descriptorSetCount-03045",
           "vkAllocateDescriptorSets: VkDescriptorSetVariableDescriptorCountAllocateInfo::descriptorSetCount is %u "
           "but %u sets are allocated",
           var->descriptorSetCount, n);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  std::vector<DescriptorSetLayout*> layouts(n);
  std::vector<uint32_t> variable(n, 0);
  for (uint32_t i = 0; i < n; ++i) {
    layouts[i] = liveSetLayout(pAllocateInfo->pSetLayouts[i]);
    // VUID-VkDescriptorSetAllocateInfo-pSetLayouts-parameter
    if (!layouts[i]) {
      report(pool, Severity::Error, "VUID-VkDescriptorSetAllocateInfo-pSetLayouts-parameter",
             "vkAllocateDescriptorSets: pSetLayouts[%u] (0x%llx) is not a live VkDescriptorSetLayout", i,
             (unsigned long long)rawHandle(pAllocateInfo->pSetLayouts[i]));
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
    // VUID-VkDescriptorSetAllocateInfo-pSetLayouts-00308
    if (layouts[i]->isPush()) {
      report(pool, Severity::Error, "VUID-VkDescriptorSetAllocateInfo-pSetLayouts-00308",
             "vkAllocateDescriptorSets: pSetLayouts[%u] (0x%llx) was created with "
             "VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR; its descriptors are pushed "
             "(vkCmdPushDescriptorSetKHR), no set is allocated with it",
             i, (unsigned long long)rawHandle(pAllocateInfo->pSetLayouts[i]));
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
    // VUID-VkDescriptorSetAllocateInfo-pSetLayouts-03044
    if ((layouts[i]->flags & VK_DESCRIPTOR_SET_LAYOUT_CREATE_UPDATE_AFTER_BIND_POOL_BIT) &&
        !(pool->flags & VK_DESCRIPTOR_POOL_CREATE_UPDATE_AFTER_BIND_BIT)) {
      report(pool, Severity::Error, "VUID-VkDescriptorSetAllocateInfo-pSetLayouts-03044",
             "vkAllocateDescriptorSets: pSetLayouts[%u] is an update-after-bind layout but the pool was not created "
             "with VK_DESCRIPTOR_POOL_CREATE_UPDATE_AFTER_BIND_BIT",
             i);
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
    if (var && var->descriptorSetCount && layouts[i]->hasVariableCount) {
      variable[i] = var->pDescriptorCounts[i];
      // VUID-VkDescriptorSetVariableDescriptorCountAllocateInfo-pSetLayouts-03046
      if (variable[i] > layouts[i]->bindings.back().count) {
        report(pool, Severity::Error, "VUID-VkDescriptorSetVariableDescriptorCountAllocateInfo-pSetLayouts-03046",
               "vkAllocateDescriptorSets: pDescriptorCounts[%u] is %u but the variable-sized binding %u holds at most "
               "%u descriptors",
               i, variable[i], layouts[i]->bindings.back().binding, layouts[i]->bindings.back().count);
        return VK_ERROR_VALIDATION_FAILED_EXT;
      }
    }
  }
  // Pool capacity (maxSets and per-type counts). Running out is not a usage error: the application gets
  // VK_ERROR_OUT_OF_POOL_MEMORY and may allocate a new pool.
  std::map<VkDescriptorType, uint64_t> pending;
  for (uint32_t i = 0; i < n; ++i)
    if (!pool->fits(*layouts[i], variable[i], pending, i)) return VK_ERROR_OUT_OF_POOL_MEMORY;
  for (uint32_t i = 0; i < n; ++i) {
    auto* set =
        createObject<DescriptorSet>(nullptr, VK_SYSTEM_ALLOCATION_SCOPE_OBJECT, dev, pool, layouts[i], variable[i]);
    if (!set) {
      for (uint32_t k = 0; k < i; ++k) {
        pool->free(fromHandleUnchecked<DescriptorSet>(pDescriptorSets[k]));
        pDescriptorSets[k] = VK_NULL_HANDLE;
      }
      return VK_ERROR_OUT_OF_HOST_MEMORY;
    }
    pool->add(set);
    pDescriptorSets[i] = toHandle(set);
  }
  return VK_SUCCESS;
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_FreeDescriptorSets(VkDevice device, VkDescriptorPool descriptorPool,
                                                       uint32_t descriptorSetCount,
                                                       const VkDescriptorSet* pDescriptorSets) {
  Device* dev = fromHandleUnchecked<Device>(device);
  DescriptorPool* pool = fromHandle<DescriptorPool>(descriptorPool);
  // VUID-vkFreeDescriptorSets-descriptorPool-parameter
  if (!pool) {
    report(dev, Severity::Error, "VUID-vkFreeDescriptorSets-descriptorPool-parameter",
           "vkFreeDescriptorSets: 0x%llx is not a live VkDescriptorPool",
           (unsigned long long)rawHandle(descriptorPool));
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // VUID-vkFreeDescriptorSets-descriptorPool-00312
  if (!(pool->flags & VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT)) {
    report(pool, Severity::Error, "VUID-vkFreeDescriptorSets-descriptorPool-00312",
           "vkFreeDescriptorSets: the pool was not created with VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT");
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  for (uint32_t i = 0; i < descriptorSetCount; ++i) {
    if (!pDescriptorSets[i]) continue;
    DescriptorSet* set = fromHandle<DescriptorSet>(pDescriptorSets[i]);
    // VUID-vkFreeDescriptorSets-pDescriptorSets-00310, VUID-vkFreeDescriptorSets-pDescriptorSets-parent
    if (!set || !pool->owns(set)) {
      report(pool, Severity::Error, "VUID-vkFreeDescriptorSets-pDescriptorSets-00310",
             "vkFreeDescriptorSets: pDescriptorSets[%u] (0x%llx) is not a live set allocated from this pool", i,
             (unsigned long long)rawHandle(pDescriptorSets[i]));
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
  }
  for (uint32_t i = 0; i < descriptorSetCount; ++i) {
    DescriptorSet* set = fromHandleUnchecked<DescriptorSet>(pDescriptorSets[i]);
    if (set && pool->owns(set)) pool->free(set);  // owns() compares pointers only: a repeated handle is skipped
  }
  return VK_SUCCESS;
}

}  // extern "C"
