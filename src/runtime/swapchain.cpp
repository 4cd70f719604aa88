#include "runtime/swapchain.hpp"

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "runtime/alloc.hpp"
#include "runtime/device.hpp"
#include "runtime/fence.hpp"
#include "runtime/image.hpp"
#include "runtime/lookup.hpp"
#include "runtime/queue.hpp"
#include "runtime/report.hpp"
#include "runtime/semaphore.hpp"
#include "runtime/surface.hpp"
#include "vkrt_entrypoints.h"

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wall"
#pragma GCC diagnostic ignored "-Wextra"
#pragma GCC diagnostic ignored "-Wconversion"
#pragma GCC diagnostic ignored "-Wsign-conversion"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>
#pragma GCC diagnostic pop

namespace vkrt {

Swapchain::Swapchain(Device* dev, Surface* s, const VkSwapchainCreateInfoKHR& info)
    : Object(kType, dev->instance, dev),
      surface(s),
      format(info.imageFormat),
      extent(info.imageExtent),
      usage(info.imageUsage),
      presentMode(info.presentMode) {}

}  // namespace vkrt

using namespace vkrt;

namespace {

// Presents are numbered in the order they execute, over the whole process: frame-000000.png, frame-000001.png...
std::atomic<uint32_t> g_frameNumber{0};

// VKRT_PRESENT_DIR: the folder presented images are written to as PNG files (unset or empty: not written).
const char* presentDir() {
  const char* d = std::getenv("VKRT_PRESENT_DIR");
  return d && *d ? d : nullptr;
}

// Writes layer 0 of a presented image as an 8-bit RGB PNG (the surface's composite alpha is OPAQUE, so alpha is
// not part of what is presented).
void writeFrame(const Swapchain& sc, uint32_t index, const char* dir) {
  uint32_t n = g_frameNumber.fetch_add(1);
  if (!dir) return;
  const Image* img = fromHandle<Image>(sc.images[index]);
  if (!img || !img->memory) return;
  const bool bgra = sc.format == VK_FORMAT_B8G8R8A8_UNORM || sc.format == VK_FORMAT_B8G8R8A8_SRGB;
  std::vector<uint8_t> rgb(size_t(sc.extent.width) * sc.extent.height * 3);
  for (uint32_t y = 0; y < sc.extent.height; ++y) {
    for (uint32_t x = 0; x < sc.extent.width; ++x) {
      const uint8_t* t = img->texel(0, 0, x, y, 0);
      uint8_t* o = &rgb[(size_t(y) * sc.extent.width + x) * 3];
      o[0] = bgra ? t[2] : t[0];
      o[1] = t[1];
      o[2] = bgra ? t[0] : t[2];
    }
  }
  char name[64];
  std::snprintf(name, sizeof(name), "/frame-%06u.png", n);
  std::string path = std::string(dir) + name;
  if (!stbi_write_png(path.c_str(), int(sc.extent.width), int(sc.extent.height), 3, rgb.data(),
                      int(sc.extent.width * 3)))
    report(&sc, Severity::Error, nullptr, "vkQueuePresentKHR: could not write %s (VKRT_PRESENT_DIR)", path.c_str());
}

// Frees what a swapchain owns (its images and their memory) and the object.
void destroySwapchain(Device* dev, Swapchain* sc, const VkAllocationCallbacks* alloc) {
  VkDevice d = toHandle(dev);
  for (VkImage i : sc->images) {
    fromHandle<Image>(i)->presentable = false;  // vkDestroyImage refuses presentable images
    vkrt_DestroyImage(d, i, nullptr);
  }
  if (sc->memory) vkrt_FreeMemory(d, sc->memory, nullptr);
  destroyObject(sc, alloc);
}

bool contains(VkFlags all, VkFlags some) { return (all & some) == some; }

}  // namespace

