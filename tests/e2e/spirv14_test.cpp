// VK_KHR_spirv_1_4 enabled by name, as applications written for Vulkan 1.1 do (ten of eleven public ray tracing
// samples; the CTS's ray_tracing_pipeline groups): SPIR-V 1.4 modules run, a compute module in hand-written
// assembly that uses what 1.4 added (tests/shaders/compute_spirv14.spv14.spvasm) and the basic trace's ray tracing
// shaders compiled by glslc for Vulkan 1.1 with SPIR-V 1.4.
#include <cstring>
#include <vector>

#include "compute_spirv14.spv14.spvasm.spv.h"
#include "e2e/compute_pipeline_helpers.hpp"
#include "e2e/trace_fixture.hpp"
#include "trace_chit.rchit.spv14.spv.h"
#include "trace_miss.rmiss.spv14.spv.h"
#include "trace_raygen.rgen.spv14.spv.h"

namespace vkrt::test {
namespace {

constexpr uint32_t kSpirv14 = 0x00010400;  // the module header's version word

class Spirv14ComputeTest : public VulkanTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o;
    o.deviceExtensions = {VK_KHR_SPIRV_1_4_EXTENSION_NAME, VK_KHR_SHADER_FLOAT_CONTROLS_EXTENSION_NAME};
    return o;
  }
};

TEST_F(Spirv14ComputeTest, CopyLogicalSelectOfStructsPointerComparisonsAndTwoMemoryOperands) {
  ASSERT_EQ(kSpv_compute_spirv14_spv14_spvasm[1], kSpirv14);
  ComputePipeline p =
      makeComputePipeline(device, kSpv_compute_spirv14_spv14_spvasm, sizeof kSpv_compute_spirv14_spv14_spvasm,
                          {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER});
  ASSERT_EQ(p.result, VK_SUCCESS);
  constexpr uint32_t kN = 16;
  HostBuffer in = createHostBuffer(kN * 8, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  HostBuffer out = createHostBuffer(kN * 8, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  auto* pairs = static_cast<uint32_t*>(in.data);
  for (uint32_t g = 0; g < kN; ++g) {
    pairs[2 * g] = 10 * g + 1;    // a
    pairs[2 * g + 1] = 1000 + g;  // b
  }
  std::memset(out.data, 0xee, out.size);
  VkDescriptorBufferInfo bi[2] = {{in.buffer, 0, VK_WHOLE_SIZE}, {out.buffer, 0, VK_WHOLE_SIZE}};
  VkWriteDescriptorSet w[2] = {{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET}, {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET}};
  for (uint32_t i = 0; i < 2; ++i) {
    w[i].dstSet = p.set;
    w[i].dstBinding = i;
    w[i].descriptorCount = 1;
    w[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    w[i].pBufferInfo = &bi[i];
  }
  vkUpdateDescriptorSets(device, 2, w, 0, nullptr);
  VkCommandBuffer cb = beginOneTime();
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
  vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout, 0, 1, &p.set, 0, nullptr);
  vkCmdDispatch(cb, kN / 8, 1, 1);
  VkMemoryBarrier mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  mb.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
  mb.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &mb, 0, nullptr, 0,
                       nullptr);
  submitAndWait(cb);
  const auto* o = static_cast<const uint32_t*>(out.data);
  for (uint32_t g = 0; g < kN; ++g) {
    const uint32_t a = 10 * g + 1, b = 1000 + g;
    EXPECT_EQ(o[2 * g], g % 2 ? b + 4 * a : a + 4 * b) << "invocation " << g << ": OpSelect of structs, the loop";
    EXPECT_EQ(o[2 * g + 1], a + (g == 3 ? 1000000 : 0) + (g != 5 ? 20000 : 0))
        << "invocation " << g << ": OpCopyLogical, then OpCopyMemory; OpPtrEqual, OpPtrNotEqual";
  }
  destroy(in);
  destroy(out);
  destroyComputePipeline(device, p);
}

// The basic trace (tests/e2e/trace_test.cpp: triangles through instances with transforms, custom indices and SBT
// offsets) with its raygen, miss and closest-hit shaders as SPIR-V 1.4 modules.
class Spirv14TraceTest : public TraceTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o = TraceTest::options();
    o.deviceExtensions.push_back(VK_KHR_SPIRV_1_4_EXTENSION_NAME);
    o.deviceExtensions.push_back(VK_KHR_SHADER_FLOAT_CONTROLS_EXTENSION_NAME);
    return o;
  }
  void SetUp() override {
    TraceTest::SetUp();
    if (HasFatalFailure() || !device) return;
    rgen = module(kSpv14_trace_raygen_rgen, sizeof kSpv14_trace_raygen_rgen);
    tmiss = module(kSpv14_trace_miss_rmiss, sizeof kSpv14_trace_miss_rmiss);
    tchit = module(kSpv14_trace_chit_rchit, sizeof kSpv14_trace_chit_rchit);
  }
};

TEST_F(Spirv14TraceTest, BasicSceneFromSpirv14Modules) {
  for (const uint32_t* words : {kSpv14_trace_raygen_rgen, kSpv14_trace_miss_rmiss, kSpv14_trace_chit_rchit})
    ASSERT_EQ(words[1], kSpirv14);
  VkAccelerationStructureKHR top = basicScene();
  Desc d = basicDesc();
  VkPipeline p = make(d);
  ASSERT_NE(p, VK_NULL_HANDLE);
  Sbt s = sbt(p, 3, {0}, {{1, {7}}}, {{2, {100}}, {2, {101}}});
  expectBasicScene(trace(p, s, top, 8, 8), 8);
}

}  // namespace
}  // namespace vkrt::test
