// Depth-comparison sampling (shadow maps), end to end with the validation layer on: samplers with compareEnable and
// every compareOp, NEAREST and LINEAR, on the depth aspect of D16_UNORM, D32_SFLOAT, D24_UNORM_S8_UINT and
// D32_SFLOAT_S8_UINT images; the OpImage*Dref* instructions and the gathers in a compute shader and in a fragment
// shader drawing a full-viewport rectangle. Expected values are computed here from the spec's "Depth Compare
// Operation" (Dref clamped to [0, 1] for UNORM depth only; each texel compared, then filtered), "Texel Gathering"
// and "Projection Operation". Also VkFormatProperties3's SAMPLED_IMAGE_DEPTH_COMPARISON bit and vkCreateSampler's
// compare and unnormalized-coordinate rules.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <vector>

#include "compute_dref.comp.spv.h"
#include "e2e/compute_pipeline_helpers.hpp"
#include "e2e/subpass_fixture.hpp"
#include "gfx_dref.frag.spv.h"
#include "subpass_quad.vert.spv.h"

namespace vkrt::test {
namespace {

constexpr uint32_t kSize = 4;  // the depth image is kSize x kSize

// The depth image's contents: texel (x, y) holds ((3x + 5y) mod 9) / 8, so 0 and 1 both occur.
double depthValue(int x, int y) { return double((3 * x + 5 * y) % 9) / 8.0; }
// The fragment test's 8 x 8 shadow map: odd sixteenths.
double shadowMapValue(int x, int y) { return double((x * 5 + y * 3) % 8) / 8.0 + 1.0 / 16.0; }

struct DepthFormat {
  VkFormat format;
  VkImageAspectFlags aspects;  // of the image (barriers); views take the depth aspect only
  uint32_t bufferBytes;        // bytes a texel of the depth aspect takes in a buffer copy
  uint32_t unormBits;          // 0: SFLOAT
};

constexpr DepthFormat kFormats[] = {
    {VK_FORMAT_D16_UNORM, VK_IMAGE_ASPECT_DEPTH_BIT, 2, 16},
    {VK_FORMAT_D32_SFLOAT, VK_IMAGE_ASPECT_DEPTH_BIT, 4, 0},
    {VK_FORMAT_D24_UNORM_S8_UINT, VK_IMAGE_ASPECT_DEPTH_BIT | VK_IMAGE_ASPECT_STENCIL_BIT, 4, 24},
    {VK_FORMAT_D32_SFLOAT_S8_UINT, VK_IMAGE_ASPECT_DEPTH_BIT | VK_IMAGE_ASPECT_STENCIL_BIT, 4, 0},
};

// A stored depth as the format holds it and as sampling reads it back (UNORM: the nearest code, then code / max).
uint32_t encodeDepth(const DepthFormat& f, double d) {
  if (!f.unormBits) {
    float v = float(d);
    uint32_t u;
    std::memcpy(&u, &v, 4);
    return u;
  }
  return uint32_t(std::lround(d * double((1u << f.unormBits) - 1)));
}
float decodeDepth(const DepthFormat& f, uint32_t raw) {
  if (!f.unormBits) {
    float v;
    std::memcpy(&v, &raw, 4);
    return v;
  }
  return float(double(raw) / double((1u << f.unormBits) - 1));
}

// "reference op test", VkCompareOp's definition.
float compare(VkCompareOp op, float ref, float test) {
  switch (op) {
    case VK_COMPARE_OP_NEVER: return 0.0f;
    case VK_COMPARE_OP_LESS: return ref < test ? 1.0f : 0.0f;
    case VK_COMPARE_OP_EQUAL: return ref == test ? 1.0f : 0.0f;
    case VK_COMPARE_OP_LESS_OR_EQUAL: return ref <= test ? 1.0f : 0.0f;
    case VK_COMPARE_OP_GREATER: return ref > test ? 1.0f : 0.0f;
    case VK_COMPARE_OP_NOT_EQUAL: return ref != test ? 1.0f : 0.0f;
    case VK_COMPARE_OP_GREATER_OR_EQUAL: return ref >= test ? 1.0f : 0.0f;
    default: return 1.0f;  // ALWAYS
  }
}

struct SamplerConfig {
  VkFilter filter;
  VkCompareOp op;
  VkSamplerAddressMode mode;
  VkBorderColor border;
};

// The reference: a kSize x kSize depth image sampled at (u, v) in level 0.
struct Reference {
  const DepthFormat& f;
  SamplerConfig s;

