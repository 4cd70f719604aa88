// The SPIR-V -> native compiler's interface (no LLVM in this header: the runtime includes it).
//
// compile() takes validated SPIR-V, applies specialization, simplifies the module with SPIRV-Tools'
// optimizer, translates the entry point and every function it calls into LLVM IR (one LLVM function per
// SPIR-V function), optimizes it and JITs it with ORC to native code. Anything not supported yet fails with
// a message naming the instruction and its word offset in the application's module; LLVM errors (fatal ones
// included) become messages too, never an abort.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "abi/abi.hpp"
#include "abi/image_functions.hpp"
#include "spirv/module.hpp"

namespace vkrt::spirv {

struct ResourceBinding {
  uint32_t set;
  uint32_t binding;
  uint32_t arraySize;  // descriptors the shader declares (0: runtime-sized array)
  bool uniform;        // Uniform storage class with Block (a uniform buffer); else a storage buffer
  // Buffer (uniform/storage per `uniform`), or an image/sampler/texel buffer descriptor of a UniformConstant
  // variable (a texel buffer is an image of Dim Buffer: uniform when Sampled is 1, storage when 2).
  enum Kind : uint8_t {
    Buffer,
    StorageImage,
    SampledImage,
    Sampler,
    CombinedImageSampler,
    AccelerationStructure,
    UniformTexelBuffer,
    StorageTexelBuffer,
    InputAttachment  // an image of Dim SubpassData
  };
  Kind kind = Buffer;
};

// What a compiled ray tracing shader tells the pipeline: the sizes its ray tracing variables declare (for
// VkRayTracingPipelineInterfaceCreateInfoKHR) and the stack it keeps while a shader it calls runs.
struct RayStageInfo {
  uint32_t payloadBytes = 0;        // the largest RayPayloadKHR or IncomingRayPayloadKHR variable
  uint32_t callableDataBytes = 0;   // the largest CallableDataKHR or IncomingCallableDataKHR variable
  uint32_t hitAttributeBytes = 0;   // the HitAttributeKHR variable
  uint32_t frameBytes = 0;          // native stack of the compiled code: every function's frame, return address
                                    // included (outgoing payloads and callable data, locals, spills)
  bool callsOut = false;            // the code makes OpTraceRayKHR or OpExecuteCallableKHR calls
  bool readsHitAttributes = false;  // any-hit / closest-hit: HitAttributeKHR is the runtime's, read via the context
  bool checksPendingAdds = false;   // compiled with CompileRequest::combineAdds

  // vkGetRayTracingShaderGroupStackSizeKHR's figure: 0 for a shader that calls nothing (none of it is live
  // while another shader runs); otherwise its frame, plus the hit attributes it reads (the runtime keeps the hit
  // they belong to while the call runs), rounded up to 16.
  uint32_t stackSize() const {
    if (!callsOut) return 0;
    uint64_t bytes = uint64_t(frameBytes) + (readsHitAttributes ? hitAttributeBytes : 0);
    return uint32_t((bytes + 15) / 16 * 16);
  }
};

// What a compiled vertex or fragment shader tells the graphics pipeline (abi::GraphicsInvocation's conventions).
struct GraphicsStageInfo {
  struct Location {
    uint8_t location = 0;
    uint8_t componentMask = 0;  // components of the location the shader declares (bit c = component c)
    enum Interpolation : uint8_t { Smooth, NoPerspective, Flat } interpolation = Smooth;
    bool centroid = false;
    bool sample = false;
    bool integer = false;  // signed or unsigned integer components (vertex inputs: the attribute's conversion)
    bool wide = false;     // 64-bit components
  };
  std::vector<Location> inputs;   // user Input locations, by increasing location
  std::vector<Location> outputs;  // user Output locations (fragment: color attachments written)
  bool needsQuad = false;         // derivatives, implicit-LOD sampling or quad operations: lanes run as fibers
  bool writesDepth = false;       // FragDepth
  bool writesSampleMask = false;  // SampleMask output
  bool readsSampleId = false;     // SampleId or SamplePosition (or a Sample-decorated input): per-sample shading
  bool canDiscard = false;        // OpKill, OpTerminateInvocation, OpDemoteToHelperInvocation
  bool earlyFragmentTests = false;
  bool sideEffects = false;  // stores or atomics to buffers or images
  bool dualSource = false;   // an output with Index 1
  bool writesPointSize = false;
  bool readsFragCoord = false;   // FragCoord (else the rasterizer need not compute its w for one-sample quads)
  bool readsPointCoord = false;  // PointCoord (else it is neither computed nor handed to the invocations)
  bool readsSampleMask = false;  // SampleMask as an input (else the invocations' sampleMaskIn is not set per quad)
  // The SPMD entry writes colour attachment 0 where the executor gives it a quad's address (CompileRequest::colorMerge,
  // abi::GraphicsInvocation::colorQuad).
  bool mergesColor = false;
  uint32_t clipDistances = 0;  // ClipDistance array size
  uint32_t cullDistances = 0;
};

class CompiledShader {
 public:
  CompiledShader();
  ~CompiledShader();
  CompiledShader(const CompiledShader&) = delete;
  CompiledShader& operator=(const CompiledShader&) = delete;

