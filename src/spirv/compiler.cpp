// SPIR-V -> LLVM IR: types, layout, constants, functions and the per-instruction dispatch to the op families.
#include <llvm/IR/Constants.h>
#include <llvm/IR/Function.h>

#include <cstdarg>
#include <cstdio>

#include "spirv/codegen.hpp"
#include "spirv/shader_debug.hpp"
#include "spirv/spmd.hpp"

namespace vkrt::spirv {

bool Codegen::unsupported(const Instruction& in, const char* detail) {
  char buf[256];
  std::snprintf(buf, sizeof buf, "unsupported instruction %s at word %u%s%s", opName(in.op).c_str(), in.offset,
                detail ? ": " : "", detail ? detail : "");
  error = buf;
  return false;
}

bool Codegen::fail(const Instruction& in, const char* what) {
  char buf[256];
  std::snprintf(buf, sizeof buf, "%s (%s at word %u)", what, opName(in.op).c_str(), in.offset);
  error = buf;
  return false;
}

// ---------------------------------------------------------------------------------------------- types

const Type& Codegen::spvType(uint32_t id) const {
  static const Type none;
  const Type* t = m.type(id);
  return t ? *t : none;
}

llvm::Type* Codegen::type(uint32_t id) {
  auto it = typeCache.find(id);
  if (it != typeCache.end()) return it->second;
  const Type& t = spvType(id);
  llvm::Type* r = nullptr;
  switch (t.kind) {
    case Type::Void: r = b.getVoidTy(); break;
    case Type::Bool: r = b.getInt1Ty(); break;
    case Type::Int: r = b.getIntNTy(t.width); break;
    case Type::Float:
      r = t.width == 16 ? b.getHalfTy() : t.width == 64 ? b.getDoubleTy() : t.width == 32 ? b.getFloatTy() : nullptr;
      break;
    case Type::Vector: {
      llvm::Type* e = type(t.element);
      if (e) r = llvm::FixedVectorType::get(e, t.count);
      break;
    }
    case Type::Matrix:
    case Type::Array: {
      llvm::Type* e = type(t.element);
      if (e && t.count) r = llvm::ArrayType::get(e, t.count);  // 0: a length never folded to a constant
      break;
    }
    case Type::Struct: {
      std::vector<llvm::Type*> members;
      for (uint32_t mt : t.members) {
        llvm::Type* e = type(mt);
        if (!e) return nullptr;
        members.push_back(e);
      }
      r = llvm::StructType::get(c, members);
      break;
    }
    case Type::Pointer: r = b.getPtrTy(); break;
    case Type::Opaque:
      if (isImageLike(id))
        r = imageValueType();
      else if (isAccelerationStructure(id))
        r = b.getInt64Ty();  // its device address
      else if (isRayQuery(id))
        r = b.getPtrTy();  // a bare ray query value: its variable's address (ray_query.cpp)
      break;
    default: break;
  }
  typeCache[id] = r;
  return r;
}

uint32_t Codegen::scalarType(uint32_t id) const {
  const Type& t = spvType(id);
  return t.kind == Type::Vector ? t.element : id;
}

bool Codegen::isFloat(uint32_t typeId) const { return spvType(scalarType(typeId)).kind == Type::Float; }
bool Codegen::isSignedInt(uint32_t typeId) const {
  const Type& t = spvType(scalarType(typeId));
  return t.kind == Type::Int && t.isSigned;
}
uint32_t Codegen::componentCount(uint32_t typeId) const {
  const Type& t = spvType(typeId);
  return t.kind == Type::Vector ? t.count : 1;
}

static uint64_t roundUp(uint64_t v, uint64_t a) { return a ? (v + a - 1) / a * a : v; }

uint64_t Codegen::layoutAlign(uint32_t id) const {
  if (isRayQuery(id)) return 16;
  const Type& t = spvType(id);
  switch (t.kind) {
    case Type::Bool: return 4;
    case Type::Pointer: return t.storage == spv::StorageClassPhysicalStorageBuffer ? 8 : 1;
    case Type::Int:
    case Type::Float: return t.width / 8;
    case Type::Vector:
    case Type::Matrix:
    case Type::Array:
    case Type::RuntimeArray: return layoutAlign(t.element);
    case Type::Struct: {
      uint64_t a = 1;
      for (uint32_t mt : t.members) a = std::max(a, layoutAlign(mt));
      return a;
    }
    default: return 1;
  }
}

uint32_t Codegen::naturalMatrixStride(uint32_t matrixTypeId) const {
  const Type& t = spvType(matrixTypeId);
  return uint32_t(layoutSize(t.element, 0, false));
}

uint64_t Codegen::layoutSize(uint32_t id, uint32_t matrixStride, bool rowMajor) const {
  if (isRayQuery(id)) return abi::kRayQueryStateBytes;
  const Type& t = spvType(id);
  switch (t.kind) {
    case Type::Bool: return 4;
    case Type::Pointer: return t.storage == spv::StorageClassPhysicalStorageBuffer ? 8 : 0;  // a device address
    case Type::Int:
    case Type::Float: return t.width / 8;
    case Type::Vector: return t.count * layoutSize(t.element, 0, false);
    case Type::Matrix: {
      uint64_t stride = matrixStride ? matrixStride : naturalMatrixStride(id);
      return (rowMajor ? spvType(t.element).count : t.count) * stride;
    }
    case Type::Array: return t.count * arrayStride(id, matrixStride, rowMajor);
    case Type::RuntimeArray: return 0;
    case Type::Struct: {
      uint64_t size = 0;
      for (uint32_t i = 0; i < t.members.size(); ++i) {
        const Decorations& d = m.memberDecor(id, i);
        uint64_t end = memberOffset(id, i) +
                       layoutSize(t.members[i], d.matrixStride > 0 ? uint32_t(d.matrixStride) : 0, d.rowMajor);
        size = std::max(size, end);
      }
      return roundUp(size, layoutAlign(id));
    }
    default: return 0;
  }
}

uint64_t Codegen::arrayStride(uint32_t arrayTypeId, uint32_t matrixStride, bool rowMajor) const {
  const Decorations& d = m.decor(arrayTypeId);
  if (d.arrayStride > 0) return uint64_t(d.arrayStride);
  const Type& t = spvType(arrayTypeId);
  return roundUp(layoutSize(t.element, matrixStride, rowMajor), layoutAlign(t.element));
}

uint64_t Codegen::memberOffset(uint32_t structId, uint32_t member) const {
  const Decorations& d = m.memberDecor(structId, member);
  if (d.offset >= 0) return uint64_t(d.offset);
  const Type& t = spvType(structId);
  uint64_t off = 0;
  for (uint32_t i = 0; i < member && i < t.members.size(); ++i) {
    const Decorations& di = m.memberDecor(structId, i);
    off = roundUp(off, layoutAlign(t.members[i]));
    off += layoutSize(t.members[i], di.matrixStride > 0 ? uint32_t(di.matrixStride) : 0, di.rowMajor);
  }
  return member < t.members.size() ? roundUp(off, layoutAlign(t.members[member])) : off;
}

// ---------------------------------------------------------------------------------------------- values

llvm::Constant* Codegen::constant(uint32_t id) {
  const Constant* k = m.constant(id);
  if (!k) return nullptr;
  llvm::Type* ty = type(k->type);
  if (!ty) return nullptr;
  if (k->null) return llvm::Constant::getNullValue(ty);
  const Type& t = spvType(k->type);
  if (k->composite) {
    std::vector<llvm::Constant*> elems;
    for (uint32_t e : k->elements) {
      llvm::Constant* v = constant(e);
      const Instruction* d = v ? nullptr : m.def(e);
      if (d && d->op == spv::OpUndef) v = llvm::dyn_cast_or_null<llvm::Constant>(value(e));  // a zero
      if (!v) return nullptr;
      elems.push_back(v);
    }
    if (t.kind == Type::Vector) return llvm::ConstantVector::get(elems);
    if (t.kind == Type::Struct) return llvm::ConstantStruct::get(llvm::cast<llvm::StructType>(ty), elems);
    return llvm::ConstantArray::get(llvm::cast<llvm::ArrayType>(ty), elems);
  }
  if (k->words.empty()) return nullptr;
  uint64_t bits = k->words[0];
  if (k->words.size() > 1) bits |= uint64_t(k->words[1]) << 32;
  switch (t.kind) {
    case Type::Bool: return b.getInt1(bits != 0);
    case Type::Int:
      return llvm::ConstantInt::get(ty, llvm::APInt(t.width, t.width < 64 ? bits & ((1ull << t.width) - 1) : bits));
    case Type::Float: {
      const llvm::fltSemantics& sem = ty->getFltSemantics();
      return llvm::ConstantFP::get(
          c, llvm::APFloat(sem, llvm::APInt(t.width, t.width < 64 ? bits & ((1ull << t.width) - 1) : bits)));
    }
    default: return nullptr;
  }
}

llvm::Value* Codegen::value(uint32_t id) {
  auto it = values.find(id);
  if (it != values.end()) return it->second;
  if (llvm::Constant* k = constant(id)) {
    values[id] = k;
    return k;
  }
  const Instruction* in = m.def(id);
  if (in && in->op == spv::OpUndef) {
    // Undefined values read as zero: deterministic, and never poison.
    llvm::Type* ty = type(in->word(1));
    if (ty) return values[id] = llvm::Constant::getNullValue(ty);
  }
  if (in && in->op == spv::OpSpecConstantOp) return specConstantOp(*in);
  return nullptr;
}

// An OpSpecConstantOp that SPIRV-Tools' folding left (it does not fold every operation the SPIR-V specification
// allows there, e.g. shifts by an operand of another width): once specialization is frozen its operands are
// constants, so the operation it names is emitted like an instruction, and the builder folds it to a constant.
// A result that did not fold (none is expected) is not kept, so every use emits it where it stands.
llvm::Value* Codegen::specConstantOp(const Instruction& in) {
  if (in.count < 4 || !b.GetInsertBlock()) return nullptr;
  std::vector<uint32_t> words = {((in.count - 1) << 16) | in.word(3), in.word(1), in.word(2)};
  words.insert(words.end(), in.words + 4, in.words + in.count);
  const Instruction op{spv::Op(in.word(3)), in.offset, in.count - 1, words.data()};
  bool ok = true;
  if (!(arithmetic(op, ok) || composite(op, ok)) || !ok) return nullptr;
  auto it = values.find(in.word(2));
  if (it == values.end()) return nullptr;
  llvm::Value* v = it->second;
  if (!llvm::isa<llvm::Constant>(v)) values.erase(it);
  return v;
}

llvm::Value* Codegen::splat(llvm::Value* scalar, llvm::Type* like) {
  if (auto* vt = llvm::dyn_cast<llvm::FixedVectorType>(like)) return b.CreateVectorSplat(vt->getNumElements(), scalar);
  return scalar;
}

// ---------------------------------------------------------------------------------------------- functions

bool Codegen::declareFunctions() {
  for (const Instruction& in : m.instructions) {
    if (in.op != spv::OpFunction) continue;
    const Type& ft = spvType(in.word(4));
    std::vector<llvm::Type*> params = {b.getPtrTy(), b.getPtrTy()};
    for (uint32_t p : ft.members) {
      if (spvType(p).kind == Type::Pointer) {
        params.insert(params.end(), {b.getPtrTy(), b.getInt64Ty(), b.getInt64Ty()});
      } else {
        llvm::Type* t = type(p);
        if (!t) return fail(in, "a function parameter has a type the compiler does not support");
        params.push_back(t);
      }
    }
    llvm::Type* ret = spvType(ft.element).kind == Type::Pointer ? nullptr : type(ft.element);
    if (!ret) return unsupported(in, "function return type");
    auto* f = llvm::Function::Create(llvm::FunctionType::get(ret, params, false), llvm::Function::InternalLinkage,
                                     "spv_" + std::to_string(in.word(2)), out);
    f->getArg(0)->addAttr(llvm::Attribute::get(c, "vkrt-ctx"));  // cancellation_poll.cpp reads it
    functions[in.word(2)] = f;
  }
  return true;
}

bool Codegen::emitFunction(size_t first, size_t* next) {
  const Instruction& fin = m.instructions[first];
  fn = functions[fin.word(2)];
  auto arg = fn->arg_begin();
  ctxArg = &*arg++;
  privArg = &*arg++;
  // Pointers to module-scope variables are rematerialized in every function.
  for (auto& [id, g] : globals) ptrs.erase(id);
  allocaBlock = llvm::BasicBlock::Create(c, "entry", fn);
  b.SetInsertPoint(allocaBlock);
  size_t i = first + 1;
  for (; i < m.instructions.size() && m.instructions[i].op == spv::OpFunctionParameter; ++i) {
    const Instruction& p = m.instructions[i];
    const Type& pt = spvType(p.word(1));
    if (pt.kind == Type::Pointer) {
      Ptr ptr;
      ptr.base = &*arg++;
      ptr.offset = &*arg++;
      ptr.limit = &*arg++;
      ptr.type = pt.element;
      ptr.storage = pt.storage;
      ptrs[p.word(2)] = ptr;
    } else {
      set(p.word(2), &*arg++);
    }
  }
  // Blocks first, so that branches can refer forward.
  bool firstBlock = true;
  for (size_t j = i; j < m.instructions.size() && m.instructions[j].op != spv::OpFunctionEnd; ++j) {
    if (m.instructions[j].op != spv::OpLabel) continue;
    uint32_t label = m.instructions[j].word(1);
    auto* bb = llvm::BasicBlock::Create(c, "l" + std::to_string(label), fn);
    blocks[label] = blockExits[label] = bb;
    if (firstBlock) {
      b.CreateBr(bb);
      firstBlock = false;
    }
  }
  if (firstBlock) return fail(fin, "function without blocks");
  uint32_t currentLabel = 0;
  for (; i < m.instructions.size(); ++i) {
    const Instruction& in = m.instructions[i];
    if (in.op == spv::OpFunctionEnd) break;
    switch (in.op) {
      case spv::OpLabel:
        currentLabel = in.word(1);
        b.SetInsertPoint(blocks[currentLabel]);
        setLine(nullptr);  // an OpLine holds to the end of its block (SPIR-V 2.4, "Debug Instructions")
        continue;
      case spv::OpLine: setLine(&in); continue;
      case spv::OpNoLine: setLine(nullptr); continue;
      case spv::OpUndef:  // materialized where it is used (value() reads it as zero)
      case spv::OpNop:
      case spv::OpSelectionMerge:
      case spv::OpLoopMerge:
      case spv::OpMemoryModel: continue;
      default: break;
    }
    bool ok = true;
    currentInstruction = &in;
    // An image or texel buffer access may alias buffer memory: combined adds (ray tracing stages) are written first.
    if (opSupport(in.op).family == OpFamily::Image && in.op != spv::OpSampledImage && in.op != spv::OpImage &&
        in.op != spv::OpImageTexelPointer)
      flushPendingAdds();
    if (arithmetic(in, ok) || composite(in, ok) || controlFlow(in, ok) || memory(in, ok) || extInst(in, ok) ||
        image(in, ok) || rayTracing(in, ok) || graphics(in, ok)) {
      if (!ok) return false;
      if (currentLabel) blockExits[currentLabel] = b.GetInsertBlock();
      continue;
    }
    return unsupported(in);
  }
  *next = i + 1;
  return true;
}

bool Codegen::run(const EntryPoint& ep) {
  model = ep.model;
  combining = combining && isRayTracing();
  info.ray.checksPendingAdds = combining;
  checks = shaderChecks();  // VKRT_SHADER_CHECKS (part of the cache key)
  for (const auto& [id, name] : m.extInstImports) {
    if (name == "GLSL.std.450") glslSet = id;
    if (name == "NonSemantic.DebugPrintf") debugPrintfSet = id;
  }
  zeros = new llvm::GlobalVariable(
      out, llvm::ArrayType::get(b.getInt8Ty(), kSinkBytes), true, llvm::GlobalValue::PrivateLinkage,
      llvm::ConstantAggregateZero::get(llvm::ArrayType::get(b.getInt8Ty(), kSinkBytes)), "vkrt_zeros");
  zeros->setAlignment(llvm::Align(16));
  if (isGraphics() && !graphicsModes(ep)) return false;
  // Compute shaders without a workgroup barrier run in vkrt_group (emitGroupEntry): their out-of-bounds accesses
  // go to its log (Codegen::outOfBoundsBlock says why).
  if (model == spv::ExecutionModelGLCompute) {
    groupLog = true;
    for (const Instruction& in : m.instructions) {
      uint64_t scope = 0;
      if (in.op == spv::OpControlBarrier && m.constantU64(in.word(1), &scope) && scope == spv::ScopeWorkgroup)
        groupLog = false;
    }
  }
  if (!declareGlobals() || !declareFunctions()) return false;
  for (size_t i = 0; i < m.instructions.size();) {
    if (m.instructions[i].op != spv::OpFunction) {
      ++i;
      continue;
    }
    if (!emitFunction(i, &i)) return false;
  }
  finishPhis();
  // The entry wrapper: the invocation's private variables, their initializers, then the entry function.
  auto* main = llvm::Function::Create(llvm::FunctionType::get(b.getVoidTy(), {b.getPtrTy()}, false),
                                      llvm::Function::ExternalLinkage, "vkrt_main", out);
  fn = main;
  ctxArg = main->getArg(0);
  main->getArg(0)->addAttr(llvm::Attribute::get(c, "vkrt-ctx"));
  allocaBlock = llvm::BasicBlock::Create(c, "entry", main);
  b.SetInsertPoint(allocaBlock);
  auto* priv = b.CreateAlloca(b.getInt8Ty(), i64(std::max<uint64_t>(privateSize, 16)));
  priv->setAlignment(llvm::Align(16));
  privArg = priv;
  b.CreateMemSet(priv, b.getInt8(0), i64(std::max<uint64_t>(privateSize, 16)), llvm::MaybeAlign(16));
  for (auto [var, init] : privateInits) {
    ptrs.erase(var);
    Ptr p;
    if (!variablePtr(var, &p)) return false;
    llvm::Value* v = value(init);
    if (v) store(p, v);
  }
  auto it = functions.find(ep.function);
  if (it == functions.end()) {
    error = "the entry point's function is missing";
    return false;
  }
  if (it->second->arg_size() != 2) {
    error = "the entry point's function takes parameters";
    return false;
  }
  if (isGraphics()) copyInterface(true);
  b.CreateCall(it->second, {ctxArg, privArg});
  if (isGraphics()) copyInterface(false);
  b.CreateRetVoid();
  // Compute shaders: the SPMD form of vkrt_group where it supports the shader (spmd.cpp; with barriers, one batch of
  // the workgroup per call, the batches run as fibers), else, without barriers, the loop; with barriers and no SPMD
  // form, vkrt_main per invocation (as fibers). (The SPMD form reports out-of-bounds accesses lane by lane:
  // Codegen::reportFailingLanes.)
  if (!isRayTracing() && !isGraphics() && !emitSpmdGroup(*this, ep, main) && !info.usesBarrier) emitGroupEntry(main);
  if (isFragment()) emitSpmdQuad(*this, ep, main);  // the quad in one call where the SPMD path supports the shader
  if (model == spv::ExecutionModelRayGenerationKHR) emitSpmdRaygen(*this, ep, main);  // launch ids in batches
  if (groupLog && info.usesBarrier) {
    error = "internal compiler error: the out-of-bounds log assumed vkrt_group";
    return false;
  }
  return true;
}

// The local context of vkrt_group (see emitGroupEntry), built where the builder stands: returns it.
llvm::Value* Codegen::groupContext(llvm::Value* ctx) {
  // VKRT_SHADER_CHECKS=bda: the checked accesses' caches follow the context (Codegen::addressCaches), empty at first.
  const uint64_t caches = uint64_t(abi::kAddressCacheBytes) * addressCaches;
  auto* local = b.CreateAlloca(b.getInt8Ty(), i64(sizeof(InvocationContext) + caches));
  local->setAlignment(llvm::Align(16));
  b.CreateMemCpy(local, llvm::MaybeAlign(16), ctx, llvm::MaybeAlign(8), i64(sizeof(InvocationContext)));
  if (caches)
    b.CreateMemSet(b.CreateConstGEP1_64(b.getInt8Ty(), local, sizeof(InvocationContext)), b.getInt8(0), i64(caches),
                   llvm::MaybeAlign(16));
  // The out-of-bounds log: a word per invocation (Codegen::outOfBounds), zeroed; `executor` points at it (compiled
  // code reads that field nowhere else; only executors of shaders with barriers use it, and they run no vkrt_group).
  if (!groupSites.empty()) {
    const uint64_t invocations = uint64_t(info.localSize[0]) * info.localSize[1] * info.localSize[2];
    auto* a = b.CreateAlloca(b.getInt8Ty(), i64(8 * invocations));
    a->setAlignment(llvm::Align(16));
    b.CreateMemSet(a, b.getInt8(0), i64(8 * invocations), llvm::MaybeAlign(16));
    b.CreateAlignedStore(a, b.CreateConstGEP1_64(b.getInt8Ty(), local, offsetof(InvocationContext, executor)),
                         llvm::Align(8));
  }
  auto field = [&](size_t offset, int i) { return b.CreateConstGEP1_64(b.getInt8Ty(), local, offset + 4 * i); };
  auto ctxPointer = [&](size_t offset) {
    return b.CreateAlignedLoad(b.getPtrTy(), b.CreateConstGEP1_64(b.getInt8Ty(), ctx, offset), llvm::Align(8));
  };
  // Push constants: kPushConstantBytes bytes.
  auto* push = b.CreateAlloca(b.getInt8Ty(), i64(kPushConstantBytes));
  push->setAlignment(llvm::Align(16));
  b.CreateMemCpy(push, llvm::MaybeAlign(16), ctxPointer(offsetof(InvocationContext, pushConstants)),
                 llvm::MaybeAlign(1), i64(kPushConstantBytes));
  b.CreateAlignedStore(push, field(offsetof(InvocationContext, pushConstants), 0), llvm::Align(8));
  // Resources: the slot table, and element 0 of each buffer binding that is not an array.
  if (size_t n = info.resources.size()) {
    llvm::Value* table = ctxPointer(offsetof(InvocationContext, resources));
    auto* slots = b.CreateAlloca(b.getInt8Ty(), i64(n * sizeof(ResourceSlot)));
    slots->setAlignment(llvm::Align(16));
    auto* records = b.CreateAlloca(b.getInt8Ty(), i64(n * sizeof(DescriptorRecord)));
    records->setAlignment(llvm::Align(alignof(DescriptorRecord)));
    for (size_t i = 0; i < n; ++i) {
      llvm::Value* from = b.CreateConstGEP1_64(b.getInt8Ty(), table, i * sizeof(ResourceSlot));
      llvm::Value* to = b.CreateConstGEP1_64(b.getInt8Ty(), slots, i * sizeof(ResourceSlot));
      llvm::Value* rec = b.CreateAlignedLoad(b.getPtrTy(), from, llvm::Align(8));
      llvm::Value* count =
          b.CreateAlignedLoad(b.getInt64Ty(), b.CreateConstGEP1_64(b.getInt8Ty(), from, 8), llvm::Align(8));
      const ResourceBinding& r = info.resources[i];
      if (r.kind == ResourceBinding::Buffer && r.arraySize == 1) {
        llvm::Value* bound = b.CreateICmpNE(count, i64(0));
        llvm::Value* copy = b.CreateConstGEP1_64(b.getInt8Ty(), records, i * sizeof(DescriptorRecord));
        b.CreateMemCpy(copy, llvm::MaybeAlign(alignof(DescriptorRecord)), b.CreateSelect(bound, rec, zeros),
                       llvm::MaybeAlign(8), i64(sizeof(DescriptorRecord)));
        rec = copy;
        count = b.CreateZExt(bound, b.getInt64Ty());
      }
      b.CreateAlignedStore(rec, to, llvm::Align(8));
      b.CreateAlignedStore(count, b.CreateConstGEP1_64(b.getInt8Ty(), to, 8), llvm::Align(8));
    }
    b.CreateAlignedStore(slots, field(offsetof(InvocationContext, resources), 0), llvm::Align(8));
  }
  return local;
}

// vkrt_group(ctx): the whole workgroup in one call, for shaders without barriers (the invocations need not
// interleave). It copies the context into a local one, then loops over the local ids (x fastest), setting the
// built-ins and running vkrt_main's body, inlined: LLVM then keeps the built-ins in registers and may vectorize
// the loop.
//
// The local context also points to local copies of what the shader reads through it that cannot change during
// the dispatch: the push constants, the resource table and, for buffer bindings that are not arrays, their
// descriptor record (a null record where nothing is bound, with a count of 0, as the shader code expects).
// Their loads then read memory LLVM knows it may read anywhere (allocas), so that it can hoist them out of
// the loop even where the shader reads them under a condition (an `if` around the buffer accesses), and
// forward them as values; reading the application's descriptor memory itself would have to stay inside.
void Codegen::emitGroupEntry(llvm::Function* main) {
  // Only vkrt_group is called then: vkrt_main, internal, is compiled once (inlined) and not kept on its own.
  main->setLinkage(llvm::Function::InternalLinkage);
  main->addFnAttr(llvm::Attribute::AlwaysInline);
  auto* group = llvm::Function::Create(llvm::FunctionType::get(b.getVoidTy(), {b.getPtrTy()}, false),
                                       llvm::Function::ExternalLinkage, "vkrt_group", out);
  llvm::Value* ctx = group->getArg(0);
  group->getArg(0)->addAttr(llvm::Attribute::get(c, "vkrt-ctx"));
  auto* entry = llvm::BasicBlock::Create(c, "entry", group);
  b.SetInsertPoint(entry);
  llvm::Value* local = groupContext(ctx);
  auto field = [&](size_t offset, int i) { return b.CreateConstGEP1_64(b.getInt8Ty(), local, offset + 4 * i); };
  llvm::Value* log =
      groupSites.empty()
          ? nullptr
          : b.CreateAlignedLoad(b.getPtrTy(), field(offsetof(InvocationContext, executor), 0), llvm::Align(8));
  llvm::Value* base[3];
  for (int i = 0; i < 3; ++i) {
    llvm::Value* wg =
        b.CreateAlignedLoad(b.getInt32Ty(), field(offsetof(InvocationContext, workgroupId), i), llvm::Align(4));
    base[i] = b.CreateMul(wg, b.getInt32(info.localSize[i]));
  }
  // Three nested counted loops: z outermost, x innermost.
  llvm::BasicBlock* preheader = entry;
  llvm::BasicBlock* headers[3];
  llvm::PHINode* ids[3];
  for (int i = 2; i >= 0; --i) {
    headers[i] = llvm::BasicBlock::Create(c, std::string("loop") + char('x' + i), group);
    b.CreateBr(headers[i]);
    b.SetInsertPoint(headers[i]);
    ids[i] = b.CreatePHI(b.getInt32Ty(), 2);
    ids[i]->addIncoming(b.getInt32(0), preheader);
    preheader = headers[i];
  }
  for (int i = 0; i < 3; ++i) {
    b.CreateAlignedStore(ids[i], field(offsetof(InvocationContext, localId), i), llvm::Align(4));
    b.CreateAlignedStore(b.CreateAdd(base[i], ids[i]), field(offsetof(InvocationContext, globalId), i), llvm::Align(4));
  }
  llvm::Value* index = b.CreateAdd(b.CreateMul(b.CreateAdd(b.CreateMul(ids[2], b.getInt32(info.localSize[1])), ids[1]),
                                               b.getInt32(info.localSize[0])),
                                   ids[0]);
  b.CreateAlignedStore(index, field(offsetof(InvocationContext, localIndex), 0), llvm::Align(4));
  b.CreateCall(main, {local});
  // Latches, innermost first: each increments its id and either repeats or falls through to the outer latch.
  for (int i = 0; i < 3; ++i) {
    llvm::Value* next = b.CreateAdd(ids[i], b.getInt32(1));
    llvm::BasicBlock* latch = b.GetInsertBlock();
    ids[i]->addIncoming(next, latch);
    auto* exit = llvm::BasicBlock::Create(c, std::string("done") + char('x' + i), group);
    b.CreateCondBr(b.CreateICmpULT(next, b.getInt32(info.localSize[i])), headers[i], exit);
    b.SetInsertPoint(exit);
  }
  if (log) reportGroupLog(ctx, local, log, base);
  b.CreateRetVoid();
}

}  // namespace vkrt::spirv
