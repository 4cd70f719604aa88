// Inline uniform blocks (VK_DESCRIPTOR_TYPE_INLINE_UNIFORM_BLOCK: Vulkan 1.3, VK_EXT_inline_uniform_block) end to
// end: bytes put into a set by a VkWriteDescriptorSetInlineUniformBlock write (one running on into the next
// binding), an update template and a descriptor copy are read back by a compute shader
// (tests/shaders/compute_inline_block.comp) and a ray generation shader (inline_block_raygen.rgen, written after
// the set was bound: update-after-bind) as uniform blocks, and compared word for word with the bytes written; the
// pool counts bytes and inline bindings; and each rule vkrt checks for them is broken once and kept once.
#include <algorithm>
#include <cstring>
#include <vector>

#include "compute_inline_block.comp.spv.h"
#include "e2e/trace_fixture.hpp"
#include "inline_block_raygen.rgen.spv.h"

namespace vkrt::test {
namespace {

constexpr VkDescriptorType kInline = VK_DESCRIPTOR_TYPE_INLINE_UNIFORM_BLOCK;
constexpr VkShaderStageFlags kCompute = VK_SHADER_STAGE_COMPUTE_BIT;

// `n` words no two of which are equal (for one seed).
std::vector<uint32_t> pattern(uint32_t n, uint32_t seed) {
  std::vector<uint32_t> w(n);
  for (uint32_t k = 0; k < n; ++k) w[k] = seed * 0x01000193u + (k + 1) * 0x9e3779b9u;
  return w;
}

// Layouts, pools, sets and writes of inline uniform blocks (the features on; the layer as `layer()` says).
class InlineBlockTest : public VulkanTest {
 protected:
  virtual bool layer() { return true; }
  FixtureOptions options() override {
    FixtureOptions o;
    o.validation = layer();
    o.descriptorBindingFlags = true;  // variable-sized bindings
    o.features13.inlineUniformBlock = VK_TRUE;
    o.features13.descriptorBindingInlineUniformBlockUpdateAfterBind = VK_TRUE;
    return o;
  }

