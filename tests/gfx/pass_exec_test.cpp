// The render pass instance's building blocks on plain memory: fillSurface (load-op and vkCmdClearAttachments
// clears: rect clipping, layers, view masks, every sample, one aspect's bytes) and the resolve and depth encoding
// routines they use (runtime/image_copy.hpp). Expected bytes are written out here.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <vector>

#include "gfx/pass_exec.hpp"
#include "runtime/format.hpp"
#include "runtime/image_copy.hpp"

namespace vkrt::gfx {
namespace {

TEST(GfxPassExec, FillSurfaceClipsToTheSurfaceAndWritesEverySampleOfTheLayers) {
  // 3x2 pixels, 2 samples of 4-byte texels, 3 layers; fill bytes 1..2 of each texel.
  const uint32_t w = 3, h = 2, s = 2, t = 4, layers = 3;
  std::vector<uint8_t> mem(size_t(w) * h * s * t * layers, 0);
  raster::Surface surf;
  surf.base = mem.data();
  surf.rowPitch = size_t(w) * s * t;
  surf.layerPitch = surf.rowPitch * h;
  surf.width = w;
  surf.height = h;
  surf.layers = layers;
  surf.samples = s;
  const uint8_t value[2] = {0xAB, 0xCD};
  fillSurface(surf, t, 1, 2, value, {{1, -1}, {5, 2}}, 1, 5, 0);  // clipped to x 1..2, y 0; layers 1..2
  for (uint32_t l = 0; l < layers; ++l)
    for (uint32_t y = 0; y < h; ++y)
      for (uint32_t x = 0; x < w; ++x)
        for (uint32_t smp = 0; smp < s; ++smp) {
          const uint8_t* p = mem.data() + l * surf.layerPitch + y * surf.rowPitch + (x * s + smp) * t;
          const bool in = l >= 1 && y == 0 && x >= 1;
          EXPECT_EQ(p[0], 0);
          EXPECT_EQ(p[1], in ? 0xAB : 0);
          EXPECT_EQ(p[2], in ? 0xCD : 0);
          EXPECT_EQ(p[3], 0);
        }
  // A view mask selects its layers (views 0 and 2) whatever the layer range says.
  std::fill(mem.begin(), mem.end(), 0);
  fillSurface(surf, t, 0, 1, value, {{0, 0}, {3, 2}}, 0, 1, 0b101);
  EXPECT_EQ(mem[0], 0xAB);
  EXPECT_EQ(mem[surf.layerPitch], 0);
  EXPECT_EQ(mem[2 * surf.layerPitch], 0xAB);
}

TEST(GfxPassExec, ResolvesAndDepthEncodings) {
  // Four R8G8B8A8_UNORM samples average per component; R32_UINT takes sample 0.
  const uint8_t rgba[16] = {0, 10, 255, 0, 60, 14, 255, 0, 120, 18, 255, 0, 200, 22, 255, 4};
  uint8_t out[4];
  resolveColorPixel(*formatInfo(VK_FORMAT_R8G8B8A8_UNORM), rgba, 4, out);
  EXPECT_EQ(out[0], 95);
  EXPECT_EQ(out[1], 16);
  EXPECT_EQ(out[2], 255);
  EXPECT_EQ(out[3], 1);
  const uint32_t ints[4] = {7, 100, 200, 300};
  uint32_t o = 0;
  resolveColorPixel(*formatInfo(VK_FORMAT_R32_UINT), reinterpret_cast<const uint8_t*>(ints), 4,
                    reinterpret_cast<uint8_t*>(&o));
  EXPECT_EQ(o, 7u);
  // D24_UNORM_S8_UINT: depth in bits 0..23, stencil in byte 3; each written without touching the other.
  uint8_t texel[4] = {0, 0, 0, 0x77};
  encodeDepth(VK_FORMAT_D24_UNORM_S8_UINT, 1.0f, texel);
  EXPECT_EQ(texel[0], 0xFF);
  EXPECT_EQ(texel[2], 0xFF);
  EXPECT_EQ(texel[3], 0x77);
  encodeStencil(VK_FORMAT_D24_UNORM_S8_UINT, 0x12, texel);
  EXPECT_EQ(texel[3], 0x12);
  EXPECT_EQ(texel[0], 0xFF);
  // Stencil MIN / MAX and depth AVERAGE of D32_SFLOAT_S8_UINT samples.
  uint8_t samples[32] = {};
  const float z[4] = {0.5f, 0.25f, 0.75f, 1.0f};
  const uint8_t st[4] = {7, 3, 9, 5};
  for (int i = 0; i < 4; ++i) {
    std::memcpy(samples + 8 * i, &z[i], 4);
    samples[8 * i + 4] = st[i];
  }
  uint8_t dst[8] = {};
  resolveDepthStencilPixel(VK_FORMAT_D32_SFLOAT_S8_UINT, VK_IMAGE_ASPECT_DEPTH_BIT, VK_RESOLVE_MODE_AVERAGE_BIT,
                           samples, 4, dst);
  resolveDepthStencilPixel(VK_FORMAT_D32_SFLOAT_S8_UINT, VK_IMAGE_ASPECT_STENCIL_BIT, VK_RESOLVE_MODE_MAX_BIT, samples,
                           4, dst);
  float got;
  std::memcpy(&got, dst, 4);
  EXPECT_EQ(got, 0.625f);
  EXPECT_EQ(dst[4], 9);
  resolveDepthStencilPixel(VK_FORMAT_D32_SFLOAT_S8_UINT, VK_IMAGE_ASPECT_STENCIL_BIT, VK_RESOLVE_MODE_MIN_BIT, samples,
                           4, dst);
  EXPECT_EQ(dst[4], 3);
  std::memcpy(&got, dst, 4);
  EXPECT_EQ(got, 0.625f);  // the depth bytes stay
}

}  // namespace
}  // namespace vkrt::gfx
