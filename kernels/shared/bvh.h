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
// Traversal keeps a fixed stack of PR_BVH_STACK_SIZE entries; it pushes at most one entry per
// level, and the host builder guarantees every BVH's depth is at most PR_BVH_STACK_SIZE.
#pragma once

#include "shared/math.h"
#include "shared/types.h"

#ifdef PR_DEVICE_CODE
// Same rounding as the host's CPU reference: no fused multiply-adds behind our back.
#pragma OPENCL FP_CONTRACT OFF
#endif

#define PR_BVH_STACK_SIZE 64

// Slab distances are scaled by this before the overlap test so rounding never culls a box
// that holds a hit (1 + 2 * gamma(3) in pbrt's terms, rounded up).
#define PR_BVH_FAR_SCALE 1.00000036f

PR_NAMESPACE_BEGIN

// Device buffers of both structures. Build it inside a kernel from the kernel's arguments
// (OpenCL C 1.2 allows pointers to __global in private structs, not in kernel arguments):
// see PR_SCENE_GEOM_PARAMS / pr_scene_geom below.
typedef struct {
  PR_GLOBAL const BvhNode* static_nodes;     // root at 0; an empty SSG is one empty leaf
  PR_GLOBAL const BvhTriangle* static_tris;
  PR_GLOBAL const BvhNode* tlas_nodes;       // root at 0; read only when instance_count > 0
  PR_GLOBAL const BvhInstance* instances;    // in TLAS leaf order
  PR_GLOBAL const BvhNode* mesh_nodes;       // all meshes' BVHs, absolute indices
  PR_GLOBAL const BvhTriangle* mesh_tris;
  u32 instance_count;
} SceneGeom;

// A ray prepared for traversal (private, never in a buffer).
typedef struct {
  float3 o, d, inv_d;
  float tmin, tmax;
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
  return r;
}

// min/max by comparison: slab distances are never NaN (finite boxes, bvh_safe_inverse), so
// fmin/fmax's NaN handling is dead weight in the hottest function.
PR_INLINE float bvh_min(float a, float b) {
  return a < b ? a : b;
}
PR_INLINE float bvh_max(float a, float b) {
  return a > b ? a : b;
}

