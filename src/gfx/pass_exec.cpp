#include "gfx/pass_exec.hpp"

#include <algorithm>
#include <cstring>

#include "exec/thread_pool.hpp"
#include "gfx/graphics_state.hpp"
#include "runtime/image.hpp"
#include "runtime/image_copy.hpp"
#include "runtime/image_functions.hpp"
#include "runtime/image_view.hpp"

namespace vkrt::gfx {
namespace {

void decodeColor(const void* format, const uint8_t* texel, uint32_t out[4]) {
  decodeTexel(*static_cast<const FormatInfo*>(format), texel, out);
}

void encodeColor(const void* format, const uint32_t in[4], uint8_t* texel) {
  encodeTexel(*static_cast<const FormatInfo*>(format), in, texel);
}

raster::Surface surfaceOf(const PassAttachment& a) {
  raster::Surface s;
  const MipLayout& m = a.image->mips[a.mip];
  s.base = a.image->data() + m.offset + a.baseLayer * m.arrayPitch;
  s.rowPitch = m.rowPitch;
  s.layerPitch = m.arrayPitch;
  s.width = m.extent.width;
  s.height = m.extent.height;
  s.layers = a.layers;
  s.samples = a.image->samples;
  return s;
}

raster::ColorFormat colorFormatOf(const FormatInfo& f) {
  raster::ColorFormat c;
  switch (f.type) {
    case NumericType::UNorm:
    case NumericType::SRGB: c.kind = raster::ColorFormat::Kind::UNorm; break;
    case NumericType::SNorm: c.kind = raster::ColorFormat::Kind::SNorm; break;
    case NumericType::UInt: c.kind = raster::ColorFormat::Kind::UInt; break;
    case NumericType::SInt: c.kind = raster::ColorFormat::Kind::SInt; break;
    case NumericType::SFloat:
    case NumericType::UFloat: c.kind = raster::ColorFormat::Kind::Float; break;
  }
  c.texelBytes = f.texelSize;
  c.componentMask = uint8_t((1u << f.components) - 1);
  c.format = &f;
  c.decode = decodeColor;
  c.encode = encodeColor;
  if (f.format == VK_FORMAT_R8G8B8A8_UNORM) c.layout = raster::ColorFormat::Layout::RGBA8UNorm;
  if (f.format == VK_FORMAT_B8G8R8A8_UNORM) c.layout = raster::ColorFormat::Layout::BGRA8UNorm;
  if (f.format == VK_FORMAT_R8G8B8A8_SRGB) c.layout = raster::ColorFormat::Layout::RGBA8Srgb;
  if (f.format == VK_FORMAT_B8G8R8A8_SRGB) c.layout = raster::ColorFormat::Layout::BGRA8Srgb;
  c.rgba16Float = f.format == VK_FORMAT_R16G16B16A16_SFLOAT;
  return c;
}

template <class F>
void forEachLayer(uint32_t baseLayer, uint32_t layerCount, uint32_t viewMask, F f) {
  if (viewMask) {
    for (uint32_t m = viewMask; m; m &= m - 1) f(uint32_t(__builtin_ctz(m)));
  } else {
    for (uint32_t l = baseLayer; l < baseLayer + layerCount; ++l) f(l);
  }
}

// `r` clipped to a width x height surface; false if nothing is left.
bool clip(const VkRect2D& r, uint32_t width, uint32_t height, uint32_t* x0, uint32_t* y0, uint32_t* x1, uint32_t* y1) {
  const int64_t ax = std::max<int64_t>(0, r.offset.x), ay = std::max<int64_t>(0, r.offset.y);
  const int64_t bx = std::min<int64_t>(width, int64_t(r.offset.x) + r.extent.width);
  const int64_t by = std::min<int64_t>(height, int64_t(r.offset.y) + r.extent.height);
  if (ax >= bx || ay >= by) return false;
  *x0 = uint32_t(ax), *y0 = uint32_t(ay), *x1 = uint32_t(bx), *y1 = uint32_t(by);
  return true;
}

void clearAttachment(const PassInstance& p, const PassSubpass& sp, const PassClear& c) {
  const PassAttachment& a = p.attachments[c.attachment];
  const raster::Surface s = surfaceOf(a);
  // The view's format: a view of a mutable-format image renders, clears and resolves in its own format ("Image
  // Views": the view's format reinterprets the image's texels), not the image's.
  const FormatInfo& f = *formatInfo(a.format);
  uint8_t texel[16] = {};
  if (c.aspects & VK_IMAGE_ASPECT_COLOR_BIT) {
    encodeTexel(f, c.value.color.uint32, texel);
    fillSurface(s, f.texelSize, 0, f.texelSize, texel, p.renderArea, 0, p.layers, sp.viewMask);
  }
  if (c.aspects & VK_IMAGE_ASPECT_DEPTH_BIT) {
    encodeDepth(a.format, c.value.depthStencil.depth, texel);
    fillSurface(s, f.texelSize, 0, aspectImageBytes(a.format, VK_IMAGE_ASPECT_DEPTH_BIT), texel, p.renderArea, 0,
                p.layers, sp.viewMask);
  }
  if (c.aspects & VK_IMAGE_ASPECT_STENCIL_BIT) {
    const uint32_t at = aspectFormatInfo(a.format, VK_IMAGE_ASPECT_STENCIL_BIT)->offset;
    texel[at] = uint8_t(c.value.depthStencil.stencil);
    fillSurface(s, f.texelSize, at, 1, texel + at, p.renderArea, 0, p.layers, sp.viewMask);
  }
}

void resolve(const PassInstance& p, const PassSubpass& sp, const PassResolve& r) {
  const PassAttachment& src = p.attachments[r.src];
  const PassAttachment& dst = p.attachments[r.dst];
  const raster::Surface s = surfaceOf(src), d = surfaceOf(dst);
  const FormatInfo& sf = *formatInfo(src.format);
  const uint32_t st = sf.texelSize, dt = formatInfo(dst.format)->texelSize;
  uint32_t x0, y0, x1, y1;
  if (!clip(p.renderArea, std::min(s.width, d.width), std::min(s.height, d.height), &x0, &y0, &x1, &y1)) return;
  forEachLayer(0, p.layers, sp.viewMask, [&](uint32_t l) {
    if (l >= s.layers || l >= d.layers) return;
    for (uint32_t y = y0; y < y1; ++y) {
      for (uint32_t x = x0; x < x1; ++x) {
        const uint8_t* from = s.base + l * s.layerPitch + y * s.rowPitch + size_t(x) * s.samples * st;
        uint8_t* to = d.base + l * d.layerPitch + y * d.rowPitch + size_t(x) * dt;
        if (r.aspect == VK_IMAGE_ASPECT_COLOR_BIT)
          resolveColorPixel(sf, from, s.samples, to);
        else
          resolveDepthStencilPixel(src.format, r.aspect, r.mode, from, s.samples, to);
      }
    }
  });
}

}  // namespace

PassAttachment attachmentOf(const ImageView& v) {
  PassAttachment a;
  a.image = v.image;
  a.format = v.format;
  a.mip = v.range.baseMipLevel;
  a.baseLayer = v.range.baseArrayLayer;
  a.layers = v.range.layerCount;
  return a;
}

void fillSurface(const raster::Surface& s, uint32_t texelBytes, uint32_t offset, uint32_t bytes, const uint8_t* texel,
                 const VkRect2D& r, uint32_t baseLayer, uint32_t layerCount, uint32_t viewMask) {
  uint32_t x0, y0, x1, y1;
  if (!clip(r, s.width, s.height, &x0, &y0, &x1, &y1)) return;
  const size_t first = size_t(x0) * s.samples, end = size_t(x1) * s.samples;  // texels of a row
  const bool whole = offset == 0 && bytes == texelBytes;
  forEachLayer(baseLayer, layerCount, viewMask, [&](uint32_t l) {
    if (l >= s.layers) return;
    uint8_t* layer = s.base + l * s.layerPitch;
    // Whole texels: the first row texel by texel, the others copied from it. An aspect of a combined texel (the
    // depth or the stencil bytes of D24S8 / D32S8) texel by texel in every row, keeping the other aspect's bytes.
    auto fillRow = [&](uint8_t* row) {
      for (size_t i = first; i < end; ++i) std::memcpy(row + i * texelBytes + offset, texel, bytes);
    };
    if (whole) fillRow(layer + size_t(y0) * s.rowPitch);
    const uint8_t* pattern = layer + size_t(y0) * s.rowPitch + first * texelBytes;
    const size_t rowBytes = (end - first) * texelBytes;
    auto rows = [&](uint32_t ya, uint32_t yb) {
      for (uint32_t y = ya; y < yb; ++y) {
        uint8_t* row = layer + size_t(y) * s.rowPitch;
        if (whole)
          std::memcpy(row + first * texelBytes, pattern, rowBytes);
        else
          fillRow(row);
      }
    };
    const uint32_t from = whole ? y0 + 1 : y0;
    // Large clears (a 1080p attachment is 8 MB) on every thread of the pool, in bands of rows: one thread's
    // stores are a fraction of the memory bandwidth.
    constexpr size_t kBandBytes = size_t(256) << 10;
    const uint32_t bandRows = uint32_t(std::max<size_t>(1, kBandBytes / std::max<size_t>(rowBytes, 1)));
    const uint32_t bands = (y1 - from + bandRows - 1) / bandRows;
    if (bands <= 1) return rows(from, y1);
    exec::ThreadPool::instance().parallelFor(bands, [&](uint64_t b, unsigned) {
      const uint32_t ya = from + uint32_t(b) * bandRows;
      rows(ya, std::min(y1, ya + bandRows));
    });
  });
}

raster::Target buildTarget(const PassInstance& p, uint32_t si) {
  const PassSubpass& sp = p.subpasses[si];
  raster::Target t;
  t.colorCount = sp.colorCount;
  for (uint32_t c = 0; c < sp.colorCount; ++c) {
    if (sp.color[c] == VK_ATTACHMENT_UNUSED) continue;
    const PassAttachment& a = p.attachments[sp.color[c]];
    t.color[c] = surfaceOf(a);
    t.colorFormat[c] = colorFormatOf(*formatInfo(a.format));
  }
  if (sp.depthStencil != VK_ATTACHMENT_UNUSED) {
    const PassAttachment& a = p.attachments[sp.depthStencil];
    raster::DepthStencilTarget& ds = t.depthStencil;
    const uint32_t texel = a.image->formatInfo->texelSize;
    const VkImageAspectFlags aspects = a.image->aspects;
    if (sp.depth && (aspects & VK_IMAGE_ASPECT_DEPTH_BIT)) {
      ds.depthFormat = a.format == VK_FORMAT_D16_UNORM ? raster::DepthFormat::D16UNorm
                       : a.format == VK_FORMAT_D32_SFLOAT || a.format == VK_FORMAT_D32_SFLOAT_S8_UINT
                           ? raster::DepthFormat::D32SFloat
                           : raster::DepthFormat::X8D24UNorm;
      ds.depth = surfaceOf(a);
      ds.depthTexelBytes = texel;
    }
    if (sp.stencil && (aspects & VK_IMAGE_ASPECT_STENCIL_BIT)) {
      ds.stencilFormat = raster::StencilFormat::S8UInt;
      ds.stencil = surfaceOf(a);
      ds.stencilTexelBytes = texel;
      ds.stencilOffset = aspectFormatInfo(a.format, VK_IMAGE_ASPECT_STENCIL_BIT)->offset;
    }
  }
  t.renderArea = {p.renderArea.offset.x, p.renderArea.offset.y, p.renderArea.extent.width, p.renderArea.extent.height};
  t.samples = sp.samples;
  t.viewMask = sp.viewMask;
  // Views past an attachment's layers render nowhere (the raster writes the layer of each view unchecked). Valid use
  // never has them: VUID-VkFramebufferCreateInfo-renderPass-04536/03198 for render passes; dynamic rendering's views
  // in the attachments' layers is the application's duty ("Dynamic Render Pass Instances"), unchecked here.
  auto keep = [&](const raster::Surface& s) {
    if (s.base && s.layers < 32) t.viewMask &= (1u << s.layers) - 1;
  };
  if (t.viewMask) {
    for (uint32_t c = 0; c < t.colorCount; ++c) keep(t.color[c]);
    keep(t.depthStencil.depth);
    keep(t.depthStencil.stencil);
    if (!t.viewMask) t.renderArea.width = t.renderArea.height = 0;  // no view left: draws cover nothing
  }
  return t;
}

void beginSubpass(ExecState& st, const PassInstance& p, uint32_t s) {
  const PassSubpass& sp = p.subpasses[s];
  for (const PassClear& c : sp.clears) clearAttachment(p, sp, c);
  PassExecState& pass = execState(st).pass;
  pass.active = true;
  pass.target = buildTarget(p, s);
}

void endSubpass(ExecState& st, const PassInstance& p, uint32_t s, bool last) {
  const PassSubpass& sp = p.subpasses[s];
  for (const PassResolve& r : sp.resolves) resolve(p, sp, r);
  if (!last) return;
  PassExecState& pass = execState(st).pass;
  pass.active = false;
  pass.target = {};
  for (const PassAttachment& a : p.attachments)
    if (a.image->presentable && a.finalLayout != VK_IMAGE_LAYOUT_UNDEFINED) a.image->trackedLayout.store(a.finalLayout);
}

}  // namespace vkrt::gfx
