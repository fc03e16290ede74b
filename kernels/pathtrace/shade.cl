// pt_shade: one work-item per live path (the bounce's queue). Reads the path and its hit; adds
// emission (MIS-weighted against next-event estimation) to the sample's radiance, writes a shadow
// ray for next-event estimation, samples the BSDF for the next ray and applies Russian roulette.
// With paths_per_pixel = C > 0 (--eye-paths), the eye path's ends on a light are weighted against
// the reuse connections that make the same paths too (shared/eye_paths.h): the path keeps the
// ratio of the two ways' densities of its vertices beyond x_1 as it goes (mis_ratio_*, and every
// weight here from shared/mis.h).
// With paths_per_pixel > 0, x_1 (the first non-delta vertex) is written to the sample's EyeVertex
// for connect. Writes the PathState, the radiance and the ShadowRay of the same index, and appends
// the path to next_queue if it goes on and to shadow_queue if it has a shadow ray (their order
// varies from run to run; what each path computes does not: its random numbers are keyed by its
// pixel and sample).
#include "shared/eye_paths.h"
#include "shared/reuse.h"
#include "shared/path_state.h"
#include "shared/resample.h"
#include "shared/resample_direct.h"

// L's density of the path over that of the eye path's vertices beyond x_1 (eye_ratio holds
// the rest), for a path ending at x_t on light l (normal n_tri, start density `start`) at z0,
// with cos_x = |cos| at x_t and rev = the light-tracing density of x_{t-1} from x_t (1 at t = 2);
// C = paths_per_pixel samples of L against eye_count of the eye path.
PR_INLINE float eye_paths_light_side(const Light* l, float3 n_tri, float start, u32 paths_per_pixel,
                                     float eye_count, float eye_ratio, float3 z0, float3 xt,
                                     float cos_x, float rev) {
  const float3 d = xt - z0;
  const float d2 = dot(d, d);
  return (float)paths_per_pixel / eye_count * start *
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
  if (dens_l > 0.0f) w *= eye_paths_eye_share(dens_n / dens_l, dens_h / dens_l, ew->t);
  ew->n = dens_n;
  ew->h = dens_h;
  ew->l = dens_l;
  return w;
}

// Whether the connections can make the paths that end after this path's last vertex x_t: x_2 is
// non-delta and t >= x_1's depth + beyond.
PR_INLINE int pt_joinable(const PathState* p, u32 paths_per_pixel, u32 beyond) {
  return paths_per_pixel > 0u && (p->eye_flags & PR_EYE_JOINABLE) &&
         p->depth >= p->x1_depth + beyond;
}

// The weight of emission found at h along d (dist2 from the previous vertex): against next-event
// estimation, and where the connections can make the path too (joinable), times their share;
// its parts into *ew.
PR_INLINE float pt_emission_weight(const SceneData* s, const PathState* p, const SurfaceHit* h,
                                   float3 d, float dist2, int joinable, u32 paths_per_pixel,
                                   float eye_count, __global const float* trace_cdf,
                                   float trace_total, u32 max_depth, EyeWeight* ew) {
  const float3 prev = make_float3(p->prev_x, p->prev_y, p->prev_z);
  const float3 prev_n = make_float3(p->prev_nx, p->prev_ny, p->prev_nz);
  float w = 1.0f;
  if (!(p->flags & PR_PATH_SPECULAR))
    w = power_heuristic(p->last_pdf, emitter_pdf(s, h, prev, prev_n));
  ew->pt = w;
  ew->n = ew->h = ew->l = ew->t = 0.0f;
  // Strategy T: x_1 .. x_t before the light, t = p->depth; its ratio was fixed at x_2.
  ew->t_len = eye_paths_camera_len(p->depth, max_depth);
  const u32 li = joinable ? emitter_light(s, h) : PR_INVALID_INDEX;
  if (li != PR_INVALID_INDEX) {
    // The connections' share of the path (eye_paths.h); the eye path's N and H split the rest.
    const Light l = s->lights.lights[li];
    const float3 n_tri = eye_paths_light_normal(s, &l);
    const float start = eye_paths_start_density(&l, li, trace_cdf, trace_total);
    const int spec = (p->flags & PR_PATH_SPECULAR) != 0u;
    const float dens_h =
        spec ? 1.0f : solid_angle_to_area_pdf(p->last_pdf, fabs(dot(n_tri, d)), dist2);
    const float dens_l = eye_paths_light_side(&l, n_tri, start, paths_per_pixel, eye_count,
                                              p->eye_ratio, h->p, prev, p->seg_cos, 1.0f);
    w = pt_eye_share(p, w, spec ? 0.0f : start, dens_h, dens_l, ew);
  }
  return w;
}

