#include "runtime/physical_device.hpp"

#include <sys/sysinfo.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <thread>

#include "runtime/alloc.hpp"
#include "runtime/instance.hpp"
#include "runtime/ray_tracing_features.hpp"
#include "runtime/report.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {
namespace {

constexpr uint32_t kVendorId = 0;  // vkrt has no registered vendor id (0x10005 would claim to be Mesa)
constexpr uint32_t kDeviceId = 0x7672;   // "vr"
constexpr uint8_t kUuid[VK_UUID_SIZE] = {'v', 'k', 'r', 't', '-', 'c', 'p', 'u', '-', 'd', 'e', 'v', 0, 0, 0, 1};
constexpr uint8_t kDriverUuid[VK_UUID_SIZE] = {'v', 'k', 'r', 't', '-', 'd', 'r', 'v', 0, 0, 0, 0, 0, 0, 0, 1};

// Heap size: half of the machine's memory, capped by the device address arena (runtime/memory.cpp).
VkDeviceSize heapSize() {
  struct sysinfo si {};
  VkDeviceSize total = 8ull << 30;
  if (sysinfo(&si) == 0) total = VkDeviceSize(si.totalram) * si.mem_unit;
  return std::min<VkDeviceSize>(total / 2, 32ull << 30);
}

// Copies the VkBool32 members that follow sType/pNext from one feature struct to another of the same type.
void copyBools(void* dst, const void* src, size_t size) {
  constexpr size_t header = offsetof(VkPhysicalDeviceVulkan11Features, storageBuffer16BitAccess);
  std::memcpy(static_cast<char*>(dst) + header, static_cast<const char*>(src) + header, size - header);
}

}  // namespace

unsigned workerThreadCount() {
  if (const char* v = std::getenv("VKRT_THREADS")) {
    int n = std::atoi(v);
    if (n > 0) return static_cast<unsigned>(n);
  }
  unsigned n = std::thread::hardware_concurrency();
  return n ? n : 1;
}

