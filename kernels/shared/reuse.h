// Shared by the path-reuse kernels: their parameters, the counters they keep, and the one
// function that builds a light path's segment rays, used both when tracing a path and when
// checking it again, so that both see the same ray bit for bit.
#pragma once

#include "shared/arena.h"
#include "shared/transport.h"
#include "shared/path_state.h"

PR_NAMESPACE_BEGIN

// 80 bytes, passed by value to every reuse kernel.
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
  float cx, cy, cz;     // scene centre
  u32 resample;         // RIS-chosen connections per eye vertex, at most PR_MAX_CONNECTIONS;
                        // 0 = every candidate
  u32 eye_paths;        // 1: connections weighted against the path tracer's (--eye-paths)
  float eye_count;      // the samples an eye path counts as in those weights (1; --resample-mis)
  float lt_scale;       // strategy T (--light-tracing): N_L A / (spp C W H); 0 = off
  u32 pad2;
} ReuseParams;

// Most resampled connections per eye vertex (ReuseParams.resample; reservoir slots in connect).
#define PR_MAX_CONNECTIONS 4

// What connect leaves for connect_shadow (docs/design.md section 5, "Connections (strategy L)"):
// per pixel sample, in the order connect found them, the terms of its estimate,
// each a ShadowRay whose value is added where its ray (if any) is unoccluded. The estimate is L,
// summed as connect used to sum it: op PR_REC_ADD adds the value to L, PR_REC_GROUP to a partial
// sum g, and PR_REC_CLOSE adds g to L and starts g again at 0, so that the floating-point sums,
// and the frames, are those of one kernel tracing as it goes. The ray is read only where op has
// PR_REC_RAY.
#define PR_REC_ADD 0u
#define PR_REC_GROUP 1u
#define PR_REC_CLOSE 2u
#define PR_REC_SUM_MASK 3u
#define PR_REC_RAY 4u      // a shadow ray to trace
#define PR_REC_COUNTED 8u  // counted in connections_unoccluded where unoccluded
// Under a shutter: the ray is traced at the time in the op's top 24 bits (light_path_time_op), a
// light path's own, not at the sample's.
#define PR_REC_TIMED 16u
#define PR_REC_TIME_SHIFT 8u

// L and g after one more term of value v (where unoccluded).
PR_INLINE void connect_record_apply(float3* L, float3* g, float3 v, u32 op) {
  const u32 sum = op & PR_REC_SUM_MASK;
  if (sum == PR_REC_ADD) {
    *L += v;
  } else if (sum == PR_REC_GROUP) {
    *g += v;
  } else {
    *L += *g;
    *g = make_float3(0.0f, 0.0f, 0.0f);
  }
}

// Counters the kernels add to (one atomic add per work-item and counter, in its work-group's
// lane), and where `--stats` reports each: X(NAME, group, "key") adds counter PR_C_NAME, reported
// as rays.key or counters.key (group rays / counters), or not at all (internal).
#define PR_REUSE_COUNTERS(X)                                                           \
  X(LIST, internal, "")                 /* invalid slots listed by invalidate */       \
  X(INVALID_RAYS, rays, "invalidation") /* DSG rays of invalidation */                 \
  X(LIGHT_RAYS, rays, "light")                                                         \
  X(CAMERA_RAYS, rays, "camera")                                                       \
  X(SPLAT_RAYS, rays, "splat")   /* strategy T: light vertices to the camera */        \
  X(SHADOW_RAYS, rays, "shadow") /* next-event estimation */                           \
  X(CONNECT_RAYS, rays, "connection")                                                  \
  X(BOUNCE_RAYS, rays, "bounce")               /* eye rays after the first hit */      \
  X(SSG_VERTICES, paths, "light_vertices_ssg") /* light vertices k >= 1 */             \
  X(DSG_VERTICES, paths, "light_vertices_dsg")                                         \
  X(CLAMPED, counters, "connections_clamped")      /* geometry term clamped */         \
  X(MIS_RAYS, counters, "connections_mis")         /* connection rays of strategy E */ \
  X(CANDIDATES, counters, "connection_candidates") /* each a ray without resampling */ \
  X(CONNECTED, counters, "connections_unoccluded")                                     \
  X(HISTORY_KEPT, counters, "history_kept")       /* carried vertices chosen again */  \
  X(HISTORY_DROPPED, counters, "history_dropped") /* carried, their slot re-traced */  \
  X(RECORD_OVERFLOW, internal, "")                /* connect records past the cap: 0 */

