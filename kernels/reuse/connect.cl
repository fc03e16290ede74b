// connect: one work-item per pixel (one pass per sample index). At the pixel sample's eye
// vertex x: next-event estimation (MIS-weighted against the BSDF sample's emitter hit, as in the
// path tracer), and connections to every stored non-delta vertex k >= 1 of
// the C light paths interleaved to this sample (docs/design.md section 5). Then, for completeness
// with mirrors and glass, one BSDF direction from x: if it meets a delta surface, the delta
// chain is followed and its end is treated like x (emission, next-event estimation,
// connections), up to the maximum depth. If it meets a non-delta surface Y, that surface is
// connected to the same light paths where connection MIS gives it a share (strategy E), and so
// is the surface Z that a BSDF sample from Y finds (strategy E2, for corners).
// Reads the EyeVertex, the arena and the scene; adds to the sample's radiance and the counters.
//
// Each strategy is one function over a Connector (what every connection of the eye sample
// shares) and the eye point it starts from; the connection MIS weights come from
// connection_mis_weight (shared/connection_mis.h, unit-tested on the host), next-event
// estimation's from the path tracer's power heuristic.
//
// Resampled connections (rp.resample = K, 1 to PR_MAX_CONNECTIONS). Every connection of both
// strategies, to all the light vertices of the C paths, is a candidate with an unshadowed
// contribution c_i, found without a ray. K candidates per eye vertex are kept by weighted
// reservoir sampling with weights luminance(c_i) (resampled importance sampling, Talbot 2005),
// and only they are traced: each counts c_k * (sum of weights) / (weight_k K) when unoccluded,
// an unbiased estimate of the sum of all candidates' shadowed contributions, for K shadow rays
// instead of one per candidate. The reservoir's draws come from a stream of their own, so the
// path's draws stay in place.
//
// The connection history (history_cap > 0, docs/design.md section 5): the first eye vertex's
// connections are resampled into a reservoir that each pixel sample carries to the next frame
// (history_resolve); one shadow ray there.
#include "shared/reuse.h"
// After reuse.h: its FP_CONTRACT OFF (shared/bvh.h) holds for these weights too.
#include "shared/connection_mis.h"

// The connections kept so far among an eye vertex's candidates: rp.resample of them, each
// chosen independently among all (with replacement), sharing the sum of the weights.
typedef struct {
  Ray ray[PR_MAX_CONNECTIONS];
  float c[3 * PR_MAX_CONNECTIONS];  // unshadowed contributions
  float w[PR_MAX_CONNECTIONS];      // their weights
  u32 strategy[PR_MAX_CONNECTIONS];
  float w_sum;  // all candidates' weights
  u32 candidates;
} Reservoir;

// Counts of the connections an eye sample made.
typedef struct {
  uint candidates, rays, mis_rays, unoccluded, clamped;
  uint history_kept, history_dropped;  // carried vertices kept; dropped, their slot re-traced
} ConnectCounts;

// The connection history's candidates at the first eye vertex: one kept by weighted reservoir
// sampling on the luminance of its unshadowed contribution (taken with weight 1, not 1 / C).
typedef struct {
  uint slot, k;  // slot PR_INVALID_INDEX: none kept
  float3 c;
  Ray ray;
  float p_sum;  // the candidates' target values
} HistoryReservoir;

// What every connection of one eye sample shares.
typedef struct {
  const SceneData* s;
  const ReuseParams* rp;
  __global const PathHeader* headers;
  __global const LightVertex* vertices;
  uint j;       // the pixel sample; its light paths are slots j C + c (mod N_L)
  float inv_c;  // 1 / C: each path's share
  Reservoir res;
  Rng rr;  // the reservoir's draws
  ConnectCounts n;
  uint history_cap;     // 0: no connection history; else the most candidates it carries, per C
  uint slot_offset;     // added to every slot: with a history, a random one per frame
  HistoryReservoir hr;  // strategy L's connections at the first eye vertex, carried
  HistoryReservoir he;  // strategy E's there, this frame's alone
} Connector;

// A shaded point on the eye side of a connection.
typedef struct {
  SurfaceHit h;
  ShadingFrame f;
  float3 wo;   // towards the previous eye vertex
  float3 wol;  // the same in the shading frame
  float3 tp;   // throughput from the camera
  uint depth;  // eye vertices up to this one
} EyePoint;

// A stored light vertex k >= 1 rebuilt as a shaded surface.
typedef struct {
  SurfaceHit h;
  ShadingFrame f;
  float3 wprev;   // towards the previous light vertex
  float3 wprevl;  // the same in the shading frame
  int delta;
} LightPoint;

PR_INLINE EyePoint eye_point(const SceneData* s, const SurfaceHit* h, float3 wo, float3 tp,
                             uint depth) {
  EyePoint x;
  x.h = *h;
  x.f = shading_frame(s, h, wo);
  x.wo = wo;
  x.wol = to_local(wo, x.f.t, x.f.b, x.f.n);
  x.tp = tp;
  x.depth = depth;
  return x;
}

// An eye point rebuilt from a stored surface point (an EyeVertex, or a history's record).
PR_INLINE EyePoint eye_point_at(const SceneData* s, u32 prim, u32 inst, float b1, float b2,
                                float3 wo, float3 tp, uint depth) {
  const SurfaceHit h = surface_at(&s->sd, prim, inst, b1, b2);
  return eye_point(s, &h, wo, tp, depth);
}

