// The fragment shader's InterpolateAtCentroid / Sample / Offset (GLSL.std.450 76-78): the quad's inputs evaluated
// again at another position of the primitive's planes ("Interpolation Decorations", "Multisample Interpolation").
// Called from the shader, rarely: everything is recomputed from the primitive's setup record.
#include <bit>
#include <cstring>

#include "raster/internal.hpp"

namespace vkrt::raster {

void interpolateAt(const FragmentQuad& q, uint32_t lane, InterpolateAt where, int32_t sample, float dx, float dy,
                   uint32_t* out) {
  using namespace detail;
  const DrawContext& ctx = *static_cast<const DrawContext*>(q.drawContext);
  const SetupTri& t = *static_cast<const SetupTri*>(q.primitive);
  lane &= 3;
  // The position within the pixel, in fixed-point units (fractions kept: an offset need not be on the grid).
  double sx = kCentre, sy = kCentre;
  auto at = [&](uint32_t s) {
    if (ctx.samples == 1) return;
    sx = kSampleX4[s];
    sy = kSampleY4[s];
  };
  switch (where) {
    case InterpolateAt::Centroid: {
      // As the Centroid decoration takes it (tile.cpp): the centre when every sample is covered, else the first
      // covered sample. With sample shading the coverage is the one sample shaded.
      const uint32_t cov = q.coverage[lane];
      if (cov && cov != ctx.allSamples) at(uint32_t(std::countr_zero(cov)));
      break;
    }
    case InterpolateAt::Sample:
      // A sample the pixel does not have: the position is undefined (GLSL.std.450); the centre.
      if (sample >= 0 && uint32_t(sample) < ctx.samples) at(uint32_t(sample));
      break;
    case InterpolateAt::Offset:
      sx += double(dx) * kSubPixel;
      sy += double(dy) * kSubPixel;
      break;
  }
  const double px = double(q.x + int32_t(lane & 1)) * kSubPixel + sx;
  const double py = double(q.y + int32_t(lane >> 1)) * kSubPixel + sy;
  double b[3];
  for (int i = 0; i < 3; ++i) b[i] = (double(t.a[i]) * px + double(t.b[i]) * py + double(t.c[i])) * t.invArea2;
  // Perspective-correct weights, as tile.cpp's interpolateLane forms them.
  double p[3] = {b[0], b[1], b[2]};
  const double w0 = b[0] * t.invW[0], w1 = b[1] * t.invW[1], w2 = b[2] * t.invW[2];
  const double sum = w0 + w1 + w2;
  if (sum != 0) p[0] = w0 / sum, p[1] = w1 / sum, p[2] = w2 / sum;
  const FragmentStage& fs = *ctx.fragment;
  for (uint32_t slot = 0; slot < fs.inputCount; ++slot) {
    const FragmentInput& in = fs.inputs[slot];
    const uint32_t k = slot * 4;
    uint32_t* dst = out + 4 * in.location;
    if (in.interpolation == Interpolation::Flat) {
      std::memcpy(dst, t.flat + k, 16);
      continue;
    }
    const double* w = in.interpolation == Interpolation::Smooth ? p : b;
    const float w1f = float(w[1]), w2f = float(w[2]);
    for (uint32_t c = 0; c < 4; ++c) {
      const float f0 = asFloat(t.var[0][k + c]);
      dst[c] = asWord(f0 + w1f * (asFloat(t.var[1][k + c]) - f0) + w2f * (asFloat(t.var[2][k + c]) - f0));
    }
  }
}

}  // namespace vkrt::raster
