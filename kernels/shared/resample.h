// Path resampling across pixels (--resample): the reconnection shift and the reservoirs' updates,
// shared by pt_shade and pt_shadow (which offer a path's candidates to its pixel's reservoir) and
// pt_resample (which takes the neighbours' paths by reconnection, with pairwise MIS).
//
// A path x_1 x_2 ... of pixel i moves to pixel j by keeping x_2 and everything beyond it and
// joining j's own x_1 to x_2 (ReSTIR GI, Ouyang et al. 2021; the reconnection shift of Lin et al.
// 2022). It may only where both ends of the new segment are rough and it is not too short, the
// same rule for the path and its image, so that a shift fails in one direction exactly where it
// fails in the other (rs_reconnectable). Its Jacobian in solid angle at x_1 is
// reconnection_jacobian (shared/mis.h).
#pragma once

#include "shared/arena.h"
#include "shared/camera.h"
#include "shared/eye_paths.h"
#include "shared/transport.h"
#include "shared/mis.h"
#include "shared/path_state.h"

PR_NAMESPACE_BEGIN

// Rough enough to reconnect at: no delta lobe and every GGX lobe's alpha at least min_alpha; not
// glass, whose reconnections would cross the surface (the shift keeps to reflections).
PR_INLINE int rs_rough(const BsdfParams* b, float min_alpha) {
  if (bsdf_is_delta(b) || bsdf_transmits(b)) return 0;
  if (!(fmin(b->alpha_x, b->alpha_y) >= min_alpha)) return 0;
  return !(b->coat > 0.0f) || b->coat_alpha >= min_alpha;
}

// wo is above h's shading normal's horizon on its own side by PR_MIN_VIEW_COS, so that the
// shading frame there does not depend on wo (shading_frame turns it otherwise).
PR_INLINE int rs_unbent(const SurfaceHit* h, float3 wo) {
  const float3 ns = dot(wo, h->ng) < 0.0f ? -h->ns : h->ns;
  return dot(wo, ns) >= PR_MIN_VIEW_COS;
}

// Whether x_2 (surface h2 in frame f2, the segment from x_1 arriving along -wo2 with squared
// length d2) can be a reconnection vertex for a path leaving it along w2, x_1's side being
// x1_ok (rough, and the segment leaves it above its geometric surface).
PR_INLINE int rs_reconnectable(int x1_ok, const SurfaceHit* h2, const ShadingFrame* f2, float3 wo2,
                               float d2, float3 w2, const ResampleParams* rp) {
  return x1_ok && d2 >= rp->min_dist2 && rs_rough(&f2->bsdf, rp->min_alpha) && rs_unbent(h2, wo2) &&
         dot(w2, f2->ng) > 0.0f && dot(wo2, f2->ng) > 0.0f;
}

// The MIS weight of a t = 2 path at x_2 against the other way of sampling its last segment.
PR_INLINE float rs_weight2(u32 kind, float pdf_light, float pdf_bsdf) {
  if ((kind & PR_RS_KIND_MASK) == PR_RS_NEE2) return power_heuristic(pdf_light, pdf_bsdf);
  if ((kind & PR_RS_KIND_MASK) == PR_RS_HIT2) return power_heuristic(pdf_bsdf, pdf_light);
  return 1.0f;
}

// --mode reuse: what the eye path keeps of a path that the connections to stored light paths
// (L) make too: the path tracer's weight `pt` and, with l > 0, the densities of the path beyond
// x_1 under next-event estimation (n), BSDF sampling (h) and L (l), in the ratios pt_shade
// weighs with (shared/eye_paths.h). l = 0: L does not make the path. t: T's density over L's
// (eye_paths_camera_ratio; 0: T does not make it); t_len: the path is short enough for T;
// l_ok: L makes it (under a shutter, none of its segments from x_2 on meets what moves), else
// its densities still give T's share, against the eye path's alone.
typedef struct {
  float pt, n, h, l, t;
  int t_len, l_ok;
} EyeWeight;

