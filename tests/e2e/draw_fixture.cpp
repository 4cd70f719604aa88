#include "e2e/draw_fixture.hpp"

#include "draw_color.frag.spv.h"
#include "draw_color.vert.spv.h"
#include "draw_flat.frag.spv.h"

namespace vkrt::test {

DrawTest::Target DrawTest::createTarget(VkFormat format, VkImageUsageFlags usage, VkImageAspectFlags aspects) {
  Target t;
  t.format = format;
  t.aspects = aspects;
  VkImageCreateInfo ci{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  ci.imageType = VK_IMAGE_TYPE_2D;
  ci.format = format;
  ci.extent = {kW, kH, 1};
  ci.mipLevels = 1;
  ci.arrayLayers = 1;
  ci.samples = VK_SAMPLE_COUNT_1_BIT;
  ci.tiling = VK_IMAGE_TILING_OPTIMAL;
  ci.usage = usage;
  EXPECT_EQ(vkCreateImage(device, &ci, nullptr, &t.image), VK_SUCCESS);
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
  vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
  vi.format = format;
  vi.subresourceRange = {aspects, 0, 1, 0, 1};
  EXPECT_EQ(vkCreateImageView(device, &vi, nullptr, &t.view), VK_SUCCESS);
  return t;
}

void DrawTest::destroy(Target& t) {
  vkDestroyImageView(device, t.view, nullptr);
  vkDestroyImage(device, t.image, nullptr);
  vkFreeMemory(device, t.memory, nullptr);
  t = {};
}

VkResult DrawTest::createPipeline(const PipelineDesc& d, VkPipeline* out) {
  if (!layout) {
    VkPipelineLayoutCreateInfo lci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    lci.pushConstantRangeCount = uint32_t(d.pushRanges.size());
    lci.pPushConstantRanges = d.pushRanges.data();
    lci.setLayoutCount = d.setLayout ? 1 : 0;
    lci.pSetLayouts = &d.setLayout;
    EXPECT_EQ(vkCreatePipelineLayout(device, &lci, nullptr, &layout), VK_SUCCESS);
  }
  auto module = [&](const uint32_t* words, size_t bytes) {
    VkShaderModuleCreateInfo sm{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    sm.codeSize = bytes;
    sm.pCode = words;
    VkShaderModule m = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreateShaderModule(device, &sm, nullptr, &m), VK_SUCCESS);
    modules.push_back(m);
    return m;
  };
  std::vector<VkPipelineShaderStageCreateInfo> stages;
  if (d.vs) {
    VkPipelineShaderStageCreateInfo s{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    s.stage = VK_SHADER_STAGE_VERTEX_BIT;
    s.module = module(d.vs, d.vsBytes);
    s.pName = "main";
    stages.push_back(s);
  }
  if (d.fs) {
    VkPipelineShaderStageCreateInfo s{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    s.stage = VK_SHADER_STAGE_FRAGMENT_BIT;
    s.module = module(d.fs, d.fsBytes);
    s.pName = "main";
    stages.push_back(s);
  }
  for (const auto& s : d.extraStages) stages.push_back(s);
  VkPipelineVertexInputStateCreateInfo vi{VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
  vi.vertexBindingDescriptionCount = uint32_t(d.bindings.size());
  vi.pVertexBindingDescriptions = d.bindings.data();
  vi.vertexAttributeDescriptionCount = uint32_t(d.attributes.size());
  vi.pVertexAttributeDescriptions = d.attributes.data();
  VkPipelineInputAssemblyStateCreateInfo ia{VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
  ia.topology = d.topology;
  ia.primitiveRestartEnable = d.primitiveRestart;
  bool dynViewportCount = false, dynScissorCount = false;
  for (VkDynamicState s : d.dynamic) {
    dynViewportCount |= s == VK_DYNAMIC_STATE_VIEWPORT_WITH_COUNT;
    dynScissorCount |= s == VK_DYNAMIC_STATE_SCISSOR_WITH_COUNT;
  }
  VkPipelineViewportStateCreateInfo vp{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
  vp.viewportCount = dynViewportCount ? 0 : 1;
  vp.pViewports = &d.viewport;
  vp.scissorCount = dynScissorCount ? 0 : 1;
  vp.pScissors = &d.scissor;
  VkPipelineRasterizationStateCreateInfo rs{VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
  rs.polygonMode = VK_POLYGON_MODE_FILL;
  rs.cullMode = d.cullMode;
  rs.frontFace = d.frontFace;
  rs.rasterizerDiscardEnable = d.rasterizerDiscard;
  rs.depthBiasEnable = d.depthBiasEnable;
  rs.depthBiasConstantFactor = d.depthBiasConstant;
  rs.lineWidth = 1.0f;
  VkPipelineMultisampleStateCreateInfo ms{VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
  ms.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
  std::vector<VkPipelineColorBlendAttachmentState> blends(d.blendCount, d.blend);
  VkPipelineColorBlendStateCreateInfo cb{VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
  cb.attachmentCount = d.blendCount;
  cb.pAttachments = blends.data();
  std::memcpy(cb.blendConstants, d.blendConstants, sizeof cb.blendConstants);
  cb.logicOpEnable = d.logicOpEnable;
  cb.logicOp = d.logicOp;
  VkPipelineDynamicStateCreateInfo dyn{VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO};
  dyn.dynamicStateCount = uint32_t(d.dynamic.size());
  dyn.pDynamicStates = d.dynamic.data();
  const VkFormat dsFormat = d.withDepthStencil ? depthStencilFormat() : VK_FORMAT_UNDEFINED;
  std::vector<VkFormat> colorFormats(d.colorCount, d.colorFormat);
  VkPipelineRenderingCreateInfo ri{VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO};
  ri.colorAttachmentCount = d.colorCount;
  ri.pColorAttachmentFormats = colorFormats.data();
  ri.depthAttachmentFormat = dsFormat;
  ri.stencilAttachmentFormat = dsFormat;
  VkGraphicsPipelineCreateInfo ci{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO, &ri};
  ci.flags = d.flags;
  ci.stageCount = uint32_t(stages.size());
  ci.pStages = stages.data();
  ci.pVertexInputState = &vi;
  ci.pInputAssemblyState = &ia;
  ci.pViewportState = &vp;
  ci.pRasterizationState = &rs;
  ci.pMultisampleState = &ms;
  ci.pDepthStencilState = d.withDepthStencil ? &d.depthStencil : nullptr;
  ci.pColorBlendState = &cb;
  ci.pDynamicState = &dyn;
  ci.layout = layout;
  if (d.renderPass) {
    ci.pNext = nullptr;
    ci.renderPass = d.renderPass;
  }
  ci.basePipelineHandle = d.base;
  ci.basePipelineIndex = -1;
  *out = VK_NULL_HANDLE;
  return vkCreateGraphicsPipelines(device, VK_NULL_HANDLE, 1, &ci, nullptr, out);
}

std::vector<uint32_t> DrawTest::render(const Target& color, const Target* depth,
                                       const std::function<void(VkCommandBuffer)>& draw, uint32_t clear) {
  const uint32_t texelBytes = color.format == VK_FORMAT_R16G16B16A16_SFLOAT ? 8 : 4;
  HostBuffer out = createHostBuffer(kW * kH * texelBytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  VkCommandBuffer cb = beginOneTime();
  VkImageMemoryBarrier barriers[2]{};
  for (int k = 0; k < 2; ++k) {
    const Target* t = k == 0 ? &color : depth;
    if (!t) continue;
    VkImageMemoryBarrier& b = barriers[k];
    b.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
    b.dstAccessMask = k == 0
                          ? VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_COLOR_ATTACHMENT_READ_BIT
                          : VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT;
    b.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    b.newLayout = k == 0 ? VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL : VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = t->image;
    b.subresourceRange = {t->aspects, 0, 1, 0, 1};
  }
  vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT,
                       VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT |
                           VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT,
                       0, 0, nullptr, 0, nullptr, depth ? 2 : 1, barriers);
  VkRenderingAttachmentInfo ca{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
  ca.imageView = color.view;
  ca.imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
  ca.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
  ca.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  for (int c = 0; c < 4; ++c) ca.clearValue.color.float32[c] = float((clear >> (8 * c)) & 0xFF) / 255.0f;
  VkRenderingAttachmentInfo da{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
  if (depth) {
    da.imageView = depth->view;
    da.imageLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
    da.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
    da.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    da.clearValue.depthStencil = {1.0f, 0};
  }
  VkRenderingInfo ri{VK_STRUCTURE_TYPE_RENDERING_INFO};
  ri.renderArea = {{0, 0}, {kW, kH}};
  ri.layerCount = 1;
  ri.colorAttachmentCount = 1;
  ri.pColorAttachments = &ca;
  ri.pDepthAttachment = depth ? &da : nullptr;
  ri.pStencilAttachment = depth ? &da : nullptr;
  vkCmdBeginRendering(cb, &ri);
  draw(cb);
  vkCmdEndRendering(cb);
  VkImageMemoryBarrier toSrc = barriers[0];
  toSrc.srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
  toSrc.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
  toSrc.oldLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
  toSrc.newLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
  vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr,
                       0, nullptr, 1, &toSrc);
  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.imageExtent = {kW, kH, 1};
  vkCmdCopyImageToBuffer(cb, color.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, out.buffer, 1, &region);
  VkBufferMemoryBarrier hb{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER};
  hb.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  hb.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  hb.srcQueueFamilyIndex = hb.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  hb.buffer = out.buffer;
  hb.size = VK_WHOLE_SIZE;
  vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 0, nullptr, 1, &hb, 0,
                       nullptr);
  submitAndWait(cb);
  std::vector<uint32_t> pixels(kW * kH * texelBytes / 4);
  std::memcpy(pixels.data(), out.data, pixels.size() * 4);
  destroy(out);
  return pixels;
}

int DrawTest::coverage(const Vertex& a, const Vertex& b, const Vertex& c, int px, int py, double margin, double vx,
                       double vy, double vw, double vh) {
  auto fx = [&](const Vertex& v) { return (double(v.x) + 1.0) * vw / 2.0 + vx; };
  auto fy = [&](const Vertex& v) { return (double(v.y) + 1.0) * vh / 2.0 + vy; };
  const double x[3] = {fx(a), fx(b), fx(c)}, y[3] = {fy(a), fy(b), fy(c)};
  const double cx = px + 0.5, cy = py + 0.5;
  const double area = (x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0]);
  if (area == 0) return 0;
  bool inside = true;
  for (int e = 0; e < 3; ++e) {
    const int i = e, j = (e + 1) % 3;
    const double ex = x[j] - x[i], ey = y[j] - y[i];
    // Signed distance of the centre from edge i->j, positive on the triangle's side.
    const double d = ((cx - x[i]) * ey - (cy - y[i]) * ex) / std::sqrt(ex * ex + ey * ey) * (area > 0 ? -1.0 : 1.0);
    if (d < -margin) return 0;
    if (d <= margin) inside = false;
  }
  return inside ? 1 : -1;
}

std::array<double, 4> DrawTest::interpolate(const Vertex& a, const Vertex& b, const Vertex& c, int px, int py) {
  auto fx = [](const Vertex& v) { return (double(v.x) + 1.0) * kW / 2.0; };
  auto fy = [](const Vertex& v) { return (double(v.y) + 1.0) * kH / 2.0; };
  const double cx = px + 0.5, cy = py + 0.5;
  const double x0 = fx(a), y0 = fy(a), x1 = fx(b), y1 = fy(b), x2 = fx(c), y2 = fy(c);
  const double area = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0);
  const double l1 = ((cx - x0) * (y2 - y0) - (x2 - x0) * (cy - y0)) / area;
  const double l2 = ((x1 - x0) * (cy - y0) - (cx - x0) * (y1 - y0)) / area;
  const double l0 = 1.0 - l1 - l2;
  return {l0 * a.r + l1 * b.r + l2 * c.r, l0 * a.g + l1 * b.g + l2 * c.g, l0 * a.b + l1 * b.b + l2 * c.b,
          l0 * a.a + l1 * b.a + l2 * c.a};
}

int DrawTest::compareTriangles(const std::vector<uint32_t>& pixels, const std::vector<std::array<Vertex, 3>>& tris,
                               uint32_t background, bool smooth) {
  int bad = 0;
  for (int py = 0; py < int(kH); ++py) {
    for (int px = 0; px < int(kW); ++px) {
      uint32_t want = background;
      bool known = true;
      for (const auto& t : tris) {
        const int cov = coverage(t[0], t[1], t[2], px, py);
        if (cov < 0) known = false;
        if (cov == 1) {
          known = true;
          const auto c =
              smooth ? interpolate(t[0], t[1], t[2], px, py) : std::array<double, 4>{t[0].r, t[0].g, t[0].b, t[0].a};
          want = rgba8(c[0], c[1], c[2], c[3]);
        }
      }
      if (!known) continue;
      const uint32_t got = pixels[py * kW + px];
      if (!near(got, want)) {
        if (++bad <= 5)
          ADD_FAILURE() << "pixel (" << px << ", " << py << "): got 0x" << std::hex << got << ", want 0x" << want;
      }
    }
  }
  return bad;
}

void DrawTest::TearDown() {
  if (device) {
    for (VkShaderModule m : modules) vkDestroyShaderModule(device, m, nullptr);
    if (layout) vkDestroyPipelineLayout(device, layout, nullptr);
  }
  modules.clear();
  layout = VK_NULL_HANDLE;
  VulkanTest::TearDown();
}

DrawTest::PipelineDesc DrawTest::colorPipeline() {
  PipelineDesc d;
  d.vs = kSpv_draw_color_vert;
  d.vsBytes = sizeof kSpv_draw_color_vert;
  d.fs = kSpv_draw_color_frag;
  d.fsBytes = sizeof kSpv_draw_color_frag;
  d.bindings = {{0, sizeof(Vertex), VK_VERTEX_INPUT_RATE_VERTEX}};
  d.attributes = {{0, 0, VK_FORMAT_R32G32_SFLOAT, 0}, {1, 0, VK_FORMAT_R32G32B32A32_SFLOAT, 8}};
  return d;
}

std::vector<uint32_t> DrawTest::drawFullScreen(const uint32_t* fs, size_t fsBytes, const float rgba[4], uint32_t clear,
                                               const uint32_t* vs, size_t vsBytes) {
  Target color = createTarget(kColorFormat, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                              VK_IMAGE_ASPECT_COLOR_BIT);
  PipelineDesc d = colorPipeline();
  if (vs) d.vs = vs, d.vsBytes = vsBytes;
  d.fs = fs;
  d.fsBytes = fsBytes;
  VkPipeline pipeline;
  if (createPipeline(d, &pipeline) != VK_SUCCESS) {
    ADD_FAILURE() << "vkCreateGraphicsPipelines failed";
    destroy(color);
    return {};
  }
  const float r = rgba[0], g = rgba[1], b = rgba[2], a = rgba[3];
  const Vertex tri[3] = {{-1, -1, r, g, b, a}, {3, -1, r, g, b, a}, {-1, 3, r, g, b, a}};
  HostBuffer vb = vertexBuffer(tri, sizeof tri);
  std::vector<uint32_t> pixels = render(
      color, nullptr,
      [&](VkCommandBuffer cb) {
        vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
        VkDeviceSize off = 0;
        vkCmdBindVertexBuffers(cb, 0, 1, &vb.buffer, &off);
        vkCmdDraw(cb, 3, 1, 0, 0);
      },
      clear);
  destroy(vb);
  vkDestroyPipeline(device, pipeline, nullptr);
  destroy(color);
  return pixels;
}

void QuadrantDrawTest::setUpQuadrants(const uint32_t* vs, size_t vsBytes) {
  PipelineDesc d;
  d.vs = vs;
  d.vsBytes = vsBytes;
  d.fs = kSpv_draw_flat_frag;
  d.fsBytes = sizeof kSpv_draw_flat_frag;
  d.bindings = {{0, 8, VK_VERTEX_INPUT_RATE_VERTEX}};
  d.attributes = {{0, 0, VK_FORMAT_R32G32_SFLOAT, 0}};
  ASSERT_EQ(createPipeline(d, &pipeline), VK_SUCCESS);
  color = createTarget(kColorFormat, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                       VK_IMAGE_ASPECT_COLOR_BIT);
  std::vector<float> v;
  for (int q = 0; q < 4; ++q) {
    const float cx = q & 1 ? 0.5f : -0.5f, cy = q & 2 ? 0.5f : -0.5f;
    for (float p : {cx - 0.35f, cy - 0.35f, cx + 0.35f, cy - 0.35f, cx, cy + 0.35f}) v.push_back(p);
    quads[q] = {Vertex{cx - 0.35f, cy - 0.35f, 0, 0, 0, 1}, Vertex{cx + 0.35f, cy - 0.35f, 0, 0, 0, 1},
                Vertex{cx, cy + 0.35f, 0, 0, 0, 1}};
  }
  vb = vertexBuffer(v.data(), v.size() * 4);
  const uint32_t idx[12] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11};
  ib = vertexBuffer(idx, sizeof idx, VK_BUFFER_USAGE_INDEX_BUFFER_BIT);
}

void QuadrantDrawTest::TearDown() {
  if (device) {
    destroy(ib);
    destroy(vb);
    vkDestroyPipeline(device, pipeline, nullptr);
    destroy(color);
  }
  DrawTest::TearDown();
}

void QuadrantDrawTest::bind(VkCommandBuffer cb) {
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
  VkDeviceSize off = 0;
  vkCmdBindVertexBuffers(cb, 0, 1, &vb.buffer, &off);
  vkCmdBindIndexBuffer(cb, ib.buffer, 0, VK_INDEX_TYPE_UINT32);
}

}  // namespace vkrt::test