PR_INLINE LightPoint light_point(const SceneData* s, __global const LightVertex* v) {
  LightPoint y;
  y.h = surface_interp(&s->sd, v->prim, v->inst, v->b1, v->b2, 0);  // ns as stored
  y.h.p = vertex_pos(v);
  y.h.ng = oct_decode(v->ng_oct);
  y.h.ns = oct_decode(v->ns_oct);
  y.wprev = -vertex_dir(v);
  y.f = shading_frame(s, &y.h, y.wprev);
  y.wprevl = to_local(y.wprev, y.f.t, y.f.b, y.f.n);
  y.delta = bsdf_is_delta(&y.f.bsdf);
  return y;
}

// The eye side's BSDF towards dir and its solid-angle pdf of sampling dir.
PR_INLINE float3 eye_point_eval(const EyePoint* x, float3 dir, float* pdf) {
  return bsdf_eval(&x->f.bsdf, x->wol, to_local(dir, x->f.t, x->f.b, x->f.n), pdf);
}

// The light side of a connection reached along dir (unit, from the eye side): its BSDF towards
// -dir with the pdf of leaving along it, |cos| at its shading normal and the shading-normal
// correction of light paths. 0 where it faces away from the eye side.
PR_INLINE int light_point_eval(const LightPoint* y, float3 dir, float3* f, float* pdf, float* cos_t,
                               float* corr) {
  if (dot(-dir, y->f.ng) <= 0.0f) return 0;
  *f = bsdf_eval(&y->f.bsdf, y->wprevl, to_local(-dir, y->f.t, y->f.b, y->f.n), pdf);
  *cos_t = fabs(dot(y->f.n, dir));
  *corr = shading_normal_correction(y->wprev, -dir, y->f.n, y->f.ng);
  return 1;
}

// The light paths of the eye sample: slot of its c-th path.
PR_INLINE uint connector_slot(const Connector* c, uint path) {
  return (uint)(((ulong)c->j * c->rp->paths_per_pixel + path + c->slot_offset) % c->rp->slots);
}

// Solid-angle pdf with which the light tracer leaves vertex 0 along dir; 0 where strategy E does
// not connect to vertex 0 (spot and directional lights).
PR_INLINE float light_emit_pdf(const SceneData* s, u32 light, __global const LightVertex* v0,
                               float3 dir) {
  const Light l = s->lights.lights[light];
  return light_pdf_emit_dir(&l, oct_decode(v0->ng_oct), dir);
}

// A connection with unshadowed contribution c along shadow ray `ray`: traced now (no
// resampling; returns what it adds) or offered to the reservoir (returns 0).
PR_INLINE float3 connection_trace_or_keep(Connector* cn, float3 c, Ray ray, u32 strategy) {
  ++cn->n.candidates;
  const u32 mis = strategy != PR_STRATEGY_L;
  if (cn->rp->resample > 0u) {
    Reservoir* res = &cn->res;
    const float w = luminance(c);
    if (w > 0.0f) {
      res->w_sum += w;
      ++res->candidates;
      for (u32 k = 0u; k < cn->rp->resample; ++k) {
        // The first candidate is kept by every slot (u * w < w).
        if (rng_next(&cn->rr) * res->w_sum < w) {
          res->ray[k] = ray;
          res->c[3 * k] = c.x, res->c[3 * k + 1] = c.y, res->c[3 * k + 2] = c.z;
          res->w[k] = w;
          res->strategy[k] = strategy;
        }
      }
    }
    return make_float3(0.0f, 0.0f, 0.0f);
  }
  ++cn->n.rays;
  cn->n.mis_rays += mis;
  if (trace_occluded(cn->s, ray)) return make_float3(0.0f, 0.0f, 0.0f);
  ++cn->n.unoccluded;
  return c;
}

// One connection's unshadowed contribution from its two sides (each side's BSDF and |cos|, the
// light side's throughput), MIS weight w and share `scale` (1 / C, or 1 for the history). The
// geometry term is clamped where rp.clamp asks (*clamped set).
PR_INLINE float3 connection_value(const Connector* cn, float3 tp_eye, float3 f_eye, float cos_eye,
                                  float3 tp_light, float3 f_light, float cos_light, float dist2,
                                  float corr, float w, float scale, uint* clamped) {
  float g = cos_eye * cos_light / dist2;
  if (cn->rp->clamp > 0.0f && g > cn->rp->clamp) {
    g = cn->rp->clamp;
    *clamped = 1u;
  }
  return tp_eye * f_eye * f_light * tp_light * (g * corr * scale * w);
}

// A connection of contribution c along `ray`: traced now or kept (connection_trace_or_keep).
PR_INLINE float3 connection(Connector* cn, float3 c, uint clamped, Ray ray, u32 strategy) {
  cn->n.clamped += clamped;
  if (!(max3(c) > 0.0f)) return make_float3(0.0f, 0.0f, 0.0f);
  return connection_trace_or_keep(cn, c, ray, strategy);
}

