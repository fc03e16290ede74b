// Direct light at x_1, resampled across pixels and frames (--resample; ReSTIR DI beside the paths'
// reservoir of shared/resample.h). A pixel sample's candidates are the path tracer's two ways to
// x_1's direct light, next-event estimation and the BSDF sample's emitter hit (or escape), each
// with its MIS weight against the other, so their resampling weights are the path tracer's
// luminances of the two terms. The reservoir keeps the light's point y as itself: moving it to
// another x_1 is the identity, with Jacobian 1, and the target there is di_eval's f with the
// shadow ray traced.
#pragma once

#include "shared/transport.h"
#include "shared/path_state.h"
#include "shared/resample.h"

PR_NAMESPACE_BEGIN

#define PR_RS_OP_DIRECT 0x80000000u  // a ShadowRay's op: its candidate is x_1's direct light

// Whether light li's direct light goes through the reservoir: an emissive glass triangle does not
// (a segment that ends on it from inside is attenuated, which the target leaves out), so both of
// its ways stay in the radiance and the reservoir's target is 0 there for every pixel.
PR_INLINE int di_light_ok(const SceneData* s, u32 li) {
  if (li == PR_INVALID_INDEX) return 0;
  const Light l = s->lights.lights[li];
  return !light_is_triangle(l.type) || !(s->sd.materials[l.material].flags & PR_MAT_GLASS);
}

PR_INLINE int di_has_light(PR_GLOBAL const DirectReservoir* r) {
  return r->light != PR_INVALID_INDEX && r->w_sum > 0.0f && r->p_hat > 0.0f;
}

// Reservoir r's light at x: its f there (0 where x does not face it) and the shadow ray to it.
PR_INLINE float3 di_eval(const SceneData* s, const RsPrimary* x, PR_GLOBAL const DirectReservoir* r,
                         Ray* shadow) {
  const float3 zero = make_float3(0.0f, 0.0f, 0.0f);
  if (r->light == PR_INVALID_INDEX) return zero;
  const Light l = s->lights.lights[r->light];
  float3 wi, le;
  float g = 1.0f, dist = PR_INF_F;
  if (light_is_triangle(l.type)) {
    const SurfaceHit e = surface_at(&s->sd, l.prim, l.inst, r->b1, r->b2);
    const float3 d = e.p - x->h.p;
    const float d2 = dot(d, d);
    if (!(d2 > 0.0f)) return zero;
    dist = sqrt(d2);
    wi = d * (1.0f / dist);
    g = fabs(dot(wi, e.ng)) / d2;
    le = material_emission(&s->sd, &e);
    *shadow = surface_ray_to(x->own, &x->h, e.p, e.ng);
  } else if (r->light == s->lights.env_light) {
    wi = make_float3(r->wx, r->wy, r->wz);
    le = environment_radiance(s, wi);
    *shadow = surface_ray(x->own, &x->h, wi, PR_INF_F);
  } else {  // punctual: the light's own sample, which draws no random number
    LightSample ls;
    float b1, b2;
    if (!light_sample_towards(&l, s->lights.env, 1.0f, x->h.p, frame_light_normal(&x->f), 0.0f,
                              0.0f, &ls, &b1, &b2))
      return zero;
    wi = ls.wi;
    le = ls.le;
    dist = ls.dist;
    *shadow =
        surface_ray(x->own, &x->h, ls.wi, ls.dist < PR_INF_F ? ls.dist * (1.0f - 1e-4f) : PR_INF_F);
  }
  if (!surface_side_ok(x->own, &x->h, &x->f, x->wo, wi)) return zero;
  const float3 wil = to_local(wi, x->f.t, x->f.b, x->f.n);
  float pdf;
  const float3 f = bsdf_eval(&x->f.bsdf, x->wol, wil, &pdf) * le * (fabs(wil.z) * g);
  return bsdf_transmits(&x->f.bsdf) ? f * segment_transmittance(x->own, &x->h, 0, wi, dist) : f;
}

