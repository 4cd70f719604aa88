// Acceleration structures and their traversal, on Embree 3: plain C++, no Vulkan types (the runtime converts
// Vulkan build inputs into the types here, and the trace executor drives the traversal).
//
// A bottom-level structure (Blas) owns copies of its geometries: triangles (float vertices, 32-bit indices) and
// axis-aligned boxes, each with its geometry flags. A top-level structure (Tlas) owns its instances, each holding
// the Blas it instantiates (shared: the Blas lives as long as a Tlas that was built with it, whatever happens to
// the Vulkan object it came from). Geometry index = position in the Blas, primitive index = position in its
// geometry, instance index = position in the Tlas: they are what the shaders' built-ins report.
//
// Traversal follows the ray traversal rules of the Vulkan specification ("Ray Traversal"): instance masks, ray
// flags, instance flags, geometry flags, triangle facing, opacity, the any-hit and intersection shaders (through
// a HitHandler), closest-hit commitment and termination. Builds and traversal are thread-safe: any number of
// threads may traverse one structure at once.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

namespace vkrt::accel {

// The values of VkGeometryFlagBitsKHR.
enum GeometryFlag : uint32_t { kGeometryOpaque = 0x1, kGeometryNoDuplicateAnyHit = 0x2 };

// The values of VkGeometryInstanceFlagBitsKHR.
enum InstanceFlag : uint32_t {
  kInstanceTriangleFacingCullDisable = 0x1,
  kInstanceTriangleFlipFacing = 0x2,
  kInstanceForceOpaque = 0x4,
  kInstanceForceNoOpaque = 0x8,
};

// The values of the SPIR-V RayFlags operand (gl_RayFlags*EXT).
enum RayFlag : uint32_t {
  kRayOpaque = 0x1,
  kRayNoOpaque = 0x2,
  kRayTerminateOnFirstHit = 0x4,
  kRaySkipClosestHitShader = 0x8,
  kRayCullBackFacingTriangles = 0x10,
  kRayCullFrontFacingTriangles = 0x20,
  kRayCullOpaque = 0x40,
  kRayCullNoOpaque = 0x80,
  kRaySkipTriangles = 0x100,
  kRaySkipAabbs = 0x200,
};

// gl_HitKindEXT of triangle hits.
inline constexpr uint32_t kHitKindFrontFacingTriangle = 0xFE;
inline constexpr uint32_t kHitKindBackFacingTriangle = 0xFF;

// The allocator of large arrays that their maker fills at once, in parallel: resizing leaves their storage untouched
// (no value initialization), so each page is first written, and faulted in, by the thread that fills it, not all
// of them by the thread that resized (for 10^7 triangles' indices, 120 MB). Whoever fills an element constructs it
// first (placement new) where it is not trivial. Everything else (initializer lists, copies, push_back, resize with
// a value) is std::allocator's.
template <class T>
struct FillArrayAllocator : std::allocator<T> {
  static_assert(std::is_trivially_destructible_v<T>);
  FillArrayAllocator() = default;
  template <class U>
  FillArrayAllocator(const FillArrayAllocator<U>&) noexcept {}
  template <class U>
  struct rebind {
    using other = FillArrayAllocator<U>;
  };
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    if constexpr (sizeof...(Args) > 0) ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};
template <class T>
using FillArray = std::vector<T, FillArrayAllocator<T>>;

struct TriangleGeometry {
  // x, y, z per vertex, in the Blas's space (any build transform applied). With room for one float more (capacity),
  // Embree reads the Blas's copy in place instead of copying it.
  FillArray<float> vertices;
  FillArray<uint32_t> indices;  // three per triangle (the runtime expands non-indexed geometry)
  uint32_t flags = 0;           // GeometryFlag
};

struct AabbGeometry {
  FillArray<float> boxes;  // min x, y, z, max x, y, z per primitive
  uint32_t flags = 0;      // GeometryFlag
};

struct Geometry {
  enum Kind : uint8_t { Triangles, Aabbs } kind = Triangles;
  TriangleGeometry triangles;  // kind == Triangles
  AabbGeometry aabbs;          // kind == Aabbs
};

// Inactive primitives (Vulkan "Inactive Primitives and Instances": a triangle with a NaN x in any of its vertices,
// a box whose min x is NaN) are kept in place, so that the indices of the others do not move, and are never hit.
// (Embree also leaves out triangles with other non-finite coordinates or out-of-range indices, and boxes with
// non-finite bounds: they are never hit either.)

class Blas;

struct Instance {
  float transform[3][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}};  // object to world, rows (VkTransformMatrixKHR)
  uint32_t customIndex = 0;                                            // 24 bits: gl_InstanceCustomIndexEXT
  uint32_t mask = 0xFF;    // 8 bits: the instance is skipped by rays whose cull mask shares no bit with it
  uint32_t sbtOffset = 0;  // 24 bits: instanceShaderBindingTableRecordOffset
  uint32_t flags = 0;      // InstanceFlag
  // null: an inactive instance (reference 0), never hit. Not owned: the Blas is one a shared_ptr owns (Blas::build,
  // update and deserializeBlas make no other), which the caller keeps alive until Tlas::build returns; the Tlas
  // then holds each distinct one itself. (A pointer rather than a shared_ptr: copying a shared_ptr per instance is
  // an atomic increment of one shared count, which serialized the build threads over 10^5-10^6 instances.)
  const Blas* blas = nullptr;
};

