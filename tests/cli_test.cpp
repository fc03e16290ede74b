// The command line as a user meets it: exit codes, one-line errors, the devices listing.
#include <gtest/gtest.h>

#include <cstdio>

#include <nlohmann/json.hpp>

#include "support/render_helpers.h"
#include "support/test_env.h"

namespace pr {
namespace {

using test::lineCount;

TEST(Cli, DevicesListsPocl) {
  auto r = test::runPathreuse("devices");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.out.find("[0] 0:0"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("CPU"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("OpenCL C"), std::string::npos) << r.out;
}

TEST(Cli, DevicesJson) {
  auto r = test::runPathreuse("devices --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  ASSERT_TRUE(j["devices"].is_array());
  ASSERT_GE(j["devices"].size(), 1u);
  for (const char* key : {"index", "platform", "name", "type", "compute_units", "global_mem_bytes",
                          "max_alloc_bytes", "opencl_c_version"})
    EXPECT_TRUE(j["devices"][0].contains(key)) << key;
  EXPECT_GT(j["devices"][0]["global_mem_bytes"].get<uint64_t>(), 0u);
}

TEST(Cli, TwoPoclDriversAreBothListed) {
  auto r = test::runPathreuse("devices --json", "POCL_DEVICES='pthread basic'");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  // Other platforms (Intel's runtime, a GPU) may be listed too.
  std::vector<std::string> pocl;
  for (const auto& d : j["devices"])
    if (d["platform_vendor"] == "The pocl project") pocl.push_back(d["name"]);
  ASSERT_EQ(pocl.size(), 2u) << r.out;
  EXPECT_NE(pocl[0], pocl[1]);
}

TEST(Cli, NoPlatformIsOneLineAndExitOne) {
  // An empty vendor folder: the ICD loader finds no platform.
  const std::string empty = test::tempDir("icd");
  auto r = test::runPathreuse("devices", "OCL_ICD_VENDORS='" + empty + "'");
  EXPECT_EQ(r.exitCode, 1) << r.out << r.err;
  EXPECT_EQ(lineCount(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find("pocl-opencl-icd"), std::string::npos) << r.err;
}

TEST(Cli, UnknownOptionAndSubcommandAreExitTwo) {
  auto r = test::runPathreuse("devices --frobnicate");
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_EQ(lineCount(r.err), 1u) << r.err;
  r = test::runPathreuse("");
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_EQ(lineCount(r.err), 1u) << r.err;
}

TEST(Cli, HelpIsExitZero) {
  auto r = test::runPathreuse("--help");
  EXPECT_EQ(r.exitCode, 0);
  EXPECT_NE(r.out.find("devices"), std::string::npos);
}

// A first render says once that it compiles kernels (a GPU's compiler may take minutes) and its
// first stats line gives each program's seconds; the next run loads them from the cache.
TEST(Cli, KernelBuildsAreAnnouncedOnceAndTimedInTheFirstStatsLine) {
  const std::string dir = test::tempDir("builds");
  const std::string cache = "PATHREUSE_CACHE_DIR='" + dir + "/cache' ";
  const std::string common = "render '" + test::sourcePath("scenes/cornell-dynamic.gltf") +
                             "' --frames 0-1 --width 16 --height 12 --spp 1 --out '" + dir +
                             "/f_%04d.exr' --stats '" + dir + "/stats.jsonl'";
  const std::string args = common + " --mode reuse";
  auto statsLine = [&](size_t i) { return nlohmann::json::parse(test::statsLines(dir).at(i)); };
  const std::string notice = "compiling OpenCL kernels for ";
  auto r = test::runPathreuse(args, cache);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const size_t at = r.err.find(notice);
  ASSERT_NE(at, std::string::npos) << r.err;
  EXPECT_EQ(r.err.find(notice, at + 1), std::string::npos) << "announced twice: " << r.err;
  EXPECT_NE(r.err.find(dir + "/cache/kernels"), std::string::npos) << r.err;
  nlohmann::json builds = statsLine(0)["build_s"];
  ASSERT_TRUE(builds.contains("reuse/connect.cl")) << builds.dump();
  EXPECT_GT(builds["reuse/connect.cl"].get<double>(), 0.0);
  EXPECT_TRUE(builds.contains("pathtrace/shade.cl")) << builds.dump();  // the eye paths
  EXPECT_FALSE(statsLine(1).contains("build_s")) << "frame 1 built nothing";

  r = test::runPathreuse(args, cache);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(r.err.find(notice), std::string::npos) << r.err;
  builds = statsLine(0)["build_s"];
  EXPECT_TRUE(builds.contains("reuse/connect.cl (cached)")) << builds.dump();
  EXPECT_FALSE(builds.contains("reuse/connect.cl")) << builds.dump();

  // The path tracer's kernels compile sooner than reuse's.
  r = test::runPathreuse(common + " --mode pathtrace --quiet",
                         "PATHREUSE_CACHE_DIR='" + dir + "/cold' ");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(r.err, "");
}

// The stats line's device memory by buffer sums to its total, and counts each buffer once: in
// reuse mode the eye paths write into reuse's radiance and eye vertices, so the path tracer
// keeps none of its own (one pixel's worth each, where it had one per pixel).
TEST(Cli, DeviceBuffersSumToTheDeviceBytes) {
  const int w = 32, h = 24;
  for (const std::string mode : {"reuse", "pathtrace"}) {
    const std::string dir = test::tempDir("buffers-" + mode);
    auto r = test::runPathreuse("render '" + test::sourcePath("scenes/cornell-dynamic.gltf") +
                                "' --frames 0 --width " + std::to_string(w) + " --height " +
                                std::to_string(h) + " --spp 1 --mode " + mode + " --out '" + dir +
                                "/f_%04d.exr' --stats '" + dir + "/stats.jsonl' --quiet");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const nlohmann::json line = nlohmann::json::parse(test::statsLines(dir).at(0));
    uint64_t sum = 0;
    for (const auto& [name, bytes] : line["device_buffers"].items()) sum += bytes.get<uint64_t>();
    EXPECT_EQ(sum, line["device_bytes"].get<uint64_t>()) << mode;
    const nlohmann::json& b = line["device_buffers"];
    ASSERT_TRUE(b.contains("sample radiance")) << b.dump();
    EXPECT_EQ(b["sample radiance"].get<uint64_t>(),
              uint64_t(w * h) * 16 + (mode == "reuse" ? 16 : 0))
        << mode;
    EXPECT_EQ(b.contains("light vertex arena"), mode == "reuse") << b.dump();
  }
}

// What ffprobe reports of a video's first stream: "frames,width,height,rate".
std::string probeVideo(const std::string& path) {
  const std::string cmd =
      "ffprobe -v error -count_frames -select_streams v:0 -show_entries "
      "stream=nb_read_frames,width,height,r_frame_rate -of "
      "compact=p=0:nk=1 '" +
      path + "' 2>&1";
  std::string out;
  if (FILE* p = popen(cmd.c_str(), "r")) {
    char buf[256];
    while (fgets(buf, sizeof buf, p)) out += buf;
    pclose(p);
  }
  while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
  return out;
}

// --video encodes every frame of the range, in order, at --fps (ffmpeg, which the set-up
// installs): an odd size padded to even, and a resumed run's video holds the frames of the run
// before it too.
TEST(Cli, VideoEncodesEveryFrameOfTheRange) {
  const std::string dir = test::tempDir("video");
  const std::string common = "render '" + test::sourcePath("scenes/cornell-dynamic.gltf") +
                             "' --width 33 --height 25 --spp 1 --fps 12 --quiet --out '" + dir +
                             "/f_%04d.exr' --video '" + dir + "/clip.mp4'";
  auto r = test::runPathreuse(common + " --frames 0-4");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const std::string mp4 = test::slurp(dir + "/clip.mp4");
  ASSERT_GT(mp4.size(), 8u);
  EXPECT_EQ(mp4.substr(4, 4), "ftyp");
  EXPECT_EQ(probeVideo(dir + "/clip.mp4"), "34|26|12/1|5");
  EXPECT_FALSE(test::slurp(dir + "/f_0004.png").empty()) << "--video writes the PNGs";
  r = test::runPathreuse(common + " --frames 0-6 --resume");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(probeVideo(dir + "/clip.mp4"), "34|26|12/1|7");
}

// A container it does not write, or no ffmpeg: one line, exit 2, before any frame.
TEST(Cli, VideoWithoutFfmpegOrAKnownContainerIsRefused) {
  const std::string dir = test::tempDir("video-refused");
  const std::string common = "render '" + test::sourcePath("scenes/cornell-dynamic.gltf") +
                             "' --frames 0-1 --width 8 --height 6 --spp 1 --out '" + dir +
                             "/f_%04d.exr' --video '" + dir;
  auto r = test::runPathreuse(common + "/clip.avi'");
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_EQ(lineCount(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find(".mp4, .mov or .mkv"), std::string::npos) << r.err;
  r = test::runPathreuse(common + "/clip.mp4'", "PATH=/nonexistent ");
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_EQ(lineCount(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find("ffmpeg is not on PATH"), std::string::npos) << r.err;
  EXPECT_TRUE(test::slurp(dir + "/f_0000.exr").empty()) << "nothing rendered";
}

}  // namespace
}  // namespace pr
