#include "runtime/descriptor_set.hpp"

#include <algorithm>
#include <cstring>
#include <vector>

#include "runtime/acceleration_structure.hpp"
#include "runtime/alloc.hpp"
#include "runtime/buffer.hpp"
#include "runtime/descriptor_pool.hpp"
#include "runtime/device.hpp"
#include "runtime/image_view.hpp"
#include "runtime/physical_device.hpp"
#include "runtime/report.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {

DescriptorSet::DescriptorSet(Device* dev, DescriptorPool* pool, DescriptorSetLayout* layout, uint32_t variableCount)
    : Object(kType, dev->instance, dev),
      pool(pool),
      layout(layout),
      variableCount(layout->hasVariableCount ? variableCount : 0),
      recordCount(layout->recordCountFor(variableCount)),
      records_(new DescriptorRecord[recordCount ? recordCount : 1]()),
      written_(new std::atomic<uint8_t>[recordCount ? recordCount : 1]()) {
  layout->retain();
  const uint32_t inlineBytes = layout->inlineBytesFor(this->variableCount);
  inline_.reset(new uint8_t[inlineBytes ? inlineBytes : 1]());
  for (const DescriptorBinding& b : layout->bindings) {
    if (isInlineBlock(b.type)) {
      if (!b.count) continue;  // no record
      // The block's record points at its bytes like a uniform buffer descriptor (descriptor_set_layout.hpp). The
      // descriptor is valid from allocation: only its bytes are undefined until written, so it never counts as
      // unwritten (VUID-vkCmdDispatch-None-08114).
      DescriptorRecord& r = records_[b.offset];
      r.address = reinterpret_cast<uint64_t>(inlineData(b));
      r.range = inlineSize(b);
      written_[b.offset].store(1, std::memory_order_relaxed);
      continue;
    }
    // Immutable samplers are part of the set from the start.
    uint32_t n = elementCount(b);
    for (uint32_t i = 0; i < n && i < b.immutableSamplers.size(); ++i)
      records_[b.offset + i].sampler = b.immutableSamplers[i];
  }
}

DescriptorSet::~DescriptorSet() { DescriptorSetLayout::release(layout); }

uint32_t DescriptorSet::elementCount(const DescriptorBinding& b) const {
  const uint32_t n = (b.flags & VK_DESCRIPTOR_BINDING_VARIABLE_DESCRIPTOR_COUNT_BIT) ? variableCount : b.count;
  return isInlineBlock(b.type) ? (n ? 1 : 0) : n;
}

uint32_t DescriptorSet::inlineSize(const DescriptorBinding& b) const {
  if (!isInlineBlock(b.type)) return 0;
  return (b.flags & VK_DESCRIPTOR_BINDING_VARIABLE_DESCRIPTOR_COUNT_BIT) ? variableCount : b.count;
}

