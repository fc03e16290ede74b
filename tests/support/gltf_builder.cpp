#include "support/gltf_builder.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>

#include <glm/gtc/matrix_transform.hpp>

namespace pr::test {

using nlohmann::json;

int GltfBuilder::addAccessor(const void* data, size_t bytes, int componentType, size_t count,
                             const char* type, bool vertexData, const json& minmax) {
  while (bin_.size() % 4) bin_.push_back(0);
  const size_t offset = bin_.size();
  bin_.insert(bin_.end(), static_cast<const unsigned char*>(data),
              static_cast<const unsigned char*>(data) + bytes);
  json view = {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes}};
  if (vertexData) view["target"] = 34962;
  views_.push_back(view);
  json acc = {{"bufferView", views_.size() - 1},
              {"componentType", componentType},
              {"count", count},
              {"type", type}};
  if (!minmax.is_null()) {
    acc["min"] = minmax[0];
    acc["max"] = minmax[1];
  }
  accessors_.push_back(acc);
  return static_cast<int>(accessors_.size() - 1);
}

int GltfBuilder::addMaterial(const MaterialSpec& m) {
  json mat = {{"pbrMetallicRoughness",
               {{"baseColorFactor", {m.baseColor.r, m.baseColor.g, m.baseColor.b, m.baseColor.a}},
                {"metallicFactor", m.metallic},
                {"roughnessFactor", m.roughness}}}};
  if (m.emissive != glm::vec3(0.0f)) {
    mat["emissiveFactor"] = {m.emissive.r, m.emissive.g, m.emissive.b};
    if (m.emissiveStrength != 1.0f)
      mat["extensions"]["KHR_materials_emissive_strength"] = {
          {"emissiveStrength", m.emissiveStrength}};
  }
  if (m.transmission > 0.0f) {
    mat["extensions"]["KHR_materials_transmission"] = {{"transmissionFactor", m.transmission}};
    mat["extensions"]["KHR_materials_ior"] = {{"ior", m.ior}};
  }
  for (const auto& [name, ext] : m.extensions.items()) {
    mat["extensions"][name] = ext;
    extensionsUsed_.insert(name);
  }
  materials_.push_back(mat);
  return static_cast<int>(materials_.size() - 1);
}

int GltfBuilder::addMesh(const std::vector<glm::vec3>& positions,
                         const std::vector<uint32_t>& indices, int material,
                         const std::vector<glm::vec3>& normals) {
  MeshAttributes a;
  a.normals = normals;
  return addMesh(positions, indices, material, a);
}

int GltfBuilder::addMesh(const std::vector<glm::vec3>& positions,
                         const std::vector<uint32_t>& indices, int material,
                         const MeshAttributes& a) {
  auto vec3s = [&](const std::vector<glm::vec3>& v) {
    glm::vec3 lo(1e30f), hi(-1e30f);
    for (const auto& p : v) lo = glm::min(lo, p), hi = glm::max(hi, p);
    return addAccessor(v.data(), v.size() * 12, 5126, v.size(), "VEC3", true,
                       json::array({{lo.x, lo.y, lo.z}, {hi.x, hi.y, hi.z}}));
  };
  const int pos = vec3s(positions);
  const int idx =
      addAccessor(indices.data(), indices.size() * 4, 5125, indices.size(), "SCALAR", false);
  json prim = {{"attributes", {{"POSITION", pos}}}, {"indices", idx}, {"material", material}};
  json& attrs = prim["attributes"];
  if (!a.normals.empty())
    attrs["NORMAL"] =
        addAccessor(a.normals.data(), a.normals.size() * 12, 5126, a.normals.size(), "VEC3", true);
  if (!a.uvs.empty())
    attrs["TEXCOORD_0"] =
        addAccessor(a.uvs.data(), a.uvs.size() * 8, 5126, a.uvs.size(), "VEC2", true);
  if (!a.tangents.empty())
    attrs["TANGENT"] = addAccessor(a.tangents.data(), a.tangents.size() * 16, 5126,
                                   a.tangents.size(), "VEC4", true);
  if (!a.joints.empty())
    attrs["JOINTS_0"] =
        addAccessor(a.joints.data(), a.joints.size() * 8, 5123, a.joints.size(), "VEC4", true);
  if (!a.weights.empty())
    attrs["WEIGHTS_0"] =
        addAccessor(a.weights.data(), a.weights.size() * 16, 5126, a.weights.size(), "VEC4", true);
  const size_t targets = std::max(a.targetPositions.size(), a.targetNormals.size());
  for (size_t t = 0; t < targets; ++t) {
    json target = json::object();
    if (t < a.targetPositions.size() && !a.targetPositions[t].empty())
      target["POSITION"] = vec3s(a.targetPositions[t]);
    if (t < a.targetNormals.size() && !a.targetNormals[t].empty())
      target["NORMAL"] = addAccessor(a.targetNormals[t].data(), a.targetNormals[t].size() * 12,
                                     5126, a.targetNormals[t].size(), "VEC3", true);
    prim["targets"].push_back(target);
  }
  meshes_.push_back({{"primitives", json::array({prim})}});
  return static_cast<int>(meshes_.size() - 1);
}

