// Private to src/accel: what a Blas and a Tlas hold, in the shape traversal reads it.
#pragma once

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

#include "accel/accel.hpp"

namespace vkrt::accel::detail {

// Embree geometry masks. A ray's Embree mask is its 8-bit cull mask plus one bit per primitive kind it does not
// skip; an instance's geometry mask is its 8-bit Vulkan mask, and the geometries inside a Blas carry their kind's
// bit. Embree drops an instance, and a primitive, whose mask shares no bit with the ray's: instance masking,
// SkipTrianglesKHR and SkipAABBsKHR cost no filter call.
inline constexpr unsigned kTriangleMaskBit = 0x100;
inline constexpr unsigned kAabbMaskBit = 0x200;

// Opacity (Vulkan "Ray Opacity Culling"): the geometry's VK_GEOMETRY_OPAQUE_BIT_KHR, overridden by the instance's
// FORCE_OPAQUE / FORCE_NO_OPAQUE, overridden by the ray's OpaqueKHR / NoOpaqueKHR. (The pairs are mutually
// exclusive in valid use; where both are set, the opaque one wins.)
inline bool instanceOpaque(uint32_t geometryFlags, uint32_t instanceFlags) {
  if (instanceFlags & kInstanceForceOpaque) return true;
  if (instanceFlags & kInstanceForceNoOpaque) return false;
  return (geometryFlags & kGeometryOpaque) != 0;
}
inline bool effectiveOpaque(uint32_t geometryFlags, uint32_t instanceFlags, uint32_t rayFlags) {
  if (rayFlags & kRayOpaque) return true;
  if (rayFlags & kRayNoOpaque) return false;
  return instanceOpaque(geometryFlags, instanceFlags);
}

// What traversal needs of one geometry of a Blas.
struct GeometryInfo {
  Geometry::Kind kind = Geometry::Triangles;
  uint32_t flags = 0;                 // GeometryFlag
  const float* boxes = nullptr;       // Aabbs: 6 floats per primitive (the Blas's copy)
  const float* vertices = nullptr;    // Triangles: x, y, z per vertex (the Blas's copy)
  const uint32_t* indices = nullptr;  // Triangles: three per primitive
  uint32_t vertexCount = 0;
  uint32_t primitiveCount = 0;
};

// Scenes of one Blas and of the Blases updated from it share a topology: an update refits one of them. A Blas
// built with allowUpdate returns its scene here when it dies, and the next update of the family takes a scene
// from here (refit) instead of building one.
struct RefitPool {
  std::mutex mutex;
  std::vector<RTCScene> idle;
  ~RefitPool();
  RTCScene take();
  void give(RTCScene scene);
};

// What a Tlas needs to know of a Blas without looking at its geometries.
struct BlasSummary {
  bool triangles = false;          // an active triangle geometry with primitives
  bool aabbs = false;              // an AABB geometry with primitives
  bool opaqueTriangles = false;    // a triangle geometry with VK_GEOMETRY_OPAQUE_BIT_KHR
  bool noOpaqueTriangles = false;  // a triangle geometry without it
};

}  // namespace vkrt::accel::detail

namespace vkrt::accel {

// A bottom level of at most this many primitives is small: its build makes no Embree scene (an Embree scene and its
// commit cost about 5 KB and 5-15 us whatever their size, which dominated builds of thousands of one-triangle
// structures). A top level puts the triangles of the small ones it instances into its own scene, in world space
// (tlas.cpp: "flattened"); a small one of boxes only never gets a scene: traversal offers its boxes one by one
// (direct); the others (triangles and boxes) get an Embree scene made on first use (sceneFor()).
inline constexpr uint64_t kSmallBlasPrimitives = 16;

namespace detail {
// A box of a direct Blas that Embree would keep (embreeKeepsBounds): the ones traversal offers.
struct DirectBox {
  uint32_t geometry, primitive;
};
}  // namespace detail

struct Blas::Impl {
  std::vector<Geometry> geometries;
  BuildOptions options;
  std::vector<detail::GeometryInfo> info;  // per geometry, pointing into `geometries`
  detail::BlasSummary summary;
  uint64_t primitives = 0;
  bool small = false;                       // primitives <= kSmallBlasPrimitives: no scene until sceneFor()
  RTCScene scene = nullptr;                 // committed, read-only after build (small: made by sceneFor())
  std::shared_ptr<detail::RefitPool> pool;  // allowUpdate, not small
  // Small and of boxes only: no Embree scene ever; its boxes Embree would keep, and their bounds (Embree's, empty
  // when there is none).
  bool direct = false;
  uint32_t directCount = 0;
  detail::DirectBox directBoxes[kSmallBlasPrimitives];
  RTCBounds directBounds{};

