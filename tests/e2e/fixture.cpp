#include "e2e/fixture.hpp"

#include <algorithm>
#include <cstddef>

namespace vkrt::test {

VKAPI_ATTR VkBool32 VKAPI_CALL VulkanTest::onMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                     VkDebugUtilsMessageTypeFlagsEXT,
                                                     const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  auto* self = static_cast<VulkanTest*>(user);
  std::lock_guard lock(self->mutex_);
  self->messages_.push_back(
      {severity, data->pMessageIdName ? data->pMessageIdName : "", data->pMessage ? data->pMessage : ""});
  return VK_FALSE;
}

void VulkanTest::SetUp() {
  FixtureOptions opt = options();

  uint32_t layerCount = 0;
  vkEnumerateInstanceLayerProperties(&layerCount, nullptr);
  std::vector<VkLayerProperties> layers(layerCount);
  vkEnumerateInstanceLayerProperties(&layerCount, layers.data());
  std::vector<const char*> enabledLayers;
  if (opt.validation) {
    for (auto& l : layers)
      if (std::strcmp(l.layerName, "VK_LAYER_KHRONOS_validation") == 0) enabledLayers.push_back(l.layerName);
    ASSERT_FALSE(enabledLayers.empty()) << "VK_LAYER_KHRONOS_validation is not installed";
    validationEnabled = true;
  }

  VkDebugUtilsMessengerCreateInfoEXT mci{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  mci.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  // Performance warnings (e.g. GENERAL instead of TRANSFER_DST_OPTIMAL) are advice, not errors: not collected.
  mci.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT;
  mci.pfnUserCallback = &VulkanTest::onMessage;
  mci.pUserData = this;

  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "vkrt-e2e";
  app.apiVersion = VK_API_VERSION_1_3;
  std::vector<const char*> exts = {VK_EXT_DEBUG_UTILS_EXTENSION_NAME};
  exts.insert(exts.end(), opt.instanceExtensions.begin(), opt.instanceExtensions.end());
  VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO, &mci};
  ici.pApplicationInfo = &app;
  ici.enabledLayerCount = static_cast<uint32_t>(enabledLayers.size());
  ici.ppEnabledLayerNames = enabledLayers.data();
  ici.enabledExtensionCount = static_cast<uint32_t>(exts.size());
  ici.ppEnabledExtensionNames = exts.data();
  ASSERT_EQ(vkCreateInstance(&ici, nullptr, &instance), VK_SUCCESS);

  auto createMessenger = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
      vkGetInstanceProcAddr(instance, "vkCreateDebugUtilsMessengerEXT"));
  ASSERT_NE(createMessenger, nullptr);
  ASSERT_EQ(createMessenger(instance, &mci, nullptr, &messenger), VK_SUCCESS);

  uint32_t count = 0;
  ASSERT_EQ(vkEnumeratePhysicalDevices(instance, &count, nullptr), VK_SUCCESS);
  ASSERT_GE(count, 1u);
  std::vector<VkPhysicalDevice> pds(count);
  ASSERT_EQ(vkEnumeratePhysicalDevices(instance, &count, pds.data()), VK_SUCCESS);
  physicalDevice = pds[0];

  float priorities[4] = {1, 1, 1, 1};
  VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  qci.queueFamilyIndex = 0;
  qci.queueCount = opt.queueCount;
  qci.pQueuePriorities = priorities;

  VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES, opt.featureChain};
  f12.timelineSemaphore = VK_TRUE;
  f12.bufferDeviceAddress = VK_TRUE;
  f12.hostQueryReset = VK_TRUE;
  f12.bufferDeviceAddressCaptureReplay = opt.bufferDeviceAddressCaptureReplay;
  f12.shaderInt8 = f12.shaderFloat16 = f12.storageBuffer8BitAccess = opt.shaderSmallTypes;
  if (opt.descriptorBindingFlags) {
    f12.descriptorBindingUniformBufferUpdateAfterBind = VK_TRUE;
    f12.descriptorBindingStorageBufferUpdateAfterBind = VK_TRUE;
    f12.descriptorBindingSampledImageUpdateAfterBind = VK_TRUE;
    f12.descriptorBindingStorageImageUpdateAfterBind = VK_TRUE;
    f12.descriptorBindingUpdateUnusedWhilePending = VK_TRUE;
    f12.descriptorBindingPartiallyBound = VK_TRUE;
    f12.descriptorBindingVariableDescriptorCount = VK_TRUE;
  }
  {
    constexpr size_t first = offsetof(VkPhysicalDeviceVulkan12Features, samplerMirrorClampToEdge);
    constexpr size_t end = offsetof(VkPhysicalDeviceVulkan12Features, subgroupBroadcastDynamicId) + sizeof(VkBool32);
    for (size_t at = first; at < end; at += sizeof(VkBool32)) {
      VkBool32 extra;
      std::memcpy(&extra, reinterpret_cast<const char*>(&opt.features12) + at, sizeof extra);
      if (extra) std::memcpy(reinterpret_cast<char*>(&f12) + at, &extra, sizeof extra);
    }
  }
  VkPhysicalDeviceVulkan13Features f13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES, &f12};
  f13.synchronization2 = VK_TRUE;
  f13.maintenance4 = VK_TRUE;  // glslc's SPIR-V 1.6 compute shaders declare their size with LocalSizeId
  f13.pipelineCreationCacheControl = opt.pipelineCreationCacheControl;
  f13.shaderZeroInitializeWorkgroupMemory = opt.zeroInitializeWorkgroupMemory;
  {
    constexpr size_t first = offsetof(VkPhysicalDeviceVulkan13Features, robustImageAccess);
    constexpr size_t end = offsetof(VkPhysicalDeviceVulkan13Features, maintenance4) + sizeof(VkBool32);
    for (size_t at = first; at < end; at += sizeof(VkBool32)) {
      VkBool32 extra;
      std::memcpy(&extra, reinterpret_cast<const char*>(&opt.features13) + at, sizeof extra);
      if (extra) std::memcpy(reinterpret_cast<char*>(&f13) + at, &extra, sizeof extra);
    }
  }
  VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &f13};
  f2.features = opt.features;

  VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, &f2};
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qci;
  dci.enabledExtensionCount = static_cast<uint32_t>(opt.deviceExtensions.size());
  dci.ppEnabledExtensionNames = opt.deviceExtensions.data();
  ASSERT_EQ(vkCreateDevice(physicalDevice, &dci, nullptr, &device), VK_SUCCESS);
  vkGetDeviceQueue(device, 0, 0, &queue);
  ASSERT_NE(queue, VK_NULL_HANDLE);

  auto createPool = reinterpret_cast<PFN_vkCreateCommandPool>(vkGetDeviceProcAddr(device, "vkCreateCommandPool"));
  if (createPool) {
    VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pci.queueFamilyIndex = 0;
    ASSERT_EQ(createPool(device, &pci, nullptr, &commandPool), VK_SUCCESS);
  }
}

