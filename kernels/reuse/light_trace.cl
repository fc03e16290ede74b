// light_trace: one work-item per slot in the compacted list of invalid slots. Traces the slot's
// light sub-path from scratch with the random numbers keyed by (seed, slot, generation) (under a
// shutter, one that meets what moves again at the slot's own time), and stores its vertices.
// Reads the scene, the light-tracing power table and the slot's generation; writes the slot's
// PathHeader and LightVertex records (with --eye-paths, their EyePathRatio records too) and adds
// to the counters.
#include "shared/reuse.h"
// After reuse.h: its FP_CONTRACT OFF (shared/bvh.h) holds for the ratios too (shared/mis.h keeps
// them safe without it).
#include "shared/eye_paths.h"

// A light sub-path's first vertex: its point on light L (chosen with probability pmf), the
// normal stored with it, the first direction and the throughput Le / (pmf x pdf); tp0 the same
// before a spot's falloff along dir, the vertex's own record (connect joins other directions
// to it).
typedef struct {
  float3 p, n, dir, tp, tp0;
  uint prim, inst;  // the emitting triangle, where L is one
  float b1, b2;
} LightEmission;

PR_INLINE LightEmission light_emit(const SceneData* s, const Light* L, const ReuseParams* rp,
                                   float pmf, float u1, float u2, float u3, float u4, float u5) {
  LightEmission e;
  e.n = make_float3(0.0f, 0.0f, 1.0f);
  e.tp = make_float3(0.0f, 0.0f, 0.0f);
  e.prim = e.inst = PR_INVALID_INDEX;
  e.b1 = e.b2 = 0.0f;
  if (light_is_triangle(L->type)) {
    const float2 b = sample_triangle(u1, u2);
    e.b1 = b.x;
    e.b2 = b.y;
    const SurfaceHit sh = surface_at(&s->sd, L->prim, L->inst, e.b1, e.b2);
    e.p = sh.p;
    // Both faces emit: one is chosen, in the quantised form the arena keeps, so that connect
    // evaluates the pdf of this very direction.
    e.n = oct_decode(oct_encode(u3 < 0.5f ? sh.ng : -sh.ng));
    const float pdf_dir = light_sample_emit_dir(L, e.n, u4, u5, &e.dir);
    // Le cos / (pmf / area x pdf_dir), with pdf_dir = cos / (2 pi).
    e.tp = pdf_dir > 0.0f ? material_emission(&s->sd, &sh) * (2.0f * PR_PI * L->area / pmf)
                          : make_float3(0.0f, 0.0f, 0.0f);
    e.prim = L->prim;
    e.inst = L->inst;
  } else if (light_at_infinity(L->type)) {
    // Parallel rays from a disk that covers the scene's bounding sphere; the environment's
    // direction from its importance map (Le / pdf of the direction).
    float3 le;
    const float pdf_w = light_sample_emit(L, s->lights.env, e.n, u4, u5, &e.dir, &le);
    le = pdf_w > 0.0f ? le / pdf_w : make_float3(0.0f, 0.0f, 0.0f);  // a directional's pdf: 1
    float3 t, bt;
    orthonormal_basis(e.dir, &t, &bt);
    const float3 d = sample_cosine_hemisphere(u1, u2);  // its xy is uniform on the unit disk
    const float r = rp->scene_radius;
    e.p = make_float3(rp->cx, rp->cy, rp->cz) - e.dir * (1.01f * r) + (t * d.x + bt * d.y) * r;
    e.tp = le * (PR_PI * r * r / pmf);
  } else {
    e.p = make_float3(L->p0x, L->p0y, L->p0z);
    const float pdf_dir = light_sample_emit_dir(L, e.n, u4, u5, &e.dir);
    const float att = light_falloff(L, e.dir);
    e.tp0 = make_float3(L->le_r, L->le_g, L->le_b) * (1.0f / (pmf * pdf_dir));
    e.tp = make_float3(L->le_r, L->le_g, L->le_b) * (att / (pmf * pdf_dir));
    return e;
  }
  e.tp0 = e.tp;
  return e;
}

