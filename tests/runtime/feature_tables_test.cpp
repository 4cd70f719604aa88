// The feature and property tables generated from vk.xml (tools/gen_features.py) as the physical device uses them:
// every structure of Vulkan 1.1-1.3 (core or promoted) is written, promoted structures agree with the core ones,
// and device creation names the first unsupported feature of any structure.
#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "runtime/alloc.hpp"
#include "runtime/instance.hpp"
#include "runtime/physical_device.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {
namespace {

class FeatureTables : public ::testing::Test {
 protected:
  void SetUp() override {
    VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    ASSERT_EQ(vkrt_CreateInstance(&ici, nullptr, &instance), VK_SUCCESS);
    uint32_t n = 1;
    VkPhysicalDevice h;
    ASSERT_EQ(vkrt_EnumeratePhysicalDevices(instance, &n, &h), VK_SUCCESS);
    pd = fromHandle<PhysicalDevice>(h);
  }
  void TearDown() override { vkrt_DestroyInstance(instance, nullptr); }
  // A structure of `size` bytes filled with 0xCD, with its sType.
  static std::vector<uint64_t> filled(VkStructureType sType, size_t size) {
    std::vector<uint64_t> v((size + 7) / 8);
    std::memset(v.data(), 0xCD, size);
    auto* h = reinterpret_cast<VkBaseOutStructure*>(v.data());
    h->sType = sType;
    h->pNext = nullptr;
    return v;
  }
  VkInstance instance = VK_NULL_HANDLE;
  PhysicalDevice* pd = nullptr;
};

TEST_F(FeatureTables, EveryCoreAndPromotedPropertyStructureIsWritten) {
  int checked = 0;
  for (size_t i = 0; i < kPropertyStructCount; ++i) {
    const PropertyStruct& ps = kPropertyStructs[i];
    if (ps.version < 11) continue;  // extension-only structures: filled only when vkrt has the extension
    SCOPED_TRACE(ps.name);
    std::vector<uint64_t> s = filled(ps.sType, ps.size);
    VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, s.data()};
    pd->fillProperties(&p2);
    auto* bytes = reinterpret_cast<const uint8_t*>(s.data());
    EXPECT_EQ(reinterpret_cast<VkBaseOutStructure*>(s.data())->sType, ps.sType);
    EXPECT_EQ(reinterpret_cast<VkBaseOutStructure*>(s.data())->pNext, nullptr);
    if (ps.count) {
      for (uint32_t k = 0; k < ps.count; ++k) {
        bool pattern = true;
        for (uint32_t b = 0; b < ps.copies[k].size; ++b) pattern &= bytes[ps.copies[k].offset + b] == 0xCD;
        EXPECT_FALSE(pattern) << "member at offset " << ps.copies[k].offset << " was not written";
      }
    } else {
      // A Vulkan 1.x properties structure: a copy of the device's.
      const void* ours = ps.sType == VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_PROPERTIES
                             ? static_cast<const void*>(&pd->properties11)
                         : ps.sType == VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_PROPERTIES
                             ? static_cast<const void*>(&pd->properties12)
                             : static_cast<const void*>(&pd->properties13);
      EXPECT_EQ(std::memcmp(bytes + 16, static_cast<const uint8_t*>(ours) + 16, ps.size - 16), 0);
    }
    ++checked;
  }
  EXPECT_GE(checked, 20) << "Vulkan 1.3 has over 20 property structures";
}

TEST_F(FeatureTables, PromotedPropertiesAgreeWithTheCoreStructures) {
  VkPhysicalDeviceSubgroupProperties sub{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES};
  VkPhysicalDeviceFloatControlsProperties fc{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FLOAT_CONTROLS_PROPERTIES, &sub};
  std::memset(&fc.denormBehaviorIndependence, 0xCD,
              sizeof fc - offsetof(VkPhysicalDeviceFloatControlsProperties, denormBehaviorIndependence));
  VkPhysicalDeviceMaintenance4Properties m4{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MAINTENANCE_4_PROPERTIES, &fc};
  VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &m4};
  pd->fillProperties(&p2);
  EXPECT_EQ(sub.supportedStages, pd->properties11.subgroupSupportedStages) << "renamed member";
  EXPECT_EQ(sub.subgroupSize, pd->properties11.subgroupSize);
  EXPECT_EQ(fc.denormBehaviorIndependence, pd->properties12.denormBehaviorIndependence);
  EXPECT_EQ(fc.shaderSignedZeroInfNanPreserveFloat64, pd->properties12.shaderSignedZeroInfNanPreserveFloat64);
  EXPECT_EQ(m4.maxBufferSize, pd->properties13.maxBufferSize);
  EXPECT_EQ(m4.pNext, &fc) << "the chain is kept";
  EXPECT_EQ(fc.pNext, &sub);
}

