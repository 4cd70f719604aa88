// shader_debug: debugPrintfEXT and an out-of-bounds report (docs/shader-debugging.md). A compute shader
// (shaders/shader_debug.g.comp, compiled with -g) prints one line per invocation and stores one element past its
// buffer; a VK_EXT_debug_utils messenger prints what the driver says: on vkrt, the eight lines (as the validation
// layer's debug printf delivers them: "UNASSIGNED-DEBUG-PRINTF") and the store, named with its file and line
// ("VKRT-shader-out-of-bounds").
//
//   VK_DRIVER_FILES=<build>/vkrt_icd.json ./shader_debug [--bda] [--frames N]
//
// --bda runs shaders/shader_debug_bda.g.comp instead: the same squares stored through a device address (a
// buffer_reference pointer), the last one element past the 32-byte buffer, into the rest of the buffer's 4096 bytes of
// memory (so that no driver faults). vkrt reports it with VKRT_SHADER_CHECKS=bda (else nothing is checked); the
// validation layer's GPU-assisted mode reports it as "Device address out of bounds". No printf in this shader (the
// layer cannot run debug printf and GPU-assisted validation at once).
//
// --frames N submits the same command buffer N more times, quietly, and prints the time per frame (submit to idle,
// the messages' delivery included): docs/shader-debugging.md compares it with the validation layer's modes. Exits 0 and
// prints "shader_debug: OK" when the squares are right and, on vkrt, both kinds of message came.
#include <vulkan/vulkan.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "example_vk.hpp"
#include "shader_debug.g.comp.spv.h"
#include "shader_debug_bda.g.comp.spv.h"

namespace {

int gPrintfs = 0, gOutOfBounds = 0;
bool gQuiet = false;  // the timed frames: counted (also the validation layer's GPU-assisted report), not printed

VKAPI_ATTR VkBool32 VKAPI_CALL onMessage(VkDebugUtilsMessageSeverityFlagBitsEXT, VkDebugUtilsMessageTypeFlagsEXT,
                                         const VkDebugUtilsMessengerCallbackDataEXT* data, void*) {
  const std::string id = data->pMessageIdName ? data->pMessageIdName : "";
  const std::string text = data->pMessage ? data->pMessage : "";
  if (gQuiet) {
    gPrintfs += id == "UNASSIGNED-DEBUG-PRINTF";
    gOutOfBounds += id == "VKRT-shader-out-of-bounds" || id == "VUID-vkCmdDispatch-None-02706" ||
                    id.find("Device address out of bounds") != std::string::npos;
    return VK_FALSE;
  }
  if (id == "UNASSIGNED-DEBUG-PRINTF") {
    // What the shader printed follows the last " | ", as with the validation layer.
    size_t at = text.rfind(" | ");
    std::printf("shader says: %s\n", at == std::string::npos ? text.c_str() : text.c_str() + at + 3);
    ++gPrintfs;
  } else {
    if (id == "VKRT-shader-out-of-bounds" || id.find("Device address out of bounds") != std::string::npos)
      ++gOutOfBounds;
    std::printf("%s\n", text.c_str());
  }
  return VK_FALSE;
}

}  // namespace

