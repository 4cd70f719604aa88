// VK_KHR_ray_tracing_position_fetch: a closest-hit shader reading HitTriangleVertexPositionsKHR
// (tests/shaders/position_fetch.rchit.newer.spvasm) and a compute shader's ray query reading
// OpRayQueryGetIntersectionTriangleVertexPositionsKHR for the candidate and the committed hit
// (position_fetch_query.comp.newer.spvasm). The bottom-level structure is built from the unit quad with a build
// transform (VkAccelerationStructureGeometryTrianglesDataKHR::transformData) and ALLOW_DATA_ACCESS; its instance
// moves it. The positions expected are the quad's vertices through the build transform, computed here: object
// space, without the instance's transform. The Debian 12 validation layer does not know the extension (nor its
// SPIR-V): these tests run without it, and vkrt's own validation of the modules is what checks them.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "e2e/compute_pipeline_helpers.hpp"
#include "e2e/trace_fixture.hpp"
#include "position_fetch.rchit.newer.spvasm.spv.h"
#include "position_fetch_query.comp.newer.spvasm.spv.h"

namespace vkrt::test {
namespace {

// The build transform (rows): x scaled by 2, then moved by (0, 0.5, 1).
constexpr float kBuild[3][4] = {{2, 0, 0, 0}, {0, 1, 0, 0.5f}, {0, 0, 1, 1}};
// The instance's translation.
constexpr float kMove[3] = {0.3f, 0.2f, 5};

// Vertex `k` of triangle `primitive` of the quad, through the build transform.
std::array<float, 3> expectedVertex(uint32_t primitive, uint32_t k) {
  const float* v = &kQuad[3 * kQuadIndices[3 * primitive + k]];
  std::array<float, 3> out{};
  for (int r = 0; r < 3; ++r) out[r] = kBuild[r][0] * v[0] + kBuild[r][1] * v[1] + kBuild[r][2] * v[2] + kBuild[r][3];
  return out;
}

// The quad triangle a ray along +z at world (x, y) hits: undoes the instance's move and the build transform, then
// quadHit. -1: a miss, or too close to an edge to say.
int expectedPrimitive(float x, float y) {
  const float px = (x - kMove[0]) / 2, py = y - kMove[1] - 0.5f;
  if (std::fabs(px) >= 0.999f || std::fabs(py) >= 0.999f)
    return std::fabs(px) > 1.001f || std::fabs(py) > 1.001f ? -2 : -1;
  if (std::fabs(px + py) < 1e-3f) return -1;
  return int(quadHit(px, py).primitive);
}

class PositionFetchTest : public TraceTest {
 protected:
  VkPhysicalDeviceRayQueryFeaturesKHR rqf{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR};
  VkPhysicalDeviceRayTracingPositionFetchFeaturesKHR pff{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_POSITION_FETCH_FEATURES_KHR};

  bool layer() override { return false; }  // the 1.3.239 layer knows neither the extension nor its SPIR-V

  FixtureOptions options() override {
    FixtureOptions o = TraceTest::options();
    o.deviceExtensions.push_back(VK_KHR_RAY_QUERY_EXTENSION_NAME);
    o.deviceExtensions.push_back(VK_KHR_RAY_TRACING_POSITION_FETCH_EXTENSION_NAME);
    rqf.rayQuery = VK_TRUE;
    pff.rayTracingPositionFetch = VK_TRUE;
    pff.pNext = asf.pNext;
    rqf.pNext = &pff;
    asf.pNext = &rqf;
    return o;
  }

  void SetUp() override {
    if (!onVkrtDriver()) GTEST_SKIP() << "vkrt's extension (the machine's other drivers may not have it)";
    TraceTest::SetUp();
  }

  static bool onVkrtDriver() {
    const char* files = std::getenv("VK_DRIVER_FILES");
    return files && std::strstr(files, "vkrt");
  }

