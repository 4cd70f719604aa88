// SPIR-V -> LLVM IR translation state, shared by the files of src/spirv that generate code (compiler.cpp:
// types, constants, functions, driver; arithmetic.cpp; control_flow.cpp; memory.cpp; glsl_std450.cpp).
// Includes LLVM headers: only src/spirv/*.cpp may include it.
//
// MEMORY MODEL. Every SPIR-V pointer is a Ptr: a base address, a byte offset and a byte limit. An access of
// N bytes at base + offset happens only when offset + N <= limit; otherwise loads read zeros, stores are
// dropped and atomics act on the invocation's sink (robust buffer access for buffers, and no memory corruption
// from wild indices into function, private or workgroup arrays). Loads and stores branch around the access
// (guardedLoad/guardedStore), which LLVM turns into masked vector loads and stores in a vectorized loop.
// Composites are loaded and stored member by member, at offsets from the explicit layout decorations (Offset,
// ArrayStride, MatrixStride, RowMajor) where the type has them and from a natural "scalar" layout otherwise.
#pragma once

#include <llvm/IR/IRBuilder.h>
#include <llvm/IR/LLVMContext.h>
#include <llvm/IR/Module.h>

#include <functional>
#include <map>
#include <string>
#include <unordered_map>
#include <vector>

#include "abi/image_functions.hpp"
#include "abi/shader_debug.hpp"
#include "spirv/compiler.hpp"
#include "spirv/module.hpp"
#include "spirv/opcode_support.hpp"

namespace vkrt::spirv {

// The compiled-code ABI (src/abi) by its short names: the code generator lays out and calls against these.
using abi::DescriptorRecord;
using abi::GraphicsInvocation;
using abi::InvocationContext;
using abi::kPushConstantBytes;
using abi::kRayStatusIgnore;
using abi::kRayStatusTerminate;
using abi::kSinkBytes;
using abi::RayInvocation;
using abi::RayRuntime;
using abi::ResourceSlot;
using abi::TraceRayArgs;

struct Ptr {
  llvm::Value* base = nullptr;    // i8*
  llvm::Value* offset = nullptr;  // i64
  llvm::Value* limit = nullptr;   // i64
  uint32_t type = 0;              // pointee type id
  spv::StorageClass storage = spv::StorageClassFunction;
  uint32_t matrixStride = 0;  // for a matrix (or array of matrices) pointee: 0 = natural layout
  bool rowMajor = false;
  uint32_t vecStride = 0;            // for a vector pointee: bytes between components (0 = packed)
  int slot = -1;                     // >= 0: a descriptor array not indexed yet (base/offset/limit unset)
  llvm::Value* descIndex = nullptr;  // UniformConstant (image/sampler) descriptors: the array index so far
  // Buffers reached through a descriptor (Uniform, StorageBuffer): the resource (index in info.resources), the
  // variable and the descriptor array element, which name an out-of-bounds access (shader_debug_codegen.cpp).
  int resource = -1;
  uint32_t variable = 0;
  llvm::Value* element = nullptr;  // i64
  // Fragment shaders' writes (forWrite): i1, set in helper lanes, whose limit is 0 (their writes are dropped, not
  // out of bounds), and the limit the lane has otherwise.
  llvm::Value* helper = nullptr;
  llvm::Value* unmaskedLimit = nullptr;
};

// The result of derivative instruction `op` (OpDPdx*, OpDPdy*, OpFwidth*) from the value's d/dx and d/dy
// (graphics.cpp).
llvm::Value* derivativeResult(llvm::IRBuilder<>& b, spv::Op op, llvm::Value* dx, llvm::Value* dy);

class Codegen {
 public:
  Codegen(const Module& m, llvm::LLVMContext& c, llvm::Module& out, CompiledShader& info)
      : m(m), c(c), out(out), info(info), b(c) {}

  // Generates "vkrt_main" for the entry point. Returns false with `error` set.
  bool run(const EntryPoint& ep);
  // vkrt_group, the per-workgroup loop around vkrt_main (`main`), for shaders without barriers.
  void emitGroupEntry(llvm::Function* main);
  // vkrt_group's local copy of the context `ctx` (push constants, resource table), made where the builder stands.
  llvm::Value* groupContext(llvm::Value* ctx);
  std::string error;