  VkDescriptorSetLayout makeLayout(const std::vector<VkDescriptorSetLayoutBinding>& bindings,
                                   const std::vector<VkDescriptorBindingFlags>& flags = {},
                                   VkDescriptorSetLayoutCreateFlags createFlags = 0, VkResult expect = VK_SUCCESS) {
    VkDescriptorSetLayoutBindingFlagsCreateInfo bf{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_BINDING_FLAGS_CREATE_INFO};
    bf.bindingCount = uint32_t(flags.size());
    bf.pBindingFlags = flags.data();
    VkDescriptorSetLayoutCreateInfo ci{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO,
                                       flags.empty() ? nullptr : &bf};
    ci.flags = createFlags;
    ci.bindingCount = uint32_t(bindings.size());
    ci.pBindings = bindings.data();
    VkDescriptorSetLayout l = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreateDescriptorSetLayout(device, &ci, nullptr, &l), expect);
    if (l) layouts.push_back(l);
    return l;
  }
  // A pool of `sizes` with a VkDescriptorPoolInlineUniformBlockCreateInfo of `inlineBindings` (none when -1).
  VkDescriptorPool makePool(const std::vector<VkDescriptorPoolSize>& sizes, uint32_t maxSets, int64_t inlineBindings,
                            VkDescriptorPoolCreateFlags flags = 0, VkResult expect = VK_SUCCESS) {
    VkDescriptorPoolInlineUniformBlockCreateInfo ib{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_INLINE_UNIFORM_BLOCK_CREATE_INFO};
    ib.maxInlineUniformBlockBindings = uint32_t(inlineBindings);
    VkDescriptorPoolCreateInfo ci{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO, inlineBindings >= 0 ? &ib : nullptr};
    ci.flags = flags;
    ci.maxSets = maxSets;
    ci.poolSizeCount = uint32_t(sizes.size());
    ci.pPoolSizes = sizes.data();
    VkDescriptorPool p = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreateDescriptorPool(device, &ci, nullptr, &p), expect);
    if (p) pools.push_back(p);
    return p;
  }
  VkResult allocate(VkDescriptorPool p, VkDescriptorSetLayout l, VkDescriptorSet* set, uint32_t variable = ~0u) {
    VkDescriptorSetVariableDescriptorCountAllocateInfo v{
        VK_STRUCTURE_TYPE_DESCRIPTOR_SET_VARIABLE_DESCRIPTOR_COUNT_ALLOCATE_INFO};
    v.descriptorSetCount = 1;
    v.pDescriptorCounts = &variable;
    VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO, variable != ~0u ? &v : nullptr};
    ai.descriptorPool = p;
    ai.descriptorSetCount = 1;
    ai.pSetLayouts = &l;
    return vkAllocateDescriptorSets(device, &ai, set);
  }
  // The write of `size` bytes from `data` at byte `offset` of `binding` (ib must outlive the write).
  static VkWriteDescriptorSet inlineWrite(VkWriteDescriptorSetInlineUniformBlock& ib, VkDescriptorSet set,
                                          uint32_t binding, uint32_t offset, const void* data, uint32_t size) {
    ib = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_INLINE_UNIFORM_BLOCK};
    ib.dataSize = size;
    ib.pData = data;
    VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, &ib};
    w.dstSet = set;
    w.dstBinding = binding;
    w.dstArrayElement = offset;
    w.descriptorCount = size;
    w.descriptorType = kInline;
    return w;
  }
  void write(VkDescriptorSet set, uint32_t binding, uint32_t offset, const void* data, uint32_t size) {
    VkWriteDescriptorSetInlineUniformBlock ib;
    VkWriteDescriptorSet w = inlineWrite(ib, set, binding, offset, data, size);
    vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);
  }
  void writeBuffer(VkDescriptorSet set, uint32_t binding, VkBuffer buffer) {
    VkDescriptorBufferInfo bi{buffer, 0, VK_WHOLE_SIZE};
    VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    w.dstSet = set;
    w.dstBinding = binding;
    w.descriptorCount = 1;
    w.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    w.pBufferInfo = &bi;
    vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);
  }
  VkDescriptorUpdateTemplate makeTemplate(VkDescriptorSetLayout l,
                                          const std::vector<VkDescriptorUpdateTemplateEntry>& entries,
                                          VkResult expect = VK_SUCCESS) {
    VkDescriptorUpdateTemplateCreateInfo ci{VK_STRUCTURE_TYPE_DESCRIPTOR_UPDATE_TEMPLATE_CREATE_INFO};
    ci.descriptorUpdateEntryCount = uint32_t(entries.size());
    ci.pDescriptorUpdateEntries = entries.data();
    ci.templateType = VK_DESCRIPTOR_UPDATE_TEMPLATE_TYPE_DESCRIPTOR_SET;
    ci.descriptorSetLayout = l;
    VkDescriptorUpdateTemplate t = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreateDescriptorUpdateTemplate(device, &ci, nullptr, &t), expect);
    if (t) templates.push_back(t);
    return t;
  }
  VkDescriptorSet copyDescriptors(VkDescriptorSet src, uint32_t srcBinding, uint32_t srcByte, VkDescriptorSet dst,
                                  uint32_t dstBinding, uint32_t dstByte, uint32_t bytes) {
    VkCopyDescriptorSet c{VK_STRUCTURE_TYPE_COPY_DESCRIPTOR_SET};
    c.srcSet = src;
    c.srcBinding = srcBinding;
    c.srcArrayElement = srcByte;
    c.dstSet = dst;
    c.dstBinding = dstBinding;
    c.dstArrayElement = dstByte;
    c.descriptorCount = bytes;
    vkUpdateDescriptorSets(device, 0, nullptr, 1, &c);
    return dst;
  }

  // Runs compute_inline_block.comp (32 invocations) over `set` of layout `l`, whose binding 2 is `out` (32 words,
  // filled with 0xee first); returns `out`'s words.
  std::vector<uint32_t> dispatch(VkDescriptorSetLayout l, VkDescriptorSet set, const HostBuffer& out) {
    VkPipelineLayoutCreateInfo plci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    plci.setLayoutCount = 1;
    plci.pSetLayouts = &l;
    VkPipelineLayout pl = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreatePipelineLayout(device, &plci, nullptr, &pl), VK_SUCCESS);
    VkShaderModuleCreateInfo sm{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    sm.codeSize = sizeof kSpv_compute_inline_block_comp;
    sm.pCode = kSpv_compute_inline_block_comp;
    VkShaderModule m = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreateShaderModule(device, &sm, nullptr, &m), VK_SUCCESS);
    VkComputePipelineCreateInfo ci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    ci.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    ci.stage.module = m;
    ci.stage.pName = "main";
    ci.layout = pl;
    VkPipeline pipe = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreateComputePipelines(device, VK_NULL_HANDLE, 1, &ci, nullptr, &pipe), VK_SUCCESS);
    std::memset(out.data, 0xee, out.size);
    VkCommandBuffer cb = beginOneTime();
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipe);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pl, 0, 1, &set, 0, nullptr);
    vkCmdDispatch(cb, 1, 1, 1);
    submitAndWait(cb);
    vkDestroyPipeline(device, pipe, nullptr);
    vkDestroyShaderModule(device, m, nullptr);
    vkDestroyPipelineLayout(device, pl, nullptr);
    return std::vector<uint32_t>(static_cast<uint32_t*>(out.data), static_cast<uint32_t*>(out.data) + 32);
  }

  void TearDown() override {
    if (device) {
      vkDeviceWaitIdle(device);
      for (VkDescriptorUpdateTemplate t : templates) vkDestroyDescriptorUpdateTemplate(device, t, nullptr);
      for (VkDescriptorPool p : pools) vkDestroyDescriptorPool(device, p, nullptr);
      for (VkDescriptorSetLayout l : layouts) vkDestroyDescriptorSetLayout(device, l, nullptr);
    }
    VulkanTest::TearDown();
  }

  std::vector<VkDescriptorSetLayout> layouts;
  std::vector<VkDescriptorPool> pools;
  std::vector<VkDescriptorUpdateTemplate> templates;
};

