// Fiber groups (exec/fiber_group.hpp): invocations that wait for each other at barriers, each on a stack of its own,
// switched between on the calling worker thread.
#include "exec/fiber_group.hpp"

#include <sys/mman.h>

#include <cstring>
#include <memory>
#include <new>
#include <vector>

#include "exec/supervise.hpp"

#if defined(__SANITIZE_ADDRESS__)
#include <sanitizer/asan_interface.h>
#include <sanitizer/common_interface_defs.h>
#define VKRT_ASAN_FIBERS 1
#endif
// ThreadSanitizer follows a thread through a fiber switch only when told which fiber runs next.
#if defined(__SANITIZE_THREAD__)
#include <sanitizer/tsan_interface.h>
#define VKRT_TSAN_FIBERS 1
#endif

// The fibers' context switch: x86-64 System V keeps rbx, rbp, r12-r15 and rsp across calls, so a switch saves those
// on the stack it leaves, stores that stack pointer in *saveSp, and loads the others from `loadSp`'s stack. Nothing
// else: unlike swapcontext, which saved and restored the signal mask with a system call each time (rt_sigprocmask; a
// 256-invocation workgroup with one barrier made about 1,300 of them), a switch here costs a few dozen instructions.
// (The signal mask is the worker thread's and no fiber changes it.) The ABI's other preserved state, the control
// bits of MXCSR and the x87 control word, is not switched either: every fiber runs with its worker's, since no code
// vkrt runs on a fiber changes them (the compiler emits no control-word write: FPRoundingMode RTZ is done in
// arithmetic, src/spirv/arithmetic.cpp). Saving them cost more than the rest of the switch (stmxcsr and fnstcw are
// microcoded), and a fragment quad that takes derivatives switches 16 times.
extern "C" void vkrt_fiber_switch(void** saveSp, void* loadSp);
asm(R"(
  .text
  .p2align 4
  .globl vkrt_fiber_switch
  .hidden vkrt_fiber_switch
  .type vkrt_fiber_switch, @function
vkrt_fiber_switch:
  .cfi_startproc
  pushq %rbp
  pushq %rbx
  pushq %r12
  pushq %r13
  pushq %r14
  pushq %r15
  movq %rsp, (%rdi)
  movq %rsi, %rsp
  popq %r15
  popq %r14
  popq %r13
  popq %r12
  popq %rbx
  popq %rbp
  ret
  .cfi_endproc
  .size vkrt_fiber_switch, .-vkrt_fiber_switch
)");

namespace vkrt::exec {

namespace {

using abi::InvocationContext;

constexpr size_t kFiberStackBytes = 256 * 1024;  // usable bytes; a guard page sits below each stack
constexpr size_t kGuardBytes = 4096;

struct Scheduler;

struct Fiber {
  void* sp = nullptr;   // the saved stack pointer while the fiber is not running (vkrt_fiber_switch)
  sigjmp_buf recovery;  // where a fault or a cancellation of this fiber's shader code jumps (exec/supervise.hpp)
  bool aborted = false;
  uint8_t* stack = nullptr;  // usable stack (the guard page is just below)
  InvocationContext* inv = nullptr;
  bool done = false;
  bool started = false;  // resumed at least once (fiberMain read tlsStarting)
  uint32_t index = 0;    // in the group
  Scheduler* scheduler = nullptr;
#if VKRT_TSAN_FIBERS
  void* tsanFiber = nullptr;  // created on first use
  ~Fiber() {
    if (tsanFiber) __tsan_destroy_fiber(tsanFiber);
  }
#endif
};

struct Scheduler {
  void* mainSp = nullptr;  // the worker's stack pointer while a fiber runs
  abi::ComputeEntry entry = nullptr;
  Abort::IdKind idKind = Abort::GlobalInvocation;  // what a report names: the fiber's invocation or its workgroup
  // The worker's records, taken once per group (exec/supervise.hpp): what runs, and where a fault jumps.
  Running* running = nullptr;
  sigjmp_buf** target = nullptr;
  Fiber* fibers = nullptr;  // the group's
  uint32_t count = 0;
  uint32_t current = 0;   // the fiber running, or the last that ran before the worker's stack got control back
  bool fromMain = false;  // the switch into the fiber now starting or resuming came from the worker's stack
  const void* mainBottom = nullptr;  // for ASan's fiber bookkeeping
  size_t mainSize = 0;
#if VKRT_TSAN_FIBERS
  void* tsanMain = nullptr;  // the worker thread's own fiber
#endif
};

// Per worker thread: fiber stacks, reused from group to group.
struct FiberStacks {
  std::vector<uint8_t*> stacks;  // mmap'd regions (guard page + stack)
  std::unique_ptr<Fiber[]> fibers;
  size_t fiberCount = 0;

