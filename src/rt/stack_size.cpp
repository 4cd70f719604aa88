#include "rt/stack_size.hpp"

#include <algorithm>

namespace vkrt::rt {

void StageStackMax::add(const ShaderDesc& s) {
  uint64_t v = s.stackSize();
  switch (s.stage) {
    case VK_SHADER_STAGE_RAYGEN_BIT_KHR: rayGen = std::max(rayGen, v); break;
    case VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR: closestHit = std::max(closestHit, v); break;
    case VK_SHADER_STAGE_MISS_BIT_KHR: miss = std::max(miss, v); break;
    case VK_SHADER_STAGE_INTERSECTION_BIT_KHR: intersection = std::max(intersection, v); break;
    case VK_SHADER_STAGE_ANY_HIT_BIT_KHR: anyHit = std::max(anyHit, v); break;
    case VK_SHADER_STAGE_CALLABLE_BIT_KHR: callable = std::max(callable, v); break;
    default: break;
  }
}

uint64_t defaultPipelineStackSize(const StageStackMax& m, uint32_t depth) {
  uint64_t first = std::max({m.closestHit, m.miss, m.intersection + m.anyHit});
  uint64_t rest = std::max(m.closestHit, m.miss);
  return m.rayGen + std::min<uint64_t>(1, depth) * first + (depth > 1 ? depth - 1 : 0) * rest + 2 * m.callable;
}

uint64_t defaultPipelineStackSize(const std::vector<const GroupRecord*>& groups, uint32_t depth) {
  StageStackMax m;
  for (const GroupRecord* g : groups)
    for (auto& s : g->desc.shaders)
      if (s) m.add(*s);
  return defaultPipelineStackSize(m, depth);
}

}  // namespace vkrt::rt
