// Traversal: one Embree query per ray, with Vulkan's rules ("Ray Traversal" in the Vulkan specification) applied
// where Embree reports candidates. Per ray and per candidate nothing is allocated, locked or looked up by key:
// instance and geometry data are reached by index (Embree's instance and geometry IDs are vkrt's indices).
//
// How the rules map onto Embree:
// - Instance masks, SkipTrianglesKHR, SkipAABBsKHR: Embree ray masks (structures.hpp), no callback.
// - Triangles: Embree's watertight intersector finds candidates. A context filter callback applies facing culling,
//   opacity, opacity culling and the any-hit shader, and is installed only for rays that need it
//   (needsTriangleFilter): a ray that can meet only opaque triangles, without culling flags, runs at Embree's speed
//   (in a scene without boxes; see trace() for the interval a ray with boxes in reach needs).
// - Boxes: Embree user geometries, whose callbacks apply opacity culling and the candidate test, and run the
//   intersection shader (HitHandler::intersect), which commits through ProceduralCandidate.
// - TerminateOnFirstHitKHR: an Embree occlusion query, which stops at the first accepted candidate; the filter and
//   box callbacks record what was committed (an occlusion query reports no hit).
// - Closest hit: an Embree intersection query; Embree keeps the closest committed hit and narrows tfar with it.
//   AcceptAndTerminate (and a box commit with terminate) accepts the candidate and sets tfar to -inf, which ends
//   the traversal at every level.
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <utility>

#include "accel/structures.hpp"

namespace vkrt::accel {
namespace detail {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// A committed hit recorded by the callbacks (occlusion queries, and terminated intersection queries); its
// sbtOffset and triangle fields are filled in when traversal ends (committedHit).
using Committed = CommittedHit;

// Embree's watertight triangle test counts a ray through a shared edge, or through a vertex, as hitting every
// triangle there (it is inclusive, with a small tolerance). The spec's watertightness rules only forbid gaps, but
// an application counting any-hit calls, and NO_DUPLICATE_ANY_HIT geometry, expect one crossing of a closed
// surface to be one candidate; so do the CTS (misc.cullmask_*, misc.maxrtinvocations_*: rays through cube
// corners and face diagonals, watertightness.closedFan2.*: a closed fan whose triangles are each in an instance
// of their own). A candidate that shares a vertex position with a triangle already offered to this ray, at the
// same t up to rounding, is the same crossing and is dropped. Within one instance positions are compared exactly
// in object space (where the Blas keeps them: one transform of equal positions gives equal world positions);
// across instances in world space, where instances meet, up to the rounding of their transforms; there a triangle
// whose three vertices all match the offered one is a second surface in the same place (another instance of it),
// not the same crossing. (Exact ownership rules on the edge functions are not enough on their own: Embree's and any
// other exact test disagree near edges, and dropping the triangle Embree offered would open a gap.)
// An offered triangle is recorded by its indices and t alone: vertices are read, and moved to world space, only
// when a later candidate's t ties with it (a ray through an edge or a vertex), so a ray whose candidates lie at
// distinct t pays a few stores per candidate.
struct Offered {
  uint32_t instance, geometry, primitive;
  float t;
};

inline bool samePoint(const float a[3], const float b[3], bool exact) {
  if (exact) return a[0] == b[0] && a[1] == b[1] && a[2] == b[2];
  for (int c = 0; c < 3; ++c) {
    const float tolerance =
        4 * std::numeric_limits<float>::epsilon() * std::max({1.0f, std::fabs(a[c]), std::fabs(b[c])});
    if (!(std::fabs(a[c] - b[c]) <= tolerance)) return false;
  }
  return true;
}

// Whether the triangles share a vertex position; across instances (not exact), not when they share all three.
bool sharesVertex(const float a[3][3], const float b[3][3], bool exact) {
  int shared = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (samePoint(a[i], b[j], exact)) {
        ++shared;
        break;
      }
  return shared > 0 && (exact || shared < 3);
}

// A triangle's object-space vertices `v` in world space, through the instance's object-to-world transform.
void worldVertices(const float (*m)[4], const float v[3][3], float w[3][3]) {
  for (int k = 0; k < 3; ++k)
    for (int r = 0; r < 3; ++r) w[k][r] = m[r][0] * v[k][0] + m[r][1] * v[k][1] + m[r][2] * v[k][2] + m[r][3];
}

bool objectTriangle(const GeometryInfo& geom, uint32_t p, float v[3][3]);

struct QueryCollect;

struct TraceContext {
  RTCIntersectContext embree;  // first: Embree hands &embree back to the callbacks
  const Tlas::Impl* tlas;
  const Ray* ray;
  HitHandler* handler;
  uint32_t flags;
  bool firstHit;  // TerminateOnFirstHitKHR: an occlusion query
  // Embree's interval is the ray's [tMin, tMax], ends included (boxes in reach, and ray queries): the filter drops
  // the triangles at the ends. Otherwise it is one float inside each end, and the filter keeps a triangle's t there.
  bool closedInterval = false;
  // Over the interval one float inside: the nearest floats inside (tMin, tMax), where insideOpen puts a t the
  // kernel's rounding moved onto or past an end (set once per ray, not per candidate).
  float openLo = 0, openHi = 0;
  bool terminated = false;        // a commit ended the traversal
  QueryCollect* query = nullptr;  // a ray query's proceed(): candidates needing the shader are collected, not run
  Committed last{};               // the latest commit made by a callback
  // The latest triangle candidates offered (culling passed), for dropping the same crossing offered twice.
  static constexpr uint32_t kOffered = 8;
  Offered offered[kOffered];
  uint32_t offeredCount = 0;

  // Whether primitives `a` and `b` of `geometry` in `instance` (both in range) have a vertex index in common.
  bool sharesIndex(uint32_t a, uint32_t b, uint32_t geometry, uint32_t instance) const {
    const uint32_t* indices = tlas->records[instance].blas->info[geometry].indices;
    const uint32_t* ia = indices + 3 * size_t(a);
    const uint32_t* ib = indices + 3 * size_t(b);
    for (int i = 0; i < 3; ++i)
      if (ia[i] == ib[0] || ia[i] == ib[1] || ia[i] == ib[2]) return true;
    return false;
  }