  // Texel (i, j) after the address mode; the border's R (its depth) outside with CLAMP_TO_BORDER.
  float texel(int i, int j) const {
    const int n = int(kSize);
    if (s.mode == VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER && (i < 0 || j < 0 || i >= n || j >= n))
      return s.border == VK_BORDER_COLOR_FLOAT_OPAQUE_WHITE ? 1.0f : 0.0f;
    i = std::clamp(i, 0, n - 1);
    j = std::clamp(j, 0, n - 1);
    return decodeDepth(f, encodeDepth(f, depthValue(i, j)));
  }
  float ref(float dref) const { return f.unormBits ? std::clamp(dref, 0.0f, 1.0f) : dref; }
  float cmp(int i, int j, float dref) const { return compare(s.op, ref(dref), texel(i, j)); }
  // OpImageSampleDref*: the comparisons, then the filter.
  // (di, dj): a ConstOffset, in texels.
  double sample(float u, float v, float dref, int di = 0, int dj = 0) const {
    const double n = kSize;
    if (s.filter == VK_FILTER_NEAREST) return cmp(int(std::floor(u * n)) + di, int(std::floor(v * n)) + dj, dref);
    const double fu = u * n - 0.5, fv = v * n - 0.5;
    const int i0 = int(std::floor(fu)) + di, j0 = int(std::floor(fv)) + dj;
    const double a = fu - std::floor(fu), b = fv - std::floor(fv);
    return (1 - a) * (1 - b) * cmp(i0, j0, dref) + a * (1 - b) * cmp(i0 + 1, j0, dref) +
           (1 - a) * b * cmp(i0, j0 + 1, dref) + a * b * cmp(i0 + 1, j0 + 1, dref);
  }
  // OpImage*Gather's four texels: (i0, j1), (i1, j1), (i1, j0), (i0, j0) of the LINEAR footprint.
  std::array<int, 8> footprint(float u, float v) const {
    const int i0 = int(std::floor(u * double(kSize) - 0.5)), j0 = int(std::floor(v * double(kSize) - 0.5));
    return {i0, j0 + 1, i0 + 1, j0 + 1, i0 + 1, j0, i0, j0};
  }
};

class DepthCompareTest : public SubpassTest {
 protected:
  bool multiview() const override { return false; }

  struct DepthImage {
    Img img;
    VkImageView view = VK_NULL_HANDLE;  // the depth aspect
  };