  // Reports an instruction this compiler cannot translate.
  bool unsupported(const Instruction& in, const char* detail = nullptr);
  bool fail(const Instruction& in, const char* what);

  // ---- types and layout (compiler.cpp)
  llvm::Type* type(uint32_t id);
  const Type& spvType(uint32_t id) const;
  uint32_t scalarType(uint32_t id) const;  // the component type of a scalar or vector type
  bool isFloat(uint32_t typeId) const;
  bool isSignedInt(uint32_t typeId) const;
  uint32_t componentCount(uint32_t typeId) const;  // 1 for scalars
  uint64_t layoutSize(uint32_t typeId, uint32_t matrixStride, bool rowMajor) const;
  uint64_t layoutAlign(uint32_t typeId) const;
  uint64_t memberOffset(uint32_t structId, uint32_t member) const;
  uint64_t arrayStride(uint32_t arrayTypeId, uint32_t matrixStride, bool rowMajor) const;
  uint32_t naturalMatrixStride(uint32_t matrixTypeId) const;

  // ---- values
  llvm::Value* value(uint32_t id);  // an SSA value (constants materialized on demand); nullptr if unknown
  llvm::Value* specConstantOp(const Instruction& in);  // an OpSpecConstantOp folding left, emitted and folded
  llvm::Constant* constant(uint32_t id);
  void set(uint32_t id, llvm::Value* v) { values[id] = v; }
  llvm::Value* i64(uint64_t v) { return b.getInt64(v); }
  llvm::Value* i32(uint32_t v) { return b.getInt32(v); }
  llvm::Value* splat(llvm::Value* scalar, llvm::Type* like);  // scalar broadcast to `like`'s shape

  // ---- families: each returns true when it handled `in` (ok stays true) or it failed (ok = false)
  bool arithmetic(const Instruction& in, bool& ok);  // arithmetic.cpp
  bool composite(const Instruction& in, bool& ok);   // arithmetic.cpp
  bool subgroup(const Instruction& in, bool& ok);    // arithmetic.cpp (called by arithmetic)
  llvm::Value* truncDoubleToHalf(llvm::Value* d);    // arithmetic.cpp
  llvm::Value* integerDot(spv::Op op, llvm::Value* a, llvm::Value* c, llvm::Value* accumulator, bool packed,
                          llvm::Type* rt);                       // arithmetic.cpp
  llvm::Value* roundTowardZero(llvm::Value* x, llvm::Value* r);  // arithmetic.cpp
  bool controlFlow(const Instruction& in, bool& ok);             // control_flow.cpp
  bool memory(const Instruction& in, bool& ok);                  // memory.cpp
  bool accessChain(const Instruction& in, bool& ok);             // memory.cpp (called by memory)
  bool atomic(const Instruction& in, bool& ok);                  // memory.cpp (called by memory)
  bool extInst(const Instruction& in, bool& ok);                 // glsl_std450.cpp
  bool image(const Instruction& in, bool& ok);                   // image.cpp
  bool texelBuffer(const Instruction& in, llvm::Value* record);  // image.cpp: image on a Dim Buffer image
  bool subpassRead(const Instruction& in, const Instruction& imageType, llvm::Value* record);  // image.cpp
  bool rayTracing(const Instruction& in, bool& ok);                                            // ray_tracing.cpp
  bool rayQuery(const Instruction& in, bool& ok);  // ray_query.cpp (called by rayTracing)
  bool isRayQuery(uint32_t typeId) const;          // OpTypeRayQueryKHR: abi::kRayQueryStateBytes of state
  // OpLoad / OpStore of a whole ray query (ray_query.cpp, called by memory)
  bool rayQueryValue(const Instruction& in, bool& ok);

