// VkPhysicalDevice: the one CPU device vkrt exposes, its features, properties and extensions.
#pragma once

#include <string>
#include <vector>

#include "runtime/object.hpp"

namespace vkrt {

class PhysicalDevice : public Object {
 public:
  using Handle = VkPhysicalDevice;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_PHYSICAL_DEVICE;

  explicit PhysicalDevice(Instance* inst);

  // What vkrt supports. Feature structs are kept with sType set and pNext null.
  VkPhysicalDeviceFeatures features10{};
  VkPhysicalDeviceVulkan11Features features11{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES};
  VkPhysicalDeviceVulkan12Features features12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  VkPhysicalDeviceVulkan13Features features13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};

  VkPhysicalDeviceProperties properties10{};
  VkPhysicalDeviceVulkan11Properties properties11{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_PROPERTIES};
  VkPhysicalDeviceVulkan12Properties properties12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_PROPERTIES};
  VkPhysicalDeviceVulkan13Properties properties13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_PROPERTIES};

  VkPhysicalDeviceMemoryProperties memoryProperties{};
  VkQueueFamilyProperties queueFamily{};

  // Device extensions vkrt advertises now (some depend on the environment, see the README).
  const std::vector<VkExtensionProperties>& extensions() const { return extensions_; }
  bool supportsExtension(const char* name) const;

  // Fills every structure vkrt knows in a VkPhysicalDeviceFeatures2/Properties2 chain; unknown ones are left
  // as they are, as the spec requires.
  void fillFeatures(VkPhysicalDeviceFeatures2* out) const;
  void fillProperties(VkPhysicalDeviceProperties2* out) const;

  // Checks that every feature requested in a VkDeviceCreateInfo is supported. Returns the name of the first
  // unsupported feature, or nullptr.
  const char* firstUnsupportedFeature(const VkDeviceCreateInfo& info) const;

 private:
  std::vector<VkExtensionProperties> extensions_;
};

// Number of worker threads vkrt uses (VKRT_THREADS, or the number of cores).
unsigned workerThreadCount();

}  // namespace vkrt
