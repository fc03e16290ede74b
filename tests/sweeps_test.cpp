// The boxes of what moves while the shutter is open (host/render/sweeps.h): every triangle in one
// part, every point of a moving mesh inside a part's box at every time between two motion steps
// (not only at the steps), and the kernels' walk of the records (sweep_clear) finding what a test
// of every part finds, with and without the tree over them (sweepTree); and resampling's test of
// a path shared across the shutter's times (rs_path_still) asking the same of its every segment.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "render/sweeps.h"
#include "shared/resample.h"
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

// Whether the segment meets the records as sweep_clear walks them: into a record's subtree only
// where its box is met, a leaf met deciding.
bool walkMeets(const std::vector<float>& r, const float o[3], const float d[3]) {
  const size_t n = r.size() / kSweepRecordFloats;
  for (size_t k = 0; k < n;) {
    const float* rec = &r[k * kSweepRecordFloats];
    const size_t below = size_t(rec[6]);
    if (!segmentMeetsBox(rec, o, d))
      k += 1 + below;
    else if (below == 0)
      return true;
    else
      ++k;
  }
  return false;
}

// Whether the records from k on form a subtree ending at `end` (its children's subtrees ending
// exactly where it says it ends, each box inside its parent's); returns where it ends.
size_t subtreeEnd(const std::vector<float>& r, size_t k, bool* ok) {
  const float* rec = &r[k * kSweepRecordFloats];
  const size_t end = k + 1 + size_t(rec[6]);
  size_t c = k + 1;
  while (c < end && *ok) {
    const float* child = &r[c * kSweepRecordFloats];
    for (int a = 0; a < 3; ++a) *ok = *ok && child[a] >= rec[a] && child[3 + a] <= rec[3 + a];
    c = subtreeEnd(r, c, ok);
  }
  *ok = *ok && c == end && end <= r.size() / kSweepRecordFloats;
  return end;
}

bool wellFormed(const std::vector<float>& r) {
  bool ok = true;
  size_t k = 0;
  while (ok && k < r.size() / kSweepRecordFloats) k = subtreeEnd(r, k, &ok);
  return ok && k == r.size() / kSweepRecordFloats;
}

// Whether the segment meets any leaf of the records (a record with nothing below it).
bool anyLeafMeets(const std::vector<float>& r, const float o[3], const float d[3]) {
  for (size_t k = 0; k < r.size() / kSweepRecordFloats; ++k) {
    const float* rec = &r[k * kSweepRecordFloats];
    if (rec[6] == 0.0f && segmentMeetsBox(rec, o, d)) return true;
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

// The walk that skips a record's subtree where its box is missed finds what testing every part
// finds, over random segments and records of many instances and light boxes, as appended and
// under the tree over them; the tree holds every record once.
TEST(Sweeps, TheWalkFindsWhatEveryPartFinds) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-5.0f, 5.0f);
  std::vector<glm::vec3> p;
  std::vector<uint32_t> idx;
  grid(6, &p, &idx);
  const auto parts = sweepParts(p, idx);
  std::vector<float> records;
  for (int i = 0; i < 12; ++i) {
    const glm::vec3 at(u(rng), u(rng), u(rng));
    appendInstanceSweep(parts,
                        {glm::translate(glm::scale(glm::mat4(1.0f), glm::vec3(0.3f)), at),
                         glm::translate(glm::scale(glm::mat4(1.0f), glm::vec3(0.3f)), at + 1.0f)},
                        {&p}, 1e-4f, &records);
    appendBoxSweep(at, at + 0.2f, 1e-4f, &records);
  }
  const std::vector<float> tree = sweepTree(records, 2);
  auto leaves = [](const std::vector<float>& r) {
    std::multiset<std::vector<float>> l;
    for (size_t k = 0; k < r.size() / kSweepRecordFloats; ++k)
      if (r[k * kSweepRecordFloats + 6] == 0.0f)
        l.emplace(r.begin() + long(k * kSweepRecordFloats),
                  r.begin() + long((k + 1) * kSweepRecordFloats));
    return l;
  };
  EXPECT_EQ(leaves(tree), leaves(records));
  EXPECT_GT(tree.size(), records.size());  // its inner nodes
  EXPECT_TRUE(wellFormed(records));
  EXPECT_TRUE(wellFormed(tree));
  int met = 0;
  for (int s = 0; s < 4000; ++s) {
    const float o[3] = {u(rng), u(rng), u(rng)}, d[3] = {u(rng), u(rng), u(rng)};
    // An instance's own box holds its parts: a leaf (no parts of its own) decides.
    const bool any = anyLeafMeets(records, o, d);
    EXPECT_EQ(walkMeets(records, o, d), any) << "segment " << s;
    EXPECT_EQ(walkMeets(tree, o, d), any) << "segment " << s;
    met += any;
  }
  EXPECT_GT(met, 100);
  EXPECT_LT(met, 3900);
}

