// SPIR-V -> LLVM IR: the ray query instructions (SPV_KHR_ray_query, VK_KHR_ray_query), in every stage. A
// RayQueryKHR variable is abi::kRayQueryStateBytes of opaque state (zeroed where a Function variable is declared,
// as Private variables are); each instruction becomes a call through the invocation's RayQueryScope (abi.hpp,
// "ray queries") with the variable's address. Results of OpRayQueryGet*KHR come back through a 64-byte frame
// slot, read as the result type in the natural layout.
#include <llvm/IR/Constants.h>

#include "spirv/codegen.hpp"
#include "spirv/newer_tokens.hpp"

namespace vkrt::spirv {

using abi::RayQueryRuntime;
using abi::RayQueryScope;

bool Codegen::isRayQuery(uint32_t typeId) const {
  const Instruction* d = m.def(typeId);
  return d && d->op == spv::OpTypeRayQueryKHR;
}

namespace {

// A frame slot of `bytes` bytes, 16-byte aligned, allocated once at the top of the function.
llvm::Value* frameSlot(Codegen& g, uint64_t bytes) {
  llvm::IRBuilderBase::InsertPointGuard guard(g.b);
  g.b.SetInsertPoint(g.allocaBlock->getTerminator());
  auto* a = g.b.CreateAlloca(g.b.getInt8Ty(), g.i64(bytes));
  a->setAlignment(llvm::Align(16));
  return a;
}

// The scope (first argument of initialize) and the RayQueryRuntime function at `offset`.
llvm::Value* scope(Codegen& g) {
  return g.b.CreateAlignedLoad(
      g.b.getPtrTy(), g.b.CreateConstGEP1_64(g.b.getInt8Ty(), g.ctxArg, offsetof(abi::InvocationContext, rayQueries)),
      llvm::Align(8));
}
llvm::Value* queryFunction(Codegen& g, size_t offset) {
  llvm::Value* rt = g.b.CreateAlignedLoad(g.b.getPtrTy(), scope(g), llvm::Align(8));  // RayQueryScope::runtime
  return g.b.CreateAlignedLoad(g.b.getPtrTy(), g.b.CreateConstGEP1_64(g.b.getInt8Ty(), rt, offset), llvm::Align(8));
}

}  // namespace

// A bare ray query value (OpLoad of a ray query variable, a function parameter of OpTypeRayQueryKHR, as the CTS's
// ray_query.advanced.using_wrapper_function passes one) is the address of the state it was loaded from; OpStore of
// one into a variable copies the state.
bool Codegen::rayQueryValue(const Instruction& in, bool& ok) {
  if (in.op == spv::OpLoad) {
    if (!isRayQuery(in.word(1))) return false;
    Ptr& p = ptr(in.word(3));
    if (!p.base || p.slot >= 0) return (ok = fail(in, "the ray query operand is not a variable")), true;
    set(in.word(2), b.CreateGEP(b.getInt8Ty(), p.base, p.offset));
    return true;
  }
  if (in.op == spv::OpStore) {
    if (!isRayQuery(m.typeOf(in.word(2)))) return false;
    Ptr& p = ptr(in.word(1));
    llvm::Value* v = value(in.word(2));
    if (!p.base || p.slot >= 0 || !v) return (ok = fail(in, "the ray query operand is not a variable")), true;
    llvm::Value* dst = b.CreateGEP(b.getInt8Ty(), p.base, p.offset);
    // (memmove: a state stored onto itself, or onto an overlapping copy, stays whole.)
    b.CreateMemMove(dst, llvm::MaybeAlign(16), v, llvm::MaybeAlign(16), i64(abi::kRayQueryStateBytes));
    return true;
  }
  return false;
}

bool Codegen::rayQuery(const Instruction& in, bool& ok) {
  if (in.op == spv::OpTypeRayQueryKHR) return true;
  // Operand 1 (no result) or 3 (with a result) is the query variable.
  const bool hasResult =
      in.op == spv::OpRayQueryProceedKHR || in.op == spv::OpRayQueryGetIntersectionTypeKHR ||
      (in.op >= spv::OpRayQueryGetRayTMinKHR && in.op <= spv::OpRayQueryGetIntersectionWorldToObjectKHR) ||
      uint32_t(in.op) == kOpRayQueryGetIntersectionTriangleVertexPositionsKHR;
  const uint32_t queryId = in.word(hasResult ? 3 : 1);
  Ptr& p = ptr(queryId);
  if (!p.base || p.slot >= 0 || !isRayQuery(p.type))
    return (ok = fail(in, "the ray query operand is not a ray query")), true;
  llvm::Value* query = b.CreateGEP(b.getInt8Ty(), p.base, p.offset);
  llvm::Type* ptrTy = b.getPtrTy();
  switch (in.op) {
    case spv::OpRayQueryInitializeKHR: {
      llvm::Value* accel = value(in.word(2));
      llvm::Value* flags = value(in.word(3));
      llvm::Value* mask = value(in.word(4));
      llvm::Value* origin = value(in.word(5));
      llvm::Value* tMin = value(in.word(6));
      llvm::Value* direction = value(in.word(7));
      llvm::Value* tMax = value(in.word(8));
      if (!accel || !accel->getType()->isIntegerTy(64) || !flags || !flags->getType()->isIntegerTy(32) || !mask ||
          !mask->getType()->isIntegerTy(32) || !origin || !tMin || !direction || !tMax)
        return (ok = fail(in, "an operand has no value")), true;
      llvm::Value* args = frameSlot(*this, sizeof(TraceRayArgs));
      auto at = [&](size_t offset) { return b.CreateConstGEP1_64(b.getInt8Ty(), args, offset); };
      b.CreateAlignedStore(accel, at(offsetof(TraceRayArgs, accelerationStructure)), llvm::Align(8));
      b.CreateAlignedStore(flags, at(offsetof(TraceRayArgs, rayFlags)), llvm::Align(4));
      b.CreateAlignedStore(mask, at(offsetof(TraceRayArgs, cullMask)), llvm::Align(4));
      b.CreateAlignedStore(tMin, at(offsetof(TraceRayArgs, tMin)), llvm::Align(4));
      b.CreateAlignedStore(tMax, at(offsetof(TraceRayArgs, tMax)), llvm::Align(4));
      for (unsigned i = 0; i < 3; ++i) {
        b.CreateAlignedStore(b.CreateExtractElement(origin, uint64_t(i)), at(offsetof(TraceRayArgs, origin) + 4 * i),
                             llvm::Align(4));
        b.CreateAlignedStore(b.CreateExtractElement(direction, uint64_t(i)),
                             at(offsetof(TraceRayArgs, direction) + 4 * i), llvm::Align(4));
      }
      // Compute shaders: the invocation's context in `payload` (which ray queries do not use), where a dispatch's ray
      // tree scope reads the global invocation id (VKRT_RAY_TREE's compute ids, exec/ray_tree.hpp). In vkrt_group
      // the local context holds the running invocation's id.
      if (model == spv::ExecutionModelGLCompute)
        b.CreateAlignedStore(ctxArg, at(offsetof(TraceRayArgs, payload)), llvm::Align(8));
      auto* ty = llvm::FunctionType::get(b.getVoidTy(), {ptrTy, ptrTy, ptrTy}, false);
      b.CreateCall(ty, queryFunction(*this, offsetof(RayQueryRuntime, initialize)), {scope(*this), query, args});
      return true;
    }
    case spv::OpRayQueryTerminateKHR:
    case spv::OpRayQueryConfirmIntersectionKHR: {
      auto* ty = llvm::FunctionType::get(b.getVoidTy(), {ptrTy}, false);
      size_t off = in.op == spv::OpRayQueryTerminateKHR ? offsetof(RayQueryRuntime, terminate)
                                                        : offsetof(RayQueryRuntime, confirmIntersection);
      b.CreateCall(ty, queryFunction(*this, off), {query});
      return true;
    }
    case spv::OpRayQueryGenerateIntersectionKHR: {
      llvm::Value* t = value(in.word(2));
      if (!t || !t->getType()->isFloatTy()) return (ok = fail(in, "the hit t is not a 32-bit float")), true;
      auto* ty = llvm::FunctionType::get(b.getVoidTy(), {ptrTy, b.getFloatTy()}, false);
      b.CreateCall(ty, queryFunction(*this, offsetof(RayQueryRuntime, generateIntersection)), {query, t});
      return true;
    }
    case spv::OpRayQueryProceedKHR: {
      auto* ty = llvm::FunctionType::get(b.getInt32Ty(), {ptrTy}, false);
      llvm::Value* r = b.CreateCall(ty, queryFunction(*this, offsetof(RayQueryRuntime, proceed)), {query});
      set(in.word(2), b.CreateICmpNE(r, i32(0)));
      return true;
    }
    default: break;
  }
  // OpRayQueryGet*KHR and OpRayQueryGetIntersectionTypeKHR: the runtime writes the value, read as the result type.
  llvm::Value* committed = i32(0);
  if (in.count > 4) {
    committed = value(in.word(4));
    if (!committed || !committed->getType()->isIntegerTy(32))
      return (ok = fail(in, "the intersection operand is not a 32-bit integer")), true;
  }
  llvm::Value* out = frameSlot(*this, 64);
  auto* ty = llvm::FunctionType::get(b.getVoidTy(), {ptrTy, b.getInt32Ty(), b.getInt32Ty(), ptrTy}, false);
  b.CreateCall(ty, queryFunction(*this, offsetof(RayQueryRuntime, get)), {query, i32(uint32_t(in.op)), committed, out});
  const uint32_t resultType = in.word(1);
  const Type& rt = spvType(resultType);
  if (rt.kind == Type::Bool) {
    llvm::Value* v = b.CreateAlignedLoad(b.getInt32Ty(), out, llvm::Align(16));
    set(in.word(2), b.CreateICmpNE(v, i32(0)));
    return true;
  }
  Ptr r;
  r.base = out;
  r.offset = i64(0);
  r.limit = i64(64);
  r.type = resultType;
  llvm::Value* v = load(r);
  if (!v) return (ok = fail(in, "result type")), true;
  set(in.word(2), v);
  return true;
}

}  // namespace vkrt::spirv
