// Ray queries against the scene's two acceleration structures (docs/design.md section 3), in the C
// subset that compiles as OpenCL C and as C++: the host's CPU reference runs this very code.
//
//   SSG: one BVH over all static triangles, in world space.
//   DSG: a top-level BVH (TLAS) over this frame's instances; each instance points at the
//        object-space BVH of its mesh. Rays are carried into object space without
//        renormalising the direction, so t is the same in both spaces.
//
// Queries: intersect_* (closest hit) and occluded_* (any hit) for the whole scene, the SSG
// alone and the DSG alone. A ray hits a triangle at t when ray.tmin < t < ray.tmax.
//
// Self-intersection policy: rays that leave a surface start at offset_ray_origin(p, ng) (ng the
// geometric normal on the side the ray leaves to, see spawn_ray / spawn_ray_to) with tmin = 0.
// The offset is a few hundred ulps of p's coordinates (a fixed tiny distance near the origin),
// so it scales with the scene and no scene-dependent epsilon on t is needed.
//
// Nodes are PR_BVH_WIDTH wide (types.h); leaves are packets of up to 4 triangles. Traversal
// keeps a fixed stack of PR_BVH_STACK_SIZE entries; the host builder checks that no path from
// the root can need more (it pushes the children a ray enters, less the one it descends into).
#pragma once

#include "shared/math.h"
#include "shared/types.h"

#ifdef PR_DEVICE_CODE
// Same rounding as the host's CPU reference: no fused multiply-adds behind our back.
#pragma OPENCL FP_CONTRACT OFF
#endif

#include "shared/motion.h"

#define PR_BVH_STACK_SIZE 64

// Slab distances are scaled by this before the overlap test so rounding never culls a box
// that holds a hit (1 + 2 * gamma(3) in pbrt's terms, rounded up).
#define PR_BVH_FAR_SCALE 1.00000036f

PR_NAMESPACE_BEGIN

// Device buffers of both structures. Build it inside a kernel from the kernel's arguments
// (OpenCL C 1.2 allows pointers to __global in private structs, not in kernel arguments):
// see PR_SCENE_GEOM() below and PR_ARGS_SCENE_GEOM (shared/kernel_args.h).
typedef struct {
  PR_GLOBAL const BvhNode* static_nodes;  // root at 0; an empty SSG is a node with no child
  PR_GLOBAL const BvhTriPacket* static_tris;
  PR_GLOBAL const BvhNode* tlas_nodes;     // root at 0; read only when instance_count > 0
  PR_GLOBAL const BvhInstance* instances;  // indexed by the TLAS's leaves
  PR_GLOBAL const BvhNode* mesh_nodes;     // all meshes' BVHs, absolute indices
  PR_GLOBAL const BvhTriPacket* mesh_tris;
  u32 instance_count;
  PR_GLOBAL const float* motion;  // --shutter: each instance's transforms (shared/motion.h)
  u32 motion_steps;               // 1: no motion blur (`instances` hold the transforms)
  float time;                     // the path's time in the shutter interval (scene_at_sample)
  // Deforming meshes under a shutter: their packets and node boxes at each step, and per mesh
  // PR_MESH_MOTION_WORDS words: its first packet in mesh_tris, its packet count, its steps' first
  // packet in motion_tris, its steps (1: none), its root node, its steps' first node record in
  // motion_bounds (6 * PR_BVH_WIDTH floats each), two unused.
  PR_GLOBAL const BvhTriPacket* motion_tris;
  PR_GLOBAL const u32* mesh_motion;
  PR_GLOBAL const float* motion_bounds;
} SceneGeom;

#define PR_MESH_MOTION_WORDS 8u

// A deforming mesh at the ray's time: packet p of mesh_tris is, at step k, steps[(p - first) *
// stride + k], and node n's child boxes bounds[((n - first_node) * stride + k) * 6 *
// PR_BVH_WIDTH ...]; a ray blends steps k and k + 1 by a. Always written whole (stride 1:
// nothing deforms).
typedef struct {
  PR_GLOBAL const BvhTriPacket* steps;
  PR_GLOBAL const float* bounds;
  u32 first, first_node, stride, k;  // stride: the steps of a packet or node
  float a;
} PacketBlend;

