#include "render/light_table.h"

#include <cmath>
#include <cstddef>
#include <cstring>

namespace pr {

dev::Light triangleLight(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c,
                         const glm::vec3& le, uint32_t prim, uint32_t inst, uint32_t material) {
  dev::Light l{};
  l.type = PR_LIGHT_TRIANGLE;
  l.p0x = a.x, l.p0y = a.y, l.p0z = a.z;
  const glm::vec3 e1 = b - a, e2 = c - a;
  l.e1x = e1.x, l.e1y = e1.y, l.e1z = e1.z;
  l.e2x = e2.x, l.e2y = e2.y, l.e2z = e2.z;
  l.inst = inst;
  l.prim = prim;
  l.le_r = le.x, l.le_g = le.y, l.le_b = le.z;
  l.area = 0.5f * glm::length(glm::cross(e1, e2));
  l.power = dev::light_power(&l, 0.0f);
  l.material = material;
  return l;
}

float runningSums(const std::vector<dev::Light>& lights, std::vector<float>* cdf) {
  cdf->resize(lights.size());
  double sum = 0.0;
  for (size_t i = 0; i < lights.size(); ++i) {
    sum += lights[i].power;
    (*cdf)[i] = static_cast<float>(sum);
  }
  return static_cast<float>(sum);
}

bool sameGeometry(const dev::Light& a, const dev::Light& b) {
  return std::memcmp(&a, &b, offsetof(dev::Light, moved)) == 0;
}

namespace {

// The disk a light at infinity's paths start on, across their direction over the scene's sphere
// (light_trace): their density per unit area there is its inverse.
float diskArea(float sceneRadius) {
  return float(M_PI) * sceneRadius * sceneRadius;
}

}  // namespace

dev::Light punctualLight(const PunctualLight& p, float sceneRadius) {
  dev::Light l{};
  const glm::vec3 c = p.color * p.intensity;
  l.le_r = c.r, l.le_g = c.g, l.le_b = c.b;
  l.p0x = p.position.x, l.p0y = p.position.y, l.p0z = p.position.z;
  const glm::vec3 d = glm::normalize(p.direction);
  l.e1x = d.x, l.e1y = d.y, l.e1z = d.z;
  l.inst = PR_INVALID_INDEX;
  l.prim = PR_INVALID_INDEX;
  switch (p.type) {
    case LightType::Point:
      l.type = PR_LIGHT_POINT;
      break;
    case LightType::Spot:
      l.type = PR_LIGHT_SPOT;
      l.cos_inner = std::cos(p.innerConeAngle);
      l.cos_outer = std::cos(p.outerConeAngle);
      break;
    case LightType::Directional:
      l.type = PR_LIGHT_DIRECTIONAL;
      l.disk_area = diskArea(sceneRadius);
      break;
  }
  l.power = dev::light_power(&l, sceneRadius);
  if (!std::isfinite(l.power) || !(l.power > 0.0f)) l.power = 0.0f;
  return l;
}

dev::Light environmentLight(const Environment& env, float meanLuminance, float sceneRadius) {
  dev::Light l{};
  l.type = PR_LIGHT_ENV;
  l.inst = static_cast<uint32_t>(env.width);
  l.prim = static_cast<uint32_t>(env.height);
  l.p0x = std::cos(env.rotation);
  l.p0y = std::sin(env.rotation);
  l.le_r = env.scale.r, l.le_g = env.scale.g, l.le_b = env.scale.b;
  l.area = meanLuminance;
  l.disk_area = diskArea(sceneRadius);
  l.leaf = PR_INVALID_INDEX;
  l.power = dev::light_power(&l, sceneRadius);
  if (!std::isfinite(l.power) || !(l.power > 0.0f)) l.power = 0.0f;
  return l;
}

}  // namespace pr