extern "C" {

VKAPI_ATTR VkResult VKAPI_CALL vkrt_CreateSwapchainKHR(VkDevice device, const VkSwapchainCreateInfoKHR* pCreateInfo,
                                                       const VkAllocationCallbacks* pAllocator,
                                                       VkSwapchainKHR* pSwapchain) {
  Device* dev = fromHandleUnchecked<Device>(device);
  const char* fn = "vkCreateSwapchainKHR";
  const VkSwapchainCreateInfoKHR& ci = *pCreateInfo;
  Surface* surface = liveOrReport<Surface>(dev, ci.surface, fn, "VUID-VkSwapchainCreateInfoKHR-surface-parameter");
  if (!surface) return VK_ERROR_SURFACE_LOST_KHR;
  const VkSurfaceCapabilitiesKHR caps = headlessCapabilities();
  const auto& formats = headlessFormats();
  const auto& modes = headlessPresentModes();
  auto fail = [&](const char* vuid, const char* what) {
    report(dev, Severity::Error, vuid,
           "%s: %s (minImageCount %u, format %d, color space %d, extent %ux%u, layers %u, usage 0x%x, present mode "
           "%d)",
           fn, what, ci.minImageCount, (int)ci.imageFormat, (int)ci.imageColorSpace, ci.imageExtent.width,
           ci.imageExtent.height, ci.imageArrayLayers, ci.imageUsage, (int)ci.presentMode);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  };
  // VUID-VkSwapchainCreateInfoKHR-minImageCount-01271 / -01272
  if (ci.minImageCount < caps.minImageCount)
    return fail("VUID-VkSwapchainCreateInfoKHR-minImageCount-01271", "minImageCount is below the surface's 2");
  if (ci.minImageCount > caps.maxImageCount)
    return fail("VUID-VkSwapchainCreateInfoKHR-minImageCount-01272", "minImageCount exceeds the surface's 8");
  // VUID-VkSwapchainCreateInfoKHR-imageFormat-01273
  if (std::none_of(formats.begin(), formats.end(), [&](const VkSurfaceFormatKHR& f) {
        return f.format == ci.imageFormat && f.colorSpace == ci.imageColorSpace;
      }))
    return fail("VUID-VkSwapchainCreateInfoKHR-imageFormat-01273",
                "imageFormat and imageColorSpace are not a pair vkGetPhysicalDeviceSurfaceFormatsKHR reports");
  // VUID-VkSwapchainCreateInfoKHR-imageExtent-01689 / -01274
  if (ci.imageExtent.width == 0 || ci.imageExtent.height == 0)
    return fail("VUID-VkSwapchainCreateInfoKHR-imageExtent-01689", "imageExtent has a zero dimension");
  if (ci.imageExtent.width > caps.maxImageExtent.width || ci.imageExtent.height > caps.maxImageExtent.height)
    return fail("VUID-VkSwapchainCreateInfoKHR-imageExtent-01274", "imageExtent exceeds maxImageExtent 16384x16384");
  // VUID-VkSwapchainCreateInfoKHR-imageArrayLayers-01275
  if (ci.imageArrayLayers == 0 || ci.imageArrayLayers > caps.maxImageArrayLayers)
    return fail("VUID-VkSwapchainCreateInfoKHR-imageArrayLayers-01275", "imageArrayLayers is not 1");
  // VUID-VkSwapchainCreateInfoKHR-imageUsage-requiredbitmask, VUID-VkSwapchainCreateInfoKHR-presentMode-01427
  if (ci.imageUsage == 0) return fail("VUID-VkSwapchainCreateInfoKHR-imageUsage-requiredbitmask", "imageUsage is 0");
  if (!contains(caps.supportedUsageFlags, ci.imageUsage))
    return fail(
        "VUID-VkSwapchainCreateInfoKHR-presentMode-01427",
        "imageUsage has bits outside the surface's supportedUsageFlags (transfer, sampled, storage, color attachment)");
  // VUID-VkSwapchainCreateInfoKHR-preTransform-01279, compositeAlpha-01280
  if (!contains(caps.supportedTransforms, ci.preTransform) || ci.preTransform == 0)
    return fail("VUID-VkSwapchainCreateInfoKHR-preTransform-01279", "preTransform is not IDENTITY");
  if (!contains(caps.supportedCompositeAlpha, ci.compositeAlpha) || ci.compositeAlpha == 0)
    return fail("VUID-VkSwapchainCreateInfoKHR-compositeAlpha-01280", "compositeAlpha is not OPAQUE");
  // VUID-VkSwapchainCreateInfoKHR-presentMode-01281
  if (std::find(modes.begin(), modes.end(), ci.presentMode) == modes.end())
    return fail("VUID-VkSwapchainCreateInfoKHR-presentMode-01281", "presentMode is neither FIFO nor IMMEDIATE");
  // VUID-VkSwapchainCreateInfoKHR-flags-parameter: no swapchain create flags are supported (no extension adds one)
  if (ci.flags != 0)
    return fail("VUID-VkSwapchainCreateInfoKHR-flags-parameter", "flags is not 0 (vkrt supports no swapchain flags)");
  Swapchain* old = nullptr;
  if (ci.oldSwapchain) {
    old = liveOrReport<Swapchain>(dev, ci.oldSwapchain, fn, "VUID-VkSwapchainCreateInfoKHR-oldSwapchain-parameter");
    if (!old) return VK_ERROR_VALIDATION_FAILED_EXT;
    std::lock_guard lock(sync::mutex());
    // VUID-VkSwapchainCreateInfoKHR-oldSwapchain-01933
    if (old->retired || old->surface != surface)
      return fail("VUID-VkSwapchainCreateInfoKHR-oldSwapchain-01933",
                  old->retired ? "oldSwapchain is retired" : "oldSwapchain belongs to another surface");
  }

  Swapchain* sc = createObject<Swapchain>(pAllocator, VK_SYSTEM_ALLOCATION_SCOPE_OBJECT, dev, surface, ci);
  if (!sc) return VK_ERROR_OUT_OF_HOST_MEMORY;
  // The images: what vkspec's "swapchain-wsi-image-create-info" implies, with the application's usage (color and
  // input attachment usages included: render passes render into them).
  VkImageCreateInfo ici{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  ici.imageType = VK_IMAGE_TYPE_2D;
  ici.format = ci.imageFormat;
  ici.extent = {ci.imageExtent.width, ci.imageExtent.height, 1};
  ici.mipLevels = 1;
  ici.arrayLayers = ci.imageArrayLayers;
  ici.samples = VK_SAMPLE_COUNT_1_BIT;
  ici.tiling = VK_IMAGE_TILING_OPTIMAL;
  ici.usage = ci.imageUsage;
  ici.sharingMode = ci.imageSharingMode;
  ici.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  const uint32_t count = std::max(ci.minImageCount, 3u);
  VkDevice d = toHandle(dev);
  VkResult r = VK_SUCCESS;
  VkDeviceSize stride = 0;
  for (uint32_t i = 0; i < count && r == VK_SUCCESS; ++i) {
    VkImage img = VK_NULL_HANDLE;
    r = vkrt_CreateImage(d, &ici, nullptr, &img);
    if (r == VK_SUCCESS) {
      sc->images.push_back(img);
      VkMemoryRequirements req;
      vkrt_GetImageMemoryRequirements(d, img, &req);
      stride = (req.size + req.alignment - 1) / req.alignment * req.alignment;
    }
  }
  if (r == VK_SUCCESS) {
    VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    mai.allocationSize = stride * count;
    mai.memoryTypeIndex = 0;
    r = vkrt_AllocateMemory(d, &mai, nullptr, &sc->memory);
  }
  for (uint32_t i = 0; i < count && r == VK_SUCCESS; ++i)
    r = vkrt_BindImageMemory(d, sc->images[i], sc->memory, stride * i);
  if (r != VK_SUCCESS) {
    destroySwapchain(dev, sc, pAllocator);
    return r == VK_ERROR_OUT_OF_HOST_MEMORY ? r : VK_ERROR_OUT_OF_DEVICE_MEMORY;
  }
  for (uint32_t i = 0; i < count; ++i) {
    sc->states.push_back(Swapchain::State::Available);
    sc->order.push_back(i);
    fromHandle<Image>(sc->images[i])->presentable = true;
  }
  if (old) {
    std::lock_guard lock(sync::mutex());
    old->retired = true;
  }
  *pSwapchain = toHandle(sc);
  return VK_SUCCESS;
}

VKAPI_ATTR void VKAPI_CALL vkrt_DestroySwapchainKHR(VkDevice device, VkSwapchainKHR swapchain,
                                                    const VkAllocationCallbacks* pAllocator) {
  if (!swapchain) return;
  Device* dev = fromHandleUnchecked<Device>(device);
  Swapchain* sc = liveOrReport<Swapchain>(dev, swapchain, "vkDestroySwapchainKHR",
                                          "VUID-vkDestroySwapchainKHR-swapchain-parameter");
  if (!sc) return;
  {
    // VUID-vkDestroySwapchainKHR-swapchain-01282: the application waits for its presents; a present still queued
    // is waited for here, so that the queue never touches a destroyed swapchain.
    std::unique_lock lock(sync::mutex());
    sync::waitFor(lock, UINT64_MAX, [&] { return sc->presentsPending == 0; });
  }
  destroySwapchain(dev, sc, pAllocator);
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_GetSwapchainImagesKHR(VkDevice device, VkSwapchainKHR swapchain,
                                                          uint32_t* pSwapchainImageCount, VkImage* pSwapchainImages) {
  Device* dev = fromHandleUnchecked<Device>(device);
  Swapchain* sc = liveOrReport<Swapchain>(dev, swapchain, "vkGetSwapchainImagesKHR",
                                          "VUID-vkGetSwapchainImagesKHR-swapchain-parameter");
  if (!sc) return VK_ERROR_VALIDATION_FAILED_EXT;
  if (!pSwapchainImages) {
    *pSwapchainImageCount = static_cast<uint32_t>(sc->images.size());
    return VK_SUCCESS;
  }
  uint32_t n = std::min<uint32_t>(*pSwapchainImageCount, static_cast<uint32_t>(sc->images.size()));
  std::copy_n(sc->images.begin(), n, pSwapchainImages);
  *pSwapchainImageCount = n;
  return n < sc->images.size() ? VK_INCOMPLETE : VK_SUCCESS;
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_AcquireNextImageKHR(VkDevice device, VkSwapchainKHR swapchain, uint64_t timeout,
                                                        VkSemaphore semaphore, VkFence fence, uint32_t* pImageIndex) {
  Device* dev = fromHandleUnchecked<Device>(device);
  const char* fn = "vkAcquireNextImageKHR";
  Swapchain* sc = liveOrReport<Swapchain>(dev, swapchain, fn, "VUID-vkAcquireNextImageKHR-swapchain-parameter");
  if (!sc) return VK_ERROR_VALIDATION_FAILED_EXT;
  Semaphore* sem = nullptr;
  Fence* fen = nullptr;
  if (semaphore &&
      !(sem = liveOrReport<Semaphore>(sc, semaphore, fn, "VUID-vkAcquireNextImageKHR-semaphore-parameter")))
    return VK_ERROR_VALIDATION_FAILED_EXT;
  if (fence && !(fen = liveOrReport<Fence>(sc, fence, fn, "VUID-vkAcquireNextImageKHR-fence-parameter")))
    return VK_ERROR_VALIDATION_FAILED_EXT;
  // VUID-vkAcquireNextImageKHR-semaphore-01780
  if (!sem && !fen) {
    report(sc, Severity::Error, "VUID-vkAcquireNextImageKHR-semaphore-01780",
           "%s: semaphore and fence are both VK_NULL_HANDLE", fn);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // VUID-vkAcquireNextImageKHR-semaphore-03265
  if (sem && sem->timeline()) {
    report(sem, Severity::Error, "VUID-vkAcquireNextImageKHR-semaphore-03265",
           "%s: the semaphore is a timeline semaphore", fn);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  std::unique_lock lock(sync::mutex());
  // VUID-vkAcquireNextImageKHR-swapchain-01285
  if (sc->retired) {
    report(sc, Severity::Error, "VUID-vkAcquireNextImageKHR-swapchain-01285",
           "%s: the swapchain is retired (it was the oldSwapchain of a newer one)", fn);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // VUID-vkAcquireNextImageKHR-semaphore-01286, -01779
  if (sem && (sem->value != 0 || sem->binarySignalSubmitted || sem->inFlight != 0)) {
    bool pending = sem->inFlight != 0;
    report(sem, Severity::Error,
           pending ? "VUID-vkAcquireNextImageKHR-semaphore-01779" : "VUID-vkAcquireNextImageKHR-semaphore-01286",
           pending ? "%s: the semaphore has a signal or wait operation that has not completed"
                   : "%s: the semaphore is signaled (or has a pending signal no wait consumes)",
           fn);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // VUID-vkAcquireNextImageKHR-fence-01287
  if (fen && (fen->signaled || fen->pendingOn)) {
    report(fen, Severity::Error, "VUID-vkAcquireNextImageKHR-fence-01287",
           fen->signaled ? "%s: the fence is signaled"
                         : "%s: the fence is associated with a queue operation that has "
                           "not completed",
           fn);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // The oldest presented image that the application does not hold, once its present has executed.
  auto ready = [&] { return !sc->order.empty() && sc->states[sc->order.front()] == Swapchain::State::Available; };
  if (!sync::waitFor(lock, timeout, ready)) return timeout == 0 ? VK_NOT_READY : VK_TIMEOUT;
  uint32_t index = sc->order.front();
  sc->order.pop_front();
  sc->states[index] = Swapchain::State::Acquired;
  if (sem) {
    sem->value = 1;
    sem->binarySignalSubmitted = true;
  }
  if (fen) fen->signaled = true;
  lock.unlock();
  sync::notifyAll();
  *pImageIndex = index;
  return VK_SUCCESS;
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_AcquireNextImage2KHR(VkDevice device, const VkAcquireNextImageInfoKHR* pAcquireInfo,
                                                         uint32_t* pImageIndex) {
  // VUID-VkAcquireNextImageInfoKHR-deviceMask-01290/01291: vkrt's device group is one device
  if (pAcquireInfo->deviceMask != 1) {
    report(fromHandleUnchecked<Device>(device), Severity::Error, "VUID-VkAcquireNextImageInfoKHR-deviceMask-01290",
           "vkAcquireNextImage2KHR: deviceMask 0x%x is not 1 (the device group has one device)",
           pAcquireInfo->deviceMask);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  return vkrt_AcquireNextImageKHR(device, pAcquireInfo->swapchain, pAcquireInfo->timeout, pAcquireInfo->semaphore,
                                  pAcquireInfo->fence, pImageIndex);
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_QueuePresentKHR(VkQueue queue, const VkPresentInfoKHR* pPresentInfo) {
  const char* fn = "vkQueuePresentKHR";
  Queue* q = fromHandle<Queue>(queue);
  if (!q) {
    report(nullptr, Severity::Error, "VUID-vkQueuePresentKHR-queue-parameter", "%s: 0x%llx is not a live VkQueue", fn,
           (unsigned long long)rawHandle(queue));
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  const VkPresentInfoKHR& pi = *pPresentInfo;
  // VUID-VkPresentInfoKHR-swapchainCount-arraylength
  if (pi.swapchainCount == 0) {
    report(q, Severity::Error, "VUID-VkPresentInfoKHR-swapchainCount-arraylength", "%s: swapchainCount is 0", fn);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  std::vector<Swapchain*> chains;
  for (uint32_t i = 0; i < pi.swapchainCount; ++i) {
    Swapchain* sc = liveOrReport<Swapchain>(q, pi.pSwapchains[i], fn, "VUID-VkPresentInfoKHR-pSwapchains-parameter");
    if (!sc) return VK_ERROR_VALIDATION_FAILED_EXT;
    chains.push_back(sc);
  }
  Batch batch;
  for (uint32_t i = 0; i < pi.waitSemaphoreCount; ++i) {
    Semaphore* s =
        liveOrReport<Semaphore>(q, pi.pWaitSemaphores[i], fn, "VUID-VkPresentInfoKHR-pWaitSemaphores-parameter");
    if (!s) return VK_ERROR_VALIDATION_FAILED_EXT;
    // VUID-vkQueuePresentKHR-pWaitSemaphores-03267
    if (s->timeline()) {
      report(s, Severity::Error, "VUID-vkQueuePresentKHR-pWaitSemaphores-03267",
             "%s: pWaitSemaphores[%u] is a timeline semaphore", fn, i);
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
    batch.waits.push_back({s, 0});
  }
  if (!q->startWorker()) return VK_ERROR_OUT_OF_HOST_MEMORY;
  std::unique_lock lock(sync::mutex());
  for (uint32_t i = 0; i < pi.waitSemaphoreCount; ++i) {
    Semaphore* s = batch.waits[i].semaphore;
    // VUID-vkQueuePresentKHR-pWaitSemaphores-03268
    bool earlier = false;
    for (uint32_t j = 0; j < i; ++j) earlier |= batch.waits[j].semaphore == s;
    if (!s->binarySignalSubmitted || earlier) {
      report(s, Severity::Error, "VUID-vkQueuePresentKHR-pWaitSemaphores-03268",
             "%s: pWaitSemaphores[%u] has no submitted signal operation for this wait to consume", fn, i);
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
  }
  for (uint32_t i = 0; i < pi.swapchainCount; ++i) {
    Swapchain* sc = chains[i];
    uint32_t index = pi.pImageIndices[i];
    bool twice = false;
    for (uint32_t j = 0; j < i; ++j) twice |= chains[j] == sc;
    // VUID-VkPresentInfoKHR-pImageIndices-01430 (the image is acquired; vkrt does not track layouts)
    if (index >= sc->images.size() || sc->states[index] != Swapchain::State::Acquired || twice) {
      const char* why = index >= sc->images.size() ? "is not an index of the swapchain's images"
                        : twice                    ? "is of a swapchain presented twice in one call"
                        : sc->states[index] == Swapchain::State::Presenting ? "is being presented already"
                                                                            : "was not acquired by the application";
      report(sc, Severity::Error, "VUID-VkPresentInfoKHR-pImageIndices-01430",
             "%s: pImageIndices[%u] = %u %s (the swapchain has %zu images)", fn, i, index, why, sc->images.size());
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
  }
  // Accepted: the waits are consumed, the images are being presented until the queue has executed the present.
  for (SemaphoreOp& w : batch.waits) {
    w.semaphore->binarySignalSubmitted = false;
    ++w.semaphore->inFlight;
  }
  std::vector<std::pair<Swapchain*, uint32_t>> presented;
  for (uint32_t i = 0; i < pi.swapchainCount; ++i) {
    chains[i]->states[pi.pImageIndices[i]] = Swapchain::State::Presenting;
    ++chains[i]->presentsPending;
    presented.emplace_back(chains[i], pi.pImageIndices[i]);
  }
  lock.unlock();
  batch.hostWork = [presented](bool abandoned) {
    const char* dir = presentDir();
    for (auto& [sc, index] : presented) {
      if (abandoned) continue;
      // VUID-VkPresentInfoKHR-pImageIndices-01430: the layout when the present executes (what the barriers that
      // executed before it on a queue left); the frame is written all the same (vkrt's layouts are all linear).
      VkImageLayout layout = fromHandle<Image>(sc->images[index])->trackedLayout.load();
      if (layout != VK_IMAGE_LAYOUT_PRESENT_SRC_KHR)
        report(sc, Severity::Error, "VUID-VkPresentInfoKHR-pImageIndices-01430",
               "vkQueuePresentKHR: image %u is in layout %d when the present executes, not "
               "VK_IMAGE_LAYOUT_PRESENT_SRC_KHR (%d): a barrier must transition it before the present",
               index, (int)layout, (int)VK_IMAGE_LAYOUT_PRESENT_SRC_KHR);
      writeFrame(*sc, index, dir);
    }
    {
      std::lock_guard l(sync::mutex());
      for (auto& [sc, index] : presented) {
        sc->states[index] = Swapchain::State::Available;
        sc->order.push_back(index);
        --sc->presentsPending;
      }
    }
    sync::notifyAll();
  };
  std::vector<Batch> batches;
  batches.push_back(std::move(batch));
  q->enqueue(std::move(batches));
  if (pi.pResults)
    for (uint32_t i = 0; i < pi.swapchainCount; ++i) pi.pResults[i] = VK_SUCCESS;
  return VK_SUCCESS;
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_GetDeviceGroupPresentCapabilitiesKHR(
    VkDevice, VkDeviceGroupPresentCapabilitiesKHR* pDeviceGroupPresentCapabilities) {
  // One physical device: it presents its own images.
  std::memset(pDeviceGroupPresentCapabilities->presentMask, 0, sizeof(pDeviceGroupPresentCapabilities->presentMask));
  pDeviceGroupPresentCapabilities->presentMask[0] = 1;
  pDeviceGroupPresentCapabilities->modes = VK_DEVICE_GROUP_PRESENT_MODE_LOCAL_BIT_KHR;
  return VK_SUCCESS;
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_GetDeviceGroupSurfacePresentModesKHR(VkDevice device, VkSurfaceKHR surface,
                                                                         VkDeviceGroupPresentModeFlagsKHR* pModes) {
  if (!liveOrReport<Surface>(fromHandleUnchecked<Device>(device), surface, "vkGetDeviceGroupSurfacePresentModesKHR",
                             "VUID-vkGetDeviceGroupSurfacePresentModesKHR-surface-parameter"))
    return VK_ERROR_SURFACE_LOST_KHR;
  *pModes = VK_DEVICE_GROUP_PRESENT_MODE_LOCAL_BIT_KHR;
  return VK_SUCCESS;
}

}  // extern "C"