PR_INLINE PacketBlend packet_blend_none(void) {
  PacketBlend b;
  b.steps = 0;
  b.bounds = 0;
  b.first = b.first_node = 0u;
  b.stride = 1u;
  b.k = 0u;
  b.a = 0.0f;
  return b;
}

// A ray prepared for traversal (private, never in a buffer). near_* / far_* are the offsets of
// the slab planes the ray meets first / last in BvhNode.bounds, chosen by the direction's signs.
typedef struct {
  float3 o, d, inv_d;
  float tmin, tmax;
  int near_x, near_y, near_z, far_x, far_y, far_z;
} BvhRay;

PR_INLINE float bvh_safe_inverse(float d) {
  // A zero component would give 0 * inf = NaN in the slab test; a huge finite slope does not.
  const float tiny = 1e-30f;
  return 1.0f / (fabs(d) > tiny ? d : (d < 0.0f ? -tiny : tiny));
}

PR_INLINE BvhRay bvh_ray(float3 o, float3 d, float tmin, float tmax) {
  BvhRay r;
  r.o = o;
  r.d = d;
  r.inv_d = make_float3(bvh_safe_inverse(d.x), bvh_safe_inverse(d.y), bvh_safe_inverse(d.z));
  r.tmin = tmin;
  r.tmax = tmax;
  const int w = PR_BVH_WIDTH;
  const int neg_x = r.inv_d.x < 0.0f, neg_y = r.inv_d.y < 0.0f, neg_z = r.inv_d.z < 0.0f;
  r.near_x = neg_x ? w : 0;
  r.far_x = neg_x ? 0 : w;
  r.near_y = neg_y ? 3 * w : 2 * w;
  r.far_y = neg_y ? 2 * w : 3 * w;
  r.near_z = neg_z ? 5 * w : 4 * w;
  r.far_z = neg_z ? 4 * w : 5 * w;
  return r;
}

// min/max by comparison: slab distances are never NaN (finite or inverted-infinite boxes,
// bvh_safe_inverse), so fmin/fmax's NaN handling is dead weight in the hottest function.
PR_INLINE float bvh_min(float a, float b) {
  return a < b ? a : b;
}
PR_INLINE float bvh_max(float a, float b) {
  return a > b ? a : b;
}

#ifdef PR_DEVICE_CODE
// bvh_bits(m): bit i set where lane i of the comparison mask m is true.
#if PR_BVH_WIDTH == 2
typedef float2 bvh_fw;
#define bvh_loadw(p) vload2(0, p)
#define bvh_storew(v, p) vstore2(v, 0, p)
PR_INLINE u32 bvh_bits(int2 m) {
  const int2 b = m & (int2)(1, 2);
  return (u32)(b.x | b.y);
}
#elif PR_BVH_WIDTH == 4
typedef float4 bvh_fw;
#define bvh_loadw(p) vload4(0, p)
#define bvh_storew(v, p) vstore4(v, 0, p)
PR_INLINE u32 bvh_bits(int4 m) {
  const int4 b = m & (int4)(1, 2, 4, 8);
  const int2 h = b.lo | b.hi;
  return (u32)(h.x | h.y);
}
#elif PR_BVH_WIDTH == 8
typedef float8 bvh_fw;
#define bvh_loadw(p) vload8(0, p)
#define bvh_storew(v, p) vstore8(v, 0, p)
PR_INLINE u32 bvh_bits(int8 m) {
  const int8 b = m & (int8)(1, 2, 4, 8, 16, 32, 64, 128);
  const int4 q = b.lo | b.hi;
  const int2 h = q.lo | q.hi;
  return (u32)(h.x | h.y);
}
#else
#error "PR_BVH_WIDTH must be 2, 4 or 8"
#endif
#endif

