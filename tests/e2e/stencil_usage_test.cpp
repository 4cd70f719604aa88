// VkImageStencilUsageCreateInfo (Vulkan 1.2, VK_EXT_separate_stencil_usage): the stencil aspect of a depth/stencil
// image has its own usage. Each usage check that names an aspect reads the depth aspect's `usage` and the stencil
// aspect's `stencilUsage`: a stencil operation that only stencilUsage allows is not reported and does its work
// (bytes read back), one that only `usage` allows is reported with the aspect's VUID and does nothing, and the
// validation layer agrees (the layer stays on; its matching report is taken and counted).
#include <cstring>

#include "e2e/render_pass_fixture.hpp"

namespace vkrt::test {
namespace {

constexpr VkFormat kFmt = VK_FORMAT_D24_UNORM_S8_UINT;
constexpr VkImageAspectFlags kDepth = VK_IMAGE_ASPECT_DEPTH_BIT;
constexpr VkImageAspectFlags kStencil = VK_IMAGE_ASPECT_STENCIL_BIT;
constexpr VkImageAspectFlags kBoth = kDepth | kStencil;
constexpr VkImageUsageFlags kDS = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT;
constexpr VkImageUsageFlags kSrc = VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
constexpr VkImageUsageFlags kDst = VK_IMAGE_USAGE_TRANSFER_DST_BIT;

class StencilUsageTest : public RenderPassTest {
 protected:
  // A 4x3 D24_UNORM_S8_UINT image with `usage` and `stencilUsage`, in GENERAL (no view).
  Attachment dsImage(VkImageUsageFlags usage, VkImageUsageFlags stencilUsage) {
    VkImageStencilUsageCreateInfo su{VK_STRUCTURE_TYPE_IMAGE_STENCIL_USAGE_CREATE_INFO, nullptr, stencilUsage};
    VkImageCreateInfo ci = imageInfo(VK_IMAGE_TYPE_2D, kFmt, {4, 3, 1}, 1, 1, usage);
    ci.pNext = &su;
    Attachment a;
    a.format = kFmt;
    a.width = 4;
    a.height = 3;
    a.img = createImage(ci);
    VkCommandBuffer cb = beginOneTime();
    barrier(cb, a.img.image, kBoth, VK_IMAGE_LAYOUT_UNDEFINED);
    submitAndWait(cb);
    return a;
  }

  // Uploads 12 stencil bytes 100 + i.
  void uploadStencil(const Attachment& a) {
    HostBuffer up = createHostBuffer(16, kXfer);
    for (uint32_t i = 0; i < 12; ++i) bytes(up)[i] = uint8_t(100 + i);
    VkCommandBuffer cb = beginOneTime();
    VkBufferImageCopy r{0, 0, 0, {kStencil, 0, 0, 1}, {}, {4, 3, 1}};
    vkCmdCopyBufferToImage(cb, up.buffer, a.img.image, VK_IMAGE_LAYOUT_GENERAL, 1, &r);
    submitAndWait(cb);
    destroy(up);
  }

  void clearDepth(const Attachment& a, float depth) {
    VkCommandBuffer cb = beginOneTime();
    VkClearDepthStencilValue v{depth, 0};
    VkImageSubresourceRange r{kDepth, 0, 1, 0, 1};
    vkCmdClearDepthStencilImage(cb, a.img.image, VK_IMAGE_LAYOUT_GENERAL, &v, 1, &r);
    submitAndWait(cb);
  }

