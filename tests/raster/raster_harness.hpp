// Test harness for raster::draw(): surfaces in std::vector, C++ functions as shaders (a vertex stage reading
// positions and attributes from arrays, a fragment stage writing a constant, an input or a per-pixel counter).
#pragma once

#include <array>
#include <cstring>
#include <vector>

#include "raster/raster.hpp"

namespace vkrt::raster::test {

using Vec4 = std::array<float, 4>;

// Screen-space barycentrics of (px, py) in a triangle given in framebuffer coordinates (double, independent of
// the rasterizer's fixed point).
inline void bary(const double* x, const double* y, double px, double py, double b[3]) {
  const double area = (x[1] - x[0]) * (y[2] - y[0]) - (y[1] - y[0]) * (x[2] - x[0]);
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3, k = (i + 2) % 3;
    b[i] = ((x[k] - x[j]) * (py - y[j]) - (y[k] - y[j]) * (px - x[j])) / area;
  }
}

// Texel codecs: RGBA32F (float kind), RGBA8 UNorm, R32 UInt.
inline void decodeF32(const void*, const uint8_t* t, uint32_t out[4]) { std::memcpy(out, t, 16); }
inline void encodeF32(const void*, const uint32_t in[4], uint8_t* t) { std::memcpy(t, in, 16); }
inline void decodeU8(const void*, const uint8_t* t, uint32_t out[4]) {
  for (int c = 0; c < 4; ++c) {
    const float f = t[c] / 255.0f;
    std::memcpy(&out[c], &f, 4);
  }
}
inline void encodeU8(const void*, const uint32_t in[4], uint8_t* t) {
  for (int c = 0; c < 4; ++c) {
    float f;
    std::memcpy(&f, &in[c], 4);
    f = f < 0 ? 0 : f > 1 ? 1 : f;
    t[c] = uint8_t(f * 255.0f + 0.5f);
  }
}
inline void decodeU32(const void*, const uint8_t* t, uint32_t out[4]) {
  std::memcpy(out, t, 4);
  out[1] = out[2] = 0;
  out[3] = 1;
}
inline void encodeU32(const void*, const uint32_t in[4], uint8_t* t) { std::memcpy(t, in, 4); }

struct Image {
  uint32_t width = 0, height = 0, samples = 1, layers = 1, texelBytes = 4;
  std::vector<uint8_t> data;
  Image() = default;
  Image(uint32_t w, uint32_t h, uint32_t bytes, uint32_t s = 1, uint32_t l = 1)
      : width(w), height(h), samples(s), layers(l), texelBytes(bytes), data(size_t(w) * h * s * l * bytes) {}
  Surface surface() {
    Surface s;
    s.base = data.data();
    s.rowPitch = size_t(width) * samples * texelBytes;
    s.layerPitch = s.rowPitch * height;
    s.width = width, s.height = height, s.layers = layers, s.samples = samples;
    return s;
  }
  uint8_t* at(uint32_t x, uint32_t y, uint32_t s = 0, uint32_t l = 0) {
    return data.data() + ((size_t(l) * height + y) * width * samples + size_t(x) * samples + s) * texelBytes;
  }
  float f(uint32_t x, uint32_t y, uint32_t c = 0, uint32_t s = 0, uint32_t l = 0) {
    float v;
    std::memcpy(&v, at(x, y, s, l) + c * 4, 4);
    return v;
  }
  void fillF(const Vec4& v) {
    for (size_t i = 0; i < data.size(); i += 16) std::memcpy(&data[i], v.data(), 16);
  }
};

enum class FragMode { Constant, Input0, PointCoord, Facing };

