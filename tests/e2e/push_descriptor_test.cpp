// VK_KHR_push_descriptor end to end, with the validation layer on: descriptors pushed into a command buffer
// (vkCmdPushDescriptorSetKHR, vkCmdPushDescriptorSetWithTemplateKHR) read and written by a compute dispatch
// (tests/shaders/push_descriptor.comp: a uniform buffer and storage buffers of the push set beside an allocated set),
// a draw (push_descriptor.frag) and a ray tracing launch (the trace fixture's shaders over a push set), each checked
// word for word or pixel for pixel against values computed here; pushes between two dispatches, draws or traces of
// one command buffer (each sees its own, and a push that changes some bindings keeps the others); the application's
// arrays changed right after the push; the property, the extension and its commands; and each rule vkrt checks for
// push descriptors broken once (vkrt and the layer report it, and the call has no effect) and kept once.
#include <array>
#include <cstddef>
#include <cstring>
#include <vector>

#include "draw_color.vert.spv.h"
#include "e2e/draw_fixture.hpp"
#include "e2e/fixture.hpp"
#include "e2e/trace_fixture.hpp"
#include "push_descriptor.comp.spv.h"
#include "push_descriptor.frag.spv.h"
#include "push_descriptor_image.comp.spv.h"

namespace vkrt::test {
namespace {

constexpr VkShaderStageFlags kCompute = VK_SHADER_STAGE_COMPUTE_BIT;
constexpr VkDescriptorType kUniform = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
constexpr VkDescriptorType kStorage = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
constexpr VkDescriptorSetLayoutCreateFlags kPush = VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR;
constexpr uint32_t kN = 64;  // invocations of a dispatch (4 workgroups of 16)

// push_descriptor.comp's uniform block.
struct Params {
  uint32_t mul, add;
};

VkWriteDescriptorSet bufferWrite(uint32_t binding, VkDescriptorType type, const VkDescriptorBufferInfo* info,
                                 uint32_t count = 1) {
  VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
  w.dstBinding = binding;
  w.descriptorCount = count;
  w.descriptorType = type;
  w.pBufferInfo = info;
  return w;
}

// The compute side: set 0 an allocated set (binding 0: the bias buffer), set 1 the push set (binding 0: Params, 1:
// src, 2: dst) of push_descriptor.comp.
class PushDescriptorTest : public VulkanTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o;
    o.deviceExtensions = {VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME};
    o.descriptorBindingFlags = true;            // the binding flags rules (03003) with their features on
    o.features13.inlineUniformBlock = VK_TRUE;  // the inline uniform block rule (02208) alike
    return o;
  }

  void SetUp() override {
    VulkanTest::SetUp();
    if (HasFatalFailure() || !device) return;
    cmdPush = reinterpret_cast<PFN_vkCmdPushDescriptorSetKHR>(vkGetDeviceProcAddr(device, "vkCmdPushDescriptorSetKHR"));
    cmdPushTemplate = reinterpret_cast<PFN_vkCmdPushDescriptorSetWithTemplateKHR>(
        vkGetDeviceProcAddr(device, "vkCmdPushDescriptorSetWithTemplateKHR"));
    ASSERT_NE(cmdPush, nullptr);
    ASSERT_NE(cmdPushTemplate, nullptr);

    setLayout0 = makeLayout({{0, kStorage, 1, kCompute, nullptr}});
    pushLayout = makeLayout(
        {{0, kUniform, 1, kCompute, nullptr}, {1, kStorage, 1, kCompute, nullptr}, {2, kStorage, 1, kCompute, nullptr}},
        kPush);
    ASSERT_NE(setLayout0, VK_NULL_HANDLE);
    ASSERT_NE(pushLayout, VK_NULL_HANDLE);
    VkDescriptorSetLayout sets[2] = {setLayout0, pushLayout};
    VkPipelineLayoutCreateInfo plci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    plci.setLayoutCount = 2;
    plci.pSetLayouts = sets;
    ASSERT_EQ(vkCreatePipelineLayout(device, &plci, nullptr, &pipelineLayout), VK_SUCCESS);
    VkShaderModuleCreateInfo sm{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    sm.codeSize = sizeof kSpv_push_descriptor_comp;
    sm.pCode = kSpv_push_descriptor_comp;
    ASSERT_EQ(vkCreateShaderModule(device, &sm, nullptr, &module), VK_SUCCESS);
    VkComputePipelineCreateInfo ci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    ci.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    ci.stage.module = module;
    ci.stage.pName = "main";
    ci.layout = pipelineLayout;
    ASSERT_EQ(vkCreateComputePipelines(device, VK_NULL_HANDLE, 1, &ci, nullptr, &pipeline), VK_SUCCESS);

    VkDescriptorPoolSize size{kStorage, 1};
    VkDescriptorPoolCreateInfo dp{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    dp.maxSets = 1;
    dp.poolSizeCount = 1;
    dp.pPoolSizes = &size;
    ASSERT_EQ(vkCreateDescriptorPool(device, &dp, nullptr, &pool), VK_SUCCESS);
    VkDescriptorSetAllocateInfo da{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    da.descriptorPool = pool;
    da.descriptorSetCount = 1;
    da.pSetLayouts = &setLayout0;
    ASSERT_EQ(vkAllocateDescriptorSets(device, &da, &set0), VK_SUCCESS);

    bias = buffer(kN * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    src = buffer(kN * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    for (uint32_t i = 0; i < kN; ++i) {
      words(bias)[i] = 1000 * i;
      words(src)[i] = 3 * i + 1;
    }
    VkDescriptorBufferInfo bi{bias.buffer, 0, VK_WHOLE_SIZE};
    VkWriteDescriptorSet w = bufferWrite(0, kStorage, &bi);
    w.dstSet = set0;
    vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);
  }

  void TearDown() override {
    if (device) {
      vkDeviceWaitIdle(device);
      for (HostBuffer& b : buffers) destroy(b);
      for (VkDescriptorUpdateTemplate t : templates) vkDestroyDescriptorUpdateTemplate(device, t, nullptr);
      if (pool) vkDestroyDescriptorPool(device, pool, nullptr);
      if (pipeline) vkDestroyPipeline(device, pipeline, nullptr);
      if (module) vkDestroyShaderModule(device, module, nullptr);
      for (VkPipelineLayout l : pipelineLayouts) vkDestroyPipelineLayout(device, l, nullptr);
      if (pipelineLayout) vkDestroyPipelineLayout(device, pipelineLayout, nullptr);
      for (VkDescriptorSetLayout l : layouts) vkDestroyDescriptorSetLayout(device, l, nullptr);
    }
    VulkanTest::TearDown();
  }

  VkDescriptorSetLayout makeLayout(const std::vector<VkDescriptorSetLayoutBinding>& bindings,
                                   VkDescriptorSetLayoutCreateFlags flags = 0,
                                   const std::vector<VkDescriptorBindingFlags>& bindingFlags = {},
                                   VkResult expect = VK_SUCCESS) {
    VkDescriptorSetLayoutBindingFlagsCreateInfo bf{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_BINDING_FLAGS_CREATE_INFO};
    bf.bindingCount = uint32_t(bindingFlags.size());
    bf.pBindingFlags = bindingFlags.data();
    VkDescriptorSetLayoutCreateInfo ci{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO,
                                       bindingFlags.empty() ? nullptr : &bf};
    ci.flags = flags;
    ci.bindingCount = uint32_t(bindings.size());
    ci.pBindings = bindings.data();
    VkDescriptorSetLayout l = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreateDescriptorSetLayout(device, &ci, nullptr, &l), expect);
    if (l) layouts.push_back(l);
    return l;
  }
  VkPipelineLayout makePipelineLayout(const std::vector<VkDescriptorSetLayout>& sets, VkResult expect = VK_SUCCESS) {
    VkPipelineLayoutCreateInfo ci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    ci.setLayoutCount = uint32_t(sets.size());
    ci.pSetLayouts = sets.data();
    VkPipelineLayout l = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreatePipelineLayout(device, &ci, nullptr, &l), expect);
    if (l) pipelineLayouts.push_back(l);
    return l;
  }
  // A push descriptor template of `entries` for set `set` of `layout` at `bindPoint`.
  VkDescriptorUpdateTemplate makePushTemplate(const std::vector<VkDescriptorUpdateTemplateEntry>& entries,
                                              VkPipelineLayout layout, uint32_t set,
                                              VkPipelineBindPoint bindPoint = VK_PIPELINE_BIND_POINT_COMPUTE,
                                              VkResult expect = VK_SUCCESS) {
    VkDescriptorUpdateTemplateCreateInfo ci{VK_STRUCTURE_TYPE_DESCRIPTOR_UPDATE_TEMPLATE_CREATE_INFO};
    ci.descriptorUpdateEntryCount = uint32_t(entries.size());
    ci.pDescriptorUpdateEntries = entries.data();
    ci.templateType = VK_DESCRIPTOR_UPDATE_TEMPLATE_TYPE_PUSH_DESCRIPTORS_KHR;
    ci.pipelineBindPoint = bindPoint;
    ci.pipelineLayout = layout;
    ci.set = set;
    VkDescriptorUpdateTemplate t = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreateDescriptorUpdateTemplate(device, &ci, nullptr, &t), expect);
    if (t) templates.push_back(t);
    return t;
  }

  HostBuffer& buffer(VkDeviceSize size, VkBufferUsageFlags usage) {
    buffers.push_back(createHostBuffer(size, usage));
    std::memset(buffers.back().data, 0xee, size);
    return buffers.back();
  }
  static uint32_t* words(const HostBuffer& b) { return static_cast<uint32_t*>(b.data); }
  HostBuffer& params(uint32_t mul, uint32_t add) {
    HostBuffer& b = buffer(256, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
    const Params p{mul, add};
    std::memcpy(b.data, &p, sizeof p);
    return b;
  }
  // Binds the pipeline and set 0.
  void bindCompute(VkCommandBuffer cb) {
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipelineLayout, 0, 1, &set0, 0, nullptr);
  }
  // What push_descriptor.comp writes with `p` over the fixture's src and bias.
  static std::vector<uint32_t> expected(const Params& p) {
    std::vector<uint32_t> w(kN);
    for (uint32_t i = 0; i < kN; ++i) w[i] = (3 * i + 1) * p.mul + p.add + 1000 * i;
    return w;
  }
  static std::vector<uint32_t> contents(const HostBuffer& b) { return {words(b), words(b) + kN}; }

  // vkrt reported `vuid` once (and nothing else); the layer reported it `layer` times.
  void expectReported(const char* vuid, size_t layer = 1) {
    EXPECT_EQ(takeLayerMessages(vuid), validationEnabled ? layer : 0) << "the layer disagrees on " << vuid;
    expectVkrtMessage(vuid);
  }
  void expectQuiet() {
    const std::vector<Message> m = vkrtMessages();
    EXPECT_TRUE(m.empty()) << m[0].text;
  }

  PFN_vkCmdPushDescriptorSetKHR cmdPush = nullptr;
  PFN_vkCmdPushDescriptorSetWithTemplateKHR cmdPushTemplate = nullptr;
  VkDescriptorSetLayout setLayout0 = VK_NULL_HANDLE, pushLayout = VK_NULL_HANDLE;
  VkPipelineLayout pipelineLayout = VK_NULL_HANDLE;
  VkShaderModule module = VK_NULL_HANDLE;
  VkPipeline pipeline = VK_NULL_HANDLE;
  VkDescriptorPool pool = VK_NULL_HANDLE;
  VkDescriptorSet set0 = VK_NULL_HANDLE;
  HostBuffer bias, src;
  std::deque<HostBuffer> buffers;  // a deque: references returned by buffer() stay valid
  std::vector<VkDescriptorSetLayout> layouts;
  std::vector<VkPipelineLayout> pipelineLayouts;
  std::vector<VkDescriptorUpdateTemplate> templates;
};

TEST_F(PushDescriptorTest, ExtensionPropertyAndCommands) {
  uint32_t n = 0;
  vkEnumerateDeviceExtensionProperties(physicalDevice, nullptr, &n, nullptr);
  std::vector<VkExtensionProperties> ext(n);
  vkEnumerateDeviceExtensionProperties(physicalDevice, nullptr, &n, ext.data());
  uint32_t version = 0;
  for (const VkExtensionProperties& e : ext)
    if (std::strcmp(e.extensionName, VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME) == 0) version = e.specVersion;
  EXPECT_EQ(version, uint32_t(VK_KHR_PUSH_DESCRIPTOR_SPEC_VERSION));
  VkPhysicalDevicePushDescriptorPropertiesKHR push{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PUSH_DESCRIPTOR_PROPERTIES_KHR};
  push.maxPushDescriptors = 0xdead;
  VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &push};
  vkGetPhysicalDeviceProperties2(physicalDevice, &p2);
  EXPECT_GE(push.maxPushDescriptors, 32u) << "the specification's required limit";
  EXPECT_NE(push.maxPushDescriptors, 0xdeadu);
  EXPECT_EQ(push.pNext, nullptr);
  // The fixture's SetUp resolved both commands on this device, which enables the extension.
}

