// Serialization: the build inputs and options in a versioned, checksummed, bounds-checked binary form.
// Deserializing builds the structure again from them (Embree's hierarchy has no stable serialized form), which
// gives the same traversal results.
//
// Format (little-endian, as vkrt's hosts are), after the header the runtime writes:
//
//   header, 32 bytes:
//     u32 magic 'vkAS' (0x53416b76)   u32 version (1)   u32 kind (1 Blas, 2 Tlas)   u32 build options (bits:
//     preferFastTrace 1, preferFastBuild 2, allowUpdate 4, lowMemory 8)   u64 payload bytes   u64 payload checksum
//   Blas payload:
//     u32 geometry count, u32 0; per geometry: u32 kind (0 triangles, 1 boxes), u32 flags, u64 float count
//     (vertices: 3 per vertex; boxes: 6 per box), u64 index count (0 for boxes); then per geometry its floats,
//     then its u32 indices
//   Tlas payload:
//     u32 instance count, u32 Blas reference count; per instance (72 bytes): 12 floats (transform rows),
//     u32 custom index, u32 mask, u32 SBT offset, u32 flags, u32 Blas reference (index into the references,
//     0xFFFFFFFF none), u32 0
//
// Reading checks every count against the bytes left before it allocates or copies, so that garbage or
// truncated input fails with an error and never reads out of bounds or allocates more than its own size.
#include <cstring>

#include "accel/accel.hpp"

namespace vkrt::accel {
namespace {

constexpr uint32_t kMagic = 0x53416b76;  // "vkAS"
constexpr uint32_t kVersion = 1;
constexpr uint32_t kKindBlas = 1, kKindTlas = 2;
constexpr size_t kHeaderBytes = 32;
constexpr uint32_t kNoBlas = 0xFFFFFFFFu;

uint64_t checksum(const uint8_t* p, size_t n) {
  // A multiply-xor hash over 8-byte words (and the tail), fixed: it detects corruption, it is no security.
  uint64_t h = 0x9E3779B97F4A7C15ull ^ n;
  size_t i = 0;
  for (; i + 8 <= n; i += 8) {
    uint64_t w;
    std::memcpy(&w, p + i, 8);
    h = (h ^ w) * 0x100000001B3ull;
    h ^= h >> 29;
  }
  for (; i < n; ++i) h = (h ^ p[i]) * 0x100000001B3ull;
  return h ^ (h >> 32);
}

uint32_t packOptions(const BuildOptions& o) {
  return (o.preferFastTrace ? 1u : 0) | (o.preferFastBuild ? 2u : 0) | (o.allowUpdate ? 4u : 0) |
         (o.lowMemory ? 8u : 0);
}

BuildOptions unpackOptions(uint32_t bits) {
  BuildOptions o;
  o.preferFastTrace = bits & 1;
  o.preferFastBuild = bits & 2;
  o.allowUpdate = bits & 4;
  o.lowMemory = bits & 8;
  return o;
}

class Writer {
 public:
  template <typename T>
  void put(T v) {
    const size_t at = bytes.size();
    bytes.resize(at + sizeof(T));
    std::memcpy(bytes.data() + at, &v, sizeof(T));
  }
  template <typename T, typename A>
  void putArray(const std::vector<T, A>& v) {
    const size_t at = bytes.size();
    bytes.resize(at + v.size() * sizeof(T));
    if (!v.empty()) std::memcpy(bytes.data() + at, v.data(), v.size() * sizeof(T));
  }
  std::vector<uint8_t> bytes;
};

class Reader {
 public:
  Reader(const uint8_t* data, size_t size) : p_(data), left_(size) {}
  template <typename T>
  bool get(T* v) {
    if (left_ < sizeof(T)) return false;
    std::memcpy(v, p_, sizeof(T));
    p_ += sizeof(T);
    left_ -= sizeof(T);
    return true;
  }
  // Checks `count` against the bytes left before allocating.
  template <typename T, typename A>
  bool getArray(uint64_t count, std::vector<T, A>* v) {
    if (count > left_ / sizeof(T)) return false;
    v->resize(size_t(count));
    if (count) std::memcpy(v->data(), p_, size_t(count) * sizeof(T));
    p_ += count * sizeof(T);
    left_ -= count * sizeof(T);
    return true;
  }
  size_t left() const { return left_; }

