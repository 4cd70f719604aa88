// The Embree side of the acceleration structures (accel-private; includes Embree's headers): the process's
// Embree device, and what a built Blas and Tlas hold besides their inputs.
#pragma once

#include <embree3/rtcore.h>

#include <string>
#include <vector>

#include "accel/accel.hpp"

namespace vkrt::accel {

// Ray mask bits below the instance mask's 8: a Blas's triangle geometries carry kMaskTriangles, its box
// geometries kMaskAabbs, so that kRaySkipTriangles / kRaySkipAabbs are Embree ray masks (no callback per
// candidate). Instance geometries carry the instance's 8-bit mask, tested against the ray's cull mask.
inline constexpr uint32_t kMaskTriangles = 1u << 8;
inline constexpr uint32_t kMaskAabbs = 1u << 9;

// The process's Embree device (created on first use). Errors Embree reports on this thread since the last
// takeError() are returned by it (empty when none).
RTCDevice embreeDevice();
std::string takeError();

// An owned RTCScene.
class SceneRef {
 public:
  SceneRef() = default;
  explicit SceneRef(RTCScene s) : scene_(s) {}
  ~SceneRef() {
    if (scene_) rtcReleaseScene(scene_);
  }
  SceneRef(const SceneRef&) = delete;
  SceneRef& operator=(const SceneRef&) = delete;
  void reset(RTCScene s) {
    if (scene_) rtcReleaseScene(scene_);
    scene_ = s;
  }
  RTCScene get() const { return scene_; }

 private:
  RTCScene scene_ = nullptr;
};

struct Blas::Impl {
  std::vector<Geometry> geometries;  // the inputs, as given
  BuildOptions options;
  SceneRef scene;
  uint64_t primitives = 0;
  bool anyNonOpaqueTriangles = false;  // a triangle geometry without kGeometryOpaque
  bool anyTriangles = false;
  bool anyAabbs = false;
  uint64_t bytes = 0;  // nativeBytes()
};

// What traversal needs of an instance (instances without a Blas are not entered in Embree).
struct InstanceData {
  float objectToWorld[3][4];
  float worldToObject[3][4];
  uint32_t index;  // position in the Tlas (gl_InstanceID)
  uint32_t customIndex, sbtOffset, flags;
  const Blas::Impl* blas;
};

struct Tlas::Impl {
  std::vector<Instance> instances;  // the inputs, as given
  BuildOptions options;
  SceneRef scene;
  std::vector<InstanceData> data;  // by Embree geometry id of the instance
  // Whether a ray without flags may meet a non-opaque triangle (so needs the filter), or boxes.
  bool mayMeetNonOpaqueTriangles = false;
  bool anyTriangles = false;
  bool anyAabbs = false;
  uint64_t bytes = 0;
};

}  // namespace vkrt::accel
