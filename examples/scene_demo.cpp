// scene_demo: traces a box with a rotated block (triangle meshes), two spheres (an intersection shader), an
// alpha-tested checkerboard panel (an any-hit shader) and a mirror, lit by one light with shadows from a second
// trace, through a Vulkan ray tracing pipeline, and writes the image as a PNG.
//
//   VK_DRIVER_FILES=<build>/vkrt_icd.json ./scene_demo [--width W] [--height H] [--out file.png] [--present N]
//
// --present N traces N frames (the blue sphere's colour changes from frame to frame) and presents each through a
// swapchain on a headless surface (VK_EXT_headless_surface): acquire, trace, copy the traced image into the
// swapchain image, present. On vkrt, VKRT_PRESENT_DIR=<folder> writes each presented frame there as a PNG.
//
// Plain Vulkan through the loader: it runs unchanged on any driver with VK_KHR_ray_tracing_pipeline.
#include <vulkan/vulkan.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>

#include "cutout.rahit.spv.h"
#include "example_vk.hpp"
#include "mesh.hpp"
#include "scene.rgen.spv.h"
#include "scene.rmiss.spv.h"
#include "shadow.rmiss.spv.h"
#include "sphere.rchit.spv.h"
#include "sphere.rint.spv.h"
#include "triangle.rchit.spv.h"

namespace {

using example::Buffer;
using example::Built;
using example::Mesh;

struct Context : example::Context {
  bool present = false;  // --present: the instance and device have the presentation extensions
};

void createDevice(Context& c) {
  VkPhysicalDeviceAccelerationStructureFeaturesKHR asf{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR};
  asf.accelerationStructure = VK_TRUE;
  VkPhysicalDeviceRayTracingPipelineFeaturesKHR rtf{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_FEATURES_KHR,
                                                    &asf};
  rtf.rayTracingPipeline = VK_TRUE;
  VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES, &rtf};
  f12.bufferDeviceAddress = VK_TRUE;
  std::vector<const char*> exts = {VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME,
                                   VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME,
                                   VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME};
  std::vector<const char*> instanceExts;
  if (c.present) {
    exts.push_back(VK_KHR_SWAPCHAIN_EXTENSION_NAME);
    instanceExts = {VK_KHR_SURFACE_EXTENSION_NAME, VK_EXT_HEADLESS_SURFACE_EXTENSION_NAME};
  }
  c.open(VK_QUEUE_COMPUTE_BIT, &f12, exts, instanceExts);
}

// ------------------------------------------------------------------------------------------------- the scene

enum Material : uint32_t { kWhite, kRed, kGreen, kMirror, kBlue, kYellow };
const float kMaterials[][4] = {{0.75f, 0.75f, 0.72f, 0},  {0.75f, 0.12f, 0.1f, 0}, {0.15f, 0.6f, 0.15f, 0},
                               {0.9f, 0.9f, 0.9f, 0.85f}, {0.15f, 0.3f, 0.8f, 0},  {0.85f, 0.7f, 0.1f, 0}};

