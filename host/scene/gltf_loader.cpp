#include "scene/gltf_loader.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include <tiny_gltf.h>

#include "scene/gltf_schema.h"
#include "scene/image_decode.h"
#include "scene/tangents.h"
#include "util/error.h"

namespace pr {

namespace {

namespace fs = std::filesystem;
using tinygltf::Value;

constexpr double kPi = 3.14159265358979323846;

// Encoded bytes of images given by uri (data: or file), keyed by image index. Images in
// buffer views are read by us after their ranges are checked: tinygltf would read them
// without checking.
struct ImageBytes {
  std::map<int, std::vector<uint8_t>> encoded;
};

bool keepImageBytes(tinygltf::Image* image, const int index, std::string*, std::string*, int, int,
                    const unsigned char* bytes, int size, void* user) {
  if (image->bufferView >= 0 || !bytes || size <= 0) return true;
  static_cast<ImageBytes*>(user)->encoded[index].assign(bytes, bytes + size);
  return true;
}

// One line: newlines and other control characters become spaces, runs collapse.
std::string oneLine(const std::string& s) {
  std::string out;
  for (char c : s) {
    const bool ctl = static_cast<unsigned char>(c) < 0x20 || c == 0x7f;
    if (ctl) c = ' ';
    if (c == ' ' && (out.empty() || out.back() == ' ')) continue;
    out += c;
  }
  while (!out.empty() && out.back() == ' ') out.pop_back();
  return out;
}

std::string named(const char* kind, int index, const std::string& name) {
  std::string s = std::string(kind) + " " + std::to_string(index);
  if (!name.empty()) s += " \"" + name + "\"";
  return s;
}

bool finite(double v) {
  return std::isfinite(v);
}

bool allFinite(const std::vector<double>& v) {
  return std::all_of(v.begin(), v.end(), finite);
}

const Value* member(const Value& obj, const char* key) {
  if (!obj.IsObject() || !obj.Has(key)) return nullptr;
  return &obj.Get(key);
}

const Value* extension(const tinygltf::ExtensionMap& ext, const char* name) {
  const auto it = ext.find(name);
  return it == ext.end() ? nullptr : &it->second;
}

size_t componentSize(int componentType) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return 4;
    default:
      return 0;
  }
}

size_t componentCount(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR:
      return 1;
    case TINYGLTF_TYPE_VEC2:
      return 2;
    case TINYGLTF_TYPE_VEC3:
      return 3;
    case TINYGLTF_TYPE_VEC4:
      return 4;
    case TINYGLTF_TYPE_MAT2:
      return 4;
    case TINYGLTF_TYPE_MAT3:
      return 9;
    case TINYGLTF_TYPE_MAT4:
      return 16;
    default:
      return 0;
  }
}

const char* typeName(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR:
      return "SCALAR";
    case TINYGLTF_TYPE_VEC2:
      return "VEC2";
    case TINYGLTF_TYPE_VEC3:
      return "VEC3";
    case TINYGLTF_TYPE_VEC4:
      return "VEC4";
    case TINYGLTF_TYPE_MAT2:
      return "MAT2";
    case TINYGLTF_TYPE_MAT3:
      return "MAT3";
    case TINYGLTF_TYPE_MAT4:
      return "MAT4";
    default:
      return "unknown type";
  }
}

const char* componentName(int componentType) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
      return "BYTE";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return "UNSIGNED_BYTE";
    case TINYGLTF_COMPONENT_TYPE_SHORT:
      return "SHORT";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return "UNSIGNED_SHORT";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
      return "UNSIGNED_INT";
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return "FLOAT";
    default:
      return "unknown component type";
  }
}

// One component as a number, normalised integers mapped to [0,1] or [-1,1].
double readComponent(const uint8_t* p, int componentType, bool normalized) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: {
      float f;
      std::memcpy(&f, p, 4);
      return f;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
      uint32_t v;
      std::memcpy(&v, p, 4);
      return v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? v / 65535.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      int16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return normalized ? *p / 255.0 : *p;
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      const int8_t v = static_cast<int8_t>(*p);
      return normalized ? std::max(v / 127.0, -1.0) : v;
    }
    default:
      return 0.0;
  }
}

