// compile(): specialization, a support check against the application's module, SPIRV-Tools' optimizer,
// LLVM IR generation (Codegen), LLVM's O2 pipeline and ORC LLJIT. LLVM's fatal errors are turned into
// messages here (a handler that throws, caught at this boundary), never an abort.
#include <llvm/ExecutionEngine/Orc/ExecutionUtils.h>
#include <llvm/ExecutionEngine/Orc/JITTargetMachineBuilder.h>
#include <llvm/ExecutionEngine/Orc/LLJIT.h>
#include <llvm/ExecutionEngine/Orc/ThreadSafeModule.h>
#include <llvm/IR/Verifier.h>
#include <llvm/Passes/PassBuilder.h>
#include <llvm/Support/ErrorHandling.h>
#include <llvm/Support/TargetSelect.h>
#include <llvm/Support/raw_ostream.h>
#include <spirv-tools/optimizer.hpp>
#include <spirv/unified1/GLSL.std.450.h>

#include <cmath>
#include <cstring>
#include <mutex>
#include <set>
#include <stdexcept>

#include "spirv/codegen.hpp"

namespace vkrt::spirv {

struct CompiledShader::Jit {
  std::unique_ptr<llvm::orc::LLJIT> lljit;
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
    case spv::OpNop: case spv::OpUndef: case spv::OpSourceContinued: case spv::OpSource: case spv::OpSourceExtension:
    case spv::OpName: case spv::OpMemberName: case spv::OpString: case spv::OpLine: case spv::OpNoLine:
    case spv::OpModuleProcessed: case spv::OpExtension: case spv::OpExtInstImport: case spv::OpExtInst:
    case spv::OpMemoryModel: case spv::OpEntryPoint: case spv::OpExecutionMode: case spv::OpExecutionModeId:
    case spv::OpCapability: case spv::OpDecorate: case spv::OpMemberDecorate: case spv::OpDecorateId:
    case spv::OpDecorateString: case spv::OpMemberDecorateString:
    case spv::OpTypeVoid: case spv::OpTypeBool: case spv::OpTypeInt: case spv::OpTypeFloat: case spv::OpTypeVector:
    case spv::OpTypeMatrix: case spv::OpTypeArray: case spv::OpTypeRuntimeArray: case spv::OpTypeStruct:
    case spv::OpTypePointer: case spv::OpTypeFunction:
    case spv::OpConstantTrue: case spv::OpConstantFalse: case spv::OpConstant: case spv::OpConstantComposite:
    case spv::OpConstantNull: case spv::OpSpecConstantTrue: case spv::OpSpecConstantFalse: case spv::OpSpecConstant:
    case spv::OpSpecConstantComposite: case spv::OpSpecConstantOp:
    case spv::OpFunction: case spv::OpFunctionParameter: case spv::OpFunctionEnd: case spv::OpFunctionCall:
    case spv::OpVariable: case spv::OpLoad: case spv::OpStore: case spv::OpCopyMemory: case spv::OpAccessChain:
    case spv::OpInBoundsAccessChain: case spv::OpArrayLength:
    case spv::OpVectorExtractDynamic: case spv::OpVectorInsertDynamic: case spv::OpVectorShuffle:
    case spv::OpCompositeConstruct: case spv::OpCompositeExtract: case spv::OpCompositeInsert: case spv::OpCopyObject:
    case spv::OpCopyLogical: case spv::OpTranspose:
    case spv::OpConvertFToU: case spv::OpConvertFToS: case spv::OpConvertSToF: case spv::OpConvertUToF:
    case spv::OpUConvert: case spv::OpSConvert: case spv::OpFConvert: case spv::OpBitcast:
    case spv::OpSNegate: case spv::OpFNegate: case spv::OpIAdd: case spv::OpFAdd: case spv::OpISub: case spv::OpFSub:
    case spv::OpIMul: case spv::OpFMul: case spv::OpUDiv: case spv::OpSDiv: case spv::OpFDiv: case spv::OpUMod:
    case spv::OpSRem: case spv::OpSMod: case spv::OpFRem: case spv::OpFMod: case spv::OpVectorTimesScalar:
    case spv::OpMatrixTimesScalar: case spv::OpVectorTimesMatrix: case spv::OpMatrixTimesVector:
    case spv::OpMatrixTimesMatrix: case spv::OpOuterProduct: case spv::OpDot: case spv::OpIAddCarry:
    case spv::OpISubBorrow: case spv::OpUMulExtended: case spv::OpSMulExtended:
    case spv::OpAny: case spv::OpAll: case spv::OpIsNan: case spv::OpIsInf:
    case spv::OpLogicalEqual: case spv::OpLogicalNotEqual: case spv::OpLogicalOr: case spv::OpLogicalAnd:
    case spv::OpLogicalNot: case spv::OpSelect: case spv::OpIEqual: case spv::OpINotEqual: case spv::OpUGreaterThan:
    case spv::OpSGreaterThan: case spv::OpUGreaterThanEqual: case spv::OpSGreaterThanEqual: case spv::OpULessThan:
    case spv::OpSLessThan: case spv::OpULessThanEqual: case spv::OpSLessThanEqual: case spv::OpFOrdEqual:
    case spv::OpFUnordEqual: case spv::OpFOrdNotEqual: case spv::OpFUnordNotEqual: case spv::OpFOrdLessThan:
    case spv::OpFUnordLessThan: case spv::OpFOrdGreaterThan: case spv::OpFUnordGreaterThan:
    case spv::OpFOrdLessThanEqual: case spv::OpFUnordLessThanEqual: case spv::OpFOrdGreaterThanEqual:
    case spv::OpFUnordGreaterThanEqual:
    case spv::OpShiftRightLogical: case spv::OpShiftRightArithmetic: case spv::OpShiftLeftLogical:
    case spv::OpBitwiseOr: case spv::OpBitwiseXor: case spv::OpBitwiseAnd: case spv::OpNot:
    case spv::OpBitFieldInsert: case spv::OpBitFieldSExtract: case spv::OpBitFieldUExtract: case spv::OpBitReverse:
    case spv::OpBitCount:
    case spv::OpControlBarrier: case spv::OpMemoryBarrier:
    case spv::OpAtomicLoad: case spv::OpAtomicStore: case spv::OpAtomicExchange: case spv::OpAtomicCompareExchange:
    case spv::OpAtomicIIncrement: case spv::OpAtomicIDecrement: case spv::OpAtomicIAdd: case spv::OpAtomicISub:
    case spv::OpAtomicSMin: case spv::OpAtomicUMin: case spv::OpAtomicSMax: case spv::OpAtomicUMax:
    case spv::OpAtomicAnd: case spv::OpAtomicOr: case spv::OpAtomicXor:
    case spv::OpPhi: case spv::OpLoopMerge: case spv::OpSelectionMerge: case spv::OpLabel: case spv::OpBranch:
    case spv::OpBranchConditional: case spv::OpSwitch: case spv::OpReturn: case spv::OpReturnValue:
    case spv::OpUnreachable:
      return true;
    default:
      return false;
  }
}

