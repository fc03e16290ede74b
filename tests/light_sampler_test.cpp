// The light BVH in whole renders, on the many-lights atrium (tools/gen_atrium.py --light
// lanterns: hundreds of small emitters, point and spot lights, an emitter on a moving
// instance): it converges to the same image as choosing lights by power, with less noise at
// the same sample count, path reuse still equals re-tracing bit for bit with it, and still
// lights keep their leaves. The exhaustive choice, on the atrium under its sky: the same
// image as by power, with less noise.
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include "portability/compare.h"
#include "support/render_helpers.h"
#include "support/test_env.h"

namespace pr {
namespace {

// The lanterns atrium at a small tessellation (its emitters do not depend on the size).
std::string lanternsScene() {
  static std::string path;
  if (!path.empty()) return path;
  const std::string dir = test::tempDir("lanterns-scene");
  const std::string out = dir + "/atrium.gltf";
  const std::string cmd = "python3 '" + test::sourcePath("tools/gen_atrium.py") +
                          "' --size 0.05 --light lanterns --out '" + out + "' >/dev/null";
  if (std::system(cmd.c_str()) != 0) {
    ADD_FAILURE() << "could not generate the lanterns atrium: " << cmd;
    return "";
  }
  path = out;
  return path;
}

const char* kDirect = "--mode pathtrace --width 96 --height 54 --force-diffuse --max-depth 2";

TEST(LightSampler, LightBvhConvergesToThePowerChoiceWithLessNoise) {
  const std::string scene = lanternsScene();
  ASSERT_FALSE(scene.empty());
  auto render = [&](const char* sampler, int spp, int seed) {
    const std::string dir =
        test::renderFrames(scene, "0",
                           std::string(kDirect) + " --light-sampler " + sampler + " --spp " +
                               std::to_string(spp) + " --seed " + std::to_string(seed),
                           std::string("lanterns-") + sampler);
    return test::frameImage(dir, 0);
  };
  const Image refBvh = render("bvh", 256, 1), refPower = render("power", 256, 2);
  const Image bvh = render("bvh", 16, 3), power = render("power", 16, 3);
  // Both unbiased: the high-sample images agree in mean (within their noise, a few tenths of a
  // percent here), and the choice by power at 16 samples is no closer to either.
  const ImageDiff refs = compareImages(refPower, refBvh);
  EXPECT_NEAR(refs.meanLum, refs.refMeanLum, 0.01 * refs.refMeanLum);
  EXPECT_NEAR(compareImages(bvh, refBvh).meanLum, refs.refMeanLum, 0.03 * refs.refMeanLum);
  // Less noise at the same sample count (measured at this size: relMSE 2.3 times lower).
  const double eBvh = compareImages(bvh, refPower).relMse;
  const double ePower = compareImages(power, refBvh).relMse;
  EXPECT_LT(eBvh * 1.5, ePower) << "relMSE with the light BVH " << eBvh << ", by power " << ePower;
}

// The atrium lit by its sky quad (two large emissive triangles), at a small tessellation.
std::string skyScene() {
  static std::string path;
  if (!path.empty()) return path;
  const std::string dir = test::tempDir("sky-atrium-scene");
  const std::string out = dir + "/atrium.gltf";
  const std::string cmd = "python3 '" + test::sourcePath("tools/gen_atrium.py") +
                          "' --size 0.05 --out '" + out + "' >/dev/null";
  if (std::system(cmd.c_str()) != 0) {
    ADD_FAILURE() << "could not generate the atrium: " << cmd;
    return "";
  }
  path = out;
  return path;
}

// Few lights: weighing each from the shaded point (what auto takes here) is unbiased and less
// noisy than power alone, which picks either half of the sky by its area wherever the point is.
TEST(LightSampler, ExhaustiveChoiceConvergesToThePowerChoiceWithLessNoise) {
  const std::string scene = skyScene();
  ASSERT_FALSE(scene.empty());
  auto render = [&](const char* sampler, int spp, int seed) {
    const std::string dir =
        test::renderFrames(scene, "0",
                           std::string(kDirect) + " --light-sampler " + sampler + " --spp " +
                               std::to_string(spp) + " --seed " + std::to_string(seed),
                           std::string("sky-") + sampler);
    return test::frameImage(dir, 0);
  };
  const Image refExh = render("exhaustive", 256, 1), refPower = render("power", 256, 2);
  const Image exh = render("exhaustive", 16, 3), power = render("power", 16, 3);
  const ImageDiff refs = compareImages(refPower, refExh);
  EXPECT_NEAR(refs.meanLum, refs.refMeanLum, 0.01 * refs.refMeanLum);
  EXPECT_NEAR(compareImages(exh, refExh).meanLum, refs.refMeanLum, 0.03 * refs.refMeanLum);
  const double eExh = compareImages(exh, refPower).relMse;
  const double ePower = compareImages(power, refExh).relMse;
  EXPECT_LT(eExh * 1.3, ePower) << "relMSE weighing each light " << eExh << ", by power " << ePower;
}

TEST(LightSampler, ReuseEqualsRetraceWithTheLightBvh) {
  const std::string scene = lanternsScene();
  ASSERT_FALSE(scene.empty());
  const std::string common = " --width 48 --height 27 --spp 2 --light-sampler bvh --fps 4";
  const std::string reuse = test::renderFrames(scene, "0-2", "--mode reuse" + common, "lbvh-reuse");
  const std::string retrace =
      test::renderFrames(scene, "0-2", "--mode retrace" + common, "lbvh-retrace");
  for (int f = 0; f <= 2; ++f) {
    const Image a = test::frameImage(reuse, f), b = test::frameImage(retrace, f);
    ASSERT_EQ(a.rgba.size(), b.rgba.size());
    EXPECT_TRUE(a.rgba == b.rgba) << "frame " << f;
    EXPECT_GT(compareImages(a, b).meanLum, 0.0);
  }
}

// Once emitters stop moving (past the animation's 10 s) the tree is neither refitted nor
// uploaded again, and every light keeps its leaf: with the camera noise frozen, the frames are
// the same bit for bit (lights that lost their leaf give MIS weights from the wrong pmf).
TEST(LightSampler, StillLightsKeepTheirLeavesFromFrameToFrame) {
  const std::string scene = lanternsScene();
  ASSERT_FALSE(scene.empty());
  const std::string dir = test::renderFrames(
      scene, "10-12",
      "--mode pathtrace --fps 1 --fixed-noise --light-sampler bvh --width 64 --height 36 --spp 4",
      "lbvh-still");
  const Image first = test::frameImage(dir, 10);
  for (int f = 11; f <= 12; ++f) EXPECT_TRUE(test::frameImage(dir, f).rgba == first.rgba) << f;
}

}  // namespace
}  // namespace pr
