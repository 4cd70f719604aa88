// Private to src/spirv: SPMD compilation of compute shaders (spmd.cpp). vkrt_group runs a workgroup in batches of
// spmdLanes() invocations, one batch per pass of its code, each SPIR-V value a scalar (uniform) or an LLVM vector of
// one element per lane (varying), with an execution mask for control flow that diverges.
#pragma once

#include <llvm/IR/Function.h>

#include <string>

#include "spirv/compiler.hpp"

namespace vkrt::spirv {

class Codegen;
struct EntryPoint;

// What the pipeline cache key holds of the SPMD setting.
std::string spmdKey();

// Emits vkrt_group in SPMD form for the entry point `ep` of `g` (vkrt_main, `main`, made internal then), when every
// instruction of the entry function is one the SPMD path supports; otherwise returns false and leaves the module as
// it was (the caller emits the scalar vkrt_group, or keeps vkrt_main for a shader with barriers). Sets
// g.info.spmdLanes. With workgroup barriers (g.info.usesBarrier) vkrt_group runs one batch of the workgroup, the
// lanes from the context's localIndex on, and calls the context's barrier at each (exec::ComputeKernel::batchLanes).
bool emitSpmdGroup(Codegen& g, const EntryPoint& ep, llvm::Function* main);

// Emits vkrt_group(GraphicsInvocation quad[4]) for a fragment entry point: the quad's four lanes in one pass
// (derivatives as differences between the lanes, helper lanes masked out of buffer stores; the user inputs and
// outputs as structures of arrays through invocation 0's slot pointers: abi.hpp), where the SPMD path
// supports every instruction; otherwise returns false, the module as it was (the executor runs vkrt_main on four
// fibers). Sets g.info.spmdLanes to 4.
bool emitSpmdQuad(Codegen& g, const EntryPoint& ep, llvm::Function* main);

// Emits vkrt_group(RayInvocation*, uint32_t lanes) for a ray generation entry point (abi::RayBatchEntry): a batch of
// launch ids along x in one pass, their traces and callables lane by lane, where the SPMD path supports every
// instruction; otherwise returns false, the module as it was. vkrt_main stays (the executor runs it where it records
// ray trees). Sets g.info.spmdLanes.
bool emitSpmdRaygen(Codegen& g, const EntryPoint& ep, llvm::Function* main);

}  // namespace vkrt::spirv
