// connect: one work-item per pixel (one pass per sample index). At the pixel sample's eye
// vertex x: next-event estimation, and connections to every stored non-delta vertex k >= 1 of
// the C light paths interleaved to this sample (DESIGN.md section 5). Then, for completeness
// with mirrors and glass, one BSDF direction from x: if it meets a delta surface, the delta
// chain is followed and its end is treated like x (emission, next-event estimation,
// connections), up to the maximum depth; otherwise it is dropped, as the connections and
// next-event estimation at x already count those paths.
// Reads the EyeVertex, the arena and the scene; adds to the sample's radiance and the counters.
#include "shared/reuse.h"

// Connections from surface x (eye depth `depth`, throughput tp) to the light paths of sample j.
PR_INLINE float3 connect_light_paths(const SceneData* s, const ReuseParams* rp, const SurfaceHit* x,
                                     const ShadingFrame* fx, float3 wo, float3 tp, uint depth, uint j,
                                     __global const PathHeader* headers,
                                     __global const LightVertex* vertices, uint* rays, uint* clamped) {
  float3 sum = make_float3(0.0f, 0.0f, 0.0f);
  const float3 wol = to_local(wo, fx->t, fx->b, fx->n);
  const float inv_c = 1.0f / (float)rp->paths_per_pixel;
  for (uint c = 0u; c < rp->paths_per_pixel; ++c) {
    const uint slot = (uint)(((ulong)j * rp->paths_per_pixel + c) % rp->slots);
    const uint count = headers[slot].vertex_count;
    __global const LightVertex* v = vertices + (size_t)slot * rp->stride;
    for (uint k = 1u; k < count && depth + k + 1u <= rp->max_depth; ++k) {
      SurfaceHit y = surface_at(&s->sd, v[k].prim, v[k].inst, v[k].b1, v[k].b2);
      y.p = vertex_pos(v + k);
      y.ng = oct_decode(v[k].ng_oct);
      y.ns = oct_decode(v[k].ns_oct);
      const float3 wy_prev = -vertex_dir(v + k);  // towards the previous light vertex
      const ShadingFrame fy = shading_frame(s, &y, wy_prev);
      if (bsdf_is_delta(&fy.bsdf)) continue;
      const float3 dxy = y.p - x->p;
      const float dist2 = dot(dxy, dxy);
      if (!(dist2 > 0.0f)) continue;
      const float3 dir = dxy * (1.0f / sqrt(dist2));  // from x to y
      if (dot(dir, fx->ng) <= 0.0f || dot(-dir, fy.ng) <= 0.0f) continue;
      float pdf_unused;
      const float3 f_x = bsdf_eval(&fx->bsdf, wol, to_local(dir, fx->t, fx->b, fx->n), &pdf_unused);
      const float3 f_y = bsdf_eval(&fy.bsdf, to_local(wy_prev, fy.t, fy.b, fy.n),
                                   to_local(-dir, fy.t, fy.b, fy.n), &pdf_unused);
      float g = fabs(dot(fx->n, dir)) * fabs(dot(fy.n, dir)) / dist2;
      if (rp->clamp > 0.0f && g > rp->clamp) {
        g = rp->clamp;
        ++*clamped;
      }
      const float corr = shading_normal_correction(wy_prev, -dir, fy.n, fy.ng);
      const float3 tpy = make_float3(v[k].tp_r, v[k].tp_g, v[k].tp_b);
      const float3 contrib = tp * f_x * f_y * tpy * (g * corr * inv_c);
      if (!(max3(contrib) > 0.0f)) continue;
      ++*rays;
      const Ray r = spawn_ray_to(x->p, fx->ng, y.p, fy.ng);
      if (!trace_occluded(s, r)) sum += contrib;
    }
  }
  return sum;
}

