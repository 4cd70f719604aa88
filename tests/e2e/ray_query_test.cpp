// VK_KHR_ray_query from compute shaders (tests/shaders/ray_query_scene.comp): rays shot at analytic scenes of
// triangles, boxes with shader-generated hits and transformed, masked instances, every value the query returns
// compared with the one computed here; the same scene through a ray tracing pipeline and through ray queries gives
// the same hits.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "e2e/compute_pipeline_helpers.hpp"
#include "e2e/trace_fixture.hpp"
#include "hit_distance.hpp"
#include "ray_query_address.comp.spv.h"
#include "ray_query_many.comp.spv.h"
#include "ray_query_raygen.rgen.spv.h"
#include "ray_query_scene.comp.spv.h"

#include <unistd.h>

namespace vkrt::test {
namespace {

// tests/shaders/ray_query_scene.comp
struct RayIn {
  float origin[4];     // w = tMin
  float direction[4];  // w = tMax
  uint32_t flags = 0, cullMask = 0xff, mode = 0, pad = 0;
};
struct Result {
  float hit[4];  // t, barycentrics, committed type
  uint32_t ids[4];
  uint32_t more[4];  // SBT offset, front face, triangle candidates, box candidates
  float objectOrigin[4];
  float objectDirection[4];
  float objectToWorld[4][4];
  float worldToObject[4][4];
  float ray[4];  // tMin, flags, first triangle candidate's t, first box candidate opaque
  float worldOrigin[4];
  float worldDirection[4];
  uint32_t firstCandidate[4];
};
static_assert(sizeof(RayIn) == 48 && sizeof(Result) == 272);

enum Mode : uint32_t { kConfirm = 0, kIgnore = 1, kTerminate = 2 };

RayIn ray(float x, float y, uint32_t mode = kConfirm, uint32_t flags = 0, uint32_t mask = 0xff, float tMin = 0,
          float tMax = 100) {
  RayIn r;
  const float o[4] = {x, y, -10, tMin}, d[4] = {0, 0, 1, tMax};
  std::memcpy(r.origin, o, sizeof o);
  std::memcpy(r.direction, d, sizeof d);
  r.flags = flags;
  r.cullMask = mask;
  r.mode = mode;
  return r;
}

// Whether the first physical device offers `extension`, asked through an instance of its own before the fixture's
// exists (NVIDIA's driver on the device machine offers no VK_KHR_ray_query).
bool firstDeviceHasExtension(const char* extension) {
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.apiVersion = VK_API_VERSION_1_3;
  VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  ici.pApplicationInfo = &app;
  VkInstance inst = VK_NULL_HANDLE;
  if (vkCreateInstance(&ici, nullptr, &inst) != VK_SUCCESS) return false;
  uint32_t n = 1;
  VkPhysicalDevice pd = VK_NULL_HANDLE;
  bool found = false;
  VkResult r = vkEnumeratePhysicalDevices(inst, &n, &pd);
  if ((r == VK_SUCCESS || r == VK_INCOMPLETE) && n >= 1) {
    uint32_t count = 0;
    vkEnumerateDeviceExtensionProperties(pd, nullptr, &count, nullptr);
    std::vector<VkExtensionProperties> exts(count);
    vkEnumerateDeviceExtensionProperties(pd, nullptr, &count, exts.data());
    for (const VkExtensionProperties& e : exts) found = found || std::strcmp(e.extensionName, extension) == 0;
  }
  vkDestroyInstance(inst, nullptr);
  return found;
}

class RayQueryTest : public TraceTest {
 protected:
  VkPhysicalDeviceRayQueryFeaturesKHR rqf{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR};

  FixtureOptions options() override {
    FixtureOptions o = TraceTest::options();
    o.deviceExtensions.push_back(VK_KHR_RAY_QUERY_EXTENSION_NAME);
    rqf.rayQuery = VK_TRUE;
    rqf.pNext = asf.pNext;
    asf.pNext = &rqf;
    return o;
  }

  void SetUp() override {
    if (!firstDeviceHasExtension(VK_KHR_RAY_QUERY_EXTENSION_NAME))
      GTEST_SKIP() << "the driver has no " VK_KHR_RAY_QUERY_EXTENSION_NAME;
    TraceTest::SetUp();
    if (HasFatalFailure() || !device) return;
    query = makeComputePipeline(device, kSpv_ray_query_scene_comp, sizeof kSpv_ray_query_scene_comp,
                                {VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                                 VK_DESCRIPTOR_TYPE_STORAGE_BUFFER});
    ASSERT_EQ(query.result, VK_SUCCESS);
  }
  void TearDown() override {
    if (device) {
      vkDeviceWaitIdle(device);
      destroyComputePipeline(device, query);
    }
    TraceTest::TearDown();
  }

