// Presentation without a display: VK_EXT_headless_surface's surface queries, a VK_KHR_swapchain on it (acquire and
// present ordered by semaphores and fences), the frames VKRT_PRESENT_DIR writes, and misuse reported by VUID.
#include <dirent.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "e2e/fixture.hpp"

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wall"
#pragma GCC diagnostic ignored "-Wextra"
#define STBI_ONLY_PNG
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#include <stb/stb_image.h>
#pragma GCC diagnostic pop

namespace vkrt::test {
namespace {

class SwapchainTest : public VulkanTest {
 protected:
  virtual bool layer() { return true; }
  FixtureOptions options() override {
    FixtureOptions o;
    o.validation = layer();
    o.instanceExtensions = {VK_KHR_SURFACE_EXTENSION_NAME, VK_EXT_HEADLESS_SURFACE_EXTENSION_NAME};
    o.deviceExtensions = {VK_KHR_SWAPCHAIN_EXTENSION_NAME};
    return o;
  }
  void SetUp() override {
    // NVIDIA's driver (580) has no VK_EXT_headless_surface: there is nothing to test then.
    uint32_t n = 0;
    vkEnumerateInstanceExtensionProperties(nullptr, &n, nullptr);
    std::vector<VkExtensionProperties> exts(n);
    vkEnumerateInstanceExtensionProperties(nullptr, &n, exts.data());
    if (std::none_of(exts.begin(), exts.end(), [](const VkExtensionProperties& e) {
          return std::strcmp(e.extensionName, VK_EXT_HEADLESS_SURFACE_EXTENSION_NAME) == 0;
        }))
      GTEST_SKIP() << "the driver has no " VK_EXT_HEADLESS_SURFACE_EXTENSION_NAME;
    VulkanTest::SetUp();
    if (HasFatalFailure()) return;
    auto create =
        reinterpret_cast<PFN_vkCreateHeadlessSurfaceEXT>(vkGetInstanceProcAddr(instance, "vkCreateHeadlessSurfaceEXT"));
    ASSERT_NE(create, nullptr);
    VkHeadlessSurfaceCreateInfoEXT info{VK_STRUCTURE_TYPE_HEADLESS_SURFACE_CREATE_INFO_EXT};
    ASSERT_EQ(create(instance, &info, nullptr, &surface), VK_SUCCESS);
  }
  void TearDown() override {
    if (device) vkDeviceWaitIdle(device);
    for (VkSemaphore s : semaphores) vkDestroySemaphore(device, s, nullptr);
    for (VkFence f : fences) vkDestroyFence(device, f, nullptr);
    for (VkSwapchainKHR s : swapchains) vkDestroySwapchainKHR(device, s, nullptr);
    if (surface) vkDestroySurfaceKHR(instance, surface, nullptr);
    if (!presentDir.empty()) {
      for (const std::string& f : frameFiles()) std::remove((presentDir + "/" + f).c_str());
      rmdir(presentDir.c_str());
      unsetenv("VKRT_PRESENT_DIR");
    }
    VulkanTest::TearDown();
  }

