// The pure image routines of runtime/image_copy.hpp, called directly on vkrt images (below the loader and
// the command buffers): buffer<->image copies with row lengths, image heights, offsets and layers,
// image->image copies, and clear colors encoded for each kind of format, compared against values computed
// here independently.
#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "runtime/format.hpp"
#include "runtime/image.hpp"
#include "runtime/image_copy.hpp"
#include "spirv/runtime_images.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {
namespace {

class ImageCopy : public ::testing::Test {
 protected:
  void SetUp() override { ASSERT_NO_FATAL_FAILURE(vkrt::testing::createPlainDevice(&instance, &device)); }
  void TearDown() override {
    for (auto& i : images) {
      vkrt_DestroyImage(device, i.first, nullptr);
      vkrt_FreeMemory(device, i.second, nullptr);
    }
    vkrt_DestroyDevice(device, nullptr);
    vkrt_DestroyInstance(instance, nullptr);
  }

  Image* makeImage(VkImageType type, VkFormat format, VkExtent3D extent, uint32_t mips, uint32_t layers) {
    VkImageCreateInfo ci{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    ci.imageType = type;
    ci.format = format;
    ci.extent = extent;
    ci.mipLevels = mips;
    ci.arrayLayers = layers;
    ci.samples = VK_SAMPLE_COUNT_1_BIT;
    ci.usage = VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    VkImage img = VK_NULL_HANDLE;
    EXPECT_EQ(vkrt_CreateImage(device, &ci, nullptr, &img), VK_SUCCESS);
    VkMemoryRequirements req;
    vkrt_GetImageMemoryRequirements(device, img, &req);
    VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    mai.allocationSize = req.size;
    VkDeviceMemory m = VK_NULL_HANDLE;
    EXPECT_EQ(vkrt_AllocateMemory(device, &mai, nullptr, &m), VK_SUCCESS);
    EXPECT_EQ(vkrt_BindImageMemory(device, img, m, 0), VK_SUCCESS);
    images.push_back({img, m});
    Image* image = fromHandle<Image>(img);
    std::memset(image->data(), 0, image->size);
    return image;
  }

  VkInstance instance = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  std::vector<std::pair<VkImage, VkDeviceMemory>> images;
};

// Byte offset of texel (x, y, z) of (mip, layer) in the documented layout, computed from scratch.
size_t layoutOffset(VkExtent3D e, uint32_t layers, uint32_t texel, uint32_t mip, uint32_t layer, uint32_t x, uint32_t y,
                    uint32_t z) {
  size_t off = 0;
  for (uint32_t m = 0; m < mip; ++m) {
    size_t w = std::max(1u, e.width >> m), h = std::max(1u, e.height >> m), d = std::max(1u, e.depth >> m);
    off += w * h * d * texel * layers;
  }
  size_t w = std::max(1u, e.width >> mip), h = std::max(1u, e.height >> mip), d = std::max(1u, e.depth >> mip);
  return off + (((layer * d + z) * h + y) * w + x) * texel;
}

TEST_F(ImageCopy, LayoutMatchesTheDocumentedFormula) {
  VkExtent3D e{7, 5, 1};
  Image* img = makeImage(VK_IMAGE_TYPE_2D, VK_FORMAT_R16G16B16A16_UINT, e, 3, 4);
  EXPECT_EQ(img->size, layoutOffset(e, 4, 8, 3, 0, 0, 0, 0));
  EXPECT_EQ(img->texel(2, 3, 0, 1, 0) - img->data(), ptrdiff_t(layoutOffset(e, 4, 8, 2, 3, 0, 1, 0)));
  EXPECT_EQ(img->texel(1, 2, 2, 1, 0) - img->data(), ptrdiff_t(layoutOffset(e, 4, 8, 1, 2, 2, 1, 0)));
  EXPECT_EQ(img->mips[2].extent.width, 1u);
  EXPECT_EQ(img->mips[2].extent.height, 1u);
}

TEST_F(ImageCopy, BufferToImageAndBackHonoursRowLengthHeightOffsetAndLayers) {
  VkExtent3D e{6, 5, 1};
  Image* img = makeImage(VK_IMAGE_TYPE_2D, VK_FORMAT_R8G8B8A8_UINT, e, 2, 3);
  VkBufferImageCopy2 r{VK_STRUCTURE_TYPE_BUFFER_IMAGE_COPY_2};
  r.bufferOffset = 12;
  r.bufferRowLength = 5;
  r.bufferImageHeight = 4;
  r.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 2};
  r.imageOffset = {2, 1, 0};
  r.imageExtent = {3, 2, 1};
  // Footprint: last texel of layer 1, row 1: ((1*4 + 1) * 5 + 3) texels.
  EXPECT_EQ(bufferFootprint(r, 4), VkDeviceSize((1 * 4 + 1) * 5 + 3) * 4);
  std::vector<uint8_t> src(12 + bufferFootprint(r, 4) + 8);
  for (size_t i = 0; i < src.size(); ++i) src[i] = uint8_t(i * 7 + 1);
  copyBufferImage(*img, src.data(), r, true);
  size_t changed = 0;
  for (uint32_t layer = 0; layer < 3; ++layer)
    for (uint32_t y = 0; y < e.height; ++y)
      for (uint32_t x = 0; x < e.width; ++x) {
        const uint8_t* t = img->data() + layoutOffset(e, 3, 4, 0, layer, x, y, 0);
        bool inside = layer >= 1 && x >= 2 && x < 5 && y >= 1 && y < 3;
        for (int c = 0; c < 4; ++c) {
          uint8_t want = 0;
          if (inside) want = src[12 + (((layer - 1) * 4 + (y - 1)) * 5 + (x - 2)) * 4 + c];
          ASSERT_EQ(t[c], want) << "layer " << layer << " x " << x << " y " << y << " c " << c;
          changed += inside;
        }
      }
  EXPECT_EQ(changed, 2u * 3 * 2 * 4);
  // Mip 1 untouched.
  for (VkDeviceSize i = img->mips[1].offset; i < img->size; ++i) ASSERT_EQ(img->data()[i], 0);

