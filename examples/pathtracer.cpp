// pathtracer: a small Vulkan path tracer. It renders a glTF 2.0 model (loaded with tinygltf) or a built-in Cornell
// box with analytic spheres, and writes the image as a PNG.
//
//   VK_DRIVER_FILES=<build>/vkrt_icd.json ./pathtracer [--scene cornell|file.glb|file.gltf] [--width W]
//       [--height H] [--spp N] [--bounces N] [--seed S] [--out file.png] [--printf 1]
//
// What it uses of the ray tracing pipeline extensions:
// - the pipeline is linked from three pipeline libraries (VK_KHR_pipeline_library): the ray generation and miss
//   shaders, the hit groups, and the materials (callable shaders);
// - the shader binding table is written from the libraries' own group handles
//   (VK_EXT_pipeline_library_group_handles), after checking that they equal the linked pipeline's;
// - a material is a callable shader that samples its BSDF (diffuse, metal, glass);
// - alpha-tested triangles (glTF alphaMode MASK, and the Cornell box's panel with round holes) run an any-hit
//   shader; the spheres are boxes with an intersection shader;
// - the pipeline stack size is dynamic state, set from vkGetRayTracingShaderGroupStackSizeKHR with the
//   specification's formula.
// It renders in passes of a few samples per pixel (one submission each, with a progress bar on a terminal), counts
// the rays it traces in a buffer (one count per pixel, written by the ray generation shader), and prints Mrays/s.
// The image depends only on the scene, the options and the seed (the random numbers are a function of the pixel,
// the sample index and the seed), not on the driver's scheduling or the pass size.
//
// Plain Vulkan through the loader: it runs unchanged on any driver with the extensions above.
#include <tiny_gltf.h>
#include <unistd.h>
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
#include "gltf_util.hpp"
#include "pt.rgen.spv.h"
#include "pt.rmiss.spv.h"
#include "pt_alpha.rahit.spv.h"
#include "pt_diffuse.rcall.spv.h"
#include "pt_glass.rcall.spv.h"
#include "pt_metal.rcall.spv.h"
#include "pt_shadow.rmiss.spv.h"
#include "pt_sphere.rchit.spv.h"
#include "pt_sphere.rint.spv.h"
#include "pt_triangle.rchit.spv.h"
#include "runtime/vk_compat.h"  // tokens newer than Debian 12's Vulkan headers (VK_EXT_pipeline_library_group_handles)