// Traces the reservoir's connections; returns their resampled contribution and empties it.
PR_INLINE float3 reservoir_resolve(Connector* cn) {
  Reservoir* res = &cn->res;
  float3 out = make_float3(0.0f, 0.0f, 0.0f);
  if (res->candidates > 0u) {
    for (u32 k = 0u; k < cn->rp->resample; ++k) {
      ++cn->n.rays;
      cn->n.mis_rays += res->strategy[k] != PR_STRATEGY_L;
      if (trace_occluded(cn->s, res->ray[k])) continue;
      ++cn->n.unoccluded;
      out += make_float3(res->c[3 * k], res->c[3 * k + 1], res->c[3 * k + 2]) *
             (res->w_sum / (res->w[k] * (float)cn->rp->resample));
    }
  }
  res->w_sum = 0.0f;
  res->candidates = 0u;
  return out;
}

// Strategy L's connection from the eye point x to the light point y, rebuilt from stored vertex
// vk, which the light tracer reached with solid-angle pdf pdf_arrive (0: strategy E cannot reach
// it): its unshadowed contribution with its MIS weight and share `scale`, and its shadow ray; 0
// where they do not connect. q_l is the area pdf of the vertex before, Z, under the light tracer
// (0: strategy E2 cannot make the path), and z_geo converts y's solid angle towards Z to area
// at Z (|cos| there over the squared length).
PR_INLINE float3 light_vertex_value(const Connector* cn, const EyePoint* x, const LightPoint* y,
                                    __global const LightVertex* vk, float pdf_arrive, float q_l,
                                    float z_geo, float scale, Ray* ray, uint* clamped) {
  const float3 zero = make_float3(0.0f, 0.0f, 0.0f);
  const float3 dxy = y->h.p - x->h.p;
  const float dist2 = dot(dxy, dxy);
  if (!(dist2 > 0.0f)) return zero;
  const float3 dir = dxy * (1.0f / sqrt(dist2));  // from x to y
  if (dot(dir, x->f.ng) <= 0.0f) return zero;
  float3 f_y;
  float pdf_unused, cos_y, corr;
  if (!light_point_eval(y, dir, &f_y, &pdf_unused, &cos_y, &corr)) return zero;
  float pdf_x;
  const float3 f_x = eye_point_eval(x, dir, &pdf_x);
  const float p_l =
      solid_angle_to_area_pdf(pdf_arrive, fabs(dot(y->f.ng, vertex_dir(vk))), vk->t * vk->t);
  const float p_e =
      pdf_arrive > 0.0f ? solid_angle_to_area_pdf(pdf_x, fabs(dot(y->f.ng, dir)), dist2) : 0.0f;
  // E2 samples Z from y, arriving from x: y's BSDF the other way round.
  float q_e = 0.0f;
  if (q_l > 0.0f && p_e > 0.0f) {
    bsdf_eval(&y->f.bsdf, to_local(-dir, y->f.t, y->f.b, y->f.n), y->wprevl, &q_e);
    q_e *= z_geo;
  }
  const float w = connection_mis_weight(PR_STRATEGY_L, p_l, p_e, q_l, q_e, cn->rp->mis_threshold);
  const float3 tpy = make_float3(vk->tp_r, vk->tp_g, vk->tp_b);
  *ray = spawn_ray_to(x->h.p, x->f.ng, y->h.p, y->f.ng);
  return connection_value(cn, x->tp, f_x, fabs(dot(x->f.n, dir)), tpy, f_y, cos_y, dist2, corr, w,
                          scale, clamped);
}

// The light tracer's solid-angle pdf of its step from y_{k-1} to y_k (k >= 1) of path v (light
// `light`), as strategy_light_vertices finds it in its loop; 0 where strategy E cannot reach
// y_{k-1} (a delta surface, or a light it does not connect to).
PR_INLINE float light_step_pdf(const Connector* cn, u32 light, __global const LightVertex* v,
                               uint k) {
  if (k == 1u) return light_emit_pdf(cn->s, light, v, vertex_dir(v + 1));
  const LightPoint yp = light_point(cn->s, v + k - 1u);
  float pdf = 0.0f;
  if (!yp.delta)
    bsdf_eval(&yp.f.bsdf, yp.wprevl, to_local(vertex_dir(v + k), yp.f.t, yp.f.b, yp.f.n), &pdf);
  return pdf;
}

// The same per unit area at y_k, whose geometric normal is ng.
PR_INLINE float light_step_area_pdf(const Connector* cn, u32 light, __global const LightVertex* v,
                                    uint k, float3 ng) {
  return solid_angle_to_area_pdf(light_step_pdf(cn, light, v, k), fabs(dot(ng, vertex_dir(v + k))),
                                 v[k].t * v[k].t);
}

