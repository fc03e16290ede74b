// --eye-paths (docs/design.md section 5, "Eye paths"): the path tracer's eye paths and the
// reuse connections make the same paths. L (the first non-delta eye vertex x_1 joined to the
// stored light vertex z_k) takes the share eye_path_share gives it against N (the eye path's
// next-event estimation) and H (its BSDF sample meets the emitter), and the eye path the rest,
// split between N and H by the path tracer's own power heuristic. Each strategy's density of a
// path is the product of the densities (per unit area) of the vertices it samples beyond x_1,
// with C light paths per camera sample counted in L's; a density sampled from a delta vertex
// counts as 1 on both sides. N's choice of z_0 is counted as the light tracer's (its power
// table, uniform on the triangle), and Russian roulette is left out: any share that both sides
// compute alike keeps the estimate unbiased, and this one needs no light-tree walk in connect.
// These helpers are what connect (kernels/reuse) and pt_shade (kernels/pathtrace) share.
#pragma once

#include "shared/connection_mis.h"
#include "shared/integrator.h"

PR_NAMESPACE_BEGIN

// The lights whose stored paths take part: emissive triangles and point lights. The others'
// paths are the path tracer's alone.
PR_INLINE int eye_paths_light(const Light* l) {
  return l->type == PR_LIGHT_TRIANGLE || l->type == PR_LIGHT_POINT;
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
  return l->type == PR_LIGHT_TRIANGLE ? pmf / l->area : pmf;
}

// The density at a point (|cos| cos_x of its geometric normal with the segment, squared
// distance d2) of the light tracer's first step from z0 along dir.
PR_INLINE float eye_paths_emit_density(const Light* l, float3 n_tri, float3 dir, float cos_x,
                                       float d2) {
  return solid_angle_to_area_pdf(light_pdf_emit_dir(l, n_tri, dir), cos_x, d2);
}

// The solid-angle pdf with which the BSDF in frame f, sampled from wo, gives wi (0 if delta).
PR_INLINE float eye_paths_bsdf_pdf(const ShadingFrame* f, float3 wo, float3 wi) {
  float pdf = 0.0f;
  bsdf_eval(&f->bsdf, to_local(wo, f->t, f->b, f->n), to_local(wi, f->t, f->b, f->n), &pdf);
  return pdf;
}

PR_NAMESPACE_END
