#include "bench_common.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <iterator>

namespace vkrt::bench {

void fail(const char* what, VkResult r) {
  std::fprintf(stderr, "vkrt benchmark: %s failed (VkResult %d)\n", what, int(r));
  std::exit(1);
}

namespace {

bool hasAll(const std::vector<VkExtensionProperties>& available, const std::vector<const char*>& wanted) {
  return std::all_of(wanted.begin(), wanted.end(), [&](const char* e) {
    return std::any_of(available.begin(), available.end(),
                       [&](const VkExtensionProperties& p) { return std::strcmp(p.extensionName, e) == 0; });
  });
}

}  // namespace

Context::Context() {
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "vkrt_bench";
  app.apiVersion = VK_API_VERSION_1_3;
  VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  ici.pApplicationInfo = &app;
  CHECK(vkCreateInstance(&ici, nullptr, &instance));
  uint32_t count = 1;
  VkResult r = vkEnumeratePhysicalDevices(instance, &count, &physical);
  if ((r != VK_SUCCESS && r != VK_INCOMPLETE) || count == 0) fail("vkEnumeratePhysicalDevices", r);
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(physical, &props);
  std::fprintf(stderr, "device: %s\n", props.deviceName);
  float priority = 1;
  VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  qci.queueCount = 1;
  qci.pQueuePriorities = &priority;
  uint32_t available = 0;
  vkEnumerateDeviceExtensionProperties(physical, nullptr, &available, nullptr);
  std::vector<VkExtensionProperties> props2(available);
  vkEnumerateDeviceExtensionProperties(physical, nullptr, &available, props2.data());
  // Acceleration structures, then ray queries and ray tracing pipelines each where the driver has them (NVIDIA's
  // driver on the device machine has pipelines but no ray queries: the trace benchmark runs there too).
  std::vector<const char*> extensions = {VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME,
                                         VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME};
  const bool accelerationStructures = hasAll(props2, extensions);
  rayQuery = accelerationStructures && hasAll(props2, {VK_KHR_RAY_QUERY_EXTENSION_NAME});
  rayTracingPipeline = accelerationStructures && hasAll(props2, {VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME});
  if (rayQuery) extensions.push_back(VK_KHR_RAY_QUERY_EXTENSION_NAME);
  if (rayTracingPipeline) extensions.push_back(VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME);
  VkPhysicalDeviceVulkan13Features f13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
  f13.maintenance4 = VK_TRUE;
  VkPhysicalDeviceRayTracingPipelineFeaturesKHR rtf{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_FEATURES_KHR};
  rtf.rayTracingPipeline = VK_TRUE;
  VkPhysicalDeviceRayQueryFeaturesKHR rqf{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR,
                                          rayTracingPipeline ? &rtf : nullptr};
  rqf.rayQuery = VK_TRUE;
  VkPhysicalDeviceAccelerationStructureFeaturesKHR asf{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR, rayQuery ? static_cast<void*>(&rqf)
                                                                             : rayTracingPipeline
                                                                                 ? static_cast<void*>(&rtf)
                                                                                 : nullptr};
  asf.accelerationStructure = VK_TRUE;
  if (accelerationStructures) {
    VkPhysicalDeviceAccelerationStructureFeaturesKHR supported{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR};
    VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &supported};
    vkGetPhysicalDeviceFeatures2(physical, &f2);
    hostCommands = supported.accelerationStructureHostCommands;
    asf.accelerationStructureHostCommands = supported.accelerationStructureHostCommands;
  }
  VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES, &asf};
  f12.bufferDeviceAddress = VK_TRUE;
  if (accelerationStructures) f13.pNext = &f12;
  VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, &f13};
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qci;
  if (accelerationStructures) {
    dci.enabledExtensionCount = uint32_t(extensions.size());
    dci.ppEnabledExtensionNames = extensions.data();
  }
  CHECK(vkCreateDevice(physical, &dci, nullptr, &device));
  vkGetDeviceQueue(device, 0, 0, &queue);
  if (accelerationStructures) {
    load(createAs, "vkCreateAccelerationStructureKHR");
    load(destroyAs, "vkDestroyAccelerationStructureKHR");
    load(buildSizes, "vkGetAccelerationStructureBuildSizesKHR");
    load(cmdBuild, "vkCmdBuildAccelerationStructuresKHR");
    load(asAddress, "vkGetAccelerationStructureDeviceAddressKHR");
    load(createDeferred, "vkCreateDeferredOperationKHR");
    load(joinDeferred, "vkDeferredOperationJoinKHR");
    load(deferredResult, "vkGetDeferredOperationResultKHR");
    load(destroyDeferred, "vkDestroyDeferredOperationKHR");
  }
  if (hostCommands) load(hostBuild, "vkBuildAccelerationStructuresKHR");
  if (rayTracingPipeline) {
    load(createRtPipelines, "vkCreateRayTracingPipelinesKHR");
    load(groupHandles, "vkGetRayTracingShaderGroupHandlesKHR");
    load(cmdTraceRays, "vkCmdTraceRaysKHR");
  }
  VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  CHECK(vkCreateCommandPool(device, &pci, nullptr, &pool));
}

