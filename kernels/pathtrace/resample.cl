// pt_resample (--resample): one work-item per pixel of the film's rows [first, end). Its sample's
// reservoir (the canonical one: a path of its own eye path, chosen by pt_shade and pt_shadow) is
// merged with those of rsp.neighbors pixels within rsp.radius, each path moved to this pixel's
// x_1 by reconnection (shared/resample.h) and weighed by pairwise MIS (shared/mis.h) against the
// canonical one: the neighbour's path needs this pixel's target at it (one shadow ray), and the
// canonical path the neighbour's target at it (one more). The kept path's f W, times the camera's
// weight of x_1, goes into the sample's radiance. Neighbours outside [first, end) count as
// pixels that make no paths, so a device's rows are resampled alone (shared/mis.h: the weights
// stay a partition of unity).
#include "shared/path_state.h"
#include "shared/resample.h"

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

// Path r moved to x by reconnection: its target there (shadow ray included), its f in *f and the
// Jacobian in *jac (0 where the shift fails or the segment is occluded).
PR_INLINE float rs_target_at(const SceneData* s, const RsPrimary* x,
                             __global const PathReservoir* r, const ResampleParams* rsp, float3* f,
                             float* jac, uint* traced) {
  float g;
  Ray seg;
  *f = rs_shift(s, x, r, rsp, &g, &seg);
  *jac = 0.0f;
  const float p = luminance(*f);
  if (!(p > 0.0f) || !(p < PR_INF_F)) return 0.0f;
  *traced += 1u;
  if (trace_occluded(s, seg)) return 0.0f;
  *jac = reconnection_jacobian(g, r->g_src);
  return p;
}

PR_KERNEL void pt_resample(PR_PARAMS(PR_ARGS_PT_RESAMPLE_SPATIAL)) {
  const uint j = (uint)get_global_id(0) + first;
  if (j >= end) return;
  const EyeVertex e = eye[j];
  if (e.prim == PR_INVALID_INDEX) return;  // no x_1: nothing was resampled
  const SceneData s = PR_SCENE();
  __global const PathReservoir* rc = rs_res + j;
  const RsPrimary x = rs_primary(&s, &e, &rsp);
  const float k = (float)rsp.neighbors;
  const int has_c = rc->prim != PR_INVALID_INDEX && rc->w_sum > 0.0f && rc->p_hat > 0.0f;
  Rng rng = rng_make(seed, PR_RNG_PATH_RESAMPLE, frame, j, sample);
  rng.dim = 0x10000u;  // apart from the paths' offers (PR_RS_DIM)
  float w_sum = 0.0f, canon_terms = 0.0f;
  float3 f_kept = make_float3(0.0f, 0.0f, 0.0f);
  float p_kept = 0.0f;
  uint traced = 0u;
  for (uint n = 0u; n < rsp.neighbors; ++n) {
    const uint i = rs_neighbor(&rsp, j, first, end, &rng);
    const float u = rng_next(&rng);
    const EyeVertex ei = i == PR_INVALID_INDEX ? e : eye[i];
    if (i == PR_INVALID_INDEX || ei.prim == PR_INVALID_INDEX) {
      canon_terms += 1.0f;  // a pixel without x_1 makes no path here
      continue;
    }
    __global const PathReservoir* ri = rs_res + i;
    // The neighbour's path, here.
    if (ri->prim != PR_INVALID_INDEX && ri->w_sum > 0.0f && ri->p_hat > 0.0f) {
      float3 f;
      float jac;
      const float p = rs_target_at(&s, &x, ri, &rsp, &f, &jac, &traced);
      if (p > 0.0f && jac > 0.0f) {
        const float m = mis_pairwise_neighbor(1.0f, ri->p_hat / jac, 1.0f, p, k);
        const float w = gris_weight(m, p, ri->w_sum / ri->p_hat * jac);
        if (w > 0.0f && w < PR_INF_F) {
          w_sum += w;
          if (ris_accept(u, w_sum, w)) {
            f_kept = f;
            p_kept = p;
          }
        }
      }
    }
    // The canonical path at the neighbour, for its own weight.
    float p_back = 0.0f;
    if (has_c) {
      const RsPrimary xi = rs_primary(&s, &ei, &rsp);
      float3 f;
      float jac;
      const float p = rs_target_at(&s, &xi, rc, &rsp, &f, &jac, &traced);
      p_back = p * jac;
    }
    canon_terms += mis_pairwise_canonical_term(1.0f, p_back, 1.0f, has_c ? rc->p_hat : 0.0f, k);
  }
  if (has_c) {
    const float m = rsp.neighbors ? mis_pairwise_canonical(canon_terms, k) : 1.0f;
    const float w = gris_weight(m, rc->p_hat, rc->w_sum / rc->p_hat);
    if (w > 0.0f && w < PR_INF_F) {
      w_sum += w;
      if (ris_accept(rng_next(&rng), w_sum, w)) {
        f_kept = make_float3(rc->f_r, rc->f_g, rc->f_b);
        p_kept = rc->p_hat;
      }
    }
  }
  if (traced) atomic_add(rays + PR_PT_RECONNECT, traced);
  if (!(p_kept > 0.0f)) return;
  const float3 c = x.tp * f_kept * (w_sum / p_kept);
  if (!(max3(c) < PR_INF_F)) return;
  radiance[j] += (float4)(c.x, c.y, c.z, 0.0f);
}