  // The quad with the build transform, built with ALLOW_DATA_ACCESS (and `geometryFlags`).
  VkAccelerationStructureKHR transformedQuad(VkGeometryFlagsKHR geometryFlags) {
    Geometry g = triangles(kQuad, kQuadIndices, geometryFlags);
    VkTransformMatrixKHR m;
    std::memcpy(m.matrix, kBuild, sizeof m.matrix);
    g.geometry.geometry.triangles.transformData.deviceAddress = upload(std::vector<VkTransformMatrixKHR>{m});
    return build(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {g},
                 VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR |
                     VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_DATA_ACCESS_KHR);
  }
};

float asFloat(uint32_t bits) {
  float f;
  std::memcpy(&f, &bits, 4);
  return f;
}

TEST_F(PositionFetchTest, TheFeatureIsReported) {
  VkPhysicalDeviceRayTracingPositionFetchFeaturesKHR f{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_POSITION_FETCH_FEATURES_KHR};
  VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &f};
  vkGetPhysicalDeviceFeatures2(physicalDevice, &f2);
  EXPECT_EQ(f.rayTracingPositionFetch, VK_TRUE);
}

TEST_F(PositionFetchTest, ClosestHitReadsTheObjectSpaceVerticesOfTheHitTriangle) {
  VkAccelerationStructureKHR quad = transformedQuad(VK_GEOMETRY_OPAQUE_BIT_KHR);
  VkAccelerationStructureKHR top = tlas({instance(quad, kMove[0], kMove[1], kMove[2], 0, 0)});
  VkShaderModule chit = module(kSpv_position_fetch_rchit_newer_spvasm, sizeof kSpv_position_fetch_rchit_newer_spvasm);
  Desc d;
  d.layout = traceLayout;
  d.general(rgen, VK_SHADER_STAGE_RAYGEN_BIT_KHR);
  d.general(tmiss, VK_SHADER_STAGE_MISS_BIT_KHR);
  d.group(VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR, VK_SHADER_UNUSED_KHR,
          d.stage(chit, VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR));
  VkPipeline p = make(d);
  ASSERT_NE(p, VK_NULL_HANDLE);
  constexpr uint32_t n = 8;
  std::vector<TracePayload> r = trace(p, sbt(p, 3, {0}, {{1, {7}}}, {{2, {100}}}), top, n, n);
  int hits[2] = {0, 0};
  for (uint32_t y = 0; y < n; ++y)
    for (uint32_t x = 0; x < n; ++x) {
      const TracePayload& t = r[y * n + x];
      const float wx = cellCentre(x, n), wy = cellCentre(y, n);
      SCOPED_TRACE("ray at " + std::to_string(wx) + "," + std::to_string(wy));
      const int want = expectedPrimitive(wx, wy);
      if (want == -1) continue;
      if (want == -2) {
        EXPECT_EQ(t.hit[0], -2.0f) << "a miss";
        continue;
      }
      ASSERT_EQ(t.extra[1], uint32_t(want)) << "primitive";
      EXPECT_EQ(t.extra[2], 0u) << "instance";
      const float got[9] = {t.hit[0],          t.hit[1],          t.hit[2],
                            t.hit[3],          asFloat(t.ids[0]), asFloat(t.ids[1]),
                            asFloat(t.ids[2]), asFloat(t.ids[3]), asFloat(t.extra[0])};
      for (uint32_t k = 0; k < 3; ++k) {
        const std::array<float, 3> v = expectedVertex(uint32_t(want), k);
        for (int c = 0; c < 3; ++c) EXPECT_FLOAT_EQ(got[3 * k + c], v[c]) << "vertex " << k << " component " << c;
      }
      ++hits[want];
    }
  EXPECT_GT(hits[0], 2);
  EXPECT_GT(hits[1], 2);
}

TEST_F(PositionFetchTest, RayQueryReadsTheCandidateAndTheCommittedVertices) {
  // Not opaque: the triangle is a candidate the shader sees (and confirms) before it is committed.
  VkAccelerationStructureKHR quad = transformedQuad(0);
  VkAccelerationStructureKHR top = tlas({instance(quad, kMove[0], kMove[1], kMove[2])});
  ComputePipeline q = makeComputePipeline(device, kSpv_position_fetch_query_comp_newer_spvasm,
                                          sizeof kSpv_position_fetch_query_comp_newer_spvasm,
                                          {VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR,
                                           VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER});
  ASSERT_EQ(q.result, VK_SUCCESS);
  // Two rays on each triangle, and one that misses.
  const std::vector<std::array<float, 2>> at = {{-1.0f, 0.0f}, {0.0f, 0.5f}, {1.5f, 1.2f}, {2.0f, 0.9f}, {3.0f, 0.0f}};
  HostBuffer& in = buffer(16 * at.size(), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  HostBuffer& out = buffer(18 * 4 * at.size(), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  for (size_t i = 0; i < at.size(); ++i) {
    const float o[4] = {at[i][0], at[i][1], -10, 0};
    std::memcpy(static_cast<uint8_t*>(in.data) + 16 * i, o, 16);
  }
  std::memset(out.data, 0xee, out.size);
  VkWriteDescriptorSetAccelerationStructureKHR asw{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_KHR};
  asw.accelerationStructureCount = 1;
  asw.pAccelerationStructures = &top;
  VkDescriptorBufferInfo bi{in.buffer, 0, VK_WHOLE_SIZE}, bo{out.buffer, 0, VK_WHOLE_SIZE};
  VkWriteDescriptorSet w[3] = {{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, &asw},
                               {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET},
                               {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET}};
  for (uint32_t i = 0; i < 3; ++i) {
    w[i].dstSet = q.set;
    w[i].dstBinding = i;
    w[i].descriptorCount = 1;
    w[i].descriptorType = i ? VK_DESCRIPTOR_TYPE_STORAGE_BUFFER : VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR;
  }
  w[1].pBufferInfo = &bi;
  w[2].pBufferInfo = &bo;
  vkUpdateDescriptorSets(device, 3, w, 0, nullptr);
  VkCommandBuffer cb = beginOneTime();
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, q.pipeline);
  vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, q.layout, 0, 1, &q.set, 0, nullptr);
  vkCmdDispatch(cb, uint32_t(at.size()), 1, 1);
  submitAndWait(cb);
  const float* f = static_cast<const float*>(out.data);
  int hits = 0;
  for (size_t i = 0; i < at.size(); ++i) {
    SCOPED_TRACE("ray at " + std::to_string(at[i][0]) + "," + std::to_string(at[i][1]));
    const int want = expectedPrimitive(at[i][0], at[i][1]);
    ASSERT_NE(want, -1) << "the test's rays keep off edges";
    for (int which = 0; which < 2; ++which) {  // 0: the candidate, 1: the committed hit
      for (uint32_t k = 0; k < 3; ++k) {
        const std::array<float, 3> v = want >= 0 ? expectedVertex(uint32_t(want), k) : std::array<float, 3>{};
        for (int c = 0; c < 3; ++c)
          EXPECT_FLOAT_EQ(f[18 * i + 9 * which + 3 * k + c], v[c])
              << (which ? "committed" : "candidate") << " vertex " << k << " component " << c;
      }
    }
    hits += want >= 0;
  }
  EXPECT_EQ(hits, 4);
  vkDeviceWaitIdle(device);
  destroyComputePipeline(device, q);
}

}  // namespace
}  // namespace vkrt::test
