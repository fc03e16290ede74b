// pt_shade: one work-item per live path (the bounce's queue). Reads the path and its hit; adds
// emission (MIS-weighted against next-event estimation) to the sample's radiance, writes a shadow
// ray for next-event estimation, samples the BSDF for the next ray and applies Russian roulette.
// Writes the PathState, the radiance and the ShadowRay of the same index, and appends the path to
// next_queue if it goes on and to shadow_queue if it has a shadow ray (their order varies from
// run to run; what each path computes does not: its random numbers are keyed by its pixel and
// sample).
// That is the path tracer. The techniques built in (shared/techniques.h) hook into it where they
// are called: PR_EYE_PATHS weighs the paths against the connections to stored light paths
// (shade_eye_paths.h), PR_RESAMPLE offers them to the pixel's reservoirs (shade_resample.h). With
// either, x_1 (the first non-delta vertex) is written to the sample's EyeVertex, for connect and
// pt_resample.
#include "pathtrace/shade_eye_paths.h"
#include "pathtrace/shade_resample.h"
#include "shared/reuse.h"

// The path tracer's weight w of a path ending on a light, as *ew's first part; the connections'
// parts are 0 until a hook sets them, and T's length is that of x_1 .. x_t, t = p->depth.
PR_INLINE void pt_weight_parts(const PathState* p, float w, u32 max_depth, int last_still,
                               EyeWeight* ew) {
  ew->pt = w;
  ew->n = ew->h = ew->l = ew->t = 0.0f;
  ew->t_len = eye_paths_camera_len(p->depth, max_depth);
  ew->l_ok = ep_l_ok(p, last_still);
}

// The weight of emission found at h along d (dist2 from the previous vertex): against next-event
// estimation, and where the connections can make the path too (joinable; L only where the
// segment to h is still too), times their share; its parts into *ew.
PR_INLINE float pt_emission_weight(const SceneData* s, const PathState* p, const SurfaceHit* h,
                                   float3 d, float dist2, int joinable, int last_still,
                                   const EyeMis* em, u32 max_depth, EyeWeight* ew) {
  const float3 prev = make_float3(p->prev_x, p->prev_y, p->prev_z);
  const float3 prev_n = make_float3(p->prev_nx, p->prev_ny, p->prev_nz);
  float w = 1.0f;
  if (!(p->flags & PR_PATH_SPECULAR))
    w = power_heuristic(p->last_pdf, emitter_pdf(s, h, prev, prev_n));
  pt_weight_parts(p, w, max_depth, last_still, ew);  // T's ratio was fixed at x_2
  if (PR_EYE_PATHS && joinable) w = ep_emission_share(s, p, h, d, dist2, em, w, ew);
  return w;
}

// The weight of a next-event sample at vertex h: the power heuristic against BSDF sampling,
// times, where h is joinable, what the connections leave of the path (L only where the shadow
// ray's segment is still too); its parts into *ew.
PR_INLINE float pt_next_event_weight(const SceneData* s, const PathState* p, const SurfaceHit* h,
                                     const ShadingFrame* f, const NextEventChoice* ch, int joinable,
                                     int last_still, int has_rev, float dist2, const EyeMis* em,
                                     u32 max_depth, EyeWeight* ew) {
  const float w = ch->delta ? 1.0f : power_heuristic(ch->pdf_light, ch->pdf_bsdf);
  pt_weight_parts(p, w, max_depth, last_still, ew);
  if (PR_EYE_PATHS && joinable)
    return ep_next_event_share(s, p, h, f, ch, has_rev, dist2, em, w, ew);
  return w;
}

// A contribution as the radiance buffer holds it.
PR_INLINE float4 pt_rgb(float3 c) {
  return (float4)(c.x, c.y, c.z, 0.0f);
}

// The weight of the environment found along d (escaped), pdf_light next-event estimation's
// density of d: against next-event estimation, and where the connections can make the path
// (joinable; L only where the escaping ray is still too), times their share; its parts into *ew.
PR_INLINE float pt_escape_weight(const SceneData* s, const PathState* p, float3 d, float pdf_light,
                                 int joinable, int last_still, const EyeMis* em, u32 max_depth,
                                 EyeWeight* ew) {
  const int spec = (p->flags & PR_PATH_SPECULAR) != 0u;
  float w = spec ? 1.0f : power_heuristic(p->last_pdf, pdf_light);
  pt_weight_parts(p, w, max_depth, last_still, ew);
  if (PR_EYE_PATHS && joinable) w = ep_escape_share(s, p, d, em, w, ew);
  return w;
}

