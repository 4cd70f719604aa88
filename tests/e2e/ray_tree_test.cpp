// VKRT_RAY_TREE (docs/ray-tree.md) through the loader: the ray tree of a named launch id, as INFO messages and as
// JSON lines in VKRT_RAY_TREE_OUT, checked node by node against a scene whose hits follow from its geometry; ray
// queries in a raygen shader; and the valid side: ids not named, and the setting unset, produce nothing.
//
// The scene (world space; launch 4 x 4 of trace_raygen.rgen: launch id (1, 1) shoots from (-0.5, -0.5, -10) along
// +z):
//  - instance 0: a non-opaque quad moved by (-1, -1, 2), custom index 10: the ray meets its triangle 1 at t = 12;
//    the any-hit shader (trace_ahit.rahit, mode 3) ignores odd primitives;
//  - instance 1: the same quad moved by (0, 0, 5), custom index 20: triangle 0 at t = 15, accepted, committed;
//  - instance 2: a box [2.5, 3.5] x [-1, 0] x [4, 5] holding trace_sphere.rint's sphere (3, -0.5, 4.5) radius 0.5,
//    custom index 30, SBT offset 1.
// The closest-hit shader (ray_tree_chit.rchit) traces from (-0.5, -0.5, 4.5) along +x (the sphere: entry at t = 3)
// and along -x (nothing: the miss shader).
#include <cinttypes>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "e2e/trace_fixture.hpp"
#include "ray_query_raygen.rgen.spv.h"
#include "ray_tree_chit.rchit.spv.h"

namespace vkrt::test {
namespace {

// ------------------------------------------------------------------------------------------------ a JSON reader

struct Json {
  enum Type { Null, Bool, Number, String, Array, Object } type = Null;
  bool b = false;
  double n = 0;
  std::string s;
  std::vector<Json> items;
  std::vector<std::pair<std::string, Json>> fields;

  const Json& operator[](const std::string& key) const {
    static const Json kNone;
    for (const auto& [k, v] : fields)
      if (k == key) return v;
    ADD_FAILURE() << "no field \"" << key << "\"";
    return kNone;
  }
  const Json& operator[](size_t i) const {
    static const Json kNone;
    if (i < items.size()) return items[i];
    ADD_FAILURE() << "no item " << i;
    return kNone;
  }
  bool has(const std::string& key) const {
    for (const auto& f : fields)
      if (f.first == key) return true;
    return false;
  }
};

class JsonReader {
 public:
  explicit JsonReader(const std::string& t) : t_(t) {}
  bool read(Json* out) {
    bool ok = value(out);
    space();
    return ok && i_ == t_.size();
  }

