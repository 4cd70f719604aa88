// vkrt's launch benchmark (a program, not a test): the cost per ray tracing invocation when the rays do almost
// nothing else, measured on the workload of the CTS's ray_tracing_pipeline.misc.maxrtinvocations_tri and _aabb
// cases (VK-GL-CTS vktRayTracingMiscTests.cpp, MAXRTInvocationsSupportedTest), which launch 2^29 raygen
// invocations of 8192 x 65536: 512 unit cubes (12 triangles each) or 512 boxes along x, 3 apart, in one bottom
// level and one instance (custom index 1); each launch index traces one short ray up +y into cell index % 512; the
// one hit runs an any-hit shader (after the intersection shader's reportIntersectionEXT for the boxes) that adds
// 1 to a shared counter and stores the custom index at the launch index. The figures are launch indices per second
// (real time, best of runs, and per CPU second), and the time the CTS's 2^29 would take at that rate; every run's
// results are checked (hits = launch indices, no miss, every custom index 1).
//
// Usage: vkrt_launchbench [--threads N] [--rays N|2^K] [--min-time S] [--geometry tri|aabb|both]
// (--rays 2^29: the CTS's launch of 8192 x 65536, a 2 GiB result buffer; the default is 2^24.)
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "bench_common.hpp"
#include "launch_cost.rahit.spv.h"
#include "launch_cost.rgen.spv.h"
#include "launch_cost.rint.spv.h"
#include "launch_cost.rmiss.spv.h"
#include "vkrt_commit.h"

