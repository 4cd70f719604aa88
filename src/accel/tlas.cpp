// Top-level structures: the instances, their transforms and inverses, vkrt's hierarchy over them (no Embree object
// per instance), and an Embree scene of the flattened small bottom levels' triangles.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <mutex>
#include <type_traits>
#include <vector>

#include "accel/embree_device.hpp"
#include "accel/structures.hpp"

namespace vkrt::accel {

namespace detail {

bool invertAffine(const float m[3][4], float out[3][4]) {
  // In double: the inverse is computed once per instance, and the shaders' WorldToObject should be as exact as
  // float storage allows.
  const double a = m[0][0], b = m[0][1], c = m[0][2];
  const double d = m[1][0], e = m[1][1], f = m[1][2];
  const double g = m[2][0], h = m[2][1], k = m[2][2];
  const double c00 = e * k - f * h, c01 = c * h - b * k, c02 = b * f - c * e;
  const double c10 = f * g - d * k, c11 = a * k - c * g, c12 = c * d - a * f;
  const double c20 = d * h - e * g, c21 = b * g - a * h, c22 = a * e - b * d;
  const double det = a * c00 + b * c10 + c * c20;
  if (det == 0 || !std::isfinite(det)) return false;
  const double inv[3][3] = {
      {c00 / det, c01 / det, c02 / det}, {c10 / det, c11 / det, c12 / det}, {c20 / det, c21 / det, c22 / det}};
  for (int r = 0; r < 3; ++r) {
    double t = 0;
    for (int j = 0; j < 3; ++j) {
      out[r][j] = float(inv[r][j]);
      t -= inv[r][j] * m[j][3];
    }
    out[r][3] = float(t);
    for (int j = 0; j < 4; ++j)
      if (!std::isfinite(out[r][j])) return false;
  }
  return true;
}

namespace {

// Whether Embree 3's own inverse of the instance's linear part (in float: adjoint over determinant) is usable: false
// when it is not finite or the determinant is not a normal float (Embree flushes denormals to zero: its inverse
// would be infinite and every ray through the instance NaN).
bool embreeInvertible(const float m[3][4]) {
  // Embree's columns (vx, vy, vz) are the rows' components by column.
  const float vx[3] = {m[0][0], m[1][0], m[2][0]}, vy[3] = {m[0][1], m[1][1], m[2][1]};
  const float vz[3] = {m[0][2], m[1][2], m[2][2]};
  auto cross = [](const float a[3], const float b[3], float out[3]) {
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
  };
  float cyz[3], czx[3], cxy[3];
  cross(vy, vz, cyz);
  cross(vz, vx, czx);
  cross(vx, vy, cxy);
  const float det = vx[0] * cyz[0] + vx[1] * cyz[1] + vx[2] * cyz[2];
  if (!std::isnormal(det)) return false;
  // Rows of the inverse: cross(vy, vz), cross(vz, vx), cross(vx, vy), each over the determinant.
  const float* rows[3] = {cyz, czx, cxy};
  for (const float* row : rows) {
    float inv[3] = {row[0] / det, row[1] / det, row[2] / det};
    float t = -(inv[0] * m[0][3] + inv[1] * m[1][3] + inv[2] * m[2][3]);
    if (!std::isfinite(inv[0]) || !std::isfinite(inv[1]) || !std::isfinite(inv[2]) || !std::isfinite(t)) return false;
  }
  return true;
}

// The distinct values a build's chunks collect (Blases, their scenes to make): each chunk keeps one of each run of
// equal values in `used` (runs are the usual case), adds them to `all` under `m` made distinct, and sortDistinct
// finishes `all` after the chunks.
template <class T>
void sortDistinct(std::vector<T>& v) {
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
}
template <class T>
void mergeDistinct(std::vector<T>& used, std::vector<T>& all, std::mutex& m) {
  if (used.empty()) return;
  sortDistinct(used);
  std::lock_guard lock(m);
  all.insert(all.end(), used.begin(), used.end());
}

// Fills the per-instance records and the Tlas summary. An instance is inactive (never hit, index kept) when its
// Blas is null (Vulkan: reference 0) or its transform has no inverse (Vulkan requires an invertible one; a
// zero scale is sometimes used to hide an instance, and hiding it is what such an instance gets), in double or in
// the float arithmetic Embree inverts it with.
// The distinct Blases are collected too, and the Tlas takes shared ownership of each once (impl.blases). Fails when
// an instance's Blas is not owned by a shared_ptr (Instance::blas's precondition).
bool makeRecords(Tlas::Impl& impl, std::string* error) {
  const size_t n = impl.instances.size();
  impl.records.resize(n, impl.inlineRecords);
  // In chunks on the build threads (an inverse in double per instance); each chunk's summary and Blases are merged
  // after it.
  std::mutex merge;
  std::vector<const Blas*> distinct;
  parallelChunks(n, 8192, 16384, [&](size_t begin, size_t end) {
    TlasSummary s;
    std::vector<const Blas*> used;  // each run of instances of one Blas adds it once (runs are the usual case)
    for (size_t i = begin; i < end; ++i) {
      const Instance& in = impl.instances[i];
      if (in.blas && (used.empty() || used.back() != in.blas)) used.push_back(in.blas);
      InstanceRecord& r = *::new (static_cast<void*>(&impl.records[i])) InstanceRecord;
      for (int row = 0; row < 3; ++row)
        for (int col = 0; col < 4; ++col) r.objectToWorld[row][col] = in.transform[row][col];
      r.customIndex = in.customIndex & 0xFFFFFF;
      r.mask = in.mask & 0xFF;
      r.sbtOffset = in.sbtOffset & 0xFFFFFF;
      r.flags = in.flags;
      if (!in.blas || !invertAffine(r.objectToWorld, r.worldToObject) || !embreeInvertible(r.objectToWorld)) {
        for (auto& row : r.worldToObject)
          for (float& v : row) v = 0;
        continue;
      }
      r.blas = in.blas->impl.get();
      const BlasSummary& b = r.blas->summary;
      if ((in.mask & 0xFF) == 0) continue;  // no ray sees it
      s.small |= r.blas->small && r.blas->primitives;
      s.aabbs |= b.aabbs;
      if (!b.triangles) continue;
      s.triangles = true;
      s.facingCullable |= !(in.flags & kInstanceTriangleFacingCullDisable);
      // Opacity after the instance's force flags (the ray's come per ray).
      const bool forcedOpaque = in.flags & kInstanceForceOpaque;
      const bool forcedNoOpaque = !forcedOpaque && (in.flags & kInstanceForceNoOpaque);
      s.opaqueTriangles |= forcedOpaque || (!forcedNoOpaque && b.opaqueTriangles);
      s.noOpaqueTriangles |= forcedNoOpaque || (!forcedOpaque && b.noOpaqueTriangles);
    }
    mergeDistinct(used, distinct, merge);
    std::lock_guard lock(merge);
    TlasSummary& all = impl.summary;
    all.triangles |= s.triangles;
    all.aabbs |= s.aabbs;
    all.opaqueTriangles |= s.opaqueTriangles;
    all.noOpaqueTriangles |= s.noOpaqueTriangles;
    all.facingCullable |= s.facingCullable;
    all.small |= s.small;
  });
  sortDistinct(distinct);
  impl.blases.reserve(distinct.size());
  for (const Blas* b : distinct) {
    std::shared_ptr<const Blas> owner = b->weak_from_this().lock();
    if (!owner) {
      if (error) *error = "Tlas build: an instance's Blas is not owned by a shared_ptr";
      return false;
    }
    impl.blases.push_back(std::move(owner));
  }
  return true;
}

// Whether an instance's world bounds, as Embree computes them (its Blas's bounds, each corner transformed in float
// with denormals flushed: x * vx + (y * vy + (z * vz + p))), have extent (structures.hpp, hasExtent). A Blas far
// smaller than the float resolution at its instance's position has none: a translation absorbs it.
bool worldBoundsHaveExtent(const RTCBounds& b, const float m[3][4]) {
  constexpr float kInf = std::numeric_limits<float>::infinity();
  float lower[3] = {kInf, kInf, kInf}, upper[3] = {-kInf, -kInf, -kInf};
  for (int corner = 0; corner < 8; ++corner) {
    const float p[3] = {flushDenormal(corner & 1 ? b.upper_x : b.lower_x),
                        flushDenormal(corner & 2 ? b.upper_y : b.lower_y),
                        flushDenormal(corner & 4 ? b.upper_z : b.lower_z)};
    for (int row = 0; row < 3; ++row) {
      auto f = [](float v) { return flushDenormal(v); };
      const float z = f(f(p[2] * m[row][2]) + f(m[row][3]));
      const float y = f(f(p[1] * m[row][1]) + z);
      const float w = f(f(p[0] * m[row][0]) + y);
      lower[row] = std::min(lower[row], w);
      upper[row] = std::max(upper[row], w);
    }
  }
  return hasExtent(lower, upper);
}

// Flattening: the triangles of a small bottom level (kSmallBlasPrimitives) go into the top level's own scene in
// world space, one triangle geometry per instance mask, instead of an Embree instance of a scene of their own: no
// per-structure Embree object at all, which is what builds of thousands of one-triangle structures paid for. Each
// vertex is transformed once per instance (a vertex shared within an instance stays bit-identical, so Embree's
// watertight test closes the instance's edges as it does in object space). Traversal maps a flattened hit back to
// its instance, geometry and primitive (hitIds) and computes facing from the object-space triangle, as for an
// instanced one. Bounded: at most kFlatTriangles triangles a top level; past them, instances get scenes.
constexpr uint64_t kFlatTriangles = uint64_t(1) << 20;

// Whether `blas` is flattened (small, triangles only).
bool flattenable(const Blas::Impl& blas) { return blas.small && !blas.summary.aabbs; }

// One mask's flattened triangles: world-space vertices (three per triangle) and what each triangle is.
struct FlatGroup {
  std::vector<float> vertices;
  std::vector<FlatTriangle> triangles;
};

// Appends the active triangles of instance `i` (a flattenable Blas) to `group`. A triangle with a vertex that is not
// finite (inactive, or one Embree would leave out) or an index out of range, or that has no extent in world space
// (structures.hpp, hasExtent), is left out: never hit.
void flattenInstance(const InstanceRecord& r, uint32_t i, FlatGroup& group) {
  const float(*m)[4] = r.objectToWorld;
  for (uint32_t g = 0; g < r.blas->info.size(); ++g) {
    const GeometryInfo& geom = r.blas->info[g];
    if (geom.kind != Geometry::Triangles || !geom.vertices) continue;
    for (uint32_t p = 0; p < geom.primitiveCount; ++p) {
      float w[3][3];
      bool usable = true;
      for (int k = 0; k < 3 && usable; ++k) {
        const uint32_t index = geom.indices[3 * size_t(p) + k];
        if (index >= geom.vertexCount) {
          usable = false;
          break;
        }
        const float* v = geom.vertices + 3 * size_t(index);
        for (int row = 0; row < 3; ++row) {
          w[k][row] = m[row][0] * v[0] + m[row][1] * v[1] + m[row][2] * v[2] + m[row][3];
          usable &= std::isfinite(w[k][row]) && std::isfinite(v[row]);
        }
      }
      if (!usable) continue;
      float lower[3], upper[3];
      for (int c = 0; c < 3; ++c) {
        lower[c] = std::min({w[0][c], w[1][c], w[2][c]});
        upper[c] = std::max({w[0][c], w[1][c], w[2][c]});
      }
      if (!hasExtent(lower, upper)) continue;
      group.vertices.insert(group.vertices.end(), &w[0][0], &w[0][0] + 9);
      group.triangles.push_back({i, g, p});
    }
  }
}

// Which instances are flattened (in index order, up to kFlatTriangles), and the Embree scene of their triangles:
// one triangle geometry per instance mask, geometry IDs in order of mask (flat[] is indexed by them). Sets
// `flat[i]` for each flattened instance; impl.flatScene stays null when there is none.
bool buildFlatScene(RTCDevice device, Tlas::Impl& impl, std::vector<uint8_t>& flat, std::string* error) {
  const size_t n = impl.instances.size();
  flat.assign(n, 0);
  if (!impl.summary.small) return true;  // (no instance to flatten: the scan over the records is skipped)
  FlatGroup groups[256];
  uint64_t flatTriangles = 0;
  for (size_t i = 0; i < n; ++i) {
    const InstanceRecord& r = impl.records[i];
    if (!r.blas || !r.blas->primitives || !r.mask || !flattenable(*r.blas)) continue;
    if (flatTriangles + r.blas->primitives > kFlatTriangles) break;
    flatTriangles += r.blas->primitives;
    flat[i] = 1;
    flattenInstance(r, uint32_t(i), groups[r.mask]);
  }
  if (!flatTriangles) return true;
  EmbreeErrors errors;
  const SceneSettings settings = sceneSettings(impl.options, false);
  RTCScene scene = rtcNewScene(device);
  if (!scene) return !errors.failed("Tlas build", error);
  rtcSetSceneFlags(scene, RTCSceneFlags(settings.sceneFlags & ~RTC_SCENE_FLAG_COMPACT));
  rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_MEDIUM);
  bool outOfMemory = false;
  for (unsigned mask = 1; mask < 256; ++mask) {
    FlatGroup& g = groups[mask];
    if (g.triangles.empty()) continue;
    RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* v = geometry ? static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0,
                                                                     RTC_FORMAT_FLOAT3, 12, g.triangles.size() * 3))
                       : nullptr;
    auto* ix = geometry ? static_cast<uint32_t*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0,
                                                                         RTC_FORMAT_UINT3, 12, g.triangles.size()))
                        : nullptr;
    if (!v || !ix) {
      if (geometry) rtcReleaseGeometry(geometry);
      outOfMemory = true;
      break;
    }
    std::memcpy(v, g.vertices.data(), g.vertices.size() * sizeof(float));
    for (uint32_t k = 0; k < 3 * g.triangles.size(); ++k) ix[k] = k;
    rtcSetGeometryMask(geometry, mask << kFlatMaskShift);
    // MEDIUM: each triangle in exactly one leaf (no spatial splits: VK_GEOMETRY_NO_DUPLICATE_ANY_HIT_INVOCATION_BIT).
    rtcSetGeometryBuildQuality(geometry, RTC_BUILD_QUALITY_MEDIUM);
    rtcCommitGeometry(geometry);
    rtcAttachGeometryByID(scene, geometry, unsigned(impl.flat.size()));
    rtcReleaseGeometry(geometry);
    impl.flat.push_back(std::move(g.triangles));  // flat[] is indexed by geometry ID: masks without triangles take none
  }
  if (!outOfMemory) rtcCommitScene(scene);
  if (outOfMemory || errors.failed("Tlas build", error)) {
    if (error && outOfMemory) *error = "Tlas build: Embree could not create a geometry (out of memory)";
    rtcReleaseScene(scene);
    return false;
  }
  impl.flatScene = scene;
  return true;
}

