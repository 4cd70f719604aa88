// Instance, physical device, device, memory and buffers through the loader.
#include <cstdio>
#include <cstring>
#include <vector>

#include "e2e/fixture.hpp"

namespace vkrt::test {
namespace {

using DeviceTest = VulkanTest;

TEST_F(DeviceTest, PhysicalDeviceIsVkrtCpu) {
  if (!onVkrt()) GTEST_SKIP() << "vkrt's own identity and queue families";
  VkPhysicalDeviceProperties p;
  vkGetPhysicalDeviceProperties(physicalDevice, &p);
  EXPECT_STREQ(p.deviceName, "vkrt");
  EXPECT_EQ(p.deviceType, VK_PHYSICAL_DEVICE_TYPE_CPU);
  EXPECT_GE(p.apiVersion, VK_API_VERSION_1_3);

  uint32_t n = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(physicalDevice, &n, nullptr);
  ASSERT_GE(n, 1u);
  std::vector<VkQueueFamilyProperties> q(n);
  vkGetPhysicalDeviceQueueFamilyProperties(physicalDevice, &n, q.data());
  EXPECT_TRUE(q[0].queueFlags & VK_QUEUE_COMPUTE_BIT);
  EXPECT_TRUE(q[0].queueFlags & VK_QUEUE_TRANSFER_BIT);
  EXPECT_GE(q[0].queueCount, 1u);
  if (onVkrt()) {
    // Family 0 does everything; family 1 compute and transfer without graphics.
    ASSERT_EQ(n, 2u);
    EXPECT_EQ(q[0].queueFlags, VkQueueFlags(VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT | VK_QUEUE_TRANSFER_BIT));
    EXPECT_EQ(q[1].queueFlags, VkQueueFlags(VK_QUEUE_COMPUTE_BIT | VK_QUEUE_TRANSFER_BIT));
    EXPECT_GE(q[1].queueCount, 1u);
    EXPECT_EQ(q[1].timestampValidBits, 64u);
    // A count of 1 gets family 0 only.
    uint32_t one = 1;
    VkQueueFamilyProperties first{};
    vkGetPhysicalDeviceQueueFamilyProperties(physicalDevice, &one, &first);
    EXPECT_EQ(one, 1u);
    EXPECT_EQ(first.queueFlags, q[0].queueFlags);
  }
}

TEST_F(DeviceTest, Properties2WalksTheWholeChainAndLeavesUnknownStructsAlone) {
  VkPhysicalDeviceVulkan13Properties p13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_PROPERTIES};
  // A structure of an extension vkrt does not implement (mesh shaders), placed in the middle of the chain:
  // vkrt must leave it untouched and continue the walk past it.
  VkPhysicalDeviceMeshShaderPropertiesEXT unknown{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MESH_SHADER_PROPERTIES_EXT, &p13};
  unknown.maxTaskWorkGroupTotalCount = 0xdeadbeef;
  VkPhysicalDeviceDriverProperties driver{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES, &unknown};
  VkPhysicalDeviceVulkan12Properties p12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_PROPERTIES, &driver};
  VkPhysicalDeviceVulkan11Properties p11{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_PROPERTIES, &p12};
  VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &p11};
  vkGetPhysicalDeviceProperties2(physicalDevice, &p2);
  EXPECT_EQ(p11.pNext, &p12);
  EXPECT_EQ(p12.pNext, &driver);
  EXPECT_EQ(driver.pNext, &unknown);
  EXPECT_EQ(unknown.pNext, &p13);
  if (onVkrt()) {  // another driver may implement mesh shaders and fill the structure
    EXPECT_STREQ(p2.properties.deviceName, "vkrt");
    EXPECT_EQ(unknown.maxTaskWorkGroupTotalCount, 0xdeadbeefu);
    EXPECT_EQ(unknown.maxMeshOutputVertices, 0u);
    EXPECT_STREQ(driver.driverName, "vkrt");
    EXPECT_STREQ(p12.driverName, "vkrt");
  }
  EXPECT_GT(p11.maxMemoryAllocationSize, 0u);
  EXPECT_GT(p13.maxBufferSize, 0u);
  if (onVkrt()) {
    EXPECT_EQ(std::memcmp(p11.deviceUUID, p2.properties.pipelineCacheUUID, VK_UUID_SIZE), 0);
  }
}

