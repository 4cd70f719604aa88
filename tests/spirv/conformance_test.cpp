// SPIR-V shapes the Khronos CTS's compute and SPIR-V assembly groups use, one small module per class of failure
// the CTS found (tests/spirv/README in spirit: CI keeps them fixed without the CTS). Each module is assembled and
// validated with SPIRV-Tools here, compiled below the API and run; expectations are computed in the test.
#include <gtest/gtest.h>
#include <spirv-tools/libspirv.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "spirv/compute_harness.hpp"

namespace vkrt::testing {
namespace {

std::vector<uint32_t> assemble(const std::string& text) {
  spvtools::SpirvTools tools(SPV_ENV_VULKAN_1_3);
  std::string diag;
  tools.SetMessageConsumer([&](spv_message_level_t, const char*, const spv_position_t& pos, const char* m) {
    diag += std::to_string(pos.index) + ": " + m + "\n";
  });
  std::vector<uint32_t> words;
  EXPECT_TRUE(tools.Assemble(text, &words)) << diag;
  EXPECT_TRUE(tools.Validate(words)) << diag;
  return words;
}

bool compileText(ComputeHarness& h, const std::string& text, std::vector<spirv::SpecValue> spec = {}) {
  std::vector<uint32_t> words = assemble(text);
  spirv::CompileRequest r;
  r.words = words.data();
  r.wordCount = words.size();
  r.specialization = std::move(spec);
  r.hostSymbols = imageFunctionSymbols();
  h.shader = spirv::compile(r, &h.error);
  return h.shader != nullptr;
}

spirv::SpecValue specU32(uint32_t id, uint32_t v) {
  spirv::SpecValue s{id, std::vector<uint8_t>(4)};
  std::memcpy(s.bytes.data(), &v, 4);
  return s;
}

// A compute module around `body`: a storage buffer `data` (a runtime array of `elem`, decorated set 0 binding 0
// unless `decorations` names it), the global id's x as %g and %slot, the pointer to data[%g]. `types` come before
// the common variables, `globals` after them, `locals` at the top of the function.
std::string module(const std::string& caps, const std::string& decorations, const std::string& elem,
                   const std::string& stride, const std::string& globals, const std::string& body,
                   const std::string& types = "", const std::string& locals = "") {
  return "OpCapability Shader\n" + caps +
         "\nOpMemoryModel Logical GLSL450\n"
         "OpEntryPoint GLCompute %main \"main\" %gid %data\n"
         "OpExecutionMode %main LocalSize 1 1 1\n"
         "OpDecorate %gid BuiltIn GlobalInvocationId\n"
         "OpDecorate %rta ArrayStride " +
         stride +
         "\nOpMemberDecorate %buf 0 Offset 0\n"
         "OpDecorate %buf Block\n" +
         (decorations.find("%data") == std::string::npos
              ? "OpDecorate %data DescriptorSet 0\nOpDecorate %data Binding 0\n"
              : "") +
         decorations +
         "\n%void = OpTypeVoid\n"
         "%fnvoid = OpTypeFunction %void\n"
         "%uint = OpTypeInt 32 0\n"
         "%int = OpTypeInt 32 1\n"
         "%bool = OpTypeBool\n"
         "%float = OpTypeFloat 32\n"
         "%v3uint = OpTypeVector %uint 3\n"
         "%ptr_in_v3 = OpTypePointer Input %v3uint\n" +
         types +
         "\n%gid = OpVariable %ptr_in_v3 Input\n"
         "%uint_0 = OpConstant %uint 0\n"
         "%uint_1 = OpConstant %uint 1\n"
         "%rta = OpTypeRuntimeArray " +
         elem +
         "\n%buf = OpTypeStruct %rta\n"
         "%ptr_sb_buf = OpTypePointer StorageBuffer %buf\n"
         "%data = OpVariable %ptr_sb_buf StorageBuffer\n"
         "%ptr_sb_elem = OpTypePointer StorageBuffer " +
         elem + "\n" + globals +
         "\n%main = OpFunction %void None %fnvoid\n"
         "%entry = OpLabel\n" +
         locals +
         "\n%g3 = OpLoad %v3uint %gid\n"
         "%g = OpCompositeExtract %uint %g3 0\n"
         "%slot = OpAccessChain %ptr_sb_elem %data %uint_0 %g\n" +
         body +
         "\nOpReturn\n"
         "OpFunctionEnd\n";
}

// The CTS's float16 cases size arrays with a module-scope OpSpecConstantOp division; such a module was refused as
// if it had no entry point (the array length was read before folding).
TEST(SpirvConformance, SpecConstantOpDivisionSizesAnArray) {
  std::string text = module("", "OpDecorate %n SpecId 7", "%uint", "4",
                            "%n = OpSpecConstant %uint 12\n"
                            "%uint_3 = OpConstant %uint 3\n"
                            "%int_m7 = OpConstant %int -7\n"
                            "%len = OpSpecConstantOp %uint UDiv %n %uint_3\n"
                            "%sn = OpSpecConstantOp %int SDiv %int_m7 %len\n"
                            "%arr = OpTypeArray %uint %len\n"
                            "%ptr_fn_arr = OpTypePointer Function %arr\n"
                            "%ptr_fn_uint = OpTypePointer Function %uint\n",
                            "%last = OpISub %uint %len %uint_1\n"
                            "%p = OpAccessChain %ptr_fn_uint %a %last\n"
                            "OpStore %p %g\n"
                            "%v = OpLoad %uint %p\n"
                            "%len1000 = OpIMul %uint %len %n\n"
                            "%snu = OpBitcast %uint %sn\n"
                            "%s1 = OpIAdd %uint %v %len1000\n"
                            "%s2 = OpIAdd %uint %s1 %snu\n"
                            "OpStore %slot %s2",
                            "", "%a = OpVariable %ptr_fn_arr Function");
  for (uint32_t n : {12u, 30u}) {
    ComputeHarness h;
    ASSERT_TRUE(compileText(h, text, n == 12 ? std::vector<spirv::SpecValue>{} : std::vector{specU32(7, n)}))
        << h.error;
    h.zeroBuffer<uint32_t>(0, 4);
    ASSERT_TRUE(h.run(4));
    auto r = h.get<uint32_t>(0);
    int32_t quotient = -7 / int32_t(n / 3);  // SDiv rounds toward zero, as C++ does
    for (uint32_t g = 0; g < 4; ++g)
      EXPECT_EQ(r[g], g + (n / 3) * n + uint32_t(quotient)) << "n " << n << ", invocation " << g;
  }
}

// OpSpecConstantOp's composite operations: a valid extract, insert and shuffle of a composite that depends on a
// specialization constant compute their values; broken ones, which Debian's SPIRV-Tools validator lets through and
// its folding crashed on (the first found by vkrt_fuzz_spirv_pipeline: fuzz/corpus/spirv/regress-*), are refused
// at compilation with the rule they break.
TEST(SpirvConformance, SpecConstantOpCompositesFoldAndBrokenOnesAreRefused) {
  const std::string types = "%v2uint = OpTypeVector %uint 2";
  const std::string globals =
      "%s = OpSpecConstant %uint 3\n"
      "%uint_7 = OpConstant %uint 7\n"
      "%uint_10 = OpConstant %uint 10\n"
      "%uint_100 = OpConstant %uint 100\n"
      "%uint_1000 = OpConstant %uint 1000\n"
      "%v3c = OpSpecConstantComposite %v3uint %uint_7 %s %uint_1\n"
      "%e = OpSpecConstantOp %uint CompositeExtract %v3c 1\n"
      "%ins = OpSpecConstantOp %v3uint CompositeInsert %uint_7 %v3c 1\n"
      "%e2 = OpSpecConstantOp %uint CompositeExtract %ins 1\n"
      "%sh = OpSpecConstantOp %v2uint VectorShuffle %v3c %ins 1 4\n"
      "%sh1 = OpSpecConstantOp %uint CompositeExtract %sh 0\n"
      "%sh2 = OpSpecConstantOp %uint CompositeExtract %sh 1\n"
      "%shu = OpSpecConstantOp %v2uint VectorShuffle %v3c %v3c 4294967295 2\n"
      "%shu1 = OpSpecConstantOp %uint CompositeExtract %shu 1\n";
  const std::string body =
      "%a1 = OpIMul %uint %e %uint_1000\n"
      "%a2 = OpIMul %uint %e2 %uint_100\n"
      "%a3 = OpIMul %uint %sh1 %uint_10\n"
      "%t1 = OpIAdd %uint %a1 %a2\n"
      "%t2 = OpIAdd %uint %t1 %a3\n"
      "%t3 = OpIAdd %uint %t2 %sh2\n"
      "%t4 = OpIAdd %uint %t3 %shu1\n"
      "OpStore %slot %t4";
  const std::string decorations = "OpDecorate %s SpecId 4";
  for (uint32_t s : {3u, 5u}) {
    ComputeHarness h;
    ASSERT_TRUE(compileText(h, module("", decorations, "%uint", "4", globals, body, types),
                            s == 3 ? std::vector<spirv::SpecValue>{} : std::vector{specU32(4, s)}))
        << h.error;
    h.zeroBuffer<uint32_t>(0, 2);
    ASSERT_TRUE(h.run(2));
    // extract(v3c, 1) = s; insert(7, v3c, 1) = (7, 7, 1), its part 1 = 7; shuffle(v3c, ins; 1, 4) = (s, 7);
    // shuffle(v3c, v3c; undefined, 2) = (?, 1) (an undefined component is allowed, as the CTS's vector_related has).
    const uint32_t expected = s * 1000 + 7 * 100 + s * 10 + 7 + 1;
    auto r = h.get<uint32_t>(0);
    for (uint32_t g = 0; g < 2; ++g) EXPECT_EQ(r[g], expected) << "s " << s << ", invocation " << g;
  }
  const struct {
    const char* line;
    const char* rule;
  } broken[] = {
      {"%bad = OpSpecConstantOp %v3uint CompositeExtract %uint_1 8", "an index is outside the composite's type"},
      {"%bad = OpSpecConstantOp %uint CompositeExtract %v3c 5", "an index is outside the composite's type"},
      {"%bad = OpSpecConstantOp %uint CompositeExtract %v3c 0 0", "an index is outside the composite's type"},
      {"%bad = OpSpecConstantOp %float CompositeExtract %v3c 1",
       "the result type is not the type of the selected part"},
      {"%bad = OpSpecConstantOp %v3uint CompositeInsert %uint_1 %v3c 7", "an index is outside the composite's type"},
      {"%bad = OpSpecConstantOp %v2uint VectorShuffle %v3c %v3c 0 9", "a component selects past both vectors"},
      {"%bad = OpSpecConstantOp %float QuantizeToF16 %s", "needs a 32-bit float operand of the result type"},
      {"%bad = OpSpecConstantOp %uint IAdd %v3c %uint_1",
       "needs integer operands with the result's component count and width"},
  };
  for (const auto& b : broken) {
    ComputeHarness h;
    EXPECT_FALSE(compileText(h, module("", decorations, "%uint", "4", globals + b.line, body, types))) << b.line;
    EXPECT_NE(h.error.find("invalid SPIR-V: OpSpecConstantOp"), std::string::npos) << b.line << ": " << h.error;
    EXPECT_NE(h.error.find(b.rule), std::string::npos) << b.line << ": " << h.error;
  }
}

// Shifts whose amount has another signedness or width than the shifted value: SPIRV-Tools' folding leaves them,
// and vkrt evaluates what is left.
TEST(SpirvConformance, SpecConstantOpShiftsAreEvaluated) {
  std::string text = module("OpCapability Int16", "OpDecorate %n SpecId 1", "%uint", "4",
                            "%ushort = OpTypeInt 16 0\n"
                            "%n = OpSpecConstant %int -64\n"
                            "%ushort_3 = OpConstant %ushort 3\n"
                            "%uint_2 = OpConstant %uint 2\n"
                            "%shl = OpSpecConstantOp %int ShiftLeftLogical %n %ushort_3\n"
                            "%sra = OpSpecConstantOp %int ShiftRightArithmetic %n %uint_2\n"
                            "%srl = OpSpecConstantOp %int ShiftRightLogical %n %ushort_3\n"
                            "%sum0 = OpSpecConstantOp %int IAdd %shl %sra\n"
                            "%sum = OpSpecConstantOp %int BitwiseXor %sum0 %srl\n",
                            "%r = OpBitcast %uint %sum\n"
                            "%rg = OpIAdd %uint %r %g\n"
                            "OpStore %slot %rg");
  for (int32_t n : {-64, 1000}) {
    ComputeHarness h;
    ASSERT_TRUE(compileText(h, text, {specU32(1, uint32_t(n))})) << h.error;
    h.zeroBuffer<uint32_t>(0, 2);
    ASSERT_TRUE(h.run(2));
    uint32_t u = uint32_t(n);
    uint32_t expected = ((u << 3) + uint32_t(n >> 2)) ^ (u >> 3);
    EXPECT_EQ(h.get<uint32_t>(0)[0], expected) << n;
    EXPECT_EQ(h.get<uint32_t>(0)[1], expected + 1) << n;
  }
}

// The reference half rounding: GCC's _Float16 conversions (libgcc, correctly rounded to nearest even).
uint16_t halfBits(_Float16 h) { return std::bit_cast<uint16_t>(h); }

TEST(SpirvConformance, QuantizeToF16RoundsToHalfAndFlushesBelowTheSmallestNormal) {
  std::string text = module("", "", "%float", "4", "",
                            "%x = OpLoad %float %slot\n"
                            "%q = OpQuantizeToF16 %float %x\n"
                            "OpStore %slot %q");
  const float inf = std::numeric_limits<float>::infinity();
  std::vector<float> in = {
      1.0f, 1.0f + 0x1p-11f, 1.0f + 0x3p-12f, -3.14159265f, 65504.0f, 65520.0f, 1e9f,   -1e9f,   inf,
      -inf, 0x1p-14f,        0x1p-15f,        -0x1p-20f,    0.0f,     -0.0f,    1e-30f, 6.1e-5f, 123.456f};
  ComputeHarness h;
  ASSERT_TRUE(compileText(h, text)) << h.error;
  h.setBuffer(0, in);
  ASSERT_TRUE(h.run(uint32_t(in.size())));
  auto out = h.get<float>(0);
  for (size_t i = 0; i < in.size(); ++i) {
    float expected = float(_Float16(in[i]));
    if (std::fabs(expected) < 0x1p-14f) expected = std::copysign(0.0f, in[i]);
    EXPECT_EQ(std::bit_cast<uint32_t>(out[i]), std::bit_cast<uint32_t>(expected)) << "input " << in[i];
  }
  // A NaN stays a NaN.
  h.setBuffer(0, std::vector<float>{std::numeric_limits<float>::quiet_NaN()});
  ASSERT_TRUE(h.run(1));
  EXPECT_TRUE(std::isnan(h.get<float>(0)[0]));
}

// OpSpecConstantOp QuantizeToF16: Debian's SPIRV-Tools crashed folding it in a module declaring a float controls
// capability (the CTS's spirv_assembly.instruction.graphics.opquantize.spec_const_inf and the like) and kept results
// below 2^-14 elsewhere; vkrt folds it itself, to the value the instruction computes at run time (the same
// reference as above), with and without each float controls capability.
TEST(SpirvConformance, QuantizeToF16SpecConstantOpFoldsAsTheInstruction) {
  const float inf = std::numeric_limits<float>::infinity();
  const std::vector<float> values = {
      1.0f,     1.0f + 0x1p-11f,     -3.14159265f,        65504.0f,  65520.0f, 1e9f, -inf, inf,
      0x1p-14f, 0x1p-14f - 0x1p-25f, 0x1p-14f - 0x1p-24f, -0x1p-20f, 1e-30f,   -0.0f};
  for (const char* cap :
       {"", "OpCapability SignedZeroInfNanPreserve", "OpCapability DenormPreserve", "OpCapability RoundingModeRTE"}) {
    std::string caps = *cap ? std::string(cap) + "\nOpExtension \"SPV_KHR_float_controls\"" : "";
    std::string text = module(caps, "OpDecorate %x SpecId 3", "%float", "4",
                              "%x = OpSpecConstant %float 0\n%q = OpSpecConstantOp %float QuantizeToF16 %x\n"
                              "%qq = OpSpecConstantOp %float QuantizeToF16 %q",
                              "OpStore %slot %q\n"
                              "%slot1 = OpAccessChain %ptr_sb_elem %data %uint_0 %uint_1\n"
                              "OpStore %slot1 %qq");
    for (float v : values) {
      spirv::SpecValue spec{3, std::vector<uint8_t>(4)};
      std::memcpy(spec.bytes.data(), &v, 4);
      ComputeHarness h;
      ASSERT_TRUE(compileText(h, text, {spec})) << h.error;
      h.zeroBuffer<float>(0, 2);
      ASSERT_TRUE(h.run(1));
      auto out = h.get<float>(0);
      float expected = float(_Float16(v));
      if (std::fabs(expected) < 0x1p-14f) expected = std::copysign(0.0f, v);
      EXPECT_EQ(std::bit_cast<uint32_t>(out[0]), std::bit_cast<uint32_t>(expected)) << cap << ", value " << v;
      EXPECT_EQ(std::bit_cast<uint32_t>(out[1]), std::bit_cast<uint32_t>(expected)) << cap << ", value " << v;
    }
    spirv::SpecValue nan{3, std::vector<uint8_t>(4)};
    const float qnan = std::numeric_limits<float>::quiet_NaN();
    std::memcpy(nan.bytes.data(), &qnan, 4);
    ComputeHarness h;
    ASSERT_TRUE(compileText(h, text, {nan})) << h.error;
    h.zeroBuffer<float>(0, 2);
    ASSERT_TRUE(h.run(1));
    EXPECT_TRUE(std::isnan(h.get<float>(0)[0])) << cap;
  }
}

// double -> half: LLVM lowers it to a library call the JIT did not have ("Failed to materialize symbols"); the
// conversion must also round once (through float with ordinary rounding it would round twice).
TEST(SpirvConformance, DoubleToHalfConversionRoundsOnce) {
  std::string text = module("OpCapability Float64\nOpCapability Float16\nOpCapability StorageBuffer16BitAccess",
                            "OpDecorate %rta_h ArrayStride 2\nOpMemberDecorate %buf_h 0 Offset 0\n"
                            "OpDecorate %buf_h Block\nOpDecorate %out DescriptorSet 0\nOpDecorate %out Binding 1",
                            "%double", "8",
                            "%rta_h = OpTypeRuntimeArray %half\n"
                            "%buf_h = OpTypeStruct %rta_h\n"
                            "%ptr_sb_buf_h = OpTypePointer StorageBuffer %buf_h\n"
                            "%out = OpVariable %ptr_sb_buf_h StorageBuffer\n"
                            "%ptr_sb_half = OpTypePointer StorageBuffer %half\n",
                            "%x = OpLoad %double %slot\n"
                            "%h = OpFConvert %half %x\n"
                            "%dst = OpAccessChain %ptr_sb_half %out %uint_0 %g\n"
                            "OpStore %dst %h",
                            "%double = OpTypeFloat 64\n%half = OpTypeFloat 16");
  // The module names %out in OpEntryPoint too (SPIR-V 1.4+ lists every global it uses).
  text.replace(text.find("%gid %data"), 10, "%gid %data %out");
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> in = {1.0 + 0x1p-11 + 0x1p-40,  // just above a half tie: rounding through float would tie
                            1.0 + 0x1p-11,            // an exact tie: to even (1.0)
                            1.0 + 0x3p-11,            // a tie: to even (1 + 2^-9)
                            -2049.0 - 0x1p-30,
                            65519.99,
                            65520.0,
                            1e300,
                            -inf,
                            0x1p-24 * 0.5 + 0x1p-60,  // just above half the smallest subnormal half: rounds up
                            0x1p-25,                  // a tie with zero: to even (zero)
                            -0x1p-30,
                            0.1,
                            1.0 / 3.0};
  ComputeHarness h;
  ASSERT_TRUE(compileText(h, text)) << h.error;
  h.setBuffer(0, in);
  h.zeroBuffer<uint16_t>(1, in.size());
  ASSERT_TRUE(h.run(uint32_t(in.size())));
  auto out = h.get<uint16_t>(1);
  for (size_t i = 0; i < in.size(); ++i) EXPECT_EQ(out[i], halfBits(_Float16(in[i]))) << "input " << in[i];
}

// NonSemantic.* extended instruction sets carry no semantics and must be ignored (SPV_KHR_non_semantic_info).
TEST(SpirvConformance, NonSemanticInstructionsAreIgnored) {
  std::string text = module("OpExtension \"SPV_KHR_non_semantic_info\"\n%ns = OpExtInstImport \"NonSemantic.Vkrt\"", "",
                            "%uint", "4", "%str = OpString \"a note\"\n%note = OpExtInst %void %ns 1 %str %uint_1",
                            "%ig = OpExtInst %void %ns 2 %g\n"
                            "%g2 = OpIMul %uint %g %g\n"
                            "OpStore %slot %g2");
  // OpString belongs to the debug section, before the decorations.
  size_t at = text.find("%str = OpString");
  std::string str = "%str = OpString \"a note\"\n";
  text.erase(at, str.size());
  text.insert(text.find("OpDecorate %gid"), str);
  ComputeHarness h;
  ASSERT_TRUE(compileText(h, text)) << h.error;
  h.zeroBuffer<uint32_t>(0, 3);
  ASSERT_TRUE(h.run(3));
  EXPECT_EQ(h.get<uint32_t>(0), (std::vector<uint32_t>{0, 1, 4}));
}

// Decorations applied through OpDecorationGroup / OpGroupDecorate / OpGroupMemberDecorate.
TEST(SpirvConformance, DecorationGroupsApply) {
  std::string decorations =
      "%grp = OpDecorationGroup\n"
      "OpDecorate %grp DescriptorSet 0\n"
      "OpDecorate %grp Binding 1\n"
      "%mgrp = OpDecorationGroup\n"
      "OpDecorate %mgrp Offset 4\n"
      "OpDecorate %in Binding 0\n"
      "OpDecorate %in DescriptorSet 0\n"
      "OpGroupDecorate %grp %data\n"
      "OpGroupMemberDecorate %mgrp %pair 1\n"
      "OpMemberDecorate %pair 0 Offset 0\n"
      "OpDecorate %pairs ArrayStride 8\n"
      "OpMemberDecorate %inbuf 0 Offset 0\n"
      "OpDecorate %inbuf Block";
  std::string text = module("", decorations, "%uint", "4",
                            "%pair = OpTypeStruct %uint %uint\n"
                            "%pairs = OpTypeRuntimeArray %pair\n"
                            "%inbuf = OpTypeStruct %pairs\n"
                            "%ptr_sb_inbuf = OpTypePointer StorageBuffer %inbuf\n"
                            "%in = OpVariable %ptr_sb_inbuf StorageBuffer\n"
                            "%ptr_sb_uint = OpTypePointer StorageBuffer %uint\n",
                            "%p1 = OpAccessChain %ptr_sb_uint %in %uint_0 %g %uint_1\n"
                            "%v = OpLoad %uint %p1\n"
                            "OpStore %slot %v");
  text.replace(text.find("%gid %data"), 10, "%gid %data %in");
  ComputeHarness h;
  ASSERT_TRUE(compileText(h, text)) << h.error;
  h.setBuffer(0, std::vector<uint32_t>{10, 11, 20, 21, 30, 31});
  h.zeroBuffer<uint32_t>(1, 3);
  ASSERT_TRUE(h.run(3));
  EXPECT_EQ(h.get<uint32_t>(1), (std::vector<uint32_t>{11, 21, 31}));
}

// DeviceIndex (Vulkan 1.1's device groups): one physical device, index 0.
TEST(SpirvConformance, DeviceIndexIsZero) {
  std::string text = module("OpCapability DeviceGroup", "OpDecorate %dev BuiltIn DeviceIndex", "%uint", "4",
                            "%ptr_in_uint = OpTypePointer Input %uint\n%dev = OpVariable %ptr_in_uint Input\n",
                            "%d = OpLoad %uint %dev\n"
                            "%d1 = OpIAdd %uint %d %g\n"
                            "OpStore %slot %d1");
  text.replace(text.find("%gid %data"), 10, "%gid %data %dev");
  ComputeHarness h;
  ASSERT_TRUE(compileText(h, text)) << h.error;
  h.setBuffer(0, std::vector<uint32_t>{99, 99});
  ASSERT_TRUE(h.run(2));
  EXPECT_EQ(h.get<uint32_t>(0), (std::vector<uint32_t>{0, 1}));
}

// 8-bit scalars in a push-constant block (StoragePushConstant8), an array with stride 1, one invocation per
// workgroup.
TEST(SpirvConformance, EightBitPushConstantArray) {
  std::string text =
      module("OpCapability StoragePushConstant8",
             "OpDecorate %u8arr ArrayStride 1\nOpDecorate %pc Block\nOpMemberDecorate %pc 0 Offset 0", "%uint", "4",
             "%uint_64 = OpConstant %uint 64\n"
             "%u8arr = OpTypeArray %u8 %uint_64\n"
             "%pc = OpTypeStruct %u8arr\n"
             "%ptr_pc = OpTypePointer PushConstant %pc\n"
             "%pcv = OpVariable %ptr_pc PushConstant\n"
             "%ptr_pc_u8 = OpTypePointer PushConstant %u8\n",
             "%p = OpAccessChain %ptr_pc_u8 %pcv %uint_0 %g\n"
             "%v8 = OpLoad %u8 %p\n"
             "%v = OpUConvert %uint %v8\n"
             "OpStore %slot %v",
             "%u8 = OpTypeInt 8 0");
  text.replace(text.find("%gid %data"), 10, "%gid %data %pcv");
  ComputeHarness h;
  ASSERT_TRUE(compileText(h, text)) << h.error;
  std::vector<uint32_t> expected(64);
  for (uint32_t i = 0; i < 64; ++i) h.push[i] = uint8_t(i * 37 + 5), expected[i] = h.push[i];
  h.setBuffer(0, std::vector<uint32_t>(64, 7));
  ASSERT_TRUE(h.run(64));
  EXPECT_EQ(h.get<uint32_t>(0), expected);
}

// FPRoundingMode RTZ on a narrowing OpFConvert (16-bit storage's *_rtz cases), from float and from double. The
// reference searches the sorted finite halves for the one at or next toward zero from the input.
double halfTowardZero(double x) {
  static const std::vector<double> halves = [] {
    std::vector<double> v;
    for (uint32_t bits = 0; bits < 0x10000; ++bits) {
      double d = double(std::bit_cast<_Float16>(uint16_t(bits)));
      if (std::isfinite(d)) v.push_back(d);
    }
    std::sort(v.begin(), v.end());
    return v;
  }();
  if (x >= 0) return *(std::upper_bound(halves.begin(), halves.end(), x) - 1);  // the last <= x
  return *std::lower_bound(halves.begin(), halves.end(), x);                    // the first >= x
}

TEST(SpirvConformance, RoundTowardZeroOnNarrowingConversions) {
  std::string decorations =
      "OpDecorate %rtz FPRoundingMode RTZ\nOpDecorate %drtz FPRoundingMode RTZ\n"
      "OpDecorate %rta_h ArrayStride 2\nOpMemberDecorate %buf_h 0 Offset 0\nOpDecorate %buf_h Block\n"
      "OpDecorate %out DescriptorSet 0\nOpDecorate %out Binding 1\n"
      "OpDecorate %rta_d ArrayStride 8\nOpMemberDecorate %buf_d 0 Offset 0\nOpDecorate %buf_d Block\n"
      "OpDecorate %din DescriptorSet 0\nOpDecorate %din Binding 2";
  std::string text = module(
      "OpCapability Float64\nOpCapability Float16\nOpCapability StorageBuffer16BitAccess", decorations, "%float", "4",
      "%rta_h = OpTypeRuntimeArray %half\n%buf_h = OpTypeStruct %rta_h\n"
      "%ptr_sb_buf_h = OpTypePointer StorageBuffer %buf_h\n%out = OpVariable %ptr_sb_buf_h StorageBuffer\n"
      "%ptr_sb_half = OpTypePointer StorageBuffer %half\n"
      "%rta_d = OpTypeRuntimeArray %double\n%buf_d = OpTypeStruct %rta_d\n"
      "%ptr_sb_buf_d = OpTypePointer StorageBuffer %buf_d\n%din = OpVariable %ptr_sb_buf_d StorageBuffer\n"
      "%ptr_sb_double = OpTypePointer StorageBuffer %double\n"
      "%uint_2 = OpConstant %uint 2\n",
      "%x = OpLoad %float %slot\n"
      "%rtz = OpFConvert %half %x\n"
      "%dslot = OpAccessChain %ptr_sb_double %din %uint_0 %g\n%dx = OpLoad %double %dslot\n"
      "%drtz = OpFConvert %half %dx\n"
      "%g2 = OpIMul %uint %g %uint_2\n"
      "%o0 = OpAccessChain %ptr_sb_half %out %uint_0 %g2\nOpStore %o0 %rtz\n"
      "%g21 = OpIAdd %uint %g2 %uint_1\n%o1 = OpAccessChain %ptr_sb_half %out %uint_0 %g21\nOpStore %o1 %drtz",
      "%double = OpTypeFloat 64\n%half = OpTypeFloat 16");
  text.replace(text.find("%gid %data"), 10, "%gid %data %out %din");
  std::vector<float> in = {
      1.0f,     1.0f + 0x1p-11f, 1.0f + 0x3p-12f, -1.0f - 0x3p-12f, 3.14159265f, -3.14159265f, 65504.0f, 65519.0f,
      70000.0f, -70000.0f,       1e-7f,           -1e-7f,           1e-9f,       -1e-9f,       0.1f,     -0.1f,
      2.0f,     1000.7f};
  std::vector<double> din = {1.0 + 0x1p-11 + 0x1p-40,
                             -1.0 - 0x1p-11 - 0x1p-40,
                             1e300,
                             -1e300,
                             0.3,
                             -0.3,
                             1e-8,
                             -1e-8,
                             2.0,
                             65505.0,
                             0.5,
                             5e-324,
                             -0.7,
                             1234.5678,
                             1e-5,
                             -1e-5,
                             7.0,
                             8.0};
  ComputeHarness h;
  ASSERT_TRUE(compileText(h, text)) << h.error;
  h.setBuffer(0, in);
  h.zeroBuffer<uint16_t>(1, 2 * in.size());
  h.setBuffer(2, din);
  ASSERT_TRUE(h.run(uint32_t(in.size())));
  auto out = h.get<uint16_t>(1);
  auto asDouble = [](uint16_t bits) { return double(std::bit_cast<_Float16>(bits)); };
  for (size_t i = 0; i < in.size(); ++i) {
    EXPECT_EQ(asDouble(out[2 * i]), halfTowardZero(in[i])) << "float input " << in[i];
    EXPECT_EQ(asDouble(out[2 * i + 1]), halfTowardZero(din[i])) << "double input " << din[i];
  }
  // Zeros keep their sign.
  EXPECT_EQ(out[2 * 0] & 0x8000, 0);
  EXPECT_EQ(out[2 * 13] & 0x8000, 0x8000) << "-1e-9 rounds toward zero to -0";
}

// GLSL.std.450 FMin/FMax/NMin/NClamp on 16-bit float vectors: LLVM 15 could not select them ("Cannot select:
// v8f16 = X86ISD::FMIN"); vkrt compares the bits. The reference is std::fmin/fmax on the (exact) float values.
TEST(SpirvConformance, HalfVectorMinMax) {
  std::string decorations =
      "OpDecorate %rta_h ArrayStride 8\nOpMemberDecorate %buf_h 0 Offset 0\nOpDecorate %buf_h Block\n"
      "OpDecorate %hin DescriptorSet 0\nOpDecorate %hin Binding 1\n"
      "OpDecorate %hout DescriptorSet 0\nOpDecorate %hout Binding 2";
  std::string text = module(
      "OpCapability Float16\nOpCapability StorageBuffer16BitAccess", decorations, "%float", "4",
      "%v4half = OpTypeVector %half 4\n%rta_h = OpTypeRuntimeArray %v4half\n%buf_h = OpTypeStruct %rta_h\n"
      "%ptr_sb_buf_h = OpTypePointer StorageBuffer %buf_h\n%hin = OpVariable %ptr_sb_buf_h StorageBuffer\n"
      "%hout = OpVariable %ptr_sb_buf_h StorageBuffer\n%ptr_sb_v4half = OpTypePointer StorageBuffer %v4half\n"
      "%uint_2 = OpConstant %uint 2\n%uint_3 = OpConstant %uint 3\n%uint_4 = OpConstant %uint 4\n",
      "%ga = OpIMul %uint %g %uint_2\n%gb = OpIAdd %uint %ga %uint_1\n"
      "%pa = OpAccessChain %ptr_sb_v4half %hin %uint_0 %ga\n%a = OpLoad %v4half %pa\n"
      "%pb = OpAccessChain %ptr_sb_v4half %hin %uint_0 %gb\n%bv = OpLoad %v4half %pb\n"
      "%mn = OpExtInst %v4half %std FMin %a %bv\n%mx = OpExtInst %v4half %std FMax %a %bv\n"
      "%nmn = OpExtInst %v4half %std NMin %a %bv\n%ncl = OpExtInst %v4half %std NClamp %a %bv %bv\n"
      "%g4 = OpIMul %uint %g %uint_4\n"
      "%o0 = OpAccessChain %ptr_sb_v4half %hout %uint_0 %g4\nOpStore %o0 %mn\n"
      "%g41 = OpIAdd %uint %g4 %uint_1\n%o1 = OpAccessChain %ptr_sb_v4half %hout %uint_0 %g41\nOpStore %o1 %mx\n"
      "%g42 = OpIAdd %uint %g4 %uint_2\n%o2 = OpAccessChain %ptr_sb_v4half %hout %uint_0 %g42\nOpStore %o2 %nmn\n"
      "%g43 = OpIAdd %uint %g4 %uint_3\n%o3 = OpAccessChain %ptr_sb_v4half %hout %uint_0 %g43\nOpStore %o3 %ncl",
      "%half = OpTypeFloat 16");
  text.replace(text.find("%gid %data"), 10, "%gid %data %hin %hout");
  text.replace(text.find("OpMemoryModel"), 0, "%std = OpExtInstImport \"GLSL.std.450\"\n");
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  // Pairs of vec4: a then b.
  std::vector<float> values = {1.0f, -2.0f, 0.5f,  -0.0f, 2.0f, -1.0f, 0.25f, 0.0f, -inf, inf, 65504.0f, -3.0f,
                               3.0f, -inf,  -7.0f, 1e-6f, nan,  4.0f,  -0.5f, 8.0f, 2.0f, nan, -0.75f,   -8.0f};
  const size_t pairs = values.size() / 8;
  std::vector<uint16_t> in;
  for (float v : values) in.push_back(halfBits(_Float16(v)));
  ComputeHarness h;
  ASSERT_TRUE(compileText(h, text)) << h.error;
  h.zeroBuffer<float>(0, pairs);
  h.setBuffer(1, in);
  h.zeroBuffer<uint16_t>(2, 16 * pairs);
  ASSERT_TRUE(h.run(uint32_t(pairs)));
  auto out = h.get<uint16_t>(2);
  auto f = [](uint16_t bits) { return float(std::bit_cast<_Float16>(bits)); };
  for (size_t p = 0; p < pairs; ++p) {
    for (int c = 0; c < 4; ++c) {
      float a = f(in[8 * p + c]), bv = f(in[8 * p + 4 + c]);
      std::string where = "pair " + std::to_string(p) + " component " + std::to_string(c);
      float mn = f(out[16 * p + c]), mx = f(out[16 * p + 4 + c]), nmn = f(out[16 * p + 8 + c]);
      if (!std::isnan(a) && !std::isnan(bv)) {  // FMin/FMax with a NaN are undefined
        EXPECT_EQ(mn, std::fmin(a, bv)) << where;
        EXPECT_EQ(mx, std::fmax(a, bv)) << where;
      }
      // NMin: the other operand where one is a NaN (std::fmin's rule too).
      EXPECT_EQ(nmn, std::fmin(a, bv)) << where;
      // NClamp(a, b, b) is b unless b is a NaN (then a).
      float ncl = f(out[16 * p + 12 + c]);
      if (std::isnan(bv))
        EXPECT_TRUE(ncl == a || (std::isnan(a) && std::isnan(ncl))) << where;
      else
        EXPECT_EQ(ncl, bv) << where;
    }
  }
}

// SPV_KHR_workgroup_memory_explicit_layout: Block-decorated Workgroup variables use their Offset/ArrayStride
// layout and alias one another (the CTS's workgroup_memory_explicit_layout.alias cases). A uint array written
// through one block is read back as floats through the other, and a struct member through a third at offset 4.
TEST(SpirvConformance, WorkgroupBlocksAliasWithExplicitLayout) {
  std::string decorations =
      "OpDecorate %ua ArrayStride 4\nOpMemberDecorate %A 0 Offset 0\nOpDecorate %A Block\n"
      "OpDecorate %fa ArrayStride 4\nOpMemberDecorate %B 0 Offset 0\nOpDecorate %B Block\n"
      "OpMemberDecorate %C 0 Offset 4\nOpDecorate %C Block\n"
      "OpDecorate %wa Aliased\nOpDecorate %wb Aliased\nOpDecorate %wc Aliased";
  std::string text =
      module("OpCapability WorkgroupMemoryExplicitLayoutKHR\nOpExtension \"SPV_KHR_workgroup_memory_explicit_layout\"",
             decorations, "%uint", "4",
             "%uint_4 = OpConstant %uint 4\n%uint_2 = OpConstant %uint 2\n%uint_3 = OpConstant %uint 3\n"
             "%ua = OpTypeArray %uint %uint_4\n%A = OpTypeStruct %ua\n%ptr_wg_A = OpTypePointer Workgroup %A\n"
             "%fa = OpTypeArray %float %uint_4\n%B = OpTypeStruct %fa\n%ptr_wg_B = OpTypePointer Workgroup %B\n"
             "%C = OpTypeStruct %uint\n%ptr_wg_C = OpTypePointer Workgroup %C\n"
             "%wa = OpVariable %ptr_wg_A Workgroup\n%wb = OpVariable %ptr_wg_B Workgroup\n"
             "%wc = OpVariable %ptr_wg_C Workgroup\n"
             "%ptr_wg_uint = OpTypePointer Workgroup %uint\n%ptr_wg_float = OpTypePointer Workgroup %float\n"
             "%bits_1_5 = OpConstant %uint 0x3fc00000\n%bits_m2 = OpConstant %uint 0xc0000000\n",
             "%a1 = OpAccessChain %ptr_wg_uint %wa %uint_0 %uint_1\nOpStore %a1 %bits_1_5\n"
             "%a2 = OpAccessChain %ptr_wg_uint %wa %uint_0 %uint_2\nOpStore %a2 %bits_m2\n"
             "%b1 = OpAccessChain %ptr_wg_float %wb %uint_0 %uint_1\n%f1 = OpLoad %float %b1\n"
             "%b2 = OpAccessChain %ptr_wg_float %wb %uint_0 %uint_2\n%f2 = OpLoad %float %b2\n"
             "%c0 = OpAccessChain %ptr_wg_uint %wc %uint_0\n%cv = OpLoad %uint %c0\n"
             "%sum = OpFAdd %float %f1 %f2\n%sumbits = OpBitcast %uint %sum\n"
             "%r = OpIAdd %uint %sumbits %cv\nOpStore %slot %r");
  text.replace(text.find("%gid %data"), 10, "%gid %data %wa %wb %wc");
  ComputeHarness h;
  ASSERT_TRUE(compileText(h, text)) << h.error;
  h.zeroBuffer<uint32_t>(0, 2);
  ASSERT_TRUE(h.run(2));
  // 1.5 + -2.0 = -0.5, plus C's member at offset 4: the word written as 1.5.
  uint32_t expected = std::bit_cast<uint32_t>(-0.5f) + 0x3fc00000u;
  EXPECT_EQ(h.get<uint32_t>(0), (std::vector<uint32_t>{expected, expected}));
}

// The float controls vkrt advertises (DenormPreserve, SignedZeroInfNanPreserve, RoundingModeRTE for 16/32/64-bit):
// the execution modes compile, denormals survive arithmetic, zeros keep their sign, infinities stay. Expected
// values are bit patterns.
TEST(SpirvConformance, FloatControlsPreserveDenormalsSignedZerosAndInfinities) {
  std::string text = module(
      "OpCapability DenormPreserve\nOpCapability SignedZeroInfNanPreserve\nOpCapability RoundingModeRTE\n"
      "OpCapability Float16\nOpCapability Int16\nOpExtension \"SPV_KHR_float_controls\"",
      "", "%uint", "4",
      "%uint_2 = OpConstant %uint 2\n%uint_3 = OpConstant %uint 3\n%uint_4 = OpConstant %uint 4\n"
      "%uint_5 = OpConstant %uint 5\n%min_denorm = OpConstant %uint 1\n%denorm = OpConstant %uint 0x00400000\n"
      "%neg_zero = OpConstant %uint 0x80000000\n%inf = OpConstant %uint 0x7f800000\n"
      "%float_2 = OpConstant %float 2\n%float_m1 = OpConstant %float -1\n%float_1 = OpConstant %float 1\n"
      "%ushort = OpTypeInt 16 0\n%half = OpTypeFloat 16\n%half_min_denorm = OpConstant %ushort 1\n",
      "%a = OpBitcast %float %min_denorm\n%s = OpFAdd %float %a %a\n%sb = OpBitcast %uint %s\n"
      "%d = OpBitcast %float %denorm\n%m = OpFMul %float %d %float_2\n%mb = OpBitcast %uint %m\n"
      "%nz = OpBitcast %float %neg_zero\n%z = OpFAdd %float %nz %nz\n%zb = OpBitcast %uint %z\n"
      "%i = OpBitcast %float %inf\n%im = OpFAdd %float %i %float_m1\n%imb = OpBitcast %uint %im\n"
      "%ni = OpFNegate %float %i\n%q = OpFDiv %float %float_1 %ni\n%qb = OpBitcast %uint %q\n"
      "%h = OpBitcast %half %half_min_denorm\n%hs = OpFAdd %half %h %h\n%hsb = OpBitcast %ushort %hs\n"
      "%hsu = OpUConvert %uint %hsb\n"
      "%e0 = OpAccessChain %ptr_sb_elem %data %uint_0 %uint_0\nOpStore %e0 %sb\n"
      "%e1 = OpAccessChain %ptr_sb_elem %data %uint_0 %uint_1\nOpStore %e1 %mb\n"
      "%e2 = OpAccessChain %ptr_sb_elem %data %uint_0 %uint_2\nOpStore %e2 %zb\n"
      "%e3 = OpAccessChain %ptr_sb_elem %data %uint_0 %uint_3\nOpStore %e3 %imb\n"
      "%e4 = OpAccessChain %ptr_sb_elem %data %uint_0 %uint_4\nOpStore %e4 %qb\n"
      "%e5 = OpAccessChain %ptr_sb_elem %data %uint_0 %uint_5\nOpStore %e5 %hsu");
  text.insert(text.find("OpDecorate %gid"),
              "OpExecutionMode %main DenormPreserve 32\nOpExecutionMode %main DenormPreserve 16\n"
              "OpExecutionMode %main SignedZeroInfNanPreserve 32\nOpExecutionMode %main RoundingModeRTE 32\n");
  ComputeHarness h;
  ASSERT_TRUE(compileText(h, text)) << h.error;
  h.zeroBuffer<uint32_t>(0, 6);
  ASSERT_TRUE(h.run(1));
  EXPECT_EQ(h.get<uint32_t>(0),
            (std::vector<uint32_t>{0x00000002u, 0x00800000u, 0x80000000u, 0x7f800000u, 0x80000000u, 0x0002u}));
}

// SPV_KHR_integer_dot_product: packed 4 x 8-bit signed, signed x unsigned with a saturating accumulator, and
// unsigned vectors; the reference multiplies and adds in 64 bits here.
TEST(SpirvConformance, IntegerDotProducts) {
  std::string text = module(
      "OpCapability DotProduct\nOpCapability DotProductInput4x8BitPacked\nOpCapability DotProductInputAll\n"
      "OpCapability Int8\nOpExtension \"SPV_KHR_integer_dot_product\"",
      "", "%uint", "4",
      "%uint_2 = OpConstant %uint 2\n%uint_3 = OpConstant %uint 3\n%uint_4 = OpConstant %uint 4\n"
      "%v4uint = OpTypeVector %uint 4\n",
      "%g4 = OpIMul %uint %g %uint_4\n"
      "%pa = OpAccessChain %ptr_sb_elem %data %uint_0 %g4\n%a = OpLoad %uint %pa\n"
      "%g41 = OpIAdd %uint %g4 %uint_1\n%pb = OpAccessChain %ptr_sb_elem %data %uint_0 %g41\n%bv = OpLoad %uint %pb\n"
      "%g42 = OpIAdd %uint %g4 %uint_2\n%pc = OpAccessChain %ptr_sb_elem %data %uint_0 %g42\n%acc = OpLoad %uint %pc\n"
      "%accs = OpBitcast %int %acc\n"
      "%sdot = OpSDot %int %a %bv PackedVectorFormat4x8Bit\n"
      "%sudot = OpSUDotAccSat %int %a %bv %accs PackedVectorFormat4x8Bit\n"
      "%va = OpCompositeConstruct %v4uint %a %bv %acc %a\n%vb = OpCompositeConstruct %v4uint %bv %a %bv %acc\n"
      "%udot = OpUDot %uint %va %vb\n"
      "%r0 = OpBitcast %uint %sdot\nOpStore %pa %r0\n%r1 = OpBitcast %uint %sudot\nOpStore %pb %r1\n"
      "OpStore %pc %udot");
  struct Case {
    uint32_t a, b, acc;
  };
  std::vector<Case> cases = {{0x807f01ffu, 0x7f80ff01u, 5u},
                             {0x01020304u, 0x05060708u, 0x7ffffff0u},
                             {0xffffffffu, 0xffffffffu, 0x80000000u},
                             {0x12345678u, 0x9abcdef0u, 0xfffffffeu},
                             {0u, 0xffffffffu, 7u}};
  std::vector<uint32_t> data;
  for (const Case& c : cases) data.insert(data.end(), {c.a, c.b, c.acc, 0});
  ComputeHarness h;
  ASSERT_TRUE(compileText(h, text)) << h.error;
  h.setBuffer(0, data);
  ASSERT_TRUE(h.run(uint32_t(cases.size())));
  auto out = h.get<uint32_t>(0);
  auto byte = [](uint32_t w, int i) { return (w >> (8 * i)) & 0xff; };
  for (size_t k = 0; k < cases.size(); ++k) {
    const Case& c = cases[k];
    int64_t sdot = 0, sudot = 0;
    for (int i = 0; i < 4; ++i) {
      sdot += int64_t(int8_t(byte(c.a, i))) * int8_t(byte(c.b, i));
      sudot += int64_t(int8_t(byte(c.a, i))) * int64_t(byte(c.b, i));
    }
    int64_t sat = std::clamp<int64_t>(sudot + int32_t(c.acc), INT32_MIN, INT32_MAX);
    uint32_t udot = c.a * c.b + c.b * c.a + c.acc * c.b + c.a * c.acc;  // wraps, as OpUDot does
    EXPECT_EQ(int32_t(out[4 * k]), int32_t(sdot)) << "case " << k;
    EXPECT_EQ(int32_t(out[4 * k + 1]), int32_t(sat)) << "case " << k;
    EXPECT_EQ(out[4 * k + 2], udot) << "case " << k;
  }
}
}  // namespace
}  // namespace vkrt::testing