  // Whether triangle `primitive` of `geometry` (a geometry keeping vertices) at `t` in `instance` is a crossing
  // already offered; records it otherwise.
  bool sameCrossingOffered(uint32_t instance, uint32_t geometry, uint32_t primitive, float t) {
    const float tolerance = 1e-5f * std::max(1.0f, std::fabs(t));
    const uint32_t n = std::min(offeredCount, kOffered);
    float v[3][3], w[3][3];
    bool read = false, moved = false;
    for (uint32_t k = 0; k < n; ++k) {
      const Offered& o = offered[k];
      if (!(std::fabs(o.t - t) <= tolerance)) continue;
      // Triangles of one geometry sharing a vertex index share that vertex's position (a mesh's own neighbours,
      // the common case), without reading positions.
      if (o.instance == instance && o.geometry == geometry && sharesIndex(o.primitive, primitive, geometry, instance))
        return true;
      if (!read) {
        objectTriangle(tlas->records[instance].blas->info[geometry], primitive, v);
        read = true;
      }
      const InstanceRecord& other = tlas->records[o.instance];
      float ov[3][3];
      objectTriangle(other.blas->info[o.geometry], o.primitive, ov);
      if (o.instance == instance) {
        if (sharesVertex(ov, v, true)) return true;
        continue;
      }
      if (!moved) {
        worldVertices(tlas->records[instance].objectToWorld, v, w);
        moved = true;
      }
      float ow[3][3];
      worldVertices(other.objectToWorld, ov, ow);
      if (sharesVertex(ow, w, false)) return true;
    }
    offered[offeredCount++ % kOffered] = Offered{instance, geometry, primitive, t};
    return false;
  }
};

inline TraceContext& contextOf(const RTCIntersectContext* c) {
  return *reinterpret_cast<TraceContext*>(const_cast<RTCIntersectContext*>(c));
}

void objectRay(const InstanceRecord& r, const Ray& ray, float org[3], float dir[3]) {
  const float(*m)[4] = r.worldToObject;
  for (int i = 0; i < 3; ++i) {
    org[i] = m[i][0] * ray.origin[0] + m[i][1] * ray.origin[1] + m[i][2] * ray.origin[2] + m[i][3];
    dir[i] = m[i][0] * ray.direction[0] + m[i][1] * ray.direction[1] + m[i][2] * ray.direction[2];
  }
}

// Vulkan "Ray Face Culling": a triangle is front-facing when its area in ray space is negative. In ray space the
// direction is the -z axis, so that area is a = (Ng . d) / (2 |d|) with Ng = (v1 - v0) x (v2 - v0), in the space
// the triangle was built in (object space: "because the facing is determined in object space, an instance
// transform does not change the winding", so a mirroring instance does not flip it). a < 0, i.e. the ray meets
// the side Ng points away from, is the front; with a right-handed basis that is a triangle whose vertices appear
// counterclockwise from the ray origin. TRIANGLE_FLIP_FACING reverses it; a == 0 faces neither way and is culled.
// Embree's Ng is (v1 - v0) x (v2 - v0) in the instance's object space.
// Returns +1 front, -1 back, 0 neither.
inline int facing(const float ng[3], const float objectDir[3], uint32_t instanceFlags) {
  const float a = ng[0] * objectDir[0] + ng[1] * objectDir[1] + ng[2] * objectDir[2];
  if (a == 0 || std::isnan(a)) return 0;
  const int front = a < 0 ? 1 : -1;
  return (instanceFlags & kInstanceTriangleFlipFacing) ? -front : front;
}

inline bool facingCulled(int face, uint32_t instanceFlags, uint32_t rayFlags) {
  if (face == 0) return true;  // "unconditionally culled, irrespective of ray flags and instance flags"
  if (instanceFlags & kInstanceTriangleFacingCullDisable) return false;
  return (face > 0 && (rayFlags & kRayCullFrontFacingTriangles)) ||
         (face < 0 && (rayFlags & kRayCullBackFacingTriangles));
}

inline bool opacityCulled(bool opaque, uint32_t rayFlags) {
  return (rayFlags & (opaque ? kRayCullOpaque : kRayCullNoOpaque)) != 0;
}

// The next float up and down from a non-negative t (inline: std::nextafter is a library call per ray).
inline float nextUp(float t) { return t == kInf ? t : std::bit_cast<float>(std::bit_cast<uint32_t>(t) + 1); }
inline float nextDown(float t) {
  return t == 0 ? -std::numeric_limits<float>::denorm_min() : std::bit_cast<float>(std::bit_cast<uint32_t>(t) - 1);
}

// Whether t lies strictly inside the ray's (tMin, tMax): where a triangle candidate must lie.
inline bool strictlyInside(float t, const Ray& ray) { return t > ray.tMin && t < ray.tMax; }

// A triangle's t as vkrt reports it: inside (tMin, tMax), the interval the rule admits, on every set of Embree
// kernels. Embree accepts a triangle when its t lies in [tnear, tfar], set one float inside the ray's ends (trace),
// but its kernels compute that t through different reciprocal estimates (SSE/AVX: 12 bits and a Newton step;
// AVX-512: 14 bits), so the t it then reports may differ from the one it tested by its last bits. Where that puts
// it on or past an end, it is the nearest float inside: the same crossing, never a t the rule excludes.
// `lo` and `hi` are nextUp(tMin) and nextDown(tMax) (TraceContext::openLo, openHi).
inline float insideOpen(float t, float lo, float hi) { return lo <= hi ? std::min(std::max(t, lo), hi) : t; }

// The built-ins every hit has but the object-space ray: the instance's and the primitive's indices.
void fillIds(HitInfo& h, const Tlas::Impl& t, uint32_t instance, uint32_t geometry, uint32_t primitive) {
  const InstanceRecord& r = t.records[instance];
  h.instanceIndex = instance;
  h.customIndex = r.customIndex;
  h.sbtOffset = r.sbtOffset;
  h.geometryIndex = geometry;
  h.primitiveIndex = primitive;
  h.objectToWorld = r.objectToWorld;
  h.worldToObject = r.worldToObject;
  h.blas = r.blas;
}

void offerQueryTriangle(TraceContext& ctx, const HitIds& ids, const RTCHit& hit, float t, uint32_t hitKind,
                        const float v[3][3]);

// The object-space vertices of primitive `p` of `geom` (zeros for an index out of range); false when the geometry
// keeps none or `p` is out of range.
bool objectTriangle(const GeometryInfo& geom, uint32_t p, float v[3][3]) {
  if (!geom.vertices || p >= geom.primitiveCount) return false;
  const uint32_t* index = geom.indices + 3 * size_t(p);
  for (int k = 0; k < 3; ++k)
    for (int c = 0; c < 3; ++c) v[k][c] = index[k] < geom.vertexCount ? geom.vertices[3 * size_t(index[k]) + c] : 0;
  return true;
}

// A triangle's geometric normal as Embree reports it for an instanced one: (v1 - v0) x (v2 - v0) in object space.
// A flattened triangle's (tlas.cpp) is computed here from its object-space vertices, since Embree's is in world
// space, where a mirroring instance would turn it around.
void objectNormal(const float v[3][3], float ng[3]) {
  const float e1[3] = {v[1][0] - v[0][0], v[1][1] - v[0][1], v[1][2] - v[0][2]};
  const float e2[3] = {v[2][0] - v[0][0], v[2][1] - v[0][1], v[2][2] - v[0][2]};
  ng[0] = e1[1] * e2[2] - e1[2] * e2[1];
  ng[1] = e1[2] * e2[0] - e1[0] * e2[2];
  ng[2] = e1[0] * e2[1] - e1[1] * e2[0];
}
void offerQueryBox(TraceContext& ctx, uint32_t instance, uint32_t geometry, uint32_t primitive, float entry,
                   bool opaque);

// The context filter: every triangle candidate of a ray that needs one (see needsTriangleFilter). Embree has set
// the ray's tfar to the candidate's t; accepting keeps it (Embree then narrows the traversal to it), rejecting
// restores the previous one.
void triangleFilter(const RTCFilterFunctionNArguments* args) {
  if (!args->valid[0]) return;
  TraceContext& ctx = contextOf(args->context);
  RTCRay& ray = *reinterpret_cast<RTCRay*>(args->ray);  // N == 1: rtcIntersect1/rtcOccluded1
  const RTCHit& hit = *reinterpret_cast<const RTCHit*>(args->hit);
  const HitIds ids = hitIds(*ctx.tlas, hit.instID[0], hit.geomID, hit.primID);
  const InstanceRecord& inst = ctx.tlas->records[ids.instance];
  const GeometryInfo& geom = inst.blas->info[ids.geometry];
  const bool hasVertices = geom.vertices && ids.primitive < geom.primitiveCount;

  // The normal and the ray in the instance's object space, where facing is decided: inside an instance Embree's
  // own (traverseTlas put the ray there, by objectRay's arithmetic); a flattened triangle's Embree traced in world
  // space, so they are computed.
  float ng[3] = {hit.Ng_x, hit.Ng_y, hit.Ng_z};
  float dir[3] = {ray.dir_x, ray.dir_y, ray.dir_z};
  if (ids.flat) {
    float v[3][3];
    objectTriangle(geom, ids.primitive, v);
    objectNormal(v, ng);
    float org[3];
    objectRay(inst, *ctx.ray, org, dir);
  }
  const int face = facing(ng, dir, inst.flags);
  const bool opaque = effectiveOpaque(geom.flags, inst.flags, ctx.flags);
  if (ctx.terminated || facingCulled(face, inst.flags, ctx.flags) || opacityCulled(opaque, ctx.flags)) {
    args->valid[0] = 0;
    return;
  }
  // Over [tMin, tMax] with both ends (boxes need them), triangles need tMin < t < tMax. Over the interval one float
  // inside, a t the kernel's rounding put on an end is the nearest float inside (insideOpen).
  if (!ctx.closedInterval) {
    ray.tfar = insideOpen(ray.tfar, ctx.openLo, ctx.openHi);
  } else if (!strictlyInside(ray.tfar, *ctx.ray)) {
    args->valid[0] = 0;
    return;
  }
  const uint32_t hitKind = face > 0 ? kHitKindFrontFacingTriangle : kHitKindBackFacingTriangle;
  if (ctx.query && !opaque) {  // a ray query's candidate: collected for the shader, never accepted here
    if (hasVertices) {
      float v[3][3];
      objectTriangle(geom, ids.primitive, v);
      offerQueryTriangle(ctx, ids, hit, ray.tfar, hitKind, v);
    }
    args->valid[0] = 0;
    return;
  }
  if (hasVertices && ctx.sameCrossingOffered(ids.instance, ids.geometry, ids.primitive, ray.tfar)) {
    args->valid[0] = 0;
    return;
  }
  // (A ray query's TerminateOnFirstHit runs as an intersection query: its first opaque commit ends it.)
  bool terminate = ctx.firstHit || (ctx.query && (ctx.flags & kRayTerminateOnFirstHit));
  if (!opaque) {
    // A non-opaque candidate goes to the any-hit shader ("Triangle and Generated Intersection Candidates"), with
    // the object-space ray: Embree's inside an instance, as above.
    HitInfo info;
    fillIds(info, *ctx.tlas, ids.instance, ids.geometry, ids.primitive);
    if (ids.flat) {
      objectRay(inst, *ctx.ray, info.objectRayOrigin, info.objectRayDirection);
    } else {
      info.objectRayOrigin[0] = ray.org_x, info.objectRayOrigin[1] = ray.org_y, info.objectRayOrigin[2] = ray.org_z;
      info.objectRayDirection[0] = dir[0], info.objectRayDirection[1] = dir[1], info.objectRayDirection[2] = dir[2];
    }
    info.t = ray.tfar;
    info.hitKind = hitKind;
    info.triangle = true;
    info.barycentrics[0] = hit.u;
    info.barycentrics[1] = hit.v;
    const AnyHitResult result = ctx.handler->anyHit(info);
    if (result == AnyHitResult::Ignore) {
      args->valid[0] = 0;
      return;
    }
    terminate |= result == AnyHitResult::AcceptAndTerminate;
  }
  Committed& c = ctx.last;
  c.t = ray.tfar;
  c.instance = ids.instance;
  c.geometry = ids.geometry;
  c.primitive = ids.primitive;
  c.hitKind = hitKind;
  c.u = hit.u;
  c.v = hit.v;
  c.ng[0] = ng[0], c.ng[1] = ng[1], c.ng[2] = ng[2];
  if (terminate) {
    ctx.terminated = true;
    if (!ctx.firstHit) ray.tfar = -kInf;  // (an occlusion query ends on acceptance by itself)
  }
}

// The filter of a ray over the closed interval that needs no other (it can meet only opaque triangles, and has no
// culling flags): the triangle candidates at tMin or tMax, which Embree's inclusive test accepts, are not
// candidates ("tMin < t < tMax"). Without it Embree would commit a triangle at tMin (a ray starting on a surface)
// and narrow the traversal to it, hiding everything behind.
void triangleEndsFilter(const RTCFilterFunctionNArguments* args) {
  if (!args->valid[0]) return;
  const TraceContext& ctx = contextOf(args->context);
  const float t = reinterpret_cast<const RTCRay*>(args->ray)->tfar;  // N == 1
  if (!strictlyInside(t, *ctx.ray)) args->valid[0] = 0;
}

// The candidate test for a box: Vulkan's AABB candidates satisfy tmin <= t <= tmax, ends included, against the
// closest hit so far ("Ray Intersection Candidate Determination"). A ray starting inside the box meets it.
bool boxCandidate(const float* b, const float org[3], const float dir[3], float tMin, float tMax,
                  float* entry = nullptr) {
  float lo = tMin, hi = tMax;
  for (int a = 0; a < 3; ++a) {
    if (dir[a] == 0) {
      if (org[a] < b[a] || org[a] > b[a + 3]) return false;
      continue;
    }
    float t0 = (b[a] - org[a]) / dir[a];
    float t1 = (b[a + 3] - org[a]) / dir[a];
    if (t0 > t1) std::swap(t0, t1);
    lo = std::max(lo, t0);
    hi = std::min(hi, t1);
  }
  if (entry) *entry = lo;
  return lo <= hi;
}

// The intersection shader's view of one box candidate.
class BoxCandidate final : public ProceduralCandidate {
 public:
  BoxCandidate(TraceContext& ctx, RTCRay& ray, RTCHit* hit, bool opaque, uint32_t instance, uint32_t geometry,
               uint32_t primitive)
      : ctx_(ctx), ray_(ray), hit_(hit), opaque_(opaque) {
    // Boxes are always inside an instance (never flattened): Embree's ray is the object-space one, as traverseTlas
    // computed it by objectRay's arithmetic.
    fillIds(info_, *ctx.tlas, instance, geometry, primitive);
    info_.objectRayOrigin[0] = ray.org_x, info_.objectRayOrigin[1] = ray.org_y, info_.objectRayOrigin[2] = ray.org_z;
    info_.objectRayDirection[0] = ray.dir_x, info_.objectRayDirection[1] = ray.dir_y;
    info_.objectRayDirection[2] = ray.dir_z;
    info_.triangle = false;
  }