// Entry distance of the ray into each child box of n, and the mask of the children it enters
// within [tmin, tmax] (bit i: child i; entry[i] is meaningful only there). Far distances are
// scaled by PR_BVH_FAR_SCALE so rounding never culls a box that holds a hit. The device tests
// all children at once with one float vector per slab; the host runs the same operations lane
// by lane (bit for bit the same results).
#ifdef PR_DEVICE_CODE
// The slab test on the children's near planes (ax, ay, az) and far planes (bx, by, bz).
PR_INLINE u32 bvh_slab_entries(bvh_fw ax, bvh_fw ay, bvh_fw az, bvh_fw bx, bvh_fw by, bvh_fw bz,
                               const BvhRay* r, float* entry) {
  const bvh_fw x0 = (ax - r->o.x) * r->inv_d.x;
  const bvh_fw y0 = (ay - r->o.y) * r->inv_d.y;
  const bvh_fw z0 = (az - r->o.z) * r->inv_d.z;
  const bvh_fw x1 = (bx - r->o.x) * r->inv_d.x;
  const bvh_fw y1 = (by - r->o.y) * r->inv_d.y;
  const bvh_fw z1 = (bz - r->o.z) * r->inv_d.z;
  const bvh_fw tmin = (bvh_fw)(r->tmin);
  // select(b, a, a > b) is a > b ? a : b per lane: bvh_max, as the host computes it.
  const bvh_fw nxy = select(y0, x0, x0 > y0), nz = select(tmin, z0, z0 > tmin);
  const bvh_fw tnear = select(nz, nxy, nxy > nz);
  const bvh_fw fxy = select(y1, x1, x1 < y1);
  const bvh_fw tfar = select(z1, fxy, fxy < z1) * PR_BVH_FAR_SCALE;
  const u32 bits = bvh_bits((tnear <= tfar) & (tnear <= r->tmax));
  if (bits != 0u) bvh_storew(tnear, entry);
  return bits;
}
#endif

// bvh_node_entries on child boxes b (BvhNode.bounds' layout).
PR_INLINE u32 bvh_bounds_entries(PR_GLOBAL const float* b, const BvhRay* r, float* entry) {
#ifdef PR_DEVICE_CODE
  return bvh_slab_entries(bvh_loadw(b + r->near_x), bvh_loadw(b + r->near_y),
                          bvh_loadw(b + r->near_z), bvh_loadw(b + r->far_x),
                          bvh_loadw(b + r->far_y), bvh_loadw(b + r->far_z), r, entry);
#else
  u32 mask = 0u;
  for (int i = 0; i < PR_BVH_WIDTH; ++i) {
    const float x0 = (b[r->near_x + i] - r->o.x) * r->inv_d.x;
    const float y0 = (b[r->near_y + i] - r->o.y) * r->inv_d.y;
    const float z0 = (b[r->near_z + i] - r->o.z) * r->inv_d.z;
    const float x1 = (b[r->far_x + i] - r->o.x) * r->inv_d.x;
    const float y1 = (b[r->far_y + i] - r->o.y) * r->inv_d.y;
    const float z1 = (b[r->far_z + i] - r->o.z) * r->inv_d.z;
    const float tnear = bvh_max(bvh_max(x0, y0), bvh_max(z0, r->tmin));
    const float tfar = bvh_min(bvh_min(x1, y1), z1) * PR_BVH_FAR_SCALE;
    entry[i] = tnear;
    if (tnear <= tfar && tnear <= r->tmax) mask |= 1u << i;
  }
  return mask;
#endif
}

PR_INLINE u32 bvh_node_entries(PR_GLOBAL const BvhNode* n, const BvhRay* r, float* entry) {
  return bvh_bounds_entries(n->bounds, r, entry);
}

// The same on the child boxes blended between two motion steps' (b0, b1) by a: boxes that hold
// the triangles blended alike (a blend of points in two boxes lies in the blend of the boxes).
PR_INLINE u32 bvh_blend_entries(PR_GLOBAL const float* b0, PR_GLOBAL const float* b1, float a,
                                const BvhRay* r, float* entry) {
#ifdef PR_DEVICE_CODE
#define PR_PLANE(o) (bvh_loadw(b0 + (o)) + (bvh_loadw(b1 + (o)) - bvh_loadw(b0 + (o))) * a)
  return bvh_slab_entries(PR_PLANE(r->near_x), PR_PLANE(r->near_y), PR_PLANE(r->near_z),
                          PR_PLANE(r->far_x), PR_PLANE(r->far_y), PR_PLANE(r->far_z), r, entry);
#undef PR_PLANE
#else
  float b[6 * PR_BVH_WIDTH];
  for (int i = 0; i < 6 * PR_BVH_WIDTH; ++i) b[i] = b0[i] + (b1[i] - b0[i]) * a;
  return bvh_bounds_entries(b, r, entry);
#endif
}

