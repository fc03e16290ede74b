// connect: one work-item per pixel (one pass per sample index). At the pixel sample's eye
// vertex x: next-event estimation (MIS-weighted against the BSDF sample's emitter hit, as in the
// path tracer), and connections to every stored non-delta vertex k >= 1 of
// the C light paths interleaved to this sample (docs/design.md section 5). Then, for completeness
// with mirrors and glass, one BSDF direction from x: if it meets a delta surface, the delta
// chain is followed and its end is treated like x (emission, next-event estimation,
// connections), up to the maximum depth. If it meets a non-delta surface Y, that surface is
// connected to the same light paths where connection MIS gives it a share.
// Reads the EyeVertex, the arena and the scene; adds to the sample's radiance and the counters.
//
// Each strategy is one function over a Connector (what every connection of the eye sample
// shares) and the eye point it starts from. Every weight, the connection MIS
// (mis_connection_weight), next-event estimation's power heuristic, the reservoirs' and the
// history's resampling weights, comes from shared/mis.h (unit-tested on the host).
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
//
// With --eye-paths (PR_EYE_PATHS), the path tracer's pass has written the sample's radiance and
// x (its first non-delta vertex): connect adds strategy L there alone, each connection with its
// share against the eye path's ways of making the same path (eye_path_weight, from the ratios
// light_trace kept beside each vertex; shared/eye_paths.h).
#include "shared/reuse.h"

// With PR_EYE_PATHS (--eye-paths, shared/techniques.h) connect traces no ray, and leaves the
// estimate's terms, shadow rays with what each adds, to connect_shadow (ShadowRay records,
// shared/reuse.h).
#include "shared/techniques.h"
// After reuse.h: its FP_CONTRACT OFF (shared/bvh.h) holds here too.
#include "shared/camera.h"
#include "shared/eye_paths.h"
#include "shared/mis.h"

// The connections kept so far among an eye vertex's candidates: rp.resample of them, each
// chosen independently among all (with replacement), sharing the sum of the weights.
typedef struct {
  Ray ray[PR_MAX_CONNECTIONS];
  float c[3 * PR_MAX_CONNECTIONS];  // unshadowed contributions
  float w[PR_MAX_CONNECTIONS];      // their weights
  u32 strategy[PR_MAX_CONNECTIONS];
  u32 time[PR_MAX_CONNECTIONS];  // their rays' time (Connector.rec_time)
  float w_sum;                   // all candidates' weights
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
  float mis_c;  // the eye path's count over C, in L's weight against it (eye_path_weight)
  float
      cam_x;  // strategy T: the camera factor of the eye sample's x_1 (0: T cannot make its paths)
  Reservoir res;
  Rng rr;  // the reservoir's draws
  ConnectCounts n;
  uint history_cap;     // 0: no connection history; else the most candidates it carries, per C
  uint slot_offset;     // added to every slot: with a history, a random one per period
  HistoryReservoir hr;  // strategy L's connections at the first eye vertex, carried
  HistoryReservoir he;  // strategy E's there, this frame's alone
  __global const EyePathRatio* ratios;  // --eye-paths: beside the vertices (light_trace)
  // The estimate's terms (ShadowRay records, shared/reuse.h): with PR_EYE_PATHS written to
  // rec for connect_shadow (at most cap of them), else traced and summed into L and g here.
  __global ShadowRay* rec;
  uint n_rec, cap, overflow;
  uint members;  // terms in the partial sum g since it was last closed
  float3 L, g;
  // Under a shutter: x_1's segment from the camera is still (camera_segment_still), so L joins it
  // to a light path that meets what moves at that path's own time, whose op bits (PR_REC_TIMED)
  // rec_time holds while such a connection is made (0: the sample's time).
  int at_own;
  u32 rec_time;
} Connector;

// One term of the estimate, of value v where `ray` (if not 0) is unoccluded.
PR_INLINE void connect_term(Connector* cn, float3 v, const Ray* ray, u32 op) {
  if ((op & PR_REC_SUM_MASK) == PR_REC_GROUP) ++cn->members;
#if PR_EYE_PATHS
  if (cn->n_rec >= cn->cap) {
    cn->overflow = 1u;
    return;
  }
  __global ShadowRay* r = cn->rec + cn->n_rec++;
  if (ray) r->ray = *ray;
  r->c_r = v.x;
  r->c_g = v.y;
  r->c_b = v.z;
  r->op = op | (ray ? PR_REC_RAY : 0u);
#else
  if (ray && trace_occluded(cn->s, *ray)) return;
  if (op & PR_REC_COUNTED) ++cn->n.unoccluded;
  connect_record_apply(&cn->L, &cn->g, v, op);
#endif
}

