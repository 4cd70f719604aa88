// SPIR-V -> LLVM IR for shader debugging: debugPrintfEXT calls and the out-of-bounds reports of buffer accesses
// (abi/shader_debug.hpp). Each call site becomes a constant record of the module (its object code).
#include <llvm/IR/Constants.h>

#include "spirv/codegen.hpp"
#include "spirv/shader_debug.hpp"

namespace vkrt::spirv {

namespace {

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

void Codegen::callOutOfBounds(llvm::Constant* site, llvm::Value* offset, llvm::Value* range, llvm::Value* element) {
  llvm::Type* i64t = b.getInt64Ty();
  llvm::FunctionCallee f = out.getOrInsertFunction(
      "vkrt_out_of_bounds",
      llvm::FunctionType::get(b.getVoidTy(), {b.getPtrTy(), b.getPtrTy(), i64t, i64t, i64t}, false));
  auto* call = b.CreateCall(f, {ctxArg, site, offset, range, element ? element : i64(0)});
  call->addFnAttr(llvm::Attribute::Cold);
}

llvm::BasicBlock* Codegen::outOfBoundsBlock(const Ptr& p, uint32_t kind, uint64_t bytes, llvm::BasicBlock* join) {
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
  callOutOfBounds(accessSiteFor(p, kind, bytes), p.offset, p.unmaskedLimit ? p.unmaskedLimit : p.limit, p.element);
  b.CreateBr(join);
  return block;
}

}  // namespace vkrt::spirv
