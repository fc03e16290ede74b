// accumulate: one work-item per pixel sample. Reads the sample's radiance and adds it to its
// pixel of the film (sample i belongs to pixel i % pixel_count; one pass per sample index, so
// no two work-items share a pixel). A non-finite sample is dropped and counted, never written.
// Writes film (float4 per pixel: rgb sum and sample count) and bad_samples (an atomic count,
// whose total does not depend on thread order).
#include "shared/common.h"
#include "shared/kernel_args.h"

PR_KERNEL void accumulate(PR_PARAMS(PR_ARGS_ACCUMULATE)) {
  const uint i = (uint)get_global_id(0);
  if (i >= count) return;
  const float4 l = radiance[i];
  const uint px = i % pixel_count;
  if (!(isfinite(l.x) && isfinite(l.y) && isfinite(l.z))) {
    atomic_inc(bad_samples);
    film[px] += (float4)(0.0f, 0.0f, 0.0f, 1.0f);  // the sample counts, as zero
    return;
  }
  film[px] += (float4)(l.x, l.y, l.z, 1.0f);
}