// A turning sun's record (all space) stays a leaf that every segment meets, wherever the tree
// puts it.
TEST(Sweeps, AnUnboundedRecordInTheTreeMeetsEverySegment) {
  std::vector<float> records;
  for (int i = 0; i < 9; ++i)
    appendBoxSweep(glm::vec3(float(i)), glm::vec3(float(i) + 0.5f), 1e-4f, &records);
  const float inf = std::numeric_limits<float>::infinity();
  appendBoxSweep(glm::vec3(-inf), glm::vec3(inf), 1e-4f, &records);
  const std::vector<float> tree = sweepTree(records, 2);
  const float o1[3] = {-50.0f, 3.0f, 7.0f}, d1[3] = {0.0f, 0.0f, 1.0f};
  EXPECT_TRUE(walkMeets(tree, o1, d1));
  const float o2[3] = {100.0f, -40.0f, 2.0f}, d2[3] = {1.0f, 0.0f, 0.0f};
  EXPECT_TRUE(walkMeets(tree, o2, d2));
  for (float v : tree) EXPECT_FALSE(std::isnan(v));
}

}  // namespace
}  // namespace pr

namespace pr {
namespace {

// Random boxes' records under a tree, as collectSweeps leaves them.
std::vector<float> randomSweeps(std::mt19937* rng, int count) {
  std::uniform_real_distribution<float> u(-5.0f, 5.0f), size(0.5f, 2.5f);
  std::vector<float> records;
  for (int i = 0; i < count; ++i) {
    const glm::vec3 lo(u(*rng), u(*rng), u(*rng));
    appendBoxSweep(lo, lo + glm::vec3(size(*rng), size(*rng), size(*rng)), 1e-4f, &records);
  }
  return sweepTree(records, 2);
}

bool pointInLeaf(const std::vector<float>& r, const float p[3]) {
  const float zero[3] = {0.0f, 0.0f, 0.0f};
  return anyLeafMeets(r, p, zero);
}

// A path shared between sample times (--shutter with --resample) is still exactly where x_2 lies
// in no sweep and none of its segments (the suffix's, the escape to infinity, and for a previous
// frame's path the segment from its x_1) meets one: this frame's sweeps, and the previous frame's
// for a path of that frame (past). Checked on 3,000 random paths against every leaf.
TEST(Sweeps, APathIsStillWhereNoSegmentMeetsASweep) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-6.0f, 6.0f);
  const std::vector<float> now = randomSweeps(&rng, 8), then = randomSweeps(&rng, 8);
  dev::RsSweeps w;
  w.now = now.data();
  w.now_count = uint32_t(now.size() / kSweepRecordFloats);
  w.then = then.data();
  w.then_count = uint32_t(then.size() / kSweepRecordFloats);
  int still[2] = {0, 0};
  for (int c = 0; c < 3000; ++c) {
    dev::PathReservoir r{};
    const uint32_t n = 1 + uint32_t(c % 3);
    const bool escapes = c % 4 == 0, fromPrevious = c % 5 < 2;
    r.suffix = n | (escapes ? PR_RS_ESCAPES : 0u);
    for (uint32_t k = 0; k < 3 * n; ++k) r.sp[k] = u(rng);
    const float p2[3] = {u(rng), u(rng), u(rng)}, from[3] = {u(rng), u(rng), u(rng)};
    for (int past = 0; past < 2; ++past) {
      auto meets = [&](const float o[3], const float d[3]) {
        return anyLeafMeets(now, o, d) || (past && anyLeafMeets(then, o, d));
      };
      bool expected = !pointInLeaf(now, p2) && !(past && pointInLeaf(then, p2));
      const float toX2[3] = {p2[0] - from[0], p2[1] - from[1], p2[2] - from[2]};
      if (fromPrevious && meets(from, toX2)) expected = false;
      const float* a = p2;
      for (uint32_t k = 0; k < n; ++k) {
        const float* q = &r.sp[3 * k];
        const float scale = escapes && k + 1 == n ? 1e3f : 1.0f;  // to infinity: past every box
        const float d[3] = {(escapes && k + 1 == n ? q[0] : q[0] - a[0]) * scale,
                            (escapes && k + 1 == n ? q[1] : q[1] - a[1]) * scale,
                            (escapes && k + 1 == n ? q[2] : q[2] - a[2]) * scale};
        if (meets(a, d)) expected = false;
        a = q;
      }
      const bool got =
          dev::rs_path_still(&w, past, &r, dev::make_float3(p2[0], p2[1], p2[2]), fromPrevious,
                             dev::make_float3(from[0], from[1], from[2]));
      EXPECT_EQ(got, expected) << "path " << c << (past ? " of the previous frame" : "");
      still[past] += got;
    }
  }
  // Both outcomes occur, and the previous frame's sweeps reject paths this frame's keep.
  EXPECT_GT(still[0], 300);
  EXPECT_LT(still[0], 2700);
  EXPECT_LT(still[1], still[0]);
  // A path longer than its suffix holds, or with none, is never still; without sweeps, always.
  dev::PathReservoir r{};
  r.suffix = PR_RS_LONG | 1u;
  const dev::float3 far = dev::make_float3(100.0f, 100.0f, 100.0f);
  r.sp[0] = r.sp[1] = r.sp[2] = 101.0f;
  EXPECT_FALSE(dev::rs_path_still(&w, 0, &r, far, 0, far));
  r.suffix = 0u;
  EXPECT_FALSE(dev::rs_path_still(&w, 0, &r, far, 0, far));
  r.suffix = 1u;
  EXPECT_TRUE(dev::rs_path_still(&w, 1, &r, far, 1, far));
  dev::RsSweeps none{};
  r.suffix = PR_RS_LONG;
  EXPECT_TRUE(dev::rs_path_still(&none, 1, &r, far, 0, far));
}

}  // namespace
}  // namespace pr
