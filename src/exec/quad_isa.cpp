#include "exec/quad_isa.hpp"

#if defined(__x86_64__)
#include <cpuid.h>
#endif

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
  // CPUID leaf 1, ECX bit 29 (clang 14's __builtin_cpu_supports does not know "f16c").
  unsigned a = 0, b = 0, c = 0, d = 0;
  return __get_cpuid(1, &a, &b, &c, &d) && (c & bit_F16C) != 0;
#else
  return false;
#endif
}

bool quadAvx2ByDefault() {
  const char* isa = std::getenv("VKRT_QUAD_ISA");
  return hostHasAvx2() && !(isa && std::strcmp(isa, "baseline") == 0);
}

}  // namespace vkrt::exec
