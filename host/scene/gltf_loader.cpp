#include "scene/gltf_loader.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <optional>
#include <set>

#include "scene/gltf_accessors.h"
#include "scene/gltf_document.h"
#include "scene/gltf_validate.h"
#include "scene/image_decode.h"
#include "scene/tangents.h"
#include "util/error.h"

namespace pr {

namespace gltf {

namespace {

// Converts a validated document into the renderer's Scene.
class Converter : Stage {
 public:
  Converter(Document& doc, Validated validated)
      : Stage(doc), parents_(std::move(validated.parents)) {
    scene_.animations = std::move(validated.animations);
  }

  Scene convert() {
    build();
    scene_.warnings = std::move(doc_.warnings);
    return std::move(scene_);
  }

 private:
  static glm::mat4 toMat4(const std::vector<double>& m) {
    glm::mat4 r(1.0f);
    for (int c = 0; c < 4; ++c)
      for (int rr = 0; rr < 4; ++rr) r[c][rr] = float(m[size_t(c * 4 + rr)]);  // column-major
    return r;
  }

  // Which channels play. glTF's animations are clips: with --animation that one alone (see
  // keepOneAnimation); else all of them, but where two animate one node's same property only the
  // first does there (as Blender's importer and most viewers play the first
  // clip), so the Fox plays its Survey, not Survey, Walk and Run at once. A warning names the
  // animations that lose channels.
  void chooseAnimations() {
    if (!doc_.options.animation.empty()) return keepOneAnimation(doc_.options.animation);
    std::set<std::pair<int, int>> earlier;  // (node, path) an earlier animation drives
    std::string shadowed;
    int count = 0;
    for (size_t a = 0; a < scene_.animations.size(); ++a) {
      std::vector<AnimationChannel>& channels = scene_.animations[a].channels;
      const size_t before = channels.size();
      channels.erase(std::remove_if(channels.begin(), channels.end(),
                                    [&](const AnimationChannel& c) {
                                      return earlier.count({c.node, int(c.path)}) > 0;
                                    }),
                     channels.end());
      for (const AnimationChannel& c : channels) earlier.insert({c.node, int(c.path)});
      if (channels.size() < before && ++count)
        shadowed +=
            (shadowed.empty() ? "" : ", ") + std::to_string(a) +
            (scene_.animations[a].name.empty() ? "" : " (" + scene_.animations[a].name + ")");
    }
    if (count > 0)
      warn((count > 1 ? "animations " : "animation ") + shadowed +
           (count > 1 ? " animate" : " animates") +
           " what an earlier animation does; the earliest plays there, as one clip");
  }

  // --animation: the animation `which` names (its index or its name) alone.
  void keepOneAnimation(const std::string& which) {
    std::string names;
    size_t chosen = scene_.animations.size();
    for (size_t a = 0; a < scene_.animations.size(); ++a) {
      const std::string& name = scene_.animations[a].name;
      if (chosen == scene_.animations.size() && (which == std::to_string(a) || which == name))
        chosen = a;
      names += (a ? ", " : "") + std::to_string(a) + (name.empty() ? "" : " (" + name + ")");
    }
    if (chosen == scene_.animations.size())
      fail("--animation " + which + ": no such animation" +
           (names.empty() ? " (the scene has none)" : " (the scene has " + names + ")"));
    for (size_t a = 0; a < scene_.animations.size(); ++a)
      if (a != chosen) scene_.animations[a].channels.clear();
  }

  void buildNodes() {
    const size_t n = model_.nodes.size();
    scene_.nodes.resize(n);
    for (size_t i = 0; i < n; ++i) {
      const auto& src = model_.nodes[i];
      Node& dst = scene_.nodes[i];
      dst.name = src.name;
      dst.parent = parents_[i];
      dst.children = src.children;
      dst.mesh = src.mesh;
      dst.camera = src.camera;
      if (src.matrix.size() == 16) {
        dst.hasMatrix = true;
        dst.matrix = toMat4(src.matrix);
      }
      if (src.translation.size() == 3)
        dst.translation = glm::vec3(src.translation[0], src.translation[1], src.translation[2]);
      if (src.rotation.size() == 4)
        dst.rotation = glm::normalize(glm::quat(float(src.rotation[3]), float(src.rotation[0]),
                                                float(src.rotation[1]), float(src.rotation[2])));
      if (src.scale.size() == 3) dst.scale = glm::vec3(src.scale[0], src.scale[1], src.scale[2]);
      if (const Value* d = member(src.extras, "dynamic"))
        dst.dynamic = d->IsBool() && d->Get<bool>();
      for (double w : src.weights) dst.weights.push_back(float(w));
    }
    chooseAnimations();
    for (uint32_t a = 0; a < scene_.animations.size(); ++a)
      for (uint32_t c = 0; c < scene_.animations[a].channels.size(); ++c) {
        const AnimationChannel& ch = scene_.animations[a].channels[c];
        Node& node = scene_.nodes[size_t(ch.node)];
        if (ch.path == AnimationPath::Weights)
          node.weightsAnimated = true;
        else
          node.animated = true;
        node.channels.push_back({a, c});
      }
    // The loaded scene: the default one, else scene 0.
    if (!model_.scenes.empty()) {
      const int s = model_.defaultScene >= 0 ? model_.defaultScene : 0;
      scene_.rootNodes = model_.scenes[size_t(s)].nodes;
    }
    // Top-down: inherit dynamic/moves flags and compute rest world transforms.
    std::vector<int> stack(scene_.rootNodes.rbegin(), scene_.rootNodes.rend());
    while (!stack.empty()) {
      const int i = stack.back();
      stack.pop_back();
      Node& node = scene_.nodes[size_t(i)];
      node.inScene = true;
      node.moves = node.animated;
      node.dynamic = node.dynamic || node.animated;
      glm::mat4 parentWorld(1.0f);
      if (node.parent >= 0) {
        const Node& p = scene_.nodes[size_t(node.parent)];
        node.moves = node.moves || p.moves;
        node.dynamic = node.dynamic || p.dynamic;
        parentWorld = p.restWorld;
      }
      node.restWorld = parentWorld * node.restLocal();
      for (auto it = node.children.rbegin(); it != node.children.rend(); ++it) stack.push_back(*it);
    }
    for (const Node& node : scene_.nodes) {
      bool finiteWorld = true;
      for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
          finiteWorld = finiteWorld && std::isfinite(node.restWorld[c][r]);
      if (!finiteWorld)
        fail("world transform is not finite",
             named("node", int(&node - scene_.nodes.data()), node.name));
    }
  }

