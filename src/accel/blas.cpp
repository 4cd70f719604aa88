// Bottom-level structures: copies of the geometries, and an Embree scene built (or refitted) from them.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>

#include "accel/embree_device.hpp"
#include "accel/structures.hpp"

namespace vkrt::accel {
namespace detail {

// Defined in traverse.cpp: the user-geometry callbacks that run the intersection shader for a box.
void boxIntersect(const RTCIntersectFunctionNArguments* args);
void boxOccluded(const RTCOccludedFunctionNArguments* args);

SceneSettings sceneSettings(const BuildOptions& options, bool noDuplicateAnyHit) {
  SceneSettings s{};
  // Robust: Embree's watertight ray/triangle test (Pluecker coordinates with a conservative edge epsilon, so a ray
  // through a shared edge or vertex never falls between two triangles) and conservative box tests in the
  // hierarchy. Vulkan asks for watertightness ("Watertightness" in "Ray Traversal"; the CTS checks it); the fast
  // Moeller-Trumbore path lets rays through shared edges (tests/accel/watertight_test.cpp: about 2% of rays aimed
  // at the shared edges of a bumpy grid miss it; none do with the robust flag). Measured on the development VM
  // (2 shared cores; -O3, 100k-triangle sphere, 1M incoherent rays, one thread, best of 3, several runs): robust
  // rtcIntersect1 runs at 0.78-0.90 of the fast path's rays/s. vkrt pays that for conformance; trace() itself
  // stays at 0.83-0.86 of raw robust rtcIntersect1 (0.68-0.77 of the fast path). Robust mode also never uses
  // spatial splits for triangles.
  s.sceneFlags = RTC_SCENE_FLAG_ROBUST | RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION;
  if (options.lowMemory) s.sceneFlags |= RTC_SCENE_FLAG_COMPACT;  // leaves index the vertices instead of copying them
  if (options.allowUpdate) {
    // Embree 3 refits only in its two-level ("dynamic", quality LOW) scenes, per geometry whose quality is REFIT
    // (bvh_builder_twolevel: the mesh refit builder): the first commit builds a SAH hierarchy per geometry, later
    // commits of the same scene refit it.
    s.sceneQuality = RTC_BUILD_QUALITY_LOW;
    s.geometryQuality = RTC_BUILD_QUALITY_REFIT;
    return s;
  }
  // HIGH adds spatial splits for triangles, which put one triangle in several leaves, and Embree then reports it
  // (runs the filter) once per leaf: a geometry with VK_GEOMETRY_NO_DUPLICATE_ANY_HIT_INVOCATION_BIT_KHR must not
  // see that, so a Blas holding one is built at MEDIUM (binned SAH, each primitive in exactly one leaf). (The
  // robust flag above already rules spatial splits out; this keeps the rule if that choice changes.)
  if (options.preferFastTrace)
    s.sceneQuality = noDuplicateAnyHit ? RTC_BUILD_QUALITY_MEDIUM : RTC_BUILD_QUALITY_HIGH;
  else if (options.preferFastBuild)
    s.sceneQuality = RTC_BUILD_QUALITY_LOW;
  else
    s.sceneQuality = RTC_BUILD_QUALITY_MEDIUM;
  s.geometryQuality = s.sceneQuality;
  return s;
}

RefitPool::~RefitPool() {
  for (RTCScene s : idle) rtcReleaseScene(s);
}

RTCScene RefitPool::take() {
  std::lock_guard<std::mutex> lock(mutex);
  if (idle.empty()) return nullptr;
  RTCScene s = idle.back();
  idle.pop_back();
  return s;
}

void RefitPool::give(RTCScene scene) {
  std::lock_guard<std::mutex> lock(mutex);
  idle.push_back(scene);
}

namespace {

// Primitives without extent (structures.hpp, hasExtent) are never given to Embree: see boxBounds and pointTriangle.
//
// Embree asks a user geometry for each primitive's bounds at build and refit. An inactive box (NaN min x) gets
// NaN bounds, which Embree leaves out of the hierarchy: it is never hit and keeps its index. A box without extent
// (hasExtent) gets bounds widened on every axis by a normal float's worth (relative to its coordinates, at least
// the smallest normal float). The bounds only cull; the intersection callback tests the box as given, so nothing
// it hits changes.
void boxBounds(const RTCBoundsFunctionArguments* args) {
  const auto* info = static_cast<const GeometryInfo*>(args->geometryUserPtr);
  float lower[3], upper[3];
  embreeBoxBounds(info->boxes + 6 * size_t(args->primID), lower, upper);
  RTCBounds* out = args->bounds_o;
  out->lower_x = lower[0];
  out->lower_y = lower[1];
  out->lower_z = lower[2];
  out->upper_x = upper[0];
  out->upper_y = upper[1];
  out->upper_z = upper[2];
}

// A triangle without extent (hasExtent: its vertices are one point, to Embree's arithmetic). It has no area, so no
// ray hits it; it is left out of Embree's hierarchy (its indices in Embree's copy point past the vertices, which
// Embree skips, so every other triangle keeps its index).
bool pointTriangle(const TriangleGeometry& t, size_t p) {
  const size_t vertexCount = t.vertices.size() / 3;
  const uint32_t* i = &t.indices[3 * p];
  if (i[0] >= vertexCount || i[1] >= vertexCount || i[2] >= vertexCount) return false;
  float lower[3], upper[3];
  for (int k = 0; k < 3; ++k) {
    const float a = t.vertices[3 * size_t(i[0]) + k], b = t.vertices[3 * size_t(i[1]) + k];
    const float c = t.vertices[3 * size_t(i[2]) + k];
    if (!std::isfinite(a) || !std::isfinite(b) || !std::isfinite(c)) return false;  // Embree leaves it out itself
    lower[k] = std::min({a, b, c});
    upper[k] = std::max({a, b, c});
  }
  return !hasExtent(lower, upper);
}

bool validate(const std::vector<Geometry>& geometries, std::string* error) {
  for (size_t i = 0; i < geometries.size(); ++i) {
    const Geometry& g = geometries[i];
    const char* problem = nullptr;
    if (g.kind == Geometry::Triangles) {
      if (g.triangles.vertices.size() % 3) problem = "vertex floats not a multiple of 3";
      if (g.triangles.indices.size() % 3) problem = "indices not a multiple of 3";
      if (g.triangles.indices.size() / 3 > std::numeric_limits<uint32_t>::max()) problem = "too many triangles";
    } else if (g.kind == Geometry::Aabbs) {
      if (g.aabbs.boxes.size() % 6) problem = "box floats not a multiple of 6";
      if (g.aabbs.boxes.size() / 6 > std::numeric_limits<uint32_t>::max()) problem = "too many boxes";
    } else {
      problem = "unknown geometry kind";
    }
    if (problem) {
      if (error) *error = "Blas geometry " + std::to_string(i) + ": " + problem;
      return false;
    }
  }
  return true;
}

// Takes the geometries over and derives what traversal reads; no Embree call.
std::unique_ptr<Blas::Impl> makeImpl(std::vector<Geometry> geometries, const BuildOptions& options) {
  auto impl = std::make_unique<Blas::Impl>();
  impl->geometries = std::move(geometries);
  impl->options = options;
  impl->info.resize(impl->geometries.size());
  for (size_t i = 0; i < impl->geometries.size(); ++i) {
    const Geometry& g = impl->geometries[i];
    GeometryInfo& info = impl->info[i];
    info.kind = g.kind;
    if (g.kind == Geometry::Triangles) {
      info.flags = g.triangles.flags;
      info.primitiveCount = uint32_t(g.triangles.indices.size() / 3);
      info.vertices = g.triangles.vertices.data();
      info.indices = g.triangles.indices.data();
      info.vertexCount = uint32_t(g.triangles.vertices.size() / 3);
      if (info.primitiveCount && !g.triangles.vertices.empty()) {
        impl->summary.triangles = true;
        (info.flags & kGeometryOpaque ? impl->summary.opaqueTriangles : impl->summary.noOpaqueTriangles) = true;
      }
    } else {
      info.flags = g.aabbs.flags;
      info.primitiveCount = uint32_t(g.aabbs.boxes.size() / 6);
      info.boxes = g.aabbs.boxes.data();
      if (info.primitiveCount) impl->summary.aabbs = true;
    }
    impl->primitives += info.primitiveCount;
  }
  return impl;
}

// A direct Blas (small, boxes only): the boxes Embree would keep, in geometry and primitive order, and the union of
// their bounds as Embree would compute the scene's (empty: lower above upper).
void makeDirect(Blas::Impl& impl) {
  impl.direct = true;
  float lo[3] = {HUGE_VALF, HUGE_VALF, HUGE_VALF}, hi[3] = {-HUGE_VALF, -HUGE_VALF, -HUGE_VALF};
  for (uint32_t g = 0; g < impl.info.size(); ++g) {
    const GeometryInfo& info = impl.info[g];
    if (info.kind != Geometry::Aabbs) continue;
    for (uint32_t p = 0; p < info.primitiveCount; ++p) {
      float lower[3], upper[3];
      embreeBoxBounds(info.boxes + 6 * size_t(p), lower, upper);
      if (!embreeKeepsBounds(lower, upper)) continue;
      impl.directBoxes[impl.directCount++] = {g, p};
      for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], lower[k]), hi[k] = std::max(hi[k], upper[k]);
    }
  }
  impl.directBounds = RTCBounds{lo[0], lo[1], lo[2], 0, hi[0], hi[1], hi[2], 0};
}

bool hasNoDuplicateAnyHit(const Blas::Impl& impl) {
  for (const GeometryInfo& info : impl.info)
    if (info.flags & kGeometryNoDuplicateAnyHit) return true;
  return false;
}

// Embree's vertex and index buffers. Where the Blas's arrays can serve as they are, Embree reads them in place
// (rtcSetSharedGeometryBuffer: they live as long as the Blas, which outlives its scene, and no copy is made): the
// vertices when their vector has room for one float past the last vertex (Embree reads each vertex with one 16-byte
// load; the runtime reserves it), the indices when no triangle collapses to a point. Otherwise Embree gets copies
// (rtcSetNewGeometryBuffer pads the vertex buffer), with the indices of collapsed triangles pointing past the
// vertices so that Embree leaves them out and the Blas's copies stay exactly what the caller gave. Large copies
// and the scan for collapsed triangles run in chunks on Embree's build threads: one after the other they cost as
// much as Embree's whole build of 10^7 triangles on 16 threads (the copies also take the first touch of Embree's
// fresh pages, which the kernel zeroes). A refit points a scene of the family at the new Blas's arrays the same
// way (a shared buffer of a dead Blas of the family is never read again).
void setTriangleBuffers(RTCGeometry geometry, const TriangleGeometry& t, bool build) {
  constexpr size_t kChunk = size_t(1) << 15, kSerialBelow = size_t(1) << 16;  // vertices or triangles
  const size_t vertexCount = t.vertices.size() / 3;
  if (t.vertices.capacity() > t.vertices.size()) {
    rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, t.vertices.data(), 0,
                               3 * sizeof(float), vertexCount);
  } else if (auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(
                 geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), vertexCount))) {
    // (A refit too gets a buffer of its own: the scene's may be one shared with a dead Blas of the family.)
    parallelChunks(vertexCount, kChunk, kSerialBelow, [&](size_t begin, size_t end) {
      std::memcpy(vertices + 3 * begin, t.vertices.data() + 3 * begin, (end - begin) * 3 * sizeof(float));
    });
  }
  const size_t triangleCount = t.indices.size() / 3;
  std::atomic<bool> collapsed{false};
  parallelChunks(triangleCount, kChunk, kSerialBelow, [&](size_t begin, size_t end) {
    for (size_t p = begin; p < end && !collapsed.load(std::memory_order_relaxed); ++p)
      if (pointTriangle(t, p)) collapsed.store(true, std::memory_order_relaxed);
  });
  if (!collapsed.load()) {
    rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, t.indices.data(), 0,
                               3 * sizeof(uint32_t), triangleCount);
    return;
  }
  // A refit keeps the copy its build made (the same indices and collapsed triangles: sameTopology).
  if (!build) return;
  auto* indices = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                 3 * sizeof(uint32_t), triangleCount));
  if (!indices) return;
  parallelChunks(triangleCount, kChunk, kSerialBelow, [&](size_t begin, size_t end) {
    std::memcpy(indices + 3 * begin, t.indices.data() + 3 * begin, (end - begin) * 3 * sizeof(uint32_t));
    for (size_t p = begin; p < end; ++p)
      if (pointTriangle(t, p))
        for (int k = 0; k < 3; ++k) indices[3 * p + k] = std::numeric_limits<uint32_t>::max();
  });
}