// How a structure is built (VkBuildAccelerationStructureFlagBitsKHR, as far as Embree can honour them; the mapping
// to Embree's build qualities and scene flags is detail::sceneSettings in blas.cpp). They never change what is hit.
struct BuildOptions {
  bool preferFastTrace = false;
  bool preferFastBuild = false;
  bool allowUpdate = false;  // keeps what a later update() needs
  bool lowMemory = false;
};

class Blas : public std::enable_shared_from_this<Blas> {
 public:
  // Builds from `geometries` (taken over). Fails, with `error` set, when Embree cannot build (out of memory).
  static std::shared_ptr<Blas> build(std::vector<Geometry> geometries, const BuildOptions& options, std::string* error);
  ~Blas();

  // An update (VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR): the same geometries with new vertex positions
  // or boxes. The result is a new Blas; this one is unchanged (it may be traversed meanwhile). When this one was
  // built with allowUpdate and the geometries keep its counts, kinds, indices, flags and active primitives (as
  // Vulkan requires of an update), the new one is a refit of an Embree hierarchy of the same topology (one left
  // idle by a Blas of the same family that died, else a new one); otherwise it is a full build with the same
  // options, so that a caller breaking the rules still gets the structure its inputs describe.
  std::shared_ptr<Blas> update(std::vector<Geometry> geometries, std::string* error) const;

  const std::vector<Geometry>& geometries() const;
  const BuildOptions& options() const;
  uint64_t primitiveCount() const;

  // The bytes the structure occupies (its copies of the inputs and Embree's hierarchy, estimated): what the
  // runtime reports as its compacted size.
  uint64_t nativeBytes() const;

  struct Impl;
  std::unique_ptr<Impl> impl;
};

// A top level's instances in one array that its maker may fill on several threads: uninitialized(n) leaves the n
// elements unconstructed, for the maker to construct each (placement new) before the array is read or built on.
// (A std::vector<Instance> of 10^6 instances is value-initialized, and its 72 MB faulted in, by the one thread that
// sizes it: a third of a top-level build's time on 16 threads.)
class InstanceArray {
 public:
  InstanceArray() = default;
  explicit InstanceArray(const std::vector<Instance>& instances);
  static InstanceArray uninitialized(size_t n);

  Instance* data() { return p_.get(); }
  const Instance* data() const { return p_.get(); }
  size_t size() const { return n_; }
  Instance& operator[](size_t i) { return p_.get()[i]; }
  const Instance& operator[](size_t i) const { return p_.get()[i]; }

 private:
  struct Free {
    void operator()(Instance* p) const;
  };
  std::unique_ptr<Instance, Free> p_;
  size_t n_ = 0;
};

class Tlas {
 public:
  static std::shared_ptr<Tlas> build(InstanceArray instances, const BuildOptions& options, std::string* error);
  static std::shared_ptr<Tlas> build(const std::vector<Instance>& instances, const BuildOptions& options,
                                     std::string* error) {
    return build(InstanceArray(instances), options, error);
  }
  // A new Tlas with the same options; this one is unchanged. (Embree 3 rebuilds the hierarchy over its instances
  // on every commit, refit or not, so an update is a build.)
  std::shared_ptr<Tlas> update(InstanceArray instances, std::string* error) const;
  std::shared_ptr<Tlas> update(const std::vector<Instance>& instances, std::string* error) const {
    return update(InstanceArray(instances), error);
  }

