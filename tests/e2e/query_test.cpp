// Timestamp queries: host and command-buffer resets, vkCmdWriteTimestamp(2), results and copies.
#include <time.h>

#include <cstdint>
#include <cstring>

#include "e2e/fixture.hpp"

namespace vkrt::test {
namespace {

uint64_t monotonicNs() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return uint64_t(ts.tv_sec) * 1000000000ull + uint64_t(ts.tv_nsec);
}

// True when the physical device is vkrt: its timestamps are host CLOCK_MONOTONIC nanoseconds (timestampPeriod 1),
// which the spec does not promise of other drivers, so the relations with the host clock are checked on vkrt only.
bool isVkrt(VkPhysicalDevice pd) {
  VkPhysicalDeviceProperties p;
  vkGetPhysicalDeviceProperties(pd, &p);
  return std::strcmp(p.deviceName, "vkrt") == 0;
}

// A 32-bit result of a value that overflows 32 bits "may either wrap or saturate" (vkGetQueryPoolResults); vkrt
// wraps (its choice, asserted on vkrt only).
bool is32BitResultOf(uint32_t low, uint64_t full, bool vkrt) {
  if (low == static_cast<uint32_t>(full)) return true;
  return !vkrt && full > UINT32_MAX && low == UINT32_MAX;
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
  const bool vkrt = isVkrt(physicalDevice);
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(physicalDevice, &props);
  if (vkrt) {
    EXPECT_EQ(props.limits.timestampPeriod, 1.0f);  // host nanoseconds
  } else {
    EXPECT_GT(props.limits.timestampPeriod, 0.0f);
  }
  uint32_t familyCount = 1;
  VkQueueFamilyProperties family;
  vkGetPhysicalDeviceQueueFamilyProperties(physicalDevice, &familyCount, &family);  // family 0, the fixture's
  ASSERT_GE(family.timestampValidBits, 36u) << "timestamps are not supported on queue family 0";

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
  // Without VK_QUERY_RESULT_WAIT_BIT a copy may run before the timestamps are written (NVIDIA's does: it then
  // reports them unavailable), so the written queries are copied with it. Query 3 stays unavailable: it is
  // copied on its own without the bit (waiting for it would never end).
  vkCmdCopyQueryPoolResults(cb, pool, 0, 3, dst.buffer, 0, 16,
                            VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WITH_AVAILABILITY_BIT | VK_QUERY_RESULT_WAIT_BIT);
  vkCmdCopyQueryPoolResults(cb, pool, 3, 1, dst.buffer, 48, 16,
                            VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WITH_AVAILABILITY_BIT);
  vkCmdCopyQueryPoolResults(cb, pool, 0, 3, dst.buffer, 128, 4, VK_QUERY_RESULT_WAIT_BIT);  // 32-bit, packed
  // Waiting for the queue does not make device writes visible to the host: a barrier to the host stage does.
  VkMemoryBarrier toHost{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  toHost.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  toHost.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &toHost, 0, nullptr, 0,
                       nullptr);
  submitAndWait(cb);  // vkQueueWaitIdle before anything is read
  const uint64_t end = monotonicNs();

  uint64_t r[3][2] = {};
  ASSERT_EQ(
      vkGetQueryPoolResults(device, pool, 0, 3, sizeof r, r, 16,
                            VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT | VK_QUERY_RESULT_WITH_AVAILABILITY_BIT),
      VK_SUCCESS);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(r[i][1], 1u);
    if (vkrt) {  // vkrt's timestamps are CLOCK_MONOTONIC nanoseconds, taken while the submission ran
      EXPECT_GE(r[i][0], start);
      EXPECT_LE(r[i][0], end);
    }
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
    EXPECT_TRUE(is32BitResultOf(low, r[i][0], vkrt)) << low << " for " << r[i][0];
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
  EXPECT_TRUE(is32BitResultOf(r32[2], r[2][0], vkrt)) << r32[2] << " for " << r[2][0];

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
  EXPECT_EQ(p, VK_NULL_HANDLE);

  VkQueryPool pool = timestampPool(2);
  // Occlusion pools are created; a timestamp pool is not begun, a query not begun is not ended, PRECISE needs the
  // occlusionQueryPrecise feature (not enabled here), and one occlusion query is active at a time.
  ci.queryType = VK_QUERY_TYPE_OCCLUSION;
  ci.queryCount = 2;
  VkQueryPool occlusion = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateQueryPool(device, &ci, nullptr, &occlusion), VK_SUCCESS);
  EXPECT_TRUE(vkrtMessages().empty());
  VkCommandBuffer cb = beginOneTime();
  vkCmdBeginQuery(cb, pool, 0, 0);
  expectVkrtMessage("VUID-vkCmdBeginQuery-queryType-02804");
  vkCmdEndQuery(cb, occlusion, 0);
  expectVkrtMessage("VUID-vkCmdEndQuery-None-01923");
  vkCmdBeginQuery(cb, occlusion, 2, 0);
  expectVkrtMessage("VUID-vkCmdBeginQuery-query-00802");
  vkCmdBeginQuery(cb, occlusion, 0, VK_QUERY_CONTROL_PRECISE_BIT);
  expectVkrtMessage("VUID-vkCmdBeginQuery-queryType-00800");
  vkCmdResetQueryPool(cb, occlusion, 0, 2);
  vkCmdBeginQuery(cb, occlusion, 0, 0);
  vkCmdBeginQuery(cb, occlusion, 1, 0);
  expectVkrtMessage("VUID-vkCmdBeginQuery-queryPool-01922");
  vkCmdEndQuery(cb, occlusion, 0);
  EXPECT_TRUE(vkrtMessages().empty());
  submitAndWait(cb);
  uint64_t counts[2] = {7, 7};
  // Query 0 ran (no draw: 0 samples); query 1 was never begun, so it stays unavailable (VK_NOT_READY).
  EXPECT_EQ(vkGetQueryPoolResults(device, occlusion, 0, 1, 8, counts, 8, VK_QUERY_RESULT_64_BIT), VK_SUCCESS);
  EXPECT_EQ(counts[0], 0u);
  EXPECT_EQ(vkGetQueryPoolResults(device, occlusion, 1, 1, 8, counts + 1, 8, VK_QUERY_RESULT_64_BIT), VK_NOT_READY);
  vkDestroyQueryPool(device, occlusion, nullptr);

  vkResetQueryPool(device, pool, 0, 2);
  uint64_t r[4];
  EXPECT_EQ(
      vkGetQueryPoolResults(device, pool, 0, 1, sizeof r, r, 8, VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_PARTIAL_BIT),
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