  int materialIndex(int gltfMaterial) {
    if (gltfMaterial >= 0) return gltfMaterial;
    if (defaultMaterial_ < 0) {
      defaultMaterial_ = int(scene_.materials.size());
      Material m;
      m.name = "default";
      scene_.materials.push_back(m);
    }
    return defaultMaterial_;
  }

  // What the primitives of one mesh have between them. Every vertex gets each attribute that any
  // primitive has (filled in where its own lacks it), so the mesh's arrays stay parallel.
  struct MeshLayout {
    bool anyTangents = false, anyUv1 = false, anyNormalMap = false;
    // Skin and morph data: as many JOINTS_n sets as the primitive with most, the targets'
    // POSITION (and NORMAL where any primitive has it) deltas.
    size_t jointSets = 0, targets = 0;
    bool targetNormals = false;
  };

  // One primitive's vertices as they are appended: the first is at `base` in the mesh.
  struct PrimitiveVertices {
    const tinygltf::Primitive& p;
    const std::string& where;
    size_t vcount = 0;
    uint32_t base = 0;
    bool hasNormals = false;
  };

  MeshLayout meshLayout(const tinygltf::Mesh& mesh) {
    MeshLayout l;
    for (const auto& p : mesh.primitives) {
      // glTF: a primitive without NORMAL is shaded flat and its TANGENT ignored.
      l.anyTangents =
          l.anyTangents || (p.attributes.count("TANGENT") && p.attributes.count("NORMAL"));
      l.anyUv1 = l.anyUv1 || p.attributes.count("TEXCOORD_1");
      // A tangent frame is needed by normal maps, the coat's normal map and anisotropy.
      const Material& m = scene_.materials[size_t(materialIndex(p.material))];
      l.anyNormalMap = l.anyNormalMap || m.normalTexture.valid() ||
                       m.clearcoatNormalTexture.valid() || m.isAnisotropic();
    }
    for (const auto& p : mesh.primitives) {
      while (p.attributes.count("JOINTS_" + std::to_string(l.jointSets)) &&
             p.attributes.count("WEIGHTS_" + std::to_string(l.jointSets)))
        ++l.jointSets;
      l.targets = std::max(l.targets, p.targets.size());
      for (const auto& t : p.targets) l.targetNormals = l.targetNormals || t.count("NORMAL");
    }
    return l;
  }

  // Object-space triangles of one glTF mesh (all TRIANGLES primitives).
  TriangleMesh convertMesh(int meshIndex) {
    const auto& mesh = model_.meshes[size_t(meshIndex)];
    TriangleMesh out;
    out.name = mesh.name;
    const MeshLayout layout = meshLayout(mesh);
    std::vector<uint8_t> normalUvSet;   // per triangle: the uv set its tangents follow
    std::vector<uint8_t> givenTangent;  // per vertex: TANGENT from the file is used
    out.influences = int(4 * layout.jointSets);
    out.morphPositions.resize(layout.targets);
    out.morphNormals.resize(layout.targets);
    for (double w : mesh.weights) out.morphWeights.push_back(float(w));
    for (size_t pi = 0; pi < mesh.primitives.size(); ++pi)
      appendPrimitive(out, meshIndex, pi, layout, normalUvSet, givenTangent);
    // glTF asks for MikkTSpace tangents where a normal-mapped mesh has none: generated for
    // every vertex whose primitive gives none (or gives them without NORMAL).
    if (layout.anyNormalMap &&
        std::find(givenTangent.begin(), givenTangent.end(), uint8_t(0)) != givenTangent.end()) {
      const std::vector<glm::vec4> given = std::move(out.tangents);
      generateTangents(out, normalUvSet);
      for (size_t v = 0; v < given.size(); ++v)
        if (givenTangent[v]) out.tangents[v] = given[v];
    }
    return out;
  }

  // Appends primitive `pi` of the mesh to `out`, or skips it with a warning where it is no
  // triangles or has no positions.
  void appendPrimitive(TriangleMesh& out, int meshIndex, size_t pi, const MeshLayout& layout,
                       std::vector<uint8_t>& normalUvSet, std::vector<uint8_t>& givenTangent) {
    const auto& mesh = model_.meshes[size_t(meshIndex)];
    const auto& p = mesh.primitives[pi];
    const std::string where =
        named("mesh", meshIndex, mesh.name) + ", primitive " + std::to_string(pi);
    const int mode = p.mode < 0 ? TINYGLTF_MODE_TRIANGLES : p.mode;
    if (mode != TINYGLTF_MODE_TRIANGLES) {
      static const char* names[] = {"POINTS",    "LINES",          "LINE_LOOP",   "LINE_STRIP",
                                    "TRIANGLES", "TRIANGLE_STRIP", "TRIANGLE_FAN"};
      // One line per mode, however many primitives use it.
      if (skippedModes_.insert(mode).second)
        warn(std::string("skipping primitives with mode ") + names[mode] +
             ": only TRIANGLES are rendered (first: " + where + ")");
      return;
    }
    const auto pos = p.attributes.find("POSITION");
    if (pos == p.attributes.end()) {
      warn("skipping a primitive without POSITION (" + where + ")");
      return;
    }
    const std::vector<double> positions = readAccessor(model_, pos->second);
    PrimitiveVertices pv{p, where};
    pv.vcount = positions.size() / 3;
    for (double x : positions)
      if (!finite(x) || std::abs(x) > 3.0e38)
        fail("POSITION has a value that is not finite", where + ", POSITION");
    const std::vector<uint32_t> idx = readIndices(p, pv.vcount, where);
    pv.base = uint32_t(out.positions.size());
    if (uint64_t(pv.base) + pv.vcount > 0xffffffffull) fail("mesh has too many vertices", where);
    for (size_t v = 0; v < pv.vcount; ++v)
      out.positions.emplace_back(positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]);
    appendNormals(out, pv, idx);
    appendUvs(out, pv, layout.anyUv1);
    appendSkin(out, pv, layout.jointSets);
    appendMorphTargets(out, pv, layout);
    appendTangents(out, pv, layout.anyTangents, givenTangent);
    const uint32_t mat = uint32_t(materialIndex(p.material));
    for (uint32_t i : idx) out.indices.push_back(pv.base + i);
    out.materials.insert(out.materials.end(), idx.size() / 3, mat);
    normalUvSet.insert(normalUvSet.end(), idx.size() / 3,
                       uint8_t(tangentUvSet(scene_.materials[mat])));
  }

