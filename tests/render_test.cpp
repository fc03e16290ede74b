// The baseline path tracer against known answers: a white furnace, a diffuse plane under a point
// light, determinism by seed, and frames free of NaN and Inf; flat facets where a primitive has
// no normals, and the camera's clipping planes (in both modes).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "io/image.h"
#include "render/session.h"
#include "scene/gltf_loader.h"
#include "support/gltf_builder.h"
#include "support/render_helpers.h"
#include "support/test_env.h"

namespace pr {
namespace {

using test::Moments;
using test::regionMean;

Image render(const std::string& scene, const std::string& args, const std::string& tag) {
  const std::string dir = test::tempDir(tag);
  const auto r =
      test::runPathreuse("render '" + scene + "' --quiet --exr-float --mode pathtrace --out '" +
                         dir + "/f_%04d.exr' " + args);
  EXPECT_EQ(r.exitCode, 0) << r.err;
  return readExr(dir + "/f_0000.exr");
}

TEST(PathTrace, WhiteFurnaceConvergesToLeOverOneMinusAlbedo) {
  const float albedo = 0.5f, le = 1.0f;
  test::GltfBuilder b;
  const int mat = b.addMaterial({glm::vec4(albedo, albedo, albedo, 1), 0, 1, glm::vec3(le), 1.0f});
  b.addNode(b.addBox(glm::vec3(-1), glm::vec3(1), mat, true));
  b.addCamera(glm::vec3(0.1f, 0.2f, 0.3f), glm::vec3(1, 0.5f, -1), 1.2f, 1.0f);
  const std::string scene = b.write(test::tempDir("furnace"), "furnace");
  // Depth 40: the truncated series misses albedo^40 ~ 1e-12 of the answer.
  const Image img =
      render(scene, "--frames 0 --width 48 --height 48 --spp 16 --max-depth 40 --force-diffuse",
             "furnace-out");
  const double expected = le / (1.0 - albedo);
  for (int c = 0; c < 3; ++c) {
    const Moments m = regionMean(img, 0, 0, 48, 48, c);
    EXPECT_NEAR(m.mean, expected, 5 * m.stderr_ + 1e-3)
        << "channel " << c << " stderr " << m.stderr_;
    EXPECT_LT(m.stderr_, 0.02);  // the test has power to see a 5% error
  }
  // Every region, not only the whole image.
  for (int q = 0; q < 4; ++q) {
    const int x0 = (q % 2) * 24, y0 = (q / 2) * 24;
    const Moments m = regionMean(img, x0, y0, x0 + 24, y0 + 24, 1);
    EXPECT_NEAR(m.mean, expected, 5 * m.stderr_ + 1e-3) << "quadrant " << q;
  }
}

TEST(PathTrace, DiffusePlaneUnderPointLightMatchesIrradianceLaw) {
  // L(x) = rho / pi * I * cos(theta) / r^2 on a Lambertian plane lit by a point light.
  const float rho = 0.8f, intensity = 10.0f, h = 2.0f;
  test::GltfBuilder b;
  const int mat = b.addMaterial({glm::vec4(rho, rho, rho, 1), 0, 1});
  b.addNode(b.addQuad({-10, 0, -10}, {-10, 0, 10}, {10, 0, 10}, {10, 0, -10}, mat));
  b.addPointLight(glm::vec3(0, h, 0), glm::vec3(1), intensity);
  const glm::vec3 eye(0.0f, 5.0f, 0.0f);
  const float yfov = 1.0f;
  b.addCamera(eye, glm::vec3(0), yfov, 1.0f);
  const std::string scene = b.write(test::tempDir("plane"), "plane");
  const int n = 32;
  const Image img =
      render(scene, "--frames 0 --width 32 --height 32 --spp 256 --max-depth 2 --force-diffuse",
             "plane-out");
  // The camera looks down -Y with up = -Z: pixel (x, y) maps to world (X, Z) on the plane.
  // Radiance changes by up to ~13% across a pixel at the edges; 256 jittered samples estimate
  // the pixel's mean to ~0.25%, so 1% is four standard errors.
  const float tanHalf = std::tan(yfov / 2);
  double worst = 0;
  for (int y = 0; y < n; y += 3)
    for (int x = 0; x < n; x += 3) {
      double expected = 0;
      const int k = 8;  // the pixel's footprint, as the jittered samples cover it
      for (int j = 0; j < k; ++j)
        for (int i = 0; i < k; ++i) {
          const float sx = (2.0f * (x + (i + 0.5f) / k) / n - 1.0f) * tanHalf;
          const float sy = (1.0f - 2.0f * (y + (j + 0.5f) / k) / n) * tanHalf;
          const glm::vec3 p(sx * eye.y, 0.0f, -sy * eye.y);
          const glm::vec3 d = glm::vec3(0, h, 0) - p;
          const float r2 = glm::dot(d, d);
          expected += rho / M_PI * intensity * (h / std::sqrt(r2)) / r2;
        }
      expected /= k * k;
      const double got = img.pixel(x, y)[0];
      worst = std::fmax(worst, std::fabs(got - expected) / expected);
      EXPECT_NEAR(got, expected, 0.01 * expected) << "pixel " << x << "," << y;
    }
  RecordProperty("worst_relative_error", std::to_string(worst));
}

TEST(PathTrace, SameSeedSameFrameDifferentSeedSameMean) {
  const std::string scene = test::sourcePath("scenes/cornell-dynamic.gltf");
  const std::string args = "--frames 10 --width 40 --height 30 --spp 8";
  auto renderFrame = [&](const std::string& seed, const std::string& tag) {
    const std::string dir = test::tempDir(tag);
    const auto r =
        test::runPathreuse("render '" + scene + "' --quiet --exr-float --mode pathtrace --seed " +
                           seed + " --out '" + dir + "/f_%04d.exr' " + args);
    EXPECT_EQ(r.exitCode, 0) << r.err;
    return readExr(dir + "/f_0010.exr");
  };
  const Image a = renderFrame("7", "seed-a"), b = renderFrame("7", "seed-b"),
              c = renderFrame("8", "seed-c");
  EXPECT_EQ(a.rgba, b.rgba) << "the same seed must reproduce the frame bit for bit";
  EXPECT_NE(a.rgba, c.rgba) << "another seed must give other noise";
  for (int ch = 0; ch < 3; ++ch) {
    const Moments ma = regionMean(a, 0, 0, 40, 30, ch), mc = regionMean(c, 0, 0, 40, 30, ch);
    EXPECT_NEAR(ma.mean, mc.mean, 5 * std::hypot(ma.stderr_, mc.stderr_)) << "channel " << ch;
  }
}

// An octagonal prism without NORMAL (radius 1, y in [-1, 1]; neighbouring facets share their
// edge vertices, so averaged normals would round it) with one facet facing the camera on +Z,
// lit by a directional light 45 degrees off that facet. Animated three ways through t = 1:
// moved, morphed (radius 1 to 1.5, with target NORMAL deltas that must be ignored) or skinned.
enum class PrismMotion { None, Moves, Morphs, Skinned };

std::string flatPrism(PrismMotion motion, const std::string& tag) {
  test::GltfBuilder b;
  const int mat = b.addMaterial({glm::vec4(0.8f, 0.8f, 0.8f, 1), 0, 1});
  std::vector<glm::vec3> p;
  std::vector<uint32_t> idx;
  test::MeshAttributes a;
  for (int i = 0; i < 8; ++i) {
    const float beta = (float(i) - 0.5f) * float(M_PI) / 4;  // facet k: vertices k and k + 1
    for (float y : {-1.0f, 1.0f}) p.emplace_back(std::sin(beta), y, std::cos(beta));
  }
  for (uint32_t k = 0; k < 8; ++k) {
    const uint32_t b0 = 2 * k, t0 = b0 + 1, b1 = 2 * ((k + 1) % 8), t1 = b1 + 1;
    idx.insert(idx.end(), {b0, b1, t1, b0, t1, t0});  // counter-clockwise seen from outside
  }
  if (motion == PrismMotion::Morphs) {
    a.targetPositions.emplace_back();
    for (const glm::vec3& v : p) a.targetPositions[0].push_back(0.5f * glm::vec3(v.x, 0, v.z));
    a.targetNormals.emplace_back(p.size(), glm::vec3(0, 1, 0));
  }
  if (motion == PrismMotion::Skinned) {
    a.joints.assign(p.size(), {0, 0, 0, 0});
    a.weights.assign(p.size(), glm::vec4(1, 0, 0, 0));
  }
  const int node = b.addNode(b.addMesh(p, idx, mat, a));
  const std::vector<glm::vec3> sway = {{0, -0.2f, 0}, {0, 0.2f, 0}};
  if (motion == PrismMotion::Moves) b.animateTranslation(node, {0, 1}, sway);
  if (motion == PrismMotion::Morphs) b.animateWeights(node, {0, 1}, {{0}, {1}});
  if (motion == PrismMotion::Skinned) {
    const int joint = b.addNode(-1);
    b.addSkin(node, {joint});
    b.animateTranslation(joint, {0, 1}, sway);
  }
  b.addDirectionalLight(glm::angleAxis(float(M_PI) / 4, glm::vec3(0, 1, 0)), glm::vec3(1), 2.0f);
  b.addCamera(glm::vec3(0, 0, 5), glm::vec3(0), 0.4f, 1.0f);
  return b.write(test::tempDir(tag), "prism");
}

// glTF: a primitive without NORMAL is shaded flat. Direct light only, so a facet under a
// directional light has one radiance, rho / pi * E * cos 45, in every pixel well inside it
// (averaged normals would take it from cos 67.5 to cos 22.5 across the facet); the same in
// both modes and while the prism moves, morphs or is skinned (frame 12 is t = 0.5).
TEST(FlatShading, PrimitivesWithoutNormals) {
  const double expected = 0.8 / M_PI * 2.0 * std::cos(M_PI / 4);
  const struct {
    PrismMotion motion;
    const char* name;
  } cases[] = {{PrismMotion::None, "static"},
               {PrismMotion::Moves, "moving"},
               {PrismMotion::Morphs, "morphing"},
               {PrismMotion::Skinned, "skinned"}};
  for (const auto& c : cases)
    for (const char* mode : {"pathtrace", "reuse"}) {
      SCOPED_TRACE(std::string(c.name) + " " + mode);
      const std::string scene = flatPrism(c.motion, std::string("prism-") + c.name);
      const int frame = c.motion == PrismMotion::None ? 0 : 12;
      const std::string dir = test::renderFrames(
          scene, std::to_string(frame),
          std::string("--width 32 --height 32 --spp 4 --max-depth 2 --env none --force-diffuse "
                      "--mode ") +
              mode,
          std::string("prism-") + c.name + "-" + mode);
      const Image img = test::frameImage(dir, frame);
      // The facet spans columns 8.6 to 23.4 (more where morphed) and every row.
      double lo = 1e30, hi = 0;
      for (int y = 8; y < 24; ++y)
        for (int x = 10; x < 22; ++x) {
          lo = std::fmin(lo, img.pixel(x, y)[1]);
          hi = std::fmax(hi, img.pixel(x, y)[1]);
        }
      EXPECT_NEAR(lo, expected, 0.01 * expected);
      EXPECT_NEAR(hi, expected, 0.01 * expected);
    }
}

// A black metal wall at depth 5 that emits 1, seen past a white quad at depth 0.5 lit by a point
// light behind the camera; camera clipping planes znear and zfar (glTF's).
std::string clippedScene(float znear, float zfar, const std::string& tag) {
  test::GltfBuilder b;
  test::MaterialSpec wall;
  wall.baseColor = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
  wall.metallic = 1.0f;  // a black metal reflects nothing
  wall.emissive = glm::vec3(1.0f);
  const int w = b.addMaterial(wall);
  b.addNode(b.addQuad({-4, -4, 0}, {4, -4, 0}, {4, 4, 0}, {-4, 4, 0}, w));
  test::MaterialSpec white;
  white.baseColor = glm::vec4(0.8f, 0.8f, 0.8f, 1.0f);
  const int m = b.addMaterial(white);
  // The left half of the view.
  b.addNode(b.addQuad({-3, -3, 4.5f}, {0, -3, 4.5f}, {0, 3, 4.5f}, {-3, 3, 4.5f}, m));
  // Behind the camera, a white wall that the light lights: light paths reach the quad's front by
  // it, so that light tracing could splat the quad.
  b.addNode(b.addQuad({-4, -4, 7}, {-4, 4, 7}, {4, 4, 7}, {4, -4, 7}, m));
  // Most light paths start here (by power), not on the wall.
  b.addPointLight({0, 0, 6}, {1, 1, 1}, 200.0f);
  b.addCamera({0, 0, 5}, {0, 0, 0}, 0.6f, 1.0f, znear, zfar);
  return b.write(test::tempDir(tag), "clipped");
}

// glTF's znear and zfar clip what the camera sees, in every mode and every strategy: nearer than
// znear the quad is not seen (light tracing splats none of its light either), so every pixel sees
// the wall's emission alone; past zfar the wall is not seen. Lights still light what is clipped.
TEST(Camera, ClippingPlanesHideWhatIsNearerOrFarther) {
  for (const char* mode : {"pathtrace", "reuse"}) {
    SCOPED_TRACE(mode);
    const std::string args =
        std::string("--width 24 --height 24 --spp 4 --light-paths 16384 --env none --mode ") + mode;
    const Image seen = test::frameImage(
        test::renderFrames(clippedScene(0.1f, 0.0f, "clip-seen"), "0", args, "clip-seen"), 0);
    const Image near = test::frameImage(
        test::renderFrames(clippedScene(1.0f, 0.0f, "clip-near"), "0", args, "clip-near"), 0);
    const Image far = test::frameImage(
        test::renderFrames(clippedScene(1.0f, 3.0f, "clip-far"), "0", args, "clip-far"), 0);
    // The quad is seen where nothing clips it: its left half differs from the wall's 1.
    EXPECT_GT(std::fabs(regionMean(seen, 2, 2, 10, 22, 1).mean - 1.0), 0.05);
    for (int y = 0; y < 24; ++y)
      for (int x = 0; x < 24; ++x)
        for (int c = 0; c < 3; ++c) {
          ASSERT_NEAR(near.pixel(x, y)[c], 1.0f, 1e-4f) << x << "," << y;
          ASSERT_EQ(far.pixel(x, y)[c], 0.0f) << x << "," << y;
        }
  }
}

uint64_t badSamplesIn(const std::string& statsFile, int* lines) {
  std::ifstream in(statsFile);
  std::string line;
  uint64_t bad = 0;
  *lines = 0;
  while (std::getline(in, line)) {
    const auto j = nlohmann::json::parse(line);
    bad += j.at("bad_samples").get<uint64_t>();
    EXPECT_GT(j.at("rays").at("camera").get<uint64_t>(), 0u);
    EXPECT_GT(j.at("wall_s").get<double>(), 0.0);
    ++*lines;
  }
  return bad;
}

TEST(PathTrace, NoNonFiniteSamplesOnTheDemoScenes) {
  for (const char* name : {"scenes/cornell-dynamic.gltf", "scenes/cornell-orbit.gltf"}) {
    const std::string dir = test::tempDir("nan");
    const auto r = test::runPathreuse(
        "render '" + test::sourcePath(name) +
        "' --quiet --mode pathtrace --frames 0-2 --width 48 --height 36 --spp 4 --out '" + dir +
        "/f_%04d.exr' --stats '" + dir + "/stats.jsonl'");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    int lines = 0;
    EXPECT_EQ(badSamplesIn(dir + "/stats.jsonl", &lines), 0u) << name;
    EXPECT_EQ(lines, 3);
    for (int f = 0; f < 3; ++f) {
      char file[64];
      std::snprintf(file, sizeof file, "/f_%04d.exr", f);
      const Image img = readExr(dir + file);
      for (float v : img.rgba) ASSERT_TRUE(std::isfinite(v)) << name;
    }
  }
}

TEST(PathTrace, NoNonFiniteSamplesOnCornellNvpro) {
  PR_SHARED_SCENE(scene, "cornell-nvpro/cornellBox.gltf");
  const std::string dir = test::tempDir("nan-nvpro");
  const auto r = test::runPathreuse(
      "render '" + scene +
      "' --quiet --mode pathtrace --frames 0 --width 64 --height 48 --spp 4 --out '" + dir +
      "/f_%04d.exr' --stats '" + dir + "/stats.jsonl'");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  int lines = 0;
  EXPECT_EQ(badSamplesIn(dir + "/stats.jsonl", &lines), 0u);
  EXPECT_EQ(lines, 1);
}

// A pass traces its paths in bands of pixels (PathTracerSettings::wavefrontPixels), each
// path's own state kept for its band alone: the frames are the same floats for bands of 37
// pixels as for one band, in every mode, with resampling's neighbours and history, adaptive
// sampling's masked passes and a device's rows.
TEST(Wavefront, BandsGiveTheSameFrames) {
  const Scene scene = loadScene(test::sourcePath("scenes/cornell-dynamic.gltf"));
  struct Case {
    const char* name;
    RenderMode mode;
    bool resample;
    float noise;
    int rowBegin, rowEnd;
  };
  const Case cases[] = {{"pathtrace", RenderMode::PathTrace, false, 0.0f, 0, 0},
                        {"pathtrace resampled", RenderMode::PathTrace, true, 0.0f, 0, 0},
                        {"reuse", RenderMode::Reuse, true, 0.0f, 0, 0},
                        {"retrace", RenderMode::Retrace, true, 0.0f, 0, 0},
                        {"adaptive", RenderMode::PathTrace, true, 0.05f, 0, 0},
                        {"rows", RenderMode::Reuse, true, 0.0f, 7, 23}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    auto render = [&](uint32_t band) {
      RenderOptions ro;
      ro.width = 40;
      ro.height = 30;
      ro.spp = c.noise > 0.0f ? 8 : 2;
      ro.mode = c.mode;
      ro.resample.asked = c.resample;
      ro.noiseThreshold = c.noise;
      ro.wavefrontPixels = band;
      RenderSession session(scene, test::testContext().device(), ro);
      if (c.rowEnd > 0) session.setRows(c.rowBegin, c.rowEnd);
      std::vector<std::vector<float>> frames;
      for (int f : {0, 1, 2}) frames.push_back(session.renderFrame(f, nullptr).rgba);
      return frames;
    };
    const auto whole = render(kWavefrontPixels), bands = render(37);
    ASSERT_EQ(whole.size(), bands.size());
    for (size_t f = 0; f < whole.size(); ++f) EXPECT_EQ(whole[f], bands[f]) << "frame " << f;
  }
}

}  // namespace
}  // namespace pr
