// The ray tracing stages of the compiler, below the Vulkan API: GLSL shaders of all six stages (compiled by glslc
// at build time) run against the test runtime of ray_runtime.hpp on a small scene, and every value they write is
// compared with one computed here from the scene's geometry, in their GL_EXT_ray_tracing and their GL_NV_ray_tracing
// (SPV_NV_ray_tracing) forms. Also: the stack-size facts of each compiled stage.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "pipeline_ahit.rahit.spv.h"
#include "pipeline_call.rcall.spv.h"
#include "pipeline_chit.rchit.spv.h"
#include "pipeline_chit_callable.rchit.spv.h"
#include "pipeline_miss.rmiss.spv.h"
#include "pipeline_raygen.rgen.spv.h"
#include "pipeline_raygen_big_payload.rgen.spv.h"
#include "pipeline_rint.rint.spv.h"
#include "rt_ahit.rahit.spv.h"
#include "rt_call.rcall.spv.h"
#include "rt_chit.rchit.spv.h"
#include "rt_miss.rmiss.spv.h"
#include "rt_miss_secondary.rmiss.spv.h"
#include "rt_nv_ahit.rahit.spv.h"
#include "rt_nv_call.rcall.spv.h"
#include "rt_nv_chit.rchit.spv.h"
#include "rt_nv_miss.rmiss.spv.h"
#include "rt_nv_miss_secondary.rmiss.spv.h"
#include "rt_nv_raygen.rgen.spv.h"
#include "rt_nv_rint.rint.spv.h"
#include "rt_raygen.rgen.spv.h"
#include "rt_raygen_spmd.rgen.spv.h"
#include "rt_rint.rint.spv.h"
#include "spirv/ray_runtime.hpp"

