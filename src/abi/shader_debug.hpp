// Shader debugging: the functions compiled code calls for debugPrintfEXT (NonSemantic.DebugPrintf) and when an
// access falls outside its buffer or descriptor array, and the site records they name. The compiler knows no
// Vulkan object: each call site is a constant record in the compiled module (its object code, so pipeline caches
// keep it), laid out below; the executor collects what the calls pass (exec/shader_debug.hpp) and the runtime
// formats and delivers it after the command (runtime/shader_messages.cpp).
//
// A site record is a byte string, 4-byte aligned, of 32-bit words then nul-terminated strings:
//
//   PrintfSite   word 0      kPrintfSiteTag
//                word 1      the execution model (spv::ExecutionModel) of the shader
//                word 2      n, the number of arguments
//                word 3..    one word per argument: kind (PrintfArgKind) | bit width << 8 | components << 16
//                then        the format string (OpString), the entry point's name
//   AccessSite   word 0      kAccessSiteTag
//                word 1      the execution model
//                word 2      AccessKind
//                word 3, 4   descriptor set and binding (~0u: not a descriptor: a buffer device address)
//                            (images and texel buffers: the image variable's)
//                word 5      the access's bytes
//                word 6      the instruction's word offset in the application's module
//                word 7, 8   the source line and column (OpLine; 0: none)
//                then        the source file (OpString of OpLine; empty: none), the entry point's name, the
//                            variable's name (OpName; empty: none)
//
// Arguments travel as one 64-bit word per component, in order: integers sign- or zero-extended by their type's
// signedness, booleans 0 or 1, floats converted to double (its bits).
#pragma once

#include <cstdint>
#include <cstring>

#include "abi/abi.hpp"

namespace vkrt::abi {

inline constexpr uint32_t kPrintfSiteTag = 0x46525056;  // "VPRF"
inline constexpr uint32_t kAccessSiteTag = 0x424f4f56;  // "VOOB"

enum PrintfArgKind : uint32_t { kArgUnsigned = 0, kArgSigned = 1, kArgFloat = 2, kArgBool = 3 };
enum AccessKind : uint32_t {
  kAccessLoad = 0,
  kAccessStore = 1,
  kAccessAtomic = 2,
  kAccessDescriptorIndex = 3,
  // The checks of VKRT_SHADER_CHECKS=image (vkrt_check_image, vkrt_check_texel_buffer): OpImageRead, OpImageWrite,
  // OpImageFetch and OpImageTexelPointer (an atomic) on an image, then the same on a texel buffer.
  kAccessImageRead = 4,
  kAccessImageWrite = 5,
  kAccessImageFetch = 6,
  kAccessImageAtomic = 7,
  kAccessTexelRead = 8,
  kAccessTexelWrite = 9,
  kAccessTexelFetch = 10,
  kAccessTexelAtomic = 11,
};

// The checks VKRT_SHADER_CHECKS compiles in (spirv::setShaderChecks), beyond the buffer and descriptor ones that are
// always there.
enum ShaderCheck : uint32_t {
  kCheckDeviceAddress = 1,  // PhysicalStorageBuffer accesses against the live buffers' device addresses
  kCheckImage = 2,          // image and texel buffer coordinates against the view's range
};

inline uint32_t siteWord(const uint8_t* site, uint32_t i) {
  uint32_t w;
  std::memcpy(&w, site + 4 * i, 4);
  return w;
}

// The strings after a site's words: `index` 0 is the first.
inline const char* siteString(const uint8_t* site, uint32_t words, uint32_t index) {
  const char* s = reinterpret_cast<const char*>(site + 4 * words);
  for (uint32_t i = 0; i < index; ++i) s += std::strlen(s) + 1;
  return s;
}

inline uint32_t printfSiteWords(const uint8_t* site) { return 3 + siteWord(site, 2); }

// Where device addresses are checked, vkrt_group's local context is followed by this many bytes per checked access
// in the shader: the range vkrt_check_address returned last for that access, kept across the workgroup's invocations.
inline constexpr uint32_t kAddressCacheBytes = 16;
inline constexpr uint32_t kAccessSiteWords = 9;

}  // namespace vkrt::abi

extern "C" {
// debugPrintfEXT: `site` is the call's PrintfSite, `args` its arguments' components (see above). Never fails: the
// executor keeps what it can (a bound per command) and counts the rest.
void vkrt_debug_printf(vkrt::abi::InvocationContext* ctx, const uint8_t* site, const uint64_t* args);
// An access outside its range (the access itself reads zeros / is dropped as robustness says): `site` is its
// AccessSite; `offset` the byte offset accessed (the index, for kAccessDescriptorIndex), `range` the bytes in range
// (the binding's descriptor count for kAccessDescriptorIndex), `element` the descriptor array element.
void vkrt_out_of_bounds(vkrt::abi::InvocationContext* ctx, const uint8_t* site, uint64_t offset, uint64_t range,
                        uint64_t element);
// kCheckDeviceAddress: the running command's table of live device address ranges (exec::AddressTable; null outside a
// command). The same for every call of a command: compiled code calls it once per function (hoisted out of loops).
const void* vkrt_address_table(vkrt::abi::InvocationContext* ctx);
// kCheckDeviceAddress: whether the `bytes` at device address `address` lie in one buffer of `table`; nonzero: the
// access happens, and `cache` (2 words) is set to that buffer's [begin, end), which compiled code tests first before
// it calls again. Zero: the access is reported at `site` (a load, store or atomic with set ~0u) and the caller reads
// zeros / drops it. A null table accepts every access (and sets no range).
uint32_t vkrt_check_address(vkrt::abi::InvocationContext* ctx, const void* table, const uint8_t* site, uint64_t address,
                            uint64_t bytes, uint64_t* cache);
// kCheckImage: reports an image access at `coord` (the instruction's integer coordinates, view order), level `lod`
// (OpImageFetch; 0 otherwise) of element `element` of the descriptor `img` when it lies outside the view. Only
// reports: the image functions themselves read zeros and write nothing there (runtime/image_functions.cpp).
void vkrt_check_image(vkrt::abi::InvocationContext* ctx, const uint8_t* site, const vkrt::abi::DescriptorRecord* img,
                      const int32_t coord[4], int32_t lod, uint64_t element);
// kCheckImage on a texel buffer: texel `index` of the view `buf`.
void vkrt_check_texel_buffer(vkrt::abi::InvocationContext* ctx, const uint8_t* site,
                             const vkrt::abi::DescriptorRecord* buf, int64_t index, uint64_t element);
}