TEST_F(InlineBlockTest, FeatureExtensionAndLimits) {
  VkPhysicalDeviceInlineUniformBlockFeatures f{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_INLINE_UNIFORM_BLOCK_FEATURES};
  VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &f};
  vkGetPhysicalDeviceFeatures2(physicalDevice, &f2);
  EXPECT_TRUE(f.inlineUniformBlock);
  EXPECT_TRUE(f.descriptorBindingInlineUniformBlockUpdateAfterBind);
  VkPhysicalDeviceInlineUniformBlockProperties p{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_INLINE_UNIFORM_BLOCK_PROPERTIES};
  VkPhysicalDeviceVulkan13Properties p13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_PROPERTIES, &p};
  VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &p13};
  vkGetPhysicalDeviceProperties2(physicalDevice, &p2);
  // "Required Limits"
  EXPECT_GE(p.maxInlineUniformBlockSize, 256u);
  EXPECT_GE(p.maxPerStageDescriptorInlineUniformBlocks, 4u);
  EXPECT_GE(p.maxPerStageDescriptorUpdateAfterBindInlineUniformBlocks, 4u);
  EXPECT_GE(p.maxDescriptorSetInlineUniformBlocks, 4u);
  EXPECT_GE(p.maxDescriptorSetUpdateAfterBindInlineUniformBlocks, 4u);
  EXPECT_GE(p13.maxInlineUniformTotalSize, 256u);
  EXPECT_EQ(p.maxInlineUniformBlockSize, p13.maxInlineUniformBlockSize);
  EXPECT_EQ(p.maxDescriptorSetInlineUniformBlocks, p13.maxDescriptorSetInlineUniformBlocks);
  uint32_t n = 0;
  vkEnumerateDeviceExtensionProperties(physicalDevice, nullptr, &n, nullptr);
  std::vector<VkExtensionProperties> ext(n);
  vkEnumerateDeviceExtensionProperties(physicalDevice, nullptr, &n, ext.data());
  bool listed = false;
  for (const VkExtensionProperties& e : ext) listed |= std::strcmp(e.extensionName, "VK_EXT_inline_uniform_block") == 0;
  EXPECT_TRUE(listed);
}

