// The per-workgroup entry point (vkrt_group): generated for shaders without barriers (instead of the
// per-invocation vkrt_main), it must give every invocation its own built-ins and fresh private variables,
// and survive the pipeline cache's round trip.
#include <gtest/gtest.h>

#include "compute_harness.hpp"
#include "compute_shared.comp.spv.h"
#include "h10_group_builtins.comp.spv.h"

namespace vkrt::testing {
namespace {

constexpr uint32_t kSize[3] = {4, 3, 2};

// Dispatches 3x2x2 workgroups with a base of (1, 0, 2) (the push constants describe the whole grid, base
// included) and checks every invocation's record.
void runAndCheck(ComputeHarness& h) {
  const uint32_t count[3] = {3, 2, 2}, base[3] = {1, 0, 2};
  const uint32_t groups[3] = {count[0] + base[0], count[1] + base[1], count[2] + base[2]};
  const uint32_t width = groups[0] * kSize[0], height = groups[1] * kSize[1], depth = groups[2] * kSize[2];
  uint32_t push[2] = {groups[0], groups[1]};
  std::memcpy(h.push, push, sizeof push);
  const uint32_t sentinel = 0xdeadbeefu;
  h.setBuffer(0, std::vector<uint32_t>(size_t(width) * height * depth * 12, sentinel));
  ASSERT_TRUE(h.run(count[0], count[1], count[2], base[0], base[1], base[2]));
  std::vector<uint32_t> out = h.get<uint32_t>(0);
  size_t written = 0;
  for (uint32_t z = 0; z < depth; ++z)
    for (uint32_t y = 0; y < height; ++y)
      for (uint32_t x = 0; x < width; ++x) {
        const uint32_t g[3] = {x, y, z};
        const uint32_t* r = &out[((size_t(z) * height + y) * width + x) * 12];
        bool inDispatch = true;
        for (int i = 0; i < 3; ++i) inDispatch &= g[i] / kSize[i] >= base[i];
        if (!inDispatch) {
          for (int i = 0; i < 12; ++i) ASSERT_EQ(r[i], sentinel) << "outside the dispatch at " << x << "," << y << "," << z;
          continue;
        }
        ++written;
        uint32_t l[3], w[3];
        for (int i = 0; i < 3; ++i) {
          l[i] = g[i] % kSize[i];
          w[i] = g[i] / kSize[i];
        }
        uint32_t index = (l[2] * kSize[1] + l[1]) * kSize[0] + l[0];
        const uint32_t expect[12] = {x, y, z, index, l[0], l[1], l[2], 7 + index, w[0], w[1], w[2], count[0]};
        for (int i = 0; i < 12; ++i)
          ASSERT_EQ(r[i], expect[i]) << "field " << i << " of invocation " << x << "," << y << "," << z;
      }
  EXPECT_EQ(written, size_t(count[0]) * count[1] * count[2] * 24);
}

TEST(SpirvGroupEntry, BuiltInsAndPrivateVariablesPerInvocation) {
  ComputeHarness h;
  ASSERT_TRUE(h.compile(kSpv_h10_group_builtins_comp)) << h.error;
  EXPECT_FALSE(h.shader->usesBarrier);
  ASSERT_NE(h.shader->groupEntry, nullptr) << "a shader without barriers gets the per-workgroup entry";
  EXPECT_EQ(h.shader->entry, nullptr) << "the per-invocation function is only kept for shaders with barriers";
  runAndCheck(h);
}

TEST(SpirvGroupEntry, ShadersWithBarriersHaveNone) {
  ComputeHarness h;
  ASSERT_TRUE(h.compile(kSpv_compute_shared_comp)) << h.error;
  EXPECT_TRUE(h.shader->usesBarrier);
  EXPECT_EQ(h.shader->groupEntry, nullptr);
  EXPECT_NE(h.shader->entry, nullptr);
  std::string error;
  auto cached = spirv::loadCached(h.shader->cacheBlob, &error);
  ASSERT_NE(cached, nullptr) << error;
  EXPECT_EQ(cached->groupEntry, nullptr);
  EXPECT_NE(cached->entry, nullptr);
}

TEST(SpirvGroupEntry, SurvivesThePipelineCache) {
  ComputeHarness h;
  ASSERT_TRUE(h.compile(kSpv_h10_group_builtins_comp)) << h.error;
  std::string error;
  auto cached = spirv::loadCached(h.shader->cacheBlob, &error);
  ASSERT_NE(cached, nullptr) << error;
  ASSERT_NE(cached->groupEntry, nullptr);
  EXPECT_EQ(cached->entry, nullptr);
  EXPECT_EQ(cached->localSize[2], 2u);
  h.shader = cached;
  runAndCheck(h);
}

}  // namespace
}  // namespace vkrt::testing
