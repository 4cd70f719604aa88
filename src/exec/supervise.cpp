#include "exec/supervise.hpp"

#include <signal.h>
#include <sys/mman.h>
#include <ucontext.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstring>
#include <mutex>
#include <thread>
#include <vector>

#include "abi/jit_code.hpp"

namespace vkrt::exec {

namespace {

uint64_t nowNs() {
  return uint64_t(
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
          .count());
}

// ---- the worker's state

constexpr size_t kAltStackBytes = 64 * 1024;

struct WorkerState {
  sigjmp_buf* target = nullptr;  // where a fault or a cancellation jumps (null: nothing supervised runs)
  Job* job = nullptr;            // the job of the task running (runSupervised)
  // What runs now (executor's stores), and its copy taken when the work was ended.
  Running running;
  const char* endedShader = nullptr;
  uint32_t endedId[3] = {};
  Abort::IdKind endedIdKind = Abort::NoId;
  int signal = 0;
  uint64_t address = 0, pc = 0;
  void* altStack = nullptr;  // ours, when the thread had none

  ~WorkerState();
};

// The handler reads the state through an initial-exec pointer: reading it allocates nothing (a general-dynamic
// thread_local may allocate on a thread's first access, which a signal handler must not do).
__thread WorkerState* tlsWorker __attribute__((tls_model("initial-exec"))) = nullptr;
thread_local WorkerState tlsState;

WorkerState::~WorkerState() {
  if (altStack) {
    stack_t off{};
    off.ss_flags = SS_DISABLE;
    sigaltstack(&off, nullptr);
    munmap(altStack, kAltStackBytes);
  }
  tlsWorker = nullptr;
}

void installHandlers();

// (Not inlined: inside runSupervised its locals would live across sigsetjmp, which GCC's -Wclobbered flags although
// nothing reads them after the jump.)
__attribute__((noinline)) WorkerState& worker() {
  if (WorkerState* w = tlsWorker) return *w;
  WorkerState& w = tlsState;
  // An alternate signal stack, so that a fault on an exhausted stack (a fiber's guard page) can be handled. A
  // thread that has one already (the sanitizers give threads one) keeps it.
  stack_t current{};
  if (sigaltstack(nullptr, &current) == 0 && (current.ss_flags & SS_DISABLE)) {
    void* p = mmap(nullptr, kAltStackBytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (p != MAP_FAILED) {
      stack_t ss{};
      ss.ss_sp = p;
      ss.ss_size = kAltStackBytes;
      if (sigaltstack(&ss, nullptr) == 0) {
        w.altStack = p;
      } else {
        munmap(p, kAltStackBytes);
      }
    }
  }
  tlsWorker = &w;
  return w;
}

void takeSnapshot(WorkerState* w) {
  w->endedShader = w->running.shader;
  w->endedIdKind = w->running.id ? w->running.idKind : Abort::NoId;
  if (w->running.id) std::memcpy(w->endedId, w->running.id, sizeof w->endedId);
}

// ---- faults

struct sigaction previousSegv, previousBus;

// The handler installed before vkrt's, for a fault that is not a shader's: its SA_SIGINFO handler or plain handler
// runs; the default action (or an ignored SIGSEGV, which would only fault again) is restored and the faulting
// instruction runs again, to end the process as it would have without vkrt.
void chain(int sig, siginfo_t* info, void* context) {
  const struct sigaction& prev = sig == SIGBUS ? previousBus : previousSegv;
  if (prev.sa_flags & SA_SIGINFO) {
    if (prev.sa_sigaction) {
      prev.sa_sigaction(sig, info, context);
      return;
    }
  } else if (prev.sa_handler != SIG_DFL && prev.sa_handler != SIG_IGN) {
    prev.sa_handler(sig);
    return;
  }
  struct sigaction dfl {};
  dfl.sa_handler = SIG_DFL;
  sigemptyset(&dfl.sa_mask);
  sigaction(sig, &dfl, nullptr);
}

// Entered (on the faulting stack) when the handler returns: a plain jump from ordinary code, which the
// sanitizers' longjmp interceptors follow.
[[noreturn]] void recoverFromFault() { siglongjmp(*tlsWorker->target, 1); }

void onFault(int sig, siginfo_t* info, void* context) {
  WorkerState* w = tlsWorker;
  auto* uc = static_cast<ucontext_t*>(context);
#if defined(__x86_64__)
  uintptr_t pc = uintptr_t(uc->uc_mcontext.gregs[REG_RIP]);
  uintptr_t sp = uintptr_t(uc->uc_mcontext.gregs[REG_RSP]);
#elif defined(__aarch64__)
  uintptr_t pc = uintptr_t(uc->uc_mcontext.pc);
  uintptr_t sp = uintptr_t(uc->uc_mcontext.sp);
#else
  uintptr_t pc = 0, sp = 0;
  (void)uc;
#endif
  if (!w || !w->target || pc == 0 || !abi::JitCode::contains(pc)) {
    chain(sig, info, context);
    return;
  }
  w->signal = sig;
  w->address = uint64_t(uintptr_t(info->si_addr));
  w->pc = pc;
  takeSnapshot(w);
  uintptr_t address = uintptr_t(info->si_addr);
  if (address < sp && sp - address < 1024 * 1024) {
    // Most likely the stack is exhausted: nothing more can run on it. Jump from here (the handler runs on the
    // alternate stack), letting the signal through again first (siglongjmp does not restore the mask).
    sigset_t set;
    sigemptyset(&set);
    sigaddset(&set, sig);
    pthread_sigmask(SIG_UNBLOCK, &set, nullptr);
    siglongjmp(*w->target, 1);
  }
  // Return into recoverFromFault, as if the faulting instruction had called it (below the red zone, with the
  // ABI's stack alignment at a function's entry).
  uintptr_t newSp = ((sp - 256) & ~uintptr_t(15)) - 8;
#if defined(__x86_64__)
  uc->uc_mcontext.gregs[REG_RSP] = greg_t(newSp);
  uc->uc_mcontext.gregs[REG_RIP] = greg_t(reinterpret_cast<uintptr_t>(&recoverFromFault));
#elif defined(__aarch64__)
  uc->uc_mcontext.sp = newSp + 8;
  uc->uc_mcontext.pc = reinterpret_cast<uintptr_t>(&recoverFromFault);
#endif
}

void installHandlers() {
  static std::once_flag once;
  std::call_once(once, [] {
    struct sigaction sa {};
    sa.sa_sigaction = onFault;
    sa.sa_flags = SA_SIGINFO | SA_ONSTACK;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGSEGV, &sa, &previousSegv);
    sigaction(SIGBUS, &sa, &previousBus);
  });
}

}  // namespace

// ---- the watchdog

// One thread (started with the first job that has a time limit) sleeps until the earliest deadline of the jobs
// running, and ends the jobs past theirs that completed no task since it was set (else sets it anew). Never destroyed:
// jobs may run during static destruction.
struct Watchdog {
  std::mutex mutex;
  std::condition_variable wake;
  std::vector<Job*> jobs;
  bool started = false;

