// Loading glTF: the real scenes, every broken file we have (each refused with one line naming
// the file), and small hand-written files for instancing, winding, materials and lights.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <functional>
#include <fstream>

#include <nlohmann/json.hpp>

#include "render/gpu_scene.h"
#include "scene/gltf_loader.h"
#include "support/gltf_builder.h"
#include "support/test_env.h"
#include "util/error.h"

namespace pr {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const char* kAssimpDir = "/usr/share/assimp/models/glTF2";

LoadOptions quiet() {
  LoadOptions o;
  o.printWarnings = false;
  return o;
}

// Loads `path`; returns "" on success or the InputError message. Any other exception fails.
std::string tryLoad(const std::string& path, Scene* out = nullptr) {
  try {
    Scene s = loadScene(path, quiet());
    if (out) *out = std::move(s);
    return "";
  } catch (const InputError& e) {
    return e.what();
  }
}

void expectRefused(const std::string& path) {
  const std::string msg = tryLoad(path);
  ASSERT_FALSE(msg.empty()) << path << " loaded but should be refused";
  EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  EXPECT_EQ(msg.rfind(path + ": ", 0), 0u) << msg;
}

// ---------------------------------------------------------------------------------------------
// Real scenes

TEST(SceneLoader, CornellNvpro) {
  PR_SHARED_SCENE(path, "cornell-nvpro/cornellBox.gltf");
  const auto start = std::chrono::steady_clock::now();
  const Scene s = loadScene(path, quiet());
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  std::cout << "cornell-nvpro loaded in " << ms << " ms\n";
  // The file's meshes hold 16,720 triangles; mesh 1 "cube_1" is placed twice (floor at y=-5,
  // ceiling at y=+5), so the world-space SSG holds 12 more.
  EXPECT_EQ(s.staticMeshTriangles, 16720u);
  EXPECT_EQ(s.staticTriangleCount(), 16732u);
  EXPECT_EQ(s.dynamicTriangleCount(), 0u);
  EXPECT_TRUE(s.instances.empty());
  EXPECT_EQ(s.materials.size(), 9u);
  EXPECT_EQ(s.emissiveTriangleCount(), 12u);  // the light: emissiveFactor 10
  EXPECT_EQ(s.lights.size(), 0u);
  ASSERT_EQ(s.fileCameraCount(), 1u);
  const CameraPose cam = s.cameraAt(0, 0.0);
  EXPECT_NEAR(cam.yfov, 0.7175f, 1e-3f);
  EXPECT_NEAR(cam.position.z, 19.992f, 1e-2f);
  EXPECT_NEAR(cam.forward.z, -1.0f, 1e-5f);
  EXPECT_EQ(s.materials[7].alphaMode, AlphaMode::Blend);
  EXPECT_FLOAT_EQ(s.materials[4].emission().x, 10.0f);
  EXPECT_EQ(s.staticMesh.normals.size(), s.staticMesh.positions.size());
  EXPECT_EQ(s.staticMesh.materials.size(), s.staticTriangleCount());
}

TEST(SceneLoader, BoxAnimatedIsSplit) {
  PR_SHARED_SCENE(path, "BoxAnimated/BoxAnimated.gltf");
  const Scene s = loadScene(path, quiet());
  EXPECT_GT(s.dynamicTriangleCount(), 0u);
  EXPECT_EQ(s.dynamicTriangleCount(),
            62u);  // node 2, under the translated node 0 and rotated itself
  EXPECT_EQ(s.staticTriangleCount(), 192u);  // node 3, not animated
  EXPECT_NEAR(s.animationDuration(), 3.70833, 1e-4);
  ASSERT_EQ(s.cameras.size(), 1u);
  EXPECT_TRUE(s.cameras[0].isDefault);
  // The default camera looks down -Z at the bounds' centre from outside the bounding sphere.
  const CameraPose cam = s.cameraAt(0, 0.0);
  EXPECT_NEAR(cam.forward.z, -1.0f, 1e-6f);
  EXPECT_GT(cam.position.z, s.bounds.max.z);
  // The instance moves between frames.
  EXPECT_NE(s.instanceTransform(0, 0.0), s.instanceTransform(0, 1.0));
}

// ---------------------------------------------------------------------------------------------
// Broken files

// Khronos validator test files: each report lists what is wrong. All of them but valid.glb have
// at least one error (severity 0) in their report, so every one must be refused.
TEST(SceneLoader, KhronosInvalidFilesAreRefused) {
  PR_SHARED_SCENE(dir, "invalid");
  int refused = 0;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    const std::string p = entry.path().string();
    const std::string ext = entry.path().extension().string();
    if (ext != ".gltf" && ext != ".glb") continue;
    std::ifstream reportFile(p + ".report.json");
    ASSERT_TRUE(reportFile) << "no report for " << p;
    const json report = json::parse(reportFile);
    bool hasError = false;
    for (const auto& m : report["issues"]["messages"]) hasError = hasError || m["severity"] == 0;
    if (entry.path().filename() == "valid.glb") {
      EXPECT_FALSE(hasError);
      EXPECT_EQ(tryLoad(p), "") << p;
      continue;
    }
    // A file whose report has only warnings or infos may load; none in this set is like that.
    ASSERT_TRUE(hasError) << p << ": report has no error; decide whether it should load";
    SCOPED_TRACE(p);
    expectRefused(p);
    ++refused;
  }
  EXPECT_GE(refused, 10);
}

