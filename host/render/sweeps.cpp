#include "render/sweeps.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <utility>

#include "accel/bvh_builder.h"
#include "render/median_split.h"

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
      const size_t mid = size_t(medianSplit(tris.begin() + long(a), tris.begin() + long(b),
                                            [&](uint32_t t, int axis) { return centre[t][axis]; }) -
                                tris.begin());
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

namespace {

struct SweepTreeBuilder {
  const std::vector<float>& in;
  std::vector<size_t> tops;  // first record of each top-level subtree
  std::vector<float> out;
  size_t leafSize;

  const float* record(size_t k) const { return &in[k * kSweepRecordFloats]; }
  size_t size(size_t k) const { return 1 + size_t(record(k)[6]); }
  // A finite stand-in for an unbounded box's centre (a turning sun's is all space).
  float centre(size_t k, int a) const {
    const float c = 0.5f * (std::clamp(record(k)[a], -1e30f, 1e30f) +
                            std::clamp(record(k)[3 + a], -1e30f, 1e30f));
    return std::isfinite(c) ? c : 0.0f;
  }

  void build(size_t first, size_t last) {  // tops[first, last)
    if (last - first <= leafSize) {
      for (size_t i = first; i < last; ++i) {
        const float* r = record(tops[i]);
        out.insert(out.end(), r, r + size(tops[i]) * kSweepRecordFloats);
      }
      return;
    }
    float box[6] = {1e30f, 1e30f, 1e30f, -1e30f, -1e30f, -1e30f};
    for (size_t i = first; i < last; ++i)
      for (int a = 0; a < 3; ++a) {
        box[a] = std::min(box[a], record(tops[i])[a]);
        box[3 + a] = std::max(box[3 + a], record(tops[i])[3 + a]);
      }
    const auto begin = tops.begin();
    const size_t mid =
        size_t(medianSplit(begin + std::ptrdiff_t(first), begin + std::ptrdiff_t(last),
                           [&](size_t k, int a) { return centre(k, a); }) -
               begin);
    const size_t self = out.size();
    out.insert(out.end(), box, box + 6);
    out.push_back(0.0f);
    build(first, mid);
    build(mid, last);
    out[self + 6] = float((out.size() - self) / kSweepRecordFloats - 1);  // exact below 2^24
  }
};

}  // namespace

std::vector<float> sweepTree(const std::vector<float>& records, size_t leafSize) {
  SweepTreeBuilder b{records, {}, {}, std::max<size_t>(leafSize, 1)};
  const size_t n = records.size() / kSweepRecordFloats;
  for (size_t k = 0; k < n; k += b.size(k)) b.tops.push_back(k);
  b.out.reserve(2 * records.size());
  b.build(0, b.tops.size());
  return std::move(b.out);
}

}  // namespace pr
