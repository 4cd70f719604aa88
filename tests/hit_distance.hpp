// How close a triangle hit's t must be to the exact value, on every set of Embree kernels (SSE2, SSE4.2, AVX,
// AVX2, AVX-512: Embree picks the CPU's best when the process starts, and VKRT_EMBREE_ISA picks a lower one).
//
// Embree computes a triangle's t as a quotient: a numerator and a denominator made of products and sums of the
// vertex coordinates relative to the ray origin (each rounding adds at most half an ulp of the largest magnitude
// involved), divided through a reciprocal that its SSE and AVX kernels take from the CPU's 12-bit estimate
// refined by one Newton step (relative error about 2^-22, up to 2 ulps of t) and its AVX-512 kernels from a
// 14-bit estimate (exact after the step for the scenes here: the AVX-512 development machine saw every t exact).
// So an exact comparison of a triangle's t holds on one kernel and fails on another (the AVX2 kernels report a
// quad at exactly 2 at 1.9999999, one ulp below). Eight ulps of the larger of |t| and the geometry's extent (its
// largest coordinate magnitude among the vertices and the ray origin) bound both sources with room, and are still far
// below the spacing of the depths the tests tell apart (at least 0.001 relative). A box's t is vkrt's own arithmetic,
// the same on every kernel, and tests compare it exactly.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

namespace vkrt::test {

inline float hitDistanceTolerance(float t, float extent = 0) {
  return 8 * std::numeric_limits<float>::epsilon() * std::max(std::fabs(t), std::fabs(extent));
}

// Whether `t` is a triangle hit at the exact distance `exact`, up to the tolerance above.
inline bool nearHit(float t, float exact, float extent = 0) {
  return std::fabs(t - exact) <= hitDistanceTolerance(exact, extent);
}

// A margin that puts a ray's tMin or tMax clearly on one side of a triangle at `t`: beyond what any kernel's
// rounding can move the triangle's computed t (four tolerances), so the test checks the rule on the interval's
// ends, not the kernel's last bit.
inline float boundaryMargin(float t, float extent = 0) { return 4 * hitDistanceTolerance(t, extent); }

// Candidate distances in order, each within the tolerance of the expected one.
inline ::testing::AssertionResult nearHits(const std::vector<float>& seen, const std::vector<float>& expected,
                                           float extent = 0) {
  bool ok = seen.size() == expected.size();
  for (size_t i = 0; ok && i < seen.size(); ++i) ok = nearHit(seen[i], expected[i], extent);
  if (ok) return ::testing::AssertionSuccess();
  std::ostringstream s;
  s.precision(9);
  s << "seen {";
  for (float t : seen) s << ' ' << t;
  s << " }, expected {";
  for (float t : expected) s << ' ' << t;
  s << " } within " << hitDistanceTolerance(expected.empty() ? 0 : expected.back(), extent);
  return ::testing::AssertionFailure() << s.str();
}

}  // namespace vkrt::test
