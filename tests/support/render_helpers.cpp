#include "support/render_helpers.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>

#include "support/gltf_builder.h"
#include "support/test_env.h"

namespace pr::test {

Moments regionMean(const Image& img, int x0, int y0, int x1, int y1, int c) {
  double s = 0, s2 = 0;
  int n = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      const double v = img.pixel(x, y)[c];
      s += v;
      s2 += v * v;
      ++n;
    }
  Moments m;
  m.mean = s / n;
  m.stderr_ = std::sqrt(std::fmax(0.0, s2 / n - m.mean * m.mean) / n);
  return m;
}

std::string renderFrames(const std::string& scene, const std::string& frames,
                         const std::string& args, const std::string& tag) {
  const std::string dir = tempDir(tag);
  const auto r =
      runPathreuse("render '" + scene + "' --quiet --exr-float --frames " + frames + " --out '" +
                   dir + "/f_%04d.exr' --stats '" + dir + "/stats.jsonl' " + args);
  EXPECT_EQ(r.exitCode, 0) << r.err;
  return dir;
}

Image frameImage(const std::string& dir, int64_t frame) {
  char name[32];
  std::snprintf(name, sizeof name, "/f_%04d.exr", frame);
  return readExr(dir + name);
}

std::vector<std::string> statsLines(const std::string& dir) {
  std::vector<std::string> lines;
  std::ifstream in(dir + "/stats.jsonl");
  std::string line;
  while (std::getline(in, line)) lines.push_back(line);
  return lines;
}

std::string glossyReflectionScene(const std::string& tag) {
  GltfBuilder b;
  const int white = b.addMaterial({glm::vec4(0.8f, 0.8f, 0.8f, 1.0f)});
  MaterialSpec chrome;
  chrome.metallic = 1.0f;
  chrome.roughness = 0.15f;
  const int metal = b.addMaterial(chrome);
  b.addNode(b.addQuad({-4, 0, 4}, {4, 0, 4}, {4, 0, -4}, {-4, 0, -4}, white));
  b.addNode(b.addQuad({-4, 0, -2}, {4, 0, -2}, {4, 4, -2}, {-4, 4, -2}, metal));
  b.addPointLight({0.0f, 1.5f, -1.0f}, {1, 1, 1}, 20.0f);
  b.addCamera({0, 5, 5}, {0, 0, 0}, 0.9f, 4.0f / 3.0f);
  return b.write(tempDir(tag), "mirror");
}

}  // namespace pr::test
