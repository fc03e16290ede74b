#include "scene/gltf_validate.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>

#include "scene/gltf_accessors.h"
#include "scene/gltf_animation.h"

namespace pr::gltf {

namespace {

// The largest radiance a material may emit (README "What pathreuse reads").
constexpr double kMaxEmission = 1e20;

// What an attribute or animation accessor may be.
struct AccessorRule {
  std::vector<int> types;
  std::vector<int> componentTypes;
  bool normalizedIntegers = false;  // integer component types must be normalized
};

// The checks, in the order that decides which problem is reported first.
class Validator : Stage {
 public:
  explicit Validator(Document& doc) : Stage(doc) {}

  Validated run() {
    checkAssetAndExtensions();
    checkBuffersAndViews();
    checkAccessors();
    checkTexturesAndImages();
    checkMaterials();
    checkCamerasAndLights();
    checkMeshes();
    checkNodesAndScenes();
    checkSkins();
    checkAnimations();
    return {std::move(parents_), std::move(animations_)};
  }

 private:
  void checkAssetAndExtensions() {
    const std::string& v = model_.asset.version;
    const auto dot = v.find('.');
    if (dot == std::string::npos || v.substr(0, dot) != "2")
      fail("unsupported glTF version \"" + v + "\" (asset.version; only 2.x is supported)");
    const std::string& minV = model_.asset.minVersion;
    if (!minV.empty() && minV != "2.0")
      fail("requires glTF version " + minV + " (asset.minVersion; only 2.0 is supported)");
    for (const std::string& e : model_.extensionsRequired)
      if (!isSupportedExtension(e))
        fail("requires extension " + e + ", which is not supported", "extensionsRequired");
    // Optional ones: named once each, and rendered without what they add.
    for (const std::string& e : model_.extensionsUsed)
      if (!isSupportedExtension(e))
        warn("extension " + e + " is not supported; what it adds is ignored (extensionsUsed)");
  }

  // --- buffers, views, accessors ---------------------------------------------------------------

  void checkBuffersAndViews() {
    for (size_t i = 0; i < model_.buffers.size(); ++i) {
      const auto& b = model_.buffers[i];
      if (b.data.empty()) fail("buffer has no data", named("buffer", int(i), b.name));
    }
    for (size_t i = 0; i < model_.bufferViews.size(); ++i) {
      const auto& v = model_.bufferViews[i];
      const std::string where = named("bufferView", int(i), v.name);
      if (v.buffer < 0 || size_t(v.buffer) >= model_.buffers.size())
        fail("refers to buffer " + std::to_string(v.buffer) + ", which does not exist", where);
      if (v.byteLength == 0) fail("byteLength is 0", where);
      const size_t size = model_.buffers[size_t(v.buffer)].data.size();
      if (!fits(v.byteOffset, v.byteLength, 1, size))
        fail("bytes " + std::to_string(v.byteOffset) + ".." +
                 std::to_string(v.byteOffset + v.byteLength) + " lie past the end of buffer " +
                 std::to_string(v.buffer) + " (" + std::to_string(size) + " bytes)",
             where);
      if (v.byteStride != 0 && (v.byteStride < 4 || v.byteStride > 252 || v.byteStride % 4 != 0))
        fail("byteStride " + std::to_string(v.byteStride) + " is not a multiple of 4 in 4..252",
             where);
    }
  }

  // Checks accessor `index` once; `where` names its use for the message.
  void checkAccessor(int index, const std::string& where) {
    if (index < 0 || size_t(index) >= model_.accessors.size())
      fail("accessor " + std::to_string(index) + " does not exist", where);
    if (accessorChecked_.count(index)) return;
    const auto& a = model_.accessors[size_t(index)];
    const std::string self = named("accessor", index, a.name);
    const std::string at = where.empty() ? self : where;
    const std::string who = where.empty() ? "" : self + " ";
    const size_t cs = componentSize(a.componentType), nc = componentCount(a.type);
    if (cs == 0) fail(who + "has invalid componentType " + std::to_string(a.componentType), at);
    if (nc == 0) fail(who + "has invalid type", at);
    if (a.count == 0) fail(who + "has count 0", at);
    if (a.normalized && (a.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT ||
                         a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT))
      fail(who + "is normalized but its components are " + componentName(a.componentType), at);
    const size_t elem = cs * nc;
    if (a.bufferView >= 0) {
      if (size_t(a.bufferView) >= model_.bufferViews.size())
        fail(
            who + "refers to bufferView " + std::to_string(a.bufferView) + ", which does not exist",
            at);
      const auto& v = model_.bufferViews[size_t(a.bufferView)];
      size_t stride = elem;
      if (v.byteStride != 0) {
        stride = v.byteStride;
        if (stride < elem || stride % cs != 0)
          fail(who + "has byteStride " + std::to_string(stride) + ", which does not suit its " +
                   std::to_string(elem) + "-byte elements (bufferView " +
                   std::to_string(a.bufferView) + ")",
               at);
      }
      if (!fits(a.byteOffset + elem, stride, a.count - 1, v.byteLength) ||
          a.byteOffset > v.byteLength)
        fail(self + " reads past the end of bufferView " + std::to_string(a.bufferView), where);
    }
    // No buffer view and no sparse data reads as zeros, as the specification says.
    if (a.sparse.isSparse) checkSparse(index, at);
    accessorChecked_.insert(index);
  }