// The magnitude the hierarchy's builder sees at most (areas and sums of such bounds stay finite in float).
constexpr float kBuildLimit = 1e18f;
// A node box's coordinate as traversal tests it: one at the limit stands for one beyond it (an infinite side).
void widenAtLimit(float lower[3], float upper[3]) {
  for (int k = 0; k < 3; ++k) {
    if (lower[k] <= -kBuildLimit) lower[k] = -HUGE_VALF;
    if (upper[k] >= kBuildLimit) upper[k] = HUGE_VALF;
  }
}

// An instance's world bounds for the hierarchy: its Blas's bounds, each corner transformed in double, rounded
// outward to float (traversal's box test is then conservative for every ray that can meet the instance). Returns
// whether they surely have extent as Embree computes it too (an extent far above float rounding of the terms of
// the transform); where that is unsure, the caller asks worldBoundsHaveExtent, which follows Embree's arithmetic.
bool worldBounds(const RTCBounds& b, const float m[3][4], RTCBuildPrimitive& out) {
  double lower[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, upper[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL}, terms[3] = {};
  for (int corner = 0; corner < 8; ++corner) {
    const double p[3] = {corner & 1 ? b.upper_x : b.lower_x, corner & 2 ? b.upper_y : b.lower_y,
                         corner & 4 ? b.upper_z : b.lower_z};
    for (int row = 0; row < 3; ++row) {
      const double x = m[row][0] * p[0], y = m[row][1] * p[1], z = m[row][2] * p[2], t = m[row][3];
      const double w = x + y + z + t;
      lower[row] = std::min(lower[row], w);
      upper[row] = std::max(upper[row], w);
      terms[row] = std::max(terms[row], std::fabs(x) + std::fabs(y) + std::fabs(z) + std::fabs(t));
    }
  }
  // A margin of a millionth of the magnitudes (far beyond the half float ulp of the conversion, and beyond Embree's
  // float transform of the ray, which may put its hits a few ulps from the exact ones), plus a tiny absolute one.
  bool extent = false;
  float lo[3], hi[3];
  for (int k = 0; k < 3; ++k) {
    const double margin = 1e-6 * std::max({std::fabs(lower[k]), std::fabs(upper[k]), upper[k] - lower[k]}) + 1e-36;
    lo[k] = float(lower[k] - margin);
    hi[k] = float(upper[k] + margin);
    extent |= upper[k] - lower[k] > 1e-4 * terms[k] && upper[k] - lower[k] > 1e-30;
  }
  // Embree's binning divides by the bounds' diagonal and sums centroids in float: bounds past kBuildLimit (or not
  // finite) trip its assertions (found by vkrt_fuzz_accel_build). The builder sees them clamped; the node boxes
  // that reach the limit are then made unbounded on that side (widenAtLimit), so the box test stays conservative.
  for (int k = 0; k < 3; ++k) {
    lo[k] = lo[k] > -kBuildLimit ? std::min(lo[k], kBuildLimit) : -kBuildLimit;  // NaN: the limit
    hi[k] = hi[k] < kBuildLimit ? std::max(hi[k], -kBuildLimit) : kBuildLimit;
  }
  out.lower_x = lo[0], out.lower_y = lo[1], out.lower_z = lo[2];
  out.upper_x = hi[0], out.upper_y = hi[1], out.upper_z = hi[2];
  return extent;
}

// rtcBuildBVH's nodes (allocated in the RTCBVH, freed with it once copied into Tlas::Impl::nodes).
struct BuildNode {
  bool leaf;
  RTCBounds bounds[2];
  void* children[2];
};
struct BuildLeaf {
  bool leaf;
  uint32_t count;
  uint32_t items[kMaxLeafItems];
};

// What the builder's callbacks share: whether a leaf was given more instances than it holds, and, under
// ThreadSanitizer, a counter each callback increments (release) after its writes and that the copy reads (acquire)
// before reading the tree, so that the sanitizer sees the writes of Embree's threads ordered before the copy (it does
// not see TBB's own synchronization).
struct BuildContext {
  std::atomic<bool> overfull{false};
  std::atomic<uint32_t> published{0};
  void publish() {
    if constexpr (kUnderThreadSanitizer) published.fetch_add(1, std::memory_order_release);
  }
  void acquire() const {
    if constexpr (kUnderThreadSanitizer) (void)published.load(std::memory_order_acquire);
  }
};

void* createNode(RTCThreadLocalAllocator alloc, unsigned, void* userPtr) {
  auto* node = static_cast<BuildNode*>(rtcThreadLocalAlloc(alloc, sizeof(BuildNode), 16));
  *node = BuildNode{false, {}, {nullptr, nullptr}};
  static_cast<BuildContext*>(userPtr)->publish();
  return node;
}
void setNodeChildren(void* node, void** children, unsigned count, void* userPtr) {
  for (unsigned k = 0; k < count && k < 2; ++k) static_cast<BuildNode*>(node)->children[k] = children[k];
  static_cast<BuildContext*>(userPtr)->publish();
}
void setNodeBounds(void* node, const RTCBounds** bounds, unsigned count, void* userPtr) {
  for (unsigned k = 0; k < count && k < 2; ++k) static_cast<BuildNode*>(node)->bounds[k] = *bounds[k];
  static_cast<BuildContext*>(userPtr)->publish();
}
void* createLeaf(RTCThreadLocalAllocator alloc, const RTCBuildPrimitive* prims, size_t count, void* userPtr) {
  auto* context = static_cast<BuildContext*>(userPtr);
  auto* leaf = static_cast<BuildLeaf*>(rtcThreadLocalAlloc(alloc, sizeof(BuildLeaf), 16));
  leaf->leaf = true;
  leaf->count = uint32_t(std::min<size_t>(count, kMaxLeafItems));
  if (count > kMaxLeafItems) context->overfull.store(true);  // (the builder keeps the bound)
  for (uint32_t k = 0; k < leaf->count; ++k) leaf->items[k] = prims[k].primID;
  context->publish();
  return leaf;
}

// The builder's tree is copied into impl.nodes / impl.leafItems depth first (a node before its children, the first
// child's subtree before the second's; leaf items in the order their leaves are met). The copy is parallel: the
// subtrees at kSplitDepth are counted on the build threads, the levels above them placed on this thread (each
// subtree's first node and item known from the counts before it), then the subtrees copied on the build threads
// into their places, so the arrays are the same as a serial copy's.
constexpr int kSplitDepth = 8;  // up to 256 subtrees

struct TreeCounts {
  uint32_t nodes = 0, items = 0;
};

const BuildLeaf* asLeaf(const void* p) {
  return static_cast<const BuildLeaf*>(p)->leaf ? static_cast<const BuildLeaf*>(p) : nullptr;
}

uint32_t leafRef(const BuildLeaf& leaf, uint32_t first) {
  return kLeafRef | (leaf.count == 1 ? leaf.items[0] : first) << 3 | (leaf.count - 1);
}

TreeCounts countTree(const void* p) {
  if (const BuildLeaf* leaf = asLeaf(p)) return {0, leaf->count};
  const auto* node = static_cast<const BuildNode*>(p);
  const TreeCounts a = countTree(node->children[0]), b = countTree(node->children[1]);
  return {1 + a.nodes + b.nodes, a.items + b.items};
}

void writeNodeBounds(const BuildNode& node, int k, uint32_t child, BvhNode& out) {
  const RTCBounds& b = node.bounds[k];
  float lower[3] = {b.lower_x, b.lower_y, b.lower_z}, upper[3] = {b.upper_x, b.upper_y, b.upper_z};
  widenAtLimit(lower, upper);
  std::memcpy(out.lower[k], lower, sizeof lower);
  std::memcpy(out.upper[k], upper, sizeof upper);
  out.child[k] = child;
}

// Writes the tree below `p` from `next` on (advanced past it); returns its reference.
uint32_t writeTree(const void* p, Tlas::Impl& impl, TreeCounts& next) {
  if (const BuildLeaf* leaf = asLeaf(p)) {
    const uint32_t first = next.items;
    std::memcpy(impl.leafItems.data() + first, leaf->items, leaf->count * sizeof(uint32_t));
    next.items += leaf->count;
    return leafRef(*leaf, first);
  }
  const auto* node = static_cast<const BuildNode*>(p);
  const uint32_t index = next.nodes++;
  for (int k = 0; k < 2; ++k) {
    const uint32_t child = writeTree(node->children[k], impl, next);
    writeNodeBounds(*node, k, child, impl.nodes[index]);
  }
  return index;
}

// The subtrees at kSplitDepth (or leaves above it), left to right.
void collectSubtrees(const void* p, int depth, std::vector<const void*>& out) {
  if (asLeaf(p) || depth == kSplitDepth) {
    out.push_back(p);
    return;
  }
  const auto* node = static_cast<const BuildNode*>(p);
  for (int k = 0; k < 2; ++k) collectSubtrees(node->children[k], depth + 1, out);
}

// The levels above the subtrees: nodes written, each subtree given its start (`starts`, in collectSubtrees' order).
uint32_t placeTop(const void* p, int depth, Tlas::Impl& impl, const std::vector<TreeCounts>& counts,
                  std::vector<TreeCounts>& starts, size_t& subtree, TreeCounts& next) {
  if (asLeaf(p) || depth == kSplitDepth) {
    const TreeCounts start = next, c = counts[subtree];
    starts[subtree++] = start;
    next.nodes += c.nodes;
    next.items += c.items;
    if (const BuildLeaf* leaf = asLeaf(p)) return leafRef(*leaf, start.items);
    return start.nodes;
  }
  const auto* node = static_cast<const BuildNode*>(p);
  const uint32_t index = next.nodes++;
  for (int k = 0; k < 2; ++k) {
    const uint32_t child = placeTop(node->children[k], depth + 1, impl, counts, starts, subtree, next);
    writeNodeBounds(*node, k, child, impl.nodes[index]);
  }
  return index;
}

uint32_t copyTree(const void* root, Tlas::Impl& impl) {
  std::vector<const void*> subtrees;
  collectSubtrees(root, 0, subtrees);
  std::vector<TreeCounts> counts(subtrees.size()), starts(subtrees.size());
  parallelChunks(subtrees.size(), 1, 2, [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) counts[i] = countTree(subtrees[i]);
  });
  TreeCounts total;
  for (const TreeCounts& c : counts) total.nodes += c.nodes, total.items += c.items;
  const uint32_t top = uint32_t(subtrees.size() - 1);  // the nodes above the subtrees of a binary tree
  impl.nodes.resize(size_t(total.nodes) + top);
  impl.leafItems.resize(total.items);
  size_t subtree = 0;
  TreeCounts next;
  const uint32_t ref = placeTop(root, 0, impl, counts, starts, subtree, next);
  parallelChunks(subtrees.size(), 1, 2, [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      TreeCounts at = starts[i];
      writeTree(subtrees[i], impl, at);
    }
  });
  return ref;
}