int GltfBuilder::addSphere(float radius, int segments, int rings, int material) {
  std::vector<glm::vec3> positions;
  std::vector<uint32_t> indices;
  MeshAttributes a;
  for (int j = 0; j <= rings; ++j)
    for (int i = 0; i <= segments; ++i) {
      const float u = float(i) / float(segments), v = float(j) / float(rings);
      const float phi = 6.28318530718f * u, theta = 3.14159265359f * v;
      const glm::vec3 n(std::sin(theta) * std::cos(phi), std::cos(theta),
                        -std::sin(theta) * std::sin(phi));
      positions.push_back(n * radius);
      a.normals.push_back(n);
      a.uvs.emplace_back(u, v);
    }
  for (int j = 0; j < rings; ++j)
    for (int i = 0; i < segments; ++i) {
      const uint32_t k = uint32_t(j * (segments + 1) + i), below = k + uint32_t(segments + 1);
      indices.insert(indices.end(), {k, below, below + 1, k, below + 1, k + 1});
    }
  return addMesh(positions, indices, material, a);
}

int GltfBuilder::addQuad(glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d, int material) {
  return addMesh({a, b, c, d}, {0, 1, 2, 0, 2, 3}, material);
}

int GltfBuilder::addBox(glm::vec3 lo, glm::vec3 hi, int material, bool inward) {
  return addBox(lo, hi, material, inward, glm::vec3(0.0f));
}

int GltfBuilder::addBox(glm::vec3 lo, glm::vec3 hi, int material, bool inward, glm::vec3 shift) {
  std::vector<glm::vec3> p;
  std::vector<uint32_t> idx;
  // Each face: four corners counter-clockwise seen from outside.
  const glm::vec3 c[8] = {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z},
                          {lo.x, hi.y, lo.z}, {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z},
                          {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}};
  const int faces[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 4, 7, 3},
                           {1, 2, 6, 5}, {0, 1, 5, 4}, {3, 7, 6, 2}};
  for (const auto& f : faces) {
    const uint32_t base = static_cast<uint32_t>(p.size());
    for (int k = 0; k < 4; ++k) p.push_back(c[f[k]]);
    if (inward)
      idx.insert(idx.end(), {base, base + 2, base + 1, base, base + 3, base + 2});
    else
      idx.insert(idx.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
  }
  if (shift == glm::vec3(0.0f)) return addMesh(p, idx, material);
  MeshAttributes a;
  a.targetPositions.emplace_back(p.size(), shift);
  return addMesh(p, idx, material, a);
}

