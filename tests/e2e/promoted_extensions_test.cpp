// Extensions promoted to Vulkan 1.1-1.3 that applications written for older versions still enable by name, each
// enabled that way on a device with the validation layer on, and what it adds exercised: SPIR-V 1.0 modules with
// the storage and type extensions, driver and tool properties, VkFormatProperties3, image format lists, pipeline
// creation feedback, NonSemantic instruction sets, external memory / semaphore / fence structures with no handle
// type, and mirror clamp to edge without the feature. (Texel buffers and descriptor indexing:
// texel_buffer_test.cpp; SPIR-V 1.4: spirv14_test.cpp.)
//
// And the audit that keeps the device's extension list honest (kPromoted, at the end): every extension vk.xml
// says was promoted to Vulkan 1.1, 1.2 or 1.3 is in a table, listed by vkrt or absent for the reason the table
// gives; the listed ones carry the registry's spec version, are enabled all at once by name under the validation
// layer, and their commands resolve.
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "compute_debug_printf.comp.spv.h"
#include "compute_subgroup_basic.comp.spv.h"
#include "compute_vulkan10_storage.spvasm.spv.h"
#include "e2e/compute_pipeline_helpers.hpp"
#include "e2e/fixture.hpp"

namespace vkrt::test {
namespace {

constexpr VkDescriptorType kStorageBuffer = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;

class PromotedTest : public VulkanTest {
 protected:
  // Runs `p` (binding i of its set: storage buffer buffers[i]) over `groups` workgroups and waits.
  void run(ComputePipeline& p, const std::vector<const HostBuffer*>& buffers, uint32_t groups) {
    writeStorageBuffers(device, p, buffers);
    VkCommandBuffer cb = beginOneTime();
    recordDispatch(cb, p, groups);
    submitAndWait(cb);
  }
};

// ---- a SPIR-V 1.0 module with the storage and type extensions

class Vulkan10StorageTest : public PromotedTest {
 protected:
  VkPhysicalDeviceVulkan11Features f11{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES};
  FixtureOptions options() override {
    FixtureOptions o;
    o.deviceExtensions = {VK_KHR_STORAGE_BUFFER_STORAGE_CLASS_EXTENSION_NAME, VK_KHR_16BIT_STORAGE_EXTENSION_NAME,
                          VK_KHR_8BIT_STORAGE_EXTENSION_NAME, VK_KHR_SHADER_FLOAT16_INT8_EXTENSION_NAME,
                          VK_KHR_RELAXED_BLOCK_LAYOUT_EXTENSION_NAME};
    o.features.shaderInt16 = VK_TRUE;
    o.shaderSmallTypes = true;  // shaderInt8, shaderFloat16, storageBuffer8BitAccess
    f11.storageBuffer16BitAccess = VK_TRUE;
    o.featureChain = &f11;
    return o;
  }
};

uint16_t toHalf(float f) {
  _Float16 h = _Float16(f);
  uint16_t u;
  std::memcpy(&u, &h, 2);
  return u;
}

TEST_F(Vulkan10StorageTest, StorageBufferClassSmallTypesAndARelaxedVec3) {
  ASSERT_EQ(kSpv_compute_vulkan10_storage_spvasm[1], 0x00010000u) << "a SPIR-V 1.0 module";
  ComputePipeline p =
      makeComputePipeline(device, kSpv_compute_vulkan10_storage_spvasm, sizeof kSpv_compute_vulkan10_storage_spvasm,
                          {kStorageBuffer, kStorageBuffer});
  ASSERT_EQ(p.result, VK_SUCCESS);
  // tests/shaders/compute_vulkan10_storage.spvasm's blocks.
  struct In {
    uint8_t bytes[8];
    int16_t shorts[8];
    uint16_t halves[8];
    uint32_t scale;
    uint32_t pad[2];
    float bias[3];  // byte 52: a vec3 that only relaxed block layout allows there
  } in{};
  static_assert(offsetof(In, scale) == 40 && offsetof(In, bias) == 52);
  struct Out {
    float f[8];
    int16_t s[8];
    uint8_t b[8];
  };
  for (int g = 0; g < 8; ++g) {
    in.bytes[g] = uint8_t(30 * g + 20);
    in.shorts[g] = int16_t(1000 * g - 3500);
    in.halves[g] = toHalf(0.5f * float(g) - 1.25f);
  }
  in.scale = 3;
  in.bias[0] = 0.25f;
  in.bias[1] = -1.5f;
  in.bias[2] = 3.0f;
  HostBuffer inBuf = createHostBuffer(sizeof in, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  std::memcpy(inBuf.data, &in, sizeof in);
  HostBuffer outBuf = createHostBuffer(sizeof(Out), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  std::memset(outBuf.data, 0x5a, outBuf.size);
  run(p, {&inBuf, &outBuf}, 1);
  const Out* o = static_cast<const Out*>(outBuf.data);
  for (int g = 0; g < 8; ++g) {
    SCOPED_TRACE("invocation " + std::to_string(g));
    float want = float(int(in.bytes[g]) + int(in.shorts[g]) * 3) + 2 * (0.5f * float(g) - 1.25f) + in.bias[g % 3];
    EXPECT_EQ(o->f[g], want) << "8/16-bit loads, 16-bit float arithmetic, the vec3 at byte 52";
    EXPECT_EQ(o->s[g], int16_t(in.shorts[g] * -3)) << "16-bit store";
    EXPECT_EQ(o->b[g], uint8_t(in.bytes[g] + 200)) << "8-bit store, wrapped";
  }
  destroy(inBuf);
  destroy(outBuf);
  destroyComputePipeline(device, p);
}

// ---- queries and structures

class PromotedQueriesTest : public PromotedTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o;
    o.deviceExtensions = {VK_KHR_DRIVER_PROPERTIES_EXTENSION_NAME,
                          VK_EXT_TOOLING_INFO_EXTENSION_NAME,
                          VK_KHR_FORMAT_FEATURE_FLAGS_2_EXTENSION_NAME,
                          VK_KHR_IMAGE_FORMAT_LIST_EXTENSION_NAME,
                          VK_EXT_PIPELINE_CREATION_FEEDBACK_EXTENSION_NAME,
                          VK_KHR_SHADER_NON_SEMANTIC_INFO_EXTENSION_NAME,
                          VK_KHR_EXTERNAL_MEMORY_EXTENSION_NAME,
                          VK_KHR_EXTERNAL_SEMAPHORE_EXTENSION_NAME,
                          VK_KHR_EXTERNAL_FENCE_EXTENSION_NAME,
                          VK_KHR_SAMPLER_MIRROR_CLAMP_TO_EDGE_EXTENSION_NAME};
    // VUID-VkDeviceCreateInfo-ppEnabledExtensionNames-02832: with VkPhysicalDeviceVulkan12Features chained (the
    // fixture chains one), the extension's feature is enabled too.
    o.features12.samplerMirrorClampToEdge = VK_TRUE;
    return o;
  }
};

TEST_F(PromotedQueriesTest, DriverProperties) {
  VkPhysicalDeviceDriverProperties driver{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES};
  std::memset(driver.driverName, 'x', sizeof driver.driverName);
  VkPhysicalDeviceVulkan12Properties p12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_PROPERTIES, &driver};
  VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &p12};
  vkGetPhysicalDeviceProperties2(physicalDevice, &p2);
  EXPECT_STREQ(driver.driverName, p12.driverName);
  EXPECT_STREQ(driver.driverInfo, p12.driverInfo);
  EXPECT_EQ(driver.driverID, p12.driverID);
  if (onVkrt()) {
    EXPECT_STREQ(driver.driverName, "vkrt");
  }
}

