// The light BVH (docs/design.md section 6): emitters clustered by position, the cone of their
// normals and their power, so that a receiving point chooses a light with probability close to
// the share of light it gets from it (Estevez and Kulla 2018). Every light but directional ones
// is a leaf; directional lights are chosen by power beside the tree. The host builds the tree
// once and refits it whenever lights move, so that each light keeps its leaf.
#pragma once

#include "shared/math.h"
#include "shared/types.h"

PR_NAMESPACE_BEGIN

#define PR_LIGHT_NODE_LEAF 1u
#define PR_LIGHT_NODE_TWO_SIDED 2u

// 64 bytes. Depth-first order: an interior node's first child is the next node.
typedef struct {
  float lo_x, lo_y, lo_z;
  float power;  // sum of the lights' selection weights
  float hi_x, hi_y, hi_z;
  u32 index;                     // interior: second child; leaf: the light
  float axis_x, axis_y, axis_z;  // the cone holding every emitter's normal (or spot axis)
  float cos_o;                   // cosine of that cone's half angle
  float cos_e;   // cosine of the angle from a normal beyond which nothing is emitted
  u32 flags;     // PR_LIGHT_NODE_*
  u32 parent;    // PR_INVALID_INDEX at the root
  float sin_o;   // sine of the cone's half angle
} LightNode;

// cos(max(0, a - b)) and sin(max(0, a - b)) for angles in [0, pi] given by sine and cosine.
PR_INLINE float cos_sub_clamped(float sin_a, float cos_a, float sin_b, float cos_b) {
  return cos_a >= cos_b ? 1.0f : cos_a * cos_b + sin_a * sin_b;
}
PR_INLINE float sin_sub_clamped(float sin_a, float cos_a, float sin_b, float cos_b) {
  return cos_a >= cos_b ? 0.0f : sin_a * cos_b - cos_a * sin_b;
}

// An estimate, up to a common factor, of the light that the node's emitters can send to p (and,
// where n is not zero, that a surface with shading normal n at p can reflect): power over the
// squared distance to the node's centre, times the cosines at the emitter and the receiver
// maximised over the node's bounds and normals. Zero only where none of them can reach p.
PR_INLINE float light_node_importance(PR_GLOBAL const LightNode* node, float3 p, float3 n) {
  if (!(node->power > 0.0f)) return 0.0f;
  const float3 lo = make_float3(node->lo_x, node->lo_y, node->lo_z);
  const float3 hi = make_float3(node->hi_x, node->hi_y, node->hi_z);
  const float3 half_size = 0.5f * (hi - lo);
  const float3 d = p - (lo + half_size);  // from the centre to p
  const float r2 = dot(half_size, half_size), dist2 = dot(d, d);
  // The cone of directions from p to the node's bounding sphere (everything from inside it).
  float cos_b = -1.0f, sin_b = 0.0f;
  if (dist2 > r2) {
    const float sin2 = r2 / dist2;
    sin_b = sqrt(sin2);
    cos_b = sqrt(fmax(0.0f, 1.0f - sin2));
  }
  const float3 wi = dist2 > 0.0f ? d * (1.0f / sqrt(dist2)) : make_float3(0.0f, 0.0f, 1.0f);
  float cos_w = dot(make_float3(node->axis_x, node->axis_y, node->axis_z), wi);
  if (node->flags & PR_LIGHT_NODE_TWO_SIDED) cos_w = fabs(cos_w);
  const float sin_w = sqrt(fmax(0.0f, 1.0f - cos_w * cos_w));
  const float sin_o = node->sin_o;
  // The smallest angle between an emitter's normal and a direction from the node to p.
  const float cos_x = cos_sub_clamped(sin_w, cos_w, sin_o, node->cos_o);
  const float sin_x = sin_sub_clamped(sin_w, cos_w, sin_o, node->cos_o);
  const float cos_p = cos_sub_clamped(sin_x, cos_x, sin_b, cos_b);
  if (cos_p <= node->cos_e) return 0.0f;
  // The squared distance is clamped at a quarter of the bounding sphere's squared radius
  // (measured on the many-lights atrium: relMSE 0.099 against 0.159 at the full radius, 0.107
  // at pbrt-v4's half diagonal length, 0.147 unclamped).
  float importance = node->power * cos_p / fmax(fmax(dist2, 0.25f * r2), 1e-20f);
  if (n.x != 0.0f || n.y != 0.0f || n.z != 0.0f) {
    // One-sided: every non-delta BSDF here reflects, so only light above n can be received.
    const float cos_i = clamp(-dot(wi, n), -1.0f, 1.0f);
    const float sin_i = sqrt(fmax(0.0f, 1.0f - cos_i * cos_i));
    const float cos_pi = cos_sub_clamped(sin_i, cos_i, sin_b, cos_b);
    if (!(cos_pi > 0.0f)) return 0.0f;
    importance *= cos_pi;
  }
  return fmax(importance, 0.0f);
}

