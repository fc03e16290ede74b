// --noise-threshold (render/film.h, kernels/adaptive.cl): after a pilot every pixel takes, each
// pixel gets a budget of samples from its neighbours' estimated relative error. Its samples'
// mean stays an unbiased estimate (the budget never depends on the pixel's own samples), the
// samples go where the image is noisy, and --aov samples writes each pixel's count.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/image.h"
#include "support/gltf_builder.h"
#include "support/render_helpers.h"
#include "support/test_env.h"

namespace pr::test {
namespace {

// Region by region (4 x 4), the adaptive render's mean against the uniform one's of the same
// seed: their difference, within 4.5 of its standard errors. The same seed gives both the same
// light paths (strategy T's splats cancel) and the same pilot passes; the difference of a pixel
// is then its pilot's, or its first passes', departure from all 64 passes, which are unbiased
// as the budget of a pixel does not depend on its own samples. These departures are independent
// between the pixels of a region where no two of them connect to the same stored light paths:
// pixel i's pass s takes slots (64 i + s) C mod the slot count, so four times as many slots as
// pixels put the next pixel with the same ones 4.5 rows and 48 columns away. (Mutations
// checked: T's splats left at spp's scale; a pixel that skips a pass counted as a zero sample.)
void expectSameMeans(const std::string& scene, const std::string& mode, const std::string& tag) {
  const std::string size =
      " --width 96 --height 72 --seed 3 --spp 64 --light-paths 27648 --mode " + mode;
  const std::string adaptive =
      renderFrames(scene, "0", size + " --noise-threshold 0.2 --adaptive-min-spp 4", tag);
  const std::string uniform = renderFrames(scene, "0", size, tag + "_u");
  const nlohmann::json spp = nlohmann::json::parse(statsLines(adaptive)[0])["spp"];
  // It took fewer samples than the uniform render, some pixels many more than the pilot.
  EXPECT_LT(spp["mean"].get<double>(), 40.0) << spp;
  EXPECT_GT(spp["max"].get<int>(), 16) << spp;
  const Image a = frameImage(adaptive, 0), u = frameImage(uniform, 0);
  Image d = a;
  for (size_t k = 0; k < d.rgba.size(); ++k) d.rgba[k] -= u.rgba[k];
  for (int c = 0; c < 3; c += 2)
    for (int ry = 0; ry < 4; ++ry)
      for (int rx = 0; rx < 4; ++rx) {
        const int x0 = rx * 24, y0 = ry * 18;
        const Moments md = regionMean(d, x0, y0, x0 + 24, y0 + 18, c);
        EXPECT_LT(std::fabs(md.mean), 4.5 * md.stderr_ + 1e-6)
            << "region " << rx << "," << ry << " channel " << c << ": "
            << regionMean(a, x0, y0, x0 + 24, y0 + 18, c).mean << " against "
            << regionMean(u, x0, y0, x0 + 24, y0 + 18, c).mean;
      }
}

TEST(Adaptive, ConvergesToTheUniformMeanWithPathReuse) {
  // T's splats must be weighed by each pixel's own count.
  expectSameMeans(glossyReflectionScene("adaptive_mirror"), "reuse", "adaptive_reuse");
}

TEST(Adaptive, ConvergesToTheUniformMeanWithThePathTracer) {
  expectSameMeans(glossyReflectionScene("adaptive_mirror"), "pathtrace", "adaptive_pt");
}

// A floor with a ball on it under a white sky, the horizon across the middle of the image: the
// sky's pixels have no variance and keep the pilot's samples; the floor's, shadowed by the ball
// and lit by the whole sky, take many more.
TEST(Adaptive, SpendsFewerSamplesWhereTheImageIsSmooth) {
  GltfBuilder b;
  const int white = b.addMaterial({glm::vec4(0.7f, 0.7f, 0.7f, 1.0f)});
  b.addNode(b.addQuad({-50, 0, 50}, {50, 0, 50}, {50, 0, -50}, {-50, 0, -50}, white));
  b.addNode(b.addSphere(1.0f, 24, 12, white), {0.0f, 1.0f, 0.0f});
  b.addCamera({0, 1, 6}, {0, 1, 0}, 0.9f, 1.0f);
  const std::string scene = b.write(tempDir("adaptive_sky"), "sky");
  const int size = 48, pilot = 4, spp = 64;
  const std::string args = " --width 48 --height 48 --env-color 1,1,1 --force-diffuse --spp " +
                           std::to_string(spp) + " --aov samples ";
  const std::string dir = renderFrames(
      scene, "0", args + "--noise-threshold 0.05 --adaptive-min-spp " + std::to_string(pilot),
      "adaptive_sky");
  const std::vector<float> n = readExrChannel(dir + "/f_0000.exr", "samples");
  ASSERT_EQ(n.size(), size_t(size * size));
  for (int y = 0; y < 8; ++y)  // sky: every neighbour exact
    for (int x = 0; x < size; ++x)
      EXPECT_EQ(n[size_t(y) * size + x], float(pilot)) << x << "," << y;
  double floor = 0.0;
  for (int y = size * 3 / 4; y < size; ++y)
    for (int x = 0; x < size; ++x) floor += n[size_t(y) * size + x];
  floor /= size * (size / 4);
  EXPECT_GT(floor, 4.0 * pilot);
  EXPECT_LE(*std::max_element(n.begin(), n.end()), float(spp));
  // The stats line's mean is the channel's.
  const nlohmann::json s = nlohmann::json::parse(statsLines(dir)[0])["spp"];
  EXPECT_NEAR(s["mean"].get<double>(), std::accumulate(n.begin(), n.end(), 0.0) / n.size(), 1e-6);
  // Without a threshold every pixel has spp.
  const std::string uniform = renderFrames(scene, "0", args, "adaptive_sky_u");
  for (float c : readExrChannel(uniform + "/f_0000.exr", "samples")) ASSERT_EQ(c, float(spp));
}

TEST(Adaptive, BadSettingsAreInputErrors) {
  const std::string scene = sourcePath("scenes/cornell-dynamic.gltf");
  const std::string out = tempDir("adaptive_bad");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--noise-threshold -1", "--noise-threshold"},
      {"--noise-threshold 0.1 --spp 1", "--noise-threshold"},
      {"--noise-threshold 0.1 --spp 8 --adaptive-min-spp 1", "--adaptive-min-spp"},
      {"--noise-threshold 0.1 --spp 8 --adaptive-min-spp 9", "--adaptive-min-spp"},
      {"--noise-threshold 0.1 --connection-history 4", "--noise-threshold"}};
  for (const auto& [bad, name] : cases) {
    const auto r = runPathreuse("render '" + scene + "' --quiet --frames 0 --width 16 --out '" +
                                out + "/f_%04d.exr' " + bad);
    EXPECT_EQ(r.exitCode, 2) << bad;
    EXPECT_NE(r.err.find(name), std::string::npos) << r.err;
    EXPECT_EQ(lineCount(r.err), 1u) << r.err;
  }
}

TEST(Adaptive, SeveralDevicesAreAnInputError) {
  const std::string scene = sourcePath("scenes/cornell-dynamic.gltf");
  const auto r = runPathreuse("render '" + scene + "' --quiet --frames 0 --width 16 --out '" +
                                  tempDir("adaptive_devices") +
                                  "/f_%04d.exr' --noise-threshold 0.1" + twoPoclDevices(),
                              kTwoPoclDrivers);
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_NE(r.err.find("--noise-threshold: renders on one device"), std::string::npos) << r.err;
  EXPECT_EQ(lineCount(r.err), 1u) << r.err;
}

}  // namespace
}  // namespace pr::test
