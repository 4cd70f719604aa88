// vkCmdTraceRaysKHR end to end: acceleration structures built on the device, a shader binding table written from
// the pipeline's handles, and every launch index's result compared with the hit computed here from the geometry.
#include "e2e/trace_fixture.hpp"
#include "hit_distance.hpp"
#include "trace_ahit_count.rahit.spv.h"
#include "trace_box_at_tmin.rint.spv.h"
#include "trace_miss_cullmask.rmiss.spv.h"

namespace vkrt::test {
namespace {

class TraceBasics : public TraceTest {};

TEST_F(TraceBasics, TrianglesThroughInstancesWithTransformsCustomIndicesAndSbtOffsets) {
  VkAccelerationStructureKHR top = basicScene();
  Desc d = basicDesc();
  VkPipeline p = make(d);
  ASSERT_NE(p, VK_NULL_HANDLE);
  Sbt s = sbt(p, 3, {0}, {{1, {7}}}, {{2, {100}}, {2, {101}}});
  expectBasicScene(trace(p, s, top, 8, 8), 8);
}

// Builds large enough for vkrt to spread their reading over threads (more than 65,536 vertices and indices,
// more than 4,096 instances): the geometry traced is what the application gave. A grid of q x q quads over
// [-2, 2]^2 in the plane z = 0 (vertex (c, r) at index r * (q + 1) + c after `skip` unused vertices; quad (c, r)
// is triangles 2k = (v0, v1, v2) and 2k + 1 = (v2, v1, v3), k = r * q + c); the visible instance sits among
// thousands of others far away (and some with mask 0) at z = 5.
TEST_F(TraceBasics, LargeBuildsTraceTheirGeometryAndInstanceIds) {
  struct Grid {
    std::vector<float> vertices;
    std::vector<uint32_t> indices;
  };
  auto grid = [](uint32_t q, uint32_t skip, uint32_t floatsPerVertex) {
    Grid g;
    g.vertices.assign(size_t(skip) * floatsPerVertex, 1e6f);  // unused, far away
    for (uint32_t r = 0; r <= q; ++r)
      for (uint32_t c = 0; c <= q; ++c) {
        g.vertices.insert(g.vertices.end(), {-2 + 4.0f * c / q, -2 + 4.0f * r / q, 0});
        if (floatsPerVertex == 4) g.vertices.push_back(0);
      }
    for (uint32_t r = 0; r < q; ++r)
      for (uint32_t c = 0; c < q; ++c) {
        const uint32_t v0 = skip + r * (q + 1) + c, v1 = v0 + 1, v2 = v0 + q + 1, v3 = v2 + 1;
        g.indices.insert(g.indices.end(), {v0, v1, v2, v2, v1, v3});
      }
    return g;
  };
  // Bottom level A: 301 x 301 quads, float3, 32-bit indices starting at vertex 1000 (90,601 + 1,000 vertices,
  // 543,606 indices). Bottom level B: 180 x 180 quads, 16-byte vertex stride, 16-bit indices, and a transform
  // that lifts it by 1 (t is then 1 more).
  const uint32_t qa = 301, qb = 180;
  const Grid a = grid(qa, 1000, 3), b = grid(qb, 0, 4);
  VkAccelerationStructureKHR blasA = blas({triangles(a.vertices, a.indices, VK_GEOMETRY_OPAQUE_BIT_KHR)});
  Geometry gb = triangles(b.vertices, b.indices, VK_GEOMETRY_OPAQUE_BIT_KHR);
  auto& tb = gb.geometry.geometry.triangles;
  tb.vertexStride = 16;
  tb.maxVertex = uint32_t(b.vertices.size() / 4 - 1);
  std::vector<uint16_t> shortIndices(b.indices.begin(), b.indices.end());
  tb.indexType = VK_INDEX_TYPE_UINT16;
  tb.indexData.deviceAddress = upload(shortIndices);
  const VkTransformMatrixKHR lift = {{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 1}}};
  tb.transformData.deviceAddress = upload(std::vector<VkTransformMatrixKHR>{lift});
  VkAccelerationStructureKHR blasB = blas({gb});

