// VkAccelerationStructureKHR (VK_KHR_acceleration_structure): a range of a buffer that holds a built structure.
//
// The built content lives in host memory that the object owns (an accel::Blas or accel::Tlas, shared): the bytes of
// the buffer range are not used, and their size only has to satisfy the application's bookkeeping
// (vkGetAccelerationStructureBuildSizesKHR reports a small figure: see requiredSize()). The device address of the
// structure is the buffer's address plus the offset; a top-level structure's instances refer to bottom-level ones
// by that address, resolved through the device's registry when the top level is built (never per ray).
//
// A build replaces the content atomically: a launch or build that already holds the previous content keeps it
// until it ends. A top-level structure keeps the bottom-level contents it was built from alive.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "accel/accel.hpp"
#include "exec/ray_query.hpp"
#include "runtime/object.hpp"

namespace vkrt {

class Buffer;

class AccelerationStructure : public Object {
 public:
  using Handle = VkAccelerationStructureKHR;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR;

  AccelerationStructure(Device* dev, const VkAccelerationStructureCreateInfoKHR& info, Buffer* buffer);
  ~AccelerationStructure();

  Buffer* const buffer;
  const VkDeviceSize offset;
  const VkDeviceSize size;
  const VkAccelerationStructureTypeKHR type;
  // The buffer's address + offset; 0 while the buffer is not bound (a structure may be created on an unbound
  // buffer and the buffer bound afterwards).
  uint64_t address() const;

  // What a build (or copy, or deserialization) produced.
  struct Content {
    VkAccelerationStructureTypeKHR type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
    VkBuildAccelerationStructureFlagsKHR flags = 0;
    std::shared_ptr<const accel::Blas> blas;
    std::shared_ptr<const accel::Tlas> tlas;
    std::vector<uint64_t> blasAddresses;  // top level: the reference each instance gave (0: inactive)
    // Top level: the device address of the structure each instance referred to (0: inactive), and the device's
    // bottom-level generation when the instances were resolved (see topLevelAt).
    std::vector<uint64_t> blasAt;
    uint64_t blasGeneration = 0;
    // Bottom level: the build's shape, for the update rules (per geometry: type, flags, primitive count, first
    // vertex, index type, vertex format).
    struct GeometryShape {
      VkGeometryTypeKHR type;
      VkGeometryFlagsKHR flags;
      uint32_t primitiveCount, firstVertex;
      VkIndexType indexType;
      VkFormat vertexFormat;
      bool hasTransform;
      bool operator==(const GeometryShape&) const = default;
    };
    std::vector<GeometryShape> shape;
    uint32_t instanceCount = 0;
  };
  std::shared_ptr<const Content> content() const;
  void setContent(std::shared_ptr<const Content> c);

  // The device's bottom-level generation at which the content's instances were last found current (topLevelAt),
  // so that a launch after an unrelated bottom-level build compares them once, not at every launch.
  std::atomic<uint64_t> checkedGeneration{0};

  // Enters the structure in the device's registry at its address (once the buffer is bound): as the structure
  // built there last when `built`, else only where nothing is registered yet.
  void registerAddress(bool built);

 protected:
  // A structure that owns its memory binding instead of a buffer range (VK_NV_ray_tracing's, of Vulkan object type
  // `objectType`): its address is what bindMemory gives it.
  AccelerationStructure(VkObjectType objectType, Device* dev, VkAccelerationStructureTypeKHR type, VkDeviceSize size);
  void bindMemory(uint8_t* base) {
    boundBase_ = base;
    registerAddress(false);
  }

 private:
  uint8_t* boundBase_ = nullptr;  // (buffer-less structures)
  mutable std::mutex mutex_;
  std::shared_ptr<const Content> content_;
  uint64_t registeredAt_ = 0;  // the address it was last registered at (guarded by the device's registry mutex)
};

// The live acceleration structure registered at `address` on `dev` (the last one built there, else the first
// created there), or null. The caller must not keep the pointer past the call that resolved it (use its content()).
AccelerationStructure* accelerationStructureAt(Device* dev, uint64_t address);
// The built top-level content at `address`, or null (nothing there, not built, or a bottom-level structure). A top
// level refers to its bottom-level structures ("takes a reference"): if one was built again since (an update in
// place, as an application animating a mesh does), the top level is rebuilt here over their current contents,
// once, and kept (a launch resolves each top level once).
std::shared_ptr<const accel::Tlas> topLevelAt(Device* dev, uint64_t address);

// What a dispatch's or launch's TopLevelResolver (exec/ray_query.hpp) takes on first use: the address of each of
// the device's structures that may hold a top level (any not created as bottom-level), in increasing order, each
// built top level whose bottom levels are current (topLevelAt's test, which holds for nearly every one) with its
// structure, under the one lock the snapshot takes anyway: a launch through many top levels makes no resolution
// of its own for them, and its threads do not queue for the resolver's and the device's locks to make one each
// (1,000 top levels cost a launch about 1.5 ms that way). The others (stale, not built, not there) are left to
// the resolver's resolve(), topLevelAt.
void snapshotTopLevels(Device* dev, exec::TopLevelResolver::Snapshot* out);

// Resolves the acceleration structure addresses of one dispatch's ray queries (exec/ray_query.hpp) on the device's
// structures; an address that is no built top-level structure is reported once per dispatch (naming `about` and
// `fn`), and those queries find nothing.
class DispatchStructures final : public exec::TopLevelResolver {
 public:
  DispatchStructures(Device* dev, const Object* about, const char* fn) : dev_(dev), about_(about), fn_(fn) {}

 protected:
  void snapshot(Snapshot* out) override { snapshotTopLevels(dev_, out); }
  std::shared_ptr<const accel::Tlas> resolve(uint64_t address) override { return topLevelAt(dev_, address); }
  void missed(uint64_t address) override;

 private:
  Device* dev_;
  const Object* about_;
  const char* fn_;
};

// The size an acceleration structure of `primitives` primitives (or instances) needs in its buffer, as
// vkGetAccelerationStructureBuildSizesKHR reports it, and the scratch size of builds and updates.
VkDeviceSize requiredSize(uint64_t primitives);
inline constexpr VkDeviceSize kScratchSize = 256;

// Converts a build's flags to accel's options.
accel::BuildOptions buildOptions(VkBuildAccelerationStructureFlagsKHR flags);

// The version data that identifies vkrt's serialized structures on `dev`: the driver UUID, then a compatibility
// UUID that changes with the serialization format (2 x VK_UUID_SIZE bytes).
void accelerationStructureVersion(const Device* dev, uint8_t out[2 * VK_UUID_SIZE]);

}  // namespace vkrt
