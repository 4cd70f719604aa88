// Texel buffers in compute shaders, end to end with the validation layer on: uniform texel buffers (texelFetch)
// and storage texel buffers (imageLoad, imageStore, image atomics) through buffer views of several formats and
// offsets, their sizes, arrays of them indexed per invocation (VK_EXT_descriptor_indexing, enabled by name), and
// views at texel-aligned offsets (VK_EXT_texel_buffer_alignment, enabled by name).
// Expected values are computed here on the CPU.
#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

#include "compute_texel_buffer_arrays.comp.spv.h"
#include "compute_texel_buffers.comp.spv.h"
#include "e2e/compute_pipeline_helpers.hpp"
#include "e2e/fixture.hpp"

namespace vkrt::test {
namespace {

constexpr VkDescriptorType kUniformTexel = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
constexpr VkDescriptorType kStorageTexel = VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER;
constexpr VkDescriptorType kStorageBuffer = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;

class TexelBufferTest : public VulkanTest {
 protected:
  // A host-visible buffer of `bytes` and a view of `texels` texels of `format` at byte `offset`.
  struct Texels {
    HostBuffer buffer;
    VkBufferView view = VK_NULL_HANDLE;
  };
  Texels makeTexels(VkFormat format, VkDeviceSize bytes, VkDeviceSize offset, VkDeviceSize range,
                    VkBufferUsageFlags usage) {
    Texels t;
    t.buffer = createHostBuffer(bytes, usage);
    VkBufferViewCreateInfo ci{VK_STRUCTURE_TYPE_BUFFER_VIEW_CREATE_INFO};
    ci.buffer = t.buffer.buffer;
    ci.format = format;
    ci.offset = offset;
    ci.range = range;
    EXPECT_EQ(vkCreateBufferView(device, &ci, nullptr, &t.view), VK_SUCCESS);
    return t;
  }
  void destroy(Texels& t) {
    vkDestroyBufferView(device, t.view, nullptr);
    VulkanTest::destroy(t.buffer);
  }
  using VulkanTest::destroy;

