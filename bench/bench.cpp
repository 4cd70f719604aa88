// vkrt's compute benchmark: SAXPY (1M floats), a 256x256 float matrix multiply and a 512x512 Mandelbrot
// (256 iterations) dispatched through the Vulkan loader to vkrt, next to the same kernels in C++ (single
// threaded, -O2); vkCreateComputePipelines from a cold cache (compiling) and a warm VkPipelineCache; and ambient
// occlusion rays (VK_KHR_ray_query from a compute shader, 131k triangles, 1M rays) next to raw Embree 3 tracing the
// same rays (rtcOccluded1 and rtcOccluded8, std::threads), each checked ray by ray against rtcOccluded1. Two more
// kernels for the cost of VKRT_SHADER_CHECKS (docs/shader-debugging.md): SAXPY through buffer device addresses and
// a 3-tap blur between two 1024x1024 storage images.
//
// The loader is pointed at this build's vkrt (VK_DRIVER_FILES) unless VK_DRIVER_FILES is set already.
// VKRT_THREADS=1 runs vkrt's dispatches on one thread, like the native kernels.
#include <benchmark/benchmark.h>
#include <vulkan/vulkan.h>

#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <memory>
#include <thread>
#include <vector>

#include "ao_query.comp.spv.h"
#include "bench_common.hpp"
#include "image_blur.comp.spv.h"
#include "mandelbrot.comp.spv.h"
#include "matmul.comp.spv.h"
#include "matmul_tiled.comp.spv.h"
#include "native_kernels.hpp"
#include "saxpy.comp.spv.h"
#include "saxpy_bda.comp.spv.h"

namespace vkrt::bench {
namespace {

// A compute pipeline whose set 0 has `bindings` storage buffers (binding 0 an acceleration structure instead where
// `accelerationStructure0`), with `pushBytes` of push constants.
struct Kernel {
  VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkShaderModule module = VK_NULL_HANDLE;
  VkPipeline pipeline = VK_NULL_HANDLE;
  VkDescriptorPool pool = VK_NULL_HANDLE;
  VkDescriptorSet set = VK_NULL_HANDLE;
  VkCommandBuffer cb = VK_NULL_HANDLE;