  std::span<const Instance> instances() const;
  const BuildOptions& options() const;
  uint64_t nativeBytes() const;

  struct Impl;
  // The structure (structures.hpp). A Tlas has no data of its own: every Tlas is made by build or update as the
  // base of a TlasBlock, whose Impl starts at the Tlas's own address, so a ray reaches it without a load.
  const Impl& impl() const;

 protected:
  Tlas() = default;
  ~Tlas();
};

// ------------------------------------------------------------------------------------------------ traversal

struct Ray {
  float origin[3] = {0, 0, 0};
  float tMin = 0;
  float direction[3] = {0, 0, 1};
  float tMax = 0;
  uint32_t flags = 0;  // RayFlag (the pipeline's SKIP_TRIANGLES / SKIP_AABBS flags already or-ed in)
  uint32_t cullMask = 0xFF;
};

// A hit, candidate or committed: what the any-hit, intersection and closest-hit shaders' built-ins read.
struct HitInfo {
  float t = 0;
  uint32_t instanceIndex = 0;   // gl_InstanceID
  uint32_t customIndex = 0;     // gl_InstanceCustomIndexEXT
  uint32_t sbtOffset = 0;       // the instance's SBT record offset
  uint32_t geometryIndex = 0;   // gl_GeometryIndexEXT
  uint32_t primitiveIndex = 0;  // gl_PrimitiveID
  uint32_t hitKind = 0;         // triangles: kHitKind*; boxes: what the intersection shader reported
  bool triangle = true;
  float barycentrics[2] = {0, 0};  // triangles: the weights of vertices 1 and 2
  // The instance's transform (rows) and its inverse, kept by the Tlas (valid while it lives).
  const float (*objectToWorld)[4] = nullptr;
  const float (*worldToObject)[4] = nullptr;
  float objectRayOrigin[3] = {};  // the ray in the instance's object space
  float objectRayDirection[3] = {};
  const Blas::Impl* blas = nullptr;  // the instance's Blas (valid while the Tlas lives): see trianglePositions
};

// VK_KHR_ray_tracing_position_fetch (HitTriangleVertexPositionsKHR, OpRayQueryGetIntersectionTriangleVertex-
// PositionsKHR): the three vertex positions of `hit`'s triangle in object space, as the Blas keeps them (after the
// build's transform; before the instance's), in the order of its indices. Every Blas keeps its vertices (also
// through updates, copies, compaction and serialization), whether or not it was built with ALLOW_DATA_ACCESS.
// Returns false with `out` zeroed when the hit is no triangle of a Blas (a box, no hit).
bool trianglePositions(const HitInfo& hit, float out[3][3]);

enum class AnyHitResult { Accept, Ignore, AcceptAndTerminate };

// A box primitive under test: the intersection shader's view of the traversal. Valid only during
// HitHandler::intersect.
class ProceduralCandidate {
 public:
  virtual ~ProceduralCandidate() = default;
  virtual const HitInfo& info() const = 0;  // t and hitKind unset
  virtual float tMin() const = 0;
  virtual float tMax() const = 0;   // the closest committed hit so far, or the ray's tMax
  virtual bool opaque() const = 0;  // after geometry, instance and ray flags
  // Commits a hit of this primitive at `t` with `hitKind` (the caller has run the any-hit shader, if any, and
  // checked tMin() <= t <= tMax(); a `t` outside that interval is ignored here too). `terminate`: the traversal
  // stops after it (an any-hit shader's terminateRayEXT). Under kRayTerminateOnFirstHit every commit stops it.
  virtual void commit(float t, uint32_t hitKind, bool terminate) = 0;
};

// What the traversal calls while it runs; implemented by the trace executor (the shaders).
class HitHandler {
 public:
  virtual ~HitHandler() = default;
  // A candidate triangle hit that is not opaque (the any-hit shader decides), inside [tMin, closest so far].
  virtual AnyHitResult anyHit(const HitInfo& candidate) = 0;
  // A box primitive whose box the ray enters (the intersection shader runs; it may commit hits).
  virtual void intersect(ProceduralCandidate& candidate) = 0;
};

