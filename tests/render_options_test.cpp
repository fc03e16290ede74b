// Parsing and validation of render options that need more than CLI11's checks.
#include <gtest/gtest.h>

#include "render/options.h"
#include "render/path_reuse.h"
#include "util/error.h"

namespace pr {
namespace {

TEST(RenderOptions, FrameRanges) {
  EXPECT_EQ(parseFrameRange("3").first, 3);
  EXPECT_EQ(parseFrameRange("3").last, 3);
  EXPECT_EQ(parseFrameRange("0-119").last, 119);
  EXPECT_EQ(parseFrameRange("99999999999").first, 99999999999);
  EXPECT_EQ(parseFrameRange("0-9223372036854775806").last, kMaxFrame);
  for (const char* bad : {"", "-", "a", "3-", "-3", "5-2", "1-2-3", "1.5", "9223372036854775807",
                          "18446744073709551616", "00000000000000000001"})
    EXPECT_THROW(parseFrameRange(bad), InputError) << bad;
}

// Path resampling is on by default in reuse and retrace (with eye paths, which it resamples),
// without neighbours there; off in pathtrace, where --resample takes one neighbour. What is given
// wins.
TEST(RenderOptions, ResamplingDefaultsByMode) {
  RenderOptions o;
  struct Case {
    RenderMode mode;
    bool eyePaths;
    std::optional<bool> asked;
    bool enabled;
    int neighbors;
  };
  const Case cases[] = {
      {RenderMode::Reuse, true, std::nullopt, true, 0},
      {RenderMode::Retrace, true, std::nullopt, true, 0},
      {RenderMode::Reuse, false, std::nullopt, false, 0},
      {RenderMode::PathTrace, true, std::nullopt, false, 1},
      {RenderMode::Reuse, true, false, false, 0},
      {RenderMode::PathTrace, true, true, true, 1},
  };
  for (const Case& c : cases) {
    o.mode = c.mode;
    o.connect.eyePaths = c.eyePaths;
    o.resample.asked = c.asked;
    const ResampleSettings r = resolveResample(o);
    EXPECT_EQ(r.enabled, c.enabled) << renderModeName(c.mode) << " " << c.eyePaths;
    EXPECT_EQ(r.neighbors, c.neighbors) << renderModeName(c.mode);
  }
  o.mode = RenderMode::Reuse;
  o.resample.neighbors = 3;
  EXPECT_EQ(resolveResample(o).neighbors, 3);
}

TEST(RenderOptions, OutPatterns) {
  EXPECT_EQ(formatOutPath("out/frame_%04d.exr", 7), "out/frame_0007.exr");
  EXPECT_EQ(formatOutPath("f%d.exr", 12), "f12.exr");
  EXPECT_EQ(formatOutPath("f%05d.exr", kMaxFrame), "f9223372036854775806.exr");
  EXPECT_EQ(formatOutPath("100%%_%03i.exr", 5), "100%_005.exr");
  EXPECT_NO_THROW(validateOutPattern("a/b_%05d.exr"));
  for (const char* bad :
       {"out.exr", "%s.exr", "%d_%d.exr", "%n.exr", "%0999d.exr", "%x.exr", "%.exr", "dir/%d/"})
    EXPECT_THROW(validateOutPattern(bad), InputError) << bad;
  EXPECT_EQ(withExtension("out/frame_0001.exr", ".png"), "out/frame_0001.png");
}

// The arena's default: one light path per pixel up to 1080p and a little beyond, then 2^21
// shared by all pixels (4K: one among four), so that the arena stays under 1.2 GiB.
TEST(RenderOptions, DefaultLightPathsAreOnePerPixelUpTo2To21) {
  EXPECT_EQ(defaultLightPaths(1), 1u);
  EXPECT_EQ(defaultLightPaths(1280 * 720), 1280u * 720u);
  EXPECT_EQ(defaultLightPaths(1920 * 1080), 1920u * 1080u);
  EXPECT_EQ(defaultLightPaths(3840 * 2160), 1u << 21);
  EXPECT_EQ(defaultLightPaths(uint64_t(1) << 40), 1u << 21);
}

}  // namespace
}  // namespace pr
