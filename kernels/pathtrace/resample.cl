// pt_resample (--resample): one work-item per pixel of the film's rows [first, end). Its
// sample's two reservoirs, the paths' (shared/resample.h) and x_1's direct light's
// (shared/resample_direct.h), are each merged with those of rsp.neighbors pixels within
// rsp.radius and, with `temporal`, with the previous frame's final reservoir at the pixel where
// x_1 was then seen. The pixel's own reservoir is the canonical one. A path is moved to this
// pixel's x_1 by reconnection, a light's point unchanged (Jacobian 1), and weighed by pairwise
// MIS with confidences (shared/mis.h) against the canonical sample: the other domain's sample
// needs this pixel's target at it (one shadow ray), and the canonical sample the other domain's
// target at it (one more). The previous frame's samples are taken only where nothing that moved
// comes near them (rs_temporal_ok, di_temporal_ok), the same test both ways. Each kept sample's
// f W, times the camera's weight of x_1, goes into the sample's radiance, and the reservoirs,
// with x_1, to history_out for the next frame, stamped with `stamp` (the previous frame's record
// counts only if its stamp is one less: a device's rows move between frames). Neighbours outside
// [first, end) or without an x_1 are domains that make no samples here and are left out, which
// keeps the weights a partition of unity. Under --noise-threshold only the pass's listed pixels
// resample (PR_ARGS_PIXEL_LIST); pt_generate left the others without an x_1, so they are such
// neighbours, and their records stay as an earlier frame left them, which the next one rejects
// by their stamps.
#include "shared/path_state.h"
#include "shared/resample.h"
#include "shared/resample_direct.h"

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

