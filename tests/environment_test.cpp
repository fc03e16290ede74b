// The environment light: its sampling tables and pdf on the host (the code the kernels run),
// reading .exr and .hdr maps, and renders: a convex Lambert box in a uniform environment shows
// its albedo, reuse converges to the path tracer under a map, reuse equals retrace with one,
// --env-rotate turns the map the documented way, and the options' errors.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <random>

#include <nlohmann/json.hpp>
#include <stb_image_write.h>

#include "io/image.h"
#include "portability/compare.h"
#include "render/options.h"
#include "scene/environment_map.h"
#include "scene/gltf_loader.h"
#include "shared/environment.h"
#include "support/chi_square.h"
#include "support/gltf_builder.h"
#include "support/render_helpers.h"
#include "support/test_env.h"
#include "util/error.h"

namespace pr {
namespace {

// A map with a bright spot (a "sun") and a sky that brightens towards +Y.
Environment testMap(int w, int h, int sunX, int sunY) {
  Environment e;
  e.width = w;
  e.height = h;
  e.rgb.resize(size_t(w) * h * 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float* p = &e.rgb[3 * (size_t(y) * w + x)];
      const float sky = 0.2f + 0.8f * float(h - y) / float(h);
      p[0] = 0.5f * sky, p[1] = 0.7f * sky, p[2] = sky;
      if (x == sunX && y == sunY) p[0] = 60.0f, p[1] = 50.0f, p[2] = 40.0f;
    }
  return e;
}

struct DeviceEnv {
  dev::Light light{};
  std::vector<float> data;
  explicit DeviceEnv(const Environment& e, float rotation = 0.0f) {
    float mean = 0.0f;
    data = environmentTables(e, &mean);
    light.type = PR_LIGHT_ENV;
    light.inst = uint32_t(e.width);
    light.prim = uint32_t(e.height);
    light.p0x = std::cos(rotation);
    light.p0y = std::sin(rotation);
    light.le_r = light.le_g = light.le_b = 1.0f;
    light.area = mean;
  }
};

TEST(Environment, SampledDirectionsHaveThePdfAndRadianceTheLookupsGive) {
  const DeviceEnv env(testMap(16, 8, 11, 2), 0.7f);
  std::mt19937 gen(5);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  int checked = 0;
  for (int i = 0; i < 4000; ++i) {
    dev::float3 dir, le;
    float pdf;
    if (!dev::env_sample(&env.light, env.data.data(), u(gen), u(gen), &dir, &pdf, &le)) continue;
    ASSERT_NEAR(dev::length(dir), 1.0f, 1e-5f);
    const float again = dev::env_pdf(&env.light, env.data.data(), dir);
    const dev::float3 look = dev::env_radiance(&env.light, env.data.data(), dir);
    // A direction on a texel boundary may look up its neighbour; the rest must agree.
    if (std::fabs(again - pdf) > 1e-3f * pdf) continue;
    EXPECT_NEAR(look.x, le.x, 1e-5f * le.x);
    ++checked;
  }
  EXPECT_GT(checked, 3950);
}

TEST(Environment, ImportanceSamplingEstimatesTheMapsIntegral) {
  const Environment map = testMap(32, 16, 20, 5);
  const DeviceEnv env(map);
  // Exact: each texel's luminance times its solid angle.
  double exact = 0.0;
  for (int y = 0; y < map.height; ++y) {
    const double omega = 2.0 * M_PI / map.width *
                         (std::cos(M_PI * y / map.height) - std::cos(M_PI * (y + 1) / map.height));
    for (int x = 0; x < map.width; ++x) {
      const float* p = &map.rgb[3 * (size_t(y) * map.width + x)];
      exact += (0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]) * omega;
    }
  }
  std::mt19937 gen(9);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const int n = 200000;
  double sum = 0.0, sum2 = 0.0;
  for (int i = 0; i < n; ++i) {
    dev::float3 dir, le;
    float pdf;
    double est = 0.0;
    if (dev::env_sample(&env.light, env.data.data(), u(gen), u(gen), &dir, &pdf, &le))
      est = (0.2126 * le.x + 0.7152 * le.y + 0.0722 * le.z) / pdf;
    sum += est;
    sum2 += est * est;
  }
  const double mean = sum / n, se = std::sqrt(std::max(0.0, sum2 / n - mean * mean) / n);
  EXPECT_NEAR(mean, exact, 4.5 * se + 1e-4 * exact) << "se " << se;
  // Importance sampling by luminance: far less noise than the sun alone would give uniformly.
  EXPECT_LT(se, 0.01 * exact);
  // The same estimate from directions uniform on the sphere: at least 5x the error (its
  // standard error over the importance-sampled one).
  double usum = 0.0, usum2 = 0.0;
  for (int i = 0; i < n; ++i) {
    const float z = 1.0f - 2.0f * u(gen), phi = 2.0f * float(M_PI) * u(gen);
    const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    const dev::float3 le = dev::env_radiance(
        &env.light, env.data.data(), dev::make_float3(r * std::cos(phi), z, r * std::sin(phi)));
    const double est = (0.2126 * le.x + 0.7152 * le.y + 0.0722 * le.z) * 4.0 * M_PI;
    usum += est;
    usum2 += est * est;
  }
  const double umean = usum / n, use = std::sqrt(std::max(0.0, usum2 / n - umean * umean) / n);
  EXPECT_NEAR(umean, exact, 4.5 * use);
  EXPECT_GT(use, 5.0 * se) << "uniform " << use << ", importance " << se;
}

TEST(Environment, DirectionsFollowTheTexelProbabilities) {
  const Environment map = testMap(8, 4, 5, 1);
  const DeviceEnv env(map, -1.1f);
  const size_t w = 8, h = 4;
  const float* marg = env.data.data() + 3 * w * h + h * (w + 1);
  std::vector<double> expected(w * h), observed(w * h, 0.0);
  const int n = 100000;
  for (size_t j = 0; j < h; ++j)
    for (size_t i = 0; i < w; ++i) {
      const float* cond = env.data.data() + 3 * w * h + j * (w + 1);
      expected[j * w + i] = n * double(marg[j + 1] - marg[j]) * double(cond[i + 1] - cond[i]);
    }
  std::mt19937 gen(13);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int k = 0; k < n; ++k) {
    dev::float3 dir, le;
    float pdf;
    ASSERT_TRUE(dev::env_sample(&env.light, env.data.data(), u(gen), u(gen), &dir, &pdf, &le));
    const dev::float2 uv = dev::env_uv_of(dev::env_to_map(&env.light, dir));
    observed[dev::env_texel_index(uv.y, h) * w + dev::env_texel_index(uv.x, w)] += 1.0;
  }
  EXPECT_GT(test::chiSquarePValue(observed, expected), 1e-4);
}

