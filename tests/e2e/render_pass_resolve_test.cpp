// Multisample resolves and dynamic rendering through the loader and the validation layer: 4-sample images whose
// samples are written through mapped memory (vkrt's layout: a pixel's samples consecutive, runtime/image.hpp; so
// these run on vkrt only), resolved by vkCmdResolveImage, by a subpass's resolve attachment, by
// vkCmdBeginRendering's resolve modes (color average, depth SAMPLE_ZERO/AVERAGE/MIN/MAX, stencil MIN/MAX), and
// dynamic rendering's load-op clears over layers, suspend/resume. Expected values are computed here.
#include <cstring>

#include "e2e/render_pass_fixture.hpp"

namespace vkrt::test {
namespace {

class ResolveTest : public RenderPassTest {
 protected:
  // Writes sample s of pixel i (row-major) of a 4-sample attachment: texelBytes bytes from `texel(i, s, out)`.
  template <class F>
  void writeSamples(const Attachment& a, uint32_t texelBytes, F texel) {
    void* p = nullptr;
    ASSERT_EQ(vkMapMemory(device, a.img.memory, 0, VK_WHOLE_SIZE, 0, &p), VK_SUCCESS);
    for (uint32_t i = 0; i < a.width * a.height; ++i)
      for (uint32_t s = 0; s < 4; ++s) texel(i, s, static_cast<uint8_t*>(p) + (i * 4 + s) * texelBytes);
    vkUnmapMemory(device, a.img.memory);
  }

