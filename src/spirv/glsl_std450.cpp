// SPIR-V -> LLVM IR: the GLSL.std.450 extended instruction set. Functions LLVM has intrinsics for use them;
// the others call the C library's math functions component by component, or work on the bits (frexp, ldexp,
// the pack/unpack family).
#include <llvm/IR/Constants.h>
#include <llvm/IR/Intrinsics.h>
#include <spirv/unified1/GLSL.std.450.h>

#include <cmath>

#include "spirv/codegen.hpp"

namespace vkrt::spirv {

namespace {

struct Std {
  Codegen& g;
  llvm::IRBuilder<>& b;
  const std::vector<llvm::Value*>& a;  // the operands' values (nullptr: a pointer operand)

  llvm::Value* arg(size_t i) const { return i < a.size() ? a[i] : nullptr; }

  llvm::Value* fconst(llvm::Type* like, double v) { return llvm::ConstantFP::get(like, v); }
  llvm::Value* intr(llvm::Intrinsic::ID id, llvm::Value* a) { return b.CreateUnaryIntrinsic(id, a); }
  llvm::Value* intr2(llvm::Intrinsic::ID id, llvm::Value* a, llvm::Value* c) {
    bool minMax = id == llvm::Intrinsic::minnum || id == llvm::Intrinsic::maxnum;
    if (minMax && a->getType()->getScalarType()->isHalfTy()) return halfMinMax(id == llvm::Intrinsic::minnum, a, c);
    return b.CreateBinaryIntrinsic(id, a, c);
  }
  // minnum/maxnum of halves on their bits: LLVM 15's x86 back end cannot select half vector min/max ("Cannot
  // select: v8f16 = X86ISD::FMIN"; float arithmetic around it is narrowed back to half by InstCombine). The bits,
  // with the magnitude bits flipped where the sign is set, order as signed integers the way the values do (-0
  // below +0); a NaN operand gives the other operand, as minnum does.
  llvm::Value* halfMinMax(bool isMin, llvm::Value* a, llvm::Value* c) {
    llvm::Type* it = shaped(a->getType(), b.getInt16Ty());
    llvm::Value* ai = b.CreateBitCast(a, it);
    llvm::Value* ci = b.CreateBitCast(c, it);
    auto key = [&](llvm::Value* bits) { return b.CreateXor(bits, b.CreateLShr(b.CreateAShr(bits, 15), 1)); };
    auto isNan = [&](llvm::Value* bits) {
      return b.CreateICmpUGT(b.CreateAnd(bits, iconst(it, 0x7fff)), iconst(it, 0x7c00));
    };
    llvm::Value* aFirst = isMin ? b.CreateICmpSLT(key(ai), key(ci)) : b.CreateICmpSGT(key(ai), key(ci));
    llvm::Value* r = b.CreateSelect(b.CreateOr(isNan(ci), b.CreateAnd(b.CreateNot(isNan(ai)), aFirst)), ai, ci);
    return b.CreateBitCast(r, a->getType());
  }

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
  // `t` with its scalar type replaced by `s` (same number of components).
  llvm::Type* shaped(llvm::Type* t, llvm::Type* s) {
    if (auto* vt = llvm::dyn_cast<llvm::FixedVectorType>(t)) return llvm::FixedVectorType::get(s, vt->getNumElements());
    return s;
  }
  llvm::Value* iconst(llvm::Type* like, uint64_t v) { return llvm::ConstantInt::get(like, v); }

