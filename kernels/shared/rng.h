// Counter-based random numbers: every value is a pure function of its key, never of thread
// order, so any sample can be replayed. Camera samples are keyed by (seed, frame, pixel,
// sample); light paths by (seed, slot, generation) with frame fixed to a constant, so that
// re-tracing a slot with the same generation reproduces it exactly (docs/design.md section 4).
#pragma once

#include "shared/common.h"
#include "shared/math.h"

PR_NAMESPACE_BEGIN

// The state is only a key, a dimension counter and whether it draws low-discrepancy samples;
// it lives in registers, never in buffers.
typedef struct {
  u32 k0, k1, k2;
  u32 dim;
  u32 sobol;
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
#define PR_RNG_CONNECT 0x434f4e31u   // camera samples' draws in `connect`, apart from eye_hit's
#define PR_RNG_RESAMPLE 0x52495331u  // `connect`'s reservoir decisions, apart from its path draws
#define PR_RNG_PATH_RESAMPLE 0x50525331u  // --resample's reservoir decisions, apart from the paths'
#define PR_RNG_SPLAT 0x53504c31u  // camera_splat's time in the shutter interval, per light path
#define PR_RNG_TEST 0x54455354u
#define PR_RNG_TEST_SOBOL 0x54455353u

// Camera streams are keyed by (pixel, sample index): their first PR_SOBOL_DIMS dimensions are
// Owen-scrambled Sobol points over the frame's samples of the pixel, hashed numbers beyond
// (deep bounces gain little from stratification). Other streams draw hashed numbers.
#define PR_SOBOL_DIMS 64u

PR_INLINE Rng rng_make(u32 seed, u32 kind, u32 frame, u32 stream, u32 index) {
  Rng r;
  r.k0 = pr_hash_u32(seed ^ pr_hash_u32(kind + pr_hash_u32(frame)));
  r.k1 = stream;
  r.k2 = index;
  r.dim = 0u;
  r.sobol = kind == PR_RNG_CAMERA || kind == PR_RNG_CONNECT || kind == PR_RNG_TEST_SOBOL;
  return r;
}

// The value of dimension `dim` of the key, without advancing anything.
PR_INLINE u32 rng_u32_at(const Rng* r, u32 dim) {
  u32 x = r->k0, y = r->k1, z = r->k2, w = dim;
  pr_pcg4d(&x, &y, &z, &w);
  return x ^ w;
}

#if defined(PR_DEVICE_CODE) && defined(PR_BITREVERSE_TABLE)
// Oclgrind 21.10 cannot run llvm.bitreverse, which LLVM makes of the shifts below (and which is
// one instruction on GPUs): tools/ci/oclgrind-check.sh builds with -DPR_BITREVERSE_TABLE.
#define PR_R2(n) n, n + 2 * 64, n + 1 * 64, n + 3 * 64
#define PR_R4(n) PR_R2(n), PR_R2(n + 2 * 16), PR_R2(n + 1 * 16), PR_R2(n + 3 * 16)
#define PR_R6(n) PR_R4(n), PR_R4(n + 2 * 4), PR_R4(n + 1 * 4), PR_R4(n + 3 * 4)
__constant uchar pr_reversed_byte[256] = {PR_R6(0), PR_R6(2), PR_R6(1), PR_R6(3)};
PR_INLINE u32 pr_reverse_bits(u32 x) {
  return ((u32)pr_reversed_byte[x & 255u] << 24) | ((u32)pr_reversed_byte[(x >> 8) & 255u] << 16) |
         ((u32)pr_reversed_byte[(x >> 16) & 255u] << 8) | (u32)pr_reversed_byte[x >> 24];
}
#else
PR_INLINE u32 pr_reverse_bits(u32 x) {
  x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
  x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
  x = ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
  x = ((x >> 8) & 0x00ff00ffu) | ((x & 0x00ff00ffu) << 8);
  return (x >> 16) | (x << 16);
}
#endif

// Owen scrambling of the bits of x, each flipped by a hash of the bits above it (Burley 2020:
// the Laine-Karras permutation applied to the reversed bits).
PR_INLINE u32 pr_owen_scramble(u32 x, u32 seed) {
  x = pr_reverse_bits(x);
  x += seed;
  x ^= x * 0x6c50b47cu;
  x ^= x * 0xb82f1e52u;
  x ^= x * 0xc7afe638u;
  x ^= x * 0x8d22f6e6u;
  return pr_reverse_bits(x);
}

// The first two dimensions of the Sobol sequence, as 32-bit fractions: van der Corput, and the
// dimension whose direction numbers follow v_k = v_(k-1) ^ (v_(k-1) >> 1) (polynomial x + 1).
PR_INLINE u32 pr_sobol0(u32 index) {
  return pr_reverse_bits(index);
}
PR_INLINE u32 pr_sobol1(u32 index) {
  u32 r = 0u;
  for (u32 v = 0x80000000u; index != 0u; index >>= 1, v ^= v >> 1)
    if (index & 1u) r ^= v;
  return r;
}

// Component c of the 2-D point of pair `pair` for sample `index`: Sobol with the index shuffled
// and each axis scrambled by hashes of (key, pixel, pair), so that every pair is stratified over
// the pixel's samples and pairs are independent of one another (padding, as pbrt-v4's
// PaddedSobolSampler). Any 2^k samples whose indices differ in their low k bits (the first 2^k
// of a frame) form a (0, k, 2)-net.
PR_INLINE u32 pr_sobol_pair(const Rng* r, u32 pair, u32 c) {
  const u32 h = pr_hash_u32(r->k0 ^ pr_hash_u32(r->k1 ^ pr_hash_u32(pair)));
  const u32 index = pr_owen_scramble(r->k2, h);
  const u32 v = c == 0u ? pr_sobol0(index) : pr_sobol1(index);
  return pr_owen_scramble(v, pr_hash_u32(h ^ (0x9e3779b9u * (c + 1u))));
}

PR_INLINE float pr_u32_to_unit(u32 v) {
  return (float)(v >> 8) * (1.0f / 16777216.0f);
}

// Every draw takes one pair of dimensions, so that a 2-D draw (a point on a light, a BSDF
// direction, the pixel jitter) is one stratified pair. A float in [0, 1): 1.0 is never returned.
PR_INLINE float rng_next(Rng* r) {
  const u32 d = r->dim;
  r->dim += 2u;
  return pr_u32_to_unit(r->sobol && d < PR_SOBOL_DIMS ? pr_sobol_pair(r, d >> 1, 0u)
                                                      : rng_u32_at(r, d));
}

PR_INLINE float2 rng_next2(Rng* r) {
  const u32 d = r->dim;
  r->dim += 2u;
  if (r->sobol && d < PR_SOBOL_DIMS)
    return make_float2(pr_u32_to_unit(pr_sobol_pair(r, d >> 1, 0u)),
                       pr_u32_to_unit(pr_sobol_pair(r, d >> 1, 1u)));
  return make_float2(pr_u32_to_unit(rng_u32_at(r, d)), pr_u32_to_unit(rng_u32_at(r, d + 1u)));
}

// Skips `draws` draws (to keep the layout of dimensions the same whichever way a path goes).
PR_INLINE void rng_skip(Rng* r, u32 draws) {
  r->dim += 2u * draws;
}

PR_NAMESPACE_END
