// Traversal with the Vulkan rules on top of rtcIntersect1.
//
// What Embree does itself: the instance mask test (instance geometries carry the instance's mask, the ray
// carries the cull mask), kRaySkipTriangles / kRaySkipAabbs (ray mask bits, see embree_scene.hpp), the closest
// hit. What the callbacks add: opacity and its culling flags, triangle facing and its culling, the any-hit shader
// (the context filter function, installed only for rays that can need it), box primitives (the user geometry's
// intersect function: an exact slab test, then the intersection shader), and termination.
//
// Triangle facing (the specification's "Ray Culling"): facing is decided in the instance's object space, from
// the triangle's winding as seen from the ray: a triangle is front-facing when its vertices appear clockwise
// looking along the ray, i.e. when dot(cross(v1 - v0, v2 - v0), direction) < 0 (the same winding DirectX calls
// front-facing by default). kInstanceTriangleFlipFacing swaps front and back.
#include <cmath>
#include <cstring>

#include "accel/embree_scene.hpp"

namespace vkrt::accel {

namespace {

struct TraceContext {
  RTCIntersectContext rtc;  // first: Embree hands callbacks its address
  const Tlas::Impl* tlas;
  const Ray* ray;
  HitHandler* handler;
  bool terminated = false;
  uint32_t committedHitKind = 0;  // of the last committed box hit
};

bool effectiveOpaque(uint32_t geometryFlags, uint32_t instanceFlags, uint32_t rayFlags) {
  bool opaque = geometryFlags & kGeometryOpaque;
  if (instanceFlags & kInstanceForceOpaque) opaque = true;
  if (instanceFlags & kInstanceForceNoOpaque) opaque = false;
  if (rayFlags & kRayOpaque) opaque = true;
  if (rayFlags & kRayNoOpaque) opaque = false;
  return opaque;
}

// Whether opacity culls the candidate.
bool culledByOpacity(bool opaque, uint32_t rayFlags) {
  return ((rayFlags & kRayCullOpaque) && opaque) || ((rayFlags & kRayCullNoOpaque) && !opaque);
}

void transformPoint(const float m[3][4], const float p[3], float out[3]) {
  for (int r = 0; r < 3; ++r) out[r] = m[r][0] * p[0] + m[r][1] * p[1] + m[r][2] * p[2] + m[r][3];
}
void transformVector(const float m[3][4], const float v[3], float out[3]) {
  for (int r = 0; r < 3; ++r) out[r] = m[r][0] * v[0] + m[r][1] * v[1] + m[r][2] * v[2];
}

// Front-facing as seen along `dir` (object space), before the instance's flip flag.
bool frontFacing(const TriangleGeometry& t, uint32_t primitive, const float dir[3]) {
  const uint32_t* idx = t.indices.data() + size_t(primitive) * 3;
  const float* v0 = t.vertices.data() + size_t(idx[0]) * 3;
  const float* v1 = t.vertices.data() + size_t(idx[1]) * 3;
  const float* v2 = t.vertices.data() + size_t(idx[2]) * 3;
  const float e1[3] = {v1[0] - v0[0], v1[1] - v0[1], v1[2] - v0[2]};
  const float e2[3] = {v2[0] - v0[0], v2[1] - v0[1], v2[2] - v0[2]};
  const float n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
  return n[0] * dir[0] + n[1] * dir[1] + n[2] * dir[2] < 0;
}

// The hit kind of a triangle hit, in object space, with the instance's flip flag.
uint32_t triangleHitKind(const InstanceData& inst, uint32_t geometry, uint32_t primitive, const float objectDir[3]) {
  bool front = frontFacing(inst.blas->geometries[geometry].triangles, primitive, objectDir);
  if (inst.flags & kInstanceTriangleFlipFacing) front = !front;
  return front ? kHitKindFrontFacingTriangle : kHitKindBackFacingTriangle;
}

void describe(const TraceContext& ctx, const InstanceData& inst, uint32_t geometry, uint32_t primitive, float t,
              HitInfo* h) {
  h->t = t;
  h->instanceIndex = inst.index;
  h->customIndex = inst.customIndex;
  h->sbtOffset = inst.sbtOffset;
  h->geometryIndex = geometry;
  h->primitiveIndex = primitive;
  h->objectToWorld = inst.objectToWorld;
  h->worldToObject = inst.worldToObject;
  transformPoint(inst.worldToObject, ctx.ray->origin, h->objectRayOrigin);
  transformVector(inst.worldToObject, ctx.ray->direction, h->objectRayDirection);
}

// The context filter function: every triangle candidate of a ray that needs one.
void triangleFilter(const RTCFilterFunctionNArguments* args) {
  if (!args->valid[0]) return;
  auto* ctx = reinterpret_cast<TraceContext*>(args->context);
  if (ctx->terminated) {
    args->valid[0] = 0;
    return;
  }
  const unsigned instId = RTCHitN_instID(args->hit, args->N, 0, 0);
  const unsigned geomId = RTCHitN_geomID(args->hit, args->N, 0);
  const unsigned primId = RTCHitN_primID(args->hit, args->N, 0);
  const InstanceData& inst = ctx->tlas->data[instId];
  const Geometry& geo = inst.blas->geometries[geomId];
  if (geo.kind != Geometry::Triangles) return;  // box hits are committed by boxIntersect itself
  const uint32_t flags = ctx->ray->flags;
  const bool opaque = effectiveOpaque(geo.triangles.flags, inst.flags, flags);
  if (culledByOpacity(opaque, flags)) {
    args->valid[0] = 0;
    return;
  }
  HitInfo h;
  describe(*ctx, inst, geomId, primId, RTCRayN_tfar(args->ray, args->N, 0), &h);
  h.triangle = true;
  h.hitKind = triangleHitKind(inst, geomId, primId, h.objectRayDirection);
  if (!(inst.flags & kInstanceTriangleFacingCullDisable)) {
    const bool front = h.hitKind == kHitKindFrontFacingTriangle;
    if (((flags & kRayCullBackFacingTriangles) && !front) || ((flags & kRayCullFrontFacingTriangles) && front)) {
      args->valid[0] = 0;
      return;
    }
  }
  AnyHitResult r = AnyHitResult::Accept;
  if (!opaque) {
    h.barycentrics[0] = RTCHitN_u(args->hit, args->N, 0);
    h.barycentrics[1] = RTCHitN_v(args->hit, args->N, 0);
    r = ctx->handler->anyHit(h);
  }
  if (r == AnyHitResult::Ignore) {
    args->valid[0] = 0;
    return;
  }
  if (r == AnyHitResult::AcceptAndTerminate || (flags & kRayTerminateOnFirstHit)) ctx->terminated = true;
}

// A box primitive the ray reached: the intersection shader's view of it.
class BoxCandidate final : public ProceduralCandidate {
 public:
  BoxCandidate(TraceContext& ctx, RTCRayHit& rh, unsigned geomId, unsigned primId, bool opaque)
      : ctx_(ctx), rh_(rh), geomId_(geomId), primId_(primId), opaque_(opaque) {}
  HitInfo info_;
  const HitInfo& info() const override { return info_; }
  float tMin() const override { return ctx_.ray->tMin; }
  float tMax() const override { return rh_.ray.tfar; }
  bool opaque() const override { return opaque_; }
  void commit(float t, uint32_t hitKind, bool terminate) override {
    rh_.ray.tfar = t;
    rh_.hit.geomID = geomId_;
    rh_.hit.primID = primId_;
    rh_.hit.instID[0] = ctx_.rtc.instID[0];
    rh_.hit.u = rh_.hit.v = 0;
    rh_.hit.Ng_x = rh_.hit.Ng_y = rh_.hit.Ng_z = 0;
    ctx_.committedHitKind = hitKind;
    if (terminate || (ctx_.ray->flags & kRayTerminateOnFirstHit)) ctx_.terminated = true;
  }

