#include "scene/gltf_animation.h"

#include <cmath>
#include <cstdio>

#include "scene/gltf_accessors.h"

namespace pr::gltf {

namespace {

// A sampler's interpolation and key times (finite, strictly increasing; CUBICSPLINE needs 2
// keys, as the glTF spec and its validator's ANIMATION_SAMPLER_INPUT_ACCESSOR_TOO_FEW_ELEMENTS
// say), without its values.
AnimationSampler samplerKeys(const Document& doc, const tinygltf::AnimationSampler& s,
                             const std::string& where) {
  AnimationSampler out;
  out.interpolation = s.interpolation == "STEP"          ? Interpolation::Step
                      : s.interpolation == "CUBICSPLINE" ? Interpolation::CubicSpline
                                                         : Interpolation::Linear;
  const std::vector<double> in = readAccessor(doc.model, s.input);
  if (out.interpolation == Interpolation::CubicSpline && in.size() < 2)
    doc.fail("CUBICSPLINE needs at least 2 keys, the input has " + std::to_string(in.size()),
             where);
  for (size_t i = 0; i < in.size(); ++i) {
    if (!finite(in[i])) doc.fail("input time " + std::to_string(i) + " is not finite", where);
    if (std::fabs(in[i]) > kMaxAnimationSeconds) {
      char t[32];
      std::snprintf(t, sizeof t, "%g", in[i]);
      doc.fail("input time " + std::to_string(i) + " is " + t + " s, beyond the " +
                   std::to_string(int(kMaxAnimationSeconds)) + " s (11.6 days) pathreuse animates",
               where);
    }
    if (i > 0 && !(float(in[i]) > float(in[i - 1])))
      doc.fail("input times are not strictly increasing at key " + std::to_string(i), where);
    out.times.push_back(float(in[i]));
  }
  return out;
}

}  // namespace

AnimationSampler readSampler(const Document& doc, const tinygltf::Animation& anim, int index,
                             const std::string& where) {
  const auto& s = anim.samplers[size_t(index)];
  AnimationSampler out = samplerKeys(doc, s, where);
  const std::vector<float>& in = out.times;
  const auto& oa = doc.model.accessors[size_t(s.output)];
  const size_t perKey = out.interpolation == Interpolation::CubicSpline ? 3 : 1;
  if (oa.count != in.size() * perKey)
    doc.fail("output has " + std::to_string(oa.count) + " values for " + std::to_string(in.size()) +
                 " keys" + (perKey == 3 ? " (CUBICSPLINE needs 3 per key)" : ""),
             where);
  const size_t nc = componentCount(oa.type);
  const std::vector<double> values = readAccessor(doc.model, s.output);
  for (size_t i = 0; i < oa.count; ++i) {
    glm::vec4 v(0.0f);
    for (size_t c = 0; c < nc && c < 4; ++c) {
      const double x = values[i * nc + c];
      if (!finite(x) || std::abs(x) > 3.0e38)
        doc.fail("output value " + std::to_string(i) + " is not finite", where);
      v[int(c)] = float(x);
    }
    out.values.push_back(v);
  }
  return out;
}

std::vector<AnimationSampler> readWeightSamplers(const Document& doc,
                                                 const tinygltf::Animation& anim, int index,
                                                 const std::string& where) {
  const auto& s = anim.samplers[size_t(index)];
  const AnimationSampler proto = samplerKeys(doc, s, where);
  const std::vector<float>& in = proto.times;
  const size_t perKey = proto.interpolation == Interpolation::CubicSpline ? 3 : 1;
  const std::vector<double> values = readAccessor(doc.model, s.output);
  const size_t slots = in.size() * perKey;
  if (slots == 0 || values.size() % slots != 0 || values.empty())
    doc.fail("output has " + std::to_string(values.size()) + " weights, not a multiple of the " +
                 std::to_string(slots) + " key values",
             where);
  const size_t n = values.size() / slots;
  for (double v : values)
    if (!finite(v)) doc.fail("output has a weight that is not finite", where);
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

}  // namespace pr::gltf
