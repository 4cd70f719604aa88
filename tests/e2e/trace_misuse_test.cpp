// Misuse of tracing that vkrt diagnoses: the SBT holding what the bound pipeline cannot run, an undersized
// pipeline stack, instances referring to structures that do not exist. Each is reported with its VUID, naming
// what it is about, and the launch goes on without running the bad record (no crash). The validation layer is off:
// it would report (or not see) the same misuse.
#include <cmath>
#include <cstdlib>

#include "e2e/trace_fixture.hpp"
#include "trace_many_raygen.rgen.spv.h"

namespace vkrt::test {
namespace {

class TraceMisuseTest : public TraceTest {
 protected:
  bool layer() override { return false; }
  void SetUp() override {
    TraceTest::SetUp();
    if (HasFatalFailure() || !device) return;
    if (!onVkrt()) GTEST_SKIP() << "vkrt's own diagnostics";
    quad = blas({triangles(kQuad, kQuadIndices, VK_GEOMETRY_OPAQUE_BIT_KHR)});
    top = tlas({instance(quad, 0, 0, 5)});
  }
  // raygen, miss, triangle hit group: the pipeline most tests here trace with.
  VkPipeline basic() {
    Desc d = basicDesc();
    return make(d);
  }
  // Asserts one vkrt report naming `vuid` (null: a report without one) whose text contains each of `parts`.
  void expectReport(const char* vuid, std::initializer_list<const char*> parts) {
    auto msgs = vkrtMessages();
    ASSERT_EQ(msgs.size(), 1u) << "expected one report naming " << (vuid ? vuid : "no VUID")
                               << (msgs.empty() ? "" : ", first: " + msgs[0].text);
    EXPECT_EQ(msgs[0].idName, vuid ? vuid : "vkrt") << msgs[0].text;
    for (const char* p : parts)
      EXPECT_NE(msgs[0].text.find(p), std::string::npos) << "missing \"" << p << "\" in: " << msgs[0].text;
    clearMessages();
  }
  VkAccelerationStructureKHR quad = VK_NULL_HANDLE, top = VK_NULL_HANDLE;
};

TEST_F(TraceMisuseTest, AHandleOfAnotherPipelineInTheSbtIsReportedWithItsGroupAndPipeline) {
  VkPipeline p = basic();
  // Another pipeline whose third group (a procedural hit group) the first one does not have.
  Desc other;
  other.layout = traceLayout;
  other.general(rgen, VK_SHADER_STAGE_RAYGEN_BIT_KHR);
  other.general(tmiss, VK_SHADER_STAGE_MISS_BIT_KHR);
  other.group(VK_RAY_TRACING_SHADER_GROUP_TYPE_PROCEDURAL_HIT_GROUP_KHR, VK_SHADER_UNUSED_KHR,
              other.stage(tchit, VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR), VK_SHADER_UNUSED_KHR,
              other.stage(tsphere, VK_SHADER_STAGE_INTERSECTION_BIT_KHR));
  VkPipeline q = make(other);
  std::vector<uint8_t> h = handles(p, 0, 3);
  std::vector<uint8_t> foreign = handles(q, 2, 1);
  std::copy(foreign.begin(), foreign.end(), h.begin() + 64);
  Sbt s = sbtFrom(h, {0}, {{1, {7}}}, {{2, {100}}});
  clearMessages();
  std::vector<TracePayload> r = trace(p, s, top, 4, 4);
  char pipe[32];
  std::snprintf(pipe, sizeof pipe, "0x%llx", (unsigned long long)reinterpret_cast<uintptr_t>(q));
  expectReport("VUID-vkCmdTraceRaysKHR-None-03429",
               {"hit record 0", "procedural hit group", "\"main\"", pipe, "neither the bound pipeline"});
  EXPECT_EQ(r[5].hit[0], -1.0f) << "the hit's closest-hit shader did not run (the payload is as raygen set it)";
}

TEST_F(TraceMisuseTest, GarbageInTheSbtIsReportedOnceAndNotRun) {
  VkPipeline p = basic();
  std::vector<uint8_t> h = handles(p, 0, 3);
  for (int k = 64; k < 96; ++k) h[k] = uint8_t(k * 37 + 11);
  Sbt s = sbtFrom(h, {0}, {{1, {7}}}, {{2, {100}}});
  clearMessages();
  std::vector<TracePayload> r = trace(p, s, top, 4, 4);
  expectReport("VUID-vkCmdTraceRaysKHR-None-03429",
               {"hit record 0", "does not hold a shader group handle of this device"});
  EXPECT_EQ(r[5].hit[0], -1.0f);
  EXPECT_EQ(r[0].hit[0], -2.0f) << "rays that miss still run the miss shader";
}

TEST_F(TraceMisuseTest, ARecordPastItsRegionIsReported) {
  VkPipeline p = basic();
  Sbt s = sbt(p, 3, {0}, {{1, {7}}}, {{2, {100}}});
  clearMessages();
  TraceParams t;
  t.sbtOffset = 3;  // hit record 3 of a one-record region
  trace(p, s, top, 4, 4, t);
  expectReport(nullptr, {"hit record 3", "outside its region"});
}

TEST_F(TraceMisuseTest, AProceduralHitGroupUsedForTrianglesIsReported) {
  Desc d;
  d.layout = traceLayout;
  d.general(rgen, VK_SHADER_STAGE_RAYGEN_BIT_KHR);
  d.general(tmiss, VK_SHADER_STAGE_MISS_BIT_KHR);
  d.group(VK_RAY_TRACING_SHADER_GROUP_TYPE_PROCEDURAL_HIT_GROUP_KHR, VK_SHADER_UNUSED_KHR,
          d.stage(tchit, VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR), VK_SHADER_UNUSED_KHR,
          d.stage(tsphere, VK_SHADER_STAGE_INTERSECTION_BIT_KHR));
  VkPipeline p = make(d);
  Sbt s = sbt(p, 3, {0}, {{1, {7}}}, {{2, {100}}});
  clearMessages();
  std::vector<TracePayload> r = trace(p, s, top, 4, 4);
  expectReport("VUID-vkCmdTraceRaysKHR-pHitShaderBindingTable-04735",
               {"hit record 0", "triangle", "procedural hit group"});
  EXPECT_EQ(r[5].hit[0], -1.0f);
}

// The CTS's pipeline_no_null_shaders_flag.*.tri_and_box.* cases without "isect" (56 of them) trace a scene of
// triangles and boxes whose every hit record holds one procedural hit group (closest-hit + intersection): the
// triangles' records too, which VUID-vkCmdTraceRaysKHR-pHitShaderBindingTable-04735 forbids ("Any non-zero hit
// shader group entries ... accessed by this call from a geometry with a geometryType of
// VK_GEOMETRY_TYPE_TRIANGLES_KHR must have been created with VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR";
// the NO_NULL_* flags change nothing there). That scene, the same with a triangles hit group in the triangles'
// record (tools/cts/pipeline-flags-test.patch: valid, nothing reported, every hit runs), and the converse (04736).
TEST_F(TraceMisuseTest, HitGroupTypesInASceneOfTrianglesAndBoxes) {
  // A quad over world x in [-2, 0] at z = 5 (instance 0, record 0); a sphere of radius 0.5 around (1, 0, 5) in its
  // box (instance 1, record 1).
  setSpheres({{1, 0, 5, 0.5f}});
  VkAccelerationStructureKHR box = blas({aabbs({{0.5f, -0.5f, 4.5f, 1.5f, 0.5f, 5.5f}}, VK_GEOMETRY_OPAQUE_BIT_KHR)});
  VkAccelerationStructureKHR scene = tlas({instance(quad, -1, 0, 5, 1, 0), instance(box, 0, 0, 0, 2, 1)});
  Desc d;
  d.layout = traceLayout;
  d.flags = VK_PIPELINE_CREATE_RAY_TRACING_NO_NULL_CLOSEST_HIT_SHADERS_BIT_KHR |
            VK_PIPELINE_CREATE_RAY_TRACING_NO_NULL_MISS_SHADERS_BIT_KHR;  // as the CTS's "chit_or_miss" case
  d.general(rgen, VK_SHADER_STAGE_RAYGEN_BIT_KHR);
  d.general(tmiss, VK_SHADER_STAGE_MISS_BIT_KHR);
  const uint32_t c = d.stage(tchit, VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR);
  d.group(VK_RAY_TRACING_SHADER_GROUP_TYPE_PROCEDURAL_HIT_GROUP_KHR, VK_SHADER_UNUSED_KHR, c, VK_SHADER_UNUSED_KHR,
          d.stage(tsphere, VK_SHADER_STAGE_INTERSECTION_BIT_KHR));                             // group 2
  d.group(VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR, VK_SHADER_UNUSED_KHR, c);  // group 3
  d.maxHitAttr = 8;
  d.maxPayload = sizeof(TracePayload);
  VkPipeline p = make(d);
  ASSERT_NE(p, VK_NULL_HANDLE);
  const uint32_t n = 8;                    // cell centres -1.75 .. 1.75
  const uint32_t quadPixel = 3 * n + 1;    // (-1.25, -0.25): the quad, t = 15
  const uint32_t spherePixel = 4 * n + 6;  // (1.25, 0.25): the sphere, t = 15 - sqrt(0.125)
  const uint32_t missPixel = 0;            // (-1.75, -1.75)
  const float sphereT = 15.0f - std::sqrt(0.125f);
  struct Case {
    const char* what;
    int32_t triangleGroup, boxGroup;
    const char* vuid;  // null: valid
    std::initializer_list<const char*> parts;
  };
  const Case cases[] = {
      {"the CTS's records: the procedural group for the triangles too",
       2,
       2,
       "VUID-vkCmdTraceRaysKHR-pHitShaderBindingTable-04735",
       {"hit record 0", "triangle", "procedural hit group"}},
      {"each geometry type its group (the patched CTS)", 3, 2, nullptr, {}},
      {"the triangles group for the boxes",
       3,
       3,
       "VUID-vkCmdTraceRaysKHR-pHitShaderBindingTable-04736",
       {"hit record 1", "AABB", "triangles hit group"}},
  };
  for (const Case& k : cases) {
    SCOPED_TRACE(k.what);
    Sbt s = sbt(p, 4, {0}, {{1, {7}}}, {{k.triangleGroup, {400}}, {k.boxGroup, {300}}});
    clearMessages();
    const std::vector<TracePayload> r = trace(p, s, scene, n, n);
    if (k.vuid)
      expectReport(k.vuid, k.parts);
    else
      EXPECT_TRUE(vkrtMessages().empty()) << "valid use is not reported";
    EXPECT_EQ(r[missPixel].hit[0], -2.0f) << "a ray that meets nothing runs the miss shader";
    if (k.triangleGroup == 3) {
      EXPECT_NEAR(r[quadPixel].hit[0], 15.0f, 1e-4f);
      EXPECT_EQ(r[quadPixel].ids[0], 1u);
      EXPECT_EQ(r[quadPixel].extra[0], 400u);
    } else {
      EXPECT_EQ(r[quadPixel].hit[0], -1.0f) << "the triangle's record is not run: the payload is as raygen set it";
    }
    if (k.boxGroup == 2) {
      EXPECT_NEAR(r[spherePixel].hit[0], sphereT, 1e-4f);
      EXPECT_EQ(r[spherePixel].ids[0], 2u);
      EXPECT_EQ(r[spherePixel].extra[0], 300u);
    } else {
      EXPECT_EQ(r[spherePixel].hit[0], -2.0f) << "the box's record is not run: no intersection shader, a miss";
    }
  }
}

TEST_F(TraceMisuseTest, AnUndersizedDynamicStackIsReportedWithTheShaderChain) {
  Desc d;
  d.layout = traceLayout;
  d.dynamicStackSize = true;
  d.general(rgen, VK_SHADER_STAGE_RAYGEN_BIT_KHR);
  d.general(tmiss, VK_SHADER_STAGE_MISS_BIT_KHR);
  d.group(VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR, VK_SHADER_UNUSED_KHR,
          d.stage(tchit, VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR));
  VkPipeline p = VK_NULL_HANDLE;
  ASSERT_EQ(create(d, &p), VK_SUCCESS);
  const VkDeviceSize raygenStack = getStackSize(device, p, 0, VK_SHADER_GROUP_SHADER_GENERAL_KHR);
  ASSERT_GT(raygenStack, 0u) << "trace_raygen calls traceRayEXT: its stack size is not 0";
  Sbt s = sbt(p, 3, {0}, {{1, {7}}}, {{2, {100}}});
  clearMessages();
  std::vector<TracePayload> r = trace(p, s, top, 4, 4, {}, int64_t(raygenStack) - 1);
  expectReport("VUID-vkCmdSetRayTracingPipelineStackSizeKHR-pipelineStackSize-03610",
               {"call chain", "raygen shader \"main\"", "more than the pipeline stack size"});
  EXPECT_EQ(r[0].ids[0], 0xeeeeeeeeu) << "the raygen shader did not run: the output keeps its fill pattern";
  // With exactly the raygen shader's stack size, the launch runs.
  r = trace(p, s, top, 4, 4, {}, int64_t(raygenStack));
  EXPECT_TRUE(vkrtMessages().empty());
  EXPECT_EQ(r[0].hit[0], -2.0f);
}

TEST_F(TraceMisuseTest, AnInstanceOfADestroyedBottomLevelStructureIsReportedAndTheLaunchMisses) {
  VkAccelerationStructureKHR doomed = blas({triangles(kQuad, kQuadIndices, VK_GEOMETRY_OPAQUE_BIT_KHR)});
  VkAccelerationStructureInstanceKHR in = instance(doomed, 0, 0, 5);
  destroyAs(device, doomed, nullptr);
  structures.erase(std::find(structures.begin(), structures.end(), doomed));
  clearMessages();
  VkAccelerationStructureKHR broken = tlas({in});
  char address[32];
  std::snprintf(address, sizeof address, "0x%llx", (unsigned long long)in.accelerationStructureReference);
  expectReport("VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-06707", {"instance 0", address, "destroyed"});
  VkPipeline p = basic();
  Sbt s = sbt(p, 3, {0}, {{1, {7}}}, {{2, {100}}});
  std::vector<TracePayload> r = trace(p, s, broken, 4, 4);
  expectReport(nullptr, {"not the address of a built top-level acceleration structure", "those rays miss"});
  EXPECT_EQ(r[5].hit[0], -2.0f);
}

// A top level of 200,000 instances (the build reads them in chunks of 65,536 on the thread pool and resolves each
// run of equal references once): every instance sits at its own launch index's ray, scaled to a 512th, and refers
// to one of three bottom levels (quads at z = 1, 2, 3) or to none, in runs of every length from 1 to 64 and runs
// that cross the chunk boundaries; each ray must meet its instance's quad at its bottom level's depth. Then the same
// instances with two destroyed bottom levels' addresses, the first at 150,000 (a run starting inside the third
// chunk) and the second at 190,000: the first bad instance is the one reported.
TEST_F(TraceMisuseTest, TensOfThousandsOfInstancesResolveEachRunOfReferencesAndReportTheFirstBadOne) {
  constexpr uint32_t kSide = 512, kInstances = 200000;
  VkAccelerationStructureKHR levels[3];
  for (int b = 0; b < 3; ++b) {
    std::vector<float> v = kQuad;
    for (size_t k = 2; k < v.size(); k += 3) v[k] = float(b + 1);
    levels[b] = blas({triangles(v, kQuadIndices, VK_GEOMETRY_OPAQUE_BIT_KHR)});
  }
  // The bottom level of instance k (3: none), in runs: lengths 1, 2, ..., 64 over and over, the level cycling;
  // instances 65,530-65,541 and 131,066-131,077 form runs across the chunk boundaries.
  std::vector<int> levelOf(kInstances);
  for (uint32_t k = 0, len = 1, run = 0; k < kInstances; ++run, len = len % 64 + 1)
    for (uint32_t i = 0; i < len && k < kInstances; ++i) levelOf[k++] = int((run * 7 + run / 5) % 4);
  for (uint32_t k = 65530; k < 65542; ++k) levelOf[k] = 2;
  for (uint32_t k = 131066; k < 131078; ++k) levelOf[k] = 1;
  levelOf[131071] = 0;  // a run of one just before the third chunk, whose first instance starts a run of its own
  std::vector<VkAccelerationStructureInstanceKHR> instances(kInstances);
  for (uint32_t k = 0; k < kInstances; ++k) {
    // The ray of launch index k: x, y = (index + 0.5) / 512 * 4 - 2 (trace_raygen).
    const float x = (float(k % kSide) + 0.5f) / float(kSide) * 4 - 2,
                y = (float(k / kSide) + 0.5f) / float(kSide) * 4 - 2;
    instances[k] = instance(levelOf[k] < 3 ? levels[levelOf[k]] : VK_NULL_HANDLE, x, y, 0, k);
    instances[k].transform.matrix[0][0] = instances[k].transform.matrix[1][1] = 1.0f / 512;
  }
  VkAccelerationStructureKHR many = tlas(instances);
  EXPECT_TRUE(vkrtMessages().empty());
  VkPipeline p = basic();
  Sbt s = sbt(p, 3, {0}, {{1, {7}}}, {{2, {100}}});
  std::vector<TracePayload> r = trace(p, s, many, kSide, kSide);
  uint32_t wrong = 0;
  for (uint32_t k = 0; k < kSide * kSide; ++k) {
    const int level = k < kInstances ? levelOf[k] : 3;
    // (t within 1e-5 of the depth: Embree's kernels for each instruction set round the object-space t differently,
    // and the levels are 1 apart.)
    const bool ok = level == 3 ? r[k].hit[0] == -2.0f
                               : std::fabs(r[k].hit[0] - (10.0f + float(level + 1))) < 1e-5f && r[k].ids[0] == k &&
                                     r[k].ids[1] == k;
    if (!ok && wrong++ < 5)
      ADD_FAILURE() << "ray " << k << " (level " << level << "): t " << r[k].hit[0] << ", custom index " << r[k].ids[0];
  }
  EXPECT_EQ(wrong, 0u);

  VkAccelerationStructureKHR doomed[2];
  for (auto& d : doomed) d = blas({triangles(kQuad, kQuadIndices, VK_GEOMETRY_OPAQUE_BIT_KHR)});
  for (uint32_t k = 150000; k < 150003; ++k) instances[k].accelerationStructureReference = addressOf(doomed[0]);
  instances[190000].accelerationStructureReference = addressOf(doomed[1]);
  const uint64_t first = instances[150000].accelerationStructureReference;
  for (VkAccelerationStructureKHR d : doomed) {
    destroyAs(device, d, nullptr);
    structures.erase(std::find(structures.begin(), structures.end(), d));
  }
  clearMessages();
  tlas(instances);
  char address[32];
  std::snprintf(address, sizeof address, "0x%llx", (unsigned long long)first);
  expectReport("VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-06707", {"instance 150000 ", address, "destroyed"});
}

// traceRayEXT through hundreds of top levels in one launch, each launch index choosing one by address: the launch
// resolves each address once (exec's TopLevelResolver), and rays take no lock, make no hash lookup and allocate
// nothing however many structures there are (before, past the 16th address of a launch every ray took two locks, a
// hash lookup and appended a reference to a list that grew with every ray). Every pixel is checked against the
// structure its index chose; a bottom-level address and a wild one among them miss, reported once per launch; the
// resident memory is checked over three launches of 2^18 rays.
TEST_F(TraceMisuseTest, HundredsOfTopLevelsInOneLaunchResolveOnceEach) {
  constexpr uint32_t kLevels = 300, kSide = 512;
  std::vector<uint64_t> words = {kLevels};  // count, pad (as one 64-bit word), then the addresses
  for (uint32_t k = 0; k < kLevels; ++k) words.push_back(addressOf(tlas({instance(quad, 0, 0, float(k % 5), k + 1)})));
  words[1 + 100] = addressOf(quad);  // a bottom level: no top level there
  words[1 + 200] = 0x1234560;        // nothing at all
  ASSERT_LE(words.size() * 8, spheres.size);
  std::memcpy(spheres.data, words.data(), words.size() * 8);  // binding 2 of the scene layout
  Desc d = basicDesc();
  d.stages[0].module = module(kSpv_trace_many_raygen_rgen, sizeof kSpv_trace_many_raygen_rgen);
  VkPipeline p = make(d);
  Sbt s = sbt(p, 3, {0}, {{1, {7}}}, {{2, {100}}});
  HostBuffer& out = buffer(sizeof(TracePayload) * kSide * kSide, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  VkWriteDescriptorSetAccelerationStructureKHR asw{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_KHR};
  asw.accelerationStructureCount = 1;
  asw.pAccelerationStructures = &top;
  VkDescriptorSet set = sceneSet(pool, setLayout, VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, &asw, out);
  uint64_t afterFirst = 0;
  for (int round = 0; round < 3; ++round) {
    std::memset(out.data, 0xee, out.size);
    VkCommandBuffer cb = beginOneTime();
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, p);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, traceLayout, 0, 1, &set, 0, nullptr);
    cmdTrace(cb, &s.raygen, &s.miss, &s.hit, &s.callable, kSide, kSide, 1);
    submitAndWait(cb);
    const auto* r = static_cast<const TracePayload*>(out.data);
    size_t wrong = 0, hits = 0;
    for (uint32_t i = 0; i < kSide * kSide; ++i) {
      const uint32_t k = uint32_t((uint64_t(i) * 7919u) % kLevels);
      const float x = cellCentre(i % kSide, kSide), y = cellCentre(i / kSide, kSide);
      const bool hit = k != 100 && k != 200 && std::fabs(x) < 1 && std::fabs(y) < 1;
      hits += hit;
      const bool ok =
          hit ? r[i].ids[0] == k + 1 && std::fabs(r[i].hit[0] - (10.0f + float(k % 5))) < 1e-4f && r[i].extra[0] == 100u
              : r[i].hit[0] == -2.0f && r[i].extra[0] == 7u;
      if (!ok && ++wrong <= 5)
        ADD_FAILURE() << "launch index " << i << " (structure " << k << "): t " << r[i].hit[0] << ", custom index "
                      << r[i].ids[0] << (hit ? ", expected a hit" : ", expected a miss");
    }
    EXPECT_EQ(wrong, 0u) << "round " << round;
    EXPECT_GT(hits, kSide * kSide / 5) << "round " << round;
    expectReport(nullptr, {"not the address of a built top-level acceleration structure", "those rays miss"});
    if (round == 0) afterFirst = residentBytes();
  }
  vkFreeDescriptorSets(device, pool, 1, &set);
  // Two more launches of 2^18 rays, 95% of them on structures past the 16th: at 10 bytes a ray they took 5 MB;
  // nothing grows per ray now (the bound leaves room for the allocator's own variation).
  const uint64_t growth = residentBytes() - std::min(afterFirst, residentBytes());
  EXPECT_LT(growth, 2u << 20) << "resident memory grew by " << growth << " bytes over two launches";
}

// The infos of one build command build distinct structures: the same destination twice
// (VUID-vkCmdBuildAccelerationStructuresKHR-dstAccelerationStructure-03698) or an update whose source is another
// info's destination (-pInfos-03403) is reported, naming both infos, and the command records nothing; distinct
// infos, an update in place among them, are not reported and build. (The check sorts the infos once: a command of
// a million infos, as the CTS's build.*_1048576 cases record, took minutes when it compared every pair.)
TEST_F(TraceMisuseTest, OneCommandsInfosBuildDistinctStructures) {
  const Geometry g = triangles(kQuad, kQuadIndices, VK_GEOMETRY_OPAQUE_BIT_KHR);
  const VkBuildAccelerationStructureFlagsKHR flags = VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR;
  const VkAccelerationStructureKHR built = build(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {g}, flags);
  auto fresh = [&] {
    VkAccelerationStructureCreateInfoKHR ci = storageOf[built];
    ci.buffer = buffer(ci.size, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR).buffer;
    VkAccelerationStructureKHR as = VK_NULL_HANDLE;
    EXPECT_EQ(createAs(device, &ci, nullptr, &as), VK_SUCCESS);
    structures.push_back(as);
    return as;
  };
  const VkAccelerationStructureKHR a = fresh(), b = fresh(), c = fresh();
  HostBuffer& scratch = buffer(4096, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  const VkDeviceAddress scratchAt = (addressOf(scratch) + 255) / 256 * 256;
  const VkAccelerationStructureBuildRangeInfoKHR range{g.primitives, 0, 0, 0};
  // (destination, source): a source makes the info an update.
  auto record = [&](std::vector<std::pair<VkAccelerationStructureKHR, VkAccelerationStructureKHR>> list) {
    std::vector<VkAccelerationStructureBuildGeometryInfoKHR> infos;
    for (size_t i = 0; i < list.size(); ++i) {
      VkAccelerationStructureBuildGeometryInfoKHR info{
          VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
      info.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
      info.flags = flags;
      info.mode = list[i].second ? VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR
                                 : VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
      info.srcAccelerationStructure = list[i].second;
      info.dstAccelerationStructure = list[i].first;
      info.geometryCount = 1;
      info.pGeometries = &g.geometry;
      info.scratchData.deviceAddress = scratchAt + 256 * i;
      infos.push_back(info);
    }
    std::vector<const VkAccelerationStructureBuildRangeInfoKHR*> ranges(list.size(), &range);
    VkCommandBuffer cb = beginOneTime();
    cmdBuild(cb, uint32_t(infos.size()), infos.data(), ranges.data());
    submitAndWait(cb);
  };
  clearMessages();
  record({{a, VK_NULL_HANDLE}, {b, VK_NULL_HANDLE}, {a, VK_NULL_HANDLE}});
  expectReport("VUID-vkCmdBuildAccelerationStructuresKHR-dstAccelerationStructure-03698",
               {"pInfos[0] and pInfos[2]", "the same dstAccelerationStructure"});
  record({{c, VK_NULL_HANDLE}, {b, built}, {built, VK_NULL_HANDLE}});
  expectReport("VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03403",
               {"pInfos[1].srcAccelerationStructure is pInfos[2].dstAccelerationStructure"});
  // Nothing of either command was built: a top level over `c` is refused (not built) and its rays miss.
  VkAccelerationStructureKHR none = tlas({instance(c, 0, 0, 5)});
  EXPECT_FALSE(vkrtMessages().empty()) << "an instance of a structure never built is reported";
  clearMessages();
  VkPipeline p = basic();
  Sbt s = sbt(p, 3, {0}, {{1, {7}}}, {{2, {100}}});
  std::vector<TracePayload> r = trace(p, s, none, 4, 4);
  clearMessages();
  EXPECT_EQ(r[5].hit[0], -2.0f);
  // Distinct destinations, an update reading a structure no info writes, and an update in place (its source is its
  // own destination): no report, all built.
  record({{a, VK_NULL_HANDLE}, {b, built}, {c, VK_NULL_HANDLE}});
  record({{c, VK_NULL_HANDLE}, {built, built}});
  EXPECT_TRUE(vkrtMessages().empty()) << vkrtMessages()[0].text;
  for (VkAccelerationStructureKHR as : {a, b, c, built}) {
    r = trace(p, s, tlas({instance(as, 0, 0, 5, 3)}), 4, 4);
    EXPECT_TRUE(vkrtMessages().empty());
    EXPECT_EQ(r[5].ids[0], 3u) << "the instance's custom index: the structure was built";
  }
}

// A host build of small bottom levels with a deferred operation builds at once and returns
// VK_OPERATION_NOT_DEFERRED_KHR (nothing to join; the operation's result is VK_SUCCESS), as the specification allows:
// the CTS's build.cpuht_* cases start threads to join every structure's operation, a million in the largest, and
// none for a build not deferred. A bottom level of 17 primitives and a top level are deferred to the joining threads.
// All of them trace the scene their inputs describe. An operation still running a command is refused for the next
// one either way (VUID-vkBuildAccelerationStructuresKHR-deferredOperation-03678), and valid use is not reported.
TEST_F(TraceMisuseTest, SmallHostBuildsRunAtOnceLargerOnesAreDeferred) {
  if (!asf.accelerationStructureHostCommands) GTEST_SKIP() << "accelerationStructureHostCommands is not supported";
  PFN_vkBuildAccelerationStructuresKHR hostBuild = nullptr;
  load(hostBuild, "vkBuildAccelerationStructuresKHR");
  // `triangles` triangles: quads of the unit quad's size side by side along x (the first one is kQuad).
  auto trianglesGeometry = [](std::vector<float>& vertices, std::vector<uint32_t>& indices, uint32_t triangles) {
    for (uint32_t q = 0; q < (triangles + 1) / 2; ++q)
      for (size_t v = 0; v < kQuad.size(); v += 3) {
        const float p[3] = {kQuad[v] + 2.0f * float(q), kQuad[v + 1], kQuad[v + 2]};
        vertices.insert(vertices.end(), p, p + 3);
      }
    for (uint32_t t = 0; t < triangles; ++t)
      for (int k = 0; k < 3; ++k) indices.push_back(4 * (t / 2) + kQuadIndices[3 * (t % 2) + k]);
    VkAccelerationStructureGeometryKHR g = opaqueTriangles(uint32_t(vertices.size() / 3 - 1), VK_INDEX_TYPE_UINT32);
    g.geometry.triangles.vertexData.hostAddress = vertices.data();
    g.geometry.triangles.indexData.hostAddress = indices.data();
    return g;
  };
  std::vector<uint8_t> scratch(4096);
  // Starts a host build of `g` (`primitives`) into a new structure of `type` with `op`; returns what it returned.
  auto start = [&](VkAccelerationStructureTypeKHR type, const VkAccelerationStructureGeometryKHR& g,
                   uint32_t primitives, VkDeferredOperationKHR op, VkAccelerationStructureKHR* as) {
    VkAccelerationStructureBuildGeometryInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
    info.type = type;
    info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
    info.geometryCount = 1;
    info.pGeometries = &g;
    VkAccelerationStructureCreateInfoKHR ci{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
    ci.size = 65536;
    ci.buffer = buffer(ci.size, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR).buffer;
    ci.type = type;
    EXPECT_EQ(createAs(device, &ci, nullptr, as), VK_SUCCESS);
    structures.push_back(*as);
    info.dstAccelerationStructure = *as;
    info.scratchData.hostAddress = scratch.data();
    const VkAccelerationStructureBuildRangeInfoKHR range{primitives, 0, 0, 0};
    const VkAccelerationStructureBuildRangeInfoKHR* pr = &range;
    return hostBuild(device, op, 1, &info, &pr);
  };
  auto join = [&](VkDeferredOperationKHR op) {
    while (joinOp(device, op) != VK_SUCCESS) {
    }
    EXPECT_EQ(opResult(device, op), VK_SUCCESS);
  };
  VkDeferredOperationKHR op = VK_NULL_HANDLE;
  ASSERT_EQ(createOp(device, nullptr, &op), VK_SUCCESS);
  std::vector<float> smallVertices, largeVertices, refusedVertices;
  std::vector<uint32_t> smallIndices, largeIndices, refusedIndices;
  VkAccelerationStructureKHR small = VK_NULL_HANDLE, large = VK_NULL_HANDLE, top = VK_NULL_HANDLE;
  clearMessages();
  EXPECT_EQ(start(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, trianglesGeometry(smallVertices, smallIndices, 16),
                  16, op, &small),
            VK_OPERATION_NOT_DEFERRED_KHR);
  EXPECT_EQ(opResult(device, op), VK_SUCCESS);
  EXPECT_EQ(start(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, trianglesGeometry(largeVertices, largeIndices, 17),
                  17, op, &large),
            VK_OPERATION_DEFERRED_KHR);
  join(op);
  // The top level (instances by handle, as host builds take them): the small one at z 5, the large one at z 7.
  std::vector<VkAccelerationStructureInstanceKHR> instances = {instance(small, 0, 0, 5, 1),
                                                               instance(large, 0, 0, 7, 2)};
  instances[0].accelerationStructureReference = reinterpret_cast<uint64_t>(small);
  instances[1].accelerationStructureReference = reinterpret_cast<uint64_t>(large);
  instances[1].mask = 0;  // (seen by no ray: the launch below sees the small one; the large one is checked after)
  VkAccelerationStructureGeometryKHR ig{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
  ig.geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;
  ig.geometry.instances.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR;
  ig.geometry.instances.data.hostAddress = instances.data();
  EXPECT_EQ(start(VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, ig, 2, op, &top), VK_OPERATION_DEFERRED_KHR);
  // The operation still runs the top level's build (nobody joined): a small build with it is refused.
  VkAccelerationStructureKHR refused = VK_NULL_HANDLE;
  EXPECT_EQ(start(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR,
                  trianglesGeometry(refusedVertices, refusedIndices, 2), 2, op, &refused),
            VK_ERROR_VALIDATION_FAILED_EXT);
  expectReport("VUID-vkBuildAccelerationStructuresKHR-deferredOperation-03678", {"still running a previous command"});
  join(op);
  EXPECT_TRUE(vkrtMessages().empty());
  VkPipeline p = basic();
  Sbt s = sbt(p, 3, {0}, {{1, {7}}}, {{2, {100}}});
  std::vector<TracePayload> r = trace(p, s, top, 4, 4);
  EXPECT_EQ(r[5].ids[0], 1u) << "the small structure, built at once, is hit";
  instances[0].mask = 0;
  instances[1].mask = 0xff;
  EXPECT_EQ(start(VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, ig, 2, VK_NULL_HANDLE, &top), VK_SUCCESS);
  r = trace(p, s, top, 4, 4);
  EXPECT_EQ(r[5].ids[0], 2u) << "the large structure, deferred and joined, is hit";
  EXPECT_TRUE(vkrtMessages().empty());
  destroyOp(device, op, nullptr);
}

}  // namespace
}  // namespace vkrt::test
