#include "runtime/physical_device.hpp"

#include <sys/sysinfo.h>

#include <algorithm>
#include <cstring>

#include "runtime/alloc.hpp"
#include "runtime/descriptor_set_layout.hpp"
#include "runtime/instance.hpp"
#include "runtime/ray_tracing_features.hpp"
#include "runtime/report.hpp"
#include "runtime/supported_features.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {
namespace {

constexpr uint32_t kVendorId = 0;       // vkrt has no registered vendor id (0x10005 would claim to be Mesa)
constexpr uint32_t kDeviceId = 0x7672;  // "vr"
constexpr uint8_t kUuid[VK_UUID_SIZE] = {'v', 'k', 'r', 't', '-', 'c', 'p', 'u', '-', 'd', 'e', 'v', 0, 0, 0, 1};
constexpr uint8_t kDriverUuid[VK_UUID_SIZE] = {'v', 'k', 'r', 't', '-', 'd', 'r', 'v', 0, 0, 0, 0, 0, 0, 0, 1};

// Heap size: half of the machine's memory, capped by the device address arena (runtime/memory.cpp).
VkDeviceSize heapSize() {
  struct sysinfo si {};
  VkDeviceSize total = 8ull << 30;
  if (sysinfo(&si) == 0) total = VkDeviceSize(si.totalram) * si.mem_unit;
  return std::min<VkDeviceSize>(total / 2, 32ull << 30);
}

}  // namespace