  // The primitive's indices (0, 1, 2 ... without an index accessor), whole triangles only.
  std::vector<uint32_t> readIndices(const tinygltf::Primitive& p, size_t vcount,
                                    const std::string& where) {
    std::vector<uint32_t> idx;
    if (p.indices >= 0) {
      const std::vector<double> raw = readAccessor(model_, p.indices);
      idx.reserve(raw.size());
      for (size_t i = 0; i < raw.size(); ++i) {
        if (raw[i] >= double(vcount))
          fail("index " + std::to_string(uint64_t(raw[i])) + " at position " + std::to_string(i) +
                   " is out of range (" + std::to_string(vcount) + " vertices)",
               where + ", indices accessor " + std::to_string(p.indices));
        idx.push_back(uint32_t(raw[i]));
      }
    } else {
      idx.resize(vcount);
      for (size_t i = 0; i < vcount; ++i) idx[i] = uint32_t(i);
    }
    if (idx.size() % 3 != 0) {
      warn("primitive has " + std::to_string(idx.size()) +
           " indices, not a multiple of 3: the rest is ignored (" + where + ")");
      idx.resize(idx.size() - idx.size() % 3);
    }
    return idx;
  }

  // Normals: given ones normalised, degenerate ones area-weighted from faces. Without NORMAL
  // the primitive is flat: zero normals, which every transform keeps zero, make the device
  // shade by the geometric normal of the triangle as it is then (deformed or not).
  void appendNormals(TriangleMesh& out, PrimitiveVertices& pv, const std::vector<uint32_t>& idx) {
    const auto normalAttr = pv.p.attributes.find("NORMAL");
    pv.hasNormals = normalAttr != pv.p.attributes.end();
    if (!pv.hasNormals) {
      out.normals.resize(out.positions.size(), glm::vec3(0.0f));
      return;
    }
    const uint32_t base = pv.base;
    std::vector<glm::vec3> faceNormals(pv.vcount, glm::vec3(0.0f));
    for (size_t t = 0; t + 2 < idx.size(); t += 3) {
      const glm::vec3 a = out.positions[base + idx[t]], b = out.positions[base + idx[t + 1]],
                      c = out.positions[base + idx[t + 2]];
      const glm::vec3 n = glm::cross(b - a, c - a);  // length = twice the area
      if (!std::isfinite(n.x + n.y + n.z)) continue;
      for (int k = 0; k < 3; ++k) faceNormals[idx[t + size_t(k)]] += n;
    }
    const std::vector<double> normals = readAccessor(model_, normalAttr->second);
    for (size_t v = 0; v < pv.vcount; ++v) {
      glm::vec3 n(normals[3 * v], normals[3 * v + 1], normals[3 * v + 2]);
      float len = glm::length(n);
      if (!(len > 1e-12f) || !std::isfinite(len)) {
        n = faceNormals[v];
        len = glm::length(n);
      }
      out.normals.push_back(len > 0.0f && std::isfinite(len) ? n / len
                                                             : glm::vec3(0.0f, 0.0f, 1.0f));
    }
  }

  // TEXCOORD_0 (zero where absent) and, where any primitive of the mesh has it, TEXCOORD_1.
  void appendUvs(TriangleMesh& out, const PrimitiveVertices& pv, bool anyUv1) {
    const auto& p = pv.p;
    if (const auto it = p.attributes.find("TEXCOORD_0"); it != p.attributes.end()) {
      const std::vector<double> uv = readAccessor(model_, it->second);
      for (size_t v = 0; v < pv.vcount; ++v) {
        if (!finite(uv[2 * v]) || !finite(uv[2 * v + 1]))
          fail("TEXCOORD_0 is not finite", pv.where + ", TEXCOORD_0");
        out.uvs.emplace_back(uv[2 * v], uv[2 * v + 1]);
      }
    } else {
      out.uvs.resize(out.positions.size(), glm::vec2(0.0f));
    }
    if (!anyUv1) return;
    std::vector<double> uv;
    if (const auto it = p.attributes.find("TEXCOORD_1"); it != p.attributes.end())
      uv = readAccessor(model_, it->second);
    for (size_t v = 0; v < pv.vcount; ++v) {
      if (uv.empty()) {
        out.uvs1.push_back(out.uvs[pv.base + v]);  // TEXCOORD_0 stands in
        continue;
      }
      if (!finite(uv[2 * v]) || !finite(uv[2 * v + 1]))
        fail("TEXCOORD_1 is not finite", pv.where + ", TEXCOORD_1");
      out.uvs1.emplace_back(uv[2 * v], uv[2 * v + 1]);
    }
  }