// The instance level over `prims` (one per instance in the hierarchy, primID = instance index; reordered by the
// builder). SAH (binned, MEDIUM) or Morton (LOW, PREFER_FAST_BUILD) on Embree's build threads.
bool buildHierarchy(RTCDevice device, Tlas::Impl& impl, FillArray<RTCBuildPrimitive>& prims, std::string* error) {
  impl.nodes.clear();
  impl.leafItems.clear();
  impl.root = kEmptyRef;
  if (prims.empty()) return true;
  EmbreeErrors errors;
  RTCBVH bvh = rtcNewBVH(device);
  if (!bvh) return !errors.failed("Tlas build", error);
  BuildContext context;
  RTCBuildArguments args = rtcDefaultBuildArguments();
  args.buildQuality = impl.options.preferFastBuild ? RTC_BUILD_QUALITY_LOW : RTC_BUILD_QUALITY_MEDIUM;
  args.maxBranchingFactor = 2;
  args.maxDepth = 48;
  args.minLeafSize = 1;
  args.maxLeafSize = kMaxLeafItems;
  // Entering an instance (a transform and an Embree query of its Blas) costs far more than a box test.
  args.traversalCost = 1.0f;
  args.intersectionCost = 8.0f;
  args.bvh = bvh;
  args.primitives = prims.data();
  args.primitiveCount = prims.size();
  args.primitiveArrayCapacity = prims.size();
  args.createNode = createNode;
  args.setNodeChildren = setNodeChildren;
  args.setNodeBounds = setNodeBounds;
  args.createLeaf = createLeaf;
  args.userPtr = &context;
  void* root = rtcBuildBVH(&args);
  context.acquire();
  bool ok = root && !context.overfull.load() && !errors.failed("Tlas build", error);
  if (ok) {
    impl.root = copyTree(root, impl);
  } else if (error && error->empty()) {
    *error = "Tlas build: Embree could not build the instance hierarchy";
  }
  rtcReleaseBVH(bvh);
  return ok;
}

