// `pathreuse portability`: the comparison metrics and verdict on synthetic images, the verdict on
// real renders with a deliberate fault, the command with two PoCL drivers, and every platform
// found.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <set>

#include <nlohmann/json.hpp>

#include "portability/compare.h"
#include "portability/portability.h"
#include "render/session.h"
#include "scene/gltf_loader.h"
#include "support/gltf_builder.h"
#include "support/test_env.h"
#include "util/error.h"

namespace pr {
namespace {

using test::lineCount;

const char* const kTwoDrivers = test::kTwoPoclDrivers;
using test::twoPoclDevices;

// A smooth image (a gradient) plus independent noise per pixel and channel: one "render".
Image noisy(uint32_t seed, double gain = 1.0, int w = 64, int h = 48) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.0f, 0.15f);
  Image img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float* p = img.pixel(x, y);
      const float base = 0.2f + 0.6f * x / w;
      for (int c = 0; c < 3; ++c) p[c] = float(gain * base * (1.0f + noise(rng)));
      p[3] = 1.0f;
    }
  return img;
}

struct Synthetic {
  Image ref = noisy(1);
  std::vector<NoiseFloor> floors = measureNoiseFloors({ref}, {{noisy(2)}, {noisy(3)}});
  Verdict judgeImage(const Image& test) const {
    return judge(compareImages(test, ref), floors[0], Tolerance{});
  }
};

TEST(PortabilityCompare, MetricsOfKnownImages) {
  Image ref(2, 1), test(2, 1);
  ref.pixel(0, 0)[0] = ref.pixel(0, 0)[1] = ref.pixel(0, 0)[2] = 1.0f;  // pixel 1 stays black
  test = ref;
  test.pixel(0, 0)[0] = 2.0f;  // (2-1)^2 / (1 + 0.01)
  test.pixel(1, 0)[2] = 0.1f;  // 0.1^2 / 0.01 = 1
  const ImageDiff d = compareImages(test, ref);
  EXPECT_NEAR(d.relMse, (1.0 / 1.01 + 1.0) / 6.0, 1e-7);  // 0.1f is not exact
  EXPECT_NEAR(d.mad, 1.1 / 6.0, 1e-7);
  EXPECT_FALSE(d.identical);
  EXPECT_EQ(d.nonFinite, 0u);
  EXPECT_TRUE(compareImages(ref, ref).identical);
  EXPECT_EQ(compareImages(ref, ref).relMse, 0.0);
  EXPECT_THROW(compareImages(Image(2, 2), ref), RuntimeError);
}

TEST(PortabilityCompare, IdenticalAgreesAndAnotherSeedAgrees) {
  const Synthetic s;
  EXPECT_TRUE(s.judgeImage(s.ref).agree);
  // A device whose every path diverged is just another seed: it must agree.
  for (uint32_t seed = 10; seed < 30; ++seed) {
    const Verdict v = s.judgeImage(noisy(seed));
    EXPECT_TRUE(v.agree) << "seed " << seed << " ratio " << v.relMseRatio << " z " << v.lumZ;
    EXPECT_LT(v.relMseRatio, 1.5);
  }
  // One firefly is noise, not a fault.
  Image firefly = noisy(40);
  firefly.pixel(5, 5)[0] = 1e4f;
  EXPECT_TRUE(s.judgeImage(firefly).agree);
}

TEST(PortabilityCompare, SystematicFaultsDisagree) {
  const Synthetic s;
  // 10% darker everywhere (a light or a BSDF scaled wrongly), with its own noise.
  Verdict v = s.judgeImage(noisy(11, 0.9));
  EXPECT_FALSE(v.agree) << "z " << v.lumZ;
  // A bright blob over 10% of the image (a light leak).
  Image blob = noisy(12);
  for (int y = 10; y < 26; ++y)
    for (int x = 10; x < 29; ++x)
      for (int c = 0; c < 3; ++c) blob.pixel(x, y)[c] += 1.0f;
  v = s.judgeImage(blob);
  EXPECT_FALSE(v.agree);
  EXPECT_GT(v.relMseRatio, 2.0);
  // A NaN anywhere.
  Image nan = s.ref;
  nan.pixel(3, 4)[1] = std::numeric_limits<float>::quiet_NaN();
  v = s.judgeImage(nan);
  EXPECT_FALSE(v.agree);
  EXPECT_EQ(compareImages(nan, s.ref).nonFinite, 1u);
  // Non-finite samples dropped on the device only.
  EXPECT_FALSE(judge(compareImages(noisy(13), s.ref), s.floors[0], Tolerance{}, 5, 0).agree);
  EXPECT_TRUE(judge(compareImages(noisy(13), s.ref), s.floors[0], Tolerance{}, 5, 3).agree);
}

