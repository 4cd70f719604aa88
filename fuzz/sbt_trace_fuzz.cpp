// libFuzzer target: shader binding table contents through vkCmdTraceRaysKHR. One ray tracing pipeline (created
// once: a raygen shader that traces one ray against the acceleration structure whose address is its push
// constant, a miss shader, a triangles hit group and a callable shader; tests/shaders/pipeline_*) and one
// host-visible SBT buffer; an input fills the buffer, places real group handles where it says, picks the four
// regions (address, stride, size: inside the buffer or anywhere), the push constant (0, the buffer, or any
// address) and the launch size (1..4 x 1..4), then records the launch, submits it and waits. Whatever the bytes,
// vkrt must report the broken rules (VUIDs; VKRT_LOG=none here) and skip or finish the launch: never crash, hang
// or read outside device memory.
//
// Input (little-endian, read from the front; zeros past its end): 8 placement bytes (handle b & 3 at record
// (b >> 2) * 32 of the buffer; 0xff: none), then per region (raygen, miss, hit, callable) a 2-byte offset into the
// buffer, 2 bytes of stride, 2 of size and a mode byte (bit 0: the address is the next 8 bytes instead; bit 1: no
// region), then width - 1 and height - 1 (mod 4), a push-constant mode byte (mod 3: 0, the buffer's address, the
// next 8 bytes); the rest is copied into the buffer before the handles are placed.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "fuzz_device.hpp"
#include "pipeline_call.rcall.spv.h"
#include "pipeline_chit.rchit.spv.h"
#include "pipeline_miss.rmiss.spv.h"
#include "pipeline_raygen.rgen.spv.h"

namespace {

constexpr VkDeviceSize kSbtBytes = 4096;
constexpr uint32_t kGroups = 4, kHandle = 32;

struct State {
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkPipeline pipeline = VK_NULL_HANDLE;
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  uint8_t* mapped = nullptr;
  VkDeviceAddress address = 0;
  VkCommandPool pool = VK_NULL_HANDLE;
  VkFence fence = VK_NULL_HANDLE;
  uint8_t handles[kGroups][kHandle] = {};
};

void check(VkResult r) {
  if (r != VK_SUCCESS) std::abort();
}

VkShaderModule module(VkDevice device, const uint32_t* words, size_t bytes) {
  VkShaderModuleCreateInfo ci{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  ci.codeSize = bytes;
  ci.pCode = words;
  VkShaderModule m = VK_NULL_HANDLE;
  check(vkrt_CreateShaderModule(device, &ci, nullptr, &m));
  return m;
}

State makeState() {
  const vkrt::fuzz::FuzzDevice& d = vkrt::fuzz::fuzzDevice();
  State s;
  s.device = d.device;
  s.queue = d.queue;
  VkPushConstantRange pc{VK_SHADER_STAGE_RAYGEN_BIT_KHR, 0, 8};
  VkPipelineLayoutCreateInfo lci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  lci.pushConstantRangeCount = 1;
  lci.pPushConstantRanges = &pc;
  check(vkrt_CreatePipelineLayout(s.device, &lci, nullptr, &s.layout));
  VkShaderModule modules[kGroups] = {module(s.device, kSpv_pipeline_raygen_rgen, sizeof kSpv_pipeline_raygen_rgen),
                                     module(s.device, kSpv_pipeline_miss_rmiss, sizeof kSpv_pipeline_miss_rmiss),
                                     module(s.device, kSpv_pipeline_chit_rchit, sizeof kSpv_pipeline_chit_rchit),
                                     module(s.device, kSpv_pipeline_call_rcall, sizeof kSpv_pipeline_call_rcall)};
  const VkShaderStageFlagBits stages[kGroups] = {VK_SHADER_STAGE_RAYGEN_BIT_KHR, VK_SHADER_STAGE_MISS_BIT_KHR,
                                                 VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR, VK_SHADER_STAGE_CALLABLE_BIT_KHR};
  VkPipelineShaderStageCreateInfo st[kGroups];
  VkRayTracingShaderGroupCreateInfoKHR groups[kGroups];
  for (uint32_t i = 0; i < kGroups; ++i) {
    st[i] = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    st[i].stage = stages[i];
    st[i].module = modules[i];
    st[i].pName = "main";
    groups[i] = {VK_STRUCTURE_TYPE_RAY_TRACING_SHADER_GROUP_CREATE_INFO_KHR};
    groups[i].type = i == 2 ? VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR
                            : VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR;
    groups[i].generalShader = i == 2 ? VK_SHADER_UNUSED_KHR : i;
    groups[i].closestHitShader = i == 2 ? i : VK_SHADER_UNUSED_KHR;
    groups[i].anyHitShader = groups[i].intersectionShader = VK_SHADER_UNUSED_KHR;
  }
  VkRayTracingPipelineCreateInfoKHR ci{VK_STRUCTURE_TYPE_RAY_TRACING_PIPELINE_CREATE_INFO_KHR};
  ci.stageCount = kGroups;
  ci.pStages = st;
  ci.groupCount = kGroups;
  ci.pGroups = groups;
  ci.maxPipelineRayRecursionDepth = 1;
  ci.layout = s.layout;
  ci.basePipelineIndex = -1;
  check(vkrt_CreateRayTracingPipelinesKHR(s.device, VK_NULL_HANDLE, VK_NULL_HANDLE, 1, &ci, nullptr, &s.pipeline));
  for (VkShaderModule m : modules) vkrt_DestroyShaderModule(s.device, m, nullptr);
  check(vkrt_GetRayTracingShaderGroupHandlesKHR(s.device, s.pipeline, 0, kGroups, sizeof s.handles, s.handles));

  VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bci.size = kSbtBytes;
  bci.usage = VK_BUFFER_USAGE_SHADER_BINDING_TABLE_BIT_KHR | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;
  check(vkrt_CreateBuffer(s.device, &bci, nullptr, &s.buffer));
  VkMemoryRequirements req;
  vkrt_GetBufferMemoryRequirements(s.device, s.buffer, &req);
  VkPhysicalDeviceMemoryProperties props;
  vkrt_GetPhysicalDeviceMemoryProperties(d.physical, &props);
  uint32_t type = 0;
  while (type < props.memoryTypeCount &&
         (!(req.memoryTypeBits & (1u << type)) ||
          !(props.memoryTypes[type].propertyFlags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT)))
    ++type;
  VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
  flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
  VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, &flags};
  ai.allocationSize = req.size;
  ai.memoryTypeIndex = type;
  check(vkrt_AllocateMemory(s.device, &ai, nullptr, &s.memory));
  check(vkrt_BindBufferMemory(s.device, s.buffer, s.memory, 0));
  void* p = nullptr;
  check(vkrt_MapMemory(s.device, s.memory, 0, VK_WHOLE_SIZE, 0, &p));
  s.mapped = static_cast<uint8_t*>(p);
  VkBufferDeviceAddressInfo bai{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO};
  bai.buffer = s.buffer;
  s.address = vkrt_GetBufferDeviceAddress(s.device, &bai);

  VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  check(vkrt_CreateCommandPool(s.device, &pci, nullptr, &s.pool));
  VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  check(vkrt_CreateFence(s.device, &fci, nullptr, &s.fence));
  return s;
}

// Reads the input from the front (zeros once it runs out), so that seeds can be written by hand.
class Reader {
 public:
  Reader(const uint8_t* data, size_t size) : data_(data), size_(size) {}
  template <typename T>
  T take() {
    T v{};
    size_t n = sizeof(T) < size_ - at_ ? sizeof(T) : size_ - at_;
    std::memcpy(&v, data_ + at_, n);
    at_ += n;
    return v;
  }
  const uint8_t* rest() const { return data_ + at_; }
  size_t restSize() const { return size_ - at_; }

