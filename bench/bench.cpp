// vkrt's compute benchmark: SAXPY (1M floats), a 256x256 float matrix multiply and a 512x512 Mandelbrot
// (256 iterations) dispatched through the Vulkan loader to vkrt, next to the same kernels in C++ (single
// threaded, -O2); and vkCreateComputePipelines from a cold cache (compiling) and a warm VkPipelineCache.
//
// The loader is pointed at this build's vkrt (VK_DRIVER_FILES) unless VK_DRIVER_FILES is set already.
// VKRT_THREADS=1 runs vkrt's dispatches on one thread, like the native kernels.
#include <benchmark/benchmark.h>
#include <vulkan/vulkan.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "mandelbrot.comp.spv.h"
#include "matmul.comp.spv.h"
#include "native_kernels.hpp"
#include "saxpy.comp.spv.h"

namespace vkrt::bench {
namespace {

[[noreturn]] void fail(const char* what, VkResult r) {
  std::fprintf(stderr, "vkrt_bench: %s failed (VkResult %d)\n", what, int(r));
  std::exit(1);
}
#define CHECK(call)                        \
  do {                                     \
    VkResult r_ = (call);                  \
    if (r_ != VK_SUCCESS) fail(#call, r_); \
  } while (0)

struct Context {
  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
  VkCommandPool pool = VK_NULL_HANDLE;

  Context() {
    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.pApplicationName = "vkrt_bench";
    app.apiVersion = VK_API_VERSION_1_3;
    VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    ici.pApplicationInfo = &app;
    CHECK(vkCreateInstance(&ici, nullptr, &instance));
    uint32_t count = 1;
    VkResult r = vkEnumeratePhysicalDevices(instance, &count, &physical);
    if ((r != VK_SUCCESS && r != VK_INCOMPLETE) || count == 0) fail("vkEnumeratePhysicalDevices", r);
    VkPhysicalDeviceProperties props;
    vkGetPhysicalDeviceProperties(physical, &props);
    std::fprintf(stderr, "device: %s\n", props.deviceName);
    float priority = 1;
    VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    qci.queueCount = 1;
    qci.pQueuePriorities = &priority;
    VkPhysicalDeviceVulkan13Features f13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
    f13.maintenance4 = VK_TRUE;
    VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, &f13};
    dci.queueCreateInfoCount = 1;
    dci.pQueueCreateInfos = &qci;
    CHECK(vkCreateDevice(physical, &dci, nullptr, &device));
    vkGetDeviceQueue(device, 0, 0, &queue);
    VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    CHECK(vkCreateCommandPool(device, &pci, nullptr, &pool));
  }
  ~Context() {
    vkDestroyCommandPool(device, pool, nullptr);
    vkDestroyDevice(device, nullptr);
    vkDestroyInstance(instance, nullptr);
  }
};

Context& ctx() {
  static Context c;
  return c;
}

struct Buffer {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  void* data = nullptr;
  VkDeviceSize size = 0;

  explicit Buffer(VkDeviceSize bytes) : size(bytes) {
    VkDevice d = ctx().device;
    VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    bci.size = bytes;
    bci.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    CHECK(vkCreateBuffer(d, &bci, nullptr, &buffer));
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(d, buffer, &req);
    VkPhysicalDeviceMemoryProperties mp;
    vkGetPhysicalDeviceMemoryProperties(ctx().physical, &mp);
    const VkMemoryPropertyFlags want = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    uint32_t type = 0;
    while (type < mp.memoryTypeCount &&
           !((req.memoryTypeBits >> type & 1) && (mp.memoryTypes[type].propertyFlags & want) == want))
      ++type;
    VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    ai.allocationSize = req.size;
    ai.memoryTypeIndex = type;
    CHECK(vkAllocateMemory(d, &ai, nullptr, &memory));
    CHECK(vkBindBufferMemory(d, buffer, memory, 0));
    CHECK(vkMapMemory(d, memory, 0, VK_WHOLE_SIZE, 0, &data));
  }
  ~Buffer() {
    vkDestroyBuffer(ctx().device, buffer, nullptr);
    vkFreeMemory(ctx().device, memory, nullptr);
  }
  template <class T>
  T* as() {
    return static_cast<T*>(data);
  }
};

// A compute pipeline whose set 0 has `bindings` storage buffers, with `pushBytes` of push constants.
struct Kernel {
  VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkShaderModule module = VK_NULL_HANDLE;
  VkPipeline pipeline = VK_NULL_HANDLE;
  VkDescriptorPool pool = VK_NULL_HANDLE;
  VkDescriptorSet set = VK_NULL_HANDLE;
  VkCommandBuffer cb = VK_NULL_HANDLE;

