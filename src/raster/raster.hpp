// The rasterizer: primitive assembly, clipping, setup, binning into tiles, rasterization and the per-fragment back
// end (depth bounds, stencil, depth, blending, write masks) for one draw. Knows no Vulkan type, as accel/ knows none:
// the graphics layer (src/gfx) translates Vulkan state into these structs, and the shaders it compiled come in as
// callbacks. Tiles are spread over exec's thread pool; within a tile, primitives keep the draw's order.
//
// Conventions (Vulkan's, "Rasterization" and "Fixed-Function Vertex Post-Processing" chapters):
// - Clip space in, framebuffer coordinates out: x_f = (x_c / w_c) * w/2 + (x + w/2), likewise y; z_f =
//   z_c / w_c * (maxDepth - minDepth) + minDepth. Primitives are clipped against 0 <= z_c <= w_c (unless depth
//   clamp) and the user clip distances; x and y only as far as the fixed-point range needs (a guard band).
// - Framebuffer positions snap to kSubPixelBits bits of sub-pixel precision. A sample is covered by a triangle when it
//   is inside all three edges, or on an edge that is a top or a left edge (the top-left rule), for both windings.
// - Pixel centres at (x + 0.5, y + 0.5); the 4-sample pattern is the standard one: (0.375, 0.125), (0.875, 0.375),
//   (0.125, 0.625), (0.625, 0.875).
// - Inputs interpolate perspective-correctly unless NoPerspective; Flat takes the provoking vertex's value (the first
//   vertex of the primitive, or the last with lastVertexProvoking).
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>

