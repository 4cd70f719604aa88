// The compiled-code ABI: the calling convention between compiled shaders (src/spirv) and the code that runs
// them (src/exec, src/runtime), and the memory they share (descriptor records). Plain data: no Vulkan objects,
// no LLVM. Everything here is baked into compiled code, and compiled code is stored in pipeline caches: a
// change to a layout or an offset must change the cache format version (src/spirv/cache_blob.cpp).
//
// ---------------------------------------------------------------------------------------------- compute
//
// A compiled compute entry point is `void entry(InvocationContext*)`, run once per invocation (`vkrt_main`),
// or for shaders without barriers once per workgroup (`vkrt_group`: it sets globalId, localId and localIndex
// itself). Everything it reads from outside comes through the context: built-ins, resources, push constants,
// workgroup memory, and the barrier callback. The compiler reads these fields at the offsets asserted below.
#pragma once

#include <cstddef>
#include <cstdint>

namespace vkrt::abi {

// DESCRIPTOR STORAGE (what compiled shaders load from)
// ----------------------------------------------------
// A descriptor set is one flat, 32-byte aligned array of DescriptorRecord (32 bytes each), one record per
// array element of every binding, bindings in increasing binding number. Binding b's element i lives at a
// record index the set layout fixes (src/runtime/descriptor_set_layout.hpp); a compiled shader receives each
// binding it uses as a ResourceSlot (below) and indexes its elements.
//
// Record contents by descriptor type (fields not listed are zero):
//   UNIFORM_BUFFER, STORAGE_BUFFER          address = device address of byte `offset` of the buffer,
//                                           range   = bytes in range (VK_WHOLE_SIZE already resolved),
//                                           object  = the buffer
//   UNIFORM/STORAGE_BUFFER_DYNAMIC          the same; the dynamic offset bound with the set is added to
//                                           `address` in the records a dispatch hands to the shader
//   UNIFORM/STORAGE_TEXEL_BUFFER            object  = the buffer view
//   SAMPLED_IMAGE, STORAGE_IMAGE            object  = the image view
//   COMBINED_IMAGE_SAMPLER                  object  = the image view, sampler = the sampler
//                                           (from pImmutableSamplers when the binding has them)
//   SAMPLER                                 sampler = the sampler
//   ACCELERATION_STRUCTURE_KHR              address = the acceleration structure's device address
//                                           (vkGetAccelerationStructureDeviceAddressKHR), object = the object
// and, for the four types whose object is an image view (SAMPLED_IMAGE, STORAGE_IMAGE, COMBINED_IMAGE_SAMPLER,
// INPUT_ATTACHMENT), address = the view's ImageTexels (below), range = 0 (so a buffer access through a record of
// one of them, a type mismatch the application should not make, is out of bounds).
// A record of all zeros is an unwritten descriptor. `object` and `sampler` are opaque to compiled code: they
// point at the runtime's objects, which only the runtime's functions (image_functions.hpp) look into, except for
// one word: every runtime object holds its VkObjectType as a 32-bit value at kObjectTypeOffset.
struct alignas(32) DescriptorRecord {
  uint64_t address;     // byte 0
  uint64_t range;       // byte 8
  const void* object;   // byte 16
  const void* sampler;  // byte 24
};
static_assert(sizeof(DescriptorRecord) == 32 && offsetof(DescriptorRecord, address) == 0 &&
                  offsetof(DescriptorRecord, range) == 8 && offsetof(DescriptorRecord, object) == 16 &&
                  offsetof(DescriptorRecord, sampler) == 24,
              "the compiler bakes the descriptor record layout into shader code");

inline constexpr uint64_t kObjectTypeOffset = 8;
inline constexpr uint32_t kObjectTypeImageView = 14;  // VK_OBJECT_TYPE_IMAGE_VIEW

// An image view's texels as compiled code may address them itself (SPMD storage image loads and stores,
// src/spirv/spmd.cpp): a 2D view of a one-sample 2D image, its base level and layer, in one of the formats `kind`
// names; kind 0 for every other view (and for a view created before its image had memory), which compiled code then
// leaves to the runtime's functions. Compiled code reads a record's `address` as an ImageTexels only after it found
// the record's object to be an image view (its type word), so that no other record's address is ever read as one.
// The texel at (x, y) is at base + y * rowPitch + x * texelBytes for x < width and y < height; its bytes are
// what the runtime's functions read and write (vkrt_image_read/vkrt_image_write).
struct ImageTexels {
  uint8_t* base;        // 0
  uint64_t rowPitch;    // 8
  uint32_t width;       // 16
  uint32_t height;      // 20
  uint32_t kind;        // 24: kTexels* bits
  uint32_t texelBytes;  // 28
};
static_assert(offsetof(ImageTexels, base) == 0 && offsetof(ImageTexels, rowPitch) == 8 &&
                  offsetof(ImageTexels, width) == 16 && offsetof(ImageTexels, height) == 20 &&
                  offsetof(ImageTexels, kind) == 24 && offsetof(ImageTexels, texelBytes) == 28 &&
                  sizeof(ImageTexels) == 32,
              "the compiler bakes the image texel record into shader code");
// ImageTexels::kind: 32-bit components stored as given (1, 2 or 4 words: SFLOAT, and with kTexelsInteger UINT or
// SINT, whose missing alpha a read gives as 1 rather than 1.0), or R8G8B8A8_UNORM (kTexelsUnorm8), B8G8R8A8_UNORM
// (with kTexelsBgra too).
inline constexpr uint32_t kTexelsWordsMask = 0x7;
inline constexpr uint32_t kTexelsInteger = 0x10;
inline constexpr uint32_t kTexelsUnorm8 = 0x20;
inline constexpr uint32_t kTexelsBgra = 0x40;

// One resource the shader uses (a buffer binding, possibly an array of descriptors): the executor resolves it
// per dispatch to the bound set's records for that binding.
struct ResourceSlot {
  const DescriptorRecord* records;  // the binding's element 0 (nullptr when nothing is bound)
  uint64_t count;                   // elements the binding has in the bound set
};

struct InvocationContext {
  uint32_t globalId[4];       // 0   GlobalInvocationId (x, y, z, unused)
  uint32_t localId[4];        // 16  LocalInvocationId
  uint32_t workgroupId[4];    // 32  WorkgroupId
  uint32_t numWorkgroups[4];  // 48  NumWorkgroups
  uint32_t workgroupSize[4];  // 64  WorkgroupSize
  uint32_t localIndex;        // 80  LocalInvocationIndex
  uint32_t pad0;
  const struct RayQueryScope* rayQueries;  // 88  OpRayQuery*KHR: the dispatch's or launch's ray query runtime
  const ResourceSlot* resources;           // 96   by slot, in the order the compiler lists the shader's resources
  const uint8_t* pushConstants;            // 104  kPushConstantBytes bytes
  uint8_t* workgroupMemory;                // 112  the shader's workgroup memory, shared by the workgroup
  void (*barrier)(InvocationContext*);     // 120  OpControlBarrier with Workgroup scope
  void* executor;                          // 128  the executor's per-invocation state
  uint8_t* sink;                           // 136  kSinkBytes bytes: out-of-bounds atomics land here
  // 144  the executor's cancellation flag (null: never cancelled). Compiled loops load it at each back edge
  // (relaxed) and, when it is nonzero, call `cancelled`, which does not return when the executor supervises the
  // work (exec/supervise.hpp: the watchdog's timeout, or a device being destroyed).
  const uint32_t* cancel;
  void (*cancelled)(InvocationContext*);  // 152
};

inline constexpr uint32_t kPushConstantBytes = 256;
inline constexpr uint32_t kSinkBytes = 64;

static_assert(offsetof(InvocationContext, globalId) == 0 && offsetof(InvocationContext, localId) == 16 &&
                  offsetof(InvocationContext, workgroupId) == 32 && offsetof(InvocationContext, numWorkgroups) == 48 &&
                  offsetof(InvocationContext, workgroupSize) == 64 && offsetof(InvocationContext, localIndex) == 80 &&
                  offsetof(InvocationContext, resources) == 96 && offsetof(InvocationContext, pushConstants) == 104 &&
                  offsetof(InvocationContext, workgroupMemory) == 112 && offsetof(InvocationContext, barrier) == 120 &&
                  offsetof(InvocationContext, executor) == 128 && offsetof(InvocationContext, sink) == 136 &&
                  offsetof(InvocationContext, rayQueries) == 88 && offsetof(InvocationContext, cancel) == 144 &&
                  offsetof(InvocationContext, cancelled) == 152 && sizeof(InvocationContext) == 160,
              "the compiler bakes these offsets into shader code");
static_assert(sizeof(ResourceSlot) == 16, "the compiler bakes the resource slot size into shader code");

using ComputeEntry = void (*)(InvocationContext*);

// ---------------------------------------------------------------------------------------------- ray queries
//
// OpRayQuery*KHR (VK_KHR_ray_query), in compute and ray tracing shaders. A variable of OpTypeRayQueryKHR is
// kRayQueryStateBytes bytes (16-byte aligned) in the invocation's own frame (Function) or private block (Private),
// opaque to compiled code: the runtime keeps the whole query there (no allocation per query). Compiled code
// calls the functions of `context->rayQueries->runtime` with the scope and the variable's address. The executor
// (compute dispatch, ray tracing launch) sets `rayQueries` for every invocation; the scope resolves acceleration
// structure addresses for the dispatch (cached: no lookup per query).
//
// RayQueryRuntime::get writes the value of OpRayQueryGet*KHR `op` (the SPIR-V opcode) for the candidate
// (committed = 0) or the committed intersection (1) at `out` (up to 64 bytes), laid out as the result type in
// the natural layout: scalars, vectors packed, matrices (ObjectToWorld/WorldToObject: 4 columns of 3 floats)
// column by column, arrays packed (OpRayQueryGetIntersectionTriangleVertexPositionsKHR: 3 vec3, 36 bytes);
// booleans as a 32-bit 0 or 1.
inline constexpr uint64_t kRayQueryStateBytes = 384;

struct RayQueryScope;
struct TraceRayArgs;

struct RayQueryRuntime {
  // OpRayQueryInitializeKHR; `args` as for traceRay (the SBT fields, payload and bytes are unused).
  void (*initialize)(const RayQueryScope* scope, void* query, const TraceRayArgs* args);
  uint32_t (*proceed)(void* query);                                      // 1: a candidate needs the shader
  void (*terminate)(void* query);                                        // OpRayQueryTerminateKHR
  void (*generateIntersection)(void* query, float hitT);                 // OpRayQueryGenerateIntersectionKHR
  void (*confirmIntersection)(void* query);                              // OpRayQueryConfirmIntersectionKHR
  void (*get)(void* query, uint32_t op, uint32_t committed, void* out);  // OpRayQueryGet*KHR
};

struct RayQueryScope {
  const RayQueryRuntime* runtime;  // 0
};
static_assert(offsetof(RayQueryScope, runtime) == 0 && offsetof(RayQueryRuntime, proceed) == 8 &&
                  offsetof(RayQueryRuntime, terminate) == 16 && offsetof(RayQueryRuntime, generateIntersection) == 24 &&
                  offsetof(RayQueryRuntime, confirmIntersection) == 32 && offsetof(RayQueryRuntime, get) == 40,
              "the compiler bakes these offsets into shader code");

// ---------------------------------------------------------------------------------------------- ray tracing
//
// A compiled ray tracing shader (any of the six stages) is `void vkrt_main(RayInvocation*)`, run once per
// invocation. The RayInvocation starts with an InvocationContext (resources, push constants, sink: the
// compute fields are unused) and adds the ray tracing built-ins, the incoming payload or callable data, the
// hit attributes, the shader record and the runtime the shader calls for OpTraceRayKHR,
// OpExecuteCallableKHR and OpReportIntersectionKHR. The runtime (the tracing executor; a test runtime in
// tests/spirv) fills the fields a stage reads before the call; the shader writes only `status` and memory
// reached through the pointers.
//
// Storage classes: RayPayloadKHR, CallableDataKHR and (in intersection shaders) HitAttributeKHR variables
// live in the invocation's own frame, laid out like Function variables (natural layout, see codegen.hpp);
// IncomingRayPayloadKHR / IncomingCallableDataKHR read and write `incoming` (the caller's variable, same
// layout: caller and callee are compiled by the same rules), HitAttributeKHR in any-hit and closest-hit
// shaders reads `hitAttributes`, ShaderRecordBufferKHR reads `shaderRecord` (explicit layout). Each is bounded
// by its byte count: a callee declaring a larger payload than its caller passed reads zeros past the end. A
// shader record read is also checked against `shaderRecordRegionBytes` (the SBT region's end), and one past it
// is told to the runtime (RayRuntime::shaderRecordOutsideRegion) before it reads what shaderRecordBytes allows.
//
// gl_HitTEXT is RayTmaxKHR (the runtime keeps `rayTmax` at the hit's t in any-hit and closest-hit shaders,
// at the closest t so far in intersection shaders). ObjectToWorldKHR / WorldToObjectKHR are 4 columns of 3
// floats, column-major (the transpose of VkTransformMatrixKHR's rows).

struct RayInvocation;
struct PendingAdds;

// OpTraceRayKHR's operands, as the shader passes them to RayRuntime::traceRay.
struct TraceRayArgs {
  uint64_t accelerationStructure;  // 0   the acceleration structure's device address
  uint32_t rayFlags;               // 8
  uint32_t cullMask;               // 12
  uint32_t sbtOffset;              // 16  SBT record offset
  uint32_t sbtStride;              // 20  SBT record stride
  uint32_t missIndex;              // 24
  float tMin;                      // 28
  float origin[3];                 // 32
  float tMax;                      // 44
  float direction[3];              // 48
  uint32_t payloadBytes;           // 60  bytes the shader's payload variable has
  void* payload;                   // 64  the payload variable (RayPayloadKHR or IncomingRayPayloadKHR)
};

struct RayRuntime {
  void (*traceRay)(RayInvocation* caller, const TraceRayArgs* args);
  void (*executeCallable)(RayInvocation* caller, uint32_t sbtIndex, void* data, uint64_t bytes);
  // Returns 1 when the hit was committed, 0 when it was not (outside [tMin, tMax] or ignored by the any-hit
  // shader). When the any-hit shader terminated the ray, the runtime also sets caller->status to
  // kRayStatusTerminate: the intersection shader stops.
  uint32_t (*reportIntersection)(RayInvocation* caller, float hitT, uint32_t hitKind, const void* attributes,
                                 uint64_t attributeBytes);
  // A read of `bytes` at `offset` of the shader record that ends past shaderRecordRegionBytes (the compiled code
  // calls it before the read, which then goes on as bounded by shaderRecordBytes).
  void (*shaderRecordOutsideRegion)(RayInvocation* caller, uint64_t offset, uint64_t bytes);
  // A ray generation batch's OpTraceRayKHR (RayBatchEntry): the traces of the lanes in `mask` (bit l: args[l], whose
  // launch id is (launchX0 + l, launchId[1], launchId[2])), with what traceRay would do for each, in lane order; the
  // runtime may traverse their rays together. caller->launchId[0] is launchX0 again when it returns.
  void (*traceRays)(RayInvocation* caller, const TraceRayArgs* args, uint32_t mask, uint32_t launchX0);
};

// RayInvocation::status: what ended the shader. 0: it ran to its end (any-hit: the hit is accepted).
inline constexpr uint32_t kRayStatusIgnore = 1;     // OpIgnoreIntersectionKHR
inline constexpr uint32_t kRayStatusTerminate = 2;  // OpTerminateRayKHR (or an any-hit shader's, seen by intersection)

struct RayInvocation {
  InvocationContext base;       // 0
  uint32_t launchId[4];         // 160  LaunchIdKHR
  uint32_t launchSize[4];       // 176  LaunchSizeKHR
  float worldRayOrigin[4];      // 192  WorldRayOriginKHR
  float worldRayDirection[4];   // 208  WorldRayDirectionKHR
  float objectRayOrigin[4];     // 224  ObjectRayOriginKHR
  float objectRayDirection[4];  // 240  ObjectRayDirectionKHR
  float rayTmin;                // 256  RayTminKHR
  float rayTmax;                // 260  RayTmaxKHR, HitTNV
  uint32_t incomingRayFlags;    // 264  IncomingRayFlagsKHR
  uint32_t cullMask;            // 268  CullMaskKHR
  int32_t instanceCustomIndex;  // 272  InstanceCustomIndexKHR
  int32_t instanceId;           // 276  InstanceId
  int32_t primitiveId;          // 280  PrimitiveId
  int32_t geometryIndex;        // 284  RayGeometryIndexKHR
  uint32_t hitKind;             // 288  HitKindKHR
  uint32_t status;              // 292  written by the shader: kRayStatus*
  uint64_t pad0;                // 296
  float objectToWorld[4][3];    // 304  ObjectToWorldKHR
  float worldToObject[4][3];    // 352  WorldToObjectKHR
  void* incoming;               // 400  incoming payload or callable data
  uint64_t incomingBytes;       // 408
  const void* hitAttributes;    // 416  any-hit / closest-hit: the hit's attributes
  uint64_t hitAttributeBytes;   // 424
  uint8_t* shaderRecord;        // 432  ShaderRecordBufferKHR: the record's bytes after the handle
  uint64_t shaderRecordBytes;   // 440
  const RayRuntime* runtime;    // 448
  // 456  HitTriangleVertexPositionsKHR (any-hit, closest-hit of a triangle hit; SPV_KHR_ray_tracing_position_fetch):
  // the triangle's three object-space vertices, x, y, z each (an array of 3 vec3 in the natural layout).
  float hitTriangleVertexPositions[3][3];
  uint32_t pad1;  // 492
  // 496  The bytes from `shaderRecord` to the end of the SBT region (what "Indexing Rules" lets a launch read; it
  // may be more or less than shaderRecordBytes). A read that ends past it calls shaderRecordOutsideRegion first.
  uint64_t shaderRecordRegionBytes;
  // 504  The worker's pending adds (PendingAdds below; null: every atomic runs where the shader has it).
  PendingAdds* pendingAdds;
};

// Combined counter adds (ray tracing stages). An OpAtomicIAdd / ISub / IIncrement / IDecrement on a buffer reached
// through a descriptor (StorageBuffer, or Uniform with BufferBlock), with Relaxed semantics (no ordering, no
// availability or visibility bits, not volatile) and a result the shader never uses, is added to the worker's
// pending sum instead of memory when the invocation has `pendingAdds`: a counter every ray adds to (statistics,
// the CTS's maxrtinvocations any-hit shaders) then costs one atomic per task, not one cache line moved between the
// cores per ray. One word is pending at a time: an add to another word writes the pending sum first (`flush`).
// The sum reaches memory, with one atomic add, before anything the worker runs could observe it or order it:
//   - before any load, store or atomic of that worker's shaders on memory that may overlap the word (buffers,
//     physical pointers, shader records: compared with [begin, end) inline);
//   - before any other atomic, barrier (OpControlBarrier, OpMemoryBarrier) or image or texel buffer access (which
//     may alias buffer memory), whatever its address;
//   - at the end of each task of the launch, also one cut short by a fault or the watchdog.
// Other workers may see the adds later than they ran, which relaxed atomics without a happens-before allow; an
// invocation that synchronizes with the adding one (a release is one of the points above), and every later access
// of the adding one, cannot miss them. Empty: begin = ~0, end = 0 (no access overlaps it).
struct PendingAdds {
  uint64_t begin;                    // 0   the pending word's address
  uint64_t end;                      // 8   begin + its bytes (4 or 8); 0: nothing pending
  uint64_t sum;                      // 16  the adds' sum, modulo 2^64 (a 32-bit word takes its low half)
  void (*flush)(PendingAdds* adds);  // 24  writes the sum (one atomic add) and empties the table
};

// The flush every executor installs: the table emptied first (a fault in the add is not met again by the flush
// at the task's end), then the sum added to the word, atomically.
inline void flushPendingAdds(PendingAdds* adds) {
  const uint64_t begin = adds->begin, end = adds->end, sum = adds->sum;
  if (end == 0) return;
  adds->begin = ~uint64_t(0);
  adds->end = 0;
  adds->sum = 0;
  if (end - begin == 8) {
    __atomic_fetch_add(reinterpret_cast<uint64_t*>(begin), sum, __ATOMIC_SEQ_CST);
  } else {
    __atomic_fetch_add(reinterpret_cast<uint32_t*>(begin), uint32_t(sum), __ATOMIC_SEQ_CST);
  }
}

static_assert(sizeof(TraceRayArgs) == 72 && offsetof(TraceRayArgs, origin) == 32 &&
                  offsetof(TraceRayArgs, payload) == 64,
              "the compiler bakes these offsets into shader code");
static_assert(offsetof(RayInvocation, launchId) == 160 && offsetof(RayInvocation, rayTmin) == 256 &&
                  offsetof(RayInvocation, status) == 292 && offsetof(RayInvocation, objectToWorld) == 304 &&
                  offsetof(RayInvocation, worldToObject) == 352 && offsetof(RayInvocation, incoming) == 400 &&
                  offsetof(RayInvocation, shaderRecord) == 432 && offsetof(RayInvocation, runtime) == 448 &&
                  offsetof(RayInvocation, hitTriangleVertexPositions) == 456 &&
                  offsetof(RayInvocation, shaderRecordRegionBytes) == 496 &&
                  offsetof(RayInvocation, pendingAdds) == 504 && offsetof(PendingAdds, end) == 8 &&
                  offsetof(PendingAdds, sum) == 16 && offsetof(PendingAdds, flush) == 24 &&
                  offsetof(RayRuntime, executeCallable) == 8 && offsetof(RayRuntime, reportIntersection) == 16 &&
                  offsetof(RayRuntime, shaderRecordOutsideRegion) == 24 && offsetof(RayRuntime, traceRays) == 32,
              "the compiler bakes these offsets into shader code");

using RayEntry = void (*)(RayInvocation*);
// A ray generation shader compiled SPMD (src/spirv/spmd.cpp) has a second entry point besides vkrt_main, vkrt_group:
// it runs the shader for `lanes` launch ids in one call (1 <= lanes <= CompiledShader::spmdLanes), those of
// (launchId[0] + l, launchId[1], launchId[2]) for l < lanes, each instruction on all of them at once. Its traces are
// one RayRuntime::traceRays call for the active lanes, its callables one executeCallable per lane in lane order,
// with the same invocation, whose launchId[0] holds the calling lane's x for such a call (and for a report of an
// out-of-bounds access); launchId[0] is as it was when the call returns. The RayInvocation is the one a scalar
// invocation would get otherwise.
using RayBatchEntry = void (*)(RayInvocation*, uint32_t lanes);

// ---------------------------------------------------------------------------------------------- graphics
//
// Vertex and fragment shaders are `void vkrt_main(GraphicsInvocation*)`, run once per vertex and once per fragment
// (per lane of a 2x2 quad). The InvocationContext gives resources, push constants, the sink and cancellation as for
// compute (the compute built-ins are unused).
//
// User inputs and outputs travel by Location: `inputs` and `outputs` are kGraphicsLocations slots of 16 bytes. A
// variable at Location L, Component C starts at byte 16 * L + 4 * C; each scalar or vector takes one location (a
// 64-bit vec3/vec4 two), a matrix one location per column, an array or a struct one per element or member in order
// (the Location rules of the "Shader Interfaces" chapter). Vertex inputs hold the attribute converted to the
// shader's component type: four 32-bit words, floats for float/normalized/scaled formats, integers for integer ones
// (missing components G = B = 0, A = 1). A fragment shader's Output at Location L is color attachment L; with
// Index 1 (dual-source blending) it goes to `outputs1`.
//
// Quads. A fragment shader that takes derivatives (OpDPdx..., OpFwidth..., implicit-LOD sampling) or uses quad
// group operations runs its four lanes together: `base.barrier` switches to the next lane (the executor runs the
// lanes as fibers), `base.localIndex` is the lane (0..3: x & 1 | (y & 1) << 1), and `base.workgroupMemory` is the
// quad's exchange area (kQuadExchangeBytes). A derivative stores the lane's value (up to 4 x 32 bits) at
// exchange[parity][lane], calls the barrier, and reads the four values of that parity; `quadParity` alternates per
// exchange, so a lane that runs ahead to the next exchange writes the other half while the others still read.
// A lane that ended (returned or was killed) no longer takes part: the others pass the barrier without it (its last
// values stay). Helper lanes (`helper` = 1) run the shader but its stores and atomics to memory have no effect.
// A fragment shader's SPMD entry (vkrt_group, spirv/spmd.hpp) takes the quad's N = 4 invocations as an array and
// reads its user inputs and writes its user outputs (locations and the dual-source output) as structures of arrays
// through invocation 0's `inputs`, `outputs` and `outputs1`: word w (byte 4 w of a lane's slots) of lane l at
// byte 4 (w N + l); the other invocations' slot pointers are not read.
inline constexpr uint32_t kGraphicsLocations = 32;
inline constexpr uint32_t kQuadExchangeBytes = 2 * 4 * 16;

// GraphicsInvocation::status, written by the fragment shader.
inline constexpr uint32_t kFragmentKilled = 1;   // OpKill / OpTerminateInvocation: outputs discarded, the lane ended
inline constexpr uint32_t kFragmentDemoted = 2;  // OpDemoteToHelperInvocation: outputs discarded, the lane goes on

// A fragment shader's SPMD entry that also writes colour attachment 0 (spirv::CompileRequest::colorMerge): the
// attachment's format and blend, as the back end's quad paths write it (raster/backend.cpp colorUnorm8Quad: the same
// float operations in the same order, so the same bytes). The entry writes a quad only where the executor gives it
// the quad's address (GraphicsInvocation::colorQuad): a fully covered quad that nothing after the shader changes.
struct ColorMerge {
  enum Format : uint8_t { kNone, kRgba8Unorm, kBgra8Unorm };
  // Off, or one of the back end's four blend equations of their own (raster/backend.cpp kBlendShapes, in order):
  // source alpha "over" with alpha as coverage, "over" on all four components, premultiplied "over", additive.
  enum Blend : uint8_t { kOff, kOver, kOverAll, kPremultiplied, kAdditive };
  Format format = kNone;
  Blend blend = kOff;
  uint8_t writeMask = 0xF;  // bit c: component c (R, G, B, A) is written; the others keep the attachment's
  bool operator==(const ColorMerge&) const = default;
};

// GraphicsInvocation::interpolateAt's `where`.
inline constexpr uint32_t kInterpolateAtCentroid = 0;
inline constexpr uint32_t kInterpolateAtSample = 1;
inline constexpr uint32_t kInterpolateAtOffset = 2;

struct GraphicsInvocation {
  InvocationContext base;  // 0
  uint32_t* inputs;        // 160  kGraphicsLocations x 16 bytes (read)
  uint32_t* outputs;       // 168  kGraphicsLocations x 16 bytes (written)
  uint32_t* outputs1;      // 176  fragment: Index 1 outputs (16 bytes, location 0)
  // Fragment, the SPMD entry's quads (set in every invocation of the quad; null on the other paths): the quad's
  // FragCoord as a structure of arrays, component c of lane l at [4 c + l]. A report names the fragment from it.
  const float* fragCoordSoa;  // 184
  // vertex
  float position[4];      // 192  Position (out)
  float pointSize;        // 208  PointSize (out)
  int32_t vertexIndex;    // 212  VertexIndex
  int32_t instanceIndex;  // 216  InstanceIndex
  int32_t baseVertex;     // 220  BaseVertex
  int32_t baseInstance;   // 224  BaseInstance
  int32_t drawIndex;      // 228  DrawIndex
  uint32_t viewIndex;     // 232  ViewIndex (both stages)
  uint32_t pad1;          // 236
  float clipDistance[8];  // 240  ClipDistance (out)
  float cullDistance[8];  // 272  CullDistance (out)
  // fragment
  float fragCoord[4];       // 304  FragCoord
  float pointCoord[2];      // 320  PointCoord
  uint32_t frontFacing;     // 328  FrontFacing (0 or 1)
  int32_t primitiveId;      // 332  PrimitiveId
  int32_t sampleId;         // 336  SampleId
  float samplePosition[2];  // 340  SamplePosition
  uint32_t sampleMaskIn;    // 348  SampleMask (in)
  uint32_t sampleMaskOut;   // 352  SampleMask (out; the executor presets ~0)
  float fragDepth;          // 356  FragDepth (out; the executor presets fragCoord[2])
  uint32_t helper;          // 360  HelperInvocation
  uint32_t status;          // 364  kFragment*: written by the shader
  uint32_t layer;           // 368  Layer (fragment in)
  uint32_t quadParity;      // 372  the next exchange's half (0 or 1), kept by the compiled code
  // GLSL.std.450 InterpolateAtCentroid / Sample / Offset: fills `out` (laid out as `inputs`) with the inputs
  // interpolated at this lane's centroid (where = kInterpolateAtCentroid), at sample `sample`'s position, or at the
  // pixel centre plus (dx, dy) pixels. Set by the executor for fragment shaders; `quad` is its argument.
  void (*interpolateAt)(const GraphicsInvocation* inv, uint32_t where, int32_t sample, float dx, float dy,
                        uint32_t* out);  // 376
  const void* quad;                      // 384
  // Fragment, the SPMD entry's quads (set with fragCoordSoa): the quad's coverage, lane l's samples at [l] (0: a
  // helper lane). The entry's helper lanes and HelperInvocation come from it; `helper` is then set only for shaders
  // with side effects, whose scalar pieces read it.
  const uint32_t* coverageSoa;  // 392
  // Fragment, an SPMD entry compiled with a ColorMerge (invocation 0's, set per quad): the quad's top-left texel in
  // colour attachment 0, whose four texels the entry writes after the shader; null: it writes none (the back end
  // does). colorPitch: the attachment's row pitch in bytes.
  uint8_t* colorQuad;  // 400
  int64_t colorPitch;  // 408
};

static_assert(offsetof(GraphicsInvocation, inputs) == 160 && offsetof(GraphicsInvocation, outputs1) == 176 &&
                  offsetof(GraphicsInvocation, position) == 192 && offsetof(GraphicsInvocation, pointSize) == 208 &&
                  offsetof(GraphicsInvocation, vertexIndex) == 212 && offsetof(GraphicsInvocation, viewIndex) == 232 &&
                  offsetof(GraphicsInvocation, clipDistance) == 240 &&
                  offsetof(GraphicsInvocation, cullDistance) == 272 && offsetof(GraphicsInvocation, fragCoord) == 304 &&
                  offsetof(GraphicsInvocation, frontFacing) == 328 &&
                  offsetof(GraphicsInvocation, sampleMaskOut) == 352 &&
                  offsetof(GraphicsInvocation, fragDepth) == 356 && offsetof(GraphicsInvocation, helper) == 360 &&
                  offsetof(GraphicsInvocation, status) == 364 && offsetof(GraphicsInvocation, quadParity) == 372 &&
                  offsetof(GraphicsInvocation, interpolateAt) == 376 &&
                  offsetof(GraphicsInvocation, coverageSoa) == 392 && offsetof(GraphicsInvocation, colorQuad) == 400 &&
                  sizeof(GraphicsInvocation) == 416,
              "the compiler bakes these offsets into shader code");

using GraphicsEntry = void (*)(GraphicsInvocation*);

}  // namespace vkrt::abi