// Words 0-15 are binding 0 (64 bytes), words 16-23 binding 1 (32 bytes). The write covers words 2-17 (from byte 8
// of binding 0 on into binding 1), the template words 0-1 and 22-23, the copy words 18-21 (from another set).
TEST_F(InlineBlockTest, ComputeReadsBytesOfWriteTemplateAndCopy) {
  VkDescriptorSetLayout l = makeLayout({{0, kInline, 64, kCompute, nullptr},
                                        {1, kInline, 32, kCompute, nullptr},
                                        {2, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, kCompute, nullptr}});
  VkDescriptorPool p = makePool({{kInline, 192}, {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 2}}, 2, 4);
  VkDescriptorSet a = VK_NULL_HANDLE, b = VK_NULL_HANDLE;
  ASSERT_EQ(allocate(p, l, &a), VK_SUCCESS);
  ASSERT_EQ(allocate(p, l, &b), VK_SUCCESS);
  HostBuffer out = createHostBuffer(32 * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  writeBuffer(a, 2, out.buffer);
  const std::vector<uint32_t> want = pattern(24, 1);

  write(a, 0, 8, want.data() + 2, 64);
  // The template's data: 4 bytes of padding, words 0-1, 4 bytes of padding, words 22-23.
  uint32_t data[6] = {0xdeadbeef, want[0], want[1], 0xdeadbeef, want[22], want[23]};
  VkDescriptorUpdateTemplate t =
      makeTemplate(l, {{0, 0, 8, kInline, 4, 0}, {1, 24, 8, kInline, 16, 12345 /* ignored for inline blocks */}});
  vkUpdateDescriptorSetWithTemplate(device, a, t, data);
  std::vector<uint32_t> other = pattern(8, 2);
  std::memcpy(other.data() + 2, want.data() + 18, 16);
  write(b, 1, 0, other.data(), 32);
  copyDescriptors(b, 1, 8, a, 1, 8, 16);

  std::vector<uint32_t> got = dispatch(l, a, out);
  for (uint32_t i = 0; i < 24; ++i) EXPECT_EQ(got[i], want[i]) << "word " << i;
  for (uint32_t i = 24; i < 32; ++i) EXPECT_EQ(got[i], 0xeeeeeeeeu) << "word " << i << " is past the blocks";

  // The bytes live in the set: a later write is what the next dispatch reads.
  const std::vector<uint32_t> again = pattern(24, 3);
  write(a, 0, 0, again.data(), 96);
  got = dispatch(l, a, out);
  for (uint32_t i = 0; i < 24; ++i) EXPECT_EQ(got[i], again[i]) << "word " << i;

  destroy(out);
}

// A pool holds inline uniform block bytes (its pool size) and bindings (maxInlineUniformBlockBindings); running
// out of either is VK_ERROR_OUT_OF_POOL_MEMORY, and a freed set gives both back.
TEST_F(InlineBlockTest, PoolCountsBytesAndBindings) {
  VkDescriptorSetLayout l = makeLayout({{0, kInline, 64, kCompute, nullptr}});
  VkDescriptorPool bytes = makePool({{kInline, 128}}, 4, 4);
  VkDescriptorSet s[3] = {};
  EXPECT_EQ(allocate(bytes, l, &s[0]), VK_SUCCESS);
  EXPECT_EQ(allocate(bytes, l, &s[1]), VK_SUCCESS);
  VkResult third = allocate(bytes, l, &s[2]);
  // The spec lets a pool serve more than it was sized for ("may" fail); vkrt does not.
  if (onVkrt()) {
    EXPECT_EQ(third, VK_ERROR_OUT_OF_POOL_MEMORY);
  }

  VkDescriptorPool bindings = makePool({{kInline, 256}}, 4, 1, VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT);
  VkDescriptorSet t[2] = {};
  EXPECT_EQ(allocate(bindings, l, &t[0]), VK_SUCCESS);
  VkResult second = allocate(bindings, l, &t[1]);
  if (onVkrt()) {
    EXPECT_EQ(second, VK_ERROR_OUT_OF_POOL_MEMORY);
    EXPECT_EQ(vkFreeDescriptorSets(device, bindings, 1, &t[0]), VK_SUCCESS);
    EXPECT_EQ(allocate(bindings, l, &t[1]), VK_SUCCESS);
  }
}

// A variable-sized inline uniform block: its variable count is a size in bytes.
TEST_F(InlineBlockTest, VariableSizeIsBytes) {
  if (!onVkrt()) GTEST_SKIP() << "maxVariableDescriptorCount is the driver's figure";
  std::vector<VkDescriptorSetLayoutBinding> b = {{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, kCompute, nullptr},
                                                 {1, kInline, 128, kCompute, nullptr}};
  VkDescriptorBindingFlags flags[2] = {0, VK_DESCRIPTOR_BINDING_VARIABLE_DESCRIPTOR_COUNT_BIT};
  VkDescriptorSetLayoutBindingFlagsCreateInfo bf{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_BINDING_FLAGS_CREATE_INFO};
  bf.bindingCount = 2;
  bf.pBindingFlags = flags;
  VkDescriptorSetLayoutCreateInfo ci{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO, &bf};
  ci.bindingCount = 2;
  ci.pBindings = b.data();
  VkDescriptorSetVariableDescriptorCountLayoutSupport vs{
      VK_STRUCTURE_TYPE_DESCRIPTOR_SET_VARIABLE_DESCRIPTOR_COUNT_LAYOUT_SUPPORT};
  VkDescriptorSetLayoutSupport support{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_SUPPORT, &vs};
  vkGetDescriptorSetLayoutSupport(device, &ci, &support);
  EXPECT_TRUE(support.supported);
  VkPhysicalDeviceVulkan13Properties p13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_PROPERTIES};
  VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &p13};
  vkGetPhysicalDeviceProperties2(physicalDevice, &p2);
  EXPECT_EQ(vs.maxVariableDescriptorCount, p13.maxInlineUniformBlockSize);
}