TEST(Environment, TurningAbouYMovesTheMapTowardsSmallerU) {
  // World = R(a) map: the map's -Z (u = 0.5) appears, turned by +90 degrees, along -X
  // (u = 0.25), counter-clockwise seen from above.
  Environment e = testMap(4, 2, 2, 0);  // the sun in the column of u = 0.5 .. 0.75
  const DeviceEnv env(e, float(M_PI / 2));
  const dev::float3 sunMap = dev::env_dir_of(0.625f, 0.25f);
  const dev::float3 world = dev::env_to_world(&env.light, sunMap);
  const dev::float2 uv = dev::env_uv_of(world);
  EXPECT_NEAR(uv.x, 0.375f, 1e-5f);
  EXPECT_GT(dev::env_radiance(&env.light, env.data.data(), world).x, 50.0f);
}

// ---------------------------------------------------------------------------------------------
// Files

TEST(Environment, ReadsExrAndRadianceHdr) {
  const std::string dir = test::tempDir("envfiles");
  Image img(4, 2);
  for (int i = 0; i < 8; ++i) {
    img.rgba[4 * i] = 0.25f * i;
    img.rgba[4 * i + 1] = 2.0f;
    img.rgba[4 * i + 2] = 0.5f;
    img.rgba[4 * i + 3] = 1.0f;
  }
  writeExr(dir + "/map.exr", img, ExrPixels::Float);
  const Environment e = loadEnvironment(dir + "/map.exr");
  ASSERT_EQ(e.width, 4);
  ASSERT_EQ(e.height, 2);
  EXPECT_FLOAT_EQ(e.rgb[3 * 5], 1.25f);
  EXPECT_FLOAT_EQ(e.rgb[3 * 5 + 1], 2.0f);
  // Radiance RGBE, flat scanlines: (1, 0.5, 0.25) is mantissas (128, 64, 32), exponent 129.
  {
    std::ofstream f(dir + "/map.hdr", std::ios::binary);
    f << "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 2\n";
    const unsigned char px[8] = {128, 64, 32, 129, 128, 128, 128, 128};
    f.write(reinterpret_cast<const char*>(px), 8);
  }
  const Environment r = loadEnvironment(dir + "/map.hdr");
  ASSERT_EQ(r.width, 2);
  ASSERT_EQ(r.height, 1);
  EXPECT_NEAR(r.rgb[0], 1.0f, 0.01f);
  EXPECT_NEAR(r.rgb[1], 0.5f, 0.01f);
  EXPECT_NEAR(r.rgb[2], 0.25f, 0.01f);
  auto refused = [&](const std::string& path, const std::string& what) {
    try {
      loadEnvironment(path);
      ADD_FAILURE() << path << " loaded";
    } catch (const InputError& ex) {
      const std::string m = ex.what();
      EXPECT_NE(m.find(path), std::string::npos) << m;
      EXPECT_NE(m.find(what), std::string::npos) << m;
      EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    }
  };
  refused(dir + "/missing.exr", "missing.exr");
  refused(dir + "/map.png", "must be .exr or .hdr");
  { std::ofstream(dir + "/bad.hdr") << "not a radiance file"; }
  refused(dir + "/bad.hdr", "cannot read the environment map");
  img.rgba[4] = -1.0f;
  writeExr(dir + "/negative.exr", img, ExrPixels::Float);
  refused(dir + "/negative.exr", "negative or non-finite");
}

