// Path resampling across pixels and frames (--resample, kernels/pathtrace/resample.cl): it
// converges to the path tracer's image, in a white furnace to le / (1 - albedo), on the demo scene
// region by region and behind slats that hide most neighbours' paths from each other; taking the
// neighbours' paths lowers the error at the same sample count, and so does taking the previous
// frames'; where objects move, the paths their motion disturbs are left behind. Mutations checked
// by hand when this was written: a dropped reconnection Jacobian fails the furnace and the demo's
// regions; a skipped reconnection shadow ray fails the slats; taking every previous path fails the
// shelf, and so does a reshaped shelf's present shape taken for its previous one; the direct
// light's canonical MIS term dropped, or its shadow ray skipped, fails the direct-light scene.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "portability/compare.h"
#include "support/gltf_builder.h"
#include "support/render_helpers.h"
#include "support/test_env.h"

namespace pr {
namespace {

using test::Moments;
using test::regionMean;

std::string demoScene() {
  return test::sourcePath("scenes/cornell-dynamic.gltf");
}

Image render(const std::string& scene, const std::string& args, const std::string& tag) {
  return test::frameImage(test::renderFrames(scene, "0", "--mode pathtrace " + args, tag), 0);
}

// The path tracer's demo at 96 x 72 and 1024 spp.
Image demoReference() {
  return render(demoScene(), "--width 96 --height 72 --spp 1024 --seed 1", "rs-demo-ref");
}

// Each 12 x 12 region of the image that is not dark (the sum of its channels' means at least
// 0.03 in ref) has the mean of ref's within tol of it; more than min_regions such regions.
void expectRegionsAgree(const Image& img, const Image& ref, double tol, int min_regions = 30) {
  int regions = 0;
  for (int y = 0; y + 12 <= ref.height; y += 12) {
    for (int x = 0; x + 12 <= ref.width; x += 12) {
      double a = 0, r = 0;
      for (int c = 0; c < 3; ++c) {
        a += regionMean(img, x, y, x + 12, y + 12, c).mean;
        r += regionMean(ref, x, y, x + 12, y + 12, c).mean;
      }
      if (r < 0.03) continue;
      ++regions;
      EXPECT_NEAR(a, r, tol * r) << "region at " << x << ", " << y;
    }
  }
  EXPECT_GT(regions, min_regions);
}

// Animates node over frames 0-5 (one a second) by a(f): moved by a(f) shift, or, where morph, its
// morph target (which moves it by shift) weighted a(f).
void animateFrames(test::GltfBuilder* b, int node, bool morph, float (*a)(int), glm::vec3 shift) {
  std::vector<float> times;
  std::vector<glm::vec3> keys;
  std::vector<std::vector<float>> weights;
  for (int f = 0; f <= 5; ++f) {
    times.push_back(float(f));
    keys.push_back(shift * a(f));
    weights.push_back({a(f)});
  }
  if (morph)
    b->animateWeights(node, times, weights);
  else
    b->animateTranslation(node, times, keys);
}

// Every surface emits le and reflects albedo (diffuse): every pixel sees le / (1 - albedo); the
// resampled paths carry all but the first two vertices' light, so a wrong weight or Jacobian
// moves the answer.
TEST(Resample, WhiteFurnaceConvergesToLeOverOneMinusAlbedo) {
  const float albedo = 0.5f, le = 1.0f;
  test::GltfBuilder b;
  const int mat = b.addMaterial({glm::vec4(albedo, albedo, albedo, 1), 0, 1, glm::vec3(le), 1.0f});
  b.addNode(b.addBox(glm::vec3(-1), glm::vec3(1), mat, true));
  b.addCamera(glm::vec3(0.1f, 0.2f, 0.3f), glm::vec3(1, 0.5f, -1), 1.2f, 1.0f);
  const std::string scene = b.write(test::tempDir("rs-furnace"), "furnace");
  const int spp = 512;
  const Image img =
      render(scene,
             "--width 32 --height 32 --max-depth 16 --force-diffuse --resample --spp " +
                 std::to_string(spp),
             "rs-furnace-out");
  const double expected = le / (1.0 - albedo);  // depth 16 leaves out albedo^16 of it
  for (int c = 0; c < 3; ++c) {
    const Moments m = regionMean(img, 0, 0, 32, 32, c);
    // Neighbours share paths, so pixels are not independent: a wider margin than 5 errors.
    EXPECT_NEAR(m.mean, expected, 10 * m.stderr_ + 2e-3) << "channel " << c;
  }
}

// The demo scene (glossy and diffuse, an area light): resampled with neighbours, each 12 x 12
// region's mean agrees with the path tracer's within 5% (the noise leaves under 3% here; the
// pixels' spread within a region is mostly the image's own detail, so no standard error is used).
// Without the reconnection Jacobian regions are up to 19% off.
TEST(Resample, ConvergesToThePathTracerRegionByRegion) {
  const std::string size = "--width 96 --height 72 ";
  const Image ref = demoReference();
  const Image img = render(demoScene(), size + "--spp 512 --seed 2 --resample", "rs-demo");
  expectRegionsAgree(img, ref, 0.05);
}

// Slats on a lit floor: a pixel's neighbours' x_2 often lie behind a slat from its x_1, which
// only the reconnection's shadow ray tells.
TEST(Resample, SlatsHideNeighboursPaths) {
  test::GltfBuilder b;
  const int white = b.addMaterial({glm::vec4(0.8f, 0.8f, 0.8f, 1), 0, 1});
  const int lamp = b.addMaterial({glm::vec4(0, 0, 0, 1), 0, 1, glm::vec3(1.0f), 20.0f});
  b.addNode(b.addQuad({-3, 0, -3}, {-3, 0, 3}, {3, 0, 3}, {3, 0, -3}, white));
  for (int i = 0; i < 8; ++i) {
    const float x = -1.75f + 0.5f * float(i);
    b.addNode(b.addBox(glm::vec3(x - 0.02f, 0, -2), glm::vec3(x + 0.02f, 1.0f, 2), white));
  }
  b.addNode(b.addQuad({2.0f, 2.5f, -0.5f}, {3.0f, 2.5f, -0.5f}, {3.0f, 2.5f, 0.5f},
                      {2.0f, 2.5f, 0.5f}, lamp));
  b.addCamera(glm::vec3(-0.3f, 2.5f, 2.5f), glm::vec3(0.0f, 0.0f, 0.0f), 0.9f, 4.0f / 3.0f);
  const std::string scene = b.write(test::tempDir("rs-slats"), "slats");
  const std::string size = "--width 96 --height 72 --force-diffuse --max-depth 5 ";
  const Image ref = render(scene, size + "--spp 2048 --seed 1", "rs-slats-ref");
  const Image img = render(
      scene, size + "--spp 1024 --seed 2 --resample --resample-neighbors 3 --resample-radius 16",
      "rs-slats");
  expectRegionsAgree(img, ref, 0.04);
}

// A shelf shades the lower half of a wall lit from above on even frames and is lifted far away
// on odd ones; the camera sees the floor, lit by the wall. Frame 5, resampled with the history of
// frames 0-4, agrees with the path tracer's region by region: the previous frame's paths whose
// light the shelf blocked (or no longer blocks) are not reused. Reusing every path of the
// previous frame instead fails it.
// A shelf under a lamp, in place in even frames and far above in odd ones (its shadow on the wall
// comes and goes). It is moved (translated) or reshaped (a morph target moves its vertices), whose
// shape of the previous frame the temporal test takes from the BVH kept for it; frame 5 resampled
// with the previous frames' paths agrees with the path tracer region by region.
class TemporalShelf : public testing::TestWithParam<bool> {};

TEST_P(TemporalShelf, ReuseLeavesPathsThatMovingObjectsDisturb) {
  const bool morph = GetParam();
  test::GltfBuilder b;
  const int white = b.addMaterial({glm::vec4(0.8f, 0.8f, 0.8f, 1), 0, 1});
  const int lamp = b.addMaterial({glm::vec4(0, 0, 0, 1), 0, 1, glm::vec3(1.0f), 10.0f});
  b.addNode(b.addQuad({-3, 0, -3}, {-3, 0, 3}, {3, 0, 3}, {3, 0, -3}, white));
  b.addNode(b.addQuad({-3, 0, -2}, {3, 0, -2}, {3, 3, -2}, {-3, 3, -2}, white));
  b.addNode(b.addQuad({-1.0f, 2.9f, -1.5f}, {1.0f, 2.9f, -1.5f}, {1.0f, 2.9f, -0.5f},
                      {-1.0f, 2.9f, -0.5f}, lamp));
  const glm::vec3 up(0, 20.0f, 0);
  const int shelf = b.addNode(b.addBox(glm::vec3(-3, 1.4f, -2), glm::vec3(3, 1.5f, -0.9f), white,
                                       false, morph ? up : glm::vec3(0.0f)));
  animateFrames(
      &b, shelf, morph, [](int f) { return f % 2 ? 1.0f : 0.0f; }, up);
  b.addCamera(glm::vec3(0, 2.2f, 3.0f), glm::vec3(0, 0.2f, -0.5f), 0.9f, 4.0f / 3.0f);
  const std::string tag = morph ? "rs-shelf-morph" : "rs-shelf";
  const std::string scene = b.write(test::tempDir(tag), "shelf");
  const std::string size = "--width 64 --height 48 --fps 1 --force-diffuse --max-depth 5 ";
  const Image ref = test::frameImage(
      test::renderFrames(scene, "5", "--mode pathtrace " + size + "--spp 2048 --seed 1",
                         tag + "-ref"),
      5);
  const Image img = test::frameImage(
      test::renderFrames(scene, "0-5", "--mode pathtrace " + size + "--spp 128 --seed 2 --resample",
                         tag),
      5);
  expectRegionsAgree(img, ref, 0.04, 10);
}

INSTANTIATE_TEST_SUITE_P(Resample, TemporalShelf, testing::Values(false, true),
                         [](const testing::TestParamInfo<bool>& i) {
                           return std::string(i.param ? "Reshaped" : "Moved");
                         });

// A wall that slides sideways fills the view (moved rigidly, or reshaped by a morph target that
// moves its vertices alike), lit by a lamp and a sky: every x_1 lies on what moved. The previous
// frame's x_1 are rebuilt on that frame's shapes (GpuScene::keepPrevious), so their paths are
// taken: frame 3 resampled with the history of frames 0-2 has less error than without it, and
// frame 5 agrees with the path tracer region by region. Taking no path of an x_1 that moved fails
// the first (checked by hand); its present shape for its previous one, a sliding plane, is not
// seen by either. The sky is weighed by its whole power in light sampling's choice, so that the
// lamp's direct light is noisy and the previous frames have error to take away: with the sky's
// uniform part left to BSDF sampling (the default) the path tracer's error is 24x lower here and
// a history of 20 frames no longer lowers it (docs/experiments/env-light-choice.md).
class TemporalOnMoved : public testing::TestWithParam<bool> {};

TEST_P(TemporalOnMoved, PathsOfMovingSurfacesAreTaken) {
  const bool morph = GetParam();
  test::GltfBuilder b;
  const int white = b.addMaterial({glm::vec4(0.8f, 0.8f, 0.8f, 1), 0, 1});
  const int lamp = b.addMaterial({glm::vec4(0, 0, 0, 1), 0, 1, glm::vec3(1.0f), 10.0f});
  b.addNode(b.addQuad({-6, 0, -3}, {-6, 0, 3}, {6, 0, 3}, {6, 0, -3}, white));
  b.addNode(b.addQuad({-1.0f, 3.5f, 0.5f}, {1.0f, 3.5f, 0.5f}, {1.0f, 3.5f, 1.5f},
                      {-1.0f, 3.5f, 1.5f}, lamp));
  const glm::vec3 step(0.03f, 0, 0);
  const int wall = b.addNode(b.addBox(glm::vec3(-4, 0, -1.0f), glm::vec3(4, 3, -0.6f), white, false,
                                      morph ? step * 10.0f : glm::vec3(0.0f)));
  animateFrames(
      &b, wall, morph, [](int f) { return 0.1f * float(f); }, step * 10.0f);
  b.addCamera(glm::vec3(0, 1.6f, 2.2f), glm::vec3(0, 1.4f, -0.6f), 0.9f, 4.0f / 3.0f);
  const std::string tag = morph ? "rs-moved-wall-morph" : "rs-moved-wall";
  const std::string scene = b.write(test::tempDir(tag), "wall");
  const std::string args =
      "--mode pathtrace --width 64 --height 48 --fps 1 --force-diffuse --max-depth 4 "
      "--env-color 0.3,0.35,0.4 --env-light-choice power ";
  auto frame = [&](const std::string& frames, int f, const std::string& more,
                   const std::string& t) {
    return test::frameImage(test::renderFrames(scene, frames, args + more, tag + t), f);
  };
  const Image ref3 = frame("3", 3, "--spp 1024 --seed 1", "-ref3");
  const Image none = frame("0-3", 3, "--spp 8 --seed 2 --resample --resample-history 0", "-h0");
  const Image kept = frame("0-3", 3, "--spp 8 --seed 2 --resample", "-h20");
  const double eNone = compareImages(none, ref3).relMse, eKept = compareImages(kept, ref3).relMse;
  EXPECT_LT(eKept * 1.2, eNone) << "relMSE with history " << eKept << ", without " << eNone;
  const Image ref5 = frame("5", 5, "--spp 2048 --seed 1", "-ref5");
  expectRegionsAgree(frame("0-5", 5, "--spp 128 --seed 2 --resample", "-conv"), ref5, 0.04, 10);
}

INSTANTIATE_TEST_SUITE_P(Resample, TemporalOnMoved, testing::Values(false, true),
                         [](const testing::TestParamInfo<bool>& i) {
                           return std::string(i.param ? "Reshaped" : "Moved");
                         });

// Direct light alone (--max-depth 2: every term is x_1's, so the direct light's reservoir holds
// all of it): an emissive quad, a point light, a directional light and the environment over a
// diffuse floor, a glossy metal block and a box that shadows part of the floor from each.
// Resampled with three neighbours within 16 pixels and with the previous frames' lights (a still
// scene, frames 0-3), frame 3 agrees with the path tracer region by region.
TEST(Resample, DirectLightOfEveryKindConverges) {
  test::GltfBuilder b;
  const int white = b.addMaterial({glm::vec4(0.7f, 0.7f, 0.7f, 1), 0, 1});
  const int metal = b.addMaterial({glm::vec4(0.9f, 0.6f, 0.3f, 1), 1, 0.35f});
  const int lamp = b.addMaterial({glm::vec4(0, 0, 0, 1), 0, 1, glm::vec3(1.0f), 8.0f});
  b.addNode(b.addQuad({-3, 0, -3}, {-3, 0, 3}, {3, 0, 3}, {3, 0, -3}, white));
  b.addNode(b.addBox(glm::vec3(-0.4f, 0, -0.4f), glm::vec3(0.4f, 0.8f, 0.4f), white));
  b.addNode(b.addBox(glm::vec3(0.9f, 0, -1.6f), glm::vec3(1.9f, 0.5f, -0.6f), metal));
  b.addNode(b.addQuad({-2.0f, 2.0f, -1.0f}, {-1.0f, 2.0f, -1.0f}, {-1.0f, 2.0f, 0.0f},
                      {-2.0f, 2.0f, 0.0f}, lamp));
  b.addPointLight(glm::vec3(1.5f, 1.5f, 1.0f), glm::vec3(1.0f, 0.8f, 0.6f), 6.0f);
  b.addDirectionalLight(glm::angleAxis(-1.0f, glm::vec3(1, 0, 0)), glm::vec3(0.6f, 0.7f, 1.0f),
                        1.5f);
  b.addCamera(glm::vec3(0.0f, 3.0f, 3.5f), glm::vec3(0.0f, 0.0f, 0.0f), 0.9f, 4.0f / 3.0f);
  const std::string scene = b.write(test::tempDir("rs-direct"), "direct");
  const std::string args =
      "--mode pathtrace --width 96 --height 72 --fps 1000 --max-depth 2 "
      "--env-color 0.3,0.35,0.4 ";
  const Image ref = test::frameImage(
      test::renderFrames(scene, "3", args + "--spp 1024 --seed 1", "rs-direct-ref"), 3);
  const Image img = test::frameImage(
      test::renderFrames(
          scene, "0-3",
          args + "--spp 256 --seed 2 --resample --resample-neighbors 3 --resample-radius 16",
          "rs-direct"),
      3);
  expectRegionsAgree(img, ref, 0.03);
}

// With --resample a pixel's samples sit at the same points of the pixel in every frame, so that
// the previous frame's x_1 is this one's where nothing moved: the demo slowed down (--fps 1000)
// and seen through --max-depth 1 (the emission at x_1 alone: the light, which does not move, and
// the points) gives the same frame twice, where the path tracer's points, drawn again each
// frame, do not.
TEST(Resample, PixelPositionsStayFromFrameToFrame) {
  const std::string args = "--mode pathtrace --width 48 --height 36 --max-depth 1 --spp 2 ";
  const std::string still =
      test::renderFrames(demoScene(), "0-1", args + "--fps 1000 --resample", "rs-positions");
  EXPECT_EQ(test::frameImage(still, 0).rgba, test::frameImage(still, 1).rgba);
  const std::string fresh =
      test::renderFrames(demoScene(), "0-1", args + "--fps 1000", "rs-positions-pt");
  EXPECT_NE(test::frameImage(fresh, 0).rgba, test::frameImage(fresh, 1).rgba);
}

// Three neighbours' paths at each pixel: less error than the pixel's own paths alone at the same
// samples, against a reference of the path tracer.
TEST(Resample, NeighboursLowerTheError) {
  const std::string size = "--width 96 --height 72 ";
  const Image ref = demoReference();
  const Image own =
      render(demoScene(), size + "--spp 8 --seed 2 --resample --resample-neighbors 0", "rs-own");
  const Image shared =
      render(demoScene(), size + "--spp 8 --seed 2 --resample --resample-neighbors 3", "rs-shared");
  const double eOwn = compareImages(own, ref).relMse, eShared = compareImages(shared, ref).relMse;
  EXPECT_LT(eShared * 1.2, eOwn) << "relMSE with neighbours " << eShared << ", alone " << eOwn;
}

// The previous frames' paths at each pixel: frame 3 of a sequence resampled with the history of
// frames 0-2 has less error than without it, at the same samples. The animation is slowed down
// (--fps 1000) so that frame 3 is the reference's frame 0 but for its moving objects' few
// micrometres, which the error test for temporal reuse leaves out.
TEST(Resample, HistoryLowersTheError) {
  const std::string args = "--mode pathtrace --width 96 --height 72 --fps 1000 --spp 8 --seed 2 ";
  const Image ref = demoReference();
  const Image none = test::frameImage(
      test::renderFrames(demoScene(), "0-3", args + "--resample --resample-history 0", "rs-h0"), 3);
  const Image kept =
      test::frameImage(test::renderFrames(demoScene(), "0-3", args + "--resample", "rs-h20"), 3);
  const double eNone = compareImages(none, ref).relMse, eKept = compareImages(kept, ref).relMse;
  EXPECT_LT(eKept * 1.2, eNone) << "relMSE with history " << eKept << ", without " << eNone;
}

// --mode reuse with --resample: the eye paths are resampled, each path weighted by its share
// against the connections to stored light paths as rebuilt at the x_1 it moves to
// (rs_eye_share), and the connections are added as without it. The demo converges to the path
// tracer's image region by region.
TEST(Resample, WithReuseConvergesToThePathTracerRegionByRegion) {
  const Image ref = demoReference();
  const Image img = test::frameImage(
      test::renderFrames(demoScene(), "0",
                         "--mode reuse --width 96 --height 72 --spp 512 --seed 2 --resample "
                         "--resample-neighbors 3 --resample-radius 16",
                         "rs-reuse"),
      0);
  expectRegionsAgree(img, ref, 0.05);
}

// A lamp above an opaque shade lights a spot on the ceiling, and the spot lights the floor the
// camera sees. The stored light paths make those floor-ceiling-lamp paths far more densely than
// the eye paths' BSDF samples from the floor do, so the eye paths keep a small share of them,
// which differs from one x_1 to the next. Resampled in --mode reuse with neighbours and the
// previous frames' paths, frame 3 agrees with the path tracer region by region; giving a path
// the eye path's whole weight where a neighbour takes it puts the floor's regions about 6% too
// high.
TEST(Resample, WithReuseWeighsEachPathAtItsNewFirstVertex) {
  test::GltfBuilder b;
  const int white = b.addMaterial({glm::vec4(0.8f, 0.8f, 0.8f, 1), 0, 1});
  const int lamp = b.addMaterial({glm::vec4(0, 0, 0, 1), 0, 1, glm::vec3(1.0f), 40.0f});
  b.addNode(b.addQuad({-3, 0, -3}, {-3, 0, 3}, {3, 0, 3}, {3, 0, -3}, white));
  b.addNode(b.addQuad({-3, 3, -3}, {3, 3, -3}, {3, 3, 3}, {-3, 3, 3}, white));
  b.addNode(b.addBox(glm::vec3(-0.4f, 2.45f, -0.4f), glm::vec3(0.4f, 2.5f, 0.4f), white));
  b.addNode(b.addQuad({-0.2f, 2.55f, -0.2f}, {-0.2f, 2.55f, 0.2f}, {0.2f, 2.55f, 0.2f},
                      {0.2f, 2.55f, -0.2f}, lamp));
  b.addCamera(glm::vec3(0.0f, 2.0f, 4.0f), glm::vec3(0.0f, 0.0f, -0.5f), 0.9f, 4.0f / 3.0f);
  const std::string scene = b.write(test::tempDir("rs-shade"), "shade");
  const std::string args = " --width 64 --height 48 --fps 1000 --max-depth 3 --force-diffuse ";
  const Image ref = test::frameImage(
      test::renderFrames(scene, "3", "--mode pathtrace" + args + "--spp 2048 --seed 1",
                         "rs-shade-ref"),
      3);
  const Image img = test::frameImage(
      test::renderFrames(scene, "0-3",
                         "--mode reuse" + args +
                             "--spp 256 --seed 2 --resample --resample-neighbors 3 "
                             "--resample-radius 16",
                         "rs-shade"),
      3);
  expectRegionsAgree(img, ref, 0.04, 10);
}

// With --resample, reuse still equals retrace bit for bit, the previous frames' paths included.
TEST(Resample, WithReuseEqualsRetrace) {
  const std::string args = " --width 48 --height 36 --spp 2 --resample";
  const std::string a = test::renderFrames(demoScene(), "0-3", "--mode reuse" + args, "rs-rr-a");
  const std::string b = test::renderFrames(demoScene(), "0-3", "--mode retrace" + args, "rs-rr-b");
  for (int f = 0; f <= 3; ++f)
    EXPECT_EQ(test::frameImage(a, f).rgba, test::frameImage(b, f).rgba) << "frame " << f;
}

}  // namespace
}  // namespace pr
