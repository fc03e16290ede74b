// adaptive_plan (--noise-threshold): one work-item per pixel of the film's range [first, end),
// after the `pilot` passes that every pixel takes. Reads the film's sums of those passes and
// the sums of their odd passes; writes each pixel's budget, its passes in all (pilot to spp),
// and the largest in *max_budget (atomic_max: the same whatever the order).
// The budget is the sample count at which the pixel's estimated relative error would fall to
// `threshold`. The variance comes from the two halves of the pilot (even and odd passes), as
// Cycles estimates it, relative to the pixel's value plus relMSE's 0.01 so that dark pixels do
// not ask for everything. It is averaged over the neighbours within `radius`, the pixel itself
// left out: a pixel's count then never depends on its own samples, and their mean stays
// unbiased (docs/design.md, "Adaptive sampling").
#include "shared/common.h"
#include "shared/kernel_args.h"
#include "shared/math.h"

#define PR_ADAPTIVE_EPS 0.01f  // relMSE's

PR_KERNEL void adaptive_plan(PR_PARAMS(PR_ARGS_ADAPTIVE_PLAN)) {
  const uint i = (uint)get_global_id(0);
  if (i >= end) return;
  const int x = (int)(i % width), y = (int)(i / width), r = (int)radius;
  const uint n_odd = pilot / 2u, n_even = pilot - n_odd;
  // Var(mean of evens - mean of odds) = sigma^2 (1/n_even + 1/n_odd).
  const float k = 1.0f / (1.0f / (float)n_even + 1.0f / (float)n_odd);
  float sum = 0.0f;
  uint count = 0u;
  for (int dy = -r; dy <= r; ++dy)
    for (int dx = -r; dx <= r; ++dx) {
      const int qx = x + dx, qy = y + dy;
      if ((dx == 0 && dy == 0) || qx < 0 || qx >= (int)width || qy < 0) continue;
      const uint q = (uint)qy * width + (uint)qx;
      if (q < first || q >= end) continue;
      const float4 s = film[q], o = odd[q];
      const float4 m = s / (float)pilot, d = (s - o) / (float)n_even - o / (float)n_odd;
      const float rel =
          k *
          (d.x * d.x / (m.x * m.x + PR_ADAPTIVE_EPS) + d.y * d.y / (m.y * m.y + PR_ADAPTIVE_EPS) +
           d.z * d.z / (m.z * m.z + PR_ADAPTIVE_EPS)) /
          3.0f;
      sum += rel;
      ++count;
    }
  // The samples N at which rel / N = threshold^2; all of them where that is unknown.
  const float want = count ? sum / (float)count / (threshold * threshold) : PR_INF_F;
  const uint b = want < (float)spp ? max(pilot, (uint)ceil(want)) : spp;
  budget[i] = b;
  atomic_max(max_budget, b);
}

// adaptive_list: one work-item per pixel of the film's range (launched from its first pixel, up
// to `end`). Appends each pixel whose budget exceeds `sample` to `pixels` (their order is the
// threads'; no kernel's result depends on it) and counts them in *count.
PR_KERNEL void adaptive_list(PR_PARAMS(PR_ARGS_ADAPTIVE_LIST)) {
  const uint i = (uint)get_global_id(0);
  if (i >= end) return;
  if (sample < budget[i]) pixels[atomic_inc(count)] = i;
}
