// Dynamic state ("Pipeline Dynamic State"; gfx/draw_state.hpp): the vkCmdSet* commands of Vulkan 1.0 and of the
// extended dynamic state made core in 1.3 (their EXT aliases resolve to the same functions through the entry point
// table), the two VK_EXT_extended_dynamic_state2 commands 1.3 left out (vkCmdSetLogicOpEXT;
// vkCmdSetPatchControlPointsEXT, whose feature vkrt lacks), and resolveState(), which merges them with a pipeline's
// static state at each draw.
#include <cmath>
#include <cstring>
#include <vector>

#include "gfx/graphics_pipeline.hpp"
#include "gfx/graphics_state.hpp"
#include "runtime/device.hpp"
#include "runtime/physical_device.hpp"
#include "runtime/report.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt::gfx {

int dynamicBit(VkDynamicState s) {
  if (s >= VK_DYNAMIC_STATE_VIEWPORT && s <= VK_DYNAMIC_STATE_STENCIL_REFERENCE) return int(s);
  if (s >= VK_DYNAMIC_STATE_CULL_MODE && s <= VK_DYNAMIC_STATE_STENCIL_OP)
    return kDynCullMode + int(s - VK_DYNAMIC_STATE_CULL_MODE);
  switch (s) {
    case VK_DYNAMIC_STATE_RASTERIZER_DISCARD_ENABLE: return kDynRasterizerDiscardEnable;
    case VK_DYNAMIC_STATE_DEPTH_BIAS_ENABLE: return kDynDepthBiasEnable;
    case VK_DYNAMIC_STATE_PRIMITIVE_RESTART_ENABLE: return kDynPrimitiveRestartEnable;
    case VK_DYNAMIC_STATE_LOGIC_OP_EXT: return kDynLogicOp;
    default: return -1;
  }
}

const char* dynamicStateName(uint32_t bit) {
  static const char* const kNames[kDynCount] = {
      "VK_DYNAMIC_STATE_VIEWPORT",
      "VK_DYNAMIC_STATE_SCISSOR",
      "VK_DYNAMIC_STATE_LINE_WIDTH",
      "VK_DYNAMIC_STATE_DEPTH_BIAS",
      "VK_DYNAMIC_STATE_BLEND_CONSTANTS",
      "VK_DYNAMIC_STATE_DEPTH_BOUNDS",
      "VK_DYNAMIC_STATE_STENCIL_COMPARE_MASK",
      "VK_DYNAMIC_STATE_STENCIL_WRITE_MASK",
      "VK_DYNAMIC_STATE_STENCIL_REFERENCE",
      "VK_DYNAMIC_STATE_CULL_MODE",
      "VK_DYNAMIC_STATE_FRONT_FACE",
      "VK_DYNAMIC_STATE_PRIMITIVE_TOPOLOGY",
      "VK_DYNAMIC_STATE_VIEWPORT_WITH_COUNT",
      "VK_DYNAMIC_STATE_SCISSOR_WITH_COUNT",
      "VK_DYNAMIC_STATE_VERTEX_INPUT_BINDING_STRIDE",
      "VK_DYNAMIC_STATE_DEPTH_TEST_ENABLE",
      "VK_DYNAMIC_STATE_DEPTH_WRITE_ENABLE",
      "VK_DYNAMIC_STATE_DEPTH_COMPARE_OP",
      "VK_DYNAMIC_STATE_DEPTH_BOUNDS_TEST_ENABLE",
      "VK_DYNAMIC_STATE_STENCIL_TEST_ENABLE",
      "VK_DYNAMIC_STATE_STENCIL_OP",
      "VK_DYNAMIC_STATE_RASTERIZER_DISCARD_ENABLE",
      "VK_DYNAMIC_STATE_DEPTH_BIAS_ENABLE",
      "VK_DYNAMIC_STATE_PRIMITIVE_RESTART_ENABLE",
      "VK_DYNAMIC_STATE_LOGIC_OP_EXT",
  };
  return bit < kDynCount ? kNames[bit] : "?";
}