// Entry distance of the ray into the node's box, or PR_INF_F when it misses it within
// [tmin, tmax].
PR_INLINE float bvh_box_entry(PR_GLOBAL const BvhNode* n, const BvhRay* r) {
  const float x0 = (n->lo_x - r->o.x) * r->inv_d.x, x1 = (n->hi_x - r->o.x) * r->inv_d.x;
  const float y0 = (n->lo_y - r->o.y) * r->inv_d.y, y1 = (n->hi_y - r->o.y) * r->inv_d.y;
  const float z0 = (n->lo_z - r->o.z) * r->inv_d.z, z1 = (n->hi_z - r->o.z) * r->inv_d.z;
  const float tnear = bvh_max(bvh_max(bvh_min(x0, x1), bvh_min(y0, y1)),
                              bvh_max(bvh_min(z0, z1), r->tmin));
  const float tfar =
      bvh_min(bvh_min(bvh_max(x0, x1), bvh_max(y0, y1)), bvh_max(z0, z1)) * PR_BVH_FAR_SCALE;
  return (tnear <= tfar && tnear <= r->tmax) ? tnear : PR_INF_F;
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

// Traverses one BVH from `root`. Closest hit (any_hit == 0): shrinks r->tmax to each nearer hit
// and fills *hit with inst = `inst`. Any hit: returns at the first one, *hit untouched.
PR_INLINE int bvh_traverse(PR_GLOBAL const BvhNode* nodes, PR_GLOBAL const BvhTriangle* tris,
                           u32 root, BvhRay* r, Hit* hit, u32 inst, int any_hit) {
  u32 stack[PR_BVH_STACK_SIZE];
  float stack_t[PR_BVH_STACK_SIZE];
  int sp = 0;
  int found = 0;
  u32 node = root;
  if (bvh_box_entry(nodes + root, r) == PR_INF_F) return 0;
  for (;;) {
    PR_GLOBAL const BvhNode* n = nodes + node;
    if (n->meta & PR_BVH_LEAF_BIT) {
      const u32 end = n->index + (n->meta & ~PR_BVH_LEAF_BIT);
      for (u32 i = n->index; i < end; ++i) {
        float t, u, v;
        if (intersect_triangle(tris + i, r->o, r->d, r->tmin, r->tmax, &t, &u, &v)) {
          if (any_hit) return 1;
          found = 1;
          r->tmax = t;
          hit->t = t;
          hit->u = u;
          hit->v = v;
          hit->prim = tris[i].prim;
          hit->inst = inst;
        }
      }
    } else {
      const u32 left = node + 1, right = n->index;
      const float tl = bvh_box_entry(nodes + left, r);
      const float tr = bvh_box_entry(nodes + right, r);
      if (tl != PR_INF_F && tr != PR_INF_F) {
        // Nearer child first; the other waits on the stack with its entry distance.
        const int right_first = tr < tl;
        stack_t[sp] = right_first ? tl : tr;
        stack[sp++] = right_first ? left : right;
        node = right_first ? right : left;
        continue;
      }
      if (tl != PR_INF_F) {
        node = left;
        continue;
      }
      if (tr != PR_INF_F) {
        node = right;
        continue;
      }
    }
    // A waiting node that starts beyond the nearest hit found since it was pushed is skipped.
    do {
      if (sp == 0) return found;
      --sp;
    } while (stack_t[sp] > r->tmax);
    node = stack[sp];
  }
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

// The ray in the instance's object space; same t, direction not renormalised.
PR_INLINE BvhRay instance_ray(PR_GLOBAL const BvhInstance* inst, const BvhRay* world) {
  return bvh_ray(xform_point(inst->world_to_object, world->o),
                 xform_vector(inst->world_to_object, world->d), world->tmin, world->tmax);
}

// Traverses the TLAS; at each instance, the instance's mesh BVH in object space.
PR_INLINE int tlas_traverse(const SceneGeom* g, BvhRay* r, Hit* hit, int any_hit) {
  if (g->instance_count == 0) return 0;
  u32 stack[PR_BVH_STACK_SIZE];
  float stack_t[PR_BVH_STACK_SIZE];
  int sp = 0;
  int found = 0;
  u32 node = 0;
  PR_GLOBAL const BvhNode* nodes = g->tlas_nodes;
  if (bvh_box_entry(nodes, r) == PR_INF_F) return 0;
  for (;;) {
    PR_GLOBAL const BvhNode* n = nodes + node;
    if (n->meta & PR_BVH_LEAF_BIT) {
      const u32 end = n->index + (n->meta & ~PR_BVH_LEAF_BIT);
      for (u32 i = n->index; i < end; ++i) {
        PR_GLOBAL const BvhInstance* inst = g->instances + i;
        BvhRay obj = instance_ray(inst, r);  // ("local" is an OpenCL keyword)
        if (bvh_traverse(g->mesh_nodes, g->mesh_tris, inst->root_node, &obj, hit,
                         inst->instance_id, any_hit)) {
          if (any_hit) return 1;
          found = 1;
          r->tmax = obj.tmax;
        }
      }
    } else {
      const u32 left = node + 1, right = n->index;
      const float tl = bvh_box_entry(nodes + left, r);
      const float tr = bvh_box_entry(nodes + right, r);
      if (tl != PR_INF_F && tr != PR_INF_F) {
        const int right_first = tr < tl;
        stack_t[sp] = right_first ? tl : tr;
        stack[sp++] = right_first ? left : right;
        node = right_first ? right : left;
        continue;
      }
      if (tl != PR_INF_F) {
        node = left;
        continue;
      }
      if (tr != PR_INF_F) {
        node = right;
        continue;
      }
    }
    // A waiting node that starts beyond the nearest hit found since it was pushed is skipped.
    do {
      if (sp == 0) return found;
      --sp;
    } while (stack_t[sp] > r->tmax);
    node = stack[sp];
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
  return bvh_ray(make_float3(ray.ox, ray.oy, ray.oz), make_float3(ray.dx, ray.dy, ray.dz),
                 ray.tmin, ray.tmax);
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
  // The DSG first: a few triangles, and the likelier blocker of a changed path.
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
// Kernel parameters that carry a SceneGeom, and the struct built from them in the kernel body.
// The host's DeviceAccel::setKernelArgs sets them in this order.
#define PR_SCENE_GEOM_PARAMS                                                                    \
  __global const BvhNode *pr_static_nodes, __global const BvhTriangle *pr_static_tris,          \
      __global const BvhNode *pr_tlas_nodes, __global const BvhInstance *pr_instances,          \
      __global const BvhNode *pr_mesh_nodes, __global const BvhTriangle *pr_mesh_tris,          \
      uint pr_instance_count
PR_INLINE SceneGeom pr_scene_geom(__global const BvhNode* sn, __global const BvhTriangle* st,
                                  __global const BvhNode* tn, __global const BvhInstance* in,
                                  __global const BvhNode* mn, __global const BvhTriangle* mt,
                                  uint count) {
  SceneGeom g;
  g.static_nodes = sn;
  g.static_tris = st;
  g.tlas_nodes = tn;
  g.instances = in;
  g.mesh_nodes = mn;
  g.mesh_tris = mt;
  g.instance_count = count;
  return g;
}
#define PR_SCENE_GEOM()                                                                     \
  pr_scene_geom(pr_static_nodes, pr_static_tris, pr_tlas_nodes, pr_instances, pr_mesh_nodes, \
                pr_mesh_tris, pr_instance_count)
#endif
