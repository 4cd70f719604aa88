// Private to src/spirv: the machine compiled code targets (VKRT_JIT_CPU: the host CPU, or a named baseline), and
// LLVM's error text, which both the target's detection and the JIT report.
#pragma once

#include <llvm/ExecutionEngine/Orc/JITTargetMachineBuilder.h>

#include <optional>
#include <string>

namespace vkrt::spirv::detail {

// The target description of the CPU chosen with setTargetCpu() (detected once per choice: CPUID is slow under
// virtualization), or nullopt with `error` set.
std::optional<llvm::orc::JITTargetMachineBuilder> targetMachine(std::string* error);

// LLVM's message for `e` (consumes it).
std::string errText(llvm::Error e);

// What the pipeline cache key holds of the target: the host CPU's name and features, or the baseline's name.
std::string targetKey();

}  // namespace vkrt::spirv::detail