  Desc d = basicDesc();
  VkPipeline p = make(d);
  ASSERT_NE(p, VK_NULL_HANDLE);
  Sbt s = sbt(p, 3, {0}, {{1, {7}}}, {{2, {100}}});
  const uint32_t kInstances = 5000;
  for (int which = 0; which < 2; ++which) {
    SCOPED_TRACE(which ? "bottom level B" : "bottom level A");
    const uint32_t visible = which ? 4321 : 1234, q = which ? qb : qa;
    std::vector<VkAccelerationStructureInstanceKHR> instances;
    for (uint32_t i = 0; i < kInstances; ++i) {
      // The others: in rows far to the side (x >= 100), every seventh with mask 0.
      const bool shown = i == visible;
      instances.push_back(instance(which ? blasB : blasA, shown ? 0 : 100 + 5.0f * (i % 100),
                                   shown ? 0 : 5.0f * (i / 100), 5, i, 0, shown || i % 7 ? 0xff : 0));
    }
    const std::vector<TracePayload> r = trace(p, s, tlas(instances), 8, 8);
    for (uint32_t y = 0; y < 8; ++y)
      for (uint32_t x = 0; x < 8; ++x) {
        SCOPED_TRACE("pixel " + std::to_string(x) + "," + std::to_string(y));
        const TracePayload& h = r[y * 8 + x];
        const double wx = cellCentre(x, 8), wy = cellCentre(y, 8);
        EXPECT_NEAR(h.hit[0], which ? 16.0f : 15.0f, 1e-4f) << "gl_HitTEXT";
        EXPECT_EQ(h.ids[0], visible) << "gl_InstanceCustomIndexEXT";
        EXPECT_EQ(h.ids[1], visible) << "gl_InstanceID";
        const double gx = (wx + 2) / 4 * q, gy = (wy + 2) / 4 * q;
        const double fx = gx - std::floor(gx), fy = gy - std::floor(gy);
        if (std::fabs(fx + fy - 1) < 1e-3) continue;  // on a quad's diagonal: either triangle
        const uint32_t k = uint32_t(std::floor(gy)) * q + uint32_t(std::floor(gx));
        EXPECT_EQ(h.ids[2], 2 * k + (fx + fy > 1 ? 1 : 0)) << "gl_PrimitiveID";
      }
  }
}

}  // namespace
}  // namespace vkrt::test

