// pt_shade's hooks for eye paths weighted against the connections (PR_EYE_PATHS,
// shared/techniques.h): a path that ends on a light after x_t, t >= 2, with x_2 non-delta, is
// made by the connections to stored light paths too (strategy L, and T from x_2 when x_1 is seen
// straight from the camera). The eye path keeps the ratio of the two ways' densities of its
// vertices beyond x_1 as it goes (mis_ratio_*), and each path's weight takes its share
// (shared/eye_paths.h; every weight from shared/mis.h).
#pragma once

#include "shared/eye_paths.h"
#include "shared/path_state.h"
#include "shared/resample.h"  // EyeWeight
#include "shared/techniques.h"

// What the eye paths' weights read besides the path: C = paths_per_pixel samples of L against
// eye_count of the eye path, and the light tracer's choice of light (trace_cdf, trace_total).
typedef struct {
  u32 paths_per_pixel;
  float eye_count;
  __global const float* trace_cdf;
  float trace_total;
} EyeMis;

// L's density of the path over that of the eye path's vertices beyond x_1 (eye_ratio holds
// the rest), for a path ending at x_t on light l (normal n_tri, start density `start`) at z0,
// with cos_x = |cos| at x_t and rev = the light-tracing density of x_{t-1} from x_t (1 at t = 2).
PR_INLINE float eye_paths_light_side(const Light* l, float3 n_tri, float start, const EyeMis* em,
                                     float eye_ratio, float3 z0, float3 xt, float cos_x,
                                     float rev) {
  const float3 d = xt - z0;
  const float d2 = dot(d, d);
  return (float)em->paths_per_pixel / em->eye_count * start *
         eye_paths_emit_density(l, n_tri, d * (1.0f / sqrt(d2)), cos_x, d2) * rev * eye_ratio;
}

// The light tracer's density of x_{t-1} (the vertex `p.ray` left, at squared distance dist2)
// sampled from a non-delta x_t in frame f, arriving from wi and leaving towards wo.
PR_INLINE float pt_light_density(const ShadingFrame* f, const PathState* p, float3 wi, float3 wo,
                                 float dist2) {
  return solid_angle_to_area_pdf(eye_paths_bsdf_pdf(f, wi, wo), p->seg_cos, dist2);
}

// A path that the connections make too, ending on a light after x_t, t = p->depth: T's ratio
// (fixed at x_2) and the eye path's share of it from N's, H's and L's densities, times w; the
// parts into *ew.
PR_INLINE float pt_eye_share(const PathState* p, float w, float dens_n, float dens_h, float dens_l,
                             EyeWeight* ew) {
  ew->t = p->x1_depth == 1u && ew->t_len ? p->lt : 0.0f;
  if (dens_l > 0.0f) w *= eye_paths_eye_share_l(dens_n / dens_l, dens_h / dens_l, ew->t, ew->l_ok);
  ew->n = dens_n;
  ew->h = dens_h;
  ew->l = dens_l;
  return w;
}

// Under a shutter (--mode reuse): whether the ray o + t d, 0 <= t <= tmax, of the eye path meets
// nothing that moves while the shutter is open. Where one of the segments that L's light path
// would hold does, L (whose paths are the frame's) cannot make the path at this sample's time and
// takes no share of it (sweep_clear); T can (light_trace traces such paths at a time of their
// own). 1 without a shutter or eye paths.
PR_INLINE int ep_ray_still(const SceneData* s, float3 o, float3 d, float tmax) {
  return !PR_EYE_PATHS || s->lights.sweep_count == 0u || sweep_clear(s, o, d, tmax);
}

// The same for a next-event sample's segment from h to the light (towards a light at infinity,
// the ray from h), which is the first segment of the light path.
PR_INLINE int ep_next_event_still(const SceneData* s, const SurfaceHit* h,
                                  const NextEventChoice* ch) {
  if (!PR_EYE_PATHS || s->lights.sweep_count == 0u) return 1;
  if (light_at_infinity(s->lights.lights[ch->light].type))
    return sweep_clear(s, h->p, ch->wi, PR_INF_F);
  return sweep_clear(s, h->p, ch->pos - h->p, 1.0f);
}

