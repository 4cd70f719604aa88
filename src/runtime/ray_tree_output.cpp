#include "runtime/ray_tree_output.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <string_view>

#include "runtime/report.hpp"

namespace vkrt {

std::unique_ptr<exec::RayTreeRecorder> rayTreeRecorder(const Device* dev, bool compute) {
  const std::vector<exec::RayTreeId>& ids = compute ? dev->rayTree.computeIds : dev->rayTree.launchIds;
  if (ids.empty()) return nullptr;
  return std::make_unique<exec::RayTreeRecorder>(ids);
}

void deliverRayTrees(const Object* about, Device* dev, exec::RayTreeRecorder& recorder, exec::RayTreeContext ctx,
                     bool skipEmpty) {
  bool any = false;
  for (const exec::RayTreeInvocation& inv : recorder.invocations())
    any = any || (inv.ran && !(skipEmpty && inv.root.children.empty()));
  if (!any) return;
  ctx.sequence = dev->rayTreeSequence.fetch_add(1);
  const std::string_view path = dev->rayTreeOut;
  const bool json = path.ends_with(".json") || path.ends_with(".jsonl");
  std::string file;
  for (const exec::RayTreeInvocation& inv : recorder.invocations()) {
    if (!inv.ran || (skipEmpty && inv.root.children.empty())) continue;
    if (path.empty()) {
      reportText(about, Severity::Info, "vkrt-ray-tree", exec::rayTreeText(inv, ctx));
    } else {
      file += json ? exec::rayTreeJson(inv, ctx) + "\n" : exec::rayTreeText(inv, ctx);
    }
  }
  if (path.empty()) return;
  // Launches on several queues may finish at once: one writer at a time keeps each tree whole.
  static std::mutex m;
  std::lock_guard<std::mutex> lock(m);
  std::FILE* f = std::fopen(dev->rayTreeOut.c_str(), "a");
  if (!f || std::fwrite(file.data(), 1, file.size(), f) != file.size()) {
    report(about, Severity::Warning, nullptr, "%s: could not write the ray trees to VKRT_RAY_TREE_OUT=\"%s\": %s",
           ctx.command.c_str(), dev->rayTreeOut.c_str(), std::strerror(errno));
  }
  if (f) std::fclose(f);
}

}  // namespace vkrt
