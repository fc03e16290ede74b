// connect_shadow: one work-item per pixel sample of connect's launch (PR_ARGS_PIXEL_LIST)
// (--eye-paths, where connect traces no ray). Traces the shadow rays of the sample's records in the
// order connect wrote them and adds the estimate they make, summed as the records say
// (shared/reuse.h), to the sample's radiance; counts the unoccluded connections.
#include "shared/reuse.h"

PR_KERNEL void connect_shadow(PR_PARAMS(PR_ARGS_CONNECT_SHADOW)) {
  const uint q = (uint)get_global_id(0);  // the records' index; the pixel where not listed
  if (q >= record_end || (listed && q >= list_count)) return;
  const uint n = record_counts[q - record_first];
  if (n == 0u) return;
  const uint i = listed ? pixels[q] : q;
  SceneData s = PR_SCENE();
  scene_at_sample(&s, seed, frame, i, sample);  // the sample's time (--shutter)
  SceneData at = s;                             // a light path's own (PR_REC_TIMED)
  __global const ShadowRay* r = records + (size_t)(q - record_first) * record_cap;
  float3 L = make_float3(0.0f, 0.0f, 0.0f), g = L;
  uint unoccluded = 0u;
  for (uint k = 0u; k < n; ++k) {
    const u32 op = r[k].op;
    if (op & PR_REC_TIMED) at.geom.time = at.sd.time = record_time(op);
    if ((op & PR_REC_RAY) && trace_occluded((op & PR_REC_TIMED) ? &at : &s, r[k].ray)) continue;
    if (op & PR_REC_COUNTED) ++unoccluded;
    connect_record_apply(&L, &g, make_float3(r[k].c_r, r[k].c_g, r[k].c_b), op);
  }
  radiance[i] += (float4)(L.x, L.y, L.z, 0.0f);
  if (unoccluded) atomic_add(counter_lane(counters, PR_C_ROW) + PR_C_CONNECTED, unoccluded);
}