TEST(Environment, ColoursParseOrAreRefused) {
  float c[3];
  parseColor("0.5,1,2e1", c);
  EXPECT_FLOAT_EQ(c[2], 20.0f);
  for (const char* bad : {"1,2", "1,2,3,4", "a,b,c", "1,-1,1", "1,,1", "nan,1,1", ""}) {
    EXPECT_THROW(parseColor(bad, c), InputError) << bad;
  }
}

// ---------------------------------------------------------------------------------------------
// Renders

// The path tracer and reuse render `scene` (frame 0, 24 x 24) with `args`; in every 8 x 8
// region and each of `channels`, their means agree within 4.5 standard errors.
void expectModesAgree(const std::string& scene, const std::string& args,
                      std::initializer_list<int> channels, const std::string& tag) {
  const Image pt = test::frameImage(
      test::renderFrames(scene, "0", "--mode pathtrace --width 24 --height 24" + args, tag + "pt"),
      0);
  const Image re = test::frameImage(
      test::renderFrames(scene, "0", "--mode reuse --width 24 --height 24" + args, tag + "re"), 0);
  for (int c : channels)
    for (int y0 = 0; y0 < 24; y0 += 8)
      for (int x0 = 0; x0 < 24; x0 += 8) {
        const test::Moments a = test::regionMean(pt, x0, y0, x0 + 8, y0 + 8, c);
        const test::Moments b = test::regionMean(re, x0, y0, x0 + 8, y0 + 8, c);
        EXPECT_NEAR(a.mean, b.mean, 4.5 * std::hypot(a.stderr_, b.stderr_) + 1e-4)
            << "channel " << c << " region " << x0 << "," << y0;
      }
}