// Whether L can make the paths that end after this path's last vertex along a last segment that
// is still (last_still): x_1's segment from the camera is still (L joins at the light path's
// time), or none of the segments from x_2 on meets what moves (at this sample's).
PR_INLINE int ep_l_ok(const PathState* p, int last_still) {
  return (p->eye_flags & PR_EYE_PREFIX_STILL) || (last_still && !(p->eye_flags & PR_EYE_MOVED));
}

// Whether the connections can make the paths that end after this path's last vertex x_t: x_2 is
// non-delta and t >= x_1's depth + beyond.
PR_INLINE int pt_joinable(const PathState* p, u32 beyond) {
  return PR_EYE_PATHS && (p->eye_flags & PR_EYE_JOINABLE) && p->depth >= p->x1_depth + beyond;
}

// Emission found at h along d (dist2 from the previous vertex), weighted w by the path tracer:
// w times the eye path's share against the connections, where h is a light they reach.
PR_INLINE float ep_emission_share(const SceneData* s, const PathState* p, const SurfaceHit* h,
                                  float3 d, float dist2, const EyeMis* em, float w, EyeWeight* ew) {
  const u32 li = emitter_light(s, h);
  if (li == PR_INVALID_INDEX) return w;
  // The connections' share of the path (eye_paths.h); the eye path's N and H split the rest.
  const float3 prev = make_float3(p->prev_x, p->prev_y, p->prev_z);
  const Light l = s->lights.lights[li];
  const float3 n_tri = eye_paths_light_normal(s, &l);
  const float start = eye_paths_start_density(&l, li, em->trace_cdf, em->trace_total);
  const int spec = (p->flags & PR_PATH_SPECULAR) != 0u;
  const float dens_h =
      spec ? 1.0f : solid_angle_to_area_pdf(p->last_pdf, fabs(dot(n_tri, d)), dist2);
  const float dens_l =
      eye_paths_light_side(&l, n_tri, start, em, p->eye_ratio, h->p, prev, p->seg_cos, 1.0f);
  return pt_eye_share(p, w, spec ? 0.0f : start, dens_h, dens_l, ew);
}

// A next-event sample at h (of light ch->light), weighted w against BSDF sampling: w times what
// the connections leave of the path; has_rev: x_t, t >= 3, whose step back to x_{t-1} (at
// squared distance dist2) the light tracer samples too.
PR_INLINE float ep_next_event_share(const SceneData* s, const PathState* p, const SurfaceHit* h,
                                    const ShadingFrame* f, const NextEventChoice* ch, int has_rev,
                                    float dist2, const EyeMis* em, float w, EyeWeight* ew) {
  const Light l = s->lights.lights[ch->light];
  if (!eye_paths_light(&l)) return w;
  const float3 n_tri =
      light_is_triangle(l.type) ? eye_paths_light_normal(s, &l) : make_float3(0.0f, 0.0f, 1.0f);
  const float3 dz = ch->pos - h->p;
  const float dz2 = dot(dz, dz);
  const float3 wi = dz * (1.0f / sqrt(dz2));
  // The environment's direction is z_0: its densities per solid angle.
  const float dens_n = eye_paths_start_density(&l, ch->light, em->trace_cdf, em->trace_total) *
                       eye_paths_direction_density(&l, s->lights.env, ch->wi);
  const float dens_h = light_is_triangle(l.type)
                           ? solid_angle_to_area_pdf(ch->pdf_bsdf, fabs(dot(n_tri, wi)), dz2)
                       : eye_paths_light_hit(&l) ? ch->pdf_bsdf
                                                 : 0.0f;
  const float rev = has_rev ? solid_angle_to_area_pdf(ch->pdf_bsdf_rev, p->seg_cos, dist2) : 1.0f;
  const float dens_l = eye_paths_light_side(&l, n_tri, dens_n, em, p->eye_ratio, ch->pos, h->p,
                                            fabs(dot(f->ng, wi)), rev);
  // T's ratio: at x_2 from the light's pdf of the step to x_1 (x_1's camera factor in p->lt),
  // beyond x_2 as fixed there.
  if (p->x1_depth == 1u && ew->t_len)
    ew->t = p->depth == 2u ? eye_paths_camera_ratio(p->lt, ch->pdf_bsdf_rev, dist2) : p->lt;
  if (dens_l > 0.0f) w *= eye_paths_eye_share_l(dens_n / dens_l, dens_h / dens_l, ew->t, ew->l_ok);
  ew->n = dens_n;
  ew->h = dens_h;
  ew->l = dens_l;
  return w;
}