// The eye path's share of a PR_RS_JOINED path, what L and T leave of it, at an x_1 whose density
// of x_2 per unit area is p2, with x_2's solid-angle pdf of omega_2 pdf2 (from that x_1) and T's
// density over L's t there. Of N's and H's densities over L's, only these two factors depend on
// x_1: the eye path's density of x_2, and of x_3 where x_2 is not the last vertex (omega_2's pdf
// times the cosine and distance at x_3, which do not). So the path keeps its ratios with them
// divided out (rn, rh: rs_candidate) and this puts them back.
PR_INLINE float rs_eye_share(u32 kind, float rn, float rh, float p2, float pdf2, float t) {
  if (!(kind & PR_RS_JOINED)) return 1.0f;
  const float u = p2 * pdf2;
  const float n = rn * ((kind & PR_RS_LAST2) ? p2 : u), h = rh * u;
  return eye_paths_eye_share_l(n, h, t, !(kind & PR_RS_NO_L));
}

// A pixel sample's x_1, rebuilt from its EyeVertex; ok: rough enough to reconnect from; cam:
// its camera factor for strategy T (0: T cannot make its paths); own: the scene of its frame,
// whose shapes its rays leave from (the previous frame's for a previous x_1, which may lie on
// what moved since).
typedef struct {
  SurfaceHit h;
  ShadingFrame f;
  float3 wo, wol, tp;
  int ok;
  float cam;
  const SceneData* own;
  int then_moved;  // the previous frame's x_1 on what moved since (its segments: rs_occluded)
} RsPrimary;

// The x_1 of EyeVertex e in scene s, seen by camera c (an x_1 of the previous frame: depth 0,
// cam 0, and s that frame's shapes).
PR_INLINE RsPrimary rs_primary(const SceneData* s, const EyeVertex* e, const ResampleParams* rp,
                               const CameraParams* c) {
  RsPrimary x;
  x.own = s;
  x.then_moved = 0;
  x.h = surface_at(&s->sd, e->prim, e->inst, e->b1, e->b2);
  x.cam = e->depth == 1u && rp->lt_scale > 0.0f
              ? eye_paths_camera_factor(rp->lt_scale, camera_cos3_d2(c, x.h.p))
              : 0.0f;
  x.wo = make_float3(e->wx, e->wy, e->wz);
  x.f = shading_frame(s, &x.h, x.wo);
  x.wol = to_local(x.wo, x.f.t, x.f.b, x.f.n);
  x.tp = make_float3(e->tp_r, e->tp_g, e->tp_b);
  x.ok = rs_rough(&x.f.bsdf, rp->min_alpha);
  return x;
}

// Path r moved to x_1 = x by reconnection: its contribution f there (0 where the shift fails),
// *g_dst of the new segment and *seg its shadow ray (traced by the caller).
PR_INLINE float3 rs_shift(const SceneData* s, const RsPrimary* x, PR_GLOBAL const PathReservoir* r,
                          const ResampleParams* rp, float* g_dst, Ray* seg) {
  const float3 zero = make_float3(0.0f, 0.0f, 0.0f);
  *g_dst = 0.0f;
  if (r->prim == PR_INVALID_INDEX || !(r->g_src > 0.0f) || !x->ok) return zero;
  const SurfaceHit h2 = surface_at(&s->sd, r->prim, r->inst, r->b1, r->b2);
  const float3 d = h2.p - x->h.p;
  const float d2 = dot(d, d);
  if (!(d2 > 0.0f)) return zero;
  const float3 w1 = d * (1.0f / sqrt(d2));
  if (!(dot(w1, x->f.ng) > 0.0f)) return zero;  // x_1's side: above its surface
  const float3 wo2 = -w1;
  const ShadingFrame f2 = shading_frame(s, &h2, wo2);
  const float3 w2 = make_float3(r->wx, r->wy, r->wz);
  if (!rs_reconnectable(1, &h2, &f2, wo2, d2, w2, rp)) return zero;
  float pdf1, pdf2, pdf2_rev;
  const float3 w1l = to_local(w1, x->f.t, x->f.b, x->f.n);
  const float3 f1 = bsdf_eval(&x->f.bsdf, x->wol, w1l, &pdf1) * fabs(w1l.z);
  const float3 w2l = to_local(w2, f2.t, f2.b, f2.n);
  // T's density over L's here, where T can make the path: the light tracer's of x_1 from x_2
  // (x_2's reverse pdf, evaluated only then) against the camera's.
  // (Under a shutter too: light paths that meet what moves are traced at their own time.)
  const int camera = (r->kind & PR_RS_CAMERA) && x->cam > 0.0f;
  const float3 wo2l = to_local(wo2, f2.t, f2.b, f2.n);
  pdf2_rev = 0.0f;
  const float3 fx2 = (camera ? bsdf_eval_both(&f2.bsdf, wo2l, w2l, &pdf2, &pdf2_rev)
                             : bsdf_eval(&f2.bsdf, wo2l, w2l, &pdf2)) *
                     fabs(w2l.z);
  *g_dst = fabs(dot(h2.ng, w1)) / d2;
  const float t = camera ? eye_paths_camera_ratio(x->cam, pdf2_rev, d2) : 0.0f;
  const float w = rs_weight2(r->kind, r->pdf_light, pdf2) *
                  rs_eye_share(r->kind, r->rn, r->rh, pdf1 * *g_dst, pdf2, t);
  *seg = surface_segment_between(x->own, &x->h, s, &h2);
  return f1 * fx2 * make_float3(r->rest_r, r->rest_g, r->rest_b) * w;
}