TEST_F(FeatureTables, EveryFeatureStructureReportsWhatIsSupported) {
  int checked = 0;
  for (size_t i = 1; i < kFeatureStructCount; ++i) {
    const FeatureStruct& fs = kFeatureStructs[i];
    const bool exists = !fs.extension || fs.version >= 10 || pd->supportsExtension(fs.extension);
    SCOPED_TRACE(fs.name);
    std::vector<uint64_t> s = filled(fs.sType, fs.size);
    VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, s.data()};
    pd->fillFeatures(&f2);
    for (uint32_t k = 0; k < fs.count; ++k) {
      VkBool32 v;
      std::memcpy(&v, reinterpret_cast<const uint8_t*>(s.data()) + fs.members[k].offset, sizeof v);
      if (!exists) {
        EXPECT_EQ(v, 0xCDCDCDCDu) << fs.members[k].name << ": a structure of an extension vkrt lacks is left alone";
        continue;
      }
      EXPECT_EQ(v, pd->supported[size_t(fs.members[k].feature)] ? VK_TRUE : VK_FALSE) << fs.members[k].name;
    }
    checked += exists;
  }
  EXPECT_GE(checked, 40);
  // The ray tracing extensions' own structures exist and report their features.
  VkPhysicalDeviceRayTracingPipelineFeaturesKHR rt{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_FEATURES_KHR};
  VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &rt};
  pd->fillFeatures(&f2);
  EXPECT_TRUE(rt.rayTracingPipeline && rt.rayTracingPipelineShaderGroupHandleCaptureReplayMixed);
}

// The specification's "Feature Requirements" (chapter Features): a device that lists one of these extensions
// supports the features named with it. `any`: one of them is enough (VK_KHR_shader_float16_int8).
struct ExtensionRequirement {
  const char* extension;
  std::vector<Feature> features;
  bool any = false;
};

const std::vector<Feature> kDescriptorIndexing = {
    Feature::shaderSampledImageArrayDynamicIndexing,
    Feature::shaderStorageBufferArrayDynamicIndexing,
    Feature::shaderUniformTexelBufferArrayDynamicIndexing,
    Feature::shaderStorageTexelBufferArrayDynamicIndexing,
    Feature::shaderSampledImageArrayNonUniformIndexing,
    Feature::shaderStorageBufferArrayNonUniformIndexing,
    Feature::shaderUniformTexelBufferArrayNonUniformIndexing,
    Feature::descriptorBindingSampledImageUpdateAfterBind,
    Feature::descriptorBindingStorageImageUpdateAfterBind,
    Feature::descriptorBindingStorageBufferUpdateAfterBind,
    Feature::descriptorBindingUniformTexelBufferUpdateAfterBind,
    Feature::descriptorBindingStorageTexelBufferUpdateAfterBind,
    Feature::descriptorBindingUpdateUnusedWhilePending,
    Feature::descriptorBindingPartiallyBound,
    Feature::runtimeDescriptorArray,
};

std::vector<Feature> with(std::vector<Feature> a, std::initializer_list<Feature> b) {
  a.insert(a.end(), b);
  return a;
}

