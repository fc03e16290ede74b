#include "scene/gltf_document.h"

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "scene/gltf_schema.h"
#include "util/error.h"

namespace pr::gltf {

namespace {

namespace fs = std::filesystem;

bool keepImageBytes(tinygltf::Image* image, const int index, std::string*, std::string*, int, int,
                    const unsigned char* bytes, int size, void* user) {
  if (image->bufferView >= 0 || !bytes || size <= 0) return true;
  static_cast<ImageBytes*>(user)->encoded[index].assign(bytes, bytes + size);
  return true;
}

// Reads and parses a glTF file (.gltf text or GLB) into the document's model.
class Parser : Stage {
 public:
  explicit Parser(Document& doc) : Stage(doc) {}
  // In memory: `bytes` stand for the file at doc.path.
  Parser(Document& doc, const std::string& bytes)
      : Stage(doc), bytes_(bytes.begin(), bytes.end()), inMemory_(true) {}

  void parse() {
    if (!inMemory_) readFileBytes();
    const std::vector<uint8_t>& bytes = bytes_;
    if (bytes.empty()) fail("file is empty");

    std::string ext = fs::path(doc_.path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return std::tolower(c); });
    binary_ = ext == ".glb" || (bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0);

    std::string baseDir = fs::path(doc_.path).parent_path().string();
    if (baseDir.empty()) baseDir = ".";

    preflight(bytes);
    tinygltf::TinyGLTF gltf;
    gltf.SetImageLoader(&keepImageBytes, &doc_.images);
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

 private:
  void readFileBytes() {
    std::error_code ec;
    const fs::file_status st = fs::status(doc_.path, ec);
    if (ec || !fs::exists(st)) fail("no such file");
    if (fs::is_directory(st)) fail("is a directory, not a glTF file");
    std::ifstream in(doc_.path, std::ios::binary);
    if (!in) fail("cannot open file");
    bytes_.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    if (in.bad()) fail("cannot read file");
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

  std::vector<uint8_t> bytes_;  // the whole file, until parsed
  bool inMemory_ = false;
  bool binary_ = false;
};

}  // namespace

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

int nodeLight(const tinygltf::Node& n) {
  const Value* e = extension(n.extensions, "KHR_lights_punctual");
  if (!e) return -1;
  const Value* l = member(*e, "light");
  return l && l->IsNumber() ? l->GetNumberAsInt() : -2;
}

Document::Document(std::string path, const LoadOptions& options)
    : path(std::move(path)), options(options) {}

void Document::fail(const std::string& what, const std::string& where) const {
  std::string msg = path + ": " + what;
  if (!where.empty()) msg += " (" + where + ")";
  throw InputError(oneLine(msg));
}

void Document::warn(const std::string& line) {
  const std::string w = oneLine(path + ": warning: " + line);
  if (std::find(warnings.begin(), warnings.end(), w) != warnings.end()) return;
  warnings.push_back(w);
  std::ostream* out = options.warningStream;
  if (!out && options.printWarnings) out = &std::cerr;
  if (out) *out << w << "\n";
}

void parseFile(Document& doc) {
  Parser(doc).parse();
}

void parseBytes(Document& doc, const std::string& bytes) {
  Parser(doc, bytes).parse();
}

}  // namespace pr::gltf