// The arena's record of a vertex at p, reached along dir after t.
PR_INLINE LightVertex light_vertex(float3 p, float t, float3 dir, uint ng_oct, uint ns_oct,
                                   float3 tp, uint prim, uint inst, float b1, float b2) {
  LightVertex v;
  v.px = p.x;
  v.py = p.y;
  v.pz = p.z;
  v.t = t;
  v.wx = dir.x;
  v.wy = dir.y;
  v.wz = dir.z;
  v.ng_oct = ng_oct;
  v.ns_oct = ns_oct;
  v.tp_r = tp.x;
  v.tp_g = tp.y;
  v.tp_b = tp.z;
  v.prim = prim;
  v.inst = inst;
  v.b1 = b1;
  v.b2 = b2;
  return v;
}

// A slot's header before its path is traced: valid, no light, no vertex, absorbed.
PR_INLINE PathHeader light_header_empty(uint generation) {
  PathHeader h;
  h.generation = generation;
  h.light = PR_INVALID_INDEX;
  h.vertex_count = 0u;
  h.end = PR_END_ABSORBED;
  h.valid = 1u;
  h.escape_x = h.escape_y = h.escape_z = 0.0f;
  return h;
}

// Eye paths' light side: the step from vertex k (frame f, arrived from wo) along wi, with its
// densities both ways (1 on both sides where delta).
PR_INLINE void light_walk_leave(EyePathWalk* walk, uint k, const ShadingFrame* f, float3 wo,
                                float3 wi) {
  const int delta = bsdf_is_delta(&f->bsdf);
  float pdf_fwd = 0.0f, pdf_rev = 0.0f;
  if (!delta)
    bsdf_eval_both(&f->bsdf, to_local(wo, f->t, f->b, f->n), to_local(wi, f->t, f->b, f->n),
                   &pdf_fwd, &pdf_rev);
  eye_path_walk_leave(walk, k, delta, pdf_fwd, pdf_rev);
}

// Traces the light sub-path of `slot` (header *h, its generation set) in s's scene, at s's time,
// from the light as it is then (`timed`: blended to that time, light_at_time), into out and
// ratio_out; adds its rays and its SSG and DSG vertices to n[0..2].
PR_INLINE void light_trace_path(const SceneData* s, const ReuseParams* rp,
                                PR_GLOBAL const float* trace_cdf, uint slot, int timed,
                                PathHeader* h, PR_GLOBAL LightVertex* out,
                                PR_GLOBAL EyePathRatio* ratio_out, uint* n) {
  Rng rng = rng_make(rp->seed, PR_RNG_LIGHT, 0u, slot, h->generation);
  const float us = rng_next(&rng);
  const float2 u12 = rng_next2(&rng);
  const float u3 = rng_next(&rng);
  const float2 u45 = rng_next2(&rng);
  const float u1 = u12.x, u2 = u12.y, u4 = u45.x, u5 = u45.y;
  if (s->lights.count == 0u || !(rp->trace_total > 0.0f)) return;
  const uint li = light_select(trace_cdf, s->lights.count, us);
  const float pmf = (trace_cdf[li] - (li > 0u ? trace_cdf[li - 1u] : 0.0f)) / rp->trace_total;
  Light L = s->lights.lights[li];
  if (timed) light_at_time(s, li, &L);
  h->light = li;

  // Vertex 0 on the light, and the first direction (shared/lights.h).
  const LightEmission em = light_emit(s, &L, rp, pmf, u1, u2, u3, u4, u5);
  float3 tp = em.tp, dir = em.dir;
  if (!(pmf > 0.0f) || !(max3(tp) > 0.0f) || !(max3(tp) < PR_INF_F)) return;
  const uint n0_oct = oct_encode(em.n);
  LightVertex v = light_vertex(em.p, 0.0f, make_float3(0.0f, 0.0f, 0.0f), n0_oct, n0_oct, em.tp0,
                               em.prim, em.inst, em.b1, em.b2);
  out[0] = v;
  uint count = 1u;
  Ray ray = make_ray(
      light_segment_origin(&s->sd, em.p, v.ng_oct, v.ns_oct, em.prim, em.inst, em.b1, em.b2, dir),
      dir, 0.0f, PR_INF_F);
  // With eye paths, the light side of L's weight at each vertex (shared/eye_paths.h).
  const int walk_on = rp->eye_paths && eye_paths_light(&L);
  EyePathWalk walk;
  if (walk_on)
    walk = eye_path_walk_start(
        &L, li,
        light_is_triangle(L.type) ? eye_paths_light_normal(s, &L) : make_float3(0.0f, 0.0f, 1.0f),
        trace_cdf, rp->trace_total, eye_paths_direction_density(&L, s->lights.env, -em.dir));
  const float tp0 = max3(tp);  // Russian roulette weighs the throughput against this

  for (uint k = 1u; k < rp->stride; ++k) {
    Hit hit;
    ++n[0];
    if (!trace_closest(s, ray, &hit)) {
      h->end = PR_END_ESCAPED;
      h->escape_x = dir.x;
      h->escape_y = dir.y;
      h->escape_z = dir.z;
      break;
    }
    const SurfaceHit sh = surface_at(&s->sd, hit.prim, hit.inst, hit.u, hit.v);
    tp = tp * volume_transmittance(s, &sh, dir, hit.t);
    v = light_vertex(sh.p, hit.t, dir, oct_encode(sh.ng), oct_encode(sh.ns), tp, hit.prim, hit.inst,
                     hit.u, hit.v);
    out[k] = v;
    if (walk_on) ratio_out[k] = eye_path_walk_arrive(&walk, k, dir, hit.t, oct_decode(v.ng_oct));
    count = k + 1u;
    ++n[hit.inst == PR_INVALID_INDEX ? 1 : 2];
    if (k + 1u >= rp->stride) {
      h->end = PR_END_MAX_DEPTH;
      break;
    }
    // Scatter, in the frame of the stored (decoded) normals.
    const float u0 = rng_next(&rng);
    const float2 v12 = rng_next2(&rng);
    const float rr = rng_next(&rng), v1 = v12.x, v2 = v12.y;
    SurfaceHit q = sh;
    q.ng = oct_decode(v.ng_oct);
    q.ns = oct_decode(v.ns_oct);
    const float3 wo = -dir;
    const ShadingFrame f = shading_frame(s, &q, wo);
    PathStep step;
    if (!path_step(s, &q, &f, wo, u0, v1, v2, PR_IMPORTANCE, &step)) break;
    if (walk_on) light_walk_leave(&walk, k, &f, wo, step.wi);
    float3 w = step.weight * shading_normal_correction(wo, step.wi, f.n, f.ng);
    // On the throughput relative to what left the light, from the third vertex on.
    if (k >= 2u && !russian_roulette(max3(tp * w) / tp0, rr, &w)) break;
    tp = tp * w;
    if (!(max3(tp) > 0.0f) || !(max3(tp) < PR_INF_F)) break;
    dir = step.wi;
    ray = make_ray(light_segment_origin(&s->sd, sh.p, v.ng_oct, v.ns_oct, hit.prim, hit.inst, hit.u,
                                        hit.v, dir),
                   dir, 0.0f, PR_INF_F);
  }
  h->vertex_count = count;
}

