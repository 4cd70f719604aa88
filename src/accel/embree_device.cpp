#include "accel/embree_device.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <atomic>

#include "accel/accel.hpp"

namespace vkrt::accel {
namespace {

std::atomic<unsigned> gBuildThreads{0};  // 0: Embree's default

}  // namespace

void setBuildThreads(unsigned threads) { gBuildThreads.store(threads); }

namespace detail {

// ThreadSanitizer does not see TBB's synchronization (the library is not instrumented): worker threads that this
// function starts made every test process that used them report a race at exit, where static destructors free
// what the workers wrote. Under it the chunks run on the calling thread; Embree's own use of TBB is covered by
// tests/tsan.supp.
#if defined(__SANITIZE_THREAD__)
constexpr bool kUnderThreadSanitizer = true;
#else
constexpr bool kUnderThreadSanitizer = false;
#endif

void parallelChunks(size_t n, size_t grain, size_t serialBelow, const std::function<void(size_t, size_t)>& body) {
  if (n == 0) return;
  const unsigned threads = gBuildThreads.load();
  if (n < serialBelow || threads == 1 || kUnderThreadSanitizer) {
    body(0, n);
    return;
  }
  tbb::task_arena arena(threads ? int(threads) : tbb::task_arena::automatic);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, grain),
                      [&](const tbb::blocked_range<size_t>& range) { body(range.begin(), range.end()); });
  });
}

namespace {

// The innermost EmbreeErrors scope of this thread: where the error callback appends.
thread_local EmbreeErrors* tCurrentScope = nullptr;
thread_local std::string* tCurrentMessages = nullptr;

void onEmbreeError(void*, RTCError code, const char* message) {
  if (!tCurrentMessages) return;  // an error outside any scope (none of vkrt's calls): dropped, never fatal
  if (!tCurrentMessages->empty()) *tCurrentMessages += "; ";
  *tCurrentMessages += message ? message : "error";
  *tCurrentMessages += " (RTCError " + std::to_string(int(code)) + ")";
}

struct Device {
  RTCDevice handle = nullptr;
  std::string error;

  Device() {
    // verbose=0: Embree prints nothing; its errors come back through the callback as strings. threads: Embree's
    // builders use as many threads as setBuildThreads() asked for (the runtime passes its worker pool's count),
    // else every hardware thread.
    std::string config = "verbose=0";
    if (const unsigned threads = gBuildThreads.load()) config += ",threads=" + std::to_string(threads);
    handle = rtcNewDevice(config.c_str());
    if (!handle) {
      error = "Embree: cannot create a device (RTCError " + std::to_string(int(rtcGetDeviceError(nullptr))) + ")";
      return;
    }
    rtcSetDeviceErrorFunction(handle, onEmbreeError, nullptr);
    // Traversal needs these compiled into the Embree library (Debian's build has them all): instance masks and
    // SKIP_TRIANGLES/SKIP_AABBS are ray masks, any-hit shaders and culling are context filter functions, boxes are
    // user geometries, a Tlas instances Blas scenes.
    struct Needed {
      RTCDeviceProperty property;
      const char* name;
    };
    const Needed needed[] = {
        {RTC_DEVICE_PROPERTY_RAY_MASK_SUPPORTED, "ray masks"},
        {RTC_DEVICE_PROPERTY_FILTER_FUNCTION_SUPPORTED, "filter functions"},
        {RTC_DEVICE_PROPERTY_TRIANGLE_GEOMETRY_SUPPORTED, "triangle geometry"},
        {RTC_DEVICE_PROPERTY_USER_GEOMETRY_SUPPORTED, "user geometry"},
        {RTC_DEVICE_PROPERTY_BACKFACE_CULLING_ENABLED, nullptr},  // must be off: vkrt culls by Vulkan's rules
    };
    for (const Needed& n : needed) {
      const bool on = rtcGetDeviceProperty(handle, n.property) != 0;
      if (n.name && !on) error = std::string("Embree was built without ") + n.name;
      if (!n.name && on) error = "Embree was built with backface culling, which Vulkan's facing rules forbid";
    }
    if (!error.empty()) {
      rtcReleaseDevice(handle);
      handle = nullptr;
    }
  }
  // The device lives until the process exits: structures may be destroyed from static destructors of other
  // libraries, and Embree's TBB threads must not lose their device underneath them.
};

}  // namespace

RTCDevice device(std::string* error) {
  static Device* const d = new Device();  // never destroyed, see above
  if (!d->handle && error) *error = d->error;
  return d->handle;
}

EmbreeErrors::EmbreeErrors() : outer_(tCurrentScope) {
  tCurrentScope = this;
  tCurrentMessages = &messages_;
  if (RTCDevice dev = device(nullptr)) rtcGetDeviceError(dev);  // forget an earlier error of this thread
}

EmbreeErrors::~EmbreeErrors() {
  tCurrentScope = outer_;
  tCurrentMessages = outer_ ? &outer_->messages_ : nullptr;
}

bool EmbreeErrors::failed(const char* what, std::string* error) {
  RTCDevice dev = device(nullptr);
  const RTCError code = dev ? rtcGetDeviceError(dev) : RTC_ERROR_UNKNOWN;
  if (code == RTC_ERROR_NONE && messages_.empty()) return false;
  if (error) {
    *error = std::string(what) + ": ";
    *error += messages_.empty() ? "Embree error " + std::to_string(int(code)) : messages_;
  }
  messages_.clear();
  return true;
}

}  // namespace detail
}  // namespace vkrt::accel
