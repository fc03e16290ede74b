// Long unattended runs: SIGINT/SIGTERM stop cleanly, --resume finishes a run bit for bit as an
// uninterrupted one would, unwritable output and full disks are one line and exit 1 with no
// partial file, a device allocation that cannot fit names the buffer, and the loader's
// in-memory entry point (the fuzz target's) checks what the file entry point checks.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/image.h"
#include "scene/gltf_loader.h"
#include "support/background.h"
#include "support/test_env.h"
#include "util/error.h"
#include "util/files.h"
#include "util/hash.h"

namespace pr {
namespace {

using test::lineCount;
using test::slurp;

namespace fs = std::filesystem;

// Files in `dir` that are not finished outputs: temporary names start with a dot.
std::vector<std::string> temporaryFiles(const std::string& dir) {
  std::vector<std::string> found;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name[0] == '.' || name.find(".tmp") != std::string::npos) found.push_back(name);
  }
  return found;
}

using test::Background;

const std::string kScene = test::sourcePath("scenes/cornell-dynamic.gltf");

// --fps 1000 turns the 5 s animation into 5001 small frames: far more than the test waits for.
TEST(Interrupt, SigintKeepsCompleteFramesOnlyAndSaysWhich) {
  const std::string dir = test::tempDir("sigint");
  const std::string out = dir + "/frames";
  Background run({"render", kScene, "--fps", "1000", "--width", "64", "--height", "48", "--spp",
                  "2", "--png", "--stats", dir + "/stats.jsonl", "--out", out + "/f_%04d.exr"},
                 dir);
  ASSERT_TRUE(run.started());
  ASSERT_TRUE(run.waitUntil([&] { return fs::exists(out + "/f_0002.exr"); }, 120)) << run.err();
  const auto sent = std::chrono::steady_clock::now();
  run.signal(SIGINT);
  const int code = run.wait(10);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - sent).count();
  ASSERT_EQ(code, 130) << run.err();
  EXPECT_LT(seconds, 5.0);

  const std::string err = run.err();
  const std::string head = "interrupted by SIGINT: frames 0-";
  const size_t at = err.find(head);
  ASSERT_NE(at, std::string::npos) << err;
  const int last = std::atoi(err.c_str() + at + head.size());
  EXPECT_NE(err.find(head + std::to_string(last) + " complete in " + out + "/f_%04d.exr; " +
                     std::to_string(last + 1) + "-5000 not rendered"),
            std::string::npos)
      << err;
  EXPECT_EQ(err.find("error"), std::string::npos) << err;

  // Exactly the frames it names, each complete with its PNG, and nothing half written.
  char name[32];
  for (int f = 0; f <= last; ++f) {
    std::snprintf(name, sizeof name, "/f_%04d", f);
    EXPECT_TRUE(isCompleteExr(out + name + ".exr")) << f;
    EXPECT_TRUE(fs::exists(out + name + ".png")) << f;
  }
  std::snprintf(name, sizeof name, "/f_%04d.exr", last + 1);
  EXPECT_FALSE(fs::exists(out + name));
  EXPECT_TRUE(temporaryFiles(out).empty()) << temporaryFiles(out)[0];
  // One stats line per complete frame.
  EXPECT_EQ(lineCount(slurp(dir + "/stats.jsonl")), size_t(last + 1));
}

// A frame of a million samples per pixel: the integrators check between passes, so SIGTERM
// still ends the run within seconds, and the partial frame is dropped.
TEST(Interrupt, SigtermStopsWithinALongFrame) {
  const std::string dir = test::tempDir("sigterm");
  const std::string out = dir + "/frames";
  Background run({"render", kScene, "--frames", "0-3", "--width", "64", "--height", "48", "--spp",
                  "1000000", "--out", out + "/f_%04d.exr"},
                 dir);
  ASSERT_TRUE(run.started());
  // The "rendering ..." line comes once the kernels are built, just before the first frame.
  ASSERT_TRUE(run.waitUntil([&] { return run.err().find("rendering ") != std::string::npos; }, 120))
      << run.err();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const auto sent = std::chrono::steady_clock::now();
  run.signal(SIGTERM);
  const int code = run.wait(10);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - sent).count();
  ASSERT_EQ(code, 143) << run.err();
  EXPECT_LT(seconds, 5.0);
  EXPECT_NE(run.err().find("interrupted by SIGTERM: no frame complete in " + out +
                           "/f_%04d.exr; 0-3 not rendered"),
            std::string::npos)
      << run.err();
  EXPECT_TRUE(fs::is_empty(out));
}