  // Joints and weights of `jointSets` sets per vertex (zero weights for sets it lacks).
  void appendSkin(TriangleMesh& out, const PrimitiveVertices& pv, size_t jointSets) {
    if (jointSets == 0) return;
    std::vector<std::vector<double>> js(jointSets), ws(jointSets);
    for (size_t set = 0; set < jointSets; ++set) {
      const auto j = pv.p.attributes.find("JOINTS_" + std::to_string(set));
      const auto w = pv.p.attributes.find("WEIGHTS_" + std::to_string(set));
      if (j != pv.p.attributes.end() && w != pv.p.attributes.end()) {
        js[set] = readAccessor(model_, j->second);
        ws[set] = readAccessor(model_, w->second);
      }
    }
    for (size_t v = 0; v < pv.vcount; ++v) {
      double sum = 0.0;
      const size_t first = out.jointWeights.size();
      for (size_t set = 0; set < jointSets; ++set)
        for (size_t c = 0; c < 4; ++c) {
          const bool have = !js[set].empty();
          const double w = have ? ws[set][4 * v + c] : 0.0;
          if (!finite(w) || w < 0.0)
            fail("WEIGHTS_" + std::to_string(set) + " has a negative or non-finite weight",
                 pv.where);
          out.joints.push_back(have ? uint32_t(js[set][4 * v + c]) : 0u);
          out.jointWeights.push_back(float(w));
          sum += w;
        }
      // The spec asks for weights that add to 1; normalise what is given.
      if (sum > 0.0)
        for (size_t k = first; k < out.jointWeights.size(); ++k)
          out.jointWeights[k] = float(out.jointWeights[k] / sum);
    }
  }

  // Position (and normal) deltas of every morph target of the mesh; zero where the primitive
  // lacks the target.
  void appendMorphTargets(TriangleMesh& out, const PrimitiveVertices& pv,
                          const MeshLayout& layout) {
    for (size_t ti = 0; ti < layout.targets; ++ti) {
      const auto* t = ti < pv.p.targets.size() ? &pv.p.targets[ti] : nullptr;
      std::vector<double> dp, dn;
      if (t && t->count("POSITION")) dp = readAccessor(model_, t->at("POSITION"));
      // NORMAL deltas of a flat primitive are ignored: its normals stay zero.
      if (t && t->count("NORMAL") && pv.hasNormals) dn = readAccessor(model_, t->at("NORMAL"));
      for (size_t v = 0; v < pv.vcount; ++v) {
        glm::vec3 d(0.0f), n(0.0f);
        if (!dp.empty()) d = glm::vec3(dp[3 * v], dp[3 * v + 1], dp[3 * v + 2]);
        if (!dn.empty()) n = glm::vec3(dn[3 * v], dn[3 * v + 1], dn[3 * v + 2]);
        if (!finite(d.x) || !finite(d.y) || !finite(d.z) || !finite(n.x) || !finite(n.y) ||
            !finite(n.z))
          fail("morph target " + std::to_string(ti) + " is not finite", pv.where);
        out.morphPositions[ti].push_back(d);
        if (layout.targetNormals) out.morphNormals[ti].push_back(n);
      }
    }
  }

  // TANGENT where the primitive has it with NORMAL (normalised, w = handedness sign), else
  // +X; `givenTangent` records which vertices' are the file's.
  void appendTangents(TriangleMesh& out, const PrimitiveVertices& pv, bool anyTangents,
                      std::vector<uint8_t>& givenTangent) {
    std::vector<double> tan;
    if (const auto it = pv.p.attributes.find("TANGENT");
        it != pv.p.attributes.end() && pv.hasNormals)
      tan = readAccessor(model_, it->second);
    givenTangent.insert(givenTangent.end(), pv.vcount, uint8_t(!tan.empty()));
    if (!anyTangents) return;
    for (size_t v = 0; v < pv.vcount; ++v) {
      glm::vec4 t(1.0f, 0.0f, 0.0f, 1.0f);
      if (!tan.empty()) {
        glm::vec3 xyz(tan[4 * v], tan[4 * v + 1], tan[4 * v + 2]);
        const float len = glm::length(xyz);
        if (len > 0.0f && std::isfinite(len))
          t = glm::vec4(xyz / len, tan[4 * v + 3] < 0.0 ? -1.0f : 1.0f);
      }
      out.tangents.push_back(t);
    }
  }

  // The uv set a material's generated tangents follow: its normal map's, else its coat normal
  // map's, else its anisotropy texture's, else TEXCOORD_0.
  static int tangentUvSet(const Material& m) {
    if (m.normalTexture.valid()) return m.normalTexture.texCoord;
    if (m.clearcoatNormalTexture.valid()) return m.clearcoatNormalTexture.texCoord;
    return m.anisotropyTexture.valid() ? m.anisotropyTexture.texCoord : 0;
  }

  const TriangleMesh& objectMesh(int meshIndex) {
    auto& slot = meshCache_[meshIndex];
    if (!slot) slot = convertMesh(meshIndex);
    return *slot;
  }

  // Appends a mesh to the SSG in world space.
  void flatten(const TriangleMesh& mesh, const glm::mat4& world) {
    TriangleMesh& ssg = scene_.staticMesh;
    const glm::mat3 linear(world);
    const float det = glm::determinant(linear);
    // Cofactor matrix = det * inverse-transpose: the normal matrix without dividing by det.
    const glm::mat3 cof = glm::transpose(glm::inverse(linear)) * det;
    const float sign = det < 0.0f ? -1.0f : 1.0f;
    const uint32_t base = uint32_t(ssg.positions.size());
    if (uint64_t(base) + mesh.positions.size() > 0xffffffffull) fail("scene has too many vertices");
    if (!mesh.uvs1.empty() && ssg.uvs1.size() < ssg.positions.size())
      ssg.uvs1 = ssg.uvs;  // earlier meshes had none: their TEXCOORD_0 stands in
    const bool tangents = !mesh.tangents.empty();
    if (tangents && ssg.tangents.size() < ssg.positions.size())
      ssg.tangents.resize(ssg.positions.size(), glm::vec4(1.0f, 0.0f, 0.0f, 1.0f));
    for (size_t v = 0; v < mesh.positions.size(); ++v) {
      ssg.positions.push_back(glm::vec3(world * glm::vec4(mesh.positions[v], 1.0f)));
      glm::vec3 n = sign * (cof * mesh.normals[v]);  // a flat primitive's zero stays zero
      const float len = glm::length(n);
      ssg.normals.push_back(len > 0.0f && std::isfinite(len) ? n / len : mesh.normals[v]);
      ssg.uvs.push_back(mesh.uvs[v]);
      if (!mesh.uvs1.empty())
        ssg.uvs1.push_back(mesh.uvs1[v]);
      else if (!ssg.uvs1.empty())
        ssg.uvs1.push_back(mesh.uvs[v]);
      if (tangents) {
        glm::vec3 t = linear * glm::vec3(mesh.tangents[v]);
        const float tl = glm::length(t);
        t = tl > 0.0f && std::isfinite(tl) ? t / tl : glm::vec3(mesh.tangents[v]);
        ssg.tangents.emplace_back(t, mesh.tangents[v].w * sign);
      } else if (!ssg.tangents.empty()) {
        ssg.tangents.emplace_back(1.0f, 0.0f, 0.0f, 1.0f);
      }
    }
    for (size_t t = 0; t < mesh.triangleCount(); ++t) {
      const uint32_t a = mesh.indices[3 * t], b = mesh.indices[3 * t + 1],
                     c = mesh.indices[3 * t + 2];
      ssg.indices.push_back(base + a);
      // A mirroring transform turns the winding around; swap to keep front faces in front.
      ssg.indices.push_back(base + (det < 0.0f ? c : b));
      ssg.indices.push_back(base + (det < 0.0f ? b : c));
    }
    ssg.materials.insert(ssg.materials.end(), mesh.materials.begin(), mesh.materials.end());
  }

