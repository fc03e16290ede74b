// The render options' table (host/app/render_cli.cpp): where each option lands, what --help and
// --help-all list, the estimator key, and the generated option tables in the docs.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <fstream>
#include <map>
#include <sstream>

#include <CLI/CLI.hpp>

#include "app/render_cli.h"
#include "util/error.h"
#include "support/test_env.h"

namespace pr {
namespace {

struct Parsed {
  RenderArgs args;
  CLI::App app;
  CLI::App* render = nullptr;
  explicit Parsed(bool listResearch = false) { render = addRenderCommand(app, args, listResearch); }
  RenderOptions parse(const std::string& line) {
    app.parse("render scene.gltf " + line, false);
    return toRenderOptions(args, *render);
  }
};

TEST(RenderCli, OptionsLandInTheirFields) {
  Parsed p;
  const RenderOptions o = p.parse(
      "--frames 3-7 --fps 30 --camera 2 --width 64 --height 48 --out o/f_%03d.exr --video v.mp4 "
      "--spp 9 --seed 4000000000 --mode pathtrace --max-depth 5 --time-limit 1.5 "
      "--noise-threshold 0.05 --adaptive-min-spp 3 --device cpu --device 0:1 --warm-up 2 -q "
      "--resample --resample-radius 5 --resample-history 7 --resample-mis-count 2.5 "
      "--light-paths 1000 --paths-per-pixel 2 --connections 3 --no-eye-paths --no-light-tracing "
      "--light-sampler power --material-model gltf-reference --shadow-terminator off "
      "--bvh-width 4 --env-color 1,2,3 --env-rotate -90 --fixed-noise");
  EXPECT_EQ(o.frames.first, 3);
  EXPECT_EQ(o.frames.last, 7);
  EXPECT_EQ(o.fps, 30.0);
  EXPECT_EQ(o.camera, 2);
  EXPECT_EQ(o.width, 64);
  EXPECT_EQ(o.height, 48);
  EXPECT_EQ(o.outPattern, "o/f_%03d.exr");
  EXPECT_EQ(o.video, "v.mp4");
  EXPECT_TRUE(o.png) << "--video writes the PNGs it is encoded from";
  EXPECT_EQ(o.spp, 9);
  EXPECT_EQ(o.seed, 4000000000u);
  EXPECT_EQ(o.mode, RenderMode::PathTrace);
  EXPECT_EQ(o.maxDepth, 5);
  EXPECT_EQ(o.timeLimit, 1.5);
  EXPECT_EQ(o.noiseThreshold, 0.05f);
  EXPECT_EQ(o.adaptiveMinSpp, 3);
  EXPECT_EQ(o.devices, (std::vector<std::string>{"cpu", "0:1"}));
  EXPECT_EQ(o.warmUp, 2);
  EXPECT_TRUE(o.quiet);
  EXPECT_EQ(o.resample.asked, std::optional<bool>(true));
  EXPECT_EQ(o.resample.radius, 5.0f);
  EXPECT_EQ(o.resample.history, 7);
  EXPECT_EQ(o.resample.misCount, 2.5f);
  EXPECT_EQ(o.connect.arenaSlots, 1000);
  EXPECT_EQ(o.connect.pathsPerPixel, 2);
  EXPECT_EQ(o.connect.resample, 3);
  EXPECT_FALSE(o.connect.eyePaths);
  EXPECT_EQ(o.connect.lightTracing, std::optional<bool>(false));
  EXPECT_EQ(o.lightSampler, LightSampler::Power);
  EXPECT_EQ(o.materialModel, MaterialModel::Gltf);
  EXPECT_FALSE(o.shadowTerminator);
  EXPECT_EQ(o.bvhWidth, 4);
  EXPECT_EQ(o.envColor, "1,2,3");
  EXPECT_EQ(o.envRotate, -90.0f);
  EXPECT_TRUE(o.fixedNoise);
}

TEST(RenderCli, DefaultsAreRenderOptionsDefaults) {
  Parsed p;
  const RenderOptions o = p.parse("");
  const RenderOptions fresh;
  EXPECT_EQ(o.spp, fresh.spp);
  EXPECT_EQ(o.mode, RenderMode::Reuse);
  EXPECT_EQ(o.outPattern, fresh.outPattern);
  EXPECT_FALSE(o.framesGiven);
  EXPECT_FALSE(o.resample.asked.has_value());
  EXPECT_FALSE(o.connect.lightTracing.has_value());
  EXPECT_EQ(o.connect.resample, -1);
  EXPECT_EQ(o.bvhWidth, 0);
}

// --help lists what every user needs; --help-all the research knobs too, under their groups.
// Hidden or not, a knob parses and names itself in its errors.
// Options built in code meet the table's ranges too: each value outside its option's range is
// refused naming the option and the value; the defaults (automatic sentinels included) and a
// value within range pass.
TEST(RenderCli, OptionsBuiltInCodeMeetTheTablesRanges) {
  EXPECT_NO_THROW(checkOptionRanges(RenderOptions{}));
  RenderOptions fine;
  fine.spp = 16;
  fine.connect.pathsPerPixel = 64;
  fine.resample.radius = 256.0f;
  EXPECT_NO_THROW(checkOptionRanges(fine));
  const std::vector<std::pair<std::function<void(RenderOptions&)>, std::string>> bad = {
      {[](RenderOptions& o) { o.spp = 0; }, "--spp 0: "},
      {[](RenderOptions& o) { o.maxDepth = 65; }, "--max-depth 65: "},
      {[](RenderOptions& o) { o.fps = 0.0; }, "--fps 0: "},
      {[](RenderOptions& o) { o.width = -3; }, "--width -3: "},
      {[](RenderOptions& o) { o.connect.pathsPerPixel = 0; }, "--paths-per-pixel 0: "},
      {[](RenderOptions& o) { o.connect.clamp = -1.0f; }, "--clamp -1: "},
      {[](RenderOptions& o) { o.connect.historyPeriod = 0; }, "--connection-history-period 0: "},
      {[](RenderOptions& o) { o.resample.radius = 0.5f; }, "--resample-radius 0.5: "},
      {[](RenderOptions& o) { o.envStrength = std::nanf(""); }, "--env-strength nan: "},
      {[](RenderOptions& o) { o.exposure = 100.0f; }, "--exposure 100: "},
      {[](RenderOptions& o) { o.motionTolerance = 0.0; }, "--motion-tolerance 0: "},
  };
  for (const auto& [edit, message] : bad) {
    RenderOptions o;
    edit(o);
    try {
      checkOptionRanges(o);
      ADD_FAILURE() << message << "was accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind(message, 0), 0u) << e.what();
    }
  }
}

TEST(RenderCli, HelpListsEverydayOptionsAndHelpAllTheResearchKnobs) {
  Parsed brief(false), all(true);
  const std::string shortHelp = brief.render->help();
  const std::string longHelp = all.render->help();
  for (const OptionSummary& s : renderOptionSummaries()) {
    // An entry starts its line ("  --spp INT..."; "  -q,--quiet").
    const bool listed = shortHelp.find("\n  " + s.name) != std::string::npos ||
                        shortHelp.find("," + s.name) != std::string::npos;
    EXPECT_EQ(listed, s.audience == OptionAudience::Everyday) << s.name;
    EXPECT_NE(longHelp.find(s.name), std::string::npos) << s.name;
  }
  for (const char* everyday : {"--frames", "--width", "--spp", "--mode", "--out", "--png",
                               "--video", "--denoise", "--device", "--resume"})
    EXPECT_NE(shortHelp.find(everyday), std::string::npos) << everyday;
  EXPECT_NE(longHelp.find("Path resampling:"), std::string::npos) << longHelp;
  EXPECT_EQ(shortHelp.find("Path resampling:"), std::string::npos) << shortHelp;
  EXPECT_EQ(shortHelp.find("\n\n\n\n"), std::string::npos) << "empty groups leave gaps";

  EXPECT_EQ(brief.parse("--resample-radius 5").resample.radius, 5.0f);
  Parsed bad;
  try {
    bad.parse("--resample-radius 500");
    FAIL() << "accepted a radius out of range";
  } catch (const CLI::ParseError& e) {
    EXPECT_NE(std::string(e.what()).find("--resample-radius"), std::string::npos) << e.what();
  }
}

// A value for each option that takes one, other than its default.
const std::map<std::string, std::string> kSampleValues = {
    {"--animation", "1"},
    {"--frames", "2-3"},
    {"--fps", "25"},
    {"--shutter", "0.5"},
    {"--motion-tolerance", "2"},
    {"--camera", "1"},
    {"--width", "33"},
    {"--height", "21"},
    {"--out", "x/f_%02d.exr"},
    {"--video", "v.mkv"},
    {"--time-limit", "2"},
    {"--noise-threshold", "0.1"},
    {"--adaptive-min-spp", "2"},
    {"--aov", "depth"},
    {"--exposure", "1"},
    {"--stats", "s.jsonl"},
    {"--warm-up", "3"},
    {"--mode", "retrace"},
    {"--spp", "3"},
    {"--max-depth", "4"},
    {"--seed", "9"},
    {"--light-sampler", "bvh"},
    {"--env-light-choice", "power"},
    {"--resample-neighbors", "2"},
    {"--resample-radius", "4"},
    {"--resample-roughness", "0.5"},
    {"--resample-distance", "1"},
    {"--resample-history", "3"},
    {"--resample-mis-count", "8"},
    {"--light-paths", "99"},
    {"--paths-per-pixel", "3"},
    {"--clamp", "10"},
    {"--connection-mis", "2"},
    {"--connections", "1"},
    {"--connection-history", "4"},
    {"--connection-history-period", "2"},
    {"--material-model", "gltf-reference"},
    {"--shadow-terminator", "off"},
    {"--env", "none"},
    {"--env-color", "1,1,1"},
    {"--env-strength", "2"},
    {"--env-rotate", "10"},
    {"--emit-base-color", "1"},
    {"--emit-strength", "2"},
    {"--device", "cpu"},
    {"--bvh-width", "2"},
};

// The resume history is used only under the same key: every option that can change a frame's
// pixels changes it, and no other does.
TEST(RenderCli, TheKeyChangesWithEveryEstimatorOptionAndNoOther) {
  const std::string base = Parsed().parse("").estimatorKey;
  for (const OptionSummary& s : renderOptionSummaries()) {
    std::string arg = s.name;
    if (!s.flag) {
      const auto v = kSampleValues.find(s.name);
      ASSERT_NE(v, kSampleValues.end()) << s.name << " needs a sample value here";
      arg += " " + v->second;
    }
    const std::string key = Parsed().parse(arg).estimatorKey;
    if (s.effect == OptionEffect::Estimator)
      EXPECT_NE(key, base) << s.name;
    else
      EXPECT_EQ(key, base) << s.name;
  }
  EXPECT_NE(Parsed().parse("--no-eye-paths").estimatorKey, base);
  EXPECT_NE(Parsed().parse("--no-light-tracing").estimatorKey,
            Parsed().parse("--light-tracing").estimatorKey);
}

std::string readFile(const std::string& rel) {
  std::ifstream in(test::sourcePath(rel));
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// README's table of everyday options and docs/options.md are the table's output.
TEST(RenderCli, TheDocsTablesAreGeneratedFromTheTable) {
  const char* const fix = "regenerate them: python3 tools/docs/option_tables.py";
  const std::string readme = readFile("README.md");
  const std::string begin = "<!-- options:begin";
  const std::string end = "<!-- options:end -->";
  const size_t b = readme.find(begin);
  const size_t e = readme.find(end);
  ASSERT_NE(b, std::string::npos) << "README.md has no options block";
  ASSERT_NE(e, std::string::npos);
  const size_t tableStart = readme.find('\n', b) + 1;
  EXPECT_EQ(readme.substr(tableStart, e - tableStart), renderOptionsMarkdown(false)) << fix;
  const std::string all = readFile("docs/options.md");
  EXPECT_NE(all.find(renderOptionsMarkdown(true)), std::string::npos) << fix;
}

}  // namespace
}  // namespace pr
