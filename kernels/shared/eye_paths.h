// --eye-paths (docs/design.md section 5, "Eye paths"): the path tracer's eye paths and the
// reuse connections make the same paths. L (the first non-delta eye vertex x_1 joined to the
// stored light vertex z_k) takes its power-heuristic share (mis_power_share) against N (the eye
// path's next-event estimation) and H (its BSDF sample meets the emitter), and the eye path the
// rest, split between N and H by the path tracer's own power heuristic. Each strategy's density of
// a path is the product of the densities (per unit area) of the vertices it samples beyond x_1,
// with C light paths per camera sample counted in L's; a density sampled from a delta vertex
// counts as 1 on both sides. N's choice of z_0 is counted as the light tracer's (its power
// table, uniform on the triangle), and Russian roulette is left out: any share that both sides
// compute alike keeps the estimate unbiased, and this one needs no light-tree walk in connect.
// These helpers are what connect (kernels/reuse) and pt_shade (kernels/pathtrace) share; the
// densities are gathered and weighed by the functions of shared/mis.h.
#pragma once

#include "shared/arena.h"
#include "shared/transport.h"
#include "shared/mis.h"

PR_NAMESPACE_BEGIN

// The lights whose stored paths take part: all (light_in_eye_paths).
PR_INLINE int eye_paths_light(const Light* l) {
  return light_in_eye_paths(l->type);
}

// The unit normal of an emissive triangle light, from the light table.
PR_INLINE float3 eye_paths_light_normal(const SceneData* s, const Light* l) {
  float3 v0, e1, e2;
  triangle_world(&s->sd, l->prim, l->inst, &v0, &e1, &e2);
  return normalize(cross(e1, e2));
}

// The density with which the light tracer starts on light li at a point: its power table's
// pmf, over the area for triangles (0 without a table).
PR_INLINE float eye_paths_start_density(const Light* l, u32 li, PR_GLOBAL const float* trace_cdf,
                                        float trace_total) {
  if (!(trace_total > 0.0f)) return 0.0f;
  const float pmf = (trace_cdf[li] - (li > 0u ? trace_cdf[li - 1u] : 0.0f)) / trace_total;
  return light_is_triangle(l->type) ? pmf / l->area : pmf;
}

// The environment's density of z_0, the direction wi towards it, as next-event estimation and
// the light tracer sample it (its map's pdf; the choice of the light is eye_paths_start_density);
// 1 for the other lights.
PR_INLINE float eye_paths_direction_density(const Light* l, PR_GLOBAL const float* env, float3 wi) {
  if (!light_at_infinity(l->type) || light_is_delta(l->type)) return 1.0f;
  return env_pdf(l, env, wi);
}

// Whether the eye path's BSDF sample can meet the light (strategy H): a triangle or the
// environment; a point, a spot or a direction never.
PR_INLINE int eye_paths_light_hit(const Light* l) {
  return !light_is_delta(l->type);
}

// The density at a point (|cos| cos_x of its geometric normal with the segment, squared
// distance d2) of the light tracer's first step from z0 along dir. A directional light's paths
// and the environment's leave a disk of area l->disk_area across their direction: per unit area
// at the point, the disk's density projected, cos_x / disk_area (the environment's density of
// the direction is z_0's: eye_paths_direction_density).
PR_INLINE float eye_paths_emit_density(const Light* l, float3 n_tri, float3 dir, float cos_x,
                                       float d2) {
  if (light_at_infinity(l->type)) return cos_x / l->disk_area;
  return solid_angle_to_area_pdf(light_pdf_emit_dir(l, n_tri, dir), cos_x, d2);
}

// The solid-angle pdf with which the BSDF in frame f, sampled from wo, gives wi (0 if delta).
PR_INLINE float eye_paths_bsdf_pdf(const ShadingFrame* f, float3 wo, float3 wi) {
  float pdf = 0.0f;
  bsdf_eval(&f->bsdf, to_local(wo, f->t, f->b, f->n), to_local(wi, f->t, f->b, f->n), &pdf);
  return pdf;
}