PhysicalDevice::PhysicalDevice(Instance* inst) : Object(kType, inst, nullptr) {
  // Properties.
  VkPhysicalDeviceLimits& l = properties10.limits;
  properties10.apiVersion = VK_MAKE_API_VERSION(0, 1, 3, VK_HEADER_VERSION);
  properties10.driverVersion = VK_MAKE_VERSION(VKRT_VERSION_MAJOR, VKRT_VERSION_MINOR, VKRT_VERSION_PATCH);
  properties10.vendorID = kVendorId;
  properties10.deviceID = kDeviceId;
  properties10.deviceType = VK_PHYSICAL_DEVICE_TYPE_CPU;
  std::strncpy(properties10.deviceName, "vkrt", VK_MAX_PHYSICAL_DEVICE_NAME_SIZE);
  std::memcpy(properties10.pipelineCacheUUID, kUuid, VK_UUID_SIZE);

  l.maxImageDimension1D = 16384;
  l.maxImageDimension2D = 16384;
  l.maxImageDimension3D = 16384;
  l.maxImageDimensionCube = 16384;
  l.maxImageArrayLayers = 2048;
  l.maxTexelBufferElements = 1u << 27;
  l.maxUniformBufferRange = 65536;
  l.maxStorageBufferRange = UINT32_MAX;  // the CTS binds 2 GiB in its largest launches; descriptor ranges are 64-bit
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
  l.maxPerStageDescriptorInputAttachments = 1u << 20;  // image view records (spirv Codegen::subpassRead)
  l.maxPerStageResources = 1u << 20;
  l.maxDescriptorSetSamplers = 1u << 20;
  l.maxDescriptorSetUniformBuffers = 1u << 20;
  l.maxDescriptorSetUniformBuffersDynamic = 16;
  l.maxDescriptorSetStorageBuffers = 1u << 20;
  l.maxDescriptorSetStorageBuffersDynamic = 16;
  l.maxDescriptorSetSampledImages = 1u << 20;
  l.maxDescriptorSetStorageImages = 1u << 20;
  l.maxDescriptorSetInputAttachments = 1u << 20;
  l.maxComputeSharedMemorySize = 65536;  // heap memory per workgroup (exec/compute.cpp)
  l.maxComputeWorkGroupCount[0] = l.maxComputeWorkGroupCount[1] = l.maxComputeWorkGroupCount[2] = 65535;
  l.maxComputeWorkGroupInvocations = 1024;
  l.maxComputeWorkGroupSize[0] = 1024;
  l.maxComputeWorkGroupSize[1] = 1024;
  l.maxComputeWorkGroupSize[2] = 64;
  // The rasterizer snaps framebuffer positions to raster::kSubPixelBits (8) bits of sub-pixel precision
  // (raster/setup.cpp); runtime sits below raster, so the number is written here.
  l.subPixelPrecisionBits = 8;
  l.subTexelPrecisionBits = 8;
  l.mipmapPrecisionBits = 8;
  // Vertex input and the stage interfaces (src/gfx): 32 attribute locations and bindings (abi::kGraphicsLocations,
  // gfx::kMaxVertexBindings), 32 varying locations of 4 components (raster::kMaxLocations), 8 color outputs, one
  // dual-source output, 8 clip and cull distances together (raster::kMaxClipDistances).
  l.maxVertexInputAttributes = 32;
  l.maxVertexInputBindings = 32;
  l.maxVertexInputAttributeOffset = 2047;
  l.maxVertexInputBindingStride = 2048;
  l.maxVertexOutputComponents = 128;
  l.maxFragmentInputComponents = 128;
  l.maxFragmentOutputAttachments = 8;
  l.maxFragmentDualSrcAttachments = 1;
  l.maxFragmentCombinedOutputResources = 1u << 20;
  l.maxClipDistances = 8;
  l.maxCullDistances = 8;
  l.maxCombinedClipAndCullDistances = 8;
  l.maxDrawIndexedIndexValue = UINT32_MAX;
  l.maxDrawIndirectCount = UINT32_MAX;
  l.maxSamplerLodBias = 15.0f;
  l.maxSamplerAnisotropy = 16.0f;  // the minimum for samplerAnisotropy (supported_features.cpp says why it holds)
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
  // 1 and 4 samples, the counts the spec requires ("Limit Requirements"): multisampled images keep a pixel's
  // samples together (runtime/image.hpp), render passes resolve them (gfx/rendering.cpp).
  l.framebufferColorSampleCounts = VK_SAMPLE_COUNT_1_BIT | VK_SAMPLE_COUNT_4_BIT;
  l.framebufferDepthSampleCounts = VK_SAMPLE_COUNT_1_BIT | VK_SAMPLE_COUNT_4_BIT;
  l.framebufferStencilSampleCounts = VK_SAMPLE_COUNT_1_BIT | VK_SAMPLE_COUNT_4_BIT;
  l.framebufferNoAttachmentsSampleCounts = VK_SAMPLE_COUNT_1_BIT | VK_SAMPLE_COUNT_4_BIT;
  l.maxColorAttachments = 8;
  l.sampledImageColorSampleCounts = VK_SAMPLE_COUNT_1_BIT | VK_SAMPLE_COUNT_4_BIT;
  l.sampledImageIntegerSampleCounts = VK_SAMPLE_COUNT_1_BIT | VK_SAMPLE_COUNT_4_BIT;
  l.sampledImageDepthSampleCounts = VK_SAMPLE_COUNT_1_BIT | VK_SAMPLE_COUNT_4_BIT;
  l.sampledImageStencilSampleCounts = VK_SAMPLE_COUNT_1_BIT | VK_SAMPLE_COUNT_4_BIT;
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
  properties11.subgroupSupportedOperations =
      VK_SUBGROUP_FEATURE_BASIC_BIT | VK_SUBGROUP_FEATURE_VOTE_BIT | VK_SUBGROUP_FEATURE_BALLOT_BIT;
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
  // Float controls a CPU honours as it is (src/spirv, tests/spirv SpirvFloatControls): compiled code uses no
  // fast-math flags, so signed zeros, infinities and NaNs are preserved; x86 arithmetic keeps denormals (vkrt never
  // sets FTZ/DAZ) and rounds to nearest even; 16-bit float arithmetic is done in float and rounded once to half,
  // which is the correctly rounded result (float has more than 2 x 11 + 2 bits). Flushing denormals and rounding
  // toward zero would need per-instruction rounding control: not advertised.
  properties12.shaderSignedZeroInfNanPreserveFloat16 = VK_TRUE;
  properties12.shaderSignedZeroInfNanPreserveFloat32 = VK_TRUE;
  properties12.shaderSignedZeroInfNanPreserveFloat64 = VK_TRUE;
  properties12.shaderDenormPreserveFloat16 = VK_TRUE;
  properties12.shaderDenormPreserveFloat32 = VK_TRUE;
  properties12.shaderDenormPreserveFloat64 = VK_TRUE;
  properties12.shaderRoundingModeRTEFloat16 = VK_TRUE;
  properties12.shaderRoundingModeRTEFloat32 = VK_TRUE;
  properties12.shaderRoundingModeRTEFloat64 = VK_TRUE;
  // Descriptors are records read when a command executes, and every access is bounds-checked against the record
  // it reads then (src/spirv/memory.cpp): robust buffer access holds for update-after-bind descriptors too.
  properties12.robustBufferAccessUpdateAfterBind = VK_TRUE;
  properties12.maxUpdateAfterBindDescriptorsInAllPools = 1u << 20;
  properties12.maxPerStageDescriptorUpdateAfterBindSamplers = 1u << 20;
  properties12.maxPerStageDescriptorUpdateAfterBindUniformBuffers = 1u << 20;
  properties12.maxPerStageDescriptorUpdateAfterBindStorageBuffers = 1u << 20;
  properties12.maxPerStageDescriptorUpdateAfterBindSampledImages = 1u << 20;
  properties12.maxPerStageDescriptorUpdateAfterBindStorageImages = 1u << 20;
  properties12.maxPerStageDescriptorUpdateAfterBindInputAttachments = 1u << 20;
  properties12.maxPerStageUpdateAfterBindResources = 1u << 20;
  properties12.maxDescriptorSetUpdateAfterBindSamplers = 1u << 20;
  properties12.maxDescriptorSetUpdateAfterBindUniformBuffers = 1u << 20;
  properties12.maxDescriptorSetUpdateAfterBindUniformBuffersDynamic = 16;
  properties12.maxDescriptorSetUpdateAfterBindStorageBuffers = 1u << 20;
  properties12.maxDescriptorSetUpdateAfterBindStorageBuffersDynamic = 16;
  properties12.maxDescriptorSetUpdateAfterBindSampledImages = 1u << 20;
  properties12.maxDescriptorSetUpdateAfterBindStorageImages = 1u << 20;
  properties12.maxDescriptorSetUpdateAfterBindInputAttachments = 1u << 20;
  // Depth/stencil resolves of render passes and dynamic rendering (gfx/rendering.cpp resolveDepthStencil).
  properties12.supportedDepthResolveModes =
      VK_RESOLVE_MODE_SAMPLE_ZERO_BIT | VK_RESOLVE_MODE_AVERAGE_BIT | VK_RESOLVE_MODE_MIN_BIT | VK_RESOLVE_MODE_MAX_BIT;
  properties12.supportedStencilResolveModes =
      VK_RESOLVE_MODE_SAMPLE_ZERO_BIT | VK_RESOLVE_MODE_MIN_BIT | VK_RESOLVE_MODE_MAX_BIT;
  properties12.independentResolveNone = VK_TRUE;
  properties12.independentResolve = VK_TRUE;
  properties12.maxTimelineSemaphoreValueDifference = UINT64_MAX;
  properties12.framebufferIntegerColorSampleCounts = VK_SAMPLE_COUNT_1_BIT | VK_SAMPLE_COUNT_4_BIT;

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

  // Family 0 for everything: render passes and draws (src/gfx) run on the same queue workers as compute. Family 1
  // without graphics ("Queue Family Properties": a compute-only family may exist beside the graphics one).
  for (VkQueueFamilyProperties& f : queueFamilies) {
    f.queueFlags = VK_QUEUE_COMPUTE_BIT | VK_QUEUE_TRANSFER_BIT;
    f.queueCount = 4;
    f.timestampValidBits = 64;
    f.minImageTransferGranularity = {1, 1, 1};
  }
  queueFamilies[0].queueFlags |= VK_QUEUE_GRAPHICS_BIT;

  extensions_ = {
      {VK_KHR_BUFFER_DEVICE_ADDRESS_EXTENSION_NAME, VK_KHR_BUFFER_DEVICE_ADDRESS_SPEC_VERSION},
      {VK_KHR_SWAPCHAIN_EXTENSION_NAME, VK_KHR_SWAPCHAIN_SPEC_VERSION},
      {VK_KHR_DEVICE_GROUP_EXTENSION_NAME, VK_KHR_DEVICE_GROUP_SPEC_VERSION},
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
      {VK_KHR_SHADER_FLOAT_CONTROLS_EXTENSION_NAME, VK_KHR_SHADER_FLOAT_CONTROLS_SPEC_VERSION},
      {VK_KHR_SHADER_INTEGER_DOT_PRODUCT_EXTENSION_NAME, VK_KHR_SHADER_INTEGER_DOT_PRODUCT_SPEC_VERSION},
      {VK_KHR_ZERO_INITIALIZE_WORKGROUP_MEMORY_EXTENSION_NAME, VK_KHR_ZERO_INITIALIZE_WORKGROUP_MEMORY_SPEC_VERSION},
      {VK_KHR_WORKGROUP_MEMORY_EXPLICIT_LAYOUT_EXTENSION_NAME, VK_KHR_WORKGROUP_MEMORY_EXPLICIT_LAYOUT_SPEC_VERSION},
      {VK_EXT_PIPELINE_CREATION_CACHE_CONTROL_EXTENSION_NAME, VK_EXT_PIPELINE_CREATION_CACHE_CONTROL_SPEC_VERSION},
      // Every feature the extension makes mandatory is supported (supported_features.cpp: descriptorIndexing).
      {VK_EXT_DESCRIPTOR_INDEXING_EXTENSION_NAME, VK_EXT_DESCRIPTOR_INDEXING_SPEC_VERSION},
      // inlineUniformBlock and its update-after-bind feature (supported_features.cpp).
      {VK_EXT_INLINE_UNIFORM_BLOCK_EXTENSION_NAME, VK_EXT_INLINE_UNIFORM_BLOCK_SPEC_VERSION},
      // SPIR-V 1.4 modules (Vulkan 1.2 takes up to 1.5 and 1.3 up to 1.6 anyway): what 1.4 added that a Vulkan
      // module may use without variable pointers is compiled (tests/e2e/spirv14_test.cpp).
      {VK_KHR_SPIRV_1_4_EXTENSION_NAME, VK_KHR_SPIRV_1_4_SPEC_VERSION},
      // More extensions promoted to Vulkan 1.1-1.3 that applications written for older versions still enable by
      // name; what each adds is implemented (tests/e2e/promoted_extensions_test.cpp has the audit of every promoted
      // extension and the reason for each one left out).
      // SPIR-V storage and types: the StorageBuffer class, 8/16-bit storage and arithmetic, relaxed block layouts
      // (modules are validated for Vulkan 1.3, which has them; the compiler follows the Offset decorations).
      {VK_KHR_STORAGE_BUFFER_STORAGE_CLASS_EXTENSION_NAME, VK_KHR_STORAGE_BUFFER_STORAGE_CLASS_SPEC_VERSION},
      {VK_KHR_16BIT_STORAGE_EXTENSION_NAME, VK_KHR_16BIT_STORAGE_SPEC_VERSION},
      {VK_KHR_8BIT_STORAGE_EXTENSION_NAME, VK_KHR_8BIT_STORAGE_SPEC_VERSION},
      {VK_KHR_SHADER_FLOAT16_INT8_EXTENSION_NAME, VK_KHR_SHADER_FLOAT16_INT8_SPEC_VERSION},
      {VK_KHR_RELAXED_BLOCK_LAYOUT_EXTENSION_NAME, VK_KHR_RELAXED_BLOCK_LAYOUT_SPEC_VERSION},
      // NonSemantic.* instruction sets: ignored by the compiler, as they may be.
      {VK_KHR_SHADER_NON_SEMANTIC_INFO_EXTENSION_NAME, VK_KHR_SHADER_NON_SEMANTIC_INFO_SPEC_VERSION},
      // Queries and structures: driver properties, tool properties (none: vkrt is no tool), VkFormatProperties3,
      // image format lists (views checked against them), pipeline creation feedback (compute and ray tracing).
      {VK_KHR_DRIVER_PROPERTIES_EXTENSION_NAME, VK_KHR_DRIVER_PROPERTIES_SPEC_VERSION},
      {VK_EXT_TOOLING_INFO_EXTENSION_NAME, VK_EXT_TOOLING_INFO_SPEC_VERSION},
      {VK_KHR_FORMAT_FEATURE_FLAGS_2_EXTENSION_NAME, VK_KHR_FORMAT_FEATURE_FLAGS_2_SPEC_VERSION},
      {VK_KHR_IMAGE_FORMAT_LIST_EXTENSION_NAME, VK_KHR_IMAGE_FORMAT_LIST_SPEC_VERSION},
      {VK_EXT_PIPELINE_CREATION_FEEDBACK_EXTENSION_NAME, VK_EXT_PIPELINE_CREATION_FEEDBACK_SPEC_VERSION},
      // External memory, semaphores and fences define no handle type of their own: their structures are taken with
      // handle types 0 and the queries answer that vkrt exports and imports none (no VK_KHR_external_*_fd).
      {VK_KHR_EXTERNAL_MEMORY_EXTENSION_NAME, VK_KHR_EXTERNAL_MEMORY_SPEC_VERSION},
      {VK_KHR_EXTERNAL_SEMAPHORE_EXTENSION_NAME, VK_KHR_EXTERNAL_SEMAPHORE_SPEC_VERSION},
      {VK_KHR_EXTERNAL_FENCE_EXTENSION_NAME, VK_KHR_EXTERNAL_FENCE_SPEC_VERSION},
      // subgroupSizeControl and computeFullSubgroups (runtime/shader_stage.cpp).
      {VK_EXT_SUBGROUP_SIZE_CONTROL_EXTENSION_NAME, VK_EXT_SUBGROUP_SIZE_CONTROL_SPEC_VERSION},
      // Private data slots (runtime/private_data_slot.cpp) and privateData.
      {VK_EXT_PRIVATE_DATA_EXTENSION_NAME, VK_EXT_PRIVATE_DATA_SPEC_VERSION},
      // texelBufferAlignment (supported_features.cpp, runtime/buffer_view.cpp).
      {VK_EXT_TEXEL_BUFFER_ALIGNMENT_EXTENSION_NAME, VK_EXT_TEXEL_BUFFER_ALIGNMENT_SPEC_VERSION},
      // robustImageAccess (supported_features.cpp).
      {VK_EXT_IMAGE_ROBUSTNESS_EXTENSION_NAME, VK_EXT_IMAGE_ROBUSTNESS_SPEC_VERSION},
      // shaderBufferInt64Atomics and shaderSharedInt64Atomics (supported_features.cpp).
      {VK_KHR_SHADER_ATOMIC_INT64_EXTENSION_NAME, VK_KHR_SHADER_ATOMIC_INT64_SPEC_VERSION},
      // Fragment termination and subgroup extended types (supported_features.cpp).
      {VK_EXT_SHADER_DEMOTE_TO_HELPER_INVOCATION_EXTENSION_NAME,
       VK_EXT_SHADER_DEMOTE_TO_HELPER_INVOCATION_SPEC_VERSION},
      {VK_KHR_SHADER_TERMINATE_INVOCATION_EXTENSION_NAME, VK_KHR_SHADER_TERMINATE_INVOCATION_SPEC_VERSION},
      {VK_KHR_SHADER_SUBGROUP_EXTENDED_TYPES_EXTENSION_NAME, VK_KHR_SHADER_SUBGROUP_EXTENDED_TYPES_SPEC_VERSION},
      // vulkanMemoryModel (supported_features.cpp).
      {VK_KHR_VULKAN_MEMORY_MODEL_EXTENSION_NAME, VK_KHR_VULKAN_MEMORY_MODEL_SPEC_VERSION},
      // The address mode, and samplerMirrorClampToEdge (supported_features.cpp).
      {VK_KHR_SAMPLER_MIRROR_CLAMP_TO_EDGE_EXTENSION_NAME, VK_KHR_SAMPLER_MIRROR_CLAMP_TO_EDGE_SPEC_VERSION},
      // Graphics (src/gfx): render passes 2, dynamic rendering, imageless framebuffers, multiview, depth/stencil
      // resolves and separate depth/stencil layouts, the count draws.
      {VK_KHR_CREATE_RENDERPASS_2_EXTENSION_NAME, VK_KHR_CREATE_RENDERPASS_2_SPEC_VERSION},
      {VK_KHR_DYNAMIC_RENDERING_EXTENSION_NAME, VK_KHR_DYNAMIC_RENDERING_SPEC_VERSION},
      {VK_KHR_IMAGELESS_FRAMEBUFFER_EXTENSION_NAME, VK_KHR_IMAGELESS_FRAMEBUFFER_SPEC_VERSION},
      {VK_KHR_MULTIVIEW_EXTENSION_NAME, VK_KHR_MULTIVIEW_SPEC_VERSION},
      {VK_KHR_DEPTH_STENCIL_RESOLVE_EXTENSION_NAME, VK_KHR_DEPTH_STENCIL_RESOLVE_SPEC_VERSION},
      {VK_KHR_SEPARATE_DEPTH_STENCIL_LAYOUTS_EXTENSION_NAME, VK_KHR_SEPARATE_DEPTH_STENCIL_LAYOUTS_SPEC_VERSION},
      {VK_KHR_DRAW_INDIRECT_COUNT_EXTENSION_NAME, VK_KHR_DRAW_INDIRECT_COUNT_SPEC_VERSION},
      // VkImageStencilUsageCreateInfo: the stencil aspect's own usage (runtime/image.hpp Image::stencilUsage).
      {VK_EXT_SEPARATE_STENCIL_USAGE_EXTENSION_NAME, VK_EXT_SEPARATE_STENCIL_USAGE_SPEC_VERSION},
      // shaderDrawParameters (supported_features.cpp); the 1.3 dynamic state with extendedDynamicState, and
      // extendedDynamicState2 with its logic op (gfx/dynamic_state.cpp); maintenance2:
      // pointClippingBehavior ALL_CLIP_PLANES (src/raster drops a point whose vertex is outside the view volume), its
      // structures (input attachment aspects narrow what an application may do, vkrt needs them not; view usage is
      // the usage the view's checks read, runtime/image_view.cpp;
      // the tessellation domain origin has no stage to apply to) and layouts (not tracked).
      {VK_KHR_SHADER_DRAW_PARAMETERS_EXTENSION_NAME, VK_KHR_SHADER_DRAW_PARAMETERS_SPEC_VERSION},
      {VK_EXT_EXTENDED_DYNAMIC_STATE_EXTENSION_NAME, VK_EXT_EXTENDED_DYNAMIC_STATE_SPEC_VERSION},
      {VK_EXT_EXTENDED_DYNAMIC_STATE_2_EXTENSION_NAME, VK_EXT_EXTENDED_DYNAMIC_STATE_2_SPEC_VERSION},
      {VK_KHR_MAINTENANCE_2_EXTENSION_NAME, VK_KHR_MAINTENANCE_2_SPEC_VERSION},
      // Push descriptors: a set the command buffer builds per push (runtime/push_descriptor_commands.cpp), and push
      // descriptor update templates (runtime/descriptor_update_template.cpp).
      {VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME, VK_KHR_PUSH_DESCRIPTOR_SPEC_VERSION},
  };
  // Ray tracing (runtime/ray_tracing_features.cpp).
  appendRayTracingExtensions(extensions_);
  rayTracingProperties = rayTracingPipelineProperties();
  accelerationStructureProperties = vkrt::accelerationStructureProperties();
  rayTracingPropertiesNV = vkrt::rayTracingPropertiesNV();
}

