#include "runtime/memory.hpp"

#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <mutex>

#include "runtime/alloc.hpp"
#include "runtime/device.hpp"
#include "runtime/lookup.hpp"
#include "runtime/physical_device.hpp"
#include "runtime/report.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {
namespace arena {
namespace {

// 86 TiB + 448 GiB, the last 64 GiB below 0x568000000000. Application memory under the sanitizers of Debian 12's GCC
// 12 and Clang 14 on x86-64: ThreadSanitizer's middle range (0x550000000000-0x568000000000, where it expects
// position-independent executables; its shadow and meta ranges lie below 0x340000000000, where the arena used to
// be), MemorySanitizer's 0x510000000000-0x600000000000, above AddressSanitizer's shadow (below 0x10007fff8000).
// Clear of the executable itself and its brk heap (Linux loads PIE at 0x555555554000 plus up to 1 TiB of
// randomization, so below 0x565600000000), and of mmap() and stacks (0x7f..).
constexpr uint64_t kHint = 0x567000000000ull;
constexpr VkDeviceSize kCapacity = 64ull << 30;
constexpr VkDeviceSize kPage = 4096;

// The arena's bytes are a memory file (memfd) mapped shared over the whole range, offset o at base + o, so that
// the pages of an allocation can be mapped a second time at another address of the range (alias): a buffer
// replayed at its captured device address sees the bytes of the memory it is bound to. Where no memory file can
// be made the arena is anonymous memory (fd < 0) and there are no aliases.
struct Arena {
  std::mutex mutex;
  uint8_t* base = nullptr;
  int fd = -1;
  std::map<uint64_t, uint64_t> freeRanges;  // offset -> size, coalesced

  Arena() {
    fd = memfd_create("vkrt-device-memory", MFD_CLOEXEC);
    if (fd >= 0 && ftruncate(fd, off_t(kCapacity)) != 0) {
      close(fd);
      fd = -1;
    }
    const int kind = fd >= 0 ? MAP_SHARED : MAP_PRIVATE | MAP_ANONYMOUS;
    void* p =
        mmap(reinterpret_cast<void*>(kHint), kCapacity, PROT_NONE, kind | MAP_NORESERVE | MAP_FIXED_NOREPLACE, fd, 0);
    if (p == MAP_FAILED) {
      // The fixed range is taken: work anywhere. Opaque capture addresses then differ between processes.
      p = mmap(nullptr, kCapacity, PROT_NONE, kind | MAP_NORESERVE, fd, 0);
    }
    if (p == MAP_FAILED) return;
    base = static_cast<uint8_t*>(p);
    freeRanges[0] = kCapacity;
  }

  // Whether [offset, offset + size) lies in one free range.
  bool isFree(uint64_t offset, uint64_t size) const {
    auto it = freeRanges.upper_bound(offset);
    if (it == freeRanges.begin()) return false;
    --it;
    return offset + size <= it->first + it->second;
  }

  uint8_t* take(uint64_t offset, uint64_t size) {
    // Precondition: [offset, offset+size) lies in one free range.
    auto it = std::prev(freeRanges.upper_bound(offset));
    uint64_t rOff = it->first, rSize = it->second;
    freeRanges.erase(it);
    if (offset > rOff) freeRanges[rOff] = offset - rOff;
    if (offset + size < rOff + rSize) freeRanges[offset + size] = rOff + rSize - (offset + size);
    uint8_t* p = base + offset;
    if (mprotect(p, size, PROT_READ | PROT_WRITE) != 0) {
      give(offset, size);
      return nullptr;
    }
    return p;
  }