Context::~Context() {
  vkDestroyCommandPool(device, pool, nullptr);
  vkDestroyDevice(device, nullptr);
  vkDestroyInstance(instance, nullptr);
}

VkCommandBuffer Context::allocate() {
  VkCommandBufferAllocateInfo cai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  cai.commandPool = pool;
  cai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  cai.commandBufferCount = 1;
  VkCommandBuffer cb;
  CHECK(vkAllocateCommandBuffers(device, &cai, &cb));
  return cb;
}

void Context::submit(VkCommandBuffer cb) {
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cb;
  CHECK(vkQueueSubmit(queue, 1, &si, VK_NULL_HANDLE));
  CHECK(vkQueueWaitIdle(queue));
}

Context& ctx() {
  static Context c;
  return c;
}

Buffer::Buffer(VkDeviceSize bytes, VkBufferUsageFlags usage) : size(bytes) {
  VkDevice d = ctx().device;
  VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bci.size = bytes;
  bci.usage = usage;
  CHECK(vkCreateBuffer(d, &bci, nullptr, &buffer));
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(d, buffer, &req);
  VkPhysicalDeviceMemoryProperties mp;
  vkGetPhysicalDeviceMemoryProperties(ctx().physical, &mp);
  const VkMemoryPropertyFlags want = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  uint32_t type = 0;
  while (type < mp.memoryTypeCount &&
         !((req.memoryTypeBits >> type & 1) && (mp.memoryTypes[type].propertyFlags & want) == want))
    ++type;
  VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
  flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
  VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  if (usage & VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT) ai.pNext = &flags;
  ai.allocationSize = req.size;
  ai.memoryTypeIndex = type;
  CHECK(vkAllocateMemory(d, &ai, nullptr, &memory));
  CHECK(vkBindBufferMemory(d, buffer, memory, 0));
  CHECK(vkMapMemory(d, memory, 0, VK_WHOLE_SIZE, 0, &data));
}

Buffer::~Buffer() {
  vkDestroyBuffer(ctx().device, buffer, nullptr);
  vkFreeMemory(ctx().device, memory, nullptr);
}

VkDeviceAddress Buffer::address() const {
  VkBufferDeviceAddressInfo i{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO};
  i.buffer = buffer;
  return vkGetBufferDeviceAddress(ctx().device, &i);
}

AccelStructures::~AccelStructures() {
  // Top-level structures (built after what they instance) go first.
  for (auto as = structures.rbegin(); as != structures.rend(); ++as) ctx().destroyAs(ctx().device, *as, nullptr);
}

Buffer& AccelStructures::buffer(VkDeviceSize bytes, VkBufferUsageFlags usage) {
  buffers.push_back(std::make_unique<Buffer>(bytes, usage));
  return *buffers.back();
}

VkDeviceAddress AccelStructures::upload(const void* data, size_t bytes) {
  Buffer& b = buffer(bytes, kInput);
  std::memcpy(b.data, data, bytes);
  return b.address();
}

