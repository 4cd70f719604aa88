// vkCreateShaderModule: real GLSL compute shaders compiled at build time, and corrupted SPIR-V.
#include <vector>

#include "compute_fill.comp.spv.h"
#include "compute_sum.comp.spv.h"
#include "e2e/fixture.hpp"

namespace vkrt::test {
namespace {

using ShaderModuleTest = VulkanTest;

VkResult create(VkDevice device, const uint32_t* words, size_t bytes, VkShaderModule* out) {
  VkShaderModuleCreateInfo ci{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  ci.codeSize = bytes;
  ci.pCode = words;
  return vkCreateShaderModule(device, &ci, nullptr, out);
}

TEST_F(ShaderModuleTest, RealComputeShadersAreAccepted) {
  VkShaderModule a = VK_NULL_HANDLE, b = VK_NULL_HANDLE;
  ASSERT_EQ(create(device, kSpv_compute_fill_comp, sizeof(kSpv_compute_fill_comp), &a), VK_SUCCESS);
  ASSERT_EQ(create(device, kSpv_compute_sum_comp, sizeof(kSpv_compute_sum_comp), &b), VK_SUCCESS);
  EXPECT_NE(a, VK_NULL_HANDLE);
  EXPECT_NE(a, b);
  vkDestroyShaderModule(device, a, nullptr);
  vkDestroyShaderModule(device, b, nullptr);
}

class ShaderModuleMisuseTest : public VulkanTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o;
    o.validation = false;  // the layer validates SPIR-V too
    return o;
  }
};

TEST_F(ShaderModuleMisuseTest, SizeAlignmentAndMagicAreChecked) {
  std::vector<uint32_t> words(kSpv_compute_fill_comp, kSpv_compute_fill_comp + sizeof(kSpv_compute_fill_comp) / 4);
  VkShaderModule m = VK_NULL_HANDLE;
  EXPECT_EQ(create(device, words.data(), words.size() * 4 - 2, &m), VK_ERROR_INVALID_SHADER_NV);
  expectVkrtMessage("VUID-VkShaderModuleCreateInfo-pCode-01376");
  EXPECT_EQ(m, VK_NULL_HANDLE);
  EXPECT_EQ(create(device, words.data(), 0, &m), VK_ERROR_INVALID_SHADER_NV);
  expectVkrtMessage("VUID-VkShaderModuleCreateInfo-codeSize-01085");
  words[0] = 0x03022307;  // byte-swapped magic
  EXPECT_EQ(create(device, words.data(), words.size() * 4, &m), VK_ERROR_INVALID_SHADER_NV);
  expectVkrtMessage("VUID-VkShaderModuleCreateInfo-pCode-01377");
  EXPECT_EQ(m, VK_NULL_HANDLE);
}

TEST_F(ShaderModuleMisuseTest, CorruptedWordsAreRejectedWithThePosition) {
  const size_t n = sizeof(kSpv_compute_fill_comp) / 4;
  // Truncation in the middle of the instruction stream.
  std::vector<uint32_t> words(kSpv_compute_fill_comp, kSpv_compute_fill_comp + n);
  VkShaderModule m = VK_NULL_HANDLE;
  EXPECT_EQ(create(device, words.data(), (n - 3) * 4, &m), VK_ERROR_INVALID_SHADER_NV);
  auto msgs = vkrtMessages();
  ASSERT_EQ(msgs.size(), 1u);
  EXPECT_EQ(msgs[0].idName, "VUID-VkShaderModuleCreateInfo-pCode-01378");
  clearMessages();

  // An ID bound smaller than the IDs used (header word 3).
  words[3] = 2;
  EXPECT_EQ(create(device, words.data(), n * 4, &m), VK_ERROR_INVALID_SHADER_NV);
  msgs = vkrtMessages();
  ASSERT_EQ(msgs.size(), 1u);
  EXPECT_EQ(msgs[0].idName, "VUID-VkShaderModuleCreateInfo-pCode-01378");
  EXPECT_NE(msgs[0].text.find("at word"), std::string::npos) << msgs[0].text;
  clearMessages();

  // Every single-word corruption of the instruction stream either validates or is refused cleanly (never a
  // crash); at least some are refused.
  int refused = 0;
  for (size_t i = 5; i < n; i += 7) {
    std::vector<uint32_t> bad(kSpv_compute_fill_comp, kSpv_compute_fill_comp + n);
    bad[i] ^= 0x00ff00ffu;
    VkResult r = create(device, bad.data(), n * 4, &m);
    if (r == VK_SUCCESS) {
      vkDestroyShaderModule(device, m, nullptr);
    } else {
      EXPECT_EQ(r, VK_ERROR_INVALID_SHADER_NV);
      ++refused;
    }
  }
  EXPECT_GT(refused, 0);
  for (auto& msg : vkrtMessages()) EXPECT_EQ(msg.idName, "VUID-VkShaderModuleCreateInfo-pCode-01378") << msg.text;
  clearMessages();
}

}  // namespace
}  // namespace vkrt::test
