// Motion blur (--shutter; kernels/shared/motion.h, docs/design.md section 3): a frame whose
// shutter is open equals the average of sharp instants over its interval.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <cstdio>
#include <string>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <nlohmann/json.hpp>

#include "io/image.h"
#include "render/gpu_scene.h"
#include "scene/gltf_loader.h"
#include "support/gltf_builder.h"
#include "support/render_helpers.h"
#include "support/test_env.h"

namespace pr {
namespace {

enum class Moving {
  Object,
  Rotating,
  Camera,
  Lamp,
  Light,
  Morph,
  Skin,
  SkinTurning,
  Blinds,
  Bounce
};

// A grey floor (y = 0) and ceiling (y = 3), 16 wide; returns a dark material for what moves.
int addFloorAndCeiling(test::GltfBuilder& b) {
  test::MaterialSpec grey;
  grey.baseColor = glm::vec4(0.8f, 0.8f, 0.8f, 1.0f);
  const int g = b.addMaterial(grey);
  b.addNode(b.addQuad({-8, 0, -8}, {-8, 0, 8}, {8, 0, 8}, {8, 0, -8}, g));
  b.addNode(b.addQuad({-8, 3, -8}, {8, 3, -8}, {8, 3, 8}, {-8, 3, 8}, g));
  test::MaterialSpec dark;
  dark.baseColor = glm::vec4(0.02f, 0.02f, 0.02f, 1.0f);
  return b.addMaterial(dark);
}

// A ceiling lit only by the pool of light that a spot casts on the floor below, and a dark slab
// just under the spot that covers it at t = 0.75 and 1.25 and is far aside at t = 1: frame 1's
// light paths (traced at t = 1) pass where the slab is for about half of a half-frame shutter.
// The camera sees the ceiling beside the slab's path (x < -3), lit from the floor alone.
std::string blindsScene(const std::string& tag) {
  test::GltfBuilder b;
  const int d = addFloorAndCeiling(b);
  b.addSpotLight({0, 2.9f, 0}, {0, 0, 0}, {1, 1, 1}, 40.0f, 0.3f, 0.5f);
  const int slab =
      b.addNode(b.addBox({-2.5f, -0.05f, -2.5f}, {2.5f, 0.05f, 2.5f}, d), glm::vec3(0, 2.5f, 0));
  b.animateTranslation(slab, {0.75f, 1.0f, 1.25f}, {{0, 2.5f, 0}, {6, 2.5f, 0}, {0, 2.5f, 0}});
  b.addCamera({-2, 1, 0.5f}, {-5, 3, -0.5f}, 0.9f, 4.0f / 3.0f);
  return b.write(test::tempDir(tag), "blinds");
}

// A ceiling lit by a lamp that slides fast along the floor under a dark lid (they move together):
// the lamp's light reaches the ceiling through the floor, so the camera, which sees the ceiling
// alone, sees paths that strategies N, H and T all make and L, under the shutter, cannot (every
// path of the lamp starts in its sweep). Their weights split the path between N, H and T alone,
// and T joins a light path to the camera where the lamp is at the path's time.
std::string bounceScene(const std::string& tag) {
  test::GltfBuilder b;
  const int dark = addFloorAndCeiling(b);
  test::MaterialSpec lamp;
  lamp.baseColor = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
  lamp.emissive = glm::vec3(1.0f, 0.9f, 0.8f);
  lamp.emissiveStrength = 200.0f;
  const int l = b.addNode(b.addQuad({-0.5f, 0, -0.5f}, {0.5f, 0, -0.5f}, {0.5f, 0, 0.5f},
                                    {-0.5f, 0, 0.5f}, b.addMaterial(lamp)),
                          glm::vec3(0, 0.5f, 0));
  const int lid =
      b.addNode(b.addBox({-0.6f, 0.0f, -0.6f}, {0.6f, 0.05f, 0.6f}, dark), glm::vec3(0, 0.51f, 0));
  b.animateTranslation(l, {0.0f, 2.0f}, {{-16, 0.5f, 0}, {16, 0.5f, 0}});
  b.animateTranslation(lid, {0.0f, 2.0f}, {{-16, 0.51f, 0}, {16, 0.51f, 0}});
  b.addCamera({0, 1.5f, 5}, {0, 3, 0}, 1.2f, 4.0f / 3.0f);
  return b.write(test::tempDir(tag), "bounce");
}

// A grey back wall and floor lit by a point light, a dark quad before the wall; one thing moves
// fast over t in [0, 2] (at fps 1 a half-frame shutter sweeps a quarter of it): the quad across
// the view (Lamp: an emitting one, which lights the wall), a bar turning a whole turn about the
// view axis, the camera sideways, the point light along the wall, or the quad again deformed (a
// morph target, a skin; SkinTurning: a skin whose joint turns as the bar does).
std::string movingScene(Moving what, const std::string& tag) {
  if (what == Moving::Blinds) return blindsScene(tag);
  if (what == Moving::Bounce) return bounceScene(tag);
  test::GltfBuilder b;
  test::MaterialSpec grey;
  grey.baseColor = glm::vec4(0.6f, 0.6f, 0.6f, 1.0f);
  const int g = b.addMaterial(grey);
  b.addNode(b.addQuad({-4, -3, 0}, {4, -3, 0}, {4, 3, 0}, {-4, 3, 0}, g));
  b.addNode(b.addQuad({-4, -3, 0}, {-4, -3, 4}, {4, -3, 4}, {4, -3, 0}, g));
  test::MaterialSpec dark;
  dark.baseColor = glm::vec4(0.05f, 0.02f, 0.02f, 1.0f);  // dark against the wall
  if (what == Moving::Lamp) {  // a lamp a little before the wall, which it lights
    dark.emissive = glm::vec3(1.0f, 0.75f, 0.5f);
    dark.emissiveStrength = 8.0f;
  }
  const bool deforms = what == Moving::Morph || what == Moving::Skin || what == Moving::SkinTurning;
  // A deformed quad is bright and lit from close by, so that where its points are shows.
  if (deforms) dark.baseColor = glm::vec4(0.8f, 0.8f, 0.8f, 1.0f);
  const int r = b.addMaterial(dark);
  const int light = deforms ? b.addPointLight({0, 0, 1.6f}, {1, 1, 1}, 6.0f)
                            : b.addPointLight({0, 2, 4}, {1, 1, 1}, 60.0f);
  if (what == Moving::Light)  // close to the wall, where its pool of light moves with it
    b.animateTranslation(light, {0.0f, 2.0f}, {{-4, 1, 1.5f}, {4, 1, 1.5f}});
  const int cam = b.addCamera({0, 0, 6}, {0, 0, 0}, 0.9f, 4.0f / 3.0f);
  std::vector<float> turnTimes;
  std::vector<glm::quat> turnKeys;
  for (int k = 0; k <= 4; ++k) {  // a quarter turn each half second
    turnTimes.push_back(0.5f * float(k));
    turnKeys.push_back(glm::angleAxis(0.5f * PR_PI * float(k), glm::vec3(0, 0, 1)));
  }
  if (what == Moving::Rotating) {
    const int bar =
        b.addNode(b.addQuad({-2, -0.5f, 0}, {2, -0.5f, 0}, {2, 0.5f, 0}, {-2, 0.5f, 0}, r),
                  glm::vec3(0, 0, 0.5f));
    b.animateRotation(bar, turnTimes, turnKeys);
  } else if (deforms) {
    // The quad of Object, moved by a morph target (weight 0 to 1) or by the joint of its skin.
    const std::vector<glm::vec3> corners = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
    test::MeshAttributes a;
    if (what == Moving::Morph) {
      a.targetPositions.emplace_back(4, glm::vec3(8, 0, 0));
    } else {
      a.joints.assign(4, {0, 0, 0, 0});
      a.weights.assign(4, glm::vec4(1, 0, 0, 0));
    }
    const int node =
        b.addNode(b.addMesh(corners, {0, 1, 2, 0, 2, 3}, r, a), glm::vec3(-4, 0, 0.5f));
    if (what == Moving::Morph) {
      b.animateWeights(node, {0.0f, 2.0f}, {{0.0f}, {1.0f}});
    } else {
      const int joint = b.addNode(-1);
      b.addSkin(node, {joint});
      if (what == Moving::SkinTurning)
        b.animateRotation(joint, turnTimes, turnKeys);
      else
        b.animateTranslation(joint, {0.0f, 2.0f}, {{-4, 0, 0.5f}, {4, 0, 0.5f}});
    }
  } else {
    const float depth = what == Moving::Lamp ? 1.5f : 0.5f;
    const int quad = b.addNode(b.addQuad({-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, r),
                               glm::vec3(0, 0, depth));
    if (what == Moving::Object || what == Moving::Lamp)
      b.animateTranslation(quad, {0.0f, 2.0f}, {{-4, 0, depth}, {4, 0, depth}});
    else if (what == Moving::Camera)
      b.animateTranslation(cam, {0.0f, 2.0f}, {{-2, 0, 6}, {2, 0, 6}});
  }
  return b.write(test::tempDir(tag), "moving");
}

constexpr int kW = 32, kH = 24, kBlock = 4;
// Depth 4: strategy T (--light-tracing) takes part (paths of x_1 and two vertices before a light).
const char* const kArgs = "--env none --max-depth 4 --width 32 --height 24";

// Per pixel, a - b.
Image difference(const Image& a, const Image& b) {
  Image d(a.width, a.height);
  for (size_t k = 0; k < d.rgba.size(); ++k) d.rgba[k] = a.rgba[k] - b.rgba[k];
  return d;
}

// Frame 1 (t = 1) with the shutter open half a frame equals the mean of 16 sharp instants at
// the middles of the interval's sixteenths (frames 49, 51, ... 79 at 64 fps, path traced), block
// by block within the noise (the blocks' means of the per-pixel difference, whose spread is the
// noise alone); and the sharp frame at t = 1 is farther from that mean, where the thing moves.
// In `mode` with `extra`; path reuse and resampling render frames 0 and 1, so that frame 1 keeps
// frame 0's still paths (or reservoirs), with a light path of its own for every pixel sample
// (their noise then in the blocks' spread).
void expectBlurIsTheMeanOfInstants(Moving what, const std::string& tag,
                                   const std::string& mode = "pathtrace",
                                   const std::string& extra = "") {
  const std::string scene = movingScene(what, tag);
  auto args = [](const std::string& m, int spp) {
    return std::string(kArgs) + " --mode " + m + " --spp " + std::to_string(spp) +
           (m != "pathtrace" ? " --light-paths " + std::to_string(kW * kH * spp) : "");
  };
  const char* frames = mode != "pathtrace" || !extra.empty() ? "0-1" : "1";
  const Image blurred = test::frameImage(
      test::renderFrames(scene, frames, args(mode, 128) + " --fps 1 --shutter 0.5 " + extra,
                         tag + "-blur"),
      1);
  const Image sharp = test::frameImage(
      test::renderFrames(scene, "1", args("pathtrace", 128) + " --fps 1", tag + "-sharp"), 1);
  const std::string dir =
      test::renderFrames(scene, "49-79", args("pathtrace", 8) + " --fps 64", tag + "-inst");
  Image mean(kW, kH);
  for (int f = 49; f <= 79; f += 2) {
    const Image instant = test::frameImage(dir, f);
    for (size_t k = 0; k < mean.rgba.size(); ++k) mean.rgba[k] += instant.rgba[k] / 16.0f;
  }
  const Image blur = difference(blurred, mean), still = difference(sharp, mean);
  double blurOff = 0.0, sharpOff = 0.0;  // summed over the blocks: how far from the mean
  for (int y = 0; y < kH; y += kBlock)
    for (int x = 0; x < kW; x += kBlock)
      for (int c = 0; c < 3; ++c) {
        const double level = test::regionMean(mean, x, y, x + kBlock, y + kBlock, c).mean;
        const test::Moments d = test::regionMean(blur, x, y, x + kBlock, y + kBlock, c);
        // The noise, and sixteen instants standing for the interval's continuum.
        EXPECT_NEAR(d.mean, 0.0, 4.5 * d.stderr_ + 0.02 * level + 1e-3)
            << "block " << x << "," << y << " channel " << c;
        const test::Moments e = test::regionMean(still, x, y, x + kBlock, y + kBlock, c);
        blurOff += std::fabs(d.mean);
        sharpOff += std::fabs(e.mean);
      }
  // A shutter that did nothing would leave the two alike.
  EXPECT_GT(sharpOff, 3.0 * blurOff) << "the sharp frame should be farther from the mean";
}

// Each kind of motion: the quad sliding, the bar turning, next-event estimation finding the lamp
// where it is at the sample's time, the point light blended between its steps, a deforming
// mesh's triangles and vertices blended (morph, skin), the camera moving.
class MeanOfInstants : public ::testing::TestWithParam<Moving> {};

std::string motionName(const ::testing::TestParamInfo<Moving>& info) {
  static const char* const kNames[] = {"Sliding",  "Turning", "Camera",      "Lamp",   "PointLight",
                                       "Morphing", "Skinned", "SkinTurning", "Blinds", "Bounce"};
  return kNames[int(info.param)];
}

TEST_P(MeanOfInstants, TheBlurredFrameIsTheMeanOfItsInstants) {
  expectBlurIsTheMeanOfInstants(GetParam(), "mb-" + motionName({GetParam(), 0}));
}

// The same with path reuse: light paths that meet what moves while the shutter is open traced at
// their own time, joined to the camera then (T) and, from an x_1 the same at every time, to the
// samples (L); others joined at the samples' times; the eye paths' weights saying the same of the
// same segments.
TEST_P(MeanOfInstants, PathReuseGivesTheMeanOfItsInstants) {
  expectBlurIsTheMeanOfInstants(GetParam(), "mb-reuse-" + motionName({GetParam(), 0}), "reuse");
}

// Resampling across pixels and frames (shared/resample.h, "Under a shutter"): a neighbour's or
// the previous frame's path or light, sampled at another time, is taken only where it is the same
// at every time of both frames' intervals, and its new segment is traced at this sample's time.
// The path tracer's and path reuse's eye paths.
TEST_P(MeanOfInstants, ResamplingGivesTheMeanOfItsInstants) {
  const std::string name = motionName({GetParam(), 0});
  expectBlurIsTheMeanOfInstants(GetParam(), "mb-rs-" + name, "pathtrace",
                                "--resample --resample-neighbors 3");
  expectBlurIsTheMeanOfInstants(GetParam(), "mb-rs-reuse-" + name, "reuse",
                                "--resample --resample-neighbors 1");
}

INSTANTIATE_TEST_SUITE_P(MotionBlur, MeanOfInstants,
                         ::testing::Values(Moving::Object, Moving::Rotating, Moving::Lamp,
                                           Moving::Light, Moving::Morph, Moving::Skin,
                                           Moving::Camera, Moving::Blinds),
                         motionName);

// Strategy T under the shutter (light_trace, camera_splat): where a light path meets what moves,
// it is traced again at the slot's own time and joined to the camera then, weighted against N and
// H alone where L cannot make the path. The bounce scene's ceiling is lit through such paths only.
TEST(MotionBlur, LightTracingJoinsMovingPathsAtTheirOwnTime) {
  expectBlurIsTheMeanOfInstants(Moving::Bounce, "mb-reuse-bounce", "reuse");
}

// Strategy L under a still camera (connect's at_own): an x_1 whose segment from the camera meets
// nothing that moves is joined to a light path that does at the path's own time. Every path of
// the blinds scene's spot passes the slab's sweep, so L joins them only so; with the shutter open
// it finds about as many connections as in the sharp frame (where the slab is aside). Its
// weights are PathReuseGivesTheMeanOfItsInstants/Blinds'.
TEST(MotionBlur, AStillCameraJoinsLightPathsThatMeetWhatMoves) {
  auto candidates = [&](const std::string& shutter, const std::string& tag) {
    const std::string dir = test::tempDir(tag + "-out");
    const test::CommandResult r =
        test::runPathreuse("render " + blindsScene(tag) + " " + kArgs +
                           " --mode reuse --spp 4 --fps 1 --frames 1" + " --shutter " + shutter +
                           " --quiet --out " + dir + "/f_%04d.exr --stats " + dir + "/stats.jsonl");
    EXPECT_EQ(r.exitCode, 0) << r.err;
    const nlohmann::json line = nlohmann::json::parse(test::statsLines(dir).at(0));
    return line["counters"]["connection_candidates"].get<double>();
  };
  const double sharp = candidates("0", "mb-l-sharp");
  EXPECT_GT(sharp, 100.0);
  EXPECT_GT(candidates("0.5", "mb-l-blur"), 0.5 * sharp);
}

// The auxiliary images under a shutter: albedo blurred as the colour is (the mean of the instants'
// albedo, block by block), Z and object ids of the frame's own time (the sharp frame's).
TEST(MotionBlur, AlbedoIsBlurredAndZIsTheFramesOwn) {
  const std::string scene = movingScene(Moving::Object, "mb-aov");
  const std::string args = std::string(kArgs) + " --mode pathtrace --aov albedo,depth,object";
  const std::string blur =
      test::renderFrames(scene, "1", args + " --fps 1 --spp 64 --shutter 0.5", "mb-aov-blur");
  const std::string sharp = test::renderFrames(scene, "1", args + " --fps 1 --spp 64", "mb-aov-s");
  const std::string inst =
      test::renderFrames(scene, "49-79", args + " --fps 64 --spp 4", "mb-aov-inst");
  auto channel = [](const std::string& dir, int f, const char* name) {
    char file[32];
    std::snprintf(file, sizeof file, "/f_%04d.exr", f);
    return readExrChannel(dir + file, name);
  };
  const std::vector<float> zb = channel(blur, 1, "Z"), zs = channel(sharp, 1, "Z");
  const std::vector<float> ob = channel(blur, 1, "object.ID"), os = channel(sharp, 1, "object.ID");
  ASSERT_EQ(zb.size(), zs.size());
  for (size_t p = 0; p < zb.size(); ++p) {
    EXPECT_NEAR(zb[p], zs[p], 1e-4f * zs[p]) << "pixel " << p;
    EXPECT_EQ(ob[p], os[p]) << "pixel " << p;
  }
  const std::vector<float> ab = channel(blur, 1, "albedo.R"), as = channel(sharp, 1, "albedo.R");
  std::vector<float> am(ab.size(), 0.0f);
  for (int f = 49; f <= 79; f += 2) {
    const std::vector<float> a = channel(inst, f, "albedo.R");
    for (size_t p = 0; p < am.size(); ++p) am[p] += a[p] / 16.0f;
  }
  double blurOff = 0.0, sharpOff = 0.0;
  for (int y = 0; y < kH; y += kBlock)
    for (int x = 0; x < kW; x += kBlock) {
      double b = 0.0, s = 0.0, m = 0.0;
      for (int v = y; v < y + kBlock; ++v)
        for (int u = x; u < x + kBlock; ++u) {
          const size_t p = size_t(v) * kW + u;
          b += ab[p], s += as[p], m += am[p];
        }
      const double n = kBlock * kBlock;
      // Albedo is noiseless but for the pixel's jitter and the passes' times: a few per cent.
      EXPECT_NEAR(b / n, m / n, 0.05 * m / n + 0.01) << "block " << x << "," << y;
      blurOff += std::fabs(b - m) / n;
      sharpOff += std::fabs(s - m) / n;
    }
  EXPECT_GT(sharpOff, 3.0 * blurOff);
}

// The motion steps: none without a shutter, the fewest (3) for motion that blends exactly (a
// translation, a pan, a skin's joint sliding); a turn, of an instance or of a skin's joint (its
// vertices sweep arcs: a mesh placed by its joints alone, whose own transform never moves), takes
// more the finer the film, as the steps keep within half a pixel of it: 3 on a 16x12 film.
// The motion steps of scene `what` at time 1 with the shutter open `shutter` seconds, on a 4:3
// film `height` pixels high, within `pixels` (--motion-tolerance).
uint32_t motionStepsOf(Moving what, const std::string& tag, double shutter, int height,
                       double pixels = 0.5) {
  const Scene scene = loadScene(movingScene(what, tag));
  GpuScene gpu(test::testContext(), scene);
  gpu.setShutter(shutter, 0, height * 4 / 3, height, true, pixels);
  gpu.setTime(1.0);
  return gpu.motionSteps();
}

TEST(MotionBlur, StepsFollowTheMotion) {
  const auto stepsOf = [](Moving what, const std::string& tag, double shutter, int height) {
    return motionStepsOf(what, tag, shutter, height);
  };
  EXPECT_EQ(stepsOf(Moving::Object, "mb-steps-none", 0.0, 12), 1u);
  EXPECT_EQ(stepsOf(Moving::Object, "mb-steps-slide", 0.5, 1200), 3u);
  EXPECT_EQ(stepsOf(Moving::Camera, "mb-steps-camera", 0.5, 1200), 3u);
  EXPECT_EQ(stepsOf(Moving::Skin, "mb-steps-skin-slide", 0.5, 1200), 3u);
  for (Moving turning : {Moving::Rotating, Moving::SkinTurning}) {
    SCOPED_TRACE(int(turning));
    const std::string tag = "mb-steps-turn-" + std::to_string(int(turning));
    const uint32_t coarse = stepsOf(turning, tag, 0.5, 12);
    const uint32_t fine = stepsOf(turning, tag, 0.5, 1200);
    EXPECT_EQ(coarse, 3u);
    EXPECT_GT(fine, 3u);
    EXPECT_LE(fine, 33u);
    EXPECT_LE(stepsOf(turning, tag, 0.5, 120), fine);
  }
}

// A camera still over the shutter is one step, pt_generate's camera, the same bit for bit as the
// frame's (so it is not blended per sample); a moving one has every step.
TEST(MotionBlur, AStillCameraIsOneStep) {
  for (Moving what : {Moving::Object, Moving::Camera}) {
    SCOPED_TRACE(int(what));
    const Scene scene =
        loadScene(movingScene(what, "mb-still-camera-" + std::to_string(int(what))));
    GpuScene gpu(test::testContext(), scene);
    gpu.setShutter(0.5, 0, 160, 120);
    gpu.setTime(1.0);
    ASSERT_EQ(gpu.motionSteps(), 3u);
    if (what == Moving::Camera) {
      EXPECT_EQ(gpu.cameraMotionSteps(), 3u);
      continue;
    }
    EXPECT_EQ(gpu.cameraMotionSteps(), 1u);
    const dev::CameraParams frame = gpu.camera(0, 1.0, 160, 120);
    EXPECT_EQ(std::memcmp(&frame, &gpu.stillCamera(), sizeof frame), 0);
  }
}

// --motion-tolerance: a turn that half a pixel asks more steps of takes fewer under a looser
// tolerance, and never more; a slide blends exactly under any.
TEST(MotionBlur, ALooserToleranceTakesNoMoreSteps) {
  const auto stepsOf = [](Moving what, const std::string& tag, double pixels) {
    return motionStepsOf(what, tag, 0.5, 1200, pixels);
  };
  EXPECT_EQ(stepsOf(Moving::Object, "mb-tol-slide", 0.01), 3u);
  for (Moving turning : {Moving::Rotating, Moving::SkinTurning}) {
    SCOPED_TRACE(int(turning));
    const std::string tag = "mb-tol-turn-" + std::to_string(int(turning));
    const uint32_t tight = stepsOf(turning, tag, 0.5);
    const uint32_t loose = stepsOf(turning, tag, 8.0);
    EXPECT_GT(tight, 3u);
    EXPECT_LT(loose, tight);
    EXPECT_LE(stepsOf(turning, tag, 100.0), loose);
    EXPECT_GE(stepsOf(turning, tag, 0.05), tight);
  }
}

// The stats line says how many times the scene was placed at: a turn seen on a fine film takes
// more than a sharp frame's one (no field) or a slide's three.
TEST(MotionBlur, TheStatsLineGivesTheMotionSteps) {
  auto stepsOf = [&](Moving what, const std::string& tag, const std::string& extra) {
    const std::string dir = test::tempDir(tag + "-out");
    const test::CommandResult r = test::runPathreuse(
        "render " + movingScene(what, tag) + " --mode pathtrace --spp 1 --fps 1 --frames 1 " +
        extra + " --quiet --out " + dir + "/f_%04d.exr --stats " + dir + "/stats.jsonl");
    EXPECT_EQ(r.exitCode, 0) << r.err;
    const nlohmann::json line = nlohmann::json::parse(test::statsLines(dir).at(0));
    return line.contains("motion_steps") ? line["motion_steps"].get<int>() : 1;
  };
  EXPECT_EQ(stepsOf(Moving::Rotating, "mb-stats-sharp", "--width 16 --height 12"), 1);
  EXPECT_EQ(stepsOf(Moving::Object, "mb-stats-slide", "--width 16 --height 12 --shutter 0.5"), 3);
  const int turn =
      stepsOf(Moving::Rotating, "mb-stats-turn", "--width 640 --height 480 --shutter 0.5");
  EXPECT_GT(turn, 3);
  EXPECT_LT(stepsOf(Moving::Rotating, "mb-stats-loose",
                    "--width 640 --height 480 --shutter 0.5 --motion-tolerance 20"),
            turn);
}

// What is not built for an open shutter is refused in one line, exit 2: the connection history,
// and path reuse without the eye paths it weighs its connections against.
TEST(MotionBlur, RefusesWhatIsNotBuiltForAnOpenShutter) {
  const std::string scene = movingScene(Moving::Object, "mb-refuse");
  for (const char* extra :
       {"--mode reuse --no-eye-paths", "--mode retrace --connection-history 4"}) {
    SCOPED_TRACE(extra);
    const test::CommandResult r =
        test::runPathreuse("render " + scene + " " + extra + " --shutter 0.5 --frames 0 --out " +
                           test::tempDir("mb-refuse-out") + "/f_%04d.exr");
    EXPECT_EQ(r.exitCode, 2) << r.err;
    EXPECT_NE(r.err.find("--shutter"), std::string::npos) << r.err;
  }
}

}  // namespace
}  // namespace pr