  // The committed Embree scene (a small one's is built on the first call, once, thread-safely); null when Embree
  // cannot build it (out of memory).
  RTCScene sceneFor() const;

  ~Impl();

 private:
  mutable std::once_flag sceneOnce_;
  mutable RTCScene lazyScene_ = nullptr;
};

namespace detail {

// One instance as traversal reads it (indexed by instance index, which is also its Embree geometry ID in the
// Tlas scene). The transforms are the ones the shaders' built-ins report.
// What traversal reads to enter an instance (worldToObject, scene, mask) is in the record's first cache line.
struct alignas(64) InstanceRecord {
  float worldToObject[3][4];
  RTCScene scene = nullptr;  // the Blas's Embree scene, where the instance is in the Tlas's hierarchy (null: direct)
  uint32_t mask = 0;         // the 8-bit instance mask
  uint32_t flags = 0;
  float objectToWorld[3][4];
  const Blas::Impl* blas = nullptr;  // null: inactive (null Blas or a transform that cannot be inverted)
  uint32_t customIndex = 0;
  uint32_t sbtOffset = 0;
};

// vkrt's own instance level: a binary hierarchy over the instances (built by Embree's rtcBuildBVH, SAH, on the
// build threads; refit by an update), traversed by traverse.cpp, which enters each instance's Blas scene with the
// ray in object space. Nodes are in depth-first order (a parent before its children), so a refit is one reverse
// pass. A child reference with kLeafRef set is a leaf: count - 1 in bits 0-2 and, in bits 3-30, the instance index
// of a leaf of one instance (no indirection: SAH leaves mostly hold one), else `first`, the leaf's instances being
// `leafItems[first .. first + count)`. leafItems lists every instance of the hierarchy, in leaf order.
inline constexpr uint32_t kLeafRef = 0x80000000u;
inline constexpr uint32_t kEmptyRef = 0xFFFFFFFFu;  // the root of a hierarchy with no instance
inline constexpr uint32_t kMaxLeafItems = 8;
inline constexpr size_t kMaxHierarchyInstances = size_t(1) << 28;
// A leaf's instances: a pointer to `count` indices (`one` holds a leaf's single instance).
inline const uint32_t* leafInstances(const std::vector<uint32_t>& leafItems, uint32_t ref, uint32_t* count,
                                     uint32_t* one) {
  *count = (ref & 7) + 1;
  *one = (ref & ~kLeafRef) >> 3;
  return *count == 1 ? one : leafItems.data() + *one;
}
struct BvhNode {
  float lower[2][3];  // the two children's bounds, world space, rounded outward
  float upper[2][3];
  uint32_t child[2];
};

// What a ray needs to know of a Tlas to decide whether it needs a filter callback at all.
struct TlasSummary {
  bool triangles = false;  // an active instance of a Blas with triangles
  bool aabbs = false;
  bool opaqueTriangles = false;    // opaque after the instance flags
  bool noOpaqueTriangles = false;  // not opaque after the instance flags
  bool facingCullable = false;     // an instance with triangles and without TRIANGLE_FACING_CULL_DISABLE
  bool small = false;              // an active instance of a small Blas (the build looks for them only then)
};

// Embree's threads run with denormals flushed to zero (inputs and results), so an extent below the smallest normal
// float is none to it. Its top-level builder (for a Tlas's instances, and to join a Blas's geometries) asserts,
// aborting the process, when a group of the nodes it sorts has no extent at all on any axis. So vkrt gives Embree no
// primitive (blas.cpp) and no instance (tlas.cpp) without extent.
inline float flushDenormal(float v) { return std::fpclassify(v) == FP_SUBNORMAL ? 0.0f : v; }

inline bool hasExtent(const float lower[3], const float upper[3]) {
  for (int k = 0; k < 3; ++k)
    if (double(flushDenormal(upper[k])) - double(flushDenormal(lower[k])) >= std::numeric_limits<float>::min())
      return true;
  return false;
}

// The bounds Embree is given for box `b` (6 floats; blas.cpp, boxBounds): the box itself, or, where it is ordered
// but has no extent (hasExtent), the box widened on every axis by a normal float's worth relative to its
// coordinates. The bounds only cull: the intersection callback tests the box as given.
inline void embreeBoxBounds(const float* b, float lower[3], float upper[3]) {
  for (int k = 0; k < 3; ++k) lower[k] = b[k], upper[k] = b[k + 3];
  if (!(lower[0] <= upper[0] && lower[1] <= upper[1] && lower[2] <= upper[2]) || hasExtent(lower, upper)) return;
  for (int k = 0; k < 3; ++k) {
    const float pad = std::max(std::fabs(lower[k]) * 0x1p-20f, std::numeric_limits<float>::min());
    lower[k] = flushDenormal(lower[k]) - pad;
    upper[k] = flushDenormal(upper[k]) + pad;
  }
}

// Embree leaves out of its hierarchy (never hit) a user primitive whose bounds are not ordered on some axis (NaN
// included: an inactive box) or reach its FLT_LARGE, 1.844e18.
inline constexpr float kEmbreeLarge = 1.844e18f;
inline bool embreeKeepsBounds(const float lower[3], const float upper[3]) {
  for (int k = 0; k < 3; ++k)
    if (!(lower[k] <= upper[k]) || !(lower[k] > -kEmbreeLarge) || !(upper[k] < kEmbreeLarge)) return false;
  return true;
}

// Embree 3 traces only rays whose origin and direction components lie within +-1.844e18 (its FLT_LARGE), in world
// space and in every instance's space; Debian's libembree3 asserts it (aborting the process). vkrt keeps every
// component it passes within 2^60 (the margin covers Embree's float rounding of the instance transform).
inline constexpr double kEmbreeRayLimit = 0x1p60;

// Whether a ray's origin and direction components (world space, or an instance's space as traversal computes them)
// are within kEmbreeRayLimit; NaN is not. A ray out of range in world space misses, as a ray Vulkan does not allow
// does (finite beyond 2^60, it is far outside any geometry Embree keeps: it drops vertices and boxes beyond
// 1.844e18); an instance whose space puts it out of range is skipped (traverseTlas).
inline bool rayInEmbreeRange(const float origin[3], const float direction[3]) {
  for (int k = 0; k < 3; ++k)
    if (!(std::fabs(origin[k]) <= float(kEmbreeRayLimit)) || !(std::fabs(direction[k]) <= float(kEmbreeRayLimit)))
      return false;
  return true;
}

// Whether a ray with `rayFlags` through a Tlas summarized by `s` needs the triangle filter callback at all
// (traverse.cpp). False is the fast path: Embree runs with no callback for triangles, as raw rtcIntersect1 does.
bool needsTriangleFilter(const TlasSummary& s, uint32_t rayFlags);

}  // namespace detail

namespace detail {

// A flattened triangle (tlas.cpp): the triangle of a small bottom level that a top level's scene holds in world
// space, as the instance, geometry and primitive traversal reports for it.
struct FlatTriangle {
  uint32_t instance, geometry, primitive;
};

// Flattened triangles sit in the top level's scene itself, not in an instance, so Embree's instance mask test does
// not apply to them: their geometries carry the instances' 8-bit mask shifted here, and a ray's Embree mask carries
// its cull mask here too unless it skips triangles (embreeRayMask).
inline constexpr unsigned kFlatMaskShift = 10;

// A ray's Embree mask: its cull mask (instances), the primitive kinds it does not skip (geometries inside
// instances), and its cull mask again for flattened triangles unless it skips triangles.
inline unsigned embreeRayMask(const Ray& ray) {
  const unsigned cull = ray.cullMask & 0xFF;
  const bool triangles = !(ray.flags & kRaySkipTriangles);
  return cull | (triangles ? kTriangleMaskBit | cull << kFlatMaskShift : 0) |
         (ray.flags & kRaySkipAabbs ? 0 : kAabbMaskBit);
}

}  // namespace detail

namespace detail {

// A Tlas's instance records (indexed by instance index): in the Tlas's own allocation when they are few
// (kInlineRecords), else an array of their own. Room only: makeRecords constructs each record.
inline constexpr size_t kInlineRecords = 2;
class RecordArray {
 public:
  RecordArray() = default;
  RecordArray(const RecordArray&) = delete;
  RecordArray& operator=(const RecordArray&) = delete;
  ~RecordArray() { release(); }
  // Room for `n` records: `inlineRoom` (room for kInlineRecords) when they fit.
  void resize(size_t n, InstanceRecord* inlineRoom) {
    release();
    data_ = n > kInlineRecords ? static_cast<InstanceRecord*>(::operator new(n * sizeof(InstanceRecord),
                                                                             std::align_val_t(alignof(InstanceRecord))))
                               : inlineRoom;
    size_ = n;
  }
  InstanceRecord& operator[](size_t i) { return data_[i]; }
  const InstanceRecord& operator[](size_t i) const { return data_[i]; }
  size_t size() const { return size_; }

