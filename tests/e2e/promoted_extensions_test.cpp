// Extensions promoted to Vulkan 1.1-1.3 that applications written for older versions still enable by name, each
// enabled that way on a device with the validation layer on, and what it adds exercised: SPIR-V 1.0 modules with
// the storage and type extensions, driver and tool properties, VkFormatProperties3, image format lists, pipeline
// creation feedback, NonSemantic instruction sets, external memory / semaphore / fence structures with no handle
// type, and mirror clamp to edge without the feature. (Texel buffers and descriptor indexing:
// texel_buffer_test.cpp; SPIR-V 1.4: spirv14_test.cpp.)
#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

#include "compute_debug_printf.comp.spv.h"
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
    for (uint32_t i = 0; i < buffers.size(); ++i) {
      VkDescriptorBufferInfo bi{buffers[i]->buffer, 0, VK_WHOLE_SIZE};
      VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
      w.dstSet = p.set;
      w.dstBinding = i;
      w.descriptorCount = 1;
      w.descriptorType = kStorageBuffer;
      w.pBufferInfo = &bi;
      vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);
    }
    VkCommandBuffer cb = beginOneTime();
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout, 0, 1, &p.set, 0, nullptr);
    vkCmdDispatch(cb, groups, 1, 1);
    VkMemoryBarrier mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    mb.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
    mb.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &mb, 0, nullptr, 0,
                         nullptr);
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
  if (onVkrt()) EXPECT_STREQ(driver.driverName, "vkrt");
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
    if (onVkrt()) EXPECT_TRUE(t.purposes & VK_TOOL_PURPOSE_VALIDATION_BIT) << t.name;
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
    // The 32 bits VkFormatFeatureFlags has are the same bits in VkFormatFeatureFlags2.
    EXPECT_EQ(uint32_t(p3.linearTilingFeatures), p.linearTilingFeatures);
    EXPECT_EQ(uint32_t(p3.optimalTilingFeatures), p.optimalTilingFeatures);
    EXPECT_EQ(uint32_t(p3.bufferFeatures), p.bufferFeatures);
    if (onVkrt()) {
      // vkrt has no format feature beyond those 32 bits (no read or write without format, no depth comparison).
      EXPECT_EQ(p3.optimalTilingFeatures >> 32, 0u);
      EXPECT_EQ(p3.bufferFeatures >> 32, 0u);
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

// glslc puts debugPrintfEXT in the NonSemantic.DebugPrintf instruction set (with SPV_KHR_non_semantic_info):
// without a tool that consumes it, the shader runs as if the calls were not there.
TEST_F(PromotedQueriesTest, NonSemanticInstructionsAreIgnored) {
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

}  // namespace
}  // namespace vkrt::test
