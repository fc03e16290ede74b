// pt_resample (--resample): one work-item per pixel of the film's rows [first, end). Its sample's
// reservoir (the canonical one: a path of its own eye path, chosen by pt_shade and pt_shadow) is
// merged with those of rsp.neighbors pixels within rsp.radius and, with `temporal`, with the
// previous frame's final reservoir at the pixel where x_1 was then seen. Each path is moved to
// this pixel's x_1 by reconnection (shared/resample.h) and weighed by pairwise MIS with
// confidences (shared/mis.h) against the canonical one: the other domain's path needs this
// pixel's target at it (one shadow ray), and the canonical path the other domain's target at it
// (one more). The previous frame's paths are taken only where nothing that moved comes near
// them (rs_temporal_ok), the same test both ways. The kept path's f W, times the camera's weight
// of x_1, goes into the sample's radiance, and the reservoir, with x_1, to history_out for the
// next frame, stamped with `stamp` (the previous frame's record counts only if its stamp is one
// less: a device's rows move between frames). Neighbours outside [first, end) or without an x_1
// are domains that make no paths here and are left out, which keeps the weights a partition of
// unity.
#include "shared/path_state.h"
#include "shared/resample.h"

#define PR_RS_MAX_NEIGHBORS 16  // --resample-neighbors at most

// The pixel of neighbour slot n of pixel j (PR_INVALID_INDEX: outside the rows), drawn in a disk.
PR_INLINE uint rs_neighbor(const ResampleParams* rsp, uint j, uint first, uint end, Rng* rng) {
  const float2 u = rng_next2(rng);
  const float r = rsp->radius * sqrt(u.x);
  const float a = 2.0f * PR_PI * u.y;
  int dx = (int)rint(r * cos(a));
  int dy = (int)rint(r * sin(a));
  if (dx == 0 && dy == 0) dx = 1;  // never the pixel itself
  const int x = (int)(j % rsp->width) + dx;
  const int y = (int)(j / rsp->width) + dy;
  if (x < 0 || y < 0 || x >= (int)rsp->width || y >= (int)rsp->height) return PR_INVALID_INDEX;
  const uint i = (uint)y * rsp->width + (uint)x;
  return i >= first && i < end ? i : PR_INVALID_INDEX;
}

// Path r moved to x by reconnection: its target there (shadow ray included), its f in *f, the
// new segment's g in *g and the Jacobian in *jac (0 where the shift fails or is occluded).
PR_INLINE float rs_target_at(const SceneData* s, const RsPrimary* x,
                             __global const PathReservoir* r, const ResampleParams* rsp, float3* f,
                             float* g, float* jac, uint* traced) {
  Ray seg;
  *f = rs_shift(s, x, r, rsp, g, &seg);
  *jac = 0.0f;
  const float p = luminance(*f);
  if (!(p > 0.0f) || !(p < PR_INF_F)) return 0.0f;
  *traced += 1u;
  if (trace_occluded(s, seg)) return 0.0f;
  *jac = reconnection_jacobian(*g, r->g_src);
  return p;
}

// The kept path r as this pixel's, into out: its f, target p and segment's g here, the
// reservoir's sum of weights and confidence.
PR_INLINE void rs_keep(__global PathReservoir* out, __global const PathReservoir* r, float3 f,
                       float p, float g, float w_sum, float m) {
  *out = *r;
  out->f_r = f.x;
  out->f_g = f.y;
  out->f_b = f.z;
  out->g_src = g;
  out->p_hat = p;
  out->w_sum = w_sum;
  out->m = m;
}

PR_INLINE int rs_has_path(__global const PathReservoir* r) {
  return r->prim != PR_INVALID_INDEX && r->w_sum > 0.0f && r->p_hat > 0.0f;
}

// The previous frame's x_1 of history record h, as an EyeVertex.
PR_INLINE EyeVertex rs_history_eye(__global const PathHistory* h) {
  EyeVertex e;
  e.prim = h->prim;
  e.inst = h->inst;
  e.b1 = h->b1;
  e.b2 = h->b2;
  e.wx = h->wx;
  e.wy = h->wy;
  e.wz = h->wz;
  e.tp_r = e.tp_g = e.tp_b = 0.0f;
  e.px = e.py = e.pz = 0.0f;
  e.ng_oct = e.ns_oct = 0u;
  e.depth = 0u;
  return e;
}