bool PhysicalDevice::supportsExtension(const char* name) const {
  return std::any_of(extensions_.begin(), extensions_.end(),
                     [&](const VkExtensionProperties& e) { return std::strcmp(e.extensionName, name) == 0; });
}

bool PhysicalDevice::available(const char* extension, uint32_t version) const {
  // Core structures and those promoted to Vulkan 1.1-1.3 exist on a 1.3 device; the others with their extension.
  return !extension || version >= 10 || supportsExtension(extension);
}

VkPhysicalDeviceFeatures PhysicalDevice::features10() const {
  VkPhysicalDeviceFeatures f{};
  writeFeatures(kFeatureStructs[0], &f);
  return f;
}

void PhysicalDevice::writeFeatures(const FeatureStruct& fs, void* out) const {
  for (uint32_t i = 0; i < fs.count; ++i) {
    VkBool32 v = supported[size_t(fs.members[i].feature)] ? VK_TRUE : VK_FALSE;
    std::memcpy(static_cast<char*>(out) + fs.members[i].offset, &v, sizeof v);
  }
}

void PhysicalDevice::fillFeatures(VkPhysicalDeviceFeatures2* out) const {
  out->features = features10();
  for (auto* s = static_cast<VkBaseOutStructure*>(out->pNext); s; s = s->pNext) {
    const FeatureStruct* fs = featureStruct(s->sType);
    // Structures of other extensions are left untouched, as the specification requires of unknown ones.
    if (fs && available(fs->extension, fs->version)) writeFeatures(*fs, s);
  }
}

