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
#include <vector>

#include "spirv/abi.hpp"
#include "spirv/module.hpp"

namespace vkrt::spirv {

struct ResourceBinding {
  uint32_t set;
  uint32_t binding;
  uint32_t arraySize;  // descriptors the shader declares (0: runtime-sized array)
  bool uniform;        // Uniform storage class with Block (a uniform buffer); else a storage buffer
  // Buffer (uniform/storage per `uniform`), or an image/sampler descriptor of a UniformConstant variable.
  enum Kind : uint8_t { Buffer, StorageImage, SampledImage, Sampler, CombinedImageSampler };
  Kind kind = Buffer;
};

class CompiledShader {
 public:
  CompiledShader();
  ~CompiledShader();
  CompiledShader(const CompiledShader&) = delete;
  CompiledShader& operator=(const CompiledShader&) = delete;

  // Exactly one of these is set. Shaders with OpControlBarrier get `entry` (vkrt_main), run once per invocation;
  // the others `groupEntry` (vkrt_group), which runs a whole workgroup in one call: it loops over the local
  // invocation ids, setting the invocation built-ins in the context (ctx->workgroupId must be set).
  ComputeEntry entry = nullptr;
  ComputeEntry groupEntry = nullptr;
  uint32_t localSize[3] = {1, 1, 1};
  uint32_t workgroupMemorySize = 0;
  bool usesBarrier = false;
  std::vector<ResourceBinding> resources;  // ResourceSlot order
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
  spv::ExecutionModel model = spv::ExecutionModelGLCompute;
  std::vector<SpecValue> specialization;
  // Inline every call with SPIRV-Tools before translation (what pipelines do). Off, each SPIR-V function
  // becomes its own LLVM function (LLVM may still inline them); the tests use this to exercise calls.
  bool inlineFunctions = true;
};

// Returns the compiled shader, or nullptr with `error` set to a message naming the reason (for unsupported
// instructions: "unsupported instruction OpXxx at word N").
std::shared_ptr<CompiledShader> compile(const CompileRequest& request, std::string* error);

// The VkPipelineCache key of a compilation: a SHA-256 over the SPIR-V, entry point, stage, specialization
// bytes, LLVM's version, vkrt's build id and the host CPU (compiled code is only reused where it can run).
std::string cacheKey(const CompileRequest& request);
// Loads a shader from a CompiledShader::cacheBlob without running LLVM's optimizer or code generator.
// Malformed or damaged blobs (checked by a checksum before LLVM sees the object) fail with `error` set.
std::shared_ptr<CompiledShader> loadCached(const std::string& blob, std::string* error);

}  // namespace vkrt::spirv
