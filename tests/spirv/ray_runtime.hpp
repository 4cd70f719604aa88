// A test runtime for compiled ray tracing shaders, standing in for the tracing executor: a scene of instances
// (a translation each) with triangle geometries and procedural (sphere) geometries, a shader binding table of
// compiled shaders with their shader-record bytes, and the RayRuntime callbacks (abi.hpp). Traversal is brute
// force in scene order: every primitive of every instance is tested, hits go through the any-hit shader (unless
// the ray is opaque), the closest committed hit gets its closest-hit shader, otherwise the miss shader runs.
//
// Hit group record index = instance.sbtOffset + trace sbtOffset + geometry index * trace sbtStride, as in
// Vulkan. Triangle hits report HitKind 0xFE and the barycentrics (u, v) of vertices 1 and 2 as attributes.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "spirv/compiler.hpp"

namespace vkrt::testing {

struct RayScene {
  struct Triangle {
    std::array<float, 3> v[3];
  };
  struct Geometry {
    bool procedural = false;
    std::vector<Triangle> triangles;  // procedural: one primitive (the intersection shader decides)
  };
  struct Instance {
    std::array<float, 3> translation{};
    int32_t customIndex = 0;
    uint32_t sbtOffset = 0;
    std::vector<Geometry> geometries;
  };
  std::vector<Instance> instances;
};

struct RaySbt {
  struct Record {
    std::shared_ptr<spirv::CompiledShader> general, closestHit, anyHit, intersection;
    std::vector<uint8_t> data;  // the shader record's bytes after the handle
  };
  std::vector<Record> hitGroups, miss, callable;
};

class RayTestRuntime {
 public:
  RayTestRuntime(const RayScene& scene, RaySbt& sbt, uint64_t accelAddress)
      : scene(scene), sbt(sbt), accel(accelAddress) {}

  // Descriptors by binding (set 0, one element each) and push constants, for every shader of the launch.
  std::map<uint32_t, abi::DescriptorRecord> bindings;
  const uint8_t* pushConstants = nullptr;

  abi::PendingAdds* pendingAdds = nullptr;  // every invocation's combined adds (abi.hpp); null: none combined
  uint32_t maxDepth = 0;                    // deepest traceRay nesting seen
  std::vector<std::string> errors;  // what the runtime found wrong (a bad AS address, an SBT index out of range)

  // Runs the raygen shader once per launch index, or, with `batches`, through its SPMD entry (abi::RayBatchEntry):
  // each row in batches of its lanes from x = 0, the last one partial.
  void launch(const std::shared_ptr<spirv::CompiledShader>& raygen, std::vector<uint8_t> raygenRecord, uint32_t width,
              uint32_t height, bool batches = false) {
    if (batches) ASSERT_TRUE(raygen->rayBatchEntry && raygen->spmdLanes) << "the raygen shader has no batch entry";
    const uint32_t step = batches ? raygen->spmdLanes : 1;
    for (uint32_t y = 0; y < height; ++y) {
      for (uint32_t x = 0; x < width; x += step) {
        Invocation inv = fresh(nullptr);
        inv.launchId[0] = x;
        inv.launchId[1] = y;
        inv.launchSize[0] = width;
        inv.launchSize[1] = height;
        inv.launchSize[2] = 1;
        inv.shaderRecord = raygenRecord.data();
        inv.shaderRecordBytes = raygenRecord.size();
        run(*raygen, inv, batches ? std::min(step, width - x) : 0);
        if (batches) EXPECT_EQ(inv.launchId[0], x) << "the batch entry left launchId[0] changed";
      }
    }
  }

 private:
  struct Traversal;
  // What the runtime passes to a shader: the ABI's RayInvocation, then the runtime's own state.
  struct Invocation : abi::RayInvocation {
    RayTestRuntime* runtime = nullptr;
    Traversal* traversal = nullptr;
    uint32_t depth = 0;
  };
  struct Hit {
    float t = 0;
    uint32_t instance = 0, geometry = 0, primitive = 0, hitKind = 0;
    uint8_t attributes[32] = {};
    uint64_t attributeBytes = 0;
  };
  struct Traversal {
    const abi::TraceRayArgs* args;
    float tMax;
    std::optional<Hit> committed;
    bool stop = false;
    Hit candidate;  // the primitive an intersection shader runs for
  };

