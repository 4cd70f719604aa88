// vkCreateGraphicsPipelines: flags and derivatives, the shader stages (vertex + optional fragment), the state
// structures (gfx/graphics_pipeline_state.cpp), compilation through runtime's shared path, and the interface between
// the stages (vertex outputs matched to fragment inputs by Location: the varying slots of raster::FragmentStage).
#include "gfx/graphics_pipeline.hpp"

#include <chrono>
#include <cstdio>

#include "gfx/graphics_pipeline_internal.hpp"
#include "gfx/render_pass.hpp"
#include "runtime/alloc.hpp"
#include "runtime/device.hpp"
#include "runtime/physical_device.hpp"
#include "runtime/pipeline_cache.hpp"
#include "runtime/pipeline_layout.hpp"
#include "runtime/report.hpp"
#include "runtime/shader_cache.hpp"
#include "runtime/shader_stage.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt::gfx {
namespace {

constexpr VkShaderStageFlags kUnsupportedStages[][2] = {
    {VK_SHADER_STAGE_GEOMETRY_BIT, 0},
    {VK_SHADER_STAGE_TESSELLATION_CONTROL_BIT | VK_SHADER_STAGE_TESSELLATION_EVALUATION_BIT, 1},
    {VK_SHADER_STAGE_MESH_BIT_EXT, 2},
    {VK_SHADER_STAGE_TASK_BIT_EXT, 3},
};
const char* const kUnsupportedStageVuids[] = {
    "VUID-VkPipelineShaderStageCreateInfo-stage-00704", "VUID-VkPipelineShaderStageCreateInfo-stage-00705",
    "VUID-VkPipelineShaderStageCreateInfo-stage-02091", "VUID-VkPipelineShaderStageCreateInfo-stage-02092"};
const char* const kUnsupportedStageFeatures[] = {"geometryShader", "tessellationShader", "meshShader", "taskShader"};

raster::Interpolation interpolation(spirv::GraphicsStageInfo::Location::Interpolation i) {
  switch (i) {
    case spirv::GraphicsStageInfo::Location::Flat: return raster::Interpolation::Flat;
    case spirv::GraphicsStageInfo::Location::NoPerspective: return raster::Interpolation::NoPerspective;
    default: return raster::Interpolation::Smooth;
  }
}

// The derivative rules (VUID-VkGraphicsPipelineCreateInfo-flags-00722..00725, VUID-vkCreateGraphicsPipelines-flags-
// 00720, -00721). `created` holds the pipelines of this call made so far.
bool checkDerivative(const Device* dev, const VkGraphicsPipelineCreateInfo& ci, uint32_t i, const char* what,
                     const VkPipeline* created) {
  if (!(ci.flags & VK_PIPELINE_CREATE_DERIVATIVE_BIT)) return true;
  const Pipeline* base = nullptr;
  const char* vuid = nullptr;
  if (ci.basePipelineHandle != VK_NULL_HANDLE && ci.basePipelineIndex != -1) {
    // VUID-VkGraphicsPipelineCreateInfo-flags-00724 / -00725 (both given)
    vuid = "VUID-VkGraphicsPipelineCreateInfo-flags-00725";
  } else if (ci.basePipelineHandle != VK_NULL_HANDLE) {
    base = fromHandle<Pipeline>(ci.basePipelineHandle);
    // VUID-VkGraphicsPipelineCreateInfo-flags-00722
    if (!base || base->bindPoint != VK_PIPELINE_BIND_POINT_GRAPHICS)
      vuid = "VUID-VkGraphicsPipelineCreateInfo-flags-00722";
  } else if (ci.basePipelineIndex < 0) {
    // VUID-VkGraphicsPipelineCreateInfo-flags-00723
    vuid = "VUID-VkGraphicsPipelineCreateInfo-flags-00723";
  } else if (uint32_t(ci.basePipelineIndex) >= i) {
    // VUID-vkCreateGraphicsPipelines-flags-00720 (the base must come earlier in pCreateInfos)
    vuid = "VUID-vkCreateGraphicsPipelines-flags-00720";
  } else {
    base = fromHandle<Pipeline>(created[ci.basePipelineIndex]);
    if (!base) return true;  // the base failed to compile: nothing to derive from, nothing to check
  }
  // VUID-vkCreateGraphicsPipelines-flags-00721
  if (!vuid && !(base->createFlags & VK_PIPELINE_CREATE_ALLOW_DERIVATIVES_BIT))
    vuid = "VUID-vkCreateGraphicsPipelines-flags-00721";
  if (vuid) {
    report(dev, Severity::Error, vuid,
           "%s: VK_PIPELINE_CREATE_DERIVATIVE_BIT with basePipelineHandle 0x%llx and basePipelineIndex %d (the base "
           "must be one graphics pipeline, created earlier with VK_PIPELINE_CREATE_ALLOW_DERIVATIVES_BIT)",
           what, (unsigned long long)rawHandle(ci.basePipelineHandle), ci.basePipelineIndex);
    return false;
  }
  return true;
}

// Builds the vertex attributes the shader reads and the fragment stage's inputs.
void linkInterfaces(GraphicsPipelineDesc* p, const std::vector<GraphicsPipelineDesc::Attribute>& all) {
  const spirv::GraphicsStageInfo& vs = p->vertex->graphics;
  for (const auto& in : vs.inputs) {
    for (const auto& a : all) {
      if (a.location != in.location) continue;
      p->attributes.push_back(a);
      p->usedBindings |= 1u << a.binding;
    }
  }
  raster::FragmentStage& f = p->fragmentStage;
  if (!p->fragment) return;
  const spirv::GraphicsStageInfo& fs = p->fragment->graphics;
  // Fragment inputs in increasing location order, one slot each. An input no vertex output writes is allowed by
  // 1.3.239 (its value is undefined: the slot holds zeros, see draw_executor.cpp).
  for (const auto& in : fs.inputs) {
    if (f.inputCount == raster::kMaxLocations) break;
    raster::FragmentInput& r = f.inputs[f.inputCount++];
    r.location = in.location;
    r.componentMask = in.componentMask ? in.componentMask : 0xF;
    // Integer inputs must be Flat ("Interpolation Decorations"); the fragment shader's decoration rules.
    r.interpolation = in.integer ? raster::Interpolation::Flat : interpolation(in.interpolation);
    r.centroid = in.centroid;
    r.sample = in.sample;
  }
  p->varyingCount = f.inputCount;
  f.needsHelpers = fs.needsQuad;
  f.writesDepth = fs.writesDepth;
  f.writesSampleMask = fs.writesSampleMask;
  f.canDiscard = fs.canDiscard;
  f.earlyFragmentTests = fs.earlyFragmentTests;
  f.hasSideEffects = fs.sideEffects;
  f.readsFragCoord = fs.readsFragCoord;
  f.readsPointCoord = fs.readsPointCoord;
  // A shader that reads input attachments may read the depth/stencil attachment this draw writes (a feedback loop,
  // ordered by the application's barriers between draws, as CTS rasterization_order_attachment_access.*
  // .multi_draw_barriers does): the tests and writes must then follow the shader, as late tests do, or the shader
  // reads its own fragment's depth or stencil. The raster's early-test shortcut is off as for side effects.
  for (const spirv::ResourceBinding& r : p->fragment->resources)
    if (r.kind == spirv::ResourceBinding::InputAttachment) f.hasSideEffects = true;
  for (const auto& out : fs.outputs)
    if (out.location < raster::kMaxColorAttachments) f.outputMask |= 1u << out.location;
  bool perSample = fs.readsSampleId;
  for (uint32_t k = 0; k < f.inputCount; ++k) perSample |= f.inputs[k].sample;
  if (perSample) p->state.sampleShading = true;
}

// What the fragment shader's SPMD entry may write of colour attachment 0 itself (abi::ColorMerge): a pipeline with
// one colour attachment of an 8-bit UNorm RGBA or BGRA format, one sample, no logic op, no alpha to coverage or to
// one, and blending off or one of the back end's four equations of their own (raster::blendShape; none of them reads
// the blend constants).
// The draw still decides per quad (the executor's DrawContext::mergesColor, the rasterizer's fast path).
abi::ColorMerge colorMergeFor(const VkGraphicsPipelineCreateInfo& ci, const GraphicsPipelineDesc& p) {
  abi::ColorMerge m;
  if (p.colorCount != 1 || !p.fragmentOutput) return m;
  VkFormat format = p.colorFormats[0];
  if (!p.dynamicRendering) {
    const RenderPass* rp = fromHandle<RenderPass>(ci.renderPass);
    if (!rp || ci.subpass >= rp->subpasses.size()) return m;
    const SubpassDesc& sd = rp->subpasses[ci.subpass];
    format = sd.color.size() == 1 && sd.color[0] != VK_ATTACHMENT_UNUSED ? rp->attachments[sd.color[0]].format
                                                                         : VK_FORMAT_UNDEFINED;
  }
  const raster::State& s = p.state;
  if (s.samples != 1 || s.sampleShading || s.alphaToCoverage || s.alphaToOne || s.logicOpEnable) return m;
  const raster::BlendAttachment& b = s.blend[0];
  const int shape = b.enable ? raster::blendShape(b) : -1;
  if (b.enable && shape < 0) return m;
  const abi::ColorMerge::Blend blend = abi::ColorMerge::Blend(shape + 1);  // kOff, or the shape's in the same order
  if (format == VK_FORMAT_R8G8B8A8_UNORM)
    m.format = abi::ColorMerge::kRgba8Unorm;
  else if (format == VK_FORMAT_B8G8R8A8_UNORM)
    m.format = abi::ColorMerge::kBgra8Unorm;
  else
    return m;
  m.blend = blend;
  m.writeMask = b.writeMask;
  return m;
}

VkResult createOne(Device* dev, PipelineCache* cache, const VkGraphicsPipelineCreateInfo& ci, uint32_t i,
                   const VkAllocationCallbacks* alloc, const VkPipeline* created, VkPipeline* out) {
  const char* fn = "vkCreateGraphicsPipelines";
  const auto start = std::chrono::steady_clock::now();
  char what[64];
  std::snprintf(what, sizeof what, "%s: pCreateInfos[%u]", fn, i);
  // VUID-VkGraphicsPipelineCreateInfo-graphicsPipelineLibrary-06606 (graphicsPipelineLibrary is not supported)
  if (ci.flags & VK_PIPELINE_CREATE_LIBRARY_BIT_KHR) {
    report(dev, Severity::Error, "VUID-VkGraphicsPipelineCreateInfo-graphicsPipelineLibrary-06606",
           "%s.flags (0x%x) has VK_PIPELINE_CREATE_LIBRARY_BIT_KHR but the graphicsPipelineLibrary feature is not "
           "enabled",
           what, ci.flags);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  if (!checkDerivative(dev, ci, i, what, created)) return VK_ERROR_VALIDATION_FAILED_EXT;
  // VUID-VkGraphicsPipelineCreateInfo-stageCount-06604, VUID-VkGraphicsPipelineCreateInfo-pStages-06600
  if (ci.stageCount == 0 || !ci.pStages) {
    report(dev, Severity::Error, "VUID-VkGraphicsPipelineCreateInfo-stageCount-06604",
           "%s: stageCount is %u and pStages %p; a vertex shader is required", what, ci.stageCount,
           static_cast<const void*>(ci.pStages));
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  const VkPipelineShaderStageCreateInfo* vsInfo = nullptr;
  const VkPipelineShaderStageCreateInfo* fsInfo = nullptr;
  uint32_t vsIndex = 0, fsIndex = 0;
  VkShaderStageFlags seen = 0;
  for (uint32_t s = 0; s < ci.stageCount; ++s) {
    const VkShaderStageFlagBits stage = ci.pStages[s].stage;
    for (uint32_t u = 0; u < 4; ++u) {
      // VUID-VkPipelineShaderStageCreateInfo-stage-00704, -00705, -02091, -02092
      if (stage & kUnsupportedStages[u][0]) {
        report(dev, Severity::Error, kUnsupportedStageVuids[u],
               "%s.pStages[%u].stage is 0x%x, which needs the %s feature (vkrt supports vertex and fragment shaders "
               "only)",
               what, s, unsigned(stage), kUnsupportedStageFeatures[u]);
        return VK_ERROR_VALIDATION_FAILED_EXT;
      }
    }
    // VUID-VkGraphicsPipelineCreateInfo-pStages-06896
    if (stage != VK_SHADER_STAGE_VERTEX_BIT && stage != VK_SHADER_STAGE_FRAGMENT_BIT) {
      report(dev, Severity::Error, "VUID-VkGraphicsPipelineCreateInfo-pStages-06896",
             "%s.pStages[%u].stage is 0x%x, not a graphics shader stage", what, s, unsigned(stage));
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
    // VUID-VkGraphicsPipelineCreateInfo-stage-06897
    if (seen & stage) {
      report(dev, Severity::Error, "VUID-VkGraphicsPipelineCreateInfo-stage-06897",
             "%s.pStages[%u].stage 0x%x appears in more than one element of pStages", what, s, unsigned(stage));
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
    seen |= stage;
    if (stage == VK_SHADER_STAGE_VERTEX_BIT) {
      vsInfo = &ci.pStages[s];
      vsIndex = s;
    } else {
      fsInfo = &ci.pStages[s];
      fsIndex = s;
    }
  }
  // VUID-VkGraphicsPipelineCreateInfo-stage-02096
  if (!vsInfo) {
    report(dev, Severity::Error, "VUID-VkGraphicsPipelineCreateInfo-stage-02096",
           "%s: pStages has no VK_SHADER_STAGE_VERTEX_BIT stage", what);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  PipelineLayout* layout = fromHandle<PipelineLayout>(ci.layout);
  // VUID-VkGraphicsPipelineCreateInfo-layout-06602
  if (!layout) {
    report(dev, Severity::Error, "VUID-VkGraphicsPipelineCreateInfo-layout-06602",
           "%s.layout 0x%llx is not a live VkPipelineLayout", what, (unsigned long long)rawHandle(ci.layout));
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }

  auto p = std::make_unique<GraphicsPipelineDesc>();
  std::vector<GraphicsPipelineDesc::Attribute> attributes;
  if (!captureDynamicState(dev, ci, what, p.get()) || !captureVertexInput(dev, ci, what, p.get(), &attributes) ||
      !captureRasterState(dev, ci, what, p.get()) || !captureRendering(dev, ci, what, p.get()))
    return VK_ERROR_VALIDATION_FAILED_EXT;
  // The fragment shader is part of "fragment shader state", absent when rasterization is statically discarded.
  if (p->state.rasterizerDiscard && !(p->dynamicMask & (1u << kDynRasterizerDiscardEnable))) fsInfo = nullptr;

  // Shaders: prepared (the stage rules), then compiled or found in the device's or the application's cache.
  const bool mayCompile = !(ci.flags & VK_PIPELINE_CREATE_FAIL_ON_PIPELINE_COMPILE_REQUIRED_BIT);
  PreparedStage vsPrep, fsPrep;
  char vsWhat[96], fsWhat[96];  // what (63 characters at most) and the index
  std::snprintf(vsWhat, sizeof vsWhat, "%s.pStages[%u]", what, vsIndex);
  std::snprintf(fsWhat, sizeof fsWhat, "%s.pStages[%u]", what, fsIndex);
  if (!prepareStage(dev, *vsInfo, spv::ExecutionModelVertex, vsWhat, &vsPrep)) return VK_ERROR_VALIDATION_FAILED_EXT;
  if (fsInfo && !prepareStage(dev, *fsInfo, spv::ExecutionModelFragment, fsWhat, &fsPrep))
    return VK_ERROR_VALIDATION_FAILED_EXT;
  if (fsInfo && dev->colorMerge) {
    fsPrep.request.colorMerge = colorMergeFor(ci, *p);
    fsPrep.key = shaderKey(fsPrep.codeHash, fsPrep.request);
  }
  CompiledStage vsc = compileStage(dev, vsPrep, mayCompile, cache, fn, vsWhat);
  if (vsc.result != VK_SUCCESS) return vsc.result;
  CompiledStage fsc;
  if (fsInfo) {
    fsc = compileStage(dev, fsPrep, mayCompile, cache, fn, fsWhat);
    if (fsc.result != VK_SUCCESS) return fsc.result;
  }
  p->vertex = vsc.shader;
  p->fragment = fsc.shader;
  if (fsInfo) p->colorMerge = fsPrep.request.colorMerge;
  p->vertexName = "vertex shader \"" + p->vertex->entryName + "\"";
  if (p->fragment) p->fragmentName = "fragment shader \"" + p->fragment->entryName + "\"";
  for (const auto& [shader, stage, where] : {std::tuple{p->vertex.get(), VK_SHADER_STAGE_VERTEX_BIT, vsWhat},
                                             std::tuple{p->fragment.get(), VK_SHADER_STAGE_FRAGMENT_BIT, fsWhat}}) {
    if (!shader) continue;
    std::string detail;
    // VUID-VkGraphicsPipelineCreateInfo-layout-00756
    if (checkLayoutProvides(*layout, *shader, stage, &detail) != LayoutMismatch::None) {
      report(dev, Severity::Error, "VUID-VkGraphicsPipelineCreateInfo-layout-00756", "%s: %s", where, detail.c_str());
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
  }
  linkInterfaces(p.get(), attributes);

  GraphicsPipeline* made =
      createObject<GraphicsPipeline>(alloc, VK_SYSTEM_ALLOCATION_SCOPE_OBJECT, dev, ci.flags, layout, std::move(*p));
  if (!made) return VK_ERROR_OUT_OF_HOST_MEMORY;
  storeInCache(cache, vsPrep.request, *made->vertex);
  if (made->fragment) storeInCache(cache, fsPrep.request, *made->fragment);
  // Pipeline creation feedback (core in 1.3): the pipeline's time, each stage's from its compilation, in pStages
  // order.
  if (auto* fb = findInChain<VkPipelineCreationFeedbackCreateInfo>(
          ci.pNext, VK_STRUCTURE_TYPE_PIPELINE_CREATION_FEEDBACK_CREATE_INFO)) {
    const uint64_t ns = uint64_t(
        std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - start).count());
    VkPipelineCreationFeedbackFlags hit = vsc.feedback.flags & (fsInfo ? fsc.feedback.flags : ~0u) &
                                          VK_PIPELINE_CREATION_FEEDBACK_APPLICATION_PIPELINE_CACHE_HIT_BIT;
    if (fb->pPipelineCreationFeedback)
      *fb->pPipelineCreationFeedback = {VK_PIPELINE_CREATION_FEEDBACK_VALID_BIT | hit, ns};
    for (uint32_t s = 0; s < fb->pipelineStageCreationFeedbackCount && fb->pPipelineStageCreationFeedbacks; ++s) {
      VkPipelineCreationFeedback f{};
      if (s == vsIndex)
        f = vsc.feedback;
      else if (fsInfo && s == fsIndex)
        f = fsc.feedback;
      fb->pPipelineStageCreationFeedbacks[s] = f;
    }
  }
  *out = toHandle(static_cast<Pipeline*>(made));
  return VK_SUCCESS;
}

}  // namespace
}  // namespace vkrt::gfx

using namespace vkrt;
using namespace vkrt::gfx;

extern "C" {

VKAPI_ATTR VkResult VKAPI_CALL vkrt_CreateGraphicsPipelines(VkDevice device, VkPipelineCache pipelineCache,
                                                            uint32_t createInfoCount,
                                                            const VkGraphicsPipelineCreateInfo* pCreateInfos,
                                                            const VkAllocationCallbacks* pAllocator,
                                                            VkPipeline* pPipelines) {
  static constexpr PipelineBatchCommand kCommand{"vkCreateGraphicsPipelines",
                                                 "VUID-vkCreateGraphicsPipelines-device-parameter",
                                                 "VUID-vkCreateGraphicsPipelines-pipelineCache-parameter"};
  return createPipelineBatch(kCommand, device, pipelineCache, createInfoCount, pCreateInfos, pAllocator, pPipelines,
                             [&](Device* dev, PipelineCache* cache, uint32_t i, VkPipeline* out) {
                               return createOne(dev, cache, pCreateInfos[i], i, pAllocator, pPipelines, out);
                             });
}

}  // extern "C"
