// compile(): specialization, a support check against the application's module, SPIRV-Tools' optimizer,
// LLVM IR generation (Codegen), LLVM's O2 pipeline and ORC LLJIT. LLVM's fatal errors are turned into
// messages here (a handler that throws, caught at this boundary), never an abort.
#include <llvm/Analysis/LoopInfo.h>
#include <llvm/Config/llvm-config.h>
#include <llvm/ExecutionEngine/Orc/ExecutionUtils.h>
#include <llvm/ExecutionEngine/Orc/JITTargetMachineBuilder.h>
#include <llvm/ExecutionEngine/Orc/LLJIT.h>
#include <llvm/ExecutionEngine/Orc/RTDyldObjectLinkingLayer.h>
#include <llvm/ExecutionEngine/Orc/ThreadSafeModule.h>
#include <llvm/ExecutionEngine/SectionMemoryManager.h>
#include <llvm/IR/Dominators.h>
#include <llvm/IR/IRBuilder.h>
#include <llvm/IR/LegacyPassManager.h>
#include <llvm/IR/MDBuilder.h>
#include <llvm/IR/Verifier.h>
#include <llvm/Object/ObjectFile.h>
#include <llvm/Passes/PassBuilder.h>
#include <llvm/Support/ErrorHandling.h>
#include <llvm/Support/Host.h>
#include <llvm/Support/LEB128.h>
#include <llvm/Support/MemoryBuffer.h>
#include <llvm/Support/SHA256.h>
#include <llvm/Support/TargetSelect.h>
#include <llvm/Support/raw_ostream.h>
#include <llvm/Target/TargetMachine.h>
#include <spirv/unified1/GLSL.std.450.h>
#include <spirv-tools/optimizer.hpp>

#include <link.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <mutex>
#include <optional>
#include <set>
#include <stdexcept>
#include <string_view>

#include "abi/jit_code.hpp"
#include "spirv/codegen.hpp"
#include "spirv/newer_tokens.hpp"
#include "spirv/shader_debug.hpp"
#include "spirv/spmd.hpp"
#include "spirv/target.hpp"

// Half-precision conversions: on a CPU without F16C (x86-64-v2 and older; VKRT_JIT_CPU=x86-64-v2 compiles for
// one), LLVM lowers fpext/fptrunc of half to these runtime library calls, which GCC's libgcc (12 and later)
// provides with the same calling convention as LLVM 15 (the half in an XMM register). Declared here only to take
// their addresses.
extern "C" void __extendhfsf2();
extern "C" void __extendhfdf2();
extern "C" void __truncsfhf2();
extern "C" void __truncdfhf2();