TEST_F(PromotedQueriesTest, ToolPropertiesThroughTheExtensionsCommand) {
  auto get = reinterpret_cast<PFN_vkGetPhysicalDeviceToolPropertiesEXT>(
      vkGetInstanceProcAddr(instance, "vkGetPhysicalDeviceToolPropertiesEXT"));
  ASSERT_NE(get, nullptr);
  uint32_t n = 0;
  ASSERT_EQ(get(physicalDevice, &n, nullptr), VK_SUCCESS);
  std::vector<VkPhysicalDeviceToolProperties> tools(n, {VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_TOOL_PROPERTIES});
  ASSERT_EQ(get(physicalDevice, &n, tools.data()), VK_SUCCESS);
  // The validation layer reports itself; vkrt is no tool and adds nothing.
  EXPECT_GE(n, 1u) << "the validation layer";
  for (const VkPhysicalDeviceToolProperties& t : tools) {
    EXPECT_GT(std::strlen(t.name), 0u);
    if (onVkrt()) {
      EXPECT_TRUE(t.purposes & VK_TOOL_PURPOSE_VALIDATION_BIT) << t.name;
    }
  }
}

TEST_F(PromotedQueriesTest, FormatProperties3AgreesWithFormatProperties) {
  int supported = 0;
  for (int f = VK_FORMAT_R4G4_UNORM_PACK8; f <= VK_FORMAT_ASTC_12x12_SRGB_BLOCK; ++f) {
    VkFormatProperties3 p3{VK_STRUCTURE_TYPE_FORMAT_PROPERTIES_3};
    p3.linearTilingFeatures = p3.optimalTilingFeatures = p3.bufferFeatures = ~0ull;
    VkFormatProperties2 p2{VK_STRUCTURE_TYPE_FORMAT_PROPERTIES_2, &p3};
    vkGetPhysicalDeviceFormatProperties2(physicalDevice, VkFormat(f), &p2);
    const VkFormatProperties& p = p2.formatProperties;
    SCOPED_TRACE("format " + std::to_string(f));
    // VkFormatFeatureFlagBits' bits (0-30) are the same bits in VkFormatFeatureFlags2; bit 31 and up exist only
    // there (STORAGE_READ_WITHOUT_FORMAT is bit 31, STORAGE_WRITE_WITHOUT_FORMAT bit 32).
    constexpr VkFormatFeatureFlags2 kLegacyBits = 0x7fffffffull;
    EXPECT_EQ(p3.linearTilingFeatures & kLegacyBits, p.linearTilingFeatures);
    EXPECT_EQ(p3.optimalTilingFeatures & kLegacyBits, p.optimalTilingFeatures);
    EXPECT_EQ(p3.bufferFeatures & kLegacyBits, p.bufferFeatures);
    if (onVkrt()) {
      // Beyond them vkrt has only the storage image reads and writes without a format, and those only where the
      // format is a storage image format, and depth comparison, only on sampled depth formats.
      const VkFormatFeatureFlags2 withoutFormat =
          VK_FORMAT_FEATURE_2_STORAGE_READ_WITHOUT_FORMAT_BIT | VK_FORMAT_FEATURE_2_STORAGE_WRITE_WITHOUT_FORMAT_BIT;
      const VkFormatFeatureFlags2 depthCompare = VK_FORMAT_FEATURE_2_SAMPLED_IMAGE_DEPTH_COMPARISON_BIT;
      EXPECT_EQ(p3.optimalTilingFeatures & ~kLegacyBits & ~withoutFormat & ~depthCompare, 0u);
      if (p3.optimalTilingFeatures & withoutFormat) {
        EXPECT_TRUE(p.optimalTilingFeatures & VK_FORMAT_FEATURE_STORAGE_IMAGE_BIT);
      }
      if (p3.optimalTilingFeatures & depthCompare) {
        EXPECT_TRUE((p.optimalTilingFeatures & VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT) &&
                    (p.optimalTilingFeatures & VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT));
      }
      EXPECT_EQ(p3.bufferFeatures & ~kLegacyBits, 0u);
    }
    supported += p.optimalTilingFeatures != 0;
  }
  EXPECT_GT(supported, 20);
}

TEST_F(PromotedQueriesTest, ImageFormatListNamesTheViewFormats) {
  const VkFormat formats[2] = {VK_FORMAT_R32_UINT, VK_FORMAT_R32_SFLOAT};
  VkImageFormatListCreateInfo list{VK_STRUCTURE_TYPE_IMAGE_FORMAT_LIST_CREATE_INFO};
  list.viewFormatCount = 2;
  list.pViewFormats = formats;
  VkPhysicalDeviceImageFormatInfo2 fi{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_IMAGE_FORMAT_INFO_2, &list};
  fi.format = VK_FORMAT_R32_UINT;
  fi.type = VK_IMAGE_TYPE_2D;
  fi.tiling = VK_IMAGE_TILING_OPTIMAL;
  fi.usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;
  fi.flags = VK_IMAGE_CREATE_MUTABLE_FORMAT_BIT;
  VkImageFormatProperties2 props{VK_STRUCTURE_TYPE_IMAGE_FORMAT_PROPERTIES_2};
  ASSERT_EQ(vkGetPhysicalDeviceImageFormatProperties2(physicalDevice, &fi, &props), VK_SUCCESS);
  VkImageCreateInfo ci{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO, &list};
  ci.flags = VK_IMAGE_CREATE_MUTABLE_FORMAT_BIT;
  ci.imageType = VK_IMAGE_TYPE_2D;
  ci.format = VK_FORMAT_R32_UINT;
  ci.extent = {8, 8, 1};
  ci.mipLevels = ci.arrayLayers = 1;
  ci.samples = VK_SAMPLE_COUNT_1_BIT;
  ci.tiling = VK_IMAGE_TILING_OPTIMAL;
  ci.usage = fi.usage;
  VkImage image = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateImage(device, &ci, nullptr, &image), VK_SUCCESS);
  VkMemoryRequirements req;
  vkGetImageMemoryRequirements(device, image, &req);
  VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  mai.allocationSize = req.size;
  mai.memoryTypeIndex = memoryTypeIndex(req.memoryTypeBits, 0);
  VkDeviceMemory memory = VK_NULL_HANDLE;
  ASSERT_EQ(vkAllocateMemory(device, &mai, nullptr, &memory), VK_SUCCESS);
  ASSERT_EQ(vkBindImageMemory(device, image, memory, 0), VK_SUCCESS);
  for (VkFormat f : formats) {
    VkImageViewCreateInfo vi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    vi.image = image;
    vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
    vi.format = f;
    vi.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    VkImageView view = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreateImageView(device, &vi, nullptr, &view), VK_SUCCESS) << "format " << f;
    vkDestroyImageView(device, view, nullptr);
  }
  vkDestroyImage(device, image, nullptr);
  vkFreeMemory(device, memory, nullptr);
}

