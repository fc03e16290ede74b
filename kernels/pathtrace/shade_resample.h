// pt_shade's hooks for path and direct-light resampling (PR_RESAMPLE, shared/techniques.h): from
// x_1 on, the eye path is tracked (PathTrack: its vertices x_1, x_2 and the suffix's points, its
// throughput split at x_2) so that what reaches a light from x_2 on is offered to the pixel's
// path reservoir, and what x_1 sees of a light to its direct-light reservoir (shared/resample.h,
// shared/resample_direct.h). rel counts a vertex from x_1 (0: x_1, 1: x_2, ...).
#pragma once

#include "shared/path_state.h"
#include "shared/resample.h"
#include "shared/resample_direct.h"
#include "shared/techniques.h"

// At a hit `rel` vertices beyond x_1 (2 and on: x_3 ...) or, escaped along d
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

// After the BSDF step at vertex `rel` beyond x_1 (0: x_1; 1: x_2, surface h in frame
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

// Next-event estimation's path at vertex `rel` >= 1 beyond x_1, the candidate for
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

// Next-event estimation (contribution c) at path p's vertex h, to a reservoir once
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
  if (!p->x1_depth) return 0u;
  const uint depth = p->depth, rel = depth - p->x1_depth;
  if (rel == 0u) return di_next_event_pending(s, di_pending, ch, c, PR_RS_DIM(depth, 1u));
  PathReservoir cand;
  rs_next_event(&cand, t, rsp, rel, h, f, wo, dist2, ch,
                light_at_infinity(s->lights.lights[ch->light].type), ew);
  *pending = cand;
  return PR_RS_DIM(depth, 1u) + 1u;
}

// The hit `rel` >= 1 vertices beyond x_1 (at p) joins the tracked path, with the
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