  void give(uint64_t offset, uint64_t size) {
    auto next = freeRanges.lower_bound(offset);
    if (next != freeRanges.end() && offset + size == next->first) {
      size += next->second;
      next = freeRanges.erase(next);
    }
    if (next != freeRanges.begin()) {
      auto prev = std::prev(next);
      if (prev->first + prev->second == offset) {
        prev->second += size;
        return;
      }
    }
    freeRanges[offset] = size;
  }
};

Arena& get() {
  static Arena* a = new Arena;  // lives as long as the process: memory may be freed during static destruction
  return *a;
}

}  // namespace

uint8_t* allocate(VkDeviceSize size, uint64_t requestedAddress, bool fromTop) {
  Arena& a = get();
  if (!a.base || size == 0) return nullptr;
  uint64_t rounded = (size + kPage - 1) / kPage * kPage;
  std::lock_guard lock(a.mutex);
  if (requestedAddress) {
    uint64_t base = reinterpret_cast<uint64_t>(a.base);
    if (requestedAddress < base || requestedAddress % kPage || requestedAddress - base + rounded > kCapacity)
      return nullptr;
    uint64_t off = requestedAddress - base;
    if (!a.isFree(off, rounded)) return nullptr;
    return a.take(off, rounded);
  }
  if (fromTop) {
    for (auto it = a.freeRanges.rbegin(); it != a.freeRanges.rend(); ++it) {
      if (it->second >= rounded) return a.take(it->first + it->second - rounded, rounded);
    }
    return nullptr;
  }
  for (auto& [off, sz] : a.freeRanges) {
    if (sz >= rounded) return a.take(off, rounded);
  }
  return nullptr;
}

void release(uint8_t* p, VkDeviceSize size) {
  Arena& a = get();
  uint64_t rounded = (size + kPage - 1) / kPage * kPage;
  // Give the pages back to the system (of a memory file: punch them out of it, which an alias sees too) and make
  // them inaccessible: a stale device address faults.
  madvise(p, rounded, a.fd >= 0 ? MADV_REMOVE : MADV_DONTNEED);
  mprotect(p, rounded, PROT_NONE);
  std::lock_guard lock(a.mutex);
  a.give(static_cast<uint64_t>(p - a.base), rounded);
}

uint8_t* alias(const uint8_t* source, VkDeviceSize size, uint64_t requestedAddress) {
  Arena& a = get();
  if (!a.base || a.fd < 0 || size == 0) return nullptr;
  const uint64_t base = reinterpret_cast<uint64_t>(a.base);
  const uint64_t src = reinterpret_cast<uint64_t>(source);
  const uint64_t within = src % kPage;
  if (requestedAddress && requestedAddress % kPage != within) return nullptr;  // pages map whole
  const uint64_t srcPage = src - within - base;
  const uint64_t rounded = (within + size + kPage - 1) / kPage * kPage;
  std::lock_guard lock(a.mutex);
  uint64_t off = 0;
  if (requestedAddress) {
    if (requestedAddress < base || requestedAddress - within - base > kCapacity - rounded) return nullptr;
    off = requestedAddress - within - base;
    if (!a.isFree(off, rounded)) return nullptr;
  } else {  // top-down, with memory that may be captured (see vkrt_AllocateMemory)
    auto it = std::find_if(a.freeRanges.rbegin(), a.freeRanges.rend(), [&](auto& r) { return r.second >= rounded; });
    if (it == a.freeRanges.rend()) return nullptr;
    off = it->first + it->second - rounded;
  }
  if (!a.take(off, rounded)) return nullptr;
  // The source's pages of the memory file, mapped over the taken range in place of its own.
  if (mmap(a.base + off, rounded, PROT_READ | PROT_WRITE, MAP_SHARED | MAP_FIXED, a.fd, off_t(srcPage)) == MAP_FAILED) {
    mmap(a.base + off, rounded, PROT_NONE, MAP_SHARED | MAP_FIXED, a.fd, off_t(off));
    a.give(off, rounded);
    return nullptr;
  }
  return a.base + off + within;
}

void unalias(uint8_t* p, VkDeviceSize size) {
  Arena& a = get();
  const uint64_t within = reinterpret_cast<uint64_t>(p) % kPage;
  const uint64_t off = uint64_t(p - a.base) - within;
  const uint64_t rounded = (within + size + kPage - 1) / kPage * kPage;
  // The range's own pages of the memory file again, inaccessible as free ranges are (the source's bytes stay).
  mmap(a.base + off, rounded, PROT_NONE, MAP_SHARED | MAP_FIXED, a.fd, off_t(off));
  std::lock_guard lock(a.mutex);
  a.give(off, rounded);
}

bool contains(uint64_t address, VkDeviceSize size) {
  uint64_t b = reinterpret_cast<uint64_t>(get().base);
  return address >= b && address + size <= b + kCapacity && address + size >= address;
}

bool accessible(uint64_t address, VkDeviceSize size) {
  if (!contains(address, size)) return false;
  Arena& a = get();
  uint64_t off = address - reinterpret_cast<uint64_t>(a.base);
  std::lock_guard lock(a.mutex);
  // Allocated memory is what lies between free ranges: the free range at or before `off` must end by `off`,
  // and the next one must start at or after the end of the range.
  auto next = a.freeRanges.upper_bound(off);
  if (next != a.freeRanges.begin()) {
    auto prev = std::prev(next);
    if (prev->first + prev->second > off) return false;
  }
  return next == a.freeRanges.end() || next->first >= off + size;
}

std::string whyUnavailable(uint64_t address, VkDeviceSize size) {
  Arena& a = get();
  const uint64_t base = reinterpret_cast<uint64_t>(a.base);
  const uint64_t rounded = (size + kPage - 1) / kPage * kPage;
  char buf[320];
  int n = std::snprintf(buf, sizeof(buf), "[0x%llx, 0x%llx)", (unsigned long long)address,
                        (unsigned long long)(address + rounded));
  const size_t at = n > 0 ? size_t(n) : 0;
  if (!a.base || address < base || address - base > kCapacity || rounded > kCapacity - (address - base)) {
    std::snprintf(buf + at, sizeof(buf) - at, " lies outside vkrt's device address range [0x%llx, 0x%llx)",
                  (unsigned long long)base, (unsigned long long)(base + kCapacity));
  } else if (address % kPage) {
    std::snprintf(buf + at, sizeof(buf) - at, " does not start at a page (4096 bytes) as vkrt's addresses do");
  } else {
    std::lock_guard lock(a.mutex);
    // Allocated memory is what lies between free ranges: find the first allocated part of the range.
    uint64_t off = address - base, from = off;
    auto next = a.freeRanges.upper_bound(off);
    if (next != a.freeRanges.begin()) {
      auto prev = std::prev(next);
      if (prev->first + prev->second > off) from = prev->first + prev->second;
    }
    uint64_t to = next == a.freeRanges.end() ? kCapacity : next->first;
    if (from >= off + rounded) {
      std::snprintf(buf + at, sizeof(buf) - at, " is free (mapping it failed)");
    } else {
      std::snprintf(buf + at, sizeof(buf) - at, ": [0x%llx, 0x%llx) of it is held by memory allocated earlier",
                    (unsigned long long)(base + from), (unsigned long long)(base + std::min(to, off + rounded)));
    }
  }
  return buf;
}

uint64_t baseAddress() { return reinterpret_cast<uint64_t>(get().base); }
VkDeviceSize capacity() { return kCapacity; }

}  // namespace arena

