// The serialized form of a structure: its inputs and build options (a deserialized structure is built again from
// them; the hierarchy itself is Embree's and not portable). Little-endian, versioned, read with bounds checks:
// damaged or foreign data is refused with a message.
//
//   "vkrtAS\0\0" (8 bytes) | u32 version | u32 kind (0 bottom, 1 top) | u32 options bits | u32 count
//   bottom: per geometry: u32 kind, u32 flags, u64 float count, [u64 index count], floats, [u32 indices]
//   top:    per instance: 12 floats (rows), u32 custom index, u32 mask, u32 SBT offset, u32 flags,
//           u32 bottom-level reference (index into the reference list, or 0xffffffff for none)
#include <cstring>

#include "accel/accel.hpp"

namespace vkrt::accel {

namespace {

constexpr char kMagic[8] = {'v', 'k', 'r', 't', 'A', 'S', 0, 0};
constexpr uint32_t kVersion = 1;
constexpr uint32_t kNoReference = 0xffffffffu;

class Writer {
 public:
  template <class T>
  void put(const T& v) {
    const auto* p = reinterpret_cast<const uint8_t*>(&v);
    out.insert(out.end(), p, p + sizeof(T));
  }
  void bytes(const void* p, size_t n) {
    const auto* b = static_cast<const uint8_t*>(p);
    out.insert(out.end(), b, b + n);
  }
  std::vector<uint8_t> out;
};

class Reader {
 public:
  Reader(const uint8_t* data, size_t size) : p_(data), end_(data + size) {}
  template <class T>
  bool get(T* v) {
    if (size_t(end_ - p_) < sizeof(T)) return false;
    std::memcpy(v, p_, sizeof(T));
    p_ += sizeof(T);
    return true;
  }
  template <class T>
  bool array(std::vector<T>* v, uint64_t count) {
    if (count > size_t(end_ - p_) / sizeof(T)) return false;
    v->resize(count);
    std::memcpy(v->data(), p_, count * sizeof(T));
    p_ += count * sizeof(T);
    return true;
  }
  bool done() const { return p_ == end_; }