TEST_F(DeviceTest, Features2ReportsWhatTheDeviceEnables) {
  VkPhysicalDeviceBufferDeviceAddressFeatures bda{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_BUFFER_DEVICE_ADDRESS_FEATURES};
  VkPhysicalDeviceTimelineSemaphoreFeatures ts{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_TIMELINE_SEMAPHORE_FEATURES, &bda};
  VkPhysicalDeviceVulkan13Features f13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES, &ts};
  VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &f13};
  vkGetPhysicalDeviceFeatures2(physicalDevice, &f2);
  EXPECT_TRUE(bda.bufferDeviceAddress);
  EXPECT_TRUE(bda.bufferDeviceAddressCaptureReplay);
  EXPECT_TRUE(ts.timelineSemaphore);
  EXPECT_TRUE(f13.synchronization2);
  EXPECT_EQ(f13.pNext, &ts);
}

TEST_F(DeviceTest, UnimplementedOrDisabledEntryPointsAreNull) {
  // A real command from an extension vkrt does not implement.
  EXPECT_EQ(vkGetDeviceProcAddr(device, "vkCmdDrawMeshTasksEXT"), nullptr);
  // Not a command at all.
  EXPECT_EQ(vkGetDeviceProcAddr(device, "vkNotARealCommand"), nullptr);
  // Implemented core commands resolve.
  EXPECT_NE(vkGetDeviceProcAddr(device, "vkCreateBuffer"), nullptr);
  EXPECT_NE(vkGetDeviceProcAddr(device, "vkGetBufferDeviceAddress"), nullptr);
}

TEST_F(DeviceTest, MemoryMapsAndKeepsItsBytes) {
  HostBuffer b = createHostBuffer(4096, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  auto* bytes = static_cast<uint8_t*>(b.data);
  for (int i = 0; i < 4096; ++i) EXPECT_EQ(bytes[i], 0) << "fresh memory is zeroed";
  for (int i = 0; i < 4096; ++i) bytes[i] = static_cast<uint8_t>(i * 7);
  vkUnmapMemory(device, b.memory);
  void* again = nullptr;
  ASSERT_EQ(vkMapMemory(device, b.memory, 1024, 1024, 0, &again), VK_SUCCESS);
  for (int i = 0; i < 1024; ++i) EXPECT_EQ(static_cast<uint8_t*>(again)[i], static_cast<uint8_t>((i + 1024) * 7));
  VkMappedMemoryRange range{VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE, nullptr, b.memory, 1024, VK_WHOLE_SIZE};
  EXPECT_EQ(vkFlushMappedMemoryRanges(device, 1, &range), VK_SUCCESS);
  EXPECT_EQ(vkInvalidateMappedMemoryRanges(device, 1, &range), VK_SUCCESS);
  destroy(b);
}

TEST_F(DeviceTest, BufferDeviceAddressIsTheBufferStart) {
  HostBuffer a = createHostBuffer(256, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true);
  HostBuffer b = createHostBuffer(256, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true);
  VkBufferDeviceAddressInfo ia{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO, nullptr, a.buffer};
  VkBufferDeviceAddressInfo ib{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO, nullptr, b.buffer};
  VkDeviceAddress addrA = vkGetBufferDeviceAddress(device, &ia);
  VkDeviceAddress addrB = vkGetBufferDeviceAddress(device, &ib);
  EXPECT_NE(addrA, 0u);
  EXPECT_NE(addrB, 0u);
  EXPECT_TRUE(addrB >= addrA + 256 || addrA >= addrB + 256) << "buffers must not overlap";
  destroy(a);
  destroy(b);
}

class MemoryMisuseTest : public VulkanTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o;
    o.validation = false;  // rules are broken on purpose; vkrt's own messages are asserted
    return o;
  }
};