void resolveState(const GraphicsPipelineDesc& p, const DrawExecState& dyn, raster::State* out) {
  raster::State& s = *out;
  const raster::State& d = dyn.dynamic;
  s = p.state;
  const uint32_t m = p.dynamicMask;
  auto on = [m](DynBit b) { return (m & (1u << b)) != 0; };
  if (on(kDynViewportWithCount)) s.viewportCount = d.viewportCount;
  if (on(kDynViewport) || on(kDynViewportWithCount))
    std::memcpy(s.viewports, d.viewports, sizeof s.viewports[0] * s.viewportCount);
  if (on(kDynScissor) || on(kDynScissorWithCount)) std::memcpy(s.scissors, d.scissors, sizeof s.scissors);
  if (on(kDynLineWidth)) s.lineWidth = d.lineWidth;
  if (on(kDynDepthBias)) {
    s.depthBiasConstant = d.depthBiasConstant;
    s.depthBiasClamp = d.depthBiasClamp;
    s.depthBiasSlope = d.depthBiasSlope;
  }
  if (on(kDynBlendConstants)) std::memcpy(s.blendConstants, d.blendConstants, sizeof s.blendConstants);
  if (on(kDynDepthBounds)) {
    s.minDepthBounds = d.minDepthBounds;
    s.maxDepthBounds = d.maxDepthBounds;
  }
  if (on(kDynStencilCompareMask)) {
    s.front.compareMask = d.front.compareMask;
    s.back.compareMask = d.back.compareMask;
  }
  if (on(kDynStencilWriteMask)) {
    s.front.writeMask = d.front.writeMask;
    s.back.writeMask = d.back.writeMask;
  }
  if (on(kDynStencilReference)) {
    s.front.reference = d.front.reference;
    s.back.reference = d.back.reference;
  }
  if (on(kDynCullMode)) s.cullMode = d.cullMode;
  if (on(kDynFrontFace)) s.frontFace = d.frontFace;
  if (on(kDynTopology)) s.topology = d.topology;
  if (on(kDynDepthTestEnable)) s.depthTest = d.depthTest;
  if (on(kDynDepthWriteEnable)) s.depthWrite = d.depthWrite;
  if (on(kDynDepthCompareOp)) s.depthCompare = d.depthCompare;
  if (on(kDynDepthBoundsTestEnable)) s.depthBoundsTest = d.depthBoundsTest;
  if (on(kDynStencilTestEnable)) s.stencilTest = d.stencilTest;
  if (on(kDynStencilOp)) {
    for (auto [to, from] : {std::pair{&s.front, &d.front}, std::pair{&s.back, &d.back}}) {
      to->failOp = from->failOp;
      to->passOp = from->passOp;
      to->depthFailOp = from->depthFailOp;
      to->compareOp = from->compareOp;
    }
  }
  if (on(kDynRasterizerDiscardEnable)) s.rasterizerDiscard = d.rasterizerDiscard;
  if (on(kDynDepthBiasEnable)) s.depthBiasEnable = d.depthBiasEnable;
  if (on(kDynPrimitiveRestartEnable)) s.primitiveRestart = d.primitiveRestart;
  if (on(kDynLogicOp)) s.logicOp = d.logicOp;
}

