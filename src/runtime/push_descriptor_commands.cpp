// Push descriptors (VK_KHR_push_descriptor): vkCmdPushDescriptorSetKHR and vkCmdPushDescriptorSetWithTemplateKHR.
//
// A push builds, while it is recorded, a descriptor set of the pipeline layout's push set layout that the command
// buffer owns (DescriptorSet::pushedBy; no handle of it is given out), writes the pushed descriptors into it with
// the code vkUpdateDescriptorSets uses (so every VkWriteDescriptorSet rule is checked the same way, and the
// application's VkDescriptorBufferInfo/ImageInfo arrays are read once, during the call), and records a command
// that binds it at `set` as vkCmdBindDescriptorSets binds an allocated set (the other sets are left as they are).
// The recorded command keeps the set alive as long as the command buffer's recording.
//
// "Push descriptors can be updated incrementally" (the specification's vkCmdPushDescriptorSetKHR): a push starts
// from a copy of the set the previous push of the same bind point and set number built (CommandBuffer::
// pushedSets) when its layout is identically defined, and changes only the copy, so a dispatch, draw or trace
// recorded before the push reads what was pushed before it. A push of another layout, or a vkCmdBindDescriptorSets
// of that set number (which disturbs it), starts from a set with no descriptor written.
#include <cstdio>
#include <memory>

#include "runtime/command_buffer.hpp"
#include "runtime/command_pool.hpp"
#include "runtime/descriptor_set.hpp"
#include "runtime/descriptor_update_template.hpp"
#include "runtime/device.hpp"
#include "runtime/pipeline_layout.hpp"
#include "runtime/report.hpp"
#include "vkrt_entrypoints.h"

using namespace vkrt;

namespace {

using ull = unsigned long long;

// The VUIDs of the rules both commands check on (layout, set).
struct TargetVuids {
  const char* layoutParameter;
  const char* setInRange;
  const char* setIsPush;
};

// `layout` if it is live and `set` is its push descriptor set; otherwise reports (naming `fn`) and returns null.
PipelineLayout* pushTarget(CommandBuffer* cb, VkPipelineLayout layout, uint32_t set, const TargetVuids& v,
                           const char* fn) {
  PipelineLayout* pl = fromHandle<PipelineLayout>(layout);
  if (!pl) {
    report(cb, Severity::Error, v.layoutParameter, "%s: layout 0x%llx is not a live VkPipelineLayout", fn,
           (ull)rawHandle(layout));
    return nullptr;
  }
  // VUID-vkCmdPushDescriptorSetKHR-set-00364, VUID-vkCmdPushDescriptorSetWithTemplateKHR-set-07304
  if (set >= pl->setLayouts.size()) {
    report(pl, Severity::Error, v.setInRange, "%s: set %u is not less than the layout's setLayoutCount %zu", fn, set,
           pl->setLayouts.size());
    return nullptr;
  }
  // VUID-vkCmdPushDescriptorSetKHR-set-00365, VUID-vkCmdPushDescriptorSetWithTemplateKHR-set-07305
  if (!pl->setLayouts[set]->isPush()) {
    report(pl, Severity::Error, v.setIsPush,
           "%s: set %u of the pipeline layout was created without "
           "VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR, "
           "so it is not the layout's push descriptor set",
           fn, set);
    return nullptr;
  }
  return pl;
}

// A new set of `layout` for a push to (bindPoint, set): a copy of the set the previous push there built when its
// layout is identically defined (incremental updates), else a set with no descriptor written.
std::shared_ptr<DescriptorSet> newPushedSet(CommandBuffer* cb, int bindPoint, uint32_t set,
                                            DescriptorSetLayout* layout) {
  auto s = std::make_shared<DescriptorSet>(cb->device, nullptr, layout, 0);
  s->retire();  // not an application object: no handle of it is valid
  s->pushedBy = cb;
  const std::shared_ptr<DescriptorSet>& prev = cb->pushedSets[bindPoint][set];
  if (prev && prev->recordCount == s->recordCount && prev->layout->sameDefinition(*layout)) {
    for (uint32_t i = 0; i < s->recordCount; ++i) {
      s->records()[i] = prev->records()[i];
      s->setWritten(i, prev->written(i));
    }
  }
  return s;
}

// Records the binding of `s` at (bindPoint, set) with pipeline layout `pl`, and keeps it as the set a later push
// there starts from.
void bindPushed(CommandBuffer* cb, int bindPoint, PipelineLayout* pl, uint32_t set, std::shared_ptr<DescriptorSet> s) {
  cb->pushedSets[bindPoint][set] = s;
  cb->record([bindPoint, pl, set, s = std::move(s)](ExecState& st) {
    BindState& bs = st.bound(bindPoint);
    bs.layout = pl;
    bs.sets[set] = s.get();
    bs.dynamicOffsets[set].clear();  // a push descriptor set has no dynamic buffer (VUID-...-flags-00280)
  });
}

}  // namespace

