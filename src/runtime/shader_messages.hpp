// Delivering what a command's shaders printed (debugPrintfEXT) and the accesses they made out of bounds
// (exec::ShaderMessages), once the command's work is done: through the report funnel (VK_EXT_debug_utils), printf
// text also to stdout (VKRT_PRINTF). See docs/shader-debugging.md.
#pragma once

#include <functional>
#include <string>

#include "abi/abi.hpp"
#include "exec/shader_debug.hpp"
#include "runtime/object.hpp"
#include "spirv/compiler.hpp"

namespace vkrt {

class CommandBuffer;

// pMessageIdName and messageIdNumber of a printf message: the Khronos validation layer's (its debug printf), so
// that handlers written for the layer show vkrt's messages too.
inline constexpr char kPrintfMessageId[] = "UNASSIGNED-DEBUG-PRINTF";
inline constexpr int32_t kPrintfMessageNumber = int32_t(0x92394c89u);
// pMessageIdName of an out-of-bounds report.
inline constexpr char kOutOfBoundsMessageId[] = "VKRT-shader-out-of-bounds";

// Names the descriptor of an access for an out-of-bounds report ("VkBuffer 0x... 'name'"), or "" when unknown.
using DescriptorNamer = std::function<std::string(uint32_t set, uint32_t binding, uint64_t element)>;

// A namer over the resource slots a compiled shader was given (in its resources' order).
DescriptorNamer descriptorNamer(const spirv::CompiledShader& shader, const abi::ResourceSlot* slots);

// Delivers `messages` (of command `fn` recorded in `cb`, running `pipeline`).
void deliverShaderMessages(const CommandBuffer* cb, const Object* pipeline, const char* fn,
                           const exec::ShaderMessages& messages, const DescriptorNamer& namer = {});

}  // namespace vkrt
