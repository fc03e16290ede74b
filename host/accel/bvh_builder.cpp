#include "accel/bvh_builder.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <cmath>
#include <numeric>
#include <exception>
#include <string>
#include <thread>

#include <glm/common.hpp>

#include "shared/bvh.h"
#include "util/check.h"
#include "util/error.h"

namespace pr::accel {

Aabb Aabb::transformed(const glm::mat4& m) const {
  Aabb out;
  if (empty()) return out;  // not by grow skipping the NaN that its infinite corners become
  for (int c = 0; c < 8; ++c) out.grow(glm::vec3(m * glm::vec4(corner(c), 1.0f)));
  return out;
}

BinaryNode makeNode(const Aabb& b, uint32_t index, uint32_t meta) {
  BinaryNode n{};
  if (!b.empty()) {
    n.lo_x = b.lo.x, n.lo_y = b.lo.y, n.lo_z = b.lo.z;
    n.hi_x = b.hi.x, n.hi_y = b.hi.y, n.hi_z = b.hi.z;
  }
  n.index = index;
  n.meta = meta;
  return n;
}

namespace {

int ceilLog2(uint32_t n) {
  int k = 0;
  while ((uint64_t(1) << k) < n) ++k;
  return k;
}

class Builder {
 public:
  Builder(const std::vector<Aabb>& boxes, const std::vector<glm::vec3>& centroids,
          std::vector<uint32_t>& order, const BuildOptions& o, int parallelDepth)
      : boxes_(boxes), centroids_(centroids), order_(order), o_(o), parallelDepth_(parallelDepth) {}

  // The subtree over order[begin, end) whose root sits at `depth`; its root is node 0 here.
  void run(uint32_t begin, uint32_t end, int depth) {
    nodes_.reserve(end > begin ? 2 * size_t(end - begin) : 1);
    nodes_.emplace_back();
    build(0, begin, end, depth);
  }

  std::vector<BinaryNode> nodes_;
  BvhStats stats_;

 private:
  struct Bin {
    Aabb box;
    uint32_t count = 0;
  };

  void build(uint32_t node, uint32_t begin, uint32_t end, int depth) {
    Aabb bounds, cbounds;
    for (uint32_t i = begin; i < end; ++i) {
      const uint32_t p = order_[i];
      bounds.grow(boxes_[p]);
      cbounds.grow(centroids_[p]);
    }
    const uint32_t n = end - begin;
    if (n <= 1) return makeLeaf(node, bounds, begin, n, depth);

    uint32_t mid = 0;
    int axis = 0;
    const glm::vec3 extent = cbounds.hi - cbounds.lo;
    axis = extent.y > extent[axis] ? 1 : axis;
    axis = extent.z > extent[axis] ? 2 : axis;
    // SAH only while a median split below could still meet the depth cap whatever SAH does.
    const bool sahAllowed = depth + 1 + ceilLog2(n) <= o_.maxDepth;
    bool split = false;
    if (sahAllowed && extent[axis] > 0.0f) {
      float bestCost = 0.0f;
      int bestAxis = -1, bestBin = 0;
      binAxes(begin, end, cbounds);
      for (int a = 0; a < 3; ++a) {
        if (!(extent[a] > 0.0f)) continue;
        int bin = 0;
        float cost = sweep(bins_[size_t(a)], n, &bin);
        if (bestAxis < 0 || cost < bestCost) bestCost = cost, bestAxis = a, bestBin = bin;
      }
      const float area = bounds.halfArea();
      const float leafCost = blocks(n);
      const float splitCost = area > 0.0f ? o_.traversalCost + bestCost / area : leafCost;
      if (n <= o_.maxLeafSize && leafCost <= splitCost)
        return makeLeaf(node, bounds, begin, n, depth);
      if (bestAxis >= 0) {
        const float lo = cbounds.lo[bestAxis];
        const float scale = float(o_.bins) / extent[bestAxis];
        uint32_t* first = order_.data() + begin;
        uint32_t* m = std::partition(first, order_.data() + end, [&](uint32_t p) {
          return binOf(centroids_[p][bestAxis], lo, scale) <= bestBin;
        });
        mid = uint32_t(m - order_.data());
        axis = bestAxis;
        split = mid > begin && mid < end;
      }
    } else if (n <= o_.maxLeafSize) {
      // All centroids equal (nothing to split) or near the depth cap: small enough to stop.
      return makeLeaf(node, bounds, begin, n, depth);
    }
    if (!split) {
      // Object median: on the widest centroid axis, or in input order when all coincide.
      mid = begin + n / 2;
      if (extent[axis] > 0.0f) {
        std::nth_element(
            order_.begin() + begin, order_.begin() + mid, order_.begin() + end,
            [&](uint32_t a, uint32_t b) { return centroids_[a][axis] < centroids_[b][axis]; });
      }
    }
    const uint32_t left = uint32_t(nodes_.size());
    nodes_.emplace_back();
    uint32_t right = 0;
    if (depth < parallelDepth_ && n >= kParallelMinimum) {
      // The right subtree on another thread (disjoint range of order_), spliced in after the
      // left one: the same tree as a serial build.
      Builder sub(boxes_, centroids_, order_, o_, parallelDepth_);
      std::exception_ptr failure;
      std::thread worker([&] {
        try {
          sub.run(mid, end, depth + 1);
        } catch (...) {
          failure = std::current_exception();
        }
      });
      build(left, begin, mid, depth + 1);
      worker.join();
      if (failure) std::rethrow_exception(failure);
      right = uint32_t(nodes_.size());
      for (BinaryNode c : sub.nodes_) {
        if (!(c.meta & PR_BVH_LEAF_BIT)) c.index += right;
        nodes_.push_back(c);
      }
      stats_.leaves += sub.stats_.leaves;
      stats_.depth = std::max(stats_.depth, sub.stats_.depth);
    } else {
      build(left, begin, mid, depth + 1);
      right = uint32_t(nodes_.size());
      nodes_.emplace_back();
      build(right, mid, end, depth + 1);
    }
    nodes_[node] = makeNode(bounds, right, uint32_t(axis));
  }