// With robustBufferAccess, reads of a block the shader declares larger than the binding stay inside the binding:
// binding 1 has 16 bytes here, the shader's block 32, and binding 1 is the last bytes of the set's storage.
class InlineBlockRobustTest : public InlineBlockTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o = InlineBlockTest::options();
    o.features.robustBufferAccess = VK_TRUE;
    return o;
  }
};

TEST_F(InlineBlockRobustTest, ReadsPastTheBindingStayInside) {
  VkDescriptorSetLayout l = makeLayout({{0, kInline, 64, kCompute, nullptr},
                                        {1, kInline, 16, kCompute, nullptr},
                                        {2, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, kCompute, nullptr}});
  VkDescriptorPool p = makePool({{kInline, 80}, {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1}}, 1, 2);
  VkDescriptorSet a = VK_NULL_HANDLE;
  ASSERT_EQ(allocate(p, l, &a), VK_SUCCESS);
  HostBuffer out = createHostBuffer(32 * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  writeBuffer(a, 2, out.buffer);
  const std::vector<uint32_t> want = pattern(20, 7);
  write(a, 0, 0, want.data(), 80);
  std::vector<uint32_t> got = dispatch(l, a, out);
  for (uint32_t i = 0; i < 20; ++i) EXPECT_EQ(got[i], want[i]) << "word " << i;
  // Past the binding: zero on vkrt; the spec allows any value from within the binding, or zero.
  for (uint32_t i = 20; i < 24; ++i) {
    if (onVkrt()) {
      EXPECT_EQ(got[i], 0u) << "word " << i;
    } else {
      EXPECT_TRUE(got[i] == 0 || std::find(want.begin() + 16, want.end(), got[i]) != want.end()) << "word " << i;
    }
  }
  destroy(out);
}

// Rules vkrt checks (the layer is off: it would report the same misuse). Each broken rule reports its VUID and
// changes nothing; its valid neighbour reports nothing.
class InlineBlockMisuseTest : public InlineBlockTest {
 protected:
  bool layer() override { return false; }
  void expectQuiet() {
    EXPECT_TRUE(vkrtMessages().empty()) << vkrtMessages().front().idName << ": " << vkrtMessages().front().text;
    clearMessages();
  }
};

TEST_F(InlineBlockMisuseTest, LayoutSizes) {
  const uint32_t max = [&] {
    VkPhysicalDeviceVulkan13Properties p13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_PROPERTIES};
    VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &p13};
    vkGetPhysicalDeviceProperties2(physicalDevice, &p2);
    return p13.maxInlineUniformBlockSize;
  }();
  makeLayout({{0, kInline, 6, kCompute, nullptr}}, {}, 0, VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkDescriptorSetLayoutBinding-descriptorType-02209");
  makeLayout({{0, kInline, 8, kCompute, nullptr}});
  expectQuiet();
  makeLayout({{0, kInline, max + 4, kCompute, nullptr}}, {}, 0, VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkDescriptorSetLayoutBinding-descriptorType-08004");
  makeLayout({{0, kInline, max, kCompute, nullptr}});
  expectQuiet();
  // Update after bind (the feature is on here; InlineBlockNoUpdateAfterBindTest has it off).
  makeLayout({{0, kInline, 16, kCompute, nullptr}}, {VK_DESCRIPTOR_BINDING_UPDATE_AFTER_BIND_BIT},
             VK_DESCRIPTOR_SET_LAYOUT_CREATE_UPDATE_AFTER_BIND_POOL_BIT);
  expectQuiet();
}

TEST_F(InlineBlockMisuseTest, PoolSizes) {
  makePool({{kInline, 6}}, 1, 1, 0, VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkDescriptorPoolSize-type-02218");
  makePool({{kInline, 8}}, 1, -1, 0, VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkDescriptorPoolCreateInfo-pPoolSizes-09424");
  makePool({{kInline, 8}}, 1, 0, 0, VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkDescriptorPoolCreateInfo-pPoolSizes-09424");
  makePool({{kInline, 8}}, 1, 1);
  expectQuiet();
  // No inline uniform block in the pool sizes: the structure is not needed.
  makePool({{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1}}, 1, -1);
  expectQuiet();
}

// Writes: the structure, byte offsets and sizes in multiples of 4, the bounds of the set and consecutive bindings.
TEST_F(InlineBlockMisuseTest, Writes) {
  VkDescriptorSetLayout l = makeLayout({{0, kInline, 16, kCompute, nullptr},
                                        {1, kInline, 16, kCompute, nullptr},
                                        {2, kInline, 16, VK_SHADER_STAGE_ALL, nullptr},
                                        {3, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, kCompute, nullptr}});
  VkDescriptorPool p = makePool({{kInline, 48}, {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1}}, 1, 3);
  VkDescriptorSet s = VK_NULL_HANDLE;
  ASSERT_EQ(allocate(p, l, &s), VK_SUCCESS);
  const std::vector<uint32_t> d = pattern(8, 4);
  VkWriteDescriptorSetInlineUniformBlock ib;
  VkWriteDescriptorSet w = inlineWrite(ib, s, 0, 0, d.data(), 16);
  w.pNext = nullptr;
  vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);
  expectVkrtMessage("VUID-VkWriteDescriptorSet-descriptorType-02221");
  w = inlineWrite(ib, s, 0, 0, d.data(), 16);
  ib.dataSize = 12;
  vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);
  expectVkrtMessage("VUID-VkWriteDescriptorSet-descriptorType-02221");
  w = inlineWrite(ib, s, 0, 0, nullptr, 16);
  vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);
  expectVkrtMessage("VUID-VkWriteDescriptorSetInlineUniformBlock-pData-parameter");
  w = inlineWrite(ib, s, 0, 2, d.data(), 8);
  vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);
  expectVkrtMessage("VUID-VkWriteDescriptorSet-descriptorType-02219");
  w = inlineWrite(ib, s, 0, 0, d.data(), 6);
  vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);
  expectVkrtMessage("VUID-VkWriteDescriptorSet-descriptorType-02220");
  // Binding 1 runs on into binding 2, whose stages differ.
  w = inlineWrite(ib, s, 1, 8, d.data(), 16);
  vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);
  expectVkrtMessage("VUID-VkWriteDescriptorSet-descriptorCount-00317");
  // Past the last inline byte of binding 2 (binding 3 is a storage buffer: a different type).
  w = inlineWrite(ib, s, 2, 8, d.data(), 16);
  vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);
  expectVkrtMessage("VUID-VkWriteDescriptorSet-descriptorCount-00317");
  w = inlineWrite(ib, s, 3, 0, d.data(), 4);
  vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);
  expectVkrtMessage("VUID-VkWriteDescriptorSet-descriptorType-00319");
  w = inlineWrite(ib, s, 7, 0, d.data(), 4);
  vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);
  expectVkrtMessage("VUID-VkWriteDescriptorSet-dstBinding-00315");
  // A uniform buffer write to an inline uniform block binding.
  HostBuffer ub = createHostBuffer(64, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
  VkDescriptorBufferInfo bi{ub.buffer, 0, VK_WHOLE_SIZE};
  VkWriteDescriptorSet uw{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
  uw.dstSet = s;
  uw.dstBinding = 0;
  uw.descriptorCount = 1;
  uw.descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
  uw.pBufferInfo = &bi;
  vkUpdateDescriptorSets(device, 1, &uw, 0, nullptr);
  expectVkrtMessage("VUID-VkWriteDescriptorSet-descriptorType-00319");
  destroy(ub);
  // Valid: binding 0 from byte 4 on into binding 1 (same stages and flags), up to binding 1's last byte.
  w = inlineWrite(ib, s, 0, 4, d.data(), 28);
  vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);
  expectQuiet();
  // Valid: the offset at the end of binding 0 is byte 0 of binding 1.
  w = inlineWrite(ib, s, 0, 16, d.data(), 16);
  vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);
  expectQuiet();
  w = inlineWrite(ib, s, 2, 0, d.data(), 16);
  vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);
  expectQuiet();
}