namespace {

bool isBufferType(VkDescriptorType t) {
  return t == VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER || t == VK_DESCRIPTOR_TYPE_STORAGE_BUFFER || isDynamicBufferType(t);
}
bool isUniform(VkDescriptorType t) {
  return t == VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER || t == VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC;
}

// Element-by-element walk over (binding, arrayElement) and the consecutive bindings after it.
struct Span {
  std::vector<const DescriptorBinding*> binding;  // per descriptor
  uint32_t firstRecord = 0;
};

// Fills `span` with the `count` descriptors from (binding, arrayElement). Reports with the VUIDs of `vuids`
// (dstBinding-invalid, type-mismatch, overflow) and returns false on error. `type` may be
// VK_DESCRIPTOR_TYPE_MAX_ENUM to take the first binding's type.
struct SpanVuids {
  const char* noBinding;
  const char* typeMismatch;
  const char* overflow;
  const char* consecutive;
};
bool walk(const DescriptorSet* set, uint32_t binding, uint32_t arrayElement, uint32_t count, VkDescriptorType type,
          const SpanVuids& v, const char* what, Span& span) {
  const DescriptorSetLayout& l = *set->layout;
  const DescriptorBinding* b = l.bindingAt(binding);
  if (!b || set->elementCount(*b) == 0) {
    report(set->reportObject(), Severity::Error, v.noBinding,
           "%s: binding %u does not exist in the set's layout (or has no descriptors)", what, binding);
    return false;
  }
  if (type != VK_DESCRIPTOR_TYPE_MAX_ENUM && b->type != type) {
    report(set->reportObject(), Severity::Error, v.typeMismatch, "%s: binding %u is %s, not %s", what, binding,
           descriptorTypeName(b->type), descriptorTypeName(type));
    return false;
  }
  span.binding.clear();
  span.firstRecord = b->offset + arrayElement;
  size_t idx = static_cast<size_t>(b - l.bindings.data());
  uint32_t e = arrayElement;
  for (uint32_t i = 0; i < count; ++i) {
    while (e >= set->elementCount(l.bindings[idx])) {
      e -= set->elementCount(l.bindings[idx]);
      ++idx;
      if (idx >= l.bindings.size()) {
        report(set->reportObject(), Severity::Error, v.overflow,
               "%s: %u descriptors from binding %u element %u run past the end of the set (%u records)", what, count,
               binding, arrayElement, set->recordCount);
        return false;
      }
      const DescriptorBinding& n = l.bindings[idx];
      if (set->elementCount(n) && (n.type != b->type || n.stages != b->stages || n.flags != b->flags ||
                                   n.immutableSamplers.empty() != b->immutableSamplers.empty())) {
        report(set->reportObject(), Severity::Error, v.consecutive,
               "%s: the update runs from binding %u into binding %u, whose type, stages, flags or immutable samplers "
               "differ",
               what, binding, n.binding);
        return false;
      }
    }
    span.binding.push_back(&l.bindings[idx]);
    ++e;
  }
  return true;
}

// One piece of an inline uniform block update: `size` bytes from byte `offset` of binding `b`.
struct InlinePiece {
  const DescriptorBinding* b;
  uint32_t offset, size;
};

// Splits `size` bytes from byte `offset` of inline uniform block `binding` over it and the consecutive bindings
// after it (an inline block's bytes play the part of array elements: "Descriptor Set Updates"). Reports with
// `v` and returns false on error. The pieces are contiguous in the set's inline storage, from byte
// `bindingAt(binding)->inlineOffset + offset`.
bool inlinePieces(const DescriptorSet* set, uint32_t binding, uint32_t offset, uint32_t size, const SpanVuids& v,
                  const char* what, std::vector<InlinePiece>& out) {
  const DescriptorSetLayout& l = *set->layout;
  const DescriptorBinding* b = l.bindingAt(binding);
  if (!b || set->elementCount(*b) == 0) {
    report(set->reportObject(), Severity::Error, v.noBinding,
           "%s: binding %u does not exist in the set's layout (or has no descriptors)", what, binding);
    return false;
  }
  if (!isInlineBlock(b->type)) {
    report(set->reportObject(), Severity::Error, v.typeMismatch,
           "%s: binding %u is %s, not VK_DESCRIPTOR_TYPE_INLINE_UNIFORM_BLOCK", what, binding,
           descriptorTypeName(b->type));
    return false;
  }
  out.clear();
  size_t idx = static_cast<size_t>(b - l.bindings.data());
  uint32_t at = offset, left = size;
  for (;;) {
    const DescriptorBinding& cur = l.bindings[idx];
    const uint32_t have = set->inlineSize(cur);
    if (left && at < have) {
      const uint32_t n = std::min(left, have - at);
      out.push_back({&cur, at, n});
      left -= n;
      at += n;
    }
    if (!left) return true;
    at -= have;
    if (++idx >= l.bindings.size()) {
      report(set->reportObject(), Severity::Error, v.overflow,
             "%s: %u bytes from byte %u of inline uniform block binding %u run past the end of the set", what, size,
             offset, binding);
      return false;
    }
    const DescriptorBinding& n = l.bindings[idx];
    if (set->elementCount(n) && (n.type != b->type || n.stages != b->stages || n.flags != b->flags)) {
      report(set->reportObject(), Severity::Error, v.consecutive,
             "%s: the update runs from binding %u into binding %u, whose type, stages or flags differ", what, binding,
             n.binding);
      return false;
    }
  }
}

// Computes descriptor `i`'s record from its source. Reports and returns false on a bad source.
bool resolve(DescriptorSet* set, const DescriptorBinding& b, VkDescriptorType type, const uint8_t* src, uint32_t i,
             const char* what, DescriptorRecord& out) {
  Device* dev = set->device;
  const VkPhysicalDeviceLimits& lim = dev->physicalDevice->properties10.limits;
  out = {};
  if (isBufferType(type)) {
    auto& bi = *reinterpret_cast<const VkDescriptorBufferInfo*>(src);
    // VUID-VkDescriptorBufferInfo-buffer-02998
    if (!bi.buffer) {
      report(set->reportObject(), Severity::Error, "VUID-VkDescriptorBufferInfo-buffer-02998",
             "%s: descriptor %u: buffer is VK_NULL_HANDLE and the nullDescriptor feature is not enabled", what, i);
      return false;
    }
    Buffer* buf = fromHandle<Buffer>(bi.buffer);
    // VUID-VkDescriptorBufferInfo-buffer-parameter
    if (!buf) {
      report(set->reportObject(), Severity::Error, "VUID-VkDescriptorBufferInfo-buffer-parameter",
             "%s: descriptor %u: buffer 0x%llx is not a live VkBuffer", what, i,
             (unsigned long long)rawHandle(bi.buffer));
      return false;
    }
    // VUID-VkDescriptorBufferInfo-offset-00340
    if (bi.offset >= buf->size) {
      report(set->reportObject(), Severity::Error, "VUID-VkDescriptorBufferInfo-offset-00340",
             "%s: descriptor %u: offset %llu is not less than the buffer size %llu", what, i,
             (unsigned long long)bi.offset, (unsigned long long)buf->size);
      return false;
    }
    // VUID-VkDescriptorBufferInfo-range-00341
    if (bi.range == 0) {
      report(set->reportObject(), Severity::Error, "VUID-VkDescriptorBufferInfo-range-00341",
             "%s: descriptor %u: range is 0", what, i);
      return false;
    }
    // VUID-VkDescriptorBufferInfo-range-00342
    if (bi.range != VK_WHOLE_SIZE && bi.range > buf->size - bi.offset) {
      report(set->reportObject(), Severity::Error, "VUID-VkDescriptorBufferInfo-range-00342",
             "%s: descriptor %u: range %llu at offset %llu exceeds the %llu-byte buffer", what, i,
             (unsigned long long)bi.range, (unsigned long long)bi.offset, (unsigned long long)buf->size);
      return false;
    }
    VkDeviceSize range = buf->rangeFrom(bi.offset, bi.range);
    bool uniform = isUniform(type);
    // VUID-VkWriteDescriptorSet-descriptorType-00330, VUID-VkWriteDescriptorSet-descriptorType-00331
    VkBufferUsageFlags need = uniform ? VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT : VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    if (!(buf->usage & need)) {
      report(
          set, Severity::Error,
          uniform ? "VUID-VkWriteDescriptorSet-descriptorType-00330" : "VUID-VkWriteDescriptorSet-descriptorType-00331",
          "%s: descriptor %u (%s): buffer 0x%llx lacks %s usage (usage 0x%x)", what, i, descriptorTypeName(type),
          (unsigned long long)rawHandle(bi.buffer),
          uniform ? "VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT" : "VK_BUFFER_USAGE_STORAGE_BUFFER_BIT", buf->usage);
      return false;
    }
    // VUID-VkWriteDescriptorSet-descriptorType-00327, VUID-VkWriteDescriptorSet-descriptorType-00328
    VkDeviceSize align = uniform ? lim.minUniformBufferOffsetAlignment : lim.minStorageBufferOffsetAlignment;
    if (bi.offset % align) {
      report(
          set, Severity::Error,
          uniform ? "VUID-VkWriteDescriptorSet-descriptorType-00327" : "VUID-VkWriteDescriptorSet-descriptorType-00328",
          "%s: descriptor %u: offset %llu is not a multiple of %llu", what, i, (unsigned long long)bi.offset,
          (unsigned long long)align);
      return false;
    }
    // VUID-VkWriteDescriptorSet-descriptorType-00332, VUID-VkWriteDescriptorSet-descriptorType-00333
    VkDeviceSize maxRange = uniform ? lim.maxUniformBufferRange : lim.maxStorageBufferRange;
    if (range > maxRange) {
      report(
          set, Severity::Error,
          uniform ? "VUID-VkWriteDescriptorSet-descriptorType-00332" : "VUID-VkWriteDescriptorSet-descriptorType-00333",
          "%s: descriptor %u: effective range %llu exceeds the limit %llu", what, i, (unsigned long long)range,
          (unsigned long long)maxRange);
      return false;
    }
    // VUID-VkWriteDescriptorSet-descriptorType-00329
    if (!buf->memory) {
      report(set->reportObject(), Severity::Error, "VUID-VkWriteDescriptorSet-descriptorType-00329",
             "%s: descriptor %u: buffer 0x%llx is not bound to memory", what, i,
             (unsigned long long)rawHandle(bi.buffer));
      return false;
    }
    out.address = reinterpret_cast<uint64_t>(buf->data() + bi.offset);
    out.range = range;
    out.object = static_cast<const Object*>(buf);
    return true;
  }
  switch (type) {
    case VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER:
    case VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER: {
      VkBufferView h = *reinterpret_cast<const VkBufferView*>(src);
      // VUID-VkWriteDescriptorSet-descriptorType-02995
      if (!h) {
        report(set->reportObject(), Severity::Error, "VUID-VkWriteDescriptorSet-descriptorType-02995",
               "%s: descriptor %u: texel buffer view is VK_NULL_HANDLE and nullDescriptor is not enabled", what, i);
        return false;
      }
      const Object* view = findObject(rawHandle(h), VK_OBJECT_TYPE_BUFFER_VIEW);
      // VUID-VkWriteDescriptorSet-descriptorType-02994
      if (!view) {
        report(set->reportObject(), Severity::Error, "VUID-VkWriteDescriptorSet-descriptorType-02994",
               "%s: descriptor %u: 0x%llx is not a live VkBufferView", what, i, (unsigned long long)rawHandle(h));
        return false;
      }
      out.object = view;
      return true;
    }
    case VK_DESCRIPTOR_TYPE_SAMPLER:
    case VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER:
    case VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE:
    case VK_DESCRIPTOR_TYPE_STORAGE_IMAGE:
    case VK_DESCRIPTOR_TYPE_INPUT_ATTACHMENT: {
      auto& ii = *reinterpret_cast<const VkDescriptorImageInfo*>(src);
      if (type != VK_DESCRIPTOR_TYPE_SAMPLER) {
        // VUID-VkWriteDescriptorSet-descriptorType-02997
        if (!ii.imageView) {
          report(set->reportObject(), Severity::Error, "VUID-VkWriteDescriptorSet-descriptorType-02997",
                 "%s: descriptor %u: imageView is VK_NULL_HANDLE and nullDescriptor is not enabled", what, i);
          return false;
        }
        out.object = findObject(rawHandle(ii.imageView), VK_OBJECT_TYPE_IMAGE_VIEW);
        // VUID-VkWriteDescriptorSet-descriptorType-02996
        if (!out.object) {
          report(set->reportObject(), Severity::Error, "VUID-VkWriteDescriptorSet-descriptorType-02996",
                 "%s: descriptor %u: imageView 0x%llx is not a live VkImageView", what, i,
                 (unsigned long long)rawHandle(ii.imageView));
          return false;
        }
        // VUID-VkWriteDescriptorSet-descriptorType-00337 / 00339 / 00338: the view's usage (inherited from the
        // usage of its aspects: stencilUsage for a stencil view of an image with separate stencil usage)
        const VkImageUsageFlags need = type == VK_DESCRIPTOR_TYPE_STORAGE_IMAGE ? VK_IMAGE_USAGE_STORAGE_BIT
                                       : type == VK_DESCRIPTOR_TYPE_INPUT_ATTACHMENT
                                           ? VK_IMAGE_USAGE_INPUT_ATTACHMENT_BIT
                                           : VK_IMAGE_USAGE_SAMPLED_BIT;
        const auto* view = static_cast<const ImageView*>(out.object);
        out.address = reinterpret_cast<uint64_t>(&view->store.texels);  // (abi.hpp: range stays 0)
        if (!(view->usage & need)) {
          report(set->reportObject(), Severity::Error,
                 need == VK_IMAGE_USAGE_STORAGE_BIT            ? "VUID-VkWriteDescriptorSet-descriptorType-00339"
                 : need == VK_IMAGE_USAGE_INPUT_ATTACHMENT_BIT ? "VUID-VkWriteDescriptorSet-descriptorType-00338"
                                                               : "VUID-VkWriteDescriptorSet-descriptorType-00337",
                 "%s: descriptor %u (%s): imageView 0x%llx has usage 0x%x without 0x%x", what, i,
                 descriptorTypeName(type), (unsigned long long)rawHandle(ii.imageView), view->usage, need);
          return false;
        }
      }
      if (type == VK_DESCRIPTOR_TYPE_SAMPLER || type == VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER) {
        if (!b.immutableSamplers.empty()) return true;  // the sampler member is ignored; the record keeps its sampler
        out.sampler = findObject(rawHandle(ii.sampler), VK_OBJECT_TYPE_SAMPLER);
        // VUID-VkWriteDescriptorSet-descriptorType-00325
        if (!out.sampler) {
          report(set->reportObject(), Severity::Error, "VUID-VkWriteDescriptorSet-descriptorType-00325",
                 "%s: descriptor %u: sampler 0x%llx is not a live VkSampler", what, i,
                 (unsigned long long)rawHandle(ii.sampler));
          return false;
        }
      }
      return true;
    }
    case VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_NV: {
      uint64_t h = *reinterpret_cast<const uint64_t*>(src);
      const Object* as = h ? findObject(h, VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_NV) : nullptr;
      // VUID-VkWriteDescriptorSetAccelerationStructureNV-pAccelerationStructures-parameter
      if (!as) {
        report(set->reportObject(), Severity::Error,
               "VUID-VkWriteDescriptorSetAccelerationStructureNV-pAccelerationStructures-parameter",
               "%s: descriptor %u: 0x%llx is not a live VkAccelerationStructureNV", what, i, (unsigned long long)h);
        return false;
      }
      out.object = as;
      out.address = static_cast<const AccelerationStructure*>(as)->address();
      return true;
    }
    case VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR: {
      uint64_t h = *reinterpret_cast<const uint64_t*>(src);
      // VUID-VkWriteDescriptorSetAccelerationStructureKHR-pAccelerationStructures-03580
      if (!h) {
        report(set->reportObject(), Severity::Error,
               "VUID-VkWriteDescriptorSetAccelerationStructureKHR-pAccelerationStructures-03580",
               "%s: descriptor %u: acceleration structure is VK_NULL_HANDLE and nullDescriptor is not enabled", what,
               i);
        return false;
      }
      const Object* as = findObject(h, VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR);
      // VUID-VkWriteDescriptorSetAccelerationStructureKHR-pAccelerationStructures-parameter
      if (!as) {
        report(set->reportObject(), Severity::Error,
               "VUID-VkWriteDescriptorSetAccelerationStructureKHR-pAccelerationStructures-parameter",
               "%s: descriptor %u: 0x%llx is not a live VkAccelerationStructureKHR", what, i, (unsigned long long)h);
        return false;
      }
      out.object = as;
      out.address = static_cast<const AccelerationStructure*>(as)->address();
      return true;
    }
    default:
      report(set->reportObject(), Severity::Error, "VUID-VkWriteDescriptorSet-descriptorType-parameter",
             "%s: descriptor type %d is not supported", what, type);
      return false;
  }
}

}  // namespace

