// What the ray tracing examples (scene_demo, pathtracer) share: error exits, host-visible buffers with device
// addresses, one-shot command buffers, the ray tracing entry points, and acceleration structure builds. Plain Vulkan
// through the loader; nothing here knows which driver runs it.
#pragma once

#include <vulkan/vulkan.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "example_fail.hpp"
#include "runtime/vk_compat.h"  // tokens newer than Debian 12's Vulkan headers (VK_EXT_pipeline_library_group_handles)

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
    VkPhysicalDeviceMemoryProperties mp;
    vkGetPhysicalDeviceMemoryProperties(physical, &mp);
    const VkMemoryPropertyFlags want = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    const VkMemoryPropertyFlags prefer =
        readBack ? VK_MEMORY_PROPERTY_HOST_CACHED_BIT : VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
    uint32_t type = UINT32_MAX;
    for (VkMemoryPropertyFlags flags : {want | prefer, want})
      for (uint32_t i = 0; i < mp.memoryTypeCount && type == UINT32_MAX; ++i)
        if ((req.memoryTypeBits & (1u << i)) && (mp.memoryTypes[i].propertyFlags & flags) == flags) type = i;
    if (type == UINT32_MAX) fail("no host-visible coherent memory type for a buffer");
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