  void writeTexels(ComputePipeline& p, uint32_t binding, VkDescriptorType type, VkBufferView view,
                   uint32_t element = 0) {
    VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    w.dstSet = p.set;
    w.dstBinding = binding;
    w.dstArrayElement = element;
    w.descriptorCount = 1;
    w.descriptorType = type;
    w.pTexelBufferView = &view;
    vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);
  }
  void writeBuffer(ComputePipeline& p, uint32_t binding, const HostBuffer& b) {
    VkDescriptorBufferInfo bi{b.buffer, 0, VK_WHOLE_SIZE};
    VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    w.dstSet = p.set;
    w.dstBinding = binding;
    w.descriptorCount = 1;
    w.descriptorType = kStorageBuffer;
    w.pBufferInfo = &bi;
    vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);
  }
  void dispatch(ComputePipeline& p, uint32_t groups, const void* push = nullptr, uint32_t pushBytes = 0) {
    VkCommandBuffer cb = beginOneTime();
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout, 0, 1, &p.set, 0, nullptr);
    if (pushBytes) vkCmdPushConstants(cb, p.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, pushBytes, push);
    vkCmdDispatch(cb, groups, 1, 1);
    VkMemoryBarrier mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    mb.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
    mb.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &mb, 0, nullptr, 0,
                         nullptr);
    submitAndWait(cb);
  }
  VkDeviceSize texelOffsetAlignment() {
    VkPhysicalDeviceProperties p;
    vkGetPhysicalDeviceProperties(physicalDevice, &p);
    return p.limits.minTexelBufferOffsetAlignment;
  }

  // The shader of compute_texel_buffers.comp over views of four formats, the R8G8B8A8_UNORM one at byte `at`.
  void fetchLoadStoreAtomicsAndSizes(VkDeviceSize at) {
    const bool vkrt = onVkrt();
    ComputePipeline p =
        makeComputePipeline(device, kSpv_compute_texel_buffers_comp, sizeof kSpv_compute_texel_buffers_comp,
                            {kUniformTexel, kUniformTexel, kStorageTexel, kStorageTexel, kStorageBuffer});
    ASSERT_EQ(p.result, VK_SUCCESS);
    constexpr uint32_t kN = 32, kUnorm = 20, kInts = 24, kFloats = 28, kCounters = 34;
    // R8G8B8A8_UNORM at an offset (the bytes before it are not texels of the view): texel i = {i, 2i, 255 - i, 51}.
    Texels unorm = makeTexels(VK_FORMAT_R8G8B8A8_UNORM, at + kUnorm * 4 + 64, at, kUnorm * 4,
                              VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT);
    auto* u8 = static_cast<uint8_t*>(unorm.buffer.data);
    std::memset(u8, 0xff, unorm.buffer.size);
    for (uint32_t i = 0; i < kUnorm; ++i) {
      uint8_t* t = u8 + at + 4 * i;
      t[0] = uint8_t(i);
      t[1] = uint8_t(2 * i);
      t[2] = uint8_t(255 - i);
      t[3] = 51;
    }
    // R16_SINT over the whole buffer: texel i = 3i - 20 (negative below 7).
    Texels ints = makeTexels(VK_FORMAT_R16_SINT, kInts * 2, 0, VK_WHOLE_SIZE, VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT);
    auto* i16 = static_cast<int16_t*>(ints.buffer.data);
    for (uint32_t i = 0; i < kInts; ++i) i16[i] = int16_t(3 * int(i) - 20);
    // R32G32B32A32_SFLOAT, kFloats texels of a buffer of kN: the texels past the view keep their -7.
    Texels floats =
        makeTexels(VK_FORMAT_R32G32B32A32_SFLOAT, kN * 16, 0, kFloats * 16, VK_BUFFER_USAGE_STORAGE_TEXEL_BUFFER_BIT);
    auto* f32 = static_cast<float*>(floats.buffer.data);
    for (uint32_t i = 0; i < kN * 4; ++i) f32[i] = -7.0f;
    // R32_UINT: texels 0-3 are counters (start at 1000 c), texel k >= 4 holds 7k.
    Texels counters =
        makeTexels(VK_FORMAT_R32_UINT, kCounters * 4, 0, VK_WHOLE_SIZE, VK_BUFFER_USAGE_STORAGE_TEXEL_BUFFER_BIT);
    auto* c32 = static_cast<uint32_t*>(counters.buffer.data);
    for (uint32_t k = 0; k < kCounters; ++k) c32[k] = k < 4 ? 1000 * k : 7 * k;
    HostBuffer out = createHostBuffer(4 * (4 + 2 * kN), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    std::memset(out.data, 0x5a, out.size);
    writeTexels(p, 0, kUniformTexel, unorm.view);
    writeTexels(p, 1, kUniformTexel, ints.view);
    writeTexels(p, 2, kStorageTexel, floats.view);
    writeTexels(p, 3, kStorageTexel, counters.view);
    writeBuffer(p, 4, out);
    dispatch(p, 1);

    const auto* o = static_cast<const int32_t*>(out.data);
    EXPECT_EQ(o[0], int32_t(kUnorm)) << "textureSize(unorm view)";
    EXPECT_EQ(o[1], int32_t(kInts)) << "textureSize(VK_WHOLE_SIZE view)";
    EXPECT_EQ(o[2], int32_t(kFloats)) << "imageSize(float view)";
    EXPECT_EQ(o[3], int32_t(kCounters)) << "imageSize(counters)";
    const auto* loaded = reinterpret_cast<const uint32_t*>(o + 4);
    for (uint32_t i = 0; i < kN; ++i) {
      SCOPED_TRACE("invocation " + std::to_string(i));
      // texelFetch: normalized to [0, 1]; the integer's missing components read 0, 0, 1.
      bool inUnorm = i < kUnorm, inInts = i < kInts;
      float want[4] = {0, 0, 0, 0};
      if (inUnorm) {
        want[0] = 2.0f * float(i) / 255.0f;
        want[1] = 2.0f * float(2 * i) / 255.0f;
        want[2] = 2.0f * float(255 - i) / 255.0f;
        want[3] = 2.0f * 51.0f / 255.0f;
      }
      if (inInts) {
        want[0] += float(3 * int(i) - 20);
        want[3] += 1.0f;
      }
      // Past a view's end, robust access reads zeros on vkrt (other drivers may return other values there).
      if (i < kFloats && (vkrt || (inUnorm && inInts))) {
        for (int k = 0; k < 4; ++k) EXPECT_FLOAT_EQ(f32[i * 4 + k], want[k]) << "imageStore component " << k;
      }
      if (i + 4 < kCounters) {
        EXPECT_EQ(loaded[i], 7 * (i + 4)) << "imageLoad";
      } else if (vkrt) {
        EXPECT_EQ(loaded[i], 0u) << "imageLoad past the view";
      }
    }
    if (vkrt) {
      for (uint32_t i = kFloats; i < kN; ++i)
        EXPECT_EQ(f32[i * 4], -7.0f) << "texel " << i << " is past the view: the store is dropped";
    }
    for (uint32_t c = 0; c < 4; ++c) {
      uint32_t sum = 1000 * c;
      for (uint32_t i = c; i < kN; i += 4) sum += i + 1;
      EXPECT_EQ(c32[c], sum) << "imageAtomicAdd on counter " << c;
    }
    for (uint32_t k = 4; k < kCounters; ++k) EXPECT_EQ(c32[k], 7 * k) << "texel " << k << " is only read";
    destroy(unorm);
    destroy(ints);
    destroy(floats);
    destroy(counters);
    destroy(out);
    destroyComputePipeline(device, p);
  }
};