TEST(SceneLoader, AssimpModelsLoadOrAreRefusedCleanly) {
  ASSERT_TRUE(fs::exists(kAssimpDir))
      << kAssimpDir << " is absent (tools/setup/install-deps.sh installs it)";
  int loaded = 0, refused = 0;
  for (const auto& entry : fs::recursive_directory_iterator(kAssimpDir)) {
    const std::string ext = entry.path().extension().string();
    if (ext != ".gltf" && ext != ".glb") continue;
    const std::string p = entry.path().string();
    std::string msg;
    try {
      loadScene(p, quiet());
    } catch (const InputError& e) {
      msg = e.what();
    } catch (const std::exception& e) {
      ADD_FAILURE() << p << ": unexpected exception " << e.what();
      continue;
    }
    if (msg.empty()) {
      ++loaded;
    } else {
      ++refused;
      EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
      EXPECT_EQ(msg.rfind(p + ": ", 0), 0u) << msg;
    }
  }
  EXPECT_GT(loaded, 20);
  EXPECT_GT(refused, 5);
}

TEST(SceneLoader, AssimpBrokenModelsAreRefused) {
  ASSERT_TRUE(fs::exists(kAssimpDir))
      << kAssimpDir << " is absent (tools/setup/install-deps.sh installs it)";
  const std::string d = kAssimpDir;
  for (const char* rel :
       {"IndexOutOfRange/IndexOutOfRange.gltf", "IndexOutOfRange/AllIndicesOutOfRange.gltf",
        "wrongTypes/badArray.gltf", "wrongTypes/badExtension.gltf", "wrongTypes/badNumber.gltf",
        "wrongTypes/badObject.gltf", "wrongTypes/badString.gltf", "wrongTypes/badUint.gltf",
        "RecursiveNodes/RecursiveNodes.gltf", "MissingBin/BoxTextured.gltf",
        "SchemaFailures/sceneWrongType.gltf", "IncorrectVertexArrays/Cube.gltf",
        "BoxWithInfinites-glTF-Binary/BoxWithInfinites.glb", "draco/2CylinderEngine.gltf"}) {
    SCOPED_TRACE(rel);
    expectRefused(d + "/" + rel);
  }
  EXPECT_NE(tryLoad(d + "/IndexOutOfRange/IndexOutOfRange.gltf").find("out of range"),
            std::string::npos);
  EXPECT_NE(tryLoad(d + "/RecursiveNodes/RecursiveNodes.gltf").find("cycle"), std::string::npos);
  EXPECT_NE(tryLoad(d + "/draco/2CylinderEngine.gltf").find("KHR_draco_mesh_compression"),
            std::string::npos);
}

TEST(SceneLoader, AssimpValidModelsLoad) {
  ASSERT_TRUE(fs::exists(kAssimpDir))
      << kAssimpDir << " is absent (tools/setup/install-deps.sh installs it)";
  const std::string d = kAssimpDir;
  Scene s;
  ASSERT_EQ(tryLoad(d + "/BoxTextured-glTF/BoxTextured.gltf", &s), "");
  EXPECT_EQ(s.staticTriangleCount(), 12u);
  ASSERT_EQ(s.textures.size(), 1u);
  EXPECT_TRUE(s.textures[0].srgb);
  EXPECT_EQ(s.textures[0].rgba8.size(), size_t(s.textures[0].width) * s.textures[0].height * 4);
  ASSERT_EQ(tryLoad(d + "/BoxTextured-glTF-Binary/BoxTextured.glb", &s), "");
  EXPECT_EQ(s.textures.size(), 1u);  // image from a GLB buffer view
  ASSERT_EQ(tryLoad(d + "/2CylinderEngine-glTF-Binary/2CylinderEngine.glb", &s), "");
  EXPECT_GT(s.staticTriangleCount(), 1000u);
  ASSERT_EQ(tryLoad(d + "/cameras/Cameras.gltf", &s), "");
  EXPECT_GE(s.fileCameraCount(), 1u);
  ASSERT_EQ(tryLoad(d + "/textureTransform/TextureTransformTest.gltf", &s), "");
  // Morph targets and skins: deforming dynamic meshes, without a warning.
  ASSERT_EQ(tryLoad(d + "/glTF-Sample-Models/AnimatedMorphCube-glTF/AnimatedMorphCube.gltf", &s),
            "");
  EXPECT_TRUE(s.warnings.empty());
  EXPECT_EQ(s.deformingTriangleCount(), 12u);
  ASSERT_EQ(tryLoad(d + "/simple_skin/simple_skin.gltf", &s), "");
  EXPECT_TRUE(s.warnings.empty());
  EXPECT_EQ(s.deformingTriangleCount(), 8u);
  ASSERT_EQ(s.skins.size(), 1u);
  // Non-triangle modes are skipped with a warning.
  ASSERT_EQ(tryLoad(d + "/glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_01.gltf", &s),
            "");
  EXPECT_EQ(s.staticTriangleCount(), 0u);
  EXPECT_EQ(s.warnings.size(), 1u);
}

