// Scalar block layout (GL_EXT_scalar_block_layout) below the Vulkan API: vec3 followed by a float at offset 12,
// vec3 arrays with stride 12, a vec3 at offset 4, 20-byte structs, read and written; output compared byte by byte.
#include <gtest/gtest.h>

#include "compute_scalar_layout.comp.spv.h"
#include "spirv/compute_harness.hpp"
#include "spirv/scalar_layout_reference.hpp"

namespace vkrt::testing {
namespace {

TEST(SpirvBlockLayout, ScalarLayoutReadAndWritten) {
  ComputeHarness h;
  ASSERT_TRUE(h.compile(kSpv_compute_scalar_layout_comp)) << h.error;
  ScalarLayoutValues v;
  h.setBuffer(0, scalarInBlock(v));
  h.setBuffer(1, scalarUniformBlock(v));
  h.setBuffer(2, std::vector<uint8_t>(kScalarOutBytes, 0xcd));
  ASSERT_TRUE(h.run(kScalarInvocations / 4));
  std::vector<uint8_t> got = h.get<uint8_t>(2), want = scalarExpectedOut(v, 0xcd);
  ASSERT_EQ(got.size(), want.size());
  for (size_t i = 0; i < got.size(); ++i) EXPECT_EQ(int(got[i]), int(want[i])) << "byte " << i;
}

}  // namespace
}  // namespace vkrt::testing