  void buildMaterials() {
    for (size_t i = 0; i < model_.materials.size(); ++i) {
      const auto& src = model_.materials[i];
      Material m;
      m.name = src.name;
      const auto& pbr = src.pbrMetallicRoughness;
      m.baseColorFactor = glm::vec4(pbr.baseColorFactor[0], pbr.baseColorFactor[1],
                                    pbr.baseColorFactor[2], pbr.baseColorFactor[3]);
      m.metallicFactor = float(pbr.metallicFactor);
      m.roughnessFactor = float(pbr.roughnessFactor);
      m.emissiveFactor =
          glm::vec3(src.emissiveFactor[0], src.emissiveFactor[1], src.emissiveFactor[2]);
      m.alphaMode = src.alphaMode == "MASK"    ? AlphaMode::Mask
                    : src.alphaMode == "BLEND" ? AlphaMode::Blend
                                               : AlphaMode::Opaque;
      m.alphaCutoff = float(src.alphaCutoff);
      m.doubleSided = src.doubleSided;
      m.normalScale = float(src.normalTexture.scale);
      const std::string where = named("material", int(i), src.name);
      m.baseColorTexture =
          textureRef(pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord, true, where);
      readTransform(pbr.baseColorTexture.extensions, &m.baseColorTexture, where);
      m.metallicRoughnessTexture = textureRef(pbr.metallicRoughnessTexture.index,
                                              pbr.metallicRoughnessTexture.texCoord, false, where);
      readTransform(pbr.metallicRoughnessTexture.extensions, &m.metallicRoughnessTexture, where);
      m.emissiveTexture =
          textureRef(src.emissiveTexture.index, src.emissiveTexture.texCoord, true, where);
      readTransform(src.emissiveTexture.extensions, &m.emissiveTexture, where);
      m.normalTexture =
          textureRef(src.normalTexture.index, src.normalTexture.texCoord, false, where);
      readTransform(src.normalTexture.extensions, &m.normalTexture, where);
      if (const Value* e = extension(src.extensions, "KHR_materials_emissive_strength"))
        if (const Value* s = member(*e, "emissiveStrength"))
          m.emissiveStrength = float(s->GetNumberAsDouble());
      if (const Value* e = extension(src.extensions, "KHR_materials_transmission")) {
        if (const Value* s = member(*e, "transmissionFactor"))
          m.transmission = float(s->GetNumberAsDouble());
        m.transmissionTexture = extensionTexture(*e, "transmissionTexture", false, where);
      }
      if (const Value* e = extension(src.extensions, "KHR_materials_ior"))
        if (const Value* s = member(*e, "ior")) m.ior = float(s->GetNumberAsDouble());
      if (const Value* e = extension(src.extensions, "KHR_materials_specular")) {
        if (const Value* s = member(*e, "specularFactor"))
          m.specular = float(s->GetNumberAsDouble());
        if (const Value* c = member(*e, "specularColorFactor"))
          m.specularColor = glm::vec3(c->Get(0).GetNumberAsDouble(), c->Get(1).GetNumberAsDouble(),
                                      c->Get(2).GetNumberAsDouble());
        m.specularTexture = extensionTexture(*e, "specularTexture", false, where);
        m.specularColorTexture = extensionTexture(*e, "specularColorTexture", true, where);
      }
      if (const Value* e = extension(src.extensions, "KHR_materials_volume")) {
        if (const Value* s = member(*e, "thicknessFactor"))
          m.thickness = float(s->GetNumberAsDouble());
        if (const Value* s = member(*e, "attenuationDistance"))
          m.attenuationDistance = float(s->GetNumberAsDouble());
        if (const Value* c = member(*e, "attenuationColor"))
          m.attenuationColor =
              glm::vec3(c->Get(0).GetNumberAsDouble(), c->Get(1).GetNumberAsDouble(),
                        c->Get(2).GetNumberAsDouble());
        warnTextures(*e, {"thicknessTexture"}, where);
      }
      if (const Value* e = extension(src.extensions, "KHR_materials_clearcoat")) {
        if (const Value* s = member(*e, "clearcoatFactor"))
          m.clearcoat = float(s->GetNumberAsDouble());
        if (const Value* s = member(*e, "clearcoatRoughnessFactor"))
          m.clearcoatRoughness = float(s->GetNumberAsDouble());
        m.clearcoatTexture = extensionTexture(*e, "clearcoatTexture", false, where);
        m.clearcoatRoughnessTexture =
            extensionTexture(*e, "clearcoatRoughnessTexture", false, where);
        m.clearcoatNormalTexture = extensionTexture(*e, "clearcoatNormalTexture", false, where);
        if (const Value* t = member(*e, "clearcoatNormalTexture"))
          if (const Value* scale = member(*t, "scale"))
            m.clearcoatNormalScale = float(scale->GetNumberAsDouble());
      }
      if (const Value* e = extension(src.extensions, "KHR_materials_sheen")) {
        if (const Value* c = member(*e, "sheenColorFactor"))
          m.sheenColor = glm::vec3(c->Get(0).GetNumberAsDouble(), c->Get(1).GetNumberAsDouble(),
                                   c->Get(2).GetNumberAsDouble());
        if (const Value* r = member(*e, "sheenRoughnessFactor"))
          m.sheenRoughness = float(r->GetNumberAsDouble());
        m.sheenColorTexture = extensionTexture(*e, "sheenColorTexture", true, where);
        m.sheenRoughnessTexture = extensionTexture(*e, "sheenRoughnessTexture", false, where);
      }
      if (const Value* e = extension(src.extensions, "KHR_materials_anisotropy")) {
        if (const Value* s = member(*e, "anisotropyStrength"))
          m.anisotropyStrength = float(s->GetNumberAsDouble());
        if (const Value* r = member(*e, "anisotropyRotation"))
          m.anisotropyRotation = float(r->GetNumberAsDouble());
        m.anisotropyTexture = extensionTexture(*e, "anisotropyTexture", false, where);
      }
      scene_.materials.push_back(m);
    }
  }