// The same for stored vertex k of `slot` alone, with the share 1 (the history's re-evaluations).
PR_INLINE float3 light_vertex_value_at(const Connector* cn, const EyePoint* x, uint slot, uint k,
                                       Ray* ray) {
  const SceneData* s = cn->s;
  const float3 zero = make_float3(0.0f, 0.0f, 0.0f);
  __global const LightVertex* v = cn->vertices + (size_t)slot * cn->rp->stride;
  const u32 light = cn->headers[slot].light;
  if (k < 1u || k >= cn->headers[slot].vertex_count || x->depth + k + 1u > cn->rp->max_depth)
    return zero;
  const LightPoint y = light_point(s, v + k);
  if (y.delta) return zero;
  float pdf_arrive = 0.0f, q_l = 0.0f, z_geo = 0.0f;
  if (cn->rp->mis_threshold > 0.0f) {
    pdf_arrive = light_step_pdf(cn, light, v, k);
    if (k >= 2u &&
        strategy_e2_takes_part(v[k].t * v[k].t, v[k - 1u].t * v[k - 1u].t, cn->rp->mis_threshold)) {
      // Z = y_{k-1}, for strategy E2.
      const float3 z_ng = oct_decode(v[k - 1u].ng_oct);
      q_l = light_step_area_pdf(cn, light, v, k - 1u, z_ng);
      z_geo = fabs(dot(z_ng, vertex_dir(v + k))) / (v[k].t * v[k].t);
    }
  }
  uint clamped = 0u;
  return light_vertex_value(cn, x, &y, v + k, pdf_arrive, q_l, z_geo, 1.0f, ray, &clamped);
}

// A candidate of the connection history: kept with probability p / (sum of p so far).
PR_INLINE void history_offer(Connector* cn, HistoryReservoir* hr, float3 c, Ray ray, uint slot,
                             uint k) {
  if (!(max3(c) > 0.0f)) return;
  ++cn->n.candidates;
  const float p = luminance(c);
  if (!(p > 0.0f)) return;
  hr->p_sum += p;
  if (rng_next(&cn->rr) * hr->p_sum < p) {
    hr->slot = slot;
    hr->k = k;
    hr->c = c;
    hr->ray = ray;
  }
}

// Strategy L: connections from the eye point x to the vertices k >= 1 of the sample's light
// paths; offered to the connection history where `history` is set.
PR_INLINE float3 strategy_light_vertices(Connector* cn, const EyePoint* x, int history) {
  const SceneData* s = cn->s;
  const ReuseParams* rp = cn->rp;
  float3 sum = make_float3(0.0f, 0.0f, 0.0f);
  const int mis = rp->mis_threshold > 0.0f;
  for (uint c = 0u; c < rp->paths_per_pixel; ++c) {
    const uint slot = connector_slot(cn, c);
    const uint count = cn->headers[slot].vertex_count;
    __global const LightVertex* v = cn->vertices + (size_t)slot * rp->stride;
    // Solid-angle pdf of the light tracer's step from y_{k-1} to y_k; 0: E cannot reach y_{k-1}.
    float pdf_step = (mis && count > 1u)
                         ? light_emit_pdf(s, cn->headers[slot].light, v, vertex_dir(v + 1))
                         : 0.0f;
    // y_{k-1} seen by strategy E2: its area pdf under the light tracer (0: E2 cannot make the
    // path) and its geometric normal.
    float q_l = 0.0f;
    float3 z_ng = make_float3(0.0f, 0.0f, 0.0f);
    for (uint k = 1u; k < count && x->depth + k + 1u <= rp->max_depth; ++k) {
      const LightPoint y = light_point(s, v + k);
      const float pdf_arrive = pdf_step;
      pdf_step = 0.0f;
      if (mis && !y.delta && k + 1u < count) {
        // The light tracer sampled the same BSDF, in the same frame, to reach y_{k+1}.
        bsdf_eval(&y.f.bsdf, y.wprevl, to_local(vertex_dir(v + k + 1u), y.f.t, y.f.b, y.f.n),
                  &pdf_step);
      }
      const float q_l_here = q_l;
      const float3 z_ng_here = z_ng;
      q_l = (mis && !y.delta)
                ? solid_angle_to_area_pdf(pdf_arrive, fabs(dot(y.h.ng, vertex_dir(v + k))),
                                          v[k].t * v[k].t)
                : 0.0f;
      z_ng = y.h.ng;
      if (y.delta) continue;
      Ray ray;
      uint clamped = 0u;
      const float z_geo = fabs(dot(z_ng_here, vertex_dir(v + k))) / (v[k].t * v[k].t);
      const int e2 =
          q_l_here > 0.0f &&
          strategy_e2_takes_part(v[k].t * v[k].t, v[k - 1u].t * v[k - 1u].t, rp->mis_threshold);
      const float3 value = light_vertex_value(cn, x, &y, v + k, pdf_arrive, e2 ? q_l_here : 0.0f,
                                              z_geo, history ? 1.0f : cn->inv_c, &ray, &clamped);
      if (history) {
        cn->n.clamped += clamped;
        history_offer(cn, &cn->hr, value, ray, slot, k);
      } else {
        sum += connection(cn, value, clamped, ray, PR_STRATEGY_L);
      }
    }
  }
  return sum;
}