  void checkSparse(int index, const std::string& at) {
    const auto& a = model_.accessors[size_t(index)];
    const auto& sp = a.sparse;
    const std::string self = "sparse accessor " + std::to_string(index);
    if (sp.count <= 0 || size_t(sp.count) > a.count)
      fail(self + " has sparse count " + std::to_string(sp.count) + " outside 1.." +
               std::to_string(a.count),
           at);
    const size_t is = componentSize(sp.indices.componentType);
    if (is == 0 || sp.indices.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT ||
        sp.indices.componentType == TINYGLTF_COMPONENT_TYPE_BYTE ||
        sp.indices.componentType == TINYGLTF_COMPONENT_TYPE_SHORT)
      fail(self + " has invalid sparse index componentType", at);
    auto view = [&](int bv, int offset, size_t bytes, const char* what) {
      if (bv < 0 || size_t(bv) >= model_.bufferViews.size())
        fail(self + " refers to " + what + " bufferView " + std::to_string(bv) +
                 ", which does not exist",
             at);
      if (offset < 0) fail(self + " has a negative " + what + " byteOffset", at);
      const auto& v = model_.bufferViews[size_t(bv)];
      if (v.byteStride != 0)
        fail(self + " " + what + " bufferView " + std::to_string(bv) + " has a byteStride", at);
      if (!fits(size_t(offset), bytes, 1, v.byteLength))
        fail(self + " " + what + " read past the end of bufferView " + std::to_string(bv), at);
    };
    view(sp.indices.bufferView, sp.indices.byteOffset, is * size_t(sp.count), "indices");
    view(sp.values.bufferView, sp.values.byteOffset,
         componentSize(a.componentType) * componentCount(a.type) * size_t(sp.count), "values");
    // Indices strictly increasing and in range.
    const auto& v = model_.bufferViews[size_t(sp.indices.bufferView)];
    const uint8_t* p =
        model_.buffers[size_t(v.buffer)].data.data() + v.byteOffset + size_t(sp.indices.byteOffset);
    double prev = -1.0;
    for (int i = 0; i < sp.count; ++i) {
      const double k = readComponent(p + size_t(i) * is, sp.indices.componentType, false);
      if (k <= prev || k >= double(a.count))
        fail(self + " has sparse index " + std::to_string(uint64_t(k)) +
                 " out of order or out of range",
             at);
      prev = k;
    }
  }

  void checkAccessors() {
    for (size_t i = 0; i < model_.accessors.size(); ++i) checkAccessor(int(i), "");
  }

  void checkRule(int index, const AccessorRule& rule, const std::string& where) {
    checkAccessor(index, where);
    const auto& a = model_.accessors[size_t(index)];
    const bool typeOk = std::find(rule.types.begin(), rule.types.end(), a.type) != rule.types.end();
    const bool compOk = std::find(rule.componentTypes.begin(), rule.componentTypes.end(),
                                  a.componentType) != rule.componentTypes.end();
    const bool normOk = !rule.normalizedIntegers ||
                        a.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT || a.normalized;
    if (!typeOk || !compOk || !normOk)
      fail("accessor " + std::to_string(index) + " is " + (a.normalized ? "normalized " : "") +
               typeName(a.type) + " " + componentName(a.componentType) +
               ", which is not allowed here",
           where);
  }

  // --- textures, materials ---------------------------------------------------------------------

