// VkAccelerationStructureNV (VK_NV_ray_tracing): the same acceleration structure as VkAccelerationStructureKHR
// (runtime/acceleration_structure.hpp, built on src/accel), created from a VkAccelerationStructureInfoNV and bound to
// memory by vkBindAccelerationStructureMemoryNV instead of a buffer range. Its address (memory + offset) is what
// vkGetAccelerationStructureHandleNV returns (the 8 bytes instance data refers to a bottom level by) and what the
// device's registry knows it by, so NV and KHR top levels resolve NV bottom levels the same way. Builds, copies and
// property queries translate their NV parameters into the KHR commands' inputs (acceleration_structure_nv.cpp).
#pragma once

#include <vector>

#include "runtime/acceleration_structure.hpp"

namespace vkrt {

class Memory;

class AccelerationStructureNV : public AccelerationStructure {
 public:
  using Handle = VkAccelerationStructureNV;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_NV;

  // `size` is what vkGetAccelerationStructureMemoryRequirementsNV reports for the object.
  AccelerationStructureNV(Device* dev, const VkAccelerationStructureCreateInfoNV& info, VkDeviceSize size);

  // The VkAccelerationStructureInfoNV it was created with (geometries copied, their pNext cleared), for the build
  // rules (VUID-vkCmdBuildAccelerationStructureNV-dst-02488).
  const VkAccelerationStructureTypeNV infoType;
  const VkBuildAccelerationStructureFlagsNV infoFlags;
  const uint32_t instanceCount;
  std::vector<VkGeometryNV> geometries;
  const VkDeviceSize compactedSize;

  Memory* memory = nullptr;  // set once by vkBindAccelerationStructureMemoryNV
  void bind(Memory* mem, VkDeviceSize offset);
};

// The primitives (triangles, boxes or instances) a VkAccelerationStructureInfoNV describes.
uint64_t primitiveCountNV(const VkAccelerationStructureInfoNV& info);

}  // namespace vkrt
