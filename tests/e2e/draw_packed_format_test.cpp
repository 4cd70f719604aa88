// Rendering into the packed 16-bit colour formats the spec requires as blended attachments (R5G6B5_UNORM_PACK16 and
// A1R5G5B5_UNORM_PACK16, "Mandatory Format Support: Sub-Byte Components"): a render pass clears the attachment, a
// full-screen triangle blends over it (SRC_ALPHA, ONE_MINUS_SRC_ALPHA), and the stored words are compared with the
// clear and blend equations computed here from the fields' bit positions in formats.adoc.
#include <cmath>
#include <cstring>

#include "e2e/draw_fixture.hpp"

namespace vkrt::test {
namespace {

using DrawPackedFormatTest = DrawTest;

struct Field {
  int shift, bits;  // bits 0: the format has no such component
};
struct Packed {
  VkFormat format;
  Field rgba[4];
};

// The nearest field value to `v` in [0, 1], or either neighbour at a tie (float arithmetic within 1e-3 of x.5).
bool nearField(int got, double v, int bits) { return std::fabs(got - v * double((1 << bits) - 1)) <= 0.5 + 1e-3; }

TEST_F(DrawPackedFormatTest, ClearAndBlendIntoSixteenBitAttachments) {
  const Packed formats[] = {
      {VK_FORMAT_R5G6B5_UNORM_PACK16, {{11, 5}, {5, 6}, {0, 5}, {0, 0}}},
      {VK_FORMAT_A1R5G5B5_UNORM_PACK16, {{10, 5}, {5, 5}, {0, 5}, {15, 1}}},
  };
  const float clear[4] = {0.2f, 0.7f, 0.45f, 0.0f}, src[4] = {0.9f, 0.1f, 0.6f, 0.25f};
  for (const Packed& p : formats) {
    SCOPED_TRACE(p.format);
    Target color = createTarget(p.format, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                                VK_IMAGE_ASPECT_COLOR_BIT);
    VkAttachmentDescription a{0,
                              p.format,
                              VK_SAMPLE_COUNT_1_BIT,
                              VK_ATTACHMENT_LOAD_OP_CLEAR,
                              VK_ATTACHMENT_STORE_OP_STORE,
                              VK_ATTACHMENT_LOAD_OP_DONT_CARE,
                              VK_ATTACHMENT_STORE_OP_DONT_CARE,
                              VK_IMAGE_LAYOUT_UNDEFINED,
                              VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL};
    VkAttachmentReference ref{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
    VkSubpassDescription sub{};
    sub.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
    sub.colorAttachmentCount = 1;
    sub.pColorAttachments = &ref;
    VkSubpassDependency dep{0,
                            VK_SUBPASS_EXTERNAL,
                            VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
                            VK_PIPELINE_STAGE_TRANSFER_BIT,
                            VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
                            VK_ACCESS_TRANSFER_READ_BIT,
                            0};
    VkRenderPassCreateInfo rci{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
    rci.attachmentCount = 1;
    rci.pAttachments = &a;
    rci.subpassCount = 1;
    rci.pSubpasses = &sub;
    rci.dependencyCount = 1;
    rci.pDependencies = &dep;
    VkRenderPass rp = VK_NULL_HANDLE;
    ASSERT_EQ(vkCreateRenderPass(device, &rci, nullptr, &rp), VK_SUCCESS);
    VkFramebufferCreateInfo fci{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
    fci.renderPass = rp;
    fci.attachmentCount = 1;
    fci.pAttachments = &color.view;
    fci.width = kW;
    fci.height = kH;
    fci.layers = 1;
    VkFramebuffer fb = VK_NULL_HANDLE;
    ASSERT_EQ(vkCreateFramebuffer(device, &fci, nullptr, &fb), VK_SUCCESS);
    PipelineDesc d = colorPipeline();
    d.blend = {VK_TRUE,
               VK_BLEND_FACTOR_SRC_ALPHA,
               VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA,
               VK_BLEND_OP_ADD,
               VK_BLEND_FACTOR_SRC_ALPHA,
               VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA,
               VK_BLEND_OP_ADD,
               0xF};
    d.renderPass = rp;
    VkPipeline pipeline = VK_NULL_HANDLE;
    ASSERT_EQ(createPipeline(d, &pipeline), VK_SUCCESS);
    // Two triangles over the top half (rows 0..15: NDC y < 0); the bottom half keeps the clear.
    const Vertex v[6] = {{-1, -1, src[0], src[1], src[2], src[3]}, {1, -1, src[0], src[1], src[2], src[3]},
                         {1, 0, src[0], src[1], src[2], src[3]},   {-1, -1, src[0], src[1], src[2], src[3]},
                         {1, 0, src[0], src[1], src[2], src[3]},   {-1, 0, src[0], src[1], src[2], src[3]}};
    HostBuffer vb = vertexBuffer(v, sizeof v);
    HostBuffer out = createHostBuffer(kW * kH * 2, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    VkCommandBuffer cb = beginOneTime();
    VkClearValue cv{};
    std::memcpy(cv.color.float32, clear, sizeof clear);
    VkRenderPassBeginInfo bi{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
    bi.renderPass = rp;
    bi.framebuffer = fb;
    bi.renderArea = {{0, 0}, {kW, kH}};
    bi.clearValueCount = 1;
    bi.pClearValues = &cv;
    vkCmdBeginRenderPass(cb, &bi, VK_SUBPASS_CONTENTS_INLINE);
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
    const VkDeviceSize offset = 0;
    vkCmdBindVertexBuffers(cb, 0, 1, &vb.buffer, &offset);
    vkCmdDraw(cb, 6, 1, 0, 0);
    vkCmdEndRenderPass(cb);
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {kW, kH, 1};
    vkCmdCopyImageToBuffer(cb, color.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, out.buffer, 1, &region);
    VkMemoryBarrier hb{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    hb.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    hb.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &hb, 0, nullptr, 0,
                         nullptr);
    submitAndWait(cb);
    // The clear, stored: each field the nearest step to the clear value (alpha: the clear's, 0). The blend reads
    // the stored clear back (decoded as field / (2^bits - 1)) and stores src * a + dst * (1 - a) (alpha likewise).
    int bad = 0;
    for (uint32_t y = 0; y < kH; ++y)
      for (uint32_t x = 0; x < kW; ++x) {
        uint16_t w;
        std::memcpy(&w, static_cast<const uint8_t*>(out.data) + 2 * (y * kW + x), 2);
        for (int c = 0; c < 4; ++c) {
          const Field f = p.rgba[c];
          if (!f.bits) continue;
          const int max = (1 << f.bits) - 1;
          const int stored = int(std::lround(double(clear[c]) * max));  // no clear value here is a tie
          double want = double(stored) / max;
          if (y < kH / 2) want = double(src[c]) * src[3] + want * (1.0 - src[3]);
          const int got = (w >> f.shift) & max;
          if (!nearField(got, want, f.bits) && bad++ < 8)
            ADD_FAILURE() << "(" << x << ", " << y << ") component " << c << ": got " << got << ", want " << want * max;
        }
      }
    EXPECT_EQ(bad, 0);
    destroy(vb);
    destroy(out);
    vkDestroyPipeline(device, pipeline, nullptr);
    vkDestroyFramebuffer(device, fb, nullptr);
    vkDestroyRenderPass(device, rp, nullptr);
    destroy(color);
  }
}

}  // namespace
}  // namespace vkrt::test
