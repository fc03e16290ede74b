// Counter-based random numbers: every value is a pure function of its key, never of thread
// order, so any sample can be replayed. Camera samples are keyed by (seed, frame, pixel,
// sample); light paths by (seed, slot, generation) with frame fixed to a constant, so that
// re-tracing a slot with the same generation reproduces it exactly (DESIGN.md section 4).
#pragma once

#include "shared/common.h"

PR_NAMESPACE_BEGIN

// The state is only a key and a dimension counter; it lives in registers, never in buffers.
typedef struct {
  u32 k0, k1, k2;
  u32 dim;
} Rng;

// A 4-in, 4-out integer permutation (the "pcg4d" hash of Jarzynski and Olano, JCGT 2020).
PR_INLINE void pr_pcg4d(u32* x, u32* y, u32* z, u32* w) {
  *x = *x * 1664525u + 1013904223u;
  *y = *y * 1664525u + 1013904223u;
  *z = *z * 1664525u + 1013904223u;
  *w = *w * 1664525u + 1013904223u;
  *x += *y * *w;
  *y += *z * *x;
  *z += *x * *y;
  *w += *y * *z;
  *x ^= *x >> 16;
  *y ^= *y >> 16;
  *z ^= *z >> 16;
  *w ^= *w >> 16;
  *x += *y * *w;
  *y += *z * *x;
  *z += *x * *y;
  *w += *y * *z;
}

// A 32-bit avalanche hash (lowbias32), used to fold extra key words into one.
PR_INLINE u32 pr_hash_u32(u32 x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}

// Stream kinds, folded into the key so camera and light streams never coincide.
#define PR_RNG_CAMERA 0x43414d31u
#define PR_RNG_LIGHT 0x4c495431u
#define PR_RNG_TEST 0x54455354u

PR_INLINE Rng rng_make(u32 seed, u32 kind, u32 frame, u32 stream, u32 index) {
  Rng r;
  r.k0 = pr_hash_u32(seed ^ pr_hash_u32(kind + pr_hash_u32(frame)));
  r.k1 = stream;
  r.k2 = index;
  r.dim = 0u;
  return r;
}

// The value of dimension `dim` of the key, without advancing anything.
PR_INLINE u32 rng_u32_at(const Rng* r, u32 dim) {
  u32 x = r->k0, y = r->k1, z = r->k2, w = dim;
  pr_pcg4d(&x, &y, &z, &w);
  return x ^ w;
}

PR_INLINE u32 rng_next_u32(Rng* r) { return rng_u32_at(r, r->dim++); }

// A float in [0, 1): the top 24 bits, so 1.0 is never returned.
PR_INLINE float rng_next(Rng* r) { return (float)(rng_next_u32(r) >> 8) * (1.0f / 16777216.0f); }

PR_NAMESPACE_END