// Ends a partial sum: L += g (where it had terms).
PR_INLINE void connect_close(Connector* cn) {
  if (cn->members == 0u) return;
  cn->members = 0u;
  connect_term(cn, make_float3(0.0f, 0.0f, 0.0f), 0, PR_REC_CLOSE);
}

// A shaded point on the eye side of a connection.
typedef struct {
  SurfaceHit h;
  ShadingFrame f;
  float3 wo;   // towards the previous eye vertex
  float3 wol;  // the same in the shading frame
  float3 tp;   // throughput from the camera
  uint depth;  // eye vertices up to this one
} EyePoint;

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

// The eye side's BSDF towards dir and its solid-angle pdf of sampling dir.
PR_INLINE float3 eye_point_eval(const EyePoint* x, float3 dir, float* pdf) {
  return bsdf_eval(&x->f.bsdf, x->wol, to_local(dir, x->f.t, x->f.b, x->f.n), pdf);
}

// The light paths of the eye sample: slot of its c-th path.
PR_INLINE uint connector_slot(const Connector* c, uint path) {
  return (uint)(((ulong)c->j * c->rp->paths_per_pixel + path + c->slot_offset) % c->rp->slots);
}

// Solid-angle pdf with which the light tracer leaves vertex 0 along dir; 0 where strategy E does
// not connect to vertex 0 (directional lights and the environment).
PR_INLINE float light_emit_pdf(const SceneData* s, u32 light, __global const LightVertex* v0,
                               float3 dir) {
  const Light l = s->lights.lights[light];
  return light_pdf_emit_dir(&l, oct_decode(v0->ng_oct), dir);
}

