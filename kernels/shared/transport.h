// Pieces of light transport shared by the path tracer and the path-reuse kernels: the scene as
// one parameter list, alpha coverage, next-event estimation and emission with MIS.
#pragma once

#include "shared/bvh.h"
#include "shared/environment.h"
#include "shared/lights.h"
#include "shared/mis.h"
#include "shared/rng.h"
#include "shared/shading.h"

PR_NAMESPACE_BEGIN

typedef struct {
  SceneGeom geom;
  ShadingData sd;
  LightData lights;
} SceneData;

// The scene as the path of camera sample (pixel, sample) sees it: under --shutter, at the
// sample's time (shared/motion.h); otherwise at the frame's.
PR_INLINE void scene_at_sample(SceneData* s, u32 seed, u32 frame, u32 pixel, u32 sample) {
  if (s->geom.motion_steps <= 1u && s->lights.motion_steps <= 1u) return;
  s->geom.time = s->sd.time = shutter_time(seed, frame, pixel, sample);
}

// Alpha coverage: MASK cuts out below the cutoff; BLEND lets a ray pass with probability
// 1 - alpha, decided by the point's key so that the same point always answers the same.
PR_INLINE int surface_passes(const SceneData* s, const SurfaceHit* h) {
  PR_GLOBAL const Material* m = s->sd.materials + h->material;
  if (!(m->flags & (PR_MAT_ALPHA_MASK | PR_MAT_ALPHA_BLEND))) return 0;
  const float alpha = material_base(&s->sd, h).w;
  if (m->flags & PR_MAT_ALPHA_MASK) return alpha < m->alpha_cutoff;
  return pr_u32_to_unit(surface_point_key(0x3b5e17c9u, h->prim, h->inst, h->b1, h->b2)) >= alpha;
}

#define PR_MAX_ALPHA_LAYERS 16

// Closest hit that skips cut-out and uncovered points (a bounded number of layers).
PR_CALLABLE int trace_closest(const SceneData* s, Ray ray, Hit* hit) {
#ifdef PR_HAS_ALPHA
  for (int layer = 0; layer < PR_MAX_ALPHA_LAYERS; ++layer) {
    if (!intersect_scene(&s->geom, ray, hit)) return 0;
    // Coverage needs only the material and uvs: no normal map.
    const SurfaceHit h = surface_interp(&s->sd, hit->prim, hit->inst, hit->u, hit->v, 0);
    if (!surface_passes(s, &h)) return 1;
    ray.tmin = hit->t;  // continue past this point, same ray
  }
  return 1;
#else
  return intersect_scene(&s->geom, ray, hit);
#endif
}

// Whether anything opaque lies on the segment (tmin, tmax) of the ray, hit by hit: cut-out and
// uncovered points are passed through, and with pass_moved every instance that moved since the
// previous frame (a bounded number of layers).
PR_INLINE int trace_occluded_layers(const SceneData* s, Ray ray, int pass_moved) {
  for (int layer = 0; layer < PR_MAX_ALPHA_LAYERS; ++layer) {
    Hit hit;
    if (!intersect_scene(&s->geom, ray, &hit)) return 0;
    if (!pass_moved || hit.inst == PR_INVALID_INDEX || !s->sd.instances[hit.inst].moved) {
#ifdef PR_HAS_ALPHA
      const SurfaceHit h = surface_interp(&s->sd, hit.prim, hit.inst, hit.u, hit.v, 0);
      if (!surface_passes(s, &h)) return 1;
#else
      return 1;
#endif
    }
    ray.tmin = hit.t;
  }
  return 1;
}

// Whether anything opaque lies on the segment (tmin, tmax) of the ray.
PR_CALLABLE int trace_occluded(const SceneData* s, Ray ray) {
#ifdef PR_HAS_ALPHA
  return trace_occluded_layers(s, ray, 0);
#else
  return occluded_scene(&s->geom, ray);
#endif
}