 private:
  const uint8_t* p_;
  size_t left_;
};

std::vector<uint8_t> finish(Writer& w, uint32_t kind, const BuildOptions& options) {
  const uint64_t payload = w.bytes.size() - kHeaderBytes;
  Writer h;
  h.put(kMagic);
  h.put(kVersion);
  h.put(kind);
  h.put(packOptions(options));
  h.put(payload);
  h.put(checksum(w.bytes.data() + kHeaderBytes, payload));
  std::memcpy(w.bytes.data(), h.bytes.data(), kHeaderBytes);
  return std::move(w.bytes);
}

bool fail(std::string* error, const std::string& message) {
  if (error) *error = "deserialize: " + message;
  return false;
}

std::nullptr_t refuse(std::string* error, const std::string& message) {
  fail(error, message);
  return nullptr;
}

// Checks the header and returns the payload's reader and the build options.
bool openPayload(const uint8_t* data, size_t size, uint32_t kind, Reader* payload, BuildOptions* options,
                 std::string* error) {
  if (!data || size < kHeaderBytes) return fail(error, "truncated (no header)");
  Reader r(data, kHeaderBytes);
  uint32_t magic, version, k, bits;
  uint64_t bytes, sum;
  r.get(&magic), r.get(&version), r.get(&k), r.get(&bits), r.get(&bytes), r.get(&sum);
  if (magic != kMagic) return fail(error, "not a vkrt acceleration structure (bad magic)");
  if (version != kVersion) return fail(error, "format version " + std::to_string(version) + ", expected 1");
  if (k != kind) return fail(error, kind == kKindBlas ? "not a bottom-level structure" : "not a top-level structure");
  if (bits & ~15u) return fail(error, "unknown build options");
  if (bytes != size - kHeaderBytes) return fail(error, "size does not match the header (truncated or padded)");
  if (checksum(data + kHeaderBytes, size - kHeaderBytes) != sum) return fail(error, "checksum mismatch (corrupt)");
  *payload = Reader(data + kHeaderBytes, size - kHeaderBytes);
  *options = unpackOptions(bits);
  return true;
}

struct GeometryHeader {
  uint32_t kind, flags;
  uint64_t floats, indices;
};

bool readGeometries(Reader& r, std::vector<Geometry>* out, std::string* error) {
  uint32_t count, zero;
  if (!r.get(&count) || !r.get(&zero)) return fail(error, "truncated (geometry count)");
  if (count > r.left() / sizeof(GeometryHeader)) return fail(error, "geometry count exceeds the data");
  std::vector<GeometryHeader> headers(count);
  for (GeometryHeader& h : headers) {
    r.get(&h.kind), r.get(&h.flags), r.get(&h.floats), r.get(&h.indices);
    if (h.kind > 1) return fail(error, "unknown geometry kind");
    if (h.kind == 1 && (h.floats % 6 || h.indices)) return fail(error, "malformed box geometry");
    if (h.kind == 0 && (h.floats % 3 || h.indices % 3)) return fail(error, "malformed triangle geometry");
  }
  out->resize(count);
  for (uint32_t i = 0; i < count; ++i) {
    Geometry& g = (*out)[i];
    const GeometryHeader& h = headers[i];
    bool ok;
    if (h.kind == 0) {
      g.kind = Geometry::Triangles;
      g.triangles.flags = h.flags;
      ok = r.getArray(h.floats, &g.triangles.vertices) && r.getArray(h.indices, &g.triangles.indices);
    } else {
      g.kind = Geometry::Aabbs;
      g.aabbs.flags = h.flags;
      ok = r.getArray(h.floats, &g.aabbs.boxes);
    }
    if (!ok) return fail(error, "truncated (geometry " + std::to_string(i) + " data)");
  }
  if (r.left()) return fail(error, "trailing bytes after the geometries");
  return true;
}

}  // namespace

std::vector<uint8_t> serialize(const Blas& blas) {
  Writer w;
  w.bytes.resize(kHeaderBytes);
  const auto& geometries = blas.geometries();
  w.put(uint32_t(geometries.size()));
  w.put(uint32_t(0));
  for (const Geometry& g : geometries) {
    const bool tri = g.kind == Geometry::Triangles;
    w.put(uint32_t(tri ? 0 : 1));
    w.put(tri ? g.triangles.flags : g.aabbs.flags);
    w.put(uint64_t(tri ? g.triangles.vertices.size() : g.aabbs.boxes.size()));
    w.put(uint64_t(tri ? g.triangles.indices.size() : 0));
  }
  for (const Geometry& g : geometries) {
    if (g.kind == Geometry::Triangles) {
      w.putArray(g.triangles.vertices);
      w.putArray(g.triangles.indices);
    } else {
      w.putArray(g.aabbs.boxes);
    }
  }
  return finish(w, kKindBlas, blas.options());
}

std::vector<uint8_t> serialize(const Tlas& tlas, std::vector<const Blas*>* blasRefs) {
  // One reference per instance (null for an inactive one), so that an application patching the references can
  // give instances that shared a Blas different ones.
  std::vector<const Blas*> refs;
  std::vector<uint32_t> instanceRefs;
  for (const Instance& in : tlas.instances()) {
    instanceRefs.push_back(in.blas ? uint32_t(refs.size()) : kNoBlas);
    refs.push_back(in.blas);
  }
  Writer w;
  w.bytes.resize(kHeaderBytes);
  w.put(uint32_t(tlas.instances().size()));
  w.put(uint32_t(refs.size()));
  for (size_t i = 0; i < tlas.instances().size(); ++i) {
    const Instance& in = tlas.instances()[i];
    for (const auto& row : in.transform)
      for (float v : row) w.put(v);
    w.put(in.customIndex);
    w.put(in.mask);
    w.put(in.sbtOffset);
    w.put(in.flags);
    w.put(instanceRefs[i]);
    w.put(uint32_t(0));
  }
  if (blasRefs) *blasRefs = std::move(refs);
  return finish(w, kKindTlas, tlas.options());
}

bool serializedTopLevel(const uint8_t* data, size_t size) {
  if (size < kHeaderBytes) return false;
  uint32_t magic, kind;
  std::memcpy(&magic, data, 4);
  std::memcpy(&kind, data + 8, 4);
  return magic == kMagic && kind == kKindTlas;
}

std::shared_ptr<Blas> deserializeBlas(const uint8_t* data, size_t size, std::string* error) {
  Reader r(nullptr, 0);
  BuildOptions options;
  if (!openPayload(data, size, kKindBlas, &r, &options, error)) return nullptr;
  std::vector<Geometry> geometries;
  if (!readGeometries(r, &geometries, error)) return nullptr;
  return Blas::build(std::move(geometries), options, error);
}

std::shared_ptr<Tlas> deserializeTlas(const uint8_t* data, size_t size,
                                      const std::vector<std::shared_ptr<const Blas>>& blasRefs, std::string* error) {
  Reader r(nullptr, 0);
  BuildOptions options;
  if (!openPayload(data, size, kKindTlas, &r, &options, error)) return nullptr;
  uint32_t count, refCount;
  if (!r.get(&count) || !r.get(&refCount)) return refuse(error, "truncated (instance count)");
  if (refCount != blasRefs.size())
    return refuse(error, "the data references " + std::to_string(refCount) + " bottom-level structures, " +
                             std::to_string(blasRefs.size()) + " given");
  constexpr size_t kInstanceBytes = 72;
  if (r.left() != size_t(count) * kInstanceBytes) return refuse(error, "instance count does not match the data");
  std::vector<Instance> instances(count);
  for (uint32_t i = 0; i < count; ++i) {
    Instance& in = instances[i];
    for (auto& row : in.transform)
      for (float& v : row) r.get(&v);
    uint32_t ref = kNoBlas, zero = 0;  // (read below: the size check above leaves no get short)
    r.get(&in.customIndex), r.get(&in.mask), r.get(&in.sbtOffset), r.get(&in.flags), r.get(&ref), r.get(&zero);
    if (ref == kNoBlas) continue;
    if (ref >= blasRefs.size())
      return refuse(error, "instance " + std::to_string(i) + " references a missing structure");
    in.blas = blasRefs[ref].get();  // null (a structure the runtime could not resolve): inactive
  }
  return Tlas::build(std::move(instances), options, error);
}

}  // namespace vkrt::accel