TEST(PortabilityCompare, ZeroFloorNeedsEqualImages) {
  Image flat(8, 8);
  for (float& v : flat.rgba) v = 0.5f;
  const auto floors = measureNoiseFloors({flat}, {{flat}});
  EXPECT_EQ(floors[0].relMse, 0.0);
  EXPECT_TRUE(judge(compareImages(flat, flat), floors[0], Tolerance{}).agree);
  Image brighter = flat;
  for (float& v : brighter.rgba) v = 0.6f;
  EXPECT_FALSE(judge(compareImages(brighter, flat), floors[0], Tolerance{}).agree);
}

TEST(PortabilityCompare, DifferenceImageIsScaledAndFinite) {
  Image a(4, 1), b(4, 1);
  a.pixel(1, 0)[0] = 0.5f;
  a.pixel(2, 0)[1] = std::numeric_limits<float>::infinity();
  double scale = 0;
  const Image d = differenceImage(a, b, &scale);
  EXPECT_GT(scale, 0.0);
  for (float v : d.rgba) EXPECT_TRUE(std::isfinite(v) && v >= 0.0f && v <= 1.0f);
  EXPECT_EQ(d.pixel(0, 0)[0], 0.0f);
  EXPECT_GT(d.pixel(1, 0)[0], 0.0f);
}

TEST(PortabilityCompare, FrameLists) {
  EXPECT_EQ(parseFrameList("0-2,24"), (std::vector<int64_t>{0, 1, 2, 24}));
  EXPECT_EQ(parseFrameList("5,1-2,2"), (std::vector<int64_t>{1, 2, 5}));
  // The last frame numbers end the list rather than wrap around.
  EXPECT_EQ(parseFrameList("9223372036854775805-9223372036854775806"),
            (std::vector<int64_t>{9223372036854775805, 9223372036854775806}));
  EXPECT_THROW(parseFrameList("9223372036854775807"), InputError);
  EXPECT_THROW(parseFrameList(""), InputError);
  EXPECT_THROW(parseFrameList("3-1"), InputError);
  EXPECT_THROW(parseFrameList("1,"), InputError);
  EXPECT_THROW(parseFrameList("x"), InputError);
}

// Real renders of the demo scene on the test device: another seed (what a diverging device
// looks like at worst) agrees; a dimmer light or a wrongly coloured wall (what a device bug
// looks like) disagrees. Reuse and the path tracer, at the command's default size.
class PortabilityVerdict : public ::testing::TestWithParam<RenderMode> {};

std::vector<Image> renderFrames(const Scene& scene, RenderMode mode, uint32_t seed) {
  RenderOptions ro;
  ro.scene = "cornell-dynamic";
  ro.width = 64;
  ro.spp = 8;
  ro.seed = seed;
  ro.mode = mode;
  RenderSession session(scene, test::testContext().device(), ro);
  std::vector<Image> out;
  for (int f : {0, 1, 24}) out.push_back(session.renderFrame(f, nullptr));
  return out;
}

TEST_P(PortabilityVerdict, AnotherSeedAgreesAFaultDisagrees) {
  const Scene scene = loadScene(test::sourcePath("scenes/cornell-dynamic.gltf"));
  Scene dim = scene, blue = scene;
  for (auto& m : dim.materials) m.emissiveStrength *= 0.85f;
  for (auto& m : blue.materials)
    if (m.name == "red") m.baseColorFactor = glm::vec4(0.05f, 0.065f, 0.63f, 1.0f);
  const RenderMode mode = GetParam();
  const auto ref = renderFrames(scene, mode, 1);
  const auto floors =
      measureNoiseFloors(ref, {renderFrames(scene, mode, 2), renderFrames(scene, mode, 3)});
  const auto other = renderFrames(scene, mode, 7);
  const auto dimmed = renderFrames(dim, mode, 1);  // same seed: the paths are the reference's
  const auto wrong = renderFrames(blue, mode, 8);  // other seed: the fault under fresh noise
  for (size_t f = 0; f < ref.size(); ++f) {
    const Verdict ok = judge(compareImages(other[f], ref[f]), floors[f], Tolerance{});
    EXPECT_TRUE(ok.agree) << "frame " << f << " ratio " << ok.relMseRatio << " z " << ok.lumZ;
    const Verdict d = judge(compareImages(dimmed[f], ref[f]), floors[f], Tolerance{});
    EXPECT_FALSE(d.agree) << "dimmed light, frame " << f << " z " << d.lumZ;
    const Verdict w = judge(compareImages(wrong[f], ref[f]), floors[f], Tolerance{});
    EXPECT_FALSE(w.agree) << "blue wall, frame " << f << " ratio " << w.relMseRatio;
  }
}

