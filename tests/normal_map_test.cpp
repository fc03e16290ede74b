// Normal maps and the second uv set: tangents generated where a mesh has none, the loader's
// TEXCOORD_1 / texCoord handling, and renders whose brightness the normal map sets by a cosine
// that is known in advance (a Lambert plane under a directional light), in both modes.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include <nlohmann/json.hpp>
#include <stb_image_write.h>

#include "render/gpu_scene.h"
#include "scene/gltf_loader.h"
#include "scene/tangents.h"
#include "support/render_helpers.h"
#include "support/test_env.h"

namespace pr {
namespace {

using nlohmann::json;

// ---------------------------------------------------------------------------------------------
// Tangent generation

TriangleMesh plane(const std::vector<glm::vec2>& uvs) {
  TriangleMesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  m.normals.assign(4, glm::vec3(0, 0, 1));
  m.uvs = uvs;
  m.indices = {0, 1, 2, 0, 2, 3};
  m.materials = {0, 0};
  return m;
}

void expectTangents(const TriangleMesh& m, glm::vec3 t, float w) {
  ASSERT_EQ(m.tangents.size(), m.vertexCount());
  for (const glm::vec4& v : m.tangents) {
    EXPECT_NEAR(v.x, t.x, 1e-5f);
    EXPECT_NEAR(v.y, t.y, 1e-5f);
    EXPECT_NEAR(v.z, t.z, 1e-5f);
    EXPECT_EQ(v.w, w);
  }
}

// glTF's v runs down the image and a normal map's +Y up it: the bitangent b = w cross(n, t)
// points along -dP/dv (the handedness of the Khronos assets' authored tangents, e.g. the
// FlightHelmet's: w = +1 where u runs along x and v along -y).
TEST(Tangents, FollowTheUvGradientAndItsHandedness) {
  TriangleMesh m = plane({{0, 0}, {1, 0}, {1, 1}, {0, 1}});  // u along x, v along y: b = -y
  generateTangents(m, {});
  expectTangents(m, {1, 0, 0}, -1.0f);
  m = plane({{0, 1}, {1, 1}, {1, 0}, {0, 0}});  // u along x, v along -y (an image upright): b = +y
  generateTangents(m, {});
  expectTangents(m, {1, 0, 0}, 1.0f);
  m = plane({{1, 0}, {0, 0}, {0, 1}, {1, 1}});  // u mirrored: along -x, v still along y
  generateTangents(m, {});
  expectTangents(m, {-1, 0, 0}, 1.0f);
  m = plane({{0, 0}, {0, -1}, {1, -1}, {1, 0}});  // rotated: u along y, v along -x: b = +x
  generateTangents(m, {});
  expectTangents(m, {0, 1, 0}, -1.0f);
}

TEST(Tangents, ChooseTheNormalMapsUvSetPerTriangle) {
  TriangleMesh m = plane({{0, 0}, {0, 0}, {0, 0}, {0, 0}});  // TEXCOORD_0 without a gradient
  m.uvs1 = {{0, 0}, {0, -1}, {1, -1}, {1, 0}};
  generateTangents(m, {1, 1});
  expectTangents(m, {0, 1, 0}, -1.0f);
  // No gradient in the set it reads: some unit tangent orthogonal to the normal.
  generateTangents(m, {0, 0});
  for (const glm::vec4& t : m.tangents) {
    EXPECT_NEAR(glm::length(glm::vec3(t)), 1.0f, 1e-5f);
    EXPECT_NEAR(t.z, 0.0f, 1e-6f);
  }
}

// A flat primitive's vertices have zero normals: the face's normal sets the frame, and the
// handedness still follows the uvs.
TEST(Tangents, OfFlatVerticesFollowTheirFaces) {
  TriangleMesh m = plane({{0, 0}, {1, 0}, {1, 1}, {0, 1}});
  m.normals.assign(4, glm::vec3(0.0f));
  generateTangents(m, {});
  expectTangents(m, {1, 0, 0}, -1.0f);
  m = plane({{1, 0}, {0, 0}, {0, 1}, {1, 1}});  // u mirrored
  m.normals.assign(4, glm::vec3(0.0f));
  generateTangents(m, {});
  expectTangents(m, {-1, 0, 0}, 1.0f);
  // A fold: the shared edge's tangent lies between the faces' planes; zero normals stay zero.
  m = plane({{0, 0}, {1, 0}, {1, 1}, {0, 1}});
  m.positions[3] = {0, 1, 1};
  m.normals.assign(4, glm::vec3(0.0f));
  generateTangents(m, {});
  for (size_t v = 0; v < 4; ++v) {
    EXPECT_NEAR(glm::length(glm::vec3(m.tangents[v])), 1.0f, 1e-5f);
    EXPECT_GT(m.tangents[v].x, 0.7f);
    EXPECT_EQ(m.tangents[v].w, -1.0f);
    EXPECT_EQ(m.normals[v], glm::vec3(0.0f));
  }
}

TEST(Tangents, AreOrthogonalToCurvedNormals) {
  TriangleMesh m = plane({{0, 0}, {1, 0}, {1, 1}, {0, 1}});
  for (glm::vec3& n : m.normals) n = glm::normalize(glm::vec3(0.3f, -0.2f, 1.0f));
  generateTangents(m, {});
  for (size_t v = 0; v < 4; ++v) {
    const glm::vec3 t(m.tangents[v]);
    EXPECT_NEAR(glm::dot(t, m.normals[v]), 0.0f, 1e-6f);
    EXPECT_NEAR(glm::length(t), 1.0f, 1e-5f);
    EXPECT_GT(t.x, 0.9f);  // still mostly along the uv gradient
  }
}

// ---------------------------------------------------------------------------------------------
// A plane seen from above, lit by a directional light, with a constant normal map.

struct PlaneScene {
  json doc;
  std::string bin;
  std::vector<uint8_t> normalTexel = {191, 128, 238, 255};  // about (0.5, 0, 0.87): 30 deg to +x
  float normalScale = 1.0f;
  float lightAngle = 0.0f;   // light from (sin a, 0, cos a), or (0, -sin a, cos a):
  bool lightAboutX = false;  // the light turned about x instead of y
  json planeNode = {{"mesh", 0}};
  bool withNormals = true;
  bool withTangents = false;
  glm::vec4 tangent{1, 0, 0, 1};
  int normalTexCoord = 0;
  json material;  // replaces the grey normal-mapped material where set