extern "C" {

VKAPI_ATTR void VKAPI_CALL vkrt_CmdPushDescriptorSetKHR(VkCommandBuffer commandBuffer,
                                                        VkPipelineBindPoint pipelineBindPoint, VkPipelineLayout layout,
                                                        uint32_t set, uint32_t descriptorWriteCount,
                                                        const VkWriteDescriptorSet* pDescriptorWrites) {
  const char* fn = "vkCmdPushDescriptorSetKHR";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  const int bp = bindPointIndex(pipelineBindPoint);
  // VUID-vkCmdPushDescriptorSetKHR-pipelineBindPoint-parameter (the queue families support the three bind points)
  if (bp < 0) {
    report(cb, Severity::Error, "VUID-vkCmdPushDescriptorSetKHR-pipelineBindPoint-parameter",
           "%s: pipelineBindPoint %d is not a bind point vkrt supports (graphics, compute, ray tracing)", fn,
           (int)pipelineBindPoint);
    return;
  }
  // VUID-vkCmdPushDescriptorSetKHR-pipelineBindPoint-00363
  if (pipelineBindPoint == VK_PIPELINE_BIND_POINT_GRAPHICS && !cb->supportsGraphics()) {
    report(cb, Severity::Error, "VUID-vkCmdPushDescriptorSetKHR-pipelineBindPoint-00363",
           "%s: VK_PIPELINE_BIND_POINT_GRAPHICS in a command buffer of queue family %u, which has no graphics", fn,
           cb->pool->queueFamilyIndex);
    return;
  }
  static const TargetVuids kVuids = {"VUID-vkCmdPushDescriptorSetKHR-layout-parameter",
                                     "VUID-vkCmdPushDescriptorSetKHR-set-00364",
                                     "VUID-vkCmdPushDescriptorSetKHR-set-00365"};
  PipelineLayout* pl = pushTarget(cb, layout, set, kVuids, fn);
  if (!pl) return;
  // VUID-vkCmdPushDescriptorSetKHR-descriptorWriteCount-arraylength
  if (descriptorWriteCount == 0) {
    report(cb, Severity::Error, "VUID-vkCmdPushDescriptorSetKHR-descriptorWriteCount-arraylength",
           "%s: descriptorWriteCount must be greater than 0", fn);
    return;
  }
  std::shared_ptr<DescriptorSet> s = newPushedSet(cb, bp, set, pl->setLayouts[set]);
  // Every write is checked before any is made: a bad one leaves the push without effect. dstSet is ignored.
  for (bool apply : {false, true}) {
    for (uint32_t i = 0; i < descriptorWriteCount; ++i) {
      const VkWriteDescriptorSet& w = pDescriptorWrites[i];
      char what[64];
      std::snprintf(what, sizeof what, "%s: pDescriptorWrites[%u]", fn, i);
      // VUID-vkCmdPushDescriptorSetKHR-pDescriptorWrites-06494
      const bool imageOnly = w.descriptorType == VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE ||
                             w.descriptorType == VK_DESCRIPTOR_TYPE_STORAGE_IMAGE ||
                             w.descriptorType == VK_DESCRIPTOR_TYPE_INPUT_ATTACHMENT;
      if (!apply && imageOnly && !w.pImageInfo) {
        report(cb, Severity::Error, "VUID-vkCmdPushDescriptorSetKHR-pDescriptorWrites-06494",
               "%s: descriptorType is %s but pImageInfo is null", what, descriptorTypeName(w.descriptorType));
        return;
      }
      if (!writeDescriptorSet(s.get(), w, apply, what)) return;
    }
  }
  bindPushed(cb, bp, pl, set, std::move(s));
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdPushDescriptorSetWithTemplateKHR(VkCommandBuffer commandBuffer,
                                                                    VkDescriptorUpdateTemplate descriptorUpdateTemplate,
                                                                    VkPipelineLayout layout, uint32_t set,
                                                                    const void* pData) {
  const char* fn = "vkCmdPushDescriptorSetWithTemplateKHR";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  auto* t = fromHandle<DescriptorUpdateTemplate>(descriptorUpdateTemplate);
  // VUID-vkCmdPushDescriptorSetWithTemplateKHR-descriptorUpdateTemplate-parameter
  if (!t) {
    report(cb, Severity::Error, "VUID-vkCmdPushDescriptorSetWithTemplateKHR-descriptorUpdateTemplate-parameter",
           "%s: descriptorUpdateTemplate 0x%llx is not a live VkDescriptorUpdateTemplate", fn,
           (ull)rawHandle(descriptorUpdateTemplate));
    return;
  }
  // VUID-vkCmdPushDescriptorSetWithTemplateKHR-commandBuffer-00366: the template's pipelineBindPoint (which only a
  // template of VK_DESCRIPTOR_UPDATE_TEMPLATE_TYPE_PUSH_DESCRIPTORS_KHR has) is one the command buffer's queue family
  // supports.
  const bool pushTemplate = t->type == VK_DESCRIPTOR_UPDATE_TEMPLATE_TYPE_PUSH_DESCRIPTORS_KHR;
  if (!pushTemplate || (t->bindPoint == VK_PIPELINE_BIND_POINT_GRAPHICS && !cb->supportsGraphics())) {
    report(t, Severity::Error, "VUID-vkCmdPushDescriptorSetWithTemplateKHR-commandBuffer-00366",
           pushTemplate
               ? "%s: the template's pipelineBindPoint is VK_PIPELINE_BIND_POINT_GRAPHICS, which queue family %u "
                 "of the command buffer does not support"
               : "%s: the template was created with templateType VK_DESCRIPTOR_UPDATE_TEMPLATE_TYPE_DESCRIPTOR_SET, "
                 "so it has no pipeline bind point to push to (queue family %u)",
           fn, cb->pool->queueFamilyIndex);
    return;
  }
  static const TargetVuids kVuids = {"VUID-vkCmdPushDescriptorSetWithTemplateKHR-layout-parameter",
                                     "VUID-vkCmdPushDescriptorSetWithTemplateKHR-set-07304",
                                     "VUID-vkCmdPushDescriptorSetWithTemplateKHR-set-07305"};
  PipelineLayout* pl = pushTarget(cb, layout, set, kVuids, fn);
  if (!pl) return;
  // VUID-vkCmdPushDescriptorSetWithTemplateKHR-pData-01686
  if (!pData) {
    report(cb, Severity::Error, "VUID-vkCmdPushDescriptorSetWithTemplateKHR-pData-01686", "%s: pData is null", fn);
    return;
  }
  const int bp = bindPointIndex(t->bindPoint);
  std::shared_ptr<DescriptorSet> s = newPushedSet(cb, bp, set, pl->setLayouts[set]);
  // The entries are checked against the command's own set layout, which the descriptors are written into.
  if (!t->write(s.get(), pData, fn)) return;
  bindPushed(cb, bp, pl, set, std::move(s));
}

}  // extern "C"
