// Acceleration structure operations, checked by tracing: a compacted copy, a serialize/deserialize round trip with
// patched bottom-level references (in one process and from another), an update that moves the geometry, and builds on
// the host (with a deferred operation joined by several threads) all trace the scene their inputs describe.
#include <malloc.h>

#include <sstream>
#include <thread>

#include "e2e/trace_fixture.hpp"
#include "hit_distance.hpp"

namespace vkrt::test {
namespace {

class TraceAsTest : public TraceTest {
 protected:
  void SetUp() override {
    TraceTest::SetUp();
    if (HasFatalFailure() || !device) return;
    load(cmdWriteProps, "vkCmdWriteAccelerationStructuresPropertiesKHR");
    load(cmdCopy, "vkCmdCopyAccelerationStructureKHR");
    load(cmdToMemory, "vkCmdCopyAccelerationStructureToMemoryKHR");
    load(cmdFromMemory, "vkCmdCopyMemoryToAccelerationStructureKHR");
    load(compatibility, "vkGetDeviceAccelerationStructureCompatibilityKHR");
    p = make(desc = basicDesc());
    ASSERT_NE(p, VK_NULL_HANDLE);
    s = sbt(p, 3, {0}, {{1, {7}}}, {{2, {100}}, {2, {101}}});
  }
  // A property of `as` read through a query pool on the device.
  VkDeviceSize property(VkAccelerationStructureKHR as, VkQueryType type) {
    VkQueryPoolCreateInfo qci{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
    qci.queryType = type;
    qci.queryCount = 1;
    VkQueryPool pool = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreateQueryPool(device, &qci, nullptr, &pool), VK_SUCCESS);
    VkCommandBuffer cb = beginOneTime();
    vkCmdResetQueryPool(cb, pool, 0, 1);
    cmdWriteProps(cb, 1, &as, type, pool, 0);
    submitAndWait(cb);
    VkDeviceSize v = 0;
    EXPECT_EQ(vkGetQueryPoolResults(device, pool, 0, 1, sizeof v, &v, sizeof v,
                                    VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
              VK_SUCCESS);
    vkDestroyQueryPool(device, pool, nullptr);
    return v;
  }
  // An empty acceleration structure of `type` and `size` (its own buffer).
  VkAccelerationStructureKHR empty(VkAccelerationStructureTypeKHR type, VkDeviceSize size) {
    HostBuffer& storage = buffer(size, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR);
    VkAccelerationStructureCreateInfoKHR ci{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
    ci.buffer = storage.buffer;
    ci.size = size;
    ci.type = type;
    VkAccelerationStructureKHR as = VK_NULL_HANDLE;
    EXPECT_EQ(createAs(device, &ci, nullptr, &as), VK_SUCCESS);
    structures.push_back(as);
    return as;
  }
  // The serialized form of `as` (vkCmdCopyAccelerationStructureToMemoryKHR), its size from the query.
  std::vector<uint8_t> serialized(VkAccelerationStructureKHR as) {
    const VkDeviceSize bytes = property(as, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR);
    EXPECT_GT(bytes, 56u);
    HostBuffer& data = buffer(bytes + 256, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    const VkDeviceAddress at = (addressOf(data) + 255) / 256 * 256;
    VkCommandBuffer cb = beginOneTime();
    VkCopyAccelerationStructureToMemoryInfoKHR out{VK_STRUCTURE_TYPE_COPY_ACCELERATION_STRUCTURE_TO_MEMORY_INFO_KHR};
    out.mode = VK_COPY_ACCELERATION_STRUCTURE_MODE_SERIALIZE_KHR;
    out.src = as;
    out.dst.deviceAddress = at;
    cmdToMemory(cb, &out);
    barrier(cb);
    submitAndWait(cb);
    const uint8_t* first = static_cast<const uint8_t*>(data.data) + (at - addressOf(data));
    return std::vector<uint8_t>(first, first + bytes);
  }
  // A new structure of `type` deserialized from `data` (vkCmdCopyMemoryToAccelerationStructureKHR), every
  // bottom-level reference in the header patched to `references` first (the application's job).
  VkAccelerationStructureKHR deserialized(std::vector<uint8_t> data, VkAccelerationStructureTypeKHR type,
                                          VkAccelerationStructureKHR references) {
    uint64_t count = 0, size = 0;
    std::memcpy(&size, data.data() + 40, 8);
    std::memcpy(&count, data.data() + 48, 8);
    EXPECT_EQ(count == 0, references == VK_NULL_HANDLE);
    for (uint64_t i = 0; i < count && 56 + (i + 1) * 8 <= data.size(); ++i) {
      const uint64_t ref = addressOf(references);
      std::memcpy(data.data() + 56 + i * 8, &ref, 8);
    }
    VkAccelerationStructureKHR as = empty(type, std::max<VkDeviceSize>(size, 256));
    HostBuffer& src = buffer(data.size() + 256, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    const VkDeviceAddress at = (addressOf(src) + 255) / 256 * 256;
    std::memcpy(static_cast<uint8_t*>(src.data) + (at - addressOf(src)), data.data(), data.size());
    VkCommandBuffer cb = beginOneTime();
    VkCopyMemoryToAccelerationStructureInfoKHR in{VK_STRUCTURE_TYPE_COPY_MEMORY_TO_ACCELERATION_STRUCTURE_INFO_KHR};
    in.mode = VK_COPY_ACCELERATION_STRUCTURE_MODE_DESERIALIZE_KHR;
    in.src.deviceAddress = at;
    in.dst = as;
    cmdFromMemory(cb, &in);
    barrier(cb);
    submitAndWait(cb);
    return as;
  }
  void barrier(VkCommandBuffer cb) {
    VkMemoryBarrier mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    mb.srcAccessMask = VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR | VK_ACCESS_TRANSFER_WRITE_BIT;
    mb.dstAccessMask =
        VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_KHR | VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 1, &mb, 0,
                         nullptr, 0, nullptr);
  }

  PFN_vkCmdWriteAccelerationStructuresPropertiesKHR cmdWriteProps = nullptr;
  PFN_vkCmdCopyAccelerationStructureKHR cmdCopy = nullptr;
  PFN_vkCmdCopyAccelerationStructureToMemoryKHR cmdToMemory = nullptr;
  PFN_vkCmdCopyMemoryToAccelerationStructureKHR cmdFromMemory = nullptr;
  PFN_vkGetDeviceAccelerationStructureCompatibilityKHR compatibility = nullptr;
  Desc desc;
  VkPipeline p = VK_NULL_HANDLE;
  Sbt s;
};

// The vertex formats the specification requires for acceleration structure builds carry the format feature
// (the CTS checks it before every build; without it, every acceleration_structures case failed).
TEST_F(TraceAsTest, MandatoryVertexFormatsHaveTheAccelerationStructureFormatFeature) {
  for (VkFormat f : {VK_FORMAT_R32G32_SFLOAT, VK_FORMAT_R32G32B32_SFLOAT, VK_FORMAT_R16G16_SFLOAT,
                     VK_FORMAT_R16G16B16A16_SFLOAT, VK_FORMAT_R16G16_SNORM, VK_FORMAT_R16G16B16A16_SNORM}) {
    VkFormatProperties props{};
    vkGetPhysicalDeviceFormatProperties(physicalDevice, f, &props);
    EXPECT_TRUE(props.bufferFeatures & VK_FORMAT_FEATURE_ACCELERATION_STRUCTURE_VERTEX_BUFFER_BIT_KHR)
        << "format " << f;
  }
  VkFormatProperties none{};
  vkGetPhysicalDeviceFormatProperties(physicalDevice, VK_FORMAT_R8_UINT, &none);
  if (onVkrt()) {
    EXPECT_FALSE(none.bufferFeatures & VK_FORMAT_FEATURE_ACCELERATION_STRUCTURE_VERTEX_BUFFER_BIT_KHR);
  }
}

TEST_F(TraceAsTest, ACompactedCopyTracesTheSame) {
  VkAccelerationStructureKHR quad = build(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR,
                                          {triangles(kQuad, kQuadIndices, VK_GEOMETRY_OPAQUE_BIT_KHR)},
                                          VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR |
                                              VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_KHR);
  const VkDeviceSize compacted = property(quad, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR);
  ASSERT_GT(compacted, 0u);
  VkAccelerationStructureKHR small = empty(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, compacted);
  VkCommandBuffer cb = beginOneTime();
  VkCopyAccelerationStructureInfoKHR copy{VK_STRUCTURE_TYPE_COPY_ACCELERATION_STRUCTURE_INFO_KHR};
  copy.src = quad;
  copy.dst = small;
  copy.mode = VK_COPY_ACCELERATION_STRUCTURE_MODE_COMPACT_KHR;
  cmdCopy(cb, &copy);
  barrier(cb);
  submitAndWait(cb);
  // The original is destroyed: the top level refers to the compacted copy alone.
  destroyAs(device, quad, nullptr);
  structures.erase(std::find(structures.begin(), structures.end(), quad));
  VkAccelerationStructureKHR top = tlas({instance(small, 0.1f, 0, 5, 10, 0), instance(small, 1.6f, 0, 2, 20, 1)});
  expectBasicScene(trace(p, s, top, 8, 8), 8);
}

// Creating an acceleration structure does not touch its buffer: one created over a built structure (same buffer,
// same offset) and never built leaves the address denoting what was built there, for bottom-level references
// resolved by a later top-level build and for the top level a trace names (the CTS's
// misc.reuse_creation_buffer_*). Building it would replace the content, as it would overwrite the memory.
TEST_F(TraceAsTest, AStructureCreatedOverABuiltOneLeavesItInPlace) {
  VkAccelerationStructureKHR quad = blas({triangles(kQuad, kQuadIndices, VK_GEOMETRY_OPAQUE_BIT_KHR)});
  VkAccelerationStructureKHR overQuad = VK_NULL_HANDLE, overTop = VK_NULL_HANDLE;
  ASSERT_EQ(createAs(device, &storageOf[quad], nullptr, &overQuad), VK_SUCCESS);
  structures.push_back(overQuad);
  EXPECT_EQ(addressOf(overQuad), addressOf(quad));
  VkAccelerationStructureKHR top = tlas({instance(quad, 0.1f, 0, 5, 10, 0), instance(quad, 1.6f, 0, 2, 20, 1)});
  ASSERT_EQ(createAs(device, &storageOf[top], nullptr, &overTop), VK_SUCCESS);
  structures.push_back(overTop);
  expectBasicScene(trace(p, s, top, 8, 8), 8);
  destroyAs(device, overTop, nullptr);
  structures.erase(std::find(structures.begin(), structures.end(), overTop));
  expectBasicScene(trace(p, s, top, 8, 8), 8);
}

TEST_F(TraceAsTest, SerializedAndDeserializedStructuresTraceTheSame) {
  VkAccelerationStructureKHR quad = blas({triangles(kQuad, kQuadIndices, VK_GEOMETRY_OPAQUE_BIT_KHR)});
  VkAccelerationStructureKHR top = tlas({instance(quad, 0.1f, 0, 5, 10, 0), instance(quad, 1.6f, 0, 2, 20, 1)});
  std::vector<uint8_t> blasData = serialized(quad), tlasData = serialized(top);
  ASSERT_FALSE(HasFailure());
  // The header: driverUUID and compatibility UUID, which this device accepts; the sizes; the references.
  VkAccelerationStructureVersionInfoKHR version{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_VERSION_INFO_KHR};
  version.pVersionData = blasData.data();
  VkAccelerationStructureCompatibilityKHR compat = VK_ACCELERATION_STRUCTURE_COMPATIBILITY_INCOMPATIBLE_KHR;
  compatibility(device, &version, &compat);
  EXPECT_EQ(compat, VK_ACCELERATION_STRUCTURE_COMPATIBILITY_COMPATIBLE_KHR);
  VkDeviceSize sizes[3];
  std::memcpy(sizes, blasData.data() + 32, sizeof sizes);
  EXPECT_EQ(sizes[0], blasData.size()) << "serialized size";
  EXPECT_EQ(sizes[2], 0u) << "a bottom level refers to nothing";
  std::memcpy(sizes, tlasData.data() + 32, sizeof sizes);
  EXPECT_EQ(sizes[0], tlasData.size());
  ASSERT_EQ(sizes[2], 2u) << "one reference per instance (both the quad)";
  for (uint64_t i = 0; i < sizes[2]; ++i) {
    uint64_t ref;
    std::memcpy(&ref, tlasData.data() + 56 + i * 8, 8);
    EXPECT_EQ(ref, addressOf(quad));
  }
  VkAccelerationStructureKHR quad2 = deserialized(blasData, VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, 0);
  VkAccelerationStructureKHR top2 = deserialized(tlasData, VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, quad2);
  // The originals are gone: the deserialized pair alone is traced.
  for (VkAccelerationStructureKHR gone : {top, quad}) {
    destroyAs(device, gone, nullptr);
    structures.erase(std::find(structures.begin(), structures.end(), gone));
  }
  expectBasicScene(trace(p, s, top2, 8, 8), 8);
}

// Run by the test below in a process of its own: the basic scene serialized, bottom level then top level, as hex.
TEST_F(TraceAsTest, HelperSerializeTheBasicScene) {
  if (!std::getenv("VKRT_HELPER_OUT")) GTEST_SKIP() << "run by TraceAsTest.DataSerializedInAnotherProcessTracesTheSame";
  VkAccelerationStructureKHR quad = blas({triangles(kQuad, kQuadIndices, VK_GEOMETRY_OPAQUE_BIT_KHR)});
  VkAccelerationStructureKHR top = tlas({instance(quad, 0.1f, 0, 5, 10, 0), instance(quad, 1.6f, 0, 2, 20, 1)});
  writeOut(hexOf(serialized(quad)) + " " + hexOf(serialized(top)));
}

TEST_F(TraceAsTest, DataSerializedInAnotherProcessTracesTheSame) {
  // On NVIDIA's driver 580 (H100) the pair deserialized from the other process traces as misses (the in-process
  // round trip above passes there): not understood yet, so the cross-process case is asserted on vkrt only.
  if (!vkrt) GTEST_SKIP() << "cross-process deserialization differs on this driver (see the comment)";
  std::istringstream in(runHelper("TraceAsTest.HelperSerializeTheBasicScene"));
  std::string blasHex, tlasHex;
  in >> blasHex >> tlasHex;
  std::vector<uint8_t> blasData = fromHex(blasHex), tlasData = fromHex(tlasHex);
  ASSERT_GT(blasData.size(), 56u);
  ASSERT_GT(tlasData.size(), 56u);
  VkAccelerationStructureKHR quad = deserialized(blasData, VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, 0);
  VkAccelerationStructureKHR top = deserialized(tlasData, VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, quad);
  expectBasicScene(trace(p, s, top, 8, 8), 8);
}

TEST_F(TraceAsTest, AnUpdateMovesTheGeometry) {
  // The quad is built for update, then updated in place 1 unit further along z. The top level built before the
  // update refers to the bottom level (the spec: it "takes a reference"), so it sees the update without a rebuild
  // (the CTS's acceleration_structures.update.* expect it).
  Geometry g = triangles(kQuad, kQuadIndices, VK_GEOMETRY_OPAQUE_BIT_KHR);
  const VkBuildAccelerationStructureFlagsKHR flags = VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR;
  VkAccelerationStructureKHR quad = build(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {g}, flags);
  VkAccelerationStructureKHR before = tlas({instance(quad, 0.1f, 0, 5, 10, 0)});
  EXPECT_NEAR(trace(p, s, before, 8, 8)[3 * 8 + 3].hit[0], 15.0f, 1e-4f) << "the quad at z = 5";
  std::vector<float> moved = kQuad;
  for (size_t i = 2; i < moved.size(); i += 3) moved[i] += 1;
  Geometry g2 = triangles(moved, kQuadIndices, VK_GEOMETRY_OPAQUE_BIT_KHR);
  VkAccelerationStructureBuildGeometryInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
  info.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
  info.flags = flags;
  info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
  info.srcAccelerationStructure = quad;
  info.dstAccelerationStructure = quad;
  info.geometryCount = 1;
  info.pGeometries = &g2.geometry;
  uint32_t count = 2;
  VkAccelerationStructureBuildSizesInfoKHR sizes{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
  buildSizes(device, VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &info, &count, &sizes);
  HostBuffer& scratch = buffer(sizes.updateScratchSize + 256, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  info.scratchData.deviceAddress = (addressOf(scratch) + 255) / 256 * 256;
  VkAccelerationStructureBuildRangeInfoKHR range{2, 0, 0, 0};
  const VkAccelerationStructureBuildRangeInfoKHR* pr = &range;
  VkCommandBuffer cb = beginOneTime();
  cmdBuild(cb, 1, &info, &pr);
  barrier(cb);
  submitAndWait(cb);
  VkAccelerationStructureKHR top = tlas({instance(quad, 0.1f, 0, 5, 10, 0)});
  std::vector<TracePayload> r = trace(p, s, top, 8, 8);
  const TracePayload& centre = r[3 * 8 + 3];
  EXPECT_NEAR(centre.hit[0], 16.0f, 1e-4f) << "the quad now sits at z = 6";
  EXPECT_NEAR(trace(p, s, before, 8, 8)[3 * 8 + 3].hit[0], 16.0f, 1e-4f) << "through the top level built before";
}

TEST_F(TraceAsTest, HostBuildsWithADeferredOperationTraceTheSame) {
  if (!asf.accelerationStructureHostCommands) GTEST_SKIP() << "accelerationStructureHostCommands is not supported";
  PFN_vkBuildAccelerationStructuresKHR hostBuild = nullptr;
  load(hostBuild, "vkBuildAccelerationStructuresKHR");
  // Inputs in host memory: host builds read host addresses, and instances refer to bottom levels by handle.
  auto hostBuildOf = [&](VkAccelerationStructureTypeKHR type, VkAccelerationStructureGeometryKHR g, uint32_t primitives,
                         VkDeferredOperationKHR op) {
    VkAccelerationStructureBuildGeometryInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
    info.type = type;
    info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
    info.geometryCount = 1;
    info.pGeometries = &g;
    VkAccelerationStructureBuildSizesInfoKHR sizes{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
    buildSizes(device, VK_ACCELERATION_STRUCTURE_BUILD_TYPE_HOST_KHR, &info, &primitives, &sizes);
    VkAccelerationStructureKHR as = empty(type, sizes.accelerationStructureSize);
    std::vector<uint8_t> scratch(sizes.buildScratchSize + 256);
    info.dstAccelerationStructure = as;
    info.scratchData.hostAddress = scratch.data();
    VkAccelerationStructureBuildRangeInfoKHR range{primitives, 0, 0, 0};
    const VkAccelerationStructureBuildRangeInfoKHR* pr = &range;
    VkResult r = hostBuild(device, op, 1, &info, &pr);
    if (op) {
      EXPECT_EQ(r, VK_OPERATION_DEFERRED_KHR);
      std::thread helper([&] { joinOp(device, op); });
      VkResult j;
      while ((j = joinOp(device, op)) == VK_THREAD_IDLE_KHR) {
      }
      helper.join();
      EXPECT_EQ(opResult(device, op), VK_SUCCESS);
    } else {
      EXPECT_EQ(r, VK_SUCCESS);
    }
    return as;
  };
  VkAccelerationStructureGeometryKHR tg = opaqueTriangles(3, VK_INDEX_TYPE_UINT32);
  tg.geometry.triangles.vertexData.hostAddress = kQuad.data();
  tg.geometry.triangles.indexData.hostAddress = kQuadIndices.data();
  VkAccelerationStructureKHR quad = hostBuildOf(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, tg, 2, VK_NULL_HANDLE);
  std::vector<VkAccelerationStructureInstanceKHR> instances = {instance(quad, 0.1f, 0, 5, 10, 0),
                                                               instance(quad, 1.6f, 0, 2, 20, 1)};
  for (auto& in : instances) in.accelerationStructureReference = reinterpret_cast<uint64_t>(quad);
  VkAccelerationStructureGeometryKHR ig{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
  ig.geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;
  ig.geometry.instances.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR;
  ig.geometry.instances.data.hostAddress = instances.data();
  VkDeferredOperationKHR op = VK_NULL_HANDLE;
  ASSERT_EQ(createOp(device, nullptr, &op), VK_SUCCESS);
  VkAccelerationStructureKHR top = hostBuildOf(VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, ig, 2, op);
  destroyOp(device, op, nullptr);
  expectBasicScene(trace(p, s, top, 8, 8), 8);
}

// Thousands of small bottom-level structures built by one command (one info each: 1 to 3 triangles, no index
// buffer), as scenes of many small meshes and the CTS's build.*.level_instances.* cases build them, under a top level
// of one instance each in a shuffled order: every ray of a 64 x 64 launch hits the one triangle in its cell, and
// reports the instance, custom index, primitive and distance it must. Built on the device (one
// vkCmdBuildAccelerationStructuresKHR with 4096 infos) and, where the driver has host commands, on the host (one
// vkBuildAccelerationStructuresKHR with 4096 infos): the builds of one command run concurrently (nothing in one
// command may depend on another of its builds).
TEST_F(TraceAsTest, ThousandsOfSmallBottomLevelsFromOneCommandHitExactly) {
  constexpr uint32_t kSide = 64, kCount = kSide * kSide;
  // Structure b: triangle b % 3 covers the cell (b % kSide, b / kSide) of [-2, 2]^2 at z = 1 (the centre of the cell,
  // where the launch's ray passes, well inside); the others lie outside the launch's square.
  std::vector<float> vertices;
  std::vector<uint32_t> first(kCount), triangles(kCount);
  const float e = 4.0f / float(kSide);
  for (uint32_t b = 0; b < kCount; ++b) {
    first[b] = uint32_t(vertices.size() / 3);
    triangles[b] = b % 3 + 1;
    for (uint32_t t = 0; t < triangles[b]; ++t) {
      const bool inCell = t == b % 3;
      const float x0 = -2.0f + e * float(b % kSide) + (inCell ? 0.0f : 10.0f + float(t)),
                  y0 = -2.0f + e * float(b / kSide);
      const float tri[9] = {x0, y0, 1, x0 + e, y0 + 0.5f * e, 1, x0 + 0.5f * e, y0 + e, 1};
      vertices.insert(vertices.end(), tri, tri + 9);
    }
  }
  // Instance i instantiates structure perm(i) (1237 is odd: a permutation of 0..4095), custom index 1000 + perm(i).
  auto perm = [](uint32_t i) { return (i * 1237u) % kCount; };
  std::vector<uint32_t> instanceOf(kCount);
  for (uint32_t i = 0; i < kCount; ++i) instanceOf[perm(i)] = i;
  auto check = [&](VkAccelerationStructureKHR top, const char* how) {
    SCOPED_TRACE(how);
    std::vector<TracePayload> r = trace(p, s, top, kSide, kSide);
    size_t wrong = 0;
    for (uint32_t c = 0; c < kCount; ++c) {
      const TracePayload& q = r[c];
      const bool ok = nearHit(q.hit[0], 11.0f) && q.ids[0] == 1000 + c && q.ids[1] == instanceOf[c] &&
                      q.ids[2] == c % 3 && q.ids[3] == 0 && q.extra[0] == 100u;
      if (!ok && ++wrong <= 5)
        ADD_FAILURE() << "cell " << c << ": t " << q.hit[0] << ", custom index " << q.ids[0] << ", instance "
                      << q.ids[1] << ", primitive " << q.ids[2] << "; expected t 11, " << 1000 + c << ", "
                      << instanceOf[c] << ", " << c % 3;
    }
    EXPECT_EQ(wrong, 0u);
  };
  // The infos of one command for the structures in `blases`, reading vertices at `vertexBase` (an address).
  auto infosFor = [&](const std::vector<VkAccelerationStructureKHR>& blases, bool host, const void* hostVertices,
                      VkDeviceAddress deviceVertices, std::vector<VkAccelerationStructureGeometryKHR>& geometries,
                      std::vector<VkAccelerationStructureBuildRangeInfoKHR>& ranges, std::vector<uint8_t>& hostScratch,
                      VkDeviceAddress scratch) {
    geometries.assign(kCount,
                      VkAccelerationStructureGeometryKHR{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR});
    ranges.resize(kCount);
    std::vector<VkAccelerationStructureBuildGeometryInfoKHR> infos(
        kCount, {VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR});
    hostScratch.resize(size_t(kCount) * 256);
    for (uint32_t b = 0; b < kCount; ++b) {
      VkAccelerationStructureGeometryKHR& g = geometries[b];
      g.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
      g.flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
      auto& t = g.geometry.triangles;
      t.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
      t.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
      if (host)
        t.vertexData.hostAddress = static_cast<const float*>(hostVertices) + size_t(first[b]) * 3;
      else
        t.vertexData.deviceAddress = deviceVertices + VkDeviceAddress(first[b]) * 12;
      t.vertexStride = 12;
      t.maxVertex = 3 * triangles[b] - 1;
      t.indexType = VK_INDEX_TYPE_NONE_KHR;
      ranges[b] = {triangles[b], 0, 0, 0};
      VkAccelerationStructureBuildGeometryInfoKHR& info = infos[b];
      info.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
      info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
      info.geometryCount = 1;
      info.pGeometries = &g;
      info.dstAccelerationStructure = blases[b];
      if (host)
        info.scratchData.hostAddress = hostScratch.data() + size_t(b) * 256;
      else
        info.scratchData.deviceAddress = scratch + VkDeviceAddress(b) * 256;
    }
    return infos;
  };
  auto makeBlases = [&]() {
    std::vector<VkAccelerationStructureKHR> blases(kCount);
    HostBuffer& storage = buffer(VkDeviceSize(kCount) * 512, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR);
    for (uint32_t b = 0; b < kCount; ++b) {
      VkAccelerationStructureCreateInfoKHR ci{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
      ci.buffer = storage.buffer;
      ci.offset = VkDeviceSize(b) * 512;
      ci.size = 512;
      ci.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
      EXPECT_EQ(createAs(device, &ci, nullptr, &blases[b]), VK_SUCCESS);
      structures.push_back(blases[b]);
    }
    return blases;
  };
  std::vector<VkAccelerationStructureGeometryKHR> geometries;
  std::vector<VkAccelerationStructureBuildRangeInfoKHR> ranges;
  std::vector<const VkAccelerationStructureBuildRangeInfoKHR*> rangePointers(kCount);
  std::vector<uint8_t> hostScratch;
  {
    const std::vector<VkAccelerationStructureKHR> blases = makeBlases();
    const VkDeviceAddress vb = upload(vertices);
    HostBuffer& scratch = buffer(VkDeviceSize(kCount) * 256 + 256, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    auto infos =
        infosFor(blases, false, nullptr, vb, geometries, ranges, hostScratch, (addressOf(scratch) + 255) / 256 * 256);
    for (uint32_t b = 0; b < kCount; ++b) rangePointers[b] = &ranges[b];
    VkCommandBuffer cb = beginOneTime();
    cmdBuild(cb, kCount, infos.data(), rangePointers.data());
    submitAndWait(cb);
    std::vector<VkAccelerationStructureInstanceKHR> instances(kCount);
    for (uint32_t i = 0; i < kCount; ++i) instances[i] = instance(blases[perm(i)], 0, 0, 0, 1000 + perm(i));
    check(tlas(instances), "built on the device");
  }
  if (asf.accelerationStructureHostCommands) {
    PFN_vkBuildAccelerationStructuresKHR hostBuild = nullptr;
    load(hostBuild, "vkBuildAccelerationStructuresKHR");
    const std::vector<VkAccelerationStructureKHR> blases = makeBlases();
    auto infos = infosFor(blases, true, vertices.data(), 0, geometries, ranges, hostScratch, 0);
    for (uint32_t b = 0; b < kCount; ++b) rangePointers[b] = &ranges[b];
    ASSERT_EQ(hostBuild(device, VK_NULL_HANDLE, kCount, infos.data(), rangePointers.data()), VK_SUCCESS);
    // The top level on the device, over the host-built structures (their addresses are theirs either way).
    std::vector<VkAccelerationStructureInstanceKHR> instances(kCount);
    for (uint32_t i = 0; i < kCount; ++i) instances[i] = instance(blases[perm(i)], 0, 0, 0, 1000 + perm(i));
    check(tlas(instances), "built on the host");
  }
}

// The bytes the process has allocated (live heap): the sanitizers' count where a sanitizer runs the tests, else
// malloc's own (mallinfo2: in-use chunks and mmapped ones).
extern "C" size_t __sanitizer_get_current_allocated_bytes() __attribute__((weak));
uint64_t allocatedBytes() {
  if (__sanitizer_get_current_allocated_bytes) return __sanitizer_get_current_allocated_bytes();
  const struct mallinfo2 m = mallinfo2();
  return m.uordblks + m.hblkhd;
}

// Thousands of one-triangle structures (half built by one recorded command, half on the host, each with a deferred
// operation as the CTS's build.cpuht_* cases build theirs, which builds them at once) and a top level over them,
// destroyed: the memory they took is returned, and a second round takes no more than the first (the CTS builds a
// million of them in one case). The inputs and the buffers the structures live in are made before the count starts; a
// warm-up round traces the scene (each cell's ray hits its structure's triangle) so that the launch's one-time
// allocations are not counted.
// (Without the validation layer: it keeps about 300 bytes of its own per deferred operation for which a build
// returned VK_OPERATION_NOT_DEFERRED_KHR, measured here, which is not vkrt's memory.)
class TraceAsMemoryTest : public TraceAsTest {
 protected:
  bool layer() override { return false; }
};

TEST_F(TraceAsMemoryTest, ThousandsOfSmallStructuresReturnTheirMemoryWhenDestroyed) {
  constexpr uint32_t kW = 64, kH = 32, kCount = kW * kH, kHalf = kCount / 2;
  const float ex = 4.0f / float(kW), ey = 4.0f / float(kH);
  std::vector<float> vertices;  // structure k: a triangle whose centroid is the centre of cell k at z = 1
  for (uint32_t k = 0; k < kCount; ++k) {
    const float x0 = -2.0f + ex * float(k % kW), y0 = -2.0f + ey * float(k / kW);
    const float tri[9] = {x0, y0, 1, x0 + ex, y0 + 0.5f * ey, 1, x0 + 0.5f * ex, y0 + ey, 1};
    vertices.insert(vertices.end(), tri, tri + 9);
  }
  const VkDeviceAddress vb = upload(vertices);
  // The structures at 512-byte steps, the top level after them (its build size is 256 + 16 bytes an instance).
  constexpr VkDeviceSize kTopSize = 65536;
  HostBuffer& storage =
      buffer(VkDeviceSize(kCount) * 512 + kTopSize, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR);
  HostBuffer& scratch = buffer(VkDeviceSize(kCount + 2) * 256, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  const VkDeviceAddress scratchAt = (addressOf(scratch) + 255) / 256 * 256;
  std::vector<uint8_t> hostScratch(256);
  // Instance k refers to structure k by its address (its buffer's address plus its offset), custom index k.
  std::vector<VkAccelerationStructureInstanceKHR> instances(kCount);
  for (uint32_t k = 0; k < kCount; ++k) {
    instances[k] = instance(VK_NULL_HANDLE, 0, 0, 0, k);
    instances[k].accelerationStructureReference = addressOf(storage) + VkDeviceSize(k) * 512;
  }
  const VkDeviceAddress instanceData = upload(instances);
  PFN_vkBuildAccelerationStructuresKHR hostBuild = nullptr;
  if (asf.accelerationStructureHostCommands) load(hostBuild, "vkBuildAccelerationStructuresKHR");
  const VkAccelerationStructureGeometryKHR g = opaqueTriangles(2, VK_INDEX_TYPE_NONE_KHR);
  const VkAccelerationStructureBuildRangeInfoKHR one{1, 0, 0, 0}, all{kCount, 0, 0, 0};
  // One round: creates and builds everything, returns the top level (the caller destroys the structures).
  std::vector<VkAccelerationStructureKHR> made;
  auto round = [&] {
    auto create = [&](uint32_t k, VkAccelerationStructureTypeKHR type) {
      VkAccelerationStructureCreateInfoKHR ci{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
      ci.buffer = storage.buffer;
      ci.offset = VkDeviceSize(k) * 512;
      ci.size = type == VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR ? kTopSize : 512;
      ci.type = type;
      VkAccelerationStructureKHR as = VK_NULL_HANDLE;
      EXPECT_EQ(createAs(device, &ci, nullptr, &as), VK_SUCCESS);
      made.push_back(as);
      return as;
    };
    VkAccelerationStructureBuildGeometryInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
    info.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
    info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
    info.geometryCount = 1;
    // The first half (the second too without host commands): one recorded command of one info each.
    const uint32_t recorded = hostBuild ? kHalf : kCount;
    {
      std::vector<VkAccelerationStructureGeometryKHR> geometries(recorded, g);
      std::vector<VkAccelerationStructureBuildGeometryInfoKHR> infos(recorded, info);
      std::vector<const VkAccelerationStructureBuildRangeInfoKHR*> ranges(recorded, &one);
      for (uint32_t k = 0; k < recorded; ++k) {
        geometries[k].geometry.triangles.vertexData.deviceAddress = vb + VkDeviceAddress(k) * 36;
        infos[k].pGeometries = &geometries[k];
        infos[k].dstAccelerationStructure = create(k, VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR);
        infos[k].scratchData.deviceAddress = scratchAt + VkDeviceAddress(k) * 256;
      }
      VkCommandBuffer cb = beginOneTime();
      cmdBuild(cb, recorded, infos.data(), ranges.data());
      submitAndWait(cb);
    }
    // The rest on the host, each with a deferred operation the caller joins.
    const VkAccelerationStructureBuildRangeInfoKHR* pr = &one;
    for (uint32_t k = recorded; k < kCount; ++k) {
      VkAccelerationStructureGeometryKHR hg = g;
      hg.geometry.triangles.vertexData.hostAddress = vertices.data() + size_t(k) * 9;
      info.pGeometries = &hg;
      info.dstAccelerationStructure = create(k, VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR);
      info.scratchData.hostAddress = hostScratch.data();
      VkDeferredOperationKHR op = VK_NULL_HANDLE;
      EXPECT_EQ(createOp(device, nullptr, &op), VK_SUCCESS);
      // (Built at once: SmallHostBuildsRunAtOnceLargerOnesAreDeferred.)
      EXPECT_EQ(hostBuild(device, op, 1, &info, &pr), VK_OPERATION_NOT_DEFERRED_KHR);
      EXPECT_EQ(opResult(device, op), VK_SUCCESS);
      destroyOp(device, op, nullptr);
    }
    VkAccelerationStructureGeometryKHR ig{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
    ig.geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;
    ig.geometry.instances.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR;
    ig.geometry.instances.data.deviceAddress = instanceData;
    info.type = VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR;
    info.pGeometries = &ig;
    info.dstAccelerationStructure = create(kCount, VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR);
    info.scratchData.deviceAddress = scratchAt + VkDeviceAddress(kCount) * 256;
    const VkAccelerationStructureBuildRangeInfoKHR* pa = &all;
    VkCommandBuffer cb = beginOneTime();
    cmdBuild(cb, 1, &info, &pa);
    submitAndWait(cb);
    return info.dstAccelerationStructure;
  };
  auto destroyAll = [&] {
    for (auto as = made.rbegin(); as != made.rend(); ++as) destroyAs(device, *as, nullptr);
    made.clear();
  };
  // The warm-up round, traced.
  std::vector<TracePayload> r = trace(p, s, round(), kW, kH);
  size_t wrong = 0;
  for (uint32_t k = 0; k < kCount; ++k)
    if (!(nearHit(r[k].hit[0], 11.0f) && r[k].ids[0] == k && r[k].ids[1] == k) && ++wrong <= 5)
      ADD_FAILURE() << "cell " << k << ": t " << r[k].hit[0] << ", custom index " << r[k].ids[0] << ", instance "
                    << r[k].ids[1];
  EXPECT_EQ(wrong, 0u);
  destroyAll();
  made.reserve(kCount + 1);
  const uint64_t before = allocatedBytes();
  uint64_t afterFirst = 0;
  for (int n = 1; n <= 2; ++n) {
    SCOPED_TRACE("round " + std::to_string(n));
    round();
    const uint64_t built = allocatedBytes();
    destroyAll();
    const uint64_t after = allocatedBytes();
    // What the structures hold is seen (more than 100 bytes each), and all of it comes back: what is left over the
    // start is a small fraction of it (the registries' hash tables keep their size).
    EXPECT_GT(built, before + kCount * 100ull);
    EXPECT_LT(after, before + (built - before) / 20) << "built: " << built - before << " bytes over the start";
    // (Measured: 4 MB while built, 20 KB left after the first round and 4 KB more after the second.)
    if (n == 1) afterFirst = after;
    if (n == 2) {
      EXPECT_LT(after, afterFirst + (built - before) / 50) << "the second round kept more than the first";
    }
  }
  EXPECT_TRUE(vkrtMessages().empty());
}

// Capture/replay of addresses as a capture tool replays them (GFXReconstruct: memory at its opaque address, buffers
// without one, structures at their captured device address), after allocations the capture did not have.
class TraceAsReplayTest : public TraceTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o = TraceTest::options();
    o.bufferDeviceAddressCaptureReplay = true;
    asf.accelerationStructureCaptureReplay = supportedAs.accelerationStructureCaptureReplay;
    return o;
  }
  struct Storage {
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkBuffer buffer = VK_NULL_HANDLE;
    VkAccelerationStructureKHR as = VK_NULL_HANDLE;
  };
  // Memory (at `memoryAddress`, or anywhere when 0), a buffer at offset 4096 in it, a bottom-level structure at
  // offset 256 in the buffer (at `asAddress`, or anywhere when 0), all created for capture/replay.
  Storage create(uint64_t memoryAddress, VkDeviceAddress structureAddress) {
    Storage s;
    VkMemoryOpaqueCaptureAddressAllocateInfo cap{VK_STRUCTURE_TYPE_MEMORY_OPAQUE_CAPTURE_ADDRESS_ALLOCATE_INFO, nullptr,
                                                 memoryAddress};
    VkMemoryAllocateFlagsInfo flags{
        VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO, &cap,
        VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT | VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_CAPTURE_REPLAY_BIT};
    VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    bci.flags = VK_BUFFER_CREATE_DEVICE_ADDRESS_CAPTURE_REPLAY_BIT;
    bci.size = 16384;
    bci.usage = VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;
    EXPECT_EQ(vkCreateBuffer(device, &bci, nullptr, &s.buffer), VK_SUCCESS);
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(device, s.buffer, &req);
    VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, &flags};
    mai.allocationSize = 65536;
    mai.memoryTypeIndex = memoryTypeIndex(req.memoryTypeBits, 0);
    EXPECT_EQ(vkAllocateMemory(device, &mai, nullptr, &s.memory), VK_SUCCESS);
    EXPECT_EQ(vkBindBufferMemory(device, s.buffer, s.memory, 4096), VK_SUCCESS);
    VkAccelerationStructureCreateInfoKHR ci{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
    ci.createFlags = VK_ACCELERATION_STRUCTURE_CREATE_DEVICE_ADDRESS_CAPTURE_REPLAY_BIT_KHR;
    ci.buffer = s.buffer;
    ci.offset = 256;
    ci.size = 4096;
    ci.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
    ci.deviceAddress = structureAddress;
    EXPECT_EQ(createAs(device, &ci, nullptr, &s.as), VK_SUCCESS);
    return s;
  }
  void destroy(Storage& s) {
    auto destroyAs = reinterpret_cast<PFN_vkDestroyAccelerationStructureKHR>(
        vkGetDeviceProcAddr(device, "vkDestroyAccelerationStructureKHR"));
    destroyAs(device, s.as, nullptr);
    vkDestroyBuffer(device, s.buffer, nullptr);
    vkFreeMemory(device, s.memory, nullptr);
  }
  VkDeviceAddress bufferAddress(VkBuffer b) {
    VkBufferDeviceAddressInfo i{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO, nullptr, b};
    return vkGetBufferDeviceAddress(device, &i);
  }
  VkDeviceAddress structureAddress(VkAccelerationStructureKHR as) {
    VkAccelerationStructureDeviceAddressInfoKHR i{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR,
                                                  nullptr, as};
    return asAddress(device, &i);
  }
};

TEST_F(TraceAsReplayTest, AddressesAreReplayedAfterOtherAllocations) {
  if (!supportedAs.accelerationStructureCaptureReplay) GTEST_SKIP() << "accelerationStructureCaptureReplay";
  Storage captured = create(0, 0);
  VkDeviceMemoryOpaqueCaptureAddressInfo mi{VK_STRUCTURE_TYPE_DEVICE_MEMORY_OPAQUE_CAPTURE_ADDRESS_INFO, nullptr,
                                            captured.memory};
  const uint64_t memoryAddress = vkGetDeviceMemoryOpaqueCaptureAddress(device, &mi);
  const VkDeviceAddress buffer = bufferAddress(captured.buffer), structure = structureAddress(captured.as);
  ASSERT_NE(memoryAddress, 0u);
  ASSERT_NE(structure, 0u);
  destroy(captured);
  // Ordinary allocations the capture did not make (on vkrt; the spec only says drivers are "expected to separate"
  // them, so elsewhere the replay follows directly).
  std::vector<HostBuffer> others;
  if (onVkrt())
    for (int i = 0; i < 4; ++i) others.push_back(createHostBuffer(65536, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true));
  Storage replayed = create(memoryAddress, structure);
  EXPECT_EQ(bufferAddress(replayed.buffer), buffer);
  EXPECT_EQ(structureAddress(replayed.as), structure);
  destroy(replayed);
  for (HostBuffer& b : others) VulkanTest::destroy(b);
}

}  // namespace
}  // namespace vkrt::test