namespace vkrt::raster {

inline constexpr uint32_t kSubPixelBits = 8;
inline constexpr uint32_t kMaxLocations = 32;  // user inputs/outputs, 4 x 32-bit components each
inline constexpr uint32_t kMaxColorAttachments = 8;
inline constexpr uint32_t kMaxClipDistances = 8;  // clip + cull distances together
inline constexpr uint32_t kMaxViewports = 16;

// Enumerations in the numeric order of the Vulkan ones, so the graphics layer converts with a cast.
enum class CompareOp : uint8_t { Never, Less, Equal, LessOrEqual, Greater, NotEqual, GreaterOrEqual, Always };
enum class StencilOp : uint8_t {
  Keep,
  Zero,
  Replace,
  IncrementAndClamp,
  DecrementAndClamp,
  Invert,
  IncrementAndWrap,
  DecrementAndWrap
};
enum class BlendFactor : uint8_t {
  Zero,
  One,
  SrcColor,
  OneMinusSrcColor,
  DstColor,
  OneMinusDstColor,
  SrcAlpha,
  OneMinusSrcAlpha,
  DstAlpha,
  OneMinusDstAlpha,
  ConstantColor,
  OneMinusConstantColor,
  ConstantAlpha,
  OneMinusConstantAlpha,
  SrcAlphaSaturate,
  Src1Color,
  OneMinusSrc1Color,
  Src1Alpha,
  OneMinusSrc1Alpha
};
enum class BlendOp : uint8_t { Add, Subtract, ReverseSubtract, Min, Max };
enum class LogicOp : uint8_t {
  Clear,
  And,
  AndReverse,
  Copy,
  AndInverted,
  NoOp,
  Xor,
  Or,
  Nor,
  Equivalent,
  Invert,
  OrReverse,
  CopyInverted,
  OrInverted,
  Nand,
  Set
};
enum class Topology : uint8_t {
  PointList,
  LineList,
  LineStrip,
  TriangleList,
  TriangleStrip,
  TriangleFan,
  LineListWithAdjacency,
  LineStripWithAdjacency,
  TriangleListWithAdjacency,
  TriangleStripWithAdjacency,
  PatchList
};
enum class PolygonMode : uint8_t { Fill, Line, Point };
enum class FrontFace : uint8_t { CounterClockwise, Clockwise };
enum CullBits : uint8_t { CullFront = 1, CullBack = 2 };
enum class IndexType : uint8_t { None, UInt16, UInt32, UInt8 };
enum class Interpolation : uint8_t { Smooth, NoPerspective, Flat };

// ------------------------------------------------------------------------------------------------ attachments

// How a color attachment's texels become the four values blending works on and back. `decode` and `encode` are
// the graphics layer's (the runtime's texel codecs); the back end only chooses arithmetic by `kind`: UNorm and SNorm
// clamp the shader's output (and the blend result) to [0, 1] / [-1, 1]; Float does not clamp; UInt and SInt skip
// blending (and logic ops apply only to them and the normalized kinds).
struct ColorFormat {
  enum class Kind : uint8_t { UNorm, SNorm, Float, UInt, SInt } kind = Kind::UNorm;
  uint32_t texelBytes = 4;
  uint8_t componentMask = 0xF;   // the components the format has (R = 1, G = 2, B = 4, A = 8)
  const void* format = nullptr;  // passed back to decode/encode
  // Texel -> four 32-bit words (floats for UNorm/SNorm/Float/sRGB, integers for UInt/SInt); A = 1 where absent.
  void (*decode)(const void* format, const uint8_t* texel, uint32_t out[4]) = nullptr;
  void (*encode)(const void* format, const uint32_t in[4], uint8_t* texel) = nullptr;
  // Set by the graphics layer for the common formats whose texels are four 8-bit unsigned normalized components in
  // memory order R, G, B, A (R8G8B8A8_UNORM, _SRGB) or B, G, R, A (B8G8R8A8_UNORM, _SRGB): the back end then converts
  // inline instead of through decode/encode, with the same results (decode: the byte / 255 rounded to float, sRGB
  // colour components by abi/srgb8.hpp's table; encode: NaN to 0, clamped to [0, 1], times 255 rounded to nearest
  // even, sRGB colour components by abi/srgb8.hpp's encode).
  enum class Layout : uint8_t { Generic, RGBA8UNorm, BGRA8UNorm, RGBA8Srgb, BGRA8Srgb } layout = Layout::Generic;
  // R16G16B16A16_SFLOAT (set by the graphics layer): the back end's quad path for it (half4Quad), with the codecs'
  // results.
  bool rgba16Float = false;
  bool bgra() const { return layout == Layout::BGRA8UNorm || layout == Layout::BGRA8Srgb; }
  bool srgb() const { return layout == Layout::RGBA8Srgb || layout == Layout::BGRA8Srgb; }
};

// A 2D view of an image's level: pixel (x, y) of layer `l` sample `s` is at
//   base + l * layerPitch + y * rowPitch + (x * samples + s) * texelBytes.
struct Surface {
  uint8_t* base = nullptr;
  size_t rowPitch = 0;
  size_t layerPitch = 0;
  uint32_t width = 0, height = 0, layers = 1;
  uint32_t samples = 1;  // 1 or 4
};

enum class DepthFormat : uint8_t { None, D16UNorm, X8D24UNorm, D32SFloat };
enum class StencilFormat : uint8_t { None, S8UInt };

// The depth/stencil attachment. Combined formats are given as two surfaces over the same texels (the graphics
// layer sets `stencilOffset`: D24_UNORM_S8_UINT keeps stencil in byte 3 of each 32-bit texel, D32_SFLOAT_S8_UINT in
// byte 4 of each 8-byte texel; a separate S8 image has offset 0 and texelBytes 1).
struct DepthStencilTarget {
  DepthFormat depthFormat = DepthFormat::None;
  Surface depth;
  uint32_t depthTexelBytes = 0;
  StencilFormat stencilFormat = StencilFormat::None;
  Surface stencil;
  uint32_t stencilTexelBytes = 0;
  uint32_t stencilOffset = 0;
};

struct Rect {
  int32_t x = 0, y = 0;
  uint32_t width = 0, height = 0;
};

// Where a draw renders: the attachments of the current subpass (or dynamic rendering), the render area, the layer
// (or, with a view mask, the views: each view renders to the layer of its index) and the sample count.
struct Target {
  uint32_t colorCount = 0;
  Surface color[kMaxColorAttachments];  // base == nullptr: VK_ATTACHMENT_UNUSED
  ColorFormat colorFormat[kMaxColorAttachments];
  DepthStencilTarget depthStencil;
  Rect renderArea;
  uint32_t samples = 1;
  uint32_t viewMask = 0;  // 0: no multiview
};

// ------------------------------------------------------------------------------------------------ state

struct Viewport {
  float x = 0, y = 0, width = 0, height = 0, minDepth = 0, maxDepth = 1;
};

struct StencilFace {
  StencilOp failOp = StencilOp::Keep, passOp = StencilOp::Keep, depthFailOp = StencilOp::Keep;
  CompareOp compareOp = CompareOp::Always;
  uint32_t compareMask = 0xFF, writeMask = 0xFF, reference = 0;
};

struct BlendAttachment {
  bool enable = false;
  BlendFactor srcColor = BlendFactor::One, dstColor = BlendFactor::Zero;
  BlendOp colorOp = BlendOp::Add;
  BlendFactor srcAlpha = BlendFactor::One, dstAlpha = BlendFactor::Zero;
  BlendOp alphaOp = BlendOp::Add;
  uint8_t writeMask = 0xF;  // R = 1, G = 2, B = 4, A = 8
};

// Everything fixed-function a draw needs, dynamic state already resolved by the graphics layer.
struct State {
  Topology topology = Topology::TriangleList;
  bool primitiveRestart = false;
  uint32_t viewportCount = 1;
  Viewport viewports[kMaxViewports];
  Rect scissors[kMaxViewports];

