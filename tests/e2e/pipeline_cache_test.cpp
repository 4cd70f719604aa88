// Pipeline caches through the loader: the standard header, byte-exact round trips, foreign data ignored.
#include <cstring>
#include <vector>

#include "e2e/fixture.hpp"

namespace vkrt::test {
namespace {

using PipelineCacheTest = VulkanTest;

VkPipelineCache makeCache(VkDevice device, const std::vector<uint8_t>& initial = {}) {
  VkPipelineCacheCreateInfo ci{VK_STRUCTURE_TYPE_PIPELINE_CACHE_CREATE_INFO};
  ci.initialDataSize = initial.size();
  ci.pInitialData = initial.empty() ? nullptr : initial.data();
  VkPipelineCache c = VK_NULL_HANDLE;
  EXPECT_EQ(vkCreatePipelineCache(device, &ci, nullptr, &c), VK_SUCCESS);
  return c;
}

std::vector<uint8_t> dataOf(VkDevice device, VkPipelineCache c) {
  size_t size = 0;
  EXPECT_EQ(vkGetPipelineCacheData(device, c, &size, nullptr), VK_SUCCESS);
  std::vector<uint8_t> data(size);
  EXPECT_EQ(vkGetPipelineCacheData(device, c, &size, data.data()), VK_SUCCESS);
  EXPECT_EQ(size, data.size());
  return data;
}

TEST_F(PipelineCacheTest, HeaderMatchesThePhysicalDevice) {
  VkPipelineCache c = makeCache(device);
  std::vector<uint8_t> data = dataOf(device, c);
  ASSERT_GE(data.size(), sizeof(VkPipelineCacheHeaderVersionOne));
  VkPipelineCacheHeaderVersionOne h;
  std::memcpy(&h, data.data(), sizeof h);
  VkPhysicalDeviceProperties p;
  vkGetPhysicalDeviceProperties(physicalDevice, &p);
  EXPECT_EQ(h.headerSize, 32u);
  EXPECT_EQ(h.headerVersion, VK_PIPELINE_CACHE_HEADER_VERSION_ONE);
  EXPECT_EQ(h.vendorID, p.vendorID);
  EXPECT_EQ(h.deviceID, p.deviceID);
  EXPECT_EQ(std::memcmp(h.pipelineCacheUUID, p.pipelineCacheUUID, VK_UUID_SIZE), 0);
  vkDestroyPipelineCache(device, c, nullptr);
}

TEST_F(PipelineCacheTest, DataRoundTripsByteExactly) {
  VkPipelineCache a = makeCache(device);
  std::vector<uint8_t> first = dataOf(device, a);
  VkPipelineCache b = makeCache(device, first);
  EXPECT_EQ(dataOf(device, b), first);
  // Merging empty caches changes nothing.
  VkPipelineCache c = makeCache(device);
  ASSERT_EQ(vkMergePipelineCaches(device, c, 1, &a), VK_SUCCESS);
  EXPECT_EQ(dataOf(device, c), first);
  // A buffer too small for the header: nothing written, size 0.
  size_t small = 16;
  uint8_t sink[16] = {};
  EXPECT_EQ(vkGetPipelineCacheData(device, a, &small, sink), VK_INCOMPLETE);
  EXPECT_EQ(small, 0u);
  for (uint8_t byte : sink) EXPECT_EQ(byte, 0);
  vkDestroyPipelineCache(device, a, nullptr);
  vkDestroyPipelineCache(device, b, nullptr);
  vkDestroyPipelineCache(device, c, nullptr);
}

TEST_F(PipelineCacheTest, ForeignDataIsIgnored) {
  VkPipelineCache a = makeCache(device);
  std::vector<uint8_t> good = dataOf(device, a);
  std::vector<uint8_t> otherUuid = good;
  otherUuid[16] ^= 0x5a;  // inside pipelineCacheUUID
  std::vector<uint8_t> otherVendor = good;
  otherVendor[8] ^= 1;
  std::vector<uint8_t> garbage(200, 0xab);
  for (const auto& initial : {otherUuid, otherVendor, garbage}) {
    VkPipelineCache c = makeCache(device, initial);
    EXPECT_EQ(dataOf(device, c), good) << "the cache must start empty";
    vkDestroyPipelineCache(device, c, nullptr);
  }
  vkDestroyPipelineCache(device, a, nullptr);
}

class PipelineCacheMisuseTest : public VulkanTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o;
    o.validation = false;
    return o;
  }
};

TEST_F(PipelineCacheMisuseTest, MergeIntoItself) {
  VkPipelineCache a = makeCache(device);
  EXPECT_EQ(vkMergePipelineCaches(device, a, 1, &a), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-vkMergePipelineCaches-dstCache-00770");
  vkDestroyPipelineCache(device, a, nullptr);
}

}  // namespace
}  // namespace vkrt::test