  // The RGBA8 samples: R {0, 60, 120, 200} (mean 95), G {i, i+4, i+8, i+12} (mean i+6), B 255, A {0, 0, 0, 4}
  // (mean 1): every mean is a whole number, so the resolved UNORM value is exact.
  static void rgbaSample(uint32_t i, uint32_t s, uint8_t* t) {
    static const uint8_t r[4] = {0, 60, 120, 200};
    t[0] = r[s];
    t[1] = uint8_t(i + 4 * s);
    t[2] = 255;
    t[3] = s == 3 ? 4 : 0;
  }
  static uint32_t rgbaMean(uint32_t i) { return 95u | (i + 6) << 8 | 255u << 16 | 1u << 24; }
};

TEST_F(ResolveTest, CmdResolveImageAveragesNormalizedAndTakesSampleZeroOfIntegers) {
  if (!onVkrt()) GTEST_SKIP() << "writes samples through vkrt's memory layout";
  Attachment ms = attachment(VK_FORMAT_R8G8B8A8_UNORM, 4, 2, 1, VK_SAMPLE_COUNT_4_BIT, kImgXfer);
  Attachment one = attachment(VK_FORMAT_R8G8B8A8_UNORM, 4, 2);
  Attachment msi = attachment(VK_FORMAT_R32_UINT, 4, 2, 1, VK_SAMPLE_COUNT_4_BIT, kImgXfer);
  Attachment onei = attachment(VK_FORMAT_R32_UINT, 4, 2);
  writeSamples(ms, 4, rgbaSample);
  writeSamples(msi, 4, [](uint32_t i, uint32_t s, uint8_t* t) {
    const uint32_t v = 1000 * i + s + 7;
    std::memcpy(t, &v, 4);
  });
  VkCommandBuffer cb = beginOneTime();
  VkImageResolve r{{VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1}, {}, {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1}, {}, {4, 2, 1}};
  vkCmdResolveImage(cb, ms.img.image, VK_IMAGE_LAYOUT_GENERAL, one.img.image, VK_IMAGE_LAYOUT_GENERAL, 1, &r);
  VkImageResolve2 r2{VK_STRUCTURE_TYPE_IMAGE_RESOLVE_2, nullptr, r.srcSubresource, {}, r.dstSubresource, {}, {4, 2, 1}};
  VkResolveImageInfo2 info{VK_STRUCTURE_TYPE_RESOLVE_IMAGE_INFO_2,
                           nullptr,
                           msi.img.image,
                           VK_IMAGE_LAYOUT_GENERAL,
                           onei.img.image,
                           VK_IMAGE_LAYOUT_GENERAL,
                           1,
                           &r2};
  vkCmdResolveImage2(cb, &info);
  submitAndWait(cb);
  std::vector<uint8_t> p = readBack(one, VK_IMAGE_ASPECT_COLOR_BIT, 4),
                       q = readBack(onei, VK_IMAGE_ASPECT_COLOR_BIT, 4);
  for (uint32_t i = 0; i < 8; ++i) {
    EXPECT_EQ(texelU32(p, i), rgbaMean(i)) << i;
    EXPECT_EQ(texelU32(q, i), 1000 * i + 7) << i;  // sample 0 (the spec lets a driver pick one sample)
  }
  destroy(ms);
  destroy(one);
  destroy(msi);
  destroy(onei);
}

TEST_F(ResolveTest, SubpassResolveAttachmentOverTheRenderArea) {
  if (!onVkrt()) GTEST_SKIP() << "writes samples through vkrt's memory layout";
  Attachment ms = attachment(VK_FORMAT_R8G8B8A8_UNORM, 4, 2, 1, VK_SAMPLE_COUNT_4_BIT);
  Attachment one = attachment(VK_FORMAT_R8G8B8A8_UNORM, 4, 2);
  writeSamples(ms, 4, rgbaSample);
  VkClearColorValue black{};
  clearColor(one, black);
  VkAttachmentReference cr{0, VK_IMAGE_LAYOUT_GENERAL}, rr{1, VK_IMAGE_LAYOUT_GENERAL};
  VkSubpassDescription sub{};
  sub.colorAttachmentCount = 1;
  sub.pColorAttachments = &cr;
  sub.pResolveAttachments = &rr;
  VkRenderPass rp = renderPass({desc(ms.format, VK_ATTACHMENT_LOAD_OP_LOAD, VK_SAMPLE_COUNT_4_BIT),
                                desc(one.format, VK_ATTACHMENT_LOAD_OP_DONT_CARE)},
                               {sub});
  VkFramebuffer fb = framebuffer(rp, {ms.view, one.view}, 4, 2);
  const VkRect2D area{{1, 0}, {2, 2}};
  VkRenderPassBeginInfo bi = beginInfo(rp, fb, area, {});
  VkCommandBuffer cb = beginOneTime();
  vkCmdBeginRenderPass(cb, &bi, VK_SUBPASS_CONTENTS_INLINE);
  vkCmdEndRenderPass(cb);
  submitAndWait(cb);
  std::vector<uint8_t> p = readBack(one, VK_IMAGE_ASPECT_COLOR_BIT, 4);
  for (uint32_t i = 0; i < 8; ++i) EXPECT_EQ(texelU32(p, i), inside(area, i % 4, i / 4) ? rgbaMean(i) : 0u) << i;
  vkDestroyFramebuffer(device, fb, nullptr);
  vkDestroyRenderPass(device, rp, nullptr);
  destroy(ms);
  destroy(one);
}

// vkCmdBeginRendering's depth and stencil resolve modes on D32_SFLOAT_S8_UINT: depth samples {0.5, 0.25, 0.75, 1},
// stencil samples {7, 3, 9, 5}.
TEST_F(ResolveTest, DynamicRenderingDepthStencilResolveModes) {
  if (!onVkrt()) GTEST_SKIP() << "writes samples through vkrt's memory layout";
  const VkFormat f = VK_FORMAT_D32_SFLOAT_S8_UINT;
  Attachment ms = attachment(f, 2, 2, 1, VK_SAMPLE_COUNT_4_BIT);
  writeSamples(ms, 8, [](uint32_t, uint32_t s, uint8_t* t) {
    static const float z[4] = {0.5f, 0.25f, 0.75f, 1.0f};
    static const uint8_t st[4] = {7, 3, 9, 5};
    std::memcpy(t, &z[s], 4);
    t[4] = st[s];
  });
  struct Case {
    VkResolveModeFlagBits depth, stencil;
    float z;
    uint8_t s;
  };
  const Case cases[] = {{VK_RESOLVE_MODE_SAMPLE_ZERO_BIT, VK_RESOLVE_MODE_SAMPLE_ZERO_BIT, 0.5f, 7},
                        {VK_RESOLVE_MODE_AVERAGE_BIT, VK_RESOLVE_MODE_MIN_BIT, 0.625f, 3},
                        {VK_RESOLVE_MODE_MIN_BIT, VK_RESOLVE_MODE_MAX_BIT, 0.25f, 9},
                        {VK_RESOLVE_MODE_MAX_BIT, VK_RESOLVE_MODE_SAMPLE_ZERO_BIT, 1.0f, 7}};
  for (const Case& c : cases) {
    Attachment one = attachment(f, 2, 2);
    VkRenderingAttachmentInfo d{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
    d.imageView = ms.view;
    d.imageLayout = VK_IMAGE_LAYOUT_GENERAL;
    d.resolveMode = c.depth;
    d.resolveImageView = one.view;
    d.resolveImageLayout = VK_IMAGE_LAYOUT_GENERAL;
    d.loadOp = VK_ATTACHMENT_LOAD_OP_LOAD;
    d.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    VkRenderingAttachmentInfo s = d;
    s.resolveMode = c.stencil;
    VkRenderingInfo ri{VK_STRUCTURE_TYPE_RENDERING_INFO};
    ri.renderArea = {{0, 0}, {2, 2}};
    ri.layerCount = 1;
    ri.pDepthAttachment = &d;
    ri.pStencilAttachment = &s;
    VkCommandBuffer cb = beginOneTime();
    vkCmdBeginRendering(cb, &ri);
    vkCmdEndRendering(cb);
    submitAndWait(cb);
    std::vector<uint8_t> z = readBack(one, VK_IMAGE_ASPECT_DEPTH_BIT, 4),
                         st = readBack(one, VK_IMAGE_ASPECT_STENCIL_BIT, 1);
    for (uint32_t i = 0; i < 4; ++i) {
      float v;
      std::memcpy(&v, z.data() + 4 * i, 4);
      EXPECT_EQ(v, c.z) << c.depth;
      EXPECT_EQ(st[i], c.s) << c.stencil;
    }
    destroy(one);
  }
  destroy(ms);
}

// vkCmdBeginRendering: a color clear over the render area of 2 layers, a color resolve, and a suspended instance
// resumed in the same command buffer (the resumed part's CLEAR does not run again).
TEST_F(ResolveTest, DynamicRenderingClearsLayersAndSuspendResume) {
  Attachment a = attachment(VK_FORMAT_R8G8B8A8_UNORM, 4, 4, 2);
  VkClearColorValue blue{{0, 0, 1, 1}};
  clearColor(a, blue);
  VkRenderingAttachmentInfo c{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
  c.imageView = a.view;
  c.imageLayout = VK_IMAGE_LAYOUT_GENERAL;
  c.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
  c.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  c.clearValue.color = {{1, 0, 0, 1}};
  VkRenderingInfo ri{VK_STRUCTURE_TYPE_RENDERING_INFO};
  ri.flags = VK_RENDERING_SUSPENDING_BIT;
  ri.renderArea = {{1, 1}, {2, 3}};
  ri.layerCount = 2;
  ri.colorAttachmentCount = 1;
  ri.pColorAttachments = &c;
  VkCommandBuffer cb = beginOneTime();
  vkCmdBeginRendering(cb, &ri);
  vkCmdEndRendering(cb);
  VkRenderingAttachmentInfo c2 = c;
  c2.clearValue.color = {{0, 1, 0, 1}};
  VkRenderingInfo ri2 = ri;
  ri2.flags = VK_RENDERING_RESUMING_BIT;
  ri2.pColorAttachments = &c2;
  vkCmdBeginRendering(cb, &ri2);
  vkCmdEndRendering(cb);
  submitAndWait(cb);
  for (uint32_t l = 0; l < 2; ++l) {
    std::vector<uint8_t> p = readBack(a, VK_IMAGE_ASPECT_COLOR_BIT, 4, l);
    for (uint32_t i = 0; i < 16; ++i)
      EXPECT_EQ(texelU32(p, i), inside(ri.renderArea, i % 4, i / 4) ? 0xFF0000FFu : 0xFFFF0000u) << l << ":" << i;
  }
  destroy(a);
}

TEST_F(ResolveTest, DynamicRenderingColorResolve) {
  if (!onVkrt()) GTEST_SKIP() << "writes samples through vkrt's memory layout";
  Attachment ms = attachment(VK_FORMAT_R8G8B8A8_UNORM, 4, 2, 1, VK_SAMPLE_COUNT_4_BIT);
  Attachment one = attachment(VK_FORMAT_R8G8B8A8_UNORM, 4, 2);
  writeSamples(ms, 4, rgbaSample);
  VkRenderingAttachmentInfo c{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
  c.imageView = ms.view;
  c.imageLayout = VK_IMAGE_LAYOUT_GENERAL;
  c.resolveMode = VK_RESOLVE_MODE_AVERAGE_BIT;
  c.resolveImageView = one.view;
  c.resolveImageLayout = VK_IMAGE_LAYOUT_GENERAL;
  c.loadOp = VK_ATTACHMENT_LOAD_OP_LOAD;
  c.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  VkRenderingInfo ri{VK_STRUCTURE_TYPE_RENDERING_INFO};
  ri.renderArea = {{0, 0}, {4, 2}};
  ri.layerCount = 1;
  ri.colorAttachmentCount = 1;
  ri.pColorAttachments = &c;
  VkCommandBuffer cb = beginOneTime();
  vkCmdBeginRendering(cb, &ri);
  vkCmdEndRendering(cb);
  submitAndWait(cb);
  std::vector<uint8_t> p = readBack(one, VK_IMAGE_ASPECT_COLOR_BIT, 4);
  for (uint32_t i = 0; i < 8; ++i) EXPECT_EQ(texelU32(p, i), rgbaMean(i)) << i;
  destroy(ms);
  destroy(one);
}

// A secondary command buffer inheriting dynamic rendering formats (VkCommandBufferInheritanceRenderingInfo), executed
// in an instance begun with VK_RENDERING_CONTENTS_SECONDARY_COMMAND_BUFFERS_BIT: its vkCmdClearAttachments clears
// the primary's attachment.
TEST_F(ResolveTest, DynamicRenderingSecondaryClearsTheInstance) {
  Attachment a = attachment(VK_FORMAT_R8G8B8A8_UNORM, 4, 4);
  VkCommandBufferAllocateInfo cai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO, nullptr, commandPool,
                                  VK_COMMAND_BUFFER_LEVEL_SECONDARY, 1};
  VkCommandBuffer sec = VK_NULL_HANDLE;
  ASSERT_EQ(vkAllocateCommandBuffers(device, &cai, &sec), VK_SUCCESS);
  VkCommandBufferInheritanceRenderingInfo ir{VK_STRUCTURE_TYPE_COMMAND_BUFFER_INHERITANCE_RENDERING_INFO};
  ir.colorAttachmentCount = 1;
  ir.pColorAttachmentFormats = &a.format;
  ir.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
  VkCommandBufferInheritanceInfo inh{VK_STRUCTURE_TYPE_COMMAND_BUFFER_INHERITANCE_INFO, &ir};
  VkCommandBufferBeginInfo sbi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO, nullptr,
                               VK_COMMAND_BUFFER_USAGE_RENDER_PASS_CONTINUE_BIT, &inh};
  ASSERT_EQ(vkBeginCommandBuffer(sec, &sbi), VK_SUCCESS);
  VkClearAttachment clear{VK_IMAGE_ASPECT_COLOR_BIT, 0, {}};
  clear.clearValue.color = {{0, 1, 0, 1}};
  VkClearRect rect{{{1, 1}, {2, 2}}, 0, 1};
  vkCmdClearAttachments(sec, 1, &clear, 1, &rect);
  ASSERT_EQ(vkEndCommandBuffer(sec), VK_SUCCESS);
  VkRenderingAttachmentInfo c{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
  c.imageView = a.view;
  c.imageLayout = VK_IMAGE_LAYOUT_GENERAL;
  c.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
  c.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  c.clearValue.color = {{1, 0, 0, 1}};
  VkRenderingInfo ri{VK_STRUCTURE_TYPE_RENDERING_INFO};
  ri.flags = VK_RENDERING_CONTENTS_SECONDARY_COMMAND_BUFFERS_BIT;
  ri.renderArea = {{0, 0}, {4, 4}};
  ri.layerCount = 1;
  ri.colorAttachmentCount = 1;
  ri.pColorAttachments = &c;
  VkCommandBuffer cb = beginOneTime();
  vkCmdBeginRendering(cb, &ri);
  vkCmdExecuteCommands(cb, 1, &sec);
  vkCmdEndRendering(cb);
  submitAndWait(cb);
  std::vector<uint8_t> p = readBack(a, VK_IMAGE_ASPECT_COLOR_BIT, 4);
  for (uint32_t i = 0; i < 16; ++i)
    EXPECT_EQ(texelU32(p, i), inside(rect.rect, i % 4, i / 4) ? 0xFF00FF00u : 0xFF0000FFu) << i;
  vkFreeCommandBuffers(device, commandPool, 1, &sec);
  destroy(a);
}

}  // namespace
}  // namespace vkrt::test
