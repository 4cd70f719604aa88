#include "runtime/acceleration_structure.hpp"

#include <algorithm>
#include <cstring>

#include "runtime/alloc.hpp"
#include "runtime/buffer.hpp"
#include "runtime/device.hpp"
#include "runtime/lookup.hpp"
#include "runtime/physical_device.hpp"
#include "runtime/report.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {

namespace {

using ull = unsigned long long;

// Changes whenever accel's serialized format or the header vkrt writes before it changes.
constexpr uint8_t kCompatibilityUuid[VK_UUID_SIZE] = {'v', 'k', 'r', 't', '-', 'a', 's', '-',
                                                      's', 'e', 'r', 0,   0,   0,   0,   1};

// The registry's entry at `at` becomes `as`, in both of its maps. Under the registry mutex.
void place(Device* dev, uint64_t at, AccelerationStructure* as) {
  dev->accelerationStructures[at] = as;
  if (as->type == VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR) {
    dev->topLevelStructures.erase(at);
  } else {
    dev->topLevelStructures[at] = as;
  }
}

// Removes the registry's entry at `at` if it is `as`. Under the registry mutex.
void unplace(Device* dev, uint64_t at, const AccelerationStructure* as) {
  auto it = dev->accelerationStructures.find(at);
  if (it == dev->accelerationStructures.end() || it->second != as) return;
  dev->accelerationStructures.erase(it);
  dev->topLevelStructures.erase(at);
}

}  // namespace

AccelerationStructure::AccelerationStructure(Device* dev, const VkAccelerationStructureCreateInfoKHR& info, Buffer* buf)
    : Object(kType, dev->instance, dev), buffer(buf), offset(info.offset), size(info.size), type(info.type) {
  registerAddress(false);
}

AccelerationStructure::AccelerationStructure(VkObjectType objectType, Device* dev, VkAccelerationStructureTypeKHR t,
                                             VkDeviceSize sz)
    : Object(objectType, dev->instance, dev), buffer(nullptr), offset(0), size(sz), type(t) {}

AccelerationStructure::~AccelerationStructure() {
  std::lock_guard lock(device->accelerationStructuresMutex);
  if (registeredAt_) unplace(device, registeredAt_, this);
}

uint64_t AccelerationStructure::address() const {
  const uint8_t* data = buffer ? buffer->data() : boundBase_;
  return data ? reinterpret_cast<uint64_t>(data) + offset : 0;
}

// The registry maps an address to the structure whose content its memory holds: the one built there last. A
// structure created over a live one takes the address only once it is built (creation does not touch the
// memory, so the structure built there before stays what the address denotes), or if nothing is there yet.
void AccelerationStructure::registerAddress(bool built) {
  const uint64_t at = address();
  if (!at) return;
  std::lock_guard lock(device->accelerationStructuresMutex);
  if (registeredAt_ && registeredAt_ != at)
    unplace(device, registeredAt_, this);  // (a buffer is bound once; kept exact)
  if (built || !device->accelerationStructures.count(at)) place(device, at, this);
  registeredAt_ = at;
}

std::shared_ptr<const AccelerationStructure::Content> AccelerationStructure::content() const {
  std::lock_guard lock(mutex_);
  return content_;
}

void AccelerationStructure::setContent(std::shared_ptr<const Content> c) {
  if (c && c->blas) device->blasGeneration.fetch_add(1);
  {
    std::lock_guard lock(mutex_);
    content_ = std::move(c);
  }
  registerAddress(true);
}

AccelerationStructure* accelerationStructureAt(Device* dev, uint64_t address) {
  std::lock_guard lock(dev->accelerationStructuresMutex);
  auto it = dev->accelerationStructures.find(address);
  return it == dev->accelerationStructures.end() ? nullptr : it->second;
}

namespace {
// Whether a top level's content `c` at `as` is known to be over its bottom levels' current contents at the device's
// bottom-level `generation`: built at it, or found current at it since (topLevelAt). (A null tlas is not.)
bool currentTopLevel(const AccelerationStructure& as, const AccelerationStructure::Content* c, uint64_t generation) {
  return c && c->tlas && (c->blasGeneration == generation || as.checkedGeneration.load() == generation);
}
}  // namespace