  void checkTexturesAndImages() {
    for (size_t i = 0; i < model_.images.size(); ++i) {
      const auto& im = model_.images[i];
      const std::string where = named("image", int(i), im.name);
      if (im.bufferView >= 0) {
        if (size_t(im.bufferView) >= model_.bufferViews.size())
          fail("refers to bufferView " + std::to_string(im.bufferView) + ", which does not exist",
               where);
      } else if (im.uri.empty() && !doc_.images.encoded.count(int(i))) {
        fail("has neither uri nor bufferView", where);
      }
    }
    for (size_t i = 0; i < model_.samplers.size(); ++i) {
      const auto& s = model_.samplers[i];
      for (int w : {s.wrapS, s.wrapT})
        if (w != TINYGLTF_TEXTURE_WRAP_REPEAT && w != TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE &&
            w != TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT)
          fail("invalid wrap mode " + std::to_string(w), named("sampler", int(i), s.name));
    }
    std::set<int> used;  // textures that materials use
    for (const auto& m : model_.materials)
      for (int t : {m.pbrMetallicRoughness.baseColorTexture.index,
                    m.pbrMetallicRoughness.metallicRoughnessTexture.index, m.emissiveTexture.index,
                    m.normalTexture.index, m.occlusionTexture.index})
        used.insert(t);
    for (size_t i = 0; i < model_.textures.size(); ++i) {
      auto& t = model_.textures[i];
      const std::string where = named("texture", int(i), t.name);
      std::string problem;
      if (t.source >= 0 && size_t(t.source) >= model_.images.size())
        problem = "refers to image " + std::to_string(t.source) + ", which does not exist";
      if (t.sampler >= 0 && size_t(t.sampler) >= model_.samplers.size())
        problem = "refers to sampler " + std::to_string(t.sampler) + ", which does not exist";
      if (problem.empty()) continue;
      // Real exporters leave dangling unused textures behind (cornell-nvpro does): harmless.
      if (used.count(int(i))) fail(problem, where);
      warn(problem + "; the texture is unused and ignored (" + where + ")");
      t.source = -1;
      t.sampler = -1;
    }
  }

  void checkFactor(double v, double lo, double hi, const std::string& what,
                   const std::string& where) {
    if (!finite(v) || v < lo || v > hi)
      fail(what + " " + std::to_string(v) + " is outside " + std::to_string(lo) + ".." +
               std::to_string(hi),
           where);
  }

  // The radiance a material emits, emissiveFactor x emissiveStrength, stays where the lights'
  // power sums (radiance x area x pi, summed) are finite in float: at most kMaxEmission.
  void checkEmission(const tinygltf::Material& m, const std::string& where) {
    double strength = 1.0;
    if (const Value* e = extension(m.extensions, "KHR_materials_emissive_strength"))
      if (const Value* s = member(*e, "emissiveStrength")) {
        if (!s->IsNumber() || !finite(s->GetNumberAsDouble()) || s->GetNumberAsDouble() < 0.0)
          fail("KHR_materials_emissive_strength emissiveStrength must be a number >= 0", where);
        strength = s->GetNumberAsDouble();
      }
    double largest = 0.0;
    for (double c : m.emissiveFactor) largest = std::max(largest, c);
    const double radiance = largest * strength;
    if (!finite(radiance) || radiance > kMaxEmission) {
      char text[96];
      std::snprintf(text, sizeof text, "%.3g is above %.0e", radiance, kMaxEmission);
      fail(std::string("emitted radiance (emissiveFactor x emissiveStrength) ") + text, where);
    }
  }

  void checkMaterials() {
    for (size_t i = 0; i < model_.materials.size(); ++i) {
      const auto& m = model_.materials[i];
      const std::string where = named("material", int(i), m.name);
      const auto& pbr = m.pbrMetallicRoughness;
      if (pbr.baseColorFactor.size() != 4) fail("baseColorFactor must have 4 numbers", where);
      for (double c : pbr.baseColorFactor)
        checkFactor(c, 0.0, 1.0, "baseColorFactor component", where);
      checkFactor(pbr.metallicFactor, 0.0, 1.0, "metallicFactor", where);
      checkFactor(pbr.roughnessFactor, 0.0, 1.0, "roughnessFactor", where);
      if (m.emissiveFactor.size() != 3) fail("emissiveFactor must have 3 numbers", where);
      // Above 1 is against the spec but common (exporters predating emissive_strength): allowed.
      for (double c : m.emissiveFactor)
        checkFactor(c, 0.0, 3.0e38, "emissiveFactor component", where);
      if (m.alphaMode != "OPAQUE" && m.alphaMode != "MASK" && m.alphaMode != "BLEND")
        fail("unknown alphaMode \"" + m.alphaMode + "\"", where);
      if (!finite(m.alphaCutoff) || m.alphaCutoff < 0.0) fail("alphaCutoff must be >= 0", where);
      checkTextureInfo(doc_, pbr.baseColorTexture.index, "baseColorTexture", where);
      checkTextureInfo(doc_, pbr.metallicRoughnessTexture.index, "metallicRoughnessTexture", where);
      checkTextureInfo(doc_, m.emissiveTexture.index, "emissiveTexture", where);
      checkTextureInfo(doc_, m.normalTexture.index, "normalTexture", where);
      checkTextureInfo(doc_, m.occlusionTexture.index, "occlusionTexture", where);
      checkEmission(m, where);
      checkMaterialExtensions(m, where);
      checkTextureTransforms(m, where);
    }
  }