bool writeDescriptors(DescriptorSet* set, uint32_t binding, uint32_t arrayElement, uint32_t count,
                      VkDescriptorType type, const uint8_t* base, size_t stride, bool apply, const char* what) {
  Span span;
  static const SpanVuids kVuids = {
      "VUID-VkWriteDescriptorSet-dstBinding-00315", "VUID-VkWriteDescriptorSet-descriptorType-00319",
      "VUID-VkWriteDescriptorSet-dstArrayElement-00321", "VUID-VkWriteDescriptorSet-descriptorCount-00317"};
  if (!walk(set, binding, arrayElement, count, type, kVuids, what, span)) return false;
  // VUID-VkWriteDescriptorSet-descriptorType-02752 (of an allocated set: push descriptors push a binding's immutable
  // samplers, which the records keep, by writing it)
  if (type == VK_DESCRIPTOR_TYPE_SAMPLER && !span.binding[0]->immutableSamplers.empty() && !set->pushedBy) {
    report(set->reportObject(), Severity::Error, "VUID-VkWriteDescriptorSet-descriptorType-02752",
           "%s: binding %u has immutable samplers; VK_DESCRIPTOR_TYPE_SAMPLER descriptors cannot be written to it",
           what, binding);
    return false;
  }
  for (uint32_t i = 0; i < count; ++i) {
    DescriptorRecord r;
    if (!resolve(set, *span.binding[i], type, base + i * stride, i, what, r)) return false;
    if (apply) {
      DescriptorRecord& dst = set->records()[span.firstRecord + i];
      if (!span.binding[i]->immutableSamplers.empty()) r.sampler = dst.sampler;  // immutable: keep
      dst = r;
      set->setWritten(span.firstRecord + i, true);
    }
  }
  return true;
}

