// JSON type checks that tinygltf skips: it silently ignores a property of the wrong type
// (a string where a number belongs, an object where an array belongs), which would load a
// broken file as if the property were absent.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

namespace pr {

// "" when the glTF JSON's properties have the types the glTF 2.0 schema gives them, else
// the first problem as "what is wrong (where)", e.g. "\"name\" must be a string (meshes[0])".
std::string checkGltfSchema(const nlohmann::json& gltf);

}  // namespace pr