  // Runs ray_query_scene.comp over `rays` against `top`.
  std::vector<Result> shoot(VkAccelerationStructureKHR top, const std::vector<RayIn>& rays) {
    HostBuffer& in = buffer(sizeof(RayIn) * rays.size(), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    HostBuffer& out = buffer(sizeof(Result) * rays.size(), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    std::memcpy(in.data, rays.data(), in.size);
    std::memset(out.data, 0xee, out.size);
    VkWriteDescriptorSetAccelerationStructureKHR asw{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_KHR};
    asw.accelerationStructureCount = 1;
    asw.pAccelerationStructures = &top;
    VkDescriptorBufferInfo bi{in.buffer, 0, VK_WHOLE_SIZE}, bo{out.buffer, 0, VK_WHOLE_SIZE};
    VkWriteDescriptorSet w[3] = {{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, &asw},
                                 {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET},
                                 {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET}};
    for (uint32_t i = 0; i < 3; ++i) {
      w[i].dstSet = query.set;
      w[i].dstBinding = i;
      w[i].descriptorCount = 1;
      w[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    }
    w[0].descriptorType = VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR;
    w[1].pBufferInfo = &bi;
    w[2].pBufferInfo = &bo;
    vkUpdateDescriptorSets(device, 3, w, 0, nullptr);
    VkCommandBuffer cb = beginOneTime();
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, query.pipeline);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, query.layout, 0, 1, &query.set, 0, nullptr);
    vkCmdDispatch(cb, uint32_t(rays.size() + 7) / 8, 1, 1);
    submitAndWait(cb);
    std::vector<Result> r(rays.size());
    std::memcpy(r.data(), out.data, out.size);
    return r;
  }

  ComputePipeline query;
};

// An instance with the row-major 3x4 transform `m`.
VkAccelerationStructureInstanceKHR transformed(VkAccelerationStructureInstanceKHR in, const float m[3][4]) {
  std::memcpy(in.transform.matrix, m, sizeof in.transform.matrix);
  return in;
}

// The committed values every hit has: the instance's data and the object-space ray, from its transform `m`
// (object to world, rows) and inverse `inv`.
void expectInstance(const Result& r, uint32_t custom, uint32_t id, uint32_t sbt, const float m[3][4],
                    const float inv[3][4], float x, float y) {
  EXPECT_EQ(r.ids[0], custom) << "custom index";
  EXPECT_EQ(r.ids[1], id) << "instance id";
  EXPECT_EQ(r.more[0], sbt) << "SBT record offset";
  const float o[3] = {x, y, -10};
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(r.objectOrigin[i], inv[i][0] * o[0] + inv[i][1] * o[1] + inv[i][2] * o[2] + inv[i][3], 1e-5f) << i;
    EXPECT_NEAR(r.objectDirection[i], inv[i][2], 1e-6f) << i;  // the direction is +z
  }
  for (int c = 0; c < 4; ++c)
    for (int row = 0; row < 3; ++row) {
      EXPECT_NEAR(r.objectToWorld[c][row], m[row][c], 1e-6f) << "objectToWorld column " << c << " row " << row;
      EXPECT_NEAR(r.worldToObject[c][row], inv[row][c], 1e-6f) << "worldToObject column " << c << " row " << row;
    }
}

TEST_F(RayQueryTest, EveryValueOfTrianglesBoxesInstancesAndFlags) {
  // Instance 0: a non-opaque quad at z = 5 (x + 0.1), custom 10, SBT offset 3, mask 1.
  // Instance 1: a non-opaque unit box [-0.5, 0.5]^3 scaled by 2 at (10, 0, 4), custom 20, SBT offset 5, mask 2.
  // Instance 2: an opaque quad turned 90 degrees about z at (10, 0, 8), custom 30, SBT offset 7, mask 4.
  // Instance 3: an opaque unit box at (20, 0, 3), custom 40, mask 8.
  // Instance 4: an opaque quad at z = 7 (x + 0.1) with TRIANGLE_FLIP_FACING, custom 50, mask 0x10.
  // Instance 5: the non-opaque quad at z = 6 (x + 0.1), custom 60, mask 0x20.
  VkAccelerationStructureKHR quadNo = blas({triangles(kQuad, kQuadIndices, 0)});
  VkAccelerationStructureKHR quadOpaque = blas({triangles(kQuad, kQuadIndices, VK_GEOMETRY_OPAQUE_BIT_KHR)});
  VkAccelerationStructureKHR box = blas({aabbs({{-0.5f, -0.5f, -0.5f, 0.5f, 0.5f, 0.5f}}, 0)});
  VkAccelerationStructureKHR boxOpaque =
      blas({aabbs({{-0.5f, -0.5f, -0.5f, 0.5f, 0.5f, 0.5f}}, VK_GEOMETRY_OPAQUE_BIT_KHR)});
  const float m0[3][4] = {{1, 0, 0, 0.1f}, {0, 1, 0, 0}, {0, 0, 1, 5}},
              i0[3][4] = {{1, 0, 0, -0.1f}, {0, 1, 0, 0}, {0, 0, 1, -5}};
  const float m1[3][4] = {{2, 0, 0, 10}, {0, 2, 0, 0}, {0, 0, 2, 4}},
              i1[3][4] = {{0.5f, 0, 0, -5}, {0, 0.5f, 0, 0}, {0, 0, 0.5f, -2}};
  const float m2[3][4] = {{0, -1, 0, 10}, {1, 0, 0, 0}, {0, 0, 1, 8}},
              i2[3][4] = {{0, 1, 0, 0}, {-1, 0, 0, 10}, {0, 0, 1, -8}};
  const float m3[3][4] = {{1, 0, 0, 20}, {0, 1, 0, 0}, {0, 0, 1, 3}},
              i3[3][4] = {{1, 0, 0, -20}, {0, 1, 0, 0}, {0, 0, 1, -3}};
  const float m4[3][4] = {{1, 0, 0, 0.1f}, {0, 1, 0, 0}, {0, 0, 1, 7}},
              i4[3][4] = {{1, 0, 0, -0.1f}, {0, 1, 0, 0}, {0, 0, 1, -7}};
  VkAccelerationStructureKHR top = tlas({
      transformed(instance(quadNo, 0, 0, 0, 10, 3, 0x01), m0),
      transformed(instance(box, 0, 0, 0, 20, 5, 0x02), m1),
      transformed(instance(quadOpaque, 0, 0, 0, 30, 7, 0x04), m2),
      transformed(instance(boxOpaque, 0, 0, 0, 40, 0, 0x08), m3),
      transformed(instance(quadOpaque, 0, 0, 0, 50, 0, 0x10, VK_GEOMETRY_INSTANCE_TRIANGLE_FLIP_FACING_BIT_KHR), m4),
      instance(quadNo, 0.1f, 0, 6, 60, 0, 0x20),
  });
  constexpr uint32_t kOpaque = 0x1, kFirstHit = 0x4, kCullNoOpaque = 0x80, kSkipTriangles = 0x100, kSkipAabbs = 0x200;
  const float qx = 0.3f, qy = 0.2f, bx = 10.3f, by = 0.2f;
  const std::vector<RayIn> rays = {
      ray(qx, qy, kConfirm, 0, 0x1f),               // 0: the non-opaque quad confirmed in front of the opaque one
      ray(qx, qy, kIgnore, 0, 0x1f),                // 1: ignored: the opaque (flipped) quad behind it
      ray(qx, qy, kConfirm, 0, 0x10),               // 2: only the opaque quad: no candidate
      ray(qx, qy, kIgnore, 0, 0x01),                // 3: only the ignored candidate: nothing committed
      ray(qx, qy, kConfirm, kOpaque, 0x1f),         // 4: OpaqueKHR: the quad is committed without the shader
      ray(qx, qy, kConfirm, kCullNoOpaque, 0x1f),   // 5: CullNoOpaqueKHR: the non-opaque quad is not met
      ray(qx, qy, kConfirm, 0, 0x1f, 16),           // 6: tMin past the non-opaque quad
      ray(bx, by, kConfirm, 0, 0xff),               // 7: the box's generated hit in front of the turned quad
      ray(bx, by, kIgnore, 0, 0xff),                // 8: the box ignored: the turned quad
      ray(20.1f, 0.1f, kConfirm, 0, 0xff),          // 9: the opaque box still asks the shader
      ray(bx, by, kConfirm, kSkipAabbs, 0xff),      // 10: SkipAABBsKHR
      ray(bx, by, kConfirm, kSkipTriangles, 0xff),  // 11: SkipTrianglesKHR
      ray(50, 0, kConfirm, 0, 0xff),                // 12: a miss
      ray(qx, qy, kIgnore, 0, 0x21),                // 13: two non-opaque quads, both ignored
      ray(qx, qy, kConfirm, 0, 0x21),               // 14: two non-opaque quads confirmed: the closer stays
      ray(qx, qy, kConfirm, kFirstHit, 0x1f),       // 15: TerminateOnFirstHitKHR
      ray(bx, by, kTerminate, 0, 0xff),             // 16: generated, then terminated
      ray(qx, qy, kConfirm, 0, 0x1f, 0, 14),        // 17: tMax short of everything
  };
  const std::vector<Result> r = shoot(top, rays);
  const QuadHit q = quadHit(qx - 0.1f, qy);
  const QuadHit turned = quadHit(by, -(bx - 10));  // the turned quad's object coordinates: (y, -x)
  auto committedQuad = [&](const Result& s, float t, uint32_t custom, uint32_t id, uint32_t sbt, const float(*m)[4],
                           const float(*inv)[4], bool front) {
    EXPECT_EQ(s.hit[3], 1.0f) << "committed type: triangle";
    EXPECT_NEAR(s.hit[0], t, 1e-4f);
    EXPECT_NEAR(s.hit[1], q.u, 1e-5f);
    EXPECT_NEAR(s.hit[2], q.v, 1e-5f);
    EXPECT_EQ(s.ids[2], q.primitive);
    EXPECT_EQ(s.ids[3], 0u);
    EXPECT_EQ(s.more[1], front ? 1u : 0u) << "front face";
    expectInstance(s, custom, id, sbt, m, inv, qx, qy);
  };
  auto nothing = [&](const Result& s) { EXPECT_EQ(s.hit[3], 0.0f) << "committed type: none"; };
  for (size_t i = 0; i < r.size(); ++i) {
    SCOPED_TRACE("ray " + std::to_string(i));
    EXPECT_EQ(r[i].ray[0], rays[i].origin[3]) << "tMin";
    EXPECT_EQ(r[i].ray[1], float(rays[i].flags)) << "ray flags";
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(r[i].worldOrigin[k], rays[i].origin[k]);
      EXPECT_EQ(r[i].worldDirection[k], rays[i].direction[k]);
    }
  }
  {
    SCOPED_TRACE("ray 0");
    // The ray runs along +z, the quad's normal is +z: back-facing.
    committedQuad(r[0], 15, 10, 0, 3, m0, i0, false);
    EXPECT_EQ(r[0].more[2], 1u) << "triangle candidates";
    EXPECT_EQ(r[0].more[3], 0u) << "box candidates";
    EXPECT_NEAR(r[0].ray[2], 15, 1e-4f) << "the candidate's t";
    EXPECT_EQ(r[0].firstCandidate[0], 10u);
    EXPECT_EQ(r[0].firstCandidate[1], 0u);
    EXPECT_EQ(r[0].firstCandidate[2], q.primitive);
    EXPECT_EQ(r[0].firstCandidate[3], 0u);
  }
  {
    SCOPED_TRACE("ray 1");
    committedQuad(r[1], 17, 50, 4, 0, m4, i4, true);  // flipped facing: front
    EXPECT_EQ(r[1].more[2], 1u);
  }
  {
    SCOPED_TRACE("ray 2");
    committedQuad(r[2], 17, 50, 4, 0, m4, i4, true);
    EXPECT_EQ(r[2].more[2], 0u);
  }
  {
    SCOPED_TRACE("ray 3");
    nothing(r[3]);
    EXPECT_EQ(r[3].more[2], 1u);
  }
  {
    SCOPED_TRACE("ray 4");
    committedQuad(r[4], 15, 10, 0, 3, m0, i0, false);
    EXPECT_EQ(r[4].more[2], 0u) << "OpaqueKHR: no candidate";
  }
  {
    SCOPED_TRACE("ray 5");
    committedQuad(r[5], 17, 50, 4, 0, m4, i4, true);
    EXPECT_EQ(r[5].more[2], 0u);
  }
  {
    SCOPED_TRACE("ray 6");
    committedQuad(r[6], 17, 50, 4, 0, m4, i4, true);
    EXPECT_EQ(r[6].more[2], 0u);
  }
  {
    SCOPED_TRACE("ray 7");
    // The box [3, 5] in z: entered at t = 13 (object space: the same t, the direction scaled by 1/2).
    EXPECT_EQ(r[7].hit[3], 2.0f) << "committed type: generated";
    EXPECT_NEAR(r[7].hit[0], 13, 1e-4f);
    EXPECT_EQ(r[7].hit[1], 0.0f);
    EXPECT_EQ(r[7].hit[2], 0.0f);
    EXPECT_EQ(r[7].ids[2], 0u);
    EXPECT_EQ(r[7].ids[3], 0u);
    EXPECT_EQ(r[7].more[1], 0u) << "front face of a generated hit";
    EXPECT_EQ(r[7].more[3], 1u) << "box candidates";
    EXPECT_EQ(r[7].ray[3], 0.0f) << "candidate AABB opaque";
    expectInstance(r[7], 20, 1, 5, m1, i1, bx, by);
  }
  {
    SCOPED_TRACE("ray 8");
    EXPECT_EQ(r[8].hit[3], 1.0f);
    EXPECT_NEAR(r[8].hit[0], 18, 1e-4f);
    EXPECT_NEAR(r[8].hit[1], turned.u, 1e-5f);
    EXPECT_NEAR(r[8].hit[2], turned.v, 1e-5f);
    EXPECT_EQ(r[8].ids[2], turned.primitive);
    EXPECT_EQ(r[8].more[1], 0u) << "back-facing";
    EXPECT_EQ(r[8].more[3], 1u);
    expectInstance(r[8], 30, 2, 7, m2, i2, bx, by);
  }
  {
    SCOPED_TRACE("ray 9");
    EXPECT_EQ(r[9].hit[3], 2.0f);
    EXPECT_NEAR(r[9].hit[0], 12.5f, 1e-4f);
    EXPECT_EQ(r[9].ray[3], 1.0f) << "candidate AABB opaque";
    expectInstance(r[9], 40, 3, 0, m3, i3, 20.1f, 0.1f);
  }
  {
    SCOPED_TRACE("ray 10");
    EXPECT_EQ(r[10].hit[3], 1.0f);
    EXPECT_NEAR(r[10].hit[0], 18, 1e-4f);
    EXPECT_EQ(r[10].more[3], 0u);
    EXPECT_EQ(r[10].ids[0], 30u);
  }
  {
    SCOPED_TRACE("ray 11");
    EXPECT_EQ(r[11].hit[3], 2.0f);
    EXPECT_NEAR(r[11].hit[0], 13, 1e-4f);
    EXPECT_EQ(r[11].ids[0], 20u);
  }
  {
    SCOPED_TRACE("ray 12");
    nothing(r[12]);
    EXPECT_EQ(r[12].more[2] + r[12].more[3], 0u);
    EXPECT_EQ(r[12].firstCandidate[0], 0xffffffffu);
  }
  {
    SCOPED_TRACE("ray 13");
    nothing(r[13]);
    EXPECT_EQ(r[13].more[2], 2u) << "both quads are candidates";
  }
  {
    SCOPED_TRACE("ray 14");
    committedQuad(r[14], 15, 10, 0, 3, m0, i0, false);
    EXPECT_GE(r[14].more[2], 1u);
    EXPECT_LE(r[14].more[2], 2u);
    if (onVkrt()) {
      EXPECT_EQ(r[14].more[2], 1u) << "vkrt returns candidates nearest first";
    }
  }
  {
    SCOPED_TRACE("ray 15");
    // The first commit ends the query: the opaque quad (committed by the traversal) or the confirmed one.
    ASSERT_EQ(r[15].hit[3], 1.0f);
    if (r[15].ids[0] == 10u)
      committedQuad(r[15], 15, 10, 0, 3, m0, i0, false);
    else
      committedQuad(r[15], 17, 50, 4, 0, m4, i4, true);
  }
  {
    SCOPED_TRACE("ray 16");
    EXPECT_EQ(r[16].more[2] + r[16].more[3], 1u) << "terminated after the first candidate";
    EXPECT_NE(r[16].hit[3], 0.0f);
  }
  {
    SCOPED_TRACE("ray 17");
    nothing(r[17]);
    EXPECT_EQ(r[17].more[2], 0u);
  }
}

// The basic scene (two opaque quads) through trace_raygen.rgen's launch and through ray queries along the same rays:
// the same hits, values for value.
TEST_F(RayQueryTest, TheSameHitsAsARayTracingPipeline) {
  VkAccelerationStructureKHR top = basicScene();
  Desc d = basicDesc();
  VkPipeline p = make(d);
  Sbt s = sbt(p, 3, {0}, {{1, {7}}}, {{2, {100}}, {2, {101}}});
  constexpr uint32_t n = 8;
  std::vector<TracePayload> traced = trace(p, s, top, n, n);
  std::vector<RayIn> rays;
  for (uint32_t y = 0; y < n; ++y)
    for (uint32_t x = 0; x < n; ++x) rays.push_back(ray(cellCentre(x, n), cellCentre(y, n)));
  std::vector<Result> queried = shoot(top, rays);
  int hits = 0;
  for (uint32_t i = 0; i < n * n; ++i) {
    SCOPED_TRACE("ray " + std::to_string(i));
    const TracePayload& t = traced[i];
    const Result& q = queried[i];
    if (t.hit[0] == -2.0f) {
      EXPECT_EQ(q.hit[3], 0.0f) << "a miss";
      continue;
    }
    ++hits;
    EXPECT_EQ(q.hit[3], 1.0f);
    EXPECT_EQ(q.hit[0], t.hit[0]) << "t";
    EXPECT_EQ(q.hit[1], t.hit[1]) << "barycentrics";
    EXPECT_EQ(q.hit[2], t.hit[2]);
    EXPECT_EQ(q.more[1], t.hit[3] == 254.0f ? 1u : 0u) << "front face against the hit kind";
    EXPECT_EQ(q.ids[0], t.ids[0]) << "custom index";
    EXPECT_EQ(q.ids[1], t.ids[1]) << "instance id";
    EXPECT_EQ(q.ids[2], t.ids[2]) << "primitive";
    EXPECT_EQ(q.ids[3], t.ids[3]) << "geometry";
  }
  EXPECT_GT(hits, 10);
}

// A ray query in a ray tracing stage: ray_query_raygen.rgen shoots trace_raygen.rgen's rays through a ray query and
// writes what the closest-hit and miss shaders would; the two launches agree on the basic scene, and on a scene of
// non-opaque quads (every candidate confirmed: the closest is committed).
TEST_F(RayQueryTest, InARaygenShaderTheSameHitsAsTraceRay) {
  VkShaderModule rq = module(kSpv_ray_query_raygen_rgen, sizeof kSpv_ray_query_raygen_rgen);
  Desc traced = basicDesc();
  VkPipeline pt = make(traced);
  Desc queried;
  queried.layout = traceLayout;
  queried.general(rq, VK_SHADER_STAGE_RAYGEN_BIT_KHR);
  queried.general(tmiss, VK_SHADER_STAGE_MISS_BIT_KHR);
  queried.group(VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR, VK_SHADER_UNUSED_KHR,
                queried.stage(tchit, VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR));
  VkPipeline pq = make(queried);
  constexpr uint32_t n = 8;
  VkAccelerationStructureKHR quadNo = blas({triangles(kQuad, kQuadIndices, 0)});
  VkAccelerationStructureKHR scenes[2] = {
      basicScene(), tlas({instance(quadNo, 0.1f, 0, 5, 10, 0), instance(quadNo, 0.3f, 0.2f, 3, 20, 1)})};
  for (int k = 0; k < 2; ++k) {
    SCOPED_TRACE(k ? "non-opaque quads" : "basic scene");
    std::vector<TracePayload> a = trace(pt, sbt(pt, 3, {0}, {{1, {7}}}, {{2, {100}}, {2, {101}}}), scenes[k], n, n);
    std::vector<TracePayload> b = trace(pq, sbt(pq, 3, {0}, {{1, {7}}}, {{2, {100}}, {2, {101}}}), scenes[k], n, n);
    int hits = 0;
    for (uint32_t i = 0; i < n * n; ++i) {
      SCOPED_TRACE("ray " + std::to_string(i));
      EXPECT_EQ(b[i].hit[0], a[i].hit[0]) << "t (-2: a miss)";
      if (a[i].hit[0] == -2.0f) continue;
      ++hits;
      for (int c = 1; c < 4; ++c) EXPECT_EQ(b[i].hit[c], a[i].hit[c]) << "barycentrics, hit kind";
      for (int c = 0; c < 4; ++c) EXPECT_EQ(b[i].ids[c], a[i].ids[c]) << "custom index, instance, primitive, geometry";
      if (k == 0) {
        EXPECT_EQ(b[i].extra[1], 0u) << "opaque quads: no candidate";
      }
    }
    EXPECT_GT(hits, 10);
  }
}

// Boxes through a ray query in a raygen shader (spheres generated as trace_sphere.rint reports them) and through a
// procedural hit group: the same hits; with an opaque quad in front of some spheres and behind others.
TEST_F(RayQueryTest, InARaygenShaderGeneratedHitsAgreeWithAnIntersectionShader) {
  setSpheres({{-1, -1, 4, 0.5f}, {1, 1, 6, 0.5f}, {0.6f, -0.9f, 5, 0.7f}});
  VkAccelerationStructureKHR b = blas({aabbs({{-1.5f, -1.5f, 3.5f, -0.5f, -0.5f, 4.5f},
                                              {0.5f, 0.5f, 5.5f, 1.5f, 1.5f, 6.5f},
                                              {-0.1f, -1.6f, 4.3f, 1.3f, -0.2f, 5.7f}},
                                             0)});
  VkAccelerationStructureKHR quadOpaque = blas({triangles(kQuad, kQuadIndices, VK_GEOMETRY_OPAQUE_BIT_KHR)});
  VkAccelerationStructureKHR top = tlas({instance(b, 0, 0, 1, 9, 0), instance(quadOpaque, 0.35f, 0.35f, 6.5f, 4, 1)});
  Desc traced;
  traced.layout = traceLayout;
  traced.general(rgen, VK_SHADER_STAGE_RAYGEN_BIT_KHR);
  traced.general(tmiss, VK_SHADER_STAGE_MISS_BIT_KHR);
  uint32_t c = traced.stage(tchit, VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR);
  uint32_t i = traced.stage(tsphere, VK_SHADER_STAGE_INTERSECTION_BIT_KHR);
  traced.group(VK_RAY_TRACING_SHADER_GROUP_TYPE_PROCEDURAL_HIT_GROUP_KHR, VK_SHADER_UNUSED_KHR, c, VK_SHADER_UNUSED_KHR,
               i);
  traced.group(VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR, VK_SHADER_UNUSED_KHR, c);
  traced.maxHitAttr = 8;
  traced.maxPayload = sizeof(TracePayload);
  VkPipeline pt = make(traced);
  VkShaderModule rq = module(kSpv_ray_query_raygen_rgen, sizeof kSpv_ray_query_raygen_rgen);
  Desc queried;
  queried.layout = traceLayout;
  queried.general(rq, VK_SHADER_STAGE_RAYGEN_BIT_KHR);
  queried.general(tmiss, VK_SHADER_STAGE_MISS_BIT_KHR);
  VkPipeline pq = make(queried);
  constexpr uint32_t n = 16;
  std::vector<TracePayload> a = trace(pt, sbt(pt, 4, {0}, {{1, {7}}}, {{2, {300}}, {3, {301}}}), top, n, n);
  std::vector<TracePayload> q = trace(pq, sbt(pq, 2, {0}, {{1, {7}}}, {}), top, n, n);
  int spheres = 0, quads = 0;
  for (uint32_t k = 0; k < n * n; ++k) {
    SCOPED_TRACE("ray " + std::to_string(k));
    EXPECT_NEAR(q[k].hit[0], a[k].hit[0], 1e-5f) << "t (-2: a miss)";
    if (a[k].hit[0] == -2.0f) continue;
    (a[k].hit[3] == 5.0f ? spheres : quads)++;
    for (int j = 1; j < 4; ++j) EXPECT_EQ(q[k].hit[j], a[k].hit[j]) << "attributes, hit kind";
    for (int j = 0; j < 4; ++j) EXPECT_EQ(q[k].ids[j], a[k].ids[j]) << "custom index, instance, primitive, geometry";
  }
  EXPECT_GT(spheres, 6);
  EXPECT_GT(quads, 6);
}

// VKRT_RAY_TREE's compute ids (docs/ray-tree.md): the ray query of global invocation 9 (in the second workgroup of
// ray_query_scene.comp, which runs in vkrt_group) is recorded under the compute shader, as ray_tree_test.cpp's
// raygen query is: a non-opaque quad at z = 2 (t = 12, confirmed) in front of an opaque one at z = 5 (t = 15,
// committed by the traversal). Invocation 9's ray alone has tMax 99, so the tree shows it is that invocation's; the
// invocations after it in the workgroup (same query variable) add nothing to it.
class RayTreeComputeTest : public RayQueryTest {
 protected:
  bool layer() override { return false; }  // the tree names the pipeline by vkrt's handle
  const std::string out = "/tmp/vkrt_ray_tree_compute_" + std::to_string(getpid()) + ".txt";