namespace {

using ull = unsigned long long;

// Records a setter: applies `apply` to the executing state and marks `bits` set for the draw-time checks.
template <class F>
void recordSetter(CommandBuffer* cb, uint32_t bits, F&& apply) {
  cb->record([bits, apply = std::forward<F>(apply)](ExecState& st) {
    DrawExecState& d = execState(st).draw;
    apply(d);
    d.dynamicSet |= bits;
  });
}

const VkPhysicalDeviceLimits& limits(const CommandBuffer* cb) {
  return cb->device->physicalDevice->properties10.limits;
}

bool checkScissors(CommandBuffer* cb, const char* fn, uint32_t count, const VkRect2D* rects, const char* xVuid,
                   const char* wVuid, const char* hVuid) {
  for (uint32_t k = 0; k < count; ++k) {
    const VkRect2D& r = rects[k];
    const char* vuid = r.offset.x < 0 || r.offset.y < 0                             ? xVuid
                       : int64_t(r.offset.x) + int64_t(r.extent.width) > INT32_MAX  ? wVuid
                       : int64_t(r.offset.y) + int64_t(r.extent.height) > INT32_MAX ? hVuid
                                                                                    : nullptr;
    if (vuid) {
      report(cb, Severity::Error, vuid,
             "%s: pScissors[%u] = offset (%d, %d), extent %ux%u: offsets must be >= 0 and offset + extent must not "
             "overflow int32",
             fn, k, r.offset.x, r.offset.y, r.extent.width, r.extent.height);
      return false;
    }
  }
  return true;
}

void storeViewports(DrawExecState& d, uint32_t first, const std::vector<VkViewport>& v) {
  for (size_t k = 0; k < v.size() && first + k < raster::kMaxViewports; ++k)
    d.dynamic.viewports[first + k] = {v[k].x, v[k].y, v[k].width, v[k].height, v[k].minDepth, v[k].maxDepth};
}

void storeScissors(DrawExecState& d, uint32_t first, const std::vector<VkRect2D>& r) {
  for (size_t k = 0; k < r.size() && first + k < raster::kMaxViewports; ++k)
    d.dynamic.scissors[first + k] = {r[k].offset.x, r[k].offset.y, r[k].extent.width, r[k].extent.height};
}

template <class F>
void forFaces(VkStencilFaceFlags faces, raster::State& s, F&& f) {
  if (faces & VK_STENCIL_FACE_FRONT_BIT) f(s.front);
  if (faces & VK_STENCIL_FACE_BACK_BIT) f(s.back);
}

bool checkFaceMask(CommandBuffer* cb, const char* fn, VkStencilFaceFlags faceMask, const char* vuid) {
  // VUID-vkCmdSetStencil*-faceMask-requiredbitmask
  if (faceMask & VK_STENCIL_FACE_FRONT_AND_BACK) return true;
  report(cb, Severity::Error, vuid, "%s: faceMask 0x%x names neither face", fn, faceMask);
  return false;
}

}  // namespace
}  // namespace vkrt::gfx

using namespace vkrt;
using namespace vkrt::gfx;

