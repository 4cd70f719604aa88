// vkrt's trace benchmark (a program, not a test): ray tracing pipelines through the Vulkan loader on vkrt next to
// raw Embree 3 tracing the same rays in the same process, and acceleration structure builds next to Embree's own.
//
// Scenes: procedural terrains of exactly N triangles (a grid of rows x cols quads, 2 triangles each, rows * cols =
// N / 2, with smooth hills and per-vertex noise). Per scene:
// - Builds: the terrain's BLAS (vkCmdBuildAccelerationStructuresKHR, PREFER_FAST_TRACE) next to rtcCommitScene of
//   the same triangles at the quality and flags vkrt uses for it (HIGH, robust); a TLAS of max(1000, N / 100)
//   instances of a 128-triangle BLAS next to rtcCommitScene of as many Embree instances. Mtriangles/s (Minstances/s
//   for TLAS), best of the repetitions.
// - Primary rays: one camera ray per pixel, the closest-hit shader only records t and the primitive
//   (bench/shaders/trace_*.r*), next to rtcIntersect1, rtcIntersect8 (coherent packets of 8 pixels of a row)
//   and rtcIntersect16 (8x2 pixels).
// - Paths: the camera ray and up to 4 cosine-weighted diffuse bounces per pixel (a deterministic hash per pixel
//   and bounce), next to rtcIntersect1 and rtcIntersect8/16 (8 or 16 pixels' paths in lockstep) on the same rays: the
//   bounce is computed from the hit's t and primitive with the same operations on both sides, so Embree does the
//   traversal only. Each side writes per pixel the rays traced and a checksum of the primitives hit; the program
//   reports how many pixels agree and how the ray totals compare (the shader's float rounding, e.g. contracted
//   multiply-adds or its own sin/cos, can move a bounce ray slightly, and a path then diverges).
// Both sides run on the same number of threads: VKRT_THREADS (--threads sets it before the Vulkan instance
// exists), the Embree side with std::threads taking chunks of 8x8-pixel tiles like vkrt's launch tiles.
// Rates are the best of repeated runs (real time), as a loaded machine slows some runs down.
//
// Many structures (each mode alone runs no terrain scene unless --sizes is given):
// - --many-tlas 1,16,17,256,1000: primary rays through N top levels chosen per pixel by address, next to raw
//   Embree tracing the same rays through N instance scenes (runManyTlas).
// - --many-blas 65536: N one-triangle bottom levels and their top level, built on the host (one deferred operation
//   per structure, joined by the calling thread, or with --join-thread by a new thread each, as the CTS does) and
//   in one recorded command, traced (--image rays) and destroyed, next to Embree building, tracing and releasing N
//   scenes and an instance scene; seconds per phase and memory (peak, what destruction leaves) (runManyBlas).
// - --tlas-builds 1e4,1e5,1e6: top-level builds of N instances alone, next to Embree's (tlasBuildFigures).
//
// Usage: vkrt_tracebench [--threads N] [--sizes 1e4,1e6,1e7] [--json out.json] [--quick] [--image WxH]
//                        [--min-time S] [--vkrt-only] [--many-tlas N,...] [--many-blas N [--join-thread] [--aabbs]]
//                        [--tlas-builds N,...]
#include <embree3/rtcore.h>
#include <malloc.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <string>
#include <vector>

#include "bench_common.hpp"
#include "gltf_util.hpp"
#include "trace_hit.rchit.spv.h"
#include "trace_instance.rchit.spv.h"
#include "trace_many.rgen.spv.h"
#include "trace_miss.rmiss.spv.h"
#include "trace_paths.rgen.spv.h"
#include "vkrt_commit.h"

