// camera_splat (strategy T, --light-tracing): one work-item per arena slot. Joins each stored
// vertex z_k, k >= 2 (z_k and z_{k-1} non-delta, z_m held for m + 2 <= max_depth), of a light
// that takes part in the eye paths, to the pinhole camera: the pixel it projects to in the film's
// rows [first, end), a shadow ray, and T's share of the path (shared/eye_paths.h, "Strategy T")
// of its contribution, a light-tracing estimate over the N_L light paths, times `film_scale` (the
// film's samples per pixel, which its mean divides by). Sums them per pixel in fixed point with
// 32-bit atomics (shared/splat.h), which give the same sum in any order. Reads the arena, its
// ratios and the scene; adds to `splat` and the counters.
#include "shared/reuse.h"
// After reuse.h: its FP_CONTRACT OFF (shared/bvh.h) holds here too.
#include "shared/camera.h"
#include "shared/eye_paths.h"
#include "shared/splat.h"

// z_k's splat (light point y, arrival record vk), seen from the camera along `dir` (unit, camera
// to z_k), the path before it z_{k-1} (light point yp, whose ratios are r_prev): its value at the
// pixel times T's share of the path (against L too where l_ok: z_0 .. z_{k-1}, or the camera's
// segment to z_k, is the same at every time of the shutter interval); 0 where the camera cannot
// see it so or T takes no share.
PR_INLINE float3 camera_splat_value(const SceneData* s, const ReuseParams* rp,
                                    const CameraParams* cam, const LightPoint* y,
                                    const LightPoint* yp, PR_GLOBAL const LightVertex* vk,
                                    EyePathRatio r_prev, uint k, float3 dir, int l_ok) {
  const float3 zero = make_float3(0.0f, 0.0f, 0.0f);
  float3 f;
  float pdf_cam, pdf_x, cos_y, corr;
  if (!light_point_eval(s, y, dir, &f, &pdf_cam, &pdf_x, &cos_y, &corr)) return zero;
  // The path seen from x_1 = z_k: z_{k-1}'s pdfs of the step to z_k (the light tracer's) and of
  // the step to z_{k-2} arriving from z_k (the eye path's).
  const float3 w = vertex_dir(vk);  // z_{k-1} to z_k
  const float dz2 = vk->t * vk->t;
  float pdf_fwd, pdf_rev;
  bsdf_eval_mode(&yp->f.bsdf, yp->wprevl, to_local(w, yp->f.t, yp->f.b, yp->f.n), PR_IMPORTANCE,
                 &pdf_fwd, &pdf_rev);
  const float cos3_d2 = camera_cos3_d2(cam, y->h.p);
  const float t =
      eye_paths_camera_ratio(eye_paths_camera_factor(rp->lt_scale, cos3_d2), pdf_fwd, dz2);
  float n, h;
  eye_path_ratios(r_prev, k - 1u, pdf_x, fabs(dot(yp->h.ng, w)), dz2, pdf_rev,
                  rp->eye_count / (float)rp->paths_per_pixel, &n, &h);
  const float share = eye_paths_camera_share_l(t, n, h, l_ok);
  if (!(share > 0.0f)) return zero;
  // The pixel's importance W H / (A cos^3 d^2) (camera.h) over the N_L paths.
  const float importance =
      (float)(cam->width * cam->height) / (camera_plane_area(cam) * cos3_d2 * (float)rp->slots);
  const float3 tp = make_float3(vk->tp_r, vk->tp_g, vk->tp_b);
  if (bsdf_transmits(&y->f.bsdf))  // a camera inside a glass object
    f = f * segment_transmittance(s, &y->h, 0, -dir, length(y->h.p - camera_position(cam)));
  return tp * f * (cos_y * corr * importance * share);
}

PR_KERNEL void camera_splat(PR_PARAMS(PR_ARGS_CAMERA_SPLAT)) {
  const uint slot = (uint)get_global_id(0);
  if (slot >= rp.slots) return;
  const PathHeader hd = headers[slot];
  if (hd.light == PR_INVALID_INDEX || hd.vertex_count < 3u) return;
  SceneData s = PR_SCENE();
  const Light l = s.lights.lights[hd.light];
  if (!eye_paths_light(&l)) return;
  __global const LightVertex* v = vertices + (size_t)slot * rp.stride;
  __global const EyePathRatio* r = ratios + (size_t)slot * rp.stride;
  // Under a shutter the path meets the camera at the slot's time, uniform over the interval as the
  // eye paths' are: the path is what tracing gives then, whether it is the same at every time or
  // light_trace traced it at that time (PR_PATH_TIMED).
  CameraParams cam_t = cam;
  if (cam_step_count > 1u) {  // the shutter is open (a scene without instances moves no mesh)
    s.geom.time = s.sd.time = light_path_time(&rp, slot);
    cam_t = camera_at_time(cam_steps, cam_step_count, s.geom.time);
  }
  const float3 c = camera_position(&cam_t);
  uint rays = 0u;
  LightPoint yp = light_point(&s, v + 1);
  int l_ok = 1;  // L's light path z_0 .. z_{k-1} is the same at every time (light_segment_still)
  for (uint k = 2u; k < hd.vertex_count && eye_paths_camera_len(k, rp.max_depth); ++k) {
    if (l_ok && s.lights.sweep_count > 0u) l_ok = light_segment_still(&s, l.type, v, k - 1u);
    const LightPoint y = light_point(&s, v + k);
    const int skip = y.delta || yp.delta;
    const uint px = skip ? PR_INVALID_INDEX : camera_pixel(&cam_t, y.h.p);
    if (px != PR_INVALID_INDEX && px >= first && px < end) {
      const float3 dc = y.h.p - c;
      const float d2 = dot(dc, dc);
      const float3 dir = dc * (1.0f / sqrt(d2));
      // L makes the path from a still x_1 at this time too (connect's at_own).
      const int l_can = l_ok || camera_segment_still(&s, c, y.h.p);
      const float3 val =
          camera_splat_value(&s, &rp, &cam_t, &y, &yp, v + k, r[k - 1u], k, dir, l_can) *
          film_scale;
      if (max3(val) > 0.0f) {
        ++rays;
        // Towards the camera as far as its near plane: nothing nearer is seen.
        const Ray ray = surface_ray(&s, &y.h, -dir,
                                    sqrt(d2) * (1.0f - 1e-4f) - camera_near_distance(&cam_t, dir));
        if (!trace_occluded(&s, ray)) splat_add(splat + (size_t)px * PR_SPLAT_WORDS, val);
      }
    }
    yp = y;
  }
  if (rays) atomic_add(counter_lane(counters, PR_C_ROW) + PR_C_SPLAT_RAYS, rays);
}