TEST_F(TexelBufferTest, FetchLoadStoreAtomicsAndSizes) { fetchLoadStoreAtomicsAndSizes(texelOffsetAlignment()); }

class TexelBufferIndexingTest : public TexelBufferTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o;
    // By name, as applications written for Vulkan 1.1 still do (its features are Vulkan 1.2's).
    o.deviceExtensions = {VK_EXT_DESCRIPTOR_INDEXING_EXTENSION_NAME};
    enableDescriptorIndexing(o);
    o.features12.descriptorIndexing = VK_TRUE;  // VUID-VkDeviceCreateInfo-ppEnabledExtensionNames-02833
    return o;
  }
};

TEST_F(TexelBufferIndexingTest, TheExtensionsFeaturesAreReported) {
  // The features the specification requires of a device with VK_EXT_descriptor_indexing ("Feature Requirements").
  VkPhysicalDeviceDescriptorIndexingFeatures di{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DESCRIPTOR_INDEXING_FEATURES};
  VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &di};
  vkGetPhysicalDeviceFeatures2(physicalDevice, &f2);
  EXPECT_TRUE(f2.features.shaderSampledImageArrayDynamicIndexing);
  EXPECT_TRUE(f2.features.shaderStorageBufferArrayDynamicIndexing);
  EXPECT_TRUE(di.shaderUniformTexelBufferArrayDynamicIndexing);
  EXPECT_TRUE(di.shaderStorageTexelBufferArrayDynamicIndexing);
  EXPECT_TRUE(di.shaderSampledImageArrayNonUniformIndexing);
  EXPECT_TRUE(di.shaderStorageBufferArrayNonUniformIndexing);
  EXPECT_TRUE(di.shaderUniformTexelBufferArrayNonUniformIndexing);
  EXPECT_TRUE(di.descriptorBindingSampledImageUpdateAfterBind);
  EXPECT_TRUE(di.descriptorBindingStorageImageUpdateAfterBind);
  EXPECT_TRUE(di.descriptorBindingStorageBufferUpdateAfterBind);
  EXPECT_TRUE(di.descriptorBindingUniformTexelBufferUpdateAfterBind);
  EXPECT_TRUE(di.descriptorBindingStorageTexelBufferUpdateAfterBind);
  EXPECT_TRUE(di.descriptorBindingUpdateUnusedWhilePending);
  EXPECT_TRUE(di.descriptorBindingPartiallyBound);
  EXPECT_TRUE(di.runtimeDescriptorArray);
  VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  f2.pNext = &f12;
  vkGetPhysicalDeviceFeatures2(physicalDevice, &f2);
  EXPECT_TRUE(f12.descriptorIndexing);
  if (onVkrt()) {
    VkPhysicalDeviceVulkan12Properties p12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_PROPERTIES};
    VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &p12};
    vkGetPhysicalDeviceProperties2(physicalDevice, &p2);
    EXPECT_TRUE(p12.robustBufferAccessUpdateAfterBind) << "descriptors are bounds-checked when a command executes";
  }
}