  // ---- memory (memory.cpp)
  bool declareGlobals();                       // Private, Workgroup, Input, buffers, push constants
  bool variablePtr(uint32_t varId, Ptr* out);  // a module-scope variable in the current function
  // The in-bounds condition of an access of `bytes` at p (nullptr: in bounds by construction); `kind`
  // (abi::AccessKind) names the access where a check reports it (VKRT_SHADER_CHECKS=bda: checkAddress).
  llvm::Value* inBounds(const Ptr& p, uint64_t bytes, uint32_t kind = abi::kAccessLoad);
  // The address an atomic uses: p's, or the zeros / the sink when out of bounds.
  llvm::Value* address(const Ptr& p, uint64_t bytes, bool write, uint32_t kind = ~0u);
  // A load that reads zeros out of bounds, and a store that is dropped there (branches around the access).
  llvm::Value* guardedLoad(const Ptr& p, llvm::Type* ty, uint64_t bytes, llvm::Align align);
  void guardedStore(const Ptr& p, llvm::Value* v, uint64_t bytes, llvm::Align align);
  // Combined counter adds (abi::PendingAdds; ray tracing stages only, no code elsewhere). Before an access of
  // `bytes` at p (a class that may reach buffer memory): the pending sum written when its word overlaps the access.
  void flushOverlappingAdds(const Ptr& p, uint64_t bytes);
  // Before an access that may reach any memory (another atomic, a barrier, an image): the pending sum written.
  void flushPendingAdds();
  // Whether the atomic `in` on p may be combined: an add or subtract (IAdd, ISub, IIncrement, IDecrement) through
  // a buffer descriptor, Relaxed (no ordering, availability, visibility or volatile bits), its result unused.
  bool combinableAdd(const Instruction& in, const Ptr& p);
  // Whether result `id` is used by no instruction of a function body (counted once per module: a word equal to it
  // anywhere but its definition counts as a use).
  bool resultUnused(uint32_t id);
  std::unordered_map<uint32_t, uint32_t> bodyWords;  // word -> occurrences in function bodies (resultUnused)
  // CompileRequest::combineAdds, kept by run() for the ray tracing stages only (RayStageInfo::checksPendingAdds):
  // without it none of the above emits anything.
  bool combining = false;
  abi::ColorMerge colorMerge;  // CompileRequest::colorMerge (fragment shaders' SPMD entry: spmd.cpp)
  llvm::Value* load(const Ptr& p);
  void store(const Ptr& p, llvm::Value* v);
  bool resolveDescriptor(Ptr& p, llvm::Value* index);
  // The DescriptorRecord* of element `index` of resource slot `slot` (a zero record past the bound ones).
  // `site`: an array element the shader indexes, reported when the index is past the bound descriptors.
  llvm::Value* descriptorRecord(int slot, llvm::Value* index, const Ptr* site = nullptr);
  void reportDescriptorIndex(const Ptr& p, llvm::Value* index, llvm::Value* count);
  // Image, sampler and sampled-image values are {image record, sampler record} (image.cpp).
  bool isImageLike(uint32_t typeId) const;
  bool isTexelBuffer(uint32_t typeId) const;  // an OpTypeImage of Dim Buffer
  llvm::Type* imageValueType();
  Ptr& ptr(uint32_t id);
  bool hasPtr(uint32_t id) const { return ptrs.count(id) != 0; }