  // Back into a tightly packed buffer.
  VkBufferImageCopy2 back = r;
  back.bufferOffset = 4;
  back.bufferRowLength = 0;
  back.bufferImageHeight = 0;
  std::vector<uint8_t> dst(4 + bufferFootprint(back, 4), 0xee);
  EXPECT_EQ(bufferFootprint(back, 4), 2u * 3 * 2 * 4);
  copyBufferImage(*img, dst.data(), back, false);
  for (int c = 0; c < 4; ++c) EXPECT_EQ(dst[c], 0xee);
  for (uint32_t layer = 0; layer < 2; ++layer)
    for (uint32_t y = 0; y < 2; ++y)
      for (uint32_t x = 0; x < 3; ++x)
        for (int c = 0; c < 4; ++c)
          ASSERT_EQ(dst[4 + ((layer * 2 + y) * 3 + x) * 4 + c], src[12 + ((layer * 4 + y) * 5 + x) * 4 + c]);
}

TEST_F(ImageCopy, ThreeDimensionalRegionsAndImageToImage) {
  VkExtent3D e{4, 4, 4};
  Image* a = makeImage(VK_IMAGE_TYPE_3D, VK_FORMAT_R32_UINT, e, 3, 1);
  Image* b = makeImage(VK_IMAGE_TYPE_3D, VK_FORMAT_R8G8B8A8_UNORM, e, 3, 1);  // same texel size
  // Fill mip 1 of `a` (2x2x2) with its linear index.
  for (uint32_t z = 0; z < 2; ++z)
    for (uint32_t y = 0; y < 2; ++y)
      for (uint32_t x = 0; x < 2; ++x) {
        uint32_t v = 100 + x + 2 * y + 4 * z;
        std::memcpy(a->texel(1, 0, x, y, z), &v, 4);
      }
  VkImageCopy2 c{VK_STRUCTURE_TYPE_IMAGE_COPY_2};
  c.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 1, 0, 1};
  c.srcOffset = {1, 0, 1};
  c.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  c.dstOffset = {2, 3, 0};
  c.extent = {1, 1, 1};
  copyImageImage(*a, *b, c);
  uint32_t got;
  std::memcpy(&got, b->data() + layoutOffset(e, 1, 4, 0, 0, 2, 3, 0), 4);
  EXPECT_EQ(got, 100u + 1 + 0 + 4);
  c.srcOffset = {0, 0, 0};
  c.dstOffset = {0, 0, 2};
  c.extent = {2, 2, 2};
  copyImageImage(*a, *b, c);
  for (uint32_t z = 0; z < 2; ++z)
    for (uint32_t y = 0; y < 2; ++y)
      for (uint32_t x = 0; x < 2; ++x) {
        std::memcpy(&got, b->data() + layoutOffset(e, 1, 4, 0, 0, x, y, 2 + z), 4);
        EXPECT_EQ(got, 100 + x + 2 * y + 4 * z);
      }
  // Everything else of b stays zero: 1 + 8 texels written.
  size_t nonzero = 0;
  for (VkDeviceSize i = 0; i < b->size; i += 4) {
    std::memcpy(&got, b->data() + i, 4);
    nonzero += got != 0;
  }
  EXPECT_EQ(nonzero, 9u);
}