// The weight of a next-event sample at vertex h: the power heuristic against BSDF sampling,
// times, where h is joinable, what the connections leave of the path; its parts into *ew.
PR_INLINE float pt_next_event_weight(const SceneData* s, const PathState* p, const SurfaceHit* h,
                                     const ShadingFrame* f, const NextEventChoice* ch, int joinable,
                                     int has_rev, float dist2, u32 paths_per_pixel, float eye_count,
                                     __global const float* trace_cdf, float trace_total,
                                     u32 max_depth, EyeWeight* ew) {
  float w = ch->delta ? 1.0f : power_heuristic(ch->pdf_light, ch->pdf_bsdf);
  ew->pt = w;
  ew->n = ew->h = ew->l = ew->t = 0.0f;
  ew->t_len = eye_paths_camera_len(p->depth, max_depth);  // x_1 .. x_t, t = p->depth
  if (!joinable) return w;  // the plain path tracer: no light record to read
  const Light l = s->lights.lights[ch->light];
  if (eye_paths_light(&l)) {
    const float3 n_tri =
        light_is_triangle(l.type) ? eye_paths_light_normal(s, &l) : make_float3(0.0f, 0.0f, 1.0f);
    const float3 dz = ch->pos - h->p;
    const float dz2 = dot(dz, dz);
    const float3 wi = dz * (1.0f / sqrt(dz2));
    // The environment's direction is z_0: its densities per solid angle.
    const float dens_n = eye_paths_start_density(&l, ch->light, trace_cdf, trace_total) *
                         eye_paths_direction_density(&l, s->lights.env, ch->wi);
    const float dens_h = light_is_triangle(l.type)
                             ? solid_angle_to_area_pdf(ch->pdf_bsdf, fabs(dot(n_tri, wi)), dz2)
                         : eye_paths_light_hit(&l) ? ch->pdf_bsdf
                                                   : 0.0f;
    const float rev = has_rev ? solid_angle_to_area_pdf(ch->pdf_bsdf_rev, p->seg_cos, dist2) : 1.0f;
    const float dens_l =
        eye_paths_light_side(&l, n_tri, dens_n, paths_per_pixel, eye_count, p->eye_ratio, ch->pos,
                             h->p, fabs(dot(f->ng, wi)), rev);
    // T's ratio: at x_2 from the light's pdf of the step to x_1 (x_1's camera factor in p->lt),
    // beyond x_2 as fixed there.
    if (p->x1_depth == 1u && ew->t_len)
      ew->t = p->depth == 2u ? eye_paths_camera_ratio(p->lt, ch->pdf_bsdf_rev, dist2) : p->lt;
    if (dens_l > 0.0f) w *= eye_paths_eye_share(dens_n / dens_l, dens_h / dens_l, ew->t);
    ew->n = dens_n;
    ew->h = dens_h;
    ew->l = dens_l;
  }
  return w;
}

// --resample, at a hit `rel` vertices beyond x_1 (2 and on: x_3 ...) or, escaped along d
// (escaped), from the vertex `rel` - 1 beyond it: the path's end on an emitter (le, weighted
// ew->pt by the path tracer and with ew's share against the connections, pdf_light its light
// pdf) offered to the pixel's reservoir.
PR_INLINE void rs_offer_emission(PR_GLOBAL const PathTrack* t, PR_GLOBAL PathReservoir* r,
                                 const PathState* p, uint rel, float3 le, const EyeWeight* ew,
                                 float pdf_light, int escaped, float3 d, const RsKey* key) {
  const int t2 = rel == 2u && !(p->flags & PR_PATH_SPECULAR);
  const float3 rest = make_float3(t->rest_r, t->rest_g, t->rest_b) * le * (t2 ? 1.0f : ew->pt);
  PathReservoir c;
  rs_candidate(&c, t, make_float3(t->f2_r, t->f2_g, t->f2_b), make_float3(t->wx, t->wy, t->wz),
               t->g_src, rest, t->pdf, t2 ? PR_RS_HIT2 : PR_RS_DEEP, pdf_light, p->last_pdf, ew,
               rel == 2u);
  if (escaped) rs_suffix_push(&c.suffix, c.sp, d, 1);
  rs_offer_keyed(r, &c, key, PR_RS_DIM(p->depth + 1u, 0u));
}

