// Descriptor storage, pipeline layouts and pipeline caches, tested below the loader: these tests look at the
// records compiled shaders will read (runtime/descriptor_set_layout.hpp documents their layout).
#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "runtime/acceleration_structure.hpp"
#include "runtime/alloc.hpp"
#include "runtime/buffer.hpp"
#include "runtime/descriptor_set.hpp"
#include "runtime/descriptor_set_layout.hpp"
#include "runtime/device.hpp"
#include "runtime/image.hpp"
#include "runtime/image_view.hpp"
#include "runtime/instance.hpp"
#include "runtime/physical_device.hpp"
#include "runtime/pipeline_cache.hpp"
#include "runtime/pipeline_layout.hpp"
#include "runtime/query_pool.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {
namespace {

class DescriptorStorage : public ::testing::Test {
 protected:
  void SetUp() override {
    VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    ASSERT_EQ(vkrt_CreateInstance(&ici, nullptr, &instance), VK_SUCCESS);
    uint32_t n = 1;
    ASSERT_EQ(vkrt_EnumeratePhysicalDevices(instance, &n, &pd), VK_SUCCESS);
    // Built directly (not with vkCreateDevice) so that VK_KHR_acceleration_structure can be "enabled" before
    // vkrt advertises it: the descriptor storage for it exists already.
    const char* exts[] = {VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME};
    VkPhysicalDeviceAccelerationStructureFeaturesKHR fas{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR};
    fas.accelerationStructure = VK_TRUE;
    VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES, &fas};
    f12.descriptorBindingPartiallyBound = VK_TRUE;
    f12.descriptorBindingVariableDescriptorCount = VK_TRUE;
    VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, &f12};
    dci.enabledExtensionCount = 1;
    dci.ppEnabledExtensionNames = exts;
    dev = createObject<Device>(nullptr, VK_SYSTEM_ALLOCATION_SCOPE_DEVICE, fromHandle<PhysicalDevice>(pd), dci);
    ASSERT_NE(dev, nullptr);
    device = toHandle(dev);
  }
  void TearDown() override {
    for (auto& b : buffers) {
      vkrt_DestroyBuffer(device, b.first, nullptr);
      vkrt_FreeMemory(device, b.second, nullptr);
    }
    destroyObject(dev, nullptr);
    vkrt_DestroyInstance(instance, nullptr);
  }

  Buffer* makeBuffer(VkDeviceSize size, VkBufferUsageFlags usage) {
    VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    bci.size = size;
    bci.usage = usage;
    VkBuffer b = VK_NULL_HANDLE;
    EXPECT_EQ(vkrt_CreateBuffer(device, &bci, nullptr, &b), VK_SUCCESS);
    VkMemoryRequirements req;
    vkrt_GetBufferMemoryRequirements(device, b, &req);
    VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    mai.allocationSize = req.size;
    VkDeviceMemory m = VK_NULL_HANDLE;
    EXPECT_EQ(vkrt_AllocateMemory(device, &mai, nullptr, &m), VK_SUCCESS);
    EXPECT_EQ(vkrt_BindBufferMemory(device, b, m, 0), VK_SUCCESS);
    buffers.push_back({b, m});
    return fromHandle<Buffer>(b);
  }

  VkDescriptorSetLayout makeLayout(std::vector<VkDescriptorSetLayoutBinding> bindings,
                                   std::vector<VkDescriptorBindingFlags> flags = {}) {
    VkDescriptorSetLayoutBindingFlagsCreateInfo bf{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_BINDING_FLAGS_CREATE_INFO};
    bf.bindingCount = static_cast<uint32_t>(flags.size());
    bf.pBindingFlags = flags.data();
    VkDescriptorSetLayoutCreateInfo ci{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO,
                                       flags.empty() ? nullptr : &bf};
    ci.bindingCount = static_cast<uint32_t>(bindings.size());
    ci.pBindings = bindings.data();
    VkDescriptorSetLayout l = VK_NULL_HANDLE;
    EXPECT_EQ(vkrt_CreateDescriptorSetLayout(device, &ci, nullptr, &l), VK_SUCCESS);
    return l;
  }

  VkDescriptorPool makePool() {
    VkDescriptorPoolSize sizes[] = {{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 64},
                                    {VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC, 8},
                                    {VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 16},
                                    {VK_DESCRIPTOR_TYPE_SAMPLER, 16},
                                    {VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 4}};
    VkDescriptorPoolCreateInfo ci{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    ci.flags = VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT;
    ci.maxSets = 8;
    ci.poolSizeCount = 5;
    ci.pPoolSizes = sizes;
    VkDescriptorPool p = VK_NULL_HANDLE;
    EXPECT_EQ(vkrt_CreateDescriptorPool(device, &ci, nullptr, &p), VK_SUCCESS);
    return p;
  }

  DescriptorSet* allocate(VkDescriptorPool pool, VkDescriptorSetLayout layout, uint32_t variableCount = 0) {
    VkDescriptorSetVariableDescriptorCountAllocateInfo v{
        VK_STRUCTURE_TYPE_DESCRIPTOR_SET_VARIABLE_DESCRIPTOR_COUNT_ALLOCATE_INFO};
    v.descriptorSetCount = 1;
    v.pDescriptorCounts = &variableCount;
    VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO, &v};
    ai.descriptorPool = pool;
    ai.descriptorSetCount = 1;
    ai.pSetLayouts = &layout;
    VkDescriptorSet s = VK_NULL_HANDLE;
    EXPECT_EQ(vkrt_AllocateDescriptorSets(device, &ai, &s), VK_SUCCESS);
    return fromHandle<DescriptorSet>(s);
  }

  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice pd = VK_NULL_HANDLE;
  Device* dev = nullptr;
  VkDevice device = VK_NULL_HANDLE;
  std::vector<std::pair<VkBuffer, VkDeviceMemory>> buffers;
};

