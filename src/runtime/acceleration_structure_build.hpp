// Acceleration structure builds (vkCmdBuildAccelerationStructuresKHR, ...IndirectKHR,
// vkBuildAccelerationStructuresKHR): what a build info is copied into when the command is recorded, and the conversion
// of the application's geometry (read from device or host memory when the build runs) into accel's inputs.
#pragma once

#include <string>
#include <vector>

#include "accel/accel.hpp"
#include "runtime/acceleration_structure.hpp"

namespace vkrt {

// One VkAccelerationStructureBuildGeometryInfoKHR with its ranges, copied out of the application's arrays.
struct BuildJob {
  VkAccelerationStructureTypeKHR type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
  VkBuildAccelerationStructureFlagsKHR flags = 0;
  VkBuildAccelerationStructureModeKHR mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
  AccelerationStructure* dst = nullptr;
  AccelerationStructure* src = nullptr;
  std::vector<VkAccelerationStructureGeometryKHR> geometries;    // pNext cleared
  std::vector<VkAccelerationStructureBuildRangeInfoKHR> ranges;  // one per geometry (indirect builds: read later)
  bool host = false;   // addresses are host pointers; instance references are VkAccelerationStructureKHR handles
  uint32_t index = 0;  // in pInfos, for reports
};

// A rule a build broke, found when its inputs were read.
struct BuildError {
  const char* vuid = nullptr;
  std::string message;
};

// Reads the job's inputs and builds; on success the destination holds the new content. `dev` resolves instance
// references. Returns false with `error` set (the destination is unchanged).
bool runBuild(Device* dev, const BuildJob& job, BuildError* error);

// The checks that need no memory contents: handles, types, modes, addresses' alignment, update preconditions
// that are known from the source's last build, the destination's size. Reports against `about` (naming `fn`
// and pInfos[job.index]) and returns false.
bool checkBuild(const Object* about, const char* fn, const BuildJob& job, const Device* dev);

// Copies pInfos[i] (with its ranges, or none for indirect builds) into a job; reports and returns false for a
// destination or source handle that is not a live acceleration structure.
bool makeJob(const Object* about, const char* fn, uint32_t i, const VkAccelerationStructureBuildGeometryInfoKHR& info,
             const VkAccelerationStructureBuildRangeInfoKHR* ranges, bool host, BuildJob* job);

// Whether `format` can be a triangle geometry's vertex format, and its decoding to three floats (a missing z is 0).
bool accelerationStructureVertexFormat(VkFormat format);
// The size of one component of a vertex format builds accept (the unit vertexStride must be a multiple of), and
// the bytes of a vertex that are read (x, y and z).
uint32_t vertexComponentBytes(VkFormat format);
uint32_t vertexReadBytes(VkFormat format);
void decodeVertex(VkFormat format, const uint8_t* p, float out[3]);

}  // namespace vkrt