// A Lambert box of albedo 0.5 seen from +Z, nothing else, no lights; optionally a floor and a
// moving second box.
std::string boxScene(const std::string& tag, bool floorAndMover = false) {
  test::GltfBuilder g;
  const int grey = g.addMaterial({glm::vec4(0.5f, 0.5f, 0.5f, 1.0f)});
  g.addNode(g.addBox({-0.5f, -0.5f, -0.5f}, {0.5f, 0.5f, 0.5f}, grey));
  if (floorAndMover) {
    g.addNode(g.addQuad({-3, -0.5f, 3}, {3, -0.5f, 3}, {3, -0.5f, -3}, {-3, -0.5f, -3}, grey));
    const int mover = g.addNode(g.addBox({-0.2f, -0.2f, -0.2f}, {0.2f, 0.2f, 0.2f}, grey),
                                glm::vec3(1.0f, 0.0f, 0.5f));
    g.animateTranslation(mover, {0.0f, 1.0f},
                         {glm::vec3(1.0f, 0.0f, 0.5f), glm::vec3(-1.0f, 0.3f, 0.8f)});
  }
  g.addCamera({0.3f, 0.6f, 3.0f}, {0, 0, 0}, 0.6f, 1.0f);
  return g.write(test::tempDir(tag), "box");
}

// A convex Lambert surface in a uniform environment of radiance 1 sees only the environment:
// its radiance is its albedo (0.5), whatever the mode; pixels that miss show the environment.
TEST(Environment, ConvexLambertBoxShowsItsAlbedoInAUniformEnvironment) {
  const std::string scene = boxScene("envbox");
  for (const char* mode : {"pathtrace", "reuse"}) {
    SCOPED_TRACE(mode);
    const std::string dir =
        test::renderFrames(scene, "0",
                           std::string("--mode ") + mode +
                               " --width 32 --height 32 --spp 64 --force-diffuse --env-color 1,1,1",
                           "envbox-r");
    const Image img = test::frameImage(dir, 0);
    const test::Moments face = test::regionMean(img, 13, 13, 19, 19, 1);
    EXPECT_NEAR(face.mean, 0.5, 4.5 * face.stderr_ + 1e-3) << "se " << face.stderr_;
    EXPECT_NEAR(img.pixel(0, 0)[0], 1.0f, 1e-6f);  // the environment itself
  }
}

// Under a map with a sun, with a floor and a moving box (light paths that the environment
// starts bounce between them): reuse converges to the path tracer, region by region.
// (With one light path per pixel, as by default, every sample of a frame shares the same few
// hundred paths, and their noise does not fall with the samples.)
TEST(Environment, ReuseConvergesToThePathTracerUnderAMap) {
  const std::string dir = test::tempDir("envmap");
  const Environment map = testMap(16, 8, 11, 2);
  Image img(map.width, map.height);
  for (size_t i = 0; i < size_t(map.width) * map.height; ++i)
    for (int c = 0; c < 3; ++c) img.rgba[4 * i + c] = map.rgb[3 * i + c];
  writeExr(dir + "/sky.exr", img, ExrPixels::Float);
  const std::string scene = boxScene("envmove", true);
  // Independent light paths for every pixel sample: the estimate's variance is then all in
  // the standard errors.
  const std::string args = " --spp 128 --light-paths " + std::to_string(24 * 24 * 128 * 4) +
                           " --force-diffuse --env " + dir +
                           "/sky.exr --env-rotate 30 --max-depth 6";
  expectModesAgree(scene, args, {1}, "env");
}

// KHR_materials_specular and KHR_materials_clearcoat in every kernel: the path tracer and
// reuse (whose light paths sample the same BSDF in importance mode) agree, region by region.
TEST(Environment, CoatedAndSpecularMaterialsAgreeInBothModes) {
  const std::string scene = boxScene("envcoat", true);
  nlohmann::json doc;
  std::ifstream(scene) >> doc;
  doc["extensionsUsed"] = {"KHR_materials_specular", "KHR_materials_clearcoat"};
  doc["materials"][0]["pbrMetallicRoughness"]["roughnessFactor"] = 0.4;
  doc["materials"][0]["extensions"] = {
      {"KHR_materials_specular", {{"specularFactor", 0.8}, {"specularColorFactor", {1, 0.6, 0.3}}}},
      {"KHR_materials_clearcoat", {{"clearcoatFactor", 0.7}, {"clearcoatRoughnessFactor", 0.3}}}};
  { std::ofstream(scene) << doc.dump(); }
  const std::string args = " --spp 128 --light-paths " + std::to_string(24 * 24 * 128 * 4) +
                           " --env-color 0.9,1,1.1 --max-depth 5";
  expectModesAgree(scene, args, {0}, "coat");
}

