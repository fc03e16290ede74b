#include "scene/gltf_schema.h"

#include <cmath>
#include <map>

namespace pr {

namespace {

using nlohmann::json;

enum class Kind {
  Any,
  String,
  Number,
  Uint,
  Bool,
  Object,
  Array,
  NumberArray,
  UintArray,
  StringArray,
  ObjectArray,
  UintMap
};

struct Schema;

struct Prop {
  Kind kind = Kind::Any;
  const Schema* sub = nullptr;  // for Object and ObjectArray
  bool required = false;
};

// The properties of one kind of glTF object, and the schemas of extensions it may carry.
struct Schema {
  std::map<std::string, Prop> props;
  std::map<std::string, const Schema*> extensions;
};

// Every schema we check, wired together once.
struct Schemas {
  Schema root, asset, scene, node, mesh, primitive, accessor, sparse, sparseIndices, sparseValues,
      bufferView, buffer, material, pbr, textureInfo, texture, image, sampler, camera, perspective,
      orthographic, animation, channel, target, animSampler, skin, anyObject;
  Schema textureTransform, emissiveStrength, transmission, ior, lightsRoot, light, spot, nodeLight;

  Schemas() {
    const Prop str{Kind::String}, num{Kind::Number}, uint{Kind::Uint}, boolean{Kind::Bool},
        nums{Kind::NumberArray}, uints{Kind::UintArray};
    auto req = [](Prop p) {
      p.required = true;
      return p;
    };
    auto obj = [](const Schema& s) { return Prop{Kind::Object, &s}; };
    auto objs = [](const Schema& s) { return Prop{Kind::ObjectArray, &s}; };

    root.props = {{"asset", req(obj(asset))},
                  {"scene", uint},
                  {"scenes", objs(scene)},
                  {"nodes", objs(node)},
                  {"meshes", objs(mesh)},
                  {"accessors", objs(accessor)},
                  {"bufferViews", objs(bufferView)},
                  {"buffers", objs(buffer)},
                  {"materials", objs(material)},
                  {"textures", objs(texture)},
                  {"images", objs(image)},
                  {"samplers", objs(sampler)},
                  {"cameras", objs(camera)},
                  {"animations", objs(animation)},
                  {"skins", objs(skin)},
                  {"extensionsUsed", Prop{Kind::StringArray}},
                  {"extensionsRequired", Prop{Kind::StringArray}}};
    root.extensions = {{"KHR_lights_punctual", &lightsRoot}};
    asset.props = {
        {"version", req(str)}, {"minVersion", str}, {"generator", str}, {"copyright", str}};
    scene.props = {{"nodes", uints}};
    node.props = {{"children", uints}, {"mesh", uint},        {"camera", uint},
                  {"skin", uint},      {"matrix", nums},      {"rotation", nums},
                  {"scale", nums},     {"translation", nums}, {"weights", nums}};
    node.extensions = {{"KHR_lights_punctual", &nodeLight}};
    mesh.props = {{"primitives", req(objs(primitive))}, {"weights", nums}};
    primitive.props = {{"attributes", req(Prop{Kind::UintMap})},
                       {"indices", uint},
                       {"material", uint},
                       {"mode", uint},
                       {"targets", Prop{Kind::ObjectArray, &anyObject}}};
    accessor.props = {{"bufferView", uint},    {"byteOffset", uint}, {"componentType", req(uint)},
                      {"normalized", boolean}, {"count", req(uint)}, {"type", req(str)},
                      {"max", nums},           {"min", nums},        {"sparse", obj(sparse)}};
    sparse.props = {{"count", req(uint)},
                    {"indices", req(obj(sparseIndices))},
                    {"values", req(obj(sparseValues))}};
    sparseIndices.props = {
        {"bufferView", req(uint)}, {"byteOffset", uint}, {"componentType", req(uint)}};
    sparseValues.props = {{"bufferView", req(uint)}, {"byteOffset", uint}};
    bufferView.props = {{"buffer", req(uint)},
                        {"byteOffset", uint},
                        {"byteLength", req(uint)},
                        {"byteStride", uint},
                        {"target", uint}};
    buffer.props = {{"uri", str}, {"byteLength", req(uint)}};
    material.props = {{"pbrMetallicRoughness", obj(pbr)},
                      {"normalTexture", obj(textureInfo)},
                      {"occlusionTexture", obj(textureInfo)},
                      {"emissiveTexture", obj(textureInfo)},
                      {"emissiveFactor", nums},
                      {"alphaMode", str},
                      {"alphaCutoff", num},
                      {"doubleSided", boolean}};
    material.extensions = {{"KHR_materials_emissive_strength", &emissiveStrength},
                           {"KHR_materials_transmission", &transmission},
                           {"KHR_materials_ior", &ior}};
    pbr.props = {{"baseColorFactor", nums},
                 {"baseColorTexture", obj(textureInfo)},
                 {"metallicFactor", num},
                 {"roughnessFactor", num},
                 {"metallicRoughnessTexture", obj(textureInfo)}};
    textureInfo.props = {
        {"index", req(uint)}, {"texCoord", uint}, {"scale", num}, {"strength", num}};
    textureInfo.extensions = {{"KHR_texture_transform", &textureTransform}};
    texture.props = {{"sampler", uint}, {"source", uint}};
    image.props = {{"uri", str}, {"mimeType", str}, {"bufferView", uint}};
    sampler.props = {{"magFilter", uint}, {"minFilter", uint}, {"wrapS", uint}, {"wrapT", uint}};
    camera.props = {
        {"type", req(str)}, {"perspective", obj(perspective)}, {"orthographic", obj(orthographic)}};
    perspective.props = {
        {"aspectRatio", num}, {"yfov", req(num)}, {"zfar", num}, {"znear", req(num)}};
    orthographic.props = {
        {"xmag", req(num)}, {"ymag", req(num)}, {"zfar", req(num)}, {"znear", req(num)}};
    animation.props = {{"channels", req(objs(channel))}, {"samplers", req(objs(animSampler))}};
    channel.props = {{"sampler", req(uint)}, {"target", req(obj(target))}};
    target.props = {{"node", uint}, {"path", req(str)}};
    animSampler.props = {{"input", req(uint)}, {"interpolation", str}, {"output", req(uint)}};
    skin.props = {{"inverseBindMatrices", uint}, {"skeleton", uint}, {"joints", req(uints)}};

    textureTransform.props = {
        {"offset", nums}, {"rotation", num}, {"scale", nums}, {"texCoord", uint}};
    emissiveStrength.props = {{"emissiveStrength", num}};
    transmission.props = {{"transmissionFactor", num}, {"transmissionTexture", obj(textureInfo)}};
    ior.props = {{"ior", num}};
    lightsRoot.props = {{"lights", objs(light)}};
    light.props = {{"type", req(str)},
                   {"color", nums},
                   {"intensity", num},
                   {"range", num},
                   {"spot", obj(spot)}};
    spot.props = {{"innerConeAngle", num}, {"outerConeAngle", num}};
    nodeLight.props = {{"light", req(uint)}};
  }
};

const char* kindName(Kind k) {
  switch (k) {
    case Kind::String:
      return "a string";
    case Kind::Number:
      return "a number";
    case Kind::Uint:
      return "a non-negative integer";
    case Kind::Bool:
      return "a boolean";
    case Kind::Object:
      return "an object";
    case Kind::Array:
      return "an array";
    case Kind::NumberArray:
      return "an array of numbers";
    case Kind::UintArray:
      return "an array of non-negative integers";
    case Kind::StringArray:
      return "an array of strings";
    case Kind::ObjectArray:
      return "an array of objects";
    case Kind::UintMap:
      return "an object of non-negative integers";
    case Kind::Any:
      break;
  }
  return "a value";
}

bool isUint(const json& v) {
  if (v.is_number_unsigned()) return true;
  if (v.is_number_integer()) return v.get<int64_t>() >= 0;
  // 3.0 is an integer in JSON's eyes; 3.5 is not.
  if (v.is_number_float()) {
    const double d = v.get<double>();
    // Range first: casting a double beyond int64 to an integer is undefined (found by fuzzing).
    return d >= 0.0 && d < 9.0e15 && d == std::floor(d);
  }
  return false;
}

bool hasKind(const json& v, Kind k) {
  auto all = [&](auto pred) {
    if (!v.is_array()) return false;
    for (const auto& e : v)
      if (!pred(e)) return false;
    return true;
  };
  switch (k) {
    case Kind::Any:
      return true;
    case Kind::String:
      return v.is_string();
    case Kind::Number:
      return v.is_number();
    case Kind::Uint:
      return isUint(v);
    case Kind::Bool:
      return v.is_boolean();
    case Kind::Object:
      return v.is_object();
    case Kind::Array:
      return v.is_array();
    case Kind::NumberArray:
      return all([](const json& e) { return e.is_number(); });
    case Kind::UintArray:
      return all(isUint);
    case Kind::StringArray:
      return all([](const json& e) { return e.is_string(); });
    case Kind::ObjectArray:
      return all([](const json& e) { return e.is_object(); });
    case Kind::UintMap:
      if (!v.is_object()) return false;
      for (const auto& e : v.items())
        if (!isUint(e.value())) return false;
      return true;
  }
  return false;
}

std::string check(const json& o, const Schema& s, const std::string& where) {
  const std::string loc = where.empty() ? "top level" : where;
  for (const auto& [key, prop] : s.props) {
    const auto it = o.find(key);
    if (it == o.end()) {
      if (prop.required) return "\"" + key + "\" is missing (" + loc + ")";
      continue;
    }
    if (!hasKind(*it, prop.kind))
      return "\"" + key + "\" must be " + kindName(prop.kind) + " (" + loc + ")";
    const std::string inner = where.empty() ? key : where + "." + key;
    if (prop.kind == Kind::Object && prop.sub) {
      std::string e = check(*it, *prop.sub, inner);
      if (!e.empty()) return e;
    } else if (prop.kind == Kind::ObjectArray && prop.sub) {
      for (size_t i = 0; i < it->size(); ++i) {
        std::string e = check((*it)[i], *prop.sub, inner + "[" + std::to_string(i) + "]");
        if (!e.empty()) return e;
      }
    }
  }
  if (const auto it = o.find("name"); it != o.end() && !it->is_string())
    return "\"name\" must be a string (" + loc + ")";
  if (const auto it = o.find("extensions"); it != o.end()) {
    if (!it->is_object()) return "\"extensions\" must be an object (" + loc + ")";
    for (const auto& e : it->items()) {
      const std::string inner = (where.empty() ? "" : where + ".") + "extensions." + e.key();
      if (!e.value().is_object())
        return "extension \"" + e.key() + "\" must be an object (" + inner + ")";
      const auto ext = s.extensions.find(e.key());
      if (ext != s.extensions.end()) {
        std::string err = check(e.value(), *ext->second, inner);
        if (!err.empty()) return err;
      }
    }
  }
  return "";
}

}  // namespace

std::string checkGltfSchema(const json& gltf) {
  static const Schemas schemas;
  if (!gltf.is_object()) return "the JSON is not an object (top level)";
  return check(gltf, schemas.root, "");
}

}  // namespace pr
