// Keyframe animation of node transforms (glTF 2.0 animations): samplers and their
// interpolation (LINEAR with slerp for rotations, STEP, CUBICSPLINE as in the glTF spec's
// Appendix C), and channels that target a node's translation, rotation or scale.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

namespace pr {

enum class Interpolation : uint32_t { Linear = 0, Step = 1, CubicSpline = 2 };
enum class AnimationPath : uint32_t { Translation = 0, Rotation = 1, Scale = 2, Weights = 3 };

// Key times (strictly increasing, finite) and values. Values hold 3 (translation, scale:
// w unused) or 4 (rotation quaternion x, y, z, w) components, or 4 morph weights (a weights
// channel is split into one sampler per 4 targets). For CUBICSPLINE each key has three values
// in a row: in-tangent, value, out-tangent.
struct AnimationSampler {
  std::vector<float> times;
  std::vector<glm::vec4> values;
  Interpolation interpolation = Interpolation::Linear;

  double startTime() const { return times.empty() ? 0.0 : times.front(); }
  double endTime() const { return times.empty() ? 0.0 : times.back(); }
};

struct AnimationChannel {
  int sampler = 0;  // index into the animation's samplers
  int node = -1;
  AnimationPath path = AnimationPath::Translation;
  int firstWeight = 0;  // Weights: the sampler's 4 values are morph weights firstWeight...+3
};

struct Animation {
  std::string name;
  std::vector<AnimationSampler> samplers;
  std::vector<AnimationChannel> channels;
};

// Which channel of which animation drives a node.
struct ChannelRef {
  uint32_t animation = 0;
  uint32_t channel = 0;
};

// The sampler's value at time t (seconds): before the first key the first value, after the
// last key the last value. Components beyond those the path uses are meaningless.
glm::vec4 sampleRaw(const AnimationSampler& s, double t);
glm::vec3 sampleVec3(const AnimationSampler& s, double t);
// Rotations: slerp along the shortest arc for LINEAR, normalised result for all modes.
glm::quat sampleQuat(const AnimationSampler& s, double t);

// Shortest-arc spherical interpolation between unit quaternions.
glm::quat slerpShortest(const glm::quat& a, const glm::quat& b, float u);

}  // namespace pr
