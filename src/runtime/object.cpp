#include "runtime/object.hpp"

#include <atomic>
#include <cstddef>
#include <shared_mutex>
#include <unordered_map>

#include "abi/abi.hpp"

namespace vkrt {

// Compiled code reads the type word of an image view descriptor's object (abi.hpp: kObjectTypeOffset) before it
// takes the record's address for the view's texels. (Object is not standard-layout; GCC and Clang give its offsets.)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Winvalid-offsetof"
static_assert(offsetof(Object, objectType) == abi::kObjectTypeOffset && sizeof(VkObjectType) == 4 &&
                  VK_OBJECT_TYPE_IMAGE_VIEW == abi::kObjectTypeImageView,
              "compiled code reads an object's type word");
#pragma GCC diagnostic pop

namespace {

struct Registry {
  std::shared_mutex mutex;
  std::unordered_map<uint64_t, VkObjectType> live;
};

Registry& registry() {
  static Registry* r = new Registry;  // never destroyed: objects may outlive static destruction
  return *r;
}

std::atomic<uint64_t> nextSerial{1};

thread_local bool tNoting = false;
thread_local std::vector<Object*> tNoted;

}  // namespace

Object::Object(VkObjectType type, Instance* inst, Device* dev)
    : objectType(type), instance(inst), device(dev), serial(nextSerial.fetch_add(1, std::memory_order_relaxed)) {
  set_loader_magic_value(&loaderData);
  Registry& r = registry();
  std::unique_lock lock(r.mutex);
  r.live[handleValue()] = type;
}

Object::~Object() {
  Registry& r = registry();
  std::unique_lock lock(r.mutex);
  r.live.erase(handleValue());
}

void Object::retire() {
  Registry& r = registry();
  std::unique_lock lock(r.mutex);
  r.live.erase(handleValue());
}

void beginNotingLookups() {
  tNoting = true;
  tNoted.clear();
}

std::vector<Object*> takeNotedLookups() {
  tNoting = false;
  std::vector<Object*> out;
  out.swap(tNoted);
  return out;
}

std::string Object::debugName() const {
  std::lock_guard lock(nameMutex_);
  return debugName_;
}

void Object::setDebugName(const char* name) {
  std::lock_guard lock(nameMutex_);
  debugName_ = name ? name : "";
}

Object* findObject(uint64_t handle, VkObjectType type) {
  if (handle == 0) return nullptr;
  Registry& r = registry();
  std::shared_lock lock(r.mutex);
  auto it = r.live.find(handle);
  if (it == r.live.end() || it->second != type) return nullptr;
  Object* o = reinterpret_cast<Object*>(handle);
  // Bounded: a lookup that is never recorded (a refused command) is dropped at the next command.
  if (tNoting && tNoted.size() < 4096) tNoted.push_back(o);
  return o;
}

Object* findAnyObject(uint64_t handle) {
  if (handle == 0) return nullptr;
  Registry& r = registry();
  std::shared_lock lock(r.mutex);
  return r.live.count(handle) ? reinterpret_cast<Object*>(handle) : nullptr;
}

size_t liveObjectCount() {
  Registry& r = registry();
  std::shared_lock lock(r.mutex);
  return r.live.size();
}

const char* objectTypeName(VkObjectType type) {
  switch (type) {
#define VKRT_OBJECT_NAME(e, s) \
  case e: return s;
    VKRT_OBJECT_NAME(VK_OBJECT_TYPE_INSTANCE, "VkInstance")
    VKRT_OBJECT_NAME(VK_OBJECT_TYPE_PHYSICAL_DEVICE, "VkPhysicalDevice")
    VKRT_OBJECT_NAME(VK_OBJECT_TYPE_DEVICE, "VkDevice")
    VKRT_OBJECT_NAME(VK_OBJECT_TYPE_QUEUE, "VkQueue")
    VKRT_OBJECT_NAME(VK_OBJECT_TYPE_SEMAPHORE, "VkSemaphore")
    VKRT_OBJECT_NAME(VK_OBJECT_TYPE_COMMAND_BUFFER, "VkCommandBuffer")
    VKRT_OBJECT_NAME(VK_OBJECT_TYPE_FENCE, "VkFence")
    VKRT_OBJECT_NAME(VK_OBJECT_TYPE_DEVICE_MEMORY, "VkDeviceMemory")
    VKRT_OBJECT_NAME(VK_OBJECT_TYPE_BUFFER, "VkBuffer")
    VKRT_OBJECT_NAME(VK_OBJECT_TYPE_IMAGE, "VkImage")
    VKRT_OBJECT_NAME(VK_OBJECT_TYPE_EVENT, "VkEvent")
    VKRT_OBJECT_NAME(VK_OBJECT_TYPE_QUERY_POOL, "VkQueryPool")
    VKRT_OBJECT_NAME(VK_OBJECT_TYPE_BUFFER_VIEW, "VkBufferView")
    VKRT_OBJECT_NAME(VK_OBJECT_TYPE_IMAGE_VIEW, "VkImageView")
    VKRT_OBJECT_NAME(VK_OBJECT_TYPE_SHADER_MODULE, "VkShaderModule")
    VKRT_OBJECT_NAME(VK_OBJECT_TYPE_PIPELINE_CACHE, "VkPipelineCache")
    VKRT_OBJECT_NAME(VK_OBJECT_TYPE_PIPELINE_LAYOUT, "VkPipelineLayout")
    VKRT_OBJECT_NAME(VK_OBJECT_TYPE_RENDER_PASS, "VkRenderPass")
    VKRT_OBJECT_NAME(VK_OBJECT_TYPE_PIPELINE, "VkPipeline")
    VKRT_OBJECT_NAME(VK_OBJECT_TYPE_DESCRIPTOR_SET_LAYOUT, "VkDescriptorSetLayout")
    VKRT_OBJECT_NAME(VK_OBJECT_TYPE_SAMPLER, "VkSampler")
    VKRT_OBJECT_NAME(VK_OBJECT_TYPE_DESCRIPTOR_POOL, "VkDescriptorPool")
    VKRT_OBJECT_NAME(VK_OBJECT_TYPE_DESCRIPTOR_SET, "VkDescriptorSet")
    VKRT_OBJECT_NAME(VK_OBJECT_TYPE_FRAMEBUFFER, "VkFramebuffer")
    VKRT_OBJECT_NAME(VK_OBJECT_TYPE_COMMAND_POOL, "VkCommandPool")
    VKRT_OBJECT_NAME(VK_OBJECT_TYPE_SAMPLER_YCBCR_CONVERSION, "VkSamplerYcbcrConversion")
    VKRT_OBJECT_NAME(VK_OBJECT_TYPE_DESCRIPTOR_UPDATE_TEMPLATE, "VkDescriptorUpdateTemplate")
    VKRT_OBJECT_NAME(VK_OBJECT_TYPE_PRIVATE_DATA_SLOT, "VkPrivateDataSlot")
    VKRT_OBJECT_NAME(VK_OBJECT_TYPE_DEBUG_UTILS_MESSENGER_EXT, "VkDebugUtilsMessengerEXT")
    VKRT_OBJECT_NAME(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, "VkAccelerationStructureKHR")
    VKRT_OBJECT_NAME(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_NV, "VkAccelerationStructureNV")
    VKRT_OBJECT_NAME(VK_OBJECT_TYPE_DEFERRED_OPERATION_KHR, "VkDeferredOperationKHR")
    VKRT_OBJECT_NAME(VK_OBJECT_TYPE_SURFACE_KHR, "VkSurfaceKHR")
    VKRT_OBJECT_NAME(VK_OBJECT_TYPE_SWAPCHAIN_KHR, "VkSwapchainKHR")
#undef VKRT_OBJECT_NAME
    default: return "VkObject";
  }
}

}  // namespace vkrt
