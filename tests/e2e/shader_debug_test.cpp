// Shader debugging through the loader (docs/shader-debugging.md): debugPrintfEXT in compute, ray generation,
// closest-hit, vertex and fragment shaders, delivered to a debug messenger as the validation layer's debug printf
// delivers them (pMessageIdName "UNASSIGNED-DEBUG-PRINTF", INFO); out-of-bounds buffer accesses named with the
// shader, the source line or the SPIR-V word offset, the invocation, the descriptor and the range
// ("VKRT-shader-out-of-bounds"); in-bounds shaders report nothing. The layer is on, as in every e2e test.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include "check_bda.g.comp.spv.h"
#include "check_bda.g.rgen.spv.h"
#include "check_image.g.comp.spv.h"
#include "check_image_draw.g.frag.spv.h"
#include "e2e/compute_pipeline_helpers.hpp"
#include "e2e/draw_fixture.hpp"
#include "e2e/trace_fixture.hpp"
#include "oob_debug_info.spvasm.spv.h"
#include "oob_draw.frag.spv.h"
#include "oob_raygen.g.rgen.spv.h"
#include "oob_raygen_lane.g.rgen.spv.h"
#include "oob_read.comp.spv.h"
#include "oob_write.g.comp.spv.h"
#include "oob_write.gv.comp.spv.h"
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

