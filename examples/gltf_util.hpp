// glTF 2.0 helpers shared by the path tracer (examples/pathtracer.cpp) and the trace benchmark
// (bench/tracebench.cpp): loading a file with Debian's tinygltf, reading accessors, node transforms. Errors end the
// program through example::fail.
#pragma once

#include <tiny_gltf.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstring>
#include <string>

#include "example_fail.hpp"

namespace gltf {

using example::fail;

// Loads a .glb or .gltf file.
inline tinygltf::Model load(const std::string& path) {
  tinygltf::Model model;
  tinygltf::TinyGLTF loader;
  std::string err, warn;
  const bool binary = path.size() >= 4 && path.compare(path.size() - 4, 4, ".glb") == 0;
  const bool ok = binary ? loader.LoadBinaryFromFile(&model, &err, &warn, path)
                         : loader.LoadASCIIFromFile(&model, &err, &warn, path);
  if (!warn.empty()) std::fprintf(stderr, "%s: tinygltf: %s\n", example::gProgram, warn.c_str());
  if (!ok) fail("cannot load " + path + ": " + err);
  return model;
}

// An accessor's element `i`, component `c`, as a float (normalized integers mapped to 0..1).
inline float readComponent(const tinygltf::Model& m, const tinygltf::Accessor& a, size_t i, int c) {
  const tinygltf::BufferView& view = m.bufferViews.at(size_t(a.bufferView));
  const tinygltf::Buffer& buf = m.buffers.at(size_t(view.buffer));
  const int componentSize = tinygltf::GetComponentSizeInBytes(uint32_t(a.componentType));
  const int components = tinygltf::GetNumComponentsInType(uint32_t(a.type));
  const size_t stride = view.byteStride ? view.byteStride : size_t(componentSize * components);
  const size_t at = view.byteOffset + a.byteOffset + i * stride + size_t(c * componentSize);
  if (at + size_t(componentSize) > buf.data.size()) fail("a glTF accessor reads past its buffer");
  const unsigned char* p = buf.data.data() + at;
  switch (a.componentType) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: {
      float f;
      std::memcpy(&f, p, 4);
      return f;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return a.normalized ? p[0] / 255.0f : p[0];
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return a.normalized ? v / 65535.0f : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
      uint32_t v;
      std::memcpy(&v, p, 4);
      return float(v);
    }
    default: fail("a glTF accessor has a component type this loader does not read");
  }
}

inline uint32_t readIndex(const tinygltf::Model& m, const tinygltf::Accessor& a, size_t i) {
  const tinygltf::BufferView& view = m.bufferViews.at(size_t(a.bufferView));
  const tinygltf::Buffer& buf = m.buffers.at(size_t(view.buffer));
  const int size = tinygltf::GetComponentSizeInBytes(uint32_t(a.componentType));
  const size_t stride = view.byteStride ? view.byteStride : size_t(size);
  const size_t at = view.byteOffset + a.byteOffset + i * stride;
  if (size <= 0 || at + size_t(size) > buf.data.size()) fail("a glTF index accessor reads past its buffer");
  uint32_t v = 0;
  std::memcpy(&v, buf.data.data() + at, size_t(size));  // little-endian
  return size == 1 ? (v & 0xff) : size == 2 ? (v & 0xffff) : v;
}

// Column-major 4x4 (glTF) products.
using Mat4 = std::array<double, 16>;
inline Mat4 mul(const Mat4& a, const Mat4& b) {
  Mat4 r{};
  for (int c = 0; c < 4; ++c)
    for (int row = 0; row < 4; ++row)
      for (int k = 0; k < 4; ++k) r[c * 4 + row] += a[k * 4 + row] * b[c * 4 + k];
  return r;
}
inline Mat4 nodeMatrix(const tinygltf::Node& n) {
  Mat4 m{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  if (n.matrix.size() == 16) {
    std::copy(n.matrix.begin(), n.matrix.end(), m.begin());
    return m;
  }
  Mat4 t = m, r = m, s = m;
  if (n.translation.size() == 3) t[12] = n.translation[0], t[13] = n.translation[1], t[14] = n.translation[2];
  if (n.rotation.size() == 4) {
    const double x = n.rotation[0], y = n.rotation[1], z = n.rotation[2], w = n.rotation[3];
    r = {1 - 2 * (y * y + z * z),
         2 * (x * y + z * w),
         2 * (x * z - y * w),
         0,
         2 * (x * y - z * w),
         1 - 2 * (x * x + z * z),
         2 * (y * z + x * w),
         0,
         2 * (x * z + y * w),
         2 * (y * z - x * w),
         1 - 2 * (x * x + y * y),
         0,
         0,
         0,
         0,
         1};
  }
  if (n.scale.size() == 3) s[0] = n.scale[0], s[5] = n.scale[1], s[10] = n.scale[2];
  return mul(t, mul(r, s));
}

}  // namespace gltf