namespace {

using example::Buffer;
using example::Built;
using example::Context;
using example::fail;
using gltf::Mat4;
using gltf::mul;
using gltf::nodeMatrix;
using gltf::readComponent;
using gltf::readIndex;

// ------------------------------------------------------------------------------------- scene tables (pt.glsl)

struct Vec3 {
  float x = 0, y = 0, z = 0;
  Vec3 operator+(Vec3 o) const { return {x + o.x, y + o.y, z + o.z}; }
  Vec3 operator-(Vec3 o) const { return {x - o.x, y - o.y, z - o.z}; }
  Vec3 operator*(float s) const { return {x * s, y * s, z * s}; }
};
Vec3 cross(Vec3 a, Vec3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
float dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
Vec3 normalize(Vec3 a) { return a * (1.0f / std::sqrt(dot(a, a))); }

struct Vertex {
  float position[3], u, normal[3], v;
};
struct Geometry {
  uint32_t firstIndex, vertexOffset, material, pad;
};
enum Kind : uint32_t { kDiffuse = 0, kMetal = 1, kGlass = 2, kKinds = 3 };
struct Material {
  float baseColor[4] = {0.8f, 0.8f, 0.8f, 1};
  float emission[4] = {0, 0, 0, 0};
  int32_t texture = -1;
  uint32_t kind = kDiffuse;
  uint32_t alphaMode = 0;  // 0 opaque, 1 glTF MASK, 2 procedural cutout
  float alphaCutoff = 0.5f;
  float roughness = 0;
  float ior = 1.5f;
  uint32_t sampledLight = 0;  // the quad light: next-event estimation samples it
  float pad = 0;
};
struct TextureInfo {
  uint32_t offset, width, height, pad;
};
struct Sphere {
  float centerRadius[4];
  uint32_t material, pad[3];
};
struct SceneInfo {
  float cameraOrigin[4], cameraForward[4], cameraRight[4], cameraUp[4];
  float lightCorner[4], lightEdge1[4], lightEdge2[4], lightEmission[4];
  float sunDirection[4], sunColor[4], skyZenith[4], skyHorizon[4];
  float params[4];
};
static_assert(sizeof(Vertex) == 32 && sizeof(Material) == 64 && sizeof(Sphere) == 32 && sizeof(SceneInfo) == 208);

void set4(float* d, Vec3 v, float w) {
  d[0] = v.x;
  d[1] = v.y;
  d[2] = v.z;
  d[3] = w;
}

// A triangle mesh: one bottom-level structure, one geometry per part (a glTF primitive), placed by instances.
struct MeshPart {
  uint32_t firstIndex, indexCount, vertexOffset, vertexCount, material;
};
struct Mesh {
  std::vector<MeshPart> parts;
};
struct Placement {
  uint32_t mesh;
  float transform[3][4];
};

struct Scene {
  std::vector<Vertex> vertices;
  std::vector<uint32_t> indices;
  std::vector<Material> materials;
  std::vector<TextureInfo> textures;
  std::vector<uint32_t> texels;
  std::vector<Sphere> spheres;
  std::vector<Mesh> meshes;
  std::vector<Placement> placements;
  SceneInfo info{};

  uint32_t material(const Material& m) {
    materials.push_back(m);
    return uint32_t(materials.size() - 1);
  }
  // Appends a part made of the given vertices and triangles to mesh `mesh`.
  void part(uint32_t mesh, const std::vector<Vertex>& v, const std::vector<uint32_t>& idx, uint32_t material) {
    MeshPart p{uint32_t(indices.size()), uint32_t(idx.size()), uint32_t(vertices.size()), uint32_t(v.size()), material};
    vertices.insert(vertices.end(), v.begin(), v.end());
    indices.insert(indices.end(), idx.begin(), idx.end());
    meshes[mesh].parts.push_back(p);
  }
  // A quad a b c d (counter-clockwise seen from the side its normal points to), texture coordinates 0..1.
  void quad(uint32_t mesh, Vec3 a, Vec3 b, Vec3 c, Vec3 d, uint32_t material) {
    Vec3 n = normalize(cross(b - a, d - a));
    const Vec3 p[4] = {a, b, c, d};
    const float uv[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    std::vector<Vertex> v(4);
    for (int k = 0; k < 4; ++k) v[k] = {{p[k].x, p[k].y, p[k].z}, uv[k][0], {n.x, n.y, n.z}, uv[k][1]};
    part(mesh, v, {0, 1, 2, 0, 2, 3}, material);
  }
  void camera(Vec3 origin, Vec3 target, float fovY) {
    Vec3 f = normalize(target - origin), r = normalize(cross(f, {0, 1, 0})), u = cross(r, f);
    set4(info.cameraOrigin, origin, std::tan(fovY / 2));
    set4(info.cameraForward, f, 0);
    set4(info.cameraRight, r, 0);
    set4(info.cameraUp, u, 0);
  }
};

const float kIdentity[3][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}};

// The Cornell box: a 2 x 2 x 2 room (x -1..1, y 0..2, z -1..1, open towards the camera at +z) with a red left and
// a green right wall, a quad light under the ceiling, a glass and a metal sphere (intersection shader) and a panel
// with round holes (any-hit shader) in front of the back wall.
Scene cornell() {
  Scene s;
  s.meshes.resize(1);
  Material white, red, green, light, panel, glass, metal;
  set4(white.baseColor, {0.73f, 0.73f, 0.73f}, 1);
  set4(red.baseColor, {0.65f, 0.05f, 0.05f}, 1);
  set4(green.baseColor, {0.12f, 0.45f, 0.15f}, 1);
  set4(light.baseColor, {0.78f, 0.78f, 0.78f}, 1);
  set4(light.emission, {17.0f, 12.0f, 4.0f}, 0);
  light.sampledLight = 1;
  set4(panel.baseColor, {0.85f, 0.65f, 0.15f}, 1);
  panel.alphaMode = 2;
  set4(glass.baseColor, {0.98f, 0.98f, 0.98f}, 1);
  glass.kind = kGlass;
  set4(metal.baseColor, {0.85f, 0.85f, 0.88f}, 1);
  metal.kind = kMetal;
  metal.roughness = 0.08f;
  const uint32_t mWhite = s.material(white), mRed = s.material(red), mGreen = s.material(green),
                 mLight = s.material(light), mPanel = s.material(panel), mGlass = s.material(glass),
                 mMetal = s.material(metal);
  const Vec3 f[8] = {{-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, {-1, 0, -1}, {-1, 2, 1}, {1, 2, 1}, {1, 2, -1}, {-1, 2, -1}};
  s.quad(0, f[0], f[1], f[2], f[3], mWhite);  // floor, normal up
  s.quad(0, f[7], f[6], f[5], f[4], mWhite);  // ceiling, normal down
  s.quad(0, f[3], f[2], f[6], f[7], mWhite);  // back wall, normal +z
  s.quad(0, f[0], f[3], f[7], f[4], mRed);    // left wall, normal +x
  s.quad(0, f[2], f[1], f[5], f[6], mGreen);  // right wall, normal -x
  // The light: 0.5 x 0.5, just under the ceiling, facing down.
  const float h = 1.98f, e = 0.25f;
  s.quad(0, {-e, h, -e}, {e, h, -e}, {e, h, e}, {-e, h, e}, mLight);
  set4(s.info.lightCorner, {-e, h, -e}, 1);
  set4(s.info.lightEdge1, {2 * e, 0, 0}, 0);  // edge1 x edge2 points down, as the light faces
  set4(s.info.lightEdge2, {0, 0, 2 * e}, 0);
  set4(s.info.lightEmission, {17.0f, 12.0f, 4.0f}, 0);
  // The panel with holes, facing the camera.
  s.quad(0, {-0.15f, 0.7f, -0.6f}, {0.75f, 0.7f, -0.6f}, {0.75f, 1.6f, -0.6f}, {-0.15f, 1.6f, -0.6f}, mPanel);
  s.spheres.push_back({{0.45f, 0.35f, 0.35f, 0.35f}, mGlass, {}});
  s.spheres.push_back({{-0.45f, 0.4f, -0.3f, 0.4f}, mMetal, {}});
  Placement room{0, {}};
  std::memcpy(room.transform, kIdentity, sizeof kIdentity);
  s.placements.push_back(room);
  s.camera({0, 1, 3.9f}, {0, 1, 0}, 0.6981f);  // 40 degrees
  set4(s.info.params, {0.0005f, 1.0f, 0}, 0);
  return s;
}

// ------------------------------------------------------------------------------------------------------- glTF

// Loads a glTF 2.0 file (.glb or .gltf): every triangle primitive of the default scene's nodes, with base colour
// factors and textures, MASK alpha, emission and metal (metallicFactor >= 0.5). Adds a ground plane under the
// model, a sun and a sky, and a camera that frames the model.
Scene loadGltf(const std::string& path) {
  tinygltf::Model model = gltf::load(path);
  Scene s;
  // Textures: decoded by tinygltf (stb_image) into RGBA8.
  std::vector<int32_t> textureOf(model.textures.size(), -1);
  for (size_t t = 0; t < model.textures.size(); ++t) {
    const int src = model.textures[t].source;
    if (src < 0 || size_t(src) >= model.images.size()) continue;
    const tinygltf::Image& img = model.images[size_t(src)];
    if (img.width <= 0 || img.height <= 0 || img.bits != 8 || img.component < 1 || img.component > 4 ||
        img.image.size() < size_t(img.width) * size_t(img.height) * size_t(img.component))
      continue;
    TextureInfo ti{uint32_t(s.texels.size()), uint32_t(img.width), uint32_t(img.height), 0};
    for (size_t p = 0; p < size_t(img.width) * size_t(img.height); ++p) {
      const unsigned char* c = &img.image[p * size_t(img.component)];
      uint32_t r = c[0], g = img.component >= 3 ? c[1] : c[0], b = img.component >= 3 ? c[2] : c[0];
      uint32_t a = img.component == 4 ? c[3] : img.component == 2 ? c[1] : 255;
      s.texels.push_back(r | g << 8 | b << 16 | a << 24);
    }
    textureOf[t] = int32_t(s.textures.size());
    s.textures.push_back(ti);
  }
  for (const tinygltf::Material& gm : model.materials) {
    Material m;
    const auto& pbr = gm.pbrMetallicRoughness;
    for (int k = 0; k < 4 && size_t(k) < pbr.baseColorFactor.size(); ++k)
      m.baseColor[k] = float(pbr.baseColorFactor[size_t(k)]);
    if (pbr.baseColorTexture.index >= 0 && size_t(pbr.baseColorTexture.index) < textureOf.size())
      m.texture = textureOf[size_t(pbr.baseColorTexture.index)];
    for (int k = 0; k < 3 && size_t(k) < gm.emissiveFactor.size(); ++k)
      m.emission[k] = float(gm.emissiveFactor[size_t(k)]);
    if (gm.alphaMode == "MASK") {
      m.alphaMode = 1;
      m.alphaCutoff = float(gm.alphaCutoff);
    }
    if (pbr.metallicFactor >= 0.5) {
      m.kind = kMetal;
      m.roughness = float(pbr.roughnessFactor) * 0.5f;
    }
    s.materials.push_back(m);
  }
  const uint32_t defaultMaterial = s.material(Material{});
  // Meshes: one part per triangle primitive.
  size_t skipped = 0;
  for (const tinygltf::Mesh& gm : model.meshes) {
    s.meshes.emplace_back();
    const uint32_t mesh = uint32_t(s.meshes.size() - 1);
    for (const tinygltf::Primitive& prim : gm.primitives) {
      ++skipped;  // until the primitive is added
      if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != -1) continue;
      auto pos = prim.attributes.find("POSITION");
      if (pos == prim.attributes.end()) continue;
      const tinygltf::Accessor& pa = model.accessors.at(size_t(pos->second));
      if (pa.type != TINYGLTF_TYPE_VEC3 || pa.bufferView < 0) continue;
      std::vector<Vertex> v(pa.count);
      bool finite = true;
      for (size_t i = 0; i < pa.count; ++i)
        for (int c = 0; c < 3; ++c) finite &= std::isfinite(v[i].position[c] = readComponent(model, pa, i, c));
      if (!finite) continue;
      auto nor = prim.attributes.find("NORMAL");
      if (nor != prim.attributes.end()) {
        const tinygltf::Accessor& na = model.accessors.at(size_t(nor->second));
        if (na.count == pa.count && na.type == TINYGLTF_TYPE_VEC3 && na.bufferView >= 0)
          for (size_t i = 0; i < pa.count; ++i)
            for (int c = 0; c < 3; ++c) v[i].normal[c] = readComponent(model, na, i, c);
      }
      auto uv = prim.attributes.find("TEXCOORD_0");
      if (uv != prim.attributes.end()) {
        const tinygltf::Accessor& ua = model.accessors.at(size_t(uv->second));
        if (ua.count == pa.count && ua.type == TINYGLTF_TYPE_VEC2 && ua.bufferView >= 0)
          for (size_t i = 0; i < pa.count; ++i)
            v[i].u = readComponent(model, ua, i, 0), v[i].v = readComponent(model, ua, i, 1);
      }
      std::vector<uint32_t> idx;
      if (prim.indices >= 0) {
        const tinygltf::Accessor& ia = model.accessors.at(size_t(prim.indices));
        if (ia.bufferView < 0) continue;
        for (size_t i = 0; i < ia.count; ++i) idx.push_back(readIndex(model, ia, i));
      } else {
        for (size_t i = 0; i < pa.count; ++i) idx.push_back(uint32_t(i));
      }
      idx.resize(idx.size() / 3 * 3);
      if (idx.empty() || std::any_of(idx.begin(), idx.end(), [&](uint32_t i) { return i >= pa.count; })) continue;
      const uint32_t mat = prim.material >= 0 && size_t(prim.material) < model.materials.size()
                               ? uint32_t(prim.material)
                               : defaultMaterial;
      s.part(mesh, v, idx, mat);
      --skipped;
    }
  }
  if (skipped)
    std::fprintf(stderr,
                 "pathtracer: %s: skipped %zu primitives (not triangle lists, no positions, non-finite positions or "
                 "indices out of range)\n",
                 path.c_str(), skipped);
  // Instances: the default scene's node tree.
  const int sceneIndex = model.defaultScene >= 0 ? model.defaultScene : 0;
  if (model.scenes.empty()) fail(path + " has no scene");
  Vec3 lo{1e30f, 1e30f, 1e30f}, hi{-1e30f, -1e30f, -1e30f};
  // (node, its parent's world matrix, its depth): a depth beyond the number of nodes means a cycle.
  struct Pending {
    int node;
    Mat4 parent;
    size_t depth;
  };
  std::vector<Pending> stack;
  for (int n : model.scenes.at(size_t(sceneIndex)).nodes)
    stack.push_back({n, Mat4{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}, 0});
  while (!stack.empty()) {
    auto [n, parent, depth] = stack.back();
    stack.pop_back();
    if (n < 0 || size_t(n) >= model.nodes.size()) fail(path + ": a node index out of range");
    if (depth >= model.nodes.size()) fail(path + ": the node hierarchy has a cycle");
    const tinygltf::Node& node = model.nodes[size_t(n)];
    const Mat4 world = mul(parent, nodeMatrix(node));
    if (node.mesh >= 0 && size_t(node.mesh) < s.meshes.size() && !s.meshes[size_t(node.mesh)].parts.empty()) {
      Placement p{uint32_t(node.mesh), {}};
      for (int row = 0; row < 3; ++row)
        for (int c = 0; c < 4; ++c) p.transform[row][c] = float(world[size_t(c * 4 + row)]);
      s.placements.push_back(p);
      for (const MeshPart& part : s.meshes[size_t(node.mesh)].parts)
        for (uint32_t i = 0; i < part.vertexCount; ++i) {
          const float* q = s.vertices[part.vertexOffset + i].position;
          float w[3];
          for (int row = 0; row < 3; ++row)
            w[row] = p.transform[row][0] * q[0] + p.transform[row][1] * q[1] + p.transform[row][2] * q[2] +
                     p.transform[row][3];
          lo = {std::min(lo.x, w[0]), std::min(lo.y, w[1]), std::min(lo.z, w[2])};
          hi = {std::max(hi.x, w[0]), std::max(hi.y, w[1]), std::max(hi.z, w[2])};
        }
    }
    for (int c : node.children) stack.push_back({c, world, depth + 1});
  }
  if (s.placements.empty()) fail(path + " has no triangle meshes in its scene");
  const Vec3 center = (lo + hi) * 0.5f;
  const float radius = std::max(std::sqrt(dot(hi - lo, hi - lo)) * 0.5f, 1e-6f);
  // A ground plane under the model.
  Material ground;
  set4(ground.baseColor, {0.45f, 0.45f, 0.42f}, 1);
  const uint32_t mGround = s.material(ground);
  s.meshes.emplace_back();
  const uint32_t groundMesh = uint32_t(s.meshes.size() - 1);
  const float g = radius * 8, y = lo.y;
  s.quad(groundMesh, {center.x - g, y, center.z + g}, {center.x + g, y, center.z + g}, {center.x + g, y, center.z - g},
         {center.x - g, y, center.z - g}, mGround);
  Placement gp{groundMesh, {}};
  std::memcpy(gp.transform, kIdentity, sizeof kIdentity);
  s.placements.push_back(gp);
  const Vec3 eye = center + normalize({0.75f, 0.55f, 1.0f}) * (radius * 2.6f);
  s.camera(eye, center, 0.6981f);
  set4(s.info.sunDirection, normalize({0.45f, 1.0f, 0.35f}), 1);
  set4(s.info.sunColor, {2.6f, 2.45f, 2.2f}, 0);
  set4(s.info.skyZenith, {0.35f, 0.5f, 0.85f}, 0);
  set4(s.info.skyHorizon, {0.75f, 0.78f, 0.8f}, 0);
  set4(s.info.params, {radius * 2e-5f, 4.0f, 0}, 0);
  return s;
}

// ---------------------------------------------------------------------------------------------------- Vulkan

bool hasExtension(const std::vector<VkExtensionProperties>& all, const char* name) {
  return std::any_of(all.begin(), all.end(),
                     [&](const VkExtensionProperties& e) { return std::strcmp(e.extensionName, name) == 0; });
}

const char* const kDeviceExtensions[] = {
    VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME, VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME,
    VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME, VK_KHR_PIPELINE_LIBRARY_EXTENSION_NAME,
    VK_EXT_PIPELINE_LIBRARY_GROUP_HANDLES_EXTENSION_NAME};

// Whether `d` has the extensions and features the path tracer needs.
bool suitable(VkPhysicalDevice d) {
  uint32_t e = 0;
  CHECK(vkEnumerateDeviceExtensionProperties(d, nullptr, &e, nullptr));
  std::vector<VkExtensionProperties> exts(e);
  CHECK(vkEnumerateDeviceExtensionProperties(d, nullptr, &e, exts.data()));
  if (!std::all_of(std::begin(kDeviceExtensions), std::end(kDeviceExtensions),
                   [&](const char* x) { return hasExtension(exts, x); }))
    return false;
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(d, &props);
  if (props.apiVersion < VK_API_VERSION_1_2) return false;
  VkPhysicalDevicePipelineLibraryGroupHandlesFeaturesEXT lgh{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PIPELINE_LIBRARY_GROUP_HANDLES_FEATURES_EXT};
  VkPhysicalDeviceAccelerationStructureFeaturesKHR asf{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR, &lgh};
  VkPhysicalDeviceRayTracingPipelineFeaturesKHR rtf{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_FEATURES_KHR,
                                                    &asf};
  VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES, &rtf};
  VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &f12};
  vkGetPhysicalDeviceFeatures2(d, &f2);
  return f12.bufferDeviceAddress && rtf.rayTracingPipeline && asf.accelerationStructure &&
         lgh.pipelineLibraryGroupHandles;
}