VkAccelerationStructureGeometryKHR AccelStructures::triangles(const float* vertices, size_t vertexCount,
                                                              const uint32_t* indices, size_t indexCount) {
  VkAccelerationStructureGeometryKHR g{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
  g.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
  g.flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
  auto& t = g.geometry.triangles;
  t.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
  t.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
  t.vertexData.deviceAddress = upload(vertices, vertexCount * 12);
  t.vertexStride = 12;
  t.maxVertex = uint32_t(vertexCount - 1);
  t.indexType = VK_INDEX_TYPE_UINT32;
  t.indexData.deviceAddress = upload(indices, indexCount * 4);
  return g;
}

VkAccelerationStructureGeometryKHR AccelStructures::instances(const VkAccelerationStructureInstanceKHR* in,
                                                              size_t count) {
  VkAccelerationStructureGeometryKHR ig{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
  ig.geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;
  ig.geometry.instances.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR;
  ig.geometry.instances.data.deviceAddress = upload(in, count * sizeof *in);
  return ig;
}

namespace {

// A structure of `type` for `g` in a new storage buffer of `structures`, and a command buffer that builds it.
VkAccelerationStructureKHR prepareBuild(AccelStructures& structures, VkAccelerationStructureTypeKHR type,
                                        const VkAccelerationStructureGeometryKHR& g, uint32_t primitives,
                                        VkCommandBuffer* cb) {
  Context& c = ctx();
  VkAccelerationStructureBuildGeometryInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
  info.type = type;
  info.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
  info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
  info.geometryCount = 1;
  info.pGeometries = &g;
  VkAccelerationStructureBuildSizesInfoKHR sizes{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
  c.buildSizes(c.device, VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &info, &primitives, &sizes);
  Buffer& storage =
      structures.buffer(sizes.accelerationStructureSize, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR |
                                                             VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT);
  VkAccelerationStructureCreateInfoKHR ci{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
  ci.buffer = storage.buffer;
  ci.size = sizes.accelerationStructureSize;
  ci.type = type;
  VkAccelerationStructureKHR as = VK_NULL_HANDLE;
  CHECK(c.createAs(c.device, &ci, nullptr, &as));
  Buffer& scratch = structures.buffer(sizes.buildScratchSize + 256,
                                      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT);
  info.dstAccelerationStructure = as;
  info.scratchData.deviceAddress = (scratch.address() + 255) / 256 * 256;
  VkAccelerationStructureBuildRangeInfoKHR range{primitives, 0, 0, 0};
  const VkAccelerationStructureBuildRangeInfoKHR* pr = &range;
  *cb = c.allocate();
  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  CHECK(vkBeginCommandBuffer(*cb, &bi));
  c.cmdBuild(*cb, 1, &info, &pr);
  // The builds and shaders after this one read what it wrote.
  VkMemoryBarrier mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  mb.srcAccessMask = VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR;
  mb.dstAccessMask = VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_KHR;
  vkCmdPipelineBarrier(*cb, VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
                       VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT |
                           VK_PIPELINE_STAGE_RAY_TRACING_SHADER_BIT_KHR,
                       0, 1, &mb, 0, nullptr, 0, nullptr);
  CHECK(vkEndCommandBuffer(*cb));
  return as;
}

}  // namespace

VkAccelerationStructureKHR AccelStructures::build(VkAccelerationStructureTypeKHR type,
                                                  const VkAccelerationStructureGeometryKHR& g, uint32_t primitives) {
  VkCommandBuffer cb;
  VkAccelerationStructureKHR as = prepareBuild(*this, type, g, primitives, &cb);
  structures.push_back(as);
  ctx().submit(cb);
  vkFreeCommandBuffers(ctx().device, ctx().pool, 1, &cb);
  return as;
}

double AccelStructures::timeBuilds(VkAccelerationStructureTypeKHR type, const VkAccelerationStructureGeometryKHR& g,
                                   uint32_t primitives, uint32_t repeat) {
  double best = 0;
  for (uint32_t i = 0; i < repeat; ++i) {
    AccelStructures fresh;  // its storage and scratch, freed after each build
    VkCommandBuffer cb;
    VkAccelerationStructureKHR as = prepareBuild(fresh, type, g, primitives, &cb);
    const double start = wallSeconds();
    ctx().submit(cb);
    const double took = wallSeconds() - start;
    if (i == 0 || took < best) best = took;
    vkFreeCommandBuffers(ctx().device, ctx().pool, 1, &cb);
    ctx().destroyAs(ctx().device, as, nullptr);
  }
  return best;
}

VkDeviceAddress AccelStructures::address(VkAccelerationStructureKHR as) const {
  VkAccelerationStructureDeviceAddressInfoKHR ai{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR};
  ai.accelerationStructure = as;
  return ctx().asAddress(ctx().device, &ai);
}

VkAccelerationStructureInstanceKHR AccelStructures::identityInstance(VkAccelerationStructureKHR blas) const {
  VkAccelerationStructureInstanceKHR in{};
  in.transform.matrix[0][0] = in.transform.matrix[1][1] = in.transform.matrix[2][2] = 1;
  in.mask = 0xff;
  in.accelerationStructureReference = address(blas);
  return in;
}

VkShaderModule shaderModule(const uint32_t* words, size_t bytes) {
  VkShaderModuleCreateInfo ci{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  ci.codeSize = bytes;
  ci.pCode = words;
  VkShaderModule m;
  CHECK(vkCreateShaderModule(ctx().device, &ci, nullptr, &m));
  return m;
}

namespace {

// A shader binding table for a ray tracing pipeline's first `count` groups: one record (one handle) per group, each
// in a region of its own at the base alignment; regions[i] is group i's {address, stride, size = stride}.
std::unique_ptr<Buffer> shaderBindingTable(VkPipeline pipeline, uint32_t count,
                                           VkStridedDeviceAddressRegionKHR* const* regions) {
  Context& c = ctx();
  auto alignUp = [](VkDeviceSize v, VkDeviceSize a) { return (v + a - 1) / a * a; };
  VkPhysicalDeviceRayTracingPipelinePropertiesKHR rt{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_PROPERTIES_KHR};
  VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &rt};
  vkGetPhysicalDeviceProperties2(c.physical, &p2);
  const VkDeviceSize handle = rt.shaderGroupHandleSize;
  const VkDeviceSize stride = alignUp(handle, rt.shaderGroupHandleAlignment);
  const VkDeviceSize region = alignUp(stride, rt.shaderGroupBaseAlignment);
  std::vector<uint8_t> handles(count * handle);
  CHECK(c.groupHandles(c.device, pipeline, 0, count, handles.size(), handles.data()));
  auto sbt = std::make_unique<Buffer>(
      count * region + rt.shaderGroupBaseAlignment,
      VK_BUFFER_USAGE_SHADER_BINDING_TABLE_BIT_KHR | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT);
  const VkDeviceAddress base = alignUp(sbt->address(), rt.shaderGroupBaseAlignment);
  for (uint32_t i = 0; i < count; ++i) {
    std::memcpy(sbt->as<uint8_t>() + (base - sbt->address()) + i * region, &handles[i * handle], handle);
    *regions[i] = {base + i * region, stride, stride};
  }
  return sbt;
}

VkDescriptorSet oneDescriptorSet(VkDescriptorSetLayout layout, const VkDescriptorPoolSize* sizes, uint32_t sizeCount,
                                 VkDescriptorPool* pool) {
  VkDescriptorPoolCreateInfo dp{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  dp.maxSets = 1;
  dp.poolSizeCount = sizeCount;
  dp.pPoolSizes = sizes;
  CHECK(vkCreateDescriptorPool(ctx().device, &dp, nullptr, pool));
  VkDescriptorSetAllocateInfo da{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  da.descriptorPool = *pool;
  da.descriptorSetCount = 1;
  da.pSetLayouts = &layout;
  VkDescriptorSet set;
  CHECK(vkAllocateDescriptorSets(ctx().device, &da, &set));
  return set;
}

}  // namespace

RayPipeline::~RayPipeline() {
  VkDevice d = ctx().device;
  vkDestroyDescriptorPool(d, pool, nullptr);
  vkDestroyPipeline(d, pipeline, nullptr);
  vkDestroyPipelineLayout(d, layout, nullptr);
  vkDestroyDescriptorSetLayout(d, setLayout, nullptr);
}

void RayPipeline::create(const VkPipelineShaderStageCreateInfo* stages, uint32_t stageCount,
                         const VkRayTracingShaderGroupCreateInfoKHR (&groups)[3], const VkDescriptorPoolSize* sizes,
                         uint32_t sizeCount) {
  Context& c = ctx();
  VkRayTracingPipelineCreateInfoKHR pci{VK_STRUCTURE_TYPE_RAY_TRACING_PIPELINE_CREATE_INFO_KHR};
  pci.stageCount = stageCount;
  pci.pStages = stages;
  pci.groupCount = 3;
  pci.pGroups = groups;
  pci.maxPipelineRayRecursionDepth = 1;
  pci.layout = layout;
  CHECK(c.createRtPipelines(c.device, VK_NULL_HANDLE, VK_NULL_HANDLE, 1, &pci, nullptr, &pipeline));
  for (uint32_t i = 0; i < stageCount; ++i) vkDestroyShaderModule(c.device, stages[i].module, nullptr);
  VkStridedDeviceAddressRegionKHR* regions[3] = {&raygen, &miss, &hit};
  sbt = shaderBindingTable(pipeline, 3, regions);
  set = oneDescriptorSet(setLayout, sizes, sizeCount, &pool);
}

unsigned workerThreads() {
  unsigned n = std::thread::hardware_concurrency();
  if (const char* env = std::getenv("VKRT_THREADS")) {
    long v = std::strtol(env, nullptr, 10);
    if (v >= 1 && v <= 256) n = unsigned(v);
  }
  return std::max(1u, n);
}

double processCpuSeconds() {
  timespec t;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + double(t.tv_nsec) * 1e-9;
}

double wallSeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace vkrt::bench
