// Ray tracing pipelines and VkPipelineCache: VK_PIPELINE_CREATE_FAIL_ON_PIPELINE_COMPILE_REQUIRED_BIT fails with
// VK_PIPELINE_COMPILE_REQUIRED until the stages are in the cache, EARLY_RETURN_ON_FAILURE stops the batch, and
// the cache's data carries the stages into a new cache, in this process and in another one.
//
// VK_PIPELINE_COMPILE_REQUIRED is what a driver returns when it cannot create the pipeline without compiling;
// another driver may find the shaders in a cache of its own (NVIDIA keeps one on disk, across devices and runs),
// so the tests that expect the failure run on vkrt only. Those that expect success from a warm cache run anywhere.
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "e2e/rt_fixture.hpp"

namespace vkrt::test {
namespace {

constexpr VkPipelineCreateFlags kFail = VK_PIPELINE_CREATE_FAIL_ON_PIPELINE_COMPILE_REQUIRED_BIT;
constexpr VkPipelineCreateFlags kEarly = VK_PIPELINE_CREATE_EARLY_RETURN_ON_FAILURE_BIT;

class RtCacheTest : public RtTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o = RtTest::options();
    o.pipelineCreationCacheControl = true;
    return o;
  }
  void TearDown() override {
    if (device)
      for (VkPipelineCache c : caches) vkDestroyPipelineCache(device, c, nullptr);
    RtTest::TearDown();
  }

  VkPipelineCache newCache(const std::vector<uint8_t>& data = {}) {
    VkPipelineCacheCreateInfo ci{VK_STRUCTURE_TYPE_PIPELINE_CACHE_CREATE_INFO};
    ci.initialDataSize = data.size();
    ci.pInitialData = data.empty() ? nullptr : data.data();
    VkPipelineCache c = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreatePipelineCache(device, &ci, nullptr, &c), VK_SUCCESS);
    caches.push_back(c);
    return c;
  }
  std::vector<uint8_t> cacheData(VkPipelineCache c) {
    size_t size = 0;
    EXPECT_EQ(vkGetPipelineCacheData(device, c, &size, nullptr), VK_SUCCESS);
    std::vector<uint8_t> data(size);
    EXPECT_EQ(vkGetPipelineCacheData(device, c, &size, data.data()), VK_SUCCESS);
    data.resize(size);
    return data;
  }

  // Creates the descriptions as one batch (one vkCreateRayTracingPipelinesKHR call); `out` gets every entry.
  VkResult createBatch(std::vector<Desc*> descs, VkPipelineCache cache, std::vector<VkPipeline>& out) {
    std::vector<VkRayTracingPipelineCreateInfoKHR> cis;
    for (Desc* d : descs) {
      VkRayTracingPipelineCreateInfoKHR ci{VK_STRUCTURE_TYPE_RAY_TRACING_PIPELINE_CREATE_INFO_KHR};
      ci.flags = d->flags;
      ci.stageCount = static_cast<uint32_t>(d->stages.size());
      ci.pStages = d->stages.data();
      ci.groupCount = static_cast<uint32_t>(d->groups.size());
      ci.pGroups = d->groups.data();
      ci.maxPipelineRayRecursionDepth = d->depth;
      ci.layout = layout;
      ci.basePipelineIndex = -1;
      cis.push_back(ci);
    }
    // Garbage in the output array, so that VK_NULL_HANDLE written by the driver is seen.
    out.assign(descs.size(), reinterpret_cast<VkPipeline>(uintptr_t(0xdead0000)));
    VkResult r = createPipelines(device, VK_NULL_HANDLE, cache, static_cast<uint32_t>(cis.size()), cis.data(), nullptr,
                                 out.data());
    for (VkPipeline p : out)
      if (p != VK_NULL_HANDLE && p != reinterpret_cast<VkPipeline>(uintptr_t(0xdead0000))) pipelines.push_back(p);
    return r;
  }

  // raygen + miss2 + the callable: a pipeline none of the other tests' descriptions share all stages with.
  Desc other(VkPipelineCreateFlags flags = 0) {
    Desc d;
    d.flags = flags;
    d.general(raygenBig, VK_SHADER_STAGE_RAYGEN_BIT_KHR);
    d.general(miss2, VK_SHADER_STAGE_MISS_BIT_KHR);
    d.general(call, VK_SHADER_STAGE_CALLABLE_BIT_KHR);
    return d;
  }

  std::vector<VkPipelineCache> caches;
};