 private:
  void space() {
    while (i_ < t_.size() && std::isspace(static_cast<unsigned char>(t_[i_]))) ++i_;
  }
  bool literal(const char* w) {
    size_t n = std::strlen(w);
    if (t_.compare(i_, n, w) != 0) return false;
    i_ += n;
    return true;
  }
  bool string(std::string* out) {
    if (t_[i_] != '"') return false;
    for (++i_; i_ < t_.size() && t_[i_] != '"'; ++i_) {
      if (t_[i_] == '\\') {
        if (++i_ >= t_.size()) return false;
        if (t_[i_] == 'u') {
          if (i_ + 4 >= t_.size()) return false;
          *out += char(std::stoi(t_.substr(i_ + 1, 4), nullptr, 16));
          i_ += 4;
          continue;
        }
      }
      *out += t_[i_];
    }
    if (i_ >= t_.size()) return false;
    ++i_;
    return true;
  }
  bool value(Json* v) {
    space();
    if (i_ >= t_.size()) return false;
    const char c = t_[i_];
    if (c == '{') {
      v->type = Json::Object;
      ++i_;
      space();
      if (t_[i_] == '}') return ++i_, true;
      for (;;) {
        space();
        std::string key;
        if (!string(&key)) return false;
        space();
        if (t_[i_++] != ':') return false;
        Json item;
        if (!value(&item)) return false;
        v->fields.emplace_back(key, std::move(item));
        space();
        if (t_[i_] == ',') {
          ++i_;
          continue;
        }
        return t_[i_++] == '}';
      }
    }
    if (c == '[') {
      v->type = Json::Array;
      ++i_;
      space();
      if (t_[i_] == ']') return ++i_, true;
      for (;;) {
        Json item;
        if (!value(&item)) return false;
        v->items.push_back(std::move(item));
        space();
        if (t_[i_] == ',') {
          ++i_;
          continue;
        }
        return t_[i_++] == ']';
      }
    }
    if (c == '"') {
      v->type = Json::String;
      return string(&v->s);
    }
    if (literal("null")) return true;
    if (literal("true") || literal("false")) {
      v->type = Json::Bool;
      v->b = t_[i_ - 1] == 'e' && t_[i_ - 2] == 'u';
      return true;
    }
    size_t used = 0;
    try {
      v->n = std::stod(t_.substr(i_), &used);
    } catch (...) {
      return false;
    }
    v->type = Json::Number;
    i_ += used;
    return used > 0;
  }
  const std::string& t_;
  size_t i_ = 0;
};

Json parse(const std::string& text) {
  Json j;
  EXPECT_TRUE(JsonReader(text).read(&j)) << "not JSON: " << text;
  return j;
}

// ------------------------------------------------------------------------------------------------ expectations

// The payload's bytes as the tree prints them: hex, four bytes to a group.
std::string hexBytes(const void* p, size_t n) {
  std::string s;
  char h[4];
  for (size_t i = 0; i < n; ++i) {
    std::snprintf(h, sizeof h, "%02x", static_cast<const uint8_t*>(p)[i]);
    if (i && i % 4 == 0) s += ' ';
    s += h;
  }
  return s;
}
TracePayload payload(std::array<float, 4> hit, std::array<uint32_t, 4> ids, std::array<uint32_t, 4> extra) {
  TracePayload p;
  std::memcpy(p.hit, hit.data(), 16);
  std::memcpy(p.ids, ids.data(), 16);
  std::memcpy(p.extra, extra.data(), 16);
  return p;
}
std::string hexAddress(uint64_t a) {
  char b[24];
  std::snprintf(b, sizeof b, "0x%" PRIx64, a);
  return b;
}

struct HitWant {
  bool triangle;
  float t;  // NaN: none (a box candidate)
  uint32_t instance, custom, primitive, hitKind;
};

void expectHit(const Json& j, const HitWant& w) {
  EXPECT_EQ(j["type"].s, w.triangle ? "triangle" : "aabb");
  if (std::isnan(w.t)) {
    EXPECT_EQ(j["t"].type, Json::Null);
  } else {
    EXPECT_NEAR(j["t"].n, w.t, 1e-4 * w.t);
  }
  EXPECT_EQ(j["instanceIndex"].n, w.instance);
  EXPECT_EQ(j["instanceCustomIndex"].n, w.custom);
  EXPECT_EQ(j["geometryIndex"].n, 0);
  EXPECT_EQ(j["primitiveIndex"].n, w.primitive);
  EXPECT_EQ(j["hitKind"].n, w.hitKind);
}

void expectShader(const Json& j, const char* stage, int group, uint64_t recordIndex, uint64_t record, size_t children) {
  EXPECT_EQ(j["kind"].s, "shader");
  EXPECT_EQ(j["stage"].s, stage);
  EXPECT_EQ(j["name"].s, std::string(stage) + " shader \"main\"");
  EXPECT_EQ(j["group"].n, group);
  EXPECT_EQ(j["recordIndex"].n, double(recordIndex));
  EXPECT_EQ(j["record"].s, hexAddress(record));
  EXPECT_EQ(j["children"].items.size(), children);
}

void expectRay(const Json& j, std::array<float, 3> origin, std::array<float, 3> direction, uint64_t as) {
  EXPECT_EQ(j["accelerationStructure"].s, hexAddress(as));
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(j["origin"][k].n, origin[k]);
    EXPECT_EQ(j["direction"][k].n, direction[k]);
  }
  EXPECT_EQ(j["tMin"].n, 0);
  EXPECT_EQ(j["tMax"].n, 100);
  EXPECT_EQ(j["rayFlags"].n, 0);
  EXPECT_EQ(j["cullMask"].n, 255);
}

// ------------------------------------------------------------------------------------------------ the fixture

class RayTreeTest : public TraceTest {
 protected:
  // Without the validation layer: it wraps handles, and the tree names the pipeline by vkrt's handle.
  bool layer() override { return false; }

  // VKRT_RAY_TREE and VKRT_RAY_TREE_OUT while the device is created (null: unset).
  virtual const char* setting() { return "1,1;3,3,5"; }
  virtual std::string outPath() { return {}; }

