// Building a compute pipeline for the end-to-end tests: set 0 with one binding per descriptor type (binding i
// of types[i], or of an array of them), a push-constant range, a descriptor pool with one set allocated, and the
// pipeline itself.
#pragma once

#include <gtest/gtest.h>
#include <vulkan/vulkan.h>

#include <cstdint>
#include <vector>

#include "e2e/fixture.hpp"

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

// Binding i of bindings[i].type, an array of bindings[i].count descriptors.
struct DescriptorArray {
  VkDescriptorType type;
  uint32_t count = 1;
};

// With no bindings the pipeline layout has no set and no pool is made.
inline ComputePipeline makeComputePipelineWithArrays(VkDevice device, const uint32_t* words, size_t bytes,
                                                     const std::vector<DescriptorArray>& bindings,
                                                     uint32_t pushBytes = 0, const VkSpecializationInfo* spec = nullptr,
                                                     VkPipelineCreateFlags flags = 0) {
  ComputePipeline p;
  std::vector<VkDescriptorSetLayoutBinding> layoutBindings;
  std::vector<VkDescriptorPoolSize> sizes;
  for (uint32_t i = 0; i < bindings.size(); ++i) {
    layoutBindings.push_back({i, bindings[i].type, bindings[i].count, VK_SHADER_STAGE_COMPUTE_BIT, nullptr});
    sizes.push_back({bindings[i].type, bindings[i].count});
  }
  VkDescriptorSetLayoutCreateInfo dl{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  dl.bindingCount = uint32_t(layoutBindings.size());
  dl.pBindings = layoutBindings.data();
  EXPECT_EQ(vkCreateDescriptorSetLayout(device, &dl, nullptr, &p.setLayout), VK_SUCCESS);
  VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, pushBytes};
  VkPipelineLayoutCreateInfo pl{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  pl.setLayoutCount = bindings.empty() ? 0 : 1;
  pl.pSetLayouts = &p.setLayout;
  pl.pushConstantRangeCount = pushBytes ? 1 : 0;
  pl.pPushConstantRanges = &range;
  EXPECT_EQ(vkCreatePipelineLayout(device, &pl, nullptr, &p.layout), VK_SUCCESS);
  if (!bindings.empty()) {
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

// One descriptor per binding.
inline ComputePipeline makeComputePipeline(VkDevice device, const uint32_t* words, size_t bytes,
                                           const std::vector<VkDescriptorType>& types, uint32_t pushBytes = 0,
                                           const VkSpecializationInfo* spec = nullptr,
                                           VkPipelineCreateFlags flags = 0) {
  std::vector<DescriptorArray> bindings;
  for (VkDescriptorType t : types) bindings.push_back({t, 1});
  return makeComputePipelineWithArrays(device, words, bytes, bindings, pushBytes, spec, flags);
}

// Enables the descriptor-indexing features vkrt's compiler implements (all but those of input attachments, a
// graphics thing): dynamic and non-uniform indices into buffer, image and texel buffer arrays, runtime-sized arrays.
inline void enableDescriptorIndexing(FixtureOptions& o) {
  o.features.shaderUniformBufferArrayDynamicIndexing = o.features.shaderSampledImageArrayDynamicIndexing = VK_TRUE;
  o.features.shaderStorageBufferArrayDynamicIndexing = o.features.shaderStorageImageArrayDynamicIndexing = VK_TRUE;
  VkPhysicalDeviceVulkan12Features& f = o.features12;
  f.runtimeDescriptorArray = f.shaderUniformBufferArrayNonUniformIndexing =
      f.shaderStorageBufferArrayNonUniformIndexing = VK_TRUE;
  f.shaderSampledImageArrayNonUniformIndexing = f.shaderStorageImageArrayNonUniformIndexing = VK_TRUE;
  f.shaderUniformTexelBufferArrayDynamicIndexing = f.shaderStorageTexelBufferArrayDynamicIndexing = VK_TRUE;
  f.shaderUniformTexelBufferArrayNonUniformIndexing = f.shaderStorageTexelBufferArrayNonUniformIndexing = VK_TRUE;
}

// Writes the whole of storage buffer buffers[i] to binding i of p's set (Buffer: the fixture's HostBuffer, which only
// its tests can name).
template <class Buffer>
void writeStorageBuffers(VkDevice device, const ComputePipeline& p, const std::vector<const Buffer*>& buffers) {
  for (uint32_t i = 0; i < buffers.size(); ++i) {
    VkDescriptorBufferInfo bi{buffers[i]->buffer, 0, VK_WHOLE_SIZE};
    VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    w.dstSet = p.set;
    w.dstBinding = i;
    w.descriptorCount = 1;
    w.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    w.pBufferInfo = &bi;
    vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);
  }
}

// Records into `cb`: p and its set bound, `pushBytes` bytes of `push` pushed (where given), `groups` x 1 x 1
// workgroups dispatched, and a barrier that makes the shader's writes visible to the host.
inline void recordDispatch(VkCommandBuffer cb, const ComputePipeline& p, uint32_t groups, const void* push = nullptr,
                           uint32_t pushBytes = 0) {
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
  vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout, 0, 1, &p.set, 0, nullptr);
  if (push) vkCmdPushConstants(cb, p.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, pushBytes, push);
  vkCmdDispatch(cb, groups, 1, 1);
  VkMemoryBarrier mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  mb.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
  mb.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &mb, 0, nullptr, 0,
                       nullptr);
}

inline void destroyComputePipeline(VkDevice device, ComputePipeline& p) {
  vkDestroyPipeline(device, p.pipeline, nullptr);
  vkDestroyShaderModule(device, p.module, nullptr);
  if (p.pool) vkDestroyDescriptorPool(device, p.pool, nullptr);
  vkDestroyPipelineLayout(device, p.layout, nullptr);
  vkDestroyDescriptorSetLayout(device, p.setLayout, nullptr);
}

}  // namespace vkrt::test
