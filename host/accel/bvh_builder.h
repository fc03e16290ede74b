// Binned-SAH BVH construction over axis-aligned boxes, flattened depth-first into the 32-byte
// BvhNode layout of kernels/shared/types.h. Used for the SSG, for each DSG mesh and for the
// per-frame top-level BVH over instances.
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include <glm/vec3.hpp>

#include "shared/types.h"

namespace pr::accel {

struct Aabb {
  glm::vec3 lo{std::numeric_limits<float>::infinity()};
  glm::vec3 hi{-std::numeric_limits<float>::infinity()};

  bool empty() const { return !(lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z); }
  void grow(const glm::vec3& p);
  void grow(const Aabb& b);
  glm::vec3 centre() const { return (lo + hi) * 0.5f; }
  // Half the surface area: all SAH needs (ratios).
  float halfArea() const;
};

struct BuildOptions {
  int bins = 16;
  uint32_t maxLeafSize = 4;    // leaves never hold more; SAH may stop earlier
  float traversalCost = 1.0f;  // relative to one primitive test
  // Deepest leaf allowed (root = depth 0). Traversal pushes one entry per level, so this must
  // not exceed PR_BVH_STACK_SIZE; deeper SAH splits give way to median splits.
  int maxDepth = 64;
  bool threads = true;  // top splits on std::threads (same tree either way)
};

struct BvhStats {
  uint32_t nodes = 0, leaves = 0;
  int depth = 0;  // deepest leaf, root = 0
  double seconds = 0.0;
};

struct Bvh {
  std::vector<dev::BvhNode> nodes;  // root at 0; always at least one node
  std::vector<uint32_t> order;      // leaf ranges index this; order[i] = input primitive
  BvhStats stats;
};

// Builds over `boxes` (empty ones allowed: they sit in some leaf and are never hit). Zero boxes
// give one empty leaf. Throws RuntimeError when the result would not fit the traversal stack.
Bvh buildBvh(const std::vector<Aabb>& boxes, const BuildOptions& options = {});

// Deepest leaf below nodes[root] (root = 0), walking the flattened tree; checks structure.
int bvhDepth(const std::vector<dev::BvhNode>& nodes, uint32_t root = 0);

// Node whose box is `b` (an empty box is stored as all zeros).
dev::BvhNode makeNode(const Aabb& b, uint32_t index, uint32_t meta);

}  // namespace pr::accel
