// Unit tests of the compiler below the Vulkan API: PhysicalStorageBuffer64 pointers and 8/16-bit storage
// through the compute harness.
#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <cstring>
#include <vector>

#include "compute_bda_linked_list.comp.spv.h"
#include "compute_small_types.comp.spv.h"
#include "spirv/compute_harness.hpp"
#include "spirv/small_types_reference.hpp"

namespace vkrt {
namespace {

// Nodes of the linked list compute_bda_linked_list.comp walks (std430: v at 0, next at 16, tag at 24; 32 bytes).
struct Node {
  float v[4];
  uint64_t next;
  uint32_t tag;
  uint32_t pad;
};
static_assert(sizeof(Node) == 32);

TEST(SpirvCompilerBda, LinkedListThroughDeviceAddresses) {
  testing::ComputeHarness h;
  ASSERT_TRUE(h.compile(kSpv_compute_bda_linked_list_comp)) << h.error;
  std::vector<Node> nodes(5);
  for (uint32_t k = 0; k < 5; ++k) {
    nodes[k] = Node{{float(10 * k + 1), float(k + 7), 0.0f, -1.0f}, 0, 100 + k, 0};
    nodes[k].next = reinterpret_cast<uint64_t>(&nodes[(k + 1) % 5]);
  }
  const uint32_t count = 37;
  std::vector<uint32_t> words(2 * count + 1, 0xDEADBEEF);
  uint64_t head = reinterpret_cast<uint64_t>(nodes.data()), out = reinterpret_cast<uint64_t>(words.data());
  std::memcpy(h.push, &head, 8);
  std::memcpy(h.push + 8, &out, 8);
  std::memcpy(h.push + 16, &count, 4);
  ASSERT_TRUE(h.run(3));
  for (uint32_t i = 0; i < count; ++i) {
    uint32_t steps = i % 5, sum = 0;
    for (uint32_t s = 0; s < steps; ++s) sum += 100 + s;
    EXPECT_EQ(words[2 * i], sum + 10 * steps + 1) << i;
    EXPECT_EQ(words[2 * i + 1], (100 + i % 5) * 1000 + (i % 5) + 7) << i;
  }
  EXPECT_EQ(words[2 * count], 0xDEADBEEF);  // nothing past the count
  for (uint32_t k = 0; k < 5; ++k) {
    EXPECT_EQ(nodes[k].v[3], float(k * 3)) << k;
    EXPECT_EQ(nodes[k].v[0], float(10 * k + 1));
    EXPECT_EQ(nodes[k].tag, 100 + k);
  }
}

TEST(SpirvCompilerSmallTypes, EightAndSixteenBitStorageAndArithmetic) {
  testing::ComputeHarness h;
  ASSERT_TRUE(h.compile(kSpv_compute_small_types_comp)) << h.error;
  using namespace vkrt::testing;
  SmallIn in = smallInput();
  h.setBuffer(0, std::vector<SmallIn>{in});
  h.zeroBuffer<uint8_t>(1, offsetof(SmallOut, hmathFused));
  ASSERT_TRUE(h.run(2));
  SmallOut got{};
  std::vector<uint8_t> bytes = h.get<uint8_t>(1);
  std::memcpy(&got, bytes.data(), bytes.size());
  expectSmall(got, smallExpected(in));
}

}  // namespace
}  // namespace vkrt