namespace {

// VK_KHR_push_descriptor's limit (runtime/descriptor_set_layout.hpp).
const VkPhysicalDevicePushDescriptorPropertiesKHR kPushDescriptorProperties{
    VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PUSH_DESCRIPTOR_PROPERTIES_KHR, nullptr, kMaxPushDescriptors};

}  // namespace

void PhysicalDevice::fillProperties(VkPhysicalDeviceProperties2* out) const {
  out->properties = properties10;
  const void* core[4] = {nullptr, &properties11, &properties12, &properties13};
  for (auto* s = static_cast<VkBaseOutStructure*>(out->pNext); s; s = s->pNext) {
    const PropertyStruct* ps = propertyStruct(s->sType);
    if (!ps || !available(ps->extension, ps->version)) continue;
    VkBaseOutStructure* next = s->pNext;
    const void* whole = nullptr;
    switch (s->sType) {
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_PROPERTIES: whole = &properties11; break;
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_PROPERTIES: whole = &properties12; break;
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_PROPERTIES: whole = &properties13; break;
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_PROPERTIES_KHR: whole = &rayTracingProperties; break;
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_PROPERTIES_KHR:
        whole = &accelerationStructureProperties;
        break;
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PROPERTIES_NV: whole = &rayTracingPropertiesNV; break;
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PUSH_DESCRIPTOR_PROPERTIES_KHR: whole = &kPushDescriptorProperties; break;
      default: break;
    }
    if (whole) {
      std::memcpy(s, whole, ps->size);
    } else {
      // A structure promoted to Vulkan 1.1-1.3: each member from the core structure that took it over.
      for (uint32_t i = 0; i < ps->count; ++i) {
        const PropertyCopy& c = ps->copies[i];
        std::memcpy(reinterpret_cast<char*>(s) + c.offset,
                    static_cast<const char*>(core[c.source - 10]) + c.sourceOffset, c.size);
      }
    }
    s->sType = static_cast<VkStructureType>(ps->sType);
    s->pNext = next;
  }
}

