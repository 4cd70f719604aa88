// The tracing e2e fixture (TraceTest): RtTest's device (with VK_KHR_acceleration_structure), helpers that build
// bottom- and top-level acceleration structures on the device (or the host), write a shader binding table from
// group handles, and trace a launch whose results (one TracePayload per launch index, tests/shaders/trace_*.r*)
// come back to the test. Everything goes through the public API, so the tests of Vulkan behaviour run on other
// drivers too (NVIDIA's); the validation layer is on.
#pragma once

#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <deque>
#include <map>
#include <string>
#include <vector>

#include "e2e/rt_fixture.hpp"
#include "trace_ahit.rahit.spv.h"
#include "trace_chit.rchit.spv.h"
#include "trace_miss.rmiss.spv.h"
#include "trace_raygen.rgen.spv.h"
#include "trace_sphere.rint.spv.h"

namespace vkrt::test {

// tests/shaders/trace_payload.glsl
struct TracePayload {
  float hit[4];
  uint32_t ids[4];
  uint32_t extra[4];
};
static_assert(sizeof(TracePayload) == 48);

// tests/shaders/trace_raygen.rgen's push constants.
struct TraceParams {
  uint32_t rayFlags = 0, cullMask = 0xff, sbtOffset = 0, sbtStride = 1, missIndex = 0;
  float originZ = -10, dirZ = 1, tmax = 100;
};

// A shader binding table record: a group of the pipeline and the data after its handle.
struct SbtRecord {
  int32_t group = -1;  // -1: a zero (null) handle
  std::vector<uint32_t> data;
};

// A unit quad over [-1, 1]^2 in the plane z = 0: triangle 0 = (v0, v1, v2), triangle 1 = (v2, v1, v3), both with
// the normal cross(v1 - v0, v2 - v0) = +z.
inline const std::vector<float> kQuad = {-1, -1, 0, 1, -1, 0, -1, 1, 0, 1, 1, 0};
inline const std::vector<uint32_t> kQuadIndices = {0, 1, 2, 2, 1, 3};

// The expected hit of a ray along +z through the quad at object (px, py): primitive and barycentrics.
struct QuadHit {
  uint32_t primitive;
  float u, v;
};
inline QuadHit quadHit(float px, float py) {
  if (px + py <= 0) return {0, (px + 1) / 2, (py + 1) / 2};
  float u = (1 - py) / 2;
  return {1, u, (px + 1) / 2 - u};
}

// The launch's ray origins: an 8 x 8 grid of cell centres over [-2, 2]^2 (trace_raygen.rgen).
inline float cellCentre(uint32_t i, uint32_t n) { return (float(i) + 0.5f) / float(n) * 4.0f - 2.0f; }

// The spheres-in-boxes scene (two spheres of radius 0.5 at (-1, -1, 5) and (1, 1, 7) in world space, found by the
// sphere intersection shader, hit group record data 300, instance custom index 9) seen by an n x n launch from
// z = -10: each payload against the analytic hit, or a miss (-2). `attributeY`: the KHR scene's shader also reports
// 0.5 as the attribute's y.
inline void expectSpheresInBoxes(const std::vector<TracePayload>& r, uint32_t n, bool attributeY) {
  int hits = 0;
  for (uint32_t y = 0; y < n; ++y)
    for (uint32_t x = 0; x < n; ++x) {
      SCOPED_TRACE("pixel " + std::to_string(x) + "," + std::to_string(y));
      const float wx = cellCentre(x, n), wy = cellCentre(y, n);
      const TracePayload& q = r[y * n + x];
      int prim = -1;
      float t = 0;
      const float centres[2][3] = {{-1, -1, 5}, {1, 1, 7}};  // world space (instance moved +1 along z)
      for (int k = 0; k < 2; ++k) {
        float dx = wx - centres[k][0], dy = wy - centres[k][1], r2 = dx * dx + dy * dy;
        if (r2 < 0.25f) {
          prim = k;
          t = centres[k][2] - std::sqrt(0.25f - r2) + 10;  // from z = -10
        }
      }
      if (prim < 0) {
        EXPECT_EQ(q.hit[0], -2.0f);
        continue;
      }
      ++hits;
      EXPECT_NEAR(q.hit[0], t, 1e-3f);
      EXPECT_EQ(q.hit[1], float(prim)) << "hit attribute x";
      if (attributeY) {
        EXPECT_EQ(q.hit[2], 0.5f);
      }
      EXPECT_EQ(q.hit[3], 5.0f) << "the hit kind the intersection shader reported";
      EXPECT_EQ(q.ids[2], uint32_t(prim));
      EXPECT_EQ(q.ids[0], 9u);
      EXPECT_EQ(q.extra[0], 300u);
    }
  EXPECT_GT(hits, 4);
}

// The process's resident memory in bytes (/proc/self/statm), for the tests that check that work does not grow it.
inline uint64_t residentBytes() {
  long pages = 0, resident = 0;
  FILE* f = std::fopen("/proc/self/statm", "r");
  if (f) {
    if (std::fscanf(f, "%ld %ld", &pages, &resident) != 2) resident = 0;
    std::fclose(f);
  }
  return uint64_t(resident) * 4096;
}

class TraceTest : public RtTest {
 protected:
  VkPhysicalDeviceRayTracingPipelinePropertiesKHR rtProps{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_PROPERTIES_KHR};

