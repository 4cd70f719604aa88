// Ray tracing pipeline interface checks of vkCreateRayTracingPipelinesKHR: VkRayTracingPipelineInterfaceCreateInfoKHR
// against what each stage's SPIR-V declares, the library rules on pLibraryInterface, pipeline layout compatibility
// of libraries with the pipeline linking them (compared structurally, not by handle), and hit attributes in the
// per-shader stack size.
#include <algorithm>
#include <string>
#include <vector>

#include "e2e/rt_fixture.hpp"
#include "rt_rint.rint.spv.h"
#include "stack_chit_trace.rchit.spv.h"
#include "stack_chit_trace_attr.rchit.spv.h"

namespace vkrt::test {
namespace {

class RtInterfaceTest : public RtTest {
 protected:
  void SetUp() override {
    RtTest::SetUp();
    if (HasFatalFailure() || !device) return;
    chitTraceAttr = module(kSpv_stack_chit_trace_attr_rchit, sizeof(kSpv_stack_chit_trace_attr_rchit));
    chitTrace = module(kSpv_stack_chit_trace_rchit, sizeof(kSpv_stack_chit_trace_rchit));
  }
  void TearDown() override {
    if (device) {
      for (VkPipelineLayout l : layouts) vkDestroyPipelineLayout(device, l, nullptr);
      for (VkDescriptorSetLayout l : setLayouts) vkDestroyDescriptorSetLayout(device, l, nullptr);
    }
    RtTest::TearDown();
  }

  // A set layout with one binding (0 unless given) of `type`, visible to `stages` (raygen unless given).
  VkDescriptorSetLayout setLayout(VkDescriptorType type, uint32_t binding = 0,
                                  VkShaderStageFlags stages = VK_SHADER_STAGE_RAYGEN_BIT_KHR) {
    VkDescriptorSetLayoutBinding b{binding, type, 1, stages, nullptr};
    VkDescriptorSetLayoutCreateInfo ci{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    ci.bindingCount = 1;
    ci.pBindings = &b;
    VkDescriptorSetLayout l = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreateDescriptorSetLayout(device, &ci, nullptr, &l), VK_SUCCESS);
    setLayouts.push_back(l);
    return l;
  }
  // A pipeline layout with `sets` and one push-constant range of `pcSize` bytes for `pcStages`.
  VkPipelineLayout pipelineLayout(std::vector<VkDescriptorSetLayout> sets, uint32_t pcSize = 8,
                                  VkShaderStageFlags pcStages = VK_SHADER_STAGE_RAYGEN_BIT_KHR) {
    VkPushConstantRange pc{pcStages, 0, pcSize};
    VkPipelineLayoutCreateInfo ci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    ci.setLayoutCount = static_cast<uint32_t>(sets.size());
    ci.pSetLayouts = sets.data();
    ci.pushConstantRangeCount = 1;
    ci.pPushConstantRanges = &pc;
    VkPipelineLayout l = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreatePipelineLayout(device, &ci, nullptr, &l), VK_SUCCESS);
    layouts.push_back(l);
    return l;
  }
  void destroyLayout(VkPipelineLayout l) {
    vkDestroyPipelineLayout(device, l, nullptr);
    layouts.erase(std::find(layouts.begin(), layouts.end(), l));
  }

  // A library of one raygen group created with `layout`.
  VkPipeline raygenLibrary(VkPipelineLayout layout) {
    Desc a;
    a.flags = VK_PIPELINE_CREATE_LIBRARY_BIT_KHR;
    a.layout = layout;
    a.general(raygen, VK_SHADER_STAGE_RAYGEN_BIT_KHR);
    return make(a);
  }