PR_KERNEL void light_trace(PR_PARAMS(PR_ARGS_LIGHT_TRACE)) {
  const uint i = (uint)get_global_id(0);
  if (i >= list_count) return;
  const uint slot = list[i];
  const SceneData s = PR_SCENE();
  const uint generation = headers[slot].generation;
  __global LightVertex* out = vertices + (size_t)slot * rp.stride;
  __global EyePathRatio* ratio_out = ratios + (size_t)slot * rp.stride;
  SceneData st = s;
  PathHeader h;
  uint n[3] = {0u, 0u, 0u};  // rays, SSG and DSG vertices
  // Under a shutter a path that meets what moves is traced again, with the same numbers, at the
  // slot's time: so every stored path is what tracing gives at that time, which strategy T needs
  // (camera_splat) and L from an x_1 the same at every time (connect's at_own). One loop,
  // not two calls: the tracing code is compiled once.
  for (int timed = 0;; timed = 1) {
    h = light_header_empty(generation);
    n[1] = n[2] = 0u;
    light_trace_path(&st, &rp, trace_cdf, slot, timed, &h, out, ratio_out, n);
    if (timed) h.valid = PR_PATH_TIMED;
    if (timed || s.lights.sweep_count == 0u || light_path_still(&s, &h, out)) break;
    st.geom.time = st.sd.time = light_path_time(&rp, slot);
  }
  headers[slot] = h;
  if (n[0]) atomic_add(counter_lane(counters, PR_C_ROW) + PR_C_LIGHT_RAYS, n[0]);
  if (n[1]) atomic_add(counter_lane(counters, PR_C_ROW) + PR_C_SSG_VERTICES, n[1]);
  if (n[2]) atomic_add(counter_lane(counters, PR_C_ROW) + PR_C_DSG_VERTICES, n[2]);
}
