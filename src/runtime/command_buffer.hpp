// VkCommandBuffer: commands are recorded into a list of closures and executed, in order, on the queue's
// worker at submit time.
//
// Every vkCmd* entry point: unwraps the command buffer with CommandBuffer::recording() (which checks that it
// is live and in the recording state, and reports otherwise), validates its arguments, and appends one
// closure with record(). The closure captures everything it needs by value (object pointers, copied
// regions): the application may change or free its arrays after the call returns. An invalid command is
// reported and not recorded.
//
// Lifecycle (the spec's state machine): Initial -> (begin) Recording -> (end) Executable -> (submit) Pending ->
// (completion) Executable, or Invalid for ONE_TIME_SUBMIT; reset or begin returns to Initial/Recording; a
// primary that executes a secondary becomes Invalid when that secondary is reset, re-recorded or freed.
// vkCmdExecuteCommands records a closure that runs the secondary's closures inline, with a fresh ExecState
// (secondaries inherit no bound state) that takes over the primary's graphics state for the time (a secondary that
// continues a render pass instance renders into its attachments; the spec leaves the rest of the primary's state
// undefined after vkCmdExecuteCommands).
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <unordered_set>
#include <vector>

#include "runtime/object.hpp"

namespace vkrt {

class CommandPool;
class DescriptorSet;
class Pipeline;
class PipelineLayout;
class Queue;

// State a command buffer carries from one command to the next while it executes: bound pipelines,
// descriptor sets and push constants, per bind point.
struct BindState {
  Pipeline* pipeline = nullptr;
  PipelineLayout* layout = nullptr;
  DescriptorSet* sets[8] = {};
  std::vector<uint32_t> dynamicOffsets[8];
};

// State that a layer above runtime (src/gfx) keeps in a command buffer or an execution: runtime creates none of it
// and only destroys it (through the virtual destructor).
struct LayerState {
  virtual ~LayerState() = default;
};

// The index of a bind point vkrt supports (0 compute, 1 graphics, 2 ray tracing: ExecState::bound,
// CommandBuffer::pushedSets); -1 for any other value.
inline int bindPointIndex(VkPipelineBindPoint bp) {
  switch (bp) {
    case VK_PIPELINE_BIND_POINT_COMPUTE: return 0;
    case VK_PIPELINE_BIND_POINT_GRAPHICS: return 1;
    case VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR: return 2;
    default: return -1;
  }
}

struct ExecState {
  BindState compute;
  BindState rayTracing;
  BindState graphics;
  // The bind state of bind point `index` (bindPointIndex); ray tracing's for any index but 0 and 1.
  BindState& bound(int index) { return index == 0 ? compute : index == 1 ? graphics : rayTracing; }
  std::unique_ptr<LayerState> graphicsState;  // src/gfx/graphics_state.hpp: render pass instance, dynamic state
  alignas(16) uint8_t pushConstants[256] = {};
  uint32_t rayTracingStackSize = 0;  // vkCmdSetRayTracingPipelineStackSizeKHR
  Queue* queue = nullptr;            // the queue executing the commands
};

using Command = std::function<void(ExecState&)>;

class CommandBuffer : public Object {
 public:
  using Handle = VkCommandBuffer;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_COMMAND_BUFFER;

  enum class State { Initial, Recording, Executable, Pending, Invalid };

  CommandBuffer(Device* dev, CommandPool* pool, VkCommandBufferLevel level);
  ~CommandBuffer();  // unlinks from primaries/secondaries (primaries become Invalid)

  CommandPool* const pool;
  const VkCommandBufferLevel level;
  VkCommandBufferUsageFlags usage = 0;
  std::vector<Command> commands;

  // The command buffer behind `h` if it is live and recording; otherwise reports (naming `command`) and
  // returns nullptr, and the caller records nothing.
  static CommandBuffer* recording(VkCommandBuffer h, const char* command);
  // Whether the pool's queue family supports graphics operations (recording() refuses the graphics commands
  // otherwise, with their "commandBuffer-cmdpool" VUID).
  bool supportsGraphics() const;
  // Whether the pool's queue family supports every pipeline stage in `stages` (the Synchronization chapter's
  // "Supported pipeline stage flags" table: the graphics stages need VK_QUEUE_GRAPHICS_BIT); otherwise reports
  // `vuid` naming `fn`, the member `what` and the stages the family lacks, and returns false (the command records
  // nothing). The rules: VUID-vkCmdPipelineBarrier-srcStageMask-06461 and its kin of the barrier, event and
  // timestamp commands.
  bool familySupportsStages(VkPipelineStageFlags2 stages, const char* fn, const char* vuid, const char* what);

