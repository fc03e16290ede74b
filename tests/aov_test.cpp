// --aov: auxiliary images as extra EXR channels (host/render/aov.h, kernels/aov.cl), checked
// against what the scene makes exact: a wall's albedo, normal and depth, the motion of a
// translated box and of a morphed one, and the ids of the objects and materials seen.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "io/image.h"
#include "portability/compare.h"
#include "support/gltf_builder.h"
#include "support/render_helpers.h"
#include "support/test_env.h"

namespace pr::test {
namespace {

namespace fs = std::filesystem;

constexpr int kSize = 64;
constexpr float kFov = 0.8f;

struct AovScene {
  std::string path;
  int wallNode = -1, movingNode = -1, morphNode = -1;
};

// A wall at z = -2 facing a camera at z = 5 along -z; before it a box (material 1) that moves
// +1 in x per second, and one (material 2) that a morph target lifts by 1 per second. Lit by a
// point light, so the background is empty.
AovScene aovScene(const std::string& tag) {
  GltfBuilder b;
  const int wallMat = b.addMaterial({glm::vec4(0.2f, 0.4f, 0.6f, 1.0f)});
  const int boxMat = b.addMaterial({glm::vec4(0.8f, 0.8f, 0.8f, 1.0f)});
  const int morphMat = b.addMaterial({glm::vec4(0.5f, 0.5f, 0.5f, 1.0f)});
  AovScene s;
  s.wallNode = b.addNode(b.addQuad({-3, -3, -2}, {3, -3, -2}, {3, 3, -2}, {-3, 3, -2}, wallMat));
  s.movingNode = b.addNode(b.addBox({-1.6f, -0.4f, -0.4f}, {-0.8f, 0.4f, 0.4f}, boxMat));
  b.animateTranslation(s.movingNode, {0.0f, 4.0f}, {glm::vec3(0.0f), glm::vec3(4.0f, 0, 0)});
  s.morphNode = b.addNode(
      b.addBox({0.8f, -1.2f, -0.4f}, {1.6f, -0.4f, 0.4f}, morphMat, false, {0.0f, 1.0f, 0.0f}));
  b.animateWeights(s.morphNode, {0.0f, 1.0f}, {{0.0f}, {1.0f}});
  b.addCamera({0, 0, 5}, {0, 0, 0}, kFov, 1.0f);
  b.addPointLight({0, 2, 3}, {1, 1, 1}, 50.0f);
  s.path = b.write(tempDir(tag), "aov");
  return s;
}

float at(const std::vector<float>& c, int x, int y) {
  return c[size_t(y) * kSize + x];
}

// Film x of world point p for the test's camera (at z = 5, looking along -z).
float filmX(glm::vec3 p) {
  const float d = 5.0f - p.z;
  return 0.5f * (p.x / (d * std::tan(0.5f * kFov)) + 1.0f) * kSize;
}

std::string args() {
  return "--width " + std::to_string(kSize) + " --height " + std::to_string(kSize) +
         " --fps 1 --spp 2 ";
}

TEST(Aov, ChannelsAreWrittenOnlyWhenAskedForInEveryMode) {
  const AovScene s = aovScene("aov_modes");
  const std::vector<std::string> names = {"albedo.R", "albedo.G",  "albedo.B",   "normal.X",
                                          "normal.Y", "normal.Z",  "Z",          "motion.X",
                                          "motion.Y", "object.ID", "material.ID"};
  for (const std::string mode : {"reuse", "retrace", "pathtrace", "reuse --no-eye-paths"}) {
    SCOPED_TRACE(mode);
    const std::string dir =
        renderFrames(s.path, "1", args() + "--aov all --mode " + mode, "aov_mode");
    for (const std::string& n : names) {
      const std::vector<float> c = readExrChannel(dir + "/f_0001.exr", n);
      EXPECT_EQ(c.size(), size_t(kSize * kSize)) << n;
    }
    // The wall's depth where nothing stands before it (the top row's middle).
    EXPECT_NEAR(at(readExrChannel(dir + "/f_0001.exr", "Z"), kSize / 2, 2), 7.0f, 1e-3f);
  }
  const std::string plain = renderFrames(s.path, "1", args(), "aov_none");
  EXPECT_THROW(readExrChannel(plain + "/f_0001.exr", "albedo.R"), InputError);
  // Half EXR: depth and ids stay 32-bit, the rest as the colour.
  const std::string half = tempDir("aov_half");
  const auto r = runPathreuse("render '" + s.path + "' --quiet --frames 1 --out '" + half +
                              "/f_%04d.exr' --aov depth,object " + args());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NEAR(at(readExrChannel(half + "/f_0001.exr", "Z"), kSize / 2, 2), 7.0f, 1e-4f);
  EXPECT_THROW(readExrChannel(half + "/f_0001.exr", "normal.X"), InputError);
}

TEST(Aov, AWallsAlbedoNormalDepthAndIdsAreItsOwn) {
  const AovScene s = aovScene("aov_wall");
  const std::string dir = renderFrames(s.path, "0", args() + "--aov all --force-diffuse", "aov_w");
  const std::string f = dir + "/f_0000.exr";
  const auto r = readExrChannel(f, "albedo.R"), g = readExrChannel(f, "albedo.G"),
             bl = readExrChannel(f, "albedo.B");
  const auto nx = readExrChannel(f, "normal.X"), ny = readExrChannel(f, "normal.Y"),
             nz = readExrChannel(f, "normal.Z");
  const auto z = readExrChannel(f, "Z"), obj = readExrChannel(f, "object.ID"),
             mat = readExrChannel(f, "material.ID");
  int wall = 0;
  for (int y = 0; y < 8; ++y)
    for (int x = 8; x < kSize - 8; ++x) {  // the wall's top band: nothing before it
      ++wall;
      EXPECT_NEAR(at(r, x, y), 0.2f, 1e-5f);
      EXPECT_NEAR(at(g, x, y), 0.4f, 1e-5f);
      EXPECT_NEAR(at(bl, x, y), 0.6f, 1e-5f);
      EXPECT_NEAR(at(nx, x, y), 0.0f, 1e-5f);
      EXPECT_NEAR(at(ny, x, y), 0.0f, 1e-5f);
      EXPECT_NEAR(at(nz, x, y), 1.0f, 1e-5f);
      EXPECT_NEAR(at(z, x, y), 7.0f, 1e-4f);  // along the axis, not the ray
      EXPECT_EQ(at(obj, x, y), float(s.wallNode));
      EXPECT_EQ(at(mat, x, y), 0.0f);
    }
  EXPECT_GT(wall, 0);
  // The moving box's front face at frame 0 (x from -1.6 to -0.8) and the morphed box's.
  const int bx = int(filmX({-1.2f, 0, 0.4f})), mx = int(filmX({1.2f, 0, 0.4f}));
  const int by = kSize / 2, my = kSize / 2 + 10;
  EXPECT_EQ(at(obj, bx, by), float(s.movingNode));
  EXPECT_EQ(at(mat, bx, by), 1.0f);
  EXPECT_NEAR(at(z, bx, by), 4.6f, 1e-4f);
  EXPECT_EQ(at(obj, mx, my), float(s.morphNode));
  EXPECT_EQ(at(mat, mx, my), 2.0f);
  // The default materials' albedo: the base under a little specular reflection.
  const std::string full = renderFrames(s.path, "0", args() + "--aov albedo", "aov_full");
  const auto fr = readExrChannel(full + "/f_0000.exr", "albedo.R");
  EXPECT_GT(at(fr, kSize / 2, 2), 0.2f);
  EXPECT_LT(at(fr, kSize / 2, 2), 0.3f);
}

TEST(Aov, MotionIsWhereThePreviousFrameSawTheSamePoint) {
  const AovScene s = aovScene("aov_motion");
  const std::string dir = renderFrames(s.path, "0-1", args() + "--aov motion", "aov_m");
  // One unit at the boxes' front faces (z = 0.4, 4.6 from the camera), in pixels.
  const float unit = filmX({1.0f, 0, 0.4f}) - filmX({0.0f, 0, 0.4f});
  for (int frame : {0, 1}) {
    char name[32];
    std::snprintf(name, sizeof name, "/f_%04d.exr", frame);
    const auto mx = readExrChannel(dir + name, "motion.X"),
               my = readExrChannel(dir + name, "motion.Y");
    // The wall stood still: exactly none; before frame 0 nothing moved either.
    EXPECT_EQ(at(mx, kSize / 2, 2), 0.0f);
    EXPECT_EQ(at(my, kSize / 2, 2), 0.0f);
    // The translated box (at frame 1, x from -0.6 to 0.2): it was 1 unit to the left.
    const int bx = int(filmX({-0.2f, 0, 0.4f})), by = kSize / 2;
    EXPECT_NEAR(at(mx, bx, by), frame == 1 ? -unit : 0.0f, 1e-3f * unit) << frame;
    EXPECT_NEAR(at(my, bx, by), 0.0f, 1e-3f * unit) << frame;
    // The morphed box, lifted 1 unit since frame 0: it was lower (film y grows downwards).
    const int mx0 = int(filmX({1.2f, 0, 0.4f})), my0 = kSize / 2 + 2;
    EXPECT_NEAR(at(mx, mx0, my0), 0.0f, 1e-3f * unit) << frame;
    EXPECT_NEAR(at(my, mx0, my0), frame == 1 ? unit : 0.0f, 1e-3f * unit) << frame;
  }
}

// Under an orbiting camera every pixel moves: the previous frame's albedo fetched where the
// motion points matches this frame's far better than the same pixel's does.
TEST(Aov, MotionWarpsThePreviousFrameOntoThisOneUnderAMovingCamera) {
  const int w = 80, h = 60;
  const std::string dir = renderFrames(sourcePath("scenes/cornell-orbit.gltf"), "4-5",
                                       "--width 80 --height 60 --spp 4 --fps 2 --force-diffuse "
                                       "--aov albedo,motion",
                                       "aov_orbit");
  const std::vector<float> now = readExrChannel(dir + "/f_0005.exr", "albedo.G"),
                           then = readExrChannel(dir + "/f_0004.exr", "albedo.G"),
                           mx = readExrChannel(dir + "/f_0005.exr", "motion.X"),
                           my = readExrChannel(dir + "/f_0005.exr", "motion.Y");
  double warped = 0.0, still = 0.0, moved = 0.0;
  int n = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t p = size_t(y) * w + x;
      const int qx = int(std::floor(x + 0.5f + mx[p])), qy = int(std::floor(y + 0.5f + my[p]));
      if (qx < 0 || qy < 0 || qx >= w || qy >= h) continue;
      ++n;
      warped += std::fabs(now[p] - then[size_t(qy) * w + qx]);
      still += std::fabs(now[p] - then[p]);
      moved += std::hypot(mx[p], my[p]);
    }
  ASSERT_GT(n, w * h / 2);
  EXPECT_GT(moved / n, 0.5) << "the camera should move the image by some pixels";
  EXPECT_LT(warped, 0.5 * still) << "warped " << warped / n << ", unwarped " << still / n;
}

// Two devices split the colour, and the first makes the auxiliary images for the whole image:
// they are one device's, bit for bit; each pixel's sample count is the devices' together.
TEST(Aov, TwoDevicesGiveOneDevicesImages) {
  const AovScene s = aovScene("aov_devices");
  const std::string two = twoPoclDevices(), one = two.substr(0, two.find(" --device", 1));
  std::vector<std::string> dirs;
  for (const std::string& devices : {one, two}) {
    dirs.push_back(tempDir("aov_dev"));
    const auto r = runPathreuse("render '" + s.path + "' --quiet --exr-float --frames 0-1 --out '" +
                                    dirs.back() + "/f_%04d.exr' --aov all " + args() + devices,
                                kTwoPoclDrivers);
    ASSERT_EQ(r.exitCode, 0) << r.err;
  }
  for (const char* c :
       {"albedo.R", "normal.Z", "Z", "motion.X", "motion.Y", "object.ID", "samples"})
    EXPECT_EQ(readExrChannel(dirs[0] + "/f_0001.exr", c),
              readExrChannel(dirs[1] + "/f_0001.exr", c))
        << c;
}

TEST(Aov, AnUnknownImageIsAnInputError) {
  const AovScene s = aovScene("aov_bad");
  const auto r = runPathreuse("render '" + s.path + "' --quiet --frames 0 --out '" +
                              tempDir("aov_bad_out") + "/f_%04d.exr' --aov albedo,shadow");
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_NE(r.err.find("--aov albedo,shadow: unknown image 'shadow'"), std::string::npos) << r.err;
  EXPECT_EQ(lineCount(r.err), 1u) << r.err;
}

// --denoise (render/denoise.h, Open Image Denoise from tools/setup/oidn.sh, which the install
// script runs): the colour becomes the denoised image, closer to a converged one than the noisy
// one it keeps as noisy.R/G/B, which is the render without --denoise.
TEST(Denoise, TheColourIsDenoisedAndTheNoisyOneKept) {
  const std::string scene = sourcePath("scenes/cornell-dynamic.gltf");
  const std::string size = "--width 96 --height 72 --spp 2 ";
  const std::string noisy = renderFrames(scene, "3", size, "denoise_off");
  const std::string denoised = renderFrames(scene, "3", size + "--denoise", "denoise_on");
  const std::string ref =
      renderFrames(scene, "3", "--width 96 --height 72 --spp 256 --seed 9", "denoise_ref");
  const Image n = frameImage(noisy, 3), d = frameImage(denoised, 3), r = frameImage(ref, 3);
  const char* names[3] = {"noisy.R", "noisy.G", "noisy.B"};
  for (int c = 0; c < 3; ++c) {
    const std::vector<float> kept = readExrChannel(denoised + "/f_0003.exr", names[c]);
    for (size_t p = 0; p < kept.size(); ++p)
      ASSERT_EQ(kept[p], n.rgba[p * 4 + c]) << names[c] << " pixel " << p;
  }
  const double before = compareImages(n, r).relMse, after = compareImages(d, r).relMse;
  EXPECT_LT(after, 0.25 * before) << "noisy " << before << ", denoised " << after;
  EXPECT_EQ(compareImages(d, r).nonFinite, 0u);
  // Without --denoise there is nothing but the colour.
  EXPECT_THROW(readExrChannel(noisy + "/f_0003.exr", "noisy.R"), InputError);
}

TEST(Denoise, WithoutTheLibraryItIsAnInputErrorThatSaysHowToInstallIt) {
  const std::string out = tempDir("denoise_missing");
  const auto r =
      runPathreuse("render '" + sourcePath("scenes/cornell-dynamic.gltf") +
                       "' --quiet --frames 0 --width 32 --denoise --out '" + out + "/f_%04d.exr'",
                   "PATHREUSE_OIDN=/nonexistent/libOpenImageDenoise.so.2");
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_NE(r.err.find("--denoise: Open Image Denoise 2 not found"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("bash tools/setup/oidn.sh"), std::string::npos) << r.err;
  EXPECT_EQ(lineCount(r.err), 1u) << r.err;
  EXPECT_FALSE(std::ifstream(out + "/f_0000.exr").good());
}

// The library tools/setup/oidn.sh installs (render/denoise.cpp looks there first).
std::string installedOidn() {
  const char* xdg = std::getenv("XDG_CACHE_HOME");
  const std::string root = xdg && *xdg ? std::string(xdg) + "/pathreuse"
                                       : std::string(std::getenv("HOME")) + "/.cache/pathreuse";
  return root + "/oidn/libOpenImageDenoise.so.2";
}

// A library cut short (dlopen would map it and die of SIGBUS), a FIFO in its place (opening it
// would wait for a writer) or a file that is no library: one line naming it, exit 2, no frame.
TEST(Denoise, ADamagedLibraryIsOneLineExitTwoBeforeRendering) {
  const std::string lib = installedOidn();
  ASSERT_TRUE(fs::is_regular_file(lib)) << lib << " absent: tools/setup/oidn.sh installs it";
  const std::string dir = tempDir("denoise_damaged");
  const std::string cut = dir + "/cut/libOpenImageDenoise.so.2";
  fs::create_directories(dir + "/cut");
  fs::copy_file(lib, cut);
  fs::resize_file(cut, 64 * 1024);
  const std::string fifo = dir + "/fifo/libOpenImageDenoise.so.2";
  fs::create_directories(dir + "/fifo");
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  const std::string text = dir + "/text/libOpenImageDenoise.so.2";
  fs::create_directories(dir + "/text");
  std::ofstream(text) << "not a library\n";
  for (const auto& [path, why] : {std::pair<std::string, std::string>{cut, "is cut short"},
                                  {fifo, "is not a regular file"},
                                  {text, "is not a 64-bit ELF shared object"}}) {
    SCOPED_TRACE(path);
    const auto r = runPathreuse("render '" + sourcePath("scenes/cornell-dynamic.gltf") +
                                    "' --quiet --frames 0 --width 32 --denoise --out '" + dir +
                                    "/out/f_%04d.exr'",
                                "timeout 60 env PATHREUSE_OIDN='" + path + "'");
    EXPECT_EQ(r.exitCode, 2) << r.err;
    EXPECT_NE(r.err.find(path + " " + why), std::string::npos) << r.err;
    EXPECT_EQ(lineCount(r.err), 1u) << r.err;
    EXPECT_FALSE(fs::exists(dir + "/out/f_0000.exr"));
  }
}

}  // namespace
}  // namespace pr::test