// Rewrites the glTF at `scene` so that material `glass` (transmissive) has ior 1 and
// KHR_materials_volume with these values; returns the document written.
nlohmann::json withVolume(const std::string& scene, int glass, double thickness, double distance,
                          const std::vector<double>& color) {
  nlohmann::json doc;
  std::ifstream(scene) >> doc;
  doc["extensionsUsed"] = {"KHR_materials_transmission", "KHR_materials_ior",
                           "KHR_materials_volume"};
  doc["materials"][glass]["extensions"]["KHR_materials_volume"] = {
      {"thicknessFactor", thickness},
      {"attenuationDistance", distance},
      {"attenuationColor", color}};
  doc["materials"][glass]["extensions"]["KHR_materials_ior"] = {{"ior", 1.0}};
  std::ofstream(scene) << doc.dump();
  return doc;
}

// KHR_materials_volume: seen through a slab of clear (ior 1) glass 0.5 thick whose
// attenuation colour (0.5, 0.25, 1) holds at distance 0.5, an emitter of radiance 1 reads that
// colour exactly, in both modes; light paths through an absorbing box agree with the path
// tracer.
TEST(Environment, VolumeAttenuatesInsideTransmissiveObjects) {
  test::GltfBuilder g;
  const int glass = g.addMaterial({glm::vec4(1.0f), 0.0f, 0.0f, glm::vec3(0.0f), 1.0f, 1.0f, 1.0f});
  const int lamp = g.addMaterial({glm::vec4(0, 0, 0, 1), 0.0f, 1.0f, glm::vec3(1.0f), 1.0f});
  g.addNode(g.addBox({-0.5f, -0.5f, -0.25f}, {0.5f, 0.5f, 0.25f}, glass));
  g.addNode(g.addQuad({-3, -3, -1}, {3, -3, -1}, {3, 3, -1}, {-3, 3, -1}, lamp));
  g.addCamera({0, 0, 3}, {0, 0, 0}, 0.2f, 1.0f);
  const std::string scene = g.write(test::tempDir("volume"), "slab");
  nlohmann::json doc = withVolume(scene, glass, 0.5, 0.5, {0.5, 0.25, 1});
  for (const char* mode : {"pathtrace", "reuse"}) {
    SCOPED_TRACE(mode);
    const Image img =
        test::frameImage(test::renderFrames(scene, "0",
                                            std::string("--mode ") + mode +
                                                " --width 16 --height 16 --spp 4 --env none",
                                            "volume-r"),
                         0);
    const float* c = img.pixel(8, 8);
    EXPECT_NEAR(c[0], 0.5f, 1e-4f);
    EXPECT_NEAR(c[1], 0.25f, 1e-4f);
    EXPECT_NEAR(c[2], 1.0f, 1e-4f);
  }
  // Refused: a colour above 1, a distance of 0.
  doc["materials"][glass]["extensions"]["KHR_materials_volume"]["attenuationColor"] = {1.5, 1, 1};
  { std::ofstream(scene) << doc.dump(); }
  EXPECT_THROW(loadScene(scene), InputError);
  doc["materials"][glass]["extensions"]["KHR_materials_volume"]["attenuationColor"] = {1, 1, 1};
  doc["materials"][glass]["extensions"]["KHR_materials_volume"]["attenuationDistance"] = 0;
  { std::ofstream(scene) << doc.dump(); }
  EXPECT_THROW(loadScene(scene), InputError);
}

