// The environment light of a render (`render --env ...`): an equirectangular radiance map
// (OpenEXR or Radiance .hdr) or a constant colour, scaled and turned about +Y. glTF has no
// standard one, so it comes from the command line, as in other renderers.
#pragma once

#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace pr {

struct Environment {
  int width = 0;  // 0: no environment
  int height = 0;
  std::vector<float> rgb;  // width * height * 3, top row (+Y) first
  glm::vec3 scale{1.0f};   // strength times colour
  float rotation = 0.0f;   // radians about +Y

  bool present() const { return width > 0; }
};

// A uniform environment of radiance `color`.
Environment constantEnvironment(const glm::vec3& color);

// Reads an equirectangular map: .exr (OpenEXR) or .hdr / .pic (Radiance RGBE). Throws
// InputError naming the file when it cannot be read, is empty, or holds a negative or
// non-finite value.
Environment loadEnvironment(const std::string& path);

// The device's data buffer and the numbers its light keeps (kernels/shared/environment.h):
// texels, then per row the conditional cumulative sums, then the marginal ones; the mean
// luminance of the map over the sphere.
std::vector<float> environmentTables(const Environment& env, float* meanLuminance);

// The share of the map's mean luminance over the sphere (environmentTables') that is its floor,
// the darkest texel's: 1 for a uniform environment, near 0 for a map with dark texels. Light
// sampling's choice leaves that part to BSDF sampling (GpuScene::envChoiceShare_).
float environmentUniformShare(const Environment& env, float meanLuminance);

}  // namespace pr