// The connection history at the first eye vertex x, that of EyeVertex e (--connection-history).
// The reservoir of strategy L's connections at x that this sample's candidates filled is merged
// with the one the same pixel sample left in the previous frame (generalized RIS, Lin et al.
// 2022: the balance heuristic over the two reservoirs' targets, each weighted by its confidence
// m) and left for the next frame. A carried vertex whose slot was traced again this frame no
// longer exists (changed[slot] > the frame that kept it): it is dropped, and the previous target
// is 0 at this frame's new vertices. The previous reservoir is dropped whole where its eye vertex
// lies on an instance that moved, whose target cannot be evaluated as it was. Strategy E's
// connections at x (from this frame's BSDF sample, which the next frame cannot evaluate) have a
// reservoir of their own; one of the two is chosen in proportion to its weight, and one shadow
// ray traced. Returns the estimate of the connections at x.
PR_INLINE float3 history_resolve(Connector* cn, const EyeVertex* e,
                                 __global ConnectionHistory* hist, __global const uint* changed,
                                 uint frame) {
  const float mc = (float)cn->rp->paths_per_pixel;
  // x as connect built it (rebuilt, rather than kept through the path's later vertices).
  const EyePoint x0 =
      eye_point_at(cn->s, e->prim, e->inst, e->b1, e->b2, make_float3(e->wx, e->wy, e->wz),
                   make_float3(e->tp_r, e->tp_g, e->tp_b), e->depth);
  const EyePoint* x = &x0;
  HistoryReservoir* hr = &cn->hr;
  const ConnectionHistory prev = *hist;
  const int have_prev = prev.frame != 0u && prev.frame + 1u == frame &&
                        (prev.inst == PR_INVALID_INDEX || !cn->s->sd.instances[prev.inst].moved);
  const uint prev_k = prev.depth_k >> 16;
  // The two resampling weights m_i(y_i) p(y_i) W_i, with target p at x.
  float w_cur = hr->slot != PR_INVALID_INDEX ? hr->p_sum / mc : 0.0f, w_prev = 0.0f, m_prev = 0.0f;
  const float w_e = cn->he.slot != PR_INVALID_INDEX ? cn->he.p_sum / mc : 0.0f;
  float3 c_prev = make_float3(0.0f, 0.0f, 0.0f);
  Ray ray_prev;
  if (have_prev) {
    m_prev = fmin(prev.m, (float)cn->history_cap * mc);
    if (prev.slot != PR_INVALID_INDEX && changed[prev.slot] <= prev.frame) {
      c_prev = light_vertex_value_at(cn, x, prev.slot, prev_k, &ray_prev);
      const float p_cur = luminance(c_prev);
      const float den = m_prev * prev.p + mc * p_cur;
      if (den > 0.0f && p_cur > 0.0f) w_prev = m_prev * prev.p / den * p_cur * prev.w;
    } else if (prev.slot != PR_INVALID_INDEX) {
      ++cn->n.history_dropped;
    }
    if (hr->slot != PR_INVALID_INDEX && changed[hr->slot] <= prev.frame) {
      const EyePoint xp = eye_point_at(
          cn->s, prev.prim, prev.inst, prev.b1, prev.b2, make_float3(prev.wx, prev.wy, prev.wz),
          make_float3(prev.tp_r, prev.tp_g, prev.tp_b), prev.depth_k & 0xffffu);
      Ray unused;
      const float p_old = luminance(light_vertex_value_at(cn, &xp, hr->slot, hr->k, &unused));
      const float p_cur = luminance(hr->c);
      w_cur *= mc * p_cur / (m_prev * p_old + mc * p_cur);
    }
  }
  const float total = w_cur + w_prev;
  ConnectionHistory next;
  next.prim = e->prim;
  next.inst = e->inst;
  next.b1 = e->b1;
  next.b2 = e->b2;
  next.wx = e->wx, next.wy = e->wy, next.wz = e->wz;
  next.tp_r = e->tp_r, next.tp_g = e->tp_g, next.tp_b = e->tp_b;
  next.depth_k = e->depth;
  next.slot = PR_INVALID_INDEX;
  next.p = next.w = 0.0f;
  next.m = m_prev + mc;
  next.frame = frame;
  // The merged reservoir's vertex y, with contribution c_l and weight total / p(y).
  float3 c_l = make_float3(0.0f, 0.0f, 0.0f);
  Ray ray_l;
  if (total > 0.0f) {
    const int take_prev = rng_next(&cn->rr) * total < w_prev;
    c_l = take_prev ? c_prev : hr->c;
    ray_l = take_prev ? ray_prev : hr->ray;
    next.slot = take_prev ? prev.slot : hr->slot;
    next.depth_k |= (take_prev ? prev_k : hr->k) << 16;
    next.p = luminance(c_l);
    next.w = total / next.p;
    cn->n.history_kept += take_prev;
  }
  *hist = next;
  // One shadow ray, to L's vertex or E's connection: resampled between the two.
  float3 out = make_float3(0.0f, 0.0f, 0.0f);
  const float both = total + w_e;
  if (both > 0.0f) {
    const int take_e = rng_next(&cn->rr) * both < w_e;
    const float3 c = take_e ? cn->he.c : c_l;
    ++cn->n.rays;
    cn->n.mis_rays += take_e;
    if (!trace_occluded(cn->s, take_e ? cn->he.ray : ray_l)) {
      ++cn->n.unoccluded;
      out = c * (both / luminance(c));
    }
  }
  hr->slot = cn->he.slot = PR_INVALID_INDEX;
  hr->p_sum = cn->he.p_sum = 0.0f;
  return out;
}

// The area pdf at v of the BSDF sample from xp that found it, with solid-angle pdf pdf_w; 0
// where there is none.
PR_INLINE float sampled_area_pdf(float3 xp, float pdf_w, const EyePoint* v) {
  const float3 d = v->h.p - xp;
  const float d2 = dot(d, d);
  if (!(d2 > 0.0f) || !(pdf_w > 0.0f)) return 0.0f;
  return solid_angle_to_area_pdf(pdf_w, fabs(dot(v->f.ng, d)) / sqrt(d2), d2);
}

