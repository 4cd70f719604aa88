// Storage image loads and stores on the SPMD path (src/spirv/spmd.cpp, imageAccess), below the Vulkan API:
// tests/shaders/spmd_storage_images.comp run over vkrt image views with SPMD on and with the scalar path (VKRT_SPMD=0,
// the reference), both against texels and results computed here. The shader reads and writes R8G8B8A8_UNORM, R32_UINT,
// R32G32B32A32_SFLOAT and R32G32_SINT images (texels the lanes address themselves: consecutive ones with one vector
// access, scattered ones with gathers and scatters) and a 2D array image (the lanes' runtime calls), inside and
// outside the images, under divergent control flow.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "compute_formatless_image.comp.spv.h"
#include "compute_grad_aniso.comp.spv.h"
#include "compute_image_robustness.comp.spv.h"
#include "compute_sample.comp.spv.h"
#include "compute_storage_image.comp.spv.h"
#include "runtime/buffer.hpp"
#include "spirv/compute_harness.hpp"
#include "spirv/runtime_images.hpp"
#include "spmd_convergence.comp.spv.h"
#include "spmd_storage_images.comp.spv.h"

namespace vkrt::testing {
namespace {

constexpr int kW = 40, kH = 5;          // the images
constexpr int kGridW = 64, kGridH = 8;  // the invocations: 4 x 4 workgroups of 16 x 2
constexpr uint32_t kOut = 7;            // results per invocation

uint32_t fbits(float f) {
  uint32_t u;
  std::memcpy(&u, &f, 4);
  return u;
}

bool inside(int x, int y) { return x >= 0 && y >= 0 && x < kW && y < kH; }

// Byte k of R8G8B8A8 texel (x, y) of the source and destination images' initial contents.
uint8_t srcByte(int x, int y, int k) { return uint8_t(((y * kW + x) * 4 + k) * 37 + 11); }
uint8_t dstByte(int x, int y, int k) { return uint8_t(((y * kW + x) * 4 + k) * 53 + 5); }

// The destination's texels (push constants): NaN, -0, values outside [0, 1], ties of the rounding.
struct Values {
  float v[8][4];
};
Values edgeValues() {
  const float nan = std::nanf("");
  const float tie = 254.5f / 255;
  return {{{nan, -0.0f, -1.0f, 2.0f},
           {0.5f, 0.5f / 255, 1.0f / 255, 1.0f},
           {std::nextafter(tie, 0.0f), tie, std::nextafter(tie, 1.0f), 0.0f},
           {3.5f / 255, 4.5f / 255, 5.5f / 255, 6.5f / 255},
           {1e-30f, -1e-30f, 0.999f, 1.001f},
           {-nan, 0.3f, 0.7f, 0.05f},
           {0.123f, 0.456f, 0.789f, 0.321f},
           {0.25f, 0.75f, 0.1f, 0.9f}}};
}

// "Conversion from Floating-Point to Normalized Fixed-Point": NaN 0, clamped to [0, 1], times 255 (vkrt: in float),
// one of the two nearest integers (vkrt: the nearest, ties to even).
uint8_t unorm8(float f) { return uint8_t(std::nearbyint((std::isnan(f) ? 0.0f : std::clamp(f, 0.0f, 1.0f)) * 255.0f)); }

struct Images {
  std::vector<uint8_t> src8, dst8, ids, wide, pairs, layers;  // tightly packed rows (layers: both layers)
};

Images initial(bool bgra) {
  Images m;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const uint32_t t = uint32_t(y * kW + x);
      for (int k = 0; k < 4; ++k) m.src8.push_back(srcByte(x, y, bgra && k != 3 ? 2 - k : k));
      for (int k = 0; k < 4; ++k) m.dst8.push_back(dstByte(x, y, k));
      auto word = [](std::vector<uint8_t>& v, uint32_t w) {
        v.insert(v.end(), {uint8_t(w), uint8_t(w >> 8), uint8_t(w >> 16), uint8_t(w >> 24)});
      };
      word(m.ids, t * 2654435761u);
      for (int k = 0; k < 4; ++k) word(m.wide, fbits(float(t * 4 + k) * 0.37f - 3.0f));
      word(m.pairs, uint32_t(int32_t(t) * 7919 - 40000));
      word(m.pairs, uint32_t(-int32_t(t)));
    }
  for (int l = 0; l < 2; ++l)
    for (int t = 0; t < kW * kH; ++t) {
      const uint32_t w = fbits(l ? float(t) * 1.5f : -1.0f);
      m.layers.insert(m.layers.end(), {uint8_t(w), uint8_t(w >> 8), uint8_t(w >> 16), uint8_t(w >> 24)});
    }
  return m;
}

uint32_t wordAt(const std::vector<uint8_t>& v, size_t i) {
  uint32_t w;
  std::memcpy(&w, v.data() + i * 4, 4);
  return w;
}
void setWord(std::vector<uint8_t>& v, size_t i, uint32_t w) { std::memcpy(v.data() + i * 4, &w, 4); }

// What the shader leaves: its results and the images' texels (from `in`, the images' initial contents as stored;
// `bgra`: the source view is B8G8R8A8).
void expected(const Images& in, bool bgra, const Values& vals, std::vector<uint32_t>* out, Images* after) {
  *after = in;
  out->assign(size_t(kGridW) * kGridH * kOut * 4, 0);
  for (int gy = 0; gy < kGridH; ++gy)
    for (int gx = 0; gx < kGridW; ++gx) {
      const uint32_t i = uint32_t(gy * kGridW + gx);
      const int px = gx - 2, py = gy - 1, qx = (gx * 7) % 64 - 4, qy = gy - 1;
      const bool inP = inside(px, py), inQ = inside(qx, qy);
      const size_t tp = size_t(py * kW + px), tq = size_t(qy * kW + qx);
      uint32_t* o = out->data() + size_t(i) * kOut * 4;
      auto src = [&](uint32_t* r, size_t t) {
        for (int k = 0; k < 4; ++k) r[k] = fbits(float(in.src8[t * 4 + (bgra && k != 3 ? 2 - k : k)]) / 255.0f);
      };
      if (inP) src(o, tp);
      if (inQ) src(o + 4, tq);
      if (inP)
        for (int k = 0; k < 4; ++k) o[8 + k] = fbits(float(in.dst8[tp * 4 + k]) / 255.0f);
      if (inQ) o[12] = wordAt(in.ids, tq), o[15] = 1;
      if (inQ)
        for (int k = 0; k < 4; ++k) o[16 + k] = wordAt(in.wide, tq * 4 + k);
      if (inP) o[20] = wordAt(in.pairs, tp * 2), o[21] = wordAt(in.pairs, tp * 2 + 1), o[23] = 1;
      if (inP) o[24] = wordAt(in.layers, size_t(kW * kH) + tp), o[27] = fbits(1.0f);
      if (inP && gx % 3 != 1)
        for (int k = 0; k < 4; ++k) after->dst8[tp * 4 + k] = unorm8(vals.v[i % 8][k]);
      if (inQ && gx % 2 == 0) setWord(after->ids, tq, 1000 + i);
      if (inQ && gx % 2 == 1) {
        const float w[4] = {float(i), -float(i), float(i) * 0.5f, 1.0f / float(i + 1)};
        for (int k = 0; k < 4; ++k) setWord(after->wide, tq * 4 + k, fbits(w[k]));
      }
      if (inP && gy != 3) setWord(after->pairs, tp * 2, i), setWord(after->pairs, tp * 2 + 1, uint32_t(-int32_t(i)));
      if (inP) setWord(after->layers, size_t(kW * kH) + tp, fbits(float(i) * 0.25f));
    }
}

class SpmdImages : public RuntimeImages {
 protected:
  struct Bound {
    ImageView *src8, *dst8, *ids, *wide, *pairs, *layers;
  };
  // The shader's images holding `m`; `bgra`: the source view B8G8R8A8_UNORM; `wideUint`: the wide view
  // R32G32B32A32_UINT. (Either is a view other than the format the shader declares: a mismatch the validation layer
  // would report, possible below the API, where the SPMD code leaves the texels to the runtime's calls.)
  Bound bind(ComputeHarness& h, const Images& m, bool bgra, bool wideUint) {
    Bound v;
    v.src8 = makeImage(bgra ? VK_FORMAT_B8G8R8A8_UNORM : VK_FORMAT_R8G8B8A8_UNORM, kW, kH);
    v.dst8 = makeImage(VK_FORMAT_R8G8B8A8_UNORM, kW, kH);
    v.ids = makeImage(VK_FORMAT_R32_UINT, kW, kH);
    v.wide = makeImage(wideUint ? VK_FORMAT_R32G32B32A32_UINT : VK_FORMAT_R32G32B32A32_SFLOAT, kW, kH);
    v.pairs = makeImage(VK_FORMAT_R32G32_SINT, kW, kH);
    v.layers = makeImage(VK_FORMAT_R32_SFLOAT, kW, kH, 2);
    setTexels(v.src8, 0, m.src8, kW * 4);
    setTexels(v.dst8, 0, m.dst8, kW * 4);
    setTexels(v.ids, 0, m.ids, kW * 4);
    setTexels(v.wide, 0, m.wide, kW * 16);
    setTexels(v.pairs, 0, m.pairs, kW * 8);
    for (uint32_t l = 0; l < 2; ++l)
      setTexels(v.layers, l,
                std::vector<uint8_t>(m.layers.begin() + l * kW * kH * 4, m.layers.begin() + (l + 1) * kW * kH * 4),
                kW * 4);
    const ImageView* all[6] = {v.src8, v.dst8, v.ids, v.wide, v.pairs, v.layers};
    for (uint32_t b = 0; b < 6; ++b) h.images[b] = static_cast<const Object*>(all[b]);
    return v;
  }
  Images read(const Bound& v) {
    Images m;
    m.src8 = texelsOf(v.src8, 0, kW * 4);
    m.dst8 = texelsOf(v.dst8, 0, kW * 4);
    m.ids = texelsOf(v.ids, 0, kW * 4);
    m.wide = texelsOf(v.wide, 0, kW * 16);
    m.pairs = texelsOf(v.pairs, 0, kW * 8);
    m.layers = texelsOf(v.layers, 0, kW * 4);
    std::vector<uint8_t> l1 = texelsOf(v.layers, 1, kW * 4);
    m.layers.insert(m.layers.end(), l1.begin(), l1.end());
    return m;
  }
  // Runs the shader with SPMD on or off over fresh images; checks it against `expected`.
  void runRound(bool spmd, bool bgra, bool wideUint) {
    SCOPED_TRACE(std::string(spmd ? "SPMD" : "scalar") + (bgra ? ", B8G8R8A8 source" : "") +
                 (wideUint ? ", R32G32B32A32_UINT wide view" : ""));
    SpmdSetting setting(spmd);
    ComputeHarness h;
    ASSERT_TRUE(h.compile(kSpv_spmd_storage_images_comp)) << h.error;
    // The SPMD compile must really take the SPMD path.
    EXPECT_EQ(h.shader->spmdLanes, spmd ? spirv::spmdLanes() : 0u);
    if (spmd) EXPECT_NE(h.shader->spmdLanes, 0u);
    const Values vals = edgeValues();
    std::memcpy(h.push, &vals, sizeof vals);
    const Images in = initial(bgra);
    Bound v = bind(h, in, bgra, wideUint);
    h.setBuffer(6, std::vector<uint32_t>(size_t(kGridW) * kGridH * kOut * 4, 0xdeadbeefu));
    ASSERT_TRUE(h.run(kGridW / 16, kGridH / 2));
    std::vector<uint32_t> want;
    Images after;
    expected(in, bgra, vals, &want, &after);
    const std::vector<uint32_t> got = h.get<uint32_t>(6);
    for (size_t i = 0; i < want.size(); ++i)
      ASSERT_EQ(got[i], want[i]) << "invocation " << i / (kOut * 4) << " result " << (i / 4) % kOut << " component "
                                 << i % 4;
    const Images now = read(v);
    EXPECT_EQ(now.src8, after.src8);
    EXPECT_EQ(now.dst8, after.dst8);
    EXPECT_EQ(now.ids, after.ids);
    EXPECT_EQ(now.wide, after.wide);
    EXPECT_EQ(now.pairs, after.pairs);
    EXPECT_EQ(now.layers, after.layers);
  }
};

TEST_F(SpmdImages, LoadsAndStoresMatchTheScalarPathAndTheFormats) {
  for (bool spmd : {true, false}) runRound(spmd, false, false);
}

// Views of formats other than the declared ones: a B8G8R8A8 view where the shader declares rgba8 is read inline in its
// byte order (its bytes as B, G, R, A, as the runtime converts them); for the R32G32B32A32_UINT view where it declares
// rgba32f the SPMD code finds the view's kind different and calls the runtime lane by lane.
TEST_F(SpmdImages, AViewOfAnotherFormatTakesTheRuntimesCalls) {
  for (bool spmd : {true, false}) runRound(spmd, true, true);
}

// A record whose object is no image view (here a buffer, as a buffer descriptor bound where the shader declares a
// storage image would give) or no object at all: its address is never read as an image's texels, even where it
// points at texels of the declared kind. Reads give zeros and writes change nothing, on both paths.
TEST_F(SpmdImages, ARecordOfAnotherTypeIsNeverReadAsTexels) {
  VkBufferCreateInfo bi{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bi.size = 256;
  bi.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  VkBuffer buffer = VK_NULL_HANDLE;
  ASSERT_EQ(vkrt_CreateBuffer(device, &bi, nullptr, &buffer), VK_SUCCESS);
  for (bool spmd : {true, false}) {
    SCOPED_TRACE(spmd ? "SPMD" : "scalar");
    SpmdSetting setting(spmd);
    ComputeHarness h;
    ASSERT_TRUE(h.compile(kSpv_spmd_storage_images_comp)) << h.error;
    const Values vals = edgeValues();
    std::memcpy(h.push, &vals, sizeof vals);
    const Images in = initial(false);
    bind(h, in, false, false);
    // Texels the records' addresses point at, of the kinds the shader declares for bindings 0 to 2.
    std::vector<uint32_t> canary(size_t(kW) * kH * 4, 0x5a5a5a5au);
    const std::vector<uint32_t> before = canary;
    auto fake = [&](uint32_t kind, uint32_t bytes) {
      abi::ImageTexels t{};
      t.base = reinterpret_cast<uint8_t*>(canary.data());
      t.rowPitch = uint64_t(kW) * bytes;
      t.width = kW;
      t.height = kH;
      t.kind = kind;
      t.texelBytes = bytes;
      return t;
    };
    const abi::ImageTexels colorTexels = fake(abi::kTexelsUnorm8, 4), idTexels = fake(1 | abi::kTexelsInteger, 4);
    for (uint32_t b = 0; b < 3; ++b) {
      h.images.erase(b);
      abi::DescriptorRecord r{};
      r.address = reinterpret_cast<uint64_t>(b == 2 ? &idTexels : &colorTexels);
      r.object = b == 1 ? nullptr : static_cast<const Object*>(fromHandle<Buffer>(buffer));
      h.givenRecords[b] = r;
    }
    h.setBuffer(6, std::vector<uint32_t>(size_t(kGridW) * kGridH * kOut * 4, 0xdeadbeefu));
    ASSERT_TRUE(h.run(kGridW / 16, kGridH / 2));
    EXPECT_EQ(canary, before);
    const std::vector<uint32_t> got = h.get<uint32_t>(6);
    for (size_t i = 0; i < size_t(kGridW) * kGridH; ++i)
      for (uint32_t r = 0; r < 4; ++r)  // src8 at p and q, dst8, ids
        for (uint32_t k = 0; k < 4; ++k) ASSERT_EQ(got[(i * kOut + r) * 4 + k], 0u) << i << " " << r << " " << k;
  }
  vkrt_DestroyBuffer(device, buffer, nullptr);
}

// A compute ray tracer as the public samples write one (tests/shaders/spmd_convergence.comp): loops over a buffer of
// spheres around divergent selections, uniform structs passed to inlined functions, a function returning from inside
// its loop, constants returned under a varying condition, a normalize of varying and uniform components, an image
// size query. It takes the SPMD path (it took the
// scalar path before: the loop counters were taken as varying) and writes what the scalar path writes; the sum over
// every sphere, the image size and, where no two candidates are close, the nearest sphere are checked against values
// computed here.
class SpmdConvergence : public RuntimeImages {};

TEST_F(SpmdConvergence, ConvergentLoopsAndInlinedReturns) {
  struct Sphere {
    float sphere[4];
    float color[3];
    float shine;
    int32_t id, kind, pad[2];
  };
  static_assert(sizeof(Sphere) == 48, "std430: vec4, vec3 + float, two ints, padded to 16");
  std::vector<Sphere> spheres;
  for (int k = 0; k < 6; ++k) {
    Sphere s{};
    s.sphere[0] = float(k % 3) * 1.5f - 1.5f;
    s.sphere[1] = float(k / 3) * 1.2f - 0.6f;
    s.sphere[2] = 2.0f + float(k) * 0.7f;
    s.sphere[3] = 0.55f + 0.1f * float(k);
    s.color[0] = 0.1f * float(k + 1), s.color[1] = 0.5f, s.color[2] = 1.0f - 0.1f * float(k);
    s.shine = 0.25f * float(k + 1);
    s.id = 10 + k;
    s.kind = k + 1;
    spheres.push_back(s);
  }
  constexpr uint32_t kW = 64, kH = 8;
  std::array<std::vector<float>, 2> results;
  for (bool spmd : {false, true}) {
    SCOPED_TRACE(spmd ? "SPMD" : "scalar");
    SpmdSetting setting(spmd);
    ComputeHarness h;
    ASSERT_TRUE(h.compile(kSpv_spmd_convergence_comp)) << h.error;
    EXPECT_EQ(h.shader->spmdLanes, spirv::spmdLanes());
    if (spmd) ASSERT_NE(h.shader->spmdLanes, 0u) << "the shader did not take the SPMD path";
    h.setBuffer(0, spheres);
    h.setBuffer(1, std::vector<float>(kW * kH * 16, -7.0f));
    h.images[2] = static_cast<const Object*>(makeImage(VK_FORMAT_R32_SFLOAT, kW, kH));
    ASSERT_TRUE(h.run(kW / 16, kH / 4));
    results[spmd] = h.get<float>(1);
  }
  ASSERT_EQ(std::memcmp(results[0].data(), results[1].data(), results[0].size() * 4), 0)
      << "the SPMD path wrote other bytes than the scalar path";
  const std::vector<float>& o = results[1];
  size_t checked = 0, hits = 0, blocked = 0;
  for (uint32_t y = 0; y < kH; ++y)
    for (uint32_t x = 0; x < kW; ++x) {
      const float* r = &o[(y * kW + x) * 16];
      SCOPED_TRACE(std::to_string(x) + "," + std::to_string(y));
      EXPECT_EQ(r[7], 21.0f) << "every sphere's kind, summed";
      hits += r[8] >= 10.0f;
      blocked += r[9] >= 10.0f;
      EXPECT_EQ(r[10], float(kW));
      EXPECT_EQ(r[11], float(kH));
      EXPECT_EQ(r[12], x % 3 == 0 ? 1.0f : 2.0f);
      EXPECT_EQ(r[13], y < 4 ? 1.0f : 2.0f);
      // The nearest sphere, in double, where it is clear (no grazing ray, no two hits within 1e-3).
      double d[3] = {(double(x) - 32.0) / 96.0, (double(y) - 4.0) / 24.0, 1.0};
      const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      for (double& c : d) c /= len;
      double best = 1e30, second = 1e30;
      int id = -1;
      bool clear = true;
      for (const Sphere& s : spheres) {
        const double oc[3] = {-s.sphere[0], -s.sphere[1], -6.0 - s.sphere[2]};
        const double b = oc[0] * d[0] + oc[1] * d[1] + oc[2] * d[2];
        const double h = b * b - (oc[0] * oc[0] + oc[1] * oc[1] + oc[2] * oc[2] - double(s.sphere[3]) * s.sphere[3]);
        if (std::abs(h) < 1e-3) clear = false;
        if (h < 0) continue;
        const double t = -b - std::sqrt(h);
        if (t > 0 && t < best)
          second = best, best = t, id = s.id;
        else if (t > 0 && t < second)
          second = t;
      }
      if (!clear || (second < 1e30 && second - best < 1e-3)) continue;
      EXPECT_EQ(r[8], float(id));
      ++checked;
    }
  EXPECT_GT(checked, kW * kH / 2);
  // Rays hit spheres and some hits' shadow rays meet another sphere (firstBlocker's return from its loop).
  EXPECT_GT(hits, kW * kH / 8);
  EXPECT_GT(blocked, 0u);
  EXPECT_LT(blocked, hits);
}

// The compute shaders of the end-to-end image tests that sample with an explicit level of detail, fetch texels, read
// and write storage images and texel buffers take the SPMD path (their images uniform): those tests then check the
// SPMD path's results against values computed on the CPU (and with VKRT_SPMD=0, the scalar path's).
TEST(SpmdCoverage, ComputeImageShadersTakeTheSpmdPath) {
  SpmdSetting on(true);
  struct Shader {
    const char* name;
    const uint32_t* words;
    size_t count;
  };
#define VKRT_SHADER(n) \
  { #n, kSpv_##n##_comp, sizeof kSpv_##n##_comp / 4 }
  // (compute_cube gathers, compute_dref samples with Proj, compute_texel_buffers takes texel pointers for atomics:
  // those stay on the scalar path.)
  const Shader shaders[] = {VKRT_SHADER(compute_sample), VKRT_SHADER(compute_image_robustness),
                            VKRT_SHADER(compute_storage_image), VKRT_SHADER(compute_formatless_image),
                            VKRT_SHADER(compute_grad_aniso)};
#undef VKRT_SHADER
  for (const Shader& sh : shaders) {
    spirv::CompileRequest r;
    r.words = sh.words;
    r.wordCount = sh.count;
    r.hostSymbols = imageFunctionSymbols();
    std::string error;
    std::shared_ptr<spirv::CompiledShader> shader = spirv::compile(r, &error);
    ASSERT_NE(shader, nullptr) << sh.name << ": " << error;
    EXPECT_EQ(shader->spmdLanes, spirv::spmdLanes()) << sh.name;
  }
}

}  // namespace
}  // namespace vkrt::testing
