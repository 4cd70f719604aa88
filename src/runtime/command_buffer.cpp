#include "runtime/command_buffer.hpp"

#include <algorithm>
#include <string>
#include <string_view>

#include "runtime/acceleration_structure.hpp"
#include "runtime/acceleration_structure_nv.hpp"
#include "runtime/alloc.hpp"
#include "runtime/buffer.hpp"
#include "runtime/buffer_view.hpp"
#include "runtime/command_pool.hpp"
#include "runtime/descriptor_set.hpp"
#include "runtime/device.hpp"
#include "runtime/image.hpp"
#include "runtime/image_view.hpp"
#include "runtime/memory.hpp"
#include "runtime/physical_device.hpp"
#include "runtime/queue.hpp"
#include "runtime/report.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {

namespace {

const char* stateName(CommandBuffer::State s) {
  switch (s) {
    case CommandBuffer::State::Initial: return "initial";
    case CommandBuffer::State::Recording: return "recording";
    case CommandBuffer::State::Executable: return "executable";
    case CommandBuffer::State::Pending: return "pending";
    case CommandBuffer::State::Invalid: return "invalid";
  }
  return "?";
}

// The spec's state; the caller holds stateMutex().
CommandBuffer::State observed(const CommandBuffer* cb) {
  return cb->pending ? CommandBuffer::State::Pending : cb->state;
}

// Forgets the secondaries this primary executes (caller holds stateMutex()).
void unlinkSecondaries(CommandBuffer* cb) {
  for (CommandBuffer* sec : cb->secondaries) std::erase(sec->primaries, cb);
  cb->secondaries.clear();
}

// A secondary that is reset, re-recorded or freed invalidates the primaries that execute it (caller holds
// stateMutex(); such primaries are not pending, or the secondary would be pending too).
void unlinkPrimaries(CommandBuffer* cb) {
  for (CommandBuffer* prim : cb->primaries) {
    std::erase(prim->secondaries, cb);
    prim->state = CommandBuffer::State::Invalid;
  }
  cb->primaries.clear();
}

}  // namespace

std::mutex& CommandBuffer::stateMutex() {
  static std::mutex* m = new std::mutex;  // never destroyed: queue workers may outlive static destruction
  return *m;
}

CommandBuffer::CommandBuffer(Device* dev, CommandPool* p, VkCommandBufferLevel l)
    : Object(kType, dev->instance, dev), pool(p), level(l) {}

CommandBuffer::~CommandBuffer() {
  std::lock_guard lock(stateMutex());
  unlinkSecondaries(this);
  unlinkPrimaries(this);
}

CommandBuffer::State CommandBuffer::currentState() const {
  std::lock_guard lock(stateMutex());
  return observed(this);
}

namespace {

// The commands whose "commandBuffer-cmdpool" rule asks for a pool that supports graphics operations: draws, render
// pass instances, vertex and index buffers, the graphics dynamic state (every vkCmdSet* but events, the ray tracing
// stack size and the device mask), blits, resolves and depth/stencil and attachment clears.
bool needsGraphics(const char* command) {
  static constexpr std::string_view kPrefixes[] = {
      "vkCmdDraw",           "vkCmdBeginRenderPass", "vkCmdEndRenderPass",          "vkCmdNextSubpass",
      "vkCmdBeginRendering", "vkCmdEndRendering",    "vkCmdBindVertexBuffers",      "vkCmdBindIndexBuffer",
      "vkCmdBlitImage",      "vkCmdResolveImage",    "vkCmdClearDepthStencilImage", "vkCmdClearAttachments"};
  const std::string_view c(command);
  for (std::string_view p : kPrefixes)
    if (c.starts_with(p)) return true;
  return c.starts_with("vkCmdSet") && !c.starts_with("vkCmdSetEvent") && !c.starts_with("vkCmdSetRayTracing") &&
         !c.starts_with("vkCmdSetDeviceMask");
}

}  // namespace

