// The light BVH in whole renders, on the many-lights atrium (tools/scenes/gen_atrium.py --light
// lanterns: hundreds of small emitters, point and spot lights, an emitter on a moving
// instance): it converges to the same image as choosing lights by power, with less noise at
// the same sample count, path reuse still equals re-tracing bit for bit with it, and still
// lights keep their leaves. The exhaustive choice, on the atrium under its sky: the same
// image as by power, with less noise.
#include <gtest/gtest.h>

#include <cstdlib>
#include <map>
#include <string>

#include "portability/compare.h"
#include "support/render_helpers.h"
#include "support/test_env.h"

namespace pr {
namespace {

// tools/scenes/gen_atrium.py at a small tessellation (its emitters do not depend on the size) with
// --light `light`, generated once per test program.
std::string generatedAtrium(const std::string& light) {
  static std::map<std::string, std::string> paths;
  auto found = paths.find(light);
  if (found != paths.end()) return found->second;
  const std::string dir = test::tempDir(light + "-atrium-scene");
  const std::string out = dir + "/atrium.gltf";
  const std::string cmd = "cd '" + test::sourcePath("") +
                          "' && python3 -m tools.scenes.gen_atrium --size 0.05 --light " + light +
                          " --out '" + out + "' >/dev/null";
  if (std::system(cmd.c_str()) != 0) {
    ADD_FAILURE() << "could not generate the atrium: " << cmd;
    return "";
  }
  return paths[light] = out;
}

std::string lanternsScene() {
  return generatedAtrium("lanterns");
}

const char* kDirect = "--mode pathtrace --width 96 --height 54 --force-diffuse --max-depth 2";

// The scene's direct light chosen with `sampler` and by power: both unbiased (the high-sample
// images agree in mean within their noise, a few tenths of a percent here, and the one with
// `sampler` at 16 samples within 3%), and `sampler` at 16 samples has at least `gain` times less
// relMSE than power (each against the other's reference, so neither is favoured).
void expectUnbiasedWithLessNoise(const std::string& scene, const char* sampler, double gain) {
  ASSERT_FALSE(scene.empty());
  auto render = [&](const char* choice, int spp, int seed) {
    const std::string dir =
        test::renderFrames(scene, "0",
                           std::string(kDirect) + " --light-sampler " + choice + " --spp " +
                               std::to_string(spp) + " --seed " + std::to_string(seed),
                           std::string("choice-") + choice);
    return test::frameImage(dir, 0);
  };
  const Image refBetter = render(sampler, 256, 1), refPower = render("power", 256, 2);
  const Image better = render(sampler, 16, 3), power = render("power", 16, 3);
  const ImageDiff refs = compareImages(refPower, refBetter);
  EXPECT_NEAR(refs.meanLum, refs.refMeanLum, 0.01 * refs.refMeanLum);
  EXPECT_NEAR(compareImages(better, refBetter).meanLum, refs.refMeanLum, 0.03 * refs.refMeanLum);
  const double eBetter = compareImages(better, refPower).relMse;
  const double ePower = compareImages(power, refBetter).relMse;
  EXPECT_LT(eBetter * gain, ePower)
      << "relMSE with " << sampler << " " << eBetter << ", by power " << ePower;
}

// Many lanterns: the tree (with its resampled choice) has far less noise than power alone.
TEST(LightSampler, LightBvhConvergesToThePowerChoiceWithLessNoise) {
  expectUnbiasedWithLessNoise(lanternsScene(), "bvh", 1.5);
}

// Few lights, the atrium's sky quad (two large emissive triangles): weighing each from the
// shaded point (what auto takes here) is less noisy than power alone, which picks either half
// of the sky by its area wherever the point is.
TEST(LightSampler, ExhaustiveChoiceConvergesToThePowerChoiceWithLessNoise) {
  expectUnbiasedWithLessNoise(generatedAtrium("sky"), "exhaustive", 1.3);
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