#define PR_C_ENUM(name, group, key) PR_C_##name,
enum { PR_REUSE_COUNTERS(PR_C_ENUM) PR_C_COUNT };
#undef PR_C_ENUM
enum { PR_C_ROW = PR_COUNTER_ROW(PR_C_COUNT) };  // one lane of `counters` (shared/types.h)

// Where the segment leaving a stored vertex (at p on triangle prim of instance inst, at
// barycentrics (b1, b2), with its encoded normals) in direction dir starts: the exact point for
// punctual lights (prim == PR_INVALID_INDEX), else as surface_ray leaves a surface (ray_exit),
// with the decoded normals. A point, not a Ray: Oclgrind cannot run the noalias scope that
// inlining a struct-returning function with these loads leaves behind.
PR_INLINE float3 light_segment_origin(const ShadingData* sd, float3 p, u32 ng_oct, u32 ns_oct,
                                      u32 prim, u32 inst, float b1, float b2, float3 dir) {
  if (prim == PR_INVALID_INDEX) return p;
  float3 side;
  const float3 o =
      ray_exit(sd, p, oct_decode(ng_oct), oct_decode(ns_oct), prim, inst, b1, b2, dir, &side);
  return offset_ray_origin(o, side);
}

// The first non-delta eye vertex of a pixel sample, as eye_hit (or, with --eye-paths, the path
// tracer's pt_shade) finds it: hit h of ray `hit`, towards wo, with throughput tp, at `depth`.
PR_INLINE void eye_vertex_set(EyeVertex* e, const SurfaceHit* h, const Hit* hit, float3 wo,
                              float3 tp, u32 depth) {
  e->px = h->p.x;
  e->py = h->p.y;
  e->pz = h->p.z;
  e->ng_oct = oct_encode(h->ng);
  e->ns_oct = oct_encode(h->ns);
  e->wx = wo.x;
  e->wy = wo.y;
  e->wz = wo.z;
  e->tp_r = tp.x;
  e->tp_g = tp.y;
  e->tp_b = tp.z;
  e->depth = depth;
  e->prim = hit->prim;
  e->inst = hit->inst;
  e->b1 = hit->u;
  e->b2 = hit->v;
}

PR_INLINE float3 vertex_pos(PR_GLOBAL const LightVertex* v) {
  return make_float3(v->px, v->py, v->pz);
}
PR_INLINE float3 vertex_dir(PR_GLOBAL const LightVertex* v) {
  return make_float3(v->wx, v->wy, v->wz);
}

// Whether segment k >= 1 of a stored light path (z_{k-1} to z_k; on a light of type light_type)
// meets nothing that moves while the shutter is open (sweep_clear). The first, from a light at
// infinity, is the ray from z_1 towards it, as the eye path sees it.
PR_INLINE int light_segment_still(const SceneData* s, u32 light_type,
                                  PR_GLOBAL const LightVertex* v, u32 k) {
  const float3 b = vertex_pos(v + k);
  if (k == 1u && light_at_infinity(light_type))
    return sweep_clear(s, b, -vertex_dir(v + 1), PR_INF_F);
  const float3 a = vertex_pos(v + k - 1u);
  return sweep_clear(s, a, b - a, 1.0f);
}

// Whether z_0 .. z_k of the path on light `light` are the same at every time of the shutter
// interval: none of its segments meets what moves (1 without a shutter).
PR_INLINE int light_prefix_still(const SceneData* s, u32 light, PR_GLOBAL const LightVertex* v,
                                 u32 k) {
  if (s->lights.sweep_count == 0u) return 1;
  const u32 type = s->lights.lights[light].type;
  for (u32 j = 1u; j <= k; ++j)
    if (!light_segment_still(s, type, v, j)) return 0;
  return 1;
}

