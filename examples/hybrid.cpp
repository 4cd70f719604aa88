// hybrid: rasterization and ray tracing in one frame. A scene of boxes on a floor is rasterized with a depth buffer
// (a graphics pipeline: vertex buffer, depth test, a render pass); its fragment shader finds each pixel's shadow
// with a ray query against the scene's acceleration structure and draws one-pixel grid lines on the floor from
// screen-space derivatives; a second pipeline blends a translucent band over the top of the image in the same
// render pass. The image is copied to a buffer and written as a PNG.
//
//   VK_DRIVER_FILES=<build>/vkrt_icd.json ./hybrid [--width W] [--height H] [--out file.png] [--check]
//
// --check compares the image with a reference computed here on the CPU (brute-force ray casting of the same scene
// and the same shading; pixels whose value changes within a fraction of a pixel, at edges, shadow boundaries and
// grid lines, are skipped) and exits with 1 when a pixel differs by more than 3/255.
//
// Plain Vulkan through the loader: it runs unchanged on any driver with VK_KHR_ray_query.
#include <vulkan/vulkan.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>

#include "example_vk.hpp"
#include "hybrid.frag.spv.h"
#include "hybrid.vert.spv.h"
#include "mesh.hpp"
#include "overlay.frag.spv.h"
#include "overlay.vert.spv.h"