// dot and cross written out: OpenCL's built-ins may fuse or reorder (their error bounds allow
// it, and Intel's CPU runtime does), which moves hits on grazing rays away from the CPU reference.
PR_INLINE float bvh_dot(float3 a, float3 b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
PR_INLINE float3 bvh_cross(float3 a, float3 b) {
  return make_float3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}

// Moller-Trumbore against one packed triangle. Writes t and the barycentrics (u for v1, v for
// v2) when tmin < t < tmax. Zero-area triangles give det == 0 (or NaN) and are never hit.
PR_INLINE int intersect_triangle(PR_GLOBAL const BvhTriangle* tri, float3 o, float3 d, float tmin,
                                 float tmax, float* t, float* u, float* v) {
  const float3 e1 = make_float3(tri->e1x, tri->e1y, tri->e1z);
  const float3 e2 = make_float3(tri->e2x, tri->e2y, tri->e2z);
  const float3 p = bvh_cross(d, e2);
  const float det = bvh_dot(e1, p);
  if (det == 0.0f) return 0;
  const float inv_det = 1.0f / det;
  const float3 s = o - make_float3(tri->v0x, tri->v0y, tri->v0z);
  const float uu = bvh_dot(s, p) * inv_det;
  if (!(uu >= 0.0f && uu <= 1.0f)) return 0;
  const float3 q = bvh_cross(s, e1);
  const float vv = bvh_dot(d, q) * inv_det;
  if (!(vv >= 0.0f && uu + vv <= 1.0f)) return 0;
  const float tt = bvh_dot(e2, q) * inv_det;
  if (!(tt > tmin && tt < tmax)) return 0;
  *t = tt;
  *u = uu;
  *v = vv;
  return 1;
}

// The ray against a leaf's triangles: the lane of the nearest hit in (tmin, tmax) (the lowest
// lane among equal distances) with its t, u, v, or -1. The device runs intersect_triangle's
// operations on all lanes at once with float4s; the host runs intersect_triangle lane by lane.
#ifdef PR_DEVICE_CODE
// intersect_packet on the lanes already loaded (v0, e1, e2 of each of the 4 triangles).
PR_INLINE int intersect_lanes(float4 v0x, float4 v0y, float4 v0z, float4 e1x, float4 e1y,
                              float4 e1z, float4 e2x, float4 e2y, float4 e2z, const BvhRay* r,
                              float* t, float* u, float* v) {
  const float3 d = r->d;
  const float4 px = d.y * e2z - d.z * e2y, py = d.z * e2x - d.x * e2z, pz = d.x * e2y - d.y * e2x;
  const float4 det = e1x * px + e1y * py + e1z * pz;
  const float4 inv_det = 1.0f / det;
  const float4 sx = r->o.x - v0x, sy = r->o.y - v0y, sz = r->o.z - v0z;
  const float4 uu = (sx * px + sy * py + sz * pz) * inv_det;
  const float4 qx = sy * e1z - sz * e1y, qy = sz * e1x - sx * e1z, qz = sx * e1y - sy * e1x;
  const float4 vv = (d.x * qx + d.y * qy + d.z * qz) * inv_det;
  const float4 tt = (e2x * qx + e2y * qy + e2z * qz) * inv_det;
  const int4 ok = (det != 0.0f) & (uu >= 0.0f) & (uu <= 1.0f) & (vv >= 0.0f) & (uu + vv <= 1.0f) &
                  (tt > r->tmin) & (tt < r->tmax);
  if (!any(ok)) return -1;
  float ta[PR_BVH_PACKET], ua[PR_BVH_PACKET], va[PR_BVH_PACKET];
  vstore4(select((float4)(PR_INF_F), tt, ok), 0, ta);
  vstore4(uu, 0, ua);
  vstore4(vv, 0, va);
  int lane = -1;
  float best = r->tmax;
  for (int i = 0; i < PR_BVH_PACKET; ++i) {
    if (ta[i] < best) {
      best = ta[i];
      lane = i;
    }
  }
  *t = ta[lane];
  *u = ua[lane];
  *v = va[lane];
  return lane;
}
#endif

PR_INLINE int intersect_packet(PR_GLOBAL const BvhTriPacket* p, const BvhRay* r, float* t, float* u,
                               float* v) {
#ifdef PR_DEVICE_CODE
  return intersect_lanes(vload4(0, p->v0x), vload4(0, p->v0y), vload4(0, p->v0z), vload4(0, p->e1x),
                         vload4(0, p->e1y), vload4(0, p->e1z), vload4(0, p->e2x), vload4(0, p->e2y),
                         vload4(0, p->e2z), r, t, u, v);
#else
  int lane = -1;
  float tmax = r->tmax;
  for (int i = 0; i < PR_BVH_PACKET; ++i) {
    BvhTriangle tri;
    tri.v0x = p->v0x[i], tri.v0y = p->v0y[i], tri.v0z = p->v0z[i];
    tri.e1x = p->e1x[i], tri.e1y = p->e1y[i], tri.e1z = p->e1z[i];
    tri.e2x = p->e2x[i], tri.e2y = p->e2y[i], tri.e2z = p->e2z[i];
    if (intersect_triangle(&tri, r->o, r->d, r->tmin, tmax, t, u, v)) {
      lane = i;
      tmax = *t;
    }
  }
  return lane;
#endif
}

// The ray against leaf packet p of a deforming mesh at the ray's time: its two steps' triangles
// blended (a blend of corners is the blend of edges).
PR_INLINE int intersect_packet_blend(const PacketBlend* b, u32 p, const BvhRay* r, float* t,
                                     float* u, float* v) {
  PR_GLOBAL const BvhTriPacket* p0 = b->steps + (size_t)(p - b->first) * b->stride + b->k;
  PR_GLOBAL const BvhTriPacket* p1 = p0 + 1;
  const float a = b->a;
#ifdef PR_DEVICE_CODE
#define PR_LANES(f) (vload4(0, p0->f) + (vload4(0, p1->f) - vload4(0, p0->f)) * a)
  return intersect_lanes(PR_LANES(v0x), PR_LANES(v0y), PR_LANES(v0z), PR_LANES(e1x), PR_LANES(e1y),
                         PR_LANES(e1z), PR_LANES(e2x), PR_LANES(e2y), PR_LANES(e2z), r, t, u, v);
#undef PR_LANES
#else
  BvhTriPacket q = *p0;
  for (int i = 0; i < PR_BVH_PACKET; ++i) {
    q.v0x[i] += (p1->v0x[i] - p0->v0x[i]) * a, q.v0y[i] += (p1->v0y[i] - p0->v0y[i]) * a;
    q.v0z[i] += (p1->v0z[i] - p0->v0z[i]) * a, q.e1x[i] += (p1->e1x[i] - p0->e1x[i]) * a;
    q.e1y[i] += (p1->e1y[i] - p0->e1y[i]) * a, q.e1z[i] += (p1->e1z[i] - p0->e1z[i]) * a;
    q.e2x[i] += (p1->e2x[i] - p0->e2x[i]) * a, q.e2y[i] += (p1->e2y[i] - p0->e2y[i]) * a;
    q.e2z[i] += (p1->e2z[i] - p0->e2z[i]) * a;
  }
  return intersect_packet(&q, r, t, u, v);
#endif
}

// Pushes the children of n that the ray enters; closest hit keeps the pushed ones sorted
// farthest first (equal distances in child order), so the nearest is popped next. Returns
// whether any was pushed.
PR_INLINE int bvh_push_children(PR_GLOBAL const BvhNode* n, u32 mask, const float* entry,
                                u32* stack, float* stack_t, int* sp, int any_hit) {
  const int base = *sp;
  int top = base;
  for (; mask != 0u; mask &= mask - 1u) {
    const int i = 31 - (int)clz(mask & (0u - mask));  // lowest set bit
    const float t = entry[i];
    PR_KCHECK(top < PR_BVH_STACK_SIZE);  // the builder bounds every path's need
    int j = top++;
    if (!any_hit) {
      for (; j > base && stack_t[j - 1] <= t; --j) {
        stack[j] = stack[j - 1];
        stack_t[j] = stack_t[j - 1];
      }
    }
    stack[j] = n->child[i];
    stack_t[j] = t;
  }
  *sp = top;
  return top > base;
}

// Pops the next entry that starts before tmax (one beyond the nearest hit found since it was
// pushed is skipped). Returns 0 when the stack is empty.
PR_INLINE int bvh_pop(const u32* stack, const float* stack_t, int* sp, float tmax, u32* ref) {
  int s = *sp;
  do {
    if (s == 0) {
      *sp = 0;
      return 0;
    }
    --s;
  } while (stack_t[s] > tmax);
  *sp = s;
  *ref = stack[s];
  return 1;
}

// Traverses one BVH from node `root`. Closest hit (any_hit == 0): shrinks r->tmax to each
// nearer hit and fills *hit with inst = `inst`. Any hit: returns at the first one, *hit untouched.
PR_INLINE int bvh_traverse_blend(PR_GLOBAL const BvhNode* nodes,
                                 PR_GLOBAL const BvhTriPacket* packets, u32 root, BvhRay* r,
                                 Hit* hit, u32 inst, int any_hit, const PacketBlend* blend) {
  u32 stack[PR_BVH_STACK_SIZE];
  float stack_t[PR_BVH_STACK_SIZE];
  int sp = 0;
  int found = 0;
  u32 ref = root;
  for (;;) {
    if (!(ref & PR_BVH_LEAF_BIT)) {
      float entry[PR_BVH_WIDTH];
      u32 mask;
      if (blend->stride > 1u) {
        PR_GLOBAL const float* b0 =
            blend->bounds +
            ((size_t)(ref - blend->first_node) * blend->stride + blend->k) * (6 * PR_BVH_WIDTH);
        mask = bvh_blend_entries(b0, b0 + 6 * PR_BVH_WIDTH, blend->a, r, entry);
      } else {
        mask = bvh_node_entries(nodes + ref, r, entry);
      }
      if (bvh_push_children(nodes + ref, mask, entry, stack, stack_t, &sp, any_hit)) {
        ref = stack[--sp];
        continue;
      }
    } else {
      PR_GLOBAL const BvhTriPacket* p = packets + (ref & ~PR_BVH_LEAF_BIT);
      float t, u, v;
      const int lane = blend->stride > 1u
                           ? intersect_packet_blend(blend, ref & ~PR_BVH_LEAF_BIT, r, &t, &u, &v)
                           : intersect_packet(p, r, &t, &u, &v);
      if (lane >= 0) {
        if (any_hit) return 1;
        found = 1;
        r->tmax = t;
        hit->t = t;
        hit->u = u;
        hit->v = v;
        hit->prim = p->prim[lane];
        hit->inst = inst;
      }
    }
    if (!bvh_pop(stack, stack_t, &sp, r->tmax, &ref)) return found;
  }
}

PR_INLINE int bvh_traverse(PR_GLOBAL const BvhNode* nodes, PR_GLOBAL const BvhTriPacket* packets,
                           u32 root, BvhRay* r, Hit* hit, u32 inst, int any_hit) {
  const PacketBlend none = packet_blend_none();
  return bvh_traverse_blend(nodes, packets, root, r, hit, inst, any_hit, &none);
}

PR_INLINE float3 xform_point(PR_GLOBAL const float* m, float3 p) {
  return make_float3(m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3],
                     m[4] * p.x + m[5] * p.y + m[6] * p.z + m[7],
                     m[8] * p.x + m[9] * p.y + m[10] * p.z + m[11]);
}