PR_KERNEL void pt_resample(PR_PARAMS(PR_ARGS_PT_RESAMPLE_SPATIAL)) {
  const uint j = (uint)get_global_id(0) + first;
  if (j >= end) return;
  const EyeVertex e = eye[j];
  __global PathHistory* out = history_out + j;
  out->prim = e.prim;
  out->inst = e.inst;
  out->b1 = e.b1;
  out->b2 = e.b2;
  out->wx = e.wx;
  out->wy = e.wy;
  out->wz = e.wz;
  out->stamp = stamp;
  out->r.prim = PR_INVALID_INDEX;
  out->r.w_sum = 0.0f;
  out->r.m = 0.0f;
  if (e.prim == PR_INVALID_INDEX) return;  // no x_1: nothing was resampled
  const SceneData s = PR_SCENE();
  __global const PathReservoir* rc = rs_res + j;
  const RsPrimary x = rs_primary(&s, &e, &rsp);
  const int has_c = rs_has_path(rc);
  Rng rng = rng_make(seed, PR_RNG_PATH_RESAMPLE, frame, j, sample);
  rng.dim = 0x10000u;  // apart from the paths' offers (PR_RS_DIM)
  // The domains: neighbours with an x_1 (confidence 1), then the previous frame's pixel.
  uint nb[PR_RS_MAX_NEIGHBORS];
  float un[PR_RS_MAX_NEIGHBORS];
  uint k = 0u;
  for (uint n = 0u; n < rsp.neighbors && n < PR_RS_MAX_NEIGHBORS; ++n) {
    const uint i = rs_neighbor(&rsp, j, first, end, &rng);
    const float u = rng_next(&rng);
    if (i == PR_INVALID_INDEX || eye[i].prim == PR_INVALID_INDEX) continue;
    nb[k] = i;
    un[k] = u;
    ++k;
  }
  const float u_t = rng_next(&rng);
  float total = 1.0f + (float)k;
  uint q = PR_INVALID_INDEX;
  float c_t = 0.0f;
  if (temporal) {
    q = rs_project(&prev_cam, x.h.p);
    if (q != PR_INVALID_INDEX && (q < first || q >= end || history[q].stamp + 1u != stamp ||
                                  history[q].prim == PR_INVALID_INDEX))
      q = PR_INVALID_INDEX;
    if (q != PR_INVALID_INDEX) c_t = fmin(history[q].r.m, rsp.max_m);
    if (!(c_t > 0.0f)) q = PR_INVALID_INDEX;
    total += c_t;
  }
  const uint domains = k + (q != PR_INVALID_INDEX ? 1u : 0u);
  const float kf = (float)domains;
  float w_sum = 0.0f, canon_terms = 0.0f;
  float3 f_kept = make_float3(0.0f, 0.0f, 0.0f);
  float p_kept = 0.0f, g_kept = 0.0f;
  __global const PathReservoir* kept = 0;
  uint traced = 0u;
  for (uint d = 0u; d < domains; ++d) {
    const int past = d == k;
    __global const PathReservoir* ri = past ? &history[q].r : rs_res + nb[d];
    const EyeVertex ei = past ? rs_history_eye(history + q) : eye[nb[d]];
    const float c_i = past ? c_t : 1.0f;
    const int ri_path = rs_has_path(ri);
    RsPrimary xi;
    if (has_c || (past && ri_path)) xi = rs_primary(&s, &ei, &rsp);
    // The other domain's path, here.
    if (ri_path && (!past || rs_temporal_ok(&s, moved, rsp.moved_count, ri, xi.h.p, x.h.p))) {
      float3 f;
      float g, jac;
      const float p = rs_target_at(&s, &x, ri, &rsp, &f, &g, &jac, &traced);
      if (p > 0.0f && jac > 0.0f) {
        const float m = mis_pairwise_neighbor(c_i, ri->p_hat / jac, 1.0f, p, kf, total);
        const float w = gris_weight(m, p, ri->w_sum / ri->p_hat * jac);
        if (w > 0.0f && w < PR_INF_F) {
          w_sum += w;
          if (ris_accept(past ? u_t : un[d], w_sum, w)) {
            f_kept = f;
            p_kept = p;
            g_kept = g;
            kept = ri;
          }
        }
      }
    }
    // The canonical path in the other domain, for its own weight.
    float p_back = 0.0f;
    if (has_c && (!past || rs_temporal_ok(&s, moved, rsp.moved_count, rc, xi.h.p, x.h.p))) {
      float3 f;
      float g, jac;
      const float p = rs_target_at(&s, &xi, rc, &rsp, &f, &g, &jac, &traced);
      p_back = p * jac;
    }
    canon_terms +=
        mis_pairwise_canonical_term(c_i, p_back, 1.0f, has_c ? rc->p_hat : 0.0f, kf, total);
  }
  if (has_c) {
    const float m = domains ? mis_pairwise_canonical(canon_terms, 1.0f, total) : 1.0f;
    const float w = gris_weight(m, rc->p_hat, rc->w_sum / rc->p_hat);
    if (w > 0.0f && w < PR_INF_F) {
      w_sum += w;
      if (ris_accept(rng_next(&rng), w_sum, w)) {
        f_kept = make_float3(rc->f_r, rc->f_g, rc->f_b);
        p_kept = rc->p_hat;
        g_kept = rc->g_src;
        kept = rc;
      }
    }
  }
  if (traced) atomic_add(rays + PR_PT_RECONNECT, traced);
  out->r.m = total;
  if (!(p_kept > 0.0f)) return;
  const float3 c = x.tp * f_kept * (w_sum / p_kept);
  if (!(max3(c) < PR_INF_F)) return;
  radiance[j] += (float4)(c.x, c.y, c.z, 0.0f);
  rs_keep(&out->r, kept, f_kept, p_kept, g_kept, w_sum, total);
}
