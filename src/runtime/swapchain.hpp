// VkSwapchainKHR on a headless surface (runtime/surface.hpp).
//
// The presentable images are ordinary vkrt images (linear layout, runtime/image.hpp) bound to memory the swapchain
// allocates. Each image is available, acquired (by the application) or being presented. vkAcquireNextImageKHR hands
// out the images in the order they were presented (round robin from image 0), waiting up to `timeout` for the
// present of the oldest one to finish, and then signals the semaphore and fence at once. vkQueuePresentKHR is a
// queue operation: it is queued behind the earlier submissions of its queue, waits for its semaphores there, then
// writes the image to VKRT_PRESENT_DIR (when set) and makes it available again. The swapchain's images are the only
// ones whose layout vkrt tracks (Image::trackedLayout, set by the barriers as they execute): a present of an image
// not in PRESENT_SRC_KHR layout is reported when it executes. A swapchain never becomes
// out of date or suboptimal: a headless surface never changes.
#pragma once

#include <cstdint>
#include <deque>
#include <vector>

#include "runtime/object.hpp"

namespace vkrt {

class Image;
class Surface;

class Swapchain : public Object {
 public:
  using Handle = VkSwapchainKHR;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_SWAPCHAIN_KHR;

  enum class State { Available, Acquired, Presenting };

  Swapchain(Device* dev, Surface* surface, const VkSwapchainCreateInfoKHR& info);

  Surface* const surface;
  const VkFormat format;
  const VkExtent2D extent;
  const VkImageUsageFlags usage;
  const VkPresentModeKHR presentMode;

  std::vector<VkImage> images;
  VkDeviceMemory memory = VK_NULL_HANDLE;

  // Guarded by sync::mutex() (runtime/fence.hpp); changes are announced on sync::changed().
  std::vector<State> states;
  std::deque<uint32_t> order;  // images not acquired, oldest presented first
  bool retired = false;        // replaced by a newer swapchain (oldSwapchain)
  uint32_t presentsPending = 0;
};

}  // namespace vkrt
