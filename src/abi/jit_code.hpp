// Where compiled shader code lives: the address ranges of the code sections the JIT (src/spirv/jit.cpp) has
// loaded, so that a fault handler (src/exec/supervise.cpp) can tell whether a faulting instruction belongs to a
// shader. Registration takes a lock; the query reads atomics only and is async-signal-safe.
//
// A fixed table of kSlots ranges: a range that finds no free slot is not registered (faults in it are then
// treated like faults anywhere else: not recovered).
#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>

namespace vkrt::abi {

struct JitCodeSlot {
  std::atomic<uintptr_t> begin{0}, end{0};
};

class JitCode {
 public:
  static constexpr uint32_t kSlots = 4096;

  // Registers [begin, end); returns the slot (kSlots when the table is full).
  static uint32_t add(uintptr_t begin, uintptr_t end) {
    std::lock_guard<std::mutex> lock(mutex());
    uint32_t used = used_.load(std::memory_order_relaxed);
    for (uint32_t i = 0; i < kSlots; ++i) {
      if (slots_[i].end.load(std::memory_order_relaxed) != 0) continue;
      slots_[i].begin.store(begin, std::memory_order_relaxed);
      slots_[i].end.store(end, std::memory_order_release);
      if (i >= used) used_.store(i + 1, std::memory_order_release);
      return i;
    }
    return kSlots;
  }
  static void remove(uint32_t slot) {
    if (slot >= kSlots) return;
    std::lock_guard<std::mutex> lock(mutex());
    slots_[slot].end.store(0, std::memory_order_release);
    slots_[slot].begin.store(0, std::memory_order_relaxed);
  }
  // Whether `pc` lies in registered code. Async-signal-safe (atomic loads only).
  static bool contains(uintptr_t pc) {
    uint32_t n = used_.load(std::memory_order_acquire);
    for (uint32_t i = 0; i < n && i < kSlots; ++i) {
      uintptr_t end = slots_[i].end.load(std::memory_order_acquire);
      if (end != 0 && pc >= slots_[i].begin.load(std::memory_order_relaxed) && pc < end) return true;
    }
    return false;
  }

 private:
  using Slot = JitCodeSlot;
  static std::mutex& mutex() {
    static std::mutex* m = new std::mutex;  // never destroyed: shaders may be released during static destruction
    return *m;
  }
  static inline Slot slots_[kSlots];
  static inline std::atomic<uint32_t> used_{0};
};

}  // namespace vkrt::abi
