// SPIR-V -> LLVM IR: branches, switches, phis, returns, function calls and barriers. Structured control flow
// maps block for block onto LLVM basic blocks (merge and continue annotations need no code).
#include <llvm/IR/Constants.h>

#include "spirv/codegen.hpp"

namespace vkrt::spirv {

void Codegen::finishPhis() {
  for (const PendingPhi& p : phis) {
    for (uint32_t i = 3; i + 1 < p.in->count; i += 2) {
      auto bit = blockExits.find(p.in->word(i + 1));
      if (bit == blockExits.end()) continue;
      llvm::Value* v = value(p.in->word(i));
      if (!v) v = llvm::Constant::getNullValue(p.phi->getType());
      // A predecessor may list the same block twice (a switch with several cases to one target): LLVM wants
      // one incoming entry per edge.
      llvm::BasicBlock* from = bit->second;
      unsigned edges = 0;
      if (auto* term = from->getTerminator()) {
        for (unsigned s = 0; s < term->getNumSuccessors(); ++s) edges += term->getSuccessor(s) == p.phi->getParent();
      }
      for (unsigned e = 0; e < edges; ++e) p.phi->addIncoming(v, from);
    }
  }
  phis.clear();
}

bool Codegen::controlFlow(const Instruction& in, bool& ok) {
  switch (in.op) {
    case spv::OpPhi: {
      // PhysicalStorageBuffer pointers are plain addresses; other pointers are not values.
      const Type& pt = spvType(in.word(1));
      if (pt.kind == Type::Pointer && pt.storage != spv::StorageClassPhysicalStorageBuffer)
        return (ok = unsupported(in, "phi of pointers")), true;
      llvm::Type* ty = type(in.word(1));
      if (!ty) return (ok = unsupported(in, "phi type")), true;
      llvm::PHINode* phi = b.CreatePHI(ty, (in.count - 3) / 2);
      set(in.word(2), phi);
      phis.push_back({phi, &in});
      return true;
    }
    case spv::OpBranch: b.CreateBr(blocks[in.word(1)]); return true;
    case spv::OpBranchConditional: {
      llvm::Value* cond = value(in.word(1));
      if (!cond) return (ok = fail(in, "condition has no value")), true;
      b.CreateCondBr(cond, blocks[in.word(2)], blocks[in.word(3)]);
      return true;
    }
    case spv::OpSwitch: {
      llvm::Value* sel = value(in.word(1));
      if (!sel) return (ok = fail(in, "selector has no value")), true;
      auto* it = llvm::cast<llvm::IntegerType>(sel->getType());
      uint32_t literalWords = it->getBitWidth() > 32 ? 2 : 1;
      uint32_t cases = (in.count - 3) / (literalWords + 1);
      llvm::SwitchInst* sw = b.CreateSwitch(sel, blocks[in.word(2)], cases);
      for (uint32_t i = 3; i + literalWords < in.count; i += literalWords + 1) {
        uint64_t lit = in.word(i);
        if (literalWords == 2) lit |= uint64_t(in.word(i + 1)) << 32;
        auto* k = llvm::ConstantInt::get(it, lit);
        if (sw->findCaseValue(k) != sw->case_default()) continue;  // validated modules have no duplicates
        sw->addCase(k, blocks[in.word(i + literalWords)]);
      }
      return true;
    }
    case spv::OpReturn: b.CreateRetVoid(); return true;
    case spv::OpReturnValue: {
      llvm::Value* v = value(in.word(1));
      if (!v) return (ok = unsupported(in, "returned value")), true;
      b.CreateRet(v);
      return true;
    }
    case spv::OpUnreachable: b.CreateUnreachable(); return true;
    case spv::OpFunctionCall: {
      auto fit = functions.find(in.word(3));
      if (fit == functions.end()) return (ok = fail(in, "call to an unknown function")), true;
      std::vector<llvm::Value*> args = {ctxArg, privArg};
      for (uint32_t i = 4; i < in.count; ++i) {
        uint32_t a = in.word(i);
        if (spvType(m.typeOf(a)).kind == Type::Pointer || hasPtr(a) || globals.count(a)) {
          Ptr& p = ptr(a);
          if (!p.base || p.slot >= 0 || p.matrixStride || p.rowMajor || p.vecStride)
            return (ok = unsupported(in, "pointer argument with an explicit layout")), true;
          args.insert(args.end(), {p.base, p.offset, p.limit});
        } else {
          llvm::Value* v = value(a);
          if (!v) return (ok = fail(in, "argument has no value")), true;
          args.push_back(v);
        }
      }
      llvm::Value* r = b.CreateCall(fit->second, args);
      if (!r->getType()->isVoidTy()) set(in.word(2), r);
      returnIfStopped();  // the callee ignored the intersection or terminated the ray
      return true;
    }
    case spv::OpControlBarrier: {
      uint64_t scope = 0;
      if (!m.constantU64(in.word(1), &scope)) return (ok = fail(in, "barrier scope is not a constant")), true;
      flushPendingAdds();  // combined adds (ray tracing stages) reach memory before any barrier
      b.CreateFence(llvm::AtomicOrdering::SequentiallyConsistent);
      if (scope == spv::ScopeWorkgroup) {
        // Every invocation of the workgroup stops here until all have arrived (the executor switches
        // between them).
        info.usesBarrier = true;
        llvm::Value* fnPtr = b.CreateAlignedLoad(
            b.getPtrTy(), b.CreateConstGEP1_64(b.getInt8Ty(), ctxArg, offsetof(InvocationContext, barrier)),
            llvm::Align(8));
        b.CreateCall(llvm::FunctionType::get(b.getVoidTy(), {b.getPtrTy()}, false), fnPtr, {ctxArg});
        b.CreateFence(llvm::AtomicOrdering::SequentiallyConsistent);
      } else if (scope != spv::ScopeSubgroup && scope != spv::ScopeInvocation) {
        return (ok = unsupported(in, "barrier execution scope")), true;
      }
      return true;
    }
    case spv::OpMemoryBarrier:
      flushPendingAdds();
      b.CreateFence(llvm::AtomicOrdering::SequentiallyConsistent);
      return true;
    default: return false;
  }
}

}  // namespace vkrt::spirv
