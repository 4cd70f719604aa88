// Storage images without a format in the shader (Image Format Unknown; StorageImageReadWithoutFormat and
// StorageImageWriteWithoutFormat), below the Vulkan API: tests/shaders/compute_formatless_image.comp compiled
// once and run over vkrt image views of several storage formats, through the runtime's image functions. The same
// compiled code reads and writes each format: the texel conversion follows the view bound at run time. Expected
// texels come from tests/spirv/formatless_reference.hpp.
#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "compute_formatless_image.comp.spv.h"
#include "spirv/compute_harness.hpp"
#include "spirv/formatless_reference.hpp"
#include "spirv/runtime_images.hpp"

namespace vkrt::testing {
namespace {

constexpr uint32_t kSize = 8;  // 8 x 8 texels: 2 x 2 workgroups of 4 x 4

class SpirvFormatlessImages : public RuntimeImages {
 protected:
  // A kSize x kSize 2D storage image of `f` holding `texels` (tightly packed rows), and its view.
  ImageView* makeImage(const StorageFormat& f, const std::vector<uint8_t>& texels) {
    ImageView* v = RuntimeImages::makeImage(f.format, kSize, kSize);
    setTexels(v, 0, texels, size_t(kSize) * f.texelSize());
    return v;
  }
  static std::vector<uint8_t> texelsOf(const ImageView* v, const StorageFormat& f) {
    return RuntimeImages::texelsOf(v, 0, size_t(kSize) * f.texelSize());
  }
};

TEST_F(SpirvFormatlessImages, OneCompiledShaderReadsAndWritesEveryFormatOfTheBoundViews) {
  ComputeHarness h;
  ASSERT_TRUE(h.compile(kSpv_compute_formatless_image_comp)) << h.error;
  const FormatlessImages rounds[] = {
      {&kRgba8, &kRgba16f, &kRgba32f, &kR32ui}, {&kBgra8, &kRgba8, &kRgba16f, &kRgba16ui},
      {&kRgba32f, &kBgra8, &kR32f, &kRgba32ui}, {&kRgba16f, &kRgba32f, &kBgra8, &kR32ui},
      {&kR32f, &kR32f, &kRgba8, &kRgba16ui},
  };
  uint32_t seed = 0;
  for (const FormatlessImages& f : rounds) {
    SCOPED_TRACE(std::string("src ") + f.src->name + ", dst " + f.dst->name + ", acc " + f.acc->name + ", ids " +
                 f.ids->name);
    const uint32_t n = kSize * kSize;
    std::vector<uint8_t> src = inputTexels(*f.src, n, ++seed), dst = inputTexels(*f.dst, n, ++seed);
    std::vector<uint8_t> acc = inputTexels(*f.acc, n, ++seed), ids = inputTexels(*f.ids, n, ++seed);
    const ImageView* views[4] = {makeImage(*f.src, src), makeImage(*f.dst, dst), makeImage(*f.acc, acc),
                                 makeImage(*f.ids, ids)};
    for (uint32_t b = 0; b < 4; ++b) h.images[b] = static_cast<const Object*>(views[b]);
    ASSERT_TRUE(h.run(2, 2));
    expectedFormatless(f, kSize, kSize, src, dst, acc, ids);
    expectTexels(*f.src, texelsOf(views[0], *f.src), src, "src (read only)");
    expectTexels(*f.dst, texelsOf(views[1], *f.dst), dst, "dst");
    expectTexels(*f.acc, texelsOf(views[2], *f.acc), acc, "acc");
    expectTexels(*f.ids, texelsOf(views[3], *f.ids), ids, "ids");
  }
}

}  // namespace
}  // namespace vkrt::testing
