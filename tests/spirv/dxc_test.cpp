// A module in the shape DXC emits for an HLSL compute shader (tests/shaders/dxc_compute.spvasm: SPIR-V 1.0,
// Uniform + BufferBlock storage buffers, byte-address buffers, a cbuffer, signed indices, bitcasts, a
// vector select, an image size query, a wrapper entry point calling src.main with a pointer), below the API.
// The image is left unbound here: its size reads as 0 x 0 (tests/e2e binds a real one).
#include <gtest/gtest.h>

#include "dxc_compute.spvasm.spv.h"
#include "spirv/compute_harness.hpp"
#include "spirv/dxc_reference.hpp"

namespace vkrt::testing {
namespace {

TEST(SpirvDxc, HlslComputeShape) {
  for (bool inl : {true, false}) {
    SCOPED_TRACE(inl ? "functions inlined" : "src.main called");
    ComputeHarness h;
    spirv::CompileRequest r;
    r.words = kSpv_dxc_compute_spvasm;
    r.wordCount = sizeof kSpv_dxc_compute_spvasm / 4;
    r.inlineFunctions = inl;
    r.hostSymbols = imageFunctionSymbols();
    h.shader = spirv::compile(r, &h.error);
    ASSERT_NE(h.shader, nullptr) << h.error;
    EXPECT_EQ(h.shader->localSize[0], 8u);
    for (const spirv::ResourceBinding& rb : h.shader->resources)
      EXPECT_EQ(rb.uniform, rb.binding == 0) << "binding " << rb.binding << ": only the cbuffer is a uniform buffer";
    DxcParams p = dxcParams();
    std::vector<uint32_t> raw = dxcRaw();
    h.setBuffer(0, std::vector<DxcParams>{p});
    h.setBuffer(1, std::vector<float>(kDxcVectors * 4, -7.0f));
    h.setBuffer(2, raw);
    h.setBuffer(4, std::vector<uint32_t>(kDxcVectors * 2, 0xdeadbeefu));
    ASSERT_TRUE(h.run(kDxcInvocations / 8));
    std::vector<float> wantOut;
    std::vector<uint32_t> wantDst;
    const uint32_t dims[2] = {0, 0};
    dxcExpected(p, raw, dims, -7.0f, 0xdeadbeefu, &wantOut, &wantDst);
    expectDxc(h.get<float>(1).data(), h.get<uint32_t>(4).data(), wantOut, wantDst);
  }
}

}  // namespace
}  // namespace vkrt::testing
