// Private to src/accel: the process's one Embree device and the capture of Embree's errors. (Embree's headers
// are included by src/accel's sources only; nothing outside this folder includes this file.)
#pragma once

#include <embree3/rtcore.h>

#include <cstddef>
#include <functional>
#include <string>

namespace vkrt::accel::detail {

// The process's Embree device, created on first use (thread-safe). Null, with `error` set, when Embree cannot
// create it or lacks a feature traversal relies on (ray masks, filter functions, user geometry, instancing).
RTCDevice device(std::string* error);

// Runs body(begin, end) over [0, n) in chunks of `grain` on Embree's build threads (a TBB arena of the thread
// count setBuildThreads() asked for), or on the calling thread alone when n is under `serialBelow`. For the
// serial parts of a build (copies and scans of the inputs, making instance geometries), so that they scale with
// Embree's own build.
// ThreadSanitizer does not see TBB's synchronization (the library is not instrumented): worker threads that
// parallelChunks starts made every test process that used them report a race at exit, where static destructors free
// what the workers wrote. Under it the chunks run on the calling thread; Embree's own use of TBB is covered by
// tests/tsan.supp, and what vkrt's callbacks write on Embree's threads is published through an atomic where vkrt
// reads it afterwards (tlas.cpp, BuildContext).
#if defined(__SANITIZE_THREAD__)
inline constexpr bool kUnderThreadSanitizer = true;
#else
inline constexpr bool kUnderThreadSanitizer = false;
#endif

void parallelChunks(size_t n, size_t grain, size_t serialBelow, const std::function<void(size_t, size_t)>& body);

// Collects the messages Embree reports on this thread while it lives. Embree calls its error callback on the
// thread whose API call failed (build work on TBB's threads is rethrown to the committing thread), and keeps
// its error code per thread, so concurrent builds on other threads do not mix their errors into this one.
class EmbreeErrors {
 public:
  EmbreeErrors();
  ~EmbreeErrors();
  EmbreeErrors(const EmbreeErrors&) = delete;
  EmbreeErrors& operator=(const EmbreeErrors&) = delete;

  // True (with `error` set to "<what>: <Embree's messages>") when Embree reported an error since the scope
  // began or since the last call; clears it.
  bool failed(const char* what, std::string* error);

 private:
  std::string messages_;
  EmbreeErrors* outer_;
};

}  // namespace vkrt::accel::detail