// Whether the whole stored path is the same at every time of the shutter interval: its segments
// and its escaping ray meet nothing that moves (1 without a shutter).
PR_INLINE int light_path_still(const SceneData* s, const PathHeader* h,
                               PR_GLOBAL const LightVertex* v) {
  if (s->lights.sweep_count == 0u || h->light == PR_INVALID_INDEX || h->vertex_count == 0u)
    return 1;
  const u32 last = h->vertex_count - 1u;
  if (!light_prefix_still(s, h->light, v, last)) return 0;
  return h->end != PR_END_ESCAPED ||
         sweep_clear(s, vertex_pos(v + last), make_float3(h->escape_x, h->escape_y, h->escape_z),
                     PR_INF_F);
}

// A slot's time in the shutter interval this frame, uniform as the eye paths' are: where strategy
// T joins its path to the camera, and where light_trace traces a path that is not still.
PR_INLINE float light_path_time(const ReuseParams* rp, uint slot) {
  Rng tr = rng_make(rp->seed, PR_RNG_SPLAT, rp->frame, slot, 0u);
  return rng_next(&tr);
}

// The same time as a record's op bits (PR_REC_TIMED), and back: a draw is a multiple of 2^-24
// below 1 (pr_u32_to_unit), so both ways are exact.
PR_INLINE u32 light_path_time_op(const ReuseParams* rp, uint slot) {
  return PR_REC_TIMED | ((u32)(light_path_time(rp, slot) * 16777216.0f) << PR_REC_TIME_SHIFT);
}
PR_INLINE float record_time(u32 op) {
  return (float)(op >> PR_REC_TIME_SHIFT) * (1.0f / 16777216.0f);
}

// Veach's correction for shading normals on light paths (importance transport), for light that
// came from direction wo and leaves along wi: |wo.ns| |wi.ng| / (|wo.ng| |wi.ns|).
PR_INLINE float shading_normal_correction(float3 wo, float3 wi, float3 ns, float3 ng) {
  const float den = fabs(dot(wo, ng)) * fabs(dot(wi, ns));
  return den > 0.0f ? fabs(dot(wo, ns)) * fabs(dot(wi, ng)) / den : 0.0f;
}

// A stored light vertex k >= 1 rebuilt as a shaded surface.
typedef struct {
  SurfaceHit h;
  ShadingFrame f;
  float3 wprev;   // towards the previous light vertex
  float3 wprevl;  // the same in the shading frame
  int delta;
} LightPoint;

PR_INLINE LightPoint light_point(const SceneData* s, PR_GLOBAL const LightVertex* v) {
  LightPoint y;
  y.h = surface_interp(&s->sd, v->prim, v->inst, v->b1, v->b2, 0);  // ns as stored
  y.h.p = vertex_pos(v);
  y.h.ng = oct_decode(v->ng_oct);
  y.h.ns = oct_decode(v->ns_oct);
  y.wprev = -vertex_dir(v);
  y.f = shading_frame(s, &y.h, y.wprev);
  y.wprevl = to_local(y.wprev, y.f.t, y.f.b, y.f.n);
  y.delta = bsdf_is_delta(&y.f.bsdf);
  return y;
}

// The light side of a connection reached along dir (unit, from the eye side): its BSDF towards
// -dir with the pdf of leaving along it (and that of arriving from it, pdf_rev), |cos| at its
// shading normal and the shading-normal correction of light paths. 0 where it faces away from
// the eye side.
PR_INLINE int light_point_eval(const SceneData* s, const LightPoint* y, float3 dir, float3* f,
                               float* pdf, float* pdf_rev, float* cos_t, float* corr) {
  if (!surface_side_ok(s, &y->h, &y->f, y->wprev, -dir)) return 0;
  // The light path's BSDF: the view is towards the eye side (the adjoint of wprev's).
  *f = bsdf_eval_mode(&y->f.bsdf, y->wprevl, to_local(-dir, y->f.t, y->f.b, y->f.n), PR_IMPORTANCE,
                      pdf, pdf_rev);
  *cos_t = fabs(dot(y->f.n, dir));
  *corr = shading_normal_correction(y->wprev, -dir, y->f.n, y->f.ng);
  return 1;
}

PR_NAMESPACE_END

PR_STATIC_ASSERT(sizeof(pr::dev::ReuseParams) == 80, "ReuseParams layout");
PR_STATIC_ASSERT(offsetof(pr::dev::ReuseParams, clamp) == 32, "ReuseParams layout");