PhysicalDevice::PhysicalDevice(Instance* inst) : Object(kType, inst, nullptr) {
  // Features. Only what works; the shader compiler and ray tracing turn on their own.
  features10.robustBufferAccess = VK_TRUE;
  features10.fullDrawIndexUint32 = VK_TRUE;
  features10.independentBlend = VK_FALSE;
  features10.samplerAnisotropy = VK_FALSE;
  // 64-bit integers and doubles in shaders: src/spirv (tests/spirv SixtyFourBitIntegersAndDoubles).
  features10.shaderInt64 = VK_TRUE;
  features10.shaderFloat64 = VK_TRUE;
  // 8/16-bit integers, 16-bit floats and their storage-buffer access: src/spirv (tests/spirv
  // SpirvCompilerSmallTypes, tests/e2e ComputeSmallTypesTest); in uniform and push-constant blocks too
  // (tests/e2e ComputeFeaturesTest.EightAndSixteenBitUniformAndPushConstantMembers).
  features10.shaderInt16 = VK_TRUE;
  features11.storageBuffer16BitAccess = VK_TRUE;
  features11.uniformAndStorageBuffer16BitAccess = VK_TRUE;
  features11.storagePushConstant16 = VK_TRUE;
  features12.storageBuffer8BitAccess = VK_TRUE;
  features12.uniformAndStorageBuffer8BitAccess = VK_TRUE;
  features12.storagePushConstant8 = VK_TRUE;
  features12.shaderInt8 = VK_TRUE;
  features12.shaderFloat16 = VK_TRUE;

  features12.timelineSemaphore = VK_TRUE;
  features12.bufferDeviceAddress = VK_TRUE;
  features12.bufferDeviceAddressCaptureReplay = VK_TRUE;
  features12.hostQueryReset = VK_TRUE;
  features12.uniformBufferStandardLayout = VK_TRUE;
  // Scalar block layout: the compiler follows the Offset/ArrayStride decorations, shader modules are validated
  // with the scalar rules when the feature is enabled (tests/spirv SpirvBlockLayout, tests/e2e ComputeFeaturesTest).
  features12.scalarBlockLayout = VK_TRUE;
  features12.separateDepthStencilLayouts = VK_TRUE;
  features12.imagelessFramebuffer = VK_TRUE;
  // Descriptor binding flags (runtime/descriptor_set_layout.cpp): descriptors are records read when a command
  // executes, so updating them after binding, leaving some unwritten or sizing the last binding per set works.
  features12.descriptorBindingUniformBufferUpdateAfterBind = VK_TRUE;
  features12.descriptorBindingSampledImageUpdateAfterBind = VK_TRUE;
  features12.descriptorBindingStorageImageUpdateAfterBind = VK_TRUE;
  features12.descriptorBindingStorageBufferUpdateAfterBind = VK_TRUE;
  features12.descriptorBindingUniformTexelBufferUpdateAfterBind = VK_TRUE;
  features12.descriptorBindingStorageTexelBufferUpdateAfterBind = VK_TRUE;
  features12.descriptorBindingUpdateUnusedWhilePending = VK_TRUE;
  features12.descriptorBindingPartiallyBound = VK_TRUE;
  features12.descriptorBindingVariableDescriptorCount = VK_TRUE;
  // Descriptor arrays indexed by any value, also per invocation, and runtime-sized (src/spirv; tests/spirv
  // SpirvDescriptorIndexing, tests/e2e ComputeFeaturesTest and ComputeImageIndexingTest). Texel buffers are not
  // compiled yet, so neither their indexing features nor the descriptorIndexing aggregate are advertised.
  features10.shaderUniformBufferArrayDynamicIndexing = VK_TRUE;
  features10.shaderSampledImageArrayDynamicIndexing = VK_TRUE;
  features10.shaderStorageBufferArrayDynamicIndexing = VK_TRUE;
  features10.shaderStorageImageArrayDynamicIndexing = VK_TRUE;
  features12.shaderUniformBufferArrayNonUniformIndexing = VK_TRUE;
  features12.shaderSampledImageArrayNonUniformIndexing = VK_TRUE;
  features12.shaderStorageBufferArrayNonUniformIndexing = VK_TRUE;
  features12.shaderStorageImageArrayNonUniformIndexing = VK_TRUE;
  features12.runtimeDescriptorArray = VK_TRUE;

  features13.synchronization2 = VK_TRUE;
  features13.pipelineCreationCacheControl = VK_TRUE;
  features13.privateData = VK_FALSE;
  features13.maintenance4 = VK_TRUE;

  // Properties.
  VkPhysicalDeviceLimits& l = properties10.limits;
  properties10.apiVersion = VK_MAKE_API_VERSION(0, 1, 3, VK_HEADER_VERSION);
  properties10.driverVersion = VK_MAKE_VERSION(0, 1, 0);
  properties10.vendorID = kVendorId;
  properties10.deviceID = kDeviceId;
  properties10.deviceType = VK_PHYSICAL_DEVICE_TYPE_CPU;
  std::strncpy(properties10.deviceName, "vkrt", VK_MAX_PHYSICAL_DEVICE_NAME_SIZE);
  std::memcpy(properties10.pipelineCacheUUID, kUuid, VK_UUID_SIZE);

  l.maxImageDimension1D = 16384;
  l.maxImageDimension2D = 16384;
  l.maxImageDimension3D = 2048;
  l.maxImageDimensionCube = 16384;
  l.maxImageArrayLayers = 2048;
  l.maxTexelBufferElements = 1u << 27;
  l.maxUniformBufferRange = 65536;
  l.maxStorageBufferRange = 1u << 30;
  l.maxPushConstantsSize = 256;
  l.maxMemoryAllocationCount = 1u << 20;
  l.maxSamplerAllocationCount = 1u << 20;
  l.bufferImageGranularity = 1;
  l.sparseAddressSpaceSize = 0;
  l.maxBoundDescriptorSets = 8;
  l.maxPerStageDescriptorSamplers = 1u << 20;
  l.maxPerStageDescriptorUniformBuffers = 1u << 20;
  l.maxPerStageDescriptorStorageBuffers = 1u << 20;
  l.maxPerStageDescriptorSampledImages = 1u << 20;
  l.maxPerStageDescriptorStorageImages = 1u << 20;
  l.maxPerStageDescriptorInputAttachments = 0;
  l.maxPerStageResources = 1u << 20;
  l.maxDescriptorSetSamplers = 1u << 20;
  l.maxDescriptorSetUniformBuffers = 1u << 20;
  l.maxDescriptorSetUniformBuffersDynamic = 16;
  l.maxDescriptorSetStorageBuffers = 1u << 20;
  l.maxDescriptorSetStorageBuffersDynamic = 16;
  l.maxDescriptorSetSampledImages = 1u << 20;
  l.maxDescriptorSetStorageImages = 1u << 20;
  l.maxDescriptorSetInputAttachments = 0;
  l.maxComputeSharedMemorySize = 32768;
  l.maxComputeWorkGroupCount[0] = l.maxComputeWorkGroupCount[1] = l.maxComputeWorkGroupCount[2] = 65535;
  l.maxComputeWorkGroupInvocations = 1024;
  l.maxComputeWorkGroupSize[0] = 1024;
  l.maxComputeWorkGroupSize[1] = 1024;
  l.maxComputeWorkGroupSize[2] = 64;
  l.subPixelPrecisionBits = 4;
  l.subTexelPrecisionBits = 8;
  l.mipmapPrecisionBits = 8;
  l.maxDrawIndexedIndexValue = UINT32_MAX;
  l.maxDrawIndirectCount = UINT32_MAX;
  l.maxSamplerLodBias = 15.0f;
  l.maxSamplerAnisotropy = 1.0f;
  l.maxViewports = 1;
  l.maxViewportDimensions[0] = l.maxViewportDimensions[1] = 16384;
  l.viewportBoundsRange[0] = -32768.0f;
  l.viewportBoundsRange[1] = 32767.0f;
  l.minMemoryMapAlignment = 64;
  l.minTexelBufferOffsetAlignment = 16;
  l.minUniformBufferOffsetAlignment = 16;
  l.minStorageBufferOffsetAlignment = 16;
  l.minTexelOffset = -8;
  l.maxTexelOffset = 7;
  l.minTexelGatherOffset = -8;
  l.maxTexelGatherOffset = 7;
  l.maxFramebufferWidth = l.maxFramebufferHeight = 16384;
  l.maxFramebufferLayers = 1024;
  l.framebufferColorSampleCounts = VK_SAMPLE_COUNT_1_BIT;
  l.framebufferDepthSampleCounts = VK_SAMPLE_COUNT_1_BIT;
  l.framebufferStencilSampleCounts = VK_SAMPLE_COUNT_1_BIT;
  l.framebufferNoAttachmentsSampleCounts = VK_SAMPLE_COUNT_1_BIT;
  l.maxColorAttachments = 8;
  l.sampledImageColorSampleCounts = VK_SAMPLE_COUNT_1_BIT;
  l.sampledImageIntegerSampleCounts = VK_SAMPLE_COUNT_1_BIT;
  l.sampledImageDepthSampleCounts = VK_SAMPLE_COUNT_1_BIT;
  l.sampledImageStencilSampleCounts = VK_SAMPLE_COUNT_1_BIT;
  l.storageImageSampleCounts = VK_SAMPLE_COUNT_1_BIT;
  l.maxSampleMaskWords = 1;
  l.timestampComputeAndGraphics = VK_TRUE;
  l.timestampPeriod = 1.0f;  // timestamps are nanoseconds of CLOCK_MONOTONIC
  l.discreteQueuePriorities = 2;
  l.pointSizeGranularity = 1.0f;
  l.lineWidthGranularity = 1.0f;
  l.pointSizeRange[0] = l.pointSizeRange[1] = 1.0f;
  l.lineWidthRange[0] = l.lineWidthRange[1] = 1.0f;
  l.strictLines = VK_FALSE;
  l.standardSampleLocations = VK_TRUE;
  l.optimalBufferCopyOffsetAlignment = 16;
  l.optimalBufferCopyRowPitchAlignment = 16;
  l.nonCoherentAtomSize = 64;

  std::memcpy(properties11.deviceUUID, kUuid, VK_UUID_SIZE);
  std::memcpy(properties11.driverUUID, kDriverUuid, VK_UUID_SIZE);
  properties11.deviceNodeMask = 1;
  properties11.subgroupSize = 1;
  properties11.subgroupSupportedStages = VK_SHADER_STAGE_COMPUTE_BIT;
  properties11.subgroupSupportedOperations = VK_SUBGROUP_FEATURE_BASIC_BIT;
  properties11.pointClippingBehavior = VK_POINT_CLIPPING_BEHAVIOR_ALL_CLIP_PLANES;
  properties11.maxMultiviewViewCount = 6;
  properties11.maxMultiviewInstanceIndex = (1u << 27) - 1;
  properties11.maxPerSetDescriptors = 1u << 20;
  properties11.maxMemoryAllocationSize = heapSize();

  properties12.driverID = static_cast<VkDriverId>(0);  // not a registered driver id
  std::strncpy(properties12.driverName, "vkrt", VK_MAX_DRIVER_NAME_SIZE);
  std::strncpy(properties12.driverInfo, "vkrt CPU ray tracing driver", VK_MAX_DRIVER_INFO_SIZE);
  properties12.conformanceVersion = {0, 0, 0, 0};
  properties12.denormBehaviorIndependence = VK_SHADER_FLOAT_CONTROLS_INDEPENDENCE_ALL;
  properties12.roundingModeIndependence = VK_SHADER_FLOAT_CONTROLS_INDEPENDENCE_ALL;
  properties12.maxUpdateAfterBindDescriptorsInAllPools = 1u << 20;
  properties12.maxPerStageDescriptorUpdateAfterBindSamplers = 1u << 20;
  properties12.maxPerStageDescriptorUpdateAfterBindUniformBuffers = 1u << 20;
  properties12.maxPerStageDescriptorUpdateAfterBindStorageBuffers = 1u << 20;
  properties12.maxPerStageDescriptorUpdateAfterBindSampledImages = 1u << 20;
  properties12.maxPerStageDescriptorUpdateAfterBindStorageImages = 1u << 20;
  properties12.maxPerStageUpdateAfterBindResources = 1u << 20;
  properties12.maxDescriptorSetUpdateAfterBindSamplers = 1u << 20;
  properties12.maxDescriptorSetUpdateAfterBindUniformBuffers = 1u << 20;
  properties12.maxDescriptorSetUpdateAfterBindUniformBuffersDynamic = 16;
  properties12.maxDescriptorSetUpdateAfterBindStorageBuffers = 1u << 20;
  properties12.maxDescriptorSetUpdateAfterBindStorageBuffersDynamic = 16;
  properties12.maxDescriptorSetUpdateAfterBindSampledImages = 1u << 20;
  properties12.maxDescriptorSetUpdateAfterBindStorageImages = 1u << 20;
  properties12.supportedDepthResolveModes = VK_RESOLVE_MODE_SAMPLE_ZERO_BIT;
  properties12.supportedStencilResolveModes = VK_RESOLVE_MODE_SAMPLE_ZERO_BIT;
  properties12.independentResolveNone = VK_TRUE;
  properties12.independentResolve = VK_TRUE;
  properties12.maxTimelineSemaphoreValueDifference = UINT64_MAX;
  properties12.framebufferIntegerColorSampleCounts = VK_SAMPLE_COUNT_1_BIT;

  properties13.minSubgroupSize = 1;
  properties13.maxSubgroupSize = 1;
  properties13.maxComputeWorkgroupSubgroups = 1024;
  properties13.requiredSubgroupSizeStages = VK_SHADER_STAGE_COMPUTE_BIT;
  properties13.maxInlineUniformBlockSize = 256;
  properties13.maxPerStageDescriptorInlineUniformBlocks = 4;
  properties13.maxPerStageDescriptorUpdateAfterBindInlineUniformBlocks = 4;
  properties13.maxDescriptorSetInlineUniformBlocks = 4;
  properties13.maxDescriptorSetUpdateAfterBindInlineUniformBlocks = 4;
  properties13.maxInlineUniformTotalSize = 1024;
  properties13.storageTexelBufferOffsetAlignmentBytes = 16;
  properties13.storageTexelBufferOffsetSingleTexelAlignment = VK_TRUE;
  properties13.uniformTexelBufferOffsetAlignmentBytes = 16;
  properties13.uniformTexelBufferOffsetSingleTexelAlignment = VK_TRUE;
  properties13.maxBufferSize = heapSize();

  memoryProperties.memoryHeapCount = 1;
  memoryProperties.memoryHeaps[0] = {heapSize(), VK_MEMORY_HEAP_DEVICE_LOCAL_BIT};
  memoryProperties.memoryTypeCount = 1;
  memoryProperties.memoryTypes[0] = {VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT | VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT |
                                         VK_MEMORY_PROPERTY_HOST_COHERENT_BIT | VK_MEMORY_PROPERTY_HOST_CACHED_BIT,
                                     0};

  queueFamily.queueFlags = VK_QUEUE_COMPUTE_BIT | VK_QUEUE_TRANSFER_BIT;
  queueFamily.queueCount = 4;
  queueFamily.timestampValidBits = 64;
  queueFamily.minImageTransferGranularity = {1, 1, 1};

  extensions_ = {
      {VK_KHR_BUFFER_DEVICE_ADDRESS_EXTENSION_NAME, VK_KHR_BUFFER_DEVICE_ADDRESS_SPEC_VERSION},
      {VK_KHR_TIMELINE_SEMAPHORE_EXTENSION_NAME, VK_KHR_TIMELINE_SEMAPHORE_SPEC_VERSION},
      {VK_KHR_SYNCHRONIZATION_2_EXTENSION_NAME, VK_KHR_SYNCHRONIZATION_2_SPEC_VERSION},
      {VK_KHR_DESCRIPTOR_UPDATE_TEMPLATE_EXTENSION_NAME, VK_KHR_DESCRIPTOR_UPDATE_TEMPLATE_SPEC_VERSION},
      {VK_KHR_GET_MEMORY_REQUIREMENTS_2_EXTENSION_NAME, VK_KHR_GET_MEMORY_REQUIREMENTS_2_SPEC_VERSION},
      {VK_KHR_BIND_MEMORY_2_EXTENSION_NAME, VK_KHR_BIND_MEMORY_2_SPEC_VERSION},
      {VK_KHR_DEDICATED_ALLOCATION_EXTENSION_NAME, VK_KHR_DEDICATED_ALLOCATION_SPEC_VERSION},
      {VK_KHR_MAINTENANCE_1_EXTENSION_NAME, VK_KHR_MAINTENANCE_1_SPEC_VERSION},
      {VK_KHR_MAINTENANCE_3_EXTENSION_NAME, VK_KHR_MAINTENANCE_3_SPEC_VERSION},
      {VK_KHR_MAINTENANCE_4_EXTENSION_NAME, VK_KHR_MAINTENANCE_4_SPEC_VERSION},
      {VK_KHR_COPY_COMMANDS_2_EXTENSION_NAME, VK_KHR_COPY_COMMANDS_2_SPEC_VERSION},
      {VK_EXT_HOST_QUERY_RESET_EXTENSION_NAME, VK_EXT_HOST_QUERY_RESET_SPEC_VERSION},
      {VK_KHR_UNIFORM_BUFFER_STANDARD_LAYOUT_EXTENSION_NAME, VK_KHR_UNIFORM_BUFFER_STANDARD_LAYOUT_SPEC_VERSION},
      {VK_EXT_SCALAR_BLOCK_LAYOUT_EXTENSION_NAME, VK_EXT_SCALAR_BLOCK_LAYOUT_SPEC_VERSION},
      {VK_EXT_PIPELINE_CREATION_CACHE_CONTROL_EXTENSION_NAME, VK_EXT_PIPELINE_CREATION_CACHE_CONTROL_SPEC_VERSION},
  };
  // Ray tracing (runtime/ray_tracing_features.cpp).
  rt::appendExtensions(extensions_);
}