  void SetUp() override {
    if (const char* s = setting()) {
      setenv("VKRT_RAY_TREE", s, 1);
    } else {
      unsetenv("VKRT_RAY_TREE");
    }
    out = outPath();
    if (!out.empty()) {
      std::remove(out.c_str());
      setenv("VKRT_RAY_TREE_OUT", out.c_str(), 1);
    } else {
      unsetenv("VKRT_RAY_TREE_OUT");
    }
    TraceTest::SetUp();
    if (HasFatalFailure() || !device) return;
    if (!onVkrt()) GTEST_SKIP() << "VKRT_RAY_TREE is vkrt's";
    // INFO messages (the fixture's messenger takes warnings and errors only).
    auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(VulkanTest::instance, "vkCreateDebugUtilsMessengerEXT"));
    VkDebugUtilsMessengerCreateInfoEXT mci{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    mci.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_INFO_BIT_EXT;
    mci.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT;
    mci.pfnUserCallback = [](VkDebugUtilsMessageSeverityFlagBitsEXT, VkDebugUtilsMessageTypeFlagsEXT,
                             const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) -> VkBool32 {
      if (data->pMessageIdName && std::strcmp(data->pMessageIdName, "vkrt-ray-tree") == 0)
        static_cast<RayTreeTest*>(user)->trees.push_back(data->pMessage);
      return VK_FALSE;
    };
    mci.pUserData = this;
    ASSERT_EQ(create(VulkanTest::instance, &mci, nullptr, &infoMessenger), VK_SUCCESS);
  }
  void TearDown() override {
    if (infoMessenger) {
      auto destroyMessenger = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
          vkGetInstanceProcAddr(VulkanTest::instance, "vkDestroyDebugUtilsMessengerEXT"));
      destroyMessenger(VulkanTest::instance, infoMessenger, nullptr);
    }
    TraceTest::TearDown();
    unsetenv("VKRT_RAY_TREE");
    unsetenv("VKRT_RAY_TREE_OUT");
    if (!out.empty()) std::remove(out.c_str());
  }

  // The scene above and its pipeline: groups 0 raygen, 1 miss, 2 triangles (ray_tree_chit, trace_ahit), 3
  // procedural (trace_chit, trace_sphere); hit records 0 (tag 100, mode 3: ignore odd primitives) and 1 (tag 101).
  void makeScene(uint32_t depth = 2) {
    setSpheres({{3, -0.5f, 4.5f, 0.5f}});
    VkAccelerationStructureKHR quad = blas({triangles(kQuad, kQuadIndices, 0)});
    VkAccelerationStructureKHR box = blas({aabbs({{2.5f, -1, 4, 3.5f, 0, 5}}, VK_GEOMETRY_OPAQUE_BIT_KHR)});
    top = tlas({instance(quad, -1, -1, 2, 10, 0), instance(quad, 0, 0, 5, 20, 0), instance(box, 0, 0, 0, 30, 1)});
    Desc d;
    d.layout = traceLayout;
    d.depth = depth;
    d.general(rgen, VK_SHADER_STAGE_RAYGEN_BIT_KHR);
    d.general(tmiss, VK_SHADER_STAGE_MISS_BIT_KHR);
    VkShaderModule chit = module(kSpv_ray_tree_chit_rchit, sizeof kSpv_ray_tree_chit_rchit);
    d.group(VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR, VK_SHADER_UNUSED_KHR,
            d.stage(chit, VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR), d.stage(tahit, VK_SHADER_STAGE_ANY_HIT_BIT_KHR));
    d.group(VK_RAY_TRACING_SHADER_GROUP_TYPE_PROCEDURAL_HIT_GROUP_KHR, VK_SHADER_UNUSED_KHR,
            d.stage(tchit, VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR), VK_SHADER_UNUSED_KHR,
            d.stage(tsphere, VK_SHADER_STAGE_INTERSECTION_BIT_KHR));
    d.maxHitAttr = 8;
    d.maxPayload = sizeof(TracePayload);
    pipeline = make(d);
    table = sbt(pipeline, 4, {0}, {{1, {7}}}, {{2, {100, 3}}, {3, {101}}});
  }
  std::vector<TracePayload> run() { return trace(pipeline, table, top, 4, 4); }
  // The vkrt reports of vkCreateDevice with VKRT_RAY_TREE=`setting`, on a device of its own (the fixture's exists).
  std::vector<Message> deviceWarnings(const char* setting);

