// Ray tracing pipelines and the device's compiled shaders (below the loader, so that the compile counter can
// be read): a shader is compiled once per device whatever pipelines and libraries use it, and linking a library
// compiles nothing.
#include <gtest/gtest.h>

#include <cstdlib>
#include <vector>

#include "pipeline_chit.rchit.spv.h"
#include "pipeline_miss.rmiss.spv.h"
#include "pipeline_raygen.rgen.spv.h"
#include "runtime/shader_cache.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {
namespace {

class RtCompileSharing : public ::testing::Test {
 protected:
  void SetUp() override {
    VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    ASSERT_EQ(vkrt_CreateInstance(&ici, nullptr, &instance), VK_SUCCESS);
    uint32_t n = 1;
    VkPhysicalDevice pd = VK_NULL_HANDLE;
    ASSERT_EQ(vkrt_EnumeratePhysicalDevices(instance, &n, &pd), VK_SUCCESS);
    VkPhysicalDeviceRayTracingPipelineFeaturesKHR rt{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_FEATURES_KHR};
    rt.rayTracingPipeline = VK_TRUE;
    const char* extensions[] = {VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME, VK_KHR_PIPELINE_LIBRARY_EXTENSION_NAME,
                                VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME};
    float priority = 1;
    VkDeviceQueueCreateInfo q{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    q.queueCount = 1;
    q.pQueuePriorities = &priority;
    VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, &rt};
    dci.queueCreateInfoCount = 1;
    dci.pQueueCreateInfos = &q;
    dci.enabledExtensionCount = 3;
    dci.ppEnabledExtensionNames = extensions;
    ASSERT_EQ(vkrt_CreateDevice(pd, &dci, nullptr, &device), VK_SUCCESS);
    VkPushConstantRange pc{VK_SHADER_STAGE_RAYGEN_BIT_KHR, 0, 8};
    VkPipelineLayoutCreateInfo lci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    lci.pushConstantRangeCount = 1;
    lci.pPushConstantRanges = &pc;
    ASSERT_EQ(vkrt_CreatePipelineLayout(device, &lci, nullptr, &layout), VK_SUCCESS);
    raygen = module(kSpv_pipeline_raygen_rgen, sizeof kSpv_pipeline_raygen_rgen);
    miss = module(kSpv_pipeline_miss_rmiss, sizeof kSpv_pipeline_miss_rmiss);
    chit = module(kSpv_pipeline_chit_rchit, sizeof kSpv_pipeline_chit_rchit);
  }
  void TearDown() override {
    for (VkPipeline p : pipelines) vkrt_DestroyPipeline(device, p, nullptr);
    for (VkShaderModule m : {raygen, miss, chit}) vkrt_DestroyShaderModule(device, m, nullptr);
    vkrt_DestroyPipelineLayout(device, layout, nullptr);
    vkrt_DestroyDevice(device, nullptr);
    vkrt_DestroyInstance(instance, nullptr);
  }