RTCGeometry newGeometry(RTCDevice device, Blas::Impl& impl, size_t i, RTCBuildQuality quality) {
  const Geometry& g = impl.geometries[i];
  GeometryInfo& info = impl.info[i];
  RTCGeometry geometry;
  if (g.kind == Geometry::Triangles) {
    geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    if (!geometry) return nullptr;
    setTriangleBuffers(geometry, g.triangles, true);
    rtcSetGeometryMask(geometry, kTriangleMaskBit);
  } else {
    geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER);
    if (!geometry) return nullptr;
    rtcSetGeometryUserPrimitiveCount(geometry, info.primitiveCount);
    rtcSetGeometryBoundsFunction(geometry, boxBounds, nullptr);
    rtcSetGeometryIntersectFunction(geometry, boxIntersect);
    rtcSetGeometryOccludedFunction(geometry, boxOccluded);
    rtcSetGeometryMask(geometry, kAabbMaskBit);
  }
  rtcSetGeometryUserData(geometry, &info);
  rtcSetGeometryBuildQuality(geometry, quality);
  rtcCommitGeometry(geometry);
  return geometry;
}

// A geometry Embree needs to see: one with primitives (and, for triangles, vertices). The others are left out;
// attaching by ID keeps every geometry's index.
bool embreeNeeds(const Blas::Impl& impl, size_t i) {
  const Geometry& g = impl.geometries[i];
  if (!impl.info[i].primitiveCount) return false;
  return g.kind != Geometry::Triangles || !g.triangles.vertices.empty();
}

