// vkrt_pipeline_bench: how fast ray tracing pipelines come into being (Google Benchmark).
//
//   RtPipeline16/cold       a 16-stage pipeline (ray generation, miss, 14 procedural-material closest hits), every
//                           stage compiled (the specialization constant changes at every creation, so no cache of any
//                           kind can serve it); counter x_slowest = the creation time over the time of the slowest
//                           of its shaders alone (a one-stage pipeline, measured before the loop);
//   RtPipeline16/deferred   the same through a VkDeferredOperationKHR joined by as many threads as the machine has;
//   RtPipeline16/warmCache  the same 16 stages from a VkPipelineCache that holds them (no live pipeline shares them);
//   LinkLibraries/N         a pipeline linked from N = 1, 10, 100 pipeline libraries of 10 groups each (the
//                           libraries exist already): counter ns_per_group shows whether the time is linear in the
//                           number of groups; the linked pipeline has no stages of its own, so nothing is compiled
//                           (its creation feedback is checked: no stage, no cache involvement).
//
// The loader is pointed at this build's vkrt unless VK_DRIVER_FILES is set (the same program runs on other drivers).
// --benchmark_out=file.json --benchmark_out_format=json writes the figures with the machine, the date and (custom
// context) the driver and the commit.
#include <benchmark/benchmark.h>
#include <vulkan/vulkan.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <thread>
#include <vector>

#include "pipe.rgen.spv.h"
#include "pipe.rmiss.spv.h"
#include "pipe_material.rchit.spv.h"
#include "vkrt_commit.h"

