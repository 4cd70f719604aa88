// Private to src/spirv: the pipeline cache form of a compiled shader (cache_blob.cpp). cacheKey() (compiler.hpp) is
// defined there too.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "spirv/compiler.hpp"

namespace vkrt::spirv {

// The blob of `s` and its object file (CompiledShader::cacheBlob).
std::string serialize(const CompiledShader& s, std::string_view object);
// Fills `s` from a blob's fields; returns the object file, or nullopt when the blob is damaged.
std::optional<std::string_view> deserialize(std::string_view blob, CompiledShader& s, bool* hasGroupEntry);

}  // namespace vkrt::spirv