TEST(SceneLoader, MissingEmptyAndNotGltf) {
  const std::string dir = test::tempDir("loader");
  expectRefused(dir + "/does-not-exist.gltf");
  expectRefused(dir);  // a folder
  std::ofstream(dir + "/empty.gltf").close();
  expectRefused(dir + "/empty.gltf");
  std::ofstream(dir + "/text.gltf") << "hello, I am not JSON\n";
  expectRefused(dir + "/text.gltf");
  std::ofstream(dir + "/array.gltf") << "[1, 2, 3]";
  expectRefused(dir + "/array.gltf");
  std::ofstream(dir + "/fake.glb") << "glTF\x02\x00\x00\x00garbage";
  expectRefused(dir + "/fake.glb");
}

// ---------------------------------------------------------------------------------------------
// Hand-written files

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

// Two triangles (a quad in z=0, indexed u16) in a data: buffer; tests edit `doc` to break it.
struct Quad {
  json doc;
  std::string bin;
  Quad() {
    const float pos[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    const uint16_t idx[] = {0, 1, 2, 0, 2, 3};
    bin.append(reinterpret_cast<const char*>(pos), sizeof pos);
    bin.append(reinterpret_cast<const char*>(idx), sizeof idx);
    doc = {{"asset", {{"version", "2.0"}}},
           {"scene", 0},
           {"scenes", {{{"nodes", {0}}}}},
           {"nodes", {{{"mesh", 0}, {"name", "quad"}}}},
           {"meshes",
            {{{"name", "Quad"},
              {"primitives", {{{"attributes", {{"POSITION", 0}}}, {"indices", 1}}}}}}},
           {"accessors",
            {{{"bufferView", 0}, {"componentType", 5126}, {"count", 4}, {"type", "VEC3"}},
             {{"bufferView", 1}, {"componentType", 5123}, {"count", 6}, {"type", "SCALAR"}}}},
           {"bufferViews",
            {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 48}},
             {{"buffer", 0}, {"byteOffset", 48}, {"byteLength", 12}}}}};
  }
  // Appends float data as an accessor of `count` elements of `type`; returns its index.
  int addFloats(const std::vector<float>& v, size_t count, const char* type) {
    doc["bufferViews"].push_back(
        {{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", v.size() * 4}});
    bin.append(reinterpret_cast<const char*>(v.data()), v.size() * 4);
    doc["accessors"].push_back({{"bufferView", doc["bufferViews"].size() - 1},
                                {"componentType", 5126},
                                {"count", count},
                                {"type", type}});
    return int(doc["accessors"].size() - 1);
  }
  // Texture 0: a 2x2 PNG in a data URI.
  void addTexture() {
    doc["images"] = {{{"uri",
                       "data:image/png;base64,iVBORw0KGgoAAAANSUhEUgAAAAIAAAACCAIAAAD91JpzAAAAEkl"
                       "EQVR4nGP4z8DAAMIM/4EAAB/uBfsL2WiLAAAAAElFTkSuQmCC"}}};
    doc["textures"] = {{{"source", 0}}};
  }
  void addNormals() {
    doc["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] =
        addFloats({0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}, 4, "VEC3");
  }
  std::string write(const std::string& name = "quad.gltf") {
    doc["buffers"] = {{{"byteLength", bin.size()},
                       {"uri", "data:application/octet-stream;base64," + base64(bin)}}};
    const std::string path = test::tempDir("quad") + "/" + name;
    std::ofstream(path) << doc.dump();
    return path;
  }
};

TEST(SceneLoader, QuadDefaultsAndFlatNormals) {
  Quad q;
  Scene s;
  ASSERT_EQ(tryLoad(q.write(), &s), "");
  EXPECT_EQ(s.staticTriangleCount(), 2u);
  ASSERT_EQ(s.materials.size(), 1u);  // the spec's default material
  EXPECT_FLOAT_EQ(s.materials[0].metallicFactor, 1.0f);
  EXPECT_FLOAT_EQ(s.materials[0].roughnessFactor, 1.0f);
  EXPECT_FLOAT_EQ(s.materials[0].ior, 1.5f);
  EXPECT_FALSE(s.materials[0].isEmissive());
  for (const auto& n : s.staticMesh.normals) EXPECT_EQ(n, glm::vec3(0.0f));  // no NORMAL: flat
  EXPECT_EQ(s.fileCameraCount(), 0u);
  EXPECT_EQ(s.cameras.size(), 1u);  // default
}

// An optional extension we do not support is named once in a warning; the file still loads.
TEST(SceneLoader, UnsupportedOptionalExtensionsAreNamedOnce) {
  Quad q;
  q.doc["extensionsUsed"] = {"KHR_materials_iridescence", "KHR_materials_ior", "EXT_foo"};
  Scene s;
  ASSERT_EQ(tryLoad(q.write(), &s), "");
  EXPECT_EQ(s.staticTriangleCount(), 2u);
  ASSERT_EQ(s.warnings.size(), 2u);
  EXPECT_NE(s.warnings[0].find("extension KHR_materials_iridescence is not supported"),
            std::string::npos)
      << s.warnings[0];
  EXPECT_NE(s.warnings[1].find("extension EXT_foo is not supported"), std::string::npos)
      << s.warnings[1];
}

// A transmission texture is not applied (the factor alone is): the user is told, once per
// material, rather than seeing opaque parts of a window rendered as clear glass unexplained.
TEST(SceneLoader, TransmissionTextureIsRead) {
  Quad q;
  q.doc["extensionsUsed"] = {"KHR_materials_transmission"};
  q.addTexture();
  q.doc["materials"] = {
      {{"name", "window"},
       {"extensions",
        {{"KHR_materials_transmission",
          {{"transmissionFactor", 1.0}, {"transmissionTexture", {{"index", 0}}}}}}}}};
  q.doc["meshes"][0]["primitives"][0]["material"] = 0;
  Scene s;
  ASSERT_EQ(tryLoad(q.write(), &s), "");
  ASSERT_EQ(s.materials.size(), 1u);
  EXPECT_FLOAT_EQ(s.materials[0].transmission, 1.0f);
  ASSERT_TRUE(s.materials[0].transmissionTexture.valid());
  EXPECT_EQ(s.materials[0].transmissionTexture.texture, 0);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
}

TEST(SceneLoader, InstancingAndMirroring) {
  Quad q;
  q.addNormals();
  q.doc["nodes"] = {{{"mesh", 0}, {"translation", {0, 0, 1}}},
                    {{"mesh", 0}, {"scale", {-1, 1, 1}}},  // mirrored: winding must flip
                    {{"mesh", 0}, {"extras", {{"dynamic", true}}}},
                    {{"mesh", 0}, {"extras", {{"dynamic", true}}}, {"translation", {5, 0, 0}}}};
  q.doc["scenes"] = {{{"nodes", {0, 1, 2, 3}}}};
  Scene s;
  ASSERT_EQ(tryLoad(q.write(), &s), "");
  EXPECT_EQ(s.staticTriangleCount(), 4u);
  EXPECT_EQ(s.dynamicMeshes.size(), 1u);  // shared by both dynamic instances
  EXPECT_EQ(s.instances.size(), 2u);
  EXPECT_EQ(s.dynamicTriangleCount(), 4u);
  EXPECT_NEAR(s.staticMesh.positions[0].z, 1.0f, 1e-6f);
  // Mirrored copy: geometric normal from the winding agrees with the shading normal.
  const auto& m = s.staticMesh;
  for (size_t t = 2; t < 4; ++t) {
    const glm::vec3 a = m.positions[m.indices[3 * t]], b = m.positions[m.indices[3 * t + 1]],
                    c = m.positions[m.indices[3 * t + 2]];
    const glm::vec3 ng = glm::cross(b - a, c - a);
    EXPECT_GT(glm::dot(ng, m.normals[m.indices[3 * t]]), 0.0f);
  }
  EXPECT_NEAR(glm::vec3(s.instanceTransform(1, 0.0)[3]).x, 5.0f, 1e-6f);
}

// glTF: a primitive without NORMAL is shaded flat and its TANGENT ignored. Its normals are zero
// (the device then shades by the geometric normal) wherever the mesh is placed; a primitive with
// NORMAL in the same mesh keeps its own, normalised, and its TANGENT.
TEST(SceneLoader, PrimitivesWithoutNormalAreFlat) {
  Quad q;
  const int nrm = q.addFloats({0, 0, 2, 0, 0, 2, 0, 0, 2, 0, 0, 2}, 4, "VEC3");
  const int tan = q.addFloats({0, 1, 0, -1, 0, 1, 0, -1, 0, 1, 0, -1, 0, 1, 0, -1}, 4, "VEC4");
  json& prims = q.doc["meshes"][0]["primitives"];
  prims[0]["attributes"]["TANGENT"] = tan;
  prims.push_back(
      {{"attributes", {{"POSITION", 0}, {"NORMAL", nrm}, {"TANGENT", tan}}}, {"indices", 1}});
  q.doc["nodes"] = {{{"mesh", 0}},
                    {{"mesh", 0}, {"scale", {-1, 1, 1}}},
                    {{"mesh", 0}, {"extras", {{"dynamic", true}}}}};
  q.doc["scenes"] = {{{"nodes", {0, 1, 2}}}};
  Scene s;
  ASSERT_EQ(tryLoad(q.write("flat.gltf"), &s), "");
  // Vertices 0-3 come from the primitive without NORMAL, 4-7 from the other; the static mesh
  // holds the plain copy, then the mirrored one.
  const TriangleMesh& m = s.staticMesh;
  ASSERT_EQ(m.vertexCount(), 16u);
  ASSERT_EQ(m.tangents.size(), 16u);
  for (size_t i = 0; i < 16; ++i)
    EXPECT_EQ(m.normals[i], i % 8 < 4 ? glm::vec3(0.0f) : glm::vec3(0, 0, 1)) << "vertex " << i;
  for (size_t i = 0; i < 4; ++i) {
    EXPECT_NE(glm::vec3(m.tangents[i]), glm::vec3(0, 1, 0)) << "ignored";
    EXPECT_EQ(m.tangents[4 + i], glm::vec4(0, 1, 0, -1)) << "given";
  }
  ASSERT_EQ(s.dynamicMeshes.size(), 1u);
  for (size_t i = 0; i < 8; ++i)
    EXPECT_EQ(s.dynamicMeshes[0].normals[i], i < 4 ? glm::vec3(0.0f) : glm::vec3(0, 0, 1));
  // What the device reads.
  const dev::ShadingVertex v = shadingVertex(m, 0);
  EXPECT_EQ(glm::vec3(v.nx, v.ny, v.nz), glm::vec3(0.0f));
}

// A deforming primitive without NORMAL stays flat: its targets' NORMAL deltas are ignored, and
// morphing (animated or applied once at load) and skinning keep its normals zero.
TEST(SceneLoader, DeformedPrimitivesWithoutNormalStayFlat) {
  const std::vector<glm::vec3> quad = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  const std::vector<uint32_t> idx = {0, 1, 2, 0, 2, 3};
  auto build = [&](bool skinned, bool animated) {
    test::GltfBuilder b;
    test::MeshAttributes a;
    a.targetPositions = {{{0, 0, 0}, {0, 0, 0}, {0, 0, 1}, {0, 0, 0}}};
    a.targetNormals = {std::vector<glm::vec3>(4, glm::vec3(1, 0, 0))};
    if (skinned) {
      a.joints.assign(4, {0, 0, 0, 0});
      a.weights.assign(4, glm::vec4(1, 0, 0, 0));
    }
    const int node = b.addNode(b.addMesh(quad, idx, b.addMaterial({}), a));
    if (animated) b.animateWeights(node, {0, 1}, {{0}, {1}});
    if (skinned) {
      const glm::quat turn = glm::angleAxis(1.0f, glm::normalize(glm::vec3(1, 2, 3)));
      const int joint = b.addNode(-1, glm::vec3(0), turn);
      b.addSkin(node, {joint});
      b.animateTranslation(joint, {0, 1}, {{0, 0, 0}, {1, 2, 3}});
    }
    return b.write(test::tempDir("flat-deform"), "m");
  };
  auto expectZero = [](const TriangleMesh& m) {
    ASSERT_EQ(m.normals.size(), 4u);
    for (const glm::vec3& n : m.normals) EXPECT_EQ(n, glm::vec3(0.0f));
  };
  for (bool skinned : {false, true}) {
    SCOPED_TRACE(skinned ? "skinned and morphed" : "morphed");
    const Scene s = loadScene(build(skinned, true), quiet());
    ASSERT_EQ(s.dynamicMeshes.size(), 1u);
    ASSERT_TRUE(s.meshDeforms(0));
    expectZero(s.dynamicMeshes[0]);
    TriangleMesh m = s.dynamicMeshes[0];
    s.deformMesh(0, 0.5, &m);
    // The target applies (vertex 2 rises by 0.5), then the joint's rigid turn and move.
    EXPECT_NEAR(glm::length(m.positions[2] - m.positions[1]), std::sqrt(1.25f), 1e-5f);
    expectZero(m);
  }
  // Weights nothing animates: applied once at load, into the static mesh.
  const std::string path = build(false, false);
  json doc;
  std::ifstream(path) >> doc;
  doc["meshes"][0]["weights"] = {0.5};
  std::ofstream(path) << doc.dump();
  const Scene s = loadScene(path, quiet());
  EXPECT_TRUE(s.dynamicMeshes.empty());
  EXPECT_NEAR(s.staticMesh.positions[2].z, 0.5f, 1e-6f);
  expectZero(s.staticMesh);
}

TEST(SceneLoader, MaterialsAndExtensions) {
  Quad q;
  q.doc["extensionsUsed"] = {"KHR_materials_emissive_strength", "KHR_materials_transmission",
                             "KHR_materials_ior", "KHR_texture_transform"};
  q.doc["materials"] = {
      {{"emissiveFactor", {1, 0.5, 0}},
       {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 4.0}}}}}},
      {{"extensions",
        {{"KHR_materials_transmission", {{"transmissionFactor", 1.0}}},
         {"KHR_materials_ior", {{"ior", 1.33}}}}},
       {"alphaMode", "MASK"},
       {"doubleSided", true}}};
  q.doc["meshes"][0]["primitives"][0]["material"] = 0;
  q.doc["meshes"].push_back(
      {{"primitives", {{{"attributes", {{"POSITION", 0}}}, {"material", 1}}}}});
  q.doc["nodes"].push_back({{"mesh", 1}});
  q.doc["scenes"][0]["nodes"] = {0, 1};
  Scene s;
  ASSERT_EQ(tryLoad(q.write(), &s), "");
  ASSERT_EQ(s.materials.size(), 2u);
  EXPECT_FLOAT_EQ(s.materials[0].emission().x, 4.0f);
  EXPECT_FLOAT_EQ(s.materials[0].emission().y, 2.0f);
  EXPECT_TRUE(s.materials[1].isDielectric());
  EXPECT_FLOAT_EQ(s.materials[1].ior, 1.33f);
  EXPECT_EQ(s.materials[1].alphaMode, AlphaMode::Mask);
  EXPECT_FLOAT_EQ(s.materials[1].alphaCutoff, 0.5f);
  EXPECT_TRUE(s.materials[1].doubleSided);
  EXPECT_EQ(s.emissiveTriangleCount(), 2u);
  EXPECT_EQ(s.staticTriangleCount(),
            3u);  // 4 vertices non-indexed: 1 triangle, one vertex left over
}