TEST_F(RtCacheTest, FailOnCompileRequiredUntilTheCacheHasTheStages) {
  if (!vkrt) GTEST_SKIP() << "another driver may find the stages in a cache of its own";
  VkPipelineCache cache = newCache();
  Desc d = sixGroups(kFail);
  VkPipeline p = reinterpret_cast<VkPipeline>(uintptr_t(0xdead0000));
  ASSERT_EQ(create(d, &p, VK_NULL_HANDLE, cache), VK_PIPELINE_COMPILE_REQUIRED);
  EXPECT_EQ(p, VK_NULL_HANDLE);
  // Without a cache there is nothing to find either.
  ASSERT_EQ(create(d, &p), VK_PIPELINE_COMPILE_REQUIRED);
  EXPECT_EQ(p, VK_NULL_HANDLE);
  // A creation without the bit compiles and fills the cache...
  Desc plain = sixGroups();
  VkPipeline compiled = VK_NULL_HANDLE;
  ASSERT_EQ(create(plain, &compiled, VK_NULL_HANDLE, cache), VK_SUCCESS);
  // ...and then the same creation with the bit succeeds, with the same groups.
  ASSERT_EQ(create(d, &p, VK_NULL_HANDLE, cache), VK_SUCCESS);
  ASSERT_NE(p, VK_NULL_HANDLE);
  EXPECT_EQ(handles(p, 0, 6), handles(compiled, 0, 6));
  if (vkrt) {  // the figures of a cache hit are those of the compile (vkrt's own stack sizes)
    for (uint32_t g : {0u, 3u})
      EXPECT_EQ(
          getStackSize(device, p, g, g ? VK_SHADER_GROUP_SHADER_CLOSEST_HIT_KHR : VK_SHADER_GROUP_SHADER_GENERAL_KHR),
          getStackSize(device, compiled, g,
                       g ? VK_SHADER_GROUP_SHADER_CLOSEST_HIT_KHR : VK_SHADER_GROUP_SHADER_GENERAL_KHR));
  }
  // Other stages are still not in the cache.
  Desc o = other(kFail);
  EXPECT_EQ(create(o, &p, VK_NULL_HANDLE, cache), VK_PIPELINE_COMPILE_REQUIRED);
  EXPECT_EQ(p, VK_NULL_HANDLE);
}