CommandBuffer* CommandBuffer::recording(VkCommandBuffer h, const char* command) {
  CommandBuffer* cb = fromHandle<CommandBuffer>(h);
  if (!cb) {
    std::string vuid = std::string("VUID-") + command + "-commandBuffer-parameter";
    report(nullptr, Severity::Error, vuid.c_str(), "%s: 0x%llx is not a live VkCommandBuffer", command,
           (unsigned long long)rawHandle(h));
    return nullptr;
  }
  State st;
  {
    std::lock_guard lock(stateMutex());
    st = observed(cb);
  }
  // VUID-vkCmd*-commandBuffer-recording
  if (st != State::Recording) {
    std::string vuid = std::string("VUID-") + command + "-commandBuffer-recording";
    report(cb, Severity::Error, vuid.c_str(), "%s: the command buffer is in the %s state, not the recording state",
           command, stateName(st));
    return nullptr;
  }
  // VUID-<command>-commandBuffer-cmdpool: a graphics command in a command buffer of a compute-only family's pool.
  if (!cb->supportsGraphics() && needsGraphics(command)) {
    std::string vuid = std::string("VUID-") + command + "-commandBuffer-cmdpool";
    report(cb, Severity::Error, vuid.c_str(),
           "%s: the command buffer's pool is of queue family %u, which does not support graphics operations", command,
           cb->pool->queueFamilyIndex);
    return nullptr;
  }
  beginNotingLookups();
  return cb;
}

bool CommandBuffer::supportsGraphics() const { return PhysicalDevice::familyHasGraphics(pool->queueFamilyIndex); }

bool CommandBuffer::familySupportsStages(VkPipelineStageFlags2 stages, const char* fn, const char* vuid,
                                         const char* what) {
  // The stages whose "Required queue capability" is VK_QUEUE_GRAPHICS_BIT alone. Every other stage (none, top and
  // bottom of pipe, draw indirect, compute, transfer, copy, clear, resolve and blit (the table allows them on compute
  // and transfer queues), host, all commands, conditional rendering, the ray tracing and acceleration structure
  // stages) is supported by a family with compute or transfer, as both of vkrt's families have.
  constexpr VkPipelineStageFlags2 kGraphicsOnly =
      VK_PIPELINE_STAGE_2_VERTEX_INPUT_BIT | VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT |
      VK_PIPELINE_STAGE_2_TESSELLATION_CONTROL_SHADER_BIT | VK_PIPELINE_STAGE_2_TESSELLATION_EVALUATION_SHADER_BIT |
      VK_PIPELINE_STAGE_2_GEOMETRY_SHADER_BIT | VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT |
      VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT |
      VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_2_ALL_GRAPHICS_BIT |
      VK_PIPELINE_STAGE_2_INDEX_INPUT_BIT | VK_PIPELINE_STAGE_2_VERTEX_ATTRIBUTE_INPUT_BIT |
      VK_PIPELINE_STAGE_2_PRE_RASTERIZATION_SHADERS_BIT | VK_PIPELINE_STAGE_2_TRANSFORM_FEEDBACK_BIT_EXT |
      VK_PIPELINE_STAGE_2_FRAGMENT_SHADING_RATE_ATTACHMENT_BIT_KHR |
      VK_PIPELINE_STAGE_2_FRAGMENT_DENSITY_PROCESS_BIT_EXT | VK_PIPELINE_STAGE_2_TASK_SHADER_BIT_EXT |
      VK_PIPELINE_STAGE_2_MESH_SHADER_BIT_EXT;
  const VkPipelineStageFlags2 lacking = supportsGraphics() ? 0 : stages & kGraphicsOnly;
  if (!lacking) return true;
  report(this, Severity::Error, vuid,
         "%s: %s 0x%llx includes stages 0x%llx that need VK_QUEUE_GRAPHICS_BIT, which queue family %u of the command "
         "buffer's pool lacks",
         fn, what, (unsigned long long)stages, (unsigned long long)lacking, pool->queueFamilyIndex);
  return false;
}

