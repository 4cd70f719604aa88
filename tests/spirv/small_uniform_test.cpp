// 8- and 16-bit members of uniform and push-constant blocks (UniformAndStorageBuffer8/16BitAccess,
// StoragePushConstant8/16), below the Vulkan API.
#include <gtest/gtest.h>

#include "compute_small_uniform_push.comp.spv.h"
#include "spirv/compute_harness.hpp"
#include "spirv/small_uniform_reference.hpp"

namespace vkrt::testing {
namespace {

TEST(SpirvCompilerSmallTypes, UniformAndPushConstantMembers) {
  ComputeHarness h;
  ASSERT_TRUE(h.compile(kSpv_compute_small_uniform_push_comp)) << h.error;
  SmallUniformValues v;
  h.setBuffer(0, smallUniformBlock(v));
  std::vector<uint8_t> push = smallPushBlock(v);
  std::memcpy(h.push, push.data(), push.size());
  h.zeroBuffer<int32_t>(1, kSmallUniformInvocations * kSmallUniformInts);
  h.zeroBuffer<float>(2, kSmallUniformInvocations * kSmallUniformFloats);
  ASSERT_TRUE(h.run(kSmallUniformInvocations / 4));
  auto o = h.get<int32_t>(1);
  auto f = h.get<float>(2);
  expectSmallUniform(o.data(), f.data(), v);
  ASSERT_EQ(h.shader->resources.size(), 3u);
  for (const spirv::ResourceBinding& rb : h.shader->resources)
    EXPECT_EQ(rb.uniform, rb.binding == 0) << "binding " << rb.binding;
}

}  // namespace
}  // namespace vkrt::testing