  VkSwapchainKHR makeSwapchain(uint32_t minImages, VkPresentModeKHR mode = VK_PRESENT_MODE_FIFO_KHR,
                               VkSwapchainKHR old = VK_NULL_HANDLE) {
    VkSwapchainCreateInfoKHR ci{VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR};
    ci.surface = surface;
    ci.minImageCount = minImages;
    ci.imageFormat = VK_FORMAT_R8G8B8A8_UNORM;
    ci.imageColorSpace = VK_COLOR_SPACE_SRGB_NONLINEAR_KHR;
    ci.imageExtent = {kWidth, kHeight};
    ci.imageArrayLayers = 1;
    ci.imageUsage = VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    ci.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
    ci.preTransform = VK_SURFACE_TRANSFORM_IDENTITY_BIT_KHR;
    ci.compositeAlpha = VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR;
    ci.presentMode = mode;
    ci.clipped = VK_TRUE;
    ci.oldSwapchain = old;
    VkSwapchainKHR s = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreateSwapchainKHR(device, &ci, nullptr, &s), VK_SUCCESS);
    if (s) swapchains.push_back(s);
    return s;
  }
  std::vector<VkImage> images(VkSwapchainKHR s) {
    uint32_t n = 0;
    EXPECT_EQ(vkGetSwapchainImagesKHR(device, s, &n, nullptr), VK_SUCCESS);
    std::vector<VkImage> v(n);
    EXPECT_EQ(vkGetSwapchainImagesKHR(device, s, &n, v.data()), VK_SUCCESS);
    return v;
  }
  VkSemaphore semaphore() {
    VkSemaphoreCreateInfo ci{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    VkSemaphore s = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreateSemaphore(device, &ci, nullptr, &s), VK_SUCCESS);
    semaphores.push_back(s);
    return s;
  }
  VkFence fence() {
    VkFenceCreateInfo ci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VkFence f = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreateFence(device, &ci, nullptr, &f), VK_SUCCESS);
    fences.push_back(f);
    return f;
  }
  // Clears swapchain image `img` to `rgba` after `wait` signals, then signals `done` (and `fence`).
  void clearImage(VkImage img, const float rgba[4], VkSemaphore wait, VkSemaphore done, VkFence f) {
    VkCommandBuffer cb = beginOneTime();
    VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    b.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    b.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    b.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = img;
    b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0,
                         nullptr, 1, &b);
    VkClearColorValue color;
    std::copy(rgba, rgba + 4, color.float32);
    vkCmdClearColorImage(cb, img, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &color, 1, &b.subresourceRange);
    b.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    b.dstAccessMask = 0;
    b.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    b.newLayout = VK_IMAGE_LAYOUT_PRESENT_SRC_KHR;
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, 0, 0, nullptr, 0,
                         nullptr, 1, &b);
    ASSERT_EQ(vkEndCommandBuffer(cb), VK_SUCCESS);
    const VkPipelineStageFlags stage = VK_PIPELINE_STAGE_TRANSFER_BIT;
    VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    si.waitSemaphoreCount = wait ? 1 : 0;
    si.pWaitSemaphores = &wait;
    si.pWaitDstStageMask = &stage;
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cb;
    si.signalSemaphoreCount = done ? 1 : 0;
    si.pSignalSemaphores = &done;
    ASSERT_EQ(vkQueueSubmit(queue, 1, &si, f), VK_SUCCESS);
    submitted.push_back(cb);
  }
  VkResult present(VkSwapchainKHR s, uint32_t index, VkSemaphore wait) {
    VkPresentInfoKHR pi{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
    pi.waitSemaphoreCount = wait ? 1 : 0;
    pi.pWaitSemaphores = &wait;
    pi.swapchainCount = 1;
    pi.pSwapchains = &s;
    pi.pImageIndices = &index;
    VkResult each = VK_RESULT_MAX_ENUM;
    pi.pResults = &each;
    VkResult r = vkQueuePresentKHR(queue, &pi);
    if (r == VK_SUCCESS) {
      EXPECT_EQ(each, VK_SUCCESS);
    }
    return r;
  }
  // A fresh folder for VKRT_PRESENT_DIR (removed with its files by TearDown).
  void usePresentDir() {
    char path[] = "/tmp/vkrt-frames-XXXXXX";
    ASSERT_NE(mkdtemp(path), nullptr);
    presentDir = path;
    setenv("VKRT_PRESENT_DIR", path, 1);
  }
  std::vector<std::string> frameFiles() const {
    std::vector<std::string> names;
    if (DIR* d = opendir(presentDir.c_str())) {
      while (dirent* e = readdir(d))
        if (e->d_name[0] != '.') names.push_back(e->d_name);
      closedir(d);
    }
    std::sort(names.begin(), names.end());
    return names;
  }

  static constexpr uint32_t kWidth = 7, kHeight = 5;
  VkSurfaceKHR surface = VK_NULL_HANDLE;
  std::vector<VkSwapchainKHR> swapchains;
  std::vector<VkSemaphore> semaphores;
  std::vector<VkFence> fences;
  std::vector<VkCommandBuffer> submitted;
  std::string presentDir;
};

