// SPIR-V -> LLVM IR: integer, float and bool arithmetic, comparisons, bit operations, conversions, matrix
// operations and composites. Operations that trap on x86 or give LLVM poison (division by zero, INT_MIN / -1,
// oversized shifts, out-of-range float -> int) are made total: SPIR-V leaves their results undefined, and
// vkrt must not crash on them.
#include <llvm/IR/Constants.h>
#include <llvm/IR/Intrinsics.h>

#include "spirv/codegen.hpp"

namespace vkrt::spirv {

namespace {

llvm::Value* zeroLike(llvm::Type* t) { return llvm::Constant::getNullValue(t); }
llvm::Value* onesLike(llvm::Type* t) { return llvm::Constant::getAllOnesValue(t); }
llvm::Value* intLike(llvm::Type* t, uint64_t v) { return llvm::ConstantInt::get(t, v); }
llvm::Value* zeroLikeFloat(llvm::Type* t) { return llvm::ConstantFP::get(t, 0.0); }
// `scalar`, or a vector of it as wide as `like`.
llvm::Type* splatType(llvm::Type* scalar, llvm::Type* like) {
  if (auto* vt = llvm::dyn_cast<llvm::FixedVectorType>(like))
    return llvm::FixedVectorType::get(scalar, vt->getNumElements());
  return scalar;
}

// Shift amounts are taken modulo the width (the result is undefined in SPIR-V beyond it).
llvm::Value* shiftAmount(llvm::IRBuilder<>& b, llvm::Value* amount, llvm::Type* ty) {
  amount = b.CreateZExtOrTrunc(amount, ty);
  unsigned w = ty->getScalarSizeInBits();
  return b.CreateAnd(amount, intLike(ty, w - 1));
}

// Reads the result type of `in` into *rt and says whether it and the operands at word indices `idx` have values.
bool operandsReady(Codegen& g, const Instruction& in, std::initializer_list<uint32_t> idx, llvm::Type** rt) {
  *rt = g.type(in.word(1));
  if (!*rt) return false;
  for (uint32_t i : idx) {
    if (!g.value(in.word(i))) return false;
  }
  return true;
}

}  // namespace

bool Codegen::arithmetic(const Instruction& in, bool& ok) {
  auto operand = [&](uint32_t i) { return value(in.word(i)); };
  uint32_t result = in.word(2);
  llvm::Type* rt = nullptr;
  auto need = [&](std::initializer_list<uint32_t> idx) { return operandsReady(*this, in, idx, &rt); };
  auto binary = [&](auto make) -> bool {
    if (!need({3, 4})) return (ok = fail(in, "operand has no value")), true;
    set(result, make(operand(3), operand(4)));
    return true;
  };
  auto unaryOp = [&](auto make) -> bool {
    if (!need({3})) return (ok = fail(in, "operand has no value")), true;
    set(result, make(operand(3)));
    return true;
  };
  switch (in.op) {
    case spv::OpIAdd: return binary([&](auto a, auto c) { return b.CreateAdd(a, c); });
    case spv::OpISub: return binary([&](auto a, auto c) { return b.CreateSub(a, c); });
    case spv::OpIMul: return binary([&](auto a, auto c) { return b.CreateMul(a, c); });
    case spv::OpUDiv:
    case spv::OpUMod:
      return binary([&](llvm::Value* a, llvm::Value* d) {
        llvm::Value* zero = b.CreateICmpEQ(d, zeroLike(d->getType()));
        llvm::Value* safe = b.CreateSelect(zero, intLike(d->getType(), 1), d);
        llvm::Value* r = in.op == spv::OpUDiv ? b.CreateUDiv(a, safe) : b.CreateURem(a, safe);
        return b.CreateSelect(zero, zeroLike(d->getType()), r);
      });
    case spv::OpSDiv:
    case spv::OpSRem:
    case spv::OpSMod:
      return binary([&](llvm::Value* a, llvm::Value* d) {
        llvm::Type* t = d->getType();
        // d == 0 and d == -1 (INT_MIN / -1 traps) take the divide-by-one path; -1 is fixed up below.
        llvm::Value* zero = b.CreateICmpEQ(d, zeroLike(t));
        llvm::Value* minus1 = b.CreateICmpEQ(d, onesLike(t));
        llvm::Value* safe = b.CreateSelect(b.CreateOr(zero, minus1), intLike(t, 1), d);
        llvm::Value* r;
        if (in.op == spv::OpSDiv) {
          r = b.CreateSelect(minus1, b.CreateNeg(a), b.CreateSDiv(a, safe));
        } else {
          llvm::Value* rem = b.CreateSRem(a, safe);
          if (in.op == spv::OpSMod) {
            // The result takes the divisor's sign.
            llvm::Value* fix =
                b.CreateAnd(b.CreateICmpNE(rem, zeroLike(t)),
                            b.CreateICmpNE(b.CreateICmpSLT(rem, zeroLike(t)), b.CreateICmpSLT(d, zeroLike(t))));
            rem = b.CreateSelect(fix, b.CreateAdd(rem, d), rem);
          }
          r = b.CreateSelect(minus1, zeroLike(t), rem);
        }
        return b.CreateSelect(zero, zeroLike(t), r);
      });
    case spv::OpFAdd: return binary([&](auto a, auto c) { return b.CreateFAdd(a, c); });
    case spv::OpFSub: return binary([&](auto a, auto c) { return b.CreateFSub(a, c); });
    case spv::OpFMul: return binary([&](auto a, auto c) { return b.CreateFMul(a, c); });
    case spv::OpFDiv: return binary([&](auto a, auto c) { return b.CreateFDiv(a, c); });
    case spv::OpFRem: return binary([&](auto a, auto c) { return b.CreateFRem(a, c); });
    case spv::OpFMod:
      return binary([&](llvm::Value* x, llvm::Value* y) {
        llvm::Value* q = b.CreateUnaryIntrinsic(llvm::Intrinsic::floor, b.CreateFDiv(x, y));
        return b.CreateFSub(x, b.CreateFMul(y, q));
      });
    case spv::OpFNegate: return unaryOp([&](auto a) { return b.CreateFNeg(a); });
    case spv::OpSNegate: return unaryOp([&](auto a) { return b.CreateNeg(a); });
    case spv::OpNot: return unaryOp([&](auto a) { return b.CreateNot(a); });
    case spv::OpLogicalNot: return unaryOp([&](auto a) { return b.CreateNot(a); });
    case spv::OpBitwiseAnd:
    case spv::OpLogicalAnd: return binary([&](auto a, auto c) { return b.CreateAnd(a, c); });
    case spv::OpBitwiseOr:
    case spv::OpLogicalOr: return binary([&](auto a, auto c) { return b.CreateOr(a, c); });
    case spv::OpBitwiseXor:
    case spv::OpLogicalNotEqual: return binary([&](auto a, auto c) { return b.CreateXor(a, c); });
    case spv::OpLogicalEqual: return binary([&](auto a, auto c) { return b.CreateICmpEQ(a, c); });
    case spv::OpShiftLeftLogical:
      return binary([&](llvm::Value* a, llvm::Value* s) { return b.CreateShl(a, shiftAmount(b, s, a->getType())); });
    case spv::OpShiftRightLogical:
      return binary([&](llvm::Value* a, llvm::Value* s) { return b.CreateLShr(a, shiftAmount(b, s, a->getType())); });
    case spv::OpShiftRightArithmetic:
      return binary([&](llvm::Value* a, llvm::Value* s) { return b.CreateAShr(a, shiftAmount(b, s, a->getType())); });
    case spv::OpIEqual: return binary([&](auto a, auto c) { return b.CreateICmpEQ(a, c); });
    case spv::OpINotEqual: return binary([&](auto a, auto c) { return b.CreateICmpNE(a, c); });
    case spv::OpUGreaterThan: return binary([&](auto a, auto c) { return b.CreateICmpUGT(a, c); });
    case spv::OpSGreaterThan: return binary([&](auto a, auto c) { return b.CreateICmpSGT(a, c); });
    case spv::OpUGreaterThanEqual: return binary([&](auto a, auto c) { return b.CreateICmpUGE(a, c); });
    case spv::OpSGreaterThanEqual: return binary([&](auto a, auto c) { return b.CreateICmpSGE(a, c); });
    case spv::OpULessThan: return binary([&](auto a, auto c) { return b.CreateICmpULT(a, c); });
    case spv::OpSLessThan: return binary([&](auto a, auto c) { return b.CreateICmpSLT(a, c); });
    case spv::OpULessThanEqual: return binary([&](auto a, auto c) { return b.CreateICmpULE(a, c); });
    case spv::OpSLessThanEqual: return binary([&](auto a, auto c) { return b.CreateICmpSLE(a, c); });
    case spv::OpFOrdEqual: return binary([&](auto a, auto c) { return b.CreateFCmpOEQ(a, c); });
    case spv::OpFUnordEqual: return binary([&](auto a, auto c) { return b.CreateFCmpUEQ(a, c); });
    case spv::OpFOrdNotEqual: return binary([&](auto a, auto c) { return b.CreateFCmpONE(a, c); });
    case spv::OpFUnordNotEqual: return binary([&](auto a, auto c) { return b.CreateFCmpUNE(a, c); });
    case spv::OpFOrdLessThan: return binary([&](auto a, auto c) { return b.CreateFCmpOLT(a, c); });
    case spv::OpFUnordLessThan: return binary([&](auto a, auto c) { return b.CreateFCmpULT(a, c); });
    case spv::OpFOrdGreaterThan: return binary([&](auto a, auto c) { return b.CreateFCmpOGT(a, c); });
    case spv::OpFUnordGreaterThan: return binary([&](auto a, auto c) { return b.CreateFCmpUGT(a, c); });
    case spv::OpFOrdLessThanEqual: return binary([&](auto a, auto c) { return b.CreateFCmpOLE(a, c); });
    case spv::OpFUnordLessThanEqual: return binary([&](auto a, auto c) { return b.CreateFCmpULE(a, c); });
    case spv::OpFOrdGreaterThanEqual: return binary([&](auto a, auto c) { return b.CreateFCmpOGE(a, c); });
    case spv::OpFUnordGreaterThanEqual: return binary([&](auto a, auto c) { return b.CreateFCmpUGE(a, c); });
    case spv::OpIsNan: return unaryOp([&](auto a) { return b.CreateFCmpUNO(a, a); });
    case spv::OpIsInf:
      return unaryOp([&](llvm::Value* a) {
        llvm::Value* abs = b.CreateUnaryIntrinsic(llvm::Intrinsic::fabs, a);
        return b.CreateFCmpOEQ(abs, llvm::ConstantFP::getInfinity(a->getType()));
      });
    case spv::OpAny: return unaryOp([&](auto a) { return b.CreateOrReduce(a); });
    case spv::OpAll: return unaryOp([&](auto a) { return b.CreateAndReduce(a); });
    case spv::OpSelect: {
      if (!need({3, 4, 5})) return (ok = fail(in, "operand has no value")), true;
      llvm::Value* cond = operand(3);
      // A scalar condition with vector (or composite) objects selects whole objects.
      set(result, b.CreateSelect(cond, operand(4), operand(5)));
      return true;
    }
    case spv::OpBitCount:
      return unaryOp(
          [&](llvm::Value* a) { return b.CreateZExtOrTrunc(b.CreateUnaryIntrinsic(llvm::Intrinsic::ctpop, a), rt); });
    case spv::OpBitReverse:
      return unaryOp([&](llvm::Value* a) { return b.CreateUnaryIntrinsic(llvm::Intrinsic::bitreverse, a); });
    case spv::OpBitFieldInsert:
    case spv::OpBitFieldSExtract:
    case spv::OpBitFieldUExtract: {
      bool insert = in.op == spv::OpBitFieldInsert;
      if (!need(insert ? std::initializer_list<uint32_t>{3, 4, 5, 6} : std::initializer_list<uint32_t>{3, 4, 5}))
        return (ok = fail(in, "operand has no value")), true;
      llvm::Type* t = rt;
      unsigned w = t->getScalarSizeInBits();
      llvm::Value* off = splat(b.CreateZExtOrTrunc(operand(insert ? 5 : 4), t->getScalarType()), t);
      llvm::Value* cnt = splat(b.CreateZExtOrTrunc(operand(insert ? 6 : 5), t->getScalarType()), t);
      // mask = count == w ? ~0 : (1 << count) - 1, with the shift made total.
      llvm::Value* full = b.CreateICmpUGE(cnt, intLike(t, w));
      llvm::Value* mask =
          b.CreateSelect(full, onesLike(t),
                         b.CreateSub(b.CreateShl(intLike(t, 1), b.CreateAnd(cnt, intLike(t, w - 1))), intLike(t, 1)));
      llvm::Value* offM = b.CreateAnd(off, intLike(t, w - 1));
      if (insert) {
        llvm::Value* m2 = b.CreateShl(mask, offM);
        set(result,
            b.CreateOr(b.CreateAnd(operand(3), b.CreateNot(m2)), b.CreateAnd(b.CreateShl(operand(4), offM), m2)));
      } else {
        llvm::Value* v = b.CreateAnd(b.CreateLShr(operand(3), offM), mask);
        if (in.op == spv::OpBitFieldSExtract) {
          // Sign-extend from bit count-1: shift left then arithmetic right by (w - count).
          llvm::Value* sh = b.CreateAnd(b.CreateSub(intLike(t, w), cnt), intLike(t, w - 1));
          llvm::Value* ext = b.CreateAShr(b.CreateShl(v, sh), sh);
          v = b.CreateSelect(b.CreateICmpEQ(cnt, zeroLike(t)), zeroLike(t), ext);
        }
        set(result, v);
      }
      return true;
    }
    case spv::OpIAddCarry:
    case spv::OpISubBorrow:
    case spv::OpUMulExtended:
    case spv::OpSMulExtended: {
      if (!need({3, 4})) return (ok = fail(in, "operand has no value")), true;
      llvm::Value* a = operand(3);
      llvm::Value* c2 = operand(4);
      llvm::Value* lo;
      llvm::Value* hi;
      llvm::Type* t = a->getType();
      if (in.op == spv::OpIAddCarry) {
        lo = b.CreateAdd(a, c2);
        hi = b.CreateZExt(b.CreateICmpULT(lo, a), t);
      } else if (in.op == spv::OpISubBorrow) {
        lo = b.CreateSub(a, c2);
        hi = b.CreateZExt(b.CreateICmpULT(a, c2), t);
      } else {
        unsigned w = t->getScalarSizeInBits();
        llvm::Type* wide = t->getWithNewBitWidth(2 * w);
        bool s = in.op == spv::OpSMulExtended;
        llvm::Value* p = b.CreateMul(s ? b.CreateSExt(a, wide) : b.CreateZExt(a, wide),
                                     s ? b.CreateSExt(c2, wide) : b.CreateZExt(c2, wide));
        lo = b.CreateTrunc(p, t);
        hi = b.CreateTrunc(b.CreateLShr(p, intLike(wide, w)), t);
      }
      llvm::Value* r = llvm::UndefValue::get(rt);
      r = b.CreateInsertValue(r, lo, {0});
      set(result, b.CreateInsertValue(r, hi, {1}));
      return true;
    }
    // ---- conversions
    case spv::OpConvertFToU:
    case spv::OpConvertFToS:
      return unaryOp([&](llvm::Value* a) -> llvm::Value* {
        // Saturating: out-of-range values clamp and NaN gives 0, instead of poison.
        auto id = in.op == spv::OpConvertFToU ? llvm::Intrinsic::fptoui_sat : llvm::Intrinsic::fptosi_sat;
        return b.CreateIntrinsic(id, {rt, a->getType()}, {a});
      });
    case spv::OpConvertSToF: return unaryOp([&](auto a) { return b.CreateSIToFP(a, rt); });
    case spv::OpConvertUToF: return unaryOp([&](auto a) { return b.CreateUIToFP(a, rt); });
    case spv::OpUConvert: return unaryOp([&](auto a) { return b.CreateZExtOrTrunc(a, rt); });
    case spv::OpSConvert: return unaryOp([&](auto a) { return b.CreateSExtOrTrunc(a, rt); });
    case spv::OpFConvert:
      return unaryOp([&](llvm::Value* a) {
        unsigned from = a->getType()->getScalarSizeInBits(), to = rt->getScalarSizeInBits();
        if (to >= from) return b.CreateFPCast(a, rt);
        llvm::Value* r = from == 64 && to == 16 ? truncDoubleToHalf(a) : b.CreateFPTrunc(a, rt);
        return m.decor(result).fpRoundingMode == spv::FPRoundingModeRTZ ? roundTowardZero(a, r) : r;
      });
    case spv::OpQuantizeToF16:
      // Rounded to a 16-bit float (to nearest even: infinities and NaNs stay, magnitudes past 65504 round to
      // infinity), then back; a result below the smallest normal half (2^-14) may be either zero, and is the zero
      // of the input's sign.
      return unaryOp([&](llvm::Value* a) {
        llvm::Type* half = splatType(b.getHalfTy(), a->getType());
        llvm::Value* q = b.CreateFPExt(b.CreateFPTrunc(a, half), a->getType());
        llvm::Value* abs = b.CreateUnaryIntrinsic(llvm::Intrinsic::fabs, q);
        llvm::Value* tiny = b.CreateFCmpOLT(abs, llvm::ConstantFP::get(a->getType(), 0x1p-14));
        llvm::Value* zero = b.CreateBinaryIntrinsic(llvm::Intrinsic::copysign, zeroLikeFloat(a->getType()), a);
        return b.CreateSelect(tiny, zero, q);
      });
    case spv::OpBitcast: {
      if (!need({3})) return (ok = fail(in, "operand has no value")), true;
      llvm::Value* a = operand(3);
      if (a->getType()->isPointerTy() || rt->isPointerTy() ||
          a->getType()->getPrimitiveSizeInBits() != rt->getPrimitiveSizeInBits())
        return (ok = unsupported(in, "bitcast between these types")), true;
      set(result, b.CreateBitCast(a, rt));
      return true;
    }
    case spv::OpCopyObject:
    case spv::OpCopyLogical: {
      if (hasPtr(in.word(3)) || globals.count(in.word(3))) {
        ptrs[result] = ptr(in.word(3));
        // A PhysicalStorageBuffer pointer is a value too (an OpSelect or a store may take the copy).
        if (auto it = values.find(in.word(3)); it != values.end()) set(result, it->second);
        return true;
      }
      return unaryOp([&](auto a) { return a; });
    }
    // ---- integer dot products (SPV_KHR_integer_dot_product)
    case spv::OpSDot:
    case spv::OpUDot:
    case spv::OpSUDot:
    case spv::OpSDotAccSat:
    case spv::OpUDotAccSat:
    case spv::OpSUDotAccSat: {
      bool acc = dotAccSatOp(in.op);
      if (!need(acc ? std::initializer_list<uint32_t>{3, 4, 5} : std::initializer_list<uint32_t>{3, 4}))
        return (ok = fail(in, "operand has no value")), true;
      set(result,
          integerDot(in.op, operand(3), operand(4), acc ? operand(5) : nullptr, in.count > (acc ? 6u : 5u), rt));
      return true;
    }
    // ---- vectors and matrices
    case spv::OpDot:
      return binary([&](llvm::Value* x, llvm::Value* y) {
        return b.CreateFAddReduce(llvm::ConstantFP::get(rt, 0.0), b.CreateFMul(x, y));
      });
    case spv::OpVectorTimesScalar:
      return binary([&](llvm::Value* v, llvm::Value* s) { return b.CreateFMul(v, splat(s, v->getType())); });
    case spv::OpMatrixTimesScalar:
      return binary([&](llvm::Value* mat, llvm::Value* s) {
        llvm::Value* r = llvm::UndefValue::get(rt);
        unsigned cols = llvm::cast<llvm::ArrayType>(rt)->getNumElements();
        for (unsigned i = 0; i < cols; ++i) {
          llvm::Value* col = b.CreateExtractValue(mat, {i});
          r = b.CreateInsertValue(r, b.CreateFMul(col, splat(s, col->getType())), {i});
        }
        return r;
      });
    case spv::OpMatrixTimesVector:
      return binary([&](llvm::Value* mat, llvm::Value* v) {
        unsigned cols = llvm::cast<llvm::ArrayType>(mat->getType())->getNumElements();
        llvm::Value* r = nullptr;
        for (unsigned i = 0; i < cols; ++i) {
          llvm::Value* term =
              b.CreateFMul(b.CreateExtractValue(mat, {i}), splat(b.CreateExtractElement(v, uint64_t(i)), rt));
          r = r ? b.CreateFAdd(r, term) : term;
        }
        return r;
      });
    case spv::OpVectorTimesMatrix:
      return binary([&](llvm::Value* v, llvm::Value* mat) {
        unsigned cols = llvm::cast<llvm::ArrayType>(mat->getType())->getNumElements();
        llvm::Value* r = llvm::UndefValue::get(rt);
        for (unsigned i = 0; i < cols; ++i) {
          llvm::Value* d = b.CreateFAddReduce(llvm::ConstantFP::get(rt->getScalarType(), 0.0),
                                              b.CreateFMul(v, b.CreateExtractValue(mat, {i})));
          r = b.CreateInsertElement(r, d, uint64_t(i));
        }
        return r;
      });
    case spv::OpMatrixTimesMatrix:
      return binary([&](llvm::Value* l, llvm::Value* r2) {
        unsigned inner = llvm::cast<llvm::ArrayType>(l->getType())->getNumElements();
        unsigned cols = llvm::cast<llvm::ArrayType>(rt)->getNumElements();
        llvm::Value* r = llvm::UndefValue::get(rt);
        for (unsigned j = 0; j < cols; ++j) {
          llvm::Value* rc = b.CreateExtractValue(r2, {j});
          llvm::Value* acc = nullptr;
          for (unsigned k = 0; k < inner; ++k) {
            llvm::Value* lc = b.CreateExtractValue(l, {k});
            llvm::Value* term = b.CreateFMul(lc, splat(b.CreateExtractElement(rc, uint64_t(k)), lc->getType()));
            acc = acc ? b.CreateFAdd(acc, term) : term;
          }
          r = b.CreateInsertValue(r, acc, {j});
        }
        return r;
      });
    case spv::OpOuterProduct:
      return binary([&](llvm::Value* x, llvm::Value* y) {
        unsigned cols = llvm::cast<llvm::ArrayType>(rt)->getNumElements();
        llvm::Value* r = llvm::UndefValue::get(rt);
        for (unsigned i = 0; i < cols; ++i)
          r = b.CreateInsertValue(r, b.CreateFMul(x, splat(b.CreateExtractElement(y, uint64_t(i)), x->getType())), {i});
        return r;
      });
    case spv::OpTranspose:
      return unaryOp([&](llvm::Value* mat) {
        unsigned cols = llvm::cast<llvm::ArrayType>(rt)->getNumElements();
        unsigned rows =
            llvm::cast<llvm::FixedVectorType>(llvm::cast<llvm::ArrayType>(rt)->getElementType())->getNumElements();
        llvm::Value* r = llvm::UndefValue::get(rt);
        for (unsigned i = 0; i < cols; ++i) {
          llvm::Value* col = llvm::UndefValue::get(llvm::cast<llvm::ArrayType>(rt)->getElementType());
          for (unsigned j = 0; j < rows; ++j)
            col = b.CreateInsertElement(col, b.CreateExtractElement(b.CreateExtractValue(mat, {j}), uint64_t(i)),
                                        uint64_t(j));
          r = b.CreateInsertValue(r, col, {i});
        }
        return r;
      });
    default: return subgroup(in, ok);
  }
}

// The subgroup instructions (Codegen::arithmetic passes them on).
bool Codegen::subgroup(const Instruction& in, bool& ok) {
  auto operand = [&](uint32_t i) { return value(in.word(i)); };
  uint32_t resultType = in.word(1);
  uint32_t result = in.word(2);
  llvm::Type* rt = nullptr;
  auto need = [&](std::initializer_list<uint32_t> idx) { return operandsReady(*this, in, idx, &rt); };
  switch (in.op) {
    // ---- subgroups of one invocation (subgroupSize 1; basic, vote and ballot operations): each invocation is elected
    case spv::OpGroupNonUniformElect: set(result, b.getTrue()); return true;
    // Vote: the one invocation's predicate is the subgroup's; its value equals itself.
    case spv::OpGroupNonUniformAllEqual: set(result, b.getTrue()); return true;
    case spv::OpGroupNonUniformAll:
    case spv::OpGroupNonUniformAny:
    // Ballot: every broadcast reads the only invocation, whatever the id (constant or dynamic: an id of another
    // invocation is undefined behaviour) and whatever the value's type (subgroupExtendedTypes); a ballot has bit 0.
    case spv::OpGroupNonUniformBroadcast:
    case spv::OpGroupNonUniformBroadcastFirst:
      if (!need({4})) return (ok = fail(in, "operand has no value")), true;
      set(result, operand(4));
      return true;
    case spv::OpGroupNonUniformBallot: {
      if (!need({4})) return (ok = fail(in, "operand has no value")), true;
      llvm::Value* v = llvm::Constant::getNullValue(rt);
      set(result, b.CreateInsertElement(v, b.CreateZExt(operand(4), rt->getScalarType()), uint64_t(0)));
      return true;
    }
    case spv::OpGroupNonUniformInverseBallot:
      // The bit of the invocation's own index, 0.
      if (!need({4})) return (ok = fail(in, "operand has no value")), true;
      set(result, b.CreateTrunc(b.CreateExtractElement(operand(4), uint64_t(0)), b.getInt1Ty()));
      return true;
    case spv::OpGroupNonUniformBallotBitExtract: {
      if (!need({4, 5})) return (ok = fail(in, "operand has no value")), true;
      llvm::Value* index = b.CreateZExtOrTrunc(operand(5), b.getInt32Ty());
      llvm::Value* word = b.CreateExtractElement(operand(4), b.CreateAnd(b.CreateLShr(index, 5), 3));
      set(result, b.CreateTrunc(b.CreateLShr(word, b.CreateAnd(index, 31)), b.getInt1Ty()));
      return true;
    }
    case spv::OpGroupNonUniformBallotBitCount: {
      // Only bit 0 counts (the bits of the subgroup's invocations); an exclusive scan counts none.
      if (!need({5})) return (ok = fail(in, "operand has no value")), true;
      llvm::Value* bit = b.CreateAnd(b.CreateExtractElement(operand(5), uint64_t(0)), 1);
      set(result, in.word(4) == spv::GroupOperationExclusiveScan ? llvm::Constant::getNullValue(rt)
                                                                 : b.CreateZExtOrTrunc(bit, rt));
      return true;
    }
    case spv::OpGroupNonUniformBallotFindLSB:
    case spv::OpGroupNonUniformBallotFindMSB:
      // Only bit 0 is considered: it is the answer when set, and any answer is allowed when it is not.
      set(result, llvm::Constant::getNullValue(type(resultType)));
      return true;
    default: return false;
  }
}

// double -> half without a library call (LLVM would call __truncdfhf2, which the JIT does not have): rounded to
// a float with round-to-odd, then to a half to nearest even. A float keeps more than twice the half's 11 bits of
// precision plus two, so the two roundings give the correctly rounded half (the round-to-odd argument).
llvm::Value* Codegen::truncDoubleToHalf(llvm::Value* d) {
  llvm::Type* dt = d->getType();
  llvm::Type* ft = splatType(b.getFloatTy(), dt);
  llvm::Type* it = splatType(b.getInt32Ty(), dt);
  llvm::Value* f = b.CreateFPTrunc(d, ft);
  llvm::Value* inexact = b.CreateFCmpUNE(b.CreateFPExt(f, dt), d);
  // Toward zero first, then the sticky bit where the float is not exact.
  llvm::Value* bits = b.CreateBitCast(roundTowardZero(d, f), it);
  bits = b.CreateSelect(inexact, b.CreateOr(bits, intLike(it, 1)), bits);
  return b.CreateFPTrunc(b.CreateBitCast(bits, ft), splatType(b.getHalfTy(), dt));
}

// A narrowing conversion under FPRoundingMode RTZ (16-bit storage allows the decoration on OpFConvert; Vulkan
// allows RTE and RTZ only): `r` is `x` rounded to nearest even; where that rounded away from zero, the neighbour
// one ulp toward zero is the answer (stepping the bits by -1: an infinity becomes the largest finite value). NaNs
// compare false and stay.
llvm::Value* Codegen::roundTowardZero(llvm::Value* x, llvm::Value* r) {
  llvm::Type* it = splatType(b.getIntNTy(r->getType()->getScalarSizeInBits()), r->getType());
  llvm::Value* back = b.CreateFPExt(r, x->getType());
  llvm::Value* away = b.CreateFCmpOGT(b.CreateUnaryIntrinsic(llvm::Intrinsic::fabs, back),
                                      b.CreateUnaryIntrinsic(llvm::Intrinsic::fabs, x));
  llvm::Value* bits = b.CreateBitCast(r, it);
  return b.CreateBitCast(b.CreateSelect(away, b.CreateSub(bits, intLike(it, 1)), bits), r->getType());
}

// OpSDot/UDot/SUDot and their AccSat forms: the components (a 32-bit scalar is four packed 8-bit ones with
// PackedVectorFormat4x8Bit) are extended by the signedness the opcode gives (S: both signed, U: both unsigned, SU:
// the first signed, the second unsigned), multiplied and summed in 128 bits, which no product or sum of these
// widths overflows. The plain forms wrap to the result's width; the AccSat forms add the accumulator and
// saturate to the result's range, signed unless the opcode is UDotAccSat.
llvm::Value* Codegen::integerDot(spv::Op op, llvm::Value* a, llvm::Value* c, llvm::Value* accumulator, bool packed,
                                 llvm::Type* rt) {
  if (packed) {
    llvm::Type* v4i8 = llvm::FixedVectorType::get(b.getInt8Ty(), 4);
    a = b.CreateBitCast(a, v4i8);
    c = b.CreateBitCast(c, v4i8);
  }
  bool firstSigned = op == spv::OpSDot || op == spv::OpSDotAccSat || op == spv::OpSUDot || op == spv::OpSUDotAccSat;
  bool secondSigned = op == spv::OpSDot || op == spv::OpSDotAccSat;
  llvm::Type* wide = b.getIntNTy(128);
  llvm::Type* wideVec = splatType(wide, a->getType());
  llvm::Value* x = firstSigned ? b.CreateSExt(a, wideVec) : b.CreateZExt(a, wideVec);
  llvm::Value* y = secondSigned ? b.CreateSExt(c, wideVec) : b.CreateZExt(c, wideVec);
  llvm::Value* products = b.CreateMul(x, y);
  llvm::Value* dot = products->getType()->isVectorTy() ? b.CreateAddReduce(products) : products;
  if (!accumulator) return b.CreateTrunc(dot, rt);
  bool signedResult = op != spv::OpUDotAccSat;
  unsigned w = rt->getIntegerBitWidth();
  llvm::Value* sum = b.CreateAdd(dot, signedResult ? b.CreateSExt(accumulator, wide) : b.CreateZExt(accumulator, wide));
  llvm::APInt lo = signedResult ? llvm::APInt::getSignedMinValue(w) : llvm::APInt::getMinValue(w);
  llvm::APInt hi = signedResult ? llvm::APInt::getSignedMaxValue(w) : llvm::APInt::getMaxValue(w);
  llvm::Value* loW = llvm::ConstantInt::get(wide, signedResult ? lo.sext(128) : lo.zext(128));
  llvm::Value* hiW = llvm::ConstantInt::get(wide, signedResult ? hi.sext(128) : hi.zext(128));
  sum = b.CreateSelect(b.CreateICmpSLT(sum, loW), loW, sum);
  sum = b.CreateSelect(b.CreateICmpSGT(sum, hiW), hiW, sum);
  return b.CreateTrunc(sum, rt);
}

bool Codegen::composite(const Instruction& in, bool& ok) {
  uint32_t result = in.word(2);
  switch (in.op) {
    case spv::OpCompositeConstruct: {
      llvm::Type* rt = type(in.word(1));
      if (!rt) return (ok = unsupported(in, "result type")), true;
      llvm::Value* r = llvm::UndefValue::get(rt);
      if (auto* vt = llvm::dyn_cast<llvm::FixedVectorType>(rt)) {
        // Constituents are scalars or vectors, concatenated.
        uint64_t at = 0;
        for (uint32_t i = 3; i < in.count; ++i) {
          llvm::Value* v = value(in.word(i));
          if (!v) return (ok = fail(in, "constituent has no value")), true;
          if (auto* cv = llvm::dyn_cast<llvm::FixedVectorType>(v->getType())) {
            for (unsigned k = 0; k < cv->getNumElements() && at < vt->getNumElements(); ++k)
              r = b.CreateInsertElement(r, b.CreateExtractElement(v, uint64_t(k)), at++);
          } else if (at < vt->getNumElements()) {
            r = b.CreateInsertElement(r, v, at++);
          }
        }
      } else {
        for (uint32_t i = 3; i < in.count; ++i) {
          llvm::Value* v = value(in.word(i));
          if (!v) return (ok = fail(in, "constituent has no value")), true;
          r = b.CreateInsertValue(r, v, {i - 3});
        }
      }
      set(result, r);
      return true;
    }
    case spv::OpCompositeExtract:
    case spv::OpCompositeInsert: {
      bool insert = in.op == spv::OpCompositeInsert;
      llvm::Value* object = insert ? value(in.word(3)) : nullptr;
      llvm::Value* comp = value(in.word(insert ? 4 : 3));
      if (!comp || (insert && !object)) return (ok = fail(in, "operand has no value")), true;
      // Walk aggregate indices, then at most one vector index.
      std::vector<unsigned> path;
      llvm::Type* t = comp->getType();
      uint32_t i = insert ? 5 : 4;
      for (; i < in.count && !t->isVectorTy(); ++i) {
        path.push_back(in.word(i));
        t = llvm::GetElementPtrInst::getTypeAtIndex(t, uint64_t(in.word(i)));
        if (!t) return (ok = fail(in, "index out of range")), true;
      }
      if (!insert) {
        llvm::Value* v = path.empty() ? comp : b.CreateExtractValue(comp, path);
        if (i < in.count) v = b.CreateExtractElement(v, uint64_t(in.word(i)));
        set(result, v);
      } else if (i < in.count) {
        llvm::Value* inner = path.empty() ? comp : b.CreateExtractValue(comp, path);
        inner = b.CreateInsertElement(inner, object, uint64_t(in.word(i)));
        set(result, path.empty() ? inner : b.CreateInsertValue(comp, inner, path));
      } else {
        set(result, path.empty() ? object : b.CreateInsertValue(comp, object, path));
      }
      return true;
    }
    case spv::OpVectorShuffle: {
      llvm::Value* v1 = value(in.word(3));
      llvm::Value* v2 = value(in.word(4));
      if (!v1 || !v2) return (ok = fail(in, "operand has no value")), true;
      unsigned n1 = llvm::cast<llvm::FixedVectorType>(v1->getType())->getNumElements();
      unsigned n2 = llvm::cast<llvm::FixedVectorType>(v2->getType())->getNumElements();
      llvm::Value* r = llvm::UndefValue::get(type(in.word(1)));
      for (uint32_t i = 5; i < in.count; ++i) {
        uint32_t k = in.word(i);
        llvm::Value* e = k == 0xffffffffu ? llvm::Constant::getNullValue(v1->getType()->getScalarType())
                         : k < n1         ? b.CreateExtractElement(v1, uint64_t(k))
                         : k < n1 + n2    ? b.CreateExtractElement(v2, uint64_t(k - n1))
                                          : nullptr;
        if (!e) return (ok = fail(in, "component index out of range")), true;
        r = b.CreateInsertElement(r, e, uint64_t(i - 5));
      }
      set(result, r);
      return true;
    }
    case spv::OpVectorExtractDynamic:
    case spv::OpVectorInsertDynamic: {
      bool insert = in.op == spv::OpVectorInsertDynamic;
      llvm::Value* v = value(in.word(3));
      llvm::Value* idx = value(in.word(insert ? 5 : 4));
      llvm::Value* comp = insert ? value(in.word(4)) : nullptr;
      if (!v || !idx || (insert && !comp)) return (ok = fail(in, "operand has no value")), true;
      // An index past the end is undefined in SPIR-V; clamp to stay out of poison.
      unsigned n = llvm::cast<llvm::FixedVectorType>(v->getType())->getNumElements();
      idx = b.CreateZExtOrTrunc(idx, b.getInt32Ty());
      idx = b.CreateSelect(b.CreateICmpULT(idx, i32(n)), idx, i32(0));
      set(result, insert ? b.CreateInsertElement(v, comp, idx) : b.CreateExtractElement(v, idx));
      return true;
    }
    default: return false;
  }
}

}  // namespace vkrt::spirv
