// Emission textures in the lights' power (scene/emission_power.h): a triangle's selection
// weight follows the texels it shows, a triangle whose texels are all black is no light, and the
// image is the same as where that triangle emits nothing at all.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>

#include <nlohmann/json.hpp>
#include <stb_image_write.h>

#include "io/image.h"
#include "scene/emission_power.h"
#include "support/gltf_builder.h"
#include "support/render_helpers.h"
#include "support/test_env.h"

namespace pr {
namespace {

constexpr int kTexels = 16;

// A 16 x 16 texture whose left half is black and right half white.
std::vector<uint8_t> halfWhite() {
  std::vector<uint8_t> rgba(kTexels * kTexels * 4, 255);
  for (int y = 0; y < kTexels; ++y)
    for (int x = 0; x < kTexels / 2; ++x)
      for (int c = 0; c < 3; ++c) rgba[(y * kTexels + x) * 4 + c] = 0;
  return rgba;
}

Scene halfWhiteScene() {
  Scene s;
  Texture t;
  t.width = t.height = kTexels;
  t.rgba8 = halfWhite();
  t.srgb = true;
  s.textures.push_back(t);
  Material m;
  m.emissiveFactor = glm::vec3(1.0f, 0.5f, 0.25f);
  m.emissiveTexture.texture = 0;
  s.materials.push_back(m);
  Material plain;
  plain.emissiveFactor = glm::vec3(2.0f);
  s.materials.push_back(plain);
  return s;
}

std::array<glm::vec2, 3> uvTriangle(float u0, float u1) {
  return {glm::vec2(u0, 0.2f), glm::vec2(u1, 0.2f), glm::vec2(u1, 0.8f)};
}

TEST(EmissionShares, FollowTheTexelsATriangleShows) {
  const Scene scene = halfWhiteScene();
  const EmissionShares shares(scene);
  EXPECT_EQ(shares.share(0, uvTriangle(0.1f, 0.4f)), 0.0f);  // black, and its neighbours too
  EXPECT_FLOAT_EQ(shares.share(0, uvTriangle(0.6f, 0.9f)), 1.0f);
  const float across = shares.share(0, uvTriangle(0.25f, 0.75f));
  EXPECT_GT(across, 0.2f);
  EXPECT_LT(across, 0.8f);
  // Within a texel of the black half's edge a bilinear lookup reads white: still a light.
  EXPECT_GT(shares.share(0, uvTriangle(0.1f, 0.47f)), 0.0f);
  // Repeat: u just past 1 reads the black texels' left neighbours, the white column at 15/16.
  EXPECT_GT(shares.share(0, uvTriangle(1.01f, 1.2f)), 0.0f);
  // A triangle spanning the texture many times over: the texture's mean.
  EXPECT_NEAR(shares.share(0, uvTriangle(-300.0f, 300.0f)), 0.5f, 1e-5f);
  EXPECT_EQ(shares.share(1, uvTriangle(0.1f, 0.4f)), 1.0f);  // no texture
}

// A white floor under a panel of two quads facing it. With `textured`, both quads emit through
// the half-white texture, the left one from its black half; else the left quad emits nothing
// and the right one emits white.
std::string panelScene(bool textured, const std::string& tag) {
  test::GltfBuilder b;
  test::MaterialSpec floor;
  floor.baseColor = glm::vec4(0.8f, 0.8f, 0.8f, 1.0f);
  const int f = b.addMaterial(floor);
  b.addNode(b.addQuad({-2, 0, -2}, {-2, 0, 2}, {2, 0, 2}, {2, 0, -2}, f));
  test::MaterialSpec panel;
  panel.baseColor = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
  panel.metallic = 1.0f;
  panel.emissive = glm::vec3(1.0f);
  panel.emissiveStrength = 4.0f;
  const int lit = b.addMaterial(panel);
  test::MaterialSpec dark = panel;
  dark.emissive = glm::vec3(0.0f);
  const int off = b.addMaterial(dark);
  // Facing down; u across x, v along z.
  auto quad = [&](float x0, float x1, float u0, float u1, int material) {
    test::MeshAttributes a;
    a.uvs = {{u0, 0.2f}, {u0, 0.8f}, {u1, 0.8f}, {u1, 0.2f}};
    b.addNode(b.addMesh({{x0, 1.5f, -0.5f}, {x0, 1.5f, 0.5f}, {x1, 1.5f, 0.5f}, {x1, 1.5f, -0.5f}},
                        {0, 2, 1, 0, 3, 2}, material, a));
  };
  quad(-1.0f, 0.0f, 0.1f, 0.4f, textured ? lit : off);
  quad(0.0f, 1.0f, 0.6f, 0.9f, lit);
  b.addCamera({0, 3, 4}, {0, 0, 0}, 0.7f, 1.0f);
  const std::string dir = test::tempDir(tag);
  const std::string path = b.write(dir, "panel");
  stbi_write_png((dir + "/half.png").c_str(), kTexels, kTexels, 4, halfWhite().data(), kTexels * 4);
  nlohmann::json doc = nlohmann::json::parse(std::ifstream(path));
  doc["images"] = {{{"uri", "half.png"}}};
  doc["samplers"] = {{{"magFilter", 9729}, {"minFilter", 9729}}};
  doc["textures"] = {{{"source", 0}, {"sampler", 0}}};
  if (textured) doc["materials"][lit]["emissiveTexture"] = {{"index", 0}};
  std::ofstream(path) << doc.dump();
  return path;
}

// The panel's black half is no light: the light table holds the white quad's two triangles, and
// the image converges to the one where the black quad emits nothing (region by region, in both
// modes).
TEST(EmissionTexture, BlackTrianglesAreNoLightsAndTheImageConverges) {
  const std::string textured = panelScene(true, "panel-textured");
  const std::string plain = panelScene(false, "panel-plain");
  for (const std::string& scene : {textured, plain}) {
    const auto info = test::runPathreuse("info '" + scene + "'");
    ASSERT_EQ(info.exitCode, 0) << info.err;
    EXPECT_NE(info.out.find("lights:     2 emissive triangles"), std::string::npos) << info.out;
  }
  for (const char* mode : {"pathtrace", "reuse"}) {
    SCOPED_TRACE(mode);
    const std::string args =
        std::string("--width 32 --height 32 --spp 256 --env none --mode ") + mode;
    const Image a = test::frameImage(test::renderFrames(textured, "0", args, "panel-a"), 0);
    const Image b = test::frameImage(test::renderFrames(plain, "0", args, "panel-b"), 0);
    for (int ry = 0; ry < 2; ++ry)
      for (int rx = 0; rx < 2; ++rx) {
        const test::Moments ma =
            test::regionMean(a, 16 * rx, 16 * ry, 16 * rx + 16, 16 * ry + 16, 1);
        const test::Moments mb =
            test::regionMean(b, 16 * rx, 16 * ry, 16 * rx + 16, 16 * ry + 16, 1);
        EXPECT_GT(mb.mean, 0.0) << rx << "," << ry;
        EXPECT_NEAR(ma.mean, mb.mean, 4.0 * std::hypot(ma.stderr_, mb.stderr_) + 1e-6)
            << "region " << rx << "," << ry;
      }
  }
}

// The panel of panelScene made of one material "panel" whose base colour is the half-white
// texture times (1, 0.5, 0.25): with `emissive` it also emits that, at strength 4, as glTF says
// it; else it emits nothing of its own.
std::string baseColourPanel(bool emissive, const std::string& tag) {
  const std::string path = panelScene(true, tag);
  nlohmann::json doc = nlohmann::json::parse(std::ifstream(path));
  nlohmann::json& panel = doc["materials"][1];
  panel["name"] = "panel";
  panel["pbrMetallicRoughness"] = {{"baseColorFactor", {1.0, 0.5, 0.25, 1.0}},
                                   {"baseColorTexture", {{"index", 0}}},
                                   {"metallicFactor", 0.0},
                                   {"roughnessFactor", 1.0}};
  panel.erase("extensions");
  panel.erase("emissiveFactor");
  panel.erase("emissiveTexture");
  if (emissive) {
    panel["emissiveFactor"] = {1.0, 0.5, 0.25};
    panel["emissiveTexture"] = {{"index", 0}};
    panel["extensions"] = {{"KHR_materials_emissive_strength", {{"emissiveStrength", 4.0}}}};
  }
  doc["materials"][2] = panel;  // the left quad: the same material under another index
  doc["materials"][2]["name"] = "panel-left";
  std::ofstream(path) << doc.dump();
  return path;
}

// --emit-base-color: a material named by name, index or range emits its base colour (factor and
// texture) at --emit-strength, the same frame as where the file says so; an unknown name is a
// one-line error, exit 2, with nothing written.
TEST(EmissionTexture, EmitBaseColorLightsWhatTheFileLeavesUnlit) {
  const std::string emissive = baseColourPanel(true, "emit-file");
  const std::string unlit = baseColourPanel(false, "emit-option");
  for (const char* mode : {"pathtrace", "reuse"}) {
    SCOPED_TRACE(mode);
    const std::string args =
        std::string("--width 24 --height 24 --spp 4 --env none --mode ") + mode;
    const Image want = test::frameImage(test::renderFrames(emissive, "0", args, "emit-want"), 0);
    EXPECT_GT(test::regionMean(want, 0, 0, 24, 24, 0).mean, 0.01) << "an unlit reference";
    for (const char* which : {"panel,panel-left", "1,2", "1-2"}) {
      SCOPED_TRACE(which);
      const Image got = test::frameImage(
          test::renderFrames(
              unlit, "0", args + " --emit-base-color " + which + " --emit-strength 4", "emit-got"),
          0);
      EXPECT_EQ(got.rgba, want.rgba);
    }
    // Not asked: the panel is dark and nothing lights the floor.
    const Image dark = test::frameImage(test::renderFrames(unlit, "0", args, "emit-none"), 0);
    EXPECT_EQ(test::regionMean(dark, 0, 0, 24, 24, 0).mean, 0.0);
  }
  const std::string out = test::tempDir("emit-bad");
  for (const char* bad : {"nosuch", "1-9", "1,"}) {
    SCOPED_TRACE(bad);
    const test::CommandResult r =
        test::runPathreuse("render '" + unlit + "' --emit-base-color '" + bad +
                           "' --frames 0 --out " + out + "/f_%04d.exr");
    EXPECT_EQ(r.exitCode, 2) << r.err;
    EXPECT_NE(r.err.find(unlit + ": --emit-base-color"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("materials: 0, 1 (panel), 2 (panel-left)"), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(std::ifstream(out + "/f_0000.exr").good());
  }
}

}  // namespace
}  // namespace pr