// The path escaped: the environment's light (weighted as pt_escape_weight says) into the
// sample's radiance, or resampling from x_1 (rel 1) to the direct light's reservoir and from x_2
// on (rel >= 2) to the paths'.
PR_INLINE void pt_escape(const SceneData* s, const PathState* p, uint rel, const EyeMis* em,
                         u32 max_depth, __global const PathTrack* track,
                         __global PathReservoir* res, __global DirectReservoir* di,
                         const RsKey* key, __global float4* radiance) {
  const float3 d = make_float3(p->ray.dx, p->ray.dy, p->ray.dz);
  const float3 le = environment_radiance(s, d);
  if (!(max3(le) > 0.0f)) return;
  const float3 prev = make_float3(p->prev_x, p->prev_y, p->prev_z);
  const float3 prev_n = make_float3(p->prev_nx, p->prev_ny, p->prev_nz);
  const float pdf_light =
      (p->flags & PR_PATH_SPECULAR) && !rel ? 0.0f : environment_pdf(s, prev, prev_n, d);
  EyeWeight ew;
  const int joinable = pt_joinable(p, 1u);
  const int still = joinable && ep_ray_still(s, prev, d, PR_INF_F);
  const float w = pt_escape_weight(s, p, d, pdf_light, joinable, still, em, max_depth, &ew);
  if (PR_RESAMPLE && rel == 1u &&
      di_offer_hit(s, p, track, s->lights.env_light, 0.0f, 0.0f, d, le, 1.0f, w, di, key))
    return;
  if (PR_RESAMPLE && rel >= 2u) {
    rs_offer_emission(track, res, p, rel, le, &ew, pdf_light, 1, d, key);
    return;
  }
  *radiance += pt_rgb(make_float3(p->tp_r, p->tp_g, p->tp_b) * le * w);
}

// Emission at h (reached along d at squared distance dist2), weighted w by the path tracer (ew:
// its parts), into the sample's radiance, or resampling at x_2 (rel 1) to the direct light's
// reservoir and from x_3 on (rel >= 2) to the paths'.
PR_INLINE void pt_emission(const SceneData* s, const PathState* p, const SurfaceHit* h, uint rel,
                           float3 d, float dist2, float w, const EyeWeight* ew, float3 tp,
                           __global const PathTrack* track, __global PathReservoir* res,
                           __global DirectReservoir* di, const RsKey* key,
                           __global float4* radiance) {
  const float3 le = surface_emission(s, h);
  if (PR_RESAMPLE && rel == 1u &&
      di_offer_hit(s, p, track, emitter_light(s, h), h->b1, h->b2, d, le,
                   fabs(dot(h->ng, d)) / dist2, w, di, key))
    return;
  if (PR_RESAMPLE && rel >= 2u) {
    const float pdf_light = emitter_pdf(s, h, make_float3(p->prev_x, p->prev_y, p->prev_z),
                                        make_float3(p->prev_nx, p->prev_ny, p->prev_nz));
    rs_offer_emission(track, res, p, rel, le, ew, pdf_light, 0, h->p, key);
    return;
  }
  *radiance += pt_rgb(tp * le * w);
}

PR_INLINE void pt_write_eye(__global EyeVertex* out, const SurfaceHit* h, const Hit* hit, float3 wo,
                            float3 tp, uint depth) {
  EyeVertex e;
  eye_vertex_set(&e, h, hit, wo, tp, depth);
  *out = e;
}

// The eye path's bookkeeping at a vertex (with eye paths or resampling): its first non-delta
// vertex becomes x_1, the eye vertex that connect joins to the stored light paths (and,
// resampling, the vertex pt_resample reconnects from); p->lt, cos^3 of the camera ray's angle
// until now, becomes its camera factor for strategy T. With eye paths, later vertices carry the
// eye path's densities for the MIS weights against the connections. prefix_still: the segment
// just traced is the camera's and still (camera_segment_still).
PR_INLINE void pt_eye_vertex(PathState* p, const SurfaceHit* h, const Hit* hit, float3 d,
                             float dist2, float3 tp, int delta_here, int seg_still,
                             int prefix_still, uint max_depth, float lt_scale,
                             __global EyeVertex* eye) {
  if (p->x1_depth == 0u) {
    if (!delta_here && p->depth < max_depth) {
      p->x1_depth = p->depth;
      if (prefix_still) p->eye_flags |= PR_EYE_PREFIX_STILL;
      p->lt = p->depth == 1u ? eye_paths_camera_factor(lt_scale, p->lt * dist2) : 0.0f;
      pt_write_eye(eye, h, hit, -d, tp, p->depth);
    }
  } else if (PR_EYE_PATHS) {
    pt_eye_arrive(p, h, d, dist2, delta_here, seg_still);
  }
}