TEST_F(TexelBufferIndexingTest, NonUniformAndDynamicIndicesIntoTexelBufferArrays) {
  constexpr uint32_t kTables = 4, kBins = 3, kN = 16;
  ComputePipeline p = makeComputePipelineWithArrays(
      device, kSpv_compute_texel_buffer_arrays_comp, sizeof kSpv_compute_texel_buffer_arrays_comp,
      {{kUniformTexel, kTables}, {kStorageTexel, kBins}, {kStorageBuffer}}, sizeof(uint32_t));
  ASSERT_EQ(p.result, VK_SUCCESS);
  // Table t: R32_SFLOAT, 16 + t texels, texel i = 100 t + i.
  std::vector<Texels> tables, bins;
  for (uint32_t t = 0; t < kTables; ++t) {
    tables.push_back(
        makeTexels(VK_FORMAT_R32_SFLOAT, (kN + t) * 4, 0, VK_WHOLE_SIZE, VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT));
    auto* f = static_cast<float*>(tables.back().buffer.data);
    for (uint32_t i = 0; i < kN + t; ++i) f[i] = float(100 * t + i);
    writeTexels(p, 0, kUniformTexel, tables.back().view, t);
  }
  // Bin s: R32_UINT, 8 + s texels, texel k = 1000 s + k.
  for (uint32_t s = 0; s < kBins; ++s) {
    bins.push_back(
        makeTexels(VK_FORMAT_R32_UINT, (8 + s) * 4, 0, VK_WHOLE_SIZE, VK_BUFFER_USAGE_STORAGE_TEXEL_BUFFER_BIT));
    auto* u = static_cast<uint32_t*>(bins.back().buffer.data);
    for (uint32_t k = 0; k < 8 + s; ++k) u[k] = 1000 * s + k;
    writeTexels(p, 1, kStorageTexel, bins.back().view, s);
  }
  HostBuffer out = createHostBuffer(kN * 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  writeBuffer(p, 2, out);
  const uint32_t pick = 2;
  dispatch(p, 1, &pick, sizeof pick);

  const auto* o = static_cast<const float*>(out.data);
  for (uint32_t i = 0; i < kN; ++i) {
    uint32_t t = (i * 5 + 1) % 4, s = i % 3;
    SCOPED_TRACE("invocation " + std::to_string(i) + ": table " + std::to_string(t) + ", bin " + std::to_string(s));
    EXPECT_EQ(o[i * 4 + 0], float(100 * t + i)) << "texelFetch(tables[nonuniformEXT(t)])";
    EXPECT_EQ(o[i * 4 + 1], float(100 * pick + i)) << "texelFetch(tables[pick])";
    EXPECT_EQ(o[i * 4 + 2], float(kN + t)) << "textureSize";
    EXPECT_EQ(o[i * 4 + 3], float(8 + s)) << "imageSize";
  }
  for (uint32_t s = 0; s < kBins; ++s) {
    const auto* u = static_cast<const uint32_t*>(bins[s].buffer.data);
    uint32_t hits = 0;
    for (uint32_t i = s; i < kN; i += 3) {
      EXPECT_EQ(u[i / 3], (1000 * s + i / 3) * 10 + i) << "bin " << s << " texel " << i / 3;
      ++hits;
    }
    EXPECT_EQ(u[7], 1000 * s + 7 + hits) << "bin " << s << ": imageAtomicAdd";
  }
  for (Texels& t : tables) destroy(t);
  for (Texels& b : bins) destroy(b);
  destroy(out);
  destroyComputePipeline(device, p);
}

// ---- VK_EXT_texel_buffer_alignment (by name, with texelBufferAlignment): views at texel-aligned offsets

class TexelBufferAlignmentTest : public TexelBufferTest {
 protected:
  VkPhysicalDeviceTexelBufferAlignmentFeaturesEXT alignmentFeature{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_TEXEL_BUFFER_ALIGNMENT_FEATURES_EXT};
  FixtureOptions options() override {
    FixtureOptions o;
    o.deviceExtensions = {VK_EXT_TEXEL_BUFFER_ALIGNMENT_EXTENSION_NAME};
    alignmentFeature.texelBufferAlignment = VK_TRUE;
    o.featureChain = &alignmentFeature;
    return o;
  }
  VkPhysicalDeviceTexelBufferAlignmentProperties alignments() {
    VkPhysicalDeviceTexelBufferAlignmentProperties a{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_TEXEL_BUFFER_ALIGNMENT_PROPERTIES};
    VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &a};
    vkGetPhysicalDeviceProperties2(physicalDevice, &p2);
    return a;
  }
};

