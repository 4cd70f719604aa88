// VK_NV_ray_tracing through the loader with the validation layer on: NV acceleration structures (created, bound to
// memory, built, compacted, cloned, referred to by their 8-byte handles), NV pipelines (with deferred compilation)
// and vkCmdTraceRaysNV trace the basic scene of the KHR tests, with GL_NV_ray_tracing shaders, to the payloads the
// scene's geometry gives and to the very bytes the KHR path gives. On vkrt, a group's NV handle is its KHR handle.
// NvMisuseTest (layer off, vkrt only) asserts vkrt's reports of NV misuse by VUID; NvRayTreeTest, the ray tree of
// a launch id of vkCmdTraceRaysNV (VKRT_RAY_TREE).
#include <fstream>

#include "e2e/trace_fixture.hpp"
#include "trace_nv_chit.rchit.spv.h"
#include "trace_nv_miss.rmiss.spv.h"
#include "trace_nv_raygen.rgen.spv.h"
#include "trace_nv_sphere.rint.spv.h"

namespace vkrt::test {
namespace {

// Every command VK_NV_ray_tracing adds.
const char* const kNvCommands[] = {
    "vkCreateAccelerationStructureNV",
    "vkDestroyAccelerationStructureNV",
    "vkGetAccelerationStructureMemoryRequirementsNV",
    "vkBindAccelerationStructureMemoryNV",
    "vkCmdBuildAccelerationStructureNV",
    "vkCmdCopyAccelerationStructureNV",
    "vkCmdTraceRaysNV",
    "vkCreateRayTracingPipelinesNV",
    "vkGetRayTracingShaderGroupHandlesNV",
    "vkGetAccelerationStructureHandleNV",
    "vkCmdWriteAccelerationStructuresPropertiesNV",
    "vkCompileDeferredNV",
};

class NvTraceTest : public TraceTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o = TraceTest::options();
    o.deviceExtensions.push_back(VK_NV_RAY_TRACING_EXTENSION_NAME);
    o.deviceExtensions.push_back(VK_KHR_GET_MEMORY_REQUIREMENTS_2_EXTENSION_NAME);  // VK_NV_ray_tracing requires it
    return o;
  }

