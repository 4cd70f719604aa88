// SPIR-V -> LLVM IR: the ray tracing instructions. OpTraceRayKHR, OpExecuteCallableKHR and
// OpReportIntersectionKHR become calls through the invocation's RayRuntime (abi.hpp); OpIgnoreIntersectionKHR and
// OpTerminateRayKHR set the invocation's status and return, and every caller up the (non-inlined) call tree
// returns too when it sees the status set.
//
// SPV_NV_ray_tracing (VK_NV_ray_tracing) shares the execution models, storage classes, built-ins (HitTNV is the
// hit's t, as RayTmaxKHR is in a hit shader), the acceleration structure type and OpReportIntersectionNV with the
// KHR extension; what differs: OpTraceNV and OpExecuteCallableNV name their payload or callable data by the
// Location of a RayPayloadNV / CallableDataNV variable (a constant id) instead of a pointer, and
// OpIgnoreIntersectionNV and OpTerminateRayNV are not block terminators (glslang follows them with the rest of
// the block): they end the invocation the same way, and what follows them in the block is unreachable.
#include <llvm/IR/Constants.h>
#include <llvm/IR/Intrinsics.h>
#include <llvm/IR/MDBuilder.h>

#include "spirv/codegen.hpp"
#include "spirv/newer_tokens.hpp"

