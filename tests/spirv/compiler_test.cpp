// The SPIR-V compiler and the compute executor, below the Vulkan API: GLSL shaders (compiled by glslc at build
// time) run on host buffers, and every output is compared with a value computed independently here.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <climits>
#include <cmath>
#include <cstring>
#include <numeric>

#include "compute_arith.comp.spv.h"
#include "compute_atomics.comp.spv.h"
#include "compute_composite.comp.spv.h"
#include "compute_control.comp.spv.h"
#include "compute_descriptor_array.comp.spv.h"
#include "compute_glsl.comp.spv.h"
#include "compute_push_spec.comp.spv.h"
#include "compute_shared.comp.spv.h"
#include "compute_unsupported.comp.spv.h"
#include "compute_wide.comp.spv.h"
#include "spirv/compute_harness.hpp"

namespace vkrt::testing {
namespace {

int32_t bitExtractS(int32_t v, int off, int bits) {
  uint32_t u = (uint32_t(v) >> off) & ((1u << bits) - 1);
  if (u >> (bits - 1)) u |= ~((1u << bits) - 1);
  return int32_t(u);
}
uint32_t reverseBits(uint32_t v) {
  uint32_t r = 0;
  for (int i = 0; i < 32; ++i) r |= ((v >> i) & 1u) << (31 - i);
  return r;
}
// glslang translates GLSL's % on ints to OpSMod: the result takes the divisor's sign.
int32_t smod(int32_t x, int32_t y) {
  if (y == 0) return 0;
  int32_t r = x % y;
  return (r != 0 && ((r < 0) != (y < 0))) ? r + y : r;
}
int32_t findMsbS(int32_t v) {
  uint32_t u = v < 0 ? ~uint32_t(v) : uint32_t(v);
  return u == 0 ? -1 : 31 - std::countl_zero(u);
}

void expectNear(float got, float want, float tol, const char* what, size_t i) {
  float err = std::fabs(got - want);
  EXPECT_LE(err, tol * std::max(1.0f, std::fabs(want))) << what << " at " << i << ": got " << got << " want " << want;
}

TEST(SpirvCompiler, IntegerFloatBoolArithmetic) {
  ComputeHarness h;
  ASSERT_TRUE(h.compile(kSpv_compute_arith_comp)) << h.error;
  const size_t n = 64;
  std::vector<int32_t> a(n), b(n);
  for (size_t i = 0; i < n; ++i) {
    a[i] = int32_t(i * 7919u % 2001) - 1000 + int32_t(i % 5 == 0 ? 0x12345678 : 0);
    b[i] = int32_t(i * 104729u % 61) - 30;
  }
  b[3] = 0;
  a[4] = 0;
  h.setBuffer(0, a);
  h.setBuffer(1, b);
  h.zeroBuffer<int32_t>(2, n * 24);
  h.zeroBuffer<float>(3, n * 8);
  ASSERT_TRUE(h.run(n / 16));
  auto r = h.get<int32_t>(2);
  auto f = h.get<float>(3);
  for (size_t i = 0; i < n; ++i) {
    int32_t x = a[i], y = b[i];
    uint32_t ux = uint32_t(x), uy = uint32_t(y);
    int32_t want[24] = {
        int32_t(ux + uy),
        int32_t(ux - uy),
        int32_t(ux * uy),
        y ? x / y : 0,
        smod(x, y),
        int32_t(uy ? ux / uy : 0u),
        int32_t(uy ? ux % uy : 0u),
        x & y,
        x | y,
        x ^ y,
        ~x,
        int32_t(ux << (uy & 31)),
        x >> (y & 31),
        int32_t(ux >> (uy & 31)),
        (x < y ? 1 : 0) | (x <= y ? 2 : 0) | (x > y ? 4 : 0) | (x >= y ? 8 : 0) | (x == y ? 16 : 0) |
            (x != y ? 32 : 0) | (ux < uy ? 64 : 0) | (ux > uy ? 128 : 0),
        int32_t(0u - ux),
        std::popcount(ux),
        findMsbS(x),
        x == 0 ? -1 : std::countr_zero(ux),
        bitExtractS(x, 3, 7),
        int32_t((ux >> 5) & 511u),
        int32_t((ux & ~0xff0u) | ((uy & 0xffu) << 4)),
        int32_t(reverseBits(ux)),
        ((x > 0 && y > 0) ? 1 : 0) | ((x > 0 || y > 0) ? 2 : 0) | (((x > 0) != (y > 0)) ? 4 : 0) | (!(x > 0) ? 8 : 0)};
    for (int k = 0; k < 24; ++k)
      EXPECT_EQ(r[i * 24 + k], want[k]) << "output " << k << " of invocation " << i << " (a=" << x << " b=" << y << ")";
    float fa = float(x) * 0.25f, fb = float(y) * 0.5f;
    float wf[8] = {fa + fb,
                   fa - fb,
                   fa * fb,
                   fb != 0 ? fa / fb : 0.0f,
                   fb != 0 ? fa - fb * std::floor(fa / fb) : 0.0f,
                   float(int32_t(fa * 3.0f)),
                   float(uint32_t(std::fabs(fa))),
                   (fa < fb ? 1.0f : 0.0f) + (fa >= fb ? 2.0f : 0.0f)};
    for (int k = 0; k < 8; ++k) expectNear(f[i * 8 + k], wf[k], 1e-5f, "float output", i * 8 + k);
  }
}

TEST(SpirvCompiler, ControlFlowLoopsSwitchCalls) {
  ComputeHarness h;
  ASSERT_TRUE(h.compile(kSpv_compute_control_comp)) << h.error;
  const size_t n = 64;
  std::vector<uint32_t> v(n);
  for (size_t i = 0; i < n; ++i) v[i] = uint32_t(i * 13 % 97);
  h.setBuffer(0, v);
  ASSERT_TRUE(h.run(n / 8));
  auto r = h.get<uint32_t>(0);
  for (size_t i = 0; i < n; ++i) {
    uint32_t x = v[i];
    uint32_t c = x + 1, steps = 0;
    while (c != 1 && steps < 1000) {
      c = c % 2 == 0 ? c / 2 : 3 * c + 1;
      ++steps;
    }
    uint32_t cls;
    switch (x % 6) {
      case 0: cls = 10; break;
      case 1:
      case 2: cls = 20 + x; break;
      case 4: cls = 40; break;
      default: cls = 30; break;
    }
    uint32_t s = 0;
    for (uint32_t k = 0; k < x; ++k) {
      if (k % 3 == 0) continue;
      if (k > 50) break;
      s += k;
    }
    uint32_t j = 0;
    do {
      s += j;
      j += 2;
    } while (j < x);
    EXPECT_EQ(r[i], steps * 1000000u + cls * 1000u + s) << "input " << x;
  }
}

TEST(SpirvCompiler, WorkgroupMemoryAndBarriers) {
  ComputeHarness h;
  ASSERT_TRUE(h.compile(kSpv_compute_shared_comp)) << h.error;
  EXPECT_TRUE(h.shader->usesBarrier);
  EXPECT_GE(h.shader->workgroupMemorySize, 64u * 4 * 2 + 4) << "two shared uint[64] arrays and a counter";
  EXPECT_LE(h.shader->workgroupMemorySize, 64u * 4 * 2 + 16);
  const size_t groups = 7, n = groups * 64;
  std::vector<uint32_t> v(n);
  for (size_t i = 0; i < n; ++i) v[i] = uint32_t(i * 2654435761u >> 8);
  h.setBuffer(0, v);
  h.zeroBuffer<uint32_t>(1, groups * 2);
  ASSERT_TRUE(h.run(groups));
  auto r = h.get<uint32_t>(0);
  auto sums = h.get<uint32_t>(1);
  for (size_t g = 0; g < groups; ++g) {
    uint32_t want = 0;
    for (size_t l = 0; l < 64; ++l) {
      EXPECT_EQ(r[g * 64 + l], v[g * 64 + 63 - l]) << "group " << g << " lane " << l;
      want += v[g * 64 + l];
    }
    EXPECT_EQ(sums[2 * g], want) << "group " << g;
    EXPECT_EQ(sums[2 * g + 1], 64u) << "workgroup atomic counter of group " << g;
  }
}

TEST(SpirvCompiler, StorageBufferAtomics) {
  ComputeHarness h;
  ASSERT_TRUE(h.compile(kSpv_compute_atomics_comp)) << h.error;
  const uint32_t n = 32 * 9;
  std::vector<uint32_t> c(8 + 16, 0);
  c[1] = 0xffffffffu;  // min
  c[5] = 0x7fffffff;   // signed min
  h.setBuffer(0, c);
  h.zeroBuffer<uint32_t>(1, n);
  ASSERT_TRUE(h.run(n / 32));
  auto r = h.get<uint32_t>(0);
  auto old = h.get<uint32_t>(1);
  uint32_t mn = 0xffffffffu, mx = 0, orv = 0, xr = 0;
  int32_t smin = 0x7fffffff;
  std::vector<uint32_t> hist(16, 0);
  for (uint32_t i = 0; i < n; ++i) {
    uint32_t v = (i * 2654435761u) >> 7;
    mn = std::min(mn, v);
    mx = std::max(mx, v);
    orv |= 1u << (i % 32);
    xr ^= v;
    smin = std::min(smin, int32_t(v) - 1000000);
    hist[v % 16]++;
  }
  EXPECT_EQ(r[0], n);
  EXPECT_EQ(r[1], mn);
  EXPECT_EQ(r[2], mx);
  EXPECT_EQ(r[3], orv);
  EXPECT_EQ(r[4], xr);
  EXPECT_EQ(int32_t(r[5]), smin);
  EXPECT_EQ(r[6], 7u);
  EXPECT_GE(r[7], 1u);
  EXPECT_LE(r[7], n);
  for (int k = 0; k < 16; ++k) EXPECT_EQ(r[8 + k], hist[k]) << "bucket " << k;
  // Every invocation saw a distinct previous counter value: a permutation of 0..n-1.
  std::sort(old.begin(), old.end());
  for (uint32_t i = 0; i < n; ++i) ASSERT_EQ(old[i], i);
}

TEST(SpirvCompiler, GlslStd450) {
  ComputeHarness h;
  ASSERT_TRUE(h.compile(kSpv_compute_glsl_comp)) << h.error;
  const size_t n = 16;
  std::vector<float> x(n + 1);
  for (size_t i = 0; i <= n; ++i) x[i] = -2.3f + 0.37f * float(i);
  h.setBuffer(0, x);
  h.zeroBuffer<float>(1, n * 32);
  ASSERT_TRUE(h.run(n / 4));
  auto r = h.get<float>(1);
  auto clampf = [](float v, float lo, float hi) { return std::min(std::max(v, lo), hi); };
  for (size_t i = 0; i < n; ++i) {
    float a = x[i], b = x[i + 1];
    float t = clampf((a + 1.0f) / 3.0f, 0.0f, 1.0f);
    float ax = a, ay = b, az = 1.0f, bx = b, by = 2.0f, bz = a;
    float len = std::sqrt(ax * ax + ay * ay + az * az);
    float cx = ay * bz - az * by, cy = az * bx - ax * bz, cz = ax * by - ay * bx;
    float bl = std::sqrt(bx * bx + by * by + bz * bz);
    float nbx = bx / bl, nby = by / bl, nbz = bz / bl;
    float d2 = 2.0f * (ax * nbx + ay * nby + az * nbz);
    float want[32] = {std::sin(a),
                      std::cos(a),
                      std::tan(a * 0.3f),
                      std::exp(a * 0.5f),
                      std::log(std::fabs(a) + 1.0f),
                      std::pow(std::fabs(a) + 0.5f, 1.7f),
                      std::sqrt(std::fabs(a)),
                      1.0f / std::sqrt(std::fabs(a) + 1.0f),
                      std::floor(a),
                      std::ceil(a),
                      a - std::floor(a),
                      clampf(a, -1.0f, 1.5f),
                      a + (b - a) * 0.25f,
                      a < 0.5f ? 0.0f : 1.0f,
                      t * t * (3.0f - 2.0f * t),
                      std::atan2(a, b + 3.0f),
                      std::min(a, b),
                      std::max(a, b),
                      a > 0   ? 1.0f
                      : a < 0 ? -1.0f
                              : 0.0f,
                      std::round(a),
                      std::trunc(a),
                      std::exp2(a * 0.5f),
                      std::log2(std::fabs(a) + 1.0f),
                      std::asin(clampf(a * 0.2f, -1.0f, 1.0f)),
                      len,
                      std::sqrt((ax - bx) * (ax - bx) + (ay - by) * (ay - by) + (az - bz) * (az - bz)),
                      ax * bx + ay * by + az * bz,
                      cx + 2 * cy + 3 * cz,
                      (ax + 2 * ay + 3 * az) / len,
                      (ax - d2 * nbx) + 2 * (ay - d2 * nby) + 3 * (az - d2 * nbz),
                      a * b + 1.0f,
                      a * 3.14159265f / 180.0f + b * 180.0f / 3.14159265f};
    for (int k = 0; k < 32; ++k) expectNear(r[i * 32 + k], want[k], 1e-4f, "GLSL.std.450 output", size_t(k));
  }
}

TEST(SpirvCompiler, PushConstantsAndSpecialization) {
  auto spec = [](uint32_t id, auto v) {
    spirv::SpecValue s{id, std::vector<uint8_t>(sizeof v)};
    std::memcpy(s.bytes.data(), &v, sizeof v);
    return s;
  };
  for (bool negate : {false, true}) {
    ComputeHarness h;
    ASSERT_TRUE(h.compile(kSpv_compute_push_spec_comp,
                          {spec(0, uint32_t(8)), spec(1, int32_t(3)), spec(2, uint32_t(negate)), spec(3, 0.25f)}))
        << h.error;
    EXPECT_EQ(h.shader->localSize[0], 8u);
    struct {
      uint32_t count;
      int32_t offset;
      float fscale;
      float pad;
      float extra[2];
    } pc = {37, -5, 1.5f, 0, {2.0f, 3.0f}};
    std::memcpy(h.push, &pc, sizeof pc);
    h.setBuffer(0, std::vector<float>(41, -1.0f));
    ASSERT_TRUE(h.run(5));  // 40 invocations: 3 past count return early
    auto r = h.get<float>(0);
    for (uint32_t i = 0; i < 37; ++i) {
      float v = float(int32_t(i) * 3 - 5) * 1.5f + 0.25f + 6.0f;
      EXPECT_FLOAT_EQ(r[i], negate ? -v : v) << i;
    }
    EXPECT_FLOAT_EQ(r[37], 8.0f) << "gl_WorkGroupSize.x from the specialized LocalSizeId";
    EXPECT_FLOAT_EQ(r[38], -1.0f);
  }
  // Defaults when nothing is specialized: local size 1, scale 2, no negation, bias 0.5.
  ComputeHarness h;
  ASSERT_TRUE(h.compile(kSpv_compute_push_spec_comp)) << h.error;
  EXPECT_EQ(h.shader->localSize[0], 1u);
}

TEST(SpirvCompiler, CompositesMatricesStd140) {
  ComputeHarness h;
  ASSERT_TRUE(h.compile(kSpv_compute_composite_comp)) << h.error;
  // std140 Params: mat4 m @0 (64 bytes), row_major mat3 r @64 (3 rows x 16), vec4 v[4] @112,
  // Item items[2] @176 (stride 32: vec3 pos @0, float w @12, ivec2 id @16).
  std::vector<uint8_t> ubo(240, 0);
  float m[4][4], rr[3][3], v[4][4];
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) m[c][r] = float(c * 4 + r) * 0.5f - 3.0f;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) rr[r][c] = float(r * 3 + c) - 4.0f + (r == c ? 2.0f : 0.0f);
  for (int i = 0; i < 4; ++i)
    for (int k = 0; k < 4; ++k) v[i][k] = float(i + 1) * (k % 2 ? -1.0f : 1.0f) + float(k);
  std::memcpy(ubo.data(), m, 64);
  for (int r = 0; r < 3; ++r) std::memcpy(ubo.data() + 64 + 16 * r, rr[r], 12);
  std::memcpy(ubo.data() + 112, v, 64);
  struct Item {
    float pos[3], w;
    int32_t id[2];
  } items[2] = {{{1, 2, 3}, 0.5f, {2, 3}}, {{-1, 4, 0.25f}, 1.5f, {-1, 5}}};
  for (int i = 0; i < 2; ++i) std::memcpy(ubo.data() + 176 + 32 * i, &items[i], sizeof(Item));
  h.setBuffer(0, ubo);
  h.zeroBuffer<float>(1, 4 * 5 * 4);
  ASSERT_TRUE(h.run(1));
  auto out = h.get<float>(1);
  for (int i = 0; i < 4; ++i) {
    const float* a = v[i];
    const float* o = &out[size_t(i) * 20];
    for (int r = 0; r < 4; ++r) {
      float s = 0;
      for (int c = 0; c < 4; ++c) s += m[c][r] * a[c];
      expectNear(o[r], s, 1e-5f, "mat4 * vec4", size_t(r));
    }
    for (int r = 0; r < 3; ++r) {
      float s = 0, s2 = 0;
      for (int c = 0; c < 3; ++c) s += rr[r][c] * a[c];
      float az[3] = {a[2], a[1], a[0]};
      for (int k = 0; k < 3; ++k) s2 += az[k] * rr[k][r];
      expectNear(o[4 + r], s, 1e-5f, "row-major mat3 * vec3", size_t(r));
      expectNear(o[8 + r], s2, 1e-5f, "vec3 * row-major mat3", size_t(r));
    }
    expectNear(o[7], m[i][i], 0, "m[i][i]", 0);
    expectNear(o[11], a[0] * a[3] + a[1] * a[2] + a[2] * a[1] + a[3] * a[0], 1e-5f, "dot", 0);
    // transpose(t) * t with t = mat2(a.x, a.y, a.z, a.w): columns (x, y), (z, w).
    float tt[4] = {a[0] * a[0] + a[1] * a[1], a[2] * a[0] + a[3] * a[1], a[0] * a[2] + a[1] * a[3],
                   a[2] * a[2] + a[3] * a[3]};
    for (int k = 0; k < 4; ++k) expectNear(o[12 + k], tt[k], 1e-5f, "transpose(t) * t", size_t(k));
    const Item& it = items[i % 2];
    float local[4] = {1, 2, 3, 4};
    local[i] += it.w;
    for (int k = 0; k < 3; ++k)
      expectNear(o[16 + k], it.pos[k] * float(it.id[0] + it.id[1]), 1e-6f, "struct array", size_t(k));
    expectNear(o[19], local[i] + local[(i + 1) % 4], 1e-6f, "local array", 0);
  }
}