namespace vkrt::bench {
namespace {

struct Options {
  unsigned threads = 0;  // 0: VKRT_THREADS or every hardware thread
  std::vector<uint64_t> sizes = {10000, 1000000, 10000000};
  std::string json;
  std::string gltf;  // --gltf file.glb: also the model's triangles (one mesh, world space)
  bool quick = false;
  uint32_t width = 1024, height = 1024;
  double minTime = 1.0;  // seconds of repetitions per figure
  uint32_t bounces = 4;
  bool vkrtOnly = false;               // --vkrt-only: no Embree tracing (for profiling vkrt's side)
  std::vector<uint32_t> manyTlas;      // --many-tlas 1,16,17,256,1000: top-level counts (runManyTlas)
  uint64_t manyTlasTriangles = 10000;  // the terrain they instance
  uint32_t manyBlas = 0;               // --many-blas N: one-triangle bottom levels (runManyBlas)
  std::vector<uint32_t> tlasBuilds;    // --tlas-builds 1e4,1e5,1e6: top-level builds alone (tlasBuildFigures)
  bool joinThread = false;             // --join-thread: each host build joined by a thread of its own (as the CTS)
  bool aabbs = false;                  // --aabbs: --many-blas structures of one box each instead (no trace)
};

// Seconds from vkQueueSubmit of an empty command buffer to vkQueueWaitIdle's return: the fixed cost in every
// vkrt figure (a build or a launch runs on the queue's thread).
double emptySubmitSeconds() {
  VkCommandBuffer cb = ctx().allocate();
  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  CHECK(vkBeginCommandBuffer(cb, &bi));
  CHECK(vkEndCommandBuffer(cb));
  double best = 0;
  for (int i = 0; i < 200; ++i) {
    const double start = wallSeconds();
    ctx().submit(cb);
    const double took = wallSeconds() - start;
    if (i == 0 || took < best) best = took;
  }
  vkFreeCommandBuffers(ctx().device, ctx().pool, 1, &cb);
  return best;
}

// ---- the scene

struct Terrain {
  uint32_t rows = 0, cols = 0;  // 0 for a glTF model
  std::vector<float> vertices;  // xyz
  std::vector<uint32_t> indices;
  float eye[3] = {-12.0f, -12.0f, 32.0f}, target[3] = {60.0f, 60.0f, 0.0f};  // the camera
  float up[3] = {0, 0, 1};
  std::string name;  // the glTF file, or empty for a terrain
  uint64_t triangles() const { return indices.size() / 3; }
};

// --gltf: every triangle primitive of the default scene of a glTF 2.0 file, in world space (node transforms
// applied), as one mesh; the camera looks at the model's bounds from the front and above (glTF is y-up).
Terrain loadModel(const std::string& path) {
  example::gProgram = "vkrt_tracebench";
  const tinygltf::Model model = gltf::load(path);
  Terrain t;
  t.name = path.substr(path.find_last_of('/') + 1);
  const int sceneIndex = model.defaultScene >= 0 ? model.defaultScene : 0;
  if (model.scenes.empty() || size_t(sceneIndex) >= model.scenes.size()) example::fail(path + " has no scene");
  struct Pending {
    int node;
    gltf::Mat4 parent;
    size_t depth;
  };
  std::vector<Pending> stack;
  for (int n : model.scenes[size_t(sceneIndex)].nodes)
    stack.push_back({n, {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}, 0});
  while (!stack.empty()) {
    const Pending at = stack.back();
    stack.pop_back();
    if (at.node < 0 || size_t(at.node) >= model.nodes.size() || at.depth >= model.nodes.size())
      example::fail(path + ": a bad node index or a cycle");
    const tinygltf::Node& node = model.nodes[size_t(at.node)];
    const gltf::Mat4 world = gltf::mul(at.parent, gltf::nodeMatrix(node));
    if (node.mesh >= 0 && size_t(node.mesh) < model.meshes.size()) {
      for (const tinygltf::Primitive& prim : model.meshes[size_t(node.mesh)].primitives) {
        const auto pos = prim.attributes.find("POSITION");
        if (prim.mode != TINYGLTF_MODE_TRIANGLES || pos == prim.attributes.end() || prim.indices < 0) continue;
        const tinygltf::Accessor& pa = model.accessors.at(size_t(pos->second));
        const tinygltf::Accessor& ia = model.accessors.at(size_t(prim.indices));
        const uint32_t base = uint32_t(t.vertices.size() / 3);
        for (size_t i = 0; i < pa.count; ++i) {
          double p[3];
          for (int c = 0; c < 3; ++c) p[c] = gltf::readComponent(model, pa, i, c);
          for (int r = 0; r < 3; ++r)
            t.vertices.push_back(float(world[r] * p[0] + world[4 + r] * p[1] + world[8 + r] * p[2] + world[12 + r]));
        }
        for (size_t i = 0; i + 2 < ia.count; i += 3)
          for (size_t k = 0; k < 3; ++k) t.indices.push_back(base + gltf::readIndex(model, ia, i + k));
      }
    }
    for (int c : node.children) stack.push_back({c, world, at.depth + 1});
  }
  if (t.indices.empty()) example::fail(path + " has no indexed triangle meshes in its default scene");
  float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
  for (size_t i = 0; i < t.vertices.size(); ++i) {
    lo[i % 3] = std::min(lo[i % 3], t.vertices[i]);
    hi[i % 3] = std::max(hi[i % 3], t.vertices[i]);
  }
  const float radius = 0.5f * std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                                        (hi[2] - lo[2]) * (hi[2] - lo[2]));
  const float dir[3] = {0.45f, 0.35f, 0.82f};  // from the model's centre towards the eye, about unit length
  for (int c = 0; c < 3; ++c) {
    t.target[c] = 0.5f * (lo[c] + hi[c]);
    t.eye[c] = t.target[c] + dir[c] * 2.2f * radius;
    t.up[c] = c == 1 ? 1.0f : 0.0f;
  }
  return t;
}

// Exactly `triangles` (even) triangles over [0, 100]^2: rows x cols quads with rows the largest divisor of the
// quad count not above its square root.
Terrain makeTerrain(uint64_t triangles) {
  Terrain t;
  const uint64_t quads = triangles / 2;
  uint64_t rows = uint64_t(std::sqrt(double(quads)));
  while (rows > 1 && quads % rows) --rows;
  t.rows = uint32_t(rows);
  t.cols = uint32_t(quads / rows);
  const uint32_t row = t.cols + 1;
  const float dx = 100.0f / float(t.cols), dy = 100.0f / float(t.rows);
  t.vertices.resize(size_t(t.rows + 1) * row * 3);
  for (uint32_t j = 0; j <= t.rows; ++j)
    for (uint32_t i = 0; i <= t.cols; ++i) {
      const float x = float(i) * dx, y = float(j) * dy;
      const float noise = float(hash32(j * row + i) >> 8) * (1.0f / 16777216.0f) - 0.5f;
      const float z = 12.0f * std::sin(0.12f * x) * std::cos(0.1f * y) + 5.0f * std::sin(0.45f * x + 0.3f * y) +
                      2.0f * std::sin(1.3f * x) * std::sin(1.1f * y) + 0.5f * std::min(dx, dy) * noise;
      float* v = &t.vertices[(size_t(j) * row + i) * 3];
      v[0] = x, v[1] = y, v[2] = z;
    }
  t.indices.resize(size_t(quads) * 6);
  uint32_t* ix = t.indices.data();
  for (uint32_t j = 0; j < t.rows; ++j)
    for (uint32_t i = 0; i < t.cols; ++i) {
      const uint32_t v = j * row + i;
      const uint32_t q[6] = {v, v + 1, v + row, v + row, v + 1, v + row + 1};
      std::memcpy(ix, q, sizeof q);
      ix += 6;
    }
  return t;
}

// The push constants of trace_paths.rgen.
struct Camera {
  float origin[4], lowerLeft[4], du[4], dv[4];
  uint32_t bounces;
};

Camera makeCamera(const Terrain& t, uint32_t width, uint32_t height, uint32_t bounces) {
  const float *eye = t.eye, *target = t.target, *up = t.up;
  float f[3], r[3], u[3];
  for (int i = 0; i < 3; ++i) f[i] = target[i] - eye[i];
  const float fl = std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
  for (float& c : f) c /= fl;
  // right = forward x up
  r[0] = f[1] * up[2] - f[2] * up[1], r[1] = f[2] * up[0] - f[0] * up[2], r[2] = f[0] * up[1] - f[1] * up[0];
  const float rl = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
  r[0] /= rl, r[1] /= rl, r[2] /= rl;
  u[0] = r[1] * f[2] - r[2] * f[1], u[1] = r[2] * f[0] - r[0] * f[2], u[2] = r[0] * f[1] - r[1] * f[0];
  const float halfH = std::tan(0.5f * 50.0f * 3.14159265f / 180.0f), halfW = halfH * float(width) / float(height);
  Camera c{};
  for (int i = 0; i < 3; ++i) {
    c.origin[i] = eye[i];
    c.lowerLeft[i] = f[i] - halfW * r[i] - halfH * u[i];
    c.du[i] = 2 * halfW * r[i] / float(width);
    c.dv[i] = 2 * halfH * u[i] / float(height);
  }
  c.bounces = bounces;
  return c;
}

// ---- the paths, as trace_paths.rgen computes them

void cameraRay(const Camera& c, uint32_t x, uint32_t y, float o[3], float d[3]) {
  for (int i = 0; i < 3; ++i) {
    o[i] = c.origin[i];
    d[i] = c.lowerLeft[i] + (float(x) + 0.5f) * c.du[i] + (float(y) + 0.5f) * c.dv[i];
  }
}

// The next ray of `pixel`'s path after bounce `b` hit primitive `p` at `t`: from the hit point off the
// surface, cosine-weighted around the normal facing the ray.
void bounceRay(const Terrain& s, uint32_t pixel, uint32_t b, float t, uint32_t p, float o[3], float d[3]) {
  const float* v[3];
  for (int k = 0; k < 3; ++k) v[k] = &s.vertices[size_t(s.indices[size_t(p) * 3 + k]) * 3];
  float e1[3], e2[3], n[3];
  for (int i = 0; i < 3; ++i) e1[i] = v[1][i] - v[0][i], e2[i] = v[2][i] - v[0][i];
  n[0] = e1[1] * e2[2] - e1[2] * e2[1];
  n[1] = e1[2] * e2[0] - e1[0] * e2[2];
  n[2] = e1[0] * e2[1] - e1[1] * e2[0];
  const float inv = 1.0f / std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  for (float& c : n) c *= inv;
  if (n[0] * d[0] + n[1] * d[1] + n[2] * d[2] > 0)
    for (float& c : n) c = -c;
  for (int i = 0; i < 3; ++i) o[i] = o[i] + t * d[i] + 1e-3f * n[i];
  const uint32_t h1 = hash32(pixel * 8u + b), h2 = hash32(h1);
  const float u1 = float(h1 >> 8) * (1.0f / 16777216.0f), u2 = float(h2 >> 8) * (1.0f / 16777216.0f);
  const float r = std::sqrt(u1), phi = 6.2831853f * u2;
  const float sg = n[2] >= 0 ? 1.0f : -1.0f;
  const float a = -1.0f / (sg + n[2]), c = n[0] * n[1] * a;
  const float t1[3] = {1.0f + sg * n[0] * n[0] * a, sg * c, -sg * n[0]}, t2[3] = {c, sg + n[1] * n[1] * a, -n[1]};
  const float x = r * std::cos(phi), y = r * std::sin(phi), z = std::sqrt(std::max(0.0f, 1.0f - u1));
  for (int i = 0; i < 3; ++i) d[i] = x * t1[i] + y * t2[i] + z * n[i];
}

// Per pixel: rays traced, checksum of the primitives hit (each + 1).
struct PixelResults {
  std::vector<uint32_t> rays, checksum;
  explicit PixelResults(size_t pixels) : rays(pixels), checksum(pixels) {}
  uint64_t totalRays() const {
    uint64_t n = 0;
    for (uint32_t r : rays) n += r;
    return n;
  }
};

constexpr uint32_t kTile = 8;  // the Embree side's tiles: 8x8 pixels, as vkrt's launch tiles

// ---- raw Embree

// The terrain in one Embree scene (no instance level), robust at HIGH quality as vkrt builds a PREFER_FAST_TRACE
// BLAS (src/accel/blas.cpp).
struct EmbreeScene {
  RTCDevice device;
  RTCScene scene = nullptr;
  double commitSeconds = 0;

  EmbreeScene(RTCDevice device, const Terrain& t) : device(device) {
    scene = rtcNewScene(device);
    RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    void* v = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 12, t.vertices.size() / 3);
    std::memcpy(v, t.vertices.data(), t.vertices.size() * 4);
    void* ix = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 12, t.triangles());
    std::memcpy(ix, t.indices.data(), t.indices.size() * 4);
    rtcSetGeometryBuildQuality(g, RTC_BUILD_QUALITY_HIGH);
    rtcCommitGeometry(g);
    rtcAttachGeometry(scene, g);
    rtcReleaseGeometry(g);
    rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
    const double start = wallSeconds();
    rtcCommitScene(scene);
    commitSeconds = wallSeconds() - start;
  }
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;
  ~EmbreeScene() { rtcReleaseScene(scene); }
};

void initRay(RTCRayHit& rh, const float o[3], const float d[3]) {
  rh.ray.org_x = o[0], rh.ray.org_y = o[1], rh.ray.org_z = o[2];
  rh.ray.dir_x = d[0], rh.ray.dir_y = d[1], rh.ray.dir_z = d[2];
  rh.ray.tnear = 0;
  rh.ray.tfar = 1e30f;
  rh.ray.time = 0;
  rh.ray.mask = ~0u;
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
}

// Runs f(context, x, y, pixel) for every pixel of a w x h image, tile by tile on the Embree side's threads.
template <class F>
void forEachPixel(uint32_t w, uint32_t h, F f) {
  const uint32_t tilesX = w / kTile, tiles = tilesX * (h / kTile);
  parallelChunks(tiles, 1, [&](uint64_t tile, uint64_t) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    const uint32_t x0 = uint32_t(tile % tilesX) * kTile, y0 = uint32_t(tile / tilesX) * kTile;
    for (uint32_t y = y0; y < y0 + kTile; ++y)
      for (uint32_t x = x0; x < x0 + kTile; ++x) f(context, x, y, y * w + x);
  });
}

// Every pixel's path with rtcIntersect1, tile by tile.
void traceEmbree1(RTCScene scene, const Terrain& s, const Camera& cam, uint32_t w, uint32_t h, PixelResults& out) {
  forEachPixel(w, h, [&](RTCIntersectContext& context, uint32_t x, uint32_t y, uint32_t pixel) {
    float o[3], d[3];
    cameraRay(cam, x, y, o, d);
    uint32_t rays = 0, checksum = 0;
    for (uint32_t b = 0;; ++b) {
      RTCRayHit rh;
      initRay(rh, o, d);
      rtcIntersect1(scene, &context, &rh);
      ++rays;
      if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) break;
      checksum += rh.hit.primID + 1;
      if (b == cam.bounces) break;
      bounceRay(s, pixel, b, rh.ray.tfar, rh.hit.primID, o, d);
    }
    out.rays[pixel] = rays;
    out.checksum[pixel] = checksum;
  });
}

// Embree's packet types and calls by width.
template <int N>
struct Packet;
template <>
struct Packet<8> {
  using RayHit = RTCRayHit8;
  static void intersect(const int* valid, RTCScene s, RTCIntersectContext* c, RayHit* r) {
    rtcIntersect8(valid, s, c, r);
  }
};
template <>
struct Packet<16> {
  using RayHit = RTCRayHit16;
  static void intersect(const int* valid, RTCScene s, RTCIntersectContext* c, RayHit* r) {
    rtcIntersect16(valid, s, c, r);
  }
};