#define PR_ONE_MINUS_EPSILON 0.99999994f

// Chooses a light for the receiver (p, n) by descending the tree with u; *pmf is the
// probability of the choice. PR_INVALID_INDEX where no light reaches p.
PR_INLINE u32 light_bvh_sample(PR_GLOBAL const LightNode* nodes, float3 p, float3 n, float u,
                               float* pmf) {
  *pmf = 0.0f;
  if ((nodes[0].flags & PR_LIGHT_NODE_LEAF) && !(light_node_importance(nodes, p, n) > 0.0f))
    return PR_INVALID_INDEX;
  u32 i = 0u;
  float prob = 1.0f;
  while (!(nodes[i].flags & PR_LIGHT_NODE_LEAF)) {
    const u32 c0 = i + 1u, c1 = nodes[i].index;
    const float i0 = light_node_importance(nodes + c0, p, n);
    const float i1 = light_node_importance(nodes + c1, p, n);
    const float sum = i0 + i1;
    if (!(sum > 0.0f) || !isfinite_f(sum)) return PR_INVALID_INDEX;
    const float p0 = i0 / sum;
    if (u < p0) {
      i = c0;
      u = fmin(u / p0, PR_ONE_MINUS_EPSILON);
      prob *= p0;
    } else {
      i = c1;
      u = fmin((u - p0) / (1.0f - p0), PR_ONE_MINUS_EPSILON);
      prob *= i1 / sum;
    }
  }
  *pmf = prob;
  return nodes[i].index;
}

// The probability that light_bvh_sample chooses the light at `leaf` for the receiver (p, n).
PR_INLINE float light_bvh_pmf(PR_GLOBAL const LightNode* nodes, u32 leaf, float3 p, float3 n) {
  if (leaf == PR_INVALID_INDEX) return 0.0f;
  if (nodes[leaf].parent == PR_INVALID_INDEX)
    return light_node_importance(nodes + leaf, p, n) > 0.0f ? 1.0f : 0.0f;
  float prob = 1.0f;
  u32 i = leaf;
  while (nodes[i].parent != PR_INVALID_INDEX) {
    const u32 parent = nodes[i].parent, c0 = parent + 1u, c1 = nodes[parent].index;
    const float i0 = light_node_importance(nodes + c0, p, n);
    const float i1 = light_node_importance(nodes + c1, p, n);
    const float sum = i0 + i1;
    if (!(sum > 0.0f) || !isfinite_f(sum)) return 0.0f;
    prob *= (i == c0 ? i0 : i1) / sum;
    i = parent;
  }
  return prob;
}

PR_NAMESPACE_END

PR_STATIC_ASSERT(sizeof(pr::dev::LightNode) == 64, "LightNode layout");
PR_STATIC_ASSERT(offsetof(pr::dev::LightNode, index) == 28, "LightNode layout");
PR_STATIC_ASSERT(offsetof(pr::dev::LightNode, parent) == 56, "LightNode layout");