TEST_F(RtCacheTest, EarlyReturnStopsTheBatchAndOtherwiseTheRestIsCreated) {
  if (!vkrt) GTEST_SKIP() << "another driver may find the stages in a cache of its own";
  VkPipelineCache cache = newCache();
  const std::vector<uint8_t> empty = cacheData(cache);
  // Without EARLY_RETURN: the failing pipeline is VK_NULL_HANDLE, the others are created.
  {
    Desc a = sixGroups(kFail), b = other();
    std::vector<VkPipeline> out;
    EXPECT_EQ(createBatch({&a, &b}, cache, out), VK_PIPELINE_COMPILE_REQUIRED);
    EXPECT_EQ(out[0], VK_NULL_HANDLE);
    EXPECT_NE(out[1], VK_NULL_HANDLE);
    if (out[1] != VK_NULL_HANDLE) {
      EXPECT_EQ(handles(out[1], 0, 3).size(), 96u);
    }
  }
  // With EARLY_RETURN on the failing one: the pipelines after it are not created.
  VkPipelineCache fresh = newCache();
  {
    Desc first = other(), a = sixGroups(kFail | kEarly), b = other(), c = sixGroups();
    std::vector<VkPipeline> out;
    EXPECT_EQ(createBatch({&first, &a, &b, &c}, fresh, out), VK_PIPELINE_COMPILE_REQUIRED);
    EXPECT_NE(out[0], VK_NULL_HANDLE);  // before the failure: created
    EXPECT_EQ(out[1], VK_NULL_HANDLE);
    EXPECT_EQ(out[2], VK_NULL_HANDLE);
    EXPECT_EQ(out[3], VK_NULL_HANDLE);
  }
  {
    // vkrt does not even build the later pipelines: the six-group stages never entered `fresh`, so they still
    // need compiling there (what another driver keeps in its cache is its own business).
    Desc again = sixGroups(kFail);
    VkPipeline p = VK_NULL_HANDLE;
    EXPECT_EQ(create(again, &p, VK_NULL_HANDLE, fresh), VK_PIPELINE_COMPILE_REQUIRED);
    EXPECT_EQ(p, VK_NULL_HANDLE);
    // The first cache got `other`'s stages only.
    EXPECT_GT(cacheData(cache).size(), empty.size());
  }
}

TEST_F(RtCacheTest, CacheDataCarriesTheStagesIntoANewCache) {
  VkPipelineCache cache = newCache();
  Desc plain = sixGroups();
  VkPipeline compiled = VK_NULL_HANDLE;
  ASSERT_EQ(create(plain, &compiled, VK_NULL_HANDLE, cache), VK_SUCCESS);
  std::vector<uint8_t> data = cacheData(cache);
  VkPipelineCache loaded = newCache(data);
  Desc d = sixGroups(kFail);
  VkPipeline p = VK_NULL_HANDLE;
  ASSERT_EQ(create(d, &p, VK_NULL_HANDLE, loaded), VK_SUCCESS);
  ASSERT_NE(p, VK_NULL_HANDLE);
  EXPECT_EQ(handles(p, 0, 6), handles(compiled, 0, 6));
  // Its data is the same again (a loaded cache serializes to what it was given; vkrt's format is canonical).
  if (vkrt) {
    EXPECT_EQ(cacheData(loaded), data);
  }
  // Merged into an empty cache, the entries come along as well.
  VkPipelineCache merged = newCache();
  ASSERT_EQ(vkMergePipelineCaches(device, merged, 1, &loaded), VK_SUCCESS);
  ASSERT_EQ(create(d, &p, VK_NULL_HANDLE, merged), VK_SUCCESS);
  EXPECT_NE(p, VK_NULL_HANDLE);
}

TEST_F(RtCacheTest, CreationFeedbackReportsEachStageAndTheCacheHits) {
  VkPipelineCache cache = newCache();
  Desc d = sixGroups();
  std::vector<VkPipelineCreationFeedback> stages(d.stages.size(), VkPipelineCreationFeedback{0, 0});
  VkPipelineCreationFeedback whole{0, 0};
  VkPipelineCreationFeedbackCreateInfo fb{VK_STRUCTURE_TYPE_PIPELINE_CREATION_FEEDBACK_CREATE_INFO};
  fb.pPipelineCreationFeedback = &whole;
  fb.pipelineStageCreationFeedbackCount = static_cast<uint32_t>(stages.size());
  fb.pPipelineStageCreationFeedbacks = stages.data();
  d.pNext = &fb;
  VkPipeline p = VK_NULL_HANDLE;
  ASSERT_EQ(create(d, &p, VK_NULL_HANDLE, cache), VK_SUCCESS);
  EXPECT_TRUE(whole.flags & VK_PIPELINE_CREATION_FEEDBACK_VALID_BIT);
  for (const VkPipelineCreationFeedback& f : stages) EXPECT_TRUE(f.flags & VK_PIPELINE_CREATION_FEEDBACK_VALID_BIT);
  if (vkrt) {  // the first creation compiled: no hit; the second finds every stage in the cache
    EXPECT_FALSE(whole.flags & VK_PIPELINE_CREATION_FEEDBACK_APPLICATION_PIPELINE_CACHE_HIT_BIT);
    EXPECT_GT(whole.duration, 0u);
    for (const VkPipelineCreationFeedback& f : stages)
      EXPECT_FALSE(f.flags & VK_PIPELINE_CREATION_FEEDBACK_APPLICATION_PIPELINE_CACHE_HIT_BIT);
    ASSERT_EQ(create(d, &p, VK_NULL_HANDLE, cache), VK_SUCCESS);
    EXPECT_TRUE(whole.flags & VK_PIPELINE_CREATION_FEEDBACK_APPLICATION_PIPELINE_CACHE_HIT_BIT);
    for (const VkPipelineCreationFeedback& f : stages)
      EXPECT_TRUE(f.flags & VK_PIPELINE_CREATION_FEEDBACK_APPLICATION_PIPELINE_CACHE_HIT_BIT);
  }
}

