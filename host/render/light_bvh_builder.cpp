#include "render/light_bvh_builder.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

namespace pr {

namespace {

constexpr double kPi = 3.14159265358979323846;

glm::vec3 load(float x, float y, float z) {
  return glm::vec3(x, y, z);
}

// The solid angle measure of a cone of normals with emission beyond them (Estevez and Kulla
// 2018, eq. 1): what the build's cost weighs besides power and size.
double orientationMeasure(double thetaO, double thetaE) {
  const double thetaW = std::min(thetaO + thetaE, kPi);
  return 2.0 * kPi * (1.0 - std::cos(thetaO)) +
         0.5 * kPi *
             (2.0 * thetaW * std::sin(thetaO) - std::cos(thetaO - 2.0 * thetaW) -
              2.0 * thetaO * std::sin(thetaO) + std::cos(thetaO));
}

double surfaceMeasure(const LightBounds& b) {
  const glm::dvec3 d = glm::dvec3(b.hi) - glm::dvec3(b.lo);
  // Lights on a point or a line still differ in size.
  return 2.0 * (d.x * d.y + d.y * d.z + d.z * d.x) + 0.01 * glm::dot(d, d);
}

double cost(const LightBounds& b) {
  return double(b.power) * orientationMeasure(b.thetaO, b.thetaE) * surfaceMeasure(b);
}

// Splits deeper than this go to the median: the tree stays shallow whatever the lights.
constexpr int kMaxSahDepth = 40;
constexpr int kBuckets = 12;

}  // namespace

LightBounds lightBounds(const dev::Light& l) {
  LightBounds b;
  b.power = std::isfinite(l.power) && l.power > 0.0f ? l.power : 0.0f;
  const glm::vec3 p = load(l.p0x, l.p0y, l.p0z);
  b.lo = b.hi = p;
  b.thetaE = float(0.5 * kPi);
  if (l.type == PR_LIGHT_TRIANGLE) {
    const glm::vec3 e1 = load(l.e1x, l.e1y, l.e1z), e2 = load(l.e2x, l.e2y, l.e2z);
    b.lo = glm::min(p, glm::min(p + e1, p + e2));
    b.hi = glm::max(p, glm::max(p + e1, p + e2));
    const glm::vec3 n = glm::cross(e1, e2);
    const float len = glm::length(n);
    if (len > 0.0f && std::isfinite(len)) {
      b.axis = n / len;
      b.thetaO = 0.0f;
    } else {
      b.thetaO = float(kPi);
    }
    b.twoSided = true;  // emitters shine from both faces
  } else if (l.type == PR_LIGHT_SPOT) {
    const glm::vec3 a = load(l.e1x, l.e1y, l.e1z);
    b.axis = glm::length(a) > 0.0f ? glm::normalize(a) : glm::vec3(0.0f, 0.0f, 1.0f);
    b.thetaO = std::acos(std::clamp(l.cos_outer, -1.0f, 1.0f));
    // The light leaves only inside the cone; a small margin keeps its edge against round-off.
    b.thetaE = 0.01f;
  } else {
    b.thetaO = float(kPi);  // a point light: every direction
  }
  if (!std::isfinite(b.lo.x + b.lo.y + b.lo.z + b.hi.x + b.hi.y + b.hi.z)) {
    b.power = 0.0f;
    b.lo = b.hi = glm::vec3(0.0f);
  }
  return b;
}

LightBounds unionOf(const LightBounds& a, const LightBounds& b) {
  // A light with no power is never chosen: the node need not bound it.
  if (!(a.power > 0.0f)) return b;
  if (!(b.power > 0.0f)) return a;
  LightBounds u;
  u.lo = glm::min(a.lo, b.lo);
  u.hi = glm::max(a.hi, b.hi);
  u.power = a.power + b.power;
  u.thetaE = std::max(a.thetaE, b.thetaE);
  u.twoSided = a.twoSided || b.twoSided;
  // The smallest cone holding both cones.
  const glm::dvec3 wa = glm::dvec3(a.axis), wb = glm::dvec3(b.axis);
  // atan2, not acos: well conditioned for nearly parallel axes.
  const double thetaD = std::atan2(glm::length(glm::cross(wa, wb)), glm::dot(wa, wb));
  if (std::min(thetaD + b.thetaO, kPi) <= a.thetaO) {
    u.axis = a.axis, u.thetaO = a.thetaO;
    return u;
  }
  if (std::min(thetaD + a.thetaO, kPi) <= b.thetaO) {
    u.axis = b.axis, u.thetaO = b.thetaO;
    return u;
  }
  const double thetaO = 0.5 * (a.thetaO + thetaD + b.thetaO);
  const glm::dvec3 k = glm::cross(wa, wb);
  const double kl = glm::length(k);
  if (thetaO >= kPi || !(kl > 1e-12)) {
    u.axis = a.axis, u.thetaO = float(kPi);
    return u;
  }
  // Rotate a's axis towards b's by thetaO - a.thetaO (k is orthogonal to wa).
  const double r = thetaO - a.thetaO;
  const glm::dvec3 kn = k / kl;
  u.axis = glm::vec3(glm::normalize(wa * std::cos(r) + glm::cross(kn, wa) * std::sin(r)));
  // Round-off in the axis must not leave either cone outside.
  u.thetaO = float(std::min(kPi, thetaO * (1.0 + 1e-6) + 1e-6));
  return u;
}

void LightBvh::store(uint32_t node, const LightBounds& b) {
  dev::LightNode& n = nodes_[node];
  const glm::vec3 c = 0.5f * (b.lo + b.hi), half = 0.5f * (b.hi - b.lo);
  n.cx = c.x, n.cy = c.y, n.cz = c.z;
  n.r2 = glm::dot(half, half);
  n.radius = std::sqrt(n.r2);
  n.power = b.power;
  n.axis_x = b.axis.x, n.axis_y = b.axis.y, n.axis_z = b.axis.z;
  n.cos_o = b.thetaO >= float(kPi) ? -1.0f : float(std::cos(double(b.thetaO)));
  n.sin_o = b.thetaO >= float(kPi) ? 0.0f : float(std::sin(double(b.thetaO)));
  n.cos_e = float(std::cos(double(b.thetaE)));
  n.flags = (n.flags & PR_LIGHT_NODE_LEAF) | (b.twoSided ? PR_LIGHT_NODE_TWO_SIDED : 0u);
  nodeBounds_[node] = b;
}

uint32_t LightBvh::buildRange(std::vector<uint32_t>& order, const std::vector<LightBounds>& bounds,
                              uint32_t begin, uint32_t end, uint32_t parent) {
  const uint32_t node = static_cast<uint32_t>(nodes_.size());
  nodes_.push_back(dev::LightNode{});
  nodeBounds_.emplace_back();
  nodes_[node].parent = parent;
  if (end - begin == 1) {
    nodes_[node].flags = PR_LIGHT_NODE_LEAF;
    nodes_[node].index = order[begin];
    store(node, bounds[order[begin]]);
    return node;
  }
  int depth = 0;
  for (uint32_t p = parent; p != PR_INVALID_INDEX; p = nodes_[p].parent) ++depth;

  glm::vec3 clo(INFINITY), chi(-INFINITY), lo(INFINITY), hi(-INFINITY);
  for (uint32_t i = begin; i < end; ++i) {
    const LightBounds& b = bounds[order[i]];
    const glm::vec3 c = 0.5f * (b.lo + b.hi);
    clo = glm::min(clo, c), chi = glm::max(chi, c);
    lo = glm::min(lo, b.lo), hi = glm::max(hi, b.hi);
  }
  const glm::vec3 ext = hi - lo, cext = chi - clo;
  const float maxExtent = std::max(ext.x, std::max(ext.y, ext.z));
  auto centroid = [&](uint32_t light, int dim) {
    return 0.5f * (bounds[light].lo[dim] + bounds[light].hi[dim]);
  };
  auto bucketOf = [&](uint32_t light, int dim) {
    const int k = int(kBuckets * (centroid(light, dim) - clo[dim]) / cext[dim]);
    return std::clamp(k, 0, kBuckets - 1);
  };

  // Binned split by the cost of Estevez and Kulla: power x orientation x surface, regularised
  // against splitting a thin node across its thin side.
  int bestDim = -1, bestSplit = 0;
  double bestCost = INFINITY;
  if (depth < kMaxSahDepth) {
    for (int dim = 0; dim < 3; ++dim) {
      if (!(cext[dim] > 0.0f)) continue;
      std::array<LightBounds, kBuckets> bucket{};
      std::array<uint32_t, kBuckets> count{};
      for (uint32_t i = begin; i < end; ++i) {
        const int k = bucketOf(order[i], dim);
        bucket[k] = count[k] ? unionOf(bucket[k], bounds[order[i]]) : bounds[order[i]];
        ++count[k];
      }
      const double kr = ext[dim] > 0.0f ? double(maxExtent) / ext[dim] : 1.0;
      for (int split = 1; split < kBuckets; ++split) {
        LightBounds left, right;
        uint32_t nl = 0, nr = 0;
        for (int k = 0; k < split; ++k)
          if (count[k]) left = nl ? unionOf(left, bucket[k]) : bucket[k], nl += count[k];
        for (int k = split; k < kBuckets; ++k)
          if (count[k]) right = nr ? unionOf(right, bucket[k]) : bucket[k], nr += count[k];
        if (!nl || !nr) continue;
        const double c = kr * (cost(left) + cost(right));
        if (c < bestCost) bestCost = c, bestDim = dim, bestSplit = split;
      }
    }
  }
  uint32_t mid;
  if (bestDim >= 0) {
    mid = static_cast<uint32_t>(
        std::partition(order.begin() + begin, order.begin() + end,
                       [&](uint32_t l) { return bucketOf(l, bestDim) < bestSplit; }) -
        order.begin());
  } else {
    // Deep, or every centre in one place: halves by count along the widest spread.
    int dim = 0;
    for (int d = 1; d < 3; ++d)
      if (cext[d] > cext[dim]) dim = d;
    mid = begin + (end - begin) / 2;
    std::nth_element(order.begin() + begin, order.begin() + mid, order.begin() + end,
                     [&](uint32_t a, uint32_t b) {
                       const float ca = centroid(a, dim), cb = centroid(b, dim);
                       return ca < cb || (ca == cb && a < b);
                     });
  }
  buildRange(order, bounds, begin, mid, node);
  const uint32_t second = buildRange(order, bounds, mid, end, node);
  nodes_[node].index = second;
  store(node, unionOf(nodeBounds_[node + 1], nodeBounds_[second]));
  return node;
}

void LightBvh::build(std::vector<dev::Light>* lights, uint32_t count) {
  count_ = count;
  nodes_.clear();
  nodeBounds_.clear();
  for (auto& l : *lights) l.leaf = PR_INVALID_INDEX;
  if (count == 0) {
    nodes_.push_back(dev::LightNode{});
    nodes_[0].flags = PR_LIGHT_NODE_LEAF;
    nodes_[0].parent = PR_INVALID_INDEX;
    nodeBounds_.emplace_back();
    return;
  }
  std::vector<LightBounds> bounds(count);
  for (uint32_t i = 0; i < count; ++i) bounds[i] = lightBounds((*lights)[i]);
  std::vector<uint32_t> order(count);
  std::iota(order.begin(), order.end(), 0u);
  nodes_.reserve(2 * size_t(count) - 1);
  buildRange(order, bounds, 0, count, PR_INVALID_INDEX);
  for (uint32_t n = 0; n < nodes_.size(); ++n)
    if (nodes_[n].flags & PR_LIGHT_NODE_LEAF) (*lights)[nodes_[n].index].leaf = n;
}

void LightBvh::refit(std::vector<dev::Light>* lights) {
  if (count_ == 0) return;
  // Children follow their parent: one backward pass sees both children before the parent.
  for (size_t n = nodes_.size(); n-- > 0;) {
    dev::LightNode& node = nodes_[n];
    if (node.flags & PR_LIGHT_NODE_LEAF) {
      dev::Light& l = (*lights)[node.index];
      l.leaf = static_cast<uint32_t>(n);
      store(static_cast<uint32_t>(n), lightBounds(l));
    } else {
      store(static_cast<uint32_t>(n), unionOf(nodeBounds_[n + 1], nodeBounds_[node.index]));
    }
  }
}

}  // namespace pr
