// Running a compute dispatch: workgroups spread over the thread pool; within a workgroup, invocations run one
// after the other on the worker, or, when the shader has workgroup barriers, as fibers (one stack per
// invocation) that the worker switches between at each barrier, so that every invocation reaches a barrier
// before any passes it.
#pragma once

#include <cstdint>

#include "spirv/compiler.hpp"

namespace vkrt::exec {

struct ComputeDispatch {
  const spirv::CompiledShader* shader = nullptr;
  const spirv::ResourceSlot* resources = nullptr;  // shader->resources.size() entries
  const uint8_t* pushConstants = nullptr;          // spirv::kPushConstantBytes bytes
  uint32_t base[3] = {0, 0, 0};                    // vkCmdDispatchBase's first workgroup
  uint32_t count[3] = {1, 1, 1};                   // workgroups
};

// Runs the dispatch to completion. Returns false when fiber stacks could not be allocated (the workgroups that
// needed them did not run).
bool runCompute(const ComputeDispatch& d);

}  // namespace vkrt::exec