  FixtureOptions options() override {
    FixtureOptions o = RtTest::options();
    rtf.rayTraversalPrimitiveCulling = supportedRt.rayTraversalPrimitiveCulling;
    asf.accelerationStructureHostCommands = supportedAs.accelerationStructureHostCommands;
    asf.accelerationStructureIndirectBuild = supportedAs.accelerationStructureIndirectBuild;
    return o;
  }

  // A set of the scene layout (makeTraceLayout) from `fromPool`: the structure written through `structureWrite`
  // (a VkWriteDescriptorSetAccelerationStructureKHR or ...NV for `asType`), `out` and the spheres buffer.
  VkDescriptorSet sceneSet(VkDescriptorPool fromPool, VkDescriptorSetLayout layout, VkDescriptorType asType,
                           const void* structureWrite, const HostBuffer& out) {
    VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    ai.descriptorPool = fromPool;
    ai.descriptorSetCount = 1;
    ai.pSetLayouts = &layout;
    VkDescriptorSet set = VK_NULL_HANDLE;
    EXPECT_EQ(vkAllocateDescriptorSets(device, &ai, &set), VK_SUCCESS);
    VkDescriptorBufferInfo bo{out.buffer, 0, VK_WHOLE_SIZE}, bs{spheres.buffer, 0, VK_WHOLE_SIZE};
    VkWriteDescriptorSet w[3] = {{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, structureWrite},
                                 {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET},
                                 {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET}};
    for (uint32_t i = 0; i < 3; ++i) {
      w[i].dstSet = set;
      w[i].dstBinding = i;
      w[i].descriptorCount = 1;
    }
    w[0].descriptorType = asType;
    w[1].descriptorType = w[2].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    w[1].pBufferInfo = &bo;
    w[2].pBufferInfo = &bs;
    vkUpdateDescriptorSets(device, 3, w, 0, nullptr);
    return set;
  }

