// Hostile and careless input, one test per case found by trying 212 of them: each ends at once
// with one line naming the file and exit code 2 (or is handled as the case says), never a
// crash, a hang, a file read from outside the scene or a broken frame kept.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/stat.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "io/image.h"
#include "scene/environment_map.h"
#include "scene/image_decode.h"
#include "support/background.h"
#include "support/gltf_builder.h"
#include "support/render_helpers.h"
#include "support/test_env.h"
#include "util/error.h"

namespace pr {
namespace {

using test::lineCount;
using test::slurp;

namespace fs = std::filesystem;
using nlohmann::json;

const std::string kScene = test::sourcePath("scenes/cornell-dynamic.gltf");
// A command that would wait for ever is cut at 60 s and fails the test (124), not CI.
const char* const kCut = "timeout -s KILL 60";

void spit(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

// One line on stderr, exit code 2, and the line holds every one of `parts`.
void expectRefused(const test::CommandResult& r, const std::vector<std::string>& parts) {
  EXPECT_EQ(r.exitCode, 2) << r.err;
  EXPECT_EQ(lineCount(r.err), 1u) << r.err;
  for (const auto& p : parts) EXPECT_NE(r.err.find(p), std::string::npos) << p << "\n" << r.err;
}

// A lit quad with a camera: dir/name.gltf and dir/name.bin.
std::string smallScene(const std::string& dir, const std::string& name = "scene") {
  test::GltfBuilder b;
  const int m = b.addMaterial({});
  b.addNode(b.addQuad({-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, m));
  b.addCamera({0, 0, 3}, {0, 0, 0}, 0.8f);
  b.addPointLight({0, 0, 2}, {1, 1, 1}, 10.0f);
  return b.write(dir, name);
}

json readJson(const std::string& path) {
  return json::parse(slurp(path));
}

void writeJson(const std::string& path, const json& j) {
  spit(path, j.dump());
}

// ---- 1: JSON nested 20,000 deep --------------------------------------------------------------

TEST(HostileInput, JsonNested20000DeepIsRefused) {
  const std::string dir = test::tempDir("deep-json");
  const std::string path = dir + "/d.gltf";
  spit(path, "{\"asset\":{\"version\":\"2.0\"},\"extras\":" + std::string(20000, '[') +
                 std::string(20000, ']') + "}");
  expectRefused(test::runPathreuse("info '" + path + "'"), {path, "nested more than"});
  // A GLB's JSON chunk is scanned the same way.
  expectRefused(test::runPathreuse("render '" + path + "' --out '" + dir + "/f_%04d.exr'"),
                {path, "nested more than"});
}

// ---- 2: a node chain 100,000 deep ------------------------------------------------------------

// The quad's node at the bottom of a chain of `depth` nodes whose root is animated (so every
// frame walks the whole chain to place the quad).
std::string chainScene(const std::string& dir, int depth) {
  test::GltfBuilder b;
  const int m = b.addMaterial({});
  b.addNode(b.addQuad({-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, m));
  b.addCamera({0, 0, 3}, {0, 0, 0}, 0.8f);
  b.animateTranslation(0, {0.0f, 1.0f}, {glm::vec3(0.0f), glm::vec3(0.1f, 0.0f, 0.0f)});
  const std::string path = b.write(dir, "chain");
  json j = readJson(path);
  // Chain nodes after the builder's put the quad (node 0) at the bottom; the root moves.
  json& nodes = j["nodes"];
  const int first = int(nodes.size());
  for (int k = 0; k < depth; ++k) nodes.push_back({{"children", {k == 0 ? 0 : first + k - 1}}});
  j["scenes"][0]["nodes"] = json::array({first + depth - 1});
  j["animations"][0]["channels"][0]["target"]["node"] = first + depth - 1;
  for (int n = 1; n < first; ++n) j["scenes"][0]["nodes"].push_back(n);  // the camera
  writeJson(path, j);
  return path;
}

TEST(HostileInput, NodeChain100000DeepIsRefusedWithTheLimit) {
  const std::string dir = test::tempDir("chain");
  const std::string path = chainScene(dir, 100000);
  expectRefused(test::runPathreuse("info '" + path + "'"), {path, "10000 levels deep"});
  expectRefused(test::runPathreuse("render '" + path +
                                   "' --frames 0 --width 8 --height 8 "
                                   "--mode pathtrace --out '" +
                                   dir + "/f_%04d.exr'"),
                {path, "10000 levels deep"});
}

TEST(HostileInput, NodeChainAtTheLimitLoadsAndRenders) {
  const std::string dir = test::tempDir("chain-ok");
  const std::string path = chainScene(dir, 9990);
  auto r = test::runPathreuse("info '" + path + "'");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  r = test::runPathreuse("render '" + path +
                         "' -q --frames 0-1 --width 8 --height 8 --spp 1 "
                         "--mode pathtrace --out '" +
                         dir + "/f_%04d.exr'");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir + "/f_0001.exr"));
}

// ---- 3, 4, 6, 16: files that are not regular files ---------------------------------------------

TEST(HostileInput, DevZeroIsNotARegularFile) {
  const auto t0 = std::chrono::steady_clock::now();
  expectRefused(test::runPathreuse("render /dev/zero", kCut),
                {"/dev/zero", "not a regular file (a character device)"});
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 10.0);
}

TEST(HostileInput, BufferOrImageUriNamingAFifoIsRefusedAtOnce) {
  const std::string dir = test::tempDir("fifo-uri");
  const std::string path = smallScene(dir);
  ASSERT_EQ(mkfifo((dir + "/pipe").c_str(), 0600), 0);
  json j = readJson(path);
  j["buffers"][0]["uri"] = "pipe";
  writeJson(path, j);
  expectRefused(test::runPathreuse("info '" + path + "'", kCut),
                {path, "pipe", "not a regular file (a FIFO)"});
  // As an image's URI.
  j = readJson(path);
  j["buffers"][0]["uri"] = "scene.bin";
  j["images"] = json::array({{{"uri", "pipe"}}});
  j["textures"] = json::array({{{"source", 0}}});
  j["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
  writeJson(path, j);
  expectRefused(test::runPathreuse("info '" + path + "'", kCut),
                {path, "pipe", "not a regular file (a FIFO)"});
}

TEST(HostileInput, EnvNamingAFifoIsRefusedAtOnce) {
  const std::string dir = test::tempDir("fifo-env");
  ASSERT_EQ(mkfifo((dir + "/sky.hdr").c_str(), 0600), 0);
  expectRefused(test::runPathreuse("render '" + kScene + "' --frames 0 --env '" + dir +
                                       "/sky.hdr' --out '" + dir + "/f_%04d.exr'",
                                   kCut),
                {dir + "/sky.hdr", "not a regular file (a FIFO)"});
  EXPECT_FALSE(fs::exists(dir + "/f_0000.exr"));
}

TEST(HostileInput, BufferUriThatIsADirectoryIsNamed) {
  const std::string dir = test::tempDir("dir-uri");
  const std::string path = smallScene(dir);
  fs::create_directory(dir + "/sub");
  json j = readJson(path);
  j["buffers"][0]["uri"] = "sub";
  writeJson(path, j);
  expectRefused(test::runPathreuse("info '" + path + "'"), {path, "sub", "is a directory"});
}

// ---- 5: a signal while loading -----------------------------------------------------------------

// Kernels compiled cold (our cache and PoCL's off) keep the renderer loading for many seconds:
// the first signal must end it at once, with the usual line, not after the compile.
void signalWhileLoading(int sig, const char* name) {
  const std::string dir = test::tempDir("sig-load");
  std::vector<std::string> env = {"PATHREUSE_CACHE_DIR=" + dir + "/cache", "POCL_KERNEL_CACHE=0"};
  if (const char* spec = std::getenv("PATHREUSE_TEST_DEVICE"); spec && *spec)
    env.push_back(std::string("PATHREUSE_DEVICE=") + spec);
  test::Background run({"render", kScene, "--frames", "0-3", "--width", "16", "--height", "12",
                        "--out", dir + "/frames/f_%04d.exr"},
                       dir, env);
  ASSERT_TRUE(run.started());
  ASSERT_TRUE(run.waitUntil(
      [&] { return run.err().find("compiling OpenCL kernels") != std::string::npos; }, 60))
      << run.err();
  const auto sent = std::chrono::steady_clock::now();
  run.signal(sig);
  const int code = run.wait(30);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - sent).count();
  EXPECT_EQ(code, 128 + sig) << run.err();
  EXPECT_LT(seconds, 1.5) << run.err();
  EXPECT_NE(run.err().find(std::string("interrupted by ") + name + " while loading " + kScene +
                           ": no frame rendered"),
            std::string::npos)
      << run.err();
  EXPECT_FALSE(fs::exists(dir + "/frames/f_0000.exr"));
}

TEST(HostileInput, SigintWhileLoadingEndsAtOnce) {
  signalWhileLoading(SIGINT, "SIGINT");
}

TEST(HostileInput, SigtermWhileLoadingEndsAtOnce) {
  signalWhileLoading(SIGTERM, "SIGTERM");
}

// ---- 7: truncated Radiance HDR -----------------------------------------------------------------

// A w x h Radiance HDR of one colour, run-length encoded as writers do (w >= 8).
std::string hdr(int w, int h) {
  std::string s = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y " + std::to_string(h) + " +X " +
                  std::to_string(w) + "\n";
  const unsigned char rgbe[4] = {128, 64, 32, 129};
  for (int y = 0; y < h; ++y) {
    s += std::string({2, 2, char(w >> 8), char(w & 0xff)});
    for (int c = 0; c < 4; ++c)
      for (int x = 0; x < w; x += 100) {  // runs of at most 127
        const int n = std::min(100, w - x);
        s += char(128 + n);
        s += char(rgbe[c]);
      }
  }
  return s;
}

TEST(HostileInput, TruncatedHdrEnvironmentIsRefused) {
  const std::string dir = test::tempDir("hdr");
  const std::string whole = hdr(16, 8);
  spit(dir + "/whole.hdr", whole);
  const Environment e = loadEnvironment(dir + "/whole.hdr");
  ASSERT_EQ(e.width, 16);
  ASSERT_EQ(e.height, 8);
  EXPECT_GT(e.rgb[3 * 127 + 0], 0.0f);  // the last pixel is lit
  const size_t header = whole.find("+X 16\n") + 6;
  spit(dir + "/header.hdr", whole.substr(0, header));
  spit(dir + "/half.hdr", whole.substr(0, header + (whole.size() - header) / 2));
  for (const char* name : {"header.hdr", "half.hdr"}) {
    const std::string path = dir + "/" + name;
    expectRefused(test::runPathreuse("render '" + kScene + "' --frames 0 --env '" + path +
                                     "' --out '" + dir + "/f_%04d.exr'"),
                  {path, "truncated"});
  }
  EXPECT_FALSE(fs::exists(dir + "/f_0000.exr"));
}

// ---- 8, 9: --resume meets a broken PNG and a half stats line -----------------------------------

const char* const kSmall = " -q --width 16 --height 12 --spp 1 --mode pathtrace";

TEST(HostileInput, ResumeRendersACutOrCorruptPngAgain) {
  const std::string dir = test::tempDir("resume-png");
  const std::string out = dir + "/f_%04d.exr";
  auto r = test::runPathreuse("render '" + kScene + "' --frames 0-2 --png" + kSmall + " --out '" +
                              out + "'");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  // Frame 0's PNG cut to 100 bytes, frame 1's with a byte of its pixels flipped, frame 2 whole.
  fs::resize_file(dir + "/f_0000.png", 100);
  std::string png = slurp(dir + "/f_0001.png");
  const size_t idat = png.find("IDAT");
  ASSERT_NE(idat, std::string::npos);
  png[idat + 8] = char(png[idat + 8] ^ 0x10);
  spit(dir + "/f_0001.png", png);
  r = test::runPathreuse("render '" + kScene + "' --frames 0-2 --png --resume" +
                         std::string(kSmall).substr(3) + " --out '" + out + "'");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.err.find("rendered 2 frame(s)"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("1 already complete"), std::string::npos) << r.err;
  for (const char* name : {"f_0000.png", "f_0001.png"}) {
    const std::string bytes = slurp(dir + "/" + name);
    DecodedImage img;
    std::string why;
    EXPECT_TRUE(decodeImageRgba8(std::vector<uint8_t>(bytes.begin(), bytes.end()), &img, &why))
        << name << ": " << why;
  }
}

TEST(HostileInput, ResumeDropsAPartialStatsLineBeforeAppending) {
  const std::string dir = test::tempDir("resume-stats");
  const std::string out = dir + "/f_%04d.exr", stats = dir + "/stats.jsonl";
  auto r = test::runPathreuse("render '" + kScene + "' --frames 0-1 --stats '" + stats + "'" +
                              kSmall + " --out '" + out + "'");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  // A disk that filled during the next line.
  { std::ofstream(stats, std::ios::app) << "{\"frame\":2,\"mode\":\"pathtr"; }
  r = test::runPathreuse("render '" + kScene + "' --frames 0-2 --resume --stats '" + stats + "'" +
                         kSmall + " --out '" + out + "'");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const std::string text = slurp(stats);
  ASSERT_FALSE(text.empty());
  EXPECT_EQ(text.back(), '\n');
  std::istringstream lines(text);
  std::string line;
  std::vector<int> frames;
  while (std::getline(lines, line)) {
    json j;
    ASSERT_NO_THROW(j = json::parse(line)) << line;
    frames.push_back(j["frame"].get<int>());
  }
  EXPECT_EQ(frames, (std::vector<int>{0, 1, 2}));
}

// ---- 10: --png with an output named .png --------------------------------------------------------

TEST(HostileInput, PngOutPatternThatIsItsOwnPngIsRefused) {
  const std::string dir = test::tempDir("png-out");
  expectRefused(test::runPathreuse("render '" + kScene + "' --frames 0 --png" + kSmall +
                                   " --out '" + dir + "/f_%04d.png'"),
                {"--out", "one file"});
  EXPECT_TRUE(fs::is_empty(dir));
}

// ---- 11: URIs outside the scene's folder -------------------------------------------------------

TEST(HostileInput, UriOutsideTheScenesFolderIsRefused) {
  const std::string dir = test::tempDir("outside");
  fs::create_directory(dir + "/scene");
  const std::string path = smallScene(dir + "/scene");
  fs::rename(dir + "/scene/scene.bin", dir + "/secret.bin");
  fs::create_symlink(dir + "/secret.bin", dir + "/scene/link.bin");
  json j = readJson(path);
  for (const char* uri : {"../secret.bin", "%2e%2e/secret.bin", "link.bin"}) {
    j["buffers"][0]["uri"] = uri;
    writeJson(path, j);
    expectRefused(test::runPathreuse("info '" + path + "'"),
                  {path, "outside the scene's folder", "--allow-outside-uris"});
    // Allowed, the same scene loads.
    const auto r = test::runPathreuse("info --allow-outside-uris '" + path + "'");
    EXPECT_EQ(r.exitCode, 0) << uri << ": " << r.err;
  }
  // The working directory is not searched either.
  j["buffers"][0]["uri"] = "secret.bin";
  writeJson(path, j);
  const auto r = test::runPathreuse("info '" + path + "'", "cd '" + dir + "' &&");
  EXPECT_EQ(r.exitCode, 2) << r.err;
}

// ---- 12: numeric options out of range ----------------------------------------------------------

TEST(HostileInput, NumericOptionsOutOfRangeAreRefusedAtParseTime) {
  const std::string dir = test::tempDir("ranges");
  for (const char* option :
       {"--width 0", "--height 0", "--light-paths 0", "--camera -7", "--spp 0", "--max-depth 65",
        "--fps 0", "--clamp nan", "--clamp -1", "--connection-mis inf", "--env-strength -1",
        "--exposure nan", "--paths-per-pixel 0", "--connection-history-period 0", "--seed -1"}) {
    const std::string name = std::string(option).substr(0, std::string(option).find(' '));
    expectRefused(
        test::runPathreuse("render '" + kScene + "' " + option + " --out '" + dir + "/f_%04d.exr'"),
        {name, "not in range"});
  }
  EXPECT_TRUE(fs::is_empty(dir));
  for (const char* option : {"--width 0", "--spp 0", "--tolerance 0", "--sigmas nan"})
    expectRefused(test::runPathreuse(std::string("portability ") + option), {"not in range"});
  // --help states the ranges.
  const auto help = test::runPathreuse("render --help");
  EXPECT_NE(help.out.find("--width INT:INT in [1 - 16384]"), std::string::npos) << help.out;
  EXPECT_NE(help.out.find("--camera INT:INT in [0 - "), std::string::npos) << help.out;
}

// ---- 13: a GLB whose header says version 1 -----------------------------------------------------

TEST(HostileInput, GlbVersion1IsRefused) {
  const std::string dir = test::tempDir("glb1");
  const std::string gltf = smallScene(dir);
  json j = readJson(gltf);
  std::string bin = slurp(dir + "/scene.bin");
  j["buffers"][0].erase("uri");
  std::string text = j.dump();
  text.resize((text.size() + 3) / 4 * 4, ' ');
  bin.resize((bin.size() + 3) / 4 * 4, '\0');
  auto glb = [&](uint32_t version) {
    std::string s = "glTF";
    auto put = [&](uint32_t v) { s.append(reinterpret_cast<const char*>(&v), 4); };
    put(version);
    put(uint32_t(12 + 8 + text.size() + 8 + bin.size()));
    put(uint32_t(text.size()));
    put(0x4E4F534Au);
    s += text;
    put(uint32_t(bin.size()));
    put(0x004E4942u);
    s += bin;
    return s;
  };
  spit(dir + "/v2.glb", glb(2));
  const auto r = test::runPathreuse("info '" + dir + "/v2.glb'");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  spit(dir + "/v1.glb", glb(1));
  expectRefused(test::runPathreuse("info '" + dir + "/v1.glb'"),
                {dir + "/v1.glb", "GLB container version 1"});
}

// ---- 14: a portability reference holding a frame of another size --------------------------------

TEST(HostileInput, ReferenceFrameOfAnotherSizeIsNamed) {
  const std::string dir = test::tempDir("ref-size");
  const std::string scene = smallScene(dir);
  const std::string common = "portability --no-demo -q '" + scene +
                             "' --frames 0 --width 16 --height 12 --spp 1 --mode pathtrace "
                             "--device 0 --out '" +
                             dir + "/out'";
  auto r = test::runPathreuse(common + " --save-reference '" + dir + "/ref'");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  // A noise-floor seed's frame replaced by one of another size.
  const std::string damaged = dir + "/ref/scene_pathtrace_s3_f0.exr";
  ASSERT_TRUE(fs::exists(damaged));
  writeExr(damaged, Image(8, 8), ExrPixels::Float);
  expectRefused(test::runPathreuse(common + " --reference '" + dir + "/ref'"), {damaged, "8x8"});
}

// ---- 15: animation key times up to 3e38 s
// --------------------------------------------------------

TEST(HostileInput, AnimationTimeBeyondTheLimitIsRefused) {
  const std::string dir = test::tempDir("times");
  test::GltfBuilder b;
  const int m = b.addMaterial({});
  b.addNode(b.addQuad({-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, m));
  b.addCamera({0, 0, 3}, {0, 0, 0}, 0.8f);
  b.animateTranslation(0, {0.0f, 1.0f, 3e38f}, {glm::vec3(0.0f), glm::vec3(1.0f), glm::vec3(2.0f)});
  const std::string path = b.write(dir, "times");
  expectRefused(test::runPathreuse("info '" + path + "'"), {path, "3e+38 s", "1000000 s"});
  expectRefused(
      test::runPathreuse("render '" + path + "'" + kSmall + " --out '" + dir + "/f_%04d.exr'"),
      {path, "1000000 s"});
  EXPECT_FALSE(fs::exists(dir + "/f_0000.exr"));
}

}  // namespace
}  // namespace pr
