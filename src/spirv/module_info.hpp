// A small SPIR-V reader for what pipeline creation needs before a shader compiler exists: the entry points,
// their execution models, the ray tracing interface variables of each entry point with their sizes, whether
// the entry point's call tree makes a traceRayEXT / executeCallableEXT call, and an estimate of the
// Function-storage locals live across such a call.
//
// Stack size of an entry point (what vkGetRayTracingShaderGroupStackSizeKHR reports for it), in bytes:
//   0                                   when its call tree contains no OpTraceRayKHR / OpExecuteCallableKHR
//                                       (nothing of the shader is live while another shader runs: NVIDIA
//                                       reports 0 for such shaders too);
//   otherwise align16( payloadBytes     sum of its RayPayloadKHR variables (the outgoing payloads)
//                    + callableBytes    sum of its CallableDataKHR variables (the outgoing callable data)
//                    + hitAttrBytes     sum of its HitAttributeKHR variables: the attributes of the hit being
//                                       shaded live in the traversal state, which a nested traceRayEXT
//                                       reuses, so a shader that calls keeps its own copy across the call
//                    + localBytes       sum of the Function-storage variables of every function in its call
//                                       tree: an upper bound of the locals live across the call
//                    + kCallFrameBytes) the return record of the call (resume point and ray state).
// Incoming payload and incoming callable data belong to the caller's frame and are not counted. The figure is
// derived from the SPIR-V alone; the shader compiler (a later issue) will refine it with real liveness
// (locals actually live across the call, spilled registers).
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace vkrt::spirv {

// SPIR-V storage classes and execution models used here (values from the SPIR-V registry).
enum : uint32_t {
  kStorageFunction = 7,
  kStorageCallableData = 5328,
  kStorageIncomingCallableData = 5329,
  kStorageRayPayload = 5338,
  kStorageHitAttribute = 5339,
  kStorageIncomingRayPayload = 5342,
  kStorageShaderRecordBuffer = 5343,
};
enum : uint32_t {
  kModelRayGeneration = 5313,
  kModelIntersection = 5314,
  kModelAnyHit = 5315,
  kModelClosestHit = 5316,
  kModelMiss = 5317,
  kModelCallable = 5318,
};

constexpr uint32_t kCallFrameBytes = 16;

struct InterfaceVariable {
  uint32_t id = 0;
  uint32_t storageClass = 0;
  uint32_t bytes = 0;  // size of the pointee type (arrays of runtime length count 0)
};

struct EntryPointInfo {
  std::string name;
  uint32_t executionModel = 0;
  uint32_t functionId = 0;
  std::vector<InterfaceVariable> variables;  // the ray tracing storage classes above only
  bool tracesRays = false;                   // OpTraceRayKHR (or the NV/motion forms) in the call tree
  bool executesCallables = false;            // OpExecuteCallableKHR (or NV) in the call tree
  uint32_t localBytes = 0;                   // Function-storage variables of every function in the call tree

  uint32_t bytesIn(uint32_t storageClass) const;
  // The largest single variable of `storageClass` (what VkRayTracingPipelineInterfaceCreateInfoKHR's
  // maxPipelineRayPayloadSize / maxPipelineRayHitAttributeSize must cover).
  uint32_t largestIn(uint32_t storageClass) const;
  // The largest RayPayloadKHR or IncomingRayPayloadKHR variable.
  uint32_t payloadSize() const { return std::max(largestIn(kStorageRayPayload), largestIn(kStorageIncomingRayPayload)); }
  uint32_t hitAttributeSize() const { return largestIn(kStorageHitAttribute); }
  // The stack-size figure documented at the top of this file.
  uint32_t stackSize() const;
};

struct ModuleInfo {
  uint32_t version = 0;  // SPIR-V version word
  std::vector<EntryPointInfo> entryPoints;

  // The entry point named `name` with execution model `model`, or nullptr.
  const EntryPointInfo* find(const char* name, uint32_t model) const;
};

// Parses `words` (assumed valid: vkCreateShaderModule validated it). Returns false, with `error` set, for a
// stream that is too short or malformed enough that the reader cannot walk it.
bool analyzeModule(const uint32_t* words, size_t wordCount, ModuleInfo& out, std::string* error = nullptr);

// The SPIR-V execution model of a ray tracing VkShaderStageFlagBits value; 0 for other stages.
uint32_t executionModelForStage(uint32_t vkStage);

}  // namespace vkrt::spirv
