#include "exec/trace.hpp"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cstring>
#include <limits>
#include <memory>
#include <mutex>
#include <new>
#include <optional>
#include <string>
#include <vector>

#include "exec/thread_pool.hpp"

namespace vkrt::exec {

namespace {

constexpr uint64_t kHandleBytes = 32;             // shaderGroupHandleSize: the record's bytes before its shader data
constexpr uint64_t kMaxCachedRecords = 1u << 20;  // per region; records past it are resolved at each use
constexpr uint32_t kTile = 8;                     // launch indices per tile side
constexpr uint32_t kTileIndices = kTile * kTile;  // launch indices per tile (a batch raygen's: lanes x 64 / lanes)
constexpr uint32_t kMaxAttributeBytes = 32;       // maxRayHitAttributeSize
constexpr uint32_t kMaxChain = 64;                // shaders named in a stack report

// Per-region cache of resolved records: null = not resolved yet, kInvalid = reported, never run.
const RayGroup kInvalidGroup{};
const RayGroup* const kInvalid = &kInvalidGroup;

class RecordCache {
 public:
  void init(const SbtRange& range) {
    range_ = range;
    // Record i is at base + i x stride ("Shader Binding Table" > "Indexing Rules"), and the region's size bounds
    // the bytes a launch may read there ("All data accessed must be less than size bytes from the base
    // address"): the record exists when its shader group handle lies inside the region. Its stride may exceed
    // the region's size (one record of a handle's size with a stride of 64 is valid use: the CTS's callable_shader
    // and pipeline_no_null_shaders_flag tests trace with it), and a zero stride puts every index on record 0.
    if (range.size < kHandleBytes) {
      count_ = 0;
    } else {
      count_ = range.stride ? (range.size - kHandleBytes) / range.stride + 1 : ~uint64_t(0);
    }
    cached_ = std::min(range.stride ? count_ : std::min<uint64_t>(count_, 1), kMaxCachedRecords);
    slots_.reset(cached_ ? new Slot[cached_] : nullptr);
    for (uint64_t i = 0; i < cached_; ++i) {
      slots_[i].group.store(nullptr, std::memory_order_relaxed);
      slots_[i].dataOutside.store(false, std::memory_order_relaxed);
    }
  }
  // The group of record `index`, or null (reported) when its handle lies outside the region or denotes no group.
  const RayGroup* get(SbtRegion region, uint64_t index, LaunchResolver& resolver, const uint8_t** record) {
    if (index >= count_) {
      resolver.recordOutsideRegion(region, index, range_.stride, range_.size);
      return nullptr;
    }
    *record = range_.base + index * range_.stride;
    const uint64_t slot = range_.stride ? index : 0;  // with a zero stride every index is record 0
    if (slot < cached_) {
      const RayGroup* g = slots_[slot].group.load(std::memory_order_acquire);
      if (!g) {
        g = resolver.group(region, index, *record);
        if (!g) g = kInvalid;
        slots_[slot].group.store(g, std::memory_order_release);
      }
      return g == kInvalid ? nullptr : g;
    }
    return resolver.group(region, index, *record);
  }
  // The shader-record bytes after the handle of a record: the stride's worth where the memory there can be read,
  // else what is left of the region. "Indexing Rules" asks that all data accessed lie less than `size` bytes from
  // the base, but a region of one handle with a larger stride whose shader reads its record data past `size` is
  // common (the CTS's pipeline_no_null_shaders_flag and callable_shader tests; GPUs read the bytes): vkrt reads
  // them too when they are the application's memory, and bounds the read by the region otherwise.
  uint64_t dataBytes(uint64_t index) const {
    uint64_t start = index * range_.stride + kHandleBytes;
    const uint64_t limit = std::max(range_.size, range_.readable);
    uint64_t end = range_.stride ? std::min(start - kHandleBytes + range_.stride, limit) : range_.size;
    return end > start ? end - start : 0;
  }
  // The bytes from the record's shader-record data to the region's end: what "Indexing Rules" lets a shader read.
  uint64_t regionBytes(uint64_t index) const {
    const uint64_t start = index * range_.stride + kHandleBytes;
    return range_.size > start ? range_.size - start : 0;
  }
  // Whether a read of record `index` past the region was reported in this launch (records past the cached ones
  // share one flag).
  std::atomic<bool>* dataOutsideReported(uint64_t index) {
    const uint64_t slot = range_.stride ? index : 0;
    return slot < cached_ ? &slots_[slot].dataOutside : &uncachedDataOutside_;
  }

 private:
  struct Slot {
    std::atomic<const RayGroup*> group;
    std::atomic<bool> dataOutside;
  };
  SbtRange range_;
  uint64_t count_ = 0, cached_ = 0;
  std::unique_ptr<Slot[]> slots_;
  std::atomic<bool> uncachedDataOutside_{false};
};

// The launch's shared state: the SBT caches and the acceleration structures met so far.
struct LaunchState {
  explicit LaunchState(const RayLaunch& l) : launch(&l), queries(l.resolver) {}
  const RayLaunch* launch = nullptr;
  Job* job = nullptr;
  RecordCache miss, hit, callable;
  std::atomic<bool> raygenDataOutside{false};  // the raygen record's RecordCache::dataOutsideReported
  RayQueryScope queries;                // the shaders' ray queries (they resolve through the launch's resolver too)
  RayTreeRecorder* recorder = nullptr;  // null unless VKRT_RAY_TREE names launch ids
  // The raygen shader's batch (RayShader::batch) in use: 0 where each launch index is a call of its own (no batch
  // entry, or ray trees recorded). Tiles are then `batchLanes` wide, a batch one tile row.
  uint32_t batchLanes = 0;
  uint32_t tileW = kTile, tileH = kTile;

