// Every struct that host and kernels share. Explicit padding, no float3 members, no bool, no
// size_t: the layout is the same on every compiler. Each struct is listed in shared/layout.h,
// which the layout test uses to compare the host's sizeof/offsetof with the device's.
#pragma once

#include "shared/common.h"

PR_NAMESPACE_BEGIN

// A ray segment [tmin, tmax] along origin + t * dir. 32 bytes.
typedef struct {
  float ox, oy, oz, tmin;
  float dx, dy, dz, tmax;
} Ray;

// The result of a closest-hit query. prim == PR_INVALID_INDEX: no hit. inst == PR_INVALID_INDEX:
// the hit is on static geometry (SSG), else the index of the dynamic instance (DSG). 32 bytes.
typedef struct {
  float t, u, v;
  u32 prim;
  u32 inst;
  u32 pad0, pad1, pad2;
} Hit;

#define PR_INVALID_INDEX 0xffffffffu

// One node of a flattened BVH, 32 bytes. Nodes are stored depth-first: an interior node's left
// child is the next node (self + 1) and `index` is its right child; a leaf has PR_BVH_LEAF_BIT
// set in `meta`, its triangle count in the low bits (0 for an empty BVH) and `index` is its
// first triangle in the BVH's reordered triangle array. Interior nodes keep the split axis in
// `meta` (informative only).
typedef struct {
  float lo_x, lo_y, lo_z;
  float hi_x, hi_y, hi_z;
  u32 index;
  u32 meta;
} BvhNode;

// A triangle laid out for Moller-Trumbore: v0 and the two edges from it, plus the triangle's id
// in the scene (what hits report). Three 16-byte rows so a device can load it as float4s. 48 bytes.
typedef struct {
  float v0x, v0y, v0z;
  u32 prim;
  float e1x, e1y, e1z;
  u32 pad0;
  float e2x, e2y, e2z;
  u32 pad1;
} BvhTriangle;

// One instance of a dynamic mesh in the current frame, in the top-level BVH's leaf order.
// Matrices are 3x4 row-major: row r is (m[4r], m[4r+1], m[4r+2] | translation m[4r+3]).
// root_node indexes the concatenated mesh node buffer (child and triangle indices in there are
// absolute too); instance_id is what hits report in Hit.inst. 112 bytes.
typedef struct {
  float world_to_object[12];
  float object_to_world[12];
  u32 root_node;
  u32 first_triangle;
  u32 mesh;
  u32 instance_id;
} BvhInstance;

#define PR_BVH_LEAF_BIT 0x80000000u

PR_NAMESPACE_END

PR_STATIC_ASSERT(sizeof(pr::dev::Ray) == 32, "Ray layout");
PR_STATIC_ASSERT(offsetof(pr::dev::Ray, tmin) == 12, "Ray layout");
PR_STATIC_ASSERT(offsetof(pr::dev::Ray, dx) == 16, "Ray layout");
PR_STATIC_ASSERT(offsetof(pr::dev::Ray, tmax) == 28, "Ray layout");
PR_STATIC_ASSERT(sizeof(pr::dev::Hit) == 32, "Hit layout");
PR_STATIC_ASSERT(offsetof(pr::dev::Hit, prim) == 12, "Hit layout");
PR_STATIC_ASSERT(offsetof(pr::dev::Hit, inst) == 16, "Hit layout");
PR_STATIC_ASSERT(sizeof(pr::dev::BvhNode) == 32, "BvhNode layout");
PR_STATIC_ASSERT(offsetof(pr::dev::BvhNode, index) == 24, "BvhNode layout");
PR_STATIC_ASSERT(offsetof(pr::dev::BvhNode, meta) == 28, "BvhNode layout");
PR_STATIC_ASSERT(sizeof(pr::dev::BvhTriangle) == 48, "BvhTriangle layout");
PR_STATIC_ASSERT(offsetof(pr::dev::BvhTriangle, prim) == 12, "BvhTriangle layout");
PR_STATIC_ASSERT(offsetof(pr::dev::BvhTriangle, e1x) == 16, "BvhTriangle layout");
PR_STATIC_ASSERT(offsetof(pr::dev::BvhTriangle, e2x) == 32, "BvhTriangle layout");
PR_STATIC_ASSERT(sizeof(pr::dev::BvhInstance) == 112, "BvhInstance layout");
PR_STATIC_ASSERT(offsetof(pr::dev::BvhInstance, object_to_world) == 48, "BvhInstance layout");
PR_STATIC_ASSERT(offsetof(pr::dev::BvhInstance, root_node) == 96, "BvhInstance layout");
PR_STATIC_ASSERT(offsetof(pr::dev::BvhInstance, instance_id) == 108, "BvhInstance layout");