  void SetUp() override {
    TraceTest::SetUp();
    if (HasFatalFailure() || !device) return;
    VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &nvProps};
    vkGetPhysicalDeviceProperties2(physicalDevice, &p2);
    load(createNv, "vkCreateAccelerationStructureNV");
    load(destroyNv, "vkDestroyAccelerationStructureNV");
    load(memReqNv, "vkGetAccelerationStructureMemoryRequirementsNV");
    load(bindNv, "vkBindAccelerationStructureMemoryNV");
    load(buildNv, "vkCmdBuildAccelerationStructureNV");
    load(copyNv, "vkCmdCopyAccelerationStructureNV");
    load(traceNv, "vkCmdTraceRaysNV");
    load(pipelinesNv, "vkCreateRayTracingPipelinesNV");
    load(handlesNv, "vkGetRayTracingShaderGroupHandlesNV");
    load(asHandleNv, "vkGetAccelerationStructureHandleNV");
    load(writePropsNv, "vkCmdWriteAccelerationStructuresPropertiesNV");
    load(compileDeferredNv, "vkCompileDeferredNV");
    makeTraceLayout(VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_NV, &nvSetLayout, &nvLayout, &nvPool);
    if (HasFatalFailure()) return;
    nvRgen = module(kSpv_trace_nv_raygen_rgen, sizeof kSpv_trace_nv_raygen_rgen);
    nvMiss = module(kSpv_trace_nv_miss_rmiss, sizeof kSpv_trace_nv_miss_rmiss);
    nvChit = module(kSpv_trace_nv_chit_rchit, sizeof kSpv_trace_nv_chit_rchit);
    nvSphere = module(kSpv_trace_nv_sphere_rint, sizeof kSpv_trace_nv_sphere_rint);
  }

  void TearDown() override {
    if (device) {
      vkDeviceWaitIdle(device);
      for (VkAccelerationStructureNV s : nvStructures) destroyNv(device, s, nullptr);
      for (VkDeviceMemory m : nvMemory) vkFreeMemory(device, m, nullptr);
      if (nvPool) vkDestroyDescriptorPool(device, nvPool, nullptr);
      if (nvLayout) vkDestroyPipelineLayout(device, nvLayout, nullptr);
      if (nvSetLayout) vkDestroyDescriptorSetLayout(device, nvSetLayout, nullptr);
    }
    TraceTest::TearDown();
  }

  // A buffer the NV commands read (geometry, instances, scratch, shader binding tables).
  HostBuffer& nvBuffer(VkDeviceSize size) {
    return buffer(std::max<VkDeviceSize>(size, 64),
                  VK_BUFFER_USAGE_RAY_TRACING_BIT_NV | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  }
  template <class T>
  VkBuffer nvUpload(const std::vector<T>& data) {
    HostBuffer& b = nvBuffer(data.size() * sizeof(T));
    std::memcpy(b.data, data.data(), data.size() * sizeof(T));
    return b.buffer;
  }

  VkMemoryRequirements requirements(VkAccelerationStructureNV as, VkAccelerationStructureMemoryRequirementsTypeNV t) {
    VkAccelerationStructureMemoryRequirementsInfoNV ri{
        VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_MEMORY_REQUIREMENTS_INFO_NV};
    ri.type = t;
    ri.accelerationStructure = as;
    VkMemoryRequirements2 r{VK_STRUCTURE_TYPE_MEMORY_REQUIREMENTS_2};
    memReqNv(device, &ri, &r);
    return r.memoryRequirements;
  }

  // Creates an NV structure for `info` (or a compacted one of `compactedSize`) and binds it to memory of its own.
  VkAccelerationStructureNV createBound(const VkAccelerationStructureInfoNV& info, VkDeviceSize compactedSize = 0) {
    VkAccelerationStructureCreateInfoNV ci{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_NV};
    ci.compactedSize = compactedSize;
    ci.info = info;
    VkAccelerationStructureNV as = VK_NULL_HANDLE;
    EXPECT_EQ(createNv(device, &ci, nullptr, &as), VK_SUCCESS);
    nvStructures.push_back(as);
    VkMemoryRequirements r = requirements(as, VK_ACCELERATION_STRUCTURE_MEMORY_REQUIREMENTS_TYPE_OBJECT_NV);
    VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    mai.allocationSize = r.size;
    mai.memoryTypeIndex = memoryTypeIndex(r.memoryTypeBits, 0);
    VkDeviceMemory mem = VK_NULL_HANDLE;
    EXPECT_EQ(vkAllocateMemory(device, &mai, nullptr, &mem), VK_SUCCESS);
    nvMemory.push_back(mem);
    VkBindAccelerationStructureMemoryInfoNV bi{VK_STRUCTURE_TYPE_BIND_ACCELERATION_STRUCTURE_MEMORY_INFO_NV};
    bi.accelerationStructure = as;
    bi.memory = mem;
    EXPECT_EQ(bindNv(device, 1, &bi), VK_SUCCESS);
    return as;
  }

  void barrier(VkCommandBuffer cb) {
    VkMemoryBarrier mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    mb.srcAccessMask = VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_NV;
    mb.dstAccessMask = VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_NV;
    vkCmdPipelineBarrier(
        cb, VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_NV,
        VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_NV | VK_PIPELINE_STAGE_RAY_TRACING_SHADER_BIT_NV, 0, 1, &mb,
        0, nullptr, 0, nullptr);
  }

  // Builds `info` into `dst` on the device (instances from `instances` for a top level).
  void nvBuild(const VkAccelerationStructureInfoNV& info, VkAccelerationStructureNV dst,
               VkBuffer instances = VK_NULL_HANDLE, VkBool32 update = VK_FALSE,
               VkAccelerationStructureNV src = VK_NULL_HANDLE) {
    VkMemoryRequirements r =
        requirements(dst, update ? VK_ACCELERATION_STRUCTURE_MEMORY_REQUIREMENTS_TYPE_UPDATE_SCRATCH_NV
                                 : VK_ACCELERATION_STRUCTURE_MEMORY_REQUIREMENTS_TYPE_BUILD_SCRATCH_NV);
    HostBuffer& scratch = nvBuffer(r.size);
    VkCommandBuffer cb = beginOneTime();
    buildNv(cb, &info, instances, 0, update, dst, src, scratch.buffer, 0);
    barrier(cb);
    submitAndWait(cb);
  }

  // The quad of the KHR tests as an NV geometry (float3 vertices, 32-bit indices).
  VkGeometryNV quadGeometry() {
    VkGeometryNV g{VK_STRUCTURE_TYPE_GEOMETRY_NV};
    g.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_NV;
    g.flags = VK_GEOMETRY_OPAQUE_BIT_NV;
    g.geometry.triangles.sType = VK_STRUCTURE_TYPE_GEOMETRY_TRIANGLES_NV;
    g.geometry.triangles.vertexData = nvUpload(kQuad);
    g.geometry.triangles.vertexCount = uint32_t(kQuad.size() / 3);
    g.geometry.triangles.vertexStride = 12;
    g.geometry.triangles.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
    g.geometry.triangles.indexData = nvUpload(kQuadIndices);
    g.geometry.triangles.indexCount = uint32_t(kQuadIndices.size());
    g.geometry.triangles.indexType = VK_INDEX_TYPE_UINT32;
    g.geometry.aabbs.sType = VK_STRUCTURE_TYPE_GEOMETRY_AABB_NV;
    return g;
  }
  VkAccelerationStructureInfoNV bottomInfo(const VkGeometryNV* g, VkBuildAccelerationStructureFlagsNV flags = 0) {
    VkAccelerationStructureInfoNV info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_INFO_NV};
    info.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_NV;
    info.flags = flags;
    info.geometryCount = 1;
    info.pGeometries = g;
    return info;
  }
  VkAccelerationStructureInfoNV topInfo(uint32_t instances) {
    VkAccelerationStructureInfoNV info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_INFO_NV};
    info.type = VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_NV;
    info.instanceCount = instances;
    return info;
  }
  uint64_t handleOf(VkAccelerationStructureNV as) {
    uint64_t h = 0;
    EXPECT_EQ(asHandleNv(device, as, sizeof h, &h), VK_SUCCESS);
    return h;
  }
  // The basic scene's top level (TraceTest::basicScene) over an NV bottom level.
  VkAccelerationStructureNV nvTopOver(VkAccelerationStructureNV quad) {
    std::vector<VkAccelerationStructureInstanceNV> in = {instance(VK_NULL_HANDLE, 0.1f, 0, 5, 10, 0),
                                                         instance(VK_NULL_HANDLE, 1.6f, 0, 2, 20, 1)};
    for (auto& i : in) i.accelerationStructureReference = handleOf(quad);
    VkAccelerationStructureInfoNV info = topInfo(2);
    VkAccelerationStructureNV top = createBound(info);
    nvBuild(info, top, nvUpload(in));
    return top;
  }
  VkAccelerationStructureNV nvBasicScene() {
    VkGeometryNV g = quadGeometry();
    VkAccelerationStructureInfoNV info = bottomInfo(&g);
    VkAccelerationStructureNV quad = createBound(info);
    nvBuild(info, quad);
    return nvTopOver(quad);
  }

  // raygen, miss, triangle hit group (closest hit) of the given modules, by vkCreateRayTracingPipelinesNV; with
  // `isect`, the hit group is a procedural one with that intersection shader.
  VkPipeline nvPipeline(VkShaderModule rg, VkShaderModule ms, VkShaderModule ch, VkPipelineLayout pl,
                        VkPipelineCreateFlags flags = 0, VkShaderModule isect = VK_NULL_HANDLE) {
    VkPipelineShaderStageCreateInfo st[4] = {};
    const VkShaderStageFlagBits stages[4] = {VK_SHADER_STAGE_RAYGEN_BIT_NV, VK_SHADER_STAGE_MISS_BIT_NV,
                                             VK_SHADER_STAGE_CLOSEST_HIT_BIT_NV, VK_SHADER_STAGE_INTERSECTION_BIT_NV};
    const VkShaderModule ms3[4] = {rg, ms, ch, isect};
    const uint32_t stageCount = isect ? 4 : 3;
    for (uint32_t i = 0; i < stageCount; ++i) {
      st[i].sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
      st[i].stage = stages[i];
      st[i].module = ms3[i];
      st[i].pName = "main";
    }
    for (int i = 0; i < 3; ++i) {
      nvGroups[i] = {VK_STRUCTURE_TYPE_RAY_TRACING_SHADER_GROUP_CREATE_INFO_NV};
      nvGroups[i].type =
          i < 2 ? VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_NV : VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_NV;
      nvGroups[i].generalShader = i < 2 ? uint32_t(i) : VK_SHADER_UNUSED_NV;
      nvGroups[i].closestHitShader = i == 2 ? 2 : VK_SHADER_UNUSED_NV;
      nvGroups[i].anyHitShader = VK_SHADER_UNUSED_NV;
      nvGroups[i].intersectionShader = VK_SHADER_UNUSED_NV;
    }
    if (isect) {
      nvGroups[2].type = VK_RAY_TRACING_SHADER_GROUP_TYPE_PROCEDURAL_HIT_GROUP_NV;
      nvGroups[2].intersectionShader = 3;
    }
    VkRayTracingPipelineCreateInfoNV ci{VK_STRUCTURE_TYPE_RAY_TRACING_PIPELINE_CREATE_INFO_NV};
    ci.flags = flags;
    ci.stageCount = stageCount;
    ci.pStages = st;
    ci.groupCount = 3;
    ci.pGroups = nvGroups;
    ci.maxRecursionDepth = 1;
    ci.layout = pl;
    ci.basePipelineIndex = -1;
    VkPipeline p = VK_NULL_HANDLE;
    EXPECT_EQ(pipelinesNv(device, VK_NULL_HANDLE, 1, &ci, nullptr, &p), VK_SUCCESS);
    if (p) pipelines.push_back(p);
    return p;
  }

  std::vector<uint8_t> nvHandles(VkPipeline p, uint32_t first, uint32_t count) {
    std::vector<uint8_t> out(size_t(nvProps.shaderGroupHandleSize) * count, 0xcd);
    EXPECT_EQ(handlesNv(device, p, first, count, out.size(), out.data()), VK_SUCCESS);
    return out;
  }

  // The NV form of TraceTest::sbt for the basic pipeline: one buffer; raygen record at offset 0, the miss record
  // (tag 7) and the two hit records (tags 100, 101) each at an offset of shaderGroupBaseAlignment, strides a
  // multiple of shaderGroupHandleSize.
  struct NvSbt {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceSize raygen = 0, miss = 0, hit = 0, stride = 0;
  };
  NvSbt nvSbt(VkPipeline p, uint32_t hitTag0 = 100, uint32_t hitTag1 = 101) {
    const uint32_t hs = nvProps.shaderGroupHandleSize, base = nvProps.shaderGroupBaseAlignment;
    std::vector<uint8_t> h = nvHandles(p, 0, 3);
    NvSbt s;
    s.stride = (hs + 4 + hs - 1) / hs * hs;
    s.miss = (s.stride + base - 1) / base * base;
    s.hit = (s.miss + s.stride + base - 1) / base * base;
    HostBuffer& b = nvBuffer(s.hit + 2 * s.stride);
    uint8_t* bytes = static_cast<uint8_t*>(b.data);
    std::memset(bytes, 0, b.size);
    auto put = [&](VkDeviceSize at, uint32_t group, uint32_t tag) {
      std::memcpy(bytes + at, h.data() + group * hs, hs);
      std::memcpy(bytes + at + hs, &tag, 4);
    };
    put(0, 0, 0);
    put(s.miss, 1, 7);
    put(s.hit, 2, hitTag0);
    put(s.hit + s.stride, 2, hitTag1);
    s.buffer = b.buffer;
    return s;
  }

  // TraceTest::trace through vkCmdTraceRaysNV, the NV descriptor and layout.
  std::vector<TracePayload> traceNvPath(VkPipeline p, const NvSbt& s, VkAccelerationStructureNV top, uint32_t n,
                                        const TraceParams& params = {}) {
    HostBuffer& out = buffer(sizeof(TracePayload) * n * n, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    std::memset(out.data, 0xee, out.size);
    VkWriteDescriptorSetAccelerationStructureNV asw{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_NV};
    asw.accelerationStructureCount = 1;
    asw.pAccelerationStructures = &top;
    VkDescriptorSet set = sceneSet(nvPool, nvSetLayout, VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_NV, &asw, out);
    VkCommandBuffer cb = beginOneTime();
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_RAY_TRACING_NV, p);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_RAY_TRACING_NV, nvLayout, 0, 1, &set, 0, nullptr);
    vkCmdPushConstants(cb, nvLayout, VK_SHADER_STAGE_RAYGEN_BIT_NV, 0, sizeof params, &params);
    traceNv(cb, s.buffer, s.raygen, s.buffer, s.miss, s.stride, s.buffer, s.hit, s.stride, VK_NULL_HANDLE, 0, 0, n, n,
            1);
    submitAndWait(cb);
    vkFreeDescriptorSets(device, nvPool, 1, &set);
    std::vector<TracePayload> r(n * n);
    std::memcpy(r.data(), out.data, r.size() * sizeof(TracePayload));
    return r;
  }

  VkPhysicalDeviceRayTracingPropertiesNV nvProps{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PROPERTIES_NV};
  PFN_vkCreateAccelerationStructureNV createNv = nullptr;
  PFN_vkDestroyAccelerationStructureNV destroyNv = nullptr;
  PFN_vkGetAccelerationStructureMemoryRequirementsNV memReqNv = nullptr;
  PFN_vkBindAccelerationStructureMemoryNV bindNv = nullptr;
  PFN_vkCmdBuildAccelerationStructureNV buildNv = nullptr;
  PFN_vkCmdCopyAccelerationStructureNV copyNv = nullptr;
  PFN_vkCmdTraceRaysNV traceNv = nullptr;
  PFN_vkCreateRayTracingPipelinesNV pipelinesNv = nullptr;
  PFN_vkGetRayTracingShaderGroupHandlesNV handlesNv = nullptr;
  PFN_vkGetAccelerationStructureHandleNV asHandleNv = nullptr;
  PFN_vkCmdWriteAccelerationStructuresPropertiesNV writePropsNv = nullptr;
  PFN_vkCompileDeferredNV compileDeferredNv = nullptr;
  VkDescriptorSetLayout nvSetLayout = VK_NULL_HANDLE;
  VkPipelineLayout nvLayout = VK_NULL_HANDLE;
  VkDescriptorPool nvPool = VK_NULL_HANDLE;
  VkShaderModule nvRgen{}, nvMiss{}, nvChit{}, nvSphere{};
  VkRayTracingShaderGroupCreateInfoNV nvGroups[3];
  std::vector<VkAccelerationStructureNV> nvStructures;
  std::vector<VkDeviceMemory> nvMemory;
};