Memory::Memory(Device* dev, uint8_t* b, VkDeviceSize s, uint32_t type, VkMemoryAllocateFlags flags)
    : Object(kType, dev->instance, dev), base(b), size(s), typeIndex(type), allocateFlags(flags) {}

Memory::~Memory() { arena::release(base, size); }

}  // namespace vkrt

using namespace vkrt;

extern "C" {

VKAPI_ATTR VkResult VKAPI_CALL vkrt_AllocateMemory(VkDevice device, const VkMemoryAllocateInfo* pAllocateInfo,
                                                   const VkAllocationCallbacks* pAllocator, VkDeviceMemory* pMemory) {
  Device* dev = fromHandleUnchecked<Device>(device);
  const VkPhysicalDeviceMemoryProperties& props = dev->physicalDevice->memoryProperties;
  if (pAllocateInfo->memoryTypeIndex >= props.memoryTypeCount) {
    report(dev, Severity::Error, "VUID-vkAllocateMemory-pAllocateInfo-01714",
           "vkAllocateMemory: memoryTypeIndex %u is not less than memoryTypeCount %u", pAllocateInfo->memoryTypeIndex,
           props.memoryTypeCount);
    return VK_ERROR_OUT_OF_DEVICE_MEMORY;
  }
  if (pAllocateInfo->allocationSize > props.memoryHeaps[0].size) {
    report(dev, Severity::Error, "VUID-vkAllocateMemory-pAllocateInfo-01713",
           "vkAllocateMemory: allocationSize %llu exceeds the heap size %llu",
           (unsigned long long)pAllocateInfo->allocationSize, (unsigned long long)props.memoryHeaps[0].size);
    return VK_ERROR_OUT_OF_DEVICE_MEMORY;
  }
  VkMemoryAllocateFlags flags = 0;
  uint64_t requested = 0;
  if (auto* f =
          findInChain<VkMemoryAllocateFlagsInfo>(pAllocateInfo->pNext, VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO))
    flags = f->flags;
  if (auto* c = findInChain<VkMemoryOpaqueCaptureAddressAllocateInfo>(
          pAllocateInfo->pNext, VK_STRUCTURE_TYPE_MEMORY_OPAQUE_CAPTURE_ADDRESS_ALLOCATE_INFO))
    requested = c->opaqueCaptureAddress;
  if (requested && !(flags & VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_CAPTURE_REPLAY_BIT)) requested = 0;
  if ((flags & VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_CAPTURE_REPLAY_BIT) &&
      !dev->enabled(Feature::bufferDeviceAddressCaptureReplay)) {
    report(dev, Severity::Error, "VUID-VkMemoryAllocateInfo-flags-03331",
           "vkAllocateMemory: VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_CAPTURE_REPLAY_BIT needs the "
           "bufferDeviceAddressCaptureReplay feature, which is not enabled");
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // Memory that may be captured is placed top-down, everything else bottom-up, so that the ordinary
  // allocations of a replaying application do not take the ranges its captured allocations need.
  uint8_t* base = arena::allocate(pAllocateInfo->allocationSize, requested,
                                  (flags & VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_CAPTURE_REPLAY_BIT) != 0);
  if (!base) {
    if (requested) {
      report(dev, Severity::Error, nullptr,
             "vkAllocateMemory: opaque capture address 0x%llx (%llu bytes) is not available in this process: %s",
             (unsigned long long)requested, (unsigned long long)pAllocateInfo->allocationSize,
             arena::whyUnavailable(requested, pAllocateInfo->allocationSize).c_str());
      return VK_ERROR_INVALID_OPAQUE_CAPTURE_ADDRESS;
    }
    return VK_ERROR_OUT_OF_DEVICE_MEMORY;
  }
  Memory* mem = createObject<Memory>(pAllocator, VK_SYSTEM_ALLOCATION_SCOPE_OBJECT, dev, base,
                                     pAllocateInfo->allocationSize, pAllocateInfo->memoryTypeIndex, flags);
  if (!mem) {
    arena::release(base, pAllocateInfo->allocationSize);
    return VK_ERROR_OUT_OF_HOST_MEMORY;
  }
  *pMemory = toHandle(mem);
  return VK_SUCCESS;
}

// The device group has one device, so no pair of device indices is valid (VUID-...-00694 asks for two different ones).
VKAPI_ATTR void VKAPI_CALL vkrt_GetDeviceGroupPeerMemoryFeatures(VkDevice device, uint32_t heapIndex,
                                                                 uint32_t localDeviceIndex, uint32_t remoteDeviceIndex,
                                                                 VkPeerMemoryFeatureFlags* pPeerMemoryFeatures) {
  Device* dev = fromHandleUnchecked<Device>(device);
  *pPeerMemoryFeatures = 0;
  // VUID-vkGetDeviceGroupPeerMemoryFeatures-heapIndex-00691, -localDeviceIndex-00692, -remoteDeviceIndex-00693,
  // -localDeviceIndex-00694
  const char* vuid = heapIndex >= dev->physicalDevice->memoryProperties.memoryHeapCount
                         ? "VUID-vkGetDeviceGroupPeerMemoryFeatures-heapIndex-00691"
                     : localDeviceIndex != 0  ? "VUID-vkGetDeviceGroupPeerMemoryFeatures-localDeviceIndex-00692"
                     : remoteDeviceIndex != 0 ? "VUID-vkGetDeviceGroupPeerMemoryFeatures-remoteDeviceIndex-00693"
                                              : "VUID-vkGetDeviceGroupPeerMemoryFeatures-localDeviceIndex-00694";
  report(dev, Severity::Error, vuid,
         "vkGetDeviceGroupPeerMemoryFeatures: heapIndex %u, localDeviceIndex %u, remoteDeviceIndex %u: vkrt's device "
         "group has one device (index 0) and one heap, so there is no peer to ask about",
         heapIndex, localDeviceIndex, remoteDeviceIndex);
}

VKAPI_ATTR void VKAPI_CALL vkrt_FreeMemory(VkDevice device, VkDeviceMemory memory,
                                           const VkAllocationCallbacks* pAllocator) {
  destroyDeviceChildWhenIdle<Memory>(device, memory, pAllocator, "vkFreeMemory", "VUID-vkFreeMemory-memory-parameter",
                                     "VUID-vkFreeMemory-memory-00677");
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_MapMemory(VkDevice device, VkDeviceMemory memory, VkDeviceSize offset,
                                              VkDeviceSize size, VkMemoryMapFlags, void** ppData) {
  Memory* mem = fromHandle<Memory>(memory);
  if (!mem) {
    report(fromHandle<Device>(device), Severity::Error, "VUID-vkMapMemory-memory-parameter",
           "vkMapMemory: 0x%llx is not a live VkDeviceMemory", (unsigned long long)rawHandle(memory));
    return VK_ERROR_MEMORY_MAP_FAILED;
  }
  if (mem->mapped) {
    report(mem, Severity::Error, "VUID-vkMapMemory-memory-00678", "vkMapMemory: memory is already mapped");
    return VK_ERROR_MEMORY_MAP_FAILED;
  }
  if (offset >= mem->size) {
    report(mem, Severity::Error, "VUID-vkMapMemory-offset-00679",
           "vkMapMemory: offset %llu is not less than the allocation size %llu", (unsigned long long)offset,
           (unsigned long long)mem->size);
    return VK_ERROR_MEMORY_MAP_FAILED;
  }
  if (size != VK_WHOLE_SIZE && (size == 0 || size > mem->size - offset)) {
    report(mem, Severity::Error, "VUID-vkMapMemory-size-00681",
           "vkMapMemory: size %llu at offset %llu exceeds the allocation size %llu", (unsigned long long)size,
           (unsigned long long)offset, (unsigned long long)mem->size);
    return VK_ERROR_MEMORY_MAP_FAILED;
  }
  mem->mapped = true;
  mem->mappedOffset = offset;
  mem->mappedSize = size == VK_WHOLE_SIZE ? mem->size - offset : size;
  *ppData = mem->base + offset;
  return VK_SUCCESS;
}

VKAPI_ATTR void VKAPI_CALL vkrt_UnmapMemory(VkDevice device, VkDeviceMemory memory) {
  Memory* mem = fromHandle<Memory>(memory);
  if (!mem || !mem->mapped) {
    report(mem ? static_cast<Object*>(mem) : fromHandle<Device>(device), Severity::Error,
           "VUID-vkUnmapMemory-memory-00689", "vkUnmapMemory: memory 0x%llx is not mapped",
           (unsigned long long)rawHandle(memory));
    return;
  }
  mem->mapped = false;
}

static VkResult checkRanges(const char* fn, Device* dev, uint32_t count, const VkMappedMemoryRange* ranges) {
  for (uint32_t i = 0; i < count; ++i) {
    Memory* mem = fromHandle<Memory>(ranges[i].memory);
    if (!mem || !mem->mapped) {
      report(mem ? static_cast<Object*>(mem) : dev, Severity::Error, "VUID-VkMappedMemoryRange-memory-00684",
             "%s: pMemoryRanges[%u].memory is not currently mapped", fn, i);
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
    const VkDeviceSize mapEnd = mem->mappedOffset + mem->mappedSize;
    if (ranges[i].size == VK_WHOLE_SIZE) {
      // VUID-VkMappedMemoryRange-size-00686: offset within the mapped range
      if (ranges[i].offset < mem->mappedOffset || ranges[i].offset >= mapEnd) {
        report(mem, Severity::Error, "VUID-VkMappedMemoryRange-size-00686",
               "%s: pMemoryRanges[%u].offset %llu is outside the mapped range [%llu, %llu)", fn, i,
               (unsigned long long)ranges[i].offset, (unsigned long long)mem->mappedOffset, (unsigned long long)mapEnd);
        return VK_ERROR_VALIDATION_FAILED_EXT;
      }
    } else if (ranges[i].offset < mem->mappedOffset || ranges[i].size > mapEnd - mem->mappedOffset ||
               ranges[i].offset - mem->mappedOffset > mapEnd - mem->mappedOffset - ranges[i].size) {
      // VUID-VkMappedMemoryRange-size-00685: [offset, offset + size) within the mapped range
      report(mem, Severity::Error, "VUID-VkMappedMemoryRange-size-00685",
             "%s: pMemoryRanges[%u] [%llu, +%llu) is outside the mapped range [%llu, %llu)", fn, i,
             (unsigned long long)ranges[i].offset, (unsigned long long)ranges[i].size,
             (unsigned long long)mem->mappedOffset, (unsigned long long)mapEnd);
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
  }
  return VK_SUCCESS;  // memory is coherent: nothing to flush or invalidate
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_FlushMappedMemoryRanges(VkDevice device, uint32_t count,
                                                            const VkMappedMemoryRange* pMemoryRanges) {
  return checkRanges("vkFlushMappedMemoryRanges", fromHandleUnchecked<Device>(device), count, pMemoryRanges);
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_InvalidateMappedMemoryRanges(VkDevice device, uint32_t count,
                                                                 const VkMappedMemoryRange* pMemoryRanges) {
  return checkRanges("vkInvalidateMappedMemoryRanges", fromHandleUnchecked<Device>(device), count, pMemoryRanges);
}

VKAPI_ATTR void VKAPI_CALL vkrt_GetDeviceMemoryCommitment(VkDevice, VkDeviceMemory memory,
                                                          VkDeviceSize* pCommittedMemoryInBytes) {
  Memory* mem = fromHandle<Memory>(memory);
  *pCommittedMemoryInBytes = mem ? mem->size : 0;
}

VKAPI_ATTR uint64_t VKAPI_CALL
vkrt_GetDeviceMemoryOpaqueCaptureAddress(VkDevice device, const VkDeviceMemoryOpaqueCaptureAddressInfo* pInfo) {
  Memory* mem = fromHandle<Memory>(pInfo->memory);
  if (!mem) {
    report(fromHandle<Device>(device), Severity::Error, "VUID-VkDeviceMemoryOpaqueCaptureAddressInfo-memory-parameter",
           "vkGetDeviceMemoryOpaqueCaptureAddress: 0x%llx is not a live VkDeviceMemory",
           (unsigned long long)rawHandle(pInfo->memory));
    return 0;
  }
  return reinterpret_cast<uint64_t>(mem->base);
}

}  // extern "C"
