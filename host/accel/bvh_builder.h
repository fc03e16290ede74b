// Binned-SAH BVH construction over axis-aligned boxes: a binary tree flattened depth-first,
// then collapsed into the wide BvhNode layout of kernels/shared/types.h that the device
// traverses (collapseBvh). Used for the SSG, for each DSG mesh and for the per-frame top-level
// BVH over instances.
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <vector>

#include <glm/common.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "shared/types.h"

namespace pr::accel {

struct Aabb {
  glm::vec3 lo{std::numeric_limits<float>::infinity()};
  glm::vec3 hi{-std::numeric_limits<float>::infinity()};

  bool empty() const { return !(lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z); }
  // Inline: the builder, refits and the motion steps' packing call them per vertex.
  void grow(const glm::vec3& p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  void grow(const Aabb& b) {
    lo = glm::min(lo, b.lo);
    hi = glm::max(hi, b.hi);
  }
  glm::vec3 centre() const { return (lo + hi) * 0.5f; }
  // Corner c (bit 0: x, 1: y, 2: z; set: hi) and the box of the eight corners under m.
  glm::vec3 corner(int c) const {
    return {(c & 1) ? hi.x : lo.x, (c & 2) ? hi.y : lo.y, (c & 4) ? hi.z : lo.z};
  }
  Aabb transformed(const glm::mat4& m) const;
  // Half the surface area: all SAH needs (ratios).
  float halfArea() const {
    if (empty()) return 0.0f;
    const glm::vec3 e = hi - lo;
    return e.x * e.y + e.y * e.z + e.z * e.x;
  }
};

struct BuildOptions {
  int bins = 16;
  uint32_t maxLeafSize = 4;    // leaves never hold more; SAH may stop earlier
  float traversalCost = 1.0f;  // relative to one primitive test
  // Primitives tested at once in a leaf (PR_BVH_PACKET for triangles): a leaf of n costs
  // ceil(n / leafPacket) tests.
  uint32_t leafPacket = 1;
  // Deepest leaf allowed (root = depth 0); deeper SAH splits give way to median splits.
  // buildWideBvh lowers it where the collapsed tree would not fit the traversal stack.
  int maxDepth = 64;
  int width = PR_BVH_WIDTH;  // children per node of the collapsed tree: 2, 4 or 8
  bool threads = true;       // top splits on std::threads (same tree either way)
};

struct BvhStats {
  uint32_t nodes = 0, leaves = 0;
  int depth = 0;  // deepest leaf, root = 0
  double seconds = 0.0;
};

// A node of the binary tree, 32 bytes. Nodes are stored depth-first: an interior node's left
// child is the next node (self + 1) and `index` is its right child; a leaf has PR_BVH_LEAF_BIT
// set in `meta`, its primitive count in the low bits (0 for an empty BVH) and `index` is its
// first primitive in `order`. Interior nodes keep the split axis in `meta` (informative only).
struct BinaryNode {
  float lo_x, lo_y, lo_z;
  float hi_x, hi_y, hi_z;
  uint32_t index;
  uint32_t meta;
};

struct Bvh {
  std::vector<BinaryNode> nodes;  // root at 0; always at least one node
  std::vector<uint32_t> order;    // leaf ranges index this; order[i] = input primitive
  BvhStats stats;
};

// Builds over `boxes` (empty ones allowed: they sit in some leaf and are never hit). Zero boxes
// give one empty leaf. Throws RuntimeError when the result would not fit the traversal stack.
Bvh buildBvh(const std::vector<Aabb>& boxes, const BuildOptions& options = {});

// Deepest leaf below nodes[root] (root = 0), walking the flattened tree; checks structure.
int bvhDepth(const std::vector<BinaryNode>& nodes, uint32_t root = 0);

// Node whose box is `b` (an empty box is stored as all zeros).
BinaryNode makeNode(const Aabb& b, uint32_t index, uint32_t meta);

// Words of one `width`-wide node (BvhNode in kernels/shared/types.h): 6 bounds and a child
// reference per child.
inline size_t wideNodeWords(int width) {
  return 7 * size_t(width);
}

// A BVH of `width`-wide nodes in the device's layout, as 32-bit words (28 * width bytes per
// node, see BvhNode in kernels/shared/types.h), root at node 0. Leaf references are
// PR_BVH_LEAF_BIT | k for the k-th entry of `leaves`, the binary tree's leaves in the order
// the collapse met them (their index / count say which primitives they hold).
struct WideBvh {
  int width = PR_BVH_WIDTH;
  std::vector<uint32_t> words;
  std::vector<BinaryNode> leaves;
  int stackNeed = 0;  // the most traversal stack entries a ray can need
  uint32_t nodeCount() const { return uint32_t(words.size() / wideNodeWords(width)); }
  uint64_t bytes() const { return uint64_t(words.size()) * 4u; }
};

// Word offsets inside wide node `node`: bound `b` (0..5 = lo_x, hi_x, lo_y, hi_y, lo_z, hi_z)
// of child i, and the reference of child i.
inline size_t wideBound(int width, uint32_t node, int b, int i) {
  return size_t(node) * wideNodeWords(width) + size_t(b * width + i);
}
inline size_t wideChild(int width, uint32_t node, int i) {
  return size_t(node) * wideNodeWords(width) + size_t(6 * width + i);
}

// Collapses a binary tree into `width`-wide nodes: each wide node takes the children of a
// binary node and opens its largest-area interior child until it has `width` (as Embree and
// tinybvh collapse). A tree that is one leaf becomes a root with that one child (none when the
// leaf is empty). Unused slots hold PR_INVALID_INDEX and an inverted box.
WideBvh collapseBvh(const std::vector<BinaryNode>& nodes, int width);

// buildBvh, then collapseBvh, lowering options.maxDepth until no ray can need more than
// PR_BVH_STACK_SIZE stack entries. *binary receives the binary tree the result came from.
WideBvh buildWideBvh(const std::vector<Aabb>& boxes, const BuildOptions& options, Bvh* binary);

// Rebases a wide BVH's references for concatenation: node references += nodeBase, leaf
// references += leafBase.
void rebaseWide(std::vector<uint32_t>& words, int width, uint32_t nodeBase, uint32_t leafBase);

}  // namespace pr::accel