  // Exactly one of these is set. Shaders with OpControlBarrier get `entry` (vkrt_main), run once per invocation, or,
  // compiled SPMD (spmdLanes > 0), `groupEntry` running one batch of spmdLanes invocations from ctx->localIndex on
  // (both as fibers that switch at each barrier); the others `groupEntry` (vkrt_group), which runs a whole workgroup
  // in one call: it loops over the local invocation ids, setting the invocation built-ins in the context
  // (ctx->workgroupId must be set). Ray tracing stages get `rayEntry` (vkrt_main taking a RayInvocation) instead.
  abi::ComputeEntry entry = nullptr;
  abi::ComputeEntry groupEntry = nullptr;
  abi::RayEntry rayEntry = nullptr;
  // Ray generation shaders compiled SPMD (spmdLanes > 0) also get this: spmdLanes launch ids in one call (abi.hpp).
  abi::RayBatchEntry rayBatchEntry = nullptr;
  abi::GraphicsEntry graphicsEntry = nullptr;  // Vertex and Fragment: vkrt_main taking a GraphicsInvocation
  GraphicsStageInfo graphics;                  // Vertex and Fragment only
  spv::ExecutionModel model = spv::ExecutionModelGLCompute;
  RayStageInfo ray;  // ray tracing stages only
  uint32_t localSize[3] = {1, 1, 1};
  uint32_t workgroupMemorySize = 0;
  bool usesBarrier = false;
  // Invocations groupEntry runs per pass (SPMD, spirv/spmd.hpp): 4, 8 or 16; 0 where it runs them one by one.
  // Fragment shaders: 4 where graphicsEntry takes a quad's four GraphicsInvocations (an array) in one call, 0 where
  // it is the scalar vkrt_main, run once per lane (as fibers where the shader takes derivatives). Ray generation
  // shaders: the lanes of rayBatchEntry, 0 where it has none.
  uint8_t spmdLanes = 0;
  std::vector<ResourceBinding> resources;  // abi::ResourceSlot order
  uint32_t pushConstantBytes = 0;          // bytes of push constants the shader may read
  std::string entryName;

  struct Jit;  // the ORC JIT that owns the code (compiler-private)
  std::unique_ptr<Jit> jit;
  // This shader serialized for VkPipelineCache (object code and the fields above; see loadCached()).
  std::string cacheBlob;
};

struct CompileRequest {
  const uint32_t* words = nullptr;
  size_t wordCount = 0;
  std::string entryName = "main";
  spv::ExecutionModel model = spv::ExecutionModelGLCompute;  // GLCompute, Vertex, Fragment or a ray tracing model
  std::vector<SpecValue> specialization;
  // Inline every call with SPIRV-Tools before translation (what pipelines do). Off, each SPIR-V function
  // becomes its own LLVM function (LLVM may still inline them); the tests use this to exercise calls.
  bool inlineFunctions = true;
  // The functions outside the shader its code may call (the image functions of abi/image_functions.hpp),
  // null-terminated; the runtime supplies its own. Code calling a function missing here fails to load.
  const abi::HostSymbol* hostSymbols = nullptr;
  // Ray tracing stages: combine counter adds (abi::PendingAdds) and check every buffer access against the pending
  // word. The pipeline asks for it in every stage when any of its stages has such an add (spirv/module.hpp's
  // hasCombinableAdds): the checks cost pipelines without one nothing. A launch combines only when every shader it can
  // run was compiled with it (RayStageInfo::checksPendingAdds).
  bool combineAdds = false;
  // Fragment shaders: colour attachment 0's format and blend, for the SPMD entry to write the attachment itself after
  // the shader (abi::ColorMerge; GraphicsStageInfo::mergesColor says whether it does: not where the shader can
  // discard or writes FragDepth or SampleMask, or has no float output at location 0). kNone: it writes no attachment.
  abi::ColorMerge colorMerge;
};

// Returns the compiled shader, or nullptr with `error` set to a message naming the reason (for unsupported
// instructions: "unsupported instruction OpXxx at word N").
std::shared_ptr<CompiledShader> compile(const CompileRequest& request, std::string* error);

// SPMD compilation of compute shaders (on by default; VKRT_SPMD=0 turns it off): a workgroup runs in batches of the
// target's vector width (CompiledShader::spmdLanes) where the compiler supports every instruction of the shader;
// fragment shaders, a quad (4 lanes) per call.
// Applies to every later compilation in the process; part of cacheKey().
void setSpmd(bool enabled);
bool spmdEnabled();
// The lanes of a batch for the target CPU (16 with AVX-512 and with AVX2, whose values take two registers, so that a
// loop-carried chain runs as two independent halves; 8 below, likewise), 0 when SPMD is off.
unsigned spmdLanes();

// The CPU compiled code targets: "native" (or empty), the host CPU and every feature it has, the default; or an
// x86-64 CPU LLVM knows ("x86-64-v2", "x86-64-v3", "haswell", ...), whose features alone code may use. False,
// with `error` set, for a name LLVM does not know or a CPU with a feature this one lacks. Applies to every later
// compilation in the process; part of cacheKey().
bool setTargetCpu(std::string_view cpu, std::string* error);
// The target setTargetCpu() chose: "native (<host CPU name>)" or the CPU's name.
std::string targetCpu();

// The VkPipelineCache key of a compilation: a SHA-256 over the SPIR-V, entry point, stage, specialization
// bytes, LLVM's version, vkrt's build id and the target CPU (compiled code is only reused where it can run).
std::string cacheKey(const CompileRequest& request);
// Loads a shader from a CompiledShader::cacheBlob without running LLVM's optimizer or code generator.
// Malformed or damaged blobs (checked by a checksum before LLVM sees the object) fail with `error` set.
std::shared_ptr<CompiledShader> loadCached(const std::string& blob, const abi::HostSymbol* hostSymbols,
                                           std::string* error);

}  // namespace vkrt::spirv
