// exec::AddressTable (VKRT_SHADER_CHECKS=bda, docs/shader-debugging.md): which accesses lie inside one live buffer,
// with aliasing and nested ranges, and the buffer a report names as the nearest.
#include <gtest/gtest.h>

#include "exec/shader_debug.hpp"

namespace vkrt::exec {
namespace {

AddressTable table(std::vector<AddressRange> ranges) {
  AddressTable t;
  t.assign(std::move(ranges));
  return t;
}

TEST(AddressTable, AnAccessMustLieInsideOneRange) {
  // Given out of order: [0x1000, 0x1040) 'a', [0x2000, 0x3000) 'b'.
  AddressTable t = table({{0x2000, 0x3000, 2}, {0x1000, 0x1040, 1}});
  EXPECT_TRUE(t.contains(0x1000, 4));
  EXPECT_TRUE(t.contains(0x103c, 4));   // the last word
  EXPECT_FALSE(t.contains(0x103e, 4));  // across the end
  EXPECT_FALSE(t.contains(0x1040, 4));  // just past it
  EXPECT_FALSE(t.contains(0x0ffc, 4));  // before the first
  EXPECT_FALSE(t.contains(0x1800, 4));  // between them
  EXPECT_TRUE(t.contains(0x2ff0, 16));
  EXPECT_FALSE(t.contains(0x3000, 1));
  EXPECT_FALSE(t.contains(UINT64_MAX - 1, 4));  // the end wraps: not inside
  EXPECT_FALSE(table({}).contains(0x1000, 4));
}

TEST(AddressTable, AliasingAndNestedBuffers) {
  // A large buffer with a smaller one inside it (two buffers bound to the same memory): an access past the small
  // one's end is still inside the large one; one past both is not.
  AddressTable t = table({{0x1000, 0x2000, 1}, {0x1100, 0x1110, 2}, {0x5000, 0x5010, 3}});
  EXPECT_TRUE(t.contains(0x1108, 16));
  EXPECT_TRUE(t.contains(0x1800, 4));
  EXPECT_FALSE(t.contains(0x1ffe, 4));
  EXPECT_FALSE(t.contains(0x4ffc, 8));
}

TEST(AddressTable, TheNearestRangeNamesTheReport) {
  AddressTable t = table({{0x1000, 0x1040, 1}, {0x2000, 0x3000, 2}});
  EXPECT_EQ(t.nearest(0x1020)->object, 1u);  // inside (an access across its end)
  EXPECT_EQ(t.nearest(0x1048)->object, 1u);  // 8 past the end of the first
  EXPECT_EQ(t.nearest(0x1ff0)->object, 2u);  // 16 before the second
  EXPECT_EQ(t.nearest(0x10)->object, 1u);
  EXPECT_EQ(table({}).nearest(0x1000), nullptr);
}

}  // namespace
}  // namespace vkrt::exec
