// The draw tests' fixture (draw_*_test.cpp, graphics_pipeline_*_test.cpp): a color target (R8G8B8A8_UNORM) and an
// optional depth/stencil target rendered with dynamic rendering, graphics pipelines from a small description, and
// the independent reference the pixels are compared with: triangles rasterized here in double precision by the
// edge functions at pixel centres, colors interpolated barycentrically by hand.
#pragma once

#include <array>
#include <cmath>
#include <functional>
#include <vector>

#include "e2e/fixture.hpp"

namespace vkrt::test {

class DrawTest : public VulkanTest {
 protected:
  static constexpr uint32_t kW = 32, kH = 32;
  static constexpr VkFormat kColorFormat = VK_FORMAT_R8G8B8A8_UNORM;

  FixtureOptions options() override {
    FixtureOptions o;
    o.features.multiDrawIndirect = VK_TRUE;
    o.features.drawIndirectFirstInstance = VK_TRUE;
    o.features.depthBounds = VK_TRUE;
    o.features.independentBlend = VK_TRUE;
    o.features12.drawIndirectCount = VK_TRUE;
    o.features13.dynamicRendering = VK_TRUE;
    return o;
  }

  struct Target {
    VkImage image = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkImageView view = VK_NULL_HANDLE;
    VkFormat format = VK_FORMAT_UNDEFINED;
    VkImageAspectFlags aspects = 0;
  };

  // A depth/stencil format with attachment support (the spec requires D24_UNORM_S8_UINT or D32_SFLOAT_S8_UINT).
  VkFormat depthStencilFormat() {
    for (VkFormat f : {VK_FORMAT_D32_SFLOAT_S8_UINT, VK_FORMAT_D24_UNORM_S8_UINT}) {
      VkFormatProperties p;
      vkGetPhysicalDeviceFormatProperties(physicalDevice, f, &p);
      if (p.optimalTilingFeatures & VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT) return f;
    }
    ADD_FAILURE() << "no depth/stencil format with stencil";
    return VK_FORMAT_D32_SFLOAT_S8_UINT;
  }

  Target createTarget(VkFormat format, VkImageUsageFlags usage, VkImageAspectFlags aspects);
  void destroy(Target& t);
  using VulkanTest::destroy;

  struct PipelineDesc {
    const uint32_t* vs = nullptr;
    size_t vsBytes = 0;
    const uint32_t* fs = nullptr;
    size_t fsBytes = 0;
    std::vector<VkVertexInputBindingDescription> bindings;
    std::vector<VkVertexInputAttributeDescription> attributes;
    VkPrimitiveTopology topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
    VkBool32 primitiveRestart = VK_FALSE;
    VkCullModeFlags cullMode = VK_CULL_MODE_NONE;
    VkFrontFace frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
    VkBool32 rasterizerDiscard = VK_FALSE;
    VkBool32 depthBiasEnable = VK_FALSE;
    float depthBiasConstant = 0;
    VkPipelineDepthStencilStateCreateInfo depthStencil{VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
    VkPipelineColorBlendAttachmentState blend{VK_FALSE,
                                              VK_BLEND_FACTOR_ONE,
                                              VK_BLEND_FACTOR_ZERO,
                                              VK_BLEND_OP_ADD,
                                              VK_BLEND_FACTOR_ONE,
                                              VK_BLEND_FACTOR_ZERO,
                                              VK_BLEND_OP_ADD,
                                              0xF};
    float blendConstants[4] = {0, 0, 0, 0};
    VkBool32 logicOpEnable = VK_FALSE;  // pColorBlendState's logic op (the logicOp feature)
    VkLogicOp logicOp = VK_LOGIC_OP_COPY;
    std::vector<VkDynamicState> dynamic;
    bool withDepthStencil = false;        // the rendering info names the depth/stencil format
    uint32_t colorCount = 1;              // VkPipelineRenderingCreateInfo::colorAttachmentCount
    VkFormat colorFormat = kColorFormat;  // ... and the format of each
    uint32_t blendCount = 1;              // pColorBlendState->attachmentCount
    VkViewport viewport{0, 0, float(kW), float(kH), 0, 1};
    VkRect2D scissor{{0, 0}, {kW, kH}};
    VkPipelineCreateFlags flags = 0;
    VkPipeline base = VK_NULL_HANDLE;
    std::vector<VkPipelineShaderStageCreateInfo> extraStages;
    std::vector<VkPushConstantRange> pushRanges;
    VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;  // set 0 of the layout, when not null
    VkRenderPass renderPass = VK_NULL_HANDLE;          // subpass 0 of it instead of dynamic rendering, when not null
  };
  // draw_color.vert and draw_color.frag, reading Vertex's position and colour (binding 0, locations 0 and 1); the
  // rest of the state PipelineDesc's defaults.
  static PipelineDesc colorPipeline();
  // Creates the pipeline (and its layout, kept in `layout`); returns vkCreateGraphicsPipelines' result.
  VkResult createPipeline(const PipelineDesc& d, VkPipeline* out);