// The same with rtcIntersect8 (each row of a tile a packet) or rtcIntersect16 (each pair of rows): the packet's
// paths in lockstep, finished lanes invalid.
template <int N>
void traceEmbreePackets(RTCScene scene, const Terrain& s, const Camera& cam, uint32_t w, uint32_t h,
                        PixelResults& out) {
  static_assert(kTile == 8 && N % kTile == 0);
  constexpr uint32_t kRows = N / kTile;
  const uint32_t tilesX = w / kTile, tiles = tilesX * (h / kTile);
  parallelChunks(tiles, 1, [&](uint64_t tile, uint64_t) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    const uint32_t x0 = uint32_t(tile % tilesX) * kTile, y0 = uint32_t(tile / tilesX) * kTile;
    for (uint32_t y = y0; y < y0 + kTile; y += kRows) {
      float o[N][3], d[N][3];
      uint32_t pixel[N], rays[N] = {}, checksum[N] = {};
      alignas(64) int valid[N];
      for (uint32_t l = 0; l < N; ++l) {
        const uint32_t px = x0 + l % kTile, py = y + l / kTile;
        pixel[l] = py * w + px;
        cameraRay(cam, px, py, o[l], d[l]);
        valid[l] = -1;
      }
      for (uint32_t b = 0;; ++b) {
        // Primary rays of a row are coherent; bounce rays are not.
        context.flags = b == 0 ? RTC_INTERSECT_CONTEXT_FLAG_COHERENT : RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
        alignas(64) typename Packet<N>::RayHit rh;
        for (uint32_t l = 0; l < N; ++l) {
          rh.ray.org_x[l] = o[l][0], rh.ray.org_y[l] = o[l][1], rh.ray.org_z[l] = o[l][2];
          rh.ray.dir_x[l] = d[l][0], rh.ray.dir_y[l] = d[l][1], rh.ray.dir_z[l] = d[l][2];
          rh.ray.tnear[l] = 0;
          rh.ray.tfar[l] = 1e30f;
          rh.ray.time[l] = 0;
          rh.ray.mask[l] = ~0u;
          rh.ray.id[l] = l;
          rh.ray.flags[l] = 0;
          rh.hit.geomID[l] = RTC_INVALID_GEOMETRY_ID;
          rh.hit.instID[0][l] = RTC_INVALID_GEOMETRY_ID;
        }
        Packet<N>::intersect(valid, scene, &context, &rh);
        bool any = false;
        for (uint32_t l = 0; l < N; ++l) {
          if (!valid[l]) continue;
          ++rays[l];
          const bool hit = rh.hit.geomID[l] != RTC_INVALID_GEOMETRY_ID;
          if (hit) checksum[l] += rh.hit.primID[l] + 1;
          if (!hit || b == cam.bounces) {
            valid[l] = 0;
            continue;
          }
          bounceRay(s, pixel[l], b, rh.ray.tfar[l], rh.hit.primID[l], o[l], d[l]);
          any = true;
        }
        if (!any) break;
      }
      for (uint32_t l = 0; l < N; ++l) {
        out.rays[pixel[l]] = rays[l];
        out.checksum[pixel[l]] = checksum[l];
      }
    }
  });
}

// ---- vkrt

VkDeviceSize alignUp(VkDeviceSize v, VkDeviceSize a) { return (v + a - 1) / a * a; }

// The pipeline (raygen, miss, triangle hit group), its SBT, and a descriptor set with the TLAS and the terrain.
struct TracePipeline : RayPipeline {
  // `raygen`: trace_paths.rgen, or trace_many.rgen (the same layout: binding 0 unused there).
  // `hit`: trace_hit.rchit (t and the primitive), or trace_instance.rchit (t and the instance).
  explicit TracePipeline(const uint32_t* raygenWords = kSpv_trace_paths_rgen,
                         size_t raygenBytes = sizeof kSpv_trace_paths_rgen,
                         const uint32_t* hitWords = kSpv_trace_hit_rchit,
                         size_t hitBytes = sizeof kSpv_trace_hit_rchit) {
    Context& c = ctx();
    const VkShaderStageFlags rg = VK_SHADER_STAGE_RAYGEN_BIT_KHR;
    const VkDescriptorSetLayoutBinding b[4] = {{0, VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 1, rg, nullptr},
                                               {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, rg, nullptr},
                                               {2, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, rg, nullptr},
                                               {3, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, rg, nullptr}};
    VkDescriptorSetLayoutCreateInfo dl{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    dl.bindingCount = 4;
    dl.pBindings = b;
    CHECK(vkCreateDescriptorSetLayout(c.device, &dl, nullptr, &setLayout));
    VkPushConstantRange range{rg, 0, sizeof(Camera)};
    VkPipelineLayoutCreateInfo pl{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    pl.setLayoutCount = 1;
    pl.pSetLayouts = &setLayout;
    pl.pushConstantRangeCount = 1;
    pl.pPushConstantRanges = &range;
    CHECK(vkCreatePipelineLayout(c.device, &pl, nullptr, &layout));

    VkShaderModule modules[3] = {shaderModule(raygenWords, raygenBytes),
                                 shaderModule(kSpv_trace_miss_rmiss, sizeof kSpv_trace_miss_rmiss),
                                 shaderModule(hitWords, hitBytes)};
    const VkShaderStageFlagBits stageBits[3] = {VK_SHADER_STAGE_RAYGEN_BIT_KHR, VK_SHADER_STAGE_MISS_BIT_KHR,
                                                VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR};
    VkPipelineShaderStageCreateInfo stages[3];
    VkRayTracingShaderGroupCreateInfoKHR groups[3];
    for (uint32_t i = 0; i < 3; ++i) {
      stages[i] = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
      stages[i].stage = stageBits[i];
      stages[i].module = modules[i];
      stages[i].pName = "main";
      groups[i] = {VK_STRUCTURE_TYPE_RAY_TRACING_SHADER_GROUP_CREATE_INFO_KHR};
      groups[i].type = i == 2 ? VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR
                              : VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR;
      groups[i].generalShader = i == 2 ? VK_SHADER_UNUSED_KHR : i;
      groups[i].closestHitShader = i == 2 ? 2 : VK_SHADER_UNUSED_KHR;
      groups[i].anyHitShader = VK_SHADER_UNUSED_KHR;
      groups[i].intersectionShader = VK_SHADER_UNUSED_KHR;
    }
    const VkDescriptorPoolSize sizes[2] = {{VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 1},
                                           {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 3}};
    create(stages, 3, groups, sizes, 2);
  }

  void bind(VkAccelerationStructureKHR tlas, const Buffer& vertices, const Buffer& indices, const Buffer& results) {
    VkWriteDescriptorSetAccelerationStructureKHR asw{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_KHR};
    asw.accelerationStructureCount = 1;
    asw.pAccelerationStructures = &tlas;
    const VkDescriptorBufferInfo bi[3] = {
        {vertices.buffer, 0, VK_WHOLE_SIZE}, {indices.buffer, 0, VK_WHOLE_SIZE}, {results.buffer, 0, VK_WHOLE_SIZE}};
    VkWriteDescriptorSet w[2] = {{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, &asw},
                                 {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET}};
    w[0].dstSet = set;
    w[0].dstBinding = 0;
    w[0].descriptorCount = 1;
    w[0].descriptorType = VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR;
    w[1].dstSet = set;
    w[1].dstBinding = 1;
    w[1].descriptorCount = 3;
    w[1].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    w[1].pBufferInfo = bi;
    vkUpdateDescriptorSets(ctx().device, 2, w, 0, nullptr);
  }

  // A command buffer with one vkCmdTraceRaysKHR of w x h.
  VkCommandBuffer record(const Camera& cam, uint32_t w, uint32_t h) {
    Context& c = ctx();
    VkCommandBuffer cb = c.allocate();
    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    CHECK(vkBeginCommandBuffer(cb, &bi));
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, pipeline);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, layout, 0, 1, &set, 0, nullptr);
    vkCmdPushConstants(cb, layout, VK_SHADER_STAGE_RAYGEN_BIT_KHR, 0, sizeof cam, &cam);
    c.cmdTraceRays(cb, &raygen, &miss, &hit, &callable, w, h, 1);
    CHECK(vkEndCommandBuffer(cb));
    return cb;
  }
};

// ---- measuring

struct Timing {
  double best = 0;       // seconds, the fastest run
  double cpuPerRun = 0;  // process CPU seconds per run, averaged
};

// Runs f once untimed, then again until `minTime` has passed (at least twice, at most `maxRuns` times).
template <class F>
Timing measure(double minTime, F f, uint32_t maxRuns = 1000) {
  f();
  Timing t;
  const double start = wallSeconds(), cpuStart = processCpuSeconds();
  uint32_t runs = 0;
  for (; runs < 2 || (wallSeconds() - start < minTime && runs < maxRuns); ++runs) {
    const double s = wallSeconds();
    f();
    const double took = wallSeconds() - s;
    if (runs == 0 || took < t.best) t.best = took;
  }
  t.cpuPerRun = (processCpuSeconds() - cpuStart) / runs;
  return t;
}

struct Compared {
  uint64_t vkrtRays = 0, embreeRays = 0;
  double pixelsAgreeing = 0;  // fraction with the same rays and checksum
};

Compared compare(const PixelResults& vk, const PixelResults& em) {
  Compared c;
  c.vkrtRays = vk.totalRays();
  c.embreeRays = em.totalRays();
  size_t same = 0;
  for (size_t i = 0; i < vk.rays.size(); ++i) same += vk.rays[i] == em.rays[i] && vk.checksum[i] == em.checksum[i];
  c.pixelsAgreeing = double(same) / double(vk.rays.size());
  return c;
}

