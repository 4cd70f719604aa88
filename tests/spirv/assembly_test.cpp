// Compiler tests on hand-written SPIR-V assembly (assembled and validated with SPIRV-Tools here): function
// calls with pointer and value parameters kept as separate functions, loop phis, and the unsupported-input
// messages with exact word offsets.
#include <gtest/gtest.h>
#include <spirv-tools/libspirv.hpp>

#include <string>
#include <vector>

#include "spirv/compute_harness.hpp"

namespace vkrt::testing {
namespace {

const char* kHeader = R"(
OpCapability Shader
%@ CAPS
OpMemoryModel Logical GLSL450
OpEntryPoint GLCompute %main "main" %gid %data %priv
OpExecutionMode %main LocalSize 4 1 1
OpDecorate %gid BuiltIn GlobalInvocationId
OpDecorate %rta ArrayStride 4
OpMemberDecorate %buf 0 Offset 0
OpDecorate %buf Block
OpDecorate %data DescriptorSet 0
OpDecorate %data Binding 0
%void = OpTypeVoid
%uint = OpTypeInt 32 0
%float = OpTypeFloat 32
%bool = OpTypeBool
%v3uint = OpTypeVector %uint 3
%ptr_in_v3 = OpTypePointer Input %v3uint
%gid = OpVariable %ptr_in_v3 Input
%rta = OpTypeRuntimeArray %uint
%buf = OpTypeStruct %rta
%ptr_sb_buf = OpTypePointer StorageBuffer %buf
%data = OpVariable %ptr_sb_buf StorageBuffer
%ptr_sb_uint = OpTypePointer StorageBuffer %uint
%ptr_fn_uint = OpTypePointer Function %uint
%uint_0 = OpConstant %uint 0
%uint_1 = OpConstant %uint 1
%uint_3 = OpConstant %uint 3
%ptr_pr_uint = OpTypePointer Private %uint
%priv = OpVariable %ptr_pr_uint Private %uint_3
%float_1 = OpConstant %float 1.5
%fnvoid = OpTypeFunction %void
%fn_square = OpTypeFunction %uint %uint
%fn_addto = OpTypeFunction %void %ptr_fn_uint %uint
)";

// square(x) = x * x * priv (a Private variable initialized to 3); addTo(p, v): *p += v; main: data[g] = sum
// of square(i) for i in 0..g, through a loop with a phi, the accumulator passed by pointer.
const char* kBody = R"(
%square = OpFunction %uint None %fn_square
%x = OpFunctionParameter %uint
%sq_entry = OpLabel
%sq = OpIMul %uint %x %x
%pv = OpLoad %uint %priv
%sq3 = OpIMul %uint %sq %pv
OpReturnValue %sq3
OpFunctionEnd
%addto = OpFunction %void None %fn_addto
%p = OpFunctionParameter %ptr_fn_uint
%v = OpFunctionParameter %uint
%at_entry = OpLabel
%old = OpLoad %uint %p
%new = OpIAdd %uint %old %v
OpStore %p %new
OpReturn
OpFunctionEnd
%main = OpFunction %void None %fnvoid
%entry = OpLabel
%acc = OpVariable %ptr_fn_uint Function
OpStore %acc %uint_0
%g = OpLoad %v3uint %gid
%gx = OpCompositeExtract %uint %g 0
%n = OpIAdd %uint %gx %uint_1
OpBranch %header
%header = OpLabel
%i = OpPhi %uint %uint_0 %entry %inext %cont
%cond = OpULessThan %bool %i %n
OpLoopMerge %merge %cont None
OpBranchConditional %cond %body %merge
%body = OpLabel
%s = OpFunctionCall %uint %square %i
%r = OpFunctionCall %void %addto %acc %s
%@ EXTRA
OpBranch %cont
%cont = OpLabel
%inext = OpIAdd %uint %i %uint_1
OpBranch %header
%merge = OpLabel
%res = OpLoad %uint %acc
%dst = OpAccessChain %ptr_sb_uint %data %uint_0 %gx
OpStore %dst %res
OpReturn
OpFunctionEnd
)";

std::string replace(std::string s, const std::string& what, const std::string& with) {
  size_t at = s.find(what);
  if (at != std::string::npos) s.replace(at, what.size(), with);
  return s;
}

std::vector<uint32_t> assemble(const std::string& caps, const std::string& extra) {
  std::string text = replace(kHeader, "%@ CAPS", caps) + replace(kBody, "%@ EXTRA", extra);
  spvtools::SpirvTools tools(SPV_ENV_VULKAN_1_3);
  std::string diag;
  tools.SetMessageConsumer([&](spv_message_level_t, const char*, const spv_position_t& pos, const char* m) {
    diag += std::to_string(pos.index) + ": " + m + "\n";
  });
  std::vector<uint32_t> words;
  EXPECT_TRUE(tools.Assemble(text, &words)) << diag;
  EXPECT_TRUE(tools.Validate(words)) << diag;
  return words;
}

// Word offset of the first instruction with opcode `op`.
uint32_t offsetOf(const std::vector<uint32_t>& w, spv::Op op) {
  for (size_t i = 5; i < w.size(); i += w[i] >> 16) {
    if ((w[i] & 0xffff) == uint32_t(op)) return uint32_t(i);
    if ((w[i] >> 16) == 0) break;
  }
  return 0;
}

std::shared_ptr<spirv::CompiledShader> compileWords(const std::vector<uint32_t>& w, bool inlineFunctions,
                                                    std::string* error) {
  spirv::CompileRequest r;
  r.words = w.data();
  r.wordCount = w.size();
  r.inlineFunctions = inlineFunctions;
  return spirv::compile(r, error);
}

TEST(SpirvAssembly, FunctionCallsWithPointerParametersAndLoopPhis) {
  std::vector<uint32_t> words = assemble("", "");
  for (bool inl : {false, true}) {
    ComputeHarness h;
    h.shader = compileWords(words, inl, &h.error);
    ASSERT_NE(h.shader, nullptr) << h.error;
    h.zeroBuffer<uint32_t>(0, 12);
    ASSERT_TRUE(h.run(3));
    auto r = h.get<uint32_t>(0);
    for (uint32_t g = 0; g < 12; ++g)
      EXPECT_EQ(r[g], 3 * (g * (g + 1) * (2 * g + 1) / 6)) << "inlined " << inl << ", invocation " << g;
  }
}

TEST(SpirvAssembly, UnsupportedInstructionNamesItsWordOffset) {
  // Subgroup shuffles are not compiled (the basic, vote and ballot operations are; the scope constant 3 is
  // Subgroup).
  std::vector<uint32_t> words =
      assemble("OpCapability GroupNonUniformShuffle", "%q = OpGroupNonUniformShuffle %uint %uint_3 %uint_3 %uint_3");
  uint32_t at = offsetOf(words, spv::OpGroupNonUniformShuffle);
  ASSERT_NE(at, 0u);
  std::string error;
  EXPECT_EQ(compileWords(words, true, &error), nullptr);
  EXPECT_EQ(error, "unsupported instruction OpGroupNonUniformShuffle at word " + std::to_string(at));
}

TEST(SpirvAssembly, UnsupportedCapabilityIsNamed) {
  // 16-bit Input/Output variables: compute has no user interface variables to give them.
  std::vector<uint32_t> words = assemble("OpCapability StorageInputOutput16", "");
  std::string error;
  EXPECT_EQ(compileWords(words, true, &error), nullptr);
  EXPECT_NE(error.find("unsupported capability 4436 (OpCapability at word"), std::string::npos) << error;
}

}  // namespace
}  // namespace vkrt::testing