  VkShaderModule chitTraceAttr{}, chitTrace{};
  std::vector<VkPipelineLayout> layouts;
  std::vector<VkDescriptorSetLayout> setLayouts;
};

// Misuse: vkrt's own messages, the layer off (see RtMisuseTest in rt_pipeline_test.cpp).
class RtInterfaceMisuseTest : public RtInterfaceTest {
 protected:
  bool layer() override { return false; }
  void SetUp() override {
    RtInterfaceTest::SetUp();
    if (!HasFatalFailure() && !vkrt) GTEST_SKIP() << "vkrt's own diagnostics";
  }
  // Expects the creation to fail with VK_ERROR_VALIDATION_FAILED_EXT, no pipeline, and one vkrt report that
  // contains every piece of `parts`; returns its text.
  std::string expectRefused(Desc& d, const std::vector<std::string>& parts) {
    VkPipeline p = VK_NULL_HANDLE;
    EXPECT_EQ(create(d, &p), VK_ERROR_VALIDATION_FAILED_EXT);
    EXPECT_EQ(p, VK_NULL_HANDLE);
    auto msgs = vkrtMessages();
    clearMessages();
    if (msgs.size() != 1) {
      ADD_FAILURE() << "expected one vkrt report, got " << msgs.size();
      return {};
    }
    for (const std::string& part : parts)
      EXPECT_NE(msgs[0].text.find(part), std::string::npos) << part << " in: " << msgs[0].text;
    return msgs[0].text;
  }
};

TEST_F(RtInterfaceMisuseTest, LayoutMustProvideTheShadersResources) {
  // rt_rint.rint writes a storage buffer at set 0 binding 2.
  VkShaderModule sphere = module(kSpv_rt_rint_rint, sizeof(kSpv_rt_rint_rint));
  auto withSphere = [&](VkPipelineLayout l) {
    Desc d;
    d.layout = l;
    d.general(raygen, VK_SHADER_STAGE_RAYGEN_BIT_KHR);
    uint32_t c = d.stage(chit, VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR);
    uint32_t i = d.stage(sphere, VK_SHADER_STAGE_INTERSECTION_BIT_KHR);
    d.group(VK_RAY_TRACING_SHADER_GROUP_TYPE_PROCEDURAL_HIT_GROUP_KHR, VK_SHADER_UNUSED_KHR, c, VK_SHADER_UNUSED_KHR,
            i);
    return d;
  };
  const char* vuid = "VUID-VkRayTracingPipelineCreateInfoKHR-layout-03427";
  Desc none = withSphere(layout);  // the fixture's layout has no set
  expectRefused(none, {vuid, "pStages[2]", "set 0 binding 2", "does not have"});
  Desc uniform = withSphere(
      pipelineLayout({setLayout(VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 2, VK_SHADER_STAGE_INTERSECTION_BIT_KHR)}));
  expectRefused(uniform, {vuid, "pStages[2]", "storage buffer descriptor", "VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER"});
  Desc hidden =
      withSphere(pipelineLayout({setLayout(VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 2, VK_SHADER_STAGE_RAYGEN_BIT_KHR)}));
  expectRefused(hidden, {vuid, "pStages[2]", "does not make visible"});
  Desc right = withSphere(
      pipelineLayout({setLayout(VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 2, VK_SHADER_STAGE_INTERSECTION_BIT_KHR)}));
  VkPipeline p = VK_NULL_HANDLE;
  EXPECT_EQ(create(right, &p), VK_SUCCESS);
  EXPECT_NE(p, VK_NULL_HANDLE);
}

TEST_F(RtInterfaceTest, InterfaceCoveringEveryShaderIsAccepted) {
  // The six-group pipeline declares payloads of 16 bytes (raygen, miss, closest hit) and hit attributes of 8
  // (closest hit, any hit, intersection): exactly that interface is enough.
  Desc d = sixGroups();
  d.maxPayload = 16;
  d.maxHitAttr = 8;
  make(d);
  Desc big;  // a 256-byte payload
  big.general(raygenBig, VK_SHADER_STAGE_RAYGEN_BIT_KHR);
  big.maxPayload = 256;
  big.maxHitAttr = 0;
  make(big);
  Desc attr;  // 16-byte hit attributes
  attr.general(raygen, VK_SHADER_STAGE_RAYGEN_BIT_KHR);
  uint32_t c = attr.stage(chitTraceAttr, VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR);
  attr.group(VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR, VK_SHADER_UNUSED_KHR, c);
  attr.depth = 2;
  attr.maxPayload = 16;
  attr.maxHitAttr = 16;
  make(attr);
}

TEST_F(RtInterfaceMisuseTest, ShaderDeclaringMoreThanTheInterfaceIsRefused) {
  // The specification defines maxPipelineRayPayloadSize / maxPipelineRayHitAttributeSize as the largest block any
  // shader of the pipeline declares, without a VUID: vkrt reports it without one, naming the stage and the sizes.
  Desc big;
  big.general(raygenBig, VK_SHADER_STAGE_RAYGEN_BIT_KHR);
  big.maxPayload = 255;
  big.maxHitAttr = 8;
  expectRefused(big, {"pCreateInfos[0].pStages[0]", "ray payload of 256 bytes", "maxPipelineRayPayloadSize 255"});
  // The incoming payload counts too: the miss shader (pStages[1]) of a 16-byte payload, the raygen's is 16 as well.
  Desc d = sixGroups();
  d.maxPayload = 15;
  d.maxHitAttr = 8;
  expectRefused(d, {"pStages[0]", "ray payload of 16 bytes", "maxPipelineRayPayloadSize 15"});
  // Hit attributes: the closest-hit shader declares 8 bytes (pStages[3]).
  Desc h = sixGroups();
  h.maxPayload = 16;
  h.maxHitAttr = 4;
  expectRefused(h, {"pStages[3]", "hit attribute of 8 bytes", "maxPipelineRayHitAttributeSize 4"});
  // A library is checked against its own interface.
  Desc lib;
  lib.flags = VK_PIPELINE_CREATE_LIBRARY_BIT_KHR;
  uint32_t c = lib.stage(chitTraceAttr, VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR);
  lib.group(VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR, VK_SHADER_UNUSED_KHR, c);
  lib.maxPayload = 16;
  lib.maxHitAttr = 12;
  expectRefused(lib, {"pStages[0]", "hit attribute of 16 bytes", "maxPipelineRayHitAttributeSize 12"});
  // With a deferred operation the report comes from the joining thread, and the operation's result is the error.
  VkDeferredOperationKHR op = VK_NULL_HANDLE;
  ASSERT_EQ(createOp(device, nullptr, &op), VK_SUCCESS);
  Desc deferred = big;
  VkPipeline p = VK_NULL_HANDLE;
  ASSERT_EQ(create(deferred, &p, op), VK_OPERATION_DEFERRED_KHR);
  EXPECT_EQ(joinOp(device, op), VK_SUCCESS);
  EXPECT_EQ(opResult(device, op), VK_ERROR_VALIDATION_FAILED_EXT);
  EXPECT_EQ(p, VK_NULL_HANDLE);
  auto msgs = vkrtMessages();
  ASSERT_EQ(msgs.size(), 1u);
  EXPECT_NE(msgs[0].text.find("maxPipelineRayPayloadSize 255"), std::string::npos) << msgs[0].text;
  clearMessages();
  destroyOp(device, op, nullptr);
}

TEST_F(RtInterfaceMisuseTest, RefusedCreationLeavesThePipelineCacheUntouched) {
  VkPipelineCacheCreateInfo cci{VK_STRUCTURE_TYPE_PIPELINE_CACHE_CREATE_INFO};
  VkPipelineCache cache = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreatePipelineCache(device, &cci, nullptr, &cache), VK_SUCCESS);
  size_t empty = 0;
  ASSERT_EQ(vkGetPipelineCacheData(device, cache, &empty, nullptr), VK_SUCCESS);
  Desc big;
  big.general(raygenBig, VK_SHADER_STAGE_RAYGEN_BIT_KHR);
  big.maxPayload = 128;
  big.maxHitAttr = 0;
  VkPipeline p = VK_NULL_HANDLE;
  EXPECT_EQ(create(big, &p, VK_NULL_HANDLE, cache), VK_ERROR_VALIDATION_FAILED_EXT);
  EXPECT_EQ(vkrtMessages().size(), 1u);
  clearMessages();
  size_t after = 0;
  ASSERT_EQ(vkGetPipelineCacheData(device, cache, &after, nullptr), VK_SUCCESS);
  EXPECT_EQ(after, empty);
  // The same shader under an interface that admits it does enter the cache (so the check above can fail).
  big.maxPayload = 256;
  ASSERT_EQ(create(big, &p, VK_NULL_HANDLE, cache), VK_SUCCESS);
  ASSERT_EQ(vkGetPipelineCacheData(device, cache, &after, nullptr), VK_SUCCESS);
  EXPECT_GT(after, empty);
  vkDestroyPipelineCache(device, cache, nullptr);
}