constexpr VkShaderStageFlags kCompute = VK_SHADER_STAGE_COMPUTE_BIT;

TEST_F(DescriptorStorage, BindingOffsetsAreFlatAndPrecomputed) {
  VkDescriptorSetLayout l = makeLayout(
      {{5, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 8, kCompute, nullptr},  // variable-sized, highest binding
       {0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 2, kCompute, nullptr},
       {3, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 2, kCompute, nullptr},
       {1, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC, 3, kCompute, nullptr}},
      {VK_DESCRIPTOR_BINDING_VARIABLE_DESCRIPTOR_COUNT_BIT | VK_DESCRIPTOR_BINDING_PARTIALLY_BOUND_BIT, 0, 0, 0});
  DescriptorSetLayout* layout = fromHandle<DescriptorSetLayout>(l);
  ASSERT_NE(layout, nullptr);
  EXPECT_EQ(layout->bindingAt(0)->offset, 0u);
  EXPECT_EQ(layout->bindingAt(1)->offset, 2u);
  EXPECT_EQ(layout->bindingAt(3)->offset, 5u);
  EXPECT_EQ(layout->bindingAt(5)->offset, 7u);
  EXPECT_EQ(layout->bindingAt(2), nullptr);
  EXPECT_EQ(layout->bindingAt(1)->dynamicIndex, 0u);
  EXPECT_EQ(layout->dynamicCount, 3u);
  EXPECT_EQ(layout->recordCount, 15u);
  EXPECT_TRUE(layout->hasVariableCount);

  VkDescriptorPool pool = makePool();
  DescriptorSet* set = allocate(pool, l, 3);
  ASSERT_NE(set, nullptr);
  EXPECT_EQ(set->variableCount, 3u);
  EXPECT_EQ(set->recordCount, 10u);
  EXPECT_EQ(reinterpret_cast<uintptr_t>(set->records()) % 32, 0u);
  for (uint32_t i = 0; i < set->recordCount; ++i) {
    EXPECT_EQ(set->records()[i].address, 0u);
    EXPECT_EQ(set->records()[i].object, nullptr);
  }
  vkrt_DestroyDescriptorPool(device, pool, nullptr);
  vkrt_DestroyDescriptorSetLayout(device, l, nullptr);
}