  // The JSON tree of launch id (1, 1) (`result`: what the launch wrote for it) against the scene's geometry.
  void expectTree(const Json& tree, const TracePayload& result) {
    const uint64_t as = addressOf(top), hit0 = table.hit.deviceAddress, hit1 = hit0 + table.hit.stride;
    expectShader(tree, "raygen", 0, 0, table.raygen.deviceAddress, 1);
    const Json& primary = tree["children"][0];
    EXPECT_EQ(primary["kind"].s, "trace");
    expectRay(primary, {-0.5f, -0.5f, -10}, {0, 0, 1}, as);
    EXPECT_EQ(primary["sbtOffset"].n, 0);
    EXPECT_EQ(primary["sbtStride"].n, 1);
    EXPECT_EQ(primary["missIndex"].n, 0);
    const TracePayload before = payload({-1, -1, -1, -1}, {~0u, ~0u, ~0u, ~0u}, {0, 0, 0, 0});
    EXPECT_EQ(primary["payloadBefore"].s, hexBytes(&before, sizeof before));
    EXPECT_EQ(primary["payloadAfter"].s, hexBytes(&result, sizeof result));
    // What the launch wrote: quad 1's triangle 0 at (-0.5, -0.5) in its plane (barycentrics 0.25, 0.25), tag 100,
    // two any-hit invocations.
    EXPECT_NEAR(result.hit[0], 15, 1e-4);
    EXPECT_NEAR(result.hit[1], 0.25f, 1e-5);
    EXPECT_NEAR(result.hit[2], 0.25f, 1e-5);
    EXPECT_EQ(result.hit[3], 255.0f);
    EXPECT_EQ(result.ids[0], 20u);
    EXPECT_EQ(result.ids[1], 1u);
    EXPECT_EQ(result.extra[0], 100u);
    EXPECT_EQ(result.extra[1], 2u);
    expectHit(primary["committed"], {true, 15, 1, 20, 0, 255});
    // Children: the two triangle candidates (in the traversal's order, which Embree chooses), the closest-hit.
    ASSERT_EQ(primary["children"].items.size(), 3u);
    const bool nearFirst = primary["children"][0]["candidate"]["t"].n < 13;
    const Json& nearCandidate = primary["children"][nearFirst ? 0 : 1];
    const Json& farCandidate = primary["children"][nearFirst ? 1 : 0];
    for (const Json* c : {&nearCandidate, &farCandidate}) {
      EXPECT_EQ((*c)["kind"].s, "candidate");
      ASSERT_EQ((*c)["children"].items.size(), 1u);
      expectShader((*c)["children"][0], "any-hit", 2, 0, hit0, 0);
    }
    expectHit(nearCandidate["candidate"], {true, 12, 0, 10, 1, 255});
    EXPECT_EQ(nearCandidate["verdict"].s, "ignored");
    expectHit(farCandidate["candidate"], {true, 15, 1, 20, 0, 255});
    EXPECT_EQ(farCandidate["verdict"].s, "accepted");
    const Json& chit = primary["children"][2];
    expectShader(chit, "closest-hit", 2, 0, hit0, 2);

    // Along +x: the box's candidate, the intersection shader's report at the sphere's entry (t = 3), trace_chit.
    const Json& toBox = chit["children"][0];
    EXPECT_EQ(toBox["kind"].s, "trace");
    expectRay(toBox, {-0.5f, -0.5f, 4.5f}, {1, 0, 0}, as);
    TracePayload p = payload({0, 0, 0, 0}, {7, 7, 7, 7}, {0, 0, 0, 0});
    EXPECT_EQ(toBox["payloadBefore"].s, hexBytes(&p, sizeof p));
    p = payload({3, 0, 0.5f, 5}, {30, 2, 0, 0}, {101, 0, 0, 0});
    EXPECT_EQ(toBox["payloadAfter"].s, hexBytes(&p, sizeof p));
    expectHit(toBox["committed"], {false, 3, 2, 30, 0, 5});
    ASSERT_EQ(toBox["children"].items.size(), 2u);
    const Json& box = toBox["children"][0];
    EXPECT_EQ(box["kind"].s, "candidate");
    expectHit(box["candidate"], {false, std::nanf(""), 2, 30, 0, 0});
    EXPECT_EQ(box["verdict"].s, "accepted");
    ASSERT_EQ(box["children"].items.size(), 1u);
    const Json& isect = box["children"][0];
    expectShader(isect, "intersection", 3, 1, hit1, 1);
    const Json& report = isect["children"][0];
    EXPECT_EQ(report["kind"].s, "report");
    expectHit(report["candidate"], {false, 3, 2, 30, 0, 5});
    EXPECT_EQ(report["candidate"]["t"].n, 3.0) << "the sphere's entry, exactly";
    EXPECT_EQ(report["verdict"].s, "accepted");
    expectShader(toBox["children"][1], "closest-hit", 3, 1, hit1, 0);

    // Along -x: nothing; the miss shader.
    const Json& away = chit["children"][1];
    expectRay(away, {-0.5f, -0.5f, 4.5f}, {-1, 0, 0}, as);
    p = payload({0, 0, 0, 0}, {7, 7, 7, 7}, {1, 1, 1, 1});
    EXPECT_EQ(away["payloadBefore"].s, hexBytes(&p, sizeof p));
    p = payload({-2, 7, 100, 0}, {7, 7, 7, 7}, {7, 1, 1, 1});
    EXPECT_EQ(away["payloadAfter"].s, hexBytes(&p, sizeof p));
    EXPECT_EQ(away["committed"].type, Json::Null);
    ASSERT_EQ(away["children"].items.size(), 1u);
    expectShader(away["children"][0], "miss", 1, 0, table.miss.deviceAddress, 0);
  }

