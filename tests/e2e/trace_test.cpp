// vkCmdTraceRaysKHR end to end: acceleration structures built on the device, a shader binding table written from
// the pipeline's handles, and every launch index's result compared with the hit computed here from the geometry.
#include "e2e/trace_fixture.hpp"

namespace vkrt::test {
namespace {

// A unit quad over [-1, 1]^2 in the plane z = 0: triangle 0 = (v0, v1, v2), triangle 1 = (v2, v1, v3), both with
// the normal cross(v1 - v0, v2 - v0) = +z.
const std::vector<float> kQuad = {-1, -1, 0, 1, -1, 0, -1, 1, 0, 1, 1, 0};
const std::vector<uint32_t> kQuadIndices = {0, 1, 2, 2, 1, 3};

// The expected hit of a ray along +z through the quad at object (px, py): primitive and barycentrics.
struct QuadHit {
  uint32_t primitive;
  float u, v;
};
QuadHit quadHit(float px, float py) {
  if (px + py <= 0) return {0, (px + 1) / 2, (py + 1) / 2};
  float u = (1 - py) / 2;
  return {1, u, (px + 1) / 2 - u};
}

// The launch's ray origins: an 8 x 8 grid of cell centres over [-2, 2]^2 (trace_raygen.rgen).
float cellCentre(uint32_t i, uint32_t n) { return (float(i) + 0.5f) / float(n) * 4.0f - 2.0f; }

class TraceBasics : public TraceTest {};

TEST_F(TraceBasics, TrianglesThroughInstancesWithTransformsCustomIndicesAndSbtOffsets) {
  VkAccelerationStructureKHR quad = blas({triangles(kQuad, kQuadIndices, VK_GEOMETRY_OPAQUE_BIT_KHR)});
  // Instance 0 at z = 5 (moved 0.1 along x so that no ray runs along the diagonal), custom index 10, SBT offset 0;
  // instance 1 at z = 2 and x + 1.6, custom index 20, SBT offset 1.
  VkAccelerationStructureKHR top = tlas({instance(quad, 0.1f, 0, 5, 10, 0), instance(quad, 1.6f, 0, 2, 20, 1)});
  Desc d;
  d.layout = traceLayout;
  d.general(rgen, VK_SHADER_STAGE_RAYGEN_BIT_KHR);
  d.general(tmiss, VK_SHADER_STAGE_MISS_BIT_KHR);
  d.group(VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR, VK_SHADER_UNUSED_KHR, d.stage(tchit, VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR));
  VkPipeline p = make(d);
  ASSERT_NE(p, VK_NULL_HANDLE);
  Sbt s = sbt(p, 3, {0}, {{1, {7}}}, {{2, {100}}, {2, {101}}});
  const uint32_t n = 8;
  std::vector<TracePayload> r = trace(p, s, top, n, n);
  int hits = 0, misses = 0;
  for (uint32_t y = 0; y < n; ++y) {
    for (uint32_t x = 0; x < n; ++x) {
      SCOPED_TRACE("pixel " + std::to_string(x) + "," + std::to_string(y));
      const TracePayload& p = r[y * n + x];
      const float wx = cellCentre(x, n), wy = cellCentre(y, n);
      const bool inB = wx - 1.6f >= -1 && wx - 1.6f <= 1 && wy >= -1 && wy <= 1;
      const bool inA = wx - 0.1f >= -1 && wx - 0.1f <= 1 && wy >= -1 && wy <= 1;
      if (!inA && !inB) {
        ++misses;
        EXPECT_EQ(p.hit[0], -2.0f);
        EXPECT_EQ(p.extra[0], 7u) << "the miss record's tag";
        EXPECT_EQ(p.hit[2], 100.0f) << "gl_RayTmaxEXT in the miss shader";
        continue;
      }
      ++hits;
      const float tx = inB ? 1.6f : 0.1f;
      const QuadHit q = quadHit(wx - tx, wy);
      EXPECT_NEAR(p.hit[0], inB ? 12.0f : 15.0f, 1e-4f) << "gl_HitTEXT";
      EXPECT_NEAR(p.hit[1], q.u, 1e-5f);
      EXPECT_NEAR(p.hit[2], q.v, 1e-5f);
      // The ray runs along +z, the triangles' normal is +z: back-facing.
      EXPECT_EQ(p.hit[3], 255.0f) << "gl_HitKindEXT";
      EXPECT_EQ(p.ids[0], inB ? 20u : 10u) << "gl_InstanceCustomIndexEXT";
      EXPECT_EQ(p.ids[1], inB ? 1u : 0u) << "gl_InstanceID";
      EXPECT_EQ(p.ids[2], q.primitive) << "gl_PrimitiveID";
      EXPECT_EQ(p.ids[3], 0u) << "gl_GeometryIndexEXT";
      EXPECT_EQ(p.extra[0], inB ? 101u : 100u) << "hit record = instance SBT offset";
    }
  }
  EXPECT_GT(hits, 10);
  EXPECT_GT(misses, 10);
}

}  // namespace
}  // namespace vkrt::test