TEST_F(InlineBlockMisuseTest, VariableSizeBoundsWrites) {
  VkDescriptorSetLayout l =
      makeLayout({{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, kCompute, nullptr}, {1, kInline, 64, kCompute, nullptr}},
                 {0, VK_DESCRIPTOR_BINDING_VARIABLE_DESCRIPTOR_COUNT_BIT});
  VkDescriptorPool p = makePool({{kInline, 64}, {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1}}, 1, 1);
  VkDescriptorSet s = VK_NULL_HANDLE;
  ASSERT_EQ(allocate(p, l, &s, 32), VK_SUCCESS);
  const std::vector<uint32_t> d = pattern(16, 5);
  write(s, 1, 0, d.data(), 36);
  expectVkrtMessage("VUID-VkWriteDescriptorSet-dstArrayElement-00321");
  write(s, 1, 0, d.data(), 32);
  expectQuiet();
}

TEST_F(InlineBlockMisuseTest, Copies) {
  VkDescriptorSetLayout l =
      makeLayout({{0, kInline, 32, kCompute, nullptr}, {1, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1, kCompute, nullptr}});
  VkDescriptorPool p = makePool({{kInline, 64}, {VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 2}}, 2, 2);
  VkDescriptorSet a = VK_NULL_HANDLE, b = VK_NULL_HANDLE;
  ASSERT_EQ(allocate(p, l, &a), VK_SUCCESS);
  ASSERT_EQ(allocate(p, l, &b), VK_SUCCESS);
  copyDescriptors(a, 0, 2, b, 0, 0, 8);
  expectVkrtMessage("VUID-VkCopyDescriptorSet-srcBinding-02223");
  copyDescriptors(a, 0, 0, b, 0, 2, 8);
  expectVkrtMessage("VUID-VkCopyDescriptorSet-dstBinding-02224");
  copyDescriptors(a, 0, 0, b, 0, 0, 6);
  expectVkrtMessage("VUID-VkCopyDescriptorSet-srcBinding-02225");
  copyDescriptors(a, 0, 0, a, 0, 8, 16);
  expectVkrtMessage("VUID-VkCopyDescriptorSet-srcSet-00349");
  copyDescriptors(a, 0, 0, b, 1, 0, 4);
  expectVkrtMessage("VUID-VkCopyDescriptorSet-dstBinding-02632");
  copyDescriptors(a, 0, 16, b, 0, 24, 16);  // 8 bytes past binding 0, which is followed by a uniform buffer
  expectVkrtMessage("VUID-VkCopyDescriptorSet-dstArrayElement-00348");
  // Valid: within one set without overlapping, and between sets.
  copyDescriptors(a, 0, 0, a, 0, 16, 16);
  expectQuiet();
  copyDescriptors(a, 0, 4, b, 0, 0, 28);
  expectQuiet();
}