// The light side of L's weight, gathered by light_trace as it traces a path (z_0 on the light,
// z_k the vertex reached) and kept per vertex in an EyePathRatio: with E = the eye's density of
// z_k sampled from x_1, over C, and rev = z_k's pdf of sampling z_{k-1} arriving from x_1, N's
// density of the path over L's is E x n (k = 1) or E x rev x n (k >= 2), and H's E x rev x h
// (eye_path_weight).
typedef struct {
  Light light;
  int tri;          // a triangle light
  int hits;         // H can reach z_0 (a triangle or the environment)
  float inv_start;  // 1 / the light tracer's density of z_0
  MisChain chain;   // fwd: its densities of z_1 .. z_k; rev: the eye's of z_1 .. z_{k-2}
  float hit;        // the eye's density of z_0 sampled from z_1 arriving from z_2 (1: z_1 delta)
  float pdf_next;   // solid-angle pdf of the light tracer's step from z_k
  float g;          // |cos| at z_{k-1} over the squared distance to z_k (z_0: the triangle's)
  int z1_delta, delta_k;
  float3 n_tri;    // the light triangle's normal
  float3 ng_prev;  // geometric normal of z_{k-1}, then (after arriving) of z_k
} EyePathWalk;

// The walk of a path that starts on light l (index li, triangle normal n_tri), z_0's direction
// density dir_density (eye_paths_direction_density; 1 but for the environment).
PR_INLINE EyePathWalk eye_path_walk_start(const Light* l, u32 li, float3 n_tri,
                                          PR_GLOBAL const float* trace_cdf, float trace_total,
                                          float dir_density) {
  EyePathWalk w;
  w.light = *l;
  w.tri = light_is_triangle(l->type);
  w.hits = eye_paths_light_hit(l);
  w.inv_start = 1.0f / (eye_paths_start_density(l, li, trace_cdf, trace_total) * dir_density);
  w.chain = mis_chain_start();
  w.hit = 1.0f;
  w.pdf_next = w.g = 0.0f;
  w.z1_delta = w.delta_k = 0;
  w.n_tri = w.ng_prev = n_tri;
  return w;
}

// Arriving at z_k (k >= 1) along unit dir at distance t, its geometric normal ng: the ratios
// kept for it.
PR_INLINE EyePathRatio eye_path_walk_arrive(EyePathWalk* w, u32 k, float3 dir, float t, float3 ng) {
  const float t2 = t * t, cos_k = fabs(dot(ng, dir));
  // z_k's density: from the light (z_0 is never delta), else the step from z_{k-1}.
  const float fwd = k == 1u ? eye_paths_emit_density(&w->light, w->n_tri, dir, cos_k, t2)
                            : solid_angle_to_area_pdf(w->pdf_next, cos_k, t2);
  mis_chain_arrive(&w->chain, fwd, w->delta_k);
  // H's density of z_0 from z_1 per unit area on a triangle, per solid angle for the
  // environment (its direction is z_0).
  w->g = (k > 1u || w->tri) ? fabs(dot(w->ng_prev, dir)) / t2 : w->hits ? 1.0f : 0.0f;
  w->ng_prev = ng;
  EyePathRatio r;
  if (k == 1u) {
    r.n = 1.0f / w->chain.fwd;
    r.h = w->g * w->inv_start / w->chain.fwd;
  } else {
    const float a = w->g * w->chain.rev / w->chain.fwd;
    r.n = w->z1_delta ? 0.0f : a;  // no next-event estimation from a delta z_1
    r.h = a * w->hit * w->inv_start;
  }
  return r;
}

// Leaving z_k (delta or not) by the light tracer's step, whose pdf was pdf_fwd and that of the
// reverse step (towards z_{k-1}) pdf_rev.
PR_INLINE void eye_path_walk_leave(EyePathWalk* w, u32 k, int delta, float pdf_fwd, float pdf_rev) {
  // The eye's density of z_{k-1} sampled from z_k (g is 0 where z_0 is not a triangle).
  const float rev = area_pdf_g(pdf_rev, w->g);
  if (k == 1u) {
    w->z1_delta = delta;
    // H never hits a point, a spot or a direction.
    w->hit = w->hits ? mis_sampled(rev, delta) : 0.0f;
  } else {
    mis_chain_leave(&w->chain, rev, delta);
  }
  w->pdf_next = delta ? 0.0f : pdf_fwd;
  w->delta_k = delta;
}

// N's and H's densities of a path over L's (*n, *h), for L joining x_1 to z_k (stored ratios
// r): pdf_x is x_1's BSDF pdf towards z_k, cos_z the |cos| there with dist2 the squared
// distance, pdf_rev z_k's pdf of sampling z_{k-1} arriving from x_1, and inv_c 1 / C.
PR_INLINE void eye_path_ratios(EyePathRatio r, u32 k, float pdf_x, float cos_z, float dist2,
                               float pdf_rev, float inv_c, float* n, float* h) {
  const float e = solid_angle_to_area_pdf(pdf_x, cos_z, dist2) * inv_c;
  *n = e * (k == 1u ? 1.0f : pdf_rev) * r.n;
  *h = e * pdf_rev * r.h;
}

