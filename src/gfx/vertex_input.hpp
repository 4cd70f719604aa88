// Vertex input (the "Vertex Input Description" chapter): the conversion of every vertex buffer format vkrt supports
// to the four 32-bit words a vertex shader input reads (abi/abi.hpp: floats for normalized, scaled and float
// formats, integers for integer ones; missing components G = B = 0, A = 1), and the fetch of a vertex's attributes
// from the bound vertex buffers. No allocation, lock or lookup: called per vertex.
#pragma once

#include <cstdint>

#include "runtime/vk.hpp"

namespace vkrt::gfx {

enum class VertexNumeric : uint8_t { UNorm, SNorm, UScaled, SScaled, UInt, SInt, SFloat };

// How a format's bytes hold its components.
enum class VertexLayout : uint8_t {
  Plain,        // components in R, G, B, A order, each bits/8 bytes, little-endian
  Bgra,         // B, G, R(, A) in memory (B8G8R8, B8G8R8A8)
  A8B8G8R8,     // one 32-bit word: R bits 0-7, G 8-15, B 16-23, A 24-31
  A2R10G10B10,  // one 32-bit word: B bits 0-9, G 10-19, R 20-29, A 30-31
  A2B10G10R10,  // one 32-bit word: R bits 0-9, G 10-19, B 20-29, A 30-31
};

struct VertexFormat {
  VkFormat format = VK_FORMAT_UNDEFINED;
  uint8_t bytes = 0;       // the attribute's size in the buffer
  uint8_t components = 0;  // 1..4
  uint8_t bits = 0;        // bits per component (R's for the packed 10-bit formats; A has 2)
  VertexNumeric numeric = VertexNumeric::UNorm;
  VertexLayout layout = VertexLayout::Plain;
  bool integer() const { return numeric == VertexNumeric::UInt || numeric == VertexNumeric::SInt; }
};

// The description of a vertex buffer format, or null when `format` is not one (vkrt's VERTEX_BUFFER_BIT formats:
// every 8-, 16- and 32-bit per component UNORM, SNORM, USCALED, SSCALED, UINT, SINT and SFLOAT format of one to four
// components, the BGR(A) and packed 8-bit and 10-bit ones; runtime/format.cpp's vertexBufferFormat() lists the same).
// Returns a pointer to a static table entry.
const VertexFormat* vertexFormat(VkFormat format);

// Converts one attribute at `src` (format->bytes readable) to four 32-bit words ("Conversion to Floating-Point" and
// "Fixed-Point Data Conversions": UNORM c / (2^b - 1), SNORM max(c / (2^(b-1) - 1), -1), SCALED the integer's value).
void convertVertexAttribute(const VertexFormat& format, const uint8_t* src, uint32_t out[4]);

// One attribute of a draw, resolved against the bound vertex buffers (at draw execution).
struct AttributeFetch {
  const VertexFormat* format = nullptr;
  uint32_t location = 0;
  const uint8_t* base = nullptr;  // the binding's buffer + bound offset (null: nothing bound, reads zeros)
  uint64_t size = 0;              // bytes readable from base (the bound range)
  uint64_t offset = 0;            // the attribute's offset within a vertex
  uint32_t stride = 0;
  bool perInstance = false;
};

// Writes the attribute of vertex `vertexIndex` / instance `instanceIndex` (InstanceIndex: firstInstance included) to
// inputs[4 * location .. +4]. A fetch whose bytes are not all inside the bound range reads (0, 0, 0, 0) (robust buffer
// access: "Vertex Input Extraction" allows zeros).
void fetchAttribute(const AttributeFetch& a, uint32_t vertexIndex, uint32_t instanceIndex, uint32_t* inputs);

}  // namespace vkrt::gfx
