// VkDescriptorPool: enforces maxSets and the per-type descriptor counts of pPoolSizes (bytes for inline uniform
// blocks, whose bindings are also counted against VkDescriptorPoolInlineUniformBlockCreateInfo::
// maxInlineUniformBlockBindings); owns its sets.
#pragma once

#include <cstdint>
#include <map>
#include <unordered_set>

#include "runtime/object.hpp"

namespace vkrt {

class DescriptorSet;
class DescriptorSetLayout;

class DescriptorPool : public Object {
 public:
  using Handle = VkDescriptorPool;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_DESCRIPTOR_POOL;

  DescriptorPool(Device* dev, const VkDescriptorPoolCreateInfo& info);
  ~DescriptorPool();  // frees every set still allocated

  const VkDescriptorPoolCreateFlags flags;
  const uint32_t maxSets;

  // Whether a set of `layout` with `variableCount` fits in what is left (counting `pending` sets already
  // reserved by the same vkAllocateDescriptorSets call).
  bool fits(const DescriptorSetLayout& layout, uint32_t variableCount, std::map<VkDescriptorType, uint64_t>& pending,
            uint32_t pendingSets) const;
  void add(DescriptorSet* set);
  // Returns the set's descriptors to the pool and destroys it (once pending work that may use it completes:
  // destroyWhenIdle, reporting a pending command buffer that refers to it under `pendingVuid`, naming `fn`).
  void free(DescriptorSet* set, const char* fn = "vkFreeDescriptorSets",
            const char* pendingVuid = "VUID-vkFreeDescriptorSets-pDescriptorSets-00309");
  // Frees every set.
  void reset(const char* fn = "vkResetDescriptorPool",
             const char* pendingVuid = "VUID-vkResetDescriptorPool-descriptorPool-00313");

  uint32_t liveSets() const { return static_cast<uint32_t>(sets_.size()); }
  bool owns(DescriptorSet* set) const { return sets_.count(set) != 0; }

 private:
  std::map<VkDescriptorType, uint64_t> capacity_;  // from pPoolSizes
  std::map<VkDescriptorType, uint64_t> used_;
  std::unordered_set<DescriptorSet*> sets_;
};

// What a pool's capacity is counted in: descriptors of each type (bytes for VK_DESCRIPTOR_TYPE_INLINE_UNIFORM_BLOCK)
// and, under kInlineBindings, inline uniform block bindings.
inline constexpr VkDescriptorType kInlineBindings = VK_DESCRIPTOR_TYPE_MAX_ENUM;

// Descriptors of each type a set of `layout` takes from a pool (and its inline uniform block bindings).
void descriptorDemand(const DescriptorSetLayout& layout, uint32_t variableCount,
                      std::map<VkDescriptorType, uint64_t>& out);

}  // namespace vkrt
