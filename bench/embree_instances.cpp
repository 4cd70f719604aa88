// vkrt_embree_instances: where a top-level build's time goes when every instance is an Embree instance geometry,
// measured on Embree 3 alone (no Vulkan, no vkrt). A top level of N instances of one small scene (two triangles)
// is set up the way src/accel/tlas.cpp does it, and each step is timed on its own:
//   make    rtcNewGeometry(INSTANCE), instanced scene, transform, mask, rtcCommitGeometry, N times: on the calling
//           thread, then in chunks of 1,024 on a TBB arena of 2, 4, ... threads (up to --threads)
//   attach  rtcAttachGeometryByID of the N geometries in index order, on the calling thread
//   commit  rtcCommitScene of the instance level (robust, high quality), on --threads build threads
// The figures are the best of --repeat rounds, in milliseconds. vkrt_tracebench's TLAS column compares vkrt's
// whole build with the commit alone; this program shows how much of the rest Embree's own objects cost.
//
// Usage: vkrt_embree_instances [--instances N] [--threads T] [--repeat R]
#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

namespace {

double now() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

[[noreturn]] void usage() {
  std::fprintf(stderr, "usage: vkrt_embree_instances [--instances N] [--threads T] [--repeat R]\n");
  std::exit(2);
}

RTCScene twoTriangles(RTCDevice device) {
  RTCScene scene = rtcNewScene(device);
  RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  const float v[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
  const unsigned ix[6] = {0, 1, 2, 1, 3, 2};
  std::memcpy(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 12, 4), v, sizeof v);
  std::memcpy(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 12, 2), ix, sizeof ix);
  rtcCommitGeometry(g);
  rtcAttachGeometry(scene, g);
  rtcReleaseGeometry(g);
  rtcCommitScene(scene);
  return scene;
}

struct Steps {
  double make = 0, attach = 0, commit = 0;  // seconds
};

// One top level: its geometries made on `makeThreads` threads (1: a plain loop), attached, committed, released.
Steps buildOnce(RTCDevice device, RTCScene blas, const std::vector<float>& transforms, unsigned makeThreads) {
  const size_t n = transforms.size() / 12;
  std::vector<RTCGeometry> geometries(n);
  auto make = [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_INSTANCE);
      rtcSetGeometryInstancedScene(g, blas);
      rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, &transforms[12 * i]);
      rtcSetGeometryMask(g, 0xFF);
      rtcCommitGeometry(g);
      geometries[i] = g;
    }
  };
  RTCScene scene = rtcNewScene(device);
  rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
  Steps s;
  double t = now();
  if (makeThreads == 1) {
    make(0, n);
  } else {
    tbb::task_arena arena{static_cast<int>(makeThreads)};
    arena.execute([&] {
      tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1024),
                        [&](const tbb::blocked_range<size_t>& r) { make(r.begin(), r.end()); });
    });
  }
  s.make = now() - t;
  t = now();
  for (size_t i = 0; i < n; ++i) rtcAttachGeometryByID(scene, geometries[i], unsigned(i));
  s.attach = now() - t;
  for (RTCGeometry g : geometries) rtcReleaseGeometry(g);
  t = now();
  rtcCommitScene(scene);
  s.commit = now() - t;
  rtcReleaseScene(scene);
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  size_t instances = 100000;
  unsigned threads = 16, repeat = 5;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (i + 1 >= argc) usage();
    const long v = std::strtol(argv[++i], nullptr, 10);
    if (v <= 0) usage();
    if (a == "--instances")
      instances = size_t(v);
    else if (a == "--threads")
      threads = unsigned(v);
    else if (a == "--repeat")
      repeat = unsigned(v);
    else
      usage();
  }
  const std::string config = "threads=" + std::to_string(threads);
  RTCDevice device = rtcNewDevice(config.c_str());
  if (!device) {
    std::fprintf(stderr, "vkrt_embree_instances: rtcNewDevice failed\n");
    return 1;
  }
  RTCScene blas = twoTriangles(device);
  std::vector<float> transforms(12 * instances, 0.0f);
  const size_t side = size_t(std::max(1.0, std::ceil(std::sqrt(double(instances)))));
  for (size_t i = 0; i < instances; ++i) {
    float* m = &transforms[12 * i];
    m[0] = m[5] = m[10] = 1;
    m[3] = 2.0f * float(i % side);
    m[7] = 2.0f * float(i / side);
  }
  std::printf("vkrt_embree_instances: %zu instances of a 2-triangle scene, %u build threads, best of %u (ms)\n",
              instances, threads, repeat);
  std::printf("%12s %10s %10s %10s %14s\n", "make threads", "make", "attach", "commit", "ns/instance");
  for (unsigned m = 1; m <= threads; m *= 2) {
    Steps best;
    for (unsigned r = 0; r < repeat; ++r) {
      const Steps s = buildOnce(device, blas, transforms, m);
      if (r == 0 || s.make < best.make) best.make = s.make;
      if (r == 0 || s.attach < best.attach) best.attach = s.attach;
      if (r == 0 || s.commit < best.commit) best.commit = s.commit;
    }
    std::printf("%12u %10.2f %10.2f %10.2f %14.0f\n", m, best.make * 1e3, best.attach * 1e3, best.commit * 1e3,
                best.make * 1e9 / double(instances));
    if (m < threads && m * 2 > threads) m = threads / 2;  // the last row is --threads itself
  }
  rtcReleaseScene(blas);
  rtcReleaseDevice(device);
  return 0;
}