// A connection with unshadowed contribution c along shadow ray `ray`: a term of the open partial
// sum (no resampling) or offered to the reservoir.
PR_INLINE void connection_trace_or_keep(Connector* cn, float3 c, Ray ray, u32 strategy) {
  ++cn->n.candidates;
  const u32 mis = strategy == PR_STRATEGY_E;
  if (cn->rp->resample > 0u) {
    Reservoir* res = &cn->res;
    const float w = luminance(c);
    if (w > 0.0f) {
      res->w_sum += w;
      ++res->candidates;
      for (u32 k = 0u; k < cn->rp->resample; ++k) {
        // The first candidate is kept by every slot (u * w < w).
        if (ris_accept(rng_next(&cn->rr), res->w_sum, w)) {
          res->ray[k] = ray;
          res->c[3 * k] = c.x, res->c[3 * k + 1] = c.y, res->c[3 * k + 2] = c.z;
          res->w[k] = w;
          res->strategy[k] = strategy;
          res->time[k] = cn->rec_time;
        }
      }
    }
    return;
  }
  ++cn->n.rays;
  cn->n.mis_rays += mis;
  connect_term(cn, c, &ray, PR_REC_GROUP | PR_REC_COUNTED | cn->rec_time);
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

// A connection of contribution c along `ray`: a term now or kept (connection_trace_or_keep).
PR_INLINE void connection(Connector* cn, float3 c, uint clamped, Ray ray, u32 strategy) {
  cn->n.clamped += clamped;
  if (!(max3(c) > 0.0f)) return;
  connection_trace_or_keep(cn, c, ray, strategy);
}

// The reservoir's connections, each with its resampled contribution, as one partial sum; empties
// the reservoir.
PR_INLINE void reservoir_resolve(Connector* cn) {
  Reservoir* res = &cn->res;
  if (res->candidates > 0u) {
    for (u32 k = 0u; k < cn->rp->resample; ++k) {
      ++cn->n.rays;
      cn->n.mis_rays += res->strategy[k] == PR_STRATEGY_E;
      const float3 c = make_float3(res->c[3 * k], res->c[3 * k + 1], res->c[3 * k + 2]) *
                       ris_contribution_weight(res->w_sum, res->w[k], (float)cn->rp->resample);
      connect_term(cn, c, &res->ray[k], PR_REC_GROUP | PR_REC_COUNTED | res->time[k]);
    }
    connect_close(cn);
  }
  res->w_sum = 0.0f;
  res->candidates = 0u;
}

// Whether the light of the path in `slot` takes part in --eye-paths' weights (shared/eye_paths.h).
PR_INLINE int eye_paths_slot(const Connector* cn, uint slot) {
  const u32 li = cn->headers[slot].light;
  if (li == PR_INVALID_INDEX || !(cn->rp->trace_total > 0.0f)) return 0;
  const Light l = cn->s->lights.lights[li];
  return eye_paths_light(&l);
}

// Strategy L's connection from the eye point x to the light point y, rebuilt from stored vertex
// vk (the path's k-th), which the light tracer reached with solid-angle pdf pdf_arrive (0:
// strategy E cannot reach it): its unshadowed contribution with its MIS weight and share
// `scale`, and its shadow ray; 0 where they do not connect. With --eye-paths, the weight is
// against the eye path's strategies instead, from the ratios light_trace kept for vk.
PR_INLINE float3 light_vertex_value(const Connector* cn, const EyePoint* x, const LightPoint* y,
                                    __global const LightVertex* vk, float pdf_arrive, float scale,
                                    uint k, Ray* ray, uint* clamped) {
  const float3 zero = make_float3(0.0f, 0.0f, 0.0f);
  const float3 dxy = y->h.p - x->h.p;
  const float dist2 = dot(dxy, dxy);
  if (!(dist2 > 0.0f)) return zero;
  const float3 dir = dxy * (1.0f / sqrt(dist2));  // from x to y
  if (!surface_side_ok(cn->s, &x->h, &x->f, x->wo, dir)) return zero;
  float3 f_y;
  float pdf_leave, pdf_rev, cos_y, corr;
  if (!light_point_eval(cn->s, y, dir, &f_y, &pdf_leave, &pdf_rev, &cos_y, &corr)) return zero;
  float pdf_x;
  float3 f_x = eye_point_eval(x, dir, &pdf_x);
  if (bsdf_transmits(&x->f.bsdf) || bsdf_transmits(&y->f.bsdf))
    f_x = f_x * segment_transmittance(cn->s, &x->h, &y->h, dir, sqrt(dist2));
  const float p_l =
      solid_angle_to_area_pdf(pdf_arrive, fabs(dot(y->f.ng, vertex_dir(vk))), vk->t * vk->t);
  const float p_e =
      pdf_arrive > 0.0f ? solid_angle_to_area_pdf(pdf_x, fabs(dot(y->f.ng, dir)), dist2) : 0.0f;
  // T's density over L's: the path has k + 1 vertices before the light (under a shutter too:
  // light_trace traces a path that meets what moves at its own time, camera_splat's).
  const float t = eye_paths_camera_len(k + 1u, cn->rp->max_depth)
                      ? eye_paths_camera_ratio(cn->cam_x, pdf_leave, dist2)
                      : 0.0f;
  const float mis = PR_EYE_PATHS
                        ? eye_path_weight(cn->ratios[vk - cn->vertices], k, pdf_x,
                                          fabs(dot(y->h.ng, dir)), dist2, pdf_rev, cn->mis_c, t)
                        : mis_connection_weight(PR_STRATEGY_L, p_l, p_e, cn->rp->mis_threshold);
  const float3 tpy = make_float3(vk->tp_r, vk->tp_g, vk->tp_b);
  *ray = surface_segment(cn->s, &x->h, &y->h);
  return connection_value(cn, x->tp, f_x, fabs(dot(x->f.n, dir)), tpy, f_y, cos_y, dist2, corr, mis,
                          scale, clamped);
}

// The same for stored vertex k of `slot` alone, with the share 1 (the history's re-evaluations).
PR_INLINE float3 light_vertex_value_at(const Connector* cn, const EyePoint* x, uint slot, uint k,
                                       Ray* ray) {
  const SceneData* s = cn->s;
  const float3 zero = make_float3(0.0f, 0.0f, 0.0f);
  __global const LightVertex* v = cn->vertices + (size_t)slot * cn->rp->stride;
  if (k < 1u || k >= cn->headers[slot].vertex_count || x->depth + k + 1u > cn->rp->max_depth)
    return zero;
  if (PR_EYE_PATHS && !eye_paths_slot(cn, slot)) return zero;
  if (!light_prefix_still(s, cn->headers[slot].light, v, k)) return zero;
  const LightPoint y = light_point(s, v + k);
  if (y.delta) return zero;
  // The light tracer's pdf of the step to y_k, as strategy_light_vertices finds it.
  float pdf_arrive = 0.0f;
  if (cn->rp->mis_threshold > 0.0f) {
    if (k == 1u) {
      pdf_arrive = light_emit_pdf(s, cn->headers[slot].light, v, vertex_dir(v + 1));
    } else {
      const LightPoint yp = light_point(s, v + k - 1u);
      if (!yp.delta)
        bsdf_eval(&yp.f.bsdf, yp.wprevl, to_local(vertex_dir(v + k), yp.f.t, yp.f.b, yp.f.n),
                  &pdf_arrive);
    }
  }
  uint clamped = 0u;
  return light_vertex_value(cn, x, &y, v + k, pdf_arrive, 1.0f, k, ray, &clamped);
}

// A candidate of the connection history: kept with probability p / (sum of p so far).
PR_INLINE void history_offer(Connector* cn, HistoryReservoir* hr, float3 c, Ray ray, uint slot,
                             uint k) {
  if (!(max3(c) > 0.0f)) return;
  ++cn->n.candidates;
  const float p = luminance(c);
  if (!(p > 0.0f)) return;
  hr->p_sum += p;
  if (ris_accept(rng_next(&cn->rr), hr->p_sum, p)) {
    hr->slot = slot;
    hr->k = k;
    hr->c = c;
    hr->ray = ray;
  }
}

// Strategy L: connections from the eye point x to the vertices k >= 1 of the sample's light
// paths, one partial sum; offered to the connection history where `history` is set.
PR_INLINE void strategy_light_vertices(Connector* cn, const EyePoint* x, int history) {
  const SceneData* s = cn->s;
  const ReuseParams* rp = cn->rp;
  const int mis = rp->mis_threshold > 0.0f;
  SceneData at = *s;  // the scene at a light path's own time (cn->at_own)
  for (uint c = 0u; c < rp->paths_per_pixel; ++c) {
    const uint slot = connector_slot(cn, c);
    const uint count = cn->headers[slot].vertex_count;
    __global const LightVertex* v = cn->vertices + (size_t)slot * rp->stride;
    // Solid-angle pdf of the light tracer's step from y_{k-1} to y_k; 0: E cannot reach y_{k-1}.
    float pdf_step = (mis && count > 1u)
                         ? light_emit_pdf(s, cn->headers[slot].light, v, vertex_dir(v + 1))
                         : 0.0f;
    if (PR_EYE_PATHS && !eye_paths_slot(cn, slot)) continue;  // the path tracer's alone
    cn->rec_time = 0u;
    for (uint k = 1u; k < count && x->depth + k + 1u <= rp->max_depth; ++k) {
      // Under a shutter, z_k and what follows where the path up to it meets nothing that moves:
      // then it is the path of this sample's time too. Where it meets something, at the path's
      // own time (light_trace traced it then), where x_1 is the same at every time.
      if (s->lights.sweep_count && !cn->rec_time &&
          !light_segment_still(s, s->lights.lights[cn->headers[slot].light].type, v, k)) {
        if (!cn->at_own) break;
        cn->rec_time = light_path_time_op(rp, slot);
        at.geom.time = at.sd.time = record_time(cn->rec_time);
      }
      cn->s = cn->rec_time ? &at : s;
      const LightPoint y = light_point(cn->s, v + k);
      const float pdf_arrive = pdf_step;
      pdf_step = 0.0f;
      if (mis && !y.delta && k + 1u < count) {
        // The light tracer sampled the same BSDF, in the same frame, to reach y_{k+1}.
        bsdf_eval(&y.f.bsdf, y.wprevl, to_local(vertex_dir(v + k + 1u), y.f.t, y.f.b, y.f.n),
                  &pdf_step);
      }
      if (y.delta) continue;
      Ray ray;
      uint clamped = 0u;
      const float3 value = light_vertex_value(cn, x, &y, v + k, pdf_arrive,
                                              history ? 1.0f : cn->inv_c, k, &ray, &clamped);
      if (history) {
        cn->n.clamped += clamped;
        history_offer(cn, &cn->hr, value, ray, slot, k);
      } else {
        connection(cn, value, clamped, ray, PR_STRATEGY_L);
      }
    }
  }
  cn->s = s;
  cn->rec_time = 0u;
  connect_close(cn);
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
// ray traced: the estimate of the connections at x, one term.
PR_INLINE void history_resolve(Connector* cn, const EyeVertex* e, __global ConnectionHistory* hist,
                               __global const uint* changed, uint frame) {
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
  Ray ray_prev = make_ray(c_prev, c_prev, 0.0f, 0.0f);  // never left unset (kernel-conformance.sh)
  if (have_prev) {
    m_prev = fmin(prev.m, (float)cn->history_cap * mc);
    const int prev_kept = prev.slot != PR_INVALID_INDEX && changed[prev.slot] <= prev.frame;
    if (!prev_kept && prev.slot != PR_INVALID_INDEX) ++cn->n.history_dropped;
    if (prev_kept) {
      c_prev = light_vertex_value_at(cn, x, prev.slot, prev_k, &ray_prev);
      const float p_cur = luminance(c_prev);
      if (p_cur > 0.0f) w_prev = gris_weight(mis_balance(m_prev, prev.p, mc, p_cur), p_cur, prev.w);
    }
    if (hr->slot != PR_INVALID_INDEX && changed[hr->slot] <= prev.frame) {
      const EyePoint xp = eye_point_at(
          cn->s, prev.prim, prev.inst, prev.b1, prev.b2, make_float3(prev.wx, prev.wy, prev.wz),
          make_float3(prev.tp_r, prev.tp_g, prev.tp_b), prev.depth_k & 0xffffu);
      Ray unused;
      const float p_old = luminance(light_vertex_value_at(cn, &xp, hr->slot, hr->k, &unused));
      const float p_cur = luminance(hr->c);
      w_cur *= mis_balance(mc, p_cur, m_prev, p_old);
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
  Ray ray_l = ray_prev;
  if (total > 0.0f) {
    const int take_prev = ris_accept(rng_next(&cn->rr), total, w_prev);
    c_l = take_prev ? c_prev : hr->c;
    ray_l = take_prev ? ray_prev : hr->ray;
    next.slot = take_prev ? prev.slot : hr->slot;
    next.depth_k |= (take_prev ? prev_k : hr->k) << 16;
    next.p = luminance(c_l);
    next.w = ris_contribution_weight(total, next.p, 1.0f);
    cn->n.history_kept += take_prev;
  }
  *hist = next;
  // One shadow ray, to L's vertex or E's connection: resampled between the two.
  const float both = total + w_e;
  if (both > 0.0f) {
    const int take_e = ris_accept(rng_next(&cn->rr), both, w_e);
    const float3 c = take_e ? cn->he.c : c_l;
    ++cn->n.rays;
    cn->n.mis_rays += take_e;
    const Ray ray = take_e ? cn->he.ray : ray_l;
    connect_term(cn, c * ris_contribution_weight(both, luminance(c), 1.0f), &ray,
                 PR_REC_ADD | PR_REC_COUNTED);
  }
  hr->slot = cn->he.slot = PR_INVALID_INDEX;
  hr->p_sum = cn->he.p_sum = 0.0f;
}

// Strategy E: connections from Y, the non-delta first hit of the BSDF sample taken at the eye
// vertex at xp with solid-angle pdf pdf_x, to the vertices k >= 0 of the sample's light paths,
// each weighted by its share of the MIS: one partial sum.
PR_INLINE void strategy_sampled_vertex(Connector* cn, float3 xp, float pdf_x, const EyePoint* y,
                                       int history) {
  const SceneData* s = cn->s;
  const ReuseParams* rp = cn->rp;
  const float3 dxy = y->h.p - xp;
  const float dxy2 = dot(dxy, dxy);
  if (!(dxy2 > 0.0f) || !(pdf_x > 0.0f)) return;
  const float p_e = solid_angle_to_area_pdf(pdf_x, fabs(dot(y->f.ng, dxy)) / sqrt(dxy2), dxy2);
  for (uint c = 0u; c < rp->paths_per_pixel; ++c) {
    const uint slot = connector_slot(cn, c);
    const uint count = cn->headers[slot].vertex_count;
    __global const LightVertex* v = cn->vertices + (size_t)slot * rp->stride;
    for (uint k = 0u; k < count && y->depth + k + 1u <= rp->max_depth; ++k) {
      const float3 zp = vertex_pos(v + k);
      const float3 d = zp - y->h.p;
      const float dist2 = dot(d, d);
      if (!(dist2 > 0.0f)) continue;
      const float3 dir = d * (1.0f / sqrt(dist2));  // from Y to z
      if (!surface_side_ok(s, &y->h, &y->f, y->wo, dir)) continue;
      float3 zng, f_z, tr = make_float3(1.0f, 1.0f, 1.0f);
      float pdf_l, cos_z, corr = 1.0f;
      if (k == 0u) {
        // Vertex 0: the point on the light; f_z * tpz is its emission over the position pdf.
        const Light lz = s->lights.lights[cn->headers[slot].light];
        if (!light_joins_vertex0(lz.type)) continue;
        zng = oct_decode(v[0].ng_oct);
        // Along -dir the light sends its emission towards Y (a spot's cone).
        pdf_l = light_pdf_emit_dir(&lz, zng, -dir);
        // The stored throughput is emission over (position pdf times pdf_l / cos), before a
        // spot's falloff: times pdf_l and the falloff towards Y, emission over the position pdf.
        const int tri = light_is_triangle(lz.type);
        cos_z = tri ? fabs(dot(zng, dir)) : 1.0f;
        f_z = make_float3(1.0f, 1.0f, 1.0f) *
              (tri ? 0.5f * PR_INV_PI : pdf_l * light_falloff(&lz, -dir));
      } else {
        const LightPoint z = light_point(s, v + k);
        float pdf_rev_unused;
        if (z.delta || !light_point_eval(s, &z, dir, &f_z, &pdf_l, &pdf_rev_unused, &cos_z, &corr))
          continue;
        zng = z.f.ng;
        if (bsdf_transmits(&y->f.bsdf) || bsdf_transmits(&z.f.bsdf))
          tr = segment_transmittance(s, &y->h, &z.h, dir, sqrt(dist2));
      }
      const float p_l = solid_angle_to_area_pdf(pdf_l, fabs(dot(y->f.ng, dir)), dist2);
      const float w = mis_connection_weight(PR_STRATEGY_E, p_l, p_e, rp->mis_threshold);
      if (!(w > 0.0f)) continue;
      float pdf_unused;
      float3 f_y = eye_point_eval(y, dir, &pdf_unused);
      if (k == 0u && bsdf_transmits(&y->f.bsdf))
        tr = segment_transmittance(s, &y->h, 0, dir, sqrt(dist2));
      f_y = f_y * tr;
      const float3 tpz = make_float3(v[k].tp_r, v[k].tp_g, v[k].tp_b);
      const Ray r = (k == 0u && v[0].prim == PR_INVALID_INDEX)
                        ? surface_ray(s, &y->h, dir, sqrt(dist2) * (1.0f - 1e-4f))
                        : surface_ray_to(s, &y->h, zp, zng);
      uint clamped = 0u;
      const float3 value = connection_value(cn, y->tp, f_y, fabs(dot(y->f.n, dir)), tpz, f_z, cos_z,
                                            dist2, corr, w, history ? 1.0f : cn->inv_c, &clamped);
      if (history) {
        cn->n.clamped += clamped;
        history_offer(cn, &cn->he, value, r, slot, k);
      } else {
        connection(cn, value, clamped, r, PR_STRATEGY_E);
      }
    }
  }
  connect_close(cn);
}

// Next-event estimation at x, weighted against the BSDF sample's emitter hit where x can
// still take one (its draws are skipped otherwise, to keep the stream's layout). One term.
PR_INLINE void strategy_next_event(Connector* cn, const EyePoint* x, Rng* rng, uint* shadow_rays) {
  if (x->depth + 1u > cn->rp->max_depth) {
    rng_skip(rng, PR_NEXT_EVENT_DRAWS);
    return;
  }
  Ray shadow;
  float3 c;
  if (!next_event(cn->s, &x->h, &x->f, x->wo, x->depth + 1u < cn->rp->max_depth, rng, &shadow, &c,
                  0))
    return;
  ++*shadow_rays;
  connect_term(cn, x->tp * c, &shadow, PR_REC_ADD);
}

// A Connector's reservoirs, counts and terms, all empty.
PR_INLINE void connector_empty(Connector* cn) {
  cn->res.w_sum = 0.0f;
  cn->res.candidates = 0u;
  cn->n.candidates = cn->n.rays = cn->n.mis_rays = cn->n.unoccluded = cn->n.clamped = 0u;
  cn->n.history_kept = cn->n.history_dropped = 0u;
  cn->hr.slot = cn->he.slot = PR_INVALID_INDEX;
  cn->hr.k = cn->he.k = 0u;
  cn->hr.p_sum = cn->he.p_sum = 0.0f;
  cn->n_rec = cn->overflow = cn->members = 0u;
  cn->L = cn->g = make_float3(0.0f, 0.0f, 0.0f);
  cn->at_own = 0;
  cn->rec_time = 0u;
}

// Adds an eye sample's counts to the frame's counters.
PR_INLINE void connect_count(const ConnectCounts* n, uint shadow_rays, uint bounce_rays,
                             __global uint* all_counters) {
  __global uint* counters = counter_lane(all_counters, PR_C_ROW);
  if (shadow_rays) atomic_add(counters + PR_C_SHADOW_RAYS, shadow_rays);
  if (n->rays) atomic_add(counters + PR_C_CONNECT_RAYS, n->rays);
  if (bounce_rays) atomic_add(counters + PR_C_BOUNCE_RAYS, bounce_rays);
  if (n->mis_rays) atomic_add(counters + PR_C_MIS_RAYS, n->mis_rays);
  if (n->clamped) atomic_add(counters + PR_C_CLAMPED, n->clamped);
  if (n->candidates) atomic_add(counters + PR_C_CANDIDATES, n->candidates);
  if (n->unoccluded) atomic_add(counters + PR_C_CONNECTED, n->unoccluded);
  if (n->history_kept) atomic_add(counters + PR_C_HISTORY_KEPT, n->history_kept);
  if (n->history_dropped) atomic_add(counters + PR_C_HISTORY_DROPPED, n->history_dropped);
}

// Strategy T makes the paths of an x_1 seen straight from the camera (--eye-paths: L at x_1
// alone): its camera factor at p, 0 where T cannot make them.
PR_INLINE float connect_camera_factor(const ReuseParams* rp, const CameraParams* cam,
                                      const EyeVertex* e, float3 p) {
  if (!PR_EYE_PATHS || e->depth != 1u || !(rp->lt_scale > 0.0f)) return 0.0f;
  return eye_paths_camera_factor(rp->lt_scale, camera_cos3_d2(cam, p));
}

// The connector of pixel i's sample `sample`: its light paths, weights, reservoir draws, history
// and where its terms go (slot_offset: 0 without a history, PathReuse::renderFrame).
PR_INLINE void connector_begin(Connector* cn, const SceneData* s, const ReuseParams* rp,
                               __global const PathHeader* headers,
                               __global const LightVertex* vertices,
                               __global const EyePathRatio* ratios, uint i, uint sample,
                               uint history_cap, uint slot_offset, __global ShadowRay* rec,
                               uint cap) {
  cn->s = s;
  cn->rp = rp;
  cn->headers = headers;
  cn->vertices = vertices;
  cn->j = i * rp->spp + sample;
  cn->inv_c = 1.0f / (float)rp->paths_per_pixel;
  cn->mis_c = rp->eye_count / (float)rp->paths_per_pixel;
  cn->rr = rng_make(rp->seed, PR_RNG_RESAMPLE, rp->frame, i, sample);
  cn->history_cap = history_cap;
  cn->ratios = ratios;
  cn->slot_offset = slot_offset;
  cn->rec = rec;
  cn->cap = cap;
  connector_empty(cn);
}

PR_KERNEL void connect(PR_PARAMS(PR_ARGS_CONNECT)) {
  const uint q = (uint)get_global_id(0);  // the records' index; the pixel where not listed
  if (q >= record_end || q >= (listed ? list_count : rp.pixel_count)) return;
  const uint i = listed ? pixels[q] : q;
  const EyeVertex e = eye[i];
#if PR_EYE_PATHS
  record_counts[q - record_first] = 0u;  // until the terms are written
#endif
  if (e.prim == PR_INVALID_INDEX) return;
  // The scene and camera at the sample's time, as its eye path saw them (--shutter).
  SceneData s = PR_SCENE();
  scene_at_sample(&s, rp.seed, rp.frame, i, sample);
  const CameraParams c =
      cam_step_count > 1u
          ? camera_at_time(cam_steps, cam_step_count, shutter_time(rp.seed, rp.frame, i, sample))
          : cam;
  // Its own stream, apart from eye_hit's.
  Rng rng = rng_make(rp.seed, PR_RNG_CONNECT, rp.frame, i, sample);
  Connector cn;
  connector_begin(&cn, &s, &rp, headers, vertices, ratios, i, sample, history_cap, slot_offset,
                  records + (size_t)(q - record_first) * record_cap, record_cap);
  EyePoint x = eye_point_at(&s, e.prim, e.inst, e.b1, e.b2, make_float3(e.wx, e.wy, e.wz),
                            make_float3(e.tp_r, e.tp_g, e.tp_b), e.depth);
  cn.cam_x = connect_camera_factor(&rp, &c, &e, x.h.p);
  // As pt_shade flags the eye path (PR_EYE_PREFIX_STILL): x_1 the first hit, its segment still.
  cn.at_own = PR_EYE_PATHS && s.lights.sweep_count > 0u && e.depth == 1u &&
              camera_segment_still(&s, camera_position(&c), make_float3(e.px, e.py, e.pz));
  uint shadow_rays = 0u, bounce_rays = 0u;
  // The first eye vertex's connections go to the history, where there is one.
  int history_open = history_cap > 0u;
  __global ConnectionHistory* hist = history + ((size_t)i * rp.spp + sample);
  for (uint vertex = 0u;; ++vertex) {
    // The history holds the first eye vertex's connections alone (resolved after the loop).
    if (vertex > 0u) history_open = 0;
    // The previous eye vertex's kept connections (each vertex of a delta chain has its own).
    reservoir_resolve(&cn);
    // With --eye-paths, the path tracer's eye paths make everything but L's connections at x.
    if (!PR_EYE_PATHS) strategy_next_event(&cn, &x, &rng, &shadow_rays);
    strategy_light_vertices(&cn, &x, history_open);
    if (PR_EYE_PATHS) break;
    // The completeness extension: one BSDF direction, kept only through delta surfaces.
    const float u0 = rng_next(&rng);
    const float2 u12 = rng_next2(&rng);
    if (x.depth + 1u >= rp.max_depth) break;
    PathStep step;
    if (!path_step(&s, &x.h, &x.f, x.wo, u0, u12.x, u12.y, PR_RADIANCE, &step)) break;
    float3 d = step.wi;
    const float pdf = step.pdf;
    const int delta = step.delta;
    float3 t2 = x.tp * step.weight;
    uint depth = x.depth;
    Ray ray = surface_ray(&s, &x.h, d, PR_INF_F);
    int found = 0;
    for (uint chain = 0u; depth < rp.max_depth; ++chain) {
      Hit hit;
      ++bounce_rays;
      if (!trace_closest(&s, ray, &hit)) {
        // The environment: the sample from x shares it with next-event estimation at x.
        const float3 le = environment_radiance(&s, d);
        if (max3(le) > 0.0f)
          connect_term(
              &cn,
              t2 * le *
                  (chain == 0u ? power_heuristic(
                                     pdf, environment_pdf(&s, x.h.p, frame_light_normal(&x.f), d))
                               : 1.0f),
              0, PR_REC_ADD);
        break;
      }
      const SurfaceHit h = surface_at(&s.sd, hit.prim, hit.inst, hit.u, hit.v);
      t2 = t2 * volume_transmittance(&s, &h, d, hit.t);
      const EyePoint y = eye_point(&s, &h, -d, t2, depth + 1u);
      const int is_delta = bsdf_is_delta(&y.f.bsdf);
      // An emitter met by the sample from x: its MIS share against next-event estimation at x.
      if (chain == 0u && (s.sd.materials[h.material].flags & PR_MAT_EMISSIVE))
        connect_term(&cn,
                     t2 * surface_emission(&s, &h) *
                         power_heuristic(pdf, emitter_pdf(&s, &h, x.h.p, frame_light_normal(&x.f))),
                     0, PR_REC_ADD);
      if (chain == 0u && !is_delta) {
        // Strategy L at x counts these paths, apart from E's share.
        if (rp.mis_threshold > 0.0f && !delta)
          strategy_sampled_vertex(&cn, x.h.p, pdf, &y, history_open);
        break;
      }
      ++depth;
      // Emission behind at least one delta bounce (the first delta surface's own emission is
      // next-event estimation's at x).
      if (chain > 0u && (s.sd.materials[h.material].flags & PR_MAT_EMISSIVE))
        connect_term(&cn, t2 * surface_emission(&s, &h), 0, PR_REC_ADD);
      if (!is_delta) {
        x = y;
        found = 1;
        break;
      }
      if (depth >= rp.max_depth) break;
      const float w0 = rng_next(&rng);
      const float2 w12 = rng_next2(&rng);
      PathStep chained;
      if (!path_step(&s, &y.h, &y.f, y.wo, w0, w12.x, w12.y, PR_RADIANCE, &chained)) break;
      d = chained.wi;
      t2 = t2 * chained.weight;
      ray = surface_ray(&s, &h, d, PR_INF_F);
    }
    if (!found || !(max3(x.tp) < PR_INF_F)) break;
  }
  if (history_cap > 0u) history_resolve(&cn, &e, hist, changed, frame_stamp);
  reservoir_resolve(&cn);
#if PR_EYE_PATHS
  record_counts[q - record_first] = cn.n_rec;
  if (cn.overflow) atomic_inc(counter_lane(counters, PR_C_ROW) + PR_C_RECORD_OVERFLOW);
#else
  radiance[i] += (float4)(cn.L.x, cn.L.y, cn.L.z, 0.0f);
#endif
  connect_count(&cn.n, shadow_rays, bounce_rays, counters);
}
