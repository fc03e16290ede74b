#include "scene/scene.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

namespace pr {

Bounds Bounds::transformed(const glm::mat4& m) const {
  Bounds out;
  if (empty()) return out;
  for (int i = 0; i < 8; ++i) {
    const glm::vec3 corner((i & 1) ? max.x : min.x, (i & 2) ? max.y : min.y,
                           (i & 4) ? max.z : min.z);
    out.extend(glm::vec3(m * glm::vec4(corner, 1.0f)));
  }
  return out;
}

Bounds TriangleMesh::bounds() const {
  Bounds b;
  // Only vertices that triangles use: skipped primitives' vertices never get here anyway.
  for (const auto& p : positions) b.extend(p);
  return b;
}

glm::vec2 TextureRef::apply(const glm::vec2& uv) const {
  const glm::vec2 s = uv * scale;
  const float c = std::cos(rotation), n = std::sin(rotation);
  return glm::vec2(c * s.x + n * s.y, -n * s.x + c * s.y) + offset;
}

glm::mat4 Node::restLocal() const {
  if (hasMatrix) return matrix;
  return glm::translate(glm::mat4(1.0f), translation) * glm::mat4_cast(rotation) *
         glm::scale(glm::mat4(1.0f), scale);
}

glm::mat4 Scene::nodeLocalTransform(int node, double t) const {
  const Node& n = nodes.at(static_cast<size_t>(node));
  if (!n.animated) return n.restLocal();
  glm::vec3 translation = n.translation, scale = n.scale;
  glm::quat rotation = n.rotation;
  for (const ChannelRef& ref : n.channels) {
    const Animation& a = animations[ref.animation];
    const AnimationChannel& c = a.channels[ref.channel];
    const AnimationSampler& s = a.samplers[static_cast<size_t>(c.sampler)];
    switch (c.path) {
      case AnimationPath::Translation:
        translation = sampleVec3(s, t);
        break;
      case AnimationPath::Rotation:
        rotation = sampleQuat(s, t);
        break;
      case AnimationPath::Scale:
        scale = sampleVec3(s, t);
        break;
    }
  }
  return glm::translate(glm::mat4(1.0f), translation) * glm::mat4_cast(rotation) *
         glm::scale(glm::mat4(1.0f), scale);
}

glm::mat4 Scene::nodeWorldTransform(int node, double t) const {
  const Node& n = nodes.at(static_cast<size_t>(node));
  if (!n.moves) return n.restWorld;
  const glm::mat4 local = nodeLocalTransform(node, t);
  return n.parent < 0 ? local : nodeWorldTransform(n.parent, t) * local;
}

glm::mat4 Scene::instanceTransform(size_t instance, double t) const {
  return nodeWorldTransform(instances.at(instance).node, t);
}

namespace {

glm::vec3 unitOr(const glm::vec3& v, const glm::vec3& fallback) {
  const float len = glm::length(v);
  return len > 0.0f && std::isfinite(len) ? v / len : fallback;
}

}  // namespace

CameraPose Scene::cameraAt(int camera, double t) const {
  const CameraDef& c = cameras.at(static_cast<size_t>(camera));
  const glm::mat4 m = c.node >= 0 ? nodeWorldTransform(c.node, t) : c.defaultWorld;
  CameraPose pose;
  pose.position = glm::vec3(m[3]);
  pose.forward = unitOr(glm::vec3(m * glm::vec4(0.0f, 0.0f, -1.0f, 0.0f)), {0.0f, 0.0f, -1.0f});
  // Scale or shear in the node may tilt +Y off the view axis: keep it orthogonal.
  glm::vec3 up = glm::vec3(m * glm::vec4(0.0f, 1.0f, 0.0f, 0.0f));
  up -= glm::dot(up, pose.forward) * pose.forward;
  const glm::vec3 fallbackUp =
      std::abs(pose.forward.y) < 0.99f ? glm::vec3(0.0f, 1.0f, 0.0f) : glm::vec3(0.0f, 0.0f, 1.0f);
  pose.up =
      unitOr(up, glm::normalize(fallbackUp - glm::dot(fallbackUp, pose.forward) * pose.forward));
  pose.yfov = c.yfov;
  pose.aspect = c.aspectRatio;
  pose.znear = c.znear;
  pose.zfar = c.zfar;
  pose.perspective = c.perspective;
  return pose;
}

PunctualLight Scene::lightAt(size_t light, double t) const {
  const PunctualLightDef& d = lights.at(light);
  const glm::mat4 m = nodeWorldTransform(d.node, t);
  PunctualLight l;
  l.type = d.type;
  l.color = d.color;
  l.intensity = d.intensity;
  l.range = d.range;
  l.innerConeAngle = d.innerConeAngle;
  l.outerConeAngle = d.outerConeAngle;
  l.position = glm::vec3(m[3]);
  l.direction = unitOr(glm::vec3(m * glm::vec4(0.0f, 0.0f, -1.0f, 0.0f)), {0.0f, 0.0f, -1.0f});
  return l;
}

Bounds Scene::boundsAt(double t) const {
  Bounds b = staticMesh.bounds();
  for (size_t i = 0; i < instances.size(); ++i)
    b.extend(dynamicMeshBounds[instances[i].mesh].transformed(instanceTransform(i, t)));
  return b;
}

Bounds Scene::sceneBounds() const {
  const double duration = animationDuration();
  if (instances.empty() || duration <= 0.0) return boundsAt(0.0);
  // Static geometry once, instances at evenly spaced samples of the animation.
  Bounds b = staticMesh.bounds();
  const int samples = 64;
  for (int k = 0; k <= samples; ++k) {
    const double t = duration * k / samples;
    for (size_t i = 0; i < instances.size(); ++i)
      b.extend(dynamicMeshBounds[instances[i].mesh].transformed(instanceTransform(i, t)));
  }
  return b;
}

double Scene::animationDuration() const {
  double d = 0.0;
  for (const Animation& a : animations)
    for (const AnimationChannel& c : a.channels)
      d = std::max(d, a.samplers[static_cast<size_t>(c.sampler)].endTime());
  return d;
}

size_t Scene::frameCount(double fps) const {
  const double d = animationDuration();
  if (!(d > 0.0) || !(fps > 0.0)) return 1;
  return static_cast<size_t>(std::floor(d * fps + 1e-9)) + 1;
}

size_t Scene::dynamicTriangleCount() const {
  size_t n = 0;
  for (const Instance& i : instances) n += dynamicMeshes[i.mesh].triangleCount();
  return n;
}

namespace {
size_t emissiveCount(const TriangleMesh& m, const std::vector<Material>& materials) {
  size_t n = 0;
  for (uint32_t mat : m.materials) n += materials[mat].isEmissive();
  return n;
}
}  // namespace

size_t Scene::staticEmissiveTriangleCount() const {
  return emissiveCount(staticMesh, materials);
}

size_t Scene::dynamicEmissiveTriangleCount() const {
  size_t n = 0;
  for (const Instance& i : instances) n += emissiveCount(dynamicMeshes[i.mesh], materials);
  return n;
}

size_t Scene::dynamicLightCount() const {
  return static_cast<size_t>(std::count_if(lights.begin(), lights.end(),
                                           [](const PunctualLightDef& l) { return l.dynamic; }));
}

size_t Scene::fileCameraCount() const {
  return static_cast<size_t>(std::count_if(cameras.begin(), cameras.end(),
                                           [](const CameraDef& c) { return !c.isDefault; }));
}

}  // namespace pr
