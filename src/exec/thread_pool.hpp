// The process-wide pool of worker threads. It runs shader work, the workgroups of compute dispatches and the tiles of
// ray tracing launches (parallelFor), and coarse independent tasks: the stages of a pipeline to compile, the chunks of
// a large acceleration structure build's inputs to read (runConcurrently).
//
// Size: VKRT_THREADS threads in all if set (1..256), else the number of hardware threads. The thread calling
// parallelFor() works too, so the pool starts one thread fewer (a pool of N runs N + 1 threads at most); each gets
// a distinct worker index < workerSlots().
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace vkrt::exec {

class ThreadPool {
 public:
  static ThreadPool& instance();

  explicit ThreadPool(unsigned threads);
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
  // Distinct worker indices handed to fn: the pool's threads plus one per concurrently calling thread is
  // bounded by this (callers share the last slot under a lock, see parallelFor).
  unsigned workerSlots() const { return unsigned(threads_.size()) + 1; }

 private:
  struct Job;
  void workerMain(unsigned index);
  static void runJob(Job& job, unsigned worker);
  // Queues the job for the workers, works on it on the calling thread, and returns when every index is done.
  void runWithWorkers(const std::shared_ptr<Job>& job);

  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::shared_ptr<Job>> jobs_;
  bool stop_ = false;
  std::vector<std::thread> threads_;
  std::mutex callerSlot_;  // the caller's worker index (threadCount()) is used by one caller at a time
};

}  // namespace vkrt::exec