// The path leaves h along the sampled step: the next ray and what the next vertex needs of this
// one (its position and light-side normal, the step's pdf, whether it was delta).
PR_INLINE void pt_leave(const SceneData* s, PathState* p, const SurfaceHit* h,
                        const ShadingFrame* f, const PathStep* step) {
  p->seg_cos = fabs(dot(f->ng, step->wi));
  p->ray = surface_ray(s, h, step->wi, PR_INF_F);
  p->prev_x = h->p.x;
  p->prev_y = h->p.y;
  p->prev_z = h->p.z;
  const float3 n_l = frame_light_normal(f);
  p->prev_nx = n_l.x;
  p->prev_ny = n_l.y;
  p->prev_nz = n_l.z;
  p->last_pdf = step->pdf;
  p->flags = step->delta ? PR_PATH_SPECULAR : 0u;
}

PR_INLINE void pt_shadow_set(__global ShadowRay* r, Ray ray, float3 c, uint op) {
  r->ray = ray;
  r->c_r = c.x;
  r->c_g = c.y;
  r->c_b = c.z;
  r->op = op;
}

#define PR_SHADE_LIVE 1u    // the path goes on
#define PR_SHADE_SHADOW 2u  // it wrote a shadow ray

// Appends `item` to `queue` where `take`, with one global atomic per work-group (its items land
// together: in work-item order where a device runs them in order, as PoCL does). Every
// work-item of the group must call it.
PR_INLINE void queue_append(__global uint* queue, __global uint* size, int take, uint item,
                            __local uint* group_count, __local uint* group_base) {
  if (get_local_id(0) == 0u) *group_count = 0u;
  barrier(CLK_LOCAL_MEM_FENCE);
  const uint slot = take ? atomic_inc(group_count) : 0u;
  barrier(CLK_LOCAL_MEM_FENCE);
  if (get_local_id(0) == 0u) *group_base = *group_count ? atomic_add(size, *group_count) : 0u;
  barrier(CLK_LOCAL_MEM_FENCE);
  if (take) queue[*group_base + slot] = item;
  barrier(CLK_LOCAL_MEM_FENCE);  // before the next call resets the counts
}