// Rays that leave a surface, in every kernel: from the point, offset a few ulps off the
// geometric surface on the side the ray leaves to (shared/bvh.h, spawn_ray). Where the ray leaves
// within PR_TERMINATOR_COS of the geometric surface's plane or below it, on the side of the
// shading normal that the surface's terminator offset lifts to (surface_lift, shared/shading.h:
// convex smooth-shaded facets), it starts from the lifted point instead, blended in linearly as
// the geometric cosine falls from PR_TERMINATOR_COS to 0 (fully below the facet). Coarse facets
// are then not shadowed by their neighbours where the smooth surface their normals describe
// would be lit (the shadow terminator); rays well above the facet, which its neighbours cannot
// block, keep their exact origin, and the lift is computed for the others alone. Measured on the
// atrium's fluted column: docs/experiments/shadow-terminator.md.
// -DPR_TERMINATOR_OFFSET=0 turns it off.
#ifndef PR_TERMINATOR_OFFSET
#define PR_TERMINATOR_OFFSET 1
#endif
#define PR_TERMINATOR_COS 0.1f

// Where a ray along d leaves the surface point p (geometric normal ng, shading normal ns) of
// triangle prim of instance inst at barycentrics (b1, b2), and in *side the geometric normal on
// the side it leaves from, for the ulp offset.
PR_INLINE float3 ray_exit(const ShadingData* sd, float3 p, float3 ng, float3 ns, u32 prim, u32 inst,
                          float b1, float b2, float3 d, float3* side) {
  const float dg = dot(d, ng);
  *side = dg < 0.0f ? -ng : ng;
#if PR_TERMINATOR_OFFSET
  // Only a ray close to the plane, or on the other side of it than of the shading normal's
  // horizon, can be moved (a ray above both leaves where a lift would not move it).
  const float near = PR_TERMINATOR_COS * sqrt(dot(d, d));
  if (!(fabs(dg) < near) && !(dg * dot(d, ns) <= 0.0f)) return p;
  const float3 lift = surface_lift(sd, prim, inst, b1, b2);
  const float lg = dot(lift, ng);
  if (lg != 0.0f && dot(d, ns) * dot(lift, ns) > 0.0f) {
    const float3 n = lg < 0.0f ? -ng : ng;  // the lift's side
    const float a = clamp(1.0f - dot(d, n) / near, 0.0f, 1.0f);
    if (a > 0.0f) {
      *side = n;
      return p + lift * a;
    }
  }
#else
  (void)sd, (void)ns, (void)prim, (void)inst, (void)b1, (void)b2;
#endif
  return p;
}

// A ray leaving surface h along d, up to tmax.
PR_INLINE Ray surface_ray(const SceneData* s, const SurfaceHit* h, float3 d, float tmax) {
  float3 side;
  const float3 o = ray_exit(&s->sd, h->p, h->ng, h->ns, h->prim, h->inst, h->b1, h->b2, d, &side);
  return make_ray(offset_ray_origin(o, side), d, 0.0f, tmax);
}

// A shadow segment from surface h to a point q of a surface with normal nq (either
// orientation; q offset off it towards h), as spawn_ray_to: t in (0, 1).
PR_INLINE Ray surface_ray_to(const SceneData* s, const SurfaceHit* h, float3 q, float3 nq) {
  const float3 d = q - h->p;
  float3 side;
  const float3 o = offset_ray_origin(
      ray_exit(&s->sd, h->p, h->ng, h->ns, h->prim, h->inst, h->b1, h->b2, d, &side), side);
  const float3 e = offset_ray_origin(q, dot(nq, d) > 0.0f ? -nq : nq);
  return make_ray(o, e - o, 0.0f, 1.0f);
}

// A shadow segment between surface points a (of scene sa's shapes) and b (of sb's), each leaving
// its surface as surface_ray does.
PR_INLINE Ray surface_segment_between(const SceneData* sa, const SurfaceHit* a, const SceneData* sb,
                                      const SurfaceHit* b) {
  const float3 d = b->p - a->p;
  float3 na, nb;
  const float3 o = offset_ray_origin(
      ray_exit(&sa->sd, a->p, a->ng, a->ns, a->prim, a->inst, a->b1, a->b2, d, &na), na);
  const float3 e = offset_ray_origin(
      ray_exit(&sb->sd, b->p, b->ng, b->ns, b->prim, b->inst, b->b1, b->b2, -d, &nb), nb);
  return make_ray(o, e - o, 0.0f, 1.0f);
}

PR_INLINE Ray surface_segment(const SceneData* s, const SurfaceHit* a, const SurfaceHit* b) {
  return surface_segment_between(s, a, s, b);
}