  std::string out;
  VkDebugUtilsMessengerEXT infoMessenger = VK_NULL_HANDLE;
  std::vector<std::string> trees;
  VkAccelerationStructureKHR top = VK_NULL_HANDLE;
  VkPipeline pipeline = VK_NULL_HANDLE;
  Sbt table;
};

// Without VKRT_RAY_TREE_OUT: one INFO message for the named launch id that ran ((3, 3, 5) lies outside the launch),
// its text the tree, line by line.
TEST_F(RayTreeTest, NamedLaunchIdIsDeliveredAsText) {
  makeScene();
  std::vector<TracePayload> r = run();
  ASSERT_EQ(trees.size(), 1u);
  const std::string& text = trees[0];
  // The same tree from the file, for the t values Embree computed (checked against the geometry in expectTree).
  const uint64_t as = addressOf(top), hit0 = table.hit.deviceAddress, hit1 = hit0 + table.hit.stride;
  const TracePayload before = payload({-1, -1, -1, -1}, {~0u, ~0u, ~0u, ~0u}, {0, 0, 0, 0});
  const TracePayload box0 = payload({0, 0, 0, 0}, {7, 7, 7, 7}, {0, 0, 0, 0});
  const TracePayload box1 = payload({3, 0, 0.5f, 5}, {30, 2, 0, 0}, {101, 0, 0, 0});
  const TracePayload away0 = payload({0, 0, 0, 0}, {7, 7, 7, 7}, {1, 1, 1, 1});
  const TracePayload away1 = payload({-2, 7, 100, 0}, {7, 7, 7, 7}, {7, 1, 1, 1});
  const std::string head = "vkrt: VkCommandBuffer ";
  ASSERT_EQ(text.rfind(head, 0), 0u) << text;
  const size_t start = text.find(": ray tree of launch id 1,1,0 in vkCmdTraceRaysKHR #0 (pipeline " +
                                 hexAddress(uint64_t(pipeline)) + ", size 4x4x1)\n");
  ASSERT_NE(start, std::string::npos) << text;
  // The candidates' t as printed: t = 12 and 15 up to Embree's rounding.
  // The t printed before `suffix` on its line.
  auto tBefore = [&](const std::string& suffix) {
    const size_t at = text.find(suffix);
    EXPECT_NE(at, std::string::npos) << suffix << "\n" << text;
    if (at == std::string::npos) return std::string("nan");
    const size_t t = text.rfind("t=", at) + 2;
    return text.substr(t, at - t);
  };
  const std::string t12 = tBefore(" instance 0 (custom 10) geometry 0 primitive 1 hitKind 0xff: ignored"),
                    t15 = tBefore(" instance 1 (custom 20) geometry 0 primitive 0 hitKind 0xff: accepted");
  EXPECT_NEAR(std::stod(t12), 12, 12e-4) << text;
  EXPECT_NEAR(std::stod(t15), 15, 15e-4) << text;
  const std::string nearLine = "      candidate triangle t=" + t12 +
                               " instance 0 (custom 10) geometry 0 primitive 1 hitKind 0xff: ignored\n"
                               "        any-hit shader \"main\": group 2, record 0 at " +
                               hexAddress(hit0) + "\n";
  const std::string farLine = "      candidate triangle t=" + t15 +
                              " instance 1 (custom 20) geometry 0 primitive 0 hitKind 0xff: accepted\n"
                              "        any-hit shader \"main\": group 2, record 0 at " +
                              hexAddress(hit0) + "\n";
  const bool nearFirst =
      text.find("primitive 1 hitKind 0xff: ignored") < text.find("primitive 0 hitKind 0xff: accepted");
  const std::string want =
      "  raygen shader \"main\": group 0, record 0 at " + hexAddress(table.raygen.deviceAddress) + "\n" +
      "    traceRay as " + hexAddress(as) +
      " origin (-0.5, -0.5, -10) direction (0, 0, 1) tMin 0 tMax 100 flags 0x0 cullMask 0xff sbtOffset 0 sbtStride 1 "
      "missIndex 0\n" +
      "      payload before: " + hexBytes(&before, sizeof before) + "\n" +
      (nearFirst ? nearLine + farLine : farLine + nearLine) +
      "      closest-hit shader \"main\": group 2, record 0 at " + hexAddress(hit0) + "\n" + "        traceRay as " +
      hexAddress(as) +
      " origin (-0.5, -0.5, 4.5) direction (1, 0, 0) tMin 0 tMax 100 flags 0x0 cullMask 0xff sbtOffset 0 sbtStride 1 "
      "missIndex 0\n" +
      "          payload before: " + hexBytes(&box0, sizeof box0) + "\n" +
      "          candidate aabb instance 2 (custom 30) geometry 0 primitive 0 hitKind 0x0: accepted\n" +
      "            intersection shader \"main\": group 3, record 1 at " + hexAddress(hit1) + "\n" +
      "              reportIntersection t=3 hitKind 0x5: accepted\n" +
      "          closest-hit shader \"main\": group 3, record 1 at " + hexAddress(hit1) + "\n" +
      "          committed aabb t=3 instance 2 (custom 30) geometry 0 primitive 0 hitKind 0x5\n" +
      "          payload after: " + hexBytes(&box1, sizeof box1) + "\n" + "        traceRay as " + hexAddress(as) +
      " origin (-0.5, -0.5, 4.5) direction (-1, 0, 0) tMin 0 tMax 100 flags 0x0 cullMask 0xff sbtOffset 0 sbtStride "
      "1 missIndex 0\n" +
      "          payload before: " + hexBytes(&away0, sizeof away0) + "\n" +
      "          miss shader \"main\": group 1, record 0 at " + hexAddress(table.miss.deviceAddress) + "\n" +
      "          miss\n" + "          payload after: " + hexBytes(&away1, sizeof away1) + "\n" +
      "      committed triangle t=" + t15 + " instance 1 (custom 20) geometry 0 primitive 0 hitKind 0xff\n" +
      "      payload after: " + hexBytes(&r[5], sizeof r[5]) + "\n";
  EXPECT_EQ(text.substr(text.find('\n', start) + 1), want);
  // A second launch: a second tree, numbered 1.
  run();
  ASSERT_EQ(trees.size(), 2u);
  EXPECT_NE(trees[1].find("in vkCmdTraceRaysKHR #1 "), std::string::npos);
}

