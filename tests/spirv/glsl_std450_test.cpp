// GLSL.std.450 against C++ references computed here: the pack/unpack family, frexp and ldexp on edge values
// (ties, NaN, infinities, signed zeros, denormals, overflow), the functions no other test shader reaches, and
// (in hand-written assembly) the forms glslang never emits: Frexp and Modf through pointers, ModfStruct, NMin,
// NMax and NClamp.
#include <gtest/gtest.h>
#include <spirv-tools/libspirv.hpp>

#include <algorithm>
#include <bit>
#include <climits>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>

#include "compute_glsl_more.comp.spv.h"
#include "compute_glsl_pack.comp.spv.h"
#include "spirv/compute_harness.hpp"

namespace vkrt::testing {
namespace {

const float kNaN = std::numeric_limits<float>::quiet_NaN();
const float kInf = std::numeric_limits<float>::infinity();

uint16_t halfBits(_Float16 h) { return std::bit_cast<uint16_t>(h); }
_Float16 halfFromBits(uint32_t b) { return std::bit_cast<_Float16>(uint16_t(b)); }
bool halfIsNan(uint16_t b) { return (b & 0x7c00) == 0x7c00 && (b & 0x3ff) != 0; }

// Equal bits, or both NaN (NaN payloads are not specified).
template <class T>
::testing::AssertionResult same(T got, T want) {
  if (std::isnan(want) ? std::isnan(got) : std::memcmp(&got, &want, sizeof(T)) == 0)
    return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "got " << got << " (bits " << std::hex
                                       << std::bit_cast<std::conditional_t<sizeof(T) == 8, uint64_t, uint32_t>>(got)
                                       << ") want " << std::dec << want;
}

// A float c with c * scale == target exactly (a rounding tie after scaling), searched near target / scale.
float tieFor(float scale, float target) {
  float c = target / scale;
  float up = c, down = c;
  for (int k = 0; k < 256; ++k) {
    if (up * scale == target) return up;
    if (down * scale == target) return down;
    up = std::nextafter(up, kInf);
    down = std::nextafter(down, -kInf);
  }
  ADD_FAILURE() << "no float c with c * " << scale << " == " << target;
  return 0;
}

// GLSL.std.450 packSnorm/packUnorm: clamp, scale, round to nearest even; NaN packs as 0 (vkrt's choice).
uint32_t refPack(const float* c, int n, bool isSigned, int bits) {
  float scale = isSigned ? float((1 << (bits - 1)) - 1) : float((1u << bits) - 1);
  uint32_t r = 0;
  for (int k = 0; k < n; ++k) {
    float v = std::isnan(c[k]) ? 0.0f : std::min(std::max(c[k], isSigned ? -1.0f : 0.0f), 1.0f);
    auto q = int32_t(std::nearbyint(v * scale));  // the default rounding mode: to nearest, ties to even
    r |= (uint32_t(q) & ((1u << bits) - 1)) << (k * bits);
  }
  return r;
}
float refUnpack(uint32_t p, int k, bool isSigned, int bits) {
  uint32_t field = (p >> (k * bits)) & ((1u << bits) - 1);
  if (!isSigned) return float(field) / float((1u << bits) - 1);
  int32_t s = int32_t(field << (32 - bits)) >> (32 - bits);
  return std::max(float(s) / float((1 << (bits - 1)) - 1), -1.0f);
}
uint32_t refPackHalf(float lo, float hi) { return halfBits(_Float16(lo)) | uint32_t(halfBits(_Float16(hi))) << 16; }

// frexp as the spec states it: zero gives (x, 0); vkrt gives (x, 0) for infinities and NaNs too.
template <class T>
T refFrexp(T x, int* e) {
  if (x == 0 || std::isinf(x) || std::isnan(x)) {
    *e = 0;
    return x;
  }
  return std::frexp(x, e);
}
// ldexp rounded once: long double holds every product exactly.
template <class T>
T refLdexp(T x, int e) {
  return T(std::ldexp(static_cast<long double>(x), std::clamp(e, -20000, 20000)));
}
_Float16 refLdexpHalf(_Float16 x, int e) { return _Float16(std::ldexp(double(x), std::clamp(e, -2000, 2000))); }

TEST(SpirvGlslStd450, PackUnpackFrexpLdexpEdgeValues) {
  ComputeHarness h;
  ASSERT_TRUE(h.compile(kSpv_compute_glsl_pack_comp)) << h.error;
  constexpr uint32_t kN = 16;
  float x[kN][4] = {
      {tieFor(127, 0.5f), tieFor(127, 1.5f), tieFor(127, 2.5f), -tieFor(127, 2.5f)},
      {tieFor(255, 0.5f), tieFor(255, 1.5f), tieFor(255, 2.5f), tieFor(255, 254.5f)},
      {tieFor(32767, 0.5f), -tieFor(32767, 2.5f), tieFor(65535, 0.5f), tieFor(65535, 4.5f)},
      {kNaN, kInf, -kInf, -0.0f},
      {1.0f, -1.0f, 0.5f, -0.5f},
      {1.5f, -1.5f, std::numeric_limits<float>::max(), -std::numeric_limits<float>::denorm_min()},
      {65504.0f, 65520.0f, 65519.996f, std::ldexp(1.0f, -25)},
      {3 * std::ldexp(1.0f, -26), 1 + std::ldexp(1.0f, -11), 1 + 3 * std::ldexp(1.0f, -11), -1e-40f},
      {0.5f, std::ldexp(1.0f, 100), std::numeric_limits<float>::denorm_min(), std::numeric_limits<float>::max()},
      {std::numeric_limits<float>::min(), -3.75f, 1e-39f, 0.3f},
      {2.0f, 3.0f, 1e30f, -1e-30f},
      {0.1f, -0.2f, 0.7f, -0.99999f},
      {0.0f, 1.0001f, -2.5f, 6.1e-5f},
      {-kNaN, 0.25f, 100.0f, -100.0f},
      {0.75f, -0.75f, 0.998f, 1e-8f},
      {5.960464477539063e-8f, 2.9802322387695312e-8f, 65536.0f, -65505.0f},
  };
  // (low word, high word): unpack inputs, the halves for half frexp/ldexp, and the packDouble2x32 input.
  uint32_t w[kN][2] = {
      {0x807f01ff, 0x3ff00000}, {0x7fff8000, 0x7ff00000}, {0x7c00fc00, 0xfff80000}, {0x7e000001, 0x00000000},
      {0x3c00bc00, 0x80000000}, {0x7bff03ff, 0x000fffff}, {0xffffffff, 0xffffffff}, {0x00000000, 0x00000001},
      {0x04000400, 0x40091eb8}, {0x12345678, 0x9abcdef0}, {0x80808080, 0x7fefffff}, {0x7f7f7f7f, 0x00100000},
      {0x01000100, 0xc0000000}, {0xfffe0002, 0x3fe00000}, {0x55aa33cc, 0x12345678}, {0x00ff7fff, 0x7ff80001}};
  int32_t n[kN][4] = {{0, 1, -1, 2},
                      {3, -3, 7, -7},
                      {10, -10, 20, -20},
                      {1, 1, 1, 1},
                      {-126, -127, -149, -150},
                      {127, 128, 129, -1},
                      {30, -30, 40, -40},
                      {-24, -25, 15, 16},
                      {128, -240, 5, -277},
                      {INT_MAX, INT_MIN, 2000, -2000},
                      {1000, -1000, 1100, -1100},
                      {-5, 6, -8, 9},
                      {0, 0, 0, 0},
                      {2, -2, 1024, 1023},
                      {12, -12, -74, -75},
                      {60, -60, 61, -62}};
  double d[kN] = {0.0,
                  -0.0,
                  1.0,
                  -2.5,
                  std::numeric_limits<double>::denorm_min(),
                  1e-310,
                  std::numeric_limits<double>::max(),
                  std::numeric_limits<double>::infinity(),
                  -std::numeric_limits<double>::infinity(),
                  std::numeric_limits<double>::quiet_NaN(),
                  0.1,
                  -1e300,
                  3.0,
                  0.5,
                  std::ldexp(1.0, -1000),
                  123.456};
  // The ties really are ties (else the rounding rule would go untested).
  EXPECT_EQ(x[0][0] * 127.0f, 0.5f);
  EXPECT_EQ(x[2][3] * 65535.0f, 4.5f);

  h.setBuffer(0, std::vector<float>(&x[0][0], &x[0][0] + kN * 4));
  h.setBuffer(1, std::vector<uint32_t>(&w[0][0], &w[0][0] + kN * 2));
  h.setBuffer(2, std::vector<int32_t>(&n[0][0], &n[0][0] + kN * 4));
  h.setBuffer(3, std::vector<double>(d, d + kN));
  h.zeroBuffer<uint32_t>(4, kN * 8);
  h.zeroBuffer<float>(5, kN * 26);
  h.zeroBuffer<int32_t>(6, kN * 6);
  h.zeroBuffer<double>(7, kN * 4);
  ASSERT_TRUE(h.run(kN / 8));
  auto ou = h.get<uint32_t>(4);
  auto of = h.get<float>(5);
  auto oi = h.get<int32_t>(6);
  auto od = h.get<double>(7);

  for (uint32_t i = 0; i < kN; ++i) {
    SCOPED_TRACE("invocation " + std::to_string(i));
    const float* v = x[i];
    const uint32_t* u = &ou[i * 8];
    EXPECT_EQ(u[0], refPack(v, 4, true, 8)) << "packSnorm4x8";
    EXPECT_EQ(u[1], refPack(v, 4, false, 8)) << "packUnorm4x8";
    EXPECT_EQ(u[2], refPack(v, 2, true, 16)) << "packSnorm2x16";
    EXPECT_EQ(u[3], refPack(v + 2, 2, false, 16)) << "packUnorm2x16";
    for (int k = 0; k < 2; ++k) {
      uint32_t want = refPackHalf(v[2 * k], v[2 * k + 1]);
      for (int half = 0; half < 2; ++half) {
        uint16_t got16 = uint16_t(u[4 + k] >> (16 * half)), want16 = uint16_t(want >> (16 * half));
        if (halfIsNan(want16))
          EXPECT_TRUE(halfIsNan(got16)) << "packHalf2x16 " << k << ": " << std::hex << got16;
        else
          EXPECT_EQ(got16, want16) << "packHalf2x16 " << k << " of " << v[2 * k + half];
      }
    }
    uint64_t dbits = std::bit_cast<uint64_t>(d[i]);
    EXPECT_EQ(u[6], uint32_t(dbits)) << "unpackDouble2x32.x";
    EXPECT_EQ(u[7], uint32_t(dbits >> 32)) << "unpackDouble2x32.y";

    uint32_t p = w[i][0];
    const float* f = &of[i * 26];
    for (int k = 0; k < 4; ++k) {
      EXPECT_TRUE(same(f[k], refUnpack(p, k, true, 8))) << "unpackSnorm4x8 " << k;
      EXPECT_TRUE(same(f[4 + k], refUnpack(p, k, false, 8))) << "unpackUnorm4x8 " << k;
    }
    for (int k = 0; k < 2; ++k) {
      EXPECT_TRUE(same(f[8 + k], refUnpack(p, k, true, 16))) << "unpackSnorm2x16 " << k;
      EXPECT_TRUE(same(f[10 + k], refUnpack(p, k, false, 16))) << "unpackUnorm2x16 " << k;
      EXPECT_TRUE(same(f[12 + k], float(halfFromBits(p >> (16 * k))))) << "unpackHalf2x16 " << k;
    }
    for (int k = 0; k < 4; ++k) {
      int e = 0;
      float sig = refFrexp(v[k], &e);
      EXPECT_TRUE(same(f[14 + k], sig)) << "frexp significand of " << v[k];
      EXPECT_EQ(oi[i * 6 + k], e) << "frexp exponent of " << v[k];
      EXPECT_TRUE(same(f[18 + k], refLdexp(v[k], n[i][k]))) << "ldexp(" << v[k] << ", " << n[i][k] << ")";
    }
    _Float16 hx = halfFromBits(p);
    int he = 0;
    float hs = refFrexp(float(hx), &he);  // a half's significand is exact in float
    EXPECT_TRUE(same(f[22], hs)) << "half frexp significand of " << float(hx);
    EXPECT_EQ(oi[i * 6 + 4], he) << "half frexp exponent of " << float(hx);
    EXPECT_TRUE(same(f[23], float(refLdexpHalf(hx, n[i][0])))) << "half ldexp(" << float(hx) << ", " << n[i][0] << ")";
    EXPECT_TRUE(same(f[24], float(refLdexpHalf(hx, n[i][1])))) << "half ldexp(" << float(hx) << ", " << n[i][1] << ")";

    int de = 0;
    double ds = refFrexp(d[i], &de);
    double packed = std::bit_cast<double>(uint64_t(w[i][0]) | uint64_t(w[i][1]) << 32);
    EXPECT_EQ(std::bit_cast<uint64_t>(od[i * 4]), std::bit_cast<uint64_t>(packed)) << "packDouble2x32";
    EXPECT_TRUE(same(od[i * 4 + 1], ds)) << "double frexp significand of " << d[i];
    EXPECT_EQ(oi[i * 6 + 5], de) << "double frexp exponent of " << d[i];
    EXPECT_TRUE(same(od[i * 4 + 2], refLdexp(d[i], n[i][2]))) << "double ldexp(" << d[i] << ", " << n[i][2] << ")";
    EXPECT_TRUE(same(od[i * 4 + 3], refLdexp(d[i], n[i][3]))) << "double ldexp(" << d[i] << ", " << n[i][3] << ")";
  }
  // Spot checks of the rules themselves, independent of the reference functions above.
  EXPECT_EQ(ou[0] & 0xff, 0u) << "0.5 after scaling rounds to even (0)";
  EXPECT_EQ((ou[0] >> 16) & 0xff, 2u) << "2.5 after scaling rounds to even (2)";
  EXPECT_EQ(ou[3 * 8 + 0], 0x00817f00u) << "packSnorm4x8(NaN, inf, -inf, -0)";
  EXPECT_EQ(of[8 * 26 + 18], std::ldexp(1.0f, 127)) << "ldexp(0.5, 128) is finite";
  EXPECT_EQ(of[8 * 26 + 19], std::ldexp(1.0f, -140)) << "ldexp(2^100, -240) is a denormal, not 0";
  EXPECT_EQ(of[8 * 26 + 16], 0.5f);
  EXPECT_EQ(oi[8 * 6 + 2], -148) << "frexp of the smallest denormal";
  EXPECT_EQ(od[13 * 4 + 2], std::ldexp(1.0, 1023)) << "double ldexp(0.5, 1024)";
  EXPECT_EQ(od[14 * 4 + 3], 0.0) << "2^-1000 * 2^-75 rounds to 0 (ties to even)";
  EXPECT_EQ(od[14 * 4 + 2], std::numeric_limits<double>::denorm_min());
}

// Determinant and inverse references: Gaussian elimination with partial pivoting in long double (another
// algorithm than the compiler's cofactor expansion).
using Mat = std::vector<std::vector<long double>>;  // [column][row]
long double refDet(Mat a) {
  size_t n = a.size();
  long double det = 1;
  for (size_t k = 0; k < n; ++k) {
    size_t piv = k;
    for (size_t r = k + 1; r < n; ++r)
      if (std::fabs(a[k][r]) > std::fabs(a[k][piv])) piv = r;
    if (piv != k) {
      for (size_t c = 0; c < n; ++c) std::swap(a[c][k], a[c][piv]);
      det = -det;
    }
    det *= a[k][k];
    for (size_t r = k + 1; r < n; ++r) {
      long double f = a[k][r] / a[k][k];
      for (size_t c = k; c < n; ++c) a[c][r] -= f * a[c][k];
    }
  }
  return det;
}
Mat refInverse(Mat a) {
  size_t n = a.size();
  Mat inv(n, std::vector<long double>(n, 0));
  for (size_t i = 0; i < n; ++i) inv[i][i] = 1;
  for (size_t k = 0; k < n; ++k) {
    size_t piv = k;
    for (size_t r = k + 1; r < n; ++r)
      if (std::fabs(a[k][r]) > std::fabs(a[k][piv])) piv = r;
    for (size_t c = 0; c < n; ++c) {
      std::swap(a[c][k], a[c][piv]);
      std::swap(inv[c][k], inv[c][piv]);
    }
    long double d = a[k][k];
    for (size_t c = 0; c < n; ++c) {
      a[c][k] /= d;
      inv[c][k] /= d;
    }
    for (size_t r = 0; r < n; ++r) {
      if (r == k) continue;
      long double f = a[k][r];
      for (size_t c = 0; c < n; ++c) {
        a[c][r] -= f * a[c][k];
        inv[c][r] -= f * inv[c][k];
      }
    }
  }
  return inv;
}

void expectClose(double got, double want, double tol, const std::string& what) {
  EXPECT_LE(std::fabs(got - want), tol * std::max(1.0, std::fabs(want))) << what << ": got " << got << " want " << want;
}

TEST(SpirvGlslStd450, FunctionsNoOtherShaderUses) {
  ComputeHarness h;
  ASSERT_TRUE(h.compile(kSpv_compute_glsl_more_comp)) << h.error;
  constexpr uint32_t kN = 8, kF = 52, kI = 12, kD = 8;
  float xs[kN][2] = {{2.5f, 1.3f},   {-3.5f, -2.2f}, {0.5f, 0.4f},  {-0.5f, 3.0f},
                     {1.25f, -0.7f}, {-2.7f, 2.5f},  {3.9f, -3.1f}, {0.1f, 0.05f}};
  int32_t ks[kN][2] = {{INT_MIN, 5}, {-7, INT_MAX}, {0, -1},          {123456, -123456},
                       {-100, 100},  {99, 101},     {-2147483647, 7}, {1 << 20, 3}};
  double ds[kN] = {2.5, -3.5, 0.1, -7.25, 1e10, -0.5, 1.5, 3.7};
  std::vector<float> mats(kN * 16);
  for (uint32_t i = 0; i < kN; ++i)
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r)
        mats[i * 16 + c * 4 + r] =
            (c == r ? 3.0f + 0.5f * float(i) : 0.0f) + float((c * 7 + r * 3 + int(i) * 5) % 11 - 5) * 0.1f;
  h.setBuffer(0, std::vector<float>(&xs[0][0], &xs[0][0] + kN * 2));
  h.setBuffer(1, std::vector<int32_t>(&ks[0][0], &ks[0][0] + kN * 2));
  h.setBuffer(2, mats);
  h.setBuffer(3, std::vector<double>(ds, ds + kN));
  h.zeroBuffer<float>(4, kN * kF);
  h.zeroBuffer<int32_t>(5, kN * kI);
  h.zeroBuffer<double>(6, kN * kD);
  ASSERT_TRUE(h.run(kN / 4));
  auto of = h.get<float>(4);
  auto oi = h.get<int32_t>(5);
  auto od = h.get<double>(6);
  for (uint32_t i = 0; i < kN; ++i) {
    SCOPED_TRACE("invocation " + std::to_string(i));
    float a = xs[i][0], b = xs[i][1];
    const float* f = &of[i * kF];
    EXPECT_EQ(f[0], std::nearbyint(a)) << "roundEven";
    expectClose(f[1], std::acos(std::clamp(b * 0.3f, -1.0f, 1.0f)), 1e-6, "acos");
    expectClose(f[2], std::atan(a), 1e-6, "atan");
    expectClose(f[3], std::sinh(b * 0.5f), 1e-6, "sinh");
    expectClose(f[4], std::cosh(b * 0.5f), 1e-6, "cosh");
    expectClose(f[5], std::tanh(b * 0.5f), 1e-6, "tanh");
    expectClose(f[6], std::asinh(a), 1e-6, "asinh");
    expectClose(f[7], std::acosh(std::fabs(a) + 1.0f), 1e-6, "acosh");
    expectClose(f[8], std::atanh(std::clamp(b * 0.3f, -0.99f, 0.99f)), 1e-6, "atanh");
    double n[3] = {a, b, 1}, v[3] = {b, -1, a}, nref[3] = {1, a, b};
    double dotRefV = nref[0] * v[0] + nref[1] * v[1] + nref[2] * v[2];
    for (int c = 0; c < 3; ++c) EXPECT_EQ(f[9 + c], float(dotRefV < 0 ? n[c] : -n[c])) << "faceforward " << c;
    double ln = std::sqrt(n[0] * n[0] + n[1] * n[1] + 1), lv = std::sqrt(v[0] * v[0] + 1 + v[2] * v[2]);
    double nn[3] = {n[0] / ln, n[1] / ln, n[2] / ln}, nv[3] = {v[0] / lv, v[1] / lv, v[2] / lv};
    double dni = nn[0] * nv[0] + nn[1] * nv[1] + nn[2] * nv[2], eta = 0.66;
    double k = 1 - eta * eta * (1 - dni * dni);
    ASSERT_GE(k, 0.0) << "the first refraction is not a total reflection";
    for (int c = 0; c < 3; ++c)
      expectClose(f[12 + c], eta * nv[c] - (eta * dni + std::sqrt(k)) * nn[c], 1e-5, "refract");
    for (int c = 0; c < 3; ++c) EXPECT_EQ(f[15 + c], 0.0f) << "refract past the critical angle is the zero vector";

    const float* m = &mats[i * 16];
    auto sub = [&](size_t size) {
      Mat a(size, std::vector<long double>(size));
      for (size_t c = 0; c < size; ++c)
        for (size_t r = 0; r < size; ++r) a[c][r] = m[c * 4 + r];
      return a;
    };
    for (size_t size = 2; size <= 4; ++size) {
      expectClose(f[18 + size - 2], double(refDet(sub(size))), 1e-5, "determinant " + std::to_string(size));
      Mat inv = refInverse(sub(size));
      size_t at = size == 2 ? 21 : size == 3 ? 25 : 34;
      for (size_t c = 0; c < size; ++c)
        for (size_t r = 0; r < size; ++r)
          expectClose(f[at + c * size + r], double(inv[c][r]), 1e-5,
                      "inverse " + std::to_string(size) + " [" + std::to_string(c) + "][" + std::to_string(r) + "]");
    }
    float whole = 0;
    float frac = std::modf(a, &whole);
    EXPECT_EQ(f[50], frac) << "modf fraction";
    EXPECT_EQ(f[51], whole) << "modf whole part";

    int32_t p = ks[i][0], q = ks[i][1];
    uint32_t up = uint32_t(p), uq = uint32_t(q);
    auto wrapAbs = [](int32_t s) { return int32_t(s < 0 ? 0u - uint32_t(s) : uint32_t(s)); };
    const int32_t* o = &oi[i * kI];
    EXPECT_EQ(o[0], wrapAbs(p)) << "abs (INT_MIN stays INT_MIN)";
    EXPECT_EQ(o[1], p > 0 ? 1 : p < 0 ? -1 : 0) << "sign";
    EXPECT_EQ(o[2], std::min(p, q)) << "min";
    EXPECT_EQ(o[3], std::max(p, q)) << "max";
    EXPECT_EQ(o[4], std::clamp(p, -100, 100)) << "clamp";
    EXPECT_EQ(uint32_t(o[5]), std::min(up, uq)) << "unsigned min";
    EXPECT_EQ(uint32_t(o[6]), std::max(up, uq)) << "unsigned max";
    EXPECT_EQ(uint32_t(o[7]), std::clamp(up, 10u, 1000000u)) << "unsigned clamp";
    EXPECT_EQ(o[8], up == 0 ? -1 : 31 - std::countl_zero(up)) << "findMSB(uint)";
    EXPECT_EQ(o[9], std::min(p, q)) << "vector min";
    EXPECT_EQ(o[10], std::min(q, int32_t(0u - up))) << "vector min";
    EXPECT_EQ(o[11], wrapAbs(q)) << "vector abs";

    double dv = ds[i];
    const double* e = &od[i * kD];
    EXPECT_EQ(e[0], std::nearbyint(dv)) << "double roundEven";
    EXPECT_EQ(e[1], std::sqrt(std::fabs(dv))) << "double sqrt (correctly rounded)";
    expectClose(e[2], double(refDet(sub(3))), 1e-12, "double determinant");
    Mat di = refInverse(sub(4));
    expectClose(e[3], double(di[0][0]), 1e-12, "double inverse [0][0]");
    expectClose(e[4], double(di[3][1]), 1e-12, "double inverse [3][1]");
    expectClose(e[5], double(di[2][3]), 1e-12, "double inverse [2][3]");
    EXPECT_EQ(e[6], std::fma(dv, dv, 1.0)) << "double fma";
    EXPECT_EQ(e[7], std::clamp(dv, -1.0, 2.0)) << "double clamp";
  }
}

// ---- hand-written assembly: the forms glslang does not emit

std::string assemblyModule() {
  std::string s = R"(
OpCapability Shader
%glsl = OpExtInstImport "GLSL.std.450"
OpMemoryModel Logical GLSL450
OpEntryPoint GLCompute %main "main" %gid %in %out %iout
OpExecutionMode %main LocalSize 1 1 1
OpDecorate %gid BuiltIn GlobalInvocationId
OpDecorate %rtf ArrayStride 4
OpDecorate %rti ArrayStride 4
OpMemberDecorate %fbuf 0 Offset 0
OpMemberDecorate %ibuf 0 Offset 0
OpDecorate %fbuf Block
OpDecorate %ibuf Block
OpDecorate %in DescriptorSet 0
OpDecorate %in Binding 0
OpDecorate %out DescriptorSet 0
OpDecorate %out Binding 1
OpDecorate %iout DescriptorSet 0
OpDecorate %iout Binding 2
%void = OpTypeVoid
%fnvoid = OpTypeFunction %void
%uint = OpTypeInt 32 0
%int = OpTypeInt 32 1
%float = OpTypeFloat 32
%v3uint = OpTypeVector %uint 3
%v2float = OpTypeVector %float 2
%v2int = OpTypeVector %int 2
%rtf = OpTypeRuntimeArray %float
%rti = OpTypeRuntimeArray %int
%fbuf = OpTypeStruct %rtf
%ibuf = OpTypeStruct %rti
%modf_s = OpTypeStruct %float %float
%p_fbuf = OpTypePointer StorageBuffer %fbuf
%p_ibuf = OpTypePointer StorageBuffer %ibuf
%p_f = OpTypePointer StorageBuffer %float
%p_i = OpTypePointer StorageBuffer %int
%p_in_v3 = OpTypePointer Input %v3uint
%p_fn_v2int = OpTypePointer Function %v2int
%p_fn_v2float = OpTypePointer Function %v2float
%gid = OpVariable %p_in_v3 Input
%in = OpVariable %p_fbuf StorageBuffer
%out = OpVariable %p_fbuf StorageBuffer
%iout = OpVariable %p_ibuf StorageBuffer
%u0 = OpConstant %uint 0
%u1 = OpConstant %uint 1
%u2 = OpConstant %uint 2
%u3 = OpConstant %uint 3
%u12 = OpConstant %uint 12
%fm1 = OpConstant %float -1
%f1 = OpConstant %float 1
%@ CONSTANTS
%main = OpFunction %void None %fnvoid
%entry = OpLabel
%ev = OpVariable %p_fn_v2int Function
%wv = OpVariable %p_fn_v2float Function
%g = OpLoad %v3uint %gid
%i = OpCompositeExtract %uint %g 0
%ia = OpIMul %uint %i %u2
%ib = OpIAdd %uint %ia %u1
%pa = OpAccessChain %p_f %in %u0 %ia
%pb = OpAccessChain %p_f %in %u0 %ib
%a = OpLoad %float %pa
%b = OpLoad %float %pb
%v = OpCompositeConstruct %v2float %a %b
%ob = OpIMul %uint %i %u12
%qb = OpIMul %uint %i %u3
%q2 = OpIAdd %uint %qb %u2
%pe = OpAccessChain %p_i %iout %u0 %q2
%fs = OpExtInst %v2float %glsl Frexp %v %ev
%fs1 = OpExtInst %float %glsl Frexp %b %pe
%mf = OpExtInst %v2float %glsl Modf %v %wv
%ms = OpExtInst %modf_s %glsl ModfStruct %a
%nmin = OpExtInst %float %glsl NMin %a %b
%nmax = OpExtInst %float %glsl NMax %a %b
%ncl = OpExtInst %float %glsl NClamp %a %fm1 %f1
%e = OpLoad %v2int %ev
%wh = OpLoad %v2float %wv
%fs_0 = OpCompositeExtract %float %fs 0
%fs_1 = OpCompositeExtract %float %fs 1
%mf_0 = OpCompositeExtract %float %mf 0
%mf_1 = OpCompositeExtract %float %mf 1
%wh_0 = OpCompositeExtract %float %wh 0
%wh_1 = OpCompositeExtract %float %wh 1
%ms_0 = OpCompositeExtract %float %ms 0
%ms_1 = OpCompositeExtract %float %ms 1
%e_0 = OpCompositeExtract %int %e 0
%e_1 = OpCompositeExtract %int %e 1
)";
  const char* floats[] = {"fs_0", "fs_1", "fs1", "mf_0", "mf_1", "wh_0", "wh_1", "ms_0", "ms_1", "nmin", "nmax", "ncl"};
  std::string constants;
  for (int k = 0; k < 12; ++k)
    constants += "%ck" + std::to_string(k) + " = OpConstant %uint " + std::to_string(k) + "\n";
  s.replace(s.find("%@ CONSTANTS\n"), 13, constants);
  for (int k = 0; k < 12; ++k) {
    std::string kk = std::to_string(k);
    s += "%o" + kk + " = OpIAdd %uint %ob %ck" + kk + "\n%po" + kk + " = OpAccessChain %p_f %out %u0 %o" + kk +
         "\nOpStore %po" + kk + " %" + floats[k] + "\n";
  }
  for (int k = 0; k < 2; ++k) {
    std::string kk = std::to_string(k);
    s += "%q" + kk + "i = OpIAdd %uint %qb %ck" + kk + "\n%pq" + kk + " = OpAccessChain %p_i %iout %u0 %q" + kk +
         "i\nOpStore %pq" + kk + " %e_" + kk + "\n";
  }
  return s + "OpReturn\nOpFunctionEnd\n";
}