// What keys the random numbers that offer a pixel sample's candidates to its reservoir
// (stream PR_RNG_PATH_RESAMPLE): dimension PR_RS_DIM(vertex, nee) for the candidate found at
// that vertex of the path (its BSDF's emitter hit in pt_shade; next-event estimation in
// pt_shadow), 0x10000 on for pt_resample.
typedef struct {
  u32 seed, frame, pixel, sample;
} RsKey;

#define PR_RS_DIM(vertex, nee) (2u * (vertex) + (nee))

// Offers candidate c (its resampling weight in c->w_sum) to reservoir r, with u uniform.
PR_INLINE void rs_offer(PR_GLOBAL PathReservoir* r, const PathReservoir* c, float u) {
  const float w = c->w_sum;
  if (!(w > 0.0f) || !(w < PR_INF_F)) return;
  const float sum = r->w_sum + w;
  if (ris_accept(u, sum, w)) *r = *c;
  r->w_sum = sum;
}

// The same with u drawn from dimension dim of key k.
PR_INLINE void rs_offer_keyed(PR_GLOBAL PathReservoir* r, const PathReservoir* c, const RsKey* k,
                              u32 dim) {
  Rng rr = rng_make(k->seed, PR_RNG_PATH_RESAMPLE, k->frame, k->pixel, k->sample);
  rr.dim = dim;
  rs_offer(r, c, rng_next(&rr));
}

// A candidate of the path tracked in t, into *c: x_2's factor f2 along w2 (g its segment's
// g_src), the rest beyond, the path's density pdf from x_1 on; at t = 2 the light's and x_2's
// BSDF's pdfs of w2 for its weight; ew: the eye path's weight against L, last2: x_2 is the path's
// last vertex. (Written through a pointer: a struct this large returned by value leaves an LLVM
// intrinsic that Oclgrind cannot run.)
PR_INLINE void rs_candidate(PathReservoir* c, PR_GLOBAL const PathTrack* t, float3 f2, float3 w2,
                            float g, float3 rest, float pdf, u32 kind, float pdf_light,
                            float pdf_bsdf, const EyeWeight* ew, int last2) {
  c->prim = t->prim;
  c->inst = t->inst;
  c->b1 = t->b1;
  c->b2 = t->b2;
  c->wx = w2.x;
  c->wy = w2.y;
  c->wz = w2.z;
  c->g_src = g;
  c->rest_r = rest.x;
  c->rest_g = rest.y;
  c->rest_b = rest.z;
  c->pdf_light = pdf_light;
  // The weight of a t = 2 path is in its f, not in rest, and so is the eye path's share of a
  // path L makes too, with its ratios free of x_1 for rs_eye_share.
  float w = rs_weight2(kind, pdf_light, pdf_bsdf);
  c->rn = c->rh = 0.0f;
  if (ew->l > 0.0f) {
    w *= eye_paths_eye_share_l(ew->n / ew->l, ew->h / ew->l, ew->t, ew->l_ok);
    const float pdf2 = last2 ? pdf_bsdf : t->pdf2;
    const float base = ew->l * t->p2;
    c->rn = ew->n / (last2 ? base : base * pdf2);
    c->rh = ew->h > 0.0f ? ew->h / (base * pdf2) : 0.0f;
    kind |= PR_RS_JOINED | (last2 ? PR_RS_LAST2 : 0u) | (ew->t_len ? PR_RS_CAMERA : 0u) |
            (ew->l_ok ? 0u : PR_RS_NO_L);
  }
  const float3 f = make_float3(t->f1_r, t->f1_g, t->f1_b) * f2 * rest * w;
  c->f_r = f.x;
  c->f_g = f.y;
  c->f_b = f.z;
  c->kind = kind;
  c->p_hat = luminance(f);
  c->w_sum = pdf > 0.0f ? c->p_hat / pdf : 0.0f;
  c->m = 1.0f;
  c->suffix = t->suffix;
  for (int k = 0; k < 3 * PR_RS_SUFFIX; ++k) c->sp[k] = t->sp[k];
}

