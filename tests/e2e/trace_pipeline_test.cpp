// Tracing through the shader-group machinery: a pipeline linked from libraries with its SBT written from the
// libraries' own handles, a capture/replayed pipeline with its SBT written from handles another process got,
// callables with shader records, and recursion: each gives the same results as the plain pipeline.
#include <sstream>

#include "e2e/trace_fixture.hpp"
#include "trace_callable.rcall.spv.h"
#include "trace_callable_chain.rcall.spv.h"
#include "trace_chit_calls.rchit.spv.h"

namespace vkrt::test {
namespace {

// Library handle queries need VkPhysicalDevicePipelineLibraryGroupHandlesFeaturesEXT, which the validation layer
// (1.3.239) drops from the device create info: these run without the layer (see rt_fixture.hpp).
class TraceLibraryTest : public TraceTest {
 protected:
  bool layer() override { return false; }
};

TEST_F(TraceLibraryTest, APipelineLinkedFromLibrariesTracesWithTheLibrariesHandles) {
  if (!lgh.pipelineLibraryGroupHandles) GTEST_SKIP() << "pipelineLibraryGroupHandles is not supported";
  VkAccelerationStructureKHR top = basicScene();
  // Library A: raygen and miss; library B: the hit group. The linked pipeline has no groups of its own.
  Desc a;
  a.layout = traceLayout;
  a.flags = VK_PIPELINE_CREATE_LIBRARY_BIT_KHR;
  a.maxPayload = sizeof(TracePayload);
  a.maxHitAttr = 8;
  a.general(rgen, VK_SHADER_STAGE_RAYGEN_BIT_KHR);
  a.general(tmiss, VK_SHADER_STAGE_MISS_BIT_KHR);
  VkPipeline libA = make(a);
  Desc b;
  b.layout = traceLayout;
  b.flags = VK_PIPELINE_CREATE_LIBRARY_BIT_KHR;
  b.maxPayload = sizeof(TracePayload);
  b.maxHitAttr = 8;
  b.group(VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR, VK_SHADER_UNUSED_KHR,
          b.stage(tchit, VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR));
  VkPipeline libB = make(b);
  ASSERT_TRUE(libA && libB);
  Desc linked;
  linked.layout = traceLayout;
  linked.maxPayload = sizeof(TracePayload);
  linked.maxHitAttr = 8;
  linked.libraries = {libA, libB};
  VkPipeline p = make(linked);
  ASSERT_NE(p, VK_NULL_HANDLE);
  // The SBT from the libraries' handles: A's groups 0, 1 and B's group 0, as the linked pipeline numbers them.
  std::vector<uint8_t> h = handles(libA, 0, 2);
  std::vector<uint8_t> hb = handles(libB, 0, 1);
  h.insert(h.end(), hb.begin(), hb.end());
  EXPECT_EQ(h, handles(p, 0, 3)) << "library handles are the linked pipeline's";
  Sbt s = sbtFrom(h, {0}, {{1, {7}}}, {{2, {100}}, {2, {101}}});
  expectBasicScene(trace(p, s, top, 8, 8), 8);
}

class TraceReplayTest : public TraceTest {};

// Run by the test below in a process of its own: the basic pipeline created for capture, its handles and capture
// data written out as hex ("handles capture").
TEST_F(TraceReplayTest, HelperWriteHandlesAndCapture) {
  if (!std::getenv("VKRT_HELPER_OUT"))
    GTEST_SKIP() << "run by TraceReplayTest.AReplayedPipelineTracesWithHandlesFromTheCaptureProcess";
  Desc d = basicDesc(VK_PIPELINE_CREATE_RAY_TRACING_SHADER_GROUP_HANDLE_CAPTURE_REPLAY_BIT_KHR);
  VkPipeline p = make(d);
  ASSERT_NE(p, VK_NULL_HANDLE);
  writeOut(hexOf(handles(p, 0, 3)) + " " + hexOf(captureData(p, 3)));
}

TEST_F(TraceReplayTest, AReplayedPipelineTracesWithHandlesFromTheCaptureProcess) {
  if (!rtf.rayTracingPipelineShaderGroupHandleCaptureReplay) GTEST_SKIP() << "capture/replay is not supported";
  std::istringstream in(runHelper("TraceReplayTest.HelperWriteHandlesAndCapture"));
  std::string handleHex, captureHex;
  in >> handleHex >> captureHex;
  std::vector<uint8_t> capturedHandles = fromHex(handleHex), capture = fromHex(captureHex);
  const uint32_t cs = rtProps.shaderGroupHandleCaptureReplaySize;
  ASSERT_EQ(capturedHandles.size(), 3u * rtProps.shaderGroupHandleSize);
  ASSERT_EQ(capture.size(), 3u * cs);
  VkAccelerationStructureKHR top = basicScene();
  // Another pipeline first, so that nothing but the capture data can make the replayed handles equal.
  if (mixedEnabled()) {
    Desc other = basicDesc();
    other.general(tmiss, VK_SHADER_STAGE_MISS_BIT_KHR);
    make(other);
  }
  Desc d = basicDesc(VK_PIPELINE_CREATE_RAY_TRACING_SHADER_GROUP_HANDLE_CAPTURE_REPLAY_BIT_KHR);
  for (uint32_t g = 0; g < 3; ++g) d.capture.push_back(slice(capture, g * cs, cs));
  VkPipeline p = make(d);
  ASSERT_NE(p, VK_NULL_HANDLE);
  EXPECT_EQ(handles(p, 0, 3), capturedHandles);
  // The SBT written from the capture process's handles traces the replayed pipeline.
  Sbt s = sbtFrom(capturedHandles, {0}, {{1, {7}}}, {{2, {100}}, {2, {101}}});
  expectBasicScene(trace(p, s, top, 8, 8), 8);
}

class TraceCallsTest : public TraceTest {
 protected:
  // raygen, miss, a triangle hit group whose closest-hit shader calls (trace_chit_calls), a callable (trace_callable
  // unless `callable` is given); with `dynamicStackSize`, the stack size is the command buffer's.
  VkPipeline calls(uint32_t depth, VkShaderModule callable = VK_NULL_HANDLE, bool dynamicStackSize = false) {
    Desc d;
    d.layout = traceLayout;
    d.depth = depth;
    d.dynamicStackSize = dynamicStackSize;
    d.general(rgen, VK_SHADER_STAGE_RAYGEN_BIT_KHR);
    d.general(tmiss, VK_SHADER_STAGE_MISS_BIT_KHR);
    d.group(VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR, VK_SHADER_UNUSED_KHR,
            d.stage(module(kSpv_trace_chit_calls_rchit, sizeof kSpv_trace_chit_calls_rchit),
                    VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR));
    d.general(callable ? callable : module(kSpv_trace_callable_rcall, sizeof kSpv_trace_callable_rcall),
              VK_SHADER_STAGE_CALLABLE_BIT_KHR);
    return make(d);
  }

