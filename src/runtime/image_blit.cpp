#include "runtime/image_blit.hpp"

#include <algorithm>
#include <cstring>

#include "exec/thread_pool.hpp"

namespace vkrt {

namespace {

bool isInteger(const FormatInfo& f) { return f.type == NumericType::UInt || f.type == NumericType::SInt; }

// "Signed and unsigned integers are converted by first clamping to the representable range of the destination
// format, then casting the value" (Image Copies With Scaling); encodeTexel keeps the low bits, so clamp first.
void clampToInteger(const FormatInfo& f, uint32_t w[4]) {
  for (unsigned c = 0; c < f.components; ++c) {
    const unsigned bits = f.bits[c];
    if (f.type == NumericType::UInt) {
      const uint32_t max = bits >= 32 ? 0xffffffffu : (1u << bits) - 1;
      w[c] = std::min(w[c], max);
    } else {
      const int64_t max = (int64_t(1) << (bits - 1)) - 1, min = -(int64_t(1) << (bits - 1));
      w[c] = uint32_t(int32_t(std::clamp<int64_t>(int32_t(w[c]), min, max)));
    }
  }
}

int dimsOf(VkImageType t) { return t == VK_IMAGE_TYPE_1D ? 1 : t == VK_IMAGE_TYPE_2D ? 2 : 3; }

}  // namespace

BlitRegion::BlitRegion(const Image& src, const Image& dst, const VkImageBlit2& r, VkFilter filter)
    : src_(src), dst_(dst), r_(r), filter_(filter), srcDims_(dimsOf(src.type)) {
  const int32_t s0[3] = {r.srcOffsets[0].x, r.srcOffsets[0].y, r.srcOffsets[0].z};
  const int32_t s1[3] = {r.srcOffsets[1].x, r.srcOffsets[1].y, r.srcOffsets[1].z};
  const int32_t d0[3] = {r.dstOffsets[0].x, r.dstOffsets[0].y, r.dstOffsets[0].z};
  const int32_t d1[3] = {r.dstOffsets[1].x, r.dstOffsets[1].y, r.dstOffsets[1].z};
  uint64_t n = r.dstSubresource.layerCount;
  for (int d = 0; d < 3; ++d) {
    // Either pair of offsets may be reversed: the region is the box between them, and a reversed pair mirrors.
    lo_[d] = std::min(d0[d], d1[d]);
    hi_[d] = std::max(d0[d], d1[d]);
    scale_[d] = d1[d] == d0[d] ? 0.0 : double(s1[d] - s0[d]) / double(d1[d] - d0[d]);
    if (d > 0) n *= uint64_t(hi_[d] - lo_[d]);
  }
  rows_ = hi_[0] > lo_[0] ? n : 0;
  // The source is sampled with the blit's filter, VK_SAMPLER_MIPMAP_MODE_NEAREST on the one level, and
  // VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE, at unnormalized coordinates.
  sampler_.sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO;
  sampler_.magFilter = sampler_.minFilter = filter;
  sampler_.addressModeU = sampler_.addressModeV = sampler_.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
  sampler_.unnormalizedCoordinates = VK_TRUE;
}

void BlitRegion::run(uint64_t row) const {
  const uint64_t height = uint64_t(hi_[1] - lo_[1]), depth = uint64_t(hi_[2] - lo_[2]);
  const int32_t y = lo_[1] + int32_t(row % height);
  const int32_t z = lo_[2] + int32_t(row / height % depth);
  const uint32_t layer = uint32_t(row / height / depth);

  TexelView v;
  v.image = &src_;
  v.format = src_.formatInfo;
  v.baseMip = r_.srcSubresource.mipLevel;
  v.baseLayer = r_.srcSubresource.baseArrayLayer + layer;
  v.dims = srcDims_;

  // Destination texel (i, j, k) samples the source at ((i + 1/2 - dst0) * scale + src0) in each dimension.
  auto map = [&](int d, int32_t at, int32_t dst0, int32_t src0) {
    return float((double(at) + 0.5 - double(dst0)) * scale_[d] + double(src0));
  };
  float coord[3];
  coord[1] = map(1, y, r_.dstOffsets[0].y, r_.srcOffsets[0].y);
  coord[2] = map(2, z, r_.dstOffsets[0].z, r_.srcOffsets[0].z);
  const FormatInfo& df = *dst_.formatInfo;
  const bool integer = isInteger(df);
  const uint32_t dstLayer = r_.dstSubresource.baseArrayLayer + layer;
  uint8_t* out = dst_.texel(r_.dstSubresource.mipLevel, dstLayer, uint32_t(lo_[0]), uint32_t(y), uint32_t(z));
  for (int32_t x = lo_[0]; x < hi_[0]; ++x, out += df.texelSize) {
    coord[0] = map(0, x, r_.dstOffsets[0].x, r_.srcOffsets[0].x);
    uint32_t w[4];
    filterTexels(v, sampler_, filter_, 0, coord, 0, w);
    // Float, normalized and sRGB values are clamped and converted by encodeTexel (sRGB destinations re-encode
    // linear values; sRGB sources were decoded to linear before filtering by decodeTexel).
    if (integer) clampToInteger(df, w);
    encodeTexel(df, w, out);
  }
}

void blitImage(const Image& src, const Image& dst, const VkImageBlit2* regions, uint32_t regionCount, VkFilter filter) {
  // Rows per task: enough texels that a task is worth handing to another thread.
  constexpr uint64_t kTexelsPerTask = 16384;
  for (uint32_t i = 0; i < regionCount; ++i) {
    const BlitRegion b(src, dst, regions[i], filter);
    const uint64_t rows = b.rows();
    const uint64_t rowsPerTask = std::max<uint64_t>(1, kTexelsPerTask / std::max(1u, b.width()));
    const uint64_t tasks = (rows + rowsPerTask - 1) / rowsPerTask;
    if (tasks <= 1) {
      for (uint64_t row = 0; row < rows; ++row) b.run(row);
      continue;
    }
    // Each task writes its own destination rows; runConcurrently (not parallelFor) so that a blit does not wait
    // behind another queue's dispatch.
    exec::ThreadPool::instance().runConcurrently(tasks, [&](uint64_t t) {
      const uint64_t end = std::min(rows, (t + 1) * rowsPerTask);
      for (uint64_t row = t * rowsPerTask; row < end; ++row) b.run(row);
    });
  }
}

}  // namespace vkrt