TEST_F(SwapchainTest, SurfaceQueriesDescribeTheHeadlessSurface) {
  VkBool32 supported = VK_FALSE;
  ASSERT_EQ(vkGetPhysicalDeviceSurfaceSupportKHR(physicalDevice, 0, surface, &supported), VK_SUCCESS);
  EXPECT_TRUE(supported);
  VkSurfaceCapabilitiesKHR caps;
  ASSERT_EQ(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(physicalDevice, surface, &caps), VK_SUCCESS);
  // What the specification requires of every surface.
  EXPECT_GE(caps.minImageCount, 1u);
  EXPECT_TRUE(caps.maxImageCount == 0 || caps.maxImageCount >= caps.minImageCount);
  EXPECT_TRUE(caps.supportedUsageFlags & VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT);
  EXPECT_TRUE(caps.supportedTransforms & caps.currentTransform);
  uint32_t n = 0;
  ASSERT_EQ(vkGetPhysicalDeviceSurfacePresentModesKHR(physicalDevice, surface, &n, nullptr), VK_SUCCESS);
  std::vector<VkPresentModeKHR> modes(n);
  ASSERT_EQ(vkGetPhysicalDeviceSurfacePresentModesKHR(physicalDevice, surface, &n, modes.data()), VK_SUCCESS);
  EXPECT_NE(std::find(modes.begin(), modes.end(), VK_PRESENT_MODE_FIFO_KHR), modes.end());
  ASSERT_EQ(vkGetPhysicalDeviceSurfaceFormatsKHR(physicalDevice, surface, &n, nullptr), VK_SUCCESS);
  std::vector<VkSurfaceFormatKHR> formats(n);
  ASSERT_GE(n, 2u);
  uint32_t one = 1;
  EXPECT_EQ(vkGetPhysicalDeviceSurfaceFormatsKHR(physicalDevice, surface, &one, formats.data()), VK_INCOMPLETE);
  ASSERT_EQ(vkGetPhysicalDeviceSurfaceFormatsKHR(physicalDevice, surface, &n, formats.data()), VK_SUCCESS);
  if (!onVkrt()) return;
  // vkrt's headless surface: no size of its own, 2..8 images, what its images can be used for, the four formats.
  EXPECT_EQ(caps.currentExtent.width, 0xFFFFFFFFu);
  EXPECT_EQ(caps.currentExtent.height, 0xFFFFFFFFu);
  EXPECT_EQ(caps.minImageCount, 2u);
  EXPECT_EQ(caps.maxImageCount, 8u);
  EXPECT_EQ(
      caps.supportedUsageFlags,
      VkImageUsageFlags(VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_SAMPLED_BIT |
                        VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT));
  EXPECT_EQ(modes, (std::vector<VkPresentModeKHR>{VK_PRESENT_MODE_FIFO_KHR, VK_PRESENT_MODE_IMMEDIATE_KHR}));
  std::vector<VkFormat> fs;
  for (auto& f : formats) {
    EXPECT_EQ(f.colorSpace, VK_COLOR_SPACE_SRGB_NONLINEAR_KHR);
    fs.push_back(f.format);
  }
  EXPECT_EQ(fs, (std::vector<VkFormat>{VK_FORMAT_B8G8R8A8_UNORM, VK_FORMAT_B8G8R8A8_SRGB, VK_FORMAT_R8G8B8A8_UNORM,
                                       VK_FORMAT_R8G8B8A8_SRGB}));
}