struct TraceFigures {
  Compared rays;
  double vkrt = 0, embree1 = 0, embree8 = 0, embree16 = 0;              // Mrays/s (real time, best run)
  double vkrtCpu = 0, embree1Cpu = 0, embree8Cpu = 0, embree16Cpu = 0;  // Mrays per CPU second
  bool embree8Agrees = false, embree16Agrees = false;  // the packets traced exactly rtcIntersect1's paths
  double bestPacket() const { return std::max(embree8, embree16); }
};

struct SizeFigures {
  std::string name;  // the glTF file (--gltf), or empty for a terrain
  uint64_t triangles = 0;
  uint32_t rows = 0, cols = 0;
  double blasVkrt = 0, blasEmbree = 0, blasEmbreeWithSetup = 0;  // Mtriangles/s
  uint32_t tlasInstances = 0;
  double tlasVkrt = 0, tlasEmbree = 0, tlasEmbreeWithSetup = 0;  // Minstances/s
  TraceFigures primary, paths;
};

// vkrt's launch and both Embree calls on the scene, for one camera (its bounces).
TraceFigures traceFigures(const Options& o, TracePipeline& tp, Buffer& results, RTCScene scene, const Terrain& t,
                          const Camera& cam) {
  TraceFigures f;
  const size_t pixels = size_t(o.width) * o.height;
  VkCommandBuffer cb = tp.record(cam, o.width, o.height);
  PixelResults vk(pixels), em1(pixels), em8(pixels), em16(pixels);
  const Timing tv = measure(o.minTime, [&] { ctx().submit(cb); });
  vkFreeCommandBuffers(ctx().device, ctx().pool, 1, &cb);
  const uint32_t* r = results.as<uint32_t>();
  for (size_t i = 0; i < pixels; ++i) vk.rays[i] = r[2 * i], vk.checksum[i] = r[2 * i + 1];
  if (o.vkrtOnly) {
    f.rays.vkrtRays = vk.totalRays();
    f.vkrt = double(f.rays.vkrtRays) * 1e-6 / tv.best;
    f.vkrtCpu = double(f.rays.vkrtRays) * 1e-6 / tv.cpuPerRun;
    return f;
  }
  const Timing t1 = measure(o.minTime, [&] { traceEmbree1(scene, t, cam, o.width, o.height, em1); });
  const Timing t8 = measure(o.minTime, [&] { traceEmbreePackets<8>(scene, t, cam, o.width, o.height, em8); });
  const Timing t16 = measure(o.minTime, [&] { traceEmbreePackets<16>(scene, t, cam, o.width, o.height, em16); });
  f.rays = compare(vk, em1);
  const Compared c8 = compare(em8, em1);
  f.embree8Agrees = c8.pixelsAgreeing == 1.0;
  const Compared c16 = compare(em16, em1);
  f.embree16Agrees = c16.pixelsAgreeing == 1.0;
  // Each side's rate counts the rays that side traced.
  const double vkRays = double(f.rays.vkrtRays) * 1e-6, emRays = double(f.rays.embreeRays) * 1e-6;
  const double em8Rays = double(c8.vkrtRays) * 1e-6, em16Rays = double(c16.vkrtRays) * 1e-6;
  f.vkrt = vkRays / tv.best;
  f.embree1 = emRays / t1.best;
  f.embree8 = em8Rays / t8.best;
  f.embree16 = em16Rays / t16.best;
  f.vkrtCpu = vkRays / tv.cpuPerRun;
  f.embree1Cpu = emRays / t1.cpuPerRun;
  f.embree8Cpu = em8Rays / t8.cpuPerRun;
  f.embree16Cpu = em16Rays / t16.cpuPerRun;
  return f;
}

// A top level of `n` instances of a small terrain (128 triangles, an Embree scene of its own in vkrt) on a grid:
// vkrt's build (submit to idle, into a fresh structure) next to Embree's rtcCommitScene of an instance scene of the
// same transforms (robust, high quality), alone and with making its instance geometries. Minstances/s, best runs.
struct TlasBuildFigures {
  double vkrt = 0, embree = 0, embreeWithSetup = 0;
};

TlasBuildFigures tlasBuildFigures(const Options& o, RTCDevice device, uint32_t n) {
  TlasBuildFigures f;
  const Terrain small = makeTerrain(128);
  AccelStructures tas;
  const VkAccelerationStructureKHR smallBlas = tas.build(
      VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR,
      tas.triangles(small.vertices.data(), small.vertices.size() / 3, small.indices.data(), small.indices.size()),
      uint32_t(small.triangles()));
  const uint32_t side = uint32_t(std::ceil(std::sqrt(double(n))));
  std::vector<VkAccelerationStructureInstanceKHR> instances(n, tas.identityInstance(smallBlas));
  for (uint32_t i = 0; i < n; ++i) {
    instances[i].transform.matrix[0][3] = 110.0f * float(i % side);
    instances[i].transform.matrix[1][3] = 110.0f * float(i / side);
    instances[i].instanceCustomIndex = i;
  }
  EmbreeScene smallEmbree(device, small);
  double eBest = 0, eSetupBest = 0, eTotal = 0;
  for (uint32_t i = 0; i < 20 && (i < 2 || eTotal < o.minTime); ++i) {
    const double start = wallSeconds();
    RTCScene scene = rtcNewScene(device);
    for (uint32_t k = 0; k < n; ++k) {
      RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_INSTANCE);
      rtcSetGeometryInstancedScene(g, smallEmbree.scene);
      rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, &instances[k].transform.matrix[0][0]);
      rtcCommitGeometry(g);
      rtcAttachGeometryByID(scene, g, k);
      rtcReleaseGeometry(g);
    }
    rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
    const double commit = wallSeconds();
    rtcCommitScene(scene);
    const double end = wallSeconds();
    rtcReleaseScene(scene);
    eTotal += end - start;
    if (i == 0 || end - commit < eBest) eBest = end - commit;
    if (i == 0 || end - start < eSetupBest) eSetupBest = end - start;
  }
  const double minst = double(n) * 1e-6;
  f.embree = minst / eBest;
  f.embreeWithSetup = minst / eSetupBest;
  f.vkrt = minst / tas.timeBuilds(VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR,
                                  tas.instances(instances.data(), instances.size()), n,
                                  uint32_t(std::clamp(o.minTime / eSetupBest, 2.0, 20.0)));
  return f;
}

SizeFigures runScene(const Options& o, RTCDevice device, const Terrain& t) {
  SizeFigures f;
  std::fprintf(stderr, "scene: %s%llu triangles\n", t.name.empty() ? "" : (t.name + ", ").c_str(),
               (unsigned long long)t.triangles());
  f.name = t.name;
  f.triangles = t.triangles();
  f.rows = t.rows;
  f.cols = t.cols;
  const double mtris = double(f.triangles) * 1e-6;

  // BLAS: Embree's own build first (its time sets the repetitions of both).
  std::unique_ptr<EmbreeScene> embree;
  double embreeBest = 0, embreeSetupBest = 0, total = 0;
  for (uint32_t i = 0; i < 20 && (i < 2 || total < o.minTime); ++i) {
    embree.reset();
    const double start = wallSeconds();
    embree = std::make_unique<EmbreeScene>(device, t);
    const double setup = wallSeconds() - start;
    total += setup;
    if (i == 0 || embree->commitSeconds < embreeBest) embreeBest = embree->commitSeconds;
    if (i == 0 || setup < embreeSetupBest) embreeSetupBest = setup;
  }
  f.blasEmbree = mtris / embreeBest;
  f.blasEmbreeWithSetup = mtris / embreeSetupBest;
  const uint32_t repeat = uint32_t(std::clamp(o.minTime / embreeSetupBest, 2.0, 20.0));
  AccelStructures as;
  const VkAccelerationStructureGeometryKHR geometry =
      as.triangles(t.vertices.data(), t.vertices.size() / 3, t.indices.data(), t.indices.size());
  f.blasVkrt =
      mtris / as.timeBuilds(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, geometry, uint32_t(f.triangles), repeat);
  const VkAccelerationStructureKHR blas =
      as.build(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, geometry, uint32_t(f.triangles));
  const VkAccelerationStructureInstanceKHR one = as.identityInstance(blas);
  const VkAccelerationStructureKHR tlas =
      as.build(VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, as.instances(&one, 1), 1);

  // TLAS: instances of a small terrain on a grid.
  f.tlasInstances = uint32_t(std::max<uint64_t>(1000, f.triangles / 100));
  const TlasBuildFigures tb = tlasBuildFigures(o, device, f.tlasInstances);
  f.tlasVkrt = tb.vkrt;
  f.tlasEmbree = tb.embree;
  f.tlasEmbreeWithSetup = tb.embreeWithSetup;

  // Tracing.
  Buffer vertices(t.vertices.size() * 4), indices(t.indices.size() * 4);
  std::memcpy(vertices.data, t.vertices.data(), t.vertices.size() * 4);
  std::memcpy(indices.data, t.indices.data(), t.indices.size() * 4);
  Buffer results(size_t(o.width) * o.height * 8);
  TracePipeline tp;
  tp.bind(tlas, vertices, indices, results);
  std::fprintf(stderr, "  primary rays\n");
  f.primary = traceFigures(o, tp, results, embree->scene, t, makeCamera(t, o.width, o.height, 0));
  std::fprintf(stderr, "  paths\n");
  f.paths = traceFigures(o, tp, results, embree->scene, t, makeCamera(t, o.width, o.height, o.bounces));
  return f;
}

// ---- many structures

// --many-tlas: the terrain's primary rays, each through one of N top-level structures chosen per pixel by its
// address (bench/shaders/trace_many.rgen); each top level is one identity instance of the terrain's BLAS, so every
// N traces the same rays to the same hits, and rays/s should not depend on N (the launch resolves each address
// once). Rates are against N = 1 of the same run.
struct ManyTlasFigures {
  uint32_t levels = 0;
  double vkrt = 0;                   // Mrays/s (best run)
  double vkrtCpu = 0;                // Mrays per CPU second (all threads' time, averaged over the runs)
  double agreeing = 0;               // fraction of pixels with the hits of the first N
  double embree = 0, embreeCpu = 0;  // raw Embree: N instance scenes of the terrain's scene, rtcIntersect1
};