// The environment found along d, weighted w by the path tracer: w times the eye path's share
// (the environment's direction is z_0: N's density of it and H's per solid angle, L's of z_1
// from the disk).
PR_INLINE float ep_escape_share(const SceneData* s, const PathState* p, float3 d, const EyeMis* em,
                                float w, EyeWeight* ew) {
  const u32 li = s->lights.env_light;
  if (li == PR_INVALID_INDEX) return w;
  const int spec = (p->flags & PR_PATH_SPECULAR) != 0u;
  const Light l = s->lights.lights[li];
  const float3 prev = make_float3(p->prev_x, p->prev_y, p->prev_z);
  const float start = eye_paths_start_density(&l, li, em->trace_cdf, em->trace_total) *
                      eye_paths_direction_density(&l, s->lights.env, d);
  const float dens_h = spec ? 1.0f : p->last_pdf;
  const float dens_l = eye_paths_light_side(&l, make_float3(0.0f, 0.0f, 1.0f), start, em,
                                            p->eye_ratio, prev - d, prev, p->seg_cos, 1.0f);
  return pt_eye_share(p, w, spec ? 0.0f : start, dens_h, dens_l, ew);
}

// The eye path's density of this vertex x_t (t >= 2; 1 when sampled from a delta vertex) into
// its running ratio, and whether x_2 is joinable. Under a shutter a segment from x_2 on that
// meets what moves (seg_still 0) ends L's share (ep_l_ok).
PR_INLINE void pt_eye_arrive(PathState* p, const SurfaceHit* h, float3 d, float dist2,
                             int delta_here, int seg_still) {
  if (p->depth == p->x1_depth + 1u)
    p->eye_flags = (p->eye_flags & PR_EYE_PREFIX_STILL) | (delta_here ? 0u : PR_EYE_JOINABLE);
  else if (!seg_still)
    p->eye_flags |= PR_EYE_MOVED;
  p->eye_ratio = mis_ratio_arrive(p->eye_ratio,
                                  solid_angle_to_area_pdf(p->last_pdf, fabs(dot(h->ng, d)), dist2),
                                  (p->flags & PR_PATH_SPECULAR) != 0u);
}

// Leaving x_t along wi: strategy T's density over L's for the vertices beyond, fixed at x_2 (of
// an x_1 seen straight from the camera) from the light tracer's pdf of the step from x_2 to x_1;
// where has_rev (t >= 3), the light tracer's density of x_{t-1} from here (1 where delta) into
// the running ratio.
PR_INLINE void ep_leave(PathState* p, const ShadingFrame* f, float3 wi, float3 wo, float dist2,
                        float lt_scale, int has_rev, int delta_here) {
  if (lt_scale > 0.0f && p->x1_depth == 1u && p->depth == 2u)
    p->lt = (p->eye_flags & PR_EYE_JOINABLE)
                ? eye_paths_camera_ratio(p->lt, eye_paths_bsdf_pdf(f, wi, wo), dist2)
                : 0.0f;
  if (has_rev)
    p->eye_ratio = mis_ratio_leave(
        p->eye_ratio, delta_here ? 1.0f : pt_light_density(f, p, wi, wo, dist2), delta_here);
}