  bool rasterizerDiscard = false;
  PolygonMode polygonMode = PolygonMode::Fill;
  uint8_t cullMode = 0;  // CullBits
  FrontFace frontFace = FrontFace::CounterClockwise;
  bool depthClamp = false;
  bool depthClipEnable = true;  // false only with depth clamp (VK_EXT_depth_clip_enable semantics)
  bool depthBiasEnable = false;
  float depthBiasConstant = 0, depthBiasClamp = 0, depthBiasSlope = 0;
  float lineWidth = 1;
  bool lastVertexProvoking = false;

  uint32_t samples = 1;
  uint32_t sampleMask = ~0u;
  bool alphaToCoverage = false, alphaToOne = false;
  bool sampleShading =
      false;  // the fragment shader runs once per covered sample (sample shading, or it reads SampleId)

  bool depthTest = false, depthWrite = false;
  CompareOp depthCompare = CompareOp::Less;
  bool depthBoundsTest = false;
  float minDepthBounds = 0, maxDepthBounds = 1;
  bool stencilTest = false;
  StencilFace front, back;

  bool logicOpEnable = false;
  LogicOp logicOp = LogicOp::Copy;
  BlendAttachment blend[kMaxColorAttachments];
  float blendConstants[4] = {0, 0, 0, 0};
};

// ------------------------------------------------------------------------------------------------ shaders

// A shaded vertex, as the vertex stage leaves it: clip position, point size, clip and cull distances, and the user
// outputs at the locations the fragment stage reads (Draw::varyingLocations of them, 16 bytes each, in the order of
// FragmentStage::inputs).
struct ShadedVertex {
  float position[4];
  float pointSize;
  float clipDistance[kMaxClipDistances];  // the first clipDistanceCount are clip distances, the next cull distances
  uint32_t* varyings;                     // Draw::varyingCount slots of 4 words
};

// The vertex stage: shades `count` vertices of one instance. `vertexIndex[i]` is the vertex's index (the index
// buffer's value plus vertexOffset, or firstVertex + i for non-indexed draws); out[i].varyings points at storage the
// rasterizer owns. Called from several workers at once with different vertices.
struct VertexStage {
  void* user = nullptr;
  void (*shade)(void* user, uint32_t instanceIndex, uint32_t viewIndex, const uint32_t* vertexIndex, uint32_t count,
                ShadedVertex* out, unsigned worker) = nullptr;
  uint32_t clipDistanceCount = 0, cullDistanceCount = 0;
};

// What the fragment stage reads, per input slot (slot i of ShadedVertex::varyings and of FragmentQuad::inputs).
struct FragmentInput {
  uint8_t location = 0;
  uint8_t componentMask = 0xF;
  Interpolation interpolation = Interpolation::Smooth;
  bool centroid = false;
  bool sample = false;  // per-sample interpolation (implies the shader runs per sample)
};

// A 2x2 quad handed to the fragment shader. Lane i is pixel (x + (i & 1), y + (i >> 1)). The rasterizer fills
// the inputs; the shader fills the outputs of the lanes in `coverage`.
struct FragmentQuad {
  int32_t x = 0, y = 0;
  uint32_t coverage[4] = {};  // per lane, the covered samples (bit s = sample s); 0: a helper lane
  uint32_t sampleIndex = 0;   // with per-sample shading: the sample this invocation shades
  // x, y (pixel centre or sample position), z (framebuffer depth), 1 / w_c: per component, the four lanes side by side.
  float fragCoord[4][4];
  float pointCoord[4][2];
  bool frontFacing = true;
  uint32_t primitiveId = 0;
  uint32_t viewIndex = 0;
  uint32_t layer = 0;
  // Inputs as structures of arrays, in the slot order of FragmentStage::inputs: word 4 s + c (slot s, component c)
  // of the four lanes side by side at inputs[4 s + c] (laneWords gathers one lane's).
  alignas(16) uint32_t inputs[kMaxLocations * 4][4];
  // The primitive and draw being shaded, for interpolateAt (the rasterizer's own records).
  const void* primitive = nullptr;
  const void* drawContext = nullptr;
  // Where FragmentStage::mergesColor0: the quad's top-left texel in colour attachment 0 when `shade` is to write the
  // quad's four texels itself (a fully covered one-sample quad that nothing after the shader changes), else null.
  uint8_t* colorOut = nullptr;

