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

TEST_F(FeatureTables, DeviceCreationNamesTheFirstUnsupportedFeatureOfAnyStructure) {
  VkPhysicalDeviceShaderAtomicInt64Features atomics{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_ATOMIC_INT64_FEATURES};
  atomics.shaderBufferInt64Atomics = VK_TRUE;  // promoted to Vulkan 1.2, not supported by vkrt
  VkPhysicalDeviceScalarBlockLayoutFeatures scalar{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SCALAR_BLOCK_LAYOUT_FEATURES,
                                                   &atomics};
  scalar.scalarBlockLayout = VK_TRUE;
  VkDeviceCreateInfo ci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, &scalar};
  EXPECT_EQ(pd->firstUnsupportedFeature(ci), "VkPhysicalDeviceShaderAtomicInt64Features::shaderBufferInt64Atomics");
  atomics.shaderBufferInt64Atomics = VK_FALSE;
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
