// Compute pipelines and dispatches end to end, through the loader with the validation layer on: GLSL shaders
// compiled by glslc at build time, results compared with values computed here on the CPU.
#include <algorithm>
#include <cstring>
#include <numeric>
#include <vector>

#include "compute_arith.comp.spv.h"
#include "compute_atomics.comp.spv.h"
#include "compute_control.comp.spv.h"
#include "compute_push_spec.comp.spv.h"
#include "compute_shared.comp.spv.h"
#include "compute_subgroup_basic.comp.spv.h"
#include "compute_unsupported.comp.spv.h"
#include "e2e/compute_pipeline_helpers.hpp"
#include "e2e/fixture.hpp"

namespace vkrt::test {
namespace {

class ComputeTest : public VulkanTest {
 protected:
  using Pipeline = ComputePipeline;

  // A pipeline whose set 0 has `types.size()` bindings (binding i of types[i]), a push-constant range of
  // `pushBytes`, built from `words`.
  Pipeline makePipeline(const uint32_t* words, size_t bytes, std::vector<VkDescriptorType> types,
                        uint32_t pushBytes = 0, const VkSpecializationInfo* spec = nullptr,
                        VkPipelineCreateFlags flags = 0) {
    return makeComputePipeline(device, words, bytes, types, pushBytes, spec, flags);
  }
  void destroy(Pipeline& p) { destroyComputePipeline(device, p); }
  void bindBuffer(Pipeline& p, uint32_t binding, VkDescriptorType type, const HostBuffer& b,
                  VkDeviceSize range = VK_WHOLE_SIZE) {
    VkDescriptorBufferInfo bi{b.buffer, 0, range};
    VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    w.dstSet = p.set;
    w.dstBinding = binding;
    w.descriptorCount = 1;
    w.descriptorType = type;
    w.pBufferInfo = &bi;
    vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);
  }
  VkCommandBuffer begin(Pipeline& p, const std::vector<uint32_t>& dynamicOffsets = {}) {
    VkCommandBuffer cb = beginOneTime();
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout, 0, 1, &p.set, uint32_t(dynamicOffsets.size()),
                            dynamicOffsets.data());
    return cb;
  }
  template <class T>
  HostBuffer bufferWith(const std::vector<T>& data, VkBufferUsageFlags usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT) {
    HostBuffer b = createHostBuffer(data.size() * sizeof(T), usage);
    std::memcpy(b.data, data.data(), data.size() * sizeof(T));
    return b;
  }
};

constexpr VkDescriptorType kStorage = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;

TEST_F(ComputeTest, ArithmeticAcrossWorkgroups) {
  Pipeline p =
      makePipeline(kSpv_compute_arith_comp, sizeof kSpv_compute_arith_comp, {kStorage, kStorage, kStorage, kStorage});
  ASSERT_EQ(p.result, VK_SUCCESS);
  const uint32_t n = 256;
  std::vector<int32_t> a(n), b(n);
  for (uint32_t i = 0; i < n; ++i) {
    a[i] = int32_t(i * 2654435761u);
    b[i] = int32_t(i % 37) - 18;
  }
  HostBuffer ba = bufferWith(a), bb = bufferWith(b);
  HostBuffer out = bufferWith(std::vector<int32_t>(n * 24)), outF = bufferWith(std::vector<float>(n * 8));
  bindBuffer(p, 0, kStorage, ba);
  bindBuffer(p, 1, kStorage, bb);
  bindBuffer(p, 2, kStorage, out);
  bindBuffer(p, 3, kStorage, outF);
  VkCommandBuffer cb = begin(p);
  vkCmdDispatch(cb, n / 16, 1, 1);
  submitAndWait(cb);
  const int32_t* r = static_cast<const int32_t*>(out.data);
  for (uint32_t i = 0; i < n; ++i) {
    uint32_t x = uint32_t(a[i]), y = uint32_t(b[i]);
    EXPECT_EQ(uint32_t(r[i * 24 + 0]), x + y) << i;
    EXPECT_EQ(uint32_t(r[i * 24 + 2]), x * y) << i;
    EXPECT_EQ(r[i * 24 + 3], b[i] ? a[i] / b[i] : 0) << i;
    EXPECT_EQ(uint32_t(r[i * 24 + 9]), x ^ y) << i;
    EXPECT_EQ(uint32_t(r[i * 24 + 11]), x << (y & 31)) << i;
    EXPECT_EQ(uint32_t(r[i * 24 + 13]), x >> (y & 31)) << i;
  }
  for (HostBuffer* h : {&ba, &bb, &out, &outF}) VulkanTest::destroy(*h);
  destroy(p);
}