PR_INLINE float3 xform_vector(PR_GLOBAL const float* m, float3 v) {
  return make_float3(m[0] * v.x + m[1] * v.y + m[2] * v.z, m[4] * v.x + m[5] * v.y + m[6] * v.z,
                     m[8] * v.x + m[9] * v.y + m[10] * v.z);
}

// The ray in the instance's object space; same t, direction not renormalised. Under motion blur,
// in the instance's space at the ray's time.
PR_INLINE BvhRay instance_ray(const SceneGeom* g, PR_GLOBAL const BvhInstance* inst,
                              const BvhRay* world) {
  if (g->motion_steps > 1u) {
    Affine o2w, w2o;
    motion_transform(g->motion, g->motion_steps, inst->instance_id, g->time, &o2w, &w2o);
    return bvh_ray(affine_point(&w2o, world->o), affine_vector(&w2o, world->d), world->tmin,
                   world->tmax);
  }
  return bvh_ray(xform_point(inst->world_to_object, world->o),
                 xform_vector(inst->world_to_object, world->d), world->tmin, world->tmax);
}

// Traverses the TLAS (leaves are instance records); at each instance, the instance's mesh BVH
// in object space.
PR_INLINE int tlas_traverse(const SceneGeom* g, BvhRay* r, Hit* hit, int any_hit) {
  if (g->instance_count == 0) return 0;
  u32 stack[PR_BVH_STACK_SIZE];
  float stack_t[PR_BVH_STACK_SIZE];
  int sp = 0;
  int found = 0;
  u32 ref = 0;
  for (;;) {
    if (!(ref & PR_BVH_LEAF_BIT)) {
      float entry[PR_BVH_WIDTH];
      const u32 mask = bvh_node_entries(g->tlas_nodes + ref, r, entry);
      if (bvh_push_children(g->tlas_nodes + ref, mask, entry, stack, stack_t, &sp, any_hit)) {
        ref = stack[--sp];
        continue;
      }
    } else {
      PR_GLOBAL const BvhInstance* inst = g->instances + (ref & ~PR_BVH_LEAF_BIT);
      BvhRay obj = instance_ray(g, inst, r);  // ("local" is an OpenCL keyword)
      PacketBlend blend = packet_blend_none();
      if (g->motion_steps > 1u && g->mesh_motion[PR_MESH_MOTION_WORDS * inst->mesh + 3u] > 1u) {
        PR_GLOBAL const u32* mm = g->mesh_motion + PR_MESH_MOTION_WORDS * inst->mesh;
        blend.steps = g->motion_tris + mm[2];
        blend.bounds = g->motion_bounds + (size_t)mm[5] * (6 * PR_BVH_WIDTH);
        blend.first = mm[0];
        blend.first_node = mm[4];
        blend.stride = mm[3];
        blend.k = motion_step(mm[3], g->time, &blend.a);
      }
      // Two copies of the traversal: the one without motion tests no blend at each node.
      const int in_mesh = blend.stride > 1u
                              ? bvh_traverse_blend(g->mesh_nodes, g->mesh_tris, inst->root_node,
                                                   &obj, hit, inst->instance_id, any_hit, &blend)
                              : bvh_traverse(g->mesh_nodes, g->mesh_tris, inst->root_node, &obj,
                                             hit, inst->instance_id, any_hit);
      if (in_mesh) {
        if (any_hit) return 1;
        found = 1;
        r->tmax = obj.tmax;
      }
    }
    if (!bvh_pop(stack, stack_t, &sp, r->tmax, &ref)) return found;
  }
}