  // Intersection tests for n primitives in packets of leafPacket.
  float blocks(uint32_t n) const { return float((n + o_.leafPacket - 1) / o_.leafPacket); }

  int binOf(float c, float lo, float scale) const {
    const int b = int((c - lo) * scale);
    return std::clamp(b, 0, o_.bins - 1);
  }

  // The primitives of [begin, end) binned by centroid on each axis with extent, in one pass:
  // each reads its box once (the build's cost is those reads).
  void binAxes(uint32_t begin, uint32_t end, const Aabb& cbounds) {
    float lo[3], scale[3];
    bool active[3];
    for (int a = 0; a < 3; ++a) {
      bins_[size_t(a)].assign(size_t(o_.bins), Bin{});
      const float extent = cbounds.hi[a] - cbounds.lo[a];
      active[a] = extent > 0.0f;
      lo[a] = cbounds.lo[a];
      scale[a] = active[a] ? float(o_.bins) / extent : 0.0f;
    }
    for (uint32_t i = begin; i < end; ++i) {
      const uint32_t p = order_[i];
      const Aabb& box = boxes_[p];
      const glm::vec3& c = centroids_[p];
      for (int a = 0; a < 3; ++a) {
        if (!active[a]) continue;
        Bin& b = bins_[size_t(a)][size_t(binOf(c[a], lo[a], scale[a]))];
        b.box.grow(box);
        ++b.count;
      }
    }
  }

  // Best split of one axis's bins (`total` primitives): returns sum(area * count) of both sides,
  // and the bin of the last left.
  float sweep(const std::vector<Bin>& bins, uint32_t total, int* bestBin) {
    // Right-side sums from the top, then sweep from the left.
    rightCost_.assign(size_t(o_.bins), 0.0f);
    Aabb acc;
    uint32_t count = 0;
    for (int i = o_.bins - 1; i > 0; --i) {
      acc.grow(bins[size_t(i)].box);
      count += bins[size_t(i)].count;
      rightCost_[size_t(i)] = count > 0 ? acc.halfArea() * blocks(count) : 0.0f;
    }
    float best = std::numeric_limits<float>::infinity();
    *bestBin = 0;
    acc = Aabb{};
    count = 0;
    for (int i = 0; i < o_.bins - 1; ++i) {
      acc.grow(bins[size_t(i)].box);
      count += bins[size_t(i)].count;
      if (count == 0 || count == total) continue;
      const float cost = acc.halfArea() * blocks(count) + rightCost_[size_t(i) + 1];
      if (cost < best) best = cost, *bestBin = i;
    }
    return best;
  }

  void makeLeaf(uint32_t node, const Aabb& bounds, uint32_t begin, uint32_t n, int depth) {
    nodes_[node] = makeNode(bounds, begin, PR_BVH_LEAF_BIT | n);
    ++stats_.leaves;
    stats_.depth = std::max(stats_.depth, depth);
  }

  static constexpr uint32_t kParallelMinimum = 16384;  // smaller subtrees: not worth a thread