  const HitInfo& info() const override { return info_; }
  float tMin() const override { return ctx_.ray->tMin; }
  float tMax() const override {
    // Before any commit the ray's tMax; after one Embree's tfar, the closest t.
    if (ctx_.terminated) return -kInf;
    return hit_ && hit_->geomID != RTC_INVALID_GEOMETRY_ID ? ray_.tfar : ctx_.ray->tMax;
  }
  bool opaque() const override { return opaque_; }

  void commit(float t, uint32_t hitKind, bool terminate) override {
    if (ctx_.terminated || !(t >= tMin() && t <= tMax())) return;  // outside the current interval: no hit
    Committed& c = ctx_.last;
    c = Committed{};
    c.t = t;
    c.instance = info_.instanceIndex;
    c.geometry = info_.geometryIndex;
    c.primitive = info_.primitiveIndex;
    c.hitKind = hitKind;
    if (hit_) {  // an intersection query: Embree's hit becomes this one, and tfar narrows to it
      ray_.tfar = t;
      hit_->geomID = c.geometry;
      hit_->primID = c.primitive;
      hit_->instID[0] = c.instance;
      hit_->u = hit_->v = 0;
      hit_->Ng_x = hit_->Ng_y = hit_->Ng_z = 0;
    }
    if (terminate || ctx_.firstHit) {
      ctx_.terminated = true;
      ray_.tfar = -kInf;  // ends the traversal (and is how an occlusion callback reports a hit)
    }
  }