// The target of reservoir r's light at x, shadow ray included (traced counted in *traced), and
// its f in *f.
PR_INLINE float di_target_at(const SceneData* s, const RsPrimary* x,
                             PR_GLOBAL const DirectReservoir* r, float3* f, uint* traced) {
  Ray shadow;
  *f = di_eval(s, x, r, &shadow);
  const float p = luminance(*f);
  if (!(p > 0.0f) || !(p < PR_INF_F)) return 0.0f;
  *traced += 1u;
  return rs_occluded(s, x, shadow) ? 0.0f : p;
}

// The segment from p to reservoir r's light: p + t d, 0 <= t <= tmax (a ray towards a light at
// infinity); 0 where a punctual light sends p nothing.
PR_INLINE int di_light_segment(const SceneData* s, PR_GLOBAL const DirectReservoir* r, float3 p,
                               float3* d, float* tmax) {
  const Light l = s->lights.lights[r->light];
  *tmax = 1.0f;
  if (light_is_triangle(l.type)) {
    *d = surface_at(&s->sd, l.prim, l.inst, r->b1, r->b2).p - p;
    return 1;
  }
  *tmax = PR_INF_F;
  if (r->light == s->lights.env_light) {
    *d = make_float3(r->wx, r->wy, r->wz);
    return 1;
  }
  LightSample ls;
  float b1, b2;
  if (!light_sample_towards(&l, s->lights.env, 1.0f, p, make_float3(0.0f, 0.0f, 0.0f), 0.0f, 0.0f,
                            &ls, &b1, &b2))
    return 0;
  *d = ls.wi;
  *tmax = ls.dist;
  return 1;
}

// Whether the segment from the previous frame's x_1 at x to reservoir r's light (a ray, towards a
// light at infinity) is seen in that frame by a shadow ray traced in this one (rs_occluded), as
// rs_reconnection_clear: from x itself where x did not move; else the segment of its shadow ray
// (di_eval's, which leaves x's shape of then), where x sees the light at all.
PR_INLINE int di_segment_clear(const SceneData* s, PR_GLOBAL const MovedInstance* moved, u32 count,
                               PR_GLOBAL const DirectReservoir* r, const RsPrimary* x) {
  if (x->then_moved) {
    Ray shadow;
    const float3 f = di_eval(s, x, r, &shadow);
    return luminance(f) > 0.0f && rs_clear_then(s, moved, count, shadow);
  }
  float3 d;
  float tmax;
  return di_light_segment(s, r, x->h.p, &d, &tmax) && rs_clear(s, moved, count, x->h.p, d, tmax);
}

// Whether reservoir r's light can be taken between frames, seen from x_1 at xa in one and at xb
// in the other: each x_1 where it may be (rs_x1_ok), and the previous frame's segment seen alike
// in both (di_segment_clear; this frame's is its shadow ray, traced now).
PR_INLINE int di_temporal_ok(const SceneData* s, PR_GLOBAL const MovedInstance* moved, u32 count,
                             PR_GLOBAL const DirectReservoir* r, const RsPrimary* pa,
                             const RsPrimary* pb, u32 prev_known) {
  if (r->light == PR_INVALID_INDEX || !rs_x1_ok(s, pa, prev_known) || !rs_x1_ok(s, pb, prev_known))
    return 0;
  return di_segment_clear(s, moved, count, r, pa);
}

// Under a shutter (shared/resample.h, RsSweeps): whether reservoir r's light is where it is at
// every time of the sweeps' intervals, so that moving it to an x_1 at another time is the
// identity: a triangle's point in no sweep, a punctual light's position in none, a light at
// infinity other than the environment in no sweep over all space (a turning sun's); with from (a
// previous x_1), the segment from it to the light meeting none either.
PR_INLINE int di_still(const SceneData* s, const RsSweeps* w, int past,
                       PR_GLOBAL const DirectReservoir* r, int has_from, float3 from) {
  if (rs_sweeps_none(w, past)) return 1;
  const Light l = s->lights.lights[r->light];
  float3 y = make_float3(l.p0x, l.p0y, l.p0z);
  if (light_is_triangle(l.type))
    y = surface_at(&s->sd, l.prim, l.inst, r->b1, r->b2).p;
  else if (light_at_infinity(l.type))
    y = make_float3(PR_INF_F, PR_INF_F, PR_INF_F);  // in no bounded sweep
  if (r->light != s->lights.env_light &&
      !rs_sweeps_clear(w, past, y, make_float3(0.0f, 0.0f, 0.0f), 0.0f))
    return 0;
  float3 d;
  float tmax;
  return !has_from ||
         (di_light_segment(s, r, from, &d, &tmax) && rs_sweeps_clear(w, past, from, d, tmax));
}