// A shading frame: ns and ng flipped to the side of wo for reflective surfaces; glass (smooth or
// rough) keeps its geometric orientation so that the sign of wo tells entering from leaving. Where
// wo is above a reflective surface but (nearly) below its shading normal's horizon (a smooth-shaded
// facet seen edge-on), the shading normal is turned towards wo until wo is PR_MIN_VIEW_COS
// above that horizon: the BSDFs only reflect between directions above their normal, which
// made such views black. `may_lift`: wo is above the geometric surface, so that a reflection
// may leave below the geometric surface where the shading normal allows and the surface is
// lifted on wo's side (surface_lifted). -DPR_TERMINATOR_OFFSET=0 (--shadow-terminator off)
// turns both off.
#define PR_MIN_VIEW_COS 0.01f

typedef struct {
  float3 t, b, n;  // shading frame
  float3 ng;
  BsdfParams bsdf;
  int may_lift;
} ShadingFrame;

PR_INLINE ShadingFrame shading_frame(const SceneData* s, const SurfaceHit* h, float3 wo) {
  ShadingFrame f;
  float2 aniso;
  f.bsdf = material_bsdf(&s->sd, h, &aniso);
  f.ng = h->ng;
  f.n = h->ns;
  const int flip = !bsdf_transmits(&f.bsdf) && dot(wo, f.ng) < 0.0f;
  if (flip) {
    f.ng = -f.ng;
    f.n = -f.n;
  }
  if (PR_TERMINATOR_OFFSET && !bsdf_transmits(&f.bsdf)) {
    const float c = dot(wo, f.n);
    if (c < PR_MIN_VIEW_COS) f.n = normalize(f.n + wo * (PR_MIN_VIEW_COS - c));
  }
  orthonormal_basis(f.n, &f.t, &f.b);
#if PR_HAS_ANISOTROPY
  // The tangent along the anisotropy direction: the vertex tangent made orthogonal to n, turned
  // towards the bitangent by the material's rotation (KHR_materials_anisotropy).
  if (aniso.x != 0.0f || aniso.y != 0.0f) {
    float tw;
    const float3 tg = surface_tangent(&s->sd, h, &tw);
    const float3 to = tg - f.n * dot(f.n, tg);
    const float tl = length(to);
    if (tl > 1e-6f && isfinite_f(tl)) {
      const float3 tu = to / tl;
      const float3 bt = cross(h->ns, tu) * (tw < 0.0f ? -1.0f : 1.0f);
      const float3 d = tu * aniso.x + bt * aniso.y;
      const float3 dn = d - f.n * dot(f.n, d);
      const float dl = length(dn);
      if (dl > 1e-6f) {
        f.t = dn / dl;
        f.b = cross(f.n, f.t);
      }
    }
  }
#endif
#if PR_HAS_COAT
  // The coat's own normal where the base's differs from it (a normal map on either layer).
  PR_GLOBAL const Material* m = s->sd.materials + h->material;
  if (f.bsdf.coat > 0.0f &&
      (m->normal_texture != PR_NO_TEXTURE || m->coat_normal_texture != PR_NO_TEXTURE)) {
    float3 nc = surface_coat_normal(&s->sd, h);
    if (flip) nc = -nc;
    const float c = dot(wo, nc);
    // (Glass keeps its coat on the outside, whichever side wo is on.)
    if (c < PR_MIN_VIEW_COS && !bsdf_transmits(&f.bsdf))
      nc = normalize(nc + wo * (PR_MIN_VIEW_COS - c));
    f.bsdf.coat_n = normalize(to_local(nc, f.t, f.b, f.n));
  }
#endif
  f.may_lift = PR_TERMINATOR_OFFSET && dot(wo, f.ng) > 0.0f;
  return f;
}

// Whether a reflection from surface h in frame f may leave below the geometric surface (where
// its shading normal allows): where the surface is lifted on the frame's side, so that the ray
// leaves from the lifted point (ray_exit) and passes over the neighbouring facets, as it would
// over the smooth surface the normals describe.
PR_INLINE int surface_lifted(const SceneData* s, const SurfaceHit* h, const ShadingFrame* f) {
  return f->may_lift && dot(surface_lift(&s->sd, h->prim, h->inst, h->b1, h->b2), f->n) > 0.0f;
}