 private:
  static_assert(std::is_trivially_destructible_v<InstanceRecord>);  // (never destroyed one by one)
  void release() {
    if (size_ > kInlineRecords) ::operator delete(data_, std::align_val_t(alignof(InstanceRecord)));
    data_ = nullptr;
    size_ = 0;
  }
  InstanceRecord* data_ = nullptr;
  size_t size_ = 0;  // (more than kInlineRecords: data_ is this array's own)
};

}  // namespace detail

struct Tlas::Impl {
  // What every ray reads first, together, in the structure's first cache line (TlasBlock): where the records are,
  // the summary, the hierarchy's root, the flattened triangles' scene, the nodes.
  detail::RecordArray records;  // constructed by makeRecords (tlas.cpp)
  detail::TlasSummary summary;
  bool built = false;  // false: a failed build (never traced)
  // The instance level (detail::BvhNode): the root reference, its nodes, the instance indices its leaves hold.
  uint32_t root = detail::kEmptyRef;
  // Flattened triangles: an Embree scene of world-space triangles (null when there are none), traced before the
  // hierarchy. Its geometry g holds flat[g] (one geometry per instance mask), its primitive p being flat[g][p].
  RTCScene flatScene = nullptr;
  FillArray<detail::BvhNode> nodes;
  // The records of a top level of at most kInlineRecords instances, from the next cache line on (the first record's
  // traversal half shares the first line's 128-byte pair, which the hardware fetches together): a ray through one
  // of many small top levels reaches its instance without waiting for another line.
  detail::InstanceRecord inlineRecords[detail::kInlineRecords];
  std::vector<uint32_t> leafItems;
  std::vector<std::vector<detail::FlatTriangle>> flat;
  InstanceArray instances;
  std::vector<std::shared_ptr<const Blas>> blases;  // each distinct Blas of the instances, kept alive (makeRecords)
  BuildOptions options;

