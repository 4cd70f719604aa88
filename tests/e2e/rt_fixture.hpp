// The ray tracing e2e fixture (RtTest) shared by tests/e2e/rt_*_test.cpp and trace_*_test.cpp, and helpers for
// cross-process tests.
//
// The device has VK_KHR_acceleration_structure, VK_KHR_ray_tracing_pipeline, VK_KHR_pipeline_library,
// VK_EXT_pipeline_library_group_handles and VK_KHR_deferred_host_operations. Validation layer note: the layer
// (1.3.239) is older than VK_EXT_pipeline_library_group_handles, so it reports VUID-VkDeviceCreateInfo-pNext-pNext
// for its feature structure (sType 1000498000) and the warning "Device Extension
// VK_EXT_pipeline_library_group_handles is not supported by this layer" (VUID_Undefined) at vkCreateDevice.
// RtTest::acceptKnownLayerMessages (after SetUp and before TearDown) accepts exactly those two and fails on any
// other layer message. The layer drops the group-handles feature structure it does not know, so library handle
// tests run without it (RtLibraryTest). (VK_NV_ray_tracing's commands, which resolve only with that extension, are
// tested in tests/e2e/trace_nv_test.cpp.)
//
// On other drivers (device name not "vkrt") the tests of Vulkan behaviour run as well; assertions about vkrt's own
// choices (exact stack sizes, handles identical across processes, deferred-operation scheduling, vkrt's messages
// for misuse) are skipped there, each with a comment. The fixture enables only the features the driver reports
// (NVIDIA has no rayTracingPipelineShaderGroupHandleCaptureReplayMixed); tests that need one skip without it.
#pragma once

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <set>
#include <thread>

#include "e2e/fixture.hpp"
#include "pipeline_ahit.rahit.spv.h"
#include "pipeline_call.rcall.spv.h"
#include "pipeline_chit.rchit.spv.h"
#include "pipeline_chit_callable.rchit.spv.h"
#include "pipeline_miss.rmiss.spv.h"
#include "pipeline_miss2.rmiss.spv.h"
#include "pipeline_miss_spec.rmiss.spv.h"
#include "pipeline_raygen.rgen.spv.h"
#include "pipeline_raygen_big_payload.rgen.spv.h"
#include "pipeline_rint.rint.spv.h"
#include "runtime/vk_compat.h"  // VK_EXT_pipeline_library_group_handles is newer than the installed headers

namespace vkrt::test {

// The layer (1.3.239) predates VK_EXT_pipeline_library_group_handles: it does not know
// VkPhysicalDevicePipelineLibraryGroupHandlesFeaturesEXT (sType 1000498000) in VkDeviceCreateInfo::pNext.
inline constexpr const char* kUnknownStructMessage = "VUID-VkDeviceCreateInfo-pNext-pNext";

// True when the physical device is vkrt: checks of vkrt's own choices and diagnostics are skipped on other drivers.
inline bool isVkrt(VkPhysicalDevice pd) {
  VkPhysicalDeviceProperties p;
  vkGetPhysicalDeviceProperties(pd, &p);
  return std::strcmp(p.deviceName, "vkrt") == 0;
}

class RtTest : public VulkanTest {
 protected:
  // The features the driver supports, read by querySupport() before options() is used.
  VkPhysicalDeviceRayTracingPipelineFeaturesKHR supportedRt{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_FEATURES_KHR};
  VkPhysicalDevicePipelineLibraryGroupHandlesFeaturesEXT supportedLgh{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PIPELINE_LIBRARY_GROUP_HANDLES_FEATURES_EXT};
  VkPhysicalDeviceAccelerationStructureFeaturesKHR supportedAs{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR};
  bool vkrt = false;
  VkPhysicalDeviceRayTracingPipelineFeaturesKHR rtf{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_FEATURES_KHR};
  VkPhysicalDevicePipelineLibraryGroupHandlesFeaturesEXT lgh{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PIPELINE_LIBRARY_GROUP_HANDLES_FEATURES_EXT};
  VkPhysicalDeviceAccelerationStructureFeaturesKHR asf{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR};
  bool libraryGroupHandles = true;
  bool captureReplay = true;
  bool captureReplayMixed = true;  // enabled where supported (with captureReplay)

  virtual bool layer() { return true; }

