// SPMD compilation of compute shaders, fragment quads and ray generation shaders (spmd.hpp). The entry function's
// blocks are emitted once, in the module's order, for a batch of N lanes:
//
// - Values. A uniform value (uniformity.hpp) is what the scalar code generator makes of it, and the scalar code
//   generator (a second Codegen, `sc`, emitting into vkrt_group) emits it: arithmetic, uniform loads, descriptors.
//   A value with a varying component is held component by component, each a scalar or an <N x T> vector; the
//   scalar emitters of the arithmetic and GLSL.std.450 families make the vectors too, through a third Codegen
//   (`lc`) whose scalar types are N lanes wide, fed one component at a time.
// - Control flow. Every block has an execution mask (<N x i1>, kept in an alloca that SROA turns into SSA): the
//   union of the masks of the edges into it, consumed (and cleared) when the block is emitted. A conditional branch
//   splits its block's mask between its targets, both of which run in turn; a phi is a variable that every edge
//   into its block blends its incoming value into under the edge's mask. A loop is a real loop: its back edge adds
//   lanes to the header's mask, and the loop repeats while any lane is left there; the lanes that leave collect in
//   the merge block's mask. A lane that returns takes no edge: it drops out of every later mask.
// - Memory. Buffers, push constants and uniform blocks: a uniform address is one scalar access (a store happens when
//   any lane is active); a varying one is a masked load or store where the lanes' addresses are consecutive (checked
//   when the code runs), else a masked gather or scatter. Each lane's access is bounds-checked as in the scalar
//   code: out of bounds it reads zeros and writes nothing. Function variables that need storage per lane keep lane
//   l's bytes o..o+3 at o * N + 4 * l (32-bit leaves only), so that a uniform offset is one vector access.
//
// - Storage images: the lanes address a bound view's texels themselves where its kind is the declared format's
//   (abi::ImageTexels), else call the runtime lane by lane (imageAccess).
// - Ray generation: a batch is N launch ids along x in one row; the payloads, callable data and Private variables
//   are per-lane storage, and each trace or callable is the runtime's call lane by lane, the lane's payload copied
//   into a block of its own for the call (traceLanes).
//
// - Barriers (compute): a shader with workgroup barriers gets a vkrt_group that runs one batch, whose barrier calls
//   switch to the workgroup's next batch (the executor runs the batches as fibers); workgroup variables are memory
//   at a uniform address, accessed as buffers are; atomics go lane by lane.
//
// The rest (subgroup operations, 64-bit or 16-bit locals, calls, Private variables, varying matrix and struct
// values, ...) is left to the scalar vkrt_group (or vkrt_main, with barriers): emitSpmdGroup() checks the
// instructions first, and removes what it emitted where the emission still fails.
#include "spirv/spmd.hpp"

#include <llvm/ADT/StringMap.h>
#include <llvm/IR/Constants.h>
#include <llvm/IR/IntrinsicInst.h>
#include <llvm/IR/Intrinsics.h>
#include <llvm/IR/IntrinsicsX86.h>
#include <llvm/IR/MDBuilder.h>
#include <llvm/Support/Host.h>
#include <llvm/Support/X86TargetParser.h>
#include <spirv/unified1/GLSL.std.450.h>

#include <algorithm>
#include <atomic>
#include <functional>

#include "abi/shader_debug.hpp"
#include "spirv/codegen.hpp"
#include "spirv/target.hpp"
#include "spirv/uniformity.hpp"

namespace vkrt::spirv {

namespace {

std::atomic<bool> spmdOn{true};

// Ids the per-component emitters see for operands (above any id a module may have: the bound is < 2^22 in
// practice, and ids are < 2^32 - 1).
constexpr uint32_t kFakeId = 0xfff00000u;

// The most bytes of payloads, callable data and Private variables a ray generation batch keeps for its lanes (on the
// worker's stack); a shader that needs more runs one launch id at a time.
constexpr uint64_t kMaxRaygenLaneBytes = 64 * 1024;

// The most bytes of Function variables a batch of a compute shader with barriers keeps for its lanes: the batch runs
// on a fiber's stack (exec/fiber_group.cpp: 256 KiB), where the scalar path's fiber holds one invocation's. A shader
// that needs more stays on the scalar path.
constexpr uint64_t kMaxBatchFiberLaneBytes = 64 * 1024;

// An image type compute shaders' SPMD code takes (texel buffers included): not a subpass input or multisampled image.
bool imageTypeOnPath(const Instruction& t) {
  return t.op == spv::OpTypeImage && t.word(3) != spv::DimSubpassData && t.word(6) == 0;
}
// Such a storage image, which the SPMD code reads and writes (imageAccess).
bool storageImageType(const Instruction& t) { return imageTypeOnPath(t) && t.word(7) == 2; }

// The image instructions whose value the scalar code makes where it is uniform (the image queries, and pairing or
// splitting a sampled image).
bool imageValueOp(spv::Op op) {
  return op == spv::OpImageQuerySize || op == spv::OpImageQuerySizeLod || op == spv::OpImageQueryLevels ||
         op == spv::OpSampledImage || op == spv::OpImage;
}

// The instructions that act component by component on scalars and vectors (opcode_support.cpp's table).
bool elementwiseOp(spv::Op op) { return opSupport(op).spmd == SpmdForm::Elementwise; }

// The GLSL.std.450 instructions that act component by component on scalars and vectors.
bool elementwiseExt(uint32_t inst) { return glslSupport(inst).spmd == SpmdForm::Elementwise; }

// The GLSL.std.450 instructions on whole vectors that spmd.cpp computes from the components.
bool vectorExt(uint32_t inst) { return glslSupport(inst).spmd == SpmdForm::Own; }

// The fragment instructions of the quad (fragmentInstruction; the table's Quad form): demotion, helper tests,
// derivatives, quad operations, sampling per lane. OpKill and OpTerminateInvocation end blocks instead, and
// OpSampledImage only pairs its operands.
bool quadOp(spv::Op op) {
  return opSupport(op).spmd == SpmdForm::Quad && op != spv::OpKill && op != spv::OpTerminateInvocation &&
         op != spv::OpSampledImage;
}

// A pointer the SPMD code tracks itself: a varying offset, a per-lane Function variable, or an invocation id.
struct LanePtr {
  Ptr p;                     // p.offset: i64 (uniform) or <N x i64>
  bool interleaved = false;  // a Function variable with storage per lane (see the top of the file)
  int builtIn = -1;          // GlobalInvocationId, LocalInvocationId, LocalInvocationIndex
  int component = -1;        // of the built-in vector (-1: the whole)
  // Where known: lane l's offset is first + l * laneStride whenever `linear` (i1) holds (checked once per access,
  // a scalar test, instead of comparing the lanes' offsets).
  llvm::Value* first = nullptr;
  int64_t laneStride = 0;
  llvm::Value* linear = nullptr;
};

// Lane l of a varying integer holds base + l * stride (in the integer's width, wrapping): the invocation index and
// x ids, and sums, differences, products and shifts of those by uniform values.
struct Affine {
  llvm::Value* base;
  int64_t stride;
};

class Spmd {
 public:
  Spmd(Codegen& g, unsigned lanes)
      : g(g), m(g.m), c(g.c), N(lanes), sc(g.m, g.c, g.out, g.info), lc(g.m, g.c, g.out, g.info), b(sc.b) {
    for (Codegen* x : {&sc, &lc}) {
      x->globals = g.globals;
      x->zeros = g.zeros;
      x->glslSet = g.glslSet;
      x->model = g.model;
      x->privateSize = g.privateSize;
    }
    // The lane emitter's scalar types are N lanes wide.
    for (const auto& [id, t] : m.types)
      if (t.kind == Type::Bool || t.kind == Type::Int || t.kind == Type::Float)
        if (llvm::Type* s = g.type(id)) lc.typeCache[id] = llvm::FixedVectorType::get(s, N);
  }

  bool supported(const EntryPoint& ep, std::string* why);
  bool emitCompute();
  bool emitQuad();
  void emitColorMerge();
  bool emitRaygen();
  // The module variable `id` as per-lane storage (interleaved) at `offset` of the lanes' block `lanes`, whose layout
  // is the private block's N times over.
  void bindLaneVariable(uint32_t id, llvm::Value* lanes, uint64_t offset) {
    const Codegen::Global& gl = g.globals.at(id);
    LanePtr lp;
    lp.p.base = b.CreateConstGEP1_64(b.getInt8Ty(), lanes, offset * N);
    lp.p.offset = b.getInt64(0);
    lp.p.limit = b.getInt64(gl.size);
    lp.p.type = g.spvType(m.def(id)->word(1)).element;
    lp.p.storage = gl.storage;
    lp.interleaved = true;
    lptrs[id] = lp;
  }
  std::string why;

 private:
  Codegen& g;
  const Module& m;
  llvm::LLVMContext& c;
  unsigned N;
  Codegen sc, lc;
  llvm::IRBuilder<>& b;
  Cfg cfg;
  Uniformity u;
  size_t firstInstruction = 0;
  uint64_t functionBytes = 0;                  // the entry function's Function variables, one invocation's
  std::vector<const Instruction*> composites;  // instructions with a matrix, struct or array result

  llvm::Function* fn = nullptr;
  llvm::BasicBlock* allocaBlock = nullptr;
  std::unordered_map<uint32_t, std::vector<llvm::Value*>> lanesOf;  // values with a varying component
  std::unordered_map<uint32_t, LanePtr> lptrs;
  std::unordered_map<uint32_t, llvm::AllocaInst*> masks;                  // block label -> incoming mask
  std::unordered_map<uint32_t, std::vector<llvm::AllocaInst*>> phiSlots;  // phi id -> per component
  std::unordered_map<uint32_t, llvm::BasicBlock*> loopHeads;
  // Divergent loops: the values used after them, and per value and component the lanes' values when they left.
  std::unordered_map<uint32_t, std::vector<uint32_t>> liveOuts;
  std::unordered_map<uint32_t, std::vector<llvm::AllocaInst*>> liveOutSlots;
  llvm::Value* mask = nullptr;
  std::unordered_map<uint64_t, Affine> affine;  // (id << 2 | component)
  static uint64_t key(uint32_t id, uint32_t k) { return uint64_t(id) << 2 | k; }
  // The affine form of component k of `id` (a uniform one has stride 0), or false.
  bool affineOf(uint32_t id, uint32_t k, Affine* out) {
    auto it = affine.find(key(id, k));
    if (it != affine.end()) return (*out = it->second), true;
    llvm::Value* v = comp(id, k);
    if (!v || isLane(v) || !v->getType()->isIntegerTy()) return false;
    *out = {v, 0};
    return true;
  }
  void affineResult(const Instruction& in, uint32_t k, uint32_t kk);
  // ---- ray generation shaders (a batch: N launch ids along x, from launchX0, in one row)
  bool raygen() const { return g.model == spv::ExecutionModelRayGenerationKHR; }
  llvm::Value* launchX0 = nullptr;  // i32: the first lane's LaunchIdKHR.x (the invocation's launchId[0] at entry)
  llvm::Value* launchYZ[2] = {};    // i32: LaunchIdKHR.y and .z, uniform
  bool traceLanes(const Instruction& in);
  // ---- fragment shaders (N = 4: the quad's lanes, lane i at pixel (x + (i & 1), y + (i >> 1)))
  bool fragment() const { return g.isFragment(); }
  llvm::Value* invArg = nullptr;                            // GraphicsInvocation[4]
  llvm::AllocaInst* helperSlot = nullptr;                   // <4 x i1>: the helper lanes (uncovered or demoted)
  uint32_t helperVar = 0;                                   // the HelperInvocation variable, where declared
  std::vector<std::pair<uint32_t, uint64_t>> builtInBlock;  // built-in variable -> its offset in the lane block
  llvm::Value* invField(unsigned l, uint64_t offset) {
    return b.CreateConstGEP1_64(b.getInt8Ty(), invArg, l * sizeof(GraphicsInvocation) + offset);
  }
  void copyLanes(bool inputs, llvm::Value* block);
  void laneStatus(uint32_t status);
  bool fragmentInstruction(const Instruction& in);
  bool derivative(const Instruction& in);
  bool sampleLanes(const Instruction& in);
  // The scalar code's `in` once per active lane, in lane order, with that lane's values of the varying operands
  // `ids` (`perLane(l)` first, where given); the result's components (`rt`: its type, 0 for none) into `comps`, the
  // lanes not run undefined.
  bool eachLane(const Instruction& in, const std::vector<uint32_t>& ids, uint32_t rt, std::vector<llvm::Value*>* comps,
                const std::function<void(unsigned)>& perLane = {},
                bool (Codegen::*emitter)(const Instruction&, bool&) = &Codegen::image,
                const std::function<void(unsigned)>& afterLane = {});
  bool atomicLanes(const Instruction& in);
  bool barrier(const Instruction& in);
  bool imageAccess(const Instruction& in);
  // The scalar code's image instruction `in` once, on uniform operands (`what` names it where the code refuses it).
  bool imageOnce(const Instruction& in, const char* what) {
    bool ok = true;
    return sc.image(in, ok) && ok ? true : fail(sc.error.empty() ? what : sc.error.c_str());
  }
  bool fetchLanes(const Instruction& in);
  uint32_t inlineTexels(const Instruction& in);
  void texelsInline(const Instruction& in, uint32_t kind, llvm::Value* bgra, llvm::Value* texels,
                    std::vector<llvm::Value*>* comps);
  bool sampleQuad(const Instruction& in, bool implicit, std::vector<llvm::Value*> dx, std::vector<llvm::Value*> dy);
  bool quadOperation(const Instruction& in);
  bool prepareSlots();
  bool laneLeaves(uint32_t typeId);

  llvm::Value* laneIndex = nullptr;  // <N x i32>: the lanes' LocalInvocationIndex
  llvm::Value* batchBase = nullptr;  // i32: the first lane's
  llvm::Value* wgBase[3] = {};       // WorkgroupId * WorkgroupSize

  bool fail(const char* what) {
    why = what;
    return false;
  }
  // The report of an access the lanes of `mk` make (Codegen::LaneReport): compute shaders' ids from the batch, ray
  // generation shaders' launch id from launchX0.
  Codegen::LaneReport lanesReport(llvm::Value* mk) const { return {mk, batchBase, wgBase, launchX0}; }
  llvm::Type* laneTy(llvm::Type* s) { return llvm::FixedVectorType::get(s, N); }
  // <N x i32> 0, 1, ..., N - 1.
  llvm::Constant* iota() {
    std::vector<llvm::Constant*> lanes;
    for (unsigned l = 0; l < N; ++l) lanes.push_back(b.getInt32(l));
    return llvm::ConstantVector::get(lanes);
  }
  // Creates the entry vkrt_group(`params`) (its first parameter the context) and its alloca block, the builder there.
  void beginEntry(llvm::ArrayRef<llvm::Type*> params) {
    fn = llvm::Function::Create(llvm::FunctionType::get(b.getVoidTy(), params, false), llvm::Function::ExternalLinkage,
                                "vkrt_group", g.out);
    fn->getArg(0)->addAttr(llvm::Attribute::get(c, "vkrt-ctx"));
    if (N == 16) fn->addFnAttr("prefer-vector-width", "512");
    allocaBlock = llvm::BasicBlock::Create(c, "entry", fn);
    b.SetInsertPoint(allocaBlock);
  }
  // The scalar and lane emitters emit into the entry, with `ctx` as their context (no private block: the SPMD code's
  // per-lane variables are its own).
  void bindEmitters(llvm::Value* ctx) {
    for (Codegen* x : {&sc, &lc}) {
      x->fn = fn;
      x->ctxArg = ctx;
      x->privArg = llvm::ConstantPointerNull::get(b.getPtrTy());
      x->allocaBlock = allocaBlock;
    }
  }
  llvm::Type* maskTy() { return laneTy(b.getInt1Ty()); }
  llvm::Value* splat(llvm::Value* s) { return b.CreateVectorSplat(N, s); }
  llvm::Value* any(llvm::Value* mk) { return b.CreateOrReduce(mk); }
  // A uniform access (or access chain) in the scalar code: it runs whatever the mask, so its out-of-bounds report
  // is made only where a lane is active (Codegen::reportIf).
  // The report names the first active lane (Codegen::laneReport).
  bool scalarMemory(const Instruction& in, bool& ok) {
    sc.reportIf = any(mask);
    Codegen::LaneReport lanes = lanesReport(mask);
    sc.laneReport = &lanes;
    bool done = sc.memory(in, ok);
    sc.laneReport = nullptr;
    sc.reportIf = nullptr;
    return done;
  }
  // The out-of-bounds report of a buffer access of `span` bytes at lp: the active lanes outside the range, on a cold
  // branch (shader_debug_codegen.cpp).
  // Where the lanes are known linear (lp.first, laneStride), all N are in bounds when the last is: a scalar test,
  // the lanes' own test only where it fails (a loop's per-lane compare costs as much as its access).
  void reportLanes(const LanePtr& lp, uint32_t kind, uint64_t span) {
    if (lp.interleaved || lp.p.resource < 0) return;
    llvm::BasicBlock* done = nullptr;
    if (lp.linear && lp.first && lp.laneStride > 0) {
      llvm::Value* end = b.CreateBinaryIntrinsic(llvm::Intrinsic::usub_sat, lp.p.limit, b.getInt64(span - 1));
      llvm::Value* room = b.CreateBinaryIntrinsic(llvm::Intrinsic::usub_sat, end, lp.first);
      llvm::Value* allIn = b.CreateAnd(lp.linear, b.CreateICmpULT(b.getInt64(uint64_t(lp.laneStride) * (N - 1)), room));
      auto* check = llvm::BasicBlock::Create(c, "spmd.lanes", fn);
      done = llvm::BasicBlock::Create(c, "spmd.lanes.done", fn);
      b.CreateCondBr(allIn, done, check, llvm::MDBuilder(c).createBranchWeights(1u << 20, 1));
      b.SetInsertPoint(check);
    }
    llvm::Value* failing = b.CreateAnd(mask, b.CreateNot(inBoundsLanes(lp, span)));
    sc.reportFailingLanes(lp.p, kind, span, failing, laneOffsets(lp, 0), lanesReport(mask));
    if (done) {
      b.CreateBr(done);
      b.SetInsertPoint(done);
    }
  }
  static bool isLane(llvm::Value* v) { return v->getType()->isVectorTy(); }  // components are SPIR-V scalars
  uint32_t count(uint32_t typeId) const { return g.componentCount(typeId); }
  bool varyingComp(uint32_t id, uint32_t k) const { return (u.bits(id) >> k) & 1; }
  llvm::AllocaInst* slot(llvm::Type* t) {
    llvm::IRBuilderBase::InsertPointGuard guard(b);
    b.SetInsertPoint(allocaBlock->getTerminator());
    return b.CreateAlloca(t);
  }