bool PhysicalDevice::supportsExtension(const char* name) const {
  return std::any_of(extensions_.begin(), extensions_.end(),
                     [&](const VkExtensionProperties& e) { return std::strcmp(e.extensionName, name) == 0; });
}

void PhysicalDevice::fillFeatures(VkPhysicalDeviceFeatures2* out) const {
  out->features = features10;
  for (auto* s = static_cast<VkBaseOutStructure*>(out->pNext); s; s = s->pNext) {
    switch (s->sType) {
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES:
        copyBools(s, &features11, sizeof(features11));
        break;
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES:
        copyBools(s, &features12, sizeof(features12));
        break;
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES:
        copyBools(s, &features13, sizeof(features13));
        break;
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_TIMELINE_SEMAPHORE_FEATURES:
        reinterpret_cast<VkPhysicalDeviceTimelineSemaphoreFeatures*>(s)->timelineSemaphore =
            features12.timelineSemaphore;
        break;
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_BUFFER_DEVICE_ADDRESS_FEATURES: {
        auto* f = reinterpret_cast<VkPhysicalDeviceBufferDeviceAddressFeatures*>(s);
        f->bufferDeviceAddress = features12.bufferDeviceAddress;
        f->bufferDeviceAddressCaptureReplay = features12.bufferDeviceAddressCaptureReplay;
        f->bufferDeviceAddressMultiDevice = features12.bufferDeviceAddressMultiDevice;
        break;
      }
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_HOST_QUERY_RESET_FEATURES:
        reinterpret_cast<VkPhysicalDeviceHostQueryResetFeatures*>(s)->hostQueryReset = features12.hostQueryReset;
        break;
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_16BIT_STORAGE_FEATURES: {
        auto* f = reinterpret_cast<VkPhysicalDevice16BitStorageFeatures*>(s);
        f->storageBuffer16BitAccess = features11.storageBuffer16BitAccess;
        f->uniformAndStorageBuffer16BitAccess = features11.uniformAndStorageBuffer16BitAccess;
        f->storagePushConstant16 = features11.storagePushConstant16;
        f->storageInputOutput16 = features11.storageInputOutput16;
        break;
      }
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_8BIT_STORAGE_FEATURES: {
        auto* f = reinterpret_cast<VkPhysicalDevice8BitStorageFeatures*>(s);
        f->storageBuffer8BitAccess = features12.storageBuffer8BitAccess;
        f->uniformAndStorageBuffer8BitAccess = features12.uniformAndStorageBuffer8BitAccess;
        f->storagePushConstant8 = features12.storagePushConstant8;
        break;
      }
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_FLOAT16_INT8_FEATURES: {
        auto* f = reinterpret_cast<VkPhysicalDeviceShaderFloat16Int8Features*>(s);
        f->shaderFloat16 = features12.shaderFloat16;
        f->shaderInt8 = features12.shaderInt8;
        break;
      }
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DESCRIPTOR_INDEXING_FEATURES: {
        // The promoted structure's members are those of VkPhysicalDeviceVulkan12Features, in the same order.
        constexpr size_t first = offsetof(VkPhysicalDeviceVulkan12Features, shaderInputAttachmentArrayDynamicIndexing);
        constexpr size_t end = offsetof(VkPhysicalDeviceVulkan12Features, runtimeDescriptorArray) + sizeof(VkBool32);
        static_assert(end - first == offsetof(VkPhysicalDeviceDescriptorIndexingFeatures, runtimeDescriptorArray) + sizeof(VkBool32) -
                                         offsetof(VkPhysicalDeviceDescriptorIndexingFeatures, shaderInputAttachmentArrayDynamicIndexing));
        std::memcpy(&reinterpret_cast<VkPhysicalDeviceDescriptorIndexingFeatures*>(s)->shaderInputAttachmentArrayDynamicIndexing,
                    reinterpret_cast<const char*>(&features12) + first, end - first);
        break;
      }
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SCALAR_BLOCK_LAYOUT_FEATURES:
        reinterpret_cast<VkPhysicalDeviceScalarBlockLayoutFeatures*>(s)->scalarBlockLayout = features12.scalarBlockLayout;
        break;
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_UNIFORM_BUFFER_STANDARD_LAYOUT_FEATURES:
        reinterpret_cast<VkPhysicalDeviceUniformBufferStandardLayoutFeatures*>(s)->uniformBufferStandardLayout =
            features12.uniformBufferStandardLayout;
        break;
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SYNCHRONIZATION_2_FEATURES:
        reinterpret_cast<VkPhysicalDeviceSynchronization2Features*>(s)->synchronization2 = features13.synchronization2;
        break;
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MAINTENANCE_4_FEATURES:
        reinterpret_cast<VkPhysicalDeviceMaintenance4Features*>(s)->maintenance4 = features13.maintenance4;
        break;
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PIPELINE_CREATION_CACHE_CONTROL_FEATURES:
        reinterpret_cast<VkPhysicalDevicePipelineCreationCacheControlFeatures*>(s)->pipelineCreationCacheControl =
            features13.pipelineCreationCacheControl;
        break;
      default:
        rt::fillFeature(s);  // ray tracing structures; others are left untouched
        break;
    }
  }
}

