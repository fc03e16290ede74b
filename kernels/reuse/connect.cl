// connect: one work-item per pixel (one pass per sample index). At the pixel sample's eye
// vertex x: next-event estimation (MIS-weighted against the BSDF sample's emitter hit, as in the
// path tracer), and connections to every stored non-delta vertex k >= 1 of
// the C light paths interleaved to this sample (docs/design.md section 5). Then, for completeness
// with mirrors and glass, one BSDF direction from x: if it meets a delta surface, the delta
// chain is followed and its end is treated like x (emission, next-event estimation,
// connections), up to the maximum depth. If it meets a non-delta surface Y, that surface is
// connected to the same light paths where connection MIS gives it a share (below).
// Reads the EyeVertex, the arena and the scene; adds to the sample's radiance and the counters.
//
// Connection MIS. A connected path x - Y - y_{k-1} - ... can be found two ways: the light
// tracer stepped from y_{k-1} to Y = y_k and x connects to it (strategy L), or x's BSDF sample
// found Y and Y connects to y_{k-1} (strategy E). L alone has unbounded variance where Y comes
// close to x (G ~ 1/d^2): the rare bright pixels of corners and contact. Both strategies weigh
// the path by the power heuristic on r = p_E / p_L, the area pdfs of Y under each, and E only
// runs where r >= rp.mis_threshold, so that it costs shadow rays only near that singularity;
// below the threshold L keeps weight 1. The weights add to 1 for every path, so the estimator
// stays unbiased. E needs y_{k-1} to be connectable: not a delta surface, nor a spot or
// directional light's vertex 0 (left to L alone).
//
// Resampled connections (rp.resample = K, 1 to PR_MAX_CONNECTIONS). Every connection above
// (both strategies, all the light vertices of the C paths) is a candidate with an unshadowed
// contribution c_i, found without a ray. K candidates per eye vertex are kept by weighted
// reservoir sampling with weights luminance(c_i) (resampled importance sampling, Talbot 2005),
// and only they are traced: each counts c_k * (sum of weights) / (weight_k K) when unoccluded,
// an unbiased estimate of the sum of all candidates' shadowed contributions, for K shadow rays
// instead of one per candidate. The reservoir's draws come from a stream of their own, so the
// path's draws stay in place.
#include "shared/reuse.h"

// The connections kept so far among an eye vertex's candidates: rp.resample of them, each
// chosen independently among all (with replacement), sharing the sum of the weights.
typedef struct {
  Ray ray[PR_MAX_CONNECTIONS];
  float c[3 * PR_MAX_CONNECTIONS];  // unshadowed contributions
  float w[PR_MAX_CONNECTIONS];      // their weights
  u32 mis[PR_MAX_CONNECTIONS];      // strategy E's
  float w_sum;                      // all candidates' weights
  u32 candidates;
} Reservoir;

PR_INLINE void reservoir_clear(Reservoir* r) {
  r->w_sum = 0.0f;
  r->candidates = 0u;
}

// Counts of the connections an eye sample made.
typedef struct {
  uint candidates, rays, mis_rays, unoccluded, clamped;
} ConnectCounts;

// A connection with unshadowed contribution c along shadow ray `ray`: traced now (no
// resampling; returns what it adds) or offered to the reservoir (returns 0).
PR_INLINE float3 connection(const SceneData* s, const ReuseParams* rp, Reservoir* res, Rng* rr,
                            float3 c, Ray ray, u32 mis, ConnectCounts* n) {
  ++n->candidates;
  if (rp->resample > 0u) {
    const float w = luminance(c);
    if (w > 0.0f) {
      res->w_sum += w;
      ++res->candidates;
      for (u32 k = 0u; k < rp->resample; ++k) {
        // The first candidate is kept by every slot (u * w < w).
        if (rng_next(rr) * res->w_sum < w) {
          res->ray[k] = ray;
          res->c[3 * k] = c.x, res->c[3 * k + 1] = c.y, res->c[3 * k + 2] = c.z;
          res->w[k] = w;
          res->mis[k] = mis;
        }
      }
    }
    return make_float3(0.0f, 0.0f, 0.0f);
  }
  ++n->rays;
  n->mis_rays += mis;
  if (trace_occluded(s, ray)) return make_float3(0.0f, 0.0f, 0.0f);
  ++n->unoccluded;
  return c;
}

