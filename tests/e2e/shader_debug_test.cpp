// Shader debugging through the loader (docs/shader-debugging.md): debugPrintfEXT in compute, ray generation,
// closest-hit, vertex and fragment shaders, delivered to a debug messenger as the validation layer's debug printf
// delivers them (pMessageIdName "UNASSIGNED-DEBUG-PRINTF", INFO); out-of-bounds buffer accesses named with the
// shader, the source line or the SPIR-V word offset, the invocation, the descriptor and the range
// ("VKRT-shader-out-of-bounds"); in-bounds shaders report nothing. The layer is on, as in every e2e test.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include "e2e/compute_pipeline_helpers.hpp"
#include "e2e/draw_fixture.hpp"
#include "e2e/trace_fixture.hpp"
#include "oob_draw.frag.spv.h"
#include "oob_read.comp.spv.h"
#include "oob_write.g.comp.spv.h"
#include "printf_chit.rchit.spv.h"
#include "printf_compute.comp.spv.h"
#include "printf_draw.frag.spv.h"
#include "printf_draw.vert.spv.h"
#include "printf_raygen.rgen.spv.h"
#include "shader_debug_scan.hpp"
#include "subpass_quad.vert.spv.h"

namespace vkrt::test {
namespace {

constexpr VkDescriptorType kStorageBuffer = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
constexpr char kPrintfId[] = "UNASSIGNED-DEBUG-PRINTF";
constexpr char kOutOfBoundsId[] = "VKRT-shader-out-of-bounds";

struct ShaderMessage {
  VkDebugUtilsMessageSeverityFlagBitsEXT severity;
  std::string idName;
  int32_t idNumber;
  std::string text;
  // The printf text: what follows the last " | " (where handlers written for the layer cut the message).
  std::string printed() const {
    size_t at = text.rfind(" | ");
    return at == std::string::npos ? std::string() : text.substr(at + 3);
  }
};

// A second messenger, of INFO and above, that keeps the shader debugging messages only (the fixture's keeps
// warnings and errors of everything: an out-of-bounds warning reaches it too, and a test clears it).
class ShaderMessageLog {
 public:
  void start(VkInstance instance) {
    instance_ = instance;
    VkDebugUtilsMessengerCreateInfoEXT ci{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    ci.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_INFO_BIT_EXT |
                         VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                         VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    ci.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT;
    ci.pfnUserCallback = &ShaderMessageLog::onMessage;
    ci.pUserData = this;
    auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance, "vkCreateDebugUtilsMessengerEXT"));
    ASSERT_EQ(create(instance, &ci, nullptr, &messenger_), VK_SUCCESS);
  }
  void stop() {
    if (!messenger_) return;
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
    destroy(instance_, messenger_, nullptr);
    messenger_ = VK_NULL_HANDLE;
  }
  std::vector<ShaderMessage> take(const char* id) {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<ShaderMessage> out, rest;
    for (ShaderMessage& m : messages_) (m.idName == id ? out : rest).push_back(std::move(m));
    messages_ = std::move(rest);
    return out;
  }

 private:
  static VKAPI_ATTR VkBool32 VKAPI_CALL onMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                  VkDebugUtilsMessageTypeFlagsEXT,
                                                  const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
    auto* self = static_cast<ShaderMessageLog*>(user);
    std::string id = data->pMessageIdName ? data->pMessageIdName : "";
    if (id != kPrintfId && id != kOutOfBoundsId) return VK_FALSE;
    std::lock_guard<std::mutex> lock(self->mutex_);
    self->messages_.push_back({severity, id, data->messageIdNumber, data->pMessage ? data->pMessage : ""});
    return VK_FALSE;
  }
  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  std::mutex mutex_;
  std::vector<ShaderMessage> messages_;
};

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

class ShaderDebugComputeTest : public VulkanTest {
 protected:
  ShaderMessageLog log;
  bool robust = false;

  FixtureOptions options() override {
    FixtureOptions o;
    o.features.shaderInt64 = VK_TRUE;  // printf_compute.comp prints a 64-bit value
    o.features.robustBufferAccess = robust;
    return o;
  }
  // Both compute paths report (the SPMD one by default; tools/test.sh runs these tests again with VKRT_SPMD=0).
  void SetUp() override {
    VulkanTest::SetUp();
    if (!HasFatalFailure()) log.start(instance);
  }
  void TearDown() override {
    log.stop();
    VulkanTest::TearDown();
  }

