// Clipping, the viewport transform, face determination and culling, and the fixed-point setup of triangles, lines
// and points (Vulkan spec: "Fixed-Function Vertex Post-Processing" (Primitive Clipping, Coordinate
// Transformations, Controlling the Viewport) and "Rasterization" (Points, Line Segments, Polygons, Depth Bias)).
#include <algorithm>
#include <cmath>

#include "raster/internal.hpp"

namespace vkrt::raster::detail {
namespace {

// Clip planes: w >= kMinW (so that no vertex with w <= 0 reaches the division), the depth planes 0 <= z_c <= w_c,
// the guard band on x and y, then the user clip distances.
enum : uint32_t { kPlaneW, kPlaneNear, kPlaneFar, kPlaneXMax, kPlaneXMin, kPlaneYMax, kPlaneYMin, kFixedPlanes };
constexpr uint32_t kMaxPlanes = kFixedPlanes + kMaxClipDistances;
constexpr uint32_t kMaxPolygon = 3 + kMaxPlanes;
constexpr float kMinW = 1e-29f;
constexpr float kMaxCoordinate = 1 << 17;  // framebuffer coordinates past the guard band (and points/lines on it)

struct ClipVert {
  float pos[4];
  float d[kMaxPlanes];
  const uint32_t* var;
};

struct ScreenVert {
  float x, y, z, invW;
  const uint32_t* var;
};

void planeDistances(const DrawContext& ctx, const ShadedVertex& v, ClipVert& out) {
  const float x = v.position[0], y = v.position[1], z = v.position[2], w = v.position[3];
  for (int i = 0; i < 4; ++i) out.pos[i] = v.position[i];
  out.d[kPlaneW] = w - kMinW;
  out.d[kPlaneNear] = z;
  out.d[kPlaneFar] = w - z;
  out.d[kPlaneXMax] = ctx.guardX * w - x;
  out.d[kPlaneXMin] = ctx.guardX * w + x;
  out.d[kPlaneYMax] = ctx.guardY * w - y;
  out.d[kPlaneYMin] = ctx.guardY * w + y;
  for (uint32_t i = 0; i < ctx.vertex->clipDistanceCount; ++i) out.d[kFixedPlanes + i] = v.clipDistance[i];
  out.var = v.varyings;
}

uint32_t activePlanes(const DrawContext& ctx) {
  uint32_t planes = (1u << kPlaneW) | (1u << kPlaneXMax) | (1u << kPlaneXMin) | (1u << kPlaneYMax) | (1u << kPlaneYMin);
  if (ctx.state->depthClipEnable || !ctx.state->depthClamp) planes |= (1u << kPlaneNear) | (1u << kPlaneFar);
  for (uint32_t i = 0; i < ctx.vertex->clipDistanceCount; ++i) planes |= 1u << (kFixedPlanes + i);
  return planes;
}

// Outside a plane: negative, or NaN (a NaN position never reaches setup).
uint32_t outcode(const ClipVert& v, uint32_t planes) {
  uint32_t code = 0;
  for (uint32_t p = planes; p; p &= p - 1) {
    const uint32_t i = std::countr_zero(p);
    if (!(v.d[i] >= 0)) code |= 1u << i;
  }
  return code;
}

// The vertex at parameter t from `in` (inside) towards `out`: position, distances and varyings linear in clip space,
// except NoPerspective inputs, which are linear in screen space ("Primitive Clipping").
void intersect(const DrawContext& ctx, const ClipVert& in, const ClipVert& out, float t, ClipVert& r, Arena& arena) {
  for (int i = 0; i < 4; ++i) r.pos[i] = in.pos[i] + t * (out.pos[i] - in.pos[i]);
  for (uint32_t i = 0; i < kMaxPlanes; ++i) r.d[i] = in.d[i] + t * (out.d[i] - in.d[i]);
  const uint32_t words = ctx.varyingWords;
  if (!words) {
    r.var = nullptr;
    return;
  }
  uint32_t* var = arena.alloc(words);
  const float wIn = in.pos[3], wOut = out.pos[3];
  const float denom = (1 - t) * wIn + t * wOut;
  const float s = denom != 0 ? t * wOut / denom : t;
  for (uint32_t slot = 0; slot < ctx.fragment->inputCount; ++slot) {
    const float u = ctx.fragment->inputs[slot].interpolation == Interpolation::NoPerspective ? s : t;
    for (uint32_t c = 0; c < 4; ++c) {
      const uint32_t k = slot * 4 + c;
      if (ctx.fragment->inputs[slot].interpolation == Interpolation::Flat) {
        var[k] = in.var[k];
      } else {
        const float a = asFloat(in.var[k]), b = asFloat(out.var[k]);
        var[k] = asWord(a + u * (b - a));
      }
    }
  }
  r.var = var;
}

// Sutherland-Hodgman against every plane in `planes`; returns the vertex count of the result (in `poly`).
uint32_t clipPolygon(const DrawContext& ctx, ClipVert* poly, uint32_t n, uint32_t planes, Arena& arena) {
  ClipVert tmp[kMaxPolygon];
  for (uint32_t p = planes; p && n; p &= p - 1) {
    const uint32_t plane = std::countr_zero(p);
    uint32_t m = 0;
    for (uint32_t i = 0; i < n; ++i) {
      const ClipVert& a = poly[i];
      const ClipVert& b = poly[(i + 1) % n];
      const float da = a.d[plane], db = b.d[plane];
      const bool aIn = da >= 0, bIn = db >= 0;
      if (aIn && m < kMaxPolygon) tmp[m++] = a;
      if (aIn != bIn && m < kMaxPolygon) {
        // Always from the inside vertex, so that an edge shared by two primitives is cut at the same point.
        if (aIn) {
          intersect(ctx, a, b, da / (da - db), tmp[m++], arena);
        } else {
          intersect(ctx, b, a, db / (db - da), tmp[m++], arena);
        }
      }
    }
    n = m;
    std::copy(tmp, tmp + n, poly);
  }
  return n;
}

ScreenVert toScreen(const DrawContext& ctx, const ClipVert& v) {
  ScreenVert s;
  s.invW = 1.0f / v.pos[3];
  s.x = v.pos[0] * s.invW * ctx.scaleX + ctx.offX;
  s.y = v.pos[1] * s.invW * ctx.scaleY + ctx.offY;
  s.z = v.pos[2] * s.invW * ctx.scaleZ + ctx.offZ;
  s.var = v.var;
  return s;
}

// Depth bias ("Depth Bias"): o = m * slopeFactor + r * constantFactor, clamped; m the maximum depth slope.
double depthBias(const DrawContext& ctx, double zA, double zB, const float* z, uint32_t n) {
  const State& st = *ctx.state;
  const double m = std::max(std::fabs(zA), std::fabs(zB));
  double r = ctx.depthR;
  if (r == 0) {
    // Floating-point depth: r = 2^(e - 23), e the largest exponent of the primitive's depths.
    float maxZ = 0;
    for (uint32_t i = 0; i < n; ++i) maxZ = std::max(maxZ, std::fabs(z[i]));
    int e = 0;
    std::frexp(maxZ, &e);  // maxZ = f * 2^e, f in [0.5, 1): the IEEE exponent is e - 1
    r = maxZ > 0 ? std::ldexp(1.0, e - 1 - 23) : std::ldexp(1.0, -149);
  }
  double o = m * st.depthBiasSlope + r * st.depthBiasConstant;
  if (st.depthBiasClamp > 0) o = std::min(o, double(st.depthBiasClamp));
  if (st.depthBiasClamp < 0) o = std::max(o, double(st.depthBiasClamp));
  return o;
}

int64_t floorDiv(int64_t v, int64_t d) { return v >= 0 ? v / d : -((-v + d - 1) / d); }

// Snaps a triangle to fixed point and appends it; kind: 0 polygon (depth bias applies), 1 line, 2 point.
void emitTriangle(const DrawContext& ctx, const ScreenVert* const in[3], bool front, const uint32_t* flat,
                  uint32_t primitiveId, int kind, std::vector<SetupTri>& out) {
  const ScreenVert* v[3] = {in[0], in[1], in[2]};
  int64_t X[3], Y[3];
  for (int i = 0; i < 3; ++i) {
    // NaN or runaway coordinates (a NaN position got through clipping's comparisons): not rasterized.
    if (!(std::fabs(v[i]->x) <= kMaxCoordinate && std::fabs(v[i]->y) <= kMaxCoordinate)) return;
  }
  for (int i = 0; i < 3; ++i) {
    X[i] = std::llrint(double(v[i]->x) * kSubPixel);
    Y[i] = std::llrint(double(v[i]->y) * kSubPixel);
  }
  int64_t area2 = (X[2] - X[1]) * (Y[0] - Y[1]) - (Y[2] - Y[1]) * (X[0] - X[1]);
  if (area2 == 0) return;
  if (area2 < 0) {  // orient so that the inside is positive for every edge
    std::swap(v[1], v[2]);
    std::swap(X[1], X[2]);
    std::swap(Y[1], Y[2]);
    area2 = -area2;
  }
  SetupTri t;
  int64_t minX = X[0], maxX = X[0], minY = Y[0], maxY = Y[0];
  for (int i = 0; i < 3; ++i) {
    minX = std::min(minX, X[i]), maxX = std::max(maxX, X[i]);
    minY = std::min(minY, Y[i]), maxY = std::max(maxY, Y[i]);
  }
  t.minX = int32_t(std::max<int64_t>(floorDiv(minX, kSubPixel), ctx.clipX0));
  t.minY = int32_t(std::max<int64_t>(floorDiv(minY, kSubPixel), ctx.clipY0));
  t.maxX = int32_t(std::min<int64_t>(floorDiv(maxX, kSubPixel), ctx.clipX1 - 1));
  t.maxY = int32_t(std::min<int64_t>(floorDiv(maxY, kSubPixel), ctx.clipY1 - 1));
  if (t.minX > t.maxX || t.minY > t.maxY) return;
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3, k = (i + 2) % 3;
    const int64_t dx = X[k] - X[j], dy = Y[k] - Y[j];
    t.a[i] = -dy;
    t.b[i] = dx;
    t.c[i] = dy * X[j] - dx * Y[j];
    // Top-left rule with y pointing down: a left edge has the inside to its right (dy < 0 when walked with the
    // inside positive); a top edge is horizontal with the inside below it (dx > 0).
    const bool topLeft = dy < 0 || (dy == 0 && dx > 0);
    t.cBias[i] = topLeft ? 0 : -1;
    t.invW[i] = v[i]->invW;
    t.var[i] = v[i]->var;
  }
  t.area2 = area2;
  const double inv = 1.0 / double(area2);
  t.invArea2 = inv;
  double zA = 0, zB = 0, zC = 0;
  for (int i = 0; i < 3; ++i) {
    zA += double(v[i]->z) * double(t.a[i]) * kSubPixel * inv;
    zB += double(v[i]->z) * double(t.b[i]) * kSubPixel * inv;
    zC += double(v[i]->z) * double(t.c[i]) * inv;
  }
  if (kind == 0 && ctx.state->depthBiasEnable) {
    const float z[3] = {v[0]->z, v[1]->z, v[2]->z};
    zC += depthBias(ctx, zA, zB, z, 3);
  }
  t.zA = zA, t.zB = zB, t.zC = zC;
  t.flat = flat;
  t.primitiveId = primitiveId;
  t.front = front;
  t.isPoint = kind == 2;
  t.pointX = t.pointY = t.pointSize = 0;
  out.push_back(t);
}

// Points ("Basic Point Rasterization"): a square of side pointSize centred on the vertex, as two triangles whose
// shared diagonal the top-left rule splits exactly.
void emitPoint(const DrawContext& ctx, const ScreenVert& p, float pointSize, uint32_t primitiveId,
               std::vector<SetupTri>& out) {
  const float size = std::clamp(std::isnan(pointSize) ? 1.0f : pointSize, 1.0f, 64.0f);
  const float h = size / 2;
  ScreenVert c[4] = {p, p, p, p};
  c[0].x -= h, c[0].y -= h;
  c[1].x += h, c[1].y -= h;
  c[2].x += h, c[2].y += h;
  c[3].x -= h, c[3].y += h;
  const ScreenVert* t0[3] = {&c[0], &c[1], &c[2]};
  const ScreenVert* t1[3] = {&c[0], &c[2], &c[3]};
  const size_t first = out.size();
  emitTriangle(ctx, t0, true, p.var, primitiveId, 2, out);
  emitTriangle(ctx, t1, true, p.var, primitiveId, 2, out);
  for (size_t i = first; i < out.size(); ++i) {
    out[i].pointX = p.x;
    out[i].pointY = p.y;
    out[i].pointSize = size;
  }
}

// Lines ("Basic Line Segment Rasterization", non-strict): the parallelogram spanned by the segment and a
// segment of length lineWidth along the minor axis, as two triangles. The corners carry the values the segment
// has at their projection t onto it (linear in screen space for z, 1/w and NoPerspective inputs; Smooth inputs as
// f/w over 1/w), so that interpolation over the parallelogram is the segment's.
void emitLine(const DrawContext& ctx, const ScreenVert& a, const ScreenVert& b, const uint32_t* flat, bool front,
              uint32_t primitiveId, std::vector<SetupTri>& out, Arena& arena) {
  const float dx = b.x - a.x, dy = b.y - a.y;
  const float len2 = dx * dx + dy * dy;
  if (!(len2 > 0)) return;
  const float hw = std::max(ctx.state->lineWidth, 1.0f) / 2;
  const bool xMajor = std::fabs(dx) >= std::fabs(dy);
  const float ox = xMajor ? 0 : hw, oy = xMajor ? hw : 0;
  const float cx[4] = {a.x - ox, a.x + ox, b.x + ox, b.x - ox};
  const float cy[4] = {a.y - oy, a.y + oy, b.y + oy, b.y - oy};
  ScreenVert c[4];
  for (int i = 0; i < 4; ++i) {
    const float t = ((cx[i] - a.x) * dx + (cy[i] - a.y) * dy) / len2;
    ScreenVert& s = c[i];
    s.x = cx[i], s.y = cy[i];
    s.z = a.z + t * (b.z - a.z);
    s.invW = a.invW + t * (b.invW - a.invW);
    s.var = nullptr;
    if (!ctx.varyingWords) continue;
    uint32_t* var = arena.alloc(ctx.varyingWords);
    for (uint32_t slot = 0; slot < ctx.fragment->inputCount; ++slot) {
      const Interpolation mode = ctx.fragment->inputs[slot].interpolation;
      for (uint32_t k = slot * 4; k < slot * 4 + 4; ++k) {
        const float fa = asFloat(a.var[k]), fb = asFloat(b.var[k]);
        if (mode == Interpolation::Flat) {
          var[k] = a.var[k];
        } else if (mode == Interpolation::NoPerspective) {
          var[k] = asWord(fa + t * (fb - fa));
        } else {
          const float num = fa * a.invW + t * (fb * b.invW - fa * a.invW);
          var[k] = asWord(s.invW != 0 ? num / s.invW : fa);
        }
      }
    }
    s.var = var;
  }
  const ScreenVert* t0[3] = {&c[0], &c[1], &c[2]};
  const ScreenVert* t1[3] = {&c[0], &c[2], &c[3]};
  emitTriangle(ctx, t0, front, flat, primitiveId, 1, out);
  emitTriangle(ctx, t1, front, flat, primitiveId, 1, out);
}

// Cull distances ("Clip and Cull Distances"): dropped when every vertex is negative for the same distance.
bool culledByDistance(const DrawContext& ctx, const AssembledPrim& prim) {
  const uint32_t first = ctx.vertex->clipDistanceCount;
  for (uint32_t i = first; i < first + ctx.vertex->cullDistanceCount; ++i) {
    bool all = true;
    for (uint32_t k = 0; k < prim.count; ++k) all = all && prim.v[k]->clipDistance[i] < 0;
    if (all) return true;
  }
  return false;
}

void setupPointPrim(const DrawContext& ctx, const AssembledPrim& prim, std::vector<SetupTri>& out) {
  // A point is kept when its vertex is inside the clip volume (x and y included) and every clip distance.
  const ShadedVertex& v = *prim.v[0];
  const float x = v.position[0], y = v.position[1], z = v.position[2], w = v.position[3];
  if (!(w > 0) || !(x >= -w && x <= w && y >= -w && y <= w)) return;
  if ((ctx.state->depthClipEnable || !ctx.state->depthClamp) && !(z >= 0 && z <= w)) return;
  for (uint32_t i = 0; i < ctx.vertex->clipDistanceCount; ++i) {
    if (!(v.clipDistance[i] >= 0)) return;
  }
  ClipVert cv;
  planeDistances(ctx, v, cv);
  emitPoint(ctx, toScreen(ctx, cv), v.pointSize, prim.primitiveId, out);
}

void setupLinePrim(const DrawContext& ctx, const AssembledPrim& prim, std::vector<SetupTri>& out, Arena& arena) {
  ClipVert a, b;
  planeDistances(ctx, *prim.v[0], a);
  planeDistances(ctx, *prim.v[1], b);
  const uint32_t planes = activePlanes(ctx);
  const uint32_t ca = outcode(a, planes), cb = outcode(b, planes);
  if (ca & cb) return;
  if (ca | cb) {
    float t0 = 0, t1 = 1;
    for (uint32_t p = ca | cb; p; p &= p - 1) {
      const uint32_t i = std::countr_zero(p);
      const float da = a.d[i], db = b.d[i];
      if (!(da >= 0) && !(db >= 0)) return;
      if (!(da >= 0)) t0 = std::max(t0, da / (da - db));
      if (!(db >= 0)) t1 = std::min(t1, da / (da - db));
    }
    if (!(t0 < t1)) return;
    ClipVert na = a, nb = b;
    if (t0 > 0) intersect(ctx, b, a, 1 - t0, na, arena);
    if (t1 < 1) intersect(ctx, a, b, t1, nb, arena);
    a = na, b = nb;
  }
  const uint32_t* flat = prim.v[prim.provoking]->varyings;
  emitLine(ctx, toScreen(ctx, a), toScreen(ctx, b), flat, true, prim.primitiveId, out, arena);
}

void setupTrianglePrim(const DrawContext& ctx, const AssembledPrim& prim, std::vector<SetupTri>& out, Arena& arena) {
  ClipVert poly[kMaxPolygon];
  const uint32_t planes = activePlanes(ctx);
  uint32_t codes[3], all = ~0u, any = 0;
  for (int i = 0; i < 3; ++i) {
    planeDistances(ctx, *prim.v[i], poly[i]);
    codes[i] = outcode(poly[i], planes);
    all &= codes[i];
    any |= codes[i];
  }
  if (all) return;
  const uint32_t n = any ? clipPolygon(ctx, poly, 3, any, arena) : 3;
  if (n < 3) return;
  ScreenVert s[kMaxPolygon];
  for (uint32_t i = 0; i < n; ++i) s[i] = toScreen(ctx, poly[i]);
  // Face determination ("Basic Polygon Rasterization"): a = -1/2 sum(x_i y_(i+1) - x_(i+1) y_i) in framebuffer
  // coordinates; positive is counter-clockwise.
  double sum = 0;
  for (uint32_t i = 0; i < n; ++i) {
    const ScreenVert& p = s[i];
    const ScreenVert& q = s[(i + 1) % n];
    sum += double(p.x) * q.y - double(q.x) * p.y;
  }
  const double area = -0.5 * sum;
  if (!(area != 0)) return;
  const bool front = (area > 0) == (ctx.state->frontFace == FrontFace::CounterClockwise);
  if (ctx.state->cullMode & (front ? CullFront : CullBack)) return;
  const uint32_t* flat = prim.v[prim.provoking]->varyings;
  const size_t first = out.size();
  switch (ctx.state->polygonMode) {
    case PolygonMode::Fill:
      for (uint32_t i = 1; i + 1 < n; ++i) {
        const ScreenVert* tri[3] = {&s[0], &s[i], &s[i + 1]};
        emitTriangle(ctx, tri, front, flat, prim.primitiveId, 0, out);
      }
      break;
    case PolygonMode::Line:
      for (uint32_t i = 0; i < n; ++i) emitLine(ctx, s[i], s[(i + 1) % n], flat, front, prim.primitiveId, out, arena);
      break;
    case PolygonMode::Point:
      for (uint32_t i = 0; i < n; ++i) {
        const size_t from = out.size();
        emitPoint(ctx, s[i], 1.0f, prim.primitiveId, out);
        for (size_t k = from; k < out.size(); ++k) out[k].front = front, out[k].flat = flat;
      }
      break;
  }
  // Depth bias applies to polygons in every polygon mode ("Depth Bias"): Line and Point take the slope of the
  // polygon's plane (its first fan triangle, unsnapped).
  if (ctx.state->depthBiasEnable && ctx.state->polygonMode != PolygonMode::Fill && out.size() > first) {
    const double x1 = s[1].x - s[0].x, y1 = s[1].y - s[0].y, z1 = s[1].z - s[0].z;
    const double x2 = s[2].x - s[0].x, y2 = s[2].y - s[0].y, z2 = s[2].z - s[0].z;
    const double det = x1 * y2 - y1 * x2;
    const double dzdx = det != 0 ? (z1 * y2 - z2 * y1) / det : 0, dzdy = det != 0 ? (z2 * x1 - z1 * x2) / det : 0;
    float z[kMaxPolygon];
    for (uint32_t i = 0; i < n; ++i) z[i] = s[i].z;
    const double bias = depthBias(ctx, dzdx, dzdy, z, n);
    for (size_t k = first; k < out.size(); ++k) out[k].zC += bias;
  }
}

}  // namespace

void setupPrimitive(const DrawContext& ctx, const AssembledPrim& prim, std::vector<SetupTri>& out, Arena& arena) {
  if (ctx.vertex->cullDistanceCount && culledByDistance(ctx, prim)) return;
  switch (prim.count) {
    case 1: setupPointPrim(ctx, prim, out); break;
    case 2: setupLinePrim(ctx, prim, out, arena); break;
    default: setupTrianglePrim(ctx, prim, out, arena); break;
  }
}

}  // namespace vkrt::raster::detail
