// Strategy T's splats (kernels/reuse/camera_splat.cl): per pixel, three channels summed in 64-bit
// fixed point, each a low and a high 32-bit word. OpenCL 1.2 has no float atomics, and floats
// summed in thread order would change a frame's bits from run to run; integers added with
// atomic_add (the low word's carry into the high word) give one sum in any order.
#pragma once

#include "shared/common.h"

PR_NAMESPACE_BEGIN

#define PR_SPLAT_WORDS 6u           // per pixel: low, high word of r, g, b
#define PR_SPLAT_ONE 268435456.0f   // 2^28 units of fixed point make 1
#define PR_SPLAT_MAX 1073741824.0f  // a splat's value at most (2^58 units): 64 of them fit in 2^64

// A splat's value in fixed point (truncated; negative or NaN: 0).
PR_INLINE u64 splat_fixed(float v) {
  if (!(v > 0.0f)) return 0u;
  return (u64)((v < PR_SPLAT_MAX ? v : PR_SPLAT_MAX) * PR_SPLAT_ONE);
}

// The value of a channel's words.
PR_INLINE float splat_value(u32 lo, u32 hi) {
  return (float)hi * (4294967296.0f / PR_SPLAT_ONE) + (float)lo * (1.0f / PR_SPLAT_ONE);
}

// The carry of adding lo to a low word that held old.
PR_INLINE u32 splat_carry(u32 old, u32 lo) {
  return (u32)(old + lo) < old ? 1u : 0u;
}

#ifdef PR_DEVICE_CODE
PR_INLINE void splat_add_channel(__global uint* w, float v) {
  const u64 q = splat_fixed(v);
  const u32 lo = (u32)q, hi = (u32)(q >> 32);
  const u32 carry = lo ? splat_carry(atomic_add(w, lo), lo) : 0u;
  if (hi + carry) atomic_add(w + 1, hi + carry);
}

// Adds v to a pixel's words w.
PR_INLINE void splat_add(__global uint* w, float3 v) {
  splat_add_channel(w, v.x);
  splat_add_channel(w + 2, v.y);
  splat_add_channel(w + 4, v.z);
}
#endif

PR_NAMESPACE_END
