// Descriptor arrays indexed at run time, below the Vulkan API: per-invocation (non-uniform) indices into a
// runtime-sized storage-buffer array and a uniform-buffer array (GLSL, GL_EXT_nonuniform_qualifier), and the
// *ArrayDynamicIndexing capabilities on a dynamically uniform index (assembly).
#include <gtest/gtest.h>
#include <spirv-tools/libspirv.hpp>

#include <string>
#include <vector>

#include "compute_nonuniform_buffers.comp.spv.h"
#include "spirv/compute_harness.hpp"
#include "spirv/nonuniform_buffers_reference.hpp"

namespace vkrt::testing {
namespace {

TEST(SpirvDescriptorIndexing, NonUniformStorageAndUniformBufferArrays) {
  ComputeHarness h;
  ASSERT_TRUE(h.compile(kSpv_compute_nonuniform_buffers_comp)) << h.error;
  NonUniformBuffers ref;
  constexpr uint32_t kN = NonUniformBuffers::kN;
  for (uint32_t k = 0; k < NonUniformBuffers::kBuffers; ++k) h.setBuffer(100 + k, ref.data[k]);
  h.arrays[0] = {100, 101, 102, 103, 104};
  for (uint32_t k = 0; k < 3; ++k) h.setBuffer(200 + k, std::vector<uint32_t>(ref.params[k], ref.params[k] + 4));
  h.arrays[1] = {200, 201, 202};
  h.zeroBuffer<uint32_t>(2, kN * 4);
  ASSERT_TRUE(h.run(kN / 8));
  std::vector<std::vector<uint32_t>> after;
  for (uint32_t k = 0; k < NonUniformBuffers::kBuffers; ++k) after.push_back(h.get<uint32_t>(100 + k));
  ref.expect(h.get<uint32_t>(2).data(), [&](uint32_t k) { return after[k].data(); });
}

// Element `sel` (read from a uniform buffer at run time: dynamically uniform) of a storage-buffer array, with
// the four core dynamic-indexing capabilities declared.
const char* kDynamicIndexing = R"(
OpCapability Shader
OpCapability UniformBufferArrayDynamicIndexing
OpCapability SampledImageArrayDynamicIndexing
OpCapability StorageBufferArrayDynamicIndexing
OpCapability StorageImageArrayDynamicIndexing
OpMemoryModel Logical GLSL450
OpEntryPoint GLCompute %main "main" %gid %arr %sel
OpExecutionMode %main LocalSize 4 1 1
OpDecorate %gid BuiltIn GlobalInvocationId
OpDecorate %rta ArrayStride 4
OpMemberDecorate %buf 0 Offset 0
OpDecorate %buf Block
OpMemberDecorate %selbuf 0 Offset 0
OpDecorate %selbuf Block
OpDecorate %arr DescriptorSet 0
OpDecorate %arr Binding 0
OpDecorate %sel DescriptorSet 0
OpDecorate %sel Binding 1
%void = OpTypeVoid
%fnvoid = OpTypeFunction %void
%uint = OpTypeInt 32 0
%v3uint = OpTypeVector %uint 3
%u0 = OpConstant %uint 0
%u3 = OpConstant %uint 3
%u100 = OpConstant %uint 100
%rta = OpTypeRuntimeArray %uint
%buf = OpTypeStruct %rta
%arrty = OpTypeArray %buf %u3
%selbuf = OpTypeStruct %uint
%p_arr = OpTypePointer StorageBuffer %arrty
%p_sel = OpTypePointer Uniform %selbuf
%p_u = OpTypePointer StorageBuffer %uint
%p_usel = OpTypePointer Uniform %uint
%p_in = OpTypePointer Input %v3uint
%gid = OpVariable %p_in Input
%arr = OpVariable %p_arr StorageBuffer
%sel = OpVariable %p_sel Uniform
%main = OpFunction %void None %fnvoid
%entry = OpLabel
%g = OpLoad %v3uint %gid
%x = OpCompositeExtract %uint %g 0
%ps = OpAccessChain %p_usel %sel %u0
%s = OpLoad %uint %ps
%pe = OpAccessChain %p_u %arr %s %u0 %x
%v = OpLoad %uint %pe
%add = OpIMul %uint %s %u100
%nv = OpIAdd %uint %v %add
OpStore %pe %nv
OpReturn
OpFunctionEnd
)";

TEST(SpirvDescriptorIndexing, DynamicIndexingCapabilities) {
  spvtools::SpirvTools tools(SPV_ENV_VULKAN_1_3);
  std::string diag;
  tools.SetMessageConsumer([&](spv_message_level_t, const char*, const spv_position_t& pos, const char* m) {
    diag += std::to_string(pos.index) + ": " + m + "\n";
  });
  std::vector<uint32_t> words;
  ASSERT_TRUE(tools.Assemble(kDynamicIndexing, &words)) << diag;
  ASSERT_TRUE(tools.Validate(words)) << diag;
  for (uint32_t sel = 0; sel < 3; ++sel) {
    ComputeHarness h;
    spirv::CompileRequest r;
    r.words = words.data();
    r.wordCount = words.size();
    h.shader = spirv::compile(r, &h.error);
    ASSERT_NE(h.shader, nullptr) << h.error;
    for (uint32_t k = 0; k < 3; ++k) h.setBuffer(10 + k, std::vector<uint32_t>(4, k + 1));
    h.arrays[0] = {10, 11, 12};
    h.setBuffer(1, std::vector<uint32_t>{sel, 0, 0, 0});
    ASSERT_TRUE(h.run(1));
    for (uint32_t k = 0; k < 3; ++k) {
      auto got = h.get<uint32_t>(10 + k);
      for (uint32_t j = 0; j < 4; ++j)
        EXPECT_EQ(got[j], k == sel ? k + 1 + 100 * sel : k + 1) << "sel " << sel << " buffer " << k;
    }
  }
}

}  // namespace
}  // namespace vkrt::testing