  Kernel(const uint32_t* words, size_t bytes, uint32_t bindings, uint32_t pushBytes) {
    VkDevice d = ctx().device;
    std::vector<VkDescriptorSetLayoutBinding> b;
    for (uint32_t i = 0; i < bindings; ++i)
      b.push_back({i, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr});
    VkDescriptorSetLayoutCreateInfo dl{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    dl.bindingCount = bindings;
    dl.pBindings = b.data();
    CHECK(vkCreateDescriptorSetLayout(d, &dl, nullptr, &setLayout));
    VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, pushBytes};
    VkPipelineLayoutCreateInfo pl{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    pl.setLayoutCount = 1;
    pl.pSetLayouts = &setLayout;
    pl.pushConstantRangeCount = 1;
    pl.pPushConstantRanges = &range;
    CHECK(vkCreatePipelineLayout(d, &pl, nullptr, &layout));
    VkShaderModuleCreateInfo sm{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    sm.codeSize = bytes;
    sm.pCode = words;
    CHECK(vkCreateShaderModule(d, &sm, nullptr, &module));
    pipeline = createPipeline(VK_NULL_HANDLE);
    VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, bindings};
    VkDescriptorPoolCreateInfo dp{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    dp.maxSets = 1;
    dp.poolSizeCount = 1;
    dp.pPoolSizes = &size;
    CHECK(vkCreateDescriptorPool(d, &dp, nullptr, &pool));
    VkDescriptorSetAllocateInfo da{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    da.descriptorPool = pool;
    da.descriptorSetCount = 1;
    da.pSetLayouts = &setLayout;
    CHECK(vkAllocateDescriptorSets(d, &da, &set));
  }
  ~Kernel() {
    VkDevice d = ctx().device;
    if (cb) vkFreeCommandBuffers(d, ctx().pool, 1, &cb);
    vkDestroyDescriptorPool(d, pool, nullptr);
    vkDestroyPipeline(d, pipeline, nullptr);
    vkDestroyShaderModule(d, module, nullptr);
    vkDestroyPipelineLayout(d, layout, nullptr);
    vkDestroyDescriptorSetLayout(d, setLayout, nullptr);
  }

  VkPipeline createPipeline(VkPipelineCache cache, VkPipelineCreationFeedback* feedback = nullptr) {
    VkPipelineCreationFeedbackCreateInfo fb{VK_STRUCTURE_TYPE_PIPELINE_CREATION_FEEDBACK_CREATE_INFO};
    fb.pPipelineCreationFeedback = feedback;
    VkComputePipelineCreateInfo ci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO, feedback ? &fb : nullptr};
    ci.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    ci.stage.module = module;
    ci.stage.pName = "main";
    ci.layout = layout;
    VkPipeline p = VK_NULL_HANDLE;
    CHECK(vkCreateComputePipelines(ctx().device, cache, 1, &ci, nullptr, &p));
    return p;
  }

  void bind(uint32_t binding, const Buffer& b) {
    VkDescriptorBufferInfo bi{b.buffer, 0, VK_WHOLE_SIZE};
    VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    w.dstSet = set;
    w.dstBinding = binding;
    w.descriptorCount = 1;
    w.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    w.pBufferInfo = &bi;
    vkUpdateDescriptorSets(ctx().device, 1, &w, 0, nullptr);
  }

  // Records (once) a command buffer with the push constants and one dispatch.
  void record(const void* push, uint32_t pushBytes, uint32_t gx, uint32_t gy) {
    VkCommandBufferAllocateInfo cai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    cai.commandPool = ctx().pool;
    cai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    cai.commandBufferCount = 1;
    CHECK(vkAllocateCommandBuffers(ctx().device, &cai, &cb));
    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    CHECK(vkBeginCommandBuffer(cb, &bi));
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, layout, 0, 1, &set, 0, nullptr);
    vkCmdPushConstants(cb, layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, pushBytes, push);
    vkCmdDispatch(cb, gx, gy, 1);
    CHECK(vkEndCommandBuffer(cb));
  }
  // Submits the recorded command buffer and waits for it.
  void run() {
    VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cb;
    CHECK(vkQueueSubmit(ctx().queue, 1, &si, VK_NULL_HANDLE));
    CHECK(vkQueueWaitIdle(ctx().queue));
  }
};

void mismatch(benchmark::State& state, const char* what) { state.SkipWithError(what); }

// ---- SAXPY, 1M floats

constexpr uint32_t kSaxpyN = 1u << 20;

void fillSaxpy(std::vector<float>& x, std::vector<float>& y) {
  x.resize(kSaxpyN);
  y.resize(kSaxpyN);
  for (uint32_t i = 0; i < kSaxpyN; ++i) {
    x[i] = float(i % 1000) * 0.25f;
    y[i] = float(i % 77) - 3.0f;
  }
}

void BM_Saxpy_vkrt(benchmark::State& state) {
  std::vector<float> x, y;
  fillSaxpy(x, y);
  Buffer bx(kSaxpyN * 4), by(kSaxpyN * 4);
  std::memcpy(bx.data, x.data(), kSaxpyN * 4);
  std::memcpy(by.data, y.data(), kSaxpyN * 4);
  Kernel k(kSpv_saxpy_comp, sizeof kSpv_saxpy_comp, 2, 8);
  k.bind(0, bx);
  k.bind(1, by);
  struct {
    float a;
    uint32_t n;
  } push{1.5f, kSaxpyN};
  k.record(&push, sizeof push, kSaxpyN / 256, 1);
  k.run();
  std::vector<float> want = y;
  saxpy(1.5f, x.data(), want.data(), kSaxpyN);
  if (std::memcmp(want.data(), by.data, kSaxpyN * 4) != 0)
    return mismatch(state, "SAXPY results differ from the native kernel");
  for (auto _ : state) k.run();
  state.SetBytesProcessed(int64_t(state.iterations()) * kSaxpyN * 12);
}

void BM_Saxpy_native(benchmark::State& state) {
  std::vector<float> x, y;
  fillSaxpy(x, y);
  for (auto _ : state) {
    saxpy(1.5f, x.data(), y.data(), kSaxpyN);
    benchmark::DoNotOptimize(y.data());
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(int64_t(state.iterations()) * kSaxpyN * 12);
}

// ---- matrix multiply, 256x256

constexpr uint32_t kMatN = 256;

void fillMat(std::vector<float>& a, std::vector<float>& b) {
  a.resize(kMatN * kMatN);
  b.resize(kMatN * kMatN);
  for (uint32_t i = 0; i < kMatN * kMatN; ++i) {
    a[i] = float(i % 17) * 0.125f - 1.0f;
    b[i] = float(i % 13) * 0.25f - 1.5f;
  }
}

void BM_Matmul_vkrt(benchmark::State& state) {
  std::vector<float> a, b;
  fillMat(a, b);
  const size_t bytes = size_t(kMatN) * kMatN * 4;
  Buffer ba(bytes), bb(bytes), bc(bytes);
  std::memcpy(ba.data, a.data(), bytes);
  std::memcpy(bb.data, b.data(), bytes);
  Kernel k(kSpv_matmul_comp, sizeof kSpv_matmul_comp, 3, 4);
  k.bind(0, ba);
  k.bind(1, bb);
  k.bind(2, bc);
  uint32_t n = kMatN;
  k.record(&n, 4, kMatN / 16, kMatN / 16);
  k.run();
  std::vector<float> want(kMatN * kMatN);
  matmul(a.data(), b.data(), want.data(), kMatN);
  // The values are exact multiples of 1/32 with small sums: any summation order gives the same floats.
  if (std::memcmp(want.data(), bc.data, bytes) != 0)
    return mismatch(state, "matmul results differ from the native kernel");
  for (auto _ : state) k.run();
  state.counters["GFLOPS"] =
      benchmark::Counter(double(state.iterations()) * 2.0 * kMatN * kMatN * kMatN * 1e-9, benchmark::Counter::kIsRate);
}

void BM_Matmul_native(benchmark::State& state) {
  std::vector<float> a, b, c(kMatN * kMatN);
  fillMat(a, b);
  for (auto _ : state) {
    matmul(a.data(), b.data(), c.data(), kMatN);
    benchmark::DoNotOptimize(c.data());
    benchmark::ClobberMemory();
  }
  state.counters["GFLOPS"] =
      benchmark::Counter(double(state.iterations()) * 2.0 * kMatN * kMatN * kMatN * 1e-9, benchmark::Counter::kIsRate);
}

// ---- Mandelbrot, 512x512, 256 iterations

constexpr uint32_t kMandelSize = 512, kMandelIterations = 256;

void BM_Mandelbrot_vkrt(benchmark::State& state) {
  Buffer out(size_t(kMandelSize) * kMandelSize * 4);
  Kernel k(kSpv_mandelbrot_comp, sizeof kSpv_mandelbrot_comp, 1, 8);
  k.bind(0, out);
  uint32_t push[2] = {kMandelSize, kMandelIterations};
  k.record(push, sizeof push, kMandelSize / 16, kMandelSize / 16);
  k.run();
  std::vector<uint32_t> want(kMandelSize * kMandelSize);
  mandelbrot(want.data(), kMandelSize, kMandelIterations);
  // Contraction into fused multiply-adds (allowed in SPIR-V) may move a few boundary pixels by an iteration.
  size_t differ = 0;
  for (size_t i = 0; i < want.size(); ++i) differ += want[i] != out.as<uint32_t>()[i];
  if (differ > want.size() / 100) return mismatch(state, "Mandelbrot results differ from the native kernel");
  state.counters["pixels_differing"] = double(differ);
  for (auto _ : state) k.run();
}

void BM_Mandelbrot_native(benchmark::State& state) {
  std::vector<uint32_t> out(kMandelSize * kMandelSize);
  for (auto _ : state) {
    mandelbrot(out.data(), kMandelSize, kMandelIterations);
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
}

// ---- pipeline creation (the matmul shader): cold compiles, warm loads from a VkPipelineCache

void BM_PipelineCreate_cold(benchmark::State& state) {
  Kernel k(kSpv_matmul_comp, sizeof kSpv_matmul_comp, 3, 4);
  vkDestroyPipeline(ctx().device, k.pipeline, nullptr);
  k.pipeline = VK_NULL_HANDLE;
  for (auto _ : state) {
    // No cache and no live pipeline of this shader: every creation compiles.
    VkPipeline p = k.createPipeline(VK_NULL_HANDLE);
    vkDestroyPipeline(ctx().device, p, nullptr);
  }
}

void BM_PipelineCreate_warmCache(benchmark::State& state) {
  Kernel k(kSpv_matmul_comp, sizeof kSpv_matmul_comp, 3, 4);
  vkDestroyPipeline(ctx().device, k.pipeline, nullptr);
  k.pipeline = VK_NULL_HANDLE;
  VkPipelineCacheCreateInfo ci{VK_STRUCTURE_TYPE_PIPELINE_CACHE_CREATE_INFO};
  VkPipelineCache cache;
  CHECK(vkCreatePipelineCache(ctx().device, &ci, nullptr, &cache));
  vkDestroyPipeline(ctx().device, k.createPipeline(cache), nullptr);  // fills the cache
  VkPipelineCreationFeedback fb{};
  vkDestroyPipeline(ctx().device, k.createPipeline(cache, &fb), nullptr);
  if (!(fb.flags & VK_PIPELINE_CREATION_FEEDBACK_APPLICATION_PIPELINE_CACHE_HIT_BIT)) {
    vkDestroyPipelineCache(ctx().device, cache, nullptr);
    return mismatch(state, "the warm cache did not hit");
  }
  for (auto _ : state) {
    // The previous pipeline is gone, so its code is loaded from the cache (not shared from a live pipeline).
    VkPipeline p = k.createPipeline(cache);
    vkDestroyPipeline(ctx().device, p, nullptr);
  }
  vkDestroyPipelineCache(ctx().device, cache, nullptr);
}

BENCHMARK(BM_Saxpy_vkrt)->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK(BM_Saxpy_native)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Matmul_vkrt)->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK(BM_Matmul_native)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Mandelbrot_vkrt)->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK(BM_Mandelbrot_native)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_PipelineCreate_cold)->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK(BM_PipelineCreate_warmCache)->Unit(benchmark::kMicrosecond)->UseRealTime();

}  // namespace
}  // namespace vkrt::bench

int main(int argc, char** argv) {
  setenv("VK_DRIVER_FILES", VKRT_BENCH_ICD_JSON, 0);  // unless set already
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