extern "C" {

VKAPI_ATTR void VKAPI_CALL vkrt_CmdSetViewport(VkCommandBuffer commandBuffer, uint32_t firstViewport,
                                               uint32_t viewportCount, const VkViewport* pViewports) {
  const char* fn = "vkCmdSetViewport";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  const uint32_t max = limits(cb).maxViewports;
  // VUID-vkCmdSetViewport-viewportCount-arraylength, VUID-vkCmdSetViewport-firstViewport-01224 (multiViewport is
  // not supported), VUID-vkCmdSetViewport-firstViewport-01223
  const char* vuid = viewportCount == 0                              ? "VUID-vkCmdSetViewport-viewportCount-arraylength"
                     : firstViewport != 0                            ? "VUID-vkCmdSetViewport-firstViewport-01224"
                     : uint64_t(firstViewport) + viewportCount > max ? "VUID-vkCmdSetViewport-firstViewport-01223"
                                                                     : nullptr;
  if (vuid) {
    report(cb, Severity::Error, vuid, "%s: firstViewport %u, viewportCount %u (maxViewports %u, no multiViewport)", fn,
           firstViewport, viewportCount, max);
    return;
  }
  std::vector<VkViewport> v(pViewports, pViewports + viewportCount);
  recordSetter(cb, 1u << kDynViewport,
               [firstViewport, v = std::move(v)](DrawExecState& d) { storeViewports(d, firstViewport, v); });
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdSetScissor(VkCommandBuffer commandBuffer, uint32_t firstScissor,
                                              uint32_t scissorCount, const VkRect2D* pScissors) {
  const char* fn = "vkCmdSetScissor";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  const uint32_t max = limits(cb).maxViewports;
  // VUID-vkCmdSetScissor-scissorCount-arraylength, VUID-vkCmdSetScissor-firstScissor-00593 (multiViewport is not
  // supported), VUID-vkCmdSetScissor-firstScissor-00592
  const char* vuid = scissorCount == 0                             ? "VUID-vkCmdSetScissor-scissorCount-arraylength"
                     : firstScissor != 0                           ? "VUID-vkCmdSetScissor-firstScissor-00593"
                     : uint64_t(firstScissor) + scissorCount > max ? "VUID-vkCmdSetScissor-firstScissor-00592"
                                                                   : nullptr;
  if (vuid) {
    report(cb, Severity::Error, vuid, "%s: firstScissor %u, scissorCount %u (maxViewports %u, no multiViewport)", fn,
           firstScissor, scissorCount, max);
    return;
  }
  // VUID-vkCmdSetScissor-x-00595, VUID-vkCmdSetScissor-offset-00596, VUID-vkCmdSetScissor-offset-00597
  if (!checkScissors(cb, fn, scissorCount, pScissors, "VUID-vkCmdSetScissor-x-00595",
                     "VUID-vkCmdSetScissor-offset-00596", "VUID-vkCmdSetScissor-offset-00597"))
    return;
  std::vector<VkRect2D> r(pScissors, pScissors + scissorCount);
  recordSetter(cb, 1u << kDynScissor,
               [firstScissor, r = std::move(r)](DrawExecState& d) { storeScissors(d, firstScissor, r); });
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdSetLineWidth(VkCommandBuffer commandBuffer, float lineWidth) {
  const char* fn = "vkCmdSetLineWidth";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  // VUID-vkCmdSetLineWidth-lineWidth-00788 (wideLines is not supported)
  if (lineWidth != 1.0f) {
    report(cb, Severity::Error, "VUID-vkCmdSetLineWidth-lineWidth-00788",
           "%s: lineWidth %g is not 1.0 and the wideLines feature is not enabled", fn, double(lineWidth));
    return;
  }
  recordSetter(cb, 1u << kDynLineWidth, [lineWidth](DrawExecState& d) { d.dynamic.lineWidth = lineWidth; });
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdSetDepthBias(VkCommandBuffer commandBuffer, float depthBiasConstantFactor,
                                                float depthBiasClamp, float depthBiasSlopeFactor) {
  const char* fn = "vkCmdSetDepthBias";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  // VUID-vkCmdSetDepthBias-depthBiasClamp-00790
  if (depthBiasClamp != 0.0f && !cb->device->enabled(Feature::depthBiasClamp)) {
    report(cb, Severity::Error, "VUID-vkCmdSetDepthBias-depthBiasClamp-00790",
           "%s: depthBiasClamp %g is not 0.0 and the depthBiasClamp feature is not enabled", fn,
           double(depthBiasClamp));
    return;
  }
  recordSetter(cb, 1u << kDynDepthBias, [=](DrawExecState& d) {
    d.dynamic.depthBiasConstant = depthBiasConstantFactor;
    d.dynamic.depthBiasClamp = depthBiasClamp;
    d.dynamic.depthBiasSlope = depthBiasSlopeFactor;
  });
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdSetBlendConstants(VkCommandBuffer commandBuffer, const float blendConstants[4]) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdSetBlendConstants");
  if (!cb) return;
  const float c[4] = {blendConstants[0], blendConstants[1], blendConstants[2], blendConstants[3]};
  recordSetter(cb, 1u << kDynBlendConstants, [c0 = c[0], c1 = c[1], c2 = c[2], c3 = c[3]](DrawExecState& d) {
    d.dynamic.blendConstants[0] = c0;
    d.dynamic.blendConstants[1] = c1;
    d.dynamic.blendConstants[2] = c2;
    d.dynamic.blendConstants[3] = c3;
  });
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdSetDepthBounds(VkCommandBuffer commandBuffer, float minDepthBounds,
                                                  float maxDepthBounds) {
  const char* fn = "vkCmdSetDepthBounds";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  // VUID-vkCmdSetDepthBounds-minDepthBounds-00600, VUID-vkCmdSetDepthBounds-maxDepthBounds-00601
  // (VK_EXT_depth_range_unrestricted is not supported)
  const bool minBad = !(minDepthBounds >= 0.0f && minDepthBounds <= 1.0f);
  if (minBad || !(maxDepthBounds >= 0.0f && maxDepthBounds <= 1.0f)) {
    report(cb, Severity::Error,
           minBad ? "VUID-vkCmdSetDepthBounds-minDepthBounds-00600" : "VUID-vkCmdSetDepthBounds-maxDepthBounds-00601",
           "%s: minDepthBounds %g, maxDepthBounds %g: both must lie in [0, 1]", fn, double(minDepthBounds),
           double(maxDepthBounds));
    return;
  }
  recordSetter(cb, 1u << kDynDepthBounds, [=](DrawExecState& d) {
    d.dynamic.minDepthBounds = minDepthBounds;
    d.dynamic.maxDepthBounds = maxDepthBounds;
  });
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdSetStencilCompareMask(VkCommandBuffer commandBuffer, VkStencilFaceFlags faceMask,
                                                         uint32_t compareMask) {
  const char* fn = "vkCmdSetStencilCompareMask";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb || !checkFaceMask(cb, fn, faceMask, "VUID-vkCmdSetStencilCompareMask-faceMask-requiredbitmask")) return;
  recordSetter(cb, 1u << kDynStencilCompareMask, [=](DrawExecState& d) {
    forFaces(faceMask, d.dynamic, [&](raster::StencilFace& f) { f.compareMask = compareMask; });
  });
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdSetStencilWriteMask(VkCommandBuffer commandBuffer, VkStencilFaceFlags faceMask,
                                                       uint32_t writeMask) {
  const char* fn = "vkCmdSetStencilWriteMask";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb || !checkFaceMask(cb, fn, faceMask, "VUID-vkCmdSetStencilWriteMask-faceMask-requiredbitmask")) return;
  recordSetter(cb, 1u << kDynStencilWriteMask, [=](DrawExecState& d) {
    forFaces(faceMask, d.dynamic, [&](raster::StencilFace& f) { f.writeMask = writeMask; });
  });
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdSetStencilReference(VkCommandBuffer commandBuffer, VkStencilFaceFlags faceMask,
                                                       uint32_t reference) {
  const char* fn = "vkCmdSetStencilReference";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb || !checkFaceMask(cb, fn, faceMask, "VUID-vkCmdSetStencilReference-faceMask-requiredbitmask")) return;
  recordSetter(cb, 1u << kDynStencilReference, [=](DrawExecState& d) {
    forFaces(faceMask, d.dynamic, [&](raster::StencilFace& f) { f.reference = reference; });
  });
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdSetCullMode(VkCommandBuffer commandBuffer, VkCullModeFlags cullMode) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdSetCullMode");
  if (!cb) return;
  recordSetter(cb, 1u << kDynCullMode, [=](DrawExecState& d) { d.dynamic.cullMode = uint8_t(cullMode & 3); });
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdSetFrontFace(VkCommandBuffer commandBuffer, VkFrontFace frontFace) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdSetFrontFace");
  if (!cb) return;
  recordSetter(cb, 1u << kDynFrontFace, [=](DrawExecState& d) { d.dynamic.frontFace = raster::FrontFace(frontFace); });
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdSetPrimitiveTopology(VkCommandBuffer commandBuffer,
                                                        VkPrimitiveTopology primitiveTopology) {
  const char* fn = "vkCmdSetPrimitiveTopology";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  // VUID-vkCmdSetPrimitiveTopology-primitiveTopology-parameter (adjacency and patch topologies need features vkrt
  // does not support; they are checked at the draw against the pipeline's class, see draw_commands.cpp)
  if (primitiveTopology < VK_PRIMITIVE_TOPOLOGY_POINT_LIST || primitiveTopology > VK_PRIMITIVE_TOPOLOGY_PATCH_LIST) {
    report(cb, Severity::Error, "VUID-vkCmdSetPrimitiveTopology-primitiveTopology-parameter",
           "%s: primitiveTopology %d is not a VkPrimitiveTopology", fn, int(primitiveTopology));
    return;
  }
  recordSetter(cb, 1u << kDynTopology,
               [=](DrawExecState& d) { d.dynamic.topology = raster::Topology(primitiveTopology); });
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdSetViewportWithCount(VkCommandBuffer commandBuffer, uint32_t viewportCount,
                                                        const VkViewport* pViewports) {
  const char* fn = "vkCmdSetViewportWithCount";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  const uint32_t max = limits(cb).maxViewports;
  // VUID-vkCmdSetViewportWithCount-viewportCount-03394, VUID-vkCmdSetViewportWithCount-viewportCount-03395
  if (viewportCount == 0 || viewportCount > max || viewportCount != 1) {
    report(cb, Severity::Error,
           viewportCount == 0 || viewportCount > max ? "VUID-vkCmdSetViewportWithCount-viewportCount-03394"
                                                     : "VUID-vkCmdSetViewportWithCount-viewportCount-03395",
           "%s: viewportCount %u (maxViewports %u; the multiViewport feature is not supported)", fn, viewportCount,
           max);
    return;
  }
  std::vector<VkViewport> v(pViewports, pViewports + viewportCount);
  recordSetter(cb, (1u << kDynViewportWithCount) | (1u << kDynViewport), [v = std::move(v)](DrawExecState& d) {
    d.dynamic.viewportCount = uint32_t(v.size());
    storeViewports(d, 0, v);
  });
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdSetScissorWithCount(VkCommandBuffer commandBuffer, uint32_t scissorCount,
                                                       const VkRect2D* pScissors) {
  const char* fn = "vkCmdSetScissorWithCount";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  const uint32_t max = limits(cb).maxViewports;
  // VUID-vkCmdSetScissorWithCount-scissorCount-03397, VUID-vkCmdSetScissorWithCount-scissorCount-03398
  if (scissorCount == 0 || scissorCount > max || scissorCount != 1) {
    report(cb, Severity::Error,
           scissorCount == 0 || scissorCount > max ? "VUID-vkCmdSetScissorWithCount-scissorCount-03397"
                                                   : "VUID-vkCmdSetScissorWithCount-scissorCount-03398",
           "%s: scissorCount %u (maxViewports %u; the multiViewport feature is not supported)", fn, scissorCount, max);
    return;
  }
  // VUID-vkCmdSetScissorWithCount-x-03399, VUID-vkCmdSetScissorWithCount-offset-03400,
  // VUID-vkCmdSetScissorWithCount-offset-03401
  if (!checkScissors(cb, fn, scissorCount, pScissors, "VUID-vkCmdSetScissorWithCount-x-03399",
                     "VUID-vkCmdSetScissorWithCount-offset-03400", "VUID-vkCmdSetScissorWithCount-offset-03401"))
    return;
  std::vector<VkRect2D> r(pScissors, pScissors + scissorCount);
  recordSetter(cb, (1u << kDynScissorWithCount) | (1u << kDynScissor), [r = std::move(r)](DrawExecState& d) {
    d.scissorCount = uint32_t(r.size());
    storeScissors(d, 0, r);
  });
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdSetDepthTestEnable(VkCommandBuffer commandBuffer, VkBool32 depthTestEnable) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdSetDepthTestEnable");
  if (!cb) return;
  recordSetter(cb, 1u << kDynDepthTestEnable, [=](DrawExecState& d) { d.dynamic.depthTest = depthTestEnable; });
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdSetDepthWriteEnable(VkCommandBuffer commandBuffer, VkBool32 depthWriteEnable) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdSetDepthWriteEnable");
  if (!cb) return;
  recordSetter(cb, 1u << kDynDepthWriteEnable, [=](DrawExecState& d) { d.dynamic.depthWrite = depthWriteEnable; });
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdSetDepthCompareOp(VkCommandBuffer commandBuffer, VkCompareOp depthCompareOp) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdSetDepthCompareOp");
  if (!cb) return;
  recordSetter(cb, 1u << kDynDepthCompareOp,
               [=](DrawExecState& d) { d.dynamic.depthCompare = raster::CompareOp(depthCompareOp); });
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdSetDepthBoundsTestEnable(VkCommandBuffer commandBuffer,
                                                            VkBool32 depthBoundsTestEnable) {
  const char* fn = "vkCmdSetDepthBoundsTestEnable";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  // (1.3.239 has no rule on the depthBounds feature for this command; the pipeline state's rule is
  // VUID-VkPipelineDepthStencilStateCreateInfo-depthBoundsTestEnable-00598.)
  recordSetter(cb, 1u << kDynDepthBoundsTestEnable,
               [=](DrawExecState& d) { d.dynamic.depthBoundsTest = depthBoundsTestEnable; });
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdSetStencilTestEnable(VkCommandBuffer commandBuffer, VkBool32 stencilTestEnable) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdSetStencilTestEnable");
  if (!cb) return;
  recordSetter(cb, 1u << kDynStencilTestEnable, [=](DrawExecState& d) { d.dynamic.stencilTest = stencilTestEnable; });
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdSetStencilOp(VkCommandBuffer commandBuffer, VkStencilFaceFlags faceMask,
                                                VkStencilOp failOp, VkStencilOp passOp, VkStencilOp depthFailOp,
                                                VkCompareOp compareOp) {
  const char* fn = "vkCmdSetStencilOp";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb || !checkFaceMask(cb, fn, faceMask, "VUID-vkCmdSetStencilOp-faceMask-requiredbitmask")) return;
  recordSetter(cb, 1u << kDynStencilOp, [=](DrawExecState& d) {
    forFaces(faceMask, d.dynamic, [&](raster::StencilFace& f) {
      f.failOp = raster::StencilOp(failOp);
      f.passOp = raster::StencilOp(passOp);
      f.depthFailOp = raster::StencilOp(depthFailOp);
      f.compareOp = raster::CompareOp(compareOp);
    });
  });
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdSetRasterizerDiscardEnable(VkCommandBuffer commandBuffer,
                                                              VkBool32 rasterizerDiscardEnable) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdSetRasterizerDiscardEnable");
  if (!cb) return;
  recordSetter(cb, 1u << kDynRasterizerDiscardEnable,
               [=](DrawExecState& d) { d.dynamic.rasterizerDiscard = rasterizerDiscardEnable; });
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdSetDepthBiasEnable(VkCommandBuffer commandBuffer, VkBool32 depthBiasEnable) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdSetDepthBiasEnable");
  if (!cb) return;
  recordSetter(cb, 1u << kDynDepthBiasEnable, [=](DrawExecState& d) { d.dynamic.depthBiasEnable = depthBiasEnable; });
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdSetPrimitiveRestartEnable(VkCommandBuffer commandBuffer,
                                                             VkBool32 primitiveRestartEnable) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdSetPrimitiveRestartEnable");
  if (!cb) return;
  recordSetter(cb, 1u << kDynPrimitiveRestartEnable,
               [=](DrawExecState& d) { d.dynamic.primitiveRestart = primitiveRestartEnable; });
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdSetLogicOpEXT(VkCommandBuffer commandBuffer, VkLogicOp logicOp) {
  const char* fn = "vkCmdSetLogicOpEXT";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  // VUID-vkCmdSetLogicOpEXT-None-04867
  if (!cb->device->enabled(Feature::extendedDynamicState2LogicOp)) {
    report(cb, Severity::Error, "VUID-vkCmdSetLogicOpEXT-None-04867",
           "%s: the extendedDynamicState2LogicOp feature is not enabled", fn);
    return;
  }
  // VUID-vkCmdSetLogicOpEXT-logicOp-parameter
  if (uint32_t(logicOp) > VK_LOGIC_OP_SET) {
    report(cb, Severity::Error, "VUID-vkCmdSetLogicOpEXT-logicOp-parameter", "%s: logicOp %d is not a VkLogicOp", fn,
           int(logicOp));
    return;
  }
  recordSetter(cb, 1u << kDynLogicOp, [=](DrawExecState& d) { d.dynamic.logicOp = raster::LogicOp(logicOp); });
}

// Tessellation is not supported, so extendedDynamicState2PatchControlPoints cannot be enabled and every call breaks
// VUID-vkCmdSetPatchControlPointsEXT-None-04873; the command exists because VK_EXT_extended_dynamic_state2 has it.
VKAPI_ATTR void VKAPI_CALL vkrt_CmdSetPatchControlPointsEXT(VkCommandBuffer commandBuffer,
                                                            uint32_t patchControlPoints) {
  const char* fn = "vkCmdSetPatchControlPointsEXT";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  report(cb, Severity::Error, "VUID-vkCmdSetPatchControlPointsEXT-None-04873",
         "%s: patchControlPoints %u, but the extendedDynamicState2PatchControlPoints feature is not enabled (vkrt has "
         "no tessellation)",
         fn, patchControlPoints);
}

}  // extern "C"