TEST_F(NvTraceTest, PropertiesAreTheKhrFigures) {
  EXPECT_EQ(nvProps.shaderGroupHandleSize, rtProps.shaderGroupHandleSize);
  EXPECT_EQ(nvProps.shaderGroupBaseAlignment, rtProps.shaderGroupBaseAlignment);
  EXPECT_GE(nvProps.maxRecursionDepth, 1u);
  EXPECT_GT(nvProps.maxGeometryCount, 0u);
  EXPECT_GT(nvProps.maxInstanceCount, 0u);
  EXPECT_GT(nvProps.maxTriangleCount, 0u);
}

// The basic scene of the KHR tests through the NV path (NV structures, pipeline, descriptor, vkCmdTraceRaysNV,
// GL_NV_ray_tracing shaders): the hits the geometry gives, and the KHR path's payloads byte for byte.
TEST_F(NvTraceTest, TheBasicSceneTracesAsThroughTheKhrPath) {
  Desc d = basicDesc();
  VkPipeline khr = make(d);
  std::vector<TracePayload> viaKhr =
      trace(khr, sbt(khr, 3, {0}, {{1, {7}}}, {{2, {100}}, {2, {101}}}), basicScene(), 8, 8);
  expectBasicScene(viaKhr, 8);
  VkPipeline nv = nvPipeline(nvRgen, nvMiss, nvChit, nvLayout);
  ASSERT_TRUE(nv);
  std::vector<TracePayload> viaNv = traceNvPath(nv, nvSbt(nv), nvBasicScene(), 8);
  expectBasicScene(viaNv, 8);
  EXPECT_EQ(std::memcmp(viaNv.data(), viaKhr.data(), viaNv.size() * sizeof(TracePayload)), 0)
      << "the NV path's payloads differ from the KHR path's";
}