namespace vkrt::testing {
namespace {

template <size_t N>
std::shared_ptr<spirv::CompiledShader> compileStage(const uint32_t (&words)[N], spv::ExecutionModel model,
                                                    bool inlineCalls, std::string* error) {
  spirv::CompileRequest r;
  r.words = words;
  r.wordCount = N;
  r.model = model;
  r.inlineFunctions = inlineCalls;
  return spirv::compile(r, error);
}

template <class T>
std::vector<uint8_t> bytesOf(const T& v) {
  std::vector<uint8_t> out(sizeof v);
  std::memcpy(out.data(), &v, sizeof v);
  return out;
}

struct Payload {
  float a[4], b[4], c[4];
  uint32_t d[4];
  float e[4];
};
static_assert(sizeof(Payload) == 80);

constexpr uint32_t kWidth = 8, kHeight = 4;
constexpr uint64_t kAccel = 0xa5a5a000;

struct Stages {
  std::shared_ptr<spirv::CompiledShader> raygen, miss, missSecondary, chit, ahit, rint, call;
};

Stages compileAll(bool inlineCalls, bool nv = false) {
  Stages s;
  auto one = [&](auto& words, spv::ExecutionModel model, std::shared_ptr<spirv::CompiledShader>& out) {
    std::string e;
    out = compileStage(words, model, inlineCalls, &e);
    EXPECT_TRUE(out) << e;
  };
  if (nv) {
    // The same shaders written with GL_NV_ray_tracing (the NV execution models have the KHR values).
    one(kSpv_rt_nv_raygen_rgen, spv::ExecutionModelRayGenerationNV, s.raygen);
    one(kSpv_rt_nv_miss_rmiss, spv::ExecutionModelMissNV, s.miss);
    one(kSpv_rt_nv_miss_secondary_rmiss, spv::ExecutionModelMissNV, s.missSecondary);
    one(kSpv_rt_nv_chit_rchit, spv::ExecutionModelClosestHitNV, s.chit);
    one(kSpv_rt_nv_ahit_rahit, spv::ExecutionModelAnyHitNV, s.ahit);
    one(kSpv_rt_nv_rint_rint, spv::ExecutionModelIntersectionNV, s.rint);
    one(kSpv_rt_nv_call_rcall, spv::ExecutionModelCallableNV, s.call);
    return s;
  }
  one(kSpv_rt_raygen_rgen, spv::ExecutionModelRayGenerationKHR, s.raygen);
  one(kSpv_rt_miss_rmiss, spv::ExecutionModelMissKHR, s.miss);
  one(kSpv_rt_miss_secondary_rmiss, spv::ExecutionModelMissKHR, s.missSecondary);
  one(kSpv_rt_chit_rchit, spv::ExecutionModelClosestHitKHR, s.chit);
  one(kSpv_rt_ahit_rahit, spv::ExecutionModelAnyHitKHR, s.ahit);
  one(kSpv_rt_rint_rint, spv::ExecutionModelIntersectionKHR, s.rint);
  one(kSpv_rt_call_rcall, spv::ExecutionModelCallableKHR, s.call);
  return s;
}

// Instance 0 (translated by z + 1, custom index 7, SBT offset 0): geometry 0 holds two triangles at object z = 1
// splitting the square [0,4]x[0,4]; geometry 1 one triangle at object z = 0.5 over the second half. Instance 1
// (translated to (6, 2, 3), custom index 9, SBT offset 2): a procedural sphere of radius 1.5 (from its record).
RayScene scene() {
  RayScene s;
  RayScene::Instance tris;
  tris.translation = {0, 0, 1};
  tris.customIndex = 7;
  RayScene::Geometry g0, g1;
  g0.triangles = {{{{0, 0, 1}, {4, 0, 1}, {0, 4, 1}}}, {{{4, 0, 1}, {4, 4, 1}, {0, 4, 1}}}};
  g1.triangles = {{{{4, 0, 0.5f}, {4, 4, 0.5f}, {0, 4, 0.5f}}}};
  tris.geometries = {g0, g1};
  RayScene::Instance sphere;
  sphere.translation = {6, 2, 3};
  sphere.customIndex = 9;
  sphere.sbtOffset = 2;
  RayScene::Geometry proc;
  proc.procedural = true;
  sphere.geometries = {proc};
  s.instances = {tris, sphere};
  return s;
}

// What one pixel must get, from the scene's geometry (not from the runtime's traversal).
struct Expected {
  enum Kind { Miss, Triangle, Sphere } kind = Miss;
  uint32_t geometry = 0, primitive = 0;
  float u = 0, v = 0, t = 0;
};

Expected expect(uint32_t x, uint32_t y) {
  float px = float(x) + 0.25f, py = float(y) + 0.5f;
  Expected e;
  if (px < 4) {
    if (px + py < 4) {
      // Triangle 0 of geometry 0: (u, v) = (px, py) / 4. The any-hit shader ignores u < 1/8: nothing else is there.
      float u = px / 4, v = py / 4;
      if (u < 0.125f) return e;
      return {Expected::Triangle, 0, 0, u, v, 2.0f};
    }
    // Triangle 1 of geometry 0 (t = 2), then geometry 1's triangle in front of it (t = 1.5), same (u, v).
    float v = (4 - px) / 4, u = (py - 4 + px) / 4;
    bool ignored = u < 0.125f;
    bool terminated = !ignored && px > 3;  // the any-hit shader commits at once: geometry 1 is never tested
    if (terminated) return {Expected::Triangle, 0, 1, u, v, 2.0f};
    return {Expected::Triangle, 1, 0, u, v, 1.5f};
  }
  float dx = px - 6, dy = py - 2;
  if (dx * dx + dy * dy >= 2.25f) return e;
  e.kind = Expected::Sphere;
  e.t = 3 - std::sqrt(2.25f - dx * dx - dy * dy);
  e.u = dx / 1.5f;
  e.v = dy / 1.5f;
  return e;
}

constexpr uint32_t kFactor = 3;  // the callable's shader record

// The scene's shader binding table: hit groups 0 and 1 for the triangle geometries (tints 0.5, 0.75; an any-hit
// shader on geometry 0), 2 for the sphere; two miss shaders; the callable.
RaySbt sceneSbt(const Stages& s) {
  RaySbt sbt;
  float tint0[4] = {0, 0, 0, 0.5f}, tint1[4] = {0, 0, 0, 0.75f}, sphere[4] = {0, 0, 0, 1.5f};
  sbt.hitGroups = {{nullptr, s.chit, s.ahit, nullptr, bytesOf(tint0)},
                   {nullptr, s.chit, nullptr, nullptr, bytesOf(tint1)},
                   {nullptr, s.chit, nullptr, s.rint, bytesOf(sphere)}};
  sbt.miss = {{s.miss, nullptr, nullptr, nullptr, {}}, {s.missSecondary, nullptr, nullptr, nullptr, {}}};
  sbt.callable = {{s.call, nullptr, nullptr, nullptr, bytesOf(kFactor)}};
  return sbt;
}

// `batches`: the raygen shader runs through its SPMD batch entry (RayTestRuntime::launch).
void traceScene(bool inlineCalls, bool nv = false, bool batches = false) {
  Stages s = compileAll(inlineCalls, nv);
  ASSERT_TRUE(s.raygen && s.miss && s.missSecondary && s.chit && s.ahit && s.rint && s.call);
  RaySbt sbt = sceneSbt(s);
  const uint32_t factor = kFactor;
  RayScene sc = scene();
  RayTestRuntime rt(sc, sbt, kAccel);
  std::vector<Payload> results(kWidth * kHeight);
  std::vector<uint32_t> answers(kWidth * kHeight * 2);
  rt.bindings[0] = abi::DescriptorRecord{kAccel, 0, nullptr, nullptr};
  rt.bindings[1] = abi::DescriptorRecord{reinterpret_cast<uint64_t>(results.data()), results.size() * sizeof(Payload),
                                         nullptr, nullptr};
  rt.bindings[2] =
      abi::DescriptorRecord{reinterpret_cast<uint64_t>(answers.data()), answers.size() * 4, nullptr, nullptr};
  rt.launch(s.raygen, {}, kWidth, kHeight, batches);
  EXPECT_TRUE(rt.errors.empty()) << rt.errors.front();
  EXPECT_EQ(rt.maxDepth, 2u);  // the sphere's closest-hit shader traced a secondary ray

  const float eps = 1e-5f;
  int hits = 0, misses = 0, spheres = 0;
  for (uint32_t y = 0; y < kHeight; ++y) {
    for (uint32_t x = 0; x < kWidth; ++x) {
      SCOPED_TRACE("pixel " + std::to_string(x) + "," + std::to_string(y));
      const Payload& p = results[y * kWidth + x];
      Expected e = expect(x, y);
      float px = float(x) + 0.25f, py = float(y) + 0.5f;
      if (e.kind == Expected::Miss) {
        ++misses;
        EXPECT_EQ(p.a[0], 0.0f);
        EXPECT_EQ(p.a[2], 1.0f);         // gl_WorldRayDirectionEXT
        EXPECT_FLOAT_EQ(p.a[3], 0.01f);  // gl_RayTminEXT
        EXPECT_EQ(p.b[0], px);           // gl_WorldRayOriginEXT
        EXPECT_EQ(p.b[1], py);
        EXPECT_EQ(p.b[3], 100.0f);   // gl_RayTmaxEXT
        EXPECT_EQ(p.d[0], 1000u);    // 1000 + gl_IncomingRayFlagsEXT (none)
        EXPECT_EQ(p.d[1], x);        // gl_LaunchIDEXT.x
        EXPECT_EQ(p.d[2], kHeight);  // gl_LaunchSizeEXT.y
        EXPECT_EQ(p.d[3], 7u);
        EXPECT_EQ(p.e[0], -1.0f);  // written by raygen before the trace, untouched by the miss shader
        EXPECT_EQ(answers[(y * kWidth + x) * 2], 0u);
        EXPECT_EQ(answers[(y * kWidth + x) * 2 + 1], 0u);
        continue;
      }
      ++hits;
      bool isSphere = e.kind == Expected::Sphere;
      spheres += isSphere;
      EXPECT_NEAR(p.a[0], e.u, eps);  // hit attributes
      EXPECT_NEAR(p.a[1], e.v, eps);
      EXPECT_NEAR(p.a[2], e.t, eps);  // gl_HitTEXT
      EXPECT_FLOAT_EQ(p.a[3], 0.01f);
      const float* tr = isSphere ? sc.instances[1].translation.data() : sc.instances[0].translation.data();
      EXPECT_EQ(p.b[0], px - tr[0]);  // gl_ObjectRayOriginEXT
      EXPECT_EQ(p.b[1], py - tr[1]);
      EXPECT_EQ(p.b[2], -tr[2]);
      EXPECT_EQ(p.b[3], float(e.primitive));  // gl_PrimitiveID
      EXPECT_EQ(p.c[0], tr[0]);               // gl_ObjectToWorldEXT[3]
      EXPECT_EQ(p.c[1], tr[1]);
      EXPECT_EQ(p.c[2], tr[2]);
      EXPECT_EQ(p.c[3], isSphere ? 1.5f : e.geometry ? 0.75f : 0.5f);  // the hit group's shader record
      EXPECT_EQ(p.d[0], isSphere ? 9u : 7u);                           // gl_InstanceCustomIndexEXT
      EXPECT_EQ(p.d[1], isSphere ? 1u : 0u);                           // gl_InstanceID
      EXPECT_EQ(p.d[2], nv ? 0u : e.geometry);                    // gl_GeometryIndexEXT (GL_NV_ray_tracing has none: 0)
      EXPECT_EQ(p.d[3], isSphere ? 5u : 0xFEu);                   // gl_HitKindEXT
      EXPECT_EQ(p.e[0], float((e.primitive + 10) * factor + 1));  // the callable's answer
      EXPECT_EQ(p.e[1], isSphere ? 0.25f - 1.0f : -1.0f);         // the secondary ray's miss shader
      EXPECT_EQ(p.e[2], -tr[2]);                                  // gl_WorldToObjectEXT[3].z
      EXPECT_NEAR(p.e[3], e.u, eps);                              // attributes read after the calls
      // The intersection shader's three reports for the primary ray: far (accepted), near (accepted), far again
      // (refused). It runs for the secondary ray too (traced from the sphere's surface away from it, opaque):
      // there all three are refused (behind or within tMin).
      EXPECT_EQ(answers[(y * kWidth + x) * 2], isSphere ? 8u + 3u : 0u);
      EXPECT_EQ(answers[(y * kWidth + x) * 2 + 1], isSphere ? 8u : 0u);
    }
  }
  // The scene covers every case: misses, both triangle geometries, a terminated ray, the sphere.
  EXPECT_GT(misses, 0);
  EXPECT_GT(spheres, 0);
  EXPECT_GT(hits - spheres, 0);
}

TEST(SpirvRayTracing, AllSixStagesTraceASceneThroughTheRuntime) { traceScene(true); }

// The same launch through the raygen shader's SPMD batch entry (a batch of the launch's 8 columns, the rest of the
// lanes off), against the same expectations.
TEST(SpirvRayTracing, TheRaygenBatchEntryTracesTheSameScene) {
  if (!spirv::spmdLanes()) GTEST_SKIP() << "SPMD off (VKRT_SPMD=0)";
  traceScene(true, false, true);
}

// The SPMD batch entry of a raygen shader with traces and a callable under divergent control (in a loop each lane
// leaves at its own iteration), a Private array and payload reads after each trace, against its scalar entry
// (vkrt_main): every byte of both outputs, at widths below, at and above a batch, a partial batch last.
TEST(SpirvRayTracing, RaygenBatchesWriteWhatTheScalarEntryWrites) {
  if (!spirv::spmdLanes()) GTEST_SKIP() << "SPMD off (VKRT_SPMD=0)";
  Stages s = compileAll(true);
  ASSERT_TRUE(s.miss && s.missSecondary && s.chit && s.ahit && s.rint && s.call);
  std::string e;
  s.raygen = compileStage(kSpv_rt_raygen_spmd_rgen, spv::ExecutionModelRayGenerationKHR, true, &e);
  ASSERT_TRUE(s.raygen) << e;
  ASSERT_TRUE(s.raygen->rayBatchEntry) << "the shader was not compiled SPMD";
  EXPECT_EQ(s.raygen->spmdLanes, spirv::spmdLanes());
  RaySbt sbt = sceneSbt(s);
  RayScene sc = scene();
  for (uint32_t width : {1u, 7u, 16u, 37u}) {
    SCOPED_TRACE("width " + std::to_string(width));
    const uint32_t height = 3, n = width * height;
    std::vector<Payload> results[2];
    std::vector<std::array<uint32_t, 4>> extra[2];
    for (int batched = 0; batched < 2; ++batched) {
      RayTestRuntime rt(sc, sbt, kAccel);
      results[batched].assign(n, Payload{});
      extra[batched].assign(n, {0xdeadbeef, 0, 0, 0});
      std::vector<uint32_t> answers(n * 2);
      rt.bindings[0] = abi::DescriptorRecord{kAccel, 0, nullptr, nullptr};
      rt.bindings[1] = abi::DescriptorRecord{reinterpret_cast<uint64_t>(results[batched].data()), n * sizeof(Payload),
                                             nullptr, nullptr};
      rt.bindings[2] = abi::DescriptorRecord{reinterpret_cast<uint64_t>(answers.data()), n * 8, nullptr, nullptr};
      rt.bindings[3] =
          abi::DescriptorRecord{reinterpret_cast<uint64_t>(extra[batched].data()), n * 16, nullptr, nullptr};
      rt.launch(s.raygen, {}, width, height, batched != 0);
      EXPECT_TRUE(rt.errors.empty()) << rt.errors.front();
    }
    ASSERT_EQ(std::memcmp(results[0].data(), results[1].data(), n * sizeof(Payload)), 0);
    for (uint32_t i = 0; i < n; ++i) {
      SCOPED_TRACE("launch index " + std::to_string(i));
      EXPECT_EQ(extra[0][i], extra[1][i]);
      // Every lane ran: its traces (1 to 3 rays, a lane of the second row all of them) and its callable.
      const uint32_t x = i % width, y = i / width;
      uint32_t traces = 0;
      for (uint32_t k = 0; k <= x % 3; ++k) traces += ((x + k) & 1) == 0 || y == 1;
      EXPECT_EQ(extra[1][i][1], traces);
      EXPECT_EQ(extra[1][i][2], x % 4 == 1 ? x * kFactor + 1 : 0u);
    }
  }
}

// Without inlining, ignoreIntersectionEXT runs in a function the any-hit shader calls: the status it sets must
// make the caller return too.
TEST(SpirvRayTracing, TerminatorsInCalledFunctionsStopTheShader) { traceScene(false); }

TEST(SpirvRayTracing, StackFactsOfEachStage) {
  Stages s = compileAll(true);
  ASSERT_TRUE(s.raygen && s.miss && s.missSecondary && s.chit && s.ahit && s.rint && s.call);
  auto align16 = [](uint64_t v) { return uint32_t((v + 15) / 16 * 16); };
  // raygen: an 80-byte outgoing payload kept in its frame across the trace, with the trace's arguments.
  const spirv::RayStageInfo& rg = s.raygen->ray;
  EXPECT_TRUE(rg.callsOut);
  EXPECT_EQ(rg.payloadBytes, sizeof(Payload));
  EXPECT_GE(rg.frameBytes, sizeof(Payload) + sizeof(abi::TraceRayArgs));
  EXPECT_LT(rg.frameBytes, 1024u);
  EXPECT_EQ(rg.stackSize(), align16(rg.frameBytes));
  // closest hit: traces and calls; reads 8 bytes of hit attributes after the calls.
  const spirv::RayStageInfo& ch = s.chit->ray;
  EXPECT_TRUE(ch.callsOut);
  EXPECT_TRUE(ch.readsHitAttributes);
  EXPECT_EQ(ch.payloadBytes, sizeof(Payload));  // the incoming payload is the largest
  EXPECT_EQ(ch.callableDataBytes, 4u);
  EXPECT_EQ(ch.hitAttributeBytes, 8u);
  EXPECT_GE(ch.frameBytes, 4u + 4u + sizeof(abi::TraceRayArgs));
  EXPECT_EQ(ch.stackSize(), align16(ch.frameBytes + 8));
  // The others call nothing: 0, whatever their frame.
  for (const auto* sh : {s.miss.get(), s.ahit.get(), s.rint.get(), s.call.get(), s.missSecondary.get()}) {
    EXPECT_FALSE(sh->ray.callsOut);
    EXPECT_EQ(sh->ray.stackSize(), 0u);
  }
  EXPECT_EQ(s.rint->ray.hitAttributeBytes, 8u);
  EXPECT_FALSE(s.rint->ray.readsHitAttributes);  // an intersection shader's attributes are its own
  EXPECT_EQ(s.call->ray.callableDataBytes, 4u);
  EXPECT_EQ(s.missSecondary->ray.payloadBytes, 4u);
}

// The shaders the pipeline tests use: the sizes their variables declare, and 0 for those that call nothing.
TEST(SpirvRayTracing, FactsOfThePipelineTestShaders) {
  std::string e;
  auto big = compileStage(kSpv_pipeline_raygen_big_payload_rgen, spv::ExecutionModelRayGenerationKHR, true, &e);
  ASSERT_TRUE(big) << e;
  EXPECT_TRUE(big->ray.callsOut);
  EXPECT_EQ(big->ray.payloadBytes, 256u);  // vec4[16]
  EXPECT_GE(big->ray.stackSize(), 256u + sizeof(abi::TraceRayArgs));
  auto small = compileStage(kSpv_pipeline_raygen_rgen, spv::ExecutionModelRayGenerationKHR, true, &e);
  ASSERT_TRUE(small) << e;
  EXPECT_EQ(small->ray.payloadBytes, 16u);
  EXPECT_GE(big->ray.stackSize(), small->ray.stackSize() + 240u);  // the payloads' difference at least
  auto chit = compileStage(kSpv_pipeline_chit_rchit, spv::ExecutionModelClosestHitKHR, true, &e);
  ASSERT_TRUE(chit) << e;
  EXPECT_EQ(chit->ray.payloadBytes, 16u);
  EXPECT_EQ(chit->ray.hitAttributeBytes, 8u);
  EXPECT_EQ(chit->ray.stackSize(), 0u);
  auto callable = compileStage(kSpv_pipeline_chit_callable_rchit, spv::ExecutionModelClosestHitKHR, true, &e);
  ASSERT_TRUE(callable) << e;
  EXPECT_TRUE(callable->ray.callsOut);
  EXPECT_EQ(callable->ray.callableDataBytes, 4u);
  EXPECT_GE(callable->ray.stackSize(), 16u);
  auto miss = compileStage(kSpv_pipeline_miss_rmiss, spv::ExecutionModelMissKHR, true, &e);
  auto ahit = compileStage(kSpv_pipeline_ahit_rahit, spv::ExecutionModelAnyHitKHR, true, &e);
  auto rint = compileStage(kSpv_pipeline_rint_rint, spv::ExecutionModelIntersectionKHR, true, &e);
  auto call = compileStage(kSpv_pipeline_call_rcall, spv::ExecutionModelCallableKHR, true, &e);
  ASSERT_TRUE(miss && ahit && rint && call) << e;
  for (const auto* sh : {miss.get(), ahit.get(), rint.get(), call.get()}) EXPECT_EQ(sh->ray.stackSize(), 0u);
  // An entry point is looked up with its execution model.
  EXPECT_FALSE(compileStage(kSpv_pipeline_miss_rmiss, spv::ExecutionModelClosestHitKHR, true, &e));
  EXPECT_EQ(e, "the module has no entry point \"main\" for this stage");
}

TEST(SpirvRayTracing, CompiledStagesRoundTripThroughTheCacheBlob) {
  Stages s = compileAll(true);
  ASSERT_TRUE(s.chit);
  std::string error;
  auto loaded = spirv::loadCached(s.chit->cacheBlob, nullptr, &error);
  ASSERT_TRUE(loaded) << error;
  EXPECT_EQ(loaded->model, spv::ExecutionModelClosestHitKHR);
  EXPECT_NE(loaded->rayEntry, nullptr);
  EXPECT_EQ(loaded->entry, nullptr);
  EXPECT_EQ(loaded->ray.frameBytes, s.chit->ray.frameBytes);
  EXPECT_EQ(loaded->ray.stackSize(), s.chit->ray.stackSize());
  EXPECT_EQ(loaded->ray.payloadBytes, s.chit->ray.payloadBytes);
  EXPECT_EQ(loaded->ray.callableDataBytes, s.chit->ray.callableDataBytes);
  EXPECT_EQ(loaded->ray.hitAttributeBytes, s.chit->ray.hitAttributeBytes);
  EXPECT_EQ(loaded->ray.readsHitAttributes, s.chit->ray.readsHitAttributes);
  ASSERT_EQ(loaded->resources.size(), s.chit->resources.size());
  EXPECT_EQ(loaded->resources[0].kind, spirv::ResourceBinding::AccelerationStructure);
}

// SPV_NV_ray_tracing: OpTraceNV and OpExecuteCallableNV name their payload by location, OpIgnoreIntersectionNV and
// OpTerminateRayNV are not block terminators; the scene's every value must come out as with the KHR forms.
TEST(SpirvRayTracing, NvStagesTraceTheSameScene) { traceScene(true, true); }

// Without inlining, ignoreIntersectionNV() ends the function it is in, and the any-hit shader calling it.
TEST(SpirvRayTracing, NvTerminatorsInCalledFunctionsStopTheShader) { traceScene(false, true); }

TEST(SpirvRayTracing, NvStagesHaveTheStackFactsOfTheKhrOnes) {
  Stages k = compileAll(true), n = compileAll(true, true);
  ASSERT_TRUE(n.raygen && n.chit && n.call && n.rint && n.miss && n.ahit);
  EXPECT_TRUE(n.raygen->ray.callsOut);
  EXPECT_EQ(n.raygen->ray.payloadBytes, k.raygen->ray.payloadBytes);
  EXPECT_TRUE(n.chit->ray.callsOut);
  EXPECT_EQ(n.chit->ray.payloadBytes, k.chit->ray.payloadBytes);
  EXPECT_EQ(n.chit->ray.callableDataBytes, 4u);
  EXPECT_EQ(n.chit->ray.hitAttributeBytes, 8u);
  EXPECT_EQ(n.rint->ray.hitAttributeBytes, 8u);
  EXPECT_EQ(n.call->ray.callableDataBytes, 4u);
  EXPECT_EQ(n.ahit->ray.stackSize(), 0u);
}

}  // namespace
}  // namespace vkrt::testing