  // The top level at `address`: the resolver resolves each address once per launch and answers without a lock
  // (TopLevelResolver, inline).
  const accel::Tlas* topLevel(uint64_t address) { return launch->resolver->topLevel(address); }
};

struct TraceFrame;

struct Invocation;

// What one task (a tile of launch indices on one worker) keeps for its rays, so that the per-ray path makes no
// thread-local lookup and no resolver call for a structure it met already: the worker's Running record (stored
// around every shader call, for the abort report) and the top level resolved last (the resolver's answer for an
// address does not change during a launch).
struct TaskState {
  Running* running = nullptr;
  // The any-hit and intersection invocations, reused from candidate to candidate (zeroed once per task, not per
  // candidate): neither stage nests, as neither can trace rays or call callables, and only an intersection shader
  // reports intersections (which run any-hit shaders in the other one).
  Invocation* anyHit = nullptr;
  Invocation* intersection = nullptr;
  // The closest-hit and miss invocations of trace depths 1..kShadingDepths, reused from ray to ray (each zeroed on
  // its first use in the task; deeper ones are made per call): at one depth at most one of them is live, since a
  // trace at depth d runs one of them at d + 1, whatever they trace runs at d + 2, and callables keep the depth.
  // Each call sets every field its stage's built-ins read.
  static constexpr uint32_t kShadingDepths = 4;
  Invocation* shading[kShadingDepths] = {};
  void* shadingStorage = nullptr;  // room for kShadingDepths invocations, constructed on first use
  // The callable invocations of nesting levels 0..kCallableDepths - 1 (a callable that a callable calls is one level
  // deeper), reused from call to call as the shading ones are (zeroing one per call was a `rep stos` that held half of
  // executeCallable's samples): calls nest strictly, so the level is the task's count of callables running, and each
  // call sets every field a callable's built-ins read. Deeper ones are made per call.
  static constexpr uint32_t kCallableDepths = 4;
  Invocation* callables[kCallableDepths] = {};
  void* callableStorage = nullptr;  // room for kCallableDepths invocations, constructed on first use
  uint32_t callableLevel = 0;
  uint64_t tlasAddress = 0;
  const accel::Tlas* tlas = nullptr;
  bool tlasResolved = false;
  // The hit record resolved last (TraceFrame::hitGroup) and its group, for a triangle or a box: a task's
  // candidates mostly select one record, whose resolution (the region's bounds, the cache slot, the group's kind)
  // does not change during a launch. Only a record that resolved to a group to run is kept (the others report).
  uint64_t hitIndex = ~uint64_t(0);
  bool hitTriangle = false;
  const RayGroup* hitGroup = nullptr;
  const uint8_t* hitRecord = nullptr;
  // The task's combined counter adds (abi::PendingAdds), flushed by runRays after the task, however it ended.
  abi::PendingAdds* pendingAdds = nullptr;