TEST_F(PromotedQueriesTest, PipelineCreationFeedbackIsValid) {
  ComputePipeline p;
  VkPipelineCreationFeedback pipelineFb{}, stageFb{};
  VkPipelineCreationFeedbackCreateInfo fb{VK_STRUCTURE_TYPE_PIPELINE_CREATION_FEEDBACK_CREATE_INFO};
  fb.pPipelineCreationFeedback = &pipelineFb;
  fb.pipelineStageCreationFeedbackCount = 1;
  fb.pPipelineStageCreationFeedbacks = &stageFb;
  VkPipelineLayoutCreateInfo pl{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  VkDescriptorSetLayoutBinding b{0, kStorageBuffer, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
  VkDescriptorSetLayoutCreateInfo dl{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  dl.bindingCount = 1;
  dl.pBindings = &b;
  ASSERT_EQ(vkCreateDescriptorSetLayout(device, &dl, nullptr, &p.setLayout), VK_SUCCESS);
  pl.setLayoutCount = 1;
  pl.pSetLayouts = &p.setLayout;
  ASSERT_EQ(vkCreatePipelineLayout(device, &pl, nullptr, &p.layout), VK_SUCCESS);
  VkShaderModuleCreateInfo sm{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  sm.codeSize = sizeof kSpv_compute_debug_printf_comp;
  sm.pCode = kSpv_compute_debug_printf_comp;
  ASSERT_EQ(vkCreateShaderModule(device, &sm, nullptr, &p.module), VK_SUCCESS);
  VkComputePipelineCreateInfo ci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO, &fb};
  ci.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
  ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  ci.stage.module = p.module;
  ci.stage.pName = "main";
  ci.layout = p.layout;
  ASSERT_EQ(vkCreateComputePipelines(device, VK_NULL_HANDLE, 1, &ci, nullptr, &p.pipeline), VK_SUCCESS);
  if (onVkrt()) {  // another driver may leave the feedback invalid, as the specification allows
    EXPECT_TRUE(pipelineFb.flags & VK_PIPELINE_CREATION_FEEDBACK_VALID_BIT);
    EXPECT_TRUE(stageFb.flags & VK_PIPELINE_CREATION_FEEDBACK_VALID_BIT);
    EXPECT_GT(pipelineFb.duration, 0u);
  }
  destroyComputePipeline(device, p);
}

// glslc puts debugPrintfEXT in the NonSemantic.DebugPrintf instruction set (with SPV_KHR_non_semantic_info): the
// shader computes what it computes without the calls. vkrt delivers their messages at INFO severity, which this
// fixture's messenger does not take (tests/e2e/shader_debug_test.cpp reads them).
TEST_F(PromotedQueriesTest, NonSemanticInstructionsLeaveTheResultsAlone) {
  const std::string words(reinterpret_cast<const char*>(kSpv_compute_debug_printf_comp),
                          sizeof kSpv_compute_debug_printf_comp);
  ASSERT_NE(words.find("NonSemantic.DebugPrintf"), std::string::npos);
  ASSERT_NE(words.find("SPV_KHR_non_semantic_info"), std::string::npos);
  ComputePipeline p = makeComputePipeline(device, kSpv_compute_debug_printf_comp, sizeof kSpv_compute_debug_printf_comp,
                                          {kStorageBuffer});
  ASSERT_EQ(p.result, VK_SUCCESS);
  HostBuffer out = createHostBuffer(16 * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  run(p, {&out}, 4);
  const auto* o = static_cast<const uint32_t*>(out.data);
  for (uint32_t i = 0; i < 16; ++i) EXPECT_EQ(o[i], i * 7 + 1) << i;
  destroy(out);
  destroyComputePipeline(device, p);
}

// External memory, semaphores and fences with no handle type: the creation structures are taken, the queries
// answer which types the driver exports and imports (vkrt: none).
TEST_F(PromotedQueriesTest, ExternalObjectsWithoutHandleTypes) {
  VkExternalMemoryBufferCreateInfo eb{VK_STRUCTURE_TYPE_EXTERNAL_MEMORY_BUFFER_CREATE_INFO};
  VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO, &eb};
  bci.size = 256;
  bci.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  VkBuffer buffer = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateBuffer(device, &bci, nullptr, &buffer), VK_SUCCESS);
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(device, buffer, &req);
  VkExportMemoryAllocateInfo em{VK_STRUCTURE_TYPE_EXPORT_MEMORY_ALLOCATE_INFO};
  VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, &em};
  mai.allocationSize = req.size;
  mai.memoryTypeIndex = memoryTypeIndex(req.memoryTypeBits, 0);
  VkDeviceMemory memory = VK_NULL_HANDLE;
  ASSERT_EQ(vkAllocateMemory(device, &mai, nullptr, &memory), VK_SUCCESS);
  EXPECT_EQ(vkBindBufferMemory(device, buffer, memory, 0), VK_SUCCESS);
  VkExportFenceCreateInfo ef{VK_STRUCTURE_TYPE_EXPORT_FENCE_CREATE_INFO};
  VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO, &ef};
  VkFence fence = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateFence(device, &fci, nullptr, &fence), VK_SUCCESS);
  VkExportSemaphoreCreateInfo es{VK_STRUCTURE_TYPE_EXPORT_SEMAPHORE_CREATE_INFO};
  VkSemaphoreCreateInfo sci{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO, &es};
  VkSemaphore semaphore = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateSemaphore(device, &sci, nullptr, &semaphore), VK_SUCCESS);
  // The objects work as any other: the fence is signalled by an empty submission that signals the semaphore.
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.signalSemaphoreCount = 1;
  si.pSignalSemaphores = &semaphore;
  ASSERT_EQ(vkQueueSubmit(queue, 1, &si, fence), VK_SUCCESS);
  EXPECT_EQ(vkWaitForFences(device, 1, &fence, VK_TRUE, UINT64_MAX), VK_SUCCESS);
  EXPECT_EQ(vkQueueWaitIdle(queue), VK_SUCCESS);

  if (onVkrt()) {
    VkPhysicalDeviceExternalBufferInfo bi{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_EXTERNAL_BUFFER_INFO};
    bi.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    bi.handleType = VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT;
    VkExternalBufferProperties bp{VK_STRUCTURE_TYPE_EXTERNAL_BUFFER_PROPERTIES};
    bp.externalMemoryProperties.externalMemoryFeatures = ~0u;
    vkGetPhysicalDeviceExternalBufferProperties(physicalDevice, &bi, &bp);
    EXPECT_EQ(bp.externalMemoryProperties.externalMemoryFeatures, 0u);
    EXPECT_EQ(bp.externalMemoryProperties.compatibleHandleTypes, 0u);
    VkPhysicalDeviceExternalFenceInfo fi{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_EXTERNAL_FENCE_INFO};
    fi.handleType = VK_EXTERNAL_FENCE_HANDLE_TYPE_OPAQUE_FD_BIT;
    VkExternalFenceProperties fp{VK_STRUCTURE_TYPE_EXTERNAL_FENCE_PROPERTIES};
    fp.externalFenceFeatures = ~0u;
    vkGetPhysicalDeviceExternalFenceProperties(physicalDevice, &fi, &fp);
    EXPECT_EQ(fp.externalFenceFeatures, 0u);
    VkPhysicalDeviceExternalSemaphoreInfo smi{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_EXTERNAL_SEMAPHORE_INFO};
    smi.handleType = VK_EXTERNAL_SEMAPHORE_HANDLE_TYPE_OPAQUE_FD_BIT;
    VkExternalSemaphoreProperties sp{VK_STRUCTURE_TYPE_EXTERNAL_SEMAPHORE_PROPERTIES};
    sp.externalSemaphoreFeatures = ~0u;
    vkGetPhysicalDeviceExternalSemaphoreProperties(physicalDevice, &smi, &sp);
    EXPECT_EQ(sp.externalSemaphoreFeatures, 0u);
    // An image with a handle type vkrt does not export is not supported; handle type 0 is as if none was asked.
    VkPhysicalDeviceExternalImageFormatInfo ei{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_EXTERNAL_IMAGE_FORMAT_INFO};
    ei.handleType = VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT;
    VkPhysicalDeviceImageFormatInfo2 ifi{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_IMAGE_FORMAT_INFO_2, &ei};
    ifi.format = VK_FORMAT_R8G8B8A8_UNORM;
    ifi.type = VK_IMAGE_TYPE_2D;
    ifi.tiling = VK_IMAGE_TILING_OPTIMAL;
    ifi.usage = VK_IMAGE_USAGE_SAMPLED_BIT;
    VkImageFormatProperties2 ip{VK_STRUCTURE_TYPE_IMAGE_FORMAT_PROPERTIES_2};
    EXPECT_EQ(vkGetPhysicalDeviceImageFormatProperties2(physicalDevice, &ifi, &ip), VK_ERROR_FORMAT_NOT_SUPPORTED);
    ei.handleType = VkExternalMemoryHandleTypeFlagBits(0);
    EXPECT_EQ(vkGetPhysicalDeviceImageFormatProperties2(physicalDevice, &ifi, &ip), VK_SUCCESS);
  }
  vkDestroySemaphore(device, semaphore, nullptr);
  vkDestroyFence(device, fence, nullptr);
  vkDestroyBuffer(device, buffer, nullptr);
  vkFreeMemory(device, memory, nullptr);
}