// --resample, after the BSDF step at vertex `rel` beyond x_1 (0: x_1; 1: x_2, surface h in frame
// f, reached along -wo at squared distance dist2): the tracked path goes on along `step`; q the
// roulette's survival probability (1: none).
PR_INLINE void rs_track_step(PR_GLOBAL PathTrack* t, const ResampleParams* rsp, uint rel,
                             const SurfaceHit* h, const ShadingFrame* f, float3 wo, float dist2,
                             const PathStep* step, float q) {
  const float pdf = step->delta ? 1.0f : step->pdf;
  const float3 fc = step->weight * pdf;
  if (rel == 0u) {
    t->x1_ok = rs_rough(&f->bsdf, rsp->min_alpha) && dot(step->wi, f->ng) > 0.0f;
    t->f1_r = fc.x;
    t->f1_g = fc.y;
    t->f1_b = fc.z;
    t->pdf = pdf * q;
    return;
  }
  if (rel == 1u) {
    t->f2_r = fc.x;
    t->f2_g = fc.y;
    t->f2_b = fc.z;
    t->wx = step->wi.x;
    t->wy = step->wi.y;
    t->wz = step->wi.z;
    t->rest_r = t->rest_g = t->rest_b = 1.0f;
    t->pdf2 = pdf;
    t->g_src = !step->delta && rs_reconnectable(t->x1_ok, h, f, wo, dist2, step->wi, rsp)
                   ? fabs(dot(h->ng, wo)) / dist2
                   : 0.0f;
  } else {
    t->rest_r *= fc.x;
    t->rest_g *= fc.y;
    t->rest_b *= fc.z;
  }
  t->pdf *= pdf * q;
}

// --resample: next-event estimation's path at vertex `rel` >= 1 beyond x_1, the candidate for
// pt_shadow to offer if its shadow ray is unoccluded, into *c. The light's point (at_infinity: its
// direction) ends the path's suffix.
PR_INLINE void rs_next_event(PathReservoir* c, PR_GLOBAL const PathTrack* t,
                             const ResampleParams* rsp, uint rel, const SurfaceHit* h,
                             const ShadingFrame* f, float3 wo, float dist2,
                             const NextEventChoice* ch, int at_infinity, const EyeWeight* ew) {
  if (rel == 1u) {
    const float g = rs_reconnectable(t->x1_ok, h, f, wo, dist2, ch->wi, rsp)
                        ? fabs(dot(h->ng, wo)) / dist2
                        : 0.0f;
    rs_candidate(c, t, ch->fr_cos, ch->wi, g, ch->le, t->pdf * ch->pdf,
                 ch->delta ? PR_RS_DEEP : PR_RS_NEE2, ch->pdf_light, ch->pdf_bsdf, ew, 1);
  } else {
    const float3 rest = make_float3(t->rest_r, t->rest_g, t->rest_b) * ch->fr_cos * ch->le * ew->pt;
    rs_candidate(c, t, make_float3(t->f2_r, t->f2_g, t->f2_b), make_float3(t->wx, t->wy, t->wz),
                 t->g_src, rest, t->pdf * ch->pdf, PR_RS_DEEP, 0.0f, 0.0f, ew, 0);
  }
  rs_suffix_push(&c->suffix, c->sp, at_infinity ? ch->wi : ch->pos, at_infinity);
}

