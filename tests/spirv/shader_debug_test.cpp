// Shader debugging below the Vulkan API: debugPrintfEXT's formatting (every conversion, flags, vectors, 64-bit
// values), compiled printf calls collected per command in order and bounded, and out-of-bounds accesses named by
// the compiled module's site records.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "check_bda.g.comp.spv.h"
#include "check_image.g.comp.spv.h"
#include "exec/supervise.hpp"
#include "oob_barrier.comp.spv.h"
#include "oob_counted_loop.spvasm.spv.h"
#include "oob_index.comp.spv.h"
#include "oob_read.comp.spv.h"
#include "oob_uniform_lane.comp.spv.h"
#include "printf_compute.comp.spv.h"
#include "printf_switched.comp.spv.h"
#include "shader_debug_scan.hpp"
#include "spirv/compiler.hpp"
#include "spirv/compute_harness.hpp"
#include "spirv/shader_debug.hpp"

namespace vkrt {
namespace {

// Out-of-bounds reports on both compute paths: `body(spmd)` runs with the scalar path (VKRT_SPMD=0's) and with the
// SPMD path (spirv/spmd.cpp), whatever VKRT_SPMD says.
template <class F>
void onBothPaths(F body) {
  const bool was = spirv::spmdEnabled();
  for (bool spmd : {false, true}) {
    SCOPED_TRACE(spmd ? "SPMD path" : "scalar path");
    spirv::setSpmd(spmd);
    body(spmd);
  }
  spirv::setSpmd(was);
}

// Compiles `spv` (oob_read.comp's interface: binding 0 holds 10, 11, 12, 13, binding 1 four 9s, a 32-bit push
// constant), checks that the path `spmd` names compiled it, and dispatches one workgroup with `push` into `job`.
template <size_t N>
void dispatchWithPush(testing::ComputeHarness& h, const uint32_t (&spv)[N], bool spmd, uint32_t push, exec::Job& job) {
  ASSERT_TRUE(h.compile(spv)) << h.error;
  EXPECT_EQ(h.shader->spmdLanes != 0, spmd);
  h.setBuffer<uint32_t>(0, {10, 11, 12, 13});
  h.setBuffer<uint32_t>(1, {9, 9, 9, 9});
  std::memcpy(h.push, &push, 4);
  h.job = &job;
  ASSERT_TRUE(h.run(1));
}

using spirv::formatPrintf;
using spirv::PrintfArg;

uint64_t bits(double d) {
  uint64_t b;
  std::memcpy(&b, &d, 8);
  return b;
}

// A site for `format` with the given arguments, formatted with `values` (one per component).
std::string format(const std::string& text, const std::vector<PrintfArg>& args, const std::vector<uint64_t>& values) {
  std::string site = spirv::printfSite(5, args, text, "main");
  std::vector<uint32_t> aligned((site.size() + 3) / 4);
  std::memcpy(aligned.data(), site.data(), site.size());
  return formatPrintf(reinterpret_cast<const uint8_t*>(aligned.data()), values.data());
}

const PrintfArg kU32{abi::kArgUnsigned, 32, 1}, kI32{abi::kArgSigned, 32, 1}, kF32{abi::kArgFloat, 32, 1},
    kF64{abi::kArgFloat, 64, 1}, kU64{abi::kArgUnsigned, 64, 1}, kI64{abi::kArgSigned, 64, 1};

TEST(DebugPrintfFormat, IntegerConversions) {
  const uint64_t minus5 = uint64_t(int64_t(-5));  // a signed 32-bit -5, sign-extended as compiled code passes it
  EXPECT_EQ(format("%d|%i", {kI32, kI32}, {minus5, 42}), "-5|42");
  EXPECT_EQ(format("%u", {kU32}, {4000000000u}), "4000000000");
  EXPECT_EQ(format("%u", {kI32}, {minus5}), "4294967291");  // the 32 bits read as unsigned
  EXPECT_EQ(format("%x %X %o", {kU32, kU32, kU32}, {255, 0xabcdef, 8}), "ff ABCDEF 10");
  EXPECT_EQ(format("%c%c", {kU32, kU32}, {'o', 'k'}), "ok");
}

TEST(DebugPrintfFormat, FloatConversions) {
  EXPECT_EQ(format("%f", {kF32}, {bits(1.5)}), "1.500000");
  EXPECT_EQ(format("%F", {kF32}, {bits(INFINITY)}), "INF");
  EXPECT_EQ(format("%e|%E", {kF32, kF32}, {bits(1234.5), bits(1234.5)}), "1.234500e+03|1.234500E+03");
  EXPECT_EQ(format("%g|%G", {kF32, kF32}, {bits(0.0001), bits(1e-10)}), "0.0001|1E-10");
  EXPECT_EQ(format("%a|%A", {kF32, kF32}, {bits(1.0), bits(-2.0)}), "0x1p+0|-0X1P+1");
  EXPECT_EQ(format("%f", {kF64}, {bits(0.125)}), "0.125000");
  // An integer printed by a float conversion is read as the float its bits make (as the layer's words are).
  EXPECT_EQ(format("%f", {kU32}, {0x3fc00000u}), "1.500000");
  // A float printed by an integer conversion: its bits.
  EXPECT_EQ(format("%x", {kF32}, {bits(1.0)}), "3f800000");
}

TEST(DebugPrintfFormat, FlagsWidthAndPrecision) {
  EXPECT_EQ(format("[%5.2f]", {kF32}, {bits(3.14159)}), "[ 3.14]");
  EXPECT_EQ(format("[%-4d]", {kI32}, {7}), "[7   ]");
  EXPECT_EQ(format("[%08x]", {kU32}, {0xbeef}), "[0000beef]");
  EXPECT_EQ(format("[%+d][% d]", {kI32, kI32}, {3, 3}), "[+3][ 3]");
  EXPECT_EQ(format("[%#x][%#o]", {kU32, kU32}, {255, 8}), "[0xff][010]");
  EXPECT_EQ(format("[%.3e]", {kF32}, {bits(0.5)}), "[5.000e-01]");
}

TEST(DebugPrintfFormat, SixtyFourBitValues) {
  const uint64_t big = (uint64_t(1) << 40) + 7;
  EXPECT_EQ(format("%lu", {kU64}, {big}), "1099511627783");
  EXPECT_EQ(format("%lx", {kU64}, {0x123456789abcdefull}), "123456789abcdef");
  EXPECT_EQ(format("%ld", {kI64}, {uint64_t(int64_t(-5000000000ll))}), "-5000000000");
  // Without `l` a conversion prints the low 32 bits.
  EXPECT_EQ(format("%u", {kU64}, {big}), "7");
}

TEST(DebugPrintfFormat, Vectors) {
  EXPECT_EQ(format("%v3f", {{abi::kArgFloat, 32, 3}}, {bits(1.0), bits(-0.5), bits(2.25)}),
            "1.000000, -0.500000, 2.250000");
  EXPECT_EQ(format("(%v2d)", {{abi::kArgSigned, 32, 2}}, {uint64_t(int64_t(-1)), 2}), "(-1, 2)");
  EXPECT_EQ(format("%v4u", {{abi::kArgUnsigned, 32, 4}}, {1, 2, 3, 4}), "1, 2, 3, 4");
  EXPECT_EQ(format("%v2lu", {{abi::kArgUnsigned, 64, 2}}, {uint64_t(1) << 33, 5}), "8589934592, 5");
  EXPECT_EQ(format("%v2x", {{abi::kArgUnsigned, 32, 2}}, {10, 11}), "a, b");
  // A scalar conversion of a vector prints its first component; a vector conversion of a scalar its one value.
  EXPECT_EQ(format("%u", {{abi::kArgUnsigned, 32, 3}}, {9, 8, 7}), "9");
  EXPECT_EQ(format("%v3u", {kU32}, {6}), "6");
}

TEST(DebugPrintfFormat, PercentSignsAndLeftovers) {
  EXPECT_EQ(format("100%% of %u", {kU32}, {3}), "100% of 3");
  EXPECT_EQ(format("no arguments: %d", {}, {}), "no arguments: %d");
  EXPECT_EQ(format("%s and %u", {kU32}, {1}), "%s and 1");  // not a conversion GLSL can pass
  EXPECT_EQ(format("trailing %", {}, {}), "trailing %");
  EXPECT_EQ(format("", {}, {}), "");
}

// The printf calls of a dispatch, collected by its job: the text of each, in invocation order within the thread
// that ran the workgroup.
std::vector<std::string> printed(const exec::ShaderMessages& m, std::vector<exec::InvocationId>* ids = nullptr) {
  std::vector<std::string> out;
  m.forEachPrintf([&](const uint8_t* site, const exec::InvocationId& id, const uint64_t* args) {
    out.push_back(formatPrintf(site, args));
    if (ids) ids->push_back(id);
  });
  return out;
}

TEST(DebugPrintfCompiled, EveryInvocationPrintsInOrder) {
  testing::ComputeHarness h;
  ASSERT_TRUE(h.compile(kSpv_printf_compute_comp)) << h.error;
  h.zeroBuffer<uint32_t>(0, 8);
  exec::Job job(nullptr, 0);
  h.job = &job;
  ASSERT_TRUE(h.run(1));
  std::vector<exec::InvocationId> ids;
  std::vector<std::string> lines = printed(job.messages, &ids);
  ASSERT_EQ(lines.size(), 8u);
  for (uint32_t i = 0; i < 8; ++i) {
    char expected[160];
    std::snprintf(expected, sizeof expected, "i=%u neg=%d hex=%x v=%u.000000, 0.500000, -2.000000 big=%llu", i, -int(i),
                  i * 16 + 15, i, static_cast<unsigned long long>(uint64_t(i) << 40));
    EXPECT_EQ(lines[i], expected);
    EXPECT_EQ(ids[i].v[0], i);
    EXPECT_EQ(h.get<uint32_t>(0)[i], i + 1);
  }
  EXPECT_EQ(job.messages.droppedPrintfs(), 0u);
  EXPECT_TRUE(job.messages.outOfBoundsSites().empty());
}

// A debugPrintfEXT under a specialization constant: switched off, the call goes with its branch and the SPMD path
// takes the shader (a printf anywhere in it kept it scalar before); switched on, the scalar path prints every line.
TEST(DebugPrintfCompiled, APrintfASpecializationConstantSwitchesOffLeavesTheShaderSpmd) {
  const bool was = spirv::spmdEnabled();
  spirv::setSpmd(true);
  for (uint32_t on : {0u, 1u}) {
    SCOPED_TRACE(on ? "printf on" : "printf off");
    spirv::SpecValue kPrint{0, std::vector<uint8_t>(4)};
    std::memcpy(kPrint.bytes.data(), &on, 4);
    testing::ComputeHarness h;
    ASSERT_TRUE(h.compile(kSpv_printf_switched_comp, {kPrint})) << h.error;
    EXPECT_EQ(h.shader->spmdLanes, on ? 0u : spirv::spmdLanes());
    h.zeroBuffer<uint32_t>(0, 16);
    exec::Job job(nullptr, 0);
    h.job = &job;
    ASSERT_TRUE(h.run(2));
    const std::vector<uint32_t> out = h.get<uint32_t>(0);
    std::vector<std::string> lines = printed(job.messages);
    ASSERT_EQ(lines.size(), on ? 16u : 0u);
    for (uint32_t i = 0; i < 16; ++i) {
      EXPECT_EQ(out[i], 3 * i + 1) << i;
      if (on) EXPECT_EQ(lines[i], "i=" + std::to_string(i));
    }
  }
  spirv::setSpmd(was);
}

// A command keeps at most printfLimit() messages (kDefaultPrintfLimit unless VKRT_PRINTF_LIMIT says otherwise) and
// counts the others.
TEST(DebugPrintfCompiled, MessagesPastTheLimitAreCounted) {
  testing::ComputeHarness h;
  ASSERT_TRUE(h.compile(kSpv_printf_compute_comp)) << h.error;
  const uint32_t limit = exec::ShaderMessages::printfLimit();
  const uint32_t groups = limit / 8 + 100;
  h.zeroBuffer<uint32_t>(0, size_t(groups) * 8);
  exec::Job job(nullptr, 0);
  h.job = &job;
  ASSERT_TRUE(h.run(groups));
  EXPECT_EQ(printed(job.messages).size(), limit);
  EXPECT_EQ(job.messages.droppedPrintfs(), uint64_t(groups) * 8 - limit);
  EXPECT_EQ(h.get<uint32_t>(0).back(), groups * 8);  // every invocation ran
}

TEST(OutOfBoundsCompiled, AReadPastTheBufferIsNamedByWordOffset) {
  onBothPaths([](bool spmd) {
    testing::ComputeHarness h;
    exec::Job job(nullptr, 0);
    const uint32_t shift = 64;
    ASSERT_NO_FATAL_FAILURE(dispatchWithPush(h, kSpv_oob_read_comp, spmd, shift, job));
    EXPECT_EQ(h.get<uint32_t>(1), (std::vector<uint32_t>{0, 0, 0, 0}));  // zeros, as robustness says
    std::vector<exec::OutOfBoundsRecord> sites = job.messages.outOfBoundsSites();
    ASSERT_EQ(sites.size(), 1u);  // one report per site, whatever the invocations
    spirv::AccessSiteInfo s = spirv::readAccessSite(sites[0].site);
    EXPECT_EQ(s.kind, abi::kAccessLoad);
    EXPECT_EQ(s.set, 0u);
    EXPECT_EQ(s.binding, 0u);
    EXPECT_EQ(s.bytes, 4u);
    EXPECT_EQ(s.entryName, "main");
    EXPECT_TRUE(s.file.empty());
    const uint32_t expected = test::loadOffsetOfBinding(kSpv_oob_read_comp, sizeof kSpv_oob_read_comp / 4, 0);
    ASSERT_NE(expected, 0u);
    EXPECT_EQ(s.wordOffset, expected);
    EXPECT_EQ(sites[0].range, 16u);
    const uint32_t x = sites[0].id.v[0];
    EXPECT_LT(x, 4u);
    EXPECT_EQ(sites[0].offset, uint64_t(x + shift) * 4);
  });
}

// Some lanes in bounds, some out: the report names the first invocation outside (on the SPMD path, the first failing
// lane of the batch, not the first active one), and the lanes inside read their elements.
TEST(OutOfBoundsCompiled, OnlyTheInvocationsOutsideAreReported) {
  onBothPaths([](bool spmd) {
    testing::ComputeHarness h;
    exec::Job job(nullptr, 0);
    // Invocations 0 and 1 read elements 2 and 3; 2 and 3 read past the end.
    ASSERT_NO_FATAL_FAILURE(dispatchWithPush(h, kSpv_oob_read_comp, spmd, 2, job));
    EXPECT_EQ(h.get<uint32_t>(1), (std::vector<uint32_t>{12, 13, 0, 0}));
    std::vector<exec::OutOfBoundsRecord> sites = job.messages.outOfBoundsSites();
    ASSERT_EQ(sites.size(), 1u);
    EXPECT_EQ(spirv::readAccessSite(sites[0].site).kind, abi::kAccessLoad);
    EXPECT_EQ(sites[0].id.v[0], 2u);
    EXPECT_EQ(sites[0].offset, 16u);
    EXPECT_EQ(sites[0].range, 16u);
  });
}

// A uniform address read by invocations 2 and 3 only: the report names invocation 2 (the SPMD path runs the access
// once for its batch and names the batch's first active lane, not the workgroup's context).
TEST(OutOfBoundsCompiled, AUniformAccessNamesAnInvocationThatMadeIt) {
  onBothPaths([](bool spmd) {
    testing::ComputeHarness h;
    exec::Job job(nullptr, 0);
    ASSERT_NO_FATAL_FAILURE(dispatchWithPush(h, kSpv_oob_uniform_lane_comp, spmd, 5, job));
    EXPECT_EQ(h.get<uint32_t>(1), (std::vector<uint32_t>{7, 7, 0, 0}));
    std::vector<exec::OutOfBoundsRecord> sites = job.messages.outOfBoundsSites();
    ASSERT_EQ(sites.size(), 1u);
    EXPECT_EQ(sites[0].id.v[0], 2u);
    EXPECT_EQ(sites[0].offset, 20u);
    EXPECT_EQ(sites[0].range, 16u);
    // The valid side: element 3 is read, nothing reported.
    const uint32_t valid = 3;
    std::memcpy(h.push, &valid, 4);
    exec::Job job2(nullptr, 0);
    h.job = &job2;
    ASSERT_TRUE(h.run(1));
    EXPECT_EQ(h.get<uint32_t>(1), (std::vector<uint32_t>{7, 7, 13, 13}));
    EXPECT_TRUE(job2.messages.empty());
  });
}

// An index past the two bound descriptors of a four-element array: reported with the bound count. In vkrt_group's
// log an invocation keeps its first failing access, so the load through the null descriptor that follows is not
// reported.
TEST(OutOfBoundsCompiled, ADescriptorIndexPastTheBoundOnes) {
  onBothPaths([](bool spmd) {
    testing::ComputeHarness h;
    ASSERT_TRUE(h.compile(kSpv_oob_index_comp)) << h.error;
    h.setBuffer<uint32_t>(100, {7});
    h.setBuffer<uint32_t>(101, {8});
    h.arrays[0] = {100, 101};
    h.setBuffer<uint32_t>(1, {9, 9, 9, 9});
    const uint32_t index = 3;
    std::memcpy(h.push, &index, 4);
    exec::Job job(nullptr, 0);
    h.job = &job;
    ASSERT_TRUE(h.run(1));
    EXPECT_EQ(h.get<uint32_t>(1), (std::vector<uint32_t>{0, 0, 0, 0}));
    std::vector<exec::OutOfBoundsRecord> sites = job.messages.outOfBoundsSites();
    // The SPMD path reads through the null descriptor the index selects once for the batch (a uniform access) and
    // reports that load too (range 0), as the other stages do; vkrt_group's log keeps the first.
    ASSERT_EQ(sites.size(), spmd ? 2u : 1u);
    if (spmd) {
      EXPECT_EQ(spirv::readAccessSite(sites[1].site).kind, abi::kAccessLoad);
      EXPECT_EQ(sites[1].range, 0u);
    }
    spirv::AccessSiteInfo s = spirv::readAccessSite(sites[0].site);
    EXPECT_EQ(s.kind, abi::kAccessDescriptorIndex);
    EXPECT_EQ(s.binding, 0u);
    EXPECT_EQ(sites[0].element, 3u);
    EXPECT_EQ(sites[0].offset, 3u);
    EXPECT_EQ(sites[0].range, 2u);    // the bound descriptors
    EXPECT_EQ(sites[0].id.v[0], 0u);  // the first invocation (the SPMD path: the batch's first active lane)
    // The valid side: index 1 reads the second buffer and reports nothing.
    const uint32_t valid = 1;
    std::memcpy(h.push, &valid, 4);
    exec::Job job2(nullptr, 0);
    h.job = &job2;
    ASSERT_TRUE(h.run(1));
    EXPECT_EQ(h.get<uint32_t>(1), (std::vector<uint32_t>{8, 8, 8, 8}));
    EXPECT_TRUE(job2.messages.empty());
  });
}

// A shader with a workgroup barrier runs invocation by invocation: its store past the end is reported by a call
// from the failing branch, with the invocation that made it.
TEST(OutOfBoundsCompiled, AStoreAfterABarrier) {
  testing::ComputeHarness h;
  ASSERT_TRUE(h.compile(kSpv_oob_barrier_comp)) << h.error;
  ASSERT_TRUE(h.shader->usesBarrier);
  h.setBuffer<uint32_t>(0, {5, 5, 5, 5});
  exec::Job job(nullptr, 0);
  h.job = &job;
  ASSERT_TRUE(h.run(2));
  EXPECT_EQ(h.get<uint32_t>(0), (std::vector<uint32_t>{5, 5, 5, 5}));
  std::vector<exec::OutOfBoundsRecord> sites = job.messages.outOfBoundsSites();
  ASSERT_EQ(sites.size(), 1u);
  spirv::AccessSiteInfo s = spirv::readAccessSite(sites[0].site);
  EXPECT_EQ(s.kind, abi::kAccessStore);
  EXPECT_EQ(sites[0].range, 16u);
  const uint32_t x = sites[0].id.v[0];
  EXPECT_LT(x, 8u);
  EXPECT_EQ(sites[0].offset, uint64_t(x + 100) * 4);
}

// The CTS's 64bit_compare shape (tests/shaders/oob_counted_loop.spvasm): a loop that tests i < 20 before it loads
// element i of two 20-double buffers. Every access is in bounds, so nothing is reported, on either path: the SPMD
// path runs the loop body's uniform loads once more with no lane active (i == 20), which must not be reported.
TEST(OutOfBoundsCompiled, ACountedLoopThatStopsAtTheEndReportsNothing) {
  const bool was = spirv::spmdEnabled();
  for (bool spmd : {false, true}) {
    SCOPED_TRACE(spmd ? "SPMD path" : "scalar path");
    spirv::setSpmd(spmd);
    testing::ComputeHarness h;
    ASSERT_TRUE(h.compile(kSpv_oob_counted_loop_spvasm)) << h.error;
    EXPECT_EQ(h.shader->spmdLanes != 0, spmd);
    std::vector<double> a(20), b(20);
    std::vector<int32_t> expected(20);
    for (int i = 0; i < 20; ++i) {
      a[i] = i;
      b[i] = i % 3 == 0 ? i : -i;
      expected[i] = a[i] != b[i];
    }
    h.setBuffer<double>(0, a);
    h.setBuffer<double>(1, b);
    h.zeroBuffer<int32_t>(2, 20);
    exec::Job job(nullptr, 0);
    h.job = &job;
    ASSERT_TRUE(h.run(1));
    EXPECT_EQ(h.get<int32_t>(2), expected);
    for (const exec::OutOfBoundsRecord& r : job.messages.outOfBoundsSites())
      ADD_FAILURE() << "reported: binding " << spirv::readAccessSite(r.site).binding << " offset " << r.offset
                    << " range " << r.range;
    EXPECT_TRUE(job.messages.empty());
    // The misuse side: inputs of 19 doubles, so the last pass with its lane active reads past them: reported.
    a.pop_back();
    b.pop_back();
    h.setBuffer<double>(0, a);
    h.setBuffer<double>(1, b);
    exec::Job job2(nullptr, 0);
    h.job = &job2;
    ASSERT_TRUE(h.run(1));
    std::vector<exec::OutOfBoundsRecord> sites = job2.messages.outOfBoundsSites();
    ASSERT_FALSE(sites.empty());  // vkrt_group's log keeps an invocation's first failing access only
    for (const exec::OutOfBoundsRecord& r : sites) {
      EXPECT_EQ(r.offset, 152u);
      EXPECT_EQ(r.range, 152u);
    }
  }
  spirv::setSpmd(was);
}

TEST(OutOfBoundsCompiled, InBoundsAccessesReportNothing) {
  onBothPaths([](bool spmd) {
    testing::ComputeHarness h;
    exec::Job job(nullptr, 0);
    ASSERT_NO_FATAL_FAILURE(dispatchWithPush(h, kSpv_oob_read_comp, spmd, 0, job));
    EXPECT_EQ(h.get<uint32_t>(1), (std::vector<uint32_t>{10, 11, 12, 13}));
    EXPECT_TRUE(job.messages.empty());
  });
}

// VKRT_SHADER_CHECKS: a shader compiled without the device address and image checks has nothing of them (its object
// code names no check function); with them, it calls them. Both shaders stay off the SPMD path, whose lanes these
// checks do not cover (docs/shader-debugging.md).
TEST(ShaderChecksCompiled, CompiledInOnlyOnRequest) {
  const bool spmdWas = spirv::spmdEnabled();
  const uint32_t checksWas = spirv::shaderChecks();
  spirv::setSpmd(true);
  for (uint32_t checks : {0u, uint32_t(abi::kCheckDeviceAddress | abi::kCheckImage)}) {
    SCOPED_TRACE("checks " + std::to_string(checks));
    spirv::setShaderChecks(checks);
    testing::ComputeHarness bda, image;
    ASSERT_TRUE(bda.compile(kSpv_check_bda_g_comp)) << bda.error;
    ASSERT_TRUE(image.compile(kSpv_check_image_g_comp)) << image.error;
    EXPECT_EQ(bda.shader->spmdLanes, 0);
    EXPECT_EQ(image.shader->spmdLanes, 0);
    auto calls = [](const testing::ComputeHarness& h, const char* fn) {
      return h.shader->cacheBlob.find(fn) != std::string::npos;
    };
    EXPECT_EQ(calls(bda, "vkrt_check_address"), checks != 0);
    EXPECT_EQ(calls(image, "vkrt_check_image"), checks != 0);
    EXPECT_EQ(calls(image, "vkrt_check_texel_buffer"), checks != 0);
    EXPECT_FALSE(calls(bda, "vkrt_check_image"));  // no image in it
  }
  spirv::setShaderChecks(checksWas);
  spirv::setSpmd(spmdWas);
}

}  // namespace
}  // namespace vkrt