// --- Temporal reuse ----------------------------------------------------------------------------
//
// A path of the previous frame is a path of this one where nothing that moved between the two
// frames comes near it: then its vertices beyond x_1, the visibility of its segments, its BSDFs
// and its lights are the same in both scenes (lights that move turn temporal reuse off for the
// frame). `moved` lists every instance that moved or changed shape (MovedInstance): a path is
// reused only where x_2 lies on none and its suffix, and the reconnection from the previous
// frame's x_1, meet none, then or now: exactly, against each frame's shape at that frame's
// transform. (This frame's reconnection is its shadow ray, traced in this frame's scene.) A suffix
// point, known by its position alone, is tested against the boxes where it lay on a DSG instance.
// x_1 may lie on what moved: the previous frame's is rebuilt on that frame's shapes (RsPrimary.own)
// and its segments leave those. The test is one function of the path and the two x_1, so the
// shift and its inverse are defined on the same paths, and the previous frame's target at a path
// is what pt_resample evaluates. This is the arena's exact invalidation (reuse/invalidate.cl) for
// eye paths: a stored path that a moving object disturbs is never reused.

// Appends point p (direction: a direction, the path's end at infinity) to a suffix.
PR_INLINE void rs_suffix_push(u32* suffix, float* sp, float3 p, int direction) {
  const u32 n = *suffix & PR_RS_COUNT_MASK;
  if (n >= PR_RS_SUFFIX) {
    *suffix |= PR_RS_LONG;
    return;
  }
  sp[3u * n] = p.x;
  sp[3u * n + 1u] = p.y;
  sp[3u * n + 2u] = p.z;
  *suffix += 1u;
  if (direction) *suffix |= PR_RS_ESCAPES;
}

// The same for the path pt_shade follows: point p, met after x_2 (on_dsg: on a DSG instance).
PR_INLINE void rs_track_push(PR_GLOBAL PathTrack* t, float3 p, int on_dsg) {
  const u32 n = t->suffix & PR_RS_COUNT_MASK;
  if (n >= PR_RS_SUFFIX) {
    t->suffix |= PR_RS_LONG;
    return;
  }
  t->sp[3u * n] = p.x;
  t->sp[3u * n + 1u] = p.y;
  t->sp[3u * n + 2u] = p.z;
  t->suffix += 1u;
  if (on_dsg) t->suffix |= 1u << (PR_RS_ON_DSG_SHIFT + n);
}

// Whether the ray o + t d, 0 <= t <= tmax, meets instance m then or now (then_only: then): its
// boxes, and then its triangles, each frame's shape (its mesh's BVH, in object space) at that
// frame's transform.
PR_INLINE int rs_meets(const SceneData* s, PR_GLOBAL const MovedInstance* m, float3 o, float3 d,
                       float tmax, int then_only) {
  if (!ray_meets_box(m->box, o, d, tmax) && (then_only || !ray_meets_box(m->box + 6, o, d, tmax)))
    return 0;
  if (m->root == PR_INVALID_INDEX) return 1;
  for (int k = 0; k < (then_only ? 1 : 2); ++k) {
    PR_GLOBAL const float* w = k ? m->after : m->before;
    BvhRay r = bvh_ray(xform_point(w, o), xform_vector(w, d), 0.0f, tmax);
    Hit h = hit_none();
    if (bvh_traverse(s->geom.mesh_nodes, s->geom.mesh_tris, k ? m->root : m->root_before, &r, &h,
                     0u, 1))
      return 1;
  }
  return 0;
}

// The record after moved[k] for a test that does (hit) or does not meet its boxes: into a node's
// subtree, or past it. Never backwards, whatever the records say.
PR_INLINE u32 rs_moved_next(PR_GLOBAL const MovedInstance* m, u32 k, int hit) {
  return hit || !m->node || m->skip <= k + 1u ? k + 1u : m->skip;
}

