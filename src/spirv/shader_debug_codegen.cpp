// SPIR-V -> LLVM IR for shader debugging: debugPrintfEXT calls and the out-of-bounds reports of buffer accesses
// (abi/shader_debug.hpp). Each call site becomes a constant record of the module (its object code).
#include <llvm/IR/Constants.h>
#include <llvm/IR/MDBuilder.h>

#include <utility>

#include "spirv/codegen.hpp"
#include "spirv/shader_debug.hpp"

namespace vkrt::spirv {

namespace {

// The index (i32) of the first set lane of `mask` (<N x i1>, not all clear).
llvm::Value* firstLane(Codegen& g, llvm::Value* mask) {
  auto* vt = llvm::cast<llvm::FixedVectorType>(mask->getType());
  llvm::Value* bits = g.b.CreateBitCast(mask, g.b.getIntNTy(vt->getNumElements()));
  return g.b.CreateZExtOrTrunc(g.b.CreateBinaryIntrinsic(llvm::Intrinsic::cttz, bits, g.b.getTrue()), g.b.getInt32Ty());
}

llvm::GlobalVariable* siteConstant(Codegen& g, const std::string& bytes) {
  auto it = g.siteGlobals.find(bytes);
  if (it != g.siteGlobals.end()) return it->second;
  auto* init = llvm::ConstantDataArray::getRaw(bytes, bytes.size(), g.b.getInt8Ty());
  auto* gv =
      new llvm::GlobalVariable(g.out, init->getType(), true, llvm::GlobalValue::PrivateLinkage, init, "vkrt.site");
  gv->setAlignment(llvm::Align(4));
  g.siteGlobals[bytes] = gv;
  return gv;
}

}  // namespace

bool Codegen::debugPrintf(const Instruction& in, bool& ok) {
  // OpExtInst %void %set DebugPrintf(1) %format %args...
  const Instruction* format = m.def(in.word(5));
  if (in.word(4) != 1 || !format || format->op != spv::OpString)
    return (ok = fail(in, "NonSemantic.DebugPrintf: not a DebugPrintf with an OpString format")), true;
  std::vector<PrintfArg> args;
  std::vector<llvm::Value*> components;
  for (uint32_t i = 6; i < in.count; ++i) {
    llvm::Value* v = value(in.word(i));
    const Type* t = m.type(m.typeOf(in.word(i)));
    const Type* scalar = t && t->kind == Type::Vector ? m.type(t->element) : t;
    if (!v || !scalar || (scalar->kind != Type::Int && scalar->kind != Type::Float && scalar->kind != Type::Bool))
      return (ok = unsupported(in, "debugPrintfEXT argument that is not a scalar or vector")), true;
    PrintfArg a;
    a.kind = scalar->kind == Type::Float  ? abi::kArgFloat
             : scalar->kind == Type::Bool ? abi::kArgBool
             : scalar->isSigned           ? abi::kArgSigned
                                          : abi::kArgUnsigned;
    a.width = scalar->kind == Type::Bool ? 1 : scalar->width;
    a.components = t->kind == Type::Vector ? t->count : 1;
    for (uint32_t k = 0; k < a.components; ++k) {
      llvm::Value* c = t->kind == Type::Vector ? b.CreateExtractElement(v, uint64_t(k)) : v;
      if (a.kind == abi::kArgFloat) {
        c = b.CreateBitCast(b.CreateFPExt(c, b.getDoubleTy()), b.getInt64Ty());
      } else if (a.kind == abi::kArgSigned) {
        c = b.CreateSExt(c, b.getInt64Ty());
      } else {
        c = b.CreateZExtOrTrunc(c, b.getInt64Ty());
      }
      components.push_back(c);
    }
    args.push_back(a);
  }
  llvm::Constant* site = siteConstant(*this, printfSite(uint32_t(model), args, format->string(2), info.entryName));
  llvm::Value* buffer = llvm::ConstantPointerNull::get(b.getPtrTy());
  if (!components.empty()) {
    llvm::IRBuilderBase::InsertPointGuard guard(b);
    if (llvm::Instruction* t = allocaBlock->getTerminator()) {
      b.SetInsertPoint(t);
    } else {
      b.SetInsertPoint(allocaBlock);
    }
    auto* a = b.CreateAlloca(b.getInt64Ty(), i64(components.size()));
    a->setAlignment(llvm::Align(8));
    buffer = a;
  }
  for (size_t k = 0; k < components.size(); ++k)
    b.CreateAlignedStore(components[k], b.CreateConstGEP1_64(b.getInt64Ty(), buffer, k), llvm::Align(8));
  llvm::FunctionCallee f = out.getOrInsertFunction(
      "vkrt_debug_printf", llvm::FunctionType::get(b.getVoidTy(), {b.getPtrTy(), b.getPtrTy(), b.getPtrTy()}, false));
  b.CreateCall(f, {ctxArg, site, buffer});
  return true;
}

llvm::Constant* Codegen::accessSiteFor(const Ptr& p, uint32_t kind, uint64_t bytes) {
  AccessSiteInfo s;
  s.model = uint32_t(model);
  s.kind = kind;
  if (p.resource >= 0 && size_t(p.resource) < info.resources.size()) {
    s.set = info.resources[p.resource].set;
    s.binding = info.resources[p.resource].binding;
  }
  s.bytes = uint32_t(bytes);
  if (const Instruction* line = currentLine) {
    const Instruction* file = m.def(line->word(1));
    std::string name = file && file->op == spv::OpString ? file->string(2) : std::string();
    if (name == kWordOffsetFile) {
      s.wordOffset = line->word(2);
    } else {
      s.file = name;
      s.line = line->word(2);
      s.column = line->word(3);
    }
  }
  auto n = m.names.find(p.variable);
  if (n != m.names.end()) s.variable = n->second;
  s.entryName = info.entryName;
  return siteConstant(*this, accessSite(s));
}

void Codegen::callOutOfBounds(llvm::Value* site, llvm::Value* offset, llvm::Value* range, llvm::Value* element) {
  llvm::Type* i64t = b.getInt64Ty();
  llvm::FunctionCallee f = out.getOrInsertFunction(
      "vkrt_out_of_bounds",
      llvm::FunctionType::get(b.getVoidTy(), {b.getPtrTy(), b.getPtrTy(), i64t, i64t, i64t}, false));
  llvm::Value* ctx = ctxArg;
  if (laneReport) {
    // The SPMD path: the first active lane (a uniform access, run once for the batch) makes the report.
    llvm::Value* lane = firstLane(*this, laneReport->mask);
    ctx = laneContext(*laneReport, lane);
  }
  auto* call = b.CreateCall(f, {ctx, site, offset, range, element ? element : i64(0)});
  call->addFnAttr(llvm::Attribute::Cold);
}

llvm::Value* Codegen::laneContext(const LaneReport& lanes, llvm::Value* lane) {
  if (lanes.launchX0) {
    b.CreateAlignedStore(b.CreateAdd(lanes.launchX0, b.CreateZExtOrTrunc(lane, b.getInt32Ty())),
                         b.CreateConstGEP1_64(b.getInt8Ty(), ctxArg, offsetof(RayInvocation, launchId)),
                         llvm::Align(4));
    return ctxArg;
  }
  if (!lanes.batchBase)
    return b.CreateGEP(b.getInt8Ty(), ctxArg,
                       b.CreateMul(b.CreateZExt(lane, b.getInt64Ty()), i64(sizeof(GraphicsInvocation))));
  return reportContext(b.CreateAdd(lanes.batchBase, lane), lanes.wgBase);
}

llvm::Value* Codegen::reportContext(llvm::Value* localIndex, llvm::Value* const base[3]) {
  llvm::Function* f = b.GetInsertBlock()->getParent();
  auto* slot = llvm::dyn_cast_or_null<llvm::AllocaInst>(reportContextSlot);
  if (!slot || slot->getFunction() != f) {
    llvm::IRBuilderBase::InsertPointGuard guard(b);
    b.SetInsertPoint(&*f->getEntryBlock().getFirstInsertionPt());
    slot = b.CreateAlloca(b.getInt8Ty(), i64(sizeof(InvocationContext)));
    slot->setAlignment(llvm::Align(16));
    reportContextSlot = slot;
  }
  b.CreateMemCpy(slot, llvm::MaybeAlign(16), ctxArg, llvm::MaybeAlign(8), i64(sizeof(InvocationContext)));
  llvm::Type* i32t = b.getInt32Ty();
  llvm::Value* index = b.CreateZExtOrTrunc(localIndex, i32t);
  llvm::Value* local[3] = {
      b.CreateURem(index, b.getInt32(info.localSize[0])),
      b.CreateURem(b.CreateUDiv(index, b.getInt32(info.localSize[0])), b.getInt32(info.localSize[1])),
      b.CreateUDiv(index, b.getInt32(info.localSize[0] * info.localSize[1]))};
  for (int d = 0; d < 3; ++d)
    b.CreateAlignedStore(b.CreateAdd(base[d], local[d]),
                         b.CreateConstGEP1_64(b.getInt8Ty(), slot, offsetof(InvocationContext, globalId) + 4 * d),
                         llvm::Align(4));
  return slot;
}

void Codegen::reportFailingLanes(const Ptr& p, uint32_t kind, uint64_t bytes, llvm::Value* failing,
                                 llvm::Value* offsets, const LaneReport& lanes) {
  if (p.resource < 0 || !ctxArg) return;
  llvm::Function* f = b.GetInsertBlock()->getParent();
  auto* report = llvm::BasicBlock::Create(c, "spmd.outofbounds", f);
  auto* next = llvm::BasicBlock::Create(c, "spmd.outofbounds.next", f);
  b.CreateCondBr(b.CreateOrReduce(failing), report, next, llvm::MDBuilder(c).createBranchWeights(1, 1u << 20));
  b.SetInsertPoint(report);
  llvm::Value* lane = firstLane(*this, failing);
  llvm::Value* offset = b.CreateExtractElement(offsets, lane);
  llvm::Value* saved = ctxArg;
  ctxArg = laneContext(lanes, lane);
  const LaneReport* savedLanes = std::exchange(laneReport, nullptr);
  callOutOfBounds(accessSiteFor(p, kind, bytes), offset, p.unmaskedLimit ? p.unmaskedLimit : p.limit, p.element);
  laneReport = savedLanes;
  ctxArg = saved;
  b.CreateBr(next);
  b.SetInsertPoint(next);
}

llvm::BasicBlock* Codegen::outOfBoundsBlock(const Ptr& p, uint32_t kind, uint64_t bytes, llvm::BasicBlock* join,
                                            llvm::BasicBlock** exit) {
  if (p.resource < 0 || !ctxArg) return nullptr;
  llvm::IRBuilderBase::InsertPointGuard guard(b);
  llvm::Function* f = b.GetInsertBlock()->getParent();
  auto* block = llvm::BasicBlock::Create(c, "outofbounds", f);
  b.SetInsertPoint(block);
  if (p.helper) {
    // A helper lane's write is dropped by design: reported only where the lane's own limit fails too.
    auto* report = llvm::BasicBlock::Create(c, "outofbounds.report", f);
    llvm::Value* end = b.CreateBinaryIntrinsic(llvm::Intrinsic::usub_sat, p.unmaskedLimit, i64(bytes ? bytes - 1 : 0));
    b.CreateCondBr(b.CreateOr(p.helper, b.CreateICmpULT(p.offset, end)), join, report);
    b.SetInsertPoint(report);
  }
  outOfBounds(p, kind, bytes, p.offset, p.unmaskedLimit ? p.unmaskedLimit : p.limit, p.element);
  if (exit) *exit = b.GetInsertBlock();
  b.CreateBr(join);
  return block;
}

void Codegen::outOfBounds(const Ptr& p, uint32_t kind, uint64_t bytes, llvm::Value* offset, llvm::Value* range,
                          llvm::Value* element) {
  if (reportIf) {
    llvm::Function* f = b.GetInsertBlock()->getParent();
    auto* active = llvm::BasicBlock::Create(c, "outofbounds.active", f);
    auto* next = llvm::BasicBlock::Create(c, "outofbounds.next", f);
    b.CreateCondBr(reportIf, active, next);
    b.SetInsertPoint(active);
    llvm::Value* saved = std::exchange(reportIf, nullptr);
    outOfBounds(p, kind, bytes, offset, range, element);
    reportIf = saved;
    b.CreateBr(next);
    b.SetInsertPoint(next);
    return;
  }
  llvm::Constant* site = accessSiteFor(p, kind, bytes);
  if (!groupLog) {
    callOutOfBounds(site, offset, range, element);
    return;
  }
  // word = site index + 1 (16 bits) | element (16 bits, saturated) << 16 | offset (32 bits, saturated) << 32.
  llvm::Type* i64t = b.getInt64Ty();
  const uint64_t index = groupSites.size();
  groupSites.push_back({site, p.resource, kind});
  auto saturate = [&](llvm::Value* v, uint64_t max) {
    return b.CreateBinaryIntrinsic(llvm::Intrinsic::umin, b.CreateZExtOrTrunc(v, i64t), i64(max));
  };
  llvm::Value* word =
      b.CreateOr(i64(index + 1), b.CreateOr(b.CreateShl(saturate(element ? element : i64(0), 0xffff), 16),
                                            b.CreateShl(saturate(offset, 0xffffffff), 32)));
  llvm::Value* invocation = b.CreateAlignedLoad(
      b.getInt32Ty(), b.CreateConstGEP1_64(b.getInt8Ty(), ctxArg, offsetof(InvocationContext, localIndex)),
      llvm::Align(4));
  // vkrt_group's local context holds the log in `executor` (which compiled code does not otherwise read).
  llvm::Value* log = b.CreateAlignedLoad(
      b.getPtrTy(), b.CreateConstGEP1_64(b.getInt8Ty(), ctxArg, offsetof(InvocationContext, executor)), llvm::Align(8));
  llvm::Value* at = b.CreateGEP(b.getInt8Ty(), log, b.CreateMul(b.CreateZExt(invocation, i64t), i64(8)));
  // The invocation's first failing access is kept (a descriptor index before the access through the null descriptor
  // it selects).
  llvm::Value* kept = b.CreateAlignedLoad(i64t, at, llvm::Align(8));
  b.CreateAlignedStore(b.CreateSelect(b.CreateICmpEQ(kept, i64(0)), word, kept), at, llvm::Align(8));
}

void Codegen::reportGroupLog(llvm::Value* ctx, llvm::Value* local, llvm::Value* log, llvm::Value* const base[3]) {
  if (groupSites.empty()) return;
  llvm::Type* i64t = b.getInt64Ty();
  llvm::Type* i32t = b.getInt32Ty();
  llvm::Function* f = b.GetInsertBlock()->getParent();
  const uint32_t n = info.localSize[0] * info.localSize[1] * info.localSize[2];
  // The sites' records, resources and kinds, indexed by the log's site index.
  std::vector<llvm::Constant*> sites;
  std::vector<uint32_t> resources, kinds;
  for (const GroupSite& s : groupSites) {
    sites.push_back(s.site);
    resources.push_back(uint32_t(s.resource));
    kinds.push_back(s.kind);
  }
  auto* siteArray = llvm::ArrayType::get(b.getPtrTy(), sites.size());
  auto* siteTable = new llvm::GlobalVariable(out, siteArray, true, llvm::GlobalValue::PrivateLinkage,
                                             llvm::ConstantArray::get(siteArray, sites), "vkrt.sites");
  auto table32 = [&](const std::vector<uint32_t>& v, const char* name) {
    auto* init = llvm::ConstantDataArray::get(c, v);
    return new llvm::GlobalVariable(out, init->getType(), true, llvm::GlobalValue::PrivateLinkage, init, name);
  };
  llvm::GlobalVariable* resourceTable = table32(resources, "vkrt.site_resources");
  llvm::GlobalVariable* kindTable = table32(kinds, "vkrt.site_kinds");

  // Pass 1: any entry at all (a loop without a call: vectorized).
  llvm::BasicBlock* pre = b.GetInsertBlock();
  auto* scan = llvm::BasicBlock::Create(c, "oob.scan", f);
  auto* scanned = llvm::BasicBlock::Create(c, "oob.scanned", f);
  b.CreateBr(scan);
  b.SetInsertPoint(scan);
  llvm::PHINode* i = b.CreatePHI(i64t, 2);
  llvm::PHINode* any = b.CreatePHI(i64t, 2);
  i->addIncoming(i64(0), pre);
  any->addIncoming(i64(0), pre);
  llvm::Value* w = b.CreateAlignedLoad(i64t, b.CreateGEP(b.getInt8Ty(), log, b.CreateMul(i, i64(8))), llvm::Align(8));
  llvm::Value* anyNext = b.CreateOr(any, w);
  llvm::Value* iNext = b.CreateAdd(i, i64(1));
  i->addIncoming(iNext, scan);
  any->addIncoming(anyNext, scan);
  b.CreateCondBr(b.CreateICmpULT(iNext, i64(n)), scan, scanned);
  b.SetInsertPoint(scanned);
  auto* entries = llvm::BasicBlock::Create(c, "oob.entries", f);
  auto* done = llvm::BasicBlock::Create(c, "oob.done", f);
  b.CreateCondBr(b.CreateICmpNE(anyNext, i64(0)), entries, done, llvm::MDBuilder(c).createBranchWeights(1, 1u << 20));

  // Pass 2 (an access went out of bounds): each entry reported, with its invocation's ids in a context of its own
  // (passing `local` to a call would keep LLVM from keeping it in registers).
  b.SetInsertPoint(entries);
  llvm::Value* slots = b.CreateAlignedLoad(
      b.getPtrTy(), b.CreateConstGEP1_64(b.getInt8Ty(), local, offsetof(InvocationContext, resources)), llvm::Align(8));
  auto* loop = llvm::BasicBlock::Create(c, "oob.entry", f);
  auto* report = llvm::BasicBlock::Create(c, "oob.report", f);
  auto* latch = llvm::BasicBlock::Create(c, "oob.latch", f);
  b.CreateBr(loop);
  b.SetInsertPoint(loop);
  llvm::PHINode* k = b.CreatePHI(i64t, 2);
  k->addIncoming(i64(0), entries);
  llvm::Value* word =
      b.CreateAlignedLoad(i64t, b.CreateGEP(b.getInt8Ty(), log, b.CreateMul(k, i64(8))), llvm::Align(8));
  b.CreateCondBr(b.CreateICmpNE(word, i64(0)), report, latch);
  b.SetInsertPoint(report);
  llvm::Value* siteIndex = b.CreateSub(b.CreateAnd(word, i64(0xffff)), i64(1));
  llvm::Value* site =
      b.CreateAlignedLoad(b.getPtrTy(), b.CreateGEP(siteArray, siteTable, {i64(0), siteIndex}), llvm::Align(8));
  llvm::Value* resource = b.CreateAlignedLoad(
      i32t, b.CreateGEP(resourceTable->getValueType(), resourceTable, {i64(0), siteIndex}), llvm::Align(4));
  llvm::Value* kind =
      b.CreateAlignedLoad(i32t, b.CreateGEP(kindTable->getValueType(), kindTable, {i64(0), siteIndex}), llvm::Align(4));
  llvm::Value* element = b.CreateAnd(b.CreateLShr(word, 16), i64(0xffff));
  llvm::Value* offset = b.CreateLShr(word, 32);
  // The range: the bound descriptor count for an index, else the element's range (0 past the bound ones).
  llvm::Value* slot =
      b.CreateGEP(b.getInt8Ty(), slots, b.CreateMul(b.CreateZExt(resource, i64t), i64(sizeof(ResourceSlot))));
  llvm::Value* records = b.CreateAlignedLoad(b.getPtrTy(), slot, llvm::Align(8));
  llvm::Value* count = b.CreateAlignedLoad(i64t, b.CreateConstGEP1_64(b.getInt8Ty(), slot, 8), llvm::Align(8));
  llvm::Value* inRange = b.CreateICmpULT(element, count);
  llvm::Value* record = b.CreateSelect(
      inRange, b.CreateGEP(b.getInt8Ty(), records, b.CreateMul(element, i64(sizeof(DescriptorRecord)))), zeros);
  llvm::Value* elementRange = b.CreateAlignedLoad(i64t, b.CreateConstGEP1_64(b.getInt8Ty(), record, 8), llvm::Align(8));
  llvm::Value* range =
      b.CreateSelect(b.CreateICmpEQ(kind, b.getInt32(abi::kAccessDescriptorIndex)), count, elementRange);
  // The invocation: local index k.
  llvm::Value* saved = ctxArg;
  ctxArg = ctx;
  ctxArg = reportContext(k, base);
  callOutOfBounds(site, offset, range, element);
  ctxArg = saved;
  b.CreateBr(latch);
  b.SetInsertPoint(latch);
  llvm::Value* kNext = b.CreateAdd(k, i64(1));
  k->addIncoming(kNext, latch);
  b.CreateCondBr(b.CreateICmpULT(kNext, i64(n)), loop, done);
  b.SetInsertPoint(done);
}

llvm::Value* Codegen::checkAddress(const Ptr& p, uint64_t bytes, uint32_t kind, llvm::Value* limitOk) {
  if (!ctxArg) return limitOk;
  llvm::Type* i64t = b.getInt64Ty();
  llvm::Type* ptrTy = b.getPtrTy();
  llvm::Function* fnc = b.GetInsertBlock()->getParent();
  auto* tableCall = llvm::dyn_cast_or_null<llvm::CallInst>(addressTable);
  if (!tableCall || tableCall->getFunction() != fnc) {
    // Once per function, at its top. The table is the same for the whole command: the call is marked as having no
    // side effects (it reads the thread's running job), so that LLVM hoists it out of vkrt_group's loop over the
    // invocations, where vkrt_main is inlined.
    auto* tf = llvm::cast<llvm::Function>(
        out.getOrInsertFunction("vkrt_address_table", llvm::FunctionType::get(ptrTy, {ptrTy}, false)).getCallee());
    tf->setDoesNotAccessMemory();
    tf->setDoesNotThrow();
    tf->setWillReturn();
    tf->addFnAttr(llvm::Attribute::Speculatable);
    llvm::IRBuilderBase::InsertPointGuard guard(b);
    b.SetInsertPoint(&*fnc->getEntryBlock().getFirstInsertionPt());
    tableCall = b.CreateCall(tf, {ctxArg});
    addressTable = tableCall;
  }
  // The access's cache: after vkrt_group's local context (groupLog: the code runs only there), else a slot of the
  // function (one per access: accesses to different buffers would evict each other's range).
  llvm::Value* cache = nullptr;
  if (groupLog) {
    cache = b.CreateConstGEP1_64(b.getInt8Ty(), ctxArg,
                                 sizeof(InvocationContext) + uint64_t(abi::kAddressCacheBytes) * addressCaches++);
  } else {
    llvm::IRBuilderBase::InsertPointGuard guard(b);
    b.SetInsertPoint(tableCall->getNextNode());
    auto* slot = b.CreateAlloca(i64t, i64(2));
    slot->setAlignment(llvm::Align(16));
    b.CreateMemSet(slot, b.getInt8(0), i64(abi::kAddressCacheBytes), llvm::MaybeAlign(16));
    cache = slot;
  }
  llvm::FunctionCallee f = out.getOrInsertFunction(
      "vkrt_check_address", llvm::FunctionType::get(b.getInt32Ty(), {ptrTy, ptrTy, ptrTy, i64t, i64t, ptrTy}, false));
  llvm::Value* address = b.CreateAdd(b.CreatePtrToInt(p.base, i64t), p.offset);
  auto call = [&] {
    llvm::Value* site = accessSiteFor(p, kind, bytes);
    return b.CreateICmpNE(b.CreateCall(f, {ctxArg, tableCall, site, address, i64(bytes), cache}), i32(0));
  };
  // Inside the cached range (the last access that passed): no call.
  auto cached = [&] {
    llvm::Value* lo = b.CreateAlignedLoad(i64t, cache, llvm::Align(8));
    llvm::Value* hi = b.CreateAlignedLoad(i64t, b.CreateConstGEP1_64(i64t, cache, 1), llvm::Align(8));
    llvm::Value* end = b.CreateAdd(address, i64(bytes));
    return b.CreateAnd(b.CreateAnd(b.CreateICmpUGE(address, lo), b.CreateICmpULE(end, hi)),
                       b.CreateICmpUGE(end, address));
  };
  // Code placed before a block's terminator cannot branch: every test, the call included.
  if (b.GetInsertBlock()->getTerminator()) {
    llvm::Value* ok = b.CreateOr(cached(), call());
    return limitOk ? b.CreateAnd(limitOk, ok) : ok;
  }
  llvm::BasicBlock* from = b.GetInsertBlock();
  auto* test = llvm::BasicBlock::Create(c, "address.cached", fnc);
  auto* slow = llvm::BasicBlock::Create(c, "address.check", fnc);
  auto* join = llvm::BasicBlock::Create(c, "address.checked", fnc);
  if (limitOk) {
    b.CreateCondBr(limitOk, test, join);
  } else {
    b.CreateBr(test);
  }
  b.SetInsertPoint(test);
  b.CreateCondBr(cached(), join, slow, llvm::MDBuilder(c).createBranchWeights(1u << 20, 1));
  b.SetInsertPoint(slow);
  llvm::Value* ok = call();
  llvm::BasicBlock* slowEnd = b.GetInsertBlock();
  b.CreateBr(join);
  b.SetInsertPoint(join);
  llvm::PHINode* phi = b.CreatePHI(b.getInt1Ty(), 3);
  if (limitOk) phi->addIncoming(b.getFalse(), from);
  phi->addIncoming(b.getTrue(), test);
  phi->addIncoming(ok, slowEnd);
  return phi;
}

namespace {

// The image variable an image value (or, with isPointer, a pointer to an image) comes from: its Ptr (resource,
// variable and descriptor array index), found through the OpLoad and the OpSampledImage / OpImage / OpCopyObject
// that made the value. Null where it cannot be traced (the report then names no descriptor).
const Ptr* imageOrigin(Codegen& g, uint32_t id, bool isPointer) {
  for (int depth = 0; depth < 8 && id; ++depth) {
    if (isPointer) {
      auto it = g.ptrs.find(id);
      return it != g.ptrs.end() && it->second.resource >= 0 ? &it->second : nullptr;
    }
    const Instruction* def = g.m.def(id);
    if (!def) return nullptr;
    switch (def->op) {
      case spv::OpLoad:
        id = def->word(3);
        isPointer = true;
        break;
      case spv::OpSampledImage:
      case spv::OpImage:
      case spv::OpCopyObject: id = def->word(3); break;
      default: return nullptr;
    }
  }
  return nullptr;
}

}  // namespace

// The site of an image access: the origin's descriptor (set, binding, variable), and the array element it indexes.
static llvm::Value* imageSite(Codegen& g, uint32_t imageId, bool isPointer, uint32_t kind, llvm::Value** element) {
  Ptr site;
  const Ptr* origin = imageOrigin(g, imageId, isPointer);
  if (origin) {
    site.resource = origin->resource;
    site.variable = origin->variable;
  }
  *element = origin && origin->descIndex ? g.b.CreateZExtOrTrunc(origin->descIndex, g.b.getInt64Ty()) : g.i64(0);
  return g.accessSiteFor(site, kind, 0);
}

void Codegen::checkImage(uint32_t imageId, bool isPointer, uint32_t kind, llvm::Value* record, llvm::Value* coords,
                         llvm::Value* level) {
  if (!(checks & abi::kCheckImage) || !ctxArg) return;
  llvm::Value* element = nullptr;
  llvm::Value* site = imageSite(*this, imageId, isPointer, kind, &element);
  llvm::Type* ptrTy = b.getPtrTy();
  llvm::FunctionCallee f = out.getOrInsertFunction(
      "vkrt_check_image",
      llvm::FunctionType::get(b.getVoidTy(), {ptrTy, ptrTy, ptrTy, ptrTy, b.getInt32Ty(), b.getInt64Ty()}, false));
  b.CreateCall(f, {ctxArg, site, record, coords, level ? level : i32(0), element});
}

void Codegen::checkTexelBuffer(uint32_t imageId, bool isPointer, uint32_t kind, llvm::Value* record,
                               llvm::Value* index) {
  if (!(checks & abi::kCheckImage) || !ctxArg) return;
  llvm::Value* element = nullptr;
  llvm::Value* site = imageSite(*this, imageId, isPointer, kind, &element);
  llvm::Type* ptrTy = b.getPtrTy();
  llvm::FunctionCallee f = out.getOrInsertFunction(
      "vkrt_check_texel_buffer",
      llvm::FunctionType::get(b.getVoidTy(), {ptrTy, ptrTy, ptrTy, b.getInt64Ty(), b.getInt64Ty()}, false));
  b.CreateCall(f, {ctxArg, site, record, index, element});
}

}  // namespace vkrt::spirv