// The camera that sample `sample` of pixel i sees through: under --shutter, at its time.
PR_INLINE CameraParams rs_camera_at(const CameraParams* cam, __global const CameraParams* steps,
                                    uint count, uint seed, uint frame, uint i, uint sample) {
  return count > 1u ? camera_at_time(steps, count, shutter_time(seed, frame, i, sample)) : *cam;
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
  if (rs_occluded(s, x, seg)) return 0.0f;
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

// Where a merge stands: the sum of resampling weights, the canonical sample's MIS terms and the
// sample kept (PR_RS_KEPT_*, or its domain), with its f and target here (and, for a path, its new
// segment's g).
typedef struct {
  float w_sum, canon;
  float3 f;
  float p, g;
  uint kept;
} RsMerge;

#define PR_RS_KEPT_NONE 0xffffffffu
#define PR_RS_KEPT_CANONICAL 0xfffffffeu

PR_INLINE RsMerge rs_merge_begin(void) {
  RsMerge m;
  m.w_sum = m.canon = m.p = m.g = 0.0f;
  m.f = make_float3(0.0f, 0.0f, 0.0f);
  m.kept = PR_RS_KEPT_NONE;
  return m;
}

// Offers a sample of resampling weight w (f, target p and g here; domain d) to merge mg.
PR_INLINE void rs_merge_take(RsMerge* mg, float w, float u, float3 f, float p, float g, uint d) {
  if (!(w > 0.0f) || !(w < PR_INF_F)) return;
  mg->w_sum += w;
  if (!ris_accept(u, mg->w_sum, w)) return;
  mg->f = f;
  mg->p = p;
  mg->g = g;
  mg->kept = d;
}

// Whether path r may move between x and the x_1 xi of another domain (past: the previous frame's;
// under a shutter, another time: rs_path_still).
PR_INLINE int rs_path_movable(const SceneData* s, const RsPrimary* x, const RsPrimary* xi,
                              __global const PathReservoir* r, int past,
                              __global const MovedInstance* moved, const ResampleParams* rsp,
                              const RsSweeps* w) {
  return (!past || rs_temporal_ok(s, moved, rsp->moved_count, r, xi, x, rsp->prev_known)) &&
         (rs_sweeps_none(w, past) ||
          rs_path_still(w, past, r, surface_at(&s->sd, r->prim, r->inst, r->b1, r->b2).p, past,
                        xi->h.p));
}

// Domain d's path ri (confidence c_i; past: the previous frame's, seen from xi in scene si, at
// its sample's time) into mg, and the canonical path rc's MIS term against that domain. same: xi
// is x (the previous frame's x_1 is this one's): the shift is then the identity both ways, and
// where the path meets nothing that moved, its target, f and g are the ones it keeps (its
// segments seen clear when it was made).
PR_INLINE void rs_merge_path(const SceneData* s, const SceneData* si, const RsPrimary* x,
                             const RsPrimary* xi, __global const PathReservoir* rc,
                             __global const PathReservoir* ri, int past, int same, float c_i,
                             float kf, float total, float u, uint d,
                             __global const MovedInstance* moved, const ResampleParams* rsp,
                             const RsSweeps* w, RsMerge* mg, uint* traced) {
  const int has_c = rs_has_path(rc);
  if (rs_has_path(ri) && rs_path_movable(s, x, xi, ri, past, moved, rsp, w)) {
    float3 f = make_float3(ri->f_r, ri->f_g, ri->f_b);
    float g = ri->g_src, jac = 1.0f;
    const float p = same ? ri->p_hat : rs_target_at(s, x, ri, rsp, &f, &g, &jac, traced);
    if (p > 0.0f && jac > 0.0f) {
      const float m = mis_pairwise_neighbor(c_i, ri->p_hat / jac, 1.0f, p, kf, total);
      rs_merge_take(mg, gris_weight(m, p, ri->w_sum / ri->p_hat * jac), u, f, p, g, d);
    }
  }
  float p_back = 0.0f;
  if (has_c && rs_path_movable(s, x, xi, rc, past, moved, rsp, w)) {
    float3 f;
    float g, jac = 1.0f;
    const float p = same ? rc->p_hat : rs_target_at(si, xi, rc, rsp, &f, &g, &jac, traced);
    p_back = p * jac;
  }
  mg->canon += mis_pairwise_canonical_term(c_i, p_back, 1.0f, has_c ? rc->p_hat : 0.0f, kf, total);
}

// Whether light r may move between x and the x_1 xi of another domain, as rs_path_movable.
PR_INLINE int di_movable(const SceneData* s, const RsPrimary* x, const RsPrimary* xi,
                         __global const DirectReservoir* r, int past,
                         __global const MovedInstance* moved, const ResampleParams* rsp,
                         const RsSweeps* w) {
  return (!past || di_temporal_ok(s, moved, rsp->moved_count, r, xi, x, rsp->prev_known)) &&
         di_still(s, w, past, r, past, xi->h.p);
}

// The same for the direct light's reservoirs (Jacobian 1).
PR_INLINE void rs_merge_direct(const SceneData* s, const SceneData* si, const RsPrimary* x,
                               const RsPrimary* xi, __global const DirectReservoir* dc,
                               __global const DirectReservoir* di, int past, int same, float c_i,
                               float kf, float total, float u, uint d,
                               __global const MovedInstance* moved, const ResampleParams* rsp,
                               const RsSweeps* w, RsMerge* mg, uint* traced) {
  const int has_c = di_has_light(dc);
  if (di_has_light(di) && di_movable(s, x, xi, di, past, moved, rsp, w)) {
    float3 f = make_float3(di->f_r, di->f_g, di->f_b);
    const float p = same ? di->p_hat : di_target_at(s, x, di, &f, traced);
    if (p > 0.0f) {
      const float m = mis_pairwise_neighbor(c_i, di->p_hat, 1.0f, p, kf, total);
      rs_merge_take(mg, gris_weight(m, p, di->w_sum / di->p_hat), u, f, p, 0.0f, d);
    }
  }
  float p_back = 0.0f;
  if (has_c && di_movable(s, x, xi, dc, past, moved, rsp, w)) {
    float3 f;
    p_back = same ? dc->p_hat : di_target_at(si, xi, dc, &f, traced);
  }
  mg->canon += mis_pairwise_canonical_term(c_i, p_back, 1.0f, has_c ? dc->p_hat : 0.0f, kf, total);
}

// The canonical sample (target p_c, sum of weights w_c, f at its own pixel) into mg, once every
// domain's term is in; `domains` of them.
PR_INLINE void rs_merge_canonical(RsMerge* mg, float p_c, float w_c, float3 f, float g,
                                  uint domains, float total, float u) {
  const float m = domains ? mis_pairwise_canonical(mg->canon, 1.0f, total) : 1.0f;
  rs_merge_take(mg, gris_weight(m, p_c, w_c / p_c), u, f, p_c, g, PR_RS_KEPT_CANONICAL);
}

// A merge's kept sample's share of the radiance: f W times the camera's weight of x_1.
PR_INLINE void rs_merge_add(const RsMerge* mg, float3 tp, __global float4* radiance) {
  const float3 c = tp * mg->f * (mg->w_sum / mg->p);
  if (max3(c) < PR_INF_F) *radiance += (float4)(c.x, c.y, c.z, 0.0f);
}

// The history record of pixel j's sample: its x_1 and stamp, with empty reservoirs.
PR_INLINE void rs_history_start(__global PathHistory* out, const EyeVertex* e, uint stamp) {
  out->prim = e->prim;
  out->inst = e->inst;
  out->b1 = e->b1;
  out->b2 = e->b2;
  out->wx = e->wx;
  out->wy = e->wy;
  out->wz = e->wz;
  out->stamp = stamp;
  out->r.prim = PR_INVALID_INDEX;
  out->r.w_sum = 0.0f;
  out->r.m = 0.0f;
  out->d.light = PR_INVALID_INDEX;
  out->d.w_sum = 0.0f;
  out->d.m = 0.0f;
}

// Whether two eye vertices are the same x_1 seen the same way.
PR_INLINE int rs_same_eye(const EyeVertex* a, const EyeVertex* b) {
  return a->prim == b->prim && a->inst == b->inst && a->b1 == b->b1 && a->b2 == b->b2 &&
         a->wx == b->wx && a->wy == b->wy && a->wz == b->wz;
}

// Whether the previous frame's record h continues x_1 at x (whose point was p then, seen from
// the previous camera at c): the same instance, its shapes then known where it moved (prev_known,
// sp), within a tenth of the camera's distance of p and seen about the same way (shading normals
// within 26 degrees). Another surface's paths would come in at the record's full confidence.
PR_INLINE int rs_history_similar(const SceneData* s, const SceneData* sp, const RsPrimary* x,
                                 float3 p, float3 c, uint prev_known,
                                 __global const PathHistory* h) {
  if (h->inst != x->h.inst || (!prev_known && !rs_unmoved(s, h->inst))) return 0;
  const SurfaceHit then = surface_at(&sp->sd, h->prim, h->inst, h->b1, h->b2);
  const float3 d = then.p - p, v = p - c;
  return dot(then.ns, x->h.ns) > 0.9f && dot(d, d) <= 0.01f * dot(v, v);
}

// The previous frame's record that pixel sample x (its x_1 at p then) continues, or
// PR_INVALID_INDEX: the one where the previous camera saw p where it is similar
// (rs_history_similar), else the first similar one of that pixel's 8 neighbours, the 4 nearest
// first (an edge or a thin part misses one pixel's record about as often as it meets it).
PR_INLINE uint rs_history_pixel(const SceneData* s, const SceneData* sp, const RsPrimary* x,
                                const ResampleParams* rsp, const CameraParams* prev_cam, float3 p,
                                uint first, uint end, __global const PathHistory* history,
                                uint stamp) {
  const uint q0 = camera_pixel(prev_cam, p);
  if (q0 == PR_INVALID_INDEX) return PR_INVALID_INDEX;
  const float3 c = camera_position(prev_cam);
  const int dx[9] = {0, 1, -1, 0, 0, 1, -1, 1, -1}, dy[9] = {0, 0, 0, 1, -1, 1, 1, -1, -1};
  for (int n = 0; n < 9; ++n) {
    const int qx = (int)(q0 % prev_cam->width) + dx[n], qy = (int)(q0 / prev_cam->width) + dy[n];
    if (qx < 0 || qy < 0 || qx >= (int)prev_cam->width || qy >= (int)prev_cam->height) continue;
    const uint q = (uint)qy * prev_cam->width + (uint)qx;
    if (q < first || q >= end || history[q].stamp + 1u != stamp ||
        history[q].prim == PR_INVALID_INDEX)
      continue;
    if (rs_history_similar(s, sp, x, p, c, rsp->prev_known, history + q)) return q;
  }
  return PR_INVALID_INDEX;
}

PR_KERNEL void pt_resample(PR_PARAMS(PR_ARGS_PT_RESAMPLE_SPATIAL)) {
  const uint w = (uint)get_global_id(0);
  if (listed ? w >= list_count : w + first >= end) return;
  const uint j = listed ? pixels[w] : w + first;  // a listed launch has the list's length
  const EyeVertex e = eye[j];
  __global PathHistory* out = history_out + j;
  rs_history_start(out, &e, stamp);
  if (e.prim == PR_INVALID_INDEX) return;  // no x_1: nothing was resampled
  // The scene at this sample's time (--shutter; its x_1's and paths' time).
  SceneData s = PR_SCENE();
  scene_at_sample(&s, seed, frame, j, sample);
  const int timed = s.geom.motion_steps > 1u || s.lights.motion_steps > 1u;
  // The previous frame's shapes, at that frame's time, on which its x_1 are rebuilt
  // (rsp.prev_known: they are known; they differ from this frame's only on what moved).
  SceneData sp = s;
  sp.sd.vertices = prev_vertices;
  sp.sd.instances = prev_instances;
  sp.sd.motion_steps = 1u;
  RsSweeps sw;
  sw.now = s.lights.sweeps;
  sw.now_count = s.lights.sweep_count;
  sw.then = prev_sweeps;
  sw.then_count = prev_sweep_count;
  __global const PathReservoir* rc = rs_res + j;
  __global const DirectReservoir* dc = di_res + j;
  const CameraParams cx = rs_camera_at(&cam, cam_steps, cam_step_count, seed, frame, j, sample);
  const RsPrimary x = rs_primary(&s, &e, &rsp, &cx);
  Rng rng = rng_make(seed, PR_RNG_PATH_RESAMPLE, frame, j, sample);
  rng.dim = 0x10000u;  // apart from the paths' offers (PR_RS_DIM)
  Rng rng_d = rng;
  rng_d.dim = 0x20000u;  // the direct light's merge
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
  // Where the previous frame saw x_1: on what moved, where its point was then.
  const int x_moved = !rs_unmoved(&s, e.inst);
  const float3 p_then =
      x_moved && rsp.prev_known ? surface_at(&sp.sd, e.prim, e.inst, e.b1, e.b2).p : x.h.p;
  const uint q =
      temporal ? rs_history_pixel(&s, &sp, &x, &rsp, &prev_cam, p_then, first, end, history, stamp)
               : PR_INVALID_INDEX;
  // Each reservoir's confidence of the previous frame (0: not a domain of that reservoir).
  const float c_t = q != PR_INVALID_INDEX ? fmin(history[q].r.m, rsp.max_m) : 0.0f;
  const float c_td = q != PR_INVALID_INDEX ? fmin(history[q].d.m, rsp.max_m) : 0.0f;
  const uint dom_p = k + (c_t > 0.0f ? 1u : 0u), dom_d = k + (c_td > 0.0f ? 1u : 0u);
  const float total_p = 1.0f + (float)k + c_t, total_d = 1.0f + (float)k + c_td;
  const int has_c = rs_has_path(rc), has_dc = di_has_light(dc);
  RsMerge mp = rs_merge_begin(), md = rs_merge_begin();
  uint traced = 0u;
  for (uint d = 0u; d < k + (q != PR_INVALID_INDEX ? 1u : 0u); ++d) {
    const int past = d == k;
    const EyeVertex ei = past ? rs_history_eye(history + q) : eye[nb[d]];
    // The same x_1 seen the same way, where it did not move: the shift is the identity.
    const int same = past && !x_moved && rs_same_eye(&ei, &e);
    // A neighbour's sample is at its own time: its scene and camera then.
    SceneData si;
    const SceneData* sc_i = &s;
    if (!past && timed) {
      si = s;
      scene_at_sample(&si, seed, frame, nb[d], sample);
      sc_i = &si;
    }
    RsPrimary xi;
    if (same) {
      xi = x;
    } else if (has_c || has_dc || past) {
      const CameraParams ci =
          past ? cam : rs_camera_at(&cam, cam_steps, cam_step_count, seed, frame, nb[d], sample);
      xi = rs_primary(past ? &sp : sc_i, &ei, &rsp, &ci);
    }
    xi.then_moved = past && !same && !rs_unmoved(&s, ei.inst);
    const float u_d = rng_next(&rng_d);
    if (!past || c_t > 0.0f)
      rs_merge_path(&s, sc_i, &x, &xi, rc, past ? &history[q].r : rs_res + nb[d], past, same,
                    past ? c_t : 1.0f, (float)dom_p, total_p, past ? u_t : un[d], d, moved, &rsp,
                    &sw, &mp, &traced);
    if (!past || c_td > 0.0f)
      rs_merge_direct(&s, sc_i, &x, &xi, dc, past ? &history[q].d : di_res + nb[d], past, same,
                      past ? c_td : 1.0f, (float)dom_d, total_d, u_d, d, moved, &rsp, &sw, &md,
                      &traced);
  }
  const float u_c = rng_next(&rng), u_dc = rng_next(&rng_d);
  if (has_c)
    rs_merge_canonical(&mp, rc->p_hat, rc->w_sum, make_float3(rc->f_r, rc->f_g, rc->f_b), rc->g_src,
                       dom_p, total_p, u_c);
  if (has_dc)
    rs_merge_canonical(&md, dc->p_hat, dc->w_sum, make_float3(dc->f_r, dc->f_g, dc->f_b), 0.0f,
                       dom_d, total_d, u_dc);
  if (traced) atomic_add(counter_lane(rays, PR_PT_ROW) + PR_PT_RECONNECT, traced);
  out->r.m = total_p;
  out->d.m = total_d;
  if (mp.p > 0.0f) {
    rs_merge_add(&mp, x.tp, radiance + j);
    __global const PathReservoir* kept = mp.kept == PR_RS_KEPT_CANONICAL ? rc
                                         : mp.kept == k                  ? &history[q].r
                                                                         : rs_res + nb[mp.kept];
    rs_keep(&out->r, kept, mp.f, mp.p, mp.g, mp.w_sum, total_p);
  }
  if (md.p > 0.0f) {
    rs_merge_add(&md, x.tp, radiance + j);
    __global const DirectReservoir* kept = md.kept == PR_RS_KEPT_CANONICAL ? dc
                                           : md.kept == k                  ? &history[q].d
                                                                           : di_res + nb[md.kept];
    di_keep(&out->d, kept, md.f, md.p, md.w_sum, total_d);
  }
}