// The bounds of a child reference of the hierarchy, from the instances' bounds (`bounds`, indexed by instance) and
// the nodes below it (already refit).
void refBounds(const Tlas::Impl& impl, const FillArray<RTCBuildPrimitive>& bounds, uint32_t ref, float lower[3],
               float upper[3]) {
  for (int k = 0; k < 3; ++k) lower[k] = HUGE_VALF, upper[k] = -HUGE_VALF;
  auto unite = [&](const float* lo, const float* hi) {
    for (int k = 0; k < 3; ++k) lower[k] = std::min(lower[k], lo[k]), upper[k] = std::max(upper[k], hi[k]);
  };
  if (ref & kLeafRef) {
    uint32_t count, one;
    const uint32_t* items = leafInstances(impl.leafItems, ref, &count, &one);
    for (uint32_t k = 0; k < count; ++k) {
      const RTCBuildPrimitive& b = bounds[items[k]];
      const float lo[3] = {b.lower_x, b.lower_y, b.lower_z}, hi[3] = {b.upper_x, b.upper_y, b.upper_z};
      unite(lo, hi);
    }
    widenAtLimit(lower, upper);
    return;
  }
  const BvhNode& node = impl.nodes[ref];
  for (int k = 0; k < 2; ++k) unite(node.lower[k], node.upper[k]);
}