  // Written by the shader:
  uint32_t killed = 0;  // lanes that discarded (bit i = lane i)
  uint32_t sampleMaskOut[4] = {~0u, ~0u, ~0u, ~0u};
  float depth[4];  // FragDepth, read when FragmentStage::writesDepth
  // Colours as structures of arrays: per output location, per component, the four lanes' words side by side (the
  // back end's vector paths read a component of the quad as one vector; laneWords gathers one lane's).
  alignas(16) uint32_t color[kMaxColorAttachments][4][4];
  alignas(16) uint32_t color1[4][4];  // Index 1 output of location 0 (dual-source blending): per component, per lane
};

// Lane `lane`'s four words out of four rows of a structure of arrays (an input slot, q.inputs + 4 s; a colour output,
// q.color[location]; the dual-source output, q.color1): out[c] = rows[c][lane]. setLaneWords writes them.
inline void laneWords(const uint32_t (*rows)[4], uint32_t lane, uint32_t out[4]) {
  for (uint32_t c = 0; c < 4; ++c) out[c] = rows[c][lane];
}
inline void setLaneWords(uint32_t (*rows)[4], uint32_t lane, const uint32_t in[4]) {
  for (uint32_t c = 0; c < 4; ++c) rows[c][lane] = in[c];
}

struct FragmentStage {
  void* user = nullptr;
  // Runs the shader for the quad's lanes: the covered ones, and the helper lanes too when `needsHelpers`. Null: no
  // fragment shader (depth/stencil only; color outputs undefined, nothing written to color).
  void (*shade)(void* user, FragmentQuad& quad, unsigned worker) = nullptr;
  // Runs body(arg), the rasterization of one tile (every call of `shade` for it), on worker `worker` under the
  // stage's supervision, so that the stage sets up once per tile what is the same for all its quads. The body may
  // be left midway (a shader fault or a time limit ends the work: exec/supervise.hpp); runTile then returns false
  // and the rest of the tile is not rasterized. Null: body runs directly.
  bool (*runTile)(void* user, void (*body)(void*), void* arg, unsigned worker) = nullptr;
  bool needsHelpers = false;  // derivatives or quad operations: all four lanes run
  bool writesDepth = false;   // FragDepth
  bool writesSampleMask = false;
  bool canDiscard = false;          // OpKill, OpTerminateInvocation or OpDemoteToHelperInvocation
  bool earlyFragmentTests = false;  // the EarlyFragmentTests execution mode
  bool hasSideEffects = false;      // stores or atomics to memory: the tests may not skip it early unless early tests
  bool readsFragCoord = true;       // else a one-sample quad's FragCoord.w (FragmentQuad::fragCoord[3]) is left as is
  bool readsPointCoord = true;      // else a one-sample quad's pointCoord is left as is
  // `shade` writes colour attachment 0 of a quad given FragmentQuad::colorOut, as the back end's quad path would (the
  // same bytes: the shader compiled with the attachment's format and blend); the shader cannot discard.
  bool mergesColor0 = false;
  uint32_t inputCount = 0;
  FragmentInput inputs[kMaxLocations];
  uint32_t outputMask = 0;  // color locations written
};

// Where interpolateAt evaluates (GLSL.std.450 InterpolateAtCentroid / Sample / Offset).
enum class InterpolateAt : uint8_t { Centroid, Sample, Offset };

// The fragment inputs of lane `lane` of `quad` (inside FragmentStage::shade) interpolated at another position than
// the one the rasterizer used: the centroid of the lane's coverage (as "Centroid" inputs take it), the position of
// sample `sample` of the lane's pixel (the pixel centre when the sample does not exist), or the pixel centre plus
// (dx, dy) pixels. Each input is interpolated as it is decorated (perspective-correct, NoPerspective; Flat inputs
// give the provoking vertex's value); written to out[16 * location ..] for every location the stage reads.
void interpolateAt(const FragmentQuad& quad, uint32_t lane, InterpolateAt where, int32_t sample, float dx, float dy,
                   uint32_t* out);

// ------------------------------------------------------------------------------------------------ the draw

struct Draw {
  // Non-indexed: vertices firstVertex .. firstVertex + count - 1. Indexed: `count` indices from `indices` (already
  // offset to firstIndex), each plus vertexOffset; `indexCount` bounds reads (indices past it read as 0, robustness).
  uint32_t count = 0;
  uint32_t instanceCount = 1;
  uint32_t firstVertex = 0;
  int32_t vertexOffset = 0;
  uint32_t firstInstance = 0;
  IndexType indexType = IndexType::None;
  const void* indices = nullptr;
  uint64_t indexBytes = 0;    // bytes readable at `indices`
  uint32_t varyingCount = 0;  // = fragment.inputCount
  // When set, the number of samples that pass the per-fragment tests (the shader's discard and sample mask, alpha
  // to coverage, depth bounds, stencil and depth: what an occlusion query counts, "Occlusion Queries") is added to
  // it, once per tile from each worker's own count.
  std::atomic<uint64_t>* samplesPassed = nullptr;
};

// Which of the back end's blend equations with code of their own `b`'s factors and ops are (kBlendShapes, in order:
// source alpha "over" with alpha as coverage, "over" on all four components, premultiplied "over", additive; the
// order abi::ColorMerge::Blend follows), or -1 for any other; `enable` is not looked at.
int blendShape(const BlendAttachment& b);

// Runs one draw to completion (on the thread pool; returns when every fragment is written). The attachments are read
// and written in place.
void draw(const Target& target, const State& state, const Draw& draw, const VertexStage& vertex,
          const FragmentStage& fragment);

}  // namespace vkrt::raster
