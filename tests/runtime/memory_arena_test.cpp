// The device address arena (runtime/memory.hpp): reserved at the base docs/handles-and-capture-replay.md documents,
// in every build (release, AddressSanitizer, ThreadSanitizer), so that opaque capture addresses mean the same in
// every process.
#include <gtest/gtest.h>

#include <cstring>

#include "runtime/memory.hpp"

namespace vkrt {
namespace {

TEST(DeviceAddressArena, IsReservedAtTheDocumentedBase) {
  EXPECT_EQ(arena::baseAddress(), 0x567000000000ull);
  EXPECT_EQ(arena::capacity(), 64ull << 30);
  // Allocated memory there is usable, and given back.
  uint8_t* p = arena::allocate(1 << 20, 0, false);
  ASSERT_NE(p, nullptr);
  EXPECT_TRUE(arena::contains(reinterpret_cast<uint64_t>(p), 1 << 20));
  std::memset(p, 0x5A, 1 << 20);
  EXPECT_EQ(p[(1 << 20) - 1], 0x5A);
  EXPECT_TRUE(arena::accessible(reinterpret_cast<uint64_t>(p), 1 << 20));
  arena::release(p, 1 << 20);
  EXPECT_FALSE(arena::accessible(reinterpret_cast<uint64_t>(p), 1 << 20));
}

}  // namespace
}  // namespace vkrt
