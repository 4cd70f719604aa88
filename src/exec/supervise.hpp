// Supervising shader work (robustness): a watchdog that cancels a dispatch or launch in which no workgroup or
// tile of rays completed for its time limit, and the recovery of faults raised by compiled shader code on vkrt's worker
// threads. Either ends the work early; the Job then says what happened (the shader, an invocation that was still
// running, the faulting address) and the runtime reports it and loses the device (the specification's "Lost Device").
//
// Cancellation: compiled loops poll InvocationContext::cancel at every loop header (src/spirv/cancellation_poll.cpp)
// and, when it is set, call InvocationContext::cancelled (exec::cancelled), which jumps back to the worker's recovery
// point.
//
// Faults: a SIGSEGV / SIGBUS handler (installed with SA_SIGINFO | SA_ONSTACK on the first supervised job; each
// worker thread gets an alternate signal stack unless it has one) recovers a fault when the faulting instruction
// lies in compiled shader code (abi::JitCode) and the thread is running a supervised task. The handler returns
// into a trampoline on the faulting stack, which jumps (siglongjmp) to the recovery point of the task, or of the
// fiber, that was running; a fault that looks like a stack overflow jumps from the handler itself. Any other fault
// goes to the handler installed before vkrt's (or the default action): vkrt does not hide its own bugs, nor the
// application's.
#pragma once

#include <atomic>
#include <csetjmp>
#include <cstdint>
#include <mutex>

#include "abi/abi.hpp"
#include "exec/shader_debug.hpp"

namespace vkrt::exec {

// What ended a job early.
struct Abort {
  enum Kind : uint8_t { None, Timeout, Fault, Cancelled } kind = None;
  int signal = 0;        // Fault: SIGSEGV or SIGBUS
  uint64_t address = 0;  // Fault: the address accessed (si_addr)
  uint64_t pc = 0;       // Fault: the faulting instruction
  // The shader that was running (the executor's name for it; null where the executor names none, see
  // Job::shaderName) and its invocation.
  const char* shader = nullptr;
  enum IdKind : uint8_t { NoId, GlobalInvocation, Workgroup, LaunchId } idKind = NoId;
  uint32_t id[3] = {};
};

// One dispatch or launch under supervision; it lives on the executor's stack while the work runs.
class Job {
 public:
  // `timeoutMs` 0: no time limit. `owner` (the device) for cancelJobsOf.
  Job(const void* owner, uint32_t timeoutMs);
  ~Job();
  Job(const Job&) = delete;
  Job& operator=(const Job&) = delete;

  // The flag compiled loops poll (InvocationContext::cancel): nonzero once the job is ending.
  std::atomic<uint32_t> cancel{0};
  // Set when a task (a workgroup, a tile of rays) completes; the watchdog clears it. The time limit is on the
  // work's progress, not its length: a job is ended when no task completed for timeoutMs, so that a long launch
  // that keeps finishing tiles (a CTS case of maxRayDispatchInvocationCount rays, a large render) is not lost.
  std::atomic<bool> progressed{false};
  const char* shaderName = nullptr;  // for compute: the shader (the trace executor names each shader itself)
  // What the job's shaders printed and the accesses they made out of bounds (exec/shader_debug.hpp).
  ShaderMessages messages;
  // The live device address ranges (VKRT_SHADER_CHECKS=bda), snapshotted through the runtime's source at the first
  // call in this job (under a lock, once; later calls read a flag).
  const AddressTable& addresses();

  bool aborted() const { return aborted_.load(std::memory_order_acquire); }
  // What ended the job (read once the work has returned).
  const Abort& abort() const { return abort_; }
  uint32_t timeoutMs() const { return timeoutMs_; }

  // Called by the watchdog (Timeout), cancelJobsOf (Cancelled) and the workers (Fault): the first reason wins;
  // the invocation is the first one a worker reports.
  void end(Abort::Kind kind);
  void record(const Abort& a);

 private:
  friend struct Watchdog;
  friend void cancelJobsOf(const void* owner);
  const void* owner_;
  uint32_t timeoutMs_;
  uint64_t deadlineNs_ = 0;  // steady clock
  std::atomic<bool> aborted_{false};
  std::atomic<uint8_t> reason_{Abort::None};
  std::mutex recordMutex_;
  bool recorded_ = false;  // guarded by recordMutex_
  Abort abort_;
  std::atomic<bool> addressesReady_{false};
  std::mutex addressesMutex_;
  AddressTable addresses_;
};

// Ends every running job of `owner` (vkDestroyDevice with work still running): their loops stop at the next poll.
void cancelJobsOf(const void* owner);

// The InvocationContext::cancelled callback: jumps to the running task's recovery point (returns when the thread
// runs nothing supervised).
void cancelled(abi::InvocationContext* ctx);

// Runs task(arg) on this thread under `job`: returns false when the job is ending (the task did not start) or
// the task was ended by a fault or a cancellation (recorded in the job).
bool runSupervised(Job& job, void (*task)(void*), void* arg);

// The job whose task this thread runs now (null outside runSupervised).
Job* runningJob();

// What the worker runs now, kept up to date by the executor (stores only) for the abort report.
struct Running {
  const char* shader = nullptr;
  const uint32_t* id = nullptr;
  Abort::IdKind idKind = Abort::NoId;
};
void setRunning(const char* shader, const uint32_t* id, Abort::IdKind kind);
void getRunning(const char** shader, const uint32_t** id, Abort::IdKind* kind);
// This thread's Running record itself (valid on this thread while it lives): an executor that stores it at every
// shader call (the trace executor, per ray) takes it once per task instead of a thread-local lookup per store.
Running& runningRecord();

// Fibers (compute shaders with barriers): each fiber has its own recovery point on its own stack. The scheduler
// makes the fiber's point the thread's target while the fiber runs, storing it into recoveryTarget() (this thread's
// target itself, valid on this thread while it lives: taken once per group, not looked up at every switch); the
// fiber's entry sets it with sigsetjmp. After a fiber was ended, the scheduler calls abortTask, which ends the task
// with what the fiber recorded.
sigjmp_buf*& recoveryTarget();
[[noreturn]] void abortTask();

}  // namespace vkrt::exec
