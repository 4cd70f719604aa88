// Vertex and fragment shaders compiled and run below the Vulkan API, with hand-made abi::GraphicsInvocation contexts
// (fragment quads through exec::runFiberGroup): the location layout, the built-ins, kill / terminate / demote and
// helper lanes, derivatives and quad operations, implicit-LOD sampling, the pipeline cache blob, and a quad's
// out-of-bounds reports.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

#include "exec/fiber_group.hpp"
#include "exec/shader_debug.hpp"
#include "exec/supervise.hpp"
#include "gfx_builtins.frag.spv.h"
#include "gfx_builtins.vert.spv.h"
#include "gfx_derivs.frag.spv.h"
#include "gfx_discard.frag.spv.h"
#include "gfx_grad.vert.spv.h"
#include "gfx_helper_builtin.g.frag.spv.h"
#include "gfx_helper_image.frag.spv.h"
#include "gfx_io.vert.spv.h"
#include "gfx_sample.frag.spv.h"
#include "gfx_sample_cube.frag.spv.h"
#include "gfx_sample_lanes.frag.spv.h"
#include "gfx_spmd_discard.frag.spv.h"
#include "oob_draw.frag.spv.h"
#include "oob_fragment.frag.spv.h"
#include "runtime/image.hpp"
#include "runtime/image_functions.hpp"
#include "runtime/image_view.hpp"
#include "runtime/sampler.hpp"
#include "spirv/compiler.hpp"
#include "spirv/runtime_images.hpp"
#include "spirv/shader_debug.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt::testing {
namespace {

using abi::GraphicsInvocation;
using abi::kGraphicsLocations;
using Location = spirv::GraphicsStageInfo::Location;

// `spmd`: fragment shaders compiled by the SPMD path (a quad in one call) where it supports them; off, the scalar
// vkrt_main the fibers run (what the tests that call graphicsEntry on one lane need).
template <size_t N>
std::shared_ptr<spirv::CompiledShader> compileStage(const uint32_t (&words)[N], spv::ExecutionModel model,
                                                    std::string* error, bool inlineFunctions = true,
                                                    bool spmd = false) {
  struct Setting {
    bool was = spirv::spmdEnabled();
    ~Setting() { spirv::setSpmd(was); }
  } setting;
  spirv::setSpmd(spmd);
  spirv::CompileRequest r;
  r.words = words;
  r.wordCount = N;
  r.model = model;
  r.inlineFunctions = inlineFunctions;
  r.hostSymbols = imageFunctionSymbols();
  return spirv::compile(r, error);
}

// One invocation's context and its location slots.
struct Lane {
  GraphicsInvocation inv{};
  alignas(16) uint32_t in[kGraphicsLocations * 4] = {};
  alignas(16) uint32_t out[kGraphicsLocations * 4] = {};
  alignas(16) uint32_t out1[4] = {};
  alignas(16) uint8_t push[abi::kPushConstantBytes] = {};
  alignas(16) uint8_t sink[abi::kSinkBytes] = {};

