// libFuzzer target: SPIR-V through the JIT. An input is a SPIR-V module's bytes (seeds: fuzz/corpus/spirv, the
// test shaders; the mutations that SPIRV-Tools' validator accepts reach the compiler). vkCreateShaderModule, then
// for each of (at most two of) its entry points the pipeline of its stage, compiled: specialization,
// SPIRV-Tools' optimizer, translation to LLVM IR, LLVM's optimizer and ORC — a compute pipeline, or a ray tracing
// pipeline library with one group. The pipeline layout is empty, so a shader using resources compiles and is then
// refused by the layout check; the compiled code never runs (a fuzzed shader may loop forever).
//
// A module with a ray tracing entry point gets its own device: the compiled code of ray tracing groups lives as
// long as the device's group records (runtime/shader_cache.hpp), so one device for the whole run would keep every
// ray tracing shader it ever compiled. Compute modules share the process's device (a failed pipeline keeps nothing).
// Per-input work is capped by the input length (-max_len in tools/fuzz.sh) and libFuzzer's -timeout.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "runtime/shader_cache.hpp"
#include "spirv_stages.hpp"

// How many inputs reached the compiler (most mutations are refused by the validator first), printed at exit: the
// figure docs/testing.md ("Fuzzing") gives as the executions "compiled".
extern "C" int LLVMFuzzerInitialize(int*, char***) {
  std::atexit([] {
    std::fprintf(stderr, "vkrt_fuzz_spirv_pipeline: %llu shader compilations\n",
                 (unsigned long long)vkrt::shaderCompileCount());
  });
  return 0;
}

extern "C" size_t LLVMFuzzerMutate(uint8_t* data, size_t size, size_t maxSize);

extern "C" size_t LLVMFuzzerCustomMutator(uint8_t* data, size_t size, size_t maxSize, unsigned int seed) {
  return vkrt::fuzz::mutateSpirv(data, size, maxSize, seed, LLVMFuzzerMutate);
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace vkrt;
  std::vector<uint32_t> words = fuzz::wordsOf(data, size);
  bool rayTracing = false;
  {
    spirv::Module m;
    std::string error;
    if (m.parse(words.data(), words.size(), &error))
      for (const spirv::EntryPoint& ep : m.entryPoints) rayTracing |= ep.model != spv::ExecutionModelGLCompute;
  }
  fuzz::FuzzDevice own;
  VkDevice device = fuzz::fuzzDevice().device;
  if (rayTracing) {
    own = fuzz::makeFuzzDevice();
    device = own.device;
  }
  VkPipelineLayoutCreateInfo lci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  VkPipelineLayout layout = VK_NULL_HANDLE;
  if (vkrt_CreatePipelineLayout(device, &lci, nullptr, &layout) == VK_SUCCESS) {
    fuzz::modulePipelines(device, layout, words, 0, data, size, 2);
    vkrt_DestroyPipelineLayout(device, layout, nullptr);
  }
  if (own.device) fuzz::destroyFuzzDevice(own);
  return 0;
}
