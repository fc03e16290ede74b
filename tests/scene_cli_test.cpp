// `pathreuse info` as a user meets it: the summary, the JSON keys, and broken files.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/render_helpers.h"
#include "support/test_env.h"

namespace pr {
namespace {

using test::lineCount;

TEST(SceneCli, InfoCornellJson) {
  PR_SHARED_SCENE(path, "cornell-nvpro/cornellBox.gltf");
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

// The Fox's three clips animate the same joints: info lists them, the first plays, and the
// others are named with the --animation that plays them.
TEST(SceneCli, InfoListsTheClipsAndWhichPlays) {
  PR_SHARED_SCENE(path, "Fox/Fox.gltf");
  auto r = test::runPathreuse("info --json '" + path + "'");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const auto clips = nlohmann::json::parse(r.out)["animation"]["clips"];
  ASSERT_EQ(clips.size(), 3u);
  EXPECT_EQ(clips[0]["name"], "Survey");
  EXPECT_EQ(clips[0]["plays"], true);
  EXPECT_EQ(clips[1]["name"], "Walk");
  EXPECT_EQ(clips[1]["plays"], false);
  EXPECT_NEAR(clips[1]["duration_s"].get<double>(), 0.7083, 1e-3);
  EXPECT_EQ(clips[2]["plays"], false);
  r = test::runPathreuse("info '" + path + "'");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.out.find("1 Walk 0.708333 s (not played: --animation 1)"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("animations 1 (Walk), 2 (Run) animate what an earlier animation does"),
            std::string::npos)
      << r.out;
}

TEST(SceneCli, InfoBoxAnimated) {
  PR_SHARED_SCENE(path, "BoxAnimated/BoxAnimated.gltf");
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

// The benchmark's lit wrappers of shared assets (tools/scenes/gen_real_scenes.py) load as the
// generator says: the city's dome walls emit (its roof cut away), a sun and a held camera added;
// BrainStem gains a stage and two cameras; `framed` adds a camera to any asset. They name the
// assets' files outside their own folder, which a render allows only when asked.
TEST(SceneCli, LitWrappersOfSharedAssetsLoadAsTheirGeneratorSays) {
  PR_SHARED_SCENE(vc, "VC/VC.gltf");
  PR_SHARED_SCENE(brainstem, "BrainStem/BrainStem.gltf");
  const std::string dir = test::tempDir("lit-wrappers");
  auto make = [&](const char* kind, const std::string& src) {
    const std::string out = dir + "/" + kind + "-lit.gltf";
    const std::string cmd = "cd '" + test::sourcePath("") +
                            "' && python3 -m tools.scenes.gen_real_scenes " + kind + " '" + src +
                            "' --out '" + out + "' >/dev/null";
    EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
    return out;
  };
  auto info = [&](const std::string& path) {
    const auto r = test::runPathreuse("info --json --allow-outside-uris '" + path + "'");
    EXPECT_EQ(r.exitCode, 0) << r.err;
    return nlohmann::json::parse(r.out);
  };
  const std::string city = make("vc", vc);
  const auto a = info(vc), c = info(city);
  EXPECT_EQ(c["triangles"]["static"].get<int>(), a["triangles"]["static"].get<int>() - 40);
  EXPECT_EQ(c["triangles"]["dynamic"], a["triangles"]["dynamic"]);
  EXPECT_EQ(a["lights"]["emissive_triangles"], 0);
  EXPECT_EQ(c["lights"]["emissive_triangles"], 16);  // 8 walls, 2 triangles each
  EXPECT_EQ(c["lights"]["punctual"], 1);
  EXPECT_EQ(c["cameras"].get<int>(), a["cameras"].get<int>() + 1);
  EXPECT_EQ(c["animation"]["frames"], a["animation"]["frames"]);
  const auto refused = test::runPathreuse("info '" + city + "'");
  EXPECT_EQ(refused.exitCode, 2) << refused.err;
  EXPECT_NE(refused.err.find("--allow-outside-uris"), std::string::npos) << refused.err;

  const auto b = info(brainstem), s = info(make("brainstem", brainstem));
  EXPECT_EQ(s["triangles"]["static"], 4);  // the floor and the wall
  EXPECT_EQ(s["triangles"]["dynamic"], b["triangles"]["dynamic"]);
  EXPECT_EQ(s["cameras"], 2);
  EXPECT_EQ(s["animation"]["frames"], b["animation"]["frames"]);

  // `framed`: the asset as it is, one camera more, no buffer of its own (glTF forbids an empty
  // one), and that camera sees the whole asset (under a white sky, the asset fills the middle
  // and none of it touches the border).
  const std::string framed = make("framed", brainstem);
  const auto f = info(framed);
  EXPECT_EQ(f["triangles"], b["triangles"]);
  EXPECT_EQ(f["cameras"].get<int>(), b["cameras"].get<int>() + 1);
  EXPECT_FALSE(std::filesystem::exists(dir + "/framed-lit.bin"));
  const std::string out = test::renderFrames(
      framed, "0",
      "--allow-outside-uris --camera " + std::to_string(f["cameras"].get<int>() - 1) +
          " --mode pathtrace --width 32 --height 32 --spp 1 --env-color 1,1,1",
      "framed");
  const Image img = test::frameImage(out, 0);
  int asset = 0, border = 0;
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) {
      const bool sky = std::fabs(img.pixel(x, y)[1] - 1.0f) < 1e-3f;
      asset += !sky;
      border += !sky && (x == 0 || y == 0 || x == 31 || y == 31);
    }
  EXPECT_GT(asset, 32 * 32 / 20) << "the asset is in view";
  EXPECT_EQ(border, 0) << "and all of it";

  // An asset whose buffers are base64 data URIs (BoxAnimated's) is framed as well: they stay in
  // the wrapper as they are.
  PR_SHARED_SCENE(box, "BoxAnimated/BoxAnimated.gltf");
  const auto x = info(box), y = info(make("framed", box));
  EXPECT_EQ(y["triangles"], x["triangles"]);
  EXPECT_EQ(y["cameras"].get<int>(), x["cameras"].get<int>() + 1);
  EXPECT_EQ(y["animation"]["frames"], x["animation"]["frames"]);
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

// The static/dynamic split of our own animated scenes against their files, read here
// independently: a mesh under an animated node is dynamic, the rest static; the frames span the
// samplers' last key. (The same as the third-party BoxAnimated test above, for a clone without
// ../shared.)
TEST(SceneCli, InfoSplitsTheDemosAsTheirFilesSay) {
  for (const char* name : {"scenes/cornell-dynamic.gltf", "scenes/cornell-orbit.gltf"}) {
    SCOPED_TRACE(name);
    const std::string path = test::sourcePath(name);
    std::ifstream in(path);
    ASSERT_TRUE(in) << path;
    const nlohmann::json g = nlohmann::json::parse(in);
    std::vector<bool> animated(g["nodes"].size(), false);
    double lastKey = 0.0;
    for (const auto& a : g["animations"]) {
      for (const auto& c : a["channels"]) animated[c["target"]["node"].get<size_t>()] = true;
      for (const auto& smp : a["samplers"])
        lastKey =
            std::max(lastKey, g["accessors"][smp["input"].get<size_t>()]["max"][0].get<double>());
    }
    size_t staticTris = 0, dynamicTris = 0, dynamicInstances = 0;
    for (size_t n = 0; n < g["nodes"].size(); ++n) {
      const auto& node = g["nodes"][n];
      ASSERT_FALSE(node.contains("children")) << "the count below assumes a flat scene";
      if (!node.contains("mesh")) continue;
      size_t tris = 0;
      for (const auto& prim : g["meshes"][node["mesh"].get<size_t>()]["primitives"])
        tris += g["accessors"][prim["indices"].get<size_t>()]["count"].get<size_t>() / 3;
      (animated[n] ? dynamicTris : staticTris) += tris;
      dynamicInstances += animated[n];
    }
    ASSERT_GT(staticTris, 0u);
    const auto r = test::runPathreuse(std::string("info --json --fps 10 '") + path + "'");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["triangles"]["static"].get<size_t>(), staticTris);
    EXPECT_EQ(j["triangles"]["dynamic"].get<size_t>(), dynamicTris);
    EXPECT_EQ(j["instances"]["dynamic"].get<size_t>(), dynamicInstances);
    EXPECT_EQ(j["animation"]["frames"].get<int>(), static_cast<int>(std::floor(lastKey * 10)) + 1);
  }
}

TEST(SceneCli, InfoUsageErrors) {
  auto r = test::runPathreuse("info");
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_EQ(lineCount(r.err), 1u) << r.err;
  const std::string path = test::sourcePath("scenes/cornell-dynamic.gltf");
  r = test::runPathreuse("info --fps 0 '" + path + "'");
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_EQ(lineCount(r.err), 1u) << r.err;
}

}  // namespace
}  // namespace pr
