// VK_NV_ray_tracing's acceleration structure commands. Each checks the NV rules under their VUIDs, then does what
// the KHR command does on the same objects: a build becomes a BuildJob (runtime/acceleration_structure_build.hpp)
// whose geometries are the NV ones with buffer + offset turned into device addresses (VkGeometryTrianglesNV: vertex
// count - 1 as maxVertex, indexCount / 3 or vertexCount / 3 triangles; VkGeometryAABBNV: numAABBs boxes; a top level:
// instanceCount VkGeometryInstanceNV records, which are VkAccelerationStructureInstanceKHR records whose reference
// is an 8-byte handle from vkGetAccelerationStructureHandleNV, that is, a structure's address); copies share the
// built content; the compacted size is the KHR query's.
#include "runtime/acceleration_structure_nv.hpp"

#include <cstring>

#include "runtime/acceleration_structure_build.hpp"
#include "runtime/alloc.hpp"
#include "runtime/buffer.hpp"
#include "runtime/command_buffer.hpp"
#include "runtime/device.hpp"
#include "runtime/lookup.hpp"
#include "runtime/memory.hpp"
#include "runtime/query_pool.hpp"
#include "runtime/ray_tracing_features.hpp"
#include "runtime/report.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {

namespace {

using ull = unsigned long long;

constexpr VkDeviceSize kAlignmentNV = 256;  // of the object's memory (VkMemoryRequirements::alignment)

uint64_t trianglesOf(const VkGeometryTrianglesNV& t) {
  return (t.indexType == VK_INDEX_TYPE_NONE_NV ? t.vertexCount : t.indexCount) / 3;
}

}  // namespace

uint64_t primitiveCountNV(const VkAccelerationStructureInfoNV& info) {
  if (info.type == VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_NV) return info.instanceCount;
  uint64_t n = 0;
  for (uint32_t g = 0; g < info.geometryCount && info.pGeometries; ++g) {
    const VkGeometryNV& geo = info.pGeometries[g];
    n += geo.geometryType == VK_GEOMETRY_TYPE_TRIANGLES_NV ? trianglesOf(geo.geometry.triangles)
                                                           : geo.geometry.aabbs.numAABBs;
  }
  return n;
}

AccelerationStructureNV::AccelerationStructureNV(Device* dev, const VkAccelerationStructureCreateInfoNV& ci,
                                                 VkDeviceSize sz)
    : AccelerationStructure(kType, dev, ci.info.type, sz),
      infoType(ci.info.type),
      infoFlags(ci.info.flags),
      instanceCount(ci.info.instanceCount),
      compactedSize(ci.compactedSize) {
  for (uint32_t g = 0; g < ci.info.geometryCount; ++g) {
    geometries.push_back(ci.info.pGeometries[g]);
    geometries.back().pNext = nullptr;
    geometries.back().geometry.triangles.pNext = nullptr;
    geometries.back().geometry.aabbs.pNext = nullptr;
  }
}

void AccelerationStructureNV::bind(Memory* mem, VkDeviceSize offset) {
  memory = mem;
  bindMemory(mem->base + offset);
}

