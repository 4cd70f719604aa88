#include "exec/thread_pool.hpp"

#include <immintrin.h>
#include <sched.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>

namespace vkrt::exec {

struct ThreadPool::Job {
  uint64_t count = 0;
  uint64_t chunk = 1;  // indices a worker takes at a time
  const std::function<void(uint64_t, unsigned)>* fn = nullptr;
  std::atomic<uint64_t> next{0};
  std::atomic<uint64_t> finished{0};
  std::mutex doneMutex;
  std::condition_variable done;
};

ThreadPool& ThreadPool::instance() {
  static ThreadPool pool(
      [] {
        unsigned n = std::thread::hardware_concurrency();
        if (const char* env = std::getenv("VKRT_THREADS")) {
          long v = std::strtol(env, nullptr, 10);
          if (v >= 1 && v <= 256) n = unsigned(v);
        }
        // The calling thread works too: N threads in all means N - 1 in the pool.
        return n > 1 ? n - 1 : 0;
      }(),
      [] {
        if (const char* env = std::getenv("VKRT_POOL_SPIN_US")) {
          const long v = std::strtol(env, nullptr, 10);
          if (v >= 0 && v <= 10000) return unsigned(v);
        }
        return kSpinMicroseconds;
      }());
  return pool;
}

ThreadPool::ThreadPool(unsigned threads, unsigned spinMicroseconds) : spinMicros_(spinMicroseconds) {
  for (unsigned i = 0; i < threads; ++i) threads_.emplace_back([this, i] { workerMain(i); });
}

ThreadPool::~ThreadPool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_.store(true, std::memory_order_relaxed);
  }
  wake_.notify_all();
  for (std::thread& t : threads_) t.join();
}

void ThreadPool::runJob(Job& job, unsigned worker) {
  for (;;) {
    uint64_t first = job.next.fetch_add(job.chunk, std::memory_order_relaxed);
    if (first >= job.count) return;
    uint64_t n = std::min(job.chunk, job.count - first);
    for (uint64_t i = first; i < first + n; ++i) (*job.fn)(i, worker);
    if (job.finished.fetch_add(n, std::memory_order_acq_rel) + n == job.count) {
      std::lock_guard<std::mutex> lock(job.doneMutex);
      job.done.notify_all();
    }
  }
}

template <typename Ready>
bool ThreadPool::spinUntil(const Ready& ready) const {
  if (spinMicros_ == 0) return ready();
  const auto until = std::chrono::steady_clock::now() + std::chrono::microseconds(spinMicros_);
  for (;;) {
    for (int i = 0; i < 32; ++i) {
      if (ready()) return true;
      _mm_pause();
    }
    if (std::chrono::steady_clock::now() >= until) return ready();
    sched_yield();  // a runnable thread waiting for this core runs first
  }
}

void ThreadPool::workerMain(unsigned index) {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    if (stop_.load(std::memory_order_relaxed)) return;
    while (!jobs_.empty() && jobs_.front()->next.load(std::memory_order_relaxed) >= jobs_.front()->count)
      jobs_.pop_front();  // every index is taken: the job needs no more workers
    if (jobs_.empty()) {
      const uint64_t seen = posted_.load(std::memory_order_relaxed);
      lock.unlock();
      spinUntil(
          [&] { return posted_.load(std::memory_order_relaxed) != seen || stop_.load(std::memory_order_relaxed); });
      lock.lock();
      if (posted_.load(std::memory_order_relaxed) == seen && !stop_.load(std::memory_order_relaxed)) {
        ++sleeping_;
        sleeps_.fetch_add(1, std::memory_order_relaxed);
        wake_.wait(lock, [&] {
          return stop_.load(std::memory_order_relaxed) || posted_.load(std::memory_order_relaxed) != seen;
        });
        --sleeping_;
      }
      continue;
    }
    std::shared_ptr<Job> job = jobs_.front();
    lock.unlock();
    runJob(*job, index);
    lock.lock();
  }
}

void ThreadPool::runWithWorkers(const std::shared_ptr<Job>& job) {
  bool sleepers;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    jobs_.push_back(job);
    posted_.fetch_add(1, std::memory_order_relaxed);
    sleepers = sleeping_ > 0;
  }
  if (sleepers) wake_.notify_all();
  runJob(*job, threadCount());
  auto finished = [&] { return job->finished.load(std::memory_order_acquire) == job->count; };
  if (spinUntil(finished)) return;
  std::unique_lock<std::mutex> lock(job->doneMutex);
  job->done.wait(lock, finished);
}

void ThreadPool::parallelFor(uint64_t count, const std::function<void(uint64_t, unsigned)>& fn) {
  if (count == 0) return;
  std::lock_guard<std::mutex> slot(callerSlot_);
  if (threads_.empty() || count == 1) {
    for (uint64_t i = 0; i < count; ++i) fn(i, threadCount());
    return;
  }
  auto job = std::make_shared<Job>();
  job->count = count;
  // Taking indices one at a time costs two contended atomics per index, as much as a small workgroup's work;
  // chunks of them still leave about 16 per worker for balancing uneven work.
  job->chunk = std::max<uint64_t>(1, count / (uint64_t(workerSlots()) * 16));
  job->fn = &fn;
  runWithWorkers(job);
}

void ThreadPool::runConcurrently(uint64_t count, const std::function<void(uint64_t)>& fn) {
  if (count == 0) return;
  if (threads_.empty() || count == 1) {
    for (uint64_t i = 0; i < count; ++i) fn(i);
    return;
  }
  const std::function<void(uint64_t, unsigned)> each = [&fn](uint64_t i, unsigned) { fn(i); };
  auto job = std::make_shared<Job>();
  job->count = count;
  job->chunk = 1;  // coarse work: one index at a time balances best
  job->fn = &each;
  runWithWorkers(job);
}

}  // namespace vkrt::exec
