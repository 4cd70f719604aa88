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
#include "runtime/image.hpp"
#include "runtime/image_view.hpp"
#include "spirv/compute_harness.hpp"
#include "spirv/formatless_reference.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt::testing {
namespace {

constexpr uint32_t kSize = 8;  // 8 x 8 texels: 2 x 2 workgroups of 4 x 4

class SpirvFormatlessImages : public ::testing::Test {
 protected:
  void SetUp() override {
    VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    ASSERT_EQ(vkrt_CreateInstance(&ici, nullptr, &instance), VK_SUCCESS);
    uint32_t n = 1;
    VkPhysicalDevice pd = VK_NULL_HANDLE;
    ASSERT_EQ(vkrt_EnumeratePhysicalDevices(instance, &n, &pd), VK_SUCCESS);
    float prio = 1.0f;
    VkDeviceQueueCreateInfo q{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    q.queueCount = 1;
    q.pQueuePriorities = &prio;
    VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    dci.queueCreateInfoCount = 1;
    dci.pQueueCreateInfos = &q;
    ASSERT_EQ(vkrt_CreateDevice(pd, &dci, nullptr, &device), VK_SUCCESS);
  }
  void TearDown() override {
    for (const Held& h : held) {
      vkrt_DestroyImageView(device, h.view, nullptr);
      vkrt_DestroyImage(device, h.image, nullptr);
      vkrt_FreeMemory(device, h.memory, nullptr);
    }
    vkrt_DestroyDevice(device, nullptr);
    vkrt_DestroyInstance(instance, nullptr);
  }

  // A kSize x kSize 2D storage image of `f` holding `texels` (tightly packed rows), and its view.
  ImageView* makeImage(const StorageFormat& f, const std::vector<uint8_t>& texels) {
    Held h;
    VkImageCreateInfo ci{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    ci.imageType = VK_IMAGE_TYPE_2D;
    ci.format = f.format;
    ci.extent = {kSize, kSize, 1};
    ci.mipLevels = 1;
    ci.arrayLayers = 1;
    ci.samples = VK_SAMPLE_COUNT_1_BIT;
    ci.usage = VK_IMAGE_USAGE_STORAGE_BIT;
    EXPECT_EQ(vkrt_CreateImage(device, &ci, nullptr, &h.image), VK_SUCCESS);
    VkMemoryRequirements req;
    vkrt_GetImageMemoryRequirements(device, h.image, &req);
    VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    mai.allocationSize = req.size;
    EXPECT_EQ(vkrt_AllocateMemory(device, &mai, nullptr, &h.memory), VK_SUCCESS);
    EXPECT_EQ(vkrt_BindImageMemory(device, h.image, h.memory, 0), VK_SUCCESS);
    VkImageViewCreateInfo vi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    vi.image = h.image;
    vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
    vi.format = f.format;
    vi.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    EXPECT_EQ(vkrt_CreateImageView(device, &vi, nullptr, &h.view), VK_SUCCESS);
    held.push_back(h);
    Image* image = fromHandle<Image>(h.image);
    for (uint32_t y = 0; y < kSize; ++y)
      std::memcpy(image->texel(0, 0, 0, y, 0), texels.data() + size_t(y) * kSize * f.texelSize(),
                  size_t(kSize) * f.texelSize());
    return fromHandle<ImageView>(h.view);
  }
  static std::vector<uint8_t> texelsOf(const ImageView* v, const StorageFormat& f) {
    std::vector<uint8_t> out(size_t(kSize) * kSize * f.texelSize());
    for (uint32_t y = 0; y < kSize; ++y)
      std::memcpy(out.data() + size_t(y) * kSize * f.texelSize(), v->image->texel(0, 0, 0, y, 0),
                  size_t(kSize) * f.texelSize());
    return out;
  }

  struct Held {
    VkImage image = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkImageView view = VK_NULL_HANDLE;
  };
  VkInstance instance = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  std::vector<Held> held;
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
