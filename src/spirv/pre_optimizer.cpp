// compile()'s steps on the application's SPIR-V words before SPIRV-Tools' optimizer (pre_optimizer.hpp): the
// OpSpecConstantOp check (the optimizer's folding trusts its operands), and the rewrites that leave the optimizer
// and the translation only the compiled entry point and the non-semantic instructions they use.
#include "spirv/pre_optimizer.hpp"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <map>
#include <set>

#include "spirv/shader_debug.hpp"

namespace vkrt::spirv {

namespace {

// OpSpecConstantOp, checked against the rules of the instruction it names before SPIRV-Tools folds it. Debian's
// SPIRV-Tools validator checks none of its operands, and its folding dereferences whatever it is given: an
// OpSpecConstantOp CompositeExtract of a scalar (found by vkrt_fuzz_spirv_pipeline), an index past a composite, a
// VectorShuffle component past both vectors or an OpQuantizeToF16 of an integer crashed the optimizer. The rules
// are the SPIR-V specification's for each opcode that Shader modules may name.
constexpr uint32_t kUndefinedComponent = 0xFFFFFFFF;  // OpVectorShuffle: the component is undefined

class SpecConstantOpCheck {
 public:
  explicit SpecConstantOpCheck(const Module& m) : m_(m) {}

  // Empty when `in` (an OpSpecConstantOp) keeps its opcode's rules, else the rule it breaks.
  std::string broken(const Instruction& in) const {
    const uint32_t result = in.word(1);
    const auto op = spv::Op(in.word(3));
    auto operand = [&](uint32_t k) { return m_.typeOf(in.word(4 + k)); };
    const uint32_t operands = in.count > 4 ? in.count - 4 : 0;
    switch (op) {
      case spv::OpCompositeExtract: {
        if (operands < 2) return "needs a composite and at least one index";
        uint32_t t = operand(0);
        for (uint32_t k = 1; k < operands; ++k)
          if (!(t = member(t, in.word(4 + k)))) return "an index is outside the composite's type";
        return t == result ? "" : "the result type is not the type of the selected part";
      }
      case spv::OpCompositeInsert: {
        if (operands < 3) return "needs an object, a composite and at least one index";
        if (operand(1) != result) return "the composite's type is not the result type";
        uint32_t t = result;
        for (uint32_t k = 2; k < operands; ++k)
          if (!(t = member(t, in.word(4 + k)))) return "an index is outside the composite's type";
        return t == operand(0) ? "" : "the object's type is not the type of the selected part";
      }
      case spv::OpVectorShuffle: {
        const Type* r = m_.type(result);
        const Type* a = m_.type(operand(0));
        const Type* b = m_.type(operand(1));
        if (!r || !a || !b || r->kind != Type::Vector || a->kind != Type::Vector || b->kind != Type::Vector)
          return "the result and both vectors must be vectors";
        if (a->element != r->element || b->element != r->element)
          return "the vectors' component type is not the result's";
        if (operands < 2 || operands - 2 != r->count) return "the component count is not the result's";
        for (uint32_t k = 2; k < operands; ++k)
          if (in.word(4 + k) >= a->count + b->count && in.word(4 + k) != kUndefinedComponent)
            return "a component selects past both vectors";
        return "";
      }
      case spv::OpSConvert:
      case spv::OpUConvert:
        return operands == 1 && is(result, Type::Int) && is(operand(0), Type::Int) && sameCount(result, operand(0))
                   ? ""
                   : "needs an integer operand and result with the same component count";
      case spv::OpFConvert:
        return operands == 1 && is(result, Type::Float) && is(operand(0), Type::Float) && sameCount(result, operand(0))
                   ? ""
                   : "needs a float operand and result with the same component count";
      case spv::OpQuantizeToF16:
        return operands == 1 && is(result, Type::Float) && width(result) == 32 && operand(0) == result
                   ? ""
                   : "needs a 32-bit float operand of the result type";
      case spv::OpSNegate:
      case spv::OpNot:
        return operands == 1 && is(result, Type::Int) && intLike(operand(0), result)
                   ? ""
                   : "needs an integer operand with the result's component count and width";
      case spv::OpIAdd:
      case spv::OpISub:
      case spv::OpIMul:
      case spv::OpUDiv:
      case spv::OpSDiv:
      case spv::OpUMod:
      case spv::OpSRem:
      case spv::OpSMod:
      case spv::OpBitwiseOr:
      case spv::OpBitwiseXor:
      case spv::OpBitwiseAnd:
        return operands == 2 && is(result, Type::Int) && intLike(operand(0), result) && intLike(operand(1), result)
                   ? ""
                   : "needs integer operands with the result's component count and width";
      case spv::OpShiftRightLogical:
      case spv::OpShiftRightArithmetic:
      case spv::OpShiftLeftLogical:
        return operands == 2 && is(result, Type::Int) && intLike(operand(0), result) && is(operand(1), Type::Int) &&
                       sameCount(operand(1), result)
                   ? ""
                   : "needs integer operands with the result's component count (the base also its width)";
      case spv::OpLogicalOr:
      case spv::OpLogicalAnd:
      case spv::OpLogicalEqual:
      case spv::OpLogicalNotEqual:
        return operands == 2 && is(result, Type::Bool) && operand(0) == result && operand(1) == result
                   ? ""
                   : "needs boolean operands of the result type";
      case spv::OpLogicalNot:
        return operands == 1 && is(result, Type::Bool) && operand(0) == result
                   ? ""
                   : "needs a boolean operand of the result type";
      case spv::OpSelect:
        return operands == 3 && is(operand(0), Type::Bool) &&
                       (sameCount(operand(0), result) || count(operand(0)) == 1) && operand(1) == result &&
                       operand(2) == result
                   ? ""
                   : "needs a boolean condition (one, or one per component) and objects of the result type";
      case spv::OpIEqual:
      case spv::OpINotEqual:
      case spv::OpULessThan:
      case spv::OpSLessThan:
      case spv::OpUGreaterThan:
      case spv::OpSGreaterThan:
      case spv::OpULessThanEqual:
      case spv::OpSLessThanEqual:
      case spv::OpUGreaterThanEqual:
      case spv::OpSGreaterThanEqual:
        return operands == 2 && is(result, Type::Bool) && is(operand(0), Type::Int) && is(operand(1), Type::Int) &&
                       sameCount(operand(0), result) && sameCount(operand(1), result) &&
                       width(operand(0)) == width(operand(1))
                   ? ""
                   : "needs integer operands of one width with the result's component count";
      default: return "";  // not an opcode a Shader module may name here: the validator refuses it
    }
  }