  // Binds `buffers` to bindings 0.. of p's set, pushes `push` (when p has push constants) and dispatches `groups`.
  void dispatch(ComputePipeline& p, const std::vector<const HostBuffer*>& buffers, uint32_t groups,
                const uint32_t* push = nullptr) {
    writeStorageBuffers(device, p, buffers);
    VkCommandBuffer cb = beginOneTime();
    recordDispatch(cb, p, groups, push, 4);
    submitAndWait(cb);
  }

  void setName(VkBuffer buffer, const char* name) {
    auto setObjectName = reinterpret_cast<PFN_vkSetDebugUtilsObjectNameEXT>(
        vkGetInstanceProcAddr(instance, "vkSetDebugUtilsObjectNameEXT"));
    VkDebugUtilsObjectNameInfoEXT ni{VK_STRUCTURE_TYPE_DEBUG_UTILS_OBJECT_NAME_INFO_EXT};
    ni.objectType = VK_OBJECT_TYPE_BUFFER;
    ni.objectHandle = uint64_t(buffer);
    ni.pObjectName = name;
    ASSERT_EQ(setObjectName(device, &ni), VK_SUCCESS);
  }
};

class ShaderDebugRobustTest : public ShaderDebugComputeTest {
 protected:
  ShaderDebugRobustTest() { robust = true; }
};

