// Per-sample state of the wavefront path tracer, in device buffers. Radiance is kept apart, in
// one float4 per sample, which the accumulate kernel shared by all modes adds to the film.
#pragma once

#include "shared/types.h"

PR_NAMESPACE_BEGIN

// 96 bytes.
typedef struct {
  Ray ray;
  float tp_r, tp_g, tp_b;
  float last_pdf;  // solid-angle pdf of the BSDF sample that made `ray`; 0 after delta/camera
  u32 depth;       // surface interactions so far
  u32 pixel;
  u32 alive;
  u32 rng_dim;                      // next random dimension of this sample
  u32 flags;                        // PR_PATH_*
  float prev_x, prev_y, prev_z;     // the vertex `ray` leaves and its shading normal (for the
  float prev_nx, prev_ny, prev_nz;  // emitter pdf of its hit)
  u32 pad;
} PathState;

#define PR_PATH_SPECULAR 1u  // the last bounce was delta (or the ray is the camera ray)

// A shadow ray with the contribution it carries if unoccluded. 48 bytes.
typedef struct {
  Ray ray;
  float c_r, c_g, c_b;
  u32 valid;
} ShadowRay;

PR_NAMESPACE_END

PR_STATIC_ASSERT(sizeof(pr::dev::PathState) == 96, "PathState layout");
PR_STATIC_ASSERT(offsetof(pr::dev::PathState, depth) == 48, "PathState layout");
PR_STATIC_ASSERT(offsetof(pr::dev::PathState, flags) == 64, "PathState layout");
PR_STATIC_ASSERT(sizeof(pr::dev::ShadowRay) == 48, "ShadowRay layout");