  // Calls a shader with its own resource table (one slot per ResourceBinding, in its order); with `lanes`, the raygen
  // shader's batch entry for that many launch ids from inv's.
  void run(const spirv::CompiledShader& shader, Invocation& inv, uint32_t lanes = 0) {
    std::vector<abi::ResourceSlot>& slots = tables[&shader];
    if (slots.size() != shader.resources.size()) {
      slots.clear();
      for (const spirv::ResourceBinding& rb : shader.resources) {
        auto it = bindings.find(rb.binding);
        slots.push_back(it != bindings.end() ? abi::ResourceSlot{&it->second, 1} : abi::ResourceSlot{nullptr, 0});
      }
    }
    inv.base.resources = slots.data();
    ASSERT_NE(shader.rayEntry, nullptr);
    if (lanes) {
      shader.rayBatchEntry(&inv, lanes);
    } else {
      shader.rayEntry(&inv);
    }
  }

  Invocation fresh(const Invocation* caller) {
    Invocation inv{};
    inv.base.pushConstants = pushConstants;
    inv.base.sink = sink;
    inv.pendingAdds = pendingAdds;
    inv.runtime = this;
    inv.depth = caller ? caller->depth : 0;
    static const abi::RayRuntime table = {&traceRay, &executeCallable, &reportIntersection, &recordOutsideRegion,
                                          &traceRays};
    inv.abi::RayInvocation::runtime = &table;
    inv.shaderRecordRegionBytes = UINT64_MAX;  // records here are not in SBT regions: no read is past one
    if (caller) {
      std::memcpy(inv.launchId, caller->launchId, sizeof inv.launchId);
      std::memcpy(inv.launchSize, caller->launchSize, sizeof inv.launchSize);
    }
    return inv;
  }

  // The ray and hit fields of a shader run for `hit` (or for the ray alone when hit is null).
  void describe(Invocation& inv, const abi::TraceRayArgs& a, const Hit* hit, float tMax) {
    for (int i = 0; i < 3; ++i) {
      inv.worldRayOrigin[i] = a.origin[i];
      inv.worldRayDirection[i] = a.direction[i];
    }
    inv.rayTmin = a.tMin;
    inv.rayTmax = tMax;
    inv.incomingRayFlags = a.rayFlags;
    inv.cullMask = a.cullMask;
    if (!hit) return;
    const RayScene::Instance& in = scene.instances[hit->instance];
    for (int i = 0; i < 3; ++i) {
      inv.objectRayOrigin[i] = a.origin[i] - in.translation[i];
      inv.objectRayDirection[i] = a.direction[i];
      for (int c = 0; c < 3; ++c) inv.objectToWorld[c][i] = inv.worldToObject[c][i] = c == i ? 1.0f : 0.0f;
      inv.objectToWorld[3][i] = in.translation[i];
      inv.worldToObject[3][i] = -in.translation[i];
    }
    inv.instanceCustomIndex = in.customIndex;
    inv.instanceId = int32_t(hit->instance);
    inv.geometryIndex = int32_t(hit->geometry);
    inv.primitiveId = int32_t(hit->primitive);
    inv.hitKind = hit->hitKind;
  }

  const RaySbt::Record* hitGroup(const abi::TraceRayArgs& a, const Hit& h) {
    uint64_t index = uint64_t(scene.instances[h.instance].sbtOffset) + a.sbtOffset + uint64_t(h.geometry) * a.sbtStride;
    if (index >= sbt.hitGroups.size()) {
      errors.push_back("hit group index " + std::to_string(index) + " out of range");
      return nullptr;
    }
    return &sbt.hitGroups[index];
  }