TEST_F(SwapchainTest, FramesArePresentedInOrderAndWrittenAsFiles) {
  usePresentDir();
  VkSwapchainKHR sc = makeSwapchain(2);
  auto imgs = images(sc);
  ASSERT_GE(imgs.size(), 2u);
  VkSemaphore acquired = semaphore(), rendered = semaphore();
  VkFence acquireFence = fence(), done = fence();
  std::vector<uint32_t> order;
  const int frames = 5;
  for (int f = 0; f < frames; ++f) {
    uint32_t index = 99;
    ASSERT_EQ(vkAcquireNextImageKHR(device, sc, UINT64_MAX, acquired, acquireFence, &index), VK_SUCCESS);
    ASSERT_LT(index, imgs.size());
    // The fence of an acquire is signaled once the image may be written.
    ASSERT_EQ(vkWaitForFences(device, 1, &acquireFence, VK_TRUE, UINT64_MAX), VK_SUCCESS);
    ASSERT_EQ(vkResetFences(device, 1, &acquireFence), VK_SUCCESS);
    order.push_back(index);
    const float color[4] = {f / 4.0f, 1.0f - f / 4.0f, 0.5f, 1.0f};
    clearImage(imgs[index], color, acquired, rendered, done);
    ASSERT_EQ(present(sc, index, rendered), VK_SUCCESS);
    ASSERT_EQ(vkWaitForFences(device, 1, &done, VK_TRUE, UINT64_MAX), VK_SUCCESS);
    ASSERT_EQ(vkResetFences(device, 1, &done), VK_SUCCESS);
  }
  ASSERT_EQ(vkQueueWaitIdle(queue), VK_SUCCESS);
  if (!onVkrt()) return;
  // vkrt hands images out in presentation order: round robin.
  for (int f = 0; f < frames; ++f) EXPECT_EQ(order[f], f % imgs.size()) << "frame " << f;
  // One PNG per present, in order, each the cleared colour (RGB; 8-bit UNORM rounding).
  auto files = frameFiles();
  ASSERT_EQ(files.size(), size_t(frames));
  for (int f = 0; f < frames; ++f) {
    int w = 0, h = 0, ch = 0;
    std::string path = presentDir + "/" + files[f];
    unsigned char* px = stbi_load(path.c_str(), &w, &h, &ch, 0);
    ASSERT_NE(px, nullptr) << path;
    EXPECT_EQ(w, int(kWidth));
    EXPECT_EQ(h, int(kHeight));
    EXPECT_EQ(ch, 3);
    const int expect[3] = {int(f / 4.0f * 255 + 0.5f), int((1.0f - f / 4.0f) * 255 + 0.5f), 128};
    for (int i = 0; i < w * h; ++i)
      for (int c = 0; c < 3; ++c) ASSERT_EQ(px[i * 3 + c], expect[c]) << path << " pixel " << i << " channel " << c;
    stbi_image_free(px);
  }
}

TEST_F(SwapchainTest, AcquireWaitsForThePresentOfTheImage) {
  // vkrt's order: with every image acquired, none is available until one is presented.
  if (!onVkrt()) GTEST_SKIP() << "which image an acquire returns is the implementation's choice";
  VkSwapchainKHR sc = makeSwapchain(2, VK_PRESENT_MODE_IMMEDIATE_KHR);
  const uint32_t n = static_cast<uint32_t>(images(sc).size());
  std::vector<VkFence> acquireFences;
  for (uint32_t i = 0; i < n; ++i) {
    acquireFences.push_back(fence());
    uint32_t index = 99;
    ASSERT_EQ(vkAcquireNextImageKHR(device, sc, 1000000000, VK_NULL_HANDLE, acquireFences[i], &index), VK_SUCCESS);
    EXPECT_EQ(index, i);
  }
  ASSERT_EQ(vkWaitForFences(device, n, acquireFences.data(), VK_TRUE, UINT64_MAX), VK_SUCCESS);
  VkFence more = fence();
  uint32_t index = 99;
  EXPECT_EQ(vkAcquireNextImageKHR(device, sc, 0, VK_NULL_HANDLE, more, &index), VK_NOT_READY);
  EXPECT_EQ(vkAcquireNextImageKHR(device, sc, 1000000, VK_NULL_HANDLE, more, &index), VK_TIMEOUT);
  EXPECT_EQ(vkGetFenceStatus(device, more), VK_NOT_READY);
  // Image 1 is presented behind a submission whose semaphore the present waits for: the next acquire returns
  // image 1 once that present has executed, and signals its fence then.
  VkSemaphore rendered = semaphore();
  const float color[4] = {0, 0, 0, 1};
  clearImage(images(sc)[1], color, VK_NULL_HANDLE, rendered, VK_NULL_HANDLE);
  ASSERT_EQ(present(sc, 1, rendered), VK_SUCCESS);
  ASSERT_EQ(vkAcquireNextImageKHR(device, sc, 5000000000ull, VK_NULL_HANDLE, more, &index), VK_SUCCESS);
  EXPECT_EQ(index, 1u);
  EXPECT_EQ(vkGetFenceStatus(device, more), VK_SUCCESS);
  // Present what is still held (in PRESENT_SRC layout), so that the swapchain is idle when destroyed.
  for (uint32_t i = 0; i < n; ++i)
    if (i != 1) clearImage(images(sc)[i], color, VK_NULL_HANDLE, VK_NULL_HANDLE, VK_NULL_HANDLE);
  ASSERT_EQ(vkQueueWaitIdle(queue), VK_SUCCESS);
  for (uint32_t i = 0; i < n; ++i) ASSERT_EQ(present(sc, i, VK_NULL_HANDLE), VK_SUCCESS);
}