namespace vkrt::spirv {

struct CompiledShader::Jit {
  std::unique_ptr<llvm::orc::LLJIT> lljit;
  // The code sections' slots in abi::JitCode (the fault handler's "is this shader code"), released before the
  // code is unmapped.
  std::shared_ptr<std::vector<uint32_t>> codeSlots;
  ~Jit() {
    if (codeSlots)
      for (uint32_t slot : *codeSlots) abi::JitCode::remove(slot);
    lljit.reset();
  }
};

CompiledShader::CompiledShader() = default;
CompiledShader::~CompiledShader() = default;

namespace {

struct LlvmFatal : std::runtime_error {
  using std::runtime_error::runtime_error;
};

void fatalHandler(void*, const char* reason, bool) { throw LlvmFatal(reason ? reason : "LLVM fatal error"); }
void badAllocHandler(void*, const char* reason, bool) { throw std::bad_alloc(); }

void initLlvm() {
  static std::once_flag once;
  std::call_once(once, [] {
    llvm::InitializeNativeTarget();
    llvm::InitializeNativeTargetAsmPrinter();
    llvm::install_fatal_error_handler(fatalHandler, nullptr);
    llvm::install_bad_alloc_error_handler(badAllocHandler, nullptr);
  });
}

// ---- what the translator supports (checked on the application's module, so that messages carry its offsets)

bool supportedOp(spv::Op op) {
  switch (op) {
    case spv::OpNop:
    case spv::OpUndef:
    case spv::OpSourceContinued:
    case spv::OpSource:
    case spv::OpSourceExtension:
    case spv::OpName:
    case spv::OpMemberName:
    case spv::OpString:
    case spv::OpLine:
    case spv::OpNoLine:
    case spv::OpModuleProcessed:
    case spv::OpExtension:
    case spv::OpExtInstImport:
    case spv::OpExtInst:
    case spv::OpMemoryModel:
    case spv::OpEntryPoint:
    case spv::OpExecutionMode:
    case spv::OpExecutionModeId:
    case spv::OpCapability:
    case spv::OpDecorate:
    case spv::OpMemberDecorate:
    case spv::OpDecorationGroup:  // flattened by SPIRV-Tools before the translation
    case spv::OpGroupDecorate:
    case spv::OpGroupMemberDecorate:
    case spv::OpDecorateId:
    case spv::OpDecorateString:
    case spv::OpMemberDecorateString:
    case spv::OpTypeVoid:
    case spv::OpTypeBool:
    case spv::OpTypeInt:
    case spv::OpTypeFloat:
    case spv::OpTypeVector:
    case spv::OpTypeMatrix:
    case spv::OpTypeArray:
    case spv::OpTypeRuntimeArray:
    case spv::OpTypeStruct:
    case spv::OpTypePointer:
    case spv::OpTypeFunction:
    case spv::OpConstantTrue:
    case spv::OpConstantFalse:
    case spv::OpConstant:
    case spv::OpConstantComposite:
    case spv::OpConstantNull:
    case spv::OpSpecConstantTrue:
    case spv::OpSpecConstantFalse:
    case spv::OpSpecConstant:
    case spv::OpSpecConstantComposite:
    case spv::OpSpecConstantOp:
    case spv::OpFunction:
    case spv::OpFunctionParameter:
    case spv::OpFunctionEnd:
    case spv::OpFunctionCall:
    case spv::OpVariable:
    case spv::OpLoad:
    case spv::OpStore:
    case spv::OpCopyMemory:
    case spv::OpAccessChain:
    case spv::OpInBoundsAccessChain:
    case spv::OpArrayLength:
    case spv::OpPtrEqual:
    case spv::OpPtrNotEqual:
    case spv::OpVectorExtractDynamic:
    case spv::OpVectorInsertDynamic:
    case spv::OpVectorShuffle:
    case spv::OpCompositeConstruct:
    case spv::OpCompositeExtract:
    case spv::OpCompositeInsert:
    case spv::OpCopyObject:
    case spv::OpCopyLogical:
    case spv::OpTranspose:
    case spv::OpConvertFToU:
    case spv::OpConvertFToS:
    case spv::OpConvertSToF:
    case spv::OpConvertUToF:
    case spv::OpUConvert:
    case spv::OpSConvert:
    case spv::OpFConvert:
    case spv::OpQuantizeToF16:
    case spv::OpGroupNonUniformElect:
    case spv::OpGroupNonUniformAll:
    case spv::OpGroupNonUniformAny:
    case spv::OpGroupNonUniformAllEqual:
    case spv::OpGroupNonUniformBroadcast:
    case spv::OpGroupNonUniformBroadcastFirst:
    case spv::OpGroupNonUniformBallot:
    case spv::OpGroupNonUniformInverseBallot:
    case spv::OpGroupNonUniformBallotBitExtract:
    case spv::OpGroupNonUniformBallotBitCount:
    case spv::OpGroupNonUniformBallotFindLSB:
    case spv::OpGroupNonUniformBallotFindMSB:
    case spv::OpSDot:
    case spv::OpUDot:
    case spv::OpSUDot:
    case spv::OpSDotAccSat:
    case spv::OpUDotAccSat:
    case spv::OpSUDotAccSat:
    case spv::OpBitcast:
    case spv::OpSNegate:
    case spv::OpFNegate:
    case spv::OpIAdd:
    case spv::OpFAdd:
    case spv::OpISub:
    case spv::OpFSub:
    case spv::OpIMul:
    case spv::OpFMul:
    case spv::OpUDiv:
    case spv::OpSDiv:
    case spv::OpFDiv:
    case spv::OpUMod:
    case spv::OpSRem:
    case spv::OpSMod:
    case spv::OpFRem:
    case spv::OpFMod:
    case spv::OpVectorTimesScalar:
    case spv::OpMatrixTimesScalar:
    case spv::OpVectorTimesMatrix:
    case spv::OpMatrixTimesVector:
    case spv::OpMatrixTimesMatrix:
    case spv::OpOuterProduct:
    case spv::OpDot:
    case spv::OpIAddCarry:
    case spv::OpISubBorrow:
    case spv::OpUMulExtended:
    case spv::OpSMulExtended:
    case spv::OpAny:
    case spv::OpAll:
    case spv::OpIsNan:
    case spv::OpIsInf:
    case spv::OpLogicalEqual:
    case spv::OpLogicalNotEqual:
    case spv::OpLogicalOr:
    case spv::OpLogicalAnd:
    case spv::OpLogicalNot:
    case spv::OpSelect:
    case spv::OpIEqual:
    case spv::OpINotEqual:
    case spv::OpUGreaterThan:
    case spv::OpSGreaterThan:
    case spv::OpUGreaterThanEqual:
    case spv::OpSGreaterThanEqual:
    case spv::OpULessThan:
    case spv::OpSLessThan:
    case spv::OpULessThanEqual:
    case spv::OpSLessThanEqual:
    case spv::OpFOrdEqual:
    case spv::OpFUnordEqual:
    case spv::OpFOrdNotEqual:
    case spv::OpFUnordNotEqual:
    case spv::OpFOrdLessThan:
    case spv::OpFUnordLessThan:
    case spv::OpFOrdGreaterThan:
    case spv::OpFUnordGreaterThan:
    case spv::OpFOrdLessThanEqual:
    case spv::OpFUnordLessThanEqual:
    case spv::OpFOrdGreaterThanEqual:
    case spv::OpFUnordGreaterThanEqual:
    case spv::OpShiftRightLogical:
    case spv::OpShiftRightArithmetic:
    case spv::OpShiftLeftLogical:
    case spv::OpBitwiseOr:
    case spv::OpBitwiseXor:
    case spv::OpBitwiseAnd:
    case spv::OpNot:
    case spv::OpBitFieldInsert:
    case spv::OpBitFieldSExtract:
    case spv::OpBitFieldUExtract:
    case spv::OpBitReverse:
    case spv::OpBitCount:
    case spv::OpControlBarrier:
    case spv::OpMemoryBarrier:
    case spv::OpAtomicLoad:
    case spv::OpAtomicStore:
    case spv::OpAtomicExchange:
    case spv::OpAtomicCompareExchange:
    case spv::OpAtomicIIncrement:
    case spv::OpAtomicIDecrement:
    case spv::OpAtomicIAdd:
    case spv::OpAtomicISub:
    case spv::OpAtomicSMin:
    case spv::OpAtomicUMin:
    case spv::OpAtomicSMax:
    case spv::OpAtomicUMax:
    case spv::OpAtomicAnd:
    case spv::OpAtomicOr:
    case spv::OpAtomicXor:
    case spv::OpPhi:
    case spv::OpLoopMerge:
    case spv::OpSelectionMerge:
    case spv::OpLabel:
    case spv::OpBranch:
    case spv::OpBranchConditional:
    case spv::OpSwitch:
    case spv::OpReturn:
    case spv::OpReturnValue:
    case spv::OpUnreachable: return true;
    default: return extraSupportedOp(op) || rayTracingOp(op) || graphicsOp(op);
  }
}

bool supportedCapability(uint32_t cap) {
  switch (cap) {
    case spv::CapabilityShader:
    case spv::CapabilityMatrix:
    case spv::CapabilityInt64:
    case spv::CapabilityInt16:
    case spv::CapabilityInt8:
    case spv::CapabilityFloat64:
    case spv::CapabilityFloat16:
    case spv::CapabilityInt64Atomics:
    case spv::CapabilityDeviceGroup:            // DeviceIndex: always 0 (one physical device)
    case spv::CapabilityGroupNonUniform:        // subgroups of one invocation: elect, the built-ins, barriers
    case spv::CapabilityGroupNonUniformVote:    // arithmetic.cpp: a subgroup's vote is its invocation's
    case spv::CapabilityGroupNonUniformBallot:  // arithmetic.cpp: broadcasts read the only invocation
    // The Vulkan memory model: every atomic is sequentially consistent and every barrier a sequentially consistent
    // fence (memory.cpp, control_flow.cpp), stronger than any semantics asks; availability and visibility operations
    // on loads and stores (NonPrivatePointer, MakePointerAvailable/Visible) have nothing to do on coherent host memory.
    case spv::CapabilityVulkanMemoryModel:
    case spv::CapabilityVulkanMemoryModelDeviceScope:
    // Float controls the compiled code honours as it is (runtime/physical_device.cpp says why).
    case spv::CapabilityDenormPreserve:
    case spv::CapabilitySignedZeroInfNanPreserve:
    case spv::CapabilityRoundingModeRTE:
    // Integer dot products on vectors of any integer width and on packed 4 x 8-bit words (arithmetic.cpp).
    case spv::CapabilityDotProductInputAll:
    case spv::CapabilityDotProductInput4x8Bit:
    case spv::CapabilityDotProductInput4x8BitPacked:
    case spv::CapabilityDotProduct: return true;
    default: return extraSupportedCapability(cap) || rayTracingCapability(cap) || graphicsCapability(cap);
  }
}

bool supportedGlsl(uint32_t inst) {
  switch (inst) {
    // IMix was never part of the published set; InterpolateAt* (fragment shaders) would need the interpolation
    // at other positions than the executor's, which the GraphicsInvocation does not carry.
    case GLSLstd450IMix:
    case GLSLstd450InterpolateAtCentroid:
    case GLSLstd450InterpolateAtSample:
    case GLSLstd450InterpolateAtOffset: return false;
    default: return inst >= GLSLstd450Round && inst < GLSLstd450Count;
  }
}

bool checkSupport(const Module& m, std::string* error) {
  char buf[256];
  for (const Instruction& in : m.instructions) {
    if (!supportedOp(in.op)) {
      std::snprintf(buf, sizeof buf, "unsupported instruction %s at word %u", opName(in.op).c_str(), in.offset);
      *error = buf;
      return false;
    }
    if (in.op == spv::OpExtInst) {
      auto it = m.extInstImports.find(in.word(3));
      // Non-semantic instruction sets (debug info, reflection) are stripped before the translation.
      if (it != m.extInstImports.end() && it->second.rfind("NonSemantic.", 0) == 0) continue;
      bool glsl = it != m.extInstImports.end() && it->second == "GLSL.std.450";
      if (!glsl || !supportedGlsl(in.word(4))) {
        std::snprintf(buf, sizeof buf, "unsupported instruction OpExtInst %s %u at word %u",
                      it != m.extInstImports.end() ? it->second.c_str() : "?", in.word(4), in.offset);
        *error = buf;
        return false;
      }
    }
  }
  // Capabilities last: an unsupported instruction is the more precise message.
  for (const Instruction& in : m.instructions) {
    if (in.op == spv::OpCapability && !supportedCapability(in.word(1))) {
      std::snprintf(buf, sizeof buf, "unsupported capability %u (OpCapability at word %u)", in.word(1), in.offset);
      *error = buf;
      return false;
    }
  }
  return true;
}

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

void ignoreDebugPrintf(abi::InvocationContext*, const uint8_t*, const uint64_t*) {}
void ignoreOutOfBounds(abi::InvocationContext*, const uint8_t*, uint64_t, uint64_t, uint64_t) {}

// The C library functions generated code may call, resolved to vkrt's own imports (the application's
// global symbol scope need not contain libm).
void defineRuntimeSymbols(llvm::orc::LLJIT& jit, const abi::HostSymbol* hostSymbols) {
  llvm::orc::SymbolMap map;
  auto add = [&](const char* name, auto* fn) {
    map[jit.mangleAndIntern(name)] =
        llvm::JITEvaluatedSymbol(llvm::pointerToJITTargetAddress(fn), llvm::JITSymbolFlags::Exported);
  };
  // The float and double variants of libm's one- and two-argument functions.
  auto math1 = [&](const char* name, float (*f)(float), double (*d)(double)) {
    add((std::string(name) + "f").c_str(), f);
    add(name, d);
  };
  auto math2 = [&](const char* name, float (*f)(float, float), double (*d)(double, double)) {
    add((std::string(name) + "f").c_str(), f);
    add(name, d);
  };
#define VKRT_MATH1(N) math1(#N, ::N##f, ::N)
#define VKRT_MATH2(N) math2(#N, ::N##f, ::N)
  VKRT_MATH1(sin);
  VKRT_MATH1(cos);
  VKRT_MATH1(tan);
  VKRT_MATH1(asin);
  VKRT_MATH1(acos);
  VKRT_MATH1(atan);
  VKRT_MATH1(sinh);
  VKRT_MATH1(cosh);
  VKRT_MATH1(tanh);
  VKRT_MATH1(asinh);
  VKRT_MATH1(acosh);
  VKRT_MATH1(atanh);
  VKRT_MATH1(exp);
  VKRT_MATH1(exp2);
  VKRT_MATH1(log);
  VKRT_MATH1(log2);
  VKRT_MATH1(sqrt);
  VKRT_MATH1(floor);
  VKRT_MATH1(ceil);
  VKRT_MATH1(trunc);
  VKRT_MATH1(round);
  VKRT_MATH1(rint);
  VKRT_MATH1(nearbyint);
  VKRT_MATH1(roundeven);
  VKRT_MATH2(atan2);
  VKRT_MATH2(pow);
  VKRT_MATH2(fmod);
  VKRT_MATH2(fmin);
  VKRT_MATH2(fmax);
#undef VKRT_MATH1
#undef VKRT_MATH2
  add("fmaf", static_cast<float (*)(float, float, float)>(::fmaf));
  add("fma", static_cast<double (*)(double, double, double)>(::fma));
  add("ldexp", static_cast<double (*)(double, int)>(::ldexp));
  add("sincosf", static_cast<void (*)(float, float*, float*)>(::sincosf));
  add("sincos", static_cast<void (*)(double, double*, double*)>(::sincos));
  add("memset", static_cast<void* (*)(void*, int, size_t)>(::memset));
  add("memcpy", static_cast<void* (*)(void*, const void*, size_t)>(::memcpy));
  add("memmove", static_cast<void* (*)(void*, const void*, size_t)>(::memmove));
  add("__extendhfsf2", &::__extendhfsf2);
  add("__extendhfdf2", &::__extendhfdf2);
  add("__truncsfhf2", &::__truncsfhf2);
  add("__truncdfhf2", &::__truncdfhf2);
  // Every shader may call the shader debugging functions (abi/shader_debug.hpp); where the caller supplies none
  // (tests running compiled code on their own), they do nothing.
  add("vkrt_debug_printf", &ignoreDebugPrintf);
  add("vkrt_out_of_bounds", &ignoreOutOfBounds);
  for (const abi::HostSymbol* s = hostSymbols; s && s->name; ++s) add(s->name, s->address);
  llvm::cantFail(jit.getMainJITDylib().define(llvm::orc::absoluteSymbols(std::move(map))));
}

using detail::errText;

// The native stack the object's code uses: the sum of every function's frame (its .stack_sizes entry: an
// address, then the size as ULEB128) plus its return address. A sum, not the deepest path: an upper bound, and
// exact when everything is inlined into vkrt_main (pipelines inline every call).
uint32_t frameBytesOf(std::string_view object) {
  auto file = llvm::object::ObjectFile::createObjectFile(
      llvm::MemoryBufferRef(llvm::StringRef(object.data(), object.size()), "shader"));
  if (!file) {
    llvm::consumeError(file.takeError());
    return 0;
  }
  uint64_t total = 0;
  for (const llvm::object::SectionRef& section : (*file)->sections()) {
    auto name = section.getName();
    if (!name || *name != ".stack_sizes") {
      if (!name) llvm::consumeError(name.takeError());
      continue;
    }
    auto contents = section.getContents();
    if (!contents) {
      llvm::consumeError(contents.takeError());
      continue;
    }
    const uint8_t* p = reinterpret_cast<const uint8_t*>(contents->data());
    const uint8_t* end = p + contents->size();
    while (end - p > 8) {
      p += 8;  // the function's address (relocated)
      unsigned n = 0;
      const char* err = nullptr;
      uint64_t size = llvm::decodeULEB128(p, &n, end, &err);
      if (err) break;
      p += n;
      total += size + 8;
    }
  }
  return uint32_t(std::min<uint64_t>(total, UINT32_MAX));
}

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

// Creates the shader's JIT, loads `object` (an ELF relocatable object of vkrt_main and its callees) and
// resolves the entry point (vkrt_group when `hasGroupEntry`, else vkrt_main, a RayEntry for ray tracing stages).
bool loadObject(CompiledShader& shader, std::string_view object, bool hasGroupEntry, const abi::HostSymbol* hostSymbols,
                std::string* error) {
  auto jtmb = detail::targetMachine(error);
  if (!jtmb) return false;
  // The object layer LLJIT would make (RuntimeDyld with a SectionMemoryManager), told to register the code
  // sections it loads with abi::JitCode.
  auto codeSlots = std::make_shared<std::vector<uint32_t>>();
  auto lljit = llvm::orc::LLJITBuilder()
                   .setJITTargetMachineBuilder(std::move(*jtmb))
                   .setObjectLinkingLayerCreator(
                       [codeSlots](llvm::orc::ExecutionSession& es,
                                   const llvm::Triple&) -> llvm::Expected<std::unique_ptr<llvm::orc::ObjectLayer>> {
                         auto layer = std::make_unique<llvm::orc::RTDyldObjectLinkingLayer>(
                             es, [] { return std::make_unique<llvm::SectionMemoryManager>(); });
                         layer->setNotifyLoaded([codeSlots](llvm::orc::MaterializationResponsibility&,
                                                            const llvm::object::ObjectFile& obj,
                                                            const llvm::RuntimeDyld::LoadedObjectInfo& info) {
                           for (const llvm::object::SectionRef& section : obj.sections()) {
                             if (!section.isText() || section.getSize() == 0) continue;
                             uint64_t address = info.getSectionLoadAddress(section);
                             if (address) codeSlots->push_back(abi::JitCode::add(address, address + section.getSize()));
                           }
                         });
                         return std::unique_ptr<llvm::orc::ObjectLayer>(std::move(layer));
                       })
                   .create();
  if (!lljit) {
    *error = "LLVM: " + errText(lljit.takeError());
    return false;
  }
  // Session errors (unresolved symbols...) are kept off stderr; the first one is added to lookup()'s message,
  // which names only the symbol that could not be materialized.
  auto sessionError = std::make_shared<std::string>();
  (*lljit)->getExecutionSession().setErrorReporter([sessionError](llvm::Error e) {
    std::string text = errText(std::move(e));
    if (sessionError->empty()) *sessionError = text;
  });
  defineRuntimeSymbols(**lljit, hostSymbols);
  auto buffer = llvm::MemoryBuffer::getMemBufferCopy(llvm::StringRef(object.data(), object.size()), "vkrt_shader.o");
  if (auto e = (*lljit)->addObjectFile(std::move(buffer))) {
    *error = "LLVM: " + errText(std::move(e));
    return false;
  }
  auto sym = (*lljit)->lookup(hasGroupEntry ? "vkrt_group" : "vkrt_main");
  if (!sym) {
    *error = "LLVM: " + errText(sym.takeError());
    if (!sessionError->empty()) *error += " (" + *sessionError + ")";
    return false;
  }
  if (shader.model == spv::ExecutionModelVertex || shader.model == spv::ExecutionModelFragment) {
    shader.graphicsEntry = sym->toPtr<abi::GraphicsEntry>();
  } else if (shader.model != spv::ExecutionModelGLCompute) {
    shader.rayEntry = sym->toPtr<abi::RayEntry>();
  } else {
    (hasGroupEntry ? shader.groupEntry : shader.entry) = sym->toPtr<abi::ComputeEntry>();
  }
  shader.jit = std::make_unique<CompiledShader::Jit>();
  shader.jit->lljit = std::move(*lljit);
  shader.jit->codeSlots = std::move(codeSlots);
  return true;
}

// ---- the pipeline cache form of a compiled shader
//
//   char magic[8] "VKRTSHD6"; uint8 sha256[32] of the payload; payload:
//   u32 localSize[3], workgroupMemorySize, usesBarrier, hasGroupEntry | spmdLanes << 8, pushConstantBytes, model;
//   u32 ray.payloadBytes, callableDataBytes, hitAttributeBytes, frameBytes, callsOut | readsHitAttributes << 1;
//   graphics: u32 flags (the GraphicsStageInfo booleans, bit by bit in declaration order), clipDistances,
//   cullDistances; u32 n + n x 8 bytes (inputs), u32 n + n x 8 bytes (outputs): {location, componentMask,
//   interpolation, centroid | sample << 1 | integer << 2 | wide << 3, 4 zero bytes};
//   u32 n + entry name; u32 n + n x {u32 set, binding, arraySize, uniform | kind << 1}; the rest: the object file.
// Every field of CompiledShader that describes the code must be here: a new one needs a line in
// serialize() and deserialize() (the size check below is the reminder).
static_assert(sizeof(CompiledShader) == 256,
              "serialize the new CompiledShader field for VkPipelineCache, then update this size");

// 6: shader record reads call RayRuntime::shaderRecordOutsideRegion, which an older vkrt does not provide.
constexpr char kBlobMagic[8] = {'V', 'K', 'R', 'T', 'S', 'H', 'D', '6'};

void put32(std::string& out, uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); }

std::string serialize(const CompiledShader& s, std::string_view object) {
  std::string payload;
  for (uint32_t v : s.localSize) put32(payload, v);
  put32(payload, s.workgroupMemorySize);
  put32(payload, s.usesBarrier ? 1 : 0);
  // hasGroupEntry (a fragment shader's vkrt_group is its graphicsEntry, spmdLanes 4), SPMD lanes
  put32(payload, s.groupEntry || s.spmdLanes ? 1u | uint32_t(s.spmdLanes) << 8 : 0);
  put32(payload, s.pushConstantBytes);
  put32(payload, uint32_t(s.model));
  for (uint32_t v : {s.ray.payloadBytes, s.ray.callableDataBytes, s.ray.hitAttributeBytes, s.ray.frameBytes})
    put32(payload, v);
  put32(payload, (s.ray.callsOut ? 1u : 0u) | (s.ray.readsHitAttributes ? 2u : 0u));
  const GraphicsStageInfo& g = s.graphics;
  uint32_t flags = 0, bit = 0;
  for (bool f : {g.needsQuad, g.writesDepth, g.writesSampleMask, g.readsSampleId, g.canDiscard, g.earlyFragmentTests,
                 g.sideEffects, g.dualSource, g.writesPointSize})
    flags |= uint32_t(f) << bit++;
  put32(payload, flags);
  put32(payload, g.clipDistances);
  put32(payload, g.cullDistances);
  for (const auto* list : {&g.inputs, &g.outputs}) {
    put32(payload, uint32_t(list->size()));
    for (const GraphicsStageInfo::Location& l : *list) {
      put32(payload, l.location | uint32_t(l.componentMask) << 8 | uint32_t(l.interpolation) << 16 |
                         uint32_t(l.centroid | l.sample << 1 | l.integer << 2 | l.wide << 3) << 24);
      put32(payload, 0);
    }
  }
  put32(payload, uint32_t(s.entryName.size()));
  payload += s.entryName;
  put32(payload, uint32_t(s.resources.size()));
  for (const ResourceBinding& r : s.resources) {
    put32(payload, r.set);
    put32(payload, r.binding);
    put32(payload, r.arraySize);
    put32(payload, (r.uniform ? 1u : 0u) | uint32_t(r.kind) << 1);  // bit 0: uniform; bits 1+: kind
  }
  payload.append(object.data(), object.size());
  auto digest =
      llvm::SHA256::hash(llvm::ArrayRef<uint8_t>(reinterpret_cast<const uint8_t*>(payload.data()), payload.size()));
  std::string blob(kBlobMagic, sizeof kBlobMagic);
  blob.append(reinterpret_cast<const char*>(digest.data()), digest.size());
  return blob + payload;
}

struct Reader {
  std::string_view rest;
  bool ok = true;
  uint32_t u32() {
    if (rest.size() < 4) {
      ok = false;
      return 0;
    }
    uint32_t v;
    std::memcpy(&v, rest.data(), 4);
    rest.remove_prefix(4);
    return v;
  }
  std::string_view bytes(uint32_t n) {
    if (rest.size() < n) {
      ok = false;
      return {};
    }
    std::string_view v = rest.substr(0, n);
    rest.remove_prefix(n);
    return v;
  }
};

// Fills `s` from a blob's fields; returns the object file, or nullopt when the blob is damaged.
std::optional<std::string_view> deserialize(std::string_view blob, CompiledShader& s, bool* hasGroupEntry) {
  if (blob.size() < 40 || std::memcmp(blob.data(), kBlobMagic, 8) != 0) return std::nullopt;
  std::string_view payload = blob.substr(40);
  auto digest =
      llvm::SHA256::hash(llvm::ArrayRef<uint8_t>(reinterpret_cast<const uint8_t*>(payload.data()), payload.size()));
  if (std::memcmp(digest.data(), blob.data() + 8, 32) != 0) return std::nullopt;
  Reader r{payload};
  for (uint32_t& v : s.localSize) v = r.u32();
  s.workgroupMemorySize = r.u32();
  s.usesBarrier = r.u32() != 0;
  uint32_t group = r.u32();
  *hasGroupEntry = (group & 1) != 0;
  s.spmdLanes = uint8_t(group >> 8);
  s.pushConstantBytes = r.u32();
  s.model = spv::ExecutionModel(r.u32());
  s.ray.payloadBytes = r.u32();
  s.ray.callableDataBytes = r.u32();
  s.ray.hitAttributeBytes = r.u32();
  s.ray.frameBytes = r.u32();
  uint32_t rayFlags = r.u32();
  s.ray.callsOut = (rayFlags & 1) != 0;
  s.ray.readsHitAttributes = (rayFlags & 2) != 0;
  GraphicsStageInfo& g = s.graphics;
  uint32_t flags = r.u32(), bit = 0;
  for (bool* f : {&g.needsQuad, &g.writesDepth, &g.writesSampleMask, &g.readsSampleId, &g.canDiscard,
                  &g.earlyFragmentTests, &g.sideEffects, &g.dualSource, &g.writesPointSize})
    *f = (flags >> bit++ & 1) != 0;
  g.clipDistances = r.u32();
  g.cullDistances = r.u32();
  for (auto* list : {&g.inputs, &g.outputs}) {
    uint32_t n = r.u32();
    if (!r.ok || n > abi::kGraphicsLocations) return std::nullopt;
    for (uint32_t i = 0; i < n; ++i) {
      uint32_t w = r.u32();
      r.u32();
      GraphicsStageInfo::Location l;
      l.location = uint8_t(w);
      l.componentMask = uint8_t(w >> 8);
      l.interpolation = GraphicsStageInfo::Location::Interpolation(std::min<uint32_t>(w >> 16 & 0xff, 2));
      uint32_t b = w >> 24;
      l.centroid = b & 1;
      l.sample = b & 2;
      l.integer = b & 4;
      l.wide = b & 8;
      list->push_back(l);
    }
  }
  uint32_t nameSize = r.u32();
  s.entryName = std::string(r.bytes(nameSize));
  uint32_t count = r.u32();
  if (!r.ok || count > r.rest.size() / 16) return std::nullopt;
  for (uint32_t i = 0; i < count; ++i) {
    ResourceBinding b{};
    b.set = r.u32();
    b.binding = r.u32();
    b.arraySize = r.u32();
    uint32_t flags = r.u32();
    b.uniform = (flags & 1) != 0;
    b.kind = ResourceBinding::Kind(std::min<uint32_t>(flags >> 1, ResourceBinding::InputAttachment));  // the last
    s.resources.push_back(b);
  }
  if (!r.ok || r.rest.empty()) return std::nullopt;
  return r.rest;
}

// The build id of the binary vkrt's code is in (a rebuilt vkrt may generate different code).
std::string buildId() {
  static const std::string id = [] {
    struct Search {
      uintptr_t address;
      std::string id;
    } search{reinterpret_cast<uintptr_t>(&buildId), {}};
    dl_iterate_phdr(
        [](dl_phdr_info* info, size_t, void* data) -> int {
          auto* s = static_cast<Search*>(data);
          bool mine = false;
          for (int i = 0; i < info->dlpi_phnum && !mine; ++i) {
            const ElfW(Phdr)& ph = info->dlpi_phdr[i];
            uintptr_t start = info->dlpi_addr + ph.p_vaddr;
            mine = ph.p_type == PT_LOAD && s->address >= start && s->address < start + ph.p_memsz;
          }
          if (!mine) return 0;
          for (int i = 0; i < info->dlpi_phnum; ++i) {
            const ElfW(Phdr)& ph = info->dlpi_phdr[i];
            if (ph.p_type != PT_NOTE) continue;
            auto* p = reinterpret_cast<const uint8_t*>(info->dlpi_addr + ph.p_vaddr);
            size_t at = 0;
            while (at + sizeof(ElfW(Nhdr)) <= ph.p_memsz) {
              auto* n = reinterpret_cast<const ElfW(Nhdr)*>(p + at);
              size_t name = at + sizeof(ElfW(Nhdr)), desc = name + ((n->n_namesz + 3) & ~3u);
              if (n->n_type == NT_GNU_BUILD_ID && n->n_namesz == 4 && std::memcmp(p + name, "GNU", 4) == 0)
                s->id.assign(reinterpret_cast<const char*>(p + desc), n->n_descsz);
              at = desc + ((n->n_descsz + 3) & ~3u);
            }
          }
          return 1;
        },
        &search);
    // Without a build id, the time this file was compiled stands in.
    return search.id.empty() ? std::string(__DATE__ " " __TIME__) : search.id;
  }();
  return id;
}

std::shared_ptr<CompiledShader> loadCachedImpl(const std::string& blob, const abi::HostSymbol* hostSymbols,
                                               std::string* error) {
  auto shader = std::make_shared<CompiledShader>();
  bool hasGroupEntry = false;
  std::optional<std::string_view> object = deserialize(blob, *shader, &hasGroupEntry);
  if (!object) {
    *error = "the cached entry is damaged (bad header or checksum)";
    return nullptr;
  }
  if (!loadObject(*shader, *object, hasGroupEntry, hostSymbols, error)) return nullptr;
  shader->cacheBlob = blob;
  return shader;
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
// instructions: debug information, reflection). A module without OpLine gets line information of its own, so
// that an out-of-bounds report can name the instruction (the optimizer moves and renumbers instructions, but keeps
// the OpLine of each): an OpString kWordOffsetFile, and before each instruction that accesses memory an OpLine
// naming it, whose line is the instruction's word offset in `words` (the application's module, specialized in
// place). Returns whether a DebugPrintf call remains.
bool prepareNonSemantic(std::vector<uint32_t>& words) {
  constexpr size_t kHeader = 5;
  if (words.size() < kHeader) return false;
  std::set<uint32_t> dropped;
  uint32_t printfSet = 0;
  bool hasLines = false, hasPrintf = false;
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
      }
    }
    if (op == spv::OpExtInst && count >= 5 && printfSet && words[at + 3] == printfSet) hasPrintf = true;
    hasLines = hasLines || op == spv::OpLine;
    at += count;
  }
  const uint32_t fileId = hasLines ? 0 : words[3];
  std::vector<uint32_t> out(words.begin(), words.begin() + kHeader);
  bool stringPlaced = hasLines, inFunctions = false;
  for (size_t at = kHeader; at < words.size();) {
    uint32_t count = words[at] >> 16;
    auto op = spv::Op(words[at] & 0xffff);
    bool drop = (op == spv::OpExtInstImport && dropped.count(words[at + 1])) ||
                (op == spv::OpExtInst && count >= 4 && dropped.count(words[at + 3]));
    if (!stringPlaced && op != spv::OpCapability && op != spv::OpExtension && op != spv::OpExtInstImport &&
        op != spv::OpMemoryModel && op != spv::OpEntryPoint && op != spv::OpExecutionMode &&
        op != spv::OpExecutionModeId) {
      // The debug section's first place: OpString comes before OpSource, OpName and everything after.
      std::vector<uint32_t> text((sizeof kWordOffsetFile + 3) / 4, 0);
      std::memcpy(text.data(), kWordOffsetFile, sizeof kWordOffsetFile);
      out.push_back(uint32_t(2 + text.size()) << 16 | spv::OpString);
      out.push_back(fileId);
      out.insert(out.end(), text.begin(), text.end());
      stringPlaced = true;
    }
    inFunctions = inFunctions || op == spv::OpFunction;
    bool access = op == spv::OpLoad || op == spv::OpStore || op == spv::OpCopyMemory || op == spv::OpAccessChain ||
                  op == spv::OpInBoundsAccessChain || op == spv::OpPtrAccessChain ||
                  op == spv::OpInBoundsPtrAccessChain || (op >= spv::OpAtomicLoad && op <= spv::OpAtomicXor);
    if (!hasLines && inFunctions && access) {
      out.push_back(4u << 16 | spv::OpLine);
      out.push_back(fileId);
      out.push_back(uint32_t(at));
      out.push_back(0);
    }
    if (!drop) out.insert(out.end(), words.begin() + at, words.begin() + at + count);
    at += count;
  }
  if (!hasLines) out[3] = words[3] + 1;
  words = std::move(out);
  return hasPrintf;
}

