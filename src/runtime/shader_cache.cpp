#include "runtime/shader_cache.hpp"

#include <atomic>
#include <cstdio>
#include <map>
#include <mutex>

#include "runtime/descriptor_set_layout.hpp"
#include "runtime/image_functions.hpp"
#include "runtime/pipeline_cache.hpp"
#include "runtime/pipeline_layout.hpp"
#include "runtime/report.hpp"

namespace vkrt {

std::string shaderKey(uint64_t codeHash, const spirv::CompileRequest& request) {
  std::string key = std::to_string(codeHash) + ":" + std::to_string(request.wordCount) + ":" +
                    std::to_string(uint32_t(request.model)) + ":" + std::to_string(request.entryName.size()) + ":" +
                    request.entryName + ":" + (request.combineAdds ? "adds:" : "");
  if (request.colorMerge.format != abi::ColorMerge::kNone)
    key += "merge" + std::to_string(request.colorMerge.format) + "," + std::to_string(request.colorMerge.blend) + "," +
           std::to_string(request.colorMerge.writeMask) + ":";
  for (const spirv::SpecValue& v : request.specialization) {
    key += std::to_string(v.specId) + "=";
    for (uint8_t b : v.bytes) key += char('a' + (b >> 4)), key += char('a' + (b & 15));
    key += ";";
  }
  return key;
}

namespace {

// `shader` is read under either mutex (compileShared under compileMutex, the sweep of unused entries under
// gCacheMutex) and written under both (setShader), so no read races a write.
struct CacheEntry {
  std::mutex compileMutex;  // held while this key compiles
  std::weak_ptr<const spirv::CompiledShader> shader;
};

std::mutex gCacheMutex;
std::map<std::pair<const Device*, std::string>, std::shared_ptr<CacheEntry>> gCache;
std::atomic<uint64_t> gCompiles{0};
std::atomic<uint64_t> gCacheLoads{0};

// The caller holds entry.compileMutex.
void setShader(CacheEntry& entry, const std::shared_ptr<const spirv::CompiledShader>& shader) {
  std::lock_guard<std::mutex> lock(gCacheMutex);
  entry.shader = shader;
}

}  // namespace

uint64_t shaderCompileCount() { return gCompiles.load(); }
uint64_t shaderCacheLoadCount() { return gCacheLoads.load(); }

std::shared_ptr<const spirv::CompiledShader> compileShared(const Device* dev, const std::string& key,
                                                           const spirv::CompileRequest& request, bool mayCompile,
                                                           std::string* error, PipelineCache* cache, bool* cacheHit,
                                                           const char* command) {
  if (cacheHit) *cacheHit = false;
  std::shared_ptr<CacheEntry> entry;
  {
    std::lock_guard<std::mutex> lock(gCacheMutex);
    // Drop entries no pipeline uses any more.
    for (auto it = gCache.begin(); it != gCache.end();) {
      if (it->second->shader.expired() && it->second.use_count() == 1) {
        it = gCache.erase(it);
      } else {
        ++it;
      }
    }
    auto& slot = gCache[{dev, key}];
    if (!slot) slot = std::make_shared<CacheEntry>();
    entry = slot;
  }
  std::string persistentKey = cache ? spirv::cacheKey(request) : std::string();
  std::lock_guard<std::mutex> lock(entry->compileMutex);
  if (auto live = entry->shader.lock()) {
    if (cache && cacheHit) *cacheHit = cache->lookup(persistentKey).has_value();
    return live;
  }
  if (cache) {
    if (std::optional<std::string> blob = cache->lookup(persistentKey)) {
      std::string loadError;
      std::shared_ptr<const spirv::CompiledShader> loaded =
          spirv::loadCached(*blob, imageFunctionSymbols(), &loadError);
      if (loaded) {
        gCacheLoads.fetch_add(1);
        setShader(*entry, loaded);
        if (cacheHit) *cacheHit = true;
        return loaded;
      }
      // A damaged entry: compiled again below (and replaced by storeInCache).
      report(cache, Severity::Warning, nullptr, "%s: ignoring a pipeline cache entry: %s", command, loadError.c_str());
    }
  }
  if (!mayCompile) return nullptr;
  spirv::CompileRequest withHost = request;
  withHost.hostSymbols = imageFunctionSymbols();  // the runtime's image functions (abi/image_functions.hpp)
  std::shared_ptr<const spirv::CompiledShader> shader = spirv::compile(withHost, error);
  gCompiles.fetch_add(1);
  if (shader) setShader(*entry, shader);
  return shader;
}

void storeInCache(PipelineCache* cache, const spirv::CompileRequest& request, const spirv::CompiledShader& shader) {
  if (!cache || shader.cacheBlob.empty()) return;
  std::string key = spirv::cacheKey(request);
  std::optional<std::string> held = cache->lookup(key);
  if (!held) {
    cache->insert(key, shader.cacheBlob);
  } else if (*held != shader.cacheBlob) {
    cache->replace(key, shader.cacheBlob);  // a damaged entry, compiled again
  }
}

LayoutMismatch checkLayoutProvides(const PipelineLayout& layout, const spirv::CompiledShader& shader,
                                   VkShaderStageFlagBits stage, std::string* detail) {
  using RK = spirv::ResourceBinding;
  char buf[256];
  for (const RK& rb : shader.resources) {
    const DescriptorBinding* b =
        rb.set < layout.setLayouts.size() ? layout.setLayouts[rb.set]->bindingAt(rb.binding) : nullptr;
    if (!b || !(b->stages & stage)) {
      std::snprintf(buf, sizeof buf, "the shader uses set %u binding %u, which the pipeline layout %s", rb.set,
                    rb.binding, b ? "does not make visible to its stage" : "does not have");
      *detail = buf;
      return LayoutMismatch::Missing;
    }
    // An inline uniform block is a uniform buffer to the shader (descriptor_set_layout.hpp).
    bool uniformType = b->type == VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER ||
                       b->type == VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC ||
                       b->type == VK_DESCRIPTOR_TYPE_INLINE_UNIFORM_BLOCK;
    bool storageType =
        b->type == VK_DESCRIPTOR_TYPE_STORAGE_BUFFER || b->type == VK_DESCRIPTOR_TYPE_STORAGE_BUFFER_DYNAMIC;
    bool ok = false;
    const char* what = "storage buffer";
    switch (rb.kind) {
      case RK::Buffer:
        ok = rb.uniform ? uniformType : storageType;
        what = rb.uniform ? "uniform buffer" : "storage buffer";
        break;
      case RK::StorageImage:
        ok = b->type == VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
        what = "storage image";
        break;
      case RK::SampledImage:
        ok = b->type == VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE || b->type == VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
        what = "sampled image";
        break;
      case RK::Sampler:
        ok = b->type == VK_DESCRIPTOR_TYPE_SAMPLER || b->type == VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
        what = "sampler";
        break;
      case RK::CombinedImageSampler:
        ok = b->type == VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
        what = "combined image sampler";
        break;
      case RK::UniformTexelBuffer:
        ok = b->type == VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
        what = "uniform texel buffer";
        break;
      case RK::StorageTexelBuffer:
        ok = b->type == VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER;
        what = "storage texel buffer";
        break;
      case RK::InputAttachment:
        ok = b->type == VK_DESCRIPTOR_TYPE_INPUT_ATTACHMENT;
        what = "input attachment";
        break;
      case RK::AccelerationStructure:
        ok = b->type == VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR ||
             b->type == VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_NV;
        what = "acceleration structure";
        break;
    }
    if (!ok) {
      std::snprintf(buf, sizeof buf, "the shader uses set %u binding %u as a %s descriptor, but the layout declares %s",
                    rb.set, rb.binding, what, descriptorTypeName(b->type));
      *detail = buf;
      return LayoutMismatch::Type;
    }
    // An inline uniform block binding is one block (its count is its size; no arrays of them, "Inline Uniform
    // Block" in the interfaces chapter).
    const uint32_t elements = b->type == VK_DESCRIPTOR_TYPE_INLINE_UNIFORM_BLOCK ? 1 : b->count;
    if (rb.arraySize > elements) {
      std::snprintf(buf, sizeof buf, "the shader declares %u descriptors at set %u binding %u, the layout only %u",
                    rb.arraySize, rb.set, rb.binding, elements);
      *detail = buf;
      return LayoutMismatch::Count;
    }
  }
  return LayoutMismatch::None;
}

}  // namespace vkrt
