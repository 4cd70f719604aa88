// vkCmdTraceRaysKHR, vkCmdTraceRaysIndirectKHR, vkCmdTraceRaysIndirect2KHR and vkCmdTraceRaysNV (whose buffers,
// offsets and strides become the same regions: the launch is the KHR one): the shader binding table (SBT)
// regions are checked when the command is recorded (or, for the indirect form 2, when its parameters are read),
// and at execution a Launch resolves the bound pipeline's groups and resources and runs the launch on the trace
// executor (src/exec/trace.hpp), answering its questions about SBT records and acceleration structures.
//
// Every record a launch uses is checked once per launch: its handle must lie inside its region (the stride may be
// larger than the region), decode to a group of the bound pipeline or of one of its libraries, of the kind its
// region holds (raygen, miss, hit, callable), not null where the pipeline's NO_NULL_* flags forbid it, and a hit
// group's type must match the geometry it is used for. A violation is reported once per launch and rule, naming the
// region, record index and address, and (where the handle is one this device gave out) the group and the pipeline it
// was created in; that shader is not run. A shader that reads its record's data past the region is reported once
// per launch and record (the compiled code checks each read), and its read goes on.
#include <algorithm>
#include <atomic>
#include <cinttypes>
#include <cstring>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "exec/trace.hpp"
#include "rt/group_handles.hpp"
#include "rt/rt_pipeline.hpp"
#include "runtime/acceleration_structure.hpp"
#include "runtime/bound_resources.hpp"
#include "runtime/buffer.hpp"
#include "runtime/command_buffer.hpp"
#include "runtime/device.hpp"
#include "runtime/memory.hpp"
#include "runtime/physical_device.hpp"
#include "runtime/ray_tracing_features.hpp"
#include "runtime/ray_tree_output.hpp"
#include "runtime/report.hpp"
#include "runtime/shader_messages.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt::rt {
namespace {

using ull = unsigned long long;

// The VUID a launch reports: the KHR rule's, or for vkCmdTraceRaysNV the NV rule it stands for where the NV command
// has one (the NV extension has no NO_NULL_* flags and no hit group / geometry type rule: those stay KHR).
const char* launchVuid(const char* fn, const char* khr) {
  static const std::pair<const char*, const char*> kNv[] = {
      {"VUID-vkCmdTraceRaysKHR-None-02697", "VUID-vkCmdTraceRaysNV-None-02697"},
      {"VUID-vkCmdTraceRaysKHR-None-02700", "VUID-vkCmdTraceRaysNV-None-02700"},
      {"VUID-vkCmdTraceRaysKHR-None-03429", "VUID-vkCmdTraceRaysNV-None-03429"},
      {"VUID-vkCmdTraceRaysKHR-maxPipelineRayRecursionDepth-03679", "VUID-vkCmdTraceRaysNV-maxRecursionDepth-03625"},
  };
  if (std::strcmp(fn, "vkCmdTraceRaysNV") != 0) return khr;
  for (const auto& [k, n] : kNv)
    if (std::strcmp(k, khr) == 0) return n;
  return khr;
}

const char* const kRegionNames[4] = {"raygen", "miss", "hit", "callable"};

// The four regions of a trace command, in exec::SbtRegion order.
struct SbtRegions {
  VkStridedDeviceAddressRegionKHR r[4] = {};
};

// The VUIDs of the region rules for one command (vkCmdTraceRaysKHR, ...IndirectKHR, VkTraceRaysIndirectCommand2KHR).
struct RegionVuids {
  const char* baseAlign[4];    // deviceAddress multiple of shaderGroupBaseAlignment
  const char* strideAlign[4];  // stride multiple of shaderGroupHandleAlignment (miss, hit, callable)
  const char* strideMax[4];    // stride <= maxShaderGroupStride
  const char* memory[4];       // the region lies in device memory bound to a buffer
  const char* raygenSize;      // raygen size == stride
  const char* size[3];         // width, height, depth limits
  const char* invocations;     // width * height * depth limit
};

#define VKRT_REGION_VUIDS(P)                                                                                          \
  {                                                                                                                   \
    {P "-pRayGenShaderBindingTable-03682", P "-pMissShaderBindingTable-03685", P "-pHitShaderBindingTable-03689",     \
     P "-pCallableShaderBindingTable-03693"},                                                                         \
        {nullptr, P "-stride-03686", P "-stride-03690", P "-stride-03694"},                                           \
        {nullptr, P "-stride-04029", P "-stride-04035", P "-stride-04041"},                                           \
        {P "-pRayGenShaderBindingTable-03680", P "-pMissShaderBindingTable-03683", P "-pHitShaderBindingTable-03687", \
         P "-pCallableShaderBindingTable-03691"},                                                                     \
        P "-size-04023", {P "-width-03638", P "-height-03639", P "-depth-03640"}, P "-width-03641"                    \
  }

const RegionVuids kDirectVuids = VKRT_REGION_VUIDS("VUID-vkCmdTraceRaysKHR");
const RegionVuids kIndirectVuids = VKRT_REGION_VUIDS("VUID-vkCmdTraceRaysIndirectKHR");
const RegionVuids kIndirect2Vuids = VKRT_REGION_VUIDS("VUID-VkTraceRaysIndirectCommand2KHR");
#undef VKRT_REGION_VUIDS

// The record-time (for the indirect form 2: read-time) rules of the SBT regions. Reports against `about`.
bool checkRegions(const Object* about, const char* fn, const SbtRegions& s, const RegionVuids& v) {
  const VkPhysicalDeviceRayTracingPipelinePropertiesKHR props = rayTracingPipelineProperties();
  for (int i = 0; i < 4; ++i) {
    const VkStridedDeviceAddressRegionKHR& r = s.r[i];
    if (r.deviceAddress == 0 && i != 0) continue;  // an unused region (raygen is always used)
    if (r.deviceAddress % props.shaderGroupBaseAlignment) {
      report(about, Severity::Error, v.baseAlign[i],
             "%s: the %s region's deviceAddress 0x%llx is not a multiple of shaderGroupBaseAlignment (%u)", fn,
             kRegionNames[i], (ull)r.deviceAddress, props.shaderGroupBaseAlignment);
      return false;
    }
    if (i != 0 && r.stride % props.shaderGroupHandleAlignment) {
      report(about, Severity::Error, v.strideAlign[i],
             "%s: the %s region's stride %llu is not a multiple of shaderGroupHandleAlignment (%u)", fn,
             kRegionNames[i], (ull)r.stride, props.shaderGroupHandleAlignment);
      return false;
    }
    if (i != 0 && r.stride > props.maxShaderGroupStride) {
      report(about, Severity::Error, v.strideMax[i],
             "%s: the %s region's stride %llu exceeds maxShaderGroupStride (%u)", fn, kRegionNames[i], (ull)r.stride,
             props.maxShaderGroupStride);
      return false;
    }
    if (i == 0 && r.size != r.stride) {
      report(about, Severity::Error, v.raygenSize,
             "%s: the raygen region's size (%llu) is not equal to its stride (%llu)", fn, (ull)r.size, (ull)r.stride);
      return false;
    }
    // The executor reads the records: every byte of the region must be device memory (a wild address is
    // reported here instead of faulting on a worker thread).
    if (r.size && !arena::accessible(r.deviceAddress, r.size)) {
      report(about, Severity::Error, v.memory[i],
             "%s: the %s region [0x%llx, 0x%llx) is not inside device memory bound to a buffer; the launch is skipped",
             fn, kRegionNames[i], (ull)r.deviceAddress, (ull)(r.deviceAddress + r.size));
      return false;
    }
  }
  return true;
}

bool checkLaunchSize(const Object* about, const char* fn, const uint32_t size[3], const RegionVuids& v,
                     const Device* dev) {
  const VkPhysicalDeviceLimits& l = dev->physicalDevice->properties10.limits;
  for (int k = 0; k < 3; ++k) {
    uint64_t max = uint64_t(l.maxComputeWorkGroupCount[k]) * l.maxComputeWorkGroupSize[k];
    if (size[k] > max) {
      report(about, Severity::Error, v.size[k],
             "%s: %s (%u) exceeds maxComputeWorkGroupCount[%d] x maxComputeWorkGroupSize[%d] (%llu)", fn,
             k == 0   ? "width"
             : k == 1 ? "height"
                      : "depth",
             size[k], k, k, (ull)max);
      return false;
    }
  }
  uint64_t n = uint64_t(size[0]) * size[1] * size[2];
  if (n > rayTracingPipelineProperties().maxRayDispatchInvocationCount) {
    report(about, Severity::Error, v.invocations,
           "%s: width x height x depth (%llu) exceeds maxRayDispatchInvocationCount (%u)", fn, (ull)n,
           rayTracingPipelineProperties().maxRayDispatchInvocationCount);
    return false;
  }
  return true;
}

const char* stageName(VkShaderStageFlagBits stage) {
  switch (stage) {
    case VK_SHADER_STAGE_RAYGEN_BIT_KHR: return "raygen";
    case VK_SHADER_STAGE_MISS_BIT_KHR: return "miss";
    case VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR: return "closest-hit";
    case VK_SHADER_STAGE_ANY_HIT_BIT_KHR: return "any-hit";
    case VK_SHADER_STAGE_INTERSECTION_BIT_KHR: return "intersection";
    default: return "callable";
  }
}

// A short description of a group for reports: its type and its shaders' entry points.
std::string describe(const GroupRecord& g) {
  static const char* const kTypes[] = {"general", "triangles hit", "procedural hit"};
  static const char* const kSlots[] = {"general", "closest-hit", "any-hit", "intersection"};
  std::string s = std::string(kTypes[std::min<uint32_t>(g.desc.type, 2)]) + " group (";
  bool first = true;
  for (int k = 0; k < 4; ++k) {
    if (!g.desc.shaders[k]) continue;
    s += (first ? "" : ", ") + std::string(kSlots[k]) + " \"" + g.desc.shaders[k]->entry + "\"";
    first = false;
  }
  return s + ")";
}

// One execution of a trace command: the pipeline's groups with this launch's resources, the resolver the
// executor calls, and the report-once bookkeeping.
class Launch final : public exec::LaunchResolver {
 public:
  Launch(const CommandBuffer* cb, const char* fn, RayTracingPipeline* pipeline)
      : cb_(cb), fn_(fn), pipeline_(pipeline), dev_(cb->device) {}

