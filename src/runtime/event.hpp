// VkEvent, and the synchronization commands that order work inside a queue: vkCmdSetEvent/ResetEvent/WaitEvents
// (and their *2 forms) and vkCmdPipelineBarrier(2).
//
// A queue executes its commands one after another on one worker thread, so barriers only need to keep their
// place in the command list: they are validated and recorded as no-ops. vkCmdWaitEvents really blocks the
// worker until the event is set (by the host or by another queue).
#pragma once

#include "runtime/object.hpp"

namespace vkrt {

class Event : public Object {
 public:
  using Handle = VkEvent;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_EVENT;

  Event(Device* dev, VkEventCreateFlags flags);

  const VkEventCreateFlags flags;
  bool set = false;  // guarded by sync::mutex() (runtime/fence.hpp)
};

}  // namespace vkrt