INSTANTIATE_TEST_SUITE_P(Modes, PortabilityVerdict,
                         ::testing::Values(RenderMode::Reuse, RenderMode::PathTrace),
                         [](const auto& info) { return std::string(renderModeName(info.param)); });

// A small scene of its own, passed besides the demo scenes.
std::string smallScene() {
  test::GltfBuilder b;
  const int white = b.addMaterial({glm::vec4(0.7f, 0.7f, 0.7f, 1), 0, 1});
  const int lamp = b.addMaterial({glm::vec4(0, 0, 0, 1), 0, 1, glm::vec3(1), 10.0f});
  b.addNode(b.addBox(glm::vec3(-1, 0, -1), glm::vec3(1, 2, 1), white, true));
  b.addNode(b.addQuad({-0.3f, 1.98f, -0.3f}, {0.3f, 1.98f, -0.3f}, {0.3f, 1.98f, 0.3f},
                      {-0.3f, 1.98f, 0.3f}, lamp));
  const int cube =
      b.addNode(b.addBox(glm::vec3(-0.2f), glm::vec3(0.2f), white), glm::vec3(0, 0.5f, 0));
  b.animateTranslation(cube, {0.0f, 1.0f}, {glm::vec3(-0.4f, 0.5f, 0), glm::vec3(0.4f, 0.5f, 0)});
  b.addCamera(glm::vec3(0, 1, 0.95f), glm::vec3(0, 1, -1), 1.2f, 4.0f / 3.0f);
  return b.write(test::tempDir("port-scene"), "small_box");
}

TEST(PortabilityCli, TwoPoclDriversAgreeOnTheSuite) {
  const std::string out = test::tempDir("port-out");
  const std::string scene = smallScene();
  const auto r = test::runPathreuse("portability '" + scene +
                                        "' --json --quiet --frames 0-1 --width 32 --spp 4" +
                                        twoPoclDevices() + " --out '" + out + "'",
                                    kTwoDrivers);
  ASSERT_EQ(r.exitCode, 0) << r.out << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["devices"].size(), 2u);
  EXPECT_TRUE(j["devices"][0]["reference"].get<bool>());
  ASSERT_EQ(j["scenes"].size(), 3u);
  EXPECT_EQ(j["scenes"][2]["label"], "small_box");
  ASSERT_EQ(j["modes"].size(), 3u);
  // Every scene x mode x frame, for the one device compared with the reference.
  ASSERT_EQ(j["results"].size(), 3u * 3u * 2u);
  std::set<std::string> seen;
  for (const auto& e : j["results"]) {
    EXPECT_TRUE(e["agree"].get<bool>()) << e.dump();
    EXPECT_EQ(e["device"], j["devices"][1]["index"]);
    EXPECT_GT(e["noise_floor_rel_mse_trimmed"].get<double>(), 0.0) << e.dump();
    EXPECT_GT(e["noise_floor_luminance_stderr"].get<double>(), 0.0) << e.dump();
    seen.insert(e["scene"].get<std::string>() + "/" + e["mode"].get<std::string>() + "/" +
                std::to_string(e["frame"].get<int>()));
  }
  EXPECT_EQ(seen.size(), 18u);
  EXPECT_TRUE(j["summary"]["agree"].get<bool>());
  EXPECT_EQ(j["summary"]["disagree"], 0);
  const std::string png = j["worst"]["png"];
  EXPECT_EQ(std::filesystem::path(png).parent_path(), std::filesystem::path(out));
  EXPECT_TRUE(std::filesystem::is_regular_file(png)) << png;
}

// The default suite (both demo scenes, frames 0-2 and 24, every mode) on the first device of
// every OpenCL platform found. tools/ci/test.sh sets PATHREUSE_REQUIRE_PLATFORMS=2 after setting up
// Intel's CPU runtime beside PoCL, so there a missing platform fails instead of skipping.
TEST(PortabilityCli, EveryPlatformAgreesOnTheDefaultSuite) {
  const test::PlatformDevices found = test::firstDevicePerPlatform();
  ASSERT_FALSE(HasFailure());
  if (found.platforms.size() < 2)
    GTEST_SKIP() << "one OpenCL platform only; tools/setup/intel-opencl.sh sets up a second "
                    "(Intel's CPU runtime)";
  std::string devices;
  for (const std::string& d : found.devices) devices += " --device " + d;
  const auto r = test::runPathreuse("portability --json --quiet" + devices + " --out '" +
                                    test::tempDir("port-platforms") + "'");
  ASSERT_EQ(r.exitCode, 0) << r.out << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["results"].size(), 24u * (found.platforms.size() - 1));
  for (const auto& e : j["results"]) EXPECT_TRUE(e["agree"].get<bool>()) << e.dump();
  EXPECT_EQ(j["summary"]["disagree"], 0);
}