  // Appends a command, and notes the objects the command's entry point looked up since recording() (the
  // buffers, images, views, samplers, descriptor sets, pipelines and acceleration structures it refers to, with
  // the memory bound to them) in `refs`.
  void record(Command c);

  // An object the recorded commands refer to; `serial` tells it from a later object at the same address.
  struct Ref {
    Object* object;  // not dereferenced unless the registry says an object with `serial` is live there
    uint64_t serial;
    VkObjectType type;
  };
  // Whether this command buffer or a secondary it executes refers to `o` (read while pending: refs do not change then).
  bool refersTo(const Object* o) const;
  // A reference (of this command buffer or a secondary it executes) to an object destroyed since; null if none.
  const Ref* destroyedRef() const;

  // Runs every recorded command in order (on the queue worker).
  void execute(ExecState& state) const;

  // The state as the spec defines it (Pending while any submission is executing).
  State currentState() const;

  // Back to the initial state (vkResetCommandBuffer, vkResetCommandPool, implicit reset of vkBeginCommandBuffer).
  void reset(bool releaseResources);

  // --- Used by vkQueueSubmit(2) (runtime/queue.cpp) ---
  // Checks that the command buffer (and the secondaries it executes) can be submitted to `queue`, counting
  // uses within this submission in `uses`. Reports (VUIDs of vkQueueSubmit or vkQueueSubmit2) and returns false.
  bool checkSubmittable(const Queue* queue, bool submit2, uint32_t submitIndex, uint32_t index,
                        std::map<const CommandBuffer*, uint32_t>& uses) const;
  // Marks a submission (this and its secondaries become Pending) / its completion.
  void markSubmitted();
  void markCompleted();

  // --- Used by the command entry points of runtime/command_buffer.cpp ---
  State state = State::Initial;             // guarded by the command-buffer mutex
  uint32_t pending = 0;                     // submissions not completed yet
  std::vector<CommandBuffer*> secondaries;  // executed by this primary (vkCmdExecuteCommands)
  std::vector<CommandBuffer*> primaries;    // primaries that execute this secondary
  uint32_t labelDepth = 0;                  // open vkCmdBeginDebugUtilsLabelEXT regions
  // Between vkCmdBeginRenderPass(2)/vkCmdBeginRendering and their end while recording: commands that may not be
  // recorded inside a render pass instance (dispatches, copies, traces...) check it ("-renderpass" VUIDs).
  bool insideRenderPass = false;
  // Reports `vuid` ("<fn> inside a render pass instance") and returns false while insideRenderPass.
  bool outsideRenderPass(const char* fn, const char* vuid);
  // A secondary's VkCommandBufferInheritanceInfo when it began with RENDER_PASS_CONTINUE (else `continues` false):
  // the render pass and subpass, or the dynamic rendering formats (VkCommandBufferInheritanceRenderingInfo). src/gfx
  // reads it to know the subpass the secondary's commands record into.
  struct Inheritance {
    bool continues = false;
    VkRenderPass renderPass = VK_NULL_HANDLE;
    uint32_t subpass = 0;
    VkFramebuffer framebuffer = VK_NULL_HANDLE;
    std::vector<VkFormat> colorFormats;  // dynamic rendering only
    VkFormat depthFormat = VK_FORMAT_UNDEFINED, stencilFormat = VK_FORMAT_UNDEFINED;
    uint32_t viewMask = 0;
    VkSampleCountFlagBits samples = VK_SAMPLE_COUNT_1_BIT;
  } inheritance;
  // src/gfx's recording state (the render pass instance being recorded, bound pipeline for validation); reset
  // with the command buffer.
  std::unique_ptr<LayerState> graphicsRecording;
  std::vector<Ref> refs;  // what the commands refer to (record()), in no order, deduplicated
  // Push descriptors while recording: the set the last vkCmdPushDescriptorSet*KHR of each bind point (compute,
  // graphics, ray tracing) and set number built, or null. The recorded command that binds it keeps it alive; a
  // later push copies it into a new set (push descriptors are updated incrementally) and leaves it as it is, so each
  // recorded dispatch, draw or trace reads the descriptors pushed before it (runtime/push_descriptor_commands.cpp).
  std::shared_ptr<DescriptorSet> pushedSets[3][8];

  // The mutex that guards every command buffer's state, pending count and links.
  static std::mutex& stateMutex();

 private:
  std::unordered_set<uint64_t> refSerials_;  // the serials in `refs`
};

}  // namespace vkrt
