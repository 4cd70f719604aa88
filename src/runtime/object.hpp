// vkrt's object model: every Vulkan object is a C++ object deriving from vkrt::Object.
//
// A handle is the address of the object's Object base. For dispatchable handles the loader writes its
// dispatch pointer into the first word of that address, so Object keeps VK_LOADER_DATA as its first member
// and is not polymorphic (a derived class may be: handles always point at the Object base).
//
// Every live object is entered in a process-wide registry, so that a garbage or stale handle is detected
// (reported, with an error return) instead of dereferenced. Looking a handle up takes a shared lock; the
// per-ray and per-invocation paths never do it.
#pragma once

#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include "runtime/vk.hpp"

namespace vkrt {

class Instance;
class Device;

class Object {
 public:
  VK_LOADER_DATA loaderData;  // must stay the first member
  const VkObjectType objectType;
  Instance* instance = nullptr;  // for reports: where the debug messengers live
  Device* device = nullptr;      // the owning device, for device children

  Object(VkObjectType type, Instance* inst, Device* dev);
  ~Object();
  Object(const Object&) = delete;
  Object& operator=(const Object&) = delete;

  uint64_t handleValue() const { return reinterpret_cast<uint64_t>(this); }

  // Unique in the process and never reused: tells this object from a later one created at the same address.
  const uint64_t serial;

  // Takes the handle out of the registry (it is no longer live) while the object itself stays, for a destruction
  // deferred until pending work that uses it completes (runtime/deferred_destroy.hpp).
  void retire();

  // The name set with vkSetDebugUtilsObjectNameEXT (empty when none).
  std::string debugName() const;
  void setDebugName(const char* name);

 private:
  mutable std::mutex nameMutex_;
  std::string debugName_;
};

// Registry lookups. `find` returns the live object with that handle value and type, or nullptr.
Object* findObject(uint64_t handle, VkObjectType type);
// Any live object with that handle value, whatever its type (for vkSetDebugUtilsObjectNameEXT).
Object* findAnyObject(uint64_t handle);
size_t liveObjectCount();

// Lookups noted for a command being recorded (runtime/command_buffer.cpp): from beginNotingLookups() until
// takeNotedLookups() on the same thread, every object findObject returns is noted, so that a command buffer knows
// the objects its commands refer to without each command listing them.
void beginNotingLookups();
std::vector<Object*> takeNotedLookups();

template <class T>
uint64_t rawHandle(T h) {
  if constexpr (std::is_pointer_v<T>) {
    return reinterpret_cast<uint64_t>(h);
  } else {
    return static_cast<uint64_t>(h);
  }
}

// Handle -> object, checked against the registry. T declares `using Handle = VkXxx;` and
// `static constexpr VkObjectType kType`.
template <class T>
T* fromHandle(typename T::Handle h) {
  Object* o = findObject(rawHandle(h), T::kType);
  return o ? static_cast<T*>(o) : nullptr;
}

// Handle -> object without the registry check, for handles vkrt already validated or created itself.
template <class T>
T* fromHandleUnchecked(typename T::Handle h) {
  return static_cast<T*>(reinterpret_cast<Object*>(rawHandle(h)));
}

template <class T>
typename T::Handle toHandle(const T* obj) {
  const Object* base = obj;
  if constexpr (std::is_pointer_v<typename T::Handle>) {
    return reinterpret_cast<typename T::Handle>(const_cast<Object*>(base));
  } else {
    return reinterpret_cast<typename T::Handle>(reinterpret_cast<uint64_t>(base));
  }
}

const char* objectTypeName(VkObjectType type);

}  // namespace vkrt
