// Animation sampling against values computed by hand: LINEAR (with slerp), STEP, CUBICSPLINE,
// clamping outside the key range, and a parent's motion reaching a static-local child.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include "scene/gltf_loader.h"
#include "support/test_env.h"

namespace pr {
namespace {

using nlohmann::json;

std::string base64(const std::string& bytes) {
  static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const uint32_t v = uint8_t(bytes[i]) << 16 | uint8_t(bytes[i + 1]) << 8 | uint8_t(bytes[i + 2]);
    for (int k = 18; k >= 0; k -= 6) out += t[(v >> k) & 63];
  }
  if (i + 1 == bytes.size()) {
    const uint32_t v = uint8_t(bytes[i]) << 16;
    out += std::string{t[(v >> 18) & 63], t[(v >> 12) & 63], '=', '='};
  } else if (i + 2 == bytes.size()) {
    const uint32_t v = uint8_t(bytes[i]) << 16 | uint8_t(bytes[i + 1]) << 8;
    out += std::string{t[(v >> 18) & 63], t[(v >> 12) & 63], t[(v >> 6) & 63], '='};
  }
  return out;
}

// A glTF document with one data: buffer that accessors are appended to.
struct Builder {
  json doc = {{"asset", {{"version", "2.0"}}},
              {"bufferViews", json::array()},
              {"accessors", json::array()}};
  std::string bin;