// --resample: next-event estimation (contribution c) at path p's vertex h, to a reservoir once
// pt_shadow finds it unoccluded: at x_1 the direct light's, from x_2 on the paths'. Its candidate
// goes into *di_pending or *pending, and the shadow ray's op is returned (1 + the random
// dimension that offers it, PR_RS_OP_DIRECT for the direct light; 0: into the radiance).
PR_INLINE uint rs_next_event_pending(const SceneData* s, PR_GLOBAL const PathTrack* t,
                                     PR_GLOBAL PathReservoir* pending,
                                     PR_GLOBAL DirectReservoir* di_pending,
                                     const ResampleParams* rsp, const PathState* p,
                                     const SurfaceHit* h, const ShadingFrame* f, float3 wo,
                                     float dist2, const NextEventChoice* ch, float3 c,
                                     const EyeWeight* ew) {
  if (!rsp->enabled || !p->x1_depth) return 0u;
  const uint depth = p->depth, rel = depth - p->x1_depth;
  if (rel == 0u) return di_next_event_pending(s, di_pending, ch, c, PR_RS_DIM(depth, 1u));
  PathReservoir cand;
  rs_next_event(&cand, t, rsp, rel, h, f, wo, dist2, ch,
                light_at_infinity(s->lights.lights[ch->light].type), ew);
  *pending = cand;
  return PR_RS_DIM(depth, 1u) + 1u;
}

// A contribution as the radiance buffer holds it.
PR_INLINE float4 pt_rgb(float3 c) {
  return (float4)(c.x, c.y, c.z, 0.0f);
}

// The weight of the environment found along d (escaped), pdf_light next-event estimation's
// density of d: against next-event estimation, and where the connections can make the path
// (joinable), times their share (the environment's direction is z_0: N's density of it and
// H's per solid angle, L's of z_1 from the disk); its parts into *ew.
PR_INLINE float pt_escape_weight(const SceneData* s, const PathState* p, float3 d, float pdf_light,
                                 int joinable, u32 paths_per_pixel, float eye_count,
                                 __global const float* trace_cdf, float trace_total, u32 max_depth,
                                 EyeWeight* ew) {
  const int spec = (p->flags & PR_PATH_SPECULAR) != 0u;
  float w = spec ? 1.0f : power_heuristic(p->last_pdf, pdf_light);
  ew->pt = w;
  ew->n = ew->h = ew->l = ew->t = 0.0f;
  ew->t_len = eye_paths_camera_len(p->depth, max_depth);
  const u32 li = s->lights.env_light;
  if (joinable && li != PR_INVALID_INDEX) {
    const Light l = s->lights.lights[li];
    const float3 prev = make_float3(p->prev_x, p->prev_y, p->prev_z);
    const float start = eye_paths_start_density(&l, li, trace_cdf, trace_total) *
                        eye_paths_direction_density(&l, s->lights.env, d);
    const float dens_h = spec ? 1.0f : p->last_pdf;
    const float dens_l =
        eye_paths_light_side(&l, make_float3(0.0f, 0.0f, 1.0f), start, paths_per_pixel, eye_count,
                             p->eye_ratio, prev - d, prev, p->seg_cos, 1.0f);
    w = pt_eye_share(p, w, spec ? 0.0f : start, dens_h, dens_l, ew);
  }
  return w;
}

// The path escaped: the environment's light (weighted as pt_escape_weight says) into the
// sample's radiance, or with --resample from x_1 (rel 1) to the direct light's reservoir and
// from x_2 on (rel >= 2) to the paths'.
PR_INLINE void pt_escape(const SceneData* s, const PathState* p, uint rel, int joinable,
                         u32 paths_per_pixel, float eye_count, __global const float* trace_cdf,
                         float trace_total, u32 max_depth, __global const PathTrack* track,
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
  const float w = pt_escape_weight(s, p, d, pdf_light, joinable, paths_per_pixel, eye_count,
                                   trace_cdf, trace_total, max_depth, &ew);
  if (rel == 1u &&
      di_offer_hit(s, p, track, s->lights.env_light, 0.0f, 0.0f, d, le, 1.0f, w, di, key))
    return;
  if (rel < 2u) {
    *radiance += pt_rgb(make_float3(p->tp_r, p->tp_g, p->tp_b) * le * w);
    return;
  }
  rs_offer_emission(track, res, p, rel, le, &ew, pdf_light, 1, d, key);
}

