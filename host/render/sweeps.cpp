#include "render/sweeps.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <utility>

#include "accel/bvh_builder.h"

namespace pr {

using accel::Aabb;

namespace {

void appendRecord(const Aabb& b, float pad, uint32_t parts, std::vector<float>* records) {
  for (int a = 0; a < 3; ++a) records->push_back(b.lo[a] - pad - 1e-4f * std::fabs(b.lo[a]));
  for (int a = 0; a < 3; ++a) records->push_back(b.hi[a] + pad + 1e-4f * std::fabs(b.hi[a]));
  records->push_back(float(parts));  // exact: parts < 2^24
}

}  // namespace

std::vector<std::vector<uint32_t>> sweepParts(const std::vector<glm::vec3>& positions,
                                              const std::vector<uint32_t>& indices, int levels) {
  const size_t n = indices.size() / 3;
  std::vector<uint32_t> tris(n);
  std::iota(tris.begin(), tris.end(), 0u);
  std::vector<glm::vec3> centre(n);
  for (size_t t = 0; t < n; ++t)
    centre[t] = (positions[indices[3 * t]] + positions[indices[3 * t + 1]] +
                 positions[indices[3 * t + 2]]) /
                3.0f;
  std::vector<std::pair<size_t, size_t>> ranges = {{0, n}};
  for (int level = 0; level < levels; ++level) {
    std::vector<std::pair<size_t, size_t>> next;
    for (const auto& [a, b] : ranges) {
      if (b - a <= 8) {
        next.emplace_back(a, b);
        continue;
      }
      Aabb box;
      for (size_t i = a; i < b; ++i) box.grow(centre[tris[i]]);
      const glm::vec3 e = box.hi - box.lo;
      const int axis = e.x >= e.y && e.x >= e.z ? 0 : e.y >= e.z ? 1 : 2;
      const size_t mid = (a + b) / 2;
      std::nth_element(tris.begin() + long(a), tris.begin() + long(mid), tris.begin() + long(b),
                       [&](uint32_t x, uint32_t y) { return centre[x][axis] < centre[y][axis]; });
      next.emplace_back(a, mid);
      next.emplace_back(mid, b);
    }
    ranges = std::move(next);
  }
  std::vector<std::vector<uint32_t>> parts;
  for (const auto& [a, b] : ranges) {
    if (a == b) continue;
    std::vector<uint32_t> v;
    for (size_t i = a; i < b; ++i)
      for (int c = 0; c < 3; ++c) v.push_back(indices[3 * size_t(tris[i]) + size_t(c)]);
    std::sort(v.begin(), v.end());
    v.erase(std::unique(v.begin(), v.end()), v.end());
    parts.push_back(std::move(v));
  }
  return parts;
}

void appendInstanceSweep(const std::vector<std::vector<uint32_t>>& parts,
                         const std::vector<glm::mat4>& transforms,
                         const std::vector<const std::vector<glm::vec3>*>& positions, float pad,
                         std::vector<float>* records) {
  if (parts.empty() || transforms.empty() || positions.empty()) return;
  std::vector<Aabb> boxes(parts.size());
  Aabb whole;
  for (size_t p = 0; p < parts.size(); ++p) {
    for (size_t k = 0; k < transforms.size(); ++k) {
      const std::vector<glm::vec3>& at = *positions[positions.size() == 1 ? 0 : k];
      for (uint32_t v : parts[p]) boxes[p].grow(glm::vec3(transforms[k] * glm::vec4(at[v], 1.0f)));
    }
    whole.grow(boxes[p]);
  }
  if (whole.empty()) return;
  appendRecord(whole, pad, uint32_t(parts.size()), records);
  for (const Aabb& b : boxes) appendRecord(b, pad, 0, records);
}

void appendBoxSweep(const glm::vec3& lo, const glm::vec3& hi, float pad,
                    std::vector<float>* records) {
  Aabb b;
  b.lo = lo;
  b.hi = hi;
  appendRecord(b, pad, 0, records);
}

}  // namespace pr
