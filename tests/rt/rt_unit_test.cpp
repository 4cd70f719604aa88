// Unit tests of the ray tracing core: handle derivation and the registry, capture/replay encoding, the default
// stack-size formula, deferred operations. (Per-shader stack sizes are the compiler's: tests/spirv.)
#include <gtest/gtest.h>

#include <atomic>
#include <cstdio>
#include <cstring>
#include <set>
#include <thread>

#include "pipeline_ahit.rahit.spv.h"
#include "pipeline_call.rcall.spv.h"
#include "pipeline_chit.rchit.spv.h"
#include "pipeline_chit_callable.rchit.spv.h"
#include "pipeline_miss.rmiss.spv.h"
#include "pipeline_miss2.rmiss.spv.h"
#include "pipeline_raygen.rgen.spv.h"
#include "pipeline_raygen_big_payload.rgen.spv.h"
#include "pipeline_rint.rint.spv.h"
#include "position_fetch.rchit.newer.spvasm.spv.h"
#include "rt/group_handles.hpp"
#include "rt/stack_size.hpp"
#include "rt_chit.rchit.spv.h"
#include "rt_nv_chit.rchit.spv.h"
#include "runtime/shader_module.hpp"

namespace vkrt::rt {
namespace {

template <size_t N>
std::shared_ptr<ShaderDesc> shader(const uint32_t (&words)[N], VkShaderStageFlagBits stage,
                                   std::vector<std::pair<uint32_t, std::string>> spec = {}) {
  auto d = std::make_shared<ShaderDesc>();
  d->code = std::make_shared<const std::vector<uint32_t>>(words, words + N);
  d->codeHash = hashBytes(words, sizeof(words));
  d->entry = "main";
  d->stage = stage;
  d->specialization = std::move(spec);
  return d;
}

GroupDesc general(std::shared_ptr<ShaderDesc> s) {
  GroupDesc g;
  g.type = VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR;
  g.shaders[kGeneral] = std::move(s);
  return g;
}

constexpr uint64_t kGoldenLo = 0x956ff948b28d0801ull, kGoldenHi = 0x6e71d46811854c04ull;

TEST(Hash128, StableAndSensitive) {
  const char text[] = "vkrt";
  Digest a = hash128(text, 4), b = hash128(text, 4);
  EXPECT_EQ(a, b);
  // A fixed value: the digest (hence every handle) must not change between builds or runs.
  EXPECT_EQ(a.lo, kGoldenLo);
  EXPECT_EQ(a.hi, kGoldenHi);
  Digest c = hash128("vkrs", 4);
  EXPECT_NE(a.lo, c.lo);
  EXPECT_NE(a.hi, c.hi);
  EXPECT_NE(hash128(text, 3), a);
}

TEST(GroupRegistry, SameContentSameHandleDifferentContentDifferentHandle) {
  GroupRegistry reg;
  auto m1 = shader(kSpv_pipeline_miss_rmiss, VK_SHADER_STAGE_MISS_BIT_KHR);
  auto m1b = shader(kSpv_pipeline_miss_rmiss, VK_SHADER_STAGE_MISS_BIT_KHR);  // another module object, same words
  auto m2 = shader(kSpv_pipeline_miss2_rmiss, VK_SHADER_STAGE_MISS_BIT_KHR);
  const GroupRecord* a = reg.acquire(general(m1), nullptr);
  const GroupRecord* b = reg.acquire(general(m1b), nullptr);
  const GroupRecord* c = reg.acquire(general(m2), nullptr);
  EXPECT_EQ(a, b);
  EXPECT_EQ(a->handle, b->handle);
  EXPECT_NE(a->handle, c->handle);
  // Another registry (another device, process or run) derives the same bytes.
  GroupRegistry other;
  EXPECT_EQ(other.acquire(general(m2), nullptr)->handle, c->handle);
  // Specialization and entry point name are part of the content.
  auto s1 = shader(kSpv_pipeline_miss_rmiss, VK_SHADER_STAGE_MISS_BIT_KHR, {{0, std::string("\1\0\0\0", 4)}});
  auto s2 = shader(kSpv_pipeline_miss_rmiss, VK_SHADER_STAGE_MISS_BIT_KHR, {{0, std::string("\2\0\0\0", 4)}});
  EXPECT_NE(reg.acquire(general(s1), nullptr)->handle, reg.acquire(general(s2), nullptr)->handle);
  EXPECT_NE(reg.acquire(general(s1), nullptr)->handle, a->handle);
  auto named = shader(kSpv_pipeline_miss_rmiss, VK_SHADER_STAGE_MISS_BIT_KHR);
  named->entry = "other";
  EXPECT_NE(reg.acquire(general(named), nullptr)->handle, a->handle);
}

TEST(GroupRegistry, HandleLayoutAndDecode) {
  GroupRegistry reg;
  const GroupRecord* r = reg.acquire(general(shader(kSpv_pipeline_miss_rmiss, VK_SHADER_STAGE_MISS_BIT_KHR)), nullptr);
  const uint8_t* h = r->handle.data();
  uint32_t slot, check, type, magic;
  std::memcpy(&slot, h, 4);
  std::memcpy(&check, h + 4, 4);
  std::memcpy(&type, h + 24, 4);
  std::memcpy(&magic, h + 28, 4);
  EXPECT_EQ(slot, r->slot);
  EXPECT_EQ(slot, static_cast<uint32_t>(r->digest.lo));
  EXPECT_EQ(check, static_cast<uint32_t>(r->digest.hi >> 32));
  EXPECT_EQ(type, uint32_t(VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR) | kHandleVersion << 8);
  EXPECT_EQ(magic, kHandleMagic);
  EXPECT_EQ(reg.decode(h), r);
  auto bad = r->handle;
  bad[4] ^= 1;  // wrong check value
  EXPECT_EQ(reg.decode(bad.data()), nullptr);
  bad = r->handle;
  bad[0] ^= 1;  // a slot nobody holds
  EXPECT_EQ(reg.decode(bad.data()), nullptr);
  uint8_t zeros[32] = {};
  EXPECT_EQ(reg.decode(zeros), nullptr);
}

TEST(GroupRegistry, SlotCollisionIsPerturbedDeterministically) {
  // Fill the slot the next group would take with a replayed group whose capture data names that slot.
  auto m = shader(kSpv_pipeline_miss_rmiss, VK_SHADER_STAGE_MISS_BIT_KHR);
  auto m2 = shader(kSpv_pipeline_miss2_rmiss, VK_SHADER_STAGE_MISS_BIT_KHR);
  GroupRegistry probe;
  const GroupRecord* want = probe.acquire(general(m), nullptr);
  GroupRegistry scratch;
  auto capture = scratch.acquire(general(m2), nullptr)->captureData();
  // Rewrite m2's captured handle to claim m's slot (and fix the check value/checksum as a capture would).
  GroupRecord forged = *scratch.acquire(general(m2), nullptr);
  forged.slot = want->slot;
  forged.handle = scratch.acquire(general(m2), nullptr)->handle;
  std::memcpy(forged.handle.data(), &want->slot, 4);
  capture = forged.captureData();
  GroupRegistry reg1, reg2;
  ASSERT_NE(reg1.replay(general(m2), capture.data(), nullptr), nullptr);
  ASSERT_NE(reg2.replay(general(m2), capture.data(), nullptr), nullptr);
  const GroupRecord* a = reg1.acquire(general(m), nullptr);
  const GroupRecord* b = reg2.acquire(general(m), nullptr);
  EXPECT_NE(a->slot, want->slot);   // moved
  EXPECT_EQ(a->handle, b->handle);  // the same way in both
  EXPECT_EQ(reg1.decode(a->handle.data()), a);
}

TEST(CaptureReplay, RoundTripAndRefusals) {
  auto m = shader(kSpv_pipeline_miss_rmiss, VK_SHADER_STAGE_MISS_BIT_KHR);
  auto m2 = shader(kSpv_pipeline_miss2_rmiss, VK_SHADER_STAGE_MISS_BIT_KHR);
  GroupRegistry capture;
  const GroupRecord* orig = capture.acquire(general(m), nullptr);
  auto data = orig->captureData();

  GroupRegistry replay;
  replay.acquire(general(m2), nullptr);  // unrelated groups first
  const GroupRecord* r = replay.replay(general(m), data.data(), nullptr);
  ASSERT_NE(r, nullptr);
  EXPECT_EQ(r->handle, orig->handle);
  EXPECT_TRUE(r->replayed);
  EXPECT_EQ(replay.acquire(general(m), nullptr)->handle, orig->handle);  // Mixed: a later plain one agrees

  ReplayError e;
  auto corrupt = data;
  corrupt[10] ^= 0x40;
  EXPECT_EQ(replay.replay(general(m), corrupt.data(), &e), nullptr);
  EXPECT_NE(e.reason.find("corrupt"), std::string::npos) << e.reason;
  auto truncated = data;
  std::memset(truncated.data() + 32, 0, 32);
  EXPECT_EQ(replay.replay(general(m), truncated.data(), &e), nullptr);
  EXPECT_NE(e.reason.find("magic"), std::string::npos) << e.reason;
  EXPECT_EQ(replay.replay(general(m2), data.data(), &e), nullptr);
  EXPECT_NE(e.reason.find("other shaders"), std::string::npos) << e.reason;
  GroupDesc hit;
  hit.type = VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR;
  hit.shaders[kClosestHit] = shader(kSpv_pipeline_chit_rchit, VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR);
  EXPECT_EQ(replay.replay(hit, data.data(), &e), nullptr);
  EXPECT_NE(e.reason.find("GENERAL"), std::string::npos) << e.reason;
}

// Found by fuzz/group_handles_fuzz.cpp (fuzz/corpus/group_handles/regress-capture-type-out-of-range): capture
// data whose group type word is past VkRayTracingShaderGroupTypeKHR's range (with a valid checksum) made the
// refusal's message convert it to the enum, undefined behaviour. It is refused naming an unknown type.
TEST(CaptureReplay, GroupTypeOutOfRangeIsRefused) {
  auto m = shader(kSpv_pipeline_miss_rmiss, VK_SHADER_STAGE_MISS_BIT_KHR);
  GroupRegistry capture;
  auto data = capture.acquire(general(m), nullptr)->captureData();
  const uint32_t type = 0xca20d260u, sum = 0;
  std::memcpy(data.data() + 56, &type, 4);
  std::memcpy(data.data() + 60, &sum, 4);
  const uint32_t checksum = uint32_t(hash128(data.data(), 60).lo);
  std::memcpy(data.data() + 60, &checksum, 4);
  GroupRegistry replay;
  ReplayError e;
  EXPECT_EQ(replay.replay(general(m), data.data(), &e), nullptr);
  EXPECT_NE(e.reason.find("captured from a unknown group"), std::string::npos) << e.reason;
  EXPECT_EQ(replay.size(), 0u);
}

TEST(StackSize, SpecFormula) {
  StageStackMax m;
  m.rayGen = 100;
  m.closestHit = 40;
  m.miss = 30;
  m.intersection = 10;
  m.anyHit = 50;
  m.callable = 7;
  // depth 0: raygen + 2 * callable.
  EXPECT_EQ(defaultPipelineStackSize(m, 0), 100u + 14u);
  // depth 1: + max(40, 30, 60).
  EXPECT_EQ(defaultPipelineStackSize(m, 1), 100u + 60u + 14u);
  // depth 3: + 2 * max(40, 30).
  EXPECT_EQ(defaultPipelineStackSize(m, 3), 100u + 60u + 80u + 14u);
}

// Which hit built-ins a shader may read decides what its invocations get (exec::RayShader): a closest-hit shader
// reading gl_ObjectToWorldEXT / gl_WorldToObjectEXT (and the NV names, the same tokens) needs the transforms, one
// with HitTriangleVertexPositionsKHR the positions, and a shader declaring neither needs neither.
TEST(HitBuiltins, TheDecorationsAndTheCapabilityDecide) {
  auto read = [](const uint32_t* words, size_t bytes, bool* transforms, bool* positions) {
    hitBuiltinsRead(std::vector<uint32_t>(words, words + bytes / 4), transforms, positions);
  };
  bool transforms = false, positions = true;
  read(kSpv_rt_chit_rchit, sizeof kSpv_rt_chit_rchit, &transforms, &positions);
  EXPECT_TRUE(transforms);
  EXPECT_FALSE(positions);
  transforms = false, positions = true;
  read(kSpv_rt_nv_chit_rchit, sizeof kSpv_rt_nv_chit_rchit, &transforms, &positions);
  EXPECT_TRUE(transforms);
  EXPECT_FALSE(positions);
  transforms = true, positions = false;
  read(kSpv_position_fetch_rchit_newer_spvasm, sizeof kSpv_position_fetch_rchit_newer_spvasm, &transforms, &positions);
  EXPECT_FALSE(transforms);
  EXPECT_TRUE(positions);
  transforms = positions = true;
  read(kSpv_pipeline_ahit_rahit, sizeof kSpv_pipeline_ahit_rahit, &transforms, &positions);
  EXPECT_FALSE(transforms);
  EXPECT_FALSE(positions);
  // A module cut inside an instruction (no module reaches the scan so: validation refuses it) reads both.
  std::vector<uint32_t> cut(kSpv_pipeline_ahit_rahit, kSpv_pipeline_ahit_rahit + 7);
  cut[5] = (100u << 16) | (cut[5] & 0xFFFF);
  hitBuiltinsRead(cut, &transforms, &positions);
  EXPECT_TRUE(transforms);
  EXPECT_TRUE(positions);
}

}  // namespace
}  // namespace vkrt::rt
