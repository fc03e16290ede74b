// Texture decoding refuses images whose headers promise more than the file holds, before any
// large allocation (regressions from fuzzing the loader); sRGB texels decode by the transfer
// function, rounded once.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "scene/image_decode.h"
#include "shared/srgb.h"

namespace pr {
namespace {

void put32(std::vector<uint8_t>& v, uint32_t x) {
  for (int s = 24; s >= 0; s -= 8) v.push_back(uint8_t(x >> s));
}

// A PNG signature and an IHDR for a w x h RGBA image, then one chunk of type `type` claiming
// `length` bytes but holding only a few.
std::vector<uint8_t> png(uint32_t w, uint32_t h, const char* type, uint32_t length) {
  std::vector<uint8_t> v = {0x89, 'P', 'N', 'G', 0x0d, 0x0a, 0x1a, 0x0a};
  put32(v, 13);
  for (char c : std::string("IHDR")) v.push_back(uint8_t(c));
  put32(v, w);
  put32(v, h);
  v.insert(v.end(), {8, 6, 0, 0, 0});
  put32(v, 0);  // CRC (stb does not check it)
  put32(v, length);
  for (int i = 0; i < 4; ++i) v.push_back(uint8_t(type[i]));
  v.insert(v.end(), {0x78, 0x9c, 0, 0, 0, 0});
  return v;
}

TEST(ImageDecode, ChunkLongerThanTheFileIsRefusedCheaply) {
  DecodedImage img;
  std::string why;
  EXPECT_FALSE(decodeImageRgba8(png(16, 16, "IDAT", 0x4b000000u), &img, &why));
  EXPECT_NE(why.find("claims"), std::string::npos) << why;
}

TEST(ImageDecode, HugeDeclaredSizeIsRefused) {
  DecodedImage img;
  std::string why;
  EXPECT_FALSE(decodeImageRgba8(png(10000, 10000, "IEND", 0), &img, &why));
  EXPECT_NE(why.find("10000 x 10000"), std::string::npos) << why;
}

TEST(ImageDecode, SmallValidImageStillDecodes) {
  // A 1x1 opaque red PNG.
  const std::vector<uint8_t> red = {
      0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x48,
      0x44, 0x52, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x01, 0x08, 0x02, 0x00, 0x00,
      0x00, 0x90, 0x77, 0x53, 0xde, 0x00, 0x00, 0x00, 0x0c, 0x49, 0x44, 0x41, 0x54, 0x08,
      0xd7, 0x63, 0xf8, 0xcf, 0xc0, 0x00, 0x00, 0x03, 0x01, 0x01, 0x00, 0x18, 0xdd, 0x8d,
      0xb0, 0x00, 0x00, 0x00, 0x00, 0x49, 0x45, 0x4e, 0x44, 0xae, 0x42, 0x60, 0x82};
  DecodedImage img;
  std::string why;
  ASSERT_TRUE(decodeImageRgba8(red, &img, &why)) << why;
  ASSERT_EQ(img.width, 1);
  ASSERT_EQ(img.height, 1);
  EXPECT_EQ(img.rgba8[0], 255);
  EXPECT_EQ(img.rgba8[1], 0);
  EXPECT_EQ(img.rgba8[3], 255);
}

// The kernels' table (tools/tables/srgb_table.py) against IEC 61966-2-1 in double precision:
// every entry the float nearest to the exact value, so every device decodes a texel alike.
TEST(Srgb, TableIsTheTransferFunction) {
  for (int b = 0; b < 256; ++b) {
    const double c = b / 255.0;
    const double exact = c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
    EXPECT_EQ(dev::pr_srgb_to_linear[b], static_cast<float>(exact)) << "byte " << b;
    if (b > 0) {
      EXPECT_GT(dev::pr_srgb_to_linear[b], dev::pr_srgb_to_linear[b - 1]) << "byte " << b;
    }
  }
  EXPECT_EQ(dev::pr_srgb_to_linear[0], 0.0f);
  EXPECT_EQ(dev::pr_srgb_to_linear[255], 1.0f);
}

}  // namespace
}  // namespace pr