// Whether light may pass between wo and w (both from surface h, in frame f) where the BSDF
// gives it: a reflection on wo's side of the geometric surface, or below it where the surface is
// lifted (surface_lifted); glass, on the side the shading normal says (reflection or
// refraction), which the geometric surface must agree with, as path_step requires.
PR_INLINE int surface_side_ok(const SceneData* s, const SurfaceHit* h, const ShadingFrame* f,
                              float3 wo, float3 w) {
  if (bsdf_transmits(&f->bsdf))
    return (dot(w, f->ng) * dot(wo, f->ng) > 0.0f) == (dot(w, f->n) * dot(wo, f->n) > 0.0f);
  return dot(w, f->ng) > 0.0f || surface_lifted(s, h, f);
}

// The normal that light choice and sampling weigh lights by from a point in frame f (zero:
// none, every direction counts): none on glass, which lets light through from behind.
PR_INLINE float3 frame_light_normal(const ShadingFrame* f) {
  return bsdf_transmits(&f->bsdf) ? make_float3(0.0f, 0.0f, 0.0f) : f->n;
}

// One step of a path from a shaded point (every kernel continues its paths through this): the
// BSDF in frame f sampled with (u0, u1, u2) from wo (towards the previous vertex), the new
// direction in world space with the BSDF weight f cos / pdf, the pdf and whether the lobe was
// delta. 0 where the BSDF gives no direction or where the direction is on the wrong side of the
// geometric surface (reflection must stay on wo's side, refraction cross it): a shading normal
// must not let a path through a surface it only reflects from, or back off one it enters. A
// reflection below the geometric surface is kept where the surface is lifted (surface_lifted):
// it leaves from the lifted point (surface_ray), above the facet, as next-event estimation's
// rays do.
typedef struct {
  float3 wi;
  float3 weight;
  float pdf;
  int delta;
} PathStep;

PR_INLINE int path_step(const SceneData* s, const SurfaceHit* h, const ShadingFrame* f, float3 wo,
                        float u0, float u1, float u2, int mode, PathStep* step) {
  const float3 wol = to_local(wo, f->t, f->b, f->n);
  float3 wil;
  if (!bsdf_sample(&f->bsdf, wol, u0, u1, u2, mode, &wil, &step->weight, &step->pdf, &step->delta))
    return 0;
  step->wi = normalize(to_world(wil, f->t, f->b, f->n));
  const int reflect = wil.z * wol.z > 0.0f;
  const float side = dot(step->wi, f->ng) * dot(wo, f->ng);
  if (!reflect) return side < 0.0f;
  return side > 0.0f || surface_lifted(s, h, f);
}

// Russian roulette: the path survives with probability q (u uniform; the caller's rule: the
// light tracer's throughput relative to its start, the eye paths' square root of theirs), and
// *w is divided by q so the estimate keeps its expectation. At q >= 1 the path always goes on.
PR_INLINE int russian_roulette(float q, float u, float3* w) {
  if (q >= 1.0f) return 1;
  if (u >= q) return 0;
  *w = *w / q;
  return 1;
}

// Emitted radiance leaving the surface at h (two-sided emitters).
PR_INLINE float3 surface_emission(const SceneData* s, const SurfaceHit* h) {
  return material_emission(&s->sd, h);
}

// Whether the ray o + t d, 0 <= t <= tmax, meets box b (6 floats).
PR_INLINE int ray_meets_box(PR_GLOBAL const float* b, float3 o, float3 d, float tmax) {
  float t0 = 0.0f, t1 = tmax;
  const float oo[3] = {o.x, o.y, o.z}, dd[3] = {d.x, d.y, d.z};
  for (int a = 0; a < 3; ++a) {
    if (fabs(dd[a]) < 1e-30f) {
      if (oo[a] < b[a] || oo[a] > b[3 + a]) return 0;
      continue;
    }
    const float ta = (b[a] - oo[a]) / dd[a], tb = (b[3 + a] - oo[a]) / dd[a];
    t0 = fmax(t0, fmin(ta, tb));
    t1 = fmin(t1, fmax(ta, tb));
    if (t0 > t1) return 0;
  }
  return 1;
}