// Emission at h (reached along d at squared distance dist2), weighted w by the path tracer (ew:
// its parts), into the sample's radiance, or with --resample at x_2 (rel 1) to the direct light's
// reservoir and from x_3 on (rel >= 2) to the paths'.
PR_INLINE void pt_emission(const SceneData* s, const PathState* p, const SurfaceHit* h, uint rel,
                           float3 d, float dist2, float w, const EyeWeight* ew, float3 tp,
                           __global const PathTrack* track, __global PathReservoir* res,
                           __global DirectReservoir* di, const RsKey* key,
                           __global float4* radiance) {
  const float3 le = surface_emission(s, h);
  if (rel == 1u && di_offer_hit(s, p, track, emitter_light(s, h), h->b1, h->b2, d, le,
                                fabs(dot(h->ng, d)) / dist2, w, di, key))
    return;
  if (rel < 2u) {
    *radiance += pt_rgb(tp * le * w);
    return;
  }
  const float pdf_light = emitter_pdf(s, h, make_float3(p->prev_x, p->prev_y, p->prev_z),
                                      make_float3(p->prev_nx, p->prev_ny, p->prev_nz));
  rs_offer_emission(track, res, p, rel, le, ew, pdf_light, 0, h->p, key);
}

// --resample: the hit `rel` >= 1 vertices beyond x_1 (at p) joins the tracked path, with the
// transmittance tr of the segment to it.
PR_INLINE void rs_track_hit(__global PathTrack* t, uint rel, const Hit* hit, float3 p, float3 tr,
                            float p2) {
  if (rel == 1u) {  // x_2, p2 its density per unit area from x_1
    t->p2 = p2;
    t->prim = hit->prim;
    t->inst = hit->inst;
    t->b1 = hit->u;
    t->b2 = hit->v;
    t->f1_r *= tr.x;
    t->f1_g *= tr.y;
    t->f1_b *= tr.z;
    t->suffix = 0u;
  } else {
    t->rest_r *= tr.x;
    t->rest_g *= tr.y;
    t->rest_b *= tr.z;
    rs_track_push(t, p, hit->inst != PR_INVALID_INDEX);
  }
}

// --eye-paths: the eye path's density of this vertex x_t (t >= 2; 1 when sampled from a delta
// vertex) into its running ratio, and whether x_2 is joinable.
PR_INLINE void pt_eye_arrive(PathState* p, const SurfaceHit* h, float3 d, float dist2,
                             int delta_here) {
  if (p->depth == p->x1_depth + 1u) p->eye_flags = delta_here ? 0u : PR_EYE_JOINABLE;
  p->eye_ratio = mis_ratio_arrive(p->eye_ratio,
                                  solid_angle_to_area_pdf(p->last_pdf, fabs(dot(h->ng, d)), dist2),
                                  (p->flags & PR_PATH_SPECULAR) != 0u);
}

PR_INLINE void pt_write_eye(__global EyeVertex* out, const SurfaceHit* h, const Hit* hit, float3 wo,
                            float3 tp, uint depth) {
  EyeVertex e;
  eye_vertex_set(&e, h, hit, wo, tp, depth);
  *out = e;
}

// Strategy T: leaving x_2 (of an x_1 seen straight from the camera) along wi, T's density over
// L's for the vertices beyond, from the light tracer's pdf of the step from x_2 to x_1.
PR_INLINE void pt_camera_leave(PathState* p, const ShadingFrame* f, float3 wi, float3 wo,
                               float dist2, float lt_scale) {
  if (!(lt_scale > 0.0f) || p->x1_depth != 1u || p->depth != 2u) return;
  p->lt = (p->eye_flags & PR_EYE_JOINABLE)
              ? eye_paths_camera_ratio(p->lt, eye_paths_bsdf_pdf(f, wi, wo), dist2)
              : 0.0f;
}