TEST_F(InlineBlockMisuseTest, Templates) {
  VkDescriptorSetLayout l = makeLayout({{0, kInline, 32, kCompute, nullptr}});
  makeTemplate(l, {{0, 2, 8, kInline, 0, 0}}, VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkDescriptorUpdateTemplateEntry-descriptor-02226");
  makeTemplate(l, {{0, 0, 6, kInline, 0, 0}}, VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkDescriptorUpdateTemplateEntry-descriptor-02227");
  makeTemplate(l, {{0, 16, 20, kInline, 0, 0}}, VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkDescriptorUpdateTemplateEntry-dstArrayElement-00355");
  makeTemplate(l, {{0, 16, 16, kInline, 0, 0}});
  expectQuiet();
}

// The features off: no inline uniform block layout.
class InlineBlockFeatureOffTest : public VulkanTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o;
    o.validation = false;
    return o;
  }
};

TEST_F(InlineBlockFeatureOffTest, LayoutNeedsTheFeature) {
  VkDescriptorSetLayoutBinding b{0, kInline, 16, kCompute, nullptr};
  VkDescriptorSetLayoutCreateInfo ci{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  ci.bindingCount = 1;
  ci.pBindings = &b;
  VkDescriptorSetLayout l = VK_NULL_HANDLE;
  EXPECT_EQ(vkCreateDescriptorSetLayout(device, &ci, nullptr, &l), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkDescriptorSetLayoutBinding-descriptorType-04604");
}

// inlineUniformBlock on, its update-after-bind feature off.
class InlineBlockNoUpdateAfterBindTest : public InlineBlockTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o;
    o.validation = false;
    o.features13.inlineUniformBlock = VK_TRUE;
    return o;
  }
};

TEST_F(InlineBlockNoUpdateAfterBindTest, UpdateAfterBindNeedsTheFeature) {
  makeLayout({{0, kInline, 16, kCompute, nullptr}}, {VK_DESCRIPTOR_BINDING_UPDATE_AFTER_BIND_BIT},
             VK_DESCRIPTOR_SET_LAYOUT_CREATE_UPDATE_AFTER_BIND_POOL_BIT, VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage(
      "VUID-VkDescriptorSetLayoutBindingFlagsCreateInfo-descriptorBindingInlineUniformBlockUpdateAfterBind-02211");
  makeLayout({{0, kInline, 16, kCompute, nullptr}});
  EXPECT_TRUE(vkrtMessages().empty());
}

// A ray generation shader reads an inline uniform block written after the set was bound (update after bind).
class InlineBlockRaygenTest : public TraceTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o = TraceTest::options();
    o.features13.inlineUniformBlock = VK_TRUE;
    o.features13.descriptorBindingInlineUniformBlockUpdateAfterBind = VK_TRUE;
    return o;
  }
};