TEST_F(DescriptorStorage, BufferWritesStoreAddressAndRangeAndCrossIntoConsecutiveBindings) {
  Buffer* buf = makeBuffer(4096, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
  VkDescriptorSetLayout l = makeLayout({{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 2, kCompute, nullptr},
                                        {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, kCompute, nullptr},
                                        {2, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC, 1, kCompute, nullptr}});
  VkDescriptorPool pool = makePool();
  DescriptorSet* set = allocate(pool, l);
  VkDescriptorBufferInfo infos[3] = {
      {toHandle(buf), 0, 256}, {toHandle(buf), 64, VK_WHOLE_SIZE}, {toHandle(buf), 1024, 16}};
  VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
  w.dstSet = toHandle(set);
  w.dstBinding = 0;
  w.descriptorCount = 3;  // binding 0 (2 elements) then binding 1
  w.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  w.pBufferInfo = infos;
  vkrt_UpdateDescriptorSets(device, 1, &w, 0, nullptr);
  const DescriptorRecord* r = set->records();
  const uint64_t base = reinterpret_cast<uint64_t>(buf->data());
  EXPECT_EQ(r[0].address, base);
  EXPECT_EQ(r[0].range, 256u);
  EXPECT_EQ(r[1].address, base + 64);
  EXPECT_EQ(r[1].range, 4096u - 64);
  EXPECT_EQ(r[2].address, base + 1024);
  EXPECT_EQ(r[2].range, 16u);

  // A write that would run from binding 1 into binding 2 (another type) is refused, and a batch with one bad
  // write changes nothing at all.
  VkDescriptorBufferInfo other[2] = {{toHandle(buf), 2048, 32}, {toHandle(buf), 2048, 32}};
  VkWriteDescriptorSet good = w;
  good.descriptorCount = 1;
  good.pBufferInfo = other;
  VkWriteDescriptorSet bad = w;
  bad.dstBinding = 1;
  bad.descriptorCount = 2;
  bad.pBufferInfo = other;
  VkWriteDescriptorSet batch[2] = {good, bad};
  vkrt_UpdateDescriptorSets(device, 2, batch, 0, nullptr);
  EXPECT_EQ(r[0].address, base) << "the valid write of a failed batch must not be applied";
  EXPECT_EQ(r[2].address, base + 1024);

  // Copies move whole records.
  DescriptorSet* set2 = allocate(pool, l);
  VkCopyDescriptorSet c{VK_STRUCTURE_TYPE_COPY_DESCRIPTOR_SET};
  c.srcSet = toHandle(set);
  c.srcBinding = 0;
  c.srcArrayElement = 1;
  c.dstSet = toHandle(set2);
  c.dstBinding = 0;
  c.dstArrayElement = 0;
  c.descriptorCount = 2;
  vkrt_UpdateDescriptorSets(device, 0, nullptr, 1, &c);
  EXPECT_EQ(std::memcmp(&set2->records()[0], &r[1], 2 * sizeof(DescriptorRecord)), 0);
  EXPECT_EQ(set2->records()[2].address, 0u);

  vkrt_DestroyDescriptorPool(device, pool, nullptr);
  vkrt_DestroyDescriptorSetLayout(device, l, nullptr);
}

TEST_F(DescriptorStorage, ImmutableSamplersImagesAndTemplates) {
  Object sampler0(VK_OBJECT_TYPE_SAMPLER, nullptr, dev), sampler1(VK_OBJECT_TYPE_SAMPLER, nullptr, dev);
  // Real views (a write reads the view's usage, VUID-VkWriteDescriptorSet-descriptorType-00337) of a sampled image.
  VkImageCreateInfo ici{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  ici.imageType = VK_IMAGE_TYPE_2D;
  ici.format = VK_FORMAT_R8G8B8A8_UNORM;
  ici.extent = {1, 1, 1};
  ici.mipLevels = ici.arrayLayers = 1;
  ici.samples = VK_SAMPLE_COUNT_1_BIT;
  ici.usage = VK_IMAGE_USAGE_SAMPLED_BIT;
  Image image(dev, ici, formatInfo(ici.format));
  VkImageViewCreateInfo vci{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
  vci.viewType = VK_IMAGE_VIEW_TYPE_2D;
  vci.format = ici.format;
  vci.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  ImageView view0(dev, vci, &image), view1(dev, vci, &image);
  VkSampler immutable[2] = {reinterpret_cast<VkSampler>(sampler0.handleValue()),
                            reinterpret_cast<VkSampler>(sampler1.handleValue())};
  VkDescriptorSetLayout l = makeLayout({{0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 2, kCompute, immutable},
                                        {1, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, kCompute, nullptr},
                                        {2, VK_DESCRIPTOR_TYPE_SAMPLER, 1, kCompute, nullptr}});
  VkDescriptorPool pool = makePool();
  DescriptorSet* set = allocate(pool, l);
  const DescriptorRecord* r = set->records();
  EXPECT_EQ(r[0].sampler, &sampler0) << "immutable samplers are in the set from allocation";
  EXPECT_EQ(r[1].sampler, &sampler1);

  // Template: binding 0 (immutable samplers: the sampler member is ignored), then binding 1 and 2.
  struct Data {
    VkDescriptorImageInfo images[3];
    VkDescriptorImageInfo sampler;
  } data{};
  data.images[0] = {immutable[1], reinterpret_cast<VkImageView>(view1.handleValue()), VK_IMAGE_LAYOUT_GENERAL};
  data.images[1] = {VK_NULL_HANDLE, reinterpret_cast<VkImageView>(view0.handleValue()), VK_IMAGE_LAYOUT_GENERAL};
  data.images[2] = {immutable[1], reinterpret_cast<VkImageView>(view1.handleValue()), VK_IMAGE_LAYOUT_GENERAL};
  data.sampler = {immutable[0], VK_NULL_HANDLE, VK_IMAGE_LAYOUT_UNDEFINED};
  VkDescriptorUpdateTemplateEntry entries[3] = {
      {0, 0, 2, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, offsetof(Data, images), sizeof(VkDescriptorImageInfo)},
      {1, 0, 1, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, offsetof(Data, images) + 2 * sizeof(VkDescriptorImageInfo),
       0},
      {2, 0, 1, VK_DESCRIPTOR_TYPE_SAMPLER, offsetof(Data, sampler), 0}};
  VkDescriptorUpdateTemplateCreateInfo tci{VK_STRUCTURE_TYPE_DESCRIPTOR_UPDATE_TEMPLATE_CREATE_INFO};
  tci.descriptorUpdateEntryCount = 3;
  tci.pDescriptorUpdateEntries = entries;
  tci.templateType = VK_DESCRIPTOR_UPDATE_TEMPLATE_TYPE_DESCRIPTOR_SET;
  tci.descriptorSetLayout = l;
  VkDescriptorUpdateTemplate t = VK_NULL_HANDLE;
  ASSERT_EQ(vkrt_CreateDescriptorUpdateTemplate(device, &tci, nullptr, &t), VK_SUCCESS);
  // The layout handle may go away: the template and the set keep what they need.
  vkrt_DestroyDescriptorSetLayout(device, l, nullptr);
  vkrt_UpdateDescriptorSetWithTemplate(device, toHandle(set), t, &data);
  EXPECT_EQ(r[0].object, &view1);
  EXPECT_EQ(r[0].sampler, &sampler0) << "immutable sampler kept";
  EXPECT_EQ(r[1].object, &view0);
  EXPECT_EQ(r[1].sampler, &sampler1);
  EXPECT_EQ(r[2].object, &view1);
  EXPECT_EQ(r[2].sampler, &sampler1);
  EXPECT_EQ(r[3].sampler, &sampler0);
  EXPECT_EQ(r[3].object, nullptr);
  vkrt_DestroyDescriptorUpdateTemplate(device, t, nullptr);
  vkrt_DestroyDescriptorPool(device, pool, nullptr);
}

TEST_F(DescriptorStorage, AccelerationStructureDescriptorsStoreTheAddress) {
  Buffer* storage = makeBuffer(4096, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR);
  VkAccelerationStructureCreateInfoKHR aci{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
  aci.buffer = toHandle(storage);
  aci.offset = 512;
  aci.size = 1024;
  aci.type = VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR;
  VkAccelerationStructureKHR h = VK_NULL_HANDLE;
  ASSERT_EQ(vkrt_CreateAccelerationStructureKHR(device, &aci, nullptr, &h), VK_SUCCESS);
  VkDescriptorSetLayout l = makeLayout({{0, VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 1, kCompute, nullptr}});
  VkDescriptorPool pool = makePool();
  DescriptorSet* set = allocate(pool, l);
  VkWriteDescriptorSetAccelerationStructureKHR asw{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_KHR};
  asw.accelerationStructureCount = 1;
  asw.pAccelerationStructures = &h;
  VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, &asw};
  w.dstSet = toHandle(set);
  w.descriptorCount = 1;
  w.descriptorType = VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR;
  vkrt_UpdateDescriptorSets(device, 1, &w, 0, nullptr);
  // The record holds the structure's device address: its buffer's address plus the offset.
  EXPECT_EQ(set->records()[0].address, reinterpret_cast<uint64_t>(storage->data()) + 512);
  EXPECT_EQ(set->records()[0].object, static_cast<const Object*>(fromHandle<AccelerationStructure>(h)));
  vkrt_DestroyDescriptorPool(device, pool, nullptr);
  vkrt_DestroyDescriptorSetLayout(device, l, nullptr);
  vkrt_DestroyAccelerationStructureKHR(device, h, nullptr);
}

TEST_F(DescriptorStorage, PipelineLayoutKeepsSetLayoutsAndDynamicOffsetStarts) {
  VkDescriptorSetLayout a = makeLayout({{0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC, 2, kCompute, nullptr}});
  VkDescriptorSetLayout b = makeLayout({{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, kCompute, nullptr},
                                        {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER_DYNAMIC, 3, kCompute, nullptr}});
  VkDescriptorSetLayout sets[3] = {a, b, a};
  VkPushConstantRange range{kCompute, 0, 16};
  VkPipelineLayoutCreateInfo ci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  ci.setLayoutCount = 3;
  ci.pSetLayouts = sets;
  ci.pushConstantRangeCount = 1;
  ci.pPushConstantRanges = &range;
  VkPipelineLayout pl = VK_NULL_HANDLE;
  ASSERT_EQ(vkrt_CreatePipelineLayout(device, &ci, nullptr, &pl), VK_SUCCESS);
  vkrt_DestroyDescriptorSetLayout(device, a, nullptr);
  vkrt_DestroyDescriptorSetLayout(device, b, nullptr);
  PipelineLayout* layout = fromHandle<PipelineLayout>(pl);
  ASSERT_EQ(layout->setLayouts.size(), 3u);
  EXPECT_EQ(layout->setLayouts[1]->bindingAt(1)->count, 3u) << "set layouts stay readable after their destruction";
  EXPECT_EQ(layout->dynamicOffsetStart, (std::vector<uint32_t>{0, 2, 5, 7}));
  EXPECT_EQ(layout->pushConstantStages(4, 8), kCompute);
  EXPECT_EQ(layout->pushConstantStages(12, 8), 0u);
  vkrt_DestroyPipelineLayout(device, pl, nullptr);
}

TEST_F(DescriptorStorage, PipelineCacheEntriesRoundTripByteExactly) {
  VkPipelineCacheCreateInfo ci{VK_STRUCTURE_TYPE_PIPELINE_CACHE_CREATE_INFO};
  VkPipelineCache h = VK_NULL_HANDLE;
  ASSERT_EQ(vkrt_CreatePipelineCache(device, &ci, nullptr, &h), VK_SUCCESS);
  PipelineCache* cache = fromHandle<PipelineCache>(h);
  EXPECT_TRUE(cache->insert("shader-b", std::string("\x01\x02\x03", 3)));
  EXPECT_TRUE(cache->insert("shader-a", std::string("code\0with\0nuls", 14)));
  EXPECT_FALSE(cache->insert("shader-a", "other")) << "the first value wins";
  EXPECT_EQ(*cache->lookup("shader-a"), std::string("code\0with\0nuls", 14));
  EXPECT_FALSE(cache->lookup("missing").has_value());

  size_t size = 0;
  ASSERT_EQ(vkrt_GetPipelineCacheData(device, h, &size, nullptr), VK_SUCCESS);
  EXPECT_EQ(size, 40u + (8 + 24) + (8 + 12));
  std::vector<uint8_t> data(size);
  ASSERT_EQ(vkrt_GetPipelineCacheData(device, h, &size, data.data()), VK_SUCCESS);

  ci.initialDataSize = data.size();
  ci.pInitialData = data.data();
  VkPipelineCache h2 = VK_NULL_HANDLE;
  ASSERT_EQ(vkrt_CreatePipelineCache(device, &ci, nullptr, &h2), VK_SUCCESS);
  EXPECT_EQ(*fromHandle<PipelineCache>(h2)->lookup("shader-b"), std::string("\x01\x02\x03", 3));
  std::vector<uint8_t> again(size);
  size_t size2 = again.size();
  ASSERT_EQ(vkrt_GetPipelineCacheData(device, h2, &size2, again.data()), VK_SUCCESS);
  EXPECT_EQ(again, data);

  // A buffer with room for the header and one entry gets exactly that, as a valid cache of its own.
  size_t partial = 40 + 8 + 24 + 3;
  std::vector<uint8_t> part(partial);
  ASSERT_EQ(vkrt_GetPipelineCacheData(device, h, &partial, part.data()), VK_INCOMPLETE);
  EXPECT_EQ(partial, 40u + 8 + 24);
  PipelineCache probe(dev, 0);
  EXPECT_TRUE(probe.load(part.data(), partial));
  EXPECT_EQ(probe.entryCount(), 1u);
  EXPECT_TRUE(probe.lookup("shader-a").has_value());

  // Damaged data is refused whole.
  data[45] ^= 0xff;
  PipelineCache damaged(dev, 0);
  EXPECT_FALSE(damaged.load(data.data(), data.size()));
  EXPECT_EQ(damaged.entryCount(), 0u);
  vkrt_DestroyPipelineCache(device, h, nullptr);
  vkrt_DestroyPipelineCache(device, h2, nullptr);
}

// Query results below the command buffers: the same copy routine serves vkGetQueryPoolResults and
// vkCmdCopyQueryPoolResults.
TEST_F(DescriptorStorage, QueryPoolResultsLayoutAndAvailability) {
  VkQueryPoolCreateInfo ci{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
  ci.queryType = VK_QUERY_TYPE_TIMESTAMP;
  ci.queryCount = 3;
  VkQueryPool h = VK_NULL_HANDLE;
  ASSERT_EQ(vkrt_CreateQueryPool(device, &ci, nullptr, &h), VK_SUCCESS);
  QueryPool* pool = fromHandle<QueryPool>(h);
  const uint64_t before = QueryPool::now();
  pool->writeTimestamp(0);
  pool->writeTimestamp(2);
  const uint64_t after = QueryPool::now();
  uint64_t out[3][2];
  std::memset(out, 0xcd, sizeof out);
  EXPECT_FALSE(pool->copyResults(0, 3, reinterpret_cast<uint8_t*>(out), 16,
                                 VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WITH_AVAILABILITY_BIT));
  EXPECT_GE(out[0][0], before);
  EXPECT_LE(out[2][0], after);
  EXPECT_LE(out[0][0], out[2][0]);
  EXPECT_EQ(out[0][1], 1u);
  EXPECT_EQ(out[1][1], 0u);
  EXPECT_EQ(out[1][0], 0xcdcdcdcdcdcdcdcdull) << "unavailable values are not written";
  uint32_t out32[4] = {};
  EXPECT_EQ(vkrt_GetQueryPoolResults(device, h, 2, 1, sizeof out32, out32, 8, VK_QUERY_RESULT_WITH_AVAILABILITY_BIT),
            VK_SUCCESS);
  EXPECT_EQ(out32[0], static_cast<uint32_t>(out[2][0]));
  EXPECT_EQ(out32[1], 1u);
  vkrt_ResetQueryPool(device, h, 0, 3);  // hostQueryReset is not enabled on this device: refused
  EXPECT_TRUE(pool->available(0));
  pool->reset(0, 3);
  EXPECT_FALSE(pool->available(2));
  vkrt_DestroyQueryPool(device, h, nullptr);
}

}  // namespace
}  // namespace vkrt
