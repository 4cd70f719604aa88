// The quad sampler's vector fast path (runtime/quad_sampling.cpp): vkrt_image_sample_grad_quad's four lanes at once
// for fastSampling's case (runtime/image_functions.cpp: a 2D (array) view of an 8-bit RGBA / BGRA UNorm or sRGB
// image, NEAREST / LINEAR filters, REPEAT / CLAMP_TO_EDGE in u and v, normalized coordinates, no depth comparison),
// isotropic samplers only. What it reads of the view and of the sampler is resolved once, when the object is
// created (QuadView in ImageView, QuadSampler in Sampler), so that a call looks nothing up: no format table, no
// level extent, no view-type switch.
//
// The results are the ones the per-lane fast path (fastAtLod in image_functions.cpp) gives, bit for bit: the same
// double, fixed-point and float operations in the same order, each lane's in one vector element (GCC vector
// extensions, SSE2 code on the baseline x86-64 target the runtime is built for: no FMA, no library call, so the
// same on every CPU).
#pragma once

#include <cstdint>

#include "runtime/vk.hpp"

namespace vkrt {

class ImageView;

// One level of a QuadView: the address of the view's base layer in it, the layer and row pitches, the extent.
struct QuadLevel {
  const uint8_t* layer0 = nullptr;
  uint64_t arrayPitch = 0;
  uint64_t rowPitch = 0;
  int32_t width = 0, height = 0;
};

// The fraction bits of the fast paths' fixed-point texel coordinates (image_functions.cpp, "texel addressing"), the
// per-lane one's and this one's alike: the LINEAR weights' 2^-8, subTexelPrecisionBits (physical_device.cpp).
inline constexpr int kSubTexelBits = 8;

// maxImageDimension2D is 16384 (physical_device.cpp): at most 15 levels. The fixed-point coordinates of a level of
// at most 2^14 texels (at most (2^14 + 3) 2^8) fit 32-bit integers.
inline constexpr uint32_t kQuadMaxLevels = 15;

// An image view as the quad fast path reads it; `fast` false where the view is not fastSampling's case (or its
// image has no memory when the view is created: the generic path then decides on every call).
struct QuadView {
  bool fast = false;
  bool srgb = false, bgr = false;
  bool identity = false;  // the component mapping changes nothing
  bool arrayed = false;   // a 2D array view: the layer is coordinate 2
  // Every level's texel offsets within a layer (row pitch times the last row, plus the last texel's bytes) are below
  // 2^31: a group of lanes at one level and layer addresses its texels with 32-bit vector arithmetic.
  bool offsets32 = false;
  uint32_t levelCount = 0, layerCount = 0;
  float size[2] = {0, 0};             // the base level's width and height, for the level of detail
  const float* srgbTable = nullptr;   // decodeTexel's 8-bit sRGB table (RGB of sRGB formats)
  const float* unormTable = nullptr;  // its 8-bit UNorm table (sRGB formats' alpha)
  QuadLevel levels[kQuadMaxLevels];
};

// A sampler as the quad fast path reads it; `fast` false for the samplers fastSampling leaves to the generic path
// and for those with anisotropyEnable (each lane's footprint decides, sampleAnisotropic).
struct QuadSampler {
  bool fast = false;
  bool repeatU = false, repeatV = false;         // else CLAMP_TO_EDGE
  bool magLinear = false, minLinear = false;     // else NEAREST
  bool mipLinear = false;                        // else NEAREST
  float mipLodBias = 0, minLod = 0, maxLod = 0;  // maxLod: max(minLod, maxLod), as the clamp applies it
};

// The records (runtime/image_functions.cpp, beside fastSampling, whose decision they hold).
QuadView describeQuadView(const ImageView& view);
QuadSampler describeQuadSampler(const VkSamplerCreateInfo& info);

// vkrt_image_sample_grad_quad's arguments (abi/image_functions.hpp) for a view and a sampler whose records are
// `fast`: writes all 16 words of `out`, the results of the lanes of `lanes` (before the view's component mapping)
// and 0 for the others, and returns the lanes it left to the caller, whose words it set to 0: those whose level of
// detail is NaN or whose coordinate has a magnitude of 2^24 or more or is NaN (the per-lane fast path's refusals),
// with their level of detail before the sampler's clamp in `lod` (biasedLod's: what sampleAtLod takes).
uint32_t sampleQuadFast(const QuadView& v, const QuadSampler& s, const float coord[16], const float ddx[16],
                        const float ddy[16], const float bias[4], uint32_t lanes, uint32_t out[16], float lod[4]);

// The code sampleQuadFast runs: the baseline target's, or AVX2's where the CPU has it (the default there; the
// environment's VKRT_QUAD_ISA=baseline keeps the baseline). Both give the same bits. setQuadSamplingIsa returns
// false, changing nothing, for AVX2 on a CPU without it.
enum class QuadIsa { Baseline, Avx2 };
QuadIsa quadSamplingIsa();
bool setQuadSamplingIsa(QuadIsa isa);

}  // namespace vkrt