// Strategies E and E2: connections from the eye point v, the non-delta first hit of a BSDF
// sample with area pdf a_e at v, to the vertices k >= 0 of the sample's light paths, each
// weighted by its share of the MIS. E (second = 0): v is Y, found by x's sample. E2: v is Z,
// found by the sample from y = Y, which x's sample found with area pdf p_e.
PR_INLINE float3 strategy_sampled_vertex(Connector* cn, const EyePoint* v, float a_e,
                                         const EyePoint* y, float p_e, int second, int history) {
  const SceneData* s = cn->s;
  const ReuseParams* rp = cn->rp;
  const float t = rp->mis_threshold;
  float3 sum = make_float3(0.0f, 0.0f, 0.0f);
  if (!(a_e > 0.0f)) return sum;
  // E2: Y as the light tracer would reach it from Z (solid angle to area at Y).
  float yz2 = 0.0f, y_geo = 0.0f;
  if (second) {
    const float3 dzy = y->h.p - v->h.p;
    yz2 = dot(dzy, dzy);
    if (!(yz2 > 0.0f)) return sum;
    y_geo = fabs(dot(y->f.ng, dzy)) / (yz2 * sqrt(yz2));
  }
  for (uint c = 0u; c < rp->paths_per_pixel; ++c) {
    const uint slot = connector_slot(cn, c);
    const uint count = cn->headers[slot].vertex_count;
    const u32 light = cn->headers[slot].light;
    __global const LightVertex* lv = cn->vertices + (size_t)slot * rp->stride;
    for (uint k = 0u; k < count && v->depth + k + 1u <= rp->max_depth; ++k) {
      const float3 zp = vertex_pos(lv + k);
      const float3 d = zp - v->h.p;
      const float dist2 = dot(d, d);
      if (!(dist2 > 0.0f)) continue;
      if (second && !strategy_e2_takes_part(yz2, dist2, t)) continue;
      const float3 dir = d * (1.0f / sqrt(dist2));  // from v to z
      if (dot(dir, v->f.ng) <= 0.0f) continue;
      float3 zng, f_z;
      float pdf_l, cos_z, corr = 1.0f;
      if (k == 0u) {
        // Vertex 0: the point on the light; f_z * tpz is its emission over the position pdf.
        const u32 type = s->lights.lights[light].type;
        if (type != PR_LIGHT_TRIANGLE && type != PR_LIGHT_POINT) continue;
        zng = oct_decode(lv[0].ng_oct);
        pdf_l = light_emit_pdf(s, light, lv, dir);
        // The stored throughput is emission over (position pdf times pdf_l / cos).
        const int tri = type == PR_LIGHT_TRIANGLE;
        cos_z = tri ? fabs(dot(zng, dir)) : 1.0f;
        f_z = make_float3(1.0f, 1.0f, 1.0f) * (tri ? 0.5f * PR_INV_PI : 0.25f * PR_INV_PI);
      } else {
        const LightPoint z = light_point(s, lv + k);
        if (z.delta || !light_point_eval(&z, dir, &f_z, &pdf_l, &cos_z, &corr)) continue;
        zng = z.f.ng;
      }
      // v's area pdf under the light tracer, from z.
      const float a_l = solid_angle_to_area_pdf(pdf_l, fabs(dot(v->f.ng, dir)), dist2);
      float pdf_v, w;
      if (!second) {
        // E's weight only falls where E2 takes part too: most candidates stop here.
        w = connection_mis_weight(PR_STRATEGY_E, a_l, a_e, 0.0f, 0.0f, t);
        if (!(w > 0.0f)) continue;
        if (k >= 1u && strategy_e2_takes_part(dist2, lv[k].t * lv[k].t, t)) {
          // E2 samples z from v, arriving from x; the light tracer reached z from z_{k-1}
          // (q_l 0: E2 cannot connect z to z_{k-1}).
          const float q_l = light_step_area_pdf(cn, light, lv, k, zng);
          float q_e = 0.0f;
          if (q_l > 0.0f) {
            bsdf_eval(&v->f.bsdf, v->wol, to_local(dir, v->f.t, v->f.b, v->f.n), &pdf_v);
            q_e = solid_angle_to_area_pdf(pdf_v, fabs(dot(zng, dir)), dist2);
          }
          w = connection_mis_weight(PR_STRATEGY_E, a_l, a_e, q_l, q_e, t);
          if (!(w > 0.0f)) continue;
        }
      } else {
        // The light tracer, arriving at v from z, would reach Y with v's BSDF the other way.
        float pdf_zy;
        bsdf_eval(&v->f.bsdf, to_local(dir, v->f.t, v->f.b, v->f.n), v->wol, &pdf_zy);
        w = connection_mis_weight(PR_STRATEGY_E2, pdf_zy * y_geo, p_e, a_l, a_e, t);
        if (!(w > 0.0f)) continue;
      }
      const float3 f_v = eye_point_eval(v, dir, &pdf_v);
      const float3 tpz = make_float3(lv[k].tp_r, lv[k].tp_g, lv[k].tp_b);
      const Ray r = (k == 0u && lv[0].prim == PR_INVALID_INDEX)
                        ? spawn_ray(v->h.p, v->f.ng, dir, sqrt(dist2) * (1.0f - 1e-4f))
                        : spawn_ray_to(v->h.p, v->f.ng, zp, zng);
      uint clamped = 0u;
      const float3 value = connection_value(cn, v->tp, f_v, fabs(dot(v->f.n, dir)), tpz, f_z, cos_z,
                                            dist2, corr, w, history ? 1.0f : cn->inv_c, &clamped);
      const u32 strategy = second ? PR_STRATEGY_E2 : PR_STRATEGY_E;
      if (history) {
        cn->n.clamped += clamped;
        history_offer(cn, &cn->he, value, r, slot, k);
      } else {
        sum += connection(cn, value, clamped, r, strategy);
      }
    }
  }
  return sum;
}