bool writeInlineBlock(DescriptorSet* set, uint32_t binding, uint32_t offset, uint32_t size, const uint8_t* data,
                      bool apply, const char* what, const char* offsetVuid, const char* sizeVuid) {
  // offsetVuid: VUID-VkWriteDescriptorSet-descriptorType-02219 or VUID-VkDescriptorUpdateTemplateEntry-descriptor-02226
  if (offset % 4) {
    report(set->reportObject(), Severity::Error, offsetVuid,
           "%s: the inline uniform block update starts at byte %u, not a multiple of 4", what, offset);
    return false;
  }
  // sizeVuid: VUID-VkWriteDescriptorSet-descriptorType-02220 or VUID-VkDescriptorUpdateTemplateEntry-descriptor-02227
  if (size % 4) {
    report(set->reportObject(), Severity::Error, sizeVuid,
           "%s: the inline uniform block update has %u bytes, not a multiple of 4", what, size);
    return false;
  }
  static const SpanVuids kVuids = {
      "VUID-VkWriteDescriptorSet-dstBinding-00315", "VUID-VkWriteDescriptorSet-descriptorType-00319",
      "VUID-VkWriteDescriptorSet-dstArrayElement-00321", "VUID-VkWriteDescriptorSet-descriptorCount-00317"};
  std::vector<InlinePiece> pieces;
  if (!inlinePieces(set, binding, offset, size, kVuids, what, pieces)) return false;
  if (apply) {
    for (const InlinePiece& p : pieces) {
      std::memcpy(set->inlineData(*p.b) + p.offset, data, p.size);
      data += p.size;
    }
  }
  return true;
}

}  // namespace vkrt

