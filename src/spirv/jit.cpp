// compile(): specialization, a support check against the application's module (opcode_support.hpp), the rewrites
// before SPIRV-Tools' optimizer (pre_optimizer.hpp), the optimizer, LLVM IR generation (Codegen), LLVM's O2 pipeline,
// the cancellation polls (cancellation_poll.hpp), an object file and ORC LLJIT; loadCached() loads a pipeline cache
// blob (cache_blob.hpp) the same way. LLVM's fatal errors are turned into messages here (a handler that throws,
// caught at this boundary), never an abort.
#include <llvm/ExecutionEngine/Orc/ExecutionUtils.h>
#include <llvm/ExecutionEngine/Orc/JITTargetMachineBuilder.h>
#include <llvm/ExecutionEngine/Orc/LLJIT.h>
#include <llvm/ExecutionEngine/Orc/RTDyldObjectLinkingLayer.h>
#include <llvm/ExecutionEngine/Orc/ThreadSafeModule.h>
#include <llvm/ExecutionEngine/SectionMemoryManager.h>
#include <llvm/IR/LegacyPassManager.h>
#include <llvm/IR/Verifier.h>
#include <llvm/Object/ELFObjectFile.h>
#include <llvm/Object/ObjectFile.h>
#include <llvm/Passes/PassBuilder.h>
#include <llvm/Support/ErrorHandling.h>
#include <llvm/Support/LEB128.h>
#include <llvm/Support/MemoryBuffer.h>
#include <llvm/Support/TargetSelect.h>
#include <llvm/Support/raw_ostream.h>
#include <llvm/Target/TargetMachine.h>
#include <spirv-tools/optimizer.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string_view>

#include "abi/jit_code.hpp"
#include "spirv/cache_blob.hpp"
#include "spirv/cancellation_poll.hpp"
#include "spirv/codegen.hpp"
#include "spirv/newer_tokens.hpp"
#include "spirv/opcode_support.hpp"
#include "spirv/pre_optimizer.hpp"
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

namespace {
// Whether the module's words hold an OpFunctionCall.
bool hasFunctionCall(const std::vector<uint32_t>& words) {
  for (size_t i = 5; i < words.size();) {
    const uint32_t n = words[i] >> 16;
    if ((words[i] & 0xffff) == spv::OpFunctionCall) return true;
    i += n ? n : 1;
  }
  return false;
}
}  // namespace

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

void ignoreDebugPrintf(abi::InvocationContext*, const uint8_t*, const uint64_t*) {}
void ignoreOutOfBounds(abi::InvocationContext*, const uint8_t*, uint64_t, uint64_t, uint64_t) {}
const void* noAddressTable(abi::InvocationContext*) { return nullptr; }
uint32_t acceptAddress(abi::InvocationContext*, const void*, const uint8_t*, uint64_t, uint64_t, uint64_t*) {
  return 1;
}
void ignoreImageCheck(abi::InvocationContext*, const uint8_t*, const abi::DescriptorRecord*, const int32_t*, int32_t,
                      uint64_t) {}
void ignoreTexelCheck(abi::InvocationContext*, const uint8_t*, const abi::DescriptorRecord*, int64_t, uint64_t) {}

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
  add("vkrt_address_table", &noAddressTable);  // (VKRT_SHADER_CHECKS: nothing to check against without the runtime)
  add("vkrt_check_address", &acceptAddress);
  add("vkrt_check_image", &ignoreImageCheck);
  add("vkrt_check_texel_buffer", &ignoreTexelCheck);
  for (const abi::HostSymbol* s = hostSymbols; s && s->name; ++s) add(s->name, s->address);
  llvm::cantFail(jit.getMainJITDylib().define(llvm::orc::absoluteSymbols(std::move(map))));
}

using detail::errText;