  // The pixels of an n x n launch of rays at quads shifted 0.1 in x (TraceTest's camera): a pixel off the quad keeps
  // the miss shader's -2, and `check(payload, primitive)` checks each on it. Returns how many are on it.
  template <class Check>
  int forEachQuadPixel(const std::vector<TracePayload>& r, uint32_t n, Check check) {
    int hits = 0;
    for (uint32_t y = 0; y < n; ++y)
      for (uint32_t x = 0; x < n; ++x) {
        SCOPED_TRACE("pixel " + std::to_string(x) + "," + std::to_string(y));
        const TracePayload& q = r[y * n + x];
        const float wx = cellCentre(x, n), wy = cellCentre(y, n);
        if (!(wx - 0.1f >= -1 && wx - 0.1f <= 1 && wy >= -1 && wy <= 1)) {
          EXPECT_EQ(q.hit[0], -2.0f);
          continue;
        }
        ++hits;
        check(q, quadHit(wx - 0.1f, wy).primitive);
      }
    return hits;
  }

  // `levels` quads stacked 2 apart from z = 3 (instance k: record k, tag 100 + k), each closest-hit tracing on to
  // the next but the last's: what the first closest-hit reports, per pixel of an 8 x 8 launch.
  void traceStackedQuads(uint32_t levels) {
    VkAccelerationStructureKHR quad = blas({triangles(kQuad, kQuadIndices, VK_GEOMETRY_OPAQUE_BIT_KHR)});
    std::vector<VkAccelerationStructureInstanceKHR> instances;
    std::vector<SbtRecord> hitRecords;
    for (uint32_t k = 0; k < levels; ++k) {
      instances.push_back(instance(quad, 0.1f, 0, 3.0f + 2.0f * float(k), 0, k));
      hitRecords.push_back({2, {100 + k, k + 1 < levels ? 1u : 0u}});
    }
    VkAccelerationStructureKHR top = tlas(instances);
    VkPipeline p = calls(levels);  // the last closest-hit runs at depth `levels`
    ASSERT_NE(p, VK_NULL_HANDLE);
    Sbt s = sbt(p, 4, {0}, {{1, {7}}}, hitRecords, {{3, {1000}}});
    const uint32_t n = 8;
    std::vector<TracePayload> r = trace(p, s, top, n, n);
    const int hits = forEachQuadPixel(r, n, [](const TracePayload& q, uint32_t primitive) {
      EXPECT_NEAR(q.hit[0], 13.0f, 1e-4f);
      EXPECT_EQ(q.extra[0], 100u);
      EXPECT_EQ(q.extra[2], primitive * 2 + 1000) << "the callable's answer, with its record's number";
      EXPECT_EQ(q.extra[3], 101u) << "the onward ray met the second quad's record";
      EXPECT_EQ(q.extra[1], 2000u) << "2 units on, from the closest-hit shader at depth 2";
    });
    EXPECT_GT(hits, 10);
  }
};

TEST_F(TraceCallsTest, CallablesWithShaderRecordsAndARecursiveTrace) {
  // A quad at z = 3 (instance 0, record 0: recurse) in front of one at z = 5 (instance 1, record 1: do not).
  traceStackedQuads(2);
}

// A chain of closest-hit shaders 7 deep, each tracing onward to the next of 7 stacked quads: the executor reuses
// the closest-hit and miss invocations of depths 1-4 per task and makes deeper ones per call (exec/trace.cpp,
// TaskState::shading); both kinds run here, in tiles where rays hit and miss.
TEST_F(TraceCallsTest, AChainOfClosestHitsDeeperThanTheReusedInvocations) { traceStackedQuads(7); }

// A chain of 7 callables, each calling the next (trace_callable_chain.rcall) from the closest-hit shader: the
// executor reuses the callable invocations of nesting levels 0-3 per task and makes deeper ones per call
// (exec/trace.cpp, TaskState::callables); every link's answer reaches its caller, on every hit of the launch.
TEST_F(TraceCallsTest, AChainOfCallablesDeeperThanTheReusedInvocations) {
  constexpr uint32_t kChain = 7;
  // (The stack size set per trace: the default holds two callable levels.)
  VkPipeline p = calls(1, module(kSpv_trace_callable_chain_rcall, sizeof kSpv_trace_callable_chain_rcall), true);
  ASSERT_NE(p, VK_NULL_HANDLE);
  VkAccelerationStructureKHR quad = blas({triangles(kQuad, kQuadIndices, VK_GEOMETRY_OPAQUE_BIT_KHR)});
  VkAccelerationStructureKHR top = tlas({instance(quad, 0.1f, 0, 3, 0, 0)});
  std::vector<SbtRecord> links;
  for (uint32_t k = 0; k < kChain; ++k) links.push_back({3, {1000 + k, k + 1 < kChain ? k + 1 : 0u}});
  Sbt s = sbt(p, 4, {0}, {{1, {7}}}, {{2, {100, 0}}}, links);
  const uint32_t n = 8;
  std::vector<TracePayload> r = trace(p, s, top, n, n, {}, 1 << 16);
  const int hits = forEachQuadPixel(r, n, [&](const TracePayload& q, uint32_t primitive) {
    // Link k gets primitive * 2^k and answers (link k + 1's answer, or what it got) * 3 + 1000 + k.
    uint32_t v = primitive << (kChain - 1);
    for (uint32_t k = kChain; k-- > 0;) v = v * 3 + 1000 + k;
    EXPECT_EQ(q.extra[2], v) << "the chain's answer";
  });
  EXPECT_GT(hits, 10);
  // With stack for five links only, the sixth is not run, and the report names the whole chain that reached it:
  // raygen, closest-hit and six callables, each invocation's caller its own (one level's invocation serving the next
  // would make its own caller, a chain of the one callable as long as the report allows).
  if (!onVkrt()) return;
  const VkDeviceSize raygenStack = getStackSize(device, p, 0, VK_SHADER_GROUP_SHADER_GENERAL_KHR);
  const VkDeviceSize hitStack = getStackSize(device, p, 2, VK_SHADER_GROUP_SHADER_CLOSEST_HIT_KHR);
  const VkDeviceSize linkStack = getStackSize(device, p, 3, VK_SHADER_GROUP_SHADER_GENERAL_KHR);
  ASSERT_GT(linkStack, 0u) << "a link calls a callable: its stack size is not 0";
  clearMessages();
  r = trace(p, s, top, n, n, {}, int64_t(raygenStack + hitStack + 5 * linkStack));
  auto msgs = vkrtMessages();
  ASSERT_EQ(msgs.size(), 1u);
  EXPECT_NE(msgs[0].text.find("(depth 8)"), std::string::npos) << msgs[0].text;
  EXPECT_EQ(msgs[0].text.find("raygen shader"), msgs[0].text.find("the call chain ") + 15) << msgs[0].text;
  clearMessages();
}

class TraceCallsMisuseTest : public TraceCallsTest {
 protected:
  bool layer() override { return false; }
};

TEST_F(TraceCallsMisuseTest, RecursionDeeperThanThePipelineAllowsIsReportedAndNotRun) {
  if (!onVkrt()) GTEST_SKIP() << "vkrt's own diagnostics";
  VkAccelerationStructureKHR quad = blas({triangles(kQuad, kQuadIndices, VK_GEOMETRY_OPAQUE_BIT_KHR)});
  VkAccelerationStructureKHR top = tlas({instance(quad, 0.1f, 0, 3, 0, 0), instance(quad, 0.1f, 0, 5, 0, 1)});
  VkPipeline p = calls(1);  // maxPipelineRayRecursionDepth 1: the closest-hit shader may not trace
  Sbt s = sbt(p, 4, {0}, {{1, {7}}}, {{2, {100, 1}}, {2, {101, 0}}}, {{3, {1000}}});
  clearMessages();
  std::vector<TracePayload> r = trace(p, s, top, 8, 8);
  auto msgs = vkrtMessages();
  ASSERT_EQ(msgs.size(), 1u) << "one report for the whole launch";
  EXPECT_EQ(msgs[0].idName, "VUID-vkCmdTraceRaysKHR-maxPipelineRayRecursionDepth-03679");
  EXPECT_NE(msgs[0].text.find("closest-hit shader \"main\" calls traceRayEXT at recursion depth 2"), std::string::npos)
      << msgs[0].text;
  clearMessages();
  const TracePayload& q = r[3 * 8 + 3];
  EXPECT_NEAR(q.hit[0], 13.0f, 1e-4f) << "the closest-hit shader ran";
  EXPECT_EQ(q.extra[2], q.ids[2] * 2 + 1000) << "its callable ran";
  EXPECT_EQ(q.extra[3], 0u) << "its trace did not";
}

}  // namespace
}  // namespace vkrt::test