std::shared_ptr<const accel::Tlas> topLevelAt(Device* dev, uint64_t address) {
  AccelerationStructure* as = nullptr;
  std::shared_ptr<const AccelerationStructure::Content> c;
  const uint64_t generation = dev->blasGeneration.load();
  std::vector<accel::Instance> instances;
  std::vector<std::shared_ptr<const accel::Blas>> keep;  // the current bottom levels, until the Tlas holds them
  bool stale = false;
  {
    std::lock_guard lock(dev->accelerationStructuresMutex);
    auto it = dev->accelerationStructures.find(address);
    if (it == dev->accelerationStructures.end()) return nullptr;
    as = it->second;
    c = as->content();
    if (!c || !c->tlas) return nullptr;
    if (currentTopLevel(*as, c.get(), generation)) return c->tlas;
    // Some bottom level was built since: compare each instance's with the current content at its address.
    instances.assign(c->tlas->instances().begin(), c->tlas->instances().end());
    for (size_t i = 0; i < instances.size() && i < c->blasAt.size(); ++i) {
      if (!instances[i].blas || !c->blasAt[i]) continue;
      auto b = dev->accelerationStructures.find(c->blasAt[i]);
      if (b == dev->accelerationStructures.end()) continue;  // destroyed: the instance keeps what it was built with
      auto bc = b->second->content();
      if (bc && bc->blas && bc->blas.get() != instances[i].blas) {
        instances[i].blas = bc->blas.get();
        keep.push_back(bc->blas);
        stale = true;
      }
    }
  }
  if (!stale) {
    as->checkedGeneration.store(generation);
    return c->tlas;
  }
  std::string error;
  auto fresh = std::make_shared<AccelerationStructure::Content>(*c);
  fresh->tlas = accel::Tlas::build(std::move(instances), c->tlas->options(), &error);
  if (!fresh->tlas) return c->tlas;  // (cannot fail for inputs that built before; kept safe)
  fresh->blasGeneration = generation;
  as->setContent(fresh);
  return fresh->tlas;
}

void snapshotTopLevels(Device* dev, exec::TopLevelResolver::Snapshot* out) {
  const uint64_t generation = dev->blasGeneration.load();
  std::lock_guard lock(dev->accelerationStructuresMutex);
  out->structures.reserve(dev->topLevelStructures.size());
  for (const auto& [address, as] : dev->topLevelStructures) {  // (a std::map: the addresses come sorted)
    std::shared_ptr<const AccelerationStructure::Content> c = as->content();
    out->structures.emplace_back(address, currentTopLevel(*as, c.get(), generation) ? c->tlas : nullptr);
  }
}

void DispatchStructures::missed(uint64_t address) {
  report(about_, Severity::Error, nullptr,
         "%s: rayQueryInitializeEXT was given the acceleration structure address 0x%llx, which is not the address "
         "of a built top-level acceleration structure of this device; those ray queries find no intersection",
         fn_, (ull)address);
}

VkDeviceSize requiredSize(uint64_t primitives) {
  // A header plus 16 bytes a primitive, rounded to 256: the structure's real data is host memory vkrt owns
  // (acceleration_structure.hpp), so the application's buffer only needs to be of a plausible, proportional size.
  return (256 + primitives * 16 + 255) / 256 * 256;
}

accel::BuildOptions buildOptions(VkBuildAccelerationStructureFlagsKHR flags) {
  accel::BuildOptions o;
  o.preferFastTrace = flags & VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
  o.preferFastBuild = flags & VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_BUILD_BIT_KHR;
  o.allowUpdate = flags & VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR;
  o.lowMemory = flags & VK_BUILD_ACCELERATION_STRUCTURE_LOW_MEMORY_BIT_KHR;
  return o;
}

void accelerationStructureVersion(const Device* dev, uint8_t out[2 * VK_UUID_SIZE]) {
  std::memcpy(out, dev->physicalDevice->properties11.driverUUID, VK_UUID_SIZE);
  std::memcpy(out + VK_UUID_SIZE, kCompatibilityUuid, VK_UUID_SIZE);
}

}  // namespace vkrt

using namespace vkrt;

