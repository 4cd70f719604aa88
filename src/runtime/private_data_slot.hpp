// VkPrivateDataSlot (Vulkan 1.3, VK_EXT_private_data): a 64-bit value the application attaches to any object of
// the device (the device included) and reads back.
//
// Values are kept by the object's serial (runtime/object.hpp), not by its handle: a handle value comes back when
// an object is destroyed and another created at the same address, and the new object has no value (reads 0).
#pragma once

#include <mutex>
#include <unordered_map>

#include "runtime/object.hpp"

namespace vkrt {

class PrivateDataSlot : public Object {
 public:
  using Handle = VkPrivateDataSlot;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_PRIVATE_DATA_SLOT;

  explicit PrivateDataSlot(Device* dev);

  void set(const Object& object, uint64_t value);
  uint64_t get(const Object& object) const;  // 0 where nothing was set

 private:
  mutable std::mutex mutex_;
  std::unordered_map<uint64_t, uint64_t> values_;  // object serial -> value
};

}  // namespace vkrt