std::shared_ptr<CompiledShader> compileImpl(const CompileRequest& req, std::string* error) {
  std::vector<uint32_t> words(req.words, req.words + req.wordCount);
  if (!applySpecialization(words, req.specialization, error)) return nullptr;
  {
    Module original;
    if (!original.parse(words.data(), words.size(), error)) return nullptr;
    if (!original.findEntryPoint(req.entryName.c_str(), req.model)) {
      *error = "the module has no entry point \"" + req.entryName + "\" for this stage";
      return nullptr;
    }
    if (!checkSupport(original, error) || !checkSpecConstantOps(original, error)) return nullptr;
  }

  const bool printf = prepareNonSemantic(words);
  defineUndefinedShuffleComponents(words);
  keepOnlyEntryPoint(words, req.model, req.entryName);
  // Tokens Debian's SPIRV-Tools does not know are hidden from its optimizer and put back after it.
  HiddenTokens hidden;
  hideNewerTokensForOptimizer(words, &hidden);
  // Freeze specialization constants, fold what depends on them, inline every call into the entry point, drop
  // what it does not use.
  spvtools::Optimizer opt(SPV_ENV_VULKAN_1_3);
  std::string optError;
  opt.SetMessageConsumer([&](spv_message_level_t level, const char*, const spv_position_t& pos, const char* msg) {
    if (level <= SPV_MSG_ERROR && optError.empty()) optError = msg ? msg : "SPIRV-Tools optimizer error";
  });
  // The other non-semantic sets are gone already (prepareNonSemantic); without DebugPrintf calls SPIRV-Tools'
  // strip pass also removes the HLSL reflection decorations.
  if (!printf) opt.RegisterPass(spvtools::CreateStripNonSemanticInfoPass());
  opt.RegisterPass(spvtools::CreateFlattenDecorationPass())
      .RegisterPass(spvtools::CreateFreezeSpecConstantValuePass())
      .RegisterPass(spvtools::CreateFoldSpecConstantOpAndCompositePass());
  if (req.inlineFunctions) opt.RegisterPass(spvtools::CreateInlineExhaustivePass());
  opt.RegisterPass(spvtools::CreateEliminateDeadFunctionsPass())
      .RegisterPass(spvtools::CreateDeadVariableEliminationPass());
  std::vector<uint32_t> optimized;
  spvtools::OptimizerOptions options;
  options.set_run_validator(false);
  if (!opt.Run(words.data(), words.size(), &optimized, options)) {
    *error = "SPIRV-Tools optimizer failed: " + optError;
    return nullptr;
  }
  restoreNewerTokens(optimized, hidden);

  Module m;
  if (!m.parse(optimized.data(), optimized.size(), error)) return nullptr;
  const EntryPoint* ep = m.findEntryPoint(req.entryName.c_str(), req.model);
  if (!ep) {
    *error = "entry point lost in optimization";
    return nullptr;
  }

  auto shader = std::make_shared<CompiledShader>();
  shader->entryName = req.entryName;
  shader->model = req.model;
  for (int i = 0; i < 3; ++i) shader->localSize[i] = ep->localSize[i];
  auto context = std::make_unique<llvm::LLVMContext>();
  context->setOpaquePointers(true);
  auto mod = std::make_unique<llvm::Module>("vkrt_shader", *context);
  {
    Codegen cg(m, *context, *mod, *shader);
    if (!cg.run(*ep)) {
      *error = cg.error;
      return nullptr;
    }
  }
  shader->pushConstantBytes = kPushConstantBytes;
  std::string verify;
  llvm::raw_string_ostream vs(verify);
  if (llvm::verifyModule(*mod, &vs)) {
    *error = "internal compiler error (invalid LLVM IR): " + vs.str().substr(0, 300);
    return nullptr;
  }

  auto jtmb = detail::targetMachine(error);
  if (!jtmb) return nullptr;
  auto tm = jtmb->createTargetMachine();
  if (!tm) {
    *error = "LLVM: " + errText(tm.takeError());
    return nullptr;
  }
  mod->setDataLayout((*tm)->createDataLayout());
  mod->setTargetTriple((*tm)->getTargetTriple().str());
  {
    llvm::LoopAnalysisManager lam;
    llvm::FunctionAnalysisManager fam;
    llvm::CGSCCAnalysisManager cgam;
    llvm::ModuleAnalysisManager mam;
    llvm::PassBuilder pb(tm->get());
    pb.registerModuleAnalyses(mam);
    pb.registerCGSCCAnalyses(cgam);
    pb.registerFunctionAnalyses(fam);
    pb.registerLoopAnalyses(lam);
    pb.crossRegisterProxies(lam, fam, cgam, mam);
    pb.buildPerModuleDefaultPipeline(llvm::OptimizationLevel::O2).run(*mod, mam);
  }
  addCancellationPolls(*mod);

  // Code generation to an object file (kept for VkPipelineCache), then loaded into the JIT: the cold and the
  // cached path run exactly the same bytes.
  llvm::SmallVector<char, 0> object;
  {
    llvm::raw_svector_ostream os(object);
    llvm::legacy::PassManager pm;
    if ((*tm)->addPassesToEmitFile(pm, os, nullptr, llvm::CGFT_ObjectFile)) {
      *error = "LLVM: the target cannot emit object files";
      return nullptr;
    }
    pm.run(*mod);
  }
  bool hasGroupEntry = mod->getFunction("vkrt_group") != nullptr;
  mod.reset();
  context.reset();
  std::string_view objectBytes(object.data(), object.size());
  if (req.model != spv::ExecutionModelGLCompute && req.model != spv::ExecutionModelVertex &&
      req.model != spv::ExecutionModelFragment)
    shader->ray.frameBytes = frameBytesOf(objectBytes);
  if (!loadObject(*shader, objectBytes, hasGroupEntry, req.hostSymbols, error)) return nullptr;
  shader->cacheBlob = serialize(*shader, objectBytes);
  return shader;
}

}  // namespace