  std::string write(const std::string& tag) {
    const std::string dir = test::tempDir(tag);
    const float pos[] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
    const float nrm[] = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
    const float uv0[] = {0, 0, 1, 0, 1, 1, 0, 1};    // u along +x
    const float uv1[] = {0, 0, 0, -1, 1, -1, 1, 0};  // u along +y, v along -x
    const float tan[] = {tangent.x, tangent.y, tangent.z, tangent.w, tangent.x, tangent.y,
                         tangent.z, tangent.w, tangent.x, tangent.y, tangent.z, tangent.w,
                         tangent.x, tangent.y, tangent.z, tangent.w};
    const uint16_t idx[] = {0, 1, 2, 0, 2, 3};
    bin.clear();
    json views = json::array(), accessors = json::array();
    auto add = [&](const void* p, size_t bytes, int type, size_t count, const char* kind) {
      views.push_back({{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", bytes}});
      bin.append(static_cast<const char*>(p), bytes);
      while (bin.size() % 4) bin.push_back(0);
      accessors.push_back({{"bufferView", views.size() - 1},
                           {"componentType", type},
                           {"count", count},
                           {"type", kind}});
      return int(accessors.size() - 1);
    };
    json attrs = {{"POSITION", add(pos, sizeof pos, 5126, 4, "VEC3")},
                  {"NORMAL", add(nrm, sizeof nrm, 5126, 4, "VEC3")},
                  {"TEXCOORD_0", add(uv0, sizeof uv0, 5126, 4, "VEC2")},
                  {"TEXCOORD_1", add(uv1, sizeof uv1, 5126, 4, "VEC2")}};
    if (!withNormals) attrs.erase("NORMAL");
    if (withTangents) attrs["TANGENT"] = add(tan, sizeof tan, 5126, 4, "VEC4");
    const int indices = add(idx, sizeof idx, 5123, 6, "SCALAR");
    accessors[0]["min"] = {-1, -1, 0};
    accessors[0]["max"] = {1, 1, 0};
    { std::ofstream(dir + "/plane.bin", std::ios::binary) << bin; }
    stbi_write_png((dir + "/n.png").c_str(), 1, 1, 4, normalTexel.data(), 4);
    const float s = std::sin(lightAngle / 2), c = std::cos(lightAngle / 2);
    doc = {
        {"asset", {{"version", "2.0"}}},
        {"extensionsUsed", {"KHR_lights_punctual"}},
        {"extensions",
         {{"KHR_lights_punctual", {{"lights", {{{"type", "directional"}, {"intensity", 2.0}}}}}}}},
        {"scene", 0},
        {"scenes", {{{"nodes", {0, 1, 2}}}}},
        {"nodes",
         {planeNode,
          {{"camera", 0}, {"translation", {0, 0, 3}}},
          {{"rotation", lightAboutX ? json{s, 0, 0, c} : json{0, s, 0, c}},  // shines along -z
           {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}}}},
        {"cameras",
         {{{"type", "perspective"},
           {"perspective", {{"yfov", 0.5}, {"aspectRatio", 1.0}, {"znear", 0.01}}}}}},
        {"meshes",
         {{{"primitives", {{{"attributes", attrs}, {"indices", indices}, {"material", 0}}}}}}},
        {"materials",
         {{{"pbrMetallicRoughness", {{"baseColorFactor", {0.5, 0.5, 0.5, 1}}}},
           {"normalTexture",
            {{"index", 0}, {"scale", normalScale}, {"texCoord", normalTexCoord}}}}}},
        {"textures", {{{"source", 0}, {"sampler", 0}}}},
        {"samplers", {{{"magFilter", 9728}, {"minFilter", 9728}}}},
        {"images", {{{"uri", "n.png"}}}},
        {"accessors", accessors},
        {"bufferViews", views},
        {"buffers", {{{"byteLength", bin.size()}, {"uri", "plane.bin"}}}}};
    if (!material.is_null()) {
      // Unused sheen and anisotropic materials: the kernels are then built with the material
      // tests' features (one build of them, not two).
      doc["materials"] = {
          material,
          {{"extensions", {{"KHR_materials_sheen", {{"sheenColorFactor", {1, 1, 1}}}}}}},
          {{"extensions", {{"KHR_materials_anisotropy", {{"anisotropyStrength", 0.5}}}}}}};
      for (const char* e : {"KHR_materials_clearcoat", "KHR_materials_specular",
                            "KHR_materials_sheen", "KHR_materials_anisotropy"})
        doc["extensionsUsed"].push_back(e);
    }
    const std::string path = dir + "/plane.gltf";
    std::ofstream(path) << doc.dump();
    return path;
  }

  // The brightness relative to an unmapped plane: cos(mapped normal, light) / cos(normal,
  // light), the map's normal in the frame (tangent t, b = w cross(n, t), n = +z).
  double expectedRatio(glm::dvec3 t, double w) const {
    glm::dvec3 m((normalTexel[0] / 255.0 * 2 - 1) * normalScale,
                 (normalTexel[1] / 255.0 * 2 - 1) * normalScale, normalTexel[2] / 255.0 * 2 - 1);
    const glm::dvec3 n(0, 0, 1), b = w * glm::cross(n, t);
    const glm::dvec3 ns = glm::normalize(m.x * t + m.y * b + m.z * n);
    const glm::dvec3 l = lightAboutX ? glm::dvec3(0, -std::sin(lightAngle), std::cos(lightAngle))
                                     : glm::dvec3(std::sin(lightAngle), 0, std::cos(lightAngle));
    return std::max(0.0, glm::dot(ns, l)) / l.z;
  }
};

double centreMean(const std::string& scene, const std::string& args, const std::string& tag) {
  const std::string dir = test::renderFrames(
      scene, "0", "--width 24 --height 24 --spp 2 --max-depth 2 --force-diffuse " + args, tag);
  const Image img = test::frameImage(dir, 0);
  return test::regionMean(img, 6, 6, 18, 18, 1).mean;
}

TEST(NormalMap, LoadsWithGeneratedTangentsAndTheSecondUvSet) {
  PlaneScene p;
  p.normalTexCoord = 1;
  LoadOptions quiet;
  quiet.printWarnings = false;
  Scene s = loadScene(p.write("nm-load"), quiet);
  ASSERT_EQ(s.materials.size(), 1u);
  EXPECT_TRUE(s.materials[0].normalTexture.valid());
  EXPECT_EQ(s.materials[0].normalTexture.texCoord, 1);
  ASSERT_EQ(s.staticMesh.uvs1.size(), 4u);
  EXPECT_EQ(s.staticMesh.uvs1[1], glm::vec2(0, -1));
  // Generated from TEXCOORD_1, whose u runs along +y.
  ASSERT_EQ(s.staticMesh.tangents.size(), 4u);
  EXPECT_NEAR(s.staticMesh.tangents[0].y, 1.0f, 1e-5f);
  const dev::Material d = toDeviceMaterial(s.materials[0]);
  EXPECT_EQ(d.normal_texture, 0);
  EXPECT_EQ(d.uv_sets, PR_UV_NORMAL);
  EXPECT_FLOAT_EQ(d.normal_scale, 1.0f);
  EXPECT_FALSE(s.textures[0].srgb);  // normal maps are linear data
}

TEST(NormalMap, TexCoordOfTheTransformOverridesAndUnknownSetsWarn) {
  PlaneScene p;
  const std::string path = p.write("nm-texcoord");
  json doc = p.doc;
  doc["extensionsUsed"].push_back("KHR_texture_transform");
  json& ext = doc["materials"][0]["normalTexture"]["extensions"]["KHR_texture_transform"];
  LoadOptions quiet;
  quiet.printWarnings = false;
  auto load = [&](int texCoord) {
    ext["texCoord"] = texCoord;
    { std::ofstream(path) << doc.dump(); }
    return loadScene(path, quiet);
  };
  EXPECT_EQ(load(1).materials[0].normalTexture.texCoord, 1);
  const Scene s = load(2);
  EXPECT_EQ(s.materials[0].normalTexture.texCoord, 0);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("texCoord 2 reads TEXCOORD_0"), std::string::npos) << s.warnings[0];
  try {
    load(-1);
    ADD_FAILURE() << "a negative texCoord loaded";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("\"texCoord\" must be a non-negative integer"),
              std::string::npos)
        << e.what();
  }
}

// The mapped normal leans 30 degrees towards the tangent: lit from that side the plane is
// brighter, from the other darker, by the cosines; scale 0 flattens the map. Both modes.
TEST(NormalMap, ShadesByTheMappedNormalInBothModes) {
  for (const char* mode : {"pathtrace", "reuse"}) {
    SCOPED_TRACE(mode);
    const std::string m = std::string("--mode ") + mode;
    PlaneScene flat;
    flat.normalScale = 0.0f;
    flat.normalTexel = {128, 128, 255, 255};
    for (float angle : {0.7f, -0.7f}) {
      PlaneScene p;
      p.lightAngle = angle;
      PlaneScene f = flat;
      f.lightAngle = angle;
      const double ref = centreMean(f.write("nm-f"), m, "nm-f-r");
      ASSERT_GT(ref, 0.01);
      const double got = centreMean(p.write("nm-p"), m, "nm-p-r");
      EXPECT_NEAR(got / ref, p.expectedRatio({1, 0, 0}, -1), 0.01) << "light angle " << angle;
    }
  }
}

// KHR_materials_clearcoat: the coat has its own normal, the vertex normal or its
// clearcoatNormalTexture, never the base layer's normal map. A black base under a rough coat,
// lit where the coat's highlight lies for a normal tilted 30 degrees by the map and far off it
// for the untilted one: the base's map leaves the coat's reflection as it is, the coat's own
// map moves the highlight to the camera.
TEST(NormalMap, TheClearcoatHasItsOwnNormal) {
  auto render = [](bool baseMap, bool coatMap, const std::string& tag) {
    PlaneScene p;
    p.lightAngle =
        1.0472f;  // 60 degrees: the mirror direction of the view about a 30-degree normal
    json m = {{"pbrMetallicRoughness",
               {{"baseColorFactor", {0, 0, 0, 1}}, {"metallicFactor", 0}, {"roughnessFactor", 1}}},
              {"extensions",
               {{"KHR_materials_specular", {{"specularFactor", 0.0}}},
                {"KHR_materials_clearcoat",
                 {{"clearcoatFactor", 1.0}, {"clearcoatRoughnessFactor", 0.3}}}}}};
    if (baseMap) m["normalTexture"] = {{"index", 0}};
    if (coatMap)
      m["extensions"]["KHR_materials_clearcoat"]["clearcoatNormalTexture"] = {{"index", 0}};
    p.material = m;
    const std::string dir = test::renderFrames(
        p.write("coat-n-" + tag), "0",
        "--mode pathtrace --width 24 --height 24 --spp 16 --max-depth 2", "coat-n-out-" + tag);
    return test::regionMean(test::frameImage(dir, 0), 6, 6, 18, 18, 1).mean;
  };
  const double plain = render(false, false, "plain"), base = render(true, false, "base"),
               coat = render(false, true, "coat");
  ASSERT_GT(plain, 0.0);
  EXPECT_NEAR(base / plain, 1.0, 0.02) << plain << " " << base;
  EXPECT_GT(coat / plain, 20.0) << plain << " " << coat;
}

// Given tangents are used as they are (here along +y, left-handed), and TEXCOORD_1's
// generated tangent where the map reads it.
TEST(NormalMap, GivenTangentsAndTheSecondUvSetSetTheFrame) {
  PlaneScene flat;
  flat.normalTexel = {128, 128, 255, 255};
  flat.normalScale = 0.0f;
  PlaneScene p;
  p.normalTexel = {128, 191, 238, 255};  // leans towards the bitangent
  p.withTangents = true;
  p.tangent = {0, 1, 0, -1};
  for (float angle : {0.6f, -0.6f}) {
    flat.lightAngle = p.lightAngle = angle;
    const double ref = centreMean(flat.write("nm-gf"), "--mode pathtrace", "nm-gf-r");
    // b = -cross(z, y) = +x: the plane is brighter lit from +x.
    const double got = centreMean(p.write("nm-gt"), "--mode pathtrace", "nm-gt-r");
    EXPECT_NEAR(got / ref, p.expectedRatio({0, 1, 0}, -1), 0.01) << angle;
    PlaneScene q;
    q.normalTexel = p.normalTexel;
    q.lightAngle = angle;
    q.normalTexCoord = 1;  // generated from TEXCOORD_1: t = +y, b = -dP/dv = +x
    const double got1 = centreMean(q.write("nm-uv1"), "--mode pathtrace", "nm-uv1-r");
    EXPECT_NEAR(got1 / ref, q.expectedRatio({0, 1, 0}, -1), 0.01) << angle;
  }
}

// Without NORMAL the plane is flat and its TANGENT (here along +y, left-handed) is ignored:
// the map reads the frame of the tangent generated from TEXCOORD_0 (t = +x, b = -y), static
// or on a moving instance, in both modes.
TEST(NormalMap, WithoutNormalsTheGivenTangentsAreIgnored) {
  for (const char* mode : {"pathtrace", "reuse"})
    for (bool dynamic : {false, true})
      for (float angle : {0.6f, -0.6f}) {
        SCOPED_TRACE(std::string(mode) + (dynamic ? " dynamic " : " static ") +
                     std::to_string(angle));
        PlaneScene flat, p;
        flat.normalTexel = {128, 128, 255, 255};
        flat.normalScale = 0.0f;
        p.normalTexel = {191, 128, 238, 255};  // leans 30 degrees towards the tangent
        p.withTangents = true;
        p.tangent = {0, 1, 0, -1};
        flat.withNormals = p.withNormals = false;
        if (dynamic) flat.planeNode = p.planeNode = {{"mesh", 0}, {"extras", {{"dynamic", true}}}};
        flat.lightAngle = p.lightAngle = angle;
        const std::string m = std::string("--mode ") + mode;
        const double ref = centreMean(flat.write("nm-nf"), m, "nm-nf-r");
        // The unmapped flat plane: rho / pi * E * cos(angle), rho = 0.5, E = 2.
        EXPECT_NEAR(ref, 1.0 / M_PI * std::cos(angle), 0.01 * ref);
        const double got = centreMean(p.write("nm-np"), m, "nm-np-r");
        EXPECT_NEAR(got / ref, p.expectedRatio({1, 0, 0}, -1), 0.01);
      }
}

// On moving geometry the tangent turns with the instance, and a mirroring instance turns the
// bitangent's handedness around (as it does the winding).
TEST(NormalMap, FollowsDynamicInstancesAndMirrors) {
  struct Case {
    json node;
    glm::dvec3 t;
    double w;
  };
  const json dyn = {{"dynamic", true}};
  const Case cases[] = {
      {{{"mesh", 0}, {"extras", dyn}, {"rotation", {0, 0, 1, 0}}}, {-1, 0, 0}, -1},  // 180 deg
      {{{"mesh", 0}, {"extras", dyn}, {"scale", {-1, 1, 1}}}, {-1, 0, 0}, 1}};
  for (const Case& c : cases) {
    for (bool aboutX : {false, true}) {
      for (float angle : {0.6f, -0.6f}) {
        SCOPED_TRACE(c.node.dump() + (aboutX ? " light about x " : " light about y ") +
                     std::to_string(angle));
        PlaneScene flat, p;
        flat.normalTexel = {128, 128, 255, 255};
        flat.normalScale = 0.0f;
        p.normalTexel = {191, 191, 220, 255};  // leans towards both t and b
        flat.planeNode = p.planeNode = c.node;
        flat.lightAngle = p.lightAngle = angle;
        flat.lightAboutX = p.lightAboutX = aboutX;
        const double ref = centreMean(flat.write("nm-df"), "--mode reuse", "nm-df-r");
        const double got = centreMean(p.write("nm-dp"), "--mode reuse", "nm-dp-r");
        EXPECT_NEAR(got / ref, p.expectedRatio(c.t, c.w), 0.01);
      }
    }
  }
}

}  // namespace
}  // namespace pr
