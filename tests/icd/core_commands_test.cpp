// Every command of the core versions vkrt reports (1.0 to 1.3) has an implementation: the generated table
// (tools/gen_entrypoints.py) refers to each through a weak declaration, so a core command vkrt forgot would
// resolve to NULL at run time; this test finds it at build-and-test time instead, naming it.
#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "icd/entrypoint_table.hpp"

namespace {

bool providedByCore(const vkrt::EntryPoint& e) {
  for (uint8_t i = 0; i < e.providerCount; ++i)
    for (const char* v : {"VK_VERSION_1_0", "VK_VERSION_1_1", "VK_VERSION_1_2", "VK_VERSION_1_3"})
      if (std::strcmp(e.providers[i], v) == 0) return true;
  return false;
}

TEST(CoreCommands, EveryCommandOfVulkan13IsImplemented) {
  std::vector<std::string> missing;
  size_t core = 0;
  for (size_t i = 0; i < vkrt::kEntryPointCount; ++i) {
    const vkrt::EntryPoint& e = vkrt::kEntryPoints[i];
    if (!providedByCore(e)) continue;
    ++core;
    if (!e.fn) missing.push_back(e.name);
  }
  // vk.xml of 1.3.239 lists 204 core commands of versions 1.0 to 1.3 (the test would pass vacuously on an empty list).
  EXPECT_GE(core, 200u);
  std::string names;
  for (const std::string& n : missing) names += " " + n;
  EXPECT_TRUE(missing.empty()) << missing.size() << " core commands resolve to NULL:" << names;
}

TEST(CoreCommands, ExtensionOnlyCommandsVkrtLacksStayNull) {
  // The other side: the table does not make up implementations (a mesh shading command is NULL).
  const vkrt::EntryPoint* e = vkrt::findEntryPoint("vkCmdDrawMeshTasksEXT");
  ASSERT_NE(e, nullptr);
  EXPECT_FALSE(providedByCore(*e));
  EXPECT_EQ(e->fn, nullptr);
}

}  // namespace