int GltfBuilder::addNode(int mesh, glm::vec3 t, glm::quat r, glm::vec3 s) {
  json n = {{"translation", {t.x, t.y, t.z}},
            {"rotation", {r.x, r.y, r.z, r.w}},
            {"scale", {s.x, s.y, s.z}}};
  if (mesh >= 0) n["mesh"] = mesh;
  nodes_.push_back(n);
  return static_cast<int>(nodes_.size() - 1);
}

int GltfBuilder::addCamera(glm::vec3 eye, glm::vec3 target, float yfov, float aspect, float znear,
                           float zfar) {
  json cam = {{"type", "perspective"}, {"perspective", {{"yfov", yfov}, {"znear", znear}}}};
  if (aspect > 0.0f) cam["perspective"]["aspectRatio"] = aspect;
  if (zfar > 0.0f) cam["perspective"]["zfar"] = zfar;
  cameras_.push_back(cam);
  // The camera looks down its local -Z: the inverse of a look-at view matrix places it.
  const glm::vec3 fwd = glm::normalize(target - eye);
  const glm::vec3 up = std::fabs(fwd.y) > 0.99f ? glm::vec3(0, 0, -1) : glm::vec3(0, 1, 0);
  const glm::mat4 world = glm::inverse(glm::lookAt(eye, target, up));
  const glm::quat q = glm::quat_cast(glm::mat3(world));
  nodes_.push_back({{"camera", cameras_.size() - 1},
                    {"translation", {eye.x, eye.y, eye.z}},
                    {"rotation", {q.x, q.y, q.z, q.w}}});
  return static_cast<int>(nodes_.size() - 1);
}

int GltfBuilder::addPointLight(glm::vec3 position, glm::vec3 color, float intensity) {
  lights_.push_back(
      {{"type", "point"}, {"color", {color.r, color.g, color.b}}, {"intensity", intensity}});
  nodes_.push_back({{"translation", {position.x, position.y, position.z}},
                    {"extensions", {{"KHR_lights_punctual", {{"light", lights_.size() - 1}}}}}});
  return static_cast<int>(nodes_.size() - 1);
}

int GltfBuilder::addSpotLight(glm::vec3 position, glm::vec3 target, glm::vec3 color,
                              float intensity, float inner, float outer) {
  lights_.push_back({{"type", "spot"},
                     {"color", {color.r, color.g, color.b}},
                     {"intensity", intensity},
                     {"spot", {{"innerConeAngle", inner}, {"outerConeAngle", outer}}}});
  // The light shines along its node's -Z, as a camera looks: placed as addCamera places one.
  const glm::vec3 fwd = glm::normalize(target - position);
  const glm::vec3 up = std::fabs(fwd.y) > 0.99f ? glm::vec3(0, 0, -1) : glm::vec3(0, 1, 0);
  const glm::quat q = glm::quat_cast(glm::mat3(glm::inverse(glm::lookAt(position, target, up))));
  nodes_.push_back({{"translation", {position.x, position.y, position.z}},
                    {"rotation", {q.x, q.y, q.z, q.w}},
                    {"extensions", {{"KHR_lights_punctual", {{"light", lights_.size() - 1}}}}}});
  return static_cast<int>(nodes_.size() - 1);
}

int GltfBuilder::addDirectionalLight(glm::quat rotation, glm::vec3 color, float intensity) {
  lights_.push_back(
      {{"type", "directional"}, {"color", {color.r, color.g, color.b}}, {"intensity", intensity}});
  nodes_.push_back({{"rotation", {rotation.x, rotation.y, rotation.z, rotation.w}},
                    {"extensions", {{"KHR_lights_punctual", {{"light", lights_.size() - 1}}}}}});
  return static_cast<int>(nodes_.size() - 1);
}

void GltfBuilder::addSkin(int node, const std::vector<int>& joints) {
  skins_.push_back({{"joints", joints}});
  nodes_[size_t(node)]["skin"] = skins_.size() - 1;
}

