// Compute features of the shader compiler end to end, with the features enabled and the validation layer on:
// 8/16-bit members of uniform and push-constant blocks. Expected values are computed here on the CPU.
#include <cstring>
#include <vector>

#include "compute_small_uniform_push.comp.spv.h"
#include "e2e/compute_pipeline_helpers.hpp"
#include "e2e/fixture.hpp"
#include "spirv/small_uniform_reference.hpp"

namespace vkrt::test {
namespace {

class ComputeFeaturesTest : public VulkanTest {
 protected:
  VkPhysicalDeviceVulkan11Features f11{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES};
  FixtureOptions options() override {
    FixtureOptions o;
    f11.storageBuffer16BitAccess = f11.uniformAndStorageBuffer16BitAccess = f11.storagePushConstant16 = VK_TRUE;
    o.featureChain = &f11;
    VkPhysicalDeviceVulkan12Features& f12 = o.features12;
    f12.storageBuffer8BitAccess = f12.uniformAndStorageBuffer8BitAccess = f12.storagePushConstant8 = VK_TRUE;
    return o;
  }

  struct Binding {
    VkDescriptorType type;
    uint32_t count = 1;
  };
  // Set 0 with binding i of bindings[i] (arrays where count > 1), a push-constant range, one set allocated.
  ComputePipeline makePipeline(const uint32_t* words, size_t bytes, const std::vector<Binding>& bindings, uint32_t pushBytes = 0) {
    ComputePipeline p;
    std::vector<VkDescriptorSetLayoutBinding> lb;
    std::vector<VkDescriptorPoolSize> sizes;
    for (uint32_t i = 0; i < bindings.size(); ++i) {
      lb.push_back({i, bindings[i].type, bindings[i].count, VK_SHADER_STAGE_COMPUTE_BIT, nullptr});
      sizes.push_back({bindings[i].type, bindings[i].count});
    }
    VkDescriptorSetLayoutCreateInfo dl{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    dl.bindingCount = uint32_t(lb.size());
    dl.pBindings = lb.data();
    EXPECT_EQ(vkCreateDescriptorSetLayout(device, &dl, nullptr, &p.setLayout), VK_SUCCESS);
    VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, pushBytes};
    VkPipelineLayoutCreateInfo pl{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    pl.setLayoutCount = 1;
    pl.pSetLayouts = &p.setLayout;
    pl.pushConstantRangeCount = pushBytes ? 1 : 0;
    pl.pPushConstantRanges = &range;
    EXPECT_EQ(vkCreatePipelineLayout(device, &pl, nullptr, &p.layout), VK_SUCCESS);
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
    VkShaderModuleCreateInfo sm{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    sm.codeSize = bytes;
    sm.pCode = words;
    EXPECT_EQ(vkCreateShaderModule(device, &sm, nullptr, &p.module), VK_SUCCESS);
    VkComputePipelineCreateInfo ci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    ci.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    ci.stage.module = p.module;
    ci.stage.pName = "main";
    ci.layout = p.layout;
    p.result = vkCreateComputePipelines(device, VK_NULL_HANDLE, 1, &ci, nullptr, &p.pipeline);
    return p;
  }
  // Buffers into consecutive elements of a binding, from element 0.
  void writeBuffers(const ComputePipeline& p, uint32_t binding, VkDescriptorType type, const std::vector<const HostBuffer*>& buffers) {
    std::vector<VkDescriptorBufferInfo> infos;
    for (const HostBuffer* b : buffers) infos.push_back({b->buffer, 0, VK_WHOLE_SIZE});
    VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    w.dstSet = p.set;
    w.dstBinding = binding;
    w.descriptorCount = uint32_t(infos.size());
    w.descriptorType = type;
    w.pBufferInfo = infos.data();
    vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);
  }
  template <class T>
  HostBuffer bufferWith(const std::vector<T>& data, VkBufferUsageFlags usage) {
    HostBuffer b = createHostBuffer(data.size() * sizeof(T), usage);
    std::memcpy(b.data, data.data(), data.size() * sizeof(T));
    return b;
  }
  VkCommandBuffer begin(const ComputePipeline& p) {
    VkCommandBuffer cb = beginOneTime();
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout, 0, 1, &p.set, 0, nullptr);
    return cb;
  }
  // Shader writes visible to the host.
  static void hostBarrier(VkCommandBuffer cb) {
    VkMemoryBarrier mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    mb.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
    mb.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &mb, 0, nullptr, 0, nullptr);
  }
};

constexpr VkDescriptorType kStorage = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
constexpr VkDescriptorType kUniform = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;

TEST_F(ComputeFeaturesTest, EightAndSixteenBitUniformAndPushConstantMembers) {
  VkPhysicalDeviceVulkan11Features r11{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES};
  VkPhysicalDeviceVulkan12Features r12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES, &r11};
  VkPhysicalDevice8BitStorageFeatures s8{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_8BIT_STORAGE_FEATURES, &r12};
  VkPhysicalDevice16BitStorageFeatures s16{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_16BIT_STORAGE_FEATURES, &s8};
  VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &s16};
  vkGetPhysicalDeviceFeatures2(physicalDevice, &f2);
  EXPECT_TRUE(r11.uniformAndStorageBuffer16BitAccess && r11.storagePushConstant16);
  EXPECT_TRUE(r12.uniformAndStorageBuffer8BitAccess && r12.storagePushConstant8);
  EXPECT_TRUE(s16.uniformAndStorageBuffer16BitAccess && s16.storagePushConstant16);
  EXPECT_TRUE(s8.uniformAndStorageBuffer8BitAccess && s8.storagePushConstant8);

  using namespace vkrt::testing;
  SmallUniformValues v;
  std::vector<uint8_t> push = smallPushBlock(v);
  ComputePipeline p = makePipeline(kSpv_compute_small_uniform_push_comp, sizeof kSpv_compute_small_uniform_push_comp,
                                   {{kUniform}, {kStorage}, {kStorage}}, uint32_t(push.size()));
  ASSERT_EQ(p.result, VK_SUCCESS);
  HostBuffer ubo = bufferWith(smallUniformBlock(v), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
  HostBuffer ints = bufferWith(std::vector<int32_t>(kSmallUniformInvocations * kSmallUniformInts, 0x5a5a5a5a), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  HostBuffer floats = bufferWith(std::vector<float>(kSmallUniformInvocations * kSmallUniformFloats, -1.0f), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  writeBuffers(p, 0, kUniform, {&ubo});
  writeBuffers(p, 1, kStorage, {&ints});
  writeBuffers(p, 2, kStorage, {&floats});
  VkCommandBuffer cb = begin(p);
  vkCmdPushConstants(cb, p.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, uint32_t(push.size()), push.data());
  vkCmdDispatch(cb, kSmallUniformInvocations / 4, 1, 1);
  hostBarrier(cb);
  submitAndWait(cb);
  expectSmallUniform(static_cast<const int32_t*>(ints.data), static_cast<const float*>(floats.data), v);
  destroy(ubo);
  destroy(ints);
  destroy(floats);
  destroyComputePipeline(device, p);
}

}  // namespace
}  // namespace vkrt::test
