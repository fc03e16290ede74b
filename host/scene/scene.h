// The scene as the renderer sees it (docs/design.md section 3): the static scene graph (SSG)
// flattened into one world-space triangle list, the dynamic scene graph (DSG) as object-space
// meshes plus instances whose transforms are evaluated per frame, materials, textures,
// punctual lights, cameras, and the node hierarchy with its animations.
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "scene/animation.h"

namespace pr {

// An axis-aligned box; empty when min > max (the default).
struct Bounds {
  glm::vec3 min{std::numeric_limits<float>::infinity()};
  glm::vec3 max{-std::numeric_limits<float>::infinity()};

  bool empty() const { return min.x > max.x || min.y > max.y || min.z > max.z; }
  void extend(const glm::vec3& p) {
    min = glm::min(min, p);
    max = glm::max(max, p);
  }
  void extend(const Bounds& b) {
    if (b.empty()) return;
    extend(b.min);
    extend(b.max);
  }
  glm::vec3 centre() const { return (min + max) * 0.5f; }
  glm::vec3 extent() const { return max - min; }
  // The box of this box's eight corners under `m` (empty stays empty).
  Bounds transformed(const glm::mat4& m) const;
};

// Triangles sharing vertex arrays. The SSG is one of these in world space; each DSG mesh is
// one in object space.
struct TriangleMesh {
  std::string name;
  std::vector<glm::vec3> positions;
  // One per vertex, unit length; zero on a primitive without NORMAL, which is shaded flat (by
  // the geometric normal): every transform and deformation keeps it zero.
  std::vector<glm::vec3> normals;
  std::vector<glm::vec2> uvs;       // one per vertex (TEXCOORD_0, zero when absent)
  std::vector<glm::vec2> uvs1;      // empty, or one per vertex (TEXCOORD_1)
  std::vector<glm::vec4> tangents;  // empty, or one per vertex (xyz, w = handedness)
  std::vector<uint32_t> indices;    // 3 per triangle
  std::vector<uint32_t> materials;  // one per triangle, index into Scene::materials
  // Deformation (glTF skins and morph targets); empty for rigid meshes.
  int influences = 0;               // joint/weight pairs per vertex (4 per JOINTS_n set)
  std::vector<uint32_t> joints;     // vertexCount * influences, indices into the skin's joints
  std::vector<float> jointWeights;  // vertexCount * influences
  std::vector<std::vector<glm::vec3>> morphPositions;  // per target: per-vertex deltas
  std::vector<std::vector<glm::vec3>> morphNormals;    // per target: empty or per-vertex deltas
  std::vector<float> morphWeights;                     // the mesh's default weights

  size_t triangleCount() const { return indices.size() / 3; }
  size_t vertexCount() const { return positions.size(); }
  Bounds bounds() const;
};

enum class AlphaMode : uint32_t { Opaque = 0, Mask = 1, Blend = 2 };

// A material's use of a texture, with KHR_texture_transform (identity when absent).
struct TextureRef {
  int texture = -1;  // index into Scene::textures, -1 = none
  int texCoord = 0;  // uv set: TEXCOORD_0 or TEXCOORD_1
  glm::vec2 offset{0.0f};
  float rotation = 0.0f;  // radians, counter-clockwise in uv as the extension defines it
  glm::vec2 scale{1.0f};

  bool valid() const { return texture >= 0; }
  // uv' = T * R * S * uv, the extension's matrix (rows: [c s ox], [-s c oy]).
  glm::vec2 apply(const glm::vec2& uv) const;
};

// glTF metallic-roughness with the extensions we support. Defaults are the glTF spec's.
struct Material {
  std::string name;
  glm::vec4 baseColorFactor{1.0f};
  TextureRef baseColorTexture;  // sRGB texture
  float metallicFactor = 1.0f;
  float roughnessFactor = 1.0f;
  TextureRef metallicRoughnessTexture;  // linear: G = roughness, B = metallic
  TextureRef normalTexture;             // linear tangent-space normal map
  float normalScale = 1.0f;
  glm::vec3 emissiveFactor{0.0f};
  TextureRef emissiveTexture;      // sRGB texture
  float emissiveStrength = 1.0f;   // KHR_materials_emissive_strength
  float transmission = 0.0f;       // KHR_materials_transmission factor
  TextureRef transmissionTexture;  // its texture: linear, R scales the factor
  float ior = 1.5f;                // KHR_materials_ior
  float specular = 1.0f;           // KHR_materials_specular: specularFactor
  glm::vec3 specularColor{1.0f};   // specularColorFactor
  float clearcoat = 0.0f;          // KHR_materials_clearcoat: clearcoatFactor
  float clearcoatRoughness = 0.0f;
  TextureRef specularTexture;            // linear, A scales specularFactor
  TextureRef specularColorTexture;       // sRGB
  TextureRef clearcoatTexture;           // linear, R
  TextureRef clearcoatRoughnessTexture;  // linear, G
  TextureRef clearcoatNormalTexture;     // linear tangent-space normal map of the coat
  float clearcoatNormalScale = 1.0f;
  glm::vec3 sheenColor{0.0f};        // KHR_materials_sheen: sheenColorFactor (0: none)
  float sheenRoughness = 0.0f;       // sheenRoughnessFactor
  TextureRef sheenColorTexture;      // sRGB, RGB
  TextureRef sheenRoughnessTexture;  // linear, A
  float anisotropyStrength = 0.0f;   // KHR_materials_anisotropy: anisotropyStrength
  float anisotropyRotation = 0.0f;   // radians, counter-clockwise from the tangent
  TextureRef anisotropyTexture;      // linear: RG direction, B strength
  float thickness = 0.0f;            // KHR_materials_volume: thicknessFactor (0: thin-walled)
  float attenuationDistance = std::numeric_limits<float>::infinity();
  glm::vec3 attenuationColor{1.0f};
  AlphaMode alphaMode = AlphaMode::Opaque;
  float alphaCutoff = 0.5f;
  bool doubleSided = false;