  const accel::Tlas* topLevel(LaunchState& state, uint64_t address);
};

// A closest-hit or miss invocation at trace depth `depth` (>= 1), with beginShared's part: the task's reused one,
// or `fresh` (zeroed).
Invocation& shadingInvocation(LaunchState& state, TaskState& task, uint32_t depth, Invocation& fresh);

const accel::Tlas* TaskState::topLevel(LaunchState& state, uint64_t address) {
  if (!tlasResolved || address != tlasAddress) {
    tlas = state.topLevel(address);
    tlasAddress = address;
    tlasResolved = true;
  }
  return tlas;
}

// What the executor passes to a shader: the ABI's RayInvocation, then the executor's own state.
struct Invocation : abi::RayInvocation {
  LaunchState* state = nullptr;
  TaskState* task = nullptr;
  const Invocation* parent = nullptr;  // the invocation that called this one (for stack reports)
  const RayShader* shader = nullptr;
  uint32_t depth = 0;           // traceRayEXT nesting: raygen 0
  uint64_t stackUsed = 0;       // the stack sizes of this shader and its callers
  TraceFrame* frame = nullptr;  // intersection shaders: the traversal they serve
  accel::ProceduralCandidate* candidate = nullptr;
  // The SBT record whose shader runs (for the report of a read past its region).
  SbtRegion recordRegion = SbtRegion::Raygen;
  uint64_t recordIndex = 0;
  std::atomic<bool>* recordDataOutside = nullptr;
  RayTreeInvocation* tree = nullptr;  // the ray tree this invocation records into (a named launch id), or null
};

// The invocation's shader record: record `index` of `region` at `record`, its data bytes up to the stride where
// they can be read (RecordCache::dataBytes), and the bytes "Indexing Rules" lets it read.
void setRecord(Invocation& inv, RecordCache& cache, SbtRegion region, uint64_t index, const uint8_t* record) {
  // A task's reused invocation keeps its record from call to call: set again only when the record changes.
  if (inv.recordDataOutside && inv.recordRegion == region && inv.recordIndex == index &&
      inv.shaderRecord == record + kHandleBytes)
    return;
  inv.shaderRecord = const_cast<uint8_t*>(record + kHandleBytes);
  inv.shaderRecordBytes = cache.dataBytes(index);
  inv.shaderRecordRegionBytes = cache.regionBytes(index);
  inv.recordRegion = region;
  inv.recordIndex = index;
  inv.recordDataOutside = cache.dataOutsideReported(index);
}

using TreeKind = RayTreeNode::Kind;

thread_local uint8_t tlsSink[abi::kSinkBytes];

void traceRay(abi::RayInvocation* caller, const abi::TraceRayArgs* args);
void executeCallable(abi::RayInvocation* caller, uint32_t index, void* data, uint64_t bytes);
uint32_t reportIntersection(abi::RayInvocation* caller, float t, uint32_t hitKind, const void* attributes,
                            uint64_t bytes);
void shaderRecordOutsideRegion(abi::RayInvocation* caller, uint64_t offset, uint64_t bytes);
void traceRays(abi::RayInvocation* caller, const abi::TraceRayArgs* args, uint32_t mask, uint32_t launchX0);

const abi::RayRuntime kRuntime = {&traceRay, &executeCallable, &reportIntersection, &shaderRecordOutsideRegion,
                                  &traceRays};

// What every invocation of a task has in common (push constants, runtime, launch size): set once per record,
// and the records a task reuses (TaskState) keep it from call to call.
void beginShared(Invocation& inv, LaunchState* state, TaskState* task) {
  inv.state = state;
  inv.task = task;
  inv.base.pushConstants = state->launch->pushConstants;
  inv.base.sink = tlsSink;
  inv.runtime = &kRuntime;
  inv.base.cancel = reinterpret_cast<const uint32_t*>(&state->job->cancel);
  inv.base.cancelled = &cancelled;
  inv.pendingAdds = task ? task->pendingAdds : nullptr;
  for (int i = 0; i < 3; ++i) inv.launchSize[i] = uint32_t(state->launch->size[i]);
}

// What a call from `caller` sets in an invocation that has beginShared's part: launch index, depth, stack.
void beginCall(Invocation& inv, const Invocation& caller) {
  inv.parent = &caller;
  inv.base.rayQueries = caller.base.rayQueries;  // a recorded chain keeps its scope
  std::memcpy(inv.launchId, caller.launchId, sizeof inv.launchId);
  inv.depth = caller.depth;
  inv.stackUsed = caller.stackUsed;
  inv.tree = caller.tree;
}

// A new invocation called by `caller` (null for raygen).
void begin(Invocation& inv, LaunchState* state, const Invocation* caller) {
  beginShared(inv, state, caller ? caller->task : nullptr);
  if (caller) {
    beginCall(inv, *caller);
  } else {
    inv.parent = nullptr;
    inv.base.rayQueries = &state->queries;
  }
}

// Invocation `i` of a task's reused ones (`slots`, `n` of them, constructed in `storage` on first use with
// beginShared's part), or `fresh`, zeroed, where `i` lies past them.
Invocation& reusedInvocation(LaunchState& state, TaskState& task, Invocation** slots, void* storage, uint32_t n,
                             uint32_t i, Invocation& fresh) {
  if (i >= n) {
    fresh = Invocation{};
    beginShared(fresh, &state, &task);
    return fresh;
  }
  Invocation*& slot = slots[i];
  if (!slot) {
    slot = new (static_cast<Invocation*>(storage) + i) Invocation{};
    beginShared(*slot, &state, &task);
  }
  return *slot;
}

Invocation& shadingInvocation(LaunchState& state, TaskState& task, uint32_t depth, Invocation& fresh) {
  // (Depth 0 wraps past the slots: a fresh one.)
  return reusedInvocation(state, task, task.shading, task.shadingStorage, TaskState::kShadingDepths, depth - 1, fresh);
}

// The callable invocation of the task's current nesting level: the task's reused one, or `fresh` (zeroed).
Invocation& callableInvocation(LaunchState& state, TaskState& task, Invocation& fresh) {
  return reusedInvocation(state, task, task.callables, task.callableStorage, TaskState::kCallableDepths,
                          task.callableLevel, fresh);
}

// Runs `shader` for `inv` unless it would take the chain's stack past the pipeline stack size (reported); with
// `lanes`, the raygen shader's batch of that many launch ids from inv's (RayShader::batch).
bool run(Invocation& inv, const RayShader& shader, uint32_t lanes = 0) {
  if (!shader.entry) return false;
  const RayLaunch& launch = *inv.state->launch;
  uint64_t needed = inv.stackUsed + shader.stackSize;
  if (needed > launch.stackSize) {
    const RayShader* chain[kMaxChain];
    uint32_t n = 0;
    chain[n++] = &shader;
    for (const Invocation* p = inv.parent; p && n < kMaxChain; p = p->parent)
      if (p->shader) chain[n++] = p->shader;
    std::reverse(chain, chain + n);
    launch.resolver->stackExceeded(chain, n, needed, launch.stackSize);
    return false;
  }
  inv.stackUsed = needed;
  inv.shader = &shader;
  inv.base.resources = shader.resources;
  // For the report of a fault or a timeout: the shader running, and its launch index (the caller's again after it).
  // (Field by field: copied whole, the record's 1-byte kind, just stored by the previous call's restore, was read back
  // in an 8-byte load with its padding, which cannot be forwarded from that store.)
  Running& running = *inv.task->running;
  const char* const callerShader = running.shader;
  const uint32_t* const callerId = running.id;
  const Abort::IdKind callerKind = running.idKind;
  running.shader = shader.name;
  running.id = inv.launchId;
  running.idKind = Abort::LaunchId;
  if (lanes) {
    shader.batch(&inv, lanes);
  } else {
    shader.entry(&inv);
  }
  running.shader = callerShader;
  running.id = callerId;
  running.idKind = callerKind;
  return true;
}

// run() for an invocation of a recorded chain: a shader node (stage, group, SBT record) under the tree's current
// node, current while the shader runs.
bool runShader(Invocation& inv, const RayShader& shader, const char* stage, const RayGroup& group, uint64_t index,
               const uint8_t* record) {
  if (!inv.tree) return run(inv, shader);
  RayTreeNode* n = inv.tree->add(TreeKind::Shader);
  if (n) {
    n->stage = stage;
    n->name = shader.name;
    n->group = group.index;
    n->recordIndex = index;
    n->record = reinterpret_cast<uintptr_t>(record);
  }
  RayTreeInvocation::Enter enter(inv.tree, n);
  const bool ran = run(inv, shader);
  if (!ran && n)
    if (RayTreeNode* note = inv.tree->add(TreeKind::Note))
      note->name = "not run: the call chain's stack would exceed the pipeline stack size (reported)";
  return ran;
}

RayTreeNode::Verdict verdictOf(accel::AnyHitResult r) {
  if (r == accel::AnyHitResult::Ignore) return RayTreeNode::Verdict::Ignored;
  if (r == accel::AnyHitResult::AcceptAndTerminate) return RayTreeNode::Verdict::Terminated;
  return RayTreeNode::Verdict::Accepted;
}

void setRay(Invocation& inv, const abi::TraceRayArgs& a, float tMax) {
  for (int i = 0; i < 3; ++i) {
    inv.worldRayOrigin[i] = a.origin[i];
    inv.worldRayDirection[i] = a.direction[i];
  }
  inv.rayTmin = a.tMin;
  inv.rayTmax = tMax;
  inv.incomingRayFlags = a.rayFlags;
  inv.cullMask = a.cullMask & 0xFF;
}

void setHit(Invocation& inv, const accel::HitInfo& h, const RayShader& shader) {
  inv.instanceCustomIndex = int32_t(h.customIndex);
  inv.instanceId = int32_t(h.instanceIndex);
  inv.geometryIndex = int32_t(h.geometryIndex);
  inv.primitiveId = int32_t(h.primitiveIndex);
  inv.hitKind = h.hitKind;
  for (int i = 0; i < 3; ++i) {
    inv.objectRayOrigin[i] = h.objectRayOrigin[i];
    inv.objectRayDirection[i] = h.objectRayDirection[i];
  }
  // The ABI's matrices are 4 columns of 3 floats: the transpose of the rows the Tlas keeps.
  if (shader.readsTransforms)
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 3; ++r) {
        inv.objectToWorld[c][r] = h.objectToWorld ? h.objectToWorld[r][c] : (c == r ? 1.0f : 0.0f);
        inv.worldToObject[c][r] = h.worldToObject ? h.worldToObject[r][c] : (c == r ? 1.0f : 0.0f);
      }
  // HitTriangleVertexPositionsKHR (zeros for a procedural hit, where the built-in is not allowed).
  if (shader.readsPositions) accel::trianglePositions(h, inv.hitTriangleVertexPositions);
}

// One traceRayEXT: the traversal's HitHandler (any-hit and intersection shaders), then closest-hit or miss.
struct TraceFrame final : accel::HitHandler {
  Invocation& caller;
  const abi::TraceRayArgs& args;
  LaunchState& state;
  // OpTraceRayKHR uses only the low 4 bits of the SBT offset and stride, 16 of the miss index (8 of the cull
  // mask: setRay() and traceRay() mask it).
  const uint32_t sbtOffset, sbtStride, missIndex;
  uint8_t committedAttributes[kMaxAttributeBytes] = {};  // of the procedural hit committed last
  uint64_t committedAttributeBytes = 0;
  RayTreeNode* node = nullptr;  // a recorded trace: its node (current while it traverses), else null
  RayTreeNode::Verdict boxVerdict = RayTreeNode::Verdict::Ignored;  // a recorded box candidate's reports

