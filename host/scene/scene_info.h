// What `pathreuse info` prints about a loaded scene: a short human summary or JSON.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "scene/scene.h"

namespace pr {

nlohmann::ordered_json sceneInfoJson(const Scene& scene, double fps);
std::string sceneInfoText(const Scene& scene, double fps);

}  // namespace pr