PR_INLINE Hit hit_none(void) {
  Hit h;
  h.t = PR_INF_F;
  h.u = 0.0f;
  h.v = 0.0f;
  h.prim = PR_INVALID_INDEX;
  h.inst = PR_INVALID_INDEX;
  h.pad0 = 0u;
  h.pad1 = 0u;
  h.pad2 = 0u;
  return h;
}

PR_INLINE BvhRay bvh_ray_from(Ray ray) {
  return bvh_ray(make_float3(ray.ox, ray.oy, ray.oz), make_float3(ray.dx, ray.dy, ray.dz), ray.tmin,
                 ray.tmax);
}

// Closest hit on the SSG. *hit is always written (prim == PR_INVALID_INDEX: no hit).
PR_CALLABLE int intersect_static(const SceneGeom* g, Ray ray, Hit* hit) {
  BvhRay r = bvh_ray_from(ray);
  *hit = hit_none();
  return bvh_traverse(g->static_nodes, g->static_tris, 0u, &r, hit, PR_INVALID_INDEX, 0);
}

// Closest hit on the DSG (hit->inst is the instance id).
PR_CALLABLE int intersect_dynamic(const SceneGeom* g, Ray ray, Hit* hit) {
  BvhRay r = bvh_ray_from(ray);
  *hit = hit_none();
  return tlas_traverse(g, &r, hit, 0);
}

