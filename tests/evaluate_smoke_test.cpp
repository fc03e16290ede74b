// The evaluation benchmark's short form (tools/bench/evaluate.py --quick): every output is written
// and its numbers hold what they must (relMSE and flicker of noisy renders positive, the trimmed
// relMSE at most the plain one, less error at more samples, flicker about twice relMSE for fresh
// noise and lower with frozen noise). Never a timing. Needs /usr/bin/python3 with numpy and
// matplotlib (tools/setup/install-deps.sh), or the Python that $PATHREUSE_PYTHON names (a machine
// whose system Python lacks them); without them the script exits 1 and this test fails.
// And exr_compare, through which the evaluation measures relMSE: 0 for an image against itself,
// the formula's value for two known images.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/image.h"
#include "support/test_env.h"

namespace pr {
namespace {

using test::slurp;

namespace fs = std::filesystem;

std::string buildDir() {
  return fs::path(PATHREUSE_BINARY).parent_path().string();
}

// exr_compare's JSON for A against the reference B.
nlohmann::json exrCompare(const std::string& a, const std::string& b) {
  const std::string out = test::tempDir("exr-compare") + "/out.json";
  const std::string cmd =
      "'" + buildDir() + "/exr_compare' '" + a + "' '" + b + "' >'" + out + "' 2>&1";
  const int status = std::system(cmd.c_str());
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << cmd << "\n" << slurp(out);
  return nlohmann::json::parse(slurp(out), nullptr, false);
}

// relMSE as the evaluation defines it (results.md): mean over pixels and RGB of
// (I - R)^2 / (R^2 + 0.01); trimmed: the same sum without the 1% of pixels with the largest
// terms, over all pixels.
void expectedRelMse(const Image& img, const Image& ref, double& plain, double& trimmed) {
  std::vector<double> perPixel;
  for (size_t i = 0; i < img.rgba.size(); i += 4) {
    double e = 0.0;
    for (int c = 0; c < 3; ++c) {
      const double d = double(img.rgba[i + c]) - double(ref.rgba[i + c]);
      e += d * d / (double(ref.rgba[i + c]) * ref.rgba[i + c] + 0.01);
    }
    perPixel.push_back(e / 3.0);
  }
  const size_t n = perPixel.size(), drop = n / 100;
  std::sort(perPixel.begin(), perPixel.end());
  plain = trimmed = 0.0;
  for (size_t i = 0; i < n; ++i) (i + drop < n ? trimmed : plain) += perPixel[i];
  plain = (plain + trimmed) / double(n);
  trimmed /= double(n);
}

TEST(ExrCompare, RelMseIsZeroAgainstItselfAndTheFormulaOtherwise) {
  // 20 x 10 pixels (2 of them trimmed), a smooth image and a noisy copy with two fireflies.
  Image ref(20, 10), img(20, 10);
  for (int y = 0; y < ref.height; ++y)
    for (int x = 0; x < ref.width; ++x)
      for (int c = 0; c < 4; ++c) {
        ref.pixel(x, y)[c] = c == 3 ? 1.0f : 0.05f * float(x + c) + 0.1f * float(y);
        img.pixel(x, y)[c] =
            ref.pixel(x, y)[c] * (c == 3 ? 1.0f : 1.0f + 0.1f * float((x * 7 + y * 3 + c) % 5 - 2));
      }
  img.pixel(3, 4)[1] = 40.0f;
  img.pixel(17, 8)[0] = 25.0f;
  const std::string dir = test::tempDir("exr-compare-images");
  writeExr(dir + "/ref.exr", ref, ExrPixels::Float);
  writeExr(dir + "/img.exr", img, ExrPixels::Float);

  const auto self = exrCompare(dir + "/ref.exr", dir + "/ref.exr");
  ASSERT_TRUE(self.is_object()) << self;
  EXPECT_EQ(self.at("relmse").get<double>(), 0.0);
  EXPECT_EQ(self.at("relmse_trimmed").get<double>(), 0.0);
  EXPECT_EQ(self.at("mad").get<double>(), 0.0);
  EXPECT_TRUE(self.at("identical").get<bool>());

  double plain = 0.0, trimmed = 0.0;
  expectedRelMse(img, ref, plain, trimmed);
  ASSERT_GT(plain, 10.0 * trimmed);  // the fireflies decide the plain one
  const auto d = exrCompare(dir + "/img.exr", dir + "/ref.exr");
  ASSERT_TRUE(d.is_object()) << d;
  EXPECT_NEAR(d.at("relmse").get<double>(), plain, 1e-12 * plain);
  EXPECT_NEAR(d.at("relmse_trimmed").get<double>(), trimmed, 1e-12 * trimmed);
  EXPECT_EQ(d.at("non_finite").get<int>(), 0);
  EXPECT_FALSE(d.at("identical").get<bool>());
  // The second file is the reference: the other way round weighs by the other image.
  double swapped = 0.0, swappedTrimmed = 0.0;
  expectedRelMse(ref, img, swapped, swappedTrimmed);
  EXPECT_NEAR(exrCompare(dir + "/ref.exr", dir + "/img.exr").at("relmse").get<double>(), swapped,
              1e-12 * swapped);
  EXPECT_GT(std::fabs(swapped - plain), 0.1 * plain);
}

// Every number in the document is finite.
void expectFinite(const nlohmann::json& j, const std::string& where) {
  if (j.is_number()) {
    EXPECT_TRUE(std::isfinite(j.get<double>())) << where;
  } else if (j.is_object()) {
    for (const auto& [k, v] : j.items()) expectFinite(v, where + "." + k);
  } else if (j.is_array()) {
    for (size_t i = 0; i < j.size(); ++i) expectFinite(j[i], where + "[" + std::to_string(i) + "]");
  }
}

// One quality row of `frames` frames: renders at a few spp against a reference at another
// seed are never exact, so relMSE and flicker are positive (0 would be an image compared with
// itself); the trimmed relMSE leaves terms out of the same sum, so it is at most the plain one.
void expectQuality(const nlohmann::json& s, size_t frames, const std::string& where) {
  const double relmse = s.at("relmse").get<double>(), trim = s.at("relmse_trim").get<double>();
  EXPECT_GT(relmse, 0.0) << where;
  EXPECT_LT(relmse, 100.0) << where;
  EXPECT_GT(trim, 0.0) << where;
  EXPECT_LE(trim, relmse) << where;
  EXPECT_GT(s.at("flicker").get<double>(), 0.0) << where;
  EXPECT_LT(s.at("flicker").get<double>(), 100.0) << where;
  ASSERT_EQ(s.at("relmse_per_frame").size(), frames) << where;
  for (const auto& e : s.at("relmse_per_frame")) EXPECT_GT(e.get<double>(), 0.0) << where;
  EXPECT_EQ(s.at("flicker_per_pair").size(), frames - 1) << where;
  EXPECT_GT(s.at("time_s_per_frame").at("median").get<double>(), 0.0) << where;
}

// The quality row of (mode, spp, fixed noise) in a scene's sweep, or null.
const nlohmann::json* sweepRow(const nlohmann::json& scene, const std::string& mode, int spp,
                               bool fixed) {
  for (const auto& q : scene.at("sweep"))
    if (q.at("mode") == mode && q.at("spp") == spp && q.at("fixed_noise") == fixed) return &q;
  return nullptr;
}

TEST(Evaluate, QuickFormWritesEveryOutputWithSaneNumbers) {
  const std::string dir = test::tempDir("evaluate");
  const std::string build = buildDir();
  const std::string log = dir + "/log.txt";
  const char* python = std::getenv("PATHREUSE_PYTHON");
  // A module of the tools package, run from the repository root.
  const std::string cmd = "cd '" + test::sourcePath("") + "' && " +
                          std::string(python && *python ? python : "/usr/bin/python3") +
                          " -m tools.bench.evaluate --quick --quiet --out-dir '" + dir +
                          "' --build '" + build + "' >'" + log + "' 2>&1";
  const int status = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << cmd << "\n" << slurp(log);

  const std::string md = slurp(dir + "/results.md");
  EXPECT_NE(md.find("## Goals"), std::string::npos);
  EXPECT_NE(md.find("relMSE"), std::string::npos);

  const auto j = nlohmann::json::parse(slurp(dir + "/results.json"));
  expectFinite(j, "results");
  ASSERT_GE(j.at("plots").size(), 5u);
  for (const auto& p : j.at("plots")) {
    const std::string png = slurp(dir + "/" + p.get<std::string>());
    ASSERT_GT(png.size(), 1000u) << p;
    EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8)) << p;
    EXPECT_NE(md.find(p.get<std::string>()), std::string::npos) << "results.md shows " << p;
  }