  // ---- shader debugging (shader_debug_codegen.cpp)
  // OpExtInst of NonSemantic.DebugPrintf (debugPrintfEXT): a call of vkrt_debug_printf.
  bool debugPrintf(const Instruction& in, bool& ok);
  // OpLine: where the instructions that follow come from (the source line, or, for modules without line
  // information, the application's word offset, see pre_optimizer.cpp's prepareNonSemantic).
  void setLine(const Instruction* line) { currentLine = line; }
  // The out-of-bounds report of an access through `p` (a buffer reached through a descriptor; nullptr for other
  // pointers): the block the failing branch runs, which calls vkrt_out_of_bounds and branches to `join`.
  // In compute shaders run by vkrt_group (no workgroup barrier) a call would keep LLVM 15 from vectorizing the loop
  // over the invocations (it predicates no calls): there the failing branch stores the site, element and offset in
  // the invocation's word of a log (a masked store when vectorized; the local context's `executor` points at it),
  // and vkrt_group reports the log after its loop (groupSites).
  // `exit`, where given, is set to the block that branches to `join` (not `block` where reportIf adds a branch).
  llvm::BasicBlock* outOfBoundsBlock(const Ptr& p, uint32_t kind, uint64_t bytes, llvm::BasicBlock* join,
                                     llvm::BasicBlock** exit = nullptr);
  // The failing branch's work at the builder: the call, or in vkrt_group the log entry.
  void outOfBounds(const Ptr& p, uint32_t kind, uint64_t bytes, llvm::Value* offset, llvm::Value* range,
                   llvm::Value* element);
  struct GroupSite {
    llvm::Constant* site;
    int resource;
    uint32_t kind;
  };
  std::vector<GroupSite> groupSites;
  bool groupLog = false;  // the code runs inside vkrt_group (set by run())
  // i1 where set: out-of-bounds accesses are reported only where it is true. The SPMD path (spmd.cpp) runs uniform
  // accesses through this scalar code in every block, also where no lane is active (a loop body's pass after the
  // last lane has left): such an access does not happen in the shader and must not be reported.
  llvm::Value* reportIf = nullptr;
  // The SPMD path (spmd.cpp) runs a batch of lanes, local invocation indices batchBase + lane, global ids
  // wgBase + the local ids: while `laneReport` is set, a report names the first lane of its `mask` (<N x i1>) rather
  // than the workgroup's context. A fragment quad has no batchBase: lane l's context is the l-th GraphicsInvocation
  // at ctxArg.
  struct LaneReport {
    llvm::Value* mask;
    llvm::Value* batchBase;
    llvm::Value* const* wgBase;
    // Ray generation batches: the first lane's LaunchIdKHR.x (i32); a report stores its lane's x in the invocation.
    llvm::Value* launchX0 = nullptr;
  };
  const LaneReport* laneReport = nullptr;
  // The SPMD path's per-lane check: where a lane of `failing` (<N x i1>) is set, a cold branch reports the first
  // such lane's access of `bytes` at its lane of `offsets` (<N x i64>), as the scalar code reports it.
  void reportFailingLanes(const Ptr& p, uint32_t kind, uint64_t bytes, llvm::Value* failing, llvm::Value* offsets,
                          const LaneReport& lanes);
  // A copy of the context at ctxArg naming local invocation `localIndex` (i32; its global id `base` + its local id),
  // for a report (one slot per function).
  llvm::Value* reportContext(llvm::Value* localIndex, llvm::Value* const base[3]);
  // The context a report names for lane `lane` (i32) of `lanes`: reportContext's copy, or a fragment quad's lane.
  llvm::Value* laneContext(const LaneReport& lanes, llvm::Value* lane);
  llvm::Value* reportContextSlot = nullptr;
  // vkrt_group's report of the log (after its loop over the invocations).
  void reportGroupLog(llvm::Value* ctx, llvm::Value* local, llvm::Value* log, llvm::Value* const base[3]);
  // The AccessSite of the current instruction (a constant of the module).
  llvm::Constant* accessSiteFor(const Ptr& p, uint32_t kind, uint64_t bytes);
  // Emits a call of vkrt_out_of_bounds(ctx, site, offset, range, element) at the builder.
  void callOutOfBounds(llvm::Value* site, llvm::Value* offset, llvm::Value* range, llvm::Value* element);
  // VKRT_SHADER_CHECKS (abi::ShaderCheck bits), taken when the compilation starts: what is compiled in beyond the
  // buffer and descriptor checks.
  uint32_t checks = 0;
  // kCheckDeviceAddress: the in-bounds condition of a PhysicalStorageBuffer access of `bytes` through p: `limitOk`
  // (p's own limit: 0 in a fragment's helper lanes; nullptr: none) and, only where it holds, a call of
  // vkrt_check_address (the live buffers' table; it reports a failure at the access's site).
  llvm::Value* checkAddress(const Ptr& p, uint64_t bytes, uint32_t kind, llvm::Value* limitOk);
  // The command's address table (vkrt_address_table), fetched once at the top of the current function. Each
  // checked access keeps the range of its last access that passed (2 x i64: begin, end), tested inline before the
  // call: in vkrt_group the access's kAddressCacheBytes after the local context (kept across the invocations;
  // groupContext makes room for addressCaches of them), elsewhere a slot of the function.
  llvm::Value* addressTable = nullptr;
  uint32_t addressCaches = 0;
  // kCheckImage: a call of vkrt_check_image (coords: 4 x i32 in memory, level: i32) or, for a texel buffer,
  // vkrt_check_texel_buffer (index: i64) before the access of `kind` to image `imageId` (a value, or with
  // `isPointer` an image variable's pointer, for OpImageTexelPointer) with descriptor record `record`.
  void checkImage(uint32_t imageId, bool isPointer, uint32_t kind, llvm::Value* record, llvm::Value* coords,
                  llvm::Value* level);
  void checkTexelBuffer(uint32_t imageId, bool isPointer, uint32_t kind, llvm::Value* record, llvm::Value* index);
  const Instruction* currentInstruction = nullptr;
  const Instruction* currentLine = nullptr;
  uint32_t debugPrintfSet = 0;  // id of the NonSemantic.DebugPrintf import
  std::map<std::string, llvm::GlobalVariable*> siteGlobals;