TEST(SpirvGlslStd450, PointerFormsAndNanAwareMinMax) {
  spvtools::SpirvTools tools(SPV_ENV_VULKAN_1_3);
  std::string diag;
  tools.SetMessageConsumer([&](spv_message_level_t, const char*, const spv_position_t& pos, const char* m) {
    diag += std::to_string(pos.index) + ": " + m + "\n";
  });
  std::vector<uint32_t> words;
  ASSERT_TRUE(tools.Assemble(assemblyModule(), &words)) << diag;
  ASSERT_TRUE(tools.Validate(words)) << diag;
  std::vector<float> in = {kNaN, 2.0f, -7.75f, kNaN, 0.0f, -0.0f, 1e-45f, -kInf, 3.25f, 0.5f, -2.5f, 1e30f};
  const uint32_t kN = uint32_t(in.size() / 2);
  for (bool inl : {true, false}) {
    ComputeHarness h;
    spirv::CompileRequest r;
    r.words = words.data();
    r.wordCount = words.size();
    r.inlineFunctions = inl;
    h.shader = spirv::compile(r, &h.error);
    ASSERT_NE(h.shader, nullptr) << h.error;
    h.setBuffer(0, in);
    h.zeroBuffer<float>(1, kN * 12);
    h.zeroBuffer<int32_t>(2, kN * 3);
    ASSERT_TRUE(h.run(kN));
    auto of = h.get<float>(1);
    auto oi = h.get<int32_t>(2);
    for (uint32_t i = 0; i < kN; ++i) {
      SCOPED_TRACE("invocation " + std::to_string(i));
      float a = in[2 * i], b = in[2 * i + 1];
      const float* f = &of[i * 12];
      int ea = 0, eb = 0;
      EXPECT_TRUE(same(f[0], refFrexp(a, &ea))) << "Frexp (Function pointer) of " << a;
      EXPECT_TRUE(same(f[1], refFrexp(b, &eb))) << "Frexp (Function pointer) of " << b;
      EXPECT_EQ(oi[i * 3], ea);
      EXPECT_EQ(oi[i * 3 + 1], eb);
      EXPECT_TRUE(same(f[2], refFrexp(b, &eb))) << "Frexp (StorageBuffer pointer) of " << b;
      EXPECT_EQ(oi[i * 3 + 2], eb);
      float wa = std::trunc(a), wb = std::trunc(b);
      // modf of an infinity: whole part infinite, fraction (x - trunc x) NaN; vkrt does not special-case it.
      EXPECT_TRUE(same(f[3], a - wa)) << "Modf fraction of " << a;
      EXPECT_TRUE(same(f[4], b - wb)) << "Modf fraction of " << b;
      EXPECT_TRUE(same(f[5], wa)) << "Modf whole part of " << a;
      EXPECT_TRUE(same(f[6], wb)) << "Modf whole part of " << b;
      EXPECT_TRUE(same(f[7], a - wa)) << "ModfStruct fraction";
      EXPECT_TRUE(same(f[8], wa)) << "ModfStruct whole part";
      // NMin/NMax: a NaN operand yields the other one; NClamp(NaN, -1, 1) is -1.
      float nmin = std::isnan(a) ? b : std::isnan(b) ? a : std::min(a, b);
      float nmax = std::isnan(a) ? b : std::isnan(b) ? a : std::max(a, b);
      if (a == 0 && b == 0) {  // +0 and -0: either is the minimum
        EXPECT_EQ(f[9], 0.0f);
        EXPECT_EQ(f[10], 0.0f);
      } else {
        EXPECT_TRUE(same(f[9], nmin)) << "NMin(" << a << ", " << b << ")";
        EXPECT_TRUE(same(f[10], nmax)) << "NMax(" << a << ", " << b << ")";
      }
      EXPECT_TRUE(same(f[11], std::isnan(a) ? -1.0f : std::clamp(a, -1.0f, 1.0f))) << "NClamp(" << a << ", -1, 1)";
    }
  }
}

}  // namespace
}  // namespace vkrt::testing