std::vector<uint8_t> encode(VkFormat format, VkClearColorValue color) {
  const FormatInfo* f = formatInfo(format);
  EXPECT_NE(f, nullptr);
  std::vector<uint8_t> out(f->texelSize);
  EXPECT_TRUE(encodeClearColor(*f, color, out.data()));
  return out;
}

VkClearColorValue floats(float r, float g, float b, float a) {
  VkClearColorValue v;
  v.float32[0] = r;
  v.float32[1] = g;
  v.float32[2] = b;
  v.float32[3] = a;
  return v;
}

TEST_F(ImageCopy, ClearColorsAreEncodedPerFormat) {
  using B = std::vector<uint8_t>;
  // UNORM: round(c * 255), ties to even: 0.5 * 255 = 127.5 -> 128, 0.25 * 255 = 63.75 -> 64.
  EXPECT_EQ(encode(VK_FORMAT_R8G8B8A8_UNORM, floats(0.5f, 0.25f, 1.0f, 0.0f)), (B{128, 64, 255, 0}));
  // Clamped.
  EXPECT_EQ(encode(VK_FORMAT_R8G8B8A8_UNORM, floats(-3.0f, 2.0f, 0.0f, 1.0f)), (B{0, 255, 0, 255}));
  // BGRA swaps red and blue in memory.
  EXPECT_EQ(encode(VK_FORMAT_B8G8R8A8_UNORM, floats(1.0f, 0.0f, 0.2f, 1.0f)), (B{51, 0, 255, 255}));
  // SNORM: round(c * 127), two's complement.
  EXPECT_EQ(encode(VK_FORMAT_R8G8_SNORM, floats(-1.0f, 0.5f, 0, 0)), (B{0x81, 64}));
  // sRGB: 1.055 * 0.5^(1/2.4) - 0.055 = 0.73536 -> 187.5 -> 188; alpha stays linear.
  EXPECT_EQ(encode(VK_FORMAT_R8G8B8A8_SRGB, floats(0.5f, 0.0f, 1.0f, 0.5f)), (B{188, 0, 255, 128}));
  // A tiny value on the linear segment: 0.002 * 12.92 * 255 = 6.59 -> 7.
  EXPECT_EQ(encode(VK_FORMAT_B8G8R8A8_SRGB, floats(0.0f, 0.0f, 0.002f, 1.0f)), (B{7, 0, 0, 255}));
  // Half floats: 1.0 = 0x3c00, -2.0 = 0xc000, 0.1 = 0x2e66, 65504 = 0x7bff.
  EXPECT_EQ(encode(VK_FORMAT_R16G16_SFLOAT, floats(1.0f, -2.0f, 0, 0)), (B{0x00, 0x3c, 0x00, 0xc0}));
  EXPECT_EQ(encode(VK_FORMAT_R16_SFLOAT, floats(0.1f, 0, 0, 0)), (B{0x66, 0x2e}));
  EXPECT_EQ(encode(VK_FORMAT_R16_SFLOAT, floats(65504.0f, 0, 0, 0)), (B{0xff, 0x7b}));
  // 2^-24, the smallest half denormal.
  EXPECT_EQ(encode(VK_FORMAT_R16_SFLOAT, floats(5.9604645e-8f, 0, 0, 0)), (B{0x01, 0x00}));
  // 32-bit floats are stored as is.
  {
    float v = 3.25f;
    B want(4);
    std::memcpy(want.data(), &v, 4);
    EXPECT_EQ(encode(VK_FORMAT_R32_SFLOAT, floats(v, 0, 0, 0)), want);
  }
  // A2B10G10R10: R in bits 0-9, G 10-19, B 20-29, A 30-31. 0.5 * 1023 = 511.5 -> 512.
  {
    uint32_t w = 0x3ffu | (512u << 10) | (0u << 20) | (1u << 30);  // a = 1/3 * 3 = 1
    B want(4);
    std::memcpy(want.data(), &w, 4);
    EXPECT_EQ(encode(VK_FORMAT_A2B10G10R10_UNORM_PACK32, floats(1.0f, 0.5f, 0.0f, 1.0f / 3.0f)), want);
  }
  // B10G11R11: 1.0 is exponent 15, mantissa 0 in each; 2.0 = exponent 16; R bits 0-10, G 11-21, B 22-31.
  {
    uint32_t w = (15u << 6) | ((16u << 6) << 11) | ((15u << 5 | 16u) << 22);  // b = 1.5 = 1 + 16/32
    B want(4);
    std::memcpy(want.data(), &w, 4);
    EXPECT_EQ(encode(VK_FORMAT_B10G11R11_UFLOAT_PACK32, floats(1.0f, 2.0f, 1.5f, 0)), want);
  }
  // Integers: truncated to the component width only through the bit pattern of in-range values.
  {
    VkClearColorValue v;
    v.int32[0] = -5;
    v.int32[1] = 7;
    int32_t w[2] = {-5, 7};
    B want(8);
    std::memcpy(want.data(), w, 8);
    EXPECT_EQ(encode(VK_FORMAT_R32G32_SINT, v), want);
    v.int32[0] = -2;
    v.int32[1] = 300;
    EXPECT_EQ(encode(VK_FORMAT_R16G16_SINT, v), (B{0xfe, 0xff, 0x2c, 0x01}));
    v.uint32[0] = 200;
    v.uint32[1] = 1;
    v.uint32[2] = 2;
    v.uint32[3] = 255;
    EXPECT_EQ(encode(VK_FORMAT_R8G8B8A8_UINT, v), (B{200, 1, 2, 255}));
  }
}

