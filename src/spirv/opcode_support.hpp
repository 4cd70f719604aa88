// The one table of what the compiler translates: every SPIR-V opcode it supports, with the instruction family that
// translates it and whether the SPMD path (spmd.cpp) emits it too; the GLSL.std.450 instructions likewise; and the
// capabilities. jit.cpp's support check (checkSupport, on the application's module) and spmd.cpp's own check both
// read it, so that a new opcode is one line here plus its emitter. No LLVM here: unit tests include it.
#pragma once

#include <cstdint>
#include <string>

#include "spirv/module.hpp"

namespace vkrt::spirv {

// Where an instruction is translated (the Codegen family functions; compiler.cpp's emitFunction tries them in turn).
enum class OpFamily : uint8_t {
  Unsupported,
  Module,       // debug, annotation, mode setting, types, constants, function declarations: module.cpp, compiler.cpp
  ControlFlow,  // blocks, branches, phis, calls, barriers: control_flow.cpp
  Memory,       // variables, access chains, loads, stores, atomics, physical pointers: memory.cpp
  Composite,    // vector and composite construction and access: arithmetic.cpp (Codegen::composite)
  Arithmetic,   // numbers, bits, relations, conversions, matrices, dot products: arithmetic.cpp
  Subgroup,     // subgroups of one invocation: arithmetic.cpp
  ExtInst,      // OpExtInst (GLSL.std.450: glsl_std450.cpp; NonSemantic sets are stripped before the translation)
  Image,        // images, samplers, texel buffers: image.cpp
  RayTracing,   // ray tracing stages' instructions: ray_tracing.cpp
  RayQuery,     // ray queries, in every stage: ray_query.cpp
  Graphics,     // fragment termination, helpers, derivatives, quad operations: graphics.cpp
};

// What the SPMD path (spmd.cpp) makes of an instruction; anything but None is a subset of the supported opcodes.
enum class SpmdForm : uint8_t {
  None,         // left to the scalar vkrt_group
  Elementwise,  // component by component on scalars and vectors: the scalar emitters, N lanes wide
  Own,          // spmd.cpp's own emitter (control flow, memory, composites, reductions)
  Checked,      // spmd.cpp decides from the operands or the stage (OpVariable's storage class, OpExtInst's
                // instruction, traces and callables: ray generation shaders)
  Quad,         // fragment shaders only (a 2x2 quad per call): spmd.cpp's fragmentInstruction (demotion, helper
                // tests, derivatives, quad operations, sampling per lane), OpKill/OpTerminateInvocation as block ends
};

struct OpSupport {
  OpFamily family = OpFamily::Unsupported;
  SpmdForm spmd = SpmdForm::None;
};

OpSupport opSupport(spv::Op op);
inline bool supportedOp(spv::Op op) { return opSupport(op).family != OpFamily::Unsupported; }
// The ray tracing instructions, ray queries included (Codegen::rayTracing's dispatch).
inline bool rayTracingOp(spv::Op op) {
  OpFamily f = opSupport(op).family;
  return f == OpFamily::RayTracing || f == OpFamily::RayQuery;
}
inline bool rayQueryOp(spv::Op op) { return opSupport(op).family == OpFamily::RayQuery; }
// The atomic instructions on memory (load, store, exchange, compare-exchange, the arithmetic and bitwise ones:
// Codegen::atomic; the SPMD path's atomicLanes). Not the texel pointer that image atomics go through.
bool atomicOp(spv::Op op);
// The integer dot products that add an accumulator and saturate (their operand 5 the accumulator).
inline bool dotAccSatOp(spv::Op op) {
  return op == spv::OpSDotAccSat || op == spv::OpUDotAccSat || op == spv::OpSUDotAccSat;
}

// A GLSL.std.450 instruction: supported or not, and its SPMD form (Elementwise: component by component; Own: on
// whole vectors, computed by spmd.cpp from the components).
struct GlslSupport {
  bool supported = false;
  SpmdForm spmd = SpmdForm::None;
};
GlslSupport glslSupport(uint32_t instruction);

bool supportedCapability(uint32_t capability);
// The capabilities of the image instructions and the memory accesses beyond the core (image.cpp), of ray tracing and
// ray queries (ray_tracing.cpp), of the vertex and fragment stages (graphics.cpp); supportedCapability adds them.
bool extraSupportedCapability(uint32_t capability);
bool rayTracingCapability(uint32_t capability);
bool graphicsCapability(uint32_t capability);

// Every instruction and capability of `m` (the application's module, so that messages carry its offsets) is one
// the compiler translates; otherwise false with `error` naming the first that is not.
bool checkSupport(const Module& m, std::string* error);

}  // namespace vkrt::spirv
