// VkPhysicalDevice: the one CPU device vkrt exposes, its features, properties and extensions.
#pragma once

#include <string>
#include <vector>

#include "runtime/object.hpp"
#include "runtime/supported_features.hpp"

namespace vkrt {

class PhysicalDevice : public Object {
 public:
  using Handle = VkPhysicalDevice;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_PHYSICAL_DEVICE;

  explicit PhysicalDevice(Instance* inst);

  // What vkrt supports (runtime/supported_features.cpp), and VkPhysicalDeviceFeatures of it.
  const FeatureSet& supported = supportedFeatures();
  VkPhysicalDeviceFeatures features10() const;

  VkPhysicalDeviceProperties properties10{};
  VkPhysicalDeviceVulkan11Properties properties11{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_PROPERTIES};
  VkPhysicalDeviceVulkan12Properties properties12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_PROPERTIES};
  VkPhysicalDeviceVulkan13Properties properties13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_PROPERTIES};
  // The properties of the extensions that are not promoted to core (runtime/ray_tracing_features.cpp).
  VkPhysicalDeviceRayTracingPipelinePropertiesKHR rayTracingProperties{};
  VkPhysicalDeviceAccelerationStructurePropertiesKHR accelerationStructureProperties{};
  VkPhysicalDeviceRayTracingPropertiesNV rayTracingPropertiesNV{};

  VkPhysicalDeviceMemoryProperties memoryProperties{};
  // Queue families: 0 does graphics, compute and transfer; kComputeQueueFamily compute and transfer only (what
  // applications and the CTS look for to run compute apart from graphics). Both run on the same queue workers.
  static constexpr uint32_t kQueueFamilyCount = 2;
  static constexpr uint32_t kComputeQueueFamily = 1;
  VkQueueFamilyProperties queueFamilies[kQueueFamilyCount]{};
  static bool familyHasGraphics(uint32_t family) { return family == 0; }

  // Device extensions vkrt advertises: a fixed list (the constructor's and runtime/ray_tracing_features.cpp's).
  const std::vector<VkExtensionProperties>& extensions() const { return extensions_; }
  bool supportsExtension(const char* name) const;

  // Fills every structure of a VkPhysicalDeviceFeatures2/Properties2 chain that the generated tables know and that
  // exists on this device (core, promoted to core, or of an advertised extension); others are left as they are,
  // as the spec requires.
  void fillFeatures(VkPhysicalDeviceFeatures2* out) const;
  void fillProperties(VkPhysicalDeviceProperties2* out) const;

  // Checks that every feature requested in a VkDeviceCreateInfo is supported. Returns "Structure::member" of the
  // first unsupported one, or an empty string.
  std::string firstUnsupportedFeature(const VkDeviceCreateInfo& info) const;

 private:
  bool available(const char* extension, uint32_t version) const;
  void writeFeatures(const FeatureStruct& fs, void* out) const;
  std::vector<VkExtensionProperties> extensions_;
};

// The features a VkDeviceCreateInfo enables (pEnabledFeatures and every feature structure of its chain).
FeatureSet enabledFeatures(const VkDeviceCreateInfo& info);

}  // namespace vkrt