  glm::vec3 emission() const { return emissiveFactor * emissiveStrength; }
  bool isEmissive() const { return emission() != glm::vec3(0.0f); }
  bool isDielectric() const { return transmission > 0.0f; }
  bool isAnisotropic() const { return anisotropyStrength > 0.0f; }
};

enum class TextureWrap : uint32_t { Repeat = 0, ClampToEdge = 1, MirroredRepeat = 2 };

// A decoded texture: RGBA8, rows top to bottom as in the image file.
struct Texture {
  std::string name;
  int width = 0;
  int height = 0;
  std::vector<uint8_t> rgba8;  // width * height * 4 bytes
  bool srgb = false;           // colour data (baseColor, emissive) vs linear data
  TextureWrap wrapS = TextureWrap::Repeat;
  TextureWrap wrapT = TextureWrap::Repeat;
  bool nearest = false;  // magFilter NEAREST
};

enum class LightType : uint32_t { Point = 0, Spot = 1, Directional = 2 };

// A KHR_lights_punctual light as placed by one node.
struct PunctualLightDef {
  std::string name;
  LightType type = LightType::Point;
  glm::vec3 color{1.0f};
  float intensity = 1.0f;  // candela (point, spot) or lux (directional)
  float range = 0.0f;      // 0 = infinite
  float innerConeAngle = 0.0f;
  float outerConeAngle = 0.7853981634f;  // pi/4
  int node = -1;                         // the node that places it
  bool dynamic = false;                  // the node or an ancestor is animated (or marked dynamic)
};

// A punctual light evaluated at a time: world-space position and direction.
struct PunctualLight {
  LightType type = LightType::Point;
  glm::vec3 color{1.0f};
  float intensity = 1.0f;
  float range = 0.0f;
  float innerConeAngle = 0.0f;
  float outerConeAngle = 0.7853981634f;
  glm::vec3 position{0.0f};
  glm::vec3 direction{0.0f, 0.0f, -1.0f};  // where spot and directional lights shine
};

// A camera as placed by one node (or the default camera framing the scene).
struct CameraDef {
  std::string name;
  bool perspective = true;   // orthographic cameras load but render refuses them
  float yfov = 0.6981317f;   // radians (40 degrees)
  float aspectRatio = 0.0f;  // 0 = unspecified, use the image's
  float znear = 0.01f;
  float zfar = 0.0f;               // 0 = infinite
  float xmag = 0.0f, ymag = 0.0f;  // orthographic only
  int node = -1;                   // -1 for the default camera
  bool dynamic = false;
  bool isDefault = false;        // made by the loader because the file has no camera
  glm::mat4 defaultWorld{1.0f};  // world transform of the default camera
};

// A camera evaluated at a time.
struct CameraPose {
  glm::vec3 position{0.0f};
  glm::vec3 forward{0.0f, 0.0f, -1.0f};  // unit
  glm::vec3 up{0.0f, 1.0f, 0.0f};        // unit, orthogonal to forward
  float yfov = 0.6981317f;
  float aspect = 0.0f;  // 0 = unspecified
  float znear = 0.01f;
  float zfar = 0.0f;
  bool perspective = true;
};

// Limits on what a scene may hold (README.md "Limits"): key times within 1e6 s (11.6 days; at
// the highest --fps, 1e9 frames, which an int counts), and node hierarchies at most this deep
// (a transform walks up to the root: deeper chains would cost quadratic time per frame).
constexpr double kMaxAnimationSeconds = 1e6;
constexpr int kMaxNodeDepth = 10000;

// A node of the glTF hierarchy (indices are the file's node indices).
struct Node {
  std::string name;
  int parent = -1;
  std::vector<int> children;
  bool hasMatrix = false;  // `matrix` given: then TRS below are unused
  glm::mat4 matrix{1.0f};
  glm::vec3 translation{0.0f};
  glm::quat rotation{1.0f, 0.0f, 0.0f, 0.0f};  // w, x, y, z
  glm::vec3 scale{1.0f};
  int mesh = -1;
  int camera = -1;                   // glTF camera index
  bool inScene = false;              // reachable from the scene that was loaded
  bool animated = false;             // target of a translation/rotation/scale channel
  bool dynamic = false;              // it or an ancestor is animated or marked "dynamic": true
  bool moves = false;                // it or an ancestor is animated: world transform depends on t
  bool weightsAnimated = false;      // target of a morph weights channel
  std::vector<float> weights;        // morph weights (empty: the mesh's)
  std::vector<ChannelRef> channels;  // the channels that target it
  glm::mat4 restWorld{1.0f};         // world transform with no animation applied

