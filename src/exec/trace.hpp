// Running a ray tracing launch (vkCmdTraceRaysKHR): the launch grid spread over the thread pool in tiles, the
// raygen shader once per launch index, and the RayRuntime (abi.hpp) the compiled shaders call: traceRayEXT
// through accel::trace with the any-hit and intersection shaders of the shader binding table (SBT), then the
// closest-hit or miss shader; executeCallableEXT; reportIntersectionEXT.
//
// No Vulkan object here: the caller (src/rt) resolves the pipeline's groups, the bound resources and the SBT regions
// into a RayLaunch, and answers, through a LaunchResolver, what needs the device: which group an SBT record's handle
// denotes, which acceleration structure an address is, and the reports. Each record is resolved once per launch and
// cached here (the first 2^20 records of each region; a record past them is resolved at each use, a hash lookup).
// Acceleration structure addresses are resolved by the resolver, once per address and launch (its
// TopLevelResolver part: a range index over the launch's sorted addresses, without a lock or a virtual call). So while
// a launch's records are cached, the per-ray path allocates nothing, takes no lock and makes no hash lookup, however
// many acceleration structures it reaches.
//
// SBT record index of a hit (the specification's formula): instance SBT offset + the trace's sbtRecordOffset +
// sbtRecordStride x geometry index. A record whose handle is all zeros is a group with no shaders (a miss or
// hit that does nothing). Recursion deeper than the pipeline's maxPipelineRayRecursionDepth, and a call chain
// whose shaders' stack sizes add up to more than the pipeline stack size, are reported and not run. A shader record
// read that ends past the SBT region (RayInvocation::shaderRecordRegionBytes) reaches the resolver once per launch and
// record (RayRuntime::shaderRecordOutsideRegion), and the read goes on.
#pragma once

#include <cstdint>

#include "abi/abi.hpp"
#include "accel/accel.hpp"
#include "exec/ray_query.hpp"
#include "exec/ray_tree.hpp"
#include "exec/supervise.hpp"

namespace vkrt::exec {

// A compiled ray tracing shader as a launch runs it.
struct RayShader {
  abi::RayEntry entry = nullptr;  // null: no shader
  // A ray generation shader compiled SPMD: `batchLanes` launch ids along x in one call (abi::RayBatchEntry), or null.
  abi::RayBatchEntry batch = nullptr;
  uint32_t batchLanes = 0;
  const abi::ResourceSlot* resources = nullptr;  // resolved for this launch, in the shader's resource order
  uint32_t stackSize = 0;                        // vkGetRayTracingShaderGroupStackSizeKHR's figure
  const char* name = "";                         // for reports: entry point and stage
  // Whether the shader may read ObjectToWorldKHR / WorldToObjectKHR, and HitTriangleVertexPositionsKHR: a hit
  // shader that reads neither leaves those RayInvocation fields unset (per candidate: 24 floats and a vertex fetch).
  bool readsTransforms = true;
  bool readsPositions = true;
};

// A shader group as an SBT record denotes it.
struct RayGroup {
  enum Type : uint8_t { General, Triangles, Procedural, Empty } type = Empty;  // Empty: a zero handle
  RayShader general, closestHit, anyHit, intersection;
  const void* id = nullptr;  // the caller's group (for reports)
  uint32_t index = 0;        // the pipeline's group index (for ray trees)
};

enum class SbtRegion : uint8_t { Raygen, Miss, Hit, Callable };

struct SbtRange {
  const uint8_t* base = nullptr;  // host address of the region (device addresses are host addresses)
  uint64_t stride = 0;
  uint64_t size = 0;
  // Bytes from `base` that can be read without a fault (>= size): the records' shader-record data may run past
  // `size` up to the stride, inside the application's buffer (see RecordCache::dataBytes).
  uint64_t readable = 0;
};

// What the executor asks the caller while a launch runs. Calls come from any worker thread, at most once per
// record or address per launch (results are cached), and the report methods are for rules the executor
// finds; the caller reports each rule once per launch.
class LaunchResolver : public TopLevelResolver {
 public:
  // The group of the record at `record` (index `index` of `region`, inside the region), or null after reporting
  // when the handle denotes no group of the bound pipeline or its libraries.
  virtual const RayGroup* group(SbtRegion region, uint64_t index, const uint8_t* record) = 0;
  // (TopLevelResolver::topLevel: the top-level acceleration structure at `address`, for traceRayEXT and ray
  // queries, or null after reporting. The structure stays alive until the launch ends.)

  // A record whose shader group handle does not lie inside its region (index x stride + shaderGroupHandleSize >
  // size): the specification's "Indexing Rules" bound every byte a launch reads by the region's size.
  virtual void recordOutsideRegion(SbtRegion region, uint64_t index, uint64_t stride, uint64_t size) = 0;
  // A shader of record `index` read `bytes` at `offset` of its shader-record data, past the region's end
  // (`regionBytes` of the data lie inside the region; the read is bounded by `readableBytes`): once per launch and
  // record.
  virtual void recordDataOutsideRegion(SbtRegion region, uint64_t index, uint64_t offset, uint64_t bytes,
                                       uint64_t regionBytes, uint64_t readableBytes, const RayShader& reader) = 0;
  // A hit group whose type does not match the geometry it was used for.
  virtual void hitGroupMismatch(uint64_t index, const RayGroup& group, bool triangles) = 0;
  // A traceRayEXT at `depth` beyond the pipeline's maximum recursion depth.
  virtual void recursionTooDeep(uint32_t depth, uint32_t maxDepth, const RayShader& caller) = 0;
  // A shader that would take the call chain's stack past the pipeline stack size.
  virtual void stackExceeded(const RayShader* const* chain, uint32_t chainLength, uint64_t needed,
                             uint64_t stackSize) = 0;
};

struct RayLaunch {
  uint32_t size[3] = {1, 1, 1};
  SbtRange raygen, miss, hit, callable;
  const RayGroup* raygenGroup = nullptr;  // resolved by the caller (the launch is skipped without one)
  uint32_t maxRecursionDepth = 1;
  uint64_t stackSize = 0;                  // the pipeline stack size (default or dynamic)
  uint32_t pipelineRayFlags = 0;           // accel::kRaySkipTriangles / kRaySkipAabbs from the pipeline flags
  const uint8_t* pushConstants = nullptr;  // abi::kPushConstantBytes bytes
  LaunchResolver* resolver = nullptr;
  // The supervision (exec/supervise.hpp), as for ComputeDispatch::job: tiles not started once the job was ended
  // are skipped; job->abort() names the shader and the launch index that was running.
  Job* job = nullptr;
  // The ray trees to record (exec/ray_tree.hpp), or null: the caller creates one only when the setting names launch
  // ids. Each raygen invocation is looked up in it once; the named ones record everything below them.
  RayTreeRecorder* rayTree = nullptr;
  // Combined counter adds (abi::PendingAdds): each task gets a table only when every shader of the launch was compiled
  // to check its accesses against it (spirv::CompileRequest::combineAdds); otherwise their adds are atomic.
  bool combineAdds = false;
};

// Runs the launch to completion on the thread pool (the calling thread works too).
void runRays(const RayLaunch& launch);

}  // namespace vkrt::exec
