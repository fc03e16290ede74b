// Several devices in one render (render/multi_device.h): the row split and its balancing, and
// frames byte-identical to a single device's with PoCL's two drivers, which compute alike.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <numeric>

#include <nlohmann/json.hpp>

#include "io/image.h"
#include "cl/device.h"
#include "render/multi_device.h"
#include "render/renderer.h"
#include "scene/gltf_loader.h"
#include "support/test_env.h"

namespace pr {
namespace {

using test::lineCount;

namespace fs = std::filesystem;

const std::string kScene = test::sourcePath("scenes/cornell-dynamic.gltf");
constexpr int kWidth = 64, kHeight = 48, kFrames = 5;

int sum(const std::vector<int>& v) {
  return std::accumulate(v.begin(), v.end(), 0);
}

TEST(SplitRows, EvenThenProportional) {
  EXPECT_EQ(splitRows(48, {1.0, 1.0}), (std::vector<int>{24, 24}));
  EXPECT_EQ(splitRows(7, {1.0, 1.0}), (std::vector<int>{4, 3}));
  EXPECT_EQ(splitRows(48, {3.0, 1.0}), (std::vector<int>{36, 12}));
  EXPECT_EQ(splitRows(10, {1.0, 1.0, 1.0}), (std::vector<int>{4, 3, 3}));
  // Largest remainders: 100 x (0.505, 0.495) = 50.5, 49.5.
  EXPECT_EQ(splitRows(100, {0.505, 0.495}), (std::vector<int>{51, 49}));
}

TEST(SplitRows, EveryDeviceGetsARowWhileThereAreEnough) {
  EXPECT_EQ(splitRows(48, {1000.0, 1e-9}), (std::vector<int>{47, 1}));
  EXPECT_EQ(splitRows(3, {1e-9, 1.0, 1e-9}), (std::vector<int>{1, 1, 1}));
  EXPECT_EQ(splitRows(1, {1.0, 1.0}), (std::vector<int>{1, 0}));
  EXPECT_EQ(splitRows(0, {1.0, 1.0}), (std::vector<int>{0, 0}));
  // Weights that are not usable count as none; all unusable: an even split.
  EXPECT_EQ(splitRows(10, {0.0, 0.0}), (std::vector<int>{5, 5}));
  EXPECT_EQ(splitRows(10, {std::nan(""), 1.0}), (std::vector<int>{1, 9}));
  for (int h : {1, 2, 5, 48, 1079})
    for (const auto& w : std::vector<std::vector<double>>{{1, 2, 3}, {0.3, 0.3, 0.4}, {5, 1}})
      EXPECT_EQ(sum(splitRows(h, w)), h);
}

TEST(BalancePasses, FollowsPassesPerSecondWhereThatPays) {
  // As fast per pass: kept.
  EXPECT_EQ(balancePasses({2, 2}, {1.0, 1.0}), (std::vector<int>{2, 2}));
  // As fast, split unevenly: evenly (2 s a frame against 3 s).
  EXPECT_EQ(balancePasses({3, 1}, {3.0, 1.0}), (std::vector<int>{2, 2}));
  // Three times as fast: three quarters of the passes, the frame in half the time.
  EXPECT_EQ(balancePasses({4, 4}, {1.0, 3.0}), (std::vector<int>{6, 2}));
  EXPECT_EQ(balancePasses({6, 2}, {1.5, 1.5}), (std::vector<int>{6, 2}));
  // {6, 4} would take 1.2 s against 1.3 s: under 15% shorter, kept.
  EXPECT_EQ(balancePasses({5, 5}, {1.0, 1.3}), (std::vector<int>{5, 5}));
  // Every device keeps a pass while there are enough.
  EXPECT_EQ(balancePasses({2, 2}, {1.0, 100.0}), (std::vector<int>{3, 1}));
  EXPECT_EQ(balancePasses({1, 1, 1}, {1.0, 9.0, 9.0}), (std::vector<int>{1, 1, 1}));
  // Nothing measured to go by: kept.
  EXPECT_EQ(balancePasses({2, 2}, {0.0, 1.0}), (std::vector<int>{2, 2}));
  EXPECT_EQ(balancePasses({1, 0}, {1.0, 0.0}), (std::vector<int>{1, 0}));
  EXPECT_EQ(balancePasses({2, 2}, {std::nan(""), 1.0}), (std::vector<int>{2, 2}));
}

bool samePixels(const std::string& a, const std::string& b) {
  const Image x = readExr(a), y = readExr(b);
  return x.width == y.width && x.height == y.height &&
         std::memcmp(x.rgba.data(), y.rgba.data(), x.rgba.size() * sizeof(float)) == 0;
}

std::string frameFile(const std::string& dir, int f) {
  char name[32];
  std::snprintf(name, sizeof name, "/f_%04d.exr", f);
  return dir + name;
}

std::string common(const std::string& mode) {
  return "render '" + kScene + "' --quiet --exr-float --width " + std::to_string(kWidth) +
         " --height " + std::to_string(kHeight) + " --spp 2 --mode " + mode;
}

// The first PoCL device alone: the reference every split must equal.
std::string oneDevice() {
  const std::string two = test::twoPoclDevices();
  return two.substr(0, two.find(" --device", 1));
}

// Each stats line names both devices, whose rows tile the image (or, where spp is given, whose
// sample passes do, each device at least one over every row: the first frame's an even split,
// later ones as the balancing chose); the top-level rays are the devices' sums. Returns each
// line's passes of the second device.
std::vector<int> checkStats(const std::string& file, int frames, int spp = 0) {
  std::vector<int> second;
  std::ifstream in(file);
  std::string line;
  int lines = 0;
  while (std::getline(in, line)) {
    ++lines;
    const auto j = nlohmann::json::parse(line);
    EXPECT_EQ(j["devices"].size(), 2u) << line;
    if (j["devices"].size() != 2u) return second;
    int rows = 0, passes = 0;
    double share = 0.0;
    std::map<std::string, uint64_t> rays;
    for (const auto& d : j["devices"]) {
      if (spp == 0) {
        EXPECT_EQ(d["row_begin"].get<int>(), rows) << line;
        rows += d["rows"].get<int>();
      } else {
        EXPECT_EQ(d["row_begin"].get<int>(), 0) << line;
        EXPECT_EQ(d["rows"].get<int>(), kHeight) << line;
        EXPECT_EQ(d["pass_begin"].get<int>(), passes) << line;
        EXPECT_GE(d["passes"].get<int>(), 1) << line;
        if (lines == 1) {
          EXPECT_EQ(d["passes"].get<int>(), splitRows(spp, {1.0, 1.0})[passes ? 1 : 0]) << line;
        }
        if (passes > 0) second.push_back(d["passes"].get<int>());
        passes += d["passes"].get<int>();
        rows = kHeight;
      }
      share += d["share"].get<double>();
      EXPECT_GT(d["rows"].get<int>(), 0) << line;
      EXPECT_GT(d["wall_s"].get<double>(), 0.0) << line;
      EXPECT_FALSE(d["stages_s"].empty()) << line;
      for (const auto& [k, v] : d["rays"].items()) rays[k] += v.get<uint64_t>();
    }
    EXPECT_EQ(rows, kHeight) << line;
    EXPECT_NEAR(share, 1.0, 1e-12) << line;
    for (const auto& [k, v] : rays) EXPECT_EQ(j["rays"][k].get<uint64_t>(), v) << k;
    if (spp > 0) {
      EXPECT_EQ(passes, spp) << line;
    }
    if (lines == 1 && spp == 0) {
      EXPECT_EQ(j["devices"][0]["rows"].get<int>(), kHeight / 2) << line;
    }
  }
  EXPECT_EQ(lines, frames);
  return second;
}

// Frames of a scene with moving objects, two devices against one, byte for byte, each device
// rendering its rows (without path resampling, which splits the passes instead:
// TwoDevicesEqualOneWithResampling), also with the shutter open.
TEST(MultiDeviceCli, TwoDevicesEqualOne) {
  const std::string two = test::twoPoclDevices();
  const std::string range = " --frames 0-" + std::to_string(kFrames - 1);
  for (const char* mode :
       {"reuse --no-resample", "pathtrace", "pathtrace --shutter 0.5", "reuse --shutter 0.5"}) {
    SCOPED_TRACE(mode);
    const std::string dir = test::tempDir("multi");
    auto r = test::runPathreuse(
        common(mode) + range + oneDevice() + " --out '" + dir + "/one/f_%04d.exr'",
        test::kTwoPoclDrivers);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    r = test::runPathreuse(common(mode) + range + two + " --out '" + dir +
                               "/two/f_%04d.exr' --stats '" + dir + "/two.jsonl'",
                           test::kTwoPoclDrivers);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    for (int f = 0; f < kFrames; ++f)
      EXPECT_TRUE(samePixels(frameFile(dir + "/one", f), frameFile(dir + "/two", f)))
          << "frame " << f;
    checkStats(dir + "/two.jsonl", kFrames);
  }
}

// The largest difference between two frames' channels relative to the larger of the two (0 for
// equal frames).
double largestRelativeDifference(const Image& x, const Image& y) {
  EXPECT_EQ(x.rgba.size(), y.rgba.size());
  double worst = 0.0;
  for (size_t k = 0; k < std::min(x.rgba.size(), y.rgba.size()); ++k) {
    const double d = std::fabs(double(x.rgba[k]) - y.rgba[k]);
    const double m = std::max(std::fabs(double(x.rgba[k])), std::fabs(double(y.rgba[k])));
    worst = std::max(worst, d > 0.0 ? d / m : 0.0);
  }
  return worst;
}

double largestRelativeDifference(const std::string& a, const std::string& b) {
  return largestRelativeDifference(readExr(a), readExr(b));
}

// With --resample a pixel's paths take its neighbours' and the previous frame's, anywhere in the
// image, so the devices split the sample passes instead of the rows: each renders every pixel and
// their films' sums are added. Every sample is one device's (a pass that changes device as the
// split follows the devices' speeds takes its paths along), and where the second device holds one
// pass the two sums added are one device's sum in its order: frames with moving objects, in both
// modes, equal one device's byte for byte there, and but for the sums' float rounding otherwise
// (with the rows split instead, some pixel of every frame was 45-100% off). Each stats line names
// both devices, each with every row and some of the passes. Strategy T's splats (on in reuse)
// are the first device's, added before its passes, so they keep that order.
TEST(MultiDeviceCli, TwoDevicesEqualOneWithResampling) {
  const std::string two = test::twoPoclDevices();
  const std::string range = " --frames 0-3 --resample";
  for (const char* mode : {"reuse", "pathtrace"}) {
    SCOPED_TRACE(mode);
    std::string args = common(mode);
    args.replace(args.find("--spp 2"), 7, "--spp 3");
    const std::string dir = test::tempDir("multi-rs");
    auto r = test::runPathreuse(args + range + oneDevice() + " --out '" + dir + "/one/f_%04d.exr'",
                                test::kTwoPoclDrivers);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    r = test::runPathreuse(
        args + range + two + " --out '" + dir + "/two/f_%04d.exr' --stats '" + dir + "/two.jsonl'",
        test::kTwoPoclDrivers);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const std::vector<int> second = checkStats(dir + "/two.jsonl", 4, 3);
    ASSERT_EQ(second.size(), 4u);
    for (int f = 0; f <= 3; ++f) {
      const std::string a = frameFile(dir + "/one", f), b = frameFile(dir + "/two", f);
      if (second[size_t(f)] == 1) {
        EXPECT_TRUE(samePixels(a, b))
            << "frame " << f << ": largest relative difference " << largestRelativeDifference(a, b);
      }
      EXPECT_LT(largestRelativeDifference(a, b), 1e-5) << "frame " << f;
    }
  }
}

// --device all with only PoCL's platform listed: its two drivers.
TEST(MultiDeviceCli, AllDevicesEqualOne) {
  const std::string icd = "/etc/OpenCL/vendors/pocl.icd";
  if (!fs::exists(icd)) GTEST_SKIP() << icd << " absent";
  const std::string vendors = test::tempDir("icd");
  fs::copy_file(icd, vendors + "/pocl.icd");
  const std::string env = std::string(test::kTwoPoclDrivers) + " OCL_ICD_VENDORS='" + vendors + "'";
  const std::string dir = test::tempDir("all");
  auto r = test::runPathreuse(
      common("reuse") + " --frames 0-2" + oneDevice() + " --out '" + dir + "/one/f_%04d.exr'", env);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  r = test::runPathreuse(common("reuse") + " --frames 0-2 --device all --out '" + dir +
                             "/all/f_%04d.exr' --stats '" + dir + "/all.jsonl'",
                         env);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  for (int f = 0; f <= 2; ++f)
    EXPECT_TRUE(samePixels(frameFile(dir + "/one", f), frameFile(dir + "/all", f))) << f;
  checkStats(dir + "/all.jsonl", 3, 2);  // reuse resamples: each device one of the 2 passes
}

// A two-device run cut short, resumed on two devices: every frame equals the single device's
// uninterrupted run. In pathtrace mode frame 1 is truncated too, and rendered again. In reuse
// mode, which resamples, each device keeps the history of its own passes beside the last frame
// (a frame cut short within the run would be rendered again without the frame before's).
TEST(MultiDeviceCli, ResumeEqualsOne) {
  const std::string two = test::twoPoclDevices();
  for (const char* mode : {"reuse", "pathtrace"}) {
    SCOPED_TRACE(mode);
    const std::string dir = test::tempDir("multiresume");
    auto r = test::runPathreuse(
        common(mode) + " --frames 0-4" + oneDevice() + " --out '" + dir + "/whole/f_%04d.exr'",
        test::kTwoPoclDrivers);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    r = test::runPathreuse(
        common(mode) + " --frames 0-2 --resume" + two + " --out '" + dir + "/cut/f_%04d.exr'",
        test::kTwoPoclDrivers);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const bool resampled = std::string(mode) == "reuse";
    const std::string truncated = frameFile(dir + "/cut", 1);
    if (!resampled) fs::resize_file(truncated, fs::file_size(truncated) / 2);
    r = test::runPathreuse(common(mode) + " --frames 0-4 --resume" + two + " --out '" + dir +
                               "/cut/f_%04d.exr' --stats '" + dir + "/cut.jsonl'",
                           test::kTwoPoclDrivers);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    for (int f = 0; f <= 4; ++f)
      EXPECT_TRUE(samePixels(frameFile(dir + "/whole", f), frameFile(dir + "/cut", f)))
          << "frame " << f;
    if (resampled) {
      checkStats(dir + "/cut.jsonl", 2, 2);  // frames 3 and 4
    } else {
      checkStats(dir + "/cut.jsonl", 3);  // frames 1, 3 and 4
    }
  }
}

TEST(MultiDeviceCli, BadDeviceAmongSeveralIsOneLineAndExitTwo) {
  const std::string dir = test::tempDir("baddevice");
  const std::string render = common("reuse") + " --frames 0 --out '" + dir + "/f_%04d.exr'";
  for (const std::string& devices : {oneDevice() + " --device nosuch", oneDevice() + oneDevice(),
                                     std::string(" --device 999"), " --device all" + oneDevice()}) {
    SCOPED_TRACE(devices);
    const auto r = test::runPathreuse(render + devices, test::kTwoPoclDrivers);
    EXPECT_EQ(r.exitCode, 2) << r.err;
    EXPECT_EQ(lineCount(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find("--device"), std::string::npos) << r.err;
    EXPECT_TRUE(fs::is_empty(dir)) << devices;
  }
}

// cornell-dynamic in --mode reuse (resampled) at 32 x 24 and 4 spp.
RenderOptions sessionOptions() {
  RenderOptions ro;
  ro.scene = kScene;
  ro.width = 32;
  ro.height = 24;
  ro.spp = 4;
  return ro;
}

// Renders cornell-dynamic's frames 0-4 at 4 spp with resampling, on one device and on two
// sessions of the test device whose split of the passes `split(f)` sets before frame f; each
// frame's images go to `check(f, one, two)`.
void renderWithSplits(const std::function<std::vector<int>(int)>& split,
                      const std::function<void(int, const Image&, const Image&)>& check) {
  const Scene scene = loadScene(kScene);
  const RenderOptions ro = sessionOptions();
  const DeviceEntry& d = test::testContext().device();
  MultiDeviceSession one(scene, {&d}, ro), two(scene, {&d, &d}, ro);
  EXPECT_EQ(two.passes(), (std::vector<int>{2, 2}));
  for (int f = 0; f < 5; ++f) {
    two.setPassSplit(split(f));
    const Image a = one.renderFrame(f, nullptr, nullptr), b = two.renderFrame(f, nullptr, nullptr);
    check(f, a, b);
  }
}

// A pass that changes device takes its chain of resampled paths along, so the frames stay one
// device's: bit for bit where the second device holds one pass, else but for the float rounding
// of the sums' grouping (all terms are positive: a few 1e-7 relative). Without the chains moved
// the frames after a change are 10-100% off in places.
TEST(MultiDeviceSession, PassesChangingDeviceTakeTheirPathsAlong) {
  const std::vector<std::vector<int>> splits = {{2, 2}, {1, 3}, {3, 1}, {3, 1}, {2, 2}};
  renderWithSplits([&](int f) { return splits[size_t(f)]; },
                   [&](int f, const Image& a, const Image& b) {
                     if (splits[size_t(f)][1] == 1) {
                       EXPECT_TRUE(a.rgba == b.rgba) << "frame " << f;
                     }
                     EXPECT_LT(largestRelativeDifference(a, b), 1e-5) << "frame " << f;
                   });
}

// --resume's history file keeps the devices' split, and a run that reads it takes that split:
// the frame after equals the writing run's bit for bit.
TEST(MultiDeviceSession, HistoryFileKeepsTheSplitOfThePasses) {
  const Scene scene = loadScene(kScene);
  const RenderOptions ro = sessionOptions();
  const DeviceEntry& d = test::testContext().device();
  MultiDeviceSession first(scene, {&d, &d}, ro), resumed(scene, {&d, &d}, ro);
  first.setPassSplit({3, 1});
  for (int f = 0; f < 2; ++f) first.renderFrame(f, nullptr, nullptr);
  first.setPassSplit({1, 3});
  const std::string file = packHistories(first, "key");
  EXPECT_FALSE(unpackHistories(file, resumed, "another key", 1));
  EXPECT_FALSE(unpackHistories(file.substr(0, file.size() - 1), resumed, "key", 1));
  ASSERT_TRUE(unpackHistories(file, resumed, "key", 1));
  EXPECT_EQ(resumed.passes(), (std::vector<int>{1, 3}));
  const Image a = first.renderFrame(2, nullptr, nullptr);
  const Image b = resumed.renderFrame(2, nullptr, nullptr);
  EXPECT_TRUE(a.rgba == b.rgba);
}

// A history file is used whole or not at all: where one device's part fails its checks (a bit
// flipped in it, or a byte after the last part) no part is loaded and the split of the passes
// stays, so the next frame equals a fresh start's.
TEST(MultiDeviceSession, HistoryFileIsUsedWholeOrNotAtAll) {
  const Scene scene = loadScene(kScene);
  const RenderOptions ro = sessionOptions();
  const DeviceEntry& d = test::testContext().device();
  MultiDeviceSession first(scene, {&d, &d}, ro);
  first.setPassSplit({3, 1});
  for (int f = 0; f < 2; ++f) first.renderFrame(f, nullptr, nullptr);
  const std::string file = packHistories(first, "key");
  std::string flipped = file;
  flipped[flipped.size() - 20] ^= 0x10;  // in device 1's records
  for (const std::string& bad : {flipped, file + "x"}) {
    MultiDeviceSession fresh(scene, {&d, &d}, ro), resumed(scene, {&d, &d}, ro);
    EXPECT_FALSE(unpackHistories(bad, resumed, "key", 1));
    EXPECT_EQ(resumed.passes(), fresh.passes());
    const Image a = fresh.renderFrame(2, nullptr, nullptr);
    const Image b = resumed.renderFrame(2, nullptr, nullptr);
    EXPECT_TRUE(a.rgba == b.rgba) << "a part of a refused history was used";
  }
}

}  // namespace
}  // namespace pr
