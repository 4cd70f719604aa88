// libFuzzer target: the SPIR-V front end up to the compiler. An input is a SPIR-V module's bytes (the seeds,
// fuzz/corpus/spirv, are the test shaders compiled by glslc; mutations of their words reach deep).
//   1. spirv::Module::parse on the words as they are, validated or not (module.hpp: it never reads past the
//      end), then the reader's accessors on whatever it parsed;
//   2. spirv::applySpecialization on the words as they are, with values from the input;
//   3. vkCreateShaderModule (SPIRV-Tools' validator), and for an accepted module, per entry point, the pipeline
//      of its stage with VK_PIPELINE_CREATE_FAIL_ON_PIPELINE_COMPILE_REQUIRED_BIT: the stage rules, the entry
//      point lookup and the specialization, stopping before the JIT (spirv_pipeline_fuzz.cpp goes on).
// Errors are expected (reported, VKRT_LOG=none); a crash, a sanitizer report or a leak is a finding.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "spirv_stages.hpp"

namespace {

VkPipelineLayout emptyLayout() {
  static VkPipelineLayout layout = [] {
    VkPipelineLayoutCreateInfo ci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    VkPipelineLayout l = VK_NULL_HANDLE;
    vkrt_CreatePipelineLayout(vkrt::fuzz::fuzzDevice().device, &ci, nullptr, &l);
    return l;
  }();
  return layout;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  emptyLayout();
  return 0;
}

extern "C" size_t LLVMFuzzerMutate(uint8_t* data, size_t size, size_t maxSize);

extern "C" size_t LLVMFuzzerCustomMutator(uint8_t* data, size_t size, size_t maxSize, unsigned int seed) {
  return vkrt::fuzz::mutateSpirv(data, size, maxSize, seed, LLVMFuzzerMutate);
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace vkrt;
  std::vector<uint32_t> words = fuzz::wordsOf(data, size);
  std::string error;
  {
    spirv::Module m;
    if (m.parse(words.data(), words.size(), &error)) {
      for (const spirv::EntryPoint& ep : m.entryPoints) (void)m.findEntryPoint(ep.name.c_str(), ep.model);
      for (const auto& [id, index] : m.defs) {
        uint64_t v;
        (void)m.constantU64(id, &v);
        (void)m.specConstantOp(id);
        (void)m.typeOf(id);
        (void)m.decor(id);
        if (const spirv::Type* t = m.type(id); t && t->kind == spirv::Type::Struct)
          for (uint32_t i = 0; i < t->members.size(); ++i) (void)m.memberDecor(id, i);
      }
      for (const spirv::Instruction& in : m.instructions) {
        if (in.op == spv::OpName || in.op == spv::OpEntryPoint || in.op == spv::OpSource) (void)in.string(2);
        (void)spirv::opName(in.op);
      }
    }
  }
  {
    std::vector<spirv::SpecValue> values;
    for (uint32_t id = 0; id < 8; ++id) {
      size_t n = (id % 3 == 0) ? 8 : (id % 3 == 1) ? 4 : 2;
      std::vector<uint8_t> bytes(n);
      for (size_t b = 0; b < n; ++b) bytes[b] = size ? data[(id * 13 + b) % size] : 0;
      values.push_back({id, bytes});
    }
    std::vector<uint32_t> copy = words;
    (void)spirv::applySpecialization(copy, values, &error);
  }
  fuzz::modulePipelines(fuzz::fuzzDevice().device, emptyLayout(), words,
                        VK_PIPELINE_CREATE_FAIL_ON_PIPELINE_COMPILE_REQUIRED_BIT, data, size, 8);
  return 0;
}