using namespace vkrt;

namespace {

// Source array and stride of a VkWriteDescriptorSet, by type. Null with a report when it is missing.
const uint8_t* writeSource(DescriptorSet* set, const VkWriteDescriptorSet& w, size_t& stride, const char* what) {
  if (w.descriptorType == VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR) {
    auto* as = findInChain<VkWriteDescriptorSetAccelerationStructureKHR>(
        w.pNext, VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_KHR);
    // VUID-VkWriteDescriptorSet-descriptorType-02382
    if (!as || as->accelerationStructureCount != w.descriptorCount) {
      report(set->reportObject(), Severity::Error, "VUID-VkWriteDescriptorSet-descriptorType-02382",
             "%s: an acceleration structure write needs a VkWriteDescriptorSetAccelerationStructureKHR with %u "
             "structures in its pNext chain",
             what, w.descriptorCount);
      return nullptr;
    }
    stride = sizeof(VkAccelerationStructureKHR);
    return reinterpret_cast<const uint8_t*>(as->pAccelerationStructures);
  }
  if (w.descriptorType == VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_NV) {
    auto* as = findInChain<VkWriteDescriptorSetAccelerationStructureNV>(
        w.pNext, VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_NV);
    // VUID-VkWriteDescriptorSet-descriptorType-03817
    if (!as || as->accelerationStructureCount != w.descriptorCount) {
      report(set->reportObject(), Severity::Error, "VUID-VkWriteDescriptorSet-descriptorType-03817",
             "%s: an NV acceleration structure write needs a VkWriteDescriptorSetAccelerationStructureNV with %u "
             "structures in its pNext chain",
             what, w.descriptorCount);
      return nullptr;
    }
    stride = sizeof(VkAccelerationStructureNV);
    return reinterpret_cast<const uint8_t*>(as->pAccelerationStructures);
  }
  if (isBufferType(w.descriptorType)) {
    stride = sizeof(VkDescriptorBufferInfo);
    return reinterpret_cast<const uint8_t*>(w.pBufferInfo);
  }
  if (w.descriptorType == VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER ||
      w.descriptorType == VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER) {
    stride = sizeof(VkBufferView);
    return reinterpret_cast<const uint8_t*>(w.pTexelBufferView);
  }
  stride = sizeof(VkDescriptorImageInfo);
  return reinterpret_cast<const uint8_t*>(w.pImageInfo);
}

}  // namespace