 private:
  TraceContext& ctx_;
  RTCRayHit& rh_;
  unsigned geomId_, primId_;
  bool opaque_;
};

// Whether the object-space ray enters the box within [tMin, tMax] (slab test, inclusive ends).
bool entersBox(const float* box, const float o[3], const float d[3], float tMin, float tMax) {
  float lo = tMin, hi = tMax;
  for (int k = 0; k < 3; ++k) {
    const float inv = 1.0f / d[k];
    float t0 = (box[k] - o[k]) * inv, t1 = (box[k + 3] - o[k]) * inv;
    if (std::isnan(t0) || std::isnan(t1)) {
      // The ray runs in the slab's plane (0 * inf): inside when the origin is between the planes.
      if (o[k] < box[k] || o[k] > box[k + 3]) return false;
      continue;
    }
    if (t0 > t1) std::swap(t0, t1);
    lo = std::max(lo, t0);
    hi = std::min(hi, t1);
    if (lo > hi) return false;
  }
  return true;
}

}  // namespace

// The user geometry's intersect function (registered by build.cpp).
void boxIntersect(const RTCIntersectFunctionNArguments* args) {
  if (!args->valid[0]) return;
  auto* ctx = reinterpret_cast<TraceContext*>(args->context);
  if (ctx->terminated) return;
  auto& rh = *reinterpret_cast<RTCRayHit*>(args->rayhit);  // N is 1: rtcIntersect1
  const InstanceData& inst = ctx->tlas->data[ctx->rtc.instID[0]];
  const Geometry& geo = inst.blas->geometries[args->geomID];
  const float* box = geo.aabbs.boxes.data() + size_t(args->primID) * 6;
  if (std::isnan(box[0])) return;
  const bool opaque = effectiveOpaque(geo.aabbs.flags, inst.flags, ctx->ray->flags);
  if (culledByOpacity(opaque, ctx->ray->flags)) return;
  BoxCandidate c(*ctx, rh, args->geomID, args->primID, opaque);
  describe(*ctx, inst, args->geomID, args->primID, 0, &c.info_);
  c.info_.triangle = false;
  if (!entersBox(box, c.info_.objectRayOrigin, c.info_.objectRayDirection, ctx->ray->tMin, rh.ray.tfar)) return;
  ctx->handler->intersect(c);
}

bool trace(const Tlas& tlas, const Ray& ray, HitHandler& handler, HitInfo* hit) {
  const Tlas::Impl& t = *tlas.impl;
  if (t.data.empty() || !(ray.tMax >= ray.tMin)) return false;
  for (int k = 0; k < 3; ++k)
    if (!std::isfinite(ray.origin[k]) || !std::isfinite(ray.direction[k])) return false;
  TraceContext ctx;
  rtcInitIntersectContext(&ctx.rtc);
  ctx.tlas = &t;
  ctx.ray = &ray;
  ctx.handler = &handler;
  const uint32_t f = ray.flags;
  const bool needFilter = (f & (kRayCullBackFacingTriangles | kRayCullFrontFacingTriangles | kRayCullOpaque |
                                kRayCullNoOpaque | kRayTerminateOnFirstHit)) ||
                          (t.anyTriangles && (f & kRayNoOpaque)) || (t.mayMeetNonOpaqueTriangles && !(f & kRayOpaque));
  ctx.rtc.filter = needFilter ? &triangleFilter : nullptr;

  RTCRayHit rh;
  rh.ray.org_x = ray.origin[0];
  rh.ray.org_y = ray.origin[1];
  rh.ray.org_z = ray.origin[2];
  rh.ray.tnear = ray.tMin;
  rh.ray.dir_x = ray.direction[0];
  rh.ray.dir_y = ray.direction[1];
  rh.ray.dir_z = ray.direction[2];
  rh.ray.time = 0;
  rh.ray.tfar = ray.tMax;
  rh.ray.mask =
      (ray.cullMask & 0xFF) | ((f & kRaySkipTriangles) ? 0 : kMaskTriangles) | ((f & kRaySkipAabbs) ? 0 : kMaskAabbs);
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(t.scene.get(), &ctx.rtc, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID || rh.hit.instID[0] == RTC_INVALID_GEOMETRY_ID) return false;

  const InstanceData& inst = t.data[rh.hit.instID[0]];
  describe(ctx, inst, rh.hit.geomID, rh.hit.primID, rh.ray.tfar, hit);
  hit->triangle = inst.blas->geometries[rh.hit.geomID].kind == Geometry::Triangles;
  if (hit->triangle) {
    hit->hitKind = triangleHitKind(inst, rh.hit.geomID, rh.hit.primID, hit->objectRayDirection);
    hit->barycentrics[0] = rh.hit.u;
    hit->barycentrics[1] = rh.hit.v;
  } else {
    hit->hitKind = ctx.committedHitKind;
    hit->barycentrics[0] = hit->barycentrics[1] = 0;
  }
  return true;
}

}  // namespace vkrt::accel