  ~Impl();
};

namespace detail {

// A Tlas and its Impl in one allocation: the Tlas (no data) is an empty base, so the Impl starts at the Tlas's
// address, on a cache line of its own (InstanceRecord's alignment), and Tlas::impl() is no load.
struct TlasBlock final : Tlas {
  Tlas::Impl body;
};

}  // namespace detail

inline const Tlas::Impl& Tlas::impl() const { return static_cast<const detail::TlasBlock&>(*this).body; }

namespace detail {

// The instance, geometry and primitive of an Embree hit: its own IDs inside an instance (traverse.cpp passes the
// instance index as the context's instID when it enters a Blas scene), or the flattened triangle's (no instance:
// instID is RTC_INVALID_GEOMETRY_ID).
struct HitIds {
  uint32_t instance, geometry, primitive;
  bool flat;
};
inline HitIds hitIds(const Tlas::Impl& t, unsigned instID, unsigned geomID, unsigned primID) {
  if (instID != RTC_INVALID_GEOMETRY_ID) return {instID, geomID, primID, false};
  const FlatTriangle& f = t.flat[geomID][primID];
  return {f.instance, f.geometry, f.primitive, true};
}

}  // namespace detail

namespace detail {

// Embree's build settings for `options` (shared by Blas and Tlas builds).
struct SceneSettings {
  RTCBuildQuality sceneQuality;
  RTCBuildQuality geometryQuality;
  int sceneFlags;
};
SceneSettings sceneSettings(const BuildOptions& options, bool noDuplicateAnyHit);

// The inverse of a 3x4 affine transform (rows); false when it is singular or not finite.
bool invertAffine(const float m[3][4], float out[3][4]);

}  // namespace detail
}  // namespace vkrt::accel
