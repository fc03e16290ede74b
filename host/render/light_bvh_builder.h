// The light BVH on the host (docs/design.md section 6): built once over the lights that a
// receiving point chooses from the tree (every light but directional ones), refitted when they
// move, so that a light keeps its leaf for the whole animation.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "shared/lights.h"

namespace pr {

// What a node knows of the lights below it.
struct LightBounds {
  glm::vec3 lo{0.0f}, hi{0.0f};
  float power = 0.0f;
  glm::vec3 axis{0.0f, 0.0f, 1.0f};  // cone of normals (or emission directions)
  float thetaO = 0.0f;               // its half angle
  float thetaE = 0.0f;               // emission beyond a normal, up to this angle
  bool twoSided = false;
};

// The bounds of one light (not a directional one).
LightBounds lightBounds(const dev::Light& l);
// The smallest bounds holding both (cones merged as Estevez and Kulla do).
LightBounds unionOf(const LightBounds& a, const LightBounds& b);

class LightBvh {
 public:
  // Builds the tree over lights[0, count) and sets their `leaf`; the others' leaf becomes
  // PR_INVALID_INDEX. With no light, the tree is one empty leaf that no receiver chooses.
  void build(std::vector<dev::Light>* lights, uint32_t count);
  // The same tree with its bounds recomputed from the lights' current geometry and power.
  // `lights` must hold the lights of build() in the same order.
  void refit(std::vector<dev::Light>* lights);

  const std::vector<dev::LightNode>& nodes() const { return nodes_; }
  // The box and cone of node i, as built or refitted.
  const LightBounds& bounds(size_t i) const { return nodeBounds_[i]; }
  uint32_t lightCount() const { return count_; }

 private:
  uint32_t buildRange(std::vector<uint32_t>& order, const std::vector<LightBounds>& bounds,
                      uint32_t begin, uint32_t end, uint32_t parent);
  void store(uint32_t node, const LightBounds& b);

  std::vector<dev::LightNode> nodes_;
  std::vector<LightBounds> nodeBounds_;
  uint32_t count_ = 0;
};

}  // namespace pr
