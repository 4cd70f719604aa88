// The steps of vkCreateGraphicsPipelines (gfx/graphics_pipeline.cpp) that capture fixed-function state
// (gfx/graphics_pipeline_state.cpp). Each checks its structure's rules, reports against the device naming `what`
// ("vkCreateGraphicsPipelines: pCreateInfos[i]") and returns false on a violation.
#pragma once

#include <vector>

#include "gfx/graphics_pipeline.hpp"

namespace vkrt::gfx {

// pDynamicState: fills dynamicMask. Runs first: the other steps skip the rules of dynamic states.
bool captureDynamicState(const Device* dev, const VkGraphicsPipelineCreateInfo& ci, const char* what,
                         GraphicsPipelineDesc* p);
// pVertexInputState: bindings into p, every attribute into `all` (the shader's use is matched later).
bool captureVertexInput(const Device* dev, const VkGraphicsPipelineCreateInfo& ci, const char* what,
                        GraphicsPipelineDesc* p, std::vector<GraphicsPipelineDesc::Attribute>* all);
// Input assembly, rasterization, viewports, multisampling, depth/stencil and color blending into p->state.
bool captureRasterState(const Device* dev, const VkGraphicsPipelineCreateInfo& ci, const char* what,
                        GraphicsPipelineDesc* p);
// renderPass/subpass or VkPipelineRenderingCreateInfo (dynamic rendering) and the blend attachment count.
bool captureRendering(const Device* dev, const VkGraphicsPipelineCreateInfo& ci, const char* what,
                      GraphicsPipelineDesc* p);

}  // namespace vkrt::gfx