// Helper for CacheDataCarriesTheStagesIntoAnotherProcess (skipped unless run by it): loads the cache file named by
// VKRT_H7_CACHE, creates the six-group pipeline with FAIL_ON_PIPELINE_COMPILE_REQUIRED from it and from an empty
// cache, and writes "<result with data> <result without> <handles hex>".
TEST_F(RtCacheTest, HelperCreateFromCacheFile) {
  const char* file = std::getenv("VKRT_H7_CACHE");
  if (!std::getenv("VKRT_HELPER_OUT") || !file)
    GTEST_SKIP() << "helper: run by CacheDataCarriesTheStagesIntoAnotherProcess";
  std::ifstream in(file, std::ios::binary);
  std::vector<uint8_t> data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  VkPipelineCache loaded = newCache(data), empty = newCache();
  Desc d = sixGroups(kFail);
  VkPipeline p = VK_NULL_HANDLE, q = VK_NULL_HANDLE;
  // The empty cache first: once loaded, the code is the device's, and later creations need no cache at all.
  VkResult without = create(d, &q, VK_NULL_HANDLE, empty);
  VkResult withData = create(d, &p, VK_NULL_HANDLE, loaded);
  writeOut(std::to_string(withData) + " " + std::to_string(without) + " " + (p ? hexOf(handles(p, 0, 6)) : "-"));
}

TEST_F(RtCacheTest, CacheDataCarriesTheStagesIntoAnotherProcess) {
  VkPipelineCache cache = newCache();
  Desc plain = sixGroups();
  VkPipeline compiled = VK_NULL_HANDLE;
  ASSERT_EQ(create(plain, &compiled, VK_NULL_HANDLE, cache), VK_SUCCESS);
  std::vector<uint8_t> data = cacheData(cache);
  char path[] = "/tmp/vkrt-h7-cache-XXXXXX";
  int fd = mkstemp(path);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(write(fd, data.data(), data.size()), static_cast<ssize_t>(data.size()));
  close(fd);
  std::string line = runHelper("RtCacheTest.HelperCreateFromCacheFile", "VKRT_H7_CACHE", path);
  unlink(path);
  // The other process found the stages in the loaded cache, and not in an empty one.
  ASSERT_EQ(line.rfind(std::to_string(VK_SUCCESS) + " ", 0), 0u) << line;
  if (vkrt) {
    // ...and not in an empty one (another driver may have them in a cache of its own); the handles are those of
    // this process (vkrt's content-derived handles).
    std::string expect = std::to_string(VK_SUCCESS) + " " + std::to_string(VK_PIPELINE_COMPILE_REQUIRED) + " " +
                         hexOf(handles(compiled, 0, 6));
    EXPECT_EQ(line, expect);
  }
}

}  // namespace
}  // namespace vkrt::test
