// SPIR-V tokens newer than Debian 12's SPIRV-Tools (2023.1) and SPIRV-Headers, and how vkrt gets modules that use
// them through that SPIRV-Tools: its validator and optimizer refuse a module with an opcode, capability or built-in
// they do not know, so vkrt hides them from SPIRV-Tools (and checks the rules they carry itself), and puts them back
// in the optimizer's output before compiling it.
//
// SPV_KHR_ray_tracing_position_fetch (VK_KHR_ray_tracing_position_fetch), values from the SPIR-V registry
// (SPIRV-Headers spirv.core.grammar.json):
//   BuiltIn HitTriangleVertexPositionsKHR (5335): any-hit and closest-hit shaders, an Input array of 3 vec3 of
//     32-bit floats; needs capability RayTracingPositionFetchKHR (5336).
//   OpRayQueryGetIntersectionTriangleVertexPositionsKHR (5340) Result Type, Result, RayQuery, Intersection: an
//     array of 3 vec3 of 32-bit floats; needs capability RayQueryPositionFetchKHR (5391).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace vkrt::spirv {

inline constexpr uint32_t kBuiltInHitTriangleVertexPositionsKHR = 5335;
inline constexpr uint32_t kCapabilityRayTracingPositionFetchKHR = 5336;
inline constexpr uint32_t kOpRayQueryGetIntersectionTriangleVertexPositionsKHR = 5340;
inline constexpr uint32_t kCapabilityRayQueryPositionFetchKHR = 5391;

// For validation: rewrites `words` (a copy; it is not compiled) into a module SPIRV-Tools 2023.1 validates as it
// validates the rest: the two capabilities and the OpExtension "SPV_KHR_ray_tracing_position_fetch" removed, the
// BuiltIn HitTriangleVertexPositionsKHR decorations removed (the variables stay Input variables), and each
// OpRayQueryGetIntersectionTriangleVertexPositionsKHR replaced by an OpUndef of its result type. What the validator
// would have checked of them, vkrt checks here: false, with `error` set, when an instruction uses them without its
// capability, a result or variable type is not (a pointer to Input of) an array of 3 vec3 of 32-bit floats, or the
// Intersection operand is not a 32-bit integer constant 0 or 1. A module without them is left untouched.
bool hideNewerTokensForValidation(std::vector<uint32_t>& words, std::string* error);

// For the optimizer, whose output must keep them: the capabilities and extension removed (nothing after needs them),
// the variables' BuiltIn HitTriangleVertexPositionsKHR changed to BuiltIn Position (recorded in `hidden`), and each
// OpRayQueryGetIntersectionTriangleVertexPositionsKHR changed to OpRayQueryGetIntersectionObjectToWorldKHR, which
// has the same operands (the optimizer checks no result type; ObjectToWorld's own result is a matrix, never an
// array). restoreNewerTokens undoes the last two on the optimizer's output (which keeps global ids; inlining renames
// only function-local ones).
struct HiddenTokens {
  std::vector<uint32_t> positionVariables;  // decorated BuiltIn HitTriangleVertexPositionsKHR
  bool any = false;
};
void hideNewerTokensForOptimizer(std::vector<uint32_t>& words, HiddenTokens* hidden);
void restoreNewerTokens(std::vector<uint32_t>& words, const HiddenTokens& hidden);

}  // namespace vkrt::spirv