// Whether the ray (segment: tmax 1 and d the far end minus o) meets none of the moved instances
// then or now (then_only: then).
PR_INLINE int rs_clear_as(const SceneData* s, PR_GLOBAL const MovedInstance* moved, u32 count,
                          float3 o, float3 d, float tmax, int then_only) {
  for (u32 k = 0u; k < count;) {
    PR_GLOBAL const MovedInstance* m = moved + k;
    if (!m->node && rs_meets(s, m, o, d, tmax, then_only)) return 0;
    k = rs_moved_next(m, k, m->node && ray_meets_box(m->box, o, d, tmax));
  }
  return 1;
}

PR_INLINE int rs_clear(const SceneData* s, PR_GLOBAL const MovedInstance* moved, u32 count,
                       float3 o, float3 d, float tmax) {
  return rs_clear_as(s, moved, count, o, d, tmax, 0);
}

// Whether point p lies outside every moved instance's boxes (a path's point known by position
// alone, which may have been on one).
PR_INLINE int rs_apart(PR_GLOBAL const MovedInstance* moved, u32 count, float3 p) {
  const float3 z = make_float3(0.0f, 0.0f, 0.0f);
  for (u32 k = 0u; k < count;) {
    PR_GLOBAL const MovedInstance* m = moved + k;
    const int in = ray_meets_box(m->box, p, z, 0.0f) || ray_meets_box(m->box + 6, p, z, 0.0f);
    if (in && !m->node) return 0;
    k = rs_moved_next(m, k, in);
  }
  return 1;
}

// Whether surface point (prim, inst) is where it was: its instance did not move.
PR_INLINE int rs_unmoved(const SceneData* s, u32 inst) {
  return inst == PR_INVALID_INDEX || !s->sd.instances[inst].moved;
}

// Whether a and b are the same point (then segments from each to one end are one segment).
PR_INLINE int rs_same_point(float3 a, float3 b) {
  return a.x == b.x && a.y == b.y && a.z == b.z;
}

// Whether x_1 at x can take part in temporal reuse: where it did not move, or where the previous
// frame's shapes are known (prev_known: x, if of the previous frame, was rebuilt on them) and it
// is not glass (whose transmittance a segment from it would measure in this frame's shapes).
PR_INLINE int rs_x1_ok(const SceneData* s, const RsPrimary* x, u32 prev_known) {
  return rs_unmoved(s, x->h.inst) || (prev_known && !bsdf_transmits(&x->f.bsdf));
}

// Whether ray r (o + t d, 0 <= t <= tmax) meets none of the moved instances as they were in the
// previous frame.
PR_INLINE int rs_clear_then(const SceneData* s, PR_GLOBAL const MovedInstance* moved, u32 count,
                            Ray r) {
  return rs_clear_as(s, moved, count, make_float3(r.ox, r.oy, r.oz), make_float3(r.dx, r.dy, r.dz),
                     r.tmax, 1);
}

// Whether the segment from the previous frame's x_1 at x to x_2 (h2) is seen in that frame by a
// shadow ray traced in this one (rs_occluded): from x itself, meeting nothing that moved then or
// now, where x did not move; else the shadow ray's own segment, which leaves x's shape of then
// (a segment from x itself would meet it at once), meeting nothing that moved as it was then.
PR_INLINE int rs_reconnection_clear(const SceneData* s, PR_GLOBAL const MovedInstance* moved,
                                    u32 count, const RsPrimary* x, const SurfaceHit* h2) {
  if (!x->then_moved) return rs_clear(s, moved, count, x->h.p, h2->p - x->h.p, 1.0f);
  return rs_clear_then(s, moved, count, surface_segment_between(x->own, &x->h, s, h2));
}

// Whether anything opaque lies on ray r in the scene of x's frame. For the previous frame's x_1
// on what moved, whose segments meet nothing that moved as it was then (rs_reconnection_clear,
// di_segment_clear), that is this frame's scene with what moved passed through
// (trace_occluded_layers).
PR_INLINE int rs_occluded(const SceneData* s, const RsPrimary* x, Ray r) {
  return x->then_moved ? trace_occluded_layers(s, r, 1) : trace_occluded(s, r);
}