  // The KHR_materials_* extensions' values.
  void checkMaterialExtensions(const tinygltf::Material& m, const std::string& where) {
    if (const Value* e = extension(m.extensions, "KHR_materials_ior"))
      if (const Value* s = member(*e, "ior"))
        if (!s->IsNumber() || !finite(s->GetNumberAsDouble()) || s->GetNumberAsDouble() <= 0.0)
          fail("KHR_materials_ior ior must be a number > 0", where);
    if (const Value* e = extension(m.extensions, "KHR_materials_transmission"))
      if (const Value* s = member(*e, "transmissionFactor"))
        checkFactor(s->IsNumber() ? s->GetNumberAsDouble() : -1.0, 0.0, 1.0,
                    "KHR_materials_transmission transmissionFactor", where);
    auto number = [&](const Value* e, const char* key, double lo, double hi, const char* ext) {
      if (const Value* s = member(*e, key))
        checkFactor(s->IsNumber() ? s->GetNumberAsDouble() : -1.0, lo, hi,
                    std::string(ext) + " " + key, where);
    };
    auto finiteNumber = [&](const Value* e, const char* key, const char* ext) {
      if (const Value* s = member(*e, key))
        if (!s->IsNumber() || !finite(s->GetNumberAsDouble()))
          fail(std::string(ext) + " " + key + " must be a finite number", where);
    };
    // A colour: 3 finite numbers in [0, hi]; `what` says the range in the error.
    auto colour = [&](const Value* e, const char* key, double hi, const char* ext,
                      const char* what) {
      if (const Value* c = member(*e, key)) {
        bool ok = c->IsArray() && c->ArrayLen() == 3;
        for (int k = 0; ok && k < 3; ++k) {
          const double x = c->Get(k).IsNumber() ? c->Get(k).GetNumberAsDouble() : -1.0;
          ok = finite(x) && x >= 0.0 && x <= hi;
        }
        if (!ok) fail(std::string(ext) + " " + key + " must be 3 numbers " + what, where);
      }
    };
    if (const Value* e = extension(m.extensions, "KHR_materials_specular")) {
      number(e, "specularFactor", 0.0, 1.0, "KHR_materials_specular");
      colour(e, "specularColorFactor", HUGE_VAL, "KHR_materials_specular", ">= 0");
    }
    if (const Value* e = extension(m.extensions, "KHR_materials_volume")) {
      number(e, "thicknessFactor", 0.0, 3.0e38, "KHR_materials_volume");
      if (const Value* d = member(*e, "attenuationDistance"))
        if (!d->IsNumber() || !finite(d->GetNumberAsDouble()) || d->GetNumberAsDouble() <= 0.0)
          fail("KHR_materials_volume attenuationDistance must be a number > 0", where);
      colour(e, "attenuationColor", 1.0, "KHR_materials_volume", "in 0..1");
    }
    if (const Value* e = extension(m.extensions, "KHR_materials_clearcoat")) {
      number(e, "clearcoatFactor", 0.0, 1.0, "KHR_materials_clearcoat");
      number(e, "clearcoatRoughnessFactor", 0.0, 1.0, "KHR_materials_clearcoat");
      if (const Value* t = member(*e, "clearcoatNormalTexture"))
        if (t->IsObject())
          finiteNumber(t, "scale", "KHR_materials_clearcoat clearcoatNormalTexture");
    }
    if (const Value* e = extension(m.extensions, "KHR_materials_sheen")) {
      colour(e, "sheenColorFactor", 1.0, "KHR_materials_sheen", "in 0..1");
      number(e, "sheenRoughnessFactor", 0.0, 1.0, "KHR_materials_sheen");
    }
    if (const Value* e = extension(m.extensions, "KHR_materials_anisotropy")) {
      number(e, "anisotropyStrength", 0.0, 1.0, "KHR_materials_anisotropy");
      finiteNumber(e, "anisotropyRotation", "KHR_materials_anisotropy");
    }
  }

