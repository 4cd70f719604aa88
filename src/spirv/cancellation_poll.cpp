// The cancellation-poll pass (cancellation_poll.hpp): an LLVM IR rewrite that lets the executor stop a shader
// that loops forever.
#include "spirv/cancellation_poll.hpp"

#include <llvm/Analysis/LoopInfo.h>
#include <llvm/IR/Dominators.h>
#include <llvm/IR/IRBuilder.h>
#include <llvm/IR/MDBuilder.h>
#include <llvm/IR/Module.h>

#include <cstddef>
#include <vector>

#include "abi/abi.hpp"

namespace vkrt::spirv {

// Cancellation polls (robustness: a shader that loops forever must not keep the device busy forever): at the
// header of every loop of the optimized code, a relaxed load of the executor's cancellation flag
// (InvocationContext::cancel, read once per function call into a register; null: a constant zero) and, when it is
// nonzero, a call of InvocationContext::cancelled (exec/supervise.hpp), which does not come back when the work is
// supervised. Added after LLVM's optimizations so that they see the loops as they were (unrolling, vectorization);
// a loop that survives them pays one load and one predicted branch per iteration. The context is the argument the
// code generator marks "vkrt-ctx" (a function whose context argument was dropped as unused has no loop to poll
// from it: such a function is left as it is).
void addCancellationPolls(llvm::Module& mod) {
  llvm::LLVMContext& c = mod.getContext();
  llvm::Type* i8 = llvm::Type::getInt8Ty(c);
  llvm::Type* i32 = llvm::Type::getInt32Ty(c);
  llvm::PointerType* ptr = llvm::PointerType::get(c, 0);
  llvm::GlobalVariable* never = nullptr;
  for (llvm::Function& f : mod) {
    if (f.isDeclaration()) continue;
    llvm::Argument* ctx = nullptr;
    for (llvm::Argument& a : f.args())
      if (f.getAttributes().hasParamAttr(a.getArgNo(), "vkrt-ctx")) ctx = &a;
    if (!ctx) continue;
    std::vector<llvm::BasicBlock*> headers;
    {
      llvm::DominatorTree dt(f);
      llvm::LoopInfo loops(dt);
      for (llvm::Loop* l : loops.getLoopsInPreorder()) headers.push_back(l->getHeader());
    }
    if (headers.empty()) continue;
    if (!never)
      never = new llvm::GlobalVariable(mod, i32, true, llvm::GlobalValue::PrivateLinkage,
                                       llvm::ConstantInt::get(i32, 0), "vkrt.never_cancelled");
    llvm::IRBuilder<> b(&*f.getEntryBlock().getFirstInsertionPt());
    llvm::Value* flag = b.CreateLoad(ptr, b.CreateConstGEP1_64(i8, ctx, offsetof(abi::InvocationContext, cancel)));
    flag = b.CreateSelect(b.CreateIsNull(flag), never, flag, "vkrt.cancel");
    llvm::FunctionType* cancelledType = llvm::FunctionType::get(b.getVoidTy(), {ptr}, false);
    llvm::MDNode* unlikely = llvm::MDBuilder(c).createBranchWeights(1, 1u << 20);
    for (llvm::BasicBlock* h : headers) {
      llvm::BasicBlock* body = h->splitBasicBlock(h->getFirstNonPHI(), h->getName() + ".polled");
      h->getTerminator()->eraseFromParent();
      b.SetInsertPoint(h);
      llvm::LoadInst* v = b.CreateLoad(i32, flag);
      v->setAtomic(llvm::AtomicOrdering::Monotonic);
      v->setAlignment(llvm::Align(4));
      auto* cancel = llvm::BasicBlock::Create(c, "vkrt.cancelled", &f);
      b.CreateCondBr(b.CreateICmpNE(v, b.getInt32(0)), cancel, body, unlikely);
      b.SetInsertPoint(cancel);
      llvm::Value* fn = b.CreateLoad(ptr, b.CreateConstGEP1_64(i8, ctx, offsetof(abi::InvocationContext, cancelled)));
      b.CreateCall(cancelledType, fn, {ctx});
      b.CreateBr(body);
    }
  }
}

}  // namespace vkrt::spirv
