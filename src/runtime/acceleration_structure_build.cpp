// Acceleration structure build inputs: checks at record time, reading and converting at build time.
//
// Addressing (the specification's "Acceleration Structure Build" rules, per geometry and its build range):
//   triangles, no indices: vertex k of primitive p at vertexData + primitiveOffset + (firstVertex + 3p + k) * stride
//   triangles, indexed:    index k of primitive p at indexData + primitiveOffset + (3p + k) * indexSize,
//                          its vertex at vertexData + (firstVertex + index) * stride (at most maxVertex)
//   transformData:         a VkTransformMatrixKHR at transformData + transformOffset, applied to the vertices
//   AABBs:                 primitive p at data + primitiveOffset + p * stride (a VkAabbPositionsKHR)
//   instances:             instance p at data + primitiveOffset + p * 64, or through the pointer at
//                          data + primitiveOffset + p * 8 (arrayOfPointers)
// Device builds read device memory: every range is checked to lie in allocated device memory first, so garbage
// addresses are reported instead of faulting. Host builds read the application's host pointers as given.
#include "runtime/acceleration_structure_build.hpp"

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <mutex>
#include <new>

#include "exec/thread_pool.hpp"
#include "runtime/buffer.hpp"
#include "runtime/device.hpp"
#include "runtime/memory.hpp"
#include "runtime/ray_tracing_features.hpp"
#include "runtime/report.hpp"