// One live path i: PR_SHADE_* of what it goes on with.
PR_INLINE uint pt_shade_path(PR_PARAMS(PR_ARGS_PT_SHADE), uint i) {
  SceneData s = PR_SCENE();
  scene_at_sample(&s, seed, frame, i, sample);
  const uint k = i - base;  // the path's own state in the band; the frame's at pixel i
  PathState p = states[k];
  uint out = 0u;
  const EyeMis em = {paths_per_pixel, rsp.eye_count, trace_cdf, trace_total};

  // Resampling: the vertex this hit is, counted from x_1 (0: x_1 not met yet); the paths that
  // reach an emitter from x_2 on go to the pixel's reservoir instead of its radiance.
  const uint rel = PR_RESAMPLE && p.x1_depth > 0u ? p.depth + 1u - p.x1_depth : 0u;
  PR_GLOBAL PathTrack* track = rs_track + k;
  const RsKey key = {seed, frame, p.pixel, sample};
  const Hit hit = hits[k];
  if (hit.prim == PR_INVALID_INDEX) {
    pt_escape(&s, &p, rel, &em, max_depth, track, rs_res + i, di_res + i, &key, radiance + i);
    p.alive = 0u;
    states[k] = p;
    return 0u;
  }
  Rng rng = rng_make(seed, PR_RNG_CAMERA, frame, p.pixel, sample);
  rng.dim = p.rng_dim;
  const float3 d = make_float3(p.ray.dx, p.ray.dy, p.ray.dz);
  const float3 wo = -d;
  const SurfaceHit h = surface_at(&s.sd, hit.prim, hit.inst, hit.u, hit.v);
  const float3 tr = volume_transmittance(&s, &h, d, hit.t);
  float3 tp = make_float3(p.tp_r, p.tp_g, p.tp_b) * tr;
  const float dist2 = hit.t * hit.t;
  if (rel > 0u)  // resampling (rel is 0 without it)
    rs_track_hit(track, rel, &hit, h.p, tr,
                 solid_angle_to_area_pdf(p.last_pdf, fabs(dot(h.ng, d)), dist2));

  // Under a shutter, whether the segment just traced meets nothing that moves (shade_eye_paths.h):
  // asked only of the segments from x_2 on of paths that L can still make.
  const float3 prev = make_float3(p.prev_x, p.prev_y, p.prev_z);
  const int seg_asked =
      p.x1_depth > 0u && p.depth > p.x1_depth &&
      (p.eye_flags & (PR_EYE_JOINABLE | PR_EYE_MOVED | PR_EYE_PREFIX_STILL)) == PR_EYE_JOINABLE;
  const int seg_still = !seg_asked || ep_ray_still(&s, prev, h.p - prev, 1.0f);
  // The camera's segment to a first hit (x_1 where it is not delta), as connect asks it.
  const int prefix_still = PR_EYE_PATHS && p.depth == 0u && s.lights.sweep_count > 0u &&
                           camera_segment_still(&s, prev, h.p);
  if (s.sd.materials[h.material].flags & PR_MAT_EMISSIVE) {
    EyeWeight ew;
    // Connections can make the paths that end after x_t, t >= 2 (x_t: the vertex `ray` left).
    const float w = pt_emission_weight(&s, &p, &h, d, dist2, pt_joinable(&p, 1u), seg_still, &em,
                                       max_depth, &ew);
    pt_emission(&s, &p, &h, rel, d, dist2, w, &ew, tp, track, rs_res + i, di_res + i, &key,
                radiance + i);
  }
  p.depth += 1u;
  const ShadingFrame f = shading_frame(&s, &h, wo);
  const int delta_here = bsdf_is_delta(&f.bsdf);
  if (PR_EYE_PATHS || PR_RESAMPLE)
    pt_eye_vertex(&p, &h, &hit, d, dist2, tp, delta_here, seg_still, prefix_still, max_depth,
                  rsp.lt_scale, eye + p.pixel);
  // x_t with t >= 3: the light tracer's density of x_{t-1}, reached from this vertex.
  const int has_rev = pt_joinable(&p, 2u);
  if (p.depth >= max_depth) {
    p.alive = 0u;
  } else {
    if (!delta_here) {
      Ray shadow;
      float3 c;
      NextEventChoice ch;
      const int here_joinable = pt_joinable(&p, 1u);
      if (next_event(&s, &h, &f, wo, !here_joinable, &rng, &shadow, &c, &ch)) {
        EyeWeight ew;
        const int still = here_joinable &&
                          ((p.eye_flags & PR_EYE_PREFIX_STILL) || ep_next_event_still(&s, &h, &ch));
        const float w = pt_next_event_weight(&s, &p, &h, &f, &ch, here_joinable, still, has_rev,
                                             dist2, &em, max_depth, &ew);
        if (here_joinable) c = c * w;  // next_event left the weight to this
        const uint op = PR_RESAMPLE
                            ? rs_next_event_pending(&s, track, rs_pending + k, di_pending + k, &rsp,
                                                    &p, &h, &f, wo, dist2, &ch, c, &ew)
                            : 0u;
        pt_shadow_set(shadows + k, shadow, tp * c, op);
        out = PR_SHADE_SHADOW;
      }
    } else {
      rng_skip(&rng, PR_NEXT_EVENT_DRAWS);  // the same dimensions whatever the material
    }
    const float u0 = rng_next(&rng);
    const float2 u12 = rng_next2(&rng);
    PathStep step;
    if (!path_step(&s, &h, &f, wo, u0, u12.x, u12.y, PR_RADIANCE, &step)) {
      p.alive = 0u;
    } else {
      tp = tp * step.weight;
      // From the third vertex on (the camera's throughput starts at 1), surviving with the
      // square root of the throughput (Cycles' rule; pbrt-v4's, the throughput itself, ends
      // paths whose light is still much of the pixel's: docs/experiments/russian-roulette.md).
      const float rr = rng_next(&rng);
      const float q = p.depth >= 3u ? fmin(sqrt(max3(tp)), 1.0f) : 1.0f;
      if (!russian_roulette(q, rr, &tp)) p.alive = 0u;
      if (PR_RESAMPLE && p.x1_depth > 0u && p.alive)
        rs_track_step(track, &rsp, p.depth - p.x1_depth, &h, &f, wo, dist2, &step, q);
      if (PR_EYE_PATHS) ep_leave(&p, &f, step.wi, wo, dist2, rsp.lt_scale, has_rev, delta_here);
      pt_leave(&s, &p, &h, &f, &step);
    }
  }
  if (!(max3(tp) < PR_INF_F)) p.alive = 0u;  // NaN or Inf throughput ends the path
  p.tp_r = tp.x;
  p.tp_g = tp.y;
  p.tp_b = tp.z;
  p.rng_dim = rng.dim;
  states[k] = p;
  return out | (p.alive ? PR_SHADE_LIVE : 0u);
}

PR_KERNEL void pt_shade(PR_PARAMS(PR_ARGS_PT_SHADE)) {
  __local uint group_count, group_base;
  const uint j = (uint)get_global_id(0);
  const uint i = j < count ? queue[j] : 0u;
  const uint out = j < count ? pt_shade_path(PR_ARG_VALUES(PR_ARGS_PT_SHADE), i) : 0u;
  queue_append(next_queue, queue_sizes + PR_QUEUE_LIVE, out & PR_SHADE_LIVE, i, &group_count,
               &group_base);
  queue_append(shadow_queue, queue_sizes + PR_QUEUE_SHADOW, out & PR_SHADE_SHADOW, i, &group_count,
               &group_base);
}
