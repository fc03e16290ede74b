// exr_compare: the mean of one OpenEXR image, or how two differ (relMSE, mean absolute
// difference, mean of each). For scripts and notes: one JSON object on stdout.
//   exr_compare A.exr [B.exr]
#include <cmath>
#include <cstdio>
#include <iostream>

#include <nlohmann/json.hpp>

#include "io/image.h"
#include "util/error.h"

int main(int argc, char** argv) {
  if (argc < 2 || argc > 3) {
    std::cerr << "usage: exr_compare A.exr [B.exr]\n";
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
      double rel = 0, mad = 0;
      size_t n = 0;
      for (size_t i = 0; i < a.rgba.size(); i += 4)
        for (int c = 0; c < 3; ++c, ++n) {
          const double d = double(a.rgba[i + c]) - b.rgba[i + c];
          rel += d * d / (double(b.rgba[i + c]) * b.rgba[i + c] + 0.01);
          mad += std::fabs(d);
        }
      out["b"] = argv[2];
      out["mean_b"] = mean(b);
      out["relmse"] = rel / double(n);
      out["mad"] = mad / double(n);
    }
    std::cout << out.dump() << "\n";
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
