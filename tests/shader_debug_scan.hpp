// What the shader debugging tests find in a SPIR-V module on their own, to compare vkrt's reports with
// (tests/spirv/shader_debug_test.cpp, tests/e2e/shader_debug_test.cpp).
#pragma once

#include <spirv/unified1/spirv.hpp>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace vkrt::test {

// The word offset of the OpLoad that reads through the variable of binding `binding`, in a module whose only such
// load is that one (the load whose pointer is an access chain of the variable); 0 when there is none.
inline uint32_t loadOffsetOfBinding(const uint32_t* words, size_t count, uint32_t binding) {
  std::vector<uint32_t> vars, chains;
  for (size_t at = 5; at < count && (words[at] >> 16); at += words[at] >> 16)
    if ((words[at] & 0xffff) == spv::OpDecorate && words[at + 2] == spv::DecorationBinding && words[at + 3] == binding)
      vars.push_back(words[at + 1]);
  auto in = [](const std::vector<uint32_t>& v, uint32_t id) { return std::find(v.begin(), v.end(), id) != v.end(); };
  for (size_t at = 5; at < count && (words[at] >> 16); at += words[at] >> 16) {
    uint32_t op = words[at] & 0xffff;
    if (op == spv::OpAccessChain && in(vars, words[at + 3])) chains.push_back(words[at + 2]);
    if (op == spv::OpLoad && in(chains, words[at + 3])) return uint32_t(at);
  }
  return 0;
}

}  // namespace vkrt::test
