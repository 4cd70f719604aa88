// Compute shaders on images and device addresses, end to end with the validation layer on: storage image
// loads/stores of several formats and dimensions, sampling with samplers of every filter and address mode (mirror
// clamp to edge with the samplerMirrorClampToEdge feature),
// texel fetches, size queries, and buffer_reference pointers. Expected values are computed here on the CPU.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <vector>

#include "compute_1d_extended_formats.comp.spv.h"
#include "compute_bda_linked_list.comp.spv.h"
#include "compute_cube.comp.spv.h"
#include "compute_formatless_image.comp.spv.h"
#include "compute_grad_aniso.comp.spv.h"
#include "compute_image_atomics.comp.spv.h"
#include "compute_image_robustness.comp.spv.h"
#include "compute_nonuniform_images.comp.spv.h"
#include "compute_sample.comp.spv.h"
#include "compute_small_types.comp.spv.h"
#include "compute_storage_image.comp.spv.h"
#include "compute_storage_view_level.comp.spv.h"
#include "dxc_compute.spvasm.spv.h"
#include "e2e/compute_pipeline_helpers.hpp"
#include "e2e/fixture.hpp"
#include "spirv/dxc_reference.hpp"
#include "spirv/formatless_reference.hpp"
#include "spirv/small_types_reference.hpp"

namespace vkrt::test {
namespace {

class ComputeImageTest : public VulkanTest {
 protected:
  // VK_SAMPLER_ADDRESS_MODE_MIRROR_CLAMP_TO_EDGE is sampled too (SampleAndFetchWithEveryFilterAndAddressMode).
  FixtureOptions options() override {
    FixtureOptions o;
    o.features12.samplerMirrorClampToEdge = VK_TRUE;
    o.features.imageCubeArray = VK_TRUE;  // CubeMapsSelectTheFaceFilterAcrossEdgesAndGather
    return o;
  }
  struct Tex {
    VkImage image = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkImageView view = VK_NULL_HANDLE;
    VkImageCreateInfo ci{};
    HostBuffer staging;  // the image's texels in vkrt's order: per mip, per layer, slices, rows
    uint32_t texelSize = 0;
    std::vector<VkDeviceSize> mipOffsets;
  };

  // Samples one image through every filter and address mode, with anisotropic filtering on or off (the results
  // must be the same: textureLod has zero derivatives, so the ratio of anisotropy is 1), and checks each result
  // against the spec's filter computed here.
  void sampleAndFetch(bool anisotropic);

  Tex makeTex(VkImageType type, VkImageViewType viewType, VkFormat format, VkExtent3D extent, uint32_t mips,
              uint32_t layers, uint32_t texelSize, VkImageUsageFlags usage, uint32_t viewBaseLayer = 0,
              uint32_t viewLayers = VK_REMAINING_ARRAY_LAYERS) {
    Tex t;
    t.texelSize = texelSize;
    t.ci = {VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    t.ci.imageType = type;
    t.ci.format = format;
    t.ci.extent = extent;
    t.ci.mipLevels = mips;
    t.ci.arrayLayers = layers;
    t.ci.samples = VK_SAMPLE_COUNT_1_BIT;
    t.ci.tiling = VK_IMAGE_TILING_OPTIMAL;
    t.ci.usage = usage | VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    t.ci.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    if (viewType == VK_IMAGE_VIEW_TYPE_CUBE || viewType == VK_IMAGE_VIEW_TYPE_CUBE_ARRAY)
      t.ci.flags = VK_IMAGE_CREATE_CUBE_COMPATIBLE_BIT;
    EXPECT_EQ(vkCreateImage(device, &t.ci, nullptr, &t.image), VK_SUCCESS);
    if (!t.image) return t;  // no image: nothing to query or bind
    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(device, t.image, &req);
    VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    mai.allocationSize = req.size;
    mai.memoryTypeIndex = memoryTypeIndex(req.memoryTypeBits, 0);
    EXPECT_EQ(vkAllocateMemory(device, &mai, nullptr, &t.memory), VK_SUCCESS);
    EXPECT_EQ(vkBindImageMemory(device, t.image, t.memory, 0), VK_SUCCESS);
    VkImageViewCreateInfo vi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    vi.image = t.image;
    vi.viewType = viewType;
    vi.format = format;
    vi.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, VK_REMAINING_MIP_LEVELS, viewBaseLayer, viewLayers};
    EXPECT_EQ(vkCreateImageView(device, &vi, nullptr, &t.view), VK_SUCCESS);
    VkDeviceSize bytes = 0;
    for (uint32_t m = 0; m < mips; ++m) {
      t.mipOffsets.push_back(bytes);
      VkExtent3D e = mipExtent(extent, m);
      bytes += VkDeviceSize(e.width) * e.height * e.depth * layers * texelSize;
    }
    t.staging = createHostBuffer(bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    return t;
  }
  static VkExtent3D mipExtent(VkExtent3D e, uint32_t m) {
    return {std::max(1u, e.width >> m), std::max(1u, e.height >> m), std::max(1u, e.depth >> m)};
  }
  void destroy(Tex& t) {
    vkDestroyImageView(device, t.view, nullptr);
    vkDestroyImage(device, t.image, nullptr);
    vkFreeMemory(device, t.memory, nullptr);
    VulkanTest::destroy(t.staging);
  }
  using VulkanTest::destroy;

  static void barrier(VkCommandBuffer cb, const Tex& t, VkImageLayout from, VkImageLayout to, VkAccessFlags src,
                      VkAccessFlags dst, VkPipelineStageFlags srcStage, VkPipelineStageFlags dstStage) {
    VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    b.srcAccessMask = src;
    b.dstAccessMask = dst;
    b.oldLayout = from;
    b.newLayout = to;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = t.image;
    b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, VK_REMAINING_MIP_LEVELS, 0, VK_REMAINING_ARRAY_LAYERS};
    vkCmdPipelineBarrier(cb, srcStage, dstStage, 0, 0, nullptr, 0, nullptr, 1, &b);
  }
  void copy(VkCommandBuffer cb, const Tex& t, bool toImage) {
    std::vector<VkBufferImageCopy> regions;
    for (uint32_t m = 0; m < t.ci.mipLevels; ++m) {
      VkBufferImageCopy r{};
      r.bufferOffset = t.mipOffsets[m];
      r.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, m, 0, t.ci.arrayLayers};
      r.imageExtent = mipExtent(t.ci.extent, m);
      regions.push_back(r);
    }
    if (toImage)
      vkCmdCopyBufferToImage(cb, t.staging.buffer, t.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                             uint32_t(regions.size()), regions.data());
    else
      vkCmdCopyImageToBuffer(cb, t.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, t.staging.buffer,
                             uint32_t(regions.size()), regions.data());
  }
  // Staging -> image, then the image in `layout` for compute shaders.
  void upload(VkCommandBuffer cb, const Tex& t, VkImageLayout layout) {
    barrier(cb, t, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 0, VK_ACCESS_TRANSFER_WRITE_BIT,
            VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT);
    copy(cb, t, true);
    barrier(cb, t, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, layout, VK_ACCESS_TRANSFER_WRITE_BIT,
            VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
            VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT);
  }
  // Image (GENERAL, written by compute) -> staging.
  void download(VkCommandBuffer cb, const Tex& t) {
    barrier(cb, t, VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_ACCESS_SHADER_WRITE_BIT,
            VK_ACCESS_TRANSFER_READ_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT);
    copy(cb, t, false);
  }

  using Pipeline = ComputePipeline;
  Pipeline makePipeline(const uint32_t* words, size_t bytes, const std::vector<VkDescriptorType>& types,
                        uint32_t pushBytes = 0) {
    return makeComputePipeline(device, words, bytes, types, pushBytes);
  }
  void destroy(Pipeline& p) { destroyComputePipeline(device, p); }
  void writeImage(Pipeline& p, uint32_t binding, VkDescriptorType type, VkImageView view, VkSampler sampler,
                  VkImageLayout layout, uint32_t arrayElement = 0) {
    VkDescriptorImageInfo ii{sampler, view, layout};
    VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    w.dstSet = p.set;
    w.dstBinding = binding;
    w.dstArrayElement = arrayElement;
    w.descriptorCount = 1;
    w.descriptorType = type;
    w.pImageInfo = &ii;
    vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);
  }
  void writeBuffer(Pipeline& p, uint32_t binding, const HostBuffer& b) {
    VkDescriptorBufferInfo bi{b.buffer, 0, VK_WHOLE_SIZE};
    VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    w.dstSet = p.set;
    w.dstBinding = binding;
    w.descriptorCount = 1;
    w.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    w.pBufferInfo = &bi;
    vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);
  }
  static void hostBarrier(VkCommandBuffer cb) {
    VkMemoryBarrier mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    mb.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
    mb.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                         VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &mb, 0, nullptr, 0, nullptr);
  }
};

constexpr VkDescriptorType kStorageImage = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
constexpr VkDescriptorType kStorageBuffer = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;

float halfToFloat(uint16_t h) {
  _Float16 f;
  std::memcpy(&f, &h, sizeof f);
  return float(f);
}
uint16_t floatToHalf(float f) {
  _Float16 h = _Float16(f);
  uint16_t u;
  std::memcpy(&u, &h, 2);
  return u;
}

TEST_F(ComputeImageTest, StorageImagesOfSeveralFormatsAndDimensions) {
  const bool vkrt = onVkrt();
  Pipeline p =
      makePipeline(kSpv_compute_storage_image_comp, sizeof kSpv_compute_storage_image_comp,
                   {kStorageImage, kStorageImage, kStorageImage, kStorageImage, kStorageImage, kStorageBuffer});
  ASSERT_EQ(p.result, VK_SUCCESS);
  const VkImageUsageFlags st = VK_IMAGE_USAGE_STORAGE_BIT;
  Tex rgba8 = makeTex(VK_IMAGE_TYPE_2D, VK_IMAGE_VIEW_TYPE_2D, VK_FORMAT_R8G8B8A8_UNORM, {8, 8, 1}, 1, 1, 4, st);
  Tex rgba32f =
      makeTex(VK_IMAGE_TYPE_2D, VK_IMAGE_VIEW_TYPE_2D, VK_FORMAT_R32G32B32A32_SFLOAT, {8, 8, 1}, 1, 1, 16, st);
  Tex arr = makeTex(VK_IMAGE_TYPE_2D, VK_IMAGE_VIEW_TYPE_2D_ARRAY, VK_FORMAT_R32_SFLOAT, {8, 8, 1}, 1, 3, 4, st);
  Tex vol = makeTex(VK_IMAGE_TYPE_3D, VK_IMAGE_VIEW_TYPE_3D, VK_FORMAT_R32_UINT, {8, 8, 2}, 1, 1, 4, st);
  Tex half = makeTex(VK_IMAGE_TYPE_2D, VK_IMAGE_VIEW_TYPE_2D, VK_FORMAT_R16G16B16A16_SFLOAT, {8, 8, 1}, 1, 1, 8, st);
  HostBuffer out = createHostBuffer(256, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  std::memset(out.data, 0x7F, 256);

  auto* src8 = static_cast<uint8_t*>(rgba8.staging.data);
  for (uint32_t i = 0; i < 8 * 8 * 4; ++i) src8[i] = uint8_t(i * 37 + 11);
  auto* dst32 = static_cast<float*>(rgba32f.staging.data);
  for (uint32_t i = 0; i < 8 * 8 * 4; ++i) dst32[i] = -5.0f;
  auto* arrF = static_cast<float*>(arr.staging.data);
  std::vector<float> arrIn(8 * 8 * 3);
  for (uint32_t i = 0; i < arrIn.size(); ++i) arrIn[i] = arrF[i] = float(i) * 0.25f - 7.0f;
  auto* volU = static_cast<uint32_t*>(vol.staging.data);
  std::vector<uint32_t> volIn(8 * 8 * 2);
  for (uint32_t i = 0; i < volIn.size(); ++i) volIn[i] = volU[i] = i * 2654435761u;
  auto* halfH = static_cast<uint16_t*>(half.staging.data);
  std::vector<uint16_t> halfIn(8 * 8 * 4);
  for (uint32_t i = 0; i < halfIn.size(); ++i) halfIn[i] = halfH[i] = floatToHalf(float(int(i % 29) - 14) * 0.375f);

  Tex* all[] = {&rgba8, &rgba32f, &arr, &vol, &half};
  for (uint32_t b = 0; b < 5; ++b)
    writeImage(p, b, kStorageImage, all[b]->view, VK_NULL_HANDLE, VK_IMAGE_LAYOUT_GENERAL);
  writeBuffer(p, 5, out);
  VkCommandBuffer cb = beginOneTime();
  for (Tex* t : all) upload(cb, *t, VK_IMAGE_LAYOUT_GENERAL);
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
  vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout, 0, 1, &p.set, 0, nullptr);
  vkCmdDispatch(cb, 2, 2, 1);
  for (Tex* t : all) download(cb, *t);
  hostBarrier(cb);
  submitAndWait(cb);

  for (uint32_t y = 0; y < 8; ++y)
    for (uint32_t x = 0; x < 8; ++x) {
      uint32_t i = y * 8 + x;
      float c[4];
      for (int k = 0; k < 4; ++k) c[k] = float(uint8_t((i * 4 + k) * 37 + 11)) / 255.0f;
      float expect[4] = {c[0] * 2 + float(x), c[1] * 2 + float(y), c[2] * 2, c[3] * 2};
      for (int k = 0; k < 4; ++k) EXPECT_NEAR(dst32[i * 4 + k], expect[k], 1e-6) << x << "," << y << " c" << k;
      for (uint32_t l = 0; l < 3; ++l)
        EXPECT_EQ(arrF[l * 64 + i], arrIn[l * 64 + i] * 3.0f + float(l)) << x << "," << y << " layer " << l;
      for (uint32_t z = 0; z < 2; ++z)
        EXPECT_EQ(volU[z * 64 + i], (volIn[z * 64 + i] ^ 0x5a5a5a5au) + z) << x << "," << y << "," << z;
      for (int k = 0; k < 4; ++k) {
        float want = halfToFloat(halfIn[i * 4 + k]) * 0.5f + c[0];
        if (vkrt) {
          EXPECT_EQ(halfH[i * 4 + k], floatToHalf(want)) << x << "," << y << " c" << k;  // round to nearest even
        } else {
          // The spec leaves the rounding of a float stored to a 16-bit float texel to the driver (RTE or RTZ).
          EXPECT_LE(std::abs(int(halfH[i * 4 + k]) - int(floatToHalf(want))), 1) << x << "," << y << " c" << k;
        }
      }
    }
  const int32_t* sizes = static_cast<const int32_t*>(out.data);
  const int32_t expectSizes[16] = {8, 8, 0, 0, 8, 8, 3, 0, 8, 8, 2, 0, 8, 8, 0, 0};
  for (int k = 0; k < 16; ++k) EXPECT_EQ(sizes[k], expectSizes[k]) << k;
  const uint32_t* oob = static_cast<const uint32_t*>(out.data) + 16;
  // Out-of-bounds image reads are undefined without robustImageAccess; vkrt returns zeros.
  if (vkrt) {
    for (int k = 0; k < 12; ++k) EXPECT_EQ(oob[k], 0u) << "out-of-bounds read " << k;
  }
  for (Tex* t : all) destroy(*t);
  destroy(out);
  destroy(p);
}