// Opens the first suitable device with those extensions and features.
void createDevice(Context& c) {
  VkPhysicalDevicePipelineLibraryGroupHandlesFeaturesEXT lgh{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PIPELINE_LIBRARY_GROUP_HANDLES_FEATURES_EXT};
  lgh.pipelineLibraryGroupHandles = VK_TRUE;
  VkPhysicalDeviceAccelerationStructureFeaturesKHR asf{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR, &lgh};
  asf.accelerationStructure = VK_TRUE;
  VkPhysicalDeviceRayTracingPipelineFeaturesKHR rtf{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_FEATURES_KHR,
                                                    &asf};
  rtf.rayTracingPipeline = VK_TRUE;
  VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES, &rtf};
  f12.bufferDeviceAddress = VK_TRUE;
  c.open(VK_QUEUE_COMPUTE_BIT, &f12, {std::begin(kDeviceExtensions), std::end(kDeviceExtensions)}, {}, suitable,
         "no Vulkan device with VK_KHR_ray_tracing_pipeline, VK_KHR_acceleration_structure, VK_KHR_pipeline_library "
         "and VK_EXT_pipeline_library_group_handles (and their features)");
  std::printf("pathtracer: shader group handles of %u bytes, ray recursion depth up to %u\n",
              c.rt.shaderGroupHandleSize, c.rt.maxRayRecursionDepth);
}