  const std::vector<Aabb>& boxes_;
  const std::vector<glm::vec3>& centroids_;
  std::vector<uint32_t>& order_;
  const BuildOptions& o_;
  const int parallelDepth_;
  std::vector<Bin> bins_[3];  // per axis (binAxes)
  std::vector<float> rightCost_;
};

}  // namespace

Bvh buildBvh(const std::vector<Aabb>& boxes, const BuildOptions& options) {
  if (options.maxDepth > PR_BVH_STACK_SIZE || options.maxDepth < 1 || options.bins < 2 ||
      options.maxLeafSize < 1 || options.leafPacket < 1 || boxes.size() >= PR_BVH_LEAF_BIT ||
      !(options.width == 2 || options.width == 4 || options.width == 8))
    throw RuntimeError("BVH build: bad options (maxDepth " + std::to_string(options.maxDepth) +
                       ", stack " + std::to_string(PR_BVH_STACK_SIZE) + ")");
  const auto t0 = std::chrono::steady_clock::now();
  Bvh bvh;
  std::vector<glm::vec3> centroids(boxes.size());
  for (size_t i = 0; i < boxes.size(); ++i)
    centroids[i] = boxes[i].empty() ? glm::vec3(0.0f) : boxes[i].centre();
  bvh.order.resize(boxes.size());
  std::iota(bvh.order.begin(), bvh.order.end(), 0u);
  // Threads for the top levels: one split per level doubles them.
  int parallelDepth = 0;
  for (unsigned t = std::thread::hardware_concurrency(); t > 1 && parallelDepth < 4; t /= 2)
    ++parallelDepth;
  if (!options.threads) parallelDepth = 0;
  Builder builder(boxes, centroids, bvh.order, options, parallelDepth);
  builder.run(0, uint32_t(boxes.size()), 0);
  bvh.nodes = std::move(builder.nodes_);
  bvh.stats = builder.stats_;
  bvh.stats.nodes = uint32_t(bvh.nodes.size());
  bvh.stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // The traversal stack must never overflow: check what was built, not what was intended.
  const int depth = bvhDepth(bvh.nodes);
  if (depth > PR_BVH_STACK_SIZE || depth != bvh.stats.depth)
    throw RuntimeError("BVH build: depth " + std::to_string(depth) +
                       " exceeds the traversal stack (" + std::to_string(PR_BVH_STACK_SIZE) + ")");
  return bvh;
}

int bvhDepth(const std::vector<BinaryNode>& nodes, uint32_t root) {
  if (root >= nodes.size()) throw RuntimeError("BVH: root node out of range");
  int deepest = 0;
  std::vector<std::pair<uint32_t, int>> stack{{root, 0}};
  while (!stack.empty()) {
    const auto [i, d] = stack.back();
    stack.pop_back();
    const BinaryNode& n = nodes[i];
    if (n.meta & PR_BVH_LEAF_BIT) {
      deepest = std::max(deepest, d);
      continue;
    }
    if (i + 1 >= nodes.size() || n.index >= nodes.size() || n.index <= i + 1 || d >= 1 << 20)
      throw RuntimeError("BVH: malformed node " + std::to_string(i));
    stack.push_back({i + 1, d + 1});
    stack.push_back({n.index, d + 1});
  }
  return deepest;
}

namespace {

class Collapser {
 public:
  Collapser(const std::vector<BinaryNode>& nodes, int width) : nodes_(nodes), w_(width) {}

  WideBvh run() {
    out_.width = w_;
    const BinaryNode& root = nodes_[0];
    const uint32_t node = allocate();
    if (!isLeaf(root)) {
      fill(node, 0);
    } else if ((root.meta & ~PR_BVH_LEAF_BIT) > 0) {
      setChild(node, 0, root, addLeaf(root));
    }
    out_.stackNeed = need(0);
    return std::move(out_);
  }

 private:
  static bool isLeaf(const BinaryNode& n) { return (n.meta & PR_BVH_LEAF_BIT) != 0; }
  static float area(const BinaryNode& n) {
    const float x = n.hi_x - n.lo_x, y = n.hi_y - n.lo_y, z = n.hi_z - n.lo_z;
    return x * y + y * z + z * x;
  }

  uint32_t allocate() {
    const uint32_t node = out_.nodeCount();
    out_.words.resize(out_.words.size() + wideNodeWords(w_));
    const float inf = std::numeric_limits<float>::infinity();
    for (int i = 0; i < w_; ++i) {
      for (int b = 0; b < 6; ++b) store(wideBound(w_, node, b, i), (b & 1) ? -inf : inf);
      out_.words[wideChild(w_, node, i)] = PR_INVALID_INDEX;
    }
    return node;
  }

  void store(size_t word, float f) { std::memcpy(&out_.words[word], &f, 4); }

  // The reference of a new leaf: the next entry of out_.leaves.
  uint32_t addLeaf(const BinaryNode& n) {
    out_.leaves.push_back(n);
    return PR_BVH_LEAF_BIT | uint32_t(out_.leaves.size() - 1);
  }

