// Loading a glTF 2.0 file (.gltf with external or data: buffers, or .glb) into a Scene, with
// the static/dynamic split of docs/design.md section 3. Broken input never crashes: every index,
// range and reference is checked and the first problem becomes one pr::InputError line
// "FILE: what is wrong (which object)".
#pragma once

#include <iosfwd>
#include <string>

#include "scene/scene.h"

namespace pr {

struct LoadOptions {
  // Where warnings (skipped primitives, unsupported features) are printed, one line each;
  // nullptr = silent. They are kept in Scene::warnings either way.
  std::ostream* warningStream = nullptr;
  bool printWarnings = true;  // to std::cerr when warningStream is null
  // Buffers and images the file names are read from its folder and below only, unless this is
  // set (--allow-outside-uris): a scene from elsewhere must not read /etc/passwd into a frame.
  bool allowOutsideUris = false;
  // Hash the content of every file read into Scene::inputDigest (what a resume history is keyed
  // by); off, the cost of hashing a scene's textures is not paid.
  bool digestInputs = false;
  // --animation: the one animation that plays, by index or name; "" = all of them (the first
  // where two animate the same node's same property).
  std::string animation;
  // --emit-base-color: materials, by name or index (comma-separated; A-B a range of indices),
  // that emit their base colour (factor and texture) at emitStrength, as a sky dome or backdrop
  // meant to be drawn unlit would look; "" = none.
  std::string emitBaseColor;
  float emitStrength = 1.0f;
};

Scene loadScene(const std::string& path, const LoadOptions& options = {});

// The same checks on a file's bytes already in memory (the fuzz target uses it). `path` names
// the file in errors, its extension or the GLB magic says whether the bytes are GLB, and
// external buffer and image URIs resolve beside it.
Scene loadSceneFromMemory(const std::string& bytes, const std::string& path,
                          const LoadOptions& options = {});

// The extensions a file may list in extensionsRequired.
bool isSupportedExtension(const std::string& name);

}  // namespace pr