// KHR_texture_transform is read on every texture, not only the base colour's, and reaches the
// device material as one matrix per texture.
TEST(SceneLoader, TextureTransformOnEveryTexture) {
  Quad q;
  q.doc["extensionsUsed"] = {"KHR_texture_transform"};
  q.addTexture();
  const json mrTransform = {{"offset", {0.25, 0.5}}, {"scale", {2.0, 3.0}}};
  q.doc["materials"] = {
      {{"pbrMetallicRoughness",
        {{"metallicRoughnessTexture",
          {{"index", 0}, {"extensions", {{"KHR_texture_transform", mrTransform}}}}}}},
       {"emissiveFactor", {1, 1, 1}},
       {"emissiveTexture",
        {{"index", 0}, {"extensions", {{"KHR_texture_transform", {{"rotation", 1.5707963}}}}}}}}};
  q.doc["meshes"][0]["primitives"][0]["material"] = 0;
  Scene s;
  ASSERT_EQ(tryLoad(q.write(), &s), "");
  ASSERT_EQ(s.materials.size(), 1u);
  const Material& m = s.materials[0];
  EXPECT_EQ(m.metallicRoughnessTexture.offset, glm::vec2(0.25f, 0.5f));
  EXPECT_EQ(m.metallicRoughnessTexture.scale, glm::vec2(2.0f, 3.0f));
  EXPECT_NEAR(m.emissiveTexture.rotation, 1.5707963f, 1e-7f);
  const dev::Material d = toDeviceMaterial(m);
  const float mr[6] = {2, 0, 0.25f, 0, 3, 0.5f};
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(d.mr_uv[k], mr[k], 1e-6f) << k;
  const float em[6] = {0, 1, 0, -1, 0, 0};
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(d.emission_uv[k], em[k], 1e-6f) << k;
  const float id[6] = {1, 0, 0, 0, 1, 0};
  for (int k = 0; k < 6; ++k) EXPECT_EQ(d.base_uv[k], id[k]) << k;
  // A broken transform on any texture is refused, naming that texture.
  q.doc["materials"][0]["emissiveTexture"]["extensions"]["KHR_texture_transform"]["scale"] = {1};
  const std::string err = tryLoad(q.write("broken.gltf"), &s);
  EXPECT_NE(err.find("emissiveTexture"), std::string::npos) << err;
  EXPECT_NE(err.find("scale must be 2 finite numbers"), std::string::npos) << err;
}