TEST_F(InlineBlockRaygenTest, RaygenReadsBlockWrittenAfterBind) {
  constexpr VkShaderStageFlags kRaygen = VK_SHADER_STAGE_RAYGEN_BIT_KHR;
  VkDescriptorSetLayoutBinding b[2] = {{0, kInline, 64, kRaygen, nullptr},
                                       {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, kRaygen, nullptr}};
  VkDescriptorBindingFlags flags[2] = {VK_DESCRIPTOR_BINDING_UPDATE_AFTER_BIND_BIT, 0};
  VkDescriptorSetLayoutBindingFlagsCreateInfo bf{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_BINDING_FLAGS_CREATE_INFO};
  bf.bindingCount = 2;
  bf.pBindingFlags = flags;
  VkDescriptorSetLayoutCreateInfo dl{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO, &bf};
  dl.flags = VK_DESCRIPTOR_SET_LAYOUT_CREATE_UPDATE_AFTER_BIND_POOL_BIT;
  dl.bindingCount = 2;
  dl.pBindings = b;
  VkDescriptorSetLayout sl = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateDescriptorSetLayout(device, &dl, nullptr, &sl), VK_SUCCESS);
  VkPipelineLayoutCreateInfo plci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  plci.setLayoutCount = 1;
  plci.pSetLayouts = &sl;
  VkPipelineLayout pl = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreatePipelineLayout(device, &plci, nullptr, &pl), VK_SUCCESS);
  VkDescriptorPoolSize sizes[2] = {{kInline, 64}, {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1}};
  VkDescriptorPoolInlineUniformBlockCreateInfo ib{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_INLINE_UNIFORM_BLOCK_CREATE_INFO};
  ib.maxInlineUniformBlockBindings = 1;
  VkDescriptorPoolCreateInfo pci{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO, &ib};
  pci.flags = VK_DESCRIPTOR_POOL_CREATE_UPDATE_AFTER_BIND_BIT;
  pci.maxSets = 1;
  pci.poolSizeCount = 2;
  pci.pPoolSizes = sizes;
  VkDescriptorPool dp = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateDescriptorPool(device, &pci, nullptr, &dp), VK_SUCCESS);
  VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  ai.descriptorPool = dp;
  ai.descriptorSetCount = 1;
  ai.pSetLayouts = &sl;
  VkDescriptorSet set = VK_NULL_HANDLE;
  ASSERT_EQ(vkAllocateDescriptorSets(device, &ai, &set), VK_SUCCESS);
  HostBuffer& out = buffer(16 * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  std::memset(out.data, 0xee, out.size);
  VkDescriptorBufferInfo bi{out.buffer, 0, VK_WHOLE_SIZE};
  VkWriteDescriptorSet bw{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
  bw.dstSet = set;
  bw.dstBinding = 1;
  bw.descriptorCount = 1;
  bw.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  bw.pBufferInfo = &bi;
  vkUpdateDescriptorSets(device, 1, &bw, 0, nullptr);

  Desc d;
  d.layout = pl;
  d.general(module(kSpv_inline_block_raygen_rgen, sizeof kSpv_inline_block_raygen_rgen),
            VK_SHADER_STAGE_RAYGEN_BIT_KHR);
  VkPipeline p = make(d);
  ASSERT_NE(p, VK_NULL_HANDLE);
  const Sbt s = sbt(p, 1, {0}, {}, {});
  VkCommandBuffer cb = beginOneTime();
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, p);
  vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, pl, 0, 1, &set, 0, nullptr);
  cmdTrace(cb, &s.raygen, &s.miss, &s.hit, &s.callable, 16, 1, 1);
  // Written after the set was bound and the trace recorded: the trace reads these bytes.
  const std::vector<uint32_t> want = pattern(16, 6);
  VkWriteDescriptorSetInlineUniformBlock iw{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_INLINE_UNIFORM_BLOCK};
  iw.dataSize = 64;
  iw.pData = want.data();
  VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, &iw};
  w.dstSet = set;
  w.dstBinding = 0;
  w.descriptorCount = 64;
  w.descriptorType = kInline;
  vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);
  submitAndWait(cb);
  const auto* got = static_cast<const uint32_t*>(out.data);
  for (uint32_t i = 0; i < 16; ++i) EXPECT_EQ(got[i], want[i]) << "word " << i;

  vkDestroyDescriptorPool(device, dp, nullptr);
  vkDestroyPipelineLayout(device, pl, nullptr);
  vkDestroyDescriptorSetLayout(device, sl, nullptr);
}

}  // namespace
}  // namespace vkrt::test