  // frexp on the bits: {significand in [0.5, 1), exponent of type `expTy`}. Zeros, infinities and NaNs give
  // {x, 0}; denormals are first scaled into the normal range by 2^(mantissa + 1), exact in every format.
  std::pair<llvm::Value*, llvm::Value*> frexp(llvm::Value* x, llvm::Type* expTy) {
    llvm::Type* ft = x->getType();
    unsigned w = ft->getScalarSizeInBits();
    unsigned mant = w == 16 ? 10 : w == 32 ? 23 : 52;
    uint64_t emax = (1ull << (w - mant - 1)) - 1, bias = emax / 2;
    llvm::Type* it = shaped(ft, b.getIntNTy(w));
    auto field = [&](llvm::Value* bits) { return b.CreateAnd(b.CreateLShr(bits, iconst(it, mant)), iconst(it, emax)); };
    llvm::Value* bits = b.CreateBitCast(x, it);
    llvm::Value* e = field(bits);
    llvm::Value* magnitude = b.CreateAnd(bits, iconst(it, ~0ull >> (65 - w)));
    llvm::Value* zeroField = b.CreateICmpEQ(e, iconst(it, 0));
    llvm::Value* special = b.CreateOr(b.CreateICmpEQ(e, iconst(it, emax)), b.CreateICmpEQ(magnitude, iconst(it, 0)));
    llvm::Value* scaled = b.CreateBitCast(b.CreateFMul(x, fconst(ft, std::ldexp(1.0, int(mant) + 1))), it);
    llvm::Value* nb = b.CreateSelect(zeroField, scaled, bits);
    llvm::Value* exp =
        b.CreateSub(field(nb), b.CreateSelect(zeroField, iconst(it, bias - 1 + mant + 1), iconst(it, bias - 1)));
    llvm::Value* sig = b.CreateOr(b.CreateAnd(nb, iconst(it, ~(emax << mant))), iconst(it, (bias - 1) << mant));
    sig = b.CreateSelect(special, x, b.CreateBitCast(sig, ft));
    exp = b.CreateSelect(special, llvm::Constant::getNullValue(it), exp);
    return {sig, b.CreateSExtOrTrunc(exp, expTy)};
  }

  // packSnorm/packUnorm: each component clamped to [-1, 1] (snorm) or [0, 1] (unorm), scaled by 2^(bits-1) - 1
  // or 2^bits - 1, rounded to nearest (ties to even), packed from the least significant bits up. A NaN packs
  // as 0 (vkrt's choice: the result is undefined).
  llvm::Value* packNorm(llvm::Value* v, bool isSigned, unsigned bits) {
    llvm::Type* ft = v->getType();
    unsigned n = unsigned(llvm::cast<llvm::FixedVectorType>(ft)->getNumElements());
    double scale = isSigned ? double((1u << (bits - 1)) - 1) : double((1u << bits) - 1);
    v = b.CreateSelect(b.CreateFCmpUNO(v, v), llvm::Constant::getNullValue(ft), v);
    v = clampF(v, fconst(ft, isSigned ? -1.0 : 0.0), fconst(ft, 1.0));
    v = intr(llvm::Intrinsic::roundeven, b.CreateFMul(v, fconst(ft, scale)));
    llvm::Type* it = shaped(ft, b.getInt32Ty());
    llvm::Value* ints = isSigned ? b.CreateFPToSI(v, it) : b.CreateFPToUI(v, it);
    llvm::Value* r = b.getInt32(0);
    for (unsigned i = 0; i < n; ++i) {
      llvm::Value* c = b.CreateAnd(b.CreateExtractElement(ints, uint64_t(i)), b.getInt32((1u << bits) - 1));
      r = b.CreateOr(r, b.CreateShl(c, b.getInt32(i * bits)));
    }
    return r;
  }
  // unpackSnorm/unpackUnorm: the `bits`-bit fields of `p`, least significant first, as c / (2^(bits-1) - 1)
  // clamped to [-1, 1] (snorm) or c / (2^bits - 1) (unorm).
  llvm::Value* unpackNorm(llvm::Value* p, bool isSigned, unsigned bits, llvm::Type* rt) {
    unsigned n = 32 / bits;
    llvm::Type* ft = rt->getScalarType();
    double scale = isSigned ? double((1u << (bits - 1)) - 1) : double((1u << bits) - 1);
    llvm::Value* r = llvm::UndefValue::get(rt);
    for (unsigned i = 0; i < n; ++i) {
      llvm::Value* c = b.CreateTrunc(b.CreateLShr(p, b.getInt32(i * bits)), b.getIntNTy(bits));
      llvm::Value* f = isSigned ? b.CreateSIToFP(c, ft) : b.CreateUIToFP(c, ft);
      f = b.CreateFDiv(f, fconst(ft, scale));
      if (isSigned) f = intr2(llvm::Intrinsic::maxnum, f, fconst(ft, -1.0));  // -128 / 127 -> -1
      r = b.CreateInsertElement(r, f, uint64_t(i));
    }
    return r;
  }