bool samePixels(const std::string& a, const std::string& b) {
  const Image x = readExr(a), y = readExr(b);
  return x.width == y.width && x.height == y.height &&
         std::memcmp(x.rgba.data(), y.rgba.data(), x.rgba.size() * sizeof(float)) == 0;
}

// A run cut short after frame 2 with frame 1 truncated (as by a crash of some other tool), then
// resumed: frame 0 and 2 are kept, 1 and 3-5 are rendered, and every frame equals the
// uninterrupted run's bit for bit, in both reuse and path-tracing modes, also with the shutter
// open.
TEST(Resume, FinishesARunBitForBitAsAnUninterruptedOne) {
  for (const char* mode :
       {"reuse --no-resample", "pathtrace", "pathtrace --shutter 0.5", "reuse --shutter 0.5"}) {
    SCOPED_TRACE(mode);
    const std::string dir = test::tempDir("resume");
    const std::string common =
        "render '" + kScene + "' --exr-float --width 64 --height 48 --spp 2 --mode " + mode;
    auto r =
        test::runPathreuse(common + " --quiet --frames 0-5 --out '" + dir + "/whole/f_%04d.exr'");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    r = test::runPathreuse(common + " --quiet --frames 0-2 --out '" + dir + "/cut/f_%04d.exr'");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const std::string truncated = dir + "/cut/f_0001.exr";
    fs::resize_file(truncated, fs::file_size(truncated) / 2);
    ASSERT_FALSE(isCompleteExr(truncated));
    const auto keptTime = fs::last_write_time(dir + "/cut/f_0000.exr");

    r = test::runPathreuse(common + " --resume --frames 0-5 --out '" + dir + "/cut/f_%04d.exr'");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.err.find("rendered 4 frame(s)"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("2 already complete, skipped"), std::string::npos) << r.err;
    EXPECT_EQ(fs::last_write_time(dir + "/cut/f_0000.exr"), keptTime);
    char name[32];
    for (int f = 0; f <= 5; ++f) {
      std::snprintf(name, sizeof name, "/f_%04d.exr", f);
      EXPECT_TRUE(samePixels(dir + "/whole" + name, dir + "/cut" + name)) << "frame " << f;
    }
  }
}