int main(int argc, char** argv) {
  example::gProgram = "shader_debug";
  int frames = 0;
  bool bda = false;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--frames") == 0 && i + 1 < argc) {
      frames = std::atoi(argv[++i]);
    } else if (std::strcmp(argv[i], "--bda") == 0) {
      bda = true;
    } else {
      example::fail(std::string("unknown argument ") + argv[i] + " (usage: shader_debug [--bda] [--frames N])");
    }
  }
  // The messenger, also chained into the instance's create info, takes INFO too: printf messages are INFO.
  VkDebugUtilsMessengerCreateInfoEXT mci{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  mci.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_INFO_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                        VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  mci.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT;  // (the loader's INFO messages are GENERAL)
  mci.pfnUserCallback = onMessage;
  VkApplicationInfo ai{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  ai.pApplicationName = "shader_debug";
  ai.apiVersion = VK_API_VERSION_1_3;
  const char* extensions[] = {VK_EXT_DEBUG_UTILS_EXTENSION_NAME};
  VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO, &mci};
  ici.pApplicationInfo = &ai;
  ici.enabledExtensionCount = 1;
  ici.ppEnabledExtensionNames = extensions;
  VkInstance instance;
  CHECK(vkCreateInstance(&ici, nullptr, &instance));
  auto createMessenger = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
      vkGetInstanceProcAddr(instance, "vkCreateDebugUtilsMessengerEXT"));
  VkDebugUtilsMessengerEXT messenger;
  CHECK(createMessenger(instance, &mci, nullptr, &messenger));

  const VkPhysicalDevice pd = example::pickPhysicalDevice(instance);
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(pd, &props);
  const bool vkrt = std::strcmp(props.deviceName, "vkrt") == 0;
  const uint32_t family = example::queueFamily(pd, VK_QUEUE_COMPUTE_BIT);
  VkPhysicalDeviceVulkan13Features f13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
  f13.maintenance4 = VK_TRUE;  // glslc's SPIR-V 1.6 compute shaders declare their size with LocalSizeId
  VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  f12.bufferDeviceAddress = VK_TRUE;
  if (bda) f13.pNext = &f12;
  const VkDevice dev = example::createDevice(pd, family, &f13);
  VkQueue queue;
  vkGetDeviceQueue(dev, family, 0, &queue);

  // The buffer of eight squares, named for the report.
  VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bci.size = 8 * sizeof(uint32_t);
  bci.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | (bda ? VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT : 0);
  VkBuffer buffer;
  CHECK(vkCreateBuffer(dev, &bci, nullptr, &buffer));
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(dev, buffer, &req);
  VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
  flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
  VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, bda ? &flags : nullptr};
  mai.allocationSize = bda ? std::max<VkDeviceSize>(req.size, 4096) : req.size;
  mai.memoryTypeIndex = example::memoryType(
      pd, req.memoryTypeBits, {VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT}, "a buffer");
  VkDeviceMemory memory;
  CHECK(vkAllocateMemory(dev, &mai, nullptr, &memory));
  CHECK(vkBindBufferMemory(dev, buffer, memory, 0));
  void* mapped = nullptr;
  CHECK(vkMapMemory(dev, memory, 0, VK_WHOLE_SIZE, 0, &mapped));
  auto setName = reinterpret_cast<PFN_vkSetDebugUtilsObjectNameEXT>(
      vkGetInstanceProcAddr(instance, "vkSetDebugUtilsObjectNameEXT"));
  VkDebugUtilsObjectNameInfoEXT ni{VK_STRUCTURE_TYPE_DEBUG_UTILS_OBJECT_NAME_INFO_EXT};
  ni.objectType = VK_OBJECT_TYPE_BUFFER;
  ni.objectHandle = uint64_t(buffer);
  ni.pObjectName = "squares";
  CHECK(setName(dev, &ni));

  uint64_t address = 0;
  if (bda) {
    VkBufferDeviceAddressInfo bai{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO};
    bai.buffer = buffer;
    address = vkGetBufferDeviceAddress(dev, &bai);
  }

  // The pipeline: one storage buffer at set 0, binding 0 (--bda: the buffer's address as a push constant).
  VkDescriptorSetLayoutBinding binding{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
  VkDescriptorSetLayoutCreateInfo dl{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  dl.bindingCount = 1;
  dl.pBindings = &binding;
  VkDescriptorSetLayout setLayout;
  CHECK(vkCreateDescriptorSetLayout(dev, &dl, nullptr, &setLayout));
  VkPipelineLayoutCreateInfo pl{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  const VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof address};
  pl.setLayoutCount = 1;
  pl.pSetLayouts = &setLayout;
  pl.pushConstantRangeCount = bda ? 1 : 0;
  pl.pPushConstantRanges = &range;
  VkPipelineLayout layout;
  CHECK(vkCreatePipelineLayout(dev, &pl, nullptr, &layout));
  VkShaderModuleCreateInfo sm{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  sm.codeSize = bda ? sizeof kSpv_shader_debug_bda_g_comp : sizeof kSpv_shader_debug_g_comp;
  sm.pCode = bda ? kSpv_shader_debug_bda_g_comp : kSpv_shader_debug_g_comp;
  VkShaderModule module;
  CHECK(vkCreateShaderModule(dev, &sm, nullptr, &module));
  VkComputePipelineCreateInfo ci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
  ci.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
  ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  ci.stage.module = module;
  ci.stage.pName = "main";
  ci.layout = layout;
  VkPipeline pipeline;
  CHECK(vkCreateComputePipelines(dev, VK_NULL_HANDLE, 1, &ci, nullptr, &pipeline));
  VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1};
  VkDescriptorPoolCreateInfo dp{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  dp.maxSets = 1;
  dp.poolSizeCount = 1;
  dp.pPoolSizes = &size;
  VkDescriptorPool pool;
  CHECK(vkCreateDescriptorPool(dev, &dp, nullptr, &pool));
  VkDescriptorSetAllocateInfo da{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  da.descriptorPool = pool;
  da.descriptorSetCount = 1;
  da.pSetLayouts = &setLayout;
  VkDescriptorSet set;
  CHECK(vkAllocateDescriptorSets(dev, &da, &set));
  VkDescriptorBufferInfo bi{buffer, 0, VK_WHOLE_SIZE};
  VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
  w.dstSet = set;
  w.descriptorCount = 1;
  w.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  w.pBufferInfo = &bi;
  vkUpdateDescriptorSets(dev, 1, &w, 0, nullptr);

  // One workgroup of eight invocations.
  VkCommandPoolCreateInfo cpi{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  cpi.queueFamilyIndex = family;
  VkCommandPool commandPool;
  CHECK(vkCreateCommandPool(dev, &cpi, nullptr, &commandPool));
  VkCommandBufferAllocateInfo cai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  cai.commandPool = commandPool;
  cai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  cai.commandBufferCount = 1;
  VkCommandBuffer cb;
  CHECK(vkAllocateCommandBuffers(dev, &cai, &cb));
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  CHECK(vkBeginCommandBuffer(cb, &begin));
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
  vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, layout, 0, 1, &set, 0, nullptr);
  if (bda) vkCmdPushConstants(cb, layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof address, &address);
  vkCmdDispatch(cb, 1, 1, 1);
  VkMemoryBarrier mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  mb.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
  mb.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &mb, 0, nullptr, 0,
                       nullptr);
  CHECK(vkEndCommandBuffer(cb));
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cb;
  CHECK(vkQueueSubmit(queue, 1, &si, VK_NULL_HANDLE));
  CHECK(vkQueueWaitIdle(queue));

  bool ok = true;
  const auto* squares = static_cast<const uint32_t*>(mapped);
  for (uint32_t i = 0; i < 8; ++i) ok = ok && squares[i] == i * i;
  if (vkrt && !bda) ok = ok && gPrintfs == 8 && gOutOfBounds == 1;
  if (vkrt && bda) {
    // Reported only where VKRT_SHADER_CHECKS asks for the device address check.
    const char* checks = std::getenv("VKRT_SHADER_CHECKS");
    const std::string c = checks ? checks : "";
    const bool checked = c.find("bda") != std::string::npos || c.find("all") != std::string::npos;
    ok = ok && gPrintfs == 0 && gOutOfBounds == (checked ? 1 : 0);
  }
  const int printfs = gPrintfs, outOfBounds = gOutOfBounds;

  if (frames > 0) {
    gQuiet = true;
    const auto start = std::chrono::steady_clock::now();
    for (int i = 0; i < frames; ++i) {
      CHECK(vkQueueSubmit(queue, 1, &si, VK_NULL_HANDLE));
      CHECK(vkQueueWaitIdle(queue));
    }
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    std::printf("%d frames on %s: %.3f ms per frame; %d printf messages, %d out-of-bounds reports in all\n", frames,
                props.deviceName, ms / frames, gPrintfs, gOutOfBounds);
  }

  vkDestroyCommandPool(dev, commandPool, nullptr);
  vkDestroyDescriptorPool(dev, pool, nullptr);
  vkDestroyPipeline(dev, pipeline, nullptr);
  vkDestroyShaderModule(dev, module, nullptr);
  vkDestroyPipelineLayout(dev, layout, nullptr);
  vkDestroyDescriptorSetLayout(dev, setLayout, nullptr);
  vkDestroyBuffer(dev, buffer, nullptr);
  vkFreeMemory(dev, memory, nullptr);
  vkDestroyDevice(dev, nullptr);
  auto destroyMessenger = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
      vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT"));
  destroyMessenger(instance, messenger, nullptr);
  vkDestroyInstance(instance, nullptr);
  if (!ok)
    example::fail("unexpected squares or messages (" + std::to_string(printfs) + " printf messages, " +
                  std::to_string(outOfBounds) + " out-of-bounds reports)");
  std::printf("shader_debug: OK\n");
  return 0;
}
