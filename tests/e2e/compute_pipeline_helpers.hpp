// Building a compute pipeline for the end-to-end tests: set 0 with one binding per descriptor type (binding i
// of types[i]), a push-constant range, a descriptor pool with one set allocated, and the pipeline itself.
#pragma once

#include <gtest/gtest.h>
#include <vulkan/vulkan.h>

#include <cstdint>
#include <vector>

namespace vkrt::test {

struct ComputePipeline {
  VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkDescriptorPool pool = VK_NULL_HANDLE;
  VkDescriptorSet set = VK_NULL_HANDLE;
  VkShaderModule module = VK_NULL_HANDLE;
  VkPipeline pipeline = VK_NULL_HANDLE;
  VkResult result = VK_SUCCESS;  // of vkCreateComputePipelines
};

// With no descriptor types the pipeline layout has no set and no pool is made.
inline ComputePipeline makeComputePipeline(VkDevice device, const uint32_t* words, size_t bytes,
                                           const std::vector<VkDescriptorType>& types, uint32_t pushBytes = 0,
                                           const VkSpecializationInfo* spec = nullptr,
                                           VkPipelineCreateFlags flags = 0) {
  ComputePipeline p;
  std::vector<VkDescriptorSetLayoutBinding> bindings;
  std::vector<VkDescriptorPoolSize> sizes;
  for (uint32_t i = 0; i < types.size(); ++i) {
    bindings.push_back({i, types[i], 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr});
    sizes.push_back({types[i], 1});
  }
  VkDescriptorSetLayoutCreateInfo dl{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  dl.bindingCount = uint32_t(bindings.size());
  dl.pBindings = bindings.data();
  EXPECT_EQ(vkCreateDescriptorSetLayout(device, &dl, nullptr, &p.setLayout), VK_SUCCESS);
  VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, pushBytes};
  VkPipelineLayoutCreateInfo pl{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  pl.setLayoutCount = types.empty() ? 0 : 1;
  pl.pSetLayouts = &p.setLayout;
  pl.pushConstantRangeCount = pushBytes ? 1 : 0;
  pl.pPushConstantRanges = &range;
  EXPECT_EQ(vkCreatePipelineLayout(device, &pl, nullptr, &p.layout), VK_SUCCESS);
  if (!types.empty()) {
    VkDescriptorPoolCreateInfo dp{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    dp.maxSets = 1;
    dp.poolSizeCount = uint32_t(sizes.size());
    dp.pPoolSizes = sizes.data();
    EXPECT_EQ(vkCreateDescriptorPool(device, &dp, nullptr, &p.pool), VK_SUCCESS);
    VkDescriptorSetAllocateInfo da{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    da.descriptorPool = p.pool;
    da.descriptorSetCount = 1;
    da.pSetLayouts = &p.setLayout;
    EXPECT_EQ(vkAllocateDescriptorSets(device, &da, &p.set), VK_SUCCESS);
  }
  VkShaderModuleCreateInfo sm{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  sm.codeSize = bytes;
  sm.pCode = words;
  EXPECT_EQ(vkCreateShaderModule(device, &sm, nullptr, &p.module), VK_SUCCESS);
  VkComputePipelineCreateInfo ci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
  ci.flags = flags;
  ci.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
  ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  ci.stage.module = p.module;
  ci.stage.pName = "main";
  ci.stage.pSpecializationInfo = spec;
  ci.layout = p.layout;
  p.result = vkCreateComputePipelines(device, VK_NULL_HANDLE, 1, &ci, nullptr, &p.pipeline);
  return p;
}

inline void destroyComputePipeline(VkDevice device, ComputePipeline& p) {
  vkDestroyPipeline(device, p.pipeline, nullptr);
  vkDestroyShaderModule(device, p.module, nullptr);
  if (p.pool) vkDestroyDescriptorPool(device, p.pool, nullptr);
  vkDestroyPipelineLayout(device, p.layout, nullptr);
  vkDestroyDescriptorSetLayout(device, p.setLayout, nullptr);
}

}  // namespace vkrt::test