  // Offers a candidate hit: any-hit (unless opaque), then commits. Returns whether it was committed.
  bool offer(Invocation& from, Traversal& tr, const Hit& h, const RaySbt::Record& group) {
    const abi::TraceRayArgs& a = *tr.args;
    if (h.t < a.tMin || h.t > tr.tMax) return false;
    bool opaque = a.rayFlags & 1u;  // gl_RayFlagsOpaqueEXT
    if (group.anyHit && !opaque) {
      Invocation inv = fresh(&from);
      describe(inv, a, &h, h.t);
      inv.hitAttributes = h.attributes;
      inv.hitAttributeBytes = h.attributeBytes;
      inv.shaderRecord = const_cast<uint8_t*>(group.data.data());
      inv.shaderRecordBytes = group.data.size();
      run(*group.anyHit, inv);
      if (inv.status == abi::kRayStatusIgnore) return false;
      if (inv.status == abi::kRayStatusTerminate) tr.stop = true;
    }
    tr.committed = h;
    tr.tMax = h.t;
    if (a.rayFlags & 4u) tr.stop = true;  // gl_RayFlagsTerminateOnFirstHitEXT
    return true;
  }

  static void traceRay(abi::RayInvocation* callerBase, const abi::TraceRayArgs* a) {
    auto* caller = static_cast<Invocation*>(callerBase);
    RayTestRuntime& rt = *caller->runtime;
    if (a->accelerationStructure != rt.accel) rt.errors.push_back("traceRay with an unknown acceleration structure");
    Traversal tr{a, a->tMax};
    uint32_t depth = caller->depth + 1;
    rt.maxDepth = std::max(rt.maxDepth, depth);
    for (uint32_t i = 0; i < rt.scene.instances.size() && !tr.stop; ++i) {
      const RayScene::Instance& in = rt.scene.instances[i];
      float o[3], d[3];
      for (int k = 0; k < 3; ++k) o[k] = a->origin[k] - in.translation[k], d[k] = a->direction[k];
      for (uint32_t g = 0; g < in.geometries.size() && !tr.stop; ++g) {
        const RayScene::Geometry& geo = in.geometries[g];
        Hit h;
        h.instance = i;
        h.geometry = g;
        const RaySbt::Record* group = rt.hitGroup(*a, h);
        if (!group) continue;
        if (geo.procedural) {
          if (!group->intersection) continue;
          Invocation inv = rt.fresh(caller);
          inv.depth = depth;
          rt.describe(inv, *a, &h, tr.tMax);
          inv.hitKind = 0;
          inv.traversal = &tr;
          tr.candidate = h;
          inv.shaderRecord = const_cast<uint8_t*>(group->data.data());
          inv.shaderRecordBytes = group->data.size();
          rt.run(*group->intersection, inv);
          continue;
        }
        for (uint32_t p = 0; p < geo.triangles.size() && !tr.stop; ++p) {
          float t, u, v;
          if (!intersect(geo.triangles[p], o, d, &t, &u, &v)) continue;
          h.primitive = p;
          h.t = t;
          h.hitKind = 0xFE;
          std::memcpy(h.attributes, &u, 4);
          std::memcpy(h.attributes + 4, &v, 4);
          h.attributeBytes = 8;
          Invocation from = rt.fresh(caller);
          from.depth = depth;
          rt.offer(from, tr, h, *group);
        }
      }
    }
    Invocation inv = rt.fresh(caller);
    inv.depth = depth;
    inv.incoming = a->payload;
    inv.incomingBytes = a->payloadBytes;
    if (tr.committed) {
      const Hit& h = *tr.committed;
      const RaySbt::Record* group = rt.hitGroup(*a, h);
      if (!group || !group->closestHit) return;
      rt.describe(inv, *a, &h, h.t);
      inv.hitAttributes = h.attributes;
      inv.hitAttributeBytes = h.attributeBytes;
      inv.shaderRecord = const_cast<uint8_t*>(group->data.data());
      inv.shaderRecordBytes = group->data.size();
      rt.run(*group->closestHit, inv);
      return;
    }
    if (a->missIndex >= rt.sbt.miss.size()) {
      rt.errors.push_back("miss index out of range");
      return;
    }
    RaySbt::Record& miss = rt.sbt.miss[a->missIndex];
    rt.describe(inv, *a, nullptr, a->tMax);
    inv.shaderRecord = miss.data.data();
    inv.shaderRecordBytes = miss.data.size();
    rt.run(*miss.general, inv);
  }