// A pipeline of recursion depth 1: the closest-hit shader's traces are not run (reported once, as without the
// setting); the tree notes each where it would be.
TEST_F(RayTreeTest, TracesPastTheRecursionDepthAreNoted) {
  makeScene(1);
  run();
  expectVkrtMessage("VUID-vkCmdTraceRaysKHR-maxPipelineRayRecursionDepth-03679");
  ASSERT_EQ(trees.size(), 1u);
  const std::string note =
      "        note: traceRay at depth 2 beyond maxPipelineRayRecursionDepth 1: not run (reported)\n";
  const std::string& text = trees[0];
  const size_t first = text.find("      closest-hit shader \"main\": group 2, record 0 at ");
  ASSERT_NE(first, std::string::npos) << text;
  const size_t line = text.find('\n', first) + 1;
  EXPECT_EQ(text.substr(line, 2 * note.size()), note + note) << text;
  EXPECT_EQ(text.find("traceRay as", line), std::string::npos) << "no nested trace ran";
}

// With VKRT_RAY_TREE_OUT=*.json: one JSON object per line per named launch id and launch, no message.
class RayTreeJsonTest : public RayTreeTest {
 protected:
  std::string outPath() override {
    return ::testing::TempDir() + "vkrt_ray_tree_" + std::to_string(getpid()) + ".json";
  }
};