namespace vkrt {

bool writeDescriptorSet(DescriptorSet* set, const VkWriteDescriptorSet& w, bool apply, const char* what) {
  Device* dev = set->device;
  if (isInlineBlock(w.descriptorType)) {
    auto* ib = findInChain<VkWriteDescriptorSetInlineUniformBlock>(
        w.pNext, VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_INLINE_UNIFORM_BLOCK);
    // VUID-VkWriteDescriptorSet-descriptorType-02221
    if (!ib || ib->dataSize != w.descriptorCount) {
      report(set->reportObject(), Severity::Error, "VUID-VkWriteDescriptorSet-descriptorType-02221",
             "%s: an inline uniform block write of %u bytes needs a VkWriteDescriptorSetInlineUniformBlock with "
             "dataSize %u in its pNext chain (%s)",
             what, w.descriptorCount, w.descriptorCount, ib ? "its dataSize differs" : "there is none");
      return false;
    }
    // VUID-VkWriteDescriptorSetInlineUniformBlock-pData-parameter
    if (!ib->pData) {
      report(set->reportObject(), Severity::Error, "VUID-VkWriteDescriptorSetInlineUniformBlock-pData-parameter",
             "%s: VkWriteDescriptorSetInlineUniformBlock::pData is null", what);
      return false;
    }
    // VUID-VkWriteDescriptorSetInlineUniformBlock-dataSize-02222 is VUID-VkWriteDescriptorSet-descriptorType-02220
    // here (dataSize equals descriptorCount).
    return writeInlineBlock(
        set, w.dstBinding, w.dstArrayElement, w.descriptorCount, static_cast<const uint8_t*>(ib->pData), apply, what,
        "VUID-VkWriteDescriptorSet-descriptorType-02219", "VUID-VkWriteDescriptorSet-descriptorType-02220");
  }
  size_t stride = 0;
  const uint8_t* src = writeSource(set, w, stride, what);
  // A push of sampler descriptors into a binding with immutable samplers pushes those; its pImageInfo may be null
  // (VUID-vkCmdPushDescriptorSetKHR-pDescriptorWrites-06494 leaves VK_DESCRIPTOR_TYPE_SAMPLER out), and resolve()
  // reads nothing of it.
  static const VkDescriptorImageInfo kNoImageInfo{};
  if (!src && set->pushedBy && w.descriptorType == VK_DESCRIPTOR_TYPE_SAMPLER) {
    const DescriptorBinding* b = set->layout->bindingAt(w.dstBinding);
    if (b && !b->immutableSamplers.empty()) {
      src = reinterpret_cast<const uint8_t*>(&kNoImageInfo);
      stride = 0;
    }
  }
  // VUID-VkWriteDescriptorSet-descriptorType-00322, -00323, -00324
  if (!src) {
    if (w.descriptorType != VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR &&
        w.descriptorType != VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_NV)
      report(set->reportObject(), Severity::Error,
             isBufferType(w.descriptorType) ? "VUID-VkWriteDescriptorSet-descriptorType-00324"
                                            : "VUID-VkWriteDescriptorSet-descriptorType-00322",
             "%s: the descriptor array for %s is null", what, descriptorTypeName(w.descriptorType));
    return false;
  }
  // VUID-VkWriteDescriptorSet-descriptorType-parameter
  if (!descriptorTypeSupported(dev, w.descriptorType)) {
    report(set->reportObject(), Severity::Error, "VUID-VkWriteDescriptorSet-descriptorType-parameter",
           "%s: descriptor type %d is not supported", what, w.descriptorType);
    return false;
  }
  return writeDescriptors(set, w.dstBinding, w.dstArrayElement, w.descriptorCount, w.descriptorType, src, stride, apply,
                          what);
}

}  // namespace vkrt

