// Skins and morph targets: vertices where glTF puts them (checked by hand), the scene's bounds
// and instance placement, and renders in which the deforming mesh is dynamic geometry: reuse
// equals retrace bit for bit while it bends, light paths are re-traced only while it moves.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include <glm/gtc/quaternion.hpp>
#include <nlohmann/json.hpp>

#include "scene/gltf_loader.h"
#include "support/render_helpers.h"
#include "support/test_env.h"

namespace pr {
namespace {

using nlohmann::json;

// Accessors over one binary buffer written beside the .gltf.
struct Buffers {
  std::string bin;
  json views = json::array(), accessors = json::array();
  int add(const void* p, size_t bytes, int componentType, size_t count, const char* type) {
    views.push_back({{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", bytes}});
    bin.append(static_cast<const char*>(p), bytes);
    while (bin.size() % 4) bin.push_back(0);
    accessors.push_back({{"bufferView", views.size() - 1},
                         {"componentType", componentType},
                         {"count", count},
                         {"type", type}});
    return int(accessors.size() - 1);
  }
  int floats(const std::vector<float>& v, size_t count, const char* type) {
    return add(v.data(), v.size() * 4, 5126, count, type);
  }
  std::string write(json doc, const std::string& tag) {
    const std::string dir = test::tempDir(tag);
    std::ofstream(dir + "/m.bin", std::ios::binary) << bin;
    doc["asset"] = {{"version", "2.0"}};
    doc["accessors"] = accessors;
    doc["bufferViews"] = views;
    doc["buffers"] = {{{"byteLength", bin.size()}, {"uri", "m.bin"}}};
    std::ofstream(dir + "/m.gltf") << doc.dump();
    return dir + "/m.gltf";
  }
};

// A strip of 6 vertices (rows y = 0, 1, 2) skinned to two joints: row 0 to the root joint, row
// 2 to the child joint at y = 1, row 1 half and half. The child turns 90 degrees about +Z from
// t = 0 to t = 1. The mesh's node is moved by (5, 0, 0), which skinning ignores. With
// `withRoom`, a floor and a point light, so that light paths meet the strip.
// With `rootTurns`, the root joint turns 90 degrees about +Z too (a nested animated chain).
std::string skinnedStrip(const std::string& tag, bool withRoom = false, bool rootTurns = false) {
  Buffers b;
  const std::vector<float> pos = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 0, 2, 0, 1, 2, 0};
  const uint16_t idx[] = {0, 1, 3, 0, 3, 2, 2, 3, 5, 2, 5, 4};
  const uint8_t joints[] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
  const std::vector<float> weights = {1,    0,    0, 0, 1, 0, 0, 0, 0.5f, 0.5f, 0, 0,
                                      0.5f, 0.5f, 0, 0, 1, 0, 0, 0, 1,    0,    0, 0};
  std::vector<float> ibm(32, 0.0f);
  for (int m = 0; m < 2; ++m)
    for (int d = 0; d < 4; ++d) ibm[16 * m + 5 * d] = 1.0f;
  ibm[16 + 13] = -1.0f;  // joint 1: translate(0, -1, 0), column-major
  const glm::quat q = glm::angleAxis(float(M_PI / 2), glm::vec3(0, 0, 1));
  const std::vector<float> times = {0, 1}, rot = {0, 0, 0, 1, q.x, q.y, q.z, q.w};
  json attrs = {{"POSITION", b.floats(pos, 6, "VEC3")},
                {"JOINTS_0", b.add(joints, sizeof joints, 5121, 6, "VEC4")},
                {"WEIGHTS_0", b.floats(weights, 6, "VEC4")}};
  b.accessors[0]["min"] = {0, 0, 0};
  b.accessors[0]["max"] = {1, 2, 0};
  const int indices = b.add(idx, sizeof idx, 5123, 12, "SCALAR");
  const int ibmAcc = b.floats(ibm, 2, "MAT4");
  const int in = b.floats(times, 2, "SCALAR");
  b.accessors[size_t(in)]["min"] = {0};
  b.accessors[size_t(in)]["max"] = {1};
  const int out = b.floats(rot, 2, "VEC4");
  json doc;
  doc["scene"] = 0;
  json nodes = {{{"mesh", 0}, {"skin", 0}, {"translation", {5, 0, 0}}},
                {{"children", {2}}},
                {{"translation", {0, 1, 0}}}};
  json roots = {0, 1};
  json meshes = {{{"primitives", {{{"attributes", attrs}, {"indices", indices}}}}}};
  if (withRoom) {
    const std::vector<float> floor = {-3, -0.5f, 3, 3, -0.5f, 3, 3, -0.5f, -3, -3, -0.5f, -3};
    const uint16_t fi[] = {0, 1, 2, 0, 2, 3};
    const int fp = b.floats(floor, 4, "VEC3");
    b.accessors[size_t(fp)]["min"] = {-3, -0.5, -3};
    b.accessors[size_t(fp)]["max"] = {3, -0.5, 3};
    meshes.push_back({{"primitives",
                       {{{"attributes", {{"POSITION", fp}}},
                         {"indices", b.add(fi, sizeof fi, 5123, 6, "SCALAR")}}}}});
    nodes.push_back({{"mesh", 1}});
    nodes.push_back(
        {{"translation", {1.5, 3, 2}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
    nodes.push_back({{"camera", 0}, {"translation", {0.5, 1, 5}}});
    roots = {0, 1, 3, 4, 5};
    doc["extensionsUsed"] = {"KHR_lights_punctual"};
    doc["extensions"] = {
        {"KHR_lights_punctual", {{"lights", {{{"type", "point"}, {"intensity", 30}}}}}}};
    doc["cameras"] = {{{"type", "perspective"},
                       {"perspective", {{"yfov", 0.9}, {"aspectRatio", 1.0}, {"znear", 0.01}}}}};
  }
  doc["scenes"] = {{{"nodes", roots}}};
  doc["nodes"] = nodes;
  doc["meshes"] = meshes;
  doc["skins"] = {{{"joints", {1, 2}}, {"inverseBindMatrices", ibmAcc}}};
  const json sampler = {{"input", in}, {"output", out}};
  const json channel = {{"sampler", 0}, {"target", {{"node", 2}, {"path", "rotation"}}}};
  json anim;
  anim["samplers"] = json::array({sampler});
  anim["channels"] = json::array({channel});
  if (rootTurns)
    anim["channels"].push_back({{"sampler", 0}, {"target", {{"node", 1}, {"path", "rotation"}}}});
  doc["animations"] = json::array({anim});
  return b.write(doc, tag);
}

LoadOptions quiet() {
  LoadOptions o;
  o.printWarnings = false;
  return o;
}

void expectVec(const glm::vec3& a, const glm::vec3& b) {
  EXPECT_NEAR(a.x, b.x, 1e-5f);
  EXPECT_NEAR(a.y, b.y, 1e-5f);
  EXPECT_NEAR(a.z, b.z, 1e-5f);
}

TEST(Skin, VerticesFollowTheirJoints) {
  const Scene s = loadScene(skinnedStrip("skin-load"), quiet());
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
  ASSERT_EQ(s.dynamicMeshes.size(), 1u);
  ASSERT_TRUE(s.meshDeforms(0));
  EXPECT_EQ(s.deformingTriangleCount(), 4u);
  EXPECT_EQ(s.staticTriangleCount(), 0u);
  // The skinned mesh is placed by its joints only: the node's (5, 0, 0) does not apply.
  EXPECT_EQ(s.instanceTransform(0, 0.5), glm::mat4(1.0f));
  TriangleMesh m = s.dynamicMeshes[0];
  s.deformMesh(0, 0.0, &m);
  for (size_t v = 0; v < 6; ++v) expectVec(m.positions[v], s.dynamicMeshes[0].positions[v]);
  s.deformMesh(0, 1.0, &m);
  expectVec(m.positions[0], {0, 0, 0});
  expectVec(m.positions[2], {0, 1, 0});
  expectVec(m.positions[3], {0.5f, 1.5f, 0});  // half of (1, 1, 0) and half of (0, 2, 0)
  expectVec(m.positions[4], {-1, 1, 0});
  expectVec(m.positions[5], {-1, 2, 0});
  // The scene's bounds hold every pose.
  EXPECT_LE(s.bounds.min.x, -1.0f + 1e-5f);
}

// A quad with two morph targets: POSITION deltas (0, 0, 1) on vertex 2 and (1, 0, 0) on
// vertex 3; NORMAL deltas on the first. Weights from (0, 0) at t = 0 to (1, 0.5) at t = 1.
std::string morphQuad(const std::string& tag, bool animated, const char* interpolation) {
  Buffers b;
  const std::vector<float> pos = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  const std::vector<float> nrm = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
  const std::vector<float> d0 = {0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0};
  const std::vector<float> d1 = {0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0};
  const std::vector<float> n0 = {0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0};
  const uint16_t idx[] = {0, 1, 2, 0, 2, 3};
  json attrs = {{"POSITION", b.floats(pos, 4, "VEC3")}, {"NORMAL", b.floats(nrm, 4, "VEC3")}};
  b.accessors[0]["min"] = {0, 0, 0};
  b.accessors[0]["max"] = {1, 1, 0};
  json targets = {{{"POSITION", b.floats(d0, 4, "VEC3")}, {"NORMAL", b.floats(n0, 4, "VEC3")}},
                  {{"POSITION", b.floats(d1, 4, "VEC3")}}};
  for (int a : {2, 4}) {
    b.accessors[size_t(a)]["min"] = {0, 0, 0};
    b.accessors[size_t(a)]["max"] = {1, 0, 1};
  }
  const int indices = b.add(idx, sizeof idx, 5123, 6, "SCALAR");
  json doc;
  doc["scene"] = 0;
  doc["scenes"] = {{{"nodes", {0}}}};
  doc["nodes"] = {{{"mesh", 0}, {"weights", {0.25, 0.0}}}};
  doc["meshes"] = {
      {{"primitives", {{{"attributes", attrs}, {"indices", indices}, {"targets", targets}}}},
       {"weights", {0.5, 0.5}}}};
  if (animated) {
    const bool cubic = std::string(interpolation) == "CUBICSPLINE";
    const std::vector<float> times = {0, 1};
    // CUBICSPLINE: in-tangents, values, out-tangents per key (tangents 0: smoothstep).
    const std::vector<float> w = cubic ? std::vector<float>{0, 0, 0, 0, 0, 0, 0, 0, 1, 0.5f, 0, 0}
                                       : std::vector<float>{0, 0, 1, 0.5f};
    const int in = b.floats(times, 2, "SCALAR");
    b.accessors[size_t(in)]["min"] = {0};
    b.accessors[size_t(in)]["max"] = {1};
    const int out = b.floats(w, w.size(), "SCALAR");
    const json sampler = {{"input", in}, {"output", out}, {"interpolation", interpolation}};
    const json channel = {{"sampler", 0}, {"target", {{"node", 0}, {"path", "weights"}}}};
    json anim;
    anim["samplers"] = json::array({sampler});
    anim["channels"] = json::array({channel});
    doc["animations"] = json::array({anim});
  }
  return b.write(doc, tag);
}

TEST(Morph, AnimatedWeightsBlendTheTargets) {
  for (const char* interp : {"LINEAR", "STEP", "CUBICSPLINE"}) {
    SCOPED_TRACE(interp);
    const Scene s = loadScene(morphQuad("morph", true, interp), quiet());
    EXPECT_TRUE(s.warnings.empty());
    ASSERT_EQ(s.dynamicMeshes.size(), 1u);
    ASSERT_TRUE(s.meshDeforms(0));
    TriangleMesh m = s.dynamicMeshes[0];
    s.deformMesh(0, 0.5, &m);
    const std::string i = interp;
    // LINEAR: (0.5, 0.25); STEP: the first key's (0, 0); CUBICSPLINE with zero tangents:
    // smoothstep(0.5) = 0.5 of the way.
    const float w0 = i == "STEP" ? 0.0f : 0.5f, w1 = i == "STEP" ? 0.0f : 0.25f;
    expectVec(m.positions[2], {1, 1, w0});
    expectVec(m.positions[3], {w1, 1, 0});
    expectVec(m.normals[2], glm::normalize(glm::vec3(w0, 0, 1)));
    EXPECT_EQ(s.instanceTransform(0, 0.5), glm::mat4(1.0f));  // the node does not move
  }
}

TEST(Morph, FixedWeightsAreAppliedOnce) {
  // The node's weights (0.25, 0) override the mesh's (0.5, 0.5); nothing animates them, so the
  // mesh is static geometry in its morphed shape.
  const Scene s = loadScene(morphQuad("morph-fixed", false, "LINEAR"), quiet());
  EXPECT_TRUE(s.dynamicMeshes.empty());
  ASSERT_EQ(s.staticMesh.vertexCount(), 4u);
  expectVec(s.staticMesh.positions[2], {1, 1, 0.25f});
  expectVec(s.staticMesh.positions[3], {0, 1, 0});
}

TEST(Skin, NestedAnimatedJointsCompose) {
  // Both joints turn 90 degrees: the child's turn happens about its own origin (0, 1, 0),
  // then the root's turns everything about the world origin.
  const Scene s = loadScene(skinnedStrip("skin-nested", false, true), quiet());
  TriangleMesh m = s.dynamicMeshes[0];
  s.deformMesh(0, 1.0, &m);
  expectVec(m.positions[1], {0, 1, 0});    // root only: (1, 0, 0) turned
  expectVec(m.positions[4], {-1, -1, 0});  // child: (-1, 1, 0) as above, then turned
  expectVec(m.positions[5], {-2, -1, 0});
  // Halfway, slerp gives 45 degrees each.
  s.deformMesh(0, 0.5, &m);
  const float c = std::sqrt(0.5f);
  expectVec(m.positions[1], {c, c, 0});
}

TEST(Skin, BrokenSkinsAreRefused) {
  const std::string path = skinnedStrip("skin-bad");
  json doc;
  std::ifstream(path) >> doc;
  auto refused = [&](const json& d, const std::string& what) {
    { std::ofstream(path) << d.dump(); }
    try {
      loadScene(path, quiet());
      ADD_FAILURE() << "loaded; expected: " << what;
    } catch (const std::exception& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  json d = doc;
  d["skins"][0]["joints"] = {1, 9};
  refused(d, "joint node 9 does not exist");
  d = doc;
  d["skins"][0]["joints"] = {1};
  refused(d, "JOINTS refer to joint 1 of a skin with 1");
  d = doc;
  d["skins"][0]["joints"] = json::array();
  refused(d, "has no joints");
}

// Reuse keeps light paths only where nothing moved: while the strip bends it equals retrace
// bit for bit, and once the animation ends (t > 1) no light path is traced again.
TEST(Skin, ReuseEqualsRetraceWhileTheMeshBends) {
  const std::string scene = skinnedStrip("skin-render", true);
  const std::string args = " --width 24 --height 24 --spp 2 --fps 4";
  const std::string a = test::renderFrames(scene, "0-6", "--mode reuse" + args, "skin-a");
  const std::string b = test::renderFrames(scene, "0-6", "--mode retrace" + args, "skin-b");
  for (int f = 0; f <= 6; ++f)
    EXPECT_EQ(test::frameImage(a, f).rgba, test::frameImage(b, f).rgba) << "frame " << f;
  const auto lines = test::statsLines(a);
  ASSERT_EQ(lines.size(), 7u);
  for (int f = 1; f <= 6; ++f) {
    const json j = json::parse(lines[size_t(f)]);
    const uint64_t retraced = j["counters"]["slots_retraced"];
    if (f <= 4)
      EXPECT_GT(retraced, 0u) << "frame " << f << " bends the strip";
    else
      EXPECT_EQ(retraced, 0u) << "frame " << f << " is after the animation";
  }
}

// The skinned demo scene (a swaying tentacle and a morphing ball in the Cornell box): reuse
// equals retrace over 12 frames.
TEST(Skin, ReuseEqualsRetraceOnTheSkinnedDemo) {
  const std::string scene = test::sourcePath("scenes/cornell-skinned.gltf");
  const std::string args = " --width 24 --height 18 --spp 1";
  const std::string a = test::renderFrames(scene, "0-11", "--mode reuse" + args, "demo-a");
  const std::string b = test::renderFrames(scene, "0-11", "--mode retrace" + args, "demo-b");
  for (int f = 0; f <= 11; ++f)
    EXPECT_EQ(test::frameImage(a, f).rgba, test::frameImage(b, f).rgba) << "frame " << f;
}

TEST(Morph, ReuseEqualsRetraceWhileTheTargetsBlend) {
  const std::string scene = morphQuad("morph-render", true, "LINEAR");
  const std::string args = " --width 16 --height 16 --spp 2 --fps 4";
  const std::string a = test::renderFrames(scene, "0-4", "--mode reuse" + args, "morph-a");
  const std::string b = test::renderFrames(scene, "0-4", "--mode retrace" + args, "morph-b");
  for (int f = 0; f <= 4; ++f)
    EXPECT_EQ(test::frameImage(a, f).rgba, test::frameImage(b, f).rgba) << "frame " << f;
}

}  // namespace
}  // namespace pr