// --shutter with path reuse (docs/design.md section 3, "Path reuse over the shutter"): whether
// the ray o + t d, 0 <= t <= tmax, meets none of the boxes that hold what moves while the shutter
// is open (host/render/sweeps.h: each moving instance's parts over the interval, each moving
// punctual light's positions; all space where a directional light turns). A light sub-path whose
// segments all pass them is the same path at every time of the interval, so a sample at any time
// may be joined to it (strategies L and T); every weight of such paths asks this of the same
// segments, from either end. A record is a box and the size of its subtree, walked in order:
// into it where its box is met (a leaf met: not clear), past it where not.
#define PR_SWEEP_FLOATS 7u
PR_INLINE int sweeps_clear(PR_GLOBAL const float* sweeps, u32 n, float3 o, float3 d, float tmax) {
  for (u32 k = 0u; k < n;) {
    PR_GLOBAL const float* r = sweeps + PR_SWEEP_FLOATS * k;
    const u32 below = (u32)r[6];
    if (!ray_meets_box(r, o, d, tmax))
      k += 1u + below;
    else if (below == 0u)
      return 0;
    else
      ++k;
  }
  return 1;
}

PR_INLINE int sweep_clear(const SceneData* s, float3 o, float3 d, float tmax) {
  return sweeps_clear(s->lights.sweeps, s->lights.sweep_count, o, d, tmax);
}

// Whether a camera sample's segment from the camera at c to its x_1 at p is the same at every time
// of the shutter interval: the camera still and nothing that moves met (p included). Then its path
// is that of any time, and strategy L may join x_1 to a light path at the path's own time.
PR_INLINE int camera_segment_still(const SceneData* s, float3 c, float3 p) {
  return !s->lights.camera_moves && sweep_clear(s, c, p - c, 1.0f);
}

// Light idx where it is at the path's time: the light table holds the lights at the frame's
// (motion blur). An emissive DSG triangle is placed as its instance is (emitter_pdf reads the same
// triangle); a punctual light's position and axis are blended between its motion steps.
PR_INLINE void light_at_time(const SceneData* s, u32 idx, Light* l) {
  if (s->sd.motion_steps <= 1u && s->lights.motion_steps <= 1u) return;
  if (light_is_triangle(l->type) && l->inst != PR_INVALID_INDEX) {
    float3 v0, e1, e2;
    triangle_world(&s->sd, l->prim, l->inst, &v0, &e1, &e2);
    l->p0x = v0.x, l->p0y = v0.y, l->p0z = v0.z;
    l->e1x = e1.x, l->e1y = e1.y, l->e1z = e1.z;
    l->e2x = e2.x, l->e2y = e2.y, l->e2z = e2.z;
    l->area = 0.5f * length(cross(e1, e2));
    return;
  }
  const LightData* d = &s->lights;
  if (d->motion_steps <= 1u || idx < d->motion_first || idx - d->motion_first >= d->motion_count)
    return;
  float a;
  const u32 k = motion_step(d->motion_steps, s->sd.time, &a);
  PR_GLOBAL const Light* l0 = d->motion + (size_t)(idx - d->motion_first) * d->motion_steps + k;
  PR_GLOBAL const Light* l1 = l0 + 1;
  const float3 p0 = make_float3(l0->p0x, l0->p0y, l0->p0z);
  const float3 p = p0 + (make_float3(l1->p0x, l1->p0y, l1->p0z) - p0) * a;
  const float3 x0 = make_float3(l0->e1x, l0->e1y, l0->e1z);
  const float3 x = normalize(x0 + (make_float3(l1->e1x, l1->e1y, l1->e1z) - x0) * a);
  l->p0x = p.x, l->p0y = p.y, l->p0z = p.z;
  l->e1x = x.x, l->e1y = x.y, l->e1z = x.z;
}

// The light that the emissive triangle of hit h is in the light table.
PR_INLINE u32 emitter_light(const SceneData* s, const SurfaceHit* h) {
  const u32 k = s->lights.prim_light[h->prim];
  if (k == PR_INVALID_INDEX || h->inst == PR_INVALID_INDEX) return k;
  return s->sd.instances[h->inst].first_light + k;
}