  int floats(const std::vector<float>& v, const char* type) {
    const size_t comps = std::string(type) == "SCALAR" ? 1
                         : std::string(type) == "VEC2" ? 2
                         : std::string(type) == "VEC3" ? 3
                                                       : 4;
    const size_t offset = bin.size();
    bin.append(reinterpret_cast<const char*>(v.data()), v.size() * 4);
    doc["bufferViews"].push_back(
        {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", v.size() * 4}});
    doc["accessors"].push_back({{"bufferView", doc["bufferViews"].size() - 1},
                                {"componentType", 5126},
                                {"count", v.size() / comps},
                                {"type", type}});
    return int(doc["accessors"].size() - 1);
  }

  // A unit triangle mesh; returns its index.
  int triangle() {
    const int pos = floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3");
    doc["meshes"].push_back({{"primitives", {{{"attributes", {{"POSITION", pos}}}}}}});
    return int(doc["meshes"].size() - 1);
  }

  std::string write(const std::string& name) {
    doc["buffers"] = {{{"byteLength", bin.size()},
                       {"uri", "data:application/octet-stream;base64," + base64(bin)}}};
    const std::string path = test::tempDir("anim") + "/" + name;
    std::ofstream(path) << doc.dump();
    return path;
  }
};

// An animation with one sampler driving one channel.
json oneChannel(const json& sampler, int node, const std::string& path) {
  json channel = {{"sampler", 0}, {"target", {{"node", node}, {"path", path}}}};
  return {{"samplers", json::array({sampler})}, {"channels", json::array({channel})}};
}

LoadOptions quiet() {
  LoadOptions o;
  o.printWarnings = false;
  return o;
}

// One node (child of an optional parent) animated by one sampler.
Scene animatedScene(const std::string& path, const char* interpolation,
                    const std::vector<float>& times, const std::vector<float>& values,
                    const char* type) {
  Builder b;
  const int mesh = b.triangle();
  const int in = b.floats(times, "SCALAR");
  const int out = b.floats(values, type);
  b.doc["nodes"] = {{{"mesh", mesh}}};
  b.doc["scenes"] = {{{"nodes", {0}}}};
  b.doc["animations"] = json::array(
      {oneChannel({{"input", in}, {"output", out}, {"interpolation", interpolation}}, 0, path)});
  return loadScene(b.write("anim.gltf"), quiet());
}

glm::vec3 translationAt(const Scene& s, double t) {
  return glm::vec3(s.nodeWorldTransform(0, t)[3]);
}

void expectNear(const glm::vec3& a, const glm::vec3& b, float tol = 1e-5f) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

TEST(Animation, LinearTranslationAndClamping) {
  const Scene s = animatedScene("translation", "LINEAR", {1.0f, 3.0f}, {0, 0, 0, 4, 2, -2}, "VEC3");
  EXPECT_DOUBLE_EQ(s.animationDuration(), 3.0);
  expectNear(translationAt(s, 0.0), {0, 0, 0});         // before the first key: first value
  expectNear(translationAt(s, 1.5), {1, 0.5f, -0.5f});  // a quarter of the way
  expectNear(translationAt(s, 2.0), {2, 1, -1});
  expectNear(translationAt(s, 10.0), {4, 2, -2});  // after the last key: last value
  EXPECT_EQ(s.frameCount(24.0), 73u);              // floor(3 * 24) + 1
  ASSERT_EQ(s.instances.size(), 1u);
  EXPECT_EQ(s.staticTriangleCount(), 0u);
  EXPECT_EQ(s.dynamicTriangleCount(), 1u);
}

TEST(Animation, StepHoldsTheKeyValue) {
  const Scene s =
      animatedScene("translation", "STEP", {0.0f, 1.0f, 2.0f}, {0, 0, 0, 5, 0, 0, 7, 0, 0}, "VEC3");
  expectNear(translationAt(s, 0.5), {0, 0, 0});
  expectNear(translationAt(s, 0.999), {0, 0, 0});
  expectNear(translationAt(s, 1.0), {5, 0, 0});
  expectNear(translationAt(s, 1.7), {5, 0, 0});
  expectNear(translationAt(s, 2.5), {7, 0, 0});
}

TEST(Animation, LinearRotationIsShortestSlerp) {
  // 0 to 90 degrees about Z; the second key is given as -q (the same rotation), so a plain
  // lerp would go the long way round.
  const float h = std::sqrt(0.5f);
  const Scene s =
      animatedScene("rotation", "LINEAR", {0.0f, 1.0f}, {0, 0, 0, 1, 0, 0, -h, -h}, "VEC4");
  const glm::mat4 m = s.nodeWorldTransform(0, 0.5);
  // Halfway is 45 degrees: +X goes to (cos 45, sin 45, 0).
  expectNear(glm::vec3(m * glm::vec4(1, 0, 0, 0)), {h, h, 0});
  const glm::mat4 q = s.nodeWorldTransform(0, 0.25);  // slerp: exactly 22.5 degrees
  const float a = glm::radians(22.5f);
  expectNear(glm::vec3(q * glm::vec4(1, 0, 0, 0)), {std::cos(a), std::sin(a), 0});
}

TEST(Animation, CubicSplineMatchesHandComputedHermite) {
  // Keys at t=0 and t=2 (dt = 2), x component only. Per key: in-tangent, value, out-tangent.
  const float v0 = 1, b0 = 3, a1 = -1, v1 = 4;
  const Scene s = animatedScene("translation", "CUBICSPLINE", {0.0f, 2.0f},
                                {0, 0, 0, v0, 0, 0, b0, 0, 0,   // key 0: in, value, out
                                 a1, 0, 0, v1, 0, 0, 0, 0, 0},  // key 1
                                "VEC3");
  for (double t : {0.5, 1.0, 1.5}) {
    const double dt = 2.0, u = t / dt, u2 = u * u, u3 = u2 * u;
    const double expected = (2 * u3 - 3 * u2 + 1) * v0 + dt * (u3 - 2 * u2 + u) * b0 +
                            (-2 * u3 + 3 * u2) * v1 + dt * (u3 - u2) * a1;
    EXPECT_NEAR(translationAt(s, t).x, expected, 1e-5) << "t=" << t;
  }
  expectNear(translationAt(s, -1.0), {v0, 0, 0});  // the key value, not the tangent
  expectNear(translationAt(s, 5.0), {v1, 0, 0});
}

TEST(Animation, CubicSplineRotationIsNormalised) {
  const Scene s = animatedScene("rotation", "CUBICSPLINE", {0.0f, 1.0f},
                                {0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 1, 0,   // key 0: in, value, out
                                 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 0, 0},  // key 1
                                "VEC4");
  const glm::mat3 r(s.nodeWorldTransform(0, 0.5));
  EXPECT_NEAR(glm::determinant(r), 1.0f, 1e-4f);  // a rotation, not a scaled one
}

TEST(Animation, ParentMotionMovesStaticLocalChild) {
  Builder b;
  const int mesh = b.triangle();
  const int in = b.floats({0.0f, 1.0f}, "SCALAR");
  const int out = b.floats({0, 0, 0, 0, 10, 0}, "VEC3");
  b.doc["nodes"] = {{{"children", {1}}},                              // 0: animated parent
                    {{"translation", {1, 0, 0}}, {"children", {2}}},  // 1: static local
                    {{"mesh", mesh}, {"scale", {2, 2, 2}}},           // 2: the mesh
                    {{"mesh", mesh}, {"translation", {0, 0, 5}}}};    // 3: static root
  b.doc["scenes"] = {{{"nodes", {0, 3}}}};
  b.doc["animations"] =
      json::array({oneChannel({{"input", in}, {"output", out}}, 0, "translation")});
  const Scene s = loadScene(b.write("nested.gltf"), quiet());
  ASSERT_EQ(s.instances.size(), 1u);
  EXPECT_EQ(s.instances[0].node, 2);
  EXPECT_TRUE(s.nodes[2].dynamic);
  EXPECT_FALSE(s.nodes[3].dynamic);
  EXPECT_EQ(s.staticTriangleCount(), 1u);
  EXPECT_EQ(s.dynamicTriangleCount(), 1u);
  // Child world = parent(t) * T(1,0,0) * S(2): vertex (1,0,0) lands at (3, 10t, 0).
  for (double t : {0.0, 0.5, 1.0}) {
    const glm::vec3 p = glm::vec3(s.instanceTransform(0, t) * glm::vec4(1, 0, 0, 1));
    expectNear(p, {3, float(10 * t), 0});
  }
  // The static triangle was flattened at (0,0,5).
  expectNear(s.staticMesh.positions[0], {0, 0, 5});
  // Bounds over the animation cover the instance's whole path.
  EXPECT_GE(s.bounds.max.y, 10.0f);
}

// Animations are clips: where two move the same node's same property the first plays there
// (the Fox's Survey, not its Walk and Run over it), and a warning says so; one that moves
// another node plays beside it, and the duration is of what plays.
TEST(Animation, TheFirstClipPlaysWhereClipsShareATarget) {
  Builder b;
  const int mesh = b.triangle();
  const int in = b.floats({0.0f, 1.0f}, "SCALAR");
  const int longIn = b.floats({0.0f, 4.0f}, "SCALAR");
  const int up = b.floats({0, 0, 0, 0, 10, 0}, "VEC3");
  const int side = b.floats({0, 0, 0, 10, 0, 0}, "VEC3");
  b.doc["nodes"] = {{{"mesh", mesh}}, {{"mesh", mesh}, {"translation", {0, 0, 5}}}};
  b.doc["scenes"] = {{{"nodes", {0, 1}}}};
  b.doc["animations"] =
      json::array({oneChannel({{"input", in}, {"output", up}}, 0, "translation"),
                   oneChannel({{"input", longIn}, {"output", side}}, 0, "translation"),
                   oneChannel({{"input", in}, {"output", side}}, 1, "translation")});
  b.doc["animations"][1]["name"] = "Walk";
  const Scene s = loadScene(b.write("clips.gltf"), quiet());
  expectNear(glm::vec3(s.nodeWorldTransform(0, 0.5)[3]), {0, 5, 0});  // the first clip
  expectNear(glm::vec3(s.nodeWorldTransform(1, 0.5)[3]), {5, 0, 0});  // another node's
  EXPECT_DOUBLE_EQ(s.animationDuration(), 1.0);                       // not the shadowed clip's 4 s
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("animation 1 (Walk) animates what an earlier animation does"),
            std::string::npos)
      << s.warnings[0];
  // --animation: that clip alone, by name or index, and an unknown one named with the others.
  LoadOptions walk = quiet();
  walk.animation = "Walk";
  const Scene w = loadScene(b.write("clips-walk.gltf"), walk);
  expectNear(glm::vec3(w.nodeWorldTransform(0, 2.0)[3]), {5, 0, 0});
  expectNear(glm::vec3(w.nodeWorldTransform(1, 0.5)[3]), {0, 0, 5});  // clip 2 does not play
  EXPECT_DOUBLE_EQ(w.animationDuration(), 4.0);
  EXPECT_TRUE(w.warnings.empty());
  walk.animation = "2";
  expectNear(glm::vec3(loadScene(b.write("clips-2.gltf"), walk).nodeWorldTransform(1, 0.5)[3]),
             {5, 0, 0});
  walk.animation = "Run";
  try {
    loadScene(b.write("clips-run.gltf"), walk);
    ADD_FAILURE() << "an unknown animation loaded";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--animation Run: no such animation (the scene has 0, "
                                         "1 (Walk), 2)"),
              std::string::npos)
        << e.what();
  }
}

TEST(Animation, ExtrasDynamicIsInherited) {
  Builder b;
  const int mesh = b.triangle();
  b.doc["nodes"] = {{{"children", {1}}, {"extras", {{"dynamic", true}}}}, {{"mesh", mesh}}};
  b.doc["scenes"] = {{{"nodes", {0}}}};
  const Scene s = loadScene(b.write("extras.gltf"), quiet());
  EXPECT_EQ(s.instances.size(), 1u);
  EXPECT_EQ(s.staticTriangleCount(), 0u);
  EXPECT_DOUBLE_EQ(s.animationDuration(), 0.0);
  EXPECT_EQ(s.frameCount(24), 1u);
}

TEST(Animation, TimesMustIncrease) {
  EXPECT_THROW(animatedScene("translation", "LINEAR", {1.0f, 1.0f}, {0, 0, 0, 1, 1, 1}, "VEC3"),
               InputError);
  EXPECT_THROW(animatedScene("translation", "LINEAR", {0.0f, NAN}, {0, 0, 0, 1, 1, 1}, "VEC3"),
               InputError);
  // Output count must match: 2 keys, 3 values.
  EXPECT_THROW(
      animatedScene("translation", "LINEAR", {0.0f, 1.0f}, {0, 0, 0, 1, 1, 1, 2, 2, 2}, "VEC3"),
      InputError);
  // CUBICSPLINE needs three values per key.
  EXPECT_THROW(
      animatedScene("translation", "CUBICSPLINE", {0.0f, 1.0f}, {0, 0, 0, 1, 1, 1}, "VEC3"),
      InputError);
  // And at least two keys (one key: in-tangent, value, out-tangent, but nothing to span).
  try {
    animatedScene("translation", "CUBICSPLINE", {0.0f}, {0, 0, 0, 1, 1, 1, 0, 0, 0}, "VEC3");
    ADD_FAILURE() << "a one-key CUBICSPLINE sampler loaded";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("CUBICSPLINE needs at least 2 keys, the input has 1"),
              std::string::npos)
        << e.what();
  }
  // A single LINEAR or STEP key is a constant, which the spec allows.
  EXPECT_NO_THROW(animatedScene("translation", "LINEAR", {0.0f}, {1, 2, 3}, "VEC3"));
}

}  // namespace
}  // namespace pr