  TraceFrame(Invocation& caller, const abi::TraceRayArgs& args)
      : caller(caller),
        args(args),
        state(*caller.state),
        sbtOffset(args.sbtOffset & 0xF),
        sbtStride(args.sbtStride & 0xF),
        missIndex(args.missIndex & 0xFFFF) {}

  // The hit group of a hit in an instance with SBT offset `instanceOffset`, of geometry `geometry` (a triangle or
  // a box), checked against the geometry kind; null when there is none to run.
  const RayGroup* hitGroup(uint32_t instanceOffset, uint32_t geometry, bool triangle, const uint8_t** record,
                           uint64_t* index) {
    *index = uint64_t(instanceOffset) + sbtOffset + uint64_t(sbtStride) * geometry;
    TaskState& task = *caller.task;
    if (*index == task.hitIndex && triangle == task.hitTriangle) {
      *record = task.hitRecord;
      return task.hitGroup;
    }
    const RayGroup* g = state.hit.get(SbtRegion::Hit, *index, *state.launch->resolver, record);
    if (!g || g->type == RayGroup::Empty) return nullptr;
    bool triangles = g->type == RayGroup::Triangles;
    if (g->type == RayGroup::General || triangles != triangle) {
      state.launch->resolver->hitGroupMismatch(*index, *g, triangle);
      return nullptr;
    }
    task.hitIndex = *index;
    task.hitTriangle = triangle;
    task.hitGroup = g;
    task.hitRecord = *record;
    return g;
  }
  const RayGroup* hitGroup(const accel::HitInfo& h, const uint8_t** record, uint64_t* index) {
    return hitGroup(h.sbtOffset, h.geometryIndex, h.triangle, record, index);
  }