// An update's refit: `source`'s hierarchy with the instances' new bounds, when the same instances are in it (every
// instance in its leaves still in the hierarchy, and no other). False otherwise (the caller builds).
bool refitHierarchy(const Tlas::Impl& source, Tlas::Impl& impl, const std::vector<uint8_t>& inHierarchy, size_t count,
                    const FillArray<RTCBuildPrimitive>& bounds) {
  if (source.leafItems.size() != count || source.instances.size() != impl.instances.size()) return false;
  for (uint32_t i : source.leafItems)
    if (!inHierarchy[i]) return false;
  impl.nodes = source.nodes;
  impl.leafItems = source.leafItems;
  impl.root = source.root;
  for (size_t n = impl.nodes.size(); n-- > 0;) {  // children after their parent: bottom up
    BvhNode& node = impl.nodes[n];
    for (int k = 0; k < 2; ++k) refBounds(impl, bounds, node.child[k], node.lower[k], node.upper[k]);
  }
  return true;
}

// The instance level: the flattened triangles' scene, then the hierarchy over the other active instances (built,
// or refit from `source`, the Tlas an update starts from).
bool buildLevels(Tlas::Impl& impl, const Tlas::Impl* source, std::string* error) {
  RTCDevice device = detail::device(error);
  if (!device) return false;
  const size_t n = impl.instances.size();
  std::vector<uint8_t> flat;
  if (!buildFlatScene(device, impl, flat, error)) return false;
  // The scenes of the small structures instanced here (not flattened, not direct) are made first, on this thread:
  // made inside the parallel loop below, a thread waiting for one Embree commit could run another chunk of the loop
  // that needs the same scene, re-entering its std::call_once.
  // (Which ones is found in chunks: each distinct one, then their scenes made one after the other.)
  if (impl.summary.small) {
    std::mutex merge;
    std::vector<const Blas::Impl*> small;
    parallelChunks(n, 8192, 16384, [&](size_t begin, size_t end) {
      std::vector<const Blas::Impl*> used;
      for (size_t i = begin; i < end; ++i) {
        const InstanceRecord& r = impl.records[i];
        if (!flat[i] && r.blas && r.blas->small && !r.blas->direct && r.blas->primitives && r.mask &&
            (used.empty() || used.back() != r.blas))
          used.push_back(r.blas);
      }
      mergeDistinct(used, small, merge);
    });
    sortDistinct(small);
    for (const Blas::Impl* b : small) b->sceneFor();
  }
  // Per instance: its scene and world bounds (in parallel: a transform of 8 corners each).
  FillArray<RTCBuildPrimitive> bounds(n);  // set for the instances in the hierarchy, the only ones read
  std::vector<uint8_t> inHierarchy(n, 0);
  std::atomic<bool> outOfMemory{false};
  parallelChunks(n, 4096, 16384, [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      InstanceRecord& r = impl.records[i];
      if (flat[i] || !r.blas || !r.blas->primitives || !r.mask) continue;  // never hit (or flattened); the index stays
      RTCScene inner = nullptr;  // (a direct Blas has none: traversal offers its boxes)
      RTCBounds b;
      if (r.blas->direct) {
        if (!r.blas->directCount) continue;  // no box Embree would keep: never hit
        b = r.blas->directBounds;
      } else {
        inner = r.blas->sceneFor();
        if (!inner) {
          outOfMemory.store(true, std::memory_order_relaxed);
          continue;
        }
        rtcGetSceneBounds(inner, &b);
      }
      // An instance without extent in world space (as Embree transforms it) is left out: never hit.
      if (!worldBounds(b, r.objectToWorld, bounds[i]) && !worldBoundsHaveExtent(b, r.objectToWorld)) continue;
      r.scene = inner;
      bounds[i].geomID = 0;
      bounds[i].primID = unsigned(i);
      inHierarchy[i] = 1;
    }
  });
  if (outOfMemory.load()) {
    if (error) *error = "Tlas build: Embree could not build a bottom level's scene (out of memory)";
    return false;
  }
  size_t count = 0;
  for (uint8_t in : inHierarchy) count += in;
  if (source && refitHierarchy(*source, impl, inHierarchy, count, bounds)) return true;
  if (count < n) {  // the hierarchy's instances, in place
    size_t kept = 0;
    for (size_t i = 0; i < n; ++i)
      if (inHierarchy[i]) bounds[kept++] = bounds[i];
    bounds.resize(kept);
  }
  return buildHierarchy(device, impl, bounds, error);
}

}  // namespace
}  // namespace detail

