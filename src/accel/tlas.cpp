// Top-level structures: the instances, their transforms and inverses, and an Embree scene of instance geometries.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "accel/embree_device.hpp"
#include "accel/structures.hpp"

namespace vkrt::accel {
namespace detail {

bool invertAffine(const float m[3][4], float out[3][4]) {
  // In double: the inverse is computed once per instance, and the shaders' WorldToObject should be as exact as
  // float storage allows.
  const double a = m[0][0], b = m[0][1], c = m[0][2];
  const double d = m[1][0], e = m[1][1], f = m[1][2];
  const double g = m[2][0], h = m[2][1], k = m[2][2];
  const double c00 = e * k - f * h, c01 = c * h - b * k, c02 = b * f - c * e;
  const double c10 = f * g - d * k, c11 = a * k - c * g, c12 = c * d - a * f;
  const double c20 = d * h - e * g, c21 = b * g - a * h, c22 = a * e - b * d;
  const double det = a * c00 + b * c10 + c * c20;
  if (det == 0 || !std::isfinite(det)) return false;
  const double inv[3][3] = {
      {c00 / det, c01 / det, c02 / det}, {c10 / det, c11 / det, c12 / det}, {c20 / det, c21 / det, c22 / det}};
  for (int r = 0; r < 3; ++r) {
    double t = 0;
    for (int j = 0; j < 3; ++j) {
      out[r][j] = float(inv[r][j]);
      t -= inv[r][j] * m[j][3];
    }
    out[r][3] = float(t);
    for (int j = 0; j < 4; ++j)
      if (!std::isfinite(out[r][j])) return false;
  }
  return true;
}

namespace {

// The inverse of the linear part as Embree 3 computes it for an instance (in float: adjoint over determinant), so
// that the bound on instance-space rays holds for Embree's own world-to-object transform too; false when it is not
// finite or the determinant is not a normal float (Embree flushes denormals to zero: its inverse would be infinite
// and every ray through the instance NaN).
bool embreeInverseGain(const float m[3][4], double* gain, double* offset) {
  // Embree's columns (vx, vy, vz) are the rows' components by column.
  const float vx[3] = {m[0][0], m[1][0], m[2][0]}, vy[3] = {m[0][1], m[1][1], m[2][1]};
  const float vz[3] = {m[0][2], m[1][2], m[2][2]};
  auto cross = [](const float a[3], const float b[3], float out[3]) {
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
  };
  float cyz[3], czx[3], cxy[3];
  cross(vy, vz, cyz);
  cross(vz, vx, czx);
  cross(vx, vy, cxy);
  const float det = vx[0] * cyz[0] + vx[1] * cyz[1] + vx[2] * cyz[2];
  if (!std::isnormal(det)) return false;
  // Rows of the inverse: cross(vy, vz), cross(vz, vx), cross(vx, vy), each over the determinant.
  const float* rows[3] = {cyz, czx, cxy};
  double g = 0, o = 0;
  for (const float* row : rows) {
    float inv[3] = {row[0] / det, row[1] / det, row[2] / det};
    float t = -(inv[0] * m[0][3] + inv[1] * m[1][3] + inv[2] * m[2][3]);
    if (!std::isfinite(inv[0]) || !std::isfinite(inv[1]) || !std::isfinite(inv[2]) || !std::isfinite(t)) return false;
    g = std::max(g, double(std::fabs(inv[0])) + std::fabs(inv[1]) + std::fabs(inv[2]));
    o = std::max(o, double(std::fabs(t)));
  }
  *gain = g;
  *offset = o;
  return true;
}

// Fills the per-instance records and the Tlas summary. An instance is inactive (never hit, index kept) when its
// Blas is null (Vulkan: reference 0) or its transform has no inverse (Vulkan requires an invertible one; a
// zero scale is sometimes used to hide an instance, and hiding it is what such an instance gets), in double or in
// the float arithmetic Embree inverts it with.
void makeRecords(Tlas::Impl& impl) {
  impl.records.resize(impl.instances.size());
  for (size_t i = 0; i < impl.instances.size(); ++i) {
    const Instance& in = impl.instances[i];
    InstanceRecord& r = impl.records[i];
    for (int row = 0; row < 3; ++row)
      for (int col = 0; col < 4; ++col) r.objectToWorld[row][col] = in.transform[row][col];
    r.customIndex = in.customIndex & 0xFFFFFF;
    r.sbtOffset = in.sbtOffset & 0xFFFFFF;
    r.flags = in.flags;
    double gain = 0, offset = 0;
    if (!in.blas || !invertAffine(r.objectToWorld, r.worldToObject) ||
        !embreeInverseGain(r.objectToWorld, &gain, &offset)) {
      for (auto& row : r.worldToObject)
        for (float& v : row) v = 0;
      continue;
    }
    r.blas = in.blas->impl.get();
    const BlasSummary& b = r.blas->summary;
    TlasSummary& s = impl.summary;
    if ((in.mask & 0xFF) == 0) continue;  // no ray sees it
    // Our double inverse bounds it as well (rayInEmbreeRange takes the larger).
    for (const auto& row : r.worldToObject) {
      gain = std::max(gain, double(std::fabs(row[0])) + std::fabs(row[1]) + std::fabs(row[2]));
      offset = std::max(offset, double(std::fabs(row[3])));
    }
    s.maxInverseGain = std::max(s.maxInverseGain, gain);
    s.maxInverseOffset = std::max(s.maxInverseOffset, offset);
    s.aabbs |= b.aabbs;
    if (!b.triangles) continue;
    s.triangles = true;
    s.facingCullable |= !(in.flags & kInstanceTriangleFacingCullDisable);
    // Opacity after the instance's force flags (the ray's come per ray).
    const bool forcedOpaque = in.flags & kInstanceForceOpaque;
    const bool forcedNoOpaque = !forcedOpaque && (in.flags & kInstanceForceNoOpaque);
    s.opaqueTriangles |= forcedOpaque || (!forcedNoOpaque && b.opaqueTriangles);
    s.noOpaqueTriangles |= forcedNoOpaque || (!forcedOpaque && b.noOpaqueTriangles);
  }
}

// Whether an instance's world bounds, as Embree computes them (its Blas's bounds, each corner transformed in float
// with denormals flushed: x * vx + (y * vy + (z * vz + p))), have extent (structures.hpp, hasExtent). A Blas far
// smaller than the float resolution at its instance's position has none: a translation absorbs it.
bool worldBoundsHaveExtent(const RTCBounds& b, const float m[3][4]) {
  constexpr float kInf = std::numeric_limits<float>::infinity();
  float lower[3] = {kInf, kInf, kInf}, upper[3] = {-kInf, -kInf, -kInf};
  for (int corner = 0; corner < 8; ++corner) {
    const float p[3] = {flushDenormal(corner & 1 ? b.upper_x : b.lower_x),
                        flushDenormal(corner & 2 ? b.upper_y : b.lower_y),
                        flushDenormal(corner & 4 ? b.upper_z : b.lower_z)};
    for (int row = 0; row < 3; ++row) {
      auto f = [](float v) { return flushDenormal(v); };
      const float z = f(f(p[2] * m[row][2]) + f(m[row][3]));
      const float y = f(f(p[1] * m[row][1]) + z);
      const float w = f(f(p[0] * m[row][0]) + y);
      lower[row] = std::min(lower[row], w);
      upper[row] = std::max(upper[row], w);
    }
  }
  return hasExtent(lower, upper);
}

// Flattening: the triangles of a small bottom level (kSmallBlasPrimitives) go into the top level's own scene in
// world space, one triangle geometry per instance mask, instead of an Embree instance of a scene of their own: no
// per-structure Embree object at all, which is what builds of thousands of one-triangle structures paid for. Each
// vertex is transformed once per instance (a vertex shared within an instance stays bit-identical, so Embree's
// watertight test closes the instance's edges as it does in object space). Traversal maps a flattened hit back to
// its instance, geometry and primitive (hitIds) and computes facing from the object-space triangle, as for an
// instanced one. Bounded: at most kFlatTriangles triangles a top level; past them, instances get scenes.
constexpr uint64_t kFlatTriangles = uint64_t(1) << 20;

// Whether `blas` is flattened (small, triangles only).
bool flattenable(const Blas::Impl& blas) { return blas.small && !blas.summary.aabbs; }

// One mask's flattened triangles: world-space vertices (three per triangle) and what each triangle is.
struct FlatGroup {
  std::vector<float> vertices;
  std::vector<FlatTriangle> triangles;
};

// Appends the active triangles of instance `i` (a flattenable Blas) to `group`. A triangle with a vertex that is not
// finite (inactive, or one Embree would leave out) or an index out of range, or that has no extent in world space
// (structures.hpp, hasExtent), is left out: never hit.
void flattenInstance(const InstanceRecord& r, uint32_t i, FlatGroup& group) {
  const float(*m)[4] = r.objectToWorld;
  for (uint32_t g = 0; g < r.blas->info.size(); ++g) {
    const GeometryInfo& geom = r.blas->info[g];
    if (geom.kind != Geometry::Triangles || !geom.vertices) continue;
    for (uint32_t p = 0; p < geom.primitiveCount; ++p) {
      float w[3][3];
      bool usable = true;
      for (int k = 0; k < 3 && usable; ++k) {
        const uint32_t index = geom.indices[3 * size_t(p) + k];
        if (index >= geom.vertexCount) {
          usable = false;
          break;
        }
        const float* v = geom.vertices + 3 * size_t(index);
        for (int row = 0; row < 3; ++row) {
          w[k][row] = m[row][0] * v[0] + m[row][1] * v[1] + m[row][2] * v[2] + m[row][3];
          usable &= std::isfinite(w[k][row]) && std::isfinite(v[row]);
        }
      }
      if (!usable) continue;
      float lower[3], upper[3];
      for (int c = 0; c < 3; ++c) {
        lower[c] = std::min({w[0][c], w[1][c], w[2][c]});
        upper[c] = std::max({w[0][c], w[1][c], w[2][c]});
      }
      if (!hasExtent(lower, upper)) continue;
      group.vertices.insert(group.vertices.end(), &w[0][0], &w[0][0] + 9);
      group.triangles.push_back({i, g, p});
    }
  }
}

RTCScene newScene(Tlas::Impl& impl, std::string* error) {
  RTCDevice device = detail::device(error);
  if (!device) return nullptr;
  EmbreeErrors errors;
  const SceneSettings settings = sceneSettings(impl.options, false);
  RTCScene scene = rtcNewScene(device);
  if (!scene) {
    errors.failed("Tlas build", error);
    return nullptr;
  }
  const size_t n = impl.instances.size();
  // Which instances are flattened (in index order, up to the bound), grouped by mask.
  std::vector<uint8_t> flat(n, 0);
  FlatGroup groups[256];
  uint64_t flatTriangles = 0;
  if (n <= 0xFFFFFFFEu - 256) {
    for (size_t i = 0; i < n; ++i) {
      const InstanceRecord& r = impl.records[i];
      const uint32_t mask = impl.instances[i].mask & 0xFF;
      if (!r.blas || !r.blas->primitives || !mask || !flattenable(*r.blas)) continue;
      if (flatTriangles + r.blas->primitives > kFlatTriangles) break;
      flatTriangles += r.blas->primitives;
      flat[i] = 1;
      flattenInstance(r, uint32_t(i), groups[mask]);
    }
  }
  // Robust here too: the instance hierarchy's box tests are conservative, so a ray grazing an instance's bounds
  // still enters it. The context filter runs for flattened triangles (no filter runs for instances themselves).
  int flags = settings.sceneFlags;
  if (!flatTriangles) flags &= ~RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION;
  rtcSetSceneFlags(scene, RTCSceneFlags(flags));
  rtcSetSceneBuildQuality(scene, settings.sceneQuality);  // (Embree's instance builders tell only LOW from the rest)
  // One instance geometry per active instance that is not flattened, attached under its index (Embree's instID = the
  // instance index). The geometries are made and committed on Embree's build threads, then attached one after the
  // other in index order (attached in parallel too, 10^5 instances took 2.5x longer on the 16-core machine: the
  // attachments contend for the scene's lock). Made in parallel, a build of 10^5 instances went from 1.35-1.50 to
  // 1.78-2.16 Minstances/s there; Embree's making of instance objects scales poorly (bench/embree_instances.cpp:
  // about 180 ns an instance on one thread, 120-150 ns on 4-16), so these per-instance objects, not Embree's build,
  // remain most of a large top level's build time.
  std::vector<RTCGeometry> geometries(n, nullptr);
  std::atomic<bool> outOfMemory{false};
  // The scenes of the small structures instanced here (not flattened) are made first, on this thread: made inside
  // the parallel loop below, a thread waiting for one Embree commit could run another chunk of the loop that needs
  // the same scene, re-entering its std::call_once.
  for (size_t i = 0; i < n; ++i) {
    const InstanceRecord& r = impl.records[i];
    if (!flat[i] && r.blas && r.blas->small && r.blas->primitives && (impl.instances[i].mask & 0xFF))
      r.blas->sceneFor();
  }
  parallelChunks(n, 1024, 4096, [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      const InstanceRecord& r = impl.records[i];
      const uint32_t mask = impl.instances[i].mask & 0xFF;
      if (flat[i] || !r.blas || !r.blas->primitives || !mask) continue;  // never hit (or flattened); the index stays
      RTCScene inner = r.blas->sceneFor();
      if (!inner) {
        outOfMemory.store(true, std::memory_order_relaxed);
        return;
      }
      // An instance without extent in world space is left out too (never hit): Embree's builder would abort.
      RTCBounds bounds;
      rtcGetSceneBounds(inner, &bounds);
      if (!worldBoundsHaveExtent(bounds, r.objectToWorld)) continue;
      RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_INSTANCE);
      if (!geometry) {
        outOfMemory.store(true, std::memory_order_relaxed);
        return;
      }
      rtcSetGeometryInstancedScene(geometry, inner);
      rtcSetGeometryTransform(geometry, 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, &r.objectToWorld[0][0]);
      rtcSetGeometryMask(geometry, mask);
      rtcCommitGeometry(geometry);
      geometries[i] = geometry;
    }
  });
  if (!outOfMemory.load())
    for (size_t i = 0; i < n; ++i)
      if (geometries[i]) rtcAttachGeometryByID(scene, geometries[i], unsigned(i));
  // The scene holds its own references now; ours go (each is a heap release: in parallel too).
  parallelChunks(n, 4096, 4096, [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i)
      if (geometries[i]) rtcReleaseGeometry(geometries[i]);
  });
  // The flattened triangles: one geometry per mask, IDs from flatBase on (after every instance's).
  impl.flatBase = uint32_t(n);
  for (unsigned mask = 1; mask < 256 && !outOfMemory.load(); ++mask) {
    FlatGroup& g = groups[mask];
    if (g.triangles.empty()) continue;
    RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* v = geometry ? static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0,
                                                                     RTC_FORMAT_FLOAT3, 12, g.triangles.size() * 3))
                       : nullptr;
    auto* ix = geometry ? static_cast<uint32_t*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0,
                                                                         RTC_FORMAT_UINT3, 12, g.triangles.size()))
                        : nullptr;
    if (!v || !ix) {
      if (geometry) rtcReleaseGeometry(geometry);
      outOfMemory.store(true);
      break;
    }
    std::memcpy(v, g.vertices.data(), g.vertices.size() * sizeof(float));
    for (uint32_t k = 0; k < 3 * g.triangles.size(); ++k) ix[k] = k;
    rtcSetGeometryMask(geometry, mask << kFlatMaskShift);
    // MEDIUM: each triangle in exactly one leaf (no spatial splits: VK_GEOMETRY_NO_DUPLICATE_ANY_HIT_INVOCATION_BIT).
    rtcSetGeometryBuildQuality(geometry, RTC_BUILD_QUALITY_MEDIUM);
    rtcCommitGeometry(geometry);
    rtcAttachGeometryByID(scene, geometry, impl.flatBase + unsigned(impl.flat.size()));
    rtcReleaseGeometry(geometry);
    impl.flat.push_back(std::move(g.triangles));
    // flat[] is indexed by geometry ID - flatBase: masks without triangles take no ID.
  }
  if (outOfMemory.load()) {
    if (error) *error = "Tlas build: Embree could not create an instance geometry (out of memory)";
    rtcReleaseScene(scene);
    return nullptr;
  }
  rtcCommitScene(scene);
  if (errors.failed("Tlas build", error)) {
    rtcReleaseScene(scene);
    return nullptr;
  }
  return scene;
}

}  // namespace
}  // namespace detail