TEST_F(SwapchainTest, AReplacedSwapchainKeepsPresentingWhatItHandedOut) {
  VkSwapchainKHR a = makeSwapchain(2);
  auto imgs = images(a);
  VkFence f = fence();
  uint32_t index = 99;
  ASSERT_EQ(vkAcquireNextImageKHR(device, a, 1000000000, VK_NULL_HANDLE, f, &index), VK_SUCCESS);
  ASSERT_EQ(vkWaitForFences(device, 1, &f, VK_TRUE, UINT64_MAX), VK_SUCCESS);
  const float color[4] = {1, 0, 0, 1};
  clearImage(imgs[index], color, VK_NULL_HANDLE, VK_NULL_HANDLE, VK_NULL_HANDLE);
  ASSERT_EQ(vkQueueWaitIdle(queue), VK_SUCCESS);
  VkSwapchainKHR b = makeSwapchain(3, VK_PRESENT_MODE_FIFO_KHR, a);
  ASSERT_NE(b, VK_NULL_HANDLE);
  EXPECT_GE(images(b).size(), 3u);
  EXPECT_EQ(present(a, index, VK_NULL_HANDLE), VK_SUCCESS);
  ASSERT_EQ(vkQueueWaitIdle(queue), VK_SUCCESS);
}

TEST_F(SwapchainTest, AnImageBoundToASwapchainImageAliasesIt) {
  // Vulkan 1.1's VK_KHR_swapchain: VkImageSwapchainCreateInfoKHR and VkBindImageMemorySwapchainInfoKHR.
  usePresentDir();
  VkSwapchainKHR sc = makeSwapchain(2);
  auto imgs = images(sc);
  VkImageSwapchainCreateInfoKHR isci{VK_STRUCTURE_TYPE_IMAGE_SWAPCHAIN_CREATE_INFO_KHR, nullptr, sc};
  VkImageCreateInfo ici{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO, &isci};
  ici.imageType = VK_IMAGE_TYPE_2D;
  ici.format = VK_FORMAT_R8G8B8A8_UNORM;
  ici.extent = {kWidth, kHeight, 1};
  ici.mipLevels = 1;
  ici.arrayLayers = 1;
  ici.samples = VK_SAMPLE_COUNT_1_BIT;
  ici.tiling = VK_IMAGE_TILING_OPTIMAL;
  ici.usage = VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  ici.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  VkImage alias = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateImage(device, &ici, nullptr, &alias), VK_SUCCESS);
  VkFence f = fence();
  uint32_t index = 99;
  ASSERT_EQ(vkAcquireNextImageKHR(device, sc, 1000000000, VK_NULL_HANDLE, f, &index), VK_SUCCESS);
  ASSERT_EQ(vkWaitForFences(device, 1, &f, VK_TRUE, UINT64_MAX), VK_SUCCESS);
  VkBindImageMemorySwapchainInfoKHR bsi{VK_STRUCTURE_TYPE_BIND_IMAGE_MEMORY_SWAPCHAIN_INFO_KHR, nullptr, sc, index};
  VkBindImageMemoryInfo bi{VK_STRUCTURE_TYPE_BIND_IMAGE_MEMORY_INFO, &bsi, alias, VK_NULL_HANDLE, 0};
  ASSERT_EQ(vkBindImageMemory2(device, 1, &bi), VK_SUCCESS);
  // Written through the alias, presented through the swapchain image (which the clear also moves to PRESENT_SRC).
  const float color[4] = {0.0f, 0.0f, 1.0f, 1.0f};
  clearImage(alias, color, VK_NULL_HANDLE, VK_NULL_HANDLE, VK_NULL_HANDLE);
  clearImage(imgs[index], color, VK_NULL_HANDLE, VK_NULL_HANDLE, VK_NULL_HANDLE);
  ASSERT_EQ(vkQueueWaitIdle(queue), VK_SUCCESS);
  ASSERT_EQ(present(sc, index, VK_NULL_HANDLE), VK_SUCCESS);
  ASSERT_EQ(vkQueueWaitIdle(queue), VK_SUCCESS);
  vkDestroyImage(device, alias, nullptr);
  if (!onVkrt()) return;
  auto files = frameFiles();
  ASSERT_EQ(files.size(), 1u);
  int w = 0, h = 0, ch = 0;
  unsigned char* px = stbi_load((presentDir + "/" + files[0]).c_str(), &w, &h, &ch, 3);
  ASSERT_NE(px, nullptr);
  EXPECT_EQ(px[0], 0);
  EXPECT_EQ(px[2], 255);
  stbi_image_free(px);
}