extern "C" {

VKAPI_ATTR VkResult VKAPI_CALL vkrt_CreateAccelerationStructureKHR(
    VkDevice device, const VkAccelerationStructureCreateInfoKHR* pCreateInfo, const VkAllocationCallbacks* pAllocator,
    VkAccelerationStructureKHR* pAccelerationStructure) {
  const char* fn = "vkCreateAccelerationStructureKHR";
  Device* dev = fromHandleUnchecked<Device>(device);
  const VkAccelerationStructureCreateInfoKHR& ci = *pCreateInfo;
  // VUID-vkCreateAccelerationStructureKHR-accelerationStructure-03611
  if (!dev->enabled(Feature::accelerationStructure)) {
    report(dev, Severity::Error, "VUID-vkCreateAccelerationStructureKHR-accelerationStructure-03611",
           "%s: the accelerationStructure feature is not enabled", fn);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // VUID-VkAccelerationStructureCreateInfoKHR-buffer-parameter
  Buffer* buf = liveOrReport<Buffer>(dev, ci.buffer, fn, "VUID-VkAccelerationStructureCreateInfoKHR-buffer-parameter");
  if (!buf) return VK_ERROR_VALIDATION_FAILED_EXT;
  // VUID-VkAccelerationStructureCreateInfoKHR-buffer-03614
  if (!(buf->usage & VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR)) {
    report(buf, Severity::Error, "VUID-VkAccelerationStructureCreateInfoKHR-buffer-03614",
           "%s: the buffer's usage 0x%x lacks VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR", fn, buf->usage);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // VUID-VkAccelerationStructureCreateInfoKHR-offset-03734
  if (ci.offset % 256) {
    report(buf, Severity::Error, "VUID-VkAccelerationStructureCreateInfoKHR-offset-03734",
           "%s: offset %llu is not a multiple of 256", fn, (ull)ci.offset);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // VUID-VkAccelerationStructureCreateInfoKHR-offset-03616
  if (ci.offset > buf->size || ci.size > buf->size - ci.offset) {
    report(buf, Severity::Error, "VUID-VkAccelerationStructureCreateInfoKHR-offset-03616",
           "%s: offset %llu + size %llu exceeds the buffer's size %llu", fn, (ull)ci.offset, (ull)ci.size,
           (ull)buf->size);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // VUID-VkAccelerationStructureCreateInfoKHR-type-parameter
  if (ci.type > VK_ACCELERATION_STRUCTURE_TYPE_GENERIC_KHR) {
    report(dev, Severity::Error, "VUID-VkAccelerationStructureCreateInfoKHR-type-parameter",
           "%s: type %d is not a valid value", fn, int(ci.type));
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  const bool replay = ci.createFlags & VK_ACCELERATION_STRUCTURE_CREATE_DEVICE_ADDRESS_CAPTURE_REPLAY_BIT_KHR;
  // VUID-VkAccelerationStructureCreateInfoKHR-deviceAddress-03612
  if (ci.deviceAddress && !replay) {
    report(dev, Severity::Error, "VUID-VkAccelerationStructureCreateInfoKHR-deviceAddress-03612",
           "%s: deviceAddress 0x%llx is given without "
           "VK_ACCELERATION_STRUCTURE_CREATE_DEVICE_ADDRESS_CAPTURE_REPLAY_BIT_KHR",
           fn, (ull)ci.deviceAddress);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // VUID-VkAccelerationStructureCreateInfoKHR-createFlags-03613
  if (replay && !dev->enabled(Feature::accelerationStructureCaptureReplay)) {
    report(dev, Severity::Error, "VUID-VkAccelerationStructureCreateInfoKHR-createFlags-03613",
           "%s: DEVICE_ADDRESS_CAPTURE_REPLAY is set but the accelerationStructureCaptureReplay feature is not enabled",
           fn);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // The buffer may still be unbound: the structure's address is known once it is (AccelerationStructure::address).
  const uint64_t address = buf->data() ? reinterpret_cast<uint64_t>(buf->data()) + ci.offset : 0;
  // Capture/replay: the structure gets its address from its buffer (placed by the memory's own capture/replay), so a
  // replayed address must be exactly where the buffer range now is.
  if (ci.deviceAddress && address && ci.deviceAddress != address) {
    report(buf, Severity::Error, nullptr,
           "%s: the captured deviceAddress 0x%llx cannot be reproduced: buffer + offset is 0x%llx (replay the buffer's "
           "memory at "
           "its captured opaque address first)",
           fn, (ull)ci.deviceAddress, (ull)address);
    return VK_ERROR_INVALID_OPAQUE_CAPTURE_ADDRESS;
  }
  auto* as = createObject<AccelerationStructure>(pAllocator, VK_SYSTEM_ALLOCATION_SCOPE_OBJECT, dev, ci, buf);
  if (!as) return VK_ERROR_OUT_OF_HOST_MEMORY;
  *pAccelerationStructure = toHandle(as);
  return VK_SUCCESS;
}

VKAPI_ATTR void VKAPI_CALL vkrt_DestroyAccelerationStructureKHR(VkDevice device,
                                                                VkAccelerationStructureKHR accelerationStructure,
                                                                const VkAllocationCallbacks* pAllocator) {
  destroyDeviceChildWhenIdle<AccelerationStructure>(
      device, accelerationStructure, pAllocator, "vkDestroyAccelerationStructureKHR",
      "VUID-vkDestroyAccelerationStructureKHR-accelerationStructure-parameter",
      "VUID-vkDestroyAccelerationStructureKHR-accelerationStructure-02442");
}

VKAPI_ATTR VkDeviceAddress VKAPI_CALL vkrt_GetAccelerationStructureDeviceAddressKHR(
    VkDevice device, const VkAccelerationStructureDeviceAddressInfoKHR* pInfo) {
  Device* dev = fromHandleUnchecked<Device>(device);
  // VUID-VkAccelerationStructureDeviceAddressInfoKHR-accelerationStructure-parameter
  auto* as = liveOrReport<AccelerationStructure>(
      dev, pInfo->accelerationStructure, "vkGetAccelerationStructureDeviceAddressKHR",
      "VUID-VkAccelerationStructureDeviceAddressInfoKHR-accelerationStructure-parameter");
  if (!as) return 0;
  as->registerAddress(false);  // (a structure created on an unbound buffer gets its address now)
  return as->address();
}

VKAPI_ATTR void VKAPI_CALL vkrt_GetAccelerationStructureBuildSizesKHR(
    VkDevice device, VkAccelerationStructureBuildTypeKHR buildType,
    const VkAccelerationStructureBuildGeometryInfoKHR* pBuildInfo, const uint32_t* pMaxPrimitiveCounts,
    VkAccelerationStructureBuildSizesInfoKHR* pSizeInfo) {
  Device* dev = fromHandleUnchecked<Device>(device);
  const char* fn = "vkGetAccelerationStructureBuildSizesKHR";
  pSizeInfo->accelerationStructureSize = 0;
  pSizeInfo->buildScratchSize = pSizeInfo->updateScratchSize = 0;
  // VUID-vkGetAccelerationStructureBuildSizesKHR-rayTracingPipeline-03617
  // (Either feature: a device with ray queries and no ray tracing pipelines builds its structures too.)
  if (!dev->enabled(Feature::rayTracingPipeline) && !dev->enabled(Feature::rayQuery)) {
    report(dev, Severity::Error, "VUID-vkGetAccelerationStructureBuildSizesKHR-rayTracingPipeline-03617",
           "%s: neither the rayTracingPipeline nor the rayQuery feature is enabled", fn);
    return;
  }
  // VUID-vkGetAccelerationStructureBuildSizesKHR-pBuildInfo-03619
  if (pBuildInfo->geometryCount && !pMaxPrimitiveCounts) {
    report(dev, Severity::Error, "VUID-vkGetAccelerationStructureBuildSizesKHR-pBuildInfo-03619",
           "%s: pMaxPrimitiveCounts is NULL for %u geometries", fn, pBuildInfo->geometryCount);
    return;
  }
  uint64_t primitives = 0;
  for (uint32_t i = 0; i < pBuildInfo->geometryCount; ++i) primitives += pMaxPrimitiveCounts[i];
  pSizeInfo->accelerationStructureSize = requiredSize(primitives);
  pSizeInfo->buildScratchSize = pSizeInfo->updateScratchSize = kScratchSize;
  (void)buildType;
}

VKAPI_ATTR void VKAPI_CALL vkrt_GetDeviceAccelerationStructureCompatibilityKHR(
    VkDevice device, const VkAccelerationStructureVersionInfoKHR* pVersionInfo,
    VkAccelerationStructureCompatibilityKHR* pCompatibility) {
  uint8_t ours[2 * VK_UUID_SIZE];
  accelerationStructureVersion(fromHandleUnchecked<Device>(device), ours);
  *pCompatibility = std::memcmp(ours, pVersionInfo->pVersionData, sizeof ours) == 0
                        ? VK_ACCELERATION_STRUCTURE_COMPATIBILITY_COMPATIBLE_KHR
                        : VK_ACCELERATION_STRUCTURE_COMPATIBILITY_INCOMPATIBLE_KHR;
}

}  // extern "C"