 private:
  // The scalar type of a scalar or vector type (0 for others).
  const Type* scalar(uint32_t typeId) const {
    const Type* t = m_.type(typeId);
    if (t && t->kind == Type::Vector) t = m_.type(t->element);
    return t && (t->kind == Type::Int || t->kind == Type::Float || t->kind == Type::Bool) ? t : nullptr;
  }
  bool is(uint32_t typeId, Type::Kind kind) const {
    const Type* t = scalar(typeId);
    return t && t->kind == kind;
  }
  uint32_t width(uint32_t typeId) const {
    const Type* t = scalar(typeId);
    return t ? t->width : 0;
  }
  uint32_t count(uint32_t typeId) const {
    const Type* t = m_.type(typeId);
    return t && t->kind == Type::Vector ? t->count : 1;
  }
  bool sameCount(uint32_t a, uint32_t b) const { return count(a) == count(b); }
  bool intLike(uint32_t operand, uint32_t result) const {
    return is(operand, Type::Int) && sameCount(operand, result) && width(operand) == width(result);
  }
  // The type of part `index` of a composite type, or 0 when there is none.
  uint32_t member(uint32_t typeId, uint32_t index) const {
    const Type* t = m_.type(typeId);
    if (!t) return 0;
    switch (t->kind) {
      case Type::Vector:
      case Type::Matrix:
      case Type::Array: return index < t->count ? t->element : 0;  // an array of unknown length: refused
      case Type::Struct: return index < t->members.size() ? t->members[index] : 0;
      default: return 0;
    }
  }