void CommandBuffer::record(Command c) {
  auto note = [&](Object* o) {
    if (o && refSerials_.insert(o->serial).second) refs.push_back({o, o->serial, o->objectType});
  };
  for (Object* o : takeNotedLookups()) {
    switch (o->objectType) {
      case VK_OBJECT_TYPE_BUFFER:
        note(o);
        note(static_cast<Buffer*>(o)->memory);
        break;
      case VK_OBJECT_TYPE_IMAGE:
        note(o);
        note(static_cast<Image*>(o)->memory);
        break;
      case VK_OBJECT_TYPE_IMAGE_VIEW:
        note(o);
        note(static_cast<ImageView*>(o)->image);
        note(static_cast<ImageView*>(o)->image->memory);
        break;
      case VK_OBJECT_TYPE_BUFFER_VIEW:
        note(o);
        note(static_cast<BufferView*>(o)->buffer);
        note(static_cast<BufferView*>(o)->buffer->memory);
        break;
      case VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR:
        note(o);
        if (Buffer* b = static_cast<AccelerationStructure*>(o)->buffer) {
          note(b);
          note(b->memory);
        }
        break;
      case VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_NV:
        note(o);
        note(static_cast<AccelerationStructureNV*>(o)->memory);
        break;
      case VK_OBJECT_TYPE_DEVICE_MEMORY:
      case VK_OBJECT_TYPE_SAMPLER:
      case VK_OBJECT_TYPE_DESCRIPTOR_SET:
      case VK_OBJECT_TYPE_PIPELINE: note(o); break;
      default: break;  // layouts, modules and templates may be destroyed once recorded (maintenance4)
    }
  }
  commands.push_back(std::move(c));
}

const CommandBuffer::Ref* CommandBuffer::destroyedRef() const {
  // The registry first: an object destroyed since may not be read; a live one at that address is the same object
  // only if its serial is.
  for (const Ref& r : refs) {
    Object* live = findObject(r.object->handleValue(), r.type);
    if (!live || live->serial != r.serial) return &r;
  }
  for (const CommandBuffer* s : secondaries)
    if (const Ref* r = s->destroyedRef()) return r;
  return nullptr;
}

bool CommandBuffer::refersTo(const Object* o) const {
  for (const Ref& r : refs)
    if (r.object == o && r.serial == o->serial) return true;
  for (const CommandBuffer* s : secondaries)
    if (s->refersTo(o)) return true;
  return false;
}

void CommandBuffer::execute(ExecState& st) const {
  for (const Command& c : commands) {
    if (device->halted()) return;  // Lost Device (or vkDestroyDevice): the rest does not run
    c(st);
  }
}

bool CommandBuffer::outsideRenderPass(const char* fn, const char* vuid) {
  if (!insideRenderPass) return true;
  report(this, Severity::Error, vuid,
         "%s: recorded inside a render pass instance (between vkCmdBeginRenderPass or "
         "vkCmdBeginRendering and its end, or in a secondary command buffer that continues one)",
         fn);
  return false;
}

void CommandBuffer::reset(bool releaseResources) {
  std::vector<Command> old;
  {
    std::lock_guard lock(stateMutex());
    unlinkSecondaries(this);
    unlinkPrimaries(this);
    old.swap(commands);
    if (!releaseResources) commands.reserve(old.capacity());
    refs.clear();
    refSerials_.clear();
    state = State::Initial;
    usage = 0;
    labelDepth = 0;
    insideRenderPass = false;
    inheritance = Inheritance{};
    graphicsRecording.reset();
    for (auto& perBindPoint : pushedSets)
      for (std::shared_ptr<DescriptorSet>& set : perBindPoint) set.reset();
  }
  // `old`'s closures are destroyed here, outside the lock.
}

