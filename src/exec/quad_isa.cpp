#include "exec/quad_isa.hpp"

#include <cstdlib>
#include <cstring>

namespace vkrt::exec {

bool hostHasAvx2() {
#if defined(__x86_64__)
  return __builtin_cpu_supports("avx2");
#else
  return false;
#endif
}

bool hostHasF16c() {
#if defined(__x86_64__)
  return __builtin_cpu_supports("f16c");
#else
  return false;
#endif
}

bool quadAvx2ByDefault() {
  const char* isa = std::getenv("VKRT_QUAD_ISA");
  return hostHasAvx2() && !(isa && std::strcmp(isa, "baseline") == 0);
}

}  // namespace vkrt::exec