  // KHR_texture_transform on every texture the material uses.
  void checkTextureTransforms(const tinygltf::Material& m, const std::string& where) {
    const auto& pbr = m.pbrMetallicRoughness;
    const std::pair<const char*, const tinygltf::ExtensionMap*> textures[] = {
        {"baseColorTexture", &pbr.baseColorTexture.extensions},
        {"metallicRoughnessTexture", &pbr.metallicRoughnessTexture.extensions},
        {"emissiveTexture", &m.emissiveTexture.extensions},
        {"normalTexture", &m.normalTexture.extensions},
        {"occlusionTexture", &m.occlusionTexture.extensions}};
    for (const auto& [name, extensions] : textures) {
      const Value* t = extension(*extensions, "KHR_texture_transform");
      if (!t) continue;
      const std::string twhere = where + ", " + name;
      auto arr2 = [&](const char* key) {
        if (const Value* v = member(*t, key)) {
          bool ok = v->IsArray() && v->ArrayLen() == 2;
          for (int k = 0; ok && k < 2; ++k)
            ok = v->Get(k).IsNumber() && finite(v->Get(k).GetNumberAsDouble());
          if (!ok)
            fail(std::string("KHR_texture_transform ") + key + " must be 2 finite numbers", twhere);
        }
      };
      arr2("offset");
      arr2("scale");
      if (const Value* r = member(*t, "rotation"))
        if (!r->IsNumber() || !finite(r->GetNumberAsDouble()))
          fail("KHR_texture_transform rotation must be a finite number", twhere);
      if (const Value* c = member(*t, "texCoord"))
        if (!c->IsInt() || c->GetNumberAsInt() < 0)
          fail("KHR_texture_transform texCoord must be a non-negative integer", twhere);
    }
  }

  // --- cameras, lights -------------------------------------------------------------------------

  void checkCamerasAndLights() {
    for (size_t i = 0; i < model_.cameras.size(); ++i) {
      const auto& c = model_.cameras[i];
      const std::string where = named("camera", int(i), c.name);
      if (c.type == "perspective") {
        const auto& p = c.perspective;
        if (!finite(p.yfov) || p.yfov <= 0.0 || p.yfov >= kPi)
          fail("yfov must be in (0, pi)", where);
        if (!finite(p.znear) || p.znear <= 0.0) fail("znear must be > 0", where);
        if (!finite(p.aspectRatio) || p.aspectRatio < 0.0) fail("aspectRatio must be > 0", where);
        if (!finite(p.zfar) || (p.zfar != 0.0 && p.zfar <= p.znear))
          fail("zfar must be > znear", where);
      } else if (c.type == "orthographic") {
        const auto& o = c.orthographic;
        if (!finite(o.xmag) || !finite(o.ymag) || o.xmag == 0.0 || o.ymag == 0.0)
          fail("xmag and ymag must be finite and non-zero", where);
        if (!finite(o.znear) || !finite(o.zfar) || o.znear < 0.0 || o.zfar <= o.znear)
          fail("orthographic needs 0 <= znear < zfar", where);
      } else {
        fail("unknown camera type \"" + c.type + "\"", where);
      }
    }
    for (size_t i = 0; i < model_.lights.size(); ++i) {
      const auto& l = model_.lights[i];
      const std::string where = "KHR_lights_punctual " + named("light", int(i), l.name);
      if (l.type != "point" && l.type != "spot" && l.type != "directional")
        fail("unknown light type \"" + l.type + "\"", where);
      if (!l.color.empty() && l.color.size() != 3) fail("color must have 3 numbers", where);
      for (double c : l.color)
        if (!finite(c) || c < 0.0) fail("color must be finite and >= 0", where);
      if (!finite(l.intensity) || l.intensity < 0.0)
        fail("intensity must be finite and >= 0", where);
      if (!finite(l.range) || l.range < 0.0) fail("range must be > 0", where);
      if (l.type == "spot") {
        const double in = l.spot.innerConeAngle, out = l.spot.outerConeAngle;
        if (!finite(in) || !finite(out) || in < 0.0 || in >= out || out > kPi / 2 + 1e-9)
          fail("spot cone angles must satisfy 0 <= innerConeAngle < outerConeAngle <= pi/2", where);
      }
    }
  }

  // --- meshes ----------------------------------------------------------------------------------

