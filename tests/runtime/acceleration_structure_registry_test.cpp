// The device's registry of acceleration structures by address, and the view of it a launch's table of top levels is
// made from (snapshotTopLevels): every structure that may hold a top level, none of the bottom levels.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "runtime/acceleration_structure.hpp"
#include "runtime/alloc.hpp"
#include "runtime/buffer.hpp"
#include "runtime/device.hpp"
#include "runtime/instance.hpp"
#include "runtime/physical_device.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {
namespace {

class AccelerationStructureRegistry : public ::testing::Test {
 protected:
  void SetUp() override {
    VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    ASSERT_EQ(vkrt_CreateInstance(&ici, nullptr, &instance), VK_SUCCESS);
    uint32_t n = 1;
    ASSERT_EQ(vkrt_EnumeratePhysicalDevices(instance, &n, &pd), VK_SUCCESS);
    const char* exts[] = {VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME};
    VkPhysicalDeviceAccelerationStructureFeaturesKHR fas{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR};
    fas.accelerationStructure = VK_TRUE;
    VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, &fas};
    dci.enabledExtensionCount = 1;
    dci.ppEnabledExtensionNames = exts;
    dev = createObject<Device>(nullptr, VK_SYSTEM_ALLOCATION_SCOPE_DEVICE, fromHandle<PhysicalDevice>(pd), dci);
    ASSERT_NE(dev, nullptr);
    device = toHandle(dev);
    VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    bci.size = kStructures * kSize;
    bci.usage = VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR;
    ASSERT_EQ(vkrt_CreateBuffer(device, &bci, nullptr, &buffer), VK_SUCCESS);
    VkMemoryRequirements req;
    vkrt_GetBufferMemoryRequirements(device, buffer, &req);
    VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    mai.allocationSize = req.size;
    ASSERT_EQ(vkrt_AllocateMemory(device, &mai, nullptr, &memory), VK_SUCCESS);
    ASSERT_EQ(vkrt_BindBufferMemory(device, buffer, memory, 0), VK_SUCCESS);
  }
  void TearDown() override {
    for (VkAccelerationStructureKHR h : structures) vkrt_DestroyAccelerationStructureKHR(device, h, nullptr);
    vkrt_DestroyBuffer(device, buffer, nullptr);
    vkrt_FreeMemory(device, memory, nullptr);
    destroyObject(dev, nullptr);
    vkrt_DestroyInstance(instance, nullptr);
  }

  // A structure of `type` at slot `slot` of the buffer.
  AccelerationStructure* make(VkAccelerationStructureTypeKHR type, uint32_t slot) {
    VkAccelerationStructureCreateInfoKHR aci{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
    aci.buffer = buffer;
    aci.offset = VkDeviceSize(slot) * kSize;
    aci.size = kSize;
    aci.type = type;
    VkAccelerationStructureKHR h = VK_NULL_HANDLE;
    EXPECT_EQ(vkrt_CreateAccelerationStructureKHR(device, &aci, nullptr, &h), VK_SUCCESS);
    structures.push_back(h);
    return fromHandle<AccelerationStructure>(h);
  }
  void destroy(AccelerationStructure* as) {
    VkAccelerationStructureKHR h = toHandle(as);
    std::erase(structures, h);
    vkrt_DestroyAccelerationStructureKHR(device, h, nullptr);
  }
  uint64_t at(uint32_t slot) const {
    return reinterpret_cast<uint64_t>(fromHandle<Buffer>(buffer)->data()) + slot * kSize;
  }
  // The addresses the snapshot lists, and whether it found each one built.
  std::vector<std::pair<uint64_t, bool>> snapshot() {
    exec::TopLevelResolver::Snapshot s;
    snapshotTopLevels(dev, &s);
    std::vector<std::pair<uint64_t, bool>> out;
    for (const auto& [address, tlas] : s.structures) out.emplace_back(address, tlas != nullptr);
    return out;
  }

  static constexpr uint32_t kStructures = 2000;
  static constexpr VkDeviceSize kSize = 256;
  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice pd = VK_NULL_HANDLE;
  Device* dev = nullptr;
  VkDevice device = VK_NULL_HANDLE;
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  std::vector<VkAccelerationStructureKHR> structures;
};

using Listed = std::vector<std::pair<uint64_t, bool>>;

TEST_F(AccelerationStructureRegistry, TheTopLevelViewListsTopAndGenericStructuresOnly) {
  for (uint32_t i = 10; i < kStructures; ++i) make(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, i);
  make(VK_ACCELERATION_STRUCTURE_TYPE_GENERIC_KHR, 7);
  AccelerationStructure* top = make(VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, 3);
  EXPECT_EQ(snapshot(), (Listed{{at(3), false}, {at(7), false}}));
  EXPECT_EQ(dev->accelerationStructures.size(), kStructures - 10 + 2);
  EXPECT_EQ(dev->topLevelStructures.size(), 2u);
  // A built top level is listed with its content (an empty instance list builds).
  auto content = std::make_shared<AccelerationStructure::Content>();
  content->type = VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR;
  std::string error;
  content->tlas = accel::Tlas::build(std::vector<accel::Instance>{}, {}, &error);
  ASSERT_NE(content->tlas, nullptr) << error;
  content->blasGeneration = dev->blasGeneration.load();
  top->setContent(content);
  EXPECT_EQ(snapshot(), (Listed{{at(3), true}, {at(7), false}}));
  destroy(top);
  EXPECT_EQ(snapshot(), (Listed{{at(7), false}}));
}

TEST_F(AccelerationStructureRegistry, ABottomLevelBuiltOverATopLevelTakesItsAddressFromTheView) {
  AccelerationStructure* top = make(VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, 5);
  // Created over the live top level, a bottom level does not take the address (creation leaves the memory as it
  // was); built there, it does, and the address leaves the top-level view.
  AccelerationStructure* bottom = make(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, 5);
  EXPECT_EQ(accelerationStructureAt(dev, at(5)), top);
  EXPECT_EQ(snapshot(), (Listed{{at(5), false}}));
  bottom->setContent(std::make_shared<AccelerationStructure::Content>());
  EXPECT_EQ(accelerationStructureAt(dev, at(5)), bottom);
  EXPECT_EQ(snapshot(), Listed{});
  // The top level built there again takes it back; destroying the bottom level then leaves the entry alone.
  top->setContent(std::make_shared<AccelerationStructure::Content>());
  EXPECT_EQ(snapshot(), (Listed{{at(5), false}}));
  destroy(bottom);
  EXPECT_EQ(accelerationStructureAt(dev, at(5)), top);
  EXPECT_EQ(snapshot(), (Listed{{at(5), false}}));
  destroy(top);
  EXPECT_EQ(accelerationStructureAt(dev, at(5)), nullptr);
  EXPECT_EQ(snapshot(), Listed{});
  EXPECT_TRUE(dev->accelerationStructures.empty());
}

}  // namespace
}  // namespace vkrt