TEST_F(MemoryMisuseTest, MappingAndFlushRulesAreReportedByVuid) {
  HostBuffer b = createHostBuffer(4096, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);  // mapped whole
  void* p = nullptr;
  EXPECT_EQ(vkMapMemory(device, b.memory, 0, VK_WHOLE_SIZE, 0, &p), VK_ERROR_MEMORY_MAP_FAILED);
  expectVkrtMessage("VUID-vkMapMemory-memory-00678");
  vkUnmapMemory(device, b.memory);
  ASSERT_EQ(vkMapMemory(device, b.memory, 1024, 1024, 0, &p), VK_SUCCESS);
  VkMappedMemoryRange before{VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE, nullptr, b.memory, 0, VK_WHOLE_SIZE};
  EXPECT_EQ(vkFlushMappedMemoryRanges(device, 1, &before), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkMappedMemoryRange-size-00686");
  VkMappedMemoryRange past{VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE, nullptr, b.memory, 1024, 2048};
  EXPECT_EQ(vkInvalidateMappedMemoryRanges(device, 1, &past), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkMappedMemoryRange-size-00685");
  EXPECT_EQ(vkMapMemory(device, b.memory, 8192, VK_WHOLE_SIZE, 0, &p), VK_ERROR_MEMORY_MAP_FAILED);
  expectVkrtMessage("VUID-vkMapMemory-memory-00678");
  vkUnmapMemory(device, b.memory);
  EXPECT_EQ(vkMapMemory(device, b.memory, 8192, VK_WHOLE_SIZE, 0, &p), VK_ERROR_MEMORY_MAP_FAILED);
  expectVkrtMessage("VUID-vkMapMemory-offset-00679");
  destroy(b);
}

// True when the physical device is vkrt: checks of vkrt's own address layout and messages run on vkrt only.
bool isVkrt(VkPhysicalDevice pd) {
  VkPhysicalDeviceProperties p;
  vkGetPhysicalDeviceProperties(pd, &p);
  return std::strcmp(p.deviceName, "vkrt") == 0;
}

TEST_F(MemoryMisuseTest, StaleHandlesAreReportedNotDereferenced) {
  HostBuffer b = createHostBuffer(256, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  VkBuffer stale = b.buffer;
  VkDeviceMemory staleMemory = b.memory;
  destroy(b);
  vkDestroyBuffer(device, stale, nullptr);
  expectVkrtMessage("VUID-vkDestroyBuffer-buffer-parameter");
  vkFreeMemory(device, staleMemory, nullptr);
  expectVkrtMessage("VUID-vkFreeMemory-memory-parameter");
  vkDestroyBuffer(device, VK_NULL_HANDLE, nullptr);  // null is allowed and ignored
  EXPECT_TRUE(vkrtMessages().empty());
}

class BufferCaptureReplayTest : public VulkanTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o;
    o.bufferDeviceAddressCaptureReplay = true;
    return o;
  }

  // A memory type that the test's buffers (see buffer()) may be bound to, device-local.
  uint32_t bufferMemoryType() {
    VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    bci.flags = VK_BUFFER_CREATE_DEVICE_ADDRESS_CAPTURE_REPLAY_BIT;
    bci.size = 1024;
    bci.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;
    VkBuffer b = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreateBuffer(device, &bci, nullptr, &b), VK_SUCCESS);
    VkMemoryRequirements req{};
    vkGetBufferMemoryRequirements(device, b, &req);
    vkDestroyBuffer(device, b, nullptr);
    return memoryTypeIndex(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  }

  // `captureReplay` false: an ordinary allocation (device address, no capture/replay).
  VkDeviceMemory allocate(VkDeviceSize size, uint64_t captured, VkResult expected, bool captureReplay = true) {
    VkMemoryOpaqueCaptureAddressAllocateInfo cap{VK_STRUCTURE_TYPE_MEMORY_OPAQUE_CAPTURE_ADDRESS_ALLOCATE_INFO};
    cap.opaqueCaptureAddress = captured;
    VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO, captured ? &cap : nullptr};
    flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT |
                  (captureReplay ? VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_CAPTURE_REPLAY_BIT : 0);
    VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, &flags, size, bufferMemoryType()};
    VkDeviceMemory mem = VK_NULL_HANDLE;
    EXPECT_EQ(vkAllocateMemory(device, &mai, nullptr, &mem), expected);
    return mem;
  }

  VkBuffer buffer(VkDeviceMemory mem, VkDeviceSize offset, uint64_t captured) {
    VkBufferOpaqueCaptureAddressCreateInfo cap{VK_STRUCTURE_TYPE_BUFFER_OPAQUE_CAPTURE_ADDRESS_CREATE_INFO};
    cap.opaqueCaptureAddress = captured;
    VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO, captured ? &cap : nullptr};
    bci.flags = VK_BUFFER_CREATE_DEVICE_ADDRESS_CAPTURE_REPLAY_BIT;
    bci.size = 1024;
    bci.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;
    VkBuffer b = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreateBuffer(device, &bci, nullptr, &b), VK_SUCCESS);
    EXPECT_EQ(vkBindBufferMemory(device, b, mem, offset), VK_SUCCESS);
    return b;
  }
};

