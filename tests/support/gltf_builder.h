// Writes small glTF 2.0 scenes for tests: meshes (with morph targets and skin weights),
// materials, nodes, a camera, punctual lights, skins, animations; the binary buffer goes to a
// .bin file beside the .gltf.
#pragma once

#include <array>
#include <set>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <nlohmann/json.hpp>

namespace pr::test {

struct MaterialSpec {
  glm::vec4 baseColor{1.0f};
  float metallic = 0.0f;
  float roughness = 1.0f;
  glm::vec3 emissive{0.0f};
  float emissiveStrength = 1.0f;
  float transmission = 0.0f;
  float ior = 1.5f;
  // More of the material's extensions, as written (e.g. {"KHR_materials_sheen": {...}}).
  nlohmann::json extensions = nlohmann::json::object();
};

// Optional per-vertex attributes of a mesh's primitive, and its morph targets.
struct MeshAttributes {
  std::vector<glm::vec3> normals;               // NORMAL
  std::vector<glm::vec2> uvs;                   // TEXCOORD_0
  std::vector<glm::vec4> tangents;              // TANGENT
  std::vector<std::array<uint16_t, 4>> joints;  // JOINTS_0
  std::vector<glm::vec4> weights;               // WEIGHTS_0
  // Per morph target: its POSITION and NORMAL deltas (either may be empty).
  std::vector<std::vector<glm::vec3>> targetPositions, targetNormals;
};

class GltfBuilder {
 public:
  int addMaterial(const MaterialSpec& m);
  // A mesh of triangles (3 indices each), with optional per-vertex normals.
  int addMesh(const std::vector<glm::vec3>& positions, const std::vector<uint32_t>& indices,
              int material, const std::vector<glm::vec3>& normals = {});
  int addMesh(const std::vector<glm::vec3>& positions, const std::vector<uint32_t>& indices,
              int material, const MeshAttributes& attributes);
  // A UV sphere of `segments` x `rings` quads with NORMAL and TEXCOORD_0 (u round +Y).
  int addSphere(float radius, int segments, int rings, int material);
  // Axis-aligned box as 12 triangles; `inward` flips the winding (a room seen from inside).
  int addBox(glm::vec3 lo, glm::vec3 hi, int material, bool inward = false);
  // The same with one morph target, which moves the whole box by `shift`.
  int addBox(glm::vec3 lo, glm::vec3 hi, int material, bool inward, glm::vec3 shift);
  // A quad (two triangles) a, b, c, d in order.
  int addQuad(glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d, int material);
  int addNode(int mesh, glm::vec3 translation = glm::vec3(0.0f),
              glm::quat rotation = glm::quat(1, 0, 0, 0), glm::vec3 scale = glm::vec3(1.0f));
  // A perspective camera at `eye` looking at `target`, with its clipping planes (zfar 0: none).
  int addCamera(glm::vec3 eye, glm::vec3 target, float yfov, float aspect = 0.0f,
                float znear = 0.01f, float zfar = 0.0f);
  int addPointLight(glm::vec3 position, glm::vec3 color, float intensity);
  // A spot light at `position` aimed at `target`, its cone's half-angles inner and outer.
  int addSpotLight(glm::vec3 position, glm::vec3 target, glm::vec3 color, float intensity,
                   float inner, float outer);
  // A directional light shining along its node's -Z turned by `rotation`.
  int addDirectionalLight(glm::quat rotation, glm::vec3 color, float intensity);
  // A skin on mesh node `node` whose joints are these nodes (inverse bind matrices identity).
  void addSkin(int node, const std::vector<int>& joints);
  // A LINEAR translation animation of `node` through `keys` at `times`.
  void animateTranslation(int node, const std::vector<float>& times,
                          const std::vector<glm::vec3>& keys);
  // A LINEAR rotation animation of `node` through `keys` at `times` (slerped, as glTF says).
  void animateRotation(int node, const std::vector<float>& times,
                       const std::vector<glm::quat>& keys);
  // A LINEAR animation of `node`'s morph weights: keys[k] holds every target's weight at times[k].
  void animateWeights(int node, const std::vector<float>& times,
                      const std::vector<std::vector<float>>& keys);

  // Writes dir/name.gltf and dir/name.bin; returns the .gltf path.
  std::string write(const std::string& dir, const std::string& name) const;

 private:
  int addAccessor(const void* data, size_t bytes, int componentType, size_t count, const char* type,
                  bool vertexData, const nlohmann::json& minmax = nullptr);
  std::vector<unsigned char> bin_;
  std::set<std::string> extensionsUsed_;  // the materials' extensions beyond the usual
  nlohmann::json accessors_ = nlohmann::json::array(), views_ = nlohmann::json::array(),
                 meshes_ = nlohmann::json::array(), materials_ = nlohmann::json::array(),
                 nodes_ = nlohmann::json::array(), cameras_ = nlohmann::json::array(),
                 lights_ = nlohmann::json::array(), animations_ = nlohmann::json::array(),
                 skins_ = nlohmann::json::array();
};

}  // namespace pr::test