  // ---- ray tracing (ray_tracing.cpp)
  bool isRayTracing() const;  // the entry point is one of the six ray tracing stages
  bool isAccelerationStructure(uint32_t typeId) const;
  // Any-hit and intersection shaders stop when `status` is set (by OpIgnoreIntersectionKHR /
  // OpTerminateRayKHR in a callee, or by the runtime in OpReportIntersectionKHR): returns from the current
  // function when it is.
  void returnIfStopped();
  // Returns from the current function (a zero value for a non-void one).
  void returnFromFunction();
  // The RayRuntime function (abi.hpp) at `offset`, from the invocation's `runtime`.
  llvm::Value* rayRuntimeFunction(size_t offset);
  // Stores an OpTraceRayKHR's abi::TraceRayArgs at `args`: `operand(w, k)` is component k (of a vector: origin,
  // direction; else 0) of the value of the instruction's word w (1..10: structure, flags, cull mask, SBT offset and
  // stride, miss index, origin, tMin, direction, tMax); the payload variable at `payload`, `payloadBytes` (i32) long.
  void storeTraceRayArgs(llvm::Value* args, const std::function<llvm::Value*(uint32_t w, uint32_t k)>& operand,
                         llvm::Value* payloadBytes, llvm::Value* payload);
  // Before a read of `bytes` at shader record pointer p: tells the runtime when the read ends past the SBT
  // region (RayInvocation::shaderRecordRegionBytes; "Indexing Rules"), on a cold branch. Called by guardedLoad.
  void checkShaderRecordRead(const Ptr& p, uint64_t bytes);