// The committed hit as traversal leaves it: which primitive, where, and what selects its hit group. The other
// built-ins (the object-space ray, the transforms, a triangle's facing) come from hitInfo(), which a launch calls
// only when a closest-hit shader runs: most rays of a launch whose hit groups have no closest-hit shader never
// need them.
struct CommittedHit {
  float t;
  uint32_t instance, geometry, primitive;
  uint32_t hitKind;    // boxes: the intersection shader's; triangles: kHitKind*, or 0 where hitInfo() finds it
  uint32_t sbtOffset;  // the instance's SBT record offset
  bool triangle;
  float u, v;   // triangles: the barycentrics of vertices 1 and 2
  float ng[3];  // triangles: (v1 - v0) x (v2 - v0) in the instance's object space (the facing, where hitKind is 0)
};

// Traces `ray` through `tlas`. Returns true with the committed hit in `hit` (may be null) when there is one. The
// handler is called only for candidates that need a shader; a ray that meets only opaque triangles runs at
// Embree's speed (no filter callback at all where no ray flag or instance flag asks for one). Triangles are hit
// for tMin < t < tMax, boxes are candidates for tMin <= t <= tMax (both as "Ray Intersection Candidate
// Determination" says). A ray Vulkan does not allow (non-finite origin or direction, tMin < 0, tMin > tMax)
// misses. A TerminateOnFirstHit ray whose committed hit the caller does not read (`hit` null: a shadow ray that
// skips its closest-hit shader) is Embree's occlusion query without the filter callback that records which triangle
// ended it (where its opaque triangles need no filter for another reason).
bool trace(const Tlas& tlas, const Ray& ray, HitHandler& handler, CommittedHit* hit);
// Asks for the cache lines a trace through `tlas` reads first (the 128-byte pair at the structure's own address:
// the fields every ray reads and a small top level's first instance record, structures.hpp), for a caller that
// knows the structure some work before it traces: a ray through one of many top levels then waits less for them.
inline void prefetchForTrace(const Tlas& tlas) {
  const char* p = reinterpret_cast<const char*>(&tlas);
  __builtin_prefetch(p);
  __builtin_prefetch(p + 64);
}
// Rays traced together (tracePacket): at most kPacketRays, each one trace() would trace through `tlas` without a
// callback, where packetTraceable() says so: the top level's triangles are all in its flattened scene (a small top
// level), no box is in reach, and the ray needs no filter (no any-hit shader or culling can apply: the opaque
// triangles of needsTriangleFilter's test). Such a ray meets nothing that calls back, so the packet's rays are
// independent: each gets what trace() would commit for it. packetTraceable() depends on the structure and the ray's
// flags alone.
inline constexpr uint32_t kPacketRays = 16;
bool packetTraceable(const Tlas& tlas, const Ray& ray);
// Traces the rays of `mask` (bit i: rays[i], each packetTraceable) with one Embree packet query; returns the mask of
// those that hit, with their committed hits in `hits` (the rest untouched). Where coherentDirections() says the rays
// run side by side, Embree traverses them coherently (one frustum for the packet): each lane hits or misses as
// trace() would, and commits what trace() commits except at a tie (a ray through a shared edge or vertex), where it
// may keep the other triangle, at a t a float or two away.
uint32_t tracePacket(const Tlas& tlas, const Ray* rays, uint32_t mask, CommittedHit* hits);
// Whether the kPacketRays directions (dx[i], dy[i], dz[i]) of the lanes where valid[i] != 0 lie within about 8 degrees
// of the first such lane's: rays of a camera or toward a light, or reflected off one flat surface, do; bounces off a
// rough surface do not. Embree's coherent packet traversal takes twice as many camera rays per second as its
// incoherent one and a third fewer scattered bounces. False for no valid lane.
bool coherentDirections(const float* dx, const float* dy, const float* dz, const int* valid);
// The built-ins of `hit`, committed by trace() for `ray` through `tlas`: every field of `out` is assigned.
void hitInfo(const Tlas& tlas, const Ray& ray, const CommittedHit& hit, HitInfo* out);
// trace() and hitInfo() together.
bool trace(const Tlas& tlas, const Ray& ray, HitHandler& handler, HitInfo* hit);

// The number of threads Embree's builders use, for the process's Embree device (created at the first build; a
// call after that changes nothing). 0, the default: every hardware thread. The runtime passes its worker pool's
// count, so that VKRT_THREADS sizes builds as it sizes launches and dispatches.
void setBuildThreads(unsigned threads);