  // ---- values
  llvm::Value* comp(uint32_t id, uint32_t k) {
    auto it = lanesOf.find(id);
    if (it != lanesOf.end()) return k < it->second.size() ? it->second[k] : nullptr;
    llvm::Value* v = sc.value(id);
    if (!v) return nullptr;
    return v->getType()->isVectorTy() ? b.CreateExtractElement(v, uint64_t(k)) : v;
  }
  llvm::Value* laneComp(uint32_t id, uint32_t k) {
    llvm::Value* v = comp(id, k);
    return v && !isLane(v) ? splat(v) : v;
  }
  // The value of `id` from its components, conformed to the analysis (uniform ones assembled for `sc`).
  bool define(uint32_t id, uint32_t typeId, std::vector<llvm::Value*> comps) {
    uint32_t bitsv = u.bits(id);
    for (uint32_t k = 0; k < comps.size(); ++k) {
      if (!comps[k]) return fail("a component without a value");
      bool lane = isLane(comps[k]);
      if ((bitsv >> k) & 1) {
        if (!lane) comps[k] = splat(comps[k]);
      } else if (lane) {
        return fail("internal: a uniform value computed per lane");
      }
    }
    if (bitsv) {
      sc.values.erase(id);
      lanesOf[id] = std::move(comps);
      return true;
    }
    lanesOf.erase(id);
    sc.set(id, assemble(typeId, comps));
    return true;
  }
  llvm::Value* assemble(uint32_t typeId, const std::vector<llvm::Value*>& comps) {
    if (g.spvType(typeId).kind != Type::Vector) return comps[0];
    llvm::Value* v = llvm::UndefValue::get(g.type(typeId));
    for (uint32_t k = 0; k < comps.size(); ++k) v = b.CreateInsertElement(v, comps[k], uint64_t(k));
    return v;
  }
  bool uniformOperands(const Instruction& in, uint32_t first) {
    for (uint32_t w = first; w < in.count; ++w)
      if (u.bits(in.word(w))) return false;
    return true;
  }

  // ---- control flow
  bool edge(uint32_t from, uint32_t to, llvm::Value* edgeMask);
  bool overwrites(uint32_t from, uint32_t to) const;
  bool block(size_t bi);
  // Emits `body` only when a lane of `mk` is active.
  template <class F>
  void ifAny(llvm::Value* mk, F body) {
    auto* then = llvm::BasicBlock::Create(c, "spmd.any", fn);
    auto* join = llvm::BasicBlock::Create(c, "spmd.any.join", fn);
    b.CreateCondBr(any(mk), then, join);
    b.SetInsertPoint(then);
    body();
    b.CreateBr(join);
    b.SetInsertPoint(join);
  }