RTCScene newScene(Blas::Impl& impl, std::string* error) {
  RTCDevice device = detail::device(error);
  if (!device) return nullptr;
  EmbreeErrors errors;
  const SceneSettings settings = sceneSettings(impl.options, hasNoDuplicateAnyHit(impl));
  RTCScene scene = rtcNewScene(device);
  if (!scene) {
    errors.failed("Blas build", error);
    return nullptr;
  }
  rtcSetSceneFlags(scene, RTCSceneFlags(settings.sceneFlags));
  rtcSetSceneBuildQuality(scene, settings.sceneQuality);
  for (size_t i = 0; i < impl.geometries.size(); ++i) {
    if (!embreeNeeds(impl, i)) continue;
    RTCGeometry geometry = newGeometry(device, impl, i, settings.geometryQuality);
    if (!geometry) break;
    rtcAttachGeometryByID(scene, geometry, unsigned(i));
    rtcReleaseGeometry(geometry);
  }
  rtcCommitScene(scene);
  if (errors.failed("Blas build", error)) {
    rtcReleaseScene(scene);
    return nullptr;
  }
  return scene;
}

// Points a scene of the family (same topology) at `impl`'s positions and refits it.
bool refitScene(RTCScene scene, Blas::Impl& impl, std::string* error) {
  EmbreeErrors errors;
  for (size_t i = 0; i < impl.geometries.size(); ++i) {
    if (!embreeNeeds(impl, i)) continue;
    RTCGeometry geometry = rtcGetGeometry(scene, unsigned(i));
    if (!geometry) break;
    if (impl.geometries[i].kind == Geometry::Triangles) {
      setTriangleBuffers(geometry, impl.geometries[i].triangles, false);
      rtcUpdateGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0);
    }
    rtcSetGeometryUserData(geometry, &impl.info[i]);  // boxes: the bounds callback reads the new copies
    rtcCommitGeometry(geometry);
  }
  rtcCommitScene(scene);
  return !errors.failed("Blas update", error);
}

