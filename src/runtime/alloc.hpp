// Creation and destruction of vkrt objects, honouring VkAllocationCallbacks where the application gives them.
#pragma once

#include <new>
#include <utility>

#include "runtime/vk.hpp"

namespace vkrt {

// Constructs a T in memory from `alloc` (or operator new when `alloc` is null). Returns nullptr when the
// allocation fails; a constructor that throws std::bad_alloc is also turned into nullptr.
template <class T, class... Args>
T* createObject(const VkAllocationCallbacks* alloc, VkSystemAllocationScope scope, Args&&... args) {
  void* mem = nullptr;
  if (alloc && alloc->pfnAllocation) {
    mem = alloc->pfnAllocation(alloc->pUserData, sizeof(T), alignof(T) < 16 ? 16 : alignof(T), scope);
  } else {
    mem = ::operator new(sizeof(T), std::align_val_t(alignof(T) < 16 ? 16 : alignof(T)), std::nothrow);
  }
  if (!mem) return nullptr;
  try {
    return new (mem) T(std::forward<Args>(args)...);
  } catch (const std::bad_alloc&) {
    if (alloc && alloc->pfnFree) {
      alloc->pfnFree(alloc->pUserData, mem);
    } else {
      ::operator delete(mem, std::align_val_t(alignof(T) < 16 ? 16 : alignof(T)));
    }
    return nullptr;
  }
}

template <class T>
void destroyObject(T* obj, const VkAllocationCallbacks* alloc) {
  if (!obj) return;
  obj->~T();
  if (alloc && alloc->pfnFree) {
    alloc->pfnFree(alloc->pUserData, obj);
  } else {
    ::operator delete(static_cast<void*>(obj), std::align_val_t(alignof(T) < 16 ? 16 : alignof(T)));
  }
}

// Walks a pNext chain for a structure of the given sType (const chains).
template <class T>
const T* findInChain(const void* pNext, VkStructureType sType) {
  for (auto* s = static_cast<const VkBaseInStructure*>(pNext); s; s = s->pNext) {
    if (s->sType == sType) return reinterpret_cast<const T*>(s);
  }
  return nullptr;
}

}  // namespace vkrt