  FixtureOptions options() override {
    FixtureOptions o;
    o.validation = layer();
    o.deviceExtensions = {VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME, VK_KHR_PIPELINE_LIBRARY_EXTENSION_NAME,
                          VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME, VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME,
                          VK_EXT_PIPELINE_LIBRARY_GROUP_HANDLES_EXTENSION_NAME};
    // Only what the driver supports is enabled (enabling an unsupported feature fails vkCreateDevice with
    // VK_ERROR_FEATURE_NOT_PRESENT).
    rtf.rayTracingPipeline = supportedRt.rayTracingPipeline;
    rtf.rayTracingPipelineShaderGroupHandleCaptureReplay =
        captureReplay && supportedRt.rayTracingPipelineShaderGroupHandleCaptureReplay;
    rtf.rayTracingPipelineShaderGroupHandleCaptureReplayMixed =
        captureReplay && captureReplayMixed && supportedRt.rayTracingPipelineShaderGroupHandleCaptureReplayMixed;
    rtf.pNext = &lgh;
    lgh.pipelineLibraryGroupHandles = libraryGroupHandles && supportedLgh.pipelineLibraryGroupHandles;
    lgh.pNext = &asf;
    asf.accelerationStructure = VK_TRUE;
    o.featureChain = &rtf;
    return o;
  }

  // Reads the supported features through an instance of its own (without the layer), before the fixture's
  // instance and device exist.
  void querySupport() {
    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.apiVersion = VK_API_VERSION_1_3;
    VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    ici.pApplicationInfo = &app;
    VkInstance inst = VK_NULL_HANDLE;
    ASSERT_EQ(vkCreateInstance(&ici, nullptr, &inst), VK_SUCCESS);
    uint32_t n = 1;
    VkPhysicalDevice pd = VK_NULL_HANDLE;
    VkResult r = vkEnumeratePhysicalDevices(inst, &n, &pd);  // the first one, as the fixture takes
    if ((r == VK_SUCCESS || r == VK_INCOMPLETE) && n >= 1) {
      supportedAs.pNext = nullptr;
      supportedLgh.pNext = &supportedAs;
      supportedRt.pNext = &supportedLgh;
      VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &supportedRt};
      vkGetPhysicalDeviceFeatures2(pd, &f2);
      supportedRt.pNext = supportedLgh.pNext = nullptr;
      vkrt = isVkrt(pd);
    }
    vkDestroyInstance(inst, nullptr);
    ASSERT_GE(n, 1u) << "no physical device";
    ASSERT_TRUE(supportedRt.rayTracingPipeline) << "rayTracingPipeline is not supported";
  }

  // True when the capture/replay tests may interleave replayed pipelines with others.
  bool mixedEnabled() const { return rtf.rayTracingPipelineShaderGroupHandleCaptureReplayMixed; }

  void SetUp() override {
    querySupport();
    if (HasFatalFailure()) return;
    VulkanTest::SetUp();
    // A failed SetUp (e.g. vkCreateDevice) must not go on with a null device; TearDown still runs.
    if (HasFatalFailure()) return;
    acceptKnownLayerMessages();
    load(createPipelines, "vkCreateRayTracingPipelinesKHR");
    load(getHandles, "vkGetRayTracingShaderGroupHandlesKHR");
    load(getCapture, "vkGetRayTracingCaptureReplayShaderGroupHandlesKHR");
    load(getStackSize, "vkGetRayTracingShaderGroupStackSizeKHR");
    load(createOp, "vkCreateDeferredOperationKHR");
    load(destroyOp, "vkDestroyDeferredOperationKHR");
    load(joinOp, "vkDeferredOperationJoinKHR");
    load(opResult, "vkGetDeferredOperationResultKHR");
    load(opConcurrency, "vkGetDeferredOperationMaxConcurrencyKHR");
    VkPushConstantRange pc{VK_SHADER_STAGE_RAYGEN_BIT_KHR, 0, 8};
    VkPipelineLayoutCreateInfo lci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    lci.pushConstantRangeCount = 1;
    lci.pPushConstantRanges = &pc;
    ASSERT_EQ(vkCreatePipelineLayout(device, &lci, nullptr, &layout), VK_SUCCESS);
    raygen = module(kSpv_pipeline_raygen_rgen, sizeof(kSpv_pipeline_raygen_rgen));
    raygenBig = module(kSpv_pipeline_raygen_big_payload_rgen, sizeof(kSpv_pipeline_raygen_big_payload_rgen));
    miss = module(kSpv_pipeline_miss_rmiss, sizeof(kSpv_pipeline_miss_rmiss));
    miss2 = module(kSpv_pipeline_miss2_rmiss, sizeof(kSpv_pipeline_miss2_rmiss));
    missSpec = module(kSpv_pipeline_miss_spec_rmiss, sizeof(kSpv_pipeline_miss_spec_rmiss));
    chit = module(kSpv_pipeline_chit_rchit, sizeof(kSpv_pipeline_chit_rchit));
    chitCall = module(kSpv_pipeline_chit_callable_rchit, sizeof(kSpv_pipeline_chit_callable_rchit));
    ahit = module(kSpv_pipeline_ahit_rahit, sizeof(kSpv_pipeline_ahit_rahit));
    rint = module(kSpv_pipeline_rint_rint, sizeof(kSpv_pipeline_rint_rint));
    call = module(kSpv_pipeline_call_rcall, sizeof(kSpv_pipeline_call_rcall));
  }

