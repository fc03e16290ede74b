// pt_shadow: one work-item per path that pt_shade gave a shadow ray (shadow_queue). If the ray is
// unoccluded, adds its contribution to the sample's radiance. Counts it in rays[PR_PT_SHADOW].
#include "shared/integrator.h"
#include "shared/path_state.h"

PR_KERNEL void pt_shadow(PR_PARAMS(PR_ARGS_PT_SHADOW)) {
  const uint j = (uint)get_global_id(0);
  if (j >= count) return;
  const uint i = shadow_queue[j];
  const ShadowRay r = shadows[i];
  const SceneData s = PR_SCENE();
  atomic_inc(rays + PR_PT_SHADOW);
  if (trace_occluded(&s, r.ray)) return;
  radiance[i] += (float4)(r.c_r, r.c_g, r.c_b, 0.0f);
}
