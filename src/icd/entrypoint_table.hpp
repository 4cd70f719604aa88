// The table of Vulkan commands, generated from vk.xml by tools/gen_entrypoints.py.
#pragma once

#include <cstddef>
#include <cstdint>

#include "runtime/vk.hpp"

namespace vkrt {

enum class EntryLevel : uint8_t { Global, Instance, PhysicalDevice, Device };

struct EntryPoint {
  const char* name;
  PFN_vkVoidFunction fn;  // NULL when vkrt does not implement the command
  EntryLevel level;
  // "VK_VERSION_1_x" or extension names that provide this name; "A+B" where A provides it only with B
  const char* const* providers;
  uint8_t providerCount;
};

extern const EntryPoint kEntryPoints[];  // sorted by name
extern const size_t kEntryPointCount;

// Binary search by name; nullptr when the name is not a Vulkan command.
const EntryPoint* findEntryPoint(const char* name);

}  // namespace vkrt