  // The layer messages caused by the layer being older than VK_EXT_pipeline_library_group_handles (see the top of
  // this file): exactly these are accepted.
  void acceptKnownLayerMessages() {
    for (const Message& m : layerMessages()) {
      bool expected =
          (m.idName == kUnknownStructMessage && m.text.find("(1000498000)") != std::string::npos) ||
          (m.idName == "VUID_Undefined" &&
           m.text.find("VK_EXT_pipeline_library_group_handles is not supported by this layer") != std::string::npos);
      EXPECT_TRUE(expected) << "unexpected validation message: " << m.text.substr(0, 300);
    }
    auto own = vkrtMessages();
    clearMessages();
    for (const Message& m : own) ADD_FAILURE() << "unexpected vkrt report: " << m.text;
  }

  void TearDown() override {
    if (!device) {  // SetUp failed (already reported): only the fixture's own clean-up
      VulkanTest::TearDown();
      return;
    }
    acceptKnownLayerMessages();
    for (VkPipeline p : pipelines) vkDestroyPipeline(device, p, nullptr);
    for (VkShaderModule m : modules) vkDestroyShaderModule(device, m, nullptr);
    if (layout) vkDestroyPipelineLayout(device, layout, nullptr);
    VulkanTest::TearDown();
  }

  template <class F>
  void load(F& f, const char* name) {
    f = reinterpret_cast<F>(vkGetDeviceProcAddr(device, name));
    ASSERT_NE(f, nullptr) << name;
  }

  VkShaderModule module(const uint32_t* words, size_t bytes) {
    VkShaderModuleCreateInfo ci{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    ci.codeSize = bytes;
    ci.pCode = words;
    VkShaderModule m = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreateShaderModule(device, &ci, nullptr, &m), VK_SUCCESS);
    modules.push_back(m);
    return m;
  }

  // A pipeline description being built.
  struct Desc {
    std::vector<VkPipelineShaderStageCreateInfo> stages;
    std::vector<VkRayTracingShaderGroupCreateInfoKHR> groups;
    std::vector<VkPipeline> libraries;
    VkPipelineCreateFlags flags = 0;
    uint32_t depth = 1;
    std::vector<std::vector<uint8_t>> capture;  // per group, empty for none
    // The pipeline interface: with maxPayload >= 0 these sizes are given; otherwise 256 / 8 when libraries are
    // involved (flags or pLibraries) and none else. omitInterface gives none in every case.
    int64_t maxPayload = -1, maxHitAttr = -1;
    bool omitInterface = false;
    VkPipelineLayout layout = VK_NULL_HANDLE;  // the fixture's when null
    const void* pNext = nullptr;               // the create info's chain
    bool dynamicStackSize = false;             // VK_DYNAMIC_STATE_RAY_TRACING_PIPELINE_STACK_SIZE_KHR