  void run(const ExecState& st, const SbtRegions& sbt, const uint32_t size[3]);

  const exec::RayGroup* group(exec::SbtRegion region, uint64_t index, const uint8_t* record) override;
  void recordOutsideRegion(exec::SbtRegion region, uint64_t index, uint64_t stride, uint64_t size) override;
  void recordDataOutsideRegion(exec::SbtRegion region, uint64_t index, uint64_t offset, uint64_t bytes,
                               uint64_t regionBytes, uint64_t readableBytes, const exec::RayShader& reader) override;
  void hitGroupMismatch(uint64_t index, const exec::RayGroup& group, bool triangles) override;
  void recursionTooDeep(uint32_t depth, uint32_t maxDepth, const exec::RayShader& caller) override;
  void stackExceeded(const exec::RayShader* const* chain, uint32_t n, uint64_t needed, uint64_t stackSize) override;

 protected:
  // The acceleration structures the launch reaches (exec::TopLevelResolver, which resolves each once).
  void snapshot(Snapshot* out) override { snapshotTopLevels(dev_, out); }
  std::shared_ptr<const accel::Tlas> resolve(uint64_t address) override { return topLevelAt(dev_, address); }
  void missed(uint64_t address) override;

 private:
  enum Rule {
    kUnknownHandle,
    kForeignHandle,
    kWrongKind,
    kNullShader,
    kOutside,
    kMismatch,
    kRecursion,
    kStack,
    kRuleCount
  };
  // True the first time `rule` is reported in this launch.
  bool first(Rule rule) { return !reported_[rule].exchange(true); }
  void prepareGroups(const BindState& bs);
  exec::RayShader shaderOf(const std::shared_ptr<const ShaderDesc>& d, const BindState& bs);
  const exec::RayGroup* checkKind(exec::SbtRegion region, uint64_t index, const uint8_t* record, uint32_t g);

