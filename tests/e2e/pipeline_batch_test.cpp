// The batch rule of vkCreateComputePipelines (runtime/pipeline.hpp's createPipelineBatch, which
// vkCreateGraphicsPipelines shares; spec "Multiple Pipeline Creation"): a VK_PIPELINE_COMPILE_REQUIRED pipeline is
// VK_NULL_HANDLE and the batch goes on, unless it has EARLY_RETURN_ON_FAILURE, which leaves the later ones
// VK_NULL_HANDLE too; a misuse in any create info undoes the whole call; pipelineCache must be live.
#include <algorithm>
#include <cstdint>

#include "compute_fill.comp.spv.h"
#include "compute_sum.comp.spv.h"
#include "e2e/compute_pipeline_helpers.hpp"
#include "e2e/fixture.hpp"

namespace vkrt::test {
namespace {

constexpr VkPipelineCreateFlags kFailOnCompile = VK_PIPELINE_CREATE_FAIL_ON_PIPELINE_COMPILE_REQUIRED_BIT;
constexpr VkPipelineCreateFlags kEarlyReturn = VK_PIPELINE_CREATE_EARLY_RETURN_ON_FAILURE_BIT;

class PipelineBatchTest : public VulkanTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o;
    o.validation = false;  // vkrt's own reports are asserted
    o.pipelineCreationCacheControl = true;
    return o;
  }
  static VkComputePipelineCreateInfo info(const ComputePipeline& p, VkPipelineCreateFlags flags) {
    VkComputePipelineCreateInfo ci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    ci.flags = flags;
    ci.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    ci.stage.module = p.module;
    ci.stage.pName = "main";
    ci.layout = p.layout;
    return ci;
  }
  void release(ComputePipeline& p) {
    vkDestroyPipeline(device, p.pipeline, nullptr);
    vkDestroyShaderModule(device, p.module, nullptr);
    vkDestroyDescriptorPool(device, p.pool, nullptr);
    vkDestroyPipelineLayout(device, p.layout, nullptr);
    vkDestroyDescriptorSetLayout(device, p.setLayout, nullptr);
  }
  // A value no live pipeline has, to see that the call writes every output.
  static VkPipeline stale() { return reinterpret_cast<VkPipeline>(uintptr_t(0x5a5a0)); }
};

TEST_F(PipelineBatchTest, CompileRequiredLeavesAHoleUnlessEarlyReturnStopsTheBatch) {
  if (!onVkrt()) GTEST_SKIP() << "another driver may have the shader in caches of its own";
  // compute_fill is not compiled on this test's device: asked not to compile, it is refused.
  ComputePipeline fill = makeComputePipeline(device, kSpv_compute_fill_comp, sizeof kSpv_compute_fill_comp,
                                             {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}, 8, nullptr, kFailOnCompile);
  ASSERT_EQ(fill.result, VK_PIPELINE_COMPILE_REQUIRED);
  ComputePipeline sum = makeComputePipeline(device, kSpv_compute_sum_comp, sizeof kSpv_compute_sum_comp,
                                            {VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER});
  ASSERT_EQ(sum.result, VK_SUCCESS);

  VkComputePipelineCreateInfo ci[3] = {info(sum, 0), info(fill, kFailOnCompile), info(sum, 0)};
  VkPipeline out[3] = {stale(), stale(), stale()};
  EXPECT_EQ(vkCreateComputePipelines(device, VK_NULL_HANDLE, 3, ci, nullptr, out), VK_PIPELINE_COMPILE_REQUIRED);
  EXPECT_NE(out[0], VK_NULL_HANDLE);
  EXPECT_EQ(out[1], VK_NULL_HANDLE);
  EXPECT_NE(out[2], VK_NULL_HANDLE);
  EXPECT_NE(out[2], stale());
  for (VkPipeline p : out) vkDestroyPipeline(device, p, nullptr);

  ci[1].flags = kFailOnCompile | kEarlyReturn;
  std::fill(std::begin(out), std::end(out), stale());
  EXPECT_EQ(vkCreateComputePipelines(device, VK_NULL_HANDLE, 3, ci, nullptr, out), VK_PIPELINE_COMPILE_REQUIRED);
  EXPECT_NE(out[0], VK_NULL_HANDLE);
  EXPECT_NE(out[0], stale());
  EXPECT_EQ(out[1], VK_NULL_HANDLE);
  EXPECT_EQ(out[2], VK_NULL_HANDLE);  // not created
  vkDestroyPipeline(device, out[0], nullptr);
  EXPECT_TRUE(vkrtMessages().empty());
  release(fill);
  release(sum);
}

TEST_F(PipelineBatchTest, AMisuseUndoesTheWholeBatch) {
  ComputePipeline sum = makeComputePipeline(device, kSpv_compute_sum_comp, sizeof kSpv_compute_sum_comp,
                                            {VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER});
  ASSERT_EQ(sum.result, VK_SUCCESS);
  VkComputePipelineCreateInfo ci[3] = {info(sum, 0), info(sum, 0), info(sum, 0)};
  ci[2].stage.stage = VK_SHADER_STAGE_VERTEX_BIT;
  VkPipeline out[3] = {stale(), stale(), stale()};
  EXPECT_EQ(vkCreateComputePipelines(device, VK_NULL_HANDLE, 3, ci, nullptr, out), VK_ERROR_VALIDATION_FAILED_EXT);
  for (VkPipeline p : out) EXPECT_EQ(p, VK_NULL_HANDLE);  // the first two were made, then destroyed
  expectVkrtMessage("VUID-VkComputePipelineCreateInfo-stage-00701");

  ci[2].stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  EXPECT_EQ(vkCreateComputePipelines(device, VK_NULL_HANDLE, 3, ci, nullptr, out), VK_SUCCESS);
  for (VkPipeline p : out) {
    EXPECT_NE(p, VK_NULL_HANDLE);
    vkDestroyPipeline(device, p, nullptr);
  }
  EXPECT_TRUE(vkrtMessages().empty());
  release(sum);
}

TEST_F(PipelineBatchTest, PipelineCacheMustBeLive) {
  if (!onVkrt()) GTEST_SKIP() << "vkrt's own report";
  ComputePipeline sum = makeComputePipeline(device, kSpv_compute_sum_comp, sizeof kSpv_compute_sum_comp,
                                            {VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER});
  ASSERT_EQ(sum.result, VK_SUCCESS);
  VkPipelineCacheCreateInfo pci{VK_STRUCTURE_TYPE_PIPELINE_CACHE_CREATE_INFO};
  VkPipelineCache cache;
  ASSERT_EQ(vkCreatePipelineCache(device, &pci, nullptr, &cache), VK_SUCCESS);
  const VkComputePipelineCreateInfo ci = info(sum, 0);
  VkPipeline out = VK_NULL_HANDLE;
  EXPECT_EQ(vkCreateComputePipelines(device, cache, 1, &ci, nullptr, &out), VK_SUCCESS);
  EXPECT_NE(out, VK_NULL_HANDLE);
  EXPECT_TRUE(vkrtMessages().empty());
  vkDestroyPipeline(device, out, nullptr);
  vkDestroyPipelineCache(device, cache, nullptr);
  out = VK_NULL_HANDLE;
  EXPECT_EQ(vkCreateComputePipelines(device, cache, 1, &ci, nullptr, &out), VK_ERROR_VALIDATION_FAILED_EXT);
  EXPECT_EQ(out, VK_NULL_HANDLE);
  expectVkrtMessage("VUID-vkCreateComputePipelines-pipelineCache-parameter");
  release(sum);
}

}  // namespace
}  // namespace vkrt::test
