// pt_shadow: one work-item per path. Reads its ShadowRay; if it is valid and unoccluded, adds
// its contribution to the sample's radiance. Writes radiance; counts the ray in rays[PR_PT_SHADOW].
#include "shared/integrator.h"
#include "shared/path_state.h"

PR_KERNEL void pt_shadow(PR_PARAMS(PR_ARGS_PT_SHADOW)) {
  const uint i = (uint)get_global_id(0);
  if (i >= count) return;
  const ShadowRay r = shadows[i];
  if (!r.valid) return;
  const SceneData s = PR_SCENE();
  atomic_inc(rays + PR_PT_SHADOW);
  if (trace_occluded(&s, r.ray)) return;
  radiance[i] += (float4)(r.c_r, r.c_g, r.c_b, 0.0f);
}