// A floor and a wall under a wide roof of absorbing clear glass: next-event estimation cannot
// see the environment through the glass, so in reuse the light the wall sends the floor comes
// from light paths that crossed the roof (the path tracer finds it by BSDF samples through
// it). They must agree.
TEST(Environment, LightPathsThroughAnAbsorbingRoofAgreeWithThePathTracer) {
  test::GltfBuilder g;
  const int grey = g.addMaterial({glm::vec4(0.6f, 0.6f, 0.6f, 1.0f)});
  const int glass = g.addMaterial({glm::vec4(1.0f), 0.0f, 0.0f, glm::vec3(0.0f), 1.0f, 1.0f, 1.0f});
  g.addNode(g.addQuad({-3, 0, 3}, {3, 0, 3}, {3, 0, -3}, {-3, 0, -3}, grey));
  g.addNode(g.addBox({-8, 1.0f, -8}, {8, 1.3f, 8}, glass));
  // A wall that the floor sees: light paths through the roof reach it, then the floor.
  g.addNode(g.addQuad({-3, 0, -1.5f}, {3, 0, -1.5f}, {3, 0.99f, -1.5f}, {-3, 0.99f, -1.5f}, grey));
  g.addCamera({0, 0.6f, 2.0f}, {0, 0, -0.5f}, 0.8f, 1.0f);
  const std::string scene = g.write(test::tempDir("envroof"), "roof");
  withVolume(scene, glass, 0.3, 0.3, {0.9, 0.5, 0.2});
  const std::string args = " --spp 64 --light-paths " + std::to_string(24 * 24 * 64 * 4) +
                           " --env-color 1,1,1 --max-depth 6";
  expectModesAgree(scene, args, {0, 2}, "roof");
}

// The extensions' textures scale their factors: a clearcoat texture whose R is 0 and a specular
// texture whose alpha is 0 give exactly the images of clearcoat 0 and specular 0.
TEST(Environment, ExtensionTexturesScaleTheirFactors) {
  const std::string scene = boxScene("exttex", true);
  const std::string dir = scene.substr(0, scene.rfind('/'));
  const unsigned char zero[4] = {0, 255, 255, 0};  // R 0 (coat), A 0 (specular)
  stbi_write_png((dir + "/zero.png").c_str(), 1, 1, 4, zero, 4);
  nlohmann::json base;
  std::ifstream(scene) >> base;
  base["extensionsUsed"] = {"KHR_materials_specular", "KHR_materials_clearcoat"};
  base["materials"][0]["pbrMetallicRoughness"]["roughnessFactor"] = 0.5;
  auto render = [&](const nlohmann::json& ext, bool textured, const std::string& tag) {
    nlohmann::json doc = base;
    doc["materials"][0]["extensions"] = ext;
    if (textured) {
      doc["images"] = {{{"uri", "zero.png"}}};
      doc["textures"] = {{{"source", 0}}};
    }
    { std::ofstream(scene) << doc.dump(); }
    return test::frameImage(
        test::renderFrames(scene, "0", "--mode pathtrace --width 16 --height 16 --spp 2", tag), 0);
  };
  const nlohmann::json tex = {{"index", 0}};
  const Image coatTex =
      render({{"KHR_materials_clearcoat", {{"clearcoatFactor", 1.0}, {"clearcoatTexture", tex}}}},
             true, "exttex-a");
  const Image noCoat =
      render({{"KHR_materials_clearcoat", {{"clearcoatFactor", 0.0}}}}, false, "exttex-b");
  EXPECT_EQ(coatTex.rgba, noCoat.rgba);
  const Image specTex =
      render({{"KHR_materials_specular", {{"specularFactor", 1.0}, {"specularTexture", tex}}}},
             true, "exttex-c");
  const Image noSpec =
      render({{"KHR_materials_specular", {{"specularFactor", 0.0}}}}, false, "exttex-d");
  EXPECT_EQ(specTex.rgba, noSpec.rgba);
  const Image plain = render(nlohmann::json::object(), false, "exttex-e");
  EXPECT_NE(plain.rgba, noSpec.rgba);  // the specular layer shows where it is on
}