Tlas::Impl::~Impl() {
  if (flatScene) rtcReleaseScene(flatScene);
}

Tlas::~Tlas() = default;

namespace {

std::shared_ptr<Tlas> buildTlas(InstanceArray instances, const BuildOptions& options, const Tlas::Impl* source,
                                std::string* error) {
  if (instances.size() > detail::kMaxHierarchyInstances) {  // the hierarchy's leaf references hold 28 bits
    if (error) *error = "Tlas build: too many instances";
    return nullptr;
  }
  auto block = std::make_shared<detail::TlasBlock>();
  Tlas::Impl& impl = block->body;
  impl.instances = std::move(instances);
  impl.options = options;
  if (!detail::makeRecords(impl, error)) return nullptr;
  if (!detail::buildLevels(impl, source, error)) return nullptr;
  impl.built = true;
  return std::shared_ptr<Tlas>(block, block.get());
}

}  // namespace

InstanceArray::InstanceArray(const std::vector<Instance>& instances) : InstanceArray(uninitialized(instances.size())) {
  std::uninitialized_copy(instances.begin(), instances.end(), p_.get());
}

InstanceArray InstanceArray::uninitialized(size_t n) {
  static_assert(std::is_trivially_destructible_v<Instance>);  // (elements are never destroyed)
  InstanceArray a;
  if (n) a.p_.reset(static_cast<Instance*>(::operator new(n * sizeof(Instance))));
  a.n_ = n;
  return a;
}