bool inactive(const Geometry& g, size_t primitive) {
  if (g.kind == Geometry::Aabbs) return std::isnan(g.aabbs.boxes[6 * primitive]);
  const auto& t = g.triangles;
  for (int k = 0; k < 3; ++k) {
    const size_t v = t.indices[3 * primitive + k];
    if (3 * v < t.vertices.size() && std::isnan(t.vertices[3 * v])) return true;
  }
  return false;
}

// Whether `b` may refit a scene built from `a`: same geometries, kinds, flags, counts, indices, and the same
// primitives active (Vulkan forbids changing any of these in an update; where a caller does, vkrt builds anew
// rather than refit a hierarchy that no longer fits), and the same triangles collapsed to a point (those are out of
// Embree's hierarchy, pointTriangle: a refit cannot move a triangle in or out of it).
bool sameTopology(const std::vector<Geometry>& a, const std::vector<Geometry>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i) {
    const Geometry& x = a[i];
    const Geometry& y = b[i];
    if (x.kind != y.kind) return false;
    size_t primitives;
    if (x.kind == Geometry::Triangles) {
      if (x.triangles.flags != y.triangles.flags || x.triangles.vertices.size() != y.triangles.vertices.size() ||
          x.triangles.indices != y.triangles.indices)
        return false;
      primitives = x.triangles.indices.size() / 3;
    } else {
      if (x.aabbs.flags != y.aabbs.flags || x.aabbs.boxes.size() != y.aabbs.boxes.size()) return false;
      primitives = x.aabbs.boxes.size() / 6;
    }
    for (size_t p = 0; p < primitives; ++p)
      if (inactive(x, p) != inactive(y, p)) return false;
    if (x.kind == Geometry::Triangles)
      for (size_t p = 0; p < primitives; ++p)
        if (pointTriangle(x.triangles, p) != pointTriangle(y.triangles, p)) return false;
  }
  return true;
}

}  // namespace
}  // namespace detail

