// The calling convention between compiled shaders and the executor (src/exec). No LLVM here.
//
// A compiled compute entry point is `void entry(InvocationContext*)`, run once per invocation (`vkrt_main`),
// or for shaders without barriers once per workgroup (`vkrt_group`: it sets globalId, localId and localIndex
// itself). Everything it reads from outside comes through the context: built-ins, resources, push constants,
// workgroup memory, and the barrier callback. The compiler reads these fields at the offsets asserted below.
#pragma once

#include <cstddef>
#include <cstdint>

#include "runtime/descriptor_set_layout.hpp"

namespace vkrt::spirv {

// One resource the shader uses (a buffer binding, possibly an array of descriptors): the executor resolves it
// per dispatch to the bound set's records for that binding.
struct ResourceSlot {
  const DescriptorRecord* records;  // the binding's element 0 (nullptr when nothing is bound)
  uint64_t count;                   // elements the binding has in the bound set
};

struct InvocationContext {
  uint32_t globalId[4];       // 0   GlobalInvocationId (x, y, z, unused)
  uint32_t localId[4];        // 16  LocalInvocationId
  uint32_t workgroupId[4];    // 32  WorkgroupId
  uint32_t numWorkgroups[4];  // 48  NumWorkgroups
  uint32_t workgroupSize[4];  // 64  WorkgroupSize
  uint32_t localIndex;        // 80  LocalInvocationIndex
  uint32_t pad0[3];
  const ResourceSlot* resources;  // 96   by slot (CompiledShader::resources order)
  const uint8_t* pushConstants;   // 104  kPushConstantBytes bytes
  uint8_t* workgroupMemory;       // 112  CompiledShader::workgroupMemorySize bytes, shared by the workgroup
  void (*barrier)(InvocationContext*);  // 120  OpControlBarrier with Workgroup scope
  void* executor;                       // 128  the executor's per-invocation state
  uint8_t* sink;                        // 136  kSinkBytes bytes: out-of-bounds atomics land here
};

inline constexpr uint32_t kPushConstantBytes = 256;
inline constexpr uint32_t kSinkBytes = 64;

static_assert(offsetof(InvocationContext, globalId) == 0 && offsetof(InvocationContext, localId) == 16 &&
                  offsetof(InvocationContext, workgroupId) == 32 && offsetof(InvocationContext, numWorkgroups) == 48 &&
                  offsetof(InvocationContext, workgroupSize) == 64 && offsetof(InvocationContext, localIndex) == 80 &&
                  offsetof(InvocationContext, resources) == 96 && offsetof(InvocationContext, pushConstants) == 104 &&
                  offsetof(InvocationContext, workgroupMemory) == 112 && offsetof(InvocationContext, barrier) == 120 &&
                  offsetof(InvocationContext, executor) == 128 && offsetof(InvocationContext, sink) == 136,
              "the compiler bakes these offsets into shader code");
static_assert(sizeof(ResourceSlot) == 16, "the compiler bakes the resource slot size into shader code");

using ComputeEntry = void (*)(InvocationContext*);

}  // namespace vkrt::spirv