// The scene's structures: a BLAS per mesh (a geometry per part; alpha-tested parts are not opaque, so that the
// any-hit shader runs for them), one BLAS of sphere boxes, and the TLAS. Fills `geometries` (the instance custom
// index of a mesh instance is the index of its first part there).
VkAccelerationStructureKHR buildScene(Context& c, const Scene& s, std::vector<Geometry>* geometries) {
  const Buffer vertices = c.upload(s.vertices, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR |
                                                   VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  const Buffer indices = c.upload(s.indices, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR |
                                                 VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  std::vector<Built> meshes;
  std::vector<uint32_t> firstGeometry;
  for (const Mesh& m : s.meshes) {
    firstGeometry.push_back(uint32_t(geometries->size()));
    if (m.parts.empty()) {
      meshes.push_back({});
      continue;
    }
    std::vector<VkAccelerationStructureGeometryKHR> gs;
    std::vector<uint32_t> counts;
    for (const MeshPart& p : m.parts) {
      geometries->push_back({p.firstIndex, p.vertexOffset, p.material, 0});
      VkAccelerationStructureGeometryKHR g{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
      g.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
      g.flags = s.materials[p.material].alphaMode != 0 ? VK_GEOMETRY_NO_DUPLICATE_ANY_HIT_INVOCATION_BIT_KHR
                                                       : VK_GEOMETRY_OPAQUE_BIT_KHR;
      auto& t = g.geometry.triangles;
      t.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
      t.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
      t.vertexData.deviceAddress = vertices.address + VkDeviceSize(p.vertexOffset) * sizeof(Vertex);
      t.vertexStride = sizeof(Vertex);
      t.maxVertex = p.vertexCount - 1;
      t.indexType = VK_INDEX_TYPE_UINT32;
      t.indexData.deviceAddress = indices.address + VkDeviceSize(p.firstIndex) * 4;
      gs.push_back(g);
      counts.push_back(p.indexCount / 3);
    }
    meshes.push_back(c.build(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, gs, counts));
  }
  std::vector<VkAccelerationStructureInstanceKHR> instances;
  for (const Placement& p : s.placements) {
    VkAccelerationStructureInstanceKHR in{};
    std::memcpy(in.transform.matrix, p.transform, sizeof p.transform);
    in.instanceCustomIndex = firstGeometry[p.mesh];
    in.mask = 0xff;
    in.instanceShaderBindingTableRecordOffset = 0;  // hit group 0: triangles
    in.accelerationStructureReference = meshes[p.mesh].address;
    instances.push_back(in);
  }
  if (!s.spheres.empty()) {
    std::vector<VkAabbPositionsKHR> boxes;
    for (const Sphere& sp : s.spheres) {
      const float* q = sp.centerRadius;
      boxes.push_back({q[0] - q[3], q[1] - q[3], q[2] - q[3], q[0] + q[3], q[1] + q[3], q[2] + q[3]});
    }
    VkAccelerationStructureGeometryKHR g{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
    g.geometryType = VK_GEOMETRY_TYPE_AABBS_KHR;
    g.flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
    g.geometry.aabbs.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_AABBS_DATA_KHR;
    g.geometry.aabbs.data.deviceAddress =
        c.upload(boxes, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR).address;
    g.geometry.aabbs.stride = sizeof(VkAabbPositionsKHR);
    Built spheres = c.build(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {g}, {uint32_t(boxes.size())});
    VkAccelerationStructureInstanceKHR in{};
    std::memcpy(in.transform.matrix, kIdentity, sizeof kIdentity);
    in.instanceCustomIndex = 0;  // spheres[0 + gl_PrimitiveID]
    in.mask = 0xff;
    in.instanceShaderBindingTableRecordOffset = 1;  // hit group 1: spheres
    in.accelerationStructureReference = spheres.address;
    instances.push_back(in);
  }
  return c.buildTopLevel(instances).as;
}

// ---------------------------------------------------------------------------------------------- the pipeline

constexpr uint32_t kBindings = 11;
struct PushConstants {
  uint32_t sampleStart, samples, seed, maxBounces;
};

// The group layout of the linked pipeline: each library's groups in order, libraries in pLibraries order.
constexpr uint32_t kRaygenGroup = 0, kMissGroups = 1, kHitGroups = 3, kCallableGroups = 5, kGroups = 8;
constexpr uint32_t kLibraryGroups[3] = {3, 2, 3};  // raygen + 2 miss; triangle + sphere hit groups; 3 materials

struct Pipeline {
  VkPipeline pipeline = VK_NULL_HANDLE;
  VkPipeline libraries[3] = {};
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;
  uint32_t stackSize = 0;
};

// The payload and hit attribute sizes every library and the linked pipeline declare (pt.glsl: HitPayload is 64
// bytes, BsdfSample 80; triangles' barycentrics are 8 bytes, the spheres report none).
constexpr uint32_t kMaxPayload = 80, kMaxHitAttributes = 8, kRecursionDepth = 1;

VkPipeline library(Context& c, const Pipeline& p, const std::vector<VkPipelineShaderStageCreateInfo>& stages,
                   const std::vector<VkRayTracingShaderGroupCreateInfoKHR>& groups) {
  VkRayTracingPipelineInterfaceCreateInfoKHR iface{VK_STRUCTURE_TYPE_RAY_TRACING_PIPELINE_INTERFACE_CREATE_INFO_KHR};
  iface.maxPipelineRayPayloadSize = kMaxPayload;
  iface.maxPipelineRayHitAttributeSize = kMaxHitAttributes;
  VkRayTracingPipelineCreateInfoKHR ci{VK_STRUCTURE_TYPE_RAY_TRACING_PIPELINE_CREATE_INFO_KHR};
  ci.flags = VK_PIPELINE_CREATE_LIBRARY_BIT_KHR;
  ci.stageCount = uint32_t(stages.size());
  ci.pStages = stages.data();
  ci.groupCount = uint32_t(groups.size());
  ci.pGroups = groups.data();
  ci.maxPipelineRayRecursionDepth = kRecursionDepth;
  ci.pLibraryInterface = &iface;
  ci.layout = p.layout;
  ci.basePipelineIndex = -1;
  VkPipeline out;
  CHECK(c.createPipelines(c.device, VK_NULL_HANDLE, VK_NULL_HANDLE, 1, &ci, nullptr, &out));
  return out;
}

Pipeline createPipeline(Context& c, bool printPixels) {
  if (c.rt.maxRayRecursionDepth < kRecursionDepth) fail("the device's maxRayRecursionDepth is below 1");
  Pipeline p;
  const VkShaderStageFlags all = VK_SHADER_STAGE_RAYGEN_BIT_KHR | VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR |
                                 VK_SHADER_STAGE_ANY_HIT_BIT_KHR | VK_SHADER_STAGE_INTERSECTION_BIT_KHR |
                                 VK_SHADER_STAGE_MISS_BIT_KHR | VK_SHADER_STAGE_CALLABLE_BIT_KHR;
  // 0 the TLAS; 1 accumulation, 2 ray counts; 3 vertices, 4 indices, 5 geometries, 6 materials, 7 textures,
  // 8 texels, 9 spheres, 10 the scene (camera, lights, sky).
  VkDescriptorSetLayoutBinding b[kBindings];
  for (uint32_t i = 0; i < kBindings; ++i)
    b[i] = {i, i == 0 ? VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, all,
            nullptr};
  VkDescriptorSetLayoutCreateInfo dl{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  dl.bindingCount = kBindings;
  dl.pBindings = b;
  CHECK(vkCreateDescriptorSetLayout(c.device, &dl, nullptr, &p.setLayout));
  VkPushConstantRange range{VK_SHADER_STAGE_RAYGEN_BIT_KHR, 0, sizeof(PushConstants)};
  VkPipelineLayoutCreateInfo lci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  lci.setLayoutCount = 1;
  lci.pSetLayouts = &p.setLayout;
  lci.pushConstantRangeCount = 1;
  lci.pPushConstantRanges = &range;
  CHECK(vkCreatePipelineLayout(c.device, &lci, nullptr, &p.layout));

  std::vector<VkShaderModule> modules;
  auto stage = [&](std::vector<VkPipelineShaderStageCreateInfo>& stages, const uint32_t* words, size_t bytes,
                   VkShaderStageFlagBits s) {
    VkPipelineShaderStageCreateInfo st{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    st.stage = s;
    st.module = c.shaderModule(words, bytes);
    st.pName = "main";
    modules.push_back(st.module);
    stages.push_back(st);
    return uint32_t(stages.size() - 1);
  };
  using example::group;
  const uint32_t U = VK_SHADER_UNUSED_KHR;
  const auto G = VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR,
             T = VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR,
             P = VK_RAY_TRACING_SHADER_GROUP_TYPE_PROCEDURAL_HIT_GROUP_KHR;
  {  // Library 0: the camera and the misses.
    std::vector<VkPipelineShaderStageCreateInfo> st;
    const uint32_t rgen = stage(st, kSpv_pt_rgen, sizeof kSpv_pt_rgen, VK_SHADER_STAGE_RAYGEN_BIT_KHR);
    // --printf: pt.rgen's kPrintPixels (constant_id 0).
    static const VkBool32 print = VK_TRUE;
    static const VkSpecializationMapEntry entry{0, 0, sizeof(VkBool32)};
    static const VkSpecializationInfo spec{1, &entry, sizeof print, &print};
    if (printPixels) st[rgen].pSpecializationInfo = &spec;
    const uint32_t miss = stage(st, kSpv_pt_rmiss, sizeof kSpv_pt_rmiss, VK_SHADER_STAGE_MISS_BIT_KHR);
    const uint32_t shadow = stage(st, kSpv_pt_shadow_rmiss, sizeof kSpv_pt_shadow_rmiss, VK_SHADER_STAGE_MISS_BIT_KHR);
    p.libraries[0] = library(c, p, st, {group(G, rgen, U, U, U), group(G, miss, U, U, U), group(G, shadow, U, U, U)});
  }
  {  // Library 1: the hit groups, triangles (closest hit + alpha-testing any hit) and spheres (intersection).
    std::vector<VkPipelineShaderStageCreateInfo> st;
    const uint32_t tch =
        stage(st, kSpv_pt_triangle_rchit, sizeof kSpv_pt_triangle_rchit, VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR);
    const uint32_t tah = stage(st, kSpv_pt_alpha_rahit, sizeof kSpv_pt_alpha_rahit, VK_SHADER_STAGE_ANY_HIT_BIT_KHR);
    const uint32_t sch =
        stage(st, kSpv_pt_sphere_rchit, sizeof kSpv_pt_sphere_rchit, VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR);
    const uint32_t sis =
        stage(st, kSpv_pt_sphere_rint, sizeof kSpv_pt_sphere_rint, VK_SHADER_STAGE_INTERSECTION_BIT_KHR);
    p.libraries[1] = library(c, p, st, {group(T, U, tch, tah, U), group(P, U, sch, U, sis)});
  }
  {  // Library 2: the materials, callable shaders in Kind order.
    std::vector<VkPipelineShaderStageCreateInfo> st;
    const uint32_t d = stage(st, kSpv_pt_diffuse_rcall, sizeof kSpv_pt_diffuse_rcall, VK_SHADER_STAGE_CALLABLE_BIT_KHR);
    const uint32_t m = stage(st, kSpv_pt_metal_rcall, sizeof kSpv_pt_metal_rcall, VK_SHADER_STAGE_CALLABLE_BIT_KHR);
    const uint32_t g = stage(st, kSpv_pt_glass_rcall, sizeof kSpv_pt_glass_rcall, VK_SHADER_STAGE_CALLABLE_BIT_KHR);
    p.libraries[2] = library(c, p, st, {group(G, d, U, U, U), group(G, m, U, U, U), group(G, g, U, U, U)});
  }
  for (VkShaderModule m : modules) vkDestroyShaderModule(c.device, m, nullptr);

  // The pipeline: the three libraries linked, no shaders of its own; the stack size is dynamic state.
  VkPipelineLibraryCreateInfoKHR libs{VK_STRUCTURE_TYPE_PIPELINE_LIBRARY_CREATE_INFO_KHR};
  libs.libraryCount = 3;
  libs.pLibraries = p.libraries;
  VkRayTracingPipelineInterfaceCreateInfoKHR iface{VK_STRUCTURE_TYPE_RAY_TRACING_PIPELINE_INTERFACE_CREATE_INFO_KHR};
  iface.maxPipelineRayPayloadSize = kMaxPayload;
  iface.maxPipelineRayHitAttributeSize = kMaxHitAttributes;
  VkDynamicState dyn = VK_DYNAMIC_STATE_RAY_TRACING_PIPELINE_STACK_SIZE_KHR;
  VkPipelineDynamicStateCreateInfo ds{VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO};
  ds.dynamicStateCount = 1;
  ds.pDynamicStates = &dyn;
  VkRayTracingPipelineCreateInfoKHR ci{VK_STRUCTURE_TYPE_RAY_TRACING_PIPELINE_CREATE_INFO_KHR};
  ci.maxPipelineRayRecursionDepth = kRecursionDepth;
  ci.pLibraryInfo = &libs;
  ci.pLibraryInterface = &iface;
  ci.pDynamicState = &ds;
  ci.layout = p.layout;
  ci.basePipelineIndex = -1;
  CHECK(c.createPipelines(c.device, VK_NULL_HANDLE, VK_NULL_HANDLE, 1, &ci, nullptr, &p.pipeline));

  // The pipeline stack size by the specification's formula ("Ray Tracing Pipeline Stack"), from the shaders' own
  // sizes: the ray generation shader, one level of traceRayEXT under it (maxPipelineRayRecursionDepth is 1:
  // closest hit, miss, or intersection + any hit), nothing deeper, and 2 x the largest callable (the materials
  // are called from the ray generation shader only, so one would do; the formula's default is kept).
  auto stack = [&](uint32_t g, VkShaderGroupShaderKHR s) { return c.groupStackSize(c.device, p.pipeline, g, s); };
  const VkDeviceSize raygen = stack(kRaygenGroup, VK_SHADER_GROUP_SHADER_GENERAL_KHR);
  const VkDeviceSize closestHit = std::max(stack(kHitGroups, VK_SHADER_GROUP_SHADER_CLOSEST_HIT_KHR),
                                           stack(kHitGroups + 1, VK_SHADER_GROUP_SHADER_CLOSEST_HIT_KHR));
  const VkDeviceSize miss = std::max(stack(kMissGroups, VK_SHADER_GROUP_SHADER_GENERAL_KHR),
                                     stack(kMissGroups + 1, VK_SHADER_GROUP_SHADER_GENERAL_KHR));
  const VkDeviceSize intersection = stack(kHitGroups + 1, VK_SHADER_GROUP_SHADER_INTERSECTION_KHR);
  const VkDeviceSize anyHit = stack(kHitGroups, VK_SHADER_GROUP_SHADER_ANY_HIT_KHR);
  VkDeviceSize callable = 0;
  for (uint32_t k = 0; k < kKinds; ++k)
    callable = std::max(callable, stack(kCallableGroups + k, VK_SHADER_GROUP_SHADER_GENERAL_KHR));
  const VkDeviceSize depth = kRecursionDepth;
  const VkDeviceSize size = raygen +
                            std::min<VkDeviceSize>(1, depth) * std::max({closestHit, miss, intersection + anyHit}) +
                            (depth > 1 ? depth - 1 : 0) * std::max(closestHit, miss) + 2 * callable;
  p.stackSize = uint32_t(size);
  std::printf(
      "pathtracer: pipeline linked from 3 libraries; stack sizes: raygen %llu, closest hit %llu, miss %llu, "
      "intersection %llu, any hit %llu, callable %llu -> pipeline stack %u bytes\n",
      (unsigned long long)raygen, (unsigned long long)closestHit, (unsigned long long)miss,
      (unsigned long long)intersection, (unsigned long long)anyHit, (unsigned long long)callable, p.stackSize);
  return p;
}

// The SBT, written from the libraries' handles (VK_EXT_pipeline_library_group_handles) after checking that the
// linked pipeline reports the same ones. Regions: raygen | miss, shadow miss | triangles, spheres | 3 materials.
struct Sbt {
  VkStridedDeviceAddressRegionKHR raygen{}, miss{}, hit{}, callable{};
};

Sbt writeSbt(Context& c, const Pipeline& p) {
  const uint32_t hs = c.rt.shaderGroupHandleSize;
  std::vector<uint8_t> fromLibraries;
  for (int l = 0; l < 3; ++l) {
    std::vector<uint8_t> h(size_t(hs) * kLibraryGroups[l]);
    CHECK(c.groupHandles(c.device, p.libraries[l], 0, kLibraryGroups[l], h.size(), h.data()));
    fromLibraries.insert(fromLibraries.end(), h.begin(), h.end());
  }
  std::vector<uint8_t> linked(size_t(hs) * kGroups);
  CHECK(c.groupHandles(c.device, p.pipeline, 0, kGroups, linked.size(), linked.data()));
  if (linked != fromLibraries) fail("the libraries' shader group handles differ from the linked pipeline's");
  std::printf("pathtracer: the %u group handles queried on the 3 libraries equal the linked pipeline's\n", kGroups);

  const VkDeviceSize stride =
      (hs + c.rt.shaderGroupHandleAlignment - 1) / c.rt.shaderGroupHandleAlignment * c.rt.shaderGroupHandleAlignment;
  const VkDeviceSize base = c.rt.shaderGroupBaseAlignment;
  auto regionSize = [&](uint32_t records) { return (records * stride + base - 1) / base * base; };
  const VkDeviceSize raygenAt = 0, missAt = raygenAt + regionSize(1), hitAt = missAt + regionSize(2),
                     callAt = hitAt + regionSize(2), total = callAt + regionSize(kKinds);
  Buffer sbt = c.buffer(total + base, VK_BUFFER_USAGE_SHADER_BINDING_TABLE_BIT_KHR);
  const VkDeviceAddress start = (sbt.address + base - 1) / base * base;
  uint8_t* bytes = static_cast<uint8_t*>(sbt.data) + (start - sbt.address);
  auto put = [&](VkDeviceSize at, uint32_t group) { std::memcpy(bytes + at, &fromLibraries[size_t(group) * hs], hs); };
  put(raygenAt, kRaygenGroup);
  for (uint32_t k = 0; k < 2; ++k) put(missAt + k * stride, kMissGroups + k);
  for (uint32_t k = 0; k < 2; ++k) put(hitAt + k * stride, kHitGroups + k);
  for (uint32_t k = 0; k < kKinds; ++k) put(callAt + k * stride, kCallableGroups + k);
  Sbt s;
  s.raygen = {start + raygenAt, stride, stride};
  s.miss = {start + missAt, stride, 2 * stride};
  s.hit = {start + hitAt, stride, 2 * stride};
  s.callable = {start + callAt, stride, kKinds * stride};
  return s;
}

// ---------------------------------------------------------------------------------------------- the render

void progress(bool terminal, uint32_t done, uint32_t total, double seconds) {
  const double f = double(done) / double(total);
  if (terminal) {
    const int width = 40, filled = int(f * width + 0.5);
    std::printf("\r[%s%s] %3d%%  %u/%u spp  %.1f s", std::string(size_t(filled), '#').c_str(),
                std::string(size_t(width - filled), ' ').c_str(), int(f * 100 + 0.5), done, total, seconds);
    if (done == total) std::printf("\n");
  } else {
    std::printf("pathtracer: %u/%u spp (%d%%), %.1f s\n", done, total, int(f * 100 + 0.5), seconds);
  }
  std::fflush(stdout);
}

uint8_t toSrgb8(float linear) {
  const float v = std::clamp(linear, 0.0f, 1.0f);
  const float s = v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1 / 2.4f) - 0.055f;
  return uint8_t(s * 255.0f + 0.5f);
}

bool parseUint(const char* s, uint32_t* out) {
  char* end = nullptr;
  const unsigned long v = std::strtoul(s, &end, 10);
  if (!*s || *end || v > 0xffffffffu || s[0] == '-') return false;
  *out = uint32_t(v);
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  example::gProgram = "pathtracer";
  uint32_t width = 640, height = 480, spp = 64, bounces = 6, seed = 1, passSpp = 0, printPixels = 0;
  std::string sceneArg = "cornell", out = "pathtracer.png";
  bool bad = false;
  for (int i = 1; i < argc; i += 2) {
    const std::string a = argv[i];
    if (i + 1 >= argc) {
      bad = true;
      break;
    }
    const char* v = argv[i + 1];
    if (a == "--scene")
      sceneArg = v;
    else if (a == "--out")
      out = v;
    else if (a == "--width")
      bad |= !parseUint(v, &width);
    else if (a == "--height")
      bad |= !parseUint(v, &height);
    else if (a == "--spp")
      bad |= !parseUint(v, &spp);
    else if (a == "--bounces")
      bad |= !parseUint(v, &bounces);
    else if (a == "--seed")
      bad |= !parseUint(v, &seed);
    else if (a == "--pass-spp")
      bad |= !parseUint(v, &passSpp);
    else if (a == "--printf")
      bad |= !parseUint(v, &printPixels);
    else
      bad = true;
  }
  // A pixel's ray count is 32 bits: at most 1 + 2 x bounces rays a path (the path rays and a shadow ray a bounce).
  const bool countFits = uint64_t(spp) * (1 + 2 * uint64_t(bounces)) < (uint64_t(1) << 32);
  if (bad || width == 0 || height == 0 || width > 16384 || height > 16384 || spp == 0 || bounces > 64 || !countFits) {
    std::fprintf(stderr,
                 "usage: pathtracer [--scene cornell|file.glb|file.gltf] [--width W] [--height H] [--spp N] "
                 "[--bounces N (0-64)] [--seed S] [--out file.png] [--pass-spp N] [--printf 1]\n"
                 "  (width and height up to 16384, spp x (1 + 2 x bounces) below 2^32)\n");
    return 2;
  }
  const auto t0 = std::chrono::steady_clock::now();
  Scene scene = sceneArg == "cornell" ? cornell() : loadGltf(sceneArg);
  Context c;
  createDevice(c);
  std::vector<Geometry> geometries;
  VkAccelerationStructureKHR tlas = buildScene(c, scene, &geometries);
  Pipeline p = createPipeline(c, printPixels != 0);
  const Sbt sbt = writeSbt(c, p);
  size_t triangles = scene.indices.size() / 3;
  std::printf(
      "pathtracer: scene %s: %zu triangles in %zu meshes, %zu instances, %zu spheres, %zu materials, %zu "
      "textures\n",
      sceneArg.c_str(), triangles, scene.meshes.size(), scene.placements.size(), scene.spheres.size(),
      scene.materials.size(), scene.textures.size());

  // Resources.
  const size_t pixels = size_t(width) * height;
  Buffer accum = c.buffer(pixels * 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true);
  Buffer rayCounts = c.buffer(pixels * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true);
  const VkBufferUsageFlags ssbo = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  Buffer vertices = c.upload(scene.vertices, ssbo), indices = c.upload(scene.indices, ssbo),
         geoms = c.upload(geometries, ssbo), mats = c.upload(scene.materials, ssbo),
         texs = c.upload(scene.textures, ssbo), texels = c.upload(scene.texels, ssbo),
         spheres = c.upload(scene.spheres, ssbo), info = c.upload(std::vector<SceneInfo>{scene.info}, ssbo);
  VkDescriptorPool pool;
  const VkDescriptorSet set = c.sceneSet(p.setLayout, tlas,
                                         {accum.buffer, rayCounts.buffer, vertices.buffer, indices.buffer, geoms.buffer,
                                          mats.buffer, texs.buffer, texels.buffer, spheres.buffer, info.buffer},
                                         &pool);
  const auto t1 = std::chrono::steady_clock::now();
  std::printf("pathtracer: scene, acceleration structures and pipeline ready in %.2f s\n",
              std::chrono::duration<double>(t1 - t0).count());

  // Passes of passSpp samples per pixel, one submission each. By default a pass is about 2 M paths (at least 1
  // sample per pixel), so a long render reports progress every second or so on a few CPU cores.
  if (passSpp == 0) passSpp = uint32_t(std::clamp<size_t>((size_t(1) << 21) / pixels, 1, 64));
  passSpp = std::min(passSpp, spp);
  const bool terminal = isatty(fileno(stdout));
  std::printf("pathtracer: %ux%u, %u spp in passes of %u, up to %u bounces, seed %u\n", width, height, spp, passSpp,
              bounces, seed);
  std::memset(accum.data, 0, pixels * 16);
  std::memset(rayCounts.data, 0, pixels * 4);
  const auto t2 = std::chrono::steady_clock::now();
  for (uint32_t done = 0; done < spp;) {
    const PushConstants pc{done, std::min(passSpp, spp - done), seed, bounces};
    VkCommandBuffer cb = c.begin();
    // Everything earlier on the queue (the structure builds, the previous pass) before this pass's shaders.
    VkMemoryBarrier before{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    before.srcAccessMask = VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR | VK_ACCESS_SHADER_WRITE_BIT;
    before.dstAccessMask =
        VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_KHR | VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
    vkCmdPipelineBarrier(
        cb, VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR | VK_PIPELINE_STAGE_RAY_TRACING_SHADER_BIT_KHR,
        VK_PIPELINE_STAGE_RAY_TRACING_SHADER_BIT_KHR, 0, 1, &before, 0, nullptr, 0, nullptr);
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, p.pipeline);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, p.layout, 0, 1, &set, 0, nullptr);
    vkCmdPushConstants(cb, p.layout, VK_SHADER_STAGE_RAYGEN_BIT_KHR, 0, sizeof pc, &pc);
    c.setStackSize(cb, p.stackSize);
    c.traceRays(cb, &sbt.raygen, &sbt.miss, &sbt.hit, &sbt.callable, width, height, 1);
    // The sums and counts, for the host once the queue is idle.
    VkMemoryBarrier after{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    after.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
    after.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_RAY_TRACING_SHADER_BIT_KHR, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &after, 0,
                         nullptr, 0, nullptr);
    c.submit(cb);
    done += pc.samples;
    progress(terminal, done, spp, std::chrono::duration<double>(std::chrono::steady_clock::now() - t2).count());
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t2).count();

  const float* sum = static_cast<const float*>(accum.data);
  const uint32_t* counts = static_cast<const uint32_t*>(rayCounts.data);
  uint64_t rays = 0;
  std::vector<uint8_t> rgba(pixels * 4);
  for (size_t i = 0; i < pixels; ++i) {
    rays += counts[i];
    for (int k = 0; k < 3; ++k) rgba[i * 4 + size_t(k)] = toSrgb8(sum[i * 4 + size_t(k)] / float(spp));
    rgba[i * 4 + 3] = 255;
  }
  if (!stbi_write_png(out.c_str(), int(width), int(height), 4, rgba.data(), int(width * 4)))
    fail("could not write " + out);
  std::printf("pathtracer: %llu rays (%.2f per path) in %.3f s: %.2f Mrays/s\n", (unsigned long long)rays,
              double(rays) / (double(pixels) * spp), seconds, double(rays) / seconds / 1e6);
  std::printf("pathtracer: wrote %s\n", out.c_str());

  CHECK(vkDeviceWaitIdle(c.device));
  vkDestroyDescriptorPool(c.device, pool, nullptr);
  vkDestroyPipeline(c.device, p.pipeline, nullptr);
  for (VkPipeline l : p.libraries) vkDestroyPipeline(c.device, l, nullptr);
  vkDestroyPipelineLayout(c.device, p.layout, nullptr);
  vkDestroyDescriptorSetLayout(c.device, p.setLayout, nullptr);
  c.destroy();
  return 0;
}
