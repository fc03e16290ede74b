// pt_generate: one work-item per pixel of the band [first, count) (its state at pixel - first).
// Reads the camera (under --shutter, its cam_step_count steps, at the sample's time); writes a
// fresh PathState with the camera ray through a jittered point of the pixel (random dimensions 0
// and 1), and zero radiance; with write_eye (--eye-paths, --resample), marks the sample's EyeVertex
// empty, and with resample its reservoirs. Every path is live: the first bounce's queue lists them
// all (pixel `first` on, in order). Under --noise-threshold's mask
// (`masked`) only the pixels that take the pass are live: they are appended to the queue, whose
// length goes to queue_size[PR_QUEUE_LIVE]; the others' samples are left empty.
#include "shared/arena.h"
#include "shared/bvh.h"
#include "shared/camera.h"
#include "shared/motion.h"
#include "shared/path_state.h"
#include "shared/rng.h"

PR_KERNEL void pt_generate(PR_PARAMS(PR_ARGS_PT_GENERATE)) {
  const uint i = (uint)get_global_id(0);
  if (i >= count) return;
  Rng rng = rng_make(seed, PR_RNG_CAMERA, frame, i, sample);
  // With resample, sample `sample`'s point in the pixel is the same in every frame (as Cycles'
  // without an animated seed): where nothing moved, its x_1 is then the previous frame's, whose
  // paths the temporal shift takes unchanged. Its other numbers change with the frame.
  Rng at = resample ? rng_make(seed, PR_RNG_CAMERA, 0u, i, sample) : rng;
  const float2 jitter = rng_next2(&at);
  rng_skip(&rng, 1u);
  const CameraParams c = cam_step_count > 1u ? camera_at_time(cam_steps, cam_step_count,
                                                              shutter_time(seed, frame, i, sample))
                                             : cam;
  PathState s;
  s.ray = camera_ray(&c, i, jitter);
  s.tp_r = s.tp_g = s.tp_b = 1.0f;
  s.last_pdf = 0.0f;
  s.depth = 0u;
  s.pixel = i;
  s.alive = 1u;
  s.rng_dim = rng.dim;
  s.flags = PR_PATH_SPECULAR;
  s.prev_x = c.px;
  s.prev_y = c.py;
  s.prev_z = c.pz;
  s.prev_nx = s.prev_ny = s.prev_nz = 0.0f;
  s.x1_depth = 0u;
  s.eye_ratio = 1.0f;
  s.seg_cos = 0.0f;
  s.eye_flags = 0u;
  const float cos_t = s.ray.dx * c.fx + s.ray.dy * c.fy + s.ray.dz * c.fz;
  s.lt = cos_t * cos_t * cos_t;  // strategy T's camera factor at x_1 needs it (pt_shade)
  states[i - first] = s;
  radiance[i] = (float4)(0.0f, 0.0f, 0.0f, 0.0f);
  if (write_eye) eye[i].prim = PR_INVALID_INDEX;  // until pt_shade meets x_1
  if (resample) {                                 // an empty reservoir (shared/resample.h)
    rs_res[i].prim = PR_INVALID_INDEX;
    rs_res[i].w_sum = 0.0f;
    di_res[i].light = PR_INVALID_INDEX;
    di_res[i].w_sum = 0.0f;
  }
  if (!masked)
    queue[i - first] = i;
  else if (pixel_takes_pass(budget, masked, i, sample))
    queue[atomic_inc(queue_size + PR_QUEUE_LIVE)] = i;
}