    uint32_t stage(VkShaderModule m, VkShaderStageFlagBits s, const VkSpecializationInfo* spec = nullptr) {
      VkPipelineShaderStageCreateInfo st{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
      st.stage = s;
      st.module = m;
      st.pName = "main";
      st.pSpecializationInfo = spec;
      stages.push_back(st);
      return static_cast<uint32_t>(stages.size() - 1);
    }
    void group(VkRayTracingShaderGroupTypeKHR type, uint32_t general, uint32_t closest = VK_SHADER_UNUSED_KHR,
               uint32_t any = VK_SHADER_UNUSED_KHR, uint32_t isect = VK_SHADER_UNUSED_KHR) {
      VkRayTracingShaderGroupCreateInfoKHR g{VK_STRUCTURE_TYPE_RAY_TRACING_SHADER_GROUP_CREATE_INFO_KHR};
      g.type = type;
      g.generalShader = general;
      g.closestHitShader = closest;
      g.anyHitShader = any;
      g.intersectionShader = isect;
      groups.push_back(g);
    }
    void general(VkShaderModule m, VkShaderStageFlagBits s, const VkSpecializationInfo* spec = nullptr) {
      group(VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR, stage(m, s, spec));
    }
  };

  VkResult create(Desc& d, VkPipeline* out, VkDeferredOperationKHR op = VK_NULL_HANDLE,
                  VkPipelineCache cache = VK_NULL_HANDLE) {
    VkPipelineLibraryCreateInfoKHR lib{VK_STRUCTURE_TYPE_PIPELINE_LIBRARY_CREATE_INFO_KHR};
    lib.libraryCount = static_cast<uint32_t>(d.libraries.size());
    lib.pLibraries = d.libraries.data();
    VkRayTracingPipelineInterfaceCreateInfoKHR iface{VK_STRUCTURE_TYPE_RAY_TRACING_PIPELINE_INTERFACE_CREATE_INFO_KHR};
    iface.maxPipelineRayPayloadSize = 256;
    iface.maxPipelineRayHitAttributeSize = 8;
    for (size_t g = 0; g < d.capture.size() && g < d.groups.size(); ++g)
      d.groups[g].pShaderGroupCaptureReplayHandle = d.capture[g].empty() ? nullptr : d.capture[g].data();
    VkRayTracingPipelineCreateInfoKHR ci{VK_STRUCTURE_TYPE_RAY_TRACING_PIPELINE_CREATE_INFO_KHR, d.pNext};
    ci.flags = d.flags;
    ci.stageCount = static_cast<uint32_t>(d.stages.size());
    ci.pStages = d.stages.data();
    ci.groupCount = static_cast<uint32_t>(d.groups.size());
    ci.pGroups = d.groups.data();
    ci.maxPipelineRayRecursionDepth = d.depth;
    bool usesLibraries = !d.libraries.empty() || (d.flags & VK_PIPELINE_CREATE_LIBRARY_BIT_KHR);
    if (d.maxPayload >= 0) {
      iface.maxPipelineRayPayloadSize = static_cast<uint32_t>(d.maxPayload);
      iface.maxPipelineRayHitAttributeSize = static_cast<uint32_t>(d.maxHitAttr);
    }
    ci.pLibraryInfo = d.libraries.empty() ? nullptr : &lib;
    ci.pLibraryInterface = (usesLibraries || d.maxPayload >= 0) && !d.omitInterface ? &iface : nullptr;
    ci.layout = d.layout ? d.layout : layout;
    ci.basePipelineIndex = -1;
    const VkDynamicState stackSize = VK_DYNAMIC_STATE_RAY_TRACING_PIPELINE_STACK_SIZE_KHR;
    VkPipelineDynamicStateCreateInfo dynamic{VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO};
    dynamic.dynamicStateCount = 1;
    dynamic.pDynamicStates = &stackSize;
    ci.pDynamicState = d.dynamicStackSize ? &dynamic : nullptr;
    *out = VK_NULL_HANDLE;
    VkResult r = createPipelines(device, op, cache, 1, &ci, nullptr, out);
    if (op == VK_NULL_HANDLE && *out) pipelines.push_back(*out);
    return r;
  }

  VkPipeline make(Desc& d) {
    VkPipeline p = VK_NULL_HANDLE;
    EXPECT_EQ(create(d, &p), VK_SUCCESS);
    return p;
  }

  std::vector<uint8_t> handles(VkPipeline p, uint32_t first, uint32_t count) {
    std::vector<uint8_t> out(32 * count, 0xcd);
    EXPECT_EQ(getHandles(device, p, first, count, out.size(), out.data()), VK_SUCCESS);
    return out;
  }
  std::vector<uint8_t> captureData(VkPipeline p, uint32_t count) {
    std::vector<uint8_t> out(64 * count);
    EXPECT_EQ(getCapture(device, p, 0, count, out.size(), out.data()), VK_SUCCESS);
    return out;
  }