  void hitInvocation(Invocation& inv, const accel::HitInfo& h, const uint8_t* record, uint64_t index, float tMax,
                     const RayShader& shader) {
    beginCall(inv, caller);  // (the record has beginShared's part: a task's reused one)
    inv.depth = caller.depth + 1;
    setRay(inv, args, tMax);
    setHit(inv, h, shader);
    setRecord(inv, state.hit, SbtRegion::Hit, index, record);
  }

  accel::AnyHitResult runAnyHit(const accel::HitInfo& h, const void* attributes, uint64_t attributeBytes) {
    const uint8_t* record;
    uint64_t index;
    const RayGroup* g = hitGroup(h, &record, &index);
    if (!g || !g->anyHit.entry) return accel::AnyHitResult::Accept;
    Invocation& inv = *caller.task->anyHit;
    hitInvocation(inv, h, record, index, h.t, g->anyHit);
    inv.status = 0;
    inv.incoming = args.payload;
    inv.incomingBytes = args.payloadBytes;
    inv.hitAttributes = attributes;
    inv.hitAttributeBytes = attributeBytes;
    if (!runShader(inv, g->anyHit, "any-hit", *g, index, record)) return accel::AnyHitResult::Accept;
    if (inv.status == abi::kRayStatusIgnore) return accel::AnyHitResult::Ignore;
    if (inv.status == abi::kRayStatusTerminate) return accel::AnyHitResult::AcceptAndTerminate;
    return accel::AnyHitResult::Accept;
  }

  accel::AnyHitResult anyHit(const accel::HitInfo& candidate) override {
    if (!node) return runAnyHit(candidate, candidate.barycentrics, sizeof candidate.barycentrics);
    RayTreeNode* n = caller.tree->add(TreeKind::Candidate);
    if (n) {
      n->hasCandidate = true;
      n->candidate = treeHit(candidate);
    }
    RayTreeInvocation::Enter enter(caller.tree, n);
    const accel::AnyHitResult r = runAnyHit(candidate, candidate.barycentrics, sizeof candidate.barycentrics);
    if (n) n->verdict = verdictOf(r);
    return r;
  }

  void intersect(accel::ProceduralCandidate& c) override {
    if (!node) return runIntersection(c);
    RayTreeNode* n = caller.tree->add(TreeKind::Candidate);
    if (n) {
      n->hasCandidate = true;
      n->candidate = treeHit(c.info());
      n->candidate.t = std::numeric_limits<float>::quiet_NaN();  // a box has no t until a report gives one
      n->candidate.hitKind = 0;
    }
    boxVerdict = RayTreeNode::Verdict::Ignored;
    RayTreeInvocation::Enter enter(caller.tree, n);
    runIntersection(c);
    if (n) n->verdict = boxVerdict;
  }

  void runIntersection(accel::ProceduralCandidate& c) {
    const accel::HitInfo& h = c.info();
    const uint8_t* record;
    uint64_t index;
    const RayGroup* g = hitGroup(h, &record, &index);
    if (!g || !g->intersection.entry) return;
    Invocation& inv = *caller.task->intersection;
    hitInvocation(inv, h, record, index, c.tMax(), g->intersection);
    inv.status = 0;
    inv.hitKind = 0;
    inv.frame = this;
    inv.candidate = &c;
    runShader(inv, g->intersection, "intersection", *g, index, record);
  }

  // reportIntersectionEXT from the intersection shader `inv`.
  uint32_t report(Invocation& inv, float t, uint32_t hitKind, const void* attributes, uint64_t bytes) {
    accel::ProceduralCandidate& c = *inv.candidate;
    RayTreeNode* n = inv.tree ? inv.tree->add(TreeKind::Report) : nullptr;
    accel::HitInfo h = c.info();
    h.t = t;
    h.hitKind = hitKind;
    if (n) {
      n->hasCandidate = true;
      n->candidate = treeHit(h);
      n->verdict = RayTreeNode::Verdict::Outside;
    }
    if (!(t >= c.tMin() && t <= c.tMax())) return 0;  // NaN fails too
    bytes = std::min<uint64_t>(bytes, kMaxAttributeBytes);
    uint8_t candidateAttributes[kMaxAttributeBytes] = {};
    if (attributes && bytes) std::memcpy(candidateAttributes, attributes, bytes);
    RayTreeInvocation::Enter enter(inv.tree, n);
    accel::AnyHitResult r = c.opaque() ? accel::AnyHitResult::Accept : runAnyHit(h, candidateAttributes, bytes);
    if (n) {
      n->verdict = verdictOf(r);
      if (r != accel::AnyHitResult::Ignore && boxVerdict != RayTreeNode::Verdict::Terminated) boxVerdict = n->verdict;
    }
    if (r == accel::AnyHitResult::Ignore) return 0;
    bool terminate = r == accel::AnyHitResult::AcceptAndTerminate || (args.rayFlags & accel::kRayTerminateOnFirstHit);
    c.commit(t, hitKind, terminate);
    std::memcpy(committedAttributes, candidateAttributes, kMaxAttributeBytes);
    committedAttributeBytes = bytes;
    inv.rayTmax = c.tMax();
    if (terminate) inv.status = abi::kRayStatusTerminate;
    return 1;
  }

