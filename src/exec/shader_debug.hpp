// What a command's shaders print (debugPrintfEXT) and the accesses they make outside their buffers, collected while
// the command runs (abi/shader_debug.hpp's functions) and handed to the runtime afterwards, which formats and
// delivers them (exec knows no Vulkan object).
//
// Each worker thread writes to a buffer of its own (found through the running exec::Job; the first call of a
// thread in a command takes a lock to create it, later calls take none and allocate only when the buffer grows):
// the messages of one invocation, which runs on one thread, keep their order. A command keeps at most
// `printfLimit()` printf messages (VKRT_PRINTF_LIMIT, default kDefaultPrintfLimit) and counts the rest; an
// out-of-bounds access is kept once per site and thread (the runtime keeps one per site).
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <vector>

#include "abi/shader_debug.hpp"

namespace vkrt::exec {

inline constexpr uint32_t kDefaultPrintfLimit = 4096;

// The invocation a message comes from: compute: GlobalInvocationId; ray tracing: LaunchIdKHR; vertex: VertexIndex,
// InstanceIndex; fragment: FragCoord x, y (float bits).
struct InvocationId {
  uint32_t v[3] = {};
};

struct OutOfBoundsRecord {
  const uint8_t* site = nullptr;
  uint64_t offset = 0, range = 0, element = 0;
  InvocationId id;
};

class ShaderMessages {
 public:
  ShaderMessages();
  ShaderMessages(const ShaderMessages&) = delete;
  ShaderMessages& operator=(const ShaderMessages&) = delete;

  // VKRT_PRINTF_LIMIT (read once per process), else kDefaultPrintfLimit.
  static uint32_t printfLimit();

  // Calls on the worker threads (abi/shader_debug.hpp's functions).
  void printf(const abi::InvocationContext* ctx, const uint8_t* site, const uint64_t* args);
  void outOfBounds(const abi::InvocationContext* ctx, const uint8_t* site, uint64_t offset, uint64_t range,
                   uint64_t element);

  // After the command (no worker writes any more): the kept printf messages, thread by thread, each in the order
  // its thread made them, then how many were not kept.
  bool empty() const;
  void forEachPrintf(
      const std::function<void(const uint8_t* site, const InvocationId& id, const uint64_t* args)>& fn) const;
  uint64_t droppedPrintfs() const;
  // The out-of-bounds accesses, the first of each site.
  std::vector<OutOfBoundsRecord> outOfBoundsSites() const;

 private:
  struct Buffer {
    std::vector<uint64_t> words;  // per message: the site, the id (2 words), the arguments
    uint64_t kept = 0, calls = 0;
    std::vector<OutOfBoundsRecord> oob;
  };
  Buffer& local();

  const uint64_t serial_;
  const uint32_t limit_;
  std::mutex mutex_;
  std::deque<Buffer> buffers_;  // guarded by mutex_ while the command runs (stable addresses)
};

// The invocation id of `ctx` for a shader of execution model `model` (spv::ExecutionModel).
InvocationId invocationId(const abi::InvocationContext* ctx, uint32_t model);

}  // namespace vkrt::exec
