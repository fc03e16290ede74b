#include "scene/animation.h"

#include <algorithm>
#include <cmath>

namespace pr {

namespace {

// Where t falls: clamped to the first or last key, or between keys k and k+1 at fraction u.
struct KeySpan {
  size_t k = 0;
  float u = 0.0f;
  float dt = 0.0f;
  bool clamped = true;  // then only k is meaningful
};

KeySpan locate(const std::vector<float>& times, double t) {
  KeySpan span;
  if (times.empty() || !(t > times.front())) return span;  // also NaN t: first key
  if (t >= times.back()) {
    span.k = times.size() - 1;
    return span;
  }
  // First key strictly after t; the loader guarantees strictly increasing times.
  const auto it = std::upper_bound(times.begin(), times.end(), static_cast<float>(t));
  size_t next = static_cast<size_t>(it - times.begin());
  if (next == 0) next = 1;
  if (next >= times.size()) {
    span.k = times.size() - 1;
    return span;
  }
  span.k = next - 1;
  span.dt = times[next] - times[span.k];
  span.u = span.dt > 0.0f ? static_cast<float>((t - times[span.k]) / span.dt) : 0.0f;
  span.u = std::clamp(span.u, 0.0f, 1.0f);
  span.clamped = false;
  return span;
}

// The key value of key k (the middle of the three CUBICSPLINE values).
glm::vec4 keyValue(const AnimationSampler& s, size_t k) {
  if (s.interpolation == Interpolation::CubicSpline) return s.values[3 * k + 1];
  return s.values[k];
}

// glTF spec Appendix C: Hermite spline with tangents scaled by the key interval.
glm::vec4 hermite(const AnimationSampler& s, const KeySpan& span) {
  const float u = span.u, u2 = u * u, u3 = u2 * u;
  const glm::vec4 v0 = s.values[3 * span.k + 1];
  const glm::vec4 b0 = s.values[3 * span.k + 2];    // out-tangent of key k
  const glm::vec4 a1 = s.values[3 * (span.k + 1)];  // in-tangent of key k+1
  const glm::vec4 v1 = s.values[3 * (span.k + 1) + 1];
  return (2.0f * u3 - 3.0f * u2 + 1.0f) * v0 + span.dt * (u3 - 2.0f * u2 + u) * b0 +
         (-2.0f * u3 + 3.0f * u2) * v1 + span.dt * (u3 - u2) * a1;
}

glm::quat toQuat(const glm::vec4& v) {
  return glm::quat(v.w, v.x, v.y, v.z);
}

glm::quat normalisedOrIdentity(const glm::quat& q) {
  const float len = glm::length(q);
  if (!(len > 0.0f) || !std::isfinite(len)) return glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
  return q / len;
}

}  // namespace

glm::quat slerpShortest(const glm::quat& a, const glm::quat& b, float u) {
  glm::quat end = b;
  float cosTheta = glm::dot(a, b);
  if (cosTheta < 0.0f) {  // q and -q are the same rotation: take the shorter way round
    end = -b;
    cosTheta = -cosTheta;
  }
  if (cosTheta > 0.9995f) return normalisedOrIdentity(a + u * (end - a));  // nearly equal
  const float theta = std::acos(std::min(cosTheta, 1.0f));
  const float sinTheta = std::sin(theta);
  return normalisedOrIdentity((std::sin((1.0f - u) * theta) / sinTheta) * a +
                              (std::sin(u * theta) / sinTheta) * end);
}

glm::vec4 sampleRaw(const AnimationSampler& s, double t) {
  if (s.times.empty()) return glm::vec4(0.0f);
  const KeySpan span = locate(s.times, t);
  if (span.clamped || s.interpolation == Interpolation::Step) return keyValue(s, span.k);
  if (s.interpolation == Interpolation::CubicSpline) return hermite(s, span);
  return glm::mix(s.values[span.k], s.values[span.k + 1], span.u);
}

glm::vec3 sampleVec3(const AnimationSampler& s, double t) {
  return glm::vec3(sampleRaw(s, t));
}

glm::quat sampleQuat(const AnimationSampler& s, double t) {
  if (s.times.empty()) return glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
  const KeySpan span = locate(s.times, t);
  if (!span.clamped && s.interpolation == Interpolation::Linear) {
    return slerpShortest(normalisedOrIdentity(toQuat(s.values[span.k])),
                         normalisedOrIdentity(toQuat(s.values[span.k + 1])), span.u);
  }
  return normalisedOrIdentity(toQuat(sampleRaw(s, t)));
}

}  // namespace pr
