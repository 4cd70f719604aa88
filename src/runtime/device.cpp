#include "runtime/device.hpp"

#include <csignal>
#include <cstdlib>
#include <cstring>
#include <string_view>

#include "accel/accel.hpp"
#include "exec/thread_pool.hpp"
#include "runtime/alloc.hpp"
#include "runtime/buffer.hpp"
#include "runtime/command_buffer.hpp"
#include "runtime/fence.hpp"
#include "runtime/instance.hpp"
#include "runtime/physical_device.hpp"
#include "runtime/queue.hpp"
#include "runtime/report.hpp"
#include "spirv/compiler.hpp"
#include "spirv/shader_debug.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {

namespace {

// VKRT_EMBREE_ISA (Embree's kernels) and VKRT_JIT_CPU (the CPU compiled shaders target): instruction sets below
// the CPU's best, so that a machine with more runs what a machine with less would (docs/testing.md). A value
// that cannot apply is reported and the default is kept.
void applyInstructionSetSettings(PhysicalDevice* physical) {
  std::string error;
  if (const char* isa = std::getenv("VKRT_EMBREE_ISA"); isa && *isa && !accel::setIsa(isa, &error))
    report(physical, Severity::Warning, nullptr, "vkCreateDevice: VKRT_EMBREE_ISA=\"%s\" is not applied: %s", isa,
           error.c_str());
  if (const char* cpu = std::getenv("VKRT_JIT_CPU"); cpu && *cpu && !spirv::setTargetCpu(cpu, &error))
    report(physical, Severity::Warning, nullptr, "vkCreateDevice: VKRT_JIT_CPU=\"%s\" is not applied: %s", cpu,
           error.c_str());
  // VKRT_SPMD=0: compute shaders run one invocation at a time, fragment quads as four fibers (the reference the SPMD
  // code is tested against).
  if (const char* spmd = std::getenv("VKRT_SPMD"); spmd && *spmd) spirv::setSpmd(std::string_view(spmd) != "0");
  // VKRT_SHADER_CHECKS: the device address and image checks compiled into later shaders (docs/shader-debugging.md);
  // unset: none. The table of device addresses comes from the buffers (runtime/buffer.cpp).
  uint32_t checks = 0;
  const char* checksText = std::getenv("VKRT_SHADER_CHECKS");
  if (!spirv::parseShaderChecks(checksText, &checks))
    report(physical, Severity::Warning, nullptr,
           "vkCreateDevice: VKRT_SHADER_CHECKS=\"%s\" is not applied: not a list of bda, image, all", checksText);
  spirv::setShaderChecks(checks);
  exec::setAddressTableSource(&deviceAddressRanges);
  report(physical, Severity::Info, nullptr,
         "vkCreateDevice: Embree's %s kernels; shaders compiled for %s; compute shaders in batches of %u lanes (SPMD; "
         "0: off)",
         accel::isaInUse(), spirv::targetCpu().c_str(), spirv::spmdLanes());
}

}  // namespace

Device::Device(PhysicalDevice* physical, const VkDeviceCreateInfo& info)
    : Object(kType, physical->instance, nullptr), physicalDevice(physical) {
  device = this;
  for (uint32_t i = 0; i < info.enabledExtensionCount; ++i) enabledExtensions.insert(info.ppEnabledExtensionNames[i]);
  features = enabledFeatures(info);
  // Builds run on as many threads as launches and dispatches (VKRT_THREADS).
  accel::setBuildThreads(exec::ThreadPool::instance().workerSlots());
  applyInstructionSetSettings(physical);
  // VKRT_COLOR_MERGE=0: no fragment shader writes its colour attachment itself (the back end writes every quad: the
  // reference the merged writes are tested against).
  if (const char* merge = std::getenv("VKRT_COLOR_MERGE"); merge && *merge) colorMerge = std::string_view(merge) != "0";
  if (const char* env = std::getenv("VKRT_SHADER_TIMEOUT_MS")) {
    char* end = nullptr;
    unsigned long v = std::strtoul(env, &end, 10);
    if (end != env && *end == '\0' && v <= UINT32_MAX) {
      shaderTimeoutMs = uint32_t(v);
    } else {
      report(physical, Severity::Warning, nullptr,
             "vkCreateDevice: VKRT_SHADER_TIMEOUT_MS=\"%s\" is not a number of milliseconds; the default %u ms is "
             "used",
             env, kDefaultShaderTimeoutMs);
    }
  }
  if (const char* env = std::getenv("VKRT_RAY_TREE"); env && *env) {
    std::string error;
    if (exec::parseRayTreeSelection(env, &rayTree, &error)) {
      if (const char* out = std::getenv("VKRT_RAY_TREE_OUT")) rayTreeOut = out;
    } else {
      report(physical, Severity::Warning, nullptr,
             "vkCreateDevice: VKRT_RAY_TREE=\"%s\" is malformed: %s; no ray tree is recorded (the syntax: "
             "\"x,y[,z]\" launch ids and \"compute:x[,y[,z]]\" global invocation ids, separated by ';')",
             env, error.c_str());
      rayTree = {};
    }
  }
}