  // A kSize x kSize image of `f` holding depthValue, in GENERAL, with a view of its depth aspect.
  DepthImage depthImage(const DepthFormat& f, uint32_t size = kSize, double (*value)(int, int) = depthValue) {
    DepthImage d;
    d.img = createImage(imageInfo(VK_IMAGE_TYPE_2D, f.format, {size, size, 1}, 1, 1,
                                  VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT));
    VkImageViewCreateInfo vi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    vi.image = d.img.image;
    vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
    vi.format = f.format;
    vi.subresourceRange = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 1, 0, 1};
    EXPECT_EQ(vkCreateImageView(device, &vi, nullptr, &d.view), VK_SUCCESS);
    HostBuffer staging = createHostBuffer(VkDeviceSize(size) * size * f.bufferBytes, kXfer);
    for (uint32_t y = 0; y < size; ++y)
      for (uint32_t x = 0; x < size; ++x) {
        const uint32_t raw = encodeDepth(f, value(int(x), int(y)));
        std::memcpy(bytes(staging) + (y * size + x) * f.bufferBytes, &raw, f.bufferBytes);
      }
    VkCommandBuffer cb = beginOneTime();
    barrier(cb, d.img.image, f.aspects, VK_IMAGE_LAYOUT_UNDEFINED);
    VkBufferImageCopy r{};
    r.imageSubresource = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 0, 1};
    r.imageExtent = {size, size, 1};
    vkCmdCopyBufferToImage(cb, staging.buffer, d.img.image, VK_IMAGE_LAYOUT_GENERAL, 1, &r);
    barrier(cb, d.img.image, f.aspects);
    submitAndWait(cb);
    destroy(staging);
    return d;
  }
  void destroy(DepthImage& d) {
    vkDestroyImageView(device, d.view, nullptr);
    destroy(d.img);
  }
  using SubpassTest::destroy;

  VkSampler sampler(const SamplerConfig& c, VkBool32 compareEnable = VK_TRUE) {
    VkSamplerCreateInfo si{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
    si.magFilter = si.minFilter = c.filter;
    si.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
    si.addressModeU = si.addressModeV = si.addressModeW = c.mode;
    si.borderColor = c.border;
    si.compareEnable = compareEnable;
    si.compareOp = c.op;
    VkSampler s = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreateSampler(device, &si, nullptr, &s), VK_SUCCESS);
    return s;
  }

  bool supportsDepthCompare(VkFormat f) {
    VkFormatProperties3 p3{VK_STRUCTURE_TYPE_FORMAT_PROPERTIES_3};
    VkFormatProperties2 p{VK_STRUCTURE_TYPE_FORMAT_PROPERTIES_2, &p3};
    vkGetPhysicalDeviceFormatProperties2(physicalDevice, f, &p);
    return (p3.optimalTilingFeatures & VK_FORMAT_FEATURE_2_SAMPLED_IMAGE_DEPTH_COMPARISON_BIT) != 0;
  }

  void writeImage(VkDescriptorSet set, uint32_t binding, VkImageView view, VkSampler s) {
    VkDescriptorImageInfo ii{s, view, VK_IMAGE_LAYOUT_GENERAL};
    VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    w.dstSet = set;
    w.dstBinding = binding;
    w.descriptorCount = 1;
    w.descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    w.pImageInfo = &ii;
    vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);
  }
  void writeBuffer(VkDescriptorSet set, uint32_t binding, const HostBuffer& b) {
    VkDescriptorBufferInfo bi{b.buffer, 0, VK_WHOLE_SIZE};
    VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    w.dstSet = set;
    w.dstBinding = binding;
    w.descriptorCount = 1;
    w.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    w.pBufferInfo = &bi;
    vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);
  }
};

// Every depth format vkrt samples reports depth comparison in VkFormatProperties3, no color format does.
TEST_F(DepthCompareTest, DepthFormatsReportDepthComparison) {
  for (const DepthFormat& f : kFormats) EXPECT_TRUE(supportsDepthCompare(f.format)) << f.format;
  EXPECT_TRUE(supportsDepthCompare(VK_FORMAT_X8_D24_UNORM_PACK32));
  if (onVkrt()) {
    for (VkFormat f : {VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_R32_SFLOAT, VK_FORMAT_R16_UNORM, VK_FORMAT_S8_UINT})
      EXPECT_FALSE(supportsDepthCompare(f)) << f;
  }
}

