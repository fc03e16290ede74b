// What the stages of loading a glTF file share (parsing here, then gltf_validate and the
// conversion in gltf_loader.cpp): the parsed model, the file's path, the options, the encoded
// image bytes, the warnings, fail() and warn(), and small helpers over tinygltf's values.
#pragma once

#include <cmath>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <tiny_gltf.h>

#include "scene/gltf_loader.h"
#include "util/hash.h"

namespace pr::gltf {

using tinygltf::Value;

constexpr double kPi = 3.14159265358979323846;

// Encoded bytes of images given by uri (data: or file), keyed by image index. Images in
// buffer views are read by us after their ranges are checked: tinygltf would read them
// without checking.
struct ImageBytes {
  std::map<int, std::vector<uint8_t>> encoded;
};

// A glTF file being loaded.
struct Document {
  Document(std::string path, const LoadOptions& options);

  // Throws InputError "path: what (where)" as one line.
  [[noreturn]] void fail(const std::string& what, const std::string& where = "") const;
  // Prints "path: warning: line" once per distinct line and keeps it in `warnings`.
  void warn(const std::string& line);

  std::string path;
  LoadOptions options;
  // The content of every file read (the scene, its buffers and images), path by path: what a
  // render's derived files (the resume history) must have been made from.
  Hash128 inputs;
  std::vector<std::string> inputFiles;  // their paths
  tinygltf::Model model;
  ImageBytes images;
  std::vector<std::string> warnings;
};

// Reads the file at doc.path and parses it into doc.model and doc.images.
void parseFile(Document& doc);
// The same for the file's bytes already in memory (doc.path names the file in errors, and
// external URIs resolve beside it).
void parseBytes(Document& doc, const std::string& bytes);

// A stage of loading: the document's model and its fail() and warn() under short names.
class Stage {
 protected:
  explicit Stage(Document& doc) : doc_(doc), model_(doc.model) {}

  [[noreturn]] void fail(const std::string& what, const std::string& where = "") const {
    doc_.fail(what, where);
  }
  void warn(const std::string& line) const { doc_.warn(line); }

  Document& doc_;
  tinygltf::Model& model_;
};

// One line: newlines and other control characters become spaces, runs collapse.
std::string oneLine(const std::string& s);

// "kind index" and the name in quotes, if it has one: node 3 "Arm".
std::string named(const char* kind, int index, const std::string& name);

inline bool finite(double v) {
  return std::isfinite(v);
}

bool allFinite(const std::vector<double>& v);
// An object's member, or an extension in an extension map; nullptr where absent.
const Value* member(const Value& obj, const char* key);
const Value* extension(const tinygltf::ExtensionMap& ext, const char* name);

// The KHR_lights_punctual light a node places: -1 for none, -2 when it is not a number.
int nodeLight(const tinygltf::Node& n);

}  // namespace pr::gltf
