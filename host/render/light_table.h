// The light table's entries (kernels/shared/lights.h) made from the scene: emissive triangles,
// punctual lights, the environment; and the power sums lights are chosen by.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "scene/environment_map.h"
#include "scene/scene.h"
#include "shared/environment.h"
#include "shared/lights.h"

namespace pr {

// An emissive triangle (a, b, c) of radiance le: shading triangle prim, DSG instance inst
// (PR_INVALID_INDEX on the SSG), its material.
dev::Light triangleLight(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c,
                         const glm::vec3& le, uint32_t prim, uint32_t inst, uint32_t material);

// A KHR_lights_punctual light at its pose (directional lights' power through the disk of radius
// sceneRadius); a non-finite or negative power becomes 0.
dev::Light punctualLight(const PunctualLight& p, float sceneRadius);

// The environment (shared/environment.h's fields) whose map has the given mean luminance.
dev::Light environmentLight(const Environment& env, float meanLuminance, float sceneRadius);

// Running sums of the lights' powers; returns the total.
float runningSums(const std::vector<dev::Light>& lights, std::vector<float>* cdf);

// Everything but the bookkeeping fields (moved, leaf) is equal.
bool sameGeometry(const dev::Light& a, const dev::Light& b);

}  // namespace pr
