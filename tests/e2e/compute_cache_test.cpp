// VkPipelineCache holds compiled compute code: a pipeline created with a cache stores its shader's object code
// there; a later creation on another device, or in another process given vkGetPipelineCacheData's bytes,
// loads it without compiling (VK_PIPELINE_CREATION_FEEDBACK_APPLICATION_PIPELINE_CACHE_HIT_BIT) and computes
// the same bytes. Damaged entries are ignored: the shader is compiled again and the entry replaced.
#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <vector>

#include "compute_push_spec.comp.spv.h"
#include "compute_shared.comp.spv.h"
#include "e2e/fixture.hpp"

namespace vkrt::test {
namespace {

constexpr VkDescriptorType kStorage = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;

struct Spec {
  uint32_t localSize;
  int32_t scale;
  uint32_t negate;
  float bias;
};

// What the push_spec shader writes for `count` invocations (computed here independently).
std::vector<float> expectedPushSpec(const Spec& s, uint32_t count) {
  std::vector<float> r(count + 2, -1.0f);
  for (uint32_t i = 0; i < count; ++i) {
    float v = float(int32_t(i) * s.scale + 7) * 0.5f + s.bias + 3.0f * -1.0f;
    r[i] = s.negate ? -v : v;
  }
  r[count] = float(s.localSize);
  return r;
}

class ComputeCacheTest : public VulkanTest {
 protected:
  // One device's objects for running a one-binding-set compute shader.
  struct Runner {
    VkDevice dev = VK_NULL_HANDLE;
    VkQueue queue = VK_NULL_HANDLE;
    VkCommandPool pool = VK_NULL_HANDLE;
    bool owned = false;  // a device this test created (not the fixture's)
  };

  Runner fixtureRunner() { return {device, queue, commandPool, false}; }

  Runner newDevice() {
    Runner r;
    float priority = 1;
    VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    qci.queueCount = 1;
    qci.pQueuePriorities = &priority;
    VkPhysicalDeviceVulkan13Features f13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
    f13.maintenance4 = VK_TRUE;
    f13.pipelineCreationCacheControl = VK_TRUE;
    VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, &f13};
    dci.queueCreateInfoCount = 1;
    dci.pQueueCreateInfos = &qci;
    EXPECT_EQ(vkCreateDevice(physicalDevice, &dci, nullptr, &r.dev), VK_SUCCESS);
    vkGetDeviceQueue(r.dev, 0, 0, &r.queue);
    VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    EXPECT_EQ(vkCreateCommandPool(r.dev, &pci, nullptr, &r.pool), VK_SUCCESS);
    r.owned = true;
    return r;
  }
  void release(Runner& r) {
    if (!r.owned) return;
    vkDestroyCommandPool(r.dev, r.pool, nullptr);
    vkDestroyDevice(r.dev, nullptr);
    r = {};
  }

  static VkPipelineCache makeCache(VkDevice dev, const std::vector<uint8_t>& data = {}) {
    VkPipelineCacheCreateInfo ci{VK_STRUCTURE_TYPE_PIPELINE_CACHE_CREATE_INFO};
    ci.initialDataSize = data.size();
    ci.pInitialData = data.empty() ? nullptr : data.data();
    VkPipelineCache c = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreatePipelineCache(dev, &ci, nullptr, &c), VK_SUCCESS);
    return c;
  }
  static std::vector<uint8_t> cacheData(VkDevice dev, VkPipelineCache c) {
    size_t size = 0;
    EXPECT_EQ(vkGetPipelineCacheData(dev, c, &size, nullptr), VK_SUCCESS);
    std::vector<uint8_t> data(size);
    EXPECT_EQ(vkGetPipelineCacheData(dev, c, &size, data.data()), VK_SUCCESS);
    data.resize(size);
    return data;
  }

  struct Result {
    VkResult create = VK_ERROR_UNKNOWN;
    VkPipelineCreationFeedbackFlags pipelineFeedback = 0, stageFeedback = 0;
    std::vector<uint8_t> bytes[2];  // the storage buffers' contents after the dispatch
  };

