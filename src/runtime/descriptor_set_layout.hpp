// VkDescriptorSetLayout, and the in-memory descriptor format every descriptor set uses.
//
// DESCRIPTOR STORAGE (what compiled shaders load from)
// ----------------------------------------------------
// A descriptor set is one flat, 32-byte aligned array of DescriptorRecord (32 bytes each), one record per
// array element of every binding, bindings in increasing binding number. Binding b's element i lives at
// record index `layout->bindingAt(b)->offset + i` (offsets are precomputed at layout creation; a compiler
// bakes them into the code as constants). A binding with VK_DESCRIPTOR_BINDING_VARIABLE_DESCRIPTOR_COUNT_BIT
// is always the highest binding, so it is last, and a set allocated with a smaller variable count simply has
// fewer records.
//
// Record contents by descriptor type (fields not listed are zero):
//   UNIFORM_BUFFER, STORAGE_BUFFER          address = device address of byte `offset` of the buffer,
//                                           range   = bytes in range (VK_WHOLE_SIZE already resolved),
//                                           object  = the Buffer
//   UNIFORM/STORAGE_BUFFER_DYNAMIC          the same; the shader adds the bound dynamic offset, found at
//                                           BindState::dynamicOffsets[set][binding.dynamicIndex + i]
//   UNIFORM/STORAGE_TEXEL_BUFFER            object  = the VkBufferView's vkrt object (const BufferView*)
//   SAMPLED_IMAGE, STORAGE_IMAGE            object  = the VkImageView's vkrt object (const ImageView*)
//   COMBINED_IMAGE_SAMPLER                  object  = image view, sampler = the VkSampler's vkrt object
//                                           (from pImmutableSamplers when the binding has them)
//   SAMPLER                                 sampler = the VkSampler's vkrt object
//   ACCELERATION_STRUCTURE_KHR              address = the acceleration structure's device address
//                                           (vkGetAccelerationStructureDeviceAddressKHR), object = its object
// A record of all zeros is an unwritten descriptor. `object` and `sampler` point at the Object base of the
// vkrt object (what a handle points at): convert with static_cast<const ImageView*>(...) etc.
#pragma once

#include <atomic>
#include <cstdint>
#include <vector>

#include "icd/object.hpp"

namespace vkrt {

struct alignas(32) DescriptorRecord {
  uint64_t address;      // byte 0
  uint64_t range;        // byte 8
  const Object* object;  // byte 16
  const Object* sampler; // byte 24
};
static_assert(sizeof(DescriptorRecord) == 32, "compiled shaders rely on 32-byte descriptor records");
static_assert(offsetof(DescriptorRecord, address) == 0 && offsetof(DescriptorRecord, range) == 8 &&
                  offsetof(DescriptorRecord, object) == 16 && offsetof(DescriptorRecord, sampler) == 24,
              "descriptor record layout is part of the compiled-code ABI");

struct DescriptorBinding {
  uint32_t binding = 0;
  VkDescriptorType type = VK_DESCRIPTOR_TYPE_SAMPLER;
  uint32_t count = 0;  // for a variable-count binding: the upper bound
  VkShaderStageFlags stages = 0;
  VkDescriptorBindingFlags flags = 0;
  uint32_t offset = 0;        // first record of this binding within the set
  uint32_t dynamicIndex = 0;  // dynamic buffers: index of element 0 in the set's dynamic offsets
  std::vector<const Object*> immutableSamplers;  // empty, or `count` samplers
};

class DescriptorSetLayout : public Object {
 public:
  using Handle = VkDescriptorSetLayout;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_DESCRIPTOR_SET_LAYOUT;

  DescriptorSetLayout(Device* dev, const VkDescriptorSetLayoutCreateInfo& info, const VkAllocationCallbacks* alloc);

  VkDescriptorSetLayoutCreateFlags flags = 0;
  std::vector<DescriptorBinding> bindings;  // sorted by binding number
  uint32_t recordCount = 0;                  // records of a set (variable binding at its upper bound)
  uint32_t dynamicCount = 0;                 // dynamic uniform + storage buffer descriptors
  bool hasVariableCount = false;             // the last binding is variable-sized

  // The binding with number `binding`, or nullptr if the layout has none.
  const DescriptorBinding* bindingAt(uint32_t binding) const;
  // Records of a set allocated with `variableCount` elements in its variable-sized binding.
  uint32_t recordCountFor(uint32_t variableCount) const;

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

// The application's live layout behind `h` (nullptr for a stale, destroyed or garbage handle).
DescriptorSetLayout* liveSetLayout(VkDescriptorSetLayout h);

// Whether `type` is a descriptor type this device accepts (acceleration structures only with
// VK_KHR_acceleration_structure enabled).
bool descriptorTypeSupported(const Device* dev, VkDescriptorType type);
const char* descriptorTypeName(VkDescriptorType type);
bool isDynamicBufferType(VkDescriptorType type);

}  // namespace vkrt