TEST_F(TexelBufferAlignmentTest, ViewsAtTexelAlignedOffsetsReadTheirTexels) {
  const VkPhysicalDeviceTexelBufferAlignmentProperties a = alignments();
  // A 4-byte texel: the lesser of the alignment in bytes and the texel where single-texel alignment holds.
  const VkDeviceSize unorm = a.uniformTexelBufferOffsetSingleTexelAlignment
                                 ? std::min<VkDeviceSize>(a.uniformTexelBufferOffsetAlignmentBytes, 4)
                                 : a.uniformTexelBufferOffsetAlignmentBytes;
  if (onVkrt()) {
    EXPECT_EQ(unorm, 4u) << "vkrt aligns texel buffer views to a texel";
  }
  fetchLoadStoreAtomicsAndSizes(unorm);
  if (onVkrt()) {
    // A three-component format aligns to one component; a one-byte format to a byte.
    Texels rgb = makeTexels(VK_FORMAT_R32G32B32_SFLOAT, 64, 4, 24, VK_BUFFER_USAGE_STORAGE_TEXEL_BUFFER_BIT);
    Texels bytes = makeTexels(VK_FORMAT_R8_UINT, 64, 3, 8, VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT);
    destroy(rgb);
    destroy(bytes);
  }
}

class TexelBufferAlignmentMisuseTest : public TexelBufferAlignmentTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o = TexelBufferAlignmentTest::options();
    o.validation = false;  // rules are broken on purpose; vkrt's own messages are asserted
    return o;
  }
  VkResult view(VkBuffer buffer, VkFormat format, VkDeviceSize offset) {
    VkBufferViewCreateInfo ci{VK_STRUCTURE_TYPE_BUFFER_VIEW_CREATE_INFO};
    ci.buffer = buffer;
    ci.format = format;
    ci.offset = offset;
    ci.range = VK_WHOLE_SIZE;
    VkBufferView v = VK_NULL_HANDLE;
    VkResult r = vkCreateBufferView(device, &ci, nullptr, &v);
    if (v) vkDestroyBufferView(device, v, nullptr);
    return r;
  }
};

TEST_F(TexelBufferAlignmentMisuseTest, OffsetsBelowATexelAreReported) {
  if (!onVkrt()) GTEST_SKIP() << "vkrt's own reports";
  HostBuffer storage = createHostBuffer(64, VK_BUFFER_USAGE_STORAGE_TEXEL_BUFFER_BIT);
  HostBuffer uniform = createHostBuffer(64, VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT);
  EXPECT_EQ(view(storage.buffer, VK_FORMAT_R32_UINT, 4), VK_SUCCESS);
  EXPECT_EQ(view(storage.buffer, VK_FORMAT_R32_UINT, 2), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkBufferViewCreateInfo-buffer-02750");
  EXPECT_EQ(view(uniform.buffer, VK_FORMAT_R16_SFLOAT, 2), VK_SUCCESS);
  EXPECT_EQ(view(uniform.buffer, VK_FORMAT_R16_SFLOAT, 1), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkBufferViewCreateInfo-buffer-02751");
  destroy(storage);
  destroy(uniform);
}

// Without the feature, minTexelBufferOffsetAlignment (16) holds.
class TexelBufferNoAlignmentFeatureMisuseTest : public TexelBufferTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o;
    o.validation = false;
    return o;
  }
};

TEST_F(TexelBufferNoAlignmentFeatureMisuseTest, OffsetsBelowTheLimitAreReported) {
  if (!onVkrt()) GTEST_SKIP() << "vkrt's own reports";
  HostBuffer storage = createHostBuffer(64, VK_BUFFER_USAGE_STORAGE_TEXEL_BUFFER_BIT);
  VkBufferViewCreateInfo ci{VK_STRUCTURE_TYPE_BUFFER_VIEW_CREATE_INFO};
  ci.buffer = storage.buffer;
  ci.format = VK_FORMAT_R32_UINT;
  ci.offset = 4;
  ci.range = VK_WHOLE_SIZE;
  VkBufferView v = VK_NULL_HANDLE;
  EXPECT_EQ(vkCreateBufferView(device, &ci, nullptr, &v), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkBufferViewCreateInfo-offset-02749");
  destroy(storage);
}

}  // namespace
}  // namespace vkrt::test