// The native stack the object's code uses: the sum of every function's frame (its .stack_sizes entry: an
// address, then the size as ULEB128) plus its return address. A sum, not the deepest path: an upper bound, and
// exact when everything is inlined into vkrt_main (pipelines inline every call). A ray generation shader's SPMD
// entry (vkrt_group) is not counted: it runs the invocations vkrt_main would, and the shader's stack size
// (vkGetRayTracingShaderGroupStackSizeKHR) is one invocation's.
uint32_t frameBytesOf(std::string_view object) {
  auto file = llvm::object::ObjectFile::createObjectFile(
      llvm::MemoryBufferRef(llvm::StringRef(object.data(), object.size()), "shader"));
  if (!file) {
    llvm::consumeError(file.takeError());
    return 0;
  }
  // vkrt_group's entry: the one whose address is relocated to vkrt_group's (a section symbol plus the function's
  // offset, or the function's own symbol).
  std::optional<llvm::object::SectionRef> groupSection;
  uint64_t groupOffset = 0;
  for (const llvm::object::SymbolRef& symbol : (*file)->symbols()) {
    auto name = symbol.getName();
    auto section = symbol.getSection();
    auto value = symbol.getValue();
    if (name && section && value && *name == "vkrt_group" && *section != (*file)->section_end()) {
      groupSection = **section;
      groupOffset = *value;
    }
    if (!name) llvm::consumeError(name.takeError());
    if (!section) llvm::consumeError(section.takeError());
    if (!value) llvm::consumeError(value.takeError());
  }
  std::vector<uint64_t> skipped;  // offsets in .stack_sizes of the entries not counted
  for (const llvm::object::SectionRef& rel : (*file)->sections()) {
    if (!groupSection || !llvm::isa<llvm::object::ELFObjectFileBase>(**file)) break;
    auto target = rel.getRelocatedSection();
    if (!target) {
      llvm::consumeError(target.takeError());
      continue;
    }
    if (*target == (*file)->section_end()) continue;
    auto targetName = (*target)->getName();
    if (!targetName || *targetName != ".stack_sizes") {
      if (!targetName) llvm::consumeError(targetName.takeError());
      continue;
    }
    for (const llvm::object::RelocationRef& r : rel.relocations()) {
      auto symbol = r.getSymbol();
      if (symbol == (*file)->symbol_end()) continue;
      auto section = symbol->getSection();
      auto value = symbol->getValue();
      auto addend = llvm::object::ELFRelocationRef(r).getAddend();
      if (section && value && addend && *section != (*file)->section_end() && **section == *groupSection &&
          *value + uint64_t(*addend) == groupOffset)
        skipped.push_back(r.getOffset());
      if (!section) llvm::consumeError(section.takeError());
      if (!value) llvm::consumeError(value.takeError());
      if (!addend) llvm::consumeError(addend.takeError());
    }
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
    const uint8_t* start = p;
    while (end - p > 8) {
      const uint64_t at = uint64_t(p - start);
      p += 8;  // the function's address (relocated)
      unsigned n = 0;
      const char* err = nullptr;
      uint64_t size = llvm::decodeULEB128(p, &n, end, &err);
      if (err) break;
      p += n;
      if (std::find(skipped.begin(), skipped.end(), at) != skipped.end()) continue;
      total += size + 8;
    }
  }
  return uint32_t(std::min<uint64_t>(total, UINT32_MAX));
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
    // Ray tracing stages: vkrt_main, and a ray generation shader's SPMD batch entry (vkrt_group) beside it.
    if (hasGroupEntry) {
      shader.rayBatchEntry = sym->toPtr<abi::RayBatchEntry>();
      sym = (*lljit)->lookup("vkrt_main");
      if (!sym) {
        *error = "LLVM: " + errText(sym.takeError());
        return false;
      }
    }
    shader.rayEntry = sym->toPtr<abi::RayEntry>();
  } else {
    (hasGroupEntry ? shader.groupEntry : shader.entry) = sym->toPtr<abi::ComputeEntry>();
  }
  shader.jit = std::make_unique<CompiledShader::Jit>();
  shader.jit->lljit = std::move(*lljit);
  shader.jit->codeSlots = std::move(codeSlots);
  return true;
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
  foldQuantizeToF16SpecConstants(words);
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
  // Further rounds on the result; one that fails leaves it as it was (what they buy is the SPMD path).
  auto round = [&](const std::function<void(spvtools::Optimizer&)>& passes) {
    spvtools::Optimizer more(SPV_ENV_VULKAN_1_3);
    more.SetMessageConsumer([](spv_message_level_t, const char*, const spv_position_t&, const char*) {});
    passes(more);
    std::vector<uint32_t> out;
    if (more.Run(optimized.data(), optimized.size(), &out, options)) optimized = std::move(out);
  };
  // The inliner leaves a function with a return inside a loop; with its returns merged into one it inlines it.
  if (req.inlineFunctions && hasFunctionCall(optimized))
    round([](spvtools::Optimizer& o) {
      o.RegisterPass(spvtools::CreateMergeReturnPass())
          .RegisterPass(spvtools::CreateInlineExhaustivePass())
          .RegisterPass(spvtools::CreateEliminateDeadFunctionsPass());
    });
  // A DebugPrintf a specialization constant turns off (`if (kDebug) debugPrintfEXT(...)`) goes with its branch,
  // which the frozen constant decides: the SPMD path, which has no printf, then takes the shader.
  if (printf) round([](spvtools::Optimizer& o) { o.RegisterPass(spvtools::CreateDeadBranchElimPass()); });
  // Compute shaders' Function variables that only loads and stores use become SSA values (structs and arrays split
  // first): the SPMD path's uniformity analysis then sees a loop counter as the phi it is, not as a variable stored
  // under a divergent loop's control (which takes storage per lane).
  if (req.model == spv::ExecutionModelGLCompute && req.inlineFunctions)
    round([](spvtools::Optimizer& o) {
      o.RegisterPass(spvtools::CreateScalarReplacementPass())
          .RegisterPass(spvtools::CreateLocalSingleBlockLoadStoreElimPass())
          .RegisterPass(spvtools::CreateLocalSingleStoreElimPass())
          .RegisterPass(spvtools::CreateSSARewritePass())
          .RegisterPass(spvtools::CreateDeadVariableEliminationPass());
    });
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
    cg.combining = req.combineAdds;
    cg.colorMerge = req.colorMerge;
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
