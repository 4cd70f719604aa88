// The process-wide pool of worker threads. It runs shader work, the workgroups of compute dispatches and the tiles of
// ray tracing launches (parallelFor), and coarse independent tasks: the stages of a pipeline to compile, the chunks of
// a large acceleration structure build's inputs to read (runConcurrently).
//
// Size: VKRT_THREADS threads in all if set (1..256), else the number of hardware threads. The thread calling
// parallelFor() works too, so the pool starts one thread fewer (a pool of N runs N + 1 threads at most); each gets
// a distinct worker index < workerSlots().
//
// Waking: a worker that finds no job watches the count of posted jobs for a while (the pool's spin time:
// kSpinMicroseconds, or VKRT_POOL_SPIN_US for the process's pool, 0..10000, 0 sleeps at once) before it sleeps on the
// condition variable, and the caller of a job watches the job's finished count as long before it sleeps on the job's. A
// frame's graphics work is a row of short parallelFors (a draw's vertices, primitives, tiles; clears; copies) with a
// few microseconds of serial work between them: woken through the condition variable, sixteen workers take tens of
// microseconds to start each one (one mutex, a futex wake each), which at sixteen threads was a tenth of a short frame.
// While watching, a worker pauses and yields, so on a machine with more runnable threads than cores it gives its core
// to them.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace vkrt::exec {

// How long an idle worker or a waiting caller watches before sleeping.
inline constexpr unsigned kSpinMicroseconds = 100;

class ThreadPool {
 public:
  static ThreadPool& instance();

  explicit ThreadPool(unsigned threads, unsigned spinMicroseconds = kSpinMicroseconds);
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  // Runs fn(index, worker) for every index in [0, count), spread over the workers and the caller, and returns
  // when all are done. Calls from several threads are serialized; fn must not call parallelFor itself.
  void parallelFor(uint64_t count, const std::function<void(uint64_t index, unsigned worker)>& fn);

  // Runs fn(index) for every index in [0, count) on the pool's threads and the caller, and returns when all are
  // done. Unlike parallelFor, any number of threads may call it at once (fn gets no worker index, so it needs no
  // per-worker scratch): for coarse independent work such as compiling a pipeline's stages. Behind a running
  // parallelFor the pool's threads join only once its indices are all taken; the caller works meanwhile.
  void runConcurrently(uint64_t count, const std::function<void(uint64_t index)>& fn);

  unsigned threadCount() const { return unsigned(threads_.size()); }
  // How many times a worker has gone to sleep on the condition variable (for tests).
  uint64_t sleeps() const { return sleeps_.load(std::memory_order_relaxed); }
  // Distinct worker indices handed to fn: the pool's threads plus one per concurrently calling thread is
  // bounded by this (callers share the last slot under a lock, see parallelFor).
  unsigned workerSlots() const { return unsigned(threads_.size()) + 1; }

 private:
  struct Job;
  void workerMain(unsigned index);
  static void runJob(Job& job, unsigned worker);
  // Queues the job for the workers, works on it on the calling thread, and returns when every index is done.
  void runWithWorkers(const std::shared_ptr<Job>& job);

  // Watches `ready` (up to spinMicros_) until it returns true; returns its last answer.
  template <typename Ready>
  bool spinUntil(const Ready& ready) const;

  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::shared_ptr<Job>> jobs_;
  std::atomic<bool> stop_{false};    // written under mutex_; watching workers read it without
  std::atomic<uint64_t> posted_{0};  // jobs queued so far (written under mutex_)
  unsigned sleeping_ = 0;            // workers waiting on wake_ (under mutex_)
  std::atomic<uint64_t> sleeps_{0};
  unsigned spinMicros_;
  std::vector<std::thread> threads_;
  std::mutex callerSlot_;  // the caller's worker index (threadCount()) is used by one caller at a time
};

}  // namespace vkrt::exec