  // The committed hit `c` of `ray` through `tlas`: its built-ins are made only when a closest-hit shader runs.
  void closestHit(const accel::Tlas& tlas, const accel::Ray& ray, const accel::CommittedHit& c) {
    if (args.rayFlags & accel::kRaySkipClosestHitShader) return;
    const uint8_t* record;
    uint64_t index;
    const RayGroup* g = hitGroup(c.sbtOffset, c.geometry, c.triangle, &record, &index);
    if (!g || !g->closestHit.entry) return;
    // (Storage without HitInfo's default member initializers, which the compiler made a `rep stos` per hit, a sixth of
    // traceRays' time on camera rays: hitInfo assigns every field.)
    union Hit {
      Hit() {}
      accel::HitInfo info;
    } hit;
    accel::HitInfo& h = hit.info;
    accel::hitInfo(tlas, ray, c, &h);
    Invocation fresh;
    Invocation& inv = shadingInvocation(state, *caller.task, caller.depth + 1, fresh);
    hitInvocation(inv, h, record, index, h.t, g->closestHit);
    inv.incoming = args.payload;
    inv.incomingBytes = args.payloadBytes;
    if (h.triangle) {
      inv.hitAttributes = h.barycentrics;
      inv.hitAttributeBytes = sizeof h.barycentrics;
    } else {
      inv.hitAttributes = committedAttributes;
      inv.hitAttributeBytes = committedAttributeBytes;
    }
    runShader(inv, g->closestHit, "closest-hit", *g, index, record);
  }