namespace vkrt::bench {
namespace {

constexpr uint32_t kCells = 512;
constexpr uint32_t kWidth = 8192;  // the CTS's launch width on vkrt's limits (2^29 % (65535 x 1024))

struct Options {
  unsigned threads = 0;
  uint64_t rays = uint64_t(1) << 24;
  double minTime = 2.0;
  bool tri = true, aabb = true;
};

// The scene: one bottom level of 512 cubes or boxes, one instance with custom index 1.
VkAccelerationStructureKHR buildScene(AccelStructures& as, bool triangles) {
  VkAccelerationStructureGeometryKHR g;
  uint32_t primitives;
  std::vector<float> vertices;
  std::vector<uint32_t> indices;
  std::vector<VkAabbPositionsKHR> boxes;
  if (triangles) {
    // A unit cube's 8 corners and 12 triangles (2 per face): the ray enters the bottom face (y = 0) through its
    // middle, on the diagonal the face's two triangles share.
    static const uint32_t kFaces[12][3] = {{0, 1, 5}, {0, 5, 4}, {2, 7, 3}, {2, 6, 7}, {0, 3, 1}, {0, 2, 3},
                                           {4, 5, 7}, {4, 7, 6}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
    for (uint32_t c = 0; c < kCells; ++c) {
      for (uint32_t k = 0; k < 8; ++k) {
        vertices.push_back(float(c) * 3.0f + float(k & 1));
        vertices.push_back(float((k >> 1) & 1));
        vertices.push_back(float((k >> 2) & 1));
      }
      for (const auto& f : kFaces)
        for (uint32_t v : f) indices.push_back(c * 8 + v);
    }
    g = as.triangles(vertices.data(), vertices.size() / 3, indices.data(), indices.size());
    primitives = uint32_t(indices.size() / 3);
  } else {
    for (uint32_t c = 0; c < kCells; ++c) boxes.push_back({float(c) * 3.0f, 0, 0, float(c) * 3.0f + 1, 1, 1});
    g = VkAccelerationStructureGeometryKHR{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
    g.geometryType = VK_GEOMETRY_TYPE_AABBS_KHR;
    g.geometry.aabbs.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_AABBS_DATA_KHR;
    g.geometry.aabbs.data.deviceAddress = as.upload(boxes.data(), boxes.size() * sizeof boxes[0]);
    g.geometry.aabbs.stride = sizeof boxes[0];
    primitives = kCells;
  }
  g.flags = VK_GEOMETRY_NO_DUPLICATE_ANY_HIT_INVOCATION_BIT_KHR;  // not opaque: the any-hit shader runs
  VkAccelerationStructureKHR blas = as.build(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, g, primitives);
  VkAccelerationStructureInstanceKHR instance = as.identityInstance(blas);
  instance.instanceCustomIndex = 1;
  return as.build(VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, as.instances(&instance, 1), 1);
}

// The pipeline (raygen, miss, one hit group: any-hit, with the intersection shader for boxes), its SBT and its
// descriptor set (binding 0 the results, 1 the scene).
struct LaunchPipeline : RayPipeline {
  explicit LaunchPipeline(bool triangles) {
    Context& c = ctx();
    const VkShaderStageFlags all = VK_SHADER_STAGE_RAYGEN_BIT_KHR | VK_SHADER_STAGE_MISS_BIT_KHR |
                                   VK_SHADER_STAGE_ANY_HIT_BIT_KHR | VK_SHADER_STAGE_INTERSECTION_BIT_KHR;
    const VkDescriptorSetLayoutBinding b[2] = {{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, all, nullptr},
                                               {1, VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 1, all, nullptr}};
    VkDescriptorSetLayoutCreateInfo dl{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    dl.bindingCount = 2;
    dl.pBindings = b;
    CHECK(vkCreateDescriptorSetLayout(c.device, &dl, nullptr, &setLayout));
    VkPipelineLayoutCreateInfo pl{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    pl.setLayoutCount = 1;
    pl.pSetLayouts = &setLayout;
    CHECK(vkCreatePipelineLayout(c.device, &pl, nullptr, &layout));

    VkShaderModule modules[4] = {shaderModule(kSpv_launch_cost_rgen, sizeof kSpv_launch_cost_rgen),
                                 shaderModule(kSpv_launch_cost_rmiss, sizeof kSpv_launch_cost_rmiss),
                                 shaderModule(kSpv_launch_cost_rahit, sizeof kSpv_launch_cost_rahit),
                                 shaderModule(kSpv_launch_cost_rint, sizeof kSpv_launch_cost_rint)};
    const VkShaderStageFlagBits stageBits[4] = {VK_SHADER_STAGE_RAYGEN_BIT_KHR, VK_SHADER_STAGE_MISS_BIT_KHR,
                                                VK_SHADER_STAGE_ANY_HIT_BIT_KHR, VK_SHADER_STAGE_INTERSECTION_BIT_KHR};
    VkPipelineShaderStageCreateInfo stages[4];
    for (uint32_t i = 0; i < 4; ++i) {
      stages[i] = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
      stages[i].stage = stageBits[i];
      stages[i].module = modules[i];
      stages[i].pName = "main";
    }
    VkRayTracingShaderGroupCreateInfoKHR groups[3];
    for (uint32_t i = 0; i < 3; ++i) {
      groups[i] = {VK_STRUCTURE_TYPE_RAY_TRACING_SHADER_GROUP_CREATE_INFO_KHR};
      groups[i].type = VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR;
      groups[i].generalShader = i;
      groups[i].closestHitShader = groups[i].anyHitShader = groups[i].intersectionShader = VK_SHADER_UNUSED_KHR;
    }
    groups[2].type = triangles ? VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR
                               : VK_RAY_TRACING_SHADER_GROUP_TYPE_PROCEDURAL_HIT_GROUP_KHR;
    groups[2].generalShader = VK_SHADER_UNUSED_KHR;
    groups[2].anyHitShader = 2;
    if (!triangles) groups[2].intersectionShader = 3;
    const VkDescriptorPoolSize sizes[2] = {{VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 1},
                                           {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1}};
    create(stages, 4, groups, sizes, 2);
  }

  void bind(VkAccelerationStructureKHR tlas, const Buffer& results) {
    VkWriteDescriptorSetAccelerationStructureKHR asw{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_KHR};
    asw.accelerationStructureCount = 1;
    asw.pAccelerationStructures = &tlas;
    const VkDescriptorBufferInfo bi{results.buffer, 0, VK_WHOLE_SIZE};
    VkWriteDescriptorSet w[2] = {{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET},
                                 {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, &asw}};
    w[0].dstSet = set;
    w[0].dstBinding = 0;
    w[0].descriptorCount = 1;
    w[0].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    w[0].pBufferInfo = &bi;
    w[1].dstSet = set;
    w[1].dstBinding = 1;
    w[1].descriptorCount = 1;
    w[1].descriptorType = VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR;
    vkUpdateDescriptorSets(ctx().device, 2, w, 0, nullptr);
  }

  VkCommandBuffer record(uint32_t w, uint32_t h) {
    Context& c = ctx();
    VkCommandBuffer cb = c.allocate();
    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    CHECK(vkBeginCommandBuffer(cb, &bi));
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, pipeline);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, layout, 0, 1, &set, 0, nullptr);
    c.cmdTraceRays(cb, &raygen, &miss, &hit, &callable, w, h, 1);
    CHECK(vkEndCommandBuffer(cb));
    return cb;
  }
};

struct Figures {
  double best = 0, cpu = 0;  // seconds: fastest run (real time), CPU time per run
  uint32_t runs = 0;
  bool correct = true;
};

Figures run(const Options& o, bool triangles) {
  AccelStructures as;
  VkAccelerationStructureKHR tlas = buildScene(as, triangles);
  LaunchPipeline p(triangles);
  const uint32_t height = uint32_t(std::max<uint64_t>(1, o.rays / kWidth));
  const uint64_t n = uint64_t(kWidth) * height;
  Buffer results((2 + n) * sizeof(uint32_t));
  p.bind(tlas, results);
  VkCommandBuffer cb = p.record(kWidth, height);
  Figures f;
  double start = 0;
  // One untimed run first (the pipeline's first launch), then runs until minTime has passed (at least 2).
  for (uint32_t i = 0;; ++i) {
    uint32_t* r = results.as<uint32_t>();
    std::memset(r, 0, results.size);
    if (i == 1) start = wallSeconds();
    const double s = wallSeconds(), cpuS = processCpuSeconds();
    ctx().submit(cb);
    const double took = wallSeconds() - s;
    if (i > 0) f.cpu += processCpuSeconds() - cpuS;
    bool ok = r[0] == n && r[1] == 0;
    for (uint64_t k = 0; ok && k < n; ++k) ok = r[2 + k] == 1;
    if (!ok) {
      std::fprintf(stderr, "%s: wrong results (hits %u, misses %u of %llu launch indices)\n",
                   triangles ? "tri" : "aabb", r[0], r[1], (unsigned long long)n);
      f.correct = false;
    }
    if (i == 0) continue;
    if (f.runs == 0 || took < f.best) f.best = took;
    ++f.runs;
    if (f.runs >= 2 && wallSeconds() - start >= o.minTime) break;
  }
  f.cpu /= f.runs;
  vkFreeCommandBuffers(ctx().device, ctx().pool, 1, &cb);
  return f;
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const char* v = i + 1 < argc ? argv[i + 1] : nullptr;
    if (a == "--threads" && v) {
      o.threads = unsigned(std::atoi(v));
      ++i;
    } else if (a == "--rays" && v) {
      // A count (4e6, 16777216) or a power of two (2^29: the CTS's launch).
      o.rays = std::strncmp(v, "2^", 2) == 0 ? uint64_t(1) << std::atoi(v + 2) : uint64_t(std::atof(v));
      ++i;
    } else if (a == "--min-time" && v) {
      o.minTime = std::atof(v);
      ++i;
    } else if (a == "--geometry" && v) {
      const std::string g = v;
      o.tri = g == "tri" || g == "both";
      o.aabb = g == "aabb" || g == "both";
      ++i;
    } else {
      std::fprintf(stderr,
                   "usage: vkrt_launchbench [--threads N] [--rays N|2^K] [--min-time S] [--geometry tri|aabb|both]\n");
      std::exit(2);
    }
  }
  return o;
}

}  // namespace
}  // namespace vkrt::bench

int main(int argc, char** argv) {
  using namespace vkrt::bench;
  const Options o = parse(argc, argv);
  setenv("VK_DRIVER_FILES", VKRT_BENCH_ICD_JSON, 0);
  if (o.threads) setenv("VKRT_THREADS", std::to_string(o.threads).c_str(), 1);
  if (!ctx().rayTracingPipeline) {
    std::fprintf(stderr, "vkrt_launchbench: the driver has no VK_KHR_ray_tracing_pipeline\n");
    return 1;
  }
  std::printf("vkrt_launchbench (%s): %u threads, %u x %llu launch indices, the CTS's maxrtinvocations workload\n",
              VKRT_COMMIT, workerThreads(), kWidth, (unsigned long long)(o.rays / kWidth));
  std::printf("%-6s %10s %14s %12s %14s %14s %6s %s\n", "scene", "Mrays/s", "Mrays/cpu-s", "cpu-ns/ray",
              "ns/ray/thread", "2^29 rays (s)", "runs", "results");
  bool allCorrect = true;
  for (int t = 0; t < 2; ++t) {
    const bool triangles = t == 0;
    if (triangles ? !o.tri : !o.aabb) continue;
    const Figures f = run(o, triangles);
    const double n = double(kWidth) * double(o.rays / kWidth);
    std::printf("%-6s %10.2f %14.2f %12.1f %14.1f %14.1f %6u %s\n", triangles ? "tri" : "aabb", n / f.best / 1e6,
                n / f.cpu / 1e6, f.cpu * 1e9 / n, f.best * 1e9 * workerThreads() / n,
                f.best * double(uint64_t(1) << 29) / n, f.runs, f.correct ? "correct" : "WRONG");
    allCorrect = allCorrect && f.correct;
  }
  return allCorrect ? 0 : 1;
}