// A top level of either extension may refer to the other's bottom levels by address / handle: the same scene.
TEST_F(NvTraceTest, NvBottomLevelsUnderAKhrPipelineAndKhrDescriptor) {
  VkGeometryNV g = quadGeometry();
  VkAccelerationStructureInfoNV info = bottomInfo(&g);
  VkAccelerationStructureNV quad = createBound(info);
  nvBuild(info, quad);
  // A KHR top level whose instances refer to the NV bottom level by its handle.
  std::vector<VkAccelerationStructureInstanceKHR> in = {instance(VK_NULL_HANDLE, 0.1f, 0, 5, 10, 0),
                                                        instance(VK_NULL_HANDLE, 1.6f, 0, 2, 20, 1)};
  for (auto& i : in) i.accelerationStructureReference = handleOf(quad);
  Geometry inst;
  inst.geometry.geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;
  inst.geometry.geometry.instances.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR;
  inst.geometry.geometry.instances.data.deviceAddress = upload(in);
  inst.primitives = 2;
  if (!onVkrt())
    GTEST_SKIP() << "an NV handle as a KHR instance reference is vkrt's choice (the spec does not mix them)";
  VkAccelerationStructureKHR top = build(VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, {inst});
  Desc d = basicDesc();
  VkPipeline khr = make(d);
  expectBasicScene(trace(khr, sbt(khr, 3, {0}, {{1, {7}}}, {{2, {100}}, {2, {101}}}), top, 8, 8), 8);
}

// The same group content gives the same handle through either extension (vkrt's content-derived handles).
TEST_F(NvTraceTest, NvHandlesAreTheKhrHandlesOfTheSameGroups) {
  Desc d = basicDesc();
  d.layout = traceLayout;
  VkPipeline khr = make(d);
  VkPipeline nv = nvPipeline(rgen, tmiss, tchit, traceLayout);
  ASSERT_TRUE(khr && nv);
  std::vector<uint8_t> a = nvHandles(nv, 0, 3), b = handles(khr, 0, 3);
  // Whatever the driver, the raygen, miss and hit groups have three distinct handles.
  EXPECT_NE(slice(a, 0, 32), slice(a, 32, 32));
  EXPECT_NE(slice(a, 32, 32), slice(a, 64, 32));
  if (!onVkrt()) GTEST_SKIP() << "equal handles across extensions are vkrt's choice";
  EXPECT_EQ(a, b);
  // The NV alias of the KHR query on the KHR pipeline, and the KHR query on the NV pipeline, agree too.
  EXPECT_EQ(nvHandles(khr, 0, 3), b);
  EXPECT_EQ(handles(nv, 1, 2), slice(b, 32, 64));
  // And the same stack sizes (the same compiled shaders behind the same groups).
  for (uint32_t g = 0; g < 3; ++g) {
    const VkShaderGroupShaderKHR which =
        g < 2 ? VK_SHADER_GROUP_SHADER_GENERAL_KHR : VK_SHADER_GROUP_SHADER_CLOSEST_HIT_KHR;
    EXPECT_EQ(getStackSize(device, nv, g, which), getStackSize(device, khr, g, which)) << "group " << g;
  }
}

// VK_PIPELINE_CREATE_DEFER_COMPILE_BIT_NV: each stage compiled once with vkCompileDeferredNV, then traced.
TEST_F(NvTraceTest, DeferredCompilationThenTrace) {
  VkPipeline nv = nvPipeline(nvRgen, nvMiss, nvChit, nvLayout, VK_PIPELINE_CREATE_DEFER_COMPILE_BIT_NV);
  ASSERT_TRUE(nv);
  for (uint32_t s = 0; s < 3; ++s) EXPECT_EQ(compileDeferredNv(device, nv, s), VK_SUCCESS);
  expectBasicScene(traceNvPath(nv, nvSbt(nv), nvBasicScene(), 8), 8);
}

