// Graphics pipelines (vkCreateGraphicsPipelines, gfx/graphics_pipeline.cpp): a vertex shader and an optional
// fragment shader, compiled through runtime's shared path (runtime/shader_stage.hpp: prepareStage, compileStage,
// the device's shader cache and the application's VkPipelineCache), and every fixed-function state of the create
// info captured as raster::State plus the vertex input description, the dynamic state mask and the render pass or
// dynamic rendering formats that draws check against.
//
// Geometry, tessellation, task and mesh stages are not supported (their features are not advertised): a pipeline
// with one reports and fails.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "gfx/draw_state.hpp"
#include "gfx/vertex_input.hpp"
#include "raster/raster.hpp"
#include "runtime/pipeline.hpp"
#include "spirv/compiler.hpp"

namespace vkrt::gfx {

// Everything a graphics pipeline captures at creation (a plain value: vkCreateGraphicsPipelines fills one before it
// makes the Vulkan object).
struct GraphicsPipelineDesc {
  std::shared_ptr<const spirv::CompiledShader> vertex;
  std::shared_ptr<const spirv::CompiledShader> fragment;  // null: no fragment shader
  std::string vertexName, fragmentName;                   // "vertex shader \"main\"", for fault reports

  // Vertex input state.
  struct Binding {
    uint32_t stride = 0;
    bool perInstance = false;
  };
  Binding bindings[kMaxVertexBindings];
  uint32_t bindingMask = 0;  // bindings described
  struct Attribute {
    uint32_t location = 0, binding = 0, offset = 0;
    const VertexFormat* format = nullptr;
  };
  std::vector<Attribute> attributes;  // the attributes the vertex shader reads
  uint32_t usedBindings = 0;          // bindings those attributes read (bit b = binding b)

  // Fixed-function state (dynamic ones hold the create info's values, or defaults, and are replaced at draws).
  raster::State state;
  uint32_t scissorCount = 1;
  uint32_t dynamicMask = 0;  // DynBit bits
  float minSampleShading = 0;

  // The fragment stage as the rasterizer sees it (user and shade are the draw's).
  raster::FragmentStage fragmentStage;
  // Varying slot i carries the vertex shader's output at Location fragmentStage.inputs[i].location.
  uint32_t varyingCount = 0;

  // What draws check the render pass instance against.
  bool dynamicRendering = false;  // renderPass was VK_NULL_HANDLE
  VkRenderPass renderPass = VK_NULL_HANDLE;
  uint32_t subpass = 0;
  bool fragmentOutput = true;  // the pipeline has fragment output state (rasterization not statically discarded)
  uint32_t colorCount = 0;  // VkPipelineRenderingCreateInfo::colorAttachmentCount or pColorBlendState->attachmentCount
  uint32_t viewMask = 0;
  VkFormat colorFormats[raster::kMaxColorAttachments] = {};
  VkFormat depthFormat = VK_FORMAT_UNDEFINED, stencilFormat = VK_FORMAT_UNDEFINED;
  // The colour attachment writes the fragment shader was compiled with (its SPMD entry makes them where
  // fragment->graphics.mergesColor; the draw checks the attachment against them).
  abi::ColorMerge colorMerge;
};

class GraphicsPipeline : public Pipeline, public GraphicsPipelineDesc {
 public:
  GraphicsPipeline(Device* dev, VkPipelineCreateFlags flags, PipelineLayout* layout, GraphicsPipelineDesc&& desc)
      : Pipeline(dev, VK_PIPELINE_BIND_POINT_GRAPHICS, flags, layout), GraphicsPipelineDesc(std::move(desc)) {}
};

}  // namespace vkrt::gfx