namespace vkrt::test {
namespace {

// A pipeline of trace_raygen, two miss shaders (tags in their records) and a triangle hit group with closest-hit
// and (optionally) any-hit shaders, over one quad at z = 5 (an instance of `quadBlas` with `flags`, `mask`).
class TraceFlags : public TraceTest {
 protected:
  VkPipeline pipeline(bool anyHit) { return pipelineWith(anyHit ? tahit : VK_NULL_HANDLE); }
  // raygen, miss, and a triangle hit group of trace_chit and the any-hit shader `anyHit` (none: VK_NULL_HANDLE).
  VkPipeline pipelineWith(VkShaderModule anyHit) {
    Desc d;
    d.layout = traceLayout;
    d.general(rgen, VK_SHADER_STAGE_RAYGEN_BIT_KHR);
    d.general(tmiss, VK_SHADER_STAGE_MISS_BIT_KHR);
    uint32_t c = d.stage(tchit, VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR);
    uint32_t a = anyHit ? d.stage(anyHit, VK_SHADER_STAGE_ANY_HIT_BIT_KHR) : VK_SHADER_UNUSED_KHR;
    d.group(VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR, VK_SHADER_UNUSED_KHR, c, a);
    return make(d);
  }
  // Two non-opaque quads over [-1, 1]^2 in one instance: geometry 0 at z = 3, geometry 1 (with `farFlags`) at z = 5.
  VkAccelerationStructureKHR twoQuads(VkGeometryFlagsKHR farFlags = 0) {
    std::vector<float> q5 = kQuad;
    for (size_t i = 2; i < q5.size(); i += 3) q5[i] = 5;
    std::vector<float> q3 = kQuad;
    for (size_t i = 2; i < q3.size(); i += 3) q3[i] = 3;
    VkAccelerationStructureKHR b = blas({triangles(q3, kQuadIndices, 0), triangles(q5, kQuadIndices, farFlags)});
    return tlas({instance(b)});
  }
  // The centre pixel of a 4 x 4 launch: the ray at (-0.5, -0.5) hits triangle 0 of a quad at the origin.
  TracePayload centre(VkPipeline p, const Sbt& s, VkAccelerationStructureKHR top, const TraceParams& params) {
    return trace(p, s, top, 4, 4, params)[1 * 4 + 1];
  }
};

TEST_F(TraceFlags, RayFlagsInstanceFlagsMasksAndMissIndex) {
  VkAccelerationStructureKHR quad = blas({triangles(kQuad, kQuadIndices, VK_GEOMETRY_OPAQUE_BIT_KHR)});
  VkAccelerationStructureKHR plain = tlas({instance(quad, 0, 0, 5, 1, 0, 0x01)});
  VkAccelerationStructureKHR flipped =
      tlas({instance(quad, 0, 0, 5, 2, 0, 0x01, VK_GEOMETRY_INSTANCE_TRIANGLE_FLIP_FACING_BIT_KHR)});
  VkAccelerationStructureKHR noCull =
      tlas({instance(quad, 0, 0, 5, 3, 0, 0x01, VK_GEOMETRY_INSTANCE_TRIANGLE_FACING_CULL_DISABLE_BIT_KHR)});
  VkPipeline p = pipeline(false);
  ASSERT_NE(p, VK_NULL_HANDLE);
  Sbt s = sbt(p, 3, {0}, {{1, {7}}, {1, {8}}}, {{2, {100}}});
  auto hits = [](const TracePayload& r) { return r.hit[0] > 0; };
  TraceParams t;
  TracePayload r = centre(p, s, plain, t);
  ASSERT_TRUE(hits(r));
  EXPECT_EQ(r.hit[3], 255.0f) << "back-facing: the ray runs along the normal";
  t.cullMask = 0x02;
  EXPECT_FALSE(hits(centre(p, s, plain, t))) << "cull mask 0x02 against instance mask 0x01";
  t.cullMask = 0xff;
  t.missIndex = 1;
  r = centre(p, s, plain, {t.rayFlags, 0x02, 0, 1, 1});
  EXPECT_EQ(r.extra[0], 8u) << "missIndex 1 selects the second miss record";
  {
    // OpTraceRayKHR uses only the low 8 bits of the cull mask, 4 of the SBT offset and stride, 16 of the miss index.
    TraceParams high;
    high.cullMask = 0xFFFFFF02;
    EXPECT_FALSE(hits(centre(p, s, plain, high))) << "cull mask 0xFFFFFF02 is 0x02";
    high.cullMask = 0xFFFFFF01;
    high.sbtOffset = 0xFFFFFFF0;
    high.sbtStride = 0xFFFFFFF0;
    r = centre(p, s, plain, high);
    ASSERT_TRUE(hits(r)) << "cull mask 0xFFFFFF01 is 0x01";
    EXPECT_EQ(r.extra[0], 100u) << "SBT offset and stride 0xFFFFFFF0 are 0: hit record 0";
    high.cullMask = 0x02;
    high.missIndex = 0xFFFF0001;
    EXPECT_EQ(centre(p, s, plain, high).extra[0], 8u) << "miss index 0xFFFF0001 is 1";
  }
  t.missIndex = 0;
  t.rayFlags = 0x10;  // gl_RayFlagsCullBackFacingTrianglesEXT
  r = centre(p, s, plain, t);
  EXPECT_FALSE(hits(r));
  EXPECT_EQ(r.hit[3], 16.0f) << "gl_IncomingRayFlagsEXT in the miss shader";
  EXPECT_TRUE(hits(centre(p, s, noCull, t))) << "TRIANGLE_FACING_CULL_DISABLE";
  r = centre(p, s, flipped, t);
  ASSERT_TRUE(hits(r)) << "TRIANGLE_FLIP_FACING makes it front-facing";
  EXPECT_EQ(r.hit[3], 254.0f);
  t.rayFlags = 0x20;  // gl_RayFlagsCullFrontFacingTrianglesEXT
  EXPECT_TRUE(hits(centre(p, s, plain, t)));
  EXPECT_FALSE(hits(centre(p, s, flipped, t)));
  t.rayFlags = 0x40;  // gl_RayFlagsCullOpaqueEXT: the geometry is opaque
  EXPECT_FALSE(hits(centre(p, s, plain, t)));
  t.rayFlags = 0x80;  // gl_RayFlagsCullNoOpaqueEXT
  EXPECT_TRUE(hits(centre(p, s, plain, t)));
  if (rtf.rayTraversalPrimitiveCulling) {
    t.rayFlags = 0x100;  // gl_RayFlagsSkipTrianglesEXT
    EXPECT_FALSE(hits(centre(p, s, plain, t)));
    t.rayFlags = 0x200;  // gl_RayFlagsSkipAABBEXT
    EXPECT_TRUE(hits(centre(p, s, plain, t)));
  }
  t.rayFlags = 0;
  t.tmax = 14.0f;  // the quad is at t = 15
  r = centre(p, s, plain, t);
  EXPECT_FALSE(hits(r));
  EXPECT_EQ(r.hit[2], 14.0f);
}

TEST_F(TraceFlags, AnyHitAcceptIgnoreTerminateAndOpacity) {
  // Two non-opaque quads, geometry 0 at z = 3 and geometry 1 at z = 5, one record each (sbtStride 1).
  VkAccelerationStructureKHR top = twoQuads(VK_GEOMETRY_NO_DUPLICATE_ANY_HIT_INVOCATION_BIT_KHR);
  VkPipeline p = pipeline(true);
  ASSERT_NE(p, VK_NULL_HANDLE);
  for (uint32_t mode : {0u, 1u, 2u}) {
    SCOPED_TRACE("any-hit mode " + std::to_string(mode));
    Sbt s = sbt(p, 3, {0}, {{1, {7}}}, {{2, {100, mode}}, {2, {101, mode}}});
    TracePayload r = centre(p, s, top, {});
    if (mode == 0) {
      EXPECT_NEAR(r.hit[0], 13.0f, 1e-4f) << "accepted: the nearer quad";
      EXPECT_EQ(r.ids[3], 0u);
      EXPECT_GE(r.extra[1], 1u);
      EXPECT_LE(r.extra[1], 2u);
    } else if (mode == 1) {
      EXPECT_EQ(r.hit[0], -2.0f) << "every candidate ignored: a miss";
      EXPECT_EQ(r.extra[1], 2u) << "one any-hit per quad";
    } else {
      EXPECT_EQ(r.extra[1], 1u) << "terminateRayEXT in the first any-hit";
      ASSERT_GT(r.hit[0], 0.0f);
      EXPECT_EQ(r.extra[0], r.ids[3] == 0 ? 100u : 101u) << "the closest-hit shader of the terminating candidate runs";
    }
    TraceParams opaque;
    opaque.rayFlags = 0x1;  // gl_RayFlagsOpaqueEXT: no any-hit
    r = centre(p, s, top, opaque);
    EXPECT_EQ(r.extra[1], 0u);
    EXPECT_NEAR(r.hit[0], 13.0f, 1e-4f);
  }
}

TEST_F(TraceFlags, AnyHitCountersEveryRayAddsToCountEveryInvocation) {
  // trace_ahit_count.rahit adds 1 to one word per invocation (result unused: vkrt combines the adds of a task and
  // writes their sum when the task ends, abi::PendingAdds). Two non-opaque quads at z = 3 and 5 over [-1, 1]^2 and
  // a 64 x 64 launch over [-2, 2]^2 (64 tiles, spread over the workers): with every candidate ignored, each ray
  // inside the quads runs the any-hit shader twice; the word must hold every one of them.
  VkAccelerationStructureKHR top = twoQuads();
  VkPipeline p = pipelineWith(module(kSpv_trace_ahit_count_rahit, sizeof kSpv_trace_ahit_count_rahit));
  ASSERT_NE(p, VK_NULL_HANDLE);
  constexpr uint32_t n = 64;
  for (uint32_t mode : {1u, 0u}) {
    SCOPED_TRACE("any-hit mode " + std::to_string(mode));
    Sbt s = sbt(p, 3, {0}, {{1, {7}}}, {{2, {100, mode}}, {2, {101, mode}}});
    std::memset(spheres.data, 0, 4);
    const std::vector<TracePayload> r = trace(p, s, top, n, n, {});
    uint32_t inside = 0, invocations = 0;
    for (uint32_t y = 0; y < n; ++y)
      for (uint32_t x = 0; x < n; ++x) {
        const float wx = cellCentre(x, n), wy = cellCentre(y, n);
        const bool in = wx >= -1 && wx <= 1 && wy >= -1 && wy <= 1;
        inside += in;
        invocations += r[y * n + x].extra[1];
        if (mode == 1) {
          EXPECT_EQ(r[y * n + x].extra[1], in ? 2u : 0u) << "launch index " << x << "," << y;
        }
      }
    uint32_t total = 0;
    std::memcpy(&total, spheres.data, 4);
    EXPECT_EQ(inside, 32u * 32u);
    EXPECT_EQ(total, invocations) << "the word every invocation added 1 to";
    if (mode == 1) {
      EXPECT_EQ(total, 2 * inside);
    }
  }
}

TEST_F(TraceFlags, EachAnyHitRunsWithTheRecordItsCandidateSelects) {
  // The executor keeps the hit record a task resolved last, and its reused any-hit invocation keeps that record's
  // data (exec/trace.cpp, TaskState::hitIndex, setRecord): candidates that select different records, in one trace
  // and from launch index to launch index of one tile, must each run with their own record. Two non-opaque quads
  // of one hit group, geometry 0 at z = 3 and geometry 1 at z = 5, with records that differ only in their data:
  // one any-hit ignores, the other accepts; which quad is hit is decided by the record each candidate read.
  VkAccelerationStructureKHR top = twoQuads();
  VkPipeline p = pipeline(true);
  ASSERT_NE(p, VK_NULL_HANDLE);
  for (uint32_t nearMode : {1u, 0u}) {
    const uint32_t farMode = 1 - nearMode;  // 0 accept, 1 ignore (trace_ahit.rahit)
    SCOPED_TRACE("near quad's any-hit mode " + std::to_string(nearMode));
    Sbt s = sbt(p, 3, {0}, {{1, {7}}}, {{2, {100, nearMode}}, {2, {101, farMode}}});
    const std::vector<TracePayload> r = trace(p, s, top, 4, 4, {});
    for (uint32_t y = 0; y < 4; ++y)
      for (uint32_t x = 0; x < 4; ++x) {
        SCOPED_TRACE("launch index " + std::to_string(x) + "," + std::to_string(y));
        const TracePayload& h = r[y * 4 + x];
        if (x == 0 || x == 3 || y == 0 || y == 3) {  // outside both quads
          EXPECT_EQ(h.hit[0], -2.0f);
          continue;
        }
        const uint32_t accepted = nearMode == 0 ? 0 : 1;  // the geometry whose record accepts
        EXPECT_NEAR(h.hit[0], accepted == 0 ? 13.0f : 15.0f, 1e-4f);
        EXPECT_EQ(h.ids[3], accepted) << "gl_GeometryIndexEXT";
        EXPECT_EQ(h.extra[0], 100u + accepted) << "the accepted geometry's closest-hit record";
        if (accepted == 1) {
          EXPECT_EQ(h.extra[1], 2u) << "an any-hit for each quad";
        }
      }
  }
}

TEST_F(TraceFlags, IntersectionShadersReportSpheresInBoxes) {
  // Two spheres (radius 0.5) in their boxes: primitive 0 centred at (-1, -1, 4), primitive 1 at (1, 1, 6); in an
  // instance moved by +1 along z.
  setSpheres({{-1, -1, 4, 0.5f}, {1, 1, 6, 0.5f}});
  VkAccelerationStructureKHR b = blas({aabbs(
      {{-1.5f, -1.5f, 3.5f, -0.5f, -0.5f, 4.5f}, {0.5f, 0.5f, 5.5f, 1.5f, 1.5f, 6.5f}}, VK_GEOMETRY_OPAQUE_BIT_KHR)});
  VkAccelerationStructureKHR top = tlas({instance(b, 0, 0, 1, 9)});
  Desc d;
  d.layout = traceLayout;
  d.general(rgen, VK_SHADER_STAGE_RAYGEN_BIT_KHR);
  d.general(tmiss, VK_SHADER_STAGE_MISS_BIT_KHR);
  uint32_t c = d.stage(tchit, VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR);
  uint32_t i = d.stage(tsphere, VK_SHADER_STAGE_INTERSECTION_BIT_KHR);
  d.group(VK_RAY_TRACING_SHADER_GROUP_TYPE_PROCEDURAL_HIT_GROUP_KHR, VK_SHADER_UNUSED_KHR, c, VK_SHADER_UNUSED_KHR, i);
  d.maxHitAttr = 8;
  d.maxPayload = sizeof(TracePayload);
  VkPipeline p = make(d);
  ASSERT_NE(p, VK_NULL_HANDLE);
  Sbt s = sbt(p, 3, {0}, {{1, {7}}}, {{2, {300}}});
  const uint32_t n = 16;
  expectSpheresInBoxes(trace(p, s, top, n, n), n, true);
}

// A ray starting inside a box meets it, also when tMin == tMax ("tmin <= t <= tmax" for AABBs): the intersection
// shader runs and its hit at t = tMin = tMax is committed (the CTS's ray_tracing_pipeline.inside_aabbs.*.
// ray_end_tmax_zero.*, "Result distance nonzero (-10000)" when it is not).
TEST_F(TraceFlags, ARayStartingInsideABoxMeetsItWhenTMinEqualsTMax) {
  // One box around every ray origin of the launch (x, y in [-2, 2], z = -10), with a quad behind it.
  VkAccelerationStructureKHR box = blas({aabbs({{-3, -3, -11, 3, 3, -9}}, VK_GEOMETRY_OPAQUE_BIT_KHR)});
  VkAccelerationStructureKHR quad = blas({triangles(kQuad, kQuadIndices, VK_GEOMETRY_OPAQUE_BIT_KHR)});
  VkAccelerationStructureKHR top = tlas({instance(box, 0, 0, 0, 3, 0), instance(quad, 0, 0, 5, 4, 1)});
  Desc d;
  d.layout = traceLayout;
  d.general(rgen, VK_SHADER_STAGE_RAYGEN_BIT_KHR);
  d.general(tmiss, VK_SHADER_STAGE_MISS_BIT_KHR);
  const uint32_t c = d.stage(tchit, VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR);
  d.group(VK_RAY_TRACING_SHADER_GROUP_TYPE_PROCEDURAL_HIT_GROUP_KHR, VK_SHADER_UNUSED_KHR, c, VK_SHADER_UNUSED_KHR,
          d.stage(module(kSpv_trace_box_at_tmin_rint, sizeof kSpv_trace_box_at_tmin_rint),
                  VK_SHADER_STAGE_INTERSECTION_BIT_KHR));
  d.group(VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR, VK_SHADER_UNUSED_KHR, c);
  d.maxHitAttr = 8;
  d.maxPayload = sizeof(TracePayload);
  VkPipeline p = make(d);
  ASSERT_NE(p, VK_NULL_HANDLE);
  Sbt s = sbt(p, 4, {0}, {{1, {7}}}, {{2, {300}}, {3, {400}}});
  for (float tmax : {0.0f, 0.5f, 100.0f}) {
    SCOPED_TRACE("tMin 0, tMax " + std::to_string(tmax));
    TraceParams t;
    t.tmax = tmax;
    const std::vector<TracePayload> r = trace(p, s, top, 4, 4, t);
    for (uint32_t i = 0; i < r.size(); ++i) {
      SCOPED_TRACE("launch index " + std::to_string(i));
      EXPECT_EQ(r[i].hit[0], 0.0f) << "gl_HitTEXT: the box's hit at tMin";
      // gl_RayTmaxEXT in the intersection shader: tMax, or the quad's t (15) where the traversal committed the quad
      // first (the order in which candidates are met is the implementation's; a small quad's triangles lie in the
      // top level's scene, which Embree traverses before its instances).
      EXPECT_TRUE(r[i].hit[2] == tmax || (tmax > 15.0f && nearHit(r[i].hit[2], 15.0f))) << r[i].hit[2];
      EXPECT_EQ(r[i].hit[3], 6.0f) << "the hit kind the intersection shader reported";
      EXPECT_EQ(r[i].ids[0], 3u) << "the box's instance";
      EXPECT_EQ(r[i].extra[0], 300u);
    }
  }
}

}  // namespace
}  // namespace vkrt::test