void InstanceArray::Free::operator()(Instance* p) const { ::operator delete(p); }

std::shared_ptr<Tlas> Tlas::build(InstanceArray instances, const BuildOptions& options, std::string* error) {
  return buildTlas(std::move(instances), options, nullptr, error);
}

// An update (VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR) refits this Tlas's hierarchy, copied, to the new
// transforms when the same instances are in it (the usual case: instances move), and builds it otherwise; the
// flattened triangles are transformed again either way. This Tlas is untouched (it may be traversed meanwhile).
std::shared_ptr<Tlas> Tlas::update(InstanceArray instances, std::string* error) const {
  return buildTlas(std::move(instances), impl().options, &impl(), error);
}

std::span<const Instance> Tlas::instances() const { return {impl().instances.data(), impl().instances.size()}; }
const BuildOptions& Tlas::options() const { return impl().options; }

uint64_t Tlas::nativeBytes() const {
  // The instances, their records, the hierarchy, and the flattened triangles (Embree's copy of their world-space
  // vertices and indices, about 48 bytes, and its hierarchy, about 32 bytes a triangle, plus vkrt's map back).
  uint64_t flat = 0;
  for (const auto& g : impl().flat) flat += g.size() * (80 + sizeof(detail::FlatTriangle));
  return sizeof(Impl) + impl().instances.size() * (sizeof(Instance) + sizeof(detail::InstanceRecord)) +
         impl().nodes.size() * sizeof(detail::BvhNode) + impl().leafItems.size() * sizeof(uint32_t) + flat;
}

}  // namespace vkrt::accel
