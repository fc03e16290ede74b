// A glTF animation's samplers read into the scene's AnimationSampler, key times and values
// checked as they are read.
#pragma once

#include <string>
#include <vector>

#include "scene/animation.h"
#include "scene/gltf_document.h"

namespace pr::gltf {

// Sampler `index` of `anim` (a translation, rotation or scale channel's), its output accessor
// checked by validation.
AnimationSampler readSampler(const Document& doc, const tinygltf::Animation& anim, int index,
                             const std::string& where);

// A morph weights sampler (n scalars per key, 3n for CUBICSPLINE) as ceil(n / 4) samplers of
// vec4s, targets 4k .. 4k + 3 in part k.
std::vector<AnimationSampler> readWeightSamplers(const Document& doc,
                                                 const tinygltf::Animation& anim, int index,
                                                 const std::string& where);

}  // namespace pr::gltf