// The Embree kernels (instruction set) of the process's Embree device: "sse2", "sse4.2", "avx", "avx2" or
// "avx512" (Embree's `isa=` option), or empty for the CPU's best. Like setBuildThreads, it applies to the device
// created at the first build; false (with `error` set) for a name Embree does not know, or once the device exists
// with another choice. Embree falls back to the best set the CPU runs when the one named is beyond it; isaInUse()
// says which set that is.
bool setIsa(std::string_view isa, std::string* error);
// The instruction set Embree's kernels use (or will use, before the first build): the one setIsa() chose, capped
// by what the CPU runs and what Debian's Embree was compiled for (SSE2, SSE4.2, AVX, AVX2, AVX-512).
const char* isaInUse();

// ------------------------------------------------------------------------------------------ serialization
//
// The opaque part of a serialized structure (the runtime writes the header the Vulkan specification defines
// before it, with the bottom-level references). `blasRefs` (filled by serialize) has one entry per instance, its
// Blas (null for an inactive instance); deserializeTlas takes the same list, each entry resolved by the caller.
std::vector<uint8_t> serialize(const Blas& blas);
std::vector<uint8_t> serialize(const Tlas& tlas, std::vector<const Blas*>* blasRefs);
// Whether serialized data (as serialize() writes it) holds a top-level structure; false for anything else.
bool serializedTopLevel(const uint8_t* data, size_t size);
std::shared_ptr<Blas> deserializeBlas(const uint8_t* data, size_t size, std::string* error);
std::shared_ptr<Tlas> deserializeTlas(const uint8_t* data, size_t size,
                                      const std::vector<std::shared_ptr<const Blas>>& blasRefs, std::string* error);

}  // namespace vkrt::accel

namespace vkrt::accel {

// ---------------------------------------------------------------------------------------------- ray queries
//
// A ray query (VK_KHR_ray_query, OpRayQuery*KHR): the traversal driven by the shader instead of by callbacks. The
// whole state is this plain struct, which lives in the invocation (compiled code reserves abi::kRayQueryStateBytes
// for it): nothing is allocated per query. See query.cpp for the algorithm (each proceed() is one traversal that
// finds the next candidate in a fixed order).
struct QueryHit {
  float t = 0;
  uint32_t instance = 0, geometry = 0, primitive = 0;
  uint32_t hitKind = 0;  // triangles: kHitKind*; generated hits: 0
  uint8_t type = 0;      // candidate: 1 triangle, 2 box; committed: 0 none, 1 triangle, 2 generated
  bool opaque = false;   // candidate boxes: after geometry, instance and ray flags
  float barycentrics[2] = {0, 0};
};

struct QueryCrossing {  // a triangle candidate already returned (for the shared-edge rule, see traverse.cpp)
  uint32_t instance;
  float t;
  float v[3][3];  // world space
};

struct RayQuery {
  const Tlas* tlas = nullptr;  // null: no structure (nothing is hit)
  Ray ray;
  uint32_t phase = 0;  // 0: not initialized or done (proceed() returns false), 1: traversing
  QueryHit candidate, committed;
  bool returned = false;  // a candidate was returned: `last` holds its order key
  struct Key {
    float t;
    uint32_t kind, instance, geometry, primitive;
  } last{};
  static constexpr uint32_t kCrossings = 4;
  QueryCrossing crossings[kCrossings];
  uint32_t crossingCount = 0;
};

// OpRayQueryInitializeKHR (`tlas` may be null: an unresolved structure, nothing is hit).
void queryInitialize(RayQuery& q, const Tlas* tlas, const Ray& ray);
// OpRayQueryProceedKHR: true with q.candidate set when a candidate needs the shader.
bool queryProceed(RayQuery& q);
// OpRayQueryConfirmIntersectionKHR (a triangle candidate), OpRayQueryGenerateIntersectionKHR (a box candidate),
// OpRayQueryTerminateKHR.
void queryConfirm(RayQuery& q);
void queryGenerate(RayQuery& q, float t);
void queryTerminate(RayQuery& q);
// The built-ins of the candidate or the committed hit (instance data, matrices, object-space ray); zeros when none.
HitInfo queryHitInfo(const RayQuery& q, bool committed);

}  // namespace vkrt::accel