// textureLod, textureProjLod and textureGrad on a sampler2DShadow, textureGather with a reference and without (a
// sampler2D on the same view), textureLodOffset, at 16 points, for every format, compareOp, filter and two address
// modes.
TEST_F(DepthCompareTest, ComputeShaderComparesEachTexelBeforeFiltering) {
  const bool vkrt = onVkrt();
  ComputePipeline p =
      makeComputePipeline(device, kSpv_compute_dref_comp, sizeof kSpv_compute_dref_comp,
                          {VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
                           VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER});
  ASSERT_EQ(p.result, VK_SUCCESS);
  // (u, v, dref): texel centres, texel edges, between texels, outside the image; references between the stored
  // depths, equal to one (0, 1, 5/8: exact in every format's decoding at those texels' codes only for SFLOAT, but the
  // reference decodes the same codes), and outside [0, 1] (clamped for UNORM only).
  const float q[][4] = {
      {0.125f, 0.125f, 0.0f, 0}, {0.375f, 0.375f, 1.0f, 0}, {0.625f, 0.125f, 0.3f, 0},  {0.3f, 0.7f, 0.5f, 0},
      {0.5f, 0.5f, 0.45f, 0},    {0.1f, 0.9f, 0.625f, 0},   {-0.2f, 0.4f, 0.6f, 0},     {1.1f, 1.3f, 0.99f, 0},
      {0.875f, 0.6f, 1.5f, 0},   {0.6f, 0.875f, -0.5f, 0},  {0.375f, 0.375f, 1.25f, 0}, {0.125f, 0.125f, -0.25f, 0},
      {0.77f, 0.31f, 0.2f, 0},   {0.45f, -0.05f, 0.75f, 0}, {0.99f, 0.01f, 0.4f, 0},    {0.25f, 0.75f, 0.55f, 0},
  };
  const uint32_t n = sizeof q / sizeof q[0];
  HostBuffer in = createHostBuffer(sizeof q, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  std::memcpy(in.data, q, sizeof q);
  HostBuffer out = createHostBuffer(n * 3 * 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  writeBuffer(p.set, 2, in);
  writeBuffer(p.set, 3, out);
  // vkrt filters in float; a GPU quantizes its weights (and may filter comparisons its own way: the spec only asks
  // for a weighted average "in an implementation-dependent manner").
  const double tol = vkrt ? 1e-5 : 0.02;
  for (const DepthFormat& f : kFormats) {
    if (!supportsDepthCompare(f.format)) continue;
    DepthImage img = depthImage(f);
    for (VkFilter filter : {VK_FILTER_NEAREST, VK_FILTER_LINEAR})
      for (int op = VK_COMPARE_OP_NEVER; op <= VK_COMPARE_OP_ALWAYS; ++op) {
        const bool border = op % 2 == 1;
        const SamplerConfig c{filter, VkCompareOp(op),
                              border ? VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER : VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE,
                              op % 4 == 1 ? VK_BORDER_COLOR_FLOAT_OPAQUE_WHITE : VK_BORDER_COLOR_FLOAT_OPAQUE_BLACK};
        SCOPED_TRACE(testing::Message() << "format " << f.format << " filter " << filter << " op " << op);
        VkSampler shadow = sampler(c);
        VkSampler plain = sampler({VK_FILTER_NEAREST, VK_COMPARE_OP_NEVER, c.mode, c.border}, VK_FALSE);
        writeImage(p.set, 0, img.view, shadow);
        writeImage(p.set, 1, img.view, plain);
        std::memset(out.data, 0x7F, out.size);
        VkCommandBuffer cb = beginOneTime();
        vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
        vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout, 0, 1, &p.set, 0, nullptr);
        vkCmdDispatch(cb, n / 4, 1, 1);
        VkMemoryBarrier mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
        mb.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
        mb.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
        vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &mb, 0,
                             nullptr, 0, nullptr);
        submitAndWait(cb);
        const Reference ref{f, c};
        const float* r = static_cast<const float*>(out.data);
        for (uint32_t i = 0; i < n; ++i) {
          const float u = q[i][0], v = q[i][1], dref = q[i][2];
          SCOPED_TRACE(testing::Message() << "point " << i << " (" << u << ", " << v << ", " << dref << ")");
          const double want = ref.sample(u, v, dref);
          EXPECT_NEAR(r[12 * i + 0], want, tol) << "textureLod";
          EXPECT_NEAR(r[12 * i + 1], want, tol) << "textureProjLod";
          EXPECT_NEAR(r[12 * i + 2], want, tol) << "textureGrad";
          EXPECT_NEAR(r[12 * i + 3], ref.sample(u, v, dref, 1, -1), tol) << "textureLodOffset";
          const std::array<int, 8> fp = ref.footprint(u, v);
          for (int k = 0; k < 4; ++k) {
            EXPECT_EQ(r[12 * i + 4 + k], ref.cmp(fp[2 * k], fp[2 * k + 1], dref)) << "textureGather ref, texel " << k;
            // The plain sampler reads the same texels' depths (NEAREST or not: gathers take the LINEAR footprint).
            const Reference plainRef{f, {VK_FILTER_NEAREST, VK_COMPARE_OP_NEVER, c.mode, c.border}};
            EXPECT_EQ(r[12 * i + 8 + k], plainRef.texel(fp[2 * k], fp[2 * k + 1])) << "textureGather, texel " << k;
          }
        }
        vkDestroySampler(device, shadow, nullptr);
        vkDestroySampler(device, plain, nullptr);
      }
    destroy(img);
  }
  destroyComputePipeline(device, p);
  destroy(in);
  destroy(out);
}