// Misuse that vkrt reports by VUID (the layer, which would report the same, is off).
class SwapchainMisuseTest : public SwapchainTest {
 protected:
  bool layer() override { return false; }
  void SetUp() override {
    SwapchainTest::SetUp();
    if (HasFatalFailure() || IsSkipped() || !device) return;
    if (!onVkrt()) GTEST_SKIP() << "vkrt's own diagnostics";
  }
};

TEST_F(SwapchainMisuseTest, PresentingAnImageNotAcquiredIsReported) {
  usePresentDir();
  VkSwapchainKHR sc = makeSwapchain(2);
  EXPECT_EQ(present(sc, 0, VK_NULL_HANDLE), VK_ERROR_VALIDATION_FAILED_EXT);
  auto msgs = vkrtMessages();
  ASSERT_EQ(msgs.size(), 1u);
  EXPECT_NE(msgs[0].text.find("pImageIndices[0] = 0 was not acquired"), std::string::npos) << msgs[0].text;
  expectVkrtMessage("VUID-VkPresentInfoKHR-pImageIndices-01430");
  EXPECT_EQ(present(sc, 17, VK_NULL_HANDLE), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkPresentInfoKHR-pImageIndices-01430");
  VkPresentInfoKHR none{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
  EXPECT_EQ(vkQueuePresentKHR(queue, &none), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkPresentInfoKHR-swapchainCount-arraylength");
  // Presented twice: the second present names the image being presented (or, once it ran, not acquired).
  VkFence f = fence();
  uint32_t index = 99;
  ASSERT_EQ(vkAcquireNextImageKHR(device, sc, 1000000000, VK_NULL_HANDLE, f, &index), VK_SUCCESS);
  const float color[4] = {1, 1, 1, 1};
  clearImage(images(sc)[index], color, VK_NULL_HANDLE, VK_NULL_HANDLE, VK_NULL_HANDLE);
  ASSERT_EQ(present(sc, index, VK_NULL_HANDLE), VK_SUCCESS);
  EXPECT_EQ(present(sc, index, VK_NULL_HANDLE), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkPresentInfoKHR-pImageIndices-01430");
  ASSERT_EQ(vkQueueWaitIdle(queue), VK_SUCCESS);
  // Refused presents write nothing: one frame file.
  EXPECT_EQ(frameFiles().size(), 1u);
}

TEST_F(SwapchainMisuseTest, PresentingAnImageNotInPresentLayoutIsReportedWhenItExecutes) {
  VkSwapchainKHR sc = makeSwapchain(2);
  auto imgs = images(sc);
  VkFence f = fence();
  uint32_t index = 99;
  ASSERT_EQ(vkAcquireNextImageKHR(device, sc, 1000000000, VK_NULL_HANDLE, f, &index), VK_SUCCESS);
  // Never transitioned: UNDEFINED.
  ASSERT_EQ(present(sc, index, VK_NULL_HANDLE), VK_SUCCESS);
  ASSERT_EQ(vkQueueWaitIdle(queue), VK_SUCCESS);
  auto msgs = vkrtMessages();
  ASSERT_EQ(msgs.size(), 1u);
  EXPECT_NE(msgs[0].text.find("is in layout 0 when the present executes"), std::string::npos) << msgs[0].text;
  expectVkrtMessage("VUID-VkPresentInfoKHR-pImageIndices-01430");
  // Transitioned to PRESENT_SRC by clearImage's last barrier: nothing to report.
  ASSERT_EQ(vkResetFences(device, 1, &f), VK_SUCCESS);
  ASSERT_EQ(vkAcquireNextImageKHR(device, sc, 1000000000, VK_NULL_HANDLE, f, &index), VK_SUCCESS);
  const float color[4] = {1, 1, 1, 1};
  clearImage(imgs[index], color, VK_NULL_HANDLE, VK_NULL_HANDLE, VK_NULL_HANDLE);
  ASSERT_EQ(present(sc, index, VK_NULL_HANDLE), VK_SUCCESS);
  ASSERT_EQ(vkQueueWaitIdle(queue), VK_SUCCESS);
  EXPECT_TRUE(vkrtMessages().empty());
}

TEST_F(SwapchainMisuseTest, PresentWaitingOnASemaphoreNothingSignalsIsReported) {
  VkSwapchainKHR sc = makeSwapchain(2);
  VkFence f = fence();
  uint32_t index = 99;
  ASSERT_EQ(vkAcquireNextImageKHR(device, sc, 1000000000, VK_NULL_HANDLE, f, &index), VK_SUCCESS);
  EXPECT_EQ(present(sc, index, semaphore()), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-vkQueuePresentKHR-pWaitSemaphores-03268");
  const float color[4] = {1, 1, 1, 1};
  clearImage(images(sc)[index], color, VK_NULL_HANDLE, VK_NULL_HANDLE, VK_NULL_HANDLE);
  ASSERT_EQ(present(sc, index, VK_NULL_HANDLE), VK_SUCCESS);
  ASSERT_EQ(vkQueueWaitIdle(queue), VK_SUCCESS);
}

TEST_F(SwapchainMisuseTest, AcquireMisuseIsReported) {
  VkSwapchainKHR sc = makeSwapchain(2);
  uint32_t index = 99;
  EXPECT_EQ(vkAcquireNextImageKHR(device, sc, 0, VK_NULL_HANDLE, VK_NULL_HANDLE, &index),
            VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-vkAcquireNextImageKHR-semaphore-01780");
  VkFence f = fence();
  ASSERT_EQ(vkAcquireNextImageKHR(device, sc, 0, VK_NULL_HANDLE, f, &index), VK_SUCCESS);
  // The fence is signaled now.
  EXPECT_EQ(vkAcquireNextImageKHR(device, sc, 0, VK_NULL_HANDLE, f, &index), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-vkAcquireNextImageKHR-fence-01287");
  VkSemaphore s = semaphore();
  ASSERT_EQ(vkAcquireNextImageKHR(device, sc, 0, s, VK_NULL_HANDLE, &index), VK_SUCCESS);
  // The semaphore is signaled and nothing waited on it.
  EXPECT_EQ(vkAcquireNextImageKHR(device, sc, 0, s, VK_NULL_HANDLE, &index), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-vkAcquireNextImageKHR-semaphore-01286");
  // A retired swapchain hands out nothing more.
  VkSwapchainKHR next = makeSwapchain(2, VK_PRESENT_MODE_FIFO_KHR, sc);
  ASSERT_NE(next, VK_NULL_HANDLE);
  EXPECT_EQ(vkAcquireNextImageKHR(device, sc, 0, VK_NULL_HANDLE, fence(), &index), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-vkAcquireNextImageKHR-swapchain-01285");
}

TEST_F(SwapchainMisuseTest, DestroyingASwapchainImageIsReported) {
  VkSwapchainKHR sc = makeSwapchain(2);
  auto imgs = images(sc);
  vkDestroyImage(device, imgs[0], nullptr);
  expectVkrtMessage("VUID-vkDestroyImage-image-04882");
  // The image is still the swapchain's: it is acquired, written and presented as before.
  VkFence f = fence();
  uint32_t index = 99;
  ASSERT_EQ(vkAcquireNextImageKHR(device, sc, 1000000000, VK_NULL_HANDLE, f, &index), VK_SUCCESS);
  ASSERT_EQ(index, 0u);
  const float color[4] = {1, 1, 1, 1};
  clearImage(imgs[0], color, VK_NULL_HANDLE, VK_NULL_HANDLE, VK_NULL_HANDLE);
  ASSERT_EQ(present(sc, 0, VK_NULL_HANDLE), VK_SUCCESS);
  ASSERT_EQ(vkQueueWaitIdle(queue), VK_SUCCESS);
}

TEST_F(SwapchainMisuseTest, SwapchainCreateInfoOutsideTheSurfaceIsReported) {
  VkSwapchainCreateInfoKHR ci{VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR};
  ci.surface = surface;
  ci.minImageCount = 2;
  ci.imageFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
  ci.imageColorSpace = VK_COLOR_SPACE_SRGB_NONLINEAR_KHR;
  ci.imageExtent = {kWidth, kHeight};
  ci.imageArrayLayers = 1;
  ci.imageUsage = VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  ci.preTransform = VK_SURFACE_TRANSFORM_IDENTITY_BIT_KHR;
  ci.compositeAlpha = VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR;
  ci.presentMode = VK_PRESENT_MODE_FIFO_KHR;
  VkSwapchainKHR s = VK_NULL_HANDLE;
  EXPECT_EQ(vkCreateSwapchainKHR(device, &ci, nullptr, &s), VK_ERROR_VALIDATION_FAILED_EXT);
  EXPECT_EQ(s, VK_NULL_HANDLE);
  expectVkrtMessage("VUID-VkSwapchainCreateInfoKHR-imageFormat-01273");
  ci.imageFormat = VK_FORMAT_B8G8R8A8_SRGB;
  ci.minImageCount = 9;
  EXPECT_EQ(vkCreateSwapchainKHR(device, &ci, nullptr, &s), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkSwapchainCreateInfoKHR-minImageCount-01272");
  ci.minImageCount = 2;
  ci.presentMode = VK_PRESENT_MODE_MAILBOX_KHR;
  EXPECT_EQ(vkCreateSwapchainKHR(device, &ci, nullptr, &s), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkSwapchainCreateInfoKHR-presentMode-01281");
}

TEST_F(SwapchainMisuseTest, DeviceGroupCallsOutsideTheOneDeviceGroupAreReported) {
  // vkrt's device group has one device: no peer memory to ask about, and device mask 1 only.
  VkPeerMemoryFeatureFlags flags = 0xff;
  vkGetDeviceGroupPeerMemoryFeatures(device, 0, 0, 0, &flags);
  EXPECT_EQ(flags, 0u);
  expectVkrtMessage("VUID-vkGetDeviceGroupPeerMemoryFeatures-localDeviceIndex-00694");
  VkCommandBuffer cb = beginOneTime();
  vkCmdSetDeviceMask(cb, 1);
  EXPECT_TRUE(vkrtMessages().empty());
  vkCmdSetDeviceMask(cb, 2);
  expectVkrtMessage("VUID-vkCmdSetDeviceMask-deviceMask-00108");
  vkCmdSetDeviceMask(cb, 0);
  expectVkrtMessage("VUID-vkCmdSetDeviceMask-deviceMask-00109");
  submitAndWait(cb);
}

}  // namespace
}  // namespace vkrt::test
