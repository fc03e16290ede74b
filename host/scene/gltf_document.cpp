#include "scene/gltf_document.h"

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "scene/gltf_schema.h"
#include "util/error.h"
#include "util/input_file.h"

namespace pr::gltf {

namespace {

namespace fs = std::filesystem;

// Deeper JSON than this is refused before any parser sees it: tinygltf's parser recurses once
// per level. glTF itself needs 6 levels; extras and extensions rarely more than a dozen.
constexpr int kMaxJsonDepth = 256;

// The deepest nesting of arrays and objects in `json`, counting no further than `limit + 1`.
int jsonDepth(const uint8_t* json, size_t length, int limit) {
  int depth = 0, deepest = 0;
  bool inString = false;
  for (size_t i = 0; i < length; ++i) {
    const uint8_t c = json[i];
    if (inString) {
      if (c == '\\')
        ++i;
      else if (c == '"')
        inString = false;
    } else if (c == '"') {
      inString = true;
    } else if (c == '[' || c == '{') {
      deepest = std::max(deepest, ++depth);
      if (deepest > limit) break;
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return deepest;
}

// How external buffers and images are read: through the one opener, and only from the scene's
// folder and below unless the options allow more. tinygltf tries the URI beside the scene, then
// beside the working directory; only the first is a file of the scene.
struct ExternalFiles {
  Document* doc;
  std::string baseDir;
};

bool externalFileExists(const std::string& path, void* user) {
  const auto* files = static_cast<const ExternalFiles*>(user);
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(path, ec))) return false;
  if (files->doc->options.allowOutsideUris) return true;
  const std::string& base = files->baseDir;
  const std::string prefix = !base.empty() && base.back() == '/' ? base : base + "/";
  return path.compare(0, prefix.size(), prefix) == 0;
}

std::string expandFilePath(const std::string& path, void*) {
  return path;  // URIs are not expanded (no ~, no variables)
}

bool readExternalFile(std::vector<unsigned char>* out, std::string*, const std::string& path,
                      void* user) {
  const auto* files = static_cast<const ExternalFiles*>(user);
  if (!files->doc->options.allowOutsideUris) {
    const std::string why = whyOutsideRoot(files->baseDir, path);
    if (!why.empty()) files->doc->fail("file " + path + " " + why);
  }
  try {
    *out = readInputFile(path, kMaxBufferFileBytes);
  } catch (const InputError& e) {
    files->doc->fail(std::string("cannot load a file it names: ") + e.what());
  }
  if (files->doc->options.digestInputs) files->doc->inputs.add(path).add(out->data(), out->size());
  files->doc->inputFiles.push_back(path);
  return true;
}

bool refuseWrite(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  if (err) *err = "writing is not supported";
  return false;
}

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
    if (doc_.options.digestInputs) doc_.inputs.add(doc_.path).add(bytes.data(), bytes.size());
    if (!inMemory_) doc_.inputFiles.push_back(doc_.path);

    std::string ext = fs::path(doc_.path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return std::tolower(c); });
    binary_ = ext == ".glb" || (bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0);

    std::string baseDir = fs::path(doc_.path).parent_path().string();
    if (baseDir.empty()) baseDir = ".";

    preflight(bytes);
    tinygltf::TinyGLTF gltf;
    gltf.SetImageLoader(&keepImageBytes, &doc_.images);
    ExternalFiles files{&doc_, baseDir};
    tinygltf::FsCallbacks callbacks{&externalFileExists, &expandFilePath, &readExternalFile,
                                    &refuseWrite, &files};
    gltf.SetFsCallbacks(callbacks);
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
  void readFileBytes() { bytes_ = readInputFile(doc_.path, kMaxSceneFileBytes); }

  // Before tinygltf: the JSON's types (tinygltf silently drops a property of the wrong type),
  // the version and the required extensions, so these get precise messages.
  void preflight(const std::vector<uint8_t>& bytes) {
    const uint8_t* json = bytes.data();
    size_t length = bytes.size();
    if (binary_) {
      // Header (magic, version, length) then the JSON chunk (length, type). A broken container
      // is left to tinygltf's checks, which name the problem.
      if (bytes.size() < 20 || std::memcmp(bytes.data(), "glTF", 4) != 0) return;
      uint32_t version = 0;
      std::memcpy(&version, bytes.data() + 4, 4);
      if (version != 2)
        fail("GLB container version " + std::to_string(version) + " (only version 2 is supported)");
      uint32_t chunkLength = 0, chunkType = 0;
      std::memcpy(&chunkLength, bytes.data() + 12, 4);
      std::memcpy(&chunkType, bytes.data() + 16, 4);
      if (chunkType != 0x4E4F534Au || chunkLength > bytes.size() - 20) return;
      json = bytes.data() + 20;
      length = chunkLength;
    }
    if (jsonDepth(json, length, kMaxJsonDepth) > kMaxJsonDepth)
      fail("JSON nested more than " + std::to_string(kMaxJsonDepth) +
           " levels deep (the limit pathreuse reads)");
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
