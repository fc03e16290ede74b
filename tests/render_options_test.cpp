// Parsing and validation of render options that need more than CLI11's checks.
#include <gtest/gtest.h>

#include "render/options.h"
#include "util/error.h"

namespace pr {
namespace {

TEST(RenderOptions, FrameRanges) {
  EXPECT_EQ(parseFrameRange("3").first, 3);
  EXPECT_EQ(parseFrameRange("3").last, 3);
  EXPECT_EQ(parseFrameRange("0-119").last, 119);
  for (const char* bad : {"", "-", "a", "3-", "-3", "5-2", "1-2-3", "1.5", "99999999999"})
    EXPECT_THROW(parseFrameRange(bad), InputError) << bad;
}

TEST(RenderOptions, OutPatterns) {
  EXPECT_EQ(formatOutPath("out/frame_%04d.exr", 7), "out/frame_0007.exr");
  EXPECT_EQ(formatOutPath("f%d.exr", 12), "f12.exr");
  EXPECT_EQ(formatOutPath("100%%_%03i.exr", 5), "100%_005.exr");
  EXPECT_NO_THROW(validateOutPattern("a/b_%05d.exr"));
  for (const char* bad :
       {"out.exr", "%s.exr", "%d_%d.exr", "%n.exr", "%0999d.exr", "%x.exr", "%.exr", "dir/%d/"})
    EXPECT_THROW(validateOutPattern(bad), InputError) << bad;
  EXPECT_EQ(withExtension("out/frame_0001.exr", ".png"), "out/frame_0001.png");
}

}  // namespace
}  // namespace pr