// Traces the reservoir's connections; returns their resampled contribution and clears it.
PR_INLINE float3 reservoir_resolve(const SceneData* s, const ReuseParams* rp, Reservoir* res,
                                   ConnectCounts* n) {
  float3 out = make_float3(0.0f, 0.0f, 0.0f);
  if (res->candidates > 0u) {
    for (u32 k = 0u; k < rp->resample; ++k) {
      ++n->rays;
      n->mis_rays += res->mis[k];
      if (trace_occluded(s, res->ray[k])) continue;
      ++n->unoccluded;
      out += make_float3(res->c[3 * k], res->c[3 * k + 1], res->c[3 * k + 2]) *
             (res->w_sum / (res->w[k] * (float)rp->resample));
    }
  }
  reservoir_clear(res);
  return out;
}

// Weight of strategy L; strategy E's is 1 minus it. r NaN or below the threshold: L alone.
PR_INLINE float mis_weight_l(float r, float threshold) {
  if (!(threshold > 0.0f) || !(r >= threshold)) return 1.0f;
  return 1.0f / (1.0f + r * r);
}

// Solid-angle pdf with which the light tracer leaves vertex 0 along dir; 0 where strategy E does
// not connect to vertex 0 (spot and directional lights).
PR_INLINE float light_emit_pdf(const SceneData* s, u32 light, PR_GLOBAL const LightVertex* v0,
                               float3 dir) {
  const Light l = s->lights.lights[light];
  return light_pdf_emit_dir(&l, oct_decode(v0->ng_oct), dir);
}

