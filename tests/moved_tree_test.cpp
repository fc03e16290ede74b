// The moved instances' tree (host/render/moved_tree.h): every instance kept once, inner boxes
// bounding their subtrees, and the skip traversal pt_resample makes (kernels/shared/resample.h,
// rs_clear and rs_apart) finding the same instances as a test of every one.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>
#include <vector>

#include "render/moved_tree.h"
#include "support/segment_box.h"

namespace pr {
namespace {

using test::segmentMeetsBox;

// The instances (by root) whose boxes the segment meets, found as rs_clear walks the records.
std::set<uint32_t> walk(const std::vector<dev::MovedInstance>& m, const float o[3],
                        const float d[3], size_t* visited) {
  std::set<uint32_t> found;
  *visited = 0;
  for (uint32_t k = 0; k < m.size();) {
    ++*visited;
    const bool hit = segmentMeetsBox(m[k].box, o, d) || segmentMeetsBox(m[k].box + 6, o, d);
    if (hit && !m[k].node) found.insert(m[k].root);
    k = hit || !m[k].node ? k + 1 : std::max(m[k].skip, k + 1);
  }
  return found;
}

std::vector<dev::MovedInstance> randomInstances(size_t n, std::mt19937* rng) {
  std::uniform_real_distribution<float> at(-50.0f, 50.0f), size(0.1f, 4.0f), step(-2.0f, 2.0f);
  std::vector<dev::MovedInstance> out(n);
  for (size_t i = 0; i < n; ++i) {
    dev::MovedInstance& m = out[i];
    m.root = uint32_t(i);
    m.root_before = uint32_t(i);
    for (int b = 0; b < 2; ++b) {
      const float shift = b ? step(*rng) : 0.0f;
      for (int a = 0; a < 3; ++a) {
        const float lo = at(*rng) * (b ? 0.0f : 1.0f);
        m.box[6 * b + a] = (b ? m.box[a] + shift : lo);
        m.box[6 * b + 3 + a] = m.box[6 * b + a] + size(*rng);
      }
    }
    if (i % 7 == 3)  // an instance with no points then (its box empty)
      for (int a = 0; a < 3; ++a) m.box[a] = 1.0f, m.box[3 + a] = -1.0f;
  }
  return out;
}

TEST(MovedTree, KeepsEveryInstanceOnceAndBoundsEachSubtree) {
  std::mt19937 rng(7);
  for (size_t n : {0u, 1u, 2u, 3u, 5u, 45u, 200u}) {
    const auto tree = movedTree(randomInstances(n, &rng));
    std::multiset<uint32_t> roots;
    for (uint32_t k = 0; k < tree.size(); ++k) {
      ASSERT_GT(tree[k].skip, k);
      ASSERT_LE(tree[k].skip, tree.size());
      if (!tree[k].node) {
        roots.insert(tree[k].root);
        EXPECT_EQ(tree[k].skip, k + 1);
        continue;
      }
      EXPECT_EQ(tree[k].root, PR_INVALID_INDEX);
      for (uint32_t c = k + 1; c < tree[k].skip; ++c)
        for (int b = 0; b < 2; ++b) {
          const float* box = tree[c].box + 6 * b;
          if (box[0] > box[3]) continue;
          for (int a = 0; a < 3; ++a) {
            EXPECT_LE(tree[k].box[a], box[a]);
            EXPECT_GE(tree[k].box[3 + a], box[3 + a]);
          }
        }
    }
    EXPECT_EQ(roots.size(), n);
    EXPECT_EQ(std::set<uint32_t>(roots.begin(), roots.end()).size(), n);
    if (n <= 2) {
      EXPECT_EQ(tree.size(), n);  // a short list is kept as it is
    }
  }
}

TEST(MovedTree, SkipWalkFindsWhatTestingEveryInstanceFinds) {
  std::mt19937 rng(11);
  const auto flat = randomInstances(120, &rng);
  const auto tree = movedTree(flat);
  std::uniform_real_distribution<float> at(-60.0f, 60.0f), len(-8.0f, 8.0f);
  size_t walked = 0, all = 0;
  for (int q = 0; q < 2000; ++q) {
    const float o[3] = {at(rng), at(rng), at(rng)};
    const float d[3] = {len(rng), len(rng), len(rng)};
    std::set<uint32_t> expect;
    for (const auto& m : flat) {
      if (segmentMeetsBox(m.box, o, d) || segmentMeetsBox(m.box + 6, o, d)) expect.insert(m.root);
    }
    size_t visited = 0;
    EXPECT_EQ(walk(tree, o, d, &visited), expect);
    walked += visited;
    all += flat.size();
  }
  EXPECT_LT(walked, all / 3);  // short segments visit a few records, not every instance
}

}  // namespace
}  // namespace pr
