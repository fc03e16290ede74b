// pt_shadow: one work-item per path that pt_shade gave a shadow ray (shadow_queue). If the ray is
// unoccluded, adds its contribution to the sample's radiance, or with --resample, where pt_shade
// marked it (op: 1 + the random dimension that offers it), offers the path it ends to the
// sample's reservoir (PR_RS_OP_DIRECT: x_1's direct light to the direct light's). Counts it in
// rays[PR_PT_SHADOW].
#include "shared/transport.h"
#include "shared/path_state.h"
#include "shared/resample_direct.h"

PR_KERNEL void pt_shadow(PR_PARAMS(PR_ARGS_PT_SHADOW)) {
  const uint j = (uint)get_global_id(0);
  if (j >= count) return;
  const uint i = shadow_queue[j];
  const uint k = i - base;  // the path's own state in the band
  const ShadowRay r = shadows[k];
  SceneData s = PR_SCENE();
  scene_at_sample(&s, seed, frame, i, sample);
  atomic_inc(counter_lane(rays, PR_PT_ROW) + PR_PT_SHADOW);
  if (trace_occluded(&s, r.ray)) return;
  if (resample && r.op) {
    const RsKey key = {seed, frame, i, sample};
    if (r.op & PR_RS_OP_DIRECT) {
      const DirectReservoir c = di_pending[k];
      di_offer_keyed(di_res + i, &c, &key, (r.op & ~PR_RS_OP_DIRECT) - 1u);
      return;
    }
    const PathReservoir c = rs_pending[k];
    rs_offer_keyed(rs_res + i, &c, &key, r.op - 1u);
    return;
  }
  radiance[i] += (float4)(r.c_r, r.c_g, r.c_b, 0.0f);
}