  // The six-group pipeline of the NVIDIA reference: raygen, two miss, triangle hit (chit + ahit), procedural
  // hit (rint + chit), callable.
  Desc sixGroups(VkPipelineCreateFlags flags = 0) {
    Desc d;
    d.flags = flags;
    d.general(raygen, VK_SHADER_STAGE_RAYGEN_BIT_KHR);
    d.general(miss, VK_SHADER_STAGE_MISS_BIT_KHR);
    d.general(miss2, VK_SHADER_STAGE_MISS_BIT_KHR);
    uint32_t c = d.stage(chit, VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR);
    uint32_t a = d.stage(ahit, VK_SHADER_STAGE_ANY_HIT_BIT_KHR);
    d.group(VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR, VK_SHADER_UNUSED_KHR, c, a);
    uint32_t i = d.stage(rint, VK_SHADER_STAGE_INTERSECTION_BIT_KHR);
    d.group(VK_RAY_TRACING_SHADER_GROUP_TYPE_PROCEDURAL_HIT_GROUP_KHR, VK_SHADER_UNUSED_KHR, c, VK_SHADER_UNUSED_KHR,
            i);
    d.general(call, VK_SHADER_STAGE_CALLABLE_BIT_KHR);
    return d;
  }

  PFN_vkCreateRayTracingPipelinesKHR createPipelines = nullptr;
  PFN_vkGetRayTracingShaderGroupHandlesKHR getHandles = nullptr;
  PFN_vkGetRayTracingCaptureReplayShaderGroupHandlesKHR getCapture = nullptr;
  PFN_vkGetRayTracingShaderGroupStackSizeKHR getStackSize = nullptr;
  PFN_vkCreateDeferredOperationKHR createOp = nullptr;
  PFN_vkDestroyDeferredOperationKHR destroyOp = nullptr;
  PFN_vkDeferredOperationJoinKHR joinOp = nullptr;
  PFN_vkGetDeferredOperationResultKHR opResult = nullptr;
  PFN_vkGetDeferredOperationMaxConcurrencyKHR opConcurrency = nullptr;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkShaderModule raygen{}, raygenBig{}, miss{}, miss2{}, missSpec{}, chit{}, chitCall{}, ahit{}, rint{}, call{};
  std::vector<VkShaderModule> modules;
  std::vector<VkPipeline> pipelines;
};

inline std::vector<uint8_t> slice(const std::vector<uint8_t>& v, size_t from, size_t n) {
  return std::vector<uint8_t>(v.begin() + from, v.begin() + from + n);
}

inline std::string hexOf(const std::vector<uint8_t>& v) {
  std::string s;
  char b[3];
  for (uint8_t x : v) {
    std::snprintf(b, sizeof(b), "%02x", x);
    s += b;
  }
  return s;
}

inline std::vector<uint8_t> fromHex(const std::string& s) {
  std::vector<uint8_t> v;
  for (size_t i = 0; i + 1 < s.size(); i += 2)
    v.push_back(static_cast<uint8_t>(std::stoi(s.substr(i, 2), nullptr, 16)));
  return v;
}

// Runs this binary again with one helper test and VKRT_HELPER_OUT=<file>; returns the file's first line.
inline std::string runHelper(const char* test, const std::string& extraEnvName = "",
                             const std::string& extraEnvValue = "") {
  char path[] = "/tmp/vkrt-helper-XXXXXX";
  int fd = mkstemp(path);
  EXPECT_GE(fd, 0);
  close(fd);
  pid_t pid = fork();
  if (pid == 0) {
    setenv("VKRT_HELPER_OUT", path, 1);
    if (!extraEnvName.empty()) setenv(extraEnvName.c_str(), extraEnvValue.c_str(), 1);
    std::string filter = std::string("--gtest_filter=") + test;
    int devnull = open("/dev/null", O_WRONLY);
    dup2(devnull, 1);
    // This very binary (VKRT_E2E_BINARY is its build path, absent where a copy runs on another machine).
    execl("/proc/self/exe", VKRT_E2E_BINARY, filter.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "helper " << test << " failed";
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  unlink(path);
  return line;
}

inline void writeOut(const std::string& text) {
  std::ofstream out(std::getenv("VKRT_HELPER_OUT"));
  out << text << "\n";
}
}  // namespace vkrt::test
