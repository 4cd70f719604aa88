// lodLog2 (runtime/lod_log2.hpp), the level of detail's log2 that the per-lane sampler and the quad sampler share:
// its accuracy against log2 in double over the whole float range, exact whole results at powers of two (a level
// of detail that is a whole number selects one level, and 0 decides magnification), and its special values.
#include "runtime/lod_log2.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

namespace vkrt {
namespace {

float lodLog2Of(float x) { return lodLog2(LodFloat4{x, x, x, x})[0]; }

// Within 1.3e-7 of log2 for the mantissa's part (the polynomial's bound), plus half an ulp of the result for the
// final sum with the exponent: over every 4099th float from the smallest subnormal to the largest finite value,
// four lanes of different values at once (each element computed alone).
TEST(LodLog2, IsWithinItsBoundOfLog2OverTheFloatRange) {
  uint32_t compared = 0;
  for (uint64_t bits = 1; bits < 0x7f800000u; bits += 4099 * 4) {
    LodFloat4 x;
    for (int l = 0; l < 4; ++l) {
      const uint32_t b = uint32_t(std::min<uint64_t>(bits + uint64_t(l) * 4099, 0x7f7fffffu));
      std::memcpy(&x[l], &b, 4);
    }
    const LodFloat4 r = lodLog2(x);
    for (int l = 0; l < 4; ++l) {
      const double exact = std::log2(double(x[l]));
      const double bound = 1.3e-7 + 0.5 * std::ldexp(1.0, std::ilogb(std::max(std::fabs(exact), 1e-30)) - 23);
      const double error = std::fabs(double(r[l]) - exact);
      ASSERT_LE(error, bound) << "x " << x[l] << " (" << std::hexfloat << x[l] << ") lodLog2 " << r[l] << " log2 "
                              << exact;
      ++compared;
    }
  }
  EXPECT_GT(compared, 500000u);
}

TEST(LodLog2, PowersOfTwoGiveWholeNumbers) {
  for (int e = -149; e <= 127; ++e) EXPECT_EQ(lodLog2Of(std::ldexp(1.0f, e)), float(e)) << "2^" << e;
}

TEST(LodLog2, SpecialValues) {
  const float inf = std::numeric_limits<float>::infinity();
  EXPECT_EQ(lodLog2Of(0.0f), -inf);
  EXPECT_EQ(lodLog2Of(inf), inf);
  EXPECT_TRUE(std::isnan(lodLog2Of(std::numeric_limits<float>::quiet_NaN())));
  // Beside one, where log2 is small and its relative error large: the absolute bound.
  for (float x : {std::nextafter(1.0f, 2.0f), std::nextafter(1.0f, 0.0f), 1.0001f, 0.9999f})
    EXPECT_NEAR(lodLog2Of(x), std::log2(double(x)), 1.3e-7) << x;
}

}  // namespace
}  // namespace vkrt