  // ldexp(x, e) = x * 2^e, rounded once. Float and half are computed exactly in a wider type (e clamped to a
  // range past which every result is 0 or infinite) and rounded by the final conversion; doubles call libm.
  llvm::Value* ldexp(llvm::Value* x, llvm::Value* e) {
    llvm::Type* ft = x->getType();
    unsigned w = ft->getScalarSizeInBits();
    llvm::Type* et = e->getType();
    auto clampE = [&](int64_t lim) {
      llvm::Type* wide = shaped(et, b.getInt64Ty());
      llvm::Value* c = b.CreateSExtOrTrunc(e, wide);
      c = intr2(llvm::Intrinsic::smin, intr2(llvm::Intrinsic::smax, c, iconst(wide, uint64_t(-lim))),
                iconst(wide, uint64_t(lim)));
      return b.CreateTrunc(c, shaped(et, b.getInt32Ty()));
    };
    if (w == 64) {
      llvm::FunctionCallee f = g.out.getOrInsertFunction("ldexp", b.getDoubleTy(), b.getDoubleTy(), b.getInt32Ty());
      llvm::Value* ei = clampE(4000);
      auto one = [&](llvm::Value* xs, llvm::Value* es) { return b.CreateCall(f, {xs, es}); };
      auto* vt = llvm::dyn_cast<llvm::FixedVectorType>(ft);
      if (!vt) return one(x, ei);
      llvm::Value* r = llvm::UndefValue::get(ft);
      for (unsigned i = 0; i < vt->getNumElements(); ++i) {
        llvm::Value* c = one(b.CreateExtractElement(x, uint64_t(i)), b.CreateExtractElement(ei, uint64_t(i)));
        r = b.CreateInsertElement(r, c, uint64_t(i));
      }
      return r;
    }
    // A float lies in [2^-149, 2^128): times 2^[-400, 400] it is a normal double, exact. A half (2^-24 to
    // 2^16) times 2^[-60, 60] is an exact float.
    unsigned ww = w == 32 ? 64 : 32;
    int64_t lim = w == 32 ? 400 : 60;
    unsigned wmant = ww == 64 ? 52 : 23;
    uint64_t wbias = ww == 64 ? 1023 : 127;
    llvm::Type* wt = shaped(ft, ww == 64 ? b.getDoubleTy() : b.getFloatTy());
    llvm::Type* wit = shaped(ft, b.getIntNTy(ww));
    llvm::Value* biased = b.CreateAdd(b.CreateSExtOrTrunc(clampE(lim), wit), iconst(wit, wbias));
    llvm::Value* pow2 = b.CreateBitCast(b.CreateShl(biased, iconst(wit, wmant)), wt);
    return b.CreateFPTrunc(b.CreateFMul(b.CreateFPExt(x, wt), pow2), ft);
  }

  // The determinant of the square sub-matrix of `e(column, row)` on the given columns and rows (Laplace
  // expansion along its first row; matrices are at most 4x4).
  template <class E>
  llvm::Value* minorDet(E& e, const std::vector<unsigned>& cols, const std::vector<unsigned>& rows) {
    if (cols.size() == 1) return e(cols[0], rows[0]);
    std::vector<unsigned> subRows(rows.begin() + 1, rows.end());
    llvm::Value* sum = nullptr;
    for (size_t j = 0; j < cols.size(); ++j) {
      std::vector<unsigned> subCols;
      for (size_t k = 0; k < cols.size(); ++k)
        if (k != j) subCols.push_back(cols[k]);
      llvm::Value* term = b.CreateFMul(e(cols[j], rows[0]), minorDet(e, subCols, subRows));
      sum = !sum ? term : j % 2 ? b.CreateFSub(sum, term) : b.CreateFAdd(sum, term);
    }
    return sum;
  }

  // ---- the cases of Codegen::extInst that are not component by component

