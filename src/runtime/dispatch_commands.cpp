// vkCmdDispatch, vkCmdDispatchBase, vkCmdDispatchIndirect: recorded as closures that, at execution, resolve the
// bound compute pipeline's resources from the bound descriptor sets and run the workgroups on the executor
// (src/exec/compute.hpp).
#include <cstring>
#include <memory>
#include <string>

#include "exec/compute.hpp"
#include "exec/ray_tree.hpp"
#include "runtime/acceleration_structure.hpp"
#include "runtime/bound_resources.hpp"
#include "runtime/buffer.hpp"
#include "runtime/command_buffer.hpp"
#include "runtime/compute_pipeline.hpp"
#include "runtime/device.hpp"
#include "runtime/physical_device.hpp"
#include "runtime/ray_tree_output.hpp"
#include "runtime/report.hpp"
#include "runtime/shader_messages.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {
namespace {

using ull = unsigned long long;

// Runs a dispatch with the state bound when the command executes. `cb` is only used to name reports.
void executeDispatch(const CommandBuffer* cb, ExecState& st, const uint32_t base[3], const uint32_t count[3],
                     const char* fn) {
  const BindState& bs = st.compute;
  // VUID-vkCmdDispatch-None-02700 (a compute pipeline must be bound)
  if (!bs.pipeline || bs.pipeline->bindPoint != VK_PIPELINE_BIND_POINT_COMPUTE) {
    report(cb, Severity::Error, "VUID-vkCmdDispatch-None-02700",
           "%s: no compute pipeline is bound; the dispatch is skipped", fn);
    return;
  }
  const auto* pipeline = static_cast<const ComputePipeline*>(bs.pipeline);
  // VUID-vkCmdDispatchBase-baseGroupX-00427
  if ((base[0] || base[1] || base[2]) && !(pipeline->createFlags & VK_PIPELINE_CREATE_DISPATCH_BASE_BIT)) {
    report(cb, Severity::Error, "VUID-vkCmdDispatchBase-baseGroupX-00427",
           "%s: base workgroup (%u, %u, %u) is not zero but the bound pipeline was created without "
           "VK_PIPELINE_CREATE_DISPATCH_BASE_BIT; the dispatch is skipped",
           fn, base[0], base[1], base[2]);
    return;
  }
  const spirv::CompiledShader& sh = *pipeline->shader;
  BoundResources resources;
  resources.resolve(sh, bs, cb, fn, "VUID-vkCmdDispatch-None-02697");
  exec::ComputeDispatch d;
  d.kernel = computeKernel(sh);
  d.resources = resources.slots();
  d.pushConstants = st.pushConstants;
  DispatchStructures structures(cb->device, cb, fn);
  exec::RayQueryScope rayQueries(&structures);
  d.rayQueries = &rayQueries;
  // VKRT_RAY_TREE's compute ids (decided once per dispatch): every invocation's ray queries go through the
  // recorder's scope, which records those of the named ids.
  std::unique_ptr<exec::RayTreeRecorder> rayTree = rayTreeRecorder(cb->device, true);
  const std::string shaderName = "compute shader \"" + sh.entryName + "\"";
  if (rayTree) {
    rayTree->setQueryScope(&rayQueries);
    for (exec::RayTreeInvocation& inv : rayTree->invocations()) {
      inv.root.stage = "compute";
      inv.root.name = shaderName;
    }
    d.rayQueries = rayTree->computeScope();
  }
  for (int k = 0; k < 3; ++k) {
    d.base[k] = base[k];
    d.count[k] = count[k];
  }
  // Supervised (the watchdog's time limit, fault recovery): registered before the device's halted() check, so
  // that vkDestroyDevice either finds the job to cancel or has already made the check fail.
  Device* dev = cb->device;
  exec::Job job(dev, dev->shaderTimeoutMs);
  job.shaderName = shaderName.c_str();
  if (dev->halted()) return;
  d.job = &job;
  if (!exec::runCompute(d))
    report(cb, Severity::Error, nullptr, "%s: out of memory for workgroup fibers; workgroups were skipped", fn);
  if (job.aborted()) dev->shaderAborted(pipeline, fn, job.abort());
  deliverShaderMessages(cb, pipeline, fn, job.messages, descriptorNamer(sh, d.resources));
  if (rayTree) {
    exec::RayTreeContext ctx;
    ctx.command = fn;
    ctx.pipeline = pipeline->handleValue();
    ctx.compute = true;
    for (int k = 0; k < 3; ++k) ctx.size[k] = count[k];
    deliverRayTrees(cb, dev, *rayTree, std::move(ctx), true);
  }
}

const VkPhysicalDeviceLimits& limitsOf(const CommandBuffer* cb) {
  return cb->device->physicalDevice->properties10.limits;
}

}  // namespace
}  // namespace vkrt