  const auto& scenes = j.at("scenes");
  for (const char* name : {"cornell-dynamic", "cornell-orbit", "atrium"}) {
    ASSERT_TRUE(scenes.contains(name)) << name;
    const auto& s = scenes.at(name);
    for (const char* mode : {"reuse", "retrace", "pathtrace"}) {
      const auto& t = s.at("timing").at(mode);
      EXPECT_GT(t.at("wall_s_per_frame").at("median").get<double>(), 0.0) << name << " " << mode;
      EXPECT_LE(t.at("wall_s_per_frame").at("min").get<double>(),
                t.at("wall_s_per_frame").at("max").get<double>());
      EXPECT_GT(t.at("rays_per_frame").at("camera").get<double>(), 0.0) << name << " " << mode;
    }
    // Reuse and retrace give the same images.
    EXPECT_EQ(s.at("reuse_equals_retrace_max_abs_diff").get<double>(), 0.0) << name;
    const size_t frames =
        s.at("quality_frames").at(1).get<size_t>() - s.at("quality_frames").at(0).get<size_t>() + 1;
    ASSERT_EQ(frames, 5u) << name;  // --quick
    ASSERT_GE(s.at("sweep").size(), 4u) << name;
    for (const auto& q : s.at("sweep")) {
      const std::string where = std::string(name) + " sweep " + q.at("mode").get<std::string>() +
                                " spp " + std::to_string(q.at("spp").get<int>()) +
                                (q.at("fixed_noise").get<bool>() ? " fixed" : "");
      expectQuality(q, frames, where);
      // Fresh noise every frame: a frame difference holds two frames' independent errors (and
      // the reference's, which the reference's own difference takes out), so F is about twice
      // relMSE; a firefly counts once in relMSE and in one or two pairs (1.25x to 2.5x here).
      if (q.at("mode") == "pathtrace" && !q.at("fixed_noise").get<bool>()) {
        const double ratio = q.at("flicker").get<double>() / q.at("relmse").get<double>();
        EXPECT_GT(ratio, 1.0) << where;
        EXPECT_LT(ratio, 3.0) << where;
      }
    }
    // Four times the samples, less error (--quick sweeps spp 1 and 4).
    const auto *pt1 = sweepRow(s, "pathtrace", 1, false), *pt4 = sweepRow(s, "pathtrace", 4, false);
    ASSERT_TRUE(pt1 && pt4) << name;
    EXPECT_LT(pt4->at("relmse").get<double>(), pt1->at("relmse").get<double>()) << name;
    const auto& et = s.at("equal_time");
    for (const char* k : {"reuse", "pathtrace_fresh", "pathtrace_fixed"})
      expectQuality(et.at(k), frames, std::string(name) + " equal time " + k);
    // A still camera and the same noise every frame: the noise of static pixels cancels in F.
    if (s.at("camera") == "still") {
      EXPECT_LT(et.at("pathtrace_fixed").at("flicker").get<double>(),
                et.at("pathtrace_fresh").at("flicker").get<double>())
          << name;
    }
    EXPECT_GT(et.at("time_ratio_pathtrace_over_reuse").get<double>(), 0.0);
    EXPECT_GT(s.at("equal_error").at("target_relmse").get<double>(), 0.0) << name;

    // The cached references, as exr_compare measures them for the evaluation: a frame against
    // itself 0, against the next frame (objects moved, other noise) more.
    const std::string ref =
        dir + "/.cache/" + name + "_" + s.at("reference_cache_key").get<std::string>() + "_f000";
    ASSERT_TRUE(fs::is_regular_file(ref + "0.exr")) << ref << "0.exr";
    EXPECT_EQ(exrCompare(ref + "0.exr", ref + "0.exr").at("relmse").get<double>(), 0.0) << name;
    EXPECT_GT(exrCompare(ref + "1.exr", ref + "0.exr").at("relmse").get<double>(), 0.0) << name;
  }
  ASSERT_GE(j.at("goals").size(), 3u);
  for (const auto& g : j.at("goals")) {
    EXPECT_TRUE(g.at("met").is_boolean());
    const std::string v = g.at("verdict").get<std::string>();
    EXPECT_TRUE(v == "met" || v == "not met" || v == "undetermined") << v;
    EXPECT_EQ(g.at("met").get<bool>(), v == "met") << v;
  }
}

}  // namespace
}  // namespace pr