  // --emit-base-color: the materials it names emit their base colour (factor and texture, with
  // the texture's uv set and transform) at --emit-strength, in place of their own emission.
  void emitBaseColors() {
    const std::string& list = doc_.options.emitBaseColor;
    if (list.empty()) return;
    const size_t count = model_.materials.size();
    std::vector<bool> chosen(count, false);
    for (size_t start = 0; start <= list.size();) {
      const size_t comma = std::min(list.find(',', start), list.size());
      const std::string item = list.substr(start, comma - start);
      start = comma + 1;
      if (!selectMaterials(item, &chosen))
        fail("--emit-base-color " + list + ": no material " + item + " (" + materialNames() + ")");
    }
    for (size_t i = 0; i < count; ++i) {
      if (!chosen[i]) continue;
      Material& m = scene_.materials[i];
      m.emissiveFactor = glm::vec3(m.baseColorFactor);
      m.emissiveTexture = m.baseColorTexture;
      m.emissiveStrength = doc_.options.emitStrength;
    }
  }

  // Marks the materials `item` names: a name, an index or a range A-B of indices.
  bool selectMaterials(const std::string& item, std::vector<bool>* chosen) const {
    bool any = false;
    for (size_t i = 0; i < chosen->size(); ++i)
      if (!item.empty() && (model_.materials[i].name == item || std::to_string(i) == item))
        (*chosen)[i] = any = true;
    if (any) return true;
    unsigned long a = 0, b = 0;
    int used = 0;
    if (std::sscanf(item.c_str(), "%lu-%lu%n", &a, &b, &used) != 2 || size_t(used) != item.size() ||
        a > b || b >= chosen->size())
      return false;
    for (size_t i = a; i <= b; ++i) (*chosen)[i] = true;
    return true;
  }

  // "the scene has N materials: 0 (name), 1, ..." (the first dozen).
  std::string materialNames() const {
    const size_t n = model_.materials.size();
    if (n == 0) return "the scene has no materials";
    std::string names =
        "the scene has " + std::to_string(n) + (n == 1 ? " material: " : " materials: ");
    for (size_t i = 0; i < n && i < 12; ++i)
      names += (i ? ", " : "") + std::to_string(i) +
               (model_.materials[i].name.empty() ? "" : " (" + model_.materials[i].name + ")");
    return names + (n > 12 ? ", ..." : "");
  }

  // The uv set a texture reads: TEXCOORD_0 or TEXCOORD_1 (others warned of, TEXCOORD_0 read).
  int uvSet(int texCoord, const std::string& where) {
    if (texCoord == 0 || texCoord == 1) return texCoord;
    warn("only TEXCOORD_0 and TEXCOORD_1 are supported; texCoord " + std::to_string(texCoord) +
         " reads TEXCOORD_0 (" + where + ")");
    return 0;
  }

  // Textures of a material extension that only its factors are applied of: one warning each.
  void warnTextures(const Value& ext, std::initializer_list<const char*> names,
                    const std::string& where) {
    for (const char* n : names)
      if (member(ext, n))
        warn(std::string(n) + " is not applied, only the extension's factors (" + where + ")");
  }

  // A texture's KHR_texture_transform (validated in checkMaterials), if it has one; its
  // texCoord overrides the texture's.
  void readTransform(const tinygltf::ExtensionMap& extensions, TextureRef* ref,
                     const std::string& where) {
    if (const Value* t = extension(extensions, "KHR_texture_transform"))
      readTransformValue(*t, ref, where);
  }

  // KHR_texture_transform's members, checked as they are read (the extensions' textures are
  // not among those checkMaterials validates).
  void readTransformValue(const Value& t, TextureRef* ref, const std::string& where) {
    auto pair = [&](const char* key, glm::vec2* out) {
      const Value* v = member(t, key);
      if (!v) return;
      bool ok = v->IsArray() && v->ArrayLen() == 2;
      for (int k = 0; ok && k < 2; ++k)
        ok = v->Get(k).IsNumber() && finite(v->Get(k).GetNumberAsDouble());
      if (!ok)
        fail(std::string("KHR_texture_transform ") + key + " must be 2 finite numbers", where);
      *out = glm::vec2(v->Get(0).GetNumberAsDouble(), v->Get(1).GetNumberAsDouble());
    };
    if (const Value* v = member(t, "texCoord")) {
      if (!v->IsInt() || v->GetNumberAsInt() < 0)
        fail("KHR_texture_transform texCoord must be a non-negative integer", where);
      ref->texCoord = uvSet(v->GetNumberAsInt(), where);
    }
    pair("offset", &ref->offset);
    pair("scale", &ref->scale);
    if (const Value* v = member(t, "rotation")) {
      if (!v->IsNumber() || !finite(v->GetNumberAsDouble()))
        fail("KHR_texture_transform rotation must be a finite number", where);
      ref->rotation = float(v->GetNumberAsDouble());
    }
  }