namespace {

[[noreturn]] void fail(const char* what, VkResult r) {
  std::fprintf(stderr, "vkrt_pipeline_bench: %s failed (VkResult %d)\n", what, int(r));
  std::exit(1);
}
#define CHECK(call)                        \
  do {                                     \
    VkResult r_ = (call);                  \
    if (r_ != VK_SUCCESS) fail(#call, r_); \
  } while (0)

struct Rt {
  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkShaderModule rgen = VK_NULL_HANDLE, rmiss = VK_NULL_HANDLE, rchit = VK_NULL_HANDLE;
  PFN_vkCreateRayTracingPipelinesKHR createPipelines = nullptr;
  PFN_vkCreateDeferredOperationKHR createOp = nullptr;
  PFN_vkDeferredOperationJoinKHR join = nullptr;
  PFN_vkGetDeferredOperationResultKHR opResult = nullptr;
  PFN_vkDestroyDeferredOperationKHR destroyOp = nullptr;
  std::string deviceName;

  Rt() {
    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.pApplicationName = "vkrt_pipeline_bench";
    app.apiVersion = VK_API_VERSION_1_3;
    VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    ici.pApplicationInfo = &app;
    CHECK(vkCreateInstance(&ici, nullptr, &instance));
    uint32_t count = 1;
    VkResult r = vkEnumeratePhysicalDevices(instance, &count, &physical);
    if ((r != VK_SUCCESS && r != VK_INCOMPLETE) || count == 0) fail("vkEnumeratePhysicalDevices", r);
    VkPhysicalDeviceProperties props;
    vkGetPhysicalDeviceProperties(physical, &props);
    deviceName = props.deviceName;
    float priority = 1;
    VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    qci.queueCount = 1;
    qci.pQueuePriorities = &priority;
    VkPhysicalDeviceRayTracingPipelineFeaturesKHR rtf{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_FEATURES_KHR};
    rtf.rayTracingPipeline = VK_TRUE;
    VkPhysicalDeviceAccelerationStructureFeaturesKHR asf{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR, &rtf};
    asf.accelerationStructure = VK_TRUE;
    VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES, &asf};
    f12.bufferDeviceAddress = VK_TRUE;
    const char* extensions[] = {VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME,
                                VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME,
                                VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME, VK_KHR_PIPELINE_LIBRARY_EXTENSION_NAME};
    VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, &f12};
    dci.queueCreateInfoCount = 1;
    dci.pQueueCreateInfos = &qci;
    dci.enabledExtensionCount = uint32_t(std::size(extensions));
    dci.ppEnabledExtensionNames = extensions;
    CHECK(vkCreateDevice(physical, &dci, nullptr, &device));
    load(createPipelines, "vkCreateRayTracingPipelinesKHR");
    load(createOp, "vkCreateDeferredOperationKHR");
    load(join, "vkDeferredOperationJoinKHR");
    load(opResult, "vkGetDeferredOperationResultKHR");
    load(destroyOp, "vkDestroyDeferredOperationKHR");

    VkDescriptorSetLayoutBinding b[2] = {
        {0, VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 1, VK_SHADER_STAGE_RAYGEN_BIT_KHR, nullptr},
        {1, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, VK_SHADER_STAGE_RAYGEN_BIT_KHR, nullptr}};
    VkDescriptorSetLayoutCreateInfo dl{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    dl.bindingCount = 2;
    dl.pBindings = b;
    CHECK(vkCreateDescriptorSetLayout(device, &dl, nullptr, &setLayout));
    VkPipelineLayoutCreateInfo pl{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    pl.setLayoutCount = 1;
    pl.pSetLayouts = &setLayout;
    CHECK(vkCreatePipelineLayout(device, &pl, nullptr, &layout));
    rgen = module(kSpv_pipe_rgen, sizeof kSpv_pipe_rgen);
    rmiss = module(kSpv_pipe_rmiss, sizeof kSpv_pipe_rmiss);
    rchit = module(kSpv_pipe_material_rchit, sizeof kSpv_pipe_material_rchit);
  }
  ~Rt() {
    for (VkShaderModule m : {rgen, rmiss, rchit}) vkDestroyShaderModule(device, m, nullptr);
    vkDestroyPipelineLayout(device, layout, nullptr);
    vkDestroyDescriptorSetLayout(device, setLayout, nullptr);
    vkDestroyDevice(device, nullptr);
    vkDestroyInstance(instance, nullptr);
  }
  template <class F>
  void load(F& f, const char* name) {
    f = reinterpret_cast<F>(vkGetDeviceProcAddr(device, name));
    if (!f) fail(name, VK_ERROR_EXTENSION_NOT_PRESENT);
  }
  VkShaderModule module(const uint32_t* words, size_t bytes) {
    VkShaderModuleCreateInfo sm{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    sm.codeSize = bytes;
    sm.pCode = words;
    VkShaderModule m;
    CHECK(vkCreateShaderModule(device, &sm, nullptr, &m));
    return m;
  }
};

Rt& rt() {
  static Rt r;
  return r;
}

// The stages and groups of one pipeline or library, with a specialization constant per stage.
struct Description {
  std::vector<uint32_t> variants;  // one per stage, each pointed at by its stage's specialization info
  VkSpecializationMapEntry entry{0, 0, sizeof(uint32_t)};
  std::vector<VkSpecializationInfo> specs;
  std::vector<VkPipelineShaderStageCreateInfo> stages;
  std::vector<VkRayTracingShaderGroupCreateInfoKHR> groups;

  void add(VkShaderStageFlagBits stage, VkShaderModule module, uint32_t variant) {
    variants.push_back(variant);
    VkPipelineShaderStageCreateInfo s{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    s.stage = stage;
    s.module = module;
    s.pName = "main";
    stages.push_back(s);
    VkRayTracingShaderGroupCreateInfoKHR g{VK_STRUCTURE_TYPE_RAY_TRACING_SHADER_GROUP_CREATE_INFO_KHR};
    g.generalShader = g.closestHitShader = g.anyHitShader = g.intersectionShader = VK_SHADER_UNUSED_KHR;
    const uint32_t index = uint32_t(stages.size() - 1);
    if (stage == VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR) {
      g.type = VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR;
      g.closestHitShader = index;
    } else {
      g.type = VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR;
      g.generalShader = index;
    }
    groups.push_back(g);
  }
  // Points the stages at their specialization data (after the last add()).
  void seal() {
    specs.resize(stages.size());
    for (size_t i = 0; i < stages.size(); ++i) {
      specs[i] = {1, &entry, sizeof(uint32_t), &variants[i]};
      stages[i].pSpecializationInfo = &specs[i];
    }
  }
};

constexpr uint32_t kStages = 16;
const VkRayTracingPipelineInterfaceCreateInfoKHR kInterface{
    VK_STRUCTURE_TYPE_RAY_TRACING_PIPELINE_INTERFACE_CREATE_INFO_KHR, nullptr, 16, 8};

// A 16-stage description whose shaders are all new to the device when `first` was never used before.
Description sixteen(uint32_t first) {
  Description d;
  d.add(VK_SHADER_STAGE_RAYGEN_BIT_KHR, rt().rgen, first);
  d.add(VK_SHADER_STAGE_MISS_BIT_KHR, rt().rmiss, first + 1);
  for (uint32_t i = 2; i < kStages; ++i) d.add(VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR, rt().rchit, first + i);
  d.seal();
  return d;
}

VkRayTracingPipelineCreateInfoKHR createInfo(const Description& d, VkPipelineCreateFlags flags = 0) {
  VkRayTracingPipelineCreateInfoKHR ci{VK_STRUCTURE_TYPE_RAY_TRACING_PIPELINE_CREATE_INFO_KHR};
  ci.flags = flags;
  ci.stageCount = uint32_t(d.stages.size());
  ci.pStages = d.stages.data();
  ci.groupCount = uint32_t(d.groups.size());
  ci.pGroups = d.groups.data();
  ci.maxPipelineRayRecursionDepth = 1;
  ci.layout = rt().layout;
  if (flags & VK_PIPELINE_CREATE_LIBRARY_BIT_KHR) ci.pLibraryInterface = &kInterface;
  return ci;
}

VkPipeline create(const VkRayTracingPipelineCreateInfoKHR& ci, VkPipelineCache cache = VK_NULL_HANDLE) {
  VkPipeline p;
  CHECK(rt().createPipelines(rt().device, VK_NULL_HANDLE, cache, 1, &ci, nullptr, &p));
  return p;
}

// Fresh specialization values: every creation that takes its variants from here compiles every stage.
uint32_t freshVariants(uint32_t n) {
  static uint32_t next = 1000;
  const uint32_t first = next;
  next += n;
  return first;
}

double seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

// The time of the slowest shader of the 16 compiled alone (a one-stage pipeline of each kind; the median of 3).
double slowestShaderSeconds() {
  double slowest = 0;
  for (int kind = 0; kind < 3; ++kind) {
    std::vector<double> t;
    for (int rep = 0; rep < 3; ++rep) {
      Description d;
      const uint32_t v = freshVariants(1);
      if (kind == 0) d.add(VK_SHADER_STAGE_RAYGEN_BIT_KHR, rt().rgen, v);
      if (kind == 1) d.add(VK_SHADER_STAGE_MISS_BIT_KHR, rt().rmiss, v);
      if (kind == 2) d.add(VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR, rt().rchit, v);
      d.seal();
      // A pipeline needs a ray generation shader (VUID-VkRayTracingPipelineCreateInfoKHR-stage-03425); the other
      // shaders are compiled alone as a library.
      const auto start = std::chrono::steady_clock::now();
      VkPipeline p = create(createInfo(d, kind == 0 ? 0 : VK_PIPELINE_CREATE_LIBRARY_BIT_KHR));
      t.push_back(seconds(start));
      vkDestroyPipeline(rt().device, p, nullptr);
    }
    std::sort(t.begin(), t.end());
    slowest = std::max(slowest, t[1]);
  }
  return slowest;
}

void BM_RtPipeline16_cold(benchmark::State& state) {
  const double slowest = slowestShaderSeconds();
  double total = 0;
  for (auto _ : state) {
    Description d = sixteen(freshVariants(kStages));
    const auto start = std::chrono::steady_clock::now();
    VkPipeline p = create(createInfo(d));
    total += seconds(start);
    vkDestroyPipeline(rt().device, p, nullptr);
  }
  state.counters["slowest_shader_ms"] = slowest * 1e3;
  state.counters["x_slowest"] = total / double(state.iterations()) / slowest;
}

void BM_RtPipeline16_deferred(benchmark::State& state) {
  const unsigned joiners = std::max(1u, std::thread::hardware_concurrency());
  for (auto _ : state) {
    Description d = sixteen(freshVariants(kStages));
    VkRayTracingPipelineCreateInfoKHR ci = createInfo(d);
    VkDeferredOperationKHR op;
    CHECK(rt().createOp(rt().device, nullptr, &op));
    VkPipeline p = VK_NULL_HANDLE;
    VkResult r = rt().createPipelines(rt().device, op, VK_NULL_HANDLE, 1, &ci, nullptr, &p);
    if (r == VK_OPERATION_DEFERRED_KHR) {
      // The application's threads join the operation (the calling thread is one of them).
      std::vector<std::thread> threads;
      for (unsigned t = 1; t < joiners; ++t)
        threads.emplace_back([op] {
          while (rt().join(rt().device, op) == VK_THREAD_IDLE_KHR) std::this_thread::yield();
        });
      while (rt().join(rt().device, op) == VK_THREAD_IDLE_KHR) std::this_thread::yield();
      for (std::thread& t : threads) t.join();
      // VK_THREAD_DONE_KHR on this thread does not mean complete: the result is read once every joiner returned.
      r = rt().opResult(rt().device, op);
    } else if (r == VK_OPERATION_NOT_DEFERRED_KHR) {
      r = VK_SUCCESS;
    }
    if (r != VK_SUCCESS) fail("the deferred vkCreateRayTracingPipelinesKHR", r);
    rt().destroyOp(rt().device, op, nullptr);
    vkDestroyPipeline(rt().device, p, nullptr);
  }
  state.counters["joining_threads"] = joiners;
}

void BM_RtPipeline16_warmCache(benchmark::State& state) {
  VkPipelineCacheCreateInfo cci{VK_STRUCTURE_TYPE_PIPELINE_CACHE_CREATE_INFO};
  VkPipelineCache cache;
  CHECK(vkCreatePipelineCache(rt().device, &cci, nullptr, &cache));
  Description d = sixteen(freshVariants(kStages));
  VkRayTracingPipelineCreateInfoKHR ci = createInfo(d);
  vkDestroyPipeline(rt().device, create(ci, cache), nullptr);  // fills the cache
  VkPipelineCreationFeedback fb{};
  VkPipelineCreationFeedbackCreateInfo fbi{VK_STRUCTURE_TYPE_PIPELINE_CREATION_FEEDBACK_CREATE_INFO};
  fbi.pPipelineCreationFeedback = &fb;
  ci.pNext = &fbi;
  vkDestroyPipeline(rt().device, create(ci, cache), nullptr);
  ci.pNext = nullptr;
  if (!(fb.flags & VK_PIPELINE_CREATION_FEEDBACK_APPLICATION_PIPELINE_CACHE_HIT_BIT))
    state.SkipWithError("the warm cache did not hit");  // NVIDIA, for one, may not set the bit
  for (auto _ : state) {
    // The previous pipeline is gone, so the code is loaded from the cache (not shared from a live pipeline).
    VkPipeline p = create(ci, cache);
    vkDestroyPipeline(rt().device, p, nullptr);
  }
  vkDestroyPipelineCache(rt().device, cache, nullptr);
}

// 100 libraries of 10 groups each, made once: a ray generation group (a linked pipeline needs one,
// VUID-VkRayTracingPipelineCreateInfoKHR-stage-03425) and 9 hit groups, the variants 0..9 in every library, so that
// the device compiles 10 shaders for all of them and shares them.
struct Libraries {
  std::vector<VkPipeline> libs;
  Libraries() {
    for (int k = 0; k < 100; ++k) {
      Description d;
      d.add(VK_SHADER_STAGE_RAYGEN_BIT_KHR, rt().rgen, 0);
      for (uint32_t g = 1; g < 10; ++g) d.add(VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR, rt().rchit, g);
      d.seal();
      libs.push_back(create(createInfo(d, VK_PIPELINE_CREATE_LIBRARY_BIT_KHR)));
    }
  }
  ~Libraries() {
    for (VkPipeline p : libs) vkDestroyPipeline(rt().device, p, nullptr);
  }
};

Libraries& libraries() {
  static Libraries l;
  return l;
}

void BM_LinkLibraries(benchmark::State& state) {
  const uint32_t n = uint32_t(state.range(0));
  VkPipelineLibraryCreateInfoKHR li{VK_STRUCTURE_TYPE_PIPELINE_LIBRARY_CREATE_INFO_KHR};
  li.libraryCount = n;
  li.pLibraries = libraries().libs.data();
  VkPipelineCreationFeedback fb{};
  VkPipelineCreationFeedbackCreateInfo fbi{VK_STRUCTURE_TYPE_PIPELINE_CREATION_FEEDBACK_CREATE_INFO};
  fbi.pPipelineCreationFeedback = &fb;
  VkRayTracingPipelineCreateInfoKHR ci{VK_STRUCTURE_TYPE_RAY_TRACING_PIPELINE_CREATE_INFO_KHR, &fbi};
  ci.pLibraryInfo = &li;
  ci.pLibraryInterface = &kInterface;
  ci.maxPipelineRayRecursionDepth = 1;
  ci.layout = rt().layout;
  for (auto _ : state) {
    VkPipeline p = create(ci);
    vkDestroyPipeline(rt().device, p, nullptr);
  }
  // The linked pipeline has no stage of its own: nothing to compile, and nothing came from a cache.
  if (fb.flags & VK_PIPELINE_CREATION_FEEDBACK_APPLICATION_PIPELINE_CACHE_HIT_BIT)
    state.SkipWithError("a pipeline without stages reported a cache hit");
  state.counters["groups"] = 10.0 * n;
  state.counters["ns_per_group"] = benchmark::Counter(10.0 * n * double(state.iterations()),
                                                      benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

BENCHMARK(BM_RtPipeline16_cold)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);
BENCHMARK(BM_RtPipeline16_deferred)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);
BENCHMARK(BM_RtPipeline16_warmCache)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_LinkLibraries)->Arg(1)->Arg(10)->Arg(100)->Unit(benchmark::kMicrosecond)->UseRealTime();

}  // namespace

int main(int argc, char** argv) {
  setenv("VK_DRIVER_FILES", VKRT_BENCH_ICD_JSON, 0);  // unless set already
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::AddCustomContext("driver", rt().deviceName);
  benchmark::AddCustomContext("commit", VKRT_COMMIT);
  if (const char* t = std::getenv("VKRT_THREADS")) benchmark::AddCustomContext("VKRT_THREADS", t);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
