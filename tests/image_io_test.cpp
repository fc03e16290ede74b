// OpenEXR and PNG output: round trips, atomic writes, clear errors on bad files.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "io/image.h"
#include "support/test_env.h"
#include "util/error.h"
#include "util/files.h"

namespace pr {
namespace {

namespace fs = std::filesystem;

Image gradient(int w, int h) {
  Image img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float* p = img.pixel(x, y);
      p[0] = x / float(w);
      p[1] = y / float(h) * 4.0f;
      p[2] = 0.25f;
      p[3] = 1.0f;
    }
  return img;
}

TEST(ImageIo, ExrFloatRoundTripIsExact) {
  const std::string dir = test::tempDir("exr");
  const Image img = gradient(37, 21);
  writeExr(dir + "/sub/f.exr", img, ExrPixels::Float);  // parent folder created
  const Image back = readExr(dir + "/sub/f.exr");
  ASSERT_EQ(back.width, 37);
  ASSERT_EQ(back.height, 21);
  EXPECT_EQ(back.rgba, img.rgba);
}

TEST(ImageIo, ExrHalfRoundTripWithinHalfPrecision) {
  const std::string dir = test::tempDir("exr");
  const Image img = gradient(16, 8);
  writeExr(dir + "/h.exr", img);
  const Image back = readExr(dir + "/h.exr");
  for (size_t i = 0; i < img.rgba.size(); ++i)
    EXPECT_NEAR(back.rgba[i], img.rgba[i], 1e-3f * std::max(1.0f, img.rgba[i]));
  // No temporary file is left beside it.
  for (const auto& e : fs::directory_iterator(dir))
    EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
}

TEST(ImageIo, TruncatedOrForeignExrIsRefused) {
  const std::string dir = test::tempDir("exr");
  writeExr(dir + "/a.exr", gradient(64, 64), ExrPixels::Float);
  EXPECT_TRUE(isCompleteExr(dir + "/a.exr"));
  std::string data;
  ASSERT_TRUE(readFile(dir + "/a.exr", &data));
  std::ofstream(dir + "/cut.exr", std::ios::binary).write(data.data(), data.size() / 2);
  EXPECT_FALSE(isCompleteExr(dir + "/cut.exr"));
  std::ofstream(dir + "/text.exr") << "not an image";
  EXPECT_FALSE(isCompleteExr(dir + "/text.exr"));
  EXPECT_FALSE(isCompleteExr(dir + "/missing.exr"));
  try {
    readExr(dir + "/text.exr");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("text.exr"), std::string::npos);
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
  }
}

TEST(ImageIo, PngIsWrittenAndUnwritableFolderIsAClearError) {
  const std::string dir = test::tempDir("png");
  writePng(dir + "/a.png", gradient(8, 8));
  std::string data;
  ASSERT_TRUE(readFile(dir + "/a.png", &data));
  ASSERT_GT(data.size(), 8u);
  EXPECT_EQ(data.substr(1, 3), "PNG");
  // A path under a regular file cannot be created.
  std::ofstream(dir + "/file") << "x";
  EXPECT_THROW(writePng(dir + "/file/b.png", gradient(4, 4)), RuntimeError);
  EXPECT_THROW(writeExr(dir + "/file/b.exr", gradient(4, 4)), RuntimeError);
}

}  // namespace
}  // namespace pr