// Whether path r can be taken between frames, reconnected to x_1 at xa in one and at xb in the
// other: its suffix kept whole, x_2 and its suffix on nothing that moved, and no segment meeting
// what moved. An x_1 on what moved is the point of its own frame's shape (rs_x1_ok).
PR_INLINE int rs_temporal_ok(const SceneData* s, PR_GLOBAL const MovedInstance* moved, u32 count,
                             PR_GLOBAL const PathReservoir* r, const RsPrimary* xa,
                             const RsPrimary* xb, u32 prev_known) {
  if (r->prim == PR_INVALID_INDEX || (r->suffix & PR_RS_LONG)) return 0;
  const u32 n = r->suffix & PR_RS_COUNT_MASK;
  if (n == 0u) return 0;
  if (!rs_x1_ok(s, xa, prev_known) || !rs_x1_ok(s, xb, prev_known) || !rs_unmoved(s, r->inst))
    return 0;
  const SurfaceHit h2 = surface_at(&s->sd, r->prim, r->inst, r->b1, r->b2);
  if (!rs_reconnection_clear(s, moved, count, xa, &h2)) return 0;
  float3 a = h2.p;
  for (u32 k = 0u; k < n; ++k) {
    const float3 p = make_float3(r->sp[3u * k], r->sp[3u * k + 1u], r->sp[3u * k + 2u]);
    if (k + 1u == n && (r->suffix & PR_RS_ESCAPES))
      return rs_clear(s, moved, count, a, p, PR_INF_F);
    const int on_dsg = (r->suffix >> (PR_RS_ON_DSG_SHIFT + k)) & 1u;
    if ((on_dsg && !rs_apart(moved, count, p)) || !rs_clear(s, moved, count, a, p - a, 1.0f))
      return 0;
    a = p;
  }
  return 1;
}

// --- Under a shutter (--shutter with --resample) -----------------------------------------------
//
// Each pixel sample's x_1 and paths are at its own time. A path moves to another sample's x_1, at
// another time, where x_2 and the suffix are the same at every time: x_2 in no sweep (what moves
// while the shutter is open, sweep_clear) and no segment of the suffix meeting one. The new
// segment from x_1 is traced at that sample's time (only T asks more of it: rs_shift). A path of
// the previous frame keeps clear of that frame's sweeps too, and so does the segment from its x_1:
// then what it was at its time is what it was at that frame's, which rs_temporal_ok compares with
// this one's. Each test is one function of the path (and the previous x_1), the same both ways.
typedef struct {
  PR_GLOBAL const float* now;   // this frame's (LightData.sweeps)
  PR_GLOBAL const float* then;  // the previous frame's
  u32 now_count, then_count;
} RsSweeps;

// Whether the ray o + t d, 0 <= t <= tmax, meets none of this frame's sweeps (past: nor the
// previous frame's).
PR_INLINE int rs_sweeps_clear(const RsSweeps* w, int past, float3 o, float3 d, float tmax) {
  return sweeps_clear(w->now, w->now_count, o, d, tmax) &&
         (!past || sweeps_clear(w->then, w->then_count, o, d, tmax));
}

PR_INLINE int rs_sweeps_none(const RsSweeps* w, int past) {
  return w->now_count == 0u && (!past || w->then_count == 0u);
}

// Whether path r, its x_2 at p2, is the same path at every time of the sweeps' intervals: x_2 in
// none and its suffix meeting none (each segment's test holds its first point, so x_2's is the
// first segment's); with from (a previous x_1), the segment from it meeting none either.
PR_INLINE int rs_path_still(const RsSweeps* w, int past, PR_GLOBAL const PathReservoir* r,
                            float3 p2, int has_from, float3 from) {
  if (rs_sweeps_none(w, past)) return 1;
  const u32 n = r->suffix & PR_RS_COUNT_MASK;
  if ((r->suffix & PR_RS_LONG) || n == 0u) return 0;
  float3 a = p2;
  if (has_from && !rs_sweeps_clear(w, past, from, a - from, 1.0f)) return 0;
  for (u32 k = 0u; k < n; ++k) {
    const float3 p = make_float3(r->sp[3u * k], r->sp[3u * k + 1u], r->sp[3u * k + 2u]);
    if (k + 1u == n && (r->suffix & PR_RS_ESCAPES)) return rs_sweeps_clear(w, past, a, p, PR_INF_F);
    if (!rs_sweeps_clear(w, past, a, p - a, 1.0f)) return 0;
    a = p;
  }
  return 1;
}

PR_NAMESPACE_END