  void miss() {
    const uint8_t* record;
    const RayGroup* g = state.miss.get(SbtRegion::Miss, missIndex, *state.launch->resolver, &record);
    if (!g || !g->general.entry) return;
    Invocation fresh;
    Invocation& inv = shadingInvocation(state, *caller.task, caller.depth + 1, fresh);
    beginCall(inv, caller);
    inv.depth = caller.depth + 1;
    setRay(inv, args, args.tMax);
    inv.incoming = args.payload;
    inv.incomingBytes = args.payloadBytes;
    setRecord(inv, state.miss, SbtRegion::Miss, missIndex, record);
    runShader(inv, g->general, "miss", *g, missIndex, record);
  }
};

void copyPayload(const abi::TraceRayArgs& a, std::vector<uint8_t>* out) {
  const auto* p = static_cast<const uint8_t*>(a.payload);
  if (p) out->assign(p, p + a.payloadBytes);
}

// A recorded trace's node, with its arguments as OpTraceRayKHR uses them (TraceFrame's masks) and the payload.
RayTreeNode* traceNode(RayTreeInvocation& tree, const TraceFrame& f) {
  RayTreeNode* n = tree.add(TreeKind::Trace);
  if (!n) return nullptr;
  const abi::TraceRayArgs& a = f.args;
  n->accelerationStructure = a.accelerationStructure;
  n->rayFlags = a.rayFlags;
  n->cullMask = a.cullMask & 0xFF;
  n->sbtOffset = f.sbtOffset;
  n->sbtStride = f.sbtStride;
  n->missIndex = f.missIndex;
  std::memcpy(n->origin, a.origin, sizeof n->origin);
  std::memcpy(n->direction, a.direction, sizeof n->direction);
  n->tMin = a.tMin;
  n->tMax = a.tMax;
  copyPayload(a, &n->payloadBefore);
  return n;
}

// One 32-bit load of a float the shader has just stored (traceRay): an empty asm keeps the compiler from merging
// neighbouring fields into one wider load, which could not be forwarded from the shader's 4-byte stores and would
// wait for them to retire (GCC merged the copies of origin and direction into 8-byte loads: a third of traceRay's
// time on primary rays).
inline float loadAlone(const float& field) {
  float v = field;
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
  asm("" : "+x"(v));
#endif
  return v;
}

// The ray of a trace's arguments, as accel traces it (the pipeline's skip flags or-ed in, 8 bits of cull mask), its
// floats read one at a time (loadAlone), written into the caller's ray in place: returned and then copied, the ray's
// flags and cull mask (two 4-byte stores) were read back by the copy as one 8-byte load, which could not be forwarded
// from them (a sixth of a trace's time in traceRay, on every ray).
void rayOf(const abi::TraceRayArgs& a, uint32_t pipelineRayFlags, accel::Ray& ray) {
  for (int i = 0; i < 3; ++i) {
    ray.origin[i] = loadAlone(a.origin[i]);
    ray.direction[i] = loadAlone(a.direction[i]);
  }
  ray.tMin = loadAlone(a.tMin);
  ray.tMax = loadAlone(a.tMax);
  ray.flags = a.rayFlags | pipelineRayFlags;
  ray.cullMask = a.cullMask & 0xFF;
}

void traceRay(abi::RayInvocation* callerBase, const abi::TraceRayArgs* args) {
  // The shader has just stored *args field by field: the fields are read one by one (TraceFrame masks what
  // OpTraceRayKHR masks), as a copy of the whole struct in wide loads would wait for those stores to retire
  // (a failed store-to-load forward, per ray).
  Invocation& caller = *static_cast<Invocation*>(callerBase);
  LaunchState& state = *caller.state;
  const RayLaunch& launch = *state.launch;
  if (caller.depth + 1 > launch.maxRecursionDepth) {
    launch.resolver->recursionTooDeep(caller.depth + 1, launch.maxRecursionDepth, *caller.shader);
    if (caller.tree)
      if (RayTreeNode* note = caller.tree->add(TreeKind::Note))
        note->name = "traceRay at depth " + std::to_string(caller.depth + 1) + " beyond maxPipelineRayRecursionDepth " +
                     std::to_string(launch.maxRecursionDepth) + ": not run (reported)";
    return;
  }
  // The structure first, so that its first lines load while the frame is set up.
  const accel::Tlas* tlas = caller.task->topLevel(state, args->accelerationStructure);
  if (tlas) accel::prefetchForTrace(*tlas);
  TraceFrame frame(caller, *args);
  if (caller.tree) frame.node = traceNode(*caller.tree, frame);
  RayTreeInvocation::Enter enter(caller.tree, frame.node);
  accel::CommittedHit hit;
  accel::Ray ray;
  bool found = false;
  if (tlas) {
    rayOf(*args, launch.pipelineRayFlags, ray);
    // Without a closest-hit shader to run or a ray tree to record it, the committed hit is not read.
    const bool readsHit = frame.node || !(ray.flags & accel::kRaySkipClosestHitShader);
    found = accel::trace(*tlas, ray, frame, readsHit ? &hit : nullptr);
  }
  if (frame.node) {
    frame.node->hasCommitted = found;
    if (found) {
      accel::HitInfo h;
      accel::hitInfo(*tlas, ray, hit, &h);
      frame.node->committed = treeHit(h);
    }
  }
  if (found) {
    frame.closestHit(*tlas, ray, hit);
  } else {
    frame.miss();
  }
  if (frame.node) copyPayload(*args, &frame.node->payloadAfter);
}

// A ray generation batch's traces (abi::RayRuntime::traceRays). Where the lanes trace through one top level and each
// ray meets nothing that calls back (accel::packetTraceable: a small top level's opaque triangles), their rays go
// through Embree as one packet, then each lane's closest-hit or miss shader runs as traceRay runs it, in lane order;
// otherwise each lane is a traceRay. The same hits either way: a packet's rays are independent.
void traceRays(abi::RayInvocation* callerBase, const abi::TraceRayArgs* args, uint32_t mask, uint32_t launchX0) {
  Invocation& caller = *static_cast<Invocation*>(callerBase);
  LaunchState& state = *caller.state;
  const RayLaunch& launch = *state.launch;
  const accel::Tlas* tlas = nullptr;
  bool packet = !caller.tree && caller.depth + 1 <= launch.maxRecursionDepth && (mask & (mask - 1)) &&
                mask < (uint64_t(1) << accel::kPacketRays);
  // (Storage without the rays' default member initializers: every lane of the mask is assigned in full.)
  union Rays {
    Rays() {}
    accel::Ray at[accel::kPacketRays];
  } store;
  accel::Ray* rays = store.at;
  uint32_t traceableFlags = ~0u;  // the ray flags packetTraceable() last accepted (a batch's rays mostly share them)
  for (uint32_t m = mask; packet && m; m &= m - 1) {
    const uint32_t l = uint32_t(std::countr_zero(m));
    const abi::TraceRayArgs& a = args[l];
    const accel::Tlas* t = caller.task->topLevel(state, a.accelerationStructure);
    if (!tlas) tlas = t;
    accel::Ray& ray = rays[l];
    rayOf(a, launch.pipelineRayFlags, ray);
    packet = t && t == tlas && (ray.flags == traceableFlags || accel::packetTraceable(*t, ray));
    traceableFlags = ray.flags;
  }
  if (!packet) {
    for (uint32_t m = mask; m; m &= m - 1) {
      const uint32_t l = uint32_t(std::countr_zero(m));
      caller.launchId[0] = launchX0 + l;
      traceRay(callerBase, &args[l]);
    }
    caller.launchId[0] = launchX0;
    return;
  }
  accel::CommittedHit hits[accel::kPacketRays];
  const uint32_t found = accel::tracePacket(*tlas, rays, mask, hits);
  for (uint32_t m = mask; m; m &= m - 1) {
    const uint32_t l = uint32_t(std::countr_zero(m));
    caller.launchId[0] = launchX0 + l;
    TraceFrame frame(caller, args[l]);
    if ((found >> l) & 1) {
      frame.closestHit(*tlas, rays[l], hits[l]);
    } else {
      frame.miss();
    }
  }
  caller.launchId[0] = launchX0;
}

void executeCallable(abi::RayInvocation* callerBase, uint32_t index, void* data, uint64_t bytes) {
  Invocation& caller = *static_cast<Invocation*>(callerBase);
  LaunchState& state = *caller.state;
  const uint8_t* record;
  const RayGroup* g = state.callable.get(SbtRegion::Callable, index, *state.launch->resolver, &record);
  if (!g || !g->general.entry) return;
  TaskState& task = *caller.task;
  Invocation fresh;
  Invocation& inv = callableInvocation(state, task, fresh);
  beginCall(inv, caller);
  inv.incoming = data;
  inv.incomingBytes = bytes;
  setRecord(inv, state.callable, SbtRegion::Callable, index, record);
  ++task.callableLevel;
  runShader(inv, g->general, "callable", *g, index, record);
  --task.callableLevel;
}

uint32_t reportIntersection(abi::RayInvocation* callerBase, float t, uint32_t hitKind, const void* attributes,
                            uint64_t bytes) {
  Invocation& inv = *static_cast<Invocation*>(callerBase);
  if (!inv.frame || !inv.candidate) return 0;  // only intersection shaders report (the compiler ensures it)
  return inv.frame->report(inv, t, hitKind, attributes, bytes);
}

// A shader's read of its record past the region (checked by the compiled code): reported once per launch and record.
void shaderRecordOutsideRegion(abi::RayInvocation* callerBase, uint64_t offset, uint64_t bytes) {
  Invocation& inv = *static_cast<Invocation*>(callerBase);
  std::atomic<bool>* reported = inv.recordDataOutside;
  if (!reported || reported->load(std::memory_order_relaxed) || reported->exchange(true)) return;
  inv.state->launch->resolver->recordDataOutsideRegion(inv.recordRegion, inv.recordIndex, offset, bytes,
                                                       inv.shaderRecordRegionBytes, inv.shaderRecordBytes, *inv.shader);
}

// The raygen invocations of one tile (a task of runRays', run under supervision).
void runTile(LaunchState& state, uint64_t tile, uint64_t tilesX, uint64_t tilesY, abi::PendingAdds* pendingAdds) {
  const RayLaunch& launch = *state.launch;
  const uint64_t w = launch.size[0], h = launch.size[1];
  const RayShader& raygen = launch.raygenGroup->general;
  const uint64_t raygenBytes = launch.raygen.size > kHandleBytes ? launch.raygen.size - kHandleBytes : 0;
  {
    const uint32_t z = uint32_t(tile / (tilesX * tilesY));
    const uint64_t inLayer = tile % (tilesX * tilesY);
    const uint32_t x0 = uint32_t(inLayer % tilesX) * state.tileW, y0 = uint32_t(inLayer / tilesX) * state.tileH;
    const uint32_t x1 = uint32_t(std::min<uint64_t>(x0 + state.tileW, w));
    const uint32_t y1 = uint32_t(std::min<uint64_t>(y0 + state.tileH, h));
    // One raygen invocation for the tile's launch indices: what they share is set once (the invocation is zeroed
    // once per tile, not per launch index), and the any-hit invocation the task's candidates reuse.
    TaskState task;
    task.running = &runningRecord();
    task.pendingAdds = pendingAdds;
    Invocation inv{};
    begin(inv, &state, nullptr);
    inv.task = &task;
    inv.pendingAdds = pendingAdds;
    inv.launchId[2] = z;
    inv.shaderRecord = const_cast<uint8_t*>(launch.raygen.base + kHandleBytes);
    inv.shaderRecordBytes = inv.shaderRecordRegionBytes = raygenBytes;  // size == stride (VUID-...-size-04023)
    inv.recordDataOutside = &state.raygenDataOutside;
    Invocation anyHit{}, intersection{};
    beginShared(anyHit, &state, &task);
    beginShared(intersection, &state, &task);
    task.anyHit = &anyHit;
    task.intersection = &intersection;
    alignas(Invocation) unsigned char shadingStorage[TaskState::kShadingDepths * sizeof(Invocation)];
    task.shadingStorage = shadingStorage;
    alignas(Invocation) unsigned char callableStorage[TaskState::kCallableDepths * sizeof(Invocation)];
    task.callableStorage = callableStorage;
    if (const uint32_t lanes = state.batchLanes) {
      // A batch raygen: each row of the tile in one call (a tile is `lanes` wide).
      for (uint32_t y = y0; y < y1; ++y) {
        inv.launchId[0] = x0;
        inv.launchId[1] = y;
        inv.stackUsed = 0;
        inv.status = 0;
        run(inv, raygen, std::min(lanes, x1 - x0));
      }
      return;
    }
    for (uint32_t y = y0; y < y1; ++y) {
      for (uint32_t x = x0; x < x1; ++x) {
        // What a raygen invocation changes in `inv` (run(), and OpTerminateRayKHR's status) is reset for the next.
        inv.launchId[0] = x;
        inv.launchId[1] = y;
        inv.stackUsed = 0;
        inv.status = 0;
        if (state.recorder) {
          inv.tree = nullptr;
          inv.base.rayQueries = &state.queries;
          if (RayTreeInvocation* tree = state.recorder->find(inv.launchId)) {
            // A named launch id: its raygen is the tree's root, and its ray queries go through the tree's scope.
            inv.tree = tree;
            inv.base.rayQueries = &tree->queries;
            tree->ran = true;
            RayTreeNode& root = tree->root;
            root.stage = "raygen";
            root.name = raygen.name;
            root.group = launch.raygenGroup->index;
            root.record = reinterpret_cast<uintptr_t>(launch.raygen.base);
          }
        }
        run(inv, raygen);
      }
    }
  }
}

}  // namespace