// KHR_materials_specular (over KHR_materials_ior) and KHR_materials_clearcoat reach the
// device material; their textures are named in a warning; bad factors are refused.
TEST(SceneLoader, SpecularAndClearcoat) {
  Quad q;
  q.doc["extensionsUsed"] = {"KHR_materials_specular", "KHR_materials_clearcoat",
                             "KHR_materials_ior"};
  q.doc["materials"] = {{{"extensions",
                          {{"KHR_materials_specular",
                            {{"specularFactor", 0.5}, {"specularColorFactor", {1.0, 0.5, 40.0}}}},
                           {"KHR_materials_ior", {{"ior", 2.0}}},
                           {"KHR_materials_clearcoat",
                            {{"clearcoatFactor", 0.8},
                             {"clearcoatRoughnessFactor", 0.1},
                             {"clearcoatTexture", {{"index", 0}}}}}}}}};
  q.doc["meshes"][0]["primitives"][0]["material"] = 0;
  q.addTexture();
  Scene s;
  ASSERT_EQ(tryLoad(q.write(), &s), "");
  EXPECT_TRUE(s.warnings.empty());
  const dev::Material d = toDeviceMaterial(s.materials[0]);
  // ((2 - 1) / (2 + 1))^2 = 1/9 times the colour; the kernel clamps at 1 after the texture and
  // multiplies by the factor (F90).
  EXPECT_NEAR(d.spec_f0[0], 1.0f / 9.0f, 1e-6f);
  EXPECT_NEAR(d.spec_f0[1], 0.5f / 9.0f, 1e-6f);
  EXPECT_NEAR(d.spec_f0[2], 40.0f / 9.0f, 1e-5f);
  EXPECT_FLOAT_EQ(d.spec_f90, 0.5f);
  EXPECT_FLOAT_EQ(d.coat, 0.8f);
  EXPECT_FLOAT_EQ(d.coat_roughness, 0.1f);
  EXPECT_EQ(d.coat_texture, 0);  // linear: a texture of its own besides any sRGB use
  EXPECT_EQ(d.spec_texture, PR_NO_TEXTURE);
  EXPECT_FALSE(s.textures[0].srgb);
  // Defaults: F0 0.04 exactly (times F90 1), no coat.
  const dev::Material plain = toDeviceMaterial(Material{});
  EXPECT_EQ(plain.spec_f0[0], 0.04f);
  EXPECT_EQ(plain.spec_f90, 1.0f);
  EXPECT_EQ(plain.coat, 0.0f);
  q.doc["materials"][0]["extensions"]["KHR_materials_clearcoat"]["clearcoatTexture"]["index"] = 7;
  EXPECT_NE(tryLoad(q.write("bad0.gltf")).find("clearcoatTexture refers to texture 7"),
            std::string::npos);
  q.doc["materials"][0]["extensions"]["KHR_materials_clearcoat"]["clearcoatTexture"]["index"] = 0;
  q.doc["materials"][0]["extensions"]["KHR_materials_clearcoat"]["clearcoatFactor"] = 1.5;
  EXPECT_NE(tryLoad(q.write("bad.gltf")).find("KHR_materials_clearcoat clearcoatFactor"),
            std::string::npos);
  q.doc["materials"][0]["extensions"]["KHR_materials_clearcoat"]["clearcoatFactor"] = 0.5;
  q.doc["materials"][0]["extensions"]["KHR_materials_specular"]["specularColorFactor"] = {1, -1, 1};
  EXPECT_NE(tryLoad(q.write("bad2.gltf")).find("specularColorFactor must be 3 numbers >= 0"),
            std::string::npos);
}

