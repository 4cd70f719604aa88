// The format features "Mandatory Format Support" (formats.adoc, Vulkan 1.3) requires, row by row as the spec's
// tables mark them (the columns that depend on shaderStorageImageExtendedFormats, which vkrt does not report, and
// the depth "at least one of" rows aside), against runtime/format.cpp's formatFeatures / bufferFormatFeatures.
#include <gtest/gtest.h>

#include <set>

#include "runtime/format.hpp"
#include "runtime/supported_features.hpp"

namespace vkrt {
namespace {

enum : uint32_t {
  S = VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT,
  BS = VK_FORMAT_FEATURE_BLIT_SRC_BIT,
  L = VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT,
  ST = VK_FORMAT_FEATURE_STORAGE_IMAGE_BIT,
  SA = VK_FORMAT_FEATURE_STORAGE_IMAGE_ATOMIC_BIT,
  CA = VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT,
  BD = VK_FORMAT_FEATURE_BLIT_DST_BIT,
  BL = VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BLEND_BIT,
  DS = VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT,
};
enum : uint32_t {
  V = VK_FORMAT_FEATURE_VERTEX_BUFFER_BIT,
  UT = VK_FORMAT_FEATURE_UNIFORM_TEXEL_BUFFER_BIT,
  STB = VK_FORMAT_FEATURE_STORAGE_TEXEL_BUFFER_BIT,
  STA = VK_FORMAT_FEATURE_STORAGE_TEXEL_BUFFER_ATOMIC_BIT,
};

struct Row {
  VkFormat format;
  uint32_t optimal, buffer;
};

// The spec's rows with at least one mark, in its order.
constexpr Row kRequired[] = {
    {VK_FORMAT_B4G4R4A4_UNORM_PACK16, S | BS | L, 0},
    {VK_FORMAT_R5G6B5_UNORM_PACK16, S | BS | L | CA | BD | BL, 0},
    {VK_FORMAT_A1R5G5B5_UNORM_PACK16, S | BS | L | CA | BD | BL, 0},
    {VK_FORMAT_R8_UNORM, S | BS | L | CA | BD | BL, V | UT},
    {VK_FORMAT_R8_SNORM, S | BS | L, V | UT},
    {VK_FORMAT_R8_UINT, S | BS | CA | BD, V | UT},
    {VK_FORMAT_R8_SINT, S | BS | CA | BD, V | UT},
    {VK_FORMAT_R8G8_UNORM, S | BS | L | CA | BD | BL, V | UT},
    {VK_FORMAT_R8G8_SNORM, S | BS | L, V | UT},
    {VK_FORMAT_R8G8_UINT, S | BS | CA | BD, V | UT},
    {VK_FORMAT_R8G8_SINT, S | BS | CA | BD, V | UT},
    {VK_FORMAT_R8G8B8A8_UNORM, S | BS | L | ST | CA | BD | BL, V | UT | STB},
    {VK_FORMAT_R8G8B8A8_SNORM, S | BS | L | ST, V | UT | STB},
    {VK_FORMAT_R8G8B8A8_UINT, S | BS | ST | CA | BD, V | UT | STB},
    {VK_FORMAT_R8G8B8A8_SINT, S | BS | ST | CA | BD, V | UT | STB},
    {VK_FORMAT_R8G8B8A8_SRGB, S | BS | L | CA | BD | BL, 0},
    {VK_FORMAT_B8G8R8A8_UNORM, S | BS | L | CA | BD | BL, V | UT},
    {VK_FORMAT_B8G8R8A8_SRGB, S | BS | L | CA | BD | BL, 0},
    {VK_FORMAT_A8B8G8R8_UNORM_PACK32, S | BS | L | CA | BD | BL, V | UT | STB},
    {VK_FORMAT_A8B8G8R8_SNORM_PACK32, S | BS | L, V | UT | STB},
    {VK_FORMAT_A8B8G8R8_UINT_PACK32, S | BS | CA | BD, V | UT | STB},
    {VK_FORMAT_A8B8G8R8_SINT_PACK32, S | BS | CA | BD, V | UT | STB},
    {VK_FORMAT_A8B8G8R8_SRGB_PACK32, S | BS | L | CA | BD | BL, 0},
    {VK_FORMAT_A2B10G10R10_UNORM_PACK32, S | BS | L | CA | BD | BL, V | UT},
    {VK_FORMAT_A2B10G10R10_UINT_PACK32, S | BS | CA | BD, UT},
    {VK_FORMAT_R16_UNORM, 0, V | UT},
    {VK_FORMAT_R16_SNORM, 0, V | UT},
    {VK_FORMAT_R16_UINT, S | BS | CA | BD, V | UT},
    {VK_FORMAT_R16_SINT, S | BS | CA | BD, V | UT},
    {VK_FORMAT_R16_SFLOAT, S | BS | L | CA | BD | BL, V | UT},
    {VK_FORMAT_R16G16_UNORM, 0, V | UT},
    {VK_FORMAT_R16G16_SNORM, 0, V | UT},
    {VK_FORMAT_R16G16_UINT, S | BS | CA | BD, V | UT},
    {VK_FORMAT_R16G16_SINT, S | BS | CA | BD, V | UT},
    {VK_FORMAT_R16G16_SFLOAT, S | BS | L | CA | BD | BL, V | UT},
    {VK_FORMAT_R16G16B16A16_UNORM, 0, V | UT},
    {VK_FORMAT_R16G16B16A16_SNORM, 0, V | UT},
    {VK_FORMAT_R16G16B16A16_UINT, S | BS | ST | CA | BD, V | UT | STB},
    {VK_FORMAT_R16G16B16A16_SINT, S | BS | ST | CA | BD, V | UT | STB},
    {VK_FORMAT_R16G16B16A16_SFLOAT, S | BS | L | ST | CA | BD | BL, V | UT | STB},
    {VK_FORMAT_R32_UINT, S | BS | ST | SA | CA | BD, V | UT | STB | STA},
    {VK_FORMAT_R32_SINT, S | BS | ST | SA | CA | BD, V | UT | STB | STA},
    {VK_FORMAT_R32_SFLOAT, S | BS | ST | CA | BD, V | UT | STB},
    {VK_FORMAT_R32G32_UINT, S | BS | ST | CA | BD, V | UT | STB},
    {VK_FORMAT_R32G32_SINT, S | BS | ST | CA | BD, V | UT | STB},
    {VK_FORMAT_R32G32_SFLOAT, S | BS | ST | CA | BD, V | UT | STB},
    {VK_FORMAT_R32G32B32_UINT, 0, V},
    {VK_FORMAT_R32G32B32_SINT, 0, V},
    {VK_FORMAT_R32G32B32_SFLOAT, 0, V},
    {VK_FORMAT_R32G32B32A32_UINT, S | BS | ST | CA | BD, V | UT | STB},
    {VK_FORMAT_R32G32B32A32_SINT, S | BS | ST | CA | BD, V | UT | STB},
    {VK_FORMAT_R32G32B32A32_SFLOAT, S | BS | ST | CA | BD, V | UT | STB},
    {VK_FORMAT_B10G11R11_UFLOAT_PACK32, S | BS | L, UT},
    {VK_FORMAT_E5B9G9R9_UFLOAT_PACK32, S | BS | L, 0},
    {VK_FORMAT_D16_UNORM, S | BS | DS, 0},
    {VK_FORMAT_D32_SFLOAT, S | BS, 0},
};

TEST(FormatRequired, EveryMarkOfTheMandatoryFormatTablesIsSupported) {
  for (const Row& r : kRequired) {
    SCOPED_TRACE(r.format);
    EXPECT_EQ(formatFeatures(r.format) & r.optimal, r.optimal);
    EXPECT_EQ(bufferFormatFeatures(r.format) & r.buffer, r.buffer);
    // Each sampled format can also be copied (Vulkan 1.1's TRANSFER_SRC / TRANSFER_DST with SAMPLED_IMAGE).
    if (r.optimal & S) {
      EXPECT_TRUE(formatFeatures(r.format) & VK_FORMAT_FEATURE_TRANSFER_SRC_BIT &&
                  formatFeatures(r.format) & VK_FORMAT_FEATURE_TRANSFER_DST_BIT);
    }
  }
  // "At least one of" X8_D24_UNORM_PACK32 / D32_SFLOAT and of D24_UNORM_S8_UINT / D32_SFLOAT_S8_UINT is a
  // depth/stencil attachment; depth/stencil formats have no buffer features.
  EXPECT_TRUE((formatFeatures(VK_FORMAT_X8_D24_UNORM_PACK32) | formatFeatures(VK_FORMAT_D32_SFLOAT)) & DS);
  EXPECT_TRUE((formatFeatures(VK_FORMAT_D24_UNORM_S8_UINT) | formatFeatures(VK_FORMAT_D32_SFLOAT_S8_UINT)) & DS);
  for (VkFormat f : {VK_FORMAT_D16_UNORM, VK_FORMAT_X8_D24_UNORM_PACK32, VK_FORMAT_D32_SFLOAT, VK_FORMAT_S8_UINT,
                     VK_FORMAT_D24_UNORM_S8_UINT, VK_FORMAT_D32_SFLOAT_S8_UINT})
    EXPECT_EQ(bufferFormatFeatures(f), 0u) << f;
}

// "Mandatory format support: BC compressed formats" (2D and 3D images): with textureCompressionBC advertised, every
// BC format is sampled, filtered and a blit source with optimal tiling (and copied both ways); the image functions
// only read blocks, so none is an attachment, a storage image, a blit destination or a buffer format, and linear
// tiling has nothing.
TEST(FormatRequired, BcFormatsFollowTheirTableWhenTextureCompressionBcIsAdvertised) {
  const bool bc = supportedFeatures()[size_t(Feature::textureCompressionBC)];
  for (int f = VK_FORMAT_BC1_RGB_UNORM_BLOCK; f <= VK_FORMAT_BC7_SRGB_BLOCK; ++f) {
    SCOPED_TRACE(f);
    const VkFormat format = VkFormat(f);
    if (!bc) {
      EXPECT_EQ(formatFeatures(format), 0u);  // nothing advertised without the feature
      continue;
    }
    EXPECT_EQ(formatFeatures(format),
              S | BS | L | VK_FORMAT_FEATURE_TRANSFER_SRC_BIT | VK_FORMAT_FEATURE_TRANSFER_DST_BIT);
    EXPECT_EQ(linearFormatFeatures(format), 0u);
    EXPECT_EQ(bufferFormatFeatures(format), 0u);
    EXPECT_FALSE(isColorAttachmentFormat(format));
    ASSERT_TRUE(formatInfo(format));
    EXPECT_EQ(formatInfo(format)->block, 4u);
    const bool small = format <= VK_FORMAT_BC1_RGBA_SRGB_BLOCK || format == VK_FORMAT_BC4_UNORM_BLOCK ||
                       format == VK_FORMAT_BC4_SNORM_BLOCK;
    EXPECT_EQ(formatInfo(format)->texelSize, small ? 8u : 16u);
  }
}

// The compatibility classes of views: a BC format's own class (its UNORM/SRGB or UNORM/SNORM or UFLOAT/SFLOAT
// pair), and with BLOCK_TEXEL_VIEW_COMPATIBLE the uncompressed formats of its block size; uncompressed formats stay
// one class per texel size.
TEST(FormatRequired, ViewCompatibilityClassesOfBlockFormats) {
  const VkImageCreateFlags blockTexel = VK_IMAGE_CREATE_BLOCK_TEXEL_VIEW_COMPATIBLE_BIT;
  EXPECT_TRUE(viewFormatCompatible(VK_FORMAT_BC1_RGB_UNORM_BLOCK, VK_FORMAT_BC1_RGB_SRGB_BLOCK, 0));
  EXPECT_FALSE(viewFormatCompatible(VK_FORMAT_BC1_RGB_UNORM_BLOCK, VK_FORMAT_BC1_RGBA_UNORM_BLOCK, 0));
  EXPECT_FALSE(viewFormatCompatible(VK_FORMAT_BC1_RGB_UNORM_BLOCK, VK_FORMAT_BC4_UNORM_BLOCK, blockTexel));
  EXPECT_TRUE(viewFormatCompatible(VK_FORMAT_BC6H_UFLOAT_BLOCK, VK_FORMAT_BC6H_SFLOAT_BLOCK, 0));
  EXPECT_FALSE(viewFormatCompatible(VK_FORMAT_BC7_UNORM_BLOCK, VK_FORMAT_R32G32B32A32_UINT, 0));
  EXPECT_TRUE(viewFormatCompatible(VK_FORMAT_BC7_UNORM_BLOCK, VK_FORMAT_R32G32B32A32_UINT, blockTexel));
  EXPECT_TRUE(viewFormatCompatible(VK_FORMAT_BC1_RGB_UNORM_BLOCK, VK_FORMAT_R32G32_UINT, blockTexel));
  EXPECT_FALSE(viewFormatCompatible(VK_FORMAT_BC1_RGB_UNORM_BLOCK, VK_FORMAT_R32G32B32A32_UINT, blockTexel));
  EXPECT_FALSE(viewFormatCompatible(VK_FORMAT_R32G32_UINT, VK_FORMAT_BC1_RGB_UNORM_BLOCK, blockTexel));
  EXPECT_TRUE(viewFormatCompatible(VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_R32_SFLOAT, 0));
}

// The shared-exponent format is sampled, filtered and copied, and blitted both ways (its encoder serves clears and
// blit destinations), but not rendered to or stored: the spec asks neither and vkrt offers neither.
TEST(FormatRequired, SharedExponentIsNeitherAnAttachmentNorAStorageFormat) {
  const VkFormatFeatureFlags f = formatFeatures(VK_FORMAT_E5B9G9R9_UFLOAT_PACK32);
  EXPECT_FALSE(f & (CA | BL | ST | SA | DS));
  EXPECT_TRUE(f & BD);
  EXPECT_EQ(bufferFormatFeatures(VK_FORMAT_E5B9G9R9_UFLOAT_PACK32), 0u);
  // The packed 16-bit formats are attachments with blending (R5G6B5, A1R5G5B5 required; B4G4R4A4 by the same codec).
  for (VkFormat p : {VK_FORMAT_R5G6B5_UNORM_PACK16, VK_FORMAT_A1R5G5B5_UNORM_PACK16, VK_FORMAT_B4G4R4A4_UNORM_PACK16}) {
    EXPECT_TRUE(isColorAttachmentFormat(p)) << p;
    EXPECT_EQ(formatInfo(p)->texelSize, 2u) << p;
  }
}

}  // namespace
}  // namespace vkrt

namespace vkrt {
namespace {

// formatInfo finds each known format's own entry (an index by value for the core formats, a search above them), and
// nothing for every other value: the core range, values past it and some extensions' formats vkrt does not know.
TEST(FormatLookup, EachFormatFindsItsOwnEntryAndNoOtherValueFindsOne) {
  std::set<uint32_t> known;
  for (const FormatInfo& f : allFormats()) {
    EXPECT_TRUE(known.insert(uint32_t(f.format)).second) << "format " << f.format << " listed twice";
    EXPECT_EQ(formatInfo(f.format), &f) << "format " << f.format;
  }
  EXPECT_GE(known.size(), 70u);  // the formats of format.cpp's table
  for (uint32_t v = 0; v < 2048; ++v) {
    if (known.count(v)) continue;
    EXPECT_EQ(formatInfo(VkFormat(v)), nullptr) << "format " << v;
  }
  for (uint32_t v : {1000054000u, 1000066000u, 1000156000u, 1000330000u, 1000340000u, 1000470000u, 0x7FFFFFFFu}) {
    if (known.count(v)) continue;
    EXPECT_EQ(formatInfo(VkFormat(v)), nullptr) << "format " << v;
  }
}

}  // namespace
}  // namespace vkrt