using namespace vkrt;

extern "C" {

VKAPI_ATTR void VKAPI_CALL vkrt_CmdDispatch(VkCommandBuffer commandBuffer, uint32_t groupCountX, uint32_t groupCountY,
                                            uint32_t groupCountZ) {
  const char* fn = "vkCmdDispatch";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  // VUID-vkCmdDispatch-renderpass: outside a render pass instance
  if (!cb->outsideRenderPass(fn, "VUID-vkCmdDispatch-renderpass")) return;
  const uint32_t count[3] = {groupCountX, groupCountY, groupCountZ};
  static const char* const kVuids[3] = {"VUID-vkCmdDispatch-groupCountX-00386", "VUID-vkCmdDispatch-groupCountY-00387",
                                        "VUID-vkCmdDispatch-groupCountZ-00388"};
  for (int k = 0; k < 3; ++k) {
    // VUID-vkCmdDispatch-groupCountX-00386, VUID-vkCmdDispatch-groupCountY-00387, VUID-vkCmdDispatch-groupCountZ-00388
    if (count[k] > limitsOf(cb).maxComputeWorkGroupCount[k]) {
      report(cb, Severity::Error, kVuids[k], "%s: groupCount%c (%u) exceeds maxComputeWorkGroupCount[%d] (%u)", fn,
             "XYZ"[k], count[k], k, limitsOf(cb).maxComputeWorkGroupCount[k]);
      return;
    }
  }
  cb->record([cb, x = groupCountX, y = groupCountY, z = groupCountZ](ExecState& st) {
    const uint32_t base[3] = {0, 0, 0}, count[3] = {x, y, z};
    executeDispatch(cb, st, base, count, "vkCmdDispatch");
  });
}

// A device group of one device (vkEnumeratePhysicalDeviceGroups): the only valid device mask is 1, and setting it
// changes nothing.
VKAPI_ATTR void VKAPI_CALL vkrt_CmdSetDeviceMask(VkCommandBuffer commandBuffer, uint32_t deviceMask) {
  const char* fn = "vkCmdSetDeviceMask";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  // VUID-vkCmdSetDeviceMask-deviceMask-00109, VUID-vkCmdSetDeviceMask-deviceMask-00108
  if (deviceMask != 1)
    report(cb, Severity::Error,
           deviceMask == 0 ? "VUID-vkCmdSetDeviceMask-deviceMask-00109" : "VUID-vkCmdSetDeviceMask-deviceMask-00108",
           "%s: deviceMask 0x%x is not a valid device mask of vkrt's device group of one device (only 0x1 is)", fn,
           deviceMask);
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdDispatchBase(VkCommandBuffer commandBuffer, uint32_t baseGroupX, uint32_t baseGroupY,
                                                uint32_t baseGroupZ, uint32_t groupCountX, uint32_t groupCountY,
                                                uint32_t groupCountZ) {
  const char* fn = "vkCmdDispatchBase";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  // VUID-vkCmdDispatchBase-renderpass: outside a render pass instance
  if (!cb->outsideRenderPass(fn, "VUID-vkCmdDispatchBase-renderpass")) return;
  const uint32_t base[3] = {baseGroupX, baseGroupY, baseGroupZ};
  const uint32_t count[3] = {groupCountX, groupCountY, groupCountZ};
  static const char* const kBaseVuids[3] = {"VUID-vkCmdDispatchBase-baseGroupX-00421",
                                            "VUID-vkCmdDispatchBase-baseGroupX-00422",
                                            "VUID-vkCmdDispatchBase-baseGroupZ-00423"};
  static const char* const kCountVuids[3] = {"VUID-vkCmdDispatchBase-groupCountX-00424",
                                             "VUID-vkCmdDispatchBase-groupCountY-00425",
                                             "VUID-vkCmdDispatchBase-groupCountZ-00426"};
  for (int k = 0; k < 3; ++k) {
    uint32_t max = limitsOf(cb).maxComputeWorkGroupCount[k];
    // VUID-vkCmdDispatchBase-baseGroupX-00421, VUID-vkCmdDispatchBase-baseGroupX-00422,
    // VUID-vkCmdDispatchBase-baseGroupZ-00423
    if (base[k] >= max) {
      report(cb, Severity::Error, kBaseVuids[k],
             "%s: baseGroup%c (%u) is not less than maxComputeWorkGroupCount[%d] (%u)", fn, "XYZ"[k], base[k], k, max);
      return;
    }
    // VUID-vkCmdDispatchBase-groupCountX-00424, VUID-vkCmdDispatchBase-groupCountY-00425,
    // VUID-vkCmdDispatchBase-groupCountZ-00426
    if (count[k] > max - base[k]) {
      report(cb, Severity::Error, kCountVuids[k],
             "%s: groupCount%c (%u) exceeds maxComputeWorkGroupCount[%d] (%u) minus baseGroup%c (%u)", fn, "XYZ"[k],
             count[k], k, max, "XYZ"[k], base[k]);
      return;
    }
  }
  cb->record([cb, bx = baseGroupX, by = baseGroupY, bz = baseGroupZ, x = groupCountX, y = groupCountY,
              z = groupCountZ](ExecState& st) {
    const uint32_t b[3] = {bx, by, bz}, c[3] = {x, y, z};
    executeDispatch(cb, st, b, c, "vkCmdDispatchBase");
  });
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdDispatchIndirect(VkCommandBuffer commandBuffer, VkBuffer buffer,
                                                    VkDeviceSize offset) {
  const char* fn = "vkCmdDispatchIndirect";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  // VUID-vkCmdDispatchIndirect-renderpass: outside a render pass instance
  if (!cb->outsideRenderPass(fn, "VUID-vkCmdDispatchIndirect-renderpass")) return;
  Buffer* buf = fromHandle<Buffer>(buffer);
  // VUID-vkCmdDispatchIndirect-buffer-parameter
  if (!buf) {
    report(cb, Severity::Error, "VUID-vkCmdDispatchIndirect-buffer-parameter",
           "%s: buffer 0x%llx is not a live VkBuffer", fn, (ull)rawHandle(buffer));
    return;
  }
  // VUID-vkCmdDispatchIndirect-buffer-02709
  if (!(buf->usage & VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT)) {
    report(buf, Severity::Error, "VUID-vkCmdDispatchIndirect-buffer-02709",
           "%s: buffer was created with usage 0x%x, without VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT", fn, buf->usage);
    return;
  }
  // VUID-vkCmdDispatchIndirect-buffer-02708
  if (!buf->memory) {
    report(buf, Severity::Error, "VUID-vkCmdDispatchIndirect-buffer-02708", "%s: buffer is not bound to memory", fn);
    return;
  }
  // VUID-vkCmdDispatchIndirect-offset-02710
  if (offset % 4) {
    report(buf, Severity::Error, "VUID-vkCmdDispatchIndirect-offset-02710", "%s: offset %llu is not a multiple of 4",
           fn, (ull)offset);
    return;
  }
  // VUID-vkCmdDispatchIndirect-offset-00407
  if (offset > buf->size || buf->size - offset < sizeof(VkDispatchIndirectCommand)) {
    report(buf, Severity::Error, "VUID-vkCmdDispatchIndirect-offset-00407",
           "%s: offset %llu + sizeof(VkDispatchIndirectCommand) (12) exceeds the buffer size %llu", fn, (ull)offset,
           (ull)buf->size);
    return;
  }
  cb->record([cb, buf, offset](ExecState& st) {
    VkDispatchIndirectCommand c;
    std::memcpy(&c, buf->data() + offset, sizeof c);
    const uint32_t base[3] = {0, 0, 0}, count[3] = {c.x, c.y, c.z};
    static const char* const kVuids[3] = {"VUID-VkDispatchIndirectCommand-x-00417",
                                          "VUID-VkDispatchIndirectCommand-y-00418",
                                          "VUID-VkDispatchIndirectCommand-z-00419"};
    for (int k = 0; k < 3; ++k) {
      // VUID-VkDispatchIndirectCommand-x-00417, VUID-VkDispatchIndirectCommand-y-00418,
      // VUID-VkDispatchIndirectCommand-z-00419
      if (count[k] > limitsOf(cb).maxComputeWorkGroupCount[k]) {
        report(cb, Severity::Error, kVuids[k],
               "vkCmdDispatchIndirect: the buffer's %c count (%u) exceeds maxComputeWorkGroupCount[%d] (%u); "
               "the dispatch is skipped",
               "xyz"[k], count[k], k, limitsOf(cb).maxComputeWorkGroupCount[k]);
        return;
      }
    }
    executeDispatch(cb, st, base, count, "vkCmdDispatchIndirect");
  });
}

}  // extern "C"