// A candidate into *c: light li at (b1, b2) or along dir, its f at its own x_1, resampling
// weight w.
PR_INLINE void di_candidate(DirectReservoir* c, u32 li, float b1, float b2, float3 dir, float3 f,
                            float w) {
  c->light = li;
  c->b1 = b1;
  c->b2 = b2;
  c->wx = dir.x;
  c->wy = dir.y;
  c->wz = dir.z;
  c->f_r = f.x;
  c->f_g = f.y;
  c->f_b = f.z;
  c->p_hat = luminance(f);
  c->w_sum = c->p_hat > 0.0f ? w : 0.0f;
  c->m = 1.0f;
}

// Offers candidate c (its resampling weight in c->w_sum) to reservoir r, with u drawn from
// dimension dim of key k.
PR_INLINE void di_offer_keyed(PR_GLOBAL DirectReservoir* r, const DirectReservoir* c,
                              const RsKey* k, u32 dim) {
  const float w = c->w_sum;
  if (!(w > 0.0f) || !(w < PR_INF_F)) return;
  Rng rr = rng_make(k->seed, PR_RNG_PATH_RESAMPLE, k->frame, k->pixel, k->sample);
  rr.dim = dim;
  const float sum = r->w_sum + w;
  if (ris_accept(rng_next(&rr), sum, w)) *r = *c;
  r->w_sum = sum;
}

// Next-event estimation at x_1 (choice ch, contribution c before the path's throughput, dim its
// shadow ray's random dimension): the candidate for pt_shadow to offer if the ray is unoccluded,
// into *pending, and the ray's op (0: into the radiance).
PR_INLINE uint di_next_event_pending(const SceneData* s, PR_GLOBAL DirectReservoir* pending,
                                     const NextEventChoice* ch, float3 c, u32 dim) {
  if (!di_light_ok(s, ch->light)) return 0u;
  DirectReservoir d;
  di_candidate(&d, ch->light, ch->b1, ch->b2, ch->wi, ch->fr_cos * ch->le * ch->g, luminance(c));
  *pending = d;
  return (dim + 1u) | PR_RS_OP_DIRECT;
}

// The BSDF sample at x_1 (tracked in t) met light li at barycentrics (b1, b2) or, escaping, the
// environment along d, with radiance le, g its geometry term (1: at infinity) and w the path
// tracer's MIS weight: the candidate, offered to r. 0 where it is not the reservoir's (a delta
// lobe at x_1, a light outside the table or not di_light_ok): the caller adds it to the radiance.
PR_INLINE int di_offer_hit(const SceneData* s, const PathState* p, PR_GLOBAL const PathTrack* t,
                           u32 li, float b1, float b2, float3 d, float3 le, float g, float w,
                           PR_GLOBAL DirectReservoir* r, const RsKey* key) {
  if ((p->flags & PR_PATH_SPECULAR) || !di_light_ok(s, li) || !(t->pdf > 0.0f)) return 0;
  const float3 f = make_float3(t->f1_r, t->f1_g, t->f1_b) * le;  // in solid angle at x_1
  DirectReservoir c;
  di_candidate(&c, li, b1, b2, d, f * g, w * luminance(f) / t->pdf);
  di_offer_keyed(r, &c, key, PR_RS_DIM(p->depth + 1u, 0u));
  return 1;
}

// The kept light k as this pixel's, into out: its f and target here, the reservoir's sum of
// weights and confidence.
PR_INLINE void di_keep(PR_GLOBAL DirectReservoir* out, PR_GLOBAL const DirectReservoir* k, float3 f,
                       float p, float w_sum, float m) {
  *out = *k;
  out->f_r = f.x;
  out->f_g = f.y;
  out->f_b = f.z;
  out->p_hat = p;
  out->w_sum = w_sum;
  out->m = m;
}

PR_NAMESPACE_END
