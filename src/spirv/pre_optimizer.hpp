// Private to src/spirv: what compile() does to the application's SPIR-V words before SPIRV-Tools' optimizer
// (pre_optimizer.cpp): checks the optimizer's folding needs and rewrites that keep only what the translation uses.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "spirv/module.hpp"

namespace vkrt::spirv {

// Every OpSpecConstantOp of `m` obeys the rules of the instruction it names; otherwise false with `error` set.
bool checkSpecConstantOps(const Module& m, std::string* error);
// OpSpecConstantOp VectorShuffle components 0xFFFFFFFF (undefined) become 0.
void defineUndefinedShuffleComponents(std::vector<uint32_t>& words);
// OpSpecConstantOp QuantizeToF16 of a 32-bit float scalar whose value is known (an OpConstant, an OpSpecConstant,
// whose default is the specialized value by then, or a QuantizeToF16 folded before) becomes that OpConstant.
void foldQuantizeToF16SpecConstants(std::vector<uint32_t>& words);
// Removes every entry point but the one compiled.
void keepOnlyEntryPoint(std::vector<uint32_t>& words, spv::ExecutionModel model, const std::string& name);
// Drops non-semantic instructions but DebugPrintf, turning NonSemantic.Shader.DebugInfo.100's DebugLine/DebugNoLine
// into OpLine/OpNoLine, and gives each memory access without a source line an OpLine naming its word offset; returns
// whether a DebugPrintf remains.
bool prepareNonSemantic(std::vector<uint32_t>& words);

}  // namespace vkrt::spirv