bool supportedCapability(uint32_t cap) {
  switch (cap) {
    case spv::CapabilityShader: case spv::CapabilityMatrix: case spv::CapabilityInt64: case spv::CapabilityInt16:
    case spv::CapabilityInt8: case spv::CapabilityFloat64: case spv::CapabilityFloat16:
    case spv::CapabilityInt64Atomics:
      return true;
    default:
      return false;
  }
}

bool supportedGlsl(uint32_t inst) {
  switch (inst) {
    case GLSLstd450IMix: case GLSLstd450Frexp: case GLSLstd450FrexpStruct: case GLSLstd450PackSnorm4x8:
    case GLSLstd450PackUnorm4x8: case GLSLstd450PackSnorm2x16: case GLSLstd450PackUnorm2x16: case GLSLstd450PackHalf2x16:
    case GLSLstd450PackDouble2x32: case GLSLstd450UnpackSnorm2x16: case GLSLstd450UnpackUnorm2x16:
    case GLSLstd450UnpackHalf2x16: case GLSLstd450UnpackSnorm4x8: case GLSLstd450UnpackUnorm4x8:
    case GLSLstd450UnpackDouble2x32: case GLSLstd450InterpolateAtCentroid: case GLSLstd450InterpolateAtSample:
    case GLSLstd450InterpolateAtOffset:
      return false;
    default:
      return inst < GLSLstd450Count;
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
    if (in.op == spv::OpCapability && !supportedCapability(in.word(1))) {
      std::snprintf(buf, sizeof buf, "unsupported capability %u (OpCapability at word %u)", in.word(1), in.offset);
      *error = buf;
      return false;
    }
    if (in.op == spv::OpExtInst) {
      auto it = m.extInstImports.find(in.word(3));
      bool glsl = it != m.extInstImports.end() && it->second == "GLSL.std.450";
      if (!glsl || !supportedGlsl(in.word(4))) {
        std::snprintf(buf, sizeof buf, "unsupported instruction OpExtInst %s %u at word %u",
                      it != m.extInstImports.end() ? it->second.c_str() : "?", in.word(4), in.offset);
        *error = buf;
        return false;
      }
    }
  }
  return true;
}

