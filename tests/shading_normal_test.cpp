// Coarse facets with smooth vertex normals (the shadow terminator): a hexagonal prism whose
// vertex normals are a cylinder's, direct light only, against the smooth surface those normals
// describe. Without the terminator offset (shared/transport.h, surface_ray) the facets shadow
// each other where the smooth surface would be lit (5-15% darker bands beside the edges), and
// facets seen edge-on, whose shading normal turns away from the camera, went black.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/image.h"
#include "support/gltf_builder.h"
#include "support/render_helpers.h"
#include "support/test_env.h"

namespace pr {
namespace {

constexpr int kSides = 6;
constexpr float kRadius = 1.0f, kHalfHeight = 20.0f, kAlbedo = 0.5f;
constexpr int kWidth = 96, kHeight = 48;
constexpr float kYfov = 0.6f;
const glm::vec3 kEye(-4.0f, 0.0f, 0.0f);
// The area light: a quad in the plane z = -6 beside the prism, radiance 1 (both faces).
const glm::vec3 kQuad[4] = {{-8, -2, -6}, {2, -2, -6}, {2, 10, -6}, {-8, 10, -6}};

float cornerAngle(int i) {
  return glm::radians(30.0f + 360.0f * static_cast<float>(i) / kSides);
}

// The prism: corners at 30 + 60 k degrees around +Y (a face towards the camera at -X), each
// corner's normal the radial direction, as a lathe's.
std::string prismScene(const std::string& tag, bool areaLight) {
  test::GltfBuilder b;
  const int grey = b.addMaterial({glm::vec4(kAlbedo, kAlbedo, kAlbedo, 1), 0, 1});
  std::vector<glm::vec3> p, n;
  std::vector<uint32_t> idx;
  for (const float y : {-kHalfHeight, kHalfHeight})
    for (int i = 0; i <= kSides; ++i) {
      const float a = cornerAngle(i);
      p.emplace_back(kRadius * std::cos(a), y, kRadius * std::sin(a));
      n.emplace_back(std::cos(a), 0.0f, std::sin(a));
    }
  const uint32_t row = kSides + 1;
  for (uint32_t i = 0; i < kSides; ++i) {
    const uint32_t a = i, c = i + 1 + row, d = i + row, e = i + 1;
    idx.insert(idx.end(), {a, c, e, a, d, c});
  }
  b.addNode(b.addMesh(p, idx, grey, n));
  if (areaLight) {
    const int sky = b.addMaterial({glm::vec4(0, 0, 0, 1), 0, 1, glm::vec3(1.0f), 1.0f});
    b.addNode(b.addQuad(kQuad[0], kQuad[1], kQuad[2], kQuad[3], sky));
  }
  b.addCamera(kEye, glm::vec3(0.0f), kYfov, static_cast<float>(kWidth) / kHeight);
  return b.write(test::tempDir(tag), "prism");
}

// Where the camera ray through film point (sx, sy) meets the prism: the point and the shading
// normal interpolated across the facet (the corners' normals, normalised). False where it misses.
bool prismHit(float sx, float sy, glm::vec3* point, glm::vec3* normal) {
  const glm::vec3 fwd = glm::normalize(-kEye);
  const glm::vec3 right = glm::normalize(glm::cross(fwd, glm::vec3(0, 1, 0)));
  const glm::vec3 up = glm::cross(right, fwd);
  const float t = std::tan(kYfov / 2);
  const glm::vec3 d = glm::normalize(fwd + right * ((2 * sx / kWidth - 1) * t * kWidth / kHeight) +
                                     up * ((1 - 2 * sy / kHeight) * t));
  // The prism's cross-section in (x, z): the nearest edge the ray's horizontal part crosses.
  const glm::vec2 o(kEye.x, kEye.z), dh(d.x, d.z);
  float best = INFINITY;
  for (int i = 0; i < kSides; ++i) {
    const glm::vec2 a(kRadius * std::cos(cornerAngle(i)), kRadius * std::sin(cornerAngle(i)));
    const glm::vec2 b(kRadius * std::cos(cornerAngle(i + 1)),
                      kRadius * std::sin(cornerAngle(i + 1)));
    const glm::vec2 e = b - a, w = a - o;
    const float det = dh.x * -e.y + dh.y * e.x;
    if (std::fabs(det) < 1e-9f) continue;
    const float th = (w.x * -e.y + w.y * e.x) / det, s = (dh.x * w.y - dh.y * w.x) / det;
    if (th <= 0 || s < 0 || s > 1 || th >= best) continue;
    best = th;
    const glm::vec2 n2 = glm::normalize(glm::mix(glm::normalize(a), glm::normalize(b), s));
    *normal = glm::vec3(n2.x, 0.0f, n2.y);
    *point = kEye + d * (th / glm::length(dh));
  }
  return best < INFINITY;
}

// Radiance of the smooth Lambertian surface at p with normal n: under a uniform environment of
// radiance 1 the albedo; under the area light albedo / pi times the integral over the quad of
// max(0, n.w) |cos at the quad| / r^2 (nothing of a convex smooth surface hides a direction
// above its tangent plane).
double smoothRadiance(glm::vec3 p, glm::vec3 n, bool areaLight) {
  if (!areaLight) return kAlbedo;
  const int k = 48;
  const glm::vec3 eu = kQuad[1] - kQuad[0], ev = kQuad[3] - kQuad[0];
  const glm::vec3 nq = glm::normalize(glm::cross(eu, ev));
  const double dA = glm::length(eu) * glm::length(ev) / (k * k);
  double sum = 0;
  for (int i = 0; i < k; ++i)
    for (int j = 0; j < k; ++j) {
      const glm::vec3 q = kQuad[0] + eu * ((i + 0.5f) / k) + ev * ((j + 0.5f) / k);
      const glm::vec3 w = q - p;
      const double r2 = glm::dot(w, w);
      const glm::vec3 u = w / static_cast<float>(std::sqrt(r2));
      sum += std::fmax(0.0, glm::dot(n, u)) * std::fabs(glm::dot(nq, u)) / r2;
    }
  return kAlbedo / M_PI * sum * dA;
}

struct Column {
  int x;
  double expected, got, stderr_;
};

// Per image column over the pixels wholly on the prism: the smooth surface's radiance (averaged
// over each pixel's footprint) and the render's, summed over the rows, and the standard error
// of the render's sum (from the spread of its pixels about their expectations).
std::vector<Column> columns(const Image& img, bool areaLight) {
  std::vector<Column> out;
  const int sub = 4;
  for (int x = 0; x < kWidth; ++x) {
    std::vector<double> residual;
    Column c{x, 0, 0, 0};
    for (int y = 0; y < kHeight; ++y) {
      double e = 0;
      bool inside = true;
      for (int j = 0; j < sub && inside; ++j)
        for (int i = 0; i < sub && inside; ++i) {
          glm::vec3 p(0.0f), n(0.0f);
          // The footprint's edges included: a pixel partly off the prism is left out.
          inside = prismHit(x + i / (sub - 1.0f), y + j / (sub - 1.0f), &p, &n);
          if (inside) e += smoothRadiance(p, n, areaLight) / (sub * sub);
        }
      if (!inside) break;
      const double v = img.pixel(x, y)[1];
      c.expected += e;
      c.got += v;
      residual.push_back(v - e);
    }
    if (static_cast<int>(residual.size()) < kHeight) continue;
    double mean = 0, var = 0;
    for (const double r : residual) mean += r / kHeight;
    for (const double r : residual) var += (r - mean) * (r - mean);
    c.stderr_ = std::sqrt(var * kHeight / (kHeight - 1.0));
    out.push_back(c);
  }
  return out;
}

Image renderPrism(const std::string& scene, const std::string& args, const std::string& tag,
                  uint64_t* badSamples) {
  const std::string dir =
      test::renderFrames(scene, "0",
                         "--width " + std::to_string(kWidth) + " --height " +
                             std::to_string(kHeight) + " --max-depth 2 --force-diffuse " + args,
                         tag);
  for (const auto& line : test::statsLines(dir))
    *badSamples += nlohmann::json::parse(line).at("bad_samples").get<uint64_t>();
  return test::frameImage(dir, 0);
}

// Every integrator, under a uniform environment: the smooth surface's radiance is the albedo at
// every point, so every column of the prism, the bands beside its edges and the facets seen
// edge-on included, must give it. Before the terminator offset the bands beside the edges were
// up to 6% dark and the edge-on facets' outer columns 85%.
TEST(SmoothShadedPrism, UniformEnvironmentGivesTheAlbedoInEveryIntegrator) {
  const std::string scene = prismScene("prism-env", false);
  for (const std::string mode :
       {"--mode pathtrace", "--mode reuse", "--mode reuse --no-eye-paths"}) {
    uint64_t bad = 0;
    const Image img =
        renderPrism(scene, mode + " --spp 64 --env-color 1,1,1", "prism-env-out", &bad);
    EXPECT_EQ(bad, 0u) << mode;
    const std::vector<Column> cols = columns(img, false);
    ASSERT_GE(cols.size(), 20u) << mode;
    for (const Column& c : cols)
      EXPECT_NEAR(c.got / c.expected, 1.0, 0.01 + 4 * c.stderr_ / c.expected)
          << mode << ", column " << c.x << ": " << c.got / kHeight << " against "
          << c.expected / kHeight;
  }
}

// A large area light beside the prism, grazing the lit facets: each column as bright as the
// smooth surface's to 2% of the brightest column (the terminator offset approximates that
// surface: at the terminator itself, where the light is nearly tangent, a column can be a fifth
// darker than the smooth surface, at 0.5% of the brightest). Before it, the band beside the
// edge facing the light was 15% darker than the smooth surface.
TEST(SmoothShadedPrism, AreaLightAtGrazingAnglesMatchesTheSmoothSurface) {
  const std::string scene = prismScene("prism-quad", true);
  for (const std::string mode : {"--mode pathtrace", "--mode reuse"}) {
    uint64_t bad = 0;
    const Image img = renderPrism(scene, mode + " --spp 512 --env none", "prism-quad-out", &bad);
    EXPECT_EQ(bad, 0u) << mode;
    const std::vector<Column> cols = columns(img, true);
    ASSERT_GE(cols.size(), 20u) << mode;
    double brightest = 0;
    for (const Column& c : cols) brightest = std::fmax(brightest, c.expected);
    for (const Column& c : cols)
      EXPECT_NEAR(c.got, c.expected, 0.02 * brightest + 4 * c.stderr_)
          << mode << ", column " << c.x << ": " << c.got / kHeight << " against "
          << c.expected / kHeight << " (brightest " << brightest / kHeight << ")";
  }
}

}  // namespace
}  // namespace pr
