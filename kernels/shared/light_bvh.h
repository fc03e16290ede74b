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

// 64 bytes. Depth-first order: an interior node's first child is the next node. The lights'
// box is kept as its bounding sphere, which is all the importance needs.
typedef struct {
  float cx, cy, cz;              // centre of the lights' bounding box
  float power;                   // sum of the lights' selection weights
  float axis_x, axis_y, axis_z;  // the cone holding every emitter's normal (or spot axis)
  u32 index;                     // interior: second child; leaf: the light
  float cos_o, sin_o;            // cosine and sine of that cone's half angle
  float cos_e;   // cosine of the angle from a normal beyond which nothing is emitted
  float r2;      // squared half diagonal of the box
  u32 flags;     // PR_LIGHT_NODE_*
  u32 parent;    // PR_INVALID_INDEX at the root
  float radius;  // half diagonal of the box
  u32 pad;
} LightNode;

// An estimate, up to a common factor, of the light that the node's emitters can send to p (and,
// where n is not zero, that a surface with shading normal n at p can reflect): power over the
// squared distance to the node's centre, times the cosines at the emitter and the receiver
// maximised over the node's bounds and normals. Zero only where none of them can reach p.
PR_INLINE float light_node_importance(PR_GLOBAL const LightNode* node, float3 p, float3 n) {
  const float power = node->power;
  if (!(power > 0.0f)) return 0.0f;
  const float3 d = p - make_float3(node->cx, node->cy, node->cz);  // from the centre to p
  const float r2 = node->r2, dist2 = dot(d, d);
  // The squared distance is clamped at a quarter of the bounding sphere's squared radius
  // (measured on the many-lights atrium: relMSE 0.099 against 0.159 at the full radius, 0.107
  // at pbrt-v4's half diagonal length, 0.147 unclamped).
  const float inv_d2 = 1.0f / fmax(fmax(dist2, 0.25f * r2), 1e-20f);
  // Inside the bounding sphere every direction and normal is possible.
  if (!(dist2 > r2)) return power * inv_d2;
  // The cone of directions from p to the bounding sphere.
  const float inv_dist = rsqrt(dist2);
  const float sin_b = node->radius * inv_dist;
  const float cos_b = sqrt(fmax(0.0f, 1.0f - sin_b * sin_b));
  const float3 wi = d * inv_dist;
  // cos(max(0, theta_w - theta_o - theta_b)): the smallest angle between an emitter's normal
  // and a direction from the node to p. Sines only where an angle is not clamped to 0.
  float cos_p = 1.0f;
  float cos_w = dot(make_float3(node->axis_x, node->axis_y, node->axis_z), wi);
  if (node->flags & PR_LIGHT_NODE_TWO_SIDED) cos_w = fabs(cos_w);
  if (cos_w < node->cos_o) {
    const float sin_w = sqrt(fmax(0.0f, 1.0f - cos_w * cos_w));
    const float cos_x = cos_w * node->cos_o + sin_w * node->sin_o;
    const float sin_x = sin_w * node->cos_o - cos_w * node->sin_o;
    cos_p = cos_x >= cos_b ? 1.0f : cos_x * cos_b + sin_x * sin_b;
    if (cos_p <= node->cos_e) return 0.0f;
  }
  float importance = power * cos_p * inv_d2;
  if (has_normal(n)) {
    // One-sided: every non-delta BSDF here reflects, so only light above n can be received.
    const float cos_i = clamp(-dot(wi, n), -1.0f, 1.0f);
    if (cos_i < cos_b) {
      const float sin_i = sqrt(fmax(0.0f, 1.0f - cos_i * cos_i));
      const float cos_pi = cos_i * cos_b + sin_i * sin_b;
      if (!(cos_pi > 0.0f)) return 0.0f;
      importance *= cos_pi;
    }
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
PR_STATIC_ASSERT(offsetof(pr::dev::LightNode, r2) == 44, "LightNode layout");
PR_STATIC_ASSERT(offsetof(pr::dev::LightNode, parent) == 52, "LightNode layout");