  ~FiberStacks() {
    for (uint8_t* s : stacks) munmap(s, kFiberStackBytes + kGuardBytes);
  }
  bool ensure(size_t n) {
    while (stacks.size() < n) {
      void* p = mmap(nullptr, kFiberStackBytes + kGuardBytes, PROT_READ | PROT_WRITE,
                     MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
      if (p == MAP_FAILED) return false;
      mprotect(p, kGuardBytes, PROT_NONE);  // a stack overflow faults instead of corrupting memory
      stacks.push_back(static_cast<uint8_t*>(p));
    }
    if (fiberCount < n) {
      fibers.reset(new (std::nothrow) Fiber[n]);
      if (!fibers) return false;
      fiberCount = n;
    }
    return true;
  }
};

thread_local Fiber* tlsStarting = nullptr;

#if VKRT_ASAN_FIBERS
// AddressSanitizer's end of a switch into a fiber: the stack it came from is the worker's when the scheduler
// switched (recorded for the switches back), another fiber's otherwise.
void finishSwitch(Scheduler& s, void* fake) {
  const void* bottom = nullptr;
  size_t size = 0;
  __sanitizer_finish_switch_fiber(fake, &bottom, &size);
  if (s.fromMain) s.mainBottom = bottom, s.mainSize = size;
}
#endif

// Makes `to` the fiber that runs (the recovery target, the report's invocation) before a switch to it; `fromMain`: the
// switch comes from the worker's stack. (ThreadSanitizer's switch is the caller's, just before its own: made in a
// function that returns before the switch, it would pop that function's frame from the new fiber's shadow stack.)
void enter(Scheduler& s, Fiber& to, bool fromMain) {
  if (!to.started) {
    tlsStarting = &to;
    to.started = true;
  }
  s.current = to.index;
  s.fromMain = fromMain;
  *s.target = &to.recovery;
  if (s.idKind == Abort::GlobalInvocation) s.running->id = to.inv->globalId;  // (a workgroup's is set once)
#if VKRT_TSAN_FIBERS
  if (!to.tsanFiber) to.tsanFiber = __tsan_create_fiber(0);
#endif
}

// A fiber's first function (its stack is laid out by makeFiber so that the first switch to it returns here). It
// never returns: it ends by switching to the scheduler for good. Not instrumented by ThreadSanitizer: it switches
// ThreadSanitizer to the scheduler's fiber before it leaves, where an instrumented function's exit would pop the
// scheduler's shadow stack.
#if VKRT_TSAN_FIBERS
__attribute__((no_sanitize_thread))
#endif
[[noreturn]] void
fiberMain() {
  Fiber* f = tlsStarting;
#if VKRT_ASAN_FIBERS
  finishSwitch(*f->scheduler, nullptr);
#endif
  // A fault or a cancellation comes back here, on the fiber's own stack; the fiber then ends as usual.
  if (sigsetjmp(f->recovery, 0) == 0) {
    f->scheduler->entry(f->inv);
  } else {
    f->aborted = true;
  }
  f->done = true;
#if VKRT_ASAN_FIBERS
  __sanitizer_start_switch_fiber(nullptr, f->scheduler->mainBottom, f->scheduler->mainSize);
#endif
#if VKRT_TSAN_FIBERS
  __tsan_switch_to_fiber(f->scheduler->tsanMain, 0);
#endif
  vkrt_fiber_switch(&f->sp, f->scheduler->mainSp);  // never resumed: the scheduler does not resume a done fiber
  __builtin_unreachable();
}

// Lays out a fresh fiber's stack as vkrt_fiber_switch leaves a stack it switches away from, so that the first switch
// to it "returns" into fiberMain: from the top, a return address slot aligned as after a call (the stack pointer is 8
// past a multiple of 16 at a function's entry) and the six callee-saved registers (zero: rbp = 0 ends the frame chain
// for debuggers and unwinders).
void makeFiber(Fiber& f) {
  uintptr_t top = (reinterpret_cast<uintptr_t>(f.stack) + kFiberStackBytes) & ~uintptr_t(15);
  uint64_t* sp = reinterpret_cast<uint64_t*>(top - 16);
  sp[0] = reinterpret_cast<uint64_t>(&fiberMain);
  for (int r = 1; r <= 6; ++r) sp[-r] = 0;  // rbp, rbx, r12, r13, r14, r15
  f.sp = &sp[-6];
}

// The group's barrier: on to the round's next fiber that has not ended (one switch, not two through the scheduler),
// or, from the round's last, back to the scheduler, which starts the next round.
void fiberBarrier(InvocationContext* inv) {
  Fiber* f = static_cast<Fiber*>(inv->executor);
  Scheduler* s = f->scheduler;
  uint32_t next = f->index + 1;
  while (next < s->count && s->fibers[next].done) ++next;
#if VKRT_ASAN_FIBERS
  void* fake = nullptr;
#endif
  if (next < s->count) {
    Fiber& to = s->fibers[next];
#if VKRT_ASAN_FIBERS
    __sanitizer_start_switch_fiber(&fake, to.stack, kFiberStackBytes);
#endif
    enter(*s, to, false);
#if VKRT_TSAN_FIBERS
    __tsan_switch_to_fiber(to.tsanFiber, 0);
#endif
    vkrt_fiber_switch(&f->sp, to.sp);
  } else {
#if VKRT_ASAN_FIBERS
    __sanitizer_start_switch_fiber(&fake, s->mainBottom, s->mainSize);
#endif
#if VKRT_TSAN_FIBERS
    __tsan_switch_to_fiber(s->tsanMain, 0);
#endif
    vkrt_fiber_switch(&f->sp, s->mainSp);
  }
#if VKRT_ASAN_FIBERS
  finishSwitch(*s, fake);
#endif
}

// Runs `f` and, where it reaches a barrier, the round's next fibers (fiberBarrier), until one switches back here:
// s.current says which.
void resume(Scheduler& s, Fiber& f) {
#if VKRT_ASAN_FIBERS
  void* fake = nullptr;
  __sanitizer_start_switch_fiber(&fake, f.stack, kFiberStackBytes);
#endif
  sigjmp_buf* outer = *s.target;
#if VKRT_TSAN_FIBERS
  s.tsanMain = __tsan_get_current_fiber();
#endif
  enter(s, f, true);
#if VKRT_TSAN_FIBERS
  __tsan_switch_to_fiber(f.tsanFiber, 0);
#endif
  vkrt_fiber_switch(&s.mainSp, f.sp);
#if VKRT_ASAN_FIBERS
  __sanitizer_finish_switch_fiber(fake, nullptr, nullptr);
#endif
  *s.target = outer;
}

}  // namespace

bool runFiberGroup(abi::ComputeEntry entry, InvocationContext* const* invocations, uint32_t count,
                   Abort::IdKind idKind) {
  thread_local FiberStacks scratch;
  if (count == 0) return true;
  if (!scratch.ensure(count)) return false;
  Scheduler s;
  s.entry = entry;
  s.idKind = idKind;
  s.running = &runningRecord();
  s.target = &recoveryTarget();
  s.fibers = scratch.fibers.get();
  s.count = count;
  *s.running =
      Running{nullptr, idKind == Abort::Workgroup ? invocations[0]->workgroupId : invocations[0]->globalId, idKind};
  for (uint32_t i = 0; i < count; ++i) {
    Fiber& f = scratch.fibers[i];
    f.done = false;
    f.started = false;
    f.aborted = false;
    f.scheduler = &s;
    f.index = i;
    f.stack = scratch.stacks[i] + kGuardBytes;
    f.inv = invocations[i];
    f.inv->barrier = fiberBarrier;
    f.inv->executor = &f;
    makeFiber(f);
  }
  // Round-robin: each round takes every unfinished invocation to its next barrier (or its end); one that ended
  // is skipped. A fiber at a barrier switches to the next itself; the scheduler gets control back from the round's
  // last or from one that ended, and goes on after it.
  for (bool again = true; again;) {
    again = false;
    for (uint32_t i = 0; i < count; ++i) {
      if (scratch.fibers[i].done) continue;
      resume(s, scratch.fibers[i]);
      for (uint32_t k = i; k <= s.current; ++k) again |= !scratch.fibers[k].done;
      i = s.current;
      Fiber& f = scratch.fibers[i];
      if (f.aborted) {
        // The group ends here: the fibers still waiting at a barrier are abandoned (each group makes its fibers
        // afresh).
#if VKRT_TSAN_FIBERS
        for (uint32_t k = 0; k < count; ++k)
          if (scratch.fibers[k].tsanFiber) {
            __tsan_destroy_fiber(scratch.fibers[k].tsanFiber);
            scratch.fibers[k].tsanFiber = nullptr;
          }
#endif
#if VKRT_ASAN_FIBERS
        // The abandoned frames' redzones would otherwise stay poisoned for the next group's fibers.
        for (uint32_t k = 0; k < count; ++k)
          __asan_unpoison_memory_region(scratch.stacks[k] + kGuardBytes, kFiberStackBytes);
#endif
        abortTask();
      }
    }
  }
  return true;
}

}  // namespace vkrt::exec