  glm::mat4 restLocal() const;
};

// A glTF skin: the joints (node indices) and their inverse bind matrices.
struct Skin {
  std::string name;
  std::vector<int> joints;
  std::vector<glm::mat4> inverseBind;  // one per joint
};

// How a dynamic mesh deforms, if it does: skinned by a skin's joints (then in world space: the
// placing node's transform does not apply, as glTF says) and/or blended with the mesh's morph
// targets by the node's (animated) weights. Such a mesh belongs to one node alone.
struct Deformer {
  int skin = -1;  // index into Scene::skins, -1: not skinned
  int node = -1;  // the node that places the mesh; -1: the mesh does not deform
  bool deforms() const { return node >= 0; }
};

// One DSG instance: an object-space mesh placed by an (animated or dynamic) node.
struct Instance {
  uint32_t mesh = 0;  // index into Scene::dynamicMeshes
  int node = -1;
  std::string name;
};

struct Scene {
  std::string path;  // the file it was loaded from
  // A hash of the content of every file it was loaded from (the glTF file, its buffers and
  // images): an edited texture changes it where the names stay. "" unless
  // LoadOptions::digestInputs.
  std::string inputDigest;
  std::vector<std::string> inputFiles;  // those files' paths

  TriangleMesh staticMesh;                    // SSG, world space
  std::vector<uint32_t> staticTriangleNodes;  // per SSG triangle, the glTF node placing it
  std::vector<TriangleMesh> dynamicMeshes;    // DSG, object space, one per glTF mesh used
  std::vector<Instance> instances;            // DSG instances
  std::vector<Bounds> dynamicMeshBounds;      // object-space bounds of each dynamic mesh
  std::vector<Deformer> deformers;            // one per dynamic mesh
  std::vector<Skin> skins;

  std::vector<Material> materials;
  std::vector<Texture> textures;
  std::vector<PunctualLightDef> lights;
  std::vector<CameraDef> cameras;  // never empty after loading: a default one when needed
  std::vector<Animation> animations;
  std::vector<Node> nodes;
  std::vector<int> rootNodes;
  std::vector<std::string> warnings;  // one line each, already printed when loading

  // SSG triangles counting each glTF mesh once, however many static nodes place it (the
  // figure a per-mesh tally of the file gives; staticTriangleCount() counts every placement).
  size_t staticMeshTriangles = 0;

  Bounds bounds;  // of all geometry over the whole animation (sampled)

  // --- evaluation at time t in seconds ---
  glm::mat4 nodeLocalTransform(int node, double t) const;
  glm::mat4 nodeWorldTransform(int node, double t) const;
  glm::mat4 instanceTransform(size_t instance, double t) const;
  CameraPose cameraAt(int camera, double t) const;
  // The morph weights of the node's mesh at t (animated, else the node's, else the mesh's).
  std::vector<float> morphWeightsAt(int node, const TriangleMesh& mesh, double t) const;
  // Dynamic mesh m as it is at time t: morphed, then skinned (positions, normals, tangents).
  // `out` starts as a copy of the mesh; a rigid mesh stays as it is.
  void deformMesh(size_t m, double t, TriangleMesh* out) const;
  // Whether dynamic mesh m deforms over the animation.
  bool meshDeforms(size_t m) const { return m < deformers.size() && deformers[m].deforms(); }
  PunctualLight lightAt(size_t light, double t) const;
  Bounds boundsAt(double t) const;  // static geometry and every instance at t
  Bounds sceneBounds() const;       // union of boundsAt over samples of the animation

  // Max key time over all channels, 0 when nothing is animated.
  double animationDuration() const;
  // Frames of the animation at `fps`: floor(duration * fps) + 1 (1 for a still scene).
  size_t frameCount(double fps) const;

  // --- counts ---
  size_t staticTriangleCount() const { return staticMesh.triangleCount(); }
  size_t dynamicTriangleCount() const;  // over instances
  size_t staticEmissiveTriangleCount() const;
  size_t dynamicEmissiveTriangleCount() const;  // over instances
  size_t emissiveTriangleCount() const {
    return staticEmissiveTriangleCount() + dynamicEmissiveTriangleCount();
  }
  size_t dynamicLightCount() const;
  size_t deformingTriangleCount() const;  // of the dynamic meshes that deform
  size_t fileCameraCount() const;         // cameras that come from the file
};

}  // namespace pr
