// accumulate: one work-item per pixel sample. Reads the sample's radiance and adds it to its
// pixel of the film (sample i belongs to pixel i % pixel_count; one pass per sample index, so
// no two work-items share a pixel). A non-finite sample is dropped and counted, never written.
// Writes film (float4 per pixel: rgb sum and sample count) and bad_samples (an atomic count,
// whose total does not depend on thread order). Where `listed` (--noise-threshold), work-item i
// is the pass's listed pixel i, and the pixels not listed add nothing.
#include "shared/common.h"
#include "shared/kernel_args.h"
#include "shared/splat.h"

PR_KERNEL void accumulate(PR_PARAMS(PR_ARGS_ACCUMULATE)) {
  const uint i = (uint)get_global_id(0);
  if (i >= count) return;
  if (listed && i >= list_count) return;
  const uint px = listed ? pixels[i] : i % pixel_count;
  const float4 l = radiance[listed ? px : i];
  if (!(isfinite(l.x) && isfinite(l.y) && isfinite(l.z))) {
    atomic_inc(bad_samples);
    film[px] += (float4)(0.0f, 0.0f, 0.0f, 1.0f);  // the sample counts, as zero
    return;
  }
  film[px] += (float4)(l.x, l.y, l.z, 1.0f);
}

// splat_film (strategy T): one work-item per pixel of the film's range (launched from its first
// pixel, up to `end`). Adds the pixel's splats (shared/splat.h) times `scale` (1, or under
// --time-limit what brings them from spp samples to the passes rendered) to its film sum, not
// to its count, and clears them for the next frame where `clear`. With `by_count` (after
// --noise-threshold's passes) it adds them times the pixel's own count as well: they stand for
// `scale` = 1/spp of strategy T's estimate per sample.
PR_KERNEL void splat_film(PR_PARAMS(PR_ARGS_SPLAT_FILM)) {
  const uint i = (uint)get_global_id(0);
  if (i >= end) return;
  __global uint* w = splat + (size_t)i * PR_SPLAT_WORDS;
  const float r = splat_value(w[0], w[1]), g = splat_value(w[2], w[3]), b = splat_value(w[4], w[5]);
  const float k = by_count ? scale * film[i].w : scale;
  film[i] += (float4)(r, g, b, 0.0f) * k;
  if (clear)
    for (uint k = 0u; k < PR_SPLAT_WORDS; ++k) w[k] = 0u;
}