namespace vkrt {

namespace {

using ull = unsigned long long;

float halfToFloat(uint16_t h) {
  const uint32_t sign = h >> 15, exp = (h >> 10) & 31, man = h & 1023;
  float v = exp == 0    ? std::ldexp(float(man), -24)
            : exp == 31 ? (man ? NAN : INFINITY)
                        : std::ldexp(float(man | 1024), int(exp) - 25);
  return sign ? -v : v;
}

template <class T>
T load(const uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

std::string format(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
std::string format(const char* fmt, ...) {
  char buf[512];
  va_list args;
  va_start(args, fmt);
  std::vsnprintf(buf, sizeof buf, fmt, args);
  va_end(args);
  return buf;
}

// Reads memory the build was pointed at: device builds check that [address, address + bytes) is device memory.
class Source {
 public:
  explicit Source(bool host) : host_(host) {}
  const uint8_t* at(uint64_t address, uint64_t bytes, const char* what, uint32_t geometry, BuildError* e) const {
    if (bytes == 0) return reinterpret_cast<const uint8_t*>(address);
    if (!address || (!host_ && !arena::accessible(address, bytes))) {
      e->vuid = host_ ? nullptr : "VUID-vkCmdBuildAccelerationStructuresKHR-geometry-03673";
      e->message = format("pGeometries[%u]: the %s (%" PRIu64 " bytes at 0x%llx) is not in %s memory", geometry, what,
                          bytes, (ull)address, host_ ? "host" : "device");
      return nullptr;
    }
    return reinterpret_cast<const uint8_t*>(address);
  }

 private:
  bool host_;
};

uint32_t indexSize(VkIndexType t) {
  switch (t) {
    case VK_INDEX_TYPE_UINT16: return 2;
    case VK_INDEX_TYPE_UINT32: return 4;
    case VK_INDEX_TYPE_UINT8_EXT: return 1;
    default: return 0;
  }
}

// Runs f(begin, end) over [0, n) in chunks on the thread pool and the calling thread: a build of millions of
// triangles reads and converts hundreds of megabytes, which one core would do alone.
template <class F>
void forChunks(uint64_t n, const F& f) {
  constexpr uint64_t kChunk = uint64_t(1) << 16;
  const uint64_t chunks = (n + kChunk - 1) / kChunk;
  if (chunks <= 1) {
    if (n) f(uint64_t(0), n);
    return;
  }
  exec::ThreadPool::instance().runConcurrently(chunks,
                                               [&](uint64_t c) { f(c * kChunk, std::min(n, (c + 1) * kChunk)); });
}

bool readTriangles(const Source& src, const VkAccelerationStructureGeometryTrianglesDataKHR& t,
                   const VkAccelerationStructureBuildRangeInfoKHR& r, uint32_t g, accel::TriangleGeometry* out,
                   BuildError* e) {
  const uint64_t n = r.primitiveCount, stride = t.vertexStride;
  const uint32_t isz = indexSize(t.indexType);
  // The vertices used, as absolute vertex numbers [lo, hi] (firstVertex + index, or firstVertex + 3p + k without
  // indices), and the geometry's indices relative to lo.
  uint64_t lo = r.firstVertex, hi = r.firstVertex + (n ? 3 * n - 1 : 0);
  const uint8_t* idx = nullptr;
  auto indexAt = [&](uint64_t i) -> uint32_t {
    return isz == 4 ? load<uint32_t>(idx + i * 4) : isz == 2 ? load<uint16_t>(idx + i * 2) : idx[i];
  };
  uint32_t minIndex = 0;
  if (isz && n) {
    idx = src.at(t.indexData.deviceAddress + r.primitiveOffset, n * 3 * isz, "index data", g, e);
    if (!idx) return false;
    // The smallest and largest index, per chunk, then over the chunks.
    std::mutex m;
    uint32_t mn = UINT32_MAX, mx = 0;
    forChunks(n * 3, [&](uint64_t begin, uint64_t end) {
      uint32_t a = UINT32_MAX, b = 0;
      for (uint64_t i = begin; i < end; ++i) {
        const uint32_t v = indexAt(i);
        a = std::min(a, v);
        b = std::max(b, v);
      }
      std::lock_guard lock(m);
      mn = std::min(mn, a);
      mx = std::max(mx, b);
    });
    minIndex = mn;
    lo = uint64_t(r.firstVertex) + mn;
    hi = uint64_t(r.firstVertex) + mx;
    // VUID-VkAccelerationStructureGeometryTrianglesDataKHR-maxVertex: indices address at most maxVertex.
    if (hi > t.maxVertex) {
      e->vuid = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03712";
      e->message =
          format("pGeometries[%u]: a triangle addresses vertex %llu (firstVertex %u + index), beyond maxVertex %u", g,
                 (ull)hi, r.firstVertex, t.maxVertex);
      return false;
    }
  }
  const uint64_t base = t.vertexData.deviceAddress + (isz ? 0 : r.primitiveOffset);
  const uint64_t count = n ? hi - lo + 1 : 0;
  const uint8_t* v =
      count ? src.at(base + lo * stride, (count - 1) * stride + vertexReadBytes(t.vertexFormat), "vertex data", g, e)
            : nullptr;
  if (count && !v) return false;
  float m[3][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}};
  const bool transformed = t.transformData.deviceAddress != 0;
  if (transformed) {
    const uint8_t* tp =
        src.at(t.transformData.deviceAddress + r.transformOffset, sizeof(VkTransformMatrixKHR), "transform data", g, e);
    if (!tp) return false;
    std::memcpy(m, tp, sizeof m);
  }
  out->vertices.reserve(count * 3 + 1);  // one float past the last vertex: Embree reads the copy in place (blas.cpp)
  out->vertices.resize(count * 3);
  float* const vertices = out->vertices.data();
  if (!transformed && t.vertexFormat == VK_FORMAT_R32G32B32_SFLOAT && stride == 12) {
    forChunks(count, [&](uint64_t begin, uint64_t end) {
      std::memcpy(vertices + begin * 3, v + begin * 12, (end - begin) * 12);
    });
  } else {
    forChunks(count, [&](uint64_t begin, uint64_t end) {
      for (uint64_t i = begin; i < end; ++i) {
        float p[3];
        decodeVertex(t.vertexFormat, v + i * stride, p);
        float* o = vertices + i * 3;
        if (transformed) {
          for (int k = 0; k < 3; ++k) o[k] = m[k][0] * p[0] + m[k][1] * p[1] + m[k][2] * p[2] + m[k][3];
        } else {
          o[0] = p[0], o[1] = p[1], o[2] = p[2];
        }
      }
    });
  }
  out->indices.resize(n * 3);
  uint32_t* const indices = out->indices.data();
  forChunks(n * 3, [&](uint64_t begin, uint64_t end) {
    if (isz) {
      for (uint64_t i = begin; i < end; ++i) indices[i] = indexAt(i) - minIndex;
    } else {
      for (uint64_t i = begin; i < end; ++i) indices[i] = uint32_t(i);
    }
  });
  return true;
}

bool readAabbs(const Source& src, const VkAccelerationStructureGeometryAabbsDataKHR& a,
               const VkAccelerationStructureBuildRangeInfoKHR& r, uint32_t g, accel::AabbGeometry* out, BuildError* e) {
  const uint64_t n = r.primitiveCount;
  const uint8_t* p =
      n ? src.at(a.data.deviceAddress + r.primitiveOffset, (n - 1) * a.stride + 24, "AABB data", g, e) : nullptr;
  if (n && !p) return false;
  out->boxes.resize(n * 6);  // (not value-initialized: each chunk's thread writes its pages first)
  float* const boxes = out->boxes.data();
  forChunks(n, [&](uint64_t begin, uint64_t end) {
    for (uint64_t i = begin; i < end; ++i) std::memcpy(boxes + i * 6, p + i * a.stride, 24);
  });
  return true;
}

// Resolves an instance's accelerationStructureReference: a device address (device builds) or a handle (host).
std::shared_ptr<const accel::Blas> resolveBlas(Device* dev, uint64_t ref, bool host, uint32_t instance, BuildError* e,
                                               uint64_t* address) {
  *address = 0;
  if (ref == 0) return nullptr;
  std::shared_ptr<const AccelerationStructure::Content> c;
  const AccelerationStructure* as = nullptr;
  if (host) {
    as = fromHandle<AccelerationStructure>(reinterpret_cast<VkAccelerationStructureKHR>(ref));
    if (as) c = as->content();
  } else {
    std::lock_guard lock(dev->accelerationStructuresMutex);
    auto it = dev->accelerationStructures.find(ref);
    if (it != dev->accelerationStructures.end()) {
      as = it->second;
      c = as->content();
    }
  }
  if (!c || !c->blas) {
    e->vuid = host ? "VUID-vkBuildAccelerationStructuresKHR-pInfos-03779"
                   : "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-06707";
    e->message = format("instance %u refers to %s 0x%llx, which is %s", instance,
                        host ? "acceleration structure" : "address", (ull)ref,
                        !as  ? (host ? "not a live acceleration structure (destroyed?)"
                                     : "not the address of a live acceleration structure (destroyed?)")
                        : !c ? "an acceleration structure that was never built"
                             : "a top-level acceleration structure (instances refer to bottom-level ones)");
    return nullptr;
  }
  *address = as->address();
  return c->blas;
}

// `keep` receives an owner of each Blas an instance points to (accel::Instance holds a plain pointer), for the caller
// to hold until the Tlas that takes them over is built.
bool readInstances(Device* dev, const Source& src, const VkAccelerationStructureGeometryInstancesDataKHR& d,
                   const VkAccelerationStructureBuildRangeInfoKHR& r, bool host, accel::InstanceArray* out,
                   std::vector<uint64_t>* refs, std::vector<uint64_t>* addresses,
                   std::vector<std::shared_ptr<const accel::Blas>>* keep, BuildError* e) {
  const uint64_t n = r.primitiveCount;
  const uint64_t each = d.arrayOfPointers ? 8 : sizeof(VkAccelerationStructureInstanceKHR);
  const uint8_t* p = n ? src.at(d.data.deviceAddress + r.primitiveOffset, n * each, "instance data", 0, e) : nullptr;
  if (n && !p) return false;
  *out = accel::InstanceArray::uninitialized(n);  // each instance constructed by the thread that copies it
  refs->resize(n);
  addresses->resize(n);
  auto copy = [&](uint64_t i, const uint8_t* ip) {
    VkAccelerationStructureInstanceKHR in;
    std::memcpy(&in, ip, sizeof in);
    accel::Instance& o = *::new (static_cast<void*>(out->data() + i)) accel::Instance;
    std::memcpy(o.transform, in.transform.matrix, sizeof o.transform);
    o.customIndex = in.instanceCustomIndex;
    o.mask = in.mask;
    o.sbtOffset = in.instanceShaderBindingTableRecordOffset;
    o.flags = in.flags;
    (*refs)[i] = in.accelerationStructureReference;
  };
  // One resolution per run of equal references (instances of one bottom level usually come together).
  struct Run {
    const accel::Blas* blas;
    uint64_t address;
  };
  auto resolveRun = [&](uint64_t i, Run* run) {
    std::shared_ptr<const accel::Blas> b = resolveBlas(dev, (*refs)[i], host, uint32_t(i), e, &run->address);
    if (!b && (*refs)[i]) return false;
    run->blas = b.get();
    if (b && (keep->empty() || keep->back() != b)) keep->push_back(std::move(b));
    return true;
  };
  if (d.arrayOfPointers) {
    Run run{};
    for (uint64_t i = 0; i < n; ++i) {
      const uint8_t* ip =
          src.at(load<uint64_t>(p + i * each), sizeof(VkAccelerationStructureInstanceKHR), "instance pointed to", 0, e);
      if (!ip) return false;
      copy(i, ip);
      if ((i == 0 || (*refs)[i] != (*refs)[i - 1]) && !resolveRun(i, &run)) return false;
      (*out)[i].blas = run.blas;
      (*addresses)[i] = run.address;
    }
    return true;
  }
  // In chunks on the thread pool: the instances copied and the runs' first instances found (a reference compared
  // with the one before it in the application's array); the runs then resolved in order on this thread (the first
  // bad reference is the one reported), and each instance given its run's in chunks again.
  constexpr size_t kReferenceAt = offsetof(VkAccelerationStructureInstanceKHR, accelerationStructureReference);
  std::mutex merge;
  std::vector<uint64_t> firsts;
  forChunks(n, [&](uint64_t begin, uint64_t end) {
    std::vector<uint64_t> found;
    uint64_t before = begin ? load<uint64_t>(p + (begin - 1) * each + kReferenceAt) : 0;
    for (uint64_t i = begin; i < end; ++i) {
      copy(i, p + i * each);
      if (i == 0 || (*refs)[i] != before) found.push_back(i);
      before = (*refs)[i];
    }
    std::lock_guard lock(merge);
    firsts.insert(firsts.end(), found.begin(), found.end());
  });
  std::sort(firsts.begin(), firsts.end());
  std::vector<Run> runs(firsts.size());
  for (size_t k = 0; k < firsts.size(); ++k)
    if (!resolveRun(firsts[k], &runs[k])) return false;
  forChunks(n, [&](uint64_t begin, uint64_t end) {
    // The run holding `begin`: the last one starting at or before it (firsts[0] is 0).
    size_t k = size_t(std::upper_bound(firsts.begin(), firsts.end(), begin) - firsts.begin()) - 1;
    for (uint64_t i = begin; i < end; ++i) {
      if (k + 1 < firsts.size() && firsts[k + 1] == i) ++k;
      (*out)[i].blas = runs[k].blas;
      (*addresses)[i] = runs[k].address;
    }
  });
  return true;
}

// The update rules that need the source's last build: same geometry count, types, flags, primitive counts.
bool checkUpdate(const BuildJob& job, const AccelerationStructure::Content& prev, BuildError* e) {
  if (!(prev.flags & VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR)) {
    e->vuid = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03667";
    e->message = "the source was not built with VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR";
    return false;
  }
  if (prev.flags != job.flags) {
    e->vuid = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03759";
    e->message = format("flags 0x%x differ from the source's last build (0x%x)", job.flags, prev.flags);
    return false;
  }
  if (prev.type != job.type) {
    e->vuid = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03760";
    e->message = "the type differs from the source's last build";
    return false;
  }
  if (job.type == VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR) {
    if (job.ranges.empty() || job.ranges[0].primitiveCount != prev.instanceCount) {
      e->vuid = "VUID-vkCmdBuildAccelerationStructuresKHR-primitiveCount-03769";
      e->message = format("the instance count differs from the source's last build (%u)", prev.instanceCount);
      return false;
    }
    return true;
  }
  if (job.geometries.size() != prev.shape.size()) {
    e->vuid = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03758";
    e->message = format("geometryCount %zu differs from the source's last build (%zu)", job.geometries.size(),
                        prev.shape.size());
    return false;
  }
  for (size_t g = 0; g < job.geometries.size(); ++g) {
    const VkAccelerationStructureGeometryKHR& geo = job.geometries[g];
    const AccelerationStructure::Content::GeometryShape& s = prev.shape[g];
    const char* vuid = nullptr;
    if (geo.geometryType != s.type)
      vuid = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03761";
    else if (geo.flags != s.flags)
      vuid = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03762";
    else if (job.ranges[g].primitiveCount != s.primitiveCount)
      vuid = "VUID-vkCmdBuildAccelerationStructuresKHR-primitiveCount-03769";
    else if (geo.geometryType == VK_GEOMETRY_TYPE_TRIANGLES_KHR) {
      const auto& t = geo.geometry.triangles;
      if (t.vertexFormat != s.vertexFormat)
        vuid = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03763";
      else if (t.indexType != s.indexType)
        vuid = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03765";
      else if ((t.transformData.deviceAddress != 0) != s.hasTransform)
        vuid = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03767";
      else if (t.indexType != VK_INDEX_TYPE_NONE_KHR && job.ranges[g].firstVertex != s.firstVertex)
        vuid = "VUID-vkCmdBuildAccelerationStructuresKHR-firstVertex-03770";
    }
    if (vuid) {
      e->vuid = vuid;
      e->message = format(
          "pGeometries[%zu] differs from the source's last build (type, flags, primitive count, vertex format, "
          "index type, transform or firstVertex)",
          g);
      return false;
    }
  }
  return true;
}

}  // namespace

namespace {

// The vertex formats builds accept: the six the specification requires, and every other 2-, 3- or 4-component
// 8/16-bit normalized, 16-bit float and 32/64-bit float format (a CPU decodes them all alike). Only x, y and z
// are read.
struct VertexFormat {
  VkFormat format;
  uint8_t componentBytes, components;
  enum Kind : uint8_t { Float, SNorm, UNorm } kind;
};
constexpr VertexFormat kVertexFormats[] = {
    {VK_FORMAT_R32G32_SFLOAT, 4, 2, VertexFormat::Float},
    {VK_FORMAT_R32G32B32_SFLOAT, 4, 3, VertexFormat::Float},
    {VK_FORMAT_R32G32B32A32_SFLOAT, 4, 4, VertexFormat::Float},
    {VK_FORMAT_R16G16_SFLOAT, 2, 2, VertexFormat::Float},
    {VK_FORMAT_R16G16B16_SFLOAT, 2, 3, VertexFormat::Float},
    {VK_FORMAT_R16G16B16A16_SFLOAT, 2, 4, VertexFormat::Float},
    {VK_FORMAT_R16G16_SNORM, 2, 2, VertexFormat::SNorm},
    {VK_FORMAT_R16G16B16_SNORM, 2, 3, VertexFormat::SNorm},
    {VK_FORMAT_R16G16B16A16_SNORM, 2, 4, VertexFormat::SNorm},
    {VK_FORMAT_R16G16_UNORM, 2, 2, VertexFormat::UNorm},
    {VK_FORMAT_R16G16B16_UNORM, 2, 3, VertexFormat::UNorm},
    {VK_FORMAT_R16G16B16A16_UNORM, 2, 4, VertexFormat::UNorm},
    {VK_FORMAT_R8G8_SNORM, 1, 2, VertexFormat::SNorm},
    {VK_FORMAT_R8G8B8_SNORM, 1, 3, VertexFormat::SNorm},
    {VK_FORMAT_R8G8B8A8_SNORM, 1, 4, VertexFormat::SNorm},
    {VK_FORMAT_R8G8_UNORM, 1, 2, VertexFormat::UNorm},
    {VK_FORMAT_R8G8B8_UNORM, 1, 3, VertexFormat::UNorm},
    {VK_FORMAT_R8G8B8A8_UNORM, 1, 4, VertexFormat::UNorm},
    {VK_FORMAT_R64G64_SFLOAT, 8, 2, VertexFormat::Float},
    {VK_FORMAT_R64G64B64_SFLOAT, 8, 3, VertexFormat::Float},
    {VK_FORMAT_R64G64B64A64_SFLOAT, 8, 4, VertexFormat::Float},
};

const VertexFormat* vertexFormat(VkFormat f) {
  for (const VertexFormat& v : kVertexFormats)
    if (v.format == f) return &v;
  return nullptr;
}

float component(const VertexFormat& v, const uint8_t* p) {
  switch (v.componentBytes) {
    case 1: return v.kind == VertexFormat::SNorm ? std::max(-1.0f, float(int8_t(p[0])) / 127.0f) : float(p[0]) / 255.0f;
    case 2:
      if (v.kind == VertexFormat::Float) return halfToFloat(load<uint16_t>(p));
      return v.kind == VertexFormat::SNorm ? std::max(-1.0f, float(load<int16_t>(p)) / 32767.0f)
                                           : float(load<uint16_t>(p)) / 65535.0f;
    case 4: return load<float>(p);
    default: return float(load<double>(p));
  }
}

}  // namespace

bool accelerationStructureVertexFormat(VkFormat f) { return vertexFormat(f) != nullptr; }

uint32_t vertexComponentBytes(VkFormat f) {
  const VertexFormat* v = vertexFormat(f);
  return v ? v->componentBytes : 1;
}

uint32_t vertexReadBytes(VkFormat f) {
  const VertexFormat* v = vertexFormat(f);
  return v ? v->componentBytes * std::min<uint32_t>(v->components, 3) : 0;
}

void decodeVertex(VkFormat f, const uint8_t* p, float out[3]) {
  out[0] = out[1] = out[2] = 0;
  const VertexFormat* v = vertexFormat(f);
  if (!v) return;
  for (uint32_t k = 0; k < std::min<uint32_t>(v->components, 3); ++k) out[k] = component(*v, p + k * v->componentBytes);
}

bool makeJob(const Object* about, const char* fn, uint32_t i, const VkAccelerationStructureBuildGeometryInfoKHR& info,
             const VkAccelerationStructureBuildRangeInfoKHR* ranges, bool host, BuildJob* job) {
  job->index = i;
  job->type = info.type;
  job->flags = info.flags;
  job->mode = info.mode;
  job->host = host;
  job->dst = fromHandle<AccelerationStructure>(info.dstAccelerationStructure);
  // VUID-vkCmdBuildAccelerationStructuresKHR-dstAccelerationStructure-03800
  if (!job->dst) {
    report(about, Severity::Error, "VUID-vkCmdBuildAccelerationStructuresKHR-dstAccelerationStructure-03800",
           "%s: pInfos[%u].dstAccelerationStructure 0x%llx is not a live VkAccelerationStructureKHR", fn, i,
           (ull)rawHandle(info.dstAccelerationStructure));
    return false;
  }
  if (info.mode == VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR) {
    job->src = fromHandle<AccelerationStructure>(info.srcAccelerationStructure);
    // VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-04630,
    // VUID-vkCmdBuildAccelerationStructuresKHR-srcAccelerationStructure-04629
    if (!job->src) {
      report(
          about, Severity::Error, "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-04630",
          "%s: pInfos[%u] is an update, but srcAccelerationStructure 0x%llx is not a live VkAccelerationStructureKHR",
          fn, i, (ull)rawHandle(info.srcAccelerationStructure));
      return false;
    }
  }
  job->geometries.resize(info.geometryCount);
  for (uint32_t g = 0; g < info.geometryCount; ++g) {
    job->geometries[g] = info.pGeometries ? info.pGeometries[g] : *info.ppGeometries[g];
    job->geometries[g].pNext = nullptr;
  }
  if (ranges) job->ranges.assign(ranges, ranges + info.geometryCount);
  return true;
}

bool checkBuild(const Object* about, const char* fn, const BuildJob& job, const Device* dev) {
  const uint32_t i = job.index;
  auto fail = [&](const char* vuid, const std::string& what) {
    report(about, Severity::Error, vuid, "%s: pInfos[%u]: %s", fn, i, what.c_str());
    return false;
  };
  // VUID-vkCmdBuildAccelerationStructuresKHR-mode-04628
  if (job.mode != VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR &&
      job.mode != VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR)
    return fail("VUID-vkCmdBuildAccelerationStructuresKHR-mode-04628",
                format("mode %d is not a valid value", int(job.mode)));
  // VUID-VkAccelerationStructureBuildGeometryInfoKHR-type-03654
  if (job.type != VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR &&
      job.type != VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR)
    return fail("VUID-VkAccelerationStructureBuildGeometryInfoKHR-type-03654",
                "type must be TOP_LEVEL or BOTTOM_LEVEL");
  // VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03699, VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03700
  if (job.dst->type != VK_ACCELERATION_STRUCTURE_TYPE_GENERIC_KHR && job.dst->type != job.type)
    return fail(job.type == VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR
                    ? "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03699"
                    : "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03700",
                "dstAccelerationStructure was created with another type than the build's");
  const bool top = job.type == VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR;
  // VUID-VkAccelerationStructureBuildGeometryInfoKHR-type-03790
  if (top && job.geometries.size() != 1)
    return fail("VUID-VkAccelerationStructureBuildGeometryInfoKHR-type-03790",
                format("a top-level build has %zu geometries; it must have exactly one", job.geometries.size()));
  uint64_t primitives = 0;
  for (size_t g = 0; g < job.geometries.size(); ++g) {
    const VkAccelerationStructureGeometryKHR& geo = job.geometries[g];
    // VUID-VkAccelerationStructureBuildGeometryInfoKHR-type-03789, -03791
    if (top != (geo.geometryType == VK_GEOMETRY_TYPE_INSTANCES_KHR))
      return fail(top ? "VUID-VkAccelerationStructureBuildGeometryInfoKHR-type-03789"
                      : "VUID-VkAccelerationStructureBuildGeometryInfoKHR-type-03791",
                  format("pGeometries[%zu] has geometryType %d, which a %s-level build does not take", g,
                         int(geo.geometryType), top ? "top" : "bottom"));
    if (geo.geometryType == VK_GEOMETRY_TYPE_TRIANGLES_KHR) {
      const auto& t = geo.geometry.triangles;
      // VUID-VkAccelerationStructureGeometryTrianglesDataKHR-vertexFormat-03797
      if (!accelerationStructureVertexFormat(t.vertexFormat))
        return fail("VUID-VkAccelerationStructureGeometryTrianglesDataKHR-vertexFormat-03797",
                    format("pGeometries[%zu].geometry.triangles.vertexFormat %d has no "
                           "VK_FORMAT_FEATURE_ACCELERATION_STRUCTURE_VERTEX_BUFFER_BIT_KHR",
                           g, int(t.vertexFormat)));
      // VUID-VkAccelerationStructureGeometryTrianglesDataKHR-indexType-03798
      if (t.indexType != VK_INDEX_TYPE_NONE_KHR && t.indexType != VK_INDEX_TYPE_UINT16 &&
          t.indexType != VK_INDEX_TYPE_UINT32)
        return fail("VUID-VkAccelerationStructureGeometryTrianglesDataKHR-indexType-03798",
                    format("pGeometries[%zu].geometry.triangles.indexType %d is not UINT16, UINT32 or NONE_KHR", g,
                           int(t.indexType)));
      // VUID-VkAccelerationStructureGeometryTrianglesDataKHR-vertexStride-03735
      if (t.vertexStride % vertexComponentBytes(t.vertexFormat))
        return fail("VUID-VkAccelerationStructureGeometryTrianglesDataKHR-vertexStride-03735",
                    format("pGeometries[%zu].geometry.triangles.vertexStride %llu is not a multiple of the vertex "
                           "format's component size",
                           g, (ull)t.vertexStride));
      // VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03810
      if (t.transformData.deviceAddress % 16)
        return fail("VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03810",
                    format("pGeometries[%zu].geometry.triangles.transformData 0x%llx is not aligned to 16 bytes", g,
                           (ull)t.transformData.deviceAddress));
    } else if (geo.geometryType == VK_GEOMETRY_TYPE_AABBS_KHR) {
      const auto& a = geo.geometry.aabbs;
      // VUID-VkAccelerationStructureGeometryAabbsDataKHR-stride-03545
      if (a.stride % 8)
        return fail("VUID-VkAccelerationStructureGeometryAabbsDataKHR-stride-03545",
                    format("pGeometries[%zu].geometry.aabbs.stride %llu is not a multiple of 8", g, (ull)a.stride));
      // VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03714
      if (a.data.deviceAddress % 8)
        return fail("VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03714",
                    format("pGeometries[%zu].geometry.aabbs.data 0x%llx is not aligned to 8 bytes", g,
                           (ull)a.data.deviceAddress));
    } else if (geo.geometryType == VK_GEOMETRY_TYPE_INSTANCES_KHR) {
      const auto& d = geo.geometry.instances;
      // VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03715, VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03716
      if (d.data.deviceAddress % (d.arrayOfPointers ? 8 : 16))
        return fail(d.arrayOfPointers ? "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03716"
                                      : "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03715",
                    format("geometry.instances.data 0x%llx is not aligned to %d bytes", (ull)d.data.deviceAddress,
                           d.arrayOfPointers ? 8 : 16));
    } else {
      return fail("VUID-VkAccelerationStructureGeometryKHR-geometryType-parameter",
                  format("pGeometries[%zu].geometryType %d is not a valid value", g, int(geo.geometryType)));
    }
    if (g < job.ranges.size()) {
      primitives += job.ranges[g].primitiveCount;
      // VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03801
      if (top && job.ranges[g].primitiveCount > accelerationStructureProperties().maxInstanceCount)
        return fail("VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03801",
                    format("%u instances exceed maxInstanceCount", job.ranges[g].primitiveCount));
    }
  }
  // VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03675
  if (!job.ranges.empty() && job.dst->size < requiredSize(primitives))
    return fail("VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03675",
                format("dstAccelerationStructure has %llu bytes, less than the %llu "
                       "vkGetAccelerationStructureBuildSizesKHR reports for %llu "
                       "primitives",
                       (ull)job.dst->size, (ull)requiredSize(primitives), (ull)primitives));
  (void)dev;
  return true;
}

bool runBuild(Device* dev, const BuildJob& job, BuildError* e) {
  std::shared_ptr<const AccelerationStructure::Content> prev;
  if (job.mode == VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR) {
    prev = job.src->content();
    if (!prev) {
      e->vuid = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03667";
      e->message = "the update's source was never built";
      return false;
    }
    if (!checkUpdate(job, *prev, e)) return false;
  }
  Source src(job.host);
  auto content = std::make_shared<AccelerationStructure::Content>();
  content->type = job.type;
  content->flags = job.flags;
  std::string error;
  if (job.type == VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR) {
    accel::InstanceArray instances;
    std::vector<std::shared_ptr<const accel::Blas>> keep;  // until the Tlas holds them
    if (!readInstances(dev, src, job.geometries[0].geometry.instances, job.ranges[0], job.host, &instances,
                       &content->blasAddresses, &content->blasAt, &keep, e))
      return false;
    content->blasGeneration = dev->blasGeneration.load();
    content->instanceCount = uint32_t(instances.size());
    content->tlas = prev && prev->tlas ? prev->tlas->update(std::move(instances), &error)
                                       : accel::Tlas::build(std::move(instances), buildOptions(job.flags), &error);
  } else {
    std::vector<accel::Geometry> geometries(job.geometries.size());
    for (uint32_t g = 0; g < job.geometries.size(); ++g) {
      const VkAccelerationStructureGeometryKHR& geo = job.geometries[g];
      const VkAccelerationStructureBuildRangeInfoKHR& r = job.ranges[g];
      AccelerationStructure::Content::GeometryShape shape{
          geo.geometryType,    geo.flags, r.primitiveCount, r.firstVertex, VK_INDEX_TYPE_NONE_KHR,
          VK_FORMAT_UNDEFINED, false};
      if (geo.geometryType == VK_GEOMETRY_TYPE_TRIANGLES_KHR) {
        geometries[g].kind = accel::Geometry::Triangles;
        geometries[g].triangles.flags = geo.flags;
        if (!readTriangles(src, geo.geometry.triangles, r, g, &geometries[g].triangles, e)) return false;
        shape.indexType = geo.geometry.triangles.indexType;
        shape.vertexFormat = geo.geometry.triangles.vertexFormat;
        shape.hasTransform = geo.geometry.triangles.transformData.deviceAddress != 0;
      } else {
        geometries[g].kind = accel::Geometry::Aabbs;
        geometries[g].aabbs.flags = geo.flags;
        if (!readAabbs(src, geo.geometry.aabbs, r, g, &geometries[g].aabbs, e)) return false;
      }
      content->shape.push_back(shape);
    }
    content->blas = prev && prev->blas ? prev->blas->update(std::move(geometries), &error)
                                       : accel::Blas::build(std::move(geometries), buildOptions(job.flags), &error);
  }
  if (!content->blas && !content->tlas) {
    e->vuid = nullptr;
    e->message = "the build failed: " + error;
    return false;
  }
  job.dst->setContent(std::move(content));
  return true;
}

}  // namespace vkrt
