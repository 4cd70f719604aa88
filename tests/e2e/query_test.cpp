// Timestamp queries: host and command-buffer resets, vkCmdWriteTimestamp(2), results and copies.
#include <time.h>

#include <cstring>

#include "e2e/fixture.hpp"

namespace vkrt::test {
namespace {

uint64_t monotonicNs() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return uint64_t(ts.tv_sec) * 1000000000ull + uint64_t(ts.tv_nsec);
}

class QueryTest : public VulkanTest {
 protected:
  VkQueryPool timestampPool(uint32_t count) {
    VkQueryPoolCreateInfo ci{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
    ci.queryType = VK_QUERY_TYPE_TIMESTAMP;
    ci.queryCount = count;
    VkQueryPool p = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreateQueryPool(device, &ci, nullptr, &p), VK_SUCCESS);
    return p;
  }
};

TEST_F(QueryTest, TimestampsAreMonotonicNanoseconds) {
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(physicalDevice, &props);
  EXPECT_EQ(props.limits.timestampPeriod, 1.0f);

  VkQueryPool pool = timestampPool(4);
  vkResetQueryPool(device, pool, 0, 4);
  // Nothing written yet: VK_NOT_READY, availability 0, values untouched.
  uint64_t before[4][2];
  std::memset(before, 0x7f, sizeof before);
  EXPECT_EQ(vkGetQueryPoolResults(device, pool, 0, 2, sizeof before, before, 16,
                                  VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WITH_AVAILABILITY_BIT),
            VK_NOT_READY);
  EXPECT_EQ(before[0][1], 0u);
  EXPECT_EQ(before[1][1], 0u);
  EXPECT_EQ(before[0][0], 0x7f7f7f7f7f7f7f7full);

  HostBuffer dst = createHostBuffer(256, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  std::memset(dst.data, 0xee, 256);
  const uint64_t start = monotonicNs();
  VkCommandBuffer cb = beginOneTime();
  vkCmdResetQueryPool(cb, pool, 0, 4);
  vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, pool, 0);
  vkCmdWriteTimestamp2(cb, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, pool, 1);
  vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, pool, 2);
  // Query 3 stays unavailable.
  vkCmdCopyQueryPoolResults(cb, pool, 0, 4, dst.buffer, 0, 16,
                            VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WITH_AVAILABILITY_BIT);
  vkCmdCopyQueryPoolResults(cb, pool, 0, 3, dst.buffer, 128, 4, 0);  // 32-bit, packed
  submitAndWait(cb);
  const uint64_t end = monotonicNs();

  uint64_t r[3][2] = {};
  ASSERT_EQ(vkGetQueryPoolResults(device, pool, 0, 3, sizeof r, r, 16,
                                  VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT |
                                      VK_QUERY_RESULT_WITH_AVAILABILITY_BIT),
            VK_SUCCESS);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(r[i][1], 1u);
    EXPECT_GE(r[i][0], start);
    EXPECT_LE(r[i][0], end);
  }
  EXPECT_LE(r[0][0], r[1][0]);
  EXPECT_LE(r[1][0], r[2][0]);

  // The copies recorded in the command buffer saw the same values.
  auto* bytes = static_cast<const uint8_t*>(dst.data);
  for (int i = 0; i < 3; ++i) {
    uint64_t v, avail;
    std::memcpy(&v, bytes + 16 * i, 8);
    std::memcpy(&avail, bytes + 16 * i + 8, 8);
    EXPECT_EQ(v, r[i][0]);
    EXPECT_EQ(avail, 1u);
    uint32_t low;
    std::memcpy(&low, bytes + 128 + 4 * i, 4);
    EXPECT_EQ(low, static_cast<uint32_t>(r[i][0]));
  }
  uint64_t avail3;
  std::memcpy(&avail3, bytes + 16 * 3 + 8, 8);
  EXPECT_EQ(avail3, 0u);
  uint64_t untouched;
  std::memcpy(&untouched, bytes + 16 * 3, 8);
  EXPECT_EQ(untouched, 0xeeeeeeeeeeeeeeeeull) << "an unavailable query's value is not written";

  // 32-bit results from the host, and query 3 still not ready.
  uint32_t r32[4] = {};
  EXPECT_EQ(vkGetQueryPoolResults(device, pool, 0, 4, sizeof r32, r32, 4, 0), VK_NOT_READY);
  EXPECT_EQ(r32[2], static_cast<uint32_t>(r[2][0]));

  // A host reset makes them unavailable again.
  vkResetQueryPool(device, pool, 0, 4);
  EXPECT_EQ(vkGetQueryPoolResults(device, pool, 0, 1, sizeof r32, r32, 4, 0), VK_NOT_READY);
  destroy(dst);
  vkDestroyQueryPool(device, pool, nullptr);
}

class QueryMisuseTest : public QueryTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o;
    o.validation = false;
    return o;
  }
};

TEST_F(QueryMisuseTest, UnsupportedTypesAndBadArguments) {
  VkQueryPoolCreateInfo ci{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
  ci.queryCount = 1;
  VkQueryPool p = VK_NULL_HANDLE;
  ci.queryType = VK_QUERY_TYPE_PIPELINE_STATISTICS;
  EXPECT_NE(vkCreateQueryPool(device, &ci, nullptr, &p), VK_SUCCESS);
  expectVkrtMessage("VUID-VkQueryPoolCreateInfo-queryType-00791");
  ci.queryType = VK_QUERY_TYPE_OCCLUSION;
  EXPECT_NE(vkCreateQueryPool(device, &ci, nullptr, &p), VK_SUCCESS);
  expectVkrtMessage("VUID-VkQueryPoolCreateInfo-queryType-parameter");
  EXPECT_EQ(p, VK_NULL_HANDLE);

  VkQueryPool pool = timestampPool(2);
  vkResetQueryPool(device, pool, 0, 2);
  uint64_t r[4];
  EXPECT_EQ(vkGetQueryPoolResults(device, pool, 0, 1, sizeof r, r, 8, VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_PARTIAL_BIT),
            VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-vkGetQueryPoolResults-queryType-00818");
  EXPECT_EQ(vkGetQueryPoolResults(device, pool, 1, 2, sizeof r, r, 8, VK_QUERY_RESULT_64_BIT),
            VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-vkGetQueryPoolResults-firstQuery-00816");
  EXPECT_EQ(vkGetQueryPoolResults(device, pool, 0, 1, sizeof r, r, 4, VK_QUERY_RESULT_64_BIT),
            VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-vkGetQueryPoolResults-flags-00815");
  EXPECT_EQ(vkGetQueryPoolResults(device, pool, 0, 2, 12, r, 8, VK_QUERY_RESULT_64_BIT),
            VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-vkGetQueryPoolResults-dataSize-00817");
  vkResetQueryPool(device, pool, 2, 1);
  expectVkrtMessage("VUID-vkResetQueryPool-firstQuery-02666");
  vkDestroyQueryPool(device, pool, nullptr);
}

}  // namespace
}  // namespace vkrt::test
