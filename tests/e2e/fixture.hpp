// The end-to-end test fixture: a Vulkan instance through the real loader (restricted to vkrt by
// VK_DRIVER_FILES, set by CTest), the Khronos validation layer, a debug messenger that records every message,
// and a device with one queue.
//
// Every test ends by asserting that the validation layer said nothing. Tests that break a rule on purpose
// assert vkrt's own message with `expectVkrtMessage(vuid)` and switch the layer off (`kNoValidation`), since
// the layer would report the same misuse.
#pragma once

#include <gtest/gtest.h>
#include <vulkan/vulkan.h>

#include <cstring>
#include <mutex>
#include <string>
#include <vector>

namespace vkrt::test {

struct Message {
  VkDebugUtilsMessageSeverityFlagBitsEXT severity;
  std::string idName;
  std::string text;
};

struct FixtureOptions {
  bool validation = true;
  std::vector<const char*> instanceExtensions;  // besides VK_EXT_debug_utils
  std::vector<const char*> deviceExtensions;
  // Extra feature structures chained into VkDeviceCreateInfo (after a VkPhysicalDeviceFeatures2).
  void* featureChain = nullptr;
  VkPhysicalDeviceFeatures features{};
  uint32_t queueCount = 1;
  bool bufferDeviceAddressCaptureReplay = false;
  // Enables the descriptor binding flag features (update after bind, partially bound, variable count).
  bool descriptorBindingFlags = false;
  // Enables shaderInt8, shaderFloat16 and storageBuffer8BitAccess (VkPhysicalDeviceVulkan12Features).
  bool shaderSmallTypes = false;
  // Enables pipelineCreationCacheControl (FAIL_ON_PIPELINE_COMPILE_REQUIRED / EARLY_RETURN_ON_FAILURE).
  bool pipelineCreationCacheControl = false;
  // Enables shaderZeroInitializeWorkgroupMemory (Workgroup variables with initializers).
  bool zeroInitializeWorkgroupMemory = false;
  // More Vulkan 1.2 features: each VK_TRUE member is also enabled in the fixture's own structure (a second
  // VkPhysicalDeviceVulkan12Features may not be chained).
  VkPhysicalDeviceVulkan12Features features12{};
  // Vulkan 1.3 features alike (besides those the fixture enables itself).
  VkPhysicalDeviceVulkan13Features features13{};
};

class VulkanTest : public ::testing::Test {
 protected:
  virtual FixtureOptions options() { return {}; }

  void SetUp() override;
  void TearDown() override;

  // Messages received so far, by origin.
  std::vector<Message> layerMessages();
  std::vector<Message> vkrtMessages();
  void clearMessages();
  // Asserts that vkrt reported exactly one message naming `vuid` since the last clear, and clears.
  void expectVkrtMessage(const char* vuid);
  // Removes the validation layer's messages named `idName` received so far; returns how many there were.
  size_t takeLayerMessages(const std::string& idName);

  uint32_t memoryTypeIndex(uint32_t typeBits, VkMemoryPropertyFlags props);

  // True when the device under test is vkrt. Assertions about vkrt's own choices (where the spec lets a
  // driver choose) run only there; the e2e tests of Vulkan behaviour also run on NVIDIA's driver.
  bool onVkrt() const {
    VkPhysicalDeviceProperties p;
    vkGetPhysicalDeviceProperties(physicalDevice, &p);
    return std::strcmp(p.deviceName, "vkrt") == 0;
  }

  struct HostBuffer {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    void* data = nullptr;
    VkDeviceSize size = 0;
  };
  HostBuffer createHostBuffer(VkDeviceSize size, VkBufferUsageFlags usage, bool deviceAddress = false);
  void destroy(HostBuffer& b);

  VkCommandBuffer beginOneTime();
  void submitAndWait(VkCommandBuffer cb);

  VkInstance instance = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
  VkPhysicalDevice physicalDevice = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
  VkCommandPool commandPool = VK_NULL_HANDLE;
  bool validationEnabled = false;

 private:
  static VKAPI_ATTR VkBool32 VKAPI_CALL onMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                  VkDebugUtilsMessageTypeFlagsEXT types,
                                                  const VkDebugUtilsMessengerCallbackDataEXT* data, void* user);
  std::mutex mutex_;
  std::vector<Message> messages_;
};

}  // namespace vkrt::test