 private:
  TraceContext& ctx_;
  RTCRay& ray_;
  RTCHit* hit_;  // null in an occlusion query
  bool opaque_;
  HitInfo info_;
};

void runBox(const RTCIntersectContext* context, const void* userPtr, unsigned geomID, unsigned primID, RTCRay& ray,
            RTCHit* hit) {
  TraceContext& ctx = contextOf(context);
  if (ctx.terminated) return;
  const uint32_t instance = context->instID[0];
  const InstanceRecord& inst = ctx.tlas->records[instance];
  const auto& geom = *static_cast<const GeometryInfo*>(userPtr);
  const float* box = geom.boxes + 6 * size_t(primID);
  if (std::isnan(box[0])) return;  // inactive (Embree leaves it out of the hierarchy already)
  const bool opaque = effectiveOpaque(geom.flags, inst.flags, ctx.flags);
  if (opacityCulled(opaque, ctx.flags)) return;
  BoxCandidate candidate(ctx, ray, hit, opaque, instance, geomID, primID);
  const HitInfo& info = candidate.info();
  float entry = 0;
  if (!boxCandidate(box, info.objectRayOrigin, info.objectRayDirection, ctx.ray->tMin, candidate.tMax(), &entry))
    return;
  if (ctx.query) {
    offerQueryBox(ctx, instance, geomID, primID, entry, opaque);
    return;
  }
  ctx.handler->intersect(candidate);
}

// A direct Blas (small, boxes only: no Embree scene) inside its instance: each box Embree would keep goes to runBox,
// which tests it exactly as Embree's callback does, unless the ray skips boxes (its Embree mask), until the
// traversal ends. (Embree would call it only for boxes its hierarchy's conservative tests admit; runBox's own test
// decides either way.)
void offerDirectBoxes(const Blas::Impl& blas, TraceContext& ctx, RTCRay& ray, RTCHit* hit) {
  if (!(ray.mask & kAabbMaskBit)) return;
  for (uint32_t k = 0; k < blas.directCount; ++k) {
    const DirectBox& d = blas.directBoxes[k];
    runBox(&ctx.embree, &blas.info[d.geometry], d.geometry, d.primitive, ray, hit);
    if (!(ray.tfar >= ray.tnear) || ctx.terminated) return;
  }
}

// Whether `ray` is traced through `t` at all: Vulkan requires finite origin and direction and 0 <= tMin <= tMax;
// anything else misses, as does a ray with an empty cull mask, an unbuilt structure, or a ray beyond what Embree can
// trace. (rayInEmbreeRange is false for an infinite or NaN component: it is the finiteness test too.)
inline bool traced(const Tlas::Impl& t, const Ray& ray) {
  return (ray.cullMask & 0xFF) && t.built && ray.tMin >= 0 && ray.tMin <= ray.tMax &&
         rayInEmbreeRange(ray.origin, ray.direction);
}

// The ray against vkrt's instance level (structures.hpp, BvhNode): the flattened triangles' scene in world space,
// then the hierarchy, front to back, entering each instance the ray's cull mask admits: the ray goes into the
// instance's object space (Embree's own instances do the same) and Embree traces it through the Blas scene with the
// instance index as the context's instID, which Embree writes into the hits and the callbacks read. `rh` is one
// Embree ray-hit for the whole traversal: tfar narrows to the closest hit found so far, in every instance (t is
// the same in object space: the direction is transformed, not normalized), and -inf ends the traversal (a
// terminating commit, or an occlusion query's hit). Nothing is allocated: the stack is bounded by the builder's
// depth.
template <bool kOccluded>
void traverseTlas(const Tlas::Impl& t, TraceContext& ctx, RTCRayHit& rh) {
  if (t.flatScene) {
    if constexpr (kOccluded)
      rtcOccluded1(t.flatScene, &ctx.embree, &rh.ray);
    else
      rtcIntersect1(t.flatScene, &ctx.embree, &rh);
    if (!(rh.ray.tfar >= rh.ray.tnear) || ctx.terminated) return;
  }
  if (t.root == kEmptyRef) return;
  const float org[3] = {rh.ray.org_x, rh.ray.org_y, rh.ray.org_z};
  const float dir[3] = {rh.ray.dir_x, rh.ray.dir_y, rh.ray.dir_z};
  // The reciprocal direction for the hierarchy's box tests, computed at the first interior node (a top level of
  // one instance, a leaf at the root, needs none).
  float inv[3] = {0, 0, 0};
  bool invSet = false;
  const uint32_t cull = ctx.ray->cullMask & 0xFF;
  // Pbrt's robust slab test: the far distances grow by 2 gamma(3), so that rounding never drops a box the ray
  // meets (the bounds are rounded outward already).
  constexpr float kFarScale = 1.0f + 2 * (3 * 0x1p-24f) / (1 - 3 * 0x1p-24f);
  auto enter = [&](const float lower[3], const float upper[3], float* entry) {
    float lo = rh.ray.tnear, hi = rh.ray.tfar;
    for (int a = 0; a < 3; ++a) {
      float t0 = (lower[a] - org[a]) * inv[a], t1 = (upper[a] - org[a]) * inv[a];
      if (t0 > t1) std::swap(t0, t1);
      t1 *= kFarScale;
      // (A NaN, from a zero direction component at a bound, leaves the interval as it is.)
      lo = t0 > lo ? t0 : lo;
      hi = t1 < hi ? t1 : hi;
    }
    *entry = lo;
    return lo <= hi;
  };
  uint32_t stack[128];
  uint32_t depth = 0;
  uint32_t ref = t.root;
  for (;;) {
    if (ref & kLeafRef) {
      uint32_t count, one;
      const uint32_t* items = leafInstances(t.leafItems, ref, &count, &one);
      for (uint32_t k = 0; k < count; ++k) {
        const uint32_t i = items[k];
        const InstanceRecord& r = t.records[i];
        if (!(r.mask & cull)) continue;
        const float(*m)[4] = r.worldToObject;
        rh.ray.org_x = m[0][0] * org[0] + m[0][1] * org[1] + m[0][2] * org[2] + m[0][3];
        rh.ray.org_y = m[1][0] * org[0] + m[1][1] * org[1] + m[1][2] * org[2] + m[1][3];
        rh.ray.org_z = m[2][0] * org[0] + m[2][1] * org[1] + m[2][2] * org[2] + m[2][3];
        rh.ray.dir_x = m[0][0] * dir[0] + m[0][1] * dir[1] + m[0][2] * dir[2];
        rh.ray.dir_y = m[1][0] * dir[0] + m[1][1] * dir[1] + m[1][2] * dir[2];
        rh.ray.dir_z = m[2][0] * dir[0] + m[2][1] * dir[1] + m[2][2] * dir[2];
        // A ray beyond Embree's range in this instance's space cannot meet its geometry (Embree keeps none that
        // far): the instance is skipped, the others are traced.
        const float o[3] = {rh.ray.org_x, rh.ray.org_y, rh.ray.org_z},
                    d[3] = {rh.ray.dir_x, rh.ray.dir_y, rh.ray.dir_z};
        if (!rayInEmbreeRange(o, d)) continue;
        ctx.embree.instID[0] = i;
        if (!r.scene)
          offerDirectBoxes(*r.blas, ctx, rh.ray, kOccluded ? nullptr : &rh.hit);
        else if constexpr (kOccluded)
          rtcOccluded1(r.scene, &ctx.embree, &rh.ray);
        else
          rtcIntersect1(r.scene, &ctx.embree, &rh);
        if (!(rh.ray.tfar >= rh.ray.tnear) || ctx.terminated) {
          depth = 0;
          break;
        }
      }
      if (!depth) break;
      ref = stack[--depth];
      continue;
    }
    const BvhNode& node = t.nodes[ref];
    if (!invSet) {
      for (int a = 0; a < 3; ++a) inv[a] = 1.0f / dir[a];
      invSet = true;
    }
    float near0, near1;
    const bool hit0 = enter(node.lower[0], node.upper[0], &near0);
    const bool hit1 = enter(node.lower[1], node.upper[1], &near1);
    if (hit0 && hit1) {
      const bool firstNear = near0 <= near1;
      stack[depth++] = node.child[firstNear ? 1 : 0];
      ref = node.child[firstNear ? 0 : 1];
    } else if (hit0 || hit1) {
      ref = node.child[hit0 ? 0 : 1];
    } else {
      if (!depth) break;
      ref = stack[--depth];
    }
  }
  rh.ray.org_x = org[0], rh.ray.org_y = org[1], rh.ray.org_z = org[2];
  rh.ray.dir_x = dir[0], rh.ray.dir_y = dir[1], rh.ray.dir_z = dir[2];
  ctx.embree.instID[0] = RTC_INVALID_GEOMETRY_ID;
}

// The hit Embree committed (its instance, geometry and primitive IDs, t, barycentrics, geometric normal) as a
// CommittedHit: a box's hit kind is `boxHitKind` (the latest commit by a box callback is the one Embree kept if it is
// a box), a triangle's t inside the open interval (openLo, openHi).
void committedOf(const Tlas::Impl& t, unsigned instID, unsigned geomID, unsigned primID, float tfar, float u, float v,
                 std::array<float, 3> ng, uint32_t boxHitKind, float openLo, float openHi, CommittedHit* hit) {
  const HitIds ids = hitIds(t, instID, geomID, primID);
  const InstanceRecord& r = t.records[ids.instance];
  const GeometryInfo& geom = r.blas->info[ids.geometry];
  CommittedHit& c = *hit;
  c.t = tfar;
  c.instance = ids.instance;
  c.geometry = ids.geometry;
  c.primitive = ids.primitive;
  c.sbtOffset = r.sbtOffset;
  c.u = u;
  c.v = v;
  c.ng[0] = ng[0], c.ng[1] = ng[1], c.ng[2] = ng[2];
  float vs[3][3];
  if (ids.flat && objectTriangle(geom, c.primitive, vs)) objectNormal(vs, c.ng);
  c.triangle = geom.kind == Geometry::Triangles;
  c.hitKind = c.triangle ? 0 : boxHitKind;
  if (c.triangle) c.t = insideOpen(c.t, openLo, openHi);
}

// The rest of a committed hit's built-ins (hitInfo).
void report(const Tlas::Impl& t, const Ray& ray, const Committed& c, HitInfo* hit) {
  // (Every field is assigned: no zeroing first, which compilers make a `rep stos` per hit.)
  HitInfo& h = *hit;
  fillIds(h, t, c.instance, c.geometry, c.primitive);
  const InstanceRecord& inst = t.records[c.instance];
  objectRay(inst, ray, h.objectRayOrigin, h.objectRayDirection);
  h.t = c.t;
  h.triangle = c.triangle;
  h.hitKind = c.hitKind;
  h.barycentrics[0] = c.triangle ? c.u : 0;
  h.barycentrics[1] = c.triangle ? c.v : 0;
  if (h.triangle && !h.hitKind) {
    // A hit Embree committed without the filter: its facing, by the same rule.
    const bool front = facing(c.ng, h.objectRayDirection, inst.flags) > 0;
    h.hitKind = front ? kHitKindFrontFacingTriangle : kHitKindBackFacingTriangle;
  }
}

// A commit the callbacks kept, with what selects its hit group.
void finishCommitted(const Tlas::Impl& t, const Committed& from, CommittedHit* hit) {
  *hit = from;
  const InstanceRecord& r = t.records[from.instance];
  hit->sbtOffset = r.sbtOffset;
  hit->triangle = r.blas->info[from.geometry].kind == Geometry::Triangles;
}

}  // namespace

bool needsTriangleFilter(const TlasSummary& s, uint32_t f) {
  if (!s.triangles || (f & kRaySkipTriangles)) return false;
  if (f & kRayTerminateOnFirstHit) return true;  // the occlusion query reports no hit: the filter records it
  if ((f & (kRayCullBackFacingTriangles | kRayCullFrontFacingTriangles)) && s.facingCullable) return true;
  const bool opaqueSeen = (f & kRayOpaque) || (!(f & kRayNoOpaque) && s.opaqueTriangles);
  const bool noOpaqueSeen = !(f & kRayOpaque) && ((f & kRayNoOpaque) || s.noOpaqueTriangles);
  return noOpaqueSeen || ((f & kRayCullOpaque) && opaqueSeen);
}

void boxIntersect(const RTCIntersectFunctionNArguments* args) {
  if (!args->valid[0]) return;
  auto* rayhit = reinterpret_cast<RTCRayHit*>(args->rayhit);  // N == 1
  runBox(args->context, args->geometryUserPtr, args->geomID, args->primID, rayhit->ray, &rayhit->hit);
}

void boxOccluded(const RTCOccludedFunctionNArguments* args) {
  if (!args->valid[0]) return;
  runBox(args->context, args->geometryUserPtr, args->geomID, args->primID, *reinterpret_cast<RTCRay*>(args->ray),
         nullptr);
}

}  // namespace detail