const ExtensionRequirement kRequirements[] = {
    {VK_EXT_DESCRIPTOR_INDEXING_EXTENSION_NAME, with(kDescriptorIndexing, {Feature::descriptorIndexing})},
    {VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME,
     with(kDescriptorIndexing,
          {Feature::accelerationStructure, Feature::descriptorBindingAccelerationStructureUpdateAfterBind,
           Feature::bufferDeviceAddress})},
    {VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME,
     {Feature::rayTracingPipeline, Feature::rayTracingPipelineTraceRaysIndirect}},
    {VK_KHR_RAY_QUERY_EXTENSION_NAME, {Feature::rayQuery}},
    {VK_KHR_16BIT_STORAGE_EXTENSION_NAME, {Feature::storageBuffer16BitAccess}},
    {VK_KHR_8BIT_STORAGE_EXTENSION_NAME, {Feature::storageBuffer8BitAccess}},
    {VK_KHR_SHADER_FLOAT16_INT8_EXTENSION_NAME, {Feature::shaderFloat16, Feature::shaderInt8}, true},
    {VK_EXT_SCALAR_BLOCK_LAYOUT_EXTENSION_NAME, {Feature::scalarBlockLayout}},
    {VK_KHR_UNIFORM_BUFFER_STANDARD_LAYOUT_EXTENSION_NAME, {Feature::uniformBufferStandardLayout}},
    {VK_KHR_SAMPLER_MIRROR_CLAMP_TO_EDGE_EXTENSION_NAME, {Feature::samplerMirrorClampToEdge}},
    {VK_KHR_TIMELINE_SEMAPHORE_EXTENSION_NAME, {Feature::timelineSemaphore}},
    {VK_EXT_HOST_QUERY_RESET_EXTENSION_NAME, {Feature::hostQueryReset}},
    {VK_KHR_BUFFER_DEVICE_ADDRESS_EXTENSION_NAME, {Feature::bufferDeviceAddress}},
    {VK_KHR_SYNCHRONIZATION_2_EXTENSION_NAME, {Feature::synchronization2}},
    {VK_EXT_PIPELINE_CREATION_CACHE_CONTROL_EXTENSION_NAME, {Feature::pipelineCreationCacheControl}},
    {VK_KHR_ZERO_INITIALIZE_WORKGROUP_MEMORY_EXTENSION_NAME, {Feature::shaderZeroInitializeWorkgroupMemory}},
    {VK_KHR_WORKGROUP_MEMORY_EXPLICIT_LAYOUT_EXTENSION_NAME, {Feature::workgroupMemoryExplicitLayout}},
    {VK_KHR_SHADER_INTEGER_DOT_PRODUCT_EXTENSION_NAME, {Feature::shaderIntegerDotProduct}},
    {VK_KHR_MAINTENANCE_4_EXTENSION_NAME, {Feature::maintenance4}},
    {VK_KHR_SHADER_ATOMIC_INT64_EXTENSION_NAME, {Feature::shaderBufferInt64Atomics, Feature::shaderInt64}},
    {VK_EXT_IMAGE_ROBUSTNESS_EXTENSION_NAME, {Feature::robustImageAccess}},
    {VK_EXT_TEXEL_BUFFER_ALIGNMENT_EXTENSION_NAME, {Feature::texelBufferAlignment}},
    {VK_EXT_PRIVATE_DATA_EXTENSION_NAME, {Feature::privateData}},
    {VK_EXT_SUBGROUP_SIZE_CONTROL_EXTENSION_NAME, {Feature::subgroupSizeControl, Feature::computeFullSubgroups}},
    {VK_EXT_INLINE_UNIFORM_BLOCK_EXTENSION_NAME,
     {Feature::inlineUniformBlock, Feature::descriptorBindingInlineUniformBlockUpdateAfterBind}},
    {VK_KHR_VARIABLE_POINTERS_EXTENSION_NAME, {Feature::variablePointersStorageBuffer}},
    {VK_KHR_SHADER_DRAW_PARAMETERS_EXTENSION_NAME, {Feature::shaderDrawParameters}},
    {VK_KHR_SAMPLER_YCBCR_CONVERSION_EXTENSION_NAME, {Feature::samplerYcbcrConversion}},
    {VK_KHR_VULKAN_MEMORY_MODEL_EXTENSION_NAME, {Feature::vulkanMemoryModel}},
    {VK_KHR_SHADER_TERMINATE_INVOCATION_EXTENSION_NAME, {Feature::shaderTerminateInvocation}},
    {VK_EXT_SHADER_DEMOTE_TO_HELPER_INVOCATION_EXTENSION_NAME, {Feature::shaderDemoteToHelperInvocation}},
    {VK_KHR_SHADER_SUBGROUP_EXTENDED_TYPES_EXTENSION_NAME, {Feature::shaderSubgroupExtendedTypes}},
    {VK_EXT_4444_FORMATS_EXTENSION_NAME, {Feature::formatA4R4G4B4}},
    {VK_EXT_TEXTURE_COMPRESSION_ASTC_HDR_EXTENSION_NAME, {Feature::textureCompressionASTC_HDR}},
    {VK_KHR_DYNAMIC_RENDERING_EXTENSION_NAME, {Feature::dynamicRendering}},
    {VK_KHR_IMAGELESS_FRAMEBUFFER_EXTENSION_NAME, {Feature::imagelessFramebuffer}},
    {VK_KHR_SEPARATE_DEPTH_STENCIL_LAYOUTS_EXTENSION_NAME, {Feature::separateDepthStencilLayouts}},
    {VK_EXT_SAMPLER_FILTER_MINMAX_EXTENSION_NAME, {Feature::samplerFilterMinmax}},
    {VK_KHR_DRAW_INDIRECT_COUNT_EXTENSION_NAME, {Feature::drawIndirectCount}},
    {VK_EXT_SHADER_VIEWPORT_INDEX_LAYER_EXTENSION_NAME,
     {Feature::shaderOutputViewportIndex, Feature::shaderOutputLayer}},
    {VK_EXT_EXTENDED_DYNAMIC_STATE_EXTENSION_NAME, {Feature::extendedDynamicState}},
    {VK_EXT_EXTENDED_DYNAMIC_STATE_2_EXTENSION_NAME, {Feature::extendedDynamicState2}},
};

