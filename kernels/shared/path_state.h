// Per-sample state of the wavefront path tracer, in device buffers. Radiance is kept apart, in
// one float4 per sample, which the accumulate kernel shared by all modes adds to the film.
#pragma once

#include "shared/types.h"

PR_NAMESPACE_BEGIN

// The path tracer's ray counters (its `rays` buffer) and their --stats names.
#define PR_PT_COUNTERS(X) \
  X(CAMERA, "camera")     \
  X(BOUNCE, "bounce")     \
  X(SHADOW, "shadow")
#define PR_PT_ENUM(name, key) PR_PT_##name,
enum { PR_PT_COUNTERS(PR_PT_ENUM) PR_PT_COUNT };
#undef PR_PT_ENUM

// The sizes of the queues pt_shade appends to (its queue_sizes buffer).
enum { PR_QUEUE_LIVE, PR_QUEUE_SHADOW, PR_QUEUE_COUNT };

// 112 bytes.
typedef struct {
  Ray ray;
  float tp_r, tp_g, tp_b;
  float last_pdf;  // solid-angle pdf of the BSDF sample that made `ray`; 0 after delta/camera
  u32 depth;       // surface interactions so far
  u32 pixel;
  u32 alive;                        // 0: ended at the last bounce (in no queue since)
  u32 rng_dim;                      // next random dimension of this sample
  u32 flags;                        // PR_PATH_*
  float prev_x, prev_y, prev_z;     // the vertex `ray` leaves and its shading normal (for the
  float prev_nx, prev_ny, prev_nz;  // emitter pdf of its hit)
  // --eye-paths (shared/eye_paths.h), on the vertices x_2.. after the first non-delta one:
  u32 x1_depth;     // depth of the first non-delta vertex x_1; 0: not met yet
  float eye_ratio;  // prod of light-tracing densities of x_2..x_{t-1} / eye densities of x_2..x_t
  float seg_cos;    // |cos| of `ray` with the geometric normal of the vertex it leaves
  u32 eye_flags;    // PR_EYE_*
  u32 pad;
} PathState;

#define PR_PATH_SPECULAR 1u  // the last bounce was delta (or the ray is the camera ray)
#define PR_EYE_JOINABLE 1u   // x_2 is non-delta: stored light paths can make this path's ends

// A shadow ray with the contribution it carries if unoccluded: the path tracer's next-event
// estimation (traced where the path is in the bounce's shadow queue) and connect's terms for
// connect_shadow (shared/reuse.h). 48 bytes.
typedef struct {
  Ray ray;
  float c_r, c_g, c_b;
  u32 op;  // connect's terms: how they sum, PR_REC_* (shared/reuse.h); unused by the path tracer
} ShadowRay;

PR_NAMESPACE_END

PR_STATIC_ASSERT(sizeof(pr::dev::PathState) == 112, "PathState layout");
PR_STATIC_ASSERT(offsetof(pr::dev::PathState, depth) == 48, "PathState layout");
PR_STATIC_ASSERT(offsetof(pr::dev::PathState, flags) == 64, "PathState layout");
PR_STATIC_ASSERT(sizeof(pr::dev::ShadowRay) == 48, "ShadowRay layout");
