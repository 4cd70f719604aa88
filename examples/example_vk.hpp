// What the examples (scene_demo, pathtracer, hybrid) and bench/rasterbench share: error exits, instance and device
// creation, memory types, images with a view, the colour + depth render pass; and, for the ray tracing examples
// (example::Context), host-visible buffers with device addresses, one-shot command buffers, the ray tracing entry
// points and acceleration structure builds. Plain Vulkan through the loader; nothing here knows which driver runs it.
#pragma once

#include <vulkan/vulkan.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <initializer_list>
#include <string>
#include <vector>

#include "example_fail.hpp"

namespace example {

#define CHECK(call)                                                                                          \
  do {                                                                                                       \
    VkResult r_ = (call);                                                                                    \
    if (r_ != VK_SUCCESS) example::fail(std::string(#call) + " failed with VkResult " + std::to_string(r_)); \
  } while (0)

template <class F>
F load(VkDevice dev, const char* name) {
  auto f = reinterpret_cast<F>(vkGetDeviceProcAddr(dev, name));
  if (!f) fail(std::string("the driver has no ") + name);
  return f;
}

// ------------------------------------------------------------------------------------ instance and device

// A Vulkan 1.3 instance (the examples' shaders are SPIR-V 1.6) for the application `app`, with `extensions`.
inline VkInstance createInstance(const char* app, const std::vector<const char*>& extensions = {}) {
  VkApplicationInfo ai{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  ai.pApplicationName = app;
  ai.apiVersion = VK_API_VERSION_1_3;
  VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  ici.pApplicationInfo = &ai;
  ici.enabledExtensionCount = uint32_t(extensions.size());
  ici.ppEnabledExtensionNames = extensions.data();
  VkInstance instance;
  CHECK(vkCreateInstance(&ici, nullptr, &instance));
  return instance;
}

// The first physical device of `instance` that `accept` takes (the first of all when `accept` is empty); fails
// with `missing` when there is none.
inline VkPhysicalDevice pickPhysicalDevice(VkInstance instance,
                                           const std::function<bool(VkPhysicalDevice)>& accept = {},
                                           const char* missing = "no Vulkan device") {
  uint32_t n = 0;
  CHECK(vkEnumeratePhysicalDevices(instance, &n, nullptr));
  std::vector<VkPhysicalDevice> devices(n);
  CHECK(vkEnumeratePhysicalDevices(instance, &n, devices.data()));
  for (VkPhysicalDevice d : devices)
    if (!accept || accept(d)) return d;
  fail(missing);
}

// The first queue family of `physical` with every flag of `flags`; fails when there is none.
inline uint32_t queueFamily(VkPhysicalDevice physical, VkQueueFlags flags) {
  uint32_t n = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(physical, &n, nullptr);
  std::vector<VkQueueFamilyProperties> families(n);
  vkGetPhysicalDeviceQueueFamilyProperties(physical, &n, families.data());
  for (uint32_t i = 0; i < n; ++i)
    if ((families[i].queueFlags & flags) == flags) return i;
  fail("the device has no queue family with flags 0x" + std::to_string(flags));
}

// A device with one queue of `family`, the feature structures chained from `features` (null for none; a
// VkPhysicalDeviceFeatures2 or any feature structure) and `extensions`.
inline VkDevice createDevice(VkPhysicalDevice physical, uint32_t family, const void* features,
                             const std::vector<const char*>& extensions = {}) {
  const float priority = 1;
  VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  qci.queueFamilyIndex = family;
  qci.queueCount = 1;
  qci.pQueuePriorities = &priority;
  VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, features};
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qci;
  dci.enabledExtensionCount = uint32_t(extensions.size());
  dci.ppEnabledExtensionNames = extensions.data();
  VkDevice device;
  CHECK(vkCreateDevice(physical, &dci, nullptr, &device));
  return device;
}

// ------------------------------------------------------------------------------- memory, images, render pass

// A memory type of `physical` allowed by `allowed` (VkMemoryRequirements::memoryTypeBits) with every flag of the
// first set in `choices` that some allowed type has; fails with `what` when no set matches.
inline uint32_t memoryType(VkPhysicalDevice physical, uint32_t allowed,
                           std::initializer_list<VkMemoryPropertyFlags> choices, const char* what) {
  VkPhysicalDeviceMemoryProperties mp;
  vkGetPhysicalDeviceMemoryProperties(physical, &mp);
  for (VkMemoryPropertyFlags flags : choices)
    for (uint32_t i = 0; i < mp.memoryTypeCount; ++i)
      if ((allowed & (1u << i)) && (mp.memoryTypes[i].propertyFlags & flags) == flags) return i;
  fail(std::string("no memory type for ") + what);
}

// A 2D image, its memory (device-local where the device has it) and a view of all its `levels` mip levels.
struct Image {
  VkImage image = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;
};

// A width x height image of `format` with `levels` mip levels, optimal tiling, one sample, bound to memory, and a
// 2D view of `aspect`.
inline Image createImage(VkDevice device, VkPhysicalDevice physical, VkFormat format, uint32_t width, uint32_t height,
                         uint32_t levels, VkImageUsageFlags usage, VkImageAspectFlags aspect) {
  Image im;
  VkImageCreateInfo ici{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  ici.imageType = VK_IMAGE_TYPE_2D;
  ici.format = format;
  ici.extent = {width, height, 1};
  ici.mipLevels = levels;
  ici.arrayLayers = 1;
  ici.samples = VK_SAMPLE_COUNT_1_BIT;
  ici.tiling = VK_IMAGE_TILING_OPTIMAL;
  ici.usage = usage;
  CHECK(vkCreateImage(device, &ici, nullptr, &im.image));
  VkMemoryRequirements req;
  vkGetImageMemoryRequirements(device, im.image, &req);
  VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  mai.allocationSize = req.size;
  mai.memoryTypeIndex = memoryType(physical, req.memoryTypeBits, {VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, 0}, "an image");
  CHECK(vkAllocateMemory(device, &mai, nullptr, &im.memory));
  CHECK(vkBindImageMemory(device, im.image, im.memory, 0));
  VkImageViewCreateInfo vci{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
  vci.image = im.image;
  vci.viewType = VK_IMAGE_VIEW_TYPE_2D;
  vci.format = format;
  vci.subresourceRange = {aspect, 0, levels, 0, 1};
  CHECK(vkCreateImageView(device, &vci, nullptr, &im.view));
  return im;
}

inline void destroyImage(VkDevice device, const Image& im) {
  vkDestroyImageView(device, im.view, nullptr);
  vkDestroyImage(device, im.image, nullptr);
  vkFreeMemory(device, im.memory, nullptr);
}

// One subpass drawing into a colour attachment of `colorFormat` and a depth attachment of `depthFormat`, both
// cleared at the start; the colour image ends in TRANSFER_SRC_OPTIMAL, ready to be copied out, and the depth
// image's contents are not kept. Its dependencies let a command buffer render the pass again and again: the pass
// waits for the copy of the previous frame and its depth writes, and the copy after the pass waits for the pass.
inline VkRenderPass createColorDepthRenderPass(VkDevice device, VkFormat colorFormat, VkFormat depthFormat) {
  VkAttachmentDescription at[2] = {};
  at[0].format = colorFormat;
  at[0].samples = VK_SAMPLE_COUNT_1_BIT;
  at[0].loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
  at[0].storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  at[0].stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
  at[0].stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
  at[0].initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  at[0].finalLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
  at[1] = at[0];
  at[1].format = depthFormat;
  at[1].storeOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
  at[1].finalLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
  VkAttachmentReference color{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
  VkAttachmentReference depth{1, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
  VkSubpassDescription sub{};
  sub.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
  sub.colorAttachmentCount = 1;
  sub.pColorAttachments = &color;
  sub.pDepthStencilAttachment = &depth;
  VkSubpassDependency deps[2] = {};
  deps[0].srcSubpass = VK_SUBPASS_EXTERNAL;
  deps[0].dstSubpass = 0;
  deps[0].srcStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT;
  deps[0].dstStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT;
  deps[0].srcAccessMask = VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
  deps[0].dstAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
  deps[1].srcSubpass = 0;
  deps[1].dstSubpass = VK_SUBPASS_EXTERNAL;
  deps[1].srcStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
  deps[1].dstStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT;
  deps[1].srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
  deps[1].dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
  VkRenderPassCreateInfo rpci{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
  rpci.attachmentCount = 2;
  rpci.pAttachments = at;
  rpci.subpassCount = 1;
  rpci.pSubpasses = &sub;
  rpci.dependencyCount = 2;
  rpci.pDependencies = deps;
  VkRenderPass rp;
  CHECK(vkCreateRenderPass(device, &rpci, nullptr, &rp));
  return rp;
}

// A width x height framebuffer of `renderPass` over the colour and depth views.
inline VkFramebuffer createFramebuffer(VkDevice device, VkRenderPass renderPass, VkImageView color, VkImageView depth,
                                       uint32_t width, uint32_t height) {
  const VkImageView views[2] = {color, depth};
  VkFramebufferCreateInfo fci{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
  fci.renderPass = renderPass;
  fci.attachmentCount = 2;
  fci.pAttachments = views;
  fci.width = width;
  fci.height = height;
  fci.layers = 1;
  VkFramebuffer fb;
  CHECK(vkCreateFramebuffer(device, &fci, nullptr, &fb));
  return fb;
}

// ----------------------------------------------------------------------------------- ray tracing examples

struct Buffer {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  void* data = nullptr;
  VkDeviceAddress address = 0;
  VkDeviceSize size = 0;
};

struct Built {
  VkAccelerationStructureKHR as = VK_NULL_HANDLE;
  VkDeviceAddress address = 0;
};

// A shader group: its type and its general, closest-hit, any-hit and intersection shaders (VK_SHADER_UNUSED_KHR
// where none).
inline VkRayTracingShaderGroupCreateInfoKHR group(VkRayTracingShaderGroupTypeKHR type, uint32_t general,
                                                  uint32_t closestHit, uint32_t anyHit, uint32_t intersection) {
  VkRayTracingShaderGroupCreateInfoKHR r{VK_STRUCTURE_TYPE_RAY_TRACING_SHADER_GROUP_CREATE_INFO_KHR};
  r.type = type;
  r.generalShader = general;
  r.closestHitShader = closestHit;
  r.anyHitShader = anyHit;
  r.intersectionShader = intersection;
  return r;
}

// A device with a queue and a command pool (the program creates them), the ray tracing entry points, and the
// buffers and acceleration structures it made (destroy() frees them with the device).
struct Context {
  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
  uint32_t queueFamily = 0;
  VkCommandPool pool = VK_NULL_HANDLE;
  VkPhysicalDeviceRayTracingPipelinePropertiesKHR rt{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_PROPERTIES_KHR};
  std::vector<Buffer> buffers;
  std::vector<VkAccelerationStructureKHR> structures;
  PFN_vkGetAccelerationStructureBuildSizesKHR buildSizes = nullptr;
  PFN_vkCreateAccelerationStructureKHR createAs = nullptr;
  PFN_vkDestroyAccelerationStructureKHR destroyAs = nullptr;
  PFN_vkCmdBuildAccelerationStructuresKHR cmdBuild = nullptr;
  PFN_vkGetAccelerationStructureDeviceAddressKHR asAddress = nullptr;
  PFN_vkCreateRayTracingPipelinesKHR createPipelines = nullptr;
  PFN_vkGetRayTracingShaderGroupHandlesKHR groupHandles = nullptr;
  PFN_vkGetRayTracingShaderGroupStackSizeKHR groupStackSize = nullptr;
  PFN_vkCmdSetRayTracingPipelineStackSizeKHR setStackSize = nullptr;
  PFN_vkCmdTraceRaysKHR traceRays = nullptr;

  // Creates the instance (with `instanceExtensions`), takes the first physical device that `accept` takes (see
  // pickPhysicalDevice), reads its ray tracing properties into `rt`, prints "<program>: device <name>", and creates
  // the device with one queue of the first family with `queueFlags`, the feature chain `features` and
  // `deviceExtensions` (which must hold VK_KHR_ray_tracing_pipeline and VK_KHR_acceleration_structure: every ray
  // tracing entry point is loaded); then the queue and the command pool.
  void open(VkQueueFlags queueFlags, const void* features, const std::vector<const char*>& deviceExtensions,
            const std::vector<const char*>& instanceExtensions = {},
            const std::function<bool(VkPhysicalDevice)>& accept = {}, const char* missing = "no Vulkan device") {
    instance = createInstance(gProgram, instanceExtensions);
    physical = pickPhysicalDevice(instance, accept, missing);
    VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &rt};
    vkGetPhysicalDeviceProperties2(physical, &p2);
    std::printf("%s: device %s\n", gProgram, p2.properties.deviceName);
    queueFamily = example::queueFamily(physical, queueFlags);
    device = createDevice(physical, queueFamily, features, deviceExtensions);
    deviceCreated();
  }

  // After vkCreateDevice: the queue, a command pool, and the ray tracing entry points.
  void deviceCreated() {
    vkGetDeviceQueue(device, queueFamily, 0, &queue);
    VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pci.queueFamilyIndex = queueFamily;
    CHECK(vkCreateCommandPool(device, &pci, nullptr, &pool));
    buildSizes = load<PFN_vkGetAccelerationStructureBuildSizesKHR>(device, "vkGetAccelerationStructureBuildSizesKHR");
    createAs = load<PFN_vkCreateAccelerationStructureKHR>(device, "vkCreateAccelerationStructureKHR");
    destroyAs = load<PFN_vkDestroyAccelerationStructureKHR>(device, "vkDestroyAccelerationStructureKHR");
    cmdBuild = load<PFN_vkCmdBuildAccelerationStructuresKHR>(device, "vkCmdBuildAccelerationStructuresKHR");
    asAddress =
        load<PFN_vkGetAccelerationStructureDeviceAddressKHR>(device, "vkGetAccelerationStructureDeviceAddressKHR");
    createPipelines = load<PFN_vkCreateRayTracingPipelinesKHR>(device, "vkCreateRayTracingPipelinesKHR");
    groupHandles = load<PFN_vkGetRayTracingShaderGroupHandlesKHR>(device, "vkGetRayTracingShaderGroupHandlesKHR");
    groupStackSize = load<PFN_vkGetRayTracingShaderGroupStackSizeKHR>(device, "vkGetRayTracingShaderGroupStackSizeKHR");
    setStackSize = load<PFN_vkCmdSetRayTracingPipelineStackSizeKHR>(device, "vkCmdSetRayTracingPipelineStackSizeKHR");
    traceRays = load<PFN_vkCmdTraceRaysKHR>(device, "vkCmdTraceRaysKHR");
  }

  // A host-visible buffer with a device address, mapped. Device-local where the device has host-visible device
  // memory (a GPU's BAR), else any host-visible coherent memory; host-cached first for what the host reads back.
  Buffer buffer(VkDeviceSize size, VkBufferUsageFlags usage, bool readBack = false) {
    Buffer b;
    b.size = size;
    VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    bci.size = size;
    bci.usage = usage | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;
    CHECK(vkCreateBuffer(device, &bci, nullptr, &b.buffer));
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(device, b.buffer, &req);
    const VkMemoryPropertyFlags want = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    const VkMemoryPropertyFlags prefer =
        readBack ? VK_MEMORY_PROPERTY_HOST_CACHED_BIT : VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
    const uint32_t type = memoryType(physical, req.memoryTypeBits, {want | prefer, want}, "a host-visible buffer");
    VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
    flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
    VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, &flags};
    mai.allocationSize = req.size;
    mai.memoryTypeIndex = type;
    CHECK(vkAllocateMemory(device, &mai, nullptr, &b.memory));
    CHECK(vkBindBufferMemory(device, b.buffer, b.memory, 0));
    CHECK(vkMapMemory(device, b.memory, 0, VK_WHOLE_SIZE, 0, &b.data));
    VkBufferDeviceAddressInfo ai{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO};
    ai.buffer = b.buffer;
    b.address = vkGetBufferDeviceAddress(device, &ai);
    buffers.push_back(b);
    return b;
  }
  template <class T>
  Buffer upload(const std::vector<T>& v, VkBufferUsageFlags usage) {
    Buffer b = buffer(std::max<VkDeviceSize>(v.size() * sizeof(T), 16), usage);
    if (!v.empty()) std::memcpy(b.data, v.data(), v.size() * sizeof(T));
    return b;
  }

  VkCommandBuffer begin() {
    VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    ai.commandPool = pool;
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = 1;
    VkCommandBuffer cb;
    CHECK(vkAllocateCommandBuffers(device, &ai, &cb));
    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    CHECK(vkBeginCommandBuffer(cb, &bi));
    return cb;
  }
  // Ends, submits and waits for `cb`, then frees it.
  void submit(VkCommandBuffer cb) {
    CHECK(vkEndCommandBuffer(cb));
    VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cb;
    CHECK(vkQueueSubmit(queue, 1, &si, VK_NULL_HANDLE));
    CHECK(vkQueueWaitIdle(queue));
    vkFreeCommandBuffers(device, pool, 1, &cb);
  }

  // Builds an acceleration structure of `type` from the geometries (primitives[i] primitives in g[i]), on the
  // device, PREFER_FAST_TRACE, and waits for it.
  Built build(VkAccelerationStructureTypeKHR type, const std::vector<VkAccelerationStructureGeometryKHR>& g,
              const std::vector<uint32_t>& primitives) {
    VkAccelerationStructureBuildGeometryInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
    info.type = type;
    info.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
    info.geometryCount = uint32_t(g.size());
    info.pGeometries = g.data();
    VkAccelerationStructureBuildSizesInfoKHR sizes{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
    buildSizes(device, VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &info, primitives.data(), &sizes);
    Buffer storage = buffer(sizes.accelerationStructureSize, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR);
    // minAccelerationStructureScratchOffsetAlignment is at most 256 (the spec's required limit).
    Buffer scratch = buffer(sizes.buildScratchSize + 256, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    VkAccelerationStructureCreateInfoKHR ci{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
    ci.buffer = storage.buffer;
    ci.size = sizes.accelerationStructureSize;
    ci.type = type;
    Built b;
    CHECK(createAs(device, &ci, nullptr, &b.as));
    structures.push_back(b.as);
    info.dstAccelerationStructure = b.as;
    info.scratchData.deviceAddress = (scratch.address + 255) / 256 * 256;
    std::vector<VkAccelerationStructureBuildRangeInfoKHR> ranges;
    for (uint32_t p : primitives) ranges.push_back({p, 0, 0, 0});
    const VkAccelerationStructureBuildRangeInfoKHR* pr = ranges.data();
    VkCommandBuffer cb = begin();
    cmdBuild(cb, 1, &info, &pr);
    submit(cb);
    VkAccelerationStructureDeviceAddressInfoKHR ai{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR};
    ai.accelerationStructure = b.as;
    b.address = asAddress(device, &ai);
    return b;
  }

  // A top-level structure over `instances` (uploaded to a build-input buffer).
  Built buildTopLevel(const std::vector<VkAccelerationStructureInstanceKHR>& instances) {
    VkAccelerationStructureGeometryKHR ig{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
    ig.geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;
    ig.geometry.instances.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR;
    ig.geometry.instances.data.deviceAddress =
        upload(instances, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR).address;
    return build(VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, {ig}, {uint32_t(instances.size())});
  }

  VkShaderModule shaderModule(const uint32_t* words, size_t bytes) {
    VkShaderModuleCreateInfo ci{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    ci.codeSize = bytes;
    ci.pCode = words;
    VkShaderModule m;
    CHECK(vkCreateShaderModule(device, &ci, nullptr, &m));
    return m;
  }

  // A descriptor set of `layout` from a pool of its own (*pool, for the caller to destroy): binding 0 the top-level
  // structure, bindings 1, 2, ... the whole of each buffer, as storage buffers.
  VkDescriptorSet sceneSet(VkDescriptorSetLayout layout, VkAccelerationStructureKHR tlas,
                           const std::vector<VkBuffer>& storage, VkDescriptorPool* pool) {
    VkDescriptorPoolSize sizes[2] = {{VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 1},
                                     {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, uint32_t(storage.size())}};
    VkDescriptorPoolCreateInfo dpci{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    dpci.maxSets = 1;
    dpci.poolSizeCount = 2;
    dpci.pPoolSizes = sizes;
    CHECK(vkCreateDescriptorPool(device, &dpci, nullptr, pool));
    VkDescriptorSetAllocateInfo dai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    dai.descriptorPool = *pool;
    dai.descriptorSetCount = 1;
    dai.pSetLayouts = &layout;
    VkDescriptorSet set;
    CHECK(vkAllocateDescriptorSets(device, &dai, &set));
    VkWriteDescriptorSetAccelerationStructureKHR asw{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_KHR};
    asw.accelerationStructureCount = 1;
    asw.pAccelerationStructures = &tlas;
    std::vector<VkDescriptorBufferInfo> infos;
    for (VkBuffer b : storage) infos.push_back({b, 0, VK_WHOLE_SIZE});
    std::vector<VkWriteDescriptorSet> w(storage.size() + 1, {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET});
    for (uint32_t i = 0; i < w.size(); ++i) {
      w[i].dstSet = set;
      w[i].dstBinding = i;
      w[i].descriptorCount = 1;
      w[i].descriptorType = i == 0 ? VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
      if (i) w[i].pBufferInfo = &infos[i - 1];
    }
    w[0].pNext = &asw;
    vkUpdateDescriptorSets(device, uint32_t(w.size()), w.data(), 0, nullptr);
    return set;
  }

  // Frees what the context made, then the device and the instance.
  void destroy() {
    for (VkAccelerationStructureKHR as : structures) destroyAs(device, as, nullptr);
    for (const Buffer& b : buffers) {
      vkDestroyBuffer(device, b.buffer, nullptr);
      vkFreeMemory(device, b.memory, nullptr);
    }
    vkDestroyCommandPool(device, pool, nullptr);
    vkDestroyDevice(device, nullptr);
    vkDestroyInstance(instance, nullptr);
  }
};

}  // namespace example
