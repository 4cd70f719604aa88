// The extent of a shader binding table record: record i of a region is at deviceAddress + i x stride, and every
// byte a launch reads there must lie less than the region's size from its start ("Shader Binding Table" >
// "Indexing Rules"). A record whose handle (and the shader record data its shader reads) lies inside the region is
// valid even when the stride is larger than the size (one handle-sized record with a stride of 64, as the CTS's
// callable_shader.* and pipeline_no_null_shaders_flag.* tests trace): it runs, and nothing is reported. A record
// whose handle lies past the region is reported (without a VUID: the rule has none) and not run; a shader that
// reads its record's data past the region is reported too, and its read returns the bytes there. The raygen
// region's size must equal its stride (VUID-vkCmdTraceRaysKHR-size-04023) and hold the handle.
#include <initializer_list>

#include "e2e/trace_fixture.hpp"
#include "pipeline_call.rcall.spv.h"
#include "trace_chit_calls.rchit.spv.h"
#include "trace_miss_cts_record.rmiss.spv.h"
#include "trace_miss_handle_only.rmiss.spv.h"

namespace vkrt::test {
namespace {

class TraceSbtTest : public TraceTest {
 protected:
  void SetUp() override {
    TraceTest::SetUp();
    if (HasFatalFailure() || !device) return;
    quad = blas({triangles(kQuad, kQuadIndices, VK_GEOMETRY_OPAQUE_BIT_KHR)});
    top = tlas({instance(quad, 0, 0, 5)});
  }
  // A region of `size` bytes with `stride` in a buffer of its own (512 bytes: every stride used here is at most
  // the buffer's size, VUID-VkStridedDeviceAddressRegionKHR-size-04632): the handle of `group` (from `h`) at each
  // byte offset of `at`, each followed by `data` as shader record data.
  VkStridedDeviceAddressRegionKHR region(const std::vector<uint8_t>& h, uint32_t group,
                                         std::initializer_list<uint64_t> at, VkDeviceSize stride, VkDeviceSize size,
                                         const std::vector<uint32_t>& data = {}) {
    const uint32_t hs = rtProps.shaderGroupHandleSize, align = rtProps.shaderGroupBaseAlignment;
    HostBuffer& b = buffer(512 + align, VK_BUFFER_USAGE_SHADER_BINDING_TABLE_BIT_KHR);
    const VkDeviceAddress base = (addressOf(b) + align - 1) / align * align;
    uint8_t* bytes = static_cast<uint8_t*>(b.data) + (base - addressOf(b));
    std::memset(bytes, 0, 512);
    for (uint64_t offset : at) {
      std::memcpy(bytes + offset, h.data() + size_t(group) * hs, hs);
      if (!data.empty()) std::memcpy(bytes + offset + hs, data.data(), data.size() * 4);
    }
    return {base, stride, size};
  }
  // raygen, trace_miss_handle_only, a triangle hit group with trace_chit.
  VkPipeline handleOnlyMiss() {
    Desc d;
    d.layout = traceLayout;
    d.general(rgen, VK_SHADER_STAGE_RAYGEN_BIT_KHR);
    d.general(module(kSpv_trace_miss_handle_only_rmiss, sizeof kSpv_trace_miss_handle_only_rmiss),
              VK_SHADER_STAGE_MISS_BIT_KHR);
    d.group(VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR, VK_SHADER_UNUSED_KHR,
            d.stage(tchit, VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR));
    return make(d);
  }
  // Of a 4 x 4 launch over the quad at z = 5: launch index 5 hits it, index 0 misses.
  static constexpr uint32_t kHit = 5, kMiss = 0;
  VkAccelerationStructureKHR quad = VK_NULL_HANDLE, top = VK_NULL_HANDLE;
};

TEST_F(TraceSbtTest, AMissRecordOfAHandlesSizeRunsWithAStrideLargerThanItsRegion) {
  VkPipeline p = handleOnlyMiss();
  ASSERT_NE(p, VK_NULL_HANDLE);
  const std::vector<uint8_t> h = handles(p, 0, 3);
  Sbt s = sbt(p, 3, {0}, {{1}}, {{2, {100}}});
  s.miss = region(h, 1, {0, 64}, 64, rtProps.shaderGroupHandleSize);  // size 32, stride 64: record 0 only
  std::vector<TracePayload> r = trace(p, s, top, 4, 4);
  EXPECT_EQ(r[kMiss].hit[0], -2.0f) << "the miss shader ran";
  EXPECT_EQ(r[kMiss].extra[0], 77u);
  EXPECT_EQ(r[kHit].extra[0], 100u) << "the hit ran its closest-hit shader";
  // Record 1's handle ends exactly at the region's end (64 + 32 = 96 bytes): it is inside, and runs.
  s.miss = region(h, 1, {0, 64}, 64, 64 + rtProps.shaderGroupHandleSize);
  TraceParams t;
  t.missIndex = 1;
  r = trace(p, s, top, 4, 4, t);
  EXPECT_EQ(r[kMiss].hit[0], -2.0f) << "miss record 1 ran";
  EXPECT_EQ(r[kMiss].extra[0], 77u);
  // (TearDown: vkrt reported nothing.)
}

TEST_F(TraceSbtTest, WithAZeroStrideEveryIndexIsRecordZero) {
  VkPipeline p = handleOnlyMiss();
  ASSERT_NE(p, VK_NULL_HANDLE);
  Sbt s = sbt(p, 3, {0}, {{1}}, {{2, {100}}});
  // deviceAddress + 0 x missIndex: miss index 3 reads record 0, inside the region.
  s.miss = region(handles(p, 0, 3), 1, {0}, 0, rtProps.shaderGroupHandleSize);
  TraceParams t;
  t.missIndex = 3;
  std::vector<TracePayload> r = trace(p, s, top, 4, 4, t);
  EXPECT_EQ(r[kMiss].hit[0], -2.0f) << "the miss shader of record 0 ran";
  EXPECT_EQ(r[kMiss].extra[0], 77u);
}

TEST_F(TraceSbtTest, ACallableRecordOfAHandlesSizeRunsWithAStrideLargerThanItsRegion) {
  Desc d;
  d.layout = traceLayout;
  d.general(rgen, VK_SHADER_STAGE_RAYGEN_BIT_KHR);
  d.general(tmiss, VK_SHADER_STAGE_MISS_BIT_KHR);
  d.group(VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR, VK_SHADER_UNUSED_KHR,
          d.stage(module(kSpv_trace_chit_calls_rchit, sizeof kSpv_trace_chit_calls_rchit),
                  VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR));
  // pipeline_call.rcall: data * 2 + 1, no shader record.
  d.general(module(kSpv_pipeline_call_rcall, sizeof kSpv_pipeline_call_rcall), VK_SHADER_STAGE_CALLABLE_BIT_KHR);
  VkPipeline p = make(d);
  ASSERT_NE(p, VK_NULL_HANDLE);
  Sbt s = sbt(p, 4, {0}, {{1, {7}}}, {{2, {100, 0}}});
  s.callable = region(handles(p, 0, 4), 3, {0}, 64, rtProps.shaderGroupHandleSize);
  std::vector<TracePayload> r = trace(p, s, top, 4, 4);
  EXPECT_EQ(r[kHit].extra[0], 100u) << "the closest-hit shader ran";
  EXPECT_EQ(r[kHit].extra[2], r[kHit].ids[2] * 2 + 1) << "the callable ran: data (gl_PrimitiveID) x 2 + 1";
}

TEST_F(TraceSbtTest, AHitRecordWhoseDataEndsTheRegionRunsWithALargerStride) {
  Desc d = basicDesc();
  VkPipeline p = make(d);
  ASSERT_NE(p, VK_NULL_HANDLE);
  Sbt s = sbt(p, 3, {0}, {{1, {7}}}, {{2, {100}}});
  // The handle and the 4-byte tag trace_chit reads: 36 bytes of region, stride 64.
  s.hit = region(handles(p, 0, 3), 2, {0}, 64, rtProps.shaderGroupHandleSize + 4, {123});
  std::vector<TracePayload> r = trace(p, s, top, 4, 4);
  EXPECT_NEAR(r[kHit].hit[0], 15.0f, 1e-4f) << "the closest-hit shader ran";
  EXPECT_EQ(r[kHit].extra[0], 123u) << "with its record's tag";
  EXPECT_EQ(r[kMiss].extra[0], 7u);
}

TEST_F(TraceSbtTest, ARaygenRegionOfExactlyAHandleRuns) {
  Desc d = basicDesc();
  VkPipeline p = make(d);
  ASSERT_NE(p, VK_NULL_HANDLE);
  Sbt s = sbt(p, 3, {0}, {{1, {7}}}, {{2, {100}}});
  const VkDeviceSize hs = rtProps.shaderGroupHandleSize;
  s.raygen = region(handles(p, 0, 3), 0, {0}, hs, hs);
  std::vector<TracePayload> r = trace(p, s, top, 4, 4);
  EXPECT_EQ(r[kHit].extra[0], 100u);
  EXPECT_EQ(r[kMiss].extra[0], 7u);
}

class TraceSbtMisuseTest : public TraceSbtTest {
 protected:
  bool layer() override { return false; }
  void SetUp() override {
    TraceSbtTest::SetUp();
    if (HasFatalFailure() || !device) return;
    if (!onVkrt()) GTEST_SKIP() << "vkrt's own diagnostics";
  }
  // Asserts one vkrt report naming `vuid` (null: a report without one) whose text contains each of `parts`.
  void expectReport(const char* vuid, std::initializer_list<const char*> parts) {
    auto msgs = vkrtMessages();
    ASSERT_EQ(msgs.size(), 1u) << "expected one report naming " << (vuid ? vuid : "no VUID")
                               << (msgs.empty() ? "" : ", first: " + msgs[0].text);
    EXPECT_EQ(msgs[0].idName, vuid ? vuid : "vkrt") << msgs[0].text;
    for (const char* part : parts)
      EXPECT_NE(msgs[0].text.find(part), std::string::npos) << "missing \"" << part << "\" in: " << msgs[0].text;
    clearMessages();
  }
};

// The CTS's pipeline_no_null_shaders_flag.* give their miss region one handle of size (32) with a stride of 64,
// and the miss shader reads the record's data after the handle: past the region, which "Indexing Rules" forbids
// ("All data accessed must be less than size bytes from the base address"). GPUs read the bytes there; vkrt
// reads the stride's worth where it is the application's memory too (zeros before: 185 CTS cases failed), and
// reports the read (no VUID), once per launch and record. A record whose data ends the region is not reported
// (AHitRecordWhoseDataEndsTheRegionRunsWithALargerStride).
TEST_F(TraceSbtMisuseTest, ShaderRecordDataReadPastTheRegionIsReportedAndStillRead) {
  Desc d = basicDesc();
  VkPipeline p = make(d);
  ASSERT_NE(p, VK_NULL_HANDLE);
  const std::vector<uint8_t> h = handles(p, 0, 3);
  Sbt s = sbt(p, 3, {0}, {{1, {7}}}, {{2, {100}}});
  const Sbt valid = s;
  s.hit = region(h, 2, {0}, 64, rtProps.shaderGroupHandleSize, {123});
  for (int launch = 0; launch < 2; ++launch) {
    SCOPED_TRACE("launch " + std::to_string(launch));
    std::vector<TracePayload> r = trace(p, s, top, 4, 4);
    // Every hit of the launch reads hit record 0's tag: one report per launch.
    expectReport(nullptr, {"closest-hit shader \"main\", run for hit record 0", "bytes [0, 4)",
                           "past the end of the hit region (the record has 0 bytes of data inside it)",
                           "Indexing Rules", "returns the bytes there"});
    EXPECT_NEAR(r[kHit].hit[0], 15.0f, 1e-4f) << "the closest-hit shader ran";
    EXPECT_EQ(r[kHit].extra[0], 123u) << "with its record's tag, past the region's 32 bytes";
    EXPECT_EQ(r[kMiss].extra[0], 7u);
  }
  s = valid;
  s.miss = region(h, 1, {0}, 64, rtProps.shaderGroupHandleSize, {9});
  std::vector<TracePayload> r = trace(p, s, top, 4, 4);
  expectReport(nullptr, {"miss shader \"main\", run for miss record 0", "bytes [0, 4)"});
  EXPECT_EQ(r[kMiss].extra[0], 9u) << "the miss shader read its record's tag";
  EXPECT_EQ(r[kHit].extra[0], 100u);
  // Two miss records, 64 apart, in a region of 96 bytes: record 0's tag lies inside the region, record 1's (bytes
  // [96, 100) from the start) past it; only record 1 is reported.
  s.miss = region(h, 1, {0, 64}, 64, 64 + rtProps.shaderGroupHandleSize, {9});
  trace(p, s, top, 4, 4);
  EXPECT_TRUE(vkrtMessages().empty()) << "miss record 0's data lies inside the region";
  TraceParams t;
  t.missIndex = 1;
  r = trace(p, s, top, 4, 4, t);
  expectReport(nullptr, {"miss record 1", "bytes [0, 4)"});
  EXPECT_EQ(r[kMiss].extra[0], 9u);
}

// The CTS's miss shader itself (trace_miss_cts_record.rmiss reads the ivec4 at bytes 16..31 of its record): with
// the region holding the handle only (the test as upstream has it), half of the record (24 bytes: the vector's
// first half) and all of it (tools/cts/pipeline-flags-test.patch). Only a read that ends past the region is
// reported, and each returns the record's values.
TEST_F(TraceSbtMisuseTest, TheCtsMissShadersVectorReadIsCheckedAgainstTheRegion) {
  Desc d;
  d.layout = traceLayout;
  d.general(rgen, VK_SHADER_STAGE_RAYGEN_BIT_KHR);
  d.general(module(kSpv_trace_miss_cts_record_rmiss, sizeof kSpv_trace_miss_cts_record_rmiss),
            VK_SHADER_STAGE_MISS_BIT_KHR);
  d.group(VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR, VK_SHADER_UNUSED_KHR,
          d.stage(tchit, VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR));
  VkPipeline p = make(d);
  ASSERT_NE(p, VK_NULL_HANDLE);
  const std::vector<uint8_t> h = handles(p, 0, 3);
  Sbt s = sbt(p, 3, {0}, {{1}}, {{2, {100}}});
  const uint32_t hs = rtProps.shaderGroupHandleSize;
  const std::vector<uint32_t> record = {1, 0xffffffffu, 0, 0, 0, '-', 0, 0};  // geomType, geomIndex, 2 pad, retValue
  for (uint32_t inside : {0u, 24u, 32u}) {
    SCOPED_TRACE(std::to_string(inside) + " bytes of the record inside the region");
    s.miss = region(h, 1, {0}, 64, hs + inside, record);
    std::vector<TracePayload> r = trace(p, s, top, 4, 4);
    if (inside < 32) {
      expectReport(nullptr, {"miss shader \"main\", run for miss record 0", "bytes [16, 32)",
                             ("the record has " + std::to_string(inside) + " bytes of data inside it").c_str()});
    } else {
      EXPECT_TRUE(vkrtMessages().empty()) << "the read ends at the region's end";
    }
    EXPECT_EQ(r[kMiss].hit[0], -2.0f) << "the miss shader ran";
    EXPECT_EQ(r[kMiss].extra[0], 0u);
    EXPECT_EQ(r[kMiss].extra[1], uint32_t('-')) << "retValue.y, read past the region or not";
    EXPECT_EQ(r[kHit].extra[0], 100u);
  }
}

TEST_F(TraceSbtMisuseTest, AMissRecordWhoseHandleLiesPastTheRegionIsReportedAndNotRun) {
  VkPipeline p = handleOnlyMiss();
  ASSERT_NE(p, VK_NULL_HANDLE);
  const std::vector<uint8_t> h = handles(p, 0, 3);
  Sbt s = sbt(p, 3, {0}, {{1}}, {{2, {100}}});
  TraceParams t;
  t.missIndex = 1;
  // A real miss handle at offset 64 (record 1), outside a region of 32 bytes: not run.
  s.miss = region(h, 1, {0, 64}, 64, rtProps.shaderGroupHandleSize);
  clearMessages();
  std::vector<TracePayload> r = trace(p, s, top, 4, 4, t);
  expectReport(nullptr, {"miss record 1", "offset 64", "outside its region of 32 bytes", "Indexing Rules"});
  EXPECT_EQ(r[kMiss].hit[0], -1.0f) << "the miss shader did not run (the payload is as raygen set it)";
  EXPECT_EQ(r[kHit].extra[0], 100u) << "the rest of the launch ran";
  // One byte short of record 1's handle.
  s.miss = region(h, 1, {0, 64}, 64, 64 + rtProps.shaderGroupHandleSize - 1);
  r = trace(p, s, top, 4, 4, t);
  expectReport(nullptr, {"miss record 1", "outside its region of 95 bytes"});
  EXPECT_EQ(r[kMiss].hit[0], -1.0f);
}

TEST_F(TraceSbtMisuseTest, ACallableRecordWhoseHandleLiesPastTheRegionIsReportedAndNotRun) {
  Desc d;
  d.layout = traceLayout;
  d.general(rgen, VK_SHADER_STAGE_RAYGEN_BIT_KHR);
  d.general(tmiss, VK_SHADER_STAGE_MISS_BIT_KHR);
  d.group(VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR, VK_SHADER_UNUSED_KHR,
          d.stage(module(kSpv_trace_chit_calls_rchit, sizeof kSpv_trace_chit_calls_rchit),
                  VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR));
  d.general(module(kSpv_pipeline_call_rcall, sizeof kSpv_pipeline_call_rcall), VK_SHADER_STAGE_CALLABLE_BIT_KHR);
  VkPipeline p = make(d);
  ASSERT_NE(p, VK_NULL_HANDLE);
  Sbt s = sbt(p, 4, {0}, {{1, {7}}}, {{2, {100, 0}}});
  // The handle lies at offset 0 of a region of 31 bytes: one byte of it is outside.
  s.callable = region(handles(p, 0, 4), 3, {0}, 64, rtProps.shaderGroupHandleSize - 1);
  clearMessages();
  std::vector<TracePayload> r = trace(p, s, top, 4, 4);
  expectReport(nullptr, {"callable record 0", "outside its region of 31 bytes"});
  EXPECT_EQ(r[kHit].extra[0], 100u) << "the closest-hit shader ran";
  EXPECT_EQ(r[kHit].extra[2], r[kHit].ids[2]) << "the callable did not: the data is as the closest-hit shader set it";
}

TEST_F(TraceSbtMisuseTest, TheRaygenRegionsSizeMustEqualItsStrideAndHoldTheHandle) {
  Desc d = basicDesc();
  VkPipeline p = make(d);
  ASSERT_NE(p, VK_NULL_HANDLE);
  const std::vector<uint8_t> h = handles(p, 0, 3);
  Sbt s = sbt(p, 3, {0}, {{1, {7}}}, {{2, {100}}});
  const VkDeviceSize hs = rtProps.shaderGroupHandleSize;
  clearMessages();
  // Size 64, stride 32: refused when recorded; nothing runs.
  s.raygen = region(h, 0, {0}, hs, 2 * hs);
  std::vector<TracePayload> r = trace(p, s, top, 4, 4);
  expectReport("VUID-vkCmdTraceRaysKHR-size-04023", {"raygen region's size (64)", "stride (32)"});
  EXPECT_EQ(r[kHit].ids[0], 0xeeeeeeeeu) << "the raygen shader did not run: the output keeps its fill pattern";
  // Size == stride == 16: the rule of 04023 holds, but the handle does not fit: reported without a VUID.
  s.raygen = region(h, 0, {0}, 16, 16);
  r = trace(p, s, top, 4, 4);
  expectReport(nullptr, {"raygen region (16 bytes) cannot hold a shader group handle (32 bytes)", "Indexing Rules"});
  EXPECT_EQ(r[kHit].ids[0], 0xeeeeeeeeu);
}

}  // namespace
}  // namespace vkrt::test