TEST(SpirvCompiler, DispatchBaseAndMultiDimensionalIds) {
  // The control-flow shader reads and writes v[gl_GlobalInvocationID.x]: with a base workgroup of 2 only
  // elements 16.. change.
  ComputeHarness h;
  ASSERT_TRUE(h.compile(kSpv_compute_control_comp)) << h.error;
  std::vector<uint32_t> v(48, 5);
  h.setBuffer(0, v);
  ASSERT_TRUE(h.run(4, 1, 1, 2, 0, 0));
  auto r = h.get<uint32_t>(0);
  for (size_t i = 0; i < 16; ++i) EXPECT_EQ(r[i], 5u) << i;
  for (size_t i = 16; i < 48; ++i) EXPECT_NE(r[i], 5u) << i;
}

TEST(SpirvCompiler, OutOfBoundsAccessesAreContained) {
  // A storage buffer smaller than the shader indexes: the writes past its range are dropped, reads give 0.
  ComputeHarness h;
  ASSERT_TRUE(h.compile(kSpv_compute_control_comp)) << h.error;
  std::vector<uint32_t> v(8, 3);
  h.setBuffer(0, v);
  ASSERT_TRUE(h.run(4));  // 32 invocations, 8 elements
  auto r = h.get<uint32_t>(0);
  for (size_t i = 0; i < 8; ++i) EXPECT_NE(r[i], 3u);
}