TEST_F(RayTreeJsonTest, NamedLaunchIdIsWrittenAsJsonLines) {
  makeScene();
  std::vector<TracePayload> a = run();
  std::vector<TracePayload> b = run();
  EXPECT_TRUE(trees.empty()) << "with a file, no message";
  std::ifstream f(out);
  std::vector<std::string> lines;
  for (std::string line; std::getline(f, line);) lines.push_back(line);
  ASSERT_EQ(lines.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    SCOPED_TRACE("launch " + std::to_string(i));
    Json j = parse(lines[i]);
    EXPECT_EQ(j["command"].s, "vkCmdTraceRaysKHR");
    EXPECT_EQ(j["sequence"].n, double(i));
    EXPECT_EQ(j["pipeline"].s, hexAddress(uint64_t(pipeline)));
    EXPECT_EQ(j["launchSize"].items.size(), 3u);
    for (int k = 0; k < 3; ++k) EXPECT_EQ(j["launchSize"][k].n, k < 2 ? 4 : 1);
    for (int k = 0; k < 3; ++k) EXPECT_EQ(j["launchId"][k].n, k < 2 ? 1 : 0);
    EXPECT_FALSE(j["truncated"].b);
    expectTree(j["tree"], (i ? b : a)[5]);
  }
}

// Launch ids not named produce nothing (the launch runs as without the setting).
class RayTreeUnnamedTest : public RayTreeTest {
 protected:
  const char* setting() override { return "4,0;0,4"; }
};
TEST_F(RayTreeUnnamedTest, LaunchIdsOutsideTheLaunchProduceNothing) {
  makeScene();
  std::vector<TracePayload> r = run();
  EXPECT_TRUE(trees.empty());
  EXPECT_EQ(r[5].extra[1], 2u);
  EXPECT_EQ(r[5].ids[0], 20u);
}

// The setting unset: nothing, and the same results.
class RayTreeOffTest : public RayTreeTest {
 protected:
  const char* setting() override { return nullptr; }
};
TEST_F(RayTreeOffTest, UnsetProducesNothing) {
  makeScene();
  std::vector<TracePayload> r = run();
  EXPECT_TRUE(trees.empty());
  EXPECT_NEAR(r[5].hit[0], 15, 1e-4);
  EXPECT_EQ(r[5].extra[1], 2u);
}

