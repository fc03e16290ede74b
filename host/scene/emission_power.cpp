#include "scene/emission_power.h"

#include <algorithm>
#include <cmath>

#include "shared/srgb.h"

namespace pr {

namespace {

float srgbToLinear(uint8_t v) {
  return dev::pr_srgb_to_linear[v];
}

float luminance(const glm::vec3& c) {
  return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z;
}

int wrap(int i, int n, TextureWrap mode) {
  switch (mode) {
    case TextureWrap::ClampToEdge:
      return std::clamp(i, 0, n - 1);
    case TextureWrap::MirroredRepeat: {
      const int period = 2 * n;
      int j = i % period;
      if (j < 0) j += period;
      return j < n ? j : period - 1 - j;
    }
    case TextureWrap::Repeat:
    default: {
      const int j = i % n;
      return j < 0 ? j + n : j;
    }
  }
}

// The luminance of texel (x, y) times the factor, over the factor's luminance.
float texelShare(const Texture& t, int x, int y, const glm::vec3& factor, float factorLum) {
  const size_t at =
      (size_t(wrap(y, t.height, t.wrapT)) * size_t(t.width) + size_t(wrap(x, t.width, t.wrapS))) *
      4;
  glm::vec3 c(t.rgba8[at], t.rgba8[at + 1], t.rgba8[at + 2]);
  if (t.srgb)
    c = glm::vec3(srgbToLinear(t.rgba8[at]), srgbToLinear(t.rgba8[at + 1]),
                  srgbToLinear(t.rgba8[at + 2]));
  else
    c /= 255.0f;
  return luminance(c * factor) / factorLum;
}

// Whether point p lies in the triangle a, b, c (either winding, edges included).
bool inside(const glm::vec2& p, const glm::vec2& a, const glm::vec2& b, const glm::vec2& c) {
  auto side = [](const glm::vec2& o, const glm::vec2& u, const glm::vec2& v) {
    return (u.x - o.x) * (v.y - o.y) - (u.y - o.y) * (v.x - o.x);
  };
  const float d1 = side(a, b, p), d2 = side(b, c, p), d3 = side(c, a, p);
  const bool neg = d1 < 0.0f || d2 < 0.0f || d3<0.0f, pos = d1> 0.0f || d2 > 0.0f || d3 > 0.0f;
  return !(neg && pos);
}

}  // namespace

float EmissionShares::share(const TriangleMesh& m, size_t tri) const {
  const uint32_t material = m.materials[tri];
  const TextureRef& ref = scene_.materials[material].emissiveTexture;
  if (!ref.valid()) return 1.0f;
  const std::vector<glm::vec2>& uvs = ref.texCoord == 1 && !m.uvs1.empty() ? m.uvs1 : m.uvs;
  std::array<glm::vec2, 3> uv{};
  for (int k = 0; k < 3; ++k) {
    const uint32_t v = m.indices[3 * tri + k];
    uv[k] = v < uvs.size() ? uvs[v] : glm::vec2(0.0f);
  }
  return share(material, uv);
}

float EmissionShares::share(uint32_t material, const std::array<glm::vec2, 3>& uvIn) const {
  const Material& mat = scene_.materials[material];
  const TextureRef& ref = mat.emissiveTexture;
  if (!ref.valid() || ref.texture >= int(scene_.textures.size())) return 1.0f;
  const Texture& t = scene_.textures[size_t(ref.texture)];
  const glm::vec3 factor = mat.emission();
  const float factorLum = luminance(factor);
  if (t.width <= 0 || t.height <= 0 || !(factorLum > 0.0f)) return 1.0f;
  // Texel space: texel (i, j) has its centre at (i, j).
  std::array<glm::vec2, 3> p;
  for (int k = 0; k < 3; ++k) {
    const glm::vec2 uv = ref.apply(uvIn[k]);
    p[k] = glm::vec2(uv.x * float(t.width) - 0.5f, uv.y * float(t.height) - 0.5f);
    if (!std::isfinite(p[k].x) || !std::isfinite(p[k].y)) return textureMean(material);
  }
  // Every texel a bilinear (or nearest) lookup inside the triangle can read.
  const glm::vec2 lo = glm::min(glm::min(p[0], p[1]), p[2]),
                  hi = glm::max(glm::max(p[0], p[1]), p[2]);
  const double x0 = std::floor(lo.x) - 1.0, y0 = std::floor(lo.y) - 1.0;
  const double x1 = std::ceil(hi.x) + 1.0, y1 = std::ceil(hi.y) + 1.0;
  if ((x1 - x0 + 1.0) * (y1 - y0 + 1.0) > double(kMaxScannedTexels)) return textureMean(material);
  double inSum = 0.0, allSum = 0.0;
  size_t inCount = 0, allCount = 0;
  float maxShare = 0.0f;
  for (int y = int(y0); y <= int(y1); ++y)
    for (int x = int(x0); x <= int(x1); ++x) {
      const float s = texelShare(t, x, y, factor, factorLum);
      maxShare = std::max(maxShare, s);
      allSum += s, ++allCount;
      if (inside(glm::vec2(float(x), float(y)), p[0], p[1], p[2])) inSum += s, ++inCount;
    }
  if (!(maxShare > 0.0f)) return 0.0f;
  const double mean =
      inCount > 0 && inSum > 0.0 ? inSum / double(inCount) : allSum / double(allCount);
  return float(mean);
}

float EmissionShares::textureMean(uint32_t material) const {
  if (means_.empty()) means_.assign(scene_.materials.size(), -1.0f);
  float& mean = means_[material];
  if (mean < 0.0f) {
    const Material& mat = scene_.materials[material];
    const Texture& t = scene_.textures[size_t(mat.emissiveTexture.texture)];
    const glm::vec3 factor = mat.emission();
    const float factorLum = luminance(factor);
    double sum = 0.0;
    for (int y = 0; y < t.height; ++y)
      for (int x = 0; x < t.width; ++x) sum += texelShare(t, x, y, factor, factorLum);
    mean = float(sum / (double(t.width) * double(t.height)));
  }
  return mean;
}

}  // namespace pr
