// Runs compiled compute shaders below the Vulkan API: buffers are host vectors bound to set 0 by binding
// number, through hand-made descriptor records (the layout abi/abi.hpp documents).
#pragma once

#include <gtest/gtest.h>

#include <cstring>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "runtime/compute_pipeline.hpp"
#include "runtime/image_functions.hpp"
#include "runtime/image_view.hpp"
#include "spirv/compiler.hpp"

namespace vkrt::testing {

// Sets the SPMD setting (VKRT_SPMD; spirv::setSpmd) for a scope.
class SpmdSetting {
 public:
  explicit SpmdSetting(bool on) : was_(spirv::spmdEnabled()) { spirv::setSpmd(on); }
  ~SpmdSetting() { spirv::setSpmd(was_); }

 private:
  bool was_;
};

struct ComputeHarness {
  std::map<uint32_t, std::vector<uint64_t>> buffers;  // binding -> storage (8-byte aligned)
  std::map<uint32_t, size_t> sizes;                   // binding -> bytes
  // Descriptor arrays: binding -> the keys (of `buffers`) of its elements; those keys are not bindings.
  std::map<uint32_t, std::vector<uint32_t>> arrays;
  std::shared_ptr<spirv::CompiledShader> shader;
  std::string error;
  alignas(16) uint8_t push[abi::kPushConstantBytes] = {};
  std::map<uint32_t, uint64_t> structures;                 // binding -> acceleration structure address
  std::map<uint32_t, const void*> images;                  // binding -> the image view (a vkrt Object) of its record
  std::map<uint32_t, abi::DescriptorRecord> givenRecords;  // binding -> a record as given (bindings above lack)
  const abi::RayQueryScope* rayQueries = nullptr;          // the dispatch's ray query runtime
  exec::Job* job = nullptr;  // the supervision (exec/supervise.hpp); null: the executor's own

  template <size_t N>
  bool compile(const uint32_t (&words)[N], std::vector<spirv::SpecValue> spec = {}) {
    spirv::CompileRequest r;
    r.words = words;
    r.wordCount = N;
    r.specialization = std::move(spec);
    r.hostSymbols = imageFunctionSymbols();
    shader = spirv::compile(r, &error);
    return shader != nullptr;
  }

  template <class T>
  void setBuffer(uint32_t binding, const std::vector<T>& data) {
    size_t bytes = data.size() * sizeof(T);
    buffers[binding].assign((bytes + 7) / 8, 0);
    std::memcpy(buffers[binding].data(), data.data(), bytes);
    sizes[binding] = bytes;
  }
  template <class T>
  void zeroBuffer(uint32_t binding, size_t count) {
    setBuffer(binding, std::vector<T>(count));
  }
  template <class T>
  std::vector<T> get(uint32_t binding) const {
    std::vector<T> out(sizes.at(binding) / sizeof(T));
    std::memcpy(out.data(), buffers.at(binding).data(), out.size() * sizeof(T));
    return out;
  }

  bool run(uint32_t x, uint32_t y = 1, uint32_t z = 1, uint32_t bx = 0, uint32_t by = 0, uint32_t bz = 0) {
    std::vector<std::vector<abi::DescriptorRecord>> records(shader->resources.size());
    std::vector<abi::ResourceSlot> slots(shader->resources.size());
    for (size_t i = 0; i < shader->resources.size(); ++i) {
      const spirv::ResourceBinding& rb = shader->resources[i];
      auto ait = arrays.find(rb.binding);
      std::vector<uint32_t> keys = ait != arrays.end() ? ait->second : std::vector<uint32_t>{rb.binding};
      for (uint32_t key : keys) {
        abi::DescriptorRecord rec{};
        auto it = buffers.find(key);
        if (rb.set == 0 && rb.kind == spirv::ResourceBinding::AccelerationStructure && structures.count(key)) {
          rec.address = structures[key];
        } else if (rb.set == 0 && it != buffers.end()) {
          rec.address = reinterpret_cast<uint64_t>(it->second.data());
          rec.range = sizes[key];
        } else if (rb.set == 0 && images.count(key)) {
          rec.object = images[key];
          // As the runtime writes an image view's record (abi.hpp): its texels at `address`.
          const auto* o = static_cast<const Object*>(rec.object);
          if (o && o->objectType == VK_OBJECT_TYPE_IMAGE_VIEW)
            rec.address = reinterpret_cast<uint64_t>(&static_cast<const ImageView*>(o)->store.texels);
        } else if (rb.set == 0 && givenRecords.count(key)) {
          rec = givenRecords[key];
        }
        records[i].push_back(rec);
      }
      slots[i] = {records[i].data(), records[i].size()};
    }
    exec::ComputeDispatch d;
    d.kernel = computeKernel(*shader);
    d.resources = slots.data();
    d.pushConstants = push;
    d.rayQueries = rayQueries;
    d.job = job;
    d.count[0] = x;
    d.count[1] = y;
    d.count[2] = z;
    d.base[0] = bx;
    d.base[1] = by;
    d.base[2] = bz;
    return exec::runCompute(d);
  }
};

}  // namespace vkrt::testing