TEST_F(ComputeTest, SharedMemoryBarriersAndReduction) {
  Pipeline p = makePipeline(kSpv_compute_shared_comp, sizeof kSpv_compute_shared_comp, {kStorage, kStorage});
  ASSERT_EQ(p.result, VK_SUCCESS);
  const uint32_t groups = 33, n = groups * 64;
  std::vector<uint32_t> v(n);
  for (uint32_t i = 0; i < n; ++i) v[i] = i * 7 + (i >> 3);
  HostBuffer data = bufferWith(v), sums = bufferWith(std::vector<uint32_t>(groups * 2));
  bindBuffer(p, 0, kStorage, data);
  bindBuffer(p, 1, kStorage, sums);
  VkCommandBuffer cb = begin(p);
  vkCmdDispatch(cb, groups, 1, 1);
  submitAndWait(cb);
  const uint32_t* r = static_cast<const uint32_t*>(data.data);
  const uint32_t* s = static_cast<const uint32_t*>(sums.data);
  for (uint32_t g = 0; g < groups; ++g) {
    uint32_t want = 0;
    for (uint32_t l = 0; l < 64; ++l) {
      ASSERT_EQ(r[g * 64 + l], v[g * 64 + 63 - l]) << g << "/" << l;
      want += v[g * 64 + l];
    }
    EXPECT_EQ(s[2 * g], want) << g;
    EXPECT_EQ(s[2 * g + 1], 64u) << g;
  }
  VulkanTest::destroy(data);
  VulkanTest::destroy(sums);
  destroy(p);
}

TEST_F(ComputeTest, AtomicsThroughDynamicStorageBuffer) {
  const VkDescriptorType dyn = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER_DYNAMIC;
  Pipeline p = makePipeline(kSpv_compute_atomics_comp, sizeof kSpv_compute_atomics_comp, {dyn, kStorage});
  ASSERT_EQ(p.result, VK_SUCCESS);
  const uint32_t n = 32 * 40;
  // Counters at a dynamic offset of 256 bytes; the first 256 bytes must stay untouched.
  std::vector<uint32_t> c(64 + 24, 0xabababab);
  uint32_t* ctr = &c[64];
  std::fill(ctr, ctr + 24, 0u);
  ctr[1] = 0xffffffffu;
  ctr[5] = 0x7fffffff;
  HostBuffer counters = bufferWith(c), old = bufferWith(std::vector<uint32_t>(n));
  bindBuffer(p, 0, dyn, counters, 24 * 4);
  bindBuffer(p, 1, kStorage, old);
  VkCommandBuffer cb = begin(p, {256});
  vkCmdDispatch(cb, n / 32, 1, 1);
  submitAndWait(cb);
  const uint32_t* r = static_cast<const uint32_t*>(counters.data);
  for (int i = 0; i < 64; ++i) ASSERT_EQ(r[i], 0xababababu) << i;
  r += 64;
  uint32_t mn = ~0u, mx = 0;
  std::vector<uint32_t> hist(16, 0);
  for (uint32_t i = 0; i < n; ++i) {
    uint32_t v = (i * 2654435761u) >> 7;
    mn = std::min(mn, v);
    mx = std::max(mx, v);
    hist[v % 16]++;
  }
  EXPECT_EQ(r[0], n);
  EXPECT_EQ(r[1], mn);
  EXPECT_EQ(r[2], mx);
  EXPECT_EQ(r[3], ~0u);
  for (int k = 0; k < 16; ++k) EXPECT_EQ(r[8 + k], hist[k]) << k;
  std::vector<uint32_t> seen(static_cast<const uint32_t*>(old.data), static_cast<const uint32_t*>(old.data) + n);
  std::sort(seen.begin(), seen.end());
  for (uint32_t i = 0; i < n; ++i) ASSERT_EQ(seen[i], i);
  VulkanTest::destroy(counters);
  VulkanTest::destroy(old);
  destroy(p);
}