  Kernel(const uint32_t* words, size_t bytes, uint32_t bindings, uint32_t pushBytes,
         bool accelerationStructure0 = false)
      : Kernel(words, bytes, bindingTypes(bindings, accelerationStructure0), pushBytes) {}
  static std::vector<VkDescriptorType> bindingTypes(uint32_t bindings, bool accelerationStructure0) {
    std::vector<VkDescriptorType> t(bindings, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER);
    if (accelerationStructure0 && bindings) t[0] = VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR;
    return t;
  }
  // Binding i of types[i].
  Kernel(const uint32_t* words, size_t bytes, const std::vector<VkDescriptorType>& types, uint32_t pushBytes) {
    VkDevice d = ctx().device;
    const uint32_t bindings = uint32_t(types.size());
    std::vector<VkDescriptorSetLayoutBinding> b;
    std::vector<VkDescriptorPoolSize> sizes;
    for (uint32_t i = 0; i < bindings; ++i) {
      b.push_back({i, types[i], 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr});
      sizes.push_back({types[i], 1});
    }
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
    VkDescriptorPoolCreateInfo dp{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    dp.maxSets = 1;
    dp.poolSizeCount = bindings;
    dp.pPoolSizes = sizes.data();
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
  void bind(uint32_t binding, VkImageView view) {  // a storage image in GENERAL
    VkDescriptorImageInfo ii{VK_NULL_HANDLE, view, VK_IMAGE_LAYOUT_GENERAL};
    VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    w.dstSet = set;
    w.dstBinding = binding;
    w.descriptorCount = 1;
    w.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
    w.pImageInfo = &ii;
    vkUpdateDescriptorSets(ctx().device, 1, &w, 0, nullptr);
  }
  void bind(uint32_t binding, VkAccelerationStructureKHR as) {
    VkWriteDescriptorSetAccelerationStructureKHR asw{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_KHR};
    asw.accelerationStructureCount = 1;
    asw.pAccelerationStructures = &as;
    VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, &asw};
    w.dstSet = set;
    w.dstBinding = binding;
    w.descriptorCount = 1;
    w.descriptorType = VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR;
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

// ---- SAXPY through buffer device addresses (VKRT_SHADER_CHECKS=bda checks each access)

void BM_SaxpyBda_vkrt(benchmark::State& state) {
  std::vector<float> x, y;
  fillSaxpy(x, y);
  const VkBufferUsageFlags usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;
  Buffer bx(kSaxpyN * 4, usage), by(kSaxpyN * 4, usage), unused(16);
  std::memcpy(bx.data, x.data(), kSaxpyN * 4);
  std::memcpy(by.data, y.data(), kSaxpyN * 4);
  Kernel k(kSpv_saxpy_bda_comp, sizeof kSpv_saxpy_bda_comp, 1, 24);
  k.bind(0, unused);
  struct {
    VkDeviceAddress x, y;
    float a;
    uint32_t n;
  } push{bx.address(), by.address(), 1.5f, kSaxpyN};
  k.record(&push, sizeof push, kSaxpyN / 256, 1);
  k.run();
  std::vector<float> want = y;
  saxpy(1.5f, x.data(), want.data(), kSaxpyN);
  if (std::memcmp(want.data(), by.data, kSaxpyN * 4) != 0)
    return mismatch(state, "SAXPY (device addresses) results differ from the native kernel");
  for (auto _ : state) k.run();
  state.SetBytesProcessed(int64_t(state.iterations()) * kSaxpyN * 12);
}

// ---- a 3-tap blur between two 1024x1024 R32_SFLOAT storage images (VKRT_SHADER_CHECKS=image checks each access)

constexpr uint32_t kBlurSize = 1024;

// A kBlurSize^2 R32_SFLOAT storage image in GENERAL, its texels copied from `texels` (or left as they are).
struct StorageImage {
  VkImage image = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;
  explicit StorageImage(const std::vector<float>& texels) {
    VkDevice d = ctx().device;
    VkImageCreateInfo ci{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    ci.imageType = VK_IMAGE_TYPE_2D;
    ci.format = VK_FORMAT_R32_SFLOAT;
    ci.extent = {kBlurSize, kBlurSize, 1};
    ci.mipLevels = ci.arrayLayers = 1;
    ci.samples = VK_SAMPLE_COUNT_1_BIT;
    ci.tiling = VK_IMAGE_TILING_OPTIMAL;
    ci.usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    CHECK(vkCreateImage(d, &ci, nullptr, &image));
    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(d, image, &req);
    VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    ai.allocationSize = req.size;
    ai.memoryTypeIndex = uint32_t(std::countr_zero(req.memoryTypeBits));
    CHECK(vkAllocateMemory(d, &ai, nullptr, &memory));
    CHECK(vkBindImageMemory(d, image, memory, 0));
    VkImageViewCreateInfo vi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    vi.image = image;
    vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
    vi.format = ci.format;
    vi.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    CHECK(vkCreateImageView(d, &vi, nullptr, &view));
    Buffer staging(texels.size() * 4, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
    std::memcpy(staging.data, texels.data(), texels.size() * 4);
    transfer([&](VkCommandBuffer cb) {
      layout(cb, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
      VkBufferImageCopy r{};
      r.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
      r.imageExtent = ci.extent;
      vkCmdCopyBufferToImage(cb, staging.buffer, image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &r);
      layout(cb, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_GENERAL);
    });
  }
  ~StorageImage() {
    VkDevice d = ctx().device;
    vkDestroyImageView(d, view, nullptr);
    vkDestroyImage(d, image, nullptr);
    vkFreeMemory(d, memory, nullptr);
  }
  std::vector<float> read() {
    Buffer staging(size_t(kBlurSize) * kBlurSize * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    transfer([&](VkCommandBuffer cb) {
      layout(cb, VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
      VkBufferImageCopy r{};
      r.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
      r.imageExtent = {kBlurSize, kBlurSize, 1};
      vkCmdCopyImageToBuffer(cb, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, staging.buffer, 1, &r);
      layout(cb, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_IMAGE_LAYOUT_GENERAL);
    });
    std::vector<float> out(size_t(kBlurSize) * kBlurSize);
    std::memcpy(out.data(), staging.data, out.size() * 4);
    return out;
  }
  void layout(VkCommandBuffer cb, VkImageLayout from, VkImageLayout to) {
    VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    b.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_SHADER_WRITE_BIT;
    b.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_SHADER_READ_BIT;
    b.oldLayout = from;
    b.newLayout = to;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image;
    b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 0, nullptr, 0,
                         nullptr, 1, &b);
  }
  template <class F>
  static void transfer(F&& record) {
    VkCommandBufferAllocateInfo cai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    cai.commandPool = ctx().pool;
    cai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    cai.commandBufferCount = 1;
    VkCommandBuffer cb = VK_NULL_HANDLE;
    CHECK(vkAllocateCommandBuffers(ctx().device, &cai, &cb));
    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    CHECK(vkBeginCommandBuffer(cb, &bi));
    record(cb);
    CHECK(vkEndCommandBuffer(cb));
    VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cb;
    CHECK(vkQueueSubmit(ctx().queue, 1, &si, VK_NULL_HANDLE));
    CHECK(vkQueueWaitIdle(ctx().queue));
    vkFreeCommandBuffers(ctx().device, ctx().pool, 1, &cb);
  }
};

void BM_ImageBlur_vkrt(benchmark::State& state) {
  const size_t n = size_t(kBlurSize) * kBlurSize;
  std::vector<float> src(n);
  for (size_t i = 0; i < n; ++i) src[i] = float(i % 61) * 0.5f;  // sums of three are exact
  StorageImage in(src), out(std::vector<float>(n, 0.0f));
  Kernel k(kSpv_image_blur_comp, sizeof kSpv_image_blur_comp,
           {VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE}, 4);
  k.bind(0, in.view);
  k.bind(1, out.view);
  uint32_t size = kBlurSize;
  k.record(&size, 4, kBlurSize / 16, kBlurSize / 16);
  k.run();
  std::vector<float> got = out.read();
  for (uint32_t y = 0; y < kBlurSize; ++y)
    for (uint32_t x = 0; x < kBlurSize; ++x) {
      const uint32_t l = x ? x - 1 : 0, r = x + 1 < kBlurSize ? x + 1 : x;
      const float want = src[y * kBlurSize + l] + src[y * kBlurSize + x] + src[y * kBlurSize + r];
      if (got[y * kBlurSize + x] != want) return mismatch(state, "image blur results differ");
    }
  for (auto _ : state) k.run();
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(n));
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

// The product on vkrt with the shader `spv` (256 / 16 workgroups in x and y), checked against the native kernel.
void runMatmul(benchmark::State& state, const uint32_t* spv, size_t bytesOfSpv, const char* mismatchText) {
  std::vector<float> a, b;
  fillMat(a, b);
  const size_t bytes = size_t(kMatN) * kMatN * 4;
  Buffer ba(bytes), bb(bytes), bc(bytes);
  std::memcpy(ba.data, a.data(), bytes);
  std::memcpy(bb.data, b.data(), bytes);
  Kernel k(spv, bytesOfSpv, 3, 4);
  k.bind(0, ba);
  k.bind(1, bb);
  k.bind(2, bc);
  uint32_t n = kMatN;
  k.record(&n, 4, kMatN / 16, kMatN / 16);
  k.run();
  std::vector<float> want(kMatN * kMatN);
  matmul(a.data(), b.data(), want.data(), kMatN);
  // The values are exact multiples of 1/32 with small sums: any summation order gives the same floats.
  if (std::memcmp(want.data(), bc.data, bytes) != 0) return mismatch(state, mismatchText);
  for (auto _ : state) k.run();
  state.counters["GFLOPS"] =
      benchmark::Counter(double(state.iterations()) * 2.0 * kMatN * kMatN * kMatN * 1e-9, benchmark::Counter::kIsRate);
}

void BM_Matmul_vkrt(benchmark::State& state) {
  runMatmul(state, kSpv_matmul_comp, sizeof kSpv_matmul_comp, "matmul results differ from the native kernel");
}

// The same product through workgroup memory and barriers (matmul_tiled.comp): the usual form of a shader that shares
// data between invocations; its workgroup's batches run as fibers that switch at each barrier.
void BM_MatmulTiled_vkrt(benchmark::State& state) {
  runMatmul(state, kSpv_matmul_tiled_comp, sizeof kSpv_matmul_tiled_comp,
            "tiled matmul results differ from the native kernel");
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

// ---- ambient occlusion rays (VK_KHR_ray_query in a compute shader) next to raw Embree 3 on the same rays

// The scene: a height field of kAoGrid x kAoGrid quads over [0, 1]^2 (2 * kAoGrid^2 triangles) and four boxes of
// 12 triangles standing in it; kAoGrid^2 points, each just above a grid vertex (+1e-3 in z), cast kAoRays rays in
// [kAoTMin, kAoTMax] in directions from an integer hash of (point, ray).
constexpr uint32_t kAoGrid = 256, kAoRays = 16, kAoPoints = kAoGrid * kAoGrid;
constexpr float kAoTMin = 0.0f, kAoTMax = 0.1f;

struct AoScene {
  std::vector<float> vertices;  // xyz
  std::vector<uint32_t> indices;
  std::vector<float> origins;  // xyzw per point
};

const AoScene& aoScene() {
  static const AoScene scene = [] {
    AoScene s;
    const uint32_t n = kAoGrid, row = kAoGrid + 1;
    for (uint32_t j = 0; j <= n; ++j)
      for (uint32_t i = 0; i <= n; ++i) {
        float x = float(i) / float(n), y = float(j) / float(n);
        float z =
            0.06f * std::sin(6.2831853f * 3 * x) * std::cos(6.2831853f * 2 * y) + 0.02f * std::sin(17 * x + 11 * y);
        s.vertices.insert(s.vertices.end(), {x, y, z});
      }
    for (uint32_t j = 0; j < n; ++j)
      for (uint32_t i = 0; i < n; ++i) {
        uint32_t v = j * row + i;
        s.indices.insert(s.indices.end(), {v, v + 1, v + row, v + row, v + 1, v + row + 1});
      }
    for (uint32_t j = 0; j < n; ++j)
      for (uint32_t i = 0; i < n; ++i) {
        const float* v = &s.vertices[size_t(j * row + i) * 3];
        s.origins.insert(s.origins.end(), {v[0], v[1], v[2] + 1e-3f, 0.0f});
      }
    // Four boxes, 0.08 wide, from z = -0.1 to 0.15.
    const float centres[4][2] = {{0.25f, 0.25f}, {0.75f, 0.25f}, {0.25f, 0.75f}, {0.75f, 0.75f}};
    const uint32_t faces[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                                   {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
    for (const auto& c : centres) {
      uint32_t base = uint32_t(s.vertices.size() / 3);
      for (uint32_t corner = 0; corner < 8; ++corner)
        s.vertices.insert(s.vertices.end(), {c[0] + (corner & 1 ? 0.04f : -0.04f), c[1] + (corner & 2 ? 0.04f : -0.04f),
                                             corner & 4 ? 0.15f : -0.1f});
      for (const auto& f : faces) s.indices.insert(s.indices.end(), {base + f[0], base + f[1], base + f[2]});
    }
    return s;
  }();
  return scene;
}

// ao_query.comp's hash and directions, the same integer operations and exact float scalings.
void aoDirection(uint32_t point, uint32_t k, float d[3]) {
  uint32_t h1 = hash32(point * kAoRays + k), h2 = hash32(h1), h3 = hash32(h2);
  d[0] = float(int32_t(h1 >> 16) - 32768) * (1.0f / 32768.0f);
  d[1] = float(int32_t(h2 >> 16) - 32768) * (1.0f / 32768.0f);
  d[2] = float((h3 >> 16) + 1u) * (1.0f / 65536.0f);
}

// Raw Embree: the same triangles in one scene (no instance level), robust and built at HIGH quality as vkrt builds
// a PREFER_FAST_TRACE structure (src/accel/blas.cpp).
struct AoEmbree {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  AoEmbree() {
    const AoScene& s = aoScene();
    device = rtcNewDevice("verbose=0");
    scene = rtcNewScene(device);
    RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* v = static_cast<float*>(
        rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 12, s.vertices.size() / 3));
    std::memcpy(v, s.vertices.data(), s.vertices.size() * 4);
    auto* ix = static_cast<uint32_t*>(
        rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 12, s.indices.size() / 3));
    std::memcpy(ix, s.indices.data(), s.indices.size() * 4);
    rtcSetGeometryBuildQuality(g, RTC_BUILD_QUALITY_HIGH);
    rtcCommitGeometry(g);
    rtcAttachGeometry(scene, g);
    rtcReleaseGeometry(g);
    rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
    rtcCommitScene(scene);
  }
  ~AoEmbree() {
    rtcReleaseScene(scene);
    rtcReleaseDevice(device);
  }

  // Points [begin, end) with rtcOccluded1: the mask of occluded rays per point.
  void occluded1(uint32_t begin, uint32_t end, uint32_t* masks) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    const float* o = aoScene().origins.data();
    for (uint32_t p = begin; p < end; ++p) {
      uint32_t mask = 0;
      for (uint32_t k = 0; k < kAoRays; ++k) {
        RTCRay r{};
        r.org_x = o[p * 4];
        r.org_y = o[p * 4 + 1];
        r.org_z = o[p * 4 + 2];
        float d[3];
        aoDirection(p, k, d);
        r.dir_x = d[0];
        r.dir_y = d[1];
        r.dir_z = d[2];
        r.tnear = kAoTMin;
        r.tfar = kAoTMax;
        r.mask = ~0u;
        rtcOccluded1(scene, &context, &r);
        if (r.tfar < 0) mask |= 1u << k;  // -inf: occluded
      }
      masks[p] = mask;
    }
  }
  // The same with rtcOccluded8: a point's rays in packets of 8.
  void occluded8(uint32_t begin, uint32_t end, uint32_t* masks) const {
    static_assert(kAoRays % 8 == 0);
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    const float* o = aoScene().origins.data();
    alignas(32) const int valid[8] = {-1, -1, -1, -1, -1, -1, -1, -1};
    for (uint32_t p = begin; p < end; ++p) {
      uint32_t mask = 0;
      for (uint32_t k0 = 0; k0 < kAoRays; k0 += 8) {
        RTCRay8 r{};
        for (uint32_t l = 0; l < 8; ++l) {
          r.org_x[l] = o[p * 4];
          r.org_y[l] = o[p * 4 + 1];
          r.org_z[l] = o[p * 4 + 2];
          float d[3];
          aoDirection(p, k0 + l, d);
          r.dir_x[l] = d[0];
          r.dir_y[l] = d[1];
          r.dir_z[l] = d[2];
          r.tnear[l] = kAoTMin;
          r.tfar[l] = kAoTMax;
          r.mask[l] = ~0u;
        }
        rtcOccluded8(valid, scene, &context, &r);
        for (uint32_t l = 0; l < 8; ++l)
          if (r.tfar[l] < 0) mask |= 1u << (k0 + l);
      }
      masks[p] = mask;
    }
  }
  // Every point, in chunks of 64 (parallelChunks).
  template <class F>
  void parallel(F f, uint32_t* masks) const {
    parallelChunks(kAoPoints, 64,
                   [&](uint64_t begin, uint64_t end) { (this->*f)(uint32_t(begin), uint32_t(end), masks); });
  }
};

AoEmbree& aoEmbree() {
  static AoEmbree e;
  return e;
}

// Raw Embree's rtcOccluded1 masks, the reference both benchmarks compare with.
const std::vector<uint32_t>& aoReference() {
  static const std::vector<uint32_t> masks = [] {
    std::vector<uint32_t> m(kAoPoints);
    aoEmbree().parallel(&AoEmbree::occluded1, m.data());
    return m;
  }();
  return masks;
}

// Compares masks with the reference: counters with the occluded fraction and the rays that differ; false (and
// the benchmark skipped) where more than 1% of the rays differ.
bool aoCompare(benchmark::State& state, const char* who, const uint32_t* masks, size_t stride) {
  const std::vector<uint32_t>& ref = aoReference();
  uint64_t occluded = 0, differ = 0;
  for (uint32_t p = 0; p < kAoPoints; ++p) {
    occluded += uint32_t(std::popcount(masks[p * stride]));
    differ += uint32_t(std::popcount(masks[p * stride] ^ ref[p]));
  }
  const double rays = double(kAoPoints) * kAoRays;
  state.counters["occluded"] = double(occluded) / rays;
  state.counters["rays_differing"] = double(differ);
  if (differ)
    std::fprintf(stderr, "%s: %llu of %.0f rays differ from rtcOccluded1\n", who, (unsigned long long)differ, rays);
  if (differ > uint64_t(rays / 100)) {
    mismatch(state, "the occlusion differs from raw Embree's in more than 1% of the rays");
    return false;
  }
  return true;
}

// Mrays per second of real time, and per second of the whole process's CPU time since `cpuStart` (less sensitive to
// other load on a shared machine than real time: a thread waiting for a core does not count).
void aoRate(benchmark::State& state, double cpuStart) {
  const double mrays = double(state.iterations()) * kAoPoints * kAoRays * 1e-6;
  state.counters["Mrays"] = benchmark::Counter(mrays, benchmark::Counter::kIsRate);
  state.counters["Mrays_per_cpu_s"] = mrays / (processCpuSeconds() - cpuStart);
}

// vkrt: a BLAS of the scene, a TLAS with one identity instance of it, both built with
// vkCmdBuildAccelerationStructuresKHR (PREFER_FAST_TRACE) before the timed loop.
struct AoVkrt {
  AccelStructures structures;
  VkAccelerationStructureKHR blas = VK_NULL_HANDLE, tlas = VK_NULL_HANDLE;

  AoVkrt() {
    const AoScene& s = aoScene();
    blas = structures.build(
        VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR,
        structures.triangles(s.vertices.data(), s.vertices.size() / 3, s.indices.data(), s.indices.size()),
        uint32_t(s.indices.size() / 3));
    VkAccelerationStructureInstanceKHR in = structures.identityInstance(blas);
    tlas = structures.build(VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, structures.instances(&in, 1), 1);
  }
};

void BM_AmbientOcclusion_vkrt(benchmark::State& state) {
  if (!ctx().rayQuery) return mismatch(state, "the driver has no VK_KHR_ray_query");
  AoVkrt scene;
  const AoScene& s = aoScene();
  Buffer origins(s.origins.size() * 4), results(size_t(kAoPoints) * 8);
  std::memcpy(origins.data, s.origins.data(), s.origins.size() * 4);
  Kernel k(kSpv_ao_query_comp, sizeof kSpv_ao_query_comp, 3, 16, true);
  k.bind(0, scene.tlas);
  k.bind(1, origins);
  k.bind(2, results);
  struct {
    uint32_t count, rays;
    float tMin, tMax;
  } push{kAoPoints, kAoRays, kAoTMin, kAoTMax};
  k.record(&push, sizeof push, kAoPoints / 64, 1);
  k.run();
  // (count, mask) per point: the count must be the mask's.
  const uint32_t* r = results.as<uint32_t>();
  for (uint32_t p = 0; p < kAoPoints; ++p)
    if (r[p * 2] != uint32_t(std::popcount(r[p * 2 + 1])))
      return mismatch(state, "a point's occluded count is not its mask's");
  if (!aoCompare(state, "vkrt ray queries", r + 1, 2)) return;
  const double cpuStart = processCpuSeconds();
  for (auto _ : state) k.run();
  aoRate(state, cpuStart);
}

void BM_AmbientOcclusion_embree(benchmark::State& state) {
  std::vector<uint32_t> masks(kAoPoints);
  const AoEmbree& e = aoEmbree();
  e.parallel(&AoEmbree::occluded1, masks.data());
  if (!aoCompare(state, "rtcOccluded1 (timed run)", masks.data(), 1)) return;
  const double cpuStart = processCpuSeconds();
  for (auto _ : state) {
    e.parallel(&AoEmbree::occluded1, masks.data());
    benchmark::ClobberMemory();
  }
  aoRate(state, cpuStart);
}

void BM_AmbientOcclusion_embree8(benchmark::State& state) {
  std::vector<uint32_t> masks(kAoPoints);
  const AoEmbree& e = aoEmbree();
  e.parallel(&AoEmbree::occluded8, masks.data());
  if (!aoCompare(state, "rtcOccluded8", masks.data(), 1)) return;
  const double cpuStart = processCpuSeconds();
  for (auto _ : state) {
    e.parallel(&AoEmbree::occluded8, masks.data());
    benchmark::ClobberMemory();
  }
  aoRate(state, cpuStart);
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
BENCHMARK(BM_SaxpyBda_vkrt)->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK(BM_ImageBlur_vkrt)->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK(BM_Matmul_vkrt)->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK(BM_Matmul_native)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_MatmulTiled_vkrt)->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK(BM_Mandelbrot_vkrt)->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK(BM_Mandelbrot_native)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_PipelineCreate_cold)->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK(BM_PipelineCreate_warmCache)->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK(BM_AmbientOcclusion_vkrt)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);
BENCHMARK(BM_AmbientOcclusion_embree)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);
BENCHMARK(BM_AmbientOcclusion_embree8)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);

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