TEST(SpirvCompiler, SixtyFourBitIntegersAndDoubles) {
  ComputeHarness h;
  ASSERT_TRUE(h.compile(kSpv_compute_wide_comp)) << h.error;
  const size_t n = 8;
  struct Pair {
    int64_t a;
    uint64_t b;
  };
  std::vector<Pair> in(n);
  std::vector<double> d(n);
  for (size_t i = 0; i < n; ++i) {
    in[i].a = (int64_t(i) - 4) * 0x123456789abll;
    in[i].b = 0xfedcba9876543210ull >> i;
    d[i] = -3.7 + 1.1 * double(i);
  }
  h.setBuffer(0, in);
  h.setBuffer(1, d);
  h.zeroBuffer<uint64_t>(2, n * 8);
  h.zeroBuffer<double>(3, n * 3);
  ASSERT_TRUE(h.run(n / 4));
  auto r = h.get<uint64_t>(2);
  auto rd = h.get<double>(3);
  for (size_t i = 0; i < n; ++i) {
    int64_t x = in[i].a;
    uint64_t y = in[i].b;
    uint64_t want[8] = {uint64_t(x) * y + 0x100000000ull,
                        uint64_t(x >> 7),
                        y >> 33,
                        y / 3,
                        uint64_t(x / 5),
                        uint64_t((x < int64_t(y) ? 1 : 0) | (uint64_t(x) < y ? 2 : 0)),
                        uint64_t(int64_t(d[i] * 1000.0)),
                        uint64_t(uint32_t(y) + uint32_t(x))};
    for (int k = 0; k < 8; ++k) EXPECT_EQ(r[i * 8 + k], want[k]) << "output " << k << " of " << i;
    EXPECT_DOUBLE_EQ(rd[i * 3 + 0], d[i] * d[i] + double(x) * 0.5);
    EXPECT_DOUBLE_EQ(rd[i * 3 + 1], std::sqrt(std::fabs(d[i])) + std::floor(d[i]));
    EXPECT_EQ(rd[i * 3 + 2], double(float(d[i])));
  }
}