  static uint32_t reportIntersection(abi::RayInvocation* callerBase, float hitT, uint32_t hitKind, const void* attrs,
                                     uint64_t bytes) {
    auto* caller = static_cast<Invocation*>(callerBase);
    RayTestRuntime& rt = *caller->runtime;
    Traversal& tr = *caller->traversal;
    Hit h = tr.candidate;
    h.t = hitT;
    h.hitKind = hitKind;
    h.attributeBytes = std::min<uint64_t>(bytes, sizeof h.attributes);
    if (attrs) std::memcpy(h.attributes, attrs, h.attributeBytes);
    const RaySbt::Record* group = rt.hitGroup(*tr.args, h);
    if (!group) return 0;
    bool committed = rt.offer(*caller, tr, h, *group);
    // The intersection shader now sees the new closest t; a terminated ray stops it.
    caller->rayTmax = tr.tMax;
    if (committed && tr.stop) caller->status = abi::kRayStatusTerminate;
    return committed ? 1 : 0;
  }

  static void executeCallable(abi::RayInvocation* callerBase, uint32_t index, void* data, uint64_t bytes) {
    auto* caller = static_cast<Invocation*>(callerBase);
    RayTestRuntime& rt = *caller->runtime;
    if (index >= rt.sbt.callable.size()) {
      rt.errors.push_back("callable index out of range");
      return;
    }
    RaySbt::Record& c = rt.sbt.callable[index];
    Invocation inv = rt.fresh(caller);
    inv.incoming = data;
    inv.incomingBytes = bytes;
    inv.shaderRecord = c.data.data();
    inv.shaderRecordBytes = c.data.size();
    rt.run(*c.general, inv);
  }

  // Never called here (shaderRecordRegionBytes is the largest value): an error if it is.
  // A raygen batch's traces: each lane's traceRay in lane order with its launch id (RayRuntime::traceRays).
  static void traceRays(abi::RayInvocation* callerBase, const abi::TraceRayArgs* args, uint32_t mask,
                        uint32_t launchX0) {
    for (uint32_t l = 0; l < 32; ++l) {
      if (!((mask >> l) & 1)) continue;
      callerBase->launchId[0] = launchX0 + l;
      traceRay(callerBase, &args[l]);
    }
    callerBase->launchId[0] = launchX0;
  }

  static void recordOutsideRegion(abi::RayInvocation* callerBase, uint64_t, uint64_t) {
    static_cast<Invocation*>(callerBase)->runtime->errors.push_back("a shader record read past its region");
  }

  // Ray / triangle (Moller-Trumbore); (u, v) are the weights of vertices 1 and 2.
  static bool intersect(const RayScene::Triangle& tri, const float o[3], const float d[3], float* t, float* u,
                        float* v) {
    float e1[3], e2[3], s[3];
    for (int k = 0; k < 3; ++k) {
      e1[k] = tri.v[1][k] - tri.v[0][k];
      e2[k] = tri.v[2][k] - tri.v[0][k];
      s[k] = o[k] - tri.v[0][k];
    }
    float p[3] = {d[1] * e2[2] - d[2] * e2[1], d[2] * e2[0] - d[0] * e2[2], d[0] * e2[1] - d[1] * e2[0]};
    float det = e1[0] * p[0] + e1[1] * p[1] + e1[2] * p[2];
    if (std::fabs(det) < 1e-12f) return false;
    float inv = 1.0f / det;
    *u = (s[0] * p[0] + s[1] * p[1] + s[2] * p[2]) * inv;
    float q[3] = {s[1] * e1[2] - s[2] * e1[1], s[2] * e1[0] - s[0] * e1[2], s[0] * e1[1] - s[1] * e1[0]};
    *v = (d[0] * q[0] + d[1] * q[1] + d[2] * q[2]) * inv;
    *t = (e2[0] * q[0] + e2[1] * q[1] + e2[2] * q[2]) * inv;
    return *u >= 0 && *v >= 0 && *u + *v <= 1;
  }

  const RayScene& scene;
  RaySbt& sbt;
  uint64_t accel;
  std::map<const spirv::CompiledShader*, std::vector<abi::ResourceSlot>> tables;
  alignas(16) uint8_t sink[abi::kSinkBytes] = {};
};

}  // namespace vkrt::testing
