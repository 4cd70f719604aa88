#include "runtime/buffer.hpp"

#include <mutex>
#include <unordered_set>

#include "abi/shader_debug.hpp"
#include "runtime/alloc.hpp"
#include "runtime/device.hpp"
#include "runtime/lookup.hpp"
#include "runtime/memory.hpp"
#include "runtime/physical_device.hpp"
#include "runtime/report.hpp"
#include "spirv/shader_debug.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {

namespace {

// The buffer's usage: VkBufferCreateInfo::usage, or (where an application chains it) the low 32 bits of
// VkBufferUsageFlags2CreateInfoKHR::usage, which the specification has take precedence.
VkBufferUsageFlags usageOf(const VkBufferCreateInfo& info) {
  if (auto* u2 = findInChain<VkBufferUsageFlags2CreateInfoKHR>(info.pNext,
                                                               VK_STRUCTURE_TYPE_BUFFER_USAGE_FLAGS_2_CREATE_INFO_KHR))
    return VkBufferUsageFlags(u2->usage & 0xffffffffu);
  return info.usage;
}

// The buffers in the device address table (VKRT_SHADER_CHECKS=bda): listed at bind, removed when destroyed.
std::mutex addressMutex;
std::unordered_set<const Buffer*>& addressBuffers() {
  static std::unordered_set<const Buffer*> set;
  return set;
}

void listAddress(Buffer* buf) {
  if (!(spirv::shaderChecks() & abi::kCheckDeviceAddress) || !(buf->usage & VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT))
    return;
  std::lock_guard lock(addressMutex);
  addressBuffers().insert(buf);
  buf->addressListed = true;
}

}  // namespace

void deviceAddressRanges(const void* owner, std::vector<exec::AddressRange>* out) {
  std::lock_guard lock(addressMutex);
  for (const Buffer* b : addressBuffers()) {
    if (b->device != owner) continue;
    const uint64_t begin = reinterpret_cast<uint64_t>(b->deviceAddress());
    // Memory freed under a bound buffer leaves the buffer unusable ("vkFreeMemory"): not in the table.
    if (!arena::accessible(begin, b->size)) continue;
    out->push_back({begin, begin + b->size, b->handleValue(), 0});
  }
}

bool withAddressBuffer(uint64_t handle, const std::function<void(const Buffer&)>& fn) {
  std::lock_guard lock(addressMutex);
  for (const Buffer* b : addressBuffers())
    if (b->handleValue() == handle) {
      fn(*b);
      return true;
    }
  return false;
}

Buffer::Buffer(Device* dev, const VkBufferCreateInfo& info)
    : Object(kType, dev->instance, dev), size(info.size), usage(usageOf(info)), flags(info.flags) {
  if (auto* c = findInChain<VkBufferOpaqueCaptureAddressCreateInfo>(
          info.pNext, VK_STRUCTURE_TYPE_BUFFER_OPAQUE_CAPTURE_ADDRESS_CREATE_INFO))
    requestedCaptureAddress = c->opaqueCaptureAddress;
}

Buffer::~Buffer() {
  if (addressListed) {
    std::lock_guard lock(addressMutex);
    addressBuffers().erase(this);
  }
  if (alias) arena::unalias(alias, size);
}

uint8_t* Buffer::data() const { return memory ? memory->base + memoryOffset : nullptr; }

VkDeviceSize Buffer::rangeFrom(VkDeviceSize offset, VkDeviceSize range) const {
  if (offset > size) return 0;
  if (range == VK_WHOLE_SIZE) return size - offset;
  return range <= size - offset ? range : 0;
}

}  // namespace vkrt

using namespace vkrt;

