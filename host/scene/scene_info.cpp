#include "scene/scene_info.h"

#include <algorithm>
#include <sstream>

namespace pr {

namespace {

// A clip's length in the file: its samplers' last key, whether or not its channels play.
double clipDuration(const Animation& a) {
  double d = 0.0;
  for (const AnimationSampler& s : a.samplers) d = std::max(d, s.endTime());
  return d;
}

nlohmann::ordered_json vec3Json(const glm::vec3& v) {
  return {v.x, v.y, v.z};
}
// Dynamic meshes that deform: skinned ones (morph targets or not), morphing-only ones.
void deformingCounts(const Scene& scene, size_t* skinned, size_t* morphing) {
  for (size_t m = 0; m < scene.dynamicMeshes.size(); ++m) {
    if (!scene.meshDeforms(m)) continue;
    if (scene.deformers[m].skin >= 0)
      ++*skinned;
    else
      ++*morphing;
  }
}

}  // namespace

nlohmann::ordered_json sceneInfoJson(const Scene& scene, double fps) {
  nlohmann::ordered_json j;
  j["file"] = scene.path;
  j["triangles"] = {{"static", scene.staticTriangleCount()},
                    {"dynamic", scene.dynamicTriangleCount()},
                    {"static_per_mesh", scene.staticMeshTriangles}};
  size_t skinned = 0, morphing = 0;
  deformingCounts(scene, &skinned, &morphing);
  j["instances"] = {{"dynamic", scene.instances.size()},
                    {"dynamic_meshes", scene.dynamicMeshes.size()},
                    {"skinned_meshes", skinned},
                    {"morphing_meshes", morphing},
                    {"deforming_triangles", scene.deformingTriangleCount()}};
  j["materials"] = scene.materials.size();
  j["textures"] = scene.textures.size();
  j["lights"] = {{"emissive_triangles", scene.emissiveTriangleCount()},
                 {"emissive_triangles_dynamic", scene.dynamicEmissiveTriangleCount()},
                 {"punctual", scene.lights.size()},
                 {"punctual_dynamic", scene.dynamicLightCount()}};
  j["cameras"] = scene.fileCameraCount();
  j["default_camera"] = scene.fileCameraCount() == 0;
  j["animation"] = {
      {"duration_s", scene.animationDuration()}, {"frames", scene.frameCount(fps)}, {"fps", fps}};
  nlohmann::ordered_json clips = nlohmann::ordered_json::array();
  for (const Animation& a : scene.animations)
    clips.push_back(
        {{"name", a.name}, {"duration_s", clipDuration(a)}, {"plays", !a.channels.empty()}});
  j["animation"]["clips"] = clips;
  const Bounds& b = scene.bounds;
  if (b.empty()) {
    j["bounds"] = {{"min", nullptr}, {"max", nullptr}};
  } else {
    j["bounds"] = {{"min", vec3Json(b.min)}, {"max", vec3Json(b.max)}};
  }
  j["warnings"] = scene.warnings;
  return j;
}

std::string sceneInfoText(const Scene& scene, double fps) {
  std::ostringstream s;
  s << "file:       " << scene.path << "\n";
  s << "triangles:  " << scene.staticTriangleCount() << " static (SSG), "
    << scene.dynamicTriangleCount() << " dynamic (DSG)";
  if (scene.staticMeshTriangles != scene.staticTriangleCount())
    s << "; " << scene.staticMeshTriangles << " static counting each mesh once";
  s << "\n";
  s << "instances:  " << scene.instances.size() << " dynamic, of " << scene.dynamicMeshes.size()
    << " meshes\n";
  size_t skinned = 0, morphing = 0;
  deformingCounts(scene, &skinned, &morphing);
  if (skinned + morphing > 0)
    s << "deforming:  " << skinned << " skinned, " << morphing << " morphing mesh(es), "
      << scene.deformingTriangleCount() << " triangles (dynamic, deformed every frame)\n";
  s << "materials:  " << scene.materials.size() << ", textures: " << scene.textures.size() << "\n";
  s << "lights:     " << scene.emissiveTriangleCount() << " emissive triangles ("
    << scene.dynamicEmissiveTriangleCount() << " dynamic), " << scene.lights.size() << " punctual ("
    << scene.dynamicLightCount() << " dynamic)\n";
  s << "cameras:    " << scene.fileCameraCount();
  if (scene.fileCameraCount() == 0) s << " (a default camera frames the scene)";
  s << "\n";
  const double d = scene.animationDuration();
  s << "animation:  ";
  if (d > 0.0)
    s << d << " s, " << scene.frameCount(fps) << " frames at " << fps << " fps\n";
  else
    s << "none (1 frame)\n";
  if (scene.animations.size() > 1) {
    s << "clips:     ";
    for (size_t a = 0; a < scene.animations.size(); ++a) {
      const Animation& c = scene.animations[a];
      s << (a ? ", " : " ") << a << (c.name.empty() ? "" : " " + c.name) << " " << clipDuration(c)
        << " s"
        << (c.channels.empty() ? " (not played: --animation " + std::to_string(a) + ")" : "");
    }
    s << "\n";
  }
  const Bounds& b = scene.bounds;
  s << "bounds:     ";
  if (b.empty())
    s << "empty (nothing to render)\n";
  else
    s << "[" << b.min.x << ", " << b.min.y << ", " << b.min.z << "] .. [" << b.max.x << ", "
      << b.max.y << ", " << b.max.z << "]\n";
  for (const std::string& w : scene.warnings) s << w << "\n";
  return s.str();
}

}  // namespace pr