// --resample (reuse's default) takes each frame's paths into the next: --resume keeps the last
// frame's beside its EXR, so a run cut after frame 2 and resumed equals the uninterrupted one bit
// for bit (a frame cut short within a run is rendered again without them: the frames before and
// the Resume test above show that). A history that does not match (cut short, or of other
// options) is not used: the run starts afresh and says so.
TEST(Resume, GoesOnFromTheResampledPathsOfTheLastFrame) {
  const std::string base = "render '" + kScene + "' --exr-float --width 64 --height 48 --resume";
  // Under a shutter too, where a kept path may be one that L cannot make (PR_RS_NO_L).
  for (const char* mode :
       {"--mode reuse", "--mode pathtrace --resample", "--mode reuse --resample --shutter 0.5"}) {
    SCOPED_TRACE(mode);
    const std::string dir = test::tempDir("resume-rs");
    const std::string common = base + " --spp 2 " + mode;
    auto r =
        test::runPathreuse(common + " --quiet --frames 0-5 --out '" + dir + "/whole/f_%04d.exr'");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    r = test::runPathreuse(common + " --frames 0-2 --out '" + dir + "/cut/f_%04d.exr'");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    ASSERT_TRUE(fs::is_regular_file(dir + "/cut/f_0002.exr.history"));
    EXPECT_FALSE(fs::exists(dir + "/cut/f_0001.exr.history"));  // only the last frame's is kept
    r = test::runPathreuse(common + " --frames 0-5 --out '" + dir + "/cut/f_%04d.exr'");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.err.find("goes on from frame 2's resampled paths"), std::string::npos) << r.err;
    char name[32];
    for (int f = 0; f <= 5; ++f) {
      std::snprintf(name, sizeof name, "/f_%04d.exr", f);
      EXPECT_TRUE(samePixels(dir + "/whole" + name, dir + "/cut" + name)) << "frame " << f;
    }
  }
  // Not used: a record naming a triangle the scene lacks (its checksum made right), a file cut
  // short, or one of another spp (its key differs). Each time the next frame starts afresh.
  const std::string dir = test::tempDir("resume-rs");
  const std::string pt = base + " --mode pathtrace --resample";
  auto r =
      test::runPathreuse(pt + " --spp 2 --quiet --frames 0-5 --out '" + dir + "/cut/f_%04d.exr'");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const auto refused = [&](int f, const std::string& extra, const char* why) {
    SCOPED_TRACE(why);
    r = test::runPathreuse(pt + extra + " --frames 0-" + std::to_string(f) + " --out '" + dir +
                           "/cut/f_%04d.exr'");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.err.find("history starts afresh at frame " + std::to_string(f)), std::string::npos)
        << r.err;
  };
  std::string bytes;
  const std::string history5 = dir + "/cut/f_0005.exr.history";
  ASSERT_TRUE(readFile(history5, &bytes));
  const size_t records = 2 * 64 * 48, record = 240;  // 2 chains (spp) of a PathHistory per pixel
  ASSERT_GT(bytes.size(), records * record + 8);
  const size_t head = bytes.size() - 8 - records * record;
  size_t k = 0;
  while (k < records && bytes.compare(head + k * record, 4, std::string(4, '\xff')) == 0) ++k;
  ASSERT_LT(k, records) << "no record keeps a path";
  const uint32_t bad = 0x7ffffff0u;  // r.prim: the record's first field
  std::memcpy(&bytes[head + k * record], &bad, sizeof bad);
  const uint64_t sum = Hash128().add(bytes.data() + head, records * record).low();
  std::memcpy(&bytes[bytes.size() - 8], &sum, sizeof sum);
  writeFileAtomic(history5, bytes);
  refused(6, " --spp 2", "a triangle out of range");
  const std::string history6 = dir + "/cut/f_0006.exr.history";
  ASSERT_TRUE(fs::is_regular_file(history6));
  EXPECT_FALSE(fs::exists(history5));
  fs::resize_file(history6, fs::file_size(history6) / 2);
  refused(7, " --spp 2", "cut short");
  refused(8, " --spp 3", "another spp");
  // Records whose numbers the kernels would sum into inf or negative pixels (checksums made
  // right): a path's value f_r of 3e38, a negative radiance beyond x_2 (rest_r).
  const auto forge = [&](int frame, size_t offset, float value) {
    char name[64];
    std::snprintf(name, sizeof name, "/cut/f_%04d.exr.history", frame);
    std::string data;
    ASSERT_TRUE(readFile(dir + name, &data));
    const size_t n = 3 * 64 * 48;  // 3 chains
    ASSERT_GT(data.size(), n * record + 8);
    const size_t at = data.size() - 8 - n * record;
    size_t j = 0;
    while (j < n && data.compare(at + j * record, 4, std::string(4, '\xff')) == 0) ++j;
    ASSERT_LT(j, n) << "no record keeps a path";
    std::memcpy(&data[at + j * record + offset], &value, sizeof value);
    const uint64_t check = Hash128().add(data.data() + at, n * record).low();
    std::memcpy(&data[data.size() - 8], &check, sizeof check);
    writeFileAtomic(dir + name, data);
  };
  forge(8, 48, 3e38f);  // PathReservoir::f_r
  refused(9, " --spp 3", "a value of 3e38");
  forge(9, 32, -7471.0f);  // PathReservoir::rest_r
  refused(10, " --spp 3", "a negative radiance");
}

// A 1x1 image of one colour.
Image plainImage(float r, float g, float b) {
  Image img(1, 1);
  float* p = img.pixel(0, 0);
  p[0] = r, p[1] = g, p[2] = b, p[3] = 1.0f;
  return img;
}