// Closest hit on the whole scene: the nearer of the SSG hit and the DSG hit.
PR_CALLABLE int intersect_scene(const SceneGeom* g, Ray ray, Hit* hit) {
  BvhRay r = bvh_ray_from(ray);
  *hit = hit_none();
  const int s = bvh_traverse(g->static_nodes, g->static_tris, 0u, &r, hit, PR_INVALID_INDEX, 0);
  const int d = tlas_traverse(g, &r, hit, 0);  // r.tmax is the SSG hit: only nearer ones count
  return s | d;
}

// Any hit in (tmin, tmax): for shadow rays and invalidation.
PR_CALLABLE int occluded_static(const SceneGeom* g, Ray ray) {
  BvhRay r = bvh_ray_from(ray);
  Hit unused;
  return bvh_traverse(g->static_nodes, g->static_tris, 0u, &r, &unused, PR_INVALID_INDEX, 1);
}

PR_CALLABLE int occluded_dynamic(const SceneGeom* g, Ray ray) {
  BvhRay r = bvh_ray_from(ray);
  Hit unused;
  return tlas_traverse(g, &r, &unused, 1);
}

PR_CALLABLE int occluded_scene(const SceneGeom* g, Ray ray) {
  // The DSG first: a few triangles, and the likelier blocker of a changed path. (The SSG first
  // measured no different on the atrium's shadow rays: +2%, within the noise.)
  return occluded_dynamic(g, ray) || occluded_static(g, ray);
}