  void checkMeshes() {
    const AccessorRule position{{TINYGLTF_TYPE_VEC3}, {TINYGLTF_COMPONENT_TYPE_FLOAT}};
    const AccessorRule normal = position;
    const AccessorRule tangent{{TINYGLTF_TYPE_VEC4}, {TINYGLTF_COMPONENT_TYPE_FLOAT}};
    const AccessorRule texcoord{
        {TINYGLTF_TYPE_VEC2},
        {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
         TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT},
        true};
    const AccessorRule indices{
        {TINYGLTF_TYPE_SCALAR},
        {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
         TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT}};
    const AccessorRule joints{
        {TINYGLTF_TYPE_VEC4},
        {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT}};
    const AccessorRule weights{
        {TINYGLTF_TYPE_VEC4},
        {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
         TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT},
        true};
    for (size_t mi = 0; mi < model_.meshes.size(); ++mi) {
      const auto& mesh = model_.meshes[mi];
      for (size_t pi = 0; pi < mesh.primitives.size(); ++pi) {
        const auto& p = mesh.primitives[pi];
        const std::string where =
            named("mesh", int(mi), mesh.name) + ", primitive " + std::to_string(pi);
        if (p.material >= 0 ? size_t(p.material) >= model_.materials.size() : p.material != -1)
          fail("material " + std::to_string(p.material) + " does not exist", where);
        if (p.mode < -1 || p.mode > 6) fail("invalid mode " + std::to_string(p.mode), where);
        size_t count = 0;
        bool first = true;
        for (const auto& [name, acc] : p.attributes) {
          const std::string at = where + ", " + name;
          if (name == "POSITION")
            checkRule(acc, position, at);
          else if (name == "NORMAL")
            checkRule(acc, normal, at);
          else if (name == "TANGENT")
            checkRule(acc, tangent, at);
          else if (name == "TEXCOORD_0" || name == "TEXCOORD_1")
            checkRule(acc, texcoord, at);
          else if (name.rfind("JOINTS_", 0) == 0)
            checkRule(acc, joints, at);
          else if (name.rfind("WEIGHTS_", 0) == 0)
            checkRule(acc, weights, at);
          else
            checkAccessor(acc, at);
          const size_t c = model_.accessors[size_t(acc)].count;
          if (!first && c != count)
            fail("attributes have different counts (" + std::to_string(count) + " and " +
                     std::to_string(c) + ")",
                 at);
          count = c;
          first = false;
        }
        if (p.indices >= 0 || p.indices < -1) checkRule(p.indices, indices, where + ", indices");
        if (p.targets.size() != mesh.primitives[0].targets.size())
          fail("primitives have different numbers of morph targets", where);
        for (size_t ti = 0; ti < p.targets.size(); ++ti)
          for (const auto& [name, acc] : p.targets[ti]) {
            const std::string at = where + ", morph target " + std::to_string(ti) + " " + name;
            if (name == "POSITION" || name == "NORMAL")
              checkRule(acc, position, at);
            else
              checkAccessor(acc, at);
            if (model_.accessors[size_t(acc)].count != count)
              fail("has " + std::to_string(model_.accessors[size_t(acc)].count) + " values for " +
                       std::to_string(count) + " vertices",
                   at);
          }
        if (!mesh.weights.empty() && mesh.weights.size() != p.targets.size())
          fail("weights has " + std::to_string(mesh.weights.size()) + " numbers for " +
                   std::to_string(p.targets.size()) + " morph targets",
               named("mesh", int(mi), mesh.name));
      }
    }
  }

  // --- skins -----------------------------------------------------------------------------------

  void checkSkins() {
    const AccessorRule mat4{{TINYGLTF_TYPE_MAT4}, {TINYGLTF_COMPONENT_TYPE_FLOAT}};
    for (size_t si = 0; si < model_.skins.size(); ++si) {
      const auto& s = model_.skins[si];
      const std::string where = named("skin", int(si), s.name);
      if (s.joints.empty()) fail("has no joints", where);
      for (int j : s.joints)
        if (j < 0 || size_t(j) >= model_.nodes.size())
          fail("joint node " + std::to_string(j) + " does not exist", where);
      if (s.inverseBindMatrices >= 0 || s.inverseBindMatrices < -1) {
        checkRule(s.inverseBindMatrices, mat4, where + ", inverseBindMatrices");
        if (model_.accessors[size_t(s.inverseBindMatrices)].count < s.joints.size())
          fail("inverseBindMatrices has fewer matrices than the " +
                   std::to_string(s.joints.size()) + " joints",
               where);
      }
    }
  }

  // --- nodes, scenes ---------------------------------------------------------------------------

