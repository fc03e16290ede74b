#include "support/gltf_builder.h"

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
  materials_.push_back(mat);
  return static_cast<int>(materials_.size() - 1);
}

int GltfBuilder::addMesh(const std::vector<glm::vec3>& positions,
                         const std::vector<uint32_t>& indices, int material,
                         const std::vector<glm::vec3>& normals) {
  glm::vec3 lo(1e30f), hi(-1e30f);
  for (const auto& p : positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
  const int pos = addAccessor(positions.data(), positions.size() * 12, 5126, positions.size(),
                              "VEC3", true, json::array({{lo.x, lo.y, lo.z}, {hi.x, hi.y, hi.z}}));
  const int idx =
      addAccessor(indices.data(), indices.size() * 4, 5125, indices.size(), "SCALAR", false);
  json prim = {{"attributes", {{"POSITION", pos}}}, {"indices", idx}, {"material", material}};
  if (!normals.empty())
    prim["attributes"]["NORMAL"] =
        addAccessor(normals.data(), normals.size() * 12, 5126, normals.size(), "VEC3", true);
  meshes_.push_back({{"primitives", json::array({prim})}});
  return static_cast<int>(meshes_.size() - 1);
}

int GltfBuilder::addQuad(glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d, int material) {
  return addMesh({a, b, c, d}, {0, 1, 2, 0, 2, 3}, material);
}

int GltfBuilder::addBox(glm::vec3 lo, glm::vec3 hi, int material, bool inward) {
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
  return addMesh(p, idx, material);
}

int GltfBuilder::addNode(int mesh, glm::vec3 t, glm::quat r, glm::vec3 s) {
  json n = {{"translation", {t.x, t.y, t.z}},
            {"rotation", {r.x, r.y, r.z, r.w}},
            {"scale", {s.x, s.y, s.z}}};
  if (mesh >= 0) n["mesh"] = mesh;
  nodes_.push_back(n);
  return static_cast<int>(nodes_.size() - 1);
}

int GltfBuilder::addCamera(glm::vec3 eye, glm::vec3 target, float yfov, float aspect) {
  json cam = {{"type", "perspective"}, {"perspective", {{"yfov", yfov}, {"znear", 0.01}}}};
  if (aspect > 0.0f) cam["perspective"]["aspectRatio"] = aspect;
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
  json used = json::array();
  if (!lights_.empty()) {
    root["extensions"]["KHR_lights_punctual"] = {{"lights", lights_}};
    used.push_back("KHR_lights_punctual");
  }
  used.push_back("KHR_materials_emissive_strength");
  used.push_back("KHR_materials_transmission");
  used.push_back("KHR_materials_ior");
  root["extensionsUsed"] = used;
  std::ofstream(dir + "/" + name + ".bin", std::ios::binary)
      .write(reinterpret_cast<const char*>(bin_.data()), static_cast<std::streamsize>(bin_.size()));
  const std::string path = dir + "/" + name + ".gltf";
  std::ofstream(path) << root.dump(1);
  return path;
}

}  // namespace pr::test