namespace vkrt::test {
namespace {

// gl_CullMaskEXT (SPV_KHR_ray_cull_mask, enabled by VK_KHR_ray_tracing_maintenance1's rayTracingMaintenance1): a
// miss shader reads the cull mask its ray was traced with, the low 8 bits of traceRayEXT's operand.
class TraceCullMaskTest : public TraceTest {
 protected:
  VkPhysicalDeviceRayTracingMaintenance1FeaturesKHR m1{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_MAINTENANCE_1_FEATURES_KHR};
  FixtureOptions options() override {
    FixtureOptions o = TraceTest::options();
    o.deviceExtensions.push_back(VK_KHR_RAY_TRACING_MAINTENANCE_1_EXTENSION_NAME);
    m1.rayTracingMaintenance1 = VK_TRUE;
    m1.pNext = nullptr;
    asf.pNext = &m1;
    return o;
  }
};

TEST_F(TraceCullMaskTest, TheMissShaderReadsTheRaysCullMask) {
  VkAccelerationStructureKHR quad = blas({triangles(kQuad, kQuadIndices, VK_GEOMETRY_OPAQUE_BIT_KHR)});
  VkAccelerationStructureKHR top = tlas({instance(quad, 0, 0, 5, 1, 0, 0x01)});
  Desc d;
  d.layout = traceLayout;
  d.general(rgen, VK_SHADER_STAGE_RAYGEN_BIT_KHR);
  d.general(module(kSpv_trace_miss_cullmask_rmiss, sizeof kSpv_trace_miss_cullmask_rmiss),
            VK_SHADER_STAGE_MISS_BIT_KHR);
  d.group(VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR, VK_SHADER_UNUSED_KHR,
          d.stage(tchit, VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR));
  VkPipeline p = make(d);
  ASSERT_NE(p, VK_NULL_HANDLE);
  Sbt s = sbt(p, 3, {0}, {{1, {7}}}, {{2, {100}}});
  for (uint32_t mask : {0x02u, 0xF6u, 0xFFFFFF02u}) {
    TraceParams t;
    t.cullMask = mask;  // no bit of the instance's 0x01: every ray misses
    std::vector<TracePayload> r = trace(p, s, top, 4, 4, t);
    EXPECT_EQ(r[5].hit[0], -2.0f) << "mask 0x" << std::hex << mask;
    EXPECT_EQ(r[5].extra[2], mask & 0xFF) << "mask 0x" << std::hex << mask;
  }
}

}  // namespace
}  // namespace vkrt::test