  const CommandBuffer* cb_;
  const char* fn_;
  RayTracingPipeline* pipeline_;
  Device* dev_;
  std::vector<exec::RayGroup> groups_;                      // by pipeline group index
  std::unordered_map<const GroupRecord*, uint32_t> index_;  // group record -> pipeline group index
  std::unordered_map<const spirv::CompiledShader*, BoundResources> resources_;
  std::deque<std::string> names_;  // RayShader::name storage
  std::atomic<bool> reported_[kRuleCount] = {};
  bool allCheckAdds_ = true;  // every shader of the groups was compiled with combined adds (prepareGroups)
};

exec::RayShader Launch::shaderOf(const std::shared_ptr<const ShaderDesc>& d, const BindState& bs) {
  exec::RayShader s;
  if (!d || !d->compiled) return s;
  const spirv::CompiledShader& code = *d->compiled;
  auto [it, fresh] = resources_.try_emplace(&code);
  if (fresh) it->second.resolve(code, bs, cb_, fn_, launchVuid(fn_, "VUID-vkCmdTraceRaysKHR-None-02697"));
  s.entry = code.rayEntry;
  if (code.rayBatchEntry && code.spmdLanes) {
    s.batch = code.rayBatchEntry;
    s.batchLanes = code.spmdLanes;
  }
  allCheckAdds_ = allCheckAdds_ && code.ray.checksPendingAdds;
  s.resources = it->second.slots();
  s.stackSize = d->stackSize();
  s.readsTransforms = d->readsTransforms;
  s.readsPositions = d->readsPositions;
  names_.push_back(std::string(stageName(d->stage)) + " shader \"" + d->entry + "\"");
  s.name = names_.back().c_str();
  return s;
}

void Launch::prepareGroups(const BindState& bs) {
  groups_.resize(pipeline_->groups.size());
  allCheckAdds_ = true;
  for (uint32_t i = 0; i < pipeline_->groups.size(); ++i) {
    const GroupRecord* r = pipeline_->groups[i];
    index_.emplace(r, i);
    exec::RayGroup& g = groups_[i];
    g.id = r;
    g.index = i;
    switch (r->desc.type) {
      case VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR: g.type = exec::RayGroup::General; break;
      case VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR: g.type = exec::RayGroup::Triangles; break;
      default: g.type = exec::RayGroup::Procedural; break;
    }
    g.general = shaderOf(r->desc.shaders[kGeneral], bs);
    g.closestHit = shaderOf(r->desc.shaders[kClosestHit], bs);
    g.anyHit = shaderOf(r->desc.shaders[kAnyHit], bs);
    g.intersection = shaderOf(r->desc.shaders[kIntersection], bs);
  }
}

void Launch::run(const ExecState& st, const SbtRegions& sbt, const uint32_t size[3]) {
  prepareGroups(st.rayTracing);
  exec::RayLaunch l;
  // Adds are combined where every shader the launch can run checks its accesses against the pending word (a
  // pipeline with such adds compiles all its stages so; a library compiled without them turns it off).
  l.combineAdds = allCheckAdds_;
  for (int k = 0; k < 3; ++k) l.size[k] = size[k];
  exec::SbtRange* ranges[4] = {&l.raygen, &l.miss, &l.hit, &l.callable};
  for (int i = 0; i < 4; ++i) {
    ranges[i]->base = reinterpret_cast<const uint8_t*>(sbt.r[i].deviceAddress);
    ranges[i]->stride = sbt.r[i].stride;
    ranges[i]->size = sbt.r[i].deviceAddress ? sbt.r[i].size : 0;
    // The last record's stride-worth of data, when that memory is allocated (exec::SbtRange::readable).
    const uint64_t size = ranges[i]->size, stride = ranges[i]->stride;
    ranges[i]->readable = size;
    if (size >= kHandleSize && stride > 0) {
      const uint64_t extent = (size - kHandleSize) / stride * stride + stride;
      if (extent > size && arena::accessible(sbt.r[i].deviceAddress, extent)) ranges[i]->readable = extent;
    }
  }
  // The raygen record: one record, resolved before the launch (no raygen, no launch).
  // Its size equals its stride (VUID-...-size-04023, checked when recorded) and bounds the bytes read ("Indexing
  // Rules": "All data accessed must be less than pRaygenShaderBindingTable->size bytes from deviceAddress"), so
  // a region smaller than a handle breaks a rule without a VUID.
  if (sbt.r[0].size < kHandleSize) {
    report(cb_, Severity::Error, nullptr,
           "%s: the raygen region (%llu bytes) cannot hold a shader group handle (%u bytes), and the specification "
           "(Shader Binding Table, Indexing Rules) requires all data accessed to lie less than size bytes from its "
           "deviceAddress; the launch is skipped",
           fn_, (ull)sbt.r[0].size, kHandleSize);
    return;
  }
  l.raygenGroup = group(exec::SbtRegion::Raygen, 0, l.raygen.base);
  if (!l.raygenGroup) return;
  l.maxRecursionDepth = pipeline_->maxRecursionDepth;
  l.stackSize = pipeline_->dynamicStackSize ? st.rayTracingStackSize : pipeline_->defaultStackSize;
  if (pipeline_->createFlags & VK_PIPELINE_CREATE_RAY_TRACING_SKIP_TRIANGLES_BIT_KHR)
    l.pipelineRayFlags |= accel::kRaySkipTriangles;
  if (pipeline_->createFlags & VK_PIPELINE_CREATE_RAY_TRACING_SKIP_AABBS_BIT_KHR)
    l.pipelineRayFlags |= accel::kRaySkipAabbs;
  l.pushConstants = st.pushConstants;
  l.resolver = this;
  // Supervised, as dispatches are (runtime/dispatch_commands.cpp says why the job comes before the check).
  Device* dev = cb_->device;
  exec::Job job(dev, dev->shaderTimeoutMs);
  if (dev->halted()) return;
  l.job = &job;
  // VKRT_RAY_TREE: a recorder only when the setting names launch ids (decided here, once per launch).
  std::unique_ptr<exec::RayTreeRecorder> rayTree = rayTreeRecorder(dev, false);
  l.rayTree = rayTree.get();
  exec::runRays(l);
  if (job.aborted()) dev->shaderAborted(pipeline_, fn_, job.abort());
  // The launch's shaders read the same bound sets: whichever uses the binding names its descriptor.
  deliverShaderMessages(cb_, pipeline_, fn_, job.messages, [this](uint32_t set, uint32_t binding, uint64_t element) {
    for (auto& [code, bound] : resources_) {
      std::string name = descriptorNamer(*code, bound.slots())(set, binding, element);
      if (!name.empty()) return name;
    }
    return std::string();
  });
  if (rayTree) {
    exec::RayTreeContext ctx;
    ctx.command = fn_;
    ctx.pipeline = pipeline_->handleValue();
    for (int k = 0; k < 3; ++k) ctx.size[k] = size[k];
    deliverRayTrees(cb_, dev, *rayTree, std::move(ctx), false);
  }
}

const exec::RayGroup* Launch::checkKind(exec::SbtRegion region, uint64_t index, const uint8_t* record, uint32_t g) {
  const exec::RayGroup& group = groups_[g];
  const GroupRecord& r = *pipeline_->groups[g];
  static const VkShaderStageFlagBits kGeneralStage[] = {VK_SHADER_STAGE_RAYGEN_BIT_KHR, VK_SHADER_STAGE_MISS_BIT_KHR,
                                                        VkShaderStageFlagBits(0), VK_SHADER_STAGE_CALLABLE_BIT_KHR};
  const int ri = int(region);
  bool ok = region == exec::SbtRegion::Hit ? group.type != exec::RayGroup::General
                                           : group.type == exec::RayGroup::General && r.desc.shaders[kGeneral] &&
                                                 r.desc.shaders[kGeneral]->stage == kGeneralStage[ri];
  if (!ok) {
    if (first(kWrongKind))
      report(
          cb_, Severity::Error, launchVuid(fn_, "VUID-vkCmdTraceRaysKHR-None-03429"),
          "%s: %s record %llu at 0x%llx holds the handle of pipeline group %u, a %s, which does not belong in the %s "
          "region; it is not run",
          fn_, kRegionNames[ri], (ull)index, (ull) reinterpret_cast<uintptr_t>(record), g, describe(r).c_str(),
          kRegionNames[ri]);
    return nullptr;
  }
  // VUID-vkCmdTraceRaysKHR-flags-03512, -03513, -03514: no null any-hit / closest-hit / intersection shaders.
  if (region == exec::SbtRegion::Hit) {
    const VkPipelineCreateFlags f = pipeline_->createFlags;
    const char* vuid = nullptr;
    const char* what = nullptr;
    if ((f & VK_PIPELINE_CREATE_RAY_TRACING_NO_NULL_ANY_HIT_SHADERS_BIT_KHR) && !group.anyHit.entry) {
      vuid = "VUID-vkCmdTraceRaysKHR-flags-03512";
      what = "any-hit";
    } else if ((f & VK_PIPELINE_CREATE_RAY_TRACING_NO_NULL_CLOSEST_HIT_SHADERS_BIT_KHR) && !group.closestHit.entry) {
      vuid = "VUID-vkCmdTraceRaysKHR-flags-03513";
      what = "closest-hit";
    } else if ((f & VK_PIPELINE_CREATE_RAY_TRACING_NO_NULL_INTERSECTION_SHADERS_BIT_KHR) &&
               group.type == exec::RayGroup::Procedural && !group.intersection.entry) {
      vuid = "VUID-vkCmdTraceRaysKHR-flags-03514";
      what = "intersection";
    }
    if (vuid) {
      if (first(kNullShader))
        report(cb_, Severity::Error, vuid,
               "%s: hit record %llu holds pipeline group %u, a %s without a %s shader, but the "
               "pipeline was created with NO_NULL_%s_SHADERS; it is not run",
               fn_, (ull)index, g, describe(r).c_str(), what,
               what[0] == 'a'   ? "ANY_HIT"
               : what[0] == 'c' ? "CLOSEST_HIT"
                                : "INTERSECTION");
      return nullptr;
    }
  }
  return &group;
}

const exec::RayGroup* Launch::group(exec::SbtRegion region, uint64_t index, const uint8_t* record) {
  static const exec::RayGroup kEmpty{};
  const int ri = int(region);
  static const uint8_t kZero[kHandleSize] = {};
  if (std::memcmp(record, kZero, kHandleSize) == 0) {
    // A zero handle: no shader. Not allowed for raygen, nor where NO_NULL_* flags forbid it.
    const VkPipelineCreateFlags f = pipeline_->createFlags;
    const char* vuid = nullptr;
    if (region == exec::SbtRegion::Raygen) vuid = launchVuid(fn_, "VUID-vkCmdTraceRaysKHR-None-03429");
    if (region == exec::SbtRegion::Miss && (f & VK_PIPELINE_CREATE_RAY_TRACING_NO_NULL_MISS_SHADERS_BIT_KHR))
      vuid = "VUID-vkCmdTraceRaysKHR-flags-03511";
    if (region == exec::SbtRegion::Hit && (f & VK_PIPELINE_CREATE_RAY_TRACING_NO_NULL_CLOSEST_HIT_SHADERS_BIT_KHR))
      vuid = "VUID-vkCmdTraceRaysKHR-flags-03513";
    if (region == exec::SbtRegion::Hit && (f & VK_PIPELINE_CREATE_RAY_TRACING_NO_NULL_ANY_HIT_SHADERS_BIT_KHR))
      vuid = "VUID-vkCmdTraceRaysKHR-flags-03512";
    if (!vuid) return &kEmpty;
    if (first(kNullShader))
      report(
          cb_, Severity::Error, vuid,
          "%s: %s record %llu at 0x%llx holds a zero (null) handle, which the %s; it is not run", fn_, kRegionNames[ri],
          (ull)index, (ull) reinterpret_cast<uintptr_t>(record),
          region == exec::SbtRegion::Raygen ? "raygen region may not hold" : "bound pipeline's NO_NULL_* flags forbid");
    return nullptr;
  }
  const GroupRecord* r = registryOf(dev_).decode(record);
  if (!r) {
    if (first(kUnknownHandle)) {
      char bytes[2 * 8 + 1];
      for (int k = 0; k < 8; ++k) std::snprintf(bytes + 2 * k, 3, "%02x", record[k]);
      report(
          cb_, Severity::Error, launchVuid(fn_, "VUID-vkCmdTraceRaysKHR-None-03429"),
          "%s: %s record %llu at 0x%llx (region stride %s) does not hold a shader group handle of this device (first "
          "bytes %s...): it was not written from vkGetRayTracingShaderGroupHandlesKHR, or is corrupt; it is not run",
          fn_, kRegionNames[ri], (ull)index, (ull) reinterpret_cast<uintptr_t>(record),
          region == exec::SbtRegion::Raygen ? "n/a" : "as given", bytes);
    }
    return nullptr;
  }
  auto it = index_.find(r);
  if (it == index_.end()) {
    if (first(kForeignHandle)) {
      uint64_t origin = r->firstPipeline;
      report(cb_, Severity::Error, launchVuid(fn_, "VUID-vkCmdTraceRaysKHR-None-03429"),
             "%s: %s record %llu at 0x%llx holds the handle of a %s created in pipeline 0x%llx, which is neither the "
             "bound "
             "pipeline 0x%llx nor one of its libraries; it is not run",
             fn_, kRegionNames[ri], (ull)index, (ull) reinterpret_cast<uintptr_t>(record), describe(*r).c_str(),
             (ull)origin, (ull)pipeline_->handleValue());
    }
    return nullptr;
  }
  return checkKind(region, index, record, it->second);
}

void Launch::missed(uint64_t address) {
  report(cb_, Severity::Error, nullptr,
         "%s: traceRayEXT or rayQueryInitializeEXT was given the acceleration structure address 0x%llx, which is "
         "not the address of a built top-level acceleration structure of this device; those rays miss (those ray "
         "queries find no intersection)",
         fn_, (ull)address);
}

// The record's extent is not a VUID: "Shader Binding Table" > "Indexing Rules" states, for each region, that "all
// data accessed must be less than size bytes from the base address", and the handle (shaderGroupHandleSize bytes
// at the record's start) is always accessed. The stride may exceed the size: only the handle must fit. (None-03429
// is about where a handle came from, not where it lies.) So the report names the rule by its section.
void Launch::recordOutsideRegion(exec::SbtRegion region, uint64_t index, uint64_t stride, uint64_t size) {
  if (!first(kOutside)) return;
  report(cb_, Severity::Error, nullptr,
         "%s: %s record %llu (at offset %llu = %llu x stride %llu) lies outside its region of %llu bytes: its shader "
         "group handle (%u bytes) is not inside the region, and the specification (Shader Binding Table, Indexing "
         "Rules) requires all data accessed to lie less than size bytes from the region's start; it is not run (the "
         "SBT record index is instance SBT offset + sbtRecordOffset + sbtRecordStride x geometry index for hits, "
         "missIndex for misses)",
         fn_, kRegionNames[int(region)], (ull)index, (ull)(index * stride), (ull)index, (ull)stride, (ull)size,
         kHandleSize);
}

// The same rule for the shader record data a shader reads (the compiled code checks each read; the executor
// reports each record once per launch). The read is not refused: it returns the bytes up to the stride where they
// are the application's memory, as GPUs do, and zeros past them.
void Launch::recordDataOutsideRegion(exec::SbtRegion region, uint64_t index, uint64_t offset, uint64_t bytes,
                                     uint64_t regionBytes, uint64_t readableBytes, const exec::RayShader& reader) {
  const uint64_t end = offset + bytes;
  report(cb_, Severity::Error, nullptr,
         "%s: the %s, run for %s record %llu, reads its shader record data at bytes [%llu, %llu) (after the "
         "%u-byte handle), past the end of the %s region (the record has %llu bytes of data inside it): the "
         "specification (Shader Binding Table, Indexing Rules) requires all data accessed to lie less than size "
         "bytes from the region's start; the read returns %s",
         fn_, reader.name, kRegionNames[int(region)], (ull)index, (ull)offset, (ull)end, kHandleSize,
         kRegionNames[int(region)], (ull)regionBytes,
         end <= readableBytes ? "the bytes there (the application's memory, inside the record's stride)"
                              : "zeros where it passes the record's stride or the application's memory");
}

void Launch::hitGroupMismatch(uint64_t index, const exec::RayGroup& group, bool triangles) {
  if (!first(kMismatch)) return;
  const GroupRecord* r = static_cast<const GroupRecord*>(group.id);
  report(cb_, Severity::Error,
         triangles ? "VUID-vkCmdTraceRaysKHR-pHitShaderBindingTable-04735"
                   : "VUID-vkCmdTraceRaysKHR-pHitShaderBindingTable-04736",
         "%s: hit record %llu, used for a hit on %s geometry, holds a %s; it is not run", fn_, (ull)index,
         triangles ? "triangle" : "AABB", r ? describe(*r).c_str() : "group of another kind");
}

void Launch::recursionTooDeep(uint32_t depth, uint32_t maxDepth, const exec::RayShader& caller) {
  if (!first(kRecursion)) return;
  report(cb_, Severity::Error, launchVuid(fn_, "VUID-vkCmdTraceRaysKHR-maxPipelineRayRecursionDepth-03679"),
         "%s: shader %s calls traceRayEXT at recursion depth %u, deeper than the bound pipeline's "
         "maxPipelineRayRecursionDepth (%u); that trace is not run",
         fn_, caller.name, depth, maxDepth);
}

void Launch::stackExceeded(const exec::RayShader* const* chain, uint32_t n, uint64_t needed, uint64_t stackSize) {
  if (!first(kStack)) return;
  std::string text;
  for (uint32_t i = 0; i < n; ++i)
    text += (i ? " -> " : "") + std::string(chain[i]->name) + " [" + std::to_string(chain[i]->stackSize) + "]";
  report(cb_, Severity::Error,
         pipeline_->dynamicStackSize ? "VUID-vkCmdSetRayTracingPipelineStackSizeKHR-pipelineStackSize-03610" : nullptr,
         "%s: the call chain %s (depth %u) needs %llu bytes of stack, more than the pipeline stack size %llu (%s); the "
         "last "
         "shader is not run",
         fn_, text.c_str(), n, (ull)needed, (ull)stackSize,
         pipeline_->dynamicStackSize ? "set with vkCmdSetRayTracingPipelineStackSizeKHR" : "the pipeline's default");
}

// Executes a trace command with the state bound at execution.
void execute(const CommandBuffer* cb, const ExecState& st, const SbtRegions& sbt, const uint32_t size[3],
             const char* fn) {
  RayTracingPipeline* p = asRayTracing(st.rayTracing.pipeline);
  // VUID-vkCmdTraceRaysKHR-None-02700
  if (!p) {
    report(cb, Severity::Error, launchVuid(fn, "VUID-vkCmdTraceRaysKHR-None-02700"),
           "%s: no ray tracing pipeline is bound; the launch is skipped", fn);
    return;
  }
  if (size[0] == 0 || size[1] == 0 || size[2] == 0) return;
  Launch launch(cb, fn, p);
  launch.run(st, sbt, size);
}

SbtRegions regionsOf(const VkStridedDeviceAddressRegionKHR* raygen, const VkStridedDeviceAddressRegionKHR* miss,
                     const VkStridedDeviceAddressRegionKHR* hit, const VkStridedDeviceAddressRegionKHR* callable) {
  SbtRegions s;
  const VkStridedDeviceAddressRegionKHR* in[4] = {raygen, miss, hit, callable};
  for (int i = 0; i < 4; ++i)
    if (in[i]) s.r[i] = *in[i];
  return s;
}

// The checks of an indirect command's address (VkTraceRaysIndirectCommandKHR or ...2KHR, `bytes` long).
bool checkIndirect(CommandBuffer* cb, const char* fn, const char* vuidPrefix, VkDeviceAddress address, uint64_t bytes,
                   const char* featureVuid, bool enabled) {
  if (!enabled) {
    report(cb, Severity::Error, featureVuid, "%s: the feature it needs is not enabled", fn);
    return false;
  }
  // VUID-vkCmdTraceRaysIndirectKHR-indirectDeviceAddress-03634
  if (address % 4) {
    report(cb, Severity::Error, (std::string(vuidPrefix) + "-indirectDeviceAddress-03634").c_str(),
           "%s: indirectDeviceAddress 0x%llx is not a multiple of 4", fn, (ull)address);
    return false;
  }
  // VUID-vkCmdTraceRaysIndirectKHR-indirectDeviceAddress-03636
  if (!arena::accessible(address, bytes)) {
    report(cb, Severity::Error, (std::string(vuidPrefix) + "-indirectDeviceAddress-03636").c_str(),
           "%s: the %llu bytes at indirectDeviceAddress 0x%llx are not inside device memory bound to a buffer", fn,
           (ull)bytes, (ull)address);
    return false;
  }
  return true;
}

}  // namespace
}  // namespace vkrt::rt

