// The object model and the generated entry-point table, tested without the loader.
#include <gtest/gtest.h>

#include <cstring>

#include "icd/entrypoint_table.hpp"
#include "runtime/alloc.hpp"
#include "runtime/buffer.hpp"
#include "runtime/object.hpp"

namespace vkrt {
namespace {

struct Thing : Object {
  using Handle = VkBuffer;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_BUFFER;
  Thing() : Object(kType, nullptr, nullptr) {}
};

TEST(ObjectModel, DispatchableObjectsStartWithTheLoaderMagic) {
  Thing t;
  EXPECT_TRUE(valid_loader_magic_value(&t));
  EXPECT_EQ(reinterpret_cast<void*>(&t), reinterpret_cast<void*>(&t.loaderData));
}

TEST(ObjectModel, HandlesRoundTripAndStaleHandlesAreRejected) {
  auto* t = new Thing;
  VkBuffer h = toHandle(t);
  EXPECT_EQ(fromHandle<Thing>(h), t);
  EXPECT_EQ(findObject(rawHandle(h), VK_OBJECT_TYPE_IMAGE), nullptr) << "wrong type is not found";
  delete t;
  EXPECT_EQ(fromHandle<Thing>(h), nullptr) << "a destroyed object is no longer found";
  EXPECT_EQ(fromHandle<Thing>(reinterpret_cast<VkBuffer>(uint64_t(0x1234))), nullptr);
  EXPECT_EQ(fromHandle<Thing>(VK_NULL_HANDLE), nullptr);
}

TEST(ObjectModel, DebugNamesAreKept) {
  Thing t;
  EXPECT_EQ(t.debugName(), "");
  t.setDebugName("sbt");
  EXPECT_EQ(t.debugName(), "sbt");
  t.setDebugName(nullptr);
  EXPECT_EQ(t.debugName(), "");
}

TEST(ObjectModel, AllocationCallbacksAreHonoured) {
  struct Counts {
    int allocs = 0, frees = 0;
  } counts;
  VkAllocationCallbacks cb{};
  cb.pUserData = &counts;
  cb.pfnAllocation = [](void* user, size_t size, size_t align, VkSystemAllocationScope) -> void* {
    static_cast<Counts*>(user)->allocs++;
    return std::aligned_alloc(align, (size + align - 1) / align * align);
  };
  cb.pfnFree = [](void* user, void* p) {
    if (p) static_cast<Counts*>(user)->frees++;
    std::free(p);
  };
  Thing* t = createObject<Thing>(&cb, VK_SYSTEM_ALLOCATION_SCOPE_OBJECT);
  ASSERT_NE(t, nullptr);
  EXPECT_EQ(counts.allocs, 1);
  destroyObject(t, &cb);
  EXPECT_EQ(counts.frees, 1);
}

TEST(PNext, FindInChainSkipsUnknownStructures) {
  VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
  flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
  struct Unknown {
    VkStructureType sType;
    const void* pNext;
  } unknown{static_cast<VkStructureType>(1000999000), &flags};
  auto* found = findInChain<VkMemoryAllocateFlagsInfo>(&unknown, VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO);
  EXPECT_EQ(found, &flags);
  EXPECT_EQ(findInChain<VkMemoryDedicatedAllocateInfo>(&unknown, VK_STRUCTURE_TYPE_MEMORY_DEDICATED_ALLOCATE_INFO),
            nullptr);
}

TEST(EntryPoints, TableIsSortedAndAliasesShareTheImplementation) {
  for (size_t i = 1; i < kEntryPointCount; ++i)
    ASSERT_LT(std::strcmp(kEntryPoints[i - 1].name, kEntryPoints[i].name), 0) << kEntryPoints[i].name;
  const EntryPoint* core = findEntryPoint("vkGetPhysicalDeviceFeatures2");
  const EntryPoint* khr = findEntryPoint("vkGetPhysicalDeviceFeatures2KHR");
  ASSERT_NE(core, nullptr);
  ASSERT_NE(khr, nullptr);
  EXPECT_NE(core->fn, nullptr);
  EXPECT_EQ(core->fn, khr->fn);
  EXPECT_EQ(core->level, EntryLevel::PhysicalDevice);
  EXPECT_EQ(findEntryPoint("vkCreateInstance")->level, EntryLevel::Global);
  EXPECT_EQ(findEntryPoint("vkCreateBuffer")->level, EntryLevel::Device);
  EXPECT_EQ(findEntryPoint("vkNotACommand"), nullptr);
}

TEST(EntryPoints, UnimplementedCommandsAreNull) {
  const EntryPoint* e = findEntryPoint("vkCmdDrawMeshTasksEXT");
  ASSERT_NE(e, nullptr);
  EXPECT_EQ(e->fn, nullptr);
}

}  // namespace
}  // namespace vkrt
