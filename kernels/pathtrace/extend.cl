// pt_extend: one work-item per live path (the bounce's queue). Reads the path's ray; writes its
// closest hit (prim == PR_INVALID_INDEX when it escapes) and counts the ray in rays[PR_PT_CAMERA]
// or rays[PR_PT_BOUNCE]. Under --shutter the ray is traced at its camera sample's time.
#include "shared/transport.h"
#include "shared/path_state.h"

PR_KERNEL void pt_extend(PR_PARAMS(PR_ARGS_PT_EXTEND)) {
  const uint j = (uint)get_global_id(0);
  if (j >= count) return;
  const uint i = queue[j];
  SceneData s = PR_SCENE();
  scene_at_sample(&s, seed, frame, i, sample);
  const uint k = i - base;  // the path's own state in the band
  atomic_inc(counter_lane(rays, PR_PT_ROW) + (states[k].depth == 0u ? PR_PT_CAMERA : PR_PT_BOUNCE));
  Hit hit;
  if (!trace_closest(&s, states[k].ray, &hit)) hit = hit_none();
  hits[k] = hit;
}
