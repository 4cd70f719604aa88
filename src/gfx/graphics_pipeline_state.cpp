// The fixed-function part of vkCreateGraphicsPipelines: each state structure of VkGraphicsPipelineCreateInfo
// checked (the VUIDs of "Graphics Pipelines" and of each state structure) and captured into GraphicsPipeline.
#include <cstdio>

#include "gfx/graphics_pipeline.hpp"
#include "gfx/graphics_pipeline_internal.hpp"
#include "runtime/alloc.hpp"
#include "runtime/device.hpp"
#include "runtime/format.hpp"
#include "runtime/physical_device.hpp"
#include "runtime/report.hpp"

namespace vkrt::gfx {
namespace {

bool isSrc1(VkBlendFactor f) {
  return f == VK_BLEND_FACTOR_SRC1_COLOR || f == VK_BLEND_FACTOR_ONE_MINUS_SRC1_COLOR ||
         f == VK_BLEND_FACTOR_SRC1_ALPHA || f == VK_BLEND_FACTOR_ONE_MINUS_SRC1_ALPHA;
}

bool sameBlend(const VkPipelineColorBlendAttachmentState& a, const VkPipelineColorBlendAttachmentState& b) {
  return a.blendEnable == b.blendEnable && a.srcColorBlendFactor == b.srcColorBlendFactor &&
         a.dstColorBlendFactor == b.dstColorBlendFactor && a.colorBlendOp == b.colorBlendOp &&
         a.srcAlphaBlendFactor == b.srcAlphaBlendFactor && a.dstAlphaBlendFactor == b.dstAlphaBlendFactor &&
         a.alphaBlendOp == b.alphaBlendOp && a.colorWriteMask == b.colorWriteMask;
}

raster::StencilFace stencilFace(const VkStencilOpState& s) {
  raster::StencilFace f;
  f.failOp = raster::StencilOp(s.failOp);
  f.passOp = raster::StencilOp(s.passOp);
  f.depthFailOp = raster::StencilOp(s.depthFailOp);
  f.compareOp = raster::CompareOp(s.compareOp);
  f.compareMask = s.compareMask;
  f.writeMask = s.writeMask;
  f.reference = s.reference;
  return f;
}

}  // namespace

bool captureDynamicState(const Device* dev, const VkGraphicsPipelineCreateInfo& ci, const char* what,
                         GraphicsPipelineDesc* p) {
  const VkPipelineDynamicStateCreateInfo* ds = ci.pDynamicState;
  if (!ds) return true;
  for (uint32_t k = 0; k < ds->dynamicStateCount; ++k) {
    const VkDynamicState s = ds->pDynamicStates[k];
    const int bit = dynamicBit(s);
    // VUID-VkGraphicsPipelineCreateInfo-pDynamicStates-04869 (logic op without extendedDynamicState2LogicOp),
    // -04870 (patch control points: extendedDynamicState2PatchControlPoints is not supported),
    // VUID-VkPipelineDynamicStateCreateInfo-pDynamicStates-parameter (states of extensions vkrt does not expose)
    const bool logicOp = s == VK_DYNAMIC_STATE_LOGIC_OP_EXT;
    if (bit < 0 || (logicOp && !dev->enabled(Feature::extendedDynamicState2LogicOp))) {
      report(dev, Severity::Error,
             logicOp ? "VUID-VkGraphicsPipelineCreateInfo-pDynamicStates-04869"
             : s == VK_DYNAMIC_STATE_PATCH_CONTROL_POINTS_EXT
                 ? "VUID-VkGraphicsPipelineCreateInfo-pDynamicStates-04870"
                 : "VUID-VkPipelineDynamicStateCreateInfo-pDynamicStates-parameter",
             "%s.pDynamicState->pDynamicStates[%u] is %d, a dynamic state vkrt does not support or whose feature is "
             "not enabled",
             what, k, int(s));
      return false;
    }
    // VUID-VkPipelineDynamicStateCreateInfo-pDynamicStates-01442
    if (p->dynamicMask & (1u << bit)) {
      report(dev, Severity::Error, "VUID-VkPipelineDynamicStateCreateInfo-pDynamicStates-01442",
             "%s.pDynamicState->pDynamicStates[%u] (%s) appears twice", what, k, dynamicStateName(bit));
      return false;
    }
    p->dynamicMask |= 1u << bit;
  }
  // VUID-VkGraphicsPipelineCreateInfo-pDynamicStates-04132
  if ((p->dynamicMask & (1u << kDynViewport)) && (p->dynamicMask & (1u << kDynViewportWithCount))) {
    report(dev, Severity::Error, "VUID-VkGraphicsPipelineCreateInfo-pDynamicStates-04132",
           "%s.pDynamicState has both VK_DYNAMIC_STATE_VIEWPORT and VK_DYNAMIC_STATE_VIEWPORT_WITH_COUNT", what);
    return false;
  }
  // VUID-VkGraphicsPipelineCreateInfo-pDynamicStates-04133
  if ((p->dynamicMask & (1u << kDynScissor)) && (p->dynamicMask & (1u << kDynScissorWithCount))) {
    report(dev, Severity::Error, "VUID-VkGraphicsPipelineCreateInfo-pDynamicStates-04133",
           "%s.pDynamicState has both VK_DYNAMIC_STATE_SCISSOR and VK_DYNAMIC_STATE_SCISSOR_WITH_COUNT", what);
    return false;
  }
  return true;
}

bool captureVertexInput(const Device* dev, const VkGraphicsPipelineCreateInfo& ci, const char* what,
                        GraphicsPipelineDesc* p, std::vector<GraphicsPipelineDesc::Attribute>* all) {
  const VkPhysicalDeviceLimits& lim = dev->physicalDevice->properties10.limits;
  const VkPipelineVertexInputStateCreateInfo* vi = ci.pVertexInputState;
  // VUID-VkGraphicsPipelineCreateInfo-pStages-02097
  if (!vi) {
    report(dev, Severity::Error, "VUID-VkGraphicsPipelineCreateInfo-pStages-02097", "%s.pVertexInputState is NULL",
           what);
    return false;
  }
  // VUID-VkPipelineVertexInputStateCreateInfo-vertexBindingDescriptionCount-00613
  if (vi->vertexBindingDescriptionCount > lim.maxVertexInputBindings) {
    report(dev, Severity::Error, "VUID-VkPipelineVertexInputStateCreateInfo-vertexBindingDescriptionCount-00613",
           "%s.pVertexInputState->vertexBindingDescriptionCount (%u) exceeds maxVertexInputBindings (%u)", what,
           vi->vertexBindingDescriptionCount, lim.maxVertexInputBindings);
    return false;
  }
  // VUID-VkPipelineVertexInputStateCreateInfo-vertexAttributeDescriptionCount-00614
  if (vi->vertexAttributeDescriptionCount > lim.maxVertexInputAttributes) {
    report(dev, Severity::Error, "VUID-VkPipelineVertexInputStateCreateInfo-vertexAttributeDescriptionCount-00614",
           "%s.pVertexInputState->vertexAttributeDescriptionCount (%u) exceeds maxVertexInputAttributes (%u)", what,
           vi->vertexAttributeDescriptionCount, lim.maxVertexInputAttributes);
    return false;
  }
  for (uint32_t k = 0; k < vi->vertexBindingDescriptionCount; ++k) {
    const VkVertexInputBindingDescription& b = vi->pVertexBindingDescriptions[k];
    // VUID-VkVertexInputBindingDescription-binding-00618
    if (b.binding >= lim.maxVertexInputBindings) {
      report(dev, Severity::Error, "VUID-VkVertexInputBindingDescription-binding-00618",
             "%s.pVertexInputState->pVertexBindingDescriptions[%u].binding (%u) is not less than "
             "maxVertexInputBindings (%u)",
             what, k, b.binding, lim.maxVertexInputBindings);
      return false;
    }
    // VUID-VkVertexInputBindingDescription-stride-00619
    if (b.stride > lim.maxVertexInputBindingStride) {
      report(dev, Severity::Error, "VUID-VkVertexInputBindingDescription-stride-00619",
             "%s.pVertexInputState->pVertexBindingDescriptions[%u].stride (%u) exceeds maxVertexInputBindingStride "
             "(%u)",
             what, k, b.stride, lim.maxVertexInputBindingStride);
      return false;
    }
    // VUID-VkPipelineVertexInputStateCreateInfo-pVertexBindingDescriptions-00616
    if (p->bindingMask & (1u << b.binding)) {
      report(dev, Severity::Error, "VUID-VkPipelineVertexInputStateCreateInfo-pVertexBindingDescriptions-00616",
             "%s.pVertexInputState->pVertexBindingDescriptions[%u] describes binding %u again", what, k, b.binding);
      return false;
    }
    p->bindingMask |= 1u << b.binding;
    p->bindings[b.binding] = {b.stride, b.inputRate == VK_VERTEX_INPUT_RATE_INSTANCE};
  }
  uint32_t locations = 0;
  for (uint32_t k = 0; k < vi->vertexAttributeDescriptionCount; ++k) {
    const VkVertexInputAttributeDescription& a = vi->pVertexAttributeDescriptions[k];
    const char* vuid = nullptr;
    // VUID-VkVertexInputAttributeDescription-location-00620, -binding-00621, -offset-00622, -format-00623
    if (a.location >= lim.maxVertexInputAttributes)
      vuid = "VUID-VkVertexInputAttributeDescription-location-00620";
    else if (a.binding >= lim.maxVertexInputBindings)
      vuid = "VUID-VkVertexInputAttributeDescription-binding-00621";
    else if (a.offset > lim.maxVertexInputAttributeOffset)
      vuid = "VUID-VkVertexInputAttributeDescription-offset-00622";
    else if (!vertexFormat(a.format))
      vuid = "VUID-VkVertexInputAttributeDescription-format-00623";
    // VUID-VkPipelineVertexInputStateCreateInfo-binding-00615
    else if (!(p->bindingMask & (1u << a.binding)))
      vuid = "VUID-VkPipelineVertexInputStateCreateInfo-binding-00615";
    // VUID-VkPipelineVertexInputStateCreateInfo-pVertexAttributeDescriptions-00617
    else if (locations & (1u << a.location))
      vuid = "VUID-VkPipelineVertexInputStateCreateInfo-pVertexAttributeDescriptions-00617";
    if (vuid) {
      report(dev, Severity::Error, vuid,
             "%s.pVertexInputState->pVertexAttributeDescriptions[%u]: location %u, binding %u, offset %u, format %d "
             "(maxVertexInputAttributes %u, maxVertexInputBindings %u, maxVertexInputAttributeOffset %u; bindings "
             "described 0x%x; a format without VK_FORMAT_FEATURE_VERTEX_BUFFER_BIT, a binding not described or a "
             "location used twice is invalid)",
             what, k, a.location, a.binding, a.offset, int(a.format), lim.maxVertexInputAttributes,
             lim.maxVertexInputBindings, lim.maxVertexInputAttributeOffset, p->bindingMask);
      return false;
    }
    locations |= 1u << a.location;
    all->push_back({a.location, a.binding, a.offset, vertexFormat(a.format)});
  }
  return true;
}

bool captureRasterState(const Device* dev, const VkGraphicsPipelineCreateInfo& ci, const char* what,
                        GraphicsPipelineDesc* p) {
  raster::State& s = p->state;
  const uint32_t dyn = p->dynamicMask;
  auto isDyn = [dyn](DynBit b) { return (dyn & (1u << b)) != 0; };

  // Input assembly.
  const VkPipelineInputAssemblyStateCreateInfo* ia = ci.pInputAssemblyState;
  // VUID-VkGraphicsPipelineCreateInfo-pStages-02098
  if (!ia) {
    report(dev, Severity::Error, "VUID-VkGraphicsPipelineCreateInfo-pStages-02098", "%s.pInputAssemblyState is NULL",
           what);
    return false;
  }
  const VkPrimitiveTopology t = ia->topology;
  if (!isDyn(kDynTopology)) {
    // VUID-VkPipelineInputAssemblyStateCreateInfo-topology-00429 (geometryShader is not supported)
    if (t >= VK_PRIMITIVE_TOPOLOGY_LINE_LIST_WITH_ADJACENCY &&
        t <= VK_PRIMITIVE_TOPOLOGY_TRIANGLE_STRIP_WITH_ADJACENCY) {
      report(dev, Severity::Error, "VUID-VkPipelineInputAssemblyStateCreateInfo-topology-00429",
             "%s.pInputAssemblyState->topology %d is an adjacency topology, which needs the geometryShader feature",
             what, int(t));
      return false;
    }
    // VUID-VkPipelineInputAssemblyStateCreateInfo-topology-00430 (tessellationShader is not supported)
    if (t == VK_PRIMITIVE_TOPOLOGY_PATCH_LIST) {
      report(dev, Severity::Error, "VUID-VkPipelineInputAssemblyStateCreateInfo-topology-00430",
             "%s.pInputAssemblyState->topology is VK_PRIMITIVE_TOPOLOGY_PATCH_LIST, which needs the "
             "tessellationShader feature",
             what);
      return false;
    }
    // VUID-VkPipelineInputAssemblyStateCreateInfo-topology-06252 (primitiveTopologyListRestart is not supported)
    if (ia->primitiveRestartEnable && !isDyn(kDynPrimitiveRestartEnable) &&
        (t == VK_PRIMITIVE_TOPOLOGY_POINT_LIST || t == VK_PRIMITIVE_TOPOLOGY_LINE_LIST ||
         t == VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST)) {
      report(dev, Severity::Error, "VUID-VkPipelineInputAssemblyStateCreateInfo-topology-06252",
             "%s.pInputAssemblyState: primitiveRestartEnable with the list topology %d", what, int(t));
      return false;
    }
  }
  s.topology = raster::Topology(t);
  s.primitiveRestart = ia->primitiveRestartEnable;

  // Rasterization.
  const VkPipelineRasterizationStateCreateInfo* rs = ci.pRasterizationState;
  // VUID-VkGraphicsPipelineCreateInfo-pRasterizationState-06601
  if (!rs) {
    report(dev, Severity::Error, "VUID-VkGraphicsPipelineCreateInfo-pRasterizationState-06601",
           "%s.pRasterizationState is NULL", what);
    return false;
  }
  // VUID-VkPipelineRasterizationStateCreateInfo-depthClampEnable-00782
  if (rs->depthClampEnable && !dev->enabled(Feature::depthClamp)) {
    report(dev, Severity::Error, "VUID-VkPipelineRasterizationStateCreateInfo-depthClampEnable-00782",
           "%s.pRasterizationState->depthClampEnable is VK_TRUE but the depthClamp feature is not enabled", what);
    return false;
  }
  // VUID-VkPipelineRasterizationStateCreateInfo-polygonMode-01413 (fillModeNonSolid is not supported)
  if (rs->polygonMode != VK_POLYGON_MODE_FILL) {
    report(dev, Severity::Error, "VUID-VkPipelineRasterizationStateCreateInfo-polygonMode-01413",
           "%s.pRasterizationState->polygonMode is %d, but the fillModeNonSolid feature is not enabled", what,
           int(rs->polygonMode));
    return false;
  }
  s.rasterizerDiscard = rs->rasterizerDiscardEnable;
  s.polygonMode = raster::PolygonMode::Fill;
  s.cullMode = uint8_t(rs->cullMode & 3);
  s.frontFace = raster::FrontFace(rs->frontFace);
  s.depthClamp = rs->depthClampEnable;
  s.depthClipEnable = !rs->depthClampEnable;
  s.depthBiasEnable = rs->depthBiasEnable;
  s.depthBiasConstant = rs->depthBiasConstantFactor;
  s.depthBiasClamp = rs->depthBiasClamp;
  s.depthBiasSlope = rs->depthBiasSlopeFactor;
  s.lineWidth = rs->lineWidth;
  // "fragment output interface state" and "fragment shader state" are present unless rasterization is discarded
  // statically.
  const bool rasterizes = !rs->rasterizerDiscardEnable || isDyn(kDynRasterizerDiscardEnable);

  // Viewports and scissors.
  const VkPipelineViewportStateCreateInfo* vp = ci.pViewportState;
  if (rasterizes) {
    // VUID-VkGraphicsPipelineCreateInfo-pViewportState-04892 (the rule for every pipeline that rasterizes)
    if (!vp) {
      report(dev, Severity::Error, "VUID-VkGraphicsPipelineCreateInfo-pViewportState-04892",
             "%s.pViewportState is NULL but rasterization is not statically disabled", what);
      return false;
    }
    const bool vpCount = isDyn(kDynViewportWithCount), scCount = isDyn(kDynScissorWithCount);
    const char* vuid = nullptr;
    // VUID-VkPipelineViewportStateCreateInfo-viewportCount-04135, -scissorCount-04136, -viewportCount-01216,
    // -scissorCount-01217 (multiViewport is not supported), -scissorCount-04134
    if (vpCount ? vp->viewportCount != 0 : vp->viewportCount == 0)
      vuid = "VUID-VkPipelineViewportStateCreateInfo-viewportCount-04135";
    else if (scCount ? vp->scissorCount != 0 : vp->scissorCount == 0)
      vuid = "VUID-VkPipelineViewportStateCreateInfo-scissorCount-04136";
    else if (vp->viewportCount > 1)
      vuid = "VUID-VkPipelineViewportStateCreateInfo-viewportCount-01216";
    else if (vp->scissorCount > 1)
      vuid = "VUID-VkPipelineViewportStateCreateInfo-scissorCount-01217";
    else if (!vpCount && !scCount && vp->viewportCount != vp->scissorCount)
      vuid = "VUID-VkPipelineViewportStateCreateInfo-scissorCount-04134";
    if (vuid) {
      report(dev, Severity::Error, vuid,
             "%s.pViewportState: viewportCount %u, scissorCount %u (viewport with count %s, scissor with count %s; "
             "the multiViewport feature is not supported)",
             what, vp->viewportCount, vp->scissorCount, vpCount ? "dynamic" : "static", scCount ? "dynamic" : "static");
      return false;
    }
    // VUID-VkGraphicsPipelineCreateInfo-pDynamicStates-04130
    if (!vpCount && !isDyn(kDynViewport) && !vp->pViewports) {
      report(dev, Severity::Error, "VUID-VkGraphicsPipelineCreateInfo-pDynamicStates-04130",
             "%s.pViewportState->pViewports is NULL but the viewports are not dynamic", what);
      return false;
    }
    // VUID-VkGraphicsPipelineCreateInfo-pDynamicStates-04131
    if (!scCount && !isDyn(kDynScissor) && !vp->pScissors) {
      report(dev, Severity::Error, "VUID-VkGraphicsPipelineCreateInfo-pDynamicStates-04131",
             "%s.pViewportState->pScissors is NULL but the scissors are not dynamic", what);
      return false;
    }
    s.viewportCount = vp->viewportCount ? vp->viewportCount : 1;
    p->scissorCount = vp->scissorCount ? vp->scissorCount : 1;
    for (uint32_t k = 0; vp->pViewports && k < vp->viewportCount; ++k) {
      const VkViewport& v = vp->pViewports[k];
      s.viewports[k] = {v.x, v.y, v.width, v.height, v.minDepth, v.maxDepth};
    }
    for (uint32_t k = 0; vp->pScissors && k < vp->scissorCount; ++k) {
      const VkRect2D& r = vp->pScissors[k];
      s.scissors[k] = {r.offset.x, r.offset.y, r.extent.width, r.extent.height};
    }
  }

  // Multisampling.
  const VkPipelineMultisampleStateCreateInfo* ms = ci.pMultisampleState;
  // VUID-VkGraphicsPipelineCreateInfo-pMultisampleState-06630
  if (rasterizes && !ms) {
    report(dev, Severity::Error, "VUID-VkGraphicsPipelineCreateInfo-pMultisampleState-06630",
           "%s.pMultisampleState is NULL but rasterization is not statically disabled", what);
    return false;
  }
  if (ms) {
    const char* vuid = nullptr;
    // VUID-VkPipelineMultisampleStateCreateInfo-sampleShadingEnable-00784, -alphaToOneEnable-00785,
    // -minSampleShading-00786
    if (ms->sampleShadingEnable && !dev->enabled(Feature::sampleRateShading))
      vuid = "VUID-VkPipelineMultisampleStateCreateInfo-sampleShadingEnable-00784";
    else if (ms->alphaToOneEnable && !dev->enabled(Feature::alphaToOne))
      vuid = "VUID-VkPipelineMultisampleStateCreateInfo-alphaToOneEnable-00785";
    else if (ms->sampleShadingEnable && !(ms->minSampleShading >= 0.0f && ms->minSampleShading <= 1.0f))
      vuid = "VUID-VkPipelineMultisampleStateCreateInfo-minSampleShading-00786";
    if (vuid) {
      report(dev, Severity::Error, vuid,
             "%s.pMultisampleState: sampleShadingEnable %u (sampleRateShading %s), minSampleShading %g, "
             "alphaToOneEnable %u (alphaToOne %s)",
             what, ms->sampleShadingEnable, dev->enabled(Feature::sampleRateShading) ? "on" : "off",
             double(ms->minSampleShading), ms->alphaToOneEnable, dev->enabled(Feature::alphaToOne) ? "on" : "off");
      return false;
    }
    s.samples = uint32_t(ms->rasterizationSamples);
    s.sampleMask = ms->pSampleMask ? ms->pSampleMask[0] : ~0u;
    s.alphaToCoverage = ms->alphaToCoverageEnable;
    s.alphaToOne = ms->alphaToOneEnable;
    p->minSampleShading = ms->sampleShadingEnable ? ms->minSampleShading : 0.0f;
    // Sample shading: with minSampleShading * samples > 1 every sample shades ("Sample Shading").
    s.sampleShading = ms->sampleShadingEnable && ms->minSampleShading * float(s.samples) > 1.0f;
  }

  // Depth and stencil.
  if (const VkPipelineDepthStencilStateCreateInfo* dsi = ci.pDepthStencilState; dsi && rasterizes) {
    // VUID-VkPipelineDepthStencilStateCreateInfo-depthBoundsTestEnable-00598
    if (dsi->depthBoundsTestEnable && !isDyn(kDynDepthBoundsTestEnable) && !dev->enabled(Feature::depthBounds)) {
      report(dev, Severity::Error, "VUID-VkPipelineDepthStencilStateCreateInfo-depthBoundsTestEnable-00598",
             "%s.pDepthStencilState->depthBoundsTestEnable is VK_TRUE but the depthBounds feature is not enabled",
             what);
      return false;
    }
    s.depthTest = dsi->depthTestEnable;
    s.depthWrite = dsi->depthWriteEnable;
    s.depthCompare = raster::CompareOp(dsi->depthCompareOp);
    s.depthBoundsTest = dsi->depthBoundsTestEnable;
    s.minDepthBounds = dsi->minDepthBounds;
    s.maxDepthBounds = dsi->maxDepthBounds;
    s.stencilTest = dsi->stencilTestEnable;
    s.front = stencilFace(dsi->front);
    s.back = stencilFace(dsi->back);
  }

  // Color blending.
  const VkPipelineColorBlendStateCreateInfo* cb = ci.pColorBlendState;
  if (cb && rasterizes) {
    // VUID-VkPipelineColorBlendStateCreateInfo-logicOpEnable-00606
    if (cb->logicOpEnable && !dev->enabled(Feature::logicOp)) {
      report(dev, Severity::Error, "VUID-VkPipelineColorBlendStateCreateInfo-logicOpEnable-00606",
             "%s.pColorBlendState->logicOpEnable is VK_TRUE but the logicOp feature is not enabled", what);
      return false;
    }
    if (cb->attachmentCount > raster::kMaxColorAttachments) {
      // (A count above maxColorAttachments cannot match a subpass: VUID-VkGraphicsPipelineCreateInfo-renderPass-06042
      // or -06055 below.)
      report(dev, Severity::Error, "VUID-VkGraphicsPipelineCreateInfo-renderPass-06055",
             "%s.pColorBlendState->attachmentCount (%u) exceeds maxColorAttachments (%u)", what, cb->attachmentCount,
             raster::kMaxColorAttachments);
      return false;
    }
    for (uint32_t k = 0; k < cb->attachmentCount && cb->pAttachments; ++k) {
      const VkPipelineColorBlendAttachmentState& a = cb->pAttachments[k];
      // VUID-VkPipelineColorBlendStateCreateInfo-pAttachments-00605
      if (!dev->enabled(Feature::independentBlend) && !sameBlend(a, cb->pAttachments[0])) {
        report(dev, Severity::Error, "VUID-VkPipelineColorBlendStateCreateInfo-pAttachments-00605",
               "%s.pColorBlendState->pAttachments[%u] differs from pAttachments[0] but the independentBlend feature "
               "is not enabled",
               what, k);
        return false;
      }
      if (!dev->enabled(Feature::dualSrcBlend)) {
        const char* vuid =
            isSrc1(a.srcColorBlendFactor)   ? "VUID-VkPipelineColorBlendAttachmentState-srcColorBlendFactor-00608"
            : isSrc1(a.dstColorBlendFactor) ? "VUID-VkPipelineColorBlendAttachmentState-dstColorBlendFactor-00609"
            : isSrc1(a.srcAlphaBlendFactor) ? "VUID-VkPipelineColorBlendAttachmentState-srcAlphaBlendFactor-00610"
            : isSrc1(a.dstAlphaBlendFactor) ? "VUID-VkPipelineColorBlendAttachmentState-dstAlphaBlendFactor-00611"
                                            : nullptr;
        // VUID-VkPipelineColorBlendAttachmentState-srcColorBlendFactor-00608, -dstColorBlendFactor-00609,
        // -srcAlphaBlendFactor-00610, -dstAlphaBlendFactor-00611
        if (vuid) {
          report(dev, Severity::Error, vuid,
                 "%s.pColorBlendState->pAttachments[%u] uses a SRC1 blend factor but the dualSrcBlend feature is not "
                 "enabled",
                 what, k);
          return false;
        }
      }
      raster::BlendAttachment& b = s.blend[k];
      b.enable = a.blendEnable;
      b.srcColor = raster::BlendFactor(a.srcColorBlendFactor);
      b.dstColor = raster::BlendFactor(a.dstColorBlendFactor);
      b.colorOp = raster::BlendOp(a.colorBlendOp);
      b.srcAlpha = raster::BlendFactor(a.srcAlphaBlendFactor);
      b.dstAlpha = raster::BlendFactor(a.dstAlphaBlendFactor);
      b.alphaOp = raster::BlendOp(a.alphaBlendOp);
      b.writeMask = uint8_t(a.colorWriteMask & 0xF);
    }
    s.logicOpEnable = cb->logicOpEnable;
    s.logicOp = raster::LogicOp(cb->logicOp);
    for (int c = 0; c < 4; ++c) s.blendConstants[c] = cb->blendConstants[c];
  }
  return true;
}

bool captureRendering(const Device* dev, const VkGraphicsPipelineCreateInfo& ci, const char* what,
                      GraphicsPipelineDesc* p) {
  const bool rasterizes = !ci.pRasterizationState || !ci.pRasterizationState->rasterizerDiscardEnable ||
                          (p->dynamicMask & (1u << kDynRasterizerDiscardEnable));
  const uint32_t blendCount = rasterizes && ci.pColorBlendState ? ci.pColorBlendState->attachmentCount : 0;
  p->renderPass = ci.renderPass;
  p->subpass = ci.subpass;
  p->fragmentOutput = rasterizes;
  if (ci.renderPass != VK_NULL_HANDLE) {
    // The subpass's color count is checked against the blend state when the pipeline is used in a render pass
    // instance (the draw-time check of gfx/draw_commands.cpp): this layer does not look into render pass objects.
    p->colorCount = blendCount;
    return true;
  }
  p->dynamicRendering = true;
  const auto* ri =
      findInChain<VkPipelineRenderingCreateInfo>(ci.pNext, VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO);
  const uint32_t count = ri ? ri->colorAttachmentCount : 0;
  p->viewMask = ri ? ri->viewMask : 0;
  // VUID-VkGraphicsPipelineCreateInfo-multiview-06577, renderPass-06578: a view mask needs the multiview feature
  // and view indices below maxMultiviewViewCount
  const uint32_t maxViews = dev->physicalDevice->properties11.maxMultiviewViewCount;
  if (p->viewMask && (!dev->enabled(Feature::multiview) || p->viewMask >> maxViews)) {
    report(dev, Severity::Error,
           !dev->enabled(Feature::multiview) ? "VUID-VkGraphicsPipelineCreateInfo-multiview-06577"
                                             : "VUID-VkGraphicsPipelineCreateInfo-renderPass-06578",
           "%s: VkPipelineRenderingCreateInfo::viewMask 0x%x (multiview %s, maxMultiviewViewCount %u)", what,
           p->viewMask, dev->enabled(Feature::multiview) ? "enabled" : "not enabled", maxViews);
    return false;
  }
  if (!rasterizes) return true;
  // VUID-VkGraphicsPipelineCreateInfo-renderPass-06055. Without color attachments pColorBlendState is ignored
  // ("is ignored if ... the subpass ... does not use any color attachments"; the validation layer compares the
  // counts only then too): the CTS's depth-only dynamic rendering cases pass one blend attachment state there.
  if ((count != 0 && blendCount != count) || count > raster::kMaxColorAttachments) {
    report(dev, Severity::Error, "VUID-VkGraphicsPipelineCreateInfo-renderPass-06055",
           "%s: pColorBlendState->attachmentCount (%u) is not VkPipelineRenderingCreateInfo::colorAttachmentCount "
           "(%u)%s",
           what, blendCount, count, count > raster::kMaxColorAttachments ? ", which exceeds maxColorAttachments" : "");
    return false;
  }
  p->colorCount = count;
  for (uint32_t k = 0; k < count; ++k) {
    const VkFormat f = ri->pColorAttachmentFormats ? ri->pColorAttachmentFormats[k] : VK_FORMAT_UNDEFINED;
    // VUID-VkGraphicsPipelineCreateInfo-renderPass-06582
    if (f != VK_FORMAT_UNDEFINED && !(formatFeatures(f) & VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT)) {
      report(dev, Severity::Error, "VUID-VkGraphicsPipelineCreateInfo-renderPass-06582",
             "%s: VkPipelineRenderingCreateInfo::pColorAttachmentFormats[%u] (%d) has no "
             "VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT",
             what, k, int(f));
      return false;
    }
    p->colorFormats[k] = f;
  }
  p->depthFormat = ri ? ri->depthAttachmentFormat : VK_FORMAT_UNDEFINED;
  p->stencilFormat = ri ? ri->stencilAttachmentFormat : VK_FORMAT_UNDEFINED;
  // The depth/stencil formats of the core API: D16_UNORM .. D32_SFLOAT_S8_UINT, S8_UINT the only one without depth;
  // the combined ones (and S8_UINT) have stencil.
  const VkFormat df = p->depthFormat, sf = p->stencilFormat;
  const bool depthAspect = df >= VK_FORMAT_D16_UNORM && df <= VK_FORMAT_D32_SFLOAT_S8_UINT && df != VK_FORMAT_S8_UINT;
  const bool stencilAspect = sf >= VK_FORMAT_S8_UINT && sf <= VK_FORMAT_D32_SFLOAT_S8_UINT;
  // VUID-VkGraphicsPipelineCreateInfo-renderPass-06587, -06588, -06589
  const char* vuid = df != VK_FORMAT_UNDEFINED && !depthAspect ? "VUID-VkGraphicsPipelineCreateInfo-renderPass-06587"
                     : sf != VK_FORMAT_UNDEFINED && !stencilAspect
                         ? "VUID-VkGraphicsPipelineCreateInfo-renderPass-06588"
                     : df != VK_FORMAT_UNDEFINED && sf != VK_FORMAT_UNDEFINED && df != sf
                         ? "VUID-VkGraphicsPipelineCreateInfo-renderPass-06589"
                         : nullptr;
  if (vuid) {
    report(dev, Severity::Error, vuid,
           "%s: VkPipelineRenderingCreateInfo::depthAttachmentFormat %d, stencilAttachmentFormat %d (a depth format "
           "with a depth aspect, a stencil format with a stencil aspect, equal when both are given)",
           what, int(df), int(sf));
    return false;
  }
  return true;
}

}  // namespace vkrt::gfx