// Moves p, a point on a surface with geometric normal ng (any length, pointing to the side the
// new ray leaves to), off the surface by a distance that scales with p's magnitude: a fixed
// number of ulps per coordinate, or a small absolute step near the origin where ulps vanish.
PR_INLINE float3 offset_ray_origin(float3 p, float3 ng) {
  const float origin_zone = 1.0f / 32.0f;  // below this, ulps are too small to step in
  const float abs_step = 1.0f / 65536.0f;
  const float ulp_step = 256.0f;
  const float3 n = normalize(ng);
  const int ix = (int)(ulp_step * n.x), iy = (int)(ulp_step * n.y), iz = (int)(ulp_step * n.z);
  // Adding to the bit pattern grows the magnitude whatever the sign, so negative coordinates
  // take the negated step (unsigned wrap-around is the two's complement sum).
  const float px = pr_as_float(pr_as_uint(p.x) + (u32)(p.x < 0.0f ? -ix : ix));
  const float py = pr_as_float(pr_as_uint(p.y) + (u32)(p.y < 0.0f ? -iy : iy));
  const float pz = pr_as_float(pr_as_uint(p.z) + (u32)(p.z < 0.0f ? -iz : iz));
  return make_float3(fabs(p.x) < origin_zone ? p.x + abs_step * n.x : px,
                     fabs(p.y) < origin_zone ? p.y + abs_step * n.y : py,
                     fabs(p.z) < origin_zone ? p.z + abs_step * n.z : pz);
}

PR_INLINE Ray make_ray(float3 o, float3 dir, float tmin, float tmax) {
  Ray r;
  r.ox = o.x;
  r.oy = o.y;
  r.oz = o.z;
  r.tmin = tmin;
  r.dx = dir.x;
  r.dy = dir.y;
  r.dz = dir.z;
  r.tmax = tmax;
  return r;
}

// A ray leaving surface point p (geometric normal ng, either orientation) in direction dir.
PR_INLINE Ray spawn_ray(float3 p, float3 ng, float3 dir, float tmax) {
  const float3 n = dot(ng, dir) < 0.0f ? -ng : ng;
  return make_ray(offset_ray_origin(p, n), dir, 0.0f, tmax);
}

// A shadow segment between two surface points, each offset off its own surface towards the
// other; the direction is the unnormalised difference, so the segment is t in (0, 1).
PR_INLINE Ray spawn_ray_to(float3 p, float3 ng, float3 q, float3 nq) {
  const float3 d = q - p;
  const float3 o = offset_ray_origin(p, dot(ng, d) < 0.0f ? -ng : ng);
  const float3 e = offset_ray_origin(q, dot(nq, d) > 0.0f ? -nq : nq);
  return make_ray(o, e - o, 0.0f, 1.0f);
}

PR_NAMESPACE_END

#ifdef PR_DEVICE_CODE
// A SceneGeom from a kernel's geometry parameters (shared/kernel_args.h).
PR_ARG_GATHER(SceneGeom, pr_scene_geom, PR_ARGS_SCENE_GEOM)
#define PR_SCENE_GEOM() pr_scene_geom(PR_ARG_VALUES(PR_ARGS_SCENE_GEOM))
#endif