void GltfBuilder::animateWeights(int node, const std::vector<float>& times,
                                 const std::vector<std::vector<float>>& keys) {
  std::vector<float> w;
  for (const auto& k : keys) w.insert(w.end(), k.begin(), k.end());
  const int in = addAccessor(times.data(), times.size() * 4, 5126, times.size(), "SCALAR", false,
                             json::array({{times.front()}, {times.back()}}));
  const int out = addAccessor(w.data(), w.size() * 4, 5126, w.size(), "SCALAR", false);
  animations_.push_back(
      {{"samplers", json::array({{{"input", in}, {"output", out}, {"interpolation", "LINEAR"}}})},
       {"channels",
        json::array({{{"sampler", 0}, {"target", {{"node", node}, {"path", "weights"}}}}})}});
}

void GltfBuilder::animateTranslation(int node, const std::vector<float>& times,
                                     const std::vector<glm::vec3>& keys) {
  const int in = addAccessor(times.data(), times.size() * 4, 5126, times.size(), "SCALAR", false,
                             json::array({{times.front()}, {times.back()}}));
  const int out = addAccessor(keys.data(), keys.size() * 12, 5126, keys.size(), "VEC3", false);
  animations_.push_back(
      {{"samplers", json::array({{{"input", in}, {"output", out}, {"interpolation", "LINEAR"}}})},
       {"channels",
        json::array({{{"sampler", 0}, {"target", {{"node", node}, {"path", "translation"}}}}})}});
}

void GltfBuilder::animateRotation(int node, const std::vector<float>& times,
                                  const std::vector<glm::quat>& keys) {
  const int in = addAccessor(times.data(), times.size() * 4, 5126, times.size(), "SCALAR", false,
                             json::array({{times.front()}, {times.back()}}));
  std::vector<float> xyzw;
  for (const glm::quat& q : keys) xyzw.insert(xyzw.end(), {q.x, q.y, q.z, q.w});
  const int out = addAccessor(xyzw.data(), xyzw.size() * 4, 5126, keys.size(), "VEC4", false);
  animations_.push_back(
      {{"samplers", json::array({{{"input", in}, {"output", out}, {"interpolation", "LINEAR"}}})},
       {"channels",
        json::array({{{"sampler", 0}, {"target", {{"node", node}, {"path", "rotation"}}}}})}});
}

std::string GltfBuilder::write(const std::string& dir, const std::string& name) const {
  json root = {{"asset", {{"version", "2.0"}}}};
  json sceneNodes = json::array();
  for (size_t i = 0; i < nodes_.size(); ++i) sceneNodes.push_back(i);
  root["scene"] = 0;
  root["scenes"] = json::array({{{"nodes", sceneNodes}}});
  root["nodes"] = nodes_;
  root["meshes"] = meshes_;
  root["materials"] = materials_;
  root["accessors"] = accessors_;
  root["bufferViews"] = views_;
  root["buffers"] = json::array({{{"uri", name + ".bin"}, {"byteLength", bin_.size()}}});
  if (!cameras_.empty()) root["cameras"] = cameras_;
  if (!animations_.empty()) root["animations"] = animations_;
  if (!skins_.empty()) root["skins"] = skins_;
  json used = json::array();
  if (!lights_.empty()) {
    root["extensions"]["KHR_lights_punctual"] = {{"lights", lights_}};
    used.push_back("KHR_lights_punctual");
  }
  used.push_back("KHR_materials_emissive_strength");
  used.push_back("KHR_materials_transmission");
  used.push_back("KHR_materials_ior");
  for (const std::string& e : extensionsUsed_)
    if (std::find(used.begin(), used.end(), e) == used.end()) used.push_back(e);
  root["extensionsUsed"] = used;
  std::ofstream(dir + "/" + name + ".bin", std::ios::binary)
      .write(reinterpret_cast<const char*>(bin_.data()), static_cast<std::streamsize>(bin_.size()));
  const std::string path = dir + "/" + name + ".gltf";
  std::ofstream(path) << root.dump(1);
  return path;
}

}  // namespace pr::test
