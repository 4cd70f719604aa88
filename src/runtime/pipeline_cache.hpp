// VkPipelineCache: a thread-safe key -> value store of compiled code.
//
// vkGetPipelineCacheData layout (all integers little-endian):
//   VkPipelineCacheHeaderVersionOne (32 bytes: headerSize = 32, headerVersion = 1, vendorID, deviceID,
//   pipelineCacheUUID of the physical device)
//   uint32 magic 'VKRC' (0x43524b56), uint32 entryCount
//   entryCount x { uint32 keySize, uint32 valueSize, key bytes, value bytes, zero padding to 4 bytes }
// Entries are written in key order, so the same contents always serialize to the same bytes.
#pragma once

#include <cstdint>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "runtime/object.hpp"

namespace vkrt {

class PhysicalDevice;

class PipelineCache : public Object {
 public:
  using Handle = VkPipelineCache;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_PIPELINE_CACHE;

  PipelineCache(Device* dev, VkPipelineCacheCreateFlags flags);

  const VkPipelineCacheCreateFlags flags;

  // Stores `value` under `key` unless the key is present already (the first value wins). Returns true when
  // stored.
  bool insert(const void* key, size_t keySize, const void* value, size_t valueSize);
  bool insert(const std::string& key, const std::string& value) {
    return insert(key.data(), key.size(), value.data(), value.size());
  }
  // Stores `value` under `key`, replacing what was there (a damaged entry once its replacement is compiled).
  void replace(const std::string& key, const std::string& value);
  // The value stored under `key`, if any.
  std::optional<std::string> lookup(const void* key, size_t keySize) const;
  std::optional<std::string> lookup(const std::string& key) const { return lookup(key.data(), key.size()); }
  size_t entryCount() const;

  // Loads serialized data. Returns false, leaving the cache as it was, when the header does not match this
  // device or the data is malformed.
  bool load(const void* data, size_t size);
  // Serializes into `out`; with `limit`, only the header and the whole entries that fit in `limit` bytes.
  // Returns the full size (what a complete serialization takes).
  size_t serialize(std::vector<uint8_t>& out, size_t limit = SIZE_MAX) const;
  // Adds every entry of `src` that this cache does not have.
  void merge(const PipelineCache& src);

  static constexpr uint32_t kMagic = 0x43524b56;  // "VKRC"

 private:
  void header(uint8_t out[32]) const;
  mutable std::mutex mutex_;
  std::map<std::string, std::string> entries_;
};

}  // namespace vkrt