// a + b * c <= limit, without overflow.
bool fits(uint64_t a, uint64_t b, uint64_t c, uint64_t limit) {
  uint64_t bc = 0, sum = 0;
  if (__builtin_mul_overflow(b, c, &bc) || __builtin_add_overflow(a, bc, &sum)) return false;
  return sum <= limit;
}

// What an attribute or animation accessor may be.
struct AccessorRule {
  std::vector<int> types;
  std::vector<int> componentTypes;
  bool normalizedIntegers = false;  // integer component types must be normalized
};

class Loader {
 public:
  Loader(std::string path, const LoadOptions& options)
      : path_(std::move(path)), options_(options) {}
  // In memory: `bytes` stand for the file at `path_` (named in errors; external URIs resolve
  // beside it).
  Loader(std::string path, const std::string& bytes, const LoadOptions& options)
      : path_(std::move(path)),
        options_(options),
        bytes_(bytes.begin(), bytes.end()),
        inMemory_(true) {}

  Scene load() {
    parse();
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
    build();
    return std::move(scene_);
  }

 private:
  [[noreturn]] void fail(const std::string& what, const std::string& where = "") const {
    std::string msg = path_ + ": " + what;
    if (!where.empty()) msg += " (" + where + ")";
    throw InputError(oneLine(msg));
  }

  void warn(const std::string& line) {
    const std::string w = oneLine(path_ + ": warning: " + line);
    if (std::find(scene_.warnings.begin(), scene_.warnings.end(), w) != scene_.warnings.end())
      return;
    scene_.warnings.push_back(w);
    std::ostream* out = options_.warningStream;
    if (!out && options_.printWarnings) out = &std::cerr;
    if (out) *out << w << "\n";
  }

  // --- parsing -------------------------------------------------------------------------------

  void readFileBytes() {
    std::error_code ec;
    const fs::file_status st = fs::status(path_, ec);
    if (ec || !fs::exists(st)) fail("no such file");
    if (fs::is_directory(st)) fail("is a directory, not a glTF file");
    std::ifstream in(path_, std::ios::binary);
    if (!in) fail("cannot open file");
    bytes_.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    if (in.bad()) fail("cannot read file");
  }