// VK_KHR_sampler_mirror_clamp_to_edge alone allows the address mode (VUID-VkSamplerCreateInfo-addressModeU-01079);
// sampling with it: compute_image_test.cpp, SampleAndFetchWithEveryFilterAndAddressMode.
TEST_F(PromotedQueriesTest, MirrorClampToEdgeSampler) {
  VkSamplerCreateInfo si{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
  si.magFilter = si.minFilter = VK_FILTER_LINEAR;
  si.addressModeU = si.addressModeV = si.addressModeW = VK_SAMPLER_ADDRESS_MODE_MIRROR_CLAMP_TO_EDGE;
  VkSampler s = VK_NULL_HANDLE;
  EXPECT_EQ(vkCreateSampler(device, &si, nullptr, &s), VK_SUCCESS);
  vkDestroySampler(device, s, nullptr);
}

// ---- private data (VK_EXT_private_data by name, the privateData feature, two slots reserved)

class PrivateDataTest : public PromotedTest {
 protected:
  VkDevicePrivateDataCreateInfo reserve{VK_STRUCTURE_TYPE_DEVICE_PRIVATE_DATA_CREATE_INFO};
  FixtureOptions options() override {
    FixtureOptions o;
    o.deviceExtensions = {VK_EXT_PRIVATE_DATA_EXTENSION_NAME};
    o.features13.privateData = VK_TRUE;
    reserve.privateDataSlotRequestCount = 2;
    o.featureChain = &reserve;
    return o;
  }
  template <class F>
  F load(const char* name) {
    auto f = reinterpret_cast<F>(vkGetDeviceProcAddr(device, name));
    EXPECT_NE(f, nullptr) << name;
    return f;
  }
};

TEST_F(PrivateDataTest, ValuesPerSlotAndObjectThroughTheExtensionsCommands) {
  auto create = load<PFN_vkCreatePrivateDataSlotEXT>("vkCreatePrivateDataSlotEXT");
  auto destroySlot = load<PFN_vkDestroyPrivateDataSlotEXT>("vkDestroyPrivateDataSlotEXT");
  auto set = load<PFN_vkSetPrivateDataEXT>("vkSetPrivateDataEXT");
  auto get = load<PFN_vkGetPrivateDataEXT>("vkGetPrivateDataEXT");
  ASSERT_TRUE(create && destroySlot && set && get);
  VkPrivateDataSlotCreateInfo ci{VK_STRUCTURE_TYPE_PRIVATE_DATA_SLOT_CREATE_INFO};
  VkPrivateDataSlot a = VK_NULL_HANDLE, b = VK_NULL_HANDLE;
  ASSERT_EQ(create(device, &ci, nullptr, &a), VK_SUCCESS);
  ASSERT_EQ(create(device, &ci, nullptr, &b), VK_SUCCESS);
  HostBuffer buf = createHostBuffer(64, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  const uint64_t dev = uint64_t(reinterpret_cast<uintptr_t>(device));
  const uint64_t q = uint64_t(reinterpret_cast<uintptr_t>(queue));
  const uint64_t bh = uint64_t(buf.buffer), mh = uint64_t(buf.memory), ah = uint64_t(a);
  // Nothing set reads 0.
  uint64_t v = 7;
  get(device, VK_OBJECT_TYPE_BUFFER, bh, a, &v);
  EXPECT_EQ(v, 0u);
  // One value per slot and object: the device itself, a queue, a buffer, its memory, a slot.
  EXPECT_EQ(set(device, VK_OBJECT_TYPE_DEVICE, dev, a, 1), VK_SUCCESS);
  EXPECT_EQ(set(device, VK_OBJECT_TYPE_QUEUE, q, a, 2), VK_SUCCESS);
  EXPECT_EQ(set(device, VK_OBJECT_TYPE_BUFFER, bh, a, 0xfedcba9876543210ull), VK_SUCCESS);
  EXPECT_EQ(set(device, VK_OBJECT_TYPE_DEVICE_MEMORY, mh, a, 4), VK_SUCCESS);
  EXPECT_EQ(set(device, VK_OBJECT_TYPE_PRIVATE_DATA_SLOT, ah, a, 5), VK_SUCCESS);
  EXPECT_EQ(set(device, VK_OBJECT_TYPE_BUFFER, bh, b, 6), VK_SUCCESS);
  get(device, VK_OBJECT_TYPE_DEVICE, dev, a, &v);
  EXPECT_EQ(v, 1u);
  get(device, VK_OBJECT_TYPE_QUEUE, q, a, &v);
  EXPECT_EQ(v, 2u);
  get(device, VK_OBJECT_TYPE_BUFFER, bh, a, &v);
  EXPECT_EQ(v, 0xfedcba9876543210ull);
  get(device, VK_OBJECT_TYPE_DEVICE_MEMORY, mh, a, &v);
  EXPECT_EQ(v, 4u);
  get(device, VK_OBJECT_TYPE_PRIVATE_DATA_SLOT, ah, a, &v);
  EXPECT_EQ(v, 5u);
  get(device, VK_OBJECT_TYPE_BUFFER, bh, b, &v);
  EXPECT_EQ(v, 6u) << "the other slot keeps its own value";
  get(device, VK_OBJECT_TYPE_DEVICE_MEMORY, mh, b, &v);
  EXPECT_EQ(v, 0u);
  // Overwritten.
  EXPECT_EQ(set(device, VK_OBJECT_TYPE_BUFFER, bh, a, 8), VK_SUCCESS);
  get(device, VK_OBJECT_TYPE_BUFFER, bh, a, &v);
  EXPECT_EQ(v, 8u);
  // A buffer created after another was destroyed (maybe at the same address) has no value.
  destroy(buf);
  HostBuffer again = createHostBuffer(64, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  get(device, VK_OBJECT_TYPE_BUFFER, uint64_t(again.buffer), a, &v);
  EXPECT_EQ(v, 0u);
  destroy(again);
  destroySlot(device, a, nullptr);
  destroySlot(device, b, nullptr);
}

// ---- subgroup size control (VK_EXT_subgroup_size_control by name, both features)

class SubgroupSizeControlTest : public PromotedTest {
 protected:
  bool features = true;
  FixtureOptions options() override {
    FixtureOptions o;
    o.deviceExtensions = {VK_EXT_SUBGROUP_SIZE_CONTROL_EXTENSION_NAME};
    o.features13.subgroupSizeControl = o.features13.computeFullSubgroups = features;
    return o;
  }
  VkPhysicalDeviceVulkan13Properties properties() {
    VkPhysicalDeviceVulkan13Properties p13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_PROPERTIES};
    VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &p13};
    vkGetPhysicalDeviceProperties2(physicalDevice, &p2);
    return p13;
  }
  // compute_subgroup_basic.comp (4 x 2 invocations a workgroup, one storage buffer) with the stage's flags and,
  // unless `size` is 0, a required subgroup size.
  ComputePipeline make(VkPipelineShaderStageCreateFlags flags, uint32_t size) {
    ComputePipeline p = makeComputePipeline(device, kSpv_compute_subgroup_basic_comp,
                                            sizeof kSpv_compute_subgroup_basic_comp, {kStorageBuffer});
    vkDestroyPipeline(device, p.pipeline, nullptr);
    p.pipeline = VK_NULL_HANDLE;
    VkPipelineShaderStageRequiredSubgroupSizeCreateInfo required{
        VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_REQUIRED_SUBGROUP_SIZE_CREATE_INFO};
    required.requiredSubgroupSize = size;
    VkComputePipelineCreateInfo ci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    ci.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, size ? &required : nullptr};
    ci.stage.flags = flags;
    ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    ci.stage.module = p.module;
    ci.stage.pName = "main";
    ci.layout = p.layout;
    p.result = vkCreateComputePipelines(device, VK_NULL_HANDLE, 1, &ci, nullptr, &p.pipeline);
    return p;
  }
  // Runs 2 workgroups; each invocation's {elected, gl_SubgroupSize, gl_SubgroupInvocationID, subgroups}.
  std::vector<uint32_t> run(ComputePipeline& p) {
    HostBuffer out = createHostBuffer(16 * 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    PromotedTest::run(p, {&out}, 2);
    std::vector<uint32_t> v(static_cast<const uint32_t*>(out.data), static_cast<const uint32_t*>(out.data) + 64);
    destroy(out);
    return v;
  }
};

TEST_F(SubgroupSizeControlTest, RequiredVaryingAndFullSubgroups) {
  const VkPhysicalDeviceVulkan13Properties p13 = properties();
  ASSERT_TRUE(p13.requiredSubgroupSizeStages & VK_SHADER_STAGE_COMPUTE_BIT);
  ASSERT_GE(p13.maxSubgroupSize, p13.minSubgroupSize);
  if (onVkrt()) {
    EXPECT_EQ(p13.maxSubgroupSize, 1u);
  }
  // A varying size.
  ComputePipeline varying = make(VK_PIPELINE_SHADER_STAGE_CREATE_ALLOW_VARYING_SUBGROUP_SIZE_BIT, 0);
  ASSERT_EQ(varying.result, VK_SUCCESS);
  std::vector<uint32_t> r = run(varying);
  for (uint32_t i = 0; i < 16; ++i) {
    EXPECT_GE(r[4 * i + 1], p13.minSubgroupSize) << i;
    EXPECT_LE(r[4 * i + 1], p13.maxSubgroupSize) << i;
  }
  destroyComputePipeline(device, varying);
  // The smallest size, required, with full subgroups (the workgroup's x, 4, must be a multiple of it).
  if (4 % p13.minSubgroupSize == 0) {
    ComputePipeline full = make(VK_PIPELINE_SHADER_STAGE_CREATE_REQUIRE_FULL_SUBGROUPS_BIT, p13.minSubgroupSize);
    ASSERT_EQ(full.result, VK_SUCCESS);
    r = run(full);
    for (uint32_t i = 0; i < 16; ++i) EXPECT_EQ(r[4 * i + 1], p13.minSubgroupSize) << "invocation " << i;
    destroyComputePipeline(device, full);
  }
}

class SubgroupSizeControlMisuseTest : public SubgroupSizeControlTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o = SubgroupSizeControlTest::options();
    o.validation = false;
    return o;
  }
  void expectRefused(VkPipelineShaderStageCreateFlags flags, uint32_t size, const char* vuid) {
    ComputePipeline p = make(flags, size);
    EXPECT_EQ(p.result, VK_ERROR_VALIDATION_FAILED_EXT) << vuid;
    expectVkrtMessage(vuid);
    destroyComputePipeline(device, p);
  }
};