void VulkanTest::TearDown() {
  if (device) {
    vkDeviceWaitIdle(device);
    if (commandPool) vkDestroyCommandPool(device, commandPool, nullptr);
    vkDestroyDevice(device, nullptr);
  }
  if (messenger) {
    auto destroyMessenger = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT"));
    destroyMessenger(instance, messenger, nullptr);
  }
  if (instance) vkDestroyInstance(instance, nullptr);
  for (const Message& m : layerMessages()) ADD_FAILURE() << "validation layer: " << m.text;
  for (const Message& m : vkrtMessages()) ADD_FAILURE() << "unexpected vkrt report: " << m.text;
}

std::vector<Message> VulkanTest::layerMessages() {
  std::lock_guard lock(mutex_);
  std::vector<Message> out;
  for (auto& m : messages_)
    if (m.text.rfind("vkrt: ", 0) != 0) out.push_back(m);
  return out;
}

std::vector<Message> VulkanTest::vkrtMessages() {
  std::lock_guard lock(mutex_);
  std::vector<Message> out;
  for (auto& m : messages_)
    if (m.text.rfind("vkrt: ", 0) == 0) out.push_back(m);
  return out;
}

void VulkanTest::clearMessages() {
  std::lock_guard lock(mutex_);
  messages_.clear();
}