void PhysicalDevice::fillProperties(VkPhysicalDeviceProperties2* out) const {
  out->properties = properties10;
  for (auto* s = static_cast<VkBaseOutStructure*>(out->pNext); s; s = s->pNext) {
    VkBaseOutStructure* next = s->pNext;
    switch (s->sType) {
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_PROPERTIES:
        std::memcpy(s, &properties11, sizeof(properties11));
        break;
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_PROPERTIES:
        std::memcpy(s, &properties12, sizeof(properties12));
        break;
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_PROPERTIES:
        std::memcpy(s, &properties13, sizeof(properties13));
        break;
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ID_PROPERTIES: {
        auto* p = reinterpret_cast<VkPhysicalDeviceIDProperties*>(s);
        std::memcpy(p->deviceUUID, properties11.deviceUUID, VK_UUID_SIZE);
        std::memcpy(p->driverUUID, properties11.driverUUID, VK_UUID_SIZE);
        p->deviceNodeMask = properties11.deviceNodeMask;
        p->deviceLUIDValid = VK_FALSE;
        break;
      }
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES: {
        auto* p = reinterpret_cast<VkPhysicalDeviceDriverProperties*>(s);
        p->driverID = properties12.driverID;
        std::memcpy(p->driverName, properties12.driverName, VK_MAX_DRIVER_NAME_SIZE);
        std::memcpy(p->driverInfo, properties12.driverInfo, VK_MAX_DRIVER_INFO_SIZE);
        p->conformanceVersion = properties12.conformanceVersion;
        break;
      }
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MAINTENANCE_3_PROPERTIES: {
        auto* p = reinterpret_cast<VkPhysicalDeviceMaintenance3Properties*>(s);
        p->maxPerSetDescriptors = properties11.maxPerSetDescriptors;
        p->maxMemoryAllocationSize = properties11.maxMemoryAllocationSize;
        break;
      }
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MAINTENANCE_4_PROPERTIES:
        reinterpret_cast<VkPhysicalDeviceMaintenance4Properties*>(s)->maxBufferSize = properties13.maxBufferSize;
        break;
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_TIMELINE_SEMAPHORE_PROPERTIES:
        reinterpret_cast<VkPhysicalDeviceTimelineSemaphoreProperties*>(s)->maxTimelineSemaphoreValueDifference =
            properties12.maxTimelineSemaphoreValueDifference;
        break;
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES: {
        auto* p = reinterpret_cast<VkPhysicalDeviceSubgroupProperties*>(s);
        p->subgroupSize = properties11.subgroupSize;
        p->supportedStages = properties11.subgroupSupportedStages;
        p->supportedOperations = properties11.subgroupSupportedOperations;
        p->quadOperationsInAllStages = properties11.subgroupQuadOperationsInAllStages;
        break;
      }
      default:
        rt::fillProperty(s);  // ray tracing properties
        break;
    }
    s->pNext = next;  // the memcpy of a whole struct above also copied our null pNext: restore the chain
  }
  // The memcpy above also overwrote sType with the same value; nothing else to restore.
}