// The history is used only by a run that would have made it: of the same options that change a
// frame, the same image size (not only the same pixel count), and files of the same content (an
// edited texture or environment map under the same names). Otherwise the frame starts afresh and
// says so. Each case resumes frame 2 from frame 1's history, kept aside and put back each time.
TEST(Resume, AHistoryOfOtherInputsOrOptionsIsNotUsed) {
  const std::string dir = test::tempDir("resume-inputs");
  nlohmann::json g = nlohmann::json::parse(slurp(kScene));
  g["images"] = {{{"uri", "tex.png"}}};
  g["textures"] = {{{"source", 0}}};
  g["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
  writeFileAtomic(dir + "/scene.gltf", g.dump());
  writePng(dir + "/tex.png", plainImage(0.5f, 0.3f, 0.2f));
  Image env(8, 4);
  for (size_t i = 0; i < env.rgba.size(); ++i) env.rgba[i] = 0.2f;
  writeExr(dir + "/env.exr", env);
  const std::string common = "render '" + dir +
                             "/scene.gltf' --exr-float --spp 2 --resume --env '" + dir +
                             "/env.exr' --out '" + dir + "/f_%04d.exr'";
  auto r = test::runPathreuse(common + " --quiet --width 32 --height 24 --frames 0-1");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const std::string history = dir + "/f_0001.exr.history";
  std::string kept;
  ASSERT_TRUE(readFile(history, &kept));
  const auto resumeFrame2 = [&](const std::string& args) {
    writeFileAtomic(history, kept);
    fs::remove(dir + "/f_0002.exr");
    fs::remove(dir + "/f_0002.exr.history");
    r = test::runPathreuse(common + " --frames 2 " + args);
    EXPECT_EQ(r.exitCode, 0) << r.err;
    return r.err;
  };
  const std::string goesOn = "goes on from frame 1's resampled paths";
  const std::string afresh = "history starts afresh at frame 2";
  EXPECT_NE(resumeFrame2("--width 32 --height 24").find(goesOn), std::string::npos) << r.err;
  EXPECT_NE(resumeFrame2("--width 24 --height 32").find(afresh), std::string::npos) << r.err;
  EXPECT_NE(resumeFrame2("--width 32 --height 24 --no-light-tracing").find(afresh),
            std::string::npos)
      << r.err;
  writePng(dir + "/tex.png", plainImage(0.2f, 0.5f, 0.3f));
  EXPECT_NE(resumeFrame2("--width 32 --height 24").find(afresh), std::string::npos)
      << "texture edited: " << r.err;
  writePng(dir + "/tex.png", plainImage(0.5f, 0.3f, 0.2f));
  for (size_t i = 0; i < env.rgba.size(); ++i) env.rgba[i] = 0.3f;
  writeExr(dir + "/env.exr", env);
  EXPECT_NE(resumeFrame2("--width 32 --height 24").find(afresh), std::string::npos)
      << "environment edited: " << r.err;
  for (size_t i = 0; i < env.rgba.size(); ++i) env.rgba[i] = 0.2f;
  writeExr(dir + "/env.exr", env);
  EXPECT_NE(resumeFrame2("--width 32 --height 24").find(goesOn), std::string::npos)
      << "all as written: " << r.err;
}

// What runs that died or broke a history chain left beside the frames (a hidden temporary of a
// process that no longer runs, the history of a frame whose next frame is done) is removed by
// the next run over that output, and a note says so; the history a resumed run needs stays, and
// so does a temporary of a running process.
TEST(Resume, StaleHistoriesAndTemporariesAreRemoved) {
  const std::string dir = test::tempDir("stale");
  const std::string common = "render '" + kScene + "' --exr-float --width 32 --height 24 --spp 1 " +
                             "--resume --out '" + dir + "/f_%04d.exr'";
  auto r = test::runPathreuse(common + " --quiet --frames 0-3");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  ASSERT_TRUE(fs::exists(dir + "/f_0003.exr.history"));
  fs::copy_file(dir + "/f_0003.exr.history", dir + "/f_0001.exr.history");
  const pid_t dead = fork();
  ASSERT_GE(dead, 0);
  if (dead == 0) _exit(0);
  waitpid(dead, nullptr, 0);
  const std::string deadTemp = dir + "/.f_0002.exr.tmp" + std::to_string(dead) + "_0";
  const std::string liveTemp = dir + "/.f_0004.exr.tmp" + std::to_string(getpid()) + "_0";
  writeFileAtomic(deadTemp, "half a frame");
  writeFileAtomic(liveTemp, "a frame being written");
  r = test::runPathreuse(common + " --frames 0-3");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.err.find("removed 2 stale"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir + "/f_0001.exr.history"));
  EXPECT_FALSE(fs::exists(deadTemp));
  EXPECT_TRUE(fs::exists(liveTemp));
  EXPECT_TRUE(fs::exists(dir + "/f_0003.exr.history"));  // frame 4 resumes from it
  r = test::runPathreuse(common + " --frames 0-4");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.err.find("goes on from frame 3's resampled paths"), std::string::npos) << r.err;
}

