// Building bottom- and top-level structures with Embree.
//
// Build quality: Embree's high-quality builder uses spatial splits for triangles, which put one triangle in
// several leaves: a ray could then meet it twice and run its any-hit shader twice, which
// VK_GEOMETRY_NO_DUPLICATE_ANY_HIT_INVOCATION_BIT_KHR forbids. So a Blas uses HIGH only when it prefers fast
// traces and none of its geometries has that flag, LOW when it prefers fast builds, MEDIUM (binned SAH, every
// primitive in exactly one leaf) otherwise. A Tlas is built with the same rule (instances are never split).
//
// Watertightness: scenes are built with RTC_SCENE_FLAG_ROBUST, Embree's watertight triangle test (a ray through
// a shared edge or vertex hits at least one of the triangles), as the Vulkan specification requires of
// ray-triangle intersection.
#include <cmath>
#include <cstring>
#include <mutex>

#include "accel/embree_scene.hpp"

namespace vkrt::accel {

namespace {

thread_local std::string tlsError;

void onEmbreeError(void*, RTCError code, const char* message) {
  if (tlsError.empty())
    tlsError = std::string("Embree error ") + std::to_string(int(code)) + ": " + (message ? message : "");
}

RTCBuildQuality qualityFor(const BuildOptions& o, bool noDuplicates) {
  if (o.preferFastBuild) return RTC_BUILD_QUALITY_LOW;
  if (o.preferFastTrace && !noDuplicates) return RTC_BUILD_QUALITY_HIGH;
  return RTC_BUILD_QUALITY_MEDIUM;
}

RTCScene newScene(RTCBuildQuality quality, bool lowMemory) {
  RTCScene s = rtcNewScene(embreeDevice());
  if (!s) return nullptr;
  int flags = RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION | RTC_SCENE_FLAG_ROBUST;
  if (lowMemory) flags |= RTC_SCENE_FLAG_COMPACT;
  rtcSetSceneFlags(s, RTCSceneFlags(flags));
  rtcSetSceneBuildQuality(s, quality);
  return s;
}

void boxBounds(const RTCBoundsFunctionArguments* args) {
  const auto* g = static_cast<const AabbGeometry*>(args->geometryUserPtr);
  const float* b = g->boxes.data() + size_t(args->primID) * 6;
  RTCBounds* o = args->bounds_o;
  if (std::isnan(b[0])) {
    // An inactive box (NaN min x): empty bounds, never entered.
    o->lower_x = o->lower_y = o->lower_z = INFINITY;
    o->upper_x = o->upper_y = o->upper_z = -INFINITY;
    return;
  }
  o->lower_x = b[0];
  o->lower_y = b[1];
  o->lower_z = b[2];
  o->upper_x = b[3];
  o->upper_y = b[4];
  o->upper_z = b[5];
}

// Checks the geometries before Embree sees them: index ranges (Embree would read past the vertices) and array
// sizes. Returns false with `error` set.
bool validate(const std::vector<Geometry>& geometries, std::string* error) {
  for (size_t g = 0; g < geometries.size(); ++g) {
    const Geometry& geo = geometries[g];
    if (geo.kind == Geometry::Triangles) {
      const TriangleGeometry& t = geo.triangles;
      if (t.vertices.size() % 3 || t.indices.size() % 3) {
        *error = "geometry " + std::to_string(g) + ": vertex or index count is not a multiple of 3";
        return false;
      }
      const uint64_t vertexCount = t.vertices.size() / 3;
      for (size_t i = 0; i < t.indices.size(); ++i) {
        if (t.indices[i] >= vertexCount) {
          *error = "geometry " + std::to_string(g) + ": triangle " + std::to_string(i / 3) + " uses vertex " +
                   std::to_string(t.indices[i]) + ", but the geometry has " + std::to_string(vertexCount) + " vertices";
          return false;
        }
      }
    } else if (geo.aabbs.boxes.size() % 6) {
      *error = "geometry " + std::to_string(g) + ": box data is not a multiple of 6 floats";
      return false;
    }
  }
  return true;
}

bool attachTriangles(RTCScene scene, const TriangleGeometry& t, unsigned id, RTCBuildQuality quality) {
  RTCGeometry geom = rtcNewGeometry(embreeDevice(), RTC_GEOMETRY_TYPE_TRIANGLE);
  if (!geom) return false;
  const size_t vertexCount = t.vertices.size() / 3, triangles = t.indices.size() / 3;
  // Embree's own buffer: it pads the end for its 16-byte vertex loads.
  if (vertexCount) {
    auto* v = static_cast<float*>(
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), vertexCount));
    if (!v) {
      rtcReleaseGeometry(geom);
      return false;
    }
    std::memcpy(v, t.vertices.data(), vertexCount * 3 * sizeof(float));
  }
  if (triangles) {
    auto* idx = static_cast<uint32_t*>(
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), triangles));
    if (!idx) {
      rtcReleaseGeometry(geom);
      return false;
    }
    std::memcpy(idx, t.indices.data(), triangles * 3 * sizeof(uint32_t));
  }
  rtcSetGeometryMask(geom, kMaskTriangles);
  rtcSetGeometryBuildQuality(geom, quality);
  rtcCommitGeometry(geom);
  rtcAttachGeometryByID(scene, geom, id);
  rtcReleaseGeometry(geom);
  return true;
}

