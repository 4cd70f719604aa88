// Top-level structures: the instances, their transforms and inverses, and an Embree scene of instance geometries.
#include <cmath>

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

// Fills the per-instance records and the Tlas summary. An instance is inactive (never hit, index kept) when its
// Blas is null (Vulkan: reference 0) or its transform has no inverse (Vulkan requires an invertible one; a
// zero scale is sometimes used to hide an instance, and hiding it is what such an instance gets).
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
    if (!in.blas || !invertAffine(r.objectToWorld, r.worldToObject)) {
      for (auto& row : r.worldToObject)
        for (float& v : row) v = 0;
      continue;
    }
    r.blas = in.blas->impl.get();
    const BlasSummary& b = r.blas->summary;
    TlasSummary& s = impl.summary;
    if ((in.mask & 0xFF) == 0) continue;  // no ray sees it
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

RTCScene newScene(const Tlas::Impl& impl, std::string* error) {
  RTCDevice device = detail::device(error);
  if (!device) return nullptr;
  EmbreeErrors errors;
  const SceneSettings settings = sceneSettings(impl.options, false);
  RTCScene scene = rtcNewScene(device);
  if (!scene) {
    errors.failed("Tlas build", error);
    return nullptr;
  }
  // Robust here too: the instance hierarchy's box tests are conservative, so a ray grazing an instance's bounds
  // still enters it. (No filter runs at this level: the context filter is called for primitives only.)
  rtcSetSceneFlags(scene, RTCSceneFlags(settings.sceneFlags & ~RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION));
  rtcSetSceneBuildQuality(scene, settings.sceneQuality);  // (Embree's instance builders tell only LOW from the rest)
  // One instance geometry per active instance, attached under its index (Embree's instID = the instance index),
  // one after the other: made in parallel on Embree's build threads (rtcAttachGeometryByID is thread-safe), 10^5
  // instances took 2.5x longer on 16 threads (the attachments contend for the scene's lock).
  bool outOfMemory = false;
  for (size_t i = 0; i < impl.instances.size() && !outOfMemory; ++i) {
    const InstanceRecord& r = impl.records[i];
    const uint32_t mask = impl.instances[i].mask & 0xFF;
    if (!r.blas || !r.blas->scene || !r.blas->primitives || !mask) continue;  // never hit; the index stays
    RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_INSTANCE);
    if (!geometry) {
      outOfMemory = true;
      break;
    }
    rtcSetGeometryInstancedScene(geometry, r.blas->scene);
    rtcSetGeometryTransform(geometry, 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, &r.objectToWorld[0][0]);
    rtcSetGeometryMask(geometry, mask);
    rtcCommitGeometry(geometry);
    rtcAttachGeometryByID(scene, geometry, unsigned(i));
    rtcReleaseGeometry(geometry);
  }
  if (outOfMemory) {
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