TEST_F(RtInterfaceMisuseTest, LibraryInterfaceRules) {
  {  // VUID-VkRayTracingPipelineCreateInfoKHR-flags-03465: a library needs pLibraryInterface
    Desc d;
    d.flags = VK_PIPELINE_CREATE_LIBRARY_BIT_KHR;
    d.general(raygen, VK_SHADER_STAGE_RAYGEN_BIT_KHR);
    d.omitInterface = true;
    expectRefused(d, {"VUID-VkRayTracingPipelineCreateInfoKHR-flags-03465", "pCreateInfos[0]"});
  }
  {  // VUID-VkRayTracingPipelineInterfaceCreateInfoKHR-maxPipelineRayHitAttributeSize-03605
    Desc d;
    d.flags = VK_PIPELINE_CREATE_LIBRARY_BIT_KHR;
    d.general(raygen, VK_SHADER_STAGE_RAYGEN_BIT_KHR);
    d.maxPayload = 16;
    d.maxHitAttr = 33;
    expectRefused(d, {"VUID-VkRayTracingPipelineInterfaceCreateInfoKHR-maxPipelineRayHitAttributeSize-03605",
                      "maxPipelineRayHitAttributeSize 33", "maxRayHitAttributeSize 32"});
    d.maxHitAttr = 32;  // the limit itself is fine
    make(d);
  }
  // A library made with the default interface (256 / 8).
  Desc a;
  a.flags = VK_PIPELINE_CREATE_LIBRARY_BIT_KHR;
  a.general(raygen, VK_SHADER_STAGE_RAYGEN_BIT_KHR);
  VkPipeline lib = make(a);
  {  // VUID-VkRayTracingPipelineCreateInfoKHR-pLibraryInfo-03593: another hit attribute size
    Desc d;
    d.libraries = {lib};
    d.maxPayload = 256;
    d.maxHitAttr = 16;
    expectRefused(d, {"VUID-VkRayTracingPipelineCreateInfoKHR-pLibraryInfo-03593", "maxPipelineRayHitAttributeSize 8",
                      "interface 256 / 16"});
  }
  {  // VUID-VkRayTracingPipelineCreateInfoKHR-pLibraryInfo-03590: libraries without pLibraryInterface
    Desc d;
    d.libraries = {lib};
    d.omitInterface = true;
    expectRefused(d, {"VUID-VkRayTracingPipelineCreateInfoKHR-pLibraryInfo-03590"});
  }
  Desc ok;  // the control: the same interface links
  ok.libraries = {lib};
  make(ok);
}