TEST_F(BufferCaptureReplayTest, ReplayedMemoryAndBufferGetTheCapturedAddresses) {
  const bool vkrt = isVkrt(physicalDevice);
  VkDeviceMemory mem = allocate(1 << 20, 0, VK_SUCCESS);
  VkBuffer buf = buffer(mem, 4096, 0);
  VkDeviceMemoryOpaqueCaptureAddressInfo mi{VK_STRUCTURE_TYPE_DEVICE_MEMORY_OPAQUE_CAPTURE_ADDRESS_INFO, nullptr, mem};
  uint64_t memCapture = vkGetDeviceMemoryOpaqueCaptureAddress(device, &mi);
  VkBufferDeviceAddressInfo bi{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO, nullptr, buf};
  uint64_t bufCapture = vkGetBufferOpaqueCaptureAddress(device, &bi);
  VkDeviceAddress address = vkGetBufferDeviceAddress(device, &bi);
  ASSERT_NE(address, 0u);
  if (vkrt) {
    // vkrt's opaque capture address of memory is its device address (the spec keeps it opaque).
    ASSERT_NE(memCapture, 0u);
    EXPECT_EQ(address, memCapture + 4096);
  }
  vkDestroyBuffer(device, buf, nullptr);
  vkFreeMemory(device, mem, nullptr);

  // On vkrt, an ordinary allocation in between must not take the replayed range. The spec only says drivers are
  // "expected to separate such buffers" from normal allocations (and tells applications not to mix replayed and
  // new capture/replay addresses), so on other drivers the replay follows the capture directly.
  VkDeviceMemory other = vkrt ? allocate(1 << 16, 0, VK_SUCCESS, /*captureReplay=*/false) : VK_NULL_HANDLE;
  VkDeviceMemory replayed = allocate(1 << 20, memCapture, VK_SUCCESS);
  VkBuffer replayedBuf = buffer(replayed, 4096, bufCapture);
  VkBufferDeviceAddressInfo ri{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO, nullptr, replayedBuf};
  // What the spec promises: the replayed buffer has the original device address, and replayed objects report the
  // (non-zero) opaque capture addresses they were created with.
  EXPECT_EQ(vkGetBufferDeviceAddress(device, &ri), address);
  if (bufCapture) {
    EXPECT_EQ(vkGetBufferOpaqueCaptureAddress(device, &ri), bufCapture);
  }
  VkDeviceMemoryOpaqueCaptureAddressInfo rmi{VK_STRUCTURE_TYPE_DEVICE_MEMORY_OPAQUE_CAPTURE_ADDRESS_INFO, nullptr,
                                             replayed};
  if (memCapture) {
    EXPECT_EQ(vkGetDeviceMemoryOpaqueCaptureAddress(device, &rmi), memCapture);
  }
  vkDestroyBuffer(device, replayedBuf, nullptr);
  if (other) vkFreeMemory(device, other, nullptr);
  vkFreeMemory(device, replayed, nullptr);
}