  // Length, Distance, Normalize, Cross, FaceForward, Reflect and Refract, on whole vectors.
  llvm::Value* geometric(uint32_t inst, llvm::Type* rt) {
    using namespace llvm;
    switch (inst) {
      case GLSLstd450Length: return length(arg(0));
      case GLSLstd450Distance: return length(b.CreateFSub(arg(0), arg(1)));
      case GLSLstd450Normalize: {
        Value* len = length(arg(0));
        return b.CreateFDiv(arg(0), g.splat(len, rt));
      }
      case GLSLstd450Cross: {
        Value* x = arg(0);
        Value* y = arg(1);
        auto sh = [&](Value* v, int a0, int a1, int a2) { return b.CreateShuffleVector(v, ArrayRef<int>{a0, a1, a2}); };
        return b.CreateFSub(b.CreateFMul(sh(x, 1, 2, 0), sh(y, 2, 0, 1)), b.CreateFMul(sh(x, 2, 0, 1), sh(y, 1, 2, 0)));
      }
      case GLSLstd450FaceForward: {
        Value* d = dot(arg(2), arg(1));
        return b.CreateSelect(b.CreateFCmpOLT(d, fconst(d->getType(), 0)), arg(0), b.CreateFNeg(arg(0)));
      }
      case GLSLstd450Reflect: {
        Value* d = dot(arg(1), arg(0));
        return b.CreateFSub(arg(0), b.CreateFMul(g.splat(b.CreateFMul(fconst(d->getType(), 2), d), rt), arg(1)));
      }
      case GLSLstd450Refract: {
        Value* I = arg(0);
        Value* N = arg(1);
        Value* eta = b.CreateFPCast(arg(2), rt->getScalarType());
        Value* d = dot(N, I);
        Value* one = fconst(d->getType(), 1);
        Value* k = b.CreateFSub(one, b.CreateFMul(b.CreateFMul(eta, eta), b.CreateFSub(one, b.CreateFMul(d, d))));
        Value* t = b.CreateFAdd(b.CreateFMul(eta, d), intr(Intrinsic::sqrt, k));
        Value* res = b.CreateFSub(b.CreateFMul(g.splat(eta, rt), I), b.CreateFMul(g.splat(t, rt), N));
        return b.CreateSelect(b.CreateFCmpOLT(k, fconst(d->getType(), 0)), llvm::Constant::getNullValue(rt), res);
      }
      default: return nullptr;
    }
  }

  // Determinant and MatrixInverse of a 2x2, 3x3 or 4x4 matrix (nullptr for another size).
  llvm::Value* matrix(uint32_t inst) {
    using namespace llvm;
    switch (inst) {
      case GLSLstd450Determinant:
      case GLSLstd450MatrixInverse: {
        Value* mtx = arg(0);
        auto* at = cast<ArrayType>(mtx->getType());
        unsigned n = unsigned(at->getNumElements());
        if (n < 2 || n > 4) return nullptr;
        std::vector<std::vector<Value*>> elems(n, std::vector<Value*>(n));
        for (unsigned col = 0; col < n; ++col)
          for (unsigned row = 0; row < n; ++row)
            elems[col][row] = b.CreateExtractElement(b.CreateExtractValue(mtx, {col}), uint64_t(row));
        auto e = [&](unsigned col, unsigned row) { return elems[col][row]; };
        std::vector<unsigned> all(n);
        for (unsigned i = 0; i < n; ++i) all[i] = i;
        Value* det = minorDet(e, all, all);
        if (inst == GLSLstd450Determinant) return det;
        // inverse = adjugate / det: element (column c, row r) is the cofactor of (column r, row c).
        Value* inv = b.CreateFDiv(fconst(det->getType(), 1), det);
        Value* r = UndefValue::get(at);
        for (unsigned col = 0; col < n; ++col) {
          Value* column = UndefValue::get(at->getElementType());
          for (unsigned row = 0; row < n; ++row) {
            std::vector<unsigned> cols, rows;
            for (unsigned i = 0; i < n; ++i) {
              if (i != row) cols.push_back(i);
              if (i != col) rows.push_back(i);
            }
            Value* cof = minorDet(e, cols, rows);
            if ((row + col) % 2) cof = b.CreateFNeg(cof);
            column = b.CreateInsertElement(column, b.CreateFMul(cof, inv), uint64_t(row));
          }
          r = b.CreateInsertValue(r, column, {col});
        }
        return r;
      }
      default: return nullptr;
    }
  }