// The warnings of vkCreateDevice for `setting`, from a device of its own (the fixture's exists already).
std::vector<Message> RayTreeTest::deviceWarnings(const char* setting) {
  setenv("VKRT_RAY_TREE", setting, 1);
  const float priority = 1;
  VkDeviceQueueCreateInfo q{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  q.queueCount = 1;
  q.pQueuePriorities = &priority;
  VkDeviceCreateInfo ci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  ci.queueCreateInfoCount = 1;
  ci.pQueueCreateInfos = &q;
  VkDevice d = VK_NULL_HANDLE;
  EXPECT_EQ(vkCreateDevice(physicalDevice, &ci, nullptr, &d), VK_SUCCESS);
  if (d) vkDestroyDevice(d, nullptr);
  unsetenv("VKRT_RAY_TREE");
  return vkrtMessages();
}

// A malformed setting: a warning at vkCreateDevice naming what is wrong; no tree is recorded.
class RayTreeMalformedTest : public RayTreeTest {
 protected:
  const char* setting() override { return nullptr; }
};
TEST_F(RayTreeMalformedTest, IsReportedAndIgnored) {
  const struct {
    const char* setting;
    const char* says;
  } kCases[] = {
      {"1;x",
       "VKRT_RAY_TREE=\"1;x\" is malformed: \"1\" has 1 number(s), at least 2 are needed; no ray tree is "
       "recorded"},
      {"1,2;;", "VKRT_RAY_TREE=\"1,2;;\" is malformed: an empty entry"},
      {"1,99999999999", "VKRT_RAY_TREE=\"1,99999999999\" is malformed: a number above 4294967295"},
  };
  for (const auto& c : kCases) {
    SCOPED_TRACE(c.setting);
    std::vector<Message> m = deviceWarnings(c.setting);
    ASSERT_EQ(m.size(), 1u);
    EXPECT_EQ(m[0].severity, VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT);
    EXPECT_NE(m[0].text.find(c.says), std::string::npos) << m[0].text;
    clearMessages();
  }
  // Valid settings: no warning.
  for (const char* valid : {"1,1", " 0 , 0 , 0 ; 3,3;", "4294967295,0", "compute:1,2;1,1", "compute:7"}) {
    SCOPED_TRACE(valid);
    EXPECT_TRUE(deviceWarnings(valid).empty());
  }
}

// Ray queries in a raygen shader (ray_query_raygen.rgen confirms every triangle candidate): a non-opaque quad at
// z = 2 in front of an opaque one at z = 5. The first proceed returns the non-opaque triangle (t = 12) with the
// opaque one (t = 15) already committed by the traversal; the confirm commits t = 12; the second proceed ends.
class RayTreeQueryTest : public RayTreeTest {
 protected:
  VkPhysicalDeviceRayQueryFeaturesKHR rqf{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR};
  const char* setting() override { return "1,1"; }
  FixtureOptions options() override {
    FixtureOptions o = RayTreeTest::options();
    o.deviceExtensions.push_back(VK_KHR_RAY_QUERY_EXTENSION_NAME);
    rqf.rayQuery = VK_TRUE;
    rqf.pNext = asf.pNext;
    asf.pNext = &rqf;
    return o;
  }
};
TEST_F(RayTreeQueryTest, QueryCallsAreRecorded) {
  VkAccelerationStructureKHR quadNo = blas({triangles(kQuad, kQuadIndices, 0)});
  VkAccelerationStructureKHR quadOpaque = blas({triangles(kQuad, kQuadIndices, VK_GEOMETRY_OPAQUE_BIT_KHR)});
  top = tlas({instance(quadNo, -1, -1, 2, 10, 0), instance(quadOpaque, 0, 0, 5, 20, 0)});
  Desc d;
  d.layout = traceLayout;
  d.general(module(kSpv_ray_query_raygen_rgen, sizeof kSpv_ray_query_raygen_rgen), VK_SHADER_STAGE_RAYGEN_BIT_KHR);
  d.general(tmiss, VK_SHADER_STAGE_MISS_BIT_KHR);
  pipeline = make(d);
  table = sbt(pipeline, 2, {0}, {{1, {7}}}, {});
  std::vector<TracePayload> r = run();
  EXPECT_NEAR(r[5].hit[0], 12, 1e-4) << "the confirmed candidate";
  ASSERT_EQ(trees.size(), 1u);
  const std::string& text = trees[0];
  const size_t at = text.find("  raygen shader \"main\": group 0, record 0 at ");
  ASSERT_NE(at, std::string::npos) << text;
  auto tOf = [&](const std::string& prefix) {
    size_t p = text.find(prefix);
    EXPECT_NE(p, std::string::npos) << prefix << "\n" << text;
    if (p == std::string::npos) return std::string();
    p += prefix.size();
    return text.substr(p, text.find(' ', p) - p);
  };
  const std::string t12 = tOf("proceed: candidate triangle t="), t15 = tOf("; committed triangle t=");
  EXPECT_NEAR(std::stod(t12), 12, 12e-4);
  EXPECT_NEAR(std::stod(t15), 15, 15e-4);
  const std::string nearHit = "triangle t=" + t12 + " instance 0 (custom 10) geometry 0 primitive 1 hitKind 0xff";
  const std::string farHit = "triangle t=" + t15 + " instance 1 (custom 20) geometry 0 primitive 0 hitKind 0xff";
  const std::string want = "  raygen shader \"main\": group 0, record 0 at " + hexAddress(table.raygen.deviceAddress) +
                           "\n    rayQueryInitialize as " + hexAddress(addressOf(top)) +
                           " origin (-0.5, -0.5, -10) direction (0, 0, 1) tMin 0 tMax 100 flags 0x0 cullMask 0xff\n" +
                           "      proceed: candidate " + nearHit + "; committed " + farHit + "\n" +
                           "      confirm: committed " + nearHit + "\n" + "      proceed: false; committed " + nearHit +
                           "\n";
  EXPECT_EQ(text.substr(at), want);
}

}  // namespace
}  // namespace vkrt::test