// Next-event estimation at x, weighted against the BSDF sample's emitter hit where x can
// still take one (its draws are skipped otherwise, to keep the stream's layout).
PR_INLINE float3 strategy_next_event(const Connector* cn, const EyePoint* x, Rng* rng,
                                     uint* shadow_rays) {
  if (x->depth + 1u > cn->rp->max_depth) {
    rng_skip(rng, PR_NEXT_EVENT_DRAWS);
    return make_float3(0.0f, 0.0f, 0.0f);
  }
  Ray shadow;
  float3 c;
  if (!next_event(cn->s, &x->h, &x->f, x->wo, x->depth + 1u < cn->rp->max_depth, rng, &shadow, &c))
    return make_float3(0.0f, 0.0f, 0.0f);
  ++*shadow_rays;
  if (trace_occluded(cn->s, shadow)) return make_float3(0.0f, 0.0f, 0.0f);
  return x->tp * c;
}

__kernel void connect(PR_SCENE_PARAMS, ReuseParams rp, uint sample, __global const EyeVertex* eye,
                      __global const PathHeader* headers, __global const LightVertex* vertices,
                      __global float4* radiance, __global uint* counters, uint history_cap,
                      uint frame_stamp, __global const uint* changed,
                      __global ConnectionHistory* history) {
  const uint i = (uint)get_global_id(0);
  if (i >= rp.pixel_count) return;
  const EyeVertex e = eye[i];
  if (e.prim == PR_INVALID_INDEX) return;
  const SceneData s = PR_SCENE();
  // Its own stream, apart from eye_hit's.
  Rng rng = rng_make(rp.seed, PR_RNG_CONNECT, rp.frame, i, sample);
  Connector cn;
  cn.s = &s;
  cn.rp = &rp;
  cn.headers = headers;
  cn.vertices = vertices;
  cn.j = i * rp.spp + sample;
  cn.inv_c = 1.0f / (float)rp.paths_per_pixel;
  cn.res.w_sum = 0.0f;
  cn.res.candidates = 0u;
  cn.rr = rng_make(rp.seed, PR_RNG_RESAMPLE, rp.frame, i, sample);
  cn.n.candidates = cn.n.rays = cn.n.mis_rays = cn.n.unoccluded = cn.n.clamped = 0u;
  cn.n.history_kept = cn.n.history_dropped = 0u;
  cn.history_cap = history_cap;
  // With a history, the light paths shift by a random offset each frame, so that the reservoir
  // meets new candidates.
  cn.slot_offset =
      history_cap > 0u ? pr_hash_u32(rp.seed ^ pr_hash_u32(rp.frame ^ 0x534c4f54u)) % rp.slots : 0u;
  cn.hr.slot = cn.he.slot = PR_INVALID_INDEX;
  cn.hr.k = cn.he.k = 0u;
  cn.hr.p_sum = cn.he.p_sum = 0.0f;
  // Strategy E2's BSDF samples, apart from the path's draws.
  Rng r2 = rng_make(rp.seed, PR_RNG_SECOND, rp.frame, i, sample);
  EyePoint x = eye_point_at(&s, e.prim, e.inst, e.b1, e.b2, make_float3(e.wx, e.wy, e.wz),
                            make_float3(e.tp_r, e.tp_g, e.tp_b), e.depth);
  float3 L = make_float3(0.0f, 0.0f, 0.0f);
  uint shadow_rays = 0u, bounce_rays = 0u;
  // The first eye vertex's connections go to the history, where there is one.
  int history_open = history_cap > 0u;
  __global ConnectionHistory* hist = history + ((size_t)i * rp.spp + sample);
  for (uint vertex = 0u;; ++vertex) {
    if (history_open && vertex > 0u) {
      L += history_resolve(&cn, &e, hist, changed, frame_stamp);
      history_open = 0;
    }
    // The previous eye vertex's kept connections (each vertex of a delta chain has its own).
    L += reservoir_resolve(&cn);
    L += strategy_next_event(&cn, &x, &rng, &shadow_rays);
    L += strategy_light_vertices(&cn, &x, history_open);
    // The completeness extension: one BSDF direction, kept only through delta surfaces.
    const float u0 = rng_next(&rng);
    const float2 u12 = rng_next2(&rng);
    if (x.depth + 1u >= rp.max_depth) break;
    PathStep step;
    if (!path_step(&x.f, x.wo, u0, u12.x, u12.y, PR_RADIANCE, &step)) break;
    float3 d = step.wi;
    const float pdf = step.pdf;
    const int delta = step.delta;
    float3 t2 = x.tp * step.weight;
    uint depth = x.depth;
    Ray ray = spawn_ray(x.h.p, x.f.ng, d, PR_INF_F);
    int found = 0;
    // After strategy E at Y, this loop traces Y's own BSDF sample for strategy E2 (second): one
    // call site each for tracing and for the strategy keeps the kernel's compile time down.
    int second = 0;
    EyePoint ys;  // Y
    float p_e = 0.0f, pdf_y = 0.0f;
    for (uint chain = 0u; depth < rp.max_depth; ++chain) {
      Hit hit;
      ++bounce_rays;
      if (!trace_closest(&s, ray, &hit)) {
        // The environment: the sample from x shares it with next-event estimation at x.
        const float3 le = environment_radiance(&s, d);
        if (!second && max3(le) > 0.0f)
          L += t2 * le *
               (chain == 0u ? power_heuristic(pdf, environment_pdf(&s, x.h.p, x.f.n, d)) : 1.0f);
        break;
      }
      const SurfaceHit h = surface_at(&s.sd, hit.prim, hit.inst, hit.u, hit.v);
      t2 = t2 * volume_transmittance(&s, &h, d, hit.t);
      const EyePoint y = eye_point(&s, &h, -d, t2, depth + 1u);
      const int is_delta = bsdf_is_delta(&y.f.bsdf);
      // An emitter met by the sample from x: its MIS share against next-event estimation at x.
      if (!second && chain == 0u && (s.sd.materials[h.material].flags & PR_MAT_EMISSIVE))
        L +=
            t2 * surface_emission(&s, &h) * power_heuristic(pdf, emitter_pdf(&s, &h, x.h.p, x.f.n));
      // Strategy L at x counts the paths through Y, apart from E's and E2's shares: E from Y
      // (the first non-delta hit), E2 from Z (the hit of Y's sample).
      int sampled = 0;
      float a_e = 0.0f;
      if (second) {
        sampled = !is_delta;
        if (sampled) a_e = sampled_area_pdf(ys.h.p, pdf_y, &y);
      } else if (chain == 0u && !is_delta && rp.mis_threshold > 0.0f && !delta) {
        sampled = 1;
        a_e = p_e = sampled_area_pdf(x.h.p, pdf, &y);
        ys = y;
      }
      if (sampled) L += strategy_sampled_vertex(&cn, &y, a_e, &ys, p_e, second, history_open);
      if (second) break;
      if (chain == 0u && !is_delta) {
        // Y's sample for E2, from its own stream; Z's connection to the light's vertex 0 makes
        // the shortest path.
        const float v0 = rng_next(&r2);
        const float2 v12 = rng_next2(&r2);
        PathStep ystep;
        if (sampled && y.depth + 2u <= rp.max_depth &&
            path_step(&y.f, y.wo, v0, v12.x, v12.y, PR_RADIANCE, &ystep) && !ystep.delta) {
          second = 1;
          pdf_y = ystep.pdf;
          d = ystep.wi;
          t2 = t2 * ystep.weight;
          ray = spawn_ray(h.p, y.f.ng, d, PR_INF_F);
          ++depth;
          continue;
        }
        break;
      }
      ++depth;
      // Emission behind at least one delta bounce (the first delta surface's own emission is
      // next-event estimation's at x).
      if (chain > 0u && (s.sd.materials[h.material].flags & PR_MAT_EMISSIVE))
        L += t2 * surface_emission(&s, &h);
      if (!is_delta) {
        x = y;
        found = 1;
        break;
      }
      if (depth >= rp.max_depth) break;
      const float w0 = rng_next(&rng);
      const float2 w12 = rng_next2(&rng);
      PathStep chained;
      if (!path_step(&y.f, y.wo, w0, w12.x, w12.y, PR_RADIANCE, &chained)) break;
      d = chained.wi;
      t2 = t2 * chained.weight;
      ray = spawn_ray(h.p, y.f.ng, d, PR_INF_F);
    }
    if (!found || !(max3(x.tp) < PR_INF_F)) break;
  }
  if (history_open) L += history_resolve(&cn, &e, hist, changed, frame_stamp);
  L += reservoir_resolve(&cn);
  radiance[i] += (float4)(L.x, L.y, L.z, 0.0f);
  if (shadow_rays) atomic_add(counters + PR_C_SHADOW_RAYS, shadow_rays);
  if (cn.n.rays) atomic_add(counters + PR_C_CONNECT_RAYS, cn.n.rays);
  if (bounce_rays) atomic_add(counters + PR_C_BOUNCE_RAYS, bounce_rays);
  if (cn.n.mis_rays) atomic_add(counters + PR_C_MIS_RAYS, cn.n.mis_rays);
  if (cn.n.clamped) atomic_add(counters + PR_C_CLAMPED, cn.n.clamped);
  if (cn.n.candidates) atomic_add(counters + PR_C_CANDIDATES, cn.n.candidates);
  if (cn.n.unoccluded) atomic_add(counters + PR_C_CONNECTED, cn.n.unoccluded);
  if (cn.n.history_kept) atomic_add(counters + PR_C_HISTORY_KEPT, cn.n.history_kept);
  if (cn.n.history_dropped) atomic_add(counters + PR_C_HISTORY_DROPPED, cn.n.history_dropped);
}