 private:
  const uint8_t* p_;
  const uint8_t* end_;
};

uint32_t optionBits(const BuildOptions& o) {
  return (o.preferFastTrace ? 1u : 0) | (o.preferFastBuild ? 2u : 0) | (o.allowUpdate ? 4u : 0) |
         (o.lowMemory ? 8u : 0);
}
BuildOptions optionsOf(uint32_t bits) {
  BuildOptions o;
  o.preferFastTrace = bits & 1;
  o.preferFastBuild = bits & 2;
  o.allowUpdate = bits & 4;
  o.lowMemory = bits & 8;
  return o;
}

void header(Writer& w, uint32_t kind, const BuildOptions& o, uint32_t count) {
  w.bytes(kMagic, sizeof kMagic);
  w.put(kVersion);
  w.put(kind);
  w.put(optionBits(o));
  w.put(count);
}

bool readHeader(Reader& r, uint32_t kind, BuildOptions* o, uint32_t* count, std::string* error) {
  char magic[8];
  uint32_t version = 0, k = 0, bits = 0;
  if (!r.get(&magic) || std::memcmp(magic, kMagic, sizeof kMagic) != 0) {
    *error = "not vkrt acceleration structure data (wrong magic)";
    return false;
  }
  if (!r.get(&version) || version != kVersion) {
    *error = "vkrt acceleration structure data of format version " + std::to_string(version) + ", not " +
             std::to_string(kVersion);
    return false;
  }
  if (!r.get(&k) || k != kind) {
    *error = k == 0 ? "a bottom-level structure, not a top-level one" : "a top-level structure, not a bottom-level one";
    return false;
  }
  if (!r.get(&bits) || !r.get(count)) {
    *error = "truncated header";
    return false;
  }
  *o = optionsOf(bits);
  return true;
}

}  // namespace

std::vector<uint8_t> serialize(const Blas& blas) {
  Writer w;
  const std::vector<Geometry>& gs = blas.geometries();
  header(w, 0, blas.options(), uint32_t(gs.size()));
  for (const Geometry& g : gs) {
    w.put(uint32_t(g.kind));
    if (g.kind == Geometry::Triangles) {
      w.put(g.triangles.flags);
      w.put(uint64_t(g.triangles.vertices.size()));
      w.put(uint64_t(g.triangles.indices.size()));
      w.bytes(g.triangles.vertices.data(), g.triangles.vertices.size() * sizeof(float));
      w.bytes(g.triangles.indices.data(), g.triangles.indices.size() * sizeof(uint32_t));
    } else {
      w.put(g.aabbs.flags);
      w.put(uint64_t(g.aabbs.boxes.size()));
      w.bytes(g.aabbs.boxes.data(), g.aabbs.boxes.size() * sizeof(float));
    }
  }
  return std::move(w.out);
}

std::vector<uint8_t> serialize(const Tlas& tlas, std::vector<const Blas*>* blasRefs) {
  Writer w;
  const std::vector<Instance>& is = tlas.instances();
  header(w, 1, tlas.options(), uint32_t(is.size()));
  blasRefs->clear();
  for (const Instance& in : is) {
    w.bytes(in.transform, sizeof in.transform);
    w.put(in.customIndex);
    w.put(in.mask);
    w.put(in.sbtOffset);
    w.put(in.flags);
    uint32_t ref = kNoReference;
    if (in.blas) {
      for (uint32_t k = 0; k < blasRefs->size(); ++k)
        if ((*blasRefs)[k] == in.blas.get()) ref = k;
      if (ref == kNoReference) {
        ref = uint32_t(blasRefs->size());
        blasRefs->push_back(in.blas.get());
      }
    }
    w.put(ref);
  }
  return std::move(w.out);
}

bool serializedTopLevel(const uint8_t* data, size_t size) {
  uint32_t kind = 0;
  if (size < sizeof kMagic + 8 || std::memcmp(data, kMagic, sizeof kMagic) != 0) return false;
  std::memcpy(&kind, data + sizeof kMagic + 4, 4);
  return kind == 1;
}

std::shared_ptr<Blas> deserializeBlas(const uint8_t* data, size_t size, std::string* error) {
  Reader r(data, size);
  BuildOptions options;
  uint32_t count = 0;
  if (!readHeader(r, 0, &options, &count, error)) return nullptr;
  std::vector<Geometry> gs;
  for (uint32_t i = 0; i < count; ++i) {
    uint32_t kind = 0;
    Geometry g;
    uint64_t n = 0;
    bool ok = r.get(&kind) && kind <= 1;
    if (ok && kind == 0) {
      uint64_t indices = 0;
      ok = r.get(&g.triangles.flags) && r.get(&n) && r.get(&indices) && r.array(&g.triangles.vertices, n) &&
           r.array(&g.triangles.indices, indices);
    } else if (ok) {
      g.kind = Geometry::Aabbs;
      ok = r.get(&g.aabbs.flags) && r.get(&n) && r.array(&g.aabbs.boxes, n);
    }
    if (!ok) {
      *error = "geometry " + std::to_string(i) + " is truncated or malformed";
      return nullptr;
    }
    gs.push_back(std::move(g));
  }
  if (!r.done()) {
    *error = "trailing bytes after the last geometry";
    return nullptr;
  }
  return Blas::build(std::move(gs), options, error);
}

std::shared_ptr<Tlas> deserializeTlas(const uint8_t* data, size_t size,
                                      const std::vector<std::shared_ptr<const Blas>>& blasRefs, std::string* error) {
  Reader r(data, size);
  BuildOptions options;
  uint32_t count = 0;
  if (!readHeader(r, 1, &options, &count, error)) return nullptr;
  std::vector<Instance> is;
  for (uint32_t i = 0; i < count; ++i) {
    Instance in;
    uint32_t ref = 0;
    if (!r.get(&in.transform) || !r.get(&in.customIndex) || !r.get(&in.mask) || !r.get(&in.sbtOffset) ||
        !r.get(&in.flags) || !r.get(&ref)) {
      *error = "instance " + std::to_string(i) + " is truncated";
      return nullptr;
    }
    if (ref != kNoReference) {
      if (ref >= blasRefs.size()) {
        *error = "instance " + std::to_string(i) + " refers to bottom-level structure " + std::to_string(ref) + " of " +
                 std::to_string(blasRefs.size());
        return nullptr;
      }
      in.blas = blasRefs[ref];
    }
    is.push_back(std::move(in));
  }
  if (!r.done()) {
    *error = "trailing bytes after the last instance";
    return nullptr;
  }
  return Tlas::build(std::move(is), options, error);
}

}  // namespace vkrt::accel