  // ---- instructions
  bool instruction(const Instruction& in);
  bool componentwise(const Instruction& in);
  bool vectorFunction(const Instruction& in, std::vector<llvm::Value*>& comps);
  bool accessChain(const Instruction& in);
  bool variable(const Instruction& in);
  bool loadInst(const Instruction& in);
  bool storeInst(const Instruction& in);
  bool storeComposite(const LanePtr& lp, uint64_t delta, uint32_t typeId, llvm::Value* value);
  LanePtr* lanePtr(uint32_t id);
  bool builtInComps(int builtIn, std::vector<llvm::Value*>& out, std::vector<Affine>& aff);
  // A scalar at `delta` bytes from lp, for an access of `span` bytes at lp that is in or out of bounds as a whole
  // (a packed vector, as the scalar code checks it).
  llvm::Value* loadLeaf(const LanePtr& lp, uint64_t delta, uint32_t scalarId, uint64_t span);
  void storeLeaf(const LanePtr& lp, uint64_t delta, uint32_t scalarId, llvm::Value* v, uint64_t span);
  // The lanes whose `span` bytes at lp are in bounds (lp's offset varying), and the same for a uniform offset.
  // Whether the lanes' offsets (offs, at `delta` from lp) are consecutive `bytes` apart, lane 0's offset, and the lanes
  // in bounds for an access of `span` bytes at lp (evaluated where the addresses are consecutive).
  struct Contiguity {
    llvm::Value* consecutive;
    llvm::Value* first;
    std::function<llvm::Value*()> inBounds;
  };
  Contiguity contiguity(const LanePtr& lp, uint64_t delta, uint64_t bytes, uint64_t span, llvm::Value* offs) {
    if (lp.linear && lp.first && lp.laneStride == int64_t(bytes)) {
      // Known linear: one scalar test; lane l is in bounds where l * bytes < end - first.
      llvm::Value* first0 = lp.first;
      return {lp.linear, b.CreateAdd(first0, b.getInt64(delta)), [this, &lp, first0, bytes, span] {
                llvm::Value* end = b.CreateBinaryIntrinsic(llvm::Intrinsic::usub_sat, lp.p.limit, b.getInt64(span - 1));
                llvm::Value* room = b.CreateBinaryIntrinsic(llvm::Intrinsic::usub_sat, end, first0);
                room = b.CreateTrunc(b.CreateBinaryIntrinsic(llvm::Intrinsic::umin, room, b.getInt64(1u << 30)),
                                     b.getInt32Ty());
                std::vector<llvm::Constant*> steps;
                for (unsigned l = 0; l < N; ++l) steps.push_back(b.getInt32(uint32_t(l * bytes)));
                return b.CreateICmpULT(llvm::ConstantVector::get(steps), splat(room));
              }};
    }
    llvm::Value* first = nullptr;
    llvm::Value* consecutive = consecutiveOffsets(offs, bytes, &first);
    return {consecutive, first, [this, &lp, span] { return inBoundsLanes(lp, span); }};
  }
  // Whether the lanes' offsets (<N x i64>) are `bytes` apart from lane 0's (`*first`), compared when the code runs.
  llvm::Value* consecutiveOffsets(llvm::Value* offs, uint64_t bytes, llvm::Value** first) {
    *first = b.CreateExtractElement(offs, uint64_t(0));
    std::vector<llvm::Constant*> steps;
    for (unsigned l = 0; l < N; ++l) steps.push_back(b.getInt64(l * bytes));
    return b.CreateAndReduce(b.CreateICmpEQ(offs, b.CreateAdd(splat(*first), llvm::ConstantVector::get(steps))));
  }
  // An offset (uniform or per lane) plus `bytes`.
  llvm::Value* addBytes(llvm::Value* offset, uint64_t bytes) {
    return b.CreateAdd(offset, isLane(offset) ? splat(b.getInt64(bytes)) : b.getInt64(bytes));
  }
  llvm::Value* inBoundsLanes(const LanePtr& lp, uint64_t span) {
    llvm::Value* end = b.CreateBinaryIntrinsic(llvm::Intrinsic::usub_sat, lp.p.limit, b.getInt64(span - 1));
    return b.CreateICmpULT(laneOffsets(lp, 0), splat(end));
  }
  llvm::Value* inBoundsUniform(const LanePtr& lp, uint64_t span) {
    uint64_t limit = llvm::cast<llvm::ConstantInt>(lp.p.limit)->getZExtValue();
    return limit < span ? b.getFalse() : b.CreateICmpULE(lp.p.offset, b.getInt64(limit - span));
  }
  llvm::Value* laneOffsets(const LanePtr& lp, uint64_t delta) {
    llvm::Value* o = lp.p.offset;
    if (!isLane(o)) o = splat(o);
    return b.CreateAdd(o, splat(b.getInt64(delta)));
  }
};

// ---------------------------------------------------------------------------------------------- support

bool Spmd::supported(const EntryPoint& ep, std::string* whyNot) {
  // (A fragment shader's interface and Private variables are per-lane storage; initializers are left to the scalar
  // path.)
  if (!g.privateInits.empty() || (!fragment() && !raygen() && g.privateSize > 0))
    return (*whyNot = "Private variables or initializers"), false;
  // A ray generation batch keeps every lane's payloads and Private variables in its frame.
  if (raygen() && uint64_t(g.privateSize) * N > kMaxRaygenLaneBytes)
    return (*whyNot = "payloads too large for a batch's frame"), false;
  // VKRT_SHADER_CHECKS=bda checks each device address access against the live buffers, on the scalar path.
  if (g.checks & abi::kCheckDeviceAddress)
    for (const auto& [id, t] : m.types)
      if (t.kind == Type::Pointer && t.storage == spv::StorageClassPhysicalStorageBuffer)
        return (*whyNot = "device addresses checked (VKRT_SHADER_CHECKS=bda)"), false;
  for (size_t i = 0; i < m.instructions.size(); ++i) {
    const Instruction& in = m.instructions[i];
    if (in.op == spv::OpFunction && in.word(2) == ep.function) firstInstruction = i;
  }
  if (m.instructions[firstInstruction].op != spv::OpFunction) return (*whyNot = "no entry function"), false;
  if (!cfg.build(m, firstInstruction, whyNot)) return false;
  for (const Cfg::Block& blk : cfg.blocks) {
    for (size_t i = blk.first + 1; i <= blk.last; ++i) {
      const Instruction& in = m.instructions[i];
      // The table's SPMD form (opcode_support.cpp); Checked instructions are decided here from their operands, Quad
      // ones only in fragment shaders.
      SpmdForm form = opSupport(in.op).spmd;
      bool ok = form == SpmdForm::Elementwise || form == SpmdForm::Own || (form == SpmdForm::Quad && fragment());
      // Compute shaders sample with an explicit level of detail, lane by lane (sampleLanes), without
      // VKRT_SHADER_CHECKS=image's per-access reports.
      if (form == SpmdForm::Quad && !fragment())
        ok = (in.op == spv::OpSampledImage || in.op == spv::OpImageSampleExplicitLod ||
              in.op == spv::OpImageSampleDrefExplicitLod) &&
             !(g.checks & abi::kCheckImage);
      switch (in.op) {
        case spv::OpVariable: {
          const Type& pt = g.spvType(in.word(1));
          ok = pt.storage == spv::StorageClassFunction && !g.isRayQuery(pt.element);
          if (ok) functionBytes += g.layoutSize(pt.element, 0, false);
          break;
        }
        case spv::OpExtInst:
          ok = in.word(3) == g.glslSet && g.glslSet && (elementwiseExt(in.word(4)) || vectorExt(in.word(4)));
          break;
        case spv::OpImageRead:
        case spv::OpImageWrite: {
          // Storage images of compute shaders (imageAccess), without VKRT_SHADER_CHECKS=image's per-access reports.
          const Instruction* it = m.def(m.typeOf(in.word(in.op == spv::OpImageWrite ? 1 : 3)));
          ok = !fragment() && !(g.checks & abi::kCheckImage) && it && storageImageType(*it);
          break;
        }
        case spv::OpImageQuerySize:
        case spv::OpImageQuerySizeLod:
        case spv::OpImageQueryLevels:
          // An image's queries in compute shaders (the scalar code's, on a uniform image and level).
          ok = !fragment();
          break;
        case spv::OpImage:
        case spv::OpImageFetch:
          // Compute shaders: the image of a sampled image (uniform), texel fetches lane by lane (fetchLanes).
          ok = !fragment() && !(g.checks & abi::kCheckImage);
          break;
        case spv::OpTraceRayKHR:
        case spv::OpExecuteCallableKHR:
        case spv::OpConvertUToAccelerationStructureKHR:
          // Ray generation shaders: traces and callables lane by lane (traceLanes), a uniform structure address.
          ok = raygen();
          break;
        case spv::OpControlBarrier:
        case spv::OpMemoryBarrier:
          // Compute shaders: a workgroup barrier is the executor's switch to the workgroup's next batch (barrier()).
          ok = g.model == spv::ExecutionModelGLCompute;
          break;
        default: break;
      }
      // Compute shaders' atomics on buffers and workgroup memory, lane by lane (atomicLanes).
      if (atomicOp(in.op)) ok = !fragment();
      if (!ok) return (*whyNot = "unsupported instruction " + opName(in.op)), false;
      // Values of composite types other than vectors (matrices, structs, arrays): uniform ones only (the scalar code
      // holds them; checked below, after the analysis).
      if (in.count >= 3 && in.op != spv::OpVariable && in.op != spv::OpAccessChain &&
          in.op != spv::OpInBoundsAccessChain && in.op != spv::OpStore && m.type(in.word(1)) &&
          !g.isImageLike(in.word(1))) {
        const Type& t = g.spvType(in.word(1));
        if (t.kind != Type::Bool && t.kind != Type::Int && t.kind != Type::Float && t.kind != Type::Vector)
          composites.push_back(&in);
      }
    }
  }
  // Module-scope variables the function reads: buffers, push constants and the compute built-ins only.
  for (const auto& [id, gl] : g.globals) {
    if (raygen()) {
      // The payloads, callable data and Private variables: per-lane storage (32-bit leaves), handed to the runtime a
      // lane at a time; the shader record (uniform: the launch's one raygen record), LaunchIdKHR (x varies) and
      // LaunchSizeKHR.
      if (gl.storage == spv::StorageClassRayPayloadKHR || gl.storage == spv::StorageClassCallableDataKHR ||
          gl.storage == spv::StorageClassPrivate) {
        if (!laneLeaves(g.spvType(m.def(id)->word(1)).element))
          return (*whyNot = "a payload, callable data or Private variable of 8-, 16- or 64-bit values"), false;
        u.laneVariables.insert(id);
        continue;
      }
      if (gl.storage == spv::StorageClassShaderRecordBufferKHR) continue;
      if (gl.storage == spv::StorageClassInput) {
        if (gl.builtIn == spv::BuiltInLaunchIdKHR || gl.builtIn == spv::BuiltInLaunchSizeKHR) continue;
        return (*whyNot = "a built-in the SPMD path does not compute"), false;
      }
    }
    if (fragment()) {
      // Images, buffers, push constants; the interface and Private variables as per-lane storage (32-bit leaves).
      if (gl.storage == spv::StorageClassWorkgroup) return (*whyNot = "workgroup variables"), false;
      bool io = gl.storage == spv::StorageClassInput || gl.storage == spv::StorageClassOutput;
      if (io && !gl.inPrivate && gl.graphicsField < 0) return (*whyNot = "a built-in without a field"), false;
      if (io || gl.storage == spv::StorageClassPrivate) {
        if (!laneLeaves(g.spvType(m.def(id)->word(1)).element))
          return (*whyNot = "an interface or Private variable of 8-, 16- or 64-bit values"), false;
        u.laneVariables.insert(id);
      }
      continue;
    }
    if (gl.storage == spv::StorageClassUniformConstant) {
      // Images, samplers, combined image samplers and texel buffers (and arrays of them, indexed uniformly); no
      // multisampled images (the scalar code has none either) or acceleration structures.
      const Type& pt = g.spvType(m.def(id)->word(1));
      const Instruction* it = m.def(pt.element);
      while (it && (it->op == spv::OpTypeArray || it->op == spv::OpTypeRuntimeArray)) it = m.def(it->word(2));
      if (it && it->op == spv::OpTypeSampledImage) it = m.def(it->word(2));
      const bool structure = it && it->op == spv::OpTypeAccelerationStructureKHR && raygen();
      if (!it || (!imageTypeOnPath(*it) && it->op != spv::OpTypeSampler && !structure))
        return (*whyNot = "a module variable of another kind"), false;
      continue;
    }
    // Workgroup variables: memory every batch of the workgroup shares, at a uniform address (the scalar code's).
    if (gl.storage == spv::StorageClassWorkgroup && g.model == spv::ExecutionModelGLCompute) continue;
    if (gl.storage == spv::StorageClassWorkgroup || gl.storage == spv::StorageClassPrivate)
      return (*whyNot = "workgroup or private variables"), false;
    if (gl.storage == spv::StorageClassInput) switch (gl.builtIn) {
        case spv::BuiltInGlobalInvocationId:
        case spv::BuiltInLocalInvocationId:
        case spv::BuiltInLocalInvocationIndex:
        case spv::BuiltInWorkgroupId:
        case spv::BuiltInNumWorkgroups:
        case spv::BuiltInWorkgroupSize: break;
        default: return (*whyNot = "a built-in the SPMD path does not compute"), false;
      }
  }
  if (g.info.usesBarrier && functionBytes * N > kMaxBatchFiberLaneBytes)
    return (*whyNot = "Function variables too large for a batch's fiber stack"), false;
  // A ray generation batch is N launch ids of one row: LaunchIdKHR.x varies, .y and .z do not, as a workgroup's ids
  // in a workgroup N wide.
  const uint32_t row[3] = {N, 1, 1};
  if (!u.analyze(m, cfg, raygen() ? row : g.info.localSize, N, whyNot)) return false;
  for (const Instruction* in : composites)
    if (u.bits(in->word(2))) return (*whyNot = "a varying value of a composite type (" + opName(in->op) + ")"), false;
  return true;
}

// ---------------------------------------------------------------------------------------------- control flow

// Whether the edge may store its phi values for every lane instead of blending them under its mask: the lanes the
// target runs with in this pass take this edge or a later one (which blends over it), never an earlier one. That
// holds for a loop's back edge (the header runs only the lanes it brings back) and for the first edge into a block
// in the module's order, unless it leaves a loop (lanes leave in different iterations).
bool Spmd::overwrites(uint32_t from, uint32_t to) const {
  const Cfg::Block& src = cfg.blocks[cfg.index.at(from)];
  if (std::count(src.successors.begin(), src.successors.end(), to) != 1) return false;
  size_t fi = cfg.index.at(from), ti = cfg.index.at(to);
  if (cfg.blocks[ti].loop && fi >= ti) return true;
  for (const auto& [header, blocks] : cfg.loopBlocks)
    if (blocks.count(from) && !blocks.count(to)) return false;
  for (size_t i = 0; i < fi; ++i)
    for (uint32_t t : cfg.blocks[i].successors)
      if (t == to) return false;
  return true;
}

bool Spmd::edge(uint32_t from, uint32_t to, llvm::Value* edgeMask) {
  auto mi = masks.find(to);
  if (mi == masks.end()) return fail("a branch to an unknown block");
  b.CreateStore(b.CreateOr(b.CreateLoad(maskTy(), mi->second), edgeMask), mi->second);
  // Leaving a divergent loop: the leaving lanes keep the values the code after the loop reads.
  for (const auto& [loop, ids] : liveOuts) {
    const auto& blocks = cfg.loopBlocks.at(loop);
    if (!blocks.count(from) || blocks.count(to)) continue;
    for (uint32_t id : ids) {
      auto& slots = liveOutSlots[id];
      for (uint32_t k = 0; k < slots.size(); ++k) {
        llvm::Value* v = laneComp(id, k);
        if (!v) return fail("a value used after its loop without a value");
        llvm::Value* old = b.CreateLoad(slots[k]->getAllocatedType(), slots[k]);
        b.CreateStore(b.CreateSelect(edgeMask, v, old), slots[k]);
      }
    }
  }
  const Cfg::Block& target = cfg.blocks[cfg.index.at(to)];
  bool whole = overwrites(from, to);
  for (size_t i = target.first + 1; i < target.last && m.instructions[i].op == spv::OpPhi; ++i) {
    const Instruction& phi = m.instructions[i];
    for (uint32_t w = 3; w + 1 < phi.count; w += 2) {
      if (phi.word(w + 1) != from) continue;
      auto& slots = phiSlots[phi.word(2)];
      for (uint32_t k = 0; k < slots.size(); ++k) {
        llvm::Type* t = slots[k]->getAllocatedType();
        llvm::Value* v = t->isVectorTy() ? laneComp(phi.word(w), k) : comp(phi.word(w), k);
        if (!v) return fail("a phi operand without a value");
        if (whole) {
          b.CreateStore(v, slots[k]);
          continue;
        }
        llvm::Value* old = b.CreateLoad(t, slots[k]);
        llvm::Value* sel = t->isVectorTy() ? edgeMask : any(edgeMask);
        b.CreateStore(b.CreateSelect(sel, v, old), slots[k]);
      }
    }
  }
  return true;
}

bool Spmd::block(size_t bi) {
  const Cfg::Block& blk = cfg.blocks[bi];
  if (blk.loop) {
    auto* head = llvm::BasicBlock::Create(c, "spmd.loop", fn);
    b.CreateBr(head);
    b.SetInsertPoint(head);
    loopHeads[blk.label] = head;
  }
  llvm::AllocaInst* mine = masks[blk.label];
  llvm::Value* incoming = b.CreateLoad(maskTy(), mine);
  b.CreateStore(llvm::Constant::getNullValue(maskTy()), mine);
  mask = bi == 0 ? mask : incoming;
  sc.setLine(nullptr);  // an OpLine holds to the end of its block
  size_t i = blk.first + 1;
  for (; i < blk.last && m.instructions[i].op == spv::OpPhi; ++i) {
    const Instruction& phi = m.instructions[i];
    std::vector<llvm::Value*> comps;
    for (llvm::AllocaInst* s : phiSlots[phi.word(2)]) comps.push_back(b.CreateLoad(s->getAllocatedType(), s));
    if (!define(phi.word(2), phi.word(1), comps)) return false;
  }
  for (; i < blk.last; ++i)
    if (!instruction(m.instructions[i])) return false;
  const Instruction& term = m.instructions[blk.last];
  if (term.op == spv::OpKill || term.op == spv::OpTerminateInvocation) {
    laneStatus(abi::kFragmentKilled);  // the lanes leave: they take no edge
  } else if (term.op == spv::OpBranch) {
    if (!edge(blk.label, term.word(1), mask)) return false;
  } else if (term.op == spv::OpBranchConditional) {
    llvm::Value* cond = comp(term.word(1), 0);
    if (!cond) return fail("a branch condition without a value");
    cond = b.CreateFreeze(isLane(cond) ? cond : splat(cond));
    if (!edge(blk.label, term.word(2), b.CreateAnd(mask, cond)) ||
        !edge(blk.label, term.word(3), b.CreateAnd(mask, b.CreateNot(cond))))
      return false;
  } else if (term.op == spv::OpSwitch) {
    // Each case takes the lanes whose selector matches its literal; the default those no case takes.
    llvm::Value* sel = comp(term.word(1), 0);
    if (!sel) return fail("a switch selector without a value");
    sel = b.CreateFreeze(isLane(sel) ? sel : splat(sel));
    auto* it = llvm::cast<llvm::IntegerType>(sel->getType()->getScalarType());
    uint32_t width = it->getBitWidth() > 32 ? 2 : 1;
    llvm::Value* rest = mask;
    for (uint32_t w = 3; w + width < term.count; w += width + 1) {
      uint64_t lit = term.word(w);
      if (width == 2) lit |= uint64_t(term.word(w + 1)) << 32;
      llvm::Value* hit = b.CreateAnd(mask, b.CreateICmpEQ(sel, splat(llvm::ConstantInt::get(it, lit))));
      if (!edge(blk.label, term.word(w + width), hit)) return false;
      rest = b.CreateAnd(rest, b.CreateNot(hit));
    }
    if (!edge(blk.label, term.word(2), rest)) return false;
  }
  // A back edge: the loop repeats while any lane is left at its header.
  for (uint32_t s : blk.successors) {
    size_t si = cfg.index.at(s);
    if (si > bi) continue;
    auto head = loopHeads.find(s);
    if (head == loopHeads.end()) return fail("a backward branch that is not a loop's back edge");
    for (uint32_t l : cfg.loopBlocks.at(s)) {
      size_t li = cfg.index.at(l);
      if (li < si || li > bi) return fail("a loop whose blocks are not all between its header and its back edge");
    }
    auto* exit = llvm::BasicBlock::Create(c, "spmd.loop.exit", fn);
    b.CreateCondBr(any(b.CreateLoad(maskTy(), masks[s])), head->second, exit);
    b.SetInsertPoint(exit);
    loopHeads.erase(head);
    auto lo = liveOuts.find(s);
    if (lo != liveOuts.end())
      for (uint32_t id : lo->second) {
        std::vector<llvm::Value*> comps;
        for (llvm::AllocaInst* a : liveOutSlots[id]) comps.push_back(b.CreateLoad(a->getAllocatedType(), a));
        if (!define(id, m.typeOf(id), comps)) return false;
      }
  }
  return true;
}

// ---------------------------------------------------------------------------------------------- instructions

bool Spmd::instruction(const Instruction& in) {
  if (quadOp(in.op)) return fragment() ? fragmentInstruction(in) : sampleLanes(in);
  if (atomicOp(in.op)) return atomicLanes(in);
  switch (in.op) {
    case spv::OpLine: return sc.setLine(&in), true;  // where out-of-bounds reports say the access is
    case spv::OpNoLine: return sc.setLine(nullptr), true;
    case spv::OpNop:
    case spv::OpUndef:
    case spv::OpSelectionMerge:
    case spv::OpLoopMerge: return true;
    case spv::OpVariable: return variable(in);
    case spv::OpAccessChain:
    case spv::OpInBoundsAccessChain: return accessChain(in);
    case spv::OpLoad: return loadInst(in);
    case spv::OpStore: return storeInst(in);
    case spv::OpImageRead:
    case spv::OpImageWrite: return imageAccess(in);
    case spv::OpImageFetch: return fetchLanes(in);
    case spv::OpTraceRayKHR:
    case spv::OpExecuteCallableKHR: return traceLanes(in);
    case spv::OpControlBarrier:
    case spv::OpMemoryBarrier: return barrier(in);
    case spv::OpConvertUToAccelerationStructureKHR: {
      if (u.bits(in.word(2))) return fail("a varying acceleration structure address");
      bool ok = true;
      return sc.rayTracing(in, ok) && ok ? true : fail(sc.error.c_str());
    }
    case spv::OpArrayLength: {
      if (lptrs.count(in.word(3))) return fail("OpArrayLength of a varying pointer");
      bool ok = true;
      return scalarMemory(in, ok) && ok ? true : fail(sc.error.c_str());
    }
    default: break;
  }
  uint32_t rt = in.word(1), id = in.word(2);
  uint32_t n = count(rt);
  uint32_t firstOperand = in.op == spv::OpExtInst ? 5 : 3;
  bool uniform = u.bits(id) == 0 && uniformOperands(in, firstOperand);
  if (in.op == spv::OpCompositeExtract || in.op == spv::OpCompositeInsert || in.op == spv::OpVectorShuffle)
    uniform = u.bits(id) == 0 && !u.bits(in.word(3)) && (in.op == spv::OpCompositeExtract || !u.bits(in.word(4)));
  if (in.op == spv::OpCopyObject && lptrs.count(in.word(3))) {
    lptrs[id] = lptrs[in.word(3)];
    return true;
  }
  if (uniform) {
    // The scalar code generator's own emitters, on uniform values.
    bool ok = true;
    if (sc.arithmetic(in, ok) || sc.composite(in, ok) || sc.extInst(in, ok) ||
        (imageValueOp(in.op) && sc.image(in, ok)))
      return ok ? true : fail(sc.error.c_str());
    return fail("an instruction the scalar emitters do not know");
  }
  if (imageValueOp(in.op)) return fail("a varying image or image query");
  std::vector<llvm::Value*> comps;
  switch (in.op) {
    case spv::OpCompositeExtract: {
      if (in.count != 5) return fail("OpCompositeExtract of a nested composite");
      comps.push_back(comp(in.word(3), in.word(4)));
      if (auto a = affine.find(key(in.word(3), in.word(4))); a != affine.end()) affine[key(id, 0)] = a->second;
      break;
    }
    case spv::OpCompositeInsert: {
      if (in.count != 6) return fail("OpCompositeInsert into a nested composite");
      for (uint32_t k = 0; k < n; ++k) comps.push_back(k == in.word(5) ? comp(in.word(3), 0) : comp(in.word(4), k));
      break;
    }
    case spv::OpCompositeConstruct:
      for (uint32_t w = 3; w < in.count; ++w)
        for (uint32_t k = 0; k < count(m.typeOf(in.word(w))); ++k) comps.push_back(comp(in.word(w), k));
      comps.resize(n);
      break;
    case spv::OpVectorShuffle: {
      uint32_t n1 = count(m.typeOf(in.word(3)));
      for (uint32_t w = 5; w < in.count; ++w) {
        uint32_t k = in.word(w);
        comps.push_back(k == 0xffffffffu ? llvm::Constant::getNullValue(g.type(g.scalarType(rt)))
                        : k < n1         ? comp(in.word(3), k)
                                         : comp(in.word(4), k - n1));
      }
      break;
    }
    case spv::OpMatrixTimesVector:
    case spv::OpVectorTimesMatrix: {
      // A uniform matrix (the scalar code's: an array of column vectors) and a varying vector, in the scalar code's
      // order of operations: M v is the columns times v's components summed in order, v M each column's ordered dot
      // product with v, starting from 0.
      const bool mv = in.op == spv::OpMatrixTimesVector;
      const uint32_t matId = in.word(mv ? 3 : 4), vecId = in.word(mv ? 4 : 3);
      llvm::Value* mat = u.bits(matId) ? nullptr : sc.value(matId);
      if (!mat) return fail("a varying matrix");
      const uint32_t cols = g.spvType(m.typeOf(matId)).count, rows = count(m.typeOf(vecId));
      auto at = [&](uint32_t col, uint32_t row) {
        return splat(b.CreateExtractElement(b.CreateExtractValue(mat, {col}), uint64_t(row)));
      };
      const uint32_t outs = mv ? n : cols;
      for (uint32_t k = 0; k < outs; ++k) {
        llvm::Value* r = nullptr;
        if (mv) {
          for (uint32_t i = 0; i < cols; ++i) {
            llvm::Value* term = b.CreateFMul(at(i, k), laneComp(vecId, i));
            r = r ? b.CreateFAdd(r, term) : term;
          }
        } else {
          r = llvm::Constant::getNullValue(laneTy(g.type(g.scalarType(rt))));
          for (uint32_t j = 0; j < rows; ++j) r = b.CreateFAdd(r, b.CreateFMul(laneComp(vecId, j), at(k, j)));
        }
        comps.push_back(r);
      }
      break;
    }
    case spv::OpSDot:
    case spv::OpUDot:
    case spv::OpSUDot:
    case spv::OpSDotAccSat:
    case spv::OpUDotAccSat:
    case spv::OpSUDotAccSat: {
      // The scalar code's integer dot product lane by lane (128-bit sums, saturation: rare, and exact so).
      const bool acc = dotAccSatOp(in.op);
      std::vector<uint32_t> ids = {in.word(3), in.word(4)};
      if (acc) ids.push_back(in.word(5));
      return eachLane(in, ids, rt, &comps, {}, &Codegen::arithmetic) && define(id, rt, comps);
    }
    case spv::OpVectorExtractDynamic:
    case spv::OpVectorInsertDynamic: {
      // As the scalar code: the index as a 32-bit unsigned value, one past the end taken as 0.
      // Values stay scalars where they are uniform (a uniform index into a vector with some varying components).
      const bool insert = in.op == spv::OpVectorInsertDynamic;
      const uint32_t vec = in.word(3), n1 = count(m.typeOf(vec));
      llvm::Value* idx = comp(in.word(insert ? 5 : 4), 0);
      llvm::Value* x = insert ? comp(in.word(4), 0) : nullptr;
      if (!idx || (insert && !x)) return fail("an operand without a value");
      auto blend = [&](llvm::Value* c, llvm::Value* t, llvm::Value* f) {
        if (isLane(c) || isLane(t) || isLane(f)) {
          c = isLane(c) ? c : splat(c), t = isLane(t) ? t : splat(t), f = isLane(f) ? f : splat(f);
        }
        return b.CreateSelect(c, t, f);
      };
      llvm::Type* i32 = isLane(idx) ? laneTy(b.getInt32Ty()) : b.getInt32Ty();
      auto k32 = [&](uint32_t k) -> llvm::Value* { return isLane(idx) ? splat(b.getInt32(k)) : b.getInt32(k); };
      idx = b.CreateZExtOrTrunc(idx, i32);
      idx = b.CreateSelect(b.CreateICmpULT(idx, k32(n1)), idx, k32(0));
      for (uint32_t k = 0; k < n1; ++k) {
        llvm::Value* ck = comp(vec, k);
        if (!ck) return fail("a component without a value");
        llvm::Value* at = b.CreateICmpEQ(idx, k32(k));
        if (insert)
          comps.push_back(blend(at, x, ck));
        else
          comps = {k == 0 ? ck : blend(at, ck, comps[0])};
      }
      break;
    }
    case spv::OpAny:
    case spv::OpAll: {
      llvm::Value* r = nullptr;
      for (uint32_t k = 0; k < count(m.typeOf(in.word(3))); ++k) {
        llvm::Value* v = laneComp(in.word(3), k);
        r = !r ? v : in.op == spv::OpAny ? b.CreateOr(r, v) : b.CreateAnd(r, v);
      }
      comps.push_back(r);
      break;
    }
    case spv::OpDot: {
      // As the scalar code's ordered reduction: ((0 + x0 y0) + x1 y1) + ...
      llvm::Value* r = splat(llvm::ConstantFP::get(g.type(rt), 0.0));
      for (uint32_t k = 0; k < count(m.typeOf(in.word(3))); ++k)
        r = b.CreateFAdd(r, b.CreateFMul(laneComp(in.word(3), k), laneComp(in.word(4), k)));
      comps.push_back(r);
      break;
    }
    case spv::OpExtInst:
      if (!vectorExt(in.word(4))) return componentwise(in);
      if (!vectorFunction(in, comps)) return false;
      break;
    default: return componentwise(in);
  }
  return define(id, rt, comps);
}

// Length, Distance, Normalize, Cross, Reflect and FaceForward of varying vectors, in the scalar code's order of
// operations (glsl_std450.cpp: a dot product is ((0 + x0 y0) + x1 y1) + ..., a scalar's is the product alone).
bool Spmd::vectorFunction(const Instruction& in, std::vector<llvm::Value*>& comps) {
  uint32_t inst = in.word(4);
  auto vec = [&](uint32_t w) {
    std::vector<llvm::Value*> v;
    for (uint32_t k = 0; k < count(m.typeOf(in.word(w))); ++k) v.push_back(laneComp(in.word(w), k));
    return v;
  };
  auto dot = [&](const std::vector<llvm::Value*>& x, const std::vector<llvm::Value*>& y) -> llvm::Value* {
    if (x.size() == 1) return b.CreateFMul(x[0], y[0]);
    llvm::Value* r = llvm::ConstantFP::get(x[0]->getType(), 0.0);
    for (size_t k = 0; k < x.size(); ++k) r = b.CreateFAdd(r, b.CreateFMul(x[k], y[k]));
    return r;
  };
  auto length = [&](const std::vector<llvm::Value*>& x) {
    return b.CreateUnaryIntrinsic(llvm::Intrinsic::sqrt, dot(x, x));
  };
  for (uint32_t w = 5; w < in.count; ++w)
    for (uint32_t k = 0; k < count(m.typeOf(in.word(w))); ++k)
      if (!comp(in.word(w), k)) return fail("an operand without a value");
  switch (inst) {
    case GLSLstd450Length: comps = {length(vec(5))}; return true;
    case GLSLstd450Distance: {
      std::vector<llvm::Value*> a = vec(5), c2 = vec(6);
      for (size_t k = 0; k < a.size(); ++k) a[k] = b.CreateFSub(a[k], c2[k]);
      comps = {length(a)};
      return true;
    }
    case GLSLstd450Normalize: {
      std::vector<llvm::Value*> x = vec(5);
      llvm::Value* len = length(x);
      for (llvm::Value* v : x) comps.push_back(b.CreateFDiv(v, len));
      return true;
    }
    case GLSLstd450Cross: {
      std::vector<llvm::Value*> x = vec(5), y = vec(6);
      if (x.size() != 3) return fail("a cross product of other than 3 components");
      for (int k = 0; k < 3; ++k) {
        int k1 = (k + 1) % 3, k2 = (k + 2) % 3;
        comps.push_back(b.CreateFSub(b.CreateFMul(x[k1], y[k2]), b.CreateFMul(x[k2], y[k1])));
      }
      return true;
    }
    case GLSLstd450Reflect: {
      std::vector<llvm::Value*> i = vec(5), n = vec(6);
      llvm::Value* d = dot(n, i);
      llvm::Value* twice = b.CreateFMul(llvm::ConstantFP::get(d->getType(), 2.0), d);
      for (size_t k = 0; k < i.size(); ++k) comps.push_back(b.CreateFSub(i[k], b.CreateFMul(twice, n[k])));
      return true;
    }
    case GLSLstd450FaceForward: {
      std::vector<llvm::Value*> n = vec(5), i = vec(6), nref = vec(7);
      llvm::Value* back = b.CreateFCmpOLT(dot(nref, i), llvm::ConstantFP::get(n[0]->getType(), 0.0));
      for (llvm::Value* v : n) comps.push_back(b.CreateSelect(back, v, b.CreateFNeg(v)));
      return true;
    }
    default: return fail("a GLSL.std.450 instruction the SPMD path does not compute");
  }
}

// Component k of an integer add, subtract, multiply or shift whose operands are affine (or uniform): affine too.
void Spmd::affineResult(const Instruction& in, uint32_t k, uint32_t n) {
  if (in.count != 5) return;
  auto opk = [&](uint32_t w) { return count(m.typeOf(in.word(w))) == n ? k : 0; };
  Affine a, c2;
  if (!affineOf(in.word(3), opk(3), &a) || !affineOf(in.word(4), opk(4), &c2)) return;
  if (a.base->getType() != c2.base->getType()) return;
  auto* kc = llvm::dyn_cast<llvm::ConstantInt>(c2.base);
  auto* ka = llvm::dyn_cast<llvm::ConstantInt>(a.base);
  Affine r{nullptr, 0};
  switch (in.op) {
    case spv::OpIAdd: r = {b.CreateAdd(a.base, c2.base), a.stride + c2.stride}; break;
    case spv::OpISub: r = {b.CreateSub(a.base, c2.base), a.stride - c2.stride}; break;
    case spv::OpIMul:
      if (kc && !c2.stride && kc->getBitWidth() <= 64)
        r = {b.CreateMul(a.base, kc), a.stride * kc->getSExtValue()};
      else if (ka && !a.stride && ka->getBitWidth() <= 64)
        r = {b.CreateMul(c2.base, ka), c2.stride * ka->getSExtValue()};
      break;
    case spv::OpShiftLeftLogical:
      if (kc && !c2.stride && kc->getZExtValue() < 32)
        r = {b.CreateShl(a.base, kc), a.stride * (int64_t(1) << kc->getZExtValue())};
      break;
    default: break;
  }
  if (r.base && r.stride > 0 && r.stride < (1 << 20)) affine[key(in.word(2), k)] = r;
}

// An elementwise instruction on varying operands: the scalar family emitters, once per component, on N-lane
// vectors (a scalar operand of a vector instruction counts for every component).
bool Spmd::componentwise(const Instruction& in) {
  uint32_t rt = in.word(1), id = in.word(2);
  uint32_t n = count(rt);
  uint32_t firstOperand = in.op == spv::OpExtInst ? 5 : 3;
  spv::Op op = in.op == spv::OpVectorTimesScalar ? spv::OpFMul : in.op;
  if (!elementwiseOp(op) && !(op == spv::OpExtInst && elementwiseExt(in.word(4))))
    return fail("an instruction the SPMD path does not vectorize");
  if (op == spv::OpBitcast && count(m.typeOf(in.word(3))) != n) return fail("a bitcast between vector sizes");
  std::vector<uint32_t> words(in.words, in.words + in.count);
  words[0] = (in.count << 16) | uint32_t(op);
  words[1] = g.scalarType(rt);
  std::vector<llvm::Value*> comps;
  for (uint32_t k = 0; k < n; ++k) {
    bool allUniform = true;
    std::vector<llvm::Value*> ops;
    for (uint32_t w = firstOperand; w < in.count; ++w) {
      uint32_t id2 = in.word(w);
      uint32_t kk = count(m.typeOf(id2)) == n ? k : 0;
      llvm::Value* v = comp(id2, kk);
      if (!v) return fail("an operand without a value");
      allUniform = allUniform && !isLane(v);
      ops.push_back(v);
    }
    Codegen& e = allUniform && !varyingComp(id, k) ? sc : lc;
    for (uint32_t w = firstOperand; w < in.count; ++w) {
      llvm::Value* v = ops[w - firstOperand];
      words[w] = kFakeId + w;
      e.set(kFakeId + w, &e == &lc && !isLane(v) ? splat(v) : v);
    }
    e.b.SetInsertPoint(b.GetInsertBlock());
    const Instruction one{op, in.offset, in.count, words.data()};
    bool ok = true;
    if (!(e.arithmetic(one, ok) || e.extInst(one, ok)) || !ok)
      return fail(ok ? "not an arithmetic instruction" : e.error.c_str());
    auto it = e.values.find(id);
    if (it == e.values.end()) return fail("no result");
    comps.push_back(it->second);
    e.values.erase(it);
    if (varyingComp(id, k)) affineResult(in, k, n);
    for (uint32_t w = firstOperand; w < in.count; ++w) e.values.erase(kFakeId + w);
  }
  return define(id, rt, comps);
}

// ---------------------------------------------------------------------------------------------- memory

LanePtr* Spmd::lanePtr(uint32_t id) {
  auto it = lptrs.find(id);
  if (it != lptrs.end()) return &it->second;
  // A module-scope invocation id: computed per lane.
  auto gl = g.globals.find(id);
  if (gl != g.globals.end() && gl->second.storage == spv::StorageClassInput &&
      (gl->second.builtIn == spv::BuiltInGlobalInvocationId || gl->second.builtIn == spv::BuiltInLocalInvocationId ||
       gl->second.builtIn == spv::BuiltInLocalInvocationIndex ||
       (raygen() && gl->second.builtIn == spv::BuiltInLaunchIdKHR))) {
    LanePtr lp;
    lp.builtIn = gl->second.builtIn;
    return &(lptrs[id] = lp);
  }
  return nullptr;
}

bool Spmd::builtInComps(int builtIn, std::vector<llvm::Value*>& out, std::vector<Affine>& aff) {
  if (builtIn == spv::BuiltInLaunchIdKHR) {
    // Ray generation: lane l at x = launchX0 + l of the batch's row.
    out = {b.CreateAdd(splat(launchX0), iota()), launchYZ[0], launchYZ[1]};
    aff = {{launchX0, 1}, {nullptr, 0}, {nullptr, 0}};
    return true;
  }
  const uint32_t* size = g.info.localSize;
  if (builtIn == spv::BuiltInLocalInvocationIndex) {
    out = {laneIndex};
    aff = {{batchBase, 1}};
    return true;
  }
  // x is base + lane where a batch stays within a row.
  aff = {{nullptr, 0}, {nullptr, 0}, {nullptr, 0}};
  if (size[0] % N == 0) {
    llvm::Value* x0 = b.CreateURem(batchBase, b.getInt32(size[0]));
    aff[0] = {builtIn == spv::BuiltInGlobalInvocationId ? b.CreateAdd(wgBase[0], x0) : x0, 1};
  }
  // Per component: uniform where the analysis says so (a batch within one row / slice), from the first lane.
  bool yUniform = size[0] % N == 0, zUniform = (size[0] * size[1]) % N == 0;
  llvm::Value* lx = b.CreateURem(laneIndex, splat(b.getInt32(size[0])));
  llvm::Value* yIdx = yUniform ? batchBase : laneIndex;
  llvm::Value* zIdx = zUniform ? batchBase : laneIndex;
  auto k = [&](llvm::Value* like, uint32_t v) -> llvm::Value* {
    return isLane(like) ? splat(b.getInt32(v)) : b.getInt32(v);
  };
  llvm::Value* ly = b.CreateURem(b.CreateUDiv(yIdx, k(yIdx, size[0])), k(yIdx, size[1]));
  llvm::Value* lz = b.CreateUDiv(zIdx, k(zIdx, size[0] * size[1]));
  out = {lx, ly, lz};
  if (builtIn == spv::BuiltInGlobalInvocationId)
    for (int i = 0; i < 3; ++i) out[i] = b.CreateAdd(isLane(out[i]) ? splat(wgBase[i]) : wgBase[i], out[i]);
  return true;
}

// Whether a value of `typeId` is made of 32-bit scalars (and booleans) only: what per-lane storage holds.
bool Spmd::laneLeaves(uint32_t typeId) {
  std::vector<uint32_t> work = {typeId};
  while (!work.empty()) {
    const Type& t = g.spvType(work.back());
    work.pop_back();
    switch (t.kind) {
      case Type::Bool: break;
      case Type::Int:
      case Type::Float:
        if (t.width != 32) return false;
        break;
      case Type::Vector:
      case Type::Matrix:
      case Type::Array: work.push_back(t.element); break;
      case Type::Struct: work.insert(work.end(), t.members.begin(), t.members.end()); break;
      default: return false;
    }
  }
  return true;
}

bool Spmd::variable(const Instruction& in) {
  uint32_t id = in.word(2);
  const Type& pt = g.spvType(in.word(1));
  if (!u.laneVariables.count(id)) {
    // Uniform: the scalar code's byte array (its initializer stored at the top of the function, every batch).
    bool ok = true;
    if (in.count > 4 && u.bits(in.word(4))) return fail("a varying initializer");
    return scalarMemory(in, ok) && ok ? true : fail(sc.error.c_str());
  }
  // Storage per lane: 32-bit leaves only, interleaved lane by lane.
  if (!laneLeaves(pt.element)) return fail("a per-lane variable of 8-, 16- or 64-bit values or of this type");
  uint64_t size = std::max<uint64_t>(g.layoutSize(pt.element, 0, false), 4);
  llvm::AllocaInst* a;
  {
    llvm::IRBuilderBase::InsertPointGuard guard(b);
    b.SetInsertPoint(allocaBlock->getTerminator());
    a = b.CreateAlloca(b.getInt8Ty(), b.getInt64(size * N));
    a->setAlignment(llvm::Align(64));
  }
  LanePtr lp;
  lp.p.base = a;
  lp.p.offset = b.getInt64(0);
  lp.p.limit = b.getInt64(size);
  lp.p.type = pt.element;
  lp.p.storage = spv::StorageClassFunction;
  lp.interleaved = true;
  lptrs[id] = lp;
  if (in.count > 4) {
    // An initializer (a constant): every lane's copy, whatever the mask.
    const Type& t = g.spvType(pt.element);
    if (t.kind != Type::Bool && t.kind != Type::Int && t.kind != Type::Float && t.kind != Type::Vector)
      return fail("an initializer of a composite per-lane variable");
    llvm::Value* saved = mask;
    mask = llvm::Constant::getAllOnesValue(maskTy());
    uint32_t sid = g.scalarType(pt.element);
    uint64_t cs = g.layoutSize(sid, 0, false);
    for (uint32_t k = 0; k < count(pt.element); ++k)
      storeLeaf(lp, k * cs, sid, laneComp(in.word(4), k), cs * count(pt.element));
    mask = saved;
  }
  return true;
}

bool Spmd::accessChain(const Instruction& in) {
  uint32_t base = in.word(3);
  LanePtr* from = lanePtr(base);
  bool varyingIndex = false;
  for (uint32_t w = 4; w < in.count; ++w) varyingIndex = varyingIndex || u.bits(in.word(w));
  if (!from && !varyingIndex) {
    bool ok = true;
    return scalarMemory(in, ok) && ok ? true : fail(sc.error.c_str());
  }
  LanePtr lp;
  if (from) {
    lp = *from;
  } else {
    Ptr& p = sc.ptr(base);
    if (!p.base && p.slot < 0) return fail("an access chain on an untracked pointer");
    lp.p = p;
    lp.linear = b.getTrue();
  }
  if (lp.builtIn >= 0) {
    uint64_t k = 0;
    if (in.count != 5 || lp.component >= 0 || !m.constantU64(in.word(4), &k) || k > 2)
      return fail("a dynamic index into an invocation id");
    lp.component = int(k);
    lptrs[in.word(2)] = lp;
    return true;
  }
  Ptr& p = lp.p;
  for (uint32_t w = 4; w < in.count; ++w) {
    uint32_t idx = in.word(w);
    if (p.slot >= 0) {
      if (u.bits(idx) || p.storage == spv::StorageClassUniformConstant) return fail("a varying descriptor index");
      sc.resolveDescriptor(p, sc.value(idx));
      continue;
    }
    if (lp.linear && !lp.first && !isLane(p.offset)) lp.first = p.offset;
    const Type& t = g.spvType(p.type);
    uint64_t k = 0;
    bool isConst = m.constantU64(idx, &k);
    llvm::Value* iv;
    Affine ia{nullptr, 0};  // a varying index's affine form, extended to i64 (lane 0's, and the lanes' step)
    if (isConst) {
      const Constant* kc = m.constant(idx);
      if (kc && g.isSignedInt(kc->type) && g.spvType(kc->type).width < 64) {
        uint32_t wd = g.spvType(kc->type).width;
        if (k >> (wd - 1)) k |= ~((1ull << wd) - 1);
      }
      iv = b.getInt64(k);
    } else {
      iv = comp(idx, 0);
      if (!iv) return fail("an index without a value");
      llvm::Type* i64t = isLane(iv) ? laneTy(b.getInt64Ty()) : b.getInt64Ty();
      bool sgn = g.isSignedInt(m.typeOf(idx));
      Affine a;
      if (isLane(iv) && lp.linear && affine.count(key(idx, 0)) && affineOf(idx, 0, &a)) {
        // The lanes' indices are consecutive after the extension when lane N-1's does not wrap.
        unsigned w = a.base->getType()->getIntegerBitWidth();
        if (w < 64) {
          llvm::APInt top = sgn ? llvm::APInt::getSignedMaxValue(w) : llvm::APInt::getMaxValue(w);
          llvm::APInt span(w, uint64_t(a.stride) * (N - 1));
          llvm::Value* room = llvm::ConstantInt::get(a.base->getType(), top - span);
          llvm::Value* ok = sgn ? b.CreateICmpSLE(a.base, room) : b.CreateICmpULE(a.base, room);
          if (!sgn || a.base->getType()->getIntegerBitWidth() == 32) {
            lp.linear = b.CreateAnd(lp.linear, ok);
            ia = {sgn ? b.CreateSExt(a.base, b.getInt64Ty()) : b.CreateZExt(a.base, b.getInt64Ty()), a.stride};
          }
        }
      }
      if (isLane(iv) && !ia.base) lp.linear = nullptr;
      iv = sgn ? b.CreateSExtOrTrunc(iv, i64t) : b.CreateZExtOrTrunc(iv, i64t);
    }
    auto add = [&](llvm::Value* bytes) {
      if (lp.linear && lp.first && !isLane(bytes)) lp.first = b.CreateAdd(lp.first, bytes);
      if (isLane(bytes) != isLane(p.offset)) {
        if (!isLane(bytes)) bytes = splat(bytes);
        if (!isLane(p.offset)) p.offset = splat(p.offset);
      }
      p.offset = b.CreateAdd(p.offset, bytes);
    };
    auto scaled = [&](uint64_t stride) {
      if (ia.base && lp.linear && lp.first) {
        lp.first = b.CreateAdd(lp.first, b.CreateMul(ia.base, b.getInt64(stride)));
        lp.laneStride += ia.stride * int64_t(stride);
      }
      return b.CreateMul(iv, isLane(iv) ? splat(b.getInt64(stride)) : b.getInt64(stride));
    };
    switch (t.kind) {
      case Type::Struct: {
        if (!isConst || k >= t.members.size()) return fail("struct index is not a valid constant");
        const Decorations& d = m.memberDecor(p.type, uint32_t(k));
        add(b.getInt64(g.memberOffset(p.type, uint32_t(k))));
        p.type = t.members[k];
        p.matrixStride = d.matrixStride > 0 ? uint32_t(d.matrixStride) : 0;
        p.rowMajor = d.rowMajor;
        p.vecStride = 0;
        break;
      }
      case Type::Array:
      case Type::RuntimeArray:
        add(scaled(g.arrayStride(p.type, p.matrixStride, p.rowMajor)));
        p.type = t.element;
        break;
      case Type::Matrix: {
        uint32_t stride = p.matrixStride ? p.matrixStride : g.naturalMatrixStride(p.type);
        uint64_t cs = g.layoutSize(g.scalarType(t.element), 0, false);
        add(scaled(p.rowMajor ? cs : stride));
        p.vecStride = p.rowMajor ? stride : 0;
        p.type = t.element;
        break;
      }
      case Type::Vector: {
        uint64_t cs = g.layoutSize(t.element, 0, false);
        add(scaled(p.vecStride ? p.vecStride : cs));
        p.vecStride = 0;
        p.type = t.element;
        break;
      }
      default: return fail("an access chain into a non-composite");
    }
  }
  lptrs[in.word(2)] = lp;
  return true;
}

llvm::Value* Spmd::loadLeaf(const LanePtr& lp, uint64_t delta, uint32_t scalarId, uint64_t span) {
  const Type& t = g.spvType(scalarId);
  bool isBool = t.kind == Type::Bool;
  llvm::Type* memTy = isBool ? b.getInt32Ty() : g.type(scalarId);
  uint64_t bytes = isBool ? 4 : t.width / 8;
  llvm::Type* vt = laneTy(memTy);
  llvm::Value* zero = llvm::Constant::getNullValue(vt);
  llvm::Value* r;
  if (lp.interleaved && !isLane(lp.p.offset)) {
    // One vector: lane l's word at o * N + 4 l. Out of bounds: zeros (the access reads the variable's start).
    llvm::Value* o = b.CreateAdd(lp.p.offset, b.getInt64(delta));
    llvm::Value* ok = inBoundsUniform(lp, span);
    llvm::Value* at =
        b.CreateGEP(b.getInt8Ty(), lp.p.base, b.CreateSelect(ok, b.CreateMul(o, b.getInt64(N)), b.getInt64(0)));
    r = b.CreateSelect(ok, b.CreateAlignedLoad(vt, at, llvm::Align(4)), zero);
  } else {
    llvm::Value* offs = laneOffsets(lp, delta);
    llvm::Align align(bytes);
    if (lp.interleaved) {
      llvm::Value* active = b.CreateAnd(mask, inBoundsLanes(lp, span));
      // Lane l's bytes of offset o at o * N + 4 l.
      std::vector<llvm::Constant*> lane4;
      for (unsigned l = 0; l < N; ++l) lane4.push_back(b.getInt64(4 * l));
      llvm::Value* at = b.CreateAdd(b.CreateMul(offs, splat(b.getInt64(N))), llvm::ConstantVector::get(lane4));
      r = b.CreateMaskedGather(vt, b.CreateGEP(b.getInt8Ty(), lp.p.base, at), align, active, zero);
    } else {
      // Consecutive addresses: one masked load; otherwise a gather.
      Contiguity ct = contiguity(lp, delta, bytes, span, offs);
      auto* contiguous = llvm::BasicBlock::Create(c, "spmd.contiguous", fn);
      auto* scattered = llvm::BasicBlock::Create(c, "spmd.gather", fn);
      auto* join = llvm::BasicBlock::Create(c, "spmd.load", fn);
      b.CreateCondBr(ct.consecutive, contiguous, scattered);
      b.SetInsertPoint(contiguous);
      llvm::Value* v1 = b.CreateMaskedLoad(vt, b.CreateGEP(b.getInt8Ty(), lp.p.base, ct.first), align,
                                           b.CreateAnd(mask, ct.inBounds()), zero);
      b.CreateBr(join);
      b.SetInsertPoint(scattered);
      llvm::Value* active = b.CreateAnd(mask, inBoundsLanes(lp, span));
      llvm::Value* v2 = b.CreateMaskedGather(vt, b.CreateGEP(b.getInt8Ty(), lp.p.base, offs), align, active, zero);
      b.CreateBr(join);
      b.SetInsertPoint(join);
      auto* phi = b.CreatePHI(vt, 2);
      phi->addIncoming(v1, contiguous);
      phi->addIncoming(v2, scattered);
      r = phi;
    }
  }
  return isBool ? b.CreateICmpNE(r, zero) : r;
}

void Spmd::storeLeaf(const LanePtr& lp, uint64_t delta, uint32_t scalarId, llvm::Value* v, uint64_t span) {
  const Type& t = g.spvType(scalarId);
  bool isBool = t.kind == Type::Bool;
  llvm::Type* memTy = isBool ? b.getInt32Ty() : g.type(scalarId);
  uint64_t bytes = isBool ? 4 : t.width / 8;
  llvm::Type* vt = laneTy(memTy);
  if (isBool) v = b.CreateZExt(v, vt);
  llvm::Align align(bytes);
  if (lp.interleaved && !isLane(lp.p.offset)) {
    // Blended into the lanes' vector (inactive lanes keep theirs); out of bounds, written back unchanged.
    llvm::Value* o = b.CreateAdd(lp.p.offset, b.getInt64(delta));
    llvm::Value* ok = inBoundsUniform(lp, span);
    llvm::Value* at =
        b.CreateGEP(b.getInt8Ty(), lp.p.base, b.CreateSelect(ok, b.CreateMul(o, b.getInt64(N)), b.getInt64(0)));
    llvm::Value* old = b.CreateAlignedLoad(vt, at, llvm::Align(4));
    b.CreateAlignedStore(b.CreateSelect(b.CreateAnd(mask, splat(ok)), v, old), at, llvm::Align(4));
    return;
  }
  llvm::Value* offs = laneOffsets(lp, delta);
  if (lp.interleaved) {
    llvm::Value* active = b.CreateAnd(mask, inBoundsLanes(lp, span));
    std::vector<llvm::Constant*> lane4;
    for (unsigned l = 0; l < N; ++l) lane4.push_back(b.getInt64(4 * l));
    llvm::Value* at = b.CreateAdd(b.CreateMul(offs, splat(b.getInt64(N))), llvm::ConstantVector::get(lane4));
    b.CreateMaskedScatter(v, b.CreateGEP(b.getInt8Ty(), lp.p.base, at), align, active);
    return;
  }
  Contiguity ct = contiguity(lp, delta, bytes, span, offs);
  auto* contiguous = llvm::BasicBlock::Create(c, "spmd.contiguous", fn);
  auto* scattered = llvm::BasicBlock::Create(c, "spmd.scatter", fn);
  auto* join = llvm::BasicBlock::Create(c, "spmd.stored", fn);
  b.CreateCondBr(ct.consecutive, contiguous, scattered);
  b.SetInsertPoint(contiguous);
  b.CreateMaskedStore(v, b.CreateGEP(b.getInt8Ty(), lp.p.base, ct.first), align, b.CreateAnd(mask, ct.inBounds()));
  b.CreateBr(join);
  b.SetInsertPoint(scattered);
  llvm::Value* active = b.CreateAnd(mask, inBoundsLanes(lp, span));
  // Lanes with the same address: the highest lane's value stays, as when the invocations run in order.
  b.CreateMaskedScatter(v, b.CreateGEP(b.getInt8Ty(), lp.p.base, offs), align, active);
  b.CreateBr(join);
  b.SetInsertPoint(join);
}

bool Spmd::loadInst(const Instruction& in) {
  uint32_t rt = in.word(1), id = in.word(2);
  LanePtr* lp = lanePtr(in.word(3));
  if (!lp) {
    bool ok = true;
    if (!(scalarMemory(in, ok) && ok))
      return fail(sc.error.empty() ? "a load the scalar code refused" : sc.error.c_str());
    if (!u.bits(id)) return true;
    // Uniform here, varying where it is read (a value used after a divergent loop): held per lane.
    std::vector<llvm::Value*> comps;
    for (uint32_t k = 0; k < count(rt); ++k) comps.push_back(comp(id, k));
    sc.values.erase(id);
    return define(id, rt, comps);
  }
  std::vector<llvm::Value*> comps;
  if (lp->builtIn >= 0) {
    std::vector<Affine> aff;
    if (!builtInComps(lp->builtIn, comps, aff)) return false;
    if (lp->component >= 0) {
      comps = {comps[lp->component]};
      aff = {aff[lp->component]};
    }
    comps.resize(count(rt));
    for (uint32_t k = 0; k < comps.size() && k < aff.size(); ++k)
      if (aff[k].base && varyingComp(id, k)) affine[key(id, k)] = aff[k];
    return define(id, rt, comps);
  }
  const Type& t = g.spvType(rt);
  uint32_t sid = g.scalarType(rt);
  uint64_t cs = g.layoutSize(sid, 0, false);
  uint64_t stride = t.kind == Type::Vector && lp->p.vecStride ? lp->p.vecStride : cs;
  // A packed vector is in or out of bounds as a whole; strided components (row-major columns) one by one.
  uint64_t span = stride == cs ? cs * count(rt) : cs;
  if (stride == cs) reportLanes(*lp, abi::kAccessLoad, span);
  for (uint32_t k = 0; k < count(rt); ++k) {
    LanePtr at = *lp;
    uint64_t delta = k * stride;
    if (stride != cs) {  // a strided component (a row-major matrix's column) is checked alone
      at.p.offset = addBytes(at.p.offset, delta);
      delta = 0;
      LanePtr component = at;
      component.first = nullptr;  // (lane 0's offset of the whole, not of this component)
      reportLanes(component, abi::kAccessLoad, span);
    }
    comps.push_back(loadLeaf(at, delta, sid, span));
  }
  // A uniform Function variable read through a per-lane pointer cannot happen (the analysis makes it per lane).
  return define(id, rt, comps);
}

bool Spmd::storeInst(const Instruction& in) {
  uint32_t ptrId = in.word(1), v = in.word(2);
  uint32_t ty = m.typeOf(v);
  LanePtr* lp = lanePtr(ptrId);
  // Helper lanes of a fragment shader write no buffer memory ("Helper Invocations").
  struct Restore {
    llvm::Value*& at;
    llvm::Value* was;
    ~Restore() { at = was; }
  } restore{mask, mask};
  spv::StorageClass storage = lp ? lp->p.storage : sc.hasPtr(ptrId) ? sc.ptr(ptrId).storage : spv::StorageClassFunction;
  if (fragment() && (storage == spv::StorageClassStorageBuffer || storage == spv::StorageClassUniform ||
                     storage == spv::StorageClassPhysicalStorageBuffer))
    mask = b.CreateAnd(mask, b.CreateNot(b.CreateLoad(maskTy(), helperSlot)));
  const Type& t = g.spvType(ty);
  const bool composite = t.kind != Type::Bool && t.kind != Type::Int && t.kind != Type::Float && t.kind != Type::Vector;
  if (composite && u.bits(v)) return fail("a store of a varying composite");
  if (composite && lp) {
    // A uniform matrix, struct or array into per-lane storage: leaf by leaf, the same value in every active lane.
    if (!lp->interleaved || isLane(lp->p.offset)) return fail("a store of a composite through a varying pointer");
    llvm::Value* value = sc.value(v);
    return value ? storeComposite(*lp, 0, ty, value) : fail("a stored value without a value");
  }
  if (!lp) {
    Ptr& p = sc.ptr(ptrId);
    if (!p.base || p.slot >= 0) return fail("a store through an untracked pointer");
    Ptr target = p;
    llvm::Value* value = nullptr;
    if (!u.bits(v)) {
      value = sc.value(v);
    } else {
      // A varying value to one address: the last active lane's (the invocations' order).
      llvm::Value* bitsv = b.CreateBitCast(mask, b.getIntNTy(N));
      llvm::Value* last =
          b.CreateSub(b.getIntN(N, N - 1), b.CreateBinaryIntrinsic(llvm::Intrinsic::ctlz, bitsv, b.getTrue()));
      last = b.CreateZExt(last, b.getInt32Ty());
      std::vector<llvm::Value*> comps;
      for (uint32_t k = 0; k < count(ty); ++k) comps.push_back(b.CreateExtractElement(laneComp(v, k), last));
      value = assemble(ty, comps);
    }
    if (!value) return fail("a stored value without a value");
    ifAny(mask, [&] {
      sc.b.SetInsertPoint(b.GetInsertBlock());
      Codegen::LaneReport lanes = lanesReport(mask);
      sc.laneReport = &lanes;
      sc.store(target, value);
      sc.laneReport = nullptr;
    });
    return true;
  }
  if (lp->builtIn >= 0) return fail("a store to an input");
  uint32_t sid = g.scalarType(ty);
  uint64_t cs = g.layoutSize(sid, 0, false);
  uint64_t stride = t.kind == Type::Vector && lp->p.vecStride ? lp->p.vecStride : cs;
  uint64_t span = stride == cs ? cs * count(ty) : cs;
  if (stride == cs) reportLanes(*lp, abi::kAccessStore, span);
  for (uint32_t k = 0; k < count(ty); ++k) {
    llvm::Value* x = laneComp(v, k);
    if (!x) return fail("a stored value without a value");
    LanePtr at = *lp;
    uint64_t delta = k * stride;
    if (stride != cs) {  // a strided component (a row-major matrix's column) is checked alone
      at.p.offset = addBytes(at.p.offset, delta);
      delta = 0;
      LanePtr component = at;
      component.first = nullptr;  // (lane 0's offset of the whole, not of this component)
      reportLanes(component, abi::kAccessStore, span);
    }
    storeLeaf(at, delta, sid, x, span);
  }
  return true;
}

// A uniform value `value` (as the scalar code holds it) of type `typeId` stored at lp + delta, a per-lane variable
// (uniform offset) in the natural layout: each 32-bit leaf as storeLeaf stores a vector of the lanes (the active
// lanes take it); other leaves fail.
bool Spmd::storeComposite(const LanePtr& lp, uint64_t delta, uint32_t typeId, llvm::Value* value) {
  const Type& t = g.spvType(typeId);
  switch (t.kind) {
    case Type::Bool:
    case Type::Int:
    case Type::Float:
      if (t.kind != Type::Bool && t.width != 32) return fail("a composite with a leaf other than 32 bits");
      storeLeaf(lp, delta, typeId, splat(value), 4);
      return true;
    case Type::Vector:
    case Type::Array:
    case Type::Struct: {
      const uint32_t n = t.kind == Type::Struct ? uint32_t(t.members.size()) : t.count;
      for (uint32_t i = 0; i < n; ++i) {
        const uint32_t member = t.kind == Type::Struct ? t.members[i] : t.element;
        const uint64_t at = t.kind == Type::Struct   ? g.memberOffset(typeId, i)
                            : t.kind == Type::Vector ? uint64_t(i) * g.layoutSize(t.element, 0, false)
                                                     : uint64_t(i) * g.arrayStride(typeId, 0, false);
        llvm::Value* part =
            t.kind == Type::Vector ? b.CreateExtractElement(value, uint64_t(i)) : b.CreateExtractValue(value, {i});
        if (!storeComposite(lp, delta + at, member, part)) return false;
      }
      return true;
    }
    default: return fail("a store of a composite of another kind");
  }
}

// ---------------------------------------------------------------------------------------------- fragment quads

// Writes `status` (abi::kFragment*) to the GraphicsInvocation of every lane of the mask.
void Spmd::laneStatus(uint32_t status) {
  for (unsigned l = 0; l < N; ++l) {
    llvm::Value* at = invField(l, offsetof(GraphicsInvocation, status));
    llvm::Value* old = b.CreateAlignedLoad(b.getInt32Ty(), at, llvm::Align(4));
    b.CreateAlignedStore(b.CreateSelect(b.CreateExtractElement(mask, uint64_t(l)), b.getInt32(status), old), at,
                         llvm::Align(4));
  }
}

// The quad's differences of a <N x float> (N = 4; lane i at pixel (x + (i & 1), y + (i >> 1))): fine derivatives
// along the lane's own row / column, coarse ones along the quad's top row / left column (graphics.cpp's order).
static void quadDifferences(llvm::IRBuilder<>& b, llvm::Value* f, bool coarse, llvm::Value** dx, llvm::Value** dy) {
  auto sh = [&](std::initializer_list<int> lanes) { return b.CreateShuffleVector(f, llvm::ArrayRef<int>(lanes)); };
  if (coarse) {
    *dx = b.CreateFSub(sh({1, 1, 1, 1}), sh({0, 0, 0, 0}));
    *dy = b.CreateFSub(sh({2, 2, 2, 2}), sh({0, 0, 0, 0}));
  } else {
    *dx = b.CreateFSub(sh({1, 1, 3, 3}), sh({0, 0, 2, 2}));
    *dy = b.CreateFSub(sh({2, 3, 2, 3}), sh({0, 1, 0, 1}));
  }
}

bool Spmd::fragmentInstruction(const Instruction& in) {
  switch (in.op) {
    case spv::OpDemoteToHelperInvocation: {
      // The lanes go on as helpers: status, the helper mask and HelperInvocation change for them.
      laneStatus(abi::kFragmentDemoted);
      b.CreateStore(b.CreateOr(b.CreateLoad(maskTy(), helperSlot), mask), helperSlot);
      if (helperVar) {
        llvm::Value* at = lptrs[helperVar].p.base;
        llvm::Type* vt = laneTy(b.getInt32Ty());
        llvm::Value* old = b.CreateAlignedLoad(vt, at, llvm::Align(4));
        b.CreateAlignedStore(b.CreateSelect(mask, splat(b.getInt32(1)), old), at, llvm::Align(4));
      }
      return true;
    }
    case spv::OpIsHelperInvocationEXT: return define(in.word(2), in.word(1), {b.CreateLoad(maskTy(), helperSlot)});
    case spv::OpGroupNonUniformQuadBroadcast:
    case spv::OpGroupNonUniformQuadSwap: return quadOperation(in);
    case spv::OpImageSampleImplicitLod:
    case spv::OpImageSampleExplicitLod:
    case spv::OpImageSampleDrefImplicitLod:
    case spv::OpImageSampleDrefExplicitLod: return sampleLanes(in);
    default: return derivative(in);
  }
}

bool Spmd::derivative(const Instruction& in) {
  uint32_t rt = in.word(1), id = in.word(2), src = in.word(3);
  if (!g.isFloat(rt)) return fail("a derivative of a value that is not a float");
  bool coarse = in.op == spv::OpDPdxCoarse || in.op == spv::OpDPdyCoarse || in.op == spv::OpFwidthCoarse;
  llvm::Type* st = g.type(g.scalarType(rt));
  llvm::Type* f32 = laneTy(b.getFloatTy());
  std::vector<llvm::Value*> comps;
  for (uint32_t k = 0; k < count(rt); ++k) {
    if (!varyingComp(id, k)) {  // a uniform value's derivatives are 0
      comps.push_back(llvm::ConstantFP::get(st, 0.0));
      continue;
    }
    llvm::Value* v = laneComp(src, k);
    if (!v) return fail("a derivative of a value without a value");
    llvm::Value *dx, *dy;
    quadDifferences(b, b.CreateFPCast(v, f32), coarse, &dx, &dy);  // in 32 bits, as the scalar path exchanges
    comps.push_back(b.CreateFPCast(derivativeResult(b, in.op, dx, dy), v->getType()));
  }
  return define(id, rt, comps);
}

// QuadBroadcast with a constant index, QuadSwap: a shuffle of the lanes.
bool Spmd::quadOperation(const Instruction& in) {
  uint32_t rt = in.word(1), id = in.word(2);
  uint64_t scope = 0, sel = 0;
  if (!m.constantU64(in.word(3), &scope) || scope != spv::ScopeSubgroup || !m.constantU64(in.word(5), &sel) || sel > 3)
    return fail("a quad operation with a computed index or another scope");
  std::vector<int> lanes(N);
  for (unsigned l = 0; l < N; ++l)
    lanes[l] = in.op == spv::OpGroupNonUniformQuadBroadcast ? int(sel) : int(l ^ (sel + 1)) & 3;
  std::vector<llvm::Value*> comps;
  for (uint32_t k = 0; k < count(rt); ++k) {
    llvm::Value* v = comp(in.word(4), k);
    if (!v) return fail("a quad operation on a value without a value");
    comps.push_back(isLane(v) ? b.CreateShuffleVector(v, lanes) : v);
  }
  return define(id, rt, comps);
}

// Sampling: a uniform one once in the scalar code; one with a varying operand lane by lane (each active lane's
// operands handed to the scalar code, which calls the runtime's function), the implicit-LOD forms with the
// coordinates' coarse derivatives taken from the quad's lanes (the quad's one level of detail, as image.cpp's scalar
// code takes them).
bool Spmd::sampleLanes(const Instruction& in) {
  uint32_t rt = in.word(1), id = in.word(2), coord = in.word(4);
  bool dref = in.op == spv::OpImageSampleDrefImplicitLod || in.op == spv::OpImageSampleDrefExplicitLod;
  bool implicit = in.op == spv::OpImageSampleImplicitLod || in.op == spv::OpImageSampleDrefImplicitLod;
  std::vector<uint32_t> ids = {coord};
  if (dref) ids.push_back(in.word(5));
  for (uint32_t w = dref ? 7 : 6; w < in.count; ++w) ids.push_back(in.word(w));  // after the operands mask
  if (u.bits(in.word(3))) return fail("sampling a varying image");
  if (!u.bits(id)) {
    sc.spmdDx = sc.spmdDy = nullptr;  // uniform coordinates: derivatives 0
    return imageOnce(in, "a sampling the scalar code refused");
  }
  uint32_t nc = count(m.typeOf(coord));
  std::vector<llvm::Value*> dxv(nc), dyv(nc);
  if (implicit)
    for (uint32_t k = 0; k < nc; ++k) {
      llvm::Value* v = laneComp(coord, k);
      if (!v) return fail("coordinates without a value");
      quadDifferences(b, b.CreateFPCast(v, laneTy(b.getFloatTy())), true, &dxv[k], &dyv[k]);
    }
  if (fragment() && !dref && sampleQuad(in, implicit, dxv, dyv)) return true;
  auto laneVector = [&](const std::vector<llvm::Value*>& v, unsigned l) -> llvm::Value* {
    if (v.size() == 1) return b.CreateExtractElement(v[0], uint64_t(l));
    llvm::Value* r = llvm::UndefValue::get(llvm::FixedVectorType::get(v[0]->getType()->getScalarType(), v.size()));
    for (size_t k = 0; k < v.size(); ++k) r = b.CreateInsertElement(r, b.CreateExtractElement(v[k], uint64_t(l)), k);
    return r;
  };
  std::vector<llvm::Value*> comps;
  bool done = eachLane(in, ids, rt, &comps, [&](unsigned l) {
    sc.spmdDx = implicit ? laneVector(dxv, l) : nullptr;
    sc.spmdDy = implicit ? laneVector(dyv, l) : nullptr;
  });
  sc.spmdDx = sc.spmdDy = nullptr;
  if (!done) return false;
  return define(id, rt, comps);
}

bool Spmd::eachLane(const Instruction& in, const std::vector<uint32_t>& ids, uint32_t rt,
                    std::vector<llvm::Value*>* comps, const std::function<void(unsigned)>& perLane,
                    bool (Codegen::*emitter)(const Instruction&, bool&),
                    const std::function<void(unsigned)>& afterLane) {
  const uint32_t id = rt ? in.word(2) : 0, nr = rt ? count(rt) : 0;
  llvm::Type* st = rt ? g.type(g.scalarType(rt)) : nullptr;
  if (comps) comps->assign(nr, rt ? llvm::UndefValue::get(laneTy(st)) : nullptr);
  for (unsigned l = 0; l < N; ++l) {
    llvm::BasicBlock* before = b.GetInsertBlock();
    auto* then = llvm::BasicBlock::Create(c, "spmd.lane", fn);
    auto* join = llvm::BasicBlock::Create(c, "spmd.lane.join", fn);
    b.CreateCondBr(b.CreateExtractElement(mask, uint64_t(l)), then, join);
    b.SetInsertPoint(then);
    std::vector<uint32_t> lent;
    for (uint32_t x : ids) {
      if (!u.bits(x) || sc.values.count(x)) continue;
      std::vector<llvm::Value*> v;
      for (uint32_t k = 0; k < count(m.typeOf(x)); ++k) v.push_back(laneComp(x, k));
      if (std::count(v.begin(), v.end(), nullptr)) return fail("an operand without a value");
      std::vector<llvm::Value*> one;
      for (llvm::Value* e : v) one.push_back(b.CreateExtractElement(e, uint64_t(l)));
      sc.set(x, assemble(m.typeOf(x), one));
      lent.push_back(x);
    }
    if (perLane) perLane(l);
    bool ok = true;
    bool done = (sc.*emitter)(in, ok) && ok;
    if (done && afterLane) afterLane(l);
    for (uint32_t x : lent) sc.values.erase(x);
    auto r = rt ? sc.values.find(id) : sc.values.end();
    if (!done || (rt && r == sc.values.end()))
      return fail(sc.error.empty() ? "an instruction the scalar code refused lane by lane" : sc.error.c_str());
    std::vector<llvm::Value*> parts;
    if (rt) {
      llvm::Value* result = r->second;
      sc.values.erase(r);
      for (uint32_t k = 0; k < nr; ++k) parts.push_back(nr > 1 ? b.CreateExtractElement(result, uint64_t(k)) : result);
    }
    llvm::BasicBlock* end = b.GetInsertBlock();
    b.CreateBr(join);
    b.SetInsertPoint(join);
    std::vector<llvm::PHINode*> phis;  // all before the inserts: a block's phis come first
    for (uint32_t k = 0; k < nr; ++k) {
      phis.push_back(b.CreatePHI(st, 2));
      phis[k]->addIncoming(llvm::UndefValue::get(st), before);
      phis[k]->addIncoming(parts[k], end);
    }
    for (uint32_t k = 0; k < nr; ++k) (*comps)[k] = b.CreateInsertElement((*comps)[k], phis[k], uint64_t(l));
  }
  return true;
}

// The kind of view (abi::ImageTexels::kind) whose texels an OpImageRead or OpImageWrite addresses itself, from the
// format the shader declares (none: 8-bit UNorm for four floats); 0 where the lanes call the runtime (another
// dimensionality, an array, a declared format without such a kind, coordinates or values other than 32-bit, image
// operands that matter). An 8-bit UNorm kind takes RGBA and BGRA views (imageAccess).
uint32_t Spmd::inlineTexels(const Instruction& in) {
  const bool write = in.op == spv::OpImageWrite;
  const Instruction* it = m.def(m.typeOf(in.word(write ? 1 : 3)));
  if (!it || it->word(3) != spv::Dim2D || it->word(5) != 0) return 0;
  uint32_t kind = 0;
  switch (it->word(8)) {
    case spv::ImageFormatR32f: kind = 1; break;
    case spv::ImageFormatRg32f: kind = 2; break;
    case spv::ImageFormatRgba32f: kind = 4; break;
    case spv::ImageFormatR32i:
    case spv::ImageFormatR32ui: kind = 1 | abi::kTexelsInteger; break;
    case spv::ImageFormatRg32i:
    case spv::ImageFormatRg32ui: kind = 2 | abi::kTexelsInteger; break;
    case spv::ImageFormatRgba32i:
    case spv::ImageFormatRgba32ui: kind = 4 | abi::kTexelsInteger; break;
    case spv::ImageFormatRgba8:
    case spv::ImageFormatUnknown:  // (a format-less access of four floats: an 8-bit UNorm view's texels inline too)
      kind = abi::kTexelsUnorm8;
      break;
    default: return 0;
  }
  const uint32_t coordType = m.typeOf(in.word(write ? 2 : 4));
  const uint32_t valueType = write ? m.typeOf(in.word(3)) : in.word(1);
  const Type* cs = m.type(g.scalarType(coordType));
  const Type* vs = m.type(g.scalarType(valueType));
  if (!cs || cs->kind != Type::Int || cs->width != 32 || count(coordType) < 2) return 0;
  if (!vs || (vs->kind != Type::Int && vs->kind != Type::Float) || vs->width != 32) return 0;
  const bool unorm = kind & abi::kTexelsUnorm8;
  if (unorm && vs->kind != Type::Float) return 0;
  // A write stores the format's components: the texel has them all.
  if (write && count(valueType) < (unorm ? 4 : (kind & abi::kTexelsWordsMask))) return 0;
  const uint32_t operandsAt = write ? 4 : 5;
  const uint32_t ignorable = spv::ImageOperandsNontemporalMask | spv::ImageOperandsNonPrivateTexelMask |
                             spv::ImageOperandsMakeTexelAvailableMask | spv::ImageOperandsMakeTexelVisibleMask;
  if (in.count > operandsAt && (in.word(operandsAt) & ~ignorable)) return 0;
  return kind;
}

// The texels of an inline access (inlineTexels' kind; `texels` the view's abi::ImageTexels; for 8-bit UNorm, `bgra`
// (i1) says whether the view is B8G8R8A8, whose first and third bytes hold blue and red): each active lane's
// texel inside the view read (into `comps`, as the runtime's vkrt_image_read gives it: zeros outside) or written
// (nothing outside), with one masked vector load or store where the lanes' texels are consecutive, else a gather or
// scatter per word (lanes writing one texel: the highest lane's value stays, as when the invocations run in order).
void Spmd::texelsInline(const Instruction& in, uint32_t kind, llvm::Value* bgra, llvm::Value* texels,
                        std::vector<llvm::Value*>* comps) {
  const bool write = in.op == spv::OpImageWrite;
  const bool unorm = kind & abi::kTexelsUnorm8;
  const uint32_t words = unorm ? 1 : kind & abi::kTexelsWordsMask;  // 32-bit words a texel
  const uint32_t coordId = in.word(write ? 2 : 4);
  llvm::Type* i32 = b.getInt32Ty();
  llvm::Type* i64 = b.getInt64Ty();
  auto field = [&](llvm::Type* t, uint64_t at) {
    return b.CreateAlignedLoad(t, b.CreateConstGEP1_64(b.getInt8Ty(), texels, at), llvm::Align(t == i64 ? 8 : 4));
  };
  llvm::Value* base = field(b.getPtrTy(), offsetof(abi::ImageTexels, base));
  llvm::Value* pitch = field(i64, offsetof(abi::ImageTexels, rowPitch));
  llvm::Value* width = field(i32, offsetof(abi::ImageTexels, width));
  llvm::Value* height = field(i32, offsetof(abi::ImageTexels, height));
  llvm::Value* x = laneComp(coordId, 0);
  llvm::Value* y = laneComp(coordId, 1);
  // (Negative coordinates wrap past the extent, as the runtime's unsigned comparison.)
  llvm::Value* inside =
      b.CreateAnd(mask, b.CreateAnd(b.CreateICmpULT(x, splat(width)), b.CreateICmpULT(y, splat(height))));
  llvm::Value* offs = b.CreateAdd(b.CreateMul(b.CreateZExt(y, laneTy(i64)), splat(pitch)),
                                  b.CreateMul(b.CreateZExt(x, laneTy(i64)), splat(b.getInt64(4 * words))));
  llvm::Value* first = nullptr;
  llvm::Value* consecutive = consecutiveOffsets(offs, 4 * words, &first);
  // The lanes' words side by side (word j of lane l at l * words + j) and back.
  std::vector<int> spread;
  for (unsigned l = 0; l < N; ++l)
    for (uint32_t j = 0; j < words; ++j) spread.push_back(int(l));
  llvm::Type* wideTy = llvm::FixedVectorType::get(i32, N * words);
  llvm::Value* wideMask = words == 1 ? inside : b.CreateShuffleVector(inside, spread);
  auto wordOf = [&](llvm::Value* wide, uint32_t j) -> llvm::Value* {
    if (words == 1) return wide;
    std::vector<int> pick;
    for (unsigned l = 0; l < N; ++l) pick.push_back(int(l * words + j));
    return b.CreateShuffleVector(wide, pick);
  };
  const llvm::Align align(4);
  llvm::Value* zero = llvm::Constant::getNullValue(laneTy(i32));
  std::vector<llvm::Value*> raw;
  if (write) {
    // A write: the texel's words (8-bit UNorm: encodeComponent's conversion, NaN to 0, clamped to [0, 1], times 255
    // in float, rounded to nearest even).
    const uint32_t texelId = in.word(3);
    if (unorm) {
      llvm::Value* packed = zero;
      llvm::Type* ft = laneTy(b.getFloatTy());
      for (uint32_t k = 0; k < 4; ++k) {
        // Byte k holds component k, or in a BGRA view component 2 - k of the first three.
        llvm::Value* f = laneComp(texelId, k);
        if (k != 1 && k != 3) f = b.CreateSelect(bgra, laneComp(texelId, 2 - k), f);
        llvm::Value* zf = llvm::Constant::getNullValue(ft);
        llvm::Value* onef = splat(llvm::ConstantFP::get(b.getFloatTy(), 1.0));
        f = b.CreateSelect(b.CreateFCmpOGT(f, zf), f, zf);
        f = b.CreateSelect(b.CreateFCmpOLT(f, onef), f, onef);
        llvm::Value* d = b.CreateFMul(f, splat(llvm::ConstantFP::get(b.getFloatTy(), 255.0)));
        d = b.CreateUnaryIntrinsic(llvm::Intrinsic::roundeven, d);
        llvm::Value* byte = b.CreateFPToUI(d, laneTy(i32));
        packed = b.CreateOr(packed, b.CreateShl(byte, splat(b.getInt32(8 * k))));
      }
      raw.push_back(packed);
    } else {
      for (uint32_t j = 0; j < words; ++j) raw.push_back(b.CreateBitCast(laneComp(texelId, j), laneTy(i32)));
    }
  }
  auto* contiguous = llvm::BasicBlock::Create(c, "spmd.texels", fn);
  auto* scattered = llvm::BasicBlock::Create(c, "spmd.texels.scattered", fn);
  auto* join = llvm::BasicBlock::Create(c, "spmd.texels.done", fn);
  b.CreateCondBr(consecutive, contiguous, scattered);
  if (!write) {
    b.SetInsertPoint(contiguous);
    llvm::Value* wide = b.CreateMaskedLoad(wideTy, b.CreateGEP(b.getInt8Ty(), base, first), align, wideMask,
                                           llvm::Constant::getNullValue(wideTy));
    std::vector<llvm::Value*> fromLoad;
    for (uint32_t j = 0; j < words; ++j) fromLoad.push_back(wordOf(wide, j));
    b.CreateBr(join);
    b.SetInsertPoint(scattered);
    std::vector<llvm::Value*> fromGather;
    for (uint32_t j = 0; j < words; ++j)
      fromGather.push_back(b.CreateMaskedGather(
          laneTy(i32), b.CreateGEP(b.getInt8Ty(), base, b.CreateAdd(offs, splat(b.getInt64(4 * j)))), align, inside,
          zero));
    b.CreateBr(join);
    b.SetInsertPoint(join);
    for (uint32_t j = 0; j < words; ++j) {
      auto* phi = b.CreatePHI(laneTy(i32), 2);
      phi->addIncoming(fromLoad[j], contiguous);
      phi->addIncoming(fromGather[j], scattered);
      raw.push_back(phi);
    }
    // The words as the runtime gives them: 8-bit UNorm components as the correctly rounded quotients i / 255 (its
    // table's values); a 32-bit format's words, then 0 and an alpha of 1 (1.0 for SFLOAT) inside the view; zeros
    // outside.
    const uint32_t rt = in.word(1);
    llvm::Type* et = g.type(g.scalarType(rt));
    comps->clear();
    for (uint32_t k = 0; k < count(rt) && k < 4; ++k) {
      llvm::Value* w;
      if (unorm) {
        llvm::Value* shift = b.getInt32(8 * k);
        if (k != 1 && k != 3) shift = b.CreateSelect(bgra, b.getInt32(8 * (2 - k)), shift);
        llvm::Value* byte = b.CreateAnd(b.CreateLShr(raw[0], splat(shift)), splat(b.getInt32(255)));
        w = b.CreateBitCast(b.CreateFDiv(b.CreateUIToFP(byte, laneTy(b.getFloatTy())),
                                         splat(llvm::ConstantFP::get(b.getFloatTy(), 255.0))),
                            laneTy(i32));
      } else if (k < words) {
        w = raw[k];
      } else if (k == 3) {
        const uint32_t one = (kind & abi::kTexelsInteger) ? 1u : 0x3f800000u;
        w = b.CreateSelect(inside, splat(b.getInt32(one)), zero);
      } else {
        w = zero;
      }
      comps->push_back(b.CreateBitCast(w, laneTy(et)));
    }
    return;
  }
  b.SetInsertPoint(contiguous);
  llvm::Value* wide = raw[0];
  if (words > 1) {
    wide = llvm::UndefValue::get(wideTy);
    for (unsigned l = 0; l < N; ++l)
      for (uint32_t j = 0; j < words; ++j)
        wide = b.CreateInsertElement(wide, b.CreateExtractElement(raw[j], uint64_t(l)), uint64_t(l * words + j));
  }
  b.CreateMaskedStore(wide, b.CreateGEP(b.getInt8Ty(), base, first), align, wideMask);
  b.CreateBr(join);
  b.SetInsertPoint(scattered);
  for (uint32_t j = 0; j < words; ++j)
    b.CreateMaskedScatter(raw[j], b.CreateGEP(b.getInt8Ty(), base, b.CreateAdd(offs, splat(b.getInt64(4 * j)))), align,
                          inside);
  b.CreateBr(join);
  b.SetInsertPoint(join);
}

// The atomics (compute shaders): each active lane's, in lane order (the invocations' order), through the scalar
// code's atomic with that lane's pointer (its offset from a varying access chain) and operands; an out-of-bounds
// lane is reported as that lane. A uniform pointer takes each lane's atomic too (each gets its own old value).
bool Spmd::atomicLanes(const Instruction& in) {
  const bool store = in.op == spv::OpAtomicStore;
  const uint32_t ptrId = in.word(store ? 1 : 3);
  const uint32_t rt = store ? 0 : in.word(1);
  std::vector<uint32_t> ids;
  for (uint32_t w = store ? 4 : 6; w < in.count; ++w) ids.push_back(in.word(w));  // values (not scope, semantics)
  LanePtr* lp = lanePtr(ptrId);
  if (lp && (lp->interleaved || lp->builtIn >= 0)) return fail("an atomic on a per-lane variable");
  if (!lp && !sc.hasPtr(ptrId)) return fail("an atomic through an untracked pointer");
  const Ptr uniform = lp ? Ptr{} : sc.ptr(ptrId);
  llvm::Value* offsets = lp ? laneOffsets(*lp, 0) : nullptr;
  Codegen::LaneReport report = lanesReport(nullptr);
  std::vector<llvm::Value*> comps;
  const bool done = eachLane(
      in, ids, rt, rt ? &comps : nullptr,
      [&](unsigned l) {
        Ptr p = lp ? lp->p : uniform;
        if (lp) p.offset = b.CreateExtractElement(offsets, uint64_t(l));
        sc.ptrs[ptrId] = p;
        std::vector<llvm::Constant*> one(N, b.getFalse());
        one[l] = b.getTrue();
        report.mask = llvm::ConstantVector::get(one);
        sc.laneReport = &report;
        sc.reportIf = b.getTrue();
      },
      &Codegen::memory);
  sc.laneReport = nullptr;
  sc.reportIf = nullptr;
  if (lp)
    sc.ptrs.erase(ptrId);
  else
    sc.ptrs[ptrId] = uniform;
  return done && (store || define(in.word(2), rt, comps));
}

// OpControlBarrier and OpMemoryBarrier (compute shaders): the scalar code's, with the batch's context. A workgroup
// barrier calls the context's `barrier`, which switches to the workgroup's next batch (each batch runs as a fiber,
// exec/compute.cpp), so that every batch reaches it before any passes it. It is called whatever the mask: the blocks
// run in order for every batch (a branch's both sides, with their masks), so each batch calls it as often as the
// others where the shader keeps its barriers in dynamically uniform control flow, as it must; the lanes of a batch
// are in step already.
bool Spmd::barrier(const Instruction& in) {
  bool ok = true;
  return sc.controlFlow(in, ok) && ok ? true : fail(sc.error.empty() ? "a barrier" : sc.error.c_str());
}

// OpTraceRayKHR and OpExecuteCallableKHR (ray generation shaders). The lanes' payloads or callable data (per-lane
// storage, their words interleaved) are copied into blocks of the variable's natural layout, one per lane, which the
// callees read and write as the caller's variable, and back after the call. A trace is one RayRuntime::traceRays
// call for the active lanes (each lane's TraceRayArgs side by side; the runtime may trace their rays as a packet); a
// callable is the scalar code's call once per active lane in lane order, the lane's x stored in the invocation's
// launchId[0] (the callee's LaunchIdKHR, the runtime's reports) first.
bool Spmd::traceLanes(const Instruction& in) {
  const bool trace = in.op == spv::OpTraceRayKHR;
  const uint32_t var = in.word(trace ? 11 : 2);
  LanePtr* lp = lanePtr(var);
  auto* limit = lp ? llvm::dyn_cast<llvm::ConstantInt>(lp->p.limit) : nullptr;
  auto* offset = lp ? llvm::dyn_cast<llvm::ConstantInt>(lp->p.offset) : nullptr;
  if (!lp || !lp->interleaved || !limit || !offset || !offset->isZero())
    return fail("a payload or callable data operand that is not a per-lane variable");
  const uint64_t words = (limit->getZExtValue() + 3) / 4;
  const uint64_t stride = (std::max<uint64_t>(words, 1) * 4 + 15) / 16 * 16;  // a lane's block
  auto frameBytes = [&](uint64_t bytes) {
    llvm::IRBuilderBase::InsertPointGuard guard(b);
    b.SetInsertPoint(allocaBlock->getTerminator());
    llvm::AllocaInst* a = b.CreateAlloca(b.getInt8Ty(), b.getInt64(bytes));
    a->setAlignment(llvm::Align(16));
    return a;
  };
  llvm::AllocaInst* blocks = frameBytes(stride * (trace ? N : 1));
  // Word w of lane l: at 4 (w N + l) in the lanes' storage, at 4 w in the lane's block.
  auto move = [&](unsigned l, bool in) {
    llvm::Value* block = b.CreateConstGEP1_64(b.getInt8Ty(), blocks, trace ? l * stride : 0);
    for (uint64_t w = 0; w < words; ++w) {
      llvm::Value* lane = b.CreateConstGEP1_64(b.getInt8Ty(), lp->p.base, 4 * (w * N + l));
      llvm::Value* own = b.CreateConstGEP1_64(b.getInt8Ty(), block, 4 * w);
      llvm::Value* from = in ? lane : own;
      b.CreateAlignedStore(b.CreateAlignedLoad(b.getInt32Ty(), from, llvm::Align(4)), in ? own : lane, llvm::Align(4));
    }
  };
  if (!trace) {
    const bool done = eachLane(
        in, {in.word(1)}, 0, nullptr,
        [&](unsigned l) {
          b.CreateAlignedStore(b.CreateAdd(launchX0, b.getInt32(l)),
                               b.CreateConstGEP1_64(b.getInt8Ty(), sc.ctxArg, offsetof(RayInvocation, launchId)),
                               llvm::Align(4));
          move(l, true);
          Ptr p = lp->p;
          p.base = blocks;
          sc.ptrs[var] = p;
        },
        &Codegen::rayTracing, [&](unsigned l) { move(l, false); });
    sc.ptrs.erase(var);
    return done;
  }
  if (u.bits(in.word(1))) return fail("a trace through a varying acceleration structure");
  // Operand w (1..10) of lane l: its component k.
  auto operand = [&](uint32_t w, uint32_t k, unsigned l) -> llvm::Value* {
    llvm::Value* v = comp(in.word(w), k);
    return v && isLane(v) ? b.CreateExtractElement(v, uint64_t(l)) : v;
  };
  for (uint32_t w = 1; w <= 10; ++w)
    if (!operand(w, 0, 0)) return fail("a trace operand without a value");
  llvm::AllocaInst* args = frameBytes(N * sizeof(TraceRayArgs));
  ifAny(mask, [&] {
    for (unsigned l = 0; l < N; ++l) {
      sc.storeTraceRayArgs(
          b.CreateConstGEP1_64(b.getInt8Ty(), args, l * sizeof(TraceRayArgs)),
          [&](uint32_t w, uint32_t k) { return operand(w, k, l); }, b.getInt32(uint32_t(limit->getZExtValue())),
          b.CreateConstGEP1_64(b.getInt8Ty(), blocks, l * stride));
      move(l, true);
    }
    llvm::Value* bits = b.CreateZExt(b.CreateBitCast(mask, b.getIntNTy(N)), b.getInt32Ty());
    auto* ty =
        llvm::FunctionType::get(b.getVoidTy(), {b.getPtrTy(), b.getPtrTy(), b.getInt32Ty(), b.getInt32Ty()}, false);
    b.CreateCall(ty, sc.rayRuntimeFunction(offsetof(RayRuntime, traceRays)), {sc.ctxArg, args, bits, launchX0});
    for (unsigned l = 0; l < N; ++l) move(l, false);
  });
  return true;
}

// OpImageFetch (compute shaders; the image uniform): the scalar code's one call where every operand is uniform, else
// its call lane by lane with each lane's coordinate and image operands.
bool Spmd::fetchLanes(const Instruction& in) {
  if (u.bits(in.word(3))) return fail("a fetch from a varying image");
  if (!u.bits(in.word(2))) return imageOnce(in, "a fetch the scalar code refused");
  std::vector<uint32_t> ids = {in.word(4)};
  for (uint32_t w = 6; w < in.count; ++w) ids.push_back(in.word(w));  // the image operands after their mask
  std::vector<llvm::Value*> comps;
  return eachLane(in, ids, in.word(1), &comps) && define(in.word(2), in.word(1), comps);
}

// OpImageRead and OpImageWrite of a storage image (compute shaders; the image uniform). Where inlineTexels names a
// kind and the bound view is of that kind (its record's object an image view whose ImageTexels say so: abi.hpp), the
// lanes address the texels themselves (texelsInline); otherwise each active lane makes the scalar code's runtime
// call. A read whose operands are all uniform is the scalar code's one call.
bool Spmd::imageAccess(const Instruction& in) {
  const bool write = in.op == spv::OpImageWrite;
  const uint32_t imageId = in.word(write ? 1 : 3);
  if (u.bits(imageId)) return fail("a varying image");
  if (!write && !u.bits(in.word(2))) return imageOnce(in, "an image read the scalar code refused");
  std::vector<uint32_t> ids = {in.word(write ? 2 : 4)};
  if (write) ids.push_back(in.word(3));
  const uint32_t rt = write ? 0 : in.word(1);
  const uint32_t kind = inlineTexels(in);
  std::vector<llvm::Value*> comps;
  if (!kind) {
    if (!eachLane(in, ids, rt, &comps)) return false;
    return write || define(in.word(2), rt, comps);
  }
  // Which path: the record's object an image view whose texels are of `kind` (abi.hpp). A record of another type has
  // no ImageTexels at its address: its type word decides before the address is read; no object reads the zeros.
  llvm::Value* img = sc.value(imageId);
  if (!img) return fail("an image without a value");
  llvm::Value* rec = b.CreateExtractValue(img, {0});
  llvm::Value* object = b.CreateAlignedLoad(
      b.getPtrTy(), b.CreateConstGEP1_64(b.getInt8Ty(), rec, offsetof(abi::DescriptorRecord, object)), llvm::Align(8));
  llvm::Value* hasObject = b.CreateIsNotNull(object);
  llvm::Value* typeAt =
      b.CreateConstGEP1_64(b.getInt8Ty(), b.CreateSelect(hasObject, object, g.zeros), abi::kObjectTypeOffset);
  llvm::Value* isView =
      b.CreateAnd(hasObject, b.CreateICmpEQ(b.CreateAlignedLoad(b.getInt32Ty(), typeAt, llvm::Align(4)),
                                            b.getInt32(abi::kObjectTypeImageView)));
  llvm::Value* address = b.CreateAlignedLoad(
      b.getPtrTy(), b.CreateConstGEP1_64(b.getInt8Ty(), rec, offsetof(abi::DescriptorRecord, address)), llvm::Align(8));
  llvm::Value* texels = b.CreateSelect(isView, address, g.zeros);
  llvm::Value* viewKind = b.CreateAlignedLoad(
      b.getInt32Ty(), b.CreateConstGEP1_64(b.getInt8Ty(), texels, offsetof(abi::ImageTexels, kind)), llvm::Align(4));
  auto* inlined = llvm::BasicBlock::Create(c, "spmd.image.inline", fn);
  auto* calls = llvm::BasicBlock::Create(c, "spmd.image.calls", fn);
  auto* join = llvm::BasicBlock::Create(c, "spmd.image.done", fn);
  // An 8-bit UNorm access takes R8G8B8A8 and B8G8R8A8 views alike (the runtime converts to the view's order too).
  const bool unorm = kind & abi::kTexelsUnorm8;
  llvm::Value* ofKind = unorm ? b.CreateAnd(viewKind, b.getInt32(~abi::kTexelsBgra)) : viewKind;
  llvm::Value* bgra =
      unorm ? b.CreateICmpNE(b.CreateAnd(viewKind, b.getInt32(abi::kTexelsBgra)), b.getInt32(0)) : b.getFalse();
  b.CreateCondBr(b.CreateICmpEQ(ofKind, b.getInt32(kind)), inlined, calls,
                 llvm::MDBuilder(c).createBranchWeights(1u << 10, 1));
  b.SetInsertPoint(inlined);
  std::vector<llvm::Value*> fast;
  texelsInline(in, kind, bgra, texels, &fast);
  llvm::BasicBlock* fastEnd = b.GetInsertBlock();
  b.CreateBr(join);
  b.SetInsertPoint(calls);
  if (!eachLane(in, ids, rt, &comps)) return false;
  llvm::BasicBlock* callsEnd = b.GetInsertBlock();
  b.CreateBr(join);
  b.SetInsertPoint(join);
  if (write) return true;
  for (size_t k = 0; k < comps.size(); ++k) {
    auto* phi = b.CreatePHI(comps[k]->getType(), 2);
    phi->addIncoming(fast[k], fastEnd);
    phi->addIncoming(comps[k], callsEnd);
    comps[k] = phi;
  }
  return define(in.word(2), rt, comps);
}

// Gradient sampling of the quad's lanes in one call (vkrt_image_sample_grad_quad) where the scalar code would call
// vkrt_image_sample_grad once per active lane: OpImageSampleImplicitLod (the coordinates' coarse derivatives `dx`,
// `dy`, with or without Bias) and OpImageSampleExplicitLod with Grad, of a 1D, 2D or 3D (array) image, 32-bit
// result components. False, with nothing emitted, for the rest (the lane by lane calls).
bool Spmd::sampleQuad(const Instruction& in, bool implicit, std::vector<llvm::Value*> dx,
                      std::vector<llvm::Value*> dy) {
  const uint32_t rt = in.word(1), id = in.word(2), coord = in.word(4);
  const Instruction* t = m.def(m.typeOf(in.word(3)));
  if (t && t->op == spv::OpTypeSampledImage) t = m.def(t->word(2));
  if (!t || t->op != spv::OpTypeImage || t->word(6) != 0) return false;
  const uint32_t dim = t->word(3);
  if (dim != spv::Dim1D && dim != spv::Dim2D && dim != spv::Dim3D) return false;
  llvm::Type* st = g.type(g.scalarType(rt));
  if (!g.isFloat(m.typeOf(coord)) || !(st->isFloatTy() || st->isIntegerTy(32)) || count(rt) > 4) return false;
  const uint32_t ignorable = spv::ImageOperandsSignExtendMask | spv::ImageOperandsZeroExtendMask |
                             spv::ImageOperandsNontemporalMask | spv::ImageOperandsNonPrivateTexelMask |
                             spv::ImageOperandsMakeTexelAvailableMask | spv::ImageOperandsMakeTexelVisibleMask;
  const uint32_t operands = in.count > 5 ? in.word(5) : 0;
  const uint32_t wanted = implicit ? spv::ImageOperandsBiasMask : spv::ImageOperandsGradMask;
  if ((operands & ~(wanted | ignorable)) || (!implicit && !(operands & wanted)) || (implicit && !fragment()))
    return false;
  llvm::Value* img = sc.value(in.word(3));
  if (!img) return false;
  llvm::Type* f4 = laneTy(b.getFloatTy());
  llvm::Value* bias = llvm::ConstantFP::getNaN(f4);
  if (operands & spv::ImageOperandsBiasMask) {
    llvm::Value* v = laneComp(in.word(6), 0);
    if (!v) return false;
    bias = b.CreateFPCast(v, f4);
  }
  if (!implicit) {
    dx.clear();
    dy.clear();
    for (uint32_t k = 0; k < count(m.typeOf(in.word(6))) && k < 4; ++k) {
      llvm::Value *x = laneComp(in.word(6), k), *y = laneComp(in.word(7), k);
      if (!x || !y) return false;
      dx.push_back(b.CreateFPCast(x, f4));
      dy.push_back(b.CreateFPCast(y, f4));
    }
  }
  std::vector<llvm::Value*> c;
  for (uint32_t k = 0; k < count(m.typeOf(coord)) && k < 4; ++k) {
    llvm::Value* v = laneComp(coord, k);
    if (!v) return false;
    c.push_back(b.CreateFPCast(v, f4));
  }
  // Four <4 x float> rows (component k of the four lanes), missing components 0 as the scalar code's words.
  llvm::Type* rows = llvm::ArrayType::get(f4, 4);
  auto buffer = [&](const std::vector<llvm::Value*>& v) {
    llvm::AllocaInst* a = slot(rows);
    a->setAlignment(llvm::Align(16));
    for (uint32_t k = 0; k < 4; ++k)
      b.CreateStore(k < v.size() ? v[k] : llvm::Constant::getNullValue(f4), b.CreateConstGEP2_32(rows, a, 0, k));
    return a;
  };
  llvm::Value *coords = buffer(c), *ddx = buffer(dx), *ddy = buffer(dy);
  llvm::AllocaInst* biasBuf = slot(f4);
  biasBuf->setAlignment(llvm::Align(16));
  b.CreateStore(bias, biasBuf);
  llvm::AllocaInst* out = slot(rows);
  out->setAlignment(llvm::Align(16));
  llvm::Value* lanes = b.CreateZExt(b.CreateBitCast(mask, b.getIntNTy(4)), b.getInt32Ty());
  llvm::Type* ptrTy = b.getPtrTy();
  llvm::FunctionCallee fnc = g.out.getOrInsertFunction(
      "vkrt_image_sample_grad_quad",
      llvm::FunctionType::get(b.getVoidTy(), {ptrTy, ptrTy, ptrTy, ptrTy, ptrTy, ptrTy, b.getInt32Ty(), ptrTy}, false));
  b.CreateCall(fnc,
               {b.CreateExtractValue(img, {0}), b.CreateExtractValue(img, {1}), coords, ddx, ddy, biasBuf, lanes, out});
  std::vector<llvm::Value*> comps;
  for (uint32_t k = 0; k < count(rt); ++k)
    comps.push_back(b.CreateLoad(laneTy(st), b.CreateConstGEP2_32(rows, out, 0, k)));
  return define(id, rt, comps);
}

// Copies between the lane block (the interface and Private variables, interleaved: lane l's word at byte o is at
// o * N + 4 l) and the quad's GraphicsInvocations: inputs (and the built-in outputs' preset values) in, outputs out.
void Spmd::copyLanes(bool inputs, llvm::Value* block) {
  // The user locations (inputs, outputs and the dual-source output) and FragCoord (fragCoordSoa) come in and go out
  // as structures of arrays through lane 0's pointers: word w of lane l at 4 (w N + l), one vector load or store per
  // word.
  auto soa = [&](int slotsField) {
    return slotsField == int(offsetof(GraphicsInvocation, inputs)) ||
           slotsField == int(offsetof(GraphicsInvocation, outputs)) ||
           slotsField == int(offsetof(GraphicsInvocation, outputs1)) ||
           slotsField == int(offsetof(GraphicsInvocation, fragCoordSoa));
  };
  auto word = [&](uint64_t blockOffset, int slotsField, uint64_t at) {
    if (soa(slotsField)) {
      llvm::Value* base = b.CreateAlignedLoad(b.getPtrTy(), invField(0, unsigned(slotsField)), llvm::Align(8));
      llvm::Value* there = b.CreateConstGEP1_64(b.getInt8Ty(), base, at * N);
      llvm::Value* here = b.CreateConstGEP1_64(b.getInt8Ty(), block, blockOffset * N);
      llvm::Type* vt = laneTy(b.getInt32Ty());
      if (inputs)
        b.CreateAlignedStore(b.CreateAlignedLoad(vt, there, llvm::Align(4)), here, llvm::Align(16));
      else
        b.CreateAlignedStore(b.CreateAlignedLoad(vt, here, llvm::Align(16)), there, llvm::Align(4));
      return;
    }
    llvm::Value* there[4];
    for (unsigned l = 0; l < N; ++l) {
      llvm::Value* base = invField(l, 0);
      if (slotsField >= 0) base = b.CreateAlignedLoad(b.getPtrTy(), invField(l, unsigned(slotsField)), llvm::Align(8));
      there[l] = b.CreateConstGEP1_64(b.getInt8Ty(), base, at);
    }
    llvm::Type* vt = laneTy(b.getInt32Ty());
    llvm::Value* here = b.CreateConstGEP1_64(b.getInt8Ty(), block, blockOffset * N);
    if (inputs) {
      llvm::Value* v = llvm::UndefValue::get(vt);
      for (unsigned l = 0; l < N; ++l)
        v = b.CreateInsertElement(v, b.CreateAlignedLoad(b.getInt32Ty(), there[l], llvm::Align(4)), uint64_t(l));
      b.CreateAlignedStore(v, here, llvm::Align(16));
    } else {
      llvm::Value* v = b.CreateAlignedLoad(vt, here, llvm::Align(16));
      for (unsigned l = 0; l < N; ++l)
        b.CreateAlignedStore(b.CreateExtractElement(v, uint64_t(l)), there[l], llvm::Align(4));
    }
  };
  for (const Codegen::IoCopy& io : g.ioCopies)
    if (io.input == inputs)
      for (uint32_t j = 0; j < io.bytes; j += 4) word(io.privOffset + j, io.slotsField, io.at + j);
  for (auto [id, offset] : builtInBlock) {
    const Codegen::Global& gl = g.globals.at(id);
    if (!inputs && gl.storage != spv::StorageClassOutput) continue;
    if (inputs && id == helperVar) continue;  // emitQuad's, from the coverage
    if (inputs && gl.graphicsField == int(offsetof(GraphicsInvocation, fragCoord))) {
      for (uint32_t j = 0; j < gl.size; j += 4) word(offset + j, int(offsetof(GraphicsInvocation, fragCoordSoa)), j);
      continue;
    }
    for (uint32_t j = 0; j < gl.size; j += 4) word(offset + j, -1, uint64_t(gl.graphicsField) + j);
  }
}

// vkrt_group(GraphicsInvocation quad[4]): the fragment shader for the quad's four lanes in one pass. The executor
// fills the four invocations as for the scalar vkrt_main and reads their outputs and status after.
bool Spmd::emitQuad() {
  beginEntry({b.getPtrTy()});
  invArg = fn->getArg(0);
  auto* body = llvm::BasicBlock::Create(c, "spmd.quad", fn);
  b.CreateBr(body);
  bindEmitters(invArg);  // lane 0's: the context fields the code reads (resources, push constants) are the quad's
  for (Codegen* x : {&sc, &lc}) x->spmdDerivatives = true;
  if (!prepareSlots()) return false;
  // The lane block: the private block's layout (user interface and Private variables), then the built-ins.
  uint64_t size = (g.privateSize + 15) / 16 * 16;
  std::vector<uint32_t> vars;
  for (const auto& [id, gl] : g.globals)
    if (u.laneVariables.count(id)) vars.push_back(id);
  std::sort(vars.begin(), vars.end());
  for (uint32_t id : vars) {
    const Codegen::Global& gl = g.globals.at(id);
    if (gl.inPrivate || gl.storage == spv::StorageClassPrivate) continue;
    builtInBlock.push_back({id, size});
    size += (gl.size + 3) / 4 * 4;
  }
  size = std::max<uint64_t>(size, 16);
  llvm::AllocaInst* lanes;
  {
    llvm::IRBuilderBase::InsertPointGuard guard(b);
    b.SetInsertPoint(allocaBlock->getTerminator());
    lanes = b.CreateAlloca(b.getInt8Ty(), b.getInt64(size * N));
    lanes->setAlignment(llvm::Align(64));
    helperSlot = b.CreateAlloca(maskTy());
  }
  b.SetInsertPoint(body);
  b.CreateMemSet(lanes, b.getInt8(0), b.getInt64(size * N), llvm::MaybeAlign(64));
  for (uint32_t id : vars) {
    const Codegen::Global& gl = g.globals.at(id);
    uint64_t offset = gl.offset;
    for (auto [bid, o] : builtInBlock)
      if (bid == id) offset = o;
    bindLaneVariable(id, lanes, offset);
    if (gl.storage == spv::StorageClassInput && gl.graphicsField == int(offsetof(GraphicsInvocation, helper)))
      helperVar = id;
  }
  copyLanes(true, lanes);
  // The helper lanes: those the quad's coverage leaves out (one vector load: the executor sets the invocations'
  // `helper` flags only for shaders with side effects), and HelperInvocation from them where the shader declares it.
  llvm::Value* coverage = b.CreateAlignedLoad(
      laneTy(b.getInt32Ty()),
      b.CreateAlignedLoad(b.getPtrTy(), invField(0, offsetof(GraphicsInvocation, coverageSoa)), llvm::Align(8)),
      llvm::Align(4));
  llvm::Value* helper = b.CreateICmpEQ(coverage, splat(b.getInt32(0)));
  b.CreateStore(helper, helperSlot);
  if (helperVar)
    b.CreateAlignedStore(b.CreateZExt(helper, laneTy(b.getInt32Ty())), lptrs[helperVar].p.base, llvm::Align(4));
  // Helper lanes run where the shader takes derivatives (needsQuad, from the scalar compilation); else only the
  // covered lanes, as the scalar path runs them.
  mask = g.info.graphics.needsQuad ? llvm::Constant::getAllOnesValue(maskTy()) : b.CreateNot(helper);
  for (size_t bi = 0; bi < cfg.blocks.size(); ++bi)
    if (!block(bi)) return false;
  if (!loopHeads.empty()) return fail("a loop without a back edge");
  copyLanes(false, lanes);
  emitColorMerge();
  b.CreateRetVoid();
  return true;
}

// After a fragment shader compiled with a ColorMerge (CodeGen::colorMerge), the writes of colour attachment 0 for the
// quad invocation 0's colorQuad points at (null: none), as the back end's quad paths make them
// (raster/backend.cpp colorUnorm8Quad, whose order of float operations this keeps, so the same bytes): the source
// clamped to [0, 1] where it blends, the destination decoded as byte / 255, the blend, the write mask, the encode
// (clamped to [0, 1], times 255, rounded to nearest even as cvtps2dq does). The colours are the four words the entry
// has just stored through invocation 0's `outputs` (location 0), read back (LLVM forwards the stores). Not where the
// shader can discard or writes FragDepth or SampleMask (the back end's tests and masks come between), or has no float
// output at location 0: GraphicsStageInfo::mergesColor stays false.
void Spmd::emitColorMerge() {
  const abi::ColorMerge mc = g.colorMerge;
  const GraphicsStageInfo& gi = g.info.graphics;
  if (mc.format == abi::ColorMerge::kNone || gi.canDiscard || gi.writesDepth || gi.writesSampleMask) return;
  bool location0 = false;
  for (const GraphicsStageInfo::Location& o : gi.outputs) location0 |= o.location == 0 && !o.integer && !o.wide;
  if (!location0) return;
  llvm::Value* dst =
      b.CreateAlignedLoad(b.getPtrTy(), invField(0, offsetof(GraphicsInvocation, colorQuad)), llvm::Align(8));
  auto* write = llvm::BasicBlock::Create(c, "merge.write", fn);
  auto* done = llvm::BasicBlock::Create(c, "merge.done", fn);
  b.CreateCondBr(b.CreateIsNotNull(dst), write, done);
  b.SetInsertPoint(write);
  // The quad's four lanes (N): a component of them as one vector, a row of the quad's texels as two words.
  llvm::Type* f4 = laneTy(b.getFloatTy());
  llvm::Type* i2 = llvm::FixedVectorType::get(b.getInt32Ty(), 2);
  auto fsplat = [&](float v) { return splat(llvm::ConstantFP::get(b.getFloatTy(), v)); };
  auto isplat = [&](uint32_t v) { return splat(b.getInt32(v)); };
  // x86's maxps(a, b) and minps(a, b): a > b ? a : b and a < b ? a : b (the second operand when unordered).
  auto maxps = [&](llvm::Value* x, llvm::Value* y) { return b.CreateSelect(b.CreateFCmpOGT(x, y), x, y); };
  auto minps = [&](llvm::Value* x, llvm::Value* y) { return b.CreateSelect(b.CreateFCmpOLT(x, y), x, y); };
  const bool blend = mc.blend != abi::ColorMerge::kOff;
  const uint32_t mask = mc.writeMask & 0xF;
  const bool readDst = blend || mask != 0xF;
  // Component c's byte in a texel.
  auto shiftOf = [&](int k) {
    return uint32_t(8 * (mc.format == abi::ColorMerge::kBgra8Unorm && k != 1 && k != 3 ? 2 - k : k));
  };
  llvm::Value* outs =
      b.CreateAlignedLoad(b.getPtrTy(), invField(0, offsetof(GraphicsInvocation, outputs)), llvm::Align(8));
  llvm::Value* s[4];
  for (int k = 0; k < 4; ++k) {
    s[k] = b.CreateAlignedLoad(f4, b.CreateConstGEP1_64(b.getInt8Ty(), outs, 16 * k), llvm::Align(4));
    if (blend) s[k] = minps(fsplat(1), maxps(fsplat(0), s[k]));  // clamp01: a NaN stays (the encode makes it 0)
  }
  llvm::Value* pitch =
      b.CreateAlignedLoad(b.getInt64Ty(), invField(0, offsetof(GraphicsInvocation, colorPitch)), llvm::Align(8));
  llvm::Value* dst1 = b.CreateGEP(b.getInt8Ty(), dst, pitch);  // the quad's second row
  llvm::Value* d[4] = {};
  if (readDst) {
    llvm::Value* words =
        b.CreateShuffleVector(b.CreateAlignedLoad(i2, dst, llvm::Align(4)),
                              b.CreateAlignedLoad(i2, dst1, llvm::Align(4)), llvm::ArrayRef<int>{0, 1, 2, 3});
    for (int k = 0; k < 4; ++k)
      d[k] = b.CreateFDiv(b.CreateSIToFP(b.CreateAnd(b.CreateLShr(words, isplat(shiftOf(k))), isplat(0xFF)), f4),
                          fsplat(255));
  }
  llvm::Value* r[4] = {s[0], s[1], s[2], s[3]};
  if (blend) {
    // The factors of the four equations (kBlendShapes): source times sf plus destination times df, per component.
    llvm::Value* oneMinusSa = b.CreateFSub(fsplat(1), s[3]);
    for (int k = 0; k < 4; ++k) {
      llvm::Value *sf = fsplat(1), *df = fsplat(1);
      switch (mc.blend) {
        case abi::ColorMerge::kOver: sf = k == 3 ? fsplat(1) : s[3], df = oneMinusSa; break;
        case abi::ColorMerge::kOverAll: sf = s[3], df = oneMinusSa; break;
        case abi::ColorMerge::kPremultiplied: df = oneMinusSa; break;
        default: break;  // kAdditive
      }
      r[k] = b.CreateFAdd(b.CreateFMul(s[k], sf), b.CreateFMul(d[k], df));
    }
  }
  llvm::Function* cvt = llvm::Intrinsic::getDeclaration(fn->getParent(), llvm::Intrinsic::x86_sse2_cvtps2dq);
  llvm::Value* out = isplat(0);
  for (int k = 0; k < 4; ++k) {
    llvm::Value* v = mask >> k & 1 ? r[k] : d[k];
    v = minps(maxps(v, fsplat(0)), fsplat(1));  // saturate: a NaN becomes 0
    llvm::Value* bytes = b.CreateCall(cvt, {b.CreateFMul(v, fsplat(255))});
    out = b.CreateOr(out, b.CreateShl(bytes, isplat(shiftOf(k))));
  }
  b.CreateAlignedStore(b.CreateShuffleVector(out, llvm::ArrayRef<int>{0, 1}), dst, llvm::Align(4));
  b.CreateAlignedStore(b.CreateShuffleVector(out, llvm::ArrayRef<int>{2, 3}), dst1, llvm::Align(4));
  b.CreateBr(done);
  b.SetInsertPoint(done);
  g.info.graphics.mergesColor = true;
}

// vkrt_group(RayInvocation* inv, uint32_t lanes) of a ray generation shader (abi::RayBatchEntry): the launch ids
// (inv->launchId[0] + l, inv->launchId[1], inv->launchId[2]) for l < lanes in one pass; the payloads, callable data and
// Private variables per lane (the private block's layout, interleaved), zeroed per batch.
bool Spmd::emitRaygen() {
  beginEntry({b.getPtrTy(), b.getInt32Ty()});
  llvm::Value* inv = fn->getArg(0);
  auto* body = llvm::BasicBlock::Create(c, "spmd.raygen", fn);
  b.CreateBr(body);
  bindEmitters(inv);
  if (!prepareSlots()) return false;
  const uint64_t size = std::max<uint64_t>((g.privateSize + 15) / 16 * 16, 16);
  llvm::AllocaInst* lanes;
  {
    llvm::IRBuilderBase::InsertPointGuard guard(b);
    b.SetInsertPoint(allocaBlock->getTerminator());
    lanes = b.CreateAlloca(b.getInt8Ty(), b.getInt64(size * N));
    lanes->setAlignment(llvm::Align(64));
  }
  b.SetInsertPoint(body);
  b.CreateMemSet(lanes, b.getInt8(0), b.getInt64(size * N), llvm::MaybeAlign(64));
  for (const auto& [id, gl] : g.globals)
    if (u.laneVariables.count(id)) bindLaneVariable(id, lanes, gl.offset);
  auto launchId = [&](int i) {
    return b.CreateConstGEP1_64(b.getInt8Ty(), inv, offsetof(RayInvocation, launchId) + 4 * i);
  };
  launchX0 = b.CreateAlignedLoad(b.getInt32Ty(), launchId(0), llvm::Align(4));
  for (int i = 0; i < 2; ++i) launchYZ[i] = b.CreateAlignedLoad(b.getInt32Ty(), launchId(i + 1), llvm::Align(4));
  mask = b.CreateICmpULT(iota(), splat(fn->getArg(1)));
  for (size_t bi = 0; bi < cfg.blocks.size(); ++bi)
    if (!block(bi)) return false;
  if (!loopHeads.empty()) return fail("a loop without a back edge");
  b.CreateAlignedStore(launchX0, launchId(0), llvm::Align(4));
  b.CreateRetVoid();
  return true;
}

// ---------------------------------------------------------------------------------------------- the entry

// The per-block masks and the phis' and loops' live-out slots, zeroed in the alloca block (every block consumes its
// mask).
bool Spmd::prepareSlots() {
  for (const Cfg::Block& blk : cfg.blocks) {
    llvm::AllocaInst* a = slot(maskTy());
    {
      llvm::IRBuilderBase::InsertPointGuard guard(b);
      b.SetInsertPoint(allocaBlock->getTerminator());
      b.CreateStore(llvm::Constant::getNullValue(maskTy()), a);
    }
    masks[blk.label] = a;
    for (size_t i = blk.first + 1; i < blk.last && m.instructions[i].op == spv::OpPhi; ++i) {
      const Instruction& phi = m.instructions[i];
      uint32_t n = count(phi.word(1));
      llvm::Type* s = g.type(g.scalarType(phi.word(1)));
      if (!s) return fail("a phi type");
      for (uint32_t k = 0; k < n; ++k)
        phiSlots[phi.word(2)].push_back(slot(varyingComp(phi.word(2), k) ? laneTy(s) : s));
    }
  }
  for (uint32_t loop : u.divergentLoops) {
    liveOuts[loop] = Uniformity::liveOuts(m, cfg, loop);
    for (uint32_t id : liveOuts[loop]) {
      if (liveOutSlots.count(id)) continue;
      llvm::Type* s = g.type(g.scalarType(m.typeOf(id)));
      if (!s) return fail("a value used after its loop of a type the SPMD path does not hold");
      for (uint32_t k = 0; k < count(m.typeOf(id)); ++k) liveOutSlots[id].push_back(slot(laneTy(s)));
    }
  }
  return true;
}

bool Spmd::emitCompute() {
  const uint32_t* size = g.info.localSize;
  uint32_t total = size[0] * size[1] * size[2];
  beginEntry({b.getPtrTy()});
  llvm::Value* local = sc.groupContext(fn->getArg(0));
  for (int i = 0; i < 3; ++i) {
    llvm::Value* wg = b.CreateAlignedLoad(
        b.getInt32Ty(), b.CreateConstGEP1_64(b.getInt8Ty(), local, offsetof(InvocationContext, workgroupId) + 4 * i),
        llvm::Align(4));
    wgBase[i] = b.CreateMul(wg, b.getInt32(size[i]));
  }
  auto* batch = llvm::BasicBlock::Create(c, "spmd.batch", fn);
  b.CreateBr(batch);
  bindEmitters(local);
  if (!prepareSlots()) return false;
  b.SetInsertPoint(batch);
  if (g.info.usesBarrier) {
    // A shader with workgroup barriers: one batch per call, the one whose first LocalInvocationIndex the context
    // holds; the executor runs the workgroup's batches as fibers, switching at each barrier.
    batchBase = b.CreateAlignedLoad(b.getInt32Ty(),
                                    b.CreateConstGEP1_64(b.getInt8Ty(), local, offsetof(InvocationContext, localIndex)),
                                    llvm::Align(4));
    laneIndex = b.CreateAdd(splat(batchBase), iota());
    mask = b.CreateICmpULT(laneIndex, splat(b.getInt32(total)));  // the tail of the last batch is off
    for (size_t bi = 0; bi < cfg.blocks.size(); ++bi)
      if (!block(bi)) return false;
    if (!loopHeads.empty()) return fail("a loop without a back edge");
    b.CreateRetVoid();
    return true;
  }
  auto* base = b.CreatePHI(b.getInt32Ty(), 2);
  base->addIncoming(b.getInt32(0), allocaBlock);
  batchBase = base;
  laneIndex = b.CreateAdd(splat(base), iota());
  mask = b.CreateICmpULT(laneIndex, splat(b.getInt32(total)));  // the tail of the last batch is off
  for (size_t bi = 0; bi < cfg.blocks.size(); ++bi)
    if (!block(bi)) return false;
  if (!loopHeads.empty()) return fail("a loop without a back edge");
  llvm::Value* next = b.CreateAdd(base, b.getInt32(N));
  base->addIncoming(next, b.GetInsertBlock());
  auto* done = llvm::BasicBlock::Create(c, "spmd.done", fn);
  b.CreateCondBr(b.CreateICmpULT(next, b.getInt32(total)), batch, done);
  b.SetInsertPoint(done);
  b.CreateRetVoid();
  return true;
}

}  // namespace

void setSpmd(bool enabled) { spmdOn = enabled; }
bool spmdEnabled() { return spmdOn; }

unsigned spmdLanes() {
  if (!spmdOn) return 0;
  std::string error;
  auto jtmb = detail::targetMachine(&error);
  if (!jtmb) return 0;
  bool avx2 = false, avx512 = false;
  for (const std::string& f : jtmb->getFeatures().getFeatures()) {
    avx2 = avx2 || f == "+avx2";
    avx512 = avx512 || f == "+avx512f";
  }
  if (!jtmb->getCPU().empty() && jtmb->getFeatures().getFeatures().empty()) {
    // A named CPU: its own features.
    llvm::SmallVector<llvm::StringRef, 64> features;
    llvm::X86::getFeaturesForCPU(jtmb->getCPU(), features);
    for (llvm::StringRef f : features) {
      avx2 = avx2 || f == "avx2";
      avx512 = avx512 || f == "avx512f";
    }
  }
  // AVX2 and SSE get twice their register's lanes: LLVM splits each value in two, and a loop-carried dependency
  // chain (Mandelbrot's iteration, a dot product's sum) then runs as two independent ones whose latencies overlap
  // (docs/spmd.md: 2.1x on Mandelbrot with AVX2).
  return avx512 || avx2 ? 16 : 8;
}

std::string spmdKey() { return "spmd " + std::to_string(spmdLanes()); }

namespace {

// Emits an SPMD entry with `emit` where the path supports the shader; else removes what it emitted (false).
bool emitEntry(Codegen& g, const EntryPoint& ep, unsigned lanes, bool (Spmd::*emit)()) {
  if (!lanes) return false;  // VKRT_SPMD=0
  Spmd s(g, lanes);
  std::string whyNot;
  if (!s.supported(ep, &whyNot)) return false;
  if (!(s.*emit)()) {
    if (llvm::Function* f = g.out.getFunction("vkrt_group")) {
      f->dropAllReferences();
      f->eraseFromParent();
    }
    return false;
  }
  g.info.spmdLanes = uint8_t(lanes);
  return true;
}

}  // namespace

bool emitSpmdQuad(Codegen& g, const EntryPoint& ep, llvm::Function* main) {
  if (!g.isFragment() || !emitEntry(g, ep, spmdLanes() ? 4 : 0, &Spmd::emitQuad)) return false;
  main->setLinkage(llvm::Function::InternalLinkage);
  return true;
}

bool emitSpmdRaygen(Codegen& g, const EntryPoint& ep, llvm::Function* main) {
  (void)main;  // vkrt_main stays: the executor runs it where it records ray trees
  return g.model == spv::ExecutionModelRayGenerationKHR && emitEntry(g, ep, spmdLanes(), &Spmd::emitRaygen);
}

bool emitSpmdGroup(Codegen& g, const EntryPoint& ep, llvm::Function* main) {
  if (!emitEntry(g, ep, spmdLanes(), &Spmd::emitCompute)) return false;
  main->setLinkage(llvm::Function::InternalLinkage);
  return true;
}

}  // namespace vkrt::spirv