bool trace(const Tlas& tlas, const Ray& ray, HitHandler& handler, CommittedHit* hit) {
  using namespace detail;
  const Tlas::Impl& t = tlas.impl();
  if (!traced(t, ray)) return false;

  TraceContext ctx;
  rtcInitIntersectContext(&ctx.embree);
  ctx.tlas = &t;
  ctx.ray = &ray;
  ctx.handler = &handler;
  ctx.flags = ray.flags;
  ctx.firstHit = (ray.flags & kRayTerminateOnFirstHit) != 0;
  // The filter records an occlusion query's commit (needsTriangleFilter); where nobody reads it, Embree's answer
  // (tfar -inf where it accepted a triangle) or a box's commit is all the caller needs.
  const uint32_t filterFlags = hit ? ray.flags : ray.flags & ~kRayTerminateOnFirstHit;
  if (needsTriangleFilter(t.summary, filterFlags)) ctx.embree.filter = triangleFilter;
  // Triangle candidates need tMin < t < tMax, box candidates tMin <= t <= tMax ("Ray Intersection Candidate
  // Determination"; a ray starting inside a box with tMin == tMax meets it), and Embree has one interval per ray,
  // which its triangle test and its hierarchy's bounds test take as inclusive. Where the ray can meet boxes,
  // Embree gets [tMin, tMax] (the box callbacks test the ends exactly) and a filter drops the triangles at the ends:
  // triangleFilter, or where the ray needs none, triangleEndsFilter, a callback per triangle candidate that only
  // such rays pay. Otherwise (only triangles in reach) each end moves one float inward, and opaque triangles need
  // no callback at all. (One float inside would not do for boxes: the interval is empty when tMin == tMax, and
  // Embree's hierarchy drops a box the ray leaves exactly at tMin = 0 or enters exactly at tMax.)
  const bool boxesInReach = t.summary.aabbs && !(ray.flags & kRaySkipAabbs);
  if (boxesInReach) {
    ctx.closedInterval = true;
    if (!ctx.embree.filter && t.summary.triangles && !(ray.flags & kRaySkipTriangles))
      ctx.embree.filter = triangleEndsFilter;
  }

  RTCRayHit rh;
  rh.ray.org_x = ray.origin[0];
  rh.ray.org_y = ray.origin[1];
  rh.ray.org_z = ray.origin[2];
  rh.ray.dir_x = ray.direction[0];
  rh.ray.dir_y = ray.direction[1];
  rh.ray.dir_z = ray.direction[2];
  // Embree's watertight test accepts tnear <= t <= tfar: without boxes each end moves one float inward (FLT_MIN
  // at least: Embree flushes denormals).
  ctx.openLo = nextUp(ray.tMin);
  ctx.openHi = nextDown(ray.tMax);
  rh.ray.tnear = ctx.closedInterval ? ray.tMin : std::max(ctx.openLo, std::numeric_limits<float>::min());
  rh.ray.tfar = ctx.closedInterval ? ray.tMax : ctx.openHi;
  rh.ray.time = 0;
  rh.ray.mask = embreeRayMask(ray);
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;

  if (ctx.firstHit) {
    traverseTlas<true>(t, ctx, rh);
    if (!hit) return ctx.terminated || rh.ray.tfar == -kInf;
    if (!ctx.terminated) return false;
    finishCommitted(t, ctx.last, hit);
    return true;
  }
  traverseTlas<false>(t, ctx, rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
  if (!hit) return true;
  if (ctx.terminated) {
    finishCommitted(t, ctx.last, hit);  // tfar is -inf now; the callbacks kept the commit
    return true;
  }
  committedOf(t, rh.hit.instID[0], rh.hit.geomID, rh.hit.primID, rh.ray.tfar, rh.hit.u, rh.hit.v,
              {rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z}, ctx.last.hitKind, ctx.openLo, ctx.openHi, hit);
  return true;
}

namespace detail {
namespace {

// The one instance whose Embree scene a packet goes through, where the top level is a single leaf of one instance with
// a scene and nothing flattened; -1 otherwise.
int64_t packetInstance(const Tlas::Impl& t) {
  if (t.flatScene || t.root == kEmptyRef || !(t.root & kLeafRef) || (t.root & 7) != 0) return -1;
  uint32_t count, one;
  const uint32_t* items = leafInstances(t.leafItems, t.root, &count, &one);
  return count == 1 && t.records[items[0]].scene ? int64_t(items[0]) : -1;
}

}  // namespace
}  // namespace detail

bool packetTraceable(const Tlas& tlas, const Ray& ray) {
  using namespace detail;
  const Tlas::Impl& t = tlas.impl();
  const bool shape = (t.flatScene && t.root == kEmptyRef) || packetInstance(t) >= 0;
  return shape && !(t.summary.aabbs && !(ray.flags & kRaySkipAabbs)) && !needsTriangleFilter(t.summary, ray.flags) &&
         !(ray.flags & kRayTerminateOnFirstHit);
}

bool coherentDirections(const float* dx, const float* dy, const float* dz, const int* valid) {
  constexpr float kCoherentCos2 = 0.98f;  // cos^2 of about 8 degrees
  uint32_t first = 0;
  while (first < kPacketRays && !valid[first]) ++first;
  if (first == kPacketRays) return false;
  // Every lane tested, four at a time (the first lane passes its own test unless its direction is zero: then no
  // packet is coherent).
  using F4 = float __attribute__((vector_size(16)));
  using I4 = int32_t __attribute__((vector_size(16)));
  const float ax = dx[first], ay = dy[first], az = dz[first];
  const float aa = ax * ax + ay * ay + az * az;
  I4 all = I4{} - 1;
  for (uint32_t i = 0; i < kPacketRays; i += 4) {
    F4 x, y, z;
    I4 v;
    std::memcpy(&x, dx + i, 16), std::memcpy(&y, dy + i, 16), std::memcpy(&z, dz + i, 16),
        std::memcpy(&v, valid + i, 16);
    const F4 dot = ax * x + ay * y + az * z;
    const F4 bb = x * x + y * y + z * z;
    all &= ((dot > 0) & (dot * dot >= kCoherentCos2 * aa * bb)) | (v == 0);
  }
  return (all[0] & all[1] & all[2] & all[3]) != 0;
}

uint32_t tracePacket(const Tlas& tlas, const Ray* rays, uint32_t mask, CommittedHit* hits) {
  using namespace detail;
  const Tlas::Impl& t = tlas.impl();
  // A flattened top level's one scene, or its one instance's scene (the rays in the instance's object space, Embree
  // told the instance's index, as traverseTlas does).
  const int64_t instance = t.flatScene ? -1 : packetInstance(t);
  const InstanceRecord* record = instance >= 0 ? &t.records[size_t(instance)] : nullptr;
  alignas(64) int valid[kPacketRays];
  alignas(64) RTCRayHit16 rh;
  float openLo[kPacketRays], openHi[kPacketRays];
  bool any = false;
  // Each ray as trace() sets it up: one float inside each end of [tMin, tMax] (no box in reach); a ray trace() would
  // not trace (traced()), or one beyond Embree's range in the instance's space, is left out (a miss).
  for (uint32_t i = 0; i < kPacketRays; ++i) {
    const Ray& ray = rays[i];
    valid[i] = 0;
    rh.ray.tnear[i] = 0;
    rh.ray.tfar[i] = -kInf;
    rh.ray.org_x[i] = rh.ray.org_y[i] = rh.ray.org_z[i] = 0;
    rh.ray.dir_x[i] = rh.ray.dir_y[i] = rh.ray.dir_z[i] = 1;
    rh.ray.time[i] = 0;
    rh.ray.mask[i] = 0;
    rh.ray.id[i] = i;
    rh.ray.flags[i] = 0;
    rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
    if (!((mask >> i) & 1) || !traced(t, ray)) continue;
    float o[3] = {ray.origin[0], ray.origin[1], ray.origin[2]};
    float d[3] = {ray.direction[0], ray.direction[1], ray.direction[2]};
    if (record) {
      if (!(record->mask & ray.cullMask & 0xFF)) continue;
      objectRay(*record, ray, o, d);
      if (!rayInEmbreeRange(o, d)) continue;
    }
    valid[i] = -1;
    any = true;
    rh.ray.org_x[i] = o[0];
    rh.ray.org_y[i] = o[1];
    rh.ray.org_z[i] = o[2];
    rh.ray.dir_x[i] = d[0];
    rh.ray.dir_y[i] = d[1];
    rh.ray.dir_z[i] = d[2];
    openLo[i] = nextUp(ray.tMin);
    openHi[i] = nextDown(ray.tMax);
    rh.ray.tnear[i] = std::max(openLo[i], std::numeric_limits<float>::min());
    rh.ray.tfar[i] = openHi[i];
    rh.ray.mask[i] = embreeRayMask(ray);
  }
  if (!any) return 0;
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  // Embree's coherent packet traversal (one frustum for the packet) where the rays run side by side: twice the rays per
  // second of the incoherent one for a camera's rays, a third fewer for a path's scattered bounces.
  if (coherentDirections(rh.ray.dir_x, rh.ray.dir_y, rh.ray.dir_z, valid))
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  if (record) context.instID[0] = uint32_t(instance);
  rtcIntersect16(valid, record ? record->scene : t.flatScene, &context, &rh);
  uint32_t found = 0;
  for (uint32_t i = 0; i < kPacketRays; ++i) {
    if (!valid[i] || rh.hit.geomID[i] == RTC_INVALID_GEOMETRY_ID) continue;
    committedOf(t, rh.hit.instID[0][i], rh.hit.geomID[i], rh.hit.primID[i], rh.ray.tfar[i], rh.hit.u[i], rh.hit.v[i],
                {rh.hit.Ng_x[i], rh.hit.Ng_y[i], rh.hit.Ng_z[i]}, 0, openLo[i], openHi[i], &hits[i]);
    found |= 1u << i;
  }
  return found;
}

void hitInfo(const Tlas& tlas, const Ray& ray, const CommittedHit& hit, HitInfo* out) {
  detail::report(tlas.impl(), ray, hit, out);
}

bool trace(const Tlas& tlas, const Ray& ray, HitHandler& handler, HitInfo* hit) {
  CommittedHit c;
  if (!trace(tlas, ray, handler, hit ? &c : nullptr)) return false;
  if (hit) hitInfo(tlas, ray, c, hit);
  return true;
}

// ------------------------------------------------------------------------------------------------ ray queries
//
// Vulkan "Ray Queries": OpRayQueryProceedKHR returns each candidate that needs the shader (non-opaque triangles,
// boxes), the shader confirms, generates or ignores it, and opaque triangles are committed by the traversal. The
// specification leaves the order of candidates to the implementation. Embree's traversal is callback-driven and
// cannot be suspended, so each proceed() is one complete traversal over [tMin, committed t] that
//  - commits opaque triangles as a traced ray does (the filter accepts them; Embree keeps the closest), and
//  - collects, without running anything, the candidates that need the shader and returns the smallest of them by
//    the key (t, box before triangle, instance, geometry, primitive) above the key of the candidate returned last
//    (a box's t is where the ray enters it).
// Candidate keys do not depend on the interval, and the interval only shrinks, so every candidate is returned at
// most once, in increasing key order, and none is skipped unless a commit put it out of reach. A proceed() costs
// one traversal; the state is the RayQuery (no allocation). Triangles met twice at a shared edge or vertex (see
// sameCrossingOffered) are returned once: a candidate of the same crossing as one returned before is dropped.
namespace detail {
namespace {

using Key = RayQuery::Key;

bool keyLess(const Key& a, const Key& b) {
  if (a.t != b.t) return a.t < b.t;
  if (a.kind != b.kind) return a.kind < b.kind;
  if (a.instance != b.instance) return a.instance < b.instance;
  if (a.geometry != b.geometry) return a.geometry < b.geometry;
  return a.primitive < b.primitive;
}

struct QueryCollect {
  RayQuery* q = nullptr;
  bool found = false;
  Key best{};
  QueryHit hit;
  float v[3][3] = {};  // the best triangle's vertices in world space (becomes a QueryCrossing)
};

// Whether `key` is a candidate this traversal should consider: above the last one returned, below the best so far.
bool better(const QueryCollect& c, const Key& key) {
  if (c.q->returned && !keyLess(c.q->last, key)) return false;
  return !c.found || keyLess(key, c.best);
}

void offerQueryTriangle(TraceContext& ctx, const HitIds& ids, const RTCHit& hit, float t, uint32_t hitKind,
                        const float v[3][3]) {
  QueryCollect& c = *ctx.query;
  const Key key{t, 1, ids.instance, ids.geometry, ids.primitive};
  if (!better(c, key)) return;
  const RayQuery& q = *c.q;
  const float tolerance = 1e-5f * std::max(1.0f, std::fabs(t));
  float w[3][3];  // compared in world space, as a traced ray's candidates are (TraceContext::sameCrossingOffered)
  worldVertices(ctx.tlas->records[key.instance].objectToWorld, v, w);
  for (uint32_t k = 0; k < std::min(q.crossingCount, RayQuery::kCrossings); ++k) {
    const QueryCrossing& o = q.crossings[k];
    if (std::fabs(o.t - t) <= tolerance && sharesVertex(o.v, w, o.instance == key.instance)) return;
  }
  c.found = true;
  c.best = key;
  c.hit = QueryHit{};
  c.hit.t = t;
  c.hit.instance = key.instance;
  c.hit.geometry = key.geometry;
  c.hit.primitive = key.primitive;
  c.hit.hitKind = hitKind;
  c.hit.type = 1;
  c.hit.barycentrics[0] = hit.u;
  c.hit.barycentrics[1] = hit.v;
  std::memcpy(c.v, w, sizeof c.v);
}

void offerQueryBox(TraceContext& ctx, uint32_t instance, uint32_t geometry, uint32_t primitive, float entry,
                   bool opaque) {
  QueryCollect& c = *ctx.query;
  const Key key{entry, 0, instance, geometry, primitive};
  if (!better(c, key)) return;
  c.found = true;
  c.best = key;
  c.hit = QueryHit{};
  c.hit.t = entry;
  c.hit.instance = instance;
  c.hit.geometry = geometry;
  c.hit.primitive = primitive;
  c.hit.type = 2;
  c.hit.opaque = opaque;
}

// The end of the interval candidates lie in: the committed hit's t, or the ray's tMax.
float queryTMax(const RayQuery& q) { return q.committed.type ? q.committed.t : q.ray.tMax; }

void commitEnd(RayQuery& q) {
  if (q.ray.flags & kRayTerminateOnFirstHit) q.phase = 0;  // the first commit ends the query
}

}  // namespace
}  // namespace detail

void queryInitialize(RayQuery& q, const Tlas* tlas, const Ray& ray) {
  q = RayQuery{};
  q.ray = ray;
  q.phase = 1;
  // A ray trace() would not trace finds nothing.
  q.tlas = tlas && detail::traced(tlas->impl(), ray) ? tlas : nullptr;
}

bool queryProceed(RayQuery& q) {
  using namespace detail;
  q.candidate = QueryHit{};
  if (q.phase != 1) return false;
  if (!q.tlas) {
    q.phase = 0;
    return false;
  }
  const Tlas::Impl& t = q.tlas->impl();
  Ray ray = q.ray;
  ray.tMax = queryTMax(q);

  QueryCollect collect;
  collect.q = &q;
  TraceContext ctx;
  rtcInitIntersectContext(&ctx.embree);
  ctx.tlas = &t;
  ctx.ray = &ray;
  ctx.handler = nullptr;
  ctx.flags = ray.flags;
  ctx.firstHit = false;
  ctx.query = &collect;
  ctx.closedInterval = true;
  if (t.summary.triangles && !(ray.flags & kRaySkipTriangles)) ctx.embree.filter = triangleFilter;

  RTCRayHit rh;
  rh.ray.org_x = ray.origin[0];
  rh.ray.org_y = ray.origin[1];
  rh.ray.org_z = ray.origin[2];
  rh.ray.dir_x = ray.direction[0];
  rh.ray.dir_y = ray.direction[1];
  rh.ray.dir_z = ray.direction[2];
  // Boxes are candidates for tMin <= t <= tMax, both ends included, so the Embree interval is [tMin, tMax] (a ray
  // that starts inside a box with tMin == tMax == 0 meets it); the filter keeps triangles strictly inside.
  rh.ray.tnear = ray.tMin;
  rh.ray.tfar = ray.tMax;
  rh.ray.time = 0;
  rh.ray.mask = embreeRayMask(ray);
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  traverseTlas<false>(t, ctx, rh);

  // Opaque triangles the traversal committed (the filter recorded the last one accepted, which is the closest).
  if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID || ctx.terminated) {
    const Committed& c = ctx.last;
    q.committed = QueryHit{};
    q.committed.t = c.t;
    q.committed.instance = c.instance;
    q.committed.geometry = c.geometry;
    q.committed.primitive = c.primitive;
    q.committed.hitKind = c.hitKind;
    q.committed.type = 1;
    q.committed.barycentrics[0] = c.u;
    q.committed.barycentrics[1] = c.v;
    if (ctx.terminated) {
      q.phase = 0;
      return false;
    }
  }
  if (collect.found) {
    const float end = queryTMax(q);
    const bool inside = collect.hit.type == 2 ? collect.best.t <= end : collect.best.t < end;
    if (inside) {
      q.candidate = collect.hit;
      q.last = collect.best;
      q.returned = true;
      if (collect.hit.type == 1) {
        QueryCrossing& slot = q.crossings[q.crossingCount++ % RayQuery::kCrossings];
        slot.instance = collect.hit.instance;
        slot.t = collect.hit.t;
        std::memcpy(slot.v, collect.v, sizeof slot.v);
      }
      return true;
    }
  }
  q.phase = 0;
  return false;
}