// An 8 x 8 shadow map sampled by a fragment shader over a 32 x 32 target (each texel covers 4 x 4 pixels): texture
// and textureProj (implicit LOD from the quad's derivatives: magnification), textureGather with a reference and
// textureOffset, for D16_UNORM and D32_SFLOAT, LINEAR with LESS (the common shadow test) and NEAREST with
// GREATER_OR_EQUAL.
TEST_F(DepthCompareTest, FragmentShaderSamplesAShadowMap) {
  constexpr uint32_t kMap = 8;
  VkDescriptorSetLayoutBinding b{0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, VK_SHADER_STAGE_FRAGMENT_BIT,
                                 nullptr};
  VkDescriptorSetLayoutCreateInfo dl{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  dl.bindingCount = 1;
  dl.pBindings = &b;
  VkDescriptorSetLayout setLayout;
  ASSERT_EQ(vkCreateDescriptorSetLayout(device, &dl, nullptr, &setLayout), VK_SUCCESS);
  VkDescriptorPoolSize ps{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1};
  VkDescriptorPoolCreateInfo dp{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  dp.maxSets = 1;
  dp.poolSizeCount = 1;
  dp.pPoolSizes = &ps;
  VkDescriptorPool pool;
  ASSERT_EQ(vkCreateDescriptorPool(device, &dp, nullptr, &pool), VK_SUCCESS);
  VkDescriptorSetAllocateInfo da{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  da.descriptorPool = pool;
  da.descriptorSetCount = 1;
  da.pSetLayouts = &setLayout;
  VkDescriptorSet set;
  ASSERT_EQ(vkAllocateDescriptorSets(device, &da, &set), VK_SUCCESS);
  PipelineDesc d;
  d.vs = kSpv_subpass_quad_vert, d.vsBytes = sizeof kSpv_subpass_quad_vert;
  d.fs = kSpv_gfx_dref_frag, d.fsBytes = sizeof kSpv_gfx_dref_frag;
  d.layout = pipelineLayout(setLayout);
  VkPipeline pipe;
  ASSERT_EQ(pipeline(d, &pipe), VK_SUCCESS);
  Attachment color = attachment(kFormat, kW, kH);
  for (const DepthFormat& f : {kFormats[0], kFormats[1]}) {
    if (!supportsDepthCompare(f.format)) continue;
    DepthImage img = depthImage(f, kMap, shadowMapValue);
    for (const SamplerConfig& c :
         {SamplerConfig{VK_FILTER_LINEAR, VK_COMPARE_OP_LESS, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE,
                        VK_BORDER_COLOR_FLOAT_OPAQUE_WHITE},
          SamplerConfig{VK_FILTER_NEAREST, VK_COMPARE_OP_GREATER_OR_EQUAL, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER,
                        VK_BORDER_COLOR_FLOAT_OPAQUE_WHITE}}) {
      SCOPED_TRACE(testing::Message() << "format " << f.format << " filter " << c.filter << " op " << c.op);
      VkSampler s = sampler(c);
      writeImage(set, 0, img.view, s);
      VkCommandBuffer cb = beginOneTime();
      VkRenderingAttachmentInfo ca{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
      ca.imageView = color.view;
      ca.imageLayout = VK_IMAGE_LAYOUT_GENERAL;
      ca.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
      ca.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
      VkRenderingInfo ri{VK_STRUCTURE_TYPE_RENDERING_INFO};
      ri.renderArea = {{0, 0}, {kW, kH}};
      ri.layerCount = 1;
      ri.colorAttachmentCount = 1;
      ri.pColorAttachments = &ca;
      vkCmdBeginRendering(cb, &ri);
      vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, pipe);
      vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, d.layout, 0, 1, &set, 0, nullptr);
      vkCmdDraw(cb, 6, 1, 0, 0);
      vkCmdEndRendering(cb);
      submitAndWait(cb);
      std::vector<uint8_t> px = readBack(color, VK_IMAGE_ASPECT_COLOR_BIT, 4);
      // The map's texel (i, j) through the address mode, compared; the filters over kMap texels.
      auto texel = [&](int i, int j) -> float {
        const int m = int(kMap);
        if (c.mode == VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER && (i < 0 || j < 0 || i >= m || j >= m)) return 1.0f;
        return decodeDepth(f, encodeDepth(f, shadowMapValue(std::clamp(i, 0, m - 1), std::clamp(j, 0, m - 1))));
      };
      int bad = 0;
      for (uint32_t y = 0; y < kH; ++y)
        for (uint32_t x = 0; x < kW; ++x) {
          const float u = float((x + 0.5) / 32.0), v = float((y + 0.5) / 32.0);
          const float dref = float(std::fmod(((x + 0.5) * 3 + (y + 0.5) * 5) / 256.0, 1.0));
          const float refc = f.unormBits ? std::clamp(dref, 0.0f, 1.0f) : dref;
          auto cmp = [&](int i, int j) { return double(compare(c.op, refc, texel(i, j))); };
          const double fu = u * double(kMap) - 0.5, fv = v * double(kMap) - 0.5;
          const int i0 = int(std::floor(fu)), j0 = int(std::floor(fv));
          const double a = fu - std::floor(fu), bb = fv - std::floor(fv);
          // (di, dj): textureOffset's ConstOffset.
          auto filter = [&](int di, int dj) {
            if (c.filter == VK_FILTER_NEAREST)
              return cmp(int(std::floor(u * double(kMap))) + di, int(std::floor(v * double(kMap))) + dj);
            return (1 - a) * (1 - bb) * cmp(i0 + di, j0 + dj) + a * (1 - bb) * cmp(i0 + 1 + di, j0 + dj) +
                   (1 - a) * bb * cmp(i0 + di, j0 + 1 + dj) + a * bb * cmp(i0 + 1 + di, j0 + 1 + dj);
          };
          const double filtered = filter(0, 0);
          const double gathered =
              (cmp(i0, j0 + 1) + 2 * cmp(i0 + 1, j0 + 1) + 4 * cmp(i0 + 1, j0) + 8 * cmp(i0, j0)) / 15.0;
          const uint32_t want = rgba8(filtered, filtered, gathered, filter(-1, 1));
          const uint32_t got = texelU32(px, y * kW + x);
          if (!near(got, want) && bad++ < 4)
            ADD_FAILURE() << "pixel (" << x << ", " << y << "): 0x" << std::hex << got << ", expected 0x" << want;
        }
      EXPECT_EQ(bad, 0);
      vkDestroySampler(device, s, nullptr);
    }
    destroy(img);
  }
  destroy(color);
  vkDestroyDescriptorPool(device, pool, nullptr);
  vkDestroyDescriptorSetLayout(device, setLayout, nullptr);
}

class DepthCompareMisuseTest : public DepthCompareTest {
 protected:
  bool validation() const override { return false; }
};

// VUID-VkSamplerCreateInfo-compareEnable-01080 and the unnormalized-coordinate rules (01072-01075, 01077), each
// broken alone next to its valid neighbour.
TEST_F(DepthCompareMisuseTest, SamplerCompareAndUnnormalizedRulesAreReported) {
  VkSamplerCreateInfo si{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
  VkSampler s = VK_NULL_HANDLE;
  si.compareEnable = VK_TRUE;
  si.compareOp = VkCompareOp(8);
  EXPECT_EQ(vkCreateSampler(device, &si, nullptr, &s), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkSamplerCreateInfo-compareEnable-01080");
  si.compareEnable = VK_FALSE;  // compareOp is ignored without compareEnable
  ASSERT_EQ(vkCreateSampler(device, &si, nullptr, &s), VK_SUCCESS);
  EXPECT_TRUE(vkrtMessages().empty());
  vkDestroySampler(device, s, nullptr);
  si.compareEnable = VK_TRUE;
  si.compareOp = VK_COMPARE_OP_ALWAYS;
  ASSERT_EQ(vkCreateSampler(device, &si, nullptr, &s), VK_SUCCESS);
  EXPECT_TRUE(vkrtMessages().empty());
  vkDestroySampler(device, s, nullptr);

  // Unnormalized coordinates: the valid base, then one rule broken at a time.
  VkSamplerCreateInfo base{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
  base.unnormalizedCoordinates = VK_TRUE;
  base.addressModeU = base.addressModeV = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
  ASSERT_EQ(vkCreateSampler(device, &base, nullptr, &s), VK_SUCCESS);
  EXPECT_TRUE(vkrtMessages().empty());
  vkDestroySampler(device, s, nullptr);
  struct Case {
    void (*breakIt)(VkSamplerCreateInfo&);
    const char* vuid;
  } cases[] = {
      {[](VkSamplerCreateInfo& c) { c.magFilter = VK_FILTER_LINEAR; },
       "VUID-VkSamplerCreateInfo-unnormalizedCoordinates-01072"},
      {[](VkSamplerCreateInfo& c) { c.mipmapMode = VK_SAMPLER_MIPMAP_MODE_LINEAR; },
       "VUID-VkSamplerCreateInfo-unnormalizedCoordinates-01073"},
      {[](VkSamplerCreateInfo& c) { c.maxLod = 1.0f; }, "VUID-VkSamplerCreateInfo-unnormalizedCoordinates-01074"},
      {[](VkSamplerCreateInfo& c) { c.addressModeV = VK_SAMPLER_ADDRESS_MODE_REPEAT; },
       "VUID-VkSamplerCreateInfo-unnormalizedCoordinates-01075"},
      {[](VkSamplerCreateInfo& c) { c.compareEnable = VK_TRUE; },
       "VUID-VkSamplerCreateInfo-unnormalizedCoordinates-01077"},
  };
  for (const Case& k : cases) {
    SCOPED_TRACE(k.vuid);
    VkSamplerCreateInfo ci = base;
    k.breakIt(ci);
    EXPECT_EQ(vkCreateSampler(device, &ci, nullptr, &s), VK_ERROR_VALIDATION_FAILED_EXT);
    expectVkrtMessage(k.vuid);
  }
}

}  // namespace
}  // namespace vkrt::test
