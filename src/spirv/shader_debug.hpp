// Shader debugging, the compiler's side (no LLVM in this header: the runtime includes it): the site records of
// abi/shader_debug.hpp, built by the code generator and read back by the runtime, and debugPrintfEXT's formatting.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "abi/shader_debug.hpp"

namespace vkrt::spirv {

// The OpString that pre_optimizer.cpp's prepareNonSemantic names in the OpLine instructions it adds to modules without
// line information: their line is the application's word offset of the instruction that follows.
inline constexpr char kWordOffsetFile[] = "vkrt:word-offset";

// The checks compiled into later shaders beyond the always-on buffer and descriptor ones (abi::ShaderCheck bits;
// VKRT_SHADER_CHECKS, read when a device is created): process-wide, part of cacheKey(). 0 (the default): none, and
// nothing of them in the compiled code.
void setShaderChecks(uint32_t checks);
uint32_t shaderChecks();
// VKRT_SHADER_CHECKS's value: "bda", "image", "all" or a comma-separated list ("bda,image"); false for anything else.
bool parseShaderChecks(const char* text, uint32_t* checks);

// One argument of a debugPrintfEXT call: its kind (abi::PrintfArgKind), bit width and component count.
struct PrintfArg {
  uint32_t kind = abi::kArgUnsigned;
  uint32_t width = 32;
  uint32_t components = 1;
};

// A PrintfSite record (abi/shader_debug.hpp).
std::string printfSite(uint32_t model, const std::vector<PrintfArg>& args, const std::string& format,
                       const std::string& entryName);

// An AccessSite record.
struct AccessSiteInfo {
  uint32_t model = 0;
  uint32_t kind = abi::kAccessLoad;
  uint32_t set = ~0u, binding = ~0u;
  uint32_t bytes = 0;
  uint32_t wordOffset = 0;
  uint32_t line = 0, column = 0;
  std::string file, entryName, variable;
};
std::string accessSite(const AccessSiteInfo& info);
AccessSiteInfo readAccessSite(const uint8_t* site);

// The text of one debugPrintfEXT message, as the Khronos validation layer's debug printf formats it: the format
// string with each conversion replaced by its argument. Conversions: %d %i %u %x %X %o %c %f %F %e %E %g %G %a %A
// with C's flags, width and precision; %% is a percent sign; `l` before the conversion (%lu, %ld, %lx) prints the
// whole 64-bit integer; `v` and a component count (%v3f, %v2d, %v4lu) print a vector's components separated by
// ", ". A conversion without an argument left, or one the list does not know, is printed as it is written.
std::string formatPrintf(const uint8_t* site, const uint64_t* args);

}  // namespace vkrt::spirv
