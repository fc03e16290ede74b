// exr_compare: the mean of one OpenEXR image, or how A differs from the reference B (relMSE,
// relMSE without the worst 1% of pixels, mean absolute difference, mean of each). For scripts
// and notes: one JSON object on stdout.
//   exr_compare A.exr [B.exr]
//   exr_compare --raw A.exr A.raw [B.exr B.raw ...]
//   exr_compare --raw-channel NAME A.exr A.raw   (one channel, e.g. material.ID of --aov)
// The differences are pr::compareImages's (host/portability/compare.cpp), the one relMSE of the
// project: `pathreuse portability`, the tests and, through this program, the Python tools
// (tools/bench/) all measure with it. relmse = mean over pixels and RGB of (A - B)^2 / (B^2 +
// 0.01); relmse_trimmed = the same sum without the 1% of pixels with the largest terms, still
// over all pixels; both over the pixels whose values are finite in both images, the others
// counted in non_finite.
// --raw writes width and height (uint32, little-endian) then float32 RGB, row by row from the
// top, so that scripts without an EXR reader (tools/bench/evaluate.py, numpy) can load the pixels;
// --raw-channel the same with one float32 per pixel.
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/image.h"
#include "portability/compare.h"
#include "util/error.h"

namespace {

void writeRaw(const pr::Image& img, const std::string& path) {
  std::vector<float> rgb;
  rgb.reserve(img.rgba.size() / 4 * 3);
  for (size_t i = 0; i < img.rgba.size(); i += 4)
    for (int c = 0; c < 3; ++c) rgb.push_back(img.rgba[i + c]);
  const uint32_t size[2] = {uint32_t(img.width), uint32_t(img.height)};
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(size), sizeof size);
  out.write(reinterpret_cast<const char*>(rgb.data()), std::streamsize(rgb.size() * sizeof(float)));
  if (!out) throw std::runtime_error(path + ": cannot write");
}

}  // namespace

void writeRawChannel(const std::string& exr, const std::string& name, const std::string& path) {
  const pr::Image img = pr::readExr(exr);
  const std::vector<float> values = pr::readExrChannel(exr, name);
  const uint32_t size[2] = {uint32_t(img.width), uint32_t(img.height)};
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(size), sizeof size);
  out.write(reinterpret_cast<const char*>(values.data()),
            std::streamsize(values.size() * sizeof(float)));
  if (!out) throw std::runtime_error(path + ": cannot write");
}

int main(int argc, char** argv) {
  if (argc >= 2 && std::string(argv[1]) == "--raw-channel") {
    if (argc != 5) {
      std::cerr << "usage: exr_compare --raw-channel NAME A.exr A.raw\n";
      return 2;
    }
    try {
      writeRawChannel(argv[3], argv[2], argv[4]);
    } catch (const std::exception& e) {
      std::cerr << "error: " << e.what() << "\n";
      return 2;
    }
    return 0;
  }
  if (argc >= 2 && std::string(argv[1]) == "--raw") {
    if (argc < 4 || argc % 2 != 0) {
      std::cerr << "usage: exr_compare --raw A.exr A.raw [B.exr B.raw ...]\n";
      return 2;
    }
    try {
      for (int i = 2; i + 1 < argc; i += 2) writeRaw(pr::readExr(argv[i]), argv[i + 1]);
    } catch (const std::exception& e) {
      std::cerr << "error: " << e.what() << "\n";
      return 2;
    }
    return 0;
  }
  if (argc < 2 || argc > 3) {
    std::cerr << "usage: exr_compare A.exr [B.exr] | exr_compare --raw A.exr A.raw [...]\n";
    return 2;
  }
  try {
    const pr::Image a = pr::readExr(argv[1]);
    auto mean = [](const pr::Image& img) {
      double s[3] = {0, 0, 0};
      for (size_t i = 0; i < img.rgba.size(); i += 4)
        for (int c = 0; c < 3; ++c) s[c] += img.rgba[i + c];
      const double n = double(img.rgba.size() / 4);
      return nlohmann::json::array({s[0] / n, s[1] / n, s[2] / n});
    };
    nlohmann::ordered_json out;
    out["a"] = argv[1];
    out["mean_a"] = mean(a);
    if (argc == 3) {
      const pr::Image b = pr::readExr(argv[2]);
      if (a.width != b.width || a.height != b.height) {
        std::cerr << "error: " << argv[2] << ": size differs from " << argv[1] << "\n";
        return 2;
      }
      const pr::ImageDiff d = pr::compareImages(a, b);
      out["b"] = argv[2];
      out["mean_b"] = mean(b);
      out["relmse"] = d.relMse;
      out["relmse_trimmed"] = d.relMseTrimmed;
      out["mad"] = d.mad;
      out["non_finite"] = d.nonFinite;
      out["identical"] = d.identical;
    }
    std::cout << out.dump() << "\n";
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