// Storage image views of mip 1 and layer 2 of 8x8 images with 3 levels and 4 layers (R8G8B8A8_UNORM and R32_UINT):
// each invocation of an 8x8 workgroup reads its texel at (x - 2, y - 2), then writes it. Inside the 4x4 level the
// reads are that level's and layer's texels and the writes land there (colours with the encode's edge cases: NaN,
// -0, values outside [0, 1], halves between two codes); outside it reads give zeros on vkrt (undefined without
// robustImageAccess) and writes are dropped; no other level or layer changes.
TEST_F(ComputeImageTest, StorageImageViewOfOneLevelAndLayer) {
  const bool vkrt = onVkrt();
  Pipeline p = makePipeline(kSpv_compute_storage_view_level_comp, sizeof kSpv_compute_storage_view_level_comp,
                            {kStorageImage, kStorageImage, kStorageBuffer}, 8 * 16);
  ASSERT_EQ(p.result, VK_SUCCESS);
  const VkImageUsageFlags st = VK_IMAGE_USAGE_STORAGE_BIT;
  Tex color = makeTex(VK_IMAGE_TYPE_2D, VK_IMAGE_VIEW_TYPE_2D_ARRAY, VK_FORMAT_R8G8B8A8_UNORM, {8, 8, 1}, 3, 4, 4, st);
  Tex ids = makeTex(VK_IMAGE_TYPE_2D, VK_IMAGE_VIEW_TYPE_2D_ARRAY, VK_FORMAT_R32_UINT, {8, 8, 1}, 3, 4, 4, st);
  VkImageView views[2];
  const Tex* texs[2] = {&color, &ids};
  for (int v = 0; v < 2; ++v) {
    VkImageViewCreateInfo vi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    vi.image = texs[v]->image;
    vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
    vi.format = texs[v]->ci.format;
    vi.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 1, 1, 2, 1};
    ASSERT_EQ(vkCreateImageView(device, &vi, nullptr, &views[v]), VK_SUCCESS);
  }
  HostBuffer out = createHostBuffer(64 * 16 + 64 * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  std::memset(out.data, 0x7F, 64 * 16 + 64 * 4);
  const size_t bytes = color.staging.size;
  auto* c8 = static_cast<uint8_t*>(color.staging.data);
  auto* u32 = static_cast<uint32_t*>(ids.staging.data);
  for (size_t i = 0; i < bytes; ++i) c8[i] = uint8_t(i * 37 + 11);
  for (size_t i = 0; i < bytes / 4; ++i) u32[i] = uint32_t(i) * 2654435761u;
  const std::vector<uint8_t> colorBefore(c8, c8 + bytes);
  const std::vector<uint32_t> idsBefore(u32, u32 + bytes / 4);
  // The colours: NaN, -0, values below 0 and above 1, the tie 127.5 (0.5: to even, 128), (k + 0.5) / 255 in float
  // (a hair above or below the tie), the floats beside 254.5 / 255, and plain values.
  const float nan = std::nanf("");
  const float tieHigh = 254.5f / 255;
  const float values[8][4] = {{nan, -0.0f, -1.0f, 2.0f},
                              {0.5f, 0.5f / 255, 1.0f / 255, 1.0f},
                              {std::nextafter(tieHigh, 0.0f), tieHigh, std::nextafter(tieHigh, 1.0f), 0.0f},
                              {3.5f / 255, 4.5f / 255, 5.5f / 255, 6.5f / 255},
                              {1e-30f, -1e-30f, 0.999f, 1.001f},
                              {-nan, 0.3f, 0.7f, 0.05f},
                              {0.123f, 0.456f, 0.789f, 0.321f},
                              {0.25f, 0.75f, 0.1f, 0.9f}};
  writeImage(p, 0, kStorageImage, views[0], VK_NULL_HANDLE, VK_IMAGE_LAYOUT_GENERAL);
  writeImage(p, 1, kStorageImage, views[1], VK_NULL_HANDLE, VK_IMAGE_LAYOUT_GENERAL);
  writeBuffer(p, 2, out);
  VkCommandBuffer cb = beginOneTime();
  upload(cb, color, VK_IMAGE_LAYOUT_GENERAL);
  upload(cb, ids, VK_IMAGE_LAYOUT_GENERAL);
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
  vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout, 0, 1, &p.set, 0, nullptr);
  vkCmdPushConstants(cb, p.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof values, values);
  vkCmdDispatch(cb, 1, 1, 1);
  download(cb, color);
  download(cb, ids);
  hostBarrier(cb);
  submitAndWait(cb);

  // Texel (x, y) of mip m, layer l in the staging order (per mip, per layer, rows).
  auto at = [&](uint32_t m, uint32_t l, uint32_t x, uint32_t y) {
    const uint32_t w = 8 >> m, h = 8 >> m;
    return size_t(color.mipOffsets[m] / 4) + (size_t(l) * h + y) * w + x;
  };
  const auto* loaded = static_cast<const float*>(out.data);
  const auto* loadedIds = reinterpret_cast<const uint32_t*>(loaded + 64 * 4);
  for (int32_t y = -2; y < 6; ++y)
    for (int32_t x = -2; x < 6; ++x) {
      const uint32_t i = uint32_t(y + 2) * 8 + uint32_t(x + 2);
      const bool inside = x >= 0 && y >= 0 && x < 4 && y < 4;
      SCOPED_TRACE(std::to_string(x) + "," + std::to_string(y));
      if (!inside) {
        if (vkrt) {
          for (int k = 0; k < 4; ++k) EXPECT_EQ(loaded[i * 4 + k], 0.0f);
          EXPECT_EQ(loadedIds[i], 0u);
        }
        continue;
      }
      const size_t t = at(1, 2, uint32_t(x), uint32_t(y));
      for (int k = 0; k < 4; ++k) {
        const float want = float(colorBefore[t * 4 + k]) / 255.0f;  // vkrt: the correctly rounded quotient
        if (vkrt)
          EXPECT_EQ(loaded[i * 4 + k], want) << k;
        else
          EXPECT_NEAR(loaded[i * 4 + k], want, 1e-6) << k;
      }
      EXPECT_EQ(loadedIds[i], idsBefore[t]);
      const float* v = values[(y * 4 + x) % 8];
      for (int k = 0; k < 4; ++k) {
        // "Conversion from Floating-Point to Normalized Fixed-Point": clamped to [0, 1] (NaN: 0), times 255, one of
        // the two integers nearest to that (the integer itself where it is one). vkrt: the product in float, rounded
        // to nearest even (a value a hair off a tie may round to the tie's other side).
        const float f = std::isnan(v[k]) ? 0.0f : std::clamp(v[k], 0.0f, 1.0f);
        const double exact = double(f) * 255.0;  // exact: 24 + 8 bits
        const int got = c8[t * 4 + k];
        EXPECT_TRUE(got == std::floor(exact) || got == std::ceil(exact)) << "component " << k << " of " << v[k];
        if (vkrt) EXPECT_EQ(got, int(std::nearbyint(f * 255.0f))) << "component " << k << " of " << v[k];
      }
      EXPECT_EQ(u32[t], 1000u + i);
    }
  // Nothing outside mip 1, layer 2's 4x4 texels changed.
  for (uint32_t m = 0; m < 3; ++m)
    for (uint32_t l = 0; l < 4; ++l)
      for (uint32_t y = 0; y < (8u >> m); ++y)
        for (uint32_t x = 0; x < (8u >> m); ++x) {
          if (m == 1 && l == 2) continue;
          const size_t t = at(m, l, x, y);
          ASSERT_EQ(std::memcmp(c8 + t * 4, colorBefore.data() + t * 4, 4), 0) << m << " " << l << " " << x << "," << y;
          ASSERT_EQ(u32[t], idsBefore[t]) << m << " " << l << " " << x << "," << y;
        }
  for (VkImageView v : views) vkDestroyImageView(device, v, nullptr);
  destroy(color);
  destroy(ids);
  destroy(out);
  destroy(p);
}