  // The scene shaders' layout (binding 0: the structure, as `asType`; 1, 2: storage buffers; raygen push constants:
  // TraceParams) and a pool for their sets; the NV tests use it with the NV descriptor type.
  void makeTraceLayout(VkDescriptorType asType, VkDescriptorSetLayout* setLayoutOut, VkPipelineLayout* layoutOut,
                       VkDescriptorPool* poolOut) {
    VkDescriptorSetLayoutBinding b[3] = {
        {0, asType, 1, kRtStages, nullptr},
        {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, kRtStages, nullptr},
        {2, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, kRtStages, nullptr},
    };
    VkDescriptorSetLayoutCreateInfo dl{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    dl.bindingCount = 3;
    dl.pBindings = b;
    ASSERT_EQ(vkCreateDescriptorSetLayout(device, &dl, nullptr, setLayoutOut), VK_SUCCESS);
    VkPushConstantRange pc{VK_SHADER_STAGE_RAYGEN_BIT_KHR, 0, sizeof(TraceParams)};
    VkPipelineLayoutCreateInfo lci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    lci.setLayoutCount = 1;
    lci.pSetLayouts = setLayoutOut;
    lci.pushConstantRangeCount = 1;
    lci.pPushConstantRanges = &pc;
    ASSERT_EQ(vkCreatePipelineLayout(device, &lci, nullptr, layoutOut), VK_SUCCESS);
    VkDescriptorPoolSize sizes[2] = {{asType, 4}, {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 8}};
    VkDescriptorPoolCreateInfo pci{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    pci.flags = VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT;
    pci.maxSets = 4;
    pci.poolSizeCount = 2;
    pci.pPoolSizes = sizes;
    ASSERT_EQ(vkCreateDescriptorPool(device, &pci, nullptr, poolOut), VK_SUCCESS);
  }

  void SetUp() override {
    // (RtTest::querySupport reads the acceleration structure features the driver has: host commands, vkrt yes,
    // NVIDIA no.)
    RtTest::SetUp();
    if (HasFatalFailure() || !device) return;
    VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &rtProps};
    vkGetPhysicalDeviceProperties2(physicalDevice, &p2);
    load(createAs, "vkCreateAccelerationStructureKHR");
    load(destroyAs, "vkDestroyAccelerationStructureKHR");
    load(buildSizes, "vkGetAccelerationStructureBuildSizesKHR");
    load(cmdBuild, "vkCmdBuildAccelerationStructuresKHR");
    load(asAddress, "vkGetAccelerationStructureDeviceAddressKHR");
    load(cmdTrace, "vkCmdTraceRaysKHR");
    makeTraceLayout(VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, &setLayout, &traceLayout, &pool);
    if (HasFatalFailure()) return;
    rgen = module(kSpv_trace_raygen_rgen, sizeof kSpv_trace_raygen_rgen);
    tchit = module(kSpv_trace_chit_rchit, sizeof kSpv_trace_chit_rchit);
    tmiss = module(kSpv_trace_miss_rmiss, sizeof kSpv_trace_miss_rmiss);
    tahit = module(kSpv_trace_ahit_rahit, sizeof kSpv_trace_ahit_rahit);
    tsphere = module(kSpv_trace_sphere_rint, sizeof kSpv_trace_sphere_rint);
    spheres = createHostBuffer(4096, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  }

  void TearDown() override {
    if (device) {
      vkDeviceWaitIdle(device);
      for (auto& s : structures) destroyAs(device, s, nullptr);
      for (auto& b : buffers) destroy(b);
      destroy(spheres);
      if (pool) vkDestroyDescriptorPool(device, pool, nullptr);
      if (traceLayout) vkDestroyPipelineLayout(device, traceLayout, nullptr);
      if (setLayout) vkDestroyDescriptorSetLayout(device, setLayout, nullptr);
    }
    RtTest::TearDown();
  }

  static constexpr VkShaderStageFlags kRtStages =
      VK_SHADER_STAGE_RAYGEN_BIT_KHR | VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR | VK_SHADER_STAGE_MISS_BIT_KHR |
      VK_SHADER_STAGE_ANY_HIT_BIT_KHR | VK_SHADER_STAGE_INTERSECTION_BIT_KHR | VK_SHADER_STAGE_CALLABLE_BIT_KHR;

  // A buffer with a device address, kept until the test ends.
  HostBuffer& buffer(VkDeviceSize size, VkBufferUsageFlags usage) {
    buffers.push_back(createHostBuffer(size, usage, true));
    return buffers.back();
  }
  VkDeviceAddress addressOf(const HostBuffer& b) {
    VkBufferDeviceAddressInfo i{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO};
    i.buffer = b.buffer;
    return vkGetBufferDeviceAddress(device, &i);
  }
  template <class T>
  VkDeviceAddress upload(const std::vector<T>& data) {
    HostBuffer& b = buffer(
        std::max<size_t>(64, data.size() * sizeof(T)),
        VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    std::memcpy(b.data, data.data(), data.size() * sizeof(T));
    return addressOf(b);
  }

  struct Geometry {
    VkAccelerationStructureGeometryKHR geometry{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
    uint32_t primitives = 0;
  };
  // Triangles, float3 vertices, 32-bit indices.
  Geometry triangles(const std::vector<float>& vertices, const std::vector<uint32_t>& indices,
                     VkGeometryFlagsKHR flags) {
    Geometry g;
    g.geometry.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
    g.geometry.flags = flags;
    auto& t = g.geometry.geometry.triangles;
    t.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
    t.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
    t.vertexData.deviceAddress = upload(vertices);
    t.vertexStride = 12;
    t.maxVertex = uint32_t(vertices.size() / 3 - 1);
    t.indexType = VK_INDEX_TYPE_UINT32;
    t.indexData.deviceAddress = upload(indices);
    g.primitives = uint32_t(indices.size() / 3);
    return g;
  }
  // An opaque triangle geometry of float3 vertices (stride 12) with `maxVertex` and `indexType`; its data addresses
  // are the caller's to set.
  static VkAccelerationStructureGeometryKHR opaqueTriangles(uint32_t maxVertex, VkIndexType indexType) {
    VkAccelerationStructureGeometryKHR g{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
    g.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
    g.flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
    auto& t = g.geometry.triangles;
    t.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
    t.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
    t.vertexStride = 12;
    t.maxVertex = maxVertex;
    t.indexType = indexType;
    return g;
  }
  Geometry aabbs(const std::vector<VkAabbPositionsKHR>& boxes, VkGeometryFlagsKHR flags) {
    Geometry g;
    g.geometry.geometryType = VK_GEOMETRY_TYPE_AABBS_KHR;
    g.geometry.flags = flags;
    auto& a = g.geometry.geometry.aabbs;
    a.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_AABBS_DATA_KHR;
    a.data.deviceAddress = upload(boxes);
    a.stride = sizeof(VkAabbPositionsKHR);
    g.primitives = uint32_t(boxes.size());
    return g;
  }

  // Builds (on the device) an acceleration structure of `type` from `geometries`; returns it.
  VkAccelerationStructureKHR build(
      VkAccelerationStructureTypeKHR type, const std::vector<Geometry>& geometries,
      VkBuildAccelerationStructureFlagsKHR flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR) {
    std::vector<VkAccelerationStructureGeometryKHR> gs;
    std::vector<uint32_t> counts;
    std::vector<VkAccelerationStructureBuildRangeInfoKHR> ranges;
    for (const Geometry& g : geometries) {
      gs.push_back(g.geometry);
      counts.push_back(g.primitives);
      ranges.push_back({g.primitives, 0, 0, 0});
    }
    VkAccelerationStructureBuildGeometryInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
    info.type = type;
    info.flags = flags;
    info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
    info.geometryCount = uint32_t(gs.size());
    info.pGeometries = gs.data();
    VkAccelerationStructureBuildSizesInfoKHR sizes{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
    buildSizes(device, VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &info, counts.data(), &sizes);
    HostBuffer& storage =
        buffer(sizes.accelerationStructureSize, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR);
    VkAccelerationStructureCreateInfoKHR ci{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
    ci.buffer = storage.buffer;
    ci.size = sizes.accelerationStructureSize;
    ci.type = type;
    VkAccelerationStructureKHR as = VK_NULL_HANDLE;
    EXPECT_EQ(createAs(device, &ci, nullptr, &as), VK_SUCCESS);
    structures.push_back(as);
    storageOf[as] = ci;
    HostBuffer& scratch = buffer(sizes.buildScratchSize + 256, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    info.dstAccelerationStructure = as;
    info.scratchData.deviceAddress = (addressOf(scratch) + 255) / 256 * 256;
    const VkAccelerationStructureBuildRangeInfoKHR* pr = ranges.data();
    VkCommandBuffer cb = beginOneTime();
    cmdBuild(cb, 1, &info, &pr);
    VkMemoryBarrier mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    mb.srcAccessMask = VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR;
    mb.dstAccessMask = VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_KHR;
    vkCmdPipelineBarrier(
        cb, VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
        VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR | VK_PIPELINE_STAGE_RAY_TRACING_SHADER_BIT_KHR, 0, 1,
        &mb, 0, nullptr, 0, nullptr);
    submitAndWait(cb);
    return as;
  }
  VkAccelerationStructureKHR blas(const std::vector<Geometry>& geometries) {
    return build(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, geometries);
  }
  VkDeviceAddress addressOf(VkAccelerationStructureKHR as) {
    VkAccelerationStructureDeviceAddressInfoKHR i{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR};
    i.accelerationStructure = as;
    return asAddress(device, &i);
  }
  // An instance of `blas` moved by (tx, ty, tz).
  VkAccelerationStructureInstanceKHR instance(VkAccelerationStructureKHR blas, float tx = 0, float ty = 0, float tz = 0,
                                              uint32_t customIndex = 0, uint32_t sbtOffset = 0, uint32_t mask = 0xff,
                                              VkGeometryInstanceFlagsKHR flags = 0) {
    VkAccelerationStructureInstanceKHR in{};
    in.transform.matrix[0][0] = in.transform.matrix[1][1] = in.transform.matrix[2][2] = 1;
    in.transform.matrix[0][3] = tx;
    in.transform.matrix[1][3] = ty;
    in.transform.matrix[2][3] = tz;
    in.instanceCustomIndex = customIndex;
    in.mask = mask;
    in.instanceShaderBindingTableRecordOffset = sbtOffset;
    in.flags = flags;
    in.accelerationStructureReference = blas ? addressOf(blas) : 0;
    return in;
  }
  VkAccelerationStructureKHR tlas(const std::vector<VkAccelerationStructureInstanceKHR>& instances) {
    Geometry g;
    g.geometry.geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;
    auto& d = g.geometry.geometry.instances;
    d.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR;
    d.arrayOfPointers = VK_FALSE;
    d.data.deviceAddress = upload(instances);
    g.primitives = uint32_t(instances.size());
    return build(VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, {g});
  }

  // The shader binding table: each region's records, laid out with the driver's alignments.
  struct Sbt {
    VkStridedDeviceAddressRegionKHR raygen{}, miss{}, hit{}, callable{};
  };
  Sbt sbt(VkPipeline p, uint32_t groupCount, const SbtRecord& raygenRecord, const std::vector<SbtRecord>& missRecords,
          const std::vector<SbtRecord>& hitRecords, const std::vector<SbtRecord>& callableRecords = {}) {
    return sbtFrom(handles(p, 0, groupCount), raygenRecord, missRecords, hitRecords, callableRecords);
  }
  // The same from handle bytes (groupCount x shaderGroupHandleSize) obtained elsewhere: a library, another process.
  Sbt sbtFrom(const std::vector<uint8_t>& h, const SbtRecord& raygenRecord, const std::vector<SbtRecord>& missRecords,
              const std::vector<SbtRecord>& hitRecords, const std::vector<SbtRecord>& callableRecords = {}) {
    const uint32_t hs = rtProps.shaderGroupHandleSize;
    auto align = [](uint64_t v, uint64_t a) { return (v + a - 1) / a * a; };
    auto strideOf = [&](const std::vector<SbtRecord>& rs) {
      size_t data = 0;
      for (const SbtRecord& r : rs) data = std::max(data, r.data.size() * 4);
      return align(hs + data, rtProps.shaderGroupHandleAlignment);
    };
    const std::vector<SbtRecord>* regions[4] = {nullptr, &missRecords, &hitRecords, &callableRecords};
    std::vector<SbtRecord> raygenVec{raygenRecord};
    regions[0] = &raygenVec;
    uint64_t offsets[4], strides[4], total = 0;
    for (int i = 0; i < 4; ++i) {
      strides[i] = strideOf(*regions[i]);
      if (i == 0) strides[i] = align(strides[i], rtProps.shaderGroupBaseAlignment);
      offsets[i] = align(total, rtProps.shaderGroupBaseAlignment);
      total = offsets[i] + strides[i] * regions[i]->size();
    }
    HostBuffer& b = buffer(total + rtProps.shaderGroupBaseAlignment, VK_BUFFER_USAGE_SHADER_BINDING_TABLE_BIT_KHR);
    const VkDeviceAddress base = align(addressOf(b), rtProps.shaderGroupBaseAlignment);
    uint8_t* bytes = static_cast<uint8_t*>(b.data) + (base - addressOf(b));
    std::memset(bytes, 0, total);
    Sbt s;
    VkStridedDeviceAddressRegionKHR* out[4] = {&s.raygen, &s.miss, &s.hit, &s.callable};
    for (int i = 0; i < 4; ++i) {
      for (size_t k = 0; k < regions[i]->size(); ++k) {
        const SbtRecord& r = (*regions[i])[k];
        uint8_t* rec = bytes + offsets[i] + k * strides[i];
        if (r.group >= 0) std::memcpy(rec, h.data() + size_t(r.group) * hs, hs);
        if (!r.data.empty()) std::memcpy(rec + hs, r.data.data(), r.data.size() * 4);
      }
      if (!regions[i]->empty()) *out[i] = {base + offsets[i], strides[i], strides[i] * regions[i]->size()};
    }
    return s;
  }

  // Traces a width x height launch of `p` over `tlas`; returns the payloads.
  // With `dynamicStackSize` >= 0, vkCmdSetRayTracingPipelineStackSizeKHR sets it (the pipeline must have the
  // dynamic state).
  std::vector<TracePayload> trace(VkPipeline p, const Sbt& s, VkAccelerationStructureKHR tlas, uint32_t width,
                                  uint32_t height, const TraceParams& params = {}, int64_t dynamicStackSize = -1) {
    HostBuffer& out = buffer(sizeof(TracePayload) * width * height, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    std::memset(out.data, 0xee, out.size);
    VkWriteDescriptorSetAccelerationStructureKHR asw{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_KHR};
    asw.accelerationStructureCount = 1;
    asw.pAccelerationStructures = &tlas;
    VkDescriptorSet set = sceneSet(pool, setLayout, VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, &asw, out);
    VkCommandBuffer cb = beginOneTime();
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, p);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, traceLayout, 0, 1, &set, 0, nullptr);
    vkCmdPushConstants(cb, traceLayout, VK_SHADER_STAGE_RAYGEN_BIT_KHR, 0, sizeof params, &params);
    if (dynamicStackSize >= 0) {
      auto setStack = reinterpret_cast<PFN_vkCmdSetRayTracingPipelineStackSizeKHR>(
          vkGetDeviceProcAddr(device, "vkCmdSetRayTracingPipelineStackSizeKHR"));
      setStack(cb, uint32_t(dynamicStackSize));
    }
    cmdTrace(cb, &s.raygen, &s.miss, &s.hit, &s.callable, width, height, 1);
    submitAndWait(cb);
    vkFreeDescriptorSets(device, pool, 1, &set);
    std::vector<TracePayload> r(width * height);
    std::memcpy(r.data(), out.data, r.size() * sizeof(TracePayload));
    return r;
  }

  // The basic scene: a quad instanced twice: instance 0 at z = 5, moved 0.1 along x (so that no ray runs along its
  // diagonal), custom index 10, SBT offset 0; instance 1 at z = 2 and x + 1.6, custom index 20, SBT offset 1.
  VkAccelerationStructureKHR basicScene() {
    VkAccelerationStructureKHR quad = blas({triangles(kQuad, kQuadIndices, VK_GEOMETRY_OPAQUE_BIT_KHR)});
    return tlas({instance(quad, 0.1f, 0, 5, 10, 0), instance(quad, 1.6f, 0, 2, 20, 1)});
  }
  // raygen, miss, a triangle hit group with trace_chit: traced with sbt(p, 3, {0}, {{1, {7}}}, {{2, {100}}, {2,
  // {101}}}).
  Desc basicDesc(VkPipelineCreateFlags flags = 0) {
    Desc d;
    d.layout = traceLayout;
    d.flags = flags;
    d.general(rgen, VK_SHADER_STAGE_RAYGEN_BIT_KHR);
    d.general(tmiss, VK_SHADER_STAGE_MISS_BIT_KHR);
    d.group(VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR, VK_SHADER_UNUSED_KHR,
            d.stage(tchit, VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR));
    return d;
  }
  // Checks an n x n launch over the basic scene against the hits computed from its geometry.
  void expectBasicScene(const std::vector<TracePayload>& r, uint32_t n) {
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

  // The spheres trace_sphere.rint intersects (object-space centre and radius per primitive).
  void setSpheres(const std::vector<std::array<float, 4>>& s) { std::memcpy(spheres.data, s.data(), s.size() * 16); }

  PFN_vkCreateAccelerationStructureKHR createAs = nullptr;
  PFN_vkDestroyAccelerationStructureKHR destroyAs = nullptr;
  PFN_vkGetAccelerationStructureBuildSizesKHR buildSizes = nullptr;
  PFN_vkCmdBuildAccelerationStructuresKHR cmdBuild = nullptr;
  PFN_vkGetAccelerationStructureDeviceAddressKHR asAddress = nullptr;
  PFN_vkCmdTraceRaysKHR cmdTrace = nullptr;
  VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;
  VkPipelineLayout traceLayout = VK_NULL_HANDLE;
  VkDescriptorPool pool = VK_NULL_HANDLE;
  VkShaderModule rgen{}, tchit{}, tmiss{}, tahit{}, tsphere{};
  HostBuffer spheres;
  std::deque<HostBuffer> buffers;  // a deque: references returned by buffer() stay valid
  std::vector<VkAccelerationStructureKHR> structures;
  std::map<VkAccelerationStructureKHR, VkAccelerationStructureCreateInfoKHR> storageOf;  // how build() created each
};

}  // namespace vkrt::test