TEST(SpirvCompiler, DescriptorArraysAndArrayLength) {
  ComputeHarness h;
  ASSERT_TRUE(h.compile(kSpv_compute_descriptor_array_comp)) << h.error;
  ASSERT_EQ(h.shader->resources.size(), 2u);
  for (const spirv::ResourceBinding& rb : h.shader->resources) EXPECT_EQ(rb.arraySize, rb.binding == 0 ? 3u : 1u);
  std::vector<uint32_t> b0(8), b1(8), b2(13);
  for (uint32_t i = 0; i < 8; ++i) {
    b0[i] = i;
    b1[i] = i + 1;
    b2[i] = 9 - i;
  }
  h.setBuffer(100, b0);
  h.setBuffer(101, b1);
  h.setBuffer(102, b2);
  h.arrays[0] = {100, 101, 102};
  h.zeroBuffer<uint32_t>(1, 8);
  ASSERT_TRUE(h.run(2));
  auto r = h.get<uint32_t>(1);
  for (uint32_t i = 0; i < 8; ++i) EXPECT_EQ(r[i], b0[i] + 10 * b1[i] + 100 * b2[i] + 1000 * 13) << i;
  // With only two descriptors bound, the third reads as an empty buffer: zeros and length 0.
  h.arrays[0] = {100, 101};
  ASSERT_TRUE(h.run(2));
  r = h.get<uint32_t>(1);
  for (uint32_t i = 0; i < 8; ++i) EXPECT_EQ(r[i], b0[i] + 10 * b1[i]) << i;
}

TEST(SpirvCompiler, UnsupportedInstructionIsReportedWithItsOffset) {
  ComputeHarness h;
  EXPECT_FALSE(h.compile(kSpv_compute_unsupported_comp));
  EXPECT_NE(h.error.find("unsupported instruction OpGroupNonUniformShuffle at word"), std::string::npos) << h.error;
}

TEST(SpirvCompiler, MissingEntryPoint) {
  spirv::CompileRequest r;
  r.words = kSpv_compute_arith_comp;
  r.wordCount = sizeof kSpv_compute_arith_comp / 4;
  r.entryName = "nope";
  std::string error;
  EXPECT_EQ(spirv::compile(r, &error), nullptr);
  EXPECT_NE(error.find("no entry point \"nope\""), std::string::npos) << error;
}

}  // namespace
}  // namespace vkrt::testing
