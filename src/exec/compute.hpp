// Running a compute dispatch: workgroups spread over the thread pool; within a workgroup, invocations run one
// after the other on the worker, or, when the shader has workgroup barriers, as fibers (one stack per
// invocation, or per batch of invocations where the shader was compiled SPMD) that the worker switches between at
// each barrier, so that every invocation reaches a barrier before any passes it.
#pragma once

#include <cstdint>

#include "abi/abi.hpp"
#include "exec/supervise.hpp"

namespace vkrt::exec {

// The compiled shader, as far as running it goes (src/spirv's CompiledShader has these fields).
struct ComputeKernel {
  abi::ComputeEntry entry = nullptr;       // vkrt_main, once per invocation: shaders with barriers
  abi::ComputeEntry groupEntry = nullptr;  // vkrt_group, once per workgroup: the others (or null)
  uint32_t localSize[3] = {1, 1, 1};
  uint32_t workgroupMemorySize = 0;  // bytes
  bool usesBarrier = false;
  // A shader with barriers compiled SPMD: groupEntry runs one batch of batchLanes invocations, those from the
  // context's localIndex on (the last batch's tail lanes off), and the workgroup's batches run as fibers.
  uint32_t batchLanes = 0;
};

struct ComputeDispatch {
  ComputeKernel kernel;
  const abi::ResourceSlot* resources = nullptr;    // one per resource the shader uses, in the compiler's order
  const uint8_t* pushConstants = nullptr;          // abi::kPushConstantBytes bytes
  uint32_t base[3] = {0, 0, 0};                    // vkCmdDispatchBase's first workgroup
  uint32_t count[3] = {1, 1, 1};                   // workgroups
  const abi::RayQueryScope* rayQueries = nullptr;  // the ray query runtime (exec/ray_query.hpp), for every invocation
  // The supervision (exec/supervise.hpp): the watchdog's time limit, fault recovery. Null: a job of its own
  // without a time limit. When the job was ended, workgroups not started are skipped; job->abort() says why.
  Job* job = nullptr;
};

// Runs the dispatch to completion. Returns false when fiber stacks could not be allocated (the workgroups that
// needed them did not run).
bool runCompute(const ComputeDispatch& d);

}  // namespace vkrt::exec