const char* PhysicalDevice::firstUnsupportedFeature(const VkDeviceCreateInfo& info) const {
  // `end` is the offset just past the last VkBool32 member (not sizeof: trailing padding is not a feature).
  auto check = [](const void* requested, const void* supported, size_t offset, size_t end,
                  const char* structName) -> const char* {
    auto* r = reinterpret_cast<const VkBool32*>(static_cast<const char*>(requested) + offset);
    auto* s = reinterpret_cast<const VkBool32*>(static_cast<const char*>(supported) + offset);
    for (size_t i = 0; i < (end - offset) / sizeof(VkBool32); ++i)
      if (r[i] && !s[i]) return structName;
    return nullptr;
  };
  constexpr size_t header = offsetof(VkPhysicalDeviceVulkan11Features, storageBuffer16BitAccess);
  constexpr size_t kEnd11 = offsetof(VkPhysicalDeviceVulkan11Features, shaderDrawParameters) + sizeof(VkBool32);
  constexpr size_t kEnd12 = offsetof(VkPhysicalDeviceVulkan12Features, subgroupBroadcastDynamicId) + sizeof(VkBool32);
  constexpr size_t kEnd13 = offsetof(VkPhysicalDeviceVulkan13Features, maintenance4) + sizeof(VkBool32);
  if (info.pEnabledFeatures)
    if (auto* n = check(info.pEnabledFeatures, &features10, 0, sizeof(features10), "VkPhysicalDeviceFeatures"))
      return n;
  for (auto* s = static_cast<const VkBaseInStructure*>(info.pNext); s; s = s->pNext) {
    const char* bad = nullptr;
    switch (s->sType) {
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2:
        bad = check(&reinterpret_cast<const VkPhysicalDeviceFeatures2*>(s)->features, &features10, 0,
                    sizeof(features10), "VkPhysicalDeviceFeatures2");
        break;
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES:
        bad = check(s, &features11, header, kEnd11, "VkPhysicalDeviceVulkan11Features");
        break;
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES:
        bad = check(s, &features12, header, kEnd12, "VkPhysicalDeviceVulkan12Features");
        break;
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES:
        bad = check(s, &features13, header, kEnd13, "VkPhysicalDeviceVulkan13Features");
        break;
      default: {
        // Any other feature struct vkrt knows: compare against what fillFeatures reports for it.
        alignas(16) unsigned char supported[512] = {};
        size_t size = 0, end = 0;
        switch (s->sType) {
#define VKRT_FEATURE_STRUCT(stype, T, last)                \
  case stype:                                              \
    size = sizeof(T);                                      \
    end = offsetof(T, last) + sizeof(VkBool32);            \
    break;
          VKRT_FEATURE_STRUCT(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_TIMELINE_SEMAPHORE_FEATURES,
                              VkPhysicalDeviceTimelineSemaphoreFeatures, timelineSemaphore)
          VKRT_FEATURE_STRUCT(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_BUFFER_DEVICE_ADDRESS_FEATURES,
                              VkPhysicalDeviceBufferDeviceAddressFeatures, bufferDeviceAddressMultiDevice)
          VKRT_FEATURE_STRUCT(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_HOST_QUERY_RESET_FEATURES,
                              VkPhysicalDeviceHostQueryResetFeatures, hostQueryReset)
          VKRT_FEATURE_STRUCT(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_16BIT_STORAGE_FEATURES,
                              VkPhysicalDevice16BitStorageFeatures, storageInputOutput16)
          VKRT_FEATURE_STRUCT(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_8BIT_STORAGE_FEATURES,
                              VkPhysicalDevice8BitStorageFeatures, storagePushConstant8)
          VKRT_FEATURE_STRUCT(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_FLOAT16_INT8_FEATURES,
                              VkPhysicalDeviceShaderFloat16Int8Features, shaderInt8)
          VKRT_FEATURE_STRUCT(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DESCRIPTOR_INDEXING_FEATURES,
                              VkPhysicalDeviceDescriptorIndexingFeatures, runtimeDescriptorArray)
          VKRT_FEATURE_STRUCT(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SCALAR_BLOCK_LAYOUT_FEATURES,
                              VkPhysicalDeviceScalarBlockLayoutFeatures, scalarBlockLayout)
          VKRT_FEATURE_STRUCT(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_UNIFORM_BUFFER_STANDARD_LAYOUT_FEATURES,
                              VkPhysicalDeviceUniformBufferStandardLayoutFeatures, uniformBufferStandardLayout)
          VKRT_FEATURE_STRUCT(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SYNCHRONIZATION_2_FEATURES,
                              VkPhysicalDeviceSynchronization2Features, synchronization2)
          VKRT_FEATURE_STRUCT(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MAINTENANCE_4_FEATURES,
                              VkPhysicalDeviceMaintenance4Features, maintenance4)
          VKRT_FEATURE_STRUCT(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PIPELINE_CREATION_CACHE_CONTROL_FEATURES,
                              VkPhysicalDevicePipelineCreationCacheControlFeatures, pipelineCreationCacheControl)
#undef VKRT_FEATURE_STRUCT
          default:
            rt::featureStructLayout(s->sType, &size, &end);  // ray tracing structures (src/rt/features.cpp)
            break;
        }
        if (size && size <= sizeof(supported)) {
          auto* hdr = reinterpret_cast<VkBaseOutStructure*>(supported);
          hdr->sType = s->sType;
          VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, hdr};
          fillFeatures(&f2);
          bad = check(s, supported, header, end, "a feature structure in VkDeviceCreateInfo::pNext");
        }
        break;
      }
    }
    if (bad) return bad;
  }
  return nullptr;
}

}  // namespace vkrt

