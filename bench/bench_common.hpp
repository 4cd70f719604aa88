// What vkrt's benchmark programs (vkrt_bench, vkrt_tracebench) share: the Vulkan device through the loader, host
// visible buffers, acceleration structure builds with vkCmdBuildAccelerationStructuresKHR, the thread count of
// the raw Embree side and its work loop, the integer hash the shaders reimplement, and CPU time.
#pragma once

#include <vulkan/vulkan.h>

#include <atomic>
#include <cstdint>
#include <memory>
#include <thread>
#include <vector>

namespace vkrt::bench {

[[noreturn]] void fail(const char* what, VkResult r);
#define CHECK(call)                                       \
  do {                                                    \
    VkResult r_ = (call);                                 \
    if (r_ != VK_SUCCESS) ::vkrt::bench::fail(#call, r_); \
  } while (0)

struct Context {
  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
  VkCommandPool pool = VK_NULL_HANDLE;
  // VK_KHR_acceleration_structure and VK_KHR_ray_query with their features, where the driver has them (the
  // ambient occlusion benchmark needs them; the compute kernels do not); VK_KHR_ray_tracing_pipeline likewise.
  bool rayQuery = false;
  bool rayTracingPipeline = false;
  PFN_vkCreateAccelerationStructureKHR createAs = nullptr;
  PFN_vkDestroyAccelerationStructureKHR destroyAs = nullptr;
  PFN_vkGetAccelerationStructureBuildSizesKHR buildSizes = nullptr;
  PFN_vkCmdBuildAccelerationStructuresKHR cmdBuild = nullptr;
  PFN_vkGetAccelerationStructureDeviceAddressKHR asAddress = nullptr;
  PFN_vkCreateRayTracingPipelinesKHR createRtPipelines = nullptr;
  PFN_vkGetRayTracingShaderGroupHandlesKHR groupHandles = nullptr;
  PFN_vkCmdTraceRaysKHR cmdTraceRays = nullptr;
  // accelerationStructureHostCommands, where the driver has it (builds on the host, joined deferred operations).
  bool hostCommands = false;
  PFN_vkBuildAccelerationStructuresKHR hostBuild = nullptr;
  PFN_vkCreateDeferredOperationKHR createDeferred = nullptr;
  PFN_vkDeferredOperationJoinKHR joinDeferred = nullptr;
  PFN_vkGetDeferredOperationResultKHR deferredResult = nullptr;
  PFN_vkDestroyDeferredOperationKHR destroyDeferred = nullptr;

  Context();
  ~Context();
  template <class F>
  void load(F& f, const char* name) {
    f = reinterpret_cast<F>(vkGetDeviceProcAddr(device, name));
    if (!f) fail(name, VK_ERROR_EXTENSION_NOT_PRESENT);
  }
  // A one-time command buffer: record(cb), then submit and wait.
  template <class F>
  void submitOnce(F record) {
    VkCommandBuffer cb = allocate();
    record(cb);
    submit(cb);
    vkFreeCommandBuffers(device, pool, 1, &cb);
  }
  VkCommandBuffer allocate();
  void submit(VkCommandBuffer cb);  // ends nothing: cb must be recorded; waits for the queue
};

Context& ctx();

struct Buffer {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  void* data = nullptr;
  VkDeviceSize size = 0;

  explicit Buffer(VkDeviceSize bytes, VkBufferUsageFlags usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;
  ~Buffer();
  VkDeviceAddress address() const;
  template <class T>
  T* as() {
    return static_cast<T*>(data);
  }
};

// Acceleration structures built with vkCmdBuildAccelerationStructuresKHR (PREFER_FAST_TRACE), with the buffers
// they live in; destroyed with this object.
struct AccelStructures {
  std::vector<std::unique_ptr<Buffer>> buffers;
  std::vector<VkAccelerationStructureKHR> structures;

  static constexpr VkBufferUsageFlags kInput =
      VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;

  AccelStructures() = default;
  AccelStructures(const AccelStructures&) = delete;
  AccelStructures& operator=(const AccelStructures&) = delete;
  ~AccelStructures();

  Buffer& buffer(VkDeviceSize bytes, VkBufferUsageFlags usage);
  VkDeviceAddress upload(const void* data, size_t bytes);
  // A triangle geometry (float3 vertices, uint32 indices) in buffers of its own.
  VkAccelerationStructureGeometryKHR triangles(const float* vertices, size_t vertexCount, const uint32_t* indices,
                                               size_t indexCount);
  // An instance geometry over `count` instances in a buffer of its own.
  VkAccelerationStructureGeometryKHR instances(const VkAccelerationStructureInstanceKHR* instances, size_t count);
  // A structure of `type` built from `g` with `primitives` primitives, with a barrier after it that lets the
  // builds and shaders after it read it.
  VkAccelerationStructureKHR build(VkAccelerationStructureTypeKHR type, const VkAccelerationStructureGeometryKHR& g,
                                   uint32_t primitives);
  // The fastest of `repeat` builds like build()'s, each into a fresh structure (destroyed after it, untimed, as
  // an application's first build finds no earlier content to free): seconds from submit to idle.
  double timeBuilds(VkAccelerationStructureTypeKHR type, const VkAccelerationStructureGeometryKHR& g,
                    uint32_t primitives, uint32_t repeat);
  VkDeviceAddress address(VkAccelerationStructureKHR as) const;
  // One identity instance of `blas`, mask 0xff, everything else zero.
  VkAccelerationStructureInstanceKHR identityInstance(VkAccelerationStructureKHR blas) const;
};

// A shader module of SPIR-V `words` (`bytes` long) on ctx()'s device.
VkShaderModule shaderModule(const uint32_t* words, size_t bytes);

// A ray tracing pipeline of three groups (0 raygen, 1 miss, 2 hit) with one record each in its SBT, its layout of
// one descriptor set layout, and one descriptor set; all destroyed with this object.
struct RayPipeline {
  VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkPipeline pipeline = VK_NULL_HANDLE;
  VkDescriptorPool pool = VK_NULL_HANDLE;
  VkDescriptorSet set = VK_NULL_HANDLE;
  std::unique_ptr<Buffer> sbt;
  VkStridedDeviceAddressRegionKHR raygen{}, miss{}, hit{}, callable{};

  RayPipeline() = default;
  RayPipeline(const RayPipeline&) = delete;
  RayPipeline& operator=(const RayPipeline&) = delete;
  ~RayPipeline();
  // With setLayout and layout made: the pipeline (maxPipelineRayRecursionDepth 1) of `stages` and `groups`,
  // whose modules it then destroys, the SBT, and a set from a pool of `sizes`.
  void create(const VkPipelineShaderStageCreateInfo* stages, uint32_t stageCount,
              const VkRayTracingShaderGroupCreateInfoKHR (&groups)[3], const VkDescriptorPoolSize* sizes,
              uint32_t sizeCount);
};

// The thread count of both sides: VKRT_THREADS as vkrt reads it (1..256), else the hardware threads.
unsigned workerThreads();

// Runs fn(begin, end) over [0, count) in chunks of `chunk` on workerThreads() std::threads (the calling thread is
// one of them), which take chunks from an atomic counter as they go: a thread that loses its core on a loaded
// machine holds up no fixed share (vkrt's pool hands out work in chunks the same way).
template <class F>
void parallelChunks(uint64_t count, uint64_t chunk, F fn) {
  std::atomic<uint64_t> next{0};
  auto work = [&] {
    for (uint64_t p; (p = next.fetch_add(chunk, std::memory_order_relaxed)) < count;)
      fn(p, p + chunk < count ? p + chunk : count);
  };
  std::vector<std::thread> threads;
  for (unsigned t = 1; t < workerThreads(); ++t) threads.emplace_back(work);
  work();
  for (auto& t : threads) t.join();
}

// A 32-bit integer hash (xor-shift-multiply, "lowbias32"); the benchmark shaders have the same one.
inline uint32_t hash32(uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}

// The process's CPU time (every thread's), in seconds.
double processCpuSeconds();
// Real time, in seconds from an arbitrary start.
double wallSeconds();

}  // namespace vkrt::bench
