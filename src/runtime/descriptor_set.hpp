// VkDescriptorSet: a flat array of DescriptorRecord (layout documented in descriptor_set_layout.hpp), and the
// write/copy machinery shared by vkUpdateDescriptorSets and descriptor update templates.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>

#include "runtime/descriptor_set_layout.hpp"

namespace vkrt {

class DescriptorPool;

class DescriptorSet : public Object {
 public:
  using Handle = VkDescriptorSet;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_DESCRIPTOR_SET;

  // Takes a reference on `layout` (released by the destructor).
  DescriptorSet(Device* dev, DescriptorPool* pool, DescriptorSetLayout* layout, uint32_t variableCount);
  ~DescriptorSet();

  DescriptorPool* const pool;  // null for a pushed set
  DescriptorSetLayout* const layout;
  // A set of push descriptors (vkCmdPushDescriptorSetKHR) is no application object: the command buffer that pushed
  // it builds and owns it, and the reports about its writes name that command buffer (the set itself is taken out
  // of the registry: no handle of it is ever given out).
  const Object* pushedBy = nullptr;
  // What reports about this set name: the set, or the command buffer that pushed it.
  const Object* reportObject() const { return pushedBy ? pushedBy : this; }
  const uint32_t variableCount;  // elements of the variable-sized binding (0 when the layout has none)
  const uint32_t recordCount;

  // The records compiled code reads: records()[binding.offset + arrayElement].
  DescriptorRecord* records() { return records_.get(); }
  const DescriptorRecord* records() const { return records_.get(); }
  // Elements binding `b` has in this set (the variable count for a variable-sized binding); an inline uniform
  // block has one (its record) unless its size is 0.
  uint32_t elementCount(const DescriptorBinding& b) const;
  // Inline uniform block binding `b`: its size in this set and its bytes (zero until written).
  uint32_t inlineSize(const DescriptorBinding& b) const;
  uint8_t* inlineData(const DescriptorBinding& b) { return inline_.get() + b.inlineOffset; }

  // Whether record `i` has been written (or copied from a written one) since the set was allocated; read when a
  // dispatch or launch executes (VUID-vkCmdDispatch-None-08114), possibly while an update-after-bind write runs.
  bool written(uint32_t i) const { return written_[i].load(std::memory_order_relaxed) != 0; }
  void setWritten(uint32_t i, bool w) { written_[i].store(w ? 1 : 0, std::memory_order_relaxed); }

 private:
  std::unique_ptr<DescriptorRecord[]> records_;
  std::unique_ptr<std::atomic<uint8_t>[]> written_;
  std::unique_ptr<uint8_t[]> inline_;  // the inline uniform blocks' bytes (layout->inlineBytesFor(variableCount))
};

// Writes `count` descriptors of `type` starting at (binding, arrayElement), crossing into consecutive bindings
// as the spec allows. Descriptor i's source is at `base + i * stride`: a VkDescriptorImageInfo, a
// VkDescriptorBufferInfo, a VkBufferView or a VkAccelerationStructureKHR, by type. With apply=false only checks
// (reporting the first problem, naming `what`) and returns false on error; with apply=true stores the records.
bool writeDescriptors(DescriptorSet* set, uint32_t binding, uint32_t arrayElement, uint32_t count,
                      VkDescriptorType type, const uint8_t* base, size_t stride, bool apply, const char* what);

// Checks (apply=false) or carries out (apply=true) one VkWriteDescriptorSet into `set` (its dstSet is not read:
// vkUpdateDescriptorSets resolves it, and a push descriptor write ignores it). Reports naming `what`.
bool writeDescriptorSet(DescriptorSet* set, const VkWriteDescriptorSet& w, bool apply, const char* what);

// Writes `size` bytes from `data` into inline uniform block `binding` from byte `offset`, the rest into the
// consecutive bindings after it from their byte 0 ("Descriptor Set Updates"). Reports (naming `what`) and returns
// false when the binding is not an inline uniform block, the bytes run past the set, a consecutive binding differs,
// or offset or size is not a multiple of 4 (under `offsetVuid`, `sizeVuid`); with apply=false only checks.
bool writeInlineBlock(DescriptorSet* set, uint32_t binding, uint32_t offset, uint32_t size, const uint8_t* data,
                      bool apply, const char* what, const char* offsetVuid, const char* sizeVuid);

}  // namespace vkrt
