#include "runtime/pipeline_cache.hpp"

#include <cstring>

#include "runtime/alloc.hpp"
#include "runtime/device.hpp"
#include "runtime/physical_device.hpp"
#include "runtime/report.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {

namespace {
void put32(std::vector<uint8_t>& out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<uint8_t>(v >> (8 * i)));
}
uint32_t get32(const uint8_t* p) {
  return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}
size_t pad4(size_t n) { return (n + 3) & ~size_t(3); }
}  // namespace

PipelineCache::PipelineCache(Device* dev, VkPipelineCacheCreateFlags flags)
    : Object(kType, dev->instance, dev), flags(flags) {}

bool PipelineCache::insert(const void* key, size_t keySize, const void* value, size_t valueSize) {
  std::string k(static_cast<const char*>(key), keySize);
  std::lock_guard lock(mutex_);
  return entries_.emplace(std::move(k), std::string(static_cast<const char*>(value), valueSize)).second;
}

void PipelineCache::replace(const std::string& key, const std::string& value) {
  std::lock_guard lock(mutex_);
  entries_.insert_or_assign(key, value);
}

std::optional<std::string> PipelineCache::lookup(const void* key, size_t keySize) const {
  std::string k(static_cast<const char*>(key), keySize);
  std::lock_guard lock(mutex_);
  auto it = entries_.find(k);
  if (it == entries_.end()) return std::nullopt;
  return it->second;
}

size_t PipelineCache::entryCount() const {
  std::lock_guard lock(mutex_);
  return entries_.size();
}

void PipelineCache::header(uint8_t out[32]) const {
  const VkPhysicalDeviceProperties& p = device->physicalDevice->properties10;
  VkPipelineCacheHeaderVersionOne h{};
  h.headerSize = 32;
  h.headerVersion = VK_PIPELINE_CACHE_HEADER_VERSION_ONE;
  h.vendorID = p.vendorID;
  h.deviceID = p.deviceID;
  std::memcpy(h.pipelineCacheUUID, p.pipelineCacheUUID, VK_UUID_SIZE);
  static_assert(sizeof(h) == 32);
  std::memcpy(out, &h, 32);
}

bool PipelineCache::load(const void* data, size_t size) {
  auto* p = static_cast<const uint8_t*>(data);
  uint8_t expect[32];
  header(expect);
  if (size < 40 || std::memcmp(p, expect, 32) != 0 || get32(p + 32) != kMagic) return false;
  uint32_t count = get32(p + 36);
  std::map<std::string, std::string> loaded;
  size_t at = 40;
  for (uint32_t i = 0; i < count; ++i) {
    if (size - at < 8) return false;
    size_t k = get32(p + at), v = get32(p + at + 4);
    at += 8;
    if (k > size - at || v > size - at - k || pad4(k + v) > size - at) return false;
    loaded.emplace(std::string(reinterpret_cast<const char*>(p + at), k),
                   std::string(reinterpret_cast<const char*>(p + at + k), v));
    at += pad4(k + v);
  }
  if (at != size) return false;
  std::lock_guard lock(mutex_);
  for (auto& [k, v] : loaded) entries_.emplace(k, v);
  return true;
}

size_t PipelineCache::serialize(std::vector<uint8_t>& out, size_t limit) const {
  out.assign(32, 0);
  header(out.data());
  put32(out, kMagic);
  put32(out, 0);
  std::lock_guard lock(mutex_);
  size_t full = out.size();
  uint32_t written = 0;
  bool fits = true;
  for (auto& [k, v] : entries_) {
    size_t entry = 8 + pad4(k.size() + v.size());
    full += entry;
    if (!fits || out.size() + entry > limit) {
      fits = false;
      continue;
    }
    put32(out, static_cast<uint32_t>(k.size()));
    put32(out, static_cast<uint32_t>(v.size()));
    out.insert(out.end(), k.begin(), k.end());
    out.insert(out.end(), v.begin(), v.end());
    out.resize(out.size() + pad4(k.size() + v.size()) - (k.size() + v.size()), 0);
    ++written;
  }
  for (int i = 0; i < 4; ++i) out[36 + i] = static_cast<uint8_t>(written >> (8 * i));
  return full;
}

void PipelineCache::merge(const PipelineCache& src) {
  std::map<std::string, std::string> copy;
  {
    std::lock_guard lock(src.mutex_);
    copy = src.entries_;
  }
  std::lock_guard lock(mutex_);
  for (auto& [k, v] : copy) entries_.emplace(k, v);
}

}  // namespace vkrt

using namespace vkrt;