  // A texture of a material extension (a textureInfo inside the extension's object).
  TextureRef extensionTexture(const Value& ext, const char* name, bool srgb,
                              const std::string& where) {
    const Value* t = member(ext, name);
    if (!t) return TextureRef{};
    const std::string twhere = where + ", " + name;
    const Value* index = member(*t, "index");
    if (!t->IsObject() || !index || !index->IsInt())
      fail(std::string(name) + " needs an integer index", where);
    checkTextureInfo(doc_, index->GetNumberAsInt(), name, where);
    int texCoord = 0;
    if (const Value* c = member(*t, "texCoord")) {
      if (!c->IsInt() || c->GetNumberAsInt() < 0)
        fail(std::string(name) + " texCoord must be a non-negative integer", where);
      texCoord = c->GetNumberAsInt();
    }
    TextureRef ref = textureRef(index->GetNumberAsInt(), texCoord, srgb, twhere);
    if (const Value* ex = member(*t, "extensions"))
      if (const Value* tt = member(*ex, "KHR_texture_transform"))
        readTransformValue(*tt, &ref, twhere);
    return ref;
  }

  // A scene texture for (glTF texture, colour space), decoded once.
  TextureRef textureRef(int gltfTexture, int texCoord, bool srgb, const std::string& where) {
    TextureRef ref;
    if (gltfTexture < 0) return ref;
    ref.texCoord = uvSet(texCoord, where);
    const auto key = std::make_pair(gltfTexture, srgb);
    if (const auto it = textureIndex_.find(key); it != textureIndex_.end()) {
      ref.texture = it->second;
      return ref;
    }
    const auto& t = model_.textures[size_t(gltfTexture)];
    const std::string twhere = named("texture", gltfTexture, t.name) + ", " + where;
    if (t.source < 0) {
      warn("texture has no image we can read; it is ignored (" + twhere + ")");
      return ref;
    }
    const auto& im = model_.images[size_t(t.source)];
    const std::string iwhere = named("image", t.source, im.name) + ", " + twhere;
    std::vector<uint8_t> encoded;
    if (im.bufferView >= 0) {
      const auto& v = model_.bufferViews[size_t(im.bufferView)];  // range checked already
      const uint8_t* p = model_.buffers[size_t(v.buffer)].data.data() + v.byteOffset;
      encoded.assign(p, p + v.byteLength);
    } else if (const auto it = doc_.images.encoded.find(t.source);
               it != doc_.images.encoded.end()) {
      encoded = it->second;
    } else {
      fail("cannot read image \"" + im.uri + "\"", iwhere);
    }
    DecodedImage img;
    std::string why;
    if (!decodeImageRgba8(encoded, &img, &why)) fail("cannot decode image: " + why, iwhere);
    Texture tex;
    tex.name = !im.name.empty() ? im.name : im.uri.rfind("data:", 0) == 0 ? std::string() : im.uri;
    tex.width = img.width;
    tex.height = img.height;
    tex.rgba8 = std::move(img.rgba8);
    tex.srgb = srgb;
    if (t.sampler >= 0) {
      const auto& s = model_.samplers[size_t(t.sampler)];
      auto wrap = [](int w) {
        return w == TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE     ? TextureWrap::ClampToEdge
               : w == TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT ? TextureWrap::MirroredRepeat
                                                            : TextureWrap::Repeat;
      };
      tex.wrapS = wrap(s.wrapS);
      tex.wrapT = wrap(s.wrapT);
      tex.nearest = s.magFilter == TINYGLTF_TEXTURE_FILTER_NEAREST;
    }
    ref.texture = int(scene_.textures.size());
    scene_.textures.push_back(std::move(tex));
    textureIndex_[key] = ref.texture;
    return ref;
  }

  void buildSkins() {
    for (size_t si = 0; si < model_.skins.size(); ++si) {
      const auto& s = model_.skins[si];
      Skin k;
      k.name = s.name;
      k.joints = s.joints;
      k.inverseBind.assign(s.joints.size(), glm::mat4(1.0f));
      if (s.inverseBindMatrices >= 0) {
        const std::vector<double> m = readAccessor(model_, s.inverseBindMatrices);
        for (size_t j = 0; j < s.joints.size(); ++j) {
          const std::vector<double> one(m.begin() + long(16 * j), m.begin() + long(16 * j + 16));
          if (!allFinite(one))
            fail("inverse bind matrix " + std::to_string(j) + " is not finite",
                 named("skin", int(si), s.name));
          k.inverseBind[j] = toMat4(one);
        }
      }
      scene_.skins.push_back(k);
    }
  }

  // A deforming mesh (skinned, or morphed by animated weights): a dynamic mesh of this node
  // alone, deformed each frame (Scene::deformMesh).
  void addDeforming(size_t node, const TriangleMesh& mesh, int skin) {
    const std::string where = named("node", int(node), scene_.nodes[node].name);
    if (skin >= 0) {
      const size_t n = scene_.skins[size_t(skin)].joints.size();
      for (uint32_t j : mesh.joints)
        if (j >= n)
          fail(
              "JOINTS refer to joint " + std::to_string(j) + " of a skin with " + std::to_string(n),
              where);
    }
    const uint32_t index = uint32_t(scene_.dynamicMeshes.size());
    scene_.dynamicMeshes.push_back(mesh);
    scene_.dynamicMeshBounds.push_back(mesh.bounds());
    Deformer d;
    d.skin = skin;
    d.node = int(node);
    scene_.deformers.push_back(d);
    scene_.instances.push_back({index, int(node), scene_.nodes[node].name});
  }

  void buildDefaultCamera() {
    CameraDef c;
    c.name = "default";
    c.isDefault = true;
    c.yfov = float(40.0 * kPi / 180.0);
    const Bounds& b = scene_.bounds;
    glm::vec3 centre(0.0f);
    float radius = 1.0f;
    if (!b.empty()) {
      centre = b.centre();
      radius = std::max(0.5f * glm::length(b.extent()), 1e-3f);
    }
    // Far enough that the bounding sphere fits the vertical field of view.
    const float distance = radius / std::sin(0.5f * c.yfov);
    c.znear = std::max(distance - radius, distance * 1e-3f) * 0.5f;
    c.defaultWorld = glm::mat4(1.0f);
    c.defaultWorld[3] = glm::vec4(centre + glm::vec3(0.0f, 0.0f, distance), 1.0f);
    scene_.cameras.push_back(c);
  }