TEST(Environment, ReuseEqualsRetraceWithAnEnvironment) {
  const std::string scene = boxScene("envrr", true);
  const std::string args = " --width 24 --height 24 --spp 2 --env-color 0.8,0.9,1 --fps 4";
  const std::string a = test::renderFrames(scene, "0-3", "--mode reuse" + args, "envrr-a");
  const std::string b = test::renderFrames(scene, "0-3", "--mode retrace" + args, "envrr-b");
  for (int f = 0; f <= 3; ++f) {
    const Image x = test::frameImage(a, f), y = test::frameImage(b, f);
    ASSERT_EQ(x.rgba.size(), y.rgba.size());
    EXPECT_EQ(x.rgba, y.rgba) << "frame " << f;
  }
}

TEST(Environment, SceneWithoutLightsIsLitByDefaultAndNoneKeepsItDark) {
  const std::string scene = boxScene("envdefault");
  auto run = [&](const std::string& args) {
    const std::string dir = test::tempDir("envdef-r");
    const auto r = test::runPathreuse("render '" + scene + "' --exr-float --frames 0 --width 8 " +
                                      "--height 8 --spp 1 --out '" + dir + "/f_%04d.exr' " + args);
    EXPECT_EQ(r.exitCode, 0) << r.err;
    return std::make_pair(r.err, test::frameImage(dir, 0));
  };
  const auto lit = run("");
  EXPECT_NE(lit.first.find("uniform white environment"), std::string::npos) << lit.first;
  EXPECT_FLOAT_EQ(lit.second.pixel(0, 0)[1], 1.0f);
  const auto dark = run("--env none");
  EXPECT_NE(dark.first.find("frames will be black"), std::string::npos) << dark.first;
  for (float v : dark.second.rgba) ASSERT_TRUE(v == 0.0f || v == 1.0f);  // alpha 1
  EXPECT_EQ(dark.second.pixel(4, 4)[0], 0.0f);
  const auto strong = run("--env-strength 2 --env-color 1,0.5,0.25");
  EXPECT_FLOAT_EQ(strong.second.pixel(0, 0)[0], 2.0f);
  EXPECT_FLOAT_EQ(strong.second.pixel(0, 0)[2], 0.5f);
}

// The floor of a map is the darkest texel's luminance over the mean over the sphere.
TEST(Environment, UniformShareIsTheDarkestTexelOverTheMean) {
  auto share = [](const Environment& e) {
    float mean = 0.0f;
    if (e.present()) environmentTables(e, &mean);
    return environmentUniformShare(e, mean);
  };
  EXPECT_FLOAT_EQ(share(constantEnvironment({0.5f, 0.6f, 0.8f})), 1.0f);
  const Environment map = testMap(16, 8, 11, 2);
  float mean = 0.0f;
  environmentTables(map, &mean);
  double lowest = 1e30;
  for (size_t i = 0; i < map.rgb.size() / 3; ++i)
    lowest = std::min(lowest, 0.2126 * map.rgb[3 * i] + 0.7152 * map.rgb[3 * i + 1] +
                                  0.0722 * map.rgb[3 * i + 2]);
  EXPECT_NEAR(share(map), lowest / mean, 1e-4);
  Environment dark = map;
  dark.rgb[0] = dark.rgb[1] = dark.rgb[2] = 0.0f;
  EXPECT_EQ(share(dark), 0.0f);
  EXPECT_EQ(share(Environment{}), 0.0f);
}