// The CTS's ray_tracing_pipeline.capture_replay.shader_binding_tables.pipeline_before_captured: a capture/replay
// buffer captured on ordinary memory (DEVICE_ADDRESS without CAPTURE_REPLAY, no memory capture address); on
// replay ordinary allocations come first (where the capture's memory was), then the buffer is created with its
// opaque capture address and bound to new ordinary memory. It must get the captured device address, and that
// address must reach the bytes of the memory it is bound to.
TEST_F(BufferCaptureReplayTest, ABufferCapturedOnOrdinaryMemoryReplaysItsAddressAfterOtherAllocations) {
  const bool vkrt = isVkrt(physicalDevice);
  VkDeviceMemory mem = allocate(4096, 0, VK_SUCCESS, /*captureReplay=*/false);
  VkBuffer buf = buffer(mem, 0, 0);
  VkBufferDeviceAddressInfo bi{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO, nullptr, buf};
  const uint64_t captured = vkGetBufferOpaqueCaptureAddress(device, &bi);
  const VkDeviceAddress address = vkGetBufferDeviceAddress(device, &bi);
  ASSERT_NE(address, 0u);
  vkDestroyBuffer(device, buf, nullptr);
  vkFreeMemory(device, mem, nullptr);

  // Replay: first the ordinary allocations (the CTS's first pipeline's tables), bound to ordinary buffers.
  std::vector<VkDeviceMemory> others;
  std::vector<VkBuffer> otherBuffers;
  for (int k = 0; k < 3; ++k) {
    others.push_back(allocate(4096, 0, VK_SUCCESS, /*captureReplay=*/false));
    VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    bci.size = 1024;
    bci.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;
    VkBuffer b = VK_NULL_HANDLE;
    ASSERT_EQ(vkCreateBuffer(device, &bci, nullptr, &b), VK_SUCCESS);
    ASSERT_EQ(vkBindBufferMemory(device, b, others.back(), 0), VK_SUCCESS);
    otherBuffers.push_back(b);
  }
  VkDeviceMemory replayedMem = allocate(4096, 0, VK_SUCCESS, /*captureReplay=*/false);
  uint32_t* mapped = nullptr;
  ASSERT_EQ(vkMapMemory(device, replayedMem, 0, VK_WHOLE_SIZE, 0, reinterpret_cast<void**>(&mapped)), VK_SUCCESS);
  for (uint32_t i = 0; i < 256; ++i) mapped[i] = 0xC0DE0000u + i;
  VkBuffer replayed = buffer(replayedMem, 0, captured);
  VkBufferDeviceAddressInfo ri{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO, nullptr, replayed};
  EXPECT_EQ(vkGetBufferDeviceAddress(device, &ri), address);
  if (captured) {
    EXPECT_EQ(vkGetBufferOpaqueCaptureAddress(device, &ri), captured);
  }
  if (vkrt) {
    // vkrt's device address is the host address of the bytes: the memory's bytes are seen there, and the other way.
    auto* at = reinterpret_cast<uint32_t*>(address);
    for (uint32_t i = 0; i < 256; ++i) ASSERT_EQ(at[i], 0xC0DE0000u + i) << i;
    at[7] = 77;
    EXPECT_EQ(mapped[7], 77u);
  }
  vkUnmapMemory(device, replayedMem);
  vkDestroyBuffer(device, replayed, nullptr);
  vkFreeMemory(device, replayedMem, nullptr);
  for (VkBuffer b : otherBuffers) vkDestroyBuffer(device, b, nullptr);
  for (VkDeviceMemory m : others) vkFreeMemory(device, m, nullptr);
  if (vkrt) {
    // The replayed buffer's address range is free again once the buffer is gone.
    VkDeviceMemory again = allocate(4096, address, VK_SUCCESS);
    vkFreeMemory(device, again, nullptr);
  }
}

class BufferCaptureReplayMisuseTest : public BufferCaptureReplayTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o = BufferCaptureReplayTest::options();
    o.validation = false;  // the range is taken on purpose
    return o;
  }
};

