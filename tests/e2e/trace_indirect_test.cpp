// Indirect launches: vkCmdTraceRaysIndirectKHR reads the launch size (VkTraceRaysIndirectCommandKHR), and
// vkCmdTraceRaysIndirect2KHR (VK_KHR_ray_tracing_maintenance1) the shader binding table regions as well
// (VkTraceRaysIndirectCommand2KHR), from device memory when the command executes, not when it is recorded. The
// CTS's trace_rays_indirect2.* submit on the first queue family with graphics (submit_graphics) and the first with
// compute (submit_compute); vkrt's one family has both. Expectations: the quad [-1, 1]^2 at z = 5 seen from z = -10
// by trace_raygen's grid of origins (cell centres over [-2, 2]^2), a hit at t = 15 where |x|, |y| < 1.
#include "e2e/trace_fixture.hpp"

namespace vkrt::test {
namespace {

class TraceIndirectTest : public TraceTest {
 protected:
  VkPhysicalDeviceRayTracingMaintenance1FeaturesKHR m1{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_MAINTENANCE_1_FEATURES_KHR};
  PFN_vkCmdTraceRaysIndirectKHR cmdTraceIndirect = nullptr;
  PFN_vkCmdTraceRaysIndirect2KHR cmdTraceIndirect2 = nullptr;
  VkAccelerationStructureKHR top = VK_NULL_HANDLE;
  VkPipeline pipeline = VK_NULL_HANDLE;
  Sbt table;

  virtual bool indirectFeatures() { return true; }

  FixtureOptions options() override {
    FixtureOptions o = TraceTest::options();
    o.deviceExtensions.push_back(VK_KHR_RAY_TRACING_MAINTENANCE_1_EXTENSION_NAME);
    rtf.rayTracingPipelineTraceRaysIndirect = indirectFeatures();
    m1.rayTracingMaintenance1 = VK_TRUE;
    m1.rayTracingPipelineTraceRaysIndirect2 = indirectFeatures();
    m1.pNext = nullptr;
    asf.pNext = &m1;
    return o;
  }

  void SetUp() override {
    TraceTest::SetUp();
    if (HasFatalFailure() || !device) return;
    load(cmdTraceIndirect, "vkCmdTraceRaysIndirectKHR");
    load(cmdTraceIndirect2, "vkCmdTraceRaysIndirect2KHR");
    VkAccelerationStructureKHR quad = blas({triangles(kQuad, kQuadIndices, VK_GEOMETRY_OPAQUE_BIT_KHR)});
    top = tlas({instance(quad, 0, 0, 5)});
    Desc d = basicDesc();
    pipeline = make(d);
    ASSERT_NE(pipeline, VK_NULL_HANDLE);
    table = sbt(pipeline, 3, {0}, {{1, {7}}}, {{2, {100}}});
  }

  // Records `launch` (which records the trace) with the scene bound, writes `command` to its buffer only after
  // recording (it is read when the command buffer executes), submits; returns width x height payloads.
  template <class Command, class Launch>
  std::vector<TracePayload> traceIndirect(const Command& command, uint32_t width, uint32_t height, Launch launch) {
    HostBuffer& out = buffer(sizeof(TracePayload) * width * height, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    std::memset(out.data, 0xee, out.size);
    HostBuffer& args = buffer(sizeof(Command), VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
    std::memset(args.data, 0, sizeof(Command));
    VkWriteDescriptorSetAccelerationStructureKHR asw{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_KHR};
    asw.accelerationStructureCount = 1;
    asw.pAccelerationStructures = &top;
    VkDescriptorSet set = sceneSet(pool, setLayout, VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, &asw, out);
    VkCommandBuffer cb = beginOneTime();
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, pipeline);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, traceLayout, 0, 1, &set, 0, nullptr);
    TraceParams params;
    vkCmdPushConstants(cb, traceLayout, VK_SHADER_STAGE_RAYGEN_BIT_KHR, 0, sizeof params, &params);
    launch(cb, addressOf(args));
    std::memcpy(args.data, &command, sizeof command);
    submitAndWait(cb);
    vkFreeDescriptorSets(device, pool, 1, &set);
    std::vector<TracePayload> r(width * height);
    std::memcpy(r.data(), out.data, r.size() * sizeof(TracePayload));
    return r;
  }

