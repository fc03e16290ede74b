// --time-limit: a frame renders no sample pass after the one during which its seconds ran out
// (render/integrator.h), and a frame so cut stays an unbiased estimate: the film's mean divides
// by the passes rendered, and strategy T's splats, added for --spp samples, are scaled to them.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <string>

#include <nlohmann/json.hpp>

#include "support/render_helpers.h"
#include "support/test_env.h"

namespace pr::test {
namespace {

const char* const kSize = " --width 96 --height 72 ";

std::string bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

TEST(TimeLimit, EachFrameStopsAfterThePassDuringWhichItRanOut) {
  const std::string scene = sourcePath("scenes/cornell-dynamic.gltf");
  const std::string base = std::string(kSize) + "--spp 4";
  const std::string cut = renderFrames(scene, "0-2", base + " --time-limit 0.000001", "tl_cut");
  const std::string none = renderFrames(scene, "0-2", base, "tl_none");
  const std::string ample = renderFrames(scene, "0-2", base + " --time-limit 1000", "tl_ample");
  for (const std::string& line : statsLines(cut))
    EXPECT_EQ(nlohmann::json::parse(line)["spp"]["max"].get<int>(), 1) << line;
  for (const std::string& line : statsLines(none))
    EXPECT_EQ(nlohmann::json::parse(line)["spp"]["mean"].get<int>(), 4) << line;
  // A limit no frame reaches changes nothing, bit for bit.
  for (const char* f : {"/f_0000.exr", "/f_0002.exr"})
    EXPECT_EQ(bytes(none + f), bytes(ample + f)) << f;
}

// A floor lit by a point light and by its glossy reflection in a metal wall: strategy T (light
// tracing) takes most of that reflected light (an eye path's next-event estimation seldom finds
// the narrow lobe), so its splats carry a large part of the floor's light. One pass of eight:
// region by region, the mean of an uncut render. (Mutation checked: the splats left at --spp
// samples' scale puts regions 2-3x too bright.)
TEST(TimeLimit, ACutFrameConvergesToTheUncutOne) {
  const std::string scene = glossyReflectionScene("tl_mirror");
  const std::string size = " --width 96 --height 72 ";
  const std::string cut =
      renderFrames(scene, "0", size + "--spp 8 --time-limit 0.000001 --seed 3", "tl_conv");
  const std::string ref = renderFrames(scene, "0", size + "--spp 64 --seed 4", "tl_ref");
  ASSERT_EQ(nlohmann::json::parse(statsLines(cut)[0])["spp"]["max"].get<int>(), 1);
  const Image a = frameImage(cut, 0), r = frameImage(ref, 0);
  for (int ry = 0; ry < 4; ++ry)
    for (int rx = 0; rx < 4; ++rx) {
      const int x0 = rx * 24, y0 = ry * 18;
      const Moments ma = regionMean(a, x0, y0, x0 + 24, y0 + 18, 1),
                    mr = regionMean(r, x0, y0, x0 + 24, y0 + 18, 1);
      const double se = std::sqrt(ma.stderr_ * ma.stderr_ + mr.stderr_ * mr.stderr_);
      EXPECT_LT(std::fabs(ma.mean - mr.mean), 4.5 * se + 1e-6)
          << "region " << rx << "," << ry << ": " << ma.mean << " against " << mr.mean;
    }
}

TEST(TimeLimit, IsAnInputErrorWithAConnectionHistoryOrANegativeTime) {
  const std::string scene = sourcePath("scenes/cornell-dynamic.gltf");
  const std::string out = tempDir("tl_bad");
  for (const std::string& bad :
       {std::string("--time-limit 1 --connection-history 4"), std::string("--time-limit -1")}) {
    const auto r = runPathreuse("render '" + scene + "' --quiet --frames 0 --width 16 --out '" +
                                out + "/f_%04d.exr' " + bad);
    EXPECT_EQ(r.exitCode, 2) << bad;
    EXPECT_NE(r.err.find("--time-limit"), std::string::npos) << r.err;
    EXPECT_EQ(lineCount(r.err), 1u) << r.err;
  }
}

}  // namespace
}  // namespace pr::test