// A draw over a width x height framebuffer with viewport = framebuffer, RGBA32F color 0 unless changed.
struct Harness {
  uint32_t width, height;
  Image color;
  Target target;
  State state;
  Draw draw;
  VertexStage vs;
  FragmentStage fs;
  // Vertices: framebuffer-space helpers fill clip positions; attributes per input slot.
  std::vector<Vec4> pos;
  std::vector<std::vector<Vec4>> attr;  // attr[slot][vertex]
  std::vector<float> pointSize;
  std::vector<std::vector<float>> clipDist;  // clipDist[i][vertex]
  FragMode mode = FragMode::Constant;
  uint32_t inputSlot = 0;  // the slot FragMode::Input0 writes out
  Vec4 constant = {1, 1, 1, 1};
  Vec4 constant1 = {0, 0, 0, 0};  // the dual-source output
  uint32_t samples;
  bool fragDepthFromInput = false;   // FragDepth = input 0's x
  float alpha0 = -1;                 // >= 0: color 0's alpha
  bool killAll = false;              // every lane discards (after writing its outputs)
  std::vector<uint32_t> helperRuns;  // pixels (y * width + x) of helper lanes the shader ran
  std::vector<float> helperValues;   // their input 0's x
  std::vector<uint32_t> primIds;     // per pixel: the last primitive ID, ~0 when none

  explicit Harness(uint32_t w = 64, uint32_t h = 64, uint32_t samples_ = 1)
      : width(w), height(h), color(w, h, 16, samples_), samples(samples_), primIds(size_t(w) * h, ~0u) {
    target.colorCount = 1;
    target.color[0] = color.surface();
    target.colorFormat[0].kind = ColorFormat::Kind::Float;
    target.colorFormat[0].texelBytes = 16;
    target.colorFormat[0].decode = decodeF32;
    target.colorFormat[0].encode = encodeF32;
    target.renderArea = Rect{0, 0, w, h};
    target.samples = samples_;
    state.samples = samples_;
    state.viewports[0] = Viewport{0, 0, float(w), float(h), 0, 1};
    state.scissors[0] = Rect{0, 0, w, h};
    vs.user = this;
    vs.shade = &Harness::vertexShader;
    fs.user = this;
    fs.shade = &Harness::fragmentShader;
    fs.outputMask = 1;
  }

  // A vertex at framebuffer position (x, y), depth z, clip w.
  void vertex(float x, float y, float z = 0.5f, float w = 1.0f) {
    pos.push_back(Vec4{(2 * x / width - 1) * w, (2 * y / height - 1) * w, z * w, w});
  }
  void addInput(Interpolation mode, std::vector<Vec4> values, bool centroid = false) {
    FragmentInput& in = fs.inputs[fs.inputCount++];
    in.location = uint8_t(fs.inputCount - 1);
    in.interpolation = mode;
    in.centroid = centroid;
    attr.push_back(std::move(values));
  }

  void run(uint32_t count = 0) {
    target.color[0] = color.surface();
    draw.count = count ? count : uint32_t(pos.size());
    draw.varyingCount = fs.inputCount;
    raster::draw(target, state, draw, vs, fs);
  }

  static void vertexShader(void* user, uint32_t, uint32_t, const uint32_t* index, uint32_t count, ShadedVertex* out,
                           unsigned) {
    auto& h = *static_cast<Harness*>(user);
    for (uint32_t i = 0; i < count; ++i) {
      const uint32_t v = index[i] < h.pos.size() ? index[i] : 0;
      std::memcpy(out[i].position, h.pos[v].data(), 16);
      if (!h.pointSize.empty()) out[i].pointSize = h.pointSize[v];
      for (size_t d = 0; d < h.clipDist.size(); ++d) out[i].clipDistance[d] = h.clipDist[d][v];
      for (size_t s = 0; s < h.attr.size(); ++s) std::memcpy(out[i].varyings + s * 4, h.attr[s][v].data(), 16);
    }
  }