TEST(SceneLoader, TextureTransformMath) {
  TextureRef r;
  r.offset = {0.5f, 0.0f};
  r.scale = {2.0f, 2.0f};
  r.rotation = 1.5707963f;  // the extension's rotation: (u,v) -> (v, -u) before the offset
  const glm::vec2 uv = r.apply({1.0f, 0.0f});
  EXPECT_NEAR(uv.x, 0.5f, 1e-5f);
  EXPECT_NEAR(uv.y, -2.0f, 1e-5f);
}

TEST(SceneLoader, PunctualLightsAndCameras) {
  Quad q;
  q.doc["extensionsUsed"] = {"KHR_lights_punctual"};
  q.doc["extensions"] = {
      {"KHR_lights_punctual",
       {{"lights",
         {{{"type", "spot"},
           {"intensity", 100},
           {"spot", {{"innerConeAngle", 0.1}, {"outerConeAngle", 0.5}}}},
          {{"type", "directional"}, {"color", {1, 0.9, 0.8}}, {"intensity", 3}}}}}}};
  q.doc["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", 0.8}, {"znear", 0.1}}}},
                      {{"type", "orthographic"},
                       {"orthographic", {{"xmag", 1}, {"ymag", 1}, {"znear", 0}, {"zfar", 10}}}}};
  q.doc["nodes"] = {
      {{"mesh", 0}},
      {{"translation", {0, 2, 0}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}},
      {{"rotation", {-0.7071068, 0, 0, 0.7071068}},
       {"extensions", {{"KHR_lights_punctual", {{"light", 1}}}}}},
      {{"camera", 0}, {"translation", {0, 0, 10}}},
      {{"camera", 1}}};
  q.doc["scenes"][0]["nodes"] = {0, 1, 2, 3, 4};
  Scene s;
  ASSERT_EQ(tryLoad(q.write(), &s), "");
  ASSERT_EQ(s.lights.size(), 2u);
  EXPECT_EQ(s.lights[0].type, LightType::Spot);
  EXPECT_FALSE(s.lights[0].dynamic);
  const PunctualLight spot = s.lightAt(0, 0.0);
  EXPECT_NEAR(spot.position.y, 2.0f, 1e-6f);
  EXPECT_NEAR(spot.direction.z, -1.0f, 1e-6f);
  const PunctualLight sun = s.lightAt(1, 0.0);  // -90 degrees about X: -Z turns to -Y
  EXPECT_NEAR(sun.direction.y, -1.0f, 1e-5f);
  EXPECT_FLOAT_EQ(sun.intensity, 3.0f);
  ASSERT_EQ(s.cameras.size(), 2u);
  EXPECT_TRUE(s.cameras[0].perspective);
  EXPECT_FALSE(s.cameras[1].perspective);  // loads; render refuses it
  const CameraPose cam = s.cameraAt(0, 0.0);
  EXPECT_NEAR(cam.position.z, 10.0f, 1e-6f);
  EXPECT_NEAR(cam.up.y, 1.0f, 1e-6f);
  EXPECT_FLOAT_EQ(cam.yfov, 0.8f);
  // Bad cone angles are refused.
  q.doc["extensions"]["KHR_lights_punctual"]["lights"][0]["spot"]["innerConeAngle"] = 0.6;
  expectRefused(q.write());
}