  // Creates a pipeline of `words` (bindings 0..buffers.size()-1 storage buffers) with `cache` and runs
  // `groups` workgroups over `buffers` (initial contents), with the push_spec shader's push constants.
  Result run(Runner& r, VkPipelineCache cache, const uint32_t* words, size_t codeSize, const VkSpecializationInfo* spec,
             std::vector<std::vector<uint8_t>> buffers, uint32_t groups, VkPipelineCreateFlags flags = 0) {
    Result res;
    VkDevice dev = r.dev;
    std::vector<VkDescriptorSetLayoutBinding> bindings;
    for (uint32_t i = 0; i < buffers.size(); ++i)
      bindings.push_back({i, kStorage, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr});
    VkDescriptorSetLayoutCreateInfo dl{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    dl.bindingCount = uint32_t(bindings.size());
    dl.pBindings = bindings.data();
    VkDescriptorSetLayout setLayout;
    EXPECT_EQ(vkCreateDescriptorSetLayout(dev, &dl, nullptr, &setLayout), VK_SUCCESS);
    VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, 32};
    VkPipelineLayoutCreateInfo pl{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    pl.setLayoutCount = 1;
    pl.pSetLayouts = &setLayout;
    pl.pushConstantRangeCount = 1;
    pl.pPushConstantRanges = &range;
    VkPipelineLayout layout;
    EXPECT_EQ(vkCreatePipelineLayout(dev, &pl, nullptr, &layout), VK_SUCCESS);
    VkShaderModuleCreateInfo sm{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    sm.codeSize = codeSize;
    sm.pCode = words;
    VkShaderModule module;
    EXPECT_EQ(vkCreateShaderModule(dev, &sm, nullptr, &module), VK_SUCCESS);

    VkPipelineCreationFeedback pipelineFb{}, stageFb{};
    VkPipelineCreationFeedbackCreateInfo fb{VK_STRUCTURE_TYPE_PIPELINE_CREATION_FEEDBACK_CREATE_INFO};
    fb.pPipelineCreationFeedback = &pipelineFb;
    fb.pipelineStageCreationFeedbackCount = 1;
    fb.pPipelineStageCreationFeedbacks = &stageFb;
    VkComputePipelineCreateInfo ci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO, &fb};
    ci.flags = flags;
    ci.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    ci.stage.module = module;
    ci.stage.pName = "main";
    ci.stage.pSpecializationInfo = spec;
    ci.layout = layout;
    VkPipeline pipeline = VK_NULL_HANDLE;
    res.create = vkCreateComputePipelines(dev, cache, 1, &ci, nullptr, &pipeline);
    res.pipelineFeedback = pipelineFb.flags;
    res.stageFeedback = stageFb.flags;

    if (res.create == VK_SUCCESS) {
      VkDescriptorPoolSize size{kStorage, uint32_t(buffers.size())};
      VkDescriptorPoolCreateInfo dp{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
      dp.maxSets = 1;
      dp.poolSizeCount = 1;
      dp.pPoolSizes = &size;
      VkDescriptorPool pool;
      EXPECT_EQ(vkCreateDescriptorPool(dev, &dp, nullptr, &pool), VK_SUCCESS);
      VkDescriptorSetAllocateInfo da{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
      da.descriptorPool = pool;
      da.descriptorSetCount = 1;
      da.pSetLayouts = &setLayout;
      VkDescriptorSet set;
      EXPECT_EQ(vkAllocateDescriptorSets(dev, &da, &set), VK_SUCCESS);
      std::vector<VkBuffer> bufs(buffers.size());
      std::vector<VkDeviceMemory> mems(buffers.size());
      std::vector<void*> maps(buffers.size());
      for (size_t i = 0; i < buffers.size(); ++i) {
        VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
        bci.size = buffers[i].size();
        bci.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
        EXPECT_EQ(vkCreateBuffer(dev, &bci, nullptr, &bufs[i]), VK_SUCCESS);
        VkMemoryRequirements req;
        vkGetBufferMemoryRequirements(dev, bufs[i], &req);
        VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
        ai.allocationSize = req.size;
        ai.memoryTypeIndex = memoryTypeIndex(
            req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
        EXPECT_EQ(vkAllocateMemory(dev, &ai, nullptr, &mems[i]), VK_SUCCESS);
        EXPECT_EQ(vkBindBufferMemory(dev, bufs[i], mems[i], 0), VK_SUCCESS);
        EXPECT_EQ(vkMapMemory(dev, mems[i], 0, VK_WHOLE_SIZE, 0, &maps[i]), VK_SUCCESS);
        std::memcpy(maps[i], buffers[i].data(), buffers[i].size());
        VkDescriptorBufferInfo bi{bufs[i], 0, VK_WHOLE_SIZE};
        VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
        w.dstSet = set;
        w.dstBinding = uint32_t(i);
        w.descriptorCount = 1;
        w.descriptorType = kStorage;
        w.pBufferInfo = &bi;
        vkUpdateDescriptorSets(dev, 1, &w, 0, nullptr);
      }
      VkCommandBufferAllocateInfo cai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
      cai.commandPool = r.pool;
      cai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
      cai.commandBufferCount = 1;
      VkCommandBuffer cb;
      EXPECT_EQ(vkAllocateCommandBuffers(dev, &cai, &cb), VK_SUCCESS);
      VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
      bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
      EXPECT_EQ(vkBeginCommandBuffer(cb, &bi), VK_SUCCESS);
      vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
      vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, layout, 0, 1, &set, 0, nullptr);
      struct {
        uint32_t count;
        int32_t offset;
        float fscale;
        float pad;
        float extra[2];
      } pc = {50, 7, 0.5f, 0, {3.0f, -1.0f}};
      vkCmdPushConstants(cb, layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof pc, &pc);
      vkCmdDispatch(cb, groups, 1, 1);
      EXPECT_EQ(vkEndCommandBuffer(cb), VK_SUCCESS);
      VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
      si.commandBufferCount = 1;
      si.pCommandBuffers = &cb;
      EXPECT_EQ(vkQueueSubmit(r.queue, 1, &si, VK_NULL_HANDLE), VK_SUCCESS);
      EXPECT_EQ(vkQueueWaitIdle(r.queue), VK_SUCCESS);
      for (size_t i = 0; i < buffers.size() && i < 2; ++i) {
        auto* p = static_cast<const uint8_t*>(maps[i]);
        res.bytes[i].assign(p, p + buffers[i].size());
      }
      vkFreeCommandBuffers(dev, r.pool, 1, &cb);
      for (size_t i = 0; i < buffers.size(); ++i) {
        vkDestroyBuffer(dev, bufs[i], nullptr);
        vkFreeMemory(dev, mems[i], nullptr);
      }
      vkDestroyDescriptorPool(dev, pool, nullptr);
    }
    vkDestroyPipeline(dev, pipeline, nullptr);
    vkDestroyShaderModule(dev, module, nullptr);
    vkDestroyPipelineLayout(dev, layout, nullptr);
    vkDestroyDescriptorSetLayout(dev, setLayout, nullptr);
    return res;
  }

  // The push_spec shader with `s`, 64 invocations (50 in range).
  Result runPushSpec(Runner& r, VkPipelineCache cache, const Spec& s, VkPipelineCreateFlags flags = 0) {
    static const VkSpecializationMapEntry entries[] = {{0, 0, 4}, {1, 4, 4}, {2, 8, 4}, {3, 12, 4}};
    VkSpecializationInfo spec{4, entries, sizeof s, &s};
    std::vector<float> init(52, -1.0f);
    std::vector<uint8_t> bytes(init.size() * 4);
    std::memcpy(bytes.data(), init.data(), bytes.size());
    return run(r, cache, kSpv_compute_push_spec_comp, sizeof kSpv_compute_push_spec_comp, &spec, {bytes},
               64 / s.localSize, flags);
  }

  // The shared-memory shader (workgroup memory, barriers, atomics): 9 workgroups of 64.
  Result runShared(Runner& r, VkPipelineCache cache) {
    std::vector<uint32_t> v(9 * 64);
    for (uint32_t i = 0; i < v.size(); ++i) v[i] = i * 7 + (i >> 3);
    std::vector<uint8_t> data(v.size() * 4), sums(9 * 2 * 4, 0);
    std::memcpy(data.data(), v.data(), data.size());
    return run(r, cache, kSpv_compute_shared_comp, sizeof kSpv_compute_shared_comp, nullptr, {data, sums}, 9);
  }

  static std::vector<uint8_t> floatBytes(const std::vector<float>& f) {
    std::vector<uint8_t> b(f.size() * 4);
    std::memcpy(b.data(), f.data(), b.size());
    return b;
  }
};

constexpr VkPipelineCreationFeedbackFlags kValid = VK_PIPELINE_CREATION_FEEDBACK_VALID_BIT;
constexpr VkPipelineCreationFeedbackFlags kHit = VK_PIPELINE_CREATION_FEEDBACK_APPLICATION_PIPELINE_CACHE_HIT_BIT;
constexpr Spec kSpec{16, -2, 1, 1.25f};

TEST_F(ComputeCacheTest, CompiledCodeRoundTripsThroughCacheDataToASecondDevice) {
  Runner first = fixtureRunner();
  VkPipelineCache cache = makeCache(device);
  Result cold = runPushSpec(first, cache, kSpec);
  ASSERT_EQ(cold.create, VK_SUCCESS);
  EXPECT_EQ(cold.pipelineFeedback, kValid) << "an empty cache cannot hit";
  EXPECT_EQ(cold.stageFeedback, kValid);
  EXPECT_EQ(cold.bytes[0], floatBytes(expectedPushSpec(kSpec, 50)));
  Result sharedCold = runShared(first, cache);
  ASSERT_EQ(sharedCold.create, VK_SUCCESS);
  EXPECT_EQ(sharedCold.pipelineFeedback, kValid);
  // The same cache again on the same device: the entry is there now.
  Result again = runPushSpec(first, cache, kSpec);
  EXPECT_EQ(again.pipelineFeedback, kValid | kHit);
  EXPECT_EQ(again.bytes[0], cold.bytes[0]);
  std::vector<uint8_t> data = cacheData(device, cache);
  vkDestroyPipelineCache(device, cache, nullptr);
  ASSERT_GT(data.size(), 1000u) << "the cache holds object code";

  // A second device (nothing compiled for it) given the data: both shaders load from the cache.
  Runner second = newDevice();
  VkPipelineCache loaded = makeCache(second.dev, data);
  Result warm = runPushSpec(second, loaded, kSpec);
  ASSERT_EQ(warm.create, VK_SUCCESS);
  EXPECT_EQ(warm.pipelineFeedback, kValid | kHit);
  EXPECT_EQ(warm.stageFeedback, kValid | kHit);
  EXPECT_EQ(warm.bytes[0], cold.bytes[0]);
  Result sharedWarm = runShared(second, loaded);
  EXPECT_EQ(sharedWarm.pipelineFeedback, kValid | kHit);
  EXPECT_EQ(sharedWarm.bytes[0], sharedCold.bytes[0]);
  EXPECT_EQ(sharedWarm.bytes[1], sharedCold.bytes[1]);
  const uint32_t* sums = reinterpret_cast<const uint32_t*>(sharedWarm.bytes[1].data());
  for (uint32_t g = 0; g < 9; ++g) {
    uint32_t want = 0;
    for (uint32_t l = 0; l < 64; ++l) want += (g * 64 + l) * 7 + ((g * 64 + l) >> 3);
    EXPECT_EQ(sums[2 * g], want) << g;
    EXPECT_EQ(sums[2 * g + 1], 64u) << g;
  }
  // Other specialization bytes are another key: a miss, then compiled, with its own results.
  Spec other{32, 3, 0, -0.5f};
  Result otherCold = runPushSpec(second, loaded, other);
  EXPECT_EQ(otherCold.pipelineFeedback, kValid);
  EXPECT_EQ(otherCold.bytes[0], floatBytes(expectedPushSpec(other, 50)));
  // Without a cache nothing can hit.
  Result none = runPushSpec(second, VK_NULL_HANDLE, kSpec);
  EXPECT_EQ(none.pipelineFeedback, kValid);
  EXPECT_EQ(none.bytes[0], cold.bytes[0]);
  // The loaded cache's data now holds the three entries, in a stable serialization.
  std::vector<uint8_t> data2 = cacheData(second.dev, loaded);
  EXPECT_GT(data2.size(), data.size());
  EXPECT_EQ(cacheData(second.dev, loaded), data2);
  vkDestroyPipelineCache(second.dev, loaded, nullptr);
  release(second);
}

TEST_F(ComputeCacheTest, FailOnCompileRequiredSucceedsFromAWarmCache) {
  Runner first = fixtureRunner();
  VkPipelineCache cache = makeCache(device);
  ASSERT_EQ(runPushSpec(first, cache, kSpec).create, VK_SUCCESS);
  std::vector<uint8_t> data = cacheData(device, cache);
  vkDestroyPipelineCache(device, cache, nullptr);

  Runner second = newDevice();
  VkPipelineCache empty = makeCache(second.dev);
  VkPipelineCache warm = makeCache(second.dev, data);
  VkResult fromEmpty =
      runPushSpec(second, empty, kSpec, VK_PIPELINE_CREATE_FAIL_ON_PIPELINE_COMPILE_REQUIRED_BIT).create;
  if (onVkrt()) {
    EXPECT_EQ(fromEmpty, VK_PIPELINE_COMPILE_REQUIRED);
  } else {
    // Another driver may find the shader in caches of its own (NVIDIA keeps one on disk), as the spec allows.
    EXPECT_TRUE(fromEmpty == VK_PIPELINE_COMPILE_REQUIRED || fromEmpty == VK_SUCCESS) << fromEmpty;
  }
  Result r = runPushSpec(second, warm, kSpec, VK_PIPELINE_CREATE_FAIL_ON_PIPELINE_COMPILE_REQUIRED_BIT);
  EXPECT_EQ(r.create, VK_SUCCESS);
  EXPECT_EQ(r.pipelineFeedback, kValid | kHit);
  EXPECT_EQ(r.bytes[0], floatBytes(expectedPushSpec(kSpec, 50)));
  vkDestroyPipelineCache(second.dev, empty, nullptr);
  vkDestroyPipelineCache(second.dev, warm, nullptr);
  release(second);
}

TEST_F(ComputeCacheTest, DamagedEntryIsIgnoredCompiledAgainAndReplaced) {
  if (!onVkrt()) GTEST_SKIP() << "vkrt's own cache entry format and messages";
  Runner first = fixtureRunner();
  VkPipelineCache cache = makeCache(device);
  Result cold = runPushSpec(first, cache, kSpec);
  ASSERT_EQ(cold.create, VK_SUCCESS);
  std::vector<uint8_t> data = cacheData(device, cache);
  vkDestroyPipelineCache(device, cache, nullptr);

  // One flipped bit inside the entry's value (its object code), and the same entry with the code cut short.
  for (int damage = 0; damage < 2; ++damage) {
    std::vector<uint8_t> bad = data;
    if (damage == 0) {
      bad[bad.size() - 64] ^= 0x10;
    } else {
      // value size (bytes 44..47 of the only entry) shortened by 256, the data cut to match.
      uint32_t valueSize;
      std::memcpy(&valueSize, &bad[44], 4);
      uint32_t keySize;
      std::memcpy(&keySize, &bad[40], 4);
      valueSize -= 256;
      std::memcpy(&bad[44], &valueSize, 4);
      bad.resize(48 + ((keySize + valueSize + 3) & ~3u));
    }
    Runner second = newDevice();
    VkPipelineCache damaged = makeCache(second.dev, bad);
    clearMessages();
    Result r = runPushSpec(second, damaged, kSpec);
    ASSERT_EQ(r.create, VK_SUCCESS) << damage;
    EXPECT_EQ(r.pipelineFeedback, kValid) << "a damaged entry is no hit";
    EXPECT_EQ(r.bytes[0], cold.bytes[0]);
    std::vector<Message> msgs = vkrtMessages();
    ASSERT_EQ(msgs.size(), 1u);
    EXPECT_NE(msgs[0].text.find("ignoring a pipeline cache entry"), std::string::npos) << msgs[0].text;
    clearMessages();
    // The entry was replaced by the newly compiled code: the data is whole again.
    EXPECT_EQ(cacheData(second.dev, damaged), data);
    Result again = runPushSpec(second, damaged, kSpec);
    EXPECT_EQ(again.pipelineFeedback, kValid | kHit);
    vkDestroyPipelineCache(second.dev, damaged, nullptr);
    release(second);
  }
}

// ---- another process

std::string tempPath() {
  char path[] = "/tmp/vkrt-h8-XXXXXX";
  int fd = mkstemp(path);
  EXPECT_GE(fd, 0);
  close(fd);
  return path;
}

TEST_F(ComputeCacheTest, AnotherProcessLoadsTheSavedDataWithoutCompiling) {
  Runner first = fixtureRunner();
  VkPipelineCache cache = makeCache(device);
  Result cold = runPushSpec(first, cache, kSpec);
  ASSERT_EQ(cold.create, VK_SUCCESS);
  std::vector<uint8_t> data = cacheData(device, cache);
  vkDestroyPipelineCache(device, cache, nullptr);
  std::string in = tempPath(), out = tempPath();
  std::ofstream(in, std::ios::binary).write(reinterpret_cast<const char*>(data.data()), std::streamsize(data.size()));

  pid_t pid = fork();
  if (pid == 0) {
    setenv("VKRT_H8_CACHE_IN", in.c_str(), 1);
    setenv("VKRT_H8_CACHE_OUT", out.c_str(), 1);
    int devnull = open("/dev/null", O_WRONLY);
    dup2(devnull, 1);
    execl("/proc/self/exe", VKRT_E2E_BINARY, "--gtest_filter=ComputeCacheChild.LoadsCacheFile",
          static_cast<char*>(nullptr));
    _exit(127);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "the child process failed";
  std::ifstream result(out, std::ios::binary);
  std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(result)), std::istreambuf_iterator<char>());
  unlink(in.c_str());
  unlink(out.c_str());
  // The child writes the feedback flags, then the output buffer.
  ASSERT_EQ(bytes.size(), 4 + cold.bytes[0].size());
  uint32_t flags;
  std::memcpy(&flags, bytes.data(), 4);
  EXPECT_EQ(flags, kValid | kHit);
  EXPECT_EQ(std::vector<uint8_t>(bytes.begin() + 4, bytes.end()), cold.bytes[0]);
}

// The child of the test above (skipped when run by itself).
class ComputeCacheChild : public ComputeCacheTest {};

TEST_F(ComputeCacheChild, LoadsCacheFile) {
  const char* in = std::getenv("VKRT_H8_CACHE_IN");
  const char* out = std::getenv("VKRT_H8_CACHE_OUT");
  if (!in || !out) GTEST_SKIP() << "run by ComputeCacheTest.AnotherProcessLoadsTheSavedDataWithoutCompiling";
  std::ifstream file(in, std::ios::binary);
  std::vector<uint8_t> data((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  Runner r = fixtureRunner();
  VkPipelineCache cache = makeCache(device, data);
  Result res = runPushSpec(r, cache, kSpec);
  ASSERT_EQ(res.create, VK_SUCCESS);
  vkDestroyPipelineCache(device, cache, nullptr);
  std::ofstream o(out, std::ios::binary);
  uint32_t flags = res.pipelineFeedback;
  o.write(reinterpret_cast<const char*>(&flags), 4);
  o.write(reinterpret_cast<const char*>(res.bytes[0].data()), std::streamsize(res.bytes[0].size()));
}

}  // namespace
}  // namespace vkrt::test
