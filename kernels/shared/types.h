// Every struct that host and kernels share. Explicit padding, no float3 members, no bool, no
// size_t: the layout is the same on every compiler. Each struct is listed in shared/layout.h,
// which the layout test uses to compare the host's sizeof/offsetof with the device's.
#pragma once

#include "shared/common.h"
#include "shared/kernel_args.h"

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

// Statistics counters (rays traced and the like) are kept in PR_COUNTER_LANES copies, a lane of
// PR_COUNTER_ROW(n) u32 for n counters (whole 64-byte lines). A work-group adds to lane
// group id mod PR_COUNTER_LANES, so that compute units do not fight over one cache line once per
// work-item (3-6% of a CPU frame); the host adds the lanes. Counters that index a list stay in lane
// 0, which starts the buffer.
enum { PR_COUNTER_LANES = 16 };
#define PR_COUNTER_ROW(n) ((((n) + 15) / 16) * 16)

#ifdef PR_DEVICE_CODE
// This work-group's lane of a counter buffer whose lanes are `row` u32 long.
PR_INLINE __global u32* counter_lane(__global u32* counters, u32 row) {
  return counters + row * ((u32)get_group_id(0) % (u32)PR_COUNTER_LANES);
}
#endif

// BVH width: children per node. CPUs take 8 (one float8 slab test per node, AVX), GPUs 4
// (host/render/options.cpp: faster than 2 and 8 on an H200); 2 is the binary node holding both
// children's boxes, as Aila and Laine 2009 lay it out for SIMT. The host builds the layout the
// device's kernels were compiled for (-DPR_BVH_WIDTH=N); the host's CPU reference traverses
// the default.
#ifndef PR_BVH_WIDTH
#define PR_BVH_WIDTH 8
#endif

// One node of a flattened wide BVH: the boxes of its children structure-of-arrays, so that a
// ray tests all of them with one vector per slab. bounds holds lo_x[W], hi_x[W], lo_y[W],
// hi_y[W], lo_z[W], hi_z[W] (W = PR_BVH_WIDTH). child[i] is a node index, PR_BVH_LEAF_BIT | a
// triangle packet (an instance record in the top-level BVH), or PR_INVALID_INDEX for an unused
// slot, whose box is inverted (lo = +inf, hi = -inf) so that no ray enters it.
// 28 * W bytes: 224 at W = 8.
typedef struct {
  float bounds[6 * PR_BVH_WIDTH];
  u32 child[PR_BVH_WIDTH];
} BvhNode;

// A triangle laid out for Moller-Trumbore: v0 and the two edges from it, plus the triangle's id
// in the scene (what hits report). 48 bytes.
typedef struct {
  float v0x, v0y, v0z;
  u32 prim;
  float e1x, e1y, e1z;
  u32 pad0;
  float e2x, e2y, e2z;
  u32 pad1;
} BvhTriangle;

// A BVH leaf: up to PR_BVH_PACKET triangles structure-of-arrays, tested by one ray at once with
// float4s. Unused lanes have zero edges (never hit) and prim PR_INVALID_INDEX. 160 bytes.
#define PR_BVH_PACKET 4
typedef struct {
  float v0x[PR_BVH_PACKET], v0y[PR_BVH_PACKET], v0z[PR_BVH_PACKET];
  float e1x[PR_BVH_PACKET], e1y[PR_BVH_PACKET], e1z[PR_BVH_PACKET];
  float e2x[PR_BVH_PACKET], e2y[PR_BVH_PACKET], e2z[PR_BVH_PACKET];
  u32 prim[PR_BVH_PACKET];
} BvhTriPacket;

// One instance of a dynamic mesh in the current frame, in the top-level BVH's leaf order.
// Matrices are 3x4 row-major: row r is (m[4r], m[4r+1], m[4r+2] | translation m[4r+3]).
// root_node indexes the concatenated mesh node buffer (child and packet indices in there are
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
PR_STATIC_ASSERT(sizeof(pr::dev::BvhNode) == 28 * PR_BVH_WIDTH, "BvhNode layout");
PR_STATIC_ASSERT(offsetof(pr::dev::BvhNode, child) == 24 * PR_BVH_WIDTH, "BvhNode layout");
PR_STATIC_ASSERT(sizeof(pr::dev::BvhTriPacket) == 40 * PR_BVH_PACKET, "BvhTriPacket layout");
PR_STATIC_ASSERT(offsetof(pr::dev::BvhTriPacket, prim) == 36 * PR_BVH_PACKET,
                 "BvhTriPacket layout");
PR_STATIC_ASSERT(sizeof(pr::dev::BvhTriangle) == 48, "BvhTriangle layout");
PR_STATIC_ASSERT(offsetof(pr::dev::BvhTriangle, prim) == 12, "BvhTriangle layout");
PR_STATIC_ASSERT(offsetof(pr::dev::BvhTriangle, e1x) == 16, "BvhTriangle layout");
PR_STATIC_ASSERT(offsetof(pr::dev::BvhTriangle, e2x) == 32, "BvhTriangle layout");
PR_STATIC_ASSERT(sizeof(pr::dev::BvhInstance) == 112, "BvhInstance layout");
PR_STATIC_ASSERT(offsetof(pr::dev::BvhInstance, object_to_world) == 48, "BvhInstance layout");
PR_STATIC_ASSERT(offsetof(pr::dev::BvhInstance, root_node) == 96, "BvhInstance layout");
PR_STATIC_ASSERT(offsetof(pr::dev::BvhInstance, instance_id) == 108, "BvhInstance layout");