  void SetUp() override {
    std::remove(out.c_str());
    setenv("VKRT_RAY_TREE", "compute:9", 1);
    setenv("VKRT_RAY_TREE_OUT", out.c_str(), 1);
    RayQueryTest::SetUp();
    if (!HasFatalFailure() && device && !onVkrt()) GTEST_SKIP() << "VKRT_RAY_TREE is vkrt's";
  }
  void TearDown() override {
    RayQueryTest::TearDown();
    unsetenv("VKRT_RAY_TREE");
    unsetenv("VKRT_RAY_TREE_OUT");
    std::remove(out.c_str());
  }
  std::string written() const {
    std::ifstream f(out);
    std::stringstream ss;
    ss << f.rdbuf();
    return ss.str();
  }
};
TEST_F(RayTreeComputeTest, TheNamedInvocationsQueryIsRecorded) {
  VkAccelerationStructureKHR quadNo = blas({triangles(kQuad, kQuadIndices, 0)});
  VkAccelerationStructureKHR quadOpaque = blas({triangles(kQuad, kQuadIndices, VK_GEOMETRY_OPAQUE_BIT_KHR)});
  VkAccelerationStructureKHR top = tlas({instance(quadNo, -1, -1, 2, 10, 0), instance(quadOpaque, 0, 0, 5, 20, 0)});
  std::vector<RayIn> rays(12, ray(-0.5f, -0.5f));
  rays[9] = ray(-0.5f, -0.5f, kConfirm, 0, 0xff, 0, 99);
  const std::vector<Result> r = shoot(top, rays);
  for (size_t i = 0; i < r.size(); ++i) EXPECT_NEAR(r[i].hit[0], 12, 1e-4) << i;
  const std::string text = written();
  const std::string head = "ray tree of global invocation id 9,0,0 in vkCmdDispatch #0 (pipeline 0x";
  ASSERT_EQ(text.compare(0, head.size(), head), 0) << text;
  EXPECT_NE(text.find(", workgroups 2x1x1)\n"), std::string::npos) << text;
  EXPECT_EQ(text.find("ray tree of", 1), std::string::npos) << "one tree: " << text;
  auto tOf = [&](const std::string& prefix) {
    size_t p = text.find(prefix);
    EXPECT_NE(p, std::string::npos) << prefix << "\n" << text;
    if (p == std::string::npos) return std::string("0");
    p += prefix.size();
    return text.substr(p, text.find(' ', p) - p);
  };
  const std::string t12 = tOf("proceed: candidate triangle t="), t15 = tOf("; committed triangle t=");
  EXPECT_NEAR(std::stod(t12), 12, 12e-4);
  EXPECT_NEAR(std::stod(t15), 15, 15e-4);
  char as[32];
  std::snprintf(as, sizeof as, "0x%" PRIx64, addressOf(top));
  const std::string nearHit = "triangle t=" + t12 + " instance 0 (custom 10) geometry 0 primitive 1 hitKind 0xff";
  const std::string farHit = "triangle t=" + t15 + " instance 1 (custom 20) geometry 0 primitive 0 hitKind 0xff";
  const std::string want = "  compute shader \"main\"\n    rayQueryInitialize as " + std::string(as) +
                           " origin (-0.5, -0.5, -10) direction (0, 0, 1) tMin 0 tMax 99 flags 0x0 cullMask 0xff\n" +
                           "      proceed: candidate " + nearHit + "; committed " + farHit + "\n" +
                           "      confirm: committed " + nearHit + "\n" + "      proceed: false; committed " + nearHit +
                           "\n";
  const size_t at = text.find('\n');
  ASSERT_NE(at, std::string::npos);
  EXPECT_EQ(text.substr(at + 1), want);
  // The valid side: a dispatch of one workgroup (invocations 0..7) does not run the named id: nothing is written.
  std::remove(out.c_str());
  shoot(top, std::vector<RayIn>(8, ray(-0.5f, -0.5f)));
  EXPECT_EQ(written(), "");
}

// Ray queries on an address from the shader (OpConvertUToAccelerationStructureKHR): a built top level is traversed;
// an address that is no acceleration structure, or one destroyed, is reported once and the query finds nothing.
class RayQueryMisuseTest : public RayQueryTest {
 protected:
  bool layer() override { return false; }
};

// Hundreds of top levels reached in one dispatch, each invocation choosing one by address: each resolves once per
// dispatch (exec's TopLevelResolver), rays take no lock, make no hash lookup and allocate nothing however many
// structures there are. Before, a dispatch's first 16 addresses were cached and every ray on a later one took two
// locks, a hash lookup and kept another reference in a list that grew with every ray (about 10 bytes a ray, without
// bound): the resident memory is checked over three dispatches of 2^18 queries. A bottom-level address and a wild
// one among them find nothing, reported once.
TEST_F(RayQueryMisuseTest, HundredsOfTopLevelsInOneDispatchResolveOnceEach) {
  if (!onVkrt()) GTEST_SKIP() << "vkrt's own diagnostics";
  constexpr uint32_t kLevels = 300, kInvocations = 1u << 18;
  VkAccelerationStructureKHR quad = blas({triangles(kQuad, kQuadIndices, VK_GEOMETRY_OPAQUE_BIT_KHR)});
  std::vector<uint64_t> addresses;
  for (uint32_t k = 0; k < kLevels; ++k) addresses.push_back(addressOf(tlas({instance(quad, 0, 0, 0, k + 1)})));
  addresses[100] = addressOf(quad);  // a bottom level: no top level there
  addresses[200] = 0x1234560;        // nothing at all
  HostBuffer& in = buffer(addresses.size() * 8, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  std::memcpy(in.data, addresses.data(), addresses.size() * 8);
  HostBuffer& out = buffer(kInvocations * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  ComputePipeline p = makeComputePipeline(device, kSpv_ray_query_many_comp, sizeof kSpv_ray_query_many_comp,
                                          {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}, 4);
  ASSERT_EQ(p.result, VK_SUCCESS);
  VkDescriptorBufferInfo bi[2] = {{in.buffer, 0, VK_WHOLE_SIZE}, {out.buffer, 0, VK_WHOLE_SIZE}};
  VkWriteDescriptorSet w[2];
  for (uint32_t b = 0; b < 2; ++b) {
    w[b] = VkWriteDescriptorSet{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    w[b].dstSet = p.set;
    w[b].dstBinding = b;
    w[b].descriptorCount = 1;
    w[b].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    w[b].pBufferInfo = &bi[b];
  }
  vkUpdateDescriptorSets(device, 2, w, 0, nullptr);
  uint64_t afterFirst = 0;
  for (int round = 0; round < 3; ++round) {
    std::memset(out.data, 0xee, kInvocations * 4);
    VkCommandBuffer cb = beginOneTime();
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout, 0, 1, &p.set, 0, nullptr);
    vkCmdPushConstants(cb, p.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, 4, &kLevels);
    vkCmdDispatch(cb, kInvocations / 64, 1, 1);
    submitAndWait(cb);
    const uint32_t* r = static_cast<const uint32_t*>(out.data);
    size_t wrong = 0;
    for (uint32_t i = 0; i < kInvocations; ++i) {
      const uint32_t k = uint32_t((uint64_t(i) * 7919u) % kLevels);
      const uint32_t expected = k == 100 || k == 200 ? 0xFFFFFFFFu : k + 1;
      if (r[i] != expected && ++wrong <= 5) ADD_FAILURE() << "invocation " << i << ": " << r[i] << ", not " << expected;
    }
    EXPECT_EQ(wrong, 0u) << "round " << round;
    auto msgs = vkrtMessages();
    ASSERT_EQ(msgs.size(), 1u) << "one report per dispatch for the two addresses without a top level";
    EXPECT_NE(msgs[0].text.find("not the address of a built top-level acceleration structure"), std::string::npos)
        << msgs[0].text;
    clearMessages();
    if (round == 0) afterFirst = residentBytes();
  }
  // Two more dispatches of 2^18 queries each, 98% of them on structures past the 16th: at 10 bytes a ray they
  // took 5 MB; nothing grows per ray now (the bound leaves room for the allocator's own variation).
  const uint64_t growth = residentBytes() - std::min(afterFirst, residentBytes());
  EXPECT_LT(growth, 2u << 20) << "resident memory grew by " << growth << " bytes over two dispatches";
}

TEST_F(RayQueryMisuseTest, AWildOrDestroyedStructureAddressIsReportedAndFindsNothing) {
  if (!onVkrt()) GTEST_SKIP() << "vkrt's own diagnostics";
  ComputePipeline p = makeComputePipeline(device, kSpv_ray_query_address_comp, sizeof kSpv_ray_query_address_comp,
                                          {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}, 8);
  ASSERT_EQ(p.result, VK_SUCCESS);
  HostBuffer& out = buffer(16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  VkDescriptorBufferInfo bo{out.buffer, 0, VK_WHOLE_SIZE};
  VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
  w.dstSet = p.set;
  w.descriptorCount = 1;
  w.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  w.pBufferInfo = &bo;
  vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);
  auto run = [&](uint64_t address) {
    std::memset(out.data, 0xee, 16);
    VkCommandBuffer cb = beginOneTime();
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout, 0, 1, &p.set, 0, nullptr);
    vkCmdPushConstants(cb, p.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, 8, &address);
    vkCmdDispatch(cb, 1, 1, 1);
    submitAndWait(cb);
    std::array<uint32_t, 4> r;
    std::memcpy(r.data(), out.data, 16);
    return r;
  };
  auto expectNothing = [&](const std::array<uint32_t, 4>& r, uint64_t address) {
    EXPECT_EQ(r[0], 0u) << "committed type: none";
    EXPECT_EQ(r[2], 0u) << "no candidate";
    EXPECT_EQ(r[3], 7u) << "the shader ran to its end";
    auto msgs = vkrtMessages();
    ASSERT_EQ(msgs.size(), 1u);
    char text[32];
    std::snprintf(text, sizeof text, "0x%llx", (unsigned long long)address);
    EXPECT_NE(msgs[0].text.find(text), std::string::npos) << msgs[0].text;
    EXPECT_NE(msgs[0].text.find("find no intersection"), std::string::npos) << msgs[0].text;
    clearMessages();
  };

  VkAccelerationStructureKHR quadNo = blas({triangles(kQuad, kQuadIndices, 0)});
  VkAccelerationStructureKHR top = tlas({instance(quadNo, 0, 0, 5)});
  std::array<uint32_t, 4> r = run(addressOf(top));
  EXPECT_EQ(r[0], 1u) << "committed type: triangle";
  float t;
  std::memcpy(&t, &r[1], 4);
  EXPECT_TRUE(nearHit(t, 15.0f, 10)) << t;  // a triangle's t, within the kernels' rounding (hit_distance.hpp)
  EXPECT_EQ(r[2], 1u);
  EXPECT_TRUE(vkrtMessages().empty());

  const uint64_t wild = 0x123456789a0ull;
  expectNothing(run(wild), wild);
  const uint64_t bottom = addressOf(quadNo);
  expectNothing(run(bottom), bottom);
  const uint64_t gone = addressOf(top);
  destroyAs(device, top, nullptr);
  structures.erase(std::find(structures.begin(), structures.end(), top));
  expectNothing(run(gone), gone);
  destroyComputePipeline(device, p);
}

// A device with VK_KHR_ray_query and without VK_KHR_ray_tracing_pipeline: its acceleration structures are sized
// like any other (VUID-vkGetAccelerationStructureBuildSizesKHR-rayTracingPipeline-03617 asks for the
// rayTracingPipeline or the rayQuery feature; vkrt asked for the first only, and sized nothing).
class RayQueryOnlyTest : public VulkanTest {
 protected:
  VkPhysicalDeviceRayQueryFeaturesKHR rqf{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR};
  VkPhysicalDeviceAccelerationStructureFeaturesKHR asf{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR};

  FixtureOptions options() override {
    FixtureOptions o;
    o.deviceExtensions = {VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME, VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME,
                          VK_KHR_RAY_QUERY_EXTENSION_NAME};
    rqf.rayQuery = VK_TRUE;
    asf.accelerationStructure = VK_TRUE;
    asf.pNext = &rqf;
    o.featureChain = &asf;
    return o;
  }

  void SetUp() override {
    if (!firstDeviceHasExtension(VK_KHR_RAY_QUERY_EXTENSION_NAME))
      GTEST_SKIP() << "the driver has no " VK_KHR_RAY_QUERY_EXTENSION_NAME;
    VulkanTest::SetUp();
  }
};

TEST_F(RayQueryOnlyTest, StructuresAreSized) {
  auto buildSizes = reinterpret_cast<PFN_vkGetAccelerationStructureBuildSizesKHR>(
      vkGetDeviceProcAddr(device, "vkGetAccelerationStructureBuildSizesKHR"));
  ASSERT_NE(buildSizes, nullptr);
  VkAccelerationStructureGeometryKHR g{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
  g.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
  auto& t = g.geometry.triangles;
  t.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
  t.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
  t.vertexStride = 12;
  t.maxVertex = 2;
  t.indexType = VK_INDEX_TYPE_NONE_KHR;
  VkAccelerationStructureBuildGeometryInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
  info.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
  info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
  info.geometryCount = 1;
  info.pGeometries = &g;
  const uint32_t primitives = 1;
  VkAccelerationStructureBuildSizesInfoKHR sizes{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
  buildSizes(device, VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &info, &primitives, &sizes);
  EXPECT_GT(sizes.accelerationStructureSize, 0u);
  EXPECT_TRUE(vkrtMessages().empty());
}

}  // namespace
}  // namespace vkrt::test