TEST_F(ComputeTest, PushConstantsAndSpecializationConstants) {
  struct {
    uint32_t localSize;
    int32_t scale;
    uint32_t negate;
    float bias;
  } data = {16, -2, 1, 1.25f};
  VkSpecializationMapEntry entries[] = {{0, 0, 4}, {1, 4, 4}, {2, 8, 4}, {3, 12, 4}};
  VkSpecializationInfo spec{4, entries, sizeof data, &data};
  Pipeline p = makePipeline(kSpv_compute_push_spec_comp, sizeof kSpv_compute_push_spec_comp, {kStorage}, 32, &spec);
  ASSERT_EQ(p.result, VK_SUCCESS);
  const uint32_t count = 50;
  HostBuffer out = bufferWith(std::vector<float>(count + 2, -1.0f));
  bindBuffer(p, 0, kStorage, out);
  struct {
    uint32_t count;
    int32_t offset;
    float fscale;
    float pad;
    float extra[2];
  } pc = {count, 7, 0.5f, 0, {3.0f, -1.0f}};
  VkCommandBuffer cb = begin(p);
  vkCmdPushConstants(cb, p.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof pc, &pc);
  vkCmdDispatch(cb, 4, 1, 1);  // 64 invocations, 14 past count
  submitAndWait(cb);
  const float* r = static_cast<const float*>(out.data);
  for (uint32_t i = 0; i < count; ++i) EXPECT_FLOAT_EQ(r[i], -(float(int32_t(i) * -2 + 7) * 0.5f + 1.25f - 3.0f)) << i;
  EXPECT_FLOAT_EQ(r[count], 16.0f);
  EXPECT_FLOAT_EQ(r[count + 1], -1.0f);
  VulkanTest::destroy(out);
  destroy(p);
}

TEST_F(ComputeTest, DispatchBaseAndIndirect) {
  Pipeline p = makePipeline(kSpv_compute_control_comp, sizeof kSpv_compute_control_comp, {kStorage}, 0, nullptr,
                            VK_PIPELINE_CREATE_DISPATCH_BASE_BIT);
  ASSERT_EQ(p.result, VK_SUCCESS);
  // 8 invocations per workgroup; elements 24..55 via the base, then 0..15 through an indirect dispatch.
  std::vector<uint32_t> v(64, 5);
  HostBuffer data = bufferWith(v);
  VkDispatchIndirectCommand ind[2] = {{9, 9, 9}, {2, 1, 1}};
  HostBuffer args = createHostBuffer(sizeof ind, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
  std::memcpy(args.data, ind, sizeof ind);
  bindBuffer(p, 0, kStorage, data);
  VkCommandBuffer cb = begin(p);
  vkCmdDispatchBase(cb, 3, 0, 0, 4, 1, 1);
  vkCmdDispatchIndirect(cb, args.buffer, sizeof(VkDispatchIndirectCommand));
  submitAndWait(cb);
  const uint32_t* r = static_cast<const uint32_t*>(data.data);
  // What the shader computes for input 5 (see compute_control.comp): collatz(6) = 8 steps, class 30,
  // sumSkipping(5) = 1+2+4 + 0+2+4 = 13.
  const uint32_t f5 = 8 * 1000000u + 30 * 1000u + 13;
  for (uint32_t i = 0; i < 64; ++i) EXPECT_EQ(r[i], (i < 16 || (i >= 24 && i < 56)) ? f5 : 5u) << i;
  VulkanTest::destroy(data);
  VulkanTest::destroy(args);
  destroy(p);
}

// The subgroup properties vkrt reports (size 1, BASIC operations in compute): each invocation is a subgroup of its
// own, elected, index 0, and a workgroup has as many subgroups as invocations.
TEST_F(ComputeTest, BasicSubgroupOperationsOnSubgroupsOfOne) {
  VkPhysicalDeviceSubgroupProperties sp{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES};
  VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &sp};
  vkGetPhysicalDeviceProperties2(physicalDevice, &p2);
  ASSERT_TRUE(sp.supportedStages & VK_SHADER_STAGE_COMPUTE_BIT);
  ASSERT_TRUE(sp.supportedOperations & VK_SUBGROUP_FEATURE_BASIC_BIT);
  Pipeline p = makePipeline(kSpv_compute_subgroup_basic_comp, sizeof kSpv_compute_subgroup_basic_comp, {kStorage});
  ASSERT_EQ(p.result, VK_SUCCESS);
  HostBuffer data = bufferWith(std::vector<uint32_t>(2 * 8 * 4, 0xcdcdcdcd));
  bindBuffer(p, 0, kStorage, data);
  VkCommandBuffer cb = begin(p);
  vkCmdDispatch(cb, 2, 1, 1);
  submitAndWait(cb);
  const uint32_t* r = static_cast<const uint32_t*>(data.data);
  const uint32_t size = sp.subgroupSize;
  for (uint32_t i = 0; i < 16; ++i) {
    uint32_t local = i % 8;
    EXPECT_EQ(r[4 * i + 1], size) << i;
    EXPECT_EQ(r[4 * i + 2], local % size) << i;
    EXPECT_EQ(r[4 * i + 3], (8 + size - 1) / size * 100 + local / size) << i;
    EXPECT_EQ(r[4 * i + 0], local % size == 0 ? 1u : 0u) << i << ": the subgroup's first active invocation is elected";
  }
  VulkanTest::destroy(data);
  destroy(p);
}

class ComputeMisuseTest : public ComputeTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o;
    o.validation = false;
    return o;
  }
};