namespace {

// The rules of a VkAccelerationStructureInfoNV (at creation and at a build), reported against `about`.
bool checkInfo(const Object* about, const char* fn, const VkAccelerationStructureInfoNV& info) {
  const VkPhysicalDeviceRayTracingPropertiesNV props = rayTracingPropertiesNV();
  auto fail = [&](const char* vuid, const char* what, auto... args) {
    std::string text(512, '\0');
    text.resize(
        std::min<size_t>(size_t(std::max(std::snprintf(text.data(), text.size(), what, args...), 0)), text.size() - 1));
    report(about, Severity::Error, vuid, "%s: %s", fn, text.c_str());
    return false;
  };
  // VUID-VkAccelerationStructureInfoNV-type-04623, VUID-VkAccelerationStructureInfoNV-type-parameter
  if (info.type != VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_NV &&
      info.type != VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_NV)
    return fail(info.type == VK_ACCELERATION_STRUCTURE_TYPE_GENERIC_KHR
                    ? "VUID-VkAccelerationStructureInfoNV-type-04623"
                    : "VUID-VkAccelerationStructureInfoNV-type-parameter",
                "info.type %d is neither TOP_LEVEL_NV nor BOTTOM_LEVEL_NV", int(info.type));
  const bool top = info.type == VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_NV;
  // VUID-VkAccelerationStructureInfoNV-type-02425
  if (top && info.geometryCount != 0)
    return fail("VUID-VkAccelerationStructureInfoNV-type-02425", "a top-level info has geometryCount %u (must be 0)",
                info.geometryCount);
  // VUID-VkAccelerationStructureInfoNV-type-02426
  if (!top && info.instanceCount != 0)
    return fail("VUID-VkAccelerationStructureInfoNV-type-02426", "a bottom-level info has instanceCount %u (must be 0)",
                info.instanceCount);
  // VUID-VkAccelerationStructureInfoNV-geometryCount-02422
  if (info.geometryCount > props.maxGeometryCount)
    return fail("VUID-VkAccelerationStructureInfoNV-geometryCount-02422",
                "geometryCount %u exceeds maxGeometryCount %llu", info.geometryCount, (ull)props.maxGeometryCount);
  // VUID-VkAccelerationStructureInfoNV-instanceCount-02423
  if (info.instanceCount > props.maxInstanceCount)
    return fail("VUID-VkAccelerationStructureInfoNV-instanceCount-02423",
                "instanceCount %u exceeds maxInstanceCount %llu", info.instanceCount, (ull)props.maxInstanceCount);
  // VUID-VkAccelerationStructureInfoNV-flags-02592
  if ((info.flags & VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_NV) &&
      (info.flags & VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_BUILD_BIT_NV))
    return fail("VUID-VkAccelerationStructureInfoNV-flags-02592",
                "flags 0x%x has both PREFER_FAST_TRACE and PREFER_FAST_BUILD", info.flags);
  if (info.geometryCount && !info.pGeometries)
    return fail("VUID-VkAccelerationStructureInfoNV-pGeometries-parameter", "pGeometries is NULL for %u geometries",
                info.geometryCount);
  for (uint32_t g = 0; g < info.geometryCount; ++g) {
    const VkGeometryNV& geo = info.pGeometries[g];
    // VUID-VkGeometryNV-geometryType-03503
    if (geo.geometryType != VK_GEOMETRY_TYPE_TRIANGLES_NV && geo.geometryType != VK_GEOMETRY_TYPE_AABBS_NV)
      return fail("VUID-VkGeometryNV-geometryType-03503",
                  "pGeometries[%u].geometryType %d is neither TRIANGLES_NV nor AABBS_NV", g, int(geo.geometryType));
    // VUID-VkAccelerationStructureInfoNV-type-02786
    if (geo.geometryType != info.pGeometries[0].geometryType)
      return fail("VUID-VkAccelerationStructureInfoNV-type-02786",
                  "pGeometries[%u].geometryType %d differs from pGeometries[0]'s (%d): a bottom level holds one kind",
                  g, int(geo.geometryType), int(info.pGeometries[0].geometryType));
  }
  // VUID-VkAccelerationStructureInfoNV-maxTriangleCount-02424
  if (!top && info.geometryCount && info.pGeometries[0].geometryType == VK_GEOMETRY_TYPE_TRIANGLES_NV &&
      primitiveCountNV(info) > props.maxTriangleCount)
    return fail("VUID-VkAccelerationStructureInfoNV-maxTriangleCount-02424",
                "%llu triangles exceed maxTriangleCount %llu", (ull)primitiveCountNV(info),
                (ull)props.maxTriangleCount);
  return true;
}

// A buffer operand of a build: live and bound. `vuid` names the parameter rule.
Buffer* boundBuffer(const Object* about, const char* fn, VkBuffer h, const char* what, const char* vuid) {
  Buffer* b = fromHandle<Buffer>(h);
  if (!b) {
    report(about, Severity::Error, vuid, "%s: %s 0x%llx is not a live VkBuffer", fn, what, (ull)rawHandle(h));
    return nullptr;
  }
  if (!b->data()) {
    report(b, Severity::Error, nullptr, "%s: %s is not bound to memory", fn, what);
    return nullptr;
  }
  return b;
}

bool isNvVertexFormat(VkFormat f) {
  switch (f) {
    case VK_FORMAT_R32G32B32_SFLOAT:
    case VK_FORMAT_R32G32_SFLOAT:
    case VK_FORMAT_R16G16B16_SFLOAT:
    case VK_FORMAT_R16G16_SFLOAT:
    case VK_FORMAT_R16G16_SNORM:
    case VK_FORMAT_R16G16B16_SNORM: return true;
    default: return false;
  }
}

// One VkGeometryNV of a build: its rules, then its KHR form and range.
bool translateGeometry(const Object* about, const char* fn, uint32_t g, const VkGeometryNV& geo,
                       VkAccelerationStructureGeometryKHR* out, VkAccelerationStructureBuildRangeInfoKHR* range) {
  char what[96];
  auto fail = [&](const char* vuid, const std::string& text) {
    report(about, Severity::Error, vuid, "%s: pInfo->pGeometries[%u]: %s", fn, g, text.c_str());
    return false;
  };
  *out = {VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
  out->geometryType = geo.geometryType;
  out->flags = geo.flags;
  *range = {};
  if (geo.geometryType == VK_GEOMETRY_TYPE_TRIANGLES_NV) {
    const VkGeometryTrianglesNV& t = geo.geometry.triangles;
    // VUID-VkGeometryTrianglesNV-vertexFormat-02430
    if (!isNvVertexFormat(t.vertexFormat))
      return fail("VUID-VkGeometryTrianglesNV-vertexFormat-02430",
                  "vertexFormat " + std::to_string(int(t.vertexFormat)) +
                      " is not R32G32B32_SFLOAT, R32G32_SFLOAT, R16G16B16_SFLOAT, R16G16_SFLOAT, R16G16_SNORM or "
                      "R16G16B16_SNORM");
    // VUID-VkGeometryTrianglesNV-vertexStride-03818
    if (t.vertexStride > UINT32_MAX)
      return fail("VUID-VkGeometryTrianglesNV-vertexStride-03818", "vertexStride exceeds 2^32-1");
    std::snprintf(what, sizeof what, "pInfo->pGeometries[%u].geometry.triangles.vertexData", g);
    // VUID-VkGeometryTrianglesNV-vertexData-parameter
    Buffer* v = boundBuffer(about, fn, t.vertexData, what, "VUID-VkGeometryTrianglesNV-vertexData-parameter");
    if (!v) return false;
    // VUID-VkGeometryTrianglesNV-vertexOffset-02428
    if (t.vertexOffset >= v->size)
      return fail("VUID-VkGeometryTrianglesNV-vertexOffset-02428", "vertexOffset " + std::to_string(t.vertexOffset) +
                                                                       " is not less than vertexData's size " +
                                                                       std::to_string(v->size));
    // VUID-VkGeometryTrianglesNV-vertexOffset-02429
    if (t.vertexOffset % vertexComponentBytes(t.vertexFormat))
      return fail("VUID-VkGeometryTrianglesNV-vertexOffset-02429",
                  "vertexOffset " + std::to_string(t.vertexOffset) +
                      " is not a multiple of the vertex format's component size");
    // VUID-VkGeometryTrianglesNV-indexType-02433
    if (t.indexType != VK_INDEX_TYPE_UINT16 && t.indexType != VK_INDEX_TYPE_UINT32 &&
        t.indexType != VK_INDEX_TYPE_NONE_NV)
      return fail("VUID-VkGeometryTrianglesNV-indexType-02433",
                  "indexType " + std::to_string(int(t.indexType)) + " is not UINT16, UINT32 or NONE_NV");
    auto& k = out->geometry.triangles;
    k = {VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR};
    k.vertexFormat = t.vertexFormat;
    k.vertexData.deviceAddress = reinterpret_cast<uint64_t>(v->data()) + t.vertexOffset;
    k.vertexStride = t.vertexStride;
    k.maxVertex = t.vertexCount ? t.vertexCount - 1 : 0;
    k.indexType = t.indexType;
    if (t.indexType == VK_INDEX_TYPE_NONE_NV) {
      // VUID-VkGeometryTrianglesNV-indexData-02434
      if (t.indexData != VK_NULL_HANDLE)
        return fail("VUID-VkGeometryTrianglesNV-indexData-02434", "indexData is given with indexType NONE_NV");
      // VUID-VkGeometryTrianglesNV-indexCount-02436
      if (t.indexCount != 0)
        return fail("VUID-VkGeometryTrianglesNV-indexCount-02436",
                    "indexCount " + std::to_string(t.indexCount) + " is not 0 with indexType NONE_NV");
    } else {
      std::snprintf(what, sizeof what, "pInfo->pGeometries[%u].geometry.triangles.indexData", g);
      // VUID-VkGeometryTrianglesNV-indexData-02435
      Buffer* ib = boundBuffer(about, fn, t.indexData, what, "VUID-VkGeometryTrianglesNV-indexData-02435");
      if (!ib) return false;
      // VUID-VkGeometryTrianglesNV-indexOffset-02431
      if (t.indexOffset >= ib->size)
        return fail("VUID-VkGeometryTrianglesNV-indexOffset-02431", "indexOffset " + std::to_string(t.indexOffset) +
                                                                        " is not less than indexData's size " +
                                                                        std::to_string(ib->size));
      // VUID-VkGeometryTrianglesNV-indexOffset-02432
      if (t.indexOffset % (t.indexType == VK_INDEX_TYPE_UINT16 ? 2 : 4))
        return fail("VUID-VkGeometryTrianglesNV-indexOffset-02432",
                    "indexOffset " + std::to_string(t.indexOffset) + " is not a multiple of the index size");
      k.indexData.deviceAddress = reinterpret_cast<uint64_t>(ib->data()) + t.indexOffset;
    }
    if (t.transformData != VK_NULL_HANDLE) {
      std::snprintf(what, sizeof what, "pInfo->pGeometries[%u].geometry.triangles.transformData", g);
      // VUID-VkGeometryTrianglesNV-transformData-parameter
      Buffer* tb = boundBuffer(about, fn, t.transformData, what, "VUID-VkGeometryTrianglesNV-transformData-parameter");
      if (!tb) return false;
      // VUID-VkGeometryTrianglesNV-transformOffset-02437
      if (t.transformOffset >= tb->size)
        return fail("VUID-VkGeometryTrianglesNV-transformOffset-02437",
                    "transformOffset " + std::to_string(t.transformOffset) + " is not less than transformData's size " +
                        std::to_string(tb->size));
      // VUID-VkGeometryTrianglesNV-transformOffset-02438
      if (t.transformOffset % 16)
        return fail("VUID-VkGeometryTrianglesNV-transformOffset-02438",
                    "transformOffset " + std::to_string(t.transformOffset) + " is not a multiple of 16");
      k.transformData.deviceAddress = reinterpret_cast<uint64_t>(tb->data()) + t.transformOffset;
    }
    range->primitiveCount = uint32_t(trianglesOf(t));
    return true;
  }
  const VkGeometryAABBNV& a = geo.geometry.aabbs;
  std::snprintf(what, sizeof what, "pInfo->pGeometries[%u].geometry.aabbs.aabbData", g);
  // VUID-VkGeometryAABBNV-aabbData-parameter
  Buffer* ab = boundBuffer(about, fn, a.aabbData, what, "VUID-VkGeometryAABBNV-aabbData-parameter");
  if (!ab) return false;
  // VUID-VkGeometryAABBNV-offset-02439
  if (a.offset >= ab->size)
    return fail("VUID-VkGeometryAABBNV-offset-02439",
                "offset " + std::to_string(a.offset) + " is not less than aabbData's size " + std::to_string(ab->size));
  // VUID-VkGeometryAABBNV-offset-02440
  if (a.offset % 8)
    return fail("VUID-VkGeometryAABBNV-offset-02440", "offset " + std::to_string(a.offset) + " is not a multiple of 8");
  // VUID-VkGeometryAABBNV-stride-02441
  if (a.stride % 8)
    return fail("VUID-VkGeometryAABBNV-stride-02441", "stride " + std::to_string(a.stride) + " is not a multiple of 8");
  auto& k = out->geometry.aabbs;
  k = {VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_AABBS_DATA_KHR};
  k.data.deviceAddress = reinterpret_cast<uint64_t>(ab->data()) + a.offset;
  k.stride = a.stride;
  range->primitiveCount = a.numAABBs;
  return true;
}

// A structure operand of a command: live and bound to memory (`boundVuid`).
AccelerationStructureNV* boundStructure(const Object* about, const char* fn, VkAccelerationStructureNV h,
                                        const char* what, const char* paramVuid, const char* boundVuid) {
  auto* as = fromHandle<AccelerationStructureNV>(h);
  if (!as) {
    report(about, Severity::Error, paramVuid, "%s: %s 0x%llx is not a live VkAccelerationStructureNV", fn, what,
           (ull)rawHandle(h));
    return nullptr;
  }
  if (!as->memory) {
    report(as, Severity::Error, boundVuid, "%s: %s is not bound to memory (vkBindAccelerationStructureMemoryNV)", fn,
           what);
    return nullptr;
  }
  return as;
}

}  // namespace

}  // namespace vkrt