// The pdf that next-event estimation at `ref`, with shading normal n_ref, would have had for
// reaching the emitter point h.
PR_INLINE float emitter_pdf(const SceneData* s, const SurfaceHit* h, float3 ref, float3 n_ref) {
  const float pmf = light_choice_pmf(&s->lights, emitter_light(s, h), ref, n_ref);
  if (!(pmf > 0.0f)) return 0.0f;
  float3 v0, e1, e2;
  triangle_world(&s->sd, h->prim, h->inst, &v0, &e1, &e2);
  return light_pdf_triangle(pmf, ref, n_ref, h->p, v0, e1, e2);
}

// KHR_materials_volume: the Beer-Lambert transmittance of a segment of length t (direction
// dir) that ended on surface h from behind, inside a closed transmissive object; 1 elsewhere.
// Applied where a segment leaves such an object, so paths need carry no medium: objects
// nested inside one are not attenuated on their way out.
PR_INLINE float3 volume_transmittance(const SceneData* s, const SurfaceHit* h, float3 dir,
                                      float t) {
  PR_GLOBAL const Material* m = s->sd.materials + h->material;
  if (!(m->flags & PR_MAT_GLASS) || !(dot(dir, h->ng) > 0.0f)) return make_float3(1.0f, 1.0f, 1.0f);
  const float3 sigma = make_float3(m->sigma_a[0], m->sigma_a[1], m->sigma_a[2]);
  if (!(max3(sigma) > 0.0f)) return make_float3(1.0f, 1.0f, 1.0f);
  return make_float3(exp(-sigma.x * t), exp(-sigma.y * t), exp(-sigma.z * t));
}

// The same for a connection segment of length t along dir from surface a to surface b (b null:
// a point on a light), which no traced ray crossed: attenuated where it ends on b from behind,
// else where it leaves a into its object (rough glass connects through its surface).
PR_INLINE float3 segment_transmittance(const SceneData* s, const SurfaceHit* a, const SurfaceHit* b,
                                       float3 dir, float t) {
  if (b) {
    const float3 tb = volume_transmittance(s, b, dir, t);
    if (max3(tb) < 1.0f) return tb;
  }
  return volume_transmittance(s, a, -dir, t);
}

// Radiance from the environment along dir, for a ray that leaves the scene (0 without one).
PR_INLINE float3 environment_radiance(const SceneData* s, float3 dir) {
  if (s->lights.env_light == PR_INVALID_INDEX) return make_float3(0.0f, 0.0f, 0.0f);
  const Light l = s->lights.lights[s->lights.env_light];
  return env_radiance(&l, s->lights.env, dir);
}

// The pdf that next-event estimation at `ref`, with shading normal n_ref, would have had for
// reaching the environment along dir.
PR_INLINE float environment_pdf(const SceneData* s, float3 ref, float3 n_ref, float3 dir) {
  if (s->lights.env_light == PR_INVALID_INDEX) return 0.0f;
  const float pmf = light_choice_pmf(&s->lights, s->lights.env_light, ref, n_ref);
  if (!(pmf > 0.0f)) return 0.0f;
  const Light l = s->lights.lights[s->lights.env_light];
  return pmf * env_pdf(&l, s->lights.env, dir);
}

// Next-event estimation at a non-delta surface: chooses a light for this point and a point on
// it. Returns 1 with the shadow ray and the unoccluded contribution (to be multiplied by the
// path throughput), or 0 when the sample carries nothing. With use_mis, area lights are
// weighted against BSDF sampling (the path tracer); without, the estimate stands alone (path
// reuse, where BSDF-sampled hits on emitters are not counted).
#define PR_NEXT_EVENT_DRAWS 2u  // rng_skip this many where next_event is not called

// What next_event chose, for weights of its own (--eye-paths): the light, the point on it, the
// solid-angle pdfs of the direction under light sampling (as BSDF-sampled hits see it) and under
// BSDF sampling, and the BSDF's pdf of sampling wo from that direction (the same evaluation).
typedef struct {
  u32 light;
  int delta;
  float3 pos;
  float pdf_light, pdf_bsdf, pdf_bsdf_rev;
  float3 fr_cos, le;  // the BSDF times the cosine, and the light's radiance (--resample)
  float3 wi;          // the direction towards the light
  float pdf;          // the density it was sampled with
  float b1, b2;       // a triangle light's point: barycentrics (--resample)
  float g;            // a triangle light's |cos| at the point over the squared distance; else 1
} NextEventChoice;

