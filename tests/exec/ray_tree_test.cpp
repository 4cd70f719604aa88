// VKRT_RAY_TREE's parser (exec/ray_tree.hpp): the selections it reads, and malformed input answered with a message
// that names what is wrong (no crash, nothing selected). The trees themselves are tested through the loader
// (tests/e2e/ray_tree_test.cpp).
#include <gtest/gtest.h>

#include <limits>
#include <string>

#include "exec/ray_tree.hpp"

namespace vkrt::exec {
namespace {

using Ids = std::vector<RayTreeId>;

TEST(RayTreeSetting, LaunchIdsAndComputeIdsSortedWithoutDuplicates) {
  RayTreeSelection s;
  std::string error;
  ASSERT_TRUE(parseRayTreeSelection("3,4; 1 , 2 ,7;compute:5;3,4,0;compute:1,2", &s, &error)) << error;
  EXPECT_EQ(s.launchIds, (Ids{{1, 2, 7}, {3, 4, 0}}));
  EXPECT_EQ(s.computeIds, (Ids{{1, 2, 0}, {5, 0, 0}}));
  ASSERT_TRUE(parseRayTreeSelection("0,0;", &s, &error)) << error;  // a trailing ';'
  EXPECT_EQ(s.launchIds, (Ids{{0, 0, 0}}));
  EXPECT_TRUE(s.computeIds.empty());
  ASSERT_TRUE(parseRayTreeSelection("4294967295,0,4294967295", &s, &error)) << error;
  EXPECT_EQ(s.launchIds, (Ids{{4294967295u, 0, 4294967295u}}));
}

TEST(RayTreeSetting, MalformedInputIsRejectedWithAMessage) {
  const struct {
    const char* text;
    const char* says;
  } kCases[] = {
      {"", "empty entry"},
      {";", "empty entry"},
      {"1", "1 number(s), at least 2"},
      {"compute:", "expected a number"},
      {"1,2,3,4", "more than three numbers"},
      {"1,,2", "expected a number"},
      {"1,2;;3,4", "empty entry"},
      {"x,y", "expected a number"},
      {"-1,2", "expected a number"},
      {"1.5,2", "unexpected '.'"},
      {"1,2 3", "unexpected '3'"},
      {"4294967296,0", "above 4294967295"},
      {"99999999999999999999999,0", "above 4294967295"},
      {"launch:1,2", "expected a number"},
      {"1,2,", "expected a number"},
  };
  for (const auto& c : kCases) {
    SCOPED_TRACE(c.text);
    RayTreeSelection s;
    s.launchIds.push_back({9, 9, 9});
    std::string error;
    EXPECT_FALSE(parseRayTreeSelection(c.text, &s, &error));
    EXPECT_NE(error.find(c.says), std::string::npos) << error;
    EXPECT_TRUE(s.empty()) << "nothing is selected after an error";
  }
}

TEST(RayTreeSetting, RecorderFindsOnlyNamedIds) {
  RayTreeRecorder r(Ids{{0, 0, 0}, {2, 1, 0}, {7, 3, 1}});
  const uint32_t a[3] = {2, 1, 0}, b[3] = {2, 1, 1}, c[3] = {7, 3, 1}, d[3] = {1, 0, 0};
  ASSERT_NE(r.find(a), nullptr);
  EXPECT_EQ(r.find(a)->id, (RayTreeId{2, 1, 0}));
  EXPECT_EQ(r.find(b), nullptr);
  ASSERT_NE(r.find(c), nullptr);
  EXPECT_EQ(r.find(d), nullptr);
  const uint32_t lo[3] = {0, 0, 0}, size[3] = {2, 2, 1}, lo2[3] = {4, 2, 0}, size2[3] = {4, 4, 1};
  EXPECT_TRUE(r.anyIn(lo, size));
  EXPECT_FALSE(r.anyIn(lo2, size2));  // (7, 3, 1) has z = 1
}

// The output of a tree built by hand: the text's indentation and the JSON's fields.
TEST(RayTreeSetting, TextAndJsonOfAHandBuiltTree) {
  RayTreeRecorder r(Ids{{1, 2, 0}});
  RayTreeInvocation& inv = r.invocations()[0];
  inv.ran = true;
  inv.root.stage = "raygen";
  inv.root.name = "raygen shader \"main\"";
  inv.root.group = 0;
  inv.root.record = 0x1000;
  RayTreeNode* t = inv.add(RayTreeNode::Kind::Trace);
  t->tMin = 0.5f;
  t->tMax = 100;
  t->direction[2] = 1;
  t->payloadBefore = {1, 2, 3, 4, 5};
  t->payloadAfter = {0xff};
  t->hasCommitted = true;
  t->committed.t = 0.1f;
  t->committed.primitiveIndex = 3;
  RayTreeInvocation::Enter enter(&inv, t);
  RayTreeNode* c = inv.add(RayTreeNode::Kind::Candidate);
  c->hasCandidate = true;
  c->candidate.triangle = false;
  c->candidate.t = std::numeric_limits<float>::quiet_NaN();
  c->verdict = RayTreeNode::Verdict::Ignored;
  RayTreeContext ctx;
  ctx.command = "vkCmdTraceRaysKHR";
  ctx.pipeline = 0xabc;
  ctx.size[0] = 4;
  ctx.size[1] = 4;
  const std::string text = rayTreeText(inv, ctx);
  EXPECT_EQ(text,
            "ray tree of launch id 1,2,0 in vkCmdTraceRaysKHR #0 (pipeline 0xabc, size 4x4x1)\n"
            "  raygen shader \"main\": group 0, record 0 at 0x1000\n"
            "    traceRay as 0x0 origin (0, 0, 0) direction (0, 0, 1) tMin 0.5 tMax 100 flags 0x0 cullMask 0x0 "
            "sbtOffset 0 sbtStride 0 missIndex 0\n"
            "      payload before: 01020304 05\n"
            "      candidate aabb instance 0 (custom 0) geometry 0 primitive 0 hitKind 0x0: ignored\n"
            "      committed triangle t=0.1 instance 0 (custom 0) geometry 0 primitive 3 hitKind 0x0\n"
            "      payload after: ff\n");
  const std::string json = rayTreeJson(inv, ctx);
  EXPECT_EQ(json.find('\n'), std::string::npos) << "one line";
  EXPECT_NE(json.find("\"launchId\":[1,2,0]"), std::string::npos) << json;
  EXPECT_NE(json.find("\"pipeline\":\"0xabc\""), std::string::npos) << json;
  EXPECT_NE(json.find("\"candidate\":{\"type\":\"aabb\",\"t\":null,"), std::string::npos) << json;
  EXPECT_NE(json.find("\"committed\":{\"type\":\"triangle\",\"t\":0.1,"), std::string::npos) << json;
  EXPECT_NE(json.find("\"payloadBefore\":\"01020304 05\""), std::string::npos) << json;
}

TEST(RayTreeSetting, NodesBeyondTheBoundAreDroppedAndNoted) {
  RayTreeRecorder r(Ids{{0, 0, 0}});
  RayTreeInvocation& inv = r.invocations()[0];
  for (size_t i = 0; i < RayTreeInvocation::kMaxNodes; ++i) ASSERT_NE(inv.add(RayTreeNode::Kind::Note), nullptr);
  EXPECT_EQ(inv.add(RayTreeNode::Kind::Note), nullptr);
  EXPECT_TRUE(inv.truncated);
  RayTreeContext ctx;
  EXPECT_NE(rayTreeText(inv, ctx).find("(truncated: more than 65536 nodes"), std::string::npos);
}

}  // namespace
}  // namespace vkrt::exec
