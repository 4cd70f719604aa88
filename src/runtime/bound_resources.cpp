#include "runtime/bound_resources.hpp"

#include "runtime/descriptor_set.hpp"
#include "runtime/report.hpp"

namespace vkrt {

void BoundResources::resolve(const spirv::CompiledShader& shader, const BindState& bs, const CommandBuffer* cb,
                             const char* command, const char* unboundVuid) {
  slots_.assign(shader.resources.size(), abi::ResourceSlot{nullptr, 0});
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