bool CommandBuffer::checkSubmittable(const Queue* queue, bool v2, uint32_t si, uint32_t i,
                                     std::map<const CommandBuffer*, uint32_t>& uses) const {
  const char* fn = v2 ? "vkQueueSubmit2" : "vkQueueSubmit";
  // VUID-VkSubmitInfo-pCommandBuffers-00075, VUID-VkCommandBufferSubmitInfo-commandBuffer-03890
  if (level != VK_COMMAND_BUFFER_LEVEL_PRIMARY) {
    report(this, Severity::Error,
           v2 ? "VUID-VkCommandBufferSubmitInfo-commandBuffer-03890" : "VUID-VkSubmitInfo-pCommandBuffers-00075",
           "%s: pSubmits[%u] command buffer %u is a secondary command buffer", fn, si, i);
    return false;
  }
  // VUID-vkQueueSubmit-pCommandBuffers-00074, VUID-vkQueueSubmit2-commandBuffer-03878
  if (pool->queueFamilyIndex != queue->family) {
    report(this, Severity::Error,
           v2 ? "VUID-vkQueueSubmit2-commandBuffer-03878" : "VUID-vkQueueSubmit-pCommandBuffers-00074",
           "%s: pSubmits[%u] command buffer %u comes from a pool of queue family %u; the queue is of family %u", fn, si,
           i, pool->queueFamilyIndex, queue->family);
    return false;
  }
  std::lock_guard lock(stateMutex());
  State st = observed(this);
  // VUID-vkQueueSubmit-pCommandBuffers-00070, VUID-vkQueueSubmit2-commandBuffer-03874
  if (st != State::Executable && st != State::Pending) {
    report(this, Severity::Error,
           v2 ? "VUID-vkQueueSubmit2-commandBuffer-03874" : "VUID-vkQueueSubmit-pCommandBuffers-00070",
           "%s: pSubmits[%u] command buffer %u is in the %s state, not executable or pending", fn, si, i,
           stateName(st));
    return false;
  }
  // VUID-vkQueueSubmit-pCommandBuffers-00070, VUID-vkQueueSubmit2-commandBuffer-03874: an object the commands
  // refer to was destroyed since they were recorded, which makes the command buffer invalid.
  if (const Ref* gone = destroyedRef()) {
    report(this, Severity::Error,
           v2 ? "VUID-vkQueueSubmit2-commandBuffer-03874" : "VUID-vkQueueSubmit-pCommandBuffers-00070",
           "%s: pSubmits[%u] command buffer %u is invalid: the %s 0x%llx its commands refer to has been destroyed "
           "since they were recorded",
           fn, si, i, objectTypeName(gone->type), (unsigned long long)gone->object->handleValue());
    return false;
  }
  // VUID-vkQueueSubmit-pCommandBuffers-00071, VUID-vkQueueSubmit2-commandBuffer-03875
  if (!(usage & VK_COMMAND_BUFFER_USAGE_SIMULTANEOUS_USE_BIT) && (st == State::Pending || uses[this])) {
    report(this, Severity::Error,
           v2 ? "VUID-vkQueueSubmit2-commandBuffer-03875" : "VUID-vkQueueSubmit-pCommandBuffers-00071",
           "%s: pSubmits[%u] command buffer %u is already pending and was not recorded with "
           "VK_COMMAND_BUFFER_USAGE_SIMULTANEOUS_USE_BIT",
           fn, si, i);
    return false;
  }
  for (const CommandBuffer* sec : secondaries) {
    State ss = observed(sec);
    // VUID-vkQueueSubmit-pCommandBuffers-00072, VUID-vkQueueSubmit2-commandBuffer-03876
    if (ss != State::Executable && ss != State::Pending) {
      report(sec, Severity::Error,
             v2 ? "VUID-vkQueueSubmit2-commandBuffer-03876" : "VUID-vkQueueSubmit-pCommandBuffers-00072",
             "%s: a secondary command buffer executed by pSubmits[%u] command buffer %u is in the %s state", fn, si, i,
             stateName(ss));
      return false;
    }
    // VUID-vkQueueSubmit-pCommandBuffers-00073, VUID-vkQueueSubmit2-commandBuffer-03877
    if (!(sec->usage & VK_COMMAND_BUFFER_USAGE_SIMULTANEOUS_USE_BIT) && (ss == State::Pending || uses[sec])) {
      report(sec, Severity::Error,
             v2 ? "VUID-vkQueueSubmit2-commandBuffer-03877" : "VUID-vkQueueSubmit-pCommandBuffers-00073",
             "%s: a secondary command buffer executed by pSubmits[%u] command buffer %u is already pending and was "
             "not recorded with VK_COMMAND_BUFFER_USAGE_SIMULTANEOUS_USE_BIT",
             fn, si, i);
      return false;
    }
  }
  ++uses[this];
  for (const CommandBuffer* sec : secondaries) ++uses[sec];
  return true;
}

