// Shared by the path-reuse kernels: their parameters, the counters they keep, and the one
// function that builds a light path's segment rays, used both when tracing a path and when
// checking it again, so that both see the same ray bit for bit.
#pragma once

#include "shared/arena.h"
#include "shared/integrator.h"

PR_NAMESPACE_BEGIN

// 64 bytes, passed by value to every reuse kernel.
typedef struct {
  u32 seed;
  u32 slots;            // N_L
  u32 stride;           // vertices per slot: max_depth - 1 (vertex 0 on the light)
  u32 max_depth;        // longest path, in surface vertices (the emitter's included)
  u32 paths_per_pixel;  // C
  u32 spp;
  u32 pixel_count;
  u32 frame;
  float clamp;  // upper bound on the connection geometry term; 0 = off
  float trace_total;
  float scene_radius;
  float mis_threshold;  // connection MIS: strategy E runs where p_E / p_L >= this; 0 = off
  float cx, cy, cz;  // scene centre
  u32 resample;      // connections per eye vertex chosen by RIS (1-4); 0 = every candidate
} ReuseParams;

// Counters the kernels add to (one atomic add per work-item and counter).
#define PR_C_LIST 0          // invalid slots listed by invalidate
#define PR_C_INVALID_RAYS 1  // DSG rays of invalidation
#define PR_C_LIGHT_RAYS 2
#define PR_C_CAMERA_RAYS 3
#define PR_C_SHADOW_RAYS 4   // next-event estimation
#define PR_C_CONNECT_RAYS 5
#define PR_C_BOUNCE_RAYS 6   // eye rays after the first hit (delta chains, extensions)
#define PR_C_SSG_VERTICES 7  // light vertices k >= 1 on static geometry
#define PR_C_DSG_VERTICES 8
#define PR_C_CLAMPED 9       // connections whose geometry term was clamped
#define PR_C_MIS_RAYS 10     // connection rays of strategy E (a subset of PR_C_CONNECT_RAYS)
#define PR_C_CANDIDATES 11   // connections evaluated (each would cost a ray without resampling)
#define PR_C_CONNECTED 12    // connection rays found unoccluded
#define PR_C_COUNT 13

// The ray of the segment leaving a stored vertex in direction dir: from the exact point for
// punctual lights (prim == PR_INVALID_INDEX), else offset off the surface along the decoded
// geometric normal.
PR_INLINE Ray light_segment_ray(float3 p, u32 ng_oct, u32 prim, float3 dir) {
  if (prim == PR_INVALID_INDEX) return make_ray(p, dir, 0.0f, PR_INF_F);
  return spawn_ray(p, oct_decode(ng_oct), dir, PR_INF_F);
}

PR_INLINE float3 vertex_pos(PR_GLOBAL const LightVertex* v) { return make_float3(v->px, v->py, v->pz); }
PR_INLINE float3 vertex_dir(PR_GLOBAL const LightVertex* v) { return make_float3(v->wx, v->wy, v->wz); }

// Veach's correction for shading normals on light paths (importance transport), for light that
// came from direction wo and leaves along wi: |wo.ns| |wi.ng| / (|wo.ng| |wi.ns|).
PR_INLINE float shading_normal_correction(float3 wo, float3 wi, float3 ns, float3 ng) {
  const float den = fabs(dot(wo, ng)) * fabs(dot(wi, ns));
  return den > 0.0f ? fabs(dot(wo, ns)) * fabs(dot(wi, ng)) / den : 0.0f;
}

PR_NAMESPACE_END

PR_STATIC_ASSERT(sizeof(pr::dev::ReuseParams) == 64, "ReuseParams layout");
PR_STATIC_ASSERT(offsetof(pr::dev::ReuseParams, clamp) == 32, "ReuseParams layout");
