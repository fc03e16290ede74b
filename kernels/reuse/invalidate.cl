// invalidate: one work-item per slot. A stored path stays valid only if tracing it again now
// would give the same vertices (docs/design.md section 5): it is invalid when (c) its light moved,
// (b) a vertex lies on a DSG instance that moved, (a) a segment, or the final escaping ray, now
// meets DSG geometry before its stored end, or (d) under a shutter, it meets what moves. Only the
// DSG is tested. Reads the headers, the vertices, the instances' moved flags and the light table;
// clears `valid` of invalid slots, appends them to `list` (its order varies, the set does not), and
// counts the light vertices of the paths that stay valid. Where frame_stamp > 0 (the connection
// history), it stamps each invalid slot in `changed` with it; with `mark_only` (--mode retrace,
// which traces every slot anyway) it does that alone, so that both modes learn the same changed
// slots.
#include "shared/reuse.h"

PR_KERNEL void invalidate(PR_PARAMS(PR_ARGS_INVALIDATE)) {
  const uint slot = (uint)get_global_id(0);
  if (slot >= rp.slots) return;
  const SceneData s = PR_SCENE();
  const PathHeader h = headers[slot];
  __global const LightVertex* v = vertices + (size_t)slot * rp.stride;
  // A path traced at the previous frame's own time (PR_PATH_TIMED) is that frame's alone.
  int ok = h.valid == 1u;
  uint rays = 0u;
  if (ok && h.light != PR_INVALID_INDEX && s.lights.lights[h.light].moved) ok = 0;  // (c)
  for (uint k = 1u; ok && k < h.vertex_count; ++k) {                                // (b)
    const uint inst = v[k].inst;
    if (inst != PR_INVALID_INDEX && s.sd.instances[inst].moved) ok = 0;
  }
  if (ok && test_segments) {  // (a)
    for (uint k = 1u; ok && k < h.vertex_count; ++k) {
      const float3 d = vertex_dir(v + k);
      Ray r = make_ray(
          light_segment_origin(&s.sd, vertex_pos(v + k - 1u), v[k - 1u].ng_oct, v[k - 1u].ns_oct,
                               v[k - 1u].prim, v[k - 1u].inst, v[k - 1u].b1, v[k - 1u].b2, d),
          d, 0.0f, PR_INF_F);
      r.tmax = v[k].t;  // strictly nearer than the stored hit, as closest-hit traversal decides
      ++rays;
      if (occluded_dynamic(&s.geom, r)) ok = 0;
    }
    if (ok && h.end == PR_END_ESCAPED && h.vertex_count > 0u) {
      const uint last = h.vertex_count - 1u;
      const float3 d = make_float3(h.escape_x, h.escape_y, h.escape_z);
      const Ray r =
          make_ray(light_segment_origin(&s.sd, vertex_pos(v + last), v[last].ng_oct, v[last].ns_oct,
                                        v[last].prim, v[last].inst, v[last].b1, v[last].b2, d),
                   d, 0.0f, PR_INF_F);
      ++rays;
      if (occluded_dynamic(&s.geom, r)) ok = 0;
    }
  }
  // (d) Under a shutter, a path that meets what moves while it is open is traced at the slot's
  // time (light_trace).
  if (ok && !light_path_still(&s, &h, v)) ok = 0;
  if (rays) atomic_add(counter_lane(counters, PR_C_ROW) + PR_C_INVALID_RAYS, rays);
  if (!ok && frame_stamp > 0u) changed[slot] = frame_stamp;
  if (mark_only) return;
  if (!ok) {
    headers[slot].valid = 0u;
    list[atomic_inc(counters + PR_C_LIST)] = slot;
    return;
  }
  uint ssg = 0u, dsg = 0u;
  for (uint k = 1u; k < h.vertex_count; ++k) {
    if (v[k].inst == PR_INVALID_INDEX)
      ++ssg;
    else
      ++dsg;
  }
  if (ssg) atomic_add(counter_lane(counters, PR_C_ROW) + PR_C_SSG_VERTICES, ssg);
  if (dsg) atomic_add(counter_lane(counters, PR_C_ROW) + PR_C_DSG_VERTICES, dsg);
}
