// A ray generation shader storing its results into storage images declared without a format (Image Format
// Unknown), as most public ray tracing samples write their output (GLSL `uniform image2D image;`, reads with
// GL_EXT_shader_image_load_formatted): tests/shaders/formatless_raygen.rgen traces the basic scene of
// trace_fixture.hpp and stores a colour, an accumulated colour and the hit's ids into views of several formats,
// one pipeline for all of them. Every texel is compared with bytes computed here from the scene's geometry and the
// formats' conversion rules (tests/spirv/formatless_reference.hpp). The validation layer is on.
#include <string>
#include <vector>

#include "e2e/trace_fixture.hpp"
#include "formatless_raygen.rgen.spv.h"
#include "spirv/formatless_reference.hpp"

namespace vkrt::test {
namespace {

using testing::Float4;
using testing::StorageFormat;
using testing::Uint4;

constexpr uint32_t kSize = 8;  // an 8 x 8 launch over 8 x 8 images

class FormatlessRaygenTest : public TraceTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o = TraceTest::options();
    o.features.shaderStorageImageReadWithoutFormat = VK_TRUE;
    o.features.shaderStorageImageWriteWithoutFormat = VK_TRUE;
    return o;
  }

  void SetUp() override {
    TraceTest::SetUp();
    if (HasFatalFailure() || !device) return;
    VkDescriptorSetLayoutBinding b[4] = {
        {0, VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 1, VK_SHADER_STAGE_RAYGEN_BIT_KHR, nullptr},
        {1, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, VK_SHADER_STAGE_RAYGEN_BIT_KHR, nullptr},
        {2, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, VK_SHADER_STAGE_RAYGEN_BIT_KHR, nullptr},
        {3, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, VK_SHADER_STAGE_RAYGEN_BIT_KHR, nullptr},
    };
    VkDescriptorSetLayoutCreateInfo dl{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    dl.bindingCount = 4;
    dl.pBindings = b;
    ASSERT_EQ(vkCreateDescriptorSetLayout(device, &dl, nullptr, &imageSetLayout), VK_SUCCESS);
    VkPipelineLayoutCreateInfo lci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    lci.setLayoutCount = 1;
    lci.pSetLayouts = &imageSetLayout;
    ASSERT_EQ(vkCreatePipelineLayout(device, &lci, nullptr, &imageLayout), VK_SUCCESS);
    VkDescriptorPoolSize sizes[2] = {{VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 1},
                                     {VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 3}};
    VkDescriptorPoolCreateInfo pci{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    pci.maxSets = 1;
    pci.poolSizeCount = 2;
    pci.pPoolSizes = sizes;
    ASSERT_EQ(vkCreateDescriptorPool(device, &pci, nullptr, &imagePool), VK_SUCCESS);
    VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    ai.descriptorPool = imagePool;
    ai.descriptorSetCount = 1;
    ai.pSetLayouts = &imageSetLayout;
    ASSERT_EQ(vkAllocateDescriptorSets(device, &ai, &imageSet), VK_SUCCESS);
  }
  void TearDown() override {
    if (device) {
      vkDeviceWaitIdle(device);
      for (Img& i : images) destroyImage(i);
      if (imagePool) vkDestroyDescriptorPool(device, imagePool, nullptr);
      if (imageLayout) vkDestroyPipelineLayout(device, imageLayout, nullptr);
      if (imageSetLayout) vkDestroyDescriptorSetLayout(device, imageSetLayout, nullptr);
    }
    TraceTest::TearDown();
  }

  // A kSize x kSize storage image of `f` with a staging buffer of its texels (tightly packed rows).
  struct Img {
    VkImage image = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkImageView view = VK_NULL_HANDLE;
    HostBuffer staging;
  };
  Img makeImage(const StorageFormat& f, const std::vector<uint8_t>& texels) {
    Img i;
    VkImageCreateInfo ci{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    ci.imageType = VK_IMAGE_TYPE_2D;
    ci.format = f.format;
    ci.extent = {kSize, kSize, 1};
    ci.mipLevels = 1;
    ci.arrayLayers = 1;
    ci.samples = VK_SAMPLE_COUNT_1_BIT;
    ci.tiling = VK_IMAGE_TILING_OPTIMAL;
    ci.usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    EXPECT_EQ(vkCreateImage(device, &ci, nullptr, &i.image), VK_SUCCESS);
    if (!i.image) return i;  // no image: nothing to query or bind
    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(device, i.image, &req);
    VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    mai.allocationSize = req.size;
    mai.memoryTypeIndex = memoryTypeIndex(req.memoryTypeBits, 0);
    EXPECT_EQ(vkAllocateMemory(device, &mai, nullptr, &i.memory), VK_SUCCESS);
    EXPECT_EQ(vkBindImageMemory(device, i.image, i.memory, 0), VK_SUCCESS);
    VkImageViewCreateInfo vi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    vi.image = i.image;
    vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
    vi.format = f.format;
    vi.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    EXPECT_EQ(vkCreateImageView(device, &vi, nullptr, &i.view), VK_SUCCESS);
    i.staging = createHostBuffer(texels.size(), VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    std::memcpy(i.staging.data, texels.data(), texels.size());
    return i;
  }
  void destroyImage(Img& i) {
    vkDestroyImageView(device, i.view, nullptr);
    vkDestroyImage(device, i.image, nullptr);
    vkFreeMemory(device, i.memory, nullptr);
    destroy(i.staging);
  }
  static void barrier(VkCommandBuffer cb, VkImage image, VkImageLayout from, VkImageLayout to, VkAccessFlags src,
                      VkAccessFlags dst, VkPipelineStageFlags srcStage, VkPipelineStageFlags dstStage) {
    VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    b.srcAccessMask = src;
    b.dstAccessMask = dst;
    b.oldLayout = from;
    b.newLayout = to;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image;
    b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    vkCmdPipelineBarrier(cb, srcStage, dstStage, 0, 0, nullptr, 0, nullptr, 1, &b);
  }

  VkDescriptorSetLayout imageSetLayout = VK_NULL_HANDLE;
  VkPipelineLayout imageLayout = VK_NULL_HANDLE;
  VkDescriptorPool imagePool = VK_NULL_HANDLE;
  VkDescriptorSet imageSet = VK_NULL_HANDLE;
  std::vector<Img> images;
};

// What formatless_raygen.rgen stores for launch index (x, y) of the basic scene (see expectBasicScene): its colour
// and its ids (instance custom index, primitive, the record's tag, 7; a miss keeps the raygen's 0xffffffff ids and
// the miss record's tag, 7).
struct Expected {
  Float4 colour;
  Uint4 ids;
};
Expected expectedPixel(uint32_t x, uint32_t y) {
  const float wx = cellCentre(x, kSize), wy = cellCentre(y, kSize);
  const bool inB = wx - 1.6f >= -1 && wx - 1.6f <= 1 && wy >= -1 && wy <= 1;
  const bool inA = wx - 0.1f >= -1 && wx - 0.1f <= 1 && wy >= -1 && wy <= 1;
  if (!inA && !inB) return {{0.0f, 0.125f, 0.25f, 0.5f}, {0xffffffffu, 0xffffffffu, 7u, 7u}};
  const uint32_t custom = inB ? 20 : 10, primitive = quadHit(wx - (inB ? 1.6f : 0.1f), wy).primitive;
  return {{float(custom) / 32.0f, float(primitive) * 0.5f + 0.25f, 0.75f, 1.0f},
          {custom, primitive, inB ? 101u : 100u, 7u}};
}

TEST_F(FormatlessRaygenTest, RaygenStoresIntoViewsOfEveryFormatWithOnePipeline) {
  using namespace vkrt::testing;
  Desc d;
  d.layout = imageLayout;
  d.general(module(kSpv_formatless_raygen_rgen, sizeof kSpv_formatless_raygen_rgen), VK_SHADER_STAGE_RAYGEN_BIT_KHR);
  d.general(tmiss, VK_SHADER_STAGE_MISS_BIT_KHR);
  d.group(VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR, VK_SHADER_UNUSED_KHR,
          d.stage(tchit, VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR));
  VkPipeline p = make(d);
  ASSERT_NE(p, VK_NULL_HANDLE);
  const Sbt s = sbt(p, 3, {0}, {{1, {7}}}, {{2, {100}}, {2, {101}}});
  VkAccelerationStructureKHR scene = basicScene();
  VkWriteDescriptorSetAccelerationStructureKHR asw{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_KHR};
  asw.accelerationStructureCount = 1;
  asw.pAccelerationStructures = &scene;
  VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, &asw};
  w.dstSet = imageSet;
  w.dstBinding = 0;
  w.descriptorCount = 1;
  w.descriptorType = VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR;
  vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);

  struct Round {
    const StorageFormat *image, *accum, *ids;
  };
  // The samples' output formats (R8G8B8A8_UNORM, B8G8R8A8_UNORM: a swapchain's; R16G16B16A16_SFLOAT,
  // R32G32B32A32_SFLOAT: accumulation) and the integer formats of an id buffer.
  const Round rounds[] = {{&kRgba8, &kRgba32f, &kR32ui},
                          {&kBgra8, &kRgba16f, &kRgba32ui},
                          {&kRgba16f, &kRgba8, &kR32ui},
                          {&kRgba32f, &kBgra8, &kRgba32ui}};
  uint32_t seed = 0;
  int hits = 0, misses = 0;
  for (const Round& r : rounds) {
    SCOPED_TRACE(std::string("image ") + r.image->name + ", accum " + r.accum->name + ", ids " + r.ids->name);
    const StorageFormat* formats[3] = {r.image, r.accum, r.ids};
    std::vector<uint8_t> want[3];
    Img img[3];
    for (uint32_t b = 0; b < 3; ++b) {
      want[b] = inputTexels(*formats[b], kSize * kSize, ++seed);
      img[b] = makeImage(*formats[b], want[b]);
      images.push_back(img[b]);
    }
    VkDescriptorImageInfo ii[3];
    VkWriteDescriptorSet iw[3];
    for (uint32_t b = 0; b < 3; ++b) {
      ii[b] = {VK_NULL_HANDLE, img[b].view, VK_IMAGE_LAYOUT_GENERAL};
      iw[b] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
      iw[b].dstSet = imageSet;
      iw[b].dstBinding = b + 1;
      iw[b].descriptorCount = 1;
      iw[b].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
      iw[b].pImageInfo = &ii[b];
    }
    vkUpdateDescriptorSets(device, 3, iw, 0, nullptr);

    VkCommandBuffer cb = beginOneTime();
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {kSize, kSize, 1};
    for (Img& i : img) {
      barrier(cb, i.image, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 0,
              VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT);
      vkCmdCopyBufferToImage(cb, i.staging.buffer, i.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
      barrier(cb, i.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_GENERAL, VK_ACCESS_TRANSFER_WRITE_BIT,
              VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
              VK_PIPELINE_STAGE_RAY_TRACING_SHADER_BIT_KHR);
    }
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, p);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, imageLayout, 0, 1, &imageSet, 0, nullptr);
    cmdTrace(cb, &s.raygen, &s.miss, &s.hit, &s.callable, kSize, kSize, 1);
    for (Img& i : img) {
      barrier(cb, i.image, VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_ACCESS_SHADER_WRITE_BIT,
              VK_ACCESS_TRANSFER_READ_BIT, VK_PIPELINE_STAGE_RAY_TRACING_SHADER_BIT_KHR,
              VK_PIPELINE_STAGE_TRANSFER_BIT);
      vkCmdCopyImageToBuffer(cb, i.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, i.staging.buffer, 1, &region);
    }
    VkMemoryBarrier mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    mb.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    mb.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &mb, 0, nullptr, 0,
                         nullptr);
    submitAndWait(cb);

    for (uint32_t y = 0; y < kSize; ++y)
      for (uint32_t x = 0; x < kSize; ++x) {
        const size_t t = size_t(y) * kSize + x;
        const Expected e = expectedPixel(x, y);
        (e.ids[0] == 0xffffffffu ? misses : hits)++;
        encodeFloat(*r.image, e.colour, want[0].data() + t * r.image->texelSize());
        Float4 a = decodeFloat(*r.accum, want[1].data() + t * r.accum->texelSize());
        for (int k = 0; k < 4; ++k) a[k] += e.colour[k];
        encodeFloat(*r.accum, a, want[1].data() + t * r.accum->texelSize());
        encodeUint(*r.ids, e.ids, want[2].data() + t * r.ids->texelSize());
      }
    const char* names[3] = {"image", "accum", "ids"};
    for (uint32_t b = 0; b < 3; ++b) {
      const auto* got = static_cast<const uint8_t*>(img[b].staging.data);
      // 16-bit floats: a driver may round toward zero (vkrt rounds to nearest even).
      expectTexels(*formats[b], std::vector<uint8_t>(got, got + want[b].size()), want[b], names[b], !vkrt);
    }
  }
  EXPECT_GT(hits, 40);
  EXPECT_GT(misses, 40);
}

}  // namespace
}  // namespace vkrt::test