  static void fragmentShader(void* user, FragmentQuad& q, unsigned) {
    auto& h = *static_cast<Harness*>(user);
    for (uint32_t l = 0; l < 4; ++l) {
      const uint32_t x = uint32_t(q.x) + (l & 1), y = uint32_t(q.y) + (l >> 1);
      if (!q.coverage[l]) {
        // A helper lane: the shader runs it only when it needs helpers (tests use one tile, one thread).
        if (h.fs.needsHelpers) {
          h.helperRuns.push_back(y * h.width + x);
          float v = 0;
          if (h.fs.inputCount) std::memcpy(&v, &q.inputs[0][l], 4);
          h.helperValues.push_back(v);
        }
        continue;
      }
      if (x < h.width && y < h.height) h.primIds[y * h.width + x] = q.primitiveId;
      Vec4 c = h.constant;
      if (h.mode == FragMode::Input0) {
        uint32_t words[4];
        laneWords(q.inputs + 4 * h.inputSlot, l, words);
        std::memcpy(c.data(), words, 16);
      }
      if (h.mode == FragMode::PointCoord) c = {q.pointCoord[l][0], q.pointCoord[l][1], 0, 1};
      if (h.mode == FragMode::Facing) c = {q.frontFacing ? 1.0f : 2.0f, float(q.viewIndex), float(q.layer), 1};
      if (h.alpha0 >= 0) c[3] = h.alpha0;
      uint32_t words[4], words1[4];
      std::memcpy(words, c.data(), 16);
      std::memcpy(words1, h.constant1.data(), 16);
      setLaneWords(q.color[0], l, words);
      setLaneWords(q.color1, l, words1);
      if (h.fragDepthFromInput) std::memcpy(&q.depth[l], &q.inputs[0][l], 4);
    }
    if (h.killAll) q.killed = 0xF;
  }
};

// Additive blending of constant 1: the red channel counts the fragments written per pixel.
inline void countWrites(Harness& h) {
  h.constant = {1, 1, 1, 1};
  h.state.blend[0].enable = true;
  h.state.blend[0].srcColor = h.state.blend[0].dstColor = BlendFactor::One;
  h.state.blend[0].srcAlpha = h.state.blend[0].dstAlpha = BlendFactor::One;
}

// The coverage rule evaluated independently: exact integer cross products on coordinates in 1/256 pixel, and the
// spec's definitions of top and left edges (Vulkan: y points down). Vertices are in 1/256 pixel units.
inline bool referenceCovered(const int64_t X[3], const int64_t Y[3], int64_t px, int64_t py) {
  const int64_t area = (X[1] - X[0]) * (Y[2] - Y[0]) - (Y[1] - Y[0]) * (X[2] - X[0]);
  if (area == 0) return false;
  for (int i = 0; i < 3; ++i) {
    const int a = i, b = (i + 1) % 3, c = (i + 2) % 3;
    // Side of p relative to edge a->b, with the sign of the third vertex c as "inside".
    const int64_t sp = (X[b] - X[a]) * (py - Y[a]) - (Y[b] - Y[a]) * (px - X[a]);
    const int64_t sc = (X[b] - X[a]) * (Y[c] - Y[a]) - (Y[b] - Y[a]) * (X[c] - X[a]);
    if (sp != 0) {
      if ((sp > 0) != (sc > 0)) return false;
      continue;
    }
    // On the edge: covered only on a top edge (horizontal, third vertex below: larger y) or a left edge (not
    // horizontal, third vertex to its right at the same height).
    if (Y[a] == Y[b]) {
      if (!(Y[c] > Y[a])) return false;
    } else {
      // x of the edge at the third vertex's y, compared with the third vertex: the inside is to the right.
      // (x_edge - x_c) * (Y[b] - Y[a]) sign without division:
      const int64_t num = X[a] * (Y[b] - Y[a]) + (Y[c] - Y[a]) * (X[b] - X[a]);  // x_edge * (Y[b]-Y[a])
      const int64_t xc = X[c] * (Y[b] - Y[a]);
      const bool right = (Y[b] - Y[a]) > 0 ? xc > num : xc < num;
      if (!right) return false;
    }
  }
  return true;
}

}  // namespace vkrt::raster::test
