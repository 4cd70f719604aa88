// VkDescriptorSetLayout, and where each binding's descriptors live in a set's storage.
//
// A descriptor set is one flat array of abi::DescriptorRecord (src/abi/abi.hpp documents the record and what
// each descriptor type puts in it). Binding b's element i lives at record index `layout->bindingAt(b)->offset + i`
// (offsets are precomputed at layout creation). A binding with VK_DESCRIPTOR_BINDING_VARIABLE_DESCRIPTOR_COUNT_BIT
// is always the highest binding, so it is last, and a set allocated with a smaller variable count simply has
// fewer records. A record's `object` and `sampler` point at the Object base of the vkrt object (what a handle
// points at); recordObject<T>() converts back.
//
// An inline uniform block binding (VK_DESCRIPTOR_TYPE_INLINE_UNIFORM_BLOCK) counts bytes, not descriptors: its
// `count` is the block's size (a variable count is a size too). Its bytes live in the set's inline storage at
// `inlineOffset`, and it takes one record (when its size is not 0), which points at them like a uniform buffer
// descriptor: address = the bytes, range = the size. Shaders read it as a uniform buffer.
#pragma once

#include <atomic>
#include <cstdint>
#include <vector>

#include "abi/abi.hpp"
#include "runtime/object.hpp"

namespace vkrt {

using abi::DescriptorRecord;

// The object a descriptor record points at (`object` or `sampler`), as its vkrt type.
template <class T>
const T* recordObject(const void* p) {
  return static_cast<const T*>(static_cast<const Object*>(p));
}

struct DescriptorBinding {
  uint32_t binding = 0;
  VkDescriptorType type = VK_DESCRIPTOR_TYPE_SAMPLER;
  uint32_t count = 0;  // for a variable-count binding: the upper bound
  VkShaderStageFlags stages = 0;
  VkDescriptorBindingFlags flags = 0;
  uint32_t offset = 0;                           // first record of this binding within the set
  uint32_t dynamicIndex = 0;                     // dynamic buffers: index of element 0 in the set's dynamic offsets
  uint32_t inlineOffset = 0;                     // inline uniform blocks: first byte in the set's inline storage
  std::vector<const Object*> immutableSamplers;  // empty, or `count` samplers
};

class DescriptorSetLayout : public Object {
 public:
  using Handle = VkDescriptorSetLayout;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_DESCRIPTOR_SET_LAYOUT;

  DescriptorSetLayout(Device* dev, const VkDescriptorSetLayoutCreateInfo& info, const VkAllocationCallbacks* alloc);

  VkDescriptorSetLayoutCreateFlags flags = 0;
  std::vector<DescriptorBinding> bindings;  // sorted by binding number
  uint32_t recordCount = 0;                 // records of a set (variable binding at its upper bound)
  uint32_t dynamicCount = 0;                // dynamic uniform + storage buffer descriptors
  uint32_t inlineBytes = 0;                 // inline uniform block bytes of a set (variable binding at its bound)
  bool hasVariableCount = false;            // the last binding is variable-sized
  // VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR: no set is allocated with it; vkCmdPushDescriptorSetKHR
  // builds one in the command buffer (runtime/push_descriptor_commands.cpp).
  bool isPush() const { return (flags & VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR) != 0; }

  // Whether `other` is "identically defined" (the same flags and bindings: VUID-vkCmdBindDescriptorSets-
  // pDescriptorSets-00358, and the push descriptor sets a later push keeps).
  bool sameDefinition(const DescriptorSetLayout& other) const;
  // The binding with number `binding`, or nullptr if the layout has none.
  const DescriptorBinding* bindingAt(uint32_t binding) const;
  // Records of a set allocated with `variableCount` elements in its variable-sized binding.
  uint32_t recordCountFor(uint32_t variableCount) const;
  // Inline uniform block bytes of a set allocated with `variableCount` (bytes, when the variable-sized binding is
  // an inline uniform block).
  uint32_t inlineBytesFor(uint32_t variableCount) const;

  // Reference counting: the application's handle holds one reference, and so does every pipeline layout,
  // descriptor set and update template made with this layout, so the application may destroy the handle
  // while they live. The object is freed (with its creation allocator) when the last reference goes.
  void retain() { refs_.fetch_add(1, std::memory_order_relaxed); }
  static void release(DescriptorSetLayout* layout);
  // Set once vkDestroyDescriptorSetLayout ran: the handle is no longer valid for the application.
  std::atomic<bool> destroyedByApp{false};

 private:
  std::atomic<uint32_t> refs_{1};
  VkAllocationCallbacks alloc_{};
  bool hasAlloc_ = false;
};

// VkPhysicalDevicePushDescriptorPropertiesKHR::maxPushDescriptors: the most descriptors a push layout holds (the
// specification's minimum is 32; a pushed set is a copy of that many records per push).
inline constexpr uint32_t kMaxPushDescriptors = 32;

// The application's live layout behind `h` (nullptr for a stale, destroyed or garbage handle).
DescriptorSetLayout* liveSetLayout(VkDescriptorSetLayout h);

// Whether `type` is a descriptor type this device accepts (acceleration structures only with
// VK_KHR_acceleration_structure enabled).
bool descriptorTypeSupported(const Device* dev, VkDescriptorType type);
const char* descriptorTypeName(VkDescriptorType type);
bool isDynamicBufferType(VkDescriptorType type);
inline bool isInlineBlock(VkDescriptorType type) { return type == VK_DESCRIPTOR_TYPE_INLINE_UNIFORM_BLOCK; }

}  // namespace vkrt