void CommandBuffer::markSubmitted() {
  std::lock_guard lock(stateMutex());
  ++pending;
  if (usage & VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT) state = State::Invalid;  // once execution completes
  for (CommandBuffer* sec : secondaries) {
    ++sec->pending;
    if (sec->usage & VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT) sec->state = State::Invalid;
  }
}

void CommandBuffer::markCompleted() {
  std::lock_guard lock(stateMutex());
  --pending;
  for (CommandBuffer* sec : secondaries) --sec->pending;
}

}  // namespace vkrt

using namespace vkrt;

namespace {

CommandBuffer* liveCommandBuffer(VkCommandBuffer h, const char* fn, const char* vuid) {
  CommandBuffer* cb = fromHandle<CommandBuffer>(h);
  if (!cb)
    report(nullptr, Severity::Error, vuid, "%s: 0x%llx is not a live VkCommandBuffer", fn,
           (unsigned long long)rawHandle(h));
  return cb;
}

}  // namespace

extern "C" {

VKAPI_ATTR VkResult VKAPI_CALL vkrt_BeginCommandBuffer(VkCommandBuffer commandBuffer,
                                                       const VkCommandBufferBeginInfo* pBeginInfo) {
  CommandBuffer* cb =
      liveCommandBuffer(commandBuffer, "vkBeginCommandBuffer", "VUID-vkBeginCommandBuffer-commandBuffer-parameter");
  if (!cb) return VK_ERROR_VALIDATION_FAILED_EXT;
  const bool secondary = cb->level == VK_COMMAND_BUFFER_LEVEL_SECONDARY;
  CommandBuffer::State st = cb->currentState();
  // VUID-vkBeginCommandBuffer-commandBuffer-00049
  if (st == CommandBuffer::State::Recording || st == CommandBuffer::State::Pending) {
    report(cb, Severity::Error, "VUID-vkBeginCommandBuffer-commandBuffer-00049",
           "vkBeginCommandBuffer: the command buffer is in the %s state", stateName(st));
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // VUID-vkBeginCommandBuffer-commandBuffer-00050
  if (st != CommandBuffer::State::Initial && !cb->pool->canResetBuffers()) {
    report(cb, Severity::Error, "VUID-vkBeginCommandBuffer-commandBuffer-00050",
           "vkBeginCommandBuffer: the command buffer is in the %s state and its pool was created without "
           "VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT, so it cannot be reset implicitly",
           stateName(st));
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // VUID-vkBeginCommandBuffer-commandBuffer-00051
  if (secondary && !pBeginInfo->pInheritanceInfo) {
    report(cb, Severity::Error, "VUID-vkBeginCommandBuffer-commandBuffer-00051",
           "vkBeginCommandBuffer: a secondary command buffer needs pBeginInfo->pInheritanceInfo");
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // VUID-vkBeginCommandBuffer-commandBuffer-02840
  if (!secondary && (pBeginInfo->flags & VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT) &&
      (pBeginInfo->flags & VK_COMMAND_BUFFER_USAGE_SIMULTANEOUS_USE_BIT)) {
    report(cb, Severity::Error, "VUID-vkBeginCommandBuffer-commandBuffer-02840",
           "vkBeginCommandBuffer: a primary command buffer cannot be both ONE_TIME_SUBMIT and SIMULTANEOUS_USE");
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // A secondary that continues a render pass instance: its render pass and subpass, or its dynamic rendering formats.
  CommandBuffer::Inheritance inh;
  if (secondary && (pBeginInfo->flags & VK_COMMAND_BUFFER_USAGE_RENDER_PASS_CONTINUE_BIT)) {
    const VkCommandBufferInheritanceInfo& ii = *pBeginInfo->pInheritanceInfo;
    auto* rendering = findInChain<VkCommandBufferInheritanceRenderingInfo>(
        ii.pNext, VK_STRUCTURE_TYPE_COMMAND_BUFFER_INHERITANCE_RENDERING_INFO);
    // VUID-VkCommandBufferBeginInfo-flags-06000: a render pass, if given, is live
    // VUID-VkCommandBufferBeginInfo-flags-06002: without one, VkCommandBufferInheritanceRenderingInfo
    const bool passLive = ii.renderPass && findObject(rawHandle(ii.renderPass), VK_OBJECT_TYPE_RENDER_PASS);
    if (ii.renderPass ? !passLive : !rendering) {
      report(cb, Severity::Error,
             ii.renderPass ? "VUID-VkCommandBufferBeginInfo-flags-06000" : "VUID-VkCommandBufferBeginInfo-flags-06002",
             "vkBeginCommandBuffer: VK_COMMAND_BUFFER_USAGE_RENDER_PASS_CONTINUE_BIT with pInheritanceInfo->renderPass "
             "0x%llx (%s) and %s VkCommandBufferInheritanceRenderingInfo",
             (unsigned long long)rawHandle(ii.renderPass), passLive ? "live" : "not a live VkRenderPass",
             rendering ? "a" : "no");
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
    inh.continues = true;
    inh.renderPass = ii.renderPass;
    inh.subpass = ii.subpass;
    inh.framebuffer = ii.framebuffer;
    if (!ii.renderPass) {
      inh.colorFormats.assign(rendering->pColorAttachmentFormats,
                              rendering->pColorAttachmentFormats + rendering->colorAttachmentCount);
      inh.depthFormat = rendering->depthAttachmentFormat;
      inh.stencilFormat = rendering->stencilAttachmentFormat;
      inh.viewMask = rendering->viewMask;
      inh.samples = rendering->rasterizationSamples ? rendering->rasterizationSamples : VK_SAMPLE_COUNT_1_BIT;
    }
  }
  cb->reset(false);
  std::lock_guard lock(CommandBuffer::stateMutex());
  cb->state = CommandBuffer::State::Recording;
  cb->usage = pBeginInfo->flags;
  cb->inheritance = std::move(inh);
  cb->insideRenderPass = cb->inheritance.continues;
  return VK_SUCCESS;
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_EndCommandBuffer(VkCommandBuffer commandBuffer) {
  CommandBuffer* cb =
      liveCommandBuffer(commandBuffer, "vkEndCommandBuffer", "VUID-vkEndCommandBuffer-commandBuffer-parameter");
  if (!cb) return VK_ERROR_VALIDATION_FAILED_EXT;
  std::lock_guard lock(CommandBuffer::stateMutex());
  CommandBuffer::State st = observed(cb);
  // VUID-vkEndCommandBuffer-commandBuffer-00059
  if (st != CommandBuffer::State::Recording) {
    report(cb, Severity::Error, "VUID-vkEndCommandBuffer-commandBuffer-00059",
           "vkEndCommandBuffer: the command buffer is in the %s state, not the recording state", stateName(st));
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // VUID-vkEndCommandBuffer-commandBuffer-00060: a primary ends no render pass instance open
  if (cb->level == VK_COMMAND_BUFFER_LEVEL_PRIMARY && cb->insideRenderPass) {
    report(cb, Severity::Error, "VUID-vkEndCommandBuffer-commandBuffer-00060",
           "vkEndCommandBuffer: a render pass instance is still active (no vkCmdEndRenderPass / vkCmdEndRendering)");
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // VUID-vkEndCommandBuffer-commandBuffer-01815
  if (cb->level == VK_COMMAND_BUFFER_LEVEL_SECONDARY && cb->labelDepth) {
    report(cb, Severity::Error, "VUID-vkEndCommandBuffer-commandBuffer-01815",
           "vkEndCommandBuffer: the secondary command buffer has %u debug label regions still open", cb->labelDepth);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  cb->state = CommandBuffer::State::Executable;
  return VK_SUCCESS;
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_ResetCommandBuffer(VkCommandBuffer commandBuffer, VkCommandBufferResetFlags flags) {
  CommandBuffer* cb =
      liveCommandBuffer(commandBuffer, "vkResetCommandBuffer", "VUID-vkResetCommandBuffer-commandBuffer-parameter");
  if (!cb) return VK_ERROR_VALIDATION_FAILED_EXT;
  // VUID-vkResetCommandBuffer-commandBuffer-00045
  if (cb->currentState() == CommandBuffer::State::Pending) {
    report(cb, Severity::Error, "VUID-vkResetCommandBuffer-commandBuffer-00045",
           "vkResetCommandBuffer: the command buffer is pending execution");
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // VUID-vkResetCommandBuffer-commandBuffer-00046
  if (!cb->pool->canResetBuffers()) {
    report(cb, Severity::Error, "VUID-vkResetCommandBuffer-commandBuffer-00046",
           "vkResetCommandBuffer: the pool was created without VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT");
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  cb->reset((flags & VK_COMMAND_BUFFER_RESET_RELEASE_RESOURCES_BIT) != 0);
  return VK_SUCCESS;
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdExecuteCommands(VkCommandBuffer commandBuffer, uint32_t commandBufferCount,
                                                   const VkCommandBuffer* pCommandBuffers) {
  const char* fn = "vkCmdExecuteCommands";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  // VUID-vkCmdExecuteCommands-bufferlevel
  if (cb->level != VK_COMMAND_BUFFER_LEVEL_PRIMARY) {
    report(cb, Severity::Error, "VUID-vkCmdExecuteCommands-bufferlevel",
           "%s: commandBuffer is a secondary command buffer; only primaries execute secondaries", fn);
    return;
  }
  // VUID-vkCmdExecuteCommands-commandBufferCount-arraylength
  if (commandBufferCount == 0) {
    report(cb, Severity::Error, "VUID-vkCmdExecuteCommands-commandBufferCount-arraylength",
           "%s: commandBufferCount must be greater than 0", fn);
    return;
  }
  std::vector<CommandBuffer*> secs(commandBufferCount);
  std::lock_guard lock(CommandBuffer::stateMutex());
  for (uint32_t i = 0; i < commandBufferCount; ++i) {
    CommandBuffer* sec = fromHandle<CommandBuffer>(pCommandBuffers[i]);
    if (!sec) {
      report(cb, Severity::Error, "VUID-vkCmdExecuteCommands-pCommandBuffers-parameter",
             "%s: pCommandBuffers[%u] 0x%llx is not a live VkCommandBuffer", fn, i,
             (unsigned long long)rawHandle(pCommandBuffers[i]));
      return;
    }
    // VUID-vkCmdExecuteCommands-pCommandBuffers-00088
    if (sec->level != VK_COMMAND_BUFFER_LEVEL_SECONDARY) {
      report(sec, Severity::Error, "VUID-vkCmdExecuteCommands-pCommandBuffers-00088",
             "%s: pCommandBuffers[%u] is a primary command buffer", fn, i);
      return;
    }
    CommandBuffer::State st = observed(sec);
    // VUID-vkCmdExecuteCommands-pCommandBuffers-00089
    if (st != CommandBuffer::State::Executable && st != CommandBuffer::State::Pending) {
      report(sec, Severity::Error, "VUID-vkCmdExecuteCommands-pCommandBuffers-00089",
             "%s: pCommandBuffers[%u] is in the %s state, not executable or pending", fn, i, stateName(st));
      return;
    }
    const bool simultaneous = sec->usage & VK_COMMAND_BUFFER_USAGE_SIMULTANEOUS_USE_BIT;
    // VUID-vkCmdExecuteCommands-pCommandBuffers-00091
    if (!simultaneous && st == CommandBuffer::State::Pending) {
      report(sec, Severity::Error, "VUID-vkCmdExecuteCommands-pCommandBuffers-00091",
             "%s: pCommandBuffers[%u] is pending and was not recorded with SIMULTANEOUS_USE", fn, i);
      return;
    }
    // VUID-vkCmdExecuteCommands-pCommandBuffers-00092
    if (!simultaneous && std::find(cb->secondaries.begin(), cb->secondaries.end(), sec) != cb->secondaries.end()) {
      report(sec, Severity::Error, "VUID-vkCmdExecuteCommands-pCommandBuffers-00092",
             "%s: pCommandBuffers[%u] was already recorded into this command buffer and was not recorded with "
             "SIMULTANEOUS_USE",
             fn, i);
      return;
    }
    // VUID-vkCmdExecuteCommands-pCommandBuffers-00093
    if (!simultaneous && std::find(secs.begin(), secs.begin() + i, sec) != secs.begin() + i) {
      report(sec, Severity::Error, "VUID-vkCmdExecuteCommands-pCommandBuffers-00093",
             "%s: pCommandBuffers[%u] appears more than once and was not recorded with SIMULTANEOUS_USE", fn, i);
      return;
    }
    // VUID-vkCmdExecuteCommands-pCommandBuffers-00094
    if (sec->pool->queueFamilyIndex != cb->pool->queueFamilyIndex) {
      report(sec, Severity::Error, "VUID-vkCmdExecuteCommands-pCommandBuffers-00094",
             "%s: pCommandBuffers[%u] comes from a pool of another queue family", fn, i);
      return;
    }
    // VUID-vkCmdExecuteCommands-contents-06018 / 00096 (inside a render pass instance: secondaries that continue
    // it) and VUID-vkCmdExecuteCommands-pCommandBuffers-00100 (outside: none that does)
    const bool continues = sec->usage & VK_COMMAND_BUFFER_USAGE_RENDER_PASS_CONTINUE_BIT;
    if (continues != cb->insideRenderPass) {
      report(sec, Severity::Error,
             cb->insideRenderPass ? "VUID-vkCmdExecuteCommands-pCommandBuffers-00096"
                                  : "VUID-vkCmdExecuteCommands-pCommandBuffers-00100",
             "%s: pCommandBuffers[%u] was %srecorded with VK_COMMAND_BUFFER_USAGE_RENDER_PASS_CONTINUE_BIT, but is "
             "executed %s a render pass instance",
             fn, i, continues ? "" : "not ", cb->insideRenderPass ? "inside" : "outside");
      return;
    }
    secs[i] = sec;
  }
  for (CommandBuffer* sec : secs) {
    cb->secondaries.push_back(sec);
    sec->primaries.push_back(cb);
    cb->record([sec](ExecState& outer) {
      ExecState inner;  // secondaries inherit no bound state...
      inner.queue = outer.queue;
      inner.graphicsState = std::move(outer.graphicsState);  // ...but render into the render pass instance
      sec->execute(inner);
      outer.graphicsState = std::move(inner.graphicsState);
    });
  }
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdBeginDebugUtilsLabelEXT(VkCommandBuffer commandBuffer, const VkDebugUtilsLabelEXT*) {
  if (CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdBeginDebugUtilsLabelEXT")) ++cb->labelDepth;
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdEndDebugUtilsLabelEXT(VkCommandBuffer commandBuffer) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdEndDebugUtilsLabelEXT");
  if (!cb) return;
  if (cb->labelDepth) {
    --cb->labelDepth;
    return;
  }
  // VUID-vkCmdEndDebugUtilsLabelEXT-commandBuffer-01913 (a primary may close a region opened by an earlier
  // command buffer on the queue: VUID-vkCmdEndDebugUtilsLabelEXT-commandBuffer-01912 is a submit-time rule)
  if (cb->level == VK_COMMAND_BUFFER_LEVEL_SECONDARY)
    report(cb, Severity::Error, "VUID-vkCmdEndDebugUtilsLabelEXT-commandBuffer-01913",
           "vkCmdEndDebugUtilsLabelEXT: the secondary command buffer has no open debug label region");
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdInsertDebugUtilsLabelEXT(VkCommandBuffer commandBuffer,
                                                            const VkDebugUtilsLabelEXT*) {
  CommandBuffer::recording(commandBuffer, "vkCmdInsertDebugUtilsLabelEXT");  // a label records nothing
}

}  // extern "C"
