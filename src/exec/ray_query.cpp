#include "exec/ray_query.hpp"

#include <algorithm>
#include <cstring>
#include <new>

namespace vkrt::exec {

static_assert(sizeof(accel::RayQuery) <= abi::kRayQueryStateBytes && alignof(accel::RayQuery) <= 16,
              "a ray query's state must fit the variable compiled code reserves");

namespace {

// SPIR-V opcodes of OpRayQueryGet*KHR (spirv.hpp is the compiler's; these values are the specification's).
enum : uint32_t {
  kGetRayTMin = 6016,
  kGetRayFlags = 6017,
  kGetIntersectionT = 6018,
  kGetIntersectionInstanceCustomIndex = 6019,
  kGetIntersectionInstanceId = 6020,
  kGetIntersectionInstanceSbtOffset = 6021,
  kGetIntersectionGeometryIndex = 6022,
  kGetIntersectionPrimitiveIndex = 6023,
  kGetIntersectionBarycentrics = 6024,
  kGetIntersectionFrontFace = 6025,
  kGetIntersectionCandidateAabbOpaque = 6026,
  kGetIntersectionObjectRayDirection = 6027,
  kGetIntersectionObjectRayOrigin = 6028,
  kGetWorldRayDirection = 6029,
  kGetWorldRayOrigin = 6030,
  kGetIntersectionObjectToWorld = 6031,
  kGetIntersectionWorldToObject = 6032,
  kGetIntersectionType = 4479,
  kGetIntersectionTriangleVertexPositions = 5340,  // SPV_KHR_ray_tracing_position_fetch
};

accel::RayQuery& stateOf(void* query) { return *static_cast<accel::RayQuery*>(query); }

void initialize(const abi::RayQueryScope* scope, void* query, const abi::TraceRayArgs* args) {
  accel::Ray ray;
  std::memcpy(ray.origin, args->origin, sizeof ray.origin);
  std::memcpy(ray.direction, args->direction, sizeof ray.direction);
  ray.tMin = args->tMin;
  ray.tMax = args->tMax;
  ray.flags = args->rayFlags;
  ray.cullMask = args->cullMask & 0xFF;  // only the low 8 bits are used
  const accel::Tlas* tlas =
      scope
          ? const_cast<RayQueryScope*>(static_cast<const RayQueryScope*>(scope))->topLevel(args->accelerationStructure)
          : nullptr;
  accel::queryInitialize(*new (query) accel::RayQuery(), tlas, ray);
}

uint32_t proceed(void* query) { return accel::queryProceed(stateOf(query)) ? 1 : 0; }
void terminate(void* query) { accel::queryTerminate(stateOf(query)); }
void generate(void* query, float t) { accel::queryGenerate(stateOf(query), t); }
void confirm(void* query) { accel::queryConfirm(stateOf(query)); }

void get(void* query, uint32_t op, uint32_t committed, void* out) {
  const accel::RayQuery& q = stateOf(query);
  auto* f = static_cast<float*>(out);
  auto* u = static_cast<uint32_t*>(out);
  std::memset(out, 0, 64);
  switch (op) {
    case kGetRayTMin: f[0] = q.ray.tMin; return;
    case kGetRayFlags: u[0] = q.ray.flags; return;
    case kGetWorldRayOrigin: std::memcpy(f, q.ray.origin, 12); return;
    case kGetWorldRayDirection: std::memcpy(f, q.ray.direction, 12); return;
    case kGetIntersectionType: u[0] = committed ? q.committed.type : (q.candidate.type == 2 ? 1 : 0); return;
    case kGetIntersectionCandidateAabbOpaque: u[0] = q.candidate.type == 2 && q.candidate.opaque; return;
    default: break;
  }
  const accel::QueryHit& s = committed ? q.committed : q.candidate;
  if (!s.type) return;  // no intersection: zeros
  const accel::HitInfo h = accel::queryHitInfo(q, committed != 0);
  switch (op) {
    case kGetIntersectionT: f[0] = h.t; return;
    case kGetIntersectionInstanceCustomIndex: u[0] = h.customIndex; return;
    case kGetIntersectionInstanceId: u[0] = h.instanceIndex; return;
    case kGetIntersectionInstanceSbtOffset: u[0] = h.sbtOffset; return;
    case kGetIntersectionGeometryIndex: u[0] = h.geometryIndex; return;
    case kGetIntersectionPrimitiveIndex: u[0] = h.primitiveIndex; return;
    case kGetIntersectionBarycentrics:
      if (h.triangle) std::memcpy(f, h.barycentrics, 8);
      return;
    case kGetIntersectionFrontFace: u[0] = h.triangle && h.hitKind == accel::kHitKindFrontFacingTriangle; return;
    case kGetIntersectionObjectRayDirection: std::memcpy(f, h.objectRayDirection, 12); return;
    case kGetIntersectionObjectRayOrigin: std::memcpy(f, h.objectRayOrigin, 12); return;
    case kGetIntersectionObjectToWorld:
    case kGetIntersectionWorldToObject: {
      // The ABI's matrices are 4 columns of 3 floats: the transpose of the rows the Tlas keeps.
      const float(*m)[4] = op == kGetIntersectionObjectToWorld ? h.objectToWorld : h.worldToObject;
      for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 3; ++r) f[3 * c + r] = m[r][c];
      return;
    }
    case kGetIntersectionTriangleVertexPositions: {  // 3 vec3, packed (zeros for a box)
      float v[3][3];
      accel::trianglePositions(h, v);
      std::memcpy(f, v, sizeof v);
      return;
    }
    default: return;
  }
}

const abi::RayQueryRuntime kRuntime = {&initialize, &proceed, &terminate, &generate, &confirm, &get};

}  // namespace