// glslangValidator -gV: the line information is NonSemantic.Shader.DebugInfo.100's DebugLine (the module's only
// OpLine is the function's, before its first block, so it names no access), yet the report names line 9.
TEST_F(ShaderDebugComputeTest, OutOfBoundsWriteNamedThroughDebugInfo100Lines) {
  if (!onVkrt()) GTEST_SKIP() << "vkrt's own report";
  ComputePipeline p =
      makeComputePipeline(device, kSpv_oob_write_gv_comp, sizeof kSpv_oob_write_gv_comp, {kStorageBuffer});
  ASSERT_EQ(p.result, VK_SUCCESS);
  HostBuffer out = createHostBuffer(16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  std::memset(out.data, 0x5a, 16);
  dispatch(p, {&out}, 1);
  std::vector<ShaderMessage> m = log.take(kOutOfBoundsId);
  ASSERT_EQ(m.size(), 1u);
  const std::string& t = m[0].text;
  EXPECT_TRUE(contains(t, "oob_write.gv.comp at line 9")) << t;
  EXPECT_FALSE(contains(t, "column")) << t;  // glslang writes column 0: none
  EXPECT_TRUE(contains(t, "store of 4 bytes at offset ")) << t;
  EXPECT_TRUE(contains(t, "variable \"result\"")) << t;
  for (int i = 0; i < 16; ++i) EXPECT_EQ(static_cast<const uint8_t*>(out.data)[i], 0x5a);
  clearMessages();
  destroy(out);
  destroyComputePipeline(device, p);
}

// The word offset of the `n`-th OpStore (from 0) of a module.
uint32_t storeOffset(const uint32_t* words, size_t count, int n) {
  for (size_t at = 5; at < count && (words[at] >> 16); at += words[at] >> 16)
    if ((words[at] & 0xffff) == spv::OpStore && n-- == 0) return uint32_t(at);
  return 0;
}

// DebugLine of two DebugSources, with a column, and DebugNoLine: three stores past the buffer, one per invocation,
// each named by what precedes it (a file, line and column; the other file; the word offset, as a store in a module
// without line information is) and by its invocation. (One invocation per store: the scalar path, VKRT_SPMD=0,
// reports an invocation's first failing access only.)
TEST_F(ShaderDebugComputeTest, OutOfBoundsWritesNamedByDebugLineAndDebugNoLine) {
  if (!onVkrt()) GTEST_SKIP() << "vkrt's own report";
  ComputePipeline p =
      makeComputePipeline(device, kSpv_oob_debug_info_spvasm, sizeof kSpv_oob_debug_info_spvasm, {kStorageBuffer});
  ASSERT_EQ(p.result, VK_SUCCESS);
  HostBuffer out = createHostBuffer(16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  std::memset(out.data, 0x5a, 16);
  dispatch(p, {&out}, 1);
  std::vector<ShaderMessage> m = log.take(kOutOfBoundsId);
  ASSERT_EQ(m.size(), 3u);
  const uint32_t third = storeOffset(kSpv_oob_debug_info_spvasm, sizeof kSpv_oob_debug_info_spvasm / 4, 2);
  ASSERT_NE(third, 0u);
  const std::string expected[3][2] = {
      {"in file first.glsl at line 21, column 5, global invocation (0, 0, 0)", "store of 4 bytes at offset 64 "},
      {"in file second.glsl at line 40, column 9, global invocation (1, 0, 0)", "store of 4 bytes at offset 68 "},
      {"at SPIR-V word offset " + std::to_string(third) +
           " (the module has no line information for it), global "
           "invocation (2, 0, 0)",
       "store of 4 bytes at offset 72 "}};
  for (const auto& e : expected) {
    auto hit = std::find_if(m.begin(), m.end(), [&](const ShaderMessage& s) { return contains(s.text, e[1]); });
    ASSERT_NE(hit, m.end()) << e[1];
    EXPECT_TRUE(contains(hit->text, e[0])) << hit->text;
  }
  for (int i = 0; i < 16; ++i) EXPECT_EQ(static_cast<const uint8_t*>(out.data)[i], 0x5a);
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

// An 8 x 4 launch in which launch id (5, 2) alone stores past the 32 payloads the buffer holds: the report names that
// launch id, also where a batch of launch ids runs in one call (the SPMD raygen entry: lane 5 of row 2's batch).
TEST_F(ShaderDebugTraceTest, RayGenerationStoreOutOfBoundsNamesTheLanesLaunchId) {
  if (!vkrt) GTEST_SKIP() << "vkrt's own report";
  Desc d;
  d.layout = traceLayout;
  d.general(module(kSpv_oob_raygen_lane_g_rgen, sizeof kSpv_oob_raygen_lane_g_rgen), VK_SHADER_STAGE_RAYGEN_BIT_KHR);
  d.general(tmiss, VK_SHADER_STAGE_MISS_BIT_KHR);
  VkPipeline p = make(d);
  ASSERT_NE(p, VK_NULL_HANDLE);
  Sbt s = sbt(p, 2, {0}, {{1, {}}}, {});
  std::vector<TracePayload> r = trace(p, s, basicScene(), 8, 4);
  for (uint32_t i = 0; i < 32; ++i) EXPECT_EQ(r[i].ids[0], i) << i;
  std::vector<ShaderMessage> m = log.take(kOutOfBoundsId);
  ASSERT_EQ(m.size(), 1u);
  const std::string& t = m[0].text;
  EXPECT_TRUE(contains(t, "oob_raygen_lane.g.rgen at line 12, launch id (5, 2, 0): store of ")) << t;
  // Payload 32 + 21's ids, 16 bytes into the 48-byte payload: past the 1536 bytes of 32 payloads.
  EXPECT_TRUE(contains(t, " bytes at offset 2560 is outside the 1536 bytes in range")) << t;
  clearMessages();
}

// A 4 x 4 launch whose ray generation shader stores one payload past the 16 the buffer holds: one report for the
// launch, naming the line, the launch id and the descriptor with its buffer, as a dispatch's report does.
TEST_F(ShaderDebugTraceTest, RayGenerationStoreOutOfBoundsNamesTheBuffer) {
  if (!vkrt) GTEST_SKIP() << "vkrt's own report";
  Desc d;
  d.layout = traceLayout;
  d.general(module(kSpv_oob_raygen_g_rgen, sizeof kSpv_oob_raygen_g_rgen), VK_SHADER_STAGE_RAYGEN_BIT_KHR);
  d.general(tmiss, VK_SHADER_STAGE_MISS_BIT_KHR);
  VkPipeline p = make(d);
  ASSERT_NE(p, VK_NULL_HANDLE);
  Sbt s = sbt(p, 2, {0}, {{1, {}}}, {});
  std::vector<TracePayload> r = trace(p, s, basicScene(), 4, 4);
  for (uint32_t i = 0; i < 16; ++i) EXPECT_EQ(r[i].ids[0], i) << i;
  std::vector<ShaderMessage> m = log.take(kOutOfBoundsId);
  ASSERT_EQ(m.size(), 1u);
  const std::string& t = m[0].text;
  EXPECT_TRUE(contains(t, "vkCmdTraceRaysKHR: ray generation shader \"main\" of VkPipeline")) << t;
  EXPECT_TRUE(contains(t, "oob_raygen.g.rgen at line 12, launch id (0, 0, 0): store of ")) << t;
  // Payload 16's ids, 16 bytes into the 48-byte payload: past the 768 bytes of 16 payloads.
  EXPECT_TRUE(contains(t, " bytes at offset 784 is outside the 768 bytes in range")) << t;
  EXPECT_TRUE(contains(t, "(set 0, binding 1, element 0, variable \"results\", VkBuffer 0x")) << t;
  EXPECT_TRUE(contains(t, "the store is dropped")) << t;
  clearMessages();
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

// ---- VKRT_SHADER_CHECKS: device addresses and images (docs/shader-debugging.md)

// The checks are compiled in by the setting, read when the device is created; the parameter is VKRT_SPMD. These
// shaders take the scalar vkrt_group on either path (images and pointer values are not on the SPMD path): both must
// report the same.
// VKRT_SPMD and VKRT_SHADER_CHECKS for the devices made while it is set (they are read when a device is created),
// restored after; VKRT_SPMD unset before is left at the default, "1" (a device applies it only where it is set).
class ShaderSettings {
 public:
  void set(const char* spmd, const char* checks) {
    for (int i = 0; i < 2; ++i) {
      const char* v = std::getenv(kVars[i]);
      saved_[i] = v ? v : "";
      had_[i] = v != nullptr;
    }
    setenv("VKRT_SPMD", spmd, 1);
    if (checks) {
      setenv("VKRT_SHADER_CHECKS", checks, 1);
    } else {
      unsetenv("VKRT_SHADER_CHECKS");
    }
  }
  void restore() {
    for (int i = 0; i < 2; ++i) {
      if (had_[i]) {
        setenv(kVars[i], saved_[i].c_str(), 1);
      } else if (i == 0) {
        setenv(kVars[i], "1", 1);
      } else {
        unsetenv(kVars[i]);
      }
    }
  }

 private:
  static constexpr const char* kVars[2] = {"VKRT_SPMD", "VKRT_SHADER_CHECKS"};
  std::string saved_[2];
  bool had_[2] = {};
};

// The checks are compiled in by the setting, read when the device is created; the parameter is VKRT_SPMD. These
// shaders take the scalar vkrt_group on either path (images and pointer values are not on the SPMD path): both must
// report the same.
class ShaderChecksTest : public ShaderDebugComputeTest, public ::testing::WithParamInterface<const char*> {
 protected:
  const char* checks = "bda,image";  // nullptr: unset

  void SetUp() override {
    settings_.set(GetParam(), checks);
    ShaderDebugComputeTest::SetUp();
  }
  void TearDown() override {
    ShaderDebugComputeTest::TearDown();
    settings_.restore();
  }

  // A 64-byte storage buffer with a device address at the start of 4096 bytes of its own memory, mapped whole: the
  // bytes after the buffer are allocated (an access there does not fault) but in no buffer. They hold 0xabababab.
  struct Guarded {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    uint32_t* words = nullptr;  // 1024 words
    uint64_t address = 0;
  };
  Guarded makeGuarded(const char* name) {
    Guarded g;
    VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    bci.size = 64;
    bci.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;
    EXPECT_EQ(vkCreateBuffer(device, &bci, nullptr, &g.buffer), VK_SUCCESS);
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(device, g.buffer, &req);
    VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
    flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
    VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, &flags};
    mai.allocationSize = 4096;
    mai.memoryTypeIndex =
        memoryTypeIndex(req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
    EXPECT_EQ(vkAllocateMemory(device, &mai, nullptr, &g.memory), VK_SUCCESS);
    EXPECT_EQ(vkBindBufferMemory(device, g.buffer, g.memory, 0), VK_SUCCESS);
    void* data = nullptr;
    EXPECT_EQ(vkMapMemory(device, g.memory, 0, VK_WHOLE_SIZE, 0, &data), VK_SUCCESS);
    g.words = static_cast<uint32_t*>(data);
    std::memset(g.words, 0xab, 4096);
    VkBufferDeviceAddressInfo ai{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO};
    ai.buffer = g.buffer;
    g.address = vkGetBufferDeviceAddress(device, &ai);
    setName(g.buffer, name);
    return g;
  }
  void destroy(Guarded& g) {
    vkDestroyBuffer(device, g.buffer, nullptr);
    vkFreeMemory(device, g.memory, nullptr);
  }
  using VulkanTest::destroy;

  // check_bda.g.comp's push constants.
  struct BdaPush {
    uint64_t dst, src, cross, stray;
    uint32_t mode;
  };
  void dispatchBda(ComputePipeline& p, const BdaPush& push, uint32_t groups) {
    VkCommandBuffer cb = beginOneTime();
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
    vkCmdPushConstants(cb, p.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, 36, &push);
    vkCmdDispatch(cb, groups, 1, 1);
    VkMemoryBarrier mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    mb.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
    mb.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &mb, 0, nullptr, 0,
                         nullptr);
    submitAndWait(cb);
  }

  // The report of `line` among `m` (each site is reported once per dispatch: exactly one).
  static const ShaderMessage* atLine(const std::vector<ShaderMessage>& m, const char* file, int line) {
    const ShaderMessage* found = nullptr;
    std::string where = std::string(file) + " at line " + std::to_string(line) + ",";
    for (const ShaderMessage& s : m)
      if (contains(s.text, where)) {
        EXPECT_EQ(found, nullptr) << "two reports of line " << line;
        found = &s;
      }
    return found;
  }
  // The fixture's messenger (warnings) saw `n` reports too: taken.
  void expectWarnings(size_t n) {
    std::vector<Message> seen = vkrtMessages();
    EXPECT_EQ(seen.size(), n);
    for (const Message& s : seen) EXPECT_EQ(s.idName, kOutOfBoundsId) << s.text;
    clearMessages();
  }

 private:
  ShaderSettings settings_;
};

class ShaderChecksOffTest : public ShaderChecksTest {
 protected:
  ShaderChecksOffTest() { checks = nullptr; }
};

std::string hex(uint64_t v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "0x%llx", static_cast<unsigned long long>(v));
  return buf;
}

// The valid side: every access inside its buffer (a copy, a 16-byte load inside, a load and a store inside through
// an address computed from an integer) reports nothing and does what the shader says.
TEST_P(ShaderChecksTest, DeviceAddressesInsideBuffersReportNothing) {
  ComputePipeline p = makeComputePipeline(device, kSpv_check_bda_g_comp, sizeof kSpv_check_bda_g_comp, {}, 36);
  ASSERT_EQ(p.result, VK_SUCCESS);
  Guarded src = makeGuarded("src"), dst = makeGuarded("dst");
  for (uint32_t k = 0; k < 16; ++k) src.words[k] = 10 * k;
  dispatchBda(p, {dst.address, src.address, 0, 0, 0}, 2);  // 16 invocations, 16 words
  for (uint32_t k = 0; k < 16; ++k) EXPECT_EQ(dst.words[k], 10 * k + 1) << k;
  EXPECT_EQ(dst.words[16], 0xababababu);
  dispatchBda(p, {dst.address, src.address, src.address + 48, src.address + 8, 1}, 1);
  EXPECT_EQ(dst.words[0], 120u + 130 + 140 + 150);  // the 16 bytes at 48: the last four words, inside
  EXPECT_EQ(dst.words[1], 27u);                     // src.words[2] + 7
  EXPECT_EQ(src.words[3], 5u);                      // stored at src + 8 + 4
  EXPECT_TRUE(log.take(kOutOfBoundsId).empty());
  destroy(src);
  destroy(dst);
  destroyComputePipeline(device, p);
}

// Loads and stores past a buffer's end, a load across it, and a load and a store at an address in no buffer: each
// site reported once, naming the line, the invocation, the address and the nearest buffer; loads read zeros and
// stores are dropped (the bytes after the buffers keep their pattern; the store to address 20 does not fault).
TEST_P(ShaderChecksTest, DeviceAddressesOutsideBuffersAreReported) {
  if (!onVkrt()) GTEST_SKIP() << "vkrt's own report";
  ComputePipeline p = makeComputePipeline(device, kSpv_check_bda_g_comp, sizeof kSpv_check_bda_g_comp, {}, 36);
  ASSERT_EQ(p.result, VK_SUCCESS);
  Guarded src = makeGuarded("src"), dst = makeGuarded("dst");
  for (uint32_t k = 0; k < 16; ++k) src.words[k] = 10 * k;
  dispatchBda(p, {dst.address, src.address, 0, 0, 0}, 3);  // 24 invocations: 16..23 are past both buffers
  for (uint32_t k = 0; k < 16; ++k) EXPECT_EQ(dst.words[k], 10 * k + 1) << k;
  for (uint32_t k = 16; k < 1024; ++k) ASSERT_EQ(dst.words[k], 0xababababu) << k;
  std::vector<ShaderMessage> m = log.take(kOutOfBoundsId);
  ASSERT_EQ(m.size(), 2u);
  const ShaderMessage* load = atLine(m, "check_bda.g.comp", 16);
  const ShaderMessage* store = atLine(m, "check_bda.g.comp", 17);
  ASSERT_TRUE(load && store);
  for (const ShaderMessage* r : {load, store}) {
    EXPECT_EQ(r->severity, VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT);
    EXPECT_TRUE(contains(r->text, "compute shader \"main\" of VkPipeline")) << r->text;
    // The first failing invocation of the only workgroup that failed: 16, at the buffer's end.
    EXPECT_TRUE(contains(r->text, "global invocation (16, 0, 0)")) << r->text;
  }
  EXPECT_TRUE(contains(load->text, "load of 4 bytes at device address " + hex(src.address + 64) +
                                       " is in no live buffer with a device address: it lies 0 bytes past the end "
                                       "of the nearest, [" +
                                       hex(src.address) + ", " + hex(src.address + 64) + ") (64 bytes), VkBuffer"))
      << load->text;
  EXPECT_TRUE(contains(load->text, "'src'; the load reads zeros")) << load->text;
  EXPECT_TRUE(contains(store->text, "store of 4 bytes at device address " + hex(dst.address + 64))) << store->text;
  EXPECT_TRUE(contains(store->text, "'dst'; the store is dropped")) << store->text;
  expectWarnings(2);

  dispatchBda(p, {dst.address, src.address, src.address + 56, 16, 1}, 1);
  EXPECT_EQ(dst.words[0], 0u);  // the 16 bytes at 56 cross the end: all read as zeros
  EXPECT_EQ(dst.words[1], 7u);  // address 16 reads zeros
  m = log.take(kOutOfBoundsId);
  ASSERT_EQ(m.size(), 3u);
  const ShaderMessage* cross = atLine(m, "check_bda.g.comp", 19);
  const ShaderMessage* strayLoad = atLine(m, "check_bda.g.comp", 22);
  const ShaderMessage* strayStore = atLine(m, "check_bda.g.comp", 23);
  ASSERT_TRUE(cross && strayLoad && strayStore);
  EXPECT_TRUE(contains(cross->text, "load of 16 bytes at device address " + hex(src.address + 56) +
                                        " crosses the end of the buffer at [" + hex(src.address) + ", " +
                                        hex(src.address + 64) + ") (64 bytes; offset 56), VkBuffer"))
      << cross->text;
  EXPECT_TRUE(contains(strayLoad->text,
                       "load of 4 bytes at device address 0x10 is in no live buffer with a device "
                       "address: it lies "))
      << strayLoad->text;
  EXPECT_TRUE(contains(strayStore->text, "store of 4 bytes at device address 0x14 is in no live buffer"))
      << strayStore->text;
  EXPECT_TRUE(contains(strayStore->text, "the store is dropped")) << strayStore->text;
  for (const ShaderMessage* r : {cross, strayLoad, strayStore})
    EXPECT_TRUE(contains(r->text, "global invocation (0, 0, 0)")) << r->text;
  expectWarnings(3);
  destroy(src);
  destroy(dst);
  destroyComputePipeline(device, p);
}

// Without the setting nothing of the check is compiled in: no report, and the store past the buffer lands in the
// allocated bytes after it (undefined behaviour the setting exists to find).
TEST_P(ShaderChecksOffTest, DeviceAddressChecksAreCompiledOut) {
  if (!onVkrt()) GTEST_SKIP() << "what an unchecked access past a buffer does is vkrt's";
  ComputePipeline p = makeComputePipeline(device, kSpv_check_bda_g_comp, sizeof kSpv_check_bda_g_comp, {}, 36);
  ASSERT_EQ(p.result, VK_SUCCESS);
  Guarded src = makeGuarded("src"), dst = makeGuarded("dst");
  dispatchBda(p, {dst.address, src.address, 0, 0, 0}, 3);
  for (uint32_t k = 16; k < 24; ++k) EXPECT_EQ(dst.words[k], 0xababababu + 1) << k;
  EXPECT_TRUE(log.take(kOutOfBoundsId).empty());
  destroy(src);
  destroy(dst);
  destroyComputePipeline(device, p);
}

// A 4 x 4 R32_UINT 2D image of one level and layer with `usage`, bound to memory of its own (of the type
// `memoryType(memoryTypeBits)`), and a view of it: the image the VKRT_SHADER_CHECKS=image tests read outside.
void createSmallImage(VkDevice device, VkImageUsageFlags usage, const std::function<uint32_t(uint32_t)>& memoryType,
                      VkImage* image, VkDeviceMemory* memory, VkImageView* view) {
  VkImageCreateInfo ci{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  ci.imageType = VK_IMAGE_TYPE_2D;
  ci.format = VK_FORMAT_R32_UINT;
  ci.extent = {4, 4, 1};
  ci.mipLevels = ci.arrayLayers = 1;
  ci.samples = VK_SAMPLE_COUNT_1_BIT;
  ci.tiling = VK_IMAGE_TILING_OPTIMAL;
  ci.usage = usage;
  ASSERT_EQ(vkCreateImage(device, &ci, nullptr, image), VK_SUCCESS);
  VkMemoryRequirements req;
  vkGetImageMemoryRequirements(device, *image, &req);
  VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  mai.allocationSize = req.size;
  mai.memoryTypeIndex = memoryType(req.memoryTypeBits);
  ASSERT_EQ(vkAllocateMemory(device, &mai, nullptr, memory), VK_SUCCESS);
  ASSERT_EQ(vkBindImageMemory(device, *image, *memory, 0), VK_SUCCESS);
  VkImageViewCreateInfo vi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
  vi.image = *image;
  vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
  vi.format = ci.format;
  vi.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  ASSERT_EQ(vkCreateImageView(device, &vi, nullptr, view), VK_SUCCESS);
}

// check_image.g.comp's images: a 4x4 R32_UINT image (storage and sampled, GENERAL), a 16-texel R32_UINT storage texel
// buffer, and the output buffer.
class ShaderImageChecksTest : public ShaderChecksTest {
 protected:
  VkImage image = VK_NULL_HANDLE;
  VkDeviceMemory imageMemory = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;
  VkSampler sampler = VK_NULL_HANDLE;
  VkBufferView texelView = VK_NULL_HANDLE;
  HostBuffer texels, out;
  ComputePipeline p;

  void SetUp() override {
    ShaderChecksTest::SetUp();
    if (HasFatalFailure()) return;
    createSmallImage(
        device, VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT,
        [&](uint32_t bits) { return memoryTypeIndex(bits, 0); }, &image, &imageMemory, &view);
    if (HasFatalFailure()) return;
    VkSamplerCreateInfo si{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
    ASSERT_EQ(vkCreateSampler(device, &si, nullptr, &sampler), VK_SUCCESS);
    texels = createHostBuffer(64, VK_BUFFER_USAGE_STORAGE_TEXEL_BUFFER_BIT);
    for (uint32_t k = 0; k < 16; ++k) static_cast<uint32_t*>(texels.data)[k] = 1000 + k;
    VkBufferViewCreateInfo bv{VK_STRUCTURE_TYPE_BUFFER_VIEW_CREATE_INFO};
    bv.buffer = texels.buffer;
    bv.format = VK_FORMAT_R32_UINT;
    bv.range = VK_WHOLE_SIZE;
    ASSERT_EQ(vkCreateBufferView(device, &bv, nullptr, &texelView), VK_SUCCESS);
    out = createHostBuffer(64 * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    p = makeComputePipeline(device, kSpv_check_image_g_comp, sizeof kSpv_check_image_g_comp,
                            {VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
                             VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER, kStorageBuffer},
                            16);
    ASSERT_EQ(p.result, VK_SUCCESS);
    VkDescriptorImageInfo storage{VK_NULL_HANDLE, view, VK_IMAGE_LAYOUT_GENERAL};
    VkDescriptorImageInfo sampled{sampler, view, VK_IMAGE_LAYOUT_GENERAL};
    VkDescriptorBufferInfo ob{out.buffer, 0, VK_WHOLE_SIZE};
    VkWriteDescriptorSet w[4] = {};
    for (uint32_t k = 0; k < 4; ++k) {
      w[k] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
      w[k].dstSet = p.set;
      w[k].dstBinding = k;
      w[k].descriptorCount = 1;
    }
    w[0].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
    w[0].pImageInfo = &storage;
    w[1].descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    w[1].pImageInfo = &sampled;
    w[2].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER;
    w[2].pTexelBufferView = &texelView;
    w[3].descriptorType = kStorageBuffer;
    w[3].pBufferInfo = &ob;
    vkUpdateDescriptorSets(device, 4, w, 0, nullptr);
    // The image to GENERAL, then filled: texel (x, y) = 100 + x + 4y.
    VkCommandBuffer cb = beginOneTime();
    VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    b.dstAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
    b.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    b.newLayout = VK_IMAGE_LAYOUT_GENERAL;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image;
    b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 0, nullptr, 0,
                         nullptr, 1, &b);
    submitAndWait(cb);
    run(0, 0, 100);
  }
  void TearDown() override {
    if (device) {
      vkDeviceWaitIdle(device);
      destroyComputePipeline(device, p);
      vkDestroyBufferView(device, texelView, nullptr);
      vkDestroySampler(device, sampler, nullptr);
      vkDestroyImageView(device, view, nullptr);
      vkDestroyImage(device, image, nullptr);
      vkFreeMemory(device, imageMemory, nullptr);
      destroy(texels);
      destroy(out);
    }
    ShaderChecksTest::TearDown();
  }
  // One dispatch of the 4x4 workgroup: mode 0 writes `value` + index at the texel shifted by (shiftX, 0); mode 1
  // reads there.
  void run(uint32_t mode, int32_t shiftX, uint32_t value = 0) {
    const int32_t push[4] = {shiftX, 0, int32_t(mode), int32_t(value)};
    VkCommandBuffer cb = beginOneTime();
    recordDispatch(cb, p, 1, push, 16);
    submitAndWait(cb);
  }
  const uint32_t* o() const { return static_cast<const uint32_t*>(out.data); }
};

TEST_P(ShaderImageChecksTest, AccessesInsideTheViewReportNothing) {
  run(1, 0);
  for (uint32_t i = 0; i < 16; ++i) {
    EXPECT_EQ(o()[i], 100 + i) << i;       // imageLoad
    EXPECT_EQ(o()[16 + i], 100 + i) << i;  // texelFetch
    EXPECT_EQ(o()[32 + i], 100 + i) << i;  // imageAtomicAdd
    EXPECT_EQ(o()[48 + i], 1000 + i) << i;
    EXPECT_EQ(static_cast<const uint32_t*>(texels.data)[i], i + 1) << i;
  }
  EXPECT_TRUE(log.take(kOutOfBoundsId).empty());
}

// Writes one texel right of the image, then reads two right of it: every image instruction's site is reported once,
// with the coordinates, the view's range and the descriptor; reads return zeros and writes are dropped.
TEST_P(ShaderImageChecksTest, AccessesOutsideTheViewAreReported) {
  if (!onVkrt()) GTEST_SKIP() << "vkrt's own report";
  EXPECT_TRUE(log.take(kOutOfBoundsId).empty());  // the fill, inside
  run(0, 1, 200);
  std::vector<ShaderMessage> m = log.take(kOutOfBoundsId);
  ASSERT_EQ(m.size(), 1u);
  const ShaderMessage* write = atLine(m, "check_image.g.comp", 16);
  ASSERT_TRUE(write);
  EXPECT_EQ(write->severity, VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT);
  EXPECT_TRUE(contains(write->text,
                       "global invocation (3, 0, 0): OpImageWrite at (4, 0, 0), layer 0, level 0 is "
                       "outside the view (level 0: 4x4x1, 1 layers; 1 levels) (set 0, binding 0, "
                       "element 0, variable \"img\", VkImageView"))
      << write->text;
  EXPECT_TRUE(contains(write->text, "; the write is dropped")) << write->text;
  expectWarnings(1);
  run(1, 2);
  // Texel (x, y) is now 100 + 4y at x = 0, 200 + (x - 1) + 4y elsewhere; read at x + 2.
  for (uint32_t i = 0; i < 16; ++i) {
    const uint32_t x = i % 4, y = i / 4;
    const uint32_t want = x + 2 < 4 ? 200 + (x + 1) + 4 * y : 0;
    EXPECT_EQ(o()[i], want) << i;
    EXPECT_EQ(o()[16 + i], want) << i;
    EXPECT_EQ(o()[32 + i], want) << i;
    EXPECT_EQ(o()[48 + i], i + 2 < 16 ? 1000 + i + 2 : 0) << i;
  }
  const auto* t = static_cast<const uint32_t*>(texels.data);
  EXPECT_EQ(t[0], 1000u);
  EXPECT_EQ(t[1], 1001u);
  for (uint32_t j = 2; j < 16; ++j) EXPECT_EQ(t[j], j - 1) << j;
  m = log.take(kOutOfBoundsId);
  ASSERT_EQ(m.size(), 5u);
  struct Want {
    int line;
    const char* text;
  } wants[] = {
      {18, "global invocation (2, 0, 0): OpImageRead at (4, 0, 0), layer 0, level 0 is outside the view"},
      {19, "global invocation (2, 0, 0): OpImageFetch at (4, 0, 0), layer 0, level 0 is outside the view"},
      {20, "global invocation (2, 0, 0): OpImageTexelPointer at (4, 0, 0), layer 0, level 0 is outside the view"},
      {21,
       "global invocation (2, 3, 0): OpImageRead at texel 16 is outside the 16 texels of the texel buffer (set 0, "
       "binding 2, element 0, variable \"texels\", VkBufferView"},
      {22, "global invocation (2, 3, 0): OpImageWrite at texel 16 is outside the 16 texels of the texel buffer"},
  };
  for (const Want& w : wants) {
    const ShaderMessage* r = atLine(m, "check_image.g.comp", w.line);
    ASSERT_TRUE(r) << w.line;
    EXPECT_TRUE(contains(r->text, w.text)) << r->text;
  }
  EXPECT_TRUE(contains(atLine(m, "check_image.g.comp", 19)->text, "binding 1, element 0, variable \"tex\""));
  EXPECT_TRUE(contains(atLine(m, "check_image.g.comp", 20)->text, "the atomic acts on nothing"));
  expectWarnings(5);
}

class ShaderImageChecksOffTest : public ShaderImageChecksTest {
 protected:
  ShaderImageChecksOffTest() { checks = nullptr; }
};

// Without the setting the same accesses report nothing, and still read zeros and write nothing (robustness).
TEST_P(ShaderImageChecksOffTest, ImageChecksAreCompiledOut) {
  if (!onVkrt()) GTEST_SKIP() << "reads outside an image without robustImageAccess are vkrt's";
  run(0, 1, 200);
  run(1, 2);
  for (uint32_t i = 0; i < 16; ++i) {
    const uint32_t x = i % 4, y = i / 4;
    EXPECT_EQ(o()[i], x + 2 < 4 ? 200 + (x + 1) + 4 * y : 0) << i;
    EXPECT_EQ(o()[48 + i], i + 2 < 16 ? 1000 + i + 2 : 0) << i;
  }
  EXPECT_TRUE(log.take(kOutOfBoundsId).empty());
}

// A ray tracing launch: the check and its report per launch are the compute dispatch's.
class ShaderChecksTraceTest : public ShaderDebugTraceTest {
 protected:
  ShaderSettings settings;
  FixtureOptions options() override {
    FixtureOptions o = ShaderDebugTraceTest::options();
    o.features.shaderInt64 = VK_TRUE;  // the ray generation shader's pointer is a 64-bit push constant
    return o;
  }
  void SetUp() override {
    settings.set("1", "bda");
    ShaderDebugTraceTest::SetUp();
  }
  void TearDown() override {
    ShaderDebugTraceTest::TearDown();
    settings.restore();
  }
};

// An 8 x 4 launch storing a word per launch id through a device address into a 16-word buffer: the ids from 16 on
// store past it, reported once for the launch with the launch id and the address; the stores inside land.
TEST_F(ShaderChecksTraceTest, RayGenerationStorePastABufferIsReported) {
  if (!vkrt) GTEST_SKIP() << "vkrt's own report";
  Desc d;
  d.layout = traceLayout;
  d.general(module(kSpv_check_bda_g_rgen, sizeof kSpv_check_bda_g_rgen), VK_SHADER_STAGE_RAYGEN_BIT_KHR);
  d.general(tmiss, VK_SHADER_STAGE_MISS_BIT_KHR);
  VkPipeline p = make(d);
  ASSERT_NE(p, VK_NULL_HANDLE);
  Sbt s = sbt(p, 2, {0}, {{1, {}}}, {});
  HostBuffer& words = buffer(64, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);  // (with a device address)
  std::memset(words.data, 0, 64);
  VkBufferDeviceAddressInfo ai{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO};
  ai.buffer = words.buffer;
  const uint64_t address = vkGetBufferDeviceAddress(device, &ai);
  TraceParams params;  // its first 8 bytes are the shader's pointer
  params.rayFlags = uint32_t(address);
  params.cullMask = uint32_t(address >> 32);
  trace(p, s, basicScene(), 8, 4, params);
  for (uint32_t i = 0; i < 16; ++i) EXPECT_EQ(static_cast<const uint32_t*>(words.data)[i], 1 + i % 8) << i;
  std::vector<ShaderMessage> m = log.take(kOutOfBoundsId);
  ASSERT_EQ(m.size(), 1u);
  const std::string& t = m[0].text;
  EXPECT_TRUE(contains(t, "vkCmdTraceRaysKHR: ray generation shader \"main\" of VkPipeline")) << t;
  EXPECT_TRUE(contains(t, "check_bda.g.rgen at line 10, launch id (")) << t;
  unsigned x = 99, y = 99;
  ASSERT_EQ(std::sscanf(t.substr(t.find("launch id (")).c_str(), "launch id (%u, %u", &x, &y), 2) << t;
  EXPECT_GE(y * 8 + x, 16u) << t;
  EXPECT_TRUE(contains(t, "store of 4 bytes at device address " + hex(address + 4 * (y * 8 + x)) +
                              " is in no live buffer with a device address"))
      << t;
  clearMessages();
}

// VKRT_SHADER_CHECKS=image in a draw: check_image_draw.g.frag reads a 4 x 4 storage image, cleared to 77, at each
// fragment's position over the 32 x 32 target. The parameter is VKRT_SPMD (the shader takes the fiber path on
// both: storage image instructions are not on the SPMD path).
class ShaderImageChecksDrawTest : public ShaderDebugDrawTest, public ::testing::WithParamInterface<const char*> {
 protected:
  const char* checks = "image";  // nullptr: unset
  ShaderSettings settings;
  VkImage image = VK_NULL_HANDLE;
  VkDeviceMemory imageMemory = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;
  VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;
  VkDescriptorPool pool = VK_NULL_HANDLE;
  VkDescriptorSet set = VK_NULL_HANDLE;

  void SetUp() override {
    settings.set(GetParam(), checks);
    ShaderDebugDrawTest::SetUp();
    if (HasFatalFailure()) return;
    createSmallImage(
        device, VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT,
        [&](uint32_t bits) { return memoryTypeIndex(bits, 0); }, &image, &imageMemory, &view);
    if (HasFatalFailure()) return;
    const VkImageSubresourceRange whole{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    // UNDEFINED -> GENERAL, cleared to 77, then read by fragment shaders.
    VkCommandBuffer cb = beginOneTime();
    VkImageMemoryBarrier barrier{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    barrier.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    barrier.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    barrier.newLayout = VK_IMAGE_LAYOUT_GENERAL;
    barrier.srcQueueFamilyIndex = barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    barrier.image = image;
    barrier.subresourceRange = whole;
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0,
                         nullptr, 1, &barrier);
    VkClearColorValue value{};
    value.uint32[0] = 77;
    vkCmdClearColorImage(cb, image, VK_IMAGE_LAYOUT_GENERAL, &value, 1, &whole);
    barrier.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT;
    barrier.oldLayout = VK_IMAGE_LAYOUT_GENERAL;
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT, 0, 0, nullptr, 0,
                         nullptr, 1, &barrier);
    submitAndWait(cb);
    VkDescriptorSetLayoutBinding b{0, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, VK_SHADER_STAGE_FRAGMENT_BIT, nullptr};
    VkDescriptorSetLayoutCreateInfo lci{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    lci.bindingCount = 1;
    lci.pBindings = &b;
    ASSERT_EQ(vkCreateDescriptorSetLayout(device, &lci, nullptr, &setLayout), VK_SUCCESS);
    VkDescriptorPoolSize ps{VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1};
    VkDescriptorPoolCreateInfo pci{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    pci.maxSets = 1;
    pci.poolSizeCount = 1;
    pci.pPoolSizes = &ps;
    ASSERT_EQ(vkCreateDescriptorPool(device, &pci, nullptr, &pool), VK_SUCCESS);
    VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    ai.descriptorPool = pool;
    ai.descriptorSetCount = 1;
    ai.pSetLayouts = &setLayout;
    ASSERT_EQ(vkAllocateDescriptorSets(device, &ai, &set), VK_SUCCESS);
    VkDescriptorImageInfo ii{VK_NULL_HANDLE, view, VK_IMAGE_LAYOUT_GENERAL};
    VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    w.dstSet = set;
    w.descriptorCount = 1;
    w.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
    w.pImageInfo = &ii;
    vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);
  }
  void TearDown() override {
    if (device) {
      vkDestroyDescriptorPool(device, pool, nullptr);
      vkDestroyDescriptorSetLayout(device, setLayout, nullptr);
      vkDestroyImageView(device, view, nullptr);
      vkDestroyImage(device, image, nullptr);
      vkFreeMemory(device, imageMemory, nullptr);
    }
    ShaderDebugDrawTest::TearDown();
    settings.restore();
  }

  // Draws the full-screen rectangle with check_image_draw.g.frag and checks every pixel: red 77 where the
  // fragment's texel is in the view, 0 (robust image access: zeros) elsewhere.
  void drawAndCheckPixels() {
    Target color = createTarget(kColorFormat, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                                VK_IMAGE_ASPECT_COLOR_BIT);
    PipelineDesc d;
    d.vs = kSpv_subpass_quad_vert;
    d.vsBytes = sizeof kSpv_subpass_quad_vert;
    d.fs = kSpv_check_image_draw_g_frag;
    d.fsBytes = sizeof kSpv_check_image_draw_g_frag;
    d.setLayout = setLayout;
    VkPipeline pipeline;
    ASSERT_EQ(createPipeline(d, &pipeline), VK_SUCCESS);
    auto pixels = render(color, nullptr, [&](VkCommandBuffer cb) {
      vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
      vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, layout, 0, 1, &set, 0, nullptr);
      vkCmdDraw(cb, 6, 1, 0, 0);
    });
    ASSERT_EQ(pixels.size(), size_t(kW * kH));
    for (uint32_t y = 0; y < kH; ++y)
      for (uint32_t x = 0; x < kW; ++x)
        EXPECT_EQ(pixels[y * kW + x], x < 4 && y < 4 ? 0xFF00004Du : 0xFF000000u) << x << ", " << y;
    vkDestroyPipeline(device, pipeline, nullptr);
    destroy(color);
  }
};

// The reads outside the view are reported once for the draw, naming the fragment (its FragCoord) and the
// coordinates it read, which are that fragment's pixel, outside the 4 x 4 view.
TEST_P(ShaderImageChecksDrawTest, FragmentReadOutsideTheViewNamesTheFragment) {
  if (!onVkrt()) GTEST_SKIP() << "vkrt's own report";
  drawAndCheckPixels();
  std::vector<ShaderMessage> m = log.take(kOutOfBoundsId);
  ASSERT_EQ(m.size(), 1u);  // once per draw and site, although 1008 fragments read outside
  const std::string& t = m[0].text;
  EXPECT_EQ(m[0].severity, VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT);  // robustImageAccess not enabled
  EXPECT_TRUE(contains(t, "vkCmdDraw: fragment shader \"main\" of VkPipeline")) << t;
  EXPECT_TRUE(contains(t, "check_image_draw.g.frag at line 8, fragment at (")) << t;
  EXPECT_TRUE(contains(t, "is outside the view (level 0: 4x4x1, 1 layers; 1 levels)")) << t;
  EXPECT_TRUE(contains(t, "(set 0, binding 0, element 0, variable \"img\", VkImageView ")) << t;
  EXPECT_TRUE(contains(t, "the read returns zeros")) << t;
  float fx = -1, fy = -1;
  int x = -1, y = -1, z = -1;
  ASSERT_EQ(std::sscanf(t.substr(t.find("fragment at (")).c_str(), "fragment at (%f, %f)", &fx, &fy), 2) << t;
  ASSERT_EQ(std::sscanf(t.substr(t.find("OpImageRead at (")).c_str(), "OpImageRead at (%d, %d, %d)", &x, &y, &z), 3)
      << t;
  EXPECT_EQ(float(x) + 0.5f, fx) << t;  // the coordinates are the named fragment's pixel
  EXPECT_EQ(float(y) + 0.5f, fy) << t;
  EXPECT_EQ(z, 0) << t;
  EXPECT_TRUE(x >= 4 || y >= 4) << t;
  EXPECT_LT(x, int(kW)) << t;
  EXPECT_LT(y, int(kH)) << t;
  std::vector<Message> seen = vkrtMessages();  // the fixture's messenger (warnings) saw the same report
  ASSERT_EQ(seen.size(), 1u);
  EXPECT_EQ(seen[0].idName, kOutOfBoundsId);
  clearMessages();
}

// Without the setting, the same draw gives the same pixels and no report.
class ShaderImageChecksDrawOffTest : public ShaderImageChecksDrawTest {
 protected:
  void SetUp() override {
    checks = nullptr;
    ShaderImageChecksDrawTest::SetUp();
  }
};

TEST_P(ShaderImageChecksDrawOffTest, FragmentReadOutsideTheViewIsNotReported) {
  drawAndCheckPixels();
  EXPECT_TRUE(log.take(kOutOfBoundsId).empty());
}

INSTANTIATE_TEST_SUITE_P(Paths, ShaderChecksTest, ::testing::Values("0", "1"));
INSTANTIATE_TEST_SUITE_P(Paths, ShaderChecksOffTest, ::testing::Values("0", "1"));
INSTANTIATE_TEST_SUITE_P(Paths, ShaderImageChecksTest, ::testing::Values("0", "1"));
INSTANTIATE_TEST_SUITE_P(Paths, ShaderImageChecksOffTest, ::testing::Values("0", "1"));
INSTANTIATE_TEST_SUITE_P(Paths, ShaderImageChecksDrawTest, ::testing::Values("0", "1"));
INSTANTIATE_TEST_SUITE_P(Paths, ShaderImageChecksDrawOffTest, ::testing::Values("0", "1"));

}  // namespace
}  // namespace vkrt::test