// A chunk of frames that cannot read the history of the frame before it (rendered at the same
// time as the chunk before, say) warms up: --warm-up N renders the N frames before its first one
// without writing them. From frame 0 on they are the uninterrupted run's frames, bit for bit;
// without warm-up the chunk's first frame starts afresh and differs.
TEST(Resume, WarmUpFramesGiveAChunkTheHistoryOfTheFramesBefore) {
  const std::string dir = test::tempDir("warm-up");
  const std::string common =
      "render '" + kScene + "' --quiet --exr-float --width 64 --height 48 --spp 2 --mode reuse";
  auto r = test::runPathreuse(common + " --frames 0-4 --out '" + dir + "/whole/f_%04d.exr'");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  r = test::runPathreuse(common + " --frames 2-4 --warm-up 2 --out '" + dir + "/warm/f_%04d.exr'");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  r = test::runPathreuse(common + " --frames 2-4 --out '" + dir + "/cold/f_%04d.exr'");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  char name[32];
  for (int f = 0; f <= 4; ++f) {
    std::snprintf(name, sizeof name, "/f_%04d.exr", f);
    if (f < 2) {
      EXPECT_FALSE(fs::exists(dir + "/warm" + name)) << "warm-up frame " << f << " was written";
      continue;
    }
    EXPECT_TRUE(samePixels(dir + "/whole" + name, dir + "/warm" + name)) << "frame " << f;
  }
  EXPECT_FALSE(samePixels(dir + "/whole/f_0002.exr", dir + "/cold/f_0002.exr"));
}

TEST(Resume, AFrameOfAnotherSizeIsRenderedAgain) {
  const std::string dir = test::tempDir("resize");
  const std::string common =
      "render '" + kScene + "' --quiet --frames 0 --spp 1 --out '" + dir + "/f_%04d.exr'";
  auto r = test::runPathreuse(common + " --width 32 --height 24");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  r = test::runPathreuse(common + " --width 64 --height 48 --resume");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(readExr(dir + "/f_0000.exr").width, 64);
}