// --- Strategy T (--light-tracing) -----------------------------------------------------------
//
// camera_splat joins a stored vertex z_k (k >= 2, z_k and z_{k-1} non-delta) to the camera: the
// path's x_1 is z_k, seen straight from the camera, and every vertex beyond it came from the
// light. T takes its power share t^2 / (t^2 + 1 + n^2 + h^2) of such a path, with t, n and h its
// densities under T, N and H over L's; L and the eye path keep their shares of the rest. T's
// density over L's is N_L p(x_1 | x_2) / (spp C p_cam(x_1)): the light tracer's density of x_1
// from x_2 against the camera's (spp samples of each pixel, C light paths each). The |cos| at
// x_1 is in both, so t = x_1's camera factor lt_scale cos^3 d^2 (lt_scale = N_L A / (spp C W H),
// camera_cos3_d2) times pdf_w / |x_1 x_2|^2, pdf_w the light tracer's solid-angle pdf of the
// step from x_2 to x_1. A path of m vertices before the light is T's only where the arena holds
// z_m: m + 2 <= max_depth. Everything that weighs such a path computes t alike: pt_shade (N, H),
// connect (L), the resampled paths (rs_eye_share) and camera_splat.

// The camera factor of an x_1 seen straight from the camera (cos3_d2: camera_cos3_d2).
PR_INLINE float eye_paths_camera_factor(float lt_scale, float cos3_d2) {
  return lt_scale * cos3_d2;
}

// t, from x_1's camera factor, the light tracer's solid-angle pdf of the step from x_2 to x_1
// and the squared distance between them.
PR_INLINE float eye_paths_camera_ratio(float factor, float pdf_w, float dist2) {
  return factor * pdf_w / dist2;
}

// Whether a path of m vertices before the light can be T's (the arena's depth).
PR_INLINE int eye_paths_camera_len(u32 m, u32 max_depth) {
  return m + 2u <= max_depth;
}

// T's share of a path, from t, n and h (0 where t is not positive: T cannot make the path).
PR_INLINE float eye_paths_camera_share(float t, float n, float h) {
  if (!(t > 0.0f)) return 0.0f;
  const float r[3] = {1.0f / t, n / t, h / t};
  return mis_power_share_n(r, 3u);
}

// What T leaves of a share: 1 - its own (1 exactly where T cannot make the path).
PR_INLINE float eye_paths_camera_rest(float t, float n, float h) {
  return 1.0f - eye_paths_camera_share(t, n, h);
}

// L's weight for joining x_1 to z_k (as eye_path_ratios), with t T's density over L's.
PR_INLINE float eye_path_weight(EyePathRatio r, u32 k, float pdf_x, float cos_z, float dist2,
                                float pdf_rev, float inv_c, float t) {
  float n, h;
  eye_path_ratios(r, k, pdf_x, cos_z, dist2, pdf_rev, inv_c, &n, &h);
  return mis_power_share(n, h) * eye_paths_camera_rest(t, n, h);
}

// The eye path's share of a path that L makes too: what L and T leave of it.
PR_INLINE float eye_paths_eye_share(float n, float h, float t) {
  return (1.0f - mis_power_share(n, h)) * eye_paths_camera_rest(t, n, h);
}

// T's share of a path that L cannot make (under a shutter, a segment of L's light path meets what
// moves and x_1's segment from the camera does too, or the camera moves), against the eye path's N
// and H alone; l_ok 1: eye_paths_camera_share.
PR_INLINE float eye_paths_camera_share_l(float t, float n, float h, int l_ok) {
  if (l_ok) return eye_paths_camera_share(t, n, h);
  if (!(t > 0.0f)) return 0.0f;
  return mis_power_share(n / t, h / t);
}

// The eye path's share of a path that L makes too where l_ok, else of one that T alone makes too.
PR_INLINE float eye_paths_eye_share_l(float n, float h, float t, int l_ok) {
  if (l_ok) return eye_paths_eye_share(n, h, t);
  return 1.0f - eye_paths_camera_share_l(t, n, h, 0);
}

PR_NAMESPACE_END
