// What vkrt supports: each feature with the reason it works (where it is implemented and tested). A feature
// that is not listed is reported VK_FALSE in every structure that has it, and requesting it fails vkCreateDevice.
#include "runtime/supported_features.hpp"

#include <unordered_map>

namespace vkrt {

namespace {

using F = Feature;

constexpr F kSupported[] = {
    // Bounds-checked buffer access in compiled shaders (src/spirv/memory.cpp).
    F::robustBufferAccess,
    // Draws (src/gfx/draw_commands.cpp, draw_executor.cpp): 32-bit index values are read as they are (the index
    // limit is the full range); indirect draws loop over drawCount records (multiDrawIndirect), pass firstInstance
    // through (drawIndirectFirstInstance), and the count variants read the count at execution (drawIndirectCount;
    // tests/e2e draw_indirect_test.cpp).
    F::fullDrawIndexUint32,
    // Multiview: the rasterizer draws once per view of the subpass's (or vkCmdBeginRendering's) view mask into the
    // layer of the view's index (src/raster/draw.cpp), with ViewIndex in vertex and fragment shaders
    // (src/spirv/graphics.cpp); clears, loads and resolves run per view (src/gfx/pass_exec.cpp; tests/e2e
    // MultiviewTest). Not multiviewGeometryShader / multiviewTessellationShader (no such stages).
    F::multiview,
    F::multiDrawIndirect,
    F::drawIndirectFirstInstance,
    F::drawIndirectCount,
    // BaseVertex (firstVertex, or vertexOffset when indexed), BaseInstance and DrawIndex (the record's index in an
    // indirect draw) in vertex shaders: GraphicsInvocation fields set per draw (gfx/draw_executor.cpp,
    // draw_commands.cpp;
    // src/spirv/graphics.cpp; tests/e2e DrawParametersTest).
    F::shaderDrawParameters,
    // The dynamic state of VK_EXT_extended_dynamic_state is Vulkan 1.3's (gfx/dynamic_state.cpp; its EXT-named
    // commands resolve to the same functions; tests/e2e DrawDynamicStateTest, ExtendedDynamicStateTest).
    F::extendedDynamicState,
    // VK_EXT_extended_dynamic_state2: its rasterizer discard, depth bias and primitive restart states are 1.3's; the
    // logic op state (vkCmdSetLogicOpEXT) replaces the pipeline's logicOp at the draw (gfx/dynamic_state.cpp
    // resolveState; tests/e2e ExtendedDynamicState2Test). Not extendedDynamicState2PatchControlPoints: no tessellation.
    F::extendedDynamicState2,
    F::extendedDynamicState2LogicOp,
    // Graphics pipeline state the rasterizer's back end implements from raster::State (src/gfx/graphics_pipeline_
    // state.cpp captures it; src/raster applies it): per-attachment blend state, logic ops, depth clamp, depth bias
    // clamp, depth bounds, alpha to one, sample shading, dual-source blending (fragment outputs with Index 1 reach
    // FragmentQuad::color1).
    F::independentBlend,
    F::logicOp,
    F::depthClamp,
    F::depthBiasClamp,
    F::depthBounds,
    F::alphaToOne,
    F::sampleRateShading,
    F::dualSrcBlend,
    // Occlusion queries count every sample that passes exactly (src/gfx/query_commands.cpp), so the precise count
    // VK_QUERY_CONTROL_PRECISE_BIT asks for is the one always given (tests/e2e DrawOcclusionTest).
    F::occlusionQueryPrecise,
    // Cube and cube array views are sampled with face selection and seamless filtering (runtime/image_functions.cpp
    // vkrt_image_sample_cube; tests/e2e ComputeImageTest.CubeMapsSelectTheFaceFilterAcrossEdgesAndGather).
    F::imageCubeArray,
    // Anisotropic filtering ("Texel Anisotropic Filtering"): the gradient and implicit-LOD forms of a sampler with
    // anisotropyEnable take N = ceil(eta) isotropic samples along the major axis at the minor axis's level of detail
    // and average them (runtime/image_functions.cpp sampleAnisotropic; tests/runtime SamplerAnisotropy.*); explicit
    // Lod has no derivatives and samples once. maxSamplerAnisotropy is 16 (runtime/physical_device.cpp).
    F::samplerAnisotropy,
    // The sixteen BC formats ("Compressed Image Formats"): images laid out in 4x4 blocks (runtime/image.cpp), copies
    // in blocks and between a BC image and a size-compatible uncompressed one (runtime/image_copy.cpp, the block rules
    // in image_commands.cpp), reads of any texel through the block decoders (runtime/bc_texel.cpp, bc_decode.cpp),
    // block-texel-view-compatible uncompressed views; the format features of "Mandatory format support: BC
    // compressed formats" (runtime/format.cpp; tests/e2e CompressedFormatTest, tests/runtime FormatRequired).
    F::textureCompressionBC,
    // 64-bit integers and floats, 8/16-bit integers and 16-bit floats in shaders, and their storage-buffer, uniform
    // and push-constant access (src/spirv; tests/spirv SixtyFourBitIntegersAndDoubles, SpirvCompilerSmallTypes,
    // tests/e2e ComputeSmallTypesTest, ComputeFeaturesTest.EightAndSixteenBitUniformAndPushConstantMembers).
    F::shaderInt64,
    F::shaderFloat64,
    F::shaderInt16,
    F::shaderInt8,
    F::shaderFloat16,
    F::storageBuffer16BitAccess,
    F::uniformAndStorageBuffer16BitAccess,
    F::storagePushConstant16,
    F::storageBuffer8BitAccess,
    F::uniformAndStorageBuffer8BitAccess,
    F::storagePushConstant8,
    // Image accesses outside the view read zeros and write nothing (runtime/image_functions.cpp: every texel address
    // is checked against the view's extent, layers and levels; tests/e2e ComputeImageRobustnessTest).
    F::robustImageAccess,
    // Texel buffer view offsets aligned to a texel (VkPhysicalDeviceTexelBufferAlignmentProperties), checked by
    // vkCreateBufferView (runtime/buffer_view.cpp); the texel buffer functions read texels at any byte.
    F::texelBufferAlignment,
    // VK_SAMPLER_ADDRESS_MODE_MIRROR_CLAMP_TO_EDGE in the image functions' addressing (runtime/image_functions.cpp;
    // tests/e2e ComputeMirrorClampTest).
    F::samplerMirrorClampToEdge,
    // 64-bit integer atomics on storage buffers and workgroup memory: the atomic instructions are width-generic
    // (src/spirv/memory.cpp; tests/e2e ComputeAtomicInt64Test).
    F::shaderBufferInt64Atomics,
    F::shaderSharedInt64Atomics,
    // Timeline semaphores (runtime/semaphore.cpp), host query reset (runtime/query_pool.cpp).
    F::timelineSemaphore,
    F::hostQueryReset,
    // Device addresses are host addresses of the arena (runtime/memory.cpp), reproducible for capture/replay.
    F::bufferDeviceAddress,
    F::bufferDeviceAddressCaptureReplay,
    // Block layouts: the compiler follows Offset/ArrayStride; modules are validated with the enabled rules.
    F::uniformBufferStandardLayout,
    F::scalarBlockLayout,
    // Separate depth/stencil layouts are accepted by barriers and attachments and have no data effect (image
    // layouts are not tracked but for presentable images). Imageless framebuffers: VkFramebufferAttachmentsCreateInfo
    // at creation, the views at vkCmdBeginRenderPass (gfx/framebuffer.cpp, gfx/render_pass_commands.cpp; tests/e2e
    // RenderPassTest.ImagelessFramebuffer).
    F::separateDepthStencilLayouts,
    F::imagelessFramebuffer,
    // Dynamic rendering: vkCmdBeginRendering/vkCmdEndRendering with load/store ops, resolves, suspend/resume and
    // secondary command buffers inheriting VkCommandBufferInheritanceRenderingInfo (gfx/rendering.cpp; tests/e2e
    // RenderPassDynamicTest). Draws inside come from gfx/draw*.
    F::dynamicRendering,
    // Stores and atomics to storage buffers and images in vertex and fragment shaders: the compiler's stores and
    // atomics of every stage; helper lanes of fragment quads write nothing (Codegen::forWrite, writableRecord in
    // src/spirv/graphics.cpp; tests/e2e DrawRenderPassTest counts fragments with atomics, tests/spirv
    // GraphicsShader helper-lane tests).
    F::vertexPipelineStoresAndAtomics,
    F::fragmentStoresAndAtomics,
    // Descriptor binding flags: descriptors are records read when a command executes (runtime/descriptor_set.cpp).
    F::descriptorBindingUniformBufferUpdateAfterBind,
    F::descriptorBindingSampledImageUpdateAfterBind,
    F::descriptorBindingStorageImageUpdateAfterBind,
    F::descriptorBindingStorageBufferUpdateAfterBind,
    F::descriptorBindingUniformTexelBufferUpdateAfterBind,
    F::descriptorBindingStorageTexelBufferUpdateAfterBind,
    F::descriptorBindingUpdateUnusedWhilePending,
    F::descriptorBindingPartiallyBound,
    F::descriptorBindingVariableDescriptorCount,
    // Inline uniform blocks: the bytes live in the descriptor set, whose record for the binding points at them as a
    // uniform buffer's does (runtime/descriptor_set.cpp); writes, copies, templates and update-after-bind
    // (tests/e2e inline_uniform_block_test.cpp).
    F::inlineUniformBlock,
    F::descriptorBindingInlineUniformBlockUpdateAfterBind,
    // Descriptor arrays of buffers, images and texel buffers indexed by any value, also per invocation, and
    // runtime-sized (src/spirv; tests/spirv SpirvDescriptorIndexing, tests/e2e TexelBufferTest). Input attachments
    // (graphics) are not compiled: their indexing features stay off.
    F::shaderUniformBufferArrayDynamicIndexing,
    F::shaderSampledImageArrayDynamicIndexing,
    F::shaderStorageBufferArrayDynamicIndexing,
    F::shaderStorageImageArrayDynamicIndexing,
    F::shaderUniformTexelBufferArrayDynamicIndexing,
    F::shaderStorageTexelBufferArrayDynamicIndexing,
    F::shaderUniformBufferArrayNonUniformIndexing,
    F::shaderSampledImageArrayNonUniformIndexing,
    F::shaderStorageBufferArrayNonUniformIndexing,
    F::shaderStorageImageArrayNonUniformIndexing,
    F::shaderUniformTexelBufferArrayNonUniformIndexing,
    F::shaderStorageTexelBufferArrayNonUniformIndexing,
    F::runtimeDescriptorArray,
    // Every feature the specification's Feature Requirements ask of descriptorIndexing (and of the
    // VK_EXT_descriptor_indexing extension) is in this list: the indexing above, the update-after-bind flags of
    // sampled and storage images, storage buffers and both texel buffers, unused-while-pending, partially bound
    // and runtime arrays.
    F::descriptorIndexing,
    // Storage images read and written without a format in the shader (Image Format Unknown): the image functions
    // convert from and to the bound view's format at run time, for every storage format (src/spirv/image.cpp,
    // runtime/image_functions.cpp; format.cpp reports STORAGE_READ/WRITE_WITHOUT_FORMAT for them). tests/spirv
    // SpirvFormatlessImages, tests/e2e
    // ComputeFormatless*, FormatlessRaygenTest.
    F::shaderStorageImageReadWithoutFormat,
    F::shaderStorageImageWriteWithoutFormat,
    // Workgroup memory: zeroed for every workgroup, so initializers (OpConstantNull) hold; explicit layouts of
    // Block variables that alias (src/spirv/memory.cpp; tests/spirv SpirvConformance.WorkgroupMemory*).
    F::shaderZeroInitializeWorkgroupMemory,
    F::workgroupMemoryExplicitLayout,
    F::workgroupMemoryExplicitLayoutScalarBlockLayout,
    F::workgroupMemoryExplicitLayout8BitAccess,
    F::workgroupMemoryExplicitLayout16BitAccess,
    // Integer dot products (SPV_KHR_integer_dot_product; none reported as accelerated): src/spirv/arithmetic.cpp,
    // tests/spirv SpirvConformance.IntegerDotProducts.
    F::shaderIntegerDotProduct,
    // Subgroup size control: subgroups have one invocation, so a required size is 1 and subgroups are always full;
    // the rules are checked for every pipeline kind (runtime/shader_stage.cpp; tests/e2e SubgroupSizeControlTest).
    F::subgroupSizeControl,
    F::computeFullSubgroups,
    // Fragment termination: OpTerminateInvocation ends the fragment, OpDemoteToHelperInvocation makes it a helper
    // whose writes land nowhere; neither writes the attachments (src/spirv/graphics.cpp, gfx/draw_executor.cpp;
    // tests/spirv GraphicsShader.Discard*, tests/e2e DrawTerminationTest).
    F::shaderDemoteToHelperInvocation,
    F::shaderTerminateInvocation,
    // Subgroups of one invocation with the vote and ballot operations: a broadcast reads the only invocation
    // whatever its id, constant or dynamic, and whatever the value's type, 8/16/64-bit included (the basic, vote and
    // ballot operations are all there is: src/spirv/arithmetic.cpp; tests/e2e Vulkan13RequirementsTest.Subgroup*).
    F::subgroupBroadcastDynamicId,
    F::shaderSubgroupExtendedTypes,
    // The Vulkan memory model, also at Device scope: the compiler accepts its capabilities and operands; its atomics
    // are sequentially consistent and its barriers full fences on coherent host memory (src/spirv/opcode_support.cpp
    // says why that is enough; tests/e2e MemoryModelTest). Availability/visibility chains stay off.
    F::vulkanMemoryModel,
    F::vulkanMemoryModelDeviceScope,
    // Private data slots: a value per object, kept by the object's serial (runtime/private_data_slot.cpp;
    // tests/e2e PrivateDataTest).
    F::privateData,
    // Vulkan 1.3: synchronization2 commands, FAIL_ON_PIPELINE_COMPILE_REQUIRED / EARLY_RETURN, maintenance4.
    F::synchronization2,
    F::pipelineCreationCacheControl,
    F::maintenance4,
    // Ray tracing pipelines (src/rt): handles, capture/replay (also mixed with non-replayed pipelines: handles are
    // content-derived), indirect traces, primitive culling flags, library group handles (tests/e2e rt_*, trace_*).
    F::rayTracingPipeline,
    F::rayTracingPipelineShaderGroupHandleCaptureReplay,
    F::rayTracingPipelineShaderGroupHandleCaptureReplayMixed,
    F::rayTracingPipelineTraceRaysIndirect,
    F::rayTraversalPrimitiveCulling,
    F::pipelineLibraryGroupHandles,
    F::rayTracingMaintenance1,
    F::rayTracingPipelineTraceRaysIndirect2,
    // Ray queries in compute and ray tracing shaders (src/spirv/ray_query.cpp, src/exec/ray_query.cpp, accel's
    // queryProceed; tests/e2e ray_query_test.cpp).
    F::rayQuery,
    // VK_KHR_ray_tracing_position_fetch: a triangle hit's object-space vertices, from the Blas's copy
    // (accel::trianglePositions), in any-hit and closest-hit shaders and ray queries (tests/e2e PositionFetch*).
    F::rayTracingPositionFetch,
    // Acceleration structures on src/accel: capture/replay at the buffer's address, indirect and host builds (the
    // device's memory is host memory), update-after-bind descriptors (tests/e2e trace_as_test.cpp).
    F::accelerationStructure,
    F::accelerationStructureCaptureReplay,
    F::accelerationStructureIndirectBuild,
    F::accelerationStructureHostCommands,
    F::descriptorBindingAccelerationStructureUpdateAfterBind,
};

}  // namespace

const FeatureSet& supportedFeatures() {
  static const FeatureSet set = [] {
    FeatureSet s;
    for (F f : kSupported) s.set(size_t(f));
    return s;
  }();
  return set;
}

const FeatureStruct* featureStruct(VkStructureType sType) {
  static const auto* index = [] {
    auto* m = new std::unordered_map<uint32_t, const FeatureStruct*>;
    for (size_t i = 0; i < kFeatureStructCount; ++i)
      if (kFeatureStructs[i].sType) (*m)[uint32_t(kFeatureStructs[i].sType)] = &kFeatureStructs[i];
    return m;
  }();
  auto it = index->find(uint32_t(sType));
  return it == index->end() ? nullptr : it->second;
}

const PropertyStruct* propertyStruct(VkStructureType sType) {
  static const auto* index = [] {
    auto* m = new std::unordered_map<uint32_t, const PropertyStruct*>;
    for (size_t i = 0; i < kPropertyStructCount; ++i) (*m)[uint32_t(kPropertyStructs[i].sType)] = &kPropertyStructs[i];
    return m;
  }();
  auto it = index->find(uint32_t(sType));
  return it == index->end() ? nullptr : it->second;
}

}  // namespace vkrt