TEST_F(BufferCaptureReplayMisuseTest, AddressAlreadyInUseFailsWithInvalidOpaqueCaptureAddress) {
  // vkrt's message (and its refusal) for an address in use; the layer is off, so other drivers are not asked.
  if (!isVkrt(physicalDevice)) GTEST_SKIP() << "vkrt's own diagnostics";
  VkDeviceMemory mem = allocate(1 << 16, 0, VK_SUCCESS);
  VkDeviceMemoryOpaqueCaptureAddressInfo mi{VK_STRUCTURE_TYPE_DEVICE_MEMORY_OPAQUE_CAPTURE_ADDRESS_INFO, nullptr, mem};
  uint64_t taken = vkGetDeviceMemoryOpaqueCaptureAddress(device, &mi);
  VkDeviceMemory clash = allocate(1 << 16, taken, VK_ERROR_INVALID_OPAQUE_CAPTURE_ADDRESS);
  EXPECT_EQ(clash, VK_NULL_HANDLE);
  auto msgs = vkrtMessages();
  ASSERT_EQ(msgs.size(), 1u);
  EXPECT_NE(msgs[0].text.find("opaque capture address"), std::string::npos) << msgs[0].text;
  // The message names the range and the part of it that is held.
  char range[64];
  std::snprintf(range, sizeof(range), "[0x%llx, 0x%llx) of it is held", (unsigned long long)taken,
                (unsigned long long)(taken + (1 << 16)));
  EXPECT_NE(msgs[0].text.find(range), std::string::npos) << msgs[0].text;
  clearMessages();
  vkFreeMemory(device, mem, nullptr);
}

// A buffer replayed at an opaque capture address that other memory holds cannot be given it: vkBindBufferMemory
// returns VK_ERROR_INVALID_OPAQUE_CAPTURE_ADDRESS (which the specification allows) and says where the range is held.
TEST_F(BufferCaptureReplayMisuseTest, ABufferReplayedAtAnAddressInUseFailsToBind) {
  if (!isVkrt(physicalDevice)) GTEST_SKIP() << "vkrt's own diagnostics";
  VkDeviceMemory holder = allocate(1 << 16, 0, VK_SUCCESS, /*captureReplay=*/false);
  VkDeviceMemoryOpaqueCaptureAddressInfo mi{VK_STRUCTURE_TYPE_DEVICE_MEMORY_OPAQUE_CAPTURE_ADDRESS_INFO, nullptr,
                                            holder};
  const uint64_t taken = vkGetDeviceMemoryOpaqueCaptureAddress(device, &mi);
  VkDeviceMemory mem = allocate(4096, 0, VK_SUCCESS, /*captureReplay=*/false);
  VkBufferOpaqueCaptureAddressCreateInfo cap{VK_STRUCTURE_TYPE_BUFFER_OPAQUE_CAPTURE_ADDRESS_CREATE_INFO};
  VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO, &cap};
  bci.flags = VK_BUFFER_CREATE_DEVICE_ADDRESS_CAPTURE_REPLAY_BIT;
  bci.size = 1024;
  bci.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;
  for (uint64_t requested : {taken + 4096, taken + 4096 + 64}) {  // held; then also off the binding's page offset
    cap.opaqueCaptureAddress = requested;
    VkBuffer b = VK_NULL_HANDLE;
    ASSERT_EQ(vkCreateBuffer(device, &bci, nullptr, &b), VK_SUCCESS);
    EXPECT_EQ(vkBindBufferMemory(device, b, mem, 0), VK_ERROR_INVALID_OPAQUE_CAPTURE_ADDRESS);
    auto msgs = vkrtMessages();
    ASSERT_EQ(msgs.size(), 1u);
    const char* why = requested % 4096 ? "offset within a 4096-byte page differs" : "of it is held";
    EXPECT_NE(msgs[0].text.find(why), std::string::npos) << msgs[0].text;
    clearMessages();
    vkDestroyBuffer(device, b, nullptr);
  }
  vkFreeMemory(device, mem, nullptr);
  vkFreeMemory(device, holder, nullptr);
}