 private:
  const uint8_t* data_;
  size_t size_, at_ = 0;
};

State& state() {
  static State s = makeState();
  return s;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  state();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  State& s = state();
  Reader in(data, size);
  uint8_t place[8];
  for (uint8_t& b : place) b = in.take<uint8_t>();
  VkStridedDeviceAddressRegionKHR regions[4];
  for (VkStridedDeviceAddressRegionKHR& r : regions) {
    uint16_t offset = in.take<uint16_t>(), stride = in.take<uint16_t>(), bytes = in.take<uint16_t>();
    uint8_t mode = in.take<uint8_t>();
    r.deviceAddress = (mode & 1) ? in.take<uint64_t>() : (mode & 2) ? 0 : s.address + offset;
    r.stride = stride;
    r.size = bytes;
  }
  uint32_t width = 1 + in.take<uint8_t>() % 4, height = 1 + in.take<uint8_t>() % 4;
  uint8_t pcMode = in.take<uint8_t>();
  uint64_t tlas = pcMode % 3 == 0 ? 0 : pcMode % 3 == 1 ? s.address : in.take<uint64_t>();
  std::memset(s.mapped, 0, kSbtBytes);
  std::memcpy(s.mapped, in.rest(), in.restSize() < kSbtBytes ? in.restSize() : kSbtBytes);
  for (uint8_t b : place)
    if (b != 0xff) std::memcpy(s.mapped + (b >> 2) * 32, s.handles[b & 3], kHandle);

  VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  ai.commandPool = s.pool;
  ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ai.commandBufferCount = 1;
  VkCommandBuffer cb = VK_NULL_HANDLE;
  if (vkrt_AllocateCommandBuffers(s.device, &ai, &cb) != VK_SUCCESS) std::abort();
  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  vkrt_BeginCommandBuffer(cb, &bi);
  vkrt_CmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, s.pipeline);
  vkrt_CmdPushConstants(cb, s.layout, VK_SHADER_STAGE_RAYGEN_BIT_KHR, 0, 8, &tlas);
  vkrt_CmdTraceRaysKHR(cb, &regions[0], &regions[1], &regions[2], &regions[3], width, height, 1);
  vkrt_EndCommandBuffer(cb);
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cb;
  if (vkrt_QueueSubmit(s.queue, 1, &si, s.fence) != VK_SUCCESS) std::abort();
  if (vkrt_WaitForFences(s.device, 1, &s.fence, VK_TRUE, UINT64_MAX) != VK_SUCCESS) std::abort();
  vkrt_ResetFences(s.device, 1, &s.fence);
  vkrt_FreeCommandBuffers(s.device, s.pool, 1, &cb);
  return 0;
}
