// The supported-opcode table (src/spirv/opcode_support.hpp), the one list the scalar JIT's support check and the
// SPMD path both read: what the SPMD path accepts is a subset of what the compiler supports, the instructions whose
// SPMD form spmd.cpp decides from the operands are the two it has checks for, and the ray tracing dispatch's
// predicates agree with the families.
#include <gtest/gtest.h>

#include <spirv/unified1/GLSL.std.450.h>

#include <set>

#include "spirv/opcode_support.hpp"

namespace vkrt::spirv {
namespace {

constexpr uint32_t kOpcodeLimit = 0x10000;  // opcodes are 16 bits (SPIR-V 2.3, the first word of an instruction)

TEST(OpcodeSupport, EveryOpcodeTheSpmdPathAcceptsIsSupported) {
  uint32_t spmd = 0;
  for (uint32_t op = 0; op < kOpcodeLimit; ++op) {
    OpSupport s = opSupport(spv::Op(op));
    if (s.spmd == SpmdForm::None) continue;
    ++spmd;
    EXPECT_TRUE(supportedOp(spv::Op(op))) << opName(spv::Op(op)) << " has an SPMD form but is not supported";
  }
  EXPECT_GT(spmd, 0u);  // the SPMD path reads this table: it accepts something
}

TEST(OpcodeSupport, EveryGlslInstructionTheSpmdPathAcceptsIsSupported) {
  uint32_t spmd = 0;
  for (uint32_t inst = 0; inst < kOpcodeLimit; ++inst) {
    GlslSupport s = glslSupport(inst);
    if (s.spmd == SpmdForm::None) continue;
    ++spmd;
    EXPECT_TRUE(s.supported) << "GLSL.std.450 instruction " << inst << " has an SPMD form but is not supported";
    // spmd.cpp emits instructions component by component, or the whole-vector ones from their components.
    EXPECT_TRUE(s.spmd == SpmdForm::Elementwise || s.spmd == SpmdForm::Own) << inst;
  }
  EXPECT_GT(spmd, 0u);
  // Past the published set, and the instructions the compiler does not translate.
  EXPECT_FALSE(glslSupport(GLSLstd450Count).supported);
  EXPECT_FALSE(glslSupport(GLSLstd450IMix).supported);
  EXPECT_TRUE(glslSupport(GLSLstd450FMix).supported);
}

// Spmd::supported decides OpVariable (its storage class), OpExtInst (its set and instruction), OpImageRead,
// OpImageWrite, OpImageFetch and OpImage (the image type, the stage and the shader checks), the image queries, the
// atomics, traces, callables and acceleration structure addresses (the stage) itself; any other instruction marked
// Checked would be refused there without a reason.
TEST(OpcodeSupport, OnlyTheInstructionsSpmdPathDecidesAreChecked) {
  std::set<uint32_t> checked;
  for (uint32_t op = 0; op < kOpcodeLimit; ++op)
    if (opSupport(spv::Op(op)).spmd == SpmdForm::Checked) checked.insert(op);
  EXPECT_EQ(checked, (std::set<uint32_t>{spv::OpVariable,
                                         spv::OpExtInst,
                                         spv::OpImageRead,
                                         spv::OpImageWrite,
                                         spv::OpImageFetch,
                                         spv::OpImage,
                                         spv::OpImageQuerySize,
                                         spv::OpImageQuerySizeLod,
                                         spv::OpImageQueryLevels,
                                         spv::OpAtomicLoad,
                                         spv::OpAtomicStore,
                                         spv::OpAtomicExchange,
                                         spv::OpAtomicCompareExchange,
                                         spv::OpAtomicIIncrement,
                                         spv::OpAtomicIDecrement,
                                         spv::OpAtomicIAdd,
                                         spv::OpAtomicISub,
                                         spv::OpAtomicSMin,
                                         spv::OpAtomicUMin,
                                         spv::OpAtomicSMax,
                                         spv::OpAtomicUMax,
                                         spv::OpAtomicAnd,
                                         spv::OpAtomicOr,
                                         spv::OpAtomicXor,
                                         spv::OpTraceRayKHR,
                                         spv::OpExecuteCallableKHR,
                                         spv::OpConvertUToAccelerationStructureKHR}));
}

TEST(OpcodeSupport, FamiliesAndDispatchPredicatesAgree) {
  for (uint32_t op = 0; op < kOpcodeLimit; ++op) {
    auto o = spv::Op(op);
    OpSupport s = opSupport(o);
    if (s.family == OpFamily::Unsupported) {
      EXPECT_EQ(s.spmd, SpmdForm::None) << opName(o);
    }
    if (rayQueryOp(o)) {
      EXPECT_TRUE(rayTracingOp(o)) << opName(o);
    }
    EXPECT_EQ(rayTracingOp(o), s.family == OpFamily::RayTracing || s.family == OpFamily::RayQuery) << opName(o);
  }
  // A few of each family, and instructions the compiler refuses.
  EXPECT_EQ(opSupport(spv::OpIAdd).family, OpFamily::Arithmetic);
  EXPECT_EQ(opSupport(spv::OpIAdd).spmd, SpmdForm::Elementwise);
  EXPECT_EQ(opSupport(spv::OpLoad).family, OpFamily::Memory);
  EXPECT_EQ(opSupport(spv::OpLoad).spmd, SpmdForm::Own);
  EXPECT_EQ(opSupport(spv::OpAtomicIAdd).spmd, SpmdForm::Checked);
  EXPECT_EQ(opSupport(spv::OpControlBarrier).spmd, SpmdForm::None);
  EXPECT_EQ(opSupport(spv::OpControlBarrier).family, OpFamily::ControlFlow);
  EXPECT_EQ(opSupport(spv::OpImageFetch).family, OpFamily::Image);
  EXPECT_EQ(opSupport(spv::OpTraceRayKHR).family, OpFamily::RayTracing);
  EXPECT_EQ(opSupport(spv::OpRayQueryProceedKHR).family, OpFamily::RayQuery);
  EXPECT_EQ(opSupport(spv::OpDPdx).family, OpFamily::Graphics);
  EXPECT_FALSE(supportedOp(spv::OpGroupNonUniformShuffle));
  EXPECT_FALSE(supportedOp(spv::OpTypeEvent));
}

}  // namespace
}  // namespace vkrt::spirv