  void checkNodesAndScenes() {
    const size_t n = model_.nodes.size();
    parents_.assign(n, -1);
    for (size_t i = 0; i < n; ++i) {
      const auto& node = model_.nodes[i];
      const std::string where = named("node", int(i), node.name);
      for (int c : node.children) {
        if (c < 0 || size_t(c) >= n) fail("child " + std::to_string(c) + " does not exist", where);
        if (c == int(i)) fail("is its own child", where);
        if (parents_[size_t(c)] >= 0)
          fail("node " + std::to_string(c) + " has two parents (nodes " +
                   std::to_string(parents_[size_t(c)]) + " and " + std::to_string(i) + ")",
               where);
        parents_[size_t(c)] = int(i);
      }
      if (node.mesh >= 0 ? size_t(node.mesh) >= model_.meshes.size() : node.mesh != -1)
        fail("mesh " + std::to_string(node.mesh) + " does not exist", where);
      if (node.camera >= 0 ? size_t(node.camera) >= model_.cameras.size() : node.camera != -1)
        fail("camera " + std::to_string(node.camera) + " does not exist", where);
      if (node.skin >= 0 ? size_t(node.skin) >= model_.skins.size() : node.skin != -1)
        fail("skin " + std::to_string(node.skin) + " does not exist", where);
      const int light = nodeLight(node);
      if (light != -1 && (light < 0 || size_t(light) >= model_.lights.size()))
        fail("KHR_lights_punctual light " + std::to_string(light) + " does not exist", where);
      auto checkArray = [&](const std::vector<double>& v, size_t size, const char* what) {
        if (!v.empty() && v.size() != size)
          fail(std::string(what) + " must have " + std::to_string(size) + " numbers", where);
        if (!allFinite(v)) fail(std::string(what) + " is not finite", where);
      };
      checkArray(node.translation, 3, "translation");
      checkArray(node.rotation, 4, "rotation");
      checkArray(node.scale, 3, "scale");
      checkArray(node.matrix, 16, "matrix");
      if (!allFinite(node.weights)) fail("weights is not finite", where);
      if (node.rotation.size() == 4) {
        const double len2 =
            node.rotation[0] * node.rotation[0] + node.rotation[1] * node.rotation[1] +
            node.rotation[2] * node.rotation[2] + node.rotation[3] * node.rotation[3];
        if (!(len2 > 1e-12)) fail("rotation is not a unit quaternion", where);
      }
    }
    // Unique parents make the graph a forest unless a walk upwards comes back: find cycles.
    std::vector<uint8_t> state(n, 0);  // 0 unvisited, 1 on the current walk, 2 done
    for (size_t i = 0; i < n; ++i) {
      std::vector<size_t> walk;
      for (size_t k = i; state[k] != 2;) {
        if (state[k] == 1)
          fail("node hierarchy has a cycle", named("node", int(k), model_.nodes[k].name));
        state[k] = 1;
        walk.push_back(k);
        if (parents_[k] < 0) break;
        k = size_t(parents_[k]);
      }
      for (size_t w : walk) state[w] = 2;
    }
    // Depths, parents first along each walk up (a node's depth is its parent's plus one).
    std::vector<int> depth(n, -1);
    for (size_t i = 0; i < n; ++i) {
      std::vector<size_t> up;
      size_t k = i;
      while (depth[k] < 0 && parents_[k] >= 0) {
        up.push_back(k);
        k = size_t(parents_[k]);
      }
      if (depth[k] < 0) depth[k] = 1;
      for (auto it = up.rbegin(); it != up.rend(); ++it) {
        depth[*it] = depth[size_t(parents_[*it])] + 1;
        if (depth[*it] > kMaxNodeDepth)
          fail("node hierarchy is more than " + std::to_string(kMaxNodeDepth) +
                   " levels deep (the limit pathreuse loads)",
               named("node", int(*it), model_.nodes[*it].name));
      }
    }
    for (size_t s = 0; s < model_.scenes.size(); ++s) {
      const auto& sc = model_.scenes[s];
      std::set<int> seen;
      for (int r : sc.nodes) {
        const std::string where = named("scene", int(s), sc.name);
        if (r < 0 || size_t(r) >= n) fail("node " + std::to_string(r) + " does not exist", where);
        if (parents_[size_t(r)] >= 0)
          fail("root node " + std::to_string(r) + " is also a child of node " +
                   std::to_string(parents_[size_t(r)]),
               where);
        if (!seen.insert(r).second) fail("node " + std::to_string(r) + " is listed twice", where);
      }
    }
    if (model_.defaultScene >= 0 ? size_t(model_.defaultScene) >= model_.scenes.size()
                                 : model_.defaultScene != -1)
      fail("default scene " + std::to_string(model_.defaultScene) + " does not exist", "scene");
  }

  // --- animations ------------------------------------------------------------------------------