bool attachBoxes(RTCScene scene, const AabbGeometry& a, unsigned id, RTCBuildQuality quality,
                 RTCIntersectFunctionN intersect) {
  RTCGeometry geom = rtcNewGeometry(embreeDevice(), RTC_GEOMETRY_TYPE_USER);
  if (!geom) return false;
  rtcSetGeometryUserPrimitiveCount(geom, unsigned(a.boxes.size() / 6));
  rtcSetGeometryUserData(geom, const_cast<AabbGeometry*>(&a));
  rtcSetGeometryBoundsFunction(geom, &boxBounds, nullptr);
  rtcSetGeometryIntersectFunction(geom, intersect);
  rtcSetGeometryMask(geom, kMaskAabbs);
  rtcSetGeometryBuildQuality(geom, quality);
  rtcCommitGeometry(geom);
  rtcAttachGeometryByID(scene, geom, id);
  rtcReleaseGeometry(geom);
  return true;
}

// The inverse of an affine 3x4 (rows); false when singular.
bool invert(const float m[3][4], float out[3][4]) {
  const double a = m[0][0], b = m[0][1], c = m[0][2], d = m[1][0], e = m[1][1], f = m[1][2], g = m[2][0], h = m[2][1],
               i = m[2][2];
  const double det = a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g);
  if (!(std::fabs(det) > 0) || !std::isfinite(det)) return false;
  const double r[3][3] = {{(e * i - f * h) / det, (c * h - b * i) / det, (b * f - c * e) / det},
                          {(f * g - d * i) / det, (a * i - c * g) / det, (c * d - a * f) / det},
                          {(d * h - e * g) / det, (b * g - a * h) / det, (a * e - b * d) / det}};
  for (int row = 0; row < 3; ++row) {
    double t = 0;
    for (int k = 0; k < 3; ++k) {
      out[row][k] = float(r[row][k]);
      t -= r[row][k] * m[k][3];
    }
    out[row][3] = float(t);
  }
  return true;
}

std::string failure(const char* what) {
  std::string e = takeError();
  return std::string(what) + (e.empty() ? ": out of memory" : ": " + e);
}

}  // namespace

// Defined in trace.cpp: the box intersection callback.
void boxIntersect(const RTCIntersectFunctionNArguments* args);

RTCDevice embreeDevice() {
  static RTCDevice device = [] {
    RTCDevice d = rtcNewDevice("verbose=0");
    if (d) rtcSetDeviceErrorFunction(d, &onEmbreeError, nullptr);
    return d;
  }();
  return device;
}

std::string takeError() {
  std::string e;
  e.swap(tlsError);
  return e;
}

Blas::~Blas() = default;
Tlas::~Tlas() = default;

std::shared_ptr<Blas> Blas::build(std::vector<Geometry> geometries, const BuildOptions& options, std::string* error) {
  if (!validate(geometries, error)) return nullptr;
  if (!embreeDevice()) {
    *error = "Embree could not create its device";
    return nullptr;
  }
  takeError();
  auto blas = std::shared_ptr<Blas>(new Blas);
  blas->impl = std::make_unique<Impl>();
  Impl& b = *blas->impl;
  b.geometries = std::move(geometries);
  b.options = options;
  bool noDuplicates = false;
  for (const Geometry& g : b.geometries) {
    noDuplicates |= (g.kind == Geometry::Triangles ? g.triangles.flags : g.aabbs.flags) & kGeometryNoDuplicateAnyHit;
    if (g.kind == Geometry::Triangles) {
      b.anyTriangles = true;
      b.anyNonOpaqueTriangles |= !(g.triangles.flags & kGeometryOpaque);
      b.primitives += g.triangles.indices.size() / 3;
      b.bytes += (g.triangles.vertices.size() + g.triangles.indices.size()) * 4 * 2;
    } else {
      b.anyAabbs = true;
      b.primitives += g.aabbs.boxes.size() / 6;
      b.bytes += g.aabbs.boxes.size() * 4;
    }
  }
  const RTCBuildQuality quality = qualityFor(options, noDuplicates);
  RTCScene scene = newScene(quality, options.lowMemory);
  if (!scene) {
    *error = failure("creating the Embree scene");
    return nullptr;
  }
  b.scene.reset(scene);
  for (unsigned g = 0; g < b.geometries.size(); ++g) {
    const Geometry& geo = b.geometries[g];
    bool ok = geo.kind == Geometry::Triangles ? attachTriangles(scene, geo.triangles, g, quality)
                                              : attachBoxes(scene, geo.aabbs, g, quality, &boxIntersect);
    if (!ok) {
      *error = failure("creating an Embree geometry");
      return nullptr;
    }
  }
  rtcCommitScene(scene);
  if (std::string e = takeError(); !e.empty()) {
    *error = "building the Embree scene: " + e;
    return nullptr;
  }
  // Embree's hierarchy: about 64 bytes a primitive at medium quality.
  b.bytes += b.primitives * 64 + 256;
  return blas;
}