TEST_F(SubgroupSizeControlMisuseTest, RequiredSizesOtherThanOneAreReported) {
  if (!onVkrt()) GTEST_SKIP() << "vkrt's own reports";
  expectRefused(0, 2, "VUID-VkPipelineShaderStageRequiredSubgroupSizeCreateInfo-requiredSubgroupSize-02762");
  expectRefused(0, 3, "VUID-VkPipelineShaderStageRequiredSubgroupSizeCreateInfo-requiredSubgroupSize-02760");
  expectRefused(VK_PIPELINE_SHADER_STAGE_CREATE_ALLOW_VARYING_SUBGROUP_SIZE_BIT, 1,
                "VUID-VkPipelineShaderStageCreateInfo-pNext-02754");
}

class SubgroupSizeControlOffMisuseTest : public SubgroupSizeControlMisuseTest {
 protected:
  FixtureOptions options() override {
    features = false;
    FixtureOptions o = SubgroupSizeControlMisuseTest::options();
    o.deviceExtensions.clear();
    return o;
  }
};

TEST_F(SubgroupSizeControlOffMisuseTest, TheFlagsAndARequiredSizeNeedTheFeatures) {
  if (!onVkrt()) GTEST_SKIP() << "vkrt's own reports";
  expectRefused(VK_PIPELINE_SHADER_STAGE_CREATE_ALLOW_VARYING_SUBGROUP_SIZE_BIT, 0,
                "VUID-VkPipelineShaderStageCreateInfo-flags-02784");
  expectRefused(VK_PIPELINE_SHADER_STAGE_CREATE_REQUIRE_FULL_SUBGROUPS_BIT, 0,
                "VUID-VkPipelineShaderStageCreateInfo-flags-02785");
  expectRefused(0, 1, "VUID-VkPipelineShaderStageCreateInfo-pNext-02755");
}

// ---- misuse: vkrt's own reports (the layer off, since it reports the same)

class PromotedMisuseTest : public PromotedTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o;
    o.validation = false;
    return o;
  }
};