using namespace vkrt;

extern "C" {

VKAPI_ATTR VkResult VKAPI_CALL vkrt_CreateAccelerationStructureNV(
    VkDevice device, const VkAccelerationStructureCreateInfoNV* pCreateInfo, const VkAllocationCallbacks* pAllocator,
    VkAccelerationStructureNV* pAccelerationStructure) {
  const char* fn = "vkCreateAccelerationStructureNV";
  Device* dev = fromHandleUnchecked<Device>(device);
  const VkAccelerationStructureCreateInfoNV& ci = *pCreateInfo;
  *pAccelerationStructure = VK_NULL_HANDLE;
  if (!checkInfo(dev, fn, ci.info)) return VK_ERROR_VALIDATION_FAILED_EXT;
  // VUID-VkAccelerationStructureCreateInfoNV-compactedSize-02421
  if (ci.compactedSize && (ci.info.geometryCount || ci.info.instanceCount)) {
    report(dev, Severity::Error, "VUID-VkAccelerationStructureCreateInfoNV-compactedSize-02421",
           "%s: compactedSize %llu is given with info.geometryCount %u and info.instanceCount %u (both must be 0)", fn,
           (ull)ci.compactedSize, ci.info.geometryCount, ci.info.instanceCount);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  const VkDeviceSize size = ci.compactedSize ? std::max<VkDeviceSize>(ci.compactedSize, requiredSize(0))
                                             : requiredSize(primitiveCountNV(ci.info));
  auto* as = createObject<AccelerationStructureNV>(pAllocator, VK_SYSTEM_ALLOCATION_SCOPE_OBJECT, dev, ci, size);
  if (!as) return VK_ERROR_OUT_OF_HOST_MEMORY;
  *pAccelerationStructure = toHandle(as);
  return VK_SUCCESS;
}

VKAPI_ATTR void VKAPI_CALL vkrt_DestroyAccelerationStructureNV(VkDevice device,
                                                               VkAccelerationStructureNV accelerationStructure,
                                                               const VkAllocationCallbacks* pAllocator) {
  destroyDeviceChildWhenIdle<AccelerationStructureNV>(
      device, accelerationStructure, pAllocator, "vkDestroyAccelerationStructureNV",
      "VUID-vkDestroyAccelerationStructureNV-accelerationStructure-parameter",
      "VUID-vkDestroyAccelerationStructureNV-accelerationStructure-03752");
}

VKAPI_ATTR void VKAPI_CALL vkrt_GetAccelerationStructureMemoryRequirementsNV(
    VkDevice device, const VkAccelerationStructureMemoryRequirementsInfoNV* pInfo,
    VkMemoryRequirements2KHR* pMemoryRequirements) {
  const char* fn = "vkGetAccelerationStructureMemoryRequirementsNV";
  Device* dev = fromHandleUnchecked<Device>(device);
  VkMemoryRequirements& r = pMemoryRequirements->memoryRequirements;
  r = {};
  // VUID-VkAccelerationStructureMemoryRequirementsInfoNV-accelerationStructure-parameter
  auto* as = liveOrReport<AccelerationStructureNV>(
      dev, pInfo->accelerationStructure, fn,
      "VUID-VkAccelerationStructureMemoryRequirementsInfoNV-accelerationStructure-parameter");
  if (!as) return;
  switch (pInfo->type) {
    case VK_ACCELERATION_STRUCTURE_MEMORY_REQUIREMENTS_TYPE_OBJECT_NV: r.size = as->size; break;
    case VK_ACCELERATION_STRUCTURE_MEMORY_REQUIREMENTS_TYPE_BUILD_SCRATCH_NV:
    case VK_ACCELERATION_STRUCTURE_MEMORY_REQUIREMENTS_TYPE_UPDATE_SCRATCH_NV: r.size = kScratchSize; break;
    default:
      // VUID-VkAccelerationStructureMemoryRequirementsInfoNV-type-parameter
      report(dev, Severity::Error, "VUID-VkAccelerationStructureMemoryRequirementsInfoNV-type-parameter",
             "%s: type %d is not a VkAccelerationStructureMemoryRequirementsTypeNV value", fn, int(pInfo->type));
      return;
  }
  r.alignment = kAlignmentNV;
  r.memoryTypeBits = 1;  // the one memory type
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_BindAccelerationStructureMemoryNV(
    VkDevice device, uint32_t bindInfoCount, const VkBindAccelerationStructureMemoryInfoNV* pBindInfos) {
  const char* fn = "vkBindAccelerationStructureMemoryNV";
  Device* dev = fromHandleUnchecked<Device>(device);
  // Every info is checked before any is bound: a failing call binds nothing.
  for (uint32_t i = 0; i < bindInfoCount; ++i) {
    const VkBindAccelerationStructureMemoryInfoNV& b = pBindInfos[i];
    // VUID-VkBindAccelerationStructureMemoryInfoNV-accelerationStructure-parameter
    auto* as = liveOrReport<AccelerationStructureNV>(
        dev, b.accelerationStructure, fn,
        "VUID-VkBindAccelerationStructureMemoryInfoNV-accelerationStructure-parameter");
    // VUID-VkBindAccelerationStructureMemoryInfoNV-memory-parameter
    auto* mem =
        liveOrReport<Memory>(dev, b.memory, fn, "VUID-VkBindAccelerationStructureMemoryInfoNV-memory-parameter");
    if (!as || !mem) return VK_ERROR_VALIDATION_FAILED_EXT;
    const char* vuid = nullptr;
    std::string why;
    if (as->memory) {
      // VUID-VkBindAccelerationStructureMemoryInfoNV-accelerationStructure-03620
      vuid = "VUID-VkBindAccelerationStructureMemoryInfoNV-accelerationStructure-03620";
      why = "the structure is already bound to memory";
    } else if (b.memoryOffset >= mem->size) {
      // VUID-VkBindAccelerationStructureMemoryInfoNV-memoryOffset-03621
      vuid = "VUID-VkBindAccelerationStructureMemoryInfoNV-memoryOffset-03621";
      why = "memoryOffset " + std::to_string(b.memoryOffset) + " is not less than the memory's size " +
            std::to_string(mem->size);
    } else if (b.memoryOffset % kAlignmentNV) {
      // VUID-VkBindAccelerationStructureMemoryInfoNV-memoryOffset-03623
      vuid = "VUID-VkBindAccelerationStructureMemoryInfoNV-memoryOffset-03623";
      why = "memoryOffset " + std::to_string(b.memoryOffset) + " is not a multiple of the required alignment " +
            std::to_string(kAlignmentNV);
    } else if (mem->size - b.memoryOffset < as->size) {
      // VUID-VkBindAccelerationStructureMemoryInfoNV-size-03624
      vuid = "VUID-VkBindAccelerationStructureMemoryInfoNV-size-03624";
      why = "the " + std::to_string(mem->size - b.memoryOffset) +
            " bytes of memory after memoryOffset are fewer than the structure's required size " +
            std::to_string(as->size);
    }
    for (uint32_t j = 0; !vuid && j < i; ++j) {
      if (pBindInfos[j].accelerationStructure == b.accelerationStructure) {
        vuid = "VUID-VkBindAccelerationStructureMemoryInfoNV-accelerationStructure-03620";
        why = "the structure is also bound by pBindInfos[" + std::to_string(j) + "]";
      }
    }
    if (vuid) {
      report(as, Severity::Error, vuid, "%s: pBindInfos[%u]: %s; nothing is bound", fn, i, why.c_str());
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
  }
  for (uint32_t i = 0; i < bindInfoCount; ++i)
    fromHandle<AccelerationStructureNV>(pBindInfos[i].accelerationStructure)
        ->bind(fromHandle<Memory>(pBindInfos[i].memory), pBindInfos[i].memoryOffset);
  return VK_SUCCESS;
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_GetAccelerationStructureHandleNV(VkDevice device,
                                                                     VkAccelerationStructureNV accelerationStructure,
                                                                     size_t dataSize, void* pData) {
  const char* fn = "vkGetAccelerationStructureHandleNV";
  Device* dev = fromHandleUnchecked<Device>(device);
  // VUID-vkGetAccelerationStructureHandleNV-accelerationStructure-parameter,
  // VUID-vkGetAccelerationStructureHandleNV-accelerationStructure-02787
  auto* as = boundStructure(dev, fn, accelerationStructure, "accelerationStructure",
                            "VUID-vkGetAccelerationStructureHandleNV-accelerationStructure-parameter",
                            "VUID-vkGetAccelerationStructureHandleNV-accelerationStructure-02787");
  if (!as) return VK_ERROR_VALIDATION_FAILED_EXT;
  // VUID-vkGetAccelerationStructureHandleNV-dataSize-02240
  if (dataSize < sizeof(uint64_t)) {
    report(as, Severity::Error, "VUID-vkGetAccelerationStructureHandleNV-dataSize-02240",
           "%s: dataSize %zu is less than the handle's 8 bytes", fn, dataSize);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // The handle is the structure's address: what a top level's instances refer to it by.
  const uint64_t handle = as->address();
  std::memcpy(pData, &handle, sizeof handle);
  return VK_SUCCESS;
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdBuildAccelerationStructureNV(VkCommandBuffer commandBuffer,
                                                                const VkAccelerationStructureInfoNV* pInfo,
                                                                VkBuffer instanceData, VkDeviceSize instanceOffset,
                                                                VkBool32 update, VkAccelerationStructureNV dst,
                                                                VkAccelerationStructureNV src, VkBuffer scratch,
                                                                VkDeviceSize scratchOffset) {
  const char* fn = "vkCmdBuildAccelerationStructureNV";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  // VUID-vkCmdBuildAccelerationStructureNV-renderpass: outside a render pass instance
  if (!cb->outsideRenderPass(fn, "VUID-vkCmdBuildAccelerationStructureNV-renderpass")) return;
  const VkAccelerationStructureInfoNV& info = *pInfo;
  if (!checkInfo(cb, fn, info)) return;
  // VUID-vkCmdBuildAccelerationStructureNV-dst-parameter, VUID-vkCmdBuildAccelerationStructureNV-dst-07787
  AccelerationStructureNV* d =
      boundStructure(cb, fn, dst, "dst", "VUID-vkCmdBuildAccelerationStructureNV-dst-parameter",
                     "VUID-vkCmdBuildAccelerationStructureNV-dst-07787");
  if (!d) return;
  // VUID-vkCmdBuildAccelerationStructureNV-geometryCount-02241
  if (info.geometryCount > rayTracingPropertiesNV().maxGeometryCount) {
    report(cb, Severity::Error, "VUID-vkCmdBuildAccelerationStructureNV-geometryCount-02241",
           "%s: geometryCount %u exceeds maxGeometryCount", fn, info.geometryCount);
    return;
  }
  // VUID-vkCmdBuildAccelerationStructureNV-dst-02488: dst was created with a compatible info.
  {
    std::string why;
    if (d->infoType != info.type || d->infoFlags != info.flags) {
      why = "type or flags differ from dst's creation info";
    } else if (d->instanceCount < info.instanceCount || d->geometries.size() < info.geometryCount) {
      why = "instanceCount " + std::to_string(info.instanceCount) + " / geometryCount " +
            std::to_string(info.geometryCount) + " exceed dst's " + std::to_string(d->instanceCount) + " / " +
            std::to_string(d->geometries.size());
    } else {
      for (uint32_t g = 0; g < info.geometryCount && why.empty(); ++g) {
        const VkGeometryNV &a = info.pGeometries[g], &c = d->geometries[g];
        bool fits = a.geometryType == c.geometryType;
        if (fits && a.geometryType == VK_GEOMETRY_TYPE_TRIANGLES_NV)
          fits = a.geometry.triangles.vertexCount <= c.geometry.triangles.vertexCount &&
                 a.geometry.triangles.indexCount <= c.geometry.triangles.indexCount;
        else if (fits)
          fits = a.geometry.aabbs.numAABBs <= c.geometry.aabbs.numAABBs;
        if (!fits)
          why = "pGeometries[" + std::to_string(g) +
                "] has another type or more vertices, indices or AABBs than dst's creation info";
      }
    }
    if (!why.empty()) {
      report(d, Severity::Error, "VUID-vkCmdBuildAccelerationStructureNV-dst-02488",
             "%s: pInfo is not compatible with the info dst was created with: %s", fn, why.c_str());
      return;
    }
  }
  AccelerationStructureNV* s = nullptr;
  if (update) {
    // VUID-vkCmdBuildAccelerationStructureNV-update-02489
    if (src == VK_NULL_HANDLE) {
      report(cb, Severity::Error, "VUID-vkCmdBuildAccelerationStructureNV-update-02489",
             "%s: update is VK_TRUE but src is VK_NULL_HANDLE", fn);
      return;
    }
    // VUID-vkCmdBuildAccelerationStructureNV-src-parameter
    s = boundStructure(cb, fn, src, "src", "VUID-vkCmdBuildAccelerationStructureNV-src-parameter", nullptr);
    if (!s) return;
    // VUID-vkCmdBuildAccelerationStructureNV-update-02490
    if (!(s->infoFlags & VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_NV)) {
      report(s, Severity::Error, "VUID-vkCmdBuildAccelerationStructureNV-update-02490",
             "%s: update is VK_TRUE but src was not created (and so not built) with "
             "VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_NV",
             fn);
      return;
    }
  }
  // VUID-vkCmdBuildAccelerationStructureNV-scratch-parameter
  Buffer* scr = boundBuffer(cb, fn, scratch, "scratch", "VUID-vkCmdBuildAccelerationStructureNV-scratch-parameter");
  if (!scr) return;
  // VUID-vkCmdBuildAccelerationStructureNV-scratch-03522
  if (!(scr->usage & VK_BUFFER_USAGE_RAY_TRACING_BIT_NV)) {
    report(scr, Severity::Error, "VUID-vkCmdBuildAccelerationStructureNV-scratch-03522",
           "%s: scratch's usage 0x%x lacks VK_BUFFER_USAGE_RAY_TRACING_BIT_NV", fn, scr->usage);
    return;
  }
  // VUID-vkCmdBuildAccelerationStructureNV-update-02491, -02492 (vkrt needs kScratchSize bytes for both)
  if (scratchOffset > scr->size || scr->size - scratchOffset < kScratchSize) {
    report(scr, Severity::Error,
           update ? "VUID-vkCmdBuildAccelerationStructureNV-update-02492"
                  : "VUID-vkCmdBuildAccelerationStructureNV-update-02491",
           "%s: scratch has fewer than the %llu bytes the %s scratch requirement reports after scratchOffset %llu", fn,
           (ull)kScratchSize, update ? "UPDATE" : "BUILD", (ull)scratchOffset);
    return;
  }
  BuildJob job;
  job.type = info.type;
  job.flags = info.flags;
  job.mode = update ? VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR : VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
  job.dst = d;
  job.src = s;
  if (info.type == VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_NV) {
    // VUID-vkCmdBuildAccelerationStructureNV-instanceData-parameter
    Buffer* inst = boundBuffer(cb, fn, instanceData, "instanceData",
                               "VUID-vkCmdBuildAccelerationStructureNV-instanceData-parameter");
    if (!inst) return;
    // VUID-vkCmdBuildAccelerationStructureNV-instanceData-03523
    if (!(inst->usage & VK_BUFFER_USAGE_RAY_TRACING_BIT_NV)) {
      report(inst, Severity::Error, "VUID-vkCmdBuildAccelerationStructureNV-instanceData-03523",
             "%s: instanceData's usage 0x%x lacks VK_BUFFER_USAGE_RAY_TRACING_BIT_NV", fn, inst->usage);
      return;
    }
    // The instances must lie in the buffer (VkGeometryInstanceNV is 64 bytes).
    if (instanceOffset > inst->size || (inst->size - instanceOffset) / 64 < info.instanceCount) {
      report(inst, Severity::Error, nullptr, "%s: instanceData has fewer than %u instances after instanceOffset %llu",
             fn, info.instanceCount, (ull)instanceOffset);
      return;
    }
    VkAccelerationStructureGeometryKHR geo{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
    geo.geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;
    geo.geometry.instances = {VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR};
    geo.geometry.instances.data.deviceAddress = reinterpret_cast<uint64_t>(inst->data()) + instanceOffset;
    job.geometries.push_back(geo);
    VkAccelerationStructureBuildRangeInfoKHR range{};
    range.primitiveCount = info.instanceCount;
    job.ranges.push_back(range);
  } else {
    for (uint32_t g = 0; g < info.geometryCount; ++g) {
      VkAccelerationStructureGeometryKHR geo;
      VkAccelerationStructureBuildRangeInfoKHR range;
      if (!translateGeometry(cb, fn, g, info.pGeometries[g], &geo, &range)) return;
      job.geometries.push_back(geo);
      job.ranges.push_back(range);
    }
  }
  cb->record([cb, job](ExecState&) {
    BuildError e;
    if (!runBuild(cb->device, job, &e))
      report(cb, Severity::Error, e.vuid, "vkCmdBuildAccelerationStructureNV: %s; the build is skipped",
             e.message.c_str());
  });
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdCopyAccelerationStructureNV(VkCommandBuffer commandBuffer,
                                                               VkAccelerationStructureNV dst,
                                                               VkAccelerationStructureNV src,
                                                               VkCopyAccelerationStructureModeKHR mode) {
  const char* fn = "vkCmdCopyAccelerationStructureNV";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  // VUID-vkCmdCopyAccelerationStructureNV-renderpass: outside a render pass instance
  if (!cb->outsideRenderPass(fn, "VUID-vkCmdCopyAccelerationStructureNV-renderpass")) return;
  // VUID-vkCmdCopyAccelerationStructureNV-src-parameter, VUID-vkCmdCopyAccelerationStructureNV-buffer-03718
  AccelerationStructureNV* s = boundStructure(cb, fn, src, "src", "VUID-vkCmdCopyAccelerationStructureNV-src-parameter",
                                              "VUID-vkCmdCopyAccelerationStructureNV-buffer-03718");
  if (!s) return;
  // VUID-vkCmdCopyAccelerationStructureNV-dst-parameter, VUID-vkCmdCopyAccelerationStructureNV-dst-07792
  AccelerationStructureNV* d = boundStructure(cb, fn, dst, "dst", "VUID-vkCmdCopyAccelerationStructureNV-dst-parameter",
                                              "VUID-vkCmdCopyAccelerationStructureNV-dst-07792");
  if (!d) return;
  // VUID-vkCmdCopyAccelerationStructureNV-mode-03410
  if (mode != VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR &&
      mode != VK_COPY_ACCELERATION_STRUCTURE_MODE_COMPACT_KHR) {
    report(cb, Severity::Error, "VUID-vkCmdCopyAccelerationStructureNV-mode-03410",
           "%s: mode %d is neither CLONE nor COMPACT", fn, int(mode));
    return;
  }
  cb->record([cb, s, d, mode](ExecState&) {
    auto c = s->content();
    // VUID-vkCmdCopyAccelerationStructureNV-src-04963
    if (!c) {
      report(cb, Severity::Error, "VUID-vkCmdCopyAccelerationStructureNV-src-04963",
             "vkCmdCopyAccelerationStructureNV: src was never built; nothing is copied");
      return;
    }
    // VUID-vkCmdCopyAccelerationStructureNV-src-03411
    if (mode == VK_COPY_ACCELERATION_STRUCTURE_MODE_COMPACT_KHR &&
        !(c->flags & VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_NV)) {
      report(cb, Severity::Error, "VUID-vkCmdCopyAccelerationStructureNV-src-03411",
             "vkCmdCopyAccelerationStructureNV: COMPACT copy of a structure built without "
             "VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_NV; nothing is copied");
      return;
    }
    d->setContent(c);  // the built content is immutable: the copy shares it
  });
}

VKAPI_ATTR void VKAPI_CALL
vkrt_CmdWriteAccelerationStructuresPropertiesNV(VkCommandBuffer commandBuffer, uint32_t accelerationStructureCount,
                                                const VkAccelerationStructureNV* pAccelerationStructures,
                                                VkQueryType queryType, VkQueryPool queryPool, uint32_t firstQuery) {
  const char* fn = "vkCmdWriteAccelerationStructuresPropertiesNV";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  // VUID-vkCmdWriteAccelerationStructuresPropertiesNV-queryType-06216
  if (queryType != VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_NV) {
    report(cb, Severity::Error, "VUID-vkCmdWriteAccelerationStructuresPropertiesNV-queryType-06216",
           "%s: queryType %d is not VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_NV", fn, int(queryType));
    return;
  }
  // VUID-vkCmdWriteAccelerationStructuresPropertiesNV-queryPool-parameter
  auto* pool = liveOrReport<QueryPool>(cb, queryPool, fn,
                                       "VUID-vkCmdWriteAccelerationStructuresPropertiesNV-queryPool-parameter");
  if (!pool) return;
  // VUID-vkCmdWriteAccelerationStructuresPropertiesNV-queryPool-03755
  if (pool->type != queryType) {
    report(pool, Severity::Error, "VUID-vkCmdWriteAccelerationStructuresPropertiesNV-queryPool-03755",
           "%s: queryType %d does not match the pool's type %d", fn, int(queryType), int(pool->type));
    return;
  }
  // (No VUID names the range; the KHR command's is VUID-vkCmdWriteAccelerationStructuresPropertiesKHR-query-04880.)
  if (uint64_t(firstQuery) + accelerationStructureCount > pool->count) {
    report(pool, Severity::Error, nullptr, "%s: firstQuery %u + %u structures exceeds the pool's %u queries", fn,
           firstQuery, accelerationStructureCount, pool->count);
    return;
  }
  std::vector<AccelerationStructureNV*> structures;
  for (uint32_t i = 0; i < accelerationStructureCount; ++i) {
    char what[64];
    std::snprintf(what, sizeof what, "pAccelerationStructures[%u]", i);
    // VUID-vkCmdWriteAccelerationStructuresPropertiesNV-pAccelerationStructures-parameter,
    // VUID-vkCmdWriteAccelerationStructuresPropertiesNV-accelerationStructure-03757
    auto* as = boundStructure(cb, fn, pAccelerationStructures[i], what,
                              "VUID-vkCmdWriteAccelerationStructuresPropertiesNV-pAccelerationStructures-parameter",
                              "VUID-vkCmdWriteAccelerationStructuresPropertiesNV-accelerationStructure-03757");
    if (!as) return;
    structures.push_back(as);
  }
  cb->record([cb, structures, pool, firstQuery](ExecState&) {
    for (uint32_t i = 0; i < structures.size(); ++i) {
      uint64_t v = 0;
      auto c = structures[i]->content();
      if (!c) {
        // VUID-vkCmdWriteAccelerationStructuresPropertiesNV-pAccelerationStructures-04958
        report(cb, Severity::Error, "VUID-vkCmdWriteAccelerationStructuresPropertiesNV-pAccelerationStructures-04958",
               "vkCmdWriteAccelerationStructuresPropertiesNV: pAccelerationStructures[%u] was never built; its query "
               "reads 0",
               i);
      } else if (!(c->flags & VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_NV)) {
        // VUID-vkCmdWriteAccelerationStructuresPropertiesNV-pAccelerationStructures-06215
        report(cb, Severity::Error, "VUID-vkCmdWriteAccelerationStructuresPropertiesNV-pAccelerationStructures-06215",
               "vkCmdWriteAccelerationStructuresPropertiesNV: pAccelerationStructures[%u] was not built with "
               "VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_NV; its query reads 0",
               i);
      } else {
        // The compacted size is the KHR query's: the size a structure of its primitives needs.
        v = requiredSize(c->tlas ? c->tlas->instances().size() : c->blas->primitiveCount());
      }
      pool->writeValue(firstQuery + i, v);
    }
  });
}

}  // extern "C"
