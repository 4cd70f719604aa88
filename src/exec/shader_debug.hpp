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
  uint64_t offset = 0, range = 0, element = 0;  // a device address access: offset is the address
  InvocationId id;
  // A device address access: the live buffer nearest the address in the command's table (size 0: none), by its
  // first byte, size and handle (AddressRange::object).
  uint64_t nearBegin = 0, nearSize = 0, nearObject = 0;
  // An image access: its coordinates (x, y, z, layer, level) and the view's (width, height, depth, layers, levels)
  // at that level (a texel buffer: the index and the texel count).
  int64_t coord[5] = {};
  uint64_t extent[5] = {};
};

// The buffers with a device address that a command's shaders may access through PhysicalStorageBuffer pointers
// (VKRT_SHADER_CHECKS=bda): each live buffer's [begin, end) device address range, sorted by begin, with the largest
// end up to each entry (buffers may alias). Built by the runtime once per command, at its first checked access.
struct AddressRange {
  uint64_t begin = 0, end = 0;
  uint64_t object = 0;  // the buffer's handle, for the report
  uint64_t maxEnd = 0;  // max(end) over this entry and every one before it
};
class AddressTable {
 public:
  // Sorts `ranges` and fills maxEnd.
  void assign(std::vector<AddressRange> ranges);
  // Whether [address, address + bytes) lies inside one range: the last range beginning at or below the address,
  // binary searched, and the largest end up to it.
  bool contains(uint64_t address, uint64_t bytes) const { return find(address, bytes) != nullptr; }
  // A range holding all of [address, address + bytes), or null.
  const AddressRange* find(uint64_t address, uint64_t bytes) const;
  // The range nearest [address, address + bytes) (containing its start, else the closest end or begin); null when
  // there is none.
  const AddressRange* nearest(uint64_t address) const;
  size_t size() const { return ranges_.size(); }

 private:
  std::vector<AddressRange> ranges_;
};
// The runtime's source of a command's table (set once; `owner` is the Job's, the device).
using AddressTableSource = void (*)(const void* owner, std::vector<AddressRange>* out);
void setAddressTableSource(AddressTableSource source);

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
  // The same with the record's other fields filled (device address and image accesses): r.id is set here.
  void outOfBounds(const abi::InvocationContext* ctx, OutOfBoundsRecord r);

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