extern "C" {

VKAPI_ATTR VkResult VKAPI_CALL vkrt_CreatePipelineCache(VkDevice device, const VkPipelineCacheCreateInfo* pCreateInfo,
                                                        const VkAllocationCallbacks* pAllocator,
                                                        VkPipelineCache* pPipelineCache) {
  Device* dev = fromHandleUnchecked<Device>(device);
  // VUID-VkPipelineCacheCreateInfo-pipelineCreationCacheControl-02892
  if ((pCreateInfo->flags & VK_PIPELINE_CACHE_CREATE_EXTERNALLY_SYNCHRONIZED_BIT) &&
      !dev->enabled(Feature::pipelineCreationCacheControl)) {
    report(dev, Severity::Error, "VUID-VkPipelineCacheCreateInfo-pipelineCreationCacheControl-02892",
           "vkCreatePipelineCache: VK_PIPELINE_CACHE_CREATE_EXTERNALLY_SYNCHRONIZED_BIT needs the "
           "pipelineCreationCacheControl feature");
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  auto* cache = createObject<PipelineCache>(pAllocator, VK_SYSTEM_ALLOCATION_SCOPE_OBJECT, dev, pCreateInfo->flags);
  if (!cache) return VK_ERROR_OUT_OF_HOST_MEMORY;
  // Data from another device, driver version or a damaged file is ignored: the cache starts empty.
  if (pCreateInfo->initialDataSize && pCreateInfo->pInitialData &&
      !cache->load(pCreateInfo->pInitialData, pCreateInfo->initialDataSize))
    report(cache, Severity::Info, nullptr,
           "vkCreatePipelineCache: initial data (%zu bytes) is not a vkrt cache for this device; starting empty",
           pCreateInfo->initialDataSize);
  *pPipelineCache = toHandle(cache);
  return VK_SUCCESS;
}

VKAPI_ATTR void VKAPI_CALL vkrt_DestroyPipelineCache(VkDevice device, VkPipelineCache pipelineCache,
                                                     const VkAllocationCallbacks* pAllocator) {
  if (!pipelineCache) return;
  PipelineCache* c = fromHandle<PipelineCache>(pipelineCache);
  // VUID-vkDestroyPipelineCache-pipelineCache-parameter
  if (!c) {
    report(fromHandle<Device>(device), Severity::Error, "VUID-vkDestroyPipelineCache-pipelineCache-parameter",
           "vkDestroyPipelineCache: 0x%llx is not a live VkPipelineCache",
           (unsigned long long)rawHandle(pipelineCache));
    return;
  }
  destroyObject(c, pAllocator);
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_GetPipelineCacheData(VkDevice device, VkPipelineCache pipelineCache,
                                                         size_t* pDataSize, void* pData) {
  PipelineCache* c = fromHandle<PipelineCache>(pipelineCache);
  // VUID-vkGetPipelineCacheData-pipelineCache-parameter
  if (!c) {
    report(fromHandle<Device>(device), Severity::Error, "VUID-vkGetPipelineCacheData-pipelineCache-parameter",
           "vkGetPipelineCacheData: 0x%llx is not a live VkPipelineCache",
           (unsigned long long)rawHandle(pipelineCache));
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  std::vector<uint8_t> bytes;
  if (!pData) {
    *pDataSize = c->serialize(bytes);
    return VK_SUCCESS;
  }
  // Too small for the header: nothing is written and the size is 0. Otherwise the header and the whole
  // entries that fit (a valid cache by itself), with VK_INCOMPLETE when some were left out.
  if (*pDataSize < 40) {
    *pDataSize = 0;
    return VK_INCOMPLETE;
  }
  size_t full = c->serialize(bytes, *pDataSize);
  std::memcpy(pData, bytes.data(), bytes.size());
  *pDataSize = bytes.size();
  return bytes.size() < full ? VK_INCOMPLETE : VK_SUCCESS;
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_MergePipelineCaches(VkDevice device, VkPipelineCache dstCache,
                                                        uint32_t srcCacheCount, const VkPipelineCache* pSrcCaches) {
  Device* dev = fromHandleUnchecked<Device>(device);
  PipelineCache* dst = fromHandle<PipelineCache>(dstCache);
  // VUID-vkMergePipelineCaches-dstCache-parameter
  if (!dst) {
    report(dev, Severity::Error, "VUID-vkMergePipelineCaches-dstCache-parameter",
           "vkMergePipelineCaches: dstCache 0x%llx is not a live VkPipelineCache",
           (unsigned long long)rawHandle(dstCache));
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  for (uint32_t i = 0; i < srcCacheCount; ++i) {
    // VUID-vkMergePipelineCaches-dstCache-00770
    if (pSrcCaches[i] == dstCache) {
      report(dst, Severity::Error, "VUID-vkMergePipelineCaches-dstCache-00770",
             "vkMergePipelineCaches: pSrcCaches[%u] is dstCache itself", i);
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
    // VUID-vkMergePipelineCaches-pSrcCaches-parameter
    if (!fromHandle<PipelineCache>(pSrcCaches[i])) {
      report(dst, Severity::Error, "VUID-vkMergePipelineCaches-pSrcCaches-parameter",
             "vkMergePipelineCaches: pSrcCaches[%u] (0x%llx) is not a live VkPipelineCache", i,
             (unsigned long long)rawHandle(pSrcCaches[i]));
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
  }
  for (uint32_t i = 0; i < srcCacheCount; ++i) dst->merge(*fromHandleUnchecked<PipelineCache>(pSrcCaches[i]));
  return VK_SUCCESS;
}

}  // extern "C"