// The eye path's bookkeeping at a vertex (--eye-paths or --resample): its first non-delta vertex
// becomes x_1, the eye vertex that connect joins to the stored light paths (and, resampling, the
// vertex pt_resample reconnects from); p->lt, cos^3 of the camera ray's angle until now, becomes
// its camera factor for strategy T. Later vertices carry the eye path's densities for the MIS
// weights against the connections.
PR_INLINE void pt_eye_vertex(PathState* p, const SurfaceHit* h, const Hit* hit, float3 d,
                             float dist2, float3 tp, int delta_here, u32 paths_per_pixel,
                             uint max_depth, float lt_scale, __global EyeVertex* eye) {
  if (p->x1_depth == 0u) {
    if (!delta_here && p->depth < max_depth) {
      p->x1_depth = p->depth;
      p->lt = p->depth == 1u ? eye_paths_camera_factor(lt_scale, p->lt * dist2) : 0.0f;
      pt_write_eye(eye, h, hit, -d, tp, p->depth);
    }
  } else if (paths_per_pixel > 0u) {
    pt_eye_arrive(p, h, d, dist2, delta_here);
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
  const SceneData s = PR_SCENE();
  const uint k = i - base;  // the path's own state in the band; the frame's at pixel i
  PathState p = states[k];
  uint out = 0u;

  // --resample: the vertex this hit is, counted from x_1 (0: x_1 not met yet); the paths that
  // reach an emitter from x_2 on go to the pixel's reservoir instead of its radiance.
  const uint rel = rsp.enabled && p.x1_depth ? p.depth + 1u - p.x1_depth : 0u;
  PR_GLOBAL PathTrack* track = rs_track + k;
  const RsKey key = {seed, frame, p.pixel, sample};
  const Hit hit = hits[k];
  if (hit.prim == PR_INVALID_INDEX) {
    pt_escape(&s, &p, rel, pt_joinable(&p, paths_per_pixel, 1u), paths_per_pixel, rsp.eye_count,
              trace_cdf, trace_total, max_depth, track, rs_res + i, di_res + i, &key, radiance + i);
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
  if (rel)
    rs_track_hit(track, rel, &hit, h.p, tr,
                 solid_angle_to_area_pdf(p.last_pdf, fabs(dot(h.ng, d)), dist2));
  // Connections can make the paths that end after x_t, t >= 2 (x_t: the vertex `ray` left).
  const int joinable = pt_joinable(&p, paths_per_pixel, 1u);

  if (s.sd.materials[h.material].flags & PR_MAT_EMISSIVE) {
    EyeWeight ew;
    const float w = pt_emission_weight(&s, &p, &h, d, dist2, joinable, paths_per_pixel,
                                       rsp.eye_count, trace_cdf, trace_total, max_depth, &ew);
    pt_emission(&s, &p, &h, rel, d, dist2, w, &ew, tp, track, rs_res + i, di_res + i, &key,
                radiance + i);
  }
  p.depth += 1u;
  const ShadingFrame f = shading_frame(&s, &h, wo);
  const int delta_here = bsdf_is_delta(&f.bsdf);
  if (paths_per_pixel > 0u || rsp.enabled)
    pt_eye_vertex(&p, &h, &hit, d, dist2, tp, delta_here, paths_per_pixel, max_depth, rsp.lt_scale,
                  eye + p.pixel);
  // x_t with t >= 3: the light tracer's density of x_{t-1}, reached from this vertex.
  const int has_rev = pt_joinable(&p, paths_per_pixel, 2u);
  if (p.depth >= max_depth) {
    p.alive = 0u;
  } else {
    if (!delta_here) {
      Ray shadow;
      float3 c;
      NextEventChoice ch;
      const int here_joinable = pt_joinable(&p, paths_per_pixel, 1u);
      if (next_event(&s, &h, &f, wo, !here_joinable, &rng, &shadow, &c, &ch)) {
        EyeWeight ew;
        const float w = pt_next_event_weight(&s, &p, &h, &f, &ch, here_joinable, has_rev, dist2,
                                             paths_per_pixel, rsp.eye_count, trace_cdf, trace_total,
                                             max_depth, &ew);
        if (here_joinable) c = c * w;  // next_event left the weight to this
        const uint op = rs_next_event_pending(&s, track, rs_pending + k, di_pending + k, &rsp, &p,
                                              &h, &f, wo, dist2, &ch, c, &ew);
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
      // From the third vertex on (the camera's throughput starts at 1).
      const float rr = rng_next(&rng);
      const float q = p.depth >= 3u ? fmin(max3(tp), 1.0f) : 1.0f;
      if (p.depth >= 3u && !russian_roulette(max3(tp), rr, &tp)) p.alive = 0u;
      if (rsp.enabled && p.x1_depth && p.alive)
        rs_track_step(track, &rsp, p.depth - p.x1_depth, &h, &f, wo, dist2, &step, q);
      pt_camera_leave(&p, &f, step.wi, wo, dist2, rsp.lt_scale);
      if (has_rev)  // x_{t-1}'s light-tracing density from here (1 where this is delta)
        p.eye_ratio = mis_ratio_leave(
            p.eye_ratio, delta_here ? 1.0f : pt_light_density(&f, &p, step.wi, wo, dist2),
            delta_here);
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