size_t VulkanTest::takeLayerMessages(const std::string& idName) {
  std::lock_guard lock(mutex_);
  auto taken = [&](const Message& m) { return m.text.rfind("vkrt: ", 0) != 0 && m.idName == idName; };
  size_t n = size_t(std::count_if(messages_.begin(), messages_.end(), taken));
  messages_.erase(std::remove_if(messages_.begin(), messages_.end(), taken), messages_.end());
  return n;
}

void VulkanTest::expectVkrtMessage(const char* vuid) {
  auto msgs = vkrtMessages();
  ASSERT_EQ(msgs.size(), 1u) << "expected one vkrt report naming " << vuid;
  EXPECT_EQ(msgs[0].idName, vuid) << msgs[0].text;
  EXPECT_NE(msgs[0].text.find(vuid), std::string::npos) << msgs[0].text;
  clearMessages();
}

uint32_t VulkanTest::memoryTypeIndex(uint32_t typeBits, VkMemoryPropertyFlags props) {
  VkPhysicalDeviceMemoryProperties mp;
  vkGetPhysicalDeviceMemoryProperties(physicalDevice, &mp);
  for (uint32_t i = 0; i < mp.memoryTypeCount; ++i)
    if ((typeBits & (1u << i)) && (mp.memoryTypes[i].propertyFlags & props) == props) return i;
  ADD_FAILURE() << "no memory type with properties " << props;
  return 0;
}

VulkanTest::HostBuffer VulkanTest::createHostBuffer(VkDeviceSize size, VkBufferUsageFlags usage, bool deviceAddress) {
  HostBuffer b;
  b.size = size;
  VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bci.size = size;
  bci.usage = usage | (deviceAddress ? VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT : 0);
  EXPECT_EQ(vkCreateBuffer(device, &bci, nullptr, &b.buffer), VK_SUCCESS);
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(device, b.buffer, &req);
  VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
  flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
  VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, deviceAddress ? &flags : nullptr};
  mai.allocationSize = req.size;
  mai.memoryTypeIndex =
      memoryTypeIndex(req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
  EXPECT_EQ(vkAllocateMemory(device, &mai, nullptr, &b.memory), VK_SUCCESS);
  EXPECT_EQ(vkBindBufferMemory(device, b.buffer, b.memory, 0), VK_SUCCESS);
  EXPECT_EQ(vkMapMemory(device, b.memory, 0, VK_WHOLE_SIZE, 0, &b.data), VK_SUCCESS);
  return b;
}

void VulkanTest::destroy(HostBuffer& b) {
  if (b.buffer) vkDestroyBuffer(device, b.buffer, nullptr);
  if (b.memory) vkFreeMemory(device, b.memory, nullptr);
  b = {};
}

VkCommandBuffer VulkanTest::beginOneTime() {
  VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  ai.commandPool = commandPool;
  ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ai.commandBufferCount = 1;
  VkCommandBuffer cb = VK_NULL_HANDLE;
  EXPECT_EQ(vkAllocateCommandBuffers(device, &ai, &cb), VK_SUCCESS);
  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  EXPECT_EQ(vkBeginCommandBuffer(cb, &bi), VK_SUCCESS);
  return cb;
}

void VulkanTest::submitAndWait(VkCommandBuffer cb) {
  EXPECT_EQ(vkEndCommandBuffer(cb), VK_SUCCESS);
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cb;
  EXPECT_EQ(vkQueueSubmit(queue, 1, &si, VK_NULL_HANDLE), VK_SUCCESS);
  EXPECT_EQ(vkQueueWaitIdle(queue), VK_SUCCESS);
  vkFreeCommandBuffers(device, commandPool, 1, &cb);
}

}  // namespace vkrt::test