  // ---- vertex and fragment shaders (graphics.cpp)
  struct Global;
  bool isGraphics() const { return model == spv::ExecutionModelVertex || model == spv::ExecutionModelFragment; }
  bool isFragment() const { return model == spv::ExecutionModelFragment; }
  // An Input or Output variable of a vertex or fragment shader (called by declareGlobals): a built-in read or
  // written in place in the GraphicsInvocation, or storage in the private block that vkrt_main copies in from the
  // location slots / built-in fields at entry (inputs) and out at the end (outputs). Fills info.graphics.
  bool declareInterface(const Instruction& var, Global& g);
  // vkrt_main's copies (inputs: at entry; outputs: after the entry function returned).
  void copyInterface(bool inputs);
  // The entry point's execution modes (fragment: EarlyFragmentTests; refuses what Vulkan does not allow).
  bool graphicsModes(const EntryPoint& ep);
  // OpKill, OpTerminateInvocation, OpDemoteToHelperInvocation, OpIsHelperInvocationEXT, derivatives, quad operations.
  bool graphics(const Instruction& in, bool& ok);
  // GLSL.std.450 InterpolateAtCentroid / Sample / Offset (`inst`), called by extInst.
  bool interpolateAt(const Instruction& in, uint32_t inst, bool& ok);
  // i1: this fragment invocation is a helper lane (constant false in other stages).
  llvm::Value* helperLane();
  // A pointer for a store or an atomic: in fragment shaders, a buffer pointer (StorageBuffer, Uniform,
  // PhysicalStorageBuffer) gets limit 0 in helper lanes, so that the store is dropped and the atomic acts on the sink.
  Ptr forWrite(const Ptr& p);
  // An image or texel buffer record written through (OpImageWrite, OpImageTexelPointer): the zero record in helper
  // lanes of fragment shaders (writes nothing).
  llvm::Value* writableRecord(llvm::Value* record);
  // The quad exchange (abi.hpp): v (up to 16 bytes) of the four lanes of the quad.
  void quadExchange(llvm::Value* v, llvm::Value* out[4]);
  // d/dx and d/dy of a float scalar or vector: fine (the lane's row / column) or coarse (the quad's top row / left
  // column); zero outside fragment shaders.
  void derivatives(llvm::Value* v, bool coarse, llvm::Value** dx, llvm::Value** dy);
  // Set by the SPMD fragment path (spmd.cpp), which runs the quad's lanes in one call and emits image sampling one
  // lane at a time through this code: derivatives() then returns spmdDx / spmdDy (the lane's differences, computed
  // there from the quad's lanes; null: the value is uniform, its derivatives zero) instead of exchanging.
  bool spmdDerivatives = false;
  llvm::Value* spmdDx = nullptr;
  llvm::Value* spmdDy = nullptr;
  struct IoCopy {
    bool input;
    uint64_t privOffset;  // in the private block
    int slotsField;       // offset in GraphicsInvocation of the slot pointer (inputs, outputs, outputs1); -1: `at`
                          // is an offset in the GraphicsInvocation itself (a built-in member of a block)
    uint32_t at;          // byte offset from there
    uint32_t bytes;
  };
  std::vector<IoCopy> ioCopies;
  std::map<uint32_t, GraphicsStageInfo::Location> inputLocations, outputLocations;  // user locations so far

  // ---- functions (compiler.cpp / control_flow.cpp)
  bool declareFunctions();
  bool emitFunction(size_t firstInstruction, size_t* next);
  void finishPhis();

  const Module& m;
  llvm::LLVMContext& c;
  llvm::Module& out;
  CompiledShader& info;
  llvm::IRBuilder<> b;

  std::unordered_map<uint32_t, llvm::Value*> values;
  std::unordered_map<uint32_t, Ptr> ptrs;
  std::unordered_map<uint32_t, llvm::Type*> typeCache;
  std::unordered_map<uint32_t, llvm::Function*> functions;
  std::unordered_map<uint32_t, llvm::BasicBlock*> blocks;      // label -> its first LLVM block
  std::unordered_map<uint32_t, llvm::BasicBlock*> blockExits;  // label -> the LLVM block it ends in
  struct PendingPhi {
    llvm::PHINode* phi;
    const Instruction* in;
  };
  std::vector<PendingPhi> phis;

  // Module-scope variables.
  struct Global {
    spv::StorageClass storage;
    uint64_t offset = 0;  // Private: in the private block; Workgroup: in workgroup memory
    uint64_t size = 0;
    int slot = -1;           // buffers: resource slot
    int builtIn = -1;        // Input
    int contextField = -1;   // a pointer the runtime provides: offset of {pointer, uint64 bytes} in RayInvocation
    int graphicsField = -1;  // a vertex / fragment built-in variable: its offset in the GraphicsInvocation
    bool inPrivate = false;  // a vertex / fragment Input or Output variable copied through the private block
  };
  std::unordered_map<uint32_t, Global> globals;
  uint64_t privateSize = 0;
  std::vector<std::pair<uint32_t, uint32_t>> privateInits;  // (variable, initializer id)

  // The current function's hidden arguments.
  spv::ExecutionModel model = spv::ExecutionModelGLCompute;
  uint32_t hitAttributeVar = 0;  // intersection shaders: the HitAttributeKHR variable (0: none)

  llvm::Function* fn = nullptr;
  llvm::Value* ctxArg = nullptr;
  llvm::Value* privArg = nullptr;
  llvm::BasicBlock* allocaBlock = nullptr;
  llvm::GlobalVariable* zeros = nullptr;  // kSinkBytes of zeros: out-of-bounds loads read here
  uint32_t glslSet = 0;                   // id of the GLSL.std.450 import
};

}  // namespace vkrt::spirv