std::string cacheKey(const CompileRequest& req) {
  llvm::SHA256 h;
  auto add = [&](const void* data, size_t size) {
    uint64_t n = size;
    h.update(llvm::ArrayRef<uint8_t>(reinterpret_cast<const uint8_t*>(&n), sizeof n));
    h.update(llvm::ArrayRef<uint8_t>(static_cast<const uint8_t*>(data), size));
  };
  auto addStr = [&](const std::string& s) { add(s.data(), s.size()); };
  addStr("vkrt compiled shader 4");
  addStr(LLVM_VERSION_STRING);
  addStr(buildId());
  addStr(detail::targetKey());
  addStr(spmdKey());
  add(req.words, req.wordCount * sizeof(uint32_t));
  addStr(req.entryName);
  uint32_t model = req.model, inl = req.inlineFunctions;
  add(&model, 4);
  add(&inl, 4);
  for (const SpecValue& v : req.specialization) {
    add(&v.specId, sizeof v.specId);
    add(v.bytes.data(), v.bytes.size());
  }
  auto digest = h.final();
  return std::string("vkrt-shader:") + std::string(reinterpret_cast<const char*>(digest.data()), digest.size());
}

std::shared_ptr<CompiledShader> loadCached(const std::string& blob, const abi::HostSymbol* hostSymbols,
                                           std::string* error) {
  initLlvm();
  try {
    return loadCachedImpl(blob, hostSymbols, error);
  } catch (const LlvmFatal& e) {
    *error = std::string("LLVM fatal error: ") + e.what();
  } catch (const std::bad_alloc&) {
    *error = "out of memory while loading a cached shader";
  }
  return nullptr;
}

std::shared_ptr<CompiledShader> compile(const CompileRequest& request, std::string* error) {
  initLlvm();
  try {
    return compileImpl(request, error);
  } catch (const LlvmFatal& e) {
    *error = std::string("LLVM fatal error: ") + e.what();
  } catch (const std::bad_alloc&) {
    *error = "out of memory while compiling";
  }
  return nullptr;
}

}  // namespace vkrt::spirv