namespace vkrt::spirv {

bool rayTracingCapability(uint32_t cap) {
  // RayTraversalPrimitiveCullingKHR only allows two ray flags, which the runtime reads; RayCullMaskKHR
  // (SPV_KHR_ray_cull_mask, VK_KHR_ray_tracing_maintenance1) only the CullMaskKHR built-in, which it fills; the
  // position fetch capabilities (newer_tokens.hpp) the HitTriangleVertexPositionsKHR built-in and
  // OpRayQueryGetIntersectionTriangleVertexPositionsKHR.
  return cap == spv::CapabilityRayTracingKHR || cap == spv::CapabilityRayTraversalPrimitiveCullingKHR ||
         cap == spv::CapabilityRayCullMaskKHR || cap == spv::CapabilityRayTracingNV ||
         cap == spv::CapabilityRayQueryKHR || cap == kCapabilityRayTracingPositionFetchKHR ||
         cap == kCapabilityRayQueryPositionFetchKHR;
}

llvm::Value* Codegen::rayRuntimeFunction(size_t offset) {
  llvm::Value* rt = b.CreateAlignedLoad(
      b.getPtrTy(), b.CreateConstGEP1_64(b.getInt8Ty(), ctxArg, offsetof(RayInvocation, runtime)), llvm::Align(8));
  return b.CreateAlignedLoad(b.getPtrTy(), b.CreateConstGEP1_64(b.getInt8Ty(), rt, offset), llvm::Align(8));
}

void Codegen::storeTraceRayArgs(llvm::Value* args, const std::function<llvm::Value*(uint32_t w, uint32_t k)>& operand,
                                llvm::Value* payloadBytes, llvm::Value* payload) {
  auto at = [&](size_t offset) { return b.CreateConstGEP1_64(b.getInt8Ty(), args, offset); };
  b.CreateAlignedStore(operand(1, 0), at(offsetof(TraceRayArgs, accelerationStructure)), llvm::Align(8));
  const size_t intFields[5] = {offsetof(TraceRayArgs, rayFlags), offsetof(TraceRayArgs, cullMask),
                               offsetof(TraceRayArgs, sbtOffset), offsetof(TraceRayArgs, sbtStride),
                               offsetof(TraceRayArgs, missIndex)};
  for (uint32_t i = 0; i < 5; ++i) b.CreateAlignedStore(operand(2 + i, 0), at(intFields[i]), llvm::Align(4));
  b.CreateAlignedStore(operand(8, 0), at(offsetof(TraceRayArgs, tMin)), llvm::Align(4));
  b.CreateAlignedStore(operand(10, 0), at(offsetof(TraceRayArgs, tMax)), llvm::Align(4));
  for (uint32_t k = 0; k < 3; ++k) {
    b.CreateAlignedStore(operand(7, k), at(offsetof(TraceRayArgs, origin) + 4 * k), llvm::Align(4));
    b.CreateAlignedStore(operand(9, k), at(offsetof(TraceRayArgs, direction) + 4 * k), llvm::Align(4));
  }
  b.CreateAlignedStore(payloadBytes, at(offsetof(TraceRayArgs, payloadBytes)), llvm::Align(4));
  b.CreateAlignedStore(payload, at(offsetof(TraceRayArgs, payload)), llvm::Align(8));
}

bool Codegen::isRayTracing() const {
  switch (model) {
    case spv::ExecutionModelRayGenerationKHR:
    case spv::ExecutionModelIntersectionKHR:
    case spv::ExecutionModelAnyHitKHR:
    case spv::ExecutionModelClosestHitKHR:
    case spv::ExecutionModelMissKHR:
    case spv::ExecutionModelCallableKHR: return true;
    default: return false;
  }
}

bool Codegen::isAccelerationStructure(uint32_t typeId) const {
  const Instruction* d = m.def(typeId);
  return d && d->op == spv::OpTypeAccelerationStructureKHR;
}

void Codegen::returnFromFunction() {
  llvm::Type* rt = fn->getReturnType();
  if (rt->isVoidTy()) {
    b.CreateRetVoid();
  } else {
    b.CreateRet(llvm::Constant::getNullValue(rt));
  }
}

namespace {

llvm::Value* ctxAt(Codegen& g, size_t offset) { return g.b.CreateConstGEP1_64(g.b.getInt8Ty(), g.ctxArg, offset); }

// A payload or callable data operand: the variable's address and its bytes.
bool blockOperand(Codegen& g, const Instruction& in, uint32_t id, llvm::Value** address, llvm::Value** bytes) {
  Ptr& p = g.ptr(id);
  if (!p.base || p.slot >= 0) return g.fail(in, "the payload or callable data operand is not a variable");
  *address = g.b.CreateGEP(g.b.getInt8Ty(), p.base, p.offset);
  *bytes = g.b.CreateSelect(g.b.CreateICmpUGT(p.limit, p.offset), g.b.CreateSub(p.limit, p.offset), g.i64(0));
  return true;
}

// The payload or callable data operand of OpTraceNV / OpExecuteCallableNV: a constant that is the Location of a
// module-scope variable of `storage` (SPV_NV_ray_tracing). Returns its id, or 0.
uint32_t variableAtLocation(Codegen& g, uint32_t constantId, spv::StorageClass storage) {
  uint64_t location = 0;
  if (!g.m.constantU64(constantId, &location)) return 0;
  for (const auto& [id, global] : g.globals) {
    if (global.storage == storage && g.m.decor(id).location == int64_t(location)) return id;
  }
  return 0;
}

// A 32-bit scalar operand.
llvm::Value* scalar32(Codegen& g, uint32_t id) {
  llvm::Value* v = g.value(id);
  return v && v->getType()->isIntegerTy(32) ? v : nullptr;
}

}  // namespace

// "Indexing Rules" (Shader Binding Table): all data a launch accesses must lie less than the region's size from
// its start. The record's bytes past the region (up to the stride, in the application's memory) are still read,
// as GPUs read them, but such a read is told to the runtime, which reports it once per launch and record. One
// comparison per read with a field the invocation keeps (invariant); the call is on a cold branch.
void Codegen::checkShaderRecordRead(const Ptr& p, uint64_t bytes) {
  auto* regionLoad = b.CreateAlignedLoad(b.getInt64Ty(), ctxAt(*this, offsetof(RayInvocation, shaderRecordRegionBytes)),
                                         llvm::Align(8));
  regionLoad->setMetadata(llvm::LLVMContext::MD_invariant_load, llvm::MDNode::get(c, {}));
  // offset + bytes <= region, without overflow (as inBounds).
  llvm::Value* end = b.CreateBinaryIntrinsic(llvm::Intrinsic::usub_sat, regionLoad, i64(bytes ? bytes - 1 : 0));
  llvm::Value* inside = b.CreateICmpULT(p.offset, end);
  auto* outside = llvm::BasicBlock::Create(c, "record.outside", fn);
  auto* join = llvm::BasicBlock::Create(c, "record.checked", fn);
  b.CreateCondBr(inside, join, outside, llvm::MDBuilder(c).createBranchWeights(1u << 20, 1));
  b.SetInsertPoint(outside);
  llvm::FunctionType* ty =
      llvm::FunctionType::get(b.getVoidTy(), {b.getPtrTy(), b.getInt64Ty(), b.getInt64Ty()}, false);
  b.CreateCall(ty, rayRuntimeFunction(offsetof(RayRuntime, shaderRecordOutsideRegion)), {ctxArg, p.offset, i64(bytes)});
  b.CreateBr(join);
  b.SetInsertPoint(join);
}

void Codegen::returnIfStopped() {
  llvm::Value* stop = nullptr;
  if (model == spv::ExecutionModelFragment) {
    // A callee killed the fragment (OpKill / OpTerminateInvocation; a demoted one goes on).
    llvm::Value* status =
        b.CreateAlignedLoad(b.getInt32Ty(), ctxAt(*this, offsetof(abi::GraphicsInvocation, status)), llvm::Align(4));
    stop = b.CreateICmpEQ(status, i32(abi::kFragmentKilled));
  } else {
    if (model != spv::ExecutionModelAnyHitKHR && model != spv::ExecutionModelIntersectionKHR) return;
    llvm::Value* status =
        b.CreateAlignedLoad(b.getInt32Ty(), ctxAt(*this, offsetof(RayInvocation, status)), llvm::Align(4));
    stop = b.CreateICmpNE(status, i32(0));
  }
  auto* stopped = llvm::BasicBlock::Create(c, "stopped", fn);
  auto* resume = llvm::BasicBlock::Create(c, "resume", fn);
  b.CreateCondBr(stop, stopped, resume);
  b.SetInsertPoint(stopped);
  returnFromFunction();
  b.SetInsertPoint(resume);
}

bool Codegen::rayTracing(const Instruction& in, bool& ok) {
  if (!rayTracingOp(in.op) || in.op == spv::OpTypeAccelerationStructureKHR) return false;
  if (rayQueryOp(in.op)) return rayQuery(in, ok);  // every stage
  // (OpConvertUToAccelerationStructureKHR feeds ray queries too.)
  if (!isRayTracing() && in.op != spv::OpConvertUToAccelerationStructureKHR)
    return (ok = unsupported(in, "ray tracing instruction outside a ray tracing stage")), true;
  switch (in.op) {
    case spv::OpConvertUToAccelerationStructureKHR: {
      // A 64-bit address, or two 32-bit halves (uvec2: low word first).
      llvm::Value* v = value(in.word(3));
      if (!v) return (ok = fail(in, "operand has no value")), true;
      if (v->getType()->isVectorTy()) v = b.CreateBitCast(v, b.getInt64Ty());
      if (!v->getType()->isIntegerTy(64))
        return (ok = fail(in, "operand is neither a 64-bit integer nor a uvec2")), true;
      set(in.word(2), v);
      return true;
    }
    case spv::OpTraceRayKHR:
    case spv::OpTraceNV: {
      llvm::Value* accel = value(in.word(1));
      llvm::Value* ints[5];
      for (int i = 0; i < 5; ++i) ints[i] = scalar32(*this, in.word(2 + i));
      llvm::Value* origin = value(in.word(7));
      llvm::Value* tMin = value(in.word(8));
      llvm::Value* direction = value(in.word(9));
      llvm::Value* tMax = value(in.word(10));
      llvm::Value *payload = nullptr, *payloadBytes = nullptr;
      if (!accel || !accel->getType()->isIntegerTy(64) || !ints[0] || !ints[1] || !ints[2] || !ints[3] || !ints[4] ||
          !origin || !tMin || !direction || !tMax)
        return (ok = fail(in, "an operand has no value")), true;
      uint32_t payloadVar = in.word(11);
      if (in.op == spv::OpTraceNV) {
        payloadVar = variableAtLocation(*this, payloadVar, spv::StorageClassRayPayloadNV);
        if (!payloadVar) return (ok = fail(in, "no RayPayloadNV variable has the payload's location")), true;
      }
      if (!blockOperand(*this, in, payloadVar, &payload, &payloadBytes)) return (ok = false), true;
      llvm::AllocaInst* args;
      {
        llvm::IRBuilderBase::InsertPointGuard guard(b);
        b.SetInsertPoint(allocaBlock->getTerminator());
        args = b.CreateAlloca(b.getInt8Ty(), i64(sizeof(TraceRayArgs)));
        args->setAlignment(llvm::Align(16));
      }
      llvm::Value* const operands[11] = {nullptr, accel,  ints[0], ints[1],   ints[2], ints[3],
                                         ints[4], origin, tMin,    direction, tMax};
      storeTraceRayArgs(
          args,
          [&](uint32_t w, uint32_t k) {
            return w == 7 || w == 9 ? b.CreateExtractElement(operands[w], uint64_t(k)) : operands[w];
          },
          b.CreateTrunc(payloadBytes, b.getInt32Ty()), payload);
      auto* ty = llvm::FunctionType::get(b.getVoidTy(), {b.getPtrTy(), b.getPtrTy()}, false);
      b.CreateCall(ty, rayRuntimeFunction(offsetof(RayRuntime, traceRay)), {ctxArg, args});
      info.ray.callsOut = true;
      return true;
    }
    case spv::OpExecuteCallableKHR:
    case spv::OpExecuteCallableNV: {
      llvm::Value* index = scalar32(*this, in.word(1));
      llvm::Value *data = nullptr, *bytes = nullptr;
      if (!index) return (ok = fail(in, "the SBT index has no value")), true;
      uint32_t dataVar = in.word(2);
      if (in.op == spv::OpExecuteCallableNV) {
        dataVar = variableAtLocation(*this, dataVar, spv::StorageClassCallableDataNV);
        if (!dataVar) return (ok = fail(in, "no CallableDataNV variable has the callable data's location")), true;
      }
      if (!blockOperand(*this, in, dataVar, &data, &bytes)) return (ok = false), true;
      auto* ty =
          llvm::FunctionType::get(b.getVoidTy(), {b.getPtrTy(), b.getInt32Ty(), b.getPtrTy(), b.getInt64Ty()}, false);
      b.CreateCall(ty, rayRuntimeFunction(offsetof(RayRuntime, executeCallable)), {ctxArg, index, data, bytes});
      info.ray.callsOut = true;
      return true;
    }
    case spv::OpReportIntersectionKHR: {
      llvm::Value* hitT = value(in.word(3));
      llvm::Value* hitKind = scalar32(*this, in.word(4));
      if (!hitT || !hitT->getType()->isFloatTy() || !hitKind) return (ok = fail(in, "an operand has no value")), true;
      llvm::Value* attrs = llvm::ConstantPointerNull::get(b.getPtrTy());
      llvm::Value* attrBytes = i64(0);
      if (hitAttributeVar && !blockOperand(*this, in, hitAttributeVar, &attrs, &attrBytes)) return (ok = false), true;
      auto* ty = llvm::FunctionType::get(
          b.getInt32Ty(), {b.getPtrTy(), b.getFloatTy(), b.getInt32Ty(), b.getPtrTy(), b.getInt64Ty()}, false);
      llvm::Value* committed = b.CreateCall(ty, rayRuntimeFunction(offsetof(RayRuntime, reportIntersection)),
                                            {ctxArg, hitT, hitKind, attrs, attrBytes});
      set(in.word(2), b.CreateICmpNE(committed, i32(0)));
      returnIfStopped();  // the any-hit shader terminated the ray
      return true;
    }
    case spv::OpIgnoreIntersectionKHR:
    case spv::OpTerminateRayKHR: {
      uint32_t status = in.op == spv::OpIgnoreIntersectionKHR ? kRayStatusIgnore : kRayStatusTerminate;
      b.CreateAlignedStore(i32(status), ctxAt(*this, offsetof(RayInvocation, status)), llvm::Align(4));
      returnFromFunction();
      return true;
    }
    case spv::OpIgnoreIntersectionNV:
    case spv::OpTerminateRayNV: {
      uint32_t status = in.op == spv::OpIgnoreIntersectionNV ? kRayStatusIgnore : kRayStatusTerminate;
      b.CreateAlignedStore(i32(status), ctxAt(*this, offsetof(RayInvocation, status)), llvm::Align(4));
      returnFromFunction();
      // Not a terminator: the rest of the SPIR-V block goes into a block nothing branches to.
      b.SetInsertPoint(llvm::BasicBlock::Create(c, "after_end", fn));
      return true;
    }
    default: return false;
  }
}

}  // namespace vkrt::spirv
