// VkCommandBuffer: commands are recorded into a list of closures and executed, in order, on the queue's
// worker at submit time.
//
// Every vkCmd* entry point: unwraps the command buffer with CommandBuffer::recording() (which checks that it
// is live and in the recording state, and reports otherwise), validates its arguments, and appends one
// closure with record(). The closure captures everything it needs by value (object pointers, copied
// regions): the application may change or free its arrays after the call returns.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "icd/object.hpp"

namespace vkrt {

class CommandPool;
class DescriptorSet;
class Pipeline;
class PipelineLayout;

// State a command buffer carries from one command to the next while it executes: bound pipelines,
// descriptor sets and push constants, per bind point.
struct BindState {
  Pipeline* pipeline = nullptr;
  PipelineLayout* layout = nullptr;
  DescriptorSet* sets[8] = {};
  std::vector<uint32_t> dynamicOffsets[8];
};

struct ExecState {
  BindState compute;
  BindState rayTracing;
  alignas(16) uint8_t pushConstants[256] = {};
  uint32_t rayTracingStackSize = 0;  // vkCmdSetRayTracingPipelineStackSizeKHR
};

using Command = std::function<void(ExecState&)>;

class CommandBuffer : public Object {
 public:
  using Handle = VkCommandBuffer;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_COMMAND_BUFFER;

  enum class State { Initial, Recording, Executable, Pending, Invalid };

  CommandBuffer(Device* dev, CommandPool* pool, VkCommandBufferLevel level);

  CommandPool* const pool;
  const VkCommandBufferLevel level;
  State state = State::Initial;
  VkCommandBufferUsageFlags usage = 0;
  std::vector<Command> commands;

  // The command buffer behind `h` if it is live and recording; otherwise reports (naming `command`) and
  // returns nullptr, and the caller records nothing.
  static CommandBuffer* recording(VkCommandBuffer h, const char* command);

  void record(Command c) { commands.push_back(std::move(c)); }

  // Runs every recorded command in order (on the queue worker).
  void execute(ExecState& state) const;
};

}  // namespace vkrt
