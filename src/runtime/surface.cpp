#include "runtime/surface.hpp"

#include <algorithm>

#include "runtime/alloc.hpp"
#include "runtime/instance.hpp"
#include "runtime/physical_device.hpp"
#include "runtime/report.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {

Surface::Surface(Instance* inst) : Object(kType, inst, nullptr) {}

VkSurfaceCapabilitiesKHR headlessCapabilities() {
  VkSurfaceCapabilitiesKHR c{};
  c.minImageCount = 2;
  c.maxImageCount = 8;
  // A headless surface has no size of its own: the swapchain's imageExtent decides it.
  c.currentExtent = {0xFFFFFFFFu, 0xFFFFFFFFu};
  c.minImageExtent = {1, 1};
  c.maxImageExtent = {16384, 16384};  // maxImageDimension2D
  c.maxImageArrayLayers = 1;
  c.supportedTransforms = VK_SURFACE_TRANSFORM_IDENTITY_BIT_KHR;
  c.currentTransform = VK_SURFACE_TRANSFORM_IDENTITY_BIT_KHR;
  c.supportedCompositeAlpha = VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR;
  // COLOR_ATTACHMENT (required by the spec) is real: every surface format is a color attachment format
  // (runtime/format.cpp). STORAGE holds for the UNORM formats only (sRGB formats have no storage feature).
  c.supportedUsageFlags = VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT |
                          VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT;
  return c;
}

const std::vector<VkSurfaceFormatKHR>& headlessFormats() {
  static const std::vector<VkSurfaceFormatKHR> formats = {
      {VK_FORMAT_B8G8R8A8_UNORM, VK_COLOR_SPACE_SRGB_NONLINEAR_KHR},
      {VK_FORMAT_B8G8R8A8_SRGB, VK_COLOR_SPACE_SRGB_NONLINEAR_KHR},
      {VK_FORMAT_R8G8B8A8_UNORM, VK_COLOR_SPACE_SRGB_NONLINEAR_KHR},
      {VK_FORMAT_R8G8B8A8_SRGB, VK_COLOR_SPACE_SRGB_NONLINEAR_KHR},
  };
  return formats;
}

const std::vector<VkPresentModeKHR>& headlessPresentModes() {
  static const std::vector<VkPresentModeKHR> modes = {VK_PRESENT_MODE_FIFO_KHR, VK_PRESENT_MODE_IMMEDIATE_KHR};
  return modes;
}

}  // namespace vkrt

using namespace vkrt;

namespace {

template <class T>
VkResult enumerate(const std::vector<T>& all, uint32_t* count, T* out) {
  if (!out) {
    *count = static_cast<uint32_t>(all.size());
    return VK_SUCCESS;
  }
  uint32_t n = std::min<uint32_t>(*count, static_cast<uint32_t>(all.size()));
  std::copy_n(all.begin(), n, out);
  *count = n;
  return n < all.size() ? VK_INCOMPLETE : VK_SUCCESS;
}

// The live surface behind `h`, or a report naming the command and the VUID.
Surface* liveSurface(const Object* about, VkSurfaceKHR h, const char* fn, const char* vuid) {
  Surface* s = fromHandle<Surface>(h);
  if (!s)
    report(about, Severity::Error, vuid, "%s: surface 0x%llx is not a live VkSurfaceKHR", fn,
           (unsigned long long)rawHandle(h));
  return s;
}

}  // namespace