TEST_F(FeatureTables, ListedExtensionsHaveTheFeaturesTheSpecificationRequires) {
  int listed = 0;
  for (const ExtensionRequirement& r : kRequirements) {
    if (!pd->supportsExtension(r.extension)) continue;
    ++listed;
    SCOPED_TRACE(r.extension);
    int have = 0;
    for (Feature f : r.features) {
      bool on = pd->supported[size_t(f)];
      have += on;
      if (!r.any) {
        EXPECT_TRUE(on) << featureName(f);
      }
    }
    if (r.any) {
      EXPECT_GT(have, 0);
    }
  }
  EXPECT_GE(listed, 15);
  // With VK_KHR_ray_tracing_pipeline, rayTraversalPrimitiveCulling too where rayQuery is supported.
  if (pd->supportsExtension(VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME) && pd->supported[size_t(Feature::rayQuery)]) {
    EXPECT_TRUE(pd->supported[size_t(Feature::rayTraversalPrimitiveCulling)]);
  }
}

TEST_F(FeatureTables, DeviceCreationNamesTheFirstUnsupportedFeatureOfAnyStructure) {
  VkPhysicalDeviceVariablePointersFeatures vp{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VARIABLE_POINTERS_FEATURES};
  vp.variablePointersStorageBuffer = VK_TRUE;  // promoted to Vulkan 1.1, not supported by vkrt
  VkPhysicalDeviceScalarBlockLayoutFeatures scalar{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SCALAR_BLOCK_LAYOUT_FEATURES, &vp};
  scalar.scalarBlockLayout = VK_TRUE;
  VkDeviceCreateInfo ci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, &scalar};
  EXPECT_EQ(pd->firstUnsupportedFeature(ci), "VkPhysicalDeviceVariablePointersFeatures::variablePointersStorageBuffer");
  vp.variablePointersStorageBuffer = VK_FALSE;
  EXPECT_EQ(pd->firstUnsupportedFeature(ci), "");
  // Enabled through the promoted structure, the feature is enabled on the device.
  FeatureSet on = enabledFeatures(ci);
  EXPECT_TRUE(on[size_t(Feature::scalarBlockLayout)]);
  EXPECT_FALSE(on[size_t(Feature::uniformBufferStandardLayout)]);
  VkPhysicalDeviceFeatures legacy{};
  legacy.samplerAnisotropy = VK_TRUE;  // supported
  legacy.geometryShader = VK_TRUE;     // not supported
  VkDeviceCreateInfo ci2{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  ci2.pEnabledFeatures = &legacy;
  EXPECT_EQ(pd->firstUnsupportedFeature(ci2), "VkPhysicalDeviceFeatures::geometryShader");
  legacy.geometryShader = VK_FALSE;
  EXPECT_EQ(pd->firstUnsupportedFeature(ci2), "");
}

}  // namespace
}  // namespace vkrt