  // Each payload of a width x height launch against the quad: t = 15 and hit group record data 100 inside it, the
  // miss (its record data 7) outside.
  static void expectQuad(const std::vector<TracePayload>& r, uint32_t width, uint32_t height) {
    int hits = 0;
    for (uint32_t y = 0; y < height; ++y)
      for (uint32_t x = 0; x < width; ++x) {
        const float cx = cellCentre(x, width), cy = cellCentre(y, height);
        const TracePayload& q = r[y * width + x];
        SCOPED_TRACE("launch index " + std::to_string(x) + "," + std::to_string(y));
        if (std::fabs(cx) < 1 && std::fabs(cy) < 1) {
          ++hits;
          EXPECT_NEAR(q.hit[0], 15.0f, 1e-4f);
          EXPECT_EQ(q.extra[0], 100u);
        } else {
          EXPECT_EQ(q.hit[0], -2.0f);
          EXPECT_EQ(q.extra[0], 7u);
        }
      }
    EXPECT_GT(hits, 0);
  }
};

TEST_F(TraceIndirectTest, TheQueueFamilyWithGraphicsAlsoTraces) {
  // The CTS's submit_graphics and submit_compute cases pick the first family with each bit: on vkrt the one family
  // the fixture's queue belongs to.
  uint32_t n = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(physicalDevice, &n, nullptr);
  std::vector<VkQueueFamilyProperties> families(n);
  vkGetPhysicalDeviceQueueFamilyProperties(physicalDevice, &n, families.data());
  ASSERT_GE(n, 1u);
  if (onVkrt()) {
    EXPECT_EQ(families[0].queueFlags & (VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT),
              VkQueueFlags(VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT));
  }
  VkTraceRaysIndirectCommand2KHR c{};
  c.raygenShaderRecordAddress = table.raygen.deviceAddress;
  c.raygenShaderRecordSize = table.raygen.size;
  c.missShaderBindingTableAddress = table.miss.deviceAddress;
  c.missShaderBindingTableSize = table.miss.size;
  c.missShaderBindingTableStride = table.miss.stride;
  c.hitShaderBindingTableAddress = table.hit.deviceAddress;
  c.hitShaderBindingTableSize = table.hit.size;
  c.hitShaderBindingTableStride = table.hit.stride;
  c.width = 11, c.height = 17, c.depth = 1;  // the CTS's first size
  expectQuad(traceIndirect(c, 11, 17, [&](VkCommandBuffer cb, VkDeviceAddress a) { cmdTraceIndirect2(cb, a); }), 11,
             17);
}

TEST_F(TraceIndirectTest, Indirect2ReadsTheTablesAndTheSizeWhenItExecutes) {
  // An 8 x 4 launch; the tables come from the command alone (nothing else names them).
  VkTraceRaysIndirectCommand2KHR c{};
  c.raygenShaderRecordAddress = table.raygen.deviceAddress;
  c.raygenShaderRecordSize = table.raygen.size;
  c.missShaderBindingTableAddress = table.miss.deviceAddress;
  c.missShaderBindingTableSize = table.miss.size;
  c.missShaderBindingTableStride = table.miss.stride;
  c.hitShaderBindingTableAddress = table.hit.deviceAddress;
  c.hitShaderBindingTableSize = table.hit.size;
  c.hitShaderBindingTableStride = table.hit.stride;
  c.width = 8, c.height = 4, c.depth = 1;
  expectQuad(traceIndirect(c, 8, 4, [&](VkCommandBuffer cb, VkDeviceAddress a) { cmdTraceIndirect2(cb, a); }), 8, 4);
  // Another hit table (record data 300) in the command: the launch uses it.
  Sbt other = sbt(pipeline, 3, {0}, {{1, {7}}}, {{2, {300}}});
  c.hitShaderBindingTableAddress = other.hit.deviceAddress;
  std::vector<TracePayload> r =
      traceIndirect(c, 8, 4, [&](VkCommandBuffer cb, VkDeviceAddress a) { cmdTraceIndirect2(cb, a); });
  EXPECT_EQ(r[1 * 8 + 3].extra[0], 300u) << "a hit (x -0.25, y -0.5) ran the command's hit record";
}

TEST_F(TraceIndirectTest, IndirectReadsTheSizeWhenItExecutes) {
  const VkTraceRaysIndirectCommandKHR c{12, 4, 1};
  expectQuad(traceIndirect(c, 12, 4,
                           [&](VkCommandBuffer cb, VkDeviceAddress a) {
                             cmdTraceIndirect(cb, &table.raygen, &table.miss, &table.hit, &table.callable, a);
                           }),
             12, 4);
}

// vkrt's checks of the indirect address at record time. The layer is off: it would report the same.
class TraceIndirectMisuseTest : public TraceIndirectTest {
 protected:
  bool layer() override { return false; }
  void SetUp() override {
    TraceIndirectTest::SetUp();
    if (HasFatalFailure() || !device) return;
    if (!onVkrt()) GTEST_SKIP() << "vkrt's own diagnostics";
  }
};

TEST_F(TraceIndirectMisuseTest, AnUnalignedOrUnboundAddressIsReportedAndNothingIsRecorded) {
  HostBuffer& args = buffer(64, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
  const VkDeviceAddress a = addressOf(args);
  VkCommandBuffer cb = beginOneTime();
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, pipeline);
  clearMessages();
  // VUID-vkCmdTraceRaysIndirect2KHR-indirectDeviceAddress-03634: a multiple of 4.
  cmdTraceIndirect2(cb, a + 2);
  expectVkrtMessage("VUID-vkCmdTraceRaysIndirect2KHR-indirectDeviceAddress-03634");
  cmdTraceIndirect(cb, &table.raygen, &table.miss, &table.hit, &table.callable, a + 2);
  expectVkrtMessage("VUID-vkCmdTraceRaysIndirectKHR-indirectDeviceAddress-03634");
  // VUID-...-indirectDeviceAddress-03636: the command's bytes inside device memory (vkrt checks the memory, not
  // the buffer's extent within it); 4 and 0 are aligned and outside every allocation.
  cmdTraceIndirect2(cb, 4);
  expectVkrtMessage("VUID-vkCmdTraceRaysIndirect2KHR-indirectDeviceAddress-03636");
  cmdTraceIndirect(cb, &table.raygen, &table.miss, &table.hit, &table.callable, 0);
  expectVkrtMessage("VUID-vkCmdTraceRaysIndirectKHR-indirectDeviceAddress-03636");
  submitAndWait(cb);
  EXPECT_TRUE(vkrtMessages().empty()) << "nothing was recorded, so nothing ran";
}

TEST_F(TraceIndirectMisuseTest, AnAlignedBoundAddressIsNotReported) {
  VkTraceRaysIndirectCommand2KHR c{};
  c.raygenShaderRecordAddress = table.raygen.deviceAddress;
  c.raygenShaderRecordSize = table.raygen.size;
  c.missShaderBindingTableAddress = table.miss.deviceAddress;
  c.missShaderBindingTableSize = table.miss.size;
  c.missShaderBindingTableStride = table.miss.stride;
  c.hitShaderBindingTableAddress = table.hit.deviceAddress;
  c.hitShaderBindingTableSize = table.hit.size;
  c.hitShaderBindingTableStride = table.hit.stride;
  c.width = c.height = c.depth = 1;
  clearMessages();
  traceIndirect(c, 1, 1, [&](VkCommandBuffer cb, VkDeviceAddress a) { cmdTraceIndirect2(cb, a); });
  EXPECT_TRUE(vkrtMessages().empty());
}

// VUID-vkCmdTraceRaysIndirect2KHR-rayTracingPipelineTraceRaysIndirect2-03637 (and the Indirect one's): the
// features off.
class TraceIndirectWithoutFeaturesTest : public TraceIndirectMisuseTest {
 protected:
  bool indirectFeatures() override { return false; }
};

TEST_F(TraceIndirectWithoutFeaturesTest, IndirectTracesNeedTheirFeatures) {
  HostBuffer& args = buffer(64, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
  VkCommandBuffer cb = beginOneTime();
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, pipeline);
  clearMessages();
  cmdTraceIndirect2(cb, addressOf(args));
  expectVkrtMessage("VUID-vkCmdTraceRaysIndirect2KHR-rayTracingPipelineTraceRaysIndirect2-03637");
  cmdTraceIndirect(cb, &table.raygen, &table.miss, &table.hit, &table.callable, addressOf(args));
  expectVkrtMessage("VUID-vkCmdTraceRaysIndirectKHR-rayTracingPipelineTraceRaysIndirect-03637");
  submitAndWait(cb);
}

}  // namespace
}  // namespace vkrt::test