  // Slot i of wide node `node`: binary node n's box and reference ref.
  void setChild(uint32_t node, int i, const BinaryNode& n, uint32_t ref) {
    const float bounds[6] = {n.lo_x, n.hi_x, n.lo_y, n.hi_y, n.lo_z, n.hi_z};
    for (int b = 0; b < 6; ++b) store(wideBound(w_, node, b, i), bounds[b]);
    out_.words[wideChild(w_, node, i)] = ref;
  }

  // Fills wide node `node` with the children gathered under interior binary node b. The wide
  // children are allocated side by side before any of them is filled (siblings share cache
  // lines and pages, which measured faster than depth-first order), and so are the leaves.
  void fill(uint32_t node, uint32_t b) {
    std::vector<uint32_t> kids{b + 1, nodes_[b].index};
    while (int(kids.size()) < w_) {
      int open = -1;
      for (size_t k = 0; k < kids.size(); ++k) {
        const BinaryNode& n = nodes_[kids[k]];
        if (!isLeaf(n) && (open < 0 || area(n) > area(nodes_[kids[size_t(open)]]))) open = int(k);
      }
      if (open < 0) break;
      const uint32_t c = kids[size_t(open)];
      kids[size_t(open)] = c + 1;
      kids.insert(kids.begin() + open + 1, nodes_[c].index);
    }
    std::vector<uint32_t> refs(kids.size());
    for (size_t k = 0; k < kids.size(); ++k) {
      const BinaryNode& n = nodes_[kids[k]];
      refs[k] = isLeaf(n) ? addLeaf(n) : allocate();
      setChild(node, int(k), n, refs[k]);
    }
    for (size_t k = 0; k < kids.size(); ++k)
      if (!(refs[k] & PR_BVH_LEAF_BIT)) fill(refs[k], kids[k]);
  }

  // Most entries on the stack below wide node `node`: its entered children go on the stack,
  // all but the one descended into stay.
  int need(uint32_t node) const {
    int k = 0, deepest = 0;
    for (int i = 0; i < w_; ++i) {
      const uint32_t ref = out_.words[wideChild(w_, node, i)];
      if (ref == PR_INVALID_INDEX) continue;
      ++k;
      if (!(ref & PR_BVH_LEAF_BIT)) deepest = std::max(deepest, need(ref));
    }
    return k == 0 ? 0 : std::max(k, k - 1 + deepest);
  }

  const std::vector<BinaryNode>& nodes_;
  const int w_;
  WideBvh out_;
};

}  // namespace

WideBvh collapseBvh(const std::vector<BinaryNode>& nodes, int width) {
  if (nodes.empty() || !(width == 2 || width == 4 || width == 8))
    throw RuntimeError("BVH collapse: no nodes or width " + std::to_string(width));
  WideBvh wide = Collapser(nodes, width).run();
  PR_CHECK(wide.words.size() == size_t(wide.nodeCount()) * wideNodeWords(width));
  // Every binary leaf but an empty root becomes one leaf reference.
  PR_DCHECK(size_t(std::count_if(nodes.begin(), nodes.end(), [](const BinaryNode& n) {
              return (n.meta & PR_BVH_LEAF_BIT) && (n.meta & ~PR_BVH_LEAF_BIT) > 0;
            })) == wide.leaves.size());
  return wide;
}

WideBvh buildWideBvh(const std::vector<Aabb>& boxes, const BuildOptions& options, Bvh* binary) {
  BuildOptions o = options;
  for (;;) {
    *binary = buildBvh(boxes, o);
    WideBvh wide = collapseBvh(binary->nodes, o.width);
    if (wide.stackNeed <= PR_BVH_STACK_SIZE) return wide;
    // Each binary level can add at most width - 1 entries.
    const int over = wide.stackNeed - PR_BVH_STACK_SIZE;
    const int lower = std::max(1, (over + o.width - 2) / (o.width - 1));
    if (o.maxDepth <= 1)
      throw RuntimeError("BVH build: the tree needs " + std::to_string(wide.stackNeed) +
                         " traversal stack entries (at most " + std::to_string(PR_BVH_STACK_SIZE) +
                         ")");
    o.maxDepth = std::max(1, o.maxDepth - lower);
  }
}

void rebaseWide(std::vector<uint32_t>& words, int width, uint32_t nodeBase, uint32_t leafBase) {
  const size_t stride = wideNodeWords(width);
  for (size_t n = 0; n < words.size() / stride; ++n) {
    for (int i = 0; i < width; ++i) {
      uint32_t& ref = words[n * stride + 6 * size_t(width) + size_t(i)];
      if (ref == PR_INVALID_INDEX) continue;
      ref = (ref & PR_BVH_LEAF_BIT) ? PR_BVH_LEAF_BIT | ((ref & ~PR_BVH_LEAF_BIT) + leafBase)
                                    : ref + nodeBase;
    }
  }
}

}  // namespace pr::accel