const abi::RayQueryRuntime& rayQueryRuntime() { return kRuntime; }

RayQueryScope::RayQueryScope(TopLevelResolver* resolver) : resolver_(resolver) { runtime = &kRuntime; }

TopLevelResolver::RangeIndex TopLevelResolver::rangeIndex(const uint64_t* addresses, size_t count, uint32_t* firstOf) {
  RangeIndex index;
  index.lo = addresses[0];
  const uint64_t span = addresses[count - 1] - index.lo;
  // The shift that cuts the span into `ranges` (>= 2) ranges (ends by 63; a single address has span 0).
  auto shiftFor = [span](uint64_t ranges) {
    unsigned shift = 0;
    while ((span >> shift) >= ranges) ++shift;
    return shift;
  };
  uint64_t n = 1;
  while (n < count) n *= 2;
  // Direct where ranges of twice or four times the power of two hold an address each at most.
  for (const uint64_t ranges : {2 * n, 4 * n}) {
    const unsigned shift = shiftFor(ranges);
    size_t i = 1;
    while (i < count && ((addresses[i] - index.lo) >> shift) != ((addresses[i - 1] - index.lo) >> shift)) ++i;
    if (i == count) {
      index.shift = shift;
      index.ranges = ranges;
      index.direct = true;
      return index;
    }
  }
  index.shift = shiftFor(n);
  uint64_t r = 0;
  for (size_t i = 0; i < count; ++i)
    for (const uint64_t ri = (addresses[i] - index.lo) >> index.shift; r <= ri;) firstOf[r++] = uint32_t(i);
  while (r <= n) firstOf[r++] = uint32_t(count);
  index.ranges = n;
  uint32_t fullest = 0;
  for (r = 0; r < n; ++r) fullest = std::max(fullest, firstOf[r + 1] - firstOf[r]);
  while ((uint64_t(1) << index.steps) < fullest) ++index.steps;
  return index;
}

void TopLevelResolver::layOut(const RangeIndex& index, const uint64_t* addresses, size_t count, Entry* entries) {
  if (index.direct) {
    // A range without an address holds one of the range below it (range 0 holds the lowest address), which locate
    // never looks for there. Where r << shift passes 2^64, the filler's range (taken modulo 2^64) is below r too.
    for (uint64_t r = 0; r < index.ranges; ++r) entries[r].address = index.lo + (r << index.shift) - 1;
    for (size_t i = 0; i < count; ++i) entries[slot(index, i, addresses[i])].address = addresses[i];
    return;
  }
  for (size_t i = 0; i < count; ++i) entries[i].address = addresses[i];
  for (size_t i = count; i < count + index.padding(); ++i) entries[i].address = ~uint64_t(0);
}

void TopLevelResolver::takeSnapshot() {
  std::lock_guard lock(mutex_);
  if (ready_.load(std::memory_order_relaxed)) return;
  Snapshot s;
  snapshot(&s);
  if (const size_t n = s.structures.size()) {
    std::vector<uint64_t> addresses(n);
    for (size_t i = 0; i < n; ++i) addresses[i] = s.structures[i].first;
    firstOf_ = std::make_unique<uint32_t[]>(2 * n + 1);
    index_ = rangeIndex(addresses.data(), n, firstOf_.get());
    if (index_.direct) firstOf_.reset();
    entries_ = std::make_unique<Entry[]>(index_.entries(n));
    layOut(index_, addresses.data(), n, entries_.get());
    count_ = n;
    kept_.reserve(n);
    for (size_t i = 0; i < n; ++i) {
      auto& [address, tlas] = s.structures[i];
      if (!tlas) continue;
      entries_[slot(index_, i, address)].tlas.store(tlas.get(), std::memory_order_relaxed);  // (published by ready_)
      kept_.push_back(std::move(tlas));
    }
  }
  ready_.store(true, std::memory_order_release);
}

const accel::Tlas* TopLevelResolver::resolveEntry(Entry& entry) {
  std::lock_guard lock(mutex_);
  const accel::Tlas* t = entry.tlas.load(std::memory_order_relaxed);
  if (!t) {
    std::shared_ptr<const accel::Tlas> kept = resolve(entry.address);
    t = kept ? kept.get() : unresolvable();
    if (kept) kept_.push_back(std::move(kept));
    entry.tlas.store(t, std::memory_order_release);
  }
  return t;
}

}  // namespace vkrt::exec