TEST(WriteErrors, OutputUnderARegularFileIsOneLineAndExitOne) {
  const std::string dir = test::tempDir("notdir");
  std::ofstream(dir + "/file") << "x";
  const auto r = test::runPathreuse("render '" + kScene +
                                    "' --frames 0 --width 32 --height 24 --spp 1 --out '" + dir +
                                    "/file/f_%04d.exr'");
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_EQ(lineCount(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find(dir + "/file/f_0000.exr: cannot create folder"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("Not a directory"), std::string::npos) << r.err;
}

// Root writes into read-only folders, so as root the render runs as user nobody (setpriv), with
// its caches in a folder nobody can write.
TEST(WriteErrors, ReadOnlyFolderIsOneLineAndExitOne) {
  const std::string dir = test::tempDir("readonly");
  std::string env;
  if (geteuid() == 0) {
    const std::string cache = dir + "/cache";
    fs::create_directory(cache);
    fs::permissions(cache, fs::perms::all);
    fs::permissions(dir, fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec |
                             fs::perms::others_read | fs::perms::others_exec);
    const std::string drop = "setpriv --reuid=65534 --regid=65534 --clear-groups";
    const std::string probe = drop + " test -x '" + std::string(PATHREUSE_BINARY) + "' -a -r '" +
                              kScene + "' 2>/dev/null";
    if (std::system(probe.c_str()) != 0)
      GTEST_SKIP() << "running as root, and user nobody cannot run " << PATHREUSE_BINARY
                   << " (or setpriv is absent)";
    env = "HOME='" + cache + "' XDG_CACHE_HOME='" + cache + "' POCL_CACHE_DIR='" + cache +
          "' PATHREUSE_CACHE_DIR='" + cache + "' " + drop;
  }
  fs::create_directory(dir + "/ro");
  fs::permissions(dir + "/ro", fs::perms::owner_read | fs::perms::owner_exec |
                                   fs::perms::group_read | fs::perms::group_exec |
                                   fs::perms::others_read | fs::perms::others_exec);
  const auto r = test::runPathreuse("render '" + kScene +
                                        "' --frames 0 --width 32 --height 24 --spp 1 --out '" +
                                        dir + "/ro/f_%04d.exr'",
                                    env);
  fs::permissions(dir + "/ro", fs::perms::owner_all);
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_EQ(lineCount(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find(dir + "/ro/f_0000.exr: cannot write: Permission denied"), std::string::npos)
      << r.err;
  EXPECT_TRUE(fs::is_empty(dir + "/ro"));
}

TEST(WriteErrors, FullDiskForTheStatsFileIsOneLineAndExitOne) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "/dev/full is absent";
  const std::string dir = test::tempDir("devfull");
  const auto r = test::runPathreuse("render '" + kScene +
                                    "' --quiet --frames 0 --width 32 --height 24 --spp 1 "
                                    "--stats /dev/full --out '" +
                                    dir + "/f_%04d.exr'");
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_EQ(lineCount(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find("/dev/full: cannot write the stats file: No space left on device"),
            std::string::npos)
      << r.err;
}

// An output never replaces a file the render reads: the scene named by --out's pattern (for the
// first frame or a later one) or by --stats, or the scene through a link. One line, exit 2, the
// file intact.
TEST(WriteErrors, AnOutputNeverReplacesAnInput) {
  const std::string dir = test::tempDir("self");
  const std::string scene = dir + "/1.gltf", original = slurp(kScene);
  writeFileAtomic(scene, original);
  fs::create_symlink(scene, dir + "/link0.exr");
  const std::string render = "render '" + scene + "' --quiet --width 8 --height 8 --spp 1 ";
  for (const std::string& args :
       {std::string("--frames 1 --out '") + dir + "/%d.gltf'",
        std::string("--frames 0-1 --out '") + dir + "/%d.gltf'",
        std::string("--frames 0 --out '") + dir + "/o_%d.exr' --stats '" + scene + "'",
        std::string("--frames 0 --out '") + dir + "/link%d.exr'"}) {
    SCOPED_TRACE(args);
    const auto r = test::runPathreuse(render + args);
    EXPECT_EQ(r.exitCode, 2) << r.err;
    EXPECT_EQ(lineCount(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find("a file this render reads"), std::string::npos) << r.err;
    EXPECT_EQ(slurp(scene), original);
  }
}

// Output names up to the file system's 255 bytes: the hidden temporary name each is written
// under first is shortened to fit where the final name fits.
TEST(WriteErrors, LongOutputNamesAreWritten) {
  const std::string dir = test::tempDir("long-names");
  const std::string stem(240, 'n');  // + "_0000.exr": 249 bytes, + ".png" the same
  const auto r = test::runPathreuse("render '" + kScene +
                                    "' --quiet --frames 0 --width 8 --height 8 --spp 1 --png "
                                    "--out '" +
                                    dir + "/" + stem + "_%04d.exr'");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir + "/" + stem + "_0000.exr"));
  EXPECT_TRUE(fs::exists(dir + "/" + stem + "_0000.png"));
  size_t files = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++files;
  EXPECT_EQ(files, 2u) << "a temporary file was left";
}

// A stats line that does not fit (a file-size limit: the write falls short mid-line, as on a full
// disk) is cut back: the file holds whole lines only, each one JSON, and the run says why, exit 1.
TEST(WriteErrors, AStatsLineIsWholeOrAbsent) {
  const std::string dir = test::tempDir("stats-limit");
  const std::string render =
      "render '" + kScene + "' --quiet --width 8 --height 8 --spp 1 --out '" + dir + "/f_%04d.exr'";
  auto r = test::runPathreuse(render + " --frames 0");  // the kernels built before the limit
  ASSERT_EQ(r.exitCode, 0) << r.err;
  // 4 KiB (dash counts 512-byte blocks): a few frames' EXRs fit, the stats lines' sum does not.
  // The limit set by the shell, and the device under test named after it (runPathreuse would put
  // PATHREUSE_DEVICE before `trap`, where it would not reach the renderer).
  const char* device = std::getenv("PATHREUSE_TEST_DEVICE");
  const std::string limited =
      std::string("trap '' XFSZ; ulimit -f 8;") +
      (device && *device ? " PATHREUSE_DEVICE='" + std::string(device) + "'" : std::string());
  r = test::runPathreuse(render + " --frames 0-20 --stats '" + dir + "/stats.jsonl'", limited);
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_NE(r.err.find(dir + "/stats.jsonl: cannot write the stats file"), std::string::npos)
      << r.err;
  const std::string text = slurp(dir + "/stats.jsonl");
  ASSERT_FALSE(text.empty());
  EXPECT_EQ(text.back(), '\n') << "a cut line was left";
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line)) EXPECT_NO_THROW(nlohmann::json::parse(line)) << line;
}

