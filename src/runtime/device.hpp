// VkDevice: the logical device, its enabled extensions and features, and its queues.
#pragma once

#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include "runtime/object.hpp"

namespace vkrt {

class AccelerationStructure;
class PhysicalDevice;
class Queue;
namespace rt {
class GroupRegistry;
}

class Device : public Object {
 public:
  using Handle = VkDevice;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_DEVICE;

  Device(PhysicalDevice* physical, const VkDeviceCreateInfo& info);
  ~Device();

  PhysicalDevice* const physicalDevice;
  std::set<std::string> enabledExtensions;

  // Enabled features, gathered from pEnabledFeatures, VkPhysicalDeviceFeatures2 and the Vulkan 1.1/1.2/1.3
  // structures or their extension equivalents in the create info's pNext chain.
  VkPhysicalDeviceFeatures enabled10{};
  VkPhysicalDeviceVulkan11Features enabled11{};
  VkPhysicalDeviceVulkan12Features enabled12{};
  VkPhysicalDeviceVulkan13Features enabled13{};

  bool extensionEnabled(const char* name) const { return enabledExtensions.count(name) != 0; }

  // Ray tracing features (VkPhysicalDeviceRayTracingPipelineFeaturesKHR and
  // VkPhysicalDevicePipelineLibraryGroupHandlesFeaturesEXT), read in the constructor; checked by src/rt.
  struct RayTracingFeatures {
    bool pipeline = false;
    bool captureReplay = false;
    bool captureReplayMixed = false;
    bool traceRaysIndirect = false;
    bool primitiveCulling = false;
    bool libraryGroupHandles = false;
    bool traceRaysIndirect2 = false;  // VkPhysicalDeviceRayTracingMaintenance1FeaturesKHR
  } rayTracing;
  // VkPhysicalDeviceAccelerationStructureFeaturesKHR, read in the constructor.
  struct AccelerationStructureFeatures {
    bool structures = false;
    bool captureReplay = false;
    bool indirectBuild = false;
    bool hostCommands = false;
    bool updateAfterBind = false;
  } accelerationStructure;
  // Live acceleration structures by device address (runtime/acceleration_structure.cpp): the most recently
  // created or built one at each address.
  std::mutex accelerationStructuresMutex;
  std::map<uint64_t, AccelerationStructure*> accelerationStructures;
  // The device-wide shader-group handle registry (src/rt/group_handles.hpp), created on first use.
  std::shared_ptr<rt::GroupRegistry> groupRegistry;
  std::once_flag groupRegistryOnce;

  // Queues by index within family 0.
  std::vector<Queue*> queues;
  const VkAllocationCallbacks* allocator = nullptr;
};

}  // namespace vkrt