std::shared_ptr<Blas> Blas::update(std::vector<Geometry> geometries, std::string* error) const {
  // Embree refits only a scene in place, and this Blas may still be traversed: the update is a new build of the
  // same geometries (with the new positions), at the quality the original asked for.
  return build(std::move(geometries), impl->options, error);
}

const std::vector<Geometry>& Blas::geometries() const { return impl->geometries; }
const BuildOptions& Blas::options() const { return impl->options; }
uint64_t Blas::primitiveCount() const { return impl->primitives; }
uint64_t Blas::nativeBytes() const { return impl->bytes; }

std::shared_ptr<Tlas> Tlas::build(std::vector<Instance> instances, const BuildOptions& options, std::string* error) {
  if (!embreeDevice()) {
    *error = "Embree could not create its device";
    return nullptr;
  }
  takeError();
  auto tlas = std::shared_ptr<Tlas>(new Tlas);
  tlas->impl = std::make_unique<Impl>();
  Impl& t = *tlas->impl;
  t.instances = std::move(instances);
  t.options = options;
  const RTCBuildQuality quality = qualityFor(options, false);
  RTCScene scene = newScene(quality, options.lowMemory);
  if (!scene) {
    *error = failure("creating the Embree scene");
    return nullptr;
  }
  t.scene.reset(scene);
  t.data.reserve(t.instances.size());
  for (uint32_t i = 0; i < t.instances.size(); ++i) {
    const Instance& in = t.instances[i];
    // Inactive (no Blas), never hit by any ray (mask 0), or singular: not entered in Embree.
    if (!in.blas || (in.mask & 0xFF) == 0) continue;
    InstanceData d{};
    std::memcpy(d.objectToWorld, in.transform, sizeof d.objectToWorld);
    if (!invert(in.transform, d.worldToObject)) continue;
    d.index = i;
    d.customIndex = in.customIndex & 0xFFFFFF;
    d.sbtOffset = in.sbtOffset & 0xFFFFFF;
    d.flags = in.flags;
    d.blas = in.blas->impl.get();
    RTCGeometry geom = rtcNewGeometry(embreeDevice(), RTC_GEOMETRY_TYPE_INSTANCE);
    if (!geom) {
      *error = failure("creating an Embree instance");
      return nullptr;
    }
    rtcSetGeometryInstancedScene(geom, d.blas->scene.get());
    rtcSetGeometryTransform(geom, 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, &in.transform[0][0]);
    rtcSetGeometryMask(geom, in.mask & 0xFF);
    rtcCommitGeometry(geom);
    rtcAttachGeometryByID(scene, geom, unsigned(t.data.size()));
    rtcReleaseGeometry(geom);
    const bool forceOpaque = in.flags & kInstanceForceOpaque, forceNoOpaque = in.flags & kInstanceForceNoOpaque;
    t.anyTriangles |= d.blas->anyTriangles;
    t.anyAabbs |= d.blas->anyAabbs;
    t.mayMeetNonOpaqueTriangles |=
        d.blas->anyTriangles && (forceNoOpaque || (!forceOpaque && d.blas->anyNonOpaqueTriangles));
    t.data.push_back(d);
  }
  rtcCommitScene(scene);
  if (std::string e = takeError(); !e.empty()) {
    *error = "building the Embree scene: " + e;
    return nullptr;
  }
  t.bytes = t.instances.size() * (sizeof(Instance) + sizeof(InstanceData) + 64) + 256;
  return tlas;
}

std::shared_ptr<Tlas> Tlas::update(std::vector<Instance> instances, std::string* error) const {
  return build(std::move(instances), impl->options, error);
}

const std::vector<Instance>& Tlas::instances() const { return impl->instances; }
const BuildOptions& Tlas::options() const { return impl->options; }
uint64_t Tlas::nativeBytes() const { return impl->bytes; }

}  // namespace vkrt::accel