std::vector<ManyTlasFigures> runManyTlas(const Options& o, RTCDevice device) {
  const Terrain t = makeTerrain(o.manyTlasTriangles);
  std::fprintf(stderr, "many top levels over a terrain of %llu triangles\n", (unsigned long long)t.triangles());
  AccelStructures as;
  const VkAccelerationStructureKHR blas =
      as.build(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR,
               as.triangles(t.vertices.data(), t.vertices.size() / 3, t.indices.data(), t.indices.size()),
               uint32_t(t.triangles()));
  const uint32_t most = *std::max_element(o.manyTlas.begin(), o.manyTlas.end());
  Buffer addresses(size_t(most) * 8), count(4), results(size_t(o.width) * o.height * 8);
  std::vector<VkAccelerationStructureKHR> tops;
  TracePipeline tp(kSpv_trace_many_rgen, sizeof kSpv_trace_many_rgen);
  const Camera cam = makeCamera(t, o.width, o.height, 0);
  // Raw Embree: the terrain's scene and N scenes of one instance of it, each pixel's ray through the one its hash
  // picks (as trace_many.rgen picks), with rtcIntersect1 tile by tile.
  std::unique_ptr<EmbreeScene> terrain;
  std::vector<RTCScene> embreeTops;
  if (!o.vkrtOnly) terrain = std::make_unique<EmbreeScene>(device, t);
  PixelResults em(size_t(o.width) * o.height);
  auto traceEmbree = [&](uint32_t n) {
    forEachPixel(o.width, o.height, [&](RTCIntersectContext& context, uint32_t x, uint32_t y, uint32_t pixel) {
      float org[3], dir[3];
      cameraRay(cam, x, y, org, dir);
      RTCRayHit rh;
      initRay(rh, org, dir);
      rtcIntersect1(embreeTops[hash32(pixel) % n], &context, &rh);
      em.rays[pixel] = 1;
      em.checksum[pixel] = rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? 0 : rh.hit.primID + 1;
    });
  };
  std::vector<uint32_t> first;
  std::vector<ManyTlasFigures> out;
  for (uint32_t n : o.manyTlas) {
    while (tops.size() < n) {
      VkAccelerationStructureInstanceKHR one = as.identityInstance(blas);
      one.instanceCustomIndex = uint32_t(tops.size());
      tops.push_back(as.build(VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, as.instances(&one, 1), 1));
      addresses.as<uint64_t>()[tops.size() - 1] = as.address(tops.back());
    }
    *count.as<uint32_t>() = n;
    tp.bind(tops[0], addresses, count, results);
    VkCommandBuffer cb = tp.record(cam, o.width, o.height);
    const Timing tv = measure(o.minTime, [&] { ctx().submit(cb); });
    vkFreeCommandBuffers(ctx().device, ctx().pool, 1, &cb);
    const uint32_t* r = results.as<uint32_t>();
    const size_t pixels = size_t(o.width) * o.height;
    std::vector<uint32_t> hits(pixels);
    for (size_t i = 0; i < pixels; ++i) hits[i] = r[2 * i + 1];
    if (first.empty()) first = hits;
    size_t same = 0;
    for (size_t i = 0; i < pixels; ++i) same += hits[i] == first[i];
    ManyTlasFigures f;
    if (terrain) {
      while (embreeTops.size() < n) {
        RTCScene top = rtcNewScene(device);
        RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_INSTANCE);
        rtcSetGeometryInstancedScene(g, terrain->scene);
        rtcCommitGeometry(g);
        rtcAttachGeometry(top, g);
        rtcReleaseGeometry(g);
        rtcSetSceneFlags(top, RTC_SCENE_FLAG_ROBUST);
        rtcCommitScene(top);
        embreeTops.push_back(top);
      }
      const Timing te = measure(o.minTime, [&] { traceEmbree(n); });
      f.embree = double(pixels) * 1e-6 / te.best;
      f.embreeCpu = double(pixels) * 1e-6 / te.cpuPerRun;
    }
    f.levels = n;
    f.vkrt = double(pixels) * 1e-6 / tv.best;
    f.vkrtCpu = double(pixels) * 1e-6 / tv.cpuPerRun;
    f.agreeing = double(same) / double(pixels);
    std::fprintf(stderr, "  %u top levels: %.2f Mrays/s\n", n, f.vkrt);
    out.push_back(f);
  }
  for (RTCScene s : embreeTops) rtcReleaseScene(s);
  return out;
}

// --many-blas N: N bottom-level structures of one triangle each and a top level of N instances of them, as the
// CTS's ray_tracing_pipeline.build.*.level_instances.triangles_N_1_1 builds them (cell k of a square grid holds
// triangle k): on the host (one vkBuildAccelerationStructuresKHR per structure with a deferred operation that the
// calling thread joins, as the cpuht_1 variant does) and recorded (one vkCmdBuildAccelerationStructuresKHR with N
// infos), next to Embree building N scenes and an instance scene over them in the same process. Each side then
// traces one primary ray per pixel of --image at the grid (rtcIntersect1 on Embree's side; the pixels must hit the
// same instances) and destroys everything. Per side: seconds of each phase, and memory: the resident set's peak
// over the side's run and what stays resident (after malloc_trim) and allocated (malloc's in-use bytes) once it is
// destroyed, each above what it was before the side began.
struct ManyBlasSide {
  bool ran = false;
  double blas = 0, tlas = 0, trace = 0, destroy = 0;  // seconds
  double peakMB = 0;                                  // resident set's peak during the side, over its start
  double keptMB = 0, heapKeptMB = 0;                  // resident / malloc'd after destruction, over the start
  std::vector<uint32_t> hits;                         // per pixel: instance + 1, 0 for a miss
  double total() const { return blas + tlas + trace + destroy; }
};
struct ManyBlasFigures {
  uint32_t count = 0;
  ManyBlasSide host, device, embree;
};

double residentMB() {
  long pages = 0, resident = 0;
  if (FILE* f = std::fopen("/proc/self/statm", "r")) {
    if (std::fscanf(f, "%ld %ld", &pages, &resident) != 2) resident = 0;
    std::fclose(f);
  }
  return double(resident) * double(sysconf(_SC_PAGESIZE)) / (1 << 20);
}
// The resident set's peak (VmHWM) since the last resetPeak (Linux: writing 5 to clear_refs resets it).
double peakResidentMB() {
  double kb = 0;
  if (FILE* f = std::fopen("/proc/self/status", "r")) {
    char line[256];
    while (std::fgets(line, sizeof line, f))
      if (std::sscanf(line, "VmHWM: %lf kB", &kb) == 1) break;
    std::fclose(f);
  }
  return kb / 1024;
}
void resetPeak() {
  if (FILE* f = std::fopen("/proc/self/clear_refs", "w")) {
    std::fputs("5", f);
    std::fclose(f);
  }
}
double heapMB() {
  const struct mallinfo2 m = mallinfo2();
  return double(m.uordblks + m.hblkhd) / (1 << 20);
}

// Measures one side: `run` does the whole side, calling `mark(phase seconds)` at the end of each phase.
struct SideMeter {
  double rss0, heap0;
  SideMeter() {
    resetPeak();
    rss0 = residentMB();
    heap0 = heapMB();
  }
  void finish(ManyBlasSide& s) const {
    s.ran = true;
    s.peakMB = peakResidentMB() - rss0;
    malloc_trim(0);  // what was freed goes back to the system: "kept" is what is still held
    s.keptMB = residentMB() - rss0;
    s.heapKeptMB = heapMB() - heap0;
  }
};