using namespace vkrt;

namespace {
PhysicalDevice* pd(VkPhysicalDevice h) { return fromHandleUnchecked<PhysicalDevice>(h); }

template <class T>
VkResult fillArray(const std::vector<T>& src, uint32_t* count, T* out) {
  if (!out) {
    *count = static_cast<uint32_t>(src.size());
    return VK_SUCCESS;
  }
  uint32_t n = std::min<uint32_t>(*count, static_cast<uint32_t>(src.size()));
  std::copy_n(src.begin(), n, out);
  *count = n;
  return n < src.size() ? VK_INCOMPLETE : VK_SUCCESS;
}
}  // namespace

extern "C" {

VKAPI_ATTR void VKAPI_CALL vkrt_GetPhysicalDeviceFeatures(VkPhysicalDevice physicalDevice,
                                                          VkPhysicalDeviceFeatures* pFeatures) {
  *pFeatures = pd(physicalDevice)->features10;
}

VKAPI_ATTR void VKAPI_CALL vkrt_GetPhysicalDeviceFeatures2(VkPhysicalDevice physicalDevice,
                                                           VkPhysicalDeviceFeatures2* pFeatures) {
  pd(physicalDevice)->fillFeatures(pFeatures);
}

VKAPI_ATTR void VKAPI_CALL vkrt_GetPhysicalDeviceProperties(VkPhysicalDevice physicalDevice,
                                                            VkPhysicalDeviceProperties* pProperties) {
  *pProperties = pd(physicalDevice)->properties10;
}

VKAPI_ATTR void VKAPI_CALL vkrt_GetPhysicalDeviceProperties2(VkPhysicalDevice physicalDevice,
                                                             VkPhysicalDeviceProperties2* pProperties) {
  pd(physicalDevice)->fillProperties(pProperties);
}

VKAPI_ATTR void VKAPI_CALL vkrt_GetPhysicalDeviceMemoryProperties(VkPhysicalDevice physicalDevice,
                                                                  VkPhysicalDeviceMemoryProperties* pMemoryProperties) {
  *pMemoryProperties = pd(physicalDevice)->memoryProperties;
}

VKAPI_ATTR void VKAPI_CALL vkrt_GetPhysicalDeviceMemoryProperties2(
    VkPhysicalDevice physicalDevice, VkPhysicalDeviceMemoryProperties2* pMemoryProperties) {
  pMemoryProperties->memoryProperties = pd(physicalDevice)->memoryProperties;
}

VKAPI_ATTR void VKAPI_CALL vkrt_GetPhysicalDeviceQueueFamilyProperties(VkPhysicalDevice physicalDevice,
                                                                       uint32_t* pCount,
                                                                       VkQueueFamilyProperties* pProps) {
  if (!pProps) {
    *pCount = 1;
    return;
  }
  if (*pCount >= 1) {
    pProps[0] = pd(physicalDevice)->queueFamily;
    *pCount = 1;
  }
}

VKAPI_ATTR void VKAPI_CALL vkrt_GetPhysicalDeviceQueueFamilyProperties2(VkPhysicalDevice physicalDevice,
                                                                        uint32_t* pCount,
                                                                        VkQueueFamilyProperties2* pProps) {
  if (!pProps) {
    *pCount = 1;
    return;
  }
  if (*pCount >= 1) {
    pProps[0].queueFamilyProperties = pd(physicalDevice)->queueFamily;
    *pCount = 1;
  }
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_EnumerateDeviceExtensionProperties(VkPhysicalDevice physicalDevice,
                                                                       const char* pLayerName, uint32_t* pCount,
                                                                       VkExtensionProperties* pProperties) {
  if (pLayerName) return VK_ERROR_LAYER_NOT_PRESENT;
  return fillArray(pd(physicalDevice)->extensions(), pCount, pProperties);
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_EnumerateDeviceLayerProperties(VkPhysicalDevice, uint32_t* pCount,
                                                                   VkLayerProperties*) {
  *pCount = 0;
  return VK_SUCCESS;
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_GetPhysicalDeviceToolProperties(VkPhysicalDevice, uint32_t* pToolCount,
                                                                    VkPhysicalDeviceToolProperties*) {
  *pToolCount = 0;
  return VK_SUCCESS;
}

}  // extern "C"