RTCScene Blas::Impl::sceneFor() const {
  if (!small) return scene;
  // (newScene only points Embree at `info`; nothing of this Blas changes.)
  std::call_once(sceneOnce_, [this] { lazyScene_ = detail::newScene(const_cast<Impl&>(*this), nullptr); });
  return lazyScene_;
}

Blas::Impl::~Impl() {
  if (lazyScene_) rtcReleaseScene(lazyScene_);
  if (!scene) return;
  if (pool)
    pool->give(scene);  // its family's next update refits it
  else
    rtcReleaseScene(scene);
}

Blas::~Blas() = default;

std::shared_ptr<Blas> Blas::build(std::vector<Geometry> geometries, const BuildOptions& options, std::string* error) {
  if (!detail::validate(geometries, error)) return nullptr;
  auto impl = detail::makeImpl(std::move(geometries), options);
  impl->small = impl->primitives <= kSmallBlasPrimitives;
  if (impl->small && impl->summary.aabbs && !impl->summary.triangles) detail::makeDirect(*impl);
  if (!impl->small) {
    impl->scene = detail::newScene(*impl, error);
    if (!impl->scene) return nullptr;
    if (options.allowUpdate) impl->pool = std::make_shared<detail::RefitPool>();
  }
  auto blas = std::make_shared<Blas>();
  blas->impl = std::move(impl);
  return blas;
}

std::shared_ptr<Blas> Blas::update(std::vector<Geometry> geometries, std::string* error) const {
  if (!detail::validate(geometries, error)) return nullptr;
  // A small structure has no hierarchy to refit: its update is a build (as cheap).
  if (impl->small || !impl->options.allowUpdate || !detail::sameTopology(impl->geometries, geometries))
    return build(std::move(geometries), impl->options, error);
  auto next = detail::makeImpl(std::move(geometries), impl->options);
  next->pool = impl->pool;
  if (RTCScene scene = next->pool->take()) {
    if (!detail::refitScene(scene, *next, error)) {
      rtcReleaseScene(scene);  // not given back: its state after a failed refit is unknown
      return nullptr;
    }
    next->scene = scene;
  } else {
    // No idle scene in the family (this one and the others are alive): this update builds one; it joins the
    // family, and later updates refit it once its Blas is gone.
    next->scene = detail::newScene(*next, error);
    if (!next->scene) return nullptr;
  }
  auto blas = std::make_shared<Blas>();
  blas->impl = std::move(next);
  return blas;
}

const std::vector<Geometry>& Blas::geometries() const { return impl->geometries; }
const BuildOptions& Blas::options() const { return impl->options; }
uint64_t Blas::primitiveCount() const { return impl->primitives; }

uint64_t Blas::nativeBytes() const {
  // Estimate: vkrt's copies, Embree's vertex and index copies, and about 64 bytes of hierarchy per primitive
  // (BVH8 nodes and 4-wide leaves holding their triangles' vertices, which is what Embree's robust builder lays out).
  uint64_t bytes = sizeof(Impl) + impl->info.size() * sizeof(detail::GeometryInfo);
  for (const Geometry& g : impl->geometries) {
    bytes += 2 * (g.triangles.vertices.size() + g.triangles.indices.size()) * 4 + g.aabbs.boxes.size() * 4;
  }
  return bytes + 64 * impl->primitives;
}

}  // namespace vkrt::accel