TEST_F(RtInterfaceTest, LibrariesLinkWithLayoutsDefinedTheSame) {
  // Compatibility is about how layouts are defined, not which objects they are: a library made with another
  // layout object of the same definition links, also after that layout was destroyed.
  VkPipelineLayout twin = pipelineLayout({});  // the fixture's layout: no sets, push constants 0..8 for raygen
  VkPipeline lib = raygenLibrary(twin);
  destroyLayout(twin);
  Desc d;
  d.libraries = {lib};
  VkPipeline p = make(d);
  if (vkrt) {  // the library's group is the same group (vkrt's content-derived handles)
    Desc solo;
    solo.general(raygen, VK_SHADER_STAGE_RAYGEN_BIT_KHR);
    EXPECT_EQ(handles(p, 0, 1), handles(make(solo), 0, 1));
  }
  // With descriptor sets: two set layouts of the same definition, in two pipeline layouts.
  VkPipelineLayout withSet1 = pipelineLayout({setLayout(VK_DESCRIPTOR_TYPE_STORAGE_BUFFER)});
  VkPipelineLayout withSet2 = pipelineLayout({setLayout(VK_DESCRIPTOR_TYPE_STORAGE_BUFFER)});
  VkPipeline lib2 = raygenLibrary(withSet1);
  Desc e;
  e.libraries = {lib2};
  e.layout = withSet2;
  make(e);
}

