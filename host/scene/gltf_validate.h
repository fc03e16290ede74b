// Validating a parsed glTF document: every index, range, count and value the conversion to a
// Scene relies on, in a fixed order, so that the first problem found is always the same one.
#pragma once

#include <string>
#include <vector>

#include "scene/animation.h"
#include "scene/gltf_document.h"

namespace pr::gltf {

// What validation establishes on the way, for the conversion.
struct Validated {
  std::vector<int> parents;           // per node: its parent node, -1 for none
  std::vector<Animation> animations;  // those with a channel we play, read and checked
};

// Checks the whole document (fail() on the first problem, warn() for what is ignored). May
// clear references of unused textures that point nowhere.
Validated validate(Document& doc);

// A textureInfo's index: -1 (none) or an existing texture.
void checkTextureInfo(const Document& doc, int index, const std::string& what,
                      const std::string& where);

}  // namespace pr::gltf