namespace {

VkResult bindBuffer(Device* dev, const VkBindBufferMemoryInfo& info, uint32_t index) {
  Buffer* buf = fromHandle<Buffer>(info.buffer);
  Memory* mem = fromHandle<Memory>(info.memory);
  if (!buf || !mem) {
    report(dev, Severity::Error, "VUID-VkBindBufferMemoryInfo-buffer-parameter",
           "vkBindBufferMemory: bind %u names a buffer 0x%llx or memory 0x%llx that is not live", index,
           (unsigned long long)rawHandle(info.buffer), (unsigned long long)rawHandle(info.memory));
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  if (buf->memory) {
    report(buf, Severity::Error, "VUID-VkBindBufferMemoryInfo-buffer-01029", "vkBindBufferMemory: already bound");
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  if (info.memoryOffset >= mem->size || info.memoryOffset % Buffer::kAlignment ||
      buf->size > mem->size - info.memoryOffset) {
    report(buf, Severity::Error, "VUID-VkBindBufferMemoryInfo-size-01037",
           "vkBindBufferMemory: %llu bytes at memoryOffset %llu do not fit the %llu-byte memory (alignment %llu)",
           (unsigned long long)buf->size, (unsigned long long)info.memoryOffset, (unsigned long long)mem->size,
           (unsigned long long)Buffer::kAlignment);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // A buffer's device address is the host address of its bytes, normally where its memory lies. A capture/replay
  // buffer ("Buffer Device Address Capture and Replay": a replayed buffer gets the device address it was captured
  // with) whose memory is not where its address must be gets a second mapping of those bytes: at its requested
  // address on replay, or, captured on ordinary memory (not DEVICE_ADDRESS_CAPTURE_REPLAY, so placed bottom-up
  // among the allocations a replay makes before it), in the top-down range of capture/replay memory, where the
  // replay finds it free.
  uint8_t* const host = mem->base + info.memoryOffset;
  const uint64_t requested = buf->requestedCaptureAddress;
  uint8_t* alias = nullptr;
  if (buf->flags & VK_BUFFER_CREATE_DEVICE_ADDRESS_CAPTURE_REPLAY_BIT) {
    if (requested && requested != reinterpret_cast<uint64_t>(host)) {
      alias = arena::alias(host, buf->size, requested);
    } else if (!requested && !(mem->allocateFlags & VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_CAPTURE_REPLAY_BIT)) {
      alias = arena::alias(host, buf->size, 0);  // none: the address is where the memory lies, as for any buffer
    }
  }
  if (requested && !alias && reinterpret_cast<uint64_t>(host) != requested) {
    report(buf, Severity::Error, nullptr,
           "vkBindBufferMemory: the buffer was created with opaque capture address 0x%llx but this binding gives "
           "it address 0x%llx, and the bytes cannot be mapped at 0x%llx (%s)",
           (unsigned long long)requested, (unsigned long long)reinterpret_cast<uint64_t>(host),
           (unsigned long long)requested,
           (buf->flags & VK_BUFFER_CREATE_DEVICE_ADDRESS_CAPTURE_REPLAY_BIT)
               ? requested % 4096 != reinterpret_cast<uint64_t>(host) % 4096
                     ? "its offset within a 4096-byte page differs from the binding's"
                     : arena::whyUnavailable(requested, buf->size).c_str()
               : "the buffer lacks VK_BUFFER_CREATE_DEVICE_ADDRESS_CAPTURE_REPLAY_BIT");
    return VK_ERROR_INVALID_OPAQUE_CAPTURE_ADDRESS;
  }
  buf->memory = mem;
  buf->memoryOffset = info.memoryOffset;
  buf->alias = alias;
  listAddress(buf);
  return VK_SUCCESS;
}

}  // namespace

extern "C" {

VKAPI_ATTR VkResult VKAPI_CALL vkrt_CreateBuffer(VkDevice device, const VkBufferCreateInfo* pCreateInfo,
                                                 const VkAllocationCallbacks* pAllocator, VkBuffer* pBuffer) {
  Device* dev = fromHandleUnchecked<Device>(device);
  if (pCreateInfo->size == 0) {
    report(dev, Severity::Error, "VUID-VkBufferCreateInfo-size-00912", "vkCreateBuffer: size must be greater than 0");
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  if (pCreateInfo->size > dev->physicalDevice->properties13.maxBufferSize) {
    report(dev, Severity::Error, "VUID-VkBufferCreateInfo-size-06409",
           "vkCreateBuffer: size %llu exceeds maxBufferSize %llu", (unsigned long long)pCreateInfo->size,
           (unsigned long long)dev->physicalDevice->properties13.maxBufferSize);
    return VK_ERROR_OUT_OF_DEVICE_MEMORY;
  }
  Buffer* buf = createObject<Buffer>(pAllocator, VK_SYSTEM_ALLOCATION_SCOPE_OBJECT, dev, *pCreateInfo);
  if (!buf) return VK_ERROR_OUT_OF_HOST_MEMORY;
  *pBuffer = toHandle(buf);
  return VK_SUCCESS;
}

VKAPI_ATTR void VKAPI_CALL vkrt_DestroyBuffer(VkDevice device, VkBuffer buffer,
                                              const VkAllocationCallbacks* pAllocator) {
  destroyDeviceChildWhenIdle<Buffer>(device, buffer, pAllocator, "vkDestroyBuffer",
                                     "VUID-vkDestroyBuffer-buffer-parameter", "VUID-vkDestroyBuffer-buffer-00922");
}

VKAPI_ATTR void VKAPI_CALL vkrt_GetBufferMemoryRequirements(VkDevice, VkBuffer buffer,
                                                            VkMemoryRequirements* pMemoryRequirements) {
  Buffer* buf = fromHandleUnchecked<Buffer>(buffer);
  pMemoryRequirements->size = (buf->size + Buffer::kAlignment - 1) / Buffer::kAlignment * Buffer::kAlignment;
  pMemoryRequirements->alignment = Buffer::kAlignment;
  pMemoryRequirements->memoryTypeBits = 1;
}

VKAPI_ATTR void VKAPI_CALL vkrt_GetBufferMemoryRequirements2(VkDevice device,
                                                             const VkBufferMemoryRequirementsInfo2* pInfo,
                                                             VkMemoryRequirements2* pMemoryRequirements) {
  vkrt_GetBufferMemoryRequirements(device, pInfo->buffer, &pMemoryRequirements->memoryRequirements);
  for (auto* s = static_cast<VkBaseOutStructure*>(pMemoryRequirements->pNext); s; s = s->pNext) {
    if (s->sType == VK_STRUCTURE_TYPE_MEMORY_DEDICATED_REQUIREMENTS) {
      auto* d = reinterpret_cast<VkMemoryDedicatedRequirements*>(s);
      d->prefersDedicatedAllocation = VK_FALSE;
      d->requiresDedicatedAllocation = VK_FALSE;
    }
  }
}

VKAPI_ATTR void VKAPI_CALL vkrt_GetDeviceBufferMemoryRequirements(VkDevice,
                                                                  const VkDeviceBufferMemoryRequirements* pInfo,
                                                                  VkMemoryRequirements2* pMemoryRequirements) {
  VkDeviceSize size = pInfo->pCreateInfo->size;
  pMemoryRequirements->memoryRequirements = {(size + Buffer::kAlignment - 1) / Buffer::kAlignment * Buffer::kAlignment,
                                             Buffer::kAlignment, 1};
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_BindBufferMemory(VkDevice device, VkBuffer buffer, VkDeviceMemory memory,
                                                     VkDeviceSize memoryOffset) {
  VkBindBufferMemoryInfo info{VK_STRUCTURE_TYPE_BIND_BUFFER_MEMORY_INFO, nullptr, buffer, memory, memoryOffset};
  return bindBuffer(fromHandleUnchecked<Device>(device), info, 0);
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_BindBufferMemory2(VkDevice device, uint32_t bindInfoCount,
                                                      const VkBindBufferMemoryInfo* pBindInfos) {
  Device* dev = fromHandleUnchecked<Device>(device);
  for (uint32_t i = 0; i < bindInfoCount; ++i) {
    VkResult r = bindBuffer(dev, pBindInfos[i], i);
    if (r != VK_SUCCESS) return r;
  }
  return VK_SUCCESS;
}

VKAPI_ATTR VkDeviceAddress VKAPI_CALL vkrt_GetBufferDeviceAddress(VkDevice device,
                                                                  const VkBufferDeviceAddressInfo* pInfo) {
  Buffer* buf = fromHandle<Buffer>(pInfo->buffer);
  if (!buf || !buf->memory) {
    report(buf ? static_cast<Object*>(buf) : fromHandle<Device>(device), Severity::Error,
           "VUID-VkBufferDeviceAddressInfo-buffer-02600",
           "vkGetBufferDeviceAddress: buffer 0x%llx is not live or not bound to memory",
           (unsigned long long)rawHandle(pInfo->buffer));
    return 0;
  }
  if (!(buf->usage & VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT)) {
    report(buf, Severity::Error, "VUID-VkBufferDeviceAddressInfo-buffer-02601",
           "vkGetBufferDeviceAddress: buffer was not created with VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT");
    return 0;
  }
  return reinterpret_cast<VkDeviceAddress>(buf->deviceAddress());
}

VKAPI_ATTR uint64_t VKAPI_CALL vkrt_GetBufferOpaqueCaptureAddress(VkDevice device,
                                                                  const VkBufferDeviceAddressInfo* pInfo) {
  Buffer* buf = fromHandle<Buffer>(pInfo->buffer);
  if (!buf || !buf->memory) {
    report(buf ? static_cast<Object*>(buf) : fromHandle<Device>(device), Severity::Error,
           "VUID-VkBufferDeviceAddressInfo-buffer-02600",
           "vkGetBufferOpaqueCaptureAddress: buffer 0x%llx is not live or not bound to memory",
           (unsigned long long)rawHandle(pInfo->buffer));
    return 0;
  }
  return reinterpret_cast<uint64_t>(buf->deviceAddress());
}

}  // extern "C"