  // vkrt reported `vuid` once (and nothing else); the layer reported it `layer` times.
  void expectReported(const char* vuid, size_t layer = 1) {
    EXPECT_EQ(takeLayerMessages(vuid), validationEnabled ? layer : 0) << "the layer disagrees on " << vuid;
    expectVkrtMessage(vuid);
  }
  void expectQuiet() { EXPECT_TRUE(vkrtMessages().empty()) << vkrtMessages()[0].text; }
};

// vkGetPhysicalDeviceImageFormatProperties2 answers for both usages; vkCreateImage alike.
TEST_F(StencilUsageTest, FormatPropertiesAnswerForBothUsages) {
  auto query = [&](VkFormat f, VkImageUsageFlags usage, const VkImageStencilUsageCreateInfo* su) {
    VkPhysicalDeviceImageFormatInfo2 info{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_IMAGE_FORMAT_INFO_2};
    info.pNext = su;
    info.format = f;
    info.type = VK_IMAGE_TYPE_2D;
    info.tiling = VK_IMAGE_TILING_OPTIMAL;
    info.usage = usage;
    VkImageFormatProperties2 p{VK_STRUCTURE_TYPE_IMAGE_FORMAT_PROPERTIES_2};
    return vkGetPhysicalDeviceImageFormatProperties2(physicalDevice, &info, &p);
  };
  VkImageStencilUsageCreateInfo storage{VK_STRUCTURE_TYPE_IMAGE_STENCIL_USAGE_CREATE_INFO, nullptr,
                                        kDS | VK_IMAGE_USAGE_STORAGE_BIT};
  VkImageStencilUsageCreateInfo sampled{VK_STRUCTURE_TYPE_IMAGE_STENCIL_USAGE_CREATE_INFO, nullptr,
                                        kDS | VK_IMAGE_USAGE_SAMPLED_BIT};
  EXPECT_EQ(query(kFmt, kDS, nullptr), VK_SUCCESS);
  EXPECT_EQ(query(kFmt, kDS, &sampled), VK_SUCCESS);
  // The stencil aspect's usage is asked too: no depth/stencil format is a storage image on vkrt.
  if (onVkrt()) {
    EXPECT_EQ(query(kFmt, kDS, &storage), VK_ERROR_FORMAT_NOT_SUPPORTED);
    EXPECT_EQ(query(kFmt, kDS | VK_IMAGE_USAGE_STORAGE_BIT, nullptr), VK_ERROR_FORMAT_NOT_SUPPORTED);
  }
  // A format without stencil ignores the structure.
  EXPECT_EQ(query(VK_FORMAT_D16_UNORM, kDS, &storage), VK_SUCCESS);
}

// Buffer copies: the rules (dstImage-00177, srcImage-00186) ask the image's usage for every aspect; the stencil
// aspect is also used only as stencilUsage says ("Image Creation").
TEST_F(StencilUsageTest, BufferCopiesOfTheStencilAspect) {
  // usage allows reading, stencilUsage only writing: the stencil upload and a depth read-back work.
  Attachment a = dsImage(kDS | kSrc | kDst, kDS | kDst);
  uploadStencil(a);
  clearDepth(a, 0.5f);
  expectQuiet();
  std::vector<uint8_t> d = readBack(a, kDepth, 4);
  for (uint32_t i = 0; i < 12; ++i) EXPECT_EQ(texelU32(d, i) & 0xFFFFFFu, 8388608u) << i;
  expectQuiet();
  // Reading the stencil back breaks stencilUsage: reported, the buffer keeps its bytes. (The 1.3.239 layer reads
  // only `usage` here, so it does not see it.)
  HostBuffer b = createHostBuffer(16, kXfer);
  std::memset(b.data, 0xEE, 16);
  VkCommandBuffer cb = beginOneTime();
  VkBufferImageCopy r{0, 0, 0, {kStencil, 0, 0, 1}, {}, {4, 3, 1}};
  vkCmdCopyImageToBuffer(cb, a.img.image, VK_IMAGE_LAYOUT_GENERAL, b.buffer, 1, &r);
  expectReported("VUID-vkCmdCopyImageToBuffer-srcImage-00186", 0);
  submitAndWait(cb);
  for (uint32_t i = 0; i < 12; ++i) EXPECT_EQ(bytes(b)[i], 0xEE) << i;
  destroy(b);
  destroy(a);
}

// vkCmdCopyImage: aspect-06662 / 06663 (other aspects: usage) and 06664 / 06665 (stencil: stencilUsage).
TEST_F(StencilUsageTest, CopyImagePerAspect) {
  // Neither image has the transfer bit in `usage` that the stencil copy needs; their stencilUsage has it.
  Attachment src = dsImage(kDS | kDst, kDS | kSrc | kDst);
  Attachment dst = dsImage(kDS | kSrc, kDS | kSrc | kDst);
  uploadStencil(src);
  expectQuiet();
  VkImageCopy stencil{{kStencil, 0, 0, 1}, {}, {kStencil, 0, 0, 1}, {}, {4, 3, 1}};
  VkCommandBuffer cb = beginOneTime();
  vkCmdCopyImage(cb, src.img.image, VK_IMAGE_LAYOUT_GENERAL, dst.img.image, VK_IMAGE_LAYOUT_GENERAL, 1, &stencil);
  submitAndWait(cb);
  expectQuiet();
  std::vector<uint8_t> s = readBack(dst, kStencil, 1);
  for (uint32_t i = 0; i < 12; ++i) EXPECT_EQ(s[i], 100 + i) << i;
  // The stencil aspect reads stencilUsage: a source whose stencilUsage lacks TRANSFER_SRC (06664) and a
  // destination whose stencilUsage lacks TRANSFER_DST (06665); dst's stencil keeps the copied bytes.
  Attachment noSrc = dsImage(kDS | kSrc | kDst, kDS | kDst);
  Attachment noDst = dsImage(kDS | kSrc | kDst, kDS | kSrc);
  // The depth aspect reads `usage`, where srcImage lacks TRANSFER_SRC (06662).
  VkImageCopy depth{{kDepth, 0, 0, 1}, {}, {kDepth, 0, 0, 1}, {}, {4, 3, 1}};
  cb = beginOneTime();
  vkCmdCopyImage(cb, src.img.image, VK_IMAGE_LAYOUT_GENERAL, noSrc.img.image, VK_IMAGE_LAYOUT_GENERAL, 1, &depth);
  expectReported("VUID-vkCmdCopyImage-aspect-06662");
  submitAndWait(cb);
  cb = beginOneTime();
  vkCmdCopyImage(cb, noSrc.img.image, VK_IMAGE_LAYOUT_GENERAL, dst.img.image, VK_IMAGE_LAYOUT_GENERAL, 1, &stencil);
  expectReported("VUID-vkCmdCopyImage-aspect-06664");
  VkCopyImageInfo2 info{VK_STRUCTURE_TYPE_COPY_IMAGE_INFO_2};
  VkImageCopy2 r2{VK_STRUCTURE_TYPE_IMAGE_COPY_2, nullptr, {kStencil, 0, 0, 1}, {}, {kStencil, 0, 0, 1}, {}, {4, 3, 1}};
  info.srcImage = dst.img.image;
  info.srcImageLayout = VK_IMAGE_LAYOUT_GENERAL;
  info.dstImage = noDst.img.image;
  info.dstImageLayout = VK_IMAGE_LAYOUT_GENERAL;
  info.regionCount = 1;
  info.pRegions = &r2;
  vkCmdCopyImage2(cb, &info);
  expectReported("VUID-VkCopyImageInfo2-aspect-06665");
  submitAndWait(cb);
  s = readBack(dst, kStencil, 1);
  for (uint32_t i = 0; i < 12; ++i) EXPECT_EQ(s[i], 100 + i) << i;
  for (Attachment* a : {&src, &dst, &noSrc, &noDst}) destroy(*a);
}

// vkCmdClearDepthStencilImage: pRanges-02660 (depth: usage), 02658 (stencil, separate stencil usage), 02659
// (stencil, one usage).
TEST_F(StencilUsageTest, ClearDepthStencilImagePerAspect) {
  // stencilUsage allows the stencil clear that usage does not.
  Attachment a = dsImage(kDS | kSrc, kDS | kSrc | kDst);
  VkCommandBuffer cb = beginOneTime();
  VkClearDepthStencilValue v{0.5f, 0x5A};
  VkImageSubresourceRange stencil{kStencil, 0, 1, 0, 1}, both{kBoth, 0, 1, 0, 1};
  vkCmdClearDepthStencilImage(cb, a.img.image, VK_IMAGE_LAYOUT_GENERAL, &v, 1, &stencil);
  submitAndWait(cb);
  expectQuiet();
  std::vector<uint8_t> s = readBack(a, kStencil, 1);
  for (uint32_t i = 0; i < 12; ++i) EXPECT_EQ(s[i], 0x5A) << i;
  // Depth and stencil: the depth aspect reads usage.
  cb = beginOneTime();
  VkClearDepthStencilValue v2{0.0f, 0x11};
  vkCmdClearDepthStencilImage(cb, a.img.image, VK_IMAGE_LAYOUT_GENERAL, &v2, 1, &both);
  expectReported("VUID-vkCmdClearDepthStencilImage-pRanges-02660");
  submitAndWait(cb);
  s = readBack(a, kStencil, 1);
  for (uint32_t i = 0; i < 12; ++i) EXPECT_EQ(s[i], 0x5A) << i;
  // usage allows the stencil clear that stencilUsage does not: reported, depth and stencil kept.
  Attachment b = dsImage(kDS | kSrc | kDst, kDS | kSrc);
  clearDepth(b, 0.5f);
  expectQuiet();
  cb = beginOneTime();
  vkCmdClearDepthStencilImage(cb, b.img.image, VK_IMAGE_LAYOUT_GENERAL, &v2, 1, &both);
  expectReported("VUID-vkCmdClearDepthStencilImage-pRanges-02658");
  submitAndWait(cb);
  std::vector<uint8_t> d = readBack(b, kDepth, 4);
  for (uint32_t i = 0; i < 12; ++i) EXPECT_EQ(texelU32(d, i) & 0xFFFFFFu, 8388608u) << i;
  // Without separate stencil usage the stencil aspect reads usage (02659).
  Img c = createImage(imageInfo(VK_IMAGE_TYPE_2D, kFmt, {4, 3, 1}, 1, 1, kDS | kSrc));
  cb = beginOneTime();
  barrier(cb, c.image, kBoth, VK_IMAGE_LAYOUT_UNDEFINED);
  vkCmdClearDepthStencilImage(cb, c.image, VK_IMAGE_LAYOUT_GENERAL, &v2, 1, &stencil);
  expectReported("VUID-vkCmdClearDepthStencilImage-pRanges-02659");
  submitAndWait(cb);
  destroy(c);
  for (Attachment* x : {&a, &b}) destroy(*x);
}

// VkImageViewUsageCreateInfo: pNext-02663 (stencil: within stencilUsage), 02664 (depth: within usage).
TEST_F(StencilUsageTest, ViewUsageWithinTheAspectsUsage) {
  Attachment a = dsImage(kDS | kSrc, kDS | kSrc | VK_IMAGE_USAGE_SAMPLED_BIT);
  VkImageViewUsageCreateInfo vu{VK_STRUCTURE_TYPE_IMAGE_VIEW_USAGE_CREATE_INFO, nullptr, VK_IMAGE_USAGE_SAMPLED_BIT};
  VkImageViewCreateInfo vi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO, &vu};
  vi.image = a.img.image;
  vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
  vi.format = kFmt;
  vi.subresourceRange = {kStencil, 0, 1, 0, 1};
  VkImageView view = VK_NULL_HANDLE;
  EXPECT_EQ(vkCreateImageView(device, &vi, nullptr, &view), VK_SUCCESS);
  expectQuiet();
  vkDestroyImageView(device, view, nullptr);
  // The depth aspect's usage lacks SAMPLED.
  vi.subresourceRange.aspectMask = kDepth;
  view = VK_NULL_HANDLE;
  const VkResult r = vkCreateImageView(device, &vi, nullptr, &view);
  expectReported("VUID-VkImageViewCreateInfo-pNext-02664");
  if (onVkrt()) {
    EXPECT_EQ(view, VkImageView(VK_NULL_HANDLE));
  }
  if (r == VK_SUCCESS) vkDestroyImageView(device, view, nullptr);
  // stencilUsage lacks SAMPLED, which usage has (02663).
  Attachment b = dsImage(kDS | kSrc | VK_IMAGE_USAGE_SAMPLED_BIT, kDS | kSrc);
  vi.image = b.img.image;
  vi.subresourceRange.aspectMask = kStencil;
  view = VK_NULL_HANDLE;
  const VkResult r2 = vkCreateImageView(device, &vi, nullptr, &view);
  expectReported("VUID-VkImageViewCreateInfo-pNext-02663");
  if (r2 == VK_SUCCESS) vkDestroyImageView(device, view, nullptr);
  for (Attachment* x : {&a, &b}) destroy(*x);
}

// Image creation: the attachment bits of stencilUsage agree with usage (VUID-VkImageCreateInfo-format-02795).
TEST_F(StencilUsageTest, StencilUsageAttachmentBitsAgree) {
  VkImageStencilUsageCreateInfo su{VK_STRUCTURE_TYPE_IMAGE_STENCIL_USAGE_CREATE_INFO, nullptr, kDst};
  VkImageCreateInfo ci = imageInfo(VK_IMAGE_TYPE_2D, kFmt, {4, 3, 1}, 1, 1, kDS | kDst);
  ci.pNext = &su;
  VkImage img = VK_NULL_HANDLE;
  const VkResult r = vkCreateImage(device, &ci, nullptr, &img);
  expectReported("VUID-VkImageCreateInfo-format-02795");
  if (onVkrt()) {
    EXPECT_EQ(r, VK_ERROR_VALIDATION_FAILED_EXT);
  }
  if (r == VK_SUCCESS) vkDestroyImage(device, img, nullptr);
}

// Dynamic rendering and imageless framebuffers read the view's usage: a depth/stencil view inherits the
// intersection of usage and stencilUsage (VUID-VkRenderPassBeginInfo-framebuffer-04627 compares it).
TEST_F(StencilUsageTest, ImagelessFramebufferComparesTheInheritedUsage) {
  Attachment a = dsImage(kDS | kSrc | kDst, kDS | kDst);
  VkImageViewCreateInfo vi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
  vi.image = a.img.image;
  vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
  vi.format = kFmt;
  vi.subresourceRange = {kBoth, 0, 1, 0, 1};
  ASSERT_EQ(vkCreateImageView(device, &vi, nullptr, &a.view), VK_SUCCESS);
  VkAttachmentReference ref{0, VK_IMAGE_LAYOUT_GENERAL};
  VkSubpassDescription sub{};
  sub.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
  sub.pDepthStencilAttachment = &ref;
  VkRenderPass rp =
      renderPass({desc(kFmt, VK_ATTACHMENT_LOAD_OP_CLEAR, VK_SAMPLE_COUNT_1_BIT, VK_ATTACHMENT_LOAD_OP_CLEAR)}, {sub});
  auto imageless = [&](VkImageUsageFlags usage) {
    VkFramebufferAttachmentImageInfo ii{VK_STRUCTURE_TYPE_FRAMEBUFFER_ATTACHMENT_IMAGE_INFO};
    ii.usage = usage;
    ii.width = 4;
    ii.height = 3;
    ii.layerCount = 1;
    ii.viewFormatCount = 1;
    ii.pViewFormats = &kFmt;
    VkFramebufferAttachmentsCreateInfo ai{VK_STRUCTURE_TYPE_FRAMEBUFFER_ATTACHMENTS_CREATE_INFO, nullptr, 1, &ii};
    VkFramebufferCreateInfo ci{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO, &ai, VK_FRAMEBUFFER_CREATE_IMAGELESS_BIT};
    ci.renderPass = rp;
    ci.attachmentCount = 1;
    ci.width = 4;
    ci.height = 3;
    ci.layers = 1;
    VkFramebuffer fb = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreateFramebuffer(device, &ci, nullptr, &fb), VK_SUCCESS);
    return fb;
  };
  // A begin vkrt rejects leaves no render pass for the end to close (vkrt reports that too; the layer does not).
  auto run = [&](VkFramebuffer fb, const char* vuid) {
    VkRenderPassAttachmentBeginInfo ab{VK_STRUCTURE_TYPE_RENDER_PASS_ATTACHMENT_BEGIN_INFO, nullptr, 1, &a.view};
    VkClearValue clear{};
    clear.depthStencil = {0.25f, 0x42};
    VkRenderPassBeginInfo bi = beginInfo(rp, fb, {{0, 0}, {4, 3}}, {clear});
    bi.pNext = &ab;
    VkCommandBuffer cb = beginOneTime();
    vkCmdBeginRenderPass(cb, &bi, VK_SUBPASS_CONTENTS_INLINE);
    if (vuid) expectReported(vuid);
    vkCmdEndRenderPass(cb);
    if (vuid) expectVkrtMessage("VUID-vkCmdEndRenderPass-renderpass");
    submitAndWait(cb);
  };
  // The inherited usage DS | TRANSFER_DST: a framebuffer that names it begins and clears the stencil to 0x42.
  VkFramebuffer ok = imageless(kDS | kDst);
  run(ok, nullptr);
  expectQuiet();
  // (the stencil read-back needs stencilUsage TRANSFER_SRC, which this image lacks: the clear is checked by the
  // depth aspect, which usage lets the read-back copy)
  std::vector<uint8_t> d = readBack(a, kDepth, 4);
  for (uint32_t i = 0; i < 12; ++i) EXPECT_EQ(texelU32(d, i) & 0xFFFFFFu, 4194304u) << i;  // 0.25 * (2^24 - 1)
  expectQuiet();
  // The image's usage is not the view's: reported.
  VkFramebuffer bad = imageless(kDS | kSrc | kDst);
  clearDepth(a, 1.0f);
  run(bad, "VUID-VkRenderPassBeginInfo-framebuffer-04627");
  d = readBack(a, kDepth, 4);
  for (uint32_t i = 0; i < 12; ++i) EXPECT_EQ(texelU32(d, i) & 0xFFFFFFu, 0xFFFFFFu) << i;
  vkDestroyFramebuffer(device, ok, nullptr);
  vkDestroyFramebuffer(device, bad, nullptr);
  vkDestroyRenderPass(device, rp, nullptr);
  destroy(a);
}