// Core commands of features vkrt does not support still resolve (a 1.3 driver's core commands are never NULL),
// and a call, which is always invalid on vkrt, is reported and has no effect.
class UnsupportedCoreFeatureTest : public MemoryMisuseTest {};

TEST_F(UnsupportedCoreFeatureTest, SparseBindingAndYcbcrConversionResolveAndReportTheirRule) {
  auto bindSparse = reinterpret_cast<PFN_vkQueueBindSparse>(vkGetDeviceProcAddr(device, "vkQueueBindSparse"));
  auto createConversion = reinterpret_cast<PFN_vkCreateSamplerYcbcrConversion>(
      vkGetDeviceProcAddr(device, "vkCreateSamplerYcbcrConversion"));
  auto destroyConversion = reinterpret_cast<PFN_vkDestroySamplerYcbcrConversion>(
      vkGetDeviceProcAddr(device, "vkDestroySamplerYcbcrConversion"));
  ASSERT_NE(bindSparse, nullptr);
  ASSERT_NE(createConversion, nullptr);
  ASSERT_NE(destroyConversion, nullptr);
  if (!onVkrt()) GTEST_SKIP() << "the rules below hold where sparse binding and Y'CbCr conversion are unsupported";

  // The queue family has no sparse binding: a bind, even an empty one with a fence, is reported and the fence is
  // not signalled.
  uint32_t count = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(physicalDevice, &count, nullptr);
  std::vector<VkQueueFamilyProperties> families(count);
  vkGetPhysicalDeviceQueueFamilyProperties(physicalDevice, &count, families.data());
  for (const VkQueueFamilyProperties& f : families) EXPECT_FALSE(f.queueFlags & VK_QUEUE_SPARSE_BINDING_BIT);
  VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  VkFence fence = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateFence(device, &fci, nullptr, &fence), VK_SUCCESS);
  VkBindSparseInfo bind{VK_STRUCTURE_TYPE_BIND_SPARSE_INFO};
  EXPECT_EQ(bindSparse(queue, 1, &bind, fence), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-vkQueueBindSparse-queuetype");
  EXPECT_EQ(vkGetFenceStatus(device, fence), VK_NOT_READY);
  vkDestroyFence(device, fence, nullptr);

  // samplerYcbcrConversion is not supported, so no conversion is created.
  VkPhysicalDeviceVulkan11Features f11{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES};
  VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &f11};
  vkGetPhysicalDeviceFeatures2(physicalDevice, &f2);
  EXPECT_FALSE(f11.samplerYcbcrConversion);
  VkSamplerYcbcrConversionCreateInfo ci{VK_STRUCTURE_TYPE_SAMPLER_YCBCR_CONVERSION_CREATE_INFO};
  ci.format = VK_FORMAT_G8_B8R8_2PLANE_420_UNORM;
  ci.ycbcrModel = VK_SAMPLER_YCBCR_MODEL_CONVERSION_YCBCR_709;
  ci.ycbcrRange = VK_SAMPLER_YCBCR_RANGE_ITU_FULL;
  ci.chromaFilter = VK_FILTER_NEAREST;
  VkSamplerYcbcrConversion conversion = VK_NULL_HANDLE;
  EXPECT_EQ(createConversion(device, &ci, nullptr, &conversion), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-vkCreateSamplerYcbcrConversion-None-01648");
  EXPECT_EQ(conversion, VK_NULL_HANDLE);

  // Destroying VK_NULL_HANDLE is valid and silent; any other handle cannot be a live conversion.
  destroyConversion(device, VK_NULL_HANDLE, nullptr);
  EXPECT_TRUE(vkrtMessages().empty());
  destroyConversion(device, reinterpret_cast<VkSamplerYcbcrConversion>(uintptr_t(0x1234560)), nullptr);
  expectVkrtMessage("VUID-vkDestroySamplerYcbcrConversion-ycbcrConversion-parameter");
}

}  // namespace
}  // namespace vkrt::test