using namespace vkrt;
using namespace vkrt::rt;

extern "C" {

VKAPI_ATTR void VKAPI_CALL vkrt_CmdTraceRaysKHR(VkCommandBuffer commandBuffer,
                                                const VkStridedDeviceAddressRegionKHR* pRaygenShaderBindingTable,
                                                const VkStridedDeviceAddressRegionKHR* pMissShaderBindingTable,
                                                const VkStridedDeviceAddressRegionKHR* pHitShaderBindingTable,
                                                const VkStridedDeviceAddressRegionKHR* pCallableShaderBindingTable,
                                                uint32_t width, uint32_t height, uint32_t depth) {
  const char* fn = "vkCmdTraceRaysKHR";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  SbtRegions sbt = regionsOf(pRaygenShaderBindingTable, pMissShaderBindingTable, pHitShaderBindingTable,
                             pCallableShaderBindingTable);
  const uint32_t size[3] = {width, height, depth};
  if (!checkRegions(cb, fn, sbt, kDirectVuids) || !checkLaunchSize(cb, fn, size, kDirectVuids, cb->device)) return;
  cb->record([cb, sbt, w = width, h = height, d = depth](ExecState& st) {
    const uint32_t s[3] = {w, h, d};
    execute(cb, st, sbt, s, "vkCmdTraceRaysKHR");
  });
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdTraceRaysIndirectKHR(
    VkCommandBuffer commandBuffer, const VkStridedDeviceAddressRegionKHR* pRaygenShaderBindingTable,
    const VkStridedDeviceAddressRegionKHR* pMissShaderBindingTable,
    const VkStridedDeviceAddressRegionKHR* pHitShaderBindingTable,
    const VkStridedDeviceAddressRegionKHR* pCallableShaderBindingTable, VkDeviceAddress indirectDeviceAddress) {
  const char* fn = "vkCmdTraceRaysIndirectKHR";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  SbtRegions sbt = regionsOf(pRaygenShaderBindingTable, pMissShaderBindingTable, pHitShaderBindingTable,
                             pCallableShaderBindingTable);
  // VUID-vkCmdTraceRaysIndirectKHR-rayTracingPipelineTraceRaysIndirect-03637
  if (!checkIndirect(cb, fn, "VUID-vkCmdTraceRaysIndirectKHR", indirectDeviceAddress,
                     sizeof(VkTraceRaysIndirectCommandKHR),
                     "VUID-vkCmdTraceRaysIndirectKHR-rayTracingPipelineTraceRaysIndirect-03637",
                     cb->device->enabled(Feature::rayTracingPipelineTraceRaysIndirect)) ||
      !checkRegions(cb, fn, sbt, kIndirectVuids))
    return;
  cb->record([cb, sbt, indirectDeviceAddress](ExecState& st) {
    const char* fn = "vkCmdTraceRaysIndirectKHR";
    if (!arena::accessible(indirectDeviceAddress, sizeof(VkTraceRaysIndirectCommandKHR))) {
      report(cb, Severity::Error, "VUID-vkCmdTraceRaysIndirectKHR-indirectDeviceAddress-03636",
             "%s: the parameters at 0x%llx are no longer in device memory; the launch is skipped", fn,
             (ull)indirectDeviceAddress);
      return;
    }
    VkTraceRaysIndirectCommandKHR c;
    std::memcpy(&c, reinterpret_cast<const void*>(indirectDeviceAddress), sizeof c);
    const uint32_t s[3] = {c.width, c.height, c.depth};
    static const RegionVuids kCommandVuids = [] {
      RegionVuids v = kIndirectVuids;
      v.size[0] = "VUID-VkTraceRaysIndirectCommandKHR-width-03638";
      v.size[1] = "VUID-VkTraceRaysIndirectCommandKHR-height-03639";
      v.size[2] = "VUID-VkTraceRaysIndirectCommandKHR-depth-03640";
      v.invocations = "VUID-VkTraceRaysIndirectCommandKHR-width-03641";
      return v;
    }();
    if (!checkLaunchSize(cb, fn, s, kCommandVuids, cb->device)) return;
    execute(cb, st, sbt, s, fn);
  });
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdTraceRaysIndirect2KHR(VkCommandBuffer commandBuffer,
                                                         VkDeviceAddress indirectDeviceAddress) {
  const char* fn = "vkCmdTraceRaysIndirect2KHR";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  if (!checkIndirect(cb, fn, "VUID-vkCmdTraceRaysIndirect2KHR", indirectDeviceAddress,
                     sizeof(VkTraceRaysIndirectCommand2KHR),
                     "VUID-vkCmdTraceRaysIndirect2KHR-rayTracingPipelineTraceRaysIndirect2-03637",
                     cb->device->enabled(Feature::rayTracingPipelineTraceRaysIndirect2)))
    return;
  cb->record([cb, indirectDeviceAddress](ExecState& st) {
    const char* fn = "vkCmdTraceRaysIndirect2KHR";
    if (!arena::accessible(indirectDeviceAddress, sizeof(VkTraceRaysIndirectCommand2KHR))) {
      report(cb, Severity::Error, "VUID-vkCmdTraceRaysIndirect2KHR-indirectDeviceAddress-03636",
             "%s: the parameters at 0x%llx are no longer in device memory; the launch is skipped", fn,
             (ull)indirectDeviceAddress);
      return;
    }
    VkTraceRaysIndirectCommand2KHR c;
    std::memcpy(&c, reinterpret_cast<const void*>(indirectDeviceAddress), sizeof c);
    SbtRegions sbt;
    sbt.r[0] = {c.raygenShaderRecordAddress, c.raygenShaderRecordSize, c.raygenShaderRecordSize};
    sbt.r[1] = {c.missShaderBindingTableAddress, c.missShaderBindingTableStride, c.missShaderBindingTableSize};
    sbt.r[2] = {c.hitShaderBindingTableAddress, c.hitShaderBindingTableStride, c.hitShaderBindingTableSize};
    sbt.r[3] = {c.callableShaderBindingTableAddress, c.callableShaderBindingTableStride,
                c.callableShaderBindingTableSize};
    const uint32_t s[3] = {c.width, c.height, c.depth};
    if (!checkRegions(cb, fn, sbt, kIndirect2Vuids) || !checkLaunchSize(cb, fn, s, kIndirect2Vuids, cb->device)) return;
    execute(cb, st, sbt, s, fn);
  });
}

// The NV form names each SBT region by a buffer, an offset and a stride. Its rules are checked here under their NV
// VUIDs; the region each becomes (the buffer's address + offset, the stride, and the rest of the buffer as its size:
// the NV form has no region sizes) then goes through the KHR launch, whose record checks and decoding are the same.
VKAPI_ATTR void VKAPI_CALL vkrt_CmdTraceRaysNV(
    VkCommandBuffer commandBuffer, VkBuffer raygenShaderBindingTableBuffer, VkDeviceSize raygenShaderBindingOffset,
    VkBuffer missShaderBindingTableBuffer, VkDeviceSize missShaderBindingOffset, VkDeviceSize missShaderBindingStride,
    VkBuffer hitShaderBindingTableBuffer, VkDeviceSize hitShaderBindingOffset, VkDeviceSize hitShaderBindingStride,
    VkBuffer callableShaderBindingTableBuffer, VkDeviceSize callableShaderBindingOffset,
    VkDeviceSize callableShaderBindingStride, uint32_t width, uint32_t height, uint32_t depth) {
  const char* fn = "vkCmdTraceRaysNV";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  const VkPhysicalDeviceRayTracingPropertiesNV props = rayTracingPropertiesNV();
  struct In {
    VkBuffer buffer;
    VkDeviceSize offset, stride;
    const char *bufferParam, *memory, *offsetSize, *offsetAlign, *strideAlign, *strideMax;
  };
  const In in[4] = {
      {raygenShaderBindingTableBuffer, raygenShaderBindingOffset, 0,
       "VUID-vkCmdTraceRaysNV-raygenShaderBindingTableBuffer-parameter",
       "VUID-vkCmdTraceRaysNV-raygenShaderBindingTableBuffer-04042",
       "VUID-vkCmdTraceRaysNV-raygenShaderBindingOffset-02455", "VUID-vkCmdTraceRaysNV-raygenShaderBindingOffset-02456",
       nullptr, nullptr},
      {missShaderBindingTableBuffer, missShaderBindingOffset, missShaderBindingStride,
       "VUID-vkCmdTraceRaysNV-missShaderBindingTableBuffer-parameter",
       "VUID-vkCmdTraceRaysNV-missShaderBindingTableBuffer-04043",
       "VUID-vkCmdTraceRaysNV-missShaderBindingOffset-02457", "VUID-vkCmdTraceRaysNV-missShaderBindingOffset-02458",
       "VUID-vkCmdTraceRaysNV-missShaderBindingStride-02463", "VUID-vkCmdTraceRaysNV-missShaderBindingStride-02466"},
      {hitShaderBindingTableBuffer, hitShaderBindingOffset, hitShaderBindingStride,
       "VUID-vkCmdTraceRaysNV-hitShaderBindingTableBuffer-parameter",
       "VUID-vkCmdTraceRaysNV-hitShaderBindingTableBuffer-04044", "VUID-vkCmdTraceRaysNV-hitShaderBindingOffset-02459",
       "VUID-vkCmdTraceRaysNV-hitShaderBindingOffset-02460", "VUID-vkCmdTraceRaysNV-hitShaderBindingStride-02464",
       "VUID-vkCmdTraceRaysNV-hitShaderBindingStride-02467"},
      {callableShaderBindingTableBuffer, callableShaderBindingOffset, callableShaderBindingStride,
       "VUID-vkCmdTraceRaysNV-callableShaderBindingTableBuffer-parameter",
       "VUID-vkCmdTraceRaysNV-callableShaderBindingTableBuffer-04045",
       "VUID-vkCmdTraceRaysNV-callableShaderBindingOffset-02461",
       "VUID-vkCmdTraceRaysNV-callableShaderBindingOffset-02462",
       "VUID-vkCmdTraceRaysNV-callableShaderBindingStride-02465",
       "VUID-vkCmdTraceRaysNV-callableShaderBindingStride-02468"},
  };
  SbtRegions sbt;
  for (int i = 0; i < 4; ++i) {
    const In& r = in[i];
    if (i != 0 && r.buffer == VK_NULL_HANDLE) continue;  // an unused region
    // VUID-vkCmdTraceRaysNV-raygenShaderBindingTableBuffer-parameter (and the other three)
    Buffer* buf = fromHandle<Buffer>(r.buffer);
    if (!buf) {
      report(cb, Severity::Error, r.bufferParam, "%s: the %s buffer 0x%llx is not a live VkBuffer", fn, kRegionNames[i],
             (ull)rawHandle(r.buffer));
      return;
    }
    // VUID-vkCmdTraceRaysNV-raygenShaderBindingTableBuffer-04042 (-04043, -04044, -04045)
    if (!buf->data()) {
      report(buf, Severity::Error, r.memory, "%s: the %s buffer is not bound to memory", fn, kRegionNames[i]);
      return;
    }
    // VUID-vkCmdTraceRaysNV-raygenShaderBindingOffset-02455 (-02457, -02459, -02461)
    if (r.offset >= buf->size) {
      report(buf, Severity::Error, r.offsetSize, "%s: the %s offset %llu is not less than the buffer's size %llu", fn,
             kRegionNames[i], (ull)r.offset, (ull)buf->size);
      return;
    }
    // VUID-vkCmdTraceRaysNV-raygenShaderBindingOffset-02456 (-02458, -02460, -02462)
    if (r.offset % props.shaderGroupBaseAlignment) {
      report(buf, Severity::Error, r.offsetAlign,
             "%s: the %s offset %llu is not a multiple of VkPhysicalDeviceRayTracingPropertiesNV::"
             "shaderGroupBaseAlignment (%u)",
             fn, kRegionNames[i], (ull)r.offset, props.shaderGroupBaseAlignment);
      return;
    }
    if (i != 0) {
      // VUID-vkCmdTraceRaysNV-missShaderBindingStride-02463 (-02464, -02465)
      if (r.stride % props.shaderGroupHandleSize) {
        report(cb, Severity::Error, r.strideAlign,
               "%s: the %s stride %llu is not a multiple of VkPhysicalDeviceRayTracingPropertiesNV::"
               "shaderGroupHandleSize (%u)",
               fn, kRegionNames[i], (ull)r.stride, props.shaderGroupHandleSize);
        return;
      }
      // VUID-vkCmdTraceRaysNV-missShaderBindingStride-02466 (-02467, -02468)
      if (r.stride > props.maxShaderGroupStride) {
        report(cb, Severity::Error, r.strideMax,
               "%s: the %s stride %llu exceeds VkPhysicalDeviceRayTracingPropertiesNV::maxShaderGroupStride (%u)", fn,
               kRegionNames[i], (ull)r.stride, props.maxShaderGroupStride);
        return;
      }
    }
    VkStridedDeviceAddressRegionKHR& out = sbt.r[i];
    out.deviceAddress = reinterpret_cast<uint64_t>(buf->data()) + r.offset;
    out.size = buf->size - r.offset;
    out.stride = i == 0 ? out.size : r.stride;
  }
  // VUID-vkCmdTraceRaysNV-width-02469, -height-02470, -depth-02471
  const uint32_t size[3] = {width, height, depth};
  const char* sizeVuids[3] = {"VUID-vkCmdTraceRaysNV-width-02469", "VUID-vkCmdTraceRaysNV-height-02470",
                              "VUID-vkCmdTraceRaysNV-depth-02471"};
  const VkPhysicalDeviceLimits& l = cb->device->physicalDevice->properties10.limits;
  for (int k = 0; k < 3; ++k) {
    if (size[k] > l.maxComputeWorkGroupCount[k]) {
      report(cb, Severity::Error, sizeVuids[k], "%s: %s %u exceeds maxComputeWorkGroupCount[%d] (%u)", fn,
             k == 0   ? "width"
             : k == 1 ? "height"
                      : "depth",
             size[k], k, l.maxComputeWorkGroupCount[k]);
      return;
    }
  }
  cb->record([cb, sbt, w = width, h = height, d = depth](ExecState& st) {
    const uint32_t s[3] = {w, h, d};
    execute(cb, st, sbt, s, "vkCmdTraceRaysNV");
  });
}

}  // extern "C"
