#include "rt/library_link.hpp"

#include <algorithm>
#include <cstdio>
#include <tuple>

#include "runtime/descriptor_set_layout.hpp"
#include "runtime/device.hpp"
#include "runtime/pipeline_layout.hpp"
#include "runtime/report.hpp"

namespace vkrt::rt {

LayoutShape shapeOf(const PipelineLayout& layout) {
  LayoutShape shape;
  for (const DescriptorSetLayout* l : layout.setLayouts) {
    LayoutShape::Set set;
    set.flags = l->flags;
    for (const DescriptorBinding& b : l->bindings) {
      LayoutShape::Binding sb;
      sb.binding = b.binding;
      sb.type = static_cast<uint32_t>(b.type);
      sb.count = b.count;
      sb.stages = b.stages;
      sb.flags = b.flags;
      sb.immutableSamplers.assign(b.immutableSamplers.begin(), b.immutableSamplers.end());
      set.bindings.push_back(std::move(sb));
    }
    shape.sets.push_back(std::move(set));
  }
  shape.pushConstants = layout.pushConstantRanges;
  std::sort(shape.pushConstants.begin(), shape.pushConstants.end(),
            [](const VkPushConstantRange& a, const VkPushConstantRange& b) {
              return std::tie(a.offset, a.size, a.stageFlags) < std::tie(b.offset, b.size, b.stageFlags);
            });
  return shape;
}

std::string layoutDifference(const LayoutShape& mine, const LayoutShape& lib) {
  char buf[256];
  if (mine.sets.size() != lib.sets.size()) {
    std::snprintf(buf, sizeof(buf), "the pipeline's layout has %zu set layouts, the library's %zu", mine.sets.size(),
                  lib.sets.size());
    return buf;
  }
  for (size_t s = 0; s < mine.sets.size(); ++s) {
    const LayoutShape::Set &a = mine.sets[s], &b = lib.sets[s];
    if (a == b) continue;
    if (a.flags != b.flags) {
      std::snprintf(buf, sizeof(buf), "set %zu: set layout flags 0x%x, the library's 0x%x", s, a.flags, b.flags);
      return buf;
    }
    if (a.bindings.size() != b.bindings.size()) {
      std::snprintf(buf, sizeof(buf), "set %zu: %zu bindings, the library's %zu", s, a.bindings.size(),
                    b.bindings.size());
      return buf;
    }
    for (size_t k = 0; k < a.bindings.size(); ++k) {
      const LayoutShape::Binding &x = a.bindings[k], &y = b.bindings[k];
      if (x == y) continue;
      std::snprintf(buf, sizeof(buf),
                    "set %zu: binding %u (type %u, count %u, stages 0x%x, flags 0x%x%s), the library's binding %u "
                    "(type %u, count %u, stages 0x%x, flags 0x%x%s)",
                    s, x.binding, x.type, x.count, x.stages, x.flags,
                    x.immutableSamplers.empty() ? "" : ", immutable samplers", y.binding, y.type, y.count, y.stages,
                    y.flags, y.immutableSamplers.empty() ? "" : ", immutable samplers");
      return buf;
    }
  }
  if (mine.pushConstants.size() != lib.pushConstants.size()) {
    std::snprintf(buf, sizeof(buf), "the pipeline's layout has %zu push-constant ranges, the library's %zu",
                  mine.pushConstants.size(), lib.pushConstants.size());
    return buf;
  }
  for (size_t r = 0; r < mine.pushConstants.size(); ++r) {
    const VkPushConstantRange &x = mine.pushConstants[r], &y = lib.pushConstants[r];
    if (x.offset != y.offset || x.size != y.size || x.stageFlags != y.stageFlags) {
      std::snprintf(buf, sizeof(buf),
                    "push-constant range {offset %u, size %u, stages 0x%x}, the library's {offset %u, size %u, "
                    "stages 0x%x}",
                    x.offset, x.size, x.stageFlags, y.offset, y.size, y.stageFlags);
      return buf;
    }
  }
  return {};
}

bool checkLibraries(Device* dev, const VkRayTracingPipelineCreateInfoKHR& info, uint32_t i, const LayoutShape& shape,
                    std::vector<RayTracingPipeline*>& libraries) {
  libraries.clear();
  const VkPipelineLibraryCreateInfoKHR* lib = info.pLibraryInfo;
  // VUID-VkRayTracingPipelineCreateInfoKHR-pLibraryInfo-03595
  if ((lib || info.pLibraryInterface) && !dev->extensionEnabled(VK_KHR_PIPELINE_LIBRARY_EXTENSION_NAME)) {
    report(dev, Severity::Error, "VUID-VkRayTracingPipelineCreateInfoKHR-pLibraryInfo-03595",
           "vkCreateRayTracingPipelinesKHR: pCreateInfos[%u] has pLibraryInfo %p / pLibraryInterface %p but "
           "VK_KHR_pipeline_library is not enabled",
           i, (const void*)lib, (const void*)info.pLibraryInterface);
    return false;
  }
  // VUID-VkRayTracingPipelineCreateInfoKHR-flags-03465
  if ((info.flags & VK_PIPELINE_CREATE_LIBRARY_BIT_KHR) && !info.pLibraryInterface) {
    report(dev, Severity::Error, "VUID-VkRayTracingPipelineCreateInfoKHR-flags-03465",
           "vkCreateRayTracingPipelinesKHR: pCreateInfos[%u] has VK_PIPELINE_CREATE_LIBRARY_BIT_KHR but no "
           "pLibraryInterface",
           i);
    return false;
  }
  if (info.pLibraryInterface) {
    // VUID-VkRayTracingPipelineInterfaceCreateInfoKHR-maxPipelineRayHitAttributeSize-03605
    if (info.pLibraryInterface->maxPipelineRayHitAttributeSize > 32) {
      report(dev, Severity::Error,
             "VUID-VkRayTracingPipelineInterfaceCreateInfoKHR-maxPipelineRayHitAttributeSize-03605",
             "vkCreateRayTracingPipelinesKHR: pCreateInfos[%u].pLibraryInterface->maxPipelineRayHitAttributeSize %u "
             "exceeds maxRayHitAttributeSize 32",
             i, info.pLibraryInterface->maxPipelineRayHitAttributeSize);
      return false;
    }
  }
  if (!lib) return true;
  if (lib->libraryCount == 0) {
    // VUID-VkRayTracingPipelineCreateInfoKHR-pLibraryInfo-03600
    if (info.stageCount == 0) {
      report(dev, Severity::Error, "VUID-VkRayTracingPipelineCreateInfoKHR-pLibraryInfo-03600",
             "vkCreateRayTracingPipelinesKHR: pCreateInfos[%u] has pLibraryInfo with libraryCount 0 and stageCount 0",
             i);
      return false;
    }
    // VUID-VkRayTracingPipelineCreateInfoKHR-pLibraryInfo-03601
    if (info.groupCount == 0) {
      report(dev, Severity::Error, "VUID-VkRayTracingPipelineCreateInfoKHR-pLibraryInfo-03601",
             "vkCreateRayTracingPipelinesKHR: pCreateInfos[%u] has pLibraryInfo with libraryCount 0 and groupCount 0",
             i);
      return false;
    }
    return true;
  }
  // VUID-VkRayTracingPipelineCreateInfoKHR-pLibraryInfo-03590
  if (!info.pLibraryInterface) {
    report(dev, Severity::Error, "VUID-VkRayTracingPipelineCreateInfoKHR-pLibraryInfo-03590",
           "vkCreateRayTracingPipelinesKHR: pCreateInfos[%u] links %u libraries but has no pLibraryInterface", i,
           lib->libraryCount);
    return false;
  }
  for (uint32_t l = 0; l < lib->libraryCount; ++l) {
    Pipeline* p = fromHandle<Pipeline>(lib->pLibraries[l]);
    RayTracingPipeline* rp = asRayTracing(p);
    // VUID-VkPipelineLibraryCreateInfoKHR-pLibraries-parameter
    if (!rp) {
      report(dev, Severity::Error, "VUID-VkPipelineLibraryCreateInfoKHR-pLibraries-parameter",
             "vkCreateRayTracingPipelinesKHR: pCreateInfos[%u].pLibraryInfo->pLibraries[%u] (0x%llx) is not a live "
             "ray tracing pipeline",
             i, l, (unsigned long long)rawHandle(lib->pLibraries[l]));
      return false;
    }
    // VUID-VkPipelineLibraryCreateInfoKHR-pLibraries-03381
    if (!rp->isLibrary()) {
      report(rp, Severity::Error, "VUID-VkPipelineLibraryCreateInfoKHR-pLibraries-03381",
             "vkCreateRayTracingPipelinesKHR: pCreateInfos[%u].pLibraryInfo->pLibraries[%u] was not created with "
             "VK_PIPELINE_CREATE_LIBRARY_BIT_KHR",
             i, l);
      return false;
    }
    // VUID-VkRayTracingPipelineCreateInfoKHR-pLibraries-03591
    if (rp->maxRecursionDepth != info.maxPipelineRayRecursionDepth) {
      report(rp, Severity::Error, "VUID-VkRayTracingPipelineCreateInfoKHR-pLibraries-03591",
             "vkCreateRayTracingPipelinesKHR: pCreateInfos[%u].pLibraryInfo->pLibraries[%u] has "
             "maxPipelineRayRecursionDepth %u, the pipeline %u",
             i, l, rp->maxRecursionDepth, info.maxPipelineRayRecursionDepth);
      return false;
    }
    // VUID-VkRayTracingPipelineCreateInfoKHR-pLibraryInfo-03593
    if (rp->maxPayloadSize != info.pLibraryInterface->maxPipelineRayPayloadSize ||
        rp->maxHitAttributeSize != info.pLibraryInterface->maxPipelineRayHitAttributeSize) {
      report(rp, Severity::Error, "VUID-VkRayTracingPipelineCreateInfoKHR-pLibraryInfo-03593",
             "vkCreateRayTracingPipelinesKHR: pCreateInfos[%u].pLibraryInfo->pLibraries[%u] has "
             "maxPipelineRayPayloadSize %u / maxPipelineRayHitAttributeSize %u, the pipeline's interface %u / %u",
             i, l, rp->maxPayloadSize, rp->maxHitAttributeSize, info.pLibraryInterface->maxPipelineRayPayloadSize,
             info.pLibraryInterface->maxPipelineRayHitAttributeSize);
      return false;
    }
    // VUID-VkRayTracingPipelineCreateInfoKHR-pLibraryInfo-03592
    std::string diff = layoutDifference(shape, rp->layoutShape);
    if (!diff.empty()) {
      report(rp, Severity::Error, "VUID-VkRayTracingPipelineCreateInfoKHR-pLibraryInfo-03592",
             "vkCreateRayTracingPipelinesKHR: pCreateInfos[%u].pLibraryInfo->pLibraries[%u] was created with a layout "
             "that is not compatible with pCreateInfos[%u].layout: %s",
             i, l, i, diff.c_str());
      return false;
    }
    // Flags a library must share with the pipeline linking it.
    struct Inherited {
      VkPipelineCreateFlags bit;
      const char* vuid;
      const char* name;
    };
    static const Inherited kInherited[] = {
        // VUID-VkRayTracingPipelineCreateInfoKHR-flags-03594
        {VK_PIPELINE_CREATE_RAY_TRACING_SHADER_GROUP_HANDLE_CAPTURE_REPLAY_BIT_KHR,
         "VUID-VkRayTracingPipelineCreateInfoKHR-flags-03594", "SHADER_GROUP_HANDLE_CAPTURE_REPLAY"},
        // VUID-VkRayTracingPipelineCreateInfoKHR-flags-04718
        {VK_PIPELINE_CREATE_RAY_TRACING_SKIP_AABBS_BIT_KHR, "VUID-VkRayTracingPipelineCreateInfoKHR-flags-04718",
         "SKIP_AABBS"},
        // VUID-VkRayTracingPipelineCreateInfoKHR-flags-04719
        {VK_PIPELINE_CREATE_RAY_TRACING_SKIP_TRIANGLES_BIT_KHR, "VUID-VkRayTracingPipelineCreateInfoKHR-flags-04719",
         "SKIP_TRIANGLES"},
        // VUID-VkRayTracingPipelineCreateInfoKHR-flags-04720
        {VK_PIPELINE_CREATE_RAY_TRACING_NO_NULL_ANY_HIT_SHADERS_BIT_KHR,
         "VUID-VkRayTracingPipelineCreateInfoKHR-flags-04720", "NO_NULL_ANY_HIT_SHADERS"},
        // VUID-VkRayTracingPipelineCreateInfoKHR-flags-04721
        {VK_PIPELINE_CREATE_RAY_TRACING_NO_NULL_CLOSEST_HIT_SHADERS_BIT_KHR,
         "VUID-VkRayTracingPipelineCreateInfoKHR-flags-04721", "NO_NULL_CLOSEST_HIT_SHADERS"},
        // VUID-VkRayTracingPipelineCreateInfoKHR-flags-04722
        {VK_PIPELINE_CREATE_RAY_TRACING_NO_NULL_INTERSECTION_SHADERS_BIT_KHR,
         "VUID-VkRayTracingPipelineCreateInfoKHR-flags-04722", "NO_NULL_INTERSECTION_SHADERS"},
        // VUID-VkRayTracingPipelineCreateInfoKHR-flags-04723
        {VK_PIPELINE_CREATE_RAY_TRACING_NO_NULL_MISS_SHADERS_BIT_KHR,
         "VUID-VkRayTracingPipelineCreateInfoKHR-flags-04723", "NO_NULL_MISS_SHADERS"},
    };
    for (const Inherited& f : kInherited) {
      if ((info.flags & f.bit) && !(rp->createFlags & f.bit)) {
        report(rp, Severity::Error, f.vuid,
               "vkCreateRayTracingPipelinesKHR: pCreateInfos[%u] has VK_PIPELINE_CREATE_RAY_TRACING_%s_BIT_KHR but "
               "pLibraryInfo->pLibraries[%u] was created without it",
               i, f.name, l);
        return false;
      }
    }
    libraries.push_back(rp);
  }
  return true;
}

void linkLibraries(const std::vector<RayTracingPipeline*>& libraries, std::vector<const GroupRecord*>& groups) {
  for (RayTracingPipeline* l : libraries) groups.insert(groups.end(), l->groups.begin(), l->groups.end());
}

}  // namespace vkrt::rt