  // The pack and unpack instructions (32- and 64-bit words of normalized, half and 32-bit components).
  llvm::Value* packing(uint32_t inst, llvm::Type* rt) {
    using namespace llvm;
    switch (inst) {
      case GLSLstd450PackSnorm4x8: return packNorm(arg(0), true, 8);
      case GLSLstd450PackUnorm4x8: return packNorm(arg(0), false, 8);
      case GLSLstd450PackSnorm2x16: return packNorm(arg(0), true, 16);
      case GLSLstd450PackUnorm2x16: return packNorm(arg(0), false, 16);
      case GLSLstd450UnpackSnorm4x8: return unpackNorm(arg(0), true, 8, rt);
      case GLSLstd450UnpackUnorm4x8: return unpackNorm(arg(0), false, 8, rt);
      case GLSLstd450UnpackSnorm2x16: return unpackNorm(arg(0), true, 16, rt);
      case GLSLstd450UnpackUnorm2x16: return unpackNorm(arg(0), false, 16, rt);
      case GLSLstd450PackHalf2x16: {
        // Each component converted to half (round to nearest even), the first in the low 16 bits.
        auto* h2 = FixedVectorType::get(b.getHalfTy(), 2);
        Value* h = b.CreateBitCast(b.CreateFPTrunc(arg(0), h2), FixedVectorType::get(b.getInt16Ty(), 2));
        Value* lo = b.CreateZExt(b.CreateExtractElement(h, uint64_t(0)), b.getInt32Ty());
        Value* hi = b.CreateZExt(b.CreateExtractElement(h, uint64_t(1)), b.getInt32Ty());
        return b.CreateOr(lo, b.CreateShl(hi, b.getInt32(16)));
      }
      case GLSLstd450UnpackHalf2x16: {
        Value* lo = b.CreateTrunc(arg(0), b.getInt16Ty());
        Value* hi = b.CreateTrunc(b.CreateLShr(arg(0), b.getInt32(16)), b.getInt16Ty());
        Value* h = UndefValue::get(FixedVectorType::get(b.getInt16Ty(), 2));
        h = b.CreateInsertElement(b.CreateInsertElement(h, lo, uint64_t(0)), hi, uint64_t(1));
        return b.CreateFPExt(b.CreateBitCast(h, FixedVectorType::get(b.getHalfTy(), 2)), rt);
      }
      case GLSLstd450PackDouble2x32: {
        // The first component is the low word.
        Value* lo = b.CreateZExt(b.CreateExtractElement(arg(0), uint64_t(0)), b.getInt64Ty());
        Value* hi = b.CreateZExt(b.CreateExtractElement(arg(0), uint64_t(1)), b.getInt64Ty());
        return b.CreateBitCast(b.CreateOr(lo, b.CreateShl(hi, b.getInt64(32))), rt);
      }
      case GLSLstd450UnpackDouble2x32: {
        Value* bits = b.CreateBitCast(arg(0), b.getInt64Ty());
        Value* lo = b.CreateTrunc(bits, b.getInt32Ty());
        Value* hi = b.CreateTrunc(b.CreateLShr(bits, b.getInt64(32)), b.getInt32Ty());
        return b.CreateInsertElement(b.CreateInsertElement(UndefValue::get(rt), lo, uint64_t(0)), hi, uint64_t(1));
      }
      default: return nullptr;
    }
  }
};

}  // namespace

// The component-by-component instructions, and frexp/modf with their pointer operands, are emitted here; those on
// whole vectors (Std::geometric), matrices (Std::matrix) and the packing family (Std::packing) by Std.
bool Codegen::extInst(const Instruction& in, bool& ok) {
  if (in.op != spv::OpExtInst) return false;
  if (debugPrintfSet && in.word(3) == debugPrintfSet) return debugPrintf(in, ok), true;
  if (in.word(3) != glslSet || glslSet == 0) return (ok = unsupported(in, "extended instruction set")), true;
  uint32_t inst = in.word(4);
  if (inst == GLSLstd450InterpolateAtCentroid || inst == GLSLstd450InterpolateAtSample ||
      inst == GLSLstd450InterpolateAtOffset)
    return interpolateAt(in, inst, ok);
  llvm::Type* rt = type(in.word(1));
  std::vector<llvm::Value*> a;
  for (uint32_t i = 5; i < in.count; ++i) {
    llvm::Value* v = value(in.word(i));
    if (!v && !(hasPtr(in.word(i)) || globals.count(in.word(i)))) return (ok = fail(in, "operand has no value")), true;
    a.push_back(v);
  }
  Std s{*this, b, a};
  auto arg = [&](size_t i) { return s.arg(i); };
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
      Value* pos = b.CreateSelect(b.CreateFCmpOGT(x, s.fconst(x->getType(), 0)), s.fconst(x->getType(), 1),
                                  s.fconst(x->getType(), 0));
      r = b.CreateSelect(b.CreateFCmpOLT(x, s.fconst(x->getType(), 0)), s.fconst(x->getType(), -1), pos);
      break;
    }
    case GLSLstd450SSign: {
      Value* x = arg(0);
      llvm::Type* t = x->getType();
      r = b.CreateSelect(b.CreateICmpSGT(x, llvm::Constant::getNullValue(t)), ConstantInt::get(t, 1),
                         b.CreateSelect(b.CreateICmpSLT(x, llvm::Constant::getNullValue(t)),
                                        llvm::Constant::getAllOnesValue(t), llvm::Constant::getNullValue(t)));
      break;
    }
    case GLSLstd450Floor: r = s.intr(Intrinsic::floor, arg(0)); break;
    case GLSLstd450Ceil: r = s.intr(Intrinsic::ceil, arg(0)); break;
    case GLSLstd450Fract: r = b.CreateFSub(arg(0), s.intr(Intrinsic::floor, arg(0))); break;
    case GLSLstd450Radians:
      r = b.CreateFMul(arg(0), s.fconst(arg(0)->getType(), 3.14159265358979323846 / 180.0));
      break;
    case GLSLstd450Degrees:
      r = b.CreateFMul(arg(0), s.fconst(arg(0)->getType(), 180.0 / 3.14159265358979323846));
      break;
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
    case GLSLstd450InverseSqrt:
      r = b.CreateFDiv(s.fconst(arg(0)->getType(), 1.0), s.intr(Intrinsic::sqrt, arg(0)));
      break;
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
      Value* t = s.clampF(b.CreateFDiv(b.CreateFSub(arg(2), arg(0)), b.CreateFSub(arg(1), arg(0))), s.fconst(rt, 0),
                          s.fconst(rt, 1));
      r = b.CreateFMul(b.CreateFMul(t, t), b.CreateFSub(s.fconst(rt, 3), b.CreateFMul(s.fconst(rt, 2), t)));
      break;
    }
    case GLSLstd450Fma: r = b.CreateIntrinsic(Intrinsic::fma, {rt}, {arg(0), arg(1), arg(2)}); break;
    case GLSLstd450Ldexp: r = s.ldexp(arg(0), arg(1)); break;
    case GLSLstd450Length:
    case GLSLstd450Distance:
    case GLSLstd450Normalize:
    case GLSLstd450Cross:
    case GLSLstd450FaceForward:
    case GLSLstd450Reflect:
    case GLSLstd450Refract: r = s.geometric(inst, rt); break;
    case GLSLstd450FindILsb: {
      Value* x = arg(0);
      Value* tz = b.CreateBinaryIntrinsic(Intrinsic::cttz, x, b.getFalse());
      r = b.CreateSelect(b.CreateICmpEQ(x, llvm::Constant::getNullValue(x->getType())),
                         llvm::Constant::getAllOnesValue(x->getType()), tz);
      break;
    }
    case GLSLstd450FindUMsb:
    case GLSLstd450FindSMsb: {
      Value* x = arg(0);
      llvm::Type* t = x->getType();
      unsigned w = t->getScalarSizeInBits();
      if (inst == GLSLstd450FindSMsb)
        x = b.CreateSelect(b.CreateICmpSLT(x, llvm::Constant::getNullValue(t)), b.CreateNot(x), x);
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
    case GLSLstd450MatrixInverse:
      r = s.matrix(inst);
      if (!r) return (ok = fail(in, "determinant/inverse of a matrix that is not 2x2, 3x3 or 4x4")), true;
      break;
    case GLSLstd450Frexp:
    case GLSLstd450FrexpStruct: {
      if (inst == GLSLstd450Frexp) {
        Ptr& p = ptr(in.word(6));
        if (!p.base || p.slot >= 0) return (ok = fail(in, "frexp's pointer operand is not tracked")), true;
        auto [sig, exp] = s.frexp(arg(0), type(p.type));
        store(p, exp);
        r = sig;
      } else {
        auto [sig, exp] = s.frexp(arg(0), cast<StructType>(rt)->getElementType(1));
        r = b.CreateInsertValue(b.CreateInsertValue(UndefValue::get(rt), sig, {0}), exp, {1});
      }
      break;
    }
    case GLSLstd450PackSnorm4x8:
    case GLSLstd450PackUnorm4x8:
    case GLSLstd450PackSnorm2x16:
    case GLSLstd450PackUnorm2x16:
    case GLSLstd450UnpackSnorm4x8:
    case GLSLstd450UnpackUnorm4x8:
    case GLSLstd450UnpackSnorm2x16:
    case GLSLstd450UnpackUnorm2x16:
    case GLSLstd450PackHalf2x16:
    case GLSLstd450UnpackHalf2x16:
    case GLSLstd450PackDouble2x32:
    case GLSLstd450UnpackDouble2x32: r = s.packing(inst, rt); break;
    default: return (ok = unsupported(in, "GLSL.std.450 instruction")), true;
  }
  if (!r) return (ok = fail(in, "operand has no value")), true;
  set(in.word(2), r);
  return true;
}

}  // namespace vkrt::spirv