std::string PhysicalDevice::firstUnsupportedFeature(const VkDeviceCreateInfo& info) const {
  auto check = [&](const FeatureStruct& fs, const void* requested) -> std::string {
    for (uint32_t i = 0; i < fs.count; ++i) {
      VkBool32 v;
      std::memcpy(&v, static_cast<const char*>(requested) + fs.members[i].offset, sizeof v);
      if (v && !supported[size_t(fs.members[i].feature)]) return std::string(fs.name) + "::" + fs.members[i].name;
    }
    return {};
  };
  if (info.pEnabledFeatures)
    if (std::string bad = check(kFeatureStructs[0], info.pEnabledFeatures); !bad.empty()) return bad;
  for (auto* s = static_cast<const VkBaseInStructure*>(info.pNext); s; s = s->pNext) {
    std::string bad;
    if (s->sType == VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2) {
      bad = check(kFeatureStructs[0], &reinterpret_cast<const VkPhysicalDeviceFeatures2*>(s)->features);
    } else if (const FeatureStruct* fs = featureStruct(s->sType)) {
      bad = check(*fs, s);
    }
    if (!bad.empty()) return bad;
  }
  return {};
}

FeatureSet enabledFeatures(const VkDeviceCreateInfo& info) {
  FeatureSet set;
  auto gather = [&](const FeatureStruct& fs, const void* p) {
    for (uint32_t i = 0; i < fs.count; ++i) {
      VkBool32 v;
      std::memcpy(&v, static_cast<const char*>(p) + fs.members[i].offset, sizeof v);
      if (v) set.set(size_t(fs.members[i].feature));
    }
  };
  if (info.pEnabledFeatures) gather(kFeatureStructs[0], info.pEnabledFeatures);
  for (auto* s = static_cast<const VkBaseInStructure*>(info.pNext); s; s = s->pNext) {
    if (s->sType == VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2) {
      gather(kFeatureStructs[0], &reinterpret_cast<const VkPhysicalDeviceFeatures2*>(s)->features);
    } else if (const FeatureStruct* fs = featureStruct(s->sType)) {
      gather(*fs, s);
    }
  }
  return set;
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
  *pFeatures = pd(physicalDevice)->features10();
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
    *pCount = PhysicalDevice::kQueueFamilyCount;
    return;
  }
  *pCount = std::min(*pCount, PhysicalDevice::kQueueFamilyCount);
  for (uint32_t i = 0; i < *pCount; ++i) pProps[i] = pd(physicalDevice)->queueFamilies[i];
}