Device::~Device() = default;

void Device::lose() {
  {
    std::lock_guard lock(sync::mutex());
    if (lost.exchange(true, std::memory_order_acq_rel)) return;
    // Batches blocked on a semaphore or an event that will never come give up (they still signal theirs).
    for (Queue* q : queues) q->abandonWaits();
  }
  sync::notifyAll();
}

void Device::shaderAborted(const Object* pipeline, const char* fn, const exec::Abort& a) {
  if (a.kind == exec::Abort::Cancelled && closing.load(std::memory_order_acquire)) return;  // vkDestroyDevice
  char who[160];
  const char* shader = a.shader ? a.shader : "a shader";
  switch (a.idKind) {
    case exec::Abort::GlobalInvocation:
      std::snprintf(who, sizeof who, "the invocation with GlobalInvocationId (%u, %u, %u)", a.id[0], a.id[1], a.id[2]);
      break;
    case exec::Abort::Workgroup:
      std::snprintf(who, sizeof who, "an invocation of the workgroup with WorkgroupId (%u, %u, %u)", a.id[0], a.id[1],
                    a.id[2]);
      break;
    case exec::Abort::LaunchId:
      std::snprintf(who, sizeof who, "the invocation with LaunchIdKHR (%u, %u, %u)", a.id[0], a.id[1], a.id[2]);
      break;
    default: std::snprintf(who, sizeof who, "an invocation"); break;
  }
  unsigned long long handle = pipeline ? (unsigned long long)pipeline->handleValue() : 0;
  if (a.kind == exec::Abort::Fault) {
    report(pipeline, Severity::Error, nullptr,
           "%s: device lost (VK_ERROR_DEVICE_LOST): %s of pipeline 0x%llx faulted (%s) accessing address 0x%llx (an "
           "address no memory is mapped at, such as a wild buffer device address) in %s; the rest of the work was "
           "skipped",
           fn, shader, handle, a.signal == SIGBUS ? "SIGBUS" : "SIGSEGV", (unsigned long long)a.address, who);
  } else {
    report(pipeline, Severity::Error, nullptr,
           "%s: device lost (VK_ERROR_DEVICE_LOST): %s of pipeline 0x%llx made no progress (no workgroup or tile of "
           "rays completed) for the shader time limit of %u ms (VKRT_SHADER_TIMEOUT_MS); %s was still running; the "
           "rest of the work was cancelled",
           fn, shader, handle, shaderTimeoutMs, who);
  }
  lose();
}

bool Device::deferIfPending(Object* obj, std::function<void()> destroy, const char* fn, const char* vuid) {
  std::lock_guard lock(deferredMutex_);
  Deferred d;
  const CommandBuffer* user = nullptr;
  Queue* userQueue = nullptr;
  for (Queue* q : queues) {
    uint64_t count = 0;
    const CommandBuffer* u = nullptr;
    if (!q->pendingWork(obj, &count, &u)) continue;
    d.waitFor.push_back({q, count});
    if (u && !user) {
      user = u;
      userQueue = q;
    }
  }
  if (d.waitFor.empty()) return false;
  // VUID-vkDestroyBuffer-buffer-00922, VUID-vkFreeMemory-memory-00677, VUID-vkDestroyImage-image-01000,
  // VUID-vkDestroyImageView-imageView-01026, VUID-vkDestroyBufferView-bufferView-00936,
  // VUID-vkDestroySampler-sampler-01082, VUID-vkDestroyPipeline-pipeline-00765,
  // VUID-vkDestroyAccelerationStructureKHR-accelerationStructure-02442,
  // VUID-vkDestroyAccelerationStructureNV-accelerationStructure-03752, VUID-vkFreeDescriptorSets-pDescriptorSets-00309,
  // VUID-vkDestroyDescriptorPool-descriptorPool-00303, VUID-vkResetDescriptorPool-descriptorPool-00313
  if (user)
    report(obj, Severity::Error, vuid,
           "%s: %s 0x%llx is used by command buffer 0x%llx, submitted to queue 0x%llx (family %u, index %u) and not "
           "completed; it is destroyed once that work completes",
           fn, objectTypeName(obj->objectType), (unsigned long long)obj->handleValue(),
           (unsigned long long)user->handleValue(), (unsigned long long)userQueue->handleValue(), userQueue->family,
           userQueue->index);
  obj->retire();
  d.destroy = std::move(destroy);
  deferred_.push_back(std::move(d));
  return true;
}