  // Records: barriers to attachment layouts, vkCmdBeginRendering (color cleared to `clear`, depth to 1, stencil to
  // 0), `draw`, vkCmdEndRendering, and a copy of the color target to a host buffer; submits, waits and returns the
  // pixels (RGBA8 as uint32_t, row-major; an R16G16B16A16_SFLOAT target's as two words a pixel). `depth` may be
  // null.
  std::vector<uint32_t> render(const Target& color, const Target* depth,
                               const std::function<void(VkCommandBuffer)>& draw, uint32_t clear = 0);

  // One triangle over the whole target in the color `rgba`, drawn by draw_color.vert (or the vertex shader `vs`, which
  // takes draw_color.vert's attributes) and the fragment shader `fs` into an RGBA8 target cleared to `clear`:
  // render()'s pixels (empty after a failure).
  std::vector<uint32_t> drawFullScreen(const uint32_t* fs, size_t fsBytes, const float rgba[4], uint32_t clear,
                                       const uint32_t* vs = nullptr, size_t vsBytes = 0);

  HostBuffer vertexBuffer(const void* data, size_t bytes,
                          VkBufferUsageFlags usage = VK_BUFFER_USAGE_VERTEX_BUFFER_BIT) {
    HostBuffer b = createHostBuffer(bytes, usage);
    std::memcpy(b.data, data, bytes);
    return b;
  }

  // ---- the reference ----
 public:
  struct Vertex {
    float x, y;        // NDC
    float r, g, b, a;  // color
  };

 protected:
  // Where a pixel centre lies relative to a triangle given in NDC, with the viewport covering the target
  // (x_f = (x + 1) * W / 2): 1 inside by more than `margin` pixels from every edge, 0 outside by more than the
  // margin, -1 near an edge (not checked). Either winding.
  static int coverage(const Vertex& a, const Vertex& b, const Vertex& c, int px, int py, double margin = 0.05,
                      double vx = 0, double vy = 0, double vw = kW, double vh = kH);
  // The color at a pixel centre inside the triangle: barycentric interpolation (w = 1: linear), as RGBA8.
  static std::array<double, 4> interpolate(const Vertex& a, const Vertex& b, const Vertex& c, int px, int py);
  static uint32_t rgba8(double r, double g, double b, double a) {
    auto q = [](double v) { return uint32_t(std::lround(std::fmin(std::fmax(v, 0.0), 1.0) * 255.0)); };
    return q(r) | q(g) << 8 | q(b) << 16 | q(a) << 24;
  }
  // Compares two RGBA8 pixels within `tolerance` per channel.
  static bool near(uint32_t got, uint32_t want, int tolerance = 1) {
    for (int c = 0; c < 4; ++c) {
      const int g = int((got >> (8 * c)) & 0xFF), w = int((want >> (8 * c)) & 0xFF);
      if (std::abs(g - w) > tolerance) return false;
    }
    return true;
  }
  // Checks the image against a list of triangles drawn in order (later ones over earlier ones) with flat colors
  // (interpolated when `smooth`), outside all of them `background`. Returns the number of mismatches (and logs the
  // first few).
  int compareTriangles(const std::vector<uint32_t>& pixels, const std::vector<std::array<Vertex, 3>>& tris,
                       uint32_t background, bool smooth = true);

  // A device command by name (an extension's EXT/KHR alias), expected to resolve.
  template <class F>
  F deviceProc(const char* name) {
    auto f = reinterpret_cast<F>(vkGetDeviceProcAddr(device, name));
    EXPECT_NE(f, nullptr) << name;
    return f;
  }

  VkPipelineLayout layout = VK_NULL_HANDLE;
  std::vector<VkShaderModule> modules;
  void TearDown() override;
};

// Four small triangles, one per quadrant (quadrant q is vertices 3q .. 3q + 2; the index buffer holds 0 .. 11),
// drawn by a vertex shader that takes the position at location 0 (R32G32_SFLOAT) and writes a color draw_flat.frag
// takes flat: the fixture of the draw tests whose colors tell which draw, record or instance drew each triangle.
class QuadrantDrawTest : public DrawTest {
 protected:
  // From the test's SetUp, after DrawTest::SetUp.
  void setUpQuadrants(const uint32_t* vs, size_t vsBytes);
  void TearDown() override;
  // Binds the pipeline, the vertex buffer and the index buffer.
  void bind(VkCommandBuffer cb);

  VkPipeline pipeline = VK_NULL_HANDLE;
  Target color;
  HostBuffer vb, ib;
  std::array<Vertex, 3> quads[4];  // each quadrant's triangle, black
};

}  // namespace vkrt::test