namespace {

using example::Buffer;
using example::Built;
using example::Context;
using example::fail;
using example::Image;
using example::Mesh;

// ------------------------------------------------------------------------------------------------- vectors

struct Vec3 {
  float x = 0, y = 0, z = 0;
};
Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
Vec3 operator*(Vec3 a, float s) { return {a.x * s, a.y * s, a.z * s}; }
float dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
Vec3 cross(Vec3 a, Vec3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
Vec3 normalize(Vec3 a) { return a * (1.0f / std::sqrt(dot(a, a))); }

// ------------------------------------------------------------------------------------------------- the scene

const float kAlbedo[][3] = {{0.8f, 0.8f, 0.76f}, {0.8f, 0.15f, 0.12f}, {0.15f, 0.35f, 0.85f}, {0.9f, 0.72f, 0.12f}};
const Vec3 kToLight = normalize({-0.45f, 0.8f, 0.4f});
const Vec3 kEye = {5.5f, 4.5f, 7.5f}, kTarget = {0.0f, 0.7f, 0.0f};
const float kFovY = 0.7854f;                           // 45 degrees
const float kAmbient = 0.25f;                          // as in hybrid.frag
const float kOverlay[4] = {0.05f, 0.08f, 0.2f, 0.6f};  // as in overlay.frag
const float kOverlayRows = 0.125f;                     // the band's height, a fraction of the image (overlay.vert)

// The floor and three boxes, in world space (one bottom-level structure, one instance).
Mesh scene() {
  Mesh m;
  const float f = 6;
  const float a[3] = {-f, 0, f}, b[3] = {f, 0, f}, c[3] = {f, 0, -f}, d[3] = {-f, 0, -f};
  m.quad(a, b, c, d, 0);
  struct Box {
    float sx, sy, sz, x, z;
    uint32_t material;
  };
  for (const Box& box : {Box{1.5f, 2.0f, 1.5f, -1.2f, -0.5f, 1}, Box{1.0f, 1.0f, 1.0f, 1.5f, 0.8f, 2},
                         Box{0.8f, 3.0f, 0.8f, 0.5f, -2.5f, 3}}) {
    Mesh one;
    one.box(box.sx, box.sy, box.sz, box.material);
    const uint32_t base = uint32_t(m.vertices.size() / 3);
    for (size_t i = 0; i < one.vertices.size(); i += 3)
      m.vertices.insert(m.vertices.end(), {one.vertices[i] + box.x, one.vertices[i + 1], one.vertices[i + 2] + box.z});
    for (uint32_t i : one.indices) m.indices.push_back(base + i);
    m.triangles.insert(m.triangles.end(), one.triangles.begin(), one.triangles.end());
  }
  return m;
}

Vec3 vertexOf(const Mesh& m, uint32_t i) { return {m.vertices[3 * i], m.vertices[3 * i + 1], m.vertices[3 * i + 2]}; }

// The vertex buffer: three vertices per triangle, each position, unit normal and albedo (9 floats).
std::vector<float> vertexStream(const Mesh& m) {
  std::vector<float> out;
  for (size_t t = 0; t < m.indices.size() / 3; ++t) {
    const Vec3 n = normalize({m.triangles[4 * t], m.triangles[4 * t + 1], m.triangles[4 * t + 2]});
    const float* albedo = kAlbedo[uint32_t(m.triangles[4 * t + 3])];
    for (int k = 0; k < 3; ++k) {
      const Vec3 p = vertexOf(m, m.indices[3 * t + k]);
      out.insert(out.end(), {p.x, p.y, p.z, n.x, n.y, n.z, albedo[0], albedo[1], albedo[2]});
    }
  }
  return out;
}

// The camera: an orthonormal frame and the view-projection matrix (column-major, Vulkan's clip space: y down,
// depth 0 at the near plane).
struct Camera {
  Vec3 forward, right, up;
  float tanHalf, aspect;
  std::array<float, 16> viewProjection;
};

Camera camera(uint32_t width, uint32_t height) {
  Camera c;
  c.forward = normalize(kTarget - kEye);
  c.right = normalize(cross(c.forward, {0, 1, 0}));
  c.up = cross(c.right, c.forward);
  c.tanHalf = std::tan(kFovY / 2);
  c.aspect = float(width) / float(height);
  const float nearZ = 0.1f, farZ = 100.0f;
  // Rows of view-projection: clip = P * V * p.
  const float sx = 1 / (c.tanHalf * c.aspect), sy = 1 / c.tanHalf;
  const float a = farZ / (nearZ - farZ), b = nearZ * farZ / (nearZ - farZ);
  const Vec3 rows[3] = {c.right, c.up, c.forward * -1.0f};  // view space: x right, y up, z towards the viewer
  float view[3][4];
  for (int r = 0; r < 3; ++r) {
    view[r][0] = rows[r].x;
    view[r][1] = rows[r].y;
    view[r][2] = rows[r].z;
    view[r][3] = -dot(rows[r], kEye);
  }
  float m[4][4];  // m[row][column]
  for (int k = 0; k < 4; ++k) {
    m[0][k] = sx * view[0][k];
    m[1][k] = -sy * view[1][k];  // Vulkan's y points down
    m[2][k] = a * view[2][k] + (k == 3 ? b : 0);
    m[3][k] = -view[2][k];
  }
  for (int col = 0; col < 4; ++col)
    for (int row = 0; row < 4; ++row) c.viewProjection[size_t(col * 4 + row)] = m[row][col];
  return c;
}

// ------------------------------------------------------------------------------------------------- the CPU reference

// The nearest triangle a ray meets (Moeller-Trumbore), or -1.
int nearest(const Mesh& m, Vec3 o, Vec3 d, float tMin, float* tHit) {
  int best = -1;
  float bestT = 1e30f;
  for (size_t t = 0; t < m.indices.size() / 3; ++t) {
    const Vec3 p0 = vertexOf(m, m.indices[3 * t]), p1 = vertexOf(m, m.indices[3 * t + 1]),
               p2 = vertexOf(m, m.indices[3 * t + 2]);
    const Vec3 e1 = p1 - p0, e2 = p2 - p0, pv = cross(d, e2);
    const float det = dot(e1, pv);
    if (std::fabs(det) < 1e-12f) continue;
    const Vec3 tv = o - p0;
    const float u = dot(tv, pv) / det;
    if (u < 0 || u > 1) continue;
    const Vec3 qv = cross(tv, e1);
    const float v = dot(d, qv) / det;
    if (v < 0 || u + v > 1) continue;
    const float tt = dot(e2, qv) / det;
    if (tt > tMin && tt < bestT) {
      bestT = tt;
      best = int(t);
    }
  }
  *tHit = bestT;
  return best;
}

struct Shade {
  float rgb[3] = {0, 0, 0};
  bool floorLine = false;   // within about two pixels of a grid line (the derivative-dependent term): not compared
  bool lineCentre = false;  // on a grid line: darker than `rgb` (0.45 of it in the shader)
};

const float kSky[3] = {0.6f, 0.75f, 0.95f};

// The colour of the ray through framebuffer position (fx, fy), as hybrid.frag and overlay.frag compute it.
Shade reference(const Mesh& m, const Camera& c, uint32_t width, uint32_t height, float fx, float fy) {
  Shade s;
  const float nx = fx / float(width) * 2 - 1, ny = fy / float(height) * 2 - 1;
  const Vec3 d = normalize(c.forward + c.right * (nx * c.tanHalf * c.aspect) - c.up * (ny * c.tanHalf));
  float t;
  const int tri = nearest(m, kEye, d, 0.1f, &t);
  if (tri < 0) {
    std::copy(kSky, kSky + 3, s.rgb);
  } else {
    const Vec3 n =
        normalize({m.triangles[4 * size_t(tri)], m.triangles[4 * size_t(tri) + 1], m.triangles[4 * size_t(tri) + 2]});
    const Vec3 p = kEye + d * t;
    float diffuse = std::max(dot(n, kToLight), 0.0f);
    float shadowT;
    if (diffuse > 0 && nearest(m, p + n * 1e-3f, kToLight, 1e-3f, &shadowT) >= 0) diffuse = 0;
    const float* albedo = kAlbedo[uint32_t(m.triangles[4 * size_t(tri) + 3])];
    if (n.y > 0.9f && p.y < 1e-3f) {
      // The grid lines need fwidth: the distance to the nearest line in units of the per-pixel change of x and z,
      // estimated here from the neighbouring pixels' rays. Near a line the pixel is not compared; away from lines
      // the line factor is 1.
      const Vec3 dx = normalize(c.forward + c.right * ((nx + 2.0f / float(width)) * c.tanHalf * c.aspect) -
                                c.up * (ny * c.tanHalf));
      const Vec3 dy = normalize(c.forward + c.right * (nx * c.tanHalf * c.aspect) -
                                c.up * ((ny + 2.0f / float(height)) * c.tanHalf));
      if (dx.y >= 0 || dy.y >= 0) {
        s.floorLine = true;
      } else {
        const Vec3 px = kEye + dx * (-kEye.y / dx.y), py = kEye + dy * (-kEye.y / dy.y);
        const float wx = std::fabs(px.x - p.x) + std::fabs(py.x - p.x);
        const float wz = std::fabs(px.z - p.z) + std::fabs(py.z - p.z);
        const float cell =
            std::min(std::fabs(p.x - std::floor(p.x) - 0.5f) / wx, std::fabs(p.z - std::floor(p.z) - 0.5f) / wz);
        s.floorLine = cell < 2.5f;
        s.lineCentre = cell < 0.25f;
      }
    }
    for (int k = 0; k < 3; ++k) s.rgb[k] = albedo[k] * (kAmbient + (1 - kAmbient) * diffuse);
  }
  if (fy < kOverlayRows * float(height))
    for (int k = 0; k < 3; ++k) s.rgb[k] = kOverlay[k] * kOverlay[3] + s.rgb[k] * (1 - kOverlay[3]);
  return s;
}

// Compares the image with the reference; returns the number of differing pixels (and prints the first few).
uint32_t check(const Mesh& m, const Camera& c, uint32_t width, uint32_t height, const uint8_t* rgba) {
  uint32_t compared = 0, differ = 0, lines = 0, lineCentres = 0, linesDarker = 0;
  for (uint32_t y = 0; y < height; ++y)
    for (uint32_t x = 0; x < width; ++x) {
      const float fx = float(x) + 0.5f, fy = float(y) + 0.5f;
      const Shade centre = reference(m, c, width, height, fx, fy);
      const uint8_t* got = rgba + 4 * (size_t(y) * width + x);
      if (centre.floorLine) {
        // The lines come from fwidth: on a line's centre the floor is darker than the line-free reference.
        ++lines;
        if (centre.lineCentre) {
          ++lineCentres;
          bool darker = true;
          for (int k = 0; k < 3; ++k) darker = darker && got[k] / 255.0f < 0.8f * centre.rgb[k];
          linesDarker += darker;
        }
        continue;
      }
      bool stable = true;
      for (float o : {-0.35f, 0.35f})
        for (int axis = 0; axis < 2 && stable; ++axis) {
          const Shade s = reference(m, c, width, height, fx + (axis == 0 ? o : 0), fy + (axis == 1 ? o : 0));
          if (s.floorLine) stable = false;
          for (int k = 0; k < 3; ++k) stable = stable && std::fabs(s.rgb[k] - centre.rgb[k]) < 1.0f / 255;
        }
      if (!stable || std::fabs(fy - kOverlayRows * float(height)) < 1.0f) continue;
      ++compared;
      bool same = true;
      for (int k = 0; k < 3; ++k) same = same && std::fabs(got[k] / 255.0f - centre.rgb[k]) <= 3.0f / 255;
      if (!same && differ++ < 8)
        std::fprintf(stderr, "hybrid: pixel (%u, %u) is %u %u %u, the reference %.0f %.0f %.0f\n", x, y, got[0], got[1],
                     got[2], centre.rgb[0] * 255, centre.rgb[1] * 255, centre.rgb[2] * 255);
    }
  std::printf(
      "hybrid: --check compared %u of %u pixels (%u near grid lines skipped): %u differ; %u of %u pixels on grid "
      "lines darker\n",
      compared, width * height, lines, differ, linesDarker, lineCentres);
  if (linesDarker * 4 < lineCentres * 3) {
    std::fprintf(stderr, "hybrid: the grid lines (fwidth) are missing\n");
    return differ + 1;
  }
  if (compared < width * height / 2) {
    std::fprintf(stderr, "hybrid: too few pixels comparable\n");
    return differ + 1;
  }
  return differ;
}

// ------------------------------------------------------------------------------------------------- Vulkan

void createDevice(Context& c) {
  VkPhysicalDeviceRayQueryFeaturesKHR rq{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR};
  rq.rayQuery = VK_TRUE;
  VkPhysicalDeviceAccelerationStructureFeaturesKHR asf{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR, &rq};
  asf.accelerationStructure = VK_TRUE;
  VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES, &asf};
  f12.bufferDeviceAddress = VK_TRUE;
  // The ray tracing pipeline extension only for example::Context's entry points (it loads them all).
  c.open(VK_QUEUE_GRAPHICS_BIT, &f12,
         {VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME, VK_KHR_RAY_QUERY_EXTENSION_NAME,
          VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME, VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME});
}

Built buildScene(Context& c, const Mesh& m) {
  VkAccelerationStructureGeometryKHR g{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
  g.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
  g.flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
  auto& t = g.geometry.triangles;
  t.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
  t.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
  t.vertexData.deviceAddress =
      c.upload(m.vertices, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR).address;
  t.vertexStride = 12;
  t.maxVertex = uint32_t(m.vertices.size() / 3 - 1);
  t.indexType = VK_INDEX_TYPE_UINT32;
  t.indexData.deviceAddress =
      c.upload(m.indices, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR).address;
  Built blas = c.build(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {g}, {uint32_t(m.indices.size() / 3)});
  VkAccelerationStructureInstanceKHR in{};
  in.transform.matrix[0][0] = in.transform.matrix[1][1] = in.transform.matrix[2][2] = 1;
  in.mask = 0xff;
  in.accelerationStructureReference = blas.address;
  return c.buildTopLevel({in});
}

constexpr VkFormat kColorFormat = VK_FORMAT_R8G8B8A8_UNORM;
constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;

struct Pipelines {
  VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkPipeline scene = VK_NULL_HANDLE, overlay = VK_NULL_HANDLE;
};

struct FramePush {
  float viewProjection[16];
  float toLight[4];
};

Pipelines createPipelines(Context& c, VkRenderPass rp, uint32_t width, uint32_t height) {
  Pipelines p;
  VkDescriptorSetLayoutBinding b{0, VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 1, VK_SHADER_STAGE_FRAGMENT_BIT};
  VkDescriptorSetLayoutCreateInfo dl{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  dl.bindingCount = 1;
  dl.pBindings = &b;
  CHECK(vkCreateDescriptorSetLayout(c.device, &dl, nullptr, &p.setLayout));
  VkPushConstantRange push{VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof(FramePush)};
  VkPipelineLayoutCreateInfo pl{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  pl.setLayoutCount = 1;
  pl.pSetLayouts = &p.setLayout;
  pl.pushConstantRangeCount = 1;
  pl.pPushConstantRanges = &push;
  CHECK(vkCreatePipelineLayout(c.device, &pl, nullptr, &p.layout));

  VkShaderModule sceneVs = c.shaderModule(kSpv_hybrid_vert, sizeof kSpv_hybrid_vert);
  VkShaderModule sceneFs = c.shaderModule(kSpv_hybrid_frag, sizeof kSpv_hybrid_frag);
  VkShaderModule overlayVs = c.shaderModule(kSpv_overlay_vert, sizeof kSpv_overlay_vert);
  VkShaderModule overlayFs = c.shaderModule(kSpv_overlay_frag, sizeof kSpv_overlay_frag);

  VkPipelineShaderStageCreateInfo stages[2] = {{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO},
                                               {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO}};
  stages[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
  stages[0].pName = "main";
  stages[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
  stages[1].pName = "main";

  VkVertexInputBindingDescription binding{0, 9 * sizeof(float), VK_VERTEX_INPUT_RATE_VERTEX};
  VkVertexInputAttributeDescription attrs[3] = {{0, 0, VK_FORMAT_R32G32B32_SFLOAT, 0},
                                                {1, 0, VK_FORMAT_R32G32B32_SFLOAT, 12},
                                                {2, 0, VK_FORMAT_R32G32B32_SFLOAT, 24}};
  VkPipelineVertexInputStateCreateInfo vi{VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
  VkPipelineInputAssemblyStateCreateInfo ia{VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
  VkViewport viewport{0, 0, float(width), float(height), 0, 1};
  VkRect2D scissor{{0, 0}, {width, height}};
  VkPipelineViewportStateCreateInfo vp{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
  vp.viewportCount = 1;
  vp.pViewports = &viewport;
  vp.scissorCount = 1;
  vp.pScissors = &scissor;
  VkPipelineRasterizationStateCreateInfo rs{VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
  rs.polygonMode = VK_POLYGON_MODE_FILL;
  rs.lineWidth = 1;
  VkPipelineMultisampleStateCreateInfo ms{VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
  ms.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
  VkPipelineDepthStencilStateCreateInfo ds{VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
  VkPipelineColorBlendAttachmentState blend{};
  blend.colorWriteMask = 0xF;
  VkPipelineColorBlendStateCreateInfo cb{VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
  cb.attachmentCount = 1;
  cb.pAttachments = &blend;
  VkGraphicsPipelineCreateInfo gp{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
  gp.stageCount = 2;
  gp.pStages = stages;
  gp.pVertexInputState = &vi;
  gp.pInputAssemblyState = &ia;
  gp.pViewportState = &vp;
  gp.pRasterizationState = &rs;
  gp.pMultisampleState = &ms;
  gp.pDepthStencilState = &ds;
  gp.pColorBlendState = &cb;
  gp.layout = p.layout;
  gp.renderPass = rp;

  // The scene: triangles from the vertex buffer, back faces culled, depth tested and written.
  stages[0].module = sceneVs;
  stages[1].module = sceneFs;
  vi.vertexBindingDescriptionCount = 1;
  vi.pVertexBindingDescriptions = &binding;
  vi.vertexAttributeDescriptionCount = 3;
  vi.pVertexAttributeDescriptions = attrs;
  ia.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
  rs.cullMode = VK_CULL_MODE_BACK_BIT;
  rs.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
  ds.depthTestEnable = VK_TRUE;
  ds.depthWriteEnable = VK_TRUE;
  ds.depthCompareOp = VK_COMPARE_OP_LESS;
  CHECK(vkCreateGraphicsPipelines(c.device, VK_NULL_HANDLE, 1, &gp, nullptr, &p.scene));

  // The overlay: a strip from the vertex index, no depth test, blended over the scene.
  stages[0].module = overlayVs;
  stages[1].module = overlayFs;
  vi.vertexBindingDescriptionCount = 0;
  vi.vertexAttributeDescriptionCount = 0;
  ia.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_STRIP;
  rs.cullMode = VK_CULL_MODE_NONE;
  ds.depthTestEnable = VK_FALSE;
  ds.depthWriteEnable = VK_FALSE;
  blend.blendEnable = VK_TRUE;
  blend.srcColorBlendFactor = VK_BLEND_FACTOR_SRC_ALPHA;
  blend.dstColorBlendFactor = VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA;
  blend.colorBlendOp = VK_BLEND_OP_ADD;
  blend.srcAlphaBlendFactor = VK_BLEND_FACTOR_ONE;
  blend.dstAlphaBlendFactor = VK_BLEND_FACTOR_ZERO;
  blend.alphaBlendOp = VK_BLEND_OP_ADD;
  CHECK(vkCreateGraphicsPipelines(c.device, VK_NULL_HANDLE, 1, &gp, nullptr, &p.overlay));

  for (VkShaderModule m : {sceneVs, sceneFs, overlayVs, overlayFs}) vkDestroyShaderModule(c.device, m, nullptr);
  return p;
}

}  // namespace

int main(int argc, char** argv) {
  example::gProgram = "hybrid";
  uint32_t width = 800, height = 600;
  std::string out = "hybrid.png";
  bool doCheck = false, bad = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--check") {
      doCheck = true;
    } else if (i + 1 < argc && a == "--width") {
      width = uint32_t(std::atoi(argv[++i]));
    } else if (i + 1 < argc && a == "--height") {
      height = uint32_t(std::atoi(argv[++i]));
    } else if (i + 1 < argc && a == "--out") {
      out = argv[++i];
    } else {
      bad = true;
    }
  }
  if (bad || width == 0 || height == 0 || width > 8192 || height > 8192) {
    std::fprintf(stderr, "usage: hybrid [--width W] [--height H] [--out file.png] [--check]\n");
    return 2;
  }

  Context c;
  createDevice(c);
  const auto t0 = std::chrono::steady_clock::now();
  const Mesh mesh = scene();
  const Built tlas = buildScene(c, mesh);
  const std::vector<float> stream = vertexStream(mesh);
  Buffer vertices = c.upload(stream, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
  // One colour and one depth attachment; the colour image ends ready to be copied.
  VkRenderPass rp = example::createColorDepthRenderPass(c.device, kColorFormat, kDepthFormat);
  Pipelines p = createPipelines(c, rp, width, height);
  const Image color = example::createImage(c.device, c.physical, kColorFormat, width, height, 1,
                                           VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                                           VK_IMAGE_ASPECT_COLOR_BIT);
  const Image depth = example::createImage(c.device, c.physical, kDepthFormat, width, height, 1,
                                           VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT, VK_IMAGE_ASPECT_DEPTH_BIT);
  VkFramebuffer fb = example::createFramebuffer(c.device, rp, color.view, depth.view, width, height);

  VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 1};
  VkDescriptorPoolCreateInfo dpci{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  dpci.maxSets = 1;
  dpci.poolSizeCount = 1;
  dpci.pPoolSizes = &size;
  VkDescriptorPool pool;
  CHECK(vkCreateDescriptorPool(c.device, &dpci, nullptr, &pool));
  VkDescriptorSetAllocateInfo dai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  dai.descriptorPool = pool;
  dai.descriptorSetCount = 1;
  dai.pSetLayouts = &p.setLayout;
  VkDescriptorSet set;
  CHECK(vkAllocateDescriptorSets(c.device, &dai, &set));
  VkWriteDescriptorSetAccelerationStructureKHR asw{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_KHR};
  asw.accelerationStructureCount = 1;
  asw.pAccelerationStructures = &tlas.as;
  VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, &asw};
  w.dstSet = set;
  w.descriptorCount = 1;
  w.descriptorType = VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR;
  vkUpdateDescriptorSets(c.device, 1, &w, 0, nullptr);

  Buffer readBack = c.buffer(uint64_t(width) * height * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
  const Camera cam = camera(width, height);
  FramePush push{};
  std::memcpy(push.viewProjection, cam.viewProjection.data(), sizeof push.viewProjection);
  push.toLight[0] = kToLight.x;
  push.toLight[1] = kToLight.y;
  push.toLight[2] = kToLight.z;
  const auto t1 = std::chrono::steady_clock::now();

  VkCommandBuffer cb = c.begin();
  VkClearValue clears[2] = {};
  std::memcpy(clears[0].color.float32, kSky, sizeof kSky);
  clears[0].color.float32[3] = 1;
  clears[1].depthStencil = {1.0f, 0};
  VkRenderPassBeginInfo rbi{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
  rbi.renderPass = rp;
  rbi.framebuffer = fb;
  rbi.renderArea = {{0, 0}, {width, height}};
  rbi.clearValueCount = 2;
  rbi.pClearValues = clears;
  vkCmdBeginRenderPass(cb, &rbi, VK_SUBPASS_CONTENTS_INLINE);
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, p.scene);
  vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, p.layout, 0, 1, &set, 0, nullptr);
  vkCmdPushConstants(cb, p.layout, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof push, &push);
  VkDeviceSize offset = 0;
  vkCmdBindVertexBuffers(cb, 0, 1, &vertices.buffer, &offset);
  vkCmdDraw(cb, uint32_t(stream.size() / 9), 1, 0, 0);
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, p.overlay);
  vkCmdDraw(cb, 4, 1, 0, 0);
  vkCmdEndRenderPass(cb);
  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.imageExtent = {width, height, 1};
  vkCmdCopyImageToBuffer(cb, color.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readBack.buffer, 1, &region);
  VkMemoryBarrier toHost{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  toHost.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  toHost.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &toHost, 0, nullptr, 0,
                       nullptr);
  c.submit(cb);
  const auto t2 = std::chrono::steady_clock::now();

  const uint8_t* rgba = static_cast<const uint8_t*>(readBack.data);
  int status = 0;
  if (!stbi_write_png(out.c_str(), int(width), int(height), 4, rgba, int(width * 4))) {
    std::fprintf(stderr, "hybrid: could not write %s\n", out.c_str());
    status = 1;
  }
  std::printf(
      "hybrid: %ux%u, %zu triangles rasterized with ray query shadows and an overlay in %.3f s; set-up %.3f s\n", width,
      height, mesh.indices.size() / 3, std::chrono::duration<double>(t2 - t1).count(),
      std::chrono::duration<double>(t1 - t0).count());
  if (status == 0) std::printf("hybrid: wrote %s\n", out.c_str());
  if (doCheck && check(mesh, cam, width, height, rgba) != 0) status = 1;

  vkDestroyFramebuffer(c.device, fb, nullptr);
  example::destroyImage(c.device, color);
  example::destroyImage(c.device, depth);
  vkDestroyRenderPass(c.device, rp, nullptr);
  vkDestroyPipeline(c.device, p.scene, nullptr);
  vkDestroyPipeline(c.device, p.overlay, nullptr);
  vkDestroyPipelineLayout(c.device, p.layout, nullptr);
  vkDestroyDescriptorSetLayout(c.device, p.setLayout, nullptr);
  vkDestroyDescriptorPool(c.device, pool, nullptr);
  c.destroy();
  return status;
}