ManyBlasFigures runManyBlas(const Options& o, RTCDevice device) {
  Context& c = ctx();
  const uint32_t n = o.manyBlas;
  ManyBlasFigures f;
  f.count = n;
  std::fprintf(stderr, "%u one-%s bottom levels\n", n, o.aabbs ? "box" : "triangle");
  const uint32_t side = uint32_t(std::ceil(std::sqrt(double(n))));
  std::vector<float> vertices(size_t(n) * 9);
  for (uint32_t k = 0; k < n; ++k) {
    const float x0 = float(k % side) / float(side), y0 = float(k / side) / float(side), e = 1.0f / float(side);
    const float v[9] = {x0, y0, 1, x0 + e, y0 + 0.5f * e, 1, x0 + 0.5f * e, y0 + e, 1};
    std::memcpy(&vertices[size_t(k) * 9], v, sizeof v);
  }
  // The rays: from (0.5, 0.5, 0) through each pixel of the unit square at z = 1.
  Camera cam{};
  cam.origin[0] = cam.origin[1] = 0.5f;
  cam.lowerLeft[0] = cam.lowerLeft[1] = -0.5f;
  cam.lowerLeft[2] = 1;
  cam.du[0] = 1.0f / float(o.width);
  cam.dv[1] = 1.0f / float(o.height);
  const size_t pixels = size_t(o.width) * o.height;

  // --aabbs: structure k holds one box over cell k instead (as the CTS's aabbs_N_1_1 cases); not traced (the
  // benchmark's pipeline has no intersection shader).
  std::vector<float> boxes;
  if (o.aabbs) {
    boxes.resize(size_t(n) * 6);
    for (uint32_t k = 0; k < n; ++k) {
      const float x0 = float(k % side) / float(side), y0 = float(k / side) / float(side), e = 1.0f / float(side);
      const float b[6] = {x0, y0, 1, x0 + e, y0 + e, 1 + e};
      std::memcpy(&boxes[size_t(k) * 6], b, sizeof b);
    }
  }
  const size_t floatsEach = o.aabbs ? 6 : 9;
  const std::vector<float>& data = o.aabbs ? boxes : vertices;
  VkAccelerationStructureGeometryKHR g{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
  g.flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
  if (o.aabbs) {
    g.geometryType = VK_GEOMETRY_TYPE_AABBS_KHR;
    g.geometry.aabbs.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_AABBS_DATA_KHR;
    g.geometry.aabbs.stride = 24;
  } else {
    auto& tri = g.geometry.triangles;
    g.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
    tri.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
    tri.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
    tri.vertexStride = 12;
    tri.maxVertex = 2;
    tri.indexType = VK_INDEX_TYPE_NONE_KHR;
  }
  auto dataOf = [](VkAccelerationStructureGeometryKHR& geometry) -> VkDeviceOrHostAddressConstKHR& {
    return geometry.geometryType == VK_GEOMETRY_TYPE_AABBS_KHR ? geometry.geometry.aabbs.data
                                                               : geometry.geometry.triangles.vertexData;
  };
  VkAccelerationStructureBuildGeometryInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
  info.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
  info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
  info.geometryCount = 1;
  info.pGeometries = &g;
  const uint32_t one = 1;
  VkAccelerationStructureBuildSizesInfoKHR sizes{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
  c.buildSizes(c.device, VK_ACCELERATION_STRUCTURE_BUILD_TYPE_HOST_OR_DEVICE_KHR, &info, &one, &sizes);
  const VkDeviceSize each = alignUp(sizes.accelerationStructureSize, 256);
  const VkDeviceSize scratchEach = alignUp(std::max<VkDeviceSize>(sizes.buildScratchSize, 1), 256);
  const VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};
  const VkAccelerationStructureBuildRangeInfoKHR* pr = &range;
  TracePipeline tp(kSpv_trace_paths_rgen, sizeof kSpv_trace_paths_rgen, kSpv_trace_instance_rchit,
                   sizeof kSpv_trace_instance_rchit);
  Buffer unused(64), results(pixels * 8);

  // N structures in one buffer (as the CTS's pool places them), and a top level over them.
  struct Set {
    AccelStructures as;
    std::vector<VkAccelerationStructureKHR> blases;
    Set(uint32_t n, VkDeviceSize each) {
      Buffer& storage = as.buffer(
          n * each, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT);
      blases.resize(n);
      for (uint32_t k = 0; k < n; ++k) {
        VkAccelerationStructureCreateInfoKHR ci{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
        ci.buffer = storage.buffer;
        ci.offset = k * each;
        ci.size = each;
        ci.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
        CHECK(ctx().createAs(ctx().device, &ci, nullptr, &blases[k]));
      }
      as.structures = blases;  // destroyed with `as`
    }
  };
  // A side's trace (one launch) and its destruction.
  auto traceAndDestroy = [&](std::unique_ptr<Set>& set, VkAccelerationStructureKHR top, ManyBlasSide& s) {
    if (!o.aabbs) {
      tp.bind(top, unused, unused, results);
      VkCommandBuffer cb = tp.record(cam, o.width, o.height);
      const double start = wallSeconds();
      c.submit(cb);
      s.trace = wallSeconds() - start;
      vkFreeCommandBuffers(c.device, c.pool, 1, &cb);
      s.hits.resize(pixels);
      for (size_t i = 0; i < pixels; ++i) s.hits[i] = results.as<uint32_t>()[2 * i + 1];
    }
    const double start = wallSeconds();
    set.reset();
    s.destroy = wallSeconds() - start;
  };

  if (c.hostCommands) {
    SideMeter meter;
    auto host = std::make_unique<Set>(n, each);
    std::vector<uint8_t> scratch(scratchEach);
    double start = wallSeconds();
    for (uint32_t k = 0; k < n; ++k) {
      dataOf(g).hostAddress = &data[size_t(k) * floatsEach];
      info.dstAccelerationStructure = host->blases[k];
      info.scratchData.hostAddress = scratch.data();
      VkDeferredOperationKHR op;
      CHECK(c.createDeferred(c.device, nullptr, &op));
      VkResult r = c.hostBuild(c.device, op, 1, &info, &pr);
      if (r == VK_OPERATION_DEFERRED_KHR) {
        auto join = [&] {
          VkResult j;
          while ((j = c.joinDeferred(c.device, op)) != VK_SUCCESS)
            if (j != VK_THREAD_IDLE_KHR && j != VK_THREAD_DONE_KHR) fail("vkDeferredOperationJoinKHR", j);
        };
        if (o.joinThread) {
          std::thread t(join);  // the CTS's finishDeferredOperation with one worker thread
          t.join();
        } else {
          join();
        }
        r = c.deferredResult(c.device, op);
      } else if (r == VK_OPERATION_NOT_DEFERRED_KHR) {
        r = VK_SUCCESS;
      }
      if (r != VK_SUCCESS) fail("vkBuildAccelerationStructuresKHR", r);
      c.destroyDeferred(c.device, op, nullptr);
    }
    f.host.blas = wallSeconds() - start;
    // The top level on the host: instances refer to structures by handle.
    std::vector<VkAccelerationStructureInstanceKHR> instances(n);
    for (uint32_t k = 0; k < n; ++k) {
      instances[k] = host->as.identityInstance(host->blases[k]);
      instances[k].accelerationStructureReference = reinterpret_cast<uint64_t>(host->blases[k]);
    }
    VkAccelerationStructureGeometryKHR ig{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
    ig.geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;
    ig.geometry.instances.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR;
    ig.geometry.instances.data.hostAddress = instances.data();
    VkAccelerationStructureBuildGeometryInfoKHR ti{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
    ti.type = VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR;
    ti.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
    ti.geometryCount = 1;
    ti.pGeometries = &ig;
    VkAccelerationStructureBuildSizesInfoKHR ts{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
    c.buildSizes(c.device, VK_ACCELERATION_STRUCTURE_BUILD_TYPE_HOST_OR_DEVICE_KHR, &ti, &n, &ts);
    Buffer& storage =
        host->as.buffer(ts.accelerationStructureSize, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR |
                                                          VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT);
    VkAccelerationStructureCreateInfoKHR ci{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
    ci.buffer = storage.buffer;
    ci.size = ts.accelerationStructureSize;
    ci.type = VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR;
    VkAccelerationStructureKHR top;
    CHECK(c.createAs(c.device, &ci, nullptr, &top));
    host->as.structures.push_back(top);
    std::vector<uint8_t> topScratch(ts.buildScratchSize + 1);
    ti.dstAccelerationStructure = top;
    ti.scratchData.hostAddress = topScratch.data();
    const VkAccelerationStructureBuildRangeInfoKHR tr{n, 0, 0, 0};
    const VkAccelerationStructureBuildRangeInfoKHR* ptr = &tr;
    start = wallSeconds();
    CHECK(c.hostBuild(c.device, VK_NULL_HANDLE, 1, &ti, &ptr));
    f.host.tlas = wallSeconds() - start;
    std::vector<VkAccelerationStructureInstanceKHR>().swap(instances);  // (its memory too)
    traceAndDestroy(host, top, f.host);
    meter.finish(f.host);
  }

  {
    SideMeter meter;
    auto dev = std::make_unique<Set>(n, each);
    Buffer& vb = dev->as.buffer(data.size() * 4, AccelStructures::kInput);
    std::memcpy(vb.data, data.data(), data.size() * 4);
    Buffer& scratch = dev->as.buffer(n * scratchEach + 256,
                                     VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT);
    const VkDeviceAddress scratchBase = alignUp(scratch.address(), 256);
    VkCommandBuffer cb = c.allocate();
    {
      std::vector<VkAccelerationStructureGeometryKHR> geometries(n, g);
      std::vector<VkAccelerationStructureBuildGeometryInfoKHR> infos(n, info);
      std::vector<const VkAccelerationStructureBuildRangeInfoKHR*> ranges(n, &range);
      for (uint32_t k = 0; k < n; ++k) {
        dataOf(geometries[k]).deviceAddress = vb.address() + VkDeviceAddress(k) * floatsEach * 4;
        infos[k].pGeometries = &geometries[k];
        infos[k].dstAccelerationStructure = dev->blases[k];
        infos[k].scratchData.deviceAddress = scratchBase + k * scratchEach;
      }
      VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
      CHECK(vkBeginCommandBuffer(cb, &bi));
      c.cmdBuild(cb, n, infos.data(), ranges.data());
      CHECK(vkEndCommandBuffer(cb));
    }
    double start = wallSeconds();
    c.submit(cb);
    f.device.blas = wallSeconds() - start;
    vkFreeCommandBuffers(c.device, c.pool, 1, &cb);
    std::vector<VkAccelerationStructureInstanceKHR> instances(n);
    for (uint32_t k = 0; k < n; ++k) instances[k] = dev->as.identityInstance(dev->blases[k]);
    const VkAccelerationStructureGeometryKHR ig = dev->as.instances(instances.data(), n);
    std::vector<VkAccelerationStructureInstanceKHR>().swap(instances);  // (its memory too)
    start = wallSeconds();
    const VkAccelerationStructureKHR top = dev->as.build(VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, ig, n);
    f.device.tlas = wallSeconds() - start;
    traceAndDestroy(dev, top, f.device);
    meter.finish(f.device);
  }

  if (!o.vkrtOnly) {
    // Embree: each triangle in a scene of its own (robust, as vkrt builds), then an instance scene over them.
    SideMeter meter;
    std::vector<RTCScene> scenes(n);
    double start = wallSeconds();
    for (uint32_t k = 0; k < n; ++k) {
      RTCScene s = rtcNewScene(device);
      RTCGeometry geo;
      if (o.aabbs) {
        geo = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER);
        rtcSetGeometryUserPrimitiveCount(geo, 1);
        rtcSetGeometryUserData(geo, &boxes[size_t(k) * 6]);
        rtcSetGeometryBoundsFunction(
            geo,
            [](const RTCBoundsFunctionArguments* a) {
              const float* b = static_cast<const float*>(a->geometryUserPtr);
              *a->bounds_o = RTCBounds{b[0], b[1], b[2], 0, b[3], b[4], b[5], 0};
            },
            nullptr);
      } else {
        geo = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
        void* v = rtcSetNewGeometryBuffer(geo, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 12, 3);
        std::memcpy(v, &vertices[size_t(k) * 9], 36);
        auto* ix =
            static_cast<uint32_t*>(rtcSetNewGeometryBuffer(geo, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 12, 1));
        ix[0] = 0, ix[1] = 1, ix[2] = 2;
      }
      rtcCommitGeometry(geo);
      rtcAttachGeometryByID(s, geo, 0);
      rtcReleaseGeometry(geo);
      rtcSetSceneFlags(s, RTC_SCENE_FLAG_ROBUST);
      rtcCommitScene(s);
      scenes[k] = s;
    }
    f.embree.blas = wallSeconds() - start;
    start = wallSeconds();
    RTCScene top = rtcNewScene(device);
    for (uint32_t k = 0; k < n; ++k) {
      RTCGeometry geo = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_INSTANCE);
      rtcSetGeometryInstancedScene(geo, scenes[k]);
      rtcCommitGeometry(geo);
      rtcAttachGeometryByID(top, geo, k);
      rtcReleaseGeometry(geo);
    }
    rtcSetSceneFlags(top, RTC_SCENE_FLAG_ROBUST);
    rtcCommitScene(top);
    f.embree.tlas = wallSeconds() - start;
    start = wallSeconds();
    if (!o.aabbs) f.embree.hits.resize(pixels);
    if (!o.aabbs)
      forEachPixel(o.width, o.height, [&](RTCIntersectContext& context, uint32_t x, uint32_t y, uint32_t pixel) {
        float org[3], dir[3];
        cameraRay(cam, x, y, org, dir);
        RTCRayHit rh;
        initRay(rh, org, dir);
        rtcIntersect1(top, &context, &rh);
        f.embree.hits[pixel] = rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? 0 : rh.hit.instID[0] + 1;
      });
    f.embree.trace = wallSeconds() - start;
    start = wallSeconds();
    rtcReleaseScene(top);
    for (RTCScene s : scenes) rtcReleaseScene(s);
    std::vector<RTCScene>().swap(scenes);
    f.embree.destroy = wallSeconds() - start;
    meter.finish(f.embree);
  }
  return f;
}

// ---- reporting

std::string cpuModel() {
  std::string model = "unknown";
  if (FILE* f = std::fopen("/proc/cpuinfo", "r")) {
    char line[512];
    while (std::fgets(line, sizeof line, f)) {
      if (std::strncmp(line, "model name", 10) == 0) {
        const char* colon = std::strchr(line, ':');
        if (colon) {
          model = colon + 1 + (colon[1] == ' ');
          while (!model.empty() && (model.back() == '\n' || model.back() == ' ')) model.pop_back();
        }
        break;
      }
    }
    std::fclose(f);
  }
  return model;
}

std::string utcNow() {
  const std::time_t now = std::time(nullptr);
  char buf[64];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  return buf;
}

// A row's scene: the terrain's triangle count, or the model's (with a *, named under the table).
std::string label(const SizeFigures& f) { return std::to_string(f.triangles) + (f.name.empty() ? "" : "*"); }

void printTable(const Options& o, const std::vector<SizeFigures>& all, double submit) {
  std::printf(
      "\nvkrt_tracebench: %u threads, %ux%u pixels, %u bounces, best of runs (real time); an empty vkrt "
      "submit takes %.0f us\n",
      workerThreads(), o.width, o.height, o.bounces, submit * 1e6);
  std::printf("%-10s %-8s %8s %8s %8s %8s %6s %6s %9s %8s\n", "triangles", "rays", "vkrt", "rtcInt1", "rtcInt8",
              "rtcInt16", "/Int1", "/best", "rays/px", "agree");
  for (const SizeFigures& f : all) {
    const TraceFigures* figs[2] = {&f.primary, &f.paths};
    const char* names[2] = {"primary", "paths"};
    for (int k = 0; k < 2; ++k) {
      const TraceFigures& t = *figs[k];
      const double pixels = double(o.width) * o.height;
      std::printf("%-10s %-8s %8.2f %8.2f %8.2f %8.2f %6.2f %6.2f %4.2f/%4.2f %7.2f%%\n", label(f).c_str(), names[k],
                  t.vkrt, t.embree1, t.embree8, t.embree16, t.vkrt / t.embree1, t.vkrt / t.bestPacket(),
                  double(t.rays.vkrtRays) / pixels, double(t.rays.embreeRays) / pixels, 100.0 * t.rays.pixelsAgreeing);
    }
  }
  std::printf(
      "(Mrays/s; /best: vkrt / the faster packet call; rays/px: vkrt/Embree rays per pixel; agree: pixels with the "
      "same rays and hits%s)\n\n",
      o.vkrtOnly ? "; --vkrt-only: no Embree columns" : "");
  std::printf("%-10s %10s %10s %7s %10s %10s %10s %7s\n", "triangles", "BLAS vkrt", "Embree", "ratio", "instances",
              "TLAS vkrt", "Embree", "ratio");
  for (const SizeFigures& f : all)
    std::printf("%-10s %10.2f %10.2f %7.2f %10u %10.2f %10.2f %7.2f\n", label(f).c_str(), f.blasVkrt, f.blasEmbree,
                f.blasVkrt / f.blasEmbree, f.tlasInstances, f.tlasVkrt, f.tlasEmbree, f.tlasVkrt / f.tlasEmbree);
  std::printf("(BLAS Mtriangles/s, TLAS Minstances/s; Embree: rtcCommitScene alone)\n");
  for (const SizeFigures& f : all)
    if (!f.name.empty()) std::printf("*: %s (glTF, all its triangles as one mesh)\n", f.name.c_str());
}

// A JSON number, or null where it is not finite (a ratio with a side that did not run).
std::string jnum(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.4f", v);
  return buf;
}

void writeTrace(FILE* j, const char* name, const TraceFigures& t, bool comma) {
  std::fprintf(j,
               "      \"%s\": {\"vkrt_mrays_per_s\": %s, \"embree1_mrays_per_s\": %s, \"embree8_mrays_per_s\": "
               "%s, \"embree16_mrays_per_s\": %s, \"ratio_vs_embree1\": %s, \"ratio_vs_embree8\": %s, "
               "\"ratio_vs_embree16\": %s, \"ratio_vs_best_packet\": %s, \"vkrt_mrays_per_cpu_s\": %s, "
               "\"embree1_mrays_per_cpu_s\": %s, \"embree8_mrays_per_cpu_s\": %s, \"embree16_mrays_per_cpu_s\": %s, "
               "\"vkrt_rays\": %llu, \"embree_rays\": %llu, \"pixels_agreeing\": %.6f, "
               "\"embree8_agrees_with_embree1\": %s, \"embree16_agrees_with_embree1\": %s}%s\n",
               name, jnum(t.vkrt).c_str(), jnum(t.embree1).c_str(), jnum(t.embree8).c_str(), jnum(t.embree16).c_str(),
               jnum(t.vkrt / t.embree1).c_str(), jnum(t.vkrt / t.embree8).c_str(), jnum(t.vkrt / t.embree16).c_str(),
               jnum(t.vkrt / t.bestPacket()).c_str(), jnum(t.vkrtCpu).c_str(), jnum(t.embree1Cpu).c_str(),
               jnum(t.embree8Cpu).c_str(), jnum(t.embree16Cpu).c_str(), (unsigned long long)t.rays.vkrtRays,
               (unsigned long long)t.rays.embreeRays, t.rays.pixelsAgreeing, t.embree8Agrees ? "true" : "false",
               t.embree16Agrees ? "true" : "false", comma ? "," : "");
}

void writeJson(const Options& o, const std::vector<SizeFigures>& all, double submit) {
  FILE* j = std::fopen(o.json.c_str(), "w");
  if (!j) {
    std::fprintf(stderr, "vkrt_tracebench: cannot write %s\n", o.json.c_str());
    std::exit(1);
  }
  std::string cpu = cpuModel();
  for (char& c : cpu)
    if (c == '"' || c == '\\') c = ' ';
  std::fprintf(j, "{\n  \"program\": \"vkrt_tracebench\",\n  \"date\": \"%s\",\n  \"git_commit\": \"%s\",\n",
               utcNow().c_str(), VKRT_COMMIT);
  std::fprintf(j, "  \"machine\": {\"cpu\": \"%s\", \"hardware_threads\": %u},\n", cpu.c_str(),
               std::thread::hardware_concurrency());
  std::fprintf(j,
               "  \"threads\": %u,\n  \"image\": [%u, %u],\n  \"bounces\": %u,\n  \"min_time_s\": %.3f,\n"
               "  \"empty_submit_us\": %.1f,\n  \"sizes\": [\n",
               workerThreads(), o.width, o.height, o.bounces, o.minTime, submit * 1e6);
  for (size_t i = 0; i < all.size(); ++i) {
    const SizeFigures& f = all[i];
    std::fprintf(j, "    {\"scene\": \"%s\", \"triangles\": %llu, \"grid\": [%u, %u],\n",
                 f.name.empty() ? "terrain" : f.name.c_str(), (unsigned long long)f.triangles, f.cols, f.rows);
    std::fprintf(j,
                 "      \"blas\": {\"vkrt_mtris_per_s\": %s, \"embree_commit_mtris_per_s\": %s, "
                 "\"embree_with_setup_mtris_per_s\": %s, \"ratio\": %s},\n",
                 jnum(f.blasVkrt).c_str(), jnum(f.blasEmbree).c_str(), jnum(f.blasEmbreeWithSetup).c_str(),
                 jnum(f.blasVkrt / f.blasEmbree).c_str());
    std::fprintf(j,
                 "      \"tlas\": {\"instances\": %u, \"vkrt_minst_per_s\": %s, \"embree_commit_minst_per_s\": %s, "
                 "\"embree_with_setup_minst_per_s\": %s, \"ratio\": %s},\n",
                 f.tlasInstances, jnum(f.tlasVkrt).c_str(), jnum(f.tlasEmbree).c_str(),
                 jnum(f.tlasEmbreeWithSetup).c_str(), jnum(f.tlasVkrt / f.tlasEmbree).c_str());
    writeTrace(j, "primary", f.primary, true);
    writeTrace(j, "paths", f.paths, false);
    std::fprintf(j, "    }%s\n", i + 1 < all.size() ? "," : "");
  }
  std::fprintf(j, "  ]\n}\n");
  std::fclose(j);
  std::fprintf(stderr, "wrote %s\n", o.json.c_str());
}

[[noreturn]] void usage() {
  std::fprintf(stderr,
               "usage: vkrt_tracebench [--threads N] [--sizes N,N,...] [--json out.json] [--quick] [--image WxH] "
               "[--min-time S] [--vkrt-only] [--gltf model.glb] [--many-tlas N,N,...] [--many-blas N "
               "[--join-thread] [--aabbs]] [--tlas-builds N,N,...]\n  sizes: even "
               "triangle counts (1e6 style allowed); image sides multiples of 8\n");
  std::exit(2);
}

Options parse(int argc, char** argv) {
  Options o;
  bool sizesGiven = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> const char* {
      if (i + 1 >= argc) usage();
      return argv[++i];
    };
    if (a == "--threads") {
      const long n = std::strtol(value(), nullptr, 10);
      if (n < 1 || n > 256) usage();
      o.threads = unsigned(n);
    } else if (a == "--sizes") {
      o.sizes.clear();
      sizesGiven = true;
      std::string list = value();
      for (size_t p = 0; p <= list.size();) {
        size_t q = list.find(',', p);
        if (q == std::string::npos) q = list.size();
        const double v = std::strtod(list.substr(p, q - p).c_str(), nullptr);
        if (!(v >= 2 && v <= 4e9) || uint64_t(v) % 2) usage();
        o.sizes.push_back(uint64_t(v));
        p = q + 1;
      }
    } else if (a == "--json") {
      o.json = value();
    } else if (a == "--gltf") {
      o.gltf = value();
    } else if (a == "--many-tlas") {
      std::string list = value();
      for (size_t p = 0; p <= list.size();) {
        size_t q = list.find(',', p);
        if (q == std::string::npos) q = list.size();
        const long v = std::strtol(list.substr(p, q - p).c_str(), nullptr, 10);
        if (v < 1 || v > 1000000) usage();
        o.manyTlas.push_back(uint32_t(v));
        p = q + 1;
      }
    } else if (a == "--many-blas") {
      const double v = std::strtod(value(), nullptr);
      if (!(v >= 1 && v <= 1e7)) usage();
      o.manyBlas = uint32_t(v);
    } else if (a == "--tlas-builds") {
      for (const char* p = value();;) {
        char* q = nullptr;
        const double v = std::strtod(p, &q);
        if (q == p || !(v >= 1 && v <= 16777215)) usage();
        o.tlasBuilds.push_back(uint32_t(v));
        if (*q != ',') break;
        p = q + 1;
      }
    } else if (a == "--join-thread") {
      o.joinThread = true;
    } else if (a == "--aabbs") {
      o.aabbs = true;
    } else if (a == "--vkrt-only") {
      o.vkrtOnly = true;
    } else if (a == "--quick") {
      o.quick = true;
    } else if (a == "--image") {
      if (std::sscanf(value(), "%ux%u", &o.width, &o.height) != 2 || !o.width || !o.height || o.width % 8 ||
          o.height % 8)
        usage();
    } else if (a == "--min-time") {
      o.minTime = std::strtod(value(), nullptr);
      if (!(o.minTime >= 0)) usage();
    } else {
      usage();
    }
  }
  // The many-structure modes alone run no terrain scene unless --sizes asks for some.
  if (!sizesGiven && (!o.manyTlas.empty() || o.manyBlas || !o.tlasBuilds.empty())) o.sizes.clear();
  if (o.quick) {
    if (!sizesGiven && o.manyTlas.empty() && !o.manyBlas && o.tlasBuilds.empty()) o.sizes = {10000, 1000000};
    o.minTime = std::min(o.minTime, 0.3);
    o.width = std::min(o.width, 512u);
    o.height = std::min(o.height, 512u);
  }
  return o;
}

}  // namespace
}  // namespace vkrt::bench

int main(int argc, char** argv) {
  using namespace vkrt::bench;
  const Options o = parse(argc, argv);
  setenv("VK_DRIVER_FILES", VKRT_BENCH_ICD_JSON, 0);  // unless set already
  // vkrt reads VKRT_THREADS when its thread pool and Embree device start (at the first device); so does
  // workerThreads() for the Embree side.
  if (o.threads) setenv("VKRT_THREADS", std::to_string(o.threads).c_str(), 1);
  if (!ctx().rayTracingPipeline) {
    std::fprintf(stderr, "vkrt_tracebench: the driver has no VK_KHR_ray_tracing_pipeline\n");
    return 1;
  }
  // Raw Embree's device builds on as many threads as vkrt's (src/accel/embree_device.cpp).
  const std::string config = "verbose=0,threads=" + std::to_string(workerThreads());
  RTCDevice device = rtcNewDevice(config.c_str());
  const double submit = emptySubmitSeconds();
  std::vector<SizeFigures> all;
  for (uint64_t n : o.sizes) all.push_back(runScene(o, device, makeTerrain(n)));
  if (!o.gltf.empty()) all.push_back(runScene(o, device, loadModel(o.gltf)));
  if (!all.empty()) printTable(o, all, submit);
  if (!o.manyTlas.empty()) {
    const std::vector<ManyTlasFigures> m = runManyTlas(o, device);
    std::printf(
        "\nvkrt_tracebench --many-tlas: %u threads, %ux%u primary rays of a %llu-triangle terrain, each "
        "through one of N top levels chosen per pixel by address\n",
        workerThreads(), o.width, o.height, (unsigned long long)o.manyTlasTriangles);
    std::printf("%-8s %10s %8s %12s %8s %8s | %10s %8s %12s %8s\n", "N", "Mrays/s", "/N=1", "Mrays/cpu-s", "/N=1",
                "agree", "Embree", "/N=1", "Embree/cpu-s", "/N=1");
    for (const ManyTlasFigures& f : m)
      std::printf("%-8u %10.2f %8.2f %12.2f %8.2f %7.2f%% | %10.2f %8.2f %12.2f %8.2f\n", f.levels, f.vkrt,
                  f.vkrt / m[0].vkrt, f.vkrtCpu, f.vkrtCpu / m[0].vkrtCpu, 100.0 * f.agreeing, f.embree,
                  f.embree / m[0].embree, f.embreeCpu, f.embreeCpu / m[0].embreeCpu);
  }
  if (o.manyBlas) {
    const ManyBlasFigures f = runManyBlas(o, device);
    std::printf(
        "\nvkrt_tracebench --many-blas: %u threads, %u one-%s bottom levels, a top level of %u instances, "
        "%ux%u primary rays, destruction (seconds; MB over the side's start)\n",
        workerThreads(), f.count, o.aabbs ? "box" : "triangle", f.count, o.width, o.height);
    std::printf("%-28s %8s %8s %8s %8s %8s | %9s %8s %8s %7s %8s\n", "", "BLASes", "TLAS", "trace", "destroy", "total",
                "peak RSS", "B/struct", "kept", "heap", "agree");
    const ManyBlasSide* ref = f.embree.ran ? &f.embree : &f.device;
    auto row = [&](const char* name, const ManyBlasSide& s) {
      if (!s.ran) return;
      size_t hit = 0, same = 0;
      for (size_t i = 0; i < s.hits.size(); ++i) hit += s.hits[i] != 0, same += s.hits[i] == ref->hits[i];
      std::printf("%-28s %8.3f %8.3f %8.3f %8.3f %8.3f | %9.1f %8.0f %8.1f %7.1f", name, s.blas, s.tlas, s.trace,
                  s.destroy, s.total(), s.peakMB, s.peakMB * (1 << 20) / f.count, s.keptMB, s.heapKeptMB);
      if (s.hits.empty())
        std::printf("        -  (not traced)\n");
      else
        std::printf(" %7.2f%%  (%zu pixels hit)\n", 100.0 * double(same) / double(s.hits.size()), hit);
    };
    row(o.joinThread ? "vkrt host (deferred, thread)" : "vkrt host (deferred, joined)", f.host);
    row("vkrt recorded (one command)", f.device);
    row("Embree (scenes, instances)", f.embree);
  }
  if (!o.tlasBuilds.empty()) {
    std::printf("\nvkrt_tracebench --tlas-builds: %u threads, top levels of N instances of a 128-triangle terrain\n",
                workerThreads());
    std::printf("%-10s %10s %10s %7s %14s\n", "instances", "TLAS vkrt", "Embree", "ratio", "Embree+setup");
    for (uint32_t n : o.tlasBuilds) {
      const TlasBuildFigures f = tlasBuildFigures(o, device, n);
      std::printf("%-10u %10.2f %10.2f %7.2f %14.2f\n", n, f.vkrt, f.embree, f.vkrt / f.embree, f.embreeWithSetup);
    }
    std::printf(
        "(Minstances/s, best runs; Embree: rtcCommitScene of its instance scene alone; +setup: with making "
        "its instance geometries)\n");
  }
  if (!o.json.empty() && !all.empty()) writeJson(o, all, submit);
  rtcReleaseDevice(device);
  return 0;
}