TEST_F(PromotedMisuseTest, MirrorClampToEdgeNeedsTheFeatureOrTheExtension) {
  if (!onVkrt()) GTEST_SKIP() << "vkrt's own reports";
  VkSamplerCreateInfo si{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
  si.addressModeV = VK_SAMPLER_ADDRESS_MODE_MIRROR_CLAMP_TO_EDGE;
  VkSampler s = VK_NULL_HANDLE;
  EXPECT_EQ(vkCreateSampler(device, &si, nullptr, &s), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkSamplerCreateInfo-addressModeU-01079");
}

// VK_KHR_copy_commands2's vkCmdResolveImage2KHR (and the core resolves): a single-sampled source is reported
// (resolves of multisampled images: tests/e2e/render_pass_resolve_test.cpp).
TEST_F(PromotedMisuseTest, ResolvesOfOneSampleSourcesAreReported) {
  if (!onVkrt()) GTEST_SKIP() << "vkrt's own reports";
  VkImageCreateInfo ci{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  ci.imageType = VK_IMAGE_TYPE_2D;
  ci.format = VK_FORMAT_R8G8B8A8_UNORM;
  ci.extent = {4, 4, 1};
  ci.mipLevels = ci.arrayLayers = 1;
  ci.samples = VK_SAMPLE_COUNT_1_BIT;
  ci.tiling = VK_IMAGE_TILING_OPTIMAL;
  ci.usage = VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  VkImage src = VK_NULL_HANDLE, dst = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateImage(device, &ci, nullptr, &src), VK_SUCCESS);
  ASSERT_EQ(vkCreateImage(device, &ci, nullptr, &dst), VK_SUCCESS);
  VkDeviceMemory mem[2];
  for (int i = 0; i < 2; ++i) {
    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(device, i ? dst : src, &req);
    VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    mai.allocationSize = req.size;
    mai.memoryTypeIndex = memoryTypeIndex(req.memoryTypeBits, 0);
    ASSERT_EQ(vkAllocateMemory(device, &mai, nullptr, &mem[i]), VK_SUCCESS);
    ASSERT_EQ(vkBindImageMemory(device, i ? dst : src, mem[i], 0), VK_SUCCESS);
  }
  VkImageResolve region{{VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1}, {}, {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1}, {}, {4, 4, 1}};
  VkCommandBuffer cb = beginOneTime();
  vkCmdResolveImage(cb, src, VK_IMAGE_LAYOUT_GENERAL, dst, VK_IMAGE_LAYOUT_GENERAL, 1, &region);
  expectVkrtMessage("VUID-vkCmdResolveImage-srcImage-00257");
  VkImageResolve2 region2{VK_STRUCTURE_TYPE_IMAGE_RESOLVE_2};
  region2.srcSubresource = region2.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region2.extent = {4, 4, 1};
  VkResolveImageInfo2 info{VK_STRUCTURE_TYPE_RESOLVE_IMAGE_INFO_2};
  info.srcImage = src;
  info.srcImageLayout = info.dstImageLayout = VK_IMAGE_LAYOUT_GENERAL;
  info.dstImage = dst;
  info.regionCount = 1;
  info.pRegions = &region2;
  vkCmdResolveImage2(cb, &info);
  expectVkrtMessage("VUID-VkResolveImageInfo2-srcImage-00257");
  submitAndWait(cb);
  vkDestroyImage(device, src, nullptr);
  vkDestroyImage(device, dst, nullptr);
  for (VkDeviceMemory m : mem) vkFreeMemory(device, m, nullptr);
}

TEST_F(PromotedMisuseTest, PrivateDataRules) {
  if (!onVkrt()) GTEST_SKIP() << "vkrt's own reports";
  // Without the privateData feature (this fixture does not enable it), no slot.
  VkPrivateDataSlotCreateInfo ci{VK_STRUCTURE_TYPE_PRIVATE_DATA_SLOT_CREATE_INFO};
  VkPrivateDataSlot slot = VK_NULL_HANDLE;
  EXPECT_EQ(vkCreatePrivateDataSlot(device, &ci, nullptr, &slot), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-vkCreatePrivateDataSlot-privateData-04564");
}

class PrivateDataMisuseTest : public PrivateDataTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o = PrivateDataTest::options();
    o.validation = false;
    return o;
  }
};

TEST_F(PrivateDataMisuseTest, ObjectsMustBeLiveAndTheDevices) {
  if (!onVkrt()) GTEST_SKIP() << "vkrt's own reports";
  VkPrivateDataSlotCreateInfo ci{VK_STRUCTURE_TYPE_PRIVATE_DATA_SLOT_CREATE_INFO};
  VkPrivateDataSlot slot = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreatePrivateDataSlot(device, &ci, nullptr, &slot), VK_SUCCESS);
  HostBuffer buf = createHostBuffer(64, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  const uint64_t stale = uint64_t(buf.buffer);
  destroy(buf);
  EXPECT_EQ(vkSetPrivateData(device, VK_OBJECT_TYPE_BUFFER, stale, slot, 1), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-vkSetPrivateData-objectHandle-04017");
  // The right handle with the wrong type is not a live object of that type either.
  EXPECT_EQ(vkSetPrivateData(device, VK_OBJECT_TYPE_IMAGE, uint64_t(slot), slot, 1), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-vkSetPrivateData-objectHandle-04017");
  // A buffer of another device is not a child of this one.
  float priority = 1;
  VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  qci.queueCount = 1;
  qci.pQueuePriorities = &priority;
  VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qci;
  VkDevice other = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateDevice(physicalDevice, &dci, nullptr, &other), VK_SUCCESS);
  VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bci.size = 64;
  bci.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  VkBuffer foreign = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateBuffer(other, &bci, nullptr, &foreign), VK_SUCCESS);
  EXPECT_EQ(vkSetPrivateData(device, VK_OBJECT_TYPE_BUFFER, uint64_t(foreign), slot, 1),
            VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-vkSetPrivateData-objectHandle-04016");
  uint64_t v = 9;
  vkGetPrivateData(device, VK_OBJECT_TYPE_BUFFER, uint64_t(foreign), slot, &v);
  EXPECT_EQ(v, 0u);
  expectVkrtMessage("VUID-vkGetPrivateData-objectType-04018");
  vkDestroyBuffer(other, foreign, nullptr);
  vkDestroyDevice(other, nullptr);
  vkDestroyPrivateDataSlot(device, slot, nullptr);
}

TEST_F(PromotedMisuseTest, ImageFormatListRules) {
  if (!onVkrt()) GTEST_SKIP() << "vkrt's own reports";
  VkFormat formats[2] = {VK_FORMAT_R32_UINT, VK_FORMAT_R32_SFLOAT};
  VkImageFormatListCreateInfo list{VK_STRUCTURE_TYPE_IMAGE_FORMAT_LIST_CREATE_INFO};
  list.viewFormatCount = 2;
  list.pViewFormats = formats;
  VkImageCreateInfo ci{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO, &list};
  ci.imageType = VK_IMAGE_TYPE_2D;
  ci.format = VK_FORMAT_R32_UINT;
  ci.extent = {4, 4, 1};
  ci.mipLevels = ci.arrayLayers = 1;
  ci.samples = VK_SAMPLE_COUNT_1_BIT;
  ci.tiling = VK_IMAGE_TILING_OPTIMAL;
  ci.usage = VK_IMAGE_USAGE_SAMPLED_BIT;
  VkImage image = VK_NULL_HANDLE;
  // Two formats without MUTABLE_FORMAT.
  EXPECT_EQ(vkCreateImage(device, &ci, nullptr, &image), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkImageCreateInfo-flags-04738");
  // A format of another size than the image's.
  ci.flags = VK_IMAGE_CREATE_MUTABLE_FORMAT_BIT;
  formats[1] = VK_FORMAT_R16_SFLOAT;
  EXPECT_EQ(vkCreateImage(device, &ci, nullptr, &image), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkImageCreateInfo-pNext-06722");
  // A view of a compatible format that is not in the list.
  formats[1] = VK_FORMAT_R32_SFLOAT;
  ASSERT_EQ(vkCreateImage(device, &ci, nullptr, &image), VK_SUCCESS);
  VkMemoryRequirements req;
  vkGetImageMemoryRequirements(device, image, &req);
  VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  mai.allocationSize = req.size;
  mai.memoryTypeIndex = memoryTypeIndex(req.memoryTypeBits, 0);
  VkDeviceMemory memory = VK_NULL_HANDLE;
  ASSERT_EQ(vkAllocateMemory(device, &mai, nullptr, &memory), VK_SUCCESS);
  ASSERT_EQ(vkBindImageMemory(device, image, memory, 0), VK_SUCCESS);
  VkImageViewCreateInfo vi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
  vi.image = image;
  vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
  vi.format = VK_FORMAT_R8G8B8A8_UNORM;  // 4 bytes a texel, as R32_UINT
  vi.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  VkImageView view = VK_NULL_HANDLE;
  EXPECT_EQ(vkCreateImageView(device, &vi, nullptr, &view), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkImageViewCreateInfo-pNext-01585");
  vi.format = VK_FORMAT_R32_SFLOAT;
  EXPECT_EQ(vkCreateImageView(device, &vi, nullptr, &view), VK_SUCCESS);
  vkDestroyImageView(device, view, nullptr);
  vkDestroyImage(device, image, nullptr);
  vkFreeMemory(device, memory, nullptr);
}

// ---- the audit: every extension the registry says was promoted to Vulkan 1.1, 1.2 or 1.3

enum Kind { kDevice, kInstance };
struct Promoted {
  const char* name;
  uint32_t minor;  // promoted to Vulkan 1.<minor>
  Kind kind;
  bool listed;      // vkrt lists it
  const char* why;  // listed: where it is tested or what it is; absent: the reason
};

// Listed only where vkrt supports everything the extension adds (commands, structures, the features the
// specification makes mandatory with it, SPIR-V): an application that enables it by name gets what it asks for.
const Promoted kPromoted[] = {
    {"VK_KHR_sampler_mirror_clamp_to_edge", 2, kDevice, true,
     "samplerMirrorClampToEdge; PromotedQueriesTest, ComputeImageTest"},
    {"VK_KHR_dynamic_rendering", 3, kDevice, true,
     "vkCmdBeginRendering; ResolveTest.DynamicRendering*, DrawBasicTest, MultiviewTest.DynamicRenderingTwoViews"},
    {"VK_KHR_multiview", 1, kDevice, true, "multiview render passes; MultiviewTest"},
    {"VK_KHR_get_physical_device_properties2", 1, kInstance, true, "instance"},
    {"VK_KHR_device_group", 1, kDevice, true, "a group of one device; swapchain_test.cpp"},
    {"VK_KHR_shader_draw_parameters", 1, kDevice, true,
     "BaseVertex, BaseInstance, DrawIndex; shaderDrawParameters; DrawParametersTest"},
    {"VK_EXT_texture_compression_astc_hdr", 3, kDevice, false,
     "no ASTC formats; textureCompressionASTC_HDR is mandatory with it"},
    {"VK_KHR_maintenance1", 1, kDevice, true, "core 1.1"},
    {"VK_KHR_device_group_creation", 1, kInstance, true, "instance"},
    {"VK_KHR_external_memory_capabilities", 1, kInstance, true, "instance"},
    {"VK_KHR_external_memory", 1, kDevice, true, "no handle types; PromotedQueriesTest"},
    {"VK_KHR_external_semaphore_capabilities", 1, kInstance, true, "instance"},
    {"VK_KHR_external_semaphore", 1, kDevice, true, "no handle types; PromotedQueriesTest"},
    {"VK_KHR_shader_float16_int8", 2, kDevice, true, "Vulkan10StorageTest"},
    {"VK_KHR_16bit_storage", 1, kDevice, true, "Vulkan10StorageTest"},
    {"VK_KHR_descriptor_update_template", 1, kDevice, true, "descriptor_test.cpp"},
    {"VK_KHR_imageless_framebuffer", 2, kDevice, true, "imageless framebuffers; RenderPassTest"},
    {"VK_KHR_create_renderpass2", 2, kDevice, true, "vkCreateRenderPass2; RenderPassTest, ResolveTest"},
    {"VK_KHR_external_fence_capabilities", 1, kInstance, true, "instance"},
    {"VK_KHR_external_fence", 1, kDevice, true, "no handle types; PromotedQueriesTest"},
    {"VK_KHR_maintenance2", 1, kDevice, true,
     "point clipping ALL_CLIP_PLANES, input attachment aspects, view usage, read-only depth/stencil layouts "
     "(Maintenance2Test), EXTENDED_USAGE (ImageTest); no tessellation for the domain origin, no compressed formats "
     "for BLOCK_TEXEL_VIEW_COMPATIBLE"},
    {"VK_KHR_variable_pointers", 1, kDevice, false,
     "variable pointers are not compiled; variablePointersStorageBuffer is mandatory with it"},
    {"VK_KHR_dedicated_allocation", 1, kDevice, true, "core 1.1"},
    {"VK_EXT_sampler_filter_minmax", 2, kDevice, false,
     "the samplers have no min/max reduction; samplerFilterMinmax is mandatory with it"},
    {"VK_KHR_storage_buffer_storage_class", 1, kDevice, true, "Vulkan10StorageTest"},
    {"VK_EXT_inline_uniform_block", 3, kDevice, true, "inline uniform blocks; inline_uniform_block_test.cpp"},
    {"VK_KHR_relaxed_block_layout", 1, kDevice, true, "Vulkan10StorageTest"},
    {"VK_KHR_get_memory_requirements2", 1, kDevice, true, "core 1.1"},
    {"VK_KHR_image_format_list", 2, kDevice, true, "PromotedQueriesTest, PromotedMisuseTest"},
    {"VK_KHR_sampler_ycbcr_conversion", 1, kDevice, false,
     "no YCbCr conversions or multi-planar formats; samplerYcbcrConversion is mandatory with it"},
    {"VK_KHR_bind_memory2", 1, kDevice, true, "core 1.1"},
    {"VK_EXT_descriptor_indexing", 2, kDevice, true, "texel_buffer_test.cpp"},
    {"VK_EXT_shader_viewport_index_layer", 2, kDevice, false,
     "Layer and ViewportIndex are no vertex shader outputs (shaderOutputLayer, shaderOutputViewportIndex are mandatory "
     "with it); no multiViewport"},
    {"VK_KHR_maintenance3", 1, kDevice, true, "core 1.1"},
    {"VK_KHR_draw_indirect_count", 2, kDevice, true, "vkCmdDrawIndirectCount; DrawIndirectTest"},
    {"VK_KHR_shader_subgroup_extended_types", 2, kDevice, true, "SubgroupVoteBallotTest"},
    {"VK_KHR_8bit_storage", 2, kDevice, true, "Vulkan10StorageTest"},
    {"VK_KHR_shader_atomic_int64", 2, kDevice, true, "ComputeAtomicInt64Test"},
    {"VK_EXT_pipeline_creation_feedback", 3, kDevice, true, "PromotedQueriesTest"},
    {"VK_KHR_driver_properties", 2, kDevice, true, "PromotedQueriesTest"},
    {"VK_KHR_shader_float_controls", 2, kDevice, true, "compute float controls"},
    {"VK_KHR_depth_stencil_resolve", 2, kDevice, true, "depth/stencil resolve attachments; ResolveTest"},
    {"VK_KHR_timeline_semaphore", 2, kDevice, true, "sync_test.cpp"},
    {"VK_KHR_vulkan_memory_model", 2, kDevice, true, "MemoryModelTest"},
    {"VK_KHR_shader_terminate_invocation", 3, kDevice, true, "DrawTerminationTest"},
    {"VK_EXT_scalar_block_layout", 2, kDevice, true, "ComputeFeaturesTest"},
    {"VK_EXT_subgroup_size_control", 3, kDevice, true, "SubgroupSizeControlTest"},
    {"VK_KHR_spirv_1_4", 2, kDevice, true, "spirv14_test.cpp"},
    {"VK_KHR_separate_depth_stencil_layouts", 2, kDevice, true, "separateDepthStencilLayouts; RenderPassTest"},
    {"VK_EXT_tooling_info", 3, kDevice, true, "no tools; PromotedQueriesTest"},
    {"VK_EXT_separate_stencil_usage", 2, kDevice, true, "the stencil aspect's own usage; stencil_usage_test.cpp"},
    {"VK_KHR_uniform_buffer_standard_layout", 2, kDevice, true, "ComputeStandardLayoutTest"},
    {"VK_KHR_buffer_device_address", 2, kDevice, true, "device addresses"},
    {"VK_EXT_host_query_reset", 2, kDevice, true, "query_test.cpp"},
    {"VK_EXT_extended_dynamic_state", 3, kDevice, true,
     "the 1.3 dynamic state; extendedDynamicState; DrawDynamicStateTest, ExtendedDynamicStateTest"},
    {"VK_EXT_shader_demote_to_helper_invocation", 3, kDevice, true, "DrawTerminationTest"},
    {"VK_KHR_shader_integer_dot_product", 3, kDevice, true, "integer dot products"},
    {"VK_EXT_texel_buffer_alignment", 3, kDevice, true, "TexelBufferAlignmentTest"},
    {"VK_KHR_shader_non_semantic_info", 3, kDevice, true, "shader_debug_test.cpp (debugPrintfEXT)"},
    {"VK_EXT_private_data", 3, kDevice, true, "PrivateDataTest"},
    {"VK_EXT_pipeline_creation_cache_control", 3, kDevice, true, "compute_cache_test.cpp"},
    {"VK_KHR_synchronization2", 3, kDevice, true, "sync_test.cpp"},
    {"VK_KHR_zero_initialize_workgroup_memory", 3, kDevice, true, "ComputeZeroInitTest"},
    {"VK_EXT_ycbcr_2plane_444_formats", 3, kDevice, false, "no YCbCr formats"},
    {"VK_EXT_image_robustness", 3, kDevice, true, "ComputeImageRobustnessTest"},
    {"VK_KHR_copy_commands2", 3, kDevice, true, "commands_test.cpp"},
    {"VK_EXT_4444_formats", 3, kDevice, false,
     "the 4444 formats are not supported; formatA4R4G4B4 is mandatory with it"},
    {"VK_KHR_format_feature_flags2", 3, kDevice, true, "PromotedQueriesTest"},
    {"VK_EXT_extended_dynamic_state2", 3, kDevice, true,
     "the 1.3 dynamic state and the logic op; extendedDynamicState2(LogicOp), not PatchControlPoints (no "
     "tessellation); ExtendedDynamicState2Test"},
    {"VK_KHR_maintenance4", 3, kDevice, true, "core 1.3"},
};

// What vk.xml says of an extension.
struct RegistryExtension {
  std::string name, type, promotedTo;
  uint32_t specVersion = 0;
  std::vector<std::string> commands;  // of its unconditional <require> blocks
};

std::map<std::string, std::string> attributes(const std::string& tag) {
  std::map<std::string, std::string> out;
  static const std::regex attr(R"re(([A-Za-z_]+)="([^"]*)")re");
  for (auto it = std::sregex_iterator(tag.begin(), tag.end(), attr); it != std::sregex_iterator(); ++it)
    out[(*it)[1]] = (*it)[2];
  return out;
}

// The extensions of the registry's "vulkan" API promoted to Vulkan 1.1-1.3, by name. Every <extension> tag of
// vk.xml is on one line, and so are the <enum> and <command> tags inside it.
std::map<std::string, RegistryExtension> promotedInRegistry() {
  std::ifstream in(VKRT_REGISTRY);
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string xml = ss.str();
  std::map<std::string, RegistryExtension> out;
  for (size_t at = xml.find("<extension "); at != std::string::npos; at = xml.find("<extension ", at + 1)) {
    const size_t tagEnd = xml.find('>', at);
    auto a = attributes(xml.substr(at, tagEnd - at));
    std::string promoted = a["promotedto"];
    if (promoted != "VK_VERSION_1_1" && promoted != "VK_VERSION_1_2" && promoted != "VK_VERSION_1_3") continue;
    std::string supported = "," + a["supported"] + ",";
    if (supported.find(",vulkan,") == std::string::npos) continue;
    RegistryExtension e{a["name"], a["type"], promoted};
    const size_t end = xml[tagEnd - 1] == '/' ? tagEnd : xml.find("</extension>", tagEnd);
    const std::string body = xml.substr(tagEnd, end - tagEnd);
    bool conditional = false;
    for (size_t t = body.find('<'); t != std::string::npos; t = body.find('<', t + 1)) {
      const std::string tag = body.substr(t, body.find('>', t) - t);
      auto ta = attributes(tag);
      if (tag.rfind("<require", 0) == 0) {
        conditional = ta.count("extension") || ta.count("feature") || ta.count("depends");
      } else if (tag.rfind("<enum ", 0) == 0 && ta.count("value") && ta["name"].size() > 13 &&
                 ta["name"].compare(ta["name"].size() - 13, 13, "_SPEC_VERSION") == 0) {
        e.specVersion = uint32_t(std::stoul(ta["value"]));
      } else if (tag.rfind("<command ", 0) == 0 && !conditional) {
        e.commands.push_back(ta["name"]);
      }
    }
    out[e.name] = e;
  }
  return out;
}

// Each command of the registry and the type of its first parameter (an alias: its command's), which tells device
// commands (VkDevice, VkQueue, VkCommandBuffer) from instance and physical-device ones.
std::map<std::string, std::string> commandDispatchTypes() {
  std::ifstream in(VKRT_REGISTRY);
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string xml = ss.str();
  std::map<std::string, std::string> first, alias;
  const size_t from = xml.find("<commands"), to = xml.find("</commands>");
  for (size_t at = xml.find("<command", from + 9); at < to; at = xml.find("<command", at + 1)) {
    if (xml.compare(at, 9, "<commands") == 0) continue;
    const size_t tagEnd = xml.find('>', at);
    auto a = attributes(xml.substr(at, tagEnd - at));
    if (a.count("alias")) {
      alias[a["name"]] = a["alias"];
      continue;
    }
    const size_t name = xml.find("<name>", at), param = xml.find("<param", at), type = xml.find("<type>", param);
    if (name == std::string::npos || type == std::string::npos) break;
    first[xml.substr(name + 6, xml.find("</name>", name) - name - 6)] =
        xml.substr(type + 6, xml.find("</type>", type) - type - 6);
  }
  for (const auto& [name, target] : alias) first[name] = first[target];
  return first;
}

TEST(PromotedExtensionsAudit, TheTableHasEveryExtensionTheRegistryPromoted) {
  const auto registry = promotedInRegistry();
  EXPECT_GE(registry.size(), 70u) << VKRT_REGISTRY << " (1.3.239 promotes 71 extensions)";
  std::set<std::string> inTable;
  for (const Promoted& p : kPromoted) {
    SCOPED_TRACE(p.name);
    EXPECT_TRUE(inTable.insert(p.name).second) << "twice in the table";
    auto it = registry.find(p.name);
    ASSERT_NE(it, registry.end()) << "not promoted in " << VKRT_REGISTRY;
    EXPECT_EQ(it->second.promotedTo, "VK_VERSION_1_" + std::to_string(p.minor));
    EXPECT_EQ(it->second.type, p.kind == kDevice ? "device" : "instance");
    EXPECT_GT(std::strlen(p.why), 0u) << "every row says why";
    if (!p.listed) {
      EXPECT_GT(it->second.specVersion, 0u);
    }
  }
  for (const auto& [name, e] : registry)
    EXPECT_TRUE(inTable.count(name)) << name << " is promoted but not in the table";
}

class PromotedAuditTest : public VulkanTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o;
    o.features12.samplerMirrorClampToEdge = VK_TRUE;
    return o;
  }
  static std::map<std::string, uint32_t> names(const std::vector<VkExtensionProperties>& v) {
    std::map<std::string, uint32_t> out;
    for (const VkExtensionProperties& e : v) out[e.extensionName] = e.specVersion;
    return out;
  }
  std::map<std::string, uint32_t> deviceExtensions() {
    uint32_t n = 0;
    vkEnumerateDeviceExtensionProperties(physicalDevice, nullptr, &n, nullptr);
    std::vector<VkExtensionProperties> v(n);
    vkEnumerateDeviceExtensionProperties(physicalDevice, nullptr, &n, v.data());
    return names(v);
  }
  static std::map<std::string, uint32_t> instanceExtensions() {
    uint32_t n = 0;
    vkEnumerateInstanceExtensionProperties(nullptr, &n, nullptr);
    std::vector<VkExtensionProperties> v(n);
    vkEnumerateInstanceExtensionProperties(nullptr, &n, v.data());
    return names(v);
  }
  // The listed device extensions of the table, and the Vulkan 1.2 features that enabling some of them by name
  // requires while VkPhysicalDeviceVulkan12Features is chained (VUID-VkDeviceCreateInfo-ppEnabledExtensionNames-
  // 02832, -02833).
  static std::vector<const char*> listedDeviceExtensions() {
    std::vector<const char*> out;
    for (const Promoted& p : kPromoted)
      if (p.listed && p.kind == kDevice) out.push_back(p.name);
    return out;
  }
};

TEST_F(PromotedAuditTest, EachIsListedOrAbsentAsTheTableSaysWithTheRegistrysVersion) {
  if (!onVkrt()) GTEST_SKIP() << "vkrt's own list";
  const auto registry = promotedInRegistry();
  const auto device = deviceExtensions(), instance = instanceExtensions();
  int listed = 0;
  for (const Promoted& p : kPromoted) {
    SCOPED_TRACE(p.name);
    const auto& have = p.kind == kDevice ? device : instance;
    auto it = have.find(p.name);
    EXPECT_EQ(it != have.end(), p.listed) << (p.listed ? "the table says listed" : p.why);
    if (it != have.end() && registry.count(p.name)) {
      EXPECT_EQ(it->second, registry.at(p.name).specVersion) << "the spec version of the registry vkrt is built from";
    }
    listed += p.listed;
  }
  EXPECT_GE(listed, 40);
}

// Every listed device extension enabled by name on one device, as an application written for Vulkan 1.0-1.2
// would, with the validation layer on: the device is created and the layer says nothing; and, through an instance
// without the layer, every device command of each extension (its KHR/EXT name) resolves.
TEST_F(PromotedAuditTest, EveryListedOneEnabledByNameAtOnceAndItsCommandsResolve) {
  if (!onVkrt()) GTEST_SKIP() << "vkrt's own list";
  const std::vector<const char*> names = listedDeviceExtensions();
  float priority = 1;
  VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  qci.queueCount = 1;
  qci.pQueuePriorities = &priority;
  VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  f12.samplerMirrorClampToEdge = f12.descriptorIndexing = f12.drawIndirectCount = VK_TRUE;
  VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, &f12};
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qci;
  dci.enabledExtensionCount = uint32_t(names.size());
  dci.ppEnabledExtensionNames = names.data();
  VkDevice all = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateDevice(physicalDevice, &dci, nullptr, &all), VK_SUCCESS);
  vkDestroyDevice(all, nullptr);

  // The commands, through the loader and vkrt alone (the layer answers for commands it knows itself).
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.apiVersion = VK_API_VERSION_1_3;
  VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  ici.pApplicationInfo = &app;
  VkInstance bare = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateInstance(&ici, nullptr, &bare), VK_SUCCESS);
  uint32_t n = 1;
  VkPhysicalDevice pd = VK_NULL_HANDLE;
  VkResult r = vkEnumeratePhysicalDevices(bare, &n, &pd);
  ASSERT_TRUE((r == VK_SUCCESS || r == VK_INCOMPLETE) && n == 1);
  ASSERT_EQ(vkCreateDevice(pd, &dci, nullptr, &all), VK_SUCCESS);
  const auto registry = promotedInRegistry();
  const auto dispatch = commandDispatchTypes();
  int resolved = 0;
  for (const char* name : names) {
    for (const std::string& command : registry.at(name).commands) {
      const std::string& type = dispatch.at(command);
      if (type != "VkDevice" && type != "VkQueue" && type != "VkCommandBuffer") continue;  // not the device's
      EXPECT_NE(vkGetDeviceProcAddr(all, command.c_str()), nullptr) << name << ": " << command;
      ++resolved;
    }
  }
  EXPECT_GE(resolved, 20) << "copy_commands2, synchronization2, timeline_semaphore, ... have device commands";
  vkDestroyDevice(all, nullptr);
  vkDestroyInstance(bare, nullptr);
}

}  // namespace
}  // namespace vkrt::test