  static Watchdog& get() {
    static Watchdog* w = new Watchdog;
    return *w;
  }

  void add(Job* job) {
    std::lock_guard<std::mutex> lock(mutex);
    jobs.push_back(job);
    if (job->deadlineNs_ == 0) return;
    if (!started) {
      started = true;
      std::thread([this] { run(); }).detach();
    }
    wake.notify_one();
  }
  void remove(Job* job) {
    std::lock_guard<std::mutex> lock(mutex);
    jobs.erase(std::find(jobs.begin(), jobs.end(), job));
  }
  void run() {
    std::unique_lock<std::mutex> lock(mutex);
    for (;;) {
      uint64_t now = nowNs(), next = UINT64_MAX;
      for (Job* j : jobs) {
        if (j->deadlineNs_ == 0 || j->aborted()) continue;
        if (j->deadlineNs_ <= now) {
          // A task completed since the deadline was set: the work progresses, the limit starts anew.
          if (j->progressed.load(std::memory_order_relaxed)) {
            j->progressed.store(false, std::memory_order_relaxed);
            j->deadlineNs_ = now + uint64_t(j->timeoutMs_) * 1000000;
            next = std::min(next, j->deadlineNs_);
          } else {
            j->end(Abort::Timeout);
          }
        } else {
          next = std::min(next, j->deadlineNs_);
        }
      }
      if (next == UINT64_MAX) {
        wake.wait(lock);
      } else {
        wake.wait_for(lock, std::chrono::nanoseconds(next - now));
      }
    }
  }
};

Job::Job(const void* owner, uint32_t timeoutMs) : owner_(owner), timeoutMs_(timeoutMs) {
  installHandlers();
  if (timeoutMs) deadlineNs_ = nowNs() + uint64_t(timeoutMs) * 1000000;
  Watchdog::get().add(this);
}

Job::~Job() { Watchdog::get().remove(this); }

void Job::end(Abort::Kind kind) {
  uint8_t none = Abort::None;
  reason_.compare_exchange_strong(none, kind, std::memory_order_acq_rel);
  aborted_.store(true, std::memory_order_release);
  cancel.store(1, std::memory_order_relaxed);
}

void Job::record(const Abort& a) {
  std::lock_guard<std::mutex> lock(recordMutex_);
  end(a.signal ? Abort::Fault : Abort::Cancelled);
  // The first report, unless a fault comes after a worker stopped by the fault's cancellation.
  if (recorded_ && !(a.signal && !abort_.signal)) return;
  recorded_ = true;
  abort_ = a;
  abort_.kind = Abort::Kind(reason_.load(std::memory_order_acquire));
  if (!abort_.shader) abort_.shader = shaderName;
}

void cancelJobsOf(const void* owner) {
  Watchdog& w = Watchdog::get();
  std::lock_guard<std::mutex> lock(w.mutex);
  for (Job* j : w.jobs)
    if (j->owner_ == owner) j->end(Abort::Cancelled);
}

// ---- the workers

void cancelled(abi::InvocationContext*) {
  WorkerState* w = tlsWorker;
  if (!w || !w->target) return;
  w->signal = 0;
  takeSnapshot(w);
  siglongjmp(*w->target, 2);
}

bool runSupervised(Job& job, void (*task)(void*), void* arg) {
  if (job.cancel.load(std::memory_order_relaxed)) return false;
  WorkerState& w = worker();
  w.running = Running{};
  w.signal = 0;
  sigjmp_buf point;
  Job* const previousJob = w.job;
  w.job = &job;
  if (sigsetjmp(point, 0) != 0) {
    WorkerState* ended = tlsWorker;
    ended->target = nullptr;
    ended->job = previousJob;
    Abort a;
    a.signal = ended->signal;
    a.address = ended->address;
    a.pc = ended->pc;
    a.shader = ended->endedShader;
    a.idKind = ended->endedIdKind;
    std::memcpy(a.id, ended->endedId, sizeof a.id);
    job.record(a);
    return false;
  }
  w.target = &point;
  task(arg);
  w.target = nullptr;
  w.job = previousJob;
  // Progress for the watchdog; read first so that the shared line is written once per watchdog period at most.
  if (!job.progressed.load(std::memory_order_relaxed)) job.progressed.store(true, std::memory_order_relaxed);
  return true;
}

Job* runningJob() {
  WorkerState* w = tlsWorker;
  return w ? w->job : nullptr;
}

void setRunning(const char* shader, const uint32_t* id, Abort::IdKind kind) {
  worker().running = Running{shader, id, kind};
}

void getRunning(const char** shader, const uint32_t** id, Abort::IdKind* kind) {
  const Running& r = worker().running;
  *shader = r.shader;
  *id = r.id;
  *kind = r.idKind;
}

Running& runningRecord() { return worker().running; }

sigjmp_buf*& recoveryTarget() { return worker().target; }

void abortTask() { siglongjmp(*tlsWorker->target, 1); }

}  // namespace vkrt::exec