TEST_F(RtInterfaceMisuseTest, LibrariesWithIncompatibleLayoutsAreRefused) {
  const char* vuid = "VUID-VkRayTracingPipelineCreateInfoKHR-pLibraryInfo-03592";
  struct Case {
    const char* name;
    VkPipelineLayout library, pipeline;
    std::string detail;
  };
  VkDescriptorSetLayout storage = setLayout(VK_DESCRIPTOR_TYPE_STORAGE_BUFFER);
  VkDescriptorSetLayout uniform = setLayout(VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER);
  std::vector<Case> cases = {
      {"push-constant size", pipelineLayout({}, 16), layout,
       "push-constant range {offset 0, size 8, stages 0x100}, the library's {offset 0, size 16, stages 0x100}"},
      {"push-constant stages", pipelineLayout({}, 8, VK_SHADER_STAGE_RAYGEN_BIT_KHR | VK_SHADER_STAGE_MISS_BIT_KHR),
       layout, "stages 0x100}, the library's {offset 0, size 8, stages 0x900}"},
      {"set count", pipelineLayout({storage}), layout, "the pipeline's layout has 0 set layouts, the library's 1"},
      {"descriptor type", pipelineLayout({storage}), pipelineLayout({uniform}),
       "set 0: binding 0 (type 6, count 1, stages 0x100, flags 0x0), the library's binding 0 (type 7"},
  };
  for (const Case& c : cases) {
    VkPipeline lib = raygenLibrary(c.library);
    Desc d;
    d.libraries = {lib};
    d.layout = c.pipeline;
    std::string text = expectRefused(d, {vuid, "pLibraries[0]", c.detail});
    EXPECT_FALSE(text.empty()) << c.name;
  }
}

TEST_F(RtInterfaceTest, HitAttributesCountInTheStackSizeOfAShaderThatTraces) {
  // Stack sizes are vkrt's own figures (spirv::RayStageInfo::stackSize: the compiled frame, plus the hit
  // attributes a shader that calls reads): the two closest-hit shaders differ only in the 16-byte hit attributes
  // the first reads after its traceRayEXT.
  if (!vkrt) GTEST_SKIP() << "exact stack sizes are vkrt's own";
  Desc d;
  d.depth = 2;
  d.general(raygen, VK_SHADER_STAGE_RAYGEN_BIT_KHR);
  uint32_t withAttr = d.stage(chitTraceAttr, VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR);
  d.group(VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR, VK_SHADER_UNUSED_KHR, withAttr);
  uint32_t without = d.stage(chitTrace, VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR);
  d.group(VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR, VK_SHADER_UNUSED_KHR, without);
  uint32_t plain = d.stage(chit, VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR);
  d.group(VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR, VK_SHADER_UNUSED_KHR, plain);
  VkPipeline p = make(d);
  VkDeviceSize with = getStackSize(device, p, 1, VK_SHADER_GROUP_SHADER_CLOSEST_HIT_KHR);
  VkDeviceSize plainTrace = getStackSize(device, p, 2, VK_SHADER_GROUP_SHADER_CLOSEST_HIT_KHR);
  // The frame holds at least the 16-byte outgoing payload and the trace's 72 bytes of arguments.
  EXPECT_GE(plainTrace, 16u + 72u);
  EXPECT_EQ(plainTrace % 16, 0u);
  EXPECT_GE(with, plainTrace + 16u);
  EXPECT_LE(with, plainTrace + 64u);
  // hit attributes but no call: nothing is live while another shader runs
  EXPECT_EQ(getStackSize(device, p, 3, VK_SHADER_GROUP_SHADER_CLOSEST_HIT_KHR), 0u);
}

}  // namespace
}  // namespace vkrt::test