PR_INLINE int next_event(const SceneData* s, const SurfaceHit* h, const ShadingFrame* f, float3 wo,
                         int use_mis, Rng* rng, Ray* shadow, float3* contribution,
                         NextEventChoice* choice) {
  const float2 us = rng_next2(rng);  // the light; the tree's resampling
  const float2 ul = rng_next2(rng);
  const float u1 = ul.x, u2 = ul.y;
  float pmf, mis_pmf;
  const float3 n_l = frame_light_normal(f);
  const u32 idx = light_choose(&s->lights, h->p, n_l, us.x, us.y, &pmf, &mis_pmf);
  if (idx == PR_INVALID_INDEX || !(pmf > 0.0f)) return 0;
  Light l = s->lights.lights[idx];
  light_at_time(s, idx, &l);
  LightSample ls;
  float b1, b2;
  if (!light_sample_towards(&l, s->lights.env, pmf, h->p, n_l, u1, u2, &ls, &b1, &b2)) return 0;
  // Below the geometric surface: only from a lifted point (shading_frame).
  if (!surface_side_ok(s, h, f, wo, ls.wi)) return 0;
  float3 le = ls.le;
  if (light_is_triangle(l.type)) {
    const SurfaceHit e = surface_interp(&s->sd, l.prim, l.inst, b1, b2, 0);
    le = material_emission(&s->sd, &e);
  }
  float bsdf_pdf = 0.0f, bsdf_pdf_rev = 0.0f;
  const float3 wol = to_local(wo, f->t, f->b, f->n), wil = to_local(ls.wi, f->t, f->b, f->n);
  float3 fr = bsdf_eval_both(&f->bsdf, wol, wil, &bsdf_pdf, &bsdf_pdf_rev);
  if (bsdf_transmits(&f->bsdf)) fr = fr * segment_transmittance(s, h, 0, ls.wi, ls.dist);
  const float cos_i = fabs(wil.z);
  // MIS from the pmf that BSDF-sampled emitter hits see (light_choice_pmf; shared/mis.h).
  const float w =
      (ls.delta || !use_mis) ? 1.0f : power_heuristic(ls.pdf * (mis_pmf / pmf), bsdf_pdf);
  *contribution = fr * le * (cos_i * w / ls.pdf);
  if (max3(*contribution) <= 0.0f) return 0;
  if (choice) {
    choice->light = idx;
    choice->delta = ls.delta;
    choice->pos = ls.pos;
    choice->pdf_light = ls.pdf * (mis_pmf / pmf);
    choice->pdf_bsdf = bsdf_pdf;
    choice->pdf_bsdf_rev = bsdf_pdf_rev;
    choice->fr_cos = fr * cos_i;
    choice->le = le;
    choice->wi = ls.wi;
    choice->pdf = ls.pdf;
    choice->b1 = b1;
    choice->b2 = b2;
    choice->g =
        light_is_triangle(l.type) ? fabs(dot(ls.wi, ls.normal)) / (ls.dist * ls.dist) : 1.0f;
  }
  if (light_is_triangle(l.type)) {
    *shadow = surface_ray_to(s, h, ls.pos, ls.normal);
  } else {
    *shadow = surface_ray(s, h, ls.wi, ls.dist < PR_INF_F ? ls.dist * (1.0f - 1e-4f) : PR_INF_F);
  }
  return 1;
}

PR_NAMESPACE_END

#ifdef PR_DEVICE_CODE
PR_INLINE SceneData pr_scene_data(SceneGeom g, ShadingData sd, LightData l) {
  SceneData s;
  s.geom = g;
  s.sd = sd;
  s.lights = l;
  return s;
}
// The SceneData of a kernel whose table begins with PR_ARGS_SCENE (shared/kernel_args.h).
#define PR_SCENE()                                                                \
  pr_scene_data(PR_SCENE_GEOM(), pr_shading_data(PR_ARG_VALUES(PR_ARGS_SHADING)), \
                pr_light_data(PR_ARG_VALUES(PR_ARGS_LIGHTS)))
#endif
