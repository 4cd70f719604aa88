#include "accel/embree_device.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <mutex>

#include "accel/accel.hpp"

namespace vkrt::accel {
namespace {

std::atomic<unsigned> gBuildThreads{0};  // 0: Embree's default

// The instruction sets Debian's Embree 3 is compiled for, worst to best, with the CPU features each of Embree's
// kernels needs (Embree's own ISA definitions: AVX2 brings FMA3, BMI1/2 and LZCNT; its AVX-512 is Skylake's).
struct Isa {
  const char* name;  // Embree's `isa=` name
  bool (*runs)();    // whether this CPU runs it
};
const Isa kIsas[] = {
    {"sse2", [] { return bool(__builtin_cpu_supports("sse2")); }},
    {"sse4.2", [] { return __builtin_cpu_supports("sse4.2") && __builtin_cpu_supports("popcnt"); }},
    {"avx", [] { return __builtin_cpu_supports("sse4.2") && __builtin_cpu_supports("avx"); }},
    {"avx2",
     [] {
       return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") && __builtin_cpu_supports("bmi") &&
              __builtin_cpu_supports("bmi2");
     }},
    {"avx512",
     [] {
       return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512cd") &&
              __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512bw") &&
              __builtin_cpu_supports("avx512vl");
     }},
};
constexpr int kIsaCount = int(sizeof kIsas / sizeof kIsas[0]);

std::mutex gIsaMutex;
int gIsaChosen = kIsaCount - 1;  // an index into kIsas: the best unless setIsa() said otherwise
bool gIsaSet = false;            // setIsa() named one (Embree's `isa=` option is passed)
bool gDeviceMade = false;        // the device exists: the choice is fixed

}  // namespace

void setBuildThreads(unsigned threads) { gBuildThreads.store(threads); }

bool setIsa(std::string_view isa, std::string* error) {
  int chosen = kIsaCount - 1;
  bool named = !isa.empty();
  if (named) {
    chosen = -1;
    for (int i = 0; i < kIsaCount; ++i)
      if (isa == kIsas[i].name) chosen = i;
    if (chosen < 0) {
      if (error) *error = "\"" + std::string(isa) + "\" is not one of Embree's sets: sse2, sse4.2, avx, avx2, avx512";
      return false;
    }
  }
  std::lock_guard lock(gIsaMutex);
  if (gDeviceMade && (chosen != gIsaChosen || named != gIsaSet)) {
    if (error)
      *error = std::string("Embree's kernels were chosen when the process's first device was created (") +
               kIsas[gIsaChosen].name + "); they cannot change while the process runs";
    return false;
  }
  gIsaChosen = chosen;
  gIsaSet = named;
  return true;
}

const char* isaInUse() {
  int chosen;
  {
    std::lock_guard lock(gIsaMutex);
    chosen = gIsaChosen;
  }
  while (chosen > 0 && !kIsas[chosen].runs()) --chosen;  // Embree falls back the same way
  return kIsas[chosen].name;
}

namespace detail {

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
    // isa: the kernels setIsa() chose (Embree caps them at what the CPU runs).
    std::string config = "verbose=0";
    if (const unsigned threads = gBuildThreads.load()) config += ",threads=" + std::to_string(threads);
    {
      std::lock_guard lock(gIsaMutex);
      gDeviceMade = true;
      if (gIsaSet) config += std::string(",isa=") + kIsas[gIsaChosen].name;
    }
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