TEST_F(ImageCopy, ClearFillsExactlyTheRange) {
  VkExtent3D e{3, 2, 1};
  Image* img = makeImage(VK_IMAGE_TYPE_2D, VK_FORMAT_R16_UINT, e, 2, 3);
  const uint8_t texel[2] = {0x34, 0x12};
  clearImage(*img, texel, {VK_IMAGE_ASPECT_COLOR_BIT, 1, VK_REMAINING_MIP_LEVELS, 1, VK_REMAINING_ARRAY_LAYERS});
  for (uint32_t m = 0; m < 2; ++m)
    for (uint32_t l = 0; l < 3; ++l) {
      VkExtent3D me = mipExtent(e, m);
      for (uint32_t y = 0; y < me.height; ++y)
        for (uint32_t x = 0; x < me.width; ++x) {
          uint16_t v;
          std::memcpy(&v, img->data() + layoutOffset(e, 3, 2, m, l, x, y, 0), 2);
          EXPECT_EQ(v, (m == 1 && l >= 1) ? 0x1234 : 0) << m << " " << l << " " << x << " " << y;
        }
    }
}

// A BC1 image of 10x6 texels and 3 levels is 3x2 blocks of 8 bytes, then 2x1 (5x3 texels), then 1x1 (2x1): a level
// smaller than a block takes a whole one. A buffer copy of the whole level 0 (its extent in texels, the right and
// bottom blocks partial) moves every block; regionInBlocks rounds extents and row lengths up to whole blocks; an
// image copy from BC1 to R32G32_UINT moves one block per texel.
TEST_F(ImageCopy, CompressedLevelsAreWholeBlocks) {
  if (!formatFeatures(VK_FORMAT_BC1_RGB_UNORM_BLOCK)) GTEST_SKIP() << "no BC formats (textureCompressionBC)";
  Image* bc = makeImage(VK_IMAGE_TYPE_2D, VK_FORMAT_BC1_RGB_UNORM_BLOCK, {10, 6, 1}, 3, 1);
  ASSERT_EQ(bc->mips.size(), 3u);
  EXPECT_EQ(bc->mips[0].rowPitch, 3u * 8);
  EXPECT_EQ(bc->mips[0].depthPitch, 2u * 3 * 8);
  EXPECT_EQ(bc->mips[1].offset, 48u);
  EXPECT_EQ(bc->mips[1].rowPitch, 2u * 8);
  EXPECT_EQ(bc->mips[2].offset, 48u + 16);
  EXPECT_EQ(bc->mips[2].arrayPitch, 8u);
  EXPECT_EQ(bc->size, 48u + 16 + 8);

  VkBufferImageCopy2 r{VK_STRUCTURE_TYPE_BUFFER_IMAGE_COPY_2};
  r.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  r.imageExtent = {10, 6, 1};
  EXPECT_EQ(bufferFootprint(r, 8, 4), 48u);
  r.bufferRowLength = 16;  // 4 blocks a row in the buffer
  EXPECT_EQ(bufferFootprint(r, 8, 4), (4u + 3) * 8);
  const VkBufferImageCopy2 b = regionInBlocks(r, 4);
  EXPECT_EQ(b.bufferRowLength, 4u);
  EXPECT_EQ(b.imageExtent.width, 3u);
  EXPECT_EQ(b.imageExtent.height, 2u);
  std::vector<uint8_t> buf(64);
  for (size_t i = 0; i < buf.size(); ++i) buf[i] = uint8_t(i + 1);
  copyBufferImage(*bc, buf.data(), r, true);
  // Block (x, y) of level 0 is buffer bytes (y * 4 + x) * 8.
  for (uint32_t y = 0; y < 2; ++y)
    for (uint32_t x = 0; x < 3; ++x)
      EXPECT_EQ(std::memcmp(bc->texel(0, 0, x, y, 0), &buf[(y * 4 + x) * 8], 8), 0) << x << "," << y;

  Image* u = makeImage(VK_IMAGE_TYPE_2D, VK_FORMAT_R32G32_UINT, {3, 2, 1}, 1, 1);
  VkImageCopy2 c{VK_STRUCTURE_TYPE_IMAGE_COPY_2};
  c.srcSubresource = c.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  c.srcOffset = {4, 0, 0};
  c.dstOffset = {1, 1, 0};
  c.extent = {6, 4, 1};  // blocks (1, 0) and (2, 0), the second partial
  copyImageImage(*bc, *u, c);
  EXPECT_EQ(std::memcmp(u->texel(0, 0, 1, 1, 0), bc->texel(0, 0, 1, 0, 0), 16), 0);
  EXPECT_EQ(u->texel(0, 0, 0, 1, 0)[0], 0);
}

}  // namespace
}  // namespace vkrt