void Device::runDeferred(bool all) {
  std::vector<std::function<void()>> ready;
  {
    std::lock_guard lock(deferredMutex_);
    for (size_t i = 0; i < deferred_.size();) {
      bool done = all;
      if (!done) {
        done = true;
        for (auto& [q, count] : deferred_[i].waitFor)
          if (q->completedCount() < count) done = false;
      }
      if (done) {
        ready.push_back(std::move(deferred_[i].destroy));
        deferred_.erase(deferred_.begin() + i);
      } else {
        ++i;
      }
    }
  }
  for (auto& f : ready) f();
}

}  // namespace vkrt

using namespace vkrt;

extern "C" {

VKAPI_ATTR VkResult VKAPI_CALL vkrt_CreateDevice(VkPhysicalDevice physicalDevice, const VkDeviceCreateInfo* pCreateInfo,
                                                 const VkAllocationCallbacks* pAllocator, VkDevice* pDevice) {
  PhysicalDevice* pd = fromHandle<PhysicalDevice>(physicalDevice);
  if (!pd) return VK_ERROR_INITIALIZATION_FAILED;
  for (uint32_t i = 0; i < pCreateInfo->enabledExtensionCount; ++i) {
    if (!pd->supportsExtension(pCreateInfo->ppEnabledExtensionNames[i])) {
      report(pd, Severity::Error, nullptr, "vkCreateDevice: device extension %s is not supported",
             pCreateInfo->ppEnabledExtensionNames[i]);
      return VK_ERROR_EXTENSION_NOT_PRESENT;
    }
  }
  if (std::string bad = pd->firstUnsupportedFeature(*pCreateInfo); !bad.empty()) {
    // VUID-VkDeviceCreateInfo-pNext-... : every requested feature must be supported (VK_ERROR_FEATURE_NOT_PRESENT)
    report(pd, Severity::Error, nullptr, "vkCreateDevice: %s is requested, but vkrt does not support it", bad.c_str());
    return VK_ERROR_FEATURE_NOT_PRESENT;
  }
  for (uint32_t i = 0; i < pCreateInfo->queueCreateInfoCount; ++i) {
    const VkDeviceQueueCreateInfo& q = pCreateInfo->pQueueCreateInfos[i];
    if (q.queueFamilyIndex >= PhysicalDevice::kQueueFamilyCount) {
      report(pd, Severity::Error, "VUID-VkDeviceQueueCreateInfo-queueFamilyIndex-00381",
             "vkCreateDevice: pQueueCreateInfos[%u].queueFamilyIndex is %u; vkrt has %u queue families", i,
             q.queueFamilyIndex, PhysicalDevice::kQueueFamilyCount);
      return VK_ERROR_INITIALIZATION_FAILED;
    }
    const uint32_t available = pd->queueFamilies[q.queueFamilyIndex].queueCount;
    if (q.queueCount == 0 || q.queueCount > available) {
      report(pd, Severity::Error, "VUID-VkDeviceQueueCreateInfo-queueCount-00382",
             "vkCreateDevice: pQueueCreateInfos[%u].queueCount is %u; family %u has %u queues", i, q.queueCount,
             q.queueFamilyIndex, available);
      return VK_ERROR_INITIALIZATION_FAILED;
    }
    // VUID-VkDeviceCreateInfo-queueFamilyIndex-02802: one VkDeviceQueueCreateInfo per family (with the same flags)
    for (uint32_t k = 0; k < i; ++k) {
      const VkDeviceQueueCreateInfo& e = pCreateInfo->pQueueCreateInfos[k];
      if (e.queueFamilyIndex == q.queueFamilyIndex && e.flags == q.flags) {
        report(pd, Severity::Error, "VUID-VkDeviceCreateInfo-queueFamilyIndex-02802",
               "vkCreateDevice: pQueueCreateInfos[%u] and [%u] both name queue family %u (flags 0x%x)", k, i,
               q.queueFamilyIndex, q.flags);
        return VK_ERROR_INITIALIZATION_FAILED;
      }
    }
  }
  Device* dev = createObject<Device>(pAllocator, VK_SYSTEM_ALLOCATION_SCOPE_DEVICE, pd, *pCreateInfo);
  if (!dev) return VK_ERROR_OUT_OF_HOST_MEMORY;
  dev->allocator = pAllocator;
  for (uint32_t i = 0; i < pCreateInfo->queueCreateInfoCount; ++i) {
    const VkDeviceQueueCreateInfo& q = pCreateInfo->pQueueCreateInfos[i];
    for (uint32_t k = 0; k < q.queueCount; ++k) {
      Queue* queue =
          createObject<Queue>(pAllocator, VK_SYSTEM_ALLOCATION_SCOPE_DEVICE, dev, q.queueFamilyIndex, k, q.flags);
      if (!queue) {
        for (Queue* made : dev->queues) destroyObject(made, pAllocator);
        destroyObject(dev, pAllocator);
        return VK_ERROR_OUT_OF_HOST_MEMORY;
      }
      dev->queues.push_back(queue);
    }
  }
  *pDevice = toHandle(dev);
  return VK_SUCCESS;
}

VKAPI_ATTR void VKAPI_CALL vkrt_DestroyDevice(VkDevice device, const VkAllocationCallbacks* pAllocator) {
  if (!device) return;
  Device* dev = fromHandle<Device>(device);
  if (!dev) {
    report(nullptr, Severity::Error, "VUID-vkDestroyDevice-device-parameter",
           "vkDestroyDevice: 0x%llx is not a live VkDevice", (unsigned long long)rawHandle(device));
    return;
  }
  // Work still running is cancelled (a shader that never ends would keep this call from returning), work not
  // started is skipped (closing, set before the cancellation: a command that registers its job afterwards sees it).
  {
    std::lock_guard lock(sync::mutex());
    dev->closing.store(true, std::memory_order_release);
    for (Queue* q : dev->queues) q->abandonWaits();
  }
  sync::notifyAll();
  exec::cancelJobsOf(dev);
  for (Queue* q : dev->queues) q->waitIdle();
  for (Queue* q : dev->queues) destroyObject(q, pAllocator);
  dev->runDeferred(true);
  destroyObject(dev, pAllocator);
}

VKAPI_ATTR void VKAPI_CALL vkrt_GetDeviceQueue(VkDevice device, uint32_t queueFamilyIndex, uint32_t queueIndex,
                                               VkQueue* pQueue) {
  Device* dev = fromHandleUnchecked<Device>(device);
  for (Queue* q : dev->queues) {
    if (q->family == queueFamilyIndex && q->index == queueIndex && q->flags == 0) {
      *pQueue = toHandle(q);
      return;
    }
  }
  report(dev, Severity::Error, "VUID-vkGetDeviceQueue-queueIndex-00385",
         "vkGetDeviceQueue: no queue (family %u, index %u) was created with flags 0", queueFamilyIndex, queueIndex);
  *pQueue = VK_NULL_HANDLE;
}

VKAPI_ATTR void VKAPI_CALL vkrt_GetDeviceQueue2(VkDevice device, const VkDeviceQueueInfo2* pQueueInfo,
                                                VkQueue* pQueue) {
  Device* dev = fromHandleUnchecked<Device>(device);
  for (Queue* q : dev->queues) {
    if (q->family == pQueueInfo->queueFamilyIndex && q->index == pQueueInfo->queueIndex &&
        q->flags == pQueueInfo->flags) {
      *pQueue = toHandle(q);
      return;
    }
  }
  *pQueue = VK_NULL_HANDLE;
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_DeviceWaitIdle(VkDevice device) {
  Device* dev = fromHandleUnchecked<Device>(device);
  for (Queue* q : dev->queues) q->waitIdle();
  // Lost Device: the queues still drain (their batches complete without running), then the loss is returned.
  return dev->lost ? VK_ERROR_DEVICE_LOST : VK_SUCCESS;
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_SetDebugUtilsObjectNameEXT(VkDevice device,
                                                               const VkDebugUtilsObjectNameInfoEXT* pNameInfo) {
  Object* o = findAnyObject(pNameInfo->objectHandle);
  if (!o) {
    report(fromHandle<Device>(device), Severity::Error, "VUID-VkDebugUtilsObjectNameInfoEXT-objectType-02590",
           "vkSetDebugUtilsObjectNameEXT: objectHandle 0x%llx is not a live vkrt object",
           (unsigned long long)pNameInfo->objectHandle);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  o->setDebugName(pNameInfo->pObjectName);
  return VK_SUCCESS;
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_SetDebugUtilsObjectTagEXT(VkDevice, const VkDebugUtilsObjectTagInfoEXT*) {
  return VK_SUCCESS;  // tags carry no meaning for vkrt; accepted as the spec allows
}

}  // extern "C"