  void parse() {
    if (!inMemory_) readFileBytes();
    const std::vector<uint8_t>& bytes = bytes_;
    if (bytes.empty()) fail("file is empty");

    std::string ext = fs::path(path_).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return std::tolower(c); });
    binary_ = ext == ".glb" || (bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0);

    std::string baseDir = fs::path(path_).parent_path().string();
    if (baseDir.empty()) baseDir = ".";

    preflight(bytes);
    tinygltf::TinyGLTF gltf;
    gltf.SetImageLoader(&keepImageBytes, &images_);
    std::string err, warnText;
    bool ok = false;
    try {
      if (binary_) {
        if (bytes.size() > 0xffffffffu) fail("file is too large for GLB");
        ok = gltf.LoadBinaryFromMemory(&model_, &err, &warnText, bytes.data(),
                                       static_cast<unsigned int>(bytes.size()), baseDir);
      } else {
        ok = gltf.LoadASCIIFromString(&model_, &err, &warnText,
                                      reinterpret_cast<const char*>(bytes.data()),
                                      static_cast<unsigned int>(bytes.size()), baseDir);
      }
    } catch (const InputError&) {
      throw;
    } catch (const std::exception& e) {
      fail(std::string("not a valid glTF file: ") + e.what());
    }
    if (!ok) {
      std::string why = oneLine(err.empty() ? warnText : err);
      if (why.empty()) why = "unknown reason";
      fail("not a valid glTF file: " + why);
    }
    std::vector<uint8_t>().swap(bytes_);  // the model holds what is needed now
  }

  // Before tinygltf: the JSON's types (tinygltf silently drops a property of the wrong type),
  // the version and the required extensions, so these get precise messages.
  void preflight(const std::vector<uint8_t>& bytes) {
    const uint8_t* json = bytes.data();
    size_t length = bytes.size();
    if (binary_) {
      // Header (magic, version, length) then the JSON chunk (length, type). A broken container
      // is left to tinygltf's checks, which name the problem.
      if (bytes.size() < 20 || std::memcmp(bytes.data(), "glTF", 4) != 0) return;
      uint32_t chunkLength = 0, chunkType = 0;
      std::memcpy(&chunkLength, bytes.data() + 12, 4);
      std::memcpy(&chunkType, bytes.data() + 16, 4);
      if (chunkType != 0x4E4F534Au || chunkLength > bytes.size() - 20) return;
      json = bytes.data() + 20;
      length = chunkLength;
    }
    nlohmann::json j;
    try {
      j = nlohmann::json::parse(json, json + length);
    } catch (const nlohmann::json::exception& e) {
      fail(std::string("invalid JSON: ") + e.what());
    }
    const std::string problem = checkGltfSchema(j);
    if (!problem.empty()) fail(problem);
    const std::string version = j["asset"]["version"].get<std::string>();
    const auto dot = version.find('.');
    if (dot == std::string::npos || version.substr(0, dot) != "2")
      fail("unsupported glTF version \"" + version + "\" (asset.version; only 2.x is supported)");
    if (j.contains("extensionsRequired"))
      for (const auto& e : j["extensionsRequired"])
        if (!isSupportedExtension(e.get<std::string>()))
          fail("requires extension " + e.get<std::string>() + ", which is not supported",
               "extensionsRequired");
  }

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
        fail((where.empty() ? self : self) + " reads past the end of bufferView " +
                 std::to_string(a.bufferView),
             where);
    } else if (!a.sparse.isSparse) {
      // No buffer view and no sparse data: all zeros, as the spec says.
    }
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

  // Every element of a checked accessor, components flattened (count * components values).
  std::vector<double> readAccessor(int index) const {
    const auto& a = model_.accessors[size_t(index)];
    const size_t cs = componentSize(a.componentType), nc = componentCount(a.type), elem = cs * nc;
    std::vector<double> out(a.count * nc, 0.0);
    if (a.bufferView >= 0) {
      const auto& v = model_.bufferViews[size_t(a.bufferView)];
      const size_t stride = v.byteStride ? v.byteStride : elem;
      const uint8_t* base =
          model_.buffers[size_t(v.buffer)].data.data() + v.byteOffset + a.byteOffset;
      for (size_t i = 0; i < a.count; ++i)
        for (size_t c = 0; c < nc; ++c)
          out[i * nc + c] =
              readComponent(base + i * stride + c * cs, a.componentType, a.normalized);
    }
    if (a.sparse.isSparse) {
      const auto& sp = a.sparse;
      const auto& iv = model_.bufferViews[size_t(sp.indices.bufferView)];
      const auto& vv = model_.bufferViews[size_t(sp.values.bufferView)];
      const uint8_t* ip = model_.buffers[size_t(iv.buffer)].data.data() + iv.byteOffset +
                          size_t(sp.indices.byteOffset);
      const uint8_t* vp = model_.buffers[size_t(vv.buffer)].data.data() + vv.byteOffset +
                          size_t(sp.values.byteOffset);
      const size_t is = componentSize(sp.indices.componentType);
      for (int i = 0; i < sp.count; ++i) {
        const size_t k =
            size_t(readComponent(ip + size_t(i) * is, sp.indices.componentType, false));
        for (size_t c = 0; c < nc; ++c)
          out[k * nc + c] =
              readComponent(vp + size_t(i) * elem + c * cs, a.componentType, a.normalized);
      }
    }
    return out;
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
      } else if (im.uri.empty() && !images_.encoded.count(int(i))) {
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

  void checkTextureInfo(int index, const std::string& what, const std::string& where) {
    if (index < 0 && index != -1) fail(what + " has invalid texture index", where);
    if (index >= 0 && size_t(index) >= model_.textures.size())
      fail(what + " refers to texture " + std::to_string(index) + ", which does not exist", where);
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
      checkTextureInfo(pbr.baseColorTexture.index, "baseColorTexture", where);
      checkTextureInfo(pbr.metallicRoughnessTexture.index, "metallicRoughnessTexture", where);
      checkTextureInfo(m.emissiveTexture.index, "emissiveTexture", where);
      checkTextureInfo(m.normalTexture.index, "normalTexture", where);
      checkTextureInfo(m.occlusionTexture.index, "occlusionTexture", where);
      if (const Value* e = extension(m.extensions, "KHR_materials_emissive_strength"))
        if (const Value* s = member(*e, "emissiveStrength"))
          if (!s->IsNumber() || !finite(s->GetNumberAsDouble()) || s->GetNumberAsDouble() < 0.0)
            fail("KHR_materials_emissive_strength emissiveStrength must be a number >= 0", where);
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
      if (const Value* e = extension(m.extensions, "KHR_materials_specular")) {
        number(e, "specularFactor", 0.0, 1.0, "KHR_materials_specular");
        if (const Value* c = member(*e, "specularColorFactor")) {
          bool ok = c->IsArray() && c->ArrayLen() == 3;
          for (int k = 0; ok && k < 3; ++k)
            ok = c->Get(k).IsNumber() && finite(c->Get(k).GetNumberAsDouble()) &&
                 c->Get(k).GetNumberAsDouble() >= 0.0;
          if (!ok) fail("KHR_materials_specular specularColorFactor must be 3 numbers >= 0", where);
        }
      }
      if (const Value* e = extension(m.extensions, "KHR_materials_volume")) {
        number(e, "thicknessFactor", 0.0, 3.0e38, "KHR_materials_volume");
        if (const Value* d = member(*e, "attenuationDistance"))
          if (!d->IsNumber() || !finite(d->GetNumberAsDouble()) || d->GetNumberAsDouble() <= 0.0)
            fail("KHR_materials_volume attenuationDistance must be a number > 0", where);
        if (const Value* c = member(*e, "attenuationColor")) {
          bool ok = c->IsArray() && c->ArrayLen() == 3;
          for (int k = 0; ok && k < 3; ++k)
            ok = c->Get(k).IsNumber() && c->Get(k).GetNumberAsDouble() >= 0.0 &&
                 c->Get(k).GetNumberAsDouble() <= 1.0;
          if (!ok) fail("KHR_materials_volume attenuationColor must be 3 numbers in 0..1", where);
        }
      }
      if (const Value* e = extension(m.extensions, "KHR_materials_clearcoat")) {
        number(e, "clearcoatFactor", 0.0, 1.0, "KHR_materials_clearcoat");
        number(e, "clearcoatRoughnessFactor", 0.0, 1.0, "KHR_materials_clearcoat");
      }
      // KHR_texture_transform on every texture the material uses.
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
              fail(std::string("KHR_texture_transform ") + key + " must be 2 finite numbers",
                   twhere);
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

  int nodeLight(const tinygltf::Node& n) const {
    const Value* e = extension(n.extensions, "KHR_lights_punctual");
    if (!e) return -1;
    const Value* l = member(*e, "light");
    return l && l->IsNumber() ? l->GetNumberAsInt() : -2;
  }

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
          const std::vector<AnimationSampler> parts = readWeightSamplers(anim, ch.sampler, swhere);
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
          out.samplers.push_back(readSampler(anim, ch.sampler, swhere));
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
      if (!out.channels.empty()) scene_.animations.push_back(std::move(out));
    }
  }

  // A sampler's interpolation and key times (finite, strictly increasing; CUBICSPLINE needs 2
  // keys, as the glTF spec and its validator's ANIMATION_SAMPLER_INPUT_ACCESSOR_TOO_FEW_ELEMENTS
  // say), without its values.
  AnimationSampler samplerKeys(const tinygltf::AnimationSampler& s, const std::string& where) {
    AnimationSampler out;
    out.interpolation = s.interpolation == "STEP"          ? Interpolation::Step
                        : s.interpolation == "CUBICSPLINE" ? Interpolation::CubicSpline
                                                           : Interpolation::Linear;
    const std::vector<double> in = readAccessor(s.input);
    if (out.interpolation == Interpolation::CubicSpline && in.size() < 2)
      fail("CUBICSPLINE needs at least 2 keys, the input has " + std::to_string(in.size()), where);
    for (size_t i = 0; i < in.size(); ++i) {
      if (!finite(in[i])) fail("input time " + std::to_string(i) + " is not finite", where);
      if (i > 0 && !(float(in[i]) > float(in[i - 1])))
        fail("input times are not strictly increasing at key " + std::to_string(i), where);
      out.times.push_back(float(in[i]));
    }
    return out;
  }

  AnimationSampler readSampler(const tinygltf::Animation& anim, int index,
                               const std::string& where) {
    const auto& s = anim.samplers[size_t(index)];
    AnimationSampler out = samplerKeys(s, where);
    const std::vector<float>& in = out.times;
    const auto& oa = model_.accessors[size_t(s.output)];
    const size_t perKey = out.interpolation == Interpolation::CubicSpline ? 3 : 1;
    if (oa.count != in.size() * perKey)
      fail("output has " + std::to_string(oa.count) + " values for " + std::to_string(in.size()) +
               " keys" + (perKey == 3 ? " (CUBICSPLINE needs 3 per key)" : ""),
           where);
    const size_t nc = componentCount(oa.type);
    const std::vector<double> values = readAccessor(s.output);
    for (size_t i = 0; i < oa.count; ++i) {
      glm::vec4 v(0.0f);
      for (size_t c = 0; c < nc && c < 4; ++c) {
        const double x = values[i * nc + c];
        if (!finite(x) || std::abs(x) > 3.0e38)
          fail("output value " + std::to_string(i) + " is not finite", where);
        v[int(c)] = float(x);
      }
      out.values.push_back(v);
    }
    return out;
  }

  // A morph weights sampler (n scalars per key, 3n for CUBICSPLINE) as ceil(n / 4) samplers of
  // vec4s, targets 4k .. 4k + 3 in part k.
  std::vector<AnimationSampler> readWeightSamplers(const tinygltf::Animation& anim, int index,
                                                   const std::string& where) {
    const auto& s = anim.samplers[size_t(index)];
    const AnimationSampler proto = samplerKeys(s, where);
    const std::vector<float>& in = proto.times;
    const size_t perKey = proto.interpolation == Interpolation::CubicSpline ? 3 : 1;
    const std::vector<double> values = readAccessor(s.output);
    const size_t slots = in.size() * perKey;
    if (slots == 0 || values.size() % slots != 0 || values.empty())
      fail("output has " + std::to_string(values.size()) + " weights, not a multiple of the " +
               std::to_string(slots) + " key values",
           where);
    const size_t n = values.size() / slots;
    for (double v : values)
      if (!finite(v)) fail("output has a weight that is not finite", where);
    std::vector<AnimationSampler> parts((n + 3) / 4, proto);
    for (size_t k = 0; k < parts.size(); ++k)
      for (size_t slot = 0; slot < slots; ++slot) {
        glm::vec4 v(0.0f);
        for (size_t c = 0; c < 4 && 4 * k + c < n; ++c)
          v[int(c)] = float(values[slot * n + 4 * k + c]);
        parts[k].values.push_back(v);
      }
    return parts;
  }

  // --- building the scene ----------------------------------------------------------------------

  static glm::mat4 toMat4(const std::vector<double>& m) {
    glm::mat4 r(1.0f);
    for (int c = 0; c < 4; ++c)
      for (int rr = 0; rr < 4; ++rr) r[c][rr] = float(m[size_t(c * 4 + rr)]);  // column-major
    return r;
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

  // Object-space triangles of one glTF mesh (all TRIANGLES primitives).
  TriangleMesh convertMesh(int meshIndex) {
    const auto& mesh = model_.meshes[size_t(meshIndex)];
    TriangleMesh out;
    out.name = mesh.name;
    bool anyTangents = false, anyUv1 = false, anyNormalMap = false;
    for (const auto& p : mesh.primitives) {
      anyTangents = anyTangents || p.attributes.count("TANGENT");
      anyUv1 = anyUv1 || p.attributes.count("TEXCOORD_1");
      anyNormalMap =
          anyNormalMap || scene_.materials[size_t(materialIndex(p.material))].normalTexture.valid();
    }
    std::vector<uint8_t> normalUvSet;  // per triangle: the uv set its normal map reads
    // Skin and morph data: as many JOINTS_n sets as the primitive with most, the targets'
    // POSITION (and NORMAL where any primitive has it) deltas.
    size_t jointSets = 0, targets = 0;
    bool targetNormals = false;
    for (const auto& p : mesh.primitives) {
      while (p.attributes.count("JOINTS_" + std::to_string(jointSets)) &&
             p.attributes.count("WEIGHTS_" + std::to_string(jointSets)))
        ++jointSets;
      targets = std::max(targets, p.targets.size());
      for (const auto& t : p.targets) targetNormals = targetNormals || t.count("NORMAL");
    }
    out.influences = int(4 * jointSets);
    out.morphPositions.resize(targets);
    out.morphNormals.resize(targets);
    for (double w : mesh.weights) out.morphWeights.push_back(float(w));
    for (size_t pi = 0; pi < mesh.primitives.size(); ++pi) {
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
        continue;
      }
      const auto pos = p.attributes.find("POSITION");
      if (pos == p.attributes.end()) {
        warn("skipping a primitive without POSITION (" + where + ")");
        continue;
      }
      const std::vector<double> positions = readAccessor(pos->second);
      const size_t vcount = positions.size() / 3;
      for (double x : positions)
        if (!finite(x) || std::abs(x) > 3.0e38)
          fail("POSITION has a value that is not finite", where + ", POSITION");
      std::vector<uint32_t> idx;
      if (p.indices >= 0) {
        const std::vector<double> raw = readAccessor(p.indices);
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
      const uint32_t base = uint32_t(out.positions.size());
      if (uint64_t(base) + vcount > 0xffffffffull) fail("mesh has too many vertices", where);
      for (size_t v = 0; v < vcount; ++v)
        out.positions.emplace_back(positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]);

      // Normals: given ones normalised; absent or degenerate ones area-weighted from faces.
      std::vector<glm::vec3> faceNormals(vcount, glm::vec3(0.0f));
      for (size_t t = 0; t + 2 < idx.size(); t += 3) {
        const glm::vec3 a = out.positions[base + idx[t]], b = out.positions[base + idx[t + 1]],
                        c = out.positions[base + idx[t + 2]];
        const glm::vec3 n = glm::cross(b - a, c - a);  // length = twice the area
        if (!std::isfinite(n.x + n.y + n.z)) continue;
        for (int k = 0; k < 3; ++k) faceNormals[idx[t + size_t(k)]] += n;
      }
      std::vector<double> normals;
      if (const auto it = p.attributes.find("NORMAL"); it != p.attributes.end())
        normals = readAccessor(it->second);
      for (size_t v = 0; v < vcount; ++v) {
        glm::vec3 n(0.0f);
        if (!normals.empty()) n = glm::vec3(normals[3 * v], normals[3 * v + 1], normals[3 * v + 2]);
        float len = glm::length(n);
        if (!(len > 1e-12f) || !std::isfinite(len)) {
          n = faceNormals[v];
          len = glm::length(n);
        }
        out.normals.push_back(len > 0.0f && std::isfinite(len) ? n / len
                                                               : glm::vec3(0.0f, 0.0f, 1.0f));
      }
      if (const auto it = p.attributes.find("TEXCOORD_0"); it != p.attributes.end()) {
        const std::vector<double> uv = readAccessor(it->second);
        for (size_t v = 0; v < vcount; ++v) {
          if (!finite(uv[2 * v]) || !finite(uv[2 * v + 1]))
            fail("TEXCOORD_0 is not finite", where + ", TEXCOORD_0");
          out.uvs.emplace_back(uv[2 * v], uv[2 * v + 1]);
        }
      } else {
        out.uvs.resize(out.positions.size(), glm::vec2(0.0f));
      }
      if (anyUv1) {
        std::vector<double> uv;
        if (const auto it = p.attributes.find("TEXCOORD_1"); it != p.attributes.end())
          uv = readAccessor(it->second);
        for (size_t v = 0; v < vcount; ++v) {
          if (uv.empty()) {
            out.uvs1.push_back(out.uvs[base + v]);  // TEXCOORD_0 stands in
            continue;
          }
          if (!finite(uv[2 * v]) || !finite(uv[2 * v + 1]))
            fail("TEXCOORD_1 is not finite", where + ", TEXCOORD_1");
          out.uvs1.emplace_back(uv[2 * v], uv[2 * v + 1]);
        }
      }
      if (jointSets > 0) {
        std::vector<std::vector<double>> js(jointSets), ws(jointSets);
        for (size_t set = 0; set < jointSets; ++set) {
          const auto j = p.attributes.find("JOINTS_" + std::to_string(set));
          const auto w = p.attributes.find("WEIGHTS_" + std::to_string(set));
          if (j != p.attributes.end() && w != p.attributes.end()) {
            js[set] = readAccessor(j->second);
            ws[set] = readAccessor(w->second);
          }
        }
        for (size_t v = 0; v < vcount; ++v) {
          double sum = 0.0;
          const size_t first = out.jointWeights.size();
          for (size_t set = 0; set < jointSets; ++set)
            for (size_t c = 0; c < 4; ++c) {
              const bool have = !js[set].empty();
              const double w = have ? ws[set][4 * v + c] : 0.0;
              if (!finite(w) || w < 0.0)
                fail("WEIGHTS_" + std::to_string(set) + " has a negative or non-finite weight",
                     where);
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
      for (size_t ti = 0; ti < targets; ++ti) {
        const auto* t = ti < p.targets.size() ? &p.targets[ti] : nullptr;
        std::vector<double> dp, dn;
        if (t && t->count("POSITION")) dp = readAccessor(t->at("POSITION"));
        if (t && t->count("NORMAL")) dn = readAccessor(t->at("NORMAL"));
        for (size_t v = 0; v < vcount; ++v) {
          glm::vec3 d(0.0f), n(0.0f);
          if (!dp.empty()) d = glm::vec3(dp[3 * v], dp[3 * v + 1], dp[3 * v + 2]);
          if (!dn.empty()) n = glm::vec3(dn[3 * v], dn[3 * v + 1], dn[3 * v + 2]);
          if (!finite(d.x) || !finite(d.y) || !finite(d.z) || !finite(n.x) || !finite(n.y) ||
              !finite(n.z))
            fail("morph target " + std::to_string(ti) + " is not finite", where);
          out.morphPositions[ti].push_back(d);
          if (targetNormals) out.morphNormals[ti].push_back(n);
        }
      }
      if (anyTangents) {
        std::vector<double> tan;
        if (const auto it = p.attributes.find("TANGENT"); it != p.attributes.end())
          tan = readAccessor(it->second);
        for (size_t v = 0; v < vcount; ++v) {
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
      const uint32_t mat = uint32_t(materialIndex(p.material));
      for (uint32_t i : idx) out.indices.push_back(base + i);
      out.materials.insert(out.materials.end(), idx.size() / 3, mat);
      normalUvSet.insert(normalUvSet.end(), idx.size() / 3,
                         uint8_t(scene_.materials[mat].normalTexture.texCoord == 1));
    }
    // glTF asks for MikkTSpace tangents where a normal-mapped mesh has none.
    if (!anyTangents && anyNormalMap) generateTangents(out, normalUvSet);
    return out;
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
      glm::vec3 n = sign * (cof * mesh.normals[v]);
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
      if (const Value* e = extension(src.extensions, "KHR_materials_transmission"))
        if (const Value* s = member(*e, "transmissionFactor"))
          m.transmission = float(s->GetNumberAsDouble());
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
        // The coat shades with the surface's normal (and its normal map).
        warnTextures(*e, {"clearcoatNormalTexture"}, where);
      }
      scene_.materials.push_back(m);
    }
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
    checkTextureInfo(index->GetNumberAsInt(), name, where);
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
    } else if (const auto it = images_.encoded.find(t.source); it != images_.encoded.end()) {
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
        const std::vector<double> m = readAccessor(s.inverseBindMatrices);
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
    scene_.path = path_;
    buildNodes();
    buildMaterials();
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

  std::string path_;
  LoadOptions options_;
  std::vector<uint8_t> bytes_;  // the whole file, until parsed
  bool inMemory_ = false;
  bool binary_ = false;
  tinygltf::Model model_;
  ImageBytes images_;
  Scene scene_;
  std::set<int> accessorChecked_;
  std::vector<int> parents_;
  std::map<int, std::optional<TriangleMesh>> meshCache_;
  std::map<std::pair<int, bool>, int> textureIndex_;
  int defaultMaterial_ = -1;
  std::set<int> skippedModes_;
};

}  // namespace

bool isSupportedExtension(const std::string& name) {
  static const std::set<std::string> supported = {
      "KHR_materials_emissive_strength", "KHR_materials_transmission", "KHR_materials_ior",
      "KHR_materials_specular",          "KHR_materials_clearcoat",    "KHR_materials_volume",
      "KHR_texture_transform",           "KHR_lights_punctual"};
  return supported.count(name) > 0;
}

Scene loadScene(const std::string& path, const LoadOptions& options) {
  return Loader(path, options).load();
}

Scene loadSceneFromMemory(const std::string& bytes, const std::string& path,
                          const LoadOptions& options) {
  return Loader(path, bytes, options).load();
}

}  // namespace pr