  const Module& m_;
};

}  // namespace

// An OpSpecConstantOp VectorShuffle component 0xFFFFFFFF (undefined: the CTS's opspecconstantop.vector_related
// uses it) becomes 0, one of the values it may take: SPIRV-Tools' folding indexed the vectors with it.
void defineUndefinedShuffleComponents(std::vector<uint32_t>& words) {
  for (size_t at = 5; at < words.size();) {
    const uint32_t count = words[at] >> 16;
    if (count == 0 || at + count > words.size()) return;  // the parse before refuses such a module
    if ((words[at] & 0xFFFF) == spv::OpSpecConstantOp && count > 6 && words[at + 3] == spv::OpVectorShuffle)
      for (uint32_t k = 6; k < count; ++k)
        if (words[at + k] == kUndefinedComponent) words[at + k] = 0;
    at += count;
  }
}

// SPIRV-Tools 2023.1 folds OpSpecConstantOp QuantizeToF16 wrongly twice over: in a module that declares a float
// controls capability (SignedZeroInfNanPreserve, DenormPreserve, DenormFlushToZero, RoundingModeRTE/RTZ) the fold
// pass dereferences a null result and crashes (the CTS's spirv_assembly.instruction.graphics.opquantize.spec_const_*
// with infinities and NaNs), and elsewhere it keeps results below the smallest normal half (2^-14), which the SPIR-V
// specification makes a zero (opquantize.spec_const_too_small, opspecconstantop_opquantize.flush_to_zero). vkrt
// folds them itself first, as arithmetic.cpp computes the instruction: to the nearest half (ties to even; infinities
// and NaNs stay, magnitudes past 65504 become infinities), then a zero of the input's sign below 2^-14.
namespace {

uint32_t quantizeToF16(uint32_t bits) {
  const uint32_t sign = bits & 0x80000000u, exponent = (bits >> 23) & 0xFF, mantissa = bits & 0x7FFFFF;
  if (exponent == 0xFF) return mantissa ? (bits | 0x400000u) : bits;  // NaN (kept quiet), infinity
  if (exponent < 127 - 14) {
    // Below 2^-14: rounded to the half denormals (steps of 2^-24), only 2^-14 - 2^-25 and up reach 2^-14 (the tie
    // goes to its even mantissa); every other result is a denormal or zero, and becomes the zero.
    return exponent == 127 - 15 && mantissa >= 0x7FE000u ? sign | (127 - 14) << 23 : sign;
  }
  // A normal half: 10 mantissa bits, rounded to nearest even.
  uint32_t m = mantissa, e = exponent;
  const uint32_t dropped = m & 0x1FFF, half = 0x1000;
  m >>= 13;
  if (dropped > half || (dropped == half && (m & 1))) ++m;
  if (m == 0x400) m = 0, ++e;
  if (e > 127 + 15) return sign | 0x7F800000u;  // past 65504
  return sign | e << 23 | m << 13;
}

}  // namespace

void foldQuantizeToF16SpecConstants(std::vector<uint32_t>& words) {
  std::vector<uint32_t> floatTypes;                  // ids of OpTypeFloat 32
  std::vector<std::pair<uint32_t, uint32_t>> known;  // id -> the bits of a 32-bit float constant
  auto isFloat32 = [&](uint32_t id) { return std::find(floatTypes.begin(), floatTypes.end(), id) != floatTypes.end(); };
  auto value = [&](uint32_t id) -> const uint32_t* {
    for (const auto& [k, v] : known)
      if (k == id) return &v;
    return nullptr;
  };
  bool any = false;
  std::vector<uint32_t> out(words.begin(), words.begin() + std::min<size_t>(words.size(), 5));
  for (size_t at = 5; at < words.size();) {
    const uint32_t count = words[at] >> 16, op = words[at] & 0xFFFF;
    if (count == 0 || at + count > words.size()) return;  // the parse before refuses such a module
    if (op == spv::OpTypeFloat && count == 3 && words[at + 2] == 32) floatTypes.push_back(words[at + 1]);
    if ((op == spv::OpConstant || op == spv::OpSpecConstant) && count == 4 && isFloat32(words[at + 1]))
      known.push_back({words[at + 2], words[at + 3]});
    const uint32_t* operand = nullptr;
    if (op == spv::OpSpecConstantOp && count == 5 && words[at + 3] == spv::OpQuantizeToF16 &&
        isFloat32(words[at + 1]) && (operand = value(words[at + 4]))) {
      const uint32_t bits = quantizeToF16(*operand);
      known.push_back({words[at + 2], bits});
      out.insert(out.end(), {4u << 16 | spv::OpConstant, words[at + 1], words[at + 2], bits});
      any = true;
    } else {
      out.insert(out.end(), words.begin() + at, words.begin() + at + count);
    }
    at += count;
  }
  if (any) words = std::move(out);
}

bool checkSpecConstantOps(const Module& m, std::string* error) {
  const SpecConstantOpCheck check(m);
  for (const Instruction& in : m.instructions) {
    if (in.op != spv::OpSpecConstantOp) continue;
    const std::string rule = check.broken(in);
    if (rule.empty()) continue;
    char buf[320];
    std::snprintf(buf, sizeof buf, "invalid SPIR-V: OpSpecConstantOp %s (result %%%u, at word %u): %s",
                  opName(spv::Op(in.word(3))).c_str(), in.word(2), in.offset, rule.c_str());
    *error = buf;
    return false;
  }
  return true;
}

// Removes every OpEntryPoint but the one compiled (and the execution modes of the functions only they named),
// so that the optimizer drops the other entry points' functions and variables: a module with several shaders
// compiles each with only its own code, and the ray tracing sizes (RayStageInfo) count only its variables.
void keepOnlyEntryPoint(std::vector<uint32_t>& words, spv::ExecutionModel model, const std::string& name) {
  constexpr size_t kHeader = 5;
  if (words.size() < kHeader) return;
  std::vector<uint32_t> out(words.begin(), words.begin() + kHeader);
  std::set<uint32_t> dropped;
  uint32_t kept = 0;
  // Two passes: execution modes may only be dropped once every entry point has been seen.
  for (int pass = 0; pass < 2; ++pass) {
    for (size_t at = kHeader; at < words.size();) {
      uint32_t count = words[at] >> 16;
      auto op = spv::Op(words[at] & 0xffff);
      if (count == 0 || at + count > words.size()) return;  // malformed: leave the module as it is
      bool drop = false;
      if (op == spv::OpEntryPoint && count >= 4) {
        Instruction in{op, uint32_t(at), count, &words[at]};
        bool mine = spv::ExecutionModel(words[at + 1]) == model && in.string(3) == name;
        if (pass == 0 && mine) kept = words[at + 2];
        if (pass == 0 && !mine) dropped.insert(words[at + 2]);
        drop = !mine;
      } else if ((op == spv::OpExecutionMode || op == spv::OpExecutionModeId) && count >= 2) {
        drop = pass == 1 && words[at + 1] != kept && dropped.count(words[at + 1]);
      }
      if (pass == 1 && !drop) out.insert(out.end(), words.begin() + at, words.begin() + at + count);
      at += count;
    }
  }
  words = std::move(out);
}

// Non-semantic instructions before the optimizer: NonSemantic.DebugPrintf (debugPrintfEXT) is kept for the
// translation (shader_debug_codegen.cpp); every other non-semantic set is dropped here (its imports and
// instructions: debug information, reflection). The line information of NonSemantic.Shader.DebugInfo.100
// (glslangValidator -gV and -gVS, newer glslc -g) becomes OpLine first: each DebugLine an OpLine of the file its
// DebugSource names, at its start line and column, each DebugNoLine an OpNoLine, so that out-of-bounds reports name
// the source line as they do for OpLine (the optimizer moves and renumbers instructions, but keeps the OpLine of
// each). An instruction that accesses memory and has no source line (a module without line information, or a block
// of one with lines where no OpLine or DebugLine precedes it) gets an OpLine of its own, naming an OpString
// kWordOffsetFile, whose line is the instruction's word offset in `words` (the application's module, specialized in
// place), so that a report can still name it. Returns whether a DebugPrintf call remains.
bool prepareNonSemantic(std::vector<uint32_t>& words) {
  constexpr size_t kHeader = 5;
  // NonSemantic.Shader.DebugInfo.100's instruction numbers and their operands' places in the OpExtInst (word 5 on).
  constexpr uint32_t kDebugSource = 35, kDebugLine = 103, kDebugNoLine = 104;
  if (words.size() < kHeader) return false;
  std::set<uint32_t> dropped;
  uint32_t printfSet = 0, debugInfoSet = 0;
  bool hasPrintf = false;
  std::set<uint32_t> int32Types;
  std::map<uint32_t, uint32_t> int32Constants;  // DebugLine's line and column operands are ids of such constants
  std::map<uint32_t, uint32_t> sourceFiles;     // DebugSource result -> the OpString of its file name
  std::set<uint32_t> strings;
  for (size_t at = kHeader; at < words.size();) {
    uint32_t count = words[at] >> 16;
    auto op = spv::Op(words[at] & 0xffff);
    if (count == 0 || at + count > words.size()) return false;  // malformed: the parse refuses it
    if (op == spv::OpExtInstImport && count >= 3) {
      Instruction in{op, uint32_t(at), count, &words[at]};
      std::string name = in.string(2);
      if (name == "NonSemantic.DebugPrintf") {
        printfSet = words[at + 1];
      } else if (name.rfind("NonSemantic.", 0) == 0) {
        dropped.insert(words[at + 1]);
        if (name == "NonSemantic.Shader.DebugInfo.100") debugInfoSet = words[at + 1];
      }
    } else if (op == spv::OpString && count >= 3) {
      strings.insert(words[at + 1]);
    } else if (op == spv::OpTypeInt && count == 4 && words[at + 2] == 32) {
      int32Types.insert(words[at + 1]);
    } else if (op == spv::OpConstant && count == 4 && int32Types.count(words[at + 1])) {
      int32Constants[words[at + 2]] = words[at + 3];
    } else if (op == spv::OpExtInst && count >= 6 && debugInfoSet && words[at + 3] == debugInfoSet &&
               words[at + 4] == kDebugSource && strings.count(words[at + 5])) {
      sourceFiles[words[at + 2]] = words[at + 5];
    }
    if (op == spv::OpExtInst && count >= 5 && printfSet && words[at + 3] == printfSet) hasPrintf = true;
    at += count;
  }
  auto constant = [&](uint32_t id, uint32_t* value) {
    auto c = int32Constants.find(id);
    if (c == int32Constants.end()) return false;
    *value = c->second;
    return true;
  };
  const uint32_t fileId = words[3];  // the word-offset OpString's id: one past the module's bound
  bool offsetLineUsed = false;
  std::vector<uint32_t> out(words.begin(), words.begin() + kHeader);
  size_t stringAt = 0;  // where the word-offset OpString goes: the debug section's first place
  bool inFunctions = false, sourceLine = false;
  for (size_t at = kHeader; at < words.size();) {
    uint32_t count = words[at] >> 16;
    auto op = spv::Op(words[at] & 0xffff);
    // Inside functions only: a DebugLine elsewhere (the non-semantic rules allow it among the types) describes no
    // instruction that runs.
    const bool debugInfo =
        inFunctions && op == spv::OpExtInst && count >= 5 && debugInfoSet && words[at + 3] == debugInfoSet;
    bool drop = (op == spv::OpExtInstImport && dropped.count(words[at + 1])) ||
                (op == spv::OpExtInst && count >= 4 && dropped.count(words[at + 3]));
    if (!stringAt && op != spv::OpCapability && op != spv::OpExtension && op != spv::OpExtInstImport &&
        op != spv::OpMemoryModel && op != spv::OpEntryPoint && op != spv::OpExecutionMode &&
        op != spv::OpExecutionModeId) {
      // OpString comes before OpSource, OpName and everything after.
      stringAt = out.size();
    }
    inFunctions = inFunctions || op == spv::OpFunction;
    if (op == spv::OpLabel || op == spv::OpNoLine || op == spv::OpFunctionEnd) sourceLine = false;
    if (op == spv::OpLine) sourceLine = true;
    if (debugInfo && words[at + 4] == kDebugLine && count >= 10) {
      auto file = sourceFiles.find(words[at + 5]);
      uint32_t line = 0, column = 0;
      if (file != sourceFiles.end() && constant(words[at + 6], &line) && constant(words[at + 8], &column)) {
        out.push_back(4u << 16 | spv::OpLine);
        out.push_back(file->second);
        out.push_back(line);
        out.push_back(column);
        sourceLine = true;
      } else {
        out.push_back(1u << 16 | spv::OpNoLine);
        sourceLine = false;
      }
    } else if (debugInfo && words[at + 4] == kDebugNoLine) {
      out.push_back(1u << 16 | spv::OpNoLine);
      sourceLine = false;
    }
    bool access = op == spv::OpLoad || op == spv::OpStore || op == spv::OpCopyMemory || op == spv::OpAccessChain ||
                  op == spv::OpInBoundsAccessChain || op == spv::OpPtrAccessChain ||
                  op == spv::OpInBoundsPtrAccessChain || (op >= spv::OpAtomicLoad && op <= spv::OpAtomicXor);
    if (inFunctions && access && !sourceLine) {
      // Holds, as an OpLine does, to the next line instruction or the end of the block: the instructions after
      // the access that use its result (an image instruction after the load of its image) are named by it too.
      out.push_back(4u << 16 | spv::OpLine);
      out.push_back(fileId);
      out.push_back(uint32_t(at));
      out.push_back(0);
      offsetLineUsed = true;
    }
    if (!drop) out.insert(out.end(), words.begin() + at, words.begin() + at + count);
    at += count;
  }
  if (offsetLineUsed) {
    std::vector<uint32_t> text((sizeof kWordOffsetFile + 3) / 4, 0);
    std::memcpy(text.data(), kWordOffsetFile, sizeof kWordOffsetFile);
    std::vector<uint32_t> string{uint32_t(2 + text.size()) << 16 | spv::OpString, fileId};
    string.insert(string.end(), text.begin(), text.end());
    out.insert(out.begin() + std::ptrdiff_t(stringAt ? stringAt : out.size()), string.begin(), string.end());
    out[3] = words[3] + 1;
  }
  words = std::move(out);
  return hasPrintf;
}

}  // namespace vkrt::spirv