TEST_F(ShaderDebugComputeTest, ComputePrintfDeliversEveryLine) {
  ComputePipeline p =
      makeComputePipeline(device, kSpv_printf_compute_comp, sizeof kSpv_printf_compute_comp, {kStorageBuffer});
  ASSERT_EQ(p.result, VK_SUCCESS);
  HostBuffer out = createHostBuffer(8 * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  dispatch(p, {&out}, 1);
  if (onVkrt()) {
    std::vector<ShaderMessage> m = log.take(kPrintfId);
    ASSERT_EQ(m.size(), 8u);
    // One workgroup runs on one thread, invocation after invocation: the lines come in order.
    for (uint32_t i = 0; i < 8; ++i) {
      char expected[160];
      std::snprintf(expected, sizeof expected, "i=%u neg=%d hex=%x v=%u.000000, 0.500000, -2.000000 big=%llu", i,
                    -int(i), i * 16 + 15, i, static_cast<unsigned long long>(uint64_t(i) << 40));
      EXPECT_EQ(m[i].printed(), expected);
      EXPECT_EQ(m[i].severity, VK_DEBUG_UTILS_MESSAGE_SEVERITY_INFO_BIT_EXT);
      EXPECT_EQ(uint32_t(m[i].idNumber), 0x92394c89u);
      EXPECT_TRUE(contains(m[i].text, "compute shader \"main\"")) << m[i].text;
      EXPECT_TRUE(contains(m[i].text, "global invocation (" + std::to_string(i) + ", 0, 0)")) << m[i].text;
    }
  }
  const auto* o = static_cast<const uint32_t*>(out.data);
  for (uint32_t i = 0; i < 8; ++i) EXPECT_EQ(o[i], i + 1);
  EXPECT_TRUE(log.take(kOutOfBoundsId).empty());
  destroy(out);
  destroyComputePipeline(device, p);
}

// glslc -g: OpLine names oob_write.g.comp and line 7, where every invocation stores past the 16-byte buffer.
TEST_F(ShaderDebugComputeTest, OutOfBoundsWriteNamedWithFileAndLine) {
  if (!onVkrt()) GTEST_SKIP() << "vkrt's own report";
  ComputePipeline p =
      makeComputePipeline(device, kSpv_oob_write_g_comp, sizeof kSpv_oob_write_g_comp, {kStorageBuffer});
  ASSERT_EQ(p.result, VK_SUCCESS);
  HostBuffer out = createHostBuffer(16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  std::memset(out.data, 0x5a, 16);
  setName(out.buffer, "results");
  dispatch(p, {&out}, 1);
  std::vector<ShaderMessage> m = log.take(kOutOfBoundsId);
  ASSERT_EQ(m.size(), 1u);  // once per dispatch and site, although four invocations stored out of bounds
  const std::string& t = m[0].text;
  // Without robustBufferAccess the access is undefined behaviour on a GPU: a warning.
  EXPECT_EQ(m[0].severity, VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT);
  EXPECT_TRUE(contains(t, "compute shader \"main\" of VkPipeline")) << t;
  EXPECT_TRUE(contains(t, "oob_write.g.comp at line 7")) << t;
  EXPECT_TRUE(contains(t, "set 0, binding 0, element 0, variable \"result\", VkBuffer")) << t;
  EXPECT_TRUE(contains(t, "'results'")) << t;
  EXPECT_TRUE(contains(t, "outside the 16 bytes in range")) << t;
  EXPECT_TRUE(contains(t, "the store is dropped")) << t;
  // The invocation and the offset agree: invocation x stores at (x + 100) * 4.
  unsigned x = 99, offset = 0;
  ASSERT_EQ(std::sscanf(t.substr(t.find("global invocation (")).c_str(), "global invocation (%u", &x), 1) << t;
  ASSERT_EQ(
      std::sscanf(t.substr(t.find("store of 4 bytes at offset ")).c_str(), "store of 4 bytes at offset %u", &offset), 1)
      << t;
  EXPECT_LT(x, 4u);
  EXPECT_EQ(offset, (x + 100) * 4);
  for (int i = 0; i < 16; ++i) EXPECT_EQ(static_cast<const uint8_t*>(out.data)[i], 0x5a);  // nothing written
  // The fixture's messenger (warnings) saw the same report.
  std::vector<Message> seen = vkrtMessages();
  ASSERT_EQ(seen.size(), 1u);
  EXPECT_EQ(seen[0].idName, kOutOfBoundsId);
  clearMessages();
  destroy(out);
  destroyComputePipeline(device, p);
}

// glslc -O keeps no line information: the report names the load by its word offset in the module, found here by
// looking for the load through binding 0. With robustBufferAccess the read is defined (zeros): an INFO report.
TEST_F(ShaderDebugRobustTest, OutOfBoundsReadNamedByWordOffset) {
  if (!onVkrt()) GTEST_SKIP() << "vkrt's own report";
  ComputePipeline p =
      makeComputePipeline(device, kSpv_oob_read_comp, sizeof kSpv_oob_read_comp, {kStorageBuffer, kStorageBuffer}, 4);
  ASSERT_EQ(p.result, VK_SUCCESS);
  HostBuffer in = createHostBuffer(16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  HostBuffer out = createHostBuffer(16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  const uint32_t shift = 64;
  dispatch(p, {&in, &out}, 1, &shift);
  std::vector<ShaderMessage> m = log.take(kOutOfBoundsId);
  ASSERT_EQ(m.size(), 1u);
  EXPECT_EQ(m[0].severity, VK_DEBUG_UTILS_MESSAGE_SEVERITY_INFO_BIT_EXT);
  const uint32_t offset = loadOffsetOfBinding(kSpv_oob_read_comp, sizeof kSpv_oob_read_comp / 4, 0);
  ASSERT_NE(offset, 0u);
  const std::string& t = m[0].text;
  EXPECT_TRUE(contains(t, "at SPIR-V word offset " + std::to_string(offset) + " ")) << t;
  EXPECT_TRUE(contains(t, "load of 4 bytes")) << t;
  EXPECT_TRUE(contains(t, "set 0, binding 0, element 0")) << t;
  EXPECT_TRUE(contains(t, "the load reads zeros")) << t;
  for (int i = 0; i < 4; ++i) EXPECT_EQ(static_cast<const uint32_t*>(out.data)[i], 0u);
  destroy(in);
  destroy(out);
  destroyComputePipeline(device, p);
}

// The valid side: the same shader reading inside its buffer reports nothing.
TEST_F(ShaderDebugRobustTest, InBoundsAccessesReportNothing) {
  ComputePipeline p =
      makeComputePipeline(device, kSpv_oob_read_comp, sizeof kSpv_oob_read_comp, {kStorageBuffer, kStorageBuffer}, 4);
  ASSERT_EQ(p.result, VK_SUCCESS);
  HostBuffer in = createHostBuffer(16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  HostBuffer out = createHostBuffer(16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  for (uint32_t i = 0; i < 4; ++i) static_cast<uint32_t*>(in.data)[i] = 40 + i;
  const uint32_t shift = 0;
  dispatch(p, {&in, &out}, 1, &shift);
  for (uint32_t i = 0; i < 4; ++i) EXPECT_EQ(static_cast<const uint32_t*>(out.data)[i], 40 + i);
  EXPECT_TRUE(log.take(kOutOfBoundsId).empty());
  EXPECT_TRUE(log.take(kPrintfId).empty());
  destroy(in);
  destroy(out);
  destroyComputePipeline(device, p);
}

class ShaderDebugTraceTest : public TraceTest {
 protected:
  ShaderMessageLog log;
  void SetUp() override {
    TraceTest::SetUp();
    if (!HasFatalFailure() && device) log.start(VulkanTest::instance);  // (TraceTest::instance makes instances)
  }
  void TearDown() override {
    log.stop();
    TraceTest::TearDown();
  }
};

// A 4 x 4 launch over the basic scene: each launch id prints before its trace, its closest-hit shader (for the rays
// that hit) prints the hit, and it prints again after, in that order.
TEST_F(ShaderDebugTraceTest, RayGenerationAndClosestHitPrint) {
  if (!vkrt) GTEST_SKIP() << "vkrt's own delivery";
  VkAccelerationStructureKHR top = basicScene();
  Desc d;
  d.layout = traceLayout;
  d.general(module(kSpv_printf_raygen_rgen, sizeof kSpv_printf_raygen_rgen), VK_SHADER_STAGE_RAYGEN_BIT_KHR);
  d.general(tmiss, VK_SHADER_STAGE_MISS_BIT_KHR);
  d.group(VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR, VK_SHADER_UNUSED_KHR,
          d.stage(module(kSpv_printf_chit_rchit, sizeof kSpv_printf_chit_rchit), VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR));
  VkPipeline p = make(d);
  ASSERT_NE(p, VK_NULL_HANDLE);
  Sbt s = sbt(p, 3, {0}, {{1, {7}}}, {{2, {}}, {2, {}}});
  std::vector<TracePayload> r = trace(p, s, top, 4, 4);
  std::vector<ShaderMessage> m = log.take(kPrintfId);
  // Per launch id, the lines of its invocations in delivery order.
  std::map<std::string, std::vector<std::string>> byLaunch;
  for (const ShaderMessage& msg : m) {
    size_t at = msg.text.find("launch id (");
    ASSERT_NE(at, std::string::npos) << msg.text;
    byLaunch[msg.text.substr(at, msg.text.find(')', at) - at + 1)].push_back(msg.printed());
  }
  ASSERT_EQ(byLaunch.size(), 16u);
  int hits = 0;
  for (uint32_t y = 0; y < 4; ++y) {
    for (uint32_t x = 0; x < 4; ++x) {
      const TracePayload& pl = r[y * 4 + x];
      const bool hit = pl.hit[0] >= 0;
      hits += hit;
      const auto& lines = byLaunch["launch id (" + std::to_string(x) + ", " + std::to_string(y) + ", 0)"];
      ASSERT_EQ(lines.size(), hit ? 3u : 2u) << x << "," << y;
      EXPECT_EQ(lines[0], "raygen " + std::to_string(x) + ", " + std::to_string(y));
      char t[32];
      std::snprintf(t, sizeof t, "%.2f", pl.hit[0]);
      if (hit) {
        EXPECT_EQ(lines[1], "closest hit: instance " + std::to_string(pl.ids[0]) + " primitive " +
                                std::to_string(pl.ids[2]) + " t=" + t);
      }
      EXPECT_EQ(lines.back(), "raygen " + std::to_string(y * 4 + x) + " after trace: t=" + t);
    }
  }
  EXPECT_GT(hits, 0);
  EXPECT_LT(hits, 16);
}

class ShaderDebugDrawTest : public DrawTest {
 protected:
  ShaderMessageLog log;
  FixtureOptions options() override {
    FixtureOptions o = DrawTest::options();
    o.features.fragmentStoresAndAtomics = VK_TRUE;
    return o;
  }
  void SetUp() override {
    DrawTest::SetUp();
    if (!HasFatalFailure()) log.start(instance);
  }
  void TearDown() override {
    log.stop();
    DrawTest::TearDown();
  }
};

// A triangle covering the target: each of its three vertices prints once, and the four fragments of the top-left
// 2 x 2 pixels print their centres.
TEST_F(ShaderDebugDrawTest, VertexAndFragmentShadersPrint) {
  if (!onVkrt()) GTEST_SKIP() << "vkrt's own delivery";
  Target color = createTarget(kColorFormat, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                              VK_IMAGE_ASPECT_COLOR_BIT);
  PipelineDesc d;
  d.vs = kSpv_printf_draw_vert;
  d.vsBytes = sizeof kSpv_printf_draw_vert;
  d.fs = kSpv_printf_draw_frag;
  d.fsBytes = sizeof kSpv_printf_draw_frag;
  VkPipeline pipeline;
  ASSERT_EQ(createPipeline(d, &pipeline), VK_SUCCESS);
  auto pixels = render(color, nullptr, [&](VkCommandBuffer cb) {
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
    vkCmdDraw(cb, 3, 1, 0, 0);
  });
  EXPECT_EQ(pixels[0], 0xFF00FF00u);  // green (RGBA8 little-endian)
  std::vector<ShaderMessage> m = log.take(kPrintfId);
  std::multiset<std::string> vertices, fragments;
  for (const ShaderMessage& msg : m) {
    (contains(msg.text, "vertex shader") ? vertices : fragments).insert(msg.printed());
    EXPECT_TRUE(contains(msg.text, "vertex shader \"main\"") || contains(msg.text, "fragment shader \"main\""))
        << msg.text;
  }
  EXPECT_EQ(vertices, (std::multiset<std::string>{"vertex 0 at -1.000000, -1.000000", "vertex 1 at 3.000000, -1.000000",
                                                  "vertex 2 at -1.000000, 3.000000"}));
  EXPECT_EQ(fragments, (std::multiset<std::string>{"fragment 0.500000, 0.500000", "fragment 1.500000, 0.500000",
                                                   "fragment 0.500000, 1.500000", "fragment 1.500000, 1.500000"}));
  vkDestroyPipeline(device, pipeline, nullptr);
  destroy(color);
}

// oob_draw.frag over the whole 32 x 32 target, each fragment storing at y * 32 + x: with the whole buffer in range
// nothing is reported; with 31 rows in range, the last row's stores are dropped and reported once, naming one of
// its fragments and that fragment's offset (on the SPMD path, a quad's failing lane: tools/test.sh runs this again
// with VKRT_SPMD=0).
TEST_F(ShaderDebugDrawTest, FragmentStoreOutOfBoundsNamesTheFragment) {
  if (!onVkrt()) GTEST_SKIP() << "vkrt's own report";
  VkDescriptorSetLayoutBinding b{0, kStorageBuffer, 1, VK_SHADER_STAGE_FRAGMENT_BIT, nullptr};
  VkDescriptorSetLayoutCreateInfo lci{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  lci.bindingCount = 1;
  lci.pBindings = &b;
  VkDescriptorSetLayout setLayout;
  ASSERT_EQ(vkCreateDescriptorSetLayout(device, &lci, nullptr, &setLayout), VK_SUCCESS);
  VkDescriptorPoolSize ps{kStorageBuffer, 1};
  VkDescriptorPoolCreateInfo pci{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  pci.maxSets = 1;
  pci.poolSizeCount = 1;
  pci.pPoolSizes = &ps;
  VkDescriptorPool pool;
  ASSERT_EQ(vkCreateDescriptorPool(device, &pci, nullptr, &pool), VK_SUCCESS);
  VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  ai.descriptorPool = pool;
  ai.descriptorSetCount = 1;
  ai.pSetLayouts = &setLayout;
  VkDescriptorSet set;
  ASSERT_EQ(vkAllocateDescriptorSets(device, &ai, &set), VK_SUCCESS);
  const uint32_t n = kW * kH, inRange = (kH - 1) * kW;
  HostBuffer out = createHostBuffer(n * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  Target color = createTarget(kColorFormat, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                              VK_IMAGE_ASPECT_COLOR_BIT);
  PipelineDesc d;
  d.vs = kSpv_subpass_quad_vert;
  d.vsBytes = sizeof kSpv_subpass_quad_vert;
  d.fs = kSpv_oob_draw_frag;
  d.fsBytes = sizeof kSpv_oob_draw_frag;
  d.setLayout = setLayout;
  VkPipeline pipeline;
  ASSERT_EQ(createPipeline(d, &pipeline), VK_SUCCESS);
  for (VkDeviceSize range : {VkDeviceSize(VK_WHOLE_SIZE), VkDeviceSize(inRange * 4)}) {
    const bool whole = range == VK_WHOLE_SIZE;
    SCOPED_TRACE(whole ? "whole buffer" : "31 rows");
    std::memset(out.data, 0x5a, n * 4);
    VkDescriptorBufferInfo bi{out.buffer, 0, range};
    VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    w.dstSet = set;
    w.descriptorCount = 1;
    w.descriptorType = kStorageBuffer;
    w.pBufferInfo = &bi;
    vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);
    auto pixels = render(color, nullptr, [&](VkCommandBuffer cb) {
      vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
      vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, layout, 0, 1, &set, 0, nullptr);
      vkCmdDraw(cb, 6, 1, 0, 0);
    });
    ASSERT_EQ(pixels.size(), size_t(n));
    for (uint32_t i = 0; i < n; ++i) EXPECT_EQ(pixels[i], 0xFF00FF00u) << i;  // green
    const auto* v = static_cast<const uint32_t*>(out.data);
    for (uint32_t i = 0; i < n; ++i) EXPECT_EQ(v[i], whole || i < inRange ? i + 1 : 0x5a5a5a5au) << i;
    std::vector<ShaderMessage> m = log.take(kOutOfBoundsId);
    if (whole) {
      EXPECT_TRUE(m.empty());
      continue;
    }
    ASSERT_EQ(m.size(), 1u);  // once per draw and site, although a row of fragments stored out of bounds
    const std::string& t = m[0].text;
    EXPECT_TRUE(contains(t, "fragment shader \"main\" of VkPipeline")) << t;
    EXPECT_TRUE(contains(t, "at SPIR-V word offset ")) << t;  // glslc -O: no OpLine, no OpName
    EXPECT_TRUE(contains(t, "(set 0, binding 0, element 0, VkBuffer ")) << t;
    EXPECT_TRUE(contains(t, "outside the 3968 bytes in range")) << t;
    EXPECT_TRUE(contains(t, "the store is dropped")) << t;
    float x = -1, y = -1;
    unsigned offset = 0;
    ASSERT_NE(t.find("fragment at ("), std::string::npos) << t;
    ASSERT_EQ(std::sscanf(t.substr(t.find("fragment at (")).c_str(), "fragment at (%f, %f)", &x, &y), 2) << t;
    ASSERT_EQ(
        std::sscanf(t.substr(t.find("store of 4 bytes at offset ")).c_str(), "store of 4 bytes at offset %u", &offset),
        1)
        << t;
    EXPECT_EQ(y, kH - 0.5f) << t;  // the last row
    EXPECT_GE(x, 0.5f) << t;
    EXPECT_LE(x, kW - 0.5f) << t;
    EXPECT_EQ(x - 0.5f, std::floor(x)) << t;              // a pixel centre
    EXPECT_EQ(offset, (inRange + uint32_t(x)) * 4) << t;  // that fragment's offset
    std::vector<Message> seen = vkrtMessages();           // the fixture's messenger (warnings) saw the same report
    ASSERT_EQ(seen.size(), 1u);
    EXPECT_EQ(seen[0].idName, kOutOfBoundsId);
    clearMessages();
  }
  vkDestroyPipeline(device, pipeline, nullptr);
  destroy(color);
  destroy(out);
  vkDestroyDescriptorPool(device, pool, nullptr);
  vkDestroyDescriptorSetLayout(device, setLayout, nullptr);
}

}  // namespace
}  // namespace vkrt::test
