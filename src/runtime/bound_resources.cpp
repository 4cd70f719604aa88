#include "runtime/bound_resources.hpp"

#include <string>

#include "runtime/descriptor_set.hpp"
#include "runtime/report.hpp"

namespace vkrt {

namespace {

// VUID-vkCmdDispatch-None-08114 (and the same rule of every dispatch and trace command): the descriptors a
// pipeline statically uses must be valid. A binding the shader uses counts in full (the elements the shader
// declares, or all of them for a runtime-sized array), except with PARTIALLY_BOUND; a sampler binding with
// immutable samplers is always valid. Reports the first element never written and how many are not; true when
// it reported.
bool reportUnwritten(const DescriptorSet& set, const DescriptorBinding& b, const spirv::ResourceBinding& rb, uint32_t n,
                     const CommandBuffer* cb, const char* command) {
  if (b.flags & VK_DESCRIPTOR_BINDING_PARTIALLY_BOUND_BIT) return false;
  if (b.type == VK_DESCRIPTOR_TYPE_SAMPLER && !b.immutableSamplers.empty()) return false;
  uint32_t used = rb.arraySize && rb.arraySize < n ? rb.arraySize : n;
  uint32_t first = used, missing = 0;
  for (uint32_t e = 0; e < used; ++e) {
    if (set.written(b.offset + e)) continue;
    if (first == used) first = e;
    ++missing;
  }
  if (!missing) return false;
  std::string vuid = std::string("VUID-") + command + "-None-08114";
  if (set.pushedBy) {  // push descriptors: the set is the command buffer's own
    report(cb, Severity::Error, vuid.c_str(),
           "%s: the bound pipeline uses set %u binding %u (%s), but element %u of it was never pushed "
           "(vkCmdPushDescriptorSetKHR; %u of the %u elements it uses are not)",
           command, rb.set, rb.binding, descriptorTypeName(b.type), first, missing, used);
    return true;
  }
  report(cb, Severity::Error, vuid.c_str(),
         "%s: the bound pipeline uses set %u binding %u (%s), but element %u of the bound descriptor set 0x%llx was "
         "never written (%u of the %u elements it uses are not)",
         command, rb.set, rb.binding, descriptorTypeName(b.type), first, (unsigned long long)set.handleValue(), missing,
         used);
  return true;
}

}  // namespace

void BoundResources::resolve(const spirv::CompiledShader& shader, const BindState& bs, const CommandBuffer* cb,
                             const char* command, const char* unboundVuid) {
  slots_.assign(shader.resources.size(), abi::ResourceSlot{nullptr, 0});
  bool reportedUnwritten = false;  // once per command
  dynamicCopies_.clear();
  for (size_t i = 0; i < shader.resources.size(); ++i) {
    const spirv::ResourceBinding& rb = shader.resources[i];
    const DescriptorSet* set = rb.set < 8 ? bs.sets[rb.set] : nullptr;
    const DescriptorBinding* b = set ? set->layout->bindingAt(rb.binding) : nullptr;
    // VUID-vkCmdDispatch-None-02697, VUID-vkCmdTraceRaysKHR-None-02697 (every set the pipeline uses is bound)
    if (!b) {
      report(cb, Severity::Error, unboundVuid,
             "%s: the bound pipeline uses set %u binding %u, but %s; its accesses read zeros and write nothing",
             command, rb.set, rb.binding,
             set ? "the bound set's layout has no such binding" : "no descriptor set is bound there");
      continue;
    }
    uint32_t n = set->elementCount(*b);
    if (!reportedUnwritten) reportedUnwritten = reportUnwritten(*set, *b, rb, n, cb, command);
    // An inline uniform block's record already points into the set's storage with its size as range
    // (DescriptorSet's constructor): the shader reads it as a uniform buffer, bounds-checked against the range.
    const abi::DescriptorRecord* records = set->records() + b->offset;
    if (isDynamicBufferType(b->type)) {
      const std::vector<uint32_t>& offs = bs.dynamicOffsets[rb.set];
      std::vector<abi::DescriptorRecord> copy(records, records + n);
      for (uint32_t e = 0; e < n; ++e) {
        uint32_t k = b->dynamicIndex + e;
        if (copy[e].address && k < offs.size()) copy[e].address += offs[k];
      }
      dynamicCopies_.push_back(std::move(copy));
      records = dynamicCopies_.back().data();
    }
    slots_[i] = {records, n};
  }
}

}  // namespace vkrt