// Descriptor writes read the view's usage (VUID-VkWriteDescriptorSet-descriptorType-00337): a stencil view of an
// image whose stencilUsage has SAMPLED is a sampled image, a depth view of it (usage without SAMPLED) is not.
TEST_F(StencilUsageTest, SampledImageDescriptorsReadTheViewsAspectUsage) {
  Attachment a = dsImage(kDS | kSrc, kDS | kSrc | VK_IMAGE_USAGE_SAMPLED_BIT);
  VkImageViewCreateInfo vi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
  vi.image = a.img.image;
  vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
  vi.format = kFmt;
  vi.subresourceRange = {kStencil, 0, 1, 0, 1};
  VkImageView stencilView = VK_NULL_HANDLE, depthView = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateImageView(device, &vi, nullptr, &stencilView), VK_SUCCESS);
  vi.subresourceRange.aspectMask = kDepth;
  ASSERT_EQ(vkCreateImageView(device, &vi, nullptr, &depthView), VK_SUCCESS);
  VkDescriptorSetLayoutBinding b{0, VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
  VkDescriptorSetLayoutCreateInfo lci{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO, nullptr, 0, 1, &b};
  VkDescriptorSetLayout layout = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateDescriptorSetLayout(device, &lci, nullptr, &layout), VK_SUCCESS);
  VkDescriptorPoolSize ps{VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, 1};
  VkDescriptorPoolCreateInfo pci{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO, nullptr, 0, 1, 1, &ps};
  VkDescriptorPool pool = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateDescriptorPool(device, &pci, nullptr, &pool), VK_SUCCESS);
  VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO, nullptr, pool, 1, &layout};
  VkDescriptorSet set = VK_NULL_HANDLE;
  ASSERT_EQ(vkAllocateDescriptorSets(device, &ai, &set), VK_SUCCESS);
  VkDescriptorImageInfo ii{VK_NULL_HANDLE, stencilView, VK_IMAGE_LAYOUT_GENERAL};
  VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, nullptr, set, 0, 0, 1,
                         VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE,       &ii};
  vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);
  expectQuiet();
  ii.imageView = depthView;
  vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);
  expectReported("VUID-VkWriteDescriptorSet-descriptorType-00337");
  vkDestroyDescriptorPool(device, pool, nullptr);
  vkDestroyDescriptorSetLayout(device, layout, nullptr);
  vkDestroyImageView(device, stencilView, nullptr);
  vkDestroyImageView(device, depthView, nullptr);
  destroy(a);
}

}  // namespace
}  // namespace vkrt::test