void queryConfirm(RayQuery& q) {
  if (q.phase != 1 || q.candidate.type != 1) return;
  q.committed = q.candidate;
  q.candidate.type = 0;
  detail::commitEnd(q);
}

void queryGenerate(RayQuery& q, float t) {
  if (q.phase != 1 || q.candidate.type != 2) return;
  // Valid usage requires tMin <= t <= the committed t (or tMax); a t outside is not committed.
  if (!(t >= q.ray.tMin && t <= detail::queryTMax(q))) return;
  q.committed = q.candidate;
  q.committed.t = t;
  q.committed.hitKind = 0;
  q.committed.opaque = false;
  q.candidate.type = 0;
  detail::commitEnd(q);
}

void queryTerminate(RayQuery& q) {
  q.phase = 0;
  q.candidate = QueryHit{};
}

HitInfo queryHitInfo(const RayQuery& q, bool committed) {
  HitInfo h;
  const QueryHit& s = committed ? q.committed : q.candidate;
  if (!s.type || !q.tlas) return h;
  const detail::InstanceRecord& r = q.tlas->impl().records[s.instance];
  h.t = s.t;
  h.instanceIndex = s.instance;
  h.customIndex = r.customIndex;
  h.sbtOffset = r.sbtOffset;
  h.geometryIndex = s.geometry;
  h.primitiveIndex = s.primitive;
  h.hitKind = s.hitKind;
  h.triangle = s.type == 1;
  h.barycentrics[0] = s.barycentrics[0];
  h.barycentrics[1] = s.barycentrics[1];
  h.objectToWorld = r.objectToWorld;
  h.worldToObject = r.worldToObject;
  h.blas = r.blas;
  detail::objectRay(r, q.ray, h.objectRayOrigin, h.objectRayDirection);
  return h;
}

bool trianglePositions(const HitInfo& hit, float out[3][3]) {
  for (int k = 0; k < 3; ++k)
    for (int c = 0; c < 3; ++c) out[k][c] = 0;
  if (!hit.blas || !hit.triangle || hit.geometryIndex >= hit.blas->info.size()) return false;
  const detail::GeometryInfo& g = hit.blas->info[hit.geometryIndex];
  if (g.kind != Geometry::Triangles || !g.vertices || hit.primitiveIndex >= g.primitiveCount) return false;
  const uint32_t* index = g.indices + 3 * size_t(hit.primitiveIndex);
  for (int k = 0; k < 3; ++k)
    if (index[k] < g.vertexCount)
      for (int c = 0; c < 3; ++c) out[k][c] = g.vertices[3 * size_t(index[k]) + c];
  return true;
}

}  // namespace vkrt::accel
