// SPIR-V -> LLVM IR: the GLSL.std.450 extended instruction set. Functions LLVM has intrinsics for use them;
// the others call the C library's math functions component by component.
#include <llvm/IR/Constants.h>
#include <llvm/IR/Intrinsics.h>
#include <spirv/unified1/GLSL.std.450.h>

#include "spirv/codegen.hpp"

namespace vkrt::spirv {

namespace {

struct Std {
  Codegen& g;
  llvm::IRBuilder<>& b;

  llvm::Value* fconst(llvm::Type* like, double v) { return llvm::ConstantFP::get(like, v); }
  llvm::Value* intr(llvm::Intrinsic::ID id, llvm::Value* a) { return b.CreateUnaryIntrinsic(id, a); }
  llvm::Value* intr2(llvm::Intrinsic::ID id, llvm::Value* a, llvm::Value* c) { return b.CreateBinaryIntrinsic(id, a, c); }

  // Calls `name` (float) or `name` without the 'f' suffix (double) on every component.
  llvm::Value* libm(const char* name, std::initializer_list<llvm::Value*> args) {
    llvm::Value* first = *args.begin();
    llvm::Type* t = first->getType();
    llvm::Type* s = t->getScalarType();
    std::string fname = name;
    if (s->isDoubleTy()) fname.pop_back();
    std::vector<llvm::Type*> params(args.size(), s->isHalfTy() ? b.getFloatTy() : s);
    llvm::Type* ct = s->isHalfTy() ? b.getFloatTy() : s;
    llvm::FunctionCallee f = g.out.getOrInsertFunction(fname, llvm::FunctionType::get(ct, params, false));
    auto scalarCall = [&](std::vector<llvm::Value*> a) {
      for (auto& v : a) v = b.CreateFPCast(v, ct);
      return b.CreateFPCast(b.CreateCall(f, a), s);
    };
    if (auto* vt = llvm::dyn_cast<llvm::FixedVectorType>(t)) {
      llvm::Value* r = llvm::UndefValue::get(t);
      for (unsigned i = 0; i < vt->getNumElements(); ++i) {
        std::vector<llvm::Value*> a;
        for (llvm::Value* v : args) a.push_back(b.CreateExtractElement(v, uint64_t(i)));
        r = b.CreateInsertElement(r, scalarCall(a), uint64_t(i));
      }
      return r;
    }
    return scalarCall(std::vector<llvm::Value*>(args));
  }