  void checkAnimations() {
    const AccessorRule times{{TINYGLTF_TYPE_SCALAR}, {TINYGLTF_COMPONENT_TYPE_FLOAT}};
    const AccessorRule vec3{{TINYGLTF_TYPE_VEC3}, {TINYGLTF_COMPONENT_TYPE_FLOAT}};
    const AccessorRule weightValues{
        {TINYGLTF_TYPE_SCALAR},
        {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_BYTE,
         TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_SHORT,
         TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT},
        true};
    const AccessorRule quat{{TINYGLTF_TYPE_VEC4},
                            {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_BYTE,
                             TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_SHORT,
                             TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT},
                            true};
    for (size_t ai = 0; ai < model_.animations.size(); ++ai) {
      const auto& anim = model_.animations[ai];
      const std::string aname = named("animation", int(ai), anim.name);
      Animation out;
      out.name = anim.name;
      std::vector<int> samplerIndex(anim.samplers.size(), -1);  // glTF sampler -> ours
      for (size_t ci = 0; ci < anim.channels.size(); ++ci) {
        const auto& ch = anim.channels[ci];
        const std::string where = aname + ", channel " + std::to_string(ci);
        if (ch.sampler < 0 || size_t(ch.sampler) >= anim.samplers.size())
          fail("sampler " + std::to_string(ch.sampler) + " does not exist", where);
        if (ch.target_node < -1 || ch.target_node >= int(model_.nodes.size()))
          fail("target node " + std::to_string(ch.target_node) + " does not exist", where);
        const std::string& path = ch.target_path;
        if (path != "translation" && path != "rotation" && path != "scale" && path != "weights")
          fail("unknown target path \"" + path + "\"", where);
        const auto& s = anim.samplers[size_t(ch.sampler)];
        const std::string swhere = aname + ", sampler " + std::to_string(ch.sampler);
        if (s.interpolation != "LINEAR" && s.interpolation != "STEP" &&
            s.interpolation != "CUBICSPLINE")
          fail("unknown interpolation \"" + s.interpolation + "\"", swhere);
        checkRule(s.input, times, swhere + ", input");
        checkAccessor(s.output, swhere + ", output");
        if (ch.target_node < 0) continue;  // target given by an extension we do not know
        if (path == "weights") {
          checkRule(s.output, weightValues, swhere + ", output");
          // One sampler per 4 targets, each a vec4 channel of its own.
          const std::vector<AnimationSampler> parts =
              readWeightSamplers(doc_, anim, ch.sampler, swhere);
          for (size_t k = 0; k < parts.size(); ++k) {
            AnimationChannel c;
            c.sampler = int(out.samplers.size());
            c.node = ch.target_node;
            c.path = AnimationPath::Weights;
            c.firstWeight = int(4 * k);
            out.samplers.push_back(parts[k]);
            out.channels.push_back(c);
          }
          continue;
        }
        const auto& node = model_.nodes[size_t(ch.target_node)];
        if (!node.matrix.empty())
          fail("node " + std::to_string(ch.target_node) + " is animated but has a matrix", where);
        checkRule(s.output, path == "rotation" ? quat : vec3, swhere + ", output");
        if (samplerIndex[size_t(ch.sampler)] < 0) {
          samplerIndex[size_t(ch.sampler)] = int(out.samplers.size());
          out.samplers.push_back(readSampler(doc_, anim, ch.sampler, swhere));
        }
        AnimationChannel c;
        c.sampler = samplerIndex[size_t(ch.sampler)];
        c.node = ch.target_node;
        c.path = path == "translation" ? AnimationPath::Translation
                 : path == "rotation"  ? AnimationPath::Rotation
                                       : AnimationPath::Scale;
        out.channels.push_back(c);
      }
      // Samplers no channel uses still get their references checked.
      for (size_t si = 0; si < anim.samplers.size(); ++si) {
        const std::string swhere = aname + ", sampler " + std::to_string(si);
        checkAccessor(anim.samplers[si].input, swhere + ", input");
        checkAccessor(anim.samplers[si].output, swhere + ", output");
      }
      if (!out.channels.empty()) animations_.push_back(std::move(out));
    }
  }

  std::set<int> accessorChecked_;
  std::vector<int> parents_;
  std::vector<Animation> animations_;
};

}  // namespace

void checkTextureInfo(const Document& doc, int index, const std::string& what,
                      const std::string& where) {
  if (index < 0 && index != -1) doc.fail(what + " has invalid texture index", where);
  if (index >= 0 && size_t(index) >= doc.model.textures.size())
    doc.fail(what + " refers to texture " + std::to_string(index) + ", which does not exist",
             where);
}

Validated validate(Document& doc) {
  return Validator(doc).run();
}

}  // namespace pr::gltf