__kernel void connect(PR_SCENE_PARAMS, ReuseParams rp, uint sample, __global const EyeVertex* eye,
                      __global const PathHeader* headers, __global const LightVertex* vertices,
                      __global float4* radiance, __global uint* counters) {
  const uint i = (uint)get_global_id(0);
  if (i >= rp.pixel_count) return;
  const EyeVertex e = eye[i];
  if (e.prim == PR_INVALID_INDEX) return;
  const SceneData s = PR_SCENE();
  // Its own stream of dimensions, after those eye_hit used.
  Rng rng = rng_make(rp.seed, PR_RNG_CAMERA, rp.frame, i, sample);
  rng.dim = 0x10000u;
  const uint j = i * rp.spp + sample;
  SurfaceHit x = surface_at(&s.sd, e.prim, e.inst, e.b1, e.b2);
  float3 wo = make_float3(e.wx, e.wy, e.wz);
  float3 tp = make_float3(e.tp_r, e.tp_g, e.tp_b);
  uint depth = e.depth;
  float3 L = make_float3(0.0f, 0.0f, 0.0f);
  uint shadow_rays = 0u, connect_rays = 0u, bounce_rays = 0u, clamped = 0u;
  for (;;) {
    const ShadingFrame f = shading_frame(&s, &x, wo);
    if (depth + 1u <= rp.max_depth) {
      Ray shadow;
      float3 c;
      if (next_event(&s, &x, &f, wo, 0, &rng, &shadow, &c)) {
        ++shadow_rays;
        if (!trace_occluded(&s, shadow)) L += tp * c;
      }
    } else {
      rng.dim += 3u;
    }
    L += connect_light_paths(&s, &rp, &x, &f, wo, tp, depth, j, headers, vertices, &connect_rays,
                             &clamped);
    // The completeness extension: one BSDF direction, kept only through delta surfaces.
    const float u0 = rng_next(&rng), u1 = rng_next(&rng), u2 = rng_next(&rng);
    if (depth + 1u >= rp.max_depth) break;
    float3 wil, weight;
    float pdf;
    int delta;
    const float3 wol = to_local(wo, f.t, f.b, f.n);
    if (!bsdf_sample(&f.bsdf, wol, u0, u1, u2, PR_RADIANCE, &wil, &weight, &pdf, &delta)) break;
    float3 d = normalize(to_world(wil, f.t, f.b, f.n));
    if (dot(d, f.ng) * dot(wo, f.ng) <= 0.0f) break;
    float3 t2 = tp * weight;
    Ray ray = spawn_ray(x.p, f.ng, d, PR_INF_F);
    int found = 0;
    for (uint chain = 0u; depth < rp.max_depth; ++chain) {
      Hit hit;
      ++bounce_rays;
      if (!trace_closest(&s, ray, &hit)) break;
      const SurfaceHit h = surface_at(&s.sd, hit.prim, hit.inst, hit.u, hit.v);
      const ShadingFrame fh = shading_frame(&s, &h, -d);
      const int is_delta = bsdf_is_delta(&fh.bsdf);
      if (chain == 0u && !is_delta) break;  // already counted at x
      ++depth;
      // Emission behind at least one delta bounce (the first delta surface's own emission is
      // next-event estimation's at x).
      if (chain > 0u && (s.sd.materials[h.material].flags & PR_MAT_EMISSIVE))
        L += t2 * surface_emission(&s, &h);
      if (!is_delta) {
        x = h;
        wo = -d;
        tp = t2;
        found = 1;
        break;
      }
      if (depth >= rp.max_depth) break;
      const float w0 = rng_next(&rng), w1 = rng_next(&rng), w2 = rng_next(&rng);
      const float3 hl = to_local(-d, fh.t, fh.b, fh.n);
      if (!bsdf_sample(&fh.bsdf, hl, w0, w1, w2, PR_RADIANCE, &wil, &weight, &pdf, &delta)) break;
      d = normalize(to_world(wil, fh.t, fh.b, fh.n));
      t2 = t2 * weight;
      ray = spawn_ray(h.p, fh.ng, d, PR_INF_F);
    }
    if (!found || !(max3(tp) < PR_INF_F)) break;
  }
  radiance[i] += (float4)(L.x, L.y, L.z, 0.0f);
  if (shadow_rays) atomic_add(counters + PR_C_SHADOW_RAYS, shadow_rays);
  if (connect_rays) atomic_add(counters + PR_C_CONNECT_RAYS, connect_rays);
  if (bounce_rays) atomic_add(counters + PR_C_BOUNCE_RAYS, bounce_rays);
  if (clamped) atomic_add(counters + PR_C_CLAMPED, clamped);
}