  llvm::Value* dot(llvm::Value* x, llvm::Value* y) {
    llvm::Value* p = b.CreateFMul(x, y);
    if (!p->getType()->isVectorTy()) return p;
    return b.CreateFAddReduce(fconst(p->getType()->getScalarType(), 0.0), p);
  }
  llvm::Value* length(llvm::Value* x) { return intr(llvm::Intrinsic::sqrt, dot(x, x)); }
  llvm::Value* clampF(llvm::Value* x, llvm::Value* lo, llvm::Value* hi) {
    return intr2(llvm::Intrinsic::minnum, intr2(llvm::Intrinsic::maxnum, x, lo), hi);
  }
};

}  // namespace

bool Codegen::extInst(const Instruction& in, bool& ok) {
  if (in.op != spv::OpExtInst) return false;
  if (in.word(3) != glslSet || glslSet == 0) return (ok = unsupported(in, "extended instruction set")), true;
  uint32_t inst = in.word(4);
  llvm::Type* rt = type(in.word(1));
  std::vector<llvm::Value*> a;
  for (uint32_t i = 5; i < in.count; ++i) {
    llvm::Value* v = value(in.word(i));
    if (!v && !(hasPtr(in.word(i)) || globals.count(in.word(i)))) return (ok = fail(in, "operand has no value")), true;
    a.push_back(v);
  }
  auto arg = [&](size_t i) { return i < a.size() ? a[i] : nullptr; };
  Std s{*this, b};
  llvm::Value* r = nullptr;
  using namespace llvm;
  switch (inst) {
    case GLSLstd450Round: r = s.intr(Intrinsic::round, arg(0)); break;
    case GLSLstd450RoundEven: r = s.intr(Intrinsic::roundeven, arg(0)); break;
    case GLSLstd450Trunc: r = s.intr(Intrinsic::trunc, arg(0)); break;
    case GLSLstd450FAbs: r = s.intr(Intrinsic::fabs, arg(0)); break;
    case GLSLstd450SAbs: r = b.CreateBinaryIntrinsic(Intrinsic::abs, arg(0), b.getFalse()); break;
    case GLSLstd450FSign: {
      Value* x = arg(0);
      Value* pos = b.CreateSelect(b.CreateFCmpOGT(x, s.fconst(x->getType(), 0)), s.fconst(x->getType(), 1), s.fconst(x->getType(), 0));
      r = b.CreateSelect(b.CreateFCmpOLT(x, s.fconst(x->getType(), 0)), s.fconst(x->getType(), -1), pos);
      break;
    }
    case GLSLstd450SSign: {
      Value* x = arg(0);
      llvm::Type* t = x->getType();
      r = b.CreateSelect(b.CreateICmpSGT(x, llvm::Constant::getNullValue(t)), ConstantInt::get(t, 1),
                         b.CreateSelect(b.CreateICmpSLT(x, llvm::Constant::getNullValue(t)), llvm::Constant::getAllOnesValue(t), llvm::Constant::getNullValue(t)));
      break;
    }
    case GLSLstd450Floor: r = s.intr(Intrinsic::floor, arg(0)); break;
    case GLSLstd450Ceil: r = s.intr(Intrinsic::ceil, arg(0)); break;
    case GLSLstd450Fract: r = b.CreateFSub(arg(0), s.intr(Intrinsic::floor, arg(0))); break;
    case GLSLstd450Radians: r = b.CreateFMul(arg(0), s.fconst(arg(0)->getType(), 3.14159265358979323846 / 180.0)); break;
    case GLSLstd450Degrees: r = b.CreateFMul(arg(0), s.fconst(arg(0)->getType(), 180.0 / 3.14159265358979323846)); break;
    case GLSLstd450Sin: r = s.intr(Intrinsic::sin, arg(0)); break;
    case GLSLstd450Cos: r = s.intr(Intrinsic::cos, arg(0)); break;
    case GLSLstd450Tan: r = s.libm("tanf", {arg(0)}); break;
    case GLSLstd450Asin: r = s.libm("asinf", {arg(0)}); break;
    case GLSLstd450Acos: r = s.libm("acosf", {arg(0)}); break;
    case GLSLstd450Atan: r = s.libm("atanf", {arg(0)}); break;
    case GLSLstd450Sinh: r = s.libm("sinhf", {arg(0)}); break;
    case GLSLstd450Cosh: r = s.libm("coshf", {arg(0)}); break;
    case GLSLstd450Tanh: r = s.libm("tanhf", {arg(0)}); break;
    case GLSLstd450Asinh: r = s.libm("asinhf", {arg(0)}); break;
    case GLSLstd450Acosh: r = s.libm("acoshf", {arg(0)}); break;
    case GLSLstd450Atanh: r = s.libm("atanhf", {arg(0)}); break;
    case GLSLstd450Atan2: r = s.libm("atan2f", {arg(0), arg(1)}); break;
    case GLSLstd450Pow: r = s.intr2(Intrinsic::pow, arg(0), arg(1)); break;
    case GLSLstd450Exp: r = s.intr(Intrinsic::exp, arg(0)); break;
    case GLSLstd450Log: r = s.intr(Intrinsic::log, arg(0)); break;
    case GLSLstd450Exp2: r = s.intr(Intrinsic::exp2, arg(0)); break;
    case GLSLstd450Log2: r = s.intr(Intrinsic::log2, arg(0)); break;
    case GLSLstd450Sqrt: r = s.intr(Intrinsic::sqrt, arg(0)); break;
    case GLSLstd450InverseSqrt: r = b.CreateFDiv(s.fconst(arg(0)->getType(), 1.0), s.intr(Intrinsic::sqrt, arg(0))); break;
    case GLSLstd450FMin:
    case GLSLstd450NMin: r = s.intr2(Intrinsic::minnum, arg(0), arg(1)); break;
    case GLSLstd450FMax:
    case GLSLstd450NMax: r = s.intr2(Intrinsic::maxnum, arg(0), arg(1)); break;
    case GLSLstd450UMin: r = s.intr2(Intrinsic::umin, arg(0), arg(1)); break;
    case GLSLstd450SMin: r = s.intr2(Intrinsic::smin, arg(0), arg(1)); break;
    case GLSLstd450UMax: r = s.intr2(Intrinsic::umax, arg(0), arg(1)); break;
    case GLSLstd450SMax: r = s.intr2(Intrinsic::smax, arg(0), arg(1)); break;
    case GLSLstd450FClamp:
    case GLSLstd450NClamp: r = s.clampF(arg(0), arg(1), arg(2)); break;
    case GLSLstd450UClamp: r = s.intr2(Intrinsic::umin, s.intr2(Intrinsic::umax, arg(0), arg(1)), arg(2)); break;
    case GLSLstd450SClamp: r = s.intr2(Intrinsic::smin, s.intr2(Intrinsic::smax, arg(0), arg(1)), arg(2)); break;
    case GLSLstd450FMix: r = b.CreateFAdd(arg(0), b.CreateFMul(b.CreateFSub(arg(1), arg(0)), arg(2))); break;
    case GLSLstd450Step: r = b.CreateSelect(b.CreateFCmpOLT(arg(1), arg(0)), s.fconst(rt, 0), s.fconst(rt, 1)); break;
    case GLSLstd450SmoothStep: {
      Value* t = s.clampF(b.CreateFDiv(b.CreateFSub(arg(2), arg(0)), b.CreateFSub(arg(1), arg(0))), s.fconst(rt, 0), s.fconst(rt, 1));
      r = b.CreateFMul(b.CreateFMul(t, t), b.CreateFSub(s.fconst(rt, 3), b.CreateFMul(s.fconst(rt, 2), t)));
      break;
    }
    case GLSLstd450Fma: r = b.CreateIntrinsic(Intrinsic::fma, {rt}, {arg(0), arg(1), arg(2)}); break;
    case GLSLstd450Ldexp: {
      // ldexp(x, e) = x * 2^e, exact for results in range.
      Value* e = arg(1);
      llvm::Type* et = b.getInt32Ty();
      if (auto* vt = dyn_cast<FixedVectorType>(e->getType())) et = FixedVectorType::get(b.getInt32Ty(), vt->getNumElements());
      r = b.CreateFMul(arg(0), s.intr(Intrinsic::exp2, b.CreateSIToFP(b.CreateSExtOrTrunc(e, et), rt)));
      break;
    }
    case GLSLstd450Length: r = s.length(arg(0)); break;
    case GLSLstd450Distance: r = s.length(b.CreateFSub(arg(0), arg(1))); break;
    case GLSLstd450Normalize: {
      Value* len = s.length(arg(0));
      r = b.CreateFDiv(arg(0), splat(len, rt));
      break;
    }
    case GLSLstd450Cross: {
      Value* x = arg(0);
      Value* y = arg(1);
      auto sh = [&](Value* v, int a0, int a1, int a2) { return b.CreateShuffleVector(v, ArrayRef<int>{a0, a1, a2}); };
      r = b.CreateFSub(b.CreateFMul(sh(x, 1, 2, 0), sh(y, 2, 0, 1)), b.CreateFMul(sh(x, 2, 0, 1), sh(y, 1, 2, 0)));
      break;
    }
    case GLSLstd450FaceForward: {
      Value* d = s.dot(arg(2), arg(1));
      r = b.CreateSelect(b.CreateFCmpOLT(d, s.fconst(d->getType(), 0)), arg(0), b.CreateFNeg(arg(0)));
      break;
    }
    case GLSLstd450Reflect: {
      Value* d = s.dot(arg(1), arg(0));
      r = b.CreateFSub(arg(0), b.CreateFMul(splat(b.CreateFMul(s.fconst(d->getType(), 2), d), rt), arg(1)));
      break;
    }
    case GLSLstd450Refract: {
      Value* I = arg(0);
      Value* N = arg(1);
      Value* eta = b.CreateFPCast(arg(2), rt->getScalarType());
      Value* d = s.dot(N, I);
      Value* one = s.fconst(d->getType(), 1);
      Value* k = b.CreateFSub(one, b.CreateFMul(b.CreateFMul(eta, eta), b.CreateFSub(one, b.CreateFMul(d, d))));
      Value* t = b.CreateFAdd(b.CreateFMul(eta, d), s.intr(Intrinsic::sqrt, k));
      Value* res = b.CreateFSub(b.CreateFMul(splat(eta, rt), I), b.CreateFMul(splat(t, rt), N));
      r = b.CreateSelect(b.CreateFCmpOLT(k, s.fconst(d->getType(), 0)), llvm::Constant::getNullValue(rt), res);
      break;
    }
    case GLSLstd450FindILsb: {
      Value* x = arg(0);
      Value* tz = b.CreateBinaryIntrinsic(Intrinsic::cttz, x, b.getFalse());
      r = b.CreateSelect(b.CreateICmpEQ(x, llvm::Constant::getNullValue(x->getType())), llvm::Constant::getAllOnesValue(x->getType()), tz);
      break;
    }
    case GLSLstd450FindUMsb:
    case GLSLstd450FindSMsb: {
      Value* x = arg(0);
      llvm::Type* t = x->getType();
      unsigned w = t->getScalarSizeInBits();
      if (inst == GLSLstd450FindSMsb) x = b.CreateSelect(b.CreateICmpSLT(x, llvm::Constant::getNullValue(t)), b.CreateNot(x), x);
      Value* lz = b.CreateBinaryIntrinsic(Intrinsic::ctlz, x, b.getFalse());
      // w - 1 - lz, which is -1 for x == 0 (lz == w).
      r = b.CreateSub(ConstantInt::get(t, w - 1), lz);
      break;
    }
    case GLSLstd450Modf:
    case GLSLstd450ModfStruct: {
      Value* x = arg(0);
      Value* whole = s.intr(Intrinsic::trunc, x);
      Value* frac = b.CreateFSub(x, whole);
      if (inst == GLSLstd450Modf) {
        Ptr& p = ptr(in.word(6));
        if (!p.base || p.slot >= 0) return (ok = fail(in, "modf's pointer operand is not tracked")), true;
        store(p, whole);
        r = frac;
      } else {
        r = b.CreateInsertValue(b.CreateInsertValue(UndefValue::get(rt), frac, {0}), whole, {1});
      }
      break;
    }
    case GLSLstd450Determinant:
    case GLSLstd450MatrixInverse: {
      Value* mtx = arg(0);
      auto* at = cast<ArrayType>(mtx->getType());
      unsigned n = unsigned(at->getNumElements());
      auto e = [&](unsigned col, unsigned row) { return b.CreateExtractElement(b.CreateExtractValue(mtx, {col}), uint64_t(row)); };
      if (n != 2 && n != 3) return (ok = unsupported(in, "determinant/inverse of this size")), true;
      if (n == 2) {
        Value* det = b.CreateFSub(b.CreateFMul(e(0, 0), e(1, 1)), b.CreateFMul(e(1, 0), e(0, 1)));
        if (inst == GLSLstd450Determinant) {
          r = det;
          break;
        }
        Value* inv = b.CreateFDiv(s.fconst(det->getType(), 1), det);
        Value* c0 = UndefValue::get(at->getElementType());
        Value* c1 = c0;
        c0 = b.CreateInsertElement(c0, b.CreateFMul(e(1, 1), inv), uint64_t(0));
        c0 = b.CreateInsertElement(c0, b.CreateFNeg(b.CreateFMul(e(0, 1), inv)), uint64_t(1));
        c1 = b.CreateInsertElement(c1, b.CreateFNeg(b.CreateFMul(e(1, 0), inv)), uint64_t(0));
        c1 = b.CreateInsertElement(c1, b.CreateFMul(e(0, 0), inv), uint64_t(1));
        r = b.CreateInsertValue(b.CreateInsertValue(UndefValue::get(at), c0, {0}), c1, {1});
        break;
      }
      // 3x3: cofactors.
      auto cof = [&](unsigned c, unsigned rr) {
        unsigned c1 = (c + 1) % 3, c2 = (c + 2) % 3, r1 = (rr + 1) % 3, r2 = (rr + 2) % 3;
        return b.CreateFSub(b.CreateFMul(e(c1, r1), e(c2, r2)), b.CreateFMul(e(c2, r1), e(c1, r2)));
      };
      Value* det = b.CreateFAdd(b.CreateFAdd(b.CreateFMul(e(0, 0), cof(0, 0)), b.CreateFMul(e(1, 0), cof(1, 0))), b.CreateFMul(e(2, 0), cof(2, 0)));
      if (inst == GLSLstd450Determinant) {
        r = det;
        break;
      }
      Value* inv = b.CreateFDiv(s.fconst(det->getType(), 1), det);
      r = UndefValue::get(at);
      for (unsigned c = 0; c < 3; ++c) {
        Value* col = UndefValue::get(at->getElementType());
        for (unsigned rr = 0; rr < 3; ++rr) col = b.CreateInsertElement(col, b.CreateFMul(cof(rr, c), inv), uint64_t(rr));
        r = b.CreateInsertValue(r, col, {c});
      }
      break;
    }
    default:
      return (ok = unsupported(in, "GLSL.std.450 instruction")), true;
  }
  if (!r) return (ok = fail(in, "operand has no value")), true;
  set(in.word(2), r);
  return true;
}

}  // namespace vkrt::spirv