// Strategy L: connections from surface x (eye depth `depth`, throughput tp) to the light paths
// of sample j.
PR_INLINE float3 connect_light_paths(const SceneData* s, const ReuseParams* rp, const SurfaceHit* x,
                                     const ShadingFrame* fx, float3 wo, float3 tp, uint depth,
                                     uint j, __global const PathHeader* headers,
                                     __global const LightVertex* vertices, Reservoir* res, Rng* rr,
                                     ConnectCounts* n) {
  float3 sum = make_float3(0.0f, 0.0f, 0.0f);
  const float3 wol = to_local(wo, fx->t, fx->b, fx->n);
  const float inv_c = 1.0f / (float)rp->paths_per_pixel;
  const int mis = rp->mis_threshold > 0.0f;
  for (uint c = 0u; c < rp->paths_per_pixel; ++c) {
    const uint slot = (uint)(((ulong)j * rp->paths_per_pixel + c) % rp->slots);
    const uint count = headers[slot].vertex_count;
    __global const LightVertex* v = vertices + (size_t)slot * rp->stride;
    // Solid-angle pdf of the light tracer's step from y_{k-1} to y_k; 0: E cannot reach y_{k-1}.
    float pdf_step =
        (mis && count > 1u) ? light_emit_pdf(s, headers[slot].light, v, vertex_dir(v + 1)) : 0.0f;
    for (uint k = 1u; k < count && depth + k + 1u <= rp->max_depth; ++k) {
      SurfaceHit y = surface_at(&s->sd, v[k].prim, v[k].inst, v[k].b1, v[k].b2);
      y.p = vertex_pos(v + k);
      y.ng = oct_decode(v[k].ng_oct);
      y.ns = oct_decode(v[k].ns_oct);
      const float3 wy_prev = -vertex_dir(v + k);  // towards the previous light vertex
      const ShadingFrame fy = shading_frame(s, &y, wy_prev);
      const int y_delta = bsdf_is_delta(&fy.bsdf);
      const float pdf_arrive = pdf_step;
      const float3 wyl = to_local(wy_prev, fy.t, fy.b, fy.n);
      pdf_step = 0.0f;
      if (mis && !y_delta && k + 1u < count) {
        // The light tracer sampled the same BSDF, in the same frame, to reach y_{k+1}.
        bsdf_eval(&fy.bsdf, wyl, to_local(vertex_dir(v + k + 1u), fy.t, fy.b, fy.n), &pdf_step);
      }
      if (y_delta) continue;
      const float3 dxy = y.p - x->p;
      const float dist2 = dot(dxy, dxy);
      if (!(dist2 > 0.0f)) continue;
      const float3 dir = dxy * (1.0f / sqrt(dist2));  // from x to y
      if (dot(dir, fx->ng) <= 0.0f || dot(-dir, fy.ng) <= 0.0f) continue;
      float pdf_x, pdf_unused;
      const float3 f_x = bsdf_eval(&fx->bsdf, wol, to_local(dir, fx->t, fx->b, fx->n), &pdf_x);
      const float3 f_y = bsdf_eval(&fy.bsdf, wyl, to_local(-dir, fy.t, fy.b, fy.n), &pdf_unused);
      float w = 1.0f;
      if (pdf_arrive > 0.0f) {
        const float p_e = pdf_x * fabs(dot(fy.ng, dir)) / dist2;
        const float p_l = pdf_arrive * fabs(dot(fy.ng, vertex_dir(v + k))) / (v[k].t * v[k].t);
        w = mis_weight_l(p_e / p_l, rp->mis_threshold);
      }
      float g = fabs(dot(fx->n, dir)) * fabs(dot(fy.n, dir)) / dist2;
      if (rp->clamp > 0.0f && g > rp->clamp) {
        g = rp->clamp;
        ++n->clamped;
      }
      const float corr = shading_normal_correction(wy_prev, -dir, fy.n, fy.ng);
      const float3 tpy = make_float3(v[k].tp_r, v[k].tp_g, v[k].tp_b);
      const float3 contrib = tp * f_x * f_y * tpy * (g * corr * inv_c * w);
      if (!(max3(contrib) > 0.0f)) continue;
      sum += connection(s, rp, res, rr, contrib, spawn_ray_to(x->p, fx->ng, y.p, fy.ng), 0u, n);
    }
  }
  return sum;
}