// A reference saved on one machine is what a device elsewhere is compared with.
TEST(PortabilityCli, SavedReferenceIsComparedWithEveryDevice) {
  const std::string ref = test::tempDir("port-ref");
  const std::string suite =
      " --quiet --frames 0-1 --width 32 --spp 2 --mode pathtrace --mode reuse";
  const std::string pocl = twoPoclDevices();  // " --device I --device J"
  const std::string first = pocl.substr(0, pocl.find(" --device", 1));
  const std::string second = pocl.substr(first.size());
  auto r = test::runPathreuse("portability" + suite + first + " --save-reference '" + ref +
                                  "' --out '" + test::tempDir("port-save") + "'",
                              kTwoDrivers);
  ASSERT_EQ(r.exitCode, 0) << r.out << r.err;
  // Two demo scenes x two modes x two frames x three seeds, and the manifest.
  size_t files = 0;
  for (const auto& e : std::filesystem::directory_iterator(ref)) files += e.is_regular_file();
  EXPECT_EQ(files, 2u * 2u * 2u * 3u + 1u);
  r = test::runPathreuse("portability" + suite + " --json" + second + " --reference '" + ref +
                             "' --out '" + test::tempDir("port-cmp") + "'",
                         kTwoDrivers);
  ASSERT_EQ(r.exitCode, 0) << r.out << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["results"].size(), 8u);
  EXPECT_FALSE(j["devices"][0]["reference"].get<bool>());
  for (const auto& e : j["results"]) EXPECT_TRUE(e["identical"].get<bool>()) << e.dump();
  // Another suite than the one saved, no manifest, a manifest of the wrong shape: one line,
  // exit 2.
  const std::string broken = test::tempDir("port-broken");
  nlohmann::json manifest = nlohmann::json::parse(std::ifstream(ref + "/reference.json"));
  for (auto& v : manifest["frames_dropped"]) v = "none";
  std::ofstream(broken + "/reference.json") << manifest.dump();
  for (const auto& e : std::filesystem::directory_iterator(ref))
    if (e.path().extension() == ".exr") std::filesystem::copy(e.path(), broken);
  for (const std::string& bad :
       {" --spp 3 --reference '" + ref + "'", " --reference '" + test::tempDir("port-empty") + "'",
        " --reference '" + broken + "'",
        " --reference '" + ref + "' --save-reference '" + ref + "'"}) {
    r = test::runPathreuse("portability --quiet --frames 0-1 --width 32 --spp 2" + bad,
                           kTwoDrivers);
    EXPECT_EQ(r.exitCode, 2) << bad << ": " << r.out << r.err;
    EXPECT_EQ(lineCount(r.err), 1u) << bad << ": " << r.err;
  }
}

TEST(PortabilityCli, TableAndSummaryOnStdout) {
  const std::string out = test::tempDir("port-table");
  const auto r =
      test::runPathreuse("portability --quiet --frames 0 --width 32 --spp 2 --mode pathtrace" +
                             twoPoclDevices() + " --out '" + out + "'",
                         kTwoDrivers);
  ASSERT_EQ(r.exitCode, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("relMSE*"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("cornell-orbit      pathtrace     0"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("OK: 0 of 2 comparisons disagree"), std::string::npos) << r.out;
  EXPECT_EQ(r.err, "");
}

TEST(PortabilityCli, OneDeviceHasNothingToCompare) {
  const auto r = test::runPathreuse(
      "portability --quiet --frames 0 --width 16 --spp 1 --mode pathtrace --device 0 --out '" +
          test::tempDir("port-one") + "'",
      kTwoDrivers);
  EXPECT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.out.find("nothing to compare"), std::string::npos) << r.out;
}

TEST(PortabilityCli, BadInputIsOneLineAndExitTwo) {
  for (const std::string args : {"--device 9", "/no/such/scene.gltf", "--frames 2-1", "--mode fast",
                                 "--tolerance 0.5", "--no-demo", "--spp 0"}) {
    const auto r = test::runPathreuse("portability --quiet " + args, kTwoDrivers);
    EXPECT_EQ(r.exitCode, 2) << args << ": " << r.err;
    EXPECT_EQ(lineCount(r.err), 1u) << args << ": " << r.err;
  }
}

}  // namespace
}  // namespace pr