// Compaction (the compacted-size query, a structure created with compactedSize, a COMPACT copy) and a clone of
// the bottom level: the top level over each traces the basic scene.
TEST_F(NvTraceTest, CompactedAndClonedBottomLevelsTraceTheScene) {
  VkGeometryNV g = quadGeometry();
  VkAccelerationStructureInfoNV info = bottomInfo(&g, VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_NV);
  VkAccelerationStructureNV quad = createBound(info);
  nvBuild(info, quad);
  VkQueryPoolCreateInfo qci{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
  qci.queryType = VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_NV;
  qci.queryCount = 1;
  VkQueryPool qp = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateQueryPool(device, &qci, nullptr, &qp), VK_SUCCESS);
  VkCommandBuffer cb = beginOneTime();
  vkCmdResetQueryPool(cb, qp, 0, 1);
  writePropsNv(cb, 1, &quad, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_NV, qp, 0);
  submitAndWait(cb);
  uint64_t compacted = 0;
  ASSERT_EQ(vkGetQueryPoolResults(device, qp, 0, 1, sizeof compacted, &compacted, sizeof compacted,
                                  VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
            VK_SUCCESS);
  vkDestroyQueryPool(device, qp, nullptr);
  EXPECT_GT(compacted, 0u);
  VkAccelerationStructureInfoNV empty = bottomInfo(nullptr, VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_NV);
  empty.geometryCount = 0;
  VkAccelerationStructureNV small = createBound(empty, compacted);
  VkAccelerationStructureNV clone = createBound(info);
  cb = beginOneTime();
  copyNv(cb, small, quad, VK_COPY_ACCELERATION_STRUCTURE_MODE_COMPACT_NV);
  copyNv(cb, clone, quad, VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_NV);
  barrier(cb);
  submitAndWait(cb);
  VkPipeline nv = nvPipeline(nvRgen, nvMiss, nvChit, nvLayout);
  ASSERT_TRUE(nv);
  NvSbt s = nvSbt(nv);
  {
    SCOPED_TRACE("compacted");
    expectBasicScene(traceNvPath(nv, s, nvTopOver(small), 8), 8);
  }
  {
    SCOPED_TRACE("clone");
    expectBasicScene(traceNvPath(nv, s, nvTopOver(clone), 8), 8);
  }
}

// An update (ALLOW_UPDATE, update = VK_TRUE) moves the quad: the rays see the moved geometry.
TEST_F(NvTraceTest, AnUpdateMovesTheGeometry) {
  VkGeometryNV g = quadGeometry();
  VkAccelerationStructureInfoNV info = bottomInfo(&g, VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_NV);
  VkAccelerationStructureNV quad = createBound(info);
  nvBuild(info, quad);
  // The same quad 3 units further along z: every hit's t grows by 3.
  std::vector<float> moved = kQuad;
  for (size_t i = 2; i < moved.size(); i += 3) moved[i] += 3;
  g.geometry.triangles.vertexData = nvUpload(moved);
  nvBuild(info, quad, VK_NULL_HANDLE, VK_TRUE, quad);
  VkPipeline nv = nvPipeline(nvRgen, nvMiss, nvChit, nvLayout);
  ASSERT_TRUE(nv);
  std::vector<TracePayload> r = traceNvPath(nv, nvSbt(nv), nvTopOver(quad), 8);
  int hits = 0;
  for (uint32_t y = 0; y < 8; ++y)
    for (uint32_t x = 0; x < 8; ++x) {
      const TracePayload& p = r[y * 8 + x];
      const float wx = cellCentre(x, 8), wy = cellCentre(y, 8);
      const bool inB = wx - 1.6f >= -1 && wx - 1.6f <= 1 && wy >= -1 && wy <= 1;
      const bool inA = wx - 0.1f >= -1 && wx - 0.1f <= 1 && wy >= -1 && wy <= 1;
      if (!inA && !inB) continue;
      ++hits;
      EXPECT_NEAR(p.hit[0], inB ? 15.0f : 18.0f, 1e-4f) << "pixel " << x << "," << y;
    }
  EXPECT_GT(hits, 10);
}

// AABB geometry (VkGeometryAABBNV) with a GL_NV_ray_tracing intersection shader in a procedural hit group: the
// spheres of the KHR test IntersectionShadersReportSpheresInBoxes, and the KHR path's payloads byte for byte.
TEST_F(NvTraceTest, IntersectionShadersReportSpheresInNvBoxes) {
  setSpheres({{-1, -1, 4, 0.5f}, {1, 1, 6, 0.5f}});
  const std::vector<VkAabbPositionsKHR> boxes = {{-1.5f, -1.5f, 3.5f, -0.5f, -0.5f, 4.5f},
                                                 {0.5f, 0.5f, 5.5f, 1.5f, 1.5f, 6.5f}};
  // The KHR path.
  VkAccelerationStructureKHR kb = blas({aabbs(boxes, VK_GEOMETRY_OPAQUE_BIT_KHR)});
  VkAccelerationStructureKHR ktop = tlas({instance(kb, 0, 0, 1, 9)});
  Desc d;
  d.layout = traceLayout;
  d.general(rgen, VK_SHADER_STAGE_RAYGEN_BIT_KHR);
  d.general(tmiss, VK_SHADER_STAGE_MISS_BIT_KHR);
  uint32_t c = d.stage(tchit, VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR);
  uint32_t i = d.stage(tsphere, VK_SHADER_STAGE_INTERSECTION_BIT_KHR);
  d.group(VK_RAY_TRACING_SHADER_GROUP_TYPE_PROCEDURAL_HIT_GROUP_KHR, VK_SHADER_UNUSED_KHR, c, VK_SHADER_UNUSED_KHR, i);
  VkPipeline khr = make(d);
  ASSERT_TRUE(khr);
  const uint32_t n = 16;
  std::vector<TracePayload> viaKhr = trace(khr, sbt(khr, 3, {0}, {{1, {7}}}, {{2, {300}}}), ktop, n, n);
  // The NV path.
  VkGeometryNV g{VK_STRUCTURE_TYPE_GEOMETRY_NV};
  g.geometryType = VK_GEOMETRY_TYPE_AABBS_NV;
  g.flags = VK_GEOMETRY_OPAQUE_BIT_NV;
  g.geometry.triangles.sType = VK_STRUCTURE_TYPE_GEOMETRY_TRIANGLES_NV;
  g.geometry.aabbs.sType = VK_STRUCTURE_TYPE_GEOMETRY_AABB_NV;
  g.geometry.aabbs.aabbData = nvUpload(boxes);
  g.geometry.aabbs.numAABBs = 2;
  g.geometry.aabbs.stride = sizeof(VkAabbPositionsKHR);
  VkAccelerationStructureInfoNV info = bottomInfo(&g);
  VkAccelerationStructureNV nb = createBound(info);
  nvBuild(info, nb);
  std::vector<VkAccelerationStructureInstanceNV> in = {instance(VK_NULL_HANDLE, 0, 0, 1, 9)};
  in[0].accelerationStructureReference = handleOf(nb);
  VkAccelerationStructureInfoNV ti = topInfo(1);
  VkAccelerationStructureNV ntop = createBound(ti);
  nvBuild(ti, ntop, nvUpload(in));
  VkPipeline nv = nvPipeline(nvRgen, nvMiss, nvChit, nvLayout, 0, nvSphere);
  ASSERT_TRUE(nv);
  std::vector<TracePayload> viaNv = traceNvPath(nv, nvSbt(nv, 300, 300), ntop, n);
  expectSpheresInBoxes(viaNv, n, false);
  EXPECT_EQ(std::memcmp(viaNv.data(), viaKhr.data(), viaNv.size() * sizeof(TracePayload)), 0)
      << "the NV path's payloads differ from the KHR path's";
}

// VKRT_RAY_TREE (docs/ray-tree.md) through vkCmdTraceRaysNV: the KHR launch records it, named by the NV command.
class NvRayTreeTest : public NvTraceTest {
 protected:
  void SetUp() override {
    out = ::testing::TempDir() + "vkrt_nv_ray_tree_" + std::to_string(getpid()) + ".json";
    std::remove(out.c_str());
    setenv("VKRT_RAY_TREE", "4,4", 1);
    setenv("VKRT_RAY_TREE_OUT", out.c_str(), 1);
    NvTraceTest::SetUp();
  }
  void TearDown() override {
    NvTraceTest::TearDown();
    unsetenv("VKRT_RAY_TREE");
    unsetenv("VKRT_RAY_TREE_OUT");
    std::remove(out.c_str());
  }
  std::string out;
};

// Launch id (4, 4) of the 8 x 8 launch shoots at world (0.25, 0.25): the basic scene's opaque quad of instance 0
// (custom index 10), committed without a candidate, then the closest-hit shader.
TEST_F(NvRayTreeTest, TheNvCommandIsNamed) {
  if (!onVkrt()) GTEST_SKIP() << "VKRT_RAY_TREE is vkrt's";
  VkPipeline nv = nvPipeline(nvRgen, nvMiss, nvChit, nvLayout);
  ASSERT_TRUE(nv);
  std::vector<TracePayload> r = traceNvPath(nv, nvSbt(nv), nvBasicScene(), 8);
  expectBasicScene(r, 8);
  std::ifstream f(out);
  std::vector<std::string> lines;
  for (std::string line; std::getline(f, line);) lines.push_back(line);
  ASSERT_EQ(lines.size(), 1u);
  const std::string& j = lines[0];
  EXPECT_EQ(j.rfind("{\"command\":\"vkCmdTraceRaysNV\",\"sequence\":0,", 0), 0u) << j;
  EXPECT_NE(j.find("\"launchSize\":[8,8,1],\"launchId\":[4,4,0],\"truncated\":false,\"tree\":{\"kind\":\"shader\","
                   "\"stage\":\"raygen\""),
            std::string::npos)
      << j;
  const TracePayload& p = r[4 * 8 + 4];
  EXPECT_EQ(p.ids[0], 10u);
  EXPECT_NE(j.find("\"instanceIndex\":0,\"instanceCustomIndex\":10,\"geometryIndex\":0,\"primitiveIndex\":" +
                   std::to_string(p.ids[2]) +
                   ",\"hitKind\":255},\"children\":[{\"kind\":\"shader\",\"stage\":"
                   "\"closest-hit\""),
            std::string::npos)
      << j;
  EXPECT_EQ(j.find("\"kind\":\"candidate\""), std::string::npos) << "opaque triangles are no candidates";
}

// ---------------------------------------------------------------------------------------------------------------
// Misuse (layer off; vkrt's reports).

class NvMisuseTest : public NvTraceTest {
 protected:
  bool layer() override { return false; }
  void SetUp() override {
    NvTraceTest::SetUp();
    if (!HasFatalFailure() && device && !onVkrt()) GTEST_SKIP() << "vkrt's own diagnostics";
  }
};

TEST_F(NvMisuseTest, PipelineRules) {
  clearMessages();
  // A miss stage as a hit group's closest-hit shader.
  VkPipelineShaderStageCreateInfo st[2] = {{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO},
                                           {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO}};
  st[0].stage = VK_SHADER_STAGE_RAYGEN_BIT_NV;
  st[0].module = nvRgen;
  st[0].pName = "main";
  st[1].stage = VK_SHADER_STAGE_MISS_BIT_NV;
  st[1].module = nvMiss;
  st[1].pName = "main";
  VkRayTracingShaderGroupCreateInfoNV g[2] = {{VK_STRUCTURE_TYPE_RAY_TRACING_SHADER_GROUP_CREATE_INFO_NV},
                                              {VK_STRUCTURE_TYPE_RAY_TRACING_SHADER_GROUP_CREATE_INFO_NV}};
  g[0].type = VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_NV;
  g[0].generalShader = 0;
  g[0].closestHitShader = g[0].anyHitShader = g[0].intersectionShader = VK_SHADER_UNUSED_NV;
  g[1].type = VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_NV;
  g[1].generalShader = g[1].anyHitShader = g[1].intersectionShader = VK_SHADER_UNUSED_NV;
  g[1].closestHitShader = 1;
  VkRayTracingPipelineCreateInfoNV ci{VK_STRUCTURE_TYPE_RAY_TRACING_PIPELINE_CREATE_INFO_NV};
  ci.stageCount = 2;
  ci.pStages = st;
  ci.groupCount = 2;
  ci.pGroups = g;
  ci.maxRecursionDepth = 1;
  ci.layout = nvLayout;
  ci.basePipelineIndex = -1;
  VkPipeline p = VK_NULL_HANDLE;
  EXPECT_EQ(pipelinesNv(device, VK_NULL_HANDLE, 1, &ci, nullptr, &p), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkRayTracingShaderGroupCreateInfoNV-closestHitShader-02417");
  // A general group naming a closest-hit shader.
  g[1].type = VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_NV;
  g[1].generalShader = 1;
  EXPECT_EQ(pipelinesNv(device, VK_NULL_HANDLE, 1, &ci, nullptr, &p), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkRayTracingShaderGroupCreateInfoNV-type-02414");
  g[1].closestHitShader = VK_SHADER_UNUSED_NV;
  // Recursion deeper than the NV limit.
  ci.maxRecursionDepth = nvProps.maxRecursionDepth + 1;
  EXPECT_EQ(pipelinesNv(device, VK_NULL_HANDLE, 1, &ci, nullptr, &p), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkRayTracingPipelineCreateInfoNV-maxRecursionDepth-03457");
  ci.maxRecursionDepth = 1;
  // KHR-only flags.
  ci.flags = VK_PIPELINE_CREATE_LIBRARY_BIT_KHR;
  EXPECT_EQ(pipelinesNv(device, VK_NULL_HANDLE, 1, &ci, nullptr, &p), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkRayTracingPipelineCreateInfoNV-flags-03456");
  ci.flags = VK_PIPELINE_CREATE_RAY_TRACING_SKIP_TRIANGLES_BIT_KHR;
  EXPECT_EQ(pipelinesNv(device, VK_NULL_HANDLE, 1, &ci, nullptr, &p), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkRayTracingPipelineCreateInfoNV-flags-03463");
  // No raygen stage.
  ci.flags = 0;
  ci.stageCount = 1;
  ci.pStages = st + 1;
  ci.groupCount = 1;
  g[1].generalShader = 0;
  ci.pGroups = g + 1;
  EXPECT_EQ(pipelinesNv(device, VK_NULL_HANDLE, 1, &ci, nullptr, &p), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkRayTracingPipelineCreateInfoNV-stage-06232");
  EXPECT_EQ(p, VK_NULL_HANDLE);
}

TEST_F(NvMisuseTest, DeferredCompileRules) {
  VkPipeline plain = nvPipeline(nvRgen, nvMiss, nvChit, nvLayout);
  VkPipeline deferred = nvPipeline(nvRgen, nvMiss, nvChit, nvLayout, VK_PIPELINE_CREATE_DEFER_COMPILE_BIT_NV);
  ASSERT_TRUE(plain && deferred);
  clearMessages();
  EXPECT_EQ(compileDeferredNv(device, plain, 0), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-vkCompileDeferredNV-pipeline-02237");
  EXPECT_EQ(compileDeferredNv(device, deferred, 1), VK_SUCCESS);
  EXPECT_EQ(compileDeferredNv(device, deferred, 1), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-vkCompileDeferredNV-shader-02238");
}

TEST_F(NvMisuseTest, StructureRules) {
  VkGeometryNV g = quadGeometry();
  VkAccelerationStructureInfoNV info = bottomInfo(&g);
  clearMessages();
  // A bottom level with instances.
  VkAccelerationStructureCreateInfoNV ci{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_NV};
  ci.info = info;
  ci.info.instanceCount = 1;
  VkAccelerationStructureNV as = VK_NULL_HANDLE;
  EXPECT_EQ(createNv(device, &ci, nullptr, &as), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkAccelerationStructureInfoNV-type-02426");
  // An unbound structure has no handle.
  ci.info.instanceCount = 0;
  ASSERT_EQ(createNv(device, &ci, nullptr, &as), VK_SUCCESS);
  nvStructures.push_back(as);
  uint64_t h = 0;
  EXPECT_EQ(asHandleNv(device, as, sizeof h, &h), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-vkGetAccelerationStructureHandleNV-accelerationStructure-02787");
  // Misaligned and twice-bound memory.
  VkMemoryRequirements r = requirements(as, VK_ACCELERATION_STRUCTURE_MEMORY_REQUIREMENTS_TYPE_OBJECT_NV);
  VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  mai.allocationSize = r.size * 2 + r.alignment;
  mai.memoryTypeIndex = memoryTypeIndex(r.memoryTypeBits, 0);
  VkDeviceMemory mem = VK_NULL_HANDLE;
  ASSERT_EQ(vkAllocateMemory(device, &mai, nullptr, &mem), VK_SUCCESS);
  nvMemory.push_back(mem);
  VkBindAccelerationStructureMemoryInfoNV bi{VK_STRUCTURE_TYPE_BIND_ACCELERATION_STRUCTURE_MEMORY_INFO_NV};
  bi.accelerationStructure = as;
  bi.memory = mem;
  bi.memoryOffset = r.alignment / 2;
  EXPECT_EQ(bindNv(device, 1, &bi), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkBindAccelerationStructureMemoryInfoNV-memoryOffset-03623");
  bi.memoryOffset = 0;
  ASSERT_EQ(bindNv(device, 1, &bi), VK_SUCCESS);
  EXPECT_EQ(bindNv(device, 1, &bi), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkBindAccelerationStructureMemoryInfoNV-accelerationStructure-03620");
  // The handle needs 8 bytes.
  EXPECT_EQ(asHandleNv(device, as, 4, &h), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-vkGetAccelerationStructureHandleNV-dataSize-02240");
  // A build with other flags than the structure was created with, and an update without a source.
  HostBuffer& scratch = nvBuffer(4096);
  VkAccelerationStructureInfoNV other = info;
  other.flags = VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_NV;
  VkCommandBuffer cb = beginOneTime();
  buildNv(cb, &other, VK_NULL_HANDLE, 0, VK_FALSE, as, VK_NULL_HANDLE, scratch.buffer, 0);
  expectVkrtMessage("VUID-vkCmdBuildAccelerationStructureNV-dst-02488");
  buildNv(cb, &info, VK_NULL_HANDLE, 0, VK_TRUE, as, VK_NULL_HANDLE, scratch.buffer, 0);
  expectVkrtMessage("VUID-vkCmdBuildAccelerationStructureNV-update-02489");
  // A vertex format the NV extension does not take, a misaligned transform offset.
  VkGeometryNV bad = g;
  bad.geometry.triangles.vertexFormat = VK_FORMAT_R8G8B8A8_SNORM;
  VkAccelerationStructureInfoNV badInfo = bottomInfo(&bad);
  buildNv(cb, &badInfo, VK_NULL_HANDLE, 0, VK_FALSE, as, VK_NULL_HANDLE, scratch.buffer, 0);
  expectVkrtMessage("VUID-VkGeometryTrianglesNV-vertexFormat-02430");
  bad = g;
  bad.geometry.triangles.transformData = nvUpload(std::vector<float>(16, 0.0f));
  bad.geometry.triangles.transformOffset = 8;
  buildNv(cb, &badInfo, VK_NULL_HANDLE, 0, VK_FALSE, as, VK_NULL_HANDLE, scratch.buffer, 0);
  expectVkrtMessage("VUID-VkGeometryTrianglesNV-transformOffset-02438");
  // Scratch without VK_BUFFER_USAGE_RAY_TRACING_BIT_NV.
  HostBuffer& plain = buffer(4096, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  buildNv(cb, &info, VK_NULL_HANDLE, 0, VK_FALSE, as, VK_NULL_HANDLE, plain.buffer, 0);
  expectVkrtMessage("VUID-vkCmdBuildAccelerationStructureNV-scratch-03522");
  // A compaction query of a structure built without ALLOW_COMPACTION is reported when it runs.
  buildNv(cb, &info, VK_NULL_HANDLE, 0, VK_FALSE, as, VK_NULL_HANDLE, scratch.buffer, 0);
  barrier(cb);
  VkQueryPoolCreateInfo qci{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
  qci.queryType = VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_NV;
  qci.queryCount = 1;
  VkQueryPool qp = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateQueryPool(device, &qci, nullptr, &qp), VK_SUCCESS);
  vkCmdResetQueryPool(cb, qp, 0, 1);
  writePropsNv(cb, 1, &as, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR, qp, 0);
  expectVkrtMessage("VUID-vkCmdWriteAccelerationStructuresPropertiesNV-queryType-06216");
  writePropsNv(cb, 1, &as, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_NV, qp, 0);
  EXPECT_TRUE(vkrtMessages().empty());
  submitAndWait(cb);
  expectVkrtMessage("VUID-vkCmdWriteAccelerationStructuresPropertiesNV-pAccelerationStructures-06215");
  vkDestroyQueryPool(device, qp, nullptr);
}

TEST_F(NvMisuseTest, TraceRules) {
  VkPipeline nv = nvPipeline(nvRgen, nvMiss, nvChit, nvLayout);
  ASSERT_TRUE(nv);
  NvSbt s = nvSbt(nv);
  clearMessages();
  VkCommandBuffer cb = beginOneTime();
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_RAY_TRACING_NV, nv);
  // A miss offset that is not a multiple of shaderGroupBaseAlignment.
  traceNv(cb, s.buffer, 0, s.buffer, s.miss + 4, s.stride, s.buffer, s.hit, s.stride, VK_NULL_HANDLE, 0, 0, 1, 1, 1);
  expectVkrtMessage("VUID-vkCmdTraceRaysNV-missShaderBindingOffset-02458");
  // A hit stride that is not a multiple of shaderGroupHandleSize, and one above maxShaderGroupStride.
  traceNv(cb, s.buffer, 0, s.buffer, s.miss, s.stride, s.buffer, s.hit, s.stride + 4, VK_NULL_HANDLE, 0, 0, 1, 1, 1);
  expectVkrtMessage("VUID-vkCmdTraceRaysNV-hitShaderBindingStride-02464");
  const VkDeviceSize tooWide =
      (nvProps.maxShaderGroupStride / nvProps.shaderGroupHandleSize + 1) * nvProps.shaderGroupHandleSize;
  traceNv(cb, s.buffer, 0, s.buffer, s.miss, tooWide, s.buffer, s.hit, s.stride, VK_NULL_HANDLE, 0, 0, 1, 1, 1);
  expectVkrtMessage("VUID-vkCmdTraceRaysNV-missShaderBindingStride-02466");
  // A raygen offset past the buffer's end.
  traceNv(cb, s.buffer, 1u << 20, s.buffer, s.miss, s.stride, s.buffer, s.hit, s.stride, VK_NULL_HANDLE, 0, 0, 1, 1, 1);
  expectVkrtMessage("VUID-vkCmdTraceRaysNV-raygenShaderBindingOffset-02455");
  vkEndCommandBuffer(cb);
}

TEST_F(NvMisuseTest, AForeignHandleInTheSbtIsReportedUnderTheNvVuid) {
  VkPipeline basic = nvPipeline(nvRgen, nvMiss, nvChit, nvLayout);
  // Same raygen and miss groups (so the same handles), but a procedural hit group the basic pipeline lacks.
  VkPipeline spheres = nvPipeline(nvRgen, nvMiss, nvChit, nvLayout, 0, nvSphere);
  ASSERT_TRUE(basic && spheres);
  NvSbt s = nvSbt(spheres);
  VkAccelerationStructureNV top = nvBasicScene();
  clearMessages();
  std::vector<TracePayload> r = traceNvPath(basic, s, top, 8);
  auto msgs = vkrtMessages();
  ASSERT_EQ(msgs.size(), 1u) << (msgs.empty() ? "no report" : msgs[0].text);
  EXPECT_EQ(msgs[0].idName, "VUID-vkCmdTraceRaysNV-None-03429") << msgs[0].text;
  EXPECT_NE(msgs[0].text.find("vkCmdTraceRaysNV"), std::string::npos) << msgs[0].text;
  EXPECT_NE(msgs[0].text.find("hit record"), std::string::npos) << msgs[0].text;
  clearMessages();
  // The foreign hit records ran nothing; the misses ran their shader.
  int misses = 0;
  for (const TracePayload& p : r) misses += p.hit[0] == -2.0f;
  EXPECT_GT(misses, 10);
  for (const TracePayload& p : r) EXPECT_TRUE(p.hit[0] == -2.0f || p.hit[0] == -1.0f) << p.hit[0];
}

}  // namespace

// The NV commands are not available while VK_NV_ray_tracing is not enabled (RtMisuseTest: the layer off, so that
// vkGetDeviceProcAddr reaches the driver through the loader), and are once it is.
class NvResolutionTest : public RtTest {
 protected:
  bool layer() override { return false; }
};

TEST_F(NvResolutionTest, NvCommandsResolveOnlyWithTheExtension) {
  for (const char* name : kNvCommands)
    EXPECT_EQ(vkGetDeviceProcAddr(device, name), nullptr) << name << " resolves without VK_NV_ray_tracing";
  // The KHR form of the handle query does.
  EXPECT_NE(vkGetDeviceProcAddr(device, "vkGetRayTracingShaderGroupHandlesKHR"), nullptr);
}

namespace {
class NvResolutionEnabledTest : public NvTraceTest {
 protected:
  bool layer() override { return false; }
};
}  // namespace

TEST_F(NvResolutionEnabledTest, NvCommandsResolveWithTheExtension) {
  for (const char* name : kNvCommands)
    EXPECT_NE(vkGetDeviceProcAddr(device, name), nullptr) << name << " does not resolve with VK_NV_ray_tracing";
}

}  // namespace vkrt::test