// 1D storage images and a 1D sampler with formats from the "storage image extended formats" list (rg16f, rg8_snorm)
// declared in the shader: Vulkan 1.0 enables the Image1D, Sampled1D and StorageImageExtendedFormats capabilities
// unconditionally (vk.xml), and the CTS's image.* groups use them throughout. Before, vkrt refused such modules at
// pipeline creation ("unsupported capability").
TEST_F(ComputeImageTest, OneDimensionalImagesAndExtendedStorageFormats) {
  Pipeline p = makePipeline(kSpv_compute_1d_extended_formats_comp, sizeof kSpv_compute_1d_extended_formats_comp,
                            {kStorageImage, kStorageImage, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, kStorageBuffer});
  ASSERT_EQ(p.result, VK_SUCCESS);
  const VkImageUsageFlags st = VK_IMAGE_USAGE_STORAGE_BIT;
  Tex halves = makeTex(VK_IMAGE_TYPE_1D, VK_IMAGE_VIEW_TYPE_1D, VK_FORMAT_R16G16_SFLOAT, {8, 1, 1}, 1, 1, 4, st);
  Tex snorms = makeTex(VK_IMAGE_TYPE_1D, VK_IMAGE_VIEW_TYPE_1D_ARRAY, VK_FORMAT_R8G8_SNORM, {8, 1, 1}, 1, 2, 2, st);
  Tex bytes = makeTex(VK_IMAGE_TYPE_1D, VK_IMAGE_VIEW_TYPE_1D, VK_FORMAT_R8_UNORM, {8, 1, 1}, 1, 1, 1,
                      VK_IMAGE_USAGE_SAMPLED_BIT);
  HostBuffer out = createHostBuffer(256, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  std::memset(out.data, 0x7F, 256);
  auto* h = static_cast<uint16_t*>(halves.staging.data);
  for (int x = 0; x < 8; ++x) h[2 * x] = floatToHalf(float(x) * 0.25f), h[2 * x + 1] = floatToHalf(float(x) * 1.5f);
  auto* sn = static_cast<int8_t*>(snorms.staging.data);  // (r, g) per texel, 8 texels per layer
  std::vector<int8_t> snIn(32);
  for (int i = 0; i < 32; ++i) snIn[i] = sn[i] = int8_t((i % 16) * 15 - 113 + (i / 16) * 7);
  auto* b8 = static_cast<uint8_t*>(bytes.staging.data);
  for (int x = 0; x < 8; ++x) b8[x] = uint8_t(x * 31 + 5);
  VkSamplerCreateInfo si{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
  si.magFilter = si.minFilter = VK_FILTER_NEAREST;
  si.addressModeU = si.addressModeV = si.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
  VkSampler sampler;
  ASSERT_EQ(vkCreateSampler(device, &si, nullptr, &sampler), VK_SUCCESS);
  writeImage(p, 0, kStorageImage, halves.view, VK_NULL_HANDLE, VK_IMAGE_LAYOUT_GENERAL);
  writeImage(p, 1, kStorageImage, snorms.view, VK_NULL_HANDLE, VK_IMAGE_LAYOUT_GENERAL);
  writeImage(p, 2, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, bytes.view, sampler,
             VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
  writeBuffer(p, 3, out);
  VkCommandBuffer cb = beginOneTime();
  upload(cb, halves, VK_IMAGE_LAYOUT_GENERAL);
  upload(cb, snorms, VK_IMAGE_LAYOUT_GENERAL);
  upload(cb, bytes, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
  vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout, 0, 1, &p.set, 0, nullptr);
  vkCmdDispatch(cb, 1, 1, 1);
  download(cb, halves);
  download(cb, snorms);
  hostBarrier(cb);
  submitAndWait(cb);

  for (int x = 0; x < 8; ++x) {
    // (x/4 * 2 + 1/2, 3x/2 - x): exact in half precision
    EXPECT_EQ(h[2 * x], floatToHalf(float(x) * 0.5f + 0.5f)) << x;
    EXPECT_EQ(h[2 * x + 1], floatToHalf(float(x) * 0.5f)) << x;
    for (int l = 0; l < 2; ++l) {
      const int t = l * 16 + 2 * x;
      const float s = std::max(float(snIn[t]) / 127.0f, -1.0f);
      const float v = std::clamp(-s * 0.5f + float(l) * 0.25f, -1.0f, 1.0f);
      EXPECT_LE(std::abs(int(sn[t]) - int(std::lround(v * 127.0f))), 1) << x << " layer " << l;
      EXPECT_EQ(sn[t + 1], snIn[t + 1] == -128 ? -127 : snIn[t + 1]) << x << " layer " << l;  // -128 reads as -1.0
    }
    const float* smp = static_cast<const float*>(out.data) + 4 * x;
    EXPECT_FLOAT_EQ(smp[0], float(x * 31 + 5) / 255.0f) << x;
    EXPECT_EQ(smp[1], 0.0f) << x;
    EXPECT_EQ(smp[2], 0.0f) << x;
    EXPECT_EQ(smp[3], 1.0f) << x;
  }
  const int32_t* sizes = static_cast<const int32_t*>(out.data) + 32;
  EXPECT_EQ(sizes[0], 8);
  EXPECT_EQ(sizes[1], 8);
  EXPECT_EQ(sizes[2], 2);
  EXPECT_EQ(sizes[3], 8);
  vkDestroySampler(device, sampler, nullptr);
  destroy(halves);
  destroy(snorms);
  destroy(bytes);
  destroy(out);
  destroy(p);
}

// ---- sampling

struct SamplerConfig {
  VkFilter filter;
  VkSamplerMipmapMode mipmap;
  VkSamplerAddressMode mode;
  VkBorderColor border;
};

// The sampled image: rgba32f 4x4, 3 mips, 2 layers; texel (x, y) of (mip, layer) holds these values.
void texelValue(uint32_t mip, uint32_t layer, int x, int y, float out[4]) {
  out[0] = float(x + 4 * y) + 16.0f * float(mip) + 100.0f * float(layer);
  out[1] = float(x) * 0.5f;
  out[2] = float(y) * 0.25f + float(mip);
  out[3] = 1.0f + float(layer);
}

// The reference sampler (Vulkan spec "Texel Filtering", written out directly).
// `alternative`: the nearest mip level by floor(d + 0.5) instead of the preferred ceil(d + 0.5) - 1 (the spec
// allows either; they differ only at exact halves).
void reference(const SamplerConfig& s, float u, float v, float lod, int layer, float out[4], bool alternative = false) {
  auto size = [](uint32_t mip) { return int(std::max(1u, 4u >> mip)); };
  auto fetch = [&](uint32_t mip, int i, int j, float t[4]) {
    int n = size(mip);
    auto wrapOne = [&](int c, bool* border) {
      switch (s.mode) {
        case VK_SAMPLER_ADDRESS_MODE_REPEAT: return ((c % n) + n) % n;
        case VK_SAMPLER_ADDRESS_MODE_MIRRORED_REPEAT: {
          int m = ((c % (2 * n)) + 2 * n) % (2 * n);
          return m < n ? m : 2 * n - 1 - m;
        }
        case VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER:
          if (c < 0 || c >= n) *border = true;
          return c;
        case VK_SAMPLER_ADDRESS_MODE_MIRROR_CLAMP_TO_EDGE: return std::min(c >= 0 ? c : -(1 + c), n - 1);
        default: return std::clamp(c, 0, n - 1);
      }
    };
    bool border = false;
    int x = wrapOne(i, &border), y = wrapOne(j, &border);
    if (border) {
      float w = s.border == VK_BORDER_COLOR_FLOAT_OPAQUE_WHITE ? 1.0f : 0.0f;
      float a = s.border == VK_BORDER_COLOR_FLOAT_TRANSPARENT_BLACK ? 0.0f : 1.0f;
      t[0] = t[1] = t[2] = w;
      t[3] = a;
      return;
    }
    texelValue(mip, uint32_t(layer), x, y, t);
  };
  auto level = [&](uint32_t mip, VkFilter f, float r[4]) {
    float n = float(size(mip));
    if (f == VK_FILTER_NEAREST) {
      fetch(mip, int(std::floor(u * n)), int(std::floor(v * n)), r);
      return;
    }
    float fu = u * n - 0.5f, fv = v * n - 0.5f;
    int i0 = int(std::floor(fu)), j0 = int(std::floor(fv));
    float a = fu - std::floor(fu), b = fv - std::floor(fv);
    float t00[4], t10[4], t01[4], t11[4];
    fetch(mip, i0, j0, t00);
    fetch(mip, i0 + 1, j0, t10);
    fetch(mip, i0, j0 + 1, t01);
    fetch(mip, i0 + 1, j0 + 1, t11);
    for (int k = 0; k < 4; ++k)
      r[k] = (1 - a) * (1 - b) * t00[k] + a * (1 - b) * t10[k] + (1 - a) * b * t01[k] + a * b * t11[k];
  };
  VkFilter f = lod <= 0 ? s.filter : s.filter;  // the configs use one filter for both
  float d = std::clamp(lod, 0.0f, 2.0f);
  if (s.mipmap == VK_SAMPLER_MIPMAP_MODE_NEAREST) {
    level(uint32_t(alternative ? std::floor(d + 0.5f) : std::ceil(d + 0.5f) - 1), f, out);
    return;
  }
  uint32_t lo = uint32_t(std::floor(d)), hi = std::min(lo + 1, 2u);
  float a[4], b[4], t = d - std::floor(d);
  level(lo, f, a);
  level(hi, f, b);
  for (int k = 0; k < 4; ++k) out[k] = a[k] * (1 - t) + b[k] * t;
}

void ComputeImageTest::sampleAndFetch(bool anisotropic) {
  const bool vkrt = onVkrt();
  // vkrt filters in float; a GPU quantizes its filter weights to subTexelPrecisionBits (and the lod fraction to
  // mipmapPrecisionBits; NVIDIA: 8 and 8), so its error is the weight's step times the difference between the
  // texels it blends: up to 20 here (texelValue: 15 across a wrapped row, 16 between levels).
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(physicalDevice, &props);
  const int bits = int(std::min(props.limits.subTexelPrecisionBits, props.limits.mipmapPrecisionBits));
  const float tol = vkrt ? 1e-4f : 20.0f * std::ldexp(1.0f, -bits) + 1e-3f;
  constexpr VkDescriptorType kCombined = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
  Pipeline p = makePipeline(kSpv_compute_sample_comp, sizeof kSpv_compute_sample_comp,
                            {kCombined, VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, VK_DESCRIPTOR_TYPE_SAMPLER, kCombined,
                             kStorageBuffer, kStorageBuffer, kStorageBuffer});
  ASSERT_EQ(p.result, VK_SUCCESS);
  // One image, viewed as a 2D texture of layer 1 and as a 2D array of both layers.
  const VkImageUsageFlags sampled = VK_IMAGE_USAGE_SAMPLED_BIT;
  Tex img = makeTex(VK_IMAGE_TYPE_2D, VK_IMAGE_VIEW_TYPE_2D, VK_FORMAT_R32G32B32A32_SFLOAT, {4, 4, 1}, 3, 2, 16,
                    sampled, 1, 1);
  VkImageView arrView;
  VkImageViewCreateInfo vi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
  vi.image = img.image;
  vi.viewType = VK_IMAGE_VIEW_TYPE_2D_ARRAY;
  vi.format = VK_FORMAT_R32G32B32A32_SFLOAT;
  vi.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 3, 0, 2};
  ASSERT_EQ(vkCreateImageView(device, &vi, nullptr, &arrView), VK_SUCCESS);
  auto* texels = static_cast<float*>(img.staging.data);
  for (uint32_t m = 0; m < 3; ++m) {
    int n = int(4u >> m);
    for (uint32_t l = 0; l < 2; ++l)
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x)
          texelValue(m, l, x, y, texels + (img.mipOffsets[m] / 4) + ((l * n + y) * n + x) * 4);
  }

  // Coordinates (u, v, lod, layer): texel centres, edges, halfway points, outside [0, 1], fractional lods.
  const float coords[][4] = {
      {0.125f, 0.125f, 0.0f, 0.0f}, {0.375f, 0.625f, 0.0f, 1.0f}, {0.25f, 0.5f, 0.0f, 0.0f},
      {0.3f, 0.71f, 0.0f, 1.0f},    {-0.2f, 0.4f, 0.0f, 0.0f},    {1.3f, -0.45f, 0.0f, 1.0f},
      {0.9f, 1.1f, 1.0f, 0.0f},     {0.6f, 0.3f, 0.5f, 1.6f},     {0.45f, 0.55f, 1.7f, 0.0f},
      {2.7f, 0.2f, 2.0f, 1.0f},     {0.1f, 0.95f, 5.0f, -3.0f},   {-1.05f, -0.6f, 0.25f, 0.4f},
      {0.5f, 0.5f, 1.25f, 1.0f},    {0.0f, 1.0f, 0.75f, 0.0f},    {1.0f, 0.0f, 0.0f, 1.0f},
      {0.62f, 0.13f, 1.5f, 0.0f},
  };
  const uint32_t n = 16;
  HostBuffer in = createHostBuffer(sizeof coords, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  std::memcpy(in.data, coords, sizeof coords);
  HostBuffer out = createHostBuffer(n * 4 * 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  HostBuffer info = createHostBuffer(16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  writeBuffer(p, 4, in);
  writeBuffer(p, 5, out);
  writeBuffer(p, 6, info);
  VkCommandBuffer cb = beginOneTime();
  upload(cb, img, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
  submitAndWait(cb);

  const SamplerConfig configs[] = {
      {VK_FILTER_NEAREST, VK_SAMPLER_MIPMAP_MODE_NEAREST, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE,
       VK_BORDER_COLOR_FLOAT_TRANSPARENT_BLACK},
      {VK_FILTER_LINEAR, VK_SAMPLER_MIPMAP_MODE_LINEAR, VK_SAMPLER_ADDRESS_MODE_REPEAT,
       VK_BORDER_COLOR_FLOAT_TRANSPARENT_BLACK},
      {VK_FILTER_LINEAR, VK_SAMPLER_MIPMAP_MODE_NEAREST, VK_SAMPLER_ADDRESS_MODE_MIRRORED_REPEAT,
       VK_BORDER_COLOR_FLOAT_TRANSPARENT_BLACK},
      {VK_FILTER_NEAREST, VK_SAMPLER_MIPMAP_MODE_LINEAR, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER,
       VK_BORDER_COLOR_FLOAT_OPAQUE_WHITE},
      {VK_FILTER_LINEAR, VK_SAMPLER_MIPMAP_MODE_LINEAR, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER,
       VK_BORDER_COLOR_FLOAT_TRANSPARENT_BLACK},
      {VK_FILTER_LINEAR, VK_SAMPLER_MIPMAP_MODE_NEAREST, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE,
       VK_BORDER_COLOR_FLOAT_OPAQUE_BLACK},
      {VK_FILTER_LINEAR, VK_SAMPLER_MIPMAP_MODE_LINEAR, VK_SAMPLER_ADDRESS_MODE_MIRROR_CLAMP_TO_EDGE,
       VK_BORDER_COLOR_FLOAT_TRANSPARENT_BLACK},
      {VK_FILTER_NEAREST, VK_SAMPLER_MIPMAP_MODE_NEAREST, VK_SAMPLER_ADDRESS_MODE_MIRROR_CLAMP_TO_EDGE,
       VK_BORDER_COLOR_FLOAT_TRANSPARENT_BLACK},
  };
  const uint32_t nc = sizeof configs / sizeof configs[0];
  std::vector<VkSampler> samplers(nc);
  for (uint32_t c = 0; c < nc; ++c) {
    VkSamplerCreateInfo si{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
    si.magFilter = si.minFilter = configs[c].filter;
    si.mipmapMode = configs[c].mipmap;
    si.addressModeU = si.addressModeV = si.addressModeW = configs[c].mode;
    si.borderColor = configs[c].border;
    si.maxLod = VK_LOD_CLAMP_NONE;
    si.anisotropyEnable = anisotropic;
    si.maxAnisotropy = anisotropic ? 16.0f : 0.0f;
    ASSERT_EQ(vkCreateSampler(device, &si, nullptr, &samplers[c]), VK_SUCCESS);
  }
  const VkImageLayout ro = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
  for (uint32_t round = 0; round < nc; ++round) {
    uint32_t c0 = round, c1 = (round + 1) % nc, c2 = (round + 2) % nc;
    writeImage(p, 0, kCombined, img.view, samplers[c0], ro);
    writeImage(p, 1, VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, img.view, VK_NULL_HANDLE, ro);
    writeImage(p, 2, VK_DESCRIPTOR_TYPE_SAMPLER, VK_NULL_HANDLE, samplers[c1], ro);
    writeImage(p, 3, kCombined, arrView, samplers[c2], ro);
    std::memset(out.data, 0x7F, out.size);
    cb = beginOneTime();
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout, 0, 1, &p.set, 0, nullptr);
    vkCmdDispatch(cb, n / 4, 1, 1);
    hostBarrier(cb);
    submitAndWait(cb);
    const float* r = static_cast<const float*>(out.data);
    for (uint32_t i = 0; i < n; ++i) {
      const float* q = coords[i];
      float e0[4], e1[4], e2[4], e3[4];
      reference(configs[c0], q[0], q[1], q[2], 1, e0);  // the 2D view is layer 1
      reference(configs[c1], q[0], q[1], q[2], 1, e1);
      int layer = int(std::clamp(std::nearbyint(q[3]), 0.0f, 1.0f));
      reference(configs[c2], q[0], q[1], q[2], layer, e2);
      // texelFetch(tex, ivec2(floor(q.xy)), int(q.z)): inside the level, or zeros (vkrt's robust behaviour).
      int fx = int(std::floor(q[0])), fy = int(std::floor(q[1])), fl = int(q[2]);
      int size = fl < 3 ? int(4u >> fl) : 0;
      bool inside = fl < 3 && fx >= 0 && fy >= 0 && fx < size && fy < size;
      if (inside)
        texelValue(uint32_t(fl), 1, fx, fy, e3);
      else
        e3[0] = e3[1] = e3[2] = e3[3] = 0.0f;
      if (!vkrt) {
        // A GPU converts coordinates to fixed point (subTexelPrecisionBits) and may take the alternative nearest
        // mip level at exact halves: where the result is not the exact reference, it must be the reference of a
        // coordinate within a fixed-point step, or of the alternative level.
        auto acceptable = [&](const SamplerConfig& cfg, int lay, const float* got, float* e) {
          const float step = std::ldexp(1.0f, -int(props.limits.subTexelPrecisionBits)) / 4;
          for (bool alt : {false, true})
            for (float du : {0.0f, -step, step})
              for (float dv : {0.0f, -step, step}) {
                float c[4];
                reference(cfg, q[0] + du, q[1] + dv, q[2], lay, c, alt);
                bool all = true;
                for (int k = 0; k < 4; ++k) all = all && std::fabs(got[k] - c[k]) <= tol;
                if (all) {
                  std::copy(c, c + 4, e);
                  return;
                }
              }
        };
        acceptable(configs[c0], 1, &r[(4 * i + 0) * 4], e0);
        acceptable(configs[c1], 1, &r[(4 * i + 1) * 4], e1);
        acceptable(configs[c2], layer, &r[(4 * i + 2) * 4], e2);
      }
      for (int k = 0; k < 4; ++k) {
        EXPECT_NEAR(r[(4 * i + 0) * 4 + k], e0[k], tol) << "round " << round << " coord " << i << " combined c" << k;
        EXPECT_NEAR(r[(4 * i + 1) * 4 + k], e1[k], tol) << "round " << round << " coord " << i << " separate c" << k;
        EXPECT_NEAR(r[(4 * i + 2) * 4 + k], e2[k], tol) << "round " << round << " coord " << i << " array c" << k;
        // An out-of-range texelFetch is undefined without robustImageAccess; vkrt returns zeros.
        if (inside || vkrt) {
          EXPECT_EQ(r[(4 * i + 3) * 4 + k], e3[k]) << "round " << round << " coord " << i << " fetch c" << k;
        }
      }
    }
    const int32_t* inf = static_cast<const int32_t*>(info.data);
    EXPECT_EQ(inf[0], 3);  // levels
    EXPECT_EQ(inf[1], 2);  // level 1 is 2x2
    EXPECT_EQ(inf[2], 2);
    EXPECT_EQ(inf[3], 2);  // layers of the array view
  }
  // Hand-checked points: halfway between texels (0,0) and (1,0) of layer 1, level 0, is their average; repeat
  // wraps 1.125 to 0.125.
  float h[4];
  reference(configs[1], 0.25f, 0.125f, 0.0f, 1, h);
  EXPECT_FLOAT_EQ(h[0], 100.5f);
  reference(configs[1], 1.125f, 0.125f, 0.0f, 1, h);
  EXPECT_FLOAT_EQ(h[0], 100.0f);
  // Mirror clamp to edge mirrors once about 0 (u = -0.3: texel -2, mirrored to 1), then clamps (u = 1.9: texel 7,
  // clamped to 3).
  reference(configs[7], -0.3f, 0.125f, 0.0f, 1, h);
  EXPECT_FLOAT_EQ(h[0], 101.0f);
  reference(configs[7], 1.9f, 0.125f, 0.0f, 1, h);
  EXPECT_FLOAT_EQ(h[0], 103.0f);
  for (VkSampler s : samplers) vkDestroySampler(device, s, nullptr);
  vkDestroyImageView(device, arrView, nullptr);
  destroy(img);
  destroy(in);
  destroy(out);
  destroy(info);
  destroy(p);
}

TEST_F(ComputeImageTest, SampleAndFetchWithEveryFilterAndAddressMode) { sampleAndFetch(false); }

// Cube map sampling ("Cube Map Face Selection and Transformations"): a 4x4 R32_SFLOAT cube of 2 levels whose texel
// (i, j) of face f, level m holds 1000 m + 100 f + 10 j + i, sampled NEAREST and LINEAR at directions over every face
// and gathered. The reference selects the face by the spec's table; LINEAR is checked where its 2x2 texels lie
// inside the face, across an edge (seamless, "Cube Map Edge Handling") and across a corner, at points worked out
// by hand.
TEST_F(ComputeImageTest, CubeMapsSelectTheFaceFilterAcrossEdgesAndGather) {
  constexpr VkDescriptorType kCombined = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
  Pipeline p = makePipeline(kSpv_compute_cube_comp, sizeof kSpv_compute_cube_comp,
                            {kCombined, kStorageBuffer, kStorageBuffer, kCombined});
  ASSERT_EQ(p.result, VK_SUCCESS);
  // 12 layers: the cube view sees the first 6, the cube array view both cubes (layer 6 + f is face f of cube 1).
  Tex img = makeTex(VK_IMAGE_TYPE_2D, VK_IMAGE_VIEW_TYPE_CUBE, VK_FORMAT_R32_SFLOAT, {4, 4, 1}, 2, 12, 4,
                    VK_IMAGE_USAGE_SAMPLED_BIT, 0, 6);
  ASSERT_NE(img.view, VK_NULL_HANDLE);
  VkImageViewCreateInfo avi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
  avi.image = img.image;
  avi.viewType = VK_IMAGE_VIEW_TYPE_CUBE_ARRAY;
  avi.format = VK_FORMAT_R32_SFLOAT;
  avi.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, VK_REMAINING_MIP_LEVELS, 0, 12};
  VkImageView arrayView = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateImageView(device, &avi, nullptr, &arrayView), VK_SUCCESS);
  auto value = [](int m, int f, int i, int j) { return float(1000 * m + 100 * f + 10 * j + i); };
  for (int m = 0; m < 2; ++m) {
    const int n = 4 >> m;
    float* t = reinterpret_cast<float*>(static_cast<uint8_t*>(img.staging.data) + img.mipOffsets[m]);
    for (int f = 0; f < 12; ++f)
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) t[(f * n + j) * n + i] = value(m, f, i, j);
  }
  // The spec's face table: major axis, then (sc, tc, ma).
  auto face = [](const float* d, float* s, float* t) {
    const float ax = std::fabs(d[0]), ay = std::fabs(d[1]), az = std::fabs(d[2]);
    int f;
    float sc, tc, ma;
    if (ax > ay && ax > az) {
      f = d[0] > 0 ? 0 : 1, sc = d[0] > 0 ? -d[2] : d[2], tc = -d[1], ma = ax;
    } else if (ay > ax && ay > az) {
      f = d[1] > 0 ? 2 : 3, sc = d[0], tc = d[1] > 0 ? d[2] : -d[2], ma = ay;
    } else {
      f = d[2] > 0 ? 4 : 5, sc = d[2] > 0 ? d[0] : -d[0], tc = -d[1], ma = az;
    }
    *s = 0.5f * (sc / ma + 1), *t = 0.5f * (tc / ma + 1);
    return f;
  };
  std::vector<std::array<float, 4>> dirs;
  for (int axis = 0; axis < 3; ++axis)
    for (float sign : {1.0f, -1.0f})
      for (float a : {-0.8f, -0.3f, 0.05f, 0.45f, 0.7f})
        for (float b : {-0.65f, -0.2f, 0.1f, 0.6f}) {
          std::array<float, 4> d{};
          d[axis] = sign * 1.5f;
          d[(axis + 1) % 3] = a * 1.5f;
          d[(axis + 2) % 3] = b * 1.5f;
          d[3] = (a > 0) ? 1.0f : 0.0f;  // lod
          dirs.push_back(d);
        }
  // Across +X's right edge (s = 15/16, t = 3/8: u = 3.25, v = 1.0): 3/4 of +X's (3, 1) and 1/4 of -Z's (0, 1).
  const size_t edge = dirs.size();
  dirs.push_back({1.0f, 0.25f, -0.875f, 0.0f});
  // Near the cube's (+x, +y, +z) corner on +X (s = t = 0.05: u = v = 0.2, so texels i, j = -1 and 0 with weight
  // 0.3 and 0.7): texel (-1, 0) is past the edge toward +z, +Z's (3, 0); (0, -1) past the edge toward +y, +Y's
  // (3, 3); (-1, -1) is past the corner, where +X's (0, 0), +Z's (3, 0) and +Y's (3, 3) meet: their average ("Cube
  // Map Corner Texel").
  const size_t corner = dirs.size();
  dirs.push_back({1.0f, 0.9f, 0.9f, 0.0f});
  const uint32_t count = uint32_t(dirs.size());
  HostBuffer in = createHostBuffer(count * 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  std::memcpy(in.data, dirs.data(), count * 16);
  HostBuffer out = createHostBuffer(count * 3 * 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  writeBuffer(p, 1, in);
  writeBuffer(p, 2, out);
  VkCommandBuffer cb = beginOneTime();
  upload(cb, img, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
  submitAndWait(cb);
  for (VkFilter filter : {VK_FILTER_NEAREST, VK_FILTER_LINEAR}) {
    VkSamplerCreateInfo si{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
    si.magFilter = si.minFilter = filter;
    si.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
    si.addressModeU = si.addressModeV = si.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
    si.maxLod = VK_LOD_CLAMP_NONE;
    VkSampler sampler;
    ASSERT_EQ(vkCreateSampler(device, &si, nullptr, &sampler), VK_SUCCESS);
    writeImage(p, 0, kCombined, img.view, sampler, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    writeImage(p, 3, kCombined, arrayView, sampler, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    std::memset(out.data, 0x7F, out.size);
    cb = beginOneTime();
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout, 0, 1, &p.set, 0, nullptr);
    vkCmdDispatch(cb, count, 1, 1);
    hostBarrier(cb);
    submitAndWait(cb);
    const float* r = static_cast<const float*>(out.data);
    int linearChecked = 0;
    for (uint32_t k = 0; k < edge; ++k) {
      float s, t;
      const int f = face(dirs[k].data(), &s, &t);
      const int m = int(dirs[k][3]), n = 4 >> m;
      const float* got = &r[(3 * k) * 4];
      if (filter == VK_FILTER_NEAREST) {
        const int i = std::min(int(std::floor(s * n)), n - 1), j = std::min(int(std::floor(t * n)), n - 1);
        EXPECT_EQ(got[0], value(m, f, i, j)) << "direction " << k << " face " << f;
        // The cube array's cube 1 (the coordinate 1.2 rounds to 1): layer 6 + f.
        EXPECT_EQ(r[(3 * k + 2) * 4], value(m, 6 + f, i, j)) << "cube array, direction " << k << " face " << f;
      } else {
        const float u = s * n - 0.5f, v = t * n - 0.5f;
        const int i0 = int(std::floor(u)), j0 = int(std::floor(v));
        if (i0 >= 0 && j0 >= 0 && i0 + 1 < n && j0 + 1 < n) {
          const float a = u - float(i0), b = v - float(j0);
          const float want = (1 - a) * (1 - b) * value(m, f, i0, j0) + a * (1 - b) * value(m, f, i0 + 1, j0) +
                             (1 - a) * b * value(m, f, i0, j0 + 1) + a * b * value(m, f, i0 + 1, j0 + 1);
          EXPECT_NEAR(got[0], want, 1e-3f) << "direction " << k << " face " << f;
          ++linearChecked;
        }
      }
      // Gather (level 0, component R): (i0 j1, i1 j1, i1 j0, i0 j0) of the LINEAR footprint, inside the face.
      const float u = s * 4 - 0.5f, v = t * 4 - 0.5f;
      const int i0 = int(std::floor(u)), j0 = int(std::floor(v));
      if (i0 >= 0 && j0 >= 0 && i0 < 3 && j0 < 3) {
        const float* g = &r[(3 * k + 1) * 4];
        EXPECT_EQ(g[0], value(0, f, i0, j0 + 1)) << "gather " << k;
        EXPECT_EQ(g[1], value(0, f, i0 + 1, j0 + 1)) << "gather " << k;
        EXPECT_EQ(g[2], value(0, f, i0 + 1, j0)) << "gather " << k;
        EXPECT_EQ(g[3], value(0, f, i0, j0)) << "gather " << k;
      }
    }
    const float* e = &r[(3 * edge) * 4];
    const float* c = &r[(3 * corner) * 4];
    // Layer offset 0: the cube view; 6: cube 1 of the cube array view.
    for (int base : {0, 6}) {
      SCOPED_TRACE("corner, cube at layer " + std::to_string(base));
      const float own = value(0, base + 0, 0, 0), acrossI = value(0, base + 4, 3, 0),
                  acrossJ = value(0, base + 2, 3, 3), avg = (own + acrossI + acrossJ) / 3;
      const float got = base ? r[(3 * corner + 2) * 4] : c[0];
      if (filter == VK_FILTER_LINEAR)
        EXPECT_NEAR(got, 0.09f * avg + 0.21f * acrossJ + 0.21f * acrossI + 0.49f * own, 1e-3f);
      else
        EXPECT_EQ(got, own);  // NEAREST clamps to the face
      if (base == 0) {
        // The gather of the same footprint: (i0 j1, i1 j1, i1 j0, i0 j0) = (-1 0, 0 0, 0 -1, -1 -1).
        const float* g = &r[(3 * corner + 1) * 4];
        EXPECT_EQ(g[0], acrossI);
        EXPECT_EQ(g[1], own);
        EXPECT_EQ(g[2], acrossJ);
        EXPECT_NEAR(g[3], avg, 1e-4f);
      }
    }
    if (filter == VK_FILTER_LINEAR) {
      EXPECT_GT(linearChecked, 20);
      EXPECT_NEAR(e[0], 0.75f * value(0, 0, 3, 1) + 0.25f * value(0, 5, 0, 1), 1e-3f);
      // The gather of the same point: (3, 2), (-Z 0, 2), (-Z 0, 1), (3, 1).
      const float* g = &r[(3 * edge + 1) * 4];
      EXPECT_EQ(g[0], value(0, 0, 3, 2));
      EXPECT_EQ(g[1], value(0, 5, 0, 2));
      EXPECT_EQ(g[2], value(0, 5, 0, 1));
      EXPECT_EQ(g[3], value(0, 0, 3, 1));
    } else {
      EXPECT_EQ(e[0], value(0, 0, 3, 1));
    }
    vkDestroySampler(device, sampler, nullptr);
  }
  vkDestroyImageView(device, arrayView, nullptr);
  destroy(img);
  destroy(in);
  destroy(out);
  destroy(p);
}

class ComputeAnisotropyTest : public ComputeImageTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o = ComputeImageTest::options();  // (with samplerMirrorClampToEdge: the samplers use it)
    o.features.samplerAnisotropy = VK_TRUE;
    return o;
  }
};

TEST_F(ComputeAnisotropyTest, ExplicitLodSamplingWithAnisotropyIsTheIsotropicFilter) {
  // samplerAnisotropy with maxSamplerAnisotropy at least 16 (the required limit when the feature is supported), and
  // samplers with anisotropyEnable and maxAnisotropy 16 filtering textureLod exactly as without anisotropy.
  VkPhysicalDeviceFeatures f;
  vkGetPhysicalDeviceFeatures(physicalDevice, &f);
  EXPECT_TRUE(f.samplerAnisotropy);
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(physicalDevice, &props);
  EXPECT_GE(props.limits.maxSamplerAnisotropy, 16.0f);
  sampleAndFetch(true);
}

TEST_F(ComputeAnisotropyTest, GradSamplingAveragesAlongTheMajorAxis) {
  // "Texel Anisotropic Filtering" through a shader: a 32x32 RGBA8 image whose R alternates 0 / 255 by column and G by
  // row, sampled with textureGrad. A footprint 4 texels long in x (or 3 in y) and 1 across: maxAnisotropy 16 gives
  // N = 4 (3) bilinear samples of level 0 at x - 1/2 + i / (N + 1) along the long axis, averaged; without anisotropy
  // one bilinear sample. A round footprint samples once either way. The references are computed here.
  constexpr uint32_t kSize = 32;
  auto texel = [](uint32_t x, uint32_t y, int c) -> uint8_t {
    const uint8_t v[4] = {uint8_t(x % 2 ? 255 : 0), uint8_t(y % 2 ? 255 : 0), uint8_t(x * 7), uint8_t(y * 5)};
    return v[c];
  };
  Tex img = makeTex(VK_IMAGE_TYPE_2D, VK_IMAGE_VIEW_TYPE_2D, VK_FORMAT_R8G8B8A8_UNORM, {kSize, kSize, 1}, 1, 1, 4,
                    VK_IMAGE_USAGE_SAMPLED_BIT);
  auto* bytes = static_cast<uint8_t*>(img.staging.data);
  for (uint32_t y = 0; y < kSize; ++y)
    for (uint32_t x = 0; x < kSize; ++x)
      for (int c = 0; c < 4; ++c) bytes[(y * kSize + x) * 4 + c] = texel(x, y, c);
  auto bilinear = [&](double u, double v, int c) {
    const double fu = u * kSize - 0.5, fv = v * kSize - 0.5, a = fu - std::floor(fu), b = fv - std::floor(fv);
    const int i0 = int(std::floor(fu)), j0 = int(std::floor(fv));
    auto t = [&](int i, int j) {
      return texel(uint32_t(std::clamp(i, 0, int(kSize) - 1)), uint32_t(std::clamp(j, 0, int(kSize) - 1)), c) / 255.0;
    };
    return (1 - a) * (1 - b) * t(i0, j0) + a * (1 - b) * t(i0 + 1, j0) + (1 - a) * b * t(i0, j0 + 1) +
           a * b * t(i0 + 1, j0 + 1);
  };
  struct Case {
    float u, v, dx, dy;  // dx along u, dy along v, in texels
    int n;               // the samples along the long axis (1: isotropic)
  };
  const Case cases[] = {{0.43f, 0.61f, 4, 1, 4}, {0.37f, 0.52f, 1, 3, 3}, {0.71f, 0.29f, 2, 2, 1}};
  const uint32_t n = sizeof cases / sizeof cases[0];
  constexpr VkDescriptorType kCombined = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
  Pipeline p = makePipeline(kSpv_compute_grad_aniso_comp, sizeof kSpv_compute_grad_aniso_comp,
                            {kCombined, kCombined, kStorageBuffer, kStorageBuffer});
  ASSERT_EQ(p.result, VK_SUCCESS);
  HostBuffer in = createHostBuffer(n * 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  HostBuffer out = createHostBuffer(n * 32, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  auto* q = static_cast<float*>(in.data);
  for (uint32_t i = 0; i < n; ++i) {
    q[4 * i] = cases[i].u, q[4 * i + 1] = cases[i].v;
    q[4 * i + 2] = cases[i].dx / kSize, q[4 * i + 3] = cases[i].dy / kSize;
  }
  VkSampler samplers[2];
  for (int k = 0; k < 2; ++k) {
    VkSamplerCreateInfo si{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
    si.magFilter = si.minFilter = VK_FILTER_LINEAR;
    si.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
    si.addressModeU = si.addressModeV = si.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
    si.anisotropyEnable = k == 0;
    si.maxAnisotropy = 16.0f;
    si.maxLod = VK_LOD_CLAMP_NONE;
    ASSERT_EQ(vkCreateSampler(device, &si, nullptr, &samplers[k]), VK_SUCCESS);
  }
  const VkImageLayout ro = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
  writeImage(p, 0, kCombined, img.view, samplers[0], ro);
  writeImage(p, 1, kCombined, img.view, samplers[1], ro);
  writeBuffer(p, 2, in);
  writeBuffer(p, 3, out);
  VkCommandBuffer cb = beginOneTime();
  upload(cb, img, ro);
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
  vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout, 0, 1, &p.set, 0, nullptr);
  vkCmdDispatch(cb, n, 1, 1);
  hostBarrier(cb);
  submitAndWait(cb);
  const float* r = static_cast<const float*>(out.data);
  for (uint32_t i = 0; i < n; ++i) {
    const Case& k = cases[i];
    for (int c = 0; c < 4; ++c) {
      double want = 0;
      for (int s = 1; s <= k.n; ++s) {
        const double t = k.n == 1 ? 0.0 : -0.5 + double(s) / (k.n + 1);
        const bool alongU = k.dx > k.dy;
        want += bilinear(k.u + (alongU ? t * k.dx / kSize : 0), k.v + (alongU ? 0 : t * k.dy / kSize), c);
      }
      want /= k.n;
      // Another driver's anisotropic filter is its own (the spec describes one scheme, and GPUs filter in fixed
      // point); vkrt's is that scheme, in float.
      if (!onVkrt()) continue;
      // One isotropic sample takes the RGBA8 fast path, whose LINEAR weights are quantized to 2^-8
      // (docs/graphics-shaders.md): within 2 x 2^-8 of the exact value; the anisotropic samples are float.
      const double oneSample = 2 * 0x1p-8 + 4e-6;
      EXPECT_NEAR(r[8 * i + c], want, k.n == 1 ? oneSample : 1e-5) << "case " << i << " component " << c;
      EXPECT_NEAR(r[8 * i + 4 + c], bilinear(k.u, k.v, c), oneSample) << "case " << i << " isotropic, component " << c;
    }
  }
  // The stripes across the long axis average out: the anisotropic R is far from the single sample's.
  if (onVkrt()) {
    EXPECT_GT(std::fabs(r[0] - r[4]), 0.1f);
  }
  for (VkSampler s : samplers) vkDestroySampler(device, s, nullptr);
  destroy(in);
  destroy(out);
  destroy(img);
  destroy(p);
}

// ---- buffer device address

struct Node {
  float v[4];
  uint64_t next;
  uint32_t tag;
  uint32_t pad;
};

class ComputeBdaTest : public ComputeImageTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o;
    o.features.shaderInt64 = VK_TRUE;  // the shader converts pointers to and from uint64_t
    return o;
  }
};

TEST_F(ComputeBdaTest, BufferReferencePointersWalkALinkedList) {
  Pipeline p = makePipeline(kSpv_compute_bda_linked_list_comp, sizeof kSpv_compute_bda_linked_list_comp, {}, 20);
  ASSERT_EQ(p.result, VK_SUCCESS);
  HostBuffer nodes = createHostBuffer(5 * sizeof(Node), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true);
  const uint32_t count = 45;
  HostBuffer words = createHostBuffer((2 * count + 4) * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true);
  VkBufferDeviceAddressInfo ai{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO};
  ai.buffer = nodes.buffer;
  uint64_t head = vkGetBufferDeviceAddress(device, &ai);
  ai.buffer = words.buffer;
  uint64_t outAddr = vkGetBufferDeviceAddress(device, &ai);
  auto* list = static_cast<Node*>(nodes.data);
  for (uint32_t k = 0; k < 5; ++k)
    list[k] = Node{{float(10 * k + 1), float(k + 7), 0.0f, -1.0f}, head + ((k + 1) % 5) * 32, 100 + k, 0};
  auto* w = static_cast<uint32_t*>(words.data);
  for (uint32_t i = 0; i < 2 * count + 4; ++i) w[i] = 0xDEADBEEF;
  uint8_t push[20];
  std::memcpy(push, &head, 8);
  std::memcpy(push + 8, &outAddr, 8);
  std::memcpy(push + 16, &count, 4);
  VkCommandBuffer cb = beginOneTime();
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
  vkCmdPushConstants(cb, p.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, 20, push);
  vkCmdDispatch(cb, 3, 1, 1);
  hostBarrier(cb);
  submitAndWait(cb);
  for (uint32_t i = 0; i < count; ++i) {
    uint32_t steps = i % 5, sum = 0;
    for (uint32_t s = 0; s < steps; ++s) sum += 100 + s;
    EXPECT_EQ(w[2 * i], sum + 10 * steps + 1) << i;
    EXPECT_EQ(w[2 * i + 1], (100 + i % 5) * 1000 + (i % 5) + 7) << i;
  }
  for (uint32_t i = 2 * count; i < 2 * count + 4; ++i) EXPECT_EQ(w[i], 0xDEADBEEFu);
  for (uint32_t k = 0; k < 5; ++k) {
    EXPECT_EQ(list[k].v[3], float(k * 3)) << k;
    EXPECT_EQ(list[k].next, head + ((k + 1) % 5) * 32);
  }
  destroy(nodes);
  destroy(words);
  destroy(p);
}

// ---- a module in the shape DXC emits (tests/shaders/dxc_compute.spvasm), with a real image to query

TEST_F(ComputeImageTest, DxcShapedHlslComputeModule) {
  using namespace vkrt::testing;
  Pipeline p =
      makePipeline(kSpv_dxc_compute_spvasm, sizeof kSpv_dxc_compute_spvasm,
                   {VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, kStorageBuffer, kStorageBuffer, kStorageImage, kStorageBuffer});
  ASSERT_EQ(p.result, VK_SUCCESS);
  DxcParams params = dxcParams();
  std::vector<uint32_t> raw = dxcRaw();
  HostBuffer cbuf = createHostBuffer(sizeof params, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
  std::memcpy(cbuf.data, &params, sizeof params);
  HostBuffer out = createHostBuffer(kDxcVectors * 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  std::vector<float> outInit(kDxcVectors * 4, -7.0f);
  std::memcpy(out.data, outInit.data(), out.size);
  HostBuffer rawBuf = createHostBuffer(raw.size() * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  std::memcpy(rawBuf.data, raw.data(), rawBuf.size);
  HostBuffer dst = createHostBuffer(kDxcVectors * 8, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  std::vector<uint32_t> dstInit(kDxcVectors * 2, 0xdeadbeefu);
  std::memcpy(dst.data, dstInit.data(), dst.size);
  Tex img = makeTex(VK_IMAGE_TYPE_2D, VK_IMAGE_VIEW_TYPE_2D, VK_FORMAT_R32G32B32A32_SFLOAT, {7, 3, 1}, 1, 1, 16,
                    VK_IMAGE_USAGE_STORAGE_BIT);
  VkDescriptorBufferInfo cbi{cbuf.buffer, 0, VK_WHOLE_SIZE};
  VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
  w.dstSet = p.set;
  w.dstBinding = 0;
  w.descriptorCount = 1;
  w.descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
  w.pBufferInfo = &cbi;
  vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);
  writeBuffer(p, 1, out);
  writeBuffer(p, 2, rawBuf);
  writeImage(p, 3, kStorageImage, img.view, VK_NULL_HANDLE, VK_IMAGE_LAYOUT_GENERAL);
  writeBuffer(p, 4, dst);
  VkCommandBuffer cb = beginOneTime();
  upload(cb, img, VK_IMAGE_LAYOUT_GENERAL);
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
  vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout, 0, 1, &p.set, 0, nullptr);
  vkCmdDispatch(cb, kDxcInvocations / 8, 1, 1);
  hostBarrier(cb);
  submitAndWait(cb);
  std::vector<float> wantOut;
  std::vector<uint32_t> wantDst;
  const uint32_t dims[2] = {7, 3};
  dxcExpected(params, raw, dims, -7.0f, 0xdeadbeefu, &wantOut, &wantDst);
  expectDxc(static_cast<const float*>(out.data), static_cast<const uint32_t*>(dst.data), wantOut, wantDst);
  destroy(img);
  destroy(cbuf);
  destroy(out);
  destroy(rawBuf);
  destroy(dst);
  destroy(p);
}

// ---- image descriptor arrays indexed per invocation

class ComputeImageIndexingTest : public ComputeImageTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o;
    enableDescriptorIndexing(o);
    return o;
  }
};

TEST_F(ComputeImageIndexingTest, NonUniformIndicesIntoImageDescriptorArrays) {
  constexpr VkDescriptorType kCombined = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
  constexpr uint32_t kTex = 4, kImg = 3, kW = 4, kH = 2;
  Pipeline p = makeComputePipelineWithArrays(device, kSpv_compute_nonuniform_images_comp,
                                             sizeof kSpv_compute_nonuniform_images_comp,
                                             {{kCombined, kTex}, {kStorageImage, kImg}, {kStorageBuffer}});
  ASSERT_EQ(p.result, VK_SUCCESS);
  // Sampled texture t, texel (x, y): {100 t + x + 4 y, t, x / 2, y}; 4x2 and 8x2 alternately (textureSize differs).
  auto texel = [](uint32_t t, uint32_t x, uint32_t y, float out[4]) {
    out[0] = float(100 * t + x + 4 * y);
    out[1] = float(t);
    out[2] = float(x) * 0.5f;
    out[3] = float(y);
  };
  std::vector<Tex> tex, img;
  VkCommandBuffer cb = beginOneTime();
  for (uint32_t t = 0; t < kTex; ++t) {
    uint32_t w = kW * (1 + t % 2);
    tex.push_back(makeTex(VK_IMAGE_TYPE_2D, VK_IMAGE_VIEW_TYPE_2D, VK_FORMAT_R32G32B32A32_SFLOAT, {w, kH, 1}, 1, 1, 16,
                          VK_IMAGE_USAGE_SAMPLED_BIT));
    auto* f = static_cast<float*>(tex.back().staging.data);
    for (uint32_t y = 0; y < kH; ++y)
      for (uint32_t x = 0; x < w; ++x) texel(t, x, y, f + (y * w + x) * 4);
    upload(cb, tex.back(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
  }
  // Storage image s (4x2, 5x2, 6x2): texel (x, y) = 1000 s + x + 4 y.
  for (uint32_t s = 0; s < kImg; ++s) {
    img.push_back(makeTex(VK_IMAGE_TYPE_2D, VK_IMAGE_VIEW_TYPE_2D, VK_FORMAT_R32_UINT, {kW + s, kH, 1}, 1, 1, 4,
                          VK_IMAGE_USAGE_STORAGE_BIT));
    auto* u = static_cast<uint32_t*>(img.back().staging.data);
    for (uint32_t y = 0; y < kH; ++y)
      for (uint32_t x = 0; x < kW + s; ++x) u[y * (kW + s) + x] = 1000 * s + x + 4 * y;
    upload(cb, img.back(), VK_IMAGE_LAYOUT_GENERAL);
  }
  submitAndWait(cb);
  VkSamplerCreateInfo si{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
  si.magFilter = si.minFilter = VK_FILTER_NEAREST;
  si.addressModeU = si.addressModeV = si.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
  VkSampler sampler = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateSampler(device, &si, nullptr, &sampler), VK_SUCCESS);
  for (uint32_t t = 0; t < kTex; ++t)
    writeImage(p, 0, kCombined, tex[t].view, sampler, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, t);
  for (uint32_t s = 0; s < kImg; ++s)
    writeImage(p, 1, kStorageImage, img[s].view, VK_NULL_HANDLE, VK_IMAGE_LAYOUT_GENERAL, s);
  HostBuffer out = createHostBuffer(kW * kH * 3 * 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  std::memset(out.data, 0x7f, out.size);
  writeBuffer(p, 2, out);
  cb = beginOneTime();
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
  vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout, 0, 1, &p.set, 0, nullptr);
  vkCmdDispatch(cb, 1, 1, 1);
  for (Tex& t : img) download(cb, t);
  hostBarrier(cb);
  submitAndWait(cb);

  const auto* o = static_cast<const float*>(out.data);
  for (uint32_t y = 0; y < kH; ++y)
    for (uint32_t x = 0; x < kW; ++x) {
      uint32_t i = y * kW + x, t = (i * 5 + 1) % 4, s = (i + y) % 3;
      SCOPED_TRACE("invocation " + std::to_string(i) + ": texture " + std::to_string(t) + ", image " +
                   std::to_string(s));
      float want[4];
      texel(t, x, y, want);
      for (int k = 0; k < 4; ++k) EXPECT_EQ(o[i * 12 + k], want[k]) << "texelFetch component " << k;
      // textureLod at u = (x + 0.5) / 4: texel x of a 4-wide texture, texel floor(8u) = 2x + 1 of an 8-wide one.
      texel(t, t % 2 ? 2 * x + 1 : x, y, want);
      for (int k = 0; k < 4; ++k) EXPECT_EQ(o[i * 12 + 4 + k], want[k]) << "textureLod component " << k;
      EXPECT_EQ(o[i * 12 + 8], float(1000 * s + x + 4 * y)) << "imageLoad";
      EXPECT_EQ(o[i * 12 + 9], float(kW + s)) << "imageSize().x";
      EXPECT_EQ(o[i * 12 + 10], float(kH)) << "imageSize().y";
      EXPECT_EQ(o[i * 12 + 11], float(kW * (1 + t % 2))) << "textureSize().x";
    }
  for (uint32_t s = 0; s < kImg; ++s) {
    const auto* u = static_cast<const uint32_t*>(img[s].staging.data);
    for (uint32_t y = 0; y < kH; ++y)
      for (uint32_t x = 0; x < kW + s; ++x) {
        uint32_t old = 1000 * s + x + 4 * y, i = y * kW + x;
        bool written = x < kW && (i + y) % 3 == s;
        EXPECT_EQ(u[y * (kW + s) + x], written ? old * 2 + i : old)
            << "storage image " << s << " texel " << x << "," << y;
      }
  }
  vkDestroySampler(device, sampler, nullptr);
  for (Tex& t : tex) destroy(t);
  for (Tex& t : img) destroy(t);
  destroy(out);
  destroy(p);
}

// ---- accesses outside the image (VK_EXT_image_robustness, enabled by name, and robustImageAccess)

class ComputeImageRobustnessTest : public ComputeImageTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o;
    o.deviceExtensions = {VK_EXT_IMAGE_ROBUSTNESS_EXTENSION_NAME};
    o.features13.robustImageAccess = VK_TRUE;
    return o;
  }
};

TEST_F(ComputeImageRobustnessTest, OutOfBoundsLoadsReadZerosAndStoresAreDropped) {
  const bool vkrt = onVkrt();
  Pipeline p = makePipeline(kSpv_compute_image_robustness_comp, sizeof kSpv_compute_image_robustness_comp,
                            {kStorageImage, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, kStorageBuffer});
  ASSERT_EQ(p.result, VK_SUCCESS);
  // Storage image texel (x, y) = {x + 4y, 1, 2, 3}; texture level m texel (x, y) = {10m + x + 4y, 5, 6, 7}.
  Tex img = makeTex(VK_IMAGE_TYPE_2D, VK_IMAGE_VIEW_TYPE_2D, VK_FORMAT_R32G32B32A32_SFLOAT, {4, 4, 1}, 1, 1, 16,
                    VK_IMAGE_USAGE_STORAGE_BIT);
  Tex tex = makeTex(VK_IMAGE_TYPE_2D, VK_IMAGE_VIEW_TYPE_2D, VK_FORMAT_R32G32B32A32_SFLOAT, {4, 4, 1}, 2, 1, 16,
                    VK_IMAGE_USAGE_SAMPLED_BIT);
  auto* fi = static_cast<float*>(img.staging.data);
  for (int k = 0; k < 16; ++k) {
    const float t[4] = {float(k), 1, 2, 3};
    std::memcpy(fi + 4 * k, t, 16);
  }
  auto* ft = static_cast<float*>(tex.staging.data);
  for (int m = 0; m < 2; ++m) {
    int n = 4 >> m;
    for (int k = 0; k < n * n; ++k) {
      const float t[4] = {float(10 * m + k % n + 4 * (k / n)), 5, 6, 7};
      std::memcpy(ft + tex.mipOffsets[m] / 4 + 4 * k, t, 16);
    }
  }
  VkCommandBuffer cb = beginOneTime();
  upload(cb, img, VK_IMAGE_LAYOUT_GENERAL);
  upload(cb, tex, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
  submitAndWait(cb);
  VkSamplerCreateInfo si{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
  si.magFilter = si.minFilter = VK_FILTER_NEAREST;
  si.addressModeU = si.addressModeV = si.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
  si.maxLod = VK_LOD_CLAMP_NONE;
  VkSampler sampler = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateSampler(device, &si, nullptr, &sampler), VK_SUCCESS);
  writeImage(p, 0, kStorageImage, img.view, VK_NULL_HANDLE, VK_IMAGE_LAYOUT_GENERAL);
  writeImage(p, 1, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, tex.view, sampler,
             VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
  HostBuffer out = createHostBuffer(8 * 3 * 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  std::memset(out.data, 0x7f, out.size);
  writeBuffer(p, 2, out);
  std::memset(img.staging.data, 0, img.staging.size);
  cb = beginOneTime();
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
  vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout, 0, 1, &p.set, 0, nullptr);
  vkCmdDispatch(cb, 1, 1, 1);
  download(cb, img);
  hostBarrier(cb);
  submitAndWait(cb);

  const auto* o = static_cast<const float*>(out.data);
  // Outside x, y, z or layer, robustImageAccess returns zero for R, G, B and zero or one for A.
  auto expectReplaced = [](const float* v, const char* what) {
    EXPECT_EQ(v[0], 0.0f) << what;
    EXPECT_EQ(v[1], 0.0f) << what;
    EXPECT_EQ(v[2], 0.0f) << what;
    EXPECT_TRUE(v[3] == 0.0f || v[3] == 1.0f) << what << ": alpha " << v[3];
  };
  for (int i = 0; i < 7; ++i) {
    SCOPED_TRACE("invocation " + std::to_string(i));
    expectReplaced(o + (i * 3 + 0) * 4, "imageLoad");
    expectReplaced(o + (i * 3 + 1) * 4, "texelFetch");
  }
  const float inside[4] = {9, 1, 2, 3}, fetched[4] = {9, 5, 6, 7};
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(o[21 * 4 + k], inside[k]) << "imageLoad inside, component " << k;
    EXPECT_EQ(o[22 * 4 + k], fetched[k]) << "texelFetch inside, component " << k;
  }
  // A level past the last is not covered by robustImageAccess (undefined); vkrt reads zeros.
  if (vkrt) {
    for (int i = 0; i < 8; ++i)
      for (int k = 0; k < 4; ++k) EXPECT_EQ(o[(i * 3 + 2) * 4 + k], 0.0f) << "invocation " << i << " level " << 2 + i;
  }
  // Only the store inside the image landed.
  for (int k = 0; k < 16; ++k) {
    const float want[4] = {k == 9 ? 99.0f : float(k), k == 9 ? 98.0f : 1, k == 9 ? 97.0f : 2, k == 9 ? 96.0f : 3};
    for (int c = 0; c < 4; ++c) EXPECT_EQ(fi[4 * k + c], want[c]) << "texel " << k << " component " << c;
  }
  vkDestroySampler(device, sampler, nullptr);
  destroy(img);
  destroy(tex);
  destroy(out);
  destroy(p);
}

// ---- 8/16-bit integers and 16-bit floats

class ComputeSmallTypesTest : public ComputeImageTest {
 protected:
  VkPhysicalDeviceVulkan11Features f11{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES};
  FixtureOptions options() override {
    FixtureOptions o;
    o.features.shaderInt16 = VK_TRUE;
    o.shaderSmallTypes = true;  // shaderInt8, shaderFloat16, storageBuffer8BitAccess
    f11.storageBuffer16BitAccess = VK_TRUE;
    o.featureChain = &f11;
    return o;
  }
};

TEST_F(ComputeSmallTypesTest, FeaturesReportedAndShaderRuns) {
  VkPhysicalDeviceShaderFloat16Int8Features f16{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_FLOAT16_INT8_FEATURES};
  VkPhysicalDevice8BitStorageFeatures s8{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_8BIT_STORAGE_FEATURES, &f16};
  VkPhysicalDevice16BitStorageFeatures s16{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_16BIT_STORAGE_FEATURES, &s8};
  VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &s16};
  vkGetPhysicalDeviceFeatures2(physicalDevice, &f2);
  EXPECT_TRUE(f2.features.shaderInt16);
  EXPECT_TRUE(f16.shaderFloat16);
  EXPECT_TRUE(f16.shaderInt8);
  EXPECT_TRUE(s8.storageBuffer8BitAccess);
  EXPECT_TRUE(s16.storageBuffer16BitAccess);

  using namespace vkrt::testing;
  Pipeline p = makePipeline(kSpv_compute_small_types_comp, sizeof kSpv_compute_small_types_comp,
                            {kStorageBuffer, kStorageBuffer});
  ASSERT_EQ(p.result, VK_SUCCESS);
  SmallIn in = smallInput();
  HostBuffer inBuf = createHostBuffer(sizeof in, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  std::memcpy(inBuf.data, &in, sizeof in);
  HostBuffer outBuf = createHostBuffer(offsetof(SmallOut, hmathFused), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  std::memset(outBuf.data, 0, outBuf.size);
  writeBuffer(p, 0, inBuf);
  writeBuffer(p, 1, outBuf);
  VkCommandBuffer cb = beginOneTime();
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
  vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout, 0, 1, &p.set, 0, nullptr);
  vkCmdDispatch(cb, 2, 1, 1);
  hostBarrier(cb);
  submitAndWait(cb);
  SmallOut got{};
  std::memcpy(&got, outBuf.data, outBuf.size);
  expectSmall(got, smallExpected(in));
  destroy(inBuf);
  destroy(outBuf);
  destroy(p);
}

// Image atomics on r32ui / r32i storage images (OpImageTexelPointer): additions and minima from 128 invocations
// over 16 texels, and a compare-exchange race that exactly one invocation per texel wins.
TEST_F(ComputeImageTest, ImageAtomicsOnR32Images) {
  Pipeline p = makePipeline(kSpv_compute_image_atomics_comp, sizeof kSpv_compute_image_atomics_comp,
                            {kStorageImage, kStorageImage, kStorageImage, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER});
  const VkImageUsageFlags st = VK_IMAGE_USAGE_STORAGE_BIT;
  Tex counts = makeTex(VK_IMAGE_TYPE_2D, VK_IMAGE_VIEW_TYPE_2D, VK_FORMAT_R32_UINT, {4, 4, 1}, 1, 1, 4, st);
  Tex minima = makeTex(VK_IMAGE_TYPE_2D, VK_IMAGE_VIEW_TYPE_2D, VK_FORMAT_R32_SINT, {4, 4, 1}, 1, 1, 4, st);
  Tex winners = makeTex(VK_IMAGE_TYPE_2D, VK_IMAGE_VIEW_TYPE_2D, VK_FORMAT_R32_UINT, {4, 4, 1}, 1, 1, 4, st);
  HostBuffer out = createHostBuffer(2 * 128 * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  auto* c = static_cast<uint32_t*>(counts.staging.data);
  auto* mn = static_cast<int32_t*>(minima.staging.data);
  auto* w = static_cast<uint32_t*>(winners.staging.data);
  for (uint32_t t = 0; t < 16; ++t) c[t] = 1000 * t, mn[t] = int32_t(t) - 50, w[t] = 0;
  Tex* all[] = {&counts, &minima, &winners};
  for (uint32_t b = 0; b < 3; ++b)
    writeImage(p, b, kStorageImage, all[b]->view, VK_NULL_HANDLE, VK_IMAGE_LAYOUT_GENERAL);
  writeBuffer(p, 3, out);
  VkCommandBuffer cb = beginOneTime();
  for (Tex* t : all) upload(cb, *t, VK_IMAGE_LAYOUT_GENERAL);
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
  vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout, 0, 1, &p.set, 0, nullptr);
  vkCmdDispatch(cb, 2, 1, 1);
  for (Tex* t : all) download(cb, *t);
  hostBarrier(cb);
  submitAndWait(cb);
  const auto* swapped = static_cast<const uint32_t*>(out.data);
  for (uint32_t t = 0; t < 16; ++t) {
    uint32_t sum = 1000 * t;
    int32_t least = int32_t(t) - 50;
    uint32_t zeros = 0;
    for (uint32_t i = t; i < 128; i += 16) {
      sum += i + 1;
      least = std::min(least, int32_t(i) - 100);
      if (swapped[i] == 0)
        ++zeros;
      else
        EXPECT_EQ(swapped[i], w[t]) << "invocation " << i << " saw another winner than the texel holds";
    }
    EXPECT_EQ(c[t], sum) << "texel " << t;
    EXPECT_EQ(mn[t], least) << "texel " << t;
    EXPECT_EQ(zeros, 1u) << "texel " << t << ": one invocation wins the compare-exchange";
    EXPECT_EQ((w[t] - 1) % 16, t) << "the winner is one of the texel's invocations";
  }
  // Atomics outside the image had no effect: the sums above; what they return is undefined.
  for (Tex* t : all) destroy(*t);
  destroy(out);
  destroy(p);
}

// ---- storage images without a format (Image Format Unknown)

// compute_formatless_image.comp over views of the formats ray tracing samples write (R8G8B8A8_UNORM,
// B8G8R8A8_UNORM, R16G16B16A16_SFLOAT, R32G32B32A32_SFLOAT) and others (R32_SFLOAT, R32_UINT, 16- and 32-bit
// four-component integers), with shaderStorageImageReadWithoutFormat and shaderStorageImageWriteWithoutFormat
// enabled; texels expected from tests/spirv/formatless_reference.hpp.
class ComputeFormatlessTest : public ComputeImageTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o;
    o.features.shaderStorageImageReadWithoutFormat = VK_TRUE;
    o.features.shaderStorageImageWriteWithoutFormat = VK_TRUE;
    return o;
  }

  // One 2 x 2 dispatch (8 x 8 texels) of `p` over new images of the formats `f`; compares every texel of the four.
  void runRound(Pipeline& p, const testing::FormatlessImages& f, uint32_t seed) {
    using namespace vkrt::testing;
    SCOPED_TRACE(std::string("src ") + f.src->name + ", dst " + f.dst->name + ", acc " + f.acc->name + ", ids " +
                 f.ids->name);
    const StorageFormat* formats[4] = {f.src, f.dst, f.acc, f.ids};
    std::vector<uint8_t> texels[4];
    Tex tex[4];
    for (uint32_t b = 0; b < 4; ++b) {
      texels[b] = inputTexels(*formats[b], 64, seed * 4 + b);
      tex[b] = makeTex(VK_IMAGE_TYPE_2D, VK_IMAGE_VIEW_TYPE_2D, formats[b]->format, {8, 8, 1}, 1, 1,
                       formats[b]->texelSize(), VK_IMAGE_USAGE_STORAGE_BIT);
      std::memcpy(tex[b].staging.data, texels[b].data(), texels[b].size());
      writeImage(p, b, kStorageImage, tex[b].view, VK_NULL_HANDLE, VK_IMAGE_LAYOUT_GENERAL);
    }
    VkCommandBuffer cb = beginOneTime();
    for (Tex& t : tex) upload(cb, t, VK_IMAGE_LAYOUT_GENERAL);
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout, 0, 1, &p.set, 0, nullptr);
    vkCmdDispatch(cb, 2, 2, 1);
    for (Tex& t : tex) download(cb, t);
    hostBarrier(cb);
    submitAndWait(cb);
    std::vector<uint8_t> src = texels[0];
    expectedFormatless(f, 8, 8, src, texels[1], texels[2], texels[3]);
    const char* names[4] = {"src (read only)", "dst", "acc", "ids"};
    // The spec leaves the rounding of a float stored to a 16-bit float texel to the driver (RTE or RTZ); vkrt
    // rounds to nearest even.
    for (uint32_t b = 0; b < 4; ++b) {
      const auto* got = static_cast<const uint8_t*>(tex[b].staging.data);
      expectTexels(*formats[b], std::vector<uint8_t>(got, got + texels[b].size()), texels[b], names[b], !onVkrt());
      destroy(tex[b]);
    }
  }
  void runAllRounds() {
    using namespace vkrt::testing;
    Pipeline p = makePipeline(kSpv_compute_formatless_image_comp, sizeof kSpv_compute_formatless_image_comp,
                              {kStorageImage, kStorageImage, kStorageImage, kStorageImage});
    ASSERT_EQ(p.result, VK_SUCCESS);
    const FormatlessImages rounds[] = {
        {&kRgba8, &kRgba16f, &kRgba32f, &kR32ui}, {&kBgra8, &kRgba8, &kRgba16f, &kRgba16ui},
        {&kRgba32f, &kBgra8, &kR32f, &kRgba32ui}, {&kRgba16f, &kRgba32f, &kBgra8, &kR32ui},
        {&kR32f, &kR32f, &kRgba8, &kRgba16ui},
    };
    uint32_t seed = 0;
    for (const FormatlessImages& f : rounds) runRound(p, f, ++seed);
    destroy(p);
  }
};

TEST_F(ComputeFormatlessTest, FeaturesAndFormatFeaturesAreReported) {
  VkPhysicalDeviceFeatures f;
  vkGetPhysicalDeviceFeatures(physicalDevice, &f);
  EXPECT_TRUE(f.shaderStorageImageReadWithoutFormat);
  EXPECT_TRUE(f.shaderStorageImageWriteWithoutFormat);
  const VkFormatFeatureFlags2 both =
      VK_FORMAT_FEATURE_2_STORAGE_READ_WITHOUT_FORMAT_BIT | VK_FORMAT_FEATURE_2_STORAGE_WRITE_WITHOUT_FORMAT_BIT;
  // Formats, "Formats Without Shader Storage Format": with both features supported (Vulkan 1.3), each listed
  // format that supports storage images supports both bits.
  const VkFormat listed[] = {
      VK_FORMAT_R8G8B8A8_UNORM,
      VK_FORMAT_R8G8B8A8_SNORM,
      VK_FORMAT_R8G8B8A8_UINT,
      VK_FORMAT_R8G8B8A8_SINT,
      VK_FORMAT_R32_UINT,
      VK_FORMAT_R32_SINT,
      VK_FORMAT_R32_SFLOAT,
      VK_FORMAT_R32G32_UINT,
      VK_FORMAT_R32G32_SINT,
      VK_FORMAT_R32G32_SFLOAT,
      VK_FORMAT_R32G32B32A32_UINT,
      VK_FORMAT_R32G32B32A32_SINT,
      VK_FORMAT_R32G32B32A32_SFLOAT,
      VK_FORMAT_R16G16B16A16_UINT,
      VK_FORMAT_R16G16B16A16_SINT,
      VK_FORMAT_R16G16B16A16_SFLOAT,
      VK_FORMAT_R16G16_SFLOAT,
      VK_FORMAT_B10G11R11_UFLOAT_PACK32,
      VK_FORMAT_R16_SFLOAT,
      VK_FORMAT_R16G16B16A16_UNORM,
      VK_FORMAT_A2B10G10R10_UNORM_PACK32,
      VK_FORMAT_R16G16_UNORM,
      VK_FORMAT_R8G8_UNORM,
      VK_FORMAT_R16_UNORM,
      VK_FORMAT_R8_UNORM,
      VK_FORMAT_R16G16B16A16_SNORM,
      VK_FORMAT_R16G16_SNORM,
      VK_FORMAT_R8G8_SNORM,
      VK_FORMAT_R16_SNORM,
      VK_FORMAT_R8_SNORM,
      VK_FORMAT_R16G16_SINT,
      VK_FORMAT_R8G8_SINT,
      VK_FORMAT_R16_SINT,
      VK_FORMAT_R8_SINT,
      VK_FORMAT_A2B10G10R10_UINT_PACK32,
      VK_FORMAT_R16G16_UINT,
      VK_FORMAT_R8G8_UINT,
      VK_FORMAT_R16_UINT,
      VK_FORMAT_R8_UINT,
  };
  auto query = [&](VkFormat format) {
    VkFormatProperties3 p3{VK_STRUCTURE_TYPE_FORMAT_PROPERTIES_3};
    VkFormatProperties2 p2{VK_STRUCTURE_TYPE_FORMAT_PROPERTIES_2, &p3};
    vkGetPhysicalDeviceFormatProperties2(physicalDevice, format, &p2);
    return p3;
  };
  for (VkFormat format : listed) {
    VkFormatProperties3 p3 = query(format);
    for (VkFormatFeatureFlags2 tiling : {p3.linearTilingFeatures, p3.optimalTilingFeatures}) {
      if (tiling & VK_FORMAT_FEATURE_2_STORAGE_IMAGE_BIT) {
        EXPECT_EQ(tiling & both, both) << "format " << format;
      }
    }
  }
  // The formats the tests bind, B8G8R8A8_UNORM among them (no SPIR-V Image Format names it: a storage image of it
  // can only be accessed without a format).
  for (const testing::StorageFormat* sf :
       {&testing::kRgba8, &testing::kBgra8, &testing::kRgba16f, &testing::kRgba32f, &testing::kR32f, &testing::kR32ui,
        &testing::kRgba16ui, &testing::kRgba32ui}) {
    VkFormatProperties3 p3 = query(sf->format);
    EXPECT_EQ(p3.optimalTilingFeatures & (both | VK_FORMAT_FEATURE_2_STORAGE_IMAGE_BIT),
              both | VK_FORMAT_FEATURE_2_STORAGE_IMAGE_BIT)
        << sf->name;
  }
  if (!onVkrt()) return;
  // vkrt: every storage format has both bits, in both tilings; buffer features have neither (storage texel
  // buffers are not compiled), and VkFormatProperties (Vulkan 1.0's flags) is unchanged.
  int storageFormats = 0;
  for (int format = VK_FORMAT_R4G4_UNORM_PACK8; format <= VK_FORMAT_ASTC_12x12_SRGB_BLOCK; ++format) {
    VkFormatProperties3 p3 = query(VkFormat(format));
    VkFormatProperties p1;
    vkGetPhysicalDeviceFormatProperties(physicalDevice, VkFormat(format), &p1);
    // Beyond `both`, depth formats have SAMPLED_IMAGE_DEPTH_COMPARISON (tests/e2e/depth_compare_test.cpp).
    EXPECT_EQ(p3.optimalTilingFeatures & ~both & ~VK_FORMAT_FEATURE_2_SAMPLED_IMAGE_DEPTH_COMPARISON_BIT,
              VkFormatFeatureFlags2(p1.optimalTilingFeatures))
        << format;
    // Linear tiling as optimal, but for the compressed formats: optimal tiling only (CompressedFormatTest).
    const bool compressed = format >= VK_FORMAT_BC1_RGB_UNORM_BLOCK;
    EXPECT_EQ(p3.linearTilingFeatures, compressed ? 0 : p3.optimalTilingFeatures) << format;
    EXPECT_EQ(p3.bufferFeatures & both, 0u) << format;
    const bool storage = p3.optimalTilingFeatures & VK_FORMAT_FEATURE_2_STORAGE_IMAGE_BIT;
    EXPECT_EQ(p3.optimalTilingFeatures & both, storage ? both : 0) << format;
    storageFormats += storage;
  }
  EXPECT_GE(storageFormats, 8);
}

TEST_F(ComputeFormatlessTest, ReadsAndWritesConvertFromAndToTheBoundViewsFormat) { runAllRounds(); }

// The same pipeline on a device without the two features. On a Vulkan 1.3 device that is valid use, so vkrt
// creates and runs it and reports nothing: the capability table (SPIR-V Environment, "Capabilities";
// VUID-VkShaderModuleCreateInfo-pCode-01091) allows StorageImageReadWithoutFormat and
// StorageImageWriteWithoutFormat with the feature, VK_KHR_format_feature_flags2, or Vulkan 1.3 as
// VkPhysicalDeviceProperties::apiVersion reports it; and the NonReadable / NonWritable decorations are required
// only where apiVersion is below 1.3 and VK_KHR_format_feature_flags2 is not supported
// (VUID-RuntimeSpirv-apiVersion-07954 and -07955). Where the features do not apply, the view's format features
// (STORAGE_READ/WRITE_WITHOUT_FORMAT, reported for every storage format) govern. The 1.3.239 validation layer
// still applies those rules as 1.3.239's text worded them, without the version condition the specification added
// later (VUID-RuntimeSpirv-OpTypeImage-06269 and -06270): exactly those messages are accepted here.
class ComputeFormatlessWithoutFeaturesTest : public ComputeFormatlessTest {
 protected:
  FixtureOptions options() override { return {}; }
};

TEST_F(ComputeFormatlessWithoutFeaturesTest, AVulkan13DeviceRunsThemByTheFormatFeatures) {
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(physicalDevice, &props);
  if (VK_API_VERSION_MINOR(props.apiVersion) < 3) GTEST_SKIP() << "the features are required below Vulkan 1.3";
  runAllRounds();
  int layerReports = 0;
  for (const Message& m : layerMessages()) {
    const bool outdatedRule =
        m.idName == "VUID-RuntimeSpirv-OpTypeImage-06269" || m.idName == "VUID-RuntimeSpirv-OpTypeImage-06270";
    EXPECT_TRUE(outdatedRule) << "unexpected validation message: " << m.text.substr(0, 300);
    layerReports += outdatedRule;
  }
  for (const Message& m : vkrtMessages()) ADD_FAILURE() << "vkrt reported valid use: " << m.text;
  clearMessages();
  RecordProperty("layer_reports_of_the_1_3_239_rule", layerReports);
}

}  // namespace
}  // namespace vkrt::test
