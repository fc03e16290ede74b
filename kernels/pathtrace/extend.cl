// pt_extend: one work-item per path. Reads the path's ray; writes its closest hit (prim ==
// PR_INVALID_INDEX when it escapes or the path is dead) and counts the ray in rays[PR_PT_CAMERA]
// or rays[PR_PT_BOUNCE].
#include "shared/integrator.h"
#include "shared/path_state.h"

PR_KERNEL void pt_extend(PR_PARAMS(PR_ARGS_PT_EXTEND)) {
  const uint i = (uint)get_global_id(0);
  if (i >= count) return;
  Hit hit = hit_none();
  if (states[i].alive) {
    const SceneData s = PR_SCENE();
    atomic_inc(rays + (states[i].depth == 0u ? PR_PT_CAMERA : PR_PT_BOUNCE));
    if (!trace_closest(&s, states[i].ray, &hit)) hit = hit_none();
  }
  hits[i] = hit;
}
