#include "scene/scene.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "scene/emission_power.h"

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
      case AnimationPath::Weights:
        break;  // the mesh's shape, not the node's transform
    }
  }
  return glm::translate(glm::mat4(1.0f), translation) * glm::mat4_cast(rotation) *
         glm::scale(glm::mat4(1.0f), scale);
}

glm::mat4 Scene::nodeWorldTransform(int node, double t) const {
  // Up to the first ancestor that does not move (its rest transform holds), then down again;
  // a loop, not a recursion: hierarchies come from files (kMaxNodeDepth levels).
  std::vector<int> chain;
  int k = node;
  while (k >= 0 && nodes.at(static_cast<size_t>(k)).moves) {
    chain.push_back(k);
    k = nodes[static_cast<size_t>(k)].parent;
  }
  glm::mat4 world = k >= 0 ? nodes[static_cast<size_t>(k)].restWorld : glm::mat4(1.0f);
  for (auto it = chain.rbegin(); it != chain.rend(); ++it)
    world = world * nodeLocalTransform(*it, t);
  return world;
}

glm::mat4 Scene::instanceTransform(size_t instance, double t) const {
  const Instance& in = instances.at(instance);
  // A skinned mesh is placed by its joints alone.
  if (in.mesh < deformers.size() && deformers[in.mesh].skin >= 0) return glm::mat4(1.0f);
  return nodeWorldTransform(in.node, t);
}

std::vector<float> Scene::morphWeightsAt(int node, const TriangleMesh& mesh, double t) const {
  const size_t n = mesh.morphPositions.size();
  std::vector<float> w = mesh.morphWeights;
  if (node >= 0 && !nodes[size_t(node)].weights.empty()) w = nodes[size_t(node)].weights;
  w.resize(n, 0.0f);
  if (node < 0 || !nodes[size_t(node)].weightsAnimated) return w;
  for (const ChannelRef& ref : nodes[size_t(node)].channels) {
    const Animation& a = animations[ref.animation];
    const AnimationChannel& c = a.channels[ref.channel];
    if (c.path != AnimationPath::Weights) continue;
    const glm::vec4 v = sampleRaw(a.samplers[size_t(c.sampler)], t);
    for (int k = 0; k < 4; ++k)
      if (size_t(c.firstWeight + k) < n) w[size_t(c.firstWeight + k)] = v[k];
  }
  return w;
}

void Scene::deformMesh(size_t m, double t, TriangleMesh* out) const {
  const TriangleMesh& base = dynamicMeshes.at(m);
  if (!meshDeforms(m)) return;
  const Deformer& d = deformers[m];
  const size_t nv = base.vertexCount();
  out->positions = base.positions;
  out->normals = base.normals;
  out->tangents = base.tangents;
  if (!base.morphPositions.empty()) {
    const std::vector<float> w = morphWeightsAt(d.node, base, t);
    for (size_t k = 0; k < w.size(); ++k) {
      if (w[k] == 0.0f) continue;
      for (size_t v = 0; v < nv; ++v) out->positions[v] += w[k] * base.morphPositions[k][v];
      if (!base.morphNormals[k].empty())
        for (size_t v = 0; v < nv; ++v) out->normals[v] += w[k] * base.morphNormals[k][v];
    }
  }
  if (d.skin >= 0 && base.influences > 0) {
    const Skin& skin = skins[size_t(d.skin)];
    std::vector<glm::mat4> joint(skin.joints.size());
    for (size_t j = 0; j < joint.size(); ++j)
      joint[j] = nodeWorldTransform(skin.joints[j], t) * skin.inverseBind[j];
    const size_t k = size_t(base.influences);
    for (size_t v = 0; v < nv; ++v) {
      glm::mat4 s(0.0f);
      float total = 0.0f;
      for (size_t i = 0; i < k; ++i) {
        const float w = base.jointWeights[v * k + i];
        if (w != 0.0f) s += w * joint[base.joints[v * k + i]];
        total += w;
      }
      if (!(total > 0.0f)) s = glm::mat4(1.0f);  // no weights: the bind pose
      const glm::mat3 lin(s);
      out->positions[v] = glm::vec3(s * glm::vec4(out->positions[v], 1.0f));
      // Normals by the cofactor matrix (the inverse transpose up to a positive factor).
      const float det = glm::determinant(lin);
      glm::vec3 n = (det != 0.0f ? glm::transpose(glm::inverse(lin)) * det : lin) * out->normals[v];
      if (det < 0.0f) n = -n;
      out->normals[v] = n;
      if (!out->tangents.empty()) {
        const glm::vec3 tg = lin * glm::vec3(out->tangents[v]);
        out->tangents[v] = glm::vec4(tg, out->tangents[v].w * (det < 0.0f ? -1.0f : 1.0f));
      }
    }
  }
  for (size_t v = 0; v < nv; ++v) {
    // A flat primitive's zero normal (no morph deltas, skinned to zero) stays zero.
    const float l = glm::length(out->normals[v]);
    out->normals[v] = l > 0.0f && std::isfinite(l) ? out->normals[v] / l : base.normals[v];
    if (!out->tangents.empty()) {
      const glm::vec3 tg(out->tangents[v]);
      const float tl = glm::length(tg);
      if (tl > 0.0f && std::isfinite(tl)) out->tangents[v] = glm::vec4(tg / tl, out->tangents[v].w);
    }
  }
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

namespace {

// Instance i's world bounds at t: its mesh's bounds placed, or its deformed vertices.
Bounds instanceBounds(const Scene& s, size_t i, double t) {
  const uint32_t m = s.instances[i].mesh;
  if (!s.meshDeforms(m)) return s.dynamicMeshBounds[m].transformed(s.instanceTransform(i, t));
  TriangleMesh shape = s.dynamicMeshes[m];
  s.deformMesh(m, t, &shape);
  return shape.bounds().transformed(s.instanceTransform(i, t));
}

}  // namespace

Bounds Scene::boundsAt(double t) const {
  Bounds b = staticMesh.bounds();
  for (size_t i = 0; i < instances.size(); ++i) b.extend(instanceBounds(*this, i, t));
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
    for (size_t i = 0; i < instances.size(); ++i) b.extend(instanceBounds(*this, i, t));
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

size_t Scene::deformingTriangleCount() const {
  size_t n = 0;
  for (const Instance& i : instances)
    if (meshDeforms(i.mesh)) n += dynamicMeshes[i.mesh].triangleCount();
  return n;
}

size_t Scene::dynamicTriangleCount() const {
  size_t n = 0;
  for (const Instance& i : instances) n += dynamicMeshes[i.mesh].triangleCount();
  return n;
}

namespace {
// The triangles that emit: an emissive material, and texels that are not all black.
size_t emissiveCount(const TriangleMesh& m, const Scene& scene) {
  const EmissionShares shares(scene);
  size_t n = 0;
  for (size_t k = 0; k < m.triangleCount(); ++k)
    n += scene.materials[m.materials[k]].isEmissive() && shares.share(m, k) > 0.0f;
  return n;
}
}  // namespace

size_t Scene::staticEmissiveTriangleCount() const {
  return emissiveCount(staticMesh, *this);
}

size_t Scene::dynamicEmissiveTriangleCount() const {
  size_t n = 0;
  for (const Instance& i : instances) n += emissiveCount(dynamicMeshes[i.mesh], *this);
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
