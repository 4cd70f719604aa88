// Compute features of the shader compiler end to end, with the features enabled and the validation layer on:
// 8/16-bit members of uniform and push-constant blocks, buffer descriptor arrays indexed per invocation, scalar
// block layout, zero-initialized workgroup memory, 64-bit integer atomics.
// Expected values are computed here on the CPU.
#include <cstring>
#include <vector>

#include "compute_atomic_int64.comp.spv.h"
#include "compute_nonuniform_buffers.comp.spv.h"
#include "compute_scalar_layout.comp.spv.h"
#include "compute_small_uniform_push.comp.spv.h"
#include "compute_std430_uniform.comp.spv.h"
#include "compute_zero_init_workgroup.comp.spv.h"
#include "e2e/compute_pipeline_helpers.hpp"
#include "e2e/fixture.hpp"
#include "spirv/nonuniform_buffers_reference.hpp"
#include "spirv/scalar_layout_reference.hpp"
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
    enableDescriptorIndexing(o);
    f12.scalarBlockLayout = VK_TRUE;
    return o;
  }

  // Buffers into consecutive elements of a binding, from element 0.
  void writeBuffers(const ComputePipeline& p, uint32_t binding, VkDescriptorType type,
                    const std::vector<const HostBuffer*>& buffers) {
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
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &mb, 0, nullptr, 0,
                         nullptr);
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
  ComputePipeline p = makeComputePipelineWithArrays(device, kSpv_compute_small_uniform_push_comp,
                                                    sizeof kSpv_compute_small_uniform_push_comp,
                                                    {{kUniform}, {kStorage}, {kStorage}}, uint32_t(push.size()));
  ASSERT_EQ(p.result, VK_SUCCESS);
  HostBuffer ubo = bufferWith(smallUniformBlock(v), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
  HostBuffer ints = bufferWith(std::vector<int32_t>(kSmallUniformInvocations * kSmallUniformInts, 0x5a5a5a5a),
                               VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  HostBuffer floats = bufferWith(std::vector<float>(kSmallUniformInvocations * kSmallUniformFloats, -1.0f),
                                 VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
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

TEST_F(ComputeFeaturesTest, NonUniformIndicesIntoBufferDescriptorArrays) {
  VkPhysicalDeviceVulkan12Features r12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  VkPhysicalDeviceDescriptorIndexingFeatures di{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DESCRIPTOR_INDEXING_FEATURES};
  VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &r12};
  vkGetPhysicalDeviceFeatures2(physicalDevice, &f2);
  EXPECT_TRUE(f2.features.shaderStorageBufferArrayDynamicIndexing &&
              f2.features.shaderUniformBufferArrayDynamicIndexing);
  EXPECT_TRUE(r12.runtimeDescriptorArray && r12.shaderStorageBufferArrayNonUniformIndexing &&
              r12.shaderUniformBufferArrayNonUniformIndexing);
  f2.pNext = &di;
  vkGetPhysicalDeviceFeatures2(physicalDevice, &f2);
  EXPECT_EQ(di.runtimeDescriptorArray, r12.runtimeDescriptorArray) << "the 1.2 struct and the promoted one agree";
  EXPECT_EQ(di.shaderStorageImageArrayNonUniformIndexing, r12.shaderStorageImageArrayNonUniformIndexing);

  using vkrt::testing::NonUniformBuffers;
  NonUniformBuffers ref;
  constexpr uint32_t kN = NonUniformBuffers::kN, kBuffers = NonUniformBuffers::kBuffers;
  ComputePipeline p = makeComputePipelineWithArrays(device, kSpv_compute_nonuniform_buffers_comp,
                                                    sizeof kSpv_compute_nonuniform_buffers_comp,
                                                    {{kStorage, kBuffers}, {kUniform, 3}, {kStorage}});
  ASSERT_EQ(p.result, VK_SUCCESS);
  std::vector<HostBuffer> buffers;
  for (uint32_t k = 0; k < kBuffers; ++k)
    buffers.push_back(bufferWith(ref.data[k], VK_BUFFER_USAGE_STORAGE_BUFFER_BIT));
  std::vector<HostBuffer> ubos;
  for (auto& q : ref.params)
    ubos.push_back(bufferWith(std::vector<uint32_t>(q, q + 4), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT));
  HostBuffer out = bufferWith(std::vector<uint32_t>(kN * 4, 0xdeadbeef), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  std::vector<const HostBuffer*> sb, ub;
  for (auto& b : buffers) sb.push_back(&b);
  for (auto& b : ubos) ub.push_back(&b);
  writeBuffers(p, 0, kStorage, sb);
  writeBuffers(p, 1, kUniform, ub);
  writeBuffers(p, 2, kStorage, {&out});
  VkCommandBuffer cb = begin(p);
  vkCmdDispatch(cb, kN / 8, 1, 1);
  hostBarrier(cb);
  submitAndWait(cb);
  ref.expect(static_cast<const uint32_t*>(out.data),
             [&](uint32_t k) { return static_cast<const uint32_t*>(buffers[k].data); });
  for (auto& b : buffers) destroy(b);
  for (auto& b : ubos) destroy(b);
  destroy(out);
  destroyComputePipeline(device, p);
}

TEST_F(ComputeFeaturesTest, ScalarBlockLayoutReadAndWritten) {
  VkPhysicalDeviceScalarBlockLayoutFeatures sbl{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SCALAR_BLOCK_LAYOUT_FEATURES};
  VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &sbl};
  vkGetPhysicalDeviceFeatures2(physicalDevice, &f2);
  EXPECT_TRUE(sbl.scalarBlockLayout);

  using namespace vkrt::testing;
  ComputePipeline p =
      makeComputePipelineWithArrays(device, kSpv_compute_scalar_layout_comp, sizeof kSpv_compute_scalar_layout_comp,
                                    {{kStorage}, {kUniform}, {kStorage}});
  ASSERT_EQ(p.result, VK_SUCCESS);
  ScalarLayoutValues v;
  HostBuffer in = bufferWith(scalarInBlock(v), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  HostBuffer ubo = bufferWith(scalarUniformBlock(v), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
  HostBuffer out = bufferWith(std::vector<uint8_t>(kScalarOutBytes, 0xcd), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  writeBuffers(p, 0, kStorage, {&in});
  writeBuffers(p, 1, kUniform, {&ubo});
  writeBuffers(p, 2, kStorage, {&out});
  VkCommandBuffer cb = begin(p);
  vkCmdDispatch(cb, kScalarInvocations / 4, 1, 1);
  hostBarrier(cb);
  submitAndWait(cb);
  std::vector<uint8_t> want = scalarExpectedOut(v, 0xcd);
  const auto* got = static_cast<const uint8_t*>(out.data);
  for (size_t i = 0; i < want.size(); ++i) EXPECT_EQ(int(got[i]), int(want[i])) << "byte " << i;
  destroy(in);
  destroy(ubo);
  destroy(out);
  destroyComputePipeline(device, p);
}

// A std430 uniform block with only uniformBufferStandardLayout enabled (not scalarBlockLayout).
class ComputeStandardLayoutTest : public ComputeFeaturesTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o;
    o.features12.uniformBufferStandardLayout = VK_TRUE;
    return o;
  }
};

TEST_F(ComputeStandardLayoutTest, Std430UniformBlock) {
  ComputePipeline p = makeComputePipelineWithArrays(device, kSpv_compute_std430_uniform_comp,
                                                    sizeof kSpv_compute_std430_uniform_comp, {{kUniform}, {kStorage}});
  ASSERT_EQ(p.result, VK_SUCCESS);
  std::vector<uint32_t> block(10);
  for (uint32_t i = 0; i < 8; ++i) {
    float f = float(i) * 0.5f - 1.0f;
    std::memcpy(&block[i], &f, 4);
  }
  block[8] = 3;
  block[9] = 100;
  HostBuffer ubo = bufferWith(block, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
  HostBuffer out = bufferWith(std::vector<float>(8, -1.0f), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  writeBuffers(p, 0, kUniform, {&ubo});
  writeBuffers(p, 1, kStorage, {&out});
  VkCommandBuffer cb = begin(p);
  vkCmdDispatch(cb, 1, 1, 1);
  hostBarrier(cb);
  submitAndWait(cb);
  const auto* o = static_cast<const float*>(out.data);
  for (uint32_t i = 0; i < 8; ++i) EXPECT_EQ(o[i], (float(i) * 0.5f - 1.0f) * 3.0f + 100.0f) << i;  // exact either way
  destroy(ubo);
  destroy(out);
  destroyComputePipeline(device, p);
}

// Without scalarBlockLayout (or uniformBufferStandardLayout) the offsets break the standard layout rules: vkrt
// validates modules with the rules the device's features allow.
class ComputeFeaturesMisuseTest : public VulkanTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o;
    o.validation = false;
    return o;
  }
};

TEST_F(ComputeFeaturesMisuseTest, ScalarLayoutWithoutTheFeatureIsRejected) {
  if (!onVkrt()) GTEST_SKIP() << "vkrt's own message";
  VkShaderModuleCreateInfo sm{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  sm.codeSize = sizeof kSpv_compute_scalar_layout_comp;
  sm.pCode = kSpv_compute_scalar_layout_comp;
  VkShaderModule module = VK_NULL_HANDLE;
  EXPECT_EQ(vkCreateShaderModule(device, &sm, nullptr, &module), VK_ERROR_INVALID_SHADER_NV);
  auto msgs = vkrtMessages();
  ASSERT_EQ(msgs.size(), 1u);
  EXPECT_NE(msgs[0].text.find("stride 12 not satisfying alignment to 16"), std::string::npos) << msgs[0].text;
  expectVkrtMessage("VUID-VkShaderModuleCreateInfo-pCode-01378");
  sm.codeSize = sizeof kSpv_compute_std430_uniform_comp;
  sm.pCode = kSpv_compute_std430_uniform_comp;
  EXPECT_EQ(vkCreateShaderModule(device, &sm, nullptr, &module), VK_ERROR_INVALID_SHADER_NV) << "std430 uniform block";
  expectVkrtMessage("VUID-VkShaderModuleCreateInfo-pCode-01378");
}

// Workgroup variables with initializers (shaderZeroInitializeWorkgroupMemory): every workgroup starts from zeros,
// whatever the previous workgroup on the same thread left there.
class ComputeZeroInitTest : public ComputeFeaturesTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o = ComputeFeaturesTest::options();
    o.zeroInitializeWorkgroupMemory = true;
    return o;
  }
};

TEST_F(ComputeZeroInitTest, WorkgroupVariablesStartAtZeroInEveryWorkgroup) {
  ComputePipeline p = makeComputePipelineWithArrays(device, kSpv_compute_zero_init_workgroup_comp,
                                                    sizeof kSpv_compute_zero_init_workgroup_comp, {{kStorage}});
  ASSERT_EQ(p.result, VK_SUCCESS);
  HostBuffer out = bufferWith(std::vector<uint32_t>(48, 0xcdcdcdcd), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  writeBuffers(p, 0, kStorage, {&out});
  VkCommandBuffer cb = begin(p);
  vkCmdDispatch(cb, 2, 1, 1);
  hostBarrier(cb);
  submitAndWait(cb);
  const auto* got = static_cast<const uint32_t*>(out.data);
  for (uint32_t i = 0; i < 16; ++i) {
    uint32_t group = i / 8, l = i % 8;
    EXPECT_EQ(got[i], 0u) << "invocation " << i << " read its workgroup's variables before any write";
    EXPECT_EQ(got[16 + i], 36u) << "invocation " << i << ": 1 + 2 + ... + 8";
    EXPECT_EQ(got[32 + i], group * 8 + (l + 1) % 8 + 100) << "invocation " << i;
  }
  destroy(out);
  destroyComputePipeline(device, p);
}

// VK_KHR_shader_atomic_int64, enabled by name with both of its features.
class ComputeAtomicInt64Test : public ComputeFeaturesTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o = ComputeFeaturesTest::options();
    o.deviceExtensions = {VK_KHR_SHADER_ATOMIC_INT64_EXTENSION_NAME};
    o.features.shaderInt64 = VK_TRUE;
    o.features12.shaderBufferInt64Atomics = o.features12.shaderSharedInt64Atomics = VK_TRUE;
    return o;
  }
};

TEST_F(ComputeAtomicInt64Test, BufferAndWorkgroupAtomicsPast32Bits) {
  ComputePipeline p = makeComputePipelineWithArrays(device, kSpv_compute_atomic_int64_comp,
                                                    sizeof kSpv_compute_atomic_int64_comp, {{kStorage}});
  ASSERT_EQ(p.result, VK_SUCCESS);
  // tests/shaders/compute_atomic_int64.comp's block.
  struct Block {
    uint64_t sum;
    int64_t minimum;
    uint64_t maximum;
    uint64_t bits;
    uint64_t cas;
    uint64_t sharedSum[2];
    int64_t sharedMin[2];
    uint64_t returned[128];
  };
  HostBuffer b = createHostBuffer(sizeof(Block), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  std::memset(b.data, 0, sizeof(Block));
  auto* blk = static_cast<Block*>(b.data);
  blk->sum = 7ull << 40;  // the sum carries into the high word from here
  blk->returned[0] = 0xdead;
  writeBuffers(p, 0, kStorage, {&b});
  VkCommandBuffer cb = begin(p);
  vkCmdDispatch(cb, 2, 1, 1);
  hostBarrier(cb);
  submitAndWait(cb);
  uint64_t groupSum = 0;
  for (uint64_t i = 0; i < 64; ++i) groupSum += (i << 33) + 5;
  const int64_t least = -int64_t((63ull << 33) + 5);
  EXPECT_EQ(blk->sum, (7ull << 40) + 2 * groupSum) << "atomicAdd";
  EXPECT_EQ(blk->minimum, least) << "atomicMin (signed)";
  EXPECT_EQ(blk->maximum, (63ull << 33) + 5) << "atomicMax (unsigned)";
  EXPECT_EQ(blk->bits, ~0ull) << "atomicOr";
  for (int g = 0; g < 2; ++g) {
    EXPECT_EQ(blk->sharedSum[g], groupSum) << "workgroup " << g << ": shared atomicAdd";
    EXPECT_EQ(blk->sharedMin[g], least) << "workgroup " << g << ": shared atomicMin";
  }
  // Exactly one invocation found 0 and swapped its value in; every other one saw that value.
  int winners = 0;
  for (uint64_t x = 0; x < 128; ++x) {
    if (blk->returned[x] != 0) continue;
    ++winners;
    EXPECT_EQ(blk->cas, (x << 40) | 0xabc) << "the winner's value";
  }
  EXPECT_EQ(winners, 1);
  for (uint64_t x = 0; x < 128; ++x) {
    if (blk->returned[x] != 0) {
      EXPECT_EQ(blk->returned[x], blk->cas) << "invocation " << x;
    }
  }
  destroy(b);
  destroyComputePipeline(device, p);
}

}  // namespace
}  // namespace vkrt::test
