// SPIR-V of SPV_KHR_ray_tracing_position_fetch through Debian's SPIRV-Tools (src/spirv/newer_tokens.hpp): modules
// that use it correctly validate (runtime::validateSpirv, what vkCreateShaderModule runs), the rules vkrt checks in
// the validator's place reject misuse, and the optimizer's hiding is undone exactly.
#include <gtest/gtest.h>

#include <spirv-tools/libspirv.hpp>
#include <spirv/unified1/spirv.hpp>

#include <string>
#include <vector>

#include "position_fetch.rchit.newer.spvasm.spv.h"
#include "position_fetch_query.comp.newer.spvasm.spv.h"
#include "runtime/shader_module.hpp"
#include "spirv/newer_tokens.hpp"

namespace vkrt {
namespace {

std::vector<uint32_t> words(const uint32_t* w, size_t bytes) { return std::vector<uint32_t>(w, w + bytes / 4); }
std::vector<uint32_t> chit() {
  return words(kSpv_position_fetch_rchit_newer_spvasm, sizeof kSpv_position_fetch_rchit_newer_spvasm);
}
std::vector<uint32_t> query() {
  return words(kSpv_position_fetch_query_comp_newer_spvasm, sizeof kSpv_position_fetch_query_comp_newer_spvasm);
}

// The word index of each instruction with opcode `op`.
std::vector<size_t> find(const std::vector<uint32_t>& w, uint32_t op) {
  std::vector<size_t> at;
  for (size_t i = 5; i < w.size() && (w[i] >> 16); i += w[i] >> 16)
    if ((w[i] & 0xffff) == op) at.push_back(i);
  return at;
}

// `w` without the instruction at word `at`.
std::vector<uint32_t> without(std::vector<uint32_t> w, size_t at) {
  w.erase(w.begin() + at, w.begin() + at + (w[at] >> 16));
  return w;
}

size_t capabilityAt(const std::vector<uint32_t>& w, uint32_t cap) {
  for (size_t at : find(w, spv::OpCapability))
    if (w[at + 1] == cap) return at;
  return 0;
}

bool valid(const std::vector<uint32_t>& w, std::string* message) { return validateSpirv(w.data(), w.size(), message); }

TEST(PositionFetchValidation, CorrectModulesValidateAndSpirvToolsAloneRefusesThem) {
  for (const std::vector<uint32_t>& w : {chit(), query()}) {
    std::string message;
    EXPECT_TRUE(valid(w, &message)) << message;
    spvtools::SpirvTools tools(SPV_ENV_VULKAN_1_3);
    tools.SetMessageConsumer([](spv_message_level_t, const char*, const spv_position_t&, const char*) {});
    EXPECT_FALSE(tools.Validate(w)) << "SPIRV-Tools now knows the tokens: newer_tokens.hpp may be retired";
  }
}

TEST(PositionFetchValidation, TheBuiltInWithoutItsCapabilityIsRefused) {
  std::vector<uint32_t> w = chit();
  const size_t at = capabilityAt(w, spirv::kCapabilityRayTracingPositionFetchKHR);
  ASSERT_NE(at, 0u);
  std::string message;
  EXPECT_FALSE(valid(without(w, at), &message));
  EXPECT_NE(message.find("RayTracingPositionFetchKHR"), std::string::npos) << message;
}

TEST(PositionFetchValidation, TheInstructionWithoutItsCapabilityIsRefused) {
  std::vector<uint32_t> w = query();
  const size_t at = capabilityAt(w, spirv::kCapabilityRayQueryPositionFetchKHR);
  ASSERT_NE(at, 0u);
  std::string message;
  EXPECT_FALSE(valid(without(w, at), &message));
  EXPECT_NE(message.find("RayQueryPositionFetchKHR"), std::string::npos) << message;
}

TEST(PositionFetchValidation, AWrongResultTypeOrIntersectionIsRefused) {
  const std::vector<uint32_t> w = query();
  const std::vector<size_t> ops = find(w, spirv::kOpRayQueryGetIntersectionTriangleVertexPositionsKHR);
  ASSERT_EQ(ops.size(), 2u);
  const std::vector<size_t> floats = find(w, spv::OpTypeFloat);
  ASSERT_FALSE(floats.empty());
  std::vector<uint32_t> wrongType = w;
  wrongType[ops[0] + 1] = w[floats[0] + 1];  // Result Type: float
  std::string message;
  EXPECT_FALSE(valid(wrongType, &message));
  EXPECT_NE(message.find("Result Type"), std::string::npos) << message;
  std::vector<uint32_t> wrongIntersection = w;
  wrongIntersection[ops[0] + 4] = w[ops[0] + 2];  // Intersection: not a constant
  message.clear();
  EXPECT_FALSE(valid(wrongIntersection, &message));
  EXPECT_NE(message.find("Intersection"), std::string::npos) << message;
}

TEST(PositionFetchValidation, TheBuiltInOnAnOutputOrWronglyTypedVariableIsRefused) {
  std::vector<uint32_t> w = chit();
  // The payload variable (IncomingRayPayloadKHR, a struct) decorated with the built-in instead.
  size_t decoration = 0;
  for (size_t at : find(w, spv::OpDecorate))
    if (w[at + 2] == spv::DecorationBuiltIn && w[at + 3] == spirv::kBuiltInHitTriangleVertexPositionsKHR)
      decoration = at;
  ASSERT_NE(decoration, 0u);
  uint32_t payload = 0;
  for (size_t at : find(w, spv::OpVariable))
    if (w[at + 3] == spv::StorageClassIncomingRayPayloadKHR) payload = w[at + 2];
  ASSERT_NE(payload, 0u);
  w[decoration + 1] = payload;
  std::string message;
  EXPECT_FALSE(valid(w, &message));
  EXPECT_NE(message.find("HitTriangleVertexPositionsKHR"), std::string::npos) << message;
}

TEST(PositionFetchValidation, OptimizerHidingIsUndoneExactly) {
  for (const std::vector<uint32_t>& original : {chit(), query()}) {
    std::vector<uint32_t> w = original;
    spirv::HiddenTokens hidden;
    spirv::hideNewerTokensForOptimizer(w, &hidden);
    ASSERT_TRUE(hidden.any);
    EXPECT_TRUE(find(w, spirv::kOpRayQueryGetIntersectionTriangleVertexPositionsKHR).empty());
    EXPECT_EQ(capabilityAt(w, spirv::kCapabilityRayTracingPositionFetchKHR), 0u);
    EXPECT_EQ(capabilityAt(w, spirv::kCapabilityRayQueryPositionFetchKHR), 0u);
    spirv::restoreNewerTokens(w, hidden);
    // The original without its position-fetch capabilities and extension.
    std::vector<uint32_t> expected = original;
    for (uint32_t cap : {spirv::kCapabilityRayTracingPositionFetchKHR, spirv::kCapabilityRayQueryPositionFetchKHR})
      if (size_t at = capabilityAt(expected, cap)) expected = without(expected, at);
    for (size_t at : find(expected, spv::OpExtension))
      if (std::string(reinterpret_cast<const char*>(&expected[at + 1])) == "SPV_KHR_ray_tracing_position_fetch") {
        expected = without(expected, at);
        break;
      }
    EXPECT_EQ(w, expected);
  }
}

TEST(PositionFetchValidation, ModulesWithoutTheTokensAreUntouched) {
  std::vector<uint32_t> w = chit();
  // Remove every position-fetch token: the builtin's decoration, capability and extension.
  std::vector<uint32_t> plain = w;
  spirv::HiddenTokens hidden;
  std::string error;
  ASSERT_TRUE(spirv::hideNewerTokensForValidation(plain, &error)) << error;
  std::vector<uint32_t> again = plain;
  EXPECT_TRUE(spirv::hideNewerTokensForValidation(again, &error));
  EXPECT_EQ(again, plain);
  spirv::hideNewerTokensForOptimizer(again, &hidden);
  EXPECT_FALSE(hidden.any);
  EXPECT_EQ(again, plain);
}

}  // namespace
}  // namespace vkrt