// A room lit by a point light under its ceiling, a uniform sky seen through a small hole in
// the ceiling. By its whole power the sky takes most of light sampling's choices, which its
// radiance, the same in every direction, does not need (BSDF sampling draws it as well) and
// which the ceiling mostly blocks; by the part above its floor (the default) the point light
// takes them. Both choices are unbiased, and the default's error is lower.
TEST(Environment, AUniformSkyLeavesLightSamplingToTheOtherLights) {
  test::GltfBuilder g;
  const int grey = g.addMaterial({glm::vec4(0.6f, 0.6f, 0.6f, 1.0f)});
  const float h = 0.3f;  // half the hole's side
  g.addNode(g.addQuad({-2, 0, 2}, {2, 0, 2}, {2, 0, -2}, {-2, 0, -2}, grey));
  for (const glm::vec3& c :
       {glm::vec3(-2, 0, 2), glm::vec3(2, 0, 2), glm::vec3(2, 0, -2), glm::vec3(-2, 0, -2)}) {
    const glm::vec3 n(c.z / 2.0f, 0.0f, -c.x / 2.0f);  // to the next corner, halved
    g.addNode(g.addQuad(c, c + glm::vec3(0, 2, 0), c + 2.0f * n + glm::vec3(0, 2, 0), c + 2.0f * n,
                        grey));
  }
  g.addNode(g.addQuad({-2, 2, -2}, {2, 2, -2}, {2, 2, -h}, {-2, 2, -h}, grey));
  g.addNode(g.addQuad({-2, 2, h}, {2, 2, h}, {2, 2, 2}, {-2, 2, 2}, grey));
  g.addNode(g.addQuad({-2, 2, -h}, {-h, 2, -h}, {-h, 2, h}, {-2, 2, h}, grey));
  g.addNode(g.addQuad({h, 2, -h}, {2, 2, -h}, {2, 2, h}, {h, 2, h}, grey));
  g.addPointLight({1.0f, 1.7f, 0.5f}, {1.0f, 1.0f, 1.0f}, 4.0f);
  g.addCamera({0.0f, 1.2f, 1.9f}, {0.0f, 0.3f, -1.0f}, 1.2f, 1.0f);
  const std::string scene = g.write(test::tempDir("envshare"), "room");
  const std::string common = " --width 24 --height 24 --env-color 1,1,1 --max-depth 5 ";
  auto render = [&](const std::string& args) {
    return test::frameImage(test::renderFrames(scene, "0", common + args, "envshare-r"), 0);
  };
  // Unbiased: the two choices agree region by region, in both modes.
  for (const char* mode : {"pathtrace", "reuse"}) {
    SCOPED_TRACE(mode);
    const Image a = render(std::string("--spp 96 --mode ") + mode);
    const Image b = render(std::string("--spp 96 --env-light-choice power --mode ") + mode);
    for (int y0 = 0; y0 < 24; y0 += 12)
      for (int x0 = 0; x0 < 24; x0 += 12)
        for (int c = 0; c < 3; ++c) {
          const test::Moments ma = test::regionMean(a, x0, y0, x0 + 12, y0 + 12, c);
          const test::Moments mb = test::regionMean(b, x0, y0, x0 + 12, y0 + 12, c);
          EXPECT_NEAR(ma.mean, mb.mean, 4.5 * std::hypot(ma.stderr_, mb.stderr_) + 1e-4)
              << "channel " << c << " region " << x0 << "," << y0;
        }
  }
  // Less error at the same samples, against one reference.
  const Image ref = render("--spp 1024 --mode pathtrace --seed 9");
  const double fine = compareImages(render("--spp 4 --mode pathtrace"), ref).relMse;
  const double coarse =
      compareImages(render("--spp 4 --mode pathtrace --env-light-choice power"), ref).relMse;
  EXPECT_LT(fine, 0.7 * coarse) << "auto " << fine << ", power " << coarse;
}

TEST(Environment, BadOptionsExitTwoWithOneLine) {
  const std::string scene = boxScene("envbad");
  const std::string dir = test::tempDir("envbad-r");
  for (const auto& [args, what] : std::vector<std::pair<std::string, std::string>>{
           {"--env " + dir + "/none.exr", "none.exr"},
           {"--env " + dir + "/sky.jpg", "must be .exr or .hdr"},
           {"--env-color 1,2", "--env-color"},
           {"--env none --env-color 1,1,1", "contradicts --env none"},
           {"--env-strength -1", "--env-strength"},
           {"--env-rotate nan", "--env-rotate"}}) {
    const auto r = test::runPathreuse("render '" + scene + "' --frames 0 --width 8 --height 8 " +
                                      "--spp 1 --out '" + dir + "/f_%04d.exr' " + args);
    EXPECT_EQ(r.exitCode, 2) << args << ": " << r.err;
    EXPECT_NE(r.err.find(what), std::string::npos) << args << ": " << r.err;
    EXPECT_FALSE(std::ifstream(dir + "/f_0000.exr").good()) << args;
  }
}

}  // namespace
}  // namespace pr