VKAPI_ATTR void VKAPI_CALL vkrt_GetPhysicalDeviceQueueFamilyProperties2(VkPhysicalDevice physicalDevice,
                                                                        uint32_t* pCount,
                                                                        VkQueueFamilyProperties2* pProps) {
  if (!pProps) {
    *pCount = PhysicalDevice::kQueueFamilyCount;
    return;
  }
  *pCount = std::min(*pCount, PhysicalDevice::kQueueFamilyCount);
  for (uint32_t i = 0; i < *pCount; ++i) pProps[i].queueFamilyProperties = pd(physicalDevice)->queueFamilies[i];
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

// External memory, fences and semaphores (core in Vulkan 1.1): vkrt exports and imports no handle type, which the
// answers say (no features, no compatible or exportable types); the queries themselves are valid for every type.
VKAPI_ATTR void VKAPI_CALL
vkrt_GetPhysicalDeviceExternalBufferProperties(VkPhysicalDevice, const VkPhysicalDeviceExternalBufferInfo*,
                                               VkExternalBufferProperties* pExternalBufferProperties) {
  pExternalBufferProperties->externalMemoryProperties = {};
}

VKAPI_ATTR void VKAPI_CALL vkrt_GetPhysicalDeviceExternalFenceProperties(
    VkPhysicalDevice, const VkPhysicalDeviceExternalFenceInfo*, VkExternalFenceProperties* pExternalFenceProperties) {
  pExternalFenceProperties->exportFromImportedHandleTypes = 0;
  pExternalFenceProperties->compatibleHandleTypes = 0;
  pExternalFenceProperties->externalFenceFeatures = 0;
}

VKAPI_ATTR void VKAPI_CALL
vkrt_GetPhysicalDeviceExternalSemaphoreProperties(VkPhysicalDevice, const VkPhysicalDeviceExternalSemaphoreInfo*,
                                                  VkExternalSemaphoreProperties* pExternalSemaphoreProperties) {
  pExternalSemaphoreProperties->exportFromImportedHandleTypes = 0;
  pExternalSemaphoreProperties->compatibleHandleTypes = 0;
  pExternalSemaphoreProperties->externalSemaphoreFeatures = 0;
}

}  // extern "C"
