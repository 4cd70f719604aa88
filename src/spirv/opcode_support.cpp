// The supported-opcode table (opcode_support.hpp): one line per opcode, its family and its SPMD form, grouped by
// family; the GLSL.std.450 instructions; the capabilities; and the support check that reads them.
#include "spirv/opcode_support.hpp"

#include <spirv/unified1/GLSL.std.450.h>

#include <cstdio>

#include "spirv/newer_tokens.hpp"

namespace vkrt::spirv {

OpSupport opSupport(spv::Op op) {
  using F = OpFamily;
  using S = SpmdForm;
  switch (op) {
    // ---- Module
    case spv::OpNop: return {F::Module, S::Own};
    case spv::OpUndef: return {F::Module, S::Own};
    case spv::OpSourceContinued: return {F::Module, S::None};
    case spv::OpSource: return {F::Module, S::None};
    case spv::OpSourceExtension: return {F::Module, S::None};
    case spv::OpName: return {F::Module, S::None};
    case spv::OpMemberName: return {F::Module, S::None};
    case spv::OpString: return {F::Module, S::None};
    case spv::OpLine: return {F::Module, S::Own};
    case spv::OpNoLine: return {F::Module, S::Own};
    case spv::OpModuleProcessed: return {F::Module, S::None};
    case spv::OpExtension: return {F::Module, S::None};
    case spv::OpExtInstImport: return {F::Module, S::None};
    case spv::OpMemoryModel: return {F::Module, S::None};
    case spv::OpEntryPoint: return {F::Module, S::None};
    case spv::OpExecutionMode: return {F::Module, S::None};
    case spv::OpExecutionModeId: return {F::Module, S::None};
    case spv::OpCapability: return {F::Module, S::None};
    case spv::OpDecorate: return {F::Module, S::None};
    case spv::OpMemberDecorate: return {F::Module, S::None};
    case spv::OpDecorationGroup: return {F::Module, S::None};
    case spv::OpGroupDecorate: return {F::Module, S::None};
    case spv::OpGroupMemberDecorate: return {F::Module, S::None};
    case spv::OpDecorateId: return {F::Module, S::None};
    case spv::OpDecorateString: return {F::Module, S::None};
    case spv::OpMemberDecorateString: return {F::Module, S::None};
    case spv::OpTypeVoid: return {F::Module, S::None};
    case spv::OpTypeBool: return {F::Module, S::None};
    case spv::OpTypeInt: return {F::Module, S::None};
    case spv::OpTypeFloat: return {F::Module, S::None};
    case spv::OpTypeVector: return {F::Module, S::None};
    case spv::OpTypeMatrix: return {F::Module, S::None};
    case spv::OpTypeArray: return {F::Module, S::None};
    case spv::OpTypeRuntimeArray: return {F::Module, S::None};
    case spv::OpTypeStruct: return {F::Module, S::None};
    case spv::OpTypePointer: return {F::Module, S::None};
    case spv::OpTypeFunction: return {F::Module, S::None};
    case spv::OpConstantTrue: return {F::Module, S::None};
    case spv::OpConstantFalse: return {F::Module, S::None};
    case spv::OpConstant: return {F::Module, S::None};
    case spv::OpConstantComposite: return {F::Module, S::None};
    case spv::OpConstantNull: return {F::Module, S::None};
    case spv::OpSpecConstantTrue: return {F::Module, S::None};
    case spv::OpSpecConstantFalse: return {F::Module, S::None};
    case spv::OpSpecConstant: return {F::Module, S::None};
    case spv::OpSpecConstantComposite: return {F::Module, S::None};
    case spv::OpSpecConstantOp: return {F::Module, S::None};
    case spv::OpFunction: return {F::Module, S::None};
    case spv::OpFunctionParameter: return {F::Module, S::None};
    case spv::OpFunctionEnd: return {F::Module, S::None};
    // ---- ControlFlow
    case spv::OpFunctionCall: return {F::ControlFlow, S::None};
    case spv::OpControlBarrier: return {F::ControlFlow, S::None};
    case spv::OpMemoryBarrier: return {F::ControlFlow, S::None};
    case spv::OpPhi: return {F::ControlFlow, S::Own};
    case spv::OpLoopMerge: return {F::ControlFlow, S::Own};
    case spv::OpSelectionMerge: return {F::ControlFlow, S::Own};
    case spv::OpLabel: return {F::ControlFlow, S::None};
    case spv::OpBranch: return {F::ControlFlow, S::Own};
    case spv::OpBranchConditional: return {F::ControlFlow, S::Own};
    case spv::OpSwitch: return {F::ControlFlow, S::Own};
    case spv::OpReturn: return {F::ControlFlow, S::Own};
    case spv::OpReturnValue: return {F::ControlFlow, S::None};
    case spv::OpUnreachable: return {F::ControlFlow, S::Own};
    // ---- Memory
    case spv::OpVariable: return {F::Memory, S::Checked};
    case spv::OpLoad: return {F::Memory, S::Own};
    case spv::OpStore: return {F::Memory, S::Own};
    case spv::OpCopyMemory: return {F::Memory, S::None};
    case spv::OpAccessChain: return {F::Memory, S::Own};
    case spv::OpInBoundsAccessChain: return {F::Memory, S::Own};
    case spv::OpArrayLength: return {F::Memory, S::Own};
    case spv::OpPtrEqual: return {F::Memory, S::None};
    case spv::OpPtrNotEqual: return {F::Memory, S::None};
    case spv::OpAtomicLoad: return {F::Memory, S::Checked};
    case spv::OpAtomicStore: return {F::Memory, S::Checked};
    case spv::OpAtomicExchange: return {F::Memory, S::Checked};
    case spv::OpAtomicCompareExchange: return {F::Memory, S::Checked};
    case spv::OpAtomicIIncrement: return {F::Memory, S::Checked};
    case spv::OpAtomicIDecrement: return {F::Memory, S::Checked};
    case spv::OpAtomicIAdd: return {F::Memory, S::Checked};
    case spv::OpAtomicISub: return {F::Memory, S::Checked};
    case spv::OpAtomicSMin: return {F::Memory, S::Checked};
    case spv::OpAtomicUMin: return {F::Memory, S::Checked};
    case spv::OpAtomicSMax: return {F::Memory, S::Checked};
    case spv::OpAtomicUMax: return {F::Memory, S::Checked};
    case spv::OpAtomicAnd: return {F::Memory, S::Checked};
    case spv::OpAtomicOr: return {F::Memory, S::Checked};
    case spv::OpAtomicXor: return {F::Memory, S::Checked};
    case spv::OpTypeForwardPointer: return {F::Memory, S::None};
    case spv::OpConvertUToPtr: return {F::Memory, S::None};
    case spv::OpConvertPtrToU: return {F::Memory, S::None};
    case spv::OpPtrAccessChain: return {F::Memory, S::None};
    // ---- Composite
    case spv::OpVectorExtractDynamic: return {F::Composite, S::Own};
    case spv::OpVectorInsertDynamic: return {F::Composite, S::Own};
    case spv::OpVectorShuffle: return {F::Composite, S::Own};
    case spv::OpCompositeConstruct: return {F::Composite, S::Own};
    case spv::OpCompositeExtract: return {F::Composite, S::Own};
    case spv::OpCompositeInsert: return {F::Composite, S::Own};
    // ---- Arithmetic
    case spv::OpCopyObject: return {F::Arithmetic, S::Elementwise};
    case spv::OpCopyLogical: return {F::Arithmetic, S::Elementwise};  // (a composite: uniform ones only)
    case spv::OpTranspose: return {F::Arithmetic, S::Elementwise};    // (a matrix: uniform ones only)
    case spv::OpConvertFToU: return {F::Arithmetic, S::Elementwise};
    case spv::OpConvertFToS: return {F::Arithmetic, S::Elementwise};
    case spv::OpConvertSToF: return {F::Arithmetic, S::Elementwise};
    case spv::OpConvertUToF: return {F::Arithmetic, S::Elementwise};
    case spv::OpUConvert: return {F::Arithmetic, S::Elementwise};
    case spv::OpSConvert: return {F::Arithmetic, S::Elementwise};
    case spv::OpFConvert: return {F::Arithmetic, S::Elementwise};
    case spv::OpQuantizeToF16: return {F::Arithmetic, S::None};
    case spv::OpSDot: return {F::Arithmetic, S::Own};
    case spv::OpUDot: return {F::Arithmetic, S::Own};
    case spv::OpSUDot: return {F::Arithmetic, S::Own};
    case spv::OpSDotAccSat: return {F::Arithmetic, S::Own};
    case spv::OpUDotAccSat: return {F::Arithmetic, S::Own};
    case spv::OpSUDotAccSat: return {F::Arithmetic, S::Own};
    case spv::OpBitcast: return {F::Arithmetic, S::Elementwise};
    case spv::OpSNegate: return {F::Arithmetic, S::Elementwise};
    case spv::OpFNegate: return {F::Arithmetic, S::Elementwise};
    case spv::OpIAdd: return {F::Arithmetic, S::Elementwise};
    case spv::OpFAdd: return {F::Arithmetic, S::Elementwise};
    case spv::OpISub: return {F::Arithmetic, S::Elementwise};
    case spv::OpFSub: return {F::Arithmetic, S::Elementwise};
    case spv::OpIMul: return {F::Arithmetic, S::Elementwise};
    case spv::OpFMul: return {F::Arithmetic, S::Elementwise};
    case spv::OpUDiv: return {F::Arithmetic, S::Elementwise};
    case spv::OpSDiv: return {F::Arithmetic, S::Elementwise};
    case spv::OpFDiv: return {F::Arithmetic, S::Elementwise};
    case spv::OpUMod: return {F::Arithmetic, S::Elementwise};
    case spv::OpSRem: return {F::Arithmetic, S::Elementwise};
    case spv::OpSMod: return {F::Arithmetic, S::Elementwise};
    case spv::OpFRem: return {F::Arithmetic, S::Elementwise};
    case spv::OpFMod: return {F::Arithmetic, S::Elementwise};
    case spv::OpVectorTimesScalar: return {F::Arithmetic, S::Own};
    case spv::OpMatrixTimesScalar: return {F::Arithmetic, S::Elementwise};  // (a matrix: uniform ones only)
    case spv::OpVectorTimesMatrix: return {F::Arithmetic, S::Own};
    case spv::OpMatrixTimesVector: return {F::Arithmetic, S::Own};
    case spv::OpMatrixTimesMatrix: return {F::Arithmetic, S::Elementwise};  // (a matrix: uniform ones only)
    case spv::OpOuterProduct: return {F::Arithmetic, S::Elementwise};       // (a matrix: uniform ones only)
    case spv::OpDot: return {F::Arithmetic, S::Own};
    case spv::OpIAddCarry: return {F::Arithmetic, S::None};
    case spv::OpISubBorrow: return {F::Arithmetic, S::None};
    case spv::OpUMulExtended: return {F::Arithmetic, S::None};
    case spv::OpSMulExtended: return {F::Arithmetic, S::None};
    case spv::OpAny: return {F::Arithmetic, S::Own};
    case spv::OpAll: return {F::Arithmetic, S::Own};
    case spv::OpIsNan: return {F::Arithmetic, S::Elementwise};
    case spv::OpIsInf: return {F::Arithmetic, S::Elementwise};
    case spv::OpLogicalEqual: return {F::Arithmetic, S::Elementwise};
    case spv::OpLogicalNotEqual: return {F::Arithmetic, S::Elementwise};
    case spv::OpLogicalOr: return {F::Arithmetic, S::Elementwise};
    case spv::OpLogicalAnd: return {F::Arithmetic, S::Elementwise};
    case spv::OpLogicalNot: return {F::Arithmetic, S::Elementwise};
    case spv::OpSelect: return {F::Arithmetic, S::Elementwise};
    case spv::OpIEqual: return {F::Arithmetic, S::Elementwise};
    case spv::OpINotEqual: return {F::Arithmetic, S::Elementwise};
    case spv::OpUGreaterThan: return {F::Arithmetic, S::Elementwise};
    case spv::OpSGreaterThan: return {F::Arithmetic, S::Elementwise};
    case spv::OpUGreaterThanEqual: return {F::Arithmetic, S::Elementwise};
    case spv::OpSGreaterThanEqual: return {F::Arithmetic, S::Elementwise};
    case spv::OpULessThan: return {F::Arithmetic, S::Elementwise};
    case spv::OpSLessThan: return {F::Arithmetic, S::Elementwise};
    case spv::OpULessThanEqual: return {F::Arithmetic, S::Elementwise};
    case spv::OpSLessThanEqual: return {F::Arithmetic, S::Elementwise};
    case spv::OpFOrdEqual: return {F::Arithmetic, S::Elementwise};
    case spv::OpFUnordEqual: return {F::Arithmetic, S::Elementwise};
    case spv::OpFOrdNotEqual: return {F::Arithmetic, S::Elementwise};
    case spv::OpFUnordNotEqual: return {F::Arithmetic, S::Elementwise};
    case spv::OpFOrdLessThan: return {F::Arithmetic, S::Elementwise};
    case spv::OpFUnordLessThan: return {F::Arithmetic, S::Elementwise};
    case spv::OpFOrdGreaterThan: return {F::Arithmetic, S::Elementwise};
    case spv::OpFUnordGreaterThan: return {F::Arithmetic, S::Elementwise};
    case spv::OpFOrdLessThanEqual: return {F::Arithmetic, S::Elementwise};
    case spv::OpFUnordLessThanEqual: return {F::Arithmetic, S::Elementwise};
    case spv::OpFOrdGreaterThanEqual: return {F::Arithmetic, S::Elementwise};
    case spv::OpFUnordGreaterThanEqual: return {F::Arithmetic, S::Elementwise};
    case spv::OpShiftRightLogical: return {F::Arithmetic, S::Elementwise};
    case spv::OpShiftRightArithmetic: return {F::Arithmetic, S::Elementwise};
    case spv::OpShiftLeftLogical: return {F::Arithmetic, S::Elementwise};
    case spv::OpBitwiseOr: return {F::Arithmetic, S::Elementwise};
    case spv::OpBitwiseXor: return {F::Arithmetic, S::Elementwise};
    case spv::OpBitwiseAnd: return {F::Arithmetic, S::Elementwise};
    case spv::OpNot: return {F::Arithmetic, S::Elementwise};
    case spv::OpBitFieldInsert: return {F::Arithmetic, S::None};
    case spv::OpBitFieldSExtract: return {F::Arithmetic, S::None};
    case spv::OpBitFieldUExtract: return {F::Arithmetic, S::None};
    case spv::OpBitReverse: return {F::Arithmetic, S::Elementwise};
    case spv::OpBitCount: return {F::Arithmetic, S::Elementwise};
    // ---- Subgroup
    case spv::OpGroupNonUniformElect: return {F::Subgroup, S::None};
    case spv::OpGroupNonUniformAll: return {F::Subgroup, S::None};
    case spv::OpGroupNonUniformAny: return {F::Subgroup, S::None};
    case spv::OpGroupNonUniformAllEqual: return {F::Subgroup, S::None};
    case spv::OpGroupNonUniformBroadcast: return {F::Subgroup, S::None};
    case spv::OpGroupNonUniformBroadcastFirst: return {F::Subgroup, S::None};
    case spv::OpGroupNonUniformBallot: return {F::Subgroup, S::None};
    case spv::OpGroupNonUniformInverseBallot: return {F::Subgroup, S::None};
    case spv::OpGroupNonUniformBallotBitExtract: return {F::Subgroup, S::None};
    case spv::OpGroupNonUniformBallotBitCount: return {F::Subgroup, S::None};
    case spv::OpGroupNonUniformBallotFindLSB: return {F::Subgroup, S::None};
    case spv::OpGroupNonUniformBallotFindMSB: return {F::Subgroup, S::None};
    // ---- ExtInst
    case spv::OpExtInst: return {F::ExtInst, S::Checked};
    // ---- Image
    case spv::OpTypeImage: return {F::Image, S::None};
    case spv::OpTypeSampler: return {F::Image, S::None};
    case spv::OpTypeSampledImage: return {F::Image, S::None};
    case spv::OpSampledImage: return {F::Image, S::Quad};
    case spv::OpImage: return {F::Image, S::Checked};
    case spv::OpImageRead: return {F::Image, S::Checked};
    case spv::OpImageWrite: return {F::Image, S::Checked};
    case spv::OpImageTexelPointer: return {F::Image, S::None};
    case spv::OpImageFetch: return {F::Image, S::Checked};
    case spv::OpImageSampleExplicitLod: return {F::Image, S::Quad};
    case spv::OpImageSampleDrefImplicitLod: return {F::Image, S::Quad};
    case spv::OpImageSampleDrefExplicitLod: return {F::Image, S::Quad};
    case spv::OpImageSampleProjImplicitLod: return {F::Image, S::None};
    case spv::OpImageSampleProjExplicitLod: return {F::Image, S::None};
    case spv::OpImageSampleProjDrefImplicitLod: return {F::Image, S::None};
    case spv::OpImageSampleProjDrefExplicitLod: return {F::Image, S::None};
    case spv::OpImageGather: return {F::Image, S::None};
    case spv::OpImageDrefGather: return {F::Image, S::None};
    case spv::OpImageQuerySize: return {F::Image, S::Checked};
    case spv::OpImageQuerySizeLod: return {F::Image, S::Checked};
    case spv::OpImageQueryLevels: return {F::Image, S::Checked};
    case spv::OpImageSampleImplicitLod: return {F::Image, S::Quad};
    // ---- RayTracing
    case spv::OpTypeAccelerationStructureKHR: return {F::RayTracing, S::None};
    case spv::OpConvertUToAccelerationStructureKHR: return {F::RayTracing, S::Checked};
    case spv::OpTraceRayKHR: return {F::RayTracing, S::Checked};
    case spv::OpExecuteCallableKHR: return {F::RayTracing, S::Checked};
    case spv::OpReportIntersectionKHR: return {F::RayTracing, S::None};
    case spv::OpIgnoreIntersectionKHR: return {F::RayTracing, S::None};
    case spv::OpTerminateRayKHR: return {F::RayTracing, S::None};
    case spv::OpTraceNV: return {F::RayTracing, S::None};
    case spv::OpExecuteCallableNV: return {F::RayTracing, S::None};
    case spv::OpIgnoreIntersectionNV: return {F::RayTracing, S::None};
    case spv::OpTerminateRayNV: return {F::RayTracing, S::None};
    // ---- RayQuery
    case spv::OpTypeRayQueryKHR: return {F::RayQuery, S::None};
    case spv::OpRayQueryInitializeKHR: return {F::RayQuery, S::None};
    case spv::OpRayQueryTerminateKHR: return {F::RayQuery, S::None};
    case spv::OpRayQueryGenerateIntersectionKHR: return {F::RayQuery, S::None};
    case spv::OpRayQueryConfirmIntersectionKHR: return {F::RayQuery, S::None};
    case spv::OpRayQueryProceedKHR: return {F::RayQuery, S::None};
    case spv::OpRayQueryGetIntersectionTypeKHR: return {F::RayQuery, S::None};
    case spv::OpRayQueryGetRayTMinKHR: return {F::RayQuery, S::None};
    case spv::OpRayQueryGetRayFlagsKHR: return {F::RayQuery, S::None};
    case spv::OpRayQueryGetIntersectionTKHR: return {F::RayQuery, S::None};
    case spv::OpRayQueryGetIntersectionInstanceCustomIndexKHR: return {F::RayQuery, S::None};
    case spv::OpRayQueryGetIntersectionInstanceIdKHR: return {F::RayQuery, S::None};
    case spv::OpRayQueryGetIntersectionInstanceShaderBindingTableRecordOffsetKHR: return {F::RayQuery, S::None};
    case spv::OpRayQueryGetIntersectionGeometryIndexKHR: return {F::RayQuery, S::None};
    case spv::OpRayQueryGetIntersectionPrimitiveIndexKHR: return {F::RayQuery, S::None};
    case spv::OpRayQueryGetIntersectionBarycentricsKHR: return {F::RayQuery, S::None};
    case spv::OpRayQueryGetIntersectionFrontFaceKHR: return {F::RayQuery, S::None};
    case spv::OpRayQueryGetIntersectionCandidateAABBOpaqueKHR: return {F::RayQuery, S::None};
    case spv::OpRayQueryGetIntersectionObjectRayDirectionKHR: return {F::RayQuery, S::None};
    case spv::OpRayQueryGetIntersectionObjectRayOriginKHR: return {F::RayQuery, S::None};
    case spv::OpRayQueryGetWorldRayDirectionKHR: return {F::RayQuery, S::None};
    case spv::OpRayQueryGetWorldRayOriginKHR: return {F::RayQuery, S::None};
    case spv::OpRayQueryGetIntersectionObjectToWorldKHR: return {F::RayQuery, S::None};
    case spv::OpRayQueryGetIntersectionWorldToObjectKHR: return {F::RayQuery, S::None};
    case spv::Op(kOpRayQueryGetIntersectionTriangleVertexPositionsKHR): return {F::RayQuery, S::None};
    // ---- Graphics
    case spv::OpKill: return {F::Graphics, S::Quad};
    case spv::OpTerminateInvocation: return {F::Graphics, S::Quad};
    case spv::OpDemoteToHelperInvocation: return {F::Graphics, S::Quad};
    case spv::OpIsHelperInvocationEXT: return {F::Graphics, S::Quad};
    case spv::OpDPdx: return {F::Graphics, S::Quad};
    case spv::OpDPdy: return {F::Graphics, S::Quad};
    case spv::OpFwidth: return {F::Graphics, S::Quad};
    case spv::OpDPdxFine: return {F::Graphics, S::Quad};
    case spv::OpDPdyFine: return {F::Graphics, S::Quad};
    case spv::OpFwidthFine: return {F::Graphics, S::Quad};
    case spv::OpDPdxCoarse: return {F::Graphics, S::Quad};
    case spv::OpDPdyCoarse: return {F::Graphics, S::Quad};
    case spv::OpFwidthCoarse: return {F::Graphics, S::Quad};
    case spv::OpGroupNonUniformQuadBroadcast: return {F::Graphics, S::Quad};
    case spv::OpGroupNonUniformQuadSwap: return {F::Graphics, S::Quad};
    default: return {};
  }
}

GlslSupport glslSupport(uint32_t inst) {
  switch (inst) {
    // IMix was never part of the published set. InterpolateAt* take the default: supported, scalar path only
    // (graphics.cpp, through GraphicsInvocation::interpolateAt).
    case GLSLstd450IMix: return {};
    case GLSLstd450Round: return {true, SpmdForm::Elementwise};
    case GLSLstd450RoundEven: return {true, SpmdForm::Elementwise};
    case GLSLstd450Trunc: return {true, SpmdForm::Elementwise};
    case GLSLstd450FAbs: return {true, SpmdForm::Elementwise};
    case GLSLstd450SAbs: return {true, SpmdForm::Elementwise};
    case GLSLstd450FSign: return {true, SpmdForm::Elementwise};
    case GLSLstd450SSign: return {true, SpmdForm::Elementwise};
    case GLSLstd450Floor: return {true, SpmdForm::Elementwise};
    case GLSLstd450Ceil: return {true, SpmdForm::Elementwise};
    case GLSLstd450Fract: return {true, SpmdForm::Elementwise};
    case GLSLstd450Radians: return {true, SpmdForm::Elementwise};
    case GLSLstd450Degrees: return {true, SpmdForm::Elementwise};
    case GLSLstd450Sin: return {true, SpmdForm::Elementwise};
    case GLSLstd450Cos: return {true, SpmdForm::Elementwise};
    case GLSLstd450Tan: return {true, SpmdForm::Elementwise};
    case GLSLstd450Asin: return {true, SpmdForm::Elementwise};
    case GLSLstd450Acos: return {true, SpmdForm::Elementwise};
    case GLSLstd450Atan: return {true, SpmdForm::Elementwise};
    case GLSLstd450Atan2: return {true, SpmdForm::Elementwise};
    case GLSLstd450Pow: return {true, SpmdForm::Elementwise};
    case GLSLstd450Exp: return {true, SpmdForm::Elementwise};
    case GLSLstd450Log: return {true, SpmdForm::Elementwise};
    case GLSLstd450Exp2: return {true, SpmdForm::Elementwise};
    case GLSLstd450Log2: return {true, SpmdForm::Elementwise};
    case GLSLstd450Sqrt: return {true, SpmdForm::Elementwise};
    case GLSLstd450InverseSqrt: return {true, SpmdForm::Elementwise};
    case GLSLstd450FMin: return {true, SpmdForm::Elementwise};
    case GLSLstd450NMin: return {true, SpmdForm::Elementwise};
    case GLSLstd450FMax: return {true, SpmdForm::Elementwise};
    case GLSLstd450NMax: return {true, SpmdForm::Elementwise};
    case GLSLstd450UMin: return {true, SpmdForm::Elementwise};
    case GLSLstd450SMin: return {true, SpmdForm::Elementwise};
    case GLSLstd450UMax: return {true, SpmdForm::Elementwise};
    case GLSLstd450SMax: return {true, SpmdForm::Elementwise};
    case GLSLstd450FClamp: return {true, SpmdForm::Elementwise};
    case GLSLstd450NClamp: return {true, SpmdForm::Elementwise};
    case GLSLstd450UClamp: return {true, SpmdForm::Elementwise};
    case GLSLstd450SClamp: return {true, SpmdForm::Elementwise};
    case GLSLstd450FMix: return {true, SpmdForm::Elementwise};
    case GLSLstd450Step: return {true, SpmdForm::Elementwise};
    case GLSLstd450SmoothStep: return {true, SpmdForm::Elementwise};
    case GLSLstd450Fma: return {true, SpmdForm::Elementwise};
    case GLSLstd450Length: return {true, SpmdForm::Own};
    case GLSLstd450Distance: return {true, SpmdForm::Own};
    case GLSLstd450Normalize: return {true, SpmdForm::Own};
    case GLSLstd450Cross: return {true, SpmdForm::Own};
    case GLSLstd450Reflect: return {true, SpmdForm::Own};
    case GLSLstd450FaceForward: return {true, SpmdForm::Own};
    default: return {inst >= GLSLstd450Round && inst < GLSLstd450Count, SpmdForm::None};
  }
}

bool supportedCapability(uint32_t cap) {
  switch (cap) {
    case spv::CapabilityShader:
    case spv::CapabilityMatrix:
    case spv::CapabilityInt64:
    case spv::CapabilityInt16:
    case spv::CapabilityInt8:
    case spv::CapabilityFloat64:
    case spv::CapabilityFloat16:
    case spv::CapabilityInt64Atomics:
    case spv::CapabilityDeviceGroup:            // DeviceIndex: always 0 (one physical device)
    case spv::CapabilityGroupNonUniform:        // subgroups of one invocation: elect, the built-ins, barriers
    case spv::CapabilityGroupNonUniformVote:    // arithmetic.cpp: a subgroup's vote is its invocation's
    case spv::CapabilityGroupNonUniformBallot:  // arithmetic.cpp: broadcasts read the only invocation
    // The Vulkan memory model: every atomic is sequentially consistent and every barrier a sequentially consistent
    // fence (memory.cpp, control_flow.cpp), stronger than any semantics asks; availability and visibility operations
    // on loads and stores (NonPrivatePointer, MakePointerAvailable/Visible) have nothing to do on coherent host memory.
    case spv::CapabilityVulkanMemoryModel:
    case spv::CapabilityVulkanMemoryModelDeviceScope:
    // Float controls the compiled code honours as it is (runtime/physical_device.cpp says why).
    case spv::CapabilityDenormPreserve:
    case spv::CapabilitySignedZeroInfNanPreserve:
    case spv::CapabilityRoundingModeRTE:
    // Integer dot products on vectors of any integer width and on packed 4 x 8-bit words (arithmetic.cpp).
    case spv::CapabilityDotProductInputAll:
    case spv::CapabilityDotProductInput4x8Bit:
    case spv::CapabilityDotProductInput4x8BitPacked:
    case spv::CapabilityDotProduct: return true;
    default: return extraSupportedCapability(cap) || rayTracingCapability(cap) || graphicsCapability(cap);
  }
}

bool checkSupport(const Module& m, std::string* error) {
  char buf[256];
  for (const Instruction& in : m.instructions) {
    if (!supportedOp(in.op)) {
      std::snprintf(buf, sizeof buf, "unsupported instruction %s at word %u", opName(in.op).c_str(), in.offset);
      *error = buf;
      return false;
    }
    if (in.op == spv::OpExtInst) {
      auto it = m.extInstImports.find(in.word(3));
      // Non-semantic instruction sets (debug info, reflection) are stripped before the translation.
      if (it != m.extInstImports.end() && it->second.rfind("NonSemantic.", 0) == 0) continue;
      bool glsl = it != m.extInstImports.end() && it->second == "GLSL.std.450";
      if (!glsl || !glslSupport(in.word(4)).supported) {
        std::snprintf(buf, sizeof buf, "unsupported instruction OpExtInst %s %u at word %u",
                      it != m.extInstImports.end() ? it->second.c_str() : "?", in.word(4), in.offset);
        *error = buf;
        return false;
      }
    }
  }
  // Capabilities last: an unsupported instruction is the more precise message.
  for (const Instruction& in : m.instructions) {
    if (in.op == spv::OpCapability && !supportedCapability(in.word(1))) {
      std::snprintf(buf, sizeof buf, "unsupported capability %u (OpCapability at word %u)", in.word(1), in.offset);
      *error = buf;
      return false;
    }
  }
  return true;
}

bool atomicOp(spv::Op op) {
  switch (op) {
    case spv::OpAtomicLoad:
    case spv::OpAtomicStore:
    case spv::OpAtomicExchange:
    case spv::OpAtomicCompareExchange:
    case spv::OpAtomicIIncrement:
    case spv::OpAtomicIDecrement:
    case spv::OpAtomicIAdd:
    case spv::OpAtomicISub:
    case spv::OpAtomicSMin:
    case spv::OpAtomicUMin:
    case spv::OpAtomicSMax:
    case spv::OpAtomicUMax:
    case spv::OpAtomicAnd:
    case spv::OpAtomicOr:
    case spv::OpAtomicXor: return true;
    default: return false;
  }
}

}  // namespace vkrt::spirv