  Lane() {
    inv.inputs = in;
    inv.outputs = out;
    inv.outputs1 = out1;
    inv.base.pushConstants = push;
    inv.base.sink = sink;
    inv.sampleMaskOut = ~0u;
  }
  float outF(uint32_t location, uint32_t component) const {
    float f;
    std::memcpy(&f, &out[location * 4 + component], 4);
    return f;
  }
  int32_t outI(uint32_t location, uint32_t component) const { return int32_t(out[location * 4 + component]); }
  double outD(uint32_t location, uint32_t component) const {
    double d;
    std::memcpy(&d, &out[location * 4 + component], 8);
    return d;
  }
  void setF(uint32_t location, uint32_t component, float f) { std::memcpy(&in[location * 4 + component], &f, 4); }
  void setI(uint32_t location, uint32_t component, int32_t i) { in[location * 4 + component] = uint32_t(i); }
};

// A 2x2 quad at (x0, y0) (even): lane = x & 1 | (y & 1) << 1, run as a fiber group sharing the exchange area.
struct Quad {
  Lane lanes[4];
  alignas(16) uint8_t exchange[abi::kQuadExchangeBytes] = {};
  Quad(uint32_t x0, uint32_t y0) {
    for (uint32_t l = 0; l < 4; ++l) {
      GraphicsInvocation& g = lanes[l].inv;
      g.base.localIndex = l;
      g.base.workgroupMemory = exchange;
      g.fragCoord[0] = float(x0 + (l & 1)) + 0.5f;
      g.fragCoord[1] = float(y0 + (l >> 1)) + 0.5f;
      g.fragCoord[3] = 1.0f;
    }
  }
  bool run(const spirv::CompiledShader& s) {
    if (s.spmdLanes == 4) {
      // The SPMD entry takes the four invocations as an array and reads the inputs and writes the outputs as
      // structures of arrays through lane 0's pointers (word w of lane l at [w][l]): the lanes' slots gathered before
      // (the output words it leaves keep their values), the outputs scattered back after.
      GraphicsInvocation inv[4];
      for (int l = 0; l < 4; ++l) inv[l] = lanes[l].inv;
      alignas(16) uint32_t in[kGraphicsLocations * 4][4], out[kGraphicsLocations * 4][4], out1[4][4];
      for (uint32_t l = 0; l < 4; ++l) {
        for (uint32_t w = 0; w < kGraphicsLocations * 4; ++w) in[w][l] = lanes[l].in[w], out[w][l] = lanes[l].out[w];
        for (uint32_t w = 0; w < 4; ++w) out1[w][l] = lanes[l].out1[w];
      }
      inv[0].inputs = &in[0][0];
      inv[0].outputs = &out[0][0];
      inv[0].outputs1 = &out1[0][0];
      // FragCoord too (fragCoordSoa, every invocation's).
      alignas(16) float fragCoord[4][4];
      for (uint32_t l = 0; l < 4; ++l)
        for (uint32_t k = 0; k < 4; ++k) fragCoord[k][l] = lanes[l].inv.fragCoord[k];
      for (uint32_t l = 0; l < 4; ++l) inv[l].fragCoordSoa = &fragCoord[0][0];
      // The coverage, from which the entry takes its helper lanes (coverageSoa): a helper lane's is 0. As the
      // executor, the `helper` flags only for a shader with side effects (GraphicsInvocation::coverageSoa).
      alignas(16) uint32_t coverage[4];
      for (uint32_t l = 0; l < 4; ++l) {
        coverage[l] = lanes[l].inv.helper ? 0 : 1, inv[l].coverageSoa = coverage;
        if (!s.graphics.sideEffects) inv[l].helper = 0;
      }
      s.graphicsEntry(inv);
      for (uint32_t l = 0; l < 4; ++l) {
        for (uint32_t w = 0; w < kGraphicsLocations * 4; ++w) lanes[l].out[w] = out[w][l];
        for (uint32_t w = 0; w < 4; ++w) lanes[l].out1[w] = out1[w][l];
        inv[l].fragCoordSoa = nullptr;
        inv[l].coverageSoa = nullptr;
        inv[l].inputs = lanes[l].in;
        inv[l].outputs = lanes[l].out;
        inv[l].outputs1 = lanes[l].out1;
        if (!s.graphics.sideEffects) inv[l].helper = coverage[l] ? 0 : 1;  // as the test set it
        lanes[l].inv = inv[l];
      }
      return true;
    }
    abi::InvocationContext* ctx[4];
    for (int l = 0; l < 4; ++l) ctx[l] = &lanes[l].inv.base;
    return exec::runFiberGroup(reinterpret_cast<abi::ComputeEntry>(s.graphicsEntry), ctx, 4);
  }
};

const Location* findLocation(const std::vector<Location>& list, uint32_t location) {
  for (const Location& l : list)
    if (l.location == location) return &l;
  return nullptr;
}

TEST(GraphicsShader, VertexLocationsFollowTheLocationAssignmentRules) {
  std::string error;
  auto s = compileStage(kSpv_gfx_io_vert, spv::ExecutionModelVertex, &error);
  ASSERT_TRUE(s) << error;
  ASSERT_NE(s->graphicsEntry, nullptr);
  Lane lane;
  lane.setF(0, 0, 1.0f), lane.setF(0, 1, 2.0f), lane.setF(0, 2, 3.0f);
  lane.setI(1, 0, 4), lane.setI(1, 1, -5), lane.setF(1, 2, 6.5f);
  lane.setF(2, 0, 7.0f), lane.setF(2, 1, 8.0f), lane.setF(3, 0, 9.0f), lane.setF(3, 1, 10.0f);
  s->graphicsEntry(&lane.inv);
  // vec3 outArr[2] at 0, 1.
  EXPECT_EQ(lane.outF(0, 0), 1.0f);
  EXPECT_EQ(lane.outF(0, 2), 3.0f);
  EXPECT_EQ(lane.outF(1, 0), 11.0f);
  EXPECT_EQ(lane.outF(1, 2), 13.0f);
  EXPECT_EQ(lane.out[1 * 4 + 3], 0u);  // not declared: untouched
  // ivec2 at 2.xy, float at 2.z.
  EXPECT_EQ(lane.outI(2, 0), 12);
  EXPECT_EQ(lane.outI(2, 1), -15);
  EXPECT_EQ(lane.outF(2, 2), 7.0f);
  // mat3x2: a column a location.
  EXPECT_EQ(lane.outF(3, 0), 7.0f);
  EXPECT_EQ(lane.outF(3, 1), 8.0f);
  EXPECT_EQ(lane.outF(4, 0), 9.0f);
  EXPECT_EQ(lane.outF(4, 1), 10.0f);
  EXPECT_EQ(lane.outF(5, 0), 16.0f);
  EXPECT_EQ(lane.outF(5, 1), 18.0f);
  // struct: a member a location.
  EXPECT_EQ(lane.outF(6, 0), 10.0f);
  EXPECT_EQ(lane.outF(7, 0), 6.5f);
  EXPECT_EQ(lane.outF(7, 1), -6.5f);
  // dvec3: x, y fill location 8, z the first half of 9.
  EXPECT_EQ(lane.outD(8, 0), 2.0);
  EXPECT_EQ(lane.outD(8, 2), 4.0);
  EXPECT_EQ(lane.outD(9, 0), 6.0);
  // gl_PerVertex.
  EXPECT_EQ(lane.inv.position[0], 2.0f);
  EXPECT_EQ(lane.inv.position[2], 6.0f);
  EXPECT_EQ(lane.inv.position[3], 1.0f);
  EXPECT_EQ(lane.inv.pointSize, 3.0f);
  EXPECT_EQ(lane.inv.clipDistance[0], 1.0f);
  EXPECT_EQ(lane.inv.clipDistance[1], -1.0f);
  EXPECT_EQ(lane.inv.cullDistance[0], 0.25f);

  const spirv::GraphicsStageInfo& g = s->graphics;
  EXPECT_EQ(g.clipDistances, 2u);
  EXPECT_EQ(g.cullDistances, 1u);
  EXPECT_TRUE(g.writesPointSize);
  ASSERT_EQ(g.inputs.size(), 4u);
  EXPECT_EQ(g.inputs[0].componentMask, 0x7);
  EXPECT_EQ(g.inputs[1].componentMask, 0x7);
  EXPECT_TRUE(g.inputs[1].integer);
  EXPECT_EQ(g.inputs[3].componentMask, 0x3);
  ASSERT_EQ(g.outputs.size(), 10u);
  const uint8_t masks[10] = {0x7, 0x7, 0x7, 0x3, 0x3, 0x3, 0x1, 0x3, 0xF, 0x3};
  for (uint32_t l = 0; l < 10; ++l) {
    const Location* o = findLocation(g.outputs, l);
    ASSERT_NE(o, nullptr) << l;
    EXPECT_EQ(o->componentMask, masks[l]) << l;
    EXPECT_EQ(o->wide, l >= 8) << l;
  }
  EXPECT_TRUE(findLocation(g.outputs, 2)->integer);
  EXPECT_EQ(findLocation(g.outputs, 2)->interpolation, Location::Flat);
  EXPECT_FALSE(g.needsQuad);
}

TEST(GraphicsShader, VertexBuiltIns) {
  std::string error;
  auto s = compileStage(kSpv_gfx_builtins_vert, spv::ExecutionModelVertex, &error);
  ASSERT_TRUE(s) << error;
  Lane lane;
  lane.inv.vertexIndex = 17;
  lane.inv.instanceIndex = 3;
  lane.inv.baseVertex = -2;
  lane.inv.baseInstance = 1;
  lane.inv.drawIndex = 5;
  lane.inv.viewIndex = 1;
  s->graphicsEntry(&lane.inv);
  EXPECT_EQ(lane.outI(0, 0), 17);
  EXPECT_EQ(lane.outI(0, 1), 3);
  EXPECT_EQ(lane.outI(0, 2), -2);
  EXPECT_EQ(lane.outI(0, 3), 1);
  EXPECT_EQ(lane.outI(1, 0), 5);
  EXPECT_EQ(lane.outI(1, 1), 1);
  EXPECT_EQ(lane.outI(1, 2), 1);  // gl_SubgroupSize
  EXPECT_EQ(lane.inv.position[0], 17.0f);
  EXPECT_EQ(s->graphics.clipDistances, 0u);
  EXPECT_FALSE(s->graphics.writesPointSize);
}

TEST(GraphicsShader, FragmentBuiltInsAndInterpolationDecorations) {
  std::string error;
  auto s = compileStage(kSpv_gfx_builtins_frag, spv::ExecutionModelFragment, &error);
  ASSERT_TRUE(s) << error;
  Lane lane;
  GraphicsInvocation& g = lane.inv;
  const float coord[4] = {3.5f, 7.5f, 0.25f, 2.0f};
  std::memcpy(g.fragCoord, coord, 16);
  g.frontFacing = 1;
  g.primitiveId = 9;
  g.sampleId = 2;
  g.sampleMaskIn = 4;
  g.pointCoord[0] = 0.125f, g.pointCoord[1] = 0.875f;
  g.samplePosition[0] = 0.375f, g.samplePosition[1] = 0.625f;
  g.layer = 3;
  g.viewIndex = 1;
  g.fragDepth = coord[2];
  lane.setI(0, 0, 4);
  lane.setF(1, 0, 1.25f);
  lane.setF(1, 2, 0.5f);
  lane.setF(2, 3, 0.25f);
  s->graphicsEntry(&g);
  for (int c = 0; c < 4; ++c) EXPECT_EQ(lane.outF(0, c), coord[c]) << c;
  EXPECT_EQ(lane.outI(1, 0), 1);
  EXPECT_EQ(lane.outI(1, 1), 9);
  EXPECT_EQ(lane.outI(1, 2), 2);
  EXPECT_EQ(lane.outI(1, 3), 4);
  EXPECT_EQ(lane.outF(2, 0), 0.125f);
  EXPECT_EQ(lane.outF(2, 1), 0.875f);
  EXPECT_EQ(lane.outF(2, 2), 0.375f);
  EXPECT_EQ(lane.outF(2, 3), 0.625f);
  EXPECT_EQ(lane.out[3 * 4 + 0], 0u);  // not a helper
  EXPECT_EQ(lane.out[3 * 4 + 1], 3u);
  EXPECT_EQ(lane.out[3 * 4 + 2], 1u);
  EXPECT_EQ(lane.out[3 * 4 + 3], 4u + 2u);  // 4 + uint(1.25 + 0.5 + 0.25)
  EXPECT_EQ(g.fragDepth, 0.75f);
  EXPECT_EQ(g.sampleMaskOut, 5u);
  EXPECT_EQ(g.status, 0u);
  // A helper lane reads HelperInvocation.
  Lane helper;
  helper.inv.helper = 1;
  s->graphicsEntry(&helper.inv);
  EXPECT_EQ(helper.out[3 * 4 + 0], 1u);

  const spirv::GraphicsStageInfo& gi = s->graphics;
  EXPECT_TRUE(gi.writesDepth);
  EXPECT_TRUE(gi.writesSampleMask);
  EXPECT_TRUE(gi.readsSampleId);
  EXPECT_FALSE(gi.canDiscard);
  EXPECT_FALSE(gi.sideEffects);
  ASSERT_EQ(gi.inputs.size(), 3u);
  EXPECT_EQ(gi.inputs[0].interpolation, Location::Flat);
  EXPECT_TRUE(gi.inputs[0].integer);
  EXPECT_EQ(gi.inputs[1].componentMask, 0x7);
  EXPECT_EQ(gi.inputs[1].interpolation, Location::NoPerspective);
  EXPECT_TRUE(gi.inputs[1].centroid);
  EXPECT_FALSE(gi.inputs[1].sample);
  EXPECT_EQ(gi.inputs[2].interpolation, Location::Smooth);
  EXPECT_TRUE(gi.inputs[2].sample);
  ASSERT_EQ(gi.outputs.size(), 4u);
  EXPECT_TRUE(gi.outputs[1].integer);
  EXPECT_FALSE(gi.outputs[0].integer);
}

// Every fragment built-in on the SPMD path, each lane of the quad with its own values: each lane reads its own.
TEST(GraphicsShader, SpmdFragmentBuiltInsPerLane) {
  std::string error;
  auto s = compileStage(kSpv_gfx_builtins_frag, spv::ExecutionModelFragment, &error, true, true);
  ASSERT_TRUE(s) << error;
  ASSERT_EQ(s->spmdLanes, 4u);
  Quad q(0, 0);
  for (uint32_t l = 0; l < 4; ++l) {
    Lane& lane = q.lanes[l];
    GraphicsInvocation& g = lane.inv;
    const float coord[4] = {3.5f + float(l), 7.5f, 0.25f * float(l), 2.0f};
    std::memcpy(g.fragCoord, coord, 16);
    g.frontFacing = l & 1;
    g.primitiveId = int32_t(9 + l);
    g.sampleId = int32_t(l);
    g.sampleMaskIn = 4u << l;
    g.pointCoord[0] = 0.125f * float(l), g.pointCoord[1] = 0.875f;
    g.samplePosition[0] = 0.375f, g.samplePosition[1] = 0.0625f * float(l);
    g.layer = 3 + l;
    g.viewIndex = l;
    g.fragDepth = 0.5f;
    lane.setI(0, 0, int32_t(4 + l));
    lane.setF(1, 0, 1.25f * float(l));
    lane.setF(1, 2, 0.5f);
    lane.setF(2, 3, 0.25f);
  }
  ASSERT_TRUE(q.run(*s));
  for (uint32_t l = 0; l < 4; ++l) {
    SCOPED_TRACE("lane " + std::to_string(l));
    const Lane& lane = q.lanes[l];
    for (int c = 0; c < 4; ++c) EXPECT_EQ(lane.outF(0, c), lane.inv.fragCoord[c]) << c;
    EXPECT_EQ(lane.outI(1, 0), int32_t(l & 1));
    EXPECT_EQ(lane.outI(1, 1), int32_t(9 + l));
    EXPECT_EQ(lane.outI(1, 2), int32_t(l));
    EXPECT_EQ(lane.outI(1, 3), int32_t(4u << l));
    EXPECT_EQ(lane.outF(2, 0), 0.125f * float(l));
    EXPECT_EQ(lane.outF(2, 1), 0.875f);
    EXPECT_EQ(lane.outF(2, 2), 0.375f);
    EXPECT_EQ(lane.outF(2, 3), 0.0625f * float(l));
    EXPECT_EQ(lane.out[3 * 4 + 0], 0u);
    EXPECT_EQ(lane.out[3 * 4 + 1], 3u + l);
    EXPECT_EQ(lane.out[3 * 4 + 2], l);
    EXPECT_EQ(lane.out[3 * 4 + 3], 4u + l + uint32_t(1.25f * float(l) + 0.5f + 0.25f));
    EXPECT_EQ(lane.inv.fragDepth, 0.75f);
    EXPECT_EQ(lane.inv.sampleMaskOut, 5u);
    EXPECT_EQ(lane.inv.status, 0u);
  }
}

// Kill (in a called function), terminate, demote, and helper lanes whose buffer writes and atomics land nowhere.
void runDiscardCases(bool inlineFunctions) {
  std::string error;
  auto s = compileStage(kSpv_gfx_discard_frag, spv::ExecutionModelFragment, &error, inlineFunctions);
  ASSERT_TRUE(s) << error;
  EXPECT_TRUE(s->graphics.canDiscard);
  EXPECT_TRUE(s->graphics.sideEffects);
  EXPECT_FALSE(s->graphics.needsQuad);
  EXPECT_FALSE(s->graphics.readsFragCoord);  // gfx_discard.frag declares no FragCoord, PointCoord or SampleMask
  EXPECT_FALSE(s->graphics.readsPointCoord);
  EXPECT_FALSE(s->graphics.readsSampleMask);
  ASSERT_EQ(s->resources.size(), 1u);
  std::vector<uint32_t> buf(16, 0);
  abi::DescriptorRecord rec{};
  rec.address = reinterpret_cast<uint64_t>(buf.data());
  rec.range = buf.size() * 4;
  abi::ResourceSlot slot{&rec, 1};
  struct Case {
    int mode, slot;
    uint32_t helper;
    uint32_t status, helperAfter, stored;
    bool counted;
  };
  const Case cases[] = {
      {0, 0, 0, 0, 0, 5, true},                       // runs to its end
      {1, 1, 0, abi::kFragmentKilled, 0, 0, false},   // discard (OpKill) in a callee
      {2, 2, 0, abi::kFragmentKilled, 0, 0, false},   // terminateInvocation
      {3, 3, 0, abi::kFragmentDemoted, 1, 0, false},  // demote: goes on as a helper
      {0, 4, 1, 0, 1, 0, false},                      // a helper lane from the start
  };
  uint32_t count = 0;
  for (const Case& c : cases) {
    SCOPED_TRACE("mode " + std::to_string(c.mode) + " helper " + std::to_string(c.helper));
    Lane lane;
    lane.inv.base.resources = &slot;
    lane.inv.helper = c.helper;
    lane.setI(0, 0, c.mode);
    lane.setI(0, 1, c.slot);
    s->graphicsEntry(&lane.inv);
    EXPECT_EQ(lane.inv.status, c.status);
    EXPECT_EQ(lane.inv.helper, c.helperAfter);
    EXPECT_EQ(buf[c.slot], c.stored);
    count += c.counted;
    EXPECT_EQ(buf[8], count);
    if (c.status != abi::kFragmentKilled) {
      EXPECT_EQ(lane.outF(0, 0), 2.0f);
      EXPECT_EQ(lane.outF(0, 1), c.helperAfter ? 1.0f : 0.0f);  // helperInvocationEXT() after the demotion
    }
  }
}

TEST(GraphicsShader, DiscardTerminateDemoteAndHelperStores) { runDiscardCases(true); }
TEST(GraphicsShader, DiscardFromACalledFunction) { runDiscardCases(false); }

double fn(double x, double y) { return x * x + 3 * y * y + x * y; }

void runDerivativeCases(bool spmd) {
  std::string error;
  auto s = compileStage(kSpv_gfx_derivs_frag, spv::ExecutionModelFragment, &error, true, spmd);
  ASSERT_TRUE(s) << error;
  EXPECT_TRUE(s->graphics.needsQuad);
  EXPECT_EQ(s->spmdLanes, spmd ? 4u : 0u);
  const uint32_t x0 = 6, y0 = 10;
  Quad q(x0, y0);
  ASSERT_TRUE(q.run(*s));
  const double xs[2] = {x0 + 0.5, x0 + 1.5}, ys[2] = {y0 + 0.5, y0 + 1.5};
  for (uint32_t l = 0; l < 4; ++l) {
    SCOPED_TRACE("lane " + std::to_string(l));
    const Lane& lane = q.lanes[l];
    uint32_t i = l & 1, j = l >> 1;
    double fineX = fn(xs[1], ys[j]) - fn(xs[0], ys[j]);
    double fineY = fn(xs[i], ys[1]) - fn(xs[i], ys[0]);
    double coarseX = fn(xs[1], ys[0]) - fn(xs[0], ys[0]);
    double coarseY = fn(xs[0], ys[1]) - fn(xs[0], ys[0]);
    EXPECT_NEAR(lane.outF(0, 0), fineX, 1e-3);
    EXPECT_NEAR(lane.outF(0, 1), fineY, 1e-3);
    EXPECT_NEAR(lane.outF(0, 2), coarseX, 1e-3);
    EXPECT_NEAR(lane.outF(0, 3), coarseY, 1e-3);
    EXPECT_NEAR(lane.outF(1, 0), std::fabs(fineX) + std::fabs(fineY), 1e-3);
    EXPECT_NEAR(lane.outF(1, 1), std::fabs(coarseX) + std::fabs(coarseY), 1e-3);
    EXPECT_NEAR(lane.outF(1, 2), fineX, 1e-3);  // dFdx: vkrt's default is fine
    EXPECT_NEAR(lane.outF(1, 3), fineY, 1e-3);
    EXPECT_NEAR(lane.outF(2, 0), xs[1] * ys[j] - xs[0] * ys[j], 1e-3);
    EXPECT_EQ(lane.outF(2, 1), 0.0f);
    EXPECT_EQ(lane.outF(2, 2), float(xs[i ^ 1]));  // subgroupQuadSwapHorizontal(x)
    EXPECT_EQ(lane.outF(2, 3), float(ys[1]));      // subgroupQuadBroadcast(y, 2)
    EXPECT_EQ(lane.inv.status, 0u);
  }
  // A lane that was killed first no longer takes part: the others go through every exchange without it.
  Quad k(2, 4);
  for (Lane& lane : k.lanes) lane.setI(0, 0, 1);
  ASSERT_TRUE(k.run(*s));
  EXPECT_EQ(k.lanes[3].inv.status, abi::kFragmentKilled);
  const double kx[2] = {2.5, 3.5}, ky[2] = {4.5, 5.5};
  for (uint32_t l = 0; l < 3; ++l) {
    EXPECT_EQ(k.lanes[l].inv.status, 0u);
    EXPECT_NEAR(k.lanes[l].outF(0, 2), fn(kx[1], ky[0]) - fn(kx[0], ky[0]), 1e-3);  // coarse: lanes 0, 1, 2 only
    EXPECT_NEAR(k.lanes[l].outF(0, 3), fn(kx[0], ky[1]) - fn(kx[0], ky[0]), 1e-3);
  }
}

TEST(GraphicsShader, DerivativesFineAndCoarseAndQuadOperations) { runDerivativeCases(false); }
TEST(GraphicsShader, SpmdDerivativesFineAndCoarseAndQuadOperations) { runDerivativeCases(true); }

// The pipeline cache keeps the SPMD form: the loaded shader's graphicsEntry is the quad entry again.
TEST(GraphicsShader, SpmdFragmentShaderSurvivesThePipelineCache) {
  std::string error;
  auto s = compileStage(kSpv_gfx_derivs_frag, spv::ExecutionModelFragment, &error, true, true);
  ASSERT_TRUE(s) << error;
  ASSERT_EQ(s->spmdLanes, 4u);
  auto c = spirv::loadCached(s->cacheBlob, imageFunctionSymbols(), &error);
  ASSERT_TRUE(c) << error;
  EXPECT_EQ(c->spmdLanes, 4u);
  Quad q(6, 10);
  ASSERT_TRUE(q.run(*c));
  for (uint32_t l = 0; l < 4; ++l) {
    const double y = 10.5 + (l >> 1);
    EXPECT_NEAR(q.lanes[l].outF(0, 0), fn(7.5, y) - fn(6.5, y), 1e-3) << l;  // dFdxFine
  }
}

// Per-lane discard and demotion in one quad, a helper lane from the start: statuses, outputs, buffer stores (none
// from helpers), derivatives after a demotion (the demoted lane keeps computing them). The same expectations on the
// fiber path and the SPMD path.
void runQuadDiscardCases(bool spmd) {
  std::string error;
  auto s = compileStage(kSpv_gfx_spmd_discard_frag, spv::ExecutionModelFragment, &error, true, spmd);
  ASSERT_TRUE(s) << error;
  EXPECT_EQ(s->spmdLanes, spmd ? 4u : 0u);
  EXPECT_TRUE(s->graphics.needsQuad);
  EXPECT_TRUE(s->graphics.canDiscard);
  struct Case {
    int mode[4];
    uint32_t helper[4];
  };
  const uint32_t K = abi::kFragmentKilled, D = abi::kFragmentDemoted;
  for (const Case& c : {Case{{0, 0, 2, 0}, {0, 0, 0, 1}}, Case{{1, 0, 0, 2}, {0, 0, 0, 0}}}) {
    SCOPED_TRACE("modes " + std::to_string(c.mode[0]) + std::to_string(c.mode[1]) + std::to_string(c.mode[2]) +
                 std::to_string(c.mode[3]));
    std::vector<uint32_t> buf(4, 0);
    abi::DescriptorRecord rec{};
    rec.address = reinterpret_cast<uint64_t>(buf.data());
    rec.range = buf.size() * 4;
    abi::ResourceSlot slot{&rec, 1};
    const uint32_t x0 = 4, y0 = 8;
    Quad q(x0, y0);
    for (uint32_t l = 0; l < 4; ++l) {
      q.lanes[l].inv.base.resources = &slot;
      q.lanes[l].inv.helper = c.helper[l];
      q.lanes[l].setI(0, 0, c.mode[l]);
    }
    ASSERT_TRUE(q.run(*s));
    bool anyKilled = false;
    for (uint32_t l = 0; l < 4; ++l) anyKilled |= c.mode[l] == 1;
    for (uint32_t l = 0; l < 4; ++l) {
      SCOPED_TRACE("lane " + std::to_string(l));
      const Lane& lane = q.lanes[l];
      const bool killed = c.mode[l] == 1, demoted = c.mode[l] == 2, helper = demoted || c.helper[l];
      EXPECT_EQ(lane.inv.status, killed ? K : demoted ? D : 0u);
      EXPECT_EQ(buf[l], killed || helper ? 0u : 5u);  // helpers store nothing
      if (killed) continue;
      EXPECT_EQ(lane.outF(0, 0), 2.0f);
      EXPECT_EQ(lane.outF(0, 1), helper ? 1.0f : 0.0f);
      if (anyKilled) continue;  // derivatives next to a terminated lane are undefined
      const double x[2] = {x0 + 0.5, x0 + 1.5}, y[2] = {y0 + 0.5, y0 + 1.5};
      EXPECT_EQ(lane.outF(0, 2), float(x[1] * x[1] - x[0] * x[0]));  // dFdx(x * x): the same in both rows
      EXPECT_EQ(lane.outF(0, 3), float(x[0] * y[1] - x[0] * y[0]));  // dFdyCoarse(x * y): the left column
    }
  }
}

// HelperInvocation (the built-in variable, not helperInvocationEXT()) in a quad whose lane 1 is a helper from the
// start and whose lane 2 demotes itself: the covered lanes 0 and 3 see it through fine derivatives (before the
// demotion 0, 1, 0, 0 by lane; after it 0, 1, 1, 0). The same expectations on the fiber path and the SPMD path (whose
// helper lanes come from the quad's coverage, GraphicsInvocation::coverageSoa).
void runHelperBuiltIn(bool spmd) {
  std::string error;
  auto s = compileStage(kSpv_gfx_helper_builtin_g_frag, spv::ExecutionModelFragment, &error, true, spmd);
  ASSERT_TRUE(s) << error;
  EXPECT_EQ(s->spmdLanes, spmd ? 4u : 0u);
  Quad q(6, 2);
  q.lanes[1].inv.helper = 1;
  q.lanes[2].setI(0, 0, 1);
  ASSERT_TRUE(q.run(*s));
  EXPECT_EQ(q.lanes[2].inv.status, abi::kFragmentDemoted);
  const float expected[4][4] = {{1, 0, 1, 1}, {}, {}, {0, -1, -1, -1}};  // lanes 0 and 3
  for (uint32_t l : {0u, 3u}) {
    SCOPED_TRACE("lane " + std::to_string(l));
    EXPECT_EQ(q.lanes[l].inv.status, 0u);
    for (uint32_t c = 0; c < 4; ++c) EXPECT_EQ(q.lanes[l].outF(0, c), expected[l][c]) << c;
  }
}

TEST(GraphicsShader, HelperInvocationBuiltIn) { runHelperBuiltIn(false); }
TEST(GraphicsShader, SpmdHelperInvocationBuiltIn) { runHelperBuiltIn(true); }

TEST(GraphicsShader, QuadDiscardDemoteAndHelpers) { runQuadDiscardCases(false); }
TEST(GraphicsShader, SpmdQuadDiscardDemoteAndHelpers) { runQuadDiscardCases(true); }

// Out-of-bounds reports of a fragment quad (oob_fragment.frag: src[i] loaded, dst[i] = it + 1 stored, i = x + 2 y,
// flag[k] = 9 at a uniform k; buffers of the case's sizes): one report per site, naming the first lane (FragCoord)
// whose access is outside, its byte offset and the descriptor's range, as exec::ShaderMessages keeps them. Helper
// lanes (uncovered or demoted) store nothing and so report no store. The expectations are computed here, and the
// fiber path's and the SPMD path's reports and values compared with them and with each other.
struct OobReport {
  uint32_t kind, binding;
  float x, y;
  uint64_t offset, range;
  bool operator==(const OobReport&) const = default;
};
std::ostream& operator<<(std::ostream& o, const OobReport& r) {
  return o << (r.kind == abi::kAccessStore ? "store" : "load") << " binding " << r.binding << " at (" << r.x << ", "
           << r.y << ") offset " << r.offset << " range " << r.range;
}

struct OobCase {
  const char* name;
  uint32_t x0, y0;
  uint32_t helper[4];  // uncovered
  int mode[4];         // 2: demoted
  uint32_t words[3];   // src, dst, flag
  uint32_t k;
};

struct OobResult {
  std::vector<OobReport> reports;  // by binding
  std::vector<uint32_t> buffers[3];
  float color[4], dx[4];
  bool operator==(const OobResult&) const = default;
};

constexpr uint32_t kOobBacking = 16;  // words behind every buffer, whatever its range: a store outside is dropped

OobResult runOobCase(const spirv::CompiledShader& s, const OobCase& c) {
  OobResult r;
  abi::DescriptorRecord recs[3] = {};
  for (uint32_t b = 0; b < 3; ++b) {
    r.buffers[b].assign(kOobBacking, 0);
    if (b == 0)
      for (uint32_t w = 0; w < kOobBacking; ++w) r.buffers[0][w] = 100 + w;
    recs[b].address = reinterpret_cast<uint64_t>(r.buffers[b].data());
    recs[b].range = c.words[b] * 4;
  }
  std::vector<abi::ResourceSlot> slots(s.resources.size());  // in the compiler's order of the resources
  for (size_t i = 0; i < s.resources.size(); ++i) {
    EXPECT_LT(s.resources[i].binding, 3u);
    slots[i] = {&recs[s.resources[i].binding % 3], 1};
  }
  Quad q(c.x0, c.y0);
  for (uint32_t l = 0; l < 4; ++l) {
    q.lanes[l].inv.base.resources = slots.data();
    q.lanes[l].inv.helper = c.helper[l];
    q.lanes[l].setI(0, 0, c.mode[l]);
    std::memcpy(q.lanes[l].push, &c.k, 4);
  }
  struct Task {
    Quad* q;
    const spirv::CompiledShader* s;
    bool ok = false;
  } task{&q, &s};
  exec::Job job(nullptr, 0);
  EXPECT_TRUE(exec::runSupervised(
      job, [](void* a) { static_cast<Task*>(a)->ok = static_cast<Task*>(a)->q->run(*static_cast<Task*>(a)->s); },
      &task));
  EXPECT_TRUE(task.ok) << "abort kind " << int(job.abort().kind) << " signal " << job.abort().signal << " address "
                       << job.abort().address;
  for (const exec::OutOfBoundsRecord& rec : job.messages.outOfBoundsSites()) {
    spirv::AccessSiteInfo site = spirv::readAccessSite(rec.site);
    EXPECT_EQ(site.model, uint32_t(spv::ExecutionModelFragment));
    EXPECT_EQ(site.bytes, 4u);
    EXPECT_EQ(site.set, 0u);
    OobReport o{site.kind, site.binding, 0, 0, rec.offset, rec.range};
    std::memcpy(&o.x, &rec.id.v[0], 4);
    std::memcpy(&o.y, &rec.id.v[1], 4);
    r.reports.push_back(o);
  }
  std::sort(r.reports.begin(), r.reports.end(),
            [](const OobReport& a, const OobReport& b) { return a.binding < b.binding; });
  for (uint32_t l = 0; l < 4; ++l) r.color[l] = q.lanes[l].outF(0, 0), r.dx[l] = q.lanes[l].outF(0, 1);
  return r;
}

// What the shader does, lane by lane in lane order (the first failing lane is the reported one).
OobResult expectedOob(const OobCase& c) {
  OobResult r;
  for (uint32_t b = 0; b < 3; ++b) r.buffers[b].assign(kOobBacking, 0);
  for (uint32_t w = 0; w < kOobBacking; ++w) r.buffers[0][w] = 100 + w;
  bool reported[3] = {};
  auto report = [&](uint32_t kind, uint32_t binding, uint32_t l, uint32_t index) {
    if (reported[binding]) return;
    reported[binding] = true;
    r.reports.push_back({kind, binding, float(c.x0 + (l & 1)) + 0.5f, float(c.y0 + (l >> 1)) + 0.5f,
                         uint64_t(index) * 4, uint64_t(c.words[binding]) * 4});
  };
  for (uint32_t l = 0; l < 4; ++l) {
    const uint32_t i = c.x0 + (l & 1) + 2 * (c.y0 + (l >> 1));
    const bool helper = c.helper[l] || c.mode[l] == 2;
    const uint32_t v = i < c.words[0] ? 100 + i : 0;  // robust load: zero outside
    r.color[l] = float(v);
    if (i >= c.words[0]) report(abi::kAccessLoad, 0, l, i);  // a helper lane's load happens (its derivative)
    if (helper) continue;
    if (i < c.words[1])
      r.buffers[1][i] = v + 1;
    else
      report(abi::kAccessStore, 1, l, i);
    if (c.k < c.words[2])
      r.buffers[2][c.k] = 9;
    else
      report(abi::kAccessStore, 2, l, c.k);
  }
  for (uint32_t l = 0; l < 4; ++l) r.dx[l] = r.color[l | 1] - r.color[l & 2];
  std::sort(r.reports.begin(), r.reports.end(),
            [](const OobReport& a, const OobReport& b) { return a.binding < b.binding; });
  return r;
}

TEST(GraphicsShader, FragmentOutOfBoundsReportsOnBothPaths) {
  std::string error;
  auto fiber = compileStage(kSpv_oob_fragment_frag, spv::ExecutionModelFragment, &error, true, false);
  ASSERT_TRUE(fiber) << error;
  auto spmd = compileStage(kSpv_oob_fragment_frag, spv::ExecutionModelFragment, &error, true, true);
  ASSERT_TRUE(spmd) << error;
  ASSERT_EQ(fiber->spmdLanes, 0u);
  ASSERT_EQ(spmd->spmdLanes, 4u);
  ASSERT_TRUE(fiber->graphics.needsQuad && spmd->graphics.needsQuad);  // every lane runs, helpers too
  // The shader of ShaderDebugDrawTest.FragmentStoreOutOfBoundsNamesTheFragment takes the SPMD path too.
  auto drawShader = compileStage(kSpv_oob_draw_frag, spv::ExecutionModelFragment, &error, true, true);
  ASSERT_TRUE(drawShader) << error;
  EXPECT_EQ(drawShader->spmdLanes, 4u);
  const OobCase cases[] = {
      {"in bounds", 0, 0, {0, 0, 0, 0}, {0, 0, 0, 0}, {8, 8, 4}, 1},
      {"lower row outside", 0, 2, {0, 0, 0, 0}, {0, 0, 0, 0}, {6, 6, 4}, 4},
      {"lanes 1 to 3 outside", 2, 2, {0, 0, 0, 0}, {0, 0, 0, 0}, {7, 7, 8}, 7},
      {"uncovered helpers 0 and 2", 0, 2, {1, 0, 1, 0}, {0, 0, 0, 0}, {8, 6, 4}, 5},
      {"demoted lanes 0 and 3", 0, 2, {0, 0, 0, 0}, {2, 0, 0, 2}, {8, 5, 4}, 2},
      {"only helpers outside", 0, 2, {0, 0, 1, 1}, {0, 0, 0, 0}, {8, 6, 4}, 0},
      {"helper lane 0, uniform store outside", 0, 0, {1, 0, 0, 0}, {0, 0, 0, 0}, {8, 8, 4}, 6},
      {"helper lane 0, uniform store inside", 0, 0, {1, 0, 0, 0}, {0, 0, 0, 0}, {8, 8, 4}, 3},
      {"demoted lane 0, uniform store outside", 0, 0, {0, 0, 0, 0}, {2, 0, 0, 0}, {8, 8, 4}, 4},
      {"every lane a helper", 0, 2, {1, 0, 1, 0}, {0, 2, 0, 2}, {4, 4, 4}, 9},
  };
  for (const OobCase& c : cases) {
    SCOPED_TRACE(c.name);
    const OobResult want = expectedOob(c);
    const OobResult a = runOobCase(*fiber, c), b = runOobCase(*spmd, c);
    EXPECT_EQ(a.reports, want.reports) << "fiber path";
    EXPECT_EQ(b.reports, want.reports) << "SPMD path";
    EXPECT_EQ(b.reports, a.reports);
    for (uint32_t buf = 1; buf < 3; ++buf) {
      EXPECT_EQ(a.buffers[buf], want.buffers[buf]) << "fiber path, binding " << buf;
      EXPECT_EQ(b.buffers[buf], want.buffers[buf]) << "SPMD path, binding " << buf;
    }
    for (uint32_t l = 0; l < 4; ++l) {
      EXPECT_EQ(a.color[l], want.color[l]) << "fiber path, lane " << l;
      EXPECT_EQ(b.color[l], want.color[l]) << "SPMD path, lane " << l;
      EXPECT_EQ(a.dx[l], want.dx[l]) << "fiber path, lane " << l;
      EXPECT_EQ(b.dx[l], want.dx[l]) << "SPMD path, lane " << l;
    }
  }
}

// PixelCenterInteger is not allowed in Vulkan (glslc's validator refuses it too): gfx_builtins.frag with its
// OriginUpperLeft execution mode turned into PixelCenterInteger.
TEST(GraphicsShader, RefusesPixelCenterInteger) {
  std::vector<uint32_t> words(std::begin(kSpv_gfx_builtins_frag), std::end(kSpv_gfx_builtins_frag));
  bool patched = false;
  for (size_t at = 5; at < words.size(); at += words[at] >> 16) {
    if ((words[at] & 0xffff) == spv::OpExecutionMode && words[at + 2] == spv::ExecutionModeOriginUpperLeft) {
      words[at + 2] = spv::ExecutionModePixelCenterInteger;
      patched = true;
    }
    if ((words[at] >> 16) == 0) break;
  }
  ASSERT_TRUE(patched);
  spirv::CompileRequest r;
  r.words = words.data();
  r.wordCount = words.size();
  r.model = spv::ExecutionModelFragment;
  r.hostSymbols = imageFunctionSymbols();
  std::string error;
  EXPECT_FALSE(spirv::compile(r, &error));
  EXPECT_NE(error.find("PixelCenterInteger"), std::string::npos) << error;
}

TEST(GraphicsShader, CacheBlobRoundTripOfAFragmentShader) {
  std::string error;
  auto s = compileStage(kSpv_gfx_builtins_frag, spv::ExecutionModelFragment, &error);
  ASSERT_TRUE(s) << error;
  auto c = spirv::loadCached(s->cacheBlob, imageFunctionSymbols(), &error);
  ASSERT_TRUE(c) << error;
  ASSERT_NE(c->graphicsEntry, nullptr);
  EXPECT_EQ(c->rayEntry, nullptr);
  EXPECT_EQ(c->model, spv::ExecutionModelFragment);
  const spirv::GraphicsStageInfo &a = s->graphics, &b = c->graphics;
  EXPECT_EQ(a.writesDepth, b.writesDepth);
  EXPECT_EQ(a.writesSampleMask, b.writesSampleMask);
  EXPECT_EQ(a.readsSampleId, b.readsSampleId);
  EXPECT_TRUE(a.readsFragCoord);  // gfx_builtins.frag reads FragCoord, PointCoord and SampleMask
  EXPECT_EQ(a.readsFragCoord, b.readsFragCoord);
  EXPECT_TRUE(a.readsPointCoord);
  EXPECT_EQ(a.readsPointCoord, b.readsPointCoord);
  EXPECT_TRUE(a.readsSampleMask);
  EXPECT_EQ(a.readsSampleMask, b.readsSampleMask);
  ASSERT_EQ(a.inputs.size(), b.inputs.size());
  for (size_t i = 0; i < a.inputs.size(); ++i) {
    EXPECT_EQ(a.inputs[i].location, b.inputs[i].location);
    EXPECT_EQ(a.inputs[i].componentMask, b.inputs[i].componentMask);
    EXPECT_EQ(a.inputs[i].interpolation, b.inputs[i].interpolation);
    EXPECT_EQ(a.inputs[i].centroid, b.inputs[i].centroid);
    EXPECT_EQ(a.inputs[i].sample, b.inputs[i].sample);
    EXPECT_EQ(a.inputs[i].integer, b.inputs[i].integer);
  }
  ASSERT_EQ(a.outputs.size(), b.outputs.size());
  Lane lane;
  lane.inv.primitiveId = 42;
  c->graphicsEntry(&lane.inv);
  EXPECT_EQ(lane.outI(1, 1), 42);
  EXPECT_EQ(lane.inv.fragDepth, 0.75f);
}

// Implicit-LOD sampling: a 64 x 64 R32_SFLOAT image whose mip m holds m everywhere, sampled at uv = fragCoord * k /
// 64 (derivatives k / 64 a pixel: rho = k, lambda = log2 k, "Level-of-Detail Operation"), with a nearest mipmap mode
// (level ceil(lambda + 0.5) - 1, "Image Level(s) Selection").
constexpr uint32_t kSize = 64, kLevels = 7;

class GraphicsShaderSampling : public ::testing::Test {
 protected:
  virtual bool cube() const { return false; }  // a cube (6 layers, every face alike) instead of a 2D image
  // BC7_UNORM instead of R32_SFLOAT: level m's texels are solid BC7 blocks of R = bc7Level(m) (levelValue).
  virtual bool bc7() const { return false; }
  // The value texels of level m read as: m, or 10 m / 255 for BC7 (a mode 6 block of endpoints 10 m).
  float levelValue(float m) const { return bc7() ? float(10 * int(m)) / 255.0f : m; }
  void SetUp() override {
    ASSERT_NO_FATAL_FAILURE(vkrt::testing::createPlainDevice(&instance, &device));
    VkImageCreateInfo ci{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    ci.imageType = VK_IMAGE_TYPE_2D;
    ci.format = bc7() ? VK_FORMAT_BC7_UNORM_BLOCK : VK_FORMAT_R32_SFLOAT;
    ci.extent = {kSize, kSize, 1};
    ci.mipLevels = kLevels;
    ci.arrayLayers = cube() ? 6 : 1;
    ci.flags = cube() ? VK_IMAGE_CREATE_CUBE_COMPATIBLE_BIT : 0;
    ci.samples = VK_SAMPLE_COUNT_1_BIT;
    ci.usage = VK_IMAGE_USAGE_SAMPLED_BIT | (bc7() ? 0 : VK_IMAGE_USAGE_STORAGE_BIT);
    ASSERT_EQ(vkrt_CreateImage(device, &ci, nullptr, &image), VK_SUCCESS);
    VkMemoryRequirements req;
    vkrt_GetImageMemoryRequirements(device, image, &req);
    VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    mai.allocationSize = req.size;
    ASSERT_EQ(vkrt_AllocateMemory(device, &mai, nullptr, &memory), VK_SUCCESS);
    ASSERT_EQ(vkrt_BindImageMemory(device, image, memory, 0), VK_SUCCESS);
    VkImageViewCreateInfo vi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    vi.image = image;
    vi.viewType = cube() ? VK_IMAGE_VIEW_TYPE_CUBE : VK_IMAGE_VIEW_TYPE_2D;
    vi.format = ci.format;
    vi.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, kLevels, 0, ci.arrayLayers};
    ASSERT_EQ(vkrt_CreateImageView(device, &vi, nullptr, &view), VK_SUCCESS);
    Image* img = fromHandle<Image>(image);
    for (uint32_t m = 0; m < kLevels; ++m) {
      uint32_t size = kSize >> m;
      float value = float(m);
      // A BC7 mode 6 block (mode bit 6) of both endpoints (5 m << 1 | 0, 0, 0, 127 << 1 | 0), all indices 0.
      uint8_t block[16] = {0x40};
      for (uint32_t bit = 0; bit < 14; ++bit)
        if ((5 * m >> (bit % 7)) & 1) block[(7 + bit) / 8] |= uint8_t(1u << ((7 + bit) % 8));  // R0, R1
      for (uint32_t bit = 49; bit < 63; ++bit) block[bit / 8] |= uint8_t(1u << (bit % 8));     // A0, A1 = 127
      const uint32_t n = bc7() ? (size + 3) / 4 : size;
      for (uint32_t l = 0; l < ci.arrayLayers; ++l)
        for (uint32_t y = 0; y < n; ++y)
          for (uint32_t x = 0; x < n; ++x)
            if (bc7())
              std::memcpy(img->texel(m, l, x, y, 0), block, 16);
            else
              std::memcpy(img->texel(m, l, x, y, 0), &value, 4);
    }
    VkSamplerCreateInfo si{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
    si.magFilter = si.minFilter = VK_FILTER_NEAREST;
    si.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
    si.addressModeU = si.addressModeV = si.addressModeW = VK_SAMPLER_ADDRESS_MODE_REPEAT;
    si.maxLod = 16.0f;
    ASSERT_EQ(vkrt_CreateSampler(device, &si, nullptr, &sampler), VK_SUCCESS);
    sampledRecord.object = static_cast<const Object*>(fromHandle<ImageView>(view));
    sampledRecord.sampler = static_cast<const Object*>(fromHandle<Sampler>(sampler));
  }
  void TearDown() override {
    vkrt_DestroySampler(device, sampler, nullptr);
    vkrt_DestroyImageView(device, view, nullptr);
    vkrt_DestroyImage(device, image, nullptr);
    vkrt_FreeMemory(device, memory, nullptr);
    vkrt_DestroyDevice(device, nullptr);
    vkrt_DestroyInstance(instance, nullptr);
  }
  VkInstance instance = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkImage image = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;
  VkSampler sampler = VK_NULL_HANDLE;
  // The view and sampler as one combined image sampler descriptor, the shaders' only resource.
  abi::DescriptorRecord sampledRecord{};
  abi::ResourceSlot sampledSlot{&sampledRecord, 1};
  void implicitLod(bool spmd);
  void coarseLod(bool spmd);
  void samplingByTheLanesLeft(bool spmd);
};

float expectedLevel(double lambda) {
  double d = std::clamp(lambda, 0.0, double(kLevels - 1));
  return float(std::ceil(d + 0.5) - 1.0);
}

TEST_F(GraphicsShaderSampling, ImplicitLodSamplingPicksTheMipOfTheDerivatives) { implicitLod(false); }
TEST_F(GraphicsShaderSampling, SpmdImplicitLodSamplingPicksTheMipOfTheDerivatives) { implicitLod(true); }

void GraphicsShaderSampling::implicitLod(bool spmd) {
  std::string error;
  auto s = compileStage(kSpv_gfx_sample_frag, spv::ExecutionModelFragment, &error, true, spmd);
  ASSERT_TRUE(s) << error;
  EXPECT_TRUE(s->graphics.needsQuad);
  EXPECT_EQ(s->spmdLanes, spmd ? 4u : 0u);
  for (double k : {1.0, 3.0, 4.0, 32.0, 0.5}) {
    SCOPED_TRACE("k = " + std::to_string(k));
    Quad q(8, 12);
    for (Lane& lane : q.lanes) {
      lane.inv.base.resources = &sampledSlot;
      lane.setF(0, 0, float(lane.inv.fragCoord[0] * k / kSize));
      lane.setF(0, 1, float(lane.inv.fragCoord[1] * k / kSize));
    }
    ASSERT_TRUE(q.run(*s));
    double lambda = std::log2(k);
    for (const Lane& lane : q.lanes) {
      EXPECT_EQ(lane.outF(0, 0), levelValue(expectedLevel(lambda)));
      EXPECT_EQ(lane.outF(1, 0), levelValue(expectedLevel(lambda + 1.0)));             // texture(tex, uv, 1.0)
      EXPECT_EQ(lane.outF(2, 0), levelValue(expectedLevel(std::log2(kSize / 16.0))));  // textureGrad: 1/16 a pixel
    }
  }
}

// Implicit LOD takes the quad's coarse derivatives (the top row's and the left column's differences, the same in
// the four lanes), on both paths: here they ask for level 0 (one texel a pixel along u in the top row, nothing along
// v), while the bottom row's fine ones would ask for level 3 (eight texels a pixel) in lanes 2 and 3 and the right
// column's for level 3 in lane 1 (seven).
void GraphicsShaderSampling::coarseLod(bool spmd) {
  std::string error;
  auto s = compileStage(kSpv_gfx_sample_frag, spv::ExecutionModelFragment, &error, true, spmd);
  ASSERT_TRUE(s) << error;
  EXPECT_EQ(s->spmdLanes, spmd ? 4u : 0u);
  const double u[4] = {0.25, 0.25 + 1.0 / kSize, 0.25, 0.25 + 8.0 / kSize};
  Quad q(8, 12);
  for (uint32_t l = 0; l < 4; ++l) {
    q.lanes[l].inv.base.resources = &sampledSlot;
    q.lanes[l].setF(0, 0, float(u[l]));
    q.lanes[l].setF(0, 1, 0.5f);
  }
  ASSERT_TRUE(q.run(*s));
  // The coarse scale factors in double: rho_x from lanes 1 - 0, rho_y from lanes 2 - 0.
  const double rho = std::max(std::fabs(u[1] - u[0]), std::fabs(u[2] - u[0])) * kSize;
  const double lambda = std::log2(rho);
  for (uint32_t l = 0; l < 4; ++l) {
    EXPECT_EQ(q.lanes[l].outF(0, 0), levelValue(expectedLevel(lambda))) << "lane " << l;
    EXPECT_EQ(q.lanes[l].outF(1, 0), levelValue(expectedLevel(lambda + 1.0))) << "lane " << l;  // Bias 1
  }
}

TEST_F(GraphicsShaderSampling, ImplicitLodTakesTheQuadsCoarseDerivatives) { coarseLod(false); }
TEST_F(GraphicsShaderSampling, SpmdImplicitLodTakesTheQuadsCoarseDerivatives) { coarseLod(true); }

// The same on a BC7 image: the quad's implicit-LOD and gradient sampling (SPMD and fiber paths) reads compressed
// views through the general path (the sampler's fast path refuses them) and decodes the level's blocks.
class GraphicsShaderBc7Sampling : public GraphicsShaderSampling {
 protected:
  bool bc7() const override { return true; }
};

TEST_F(GraphicsShaderBc7Sampling, ImplicitLodSamplingDecodesTheLevelsBlocks) { implicitLod(false); }
TEST_F(GraphicsShaderBc7Sampling, SpmdImplicitLodSamplingDecodesTheLevelsBlocks) { implicitLod(true); }

// Grad sampling after a discard ended some lanes: the SPMD path samples the lanes left in one call
// (vkrt_image_sample_grad_quad with the active lanes as a bit mask), each with its own gradient, so lane l's level is
// its own (log2(64 g)). The same on the fiber path.
void GraphicsShaderSampling::samplingByTheLanesLeft(bool spmd) {
  std::string error;
  auto s = compileStage(kSpv_gfx_sample_lanes_frag, spv::ExecutionModelFragment, &error, true, spmd);
  ASSERT_TRUE(s) << error;
  EXPECT_EQ(s->spmdLanes, spmd ? 4u : 0u);
  for (uint32_t leaving : {0x0u, 0x2u, 0x3u, 0x8u, 0xeu}) {
    SCOPED_TRACE("leaving lanes " + std::to_string(leaving));
    Quad q(8, 12);
    for (uint32_t l = 0; l < 4; ++l) {
      Lane& lane = q.lanes[l];
      lane.inv.base.resources = &sampledSlot;
      lane.setF(0, 0, 0.25f + 0.125f * float(l));
      lane.setF(0, 1, 0.5f);
      lane.setF(1, 0, std::ldexp(1.0f, int(l) - 6));  // level l
      lane.setI(2, 0, int32_t(leaving >> l & 1));
    }
    ASSERT_TRUE(q.run(*s));
    for (uint32_t l = 0; l < 4; ++l) {
      if (leaving >> l & 1)
        EXPECT_EQ(q.lanes[l].inv.status, abi::kFragmentKilled) << "lane " << l;  // its outputs do not count
      else
        EXPECT_EQ(q.lanes[l].outF(0, 0), float(l)) << "lane " << l;
    }
  }
}

TEST_F(GraphicsShaderSampling, QuadSamplingByTheLanesLeft) { samplingByTheLanesLeft(false); }
TEST_F(GraphicsShaderSampling, SpmdQuadSamplingByTheLanesLeft) { samplingByTheLanesLeft(true); }

// The same on a cube's +X face: the direction's derivatives projected on the face ("Cube Map Derivation") give the
// same levels (directions stay on +X: uv <= 1, so k <= 4 at this quad).
class GraphicsShaderCubeSampling : public GraphicsShaderSampling {
 protected:
  bool cube() const override { return true; }
};

TEST_F(GraphicsShaderCubeSampling, ImplicitLodSamplingOfACubeFollowsTheFacesDerivatives) {
  std::string error;
  auto s = compileStage(kSpv_gfx_sample_cube_frag, spv::ExecutionModelFragment, &error);
  ASSERT_TRUE(s) << error;
  EXPECT_TRUE(s->graphics.needsQuad);
  for (double k : {0.5, 1.0, 3.0, 4.0}) {
    SCOPED_TRACE("k = " + std::to_string(k));
    Quad q(8, 12);
    for (Lane& lane : q.lanes) {
      lane.inv.base.resources = &sampledSlot;
      lane.setF(0, 0, float(lane.inv.fragCoord[0] * k / kSize));
      lane.setF(0, 1, float(lane.inv.fragCoord[1] * k / kSize));
    }
    ASSERT_TRUE(q.run(*s));
    const double lambda = std::log2(k);
    for (const Lane& lane : q.lanes) {
      EXPECT_EQ(lane.outF(0, 0), expectedLevel(lambda));
      EXPECT_EQ(lane.outF(1, 0), expectedLevel(lambda + 1.0));             // texture(tex, d, 1.0)
      EXPECT_EQ(lane.outF(2, 0), expectedLevel(std::log2(kSize / 16.0)));  // textureGrad: 1/16 of the face a pixel
    }
  }
}

TEST_F(GraphicsShaderSampling, GradSamplingInAVertexShader) {
  std::string error;
  auto s = compileStage(kSpv_gfx_grad_vert, spv::ExecutionModelVertex, &error);
  ASSERT_TRUE(s) << error;
  EXPECT_FALSE(s->graphics.needsQuad);
  Lane lane;
  lane.inv.base.resources = &sampledSlot;
  s->graphicsEntry(&lane.inv);
  EXPECT_EQ(lane.outF(0, 0), expectedLevel(std::log2(4.0)));
  EXPECT_EQ(lane.outF(0, 1), 5.0f);
}

// Level 0 of the image, written at each lane's fragment coordinate: not by the helper lane.
TEST_F(GraphicsShaderSampling, HelperLanesWriteNoImage) {
  std::string error;
  auto s = compileStage(kSpv_gfx_helper_image_frag, spv::ExecutionModelFragment, &error);
  ASSERT_TRUE(s) << error;
  EXPECT_TRUE(s->graphics.sideEffects);
  EXPECT_FALSE(s->graphics.needsQuad);
  abi::DescriptorRecord rec{};
  rec.object = static_cast<const Object*>(fromHandle<ImageView>(view));
  abi::ResourceSlot slot{&rec, 1};
  Quad q(4, 6);
  q.lanes[3].inv.helper = 1;
  for (Lane& lane : q.lanes) {
    lane.inv.base.resources = &slot;
    s->graphicsEntry(&lane.inv);
  }
  Image* img = fromHandle<Image>(image);
  for (uint32_t l = 0; l < 4; ++l) {
    uint32_t x = 4 + (l & 1), y = 6 + (l >> 1);
    float v;
    std::memcpy(&v, img->texel(0, 0, x, y, 0), 4);
    EXPECT_EQ(v, l == 3 ? 0.0f : float(x + 0.5) + 100.0f * float(y + 0.5)) << l;
  }
}

}  // namespace
}  // namespace vkrt::testing
