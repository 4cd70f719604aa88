// vkCmdBlitImage's texel work ("Image Copies With Scaling"): plain functions on vkrt images, run by the command
// (runtime/image_commands.cpp) on the queue worker, with no Vulkan object state.
#pragma once

#include <cstdint>

#include "runtime/image.hpp"
#include "runtime/image_functions.hpp"

namespace vkrt {

// One region of a blit, resolved once: the destination box, the mapping of destination texel centres into the
// source, and the source as the sampling code addresses it. Destination rows (one row of texels in x at a given
// layer, slice and y) are independent, so a caller may run them on several threads.
class BlitRegion {
 public:
  // `r` must have passed the command's checks (subresources and offsets inside the images).
  BlitRegion(const Image& src, const Image& dst, const VkImageBlit2& r, VkFilter filter);

  // Destination rows: layers x slices x rows of the destination box (0 when the box is empty).
  uint64_t rows() const { return rows_; }
  // Texels in one destination row.
  uint32_t width() const { return uint32_t(hi_[0] - lo_[0]); }
  // Samples and writes destination row `row` (< rows()).
  void run(uint64_t row) const;

 private:
  const Image& src_;
  const Image& dst_;
  VkImageBlit2 r_;
  VkFilter filter_;
  int32_t lo_[3], hi_[3];  // the destination box [lo, hi) per dimension
  double scale_[3];        // source texels per destination texel, signed (negative: mirrored)
  uint64_t rows_ = 0;
  int srcDims_;
  VkSamplerCreateInfo sampler_{};
};

// Blits every region, spreading large regions' rows over the worker thread pool.
void blitImage(const Image& src, const Image& dst, const VkImageBlit2* regions, uint32_t regionCount, VkFilter filter);

}  // namespace vkrt