// A file-size limit makes write() fail the way a full disk does (EFBIG instead of ENOSPC), for
// this process only: the EXR write reports the file, and neither it nor its temporary remains.
TEST(WriteErrors, FailingExrWriteLeavesNoFile) {
  const std::string dir = test::tempDir("fsize");
  Image img(256, 256);
  for (size_t i = 0; i < img.rgba.size(); ++i) img.rgba[i] = float((i * 2654435761u) % 1000) / 7.0f;
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    signal(SIGXFSZ, SIG_IGN);
    const rlimit limit{16384, 16384};
    setrlimit(RLIMIT_FSIZE, &limit);
    try {
      writeExr(dir + "/f.exr", img, ExrPixels::Float);
      _exit(3);
    } catch (const RuntimeError& e) {
      const std::string what = e.what();
      _exit(what.find(dir + "/f.exr: cannot write: File too large") == 0 ? 0 : 4);
    } catch (...) {
      _exit(5);
    }
  }
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "3: no error, 4: wrong message, 5: wrong exception";
  EXPECT_TRUE(fs::is_empty(dir));
}

// The size named is the one `pathreuse devices` lists (they were formatted apart: 4.0 / 4.00).
TEST(DeviceMemory, ArenaTooLargeNamesItAndItsSize) {
  const std::string dir = test::tempDir("oom");
  const auto r = test::runPathreuse("render '" + kScene +
                                    "' --frames 0 --width 32 --height 24 --spp 1 "
                                    "--light-paths 67108864 --max-depth 64 --out '" +
                                    dir + "/f_%04d.exr'");
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_EQ(lineCount(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find("device out of memory: light vertex arena needs "), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find(" GiB"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::is_empty(dir));
  // "allows is X": X is what `devices` prints as the rendering device's max alloc.
  const size_t at = r.err.find("allows is ");
  ASSERT_NE(at, std::string::npos) << r.err;
  const std::string size = r.err.substr(at + 10, r.err.find('\n', at) - at - 10);
  const auto list = test::runPathreuse("devices");
  EXPECT_NE(list.out.find("max alloc " + size + ","), std::string::npos) << size << "\n"
                                                                         << list.out;
}

TEST(DeviceMemory, AbsurdSizesAreBadInput) {
  for (const char* args :
       {"--light-paths 100000000", "--width 100000", "--max-depth 1000", "--spp 0"}) {
    const auto r = test::runPathreuse("render '" + kScene + "' --frames 0 " + args);
    EXPECT_EQ(r.exitCode, 2) << args << ": " << r.err;
    EXPECT_EQ(lineCount(r.err), 1u) << r.err;
  }
}

// Ranges are checked whether or not the option's feature is on; frame numbers are 64-bit and
// say the limit past it; a scene with a camera and nothing to render is one line, the
// note about its missing lights left out.
TEST(BadOptions, RangesAndEmptyScenesAreOneLineAndExitTwo) {
  const std::string dir = test::tempDir("bad-options");
  const std::string common =
      " --frames 0 --width 8 --height 8 --spp 1 --out '" + dir + "/f_%04d.exr'";
  auto r = test::runPathreuse("render '" + kScene + "'" + common + " --adaptive-min-spp -5");
  EXPECT_EQ(r.exitCode, 2) << r.err;
  EXPECT_EQ(lineCount(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find("--adaptive-min-spp"), std::string::npos) << r.err;
  auto renderBig = [&](const std::string& frames) {
    return test::runPathreuse("render '" + kScene + "' --quiet --frames " + frames +
                              " --width 8 --height 8 --spp 1 --out '" + dir + "/big_%d.exr'");
  };
  r = renderBig("1234567890");
  EXPECT_EQ(r.exitCode, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir + "/big_1234567890.exr"));
  // 64-bit frame numbers; the last two end the run (a 32-bit counter wrapped and rendered on).
  r = renderBig("9223372036854775805-9223372036854775806");
  EXPECT_EQ(r.exitCode, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir + "/big_9223372036854775806.exr"));
  size_t frames = 0;
  for (const auto& e : fs::directory_iterator(dir))
    frames += e.path().filename().string().rfind("big_", 0) == 0;
  EXPECT_EQ(frames, 3u) << "frames outside the range were rendered";
  for (const char* frames : {"9223372036854775807", "99999999999999999999"}) {
    r = test::runPathreuse("render '" + kScene + "' --frames " + frames + common.substr(11));
    EXPECT_EQ(r.exitCode, 2) << r.err;
    EXPECT_EQ(lineCount(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find("9223372036854775806"), std::string::npos) << r.err;
  }
  writeFileAtomic(dir + "/camera.gltf",
                  R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],)"
                  R"("nodes":[{"camera":0}],"cameras":[{"type":"perspective",)"
                  R"("perspective":{"yfov":0.8,"znear":0.1}}]})");
  r = test::runPathreuse("render '" + dir + "/camera.gltf'" + common);
  EXPECT_EQ(r.exitCode, 2) << r.err;
  EXPECT_EQ(lineCount(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find("nothing to render"), std::string::npos) << r.err;
}

TEST(BadOptions, HistoryPeriodOutOfRangeIsOneLineAndExitTwo) {
  for (const char* period : {"0", "1001", "-3"}) {
    const std::string dir = test::tempDir("bad-period");
    const auto r =
        test::runPathreuse("render '" + kScene + "' --frames 0 --connection-history-period " +
                           period + " --out '" + dir + "/f_%04d.exr'");
    EXPECT_EQ(r.exitCode, 2) << period << ": " << r.err;
    EXPECT_EQ(lineCount(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find("--connection-history-period"), std::string::npos) << r.err;
    EXPECT_TRUE(fs::is_empty(dir));
  }
}

TEST(LoaderFromMemory, SameSceneAsFromTheFile) {
  std::string bytes;
  bytes = slurp(kScene);
  LoadOptions quiet;
  quiet.printWarnings = false;
  const Scene a = loadScene(kScene, quiet);
  const Scene b = loadSceneFromMemory(bytes, kScene, quiet);
  EXPECT_EQ(a.staticTriangleCount(), b.staticTriangleCount());
  EXPECT_EQ(a.dynamicTriangleCount(), b.dynamicTriangleCount());
  EXPECT_EQ(a.emissiveTriangleCount(), b.emissiveTriangleCount());
  EXPECT_EQ(a.frameCount(24.0), b.frameCount(24.0));
}

TEST(LoaderFromMemory, BrokenBytesAreAnInputErrorNamingTheFile) {
  for (const std::string& bytes :
       {std::string(), std::string("{"), std::string("glTF\x02\0\0\0", 8),
        std::string("{\"asset\":{\"version\":\"1.0\"}}")}) {
    try {
      loadSceneFromMemory(bytes, "mem/x.gltf");
      ADD_FAILURE() << "loaded: " << bytes;
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind("mem/x.gltf: ", 0), 0u) << e.what();
    }
  }
}

// Found by tools/fuzz/fuzz.sh: an index of 2e78 was cast to int64 before its range was checked,
// which is undefined behaviour (UBSan in build-asan stops here if it comes back).
TEST(LoaderFromMemory, HugeIndexIsAnInputError) {
  for (const char* text : {R"({"asset":{"version":"2.0"},"scene":2e78})",
                           R"({"asset":{"version":"2.0"},"scene":-1e300})",
                           R"({"asset":{"version":"2.0"},"scenes":[{"nodes":[1e19]}]})"}) {
    EXPECT_THROW(loadSceneFromMemory(text, "mem/huge.gltf"), InputError) << text;
  }
}

}  // namespace
}  // namespace pr