struct BrokenQuad {
  const char* name;
  std::function<void(Quad&)> edit;
  const char* expected;  // part of the message
};

// Each edit breaks the quad in one way.
std::vector<BrokenQuad> brokenQuads() {
  return {
      {"accessor past view", [](Quad& q) { q.doc["accessors"][0]["count"] = 5; },
       "reads past the end of bufferView 0"},
      {"view past buffer", [](Quad& q) { q.doc["bufferViews"][1]["byteLength"] = 100; },
       "past the end of buffer"},
      {"bad stride", [](Quad& q) { q.doc["bufferViews"][0]["byteStride"] = 6; }, "byteStride"},
      {"stride too small", [](Quad& q) { q.doc["bufferViews"][0]["byteStride"] = 8; },
       "byteStride"},
      {"index out of range", [](Quad& q) { q.bin[48] = 9; }, "out of range"},
      {"position type",
       [](Quad& q) {
         q.doc["accessors"][0]["type"] = "VEC4";
         q.doc["accessors"][0]["count"] = 3;
       },
       "POSITION"},
      {"float indices",
       [](Quad& q) {
         q.doc["accessors"][1]["componentType"] = 5126;
         q.doc["accessors"][1]["count"] = 3;
       },
       "indices"},
      {"missing accessor", [](Quad& q) { q.doc["meshes"][0]["primitives"][0]["indices"] = 7; },
       "indices"},
      {"missing mesh", [](Quad& q) { q.doc["nodes"][0]["mesh"] = 3; }, "mesh 3"},
      {"missing material", [](Quad& q) { q.doc["meshes"][0]["primitives"][0]["material"] = 2; },
       "material 2"},
      {"missing node", [](Quad& q) { q.doc["scenes"][0]["nodes"] = {4}; }, "node 4"},
      {"missing scene", [](Quad& q) { q.doc["scene"] = 3; }, "scene"},
      {"two parents",
       [](Quad& q) {
         q.doc["nodes"] = {{{"children", {2}}}, {{"children", {2}}}, {{"mesh", 0}}};
         q.doc["scenes"][0]["nodes"] = {0, 1};
       },
       "two parents"},
      {"self child", [](Quad& q) { q.doc["nodes"][0]["children"] = {0}; }, "own child"},
      {"nan translation",
       [](Quad& q) {
         q.doc["nodes"][0]["translation"] = {0, 1e39, 0};
       },
       "not finite"},
      {"version 3", [](Quad& q) { q.doc["asset"]["version"] = "3.0"; }, "version"},
      {"required ext", [](Quad& q) { q.doc["extensionsRequired"] = {"EXT_meshopt_compression"}; },
       "EXT_meshopt"},
      {"negative strength",
       [](Quad& q) {
         q.doc["materials"] = {
             {{"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", -1}}}}}}};
       },
       "emissiveStrength"},
      {"emission overflows",
       [](Quad& q) {
         q.doc["materials"] = {
             {{"emissiveFactor", {1e38, 1, 1}},
              {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 3e38}}}}}}};
       },
       "emitted radiance"},
      {"zero ior",
       [](Quad& q) {
         q.doc["materials"] = {{{"extensions", {{"KHR_materials_ior", {{"ior", 0}}}}}}};
       },
       "ior"},
      {"bad texture",
       [](Quad& q) {
         q.doc["materials"] = {{{"emissiveTexture", {{"index", 0}}}}};
       },
       "texture 0"},
      {"sparse out of range",
       [](Quad& q) {
         q.doc["accessors"][0]["sparse"] = {
             {"count", 1},
             {"indices", {{"bufferView", 1}, {"componentType", 5123}}},
             {"values", {{"bufferView", 0}}}};
         q.bin[48] = 7;  // sparse index 7 >= count 4
       },
       "sparse"},
      {"animation target",
       [](Quad& q) {
         json a = {
             {"samplers", json::array({json{{"input", 1}, {"output", 0}}})},
             {"channels", json::array({json{{"sampler", 0},
                                            {"target", {{"node", 9}, {"path", "translation"}}}}})}};
         q.doc["animations"] = json::array({a});
       },
       "node 9"},
      {"animation sampler",
       [](Quad& q) {
         json a = {
             {"samplers", json::array()},
             {"channels", json::array({json{{"sampler", 0},
                                            {"target", {{"node", 0}, {"path", "translation"}}}}})}};
         q.doc["animations"] = json::array({a});
       },
       "sampler 0"},
      {"camera ref", [](Quad& q) { q.doc["nodes"][0]["camera"] = 0; }, "camera 0"},
      {"light ref",
       [](Quad& q) {
         q.doc["nodes"][0]["extensions"] = {{"KHR_lights_punctual", {{"light", 0}}}};
       },
       "light 0"},
  };
}

// Each broken quad must be refused with one line naming the file.
TEST(SceneLoader, BrokenQuadsAreRefused) {
  for (const BrokenQuad& c : brokenQuads()) {
    SCOPED_TRACE(c.name);
    Quad q;
    c.edit(q);
    const std::string path = q.write(std::string(c.name) + ".gltf");
    const std::string msg = tryLoad(path);
    ASSERT_FALSE(msg.empty());
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    EXPECT_EQ(msg.rfind(path + ": ", 0), 0u) << msg;
    EXPECT_NE(msg.find(c.expected), std::string::npos) << msg;
  }
}

TEST(SceneLoader, ValidFileWithNothingToRenderLoads) {
  const std::string path = test::tempDir("empty") + "/nothing.gltf";
  std::ofstream(path) << R"({"asset": {"version": "2.0"}})";
  Scene s;
  ASSERT_EQ(tryLoad(path, &s), "");
  EXPECT_EQ(s.staticTriangleCount() + s.dynamicTriangleCount(), 0u);
  EXPECT_TRUE(s.bounds.empty());
}

}  // namespace
}  // namespace pr