  void build() {
    scene_.path = doc_.path;
    buildNodes();
    buildMaterials();
    emitBaseColors();
    meshCache_.clear();
    buildSkins();
    std::map<int, uint32_t> dynamicIndex;  // glTF mesh -> dynamic mesh
    std::set<int> staticMeshes;
    for (size_t i = 0; i < scene_.nodes.size(); ++i) {
      const Node& node = scene_.nodes[i];
      if (!node.inScene) continue;
      const auto& src = model_.nodes[i];
      if (node.mesh >= 0) {
        const TriangleMesh& shared = objectMesh(node.mesh);
        const bool skinned = src.skin >= 0 && shared.influences > 0;
        const bool morphing = !shared.morphPositions.empty() && node.weightsAnimated;
        if (skinned || morphing) {
          addDeforming(i, shared, skinned ? src.skin : -1);
          continue;
        }
        // Morph targets at fixed weights: applied once; the mesh is then this node's own.
        std::optional<TriangleMesh> baked;
        if (!shared.morphPositions.empty()) {
          baked = shared;
          const std::vector<float> w = scene_.morphWeightsAt(int(i), shared, 0.0);
          for (size_t k = 0; k < w.size(); ++k)
            for (size_t v = 0; v < baked->vertexCount(); ++v) {
              baked->positions[v] += w[k] * shared.morphPositions[k][v];
              if (!shared.morphNormals[k].empty())
                baked->normals[v] += w[k] * shared.morphNormals[k][v];
            }
          for (glm::vec3& n : baked->normals) {
            const float l = glm::length(n);
            if (l > 0.0f && std::isfinite(l)) n /= l;
          }
          baked->morphPositions.clear();
          baked->morphNormals.clear();
        }
        const TriangleMesh& mesh = baked ? *baked : shared;
        if (node.dynamic) {
          const auto it = baked ? dynamicIndex.end() : dynamicIndex.find(node.mesh);
          uint32_t index = it != dynamicIndex.end() ? it->second : 0u;
          if (it == dynamicIndex.end()) {
            index = uint32_t(scene_.dynamicMeshes.size());
            if (!baked) dynamicIndex.emplace(node.mesh, index);
            scene_.dynamicMeshes.push_back(mesh);
            scene_.dynamicMeshBounds.push_back(mesh.bounds());
            scene_.deformers.emplace_back();
          }
          scene_.instances.push_back({index, int(i), node.name});
        } else {
          flatten(mesh, node.restWorld);
          scene_.staticTriangleNodes.insert(scene_.staticTriangleNodes.end(), mesh.triangleCount(),
                                            uint32_t(i));
          if (staticMeshes.insert(node.mesh).second)
            scene_.staticMeshTriangles += mesh.triangleCount();
        }
      }
      const int light = nodeLight(src);
      if (light >= 0) {
        const auto& l = model_.lights[size_t(light)];
        PunctualLightDef d;
        d.name = l.name;
        d.type = l.type == "spot"          ? LightType::Spot
                 : l.type == "directional" ? LightType::Directional
                                           : LightType::Point;
        if (l.color.size() == 3) d.color = glm::vec3(l.color[0], l.color[1], l.color[2]);
        d.intensity = float(l.intensity);
        d.range = float(l.range);
        d.innerConeAngle = float(l.spot.innerConeAngle);
        d.outerConeAngle = float(l.spot.outerConeAngle);
        d.node = int(i);
        d.dynamic = node.dynamic;
        scene_.lights.push_back(d);
      }
      if (node.camera >= 0) {
        const auto& c = model_.cameras[size_t(node.camera)];
        CameraDef d;
        d.name = c.name;
        d.perspective = c.type == "perspective";
        if (d.perspective) {
          d.yfov = float(c.perspective.yfov);
          d.aspectRatio = float(c.perspective.aspectRatio);
          d.znear = float(c.perspective.znear);
          d.zfar = float(c.perspective.zfar);
        } else {
          d.xmag = float(c.orthographic.xmag);
          d.ymag = float(c.orthographic.ymag);
          d.znear = float(c.orthographic.znear);
          d.zfar = float(c.orthographic.zfar);
        }
        d.node = int(i);
        d.dynamic = node.dynamic;
        scene_.cameras.push_back(d);
      }
    }
    scene_.bounds = scene_.sceneBounds();
    if (scene_.cameras.empty()) buildDefaultCamera();
  }

  const std::vector<int> parents_;
  Scene scene_;
  std::map<int, std::optional<TriangleMesh>> meshCache_;
  std::map<std::pair<int, bool>, int> textureIndex_;
  int defaultMaterial_ = -1;
  std::set<int> skippedModes_;
};

// A parsed document validated, then converted.
Scene load(Document& doc) {
  Validated validated = validate(doc);
  Scene scene = Converter(doc, std::move(validated)).convert();
  if (doc.options.digestInputs) scene.inputDigest = doc.inputs.hex();
  scene.inputFiles = doc.inputFiles;
  return scene;
}

}  // namespace

}  // namespace gltf

bool isSupportedExtension(const std::string& name) {
  static const std::set<std::string> supported = {"KHR_materials_emissive_strength",
                                                  "KHR_materials_transmission",
                                                  "KHR_materials_ior",
                                                  "KHR_materials_specular",
                                                  "KHR_materials_clearcoat",
                                                  "KHR_materials_volume",
                                                  "KHR_materials_sheen",
                                                  "KHR_materials_anisotropy",
                                                  "KHR_texture_transform",
                                                  "KHR_lights_punctual"};
  return supported.count(name) > 0;
}

Scene loadScene(const std::string& path, const LoadOptions& options) {
  gltf::Document doc(path, options);
  gltf::parseFile(doc);
  return gltf::load(doc);
}

Scene loadSceneFromMemory(const std::string& bytes, const std::string& path,
                          const LoadOptions& options) {
  gltf::Document doc(path, options);
  gltf::parseBytes(doc, bytes);
  return gltf::load(doc);
}

}  // namespace pr
