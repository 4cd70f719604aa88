// What compiled code reads of the descriptor sets bound at a bind point: one abi::ResourceSlot per resource a
// compiled shader uses, in the compiler's order. Compute dispatches and ray tracing launches resolve it when
// their command executes (descriptors may change until then: update-after-bind, partially bound sets).
#pragma once

#include <vector>

#include "abi/abi.hpp"
#include "runtime/command_buffer.hpp"
#include "spirv/compiler.hpp"

namespace vkrt {

class BoundResources {
 public:
  // Resolves every resource `shader` uses from the sets bound in `bs`. Dynamic buffers get copies of their
  // records with the bound dynamic offsets added. A resource whose set is not bound, or whose binding the bound
  // set's layout lacks, is reported against `cb` (with `unboundVuid`, naming `command`) and left empty: its
  // accesses read zeros and write nothing. The first used binding with elements never written (outside
  // PARTIALLY_BOUND bindings) is reported once, under VUID-<command>-None-08114.
  void resolve(const spirv::CompiledShader& shader, const BindState& bs, const CommandBuffer* cb, const char* command,
               const char* unboundVuid);

  const abi::ResourceSlot* slots() const { return slots_.data(); }

 private:
  std::vector<abi::ResourceSlot> slots_;
  std::vector<std::vector<abi::DescriptorRecord>> dynamicCopies_;
};

}  // namespace vkrt
