// VkDevice: the logical device, its enabled extensions and features, and its queues.
#pragma once

#include <atomic>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include "exec/ray_tree.hpp"
#include "exec/supervise.hpp"
#include "runtime/object.hpp"
#include "runtime/supported_features.hpp"

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
  // Graphics pipelines compile colour attachment 0's writes into the fragment shader where they can
  // (abi::ColorMerge); VKRT_COLOR_MERGE=0 at creation turns it off.
  bool colorMerge = true;

  // The features enabled at creation (pEnabledFeatures and every feature structure of the create info's chain,
  // through the tables generated from vk.xml).
  FeatureSet features;
  bool enabled(Feature f) const { return features[size_t(f)]; }
  bool extensionEnabled(const char* name) const { return enabledExtensions.count(name) != 0; }

  // Live acceleration structures by device address (runtime/acceleration_structure.cpp): the most recently
  // created or built one at each address.
  std::mutex accelerationStructuresMutex;
  std::map<uint64_t, AccelerationStructure*> accelerationStructures;
  // The entries of accelerationStructures whose structure is not of bottom-level type, kept in step with it (under
  // the same mutex): what a launch's table of top levels is made from, without walking every bottom level.
  std::map<uint64_t, AccelerationStructure*> topLevelStructures;
  // Counts the builds (and copies) of bottom-level contents: a top level built at the current count refers to the
  // current contents of its bottom levels (topLevelAt).
  std::atomic<uint64_t> blasGeneration{0};
  // The device-wide shader-group handle registry (src/rt/group_handles.hpp), created on first use.
  std::shared_ptr<rt::GroupRegistry> groupRegistry;
  std::once_flag groupRegistryOnce;

  // Queues by index within family 0.
  std::vector<Queue*> queues;

  // Destruction while work is pending (vkDestroyBuffer, vkFreeMemory, ... : runtime/lookup.hpp's
  // destroyWhenIdle). While any queue has work submitted and not completed, `obj` is retired (its handle is no
  // longer live) and `destroy` runs once that work has completed, on the queue's worker (a shader may still reach
  // the object through a descriptor or a device address). A pending command buffer that refers to `obj` is
  // reported under `vuid`, naming `fn`, the command buffer and its queue. False (nothing done) when no work is
  // pending: the caller destroys `obj` now.
  bool deferIfPending(Object* obj, std::function<void()> destroy, const char* fn, const char* vuid);
  // Runs the deferred destructions whose work has completed (every one when `all`, at vkDestroyDevice).
  void runDeferred(bool all);

  const VkAllocationCallbacks* allocator = nullptr;

  // Robustness (the specification's "Lost Device"). `lost`: a shader ran past the time limit or faulted; never
  // cleared. From then on command buffers stop at their next command, queue batches still waiting for a semaphore
  // or an event give up, every batch still signals its semaphores and fence, and the submits and waits return
  // VK_ERROR_DEVICE_LOST. `closing`: vkDestroyDevice has begun; work not started is skipped and running shaders
  // are cancelled. Both are set under sync::mutex() and announced on sync::changed().
  std::atomic<bool> lost{false};
  std::atomic<bool> closing{false};
  bool halted() const { return lost.load(std::memory_order_acquire) || closing.load(std::memory_order_acquire); }
  void lose();
  // The watchdog's limit for one dispatch or ray tracing launch (exec/supervise.hpp): VKRT_SHADER_TIMEOUT_MS at
  // device creation (milliseconds; 0 turns the watchdog off), else kDefaultShaderTimeoutMs.
  static constexpr uint32_t kDefaultShaderTimeoutMs = 30000;
  uint32_t shaderTimeoutMs = kDefaultShaderTimeoutMs;
  // After a supervised command `fn` was ended (job.aborted()): reports which shader of `pipeline` faulted or ran
  // too long, and which invocation, and loses the device (nothing when vkDestroyDevice cancelled it).
  void shaderAborted(const Object* pipeline, const char* fn, const exec::Abort& abort);

  // VKRT_RAY_TREE (docs/ray-tree.md), read at device creation: the launch ids and compute global invocation ids
  // whose ray trees are recorded (empty: none, and launches get no recorder), and VKRT_RAY_TREE_OUT, the file they
  // are appended to (empty: INFO messages). `rayTreeSequence` numbers the launches and dispatches that recorded.
  exec::RayTreeSelection rayTree;
  std::string rayTreeOut;
  std::atomic<uint64_t> rayTreeSequence{0};

 private:
  struct Deferred {
    std::function<void()> destroy;
    std::vector<std::pair<Queue*, uint64_t>> waitFor;  // each queue's batch count when it was destroyed
  };
  std::mutex deferredMutex_;  // taken before any queue's mutex
  std::vector<Deferred> deferred_;
};

}  // namespace vkrt
