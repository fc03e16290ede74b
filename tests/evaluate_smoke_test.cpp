// The evaluation benchmark's short form (tools/bench/evaluate.py --quick): every output is written
// and its numbers are sane. Never a timing. Needs /usr/bin/python3 with numpy and matplotlib
// (tools/setup/install-deps.sh), or the Python that $PATHREUSE_PYTHON names (a machine whose system
// Python lacks them); without them the script exits 1 and this test fails.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "support/test_env.h"

namespace pr {
namespace {

using test::slurp;

namespace fs = std::filesystem;

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

void expectQuality(const nlohmann::json& s, const std::string& where) {
  EXPECT_GE(s.at("relmse").get<double>(), 0.0) << where;
  EXPECT_LT(s.at("relmse").get<double>(), 100.0) << where;
  EXPECT_GE(s.at("flicker").get<double>(), 0.0) << where;
  EXPECT_LT(s.at("flicker").get<double>(), 100.0) << where;
  EXPECT_GT(s.at("time_s_per_frame").at("median").get<double>(), 0.0) << where;
}

TEST(Evaluate, QuickFormWritesEveryOutputWithSaneNumbers) {
  const std::string dir = test::tempDir("evaluate");
  const std::string build = fs::path(PATHREUSE_BINARY).parent_path().string();
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
    ASSERT_GE(s.at("sweep").size(), 4u) << name;
    for (const auto& q : s.at("sweep")) expectQuality(q, std::string(name) + " sweep");
    const auto& et = s.at("equal_time");
    for (const char* k : {"reuse", "pathtrace_fresh", "pathtrace_fixed"})
      expectQuality(et.at(k), std::string(name) + " equal time " + k);
    EXPECT_GT(et.at("time_ratio_pathtrace_over_reuse").get<double>(), 0.0);
    EXPECT_GT(s.at("equal_error").at("target_relmse").get<double>(), 0.0) << name;
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