// The C library functions generated code may call, resolved to vkrt's own imports (the application's
// global symbol scope need not contain libm).
void defineRuntimeSymbols(llvm::orc::LLJIT& jit) {
  llvm::orc::SymbolMap map;
  auto add = [&](const char* name, auto* fn) {
    map[jit.mangleAndIntern(name)] = llvm::JITEvaluatedSymbol(llvm::pointerToJITTargetAddress(fn), llvm::JITSymbolFlags::Exported);
  };
#define VKRT_MATH1(N) add(#N "f", static_cast<float (*)(float)>(::N##f)); add(#N, static_cast<double (*)(double)>(::N));
#define VKRT_MATH2(N) add(#N "f", static_cast<float (*)(float, float)>(::N##f)); add(#N, static_cast<double (*)(double, double)>(::N));
  VKRT_MATH1(sin) VKRT_MATH1(cos) VKRT_MATH1(tan) VKRT_MATH1(asin) VKRT_MATH1(acos) VKRT_MATH1(atan)
  VKRT_MATH1(sinh) VKRT_MATH1(cosh) VKRT_MATH1(tanh) VKRT_MATH1(asinh) VKRT_MATH1(acosh) VKRT_MATH1(atanh)
  VKRT_MATH1(exp) VKRT_MATH1(exp2) VKRT_MATH1(log) VKRT_MATH1(log2) VKRT_MATH1(sqrt) VKRT_MATH1(floor)
  VKRT_MATH1(ceil) VKRT_MATH1(trunc) VKRT_MATH1(round) VKRT_MATH1(rint) VKRT_MATH1(nearbyint) VKRT_MATH1(roundeven)
  VKRT_MATH2(atan2) VKRT_MATH2(pow) VKRT_MATH2(fmod) VKRT_MATH2(fmin) VKRT_MATH2(fmax)
#undef VKRT_MATH1
#undef VKRT_MATH2
  add("fmaf", static_cast<float (*)(float, float, float)>(::fmaf));
  add("fma", static_cast<double (*)(double, double, double)>(::fma));
  add("sincosf", static_cast<void (*)(float, float*, float*)>(::sincosf));
  add("sincos", static_cast<void (*)(double, double*, double*)>(::sincos));
  add("memset", static_cast<void* (*)(void*, int, size_t)>(::memset));
  add("memcpy", static_cast<void* (*)(void*, const void*, size_t)>(::memcpy));
  add("memmove", static_cast<void* (*)(void*, const void*, size_t)>(::memmove));
  llvm::cantFail(jit.getMainJITDylib().define(llvm::orc::absoluteSymbols(std::move(map))));
}

std::string errText(llvm::Error e) {
  std::string s;
  llvm::raw_string_ostream os(s);
  os << e;
  return os.str();
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
    if (!checkSupport(original, error)) return nullptr;
  }

  // Freeze specialization constants, fold what depends on them, inline every call into the entry points.
  spvtools::Optimizer opt(SPV_ENV_VULKAN_1_3);
  std::string optError;
  opt.SetMessageConsumer([&](spv_message_level_t level, const char*, const spv_position_t& pos, const char* msg) {
    if (level <= SPV_MSG_ERROR && optError.empty()) optError = msg ? msg : "SPIRV-Tools optimizer error";
  });
  opt.RegisterPass(spvtools::CreateFreezeSpecConstantValuePass())
      .RegisterPass(spvtools::CreateFoldSpecConstantOpAndCompositePass());
  if (req.inlineFunctions) opt.RegisterPass(spvtools::CreateInlineExhaustivePass());
  opt.RegisterPass(spvtools::CreateEliminateDeadFunctionsPass());
  std::vector<uint32_t> optimized;
  spvtools::OptimizerOptions options;
  options.set_run_validator(false);
  if (!opt.Run(words.data(), words.size(), &optimized, options)) {
    *error = "SPIRV-Tools optimizer failed: " + optError;
    return nullptr;
  }

  Module m;
  if (!m.parse(optimized.data(), optimized.size(), error)) return nullptr;
  const EntryPoint* ep = m.findEntryPoint(req.entryName.c_str(), req.model);
  if (!ep) {
    *error = "entry point lost in optimization";
    return nullptr;
  }
  for (const Instruction& in : m.instructions) {
    if (in.op == spv::OpSpecConstantOp) {
      *error = "specialization constant operation left after folding (OpSpecConstantOp)";
      return nullptr;
    }
  }

  auto shader = std::make_shared<CompiledShader>();
  shader->entryName = req.entryName;
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

  auto jtmb = llvm::orc::JITTargetMachineBuilder::detectHost();
  if (!jtmb) {
    *error = "LLVM: " + errText(jtmb.takeError());
    return nullptr;
  }
  jtmb->setCodeGenOptLevel(llvm::CodeGenOpt::Default);
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

  auto lljit = llvm::orc::LLJITBuilder().setJITTargetMachineBuilder(std::move(*jtmb)).create();
  if (!lljit) {
    *error = "LLVM: " + errText(lljit.takeError());
    return nullptr;
  }
  // Session errors (unresolved symbols...) come back through lookup(); keep them off stderr.
  (*lljit)->getExecutionSession().setErrorReporter([](llvm::Error e) { llvm::consumeError(std::move(e)); });
  defineRuntimeSymbols(**lljit);
  if (auto e = (*lljit)->addIRModule(llvm::orc::ThreadSafeModule(std::move(mod), std::move(context)))) {
    *error = "LLVM: " + errText(std::move(e));
    return nullptr;
  }
  auto sym = (*lljit)->lookup("vkrt_main");
  if (!sym) {
    *error = "LLVM: " + errText(sym.takeError());
    return nullptr;
  }
  shader->entry = sym->toPtr<ComputeEntry>();
  shader->jit = std::make_unique<CompiledShader::Jit>();
  shader->jit->lljit = std::move(*lljit);
  return shader;
}

}  // namespace

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