Tlas::Impl::~Impl() {
  if (scene) rtcReleaseScene(scene);
}

Tlas::~Tlas() = default;

std::shared_ptr<Tlas> Tlas::build(std::vector<Instance> instances, const BuildOptions& options, std::string* error) {
  if (instances.size() > 0xFFFFFFFEu) {  // Embree's geometry IDs are 32-bit, with ~0u meaning none
    if (error) *error = "Tlas build: too many instances";
    return nullptr;
  }
  auto impl = std::make_unique<Impl>();
  impl->instances = std::move(instances);
  impl->options = options;
  detail::makeRecords(*impl);
  impl->scene = detail::newScene(*impl, error);
  if (!impl->scene) return nullptr;
  auto tlas = std::make_shared<Tlas>();
  tlas->impl = std::move(impl);
  return tlas;
}

// An update builds anew with the same options. Embree 3 keeps instances one geometry each and always rebuilds the
// hierarchy above them (even its two-level "refit" scenes rebuild their top level on every commit), so a refit
// would cost what a build costs; the old Tlas is untouched either way.
std::shared_ptr<Tlas> Tlas::update(std::vector<Instance> instances, std::string* error) const {
  return build(std::move(instances), impl->options, error);
}

const std::vector<Instance>& Tlas::instances() const { return impl->instances; }
const BuildOptions& Tlas::options() const { return impl->options; }

uint64_t Tlas::nativeBytes() const {
  // Estimate: the instances, their records, and Embree's instance geometry plus hierarchy (about 256 bytes each).
  return sizeof(Impl) + impl->instances.size() * (sizeof(Instance) + sizeof(detail::InstanceRecord) + 256);
}

}  // namespace vkrt::accel