extern "C" {

VKAPI_ATTR VkResult VKAPI_CALL vkrt_CreateHeadlessSurfaceEXT(VkInstance instance,
                                                             const VkHeadlessSurfaceCreateInfoEXT* pCreateInfo,
                                                             const VkAllocationCallbacks* pAllocator,
                                                             VkSurfaceKHR* pSurface) {
  (void)pCreateInfo;  // flags are reserved
  Instance* inst = fromHandle<Instance>(instance);
  if (!inst) {
    report(nullptr, Severity::Error, "VUID-vkCreateHeadlessSurfaceEXT-instance-parameter",
           "vkCreateHeadlessSurfaceEXT: 0x%llx is not a live VkInstance", (unsigned long long)rawHandle(instance));
    return VK_ERROR_INITIALIZATION_FAILED;
  }
  Surface* s = createObject<Surface>(pAllocator, VK_SYSTEM_ALLOCATION_SCOPE_OBJECT, inst);
  if (!s) return VK_ERROR_OUT_OF_HOST_MEMORY;
  *pSurface = toHandle(s);
  return VK_SUCCESS;
}

VKAPI_ATTR void VKAPI_CALL vkrt_DestroySurfaceKHR(VkInstance instance, VkSurfaceKHR surface,
                                                  const VkAllocationCallbacks* pAllocator) {
  if (!surface) return;
  if (Surface* s = liveSurface(fromHandle<Instance>(instance), surface, "vkDestroySurfaceKHR",
                               "VUID-vkDestroySurfaceKHR-surface-parameter"))
    destroyObject(s, pAllocator);
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_GetPhysicalDeviceSurfaceSupportKHR(VkPhysicalDevice physicalDevice,
                                                                       uint32_t queueFamilyIndex, VkSurfaceKHR surface,
                                                                       VkBool32* pSupported) {
  PhysicalDevice* pd = fromHandleUnchecked<PhysicalDevice>(physicalDevice);
  const char* fn = "vkGetPhysicalDeviceSurfaceSupportKHR";
  if (!liveSurface(pd, surface, fn, "VUID-vkGetPhysicalDeviceSurfaceSupportKHR-surface-parameter"))
    return VK_ERROR_SURFACE_LOST_KHR;
  // VUID-vkGetPhysicalDeviceSurfaceSupportKHR-queueFamilyIndex-01269
  if (queueFamilyIndex >= PhysicalDevice::kQueueFamilyCount) {
    report(pd, Severity::Error, "VUID-vkGetPhysicalDeviceSurfaceSupportKHR-queueFamilyIndex-01269",
           "%s: queueFamilyIndex %u is not less than the %u queue families vkrt reports", fn, queueFamilyIndex,
           PhysicalDevice::kQueueFamilyCount);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  *pSupported = VK_TRUE;
  return VK_SUCCESS;
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_GetPhysicalDeviceSurfaceCapabilitiesKHR(
    VkPhysicalDevice physicalDevice, VkSurfaceKHR surface, VkSurfaceCapabilitiesKHR* pSurfaceCapabilities) {
  PhysicalDevice* pd = fromHandleUnchecked<PhysicalDevice>(physicalDevice);
  if (!liveSurface(pd, surface, "vkGetPhysicalDeviceSurfaceCapabilitiesKHR",
                   "VUID-vkGetPhysicalDeviceSurfaceCapabilitiesKHR-surface-parameter"))
    return VK_ERROR_SURFACE_LOST_KHR;
  *pSurfaceCapabilities = headlessCapabilities();
  return VK_SUCCESS;
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_GetPhysicalDeviceSurfaceFormatsKHR(VkPhysicalDevice physicalDevice,
                                                                       VkSurfaceKHR surface,
                                                                       uint32_t* pSurfaceFormatCount,
                                                                       VkSurfaceFormatKHR* pSurfaceFormats) {
  PhysicalDevice* pd = fromHandleUnchecked<PhysicalDevice>(physicalDevice);
  if (!liveSurface(pd, surface, "vkGetPhysicalDeviceSurfaceFormatsKHR",
                   "VUID-vkGetPhysicalDeviceSurfaceFormatsKHR-surface-parameter"))
    return VK_ERROR_SURFACE_LOST_KHR;
  return enumerate(headlessFormats(), pSurfaceFormatCount, pSurfaceFormats);
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_GetPhysicalDeviceSurfacePresentModesKHR(VkPhysicalDevice physicalDevice,
                                                                            VkSurfaceKHR surface,
                                                                            uint32_t* pPresentModeCount,
                                                                            VkPresentModeKHR* pPresentModes) {
  PhysicalDevice* pd = fromHandleUnchecked<PhysicalDevice>(physicalDevice);
  if (!liveSurface(pd, surface, "vkGetPhysicalDeviceSurfacePresentModesKHR",
                   "VUID-vkGetPhysicalDeviceSurfacePresentModesKHR-surface-parameter"))
    return VK_ERROR_SURFACE_LOST_KHR;
  return enumerate(headlessPresentModes(), pPresentModeCount, pPresentModes);
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_GetPhysicalDevicePresentRectanglesKHR(VkPhysicalDevice physicalDevice,
                                                                          VkSurfaceKHR surface, uint32_t* pRectCount,
                                                                          VkRect2D* pRects) {
  PhysicalDevice* pd = fromHandleUnchecked<PhysicalDevice>(physicalDevice);
  if (!liveSurface(pd, surface, "vkGetPhysicalDevicePresentRectanglesKHR",
                   "VUID-vkGetPhysicalDevicePresentRectanglesKHR-surface-parameter"))
    return VK_ERROR_SURFACE_LOST_KHR;
  // The one device presents all of a headless surface, whose size is the swapchain's (at most maxImageExtent).
  VkSurfaceCapabilitiesKHR c = headlessCapabilities();
  return enumerate(std::vector<VkRect2D>{{{0, 0}, c.maxImageExtent}}, pRectCount, pRects);
}

}  // extern "C"
