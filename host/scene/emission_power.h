// What an emission texture does to a triangle light's power: the lights' selection weights (the
// power table, the light BVH) follow the texels each triangle shows, and a triangle all of whose
// texels are black is no light at all (a BSDF ray that hits it counts its emission alone, as
// for any emitter outside the light table, so the estimate stays unbiased either way).
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace pr {

// The ratio of a triangle's mean emitted luminance to its material's untextured emission
// (emissiveFactor x strength): 1 without an emission texture; the mean over the texels whose
// centres the triangle covers in uv (the texels around it where it covers none); 0 exactly
// where every texel a bilinear lookup inside the triangle can reach is black. A triangle whose uv
// spans more than kMaxScannedTexels texels gets the texture's mean.
class EmissionShares {
 public:
  static constexpr size_t kMaxScannedTexels = size_t(1) << 16;

  explicit EmissionShares(const Scene& scene) : scene_(scene) {}

  // Triangle `tri` of mesh m.
  float share(const TriangleMesh& m, size_t tri) const;

  // The same for a triangle of material `material` with uv coordinates uv (the set the texture
  // reads, before its transform).
  float share(uint32_t material, const std::array<glm::vec2, 3>& uv) const;

 private:
  // The share over the whole of the material's emission texture.
  float textureMean(uint32_t material) const;

  const Scene& scene_;
  mutable std::vector<float> means_;  // per material; < 0 not yet computed
};

}  // namespace pr
