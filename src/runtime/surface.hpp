// VkSurfaceKHR: the headless surface of VK_EXT_headless_surface, and the surface queries of VK_KHR_surface.
//
// A headless surface has no window: its size is whatever the swapchain says (currentExtent is the special value
// 0xFFFFFFFF), it is always supported by vkrt's one queue family, and what is presented to it goes nowhere,
// unless VKRT_PRESENT_DIR names a folder to write each presented image to (runtime/swapchain.cpp).
//
// The loader (interface version >= 3) asks vkrt for its own surface through vkCreateHeadlessSurfaceEXT and hands
// that handle to every vkrt call that takes a surface, so a surface vkrt is given is always one of its own.
#pragma once

#include <vector>

#include "runtime/object.hpp"

namespace vkrt {

class Surface : public Object {
 public:
  using Handle = VkSurfaceKHR;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_SURFACE_KHR;

  explicit Surface(Instance* inst);
};

// What every headless surface supports (the swapchain checks its create info against these).
VkSurfaceCapabilitiesKHR headlessCapabilities();
const std::vector<VkSurfaceFormatKHR>& headlessFormats();
const std::vector<VkPresentModeKHR>& headlessPresentModes();

}  // namespace vkrt
