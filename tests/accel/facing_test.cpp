// Triangle facing (Vulkan "Ray Face Culling"), face culling, and the instance flags that change them.
#include <random>

#include "accel/scenes.hpp"

namespace vkrt::accel::test {
namespace {

constexpr uint32_t kFront = kHitKindFrontFacingTriangle, kBack = kHitKindBackFacingTriangle;

Ray fromBelow(uint32_t flags = 0) { return rayFrom(0.3f, -0.4f, 0, 0, 0, 1, flags); }
Ray fromAbove(uint32_t flags = 0) { return rayFrom(0.3f, -0.4f, 10, 0, 0, -1, flags); }

uint32_t hitKindOf(const Tlas& tlas, const Ray& ray) {
  Traced r = traceOnce(tlas, ray);
  EXPECT_TRUE(r.hit);
  return r.hit ? r.info.hitKind : 0;
}

TEST(AccelFacing, CounterclockwiseSeenFromTheRayIsFront) {
  // The quad's vertices are counterclockwise seen from +z (above): a ray from above meets its front.
  auto tlas = sceneOf({quad(5)});
  EXPECT_EQ(hitKindOf(*tlas, fromAbove()), kFront);
  EXPECT_EQ(hitKindOf(*tlas, fromBelow()), kBack);
  Geometry reversed;
  reversed.kind = Geometry::Triangles;
  reversed.triangles.flags = kGeometryOpaque;
  addQuad(reversed.triangles, -1, -1, 1, 1, 5, true);
  auto rtlas = sceneOf({reversed});
  EXPECT_EQ(hitKindOf(*rtlas, fromAbove()), kBack);
  EXPECT_EQ(hitKindOf(*rtlas, fromBelow()), kFront);
}

TEST(AccelFacing, CullBackAndFrontFacing) {
  auto tlas = sceneOf({quad(5)});
  EXPECT_FALSE(traceOnce(*tlas, fromBelow(kRayCullBackFacingTriangles)).hit);
  EXPECT_EQ(hitKindOf(*tlas, fromAbove(kRayCullBackFacingTriangles)), kFront);
  EXPECT_FALSE(traceOnce(*tlas, fromAbove(kRayCullFrontFacingTriangles)).hit);
  EXPECT_EQ(hitKindOf(*tlas, fromBelow(kRayCullFrontFacingTriangles)), kBack);
  // A culled triangle lets the ray go on: reversed quad at 3 (front from below), quad at 5 (back from below).
  Geometry g = quad(5);
  addQuad(g.triangles, -1, -1, 1, 1, 3, true);
  auto two = sceneOf({g});
  Traced r = traceOnce(*two, fromBelow(kRayCullFrontFacingTriangles));
  ASSERT_TRUE(r.hit);
  EXPECT_NEAR(r.info.t, 5.0f, kTol);
  EXPECT_EQ(r.info.hitKind, kBack);
  r = traceOnce(*two, fromBelow(kRayCullBackFacingTriangles));
  ASSERT_TRUE(r.hit);
  EXPECT_NEAR(r.info.t, 3.0f, kTol);
  EXPECT_EQ(r.info.hitKind, kFront);
}

TEST(AccelFacing, FlipFacingAndCullDisable) {
  auto blas = makeBlas({quad(5)});
  auto flipped = makeTlas({instanceOf(blas, kInstanceTriangleFlipFacing)});
  EXPECT_EQ(hitKindOf(*flipped, fromBelow()), kFront);
  EXPECT_EQ(hitKindOf(*flipped, fromAbove()), kBack);
  EXPECT_EQ(hitKindOf(*flipped, fromBelow(kRayCullBackFacingTriangles)), kFront);
  EXPECT_FALSE(traceOnce(*flipped, fromBelow(kRayCullFrontFacingTriangles)).hit);

  auto noCull = makeTlas({instanceOf(blas, kInstanceTriangleFacingCullDisable)});
  EXPECT_EQ(hitKindOf(*noCull, fromBelow(kRayCullBackFacingTriangles)), kBack);
  EXPECT_EQ(hitKindOf(*noCull, fromAbove(kRayCullFrontFacingTriangles)), kFront);
  auto both = makeTlas({instanceOf(blas, kInstanceTriangleFacingCullDisable | kInstanceTriangleFlipFacing)});
  EXPECT_EQ(hitKindOf(*both, fromBelow(kRayCullFrontFacingTriangles)), kFront);
  // One instance disabling culling does not protect another.
  auto mixed = makeTlas({instanceOf(blas, kInstanceTriangleFacingCullDisable), translated(blas, 5, 0, 0)});
  EXPECT_TRUE(traceOnce(*mixed, fromBelow(kRayCullBackFacingTriangles)).hit);
  EXPECT_FALSE(traceOnce(*mixed, rayFrom(5.3f, -0.4f, 0, 0, 0, 1, kRayCullBackFacingTriangles)).hit);
}

TEST(AccelFacing, MirroringInstanceKeepsObjectSpaceFacing) {
  // "Because the facing is determined in object space, an instance transform does not change the winding": a
  // mirrored instance reverses the world-space winding, but not the facing.
  auto blas = makeBlas({quad(5)});
  Instance mirrorX = instanceOf(blas);
  mirrorX.transform[0][0] = -1;  // x -> -x: the quad stays at z = 5, its world winding seen from below reverses
  auto tx = makeTlas({mirrorX});
  EXPECT_EQ(hitKindOf(*tx, fromBelow()), kBack);
  EXPECT_EQ(hitKindOf(*tx, fromAbove()), kFront);
  EXPECT_FALSE(traceOnce(*tx, fromBelow(kRayCullBackFacingTriangles)).hit);

  Instance mirrorZ = instanceOf(blas);
  mirrorZ.transform[2][2] = -1;  // the quad moves to z = -5; a ray from the origin along -z meets object +z
  auto tz = makeTlas({mirrorZ});
  Traced r = traceOnce(*tz, rayFrom(0.3f, -0.4f, 0, 0, 0, -1));
  ASSERT_TRUE(r.hit);
  EXPECT_NEAR(r.info.t, 5.0f, kTol);
  EXPECT_EQ(r.info.hitKind, kBack);
  EXPECT_NEAR(r.info.objectRayDirection[2], 1.0f, kTol);
  EXPECT_EQ(hitKindOf(*tz, rayFrom(0.3f, -0.4f, -10, 0, 0, 1)), kFront);
  mirrorZ.flags = kInstanceTriangleFlipFacing;
  EXPECT_EQ(hitKindOf(*makeTlas({mirrorZ}), rayFrom(0.3f, -0.4f, 0, 0, 0, -1)), kFront);
}

// The specification's own computation ("Ray Face Culling"): rotate the object-space vertices into ray space,
// where the ray runs along -z, and take the sign of a = -1/2 sum(x_i y_(i+1) - x_(i+1) y_i); a < 0 is the front.
// Everything in double, from the formulas in "Ray Intersection Candidate Determination".
int specFacing(const double v[3][3], const double o[3], const double d[3]) {
  const double k[3] = {0, 0, -1};
  const double dk[3] = {d[1] * k[2] - d[2] * k[1], d[2] * k[0] - d[0] * k[2], d[0] * k[1] - d[1] * k[0]};
  const double dkLen = std::sqrt(dk[0] * dk[0] + dk[1] * dk[1] + dk[2] * dk[2]);
  const double dLen = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  double a[3] = {0, 1, 0};
  if (dkLen != 0)
    for (int i = 0; i < 3; ++i) a[i] = dk[i] / dkLen;
  const double c = (d[0] * k[0] + d[1] * k[1] + d[2] * k[2]) / dLen;
  const double s = std::sqrt(std::max(0.0, 1 - c * c));
  const double R[3][3] = {
      {a[0] * a[0] * (1 - c) + c, a[0] * a[1] * (1 - c) - s * a[2], a[0] * a[2] * (1 - c) + s * a[1]},
      {a[0] * a[1] * (1 - c) + s * a[2], a[1] * a[1] * (1 - c) + c, a[1] * a[2] * (1 - c) - s * a[0]},
      {a[0] * a[2] * (1 - c) - s * a[1], a[1] * a[2] * (1 - c) + s * a[0], a[2] * a[2] * (1 - c) + c}};
  double r[3][2];
  for (int i = 0; i < 3; ++i)
    for (int row = 0; row < 2; ++row)
      r[i][row] = R[row][0] * (v[i][0] - o[0]) + R[row][1] * (v[i][1] - o[1]) + R[row][2] * (v[i][2] - o[2]);
  double sum = 0;
  for (int i = 0; i < 3; ++i) sum += r[i][0] * r[(i + 1) % 3][1] - r[(i + 1) % 3][0] * r[i][1];
  const double area = -0.5 * sum;
  return area < 0 ? 1 : area > 0 ? -1 : 0;
}

// Random triangles, rays aimed inside them, and instance transforms (mirroring ones included): the hit kind must
// be the specification's facing of the object-space triangle and ray, reversed by FLIP_FACING.
TEST(AccelFacing, MatchesTheSpecificationFormulaUnderRandomTransforms) {
  std::mt19937 rng(1234);
  std::uniform_real_distribution<double> u(-1, 1);
  int mirrored = 0, fronts = 0, backs = 0;
  for (int iter = 0; iter < 120; ++iter) {
    double v[3][3];
    Geometry g;
    g.kind = Geometry::Triangles;
    g.triangles.flags = kGeometryOpaque;
    for (auto& p : v)
      for (double& c : p) {
        c = 3 * u(rng);
        g.triangles.vertices.push_back(float(c));
      }
    g.triangles.indices = {0, 1, 2};
    // A random linear part (a third of them mirroring: determinant < 0) and translation.
    const auto blas = makeBlas({g});
    Instance in = instanceOf(blas, iter % 2 ? uint32_t(kInstanceTriangleFlipFacing) : 0u);
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) in.transform[r][c] = float((r == c ? 1.5 : 0) + 0.5 * u(rng));
      in.transform[r][3] = float(2 * u(rng));
    }
    if (iter % 3 == 0)
      for (int c = 0; c < 4; ++c) in.transform[1][c] = -in.transform[1][c];
    const float(*m)[4] = in.transform;
    const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                       m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                       m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    if (std::abs(det) < 0.2) continue;
    mirrored += det < 0;
    auto tlas = makeTlas({in});
    // Aim at an interior point (barycentric weights >= 0.15) from a random world origin.
    double w1 = 0.15 + 0.3 * (u(rng) + 1) / 2, w2 = 0.15 + 0.3 * (u(rng) + 1) / 2;
    double target[3], world[3], origin[3], dir[3];
    for (int i = 0; i < 3; ++i) target[i] = v[0][i] + w1 * (v[1][i] - v[0][i]) + w2 * (v[2][i] - v[0][i]);
    for (int r = 0; r < 3; ++r) world[r] = m[r][0] * target[0] + m[r][1] * target[1] + m[r][2] * target[2] + m[r][3];
    for (int i = 0; i < 3; ++i) {
      origin[i] = world[i] + 6 * u(rng);
      dir[i] = world[i] - origin[i];
    }
    Ray ray = rayFrom(float(origin[0]), float(origin[1]), float(origin[2]), float(dir[0]), float(dir[1]), float(dir[2]),
                      0, 2.0f);
    Traced t = traceOnce(*tlas, ray);
    ASSERT_TRUE(t.hit) << iter;
    EXPECT_NEAR(t.info.t, 1.0f, 1e-3) << iter;
    // The object-space ray, from the test's own inverse of the transform (Cramer's rule on the world offsets).
    double o[3], d[3];
    const double inv[3][3] = {
        {(m[1][1] * m[2][2] - m[1][2] * m[2][1]) / det, (m[0][2] * m[2][1] - m[0][1] * m[2][2]) / det,
         (m[0][1] * m[1][2] - m[0][2] * m[1][1]) / det},
        {(m[1][2] * m[2][0] - m[1][0] * m[2][2]) / det, (m[0][0] * m[2][2] - m[0][2] * m[2][0]) / det,
         (m[0][2] * m[1][0] - m[0][0] * m[1][2]) / det},
        {(m[1][0] * m[2][1] - m[1][1] * m[2][0]) / det, (m[0][1] * m[2][0] - m[0][0] * m[2][1]) / det,
         (m[0][0] * m[1][1] - m[0][1] * m[1][0]) / det}};
    for (int r = 0; r < 3; ++r) {
      o[r] = d[r] = 0;
      for (int c = 0; c < 3; ++c) {
        o[r] += inv[r][c] * (ray.origin[c] - m[c][3]);
        d[r] += inv[r][c] * ray.direction[c];
      }
    }
    int face = specFacing(v, o, d);
    ASSERT_NE(face, 0) << iter;
    if (in.flags & kInstanceTriangleFlipFacing) face = -face;
    (face > 0 ? fronts : backs)++;
    EXPECT_EQ(t.info.hitKind, face > 0 ? kFront : kBack) << "iteration " << iter << ", det " << det;
  }
  EXPECT_GT(mirrored, 10);
  EXPECT_GT(fronts, 10);
  EXPECT_GT(backs, 10);
}

}  // namespace
}  // namespace vkrt::accel::test