  VkShaderModule module(const uint32_t* words, size_t bytes) {
    VkShaderModuleCreateInfo ci{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    ci.codeSize = bytes;
    ci.pCode = words;
    VkShaderModule m = VK_NULL_HANDLE;
    EXPECT_EQ(vkrt_CreateShaderModule(device, &ci, nullptr, &m), VK_SUCCESS);
    return m;
  }

  // A pipeline (or a library) of general groups for `generals` and one triangle hit group per `hits`.
  VkPipeline create(std::vector<std::pair<VkShaderModule, VkShaderStageFlagBits>> generals,
                    std::vector<VkShaderModule> hits, std::vector<VkPipeline> libraries = {},
                    VkPipelineCreateFlags flags = 0) {
    std::vector<VkPipelineShaderStageCreateInfo> stages;
    std::vector<VkRayTracingShaderGroupCreateInfoKHR> groups;
    auto stage = [&](VkShaderModule m, VkShaderStageFlagBits s) {
      VkPipelineShaderStageCreateInfo st{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
      st.stage = s;
      st.module = m;
      st.pName = "main";
      stages.push_back(st);
      return uint32_t(stages.size() - 1);
    };
    for (auto [m, s] : generals) {
      VkRayTracingShaderGroupCreateInfoKHR g{VK_STRUCTURE_TYPE_RAY_TRACING_SHADER_GROUP_CREATE_INFO_KHR};
      g.type = VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR;
      g.generalShader = stage(m, s);
      g.closestHitShader = g.anyHitShader = g.intersectionShader = VK_SHADER_UNUSED_KHR;
      groups.push_back(g);
    }
    for (VkShaderModule m : hits) {
      VkRayTracingShaderGroupCreateInfoKHR g{VK_STRUCTURE_TYPE_RAY_TRACING_SHADER_GROUP_CREATE_INFO_KHR};
      g.type = VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR;
      g.generalShader = g.anyHitShader = g.intersectionShader = VK_SHADER_UNUSED_KHR;
      g.closestHitShader = stage(m, VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR);
      groups.push_back(g);
    }
    VkPipelineLibraryCreateInfoKHR lib{VK_STRUCTURE_TYPE_PIPELINE_LIBRARY_CREATE_INFO_KHR};
    lib.libraryCount = uint32_t(libraries.size());
    lib.pLibraries = libraries.data();
    VkRayTracingPipelineInterfaceCreateInfoKHR iface{VK_STRUCTURE_TYPE_RAY_TRACING_PIPELINE_INTERFACE_CREATE_INFO_KHR};
    iface.maxPipelineRayPayloadSize = 16;
    iface.maxPipelineRayHitAttributeSize = 8;
    VkRayTracingPipelineCreateInfoKHR ci{VK_STRUCTURE_TYPE_RAY_TRACING_PIPELINE_CREATE_INFO_KHR};
    ci.flags = flags;
    ci.stageCount = uint32_t(stages.size());
    ci.pStages = stages.data();
    ci.groupCount = uint32_t(groups.size());
    ci.pGroups = groups.data();
    ci.maxPipelineRayRecursionDepth = 1;
    ci.pLibraryInfo = &lib;
    ci.pLibraryInterface = &iface;
    ci.layout = layout;
    ci.basePipelineIndex = -1;
    VkPipeline p = VK_NULL_HANDLE;
    EXPECT_EQ(vkrt_CreateRayTracingPipelinesKHR(device, VK_NULL_HANDLE, VK_NULL_HANDLE, 1, &ci, nullptr, &p),
              VK_SUCCESS);
    if (p) pipelines.push_back(p);
    return p;
  }

  VkInstance instance = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkShaderModule raygen = VK_NULL_HANDLE, miss = VK_NULL_HANDLE, chit = VK_NULL_HANDLE;
  std::vector<VkPipeline> pipelines;
};

TEST_F(RtCompileSharing, LinkingALibraryCompilesNothingAndShadersCompileOncePerDevice) {
  uint64_t before = shaderCompileCount();
  VkPipeline library = create({{miss, VK_SHADER_STAGE_MISS_BIT_KHR}}, {chit}, {}, VK_PIPELINE_CREATE_LIBRARY_BIT_KHR);
  ASSERT_NE(library, VK_NULL_HANDLE);
  EXPECT_EQ(shaderCompileCount(), before + 2);  // the miss and the closest-hit shader
  // A pipeline of its own raygen and the library: only the raygen compiles.
  ASSERT_NE(create({{raygen, VK_SHADER_STAGE_RAYGEN_BIT_KHR}}, {}, {library}), VK_NULL_HANDLE);
  EXPECT_EQ(shaderCompileCount(), before + 3);
  // Another one linking the same library, and one repeating the library's shaders as its own: nothing new.
  ASSERT_NE(create({{raygen, VK_SHADER_STAGE_RAYGEN_BIT_KHR}}, {}, {library}), VK_NULL_HANDLE);
  ASSERT_NE(create({{raygen, VK_SHADER_STAGE_RAYGEN_BIT_KHR}, {miss, VK_SHADER_STAGE_MISS_BIT_KHR}}, {chit}),
            VK_NULL_HANDLE);
  EXPECT_EQ(shaderCompileCount(), before + 3);
}

}  // namespace
}  // namespace vkrt