void runRays(const RayLaunch& launch) {
  if (!launch.raygenGroup || !launch.raygenGroup->general.entry) return;
  const uint64_t w = launch.size[0], h = launch.size[1], d = launch.size[2];
  if (w == 0 || h == 0 || d == 0) return;
  LaunchState state(launch);
  std::optional<Job> ownJob;
  state.job = launch.job ? launch.job : &ownJob.emplace(nullptr, 0);
  state.miss.init(launch.miss);
  state.hit.init(launch.hit);
  state.callable.init(launch.callable);
  state.recorder = launch.rayTree;
  if (state.recorder) state.recorder->setQueryScope(&state.queries);
  const RayShader& raygen = launch.raygenGroup->general;
  if (raygen.batch && raygen.batchLanes && !state.recorder) {
    state.batchLanes = raygen.batchLanes;
    state.tileW = raygen.batchLanes;
    state.tileH = std::max<uint32_t>(1, kTileIndices / raygen.batchLanes);
  }
  const uint64_t tilesX = (w + state.tileW - 1) / state.tileW, tilesY = (h + state.tileH - 1) / state.tileH;
  ThreadPool::instance().parallelFor(tilesX * tilesY * d, [&](uint64_t tile, unsigned) {
    // The tile's combined adds live here, outside the supervised task: a task cut short by a fault or the watchdog
    // still writes what its shaders added.
    abi::PendingAdds adds{~uint64_t(0), 0, 0, &abi::flushPendingAdds};
    auto task = [&] { runTile(state, tile, tilesX, tilesY, launch.combineAdds ? &adds : nullptr); };
    runSupervised(
        *state.job, [](void* t) { (*static_cast<decltype(task)*>(t))(); }, &task);
    abi::flushPendingAdds(&adds);
  });
}

}  // namespace vkrt::exec
