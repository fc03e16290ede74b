// The boxes of what moves while the shutter is open (host/render/sweeps.h): every triangle in one
// part, every point of a moving mesh inside a part's box at every time between two motion steps
// (not only at the steps), and the kernels' walk of the records (sweep_clear) finding what a test
// of every part finds.
#include <gtest/gtest.h>

#include <random>
#include <set>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "render/sweeps.h"
#include "support/segment_box.h"

namespace pr {
namespace {

using test::segmentMeetsBox;

// A grid of n x n quads (two triangles each) in the z = 0 plane, [0, n] x [0, n].
void grid(int n, std::vector<glm::vec3>* p, std::vector<uint32_t>* idx) {
  for (int y = 0; y <= n; ++y)
    for (int x = 0; x <= n; ++x) p->emplace_back(float(x), float(y), 0.0f);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const uint32_t a = uint32_t(y * (n + 1) + x), b = a + 1, c = a + uint32_t(n) + 1, d = c + 1;
      idx->insert(idx->end(), {a, b, d, a, d, c});
    }
}

// Whether the segment meets the records as sweep_clear walks them: a record's parts only where
// its box is met.
bool walkMeets(const std::vector<float>& r, const float o[3], const float d[3]) {
  const size_t n = r.size() / kSweepRecordFloats;
  for (size_t k = 0; k < n;) {
    const float* rec = &r[k * kSweepRecordFloats];
    const size_t parts = size_t(rec[6]);
    if (segmentMeetsBox(rec, o, d)) {
      if (parts == 0) return true;
      for (size_t j = k + 1; j <= k + parts && j < n; ++j)
        if (segmentMeetsBox(&r[j * kSweepRecordFloats], o, d)) return true;
    }
    k += 1 + parts;
  }
  return false;
}

TEST(Sweeps, EveryTriangleIsInOnePartWhole) {
  std::vector<glm::vec3> p;
  std::vector<uint32_t> idx;
  grid(20, &p, &idx);
  const auto parts = sweepParts(p, idx);
  EXPECT_GT(parts.size(), 16u);
  EXPECT_LE(parts.size(), 32u);
  for (size_t t = 0; t < idx.size() / 3; ++t) {
    bool whole = false;
    for (const auto& part : parts) {
      const std::set<uint32_t> in(part.begin(), part.end());
      whole =
          whole || (in.count(idx[3 * t]) && in.count(idx[3 * t + 1]) && in.count(idx[3 * t + 2]));
    }
    EXPECT_TRUE(whole) << "triangle " << t;
  }
}

// A unit square that is left of x = 0 at the first step and right of it at the second (and
// third): a segment through x = 0.5 meets it only between the first two steps. The records hold
// it there; records of each step's placement alone (the interval's ends and middle) do not.
TEST(Sweeps, APartHoldsItsMeshBetweenTheSteps) {
  std::vector<glm::vec3> p;
  std::vector<uint32_t> idx;
  grid(1, &p, &idx);
  const auto parts = sweepParts(p, idx);
  const std::vector<glm::mat4> steps = {glm::translate(glm::mat4(1.0f), glm::vec3(-6, 0, 0)),
                                        glm::translate(glm::mat4(1.0f), glm::vec3(6, 0, 0)),
                                        glm::translate(glm::mat4(1.0f), glm::vec3(6, 0, 0))};
  std::vector<float> records;
  appendInstanceSweep(parts, steps, {&p}, 1e-4f, &records);
  const float o[3] = {0.5f, 0.5f, -1.0f}, d[3] = {0.0f, 0.0f, 2.0f};
  EXPECT_TRUE(walkMeets(records, o, d));
  for (const glm::mat4& m : steps) {
    std::vector<float> alone;
    appendInstanceSweep(parts, {m}, {&p}, 1e-4f, &alone);
    EXPECT_FALSE(walkMeets(alone, o, d));
  }
  // Every blend of two steps' placements of every vertex is in a part's box.
  for (float a = 0.0f; a <= 1.0f; a += 0.125f)
    for (const glm::vec3& v : p) {
      const glm::vec3 w = glm::mix(glm::vec3(steps[0] * glm::vec4(v, 1.0f)),
                                   glm::vec3(steps[1] * glm::vec4(v, 1.0f)), a);
      const float po[3] = {w.x, w.y, w.z}, zero[3] = {0, 0, 0};
      EXPECT_TRUE(walkMeets(records, po, zero)) << "blend " << a;
    }
}

// Deforming meshes: each step's own positions, placed by that step's transform.
TEST(Sweeps, DeformedStepsAreHeld) {
  std::vector<glm::vec3> p;
  std::vector<uint32_t> idx;
  grid(4, &p, &idx);
  std::vector<glm::vec3> lifted = p;
  for (glm::vec3& v : lifted) v.z += 3.0f;
  const auto parts = sweepParts(p, idx);
  std::vector<float> records;
  const glm::mat4 id(1.0f);
  appendInstanceSweep(parts, {id, id}, {&p, &lifted}, 1e-4f, &records);
  const float o[3] = {-1.0f, 2.0f, 1.5f}, d[3] = {6.0f, 0.0f, 0.0f};  // between the two shapes
  EXPECT_TRUE(walkMeets(records, o, d));
  const float above[3] = {-1.0f, 2.0f, 3.5f};
  EXPECT_FALSE(walkMeets(records, above, d));
}

// The walk that skips a record's parts where its box is missed finds what testing every part
// finds, over random segments and records of several instances and light boxes.
TEST(Sweeps, TheWalkFindsWhatEveryPartFinds) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-5.0f, 5.0f);
  std::vector<glm::vec3> p;
  std::vector<uint32_t> idx;
  grid(6, &p, &idx);
  const auto parts = sweepParts(p, idx);
  std::vector<float> records;
  for (int i = 0; i < 4; ++i) {
    const glm::vec3 at(u(rng), u(rng), u(rng));
    appendInstanceSweep(parts,
                        {glm::translate(glm::scale(glm::mat4(1.0f), glm::vec3(0.3f)), at),
                         glm::translate(glm::scale(glm::mat4(1.0f), glm::vec3(0.3f)), at + 1.0f)},
                        {&p}, 1e-4f, &records);
    appendBoxSweep(at, at + 0.2f, 1e-4f, &records);
  }
  int met = 0;
  for (int s = 0; s < 2000; ++s) {
    const float o[3] = {u(rng), u(rng), u(rng)}, d[3] = {u(rng), u(rng), u(rng)};
    bool any = false;
    const size_t n = records.size() / kSweepRecordFloats;
    for (size_t k = 0; k < n; ++k) {
      const float* rec = &records[k * kSweepRecordFloats];
      // An instance's own box holds its parts: a leaf (no parts of its own) decides.
      const bool leaf = rec[6] == 0.0f;
      any = any || (leaf && segmentMeetsBox(rec, o, d));
    }
    EXPECT_EQ(walkMeets(records, o, d), any) << "segment " << s;
    met += any;
  }
  EXPECT_GT(met, 50);
  EXPECT_LT(met, 1900);
}

}  // namespace
}  // namespace pr
