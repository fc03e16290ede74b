// `pathreuse info` as a user meets it: the summary, the JSON keys, and broken files.
#include <gtest/gtest.h>

#include <fstream>

#include <nlohmann/json.hpp>

#include "support/test_env.h"

namespace pr {
namespace {

using test::lineCount;

TEST(SceneCli, InfoCornellJson) {
  const std::string path = test::sharedScene("cornell-nvpro/cornellBox.gltf");
  ASSERT_FALSE(path.empty())
      << "../shared/scenes is absent: the tests need ../shared beside the project";
  const auto r = test::runPathreuse("info --json '" + path + "'");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  // 16,720 triangles in the file's meshes; one mesh placed twice (floor and ceiling) adds 12.
  EXPECT_EQ(j["triangles"]["static_per_mesh"], 16720);
  EXPECT_EQ(j["triangles"]["static"], 16732);
  EXPECT_EQ(j["triangles"]["dynamic"], 0);
  EXPECT_EQ(j["instances"]["dynamic"], 0);
  EXPECT_EQ(j["materials"], 9);
  EXPECT_EQ(j["textures"], 0);
  EXPECT_EQ(j["lights"]["emissive_triangles"], 12);
  EXPECT_EQ(j["lights"]["punctual"], 0);
  EXPECT_EQ(j["cameras"], 1);
  EXPECT_EQ(j["animation"]["duration_s"], 0.0);
  EXPECT_EQ(j["animation"]["frames"], 1);
  EXPECT_EQ(j["animation"]["fps"], 24.0);
  ASSERT_EQ(j["bounds"]["min"].size(), 3u);
  ASSERT_EQ(j["bounds"]["max"].size(), 3u);
  EXPECT_NEAR(j["bounds"]["max"][0].get<double>(), 5.05, 1e-4);
}

TEST(SceneCli, InfoBoxAnimated) {
  const std::string path = test::sharedScene("BoxAnimated/BoxAnimated.gltf");
  ASSERT_FALSE(path.empty())
      << "../shared/scenes is absent: the tests need ../shared beside the project";
  auto r = test::runPathreuse("info --json --fps 10 '" + path + "'");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_GT(j["triangles"]["dynamic"].get<int>(), 0);
  EXPECT_EQ(j["instances"]["dynamic"], 1);
  EXPECT_EQ(j["animation"]["fps"], 10.0);
  EXPECT_EQ(j["animation"]["frames"], 38);  // floor(3.708 * 10) + 1
  r = test::runPathreuse("info '" + path + "'");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.out.find("62 dynamic"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("89 frames at 24 fps"), std::string::npos) << r.out;
}

TEST(SceneCli, BrokenFileIsOneLineExitTwo) {
  const std::string dir = test::tempDir("cli-scene");
  const std::string broken = dir + "/broken.gltf";
  std::ofstream(broken) << R"({"asset": {"version": "2.0"}, "scene": 0})";  // no scene 0
  for (const std::string& path : {broken, dir + "/missing.gltf"}) {
    const auto r = test::runPathreuse("info '" + path + "'");
    EXPECT_EQ(r.exitCode, 2) << r.out << r.err;
    EXPECT_EQ(lineCount(r.err), 1u) << r.err;
    EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(path), std::string::npos) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
  }
}

TEST(SceneCli, InfoUsageErrors) {
  auto r = test::runPathreuse("info");
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_EQ(lineCount(r.err), 1u) << r.err;
  const std::string path = test::sharedScene("BoxAnimated/BoxAnimated.gltf");
  ASSERT_FALSE(path.empty())
      << "../shared/scenes is absent: the tests need ../shared beside the project";
  r = test::runPathreuse("info --fps 0 '" + path + "'");
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_EQ(lineCount(r.err), 1u) << r.err;
}

}  // namespace
}  // namespace pr
