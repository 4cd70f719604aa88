// VkInstance and VkDebugUtilsMessengerEXT.
#pragma once

#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include "runtime/object.hpp"

namespace vkrt {

class PhysicalDevice;

class DebugMessenger : public Object {
 public:
  using Handle = VkDebugUtilsMessengerEXT;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_DEBUG_UTILS_MESSENGER_EXT;
  DebugMessenger(Instance* inst, const VkDebugUtilsMessengerCreateInfoEXT& info);

  VkDebugUtilsMessageSeverityFlagsEXT severities;
  VkDebugUtilsMessageTypeFlagsEXT types;
  PFN_vkDebugUtilsMessengerCallbackEXT callback;
  void* userData;
};

class Instance : public Object {
 public:
  using Handle = VkInstance;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_INSTANCE;

  explicit Instance(const VkInstanceCreateInfo& info);
  ~Instance();

  uint32_t apiVersion;
  std::set<std::string> enabledExtensions;
  PhysicalDevice* physicalDevice = nullptr;

  void addMessenger(DebugMessenger* m);
  void removeMessenger(DebugMessenger* m);
  // Sends one message to the messengers; returns false when none accepted it (so the caller may print it).
  bool dispatch(VkDebugUtilsMessageSeverityFlagBitsEXT severity, VkDebugUtilsMessageTypeFlagsEXT type,
                const VkDebugUtilsMessengerCallbackDataEXT& data) const;
  bool hasMessengers() const;

  // Messengers given in VkInstanceCreateInfo::pNext, used during vkCreateInstance/vkDestroyInstance too.
  std::vector<VkDebugUtilsMessengerCreateInfoEXT> creationMessengers;
  bool inCreateOrDestroy = true;

 private:
  mutable std::mutex messengerMutex_;
  std::vector<DebugMessenger*> messengers_;
};

// The instance extensions vkrt implements.
const std::vector<VkExtensionProperties>& instanceExtensions();

}  // namespace vkrt