// Strategy E: connections from Y, the non-delta first hit of the BSDF sample taken at the eye
// vertex at xp with solid-angle pdf pdf_x (Y at eye depth `depth`, throughput tp), to the
// vertices k >= 0 of the light paths of sample j, each weighted by its share of the MIS.
PR_INLINE float3 connect_sampled_vertex(const SceneData* s, const ReuseParams* rp, float3 xp,
                                        const SurfaceHit* yh, const ShadingFrame* fy, float3 wo,
                                        float3 tp, float pdf_x, uint depth, uint j,
                                        __global const PathHeader* headers,
                                        __global const LightVertex* vertices, Reservoir* res,
                                        Rng* rr, ConnectCounts* n) {
  float3 sum = make_float3(0.0f, 0.0f, 0.0f);
  const float3 dxy = yh->p - xp;
  const float dxy2 = dot(dxy, dxy);
  if (!(dxy2 > 0.0f) || !(pdf_x > 0.0f)) return sum;
  const float p_e = pdf_x * fabs(dot(fy->ng, dxy)) / (dxy2 * sqrt(dxy2));
  const float3 wol = to_local(wo, fy->t, fy->b, fy->n);
  const float inv_c = 1.0f / (float)rp->paths_per_pixel;
  for (uint c = 0u; c < rp->paths_per_pixel; ++c) {
    const uint slot = (uint)(((ulong)j * rp->paths_per_pixel + c) % rp->slots);
    const uint count = headers[slot].vertex_count;
    __global const LightVertex* v = vertices + (size_t)slot * rp->stride;
    for (uint k = 0u; k < count && depth + k + 1u <= rp->max_depth; ++k) {
      const float3 zp = vertex_pos(v + k);
      const float3 d = zp - yh->p;
      const float dist2 = dot(d, d);
      if (!(dist2 > 0.0f)) continue;
      const float3 dir = d * (1.0f / sqrt(dist2));  // from Y to z
      if (dot(dir, fy->ng) <= 0.0f) continue;
      float3 zng, f_z;
      float pdf_l, cos_z, corr = 1.0f;
      if (k == 0u) {
        // Vertex 0: the point on the light; f_z * tpz is its emission over the position pdf.
        const u32 type = s->lights.lights[headers[slot].light].type;
        if (type != PR_LIGHT_TRIANGLE && type != PR_LIGHT_POINT) continue;
        zng = oct_decode(v[0].ng_oct);
        pdf_l = light_emit_pdf(s, headers[slot].light, v, dir);
        // The stored throughput is emission over (position pdf times pdf_l / cos).
        const int tri = type == PR_LIGHT_TRIANGLE;
        cos_z = tri ? fabs(dot(zng, dir)) : 1.0f;
        f_z = make_float3(1.0f, 1.0f, 1.0f) * (tri ? 0.5f * PR_INV_PI : 0.25f * PR_INV_PI);
      } else {
        SurfaceHit z = surface_at(&s->sd, v[k].prim, v[k].inst, v[k].b1, v[k].b2);
        z.p = zp;
        z.ng = oct_decode(v[k].ng_oct);
        z.ns = oct_decode(v[k].ns_oct);
        const float3 wz_prev = -vertex_dir(v + k);
        const ShadingFrame fz = shading_frame(s, &z, wz_prev);
        if (bsdf_is_delta(&fz.bsdf) || dot(-dir, fz.ng) <= 0.0f) continue;
        zng = fz.ng;
        f_z = bsdf_eval(&fz.bsdf, to_local(wz_prev, fz.t, fz.b, fz.n),
                        to_local(-dir, fz.t, fz.b, fz.n), &pdf_l);
        cos_z = fabs(dot(fz.n, dir));
        corr = shading_normal_correction(wz_prev, -dir, fz.n, fz.ng);
      }
      const float3 tpz = make_float3(v[k].tp_r, v[k].tp_g, v[k].tp_b);
      const float p_l = pdf_l * fabs(dot(fy->ng, dir)) / dist2;
      const float w = 1.0f - mis_weight_l(p_e / p_l, rp->mis_threshold);
      if (!(w > 0.0f)) continue;
      float pdf_unused;
      const float3 f_y = bsdf_eval(&fy->bsdf, wol, to_local(dir, fy->t, fy->b, fy->n), &pdf_unused);
      float g = fabs(dot(fy->n, dir)) * cos_z / dist2;
      if (rp->clamp > 0.0f && g > rp->clamp) {
        g = rp->clamp;
        ++n->clamped;
      }
      const float3 contrib = tp * f_y * f_z * tpz * (g * corr * inv_c * w);
      if (!(max3(contrib) > 0.0f)) continue;
      const Ray r = (k == 0u && v[0].prim == PR_INVALID_INDEX)
                        ? spawn_ray(yh->p, fy->ng, dir, sqrt(dist2) * (1.0f - 1e-4f))
                        : spawn_ray_to(yh->p, fy->ng, zp, zng);
      sum += connection(s, rp, res, rr, contrib, r, 1u, n);
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
  // Its own stream, apart from eye_hit's.
  Rng rng = rng_make(rp.seed, PR_RNG_CONNECT, rp.frame, i, sample);
  Rng rr = rng_make(rp.seed, PR_RNG_RESAMPLE, rp.frame, i, sample);
  Reservoir res;
  reservoir_clear(&res);
  ConnectCounts n;
  n.candidates = n.rays = n.mis_rays = n.unoccluded = n.clamped = 0u;
  const uint j = i * rp.spp + sample;
  SurfaceHit x = surface_at(&s.sd, e.prim, e.inst, e.b1, e.b2);
  float3 wo = make_float3(e.wx, e.wy, e.wz);
  float3 tp = make_float3(e.tp_r, e.tp_g, e.tp_b);
  uint depth = e.depth;
  float3 L = make_float3(0.0f, 0.0f, 0.0f);
  uint shadow_rays = 0u, bounce_rays = 0u;
  for (;;) {
    // The previous eye vertex's kept connection (each vertex of a delta chain has its own).
    L += reservoir_resolve(&s, &rp, &res, &n);
    const ShadingFrame f = shading_frame(&s, &x, wo);
    if (depth + 1u <= rp.max_depth) {
      Ray shadow;
      float3 c;
      // Weighted against the BSDF sample's emitter hit below, when there is a sample.
      if (next_event(&s, &x, &f, wo, depth + 1u < rp.max_depth, &rng, &shadow, &c)) {
        ++shadow_rays;
        if (!trace_occluded(&s, shadow)) L += tp * c;
      }
    } else {
      rng_skip(&rng, PR_NEXT_EVENT_DRAWS);
    }
    L += connect_light_paths(&s, &rp, &x, &f, wo, tp, depth, j, headers, vertices, &res, &rr, &n);
    // The completeness extension: one BSDF direction, kept only through delta surfaces.
    const float u0 = rng_next(&rng);
    const float2 u12 = rng_next2(&rng);
    if (depth + 1u >= rp.max_depth) break;
    float3 wil, weight;
    float pdf;
    int delta;
    const float3 wol = to_local(wo, f.t, f.b, f.n);
    if (!bsdf_sample(&f.bsdf, wol, u0, u12.x, u12.y, PR_RADIANCE, &wil, &weight, &pdf, &delta))
      break;
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
      // An emitter met by the sample from x: its MIS share against next-event estimation at x.
      if (chain == 0u && (s.sd.materials[h.material].flags & PR_MAT_EMISSIVE))
        L += t2 * surface_emission(&s, &h) * power_heuristic(pdf, emitter_pdf(&s, &h, x.p, f.n));
      if (chain == 0u && !is_delta) {
        // Strategy L at x counts these paths, apart from E's share.
        if (rp.mis_threshold > 0.0f && !delta)
          L += connect_sampled_vertex(&s, &rp, x.p, &h, &fh, -d, t2, pdf, depth + 1u, j, headers,
                                      vertices, &res, &rr, &n);
        break;
      }
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
      const float w0 = rng_next(&rng);
      const float2 w12 = rng_next2(&rng);
      const float3 hl = to_local(-d, fh.t, fh.b, fh.n);
      if (!bsdf_sample(&fh.bsdf, hl, w0, w12.x, w12.y, PR_RADIANCE, &wil, &weight, &pdf, &delta))
        break;
      d = normalize(to_world(wil, fh.t, fh.b, fh.n));
      t2 = t2 * weight;
      ray = spawn_ray(h.p, fh.ng, d, PR_INF_F);
    }
    if (!found || !(max3(tp) < PR_INF_F)) break;
  }
  L += reservoir_resolve(&s, &rp, &res, &n);
  radiance[i] += (float4)(L.x, L.y, L.z, 0.0f);
  if (shadow_rays) atomic_add(counters + PR_C_SHADOW_RAYS, shadow_rays);
  if (n.rays) atomic_add(counters + PR_C_CONNECT_RAYS, n.rays);
  if (bounce_rays) atomic_add(counters + PR_C_BOUNCE_RAYS, bounce_rays);
  if (n.mis_rays) atomic_add(counters + PR_C_MIS_RAYS, n.mis_rays);
  if (n.clamped) atomic_add(counters + PR_C_CLAMPED, n.clamped);
  if (n.candidates) atomic_add(counters + PR_C_CANDIDATES, n.candidates);
  if (n.unoccluded) atomic_add(counters + PR_C_CONNECTED, n.unoccluded);
}