namespace {

bool doWrite(Device* dev, const VkWriteDescriptorSet& w, uint32_t index, bool apply) {
  char what[64];
  std::snprintf(what, sizeof what, "vkUpdateDescriptorSets: pDescriptorWrites[%u]", index);
  DescriptorSet* set = fromHandle<DescriptorSet>(w.dstSet);
  // VUID-VkWriteDescriptorSet-dstSet-00320
  if (!set) {
    report(dev, Severity::Error, "VUID-VkWriteDescriptorSet-dstSet-00320",
           "%s: dstSet 0x%llx is not a live VkDescriptorSet", what, (unsigned long long)rawHandle(w.dstSet));
    return false;
  }
  return writeDescriptorSet(set, w, apply, what);
}

// A copy from an inline uniform block: srcArrayElement, dstArrayElement and descriptorCount are bytes.
bool copyInline(DescriptorSet* src, DescriptorSet* dst, const VkCopyDescriptorSet& c, bool apply, const char* what) {
  // VUID-VkCopyDescriptorSet-srcBinding-02223, VUID-VkCopyDescriptorSet-dstBinding-02224,
  // VUID-VkCopyDescriptorSet-srcBinding-02225
  const char* vuid = c.srcArrayElement % 4   ? "VUID-VkCopyDescriptorSet-srcBinding-02223"
                     : c.dstArrayElement % 4 ? "VUID-VkCopyDescriptorSet-dstBinding-02224"
                     : c.descriptorCount % 4 ? "VUID-VkCopyDescriptorSet-srcBinding-02225"
                                             : nullptr;
  if (vuid) {
    report(dst, Severity::Error, vuid,
           "%s: an inline uniform block copy needs srcArrayElement (%u), dstArrayElement (%u) and descriptorCount (%u) "
           "to be multiples of 4 (they are bytes)",
           what, c.srcArrayElement, c.dstArrayElement, c.descriptorCount);
    return false;
  }
  static const SpanVuids kSrc = {
      "VUID-VkCopyDescriptorSet-srcBinding-00345", "VUID-VkCopyDescriptorSet-dstBinding-02632",
      "VUID-VkCopyDescriptorSet-srcArrayElement-00346", "VUID-VkCopyDescriptorSet-srcArrayElement-00346"};
  static const SpanVuids kDst = {
      "VUID-VkCopyDescriptorSet-dstBinding-00347", "VUID-VkCopyDescriptorSet-dstBinding-02632",
      "VUID-VkCopyDescriptorSet-dstArrayElement-00348", "VUID-VkCopyDescriptorSet-dstArrayElement-00348"};
  std::vector<InlinePiece> s, d;
  if (!inlinePieces(src, c.srcBinding, c.srcArrayElement, c.descriptorCount, kSrc, what, s)) return false;
  if (!inlinePieces(dst, c.dstBinding, c.dstArrayElement, c.descriptorCount, kDst, what, d)) return false;
  // VUID-VkCopyDescriptorSet-srcSet-00349 (the pieces are contiguous in the set's inline storage)
  const uint64_t from = uint64_t(src->layout->bindingAt(c.srcBinding)->inlineOffset) + c.srcArrayElement;
  const uint64_t to = uint64_t(dst->layout->bindingAt(c.dstBinding)->inlineOffset) + c.dstArrayElement;
  if (src == dst && from < to + c.descriptorCount && to < from + c.descriptorCount) {
    report(dst, Severity::Error, "VUID-VkCopyDescriptorSet-srcSet-00349",
           "%s: source bytes [%llu, %llu) and destination bytes [%llu, %llu) of the set's inline uniform blocks "
           "overlap",
           what, (unsigned long long)from, (unsigned long long)(from + c.descriptorCount), (unsigned long long)to,
           (unsigned long long)(to + c.descriptorCount));
    return false;
  }
  if (apply) {
    std::vector<uint8_t> bytes;
    bytes.reserve(c.descriptorCount);
    for (const InlinePiece& p : s) {
      const uint8_t* at = src->inlineData(*p.b) + p.offset;
      bytes.insert(bytes.end(), at, at + p.size);
    }
    const uint8_t* next = bytes.data();
    for (const InlinePiece& p : d) {
      std::memcpy(dst->inlineData(*p.b) + p.offset, next, p.size);
      next += p.size;
    }
  }
  return true;
}

bool doCopy(Device* dev, const VkCopyDescriptorSet& c, uint32_t index, bool apply) {
  char what[64];
  std::snprintf(what, sizeof what, "vkUpdateDescriptorSets: pDescriptorCopies[%u]", index);
  DescriptorSet* src = fromHandle<DescriptorSet>(c.srcSet);
  DescriptorSet* dst = fromHandle<DescriptorSet>(c.dstSet);
  // VUID-VkCopyDescriptorSet-srcSet-parameter, VUID-VkCopyDescriptorSet-dstSet-parameter
  if (!src || !dst) {
    report(dev, Severity::Error,
           !src ? "VUID-VkCopyDescriptorSet-srcSet-parameter" : "VUID-VkCopyDescriptorSet-dstSet-parameter",
           "%s: %s 0x%llx is not a live VkDescriptorSet", what, !src ? "srcSet" : "dstSet",
           (unsigned long long)rawHandle(!src ? c.srcSet : c.dstSet));
    return false;
  }
  const DescriptorBinding* sb = src->layout->bindingAt(c.srcBinding);
  if (sb && isInlineBlock(sb->type)) return copyInline(src, dst, c, apply, what);
  Span s, d;
  static const SpanVuids kSrc = {
      "VUID-VkCopyDescriptorSet-srcBinding-00345", "VUID-VkCopyDescriptorSet-dstBinding-02632",
      "VUID-VkCopyDescriptorSet-srcArrayElement-00346", "VUID-VkCopyDescriptorSet-srcArrayElement-00346"};
  static const SpanVuids kDst = {
      "VUID-VkCopyDescriptorSet-dstBinding-00347", "VUID-VkCopyDescriptorSet-dstBinding-02632",
      "VUID-VkCopyDescriptorSet-dstArrayElement-00348", "VUID-VkCopyDescriptorSet-dstArrayElement-00348"};
  if (!walk(src, c.srcBinding, c.srcArrayElement, c.descriptorCount, VK_DESCRIPTOR_TYPE_MAX_ENUM, kSrc, what, s))
    return false;
  if (!walk(dst, c.dstBinding, c.dstArrayElement, c.descriptorCount, s.binding[0]->type, kDst, what, d)) return false;
  // VUID-VkCopyDescriptorSet-dstBinding-02753
  if (d.binding[0]->type == VK_DESCRIPTOR_TYPE_SAMPLER && !d.binding[0]->immutableSamplers.empty()) {
    report(dst, Severity::Error, "VUID-VkCopyDescriptorSet-dstBinding-02753",
           "%s: dstBinding %u has immutable samplers and cannot receive sampler descriptors", what, c.dstBinding);
    return false;
  }
  // VUID-VkCopyDescriptorSet-srcSet-00349
  if (src == dst && s.firstRecord < d.firstRecord + c.descriptorCount &&
      d.firstRecord < s.firstRecord + c.descriptorCount) {
    report(dst, Severity::Error, "VUID-VkCopyDescriptorSet-srcSet-00349",
           "%s: source and destination ranges of the same set overlap", what);
    return false;
  }
  if (apply) {
    for (uint32_t i = 0; i < c.descriptorCount; ++i) {
      DescriptorRecord r = src->records()[s.firstRecord + i];
      DescriptorRecord& out = dst->records()[d.firstRecord + i];
      if (!d.binding[i]->immutableSamplers.empty()) r.sampler = out.sampler;
      out = r;
      dst->setWritten(d.firstRecord + i, src->written(s.firstRecord + i));
    }
  }
  return true;
}

}  // namespace

extern "C" {

VKAPI_ATTR void VKAPI_CALL vkrt_UpdateDescriptorSets(VkDevice device, uint32_t descriptorWriteCount,
                                                     const VkWriteDescriptorSet* pDescriptorWrites,
                                                     uint32_t descriptorCopyCount,
                                                     const VkCopyDescriptorSet* pDescriptorCopies) {
  Device* dev = fromHandleUnchecked<Device>(device);
  // Everything is checked first, so that a bad write or copy leaves every set as it was.
  for (uint32_t i = 0; i < descriptorWriteCount; ++i)
    if (!doWrite(dev, pDescriptorWrites[i], i, false)) return;
  for (uint32_t i = 0; i < descriptorCopyCount; ++i)
    if (!doCopy(dev, pDescriptorCopies[i], i, false)) return;
  for (uint32_t i = 0; i < descriptorWriteCount; ++i) doWrite(dev, pDescriptorWrites[i], i, true);
  for (uint32_t i = 0; i < descriptorCopyCount; ++i) doCopy(dev, pDescriptorCopies[i], i, true);
}

}  // extern "C"