Built buildMesh(Context& c, const Mesh& m, bool opaque) {
  VkAccelerationStructureGeometryKHR g{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
  g.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
  g.flags = opaque ? VK_GEOMETRY_OPAQUE_BIT_KHR : VK_GEOMETRY_NO_DUPLICATE_ANY_HIT_INVOCATION_BIT_KHR;
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
  return c.build(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {g}, {uint32_t(m.indices.size() / 3)});
}

VkAccelerationStructureInstanceKHR instanceOf(const Built& b, float angle, float tx, float ty, float tz, float scale,
                                              uint32_t customIndex, uint32_t sbtOffset) {
  VkAccelerationStructureInstanceKHR in{};
  const float cs = std::cos(angle) * scale, sn = std::sin(angle) * scale;
  const float m[3][4] = {{cs, 0, sn, tx}, {0, scale, 0, ty}, {-sn, 0, cs, tz}};
  std::memcpy(in.transform.matrix, m, sizeof m);
  in.instanceCustomIndex = customIndex;
  in.mask = 0xff;
  in.instanceShaderBindingTableRecordOffset = sbtOffset;
  in.accelerationStructureReference = b.address;
  return in;
}

// Builds the scene; fills the triangle table (normal + material per triangle, by instance) and the sphere table.
VkAccelerationStructureKHR buildScene(Context& c, std::vector<float>* triangleTable, std::vector<float>* sphereTable) {
  Mesh room, block, panel;
  const float f[8][3] = {{-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, {-1, 0, -1},
                         {-1, 2, 1}, {1, 2, 1}, {1, 2, -1}, {-1, 2, -1}};
  room.quad(f[0], f[1], f[2], f[3], kWhite);  // floor, normal up
  room.quad(f[7], f[6], f[5], f[4], kWhite);  // ceiling, normal down
  room.quad(f[3], f[2], f[6], f[7], kWhite);  // back wall, normal +z
  room.quad(f[0], f[3], f[7], f[4], kRed);    // left wall, normal +x
  room.quad(f[2], f[1], f[5], f[6], kGreen);  // right wall, normal -x
  block.box(0.5f, 1.1f, 0.5f, kWhite);
  const float p[4][3] = {
      {0.05f, 0.75f, -0.35f}, {0.85f, 0.75f, -0.35f}, {0.85f, 1.65f, -0.35f}, {0.05f, 1.65f, -0.35f}};
  panel.quad(p[0], p[1], p[2], p[3], kYellow);
  // The triangle table: room, block, panel, each instance's custom index the offset of its first triangle.
  uint32_t offsets[3], at = 0, k = 0;
  for (const Mesh* m : {&room, &block, &panel}) {
    offsets[k++] = at;
    triangleTable->insert(triangleTable->end(), m->triangles.begin(), m->triangles.end());
    at += uint32_t(m->triangles.size() / 4);
  }
  Built roomAs = buildMesh(c, room, true), blockAs = buildMesh(c, block, true), panelAs = buildMesh(c, panel, false);
  // One unit sphere in a box; two instances (a mirror and a blue sphere) scale and place it.
  *sphereTable = {0, 0, 0, 1};
  VkAabbPositionsKHR box{-1, -1, -1, 1, 1, 1};
  VkAccelerationStructureGeometryKHR g{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
  g.geometryType = VK_GEOMETRY_TYPE_AABBS_KHR;
  g.flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
  g.geometry.aabbs.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_AABBS_DATA_KHR;
  g.geometry.aabbs.data.deviceAddress = c.upload(std::vector<VkAabbPositionsKHR>{box},
                                                 VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR)
                                            .address;
  g.geometry.aabbs.stride = sizeof(VkAabbPositionsKHR);
  Built sphereAs = c.build(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {g}, {1});
  // SBT hit records: 0 opaque triangles, 1 the alpha-tested panel, 2 spheres.
  std::vector<VkAccelerationStructureInstanceKHR> instances = {
      instanceOf(roomAs, 0, 0, 0, 0, 1, offsets[0], 0),
      instanceOf(blockAs, 0.35f, -0.45f, 0, -0.45f, 1, offsets[1], 0),
      instanceOf(panelAs, 0, 0, 0, 0, 1, offsets[2], 1),
      instanceOf(sphereAs, 0, 0.45f, 0.35f, 0.3f, 0.35f, kMirror, 2),
      instanceOf(sphereAs, 0, -0.25f, 0.22f, 0.55f, 0.22f, kBlue, 2),
  };
  return c.buildTopLevel(instances).as;
}

// ---------------------------------------------------------------------------------------------- the pipeline

struct Pipeline {
  VkPipeline pipeline;
  VkPipelineLayout layout;
  VkDescriptorSetLayout setLayout;
  uint64_t stackSize;
};

Pipeline createPipeline(Context& c) {
  Pipeline p{};
  const VkShaderStageFlags all = VK_SHADER_STAGE_RAYGEN_BIT_KHR | VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR |
                                 VK_SHADER_STAGE_ANY_HIT_BIT_KHR | VK_SHADER_STAGE_INTERSECTION_BIT_KHR |
                                 VK_SHADER_STAGE_MISS_BIT_KHR;
  VkDescriptorSetLayoutBinding b[5] = {{0, VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 1, all, nullptr},
                                       {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, all, nullptr},
                                       {2, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, all, nullptr},
                                       {3, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, all, nullptr},
                                       {4, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, all, nullptr}};
  VkDescriptorSetLayoutCreateInfo dl{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  dl.bindingCount = 5;
  dl.pBindings = b;
  CHECK(vkCreateDescriptorSetLayout(c.device, &dl, nullptr, &p.setLayout));
  VkPipelineLayoutCreateInfo lci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  lci.setLayoutCount = 1;
  lci.pSetLayouts = &p.setLayout;
  CHECK(vkCreatePipelineLayout(c.device, &lci, nullptr, &p.layout));
  struct S {
    const uint32_t* words;
    size_t bytes;
    VkShaderStageFlagBits stage;
  } shaders[] = {{kSpv_scene_rgen, sizeof kSpv_scene_rgen, VK_SHADER_STAGE_RAYGEN_BIT_KHR},
                 {kSpv_scene_rmiss, sizeof kSpv_scene_rmiss, VK_SHADER_STAGE_MISS_BIT_KHR},
                 {kSpv_shadow_rmiss, sizeof kSpv_shadow_rmiss, VK_SHADER_STAGE_MISS_BIT_KHR},
                 {kSpv_triangle_rchit, sizeof kSpv_triangle_rchit, VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR},
                 {kSpv_cutout_rahit, sizeof kSpv_cutout_rahit, VK_SHADER_STAGE_ANY_HIT_BIT_KHR},
                 {kSpv_sphere_rint, sizeof kSpv_sphere_rint, VK_SHADER_STAGE_INTERSECTION_BIT_KHR},
                 {kSpv_sphere_rchit, sizeof kSpv_sphere_rchit, VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR}};
  std::vector<VkPipelineShaderStageCreateInfo> stages;
  for (const S& s : shaders) {
    VkPipelineShaderStageCreateInfo st{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    st.stage = s.stage;
    st.module = c.shaderModule(s.words, s.bytes);
    st.pName = "main";
    stages.push_back(st);
  }
  using example::group;
  const uint32_t U = VK_SHADER_UNUSED_KHR;
  const auto G = VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR,
             T = VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR,
             P = VK_RAY_TRACING_SHADER_GROUP_TYPE_PROCEDURAL_HIT_GROUP_KHR;
  // Groups: 0 raygen, 1 miss, 2 shadow miss, 3 opaque triangles, 4 alpha-tested triangles, 5 spheres.
  VkRayTracingShaderGroupCreateInfoKHR groups[] = {group(G, 0, U, U, U), group(G, 1, U, U, U), group(G, 2, U, U, U),
                                                   group(T, U, 3, U, U), group(T, U, 3, 4, U), group(P, U, 6, U, 5)};
  VkDynamicState dyn = VK_DYNAMIC_STATE_RAY_TRACING_PIPELINE_STACK_SIZE_KHR;
  VkPipelineDynamicStateCreateInfo ds{VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO};
  ds.dynamicStateCount = 1;
  ds.pDynamicStates = &dyn;
  VkRayTracingPipelineCreateInfoKHR ci{VK_STRUCTURE_TYPE_RAY_TRACING_PIPELINE_CREATE_INFO_KHR};
  ci.stageCount = uint32_t(stages.size());
  ci.pStages = stages.data();
  ci.groupCount = 6;
  ci.pGroups = groups;
  ci.maxPipelineRayRecursionDepth = 3;
  ci.pDynamicState = &ds;
  ci.layout = p.layout;
  CHECK(c.createPipelines(c.device, VK_NULL_HANDLE, VK_NULL_HANDLE, 1, &ci, nullptr, &p.pipeline));
  for (auto& st : stages) vkDestroyShaderModule(c.device, st.module, nullptr);
  // The pipeline stack size by the specification's formula, from the shaders' own stack sizes: the camera ray
  // (raygen), a hit at depth 1 (closest-hit, or intersection + any-hit), and two levels under it (reflected and
  // shadow rays: closest-hit or miss).
  auto stack = [&](uint32_t g, VkShaderGroupShaderKHR s) { return c.groupStackSize(c.device, p.pipeline, g, s); };
  const uint64_t raygen = stack(0, VK_SHADER_GROUP_SHADER_GENERAL_KHR);
  const uint64_t closestHit =
      std::max({stack(3, VK_SHADER_GROUP_SHADER_CLOSEST_HIT_KHR), stack(5, VK_SHADER_GROUP_SHADER_CLOSEST_HIT_KHR)});
  const uint64_t miss =
      std::max(stack(1, VK_SHADER_GROUP_SHADER_GENERAL_KHR), stack(2, VK_SHADER_GROUP_SHADER_GENERAL_KHR));
  const uint64_t isectAny =
      stack(5, VK_SHADER_GROUP_SHADER_INTERSECTION_KHR) + stack(4, VK_SHADER_GROUP_SHADER_ANY_HIT_KHR);
  const uint32_t depth = 3;
  p.stackSize =
      raygen + std::min(1u, depth) * std::max({closestHit, miss, isectAny}) + (depth - 1) * std::max(closestHit, miss);
  return p;
}

// --present: N frames through a swapchain on a headless surface. Each frame: acquire an image, change the blue
// sphere's colour (material 4), trace, copy the traced image (RGBA8 words) into the swapchain image, present.
template <class Record>
void presentFrames(Context& c, int frames, uint32_t width, uint32_t height, const Buffer& image, const Buffer& mats,
                   const Record& recordTrace) {
  auto createSurface =
      reinterpret_cast<PFN_vkCreateHeadlessSurfaceEXT>(vkGetInstanceProcAddr(c.instance, "vkCreateHeadlessSurfaceEXT"));
  if (!createSurface) {
    std::fprintf(stderr, "scene_demo: the driver has no vkCreateHeadlessSurfaceEXT\n");
    std::exit(1);
  }
  VkHeadlessSurfaceCreateInfoEXT hci{VK_STRUCTURE_TYPE_HEADLESS_SURFACE_CREATE_INFO_EXT};
  VkSurfaceKHR surface;
  CHECK(createSurface(c.instance, &hci, nullptr, &surface));
  VkBool32 supported = VK_FALSE;
  CHECK(vkGetPhysicalDeviceSurfaceSupportKHR(c.physical, 0, surface, &supported));
  VkSurfaceCapabilitiesKHR caps;
  CHECK(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(c.physical, surface, &caps));
  uint32_t n = 0;
  CHECK(vkGetPhysicalDeviceSurfaceFormatsKHR(c.physical, surface, &n, nullptr));
  std::vector<VkSurfaceFormatKHR> formats(n);
  CHECK(vkGetPhysicalDeviceSurfaceFormatsKHR(c.physical, surface, &n, formats.data()));
  const bool rgba = std::any_of(formats.begin(), formats.end(), [](const VkSurfaceFormatKHR& f) {
    return f.format == VK_FORMAT_R8G8B8A8_UNORM && f.colorSpace == VK_COLOR_SPACE_SRGB_NONLINEAR_KHR;
  });
  if (!supported || !rgba || !(caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_DST_BIT)) {
    std::fprintf(stderr, "scene_demo: the surface cannot take R8G8B8A8_UNORM images written by copies\n");
    std::exit(1);
  }
  VkSwapchainCreateInfoKHR sci{VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR};
  sci.surface = surface;
  sci.minImageCount = std::max(caps.minImageCount, 2u);
  sci.imageFormat = VK_FORMAT_R8G8B8A8_UNORM;
  sci.imageColorSpace = VK_COLOR_SPACE_SRGB_NONLINEAR_KHR;
  sci.imageExtent = {width, height};
  sci.imageArrayLayers = 1;
  sci.imageUsage = VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  sci.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
  sci.preTransform = VK_SURFACE_TRANSFORM_IDENTITY_BIT_KHR;
  sci.compositeAlpha = VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR;
  sci.presentMode = VK_PRESENT_MODE_FIFO_KHR;
  sci.clipped = VK_TRUE;
  VkSwapchainKHR swapchain;
  CHECK(vkCreateSwapchainKHR(c.device, &sci, nullptr, &swapchain));
  CHECK(vkGetSwapchainImagesKHR(c.device, swapchain, &n, nullptr));
  std::vector<VkImage> images(n);
  CHECK(vkGetSwapchainImagesKHR(c.device, swapchain, &n, images.data()));

  VkSemaphoreCreateInfo semInfo{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
  VkSemaphore acquired, rendered;
  CHECK(vkCreateSemaphore(c.device, &semInfo, nullptr, &acquired));
  CHECK(vkCreateSemaphore(c.device, &semInfo, nullptr, &rendered));
  VkFenceCreateInfo fenceInfo{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  fenceInfo.flags = VK_FENCE_CREATE_SIGNALED_BIT;
  VkFence done;
  CHECK(vkCreateFence(c.device, &fenceInfo, nullptr, &done));
  VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  ai.commandPool = c.pool;
  ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ai.commandBufferCount = 1;
  VkCommandBuffer cb;
  CHECK(vkAllocateCommandBuffers(c.device, &ai, &cb));

  for (int f = 0; f < frames; ++f) {
    // The previous frame's commands have run: its semaphores, command buffer and buffers may be reused.
    CHECK(vkWaitForFences(c.device, 1, &done, VK_TRUE, UINT64_MAX));
    CHECK(vkResetFences(c.device, 1, &done));
    uint32_t index = 0;
    CHECK(vkAcquireNextImageKHR(c.device, swapchain, UINT64_MAX, acquired, VK_NULL_HANDLE, &index));
    CHECK(vkResetCommandBuffer(cb, 0));
    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    CHECK(vkBeginCommandBuffer(cb, &bi));
    const float t = float(f) / float(std::max(frames - 1, 1));
    const float blue[4] = {0.15f + 0.7f * t, 0.3f, 0.8f - 0.5f * t, 0};
    vkCmdUpdateBuffer(cb, mats.buffer, 4 * sizeof blue, sizeof blue, blue);
    VkMemoryBarrier mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    mb.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    mb.dstAccessMask = VK_ACCESS_SHADER_READ_BIT;
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_RAY_TRACING_SHADER_BIT_KHR, 0, 1, &mb, 0,
                         nullptr, 0, nullptr);
    recordTrace(cb);
    VkBufferMemoryBarrier traced{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER};
    traced.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
    traced.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
    traced.srcQueueFamilyIndex = traced.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    traced.buffer = image.buffer;
    traced.size = VK_WHOLE_SIZE;
    VkImageMemoryBarrier toDst{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    toDst.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    toDst.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    toDst.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    toDst.srcQueueFamilyIndex = toDst.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    toDst.image = images[index];
    toDst.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_RAY_TRACING_SHADER_BIT_KHR, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0,
                         nullptr, 1, &traced, 1, &toDst);
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {width, height, 1};
    vkCmdCopyBufferToImage(cb, image.buffer, images[index], VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
    VkImageMemoryBarrier toPresent = toDst;
    toPresent.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    toPresent.dstAccessMask = 0;
    toPresent.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    toPresent.newLayout = VK_IMAGE_LAYOUT_PRESENT_SRC_KHR;
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, 0, 0, nullptr, 0,
                         nullptr, 1, &toPresent);
    CHECK(vkEndCommandBuffer(cb));
    const VkPipelineStageFlags waitStage = VK_PIPELINE_STAGE_TRANSFER_BIT;
    VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    si.waitSemaphoreCount = 1;
    si.pWaitSemaphores = &acquired;
    si.pWaitDstStageMask = &waitStage;
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cb;
    si.signalSemaphoreCount = 1;
    si.pSignalSemaphores = &rendered;
    CHECK(vkQueueSubmit(c.queue, 1, &si, done));
    VkPresentInfoKHR pi{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
    pi.waitSemaphoreCount = 1;
    pi.pWaitSemaphores = &rendered;
    pi.swapchainCount = 1;
    pi.pSwapchains = &swapchain;
    pi.pImageIndices = &index;
    CHECK(vkQueuePresentKHR(c.queue, &pi));
  }
  CHECK(vkQueueWaitIdle(c.queue));
  vkFreeCommandBuffers(c.device, c.pool, 1, &cb);
  vkDestroyFence(c.device, done, nullptr);
  vkDestroySemaphore(c.device, rendered, nullptr);
  vkDestroySemaphore(c.device, acquired, nullptr);
  vkDestroySwapchainKHR(c.device, swapchain, nullptr);
  vkDestroySurfaceKHR(c.instance, surface, nullptr);
}

}  // namespace

int main(int argc, char** argv) {
  example::gProgram = "scene_demo";
  uint32_t width = 800, height = 600;
  std::string out = "scene.png";
  int frames = 0;
  bool bad = false;
  for (int i = 1; i < argc; i += 2) {
    std::string a = argv[i];
    if (i + 1 >= argc)
      bad = true;
    else if (a == "--width")
      width = uint32_t(std::atoi(argv[i + 1]));
    else if (a == "--height")
      height = uint32_t(std::atoi(argv[i + 1]));
    else if (a == "--out")
      out = argv[i + 1];
    else if (a == "--present")
      frames = std::atoi(argv[i + 1]);
    else
      bad = true;
  }
  if (bad || width == 0 || height == 0 || frames < 0) {
    std::fprintf(stderr, "usage: scene_demo [--width W] [--height H] [--out file.png] [--present N]\n");
    return 2;
  }
  Context c;
  c.present = frames > 0;
  createDevice(c);
  std::vector<float> triangleTable, sphereTable;
  const auto t0 = std::chrono::steady_clock::now();
  VkAccelerationStructureKHR tlas = buildScene(c, &triangleTable, &sphereTable);
  Pipeline p = createPipeline(c);
  const auto t1 = std::chrono::steady_clock::now();

  // Shader binding table: raygen | miss, shadow miss | opaque, alpha-tested, sphere hit groups.
  const uint32_t hs = c.rt.shaderGroupHandleSize, groups = 6;
  std::vector<uint8_t> handles(size_t(hs) * groups);
  CHECK(c.groupHandles(c.device, p.pipeline, 0, groups, handles.size(), handles.data()));
  const uint64_t stride =
      (hs + c.rt.shaderGroupHandleAlignment - 1) / c.rt.shaderGroupHandleAlignment * c.rt.shaderGroupHandleAlignment;
  const uint64_t base = c.rt.shaderGroupBaseAlignment;
  const uint64_t raygenAt = 0, missAt = base, hitAt = 2 * base;
  Buffer sbt = c.buffer(4 * base, VK_BUFFER_USAGE_SHADER_BINDING_TABLE_BIT_KHR);
  const VkDeviceAddress sbtBase = (sbt.address + base - 1) / base * base;
  uint8_t* bytes = static_cast<uint8_t*>(sbt.data) + (sbtBase - sbt.address);
  std::memcpy(bytes + raygenAt, handles.data(), hs);
  for (uint32_t k = 0; k < 2; ++k) std::memcpy(bytes + missAt + k * stride, handles.data() + (1 + k) * hs, hs);
  for (uint32_t k = 0; k < 3; ++k) std::memcpy(bytes + hitAt + k * stride, handles.data() + (3 + k) * hs, hs);
  VkStridedDeviceAddressRegionKHR raygenRegion{sbtBase + raygenAt, stride, stride},
      missRegion{sbtBase + missAt, stride, 2 * stride}, hitRegion{sbtBase + hitAt, stride, 3 * stride},
      callableRegion{};

  // Resources: the image (RGBA8 words), the triangle, sphere and material tables.
  Buffer image =
      c.buffer(uint64_t(width) * height * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  Buffer tris = c.upload(triangleTable, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  Buffer spheres = c.upload(sphereTable, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  std::vector<float> materials(&kMaterials[0][0], &kMaterials[0][0] + sizeof kMaterials / sizeof(float));
  Buffer mats = c.upload(materials, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  VkDescriptorPool pool;
  const VkDescriptorSet set =
      c.sceneSet(p.setLayout, tlas, {image.buffer, tris.buffer, spheres.buffer, mats.buffer}, &pool);

  auto recordTrace = [&](VkCommandBuffer cb) {
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, p.pipeline);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, p.layout, 0, 1, &set, 0, nullptr);
    c.setStackSize(cb, uint32_t(p.stackSize));
    c.traceRays(cb, &raygenRegion, &missRegion, &hitRegion, &callableRegion, width, height, 1);
  };
  const auto t2 = std::chrono::steady_clock::now();
  if (frames == 0) {
    VkCommandBuffer cb = c.begin();
    recordTrace(cb);
    c.submit(cb);
  } else {
    presentFrames(c, frames, width, height, image, mats, recordTrace);
  }
  const auto t3 = std::chrono::steady_clock::now();

  if (!stbi_write_png(out.c_str(), int(width), int(height), 4, image.data, int(width * 4))) {
    std::fprintf(stderr, "scene_demo: could not write %s\n", out.c_str());
    return 1;
  }
  const double trace = std::chrono::duration<double>(t3 - t2).count();
  const double setup = std::chrono::duration<double>(t1 - t0).count();
  std::printf(
      "scene_demo: %ux%u, 4 camera rays a pixel, traced in %.3f s (%.2f M camera rays/s); acceleration structures "
      "and pipeline in %.3f s\n",
      width, height, trace, 4.0 * width * height * std::max(frames, 1) / trace / 1e6, setup);
  if (frames) std::printf("scene_demo: presented %d frames through a headless swapchain\n", frames);
  std::printf("scene_demo: wrote %s\n", out.c_str());
  return 0;
}