// One push of a uniform buffer and two storage buffers beside an allocated set 0: the dispatch reads and writes
// them.
TEST_F(PushDescriptorTest, ComputeReadsAndWritesPushedBuffers) {
  HostBuffer& p = params(5, 7);
  HostBuffer& dst = buffer(kN * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  VkDescriptorBufferInfo infos[3] = {
      {p.buffer, 0, sizeof(Params)}, {src.buffer, 0, VK_WHOLE_SIZE}, {dst.buffer, 0, VK_WHOLE_SIZE}};
  VkWriteDescriptorSet w[3] = {bufferWrite(0, kUniform, &infos[0]), bufferWrite(1, kStorage, &infos[1]),
                               bufferWrite(2, kStorage, &infos[2])};
  VkCommandBuffer cb = beginOneTime();
  bindCompute(cb);
  cmdPush(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipelineLayout, 1, 3, w);
  vkCmdDispatch(cb, kN / 16, 1, 1);
  submitAndWait(cb);
  EXPECT_EQ(contents(dst), expected({5, 7}));
  expectQuiet();
}

// Three dispatches in one command buffer, a push before each: the second push changes the uniform buffer and the
// destination only (the source stays from the first), the third (one write running from binding 1 into binding 2)
// the source and destination only; the application's VkDescriptorBufferInfo arrays are overwritten after each push,
// before the submission. Each dispatch sees the descriptors pushed before it.
TEST_F(PushDescriptorTest, EachDispatchSeesItsOwnPush) {
  HostBuffer& pa = params(5, 7);
  HostBuffer& pb = params(11, 13);
  HostBuffer& src2 = buffer(kN * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  for (uint32_t i = 0; i < kN; ++i) words(src2)[i] = 3 * i + 1;  // the same source values in another buffer
  HostBuffer& d1 = buffer(kN * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  HostBuffer& d2 = buffer(kN * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  HostBuffer& d3 = buffer(kN * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  VkCommandBuffer cb = beginOneTime();
  bindCompute(cb);
  std::array<VkDescriptorBufferInfo, 3> infos = {
      {{pa.buffer, 0, sizeof(Params)}, {src.buffer, 0, VK_WHOLE_SIZE}, {d1.buffer, 0, VK_WHOLE_SIZE}}};
  VkWriteDescriptorSet w[3] = {bufferWrite(0, kUniform, &infos[0]), bufferWrite(1, kStorage, &infos[1]),
                               bufferWrite(2, kStorage, &infos[2])};
  cmdPush(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipelineLayout, 1, 3, w);
  vkCmdDispatch(cb, kN / 16, 1, 1);
  infos = {{{pb.buffer, 0, sizeof(Params)}, {VK_NULL_HANDLE, 0, 0}, {d2.buffer, 0, VK_WHOLE_SIZE}}};
  VkWriteDescriptorSet w2[2] = {bufferWrite(0, kUniform, &infos[0]), bufferWrite(2, kStorage, &infos[2])};
  cmdPush(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipelineLayout, 1, 2, w2);
  vkCmdDispatch(cb, kN / 16, 1, 1);
  infos = {{{VK_NULL_HANDLE, 0, 0}, {src2.buffer, 0, VK_WHOLE_SIZE}, {d3.buffer, 0, VK_WHOLE_SIZE}}};
  VkWriteDescriptorSet w3 = bufferWrite(1, kStorage, &infos[1], 2);  // bindings 1 and 2
  cmdPush(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipelineLayout, 1, 1, &w3);
  vkCmdDispatch(cb, kN / 16, 1, 1);
  infos = {};  // the application reuses its memory before the command buffer runs
  submitAndWait(cb);
  EXPECT_EQ(contents(d1), expected({5, 7}));
  EXPECT_EQ(contents(d2), expected({11, 13})) << "the second push kept the first one's source";
  EXPECT_EQ(contents(d3), expected({11, 13})) << "the third push kept the second one's uniform buffer";
  expectQuiet();
}

// The same through a push descriptor template (one entry for the uniform buffer, one of two descriptors with a
// stride for the source and destination), its data changed between two pushes of one command buffer.
TEST_F(PushDescriptorTest, TemplatePushesBetweenDispatches) {
  struct Data {
    uint32_t pad;
    VkDescriptorBufferInfo params;
    VkDescriptorBufferInfo buffers[2];  // src, dst
  };
  VkDescriptorUpdateTemplate t =
      makePushTemplate({{0, 0, 1, kUniform, offsetof(Data, params), 0},
                        {1, 0, 2, kStorage, offsetof(Data, buffers), sizeof(VkDescriptorBufferInfo)}},
                       pipelineLayout, 1);
  ASSERT_NE(t, VK_NULL_HANDLE);
  HostBuffer& pa = params(2, 3);
  HostBuffer& pb = params(17, 19);
  HostBuffer& d1 = buffer(kN * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  HostBuffer& d2 = buffer(kN * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  Data data{0, {pa.buffer, 0, VK_WHOLE_SIZE}, {{src.buffer, 0, VK_WHOLE_SIZE}, {d1.buffer, 0, VK_WHOLE_SIZE}}};
  VkCommandBuffer cb = beginOneTime();
  bindCompute(cb);
  cmdPushTemplate(cb, t, pipelineLayout, 1, &data);
  vkCmdDispatch(cb, kN / 16, 1, 1);
  data.params.buffer = pb.buffer;
  data.buffers[1].buffer = d2.buffer;
  cmdPushTemplate(cb, t, pipelineLayout, 1, &data);
  vkCmdDispatch(cb, kN / 16, 1, 1);
  std::memset(&data, 0, sizeof data);
  submitAndWait(cb);
  EXPECT_EQ(contents(d1), expected({2, 3}));
  EXPECT_EQ(contents(d2), expected({17, 19}));
  expectQuiet();
}

// A command buffer submitted twice reads the same pushed descriptors both times (the pushed set is recorded, not
// consumed), and a vkCmdBindDescriptorSets of set 0 after the push leaves the push set bound.
TEST_F(PushDescriptorTest, ResubmittedCommandBufferKeepsItsPush) {
  HostBuffer& p = params(9, 1);
  HostBuffer& dst = buffer(kN * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  VkDescriptorBufferInfo infos[3] = {
      {p.buffer, 0, sizeof(Params)}, {src.buffer, 0, VK_WHOLE_SIZE}, {dst.buffer, 0, VK_WHOLE_SIZE}};
  VkWriteDescriptorSet w[3] = {bufferWrite(0, kUniform, &infos[0]), bufferWrite(1, kStorage, &infos[1]),
                               bufferWrite(2, kStorage, &infos[2])};
  VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  ai.commandPool = commandPool;
  ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ai.commandBufferCount = 1;
  VkCommandBuffer cb = VK_NULL_HANDLE;
  ASSERT_EQ(vkAllocateCommandBuffers(device, &ai, &cb), VK_SUCCESS);
  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  ASSERT_EQ(vkBeginCommandBuffer(cb, &bi), VK_SUCCESS);
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
  cmdPush(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipelineLayout, 1, 3, w);
  vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipelineLayout, 0, 1, &set0, 0, nullptr);
  vkCmdDispatch(cb, kN / 16, 1, 1);
  ASSERT_EQ(vkEndCommandBuffer(cb), VK_SUCCESS);
  for (int round = 0; round < 2; ++round) {
    std::memset(dst.data, 0xee, dst.size);
    VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cb;
    ASSERT_EQ(vkQueueSubmit(queue, 1, &si, VK_NULL_HANDLE), VK_SUCCESS);
    ASSERT_EQ(vkQueueWaitIdle(queue), VK_SUCCESS);
    EXPECT_EQ(contents(dst), expected({9, 1})) << "submission " << round;
  }
  vkFreeCommandBuffers(device, commandPool, 1, &cb);
  expectQuiet();
}

// A secondary command buffer pushes and dispatches on its own (it inherits no push from the primary, and its pushed
// set lives as long as its recording); the primary's own push before vkCmdExecuteCommands and its dispatch read the
// primary's descriptors.
TEST_F(PushDescriptorTest, SecondaryCommandBufferPushesItsOwnDescriptors) {
  HostBuffer& pa = params(3, 5);
  HostBuffer& pb = params(7, 9);
  HostBuffer& d1 = buffer(kN * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  HostBuffer& d2 = buffer(kN * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  auto writes = [&](const HostBuffer& p, const HostBuffer& dst, VkDescriptorBufferInfo(&infos)[3],
                    VkWriteDescriptorSet(&w)[3]) {
    infos[0] = {p.buffer, 0, sizeof(Params)};
    infos[1] = {src.buffer, 0, VK_WHOLE_SIZE};
    infos[2] = {dst.buffer, 0, VK_WHOLE_SIZE};
    w[0] = bufferWrite(0, kUniform, &infos[0]);
    w[1] = bufferWrite(1, kStorage, &infos[1]);
    w[2] = bufferWrite(2, kStorage, &infos[2]);
  };
  VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  ai.commandPool = commandPool;
  ai.level = VK_COMMAND_BUFFER_LEVEL_SECONDARY;
  ai.commandBufferCount = 1;
  VkCommandBuffer sec = VK_NULL_HANDLE;
  ASSERT_EQ(vkAllocateCommandBuffers(device, &ai, &sec), VK_SUCCESS);
  VkCommandBufferInheritanceInfo inh{VK_STRUCTURE_TYPE_COMMAND_BUFFER_INHERITANCE_INFO};
  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  bi.pInheritanceInfo = &inh;
  ASSERT_EQ(vkBeginCommandBuffer(sec, &bi), VK_SUCCESS);
  {
    VkDescriptorBufferInfo infos[3];
    VkWriteDescriptorSet w[3];
    writes(pb, d2, infos, w);
    bindCompute(sec);
    cmdPush(sec, VK_PIPELINE_BIND_POINT_COMPUTE, pipelineLayout, 1, 3, w);
    vkCmdDispatch(sec, kN / 16, 1, 1);
  }
  ASSERT_EQ(vkEndCommandBuffer(sec), VK_SUCCESS);
  VkCommandBuffer cb = beginOneTime();
  {
    VkDescriptorBufferInfo infos[3];
    VkWriteDescriptorSet w[3];
    writes(pa, d1, infos, w);
    bindCompute(cb);
    cmdPush(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipelineLayout, 1, 3, w);
    vkCmdDispatch(cb, kN / 16, 1, 1);
  }
  vkCmdExecuteCommands(cb, 1, &sec);
  submitAndWait(cb);
  EXPECT_EQ(contents(d1), expected({3, 5}));
  EXPECT_EQ(contents(d2), expected({7, 9}));
  vkFreeCommandBuffers(device, commandPool, 1, &sec);
  expectQuiet();
}

// Images through pushed descriptors (push_descriptor_image.comp): a sampled image and a sampler binding with an
// immutable sampler (pushed by writing the binding, with no pImageInfo: its samplers would be ignored), a combined
// image sampler
// with an immutable sampler, and a storage image; two dispatches, the second push swapping the two textures and
// changing the storage image. Every texel is checked against the uploaded ones.
TEST_F(PushDescriptorTest, ComputeSamplesAndStoresPushedImages) {
  VkSamplerCreateInfo sci{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
  sci.magFilter = sci.minFilter = VK_FILTER_NEAREST;
  sci.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
  sci.addressModeU = sci.addressModeV = sci.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
  VkSampler sampler = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateSampler(device, &sci, nullptr, &sampler), VK_SUCCESS);
  VkDescriptorSetLayout l = makeLayout({{0, VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, 1, kCompute, nullptr},
                                        {1, VK_DESCRIPTOR_TYPE_SAMPLER, 1, kCompute, &sampler},
                                        {2, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, kCompute, &sampler},
                                        {3, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, kCompute, nullptr}},
                                       kPush);
  ASSERT_NE(l, VK_NULL_HANDLE);
  VkPipelineLayout pl = makePipelineLayout({l});
  VkShaderModuleCreateInfo sm{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  sm.codeSize = sizeof kSpv_push_descriptor_image_comp;
  sm.pCode = kSpv_push_descriptor_image_comp;
  VkShaderModule m = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateShaderModule(device, &sm, nullptr, &m), VK_SUCCESS);
  VkComputePipelineCreateInfo ci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
  ci.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
  ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  ci.stage.module = m;
  ci.stage.pName = "main";
  ci.layout = pl;
  VkPipeline pipe = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateComputePipelines(device, VK_NULL_HANDLE, 1, &ci, nullptr, &pipe), VK_SUCCESS);

  // Two RGBA8 textures and two R32_UINT storage images of 4 x 4, their memory and views.
  struct Image {
    VkImage image = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkImageView view = VK_NULL_HANDLE;
  };
  auto makeImage = [&](VkFormat format, VkImageUsageFlags usage) {
    Image img;
    VkImageCreateInfo ici{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    ici.imageType = VK_IMAGE_TYPE_2D;
    ici.format = format;
    ici.extent = {4, 4, 1};
    ici.mipLevels = ici.arrayLayers = 1;
    ici.samples = VK_SAMPLE_COUNT_1_BIT;
    ici.tiling = VK_IMAGE_TILING_OPTIMAL;
    ici.usage = usage;
    EXPECT_EQ(vkCreateImage(device, &ici, nullptr, &img.image), VK_SUCCESS);
    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(device, img.image, &req);
    VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    mai.allocationSize = req.size;
    mai.memoryTypeIndex = memoryTypeIndex(req.memoryTypeBits, 0);
    EXPECT_EQ(vkAllocateMemory(device, &mai, nullptr, &img.memory), VK_SUCCESS);
    EXPECT_EQ(vkBindImageMemory(device, img.image, img.memory, 0), VK_SUCCESS);
    VkImageViewCreateInfo vci{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    vci.image = img.image;
    vci.viewType = VK_IMAGE_VIEW_TYPE_2D;
    vci.format = format;
    vci.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    EXPECT_EQ(vkCreateImageView(device, &vci, nullptr, &img.view), VK_SUCCESS);
    return img;
  };
  constexpr VkImageUsageFlags kSampled = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  constexpr VkImageUsageFlags kStorageImg = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  Image tex[2] = {makeImage(VK_FORMAT_R8G8B8A8_UNORM, kSampled), makeImage(VK_FORMAT_R8G8B8A8_UNORM, kSampled)};
  Image out[2] = {makeImage(VK_FORMAT_R32_UINT, kStorageImg), makeImage(VK_FORMAT_R32_UINT, kStorageImg)};
  HostBuffer& up = buffer(2 * 16 * 4, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  for (uint32_t i = 0; i < 32; ++i) words(up)[i] = 0x01000193u * (i + 1) ^ 0x9e3779b9u;
  HostBuffer& down = buffer(2 * 16 * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT);

  auto barrier = [](VkCommandBuffer cb, VkImage image, VkImageLayout from, VkImageLayout to, VkAccessFlags srcAccess,
                    VkAccessFlags dstAccess, VkPipelineStageFlags srcStage, VkPipelineStageFlags dstStage) {
    VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    b.srcAccessMask = srcAccess;
    b.dstAccessMask = dstAccess;
    b.oldLayout = from;
    b.newLayout = to;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image;
    b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    vkCmdPipelineBarrier(cb, srcStage, dstStage, 0, 0, nullptr, 0, nullptr, 1, &b);
  };
  constexpr VkPipelineStageFlags kXferStage = VK_PIPELINE_STAGE_TRANSFER_BIT;
  constexpr VkPipelineStageFlags kShader = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT;
  VkCommandBuffer cb = beginOneTime();
  for (uint32_t k = 0; k < 2; ++k) {
    barrier(cb, tex[k].image, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 0,
            VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, kXferStage);
    VkBufferImageCopy r{k * 64, 0, 0, {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1}, {0, 0, 0}, {4, 4, 1}};
    vkCmdCopyBufferToImage(cb, up.buffer, tex[k].image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &r);
    barrier(cb, tex[k].image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
            VK_ACCESS_TRANSFER_WRITE_BIT, VK_ACCESS_SHADER_READ_BIT, kXferStage, kShader);
    barrier(cb, out[k].image, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL, 0, VK_ACCESS_SHADER_WRITE_BIT,
            VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, kShader);
  }
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipe);
  constexpr VkImageLayout kRead = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
  std::array<VkDescriptorImageInfo, 4> ii = {{{VK_NULL_HANDLE, tex[0].view, kRead},
                                              {VK_NULL_HANDLE, VK_NULL_HANDLE, VK_IMAGE_LAYOUT_UNDEFINED},
                                              {VK_NULL_HANDLE, tex[1].view, kRead},
                                              {VK_NULL_HANDLE, out[0].view, VK_IMAGE_LAYOUT_GENERAL}}};
  const VkDescriptorType types[4] = {VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, VK_DESCRIPTOR_TYPE_SAMPLER,
                                     VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE};
  VkWriteDescriptorSet w[4];
  for (uint32_t b = 0; b < 4; ++b) {
    w[b] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    w[b].dstBinding = b;
    w[b].descriptorCount = 1;
    w[b].descriptorType = types[b];
    w[b].pImageInfo = &ii[b];
  }
  w[1].pImageInfo = nullptr;  // the immutable sampler's binding: pImageInfo is not read (06494 leaves samplers out)
  cmdPush(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pl, 0, 4, w);
  vkCmdDispatch(cb, 1, 1, 1);
  ii[0].imageView = tex[1].view;
  ii[2].imageView = tex[0].view;
  ii[3].imageView = out[1].view;
  const VkWriteDescriptorSet second[3] = {w[0], w[2], w[3]};  // the sampler binding stays pushed
  cmdPush(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pl, 0, 3, second);
  vkCmdDispatch(cb, 1, 1, 1);
  ii = {};
  for (uint32_t k = 0; k < 2; ++k) {
    barrier(cb, out[k].image, VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_GENERAL, VK_ACCESS_SHADER_WRITE_BIT,
            VK_ACCESS_TRANSFER_READ_BIT, kShader, kXferStage);
    VkBufferImageCopy r{k * 64, 0, 0, {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1}, {0, 0, 0}, {4, 4, 1}};
    vkCmdCopyImageToBuffer(cb, out[k].image, VK_IMAGE_LAYOUT_GENERAL, down.buffer, 1, &r);
  }
  submitAndWait(cb);
  for (uint32_t k = 0; k < 2; ++k) {
    SCOPED_TRACE(k == 0 ? "first dispatch" : "second dispatch");
    const uint32_t* a = words(up) + (k == 0 ? 0 : 16);  // the sampled image's texels
    const uint32_t* b = words(up) + (k == 0 ? 16 : 0);  // the combined image sampler's
    for (uint32_t i = 0; i < 16; ++i) EXPECT_EQ(words(down)[k * 16 + i], a[i] ^ (b[i] << 1)) << "texel " << i;
  }
  expectQuiet();
  for (Image* imgs : {tex, out})
    for (uint32_t k = 0; k < 2; ++k) {
      vkDestroyImageView(device, imgs[k].view, nullptr);
      vkDestroyImage(device, imgs[k].image, nullptr);
      vkFreeMemory(device, imgs[k].memory, nullptr);
    }
  vkDestroyPipeline(device, pipe, nullptr);
  vkDestroyShaderModule(device, m, nullptr);
  vkDestroySampler(device, sampler, nullptr);
}

// ---- the rules, each broken once and kept once ----

// VUID-VkDescriptorSetLayoutCreateInfo-flags-00280, -02208, -00281, VUID-VkDescriptorSetLayoutBindingFlagsCreateInfo-
// flags-03003: what a push layout may not hold; the same bindings are fine in a layout that is not for pushing, and
// maxPushDescriptors descriptors are fine in a push layout.
TEST_F(PushDescriptorTest, PushLayoutRules) {
  VkPhysicalDevicePushDescriptorPropertiesKHR push{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PUSH_DESCRIPTOR_PROPERTIES_KHR};
  VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &push};
  vkGetPhysicalDeviceProperties2(physicalDevice, &p2);
  const uint32_t max = push.maxPushDescriptors;

  const VkDescriptorSetLayoutBinding dynamic{0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC, 1, kCompute, nullptr};
  EXPECT_EQ(makeLayout({dynamic}, kPush, {}, VK_ERROR_VALIDATION_FAILED_EXT), VK_NULL_HANDLE);
  expectReported("VUID-VkDescriptorSetLayoutCreateInfo-flags-00280");
  EXPECT_NE(makeLayout({dynamic}), VK_NULL_HANDLE);
  expectQuiet();

  const VkDescriptorSetLayoutBinding block{0, VK_DESCRIPTOR_TYPE_INLINE_UNIFORM_BLOCK, 16, kCompute, nullptr};
  EXPECT_EQ(makeLayout({block}, kPush, {}, VK_ERROR_VALIDATION_FAILED_EXT), VK_NULL_HANDLE);
  expectReported("VUID-VkDescriptorSetLayoutCreateInfo-flags-02208");
  EXPECT_NE(makeLayout({block}), VK_NULL_HANDLE);
  expectQuiet();

  EXPECT_EQ(makeLayout({{0, kStorage, max, kCompute, nullptr}, {1, kUniform, 1, kCompute, nullptr}}, kPush, {},
                       VK_ERROR_VALIDATION_FAILED_EXT),
            VK_NULL_HANDLE);
  expectReported("VUID-VkDescriptorSetLayoutCreateInfo-flags-00281");
  EXPECT_NE(makeLayout({{0, kStorage, max - 1, kCompute, nullptr}, {1, kUniform, 1, kCompute, nullptr}}, kPush),
            VK_NULL_HANDLE);
  expectQuiet();

  const VkDescriptorSetLayoutBinding storage{0, kStorage, 4, kCompute, nullptr};
  EXPECT_EQ(makeLayout({storage}, kPush, {VK_DESCRIPTOR_BINDING_VARIABLE_DESCRIPTOR_COUNT_BIT},
                       VK_ERROR_VALIDATION_FAILED_EXT),
            VK_NULL_HANDLE);
  expectReported("VUID-VkDescriptorSetLayoutBindingFlagsCreateInfo-flags-03003");
  EXPECT_EQ(makeLayout({storage}, kPush | VK_DESCRIPTOR_SET_LAYOUT_CREATE_UPDATE_AFTER_BIND_POOL_BIT,
                       {VK_DESCRIPTOR_BINDING_UPDATE_AFTER_BIND_BIT}, VK_ERROR_VALIDATION_FAILED_EXT),
            VK_NULL_HANDLE);
  expectReported("VUID-VkDescriptorSetLayoutBindingFlagsCreateInfo-flags-03003");
  EXPECT_NE(makeLayout({storage}, kPush, {VK_DESCRIPTOR_BINDING_PARTIALLY_BOUND_BIT}), VK_NULL_HANDLE);
  EXPECT_NE(makeLayout({storage}, 0, {VK_DESCRIPTOR_BINDING_VARIABLE_DESCRIPTOR_COUNT_BIT}), VK_NULL_HANDLE);
  expectQuiet();

  // vkGetDescriptorSetLayoutSupport answers by the same rules.
  VkDescriptorSetLayoutBinding big{0, kStorage, max + 1, kCompute, nullptr};
  VkDescriptorSetLayoutCreateInfo ci{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  ci.flags = kPush;
  ci.bindingCount = 1;
  ci.pBindings = &big;
  VkDescriptorSetLayoutSupport support{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_SUPPORT};
  vkGetDescriptorSetLayoutSupport(device, &ci, &support);
  EXPECT_FALSE(support.supported);
  big.descriptorCount = max;
  vkGetDescriptorSetLayoutSupport(device, &ci, &support);
  EXPECT_TRUE(support.supported);
  expectQuiet();
}

// VUID-VkPipelineLayoutCreateInfo-pSetLayouts-00293 and VUID-VkDescriptorSetAllocateInfo-pSetLayouts-00308.
TEST_F(PushDescriptorTest, PipelineLayoutAndAllocationRules) {
  VkDescriptorSetLayout other = makeLayout({{0, kStorage, 1, kCompute, nullptr}}, kPush);
  EXPECT_EQ(makePipelineLayout({pushLayout, other}, VK_ERROR_VALIDATION_FAILED_EXT), VK_NULL_HANDLE);
  expectReported("VUID-VkPipelineLayoutCreateInfo-pSetLayouts-00293");
  EXPECT_NE(makePipelineLayout({setLayout0, other}), VK_NULL_HANDLE);
  EXPECT_NE(makePipelineLayout({other, setLayout0, setLayout0}), VK_NULL_HANDLE);
  expectQuiet();

  VkDescriptorPoolSize sizes[2] = {{kStorage, 4}, {kUniform, 4}};
  VkDescriptorPoolCreateInfo dp{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  dp.maxSets = 2;
  dp.poolSizeCount = 2;
  dp.pPoolSizes = sizes;
  VkDescriptorPool p = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateDescriptorPool(device, &dp, nullptr, &p), VK_SUCCESS);
  VkDescriptorSetAllocateInfo da{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  da.descriptorPool = p;
  da.descriptorSetCount = 1;
  da.pSetLayouts = &pushLayout;
  VkDescriptorSet s = VK_NULL_HANDLE;
  EXPECT_EQ(vkAllocateDescriptorSets(device, &da, &s), VK_ERROR_VALIDATION_FAILED_EXT);
  EXPECT_EQ(s, VK_NULL_HANDLE);
  expectReported("VUID-VkDescriptorSetAllocateInfo-pSetLayouts-00308");
  da.pSetLayouts = &setLayout0;
  EXPECT_EQ(vkAllocateDescriptorSets(device, &da, &s), VK_SUCCESS);
  expectQuiet();
  vkDestroyDescriptorPool(device, p, nullptr);
}

// VUID-VkDescriptorUpdateTemplateCreateInfo-templateType-00353: the template's set is the layout's push set.
TEST_F(PushDescriptorTest, PushTemplateCreationRules) {
  const std::vector<VkDescriptorUpdateTemplateEntry> entries = {{0, 0, 1, kStorage, 0, 0}};
  EXPECT_EQ(
      makePushTemplate(entries, pipelineLayout, 0, VK_PIPELINE_BIND_POINT_COMPUTE, VK_ERROR_VALIDATION_FAILED_EXT),
      VK_NULL_HANDLE);
  expectReported("VUID-VkDescriptorUpdateTemplateCreateInfo-templateType-00353");
  EXPECT_EQ(
      makePushTemplate(entries, pipelineLayout, 2, VK_PIPELINE_BIND_POINT_COMPUTE, VK_ERROR_VALIDATION_FAILED_EXT),
      VK_NULL_HANDLE);
  expectReported("VUID-VkDescriptorUpdateTemplateCreateInfo-templateType-00353");
  EXPECT_NE(makePushTemplate({{1, 0, 1, kStorage, 0, 0}}, pipelineLayout, 1), VK_NULL_HANDLE);
  EXPECT_NE(makePushTemplate({{0, 0, 1, kUniform, 0, 0}}, pipelineLayout, 1, VK_PIPELINE_BIND_POINT_GRAPHICS),
            VK_NULL_HANDLE);
  expectQuiet();
}

// VUID-vkCmdPushDescriptorSetKHR-set-00364, -set-00365, -descriptorWriteCount-arraylength, and a write's own rule
// (VUID-VkWriteDescriptorSet-descriptorType-00319): each refused push has no effect, so the dispatch after them
// reads the descriptors of the valid push before them.
TEST_F(PushDescriptorTest, PushCommandRules) {
  HostBuffer& pa = params(4, 6);
  HostBuffer& pb = params(8, 10);
  HostBuffer& dst = buffer(kN * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  HostBuffer& other = buffer(kN * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  VkDescriptorBufferInfo infos[3] = {
      {pa.buffer, 0, sizeof(Params)}, {src.buffer, 0, VK_WHOLE_SIZE}, {dst.buffer, 0, VK_WHOLE_SIZE}};
  VkWriteDescriptorSet w[3] = {bufferWrite(0, kUniform, &infos[0]), bufferWrite(1, kStorage, &infos[1]),
                               bufferWrite(2, kStorage, &infos[2])};
  VkCommandBuffer cb = beginOneTime();
  bindCompute(cb);
  cmdPush(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipelineLayout, 1, 3, w);
  expectQuiet();

  const VkDescriptorBufferInfo bad[2] = {{pb.buffer, 0, sizeof(Params)}, {other.buffer, 0, VK_WHOLE_SIZE}};
  VkWriteDescriptorSet uniformWrite = bufferWrite(0, kUniform, &bad[0]);
  VkWriteDescriptorSet dstWrite = bufferWrite(2, kStorage, &bad[1]);
  cmdPush(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipelineLayout, 2, 1, &uniformWrite);
  expectReported("VUID-vkCmdPushDescriptorSetKHR-set-00364");
  cmdPush(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipelineLayout, 0, 1, &dstWrite);
  expectReported("VUID-vkCmdPushDescriptorSetKHR-set-00365");
  cmdPush(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipelineLayout, 1, 0, &uniformWrite);
  expectReported("VUID-vkCmdPushDescriptorSetKHR-descriptorWriteCount-arraylength");
  // Binding 2 is a storage buffer: a uniform buffer write to it is refused, with the valid write before it.
  VkWriteDescriptorSet mismatched[2] = {uniformWrite, bufferWrite(2, kUniform, &bad[0])};
  cmdPush(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipelineLayout, 1, 2, mismatched);
  expectReported("VUID-VkWriteDescriptorSet-descriptorType-00319");
  vkCmdDispatch(cb, kN / 16, 1, 1);
  submitAndWait(cb);
  EXPECT_EQ(contents(dst), expected({4, 6})) << "a refused push changed the pushed descriptors";
  for (uint32_t i = 0; i < kN; ++i) EXPECT_EQ(words(other)[i], 0xeeeeeeeeu);
  expectQuiet();
}

// VUID-vkCmdPushDescriptorSetWithTemplateKHR-set-07305: the template push's set is the layout's push set; a refused
// one has no effect. (-set-07304, a set past the layout's, is in CommandAndTemplateParameterRules: the layer of
// 1.3.239 crashes on it.)
TEST_F(PushDescriptorTest, TemplatePushCommandRules) {
  VkDescriptorUpdateTemplate t = makePushTemplate({{0, 0, 1, kUniform, 0, 0}}, pipelineLayout, 1);
  ASSERT_NE(t, VK_NULL_HANDLE);
  HostBuffer& pa = params(4, 6);
  HostBuffer& pb = params(8, 10);
  HostBuffer& dst = buffer(kN * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  VkDescriptorBufferInfo infos[3] = {
      {pa.buffer, 0, sizeof(Params)}, {src.buffer, 0, VK_WHOLE_SIZE}, {dst.buffer, 0, VK_WHOLE_SIZE}};
  VkWriteDescriptorSet w[3] = {bufferWrite(0, kUniform, &infos[0]), bufferWrite(1, kStorage, &infos[1]),
                               bufferWrite(2, kStorage, &infos[2])};
  const VkDescriptorBufferInfo other{pb.buffer, 0, sizeof(Params)};
  VkCommandBuffer cb = beginOneTime();
  bindCompute(cb);
  cmdPush(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipelineLayout, 1, 3, w);
  cmdPushTemplate(cb, t, pipelineLayout, 0, &other);
  expectReported("VUID-vkCmdPushDescriptorSetWithTemplateKHR-set-07305", 0);  // the layer of 1.3.239 lacks the check
  vkCmdDispatch(cb, kN / 16, 1, 1);
  submitAndWait(cb);
  EXPECT_EQ(contents(dst), expected({4, 6}));
  expectQuiet();
}

// The rules whose misuse the layer is not fed (a bind point that is no enum value, null handles and pointers): vkrt
// alone, the layer off. Their valid side is every push of the tests above.
class PushDescriptorNoLayerTest : public PushDescriptorTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o = PushDescriptorTest::options();
    o.validation = false;
    return o;
  }
};

// VUID-vkCmdPushDescriptorSetKHR-pipelineBindPoint-parameter, -layout-parameter, -pDescriptorWrites-06494;
// VUID-vkCmdPushDescriptorSetWithTemplateKHR-descriptorUpdateTemplate-parameter, -layout-parameter, -set-07304,
// -pData-01686,
// -commandBuffer-00366 (a template of VK_DESCRIPTOR_UPDATE_TEMPLATE_TYPE_DESCRIPTOR_SET has no bind point);
// VUID-VkDescriptorUpdateTemplateCreateInfo-templateType-00351 and -00352. None of the refused pushes has an effect.
TEST_F(PushDescriptorNoLayerTest, CommandAndTemplateParameterRules) {
  HostBuffer& pa = params(4, 6);
  HostBuffer& dst = buffer(kN * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  VkDescriptorBufferInfo infos[3] = {
      {pa.buffer, 0, sizeof(Params)}, {src.buffer, 0, VK_WHOLE_SIZE}, {dst.buffer, 0, VK_WHOLE_SIZE}};
  VkWriteDescriptorSet w[3] = {bufferWrite(0, kUniform, &infos[0]), bufferWrite(1, kStorage, &infos[1]),
                               bufferWrite(2, kStorage, &infos[2])};
  VkDescriptorSetLayout imageLayout = makeLayout({{0, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, kCompute, nullptr}}, kPush);
  VkPipelineLayout imagePipelineLayout = makePipelineLayout({imageLayout});
  VkDescriptorUpdateTemplate t = makePushTemplate({{0, 0, 1, kUniform, 0, 0}}, pipelineLayout, 1);
  ASSERT_NE(t, VK_NULL_HANDLE);
  VkDescriptorUpdateTemplateEntry e{0, 0, 1, kStorage, 0, 0};
  VkDescriptorUpdateTemplateCreateInfo tci{VK_STRUCTURE_TYPE_DESCRIPTOR_UPDATE_TEMPLATE_CREATE_INFO};
  tci.descriptorUpdateEntryCount = 1;
  tci.pDescriptorUpdateEntries = &e;
  tci.templateType = VK_DESCRIPTOR_UPDATE_TEMPLATE_TYPE_DESCRIPTOR_SET;
  tci.descriptorSetLayout = setLayout0;
  VkDescriptorUpdateTemplate setTemplate = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateDescriptorUpdateTemplate(device, &tci, nullptr, &setTemplate), VK_SUCCESS);
  templates.push_back(setTemplate);

  EXPECT_EQ(makePushTemplate({{0, 0, 1, kUniform, 0, 0}}, pipelineLayout, 1, VkPipelineBindPoint(7),
                             VK_ERROR_VALIDATION_FAILED_EXT),
            VK_NULL_HANDLE);
  expectVkrtMessage("VUID-VkDescriptorUpdateTemplateCreateInfo-templateType-00351");
  EXPECT_EQ(makePushTemplate({{0, 0, 1, kUniform, 0, 0}}, VK_NULL_HANDLE, 1, VK_PIPELINE_BIND_POINT_COMPUTE,
                             VK_ERROR_VALIDATION_FAILED_EXT),
            VK_NULL_HANDLE);
  expectVkrtMessage("VUID-VkDescriptorUpdateTemplateCreateInfo-templateType-00352");

  const VkDescriptorBufferInfo other{pa.buffer, 0, sizeof(Params)};
  VkWriteDescriptorSet otherWrite = bufferWrite(2, kStorage, &other);
  VkCommandBuffer cb = beginOneTime();
  bindCompute(cb);
  cmdPush(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipelineLayout, 1, 3, w);
  expectQuiet();
  cmdPush(cb, VkPipelineBindPoint(7), pipelineLayout, 1, 1, &otherWrite);
  expectVkrtMessage("VUID-vkCmdPushDescriptorSetKHR-pipelineBindPoint-parameter");
  cmdPush(cb, VK_PIPELINE_BIND_POINT_COMPUTE, VK_NULL_HANDLE, 1, 1, &otherWrite);
  expectVkrtMessage("VUID-vkCmdPushDescriptorSetKHR-layout-parameter");
  VkWriteDescriptorSet imageWrite{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
  imageWrite.descriptorCount = 1;
  imageWrite.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
  cmdPush(cb, VK_PIPELINE_BIND_POINT_COMPUTE, imagePipelineLayout, 0, 1, &imageWrite);
  expectVkrtMessage("VUID-vkCmdPushDescriptorSetKHR-pDescriptorWrites-06494");
  cmdPushTemplate(cb, VK_NULL_HANDLE, pipelineLayout, 1, &other);
  expectVkrtMessage("VUID-vkCmdPushDescriptorSetWithTemplateKHR-descriptorUpdateTemplate-parameter");
  cmdPushTemplate(cb, t, VK_NULL_HANDLE, 1, &other);
  expectVkrtMessage("VUID-vkCmdPushDescriptorSetWithTemplateKHR-layout-parameter");
  cmdPushTemplate(cb, t, pipelineLayout, 2, &other);
  expectVkrtMessage("VUID-vkCmdPushDescriptorSetWithTemplateKHR-set-07304");
  cmdPushTemplate(cb, t, pipelineLayout, 1, nullptr);
  expectVkrtMessage("VUID-vkCmdPushDescriptorSetWithTemplateKHR-pData-01686");
  cmdPushTemplate(cb, setTemplate, pipelineLayout, 1, &other);
  expectVkrtMessage("VUID-vkCmdPushDescriptorSetWithTemplateKHR-commandBuffer-00366");
  vkCmdDispatch(cb, kN / 16, 1, 1);
  submitAndWait(cb);
  EXPECT_EQ(contents(dst), expected({4, 6}));
  expectQuiet();
}

// A dispatch that uses a binding of the push set no push wrote: VUID-vkCmdDispatch-None-08114, as for an allocated
// set whose descriptor was never written (the layer off: it reports the same at vkCmdDispatch).
TEST_F(PushDescriptorNoLayerTest, DispatchOfAnUnpushedBindingIsReported) {
  HostBuffer& pa = params(4, 6);
  HostBuffer& dst = buffer(kN * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  VkDescriptorBufferInfo infos[2] = {{pa.buffer, 0, sizeof(Params)}, {dst.buffer, 0, VK_WHOLE_SIZE}};
  VkWriteDescriptorSet w[2] = {bufferWrite(0, kUniform, &infos[0]), bufferWrite(2, kStorage, &infos[1])};
  VkCommandBuffer cb = beginOneTime();
  bindCompute(cb);
  cmdPush(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipelineLayout, 1, 2, w);  // binding 1 (src) is not pushed
  vkCmdDispatch(cb, kN / 16, 1, 1);
  submitAndWait(cb);
  const std::vector<Message> msgs = vkrtMessages();
  clearMessages();
  // The report, and the out-of-bounds report of the read through the null descriptor (which reads zeros).
  ASSERT_EQ(msgs.size(), 2u);
  EXPECT_EQ(msgs[0].idName, "VUID-vkCmdDispatch-None-08114");
  EXPECT_NE(msgs[0].text.find("set 1 binding 1"), std::string::npos) << msgs[0].text;
  EXPECT_NE(msgs[0].text.find("never pushed"), std::string::npos) << msgs[0].text;
  EXPECT_EQ(msgs[1].idName, "VKRT-shader-out-of-bounds");
  EXPECT_EQ(contents(dst), expected({0, 6})) << "src reads as zeros: dst[i] = 0 * 4 + 6 + bias[i]";
}

// VUID-vkCmdPushDescriptorSetKHR-pipelineBindPoint-00363 and VUID-vkCmdPushDescriptorSetWithTemplateKHR-
// commandBuffer-00366: a command buffer of the compute-only queue family pushes for compute, not for graphics. A
// second device with a queue of each family (the fixture's has family 0 only); the layer on.
TEST_F(PushDescriptorTest, GraphicsPushInAComputeOnlyFamilyIsRefused) {
  float prio = 1;
  VkDeviceQueueCreateInfo q[2] = {{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO},
                                  {VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO}};
  for (uint32_t f = 0; f < 2; ++f) {
    q[f].queueFamilyIndex = f;
    q[f].queueCount = 1;
    q[f].pQueuePriorities = &prio;
  }
  const char* ext = VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME;
  VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  dci.queueCreateInfoCount = 2;
  dci.pQueueCreateInfos = q;
  dci.enabledExtensionCount = 1;
  dci.ppEnabledExtensionNames = &ext;
  VkDevice dev = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateDevice(physicalDevice, &dci, nullptr, &dev), VK_SUCCESS);
  auto push = reinterpret_cast<PFN_vkCmdPushDescriptorSetKHR>(vkGetDeviceProcAddr(dev, "vkCmdPushDescriptorSetKHR"));
  auto pushTemplate = reinterpret_cast<PFN_vkCmdPushDescriptorSetWithTemplateKHR>(
      vkGetDeviceProcAddr(dev, "vkCmdPushDescriptorSetWithTemplateKHR"));
  ASSERT_NE(push, nullptr);
  ASSERT_NE(pushTemplate, nullptr);

  VkDescriptorSetLayoutBinding b{0, kUniform, 1, VK_SHADER_STAGE_FRAGMENT_BIT | kCompute, nullptr};
  VkDescriptorSetLayoutCreateInfo lci{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  lci.flags = kPush;
  lci.bindingCount = 1;
  lci.pBindings = &b;
  VkDescriptorSetLayout sl = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateDescriptorSetLayout(dev, &lci, nullptr, &sl), VK_SUCCESS);
  VkPipelineLayoutCreateInfo plci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  plci.setLayoutCount = 1;
  plci.pSetLayouts = &sl;
  VkPipelineLayout pl = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreatePipelineLayout(dev, &plci, nullptr, &pl), VK_SUCCESS);
  VkDescriptorUpdateTemplate templates[2] = {};  // graphics, compute
  for (int k = 0; k < 2; ++k) {
    VkDescriptorUpdateTemplateEntry e{0, 0, 1, kUniform, 0, 0};
    VkDescriptorUpdateTemplateCreateInfo tci{VK_STRUCTURE_TYPE_DESCRIPTOR_UPDATE_TEMPLATE_CREATE_INFO};
    tci.descriptorUpdateEntryCount = 1;
    tci.pDescriptorUpdateEntries = &e;
    tci.templateType = VK_DESCRIPTOR_UPDATE_TEMPLATE_TYPE_PUSH_DESCRIPTORS_KHR;
    tci.pipelineBindPoint = k == 0 ? VK_PIPELINE_BIND_POINT_GRAPHICS : VK_PIPELINE_BIND_POINT_COMPUTE;
    tci.pipelineLayout = pl;
    ASSERT_EQ(vkCreateDescriptorUpdateTemplate(dev, &tci, nullptr, &templates[k]), VK_SUCCESS);
  }
  VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bci.size = 256;
  bci.usage = VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT;
  VkBuffer buf = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateBuffer(dev, &bci, nullptr, &buf), VK_SUCCESS);
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(dev, buf, &req);
  VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  mai.allocationSize = req.size;
  mai.memoryTypeIndex = memoryTypeIndex(req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT);
  VkDeviceMemory mem = VK_NULL_HANDLE;
  ASSERT_EQ(vkAllocateMemory(dev, &mai, nullptr, &mem), VK_SUCCESS);
  ASSERT_EQ(vkBindBufferMemory(dev, buf, mem, 0), VK_SUCCESS);

  VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pci.queueFamilyIndex = 1;  // compute and transfer only
  VkCommandPool cmdPool = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateCommandPool(dev, &pci, nullptr, &cmdPool), VK_SUCCESS);
  VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  ai.commandPool = cmdPool;
  ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ai.commandBufferCount = 1;
  VkCommandBuffer cb = VK_NULL_HANDLE;
  ASSERT_EQ(vkAllocateCommandBuffers(dev, &ai, &cb), VK_SUCCESS);
  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  ASSERT_EQ(vkBeginCommandBuffer(cb, &bi), VK_SUCCESS);
  VkDescriptorBufferInfo info{buf, 0, VK_WHOLE_SIZE};
  VkWriteDescriptorSet w = bufferWrite(0, kUniform, &info);
  push(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, pl, 0, 1, &w);
  expectReported("VUID-vkCmdPushDescriptorSetKHR-pipelineBindPoint-00363");
  push(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pl, 0, 1, &w);
  expectQuiet();
  pushTemplate(cb, templates[0], pl, 0, &info);
  expectReported("VUID-vkCmdPushDescriptorSetWithTemplateKHR-commandBuffer-00366");
  pushTemplate(cb, templates[1], pl, 0, &info);
  expectQuiet();
  EXPECT_EQ(vkEndCommandBuffer(cb), VK_SUCCESS);

  vkDestroyCommandPool(dev, cmdPool, nullptr);
  vkDestroyBuffer(dev, buf, nullptr);
  vkFreeMemory(dev, mem, nullptr);
  for (VkDescriptorUpdateTemplate t : templates) vkDestroyDescriptorUpdateTemplate(dev, t, nullptr);
  vkDestroyPipelineLayout(dev, pl, nullptr);
  vkDestroyDescriptorSetLayout(dev, sl, nullptr);
  vkDestroyDevice(dev, nullptr);
}

// A device without VK_KHR_push_descriptor: its commands do not resolve, and a push layout or template is refused.
class PushDescriptorDisabledTest : public VulkanTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o;
    o.validation = false;  // the layer's own report of the disabled extension's flag is not what is tested
    o.deviceExtensions = {VK_KHR_DESCRIPTOR_UPDATE_TEMPLATE_EXTENSION_NAME};
    return o;
  }
};

TEST_F(PushDescriptorDisabledTest, CommandsDoNotResolveAndPushLayoutsAreRefused) {
  EXPECT_EQ(vkGetDeviceProcAddr(device, "vkCmdPushDescriptorSetKHR"), nullptr);
  EXPECT_EQ(vkGetDeviceProcAddr(device, "vkCmdPushDescriptorSetWithTemplateKHR"), nullptr)
      << "VK_KHR_descriptor_update_template provides it only with VK_KHR_push_descriptor";
  VkDescriptorSetLayoutBinding b{0, kStorage, 1, kCompute, nullptr};
  VkDescriptorSetLayoutCreateInfo ci{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  ci.flags = kPush;
  ci.bindingCount = 1;
  ci.pBindings = &b;
  VkDescriptorSetLayout l = VK_NULL_HANDLE;
  EXPECT_EQ(vkCreateDescriptorSetLayout(device, &ci, nullptr, &l), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkDescriptorSetLayoutCreateInfo-flags-parameter");
  ci.flags = 0;
  ASSERT_EQ(vkCreateDescriptorSetLayout(device, &ci, nullptr, &l), VK_SUCCESS);
  VkPipelineLayoutCreateInfo plci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  plci.setLayoutCount = 1;
  plci.pSetLayouts = &l;
  VkPipelineLayout pl = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreatePipelineLayout(device, &plci, nullptr, &pl), VK_SUCCESS);
  VkDescriptorUpdateTemplateEntry e{0, 0, 1, kStorage, 0, 0};
  VkDescriptorUpdateTemplateCreateInfo tci{VK_STRUCTURE_TYPE_DESCRIPTOR_UPDATE_TEMPLATE_CREATE_INFO};
  tci.descriptorUpdateEntryCount = 1;
  tci.pDescriptorUpdateEntries = &e;
  tci.templateType = VK_DESCRIPTOR_UPDATE_TEMPLATE_TYPE_PUSH_DESCRIPTORS_KHR;
  tci.pipelineBindPoint = VK_PIPELINE_BIND_POINT_COMPUTE;
  tci.pipelineLayout = pl;
  VkDescriptorUpdateTemplate t = VK_NULL_HANDLE;
  EXPECT_EQ(vkCreateDescriptorUpdateTemplate(device, &tci, nullptr, &t), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkDescriptorUpdateTemplateCreateInfo-templateType-parameter");
  vkDestroyPipelineLayout(device, pl, nullptr);
  vkDestroyDescriptorSetLayout(device, l, nullptr);
}

// ---- graphics ----

// Two full-screen draws with additive blending, a push of the fragment shader's color before each: the target holds
// their sum, so each draw read its own color (had both read the second, it would hold twice that).
class PushDescriptorDrawTest : public DrawTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o = DrawTest::options();
    o.deviceExtensions.push_back(VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME);
    return o;
  }
};

TEST_F(PushDescriptorDrawTest, EachDrawSeesItsOwnPushedColor) {
  auto cmdPush = deviceProc<PFN_vkCmdPushDescriptorSetKHR>("vkCmdPushDescriptorSetKHR");
  ASSERT_NE(cmdPush, nullptr);
  VkDescriptorSetLayoutBinding b{0, kUniform, 1, VK_SHADER_STAGE_FRAGMENT_BIT, nullptr};
  VkDescriptorSetLayoutCreateInfo ci{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  ci.flags = kPush;
  ci.bindingCount = 1;
  ci.pBindings = &b;
  VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateDescriptorSetLayout(device, &ci, nullptr, &setLayout), VK_SUCCESS);

  PipelineDesc d;
  d.vs = kSpv_draw_color_vert;
  d.vsBytes = sizeof kSpv_draw_color_vert;
  d.fs = kSpv_push_descriptor_frag;
  d.fsBytes = sizeof kSpv_push_descriptor_frag;
  d.bindings = {{0, sizeof(Vertex), VK_VERTEX_INPUT_RATE_VERTEX}};
  d.attributes = {{0, 0, VK_FORMAT_R32G32_SFLOAT, 0}, {1, 0, VK_FORMAT_R32G32B32A32_SFLOAT, 8}};
  d.blend = {VK_TRUE,
             VK_BLEND_FACTOR_ONE,
             VK_BLEND_FACTOR_ONE,
             VK_BLEND_OP_ADD,
             VK_BLEND_FACTOR_ONE,
             VK_BLEND_FACTOR_ONE,
             VK_BLEND_OP_ADD,
             0xF};
  d.setLayout = setLayout;
  VkPipeline pipeline = VK_NULL_HANDLE;
  ASSERT_EQ(createPipeline(d, &pipeline), VK_SUCCESS);

  // Colors in 255ths (exact in UNORM8).
  const float a[4] = {64 / 255.0f, 0, 128 / 255.0f, 32 / 255.0f}, c[4] = {0, 96 / 255.0f, 64 / 255.0f, 16 / 255.0f};
  HostBuffer ua = vertexBuffer(a, sizeof a, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
  HostBuffer uc = vertexBuffer(c, sizeof c, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
  const Vertex tri[3] = {{-1, -1, 0, 0, 0, 1}, {3, -1, 0, 0, 0, 1}, {-1, 3, 0, 0, 0, 1}};
  HostBuffer vb = vertexBuffer(tri, sizeof tri);
  Target color = createTarget(kColorFormat, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                              VK_IMAGE_ASPECT_COLOR_BIT);
  std::vector<uint32_t> pixels = render(color, nullptr, [&](VkCommandBuffer cb) {
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
    VkDeviceSize off = 0;
    vkCmdBindVertexBuffers(cb, 0, 1, &vb.buffer, &off);
    VkDescriptorBufferInfo info{ua.buffer, 0, VK_WHOLE_SIZE};
    VkWriteDescriptorSet w = bufferWrite(0, kUniform, &info);
    cmdPush(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, layout, 0, 1, &w);
    vkCmdDraw(cb, 3, 1, 0, 0);
    info.buffer = uc.buffer;
    cmdPush(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, layout, 0, 1, &w);
    vkCmdDraw(cb, 3, 1, 0, 0);
    info.buffer = VK_NULL_HANDLE;  // reused by the application before the command buffer runs
  });
  ASSERT_EQ(pixels.size(), size_t(kW * kH));
  const uint32_t want = 64 | 96 << 8 | 192 << 16 | 48u << 24;
  int wrong = 0;
  for (uint32_t px : pixels) wrong += px != want;
  EXPECT_EQ(wrong, 0) << "pixel 0 is 0x" << std::hex << pixels[0] << ", want 0x" << want;
  destroy(color);
  destroy(vb);
  destroy(uc);
  destroy(ua);
  vkDestroyPipeline(device, pipeline, nullptr);
  vkDestroyDescriptorSetLayout(device, setLayout, nullptr);
}

// ---- ray tracing ----

// The basic scene traced through a push set (binding 0: the top level, 1: the results, 2: the spheres), twice in one
// command buffer, the second push changing the results buffer only.
class PushDescriptorTraceTest : public TraceTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o = TraceTest::options();
    o.deviceExtensions.push_back(VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME);
    return o;
  }
};

TEST_F(PushDescriptorTraceTest, TracesReadPushedStructureAndBuffers) {
  PFN_vkCmdPushDescriptorSetKHR cmdPush = nullptr;
  load(cmdPush, "vkCmdPushDescriptorSetKHR");
  VkDescriptorSetLayoutBinding b[3] = {
      {0, VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 1, kRtStages, nullptr},
      {1, kStorage, 1, kRtStages, nullptr},
      {2, kStorage, 1, kRtStages, nullptr},
  };
  VkDescriptorSetLayoutCreateInfo dl{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  dl.flags = kPush;
  dl.bindingCount = 3;
  dl.pBindings = b;
  VkDescriptorSetLayout pushSetLayout = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateDescriptorSetLayout(device, &dl, nullptr, &pushSetLayout), VK_SUCCESS);
  VkPushConstantRange pc{VK_SHADER_STAGE_RAYGEN_BIT_KHR, 0, sizeof(TraceParams)};
  VkPipelineLayoutCreateInfo lci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  lci.setLayoutCount = 1;
  lci.pSetLayouts = &pushSetLayout;
  lci.pushConstantRangeCount = 1;
  lci.pPushConstantRanges = &pc;
  VkPipelineLayout pl = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreatePipelineLayout(device, &lci, nullptr, &pl), VK_SUCCESS);

  VkAccelerationStructureKHR top = basicScene();
  Desc d = basicDesc();
  d.layout = pl;
  VkPipeline p = make(d);
  ASSERT_NE(p, VK_NULL_HANDLE);
  Sbt s = sbt(p, 3, {0}, {{1, {7}}}, {{2, {100}}, {2, {101}}});
  constexpr uint32_t n = 8;
  HostBuffer& out1 = buffer(sizeof(TracePayload) * n * n, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  HostBuffer& out2 = buffer(sizeof(TracePayload) * n * n, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  std::memset(out1.data, 0xee, out1.size);
  std::memset(out2.data, 0xee, out2.size);

  VkWriteDescriptorSetAccelerationStructureKHR asw{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_KHR};
  asw.accelerationStructureCount = 1;
  asw.pAccelerationStructures = &top;
  VkDescriptorBufferInfo bo{out1.buffer, 0, VK_WHOLE_SIZE}, bs{spheres.buffer, 0, VK_WHOLE_SIZE};
  VkWriteDescriptorSet w[3] = {
      {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, &asw}, bufferWrite(1, kStorage, &bo), bufferWrite(2, kStorage, &bs)};
  w[0].dstBinding = 0;
  w[0].descriptorCount = 1;
  w[0].descriptorType = VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR;
  const TraceParams params;
  VkCommandBuffer cb = beginOneTime();
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, p);
  vkCmdPushConstants(cb, pl, VK_SHADER_STAGE_RAYGEN_BIT_KHR, 0, sizeof params, &params);
  cmdPush(cb, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, pl, 0, 3, w);
  cmdTrace(cb, &s.raygen, &s.miss, &s.hit, &s.callable, n, n, 1);
  bo.buffer = out2.buffer;
  cmdPush(cb, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, pl, 0, 1, &w[1]);
  cmdTrace(cb, &s.raygen, &s.miss, &s.hit, &s.callable, n, n, 1);
  submitAndWait(cb);
  for (const HostBuffer* out : {&out1, &out2}) {
    SCOPED_TRACE(out == &out1 ? "first trace" : "second trace");
    std::vector<TracePayload> r(n * n);
    std::memcpy(r.data(), out->data, r.size() * sizeof(TracePayload));
    expectBasicScene(r, n);
  }
  vkDestroyPipelineLayout(device, pl, nullptr);
  vkDestroyDescriptorSetLayout(device, pushSetLayout, nullptr);
}

}  // namespace
}  // namespace vkrt::test