TEST_F(ComputeMisuseTest, UnsupportedInstructionFailsCreationWithItsName) {
  Pipeline p = makePipeline(kSpv_compute_unsupported_comp, sizeof kSpv_compute_unsupported_comp,
                            {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER});
  EXPECT_EQ(p.result, VK_ERROR_UNKNOWN);
  EXPECT_EQ(p.pipeline, VK_NULL_HANDLE);
  auto msgs = vkrtMessages();
  ASSERT_EQ(msgs.size(), 1u);
  EXPECT_NE(msgs[0].text.find("unsupported instruction OpGroupNonUniformShuffle at word"), std::string::npos)
      << msgs[0].text;
  clearMessages();
  destroy(p);
}

TEST_F(ComputeMisuseTest, LayoutWithoutTheShadersBindingIsRejected) {
  // The shared-memory shader uses bindings 0 and 1; the layout has only binding 0.
  Pipeline p = makePipeline(kSpv_compute_shared_comp, sizeof kSpv_compute_shared_comp, {kStorage});
  EXPECT_EQ(p.result, VK_ERROR_VALIDATION_FAILED_EXT);
  EXPECT_EQ(p.pipeline, VK_NULL_HANDLE);
  expectVkrtMessage("VUID-VkComputePipelineCreateInfo-layout-07988");
  destroy(p);
  // A uniform buffer where the shader declares a storage buffer.
  Pipeline q = makePipeline(kSpv_compute_shared_comp, sizeof kSpv_compute_shared_comp,
                            {kStorage, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER});
  EXPECT_EQ(q.result, VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkComputePipelineCreateInfo-layout-07990");
  destroy(q);
}

TEST_F(ComputeMisuseTest, DispatchLimitsAndIndirectBufferChecks) {
  Pipeline p = makePipeline(kSpv_compute_control_comp, sizeof kSpv_compute_control_comp, {kStorage});
  ASSERT_EQ(p.result, VK_SUCCESS);
  std::vector<uint32_t> v(8, 5);
  HostBuffer data = bufferWith(v);
  HostBuffer notIndirect = createHostBuffer(64, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  bindBuffer(p, 0, kStorage, data);
  VkCommandBuffer cb = begin(p);
  vkCmdDispatch(cb, 70000, 1, 1);
  expectVkrtMessage("VUID-vkCmdDispatch-groupCountX-00386");
  vkCmdDispatchBase(cb, 65000, 0, 0, 1000, 1, 1);
  expectVkrtMessage("VUID-vkCmdDispatchBase-groupCountX-00424");
  vkCmdDispatchIndirect(cb, notIndirect.buffer, 0);
  expectVkrtMessage("VUID-vkCmdDispatchIndirect-buffer-02709");
  // A non-zero base with a pipeline created without VK_PIPELINE_CREATE_DISPATCH_BASE_BIT: reported when the
  // command executes, and nothing runs.
  vkCmdDispatchBase(cb, 0, 1, 0, 1, 1, 1);
  submitAndWait(cb);
  expectVkrtMessage("VUID-vkCmdDispatchBase-baseGroupX-00427");
  for (int i = 0; i < 8; ++i) EXPECT_EQ(static_cast<const uint32_t*>(data.data)[i], 5u);
  VulkanTest::destroy(data);
  VulkanTest::destroy(notIndirect);
  destroy(p);
}

TEST_F(ComputeMisuseTest, WrongStageIsRejected) {
  Pipeline p = makePipeline(kSpv_compute_control_comp, sizeof kSpv_compute_control_comp, {kStorage});
  ASSERT_EQ(p.result, VK_SUCCESS);
  VkComputePipelineCreateInfo ci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
  ci.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
  ci.stage.stage = VK_SHADER_STAGE_FRAGMENT_BIT;
  ci.stage.module = p.module;
  ci.stage.pName = "main";
  ci.layout = p.layout;
  VkPipeline out = reinterpret_cast<VkPipeline>(uintptr_t(0x1234));
  EXPECT_EQ(vkCreateComputePipelines(device, VK_NULL_HANDLE, 1, &ci, nullptr, &out), VK_ERROR_VALIDATION_FAILED_EXT);
  EXPECT_EQ(out, VK_NULL_HANDLE);
  expectVkrtMessage("VUID-VkComputePipelineCreateInfo-stage-00701");
  ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  ci.stage.pName = "other";
  EXPECT_EQ(vkCreateComputePipelines(device, VK_NULL_HANDLE, 1, &ci, nullptr, &out), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkPipelineShaderStageCreateInfo-pName-00707");
  destroy(p);
}

}  // namespace
}  // namespace vkrt::test
